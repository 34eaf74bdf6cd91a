//! The prose drawn from the numbers: what the tables say of each model
//! (gains, best strategies, lost samples), and the readings of a table
//! row it rests on.

use super::catalogue::{Model, Source, THETAS, param_value};
use super::format::{factor, percent};
use super::jobs::{ModelResult, Point, Warp};
use lobe::BsdfStrategy;
use lobe::experiment::converge::Curve;
use lobe::experiment::table::{Row, Table};
use std::fmt::Write as _;

/// Whether a row's variance is zero up to rounding (relative to its mean²).
pub(super) fn exact(row: &Row) -> bool {
    crate::common::row_is_exact(row)
}

/// Uniform's variance over this row's; `None` for a zero variance.
pub(super) fn reduction(row: &Row) -> Option<f64> {
    if exact(row) {
        None
    } else {
        row.variance_reduction
    }
}

/// `1/(variance × time)`; `None` for a zero variance.
pub(super) fn efficiency(row: &Row) -> Option<f64> {
    if exact(row) { None } else { row.efficiency }
}

pub(super) fn uniform_row(t: &Table) -> Option<&Row> {
    t.row(BsdfStrategy::Uniform.into())
}

pub(super) fn find_point(r: &ModelResult, value: f64, theta: f64) -> Option<&Point> {
    r.points
        .iter()
        .find(|p| p.value == value && p.theta == theta)
}

pub(super) fn variance_of(p: &Point, s: BsdfStrategy) -> Option<f64> {
    p.table
        .row(s.into())
        .map(|r| if exact(r) { 0.0 } else { r.variance })
}

pub(super) fn lost_of(p: &Point, s: BsdfStrategy) -> Option<f64> {
    p.table
        .position(s.into())
        .and_then(|i| p.lost.get(i).copied())
}

/// A sentence or two drawn from the numbers of a model.
pub(super) fn findings(model: &Model, r: &ModelResult) -> String {
    let mut out = String::new();
    // brdf against uniform: smallest and largest gain.
    let gains: Vec<(&Point, f64)> = r
        .points
        .iter()
        .filter_map(|p| {
            let u = variance_of(p, BsdfStrategy::Uniform)?;
            let b = variance_of(p, BsdfStrategy::Brdf)?;
            Some((p, if b > 0.0 { u / b } else { f64::INFINITY }))
        })
        .collect();
    if let (Some(lo), Some(hi)) = (
        gains.iter().min_by(|a, b| a.1.total_cmp(&b.1)),
        gains.iter().max_by(|a, b| a.1.total_cmp(&b.1)),
    ) {
        let most = if hi.1.is_finite() {
            format!("by {}", factor(hi.1))
        } else {
            "to zero (up to rounding)".into()
        };
        let at = |p: &Point| {
            format!(
                "{}, θ<sub>o</sub>&nbsp;=&nbsp;{}°",
                param_value(model, p.value),
                p.theta
            )
        };
        let _ = write!(
            out,
            "The {} <code>brdf</code> sampler cuts the variance of uniform sampling {most} \
             at {}: the sharper the lobe, the more a blind (uniform) sampler misses it, and the \
             more importance sampling gains. ",
            if matches!(model.source, Source::Lecture(_)) {
                "lecture's"
            } else {
                "material's"
            },
            at(hi.0)
        );
        if lo.1 >= 1.0 {
            let _ = write!(
                out,
                "Its smallest gain is {} at {}. ",
                factor(lo.1),
                at(lo.0)
            );
        } else {
            let _ = write!(
                out,
                "But at {} it has {} <i>more</i> variance than uniform sampling: a sampler that \
                 puts its samples in the wrong places is worse than none. ",
                at(lo.0),
                factor(1.0 / lo.1)
            );
        }
    }
    // VNDF against brdf at the most grazing view.
    let theta = THETAS[THETAS.len() - 1];
    let mut all_better = true;
    let vs: Vec<String> = model
        .values
        .iter()
        .filter_map(|&v| {
            let p = find_point(r, v, theta)?;
            let b = variance_of(p, BsdfStrategy::Brdf)?;
            let n = variance_of(p, BsdfStrategy::Vndf)?;
            all_better &= b > n;
            let lost = lost_of(p, BsdfStrategy::Brdf).unwrap_or(f64::NAN);
            let name = if matches!(model.source, Source::Lecture(_)) {
                format!("{}: ", param_value(model, v))
            } else {
                String::new()
            };
            Some(format!(
                "{name}{} (<code>brdf</code> loses {} of its samples below the horizon)",
                if n > 0.0 { factor(b / n) } else { "∞".into() },
                percent(lost)
            ))
        })
        .collect();
    if !vs.is_empty() {
        // A measured table's brdf sampler follows the data, not D·cos.
        let brdf = if model.family == "measured" {
            "<code>brdf</code> (tabulated)"
        } else {
            "<code>brdf</code> (D·cos)"
        };
        if all_better {
            let _ = write!(
                out,
                "At the grazing view θ<sub>o</sub>&nbsp;=&nbsp;{theta}°, VNDF sampling has less \
                 variance than {brdf} sampling by {}.",
                vs.join("; ")
            );
        } else {
            let _ = write!(
                out,
                "At the grazing view θ<sub>o</sub>&nbsp;=&nbsp;{theta}°, VNDF sampling does not \
                 always beat {brdf} sampling here: the variance of {brdf} over VNDF's is {}.",
                vs.join("; ")
            );
        }
    }
    out
}

pub(super) fn slope_text(c: &Curve) -> String {
    match c.slope {
        Some(s) => format!("{s:.2}").replace('-', "−"),
        None => "—".into(),
    }
}

pub(super) fn lost_note(w: &Warp) -> String {
    if w.lost > 0.0 {
        format!(
            "{} of the samples were lost below the horizon: they fall in no pixel, and the pdf \
             integrates to {:.5} over the sphere, short of one by the same amount.",
            percent(w.lost),
            w.pdf_integral
        )
    } else {
        "No sample was lost below the horizon.".into()
    }
}
