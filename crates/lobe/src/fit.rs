//! Fit an analytic material to a measured one (`lobe fit`).
//!
//! The model is Cook-Torrance (GGX or Beckmann, Smith height-correlated
//! shadowing, Schlick Fresnel with an RGB `f0`, `ks = 1`) plus a Lambertian
//! `kd`: seven numbers, `alpha`, `f0` and `kd`. The error is the
//! cosine-weighted log-space L2 distance over the entries of the target,
//! taken at the centres of a subset of MERL's (θh, θd, φd) entries (every
//! θh, every 6th θd, every 12th φd: 20 250 pairs, those with both directions
//! above the horizon and a non-zero target kept):
//!
//! `E = Σ_k cos θi Σ_c [ln(1 + f̂_c cos θi) − ln(1 + f_c cos θi)]² / (3 Σ_k cos θi)`
//!
//! (`f̂` the model, `f` the target, both without the cosine), minimised by
//! Nelder-Mead over `(ln α, logit f0, logit kd)` from up to three starts
//! (each refined once by a restart), the best kept; the starts stop early
//! at `E < 1e-12`.

use crate::fresnel::Fresnel;
use crate::math::Rgb;
use crate::microfacet::{Microfacet, Ndf, Shadowing};
use crate::models::CookTorrance;
use crate::models::measured::merl;
use crate::{Glossy, Material};
use glam::DVec3;

/// A fitted material.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    pub distribution: Ndf,
    pub alpha: f64,
    pub f0: Rgb,
    pub kd: Rgb,
    /// The error `E` at the fit.
    pub error: f64,
    /// Error evaluations spent.
    pub evaluations: usize,
    /// Pairs the error sums over.
    pub pairs: usize,
}

impl Fit {
    /// The fitted material.
    pub fn material(&self) -> crate::error::Result<Material> {
        model(self.distribution, self.alpha, self.f0, self.kd)
    }

    /// The material as `--material` accepts it (JSON).
    #[must_use]
    pub fn to_json(&self) -> String {
        let c = |v: Rgb| format!("[{:.6},{:.6},{:.6}]", v.x, v.y, v.z);
        format!(
            r#"{{"type":"cook-torrance","distribution":"{}","alpha":{:.6},"shadowing":"smith-correlated","kd":{},"fresnel":{{"type":"schlick","f0":{}}}}}"#,
            self.distribution.name(),
            self.alpha,
            c(self.kd),
            c(self.f0)
        )
    }
}

fn model(ndf: Ndf, alpha: f64, f0: Rgb, kd: Rgb) -> crate::error::Result<Material> {
    let lobe = CookTorrance::new(
        Rgb::ONE,
        Microfacet::new(ndf, alpha, alpha)?,
        Shadowing::SmithCorrelated,
        Fresnel::Schlick { f0 },
    )?;
    Material::with_diffuse(kd, Glossy::CookTorrance(lobe))
}

/// The pairs the error sums over, with the target's `ln(1 + f cos θi)` and
/// the weight `cos θi`.
struct Target {
    pairs: Vec<(DVec3, DVec3)>,
    log_f: Vec<[f64; 3]>,
    weight: Vec<f64>,
}

fn target(m: &Material) -> Target {
    let mut t = Target {
        pairs: Vec::new(),
        log_f: Vec::new(),
        weight: Vec::new(),
    };
    for ih in 0..merl::N_THETA_H {
        for id in (0..merl::N_THETA_D).step_by(6) {
            for ip in (0..merl::N_PHI_D).step_by(12) {
                let (wo, wi) = merl::centre(ih, id, ip);
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    continue;
                }
                let f = m.eval(wo, wi);
                if !(crate::math::luminance(f) > 0.0) || !f.is_finite() {
                    continue;
                }
                let c = wi.z;
                t.pairs.push((wo, wi));
                t.log_f.push([
                    (1.0 + f.x * c).ln(),
                    (1.0 + f.y * c).ln(),
                    (1.0 + f.z * c).ln(),
                ]);
                t.weight.push(c);
            }
        }
    }
    t
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

fn logit(p: f64) -> f64 {
    let p = p.clamp(1e-6, 1.0 - 1e-6);
    (p / (1.0 - p)).ln()
}

/// `(alpha, f0, kd)` of a point of the search space.
fn params(x: &[f64; 7]) -> (f64, Rgb, Rgb) {
    (
        x[0].exp().clamp(1e-3, 1.0),
        Rgb::new(sigmoid(x[1]), sigmoid(x[2]), sigmoid(x[3])),
        Rgb::new(sigmoid(x[4]), sigmoid(x[5]), sigmoid(x[6])),
    )
}

fn error(t: &Target, ndf: Ndf, x: &[f64; 7]) -> f64 {
    let (alpha, f0, kd) = params(x);
    let Ok(m) = model(ndf, alpha, f0, kd) else {
        return f64::INFINITY;
    };
    let mut sum = 0.0;
    let mut wsum = 0.0;
    for ((&(wo, wi), lf), &w) in t.pairs.iter().zip(&t.log_f).zip(&t.weight) {
        let f = m.eval(wo, wi);
        let c = wi.z;
        let d = [
            (1.0 + f.x * c).ln() - lf[0],
            (1.0 + f.y * c).ln() - lf[1],
            (1.0 + f.z * c).ln() - lf[2],
        ];
        sum += w * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        wsum += w;
    }
    sum / (3.0 * wsum)
}

/// Nelder-Mead (reflection 1, expansion 2, contraction ½, shrink ½) from
/// `x0` with initial steps `step`; stops when the simplex's values differ
/// by less than `tol` relative or `abs` absolute, or after `max_evals`.
fn nelder_mead(
    f: &mut impl FnMut(&[f64; 7]) -> f64,
    x0: [f64; 7],
    step: f64,
    tol: f64,
    abs: f64,
    max_evals: usize,
) -> ([f64; 7], f64, usize) {
    let mut simplex: Vec<([f64; 7], f64)> = Vec::with_capacity(8);
    simplex.push((x0, f(&x0)));
    for i in 0..7 {
        let mut x = x0;
        x[i] += step;
        simplex.push((x, f(&x)));
    }
    let mut evals = 8;
    let lerp = |a: &[f64; 7], b: &[f64; 7], t: f64| {
        let mut r = [0.0; 7];
        for i in 0..7 {
            r[i] = a[i] + t * (b[i] - a[i]);
        }
        r
    };
    while evals < max_evals {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (simplex[7].1 - simplex[0].1).abs() <= tol * simplex[0].1.abs() + abs {
            break;
        }
        let mut centroid = [0.0; 7];
        for (x, _) in &simplex[..7] {
            for i in 0..7 {
                centroid[i] += x[i] / 7.0;
            }
        }
        let worst = simplex[7];
        let xr = lerp(&centroid, &worst.0, -1.0);
        let fr = f(&xr);
        evals += 1;
        if fr < simplex[0].1 {
            let xe = lerp(&centroid, &worst.0, -2.0);
            let fe = f(&xe);
            evals += 1;
            simplex[7] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[6].1 {
            simplex[7] = (xr, fr);
        } else {
            let xc = if fr < worst.1 {
                lerp(&centroid, &worst.0, -0.5)
            } else {
                lerp(&centroid, &worst.0, 0.5)
            };
            let fc = f(&xc);
            evals += 1;
            if fc < worst.1.min(fr) {
                simplex[7] = (xc, fc);
            } else {
                let best = simplex[0].0;
                for s in simplex.iter_mut().skip(1) {
                    s.0 = lerp(&best, &s.0, 0.5);
                    s.1 = f(&s.0);
                }
                evals += 7;
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    (simplex[0].0, simplex[0].1, evals)
}

/// Fit Cook-Torrance with `distribution` (GGX or Beckmann) and a Lambertian
/// term to `target` (any material; a measured one in practice).
pub fn fit_cook_torrance(
    target_material: &Material,
    distribution: Ndf,
) -> crate::error::Result<Fit> {
    if distribution == Ndf::BlinnPhong {
        return Err(crate::Error::UnknownName {
            field: "distribution".into(),
            value: "blinn-phong".into(),
            expected: "ggx, beckmann".into(),
        });
    }
    let t = target(target_material);
    if t.pairs.is_empty() {
        return Err(crate::Error::param(
            "material",
            "the target reflects nothing at any of the fitting pairs",
        ));
    }
    let mut f = |x: &[f64; 7]| error(&t, distribution, x);
    let mut best: Option<([f64; 7], f64)> = None;
    let mut evaluations = 0;
    for (alpha, f0, kd) in [(0.3, 0.5, 0.3), (0.05, 0.9, 0.05), (0.7, 0.1, 0.6)] {
        let x0 = [
            f64::ln(alpha),
            logit(f0),
            logit(f0),
            logit(f0),
            logit(kd),
            logit(kd),
            logit(kd),
        ];
        // Two rounds: restart from the best point with a fresh simplex.
        let (x1, _, e1) = nelder_mead(&mut f, x0, 0.5, 1e-6, 1e-9, 1500);
        let (x2, v2, e2) = nelder_mead(&mut f, x1, 0.1, 1e-8, 1e-14, 1500);
        evaluations += e1 + e2;
        if best.is_none_or(|(_, v)| v2 < v) {
            best = Some((x2, v2));
        }
        // An exact fit: the other starts cannot do better.
        if best.is_some_and(|(_, v)| v < 1e-12) {
            break;
        }
    }
    let (x, e) = best.expect("three starts");
    let (alpha, f0, kd) = params(&x);
    Ok(Fit {
        distribution,
        alpha,
        f0,
        kd,
        error: e,
        evaluations,
        pairs: t.pairs.len(),
    })
}

/// `lum(f(wo, wi) cos θi)` in the plane of incidence of the view at
/// `theta_o_deg` (`wo = (sin θo, 0, cos θo)`): `steps + 1` points
/// `(θi in degrees, value)`, `θi` from −90° (the side of the mirror
/// direction) to 90°, `wi = (sin θi, 0, cos θi)`.
#[must_use]
pub fn incidence_plane(m: &Material, theta_o_deg: f64, steps: usize) -> Vec<(f64, f64)> {
    let t = theta_o_deg.to_radians();
    let wo = DVec3::new(t.sin(), 0.0, t.cos());
    (0..=steps.max(1))
        .map(|i| {
            let a = -90.0 + 180.0 * i as f64 / steps.max(1) as f64;
            let r = a.to_radians();
            let wi = DVec3::new(r.sin(), 0.0, r.cos());
            let v = if wi.z > 0.0 {
                crate::math::luminance(m.eval(wo, wi)) * wi.z
            } else {
                0.0
            };
            (a, v)
        })
        .collect()
}
