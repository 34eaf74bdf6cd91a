//! The white furnace: the directional albedo `∫ f |cos θi| dωi` of a
//! microfacet material against `θo` and `α`, without energy compensation,
//! with each kind of it, and by Heitz et al.'s random walk (the reference
//! with every bounce; conductors and dielectrics), per RGB channel (`lobe furnace`). A
//! rough dielectric's is `R + T` over the whole sphere, in importance mode
//! (the energy it passes on); a rough plastic's is the coating's reflection
//! and what its base sends back through it.
//!
//! The albedos of the models are adaptive quadratures of `eval` over half
//! the hemisphere (the cells are isotropic and `wo` is at `φ = 0`, so
//! `f` is even in `φ`; relative tolerance [`TOLERANCE`]); the random walk's is the mean weight of
//! `walks` walks with its standard error, from a stream of its own per
//! cell, so the table is the same for any thread count.

use crate::energy::{Compensation, RandomWalk, random_walk::RgbEstimate};
use crate::progress::Progress;
use crate::stats::quadrature::{Tolerance, integrate_sphere_region};
use crate::{Error, Glossy, Material, MaterialDesc, Rgb};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// Relative tolerance of the quadratures.
pub const TOLERANCE: f64 = 1e-4;

/// Largest `θo` in degrees (the horizon itself has no albedo).
pub const MAX_THETA: f64 = 89.9;

/// What to compute.
#[derive(Debug, Clone, PartialEq)]
pub struct FurnaceSettings {
    /// `θo` in degrees, each in `[0, MAX_THETA]`.
    pub thetas: Vec<f64>,
    /// `α` values, each a width the material accepts.
    pub alphas: Vec<f64>,
    /// Walks per cell of the random walk; 0 for none.
    pub walks: u64,
    pub seed: u64,
}

impl FurnaceSettings {
    /// `lobe furnace`'s defaults: θo from 0° to 85° by 5° and 89°, the eight
    /// `α` of the range, 10⁵ walks per cell.
    #[must_use]
    pub fn standard() -> Self {
        let mut thetas: Vec<f64> = (0..=17).map(|k| 5.0 * f64::from(k)).collect();
        thetas.push(89.0);
        FurnaceSettings {
            thetas,
            alphas: vec![0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.85, 1.0],
            walks: 100_000,
            seed: 1,
        }
    }
}

/// One `(θo, α)` cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FurnaceRow {
    pub theta: f64,
    pub alpha: f64,
    /// The albedo without compensation, with Kulla-Conty's, with
    /// Turquin's.
    pub none: Rgb,
    pub kulla_conty: Rgb,
    pub turquin: Rgb,
    /// The random walk's, with its standard error (`None` without walks,
    /// or for a plastic; a dielectric's, `R + T` in importance mode, is 1).
    pub walk: Option<RgbEstimate>,
}

impl FurnaceRow {
    /// The albedo of compensation `kind`.
    #[must_use]
    pub fn albedo(&self, kind: Compensation) -> Rgb {
        match kind {
            Compensation::None => self.none,
            Compensation::KullaConty => self.kulla_conty,
            Compensation::Turquin => self.turquin,
        }
    }
}

/// The table: rows `α`-major, each `α` over every `θo`.
#[derive(Debug, Clone, PartialEq)]
pub struct Furnace {
    /// The material's `type`.
    pub model: String,
    /// Walks per cell of the random walk (0: none).
    pub walks: u64,
    pub rows: Vec<FurnaceRow>,
}

#[cfg(feature = "desc")]
impl Furnace {
    /// The table as JSON text (`lobe furnace --json`, `lobe.furnace`):
    /// `model`, `walks` and `rows`, each with `theta`, `alpha`, and RGB
    /// triples `none`, `kulla-conty`, `turquin`, `walk`, `walk_std_error`
    /// (the walk's `null` where none ran).
    #[must_use]
    pub fn to_json(&self) -> String {
        use serde_json::json;
        let rgb = |c: Rgb| json!([c.x, c.y, c.z]);
        let rows: Vec<_> = self
            .rows
            .iter()
            .map(|r| {
                json!({
                    "theta": r.theta, "alpha": r.alpha,
                    "none": rgb(r.none), "kulla-conty": rgb(r.kulla_conty), "turquin": rgb(r.turquin),
                    "walk": r.walk.map(|w| rgb(w.mean)),
                    "walk_std_error": r.walk.map(|w| rgb(w.std_error)),
                })
            })
            .collect();
        json!({"model": self.model, "walks": self.walks, "rows": rows}).to_string()
    }
}

/// `∫ f |cos θi| dωi` at `wo` (`φ = 0`) of an isotropic material, per
/// channel: twice the integral over `φ ∈ [0, π]`, over the lower
/// hemisphere too where it transmits.
///
/// The quadrature is adaptive but deterministic: it chooses its nodes from
/// the values it has seen. So if the three channels were equal at every
/// node the red channel's integral visited, the green and blue integrals
/// would visit the same nodes and give the same bits; they are then not
/// computed again (a grey material costs one integral, not three).
fn albedo(m: &Material, wo: DVec3) -> Rgb {
    let below = m.reach().transmits;
    let grey = std::cell::Cell::new(true);
    let channel = |c: usize| {
        let f = |wi: DVec3| {
            let v = m.eval(wo, wi);
            if c == 0 && (v.x.to_bits() != v.y.to_bits() || v.x.to_bits() != v.z.to_bits()) {
                grey.set(false);
            }
            v[c] * wi.z.abs()
        };
        let tol = Tolerance::relative(TOLERANCE).with_initial(32, 32);
        let mut sum = integrate_sphere_region(f, (0.0, FRAC_PI_2), (0.0, PI), tol).value;
        if below {
            sum += integrate_sphere_region(f, (FRAC_PI_2, PI), (0.0, PI), tol).value;
        }
        2.0 * sum
    };
    let red = channel(0);
    if grey.get() {
        Rgb::splat(red)
    } else {
        Rgb::new(red, channel(1), channel(2))
    }
}

/// `desc` at width `alpha` (isotropic) with compensation `kind` (in
/// importance mode where the model has modes).
fn at(desc: &MaterialDesc, alpha: f64, kind: Compensation) -> Result<Material, Error> {
    let mut d = desc.clone();
    d.alpha = Some(alpha);
    (d.alpha_u, d.alpha_v, d.roughness) = (None, None, None);
    d.multiscatter = Some(kind.name().to_string());
    if d.kind == "roughdielectric" {
        d.mode = Some("importance".into());
    }
    d.build()
}

/// The furnace table of `desc` (a `cook-torrance`, `roughconductor`,
/// `roughdielectric` or `roughplastic` description; its `alpha`, `roughness` and
/// `multiscatter` are replaced by each cell's, and a dielectric's `mode` by
/// `importance`). Reports one step per cell to `progress` (after `start`).
/// The error names the setting or key that is wrong.
pub fn furnace(
    desc: &MaterialDesc,
    s: &FurnaceSettings,
    progress: &dyn Progress,
) -> Result<Furnace, Error> {
    if s.thetas.is_empty() || s.alphas.is_empty() {
        return Err(Error::param("theta", "needs at least one θo and one α"));
    }
    if let Some(t) = s
        .thetas
        .iter()
        .find(|t| !(t.is_finite() && (0.0..=MAX_THETA).contains(*t)))
    {
        return Err(Error::param(
            "theta",
            format!("{t} is out of range: θo must be in [0, {MAX_THETA}] degrees"),
        ));
    }
    // Build every material once, so that a bad key or α fails before any work.
    let mut cells = Vec::with_capacity(s.alphas.len());
    for &a in &s.alphas {
        let none = at(desc, a, Compensation::None).map_err(|e| match e {
            Error::Param { field, message } if field == "alpha" => Error::Param {
                field: "alpha".into(),
                message: format!("furnace α {a}: {message}"),
            },
            e => e,
        })?;
        // The random walk where lobe has one.
        let walk = match &none.glossy {
            Glossy::CookTorrance(ct) => {
                Some(RandomWalk::conductor(ct.microfacet, ct.ks, ct.fresnel)?)
            }
            Glossy::RoughDielectric(rd) => Some(RandomWalk::dielectric(rd.microfacet, rd.eta)?),
            Glossy::RoughPlastic(_) => None,
            _ => {
                return Err(Error::param(
                    "type",
                    format!(
                        "the furnace compares energy compensation of microfacet models \
                         (cook-torrance, roughconductor, roughdielectric, roughplastic), not {}",
                        desc.kind
                    ),
                ));
            }
        };
        if none.diffuse.albedo != Rgb::ZERO {
            return Err(Error::param(
                "kd",
                "the furnace measures the microfacet lobe alone: leave kd out",
            ));
        }
        let (kc, tq) = (
            at(desc, a, Compensation::KullaConty)?,
            at(desc, a, Compensation::Turquin)?,
        );
        cells.push((a, none, kc, tq, walk));
    }
    let nt = s.thetas.len();
    progress.start("furnace", (s.alphas.len() * nt) as u64);
    let rows = crate::parallel::map_indices(s.alphas.len() * nt, |k| {
        let (a, none, kc, tq, walk) = &cells[k / nt];
        let theta = s.thetas[k % nt];
        let wo = crate::frame::wo_from_theta(theta, 0.0);
        let row = FurnaceRow {
            theta,
            alpha: *a,
            none: albedo(none, wo),
            kulla_conty: albedo(kc, wo),
            turquin: albedo(tq, wo),
            walk: walk
                .as_ref()
                .filter(|_| s.walks > 0)
                .map(|w| w.albedo(wo, s.walks, s.seed, k)),
        };
        progress.advance(1);
        row
    });
    Ok(Furnace {
        model: desc.kind.clone(),
        walks: s.walks,
        rows,
    })
}
