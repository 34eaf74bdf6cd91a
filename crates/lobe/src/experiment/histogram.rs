//! Sampling histograms and sample weights over the *projected hemisphere*:
//! the unit disk of the `(x, y)` coordinates of `wi` in the local frame
//! (`+z` is the normal). These are the numbers of `lobe plot`'s warp-test
//! histograms and weight heat maps; the drawing is the caller's.
//!
//! Grids are `res × res`, row-major: pixel `(i, j)` at index `j * res + i`
//! covers `x ∈ [−1 + 2i/res, −1 + 2(i+1)/res)` and likewise `y` with `j`, so
//! row 0 is the bottom (`y = −1`).
//!
//! Over the whole sphere ([`over_sphere`]: the material transmits, or is
//! seen from below), a map is two such grids, `2 res²` values: the upper
//! hemisphere's (`z > 0`), then the lower one's (`z < 0`), each the
//! projection of its hemisphere on the unit disk.

use super::map_indices;
use crate::math::luminance;
use crate::progress::Progress;
use crate::{BsdfSampler, BsdfStrategy, Material};
use glam::{DVec2, DVec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

/// Observed and expected sample counts over a `res × res` grid (two, one
/// per hemisphere, over the sphere).
#[derive(Debug, Clone, PartialEq)]
pub struct Histograms {
    /// Samples that fell in each pixel.
    pub observed: Vec<f64>,
    /// `samples × ∫ pdf dω` over each pixel's directions.
    pub expected: Vec<f64>,
    /// The grid's side.
    pub res: usize,
    /// Two grids, the upper hemisphere's then the lower one's
    /// ([`over_sphere`]).
    pub sphere: bool,
}

/// Whether the maps of `m` at `wo` cover the whole sphere, two disks: it
/// transmits, or it is seen from below (a two-sided material, whose lobe is
/// then below).
#[must_use]
pub fn over_sphere(m: &Material, wo: DVec3) -> bool {
    m.reach().transmits || wo.z < 0.0
}

/// The direction at disk point `c` (inside the unit disk) of hemisphere
/// `k` (0 upper, 1 lower).
fn disk_direction(c: DVec2, k: usize) -> DVec3 {
    let z = (1.0 - c.length_squared()).max(0.0).sqrt();
    DVec3::new(c.x, c.y, if k == 0 { z } else { -z })
}

/// The pixel column (or row) of a `res`-pixel side holding coordinate
/// `x ∈ [−1, 1]` (clamped to the grid; NaN gives 0).
#[must_use]
pub fn disk_cell(x: f64, res: usize) -> usize {
    let i = ((x + 1.0) * 0.5 * res as f64).floor();
    if i.is_nan() || i < 0.0 {
        0
    } else {
        (i as usize).min(res - 1)
    }
}

/// Observed and expected sample counts of `sampler.sample(wo, ..)`
/// over a `res × res` grid on the projected hemisphere, or two over the
/// sphere ([`over_sphere`]; layout in the [module docs](self); `res` below 1
/// is taken as 1). Pixels outside the disk hold zero. Samples of a delta
/// part (a mirror reflection, smooth refraction) have no density to compare
/// with: they fall in no pixel, like failed samples.
///
/// The observed counts come from `samples` draws with the uniforms `uc`,
/// `u.x`, `u.y` taken in that order from `Pcg64::seed_from_u64(seed)`, the
/// same stream as [`crate::stats::chi2::chi2_test`]; failed samples are
/// counted in `samples` but fall in no pixel. The expected count of a pixel
/// is `samples × ∫ pdf dω` over its directions: the pixel is cut into a few
/// × a few cells in disk coordinates, each weighing the pdf at its centre by
/// its solid angle ([`rect_solid_angle`], exact, so the pixels on the rim,
/// where `1/z` blows up, are as accurate as the others).
///
/// Progress: one task `histogram` of
/// `samples` steps (the draws; the expected counts are not counted).
#[must_use]
pub fn projected_histograms(
    sampler: &BsdfSampler<'_>,
    wo: DVec3,
    samples: usize,
    seed: u64,
    res: usize,
    progress: &dyn Progress,
) -> Histograms {
    const STEP: usize = 1 << 16;
    progress.start("histogram", samples as u64);
    let res = res.max(1);
    let sphere = over_sphere(sampler.material(), wo);
    let disks = if sphere { 2 } else { 1 };
    let mut observed = vec![0.0; disks * res * res];
    let mut rng = Pcg64::seed_from_u64(seed);
    for n in 0..samples {
        let uc: f64 = rng.random();
        let ux: f64 = rng.random();
        let uy: f64 = rng.random();
        if let Some(s) = sampler.sample(wo, uc, DVec2::new(ux, uy))
            && !s.scattering.is_specular()
            && (sphere || s.wi.z >= 0.0)
        {
            let (i, j) = (disk_cell(s.wi.x, res), disk_cell(s.wi.y, res));
            let k = usize::from(s.wi.z < 0.0);
            observed[k * res * res + j * res + i] += 1.0;
        }
        if (n + 1) % STEP == 0 {
            progress.advance(STEP as u64);
        }
    }
    progress.advance((samples % STEP) as u64);

    // Each pixel is cut into sub × sub cells; a cell contributes the pdf at
    // its centre (pulled inside the disk at the rim) times its exact solid
    // angle, so the 1/z singularity of dω = dx dy / z at the rim costs no
    // accuracy.
    let sub = (512 / res).clamp(3, 8);
    let h = 2.0 / res as f64;
    let hs = h / sub as f64;
    let n = samples as f64;
    let expected = map_indices(disks * res * res, |k| {
        let (disk, k) = (k / (res * res), k % (res * res));
        let (i, j) = (k % res, k / res);
        let mut acc = 0.0;
        for b in 0..sub {
            let y0 = -1.0 + j as f64 * h + b as f64 * hs;
            for a in 0..sub {
                let x0 = -1.0 + i as f64 * h + a as f64 * hs;
                let omega = rect_solid_angle(x0, x0 + hs, y0, y0 + hs);
                if omega <= 0.0 {
                    continue;
                }
                let mut c = DVec2::new(x0 + 0.5 * hs, y0 + 0.5 * hs);
                let r = c.length();
                if r > 1.0 - 1e-7 {
                    c *= (1.0 - 1e-7) / r;
                }
                let p = sampler.pdf(wo, disk_direction(c, disk));
                if p.is_finite() && p > 0.0 {
                    acc += p * omega;
                }
            }
        }
        n * acc
    });
    Histograms {
        observed,
        expected,
        res,
        sphere,
    }
}

/// An antiderivative of `1/sqrt(1 − x² − y²)` in `x` and `y` over the unit
/// disk (continuous up to its rim): `∂²F/∂x∂y = 1/z` and
/// `∂F/∂y = asin(x / sqrt(1 − y²))`.
fn solid_angle_antiderivative(x: f64, y: f64) -> f64 {
    let half_asin = |num: f64, den2: f64| {
        if den2 > 0.0 {
            (num / den2.sqrt()).clamp(-1.0, 1.0).asin()
        } else if num == 0.0 {
            0.0
        } else {
            std::f64::consts::FRAC_PI_2.copysign(num)
        }
    };
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    y * half_asin(x, 1.0 - y * y) + x * half_asin(y, 1.0 - x * x) - (x * y).atan2(z)
}

/// The solid angle (steradians) of the upper-hemisphere directions whose
/// `(x, y)` lie in the rectangle `[x0, x1] × [y0, y1]` and in the unit disk:
/// `∫∫ dx dy / z`, exactly (no cosine: the whole disk gives 2π). An empty
/// rectangle gives 0.
#[must_use]
pub fn rect_solid_angle(x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    use std::f64::consts::FRAC_PI_2;
    let (ya, yb) = (y0.max(-1.0), y1.min(1.0));
    if ya >= yb || x0 >= x1 {
        return 0.0;
    }
    // Cut [ya, yb] where the rim crosses x = x0 and x = x1, so that in each
    // piece each side of the rectangle is either inside the disk or not.
    let mut cuts = vec![ya, yb];
    for x in [x0, x1] {
        if x.abs() < 1.0 {
            let yc = (1.0 - x * x).sqrt();
            cuts.extend([-yc, yc].into_iter().filter(|&v| v > ya && v < yb));
        }
    }
    cuts.sort_by(f64::total_cmp);
    let f = solid_angle_antiderivative;
    let mut total = 0.0;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let c = (1.0 - (0.5 * (a + b)).powi(2)).max(0.0).sqrt();
        if x1 <= -c || x0 >= c {
            continue;
        }
        let upper = if x1 < c {
            f(x1, b) - f(x1, a)
        } else {
            FRAC_PI_2 * (b - a)
        };
        let lower = if x0 > -c {
            f(x0, b) - f(x0, a)
        } else {
            -FRAC_PI_2 * (b - a)
        };
        total += upper - lower;
    }
    total.max(0.0)
}

/// The sample weight at one pixel of a weight map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WeightPixel {
    /// The pixel's centre is outside the unit disk.
    Outside,
    /// `f = 0` (or NaN): the weight is zero.
    ZeroF,
    /// `f > 0` and `pdf = 0`: the strategy never samples this direction.
    Unsampled,
    /// `f·cos θi / pdf`, with `f` the luminance of the BRDF.
    Weight(f64),
}

/// The sample weight `f·|cos θi| / pdf` (cosine included; `f` is the
/// luminance of the material's `eval`) that `sampler` gives the direction at the
/// centre of each pixel of a `res × res` grid over the projected hemisphere,
/// or two over the sphere ([`over_sphere`]; layout in the
/// [module docs](self)). `res` must be at least 1.
#[must_use]
pub fn weight_pixels(sampler: &BsdfSampler<'_>, wo: DVec3, res: usize) -> Vec<WeightPixel> {
    let material = sampler.material();
    let disks = if over_sphere(material, wo) { 2 } else { 1 };
    map_indices(disks * res * res, |k| {
        let (disk, k) = (k / (res * res), k % (res * res));
        let (i, j) = (k % res, k / res);
        let x = -1.0 + (i as f64 + 0.5) * 2.0 / res as f64;
        let y = -1.0 + (j as f64 + 0.5) * 2.0 / res as f64;
        let r2 = x * x + y * y;
        if r2 >= 1.0 {
            return WeightPixel::Outside;
        }
        let wi = disk_direction(DVec2::new(x, y), disk);
        let f = luminance(material.eval(wo, wi));
        let pdf = sampler.pdf(wo, wi);
        if f.is_nan() || f <= 0.0 {
            WeightPixel::ZeroF
        } else if pdf.is_nan() || pdf <= 0.0 {
            WeightPixel::Unsampled
        } else {
            WeightPixel::Weight(f * wi.z.abs() / pdf)
        }
    })
}

/// The fraction of `samples` draws of `strategy` at `wo` that fail (a
/// direction below the horizon, which an estimator counts with weight
/// zero), from independent uniform numbers seeded by `seed`. Zero when
/// `samples` is zero. The error says why the strategy does not apply.
pub fn lost_fraction(
    m: &Material,
    strategy: BsdfStrategy,
    wo: DVec3,
    samples: usize,
    seed: u64,
) -> Result<f64, crate::Error> {
    let sampler = m.sampler(strategy)?;
    let mut rng = Pcg64::seed_from_u64(crate::sequence::hash64(seed ^ 0x6c6f_7374));
    let mut lost = 0usize;
    for _ in 0..samples {
        let uc: f64 = rng.random();
        let u = DVec2::new(rng.random(), rng.random());
        if sampler.sample(wo, uc, u).is_none() {
            lost += 1;
        }
    }
    Ok(lost as f64 / samples.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;
    use std::f64::consts::PI;

    fn lambert() -> Material {
        Material::lambert(Rgb::splat(0.8)).unwrap()
    }

    #[test]
    fn solid_angles_of_rectangles() {
        // Points on the rim lose about half the digits (z = sqrt of a rounding error).
        let close = |a: f64, b: f64| (a - b).abs() < 1e-7 * b.abs().max(1.0);
        assert!(close(rect_solid_angle(-1.0, 1.0, -1.0, 1.0), 2.0 * PI));
        assert!(close(rect_solid_angle(0.0, 1.0, 0.0, 1.0), PI / 2.0));
        assert!(close(rect_solid_angle(-2.0, 3.0, -1.5, 1.5), 2.0 * PI));
        assert!(close(rect_solid_angle(0.3, 0.5, -1.0, 1.0), PI * 0.2));
        assert!(close(rect_solid_angle(-1.0, 1.0, -0.7, -0.2), PI * 0.5));
        assert_eq!(rect_solid_angle(0.8, 1.0, 0.8, 1.0), 0.0);
        assert_eq!(rect_solid_angle(0.5, 0.5, -1.0, 1.0), 0.0);
        // Against a fine midpoint rule, on a rectangle that crosses the rim.
        let (x0, x1, y0, y1) = (0.55, 0.8, 0.3, 0.9);
        let m = 2000;
        let mut num = 0.0;
        for i in 0..m {
            for j in 0..m {
                let x = x0 + (x1 - x0) * (f64::from(i) + 0.5) / f64::from(m);
                let y = y0 + (y1 - y0) * (f64::from(j) + 0.5) / f64::from(m);
                let r2 = x * x + y * y;
                if r2 < 1.0 {
                    num += 1.0 / (1.0 - r2).sqrt();
                }
            }
        }
        num *= (x1 - x0) * (y1 - y0) / f64::from(m * m);
        let exact = rect_solid_angle(x0, x1, y0, y1);
        assert!((num / exact - 1.0).abs() < 2e-3, "{num} vs {exact}");
    }

    /// A grid of rectangles tiles the disk: the two hemispheres (each 2π)
    /// sum to the sphere's 4π.
    #[test]
    fn rectangles_sum_to_the_sphere() {
        for res in [1, 7, 32] {
            let h = 2.0 / f64::from(res);
            let mut total = 0.0;
            for i in 0..res {
                for j in 0..res {
                    let (x0, y0) = (-1.0 + f64::from(i) * h, -1.0 + f64::from(j) * h);
                    total += rect_solid_angle(x0, x0 + h, y0, y0 + h);
                }
            }
            assert!((2.0 * total - 4.0 * PI).abs() < 1e-6, "res {res}: {total}");
        }
    }

    #[test]
    fn lost_samples() {
        let wo = crate::frame::wo_from_theta(80.0, 0.0);
        let m = lambert();
        assert_eq!(
            lost_fraction(&m, BsdfStrategy::Cosine, wo, 1000, 1),
            Ok(0.0)
        );
        assert_eq!(lost_fraction(&m, BsdfStrategy::Uniform, wo, 0, 1), Ok(0.0));
        assert!(lost_fraction(&m, BsdfStrategy::Vndf, wo, 10, 1).is_err());
        // Phong's lobe about the mirror direction of a grazing view: about
        // half of it is below the horizon.
        let phong = Material::with_diffuse(
            Rgb::ZERO,
            crate::Glossy::Phong(crate::models::Phong::new(Rgb::splat(0.8), 10.0, true).unwrap()),
        )
        .unwrap();
        let a = lost_fraction(&phong, BsdfStrategy::Brdf, wo, 20_000, 3).unwrap();
        assert!(a > 0.2 && a < 0.6, "{a}");
        assert_eq!(
            lost_fraction(&phong, BsdfStrategy::Brdf, wo, 20_000, 3),
            Ok(a)
        );
        assert_ne!(
            lost_fraction(&phong, BsdfStrategy::Brdf, wo, 20_000, 4),
            Ok(a)
        );
    }

    #[test]
    fn cells() {
        assert_eq!(disk_cell(-1.0, 8), 0);
        assert_eq!(disk_cell(1.0, 8), 7);
        assert_eq!(disk_cell(0.0, 8), 4);
        assert_eq!(disk_cell(-0.01, 8), 3);
        assert_eq!(disk_cell(f64::NAN, 8), 0);
        assert_eq!(disk_cell(-5.0, 8), 0);
    }

    /// For a uniform pdf, the expected counts of a column of pixels are
    /// `N × (x1 − x0) / 2` exactly, rim included.
    #[test]
    fn expected_counts_are_accurate_at_the_rim() {
        let wo = DVec3::new(0.0, 0.0, 1.0);
        let res = 16;
        let h = projected_histograms(
            &lambert().sampler(BsdfStrategy::Uniform).unwrap(),
            wo,
            1_000_000,
            1,
            res,
            &(),
        );
        for i in 0..res {
            let column: f64 = (0..res).map(|j| h.expected[j * res + i]).sum();
            let exact = 1_000_000.0 / res as f64;
            assert!(
                (column / exact - 1.0).abs() < 1e-6,
                "column {i}: {column} vs {exact}"
            );
        }
    }

    struct Steps(std::sync::Mutex<(u64, u64)>);
    impl Progress for Steps {
        fn start(&self, _label: &str, total: u64) {
            self.0.lock().unwrap().0 = total;
        }
        fn advance(&self, n: u64) {
            self.0.lock().unwrap().1 += n;
        }
    }

    /// Every sample of cosine sampling lands in a pixel: the observed total
    /// is the sample count, and the expected total matches it.
    #[test]
    fn histograms_agree_for_cosine_sampling() {
        let wo = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        let steps = Steps(std::sync::Mutex::new((0, 0)));
        let h = projected_histograms(
            &lambert().sampler(BsdfStrategy::Cosine).unwrap(),
            wo,
            200_000,
            3,
            16,
            &steps,
        );
        assert_eq!(h.res, 16);
        assert_eq!((h.observed.len(), h.expected.len()), (256, 256));
        let (so, se): (f64, f64) = (h.observed.iter().sum(), h.expected.iter().sum());
        assert_eq!(so, 200_000.0);
        assert!((se / 200_000.0 - 1.0).abs() < 2e-3, "{se}");
        assert_eq!(*steps.0.lock().unwrap(), (200_000, 200_000));
        // The same seed gives the same counts.
        let again = projected_histograms(
            &lambert().sampler(BsdfStrategy::Cosine).unwrap(),
            wo,
            200_000,
            3,
            16,
            &(),
        );
        assert_eq!(again, h);
    }

    /// Cosine sampling of a Lambert BRDF has the weight `albedo` everywhere
    /// in the disk; uniform sampling has `2 albedo cos θ`.
    #[test]
    fn weights_of_lambert() {
        let wo = DVec3::Z;
        let res = 9;
        let cos = weight_pixels(&lambert().sampler(BsdfStrategy::Cosine).unwrap(), wo, res);
        let uni = weight_pixels(&lambert().sampler(BsdfStrategy::Uniform).unwrap(), wo, res);
        assert_eq!(cos.len(), 81);
        assert_eq!(cos[0], WeightPixel::Outside);
        let mut inside = 0;
        for (k, (c, u)) in cos.iter().zip(&uni).enumerate() {
            match (c, u) {
                (WeightPixel::Weight(c), WeightPixel::Weight(u)) => {
                    inside += 1;
                    assert!((c - 0.8).abs() < 1e-12, "{k}: {c}");
                    let (i, j) = (k % res, k / res);
                    let x = -1.0 + (i as f64 + 0.5) * 2.0 / res as f64;
                    let y = -1.0 + (j as f64 + 0.5) * 2.0 / res as f64;
                    let z = (1.0 - x * x - y * y).sqrt();
                    assert!((u - 1.6 * z).abs() < 1e-12, "{k}: {u}");
                }
                (WeightPixel::Outside, WeightPixel::Outside) => {}
                other => panic!("{k}: {other:?}"),
            }
        }
        assert!(inside > 40);
    }
}
