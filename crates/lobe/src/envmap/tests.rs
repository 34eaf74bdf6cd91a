//! Tests of the map as a whole: its sampler's tables, built lazily and in
//! place, seen through its draws and lookups, and its clamping of texels.

use super::distribution::Distribution1D;
use super::map::EnvMap;
use super::sampler::TexelSampler;
use crate::math::Rgb;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// `w × h` texels (at least 41 × 10) with a black row (5), a sun (one
/// texel, (40, 9)) and a sky that varies along both axes.
fn black_row_and_sun(w: usize, h: usize) -> Vec<Rgb> {
    (0..w * h)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            if j == 5 {
                Rgb::ZERO
            } else if (i, j) == (40, 9) {
                Rgb::splat(5e4)
            } else {
                Rgb::new(0.2 + (i as f64 * 0.37).sin().abs(), 0.5, 1.0 + j as f64)
            }
        })
        .collect()
}

/// The plain density's tables wait for the first draw: a map fresh from
/// `EnvMap::new` has the compensated one's only. Built by draws on
/// the threads of a pool (several asking at once, each of them a thread
/// that could otherwise take a job of the build), they are the tables
/// [`EnvMap::prepare_sampling`] builds on the calling thread, and they
/// draw the same directions and densities, bit for bit; their rows'
/// totals are the sums the density had before.
#[test]
fn plain_tables_are_built_on_first_draw() {
    use rayon::prelude::*;
    let (w, h) = (64, 16);
    let rgb = black_row_and_sun(w, h);
    let lazy = EnvMap::new(w, h, rgb.clone(), 1.5, 20.0).unwrap().0;
    let eager = EnvMap::new(w, h, rgb, 1.5, 20.0).unwrap().0;
    assert!(lazy.plain.cols.tables.get().is_none());
    assert!(lazy.compensated.cols.tables.get().is_some());
    eager.prepare_sampling();
    assert!(eager.plain.cols.tables.get().is_some());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let us: Vec<DVec2> = (0..4000)
        .map(|k| DVec2::new((k as f64 * 0.618_034) % 1.0, (k as f64 * 0.754_877) % 1.0))
        .collect();
    let drawn: Vec<_> = pool.install(|| {
        us.par_iter()
            .with_max_len(1)
            .map(|&u| (lazy.sample(u), lazy.sample_lookup(false, u)))
            .collect()
    });
    for (&u, (s, l)) in us.iter().zip(&drawn) {
        assert_eq!(*s, eager.sample(u), "u {u}");
        assert_eq!(*l, eager.sample_lookup(false, u), "u {u}");
    }
    let (a, b) = (
        lazy.plain.columns((&lazy.texels[..]).into()),
        eager.plain.columns((&eager.texels[..]).into()),
    );
    assert_eq!(a.tables.cdf, b.tables.cdf);
    assert_eq!(a.tables.guide, b.tables.guide);
    let (_, built) = TexelSampler::build_tables(w, h, None, (&lazy.texels[..]).into(), false);
    assert_eq!(a.tables.cdf, built.cdf);
    for j in 0..h {
        assert_eq!(a.row(j).total.to_bits(), a.totals[j].to_bits());
    }
    let (totals, _) = TexelSampler::build_tables(w, h, None, (&lazy.texels[..]).into(), true);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&totals), bits(&lazy.plain.cols.totals));
}

/// A sampler's rows, built in place in its two shared buffers
/// ([`Columns`]), are the distributions [`Distribution1D::from_weights`]
/// builds alone, bit for bit, and sample alike (a sun in a sky, a
/// black row).
#[test]
fn columns_are_the_rows_distributions() {
    let (w, h) = (64usize, 16usize);
    let m = EnvMap::new(w, h, black_row_and_sun(w, h), 1.0, 0.0)
        .unwrap()
        .0;
    for t in [&m.plain, &m.compensated] {
        let dphi = 2.0 * PI / w as f64;
        for j in 0..h {
            let omega = dphi * TexelSampler::band(h, j);
            let alone = Distribution1D::from_weights(
                m.texels[j * w..(j + 1) * w]
                    .iter()
                    .map(|x| TexelSampler::weight_of(t.shift, x.lum()) * omega),
            );
            let row = t.columns((&m.texels[..]).into()).row(j);
            assert_eq!(row.cdf, &alone.cdf[..], "row {j}");
            assert_eq!(row.guide, &alone.guide[..], "row {j}");
            assert_eq!(row.total.to_bits(), alone.total().to_bits(), "row {j}");
            for k in 0..200 {
                let u = k as f64 / 200.0 + 1e-3;
                assert_eq!(row.sample(u), alone.sample(u), "row {j} u {u}");
            }
        }
    }
}

#[test]
fn negative_nan_and_huge_texels_are_clamped_and_counted() {
    let (m, n) = EnvMap::new(
        2,
        1,
        vec![
            Rgb::new(-1.0, 0.5, f64::NAN),
            Rgb::new(f64::INFINITY, 1.0, 1.0),
        ],
        1.0,
        0.0,
    )
    .unwrap();
    assert_eq!(n, 2);
    assert_eq!(m.texel(0, 0), Rgb::new(0.0, 0.5, 0.0));
    assert_eq!(m.texel(1, 0), Rgb::new(0.0, 1.0, 1.0));
    // Beyond f32: the largest f32, and counted; an f64 value is
    // rounded to the nearest f32. (+∞ is clamped to 0 like NaN.)
    let big = f64::from(f32::MAX);
    let (m, n) = EnvMap::new(
        3,
        1,
        vec![Rgb::new(1e300, 0.1, 2e38), Rgb::splat(big), Rgb::ONE],
        1.0,
        0.0,
    )
    .unwrap();
    assert_eq!(n, 1);
    assert_eq!(
        m.texel(0, 0),
        Rgb::new(big, f64::from(0.1f32), f64::from(2e38f32))
    );
    assert_eq!(m.texel(1, 0), Rgb::splat(big));
    assert!(m.lookup(DVec3::X).pdf.is_finite());
}
