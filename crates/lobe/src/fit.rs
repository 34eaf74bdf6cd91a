//! Fit an analytic material to a measured one (`lobe fit`).
//!
//! The model is Cook-Torrance (GGX or Beckmann, Smith height-correlated
//! shadowing, `ks = 1`) plus a Lambertian `kd`, with ([`FitSettings`]):
//! * an isotropic `alpha`, or (`anisotropic`) `alpha_u` along the tangent
//!   x and `alpha_v` along y;
//! * a Schlick Fresnel term with an RGB `f0`, or (`FresnelFit::Conductor`)
//!   the exact conductor Fresnel term of an RGB complex index `eta + i k`.
//!
//! Seven numbers (isotropic Schlick) to eleven (anisotropic conductor). The
//! error is the cosine-weighted log-space L2 distance over the entries of
//! the target, taken at the centres of a subset of MERL's (θh, θd, φd)
//! entries (every θh, every 6th θd, every 12th φd: 20 250 pairs, those with
//! both directions above the horizon and a non-zero target kept):
//!
//! `E = Σ_k cos θi Σ_c [ln(1 + f̂_c cos θi) − ln(1 + f_c cos θi)]² / (3 Σ_k cos θi)`
//!
//! (`f̂` the model, `f` the target, both without the cosine), minimised by
//! Nelder-Mead over `(ln α, logit f0 | ln eta, ln k, logit kd)`: first on
//! every 8th pair from up to three starts (each refined once by a
//! restart; the starts stop early at an exact fit, `E < 1e-11`), then on
//! every pair from the best of them.
//!
//! MERL's entries all have the half vector in the plane `φh = 0`, which
//! says nothing about anisotropy: for an anisotropic fit, pair `k` is turned
//! about the normal by `k` times the golden angle, so that the pairs cover
//! every azimuth of the half vector. The tables lobe reads (MERL, and RGL
//! files, which lobe reads when isotropic only) are isotropic: their
//! anisotropic fit is `alpha_u ≈ alpha_v`; an anisotropic target (any
//! [`Material`]) gives its two alphas.

use crate::fresnel::Fresnel;
use crate::math::Rgb;
use crate::microfacet::{Microfacet, Ndf, Shadowing};
use crate::models::CookTorrance;
use crate::models::measured::merl;
use crate::{Glossy, Material};
use glam::DVec3;

/// The Fresnel term a fit has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FresnelFit {
    /// Schlick's approximation with an RGB `f0` in `[0, 1]`.
    #[default]
    Schlick,
    /// The exact conductor term of `eta + i k` (RGB each; `eta` in
    /// `[0.01, 20]`, `k` in `[1e-4, 50]`).
    Conductor,
}

impl FresnelFit {
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            FresnelFit::Schlick => "schlick",
            FresnelFit::Conductor => "conductor",
        }
    }
}

impl std::str::FromStr for FresnelFit {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "schlick" => Ok(FresnelFit::Schlick),
            "conductor" => Ok(FresnelFit::Conductor),
            other => Err(crate::Error::UnknownName {
                field: "fresnel".into(),
                value: other.into(),
                expected: "schlick, conductor".into(),
            }),
        }
    }
}

/// What is fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FitSettings {
    /// GGX or Beckmann.
    pub distribution: Ndf,
    pub fresnel: FresnelFit,
    /// `alpha_u` and `alpha_v` (otherwise one `alpha`).
    pub anisotropic: bool,
}

impl Default for FitSettings {
    /// GGX, Schlick, isotropic.
    fn default() -> Self {
        FitSettings {
            distribution: Ndf::Ggx,
            fresnel: FresnelFit::Schlick,
            anisotropic: false,
        }
    }
}

/// A fitted material.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    pub settings: FitSettings,
    /// `alpha_u` (= `alpha_v` unless anisotropic).
    pub alpha_u: f64,
    pub alpha_v: f64,
    /// `Fresnel::Schlick { f0 }` or `Fresnel::Conductor { eta, k }`.
    pub fresnel: Fresnel,
    pub kd: Rgb,
    /// The error `E` at the fit.
    pub error: f64,
    /// Error evaluations spent, in evaluations over every pair (one over
    /// the coarse subset counts 1/8).
    pub evaluations: usize,
    /// Pairs the error sums over.
    pub pairs: usize,
}

impl Fit {
    /// The fitted material.
    pub fn material(&self) -> crate::error::Result<Material> {
        model(
            self.settings.distribution,
            self.alpha_u,
            self.alpha_v,
            self.fresnel,
            self.kd,
        )
    }

    /// `alpha` of an isotropic fit (`√(alpha_u alpha_v)` otherwise).
    #[must_use]
    pub fn alpha(&self) -> f64 {
        (self.alpha_u * self.alpha_v).sqrt()
    }

    /// The fit as `lobe fit --json` prints it: `material` (as
    /// [`Fit::to_json`]), `error`, `pairs`, `evaluations`, and `seconds`
    /// where given.
    #[must_use]
    pub fn report_json(&self, seconds: Option<f64>) -> String {
        let seconds = seconds.map_or(String::new(), |s| format!(r#","seconds":{s:.3}"#));
        format!(
            r#"{{"material":{},"error":{:e},"pairs":{},"evaluations":{}{seconds}}}"#,
            self.to_json(),
            self.error,
            self.pairs,
            self.evaluations
        )
    }

    /// The material as `--material` accepts it (JSON).
    #[must_use]
    pub fn to_json(&self) -> String {
        let c = |v: Rgb| format!("[{:.6},{:.6},{:.6}]", v.x, v.y, v.z);
        let alpha = if self.settings.anisotropic {
            format!(
                r#""alpha_u":{:.6},"alpha_v":{:.6}"#,
                self.alpha_u, self.alpha_v
            )
        } else {
            format!(r#""alpha":{:.6}"#, self.alpha_u)
        };
        let fresnel = match self.fresnel {
            Fresnel::Conductor { eta, k } => {
                format!(r#"{{"type":"conductor","eta":{},"k":{}}}"#, c(eta), c(k))
            }
            Fresnel::Schlick { f0 } => format!(r#"{{"type":"schlick","f0":{}}}"#, c(f0)),
            _ => unreachable!("fits are Schlick or conductor"),
        };
        format!(
            r#"{{"type":"cook-torrance","distribution":"{}",{alpha},"shadowing":"smith-correlated","kd":{},"fresnel":{fresnel}}}"#,
            self.settings.distribution.name(),
            c(self.kd),
        )
    }
}

fn model(ndf: Ndf, au: f64, av: f64, fresnel: Fresnel, kd: Rgb) -> crate::error::Result<Material> {
    let lobe = CookTorrance::new(
        Rgb::ONE,
        Microfacet::new(ndf, au, av)?,
        Shadowing::SmithCorrelated,
        fresnel,
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

impl Target {
    /// Every `n`-th pair.
    fn every(&self, n: usize) -> Target {
        Target {
            pairs: self.pairs.iter().copied().step_by(n).collect(),
            log_f: self.log_f.iter().copied().step_by(n).collect(),
            weight: self.weight.iter().copied().step_by(n).collect(),
        }
    }
}

fn target(m: &Material, turn: bool) -> Target {
    let mut t = Target {
        pairs: Vec::new(),
        log_f: Vec::new(),
        weight: Vec::new(),
    };
    // The golden angle, in radians.
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut k = 0u32;
    for ih in 0..merl::N_THETA_H {
        for id in (0..merl::N_THETA_D).step_by(6) {
            for ip in (0..merl::N_PHI_D).step_by(12) {
                let (mut wo, mut wi) = merl::centre(ih, id, ip);
                if wo.z <= 0.0 || wi.z <= 0.0 {
                    continue;
                }
                if turn {
                    let (s, c) = (f64::from(k) * golden).sin_cos();
                    let r = |v: DVec3| DVec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
                    (wo, wi) = (r(wo), r(wi));
                    k += 1;
                }
                let f = m.eval(wo, wi);
                if crate::math::luminance(f).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
                    || !f.is_finite()
                {
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

/// `(alpha_u, alpha_v, fresnel, kd)` of a point of the search space:
/// `ln alpha_u [, ln alpha_v]`, then `logit f0` (3) or `ln eta`, `ln k`
/// (3 + 3), then `logit kd` (3).
fn params(o: FitSettings, x: &[f64]) -> (f64, f64, Fresnel, Rgb) {
    let a = |v: f64| v.exp().clamp(1e-3, 1.0);
    let au = a(x[0]);
    let (av, i) = if o.anisotropic { (a(x[1]), 2) } else { (au, 1) };
    let rgb = |f: &dyn Fn(f64) -> f64, j: usize| Rgb::new(f(x[j]), f(x[j + 1]), f(x[j + 2]));
    let (fresnel, i) = match o.fresnel {
        FresnelFit::Schlick => (
            Fresnel::Schlick {
                f0: rgb(&sigmoid, i),
            },
            i + 3,
        ),
        FresnelFit::Conductor => (
            Fresnel::Conductor {
                eta: rgb(&|v: f64| v.exp().clamp(0.01, 20.0), i),
                k: rgb(&|v: f64| v.exp().clamp(1e-4, 50.0), i + 3),
            },
            i + 6,
        ),
    };
    (au, av, fresnel, rgb(&sigmoid, i))
}

/// The start of the search space for `alpha`, a Fresnel guess (`f0`, or
/// `(eta, k)`) and `kd`.
fn start(o: FitSettings, alpha: f64, f0: f64, eta_k: (f64, f64), kd: f64) -> Vec<f64> {
    let mut x = vec![alpha.ln()];
    if o.anisotropic {
        x.push(alpha.ln());
    }
    match o.fresnel {
        FresnelFit::Schlick => x.extend([logit(f0); 3]),
        FresnelFit::Conductor => {
            x.extend([eta_k.0.ln(); 3]);
            x.extend([eta_k.1.ln(); 3]);
        }
    }
    x.extend([logit(kd); 3]);
    x
}

/// The coarse search runs on every `COARSE`-th pair.
const COARSE: usize = 8;

/// Pairs per chunk of the error's sum.
const CHUNK: usize = 2048;

/// The search stops below this error: an exact fit (a tabulated analytic
/// material), whose parameters are then within about 1e-5 relative.
const EXACT: f64 = 1e-11;

fn error(t: &Target, o: FitSettings, x: &[f64]) -> f64 {
    let (au, av, fresnel, kd) = params(o, x);
    let Ok(m) = model(o.distribution, au, av, fresnel, kd) else {
        return f64::INFINITY;
    };
    // Sums over fixed chunks, added in order: the same number whatever the
    // thread count.
    let chunk = |k: usize| -> (f64, f64) {
        let (a, b) = (k * CHUNK, ((k + 1) * CHUNK).min(t.pairs.len()));
        let mut sum = 0.0;
        let mut wsum = 0.0;
        for i in a..b {
            let (wo, wi) = t.pairs[i];
            let (lf, w) = (t.log_f[i], t.weight[i]);
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
        (sum, wsum)
    };
    let chunks = t.pairs.len().div_ceil(CHUNK);
    #[cfg(feature = "parallel")]
    let parts: Vec<(f64, f64)> = {
        use rayon::prelude::*;
        (0..chunks).into_par_iter().map(chunk).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let parts: Vec<(f64, f64)> = (0..chunks).map(chunk).collect();
    let (sum, wsum) = parts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let e = sum / (3.0 * wsum);
    if e.is_finite() { e } else { f64::INFINITY }
}

/// Nelder-Mead (reflection 1, expansion 2, contraction ½, shrink ½) from
/// `x0` with initial steps `step`; stops when the simplex's values differ
/// by less than `tol` relative or `abs` absolute, or after `max_evals`.
fn nelder_mead(
    f: &mut impl FnMut(&[f64]) -> f64,
    x0: &[f64],
    step: f64,
    tol: f64,
    abs: f64,
    max_evals: usize,
) -> (Vec<f64>, f64, usize) {
    let n = x0.len();
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    simplex.push((x0.to_vec(), f(x0)));
    for i in 0..n {
        let mut x = x0.to_vec();
        x[i] += step;
        let v = f(&x);
        simplex.push((x, v));
    }
    let mut evals = n + 1;
    let lerp = |a: &[f64], b: &[f64], t: f64| -> Vec<f64> {
        a.iter().zip(b).map(|(a, b)| a + t * (b - a)).collect()
    };
    while evals < max_evals {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (simplex[n].1 - simplex[0].1).abs() <= tol * simplex[0].1.abs() + abs
            || simplex[0].1 < EXACT
        {
            break;
        }
        let mut centroid = vec![0.0; n];
        for (x, _) in &simplex[..n] {
            for i in 0..n {
                centroid[i] += x[i] / n as f64;
            }
        }
        let worst = simplex[n].clone();
        let xr = lerp(&centroid, &worst.0, -1.0);
        let fr = f(&xr);
        evals += 1;
        if fr < simplex[0].1 {
            let xe = lerp(&centroid, &worst.0, -2.0);
            let fe = f(&xe);
            evals += 1;
            simplex[n] = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let xc = if fr < worst.1 {
                lerp(&centroid, &worst.0, -0.5)
            } else {
                lerp(&centroid, &worst.0, 0.5)
            };
            let fc = f(&xc);
            evals += 1;
            if fc < worst.1.min(fr) {
                simplex[n] = (xc, fc);
            } else {
                let best = simplex[0].0.clone();
                for s in simplex.iter_mut().skip(1) {
                    s.0 = lerp(&best, &s.0, 0.5);
                    s.1 = f(&s.0);
                }
                evals += n;
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (x, v) = simplex.swap_remove(0);
    (x, v, evals)
}

/// Fit Cook-Torrance with `distribution` (GGX or Beckmann), a Schlick
/// Fresnel term, one alpha and a Lambertian term to `target` (any
/// material; a measured one in practice): [`fit`] with those settings.
pub fn fit_cook_torrance(
    target_material: &Material,
    distribution: Ndf,
) -> crate::error::Result<Fit> {
    fit(
        target_material,
        FitSettings {
            distribution,
            ..FitSettings::default()
        },
    )
}

/// Fit Cook-Torrance + Lambert with `settings` to `target_material` (any
/// material; a measured one in practice). Errors: the Blinn-Phong NDF, a
/// target that reflects nothing at the fitting pairs.
pub fn fit(target_material: &Material, settings: FitSettings) -> crate::error::Result<Fit> {
    if settings.distribution == Ndf::BlinnPhong {
        return Err(crate::Error::UnknownName {
            field: "distribution".into(),
            value: "blinn-phong".into(),
            expected: "ggx, beckmann".into(),
        });
    }
    let full = target(target_material, settings.anisotropic);
    if full.pairs.is_empty() {
        return Err(crate::Error::param(
            "material",
            "the target reflects nothing at any of the fitting pairs",
        ));
    }
    let coarse = full.every(COARSE);
    let mut evaluations = 0.0;
    let dims = start(settings, 0.3, 0.5, (1.0, 1.0), 0.3).len();
    let max_evals = 200 * dims + 100;
    // Coarse: the starts on every COARSE-th pair.
    let mut best: Option<(Vec<f64>, f64)> = None;
    {
        let mut f = |x: &[f64]| error(&coarse, settings, x);
        // (alpha, f0, (eta, k), kd): a rough plastic, a glossy metal, a matte one.
        for (alpha, f0, eta_k, kd) in [
            (0.3, 0.5, (1.0, 2.0), 0.3),
            (0.05, 0.9, (0.3, 3.0), 0.05),
            (0.7, 0.1, (1.5, 0.5), 0.6),
        ] {
            let x0 = start(settings, alpha, f0, eta_k, kd);
            // Two rounds: restart from the best point with a fresh simplex.
            let (x1, _, e1) = nelder_mead(&mut f, &x0, 0.5, 1e-6, 1e-9, max_evals);
            let (x2, v2, e2) = nelder_mead(&mut f, &x1, 0.1, 1e-8, 1e-14, max_evals);
            evaluations += (e1 + e2) as f64 / COARSE as f64;
            if best.as_ref().is_none_or(|(_, v)| v2 < *v) {
                best = Some((x2, v2));
            }
            // An exact fit: the other starts cannot do better.
            if best.as_ref().is_some_and(|(_, v)| *v < EXACT) {
                break;
            }
        }
    }
    // Fine: every pair, from the coarse fit.
    let (x0, _) = best.expect("three starts");
    let mut f = |x: &[f64]| error(&full, settings, x);
    let (x, e, n) = nelder_mead(&mut f, &x0, 0.05, 1e-8, 1e-14, max_evals);
    evaluations += n as f64;
    let (alpha_u, alpha_v, fresnel, kd) = params(settings, &x);
    Ok(Fit {
        settings,
        alpha_u,
        alpha_v,
        fresnel,
        kd,
        error: e,
        evaluations: evaluations.round() as usize,
        pairs: full.pairs.len(),
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
