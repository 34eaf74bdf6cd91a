//! How the directions of an estimate are drawn ([`Strategy`]): a BSDF
//! strategy ([`BsdfStrategy`], in its own module), light sampling, or MIS
//! with its heuristic and form; selected by name.

use crate::Error;
use crate::Material;
pub use crate::bsdf_strategy::BsdfStrategy;
use crate::light::LightDistribution;

/// How Multiple Importance Sampling weights its strategies (Veach 1997).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Heuristic {
    /// `w_t = n_t p_t / Σ n p`.
    Balance,
    /// `w_t = (n_t p_t)² / Σ (n p)²`.
    Power,
}

impl Heuristic {
    /// The weight of a strategy whose (count-scaled) density is `a`
    /// against another's `b`.
    #[inline]
    #[must_use]
    pub fn weight(self, a: f64, b: f64) -> f64 {
        match self {
            Heuristic::Balance => a / (a + b),
            Heuristic::Power => a * a / (a * a + b * b),
        }
    }
}

/// Multi-sample MIS draws `n_bsdf` and `n_light` samples for every estimate;
/// one-sample MIS draws one, choosing the strategy with probability
/// `n_t / (n_bsdf + n_light)`; adaptive MIS draws `n_bsdf + n_light`
/// directions per estimate and gives them to the strategies as a pilot
/// says is best ([`crate::estimator::Allocation`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MisForm {
    MultiSample,
    OneSample,
    /// Variance-aware allocation (after Grittmann et al. 2019, "Variance-aware
    /// multiple importance sampling"): from a pilot, the per-sample variance
    /// of every allocation of the `n_bsdf + n_light` draws (all to BSDF
    /// sampling, the multi-sample balance heuristic with the given counts,
    /// all to light sampling) is estimated, and the least is used. Never
    /// much worse than the better strategy alone, keeping MIS's wins.
    Adaptive,
}

/// BSDF sampling combined with light sampling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Mis {
    /// The BSDF strategy; `None`: the material's best
    /// ([`Material::best_bsdf_strategy`]), chosen per material.
    pub bsdf: Option<BsdfStrategy>,
    pub heuristic: Heuristic,
    pub form: MisForm,
    pub n_bsdf: u32,
    pub n_light: u32,
}

/// How the directions of an estimate are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// BSDF sampling by a strategy.
    Bsdf(BsdfStrategy),
    /// Light sampling alone.
    Light,
    /// Both, combined by MIS.
    Mis(Mis),
}

impl std::fmt::Display for Strategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl From<BsdfStrategy> for Strategy {
    fn from(s: BsdfStrategy) -> Self {
        Strategy::Bsdf(s)
    }
}

/// The names of the strategies that are not BSDF strategies.
pub const NON_BSDF_NAMES: [&str; 6] = [
    "light",
    "mis",
    "mis-balance",
    "mis-power",
    "mis-one",
    "mis-power-one",
];

impl Strategy {
    /// `mis`, the default: adaptive MIS ([`MisForm::Adaptive`]), one BSDF
    /// and one light draw per sample, on the material's best BSDF strategy.
    pub const MIS: Strategy = Strategy::Mis(Mis {
        bsdf: None,
        heuristic: Heuristic::Balance,
        form: MisForm::Adaptive,
        n_bsdf: 1,
        n_light: 1,
    });

    /// `mis-balance` or `mis-power`: one sample of each strategy,
    /// multi-sample, on the material's best BSDF strategy.
    #[must_use]
    pub const fn mis(heuristic: Heuristic) -> Self {
        Strategy::Mis(Mis {
            bsdf: None,
            heuristic,
            form: MisForm::MultiSample,
            n_bsdf: 1,
            n_light: 1,
        })
    }

    /// Every strategy by name: the BSDF strategies, `light`, `mis`,
    /// `mis-balance`, `mis-power`, `mis-one`, `mis-power-one` (MIS on the
    /// material's best BSDF strategy, one sample of each strategy).
    #[must_use]
    pub fn all() -> Vec<Strategy> {
        let mut v: Vec<Strategy> = BsdfStrategy::ALL.into_iter().map(Strategy::Bsdf).collect();
        v.push(Strategy::Light);
        v.push(Strategy::MIS);
        for form in [MisForm::MultiSample, MisForm::OneSample] {
            for heuristic in [Heuristic::Balance, Heuristic::Power] {
                v.push(Strategy::Mis(Mis {
                    bsdf: None,
                    heuristic,
                    form,
                    n_bsdf: 1,
                    n_light: 1,
                }));
            }
        }
        v
    }

    /// Every accepted name, comma separated, for help and error messages.
    #[must_use]
    pub fn names() -> String {
        format!("{}, {}", BsdfStrategy::names(), NON_BSDF_NAMES.join(", "))
    }

    /// The name used on the command line, in scene files and in tables.
    #[must_use]
    pub fn name(&self) -> String {
        match self {
            Strategy::Bsdf(s) => s.name().to_string(),
            Strategy::Light => "light".into(),
            Strategy::Mis(m) => match (m.form, m.heuristic) {
                (MisForm::Adaptive, Heuristic::Balance) => "mis".into(),
                (MisForm::Adaptive, Heuristic::Power) => "mis-adaptive-power".into(),
                (MisForm::MultiSample, Heuristic::Balance) => "mis-balance".into(),
                (MisForm::MultiSample, Heuristic::Power) => "mis-power".into(),
                (MisForm::OneSample, Heuristic::Balance) => "mis-one".into(),
                (MisForm::OneSample, Heuristic::Power) => "mis-power-one".into(),
            },
        }
    }

    /// Sequence points used by one estimate (`n_bsdf + n_light` for
    /// multi-sample and adaptive MIS, else 1).
    #[must_use]
    pub fn points_per_sample(&self) -> usize {
        match self {
            Strategy::Mis(m) if m.form != MisForm::OneSample => (m.n_bsdf + m.n_light) as usize,
            _ => 1,
        }
    }

    /// The light distribution this strategy draws light samples from: the
    /// plain one for light sampling alone, the MIS-compensated one inside
    /// MIS. The one place where that choice is made.
    #[must_use]
    pub fn light_distribution(&self) -> LightDistribution {
        match self {
            Strategy::Mis(_) => LightDistribution::Compensated,
            _ => LightDistribution::Plain,
        }
    }

    /// The BSDF strategy this strategy samples `m` by, if any: its own for
    /// a BSDF strategy, the given or the material's best for MIS, none for
    /// light sampling.
    #[must_use]
    pub fn bsdf_strategy(&self, m: &Material) -> Option<BsdfStrategy> {
        match self {
            Strategy::Bsdf(s) => Some(*s),
            Strategy::Light => None,
            Strategy::Mis(mis) => Some(mis.bsdf.unwrap_or_else(|| m.best_bsdf_strategy())),
        }
    }
}

impl std::str::FromStr for Strategy {
    type Err = Error;
    /// Any name of [`Strategy::names`].
    fn from_str(s: &str) -> Result<Self, Error> {
        Strategy::all()
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| Error::UnknownStrategy {
                value: s.into(),
                expected: Strategy::names(),
            })
    }
}

/// The strategies `all` stands for: every BSDF strategy that applies to the
/// material, `light`, `mis`, `mis-balance`, `mis-power`.
pub const ALL_MEANS: &str = "every BSDF strategy that applies, light, mis, mis-balance, mis-power";

impl Strategy {
    /// A list of strategy names for material `m`, in order, without
    /// repeats: each name is a BSDF strategy (checked against `m`), `light`,
    /// or an MIS name of [`NON_BSDF_NAMES`], whose MIS combines light
    /// sampling with `mis_bsdf` at `n_bsdf` and `n_light` draws; `all` is
    /// [`ALL_MEANS`]. The one parser of `lobe estimate --strategy`, the
    /// experiments and the Python `lobe.estimate`.
    pub fn parse_list<'a>(
        names: impl IntoIterator<Item = &'a str>,
        m: &Material,
        mis_bsdf: BsdfStrategy,
        n_bsdf: u32,
        n_light: u32,
    ) -> Result<Vec<Strategy>, Error> {
        let mis = |heuristic, form| {
            Strategy::Mis(Mis {
                bsdf: Some(mis_bsdf),
                heuristic,
                form,
                n_bsdf,
                n_light,
            })
        };
        let mut v: Vec<Strategy> = Vec::new();
        let push = |t: Strategy, v: &mut Vec<Strategy>| {
            if !v.contains(&t) {
                v.push(t);
            }
        };
        for name in names {
            let name = name.trim();
            let t = match name {
                "all" => {
                    for s in m.strategies() {
                        push(Strategy::Bsdf(s), &mut v);
                    }
                    // Light sampling alone never reaches a delta part.
                    if !m.reach().delta {
                        push(Strategy::Light, &mut v);
                    }
                    for t in [
                        mis(Heuristic::Balance, MisForm::Adaptive),
                        mis(Heuristic::Balance, MisForm::MultiSample),
                        mis(Heuristic::Power, MisForm::MultiSample),
                    ] {
                        push(t, &mut v);
                    }
                    continue;
                }
                "light" if m.reach().delta => return Err(light_never_hits(m)),
                "light" => Strategy::Light,
                "mis" => mis(Heuristic::Balance, MisForm::Adaptive),
                "mis-balance" => mis(Heuristic::Balance, MisForm::MultiSample),
                "mis-power" => mis(Heuristic::Power, MisForm::MultiSample),
                "mis-one" => mis(Heuristic::Balance, MisForm::OneSample),
                "mis-power-one" => mis(Heuristic::Power, MisForm::OneSample),
                _ => {
                    let s: BsdfStrategy = name.parse().map_err(|_| Error::UnknownStrategy {
                        value: name.into(),
                        expected: format!("all, {}", Strategy::names()),
                    })?;
                    m.check(s)?;
                    Strategy::Bsdf(s)
                }
            };
            push(t, &mut v);
        }
        Ok(v)
    }
}

/// Why light sampling alone does not apply to `m`, which has a delta part:
/// the error the strategy parser and the estimator give.
pub(crate) fn light_never_hits(m: &Material) -> Error {
    Error::Unsupported {
        strategy: "light".into(),
        reason: format!(
            "{} has a delta part (a mirror or a smooth interface) that light sampling never hits",
            m.model_name()
        ),
        available: m
            .strategies()
            .into_iter()
            .map(BsdfStrategy::name)
            .chain(["mis"])
            .collect(),
    }
}

/// What `mis`, the default strategy, is: the one description of every help
/// text that names it (`lobe estimate --help`, `lobe render --help`).
pub const MIS_DESCRIPTION: &str = "adaptive MIS, the default: each sample draws one BSDF direction (vndf where the material has it, else brdf) and one light direction, and gives both to BSDF sampling, to the balance heuristic or to light sampling, whichever a pilot of its own samples finds of least variance (in a render: per pixel, from the pilots of the 7 × 7 pixels around it; deeper bounces use the balance heuristic)";

/// What a strategy of [`Strategy::names`] (or a BSDF strategy's
/// [`BsdfStrategy::name`](crate::BsdfStrategy::name)) is, in a few words; `None` for a name this list does not know (a test
/// checks that every accepted name has one).
#[must_use]
pub fn description(name: &str) -> Option<&'static str> {
    Some(match name {
        "uniform" => "uniform over the hemisphere (the baseline)",
        "cosine" => "cosine-weighted hemisphere",
        "brdf" => {
            "the lecture's importance sampling (Phong's lobe, Blinn-Phong's half vector, Cook-Torrance's D(h) cos θh)"
        }
        "vndf" => "visible normals (Heitz 2018; GGX and Beckmann)",
        "spherical-caps" => "visible normals by spherical caps (Dupuy and Benyoub 2023; GGX)",
        "bounded-vndf" => "bounded VNDF (Eto and Tokuyoshi 2023; GGX)",
        "light" => "light sampling alone (the environment map's or the light's own distribution)",
        "mis" => MIS_DESCRIPTION,
        "mis-balance" => {
            "multi-sample MIS with the balance heuristic: one BSDF and one light sample, both weighted"
        }
        "mis-power" => "multi-sample MIS with the power heuristic",
        "mis-one" => {
            "one-sample MIS with the balance heuristic: one draw, BSDF or light at even odds"
        }
        "mis-power-one" => "one-sample MIS with the power heuristic",
        _ => return None,
    })
}
