//! The page: its head, style sheet and script, the background, one
//! section per model (tables, figures and their captions), and the notes
//! on how it was made.

use super::args::ReportArgs;
use super::catalogue::{Model, Source, param_value};
use super::findings::{
    efficiency, find_point, findings, lost_note, reduction, slope_text, uniform_row,
};
use super::format::{esc, factor, lum, num, percent, shell_quote};
use super::jobs::{Figure, ModelResult, Point, ReportSettings};
use crate::figures;
use lobe::BsdfStrategy;
use std::fmt::Write as _;

pub(super) fn strategy_cell(name: &str) -> String {
    format!("<td class=\"s\"><code>{}</code></td>", esc(name))
}

/// The full table of one shading point.
pub(super) fn point_table(h: &mut String, model: &Model, p: &Point) {
    let reference = lum(p.table.reference);
    let uniform_eff = uniform_row(&p.table).and_then(efficiency);
    let best = p
        .table
        .strategies
        .iter()
        .map(|r| efficiency(r).unwrap_or(f64::INFINITY))
        .fold(0.0, f64::max);
    let _ = writeln!(
        h,
        "<table class=\"data\"><caption>{}, θ<sub>o</sub>&nbsp;=&nbsp;{}°: reference {} \
         (quadrature), {} samples per estimate</caption>",
        param_value(model, p.value),
        p.theta,
        num(reference),
        p.table.strategies.first().map_or(0, |r| r.samples)
    );
    h.push_str(
        "<thead><tr><th>strategy</th><th>estimate</th><th>std.&nbsp;error</th><th>reference</th>\
         <th>rel.&nbsp;error</th><th>variance</th><th>variance reduction</th><th>lost</th>\
         <th>time (ns/sample)</th><th>efficiency</th><th>efficiency vs uniform</th></tr></thead><tbody>\n",
    );
    for (row, lost) in p.table.strategies.iter().zip(&p.lost) {
        let est = lum(row.mean);
        let se = (row.variance / row.samples as f64).sqrt();
        let red = reduction(row).map_or("exact".to_string(), factor);
        let eff = efficiency(row).map_or("∞".to_string(), num);
        let vs = match (efficiency(row), uniform_eff) {
            (Some(e), Some(u)) if u > 0.0 => factor(e / u),
            (None, _) => "∞".into(),
            _ => "—".into(),
        };
        let class = if efficiency(row).unwrap_or(f64::INFINITY) == best {
            " class=\"best\""
        } else {
            ""
        };
        let _ = writeln!(
            h,
            "<tr{class}>{}<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{red}</td>\
             <td>{}</td><td>{:.0}</td><td>{eff}</td><td>{vs}</td></tr>",
            strategy_cell(&row.name),
            num(est),
            num(se),
            num(reference),
            num(row.relative_error),
            num(row.variance),
            percent(*lost),
            row.time_s / row.samples as f64 * 1e9,
        );
    }
    h.push_str("</tbody></table>\n");
}

/// The variance reductions of every shading point of a model.
pub(super) fn summary_table(h: &mut String, model: &Model, r: &ModelResult) {
    let names: Vec<String> = r
        .points
        .first()
        .map(|p| p.table.strategies.iter().map(|r| r.name.clone()).collect())
        .unwrap_or_default();
    let lecture = matches!(model.source, Source::Lecture(_));
    let _ = write!(
        h,
        "<p class=\"tcap\">Variance reduction against uniform sampling (uniform's variance \
         divided by each strategy's; higher is better, the best of each row in bold)</p>\
         <table class=\"data summary\"><thead><tr>{}<th>θ<sub>o</sub></th>\
         <th>reference</th>",
        if lecture {
            format!("<th><i>{}</i></th>", model.param)
        } else {
            String::new()
        }
    );
    for n in &names {
        let _ = write!(h, "<th><code>{}</code></th>", esc(n));
    }
    h.push_str("</tr></thead><tbody>\n");
    for p in &r.points {
        let best = p
            .table
            .strategies
            .iter()
            .map(|r| reduction(r).unwrap_or(f64::INFINITY))
            .fold(0.0, f64::max);
        let _ = write!(
            h,
            "<tr>{}<td>{}°</td><td>{}</td>",
            if lecture {
                format!("<td>{}</td>", p.value)
            } else {
                String::new()
            },
            p.theta,
            num(lum(p.table.reference))
        );
        for row in &p.table.strategies {
            let v = reduction(row).unwrap_or(f64::INFINITY);
            let text = reduction(row).map_or("exact".to_string(), factor);
            if v == best {
                let _ = write!(h, "<td><b>{text}</b></td>");
            } else {
                let _ = write!(h, "<td>{text}</td>");
            }
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table>\n");
}

pub(super) fn figure(h: &mut String, f: &Figure, caption: &str) {
    let _ = writeln!(
        h,
        "<figure><a href=\"{0}\" title=\"open the full-size image\"><img src=\"{0}\" alt=\"{1}\"></a>\
         <figcaption>{caption}</figcaption></figure>",
        esc(&f.file),
        esc(&f.alt)
    );
}

pub(super) fn section(h: &mut String, model: &Model, r: &ModelResult, st: &ReportSettings) {
    let fig_value = model.values[model.figure_value];
    let _ = writeln!(h, "<section id=\"{}\"><h2>{}</h2>", model.id, model.title);
    h.push_str(&model.intro);
    let _ = writeln!(h, "<p class=\"finding\">{}</p>", findings(model, r));

    let _ = writeln!(
        h,
        "<h3>Strategies compared</h3>\
         <p>Every strategy at {} view angles, with {} samples each. The best \
         strategy of each row is in bold. The full tables, with estimates, errors, lost samples, \
         times and efficiencies, follow.</p>",
        match (&model.source, model.param) {
            (Source::Given(..), _) => "three",
            (_, "n") => "three exponents and three",
            _ => "three roughnesses and three",
        },
        st.samples
    );
    summary_table(h, model, r);
    if let Some(p) = find_point(r, fig_value, model.figure_theta) {
        let _ = writeln!(
            h,
            "<p>The shading point of the figures below, in full (the most efficient strategy \
             highlighted):</p>"
        );
        point_table(h, model, p);
    }
    let _ = writeln!(
        h,
        "<details><summary>All {} shading points in full</summary>",
        r.points.len()
    );
    for p in &r.points {
        point_table(h, model, p);
    }
    h.push_str("</details>\n");
    let _ = writeln!(
        h,
        "<p class=\"explain\"><b>What to look for.</b> The estimates of all strategies agree with \
         the reference within a few standard errors: every strategy is unbiased, they differ only \
         in noise. The variance column is the noise of one sample; the standard error of the \
         estimate is √(variance/N). A variance reduction of 100× means uniform sampling needs 100 \
         times more samples for the same noise. Efficiency also charges for time: a sampler that \
         costs twice as much per sample must cut the variance by more than 2× to pay off.</p>"
    );

    // Figures, all at one shading point.
    let _ = writeln!(
        h,
        "<h3>Figures at {}, θ<sub>o</sub>&nbsp;=&nbsp;{}°</h3>\
         <p class=\"note\">Click a figure to open it at full size.</p>",
        param_value(model, fig_value),
        model.figure_theta
    );
    let slopes: Vec<String> = r
        .curves
        .iter()
        .map(|c| {
            format!(
                "<code>{}</code>&nbsp;/&nbsp;{}&nbsp;{}",
                c.strategy,
                c.sequence,
                slope_text(c)
            )
        })
        .collect();
    figure(
        h,
        &r.convergence,
        &format!(
            "<b>Convergence.</b> RMSE of {} independent estimates against the reference, for \
             N&nbsp;=&nbsp;1&nbsp;…&nbsp;2<sup>{}</sup> samples, on log-log axes. With independent \
             samples every strategy falls along a line of slope −1/2 (RMSE&nbsp;∝&nbsp;1/√N, the \
             dashed line): importance sampling does not change the rate, it moves the whole line \
             down, and a line 10× lower means 100× fewer samples for the same error. Stratified \
             and Sobol points change the rate itself where the weight f·cos/p is a smooth function \
             of the random numbers. The stratified curve zigzags: when N is a square \
             (N&nbsp;=&nbsp;4,&nbsp;16,&nbsp;64,&nbsp;…) its points form a √N×√N jittered grid; \
             otherwise they fall back to Latin hypercube sampling, which stratifies each \
             coordinate only on its own. Slopes fitted by least squares over the upper half of the range \
             (N&nbsp;≥&nbsp;2<sup>{}</sup>): {}.",
            st.runs,
            st.max_exp,
            lobe::experiment::converge::fit_start(st.max_exp),
            slopes.join(", ")
        ),
    );
    figure(
        h,
        &r.polar,
        "<b>Shapes in the plane of incidence.</b> The integrand f<sub>r</sub>·cos&thinsp;θ<sub>i</sub> \
         divided by its integral (the ideal density, which would give zero variance) and the density \
         of each strategy, all in 1/sr on one logarithmic radial scale (four decades below the largest \
         value; the legend gives each curve's peak), so that the curves compare directly. The \
         viewer is on the right, the mirror direction on the left, as in the histograms and weight maps. A good sampler has the shape of \
         the integrand: where its density is much lower than the integrand, the rare samples that \
         land there carry huge weights — the fireflies of a render. Uniform and cosine sampling \
         spread their samples over the whole hemisphere while the integrand lives in a narrow lobe.",
    );
    for w in &r.warps {
        let verdict = if w.p_value > figures::PASS_LEVEL {
            "passes"
        } else {
            "fails"
        };
        figure(
            h,
            &w.figure,
            &format!(
                "<b>Warp test of the <code>{}</code> sampler</b> at θ<sub>o</sub>&nbsp;=&nbsp;{}° \
                 (a less grazing view than the other figures, so that the lobe is not squeezed \
                 against the rim of the disk). Left: where {} sampled directions \
                 landed, seen from above (the disk is the hemisphere projected onto the surface). \
                 Right: where the sampler's own pdf says they should land. They must match: \
                 an estimator divides by the pdf, so a sampler whose samples do not follow its pdf \
                 gives a <i>biased</i> answer, however many samples it takes. A chi-square test over \
                 {}×{} bins of the sphere (after pooling sparse bins: {} degrees of freedom) gives \
                 p&nbsp;=&nbsp;{}; the test {verdict} at the 1% level (p&nbsp;>&nbsp;0.01 means no \
                 evidence of a mismatch). {}{}",
                w.strategy,
                model.warp_theta,
                st.warp_samples,
                st.chi2_nz,
                st.chi2_nphi,
                w.dof,
                num(w.p_value),
                lost_note(w),
                warp_note(model, w.strategy)
            ),
        );
    }
    h.push_str("<div class=\"row\">\n");
    for (s, f) in &r.heat {
        figure(h, f, &format!("<code>{s}</code>"));
    }
    h.push_str("</div>\n");
    let _ = writeln!(
        h,
        "<p class=\"explain\"><b>Sample weights.</b> Each pixel is a direction ω<sub>i</sub> seen \
         from above, coloured by the weight f<sub>r</sub>·cos&thinsp;θ<sub>i</sub>/p that a sample \
         there would carry (log colour scale; the white + is the mirror direction; grey: f<sub>r</sub> \
         = 0). The estimate is the average of these weights over the samples, so its noise is the \
         spread of the weights <i>where samples land</i>. With uniform sampling the weights span \
         many decades: huge in the small lobe, tiny everywhere else, and most samples land where \
         they are worthless. With p&nbsp;∝&nbsp;f<sub>r</sub>·cos&thinsp;θ<sub>i</sub> the weight \
         would be the same constant everywhere; a good sampler's map is nearly flat where it puts \
         its samples.{}</p>",
        heat_note(model)
    );
    if let Some(f) = &r.furnace {
        figure(
            h,
            f,
            &format!(
                "<b>White furnace.</b> The directional albedo ∫&thinsp;f<sub>r</sub>&thinsp;cos&thinsp;θ<sub>i</sub>&thinsp;dω<sub>i</sub> \
                 (light 1 from every direction) against θ<sub>o</sub>, one panel per α, by quadrature: \
                 the single-scattering lobe (<code>multiscatter</code> <code>none</code>, grey), and with \
                 Kulla and Conty's and Turquin's energy compensation; the black points are Heitz et al.'s \
                 random walk on the microsurface ({} walks a point), which follows every bounce between \
                 microfacets and loses nothing. A white single-scattering lobe reflects less than 1: the \
                 light that bounces more than once is lost, up to 70% at α&nbsp;=&nbsp;1, and rough \
                 metals render too dark. The compensated lobes give it back (docs/energy.md).",
                st.furnace_walks
            ),
        );
    }
    h.push_str("</section>\n");
}

pub(super) fn warp_note(model: &Model, s: BsdfStrategy) -> &'static str {
    match (model.family, s) {
        ("blinn-phong", BsdfStrategy::Brdf) => {
            " This sampler draws the half vector h, not ω<sub>i</sub>; its pdf includes the \
             Jacobian 1/(4&thinsp;ω<sub>o</sub>·h) of the reflection. Without it the right map \
             would not match the left one."
        }
        ("ggx" | "beckmann", BsdfStrategy::Vndf) => {
            " VNDF draws only normals that face the viewer, so fewer of its samples are lost \
             than with <code>brdf</code> (the tables give the lost fraction at every view)."
        }
        _ => "",
    }
}

pub(super) fn heat_note(model: &Model) -> &'static str {
    match model.family {
        "measured" => {
            " For a measured table the <code>brdf</code> sampler follows the tabulated data \
             (luminance × cos&thinsp;θ<sub>i</sub>), so its weight is nearly flat where the \
             data are smooth, and stays bounded where the cosine share of the mixture covers \
             what the table misses."
        }
        "other" => "",
        "phong" => {
            " For Phong the <code>brdf</code> weight is k<sub>s</sub>(n+2)/(n+1)·cos&thinsp;θ<sub>i</sub>: \
             it varies only with cos&thinsp;θ<sub>i</sub> across the lobe."
        }
        "blinn-phong" => {
            " For Blinn-Phong the <code>brdf</code> weight varies a little more, through the \
             Jacobian 4&thinsp;ω<sub>o</sub>·h and cos&thinsp;θ<sub>i</sub>, but it stays within a \
             small range where samples land."
        }
        _ => {
            " For microfacets the <code>brdf</code> (D·cos) weight is G·(ω<sub>o</sub>·h)/(cos&thinsp;θ<sub>o</sub> \
             cos&thinsp;θ<sub>h</sub>): at a grazing view cos&thinsp;θ<sub>o</sub> is small and the \
             weight grows large. The <code>vndf</code> weight is G<sub>2</sub>/G<sub>1</sub> ≤ 1 \
             everywhere: its map is flat and bounded."
        }
    }
}

pub(super) fn page(
    models: &[Model],
    results: &[ModelResult],
    st: &ReportSettings,
    args: &ReportArgs,
    elapsed: f64,
) -> String {
    let images: usize = results
        .iter()
        .map(|r| 2 + r.warps.len() + r.heat.len())
        .sum();
    let mut h = String::with_capacity(1 << 18);
    h.push_str(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>Importance sampling in BRDF evaluation — lobe report</title>\n<style>\n",
    );
    h.push_str(CSS);
    h.push_str("</style>\n</head>\n<body>\n<main>\n");
    let _ = writeln!(
        h,
        "<header><h1>Importance sampling in BRDF evaluation</h1>\
         <p class=\"sub\">{}: how the choice of sampling density changes the noise of a Monte \
         Carlo estimate.</p></header>",
        if args.materials.is_empty() {
            "Phong, Blinn-Phong and Cook-Torrance (GGX and Beckmann)".to_string()
        } else {
            models
                .iter()
                .map(|m| esc(&m.title))
                .collect::<Vec<_>>()
                .join("; ")
        }
    );
    h.push_str("<nav><b>Contents:</b> <a href=\"#background\">Background</a>");
    for m in models {
        let _ = write!(h, " · <a href=\"#{}\">{}</a>", m.id, m.title);
    }
    h.push_str(" · <a href=\"#about\">About this page</a></nav>\n");
    h.push_str(BACKGROUND);
    for (m, r) in models.iter().zip(results) {
        section(&mut h, m, r, st);
    }
    let _ = writeln!(
        h,
        "<section id=\"about\"><h2>About this page</h2><p>Generated by <code>lobe report{}{}{}</code> \
         in {elapsed:.1}&nbsp;s. Tables: {} samples per estimate (independent samples, seed {}). \
         Convergence: {} runs per N, N up to 2<sup>{}</sup>; each estimate uses its own sequence of \
         exactly N samples. Warp tests: {} samples, chi-square over {}×{} bins of the sphere. \
         References: {}. \
         Times are wall-clock on every thread of this machine and vary from run to run; all other \
         numbers depend only on the seed. {}</p>",
        if args.quick { " --quick" } else { "" },
        args.materials
            .iter()
            .map(|m| format!(" --material {}", esc(&shell_quote(m))))
            .collect::<String>(),
        if args.seed != 1 {
            format!(" --seed {}", args.seed)
        } else {
            String::new()
        },
        st.samples,
        args.seed,
        reference_methods(results),
        st.runs,
        st.max_exp,
        st.warp_samples,
        st.chi2_nz,
        st.chi2_nphi,
        if args.quick {
            "<b>Quick mode:</b> few samples; the numbers are rough."
        } else {
            ""
        }
    );
    let _ = writeln!(
        h,
        "<p>Page check: <span id=\"image-check\">{images} images; waiting for the page to load…</span></p>\
         </section>"
    );
    h.push_str("</main>\n<script>\n");
    h.push_str(IMAGE_CHECK);
    h.push_str("</script>\n</body>\n</html>\n");
    h
}

/// The distinct ways the tables' references were computed, joined.
pub(super) fn reference_methods(results: &[ModelResult]) -> String {
    let mut v: Vec<&str> = Vec::new();
    for p in results.iter().flat_map(|r| &r.points) {
        if !v.contains(&p.table.reference_method.as_str()) {
            v.push(&p.table.reference_method);
        }
    }
    esc(&v.join("; "))
}

/// Writes `ok N/N images loaded`, or the images that did not load, into
/// `#image-check` once the page has loaded.
pub(super) const IMAGE_CHECK: &str = include_str!("assets/image_check.js");

/// The page's style sheet.
pub(super) const CSS: &str = include_str!("assets/style.css");

/// The section every page opens with: the estimator and why importance
/// sampling lowers its noise.
pub(super) const BACKGROUND: &str = include_str!("assets/background.html");
