//! The tabulated sampler of a measured material (`brdf` strategy).
//!
//! Per bin of θo (the view elevation; `N_THETA_O` bins uniform in θo), a
//! piecewise-constant distribution over the half vector `h`: cells
//! `N_U × N_V` in `(√(θh/(π/2)), φh − φo)`, each cell's probability
//! proportional to `∫_cell lum(f(wo, wi)) cos θi · 4 (wo·h) dω_h` (the
//! luminance of `f cos θi` times the half-vector Jacobian, a 3 × 3 midpoint
//! rule with `wo` at the bin's centre), and `h` uniform in solid angle within
//! its cell. `wi` is `wo` mirrored about `h` (a sample below the horizon is
//! lost). A share `COSINE_SHARE` of the samples is drawn from the cosine
//! distribution instead, so that no direction with `f > 0` has pdf 0.
//!
//! The pdf is exact: `pdf(wo, wi) = (1 − c) P(cell(h)) / Ω(cell) / (4 wo·h) +
//! c cos θi / π`, the same bin and cell lookup that `sample` uses.

use crate::math::Rgb;
use crate::warp;
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Bins of θo.
pub const N_THETA_O: usize = 24;
/// Cells in `√(θh/(π/2))`.
pub const N_U: usize = 48;
/// Cells in `φh − φo` over `[0, 2π)`.
pub const N_V: usize = 96;
/// The share of cosine-sampled directions.
pub const COSINE_SHARE: f64 = 0.1;

/// The sampler's tables (densities `f32`, cdfs `f64`).
#[derive(Debug, Clone)]
pub struct HalfVectorTable {
    /// Per bin, per cell: the cell's probability over its solid angle
    /// (density of `h` in solid angle).
    density: Vec<f32>,
    /// Per bin: cdf over the rows (`N_U`), normalised, last = 1 (`f64`:
    /// in `f32` the rows far from a glossy peak, whose cdf is near 1, would
    /// lose their probability to rounding).
    row_cdf: Vec<f64>,
    /// Per bin and row: cdf over the columns (`N_V`), normalised.
    col_cdf: Vec<f64>,
    /// Per bin: `∫ lum(f) cos θi dωi` (the albedo at the bin's centre).
    albedo: Vec<f32>,
}

#[inline]
fn theta_edge(i: usize) -> f64 {
    let u = i as f64 / N_U as f64;
    u * u * FRAC_PI_2
}

#[inline]
fn bin_of(wo: DVec3) -> usize {
    let t = crate::math::safe_acos(wo.z);
    ((t / FRAC_PI_2 * N_THETA_O as f64) as usize).min(N_THETA_O - 1)
}

/// `(cos φo, sin φo)`.
#[inline]
fn azimuth(wo: DVec3) -> (f64, f64) {
    crate::math::cos_sin_phi(wo)
}

/// Index of the first entry of `cdf` that is `> u` (at most `len − 1`).
fn find(cdf: &[f64], u: f64) -> usize {
    let i = cdf.partition_point(|&c| c <= u);
    i.min(cdf.len() - 1)
}

impl HalfVectorTable {
    /// Build the tables from `f(wo, wi)` (no cosine).
    pub fn build(f: impl Fn(DVec3, DVec3) -> Rgb + Sync) -> HalfVectorTable {
        let per_bin = |k: usize| -> (Vec<f32>, Vec<f64>, Vec<f64>, f32) {
            let t = (k as f64 + 0.5) / N_THETA_O as f64 * FRAC_PI_2;
            let wo = DVec3::new(t.sin(), 0.0, t.cos());
            let mut w = vec![0f64; N_U * N_V];
            for iu in 0..N_U {
                let (z0, z1) = (theta_edge(iu).cos(), theta_edge(iu + 1).cos());
                let omega = (z0 - z1) * TAU / N_V as f64;
                for iv in 0..N_V {
                    let mut s = 0.0;
                    for a in 0..3 {
                        let z = z0 - (a as f64 + 0.5) / 3.0 * (z0 - z1);
                        let r = crate::math::safe_sqrt(1.0 - z * z);
                        for b in 0..3 {
                            let phi = (iv as f64 + (b as f64 + 0.5) / 3.0) / N_V as f64 * TAU;
                            let h = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                            let c = wo.dot(h);
                            let wi = crate::math::reflect(wo, h);
                            if wi.z <= 0.0 || c <= 0.0 {
                                continue;
                            }
                            let v = crate::math::luminance(f(wo, wi.normalize())) * wi.z * 4.0 * c;
                            if v.is_finite() && v > 0.0 {
                                s += v;
                            }
                        }
                    }
                    w[iu * N_V + iv] = s / 9.0 * omega;
                }
            }
            let total: f64 = w.iter().sum();
            let mut density = vec![0f32; N_U * N_V];
            let mut row_cdf = vec![0f64; N_U];
            let mut col_cdf = vec![0f64; N_U * N_V];
            let mut acc_rows = 0.0;
            for iu in 0..N_U {
                let (z0, z1) = (theta_edge(iu).cos(), theta_edge(iu + 1).cos());
                let omega = (z0 - z1) * TAU / N_V as f64;
                let row = &w[iu * N_V..(iu + 1) * N_V];
                let row_sum: f64 = row.iter().sum();
                let mut acc = 0.0;
                for iv in 0..N_V {
                    acc += row[iv];
                    col_cdf[iu * N_V + iv] = if row_sum > 0.0 {
                        (acc / row_sum).min(1.0)
                    } else {
                        (iv + 1) as f64 / N_V as f64
                    };
                    if total > 0.0 {
                        density[iu * N_V + iv] = (row[iv] / total / omega) as f32;
                    }
                }
                col_cdf[iu * N_V + N_V - 1] = 1.0;
                acc_rows += row_sum;
                row_cdf[iu] = if total > 0.0 { (acc_rows / total).min(1.0) } else { 0.0 };
            }
            if total > 0.0 {
                row_cdf[N_U - 1] = 1.0;
            }
            (density, row_cdf, col_cdf, total as f32)
        };
        #[cfg(feature = "parallel")]
        let bins: Vec<_> = {
            use rayon::prelude::*;
            (0..N_THETA_O).into_par_iter().map(per_bin).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let bins: Vec<_> = (0..N_THETA_O).map(per_bin).collect();
        let mut t = HalfVectorTable {
            density: Vec::with_capacity(N_THETA_O * N_U * N_V),
            row_cdf: Vec::with_capacity(N_THETA_O * N_U),
            col_cdf: Vec::with_capacity(N_THETA_O * N_U * N_V),
            albedo: Vec::with_capacity(N_THETA_O),
        };
        for (d, r, c, a) in bins {
            t.density.extend(d);
            t.row_cdf.extend(r);
            t.col_cdf.extend(c);
            t.albedo.push(a);
        }
        t
    }

    /// Bytes held.
    #[must_use]
    pub fn memory(&self) -> usize {
        4 * (self.density.len() + self.albedo.len()) + 8 * (self.row_cdf.len() + self.col_cdf.len())
    }

    /// The albedo (luminance) of the bin of `wo`.
    #[must_use]
    pub fn albedo(&self, wo: DVec3) -> f64 {
        f64::from(self.albedo[bin_of(wo)])
    }

    /// Draw `wi` for `wo` (`wo.z > 0`); `None` for a lost sample.
    #[must_use]
    pub fn sample(&self, wo: DVec3, u: DVec2) -> Option<DVec3> {
        if u.x < COSINE_SHARE {
            let wi = warp::square_to_cosine_hemisphere(DVec2::new(u.x / COSINE_SHARE, u.y));
            return (wi.z > 0.0).then_some(wi);
        }
        let ux = ((u.x - COSINE_SHARE) / (1.0 - COSINE_SHARE)).min(1.0);
        let h = self.sample_half(wo, DVec2::new(ux, u.y))?;
        let wi = crate::math::reflect(wo, h);
        if wi.z <= 0.0 {
            return None;
        }
        Some(wi.normalize())
    }

    /// The tabulated branch alone: a half vector for `wo` (in the world's
    /// azimuth), `None` when the table of `wo`'s bin is empty.
    #[must_use]
    pub fn sample_half(&self, wo: DVec3, u: DVec2) -> Option<DVec3> {
        let k = bin_of(wo);
        let rows = &self.row_cdf[k * N_U..(k + 1) * N_U];
        if rows[N_U - 1] <= 0.0 {
            return None;
        }
        let iu = find(rows, u.x);
        let r0 = if iu > 0 { rows[iu - 1] } else { 0.0 };
        let r1 = rows[iu];
        let a = if r1 > r0 { ((u.x - r0) / (r1 - r0)).clamp(0.0, 1.0) } else { 0.5 };
        let cols = &self.col_cdf[(k * N_U + iu) * N_V..(k * N_U + iu + 1) * N_V];
        let iv = find(cols, u.y);
        let c0 = if iv > 0 { cols[iv - 1] } else { 0.0 };
        let c1 = cols[iv];
        let b = if c1 > c0 { ((u.y - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.5 };
        let (z0, z1) = (theta_edge(iu).cos(), theta_edge(iu + 1).cos());
        let z = z0 - a * (z0 - z1);
        let r = crate::math::safe_sqrt(1.0 - z * z);
        let phi = (iv as f64 + b) / N_V as f64 * TAU;
        let (cp, sp) = azimuth(wo);
        let (x, y) = (r * phi.cos(), r * phi.sin());
        Some(DVec3::new(cp * x - sp * y, sp * x + cp * y, z))
    }

    /// The cell `(iu, iv)` of a half vector `h` for `wo`: `iu` over
    /// `√(θh/(π/2))`, `iv` over `φh − φo`.
    #[must_use]
    pub fn cell_of(wo: DVec3, h: DVec3) -> (usize, usize) {
        let theta = crate::math::safe_acos(h.z);
        let iu = (((theta / FRAC_PI_2).max(0.0).sqrt() * N_U as f64) as usize).min(N_U - 1);
        let (cp, sp) = azimuth(wo);
        let x = cp * h.x + sp * h.y;
        let y = -sp * h.x + cp * h.y;
        let phi = y.atan2(x).rem_euclid(TAU);
        let iv = ((phi / TAU * N_V as f64) as usize).min(N_V - 1);
        (iu, iv)
    }

    /// The probability of cell `(iu, iv)` in the tabulated branch for `wo`.
    #[must_use]
    pub fn cell_probability(&self, wo: DVec3, iu: usize, iv: usize) -> f64 {
        let (z0, z1) = (theta_edge(iu).cos(), theta_edge(iu + 1).cos());
        let omega = (z0 - z1) * TAU / N_V as f64;
        f64::from(self.density[(bin_of(wo) * N_U + iu) * N_V + iv]) * omega
    }

    /// The solid-angle density of `sample` at `wi` (both above the horizon).
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        let cosine = COSINE_SHARE * warp::square_to_cosine_hemisphere_pdf(wi);
        let sum = wo + wi;
        let len = sum.length();
        if len <= 0.0 {
            return cosine;
        }
        let h = sum / len;
        let c = wo.dot(h);
        if c <= 0.0 {
            return cosine;
        }
        let (iu, iv) = Self::cell_of(wo, h);
        let k = bin_of(wo);
        let d = f64::from(self.density[(k * N_U + iu) * N_V + iv]);
        (1.0 - COSINE_SHARE) * d / (4.0 * c) + cosine
    }
}


#[cfg(all(test, feature = "stats"))]
mod tests {
    use super::*;
    use crate::stats::chi2::{Chi2Settings, chi2_test_cells};
    use crate::stats::quadrature::Estimate;

    fn glossy() -> crate::Material {
        crate::Material::with_diffuse(
            Rgb::ZERO,
            crate::Glossy::CookTorrance(
                crate::models::CookTorrance::new(
                    Rgb::ONE,
                    crate::Microfacet::new(crate::Ndf::Ggx, 0.1, 0.1).unwrap(),
                    crate::Shadowing::SmithCorrelated,
                    crate::Fresnel::None,
                )
                .unwrap(),
            ),
        )
        .unwrap()
    }

    /// Chi-square of the tabulated branch in its own cells, with their
    /// exact probabilities: a half vector of cell `(iu, iv)` is binned as
    /// the direction `z = 1 − √(θh/(π/2))`, `φ = φh − φo`, so that the test's
    /// `2 N_U × N_V` equal-area cells are the table's cells one for one.
    #[test]
    fn chi2_of_the_half_vector_cells_is_exact() {
        let m = glossy();
        // Not symmetric in φ, with holes.
        let t = HalfVectorTable::build(|o, i| {
            let bump = 1.0 + 0.8 * (5.0 * i.y.atan2(i.x)).sin();
            let hole = if (i.x * 40.0).floor() as i64 % 7 == 0 { 0.0 } else { 1.0 };
            m.eval(o, i) * bump * hole
        });
        let cfg = Chi2Settings {
            n_z: 2 * N_U,
            n_phi: N_V,
            samples: 1_000_000,
            ..Chi2Settings::default()
        };
        let alpha = crate::stats::chi2::sidak(0.01, 4);
        for theta in [0.0f64, 20.0, 55.0, 85.0] {
            let t0 = theta.to_radians();
            let wo = DVec3::new(t0.sin() * 0.6, t0.sin() * 0.8, t0.cos());
            let r = chi2_test_cells(
                &cfg,
                |_, u| {
                    let h = t.sample_half(wo, u)?;
                    let u_h = (crate::math::safe_acos(h.z) / FRAC_PI_2).sqrt();
                    let (cp, sp) = azimuth(wo);
                    let phi = (-sp * h.x + cp * h.y).atan2(cp * h.x + sp * h.y).rem_euclid(TAU);
                    let z = 1.0 - u_h;
                    let r = crate::math::safe_sqrt(1.0 - z * z);
                    Some(DVec3::new(r * phi.cos(), r * phi.sin(), z))
                },
                |z0, z1, p0, _| {
                    let value = if z0 < 0.0 {
                        0.0
                    } else {
                        let iu = ((1.0 - z1) * N_U as f64).round() as usize;
                        let iv = (p0 / TAU * N_V as f64).round() as usize;
                        t.cell_probability(wo, iu.min(N_U - 1), iv.min(N_V - 1))
                    };
                    Estimate { value, error: 0.0, evals: 1, converged: true }
                },
            );
            eprintln!("half-vector cells, θo={theta}: χ² = {:.1}, dof {}, p = {:.3}", r.statistic, r.dof, r.p_value);
            assert!(r.passes(alpha), "θo={theta}: p = {:.3e} {:?}", r.p_value, r.message);
        }
    }
}
