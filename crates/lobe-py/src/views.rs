//! `lobe.polar`, `lobe.lobe_grid`, `lobe.albedo_curve`, `lobe.warp_test`
//! and `lobe.weight_map`: the views of the explorer (`lobe explore`,
//! `crates/lobe-explore/src/api.rs`) from the same library calls
//! ([`lobe::experiment`]), with the explorer's checks of the view angle
//! and its warp-test bins, and errors that name the Python argument.
//! Every call gives the same numbers for any thread count.

use glam::DVec3;
use lobe::experiment::histogram::{WeightPixel, weight_pixels};
use lobe::experiment::warp_test::interactive_config;
use lobe::experiment::{albedo, lobe_grid, polar};
use lobe::stats::chi2::Chi2Settings;
use lobe::{BsdfSampler, BsdfStrategy, Material};

/// The view direction at `theta_o`, `phi_o` degrees
/// ([`Material::view_direction`], as the explorer checks it; the errors
/// name `theta_o` and `phi_o`).
pub fn view(m: &Material, theta_o: f64, phi_o: f64) -> Result<DVec3, String> {
    m.view_direction(theta_o, phi_o)
        .map_err(|e| e.named("theta_o", "phi_o"))
}

/// A count that must be at least `min`; the error names `name`.
fn at_least(name: &str, v: usize, min: usize) -> Result<usize, String> {
    if v < min {
        return Err(format!("{name} {v}: must be at least {min}"));
    }
    Ok(v)
}

/// The sampler of the strategy named `name`; the error names the strategy.
fn sampler<'m>(m: &'m Material, name: &str) -> Result<BsdfSampler<'m>, String> {
    let s: BsdfStrategy = name.parse().map_err(|_: lobe::Error| {
        format!(
            "strategy `{name}`: not a BSDF strategy, expected one of: {}",
            BsdfStrategy::names()
        )
    })?;
    m.sampler(s).map_err(|e| e.to_string())
}

/// [`polar`]'s curves in the plane of incidence.
#[derive(Debug, Clone, PartialEq)]
pub struct Polar {
    /// The signed angles θi in radians ([`polar::angles`]): `steps + 1`
    /// from −π/2 to π/2, or `2 steps + 1` from −π to π round the full
    /// circle.
    pub theta: Vec<f64>,
    /// The luminance of `f·|cos θi|` at each angle (not divided by the
    /// albedo).
    pub fcos: Vec<f64>,
    /// Each strategy of the material (in [`BsdfStrategy::ALL`] order) and
    /// its pdf in solid angle at each angle.
    pub pdfs: Vec<(&'static str, Vec<f64>)>,
    /// The curves go round the whole circle (the material transmits, or is
    /// seen from below).
    pub full_circle: bool,
}

/// The explorer's polar view: `f·|cos θi|` in the plane of incidence
/// ([`polar::integrand`] with albedo 1) and the pdf of every strategy of
/// `m` there ([`polar::pdf`]), at `steps` steps over the half circle.
pub fn polar(m: &Material, theta_o: f64, phi_o: f64, steps: usize) -> Result<Polar, String> {
    let steps = at_least("steps", steps, 1)?;
    let wo = view(m, theta_o, phi_o)?;
    let fcos = polar::integrand(m, wo, 1.0, steps);
    let pdfs = m
        .strategies()
        .into_iter()
        .map(|s| {
            polar::pdf(m, s, wo, steps)
                .map(|c| (s.name(), c.points.iter().map(|p| p.1).collect()))
                .map_err(|e| e.to_string())
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Polar {
        theta: fcos.points.iter().map(|p| p.0).collect(),
        fcos: fcos.points.iter().map(|p| p.1).collect(),
        pdfs,
        full_circle: polar::full_circle(m, wo),
    })
}

/// The explorer's 3D lobe: [`lobe_grid::grid`] at the view `theta_o`,
/// `phi_o` (degrees), `n_theta` and `n_phi` at least 1.
pub fn lobe_grid(
    m: &Material,
    theta_o: f64,
    phi_o: f64,
    n_theta: usize,
    n_phi: usize,
) -> Result<lobe_grid::LobeGrid, String> {
    let n_theta = at_least("n_theta", n_theta, 1)?;
    let n_phi = at_least("n_phi", n_phi, 1)?;
    let wo = view(m, theta_o, phi_o)?;
    Ok(lobe_grid::grid(m, wo, n_theta, n_phi))
}

/// The explorer's albedo curve: [`albedo::albedo_curve`] (RGB) at each of
/// `thetas_deg`, each checked as a view angle (the error names
/// `thetas_deg[i]`), with an `n × n` grid (`n` at least 1).
pub fn albedo_curve(
    m: &Material,
    thetas_deg: &[f64],
    phi_deg: f64,
    n: usize,
) -> Result<Vec<[f64; 3]>, String> {
    let n = at_least("n", n, 1)?;
    for (i, &t) in thetas_deg.iter().enumerate() {
        m.view_direction(t, phi_deg)
            .map_err(|e| e.named(&format!("thetas_deg[{i}]"), "phi_deg"))?;
    }
    Ok(albedo::albedo_curve(m, thetas_deg, phi_deg, n)
        .into_iter()
        .map(|c| [c.x, c.y, c.z])
        .collect())
}

/// [`warp`]'s warp test.
#[derive(Debug, Clone, PartialEq)]
pub struct Warp {
    /// Draws in each pixel of the projected hemisphere: `res × res`
    /// row-major (row 0 at `y = −1`, column 0 at `x = −1`), the upper
    /// hemisphere's grid then, with `sphere`, the lower one's.
    pub observed: Vec<f64>,
    /// The counts the pdf expects there, laid out as `observed`.
    pub expected: Vec<f64>,
    pub res: usize,
    /// Two grids (the material transmits, or is seen from below).
    pub sphere: bool,
    /// The chi-square test over the sphere (`lobe::experiment::warp_test::INTERACTIVE_BINS`²
    /// bins): statistic, degrees of freedom, p-value and message.
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    pub message: Option<String>,
}

/// The explorer's warp test of strategy `strategy` at the view `theta_o`,
/// `phi_o` (degrees): `samples` draws into a `res × res` histogram and the
/// chi-square test over the sphere with [`interactive_config`]'s settings,
/// from `seed` (`None`: [`interactive_config`]'s seed, the
/// explorer's).
pub fn warp(
    m: &Material,
    strategy: &str,
    theta_o: f64,
    phi_o: f64,
    samples: usize,
    res: usize,
    seed: Option<u64>,
) -> Result<Warp, String> {
    let samples = at_least("samples", samples, 1)?;
    let res = at_least("res", res, 1)?;
    let sp = sampler(m, strategy)?;
    let wo = view(m, theta_o, phi_o)?;
    let base = interactive_config(m, samples);
    let config = Chi2Settings {
        seed: seed.unwrap_or(base.seed),
        ..base
    };
    let w = lobe::experiment::warp_test::warp_test(&sp, wo, config, res, &());
    Ok(Warp {
        observed: w.histograms.observed,
        expected: w.histograms.expected,
        res: w.histograms.res,
        sphere: w.histograms.sphere,
        statistic: w.chi2.statistic,
        dof: w.chi2.dof,
        p_value: w.chi2.p_value,
        message: w.chi2.message,
    })
}

/// The explorer's weight heat map of strategy `strategy` at the view
/// `theta_o`, `phi_o` (degrees): [`weight_pixels`] over a `res × res` grid
/// (two over the sphere, laid out as [`Warp::observed`]), NaN where the
/// pixel is outside the disk or the strategy never samples it, 0 where
/// `f = 0`. Returns the values and whether there are two grids.
pub fn weight_map(
    m: &Material,
    strategy: &str,
    theta_o: f64,
    phi_o: f64,
    res: usize,
) -> Result<(Vec<f64>, bool), String> {
    let res = at_least("res", res, 1)?;
    let sp = sampler(m, strategy)?;
    let wo = view(m, theta_o, phi_o)?;
    let v: Vec<f64> = weight_pixels(&sp, wo, res)
        .into_iter()
        .map(|p| match p {
            WeightPixel::Weight(x) => x,
            WeightPixel::ZeroF => 0.0,
            WeightPixel::Outside | WeightPixel::Unsampled => f64::NAN,
        })
        .collect();
    let sphere = v.len() == 2 * res * res;
    Ok((v, sphere))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(json: &str) -> Material {
        Material::load(json).unwrap()
    }

    #[test]
    fn view_angles_as_the_explorer_checks_them() {
        let opaque = load(r#"{"type":"diffuse"}"#);
        let glass = load(r#"{"type":"roughdielectric","alpha":0.2}"#);
        let two = load(r#"{"type":"twosided","bsdf":{"type":"diffuse"}}"#);
        for t in [0.0, 45.0, 89.9] {
            assert!(view(&opaque, t, 0.0).is_ok(), "{t}");
        }
        for t in [-1.0, 90.0, 95.0, 180.0, f64::NAN] {
            let e = view(&opaque, t, 0.0).unwrap_err();
            assert!(e.starts_with("theta_o ") && e.contains("[0, 90)"), "{e}");
        }
        for m in [&glass, &two] {
            assert!(view(m, 135.0, 10.0).is_ok() && view(m, 180.0, 0.0).is_ok());
            let e = view(m, 90.0, 0.0).unwrap_err();
            assert!(e.contains("(90, 180]"), "{e}");
            assert!(view(m, 180.5, 0.0).is_err());
        }
        assert!(
            view(&opaque, 30.0, f64::INFINITY)
                .unwrap_err()
                .starts_with("phi_o ")
        );
        let e = albedo_curve(&opaque, &[0.0, 90.0], 0.0, 4).unwrap_err();
        assert!(e.starts_with("thetas_deg[1] 90"), "{e}");
    }

    #[test]
    fn shapes_and_strategies() {
        let m = load(r#"{"type":"roughconductor","alpha":0.3}"#);
        let p = polar(&m, 40.0, 0.0, 8).unwrap();
        assert!(!p.full_circle && p.theta.len() == 9 && p.fcos.len() == 9);
        let names: Vec<&str> = p.pdfs.iter().map(|x| x.0).collect();
        let want: Vec<&str> = m.strategies().iter().map(|s| s.name()).collect();
        assert_eq!(names, want);
        let g = lobe_grid(&m, 40.0, 0.0, 3, 4).unwrap();
        assert_eq!(g.values.len(), 4 * 5);
        let w = warp(&m, "vndf", 40.0, 0.0, 2000, 6, Some(1)).unwrap();
        assert_eq!(
            (w.observed.len(), w.expected.len(), w.sphere),
            (36, 36, false)
        );
        let (v, sphere) = weight_map(&m, "vndf", 40.0, 0.0, 8).unwrap();
        assert!(!sphere && v.len() == 64 && v[0].is_nan());
        let e = warp(&m, "nope", 40.0, 0.0, 100, 4, None).unwrap_err();
        assert!(e.starts_with("strategy `nope`: "), "{e}");
        let lambert = load(r#"{"type":"diffuse"}"#);
        let e = weight_map(&lambert, "vndf", 40.0, 0.0, 8).unwrap_err();
        assert!(e.contains("strategy `vndf`"), "{e}");
        assert!(polar(&m, 40.0, 0.0, 0).unwrap_err().starts_with("steps 0"));
        let glass = load(r#"{"type":"roughdielectric","alpha":0.2}"#);
        let (v, sphere) = weight_map(&glass, "vndf", 40.0, 0.0, 8).unwrap();
        assert!(sphere && v.len() == 128);
    }
}
