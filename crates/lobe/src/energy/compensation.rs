//! Energy compensation of a microfacet reflection lobe: the light that a
//! single-scattering model loses between microfacets, given back.
//!
//! | `multiscatter` | what is added | reciprocal | sampling |
//! |---|---|---|---|
//! | `none` | nothing (Mitsuba 3 and pbrt-v4's lobe, bit for bit) | yes | the lobe's |
//! | `kulla-conty` | `f_ms = F_ms (1 − E(μo))(1 − E(μi)) / (π (1 − E_avg))` | yes | the lobe's, or cosine with probability `q(μo)` |
//! | `turquin` | `f · F0 (1 − E(μo)) / E(μo)` | no | the lobe's |
//!
//! `E(μ, α)` and `E_avg(α)` are the albedo and average albedo of the lobe
//! with `F = 1` ([`super::table`]). Kulla and Conty 2017's colour term is
//! `F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg))`, `F_avg = 2 ∫ F(μ) μ dμ`
//! the cosine-weighted average of the lobe's reflectance (tint times
//! Fresnel): light that bounces `k` times is tinted `k` times, so rough
//! coloured metals gain saturation. Turquin 2019 scales the lobe by
//! `1 + F0 (1 − E)/E`, `F0` the reflectance at normal incidence. With
//! `F = 1` both reflect `E(μo) + 1 − E(μo)`: all of a white furnace.
//!
//! An anisotropic lobe is compensated with the tables of `α = √(αu αv)`
//! (the tables are isotropic): approximate, and said where the key is.

use super::table::{AlbedoRow, AlbedoTable};
use crate::math::{INV_PI, Rgb, luminance};
use glam::{DVec2, DVec3};

/// The value of the material key `multiscatter`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Compensation {
    None,
    KullaConty,
    Turquin,
}

impl Compensation {
    pub const ALL: [Compensation; 3] = [
        Compensation::None,
        Compensation::KullaConty,
        Compensation::Turquin,
    ];
    pub const NAMES: &'static str = "none, kulla-conty, turquin";

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Compensation::None => "none",
            Compensation::KullaConty => "kulla-conty",
            Compensation::Turquin => "turquin",
        }
    }
}

impl std::fmt::Display for Compensation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Compensation {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Compensation::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| crate::Error::UnknownName {
                field: "multiscatter".into(),
                value: s.into(),
                expected: Compensation::NAMES.into(),
            })
    }
}

/// The compensation of one lobe, with what it needs precomputed: a small
/// `Copy` value (its table is `'static`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Multiscatter {
    None,
    KullaConty(KullaConty),
    Turquin(Turquin),
}

impl Multiscatter {
    /// Which compensation this is.
    #[must_use]
    pub fn kind(&self) -> Compensation {
        match self {
            Multiscatter::None => Compensation::None,
            Multiscatter::KullaConty(_) => Compensation::KullaConty,
            Multiscatter::Turquin(_) => Compensation::Turquin,
        }
    }

    /// The compensation `kind` of a lobe of width `alpha` (`√(αu αv)`)
    /// whose reflectance (tint times Fresnel) at cosine `μ` is
    /// `reflectance(μ)`, from `table` (the lobe's distribution and
    /// shadowing term).
    #[must_use]
    pub fn new(
        kind: Compensation,
        table: &'static AlbedoTable,
        alpha: f64,
        reflectance: impl Fn(f64) -> Rgb,
    ) -> Self {
        match kind {
            Compensation::None => Multiscatter::None,
            Compensation::KullaConty => {
                Multiscatter::KullaConty(KullaConty::new(table, alpha, reflectance))
            }
            Compensation::Turquin => Multiscatter::Turquin(Turquin {
                row: table.row(alpha),
                f0: reflectance(1.0),
            }),
        }
    }
}

/// Kulla and Conty's added lobe (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KullaConty {
    /// `E(μ)` at the lobe's `α`.
    row: AlbedoRow,
    /// `F_ms / (π (1 − E_avg))`: the lobe is this times `(1 − E(μo))(1 − E(μi))`.
    scale: Rgb,
    /// The albedo of the added lobe is `ms_albedo (1 − E(μo))`: `F_ms`'s luminance.
    ms_albedo: f64,
}

impl KullaConty {
    #[must_use]
    pub fn new(table: &'static AlbedoTable, alpha: f64, reflectance: impl Fn(f64) -> Rgb) -> Self {
        let e_avg = table.e_avg(alpha);
        let f_avg = cosine_average(reflectance);
        let f_ms = f_avg * f_avg * e_avg / (Rgb::ONE - f_avg * (1.0 - e_avg));
        // Below 1e-9 of lost energy the lobe is nothing (and 1/(1 − E_avg)
        // would only amplify the table's rounding).
        let lost = 1.0 - e_avg;
        let (scale, ms_albedo) = if lost > 1e-9 {
            (f_ms * (INV_PI / lost), luminance(f_ms))
        } else {
            (Rgb::ZERO, 0.0)
        };
        KullaConty {
            row: table.row(alpha),
            scale,
            ms_albedo,
        }
    }

    /// `1 − E(μ)`, at least 0.
    #[inline]
    fn lost(&self, mu: f64) -> f64 {
        (1.0 - self.row.e(mu)).max(0.0)
    }

    /// What the lobe needs of `wo`, looked up once, given the
    /// single-scattering lobe's reflectance there (tint times Fresnel): the
    /// probability of drawing the added lobe by cosine sampling (its share
    /// of the albedo, `ms_albedo (1 − E(μo))` against `E(μo)` times the
    /// luminance of `reflectance`, at most 0.9) and `1 − E(μo)`.
    #[inline]
    #[must_use]
    pub fn at(&self, wo: DVec3, reflectance: Rgb) -> KullaContyAt {
        let lost = if wo.z > 0.0 { self.lost(wo.z) } else { 0.0 };
        let e = 1.0 - lost;
        let ms = self.ms_albedo * lost;
        let single = e * luminance(reflectance);
        let q = if ms > 0.0 {
            (ms / (ms + single.max(0.0))).min(0.9)
        } else {
            0.0
        };
        KullaContyAt { q, lost_o: lost }
    }

    /// The added lobe toward `wi` from the `wo` of `at` (as
    /// [`KullaConty::eval`]).
    #[inline]
    #[must_use]
    pub fn eval_at(&self, at: &KullaContyAt, wi: DVec3) -> Rgb {
        if wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.scale * (at.lost_o * self.lost(wi.z))
    }

    /// The added lobe `f_ms(wo, wi)` (no cosine), zero below the horizon.
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.scale * (self.lost(wo.z) * self.lost(wi.z))
    }

    /// The added lobe's albedo at `wo` (luminance).
    #[must_use]
    pub fn albedo(&self, wo: DVec3) -> f64 {
        self.ms_albedo * self.lost(wo.z)
    }
}

/// Kulla-Conty's lobe at one `wo` ([`KullaConty::at`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KullaContyAt {
    /// The probability of drawing the added lobe by cosine sampling.
    pub q: f64,
    /// `1 − E(μo)` (0 below the horizon).
    lost_o: f64,
}

/// Turquin's scaling (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turquin {
    /// `E(μ)` at the lobe's `α`.
    row: AlbedoRow,
    f0: Rgb,
}

impl Turquin {
    /// `E(μ)` at the lobe's `α` (what the batch kernels tabulate).
    #[must_use]
    pub fn row(&self) -> AlbedoRow {
        self.row
    }

    /// `F0`, the lobe's reflectance at normal incidence (tint times
    /// Fresnel).
    #[must_use]
    pub fn f0(&self) -> Rgb {
        self.f0
    }

    /// The factor `1 + F0 (1 − E(μo)) / E(μo)` of the lobe at `wo`.
    #[inline]
    #[must_use]
    pub fn scale(&self, wo: DVec3) -> Rgb {
        let e = self.row.e(wo.z).max(1e-3);
        Rgb::ONE + self.f0 * ((1.0 - e) / e)
    }
}

/// The compensation of a rough dielectric interface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DielectricMultiscatter {
    None,
    KullaConty(DielectricKullaConty),
    Turquin(DielectricTurquin),
}

impl DielectricMultiscatter {
    /// Which compensation this is.
    #[must_use]
    pub fn kind(&self) -> Compensation {
        match self {
            DielectricMultiscatter::None => Compensation::None,
            DielectricMultiscatter::KullaConty(_) => Compensation::KullaConty,
            DielectricMultiscatter::Turquin(_) => Compensation::Turquin,
        }
    }
}

/// Turquin's scaling of a rough dielectric: reflection and transmission
/// both divided by `E(μo, α, η)`, the single-scattering lobe's `R + T`
/// (exact Fresnel, energy as importance carries it), so that a clear
/// interface passes on all the energy it receives. `E` below
/// [`MIN_DIELECTRIC_E`] (within a degree of the horizon at an interface of
/// nearly matched indices) is taken as that.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricTurquin {
    table: &'static AlbedoTable,
    alpha: f64,
}

/// The smallest `E` a dielectric's scaling divides by.
pub const MIN_DIELECTRIC_E: f64 = 0.01;

/// lobe's built-in dielectric table of `ndf` for an interface of relative
/// index `eta`. The error names `multiscatter`: no table of that
/// distribution, or `η` (either way round) beyond the tables' `[1/3, 3]`.
pub fn dielectric_table(ndf: crate::Ndf, eta: f64) -> crate::error::Result<&'static AlbedoTable> {
    use super::table::{MAX_TABLE_ETA, Surface};
    let table = super::AlbedoTables::builtin()
        .get(ndf, Surface::Dielectric)
        .ok_or_else(|| {
            crate::Error::param(
                "multiscatter",
                format!("no built-in table of a {} dielectric", ndf.name()),
            )
        })?;
    if !(1.0 / MAX_TABLE_ETA..=MAX_TABLE_ETA).contains(&eta) {
        return Err(crate::Error::param(
            "multiscatter",
            format!(
                "the relative index int_ior/ext_ior is {eta}: the dielectric albedo tables \
                 span 1/{MAX_TABLE_ETA} to {MAX_TABLE_ETA}"
            ),
        ));
    }
    Ok(table)
}

impl DielectricTurquin {
    #[must_use]
    pub fn new(table: &'static AlbedoTable, alpha: f64) -> Self {
        DielectricTurquin { table, alpha }
    }

    /// The scaling of an interface of distribution `ndf`, width `alpha`
    /// (`√(αu αv)`) and relative index `eta` from lobe's built-in tables
    /// (the error as [`dielectric_table`]'s).
    pub fn builtin(ndf: crate::Ndf, alpha: f64, eta: f64) -> crate::error::Result<Self> {
        Ok(DielectricTurquin::new(dielectric_table(ndf, eta)?, alpha))
    }

    /// Cosine nodes of its table.
    #[must_use]
    pub fn mu_nodes(&self) -> usize {
        self.table.n_mu
    }

    /// `E(μ, α, η)`, what [`DielectricTurquin::scale`] divides by (at
    /// least [`MIN_DIELECTRIC_E`]).
    #[inline]
    #[must_use]
    pub fn albedo(&self, mu: f64, eta: f64) -> f64 {
        self.table.e_eta(mu, self.alpha, eta)
    }

    /// The factor `1/E(μo, α, η)` at `|cos θo| = mu`, `η` the relative
    /// index of the far side over the side of `wo`.
    #[inline]
    #[must_use]
    pub fn scale(&self, mu: f64, eta: f64) -> f64 {
        1.0 / self.table.e_eta(mu, self.alpha, eta).max(MIN_DIELECTRIC_E)
    }
}

/// Kulla and Conty's lobes for a rough dielectric interface: the light
/// the single-scattering lobe loses from side `s`, `1 − E_s(μo)`, is given
/// back as an added reflection on that side and an added transmission to
/// the other, both of Kelemen's separable shape:
///
/// * reflection: `ρ_s (1 − E_s(μo))(1 − E_s(μi)) / (π A_s)`,
/// * transmission: `τ_s (1 − E_s(μo))(1 − E_s'(μi)) / (π A_s')`,
///
/// `E_s(μ) = E(μ, α, η_s)` the interface's single-scattering `R + T` seen
/// from side `s` (lobe's tables, importance mode), `A_s = 1 − E_avg,s`,
/// `ρ_s + τ_s = 1` so that a clear interface passes on everything from
/// either side. The split follows the average Fresnel transmittance of each
/// side, `T_out = 1 − F_avg(η)` and `T_in = T_out / η²` (the exact relation
/// between the two sides' averages), weighed by the other side's loss:
/// `τ_out = T_out A_in / (A_out + A_in)`, `τ_in = T_in A_out / (A_out + A_in)`.
/// Then `τ_out A_out = η² τ_in A_in`, which is what the generalized
/// reciprocity `f(wo, wi)/η_i² = f(wi, wo)/η_o²` of an importance-mode
/// transmission asks of the added lobes. Light bouncing inside the denser
/// medium mostly reflects back (`τ_in` is small), as total internal
/// reflection makes it. Values here are importance mode and untinted; the
/// model scales transmission for radiance and applies its tints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricKullaConty {
    table: &'static AlbedoTable,
    alpha: f64,
    /// `η = η_inside / η_outside`.
    eta: f64,
    /// `A_out`, `A_in`.
    lost_avg: [f64; 2],
    /// `τ_out`, `τ_in`.
    tau: [f64; 2],
}

/// Below this `A_out + A_in` the interface loses nothing worth giving
/// back (index-matched, or α near zero) and the added lobes are zero.
pub const MIN_DIELECTRIC_LOSS: f64 = 1e-9;

impl DielectricKullaConty {
    /// The lobes of an interface of distribution `ndf`, width `alpha`
    /// (`√(αu αv)`) and relative index `eta` (inside over outside) from
    /// lobe's built-in tables (the error as [`dielectric_table`]'s).
    pub fn builtin(ndf: crate::Ndf, alpha: f64, eta: f64) -> crate::error::Result<Self> {
        let table = dielectric_table(ndf, eta)?;
        let lost = |e: f64| (1.0 - table.e_avg_eta(alpha, e)).clamp(0.0, 1.0);
        let lost_avg = [lost(eta), lost(1.0 / eta)];
        let t_out = 1.0 - crate::fresnel::diffuse_reflectance(eta);
        let t_in = t_out / (eta * eta);
        let sum = lost_avg[0] + lost_avg[1];
        let tau = if sum > MIN_DIELECTRIC_LOSS {
            [t_out * lost_avg[1] / sum, t_in * lost_avg[0] / sum]
        } else {
            [0.0, 0.0]
        };
        Ok(DielectricKullaConty {
            table,
            alpha,
            eta,
            lost_avg,
            tau,
        })
    }

    /// Side index: 0 above the surface, 1 below.
    #[inline]
    fn side(w: DVec3) -> usize {
        usize::from(w.z < 0.0)
    }

    /// `1 − E_s(|cos θ|)` of direction `w` seen from its own side.
    #[inline]
    fn lost(&self, w: DVec3) -> f64 {
        let eta = if w.z >= 0.0 { self.eta } else { 1.0 / self.eta };
        (1.0 - self.table.e_eta(w.z.abs(), self.alpha, eta)).clamp(0.0, 1.0)
    }

    /// The share of the added light from `wo`'s side that is transmitted.
    #[must_use]
    pub fn tau(&self, wo: DVec3) -> f64 {
        self.tau[Self::side(wo)]
    }

    /// The added lobes' albedo at `wo`: `1 − E_s(μo)` (0 where the
    /// interface loses nothing).
    #[inline]
    #[must_use]
    pub fn albedo(&self, wo: DVec3) -> f64 {
        if self.tau == [0.0, 0.0] {
            return 0.0;
        }
        self.lost(wo)
    }

    /// The added lobe toward `wi` (importance mode, untinted, no cosine):
    /// the reflection if `wi` is on `wo`'s side, the transmission if not.
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z == 0.0 || wi.z == 0.0 || self.tau == [0.0, 0.0] {
            return 0.0;
        }
        let (so, si) = (Self::side(wo), Self::side(wi));
        let share = if so == si {
            1.0 - self.tau[so]
        } else {
            self.tau[so]
        };
        let norm = self.lost_avg[si];
        if norm <= 0.0 {
            // That side loses nothing: its 1 − E(μi) is zero too.
            return 0.0;
        }
        share * self.lost(wo) * self.lost(wi) * INV_PI / norm
    }

    /// The density of drawing `wi` by the added lobes' own sampler from
    /// `wo`: reflection with probability `1 − τ`, transmission with `τ`,
    /// each cosine-distributed on its hemisphere.
    #[inline]
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        let t = self.tau(wo);
        let share = if Self::side(wo) == Self::side(wi) {
            1.0 - t
        } else {
            t
        };
        share * wi.z.abs() * INV_PI
    }

    /// Draw from the added lobes: `uc` chooses transmission (`uc < τ`) or
    /// reflection, `u` the cosine-distributed direction on that side.
    #[inline]
    #[must_use]
    pub fn sample(&self, wo: DVec3, uc: f64, u: DVec2) -> Option<DVec3> {
        let w = crate::warp::square_to_cosine_hemisphere(u);
        if w.z <= 0.0 {
            return None;
        }
        let up = wo.z > 0.0;
        let through = uc < self.tau(wo);
        // On wo's side unless transmitted.
        Some(if up != through {
            w
        } else {
            DVec3::new(w.x, w.y, -w.z)
        })
    }
}

/// `2 ∫₀¹ r(μ) μ dμ` by 32-point Gauss-Legendre.
fn cosine_average(r: impl Fn(f64) -> Rgb) -> Rgb {
    let mut sum = Rgb::ZERO;
    for (t, w) in crate::stats::quadrature::gauss_legendre(32) {
        let mu = 0.5 * (t + 1.0);
        sum += r(mu) * (w * mu);
    }
    sum
}

/// Choose between two samplers with one uniform: `Ok(u)` for the first
/// (probability `q`), `Err(u)` for the second, `u.x` rescaled to `[0, 1)`
/// for the chosen one.
#[inline]
pub fn choose(u: DVec2, q: f64) -> Result<DVec2, DVec2> {
    if u.x < q {
        Ok(DVec2::new(u.x / q, u.y))
    } else {
        Err(DVec2::new(
            ((u.x - q) / (1.0 - q)).min(1.0 - f64::EPSILON / 2.0),
            u.y,
        ))
    }
}
