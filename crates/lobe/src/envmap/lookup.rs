//! A direction's radiance and both densities from one texel read
//! ([`EnvLookup`]), alone or with a draw, and for many directions or draws
//! at once, their texel reads overlapped ([`prefetch`], the [`Step`]s
//! [`SampleLookups`] and [`TexelIndices`]).

use super::map::{EnvMap, acos_guess, atan_01};
use super::sampler::TexelSampler;
use crate::batch::{SimdLevel, Step};
use crate::math::Rgb;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Radiance and the two light-sampling densities of one direction
/// ([`EnvMap::lookup`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnvLookup {
    /// The radiance arriving from the direction ([`EnvMap::eval`]).
    pub radiance: Rgb,
    /// [`EnvMap::pdf`], solid angle.
    pub pdf: f64,
    /// [`EnvMap::pdf_compensated`], solid angle.
    pub pdf_compensated: f64,
}

/// Draws or directions per step of [`EnvMap::sample_lookup_many`] and
/// [`EnvMap::lookup_many`].
const LOOKUP_CHUNK: usize = 64;

/// Ask the CPU to bring `v`'s cache line in (a hint: no effect on any
/// value, and none on other architectures), so that the reads of a chunk's
/// texels, which miss the caches for a large map, overlap.
#[inline(always)]
fn prefetch<T>(v: &T) {
    // SAFETY: SSE is in every x86-64 CPU (the target's baseline), and a
    // prefetch reads nothing and never faults, whatever the address.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
            std::ptr::from_ref(v).cast::<i8>(),
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = v;
}

/// [`EnvMap::sample_lookup_many`]'s work, run at a SIMD level: per chunk
/// of draws, the rows drawn, then the columns, the texels' cache lines
/// asked for, then each draw finished.
struct SampleLookups<'a> {
    map: &'a EnvMap,
    draws: &'a [(bool, DVec2)],
    out: &'a mut [Option<(DVec3, EnvLookup)>],
}

impl Step for SampleLookups<'_> {
    #[inline(always)]
    fn run(self) {
        let SampleLookups { map, draws, out } = self;
        // (A chunk's rows and columns as plain arrays, `NONE` where the
        // draw has none: no `Option`s to write and test.)
        const NONE: u32 = u32::MAX;
        for (dc, oc) in draws.chunks(LOOKUP_CHUNK).zip(out.chunks_mut(LOOKUP_CHUNK)) {
            let n = dc.len();
            let (mut rj, mut ru) = ([NONE; LOOKUP_CHUNK], [0.0; LOOKUP_CHUNK]);
            for ((j, r), &(comp, u)) in rj.iter_mut().zip(&mut ru).zip(dc) {
                if let Some((jj, rr)) = map.sampler(comp).rows.sample(u.x) {
                    (*j, *r) = (jj as u32, rr);
                }
            }
            let (mut ci, mut rv) = ([NONE; LOOKUP_CHUNK], [0.0; LOOKUP_CHUNK]);
            for (k, &(comp, u)) in dc.iter().enumerate() {
                if rj[k] == NONE {
                    continue;
                }
                let j = rj[k] as usize;
                if let Some((i, r)) = map
                    .sampler(comp)
                    .columns(map.weights(comp))
                    .row(j)
                    .sample(u.y)
                {
                    (ci[k], rv[k]) = (i as u32, r);
                    prefetch(&map.texels[j * map.width + i]);
                }
            }
            for (k, o) in oc[..n].iter_mut().enumerate() {
                *o = if ci[k] == NONE {
                    None
                } else {
                    map.finish_sample(dc[k].0, (rj[k] as usize, ru[k]), (ci[k] as usize, rv[k]))
                };
            }
        }
    }
}

/// The texels `j · width + i` of up to [`LOOKUP_CHUNK`] directions, as
/// [`EnvMap::texel_index`] finds them: the guesses of the whole chunk first,
/// in a loop without branches that the compiler vectorizes, then each
/// one's corrections.
struct TexelIndices<'a> {
    map: &'a EnvMap,
    dirs: &'a [DVec3],
    out: &'a mut [usize; LOOKUP_CHUNK],
}

impl Step for TexelIndices<'_> {
    #[inline(always)]
    fn run(self) {
        let TexelIndices { map, dirs, out } = self;
        let (w, h) = (map.width, map.height);
        let n = dirs.len().min(LOOKUP_CHUNK);
        let (mut sx, mut cx, mut y) = (
            [0.0; LOOKUP_CHUNK],
            [0.0; LOOKUP_CHUNK],
            [0.0; LOOKUP_CHUNK],
        );
        for (k, d) in dirs[..n].iter().enumerate() {
            let d = map.unrotate(*d);
            (sx[k], cx[k], y[k]) = (d.x, -d.z, d.y.clamp(-1.0, 1.0));
        }
        let (mut gi, mut gj) = ([0u32; LOOKUP_CHUNK], [0u32; LOOKUP_CHUNK]);
        let (wf, hf) = (w as f64, h as f64 / PI);
        let (wm, hm) = ((w - 1) as u32, (h - 1) as u32);
        for k in 0..LOOKUP_CHUNK {
            let (ax, ay) = (cx[k].abs(), sx[k].abs());
            let steep = ay > ax;
            let (lo, hi) = if steep { (ax, ay) } else { (ay, ax) };
            let a = atan_01(lo / hi);
            let a = if steep { 0.5 * PI - a } else { a };
            let a = if cx[k] < 0.0 { PI - a } else { a };
            let u = a / (2.0 * PI);
            let u = if sx[k] < 0.0 { 1.0 - u } else { u };
            let u = if u >= 1.0 { 0.0 } else { u };
            // (NaN, at a pole, converts to 0; the pole is column 0 below.)
            gi[k] = if hi > 0.0 {
                ((u * wf) as u32).min(wm)
            } else {
                0
            };
            gj[k] = ((acos_guess(y[k]) * hf) as u32).min(hm);
        }
        for k in 0..n {
            let (sx, cx, y) = (sx[k], cx[k], y[k]);
            let mut i = gi[k] as usize;
            if w > 1 && (sx != 0.0 || cx != 0.0) {
                let past = |k: usize| sx * map.col_cs[k].1 - cx * map.col_cs[k].0 >= 0.0;
                while i > 0 && !past(i) {
                    i -= 1;
                }
                while i + 1 < w && past(i + 1) {
                    i += 1;
                }
            } else {
                i = 0;
            }
            let mut j = gj[k] as usize;
            while j > 0 && y > map.row_cos[j] {
                j -= 1;
            }
            while j + 1 < h && y <= map.row_cos[j + 1] {
                j += 1;
            }
            out[k] = j * w + i;
        }
    }
}

impl EnvMap {
    /// Radiance and both densities ([`EnvMap::pdf`],
    /// [`EnvMap::pdf_compensated`]) at world direction `d` (unit), from one
    /// texel lookup: the same values as the three calls.
    #[inline]
    #[must_use]
    pub fn lookup(&self, d: DVec3) -> EnvLookup {
        let (i, j) = self.texel_index(d);
        self.texel_lookup(j * self.width + i, d)
    }

    /// The lookup of direction `d` in its texel `k`.
    #[inline(always)]
    fn texel_lookup(&self, k: usize, d: DVec3) -> EnvLookup {
        if self.smooth.is_some() {
            let (radiance, s, t) = self.smooth_at(k, d);
            return EnvLookup {
                radiance,
                pdf: self.smooth_pdf(false, k, s, t),
                pdf_compensated: self.smooth_pdf(true, k, s, t),
            };
        }
        let lum = self.texels[k].lum();
        let pdf = |t: &TexelSampler| {
            if t.norm > 0.0 {
                t.weight(lum) / t.norm
            } else {
                0.0
            }
        };
        EnvLookup {
            radiance: self.radiance_in(k, d),
            pdf: pdf(&self.plain),
            pdf_compensated: pdf(&self.compensated),
        }
    }

    /// Draw a world direction as [`EnvMap::sample`] (`compensated = false`)
    /// or [`EnvMap::sample_compensated`] (`true`) do, from the same
    /// distribution over the texels and uniformly in solid angle inside the
    /// texel, and return it with the [`EnvLookup`] of the texel it was drawn
    /// in (no second lookup, and no `acos`: `sin θ` comes from `cos θ`).
    /// `None` for a black map. The direction can differ from
    /// [`EnvMap::sample`]'s in its last bits.
    #[inline]
    #[must_use]
    pub fn sample_lookup(&self, compensated: bool, u: DVec2) -> Option<(DVec3, EnvLookup)> {
        let t = self.sampler(compensated);
        let (j, ru) = t.rows.sample(u.x)?;
        let (i, rv) = t.columns(self.weights(compensated)).row(j).sample(u.y)?;
        self.finish_sample(compensated, (j, ru), (i, rv))
    }

    /// [`EnvMap::sample_lookup`] of many draws `(compensated, u)`:
    /// `out[k] = self.sample_lookup(draws[k].0, draws[k].1)`, bit for bit.
    /// Each step (the row, the column, the texel) is taken for a chunk of
    /// draws before the next, so that their reads of a map larger than the
    /// caches overlap instead of waiting in turn.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn sample_lookup_many(
        &self,
        draws: &[(bool, DVec2)],
        out: &mut [Option<(DVec3, EnvLookup)>],
    ) {
        assert_eq!(draws.len(), out.len(), "sample_lookup_many: lengths differ");
        // Compiled for the CPU's widest level (the same arithmetic, so the
        // same bits at every level).
        SimdLevel::best().run(SampleLookups {
            map: self,
            draws,
            out,
        });
    }

    /// [`EnvMap::lookup`] of many directions: `out[k] = self.lookup(dirs[k])`,
    /// bit for bit, the texel searches of a chunk first and then its reads,
    /// which overlap.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn lookup_many(&self, dirs: &[DVec3], out: &mut [EnvLookup]) {
        self.lookup_many_at(SimdLevel::best(), dirs, out);
    }

    /// [`EnvMap::lookup_many`] with the texel guesses compiled for `level`
    /// (the same bits at every level).
    fn lookup_many_at(&self, level: SimdLevel, dirs: &[DVec3], out: &mut [EnvLookup]) {
        assert_eq!(dirs.len(), out.len(), "lookup_many: lengths differ");
        self.texels_many(level, dirs, out, |k, d| self.texel_lookup(k, d));
    }

    /// [`EnvMap::eval`] of many directions, the radiance alone (no
    /// densities): `out[k] = self.eval(dirs[k])`, bit for bit, as
    /// [`EnvMap::lookup_many`] finds the texels.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn eval_many(&self, dirs: &[DVec3], out: &mut [Rgb]) {
        self.eval_many_at(SimdLevel::best(), dirs, out);
    }

    fn eval_many_at(&self, level: SimdLevel, dirs: &[DVec3], out: &mut [Rgb]) {
        assert_eq!(dirs.len(), out.len(), "eval_many: lengths differ");
        self.texels_many(level, dirs, out, |k, d| self.radiance_in(k, d));
    }

    /// `out[k] = at(texel index of dirs[k])`, the indices of a chunk found
    /// together at `level` first.
    #[inline]
    fn texels_many<T>(
        &self,
        level: SimdLevel,
        dirs: &[DVec3],
        out: &mut [T],
        at: impl Fn(usize, DVec3) -> T,
    ) {
        for (dc, oc) in dirs.chunks(LOOKUP_CHUNK).zip(out.chunks_mut(LOOKUP_CHUNK)) {
            let mut idx = [0usize; LOOKUP_CHUNK];
            level.run(TexelIndices {
                map: self,
                dirs: dc,
                out: &mut idx,
            });
            for &k in &idx[..dc.len()] {
                prefetch(&self.texels[k]);
            }
            for ((o, &k), &d) in oc.iter_mut().zip(&idx).zip(dc) {
                *o = at(k, d);
            }
        }
    }

    /// `sin_cos` of `φ = 2π (i + rv) / width`, `rv ∈ [0, 1)`: column
    /// `i`'s edge from the table turned by `δ = 2π rv / width`, whose sine
    /// and cosine are Taylor polynomials exact to f64 rounding for
    /// `δ < 2π/256` (the terms left out are below 1e-18 of the result);
    /// narrower maps call `sin_cos`.
    #[inline(always)]
    fn column_sin_cos(&self, i: usize, rv: f64) -> (f64, f64) {
        let w = self.width as f64;
        if self.width < 256 {
            return (2.0 * PI * (i as f64 + rv) / w).sin_cos();
        }
        let d = 2.0 * PI * rv / w;
        let d2 = d * d;
        let sd =
            d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))));
        let cd = 1.0
            - d2 * 0.5
                * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0))));
        let (s, c) = self.col_cs[i];
        (s * cd + c * sd, c * cd - s * sd)
    }

    /// The direction and lookup of a draw in texel `(i, j)` at `(ru, rv)`.
    #[inline(always)]
    fn finish_sample(
        &self,
        compensated: bool,
        (j, ru): (usize, f64),
        (i, rv): (usize, f64),
    ) -> Option<(DVec3, EnvLookup)> {
        let (rv, ru) = self.place_in_texel(compensated, (i, j), ru, rv);
        let (c0, c1) = (self.row_cos[j], self.row_cos[j + 1]);
        let ct = (c0 + (c1 - c0) * ru).clamp(c1.min(c0), c0.max(c1));
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let (sp, cp) = self.column_sin_cos(i, rv);
        let d = self.rotate(DVec3::new(st * sp, ct, -st * cp));
        let l = self.texel_lookup(j * self.width + i, d);
        let p = if compensated {
            l.pdf_compensated
        } else {
            l.pdf
        };
        (p > 0.0).then_some((d, l))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The column's sine and cosine from the table and the polynomials
    /// are `sin_cos`'s within 4e-15 (both round the angle, whose unit in
    /// the last place is up to 8.9e-16).
    #[test]
    fn column_sin_cos_is_sin_cos() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
        for w in [1usize, 3, 255, 256, 1024, 4096] {
            let m = EnvMap::new(w, 2, vec![Rgb::ONE; 2 * w], 1.0, 0.0)
                .unwrap()
                .0;
            for k in 0..5000 {
                let i = rng.random_range(0..w);
                let rv = match k {
                    0 => 0.0,
                    1 => 1.0 - f64::EPSILON / 2.0,
                    _ => rng.random::<f64>(),
                };
                let (s, c) = m.column_sin_cos(i, rv);
                let (s0, c0) = (2.0 * PI * (i as f64 + rv) / w as f64).sin_cos();
                assert!(
                    (s - s0).abs() <= 4e-15 && (c - c0).abs() <= 4e-15,
                    "w {w} i {i} rv {rv}: {s} {c} against {s0} {c0}"
                );
            }
        }
    }

    /// The built-in sky at 64 × 32 through `EnvMap::new`, scaled by 1.5
    /// and rotated by 33°.
    fn scaled_sky() -> EnvMap {
        let texels = EnvMap::sky(64, 32, 30.0, 40.0)
            .texels
            .iter()
            .map(|t| t.rgb())
            .collect();
        EnvMap::new(64, 32, texels, 1.5, 33.0).unwrap().0
    }

    /// The block forms give the single calls' values, bit for bit (over
    /// more than two chunks, with both distributions).
    #[test]
    fn the_many_lookups_are_the_single_ones() {
        let m = scaled_sky();
        let n = 150;
        let u = |k: usize| {
            let a = crate::sequence::hash64(k as u64);
            DVec2::new(
                (a >> 40) as f64 / (1u64 << 24) as f64,
                (a & 0xffffff) as f64 / (1u64 << 24) as f64,
            )
        };
        let draws: Vec<(bool, DVec2)> = (0..n).map(|k| (k % 3 == 0, u(k))).collect();
        let mut got = vec![None; n];
        m.sample_lookup_many(&draws, &mut got);
        for (k, &(c, uk)) in draws.iter().enumerate() {
            assert_eq!(got[k], m.sample_lookup(c, uk), "draw {k}");
        }
        // Lookups at every SIMD level, on maps of one texel, one column,
        // a few and many; the poles, the axes and the seam included.
        let mut dirs: Vec<DVec3> = (0..2000).map(|k| m.uv_to_direction(u(k + n))).collect();
        for d in [DVec3::X, DVec3::Y, DVec3::Z] {
            dirs.extend([d, -d]);
        }
        dirs.extend((0..100).map(|k| DVec3::new(-1e-9 * k as f64, 0.3, 1.0).normalize()));
        let one = EnvMap::new(1, 2, vec![Rgb::ONE, Rgb::splat(2.0)], 1.0, 0.0)
            .unwrap()
            .0;
        let few = EnvMap::new(
            3,
            2,
            (0..6).map(|k| Rgb::splat(k as f64)).collect(),
            1.0,
            -10.0,
        )
        .unwrap()
        .0;
        let smooth = scaled_sky().smooth();
        for map in [&m, &smooth, &one, &few, &EnvMap::constant(Rgb::ONE)] {
            for level in SimdLevel::ALL.into_iter().filter(|l| l.is_available()) {
                let mut looked = vec![EnvLookup::default(); dirs.len()];
                map.lookup_many_at(level, &dirs, &mut looked);
                let mut radiance = vec![Rgb::ZERO; dirs.len()];
                map.eval_many_at(level, &dirs, &mut radiance);
                for (k, &d) in dirs.iter().enumerate() {
                    assert_eq!(looked[k], map.lookup(d), "{level:?} direction {k} {d}");
                    assert_eq!(radiance[k], map.eval(d), "{level:?} direction {k} {d}");
                }
            }
        }
    }

    /// `sample_lookup` draws inside the texel whose lookup it returns, that
    /// lookup is `lookup` of the direction, and it is `sample`'s
    /// distribution (the same texel for the same numbers).
    #[test]
    fn sample_lookup_agrees_with_sample_and_lookup() {
        for (m, comp) in [
            (scaled_sky(), false),
            (scaled_sky(), true),
            (scaled_sky().smooth(), false),
            (scaled_sky().smooth(), true),
        ] {
            for k in 0..2000 {
                let u = DVec2::new(
                    (k as f64 * 0.618_033_988_7 + 0.01) % 1.0,
                    (k as f64 * 0.414_213_562 + 0.02) % 1.0,
                );
                let (d, l) = m.sample_lookup(comp, u).unwrap();
                assert!((d.length() - 1.0).abs() < 1e-12);
                let (d0, p0) = if comp {
                    m.sample_compensated(u).unwrap()
                } else {
                    m.sample(u).unwrap()
                };
                assert!((d - d0).length() < 1e-9, "{d} {d0}");
                let p = if comp { l.pdf_compensated } else { l.pdf };
                assert!((p - p0).abs() <= 1e-12 * p0);
                assert_eq!(m.lookup(d), l);
                assert_eq!(l.radiance, m.eval(d));
                assert_eq!(l.pdf, m.pdf(d));
                assert_eq!(l.pdf_compensated, m.pdf_compensated(d));
            }
        }
    }
}
