//! What the report covers: the lecture's models (or the materials given
//! with `--material`), their parameter values, the view angles, which
//! samplers are warp-tested and mapped, and how each section is named.

use super::format::{esc, strip_tags};
use anyhow::{Context, Result, anyhow};
use glam::DVec3;
use lobe::{BsdfStrategy, Material, MaterialDesc};
use std::fmt::Write as _;

/// The view angles of the tables, in degrees.
pub(super) const THETAS: [f64; 3] = [0.0, 45.0, 75.0];

/// One section of the page: a reflection model of the lecture and its
/// parameter values, or a material given with `--material`.
pub(super) struct Model {
    /// File-name stem and HTML anchor.
    pub(super) id: String,
    /// Section title.
    pub(super) title: String,
    /// The parameter's name in HTML (`n`, `α`); empty for a given material.
    pub(super) param: &'static str,
    /// The parameter values (one, `0`, for a given material).
    pub(super) values: Vec<f64>,
    /// The configuration of the figures: index into `values`, and θo.
    pub(super) figure_value: usize,
    pub(super) figure_theta: f64,
    /// The view angle of the warp tests: less grazing than the other
    /// figures, where a grazing lobe would fill a pixel or two at the rim of
    /// the projected hemisphere.
    pub(super) warp_theta: f64,
    /// Extra strategies whose sampler is warp-tested (brdf always is).
    pub(super) warp_extra: Vec<BsdfStrategy>,
    /// Extra strategies whose weights are mapped (uniform and brdf always are).
    pub(super) heat_extra: Vec<BsdfStrategy>,
    /// Where the materials come from.
    pub(super) source: Source,
    /// What the model is and how its brdf sampler works (HTML).
    pub(super) intro: String,
    /// Which notes of the figures apply: `phong`, `blinn-phong`, `ggx`,
    /// `beckmann`, `measured` or `other`.
    pub(super) family: &'static str,
}

/// The materials of a section.
pub(super) enum Source {
    /// The material description for a parameter value.
    Lecture(fn(f64) -> String),
    /// A material of `--material` (loaded once).
    Given(Box<Material>),
}

pub(super) fn models() -> Vec<Model> {
    vec![
        Model {
            id: "phong".into(),
            title: "Phong".into(),
            param: "n",
            values: vec![10.0, 100.0, 1000.0],
            figure_value: 1,
            figure_theta: 45.0,
            warp_theta: 45.0,
            warp_extra: vec![],
            heat_extra: vec![],
            source: Source::Lecture(|n| format!(r#"{{"type":"phong","exponent":{n}}}"#)),
            intro: PHONG_INTRO.into(),
            family: "phong",
        },
        Model {
            id: "blinn-phong".into(),
            title: "Blinn-Phong".into(),
            param: "n",
            values: vec![10.0, 100.0, 1000.0],
            figure_value: 1,
            figure_theta: 45.0,
            warp_theta: 45.0,
            warp_extra: vec![],
            heat_extra: vec![],
            source: Source::Lecture(|n| format!(r#"{{"type":"blinn-phong","exponent":{n}}}"#)),
            intro: BLINN_INTRO.into(),
            family: "blinn-phong",
        },
        Model {
            id: "ggx".into(),
            title: "Cook-Torrance with GGX".into(),
            param: "α",
            values: vec![0.05, 0.2, 0.5],
            figure_value: 1,
            figure_theta: 75.0,
            warp_theta: 45.0,
            warp_extra: vec![BsdfStrategy::Vndf],
            heat_extra: vec![BsdfStrategy::Vndf],
            source: Source::Lecture(|a| {
                format!(r#"{{"type":"cook-torrance","distribution":"ggx","alpha":{a}}}"#)
            }),
            intro: GGX_INTRO.into(),
            family: "ggx",
        },
        Model {
            id: "beckmann".into(),
            title: "Cook-Torrance with Beckmann".into(),
            param: "α",
            values: vec![0.05, 0.2, 0.5],
            figure_value: 1,
            figure_theta: 75.0,
            warp_theta: 45.0,
            warp_extra: vec![],
            heat_extra: vec![BsdfStrategy::Vndf],
            source: Source::Lecture(|a| {
                format!(r#"{{"type":"cook-torrance","distribution":"beckmann","alpha":{a}}}"#)
            }),
            intro: BECKMANN_INTRO.into(),
            family: "beckmann",
        },
    ]
}

/// The sections of the materials given with `--material`, one each,
/// every material loaded (and checked) before any work.
pub(super) fn given_models(specs: &[String]) -> Result<Vec<Model>> {
    specs
        .iter()
        .enumerate()
        .map(|(i, spec)| {
            let m =
                crate::common::load_material(spec).with_context(|| format!("--material {spec}"))?;
            crate::common::refuse_all_delta(&m, glam::DVec3::Z)
                .with_context(|| format!("--material {spec}"))?;
            let vndf = if m.check(BsdfStrategy::Vndf).is_ok() {
                vec![BsdfStrategy::Vndf]
            } else {
                vec![]
            };
            let name = m.model_name();
            let label = match m.measured() {
                Some(t) => format!(
                    "{name} ({})",
                    t.data.path.file_name().map_or_else(
                        || t.data.path.display().to_string(),
                        |f| f.to_string_lossy().into_owned()
                    )
                ),
                None => name.to_string(),
            };
            let family = match (&m.glossy, m.measured()) {
                (_, Some(_)) => "measured",
                (lobe::Glossy::Phong(_), _) => "phong",
                (lobe::Glossy::BlinnPhong(_), _) => "blinn-phong",
                (lobe::Glossy::CookTorrance(ct), _) => match ct.microfacet.ndf() {
                    lobe::Ndf::Ggx => "ggx",
                    lobe::Ndf::Beckmann => "beckmann",
                    lobe::Ndf::BlinnPhong => "microfacet",
                },
                _ => "other",
            };
            let mut intro = format!(
                "<p>The material given with <code>--material {}</code>: <code>{}</code>, under the \
                 same white furnace and at the same three views as the lecture's models. Its \
                 strategies: {}.</p>\n",
                esc(spec),
                esc(name),
                m.strategies()
                    .iter()
                    .map(|s| format!("<code>{s}</code>"))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            let reach = m.reach();
            if reach.transmits {
                intro.push_str(
                    "<p>It transmits: its integrals (the reference, the variances) are over \
                     the whole sphere, uniform and cosine sampling draw from the whole sphere, \
                     the polar plot goes round the full circle with the transmitted lobe below \
                     the surface line, and the maps show both hemispheres.</p>\n",
                );
            }
            if reach.delta {
                intro.push_str(
                    "<p>It has a delta part (a mirror reflection or smooth refraction): its \
                     light is in the reference and the estimates, BSDF sampling draws it with \
                     its probability, and the figures of densities leave it out (it has none); \
                     the warp test counts its samples as lost.</p>\n",
                );
            }
            if let Some(t) = m.measured() {
                let _ = writeln!(
                    intro,
                    "<p>A measured table ({}). Its <code>brdf</code> sampler draws from a \
                     tabulated distribution built from the data (per bin of θ<sub>o</sub>, a \
                     piecewise-constant density over the half vector weighted by luminance × \
                     cos&thinsp;θ<sub>i</sub> × the half-vector Jacobian, mixed with a small share \
                     of cosine sampling), with an exact pdf: the warp test below checks it.</p>",
                    esc(&t.summary())
                );
            }
            Ok(Model {
                id: format!("material-{}", i + 1),
                title: format!("Material {}: {}", i + 1, label),
                param: "",
                values: vec![0.0],
                figure_value: 0,
                figure_theta: if vndf.is_empty() { 45.0 } else { 75.0 },
                warp_theta: 45.0,
                warp_extra: vndf.clone(),
                heat_extra: vndf,
                source: Source::Given(Box::new(m)),
                intro,
                family,
            })
        })
        .collect()
}

pub(super) fn build(model: &Model, value: f64) -> Result<Material> {
    match &model.source {
        Source::Lecture(json) => {
            let json = json(value);
            MaterialDesc::from_json(&json)
                .and_then(|d| d.build())
                .map_err(|e| anyhow!("report material {json}: {e}"))
        }
        Source::Given(m) => Ok(m.as_ref().clone()),
    }
}

pub(super) fn view(theta: f64) -> DVec3 {
    let t = theta.to_radians();
    DVec3::new(t.sin(), 0.0, t.cos())
}

/// The estimates at the figure's configuration use this view.
pub(super) fn figure_point(model: &Model) -> (usize, DVec3) {
    (model.figure_value, view(model.figure_theta))
}

/// The value of a parameter: `n = 100`, `α = 0.2` (HTML); a given
/// material's name.
pub(super) fn param_value(model: &Model, v: f64) -> String {
    match &model.source {
        Source::Lecture(_) => format!("<i>{}</i>&nbsp;=&nbsp;{v}", model.param),
        Source::Given(..) => esc(&model.title),
    }
}

/// The section's title and the parameter value, as plain text for figure
/// titles: `Phong, n = 100`.
pub(super) fn plain_point(model: &Model, v: f64) -> String {
    match &model.source {
        Source::Lecture(_) => format!("{}, {} = {v}", model.title, strip_tags(model.param)),
        Source::Given(..) => model.title.clone(),
    }
}

pub(super) const PHONG_INTRO: &str = r#"<p>The (energy-normalized) Phong model is
f<sub>r</sub> = k<sub>s</sub> (n+2)/(2π) cos<sup>n</sup> α, where α is the angle between
ω<sub>i</sub> and the mirror direction of ω<sub>o</sub>. The highlight is a cone around the
mirror direction whose width shrinks like 1/√n. The lecture's <code>brdf</code> sampler draws α
with density (n+1)/(2π) cos<sup>n</sup> α around the mirror direction (cos α = u<sup>1/(n+1)</sup>),
so f<sub>r</sub>/p is the constant k<sub>s</sub>(n+2)/(n+1): the weight varies only through
cos θ<sub>i</sub>. At grazing views part of the cone lies below the horizon, and those samples
are lost.</p>
"#;

pub(super) const BLINN_INTRO: &str = r#"<p>Blinn-Phong uses the half vector
h = (ω<sub>o</sub> + ω<sub>i</sub>)/|ω<sub>o</sub> + ω<sub>i</sub>|:
f<sub>r</sub> = k<sub>s</sub> K cos<sup>n</sup> θ<sub>h</sub>, with K chosen so that the albedo at
normal incidence is k<sub>s</sub>. The <code>brdf</code> sampler draws the half vector with density
p<sub>h</sub>(h) = (n+1)/(2π) cos<sup>n</sup> θ<sub>h</sub> and reflects ω<sub>o</sub> about it.
But the estimator needs the density of ω<sub>i</sub>, not of h. <b>The half-vector Jacobian:</b>
reflecting about h doubles angles, so a small patch of half vectors dω<sub>h</sub> becomes a
patch of directions dω<sub>i</sub> = 4 (ω<sub>o</sub>·h) dω<sub>h</sub>, and</p>
<p class="formula">p(ω<sub>i</sub>) = p<sub>h</sub>(h) / (4 ω<sub>o</sub>·h).</p>
<p>Forgetting the factor, i.e. dividing by p<sub>h</sub>, does not just add noise: it makes the
estimate wrong on average (biased). The warp test below checks that the samples really follow
the corrected density.</p>
"#;

pub(super) const GGX_INTRO: &str = r#"<p>Cook-Torrance models a surface as tiny mirrors (microfacets):
f<sub>r</sub> = D(h) G(ω<sub>o</sub>, ω<sub>i</sub>) F / (4 cos θ<sub>o</sub> cos θ<sub>i</sub>),
here with F = 1 and Smith's height-correlated G. D is the distribution of microfacet normals,
of width α; GGX has long tails (a soft glow around the highlight). The lecture's
<code>brdf</code> sampler draws h from D(h) cos θ<sub>h</sub> and reflects ω<sub>o</sub> about
it, with the same Jacobian 1/(4 ω<sub>o</sub>·h) as Blinn-Phong. Its weight is
G (ω<sub>o</sub>·h) / (cos θ<sub>o</sub> cos θ<sub>h</sub>).</p>
<p><b>Why VNDF beats D·cos at grazing angles.</b> D·cos draws normals as the surface holds them,
ignoring where the viewer is. At a grazing view many of those normals face away from the viewer
or reflect ω<sub>o</sub> below the horizon (lost samples), and the weight above grows like
1/cos θ<sub>o</sub>. VNDF sampling draws only the normals the viewer can see, in proportion to
their visible area, p(h) = G<sub>1</sub>(ω<sub>o</sub>) max(0, ω<sub>o</sub>·h) D(h) / cos θ<sub>o</sub>.
Its weight is G<sub>2</sub>/G<sub>1</sub> ≤ 1 at every angle. Looking straight down both
densities are almost the same; the gap opens as θ<sub>o</sub> grows.</p>
"#;

pub(super) const BECKMANN_INTRO: &str = r#"<p>The same Cook-Torrance model with the Beckmann distribution
of normals, a Gaussian-like D with shorter tails than GGX (a crisper highlight edge). The
samplers are the same: <code>brdf</code> draws h from D(h) cos θ<sub>h</sub>; <code>vndf</code>
draws only visible normals (for Beckmann this needs a numerical inversion, which makes it
slower per sample: compare the time and efficiency columns). The same reasoning holds: at grazing
views the D·cos weights G (ω<sub>o</sub>·h)/(cos θ<sub>o</sub> cos θ<sub>h</sub>) grow, and VNDF's
stay bounded by one.</p>
"#;
