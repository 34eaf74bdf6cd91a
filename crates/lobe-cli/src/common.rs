//! Pieces shared by the commands: view and light arguments, progress bars
//! and output names.

use anyhow::{Result, anyhow, bail};
use clap::Args;
use glam::DVec3;
use indicatif::{ProgressBar, ProgressStyle};
use lobe::estimator::ShadingPoint;
use lobe::progress::Progress;
use lobe::{Frame, Light};
use std::path::{Path, PathBuf};

/// `--theta DEG` or `--wo x,y,z`: the view direction in the local frame.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// View angle from the normal in degrees, in [0, 90): wo = (sin θ, 0,
    /// cos θ); up to 180 (below the surface, seen from inside) for a
    /// material that transmits or is two-sided
    #[arg(long, conflicts_with = "wo", allow_hyphen_values = true)]
    pub theta: Option<f64>,
    /// View direction x,y,z in the local frame (+z is the normal); normalized
    #[arg(long, allow_hyphen_values = true)]
    pub wo: Option<String>,
}

impl ViewArgs {
    /// The unit view direction; 30° when neither flag is given. Below the
    /// horizon only where `m` scatters from there (it transmits, or is
    /// two-sided); never on it.
    pub fn wo(&self, m: &lobe::Material) -> Result<DVec3> {
        let below_ok = m.reach().transmits || m.two_sided;
        if let Some(w) = &self.wo {
            let v = parse_vec3("--wo", w)?;
            if v.z == 0.0 {
                bail!("--wo {w}: the view direction is on the horizon (z must not be 0)");
            }
            if v.z < 0.0 && !below_ok {
                bail!(
                    "--wo {w}: the view direction is below the horizon (z must be > 0 in the local frame; below it only for a material that transmits or is two-sided)"
                );
            }
            return Ok(v.normalize());
        }
        let t = self.theta.unwrap_or(30.0);
        if below_ok && t.is_finite() && t > 90.0 && t <= 180.0 {
            let r = t.to_radians();
            return Ok(DVec3::new(r.sin(), 0.0, r.cos()));
        }
        theta_to_wo(t).map_err(|e| {
            if below_ok {
                anyhow!("{e}, or in (90, 180] from inside")
            } else {
                e
            }
        })
    }
}

/// `wo = (sin θ, 0, cos θ)` for θ in degrees, refusing θ outside [0, 90).
pub fn theta_to_wo(theta: f64) -> Result<DVec3> {
    if !theta.is_finite() || !(0.0..90.0).contains(&theta) {
        bail!("--theta {theta}: the view angle must be in [0, 90) degrees");
    }
    let t = theta.to_radians();
    Ok(DVec3::new(t.sin(), 0.0, t.cos()))
}

/// Parse `x,y,z` into a non-zero finite vector.
pub fn parse_vec3(flag: &str, s: &str) -> Result<DVec3> {
    lobe_render::light_spec::parse_vec3(flag, s).map_err(|e| anyhow!(e))
}

/// `--light`, `--normal`, `--tangent`: incident light at the shading point.
#[derive(Args, Debug, Clone)]
pub struct LightArgs {
    /// Lighting: `constant[:VALUE]` (the furnace, default 1);
    /// `beam[:K[:X,Y,Z[:VALUE]]]`, radiance VALUE·max(0, ω·d)^K toward the
    /// world direction d (default K = 8, d = 0,1,0.5 normalized, VALUE = 1);
    /// `sky[:ELEVATION[:AZIMUTH]]`, the built-in sky with a sun (default 35°
    /// above the horizon, azimuth 40°); or an equirectangular environment
    /// map FILE.hdr / FILE.exr, any case (Mitsuba's convention, world +Y up)
    #[arg(long, default_value = "constant", allow_hyphen_values = true)]
    pub light: String,
    /// World-space normal: local z
    #[arg(long, default_value = "0,1,0", allow_hyphen_values = true)]
    pub normal: String,
    /// World-space tangent: local x (local y = normal × tangent)
    #[arg(long, default_value = "1,0,0", allow_hyphen_values = true)]
    pub tangent: String,
}

impl LightArgs {
    pub fn frame(&self) -> Result<Frame> {
        let n = parse_vec3("--normal", &self.normal)?;
        let t = parse_vec3("--tangent", &self.tangent)?;
        Frame::from_normal_tangent(n, t).ok_or_else(|| {
            anyhow!(
                "--tangent {} is parallel to --normal {}",
                self.tangent,
                self.normal
            )
        })
    }

    /// The light. An analytic light is given in the local frame (its
    /// world direction taken there by `--normal` and `--tangent`); an
    /// environment map in the world.
    pub fn light(&self) -> Result<Light> {
        parse_light(&self.light, &self.frame()?)
    }

    /// The shading point of `light` ([`LightArgs::light`]) with view `wo`:
    /// the frame of `--normal` and `--tangent` under an environment map, the
    /// local frame itself under an analytic light (which is given in it).
    pub fn shading_point(&self, light: &Light, wo: DVec3) -> Result<ShadingPoint> {
        Ok(match light {
            Light::Env(_) => ShadingPoint {
                frame: self.frame()?,
                wo,
            },
            _ => ShadingPoint::local(wo),
        })
    }
}

/// Parse a light description (see [`LightArgs`] and
/// [`lobe_render::light_spec`]); an analytic light's direction is taken to
/// the local `frame`. Warnings of loading a map are printed.
pub fn parse_light(spec: &str, frame: &Frame) -> Result<Light> {
    let parsed =
        lobe_render::light_spec::parse_light("--light", spec, frame).map_err(|e| anyhow!(e))?;
    for w in &parsed.warnings {
        eprintln!("lobe: warning: {w}");
    }
    Ok(parsed.light)
}

/// Parse a count: digits (`65536`, `65_536`), a power `B^E` (`2^20`) or
/// scientific notation (`1e6`, `1.5e3`) whose value is a whole number from
/// `min` to `max`. `what` names the unit in errors ("samples").
pub fn parse_count(s: &str, min: u64, max: u64, what: &str) -> Result<u64, String> {
    let t = s.trim().replace('_', "");
    let out_of_range = || format!("`{s}` is too large: {what} must be from {min} to {max}");
    let value: u64 = if let Some((b, e)) = t.split_once('^') {
        let (b, e): (u64, u32) = match (b.parse(), e.parse()) {
            (Ok(b), Ok(e)) => (b, e),
            _ => {
                return Err(format!(
                    "`{s}`: expected B^E with whole numbers B and E, e.g. 2^20"
                ));
            }
        };
        b.checked_pow(e).ok_or_else(out_of_range)?
    } else if t.bytes().all(|c| c.is_ascii_digit()) && !t.is_empty() {
        t.parse().map_err(|_| out_of_range())?
    } else {
        let x: f64 = t.parse().map_err(|_| {
            format!(
                "`{s}` is not a count of {what}: expected a whole number such as 65536, 1e6 or 2^20"
            )
        })?;
        if !x.is_finite() || x < 0.0 {
            return Err(format!(
                "`{s}`: a count of {what} must be a finite number >= 0"
            ));
        }
        if x.fract() != 0.0 {
            return Err(format!("`{s}` = {x} is not a whole number of {what}"));
        }
        if x >= 18_446_744_073_709_551_615.0 {
            return Err(out_of_range());
        }
        x as u64
    };
    if value > max {
        return Err(out_of_range());
    }
    if value < min {
        return Err(format!(
            "`{s}` is too small: {what} must be from {min} to {max}"
        ));
    }
    Ok(value)
}

/// [`parse_count`] of samples as a `usize` (clap value parser).
pub fn samples_usize(s: &str) -> Result<usize, String> {
    parse_count(s, 0, usize::MAX as u64, "samples").map(|v| v as usize)
}

/// [`parse_count`] of samples per pixel as a `u64` (clap value parser).
pub fn spp_u64(s: &str) -> Result<u64, String> {
    parse_count(s, 0, u64::MAX, "samples per pixel")
}

/// [`parse_count`] of samples per pixel as a `u32` (clap value parser).
pub fn spp_u32(s: &str) -> Result<u32, String> {
    parse_count(s, 0, u64::from(u32::MAX), "samples per pixel").map(|v| v as u32)
}

/// Load a material (JSON text, @file.json or @file.toml) and warn once on
/// stderr when it reflects more light than it receives.
pub fn load_material(spec: &str) -> Result<lobe::Material> {
    let m = lobe::Material::load(spec)?;
    warn_energy_gain(&m, "the material");
    Ok(m)
}

/// Refuse a material that `command` cannot show yet: one that transmits
/// or has a delta part (its figures and tables are of the hemisphere of
/// reflection, which would leave part of it out without a word).
pub fn refuse_transmission(m: &lobe::Material, command: &str) -> Result<()> {
    let reach = m.reach();
    if reach.transmits || reach.delta {
        bail!(
            "--material: {command} does not yet take {} ({} {}; issue 42's next part): `lobe estimate` and `lobe converge` do",
            m.model_name(),
            m.model_name(),
            if reach.transmits {
                "transmits"
            } else {
                "has a delta part"
            }
        );
    }
    Ok(())
}

/// Refuse a material whose scattering is all delta (a smooth mirror,
/// smooth or thin glass) for a figure of densities (`plot`, `report`): it
/// has no curve, no histogram and no weight map to draw.
pub fn refuse_all_delta(m: &lobe::Material, wo: glam::DVec3) -> Result<()> {
    if m.reach().delta && lobe::experiment::polar::albedo(m, wo) == 0.0 {
        bail!(
            "--material: {} scatters only into single directions (delta lobes: a mirror reflection, smooth refraction), which have no density to draw or to test; `lobe estimate` and `lobe eval` take it",
            m.model_name()
        );
    }
    Ok(())
}

/// [`warn_energy_gain`] for every object of a scene loaded from `path`,
/// named by its place among the file's `[[object]]` tables.
pub fn warn_scene_energy_gain(scene: &lobe_render::Scene, path: &std::path::Path) {
    for (i, o) in scene.objects.iter().enumerate() {
        warn_energy_gain(
            &o.material,
            &format!("{}: object {}'s material", path.display(), i + 1),
        );
    }
}

/// Warn once on stderr when `m` reflects more than it receives: its largest
/// directional albedo ([`lobe::experiment::variance::max_albedo`]) is above 1.
pub fn warn_energy_gain(m: &lobe::Material, what: &str) {
    // A Lambertian term and a Cook-Torrance lobe reflect at most kd + ks
    // (a microfacet lobe's single scattering and every Fresnel term are at
    // most 1): where that bound is at most 1 the quadrature (about a second
    // for a Beckmann lobe, paid at every start-up) cannot find a gain.
    // Mitsuba's models scatter at most their largest tint: a mirror's
    // Fresnel term is at most 1, glass splits the flux into R + T = 1 at
    // most, and plastic's base sends out at most the (1 − F) its coating
    // lets in (the internal reflections' series sums to at most 1 for
    // ρ ≤ 1).
    use lobe::Glossy;
    let ks = match &m.glossy {
        Glossy::None => Some(lobe::Rgb::ZERO),
        Glossy::CookTorrance(ct) => Some(ct.ks),
        Glossy::Conductor(c) => Some(c.specular_reflectance),
        Glossy::Dielectric(d) => Some(d.specular_reflectance.max(d.specular_transmittance)),
        Glossy::ThinDielectric(d) => Some(d.specular_reflectance.max(d.specular_transmittance)),
        Glossy::RoughDielectric(d) => Some(d.specular_reflectance.max(d.specular_transmittance)),
        Glossy::Plastic(p) => Some(p.specular_reflectance.max(p.diffuse_reflectance)),
        Glossy::RoughPlastic(p) => Some(p.coating.ks.max(p.diffuse_reflectance)),
        Glossy::Phong(_) | Glossy::BlinnPhong(_) | Glossy::Measured(_) => None,
    };
    if ks.is_some_and(|ks| (m.diffuse.albedo + ks).max_element() <= 1.0) {
        return;
    }
    let a = lobe::experiment::variance::max_albedo(m);
    if a.gains_energy() {
        // Cook-Torrance without a Fresnel term (Mitsuba's default) reflects
        // all of ks at every angle: the usual cause.
        let hint = match &m.glossy {
            lobe::Glossy::CookTorrance(ct) if ct.fresnel == lobe::Fresnel::None => {
                "lower kd or ks, or give the Cook-Torrance lobe a fresnel term: its default, none, is F = 1"
            }
            _ => "lower kd or ks",
        };
        eprintln!(
            "lobe: warning: {what} reflects more light than it receives: its directional albedo is {:.3} at θo = {}° (above 1, so it gains energy; {hint})",
            a.albedo, a.theta_deg
        );
    }
}

pub use lobe::strategy::description as strategy_description;

/// Every strategy name with its description ([`strategy_description`]):
/// the one text of `--strategy` in `estimate`, `converge`, `render` and
/// `compare`.
#[must_use]
pub fn strategy_help() -> String {
    lobe::estimator::Strategy::names()
        .split(", ")
        .map(|n| {
            format!(
                "{n}: {}",
                strategy_description(n).unwrap_or("(no description)")
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// Per-sample standard deviation, relative to the mean, below which a
/// measured variance is rounding and not noise: such an estimator is exact
/// (every sample gives the integral, as BRDF sampling of a Lambert surface
/// under a constant light does), and its variance, its slope and any ratio
/// against it are printed as exact, not as the rounding's numbers.
pub const EXACT_RELATIVE_SD: f64 = 1e-10;

/// Whether a per-sample `variance` of an estimate of `mean` is zero up to
/// rounding ([`EXACT_RELATIVE_SD`]).
#[must_use]
pub fn is_exact(variance: f64, mean: f64) -> bool {
    variance <= (EXACT_RELATIVE_SD * mean).powi(2)
}

/// Whether a table row is exact ([`is_exact`] of its luminance).
#[must_use]
pub fn row_is_exact(row: &lobe::experiment::table::Row) -> bool {
    is_exact(
        row.variance,
        lobe::math::luminance(lobe::Rgb::from_array(row.mean)),
    )
}

/// The rows of `t` whose variance is rounding ([`row_is_exact`]) with their
/// variance and standard error set to 0 and no variance reduction or
/// efficiency (both infinite), so that tables and JSON print exact values,
/// not the rounding's (a variance of 3e-33, a reduction of 7e31×).
pub fn zero_exact_rows(t: &mut lobe::experiment::table::Table) {
    for row in &mut t.strategies {
        if row_is_exact(row) {
            row.variance = 0.0;
            row.stderr = [0.0; 3];
            row.variance_reduction = None;
            row.efficiency = None;
        }
    }
}

/// Seconds between the plain progress lines written when stderr is not a
/// terminal (a log, CI, a pipe), where indicatif draws nothing.
pub const PLAIN_PROGRESS_EVERY_S: f64 = 5.0;

/// The time left, or `?` until it can be told: before a second has passed
/// or anything is done, indicatif's estimate is nonsense (`0s<3w`).
fn eta_text(state: &indicatif::ProgressState) -> String {
    let elapsed = state.elapsed().as_secs_f64();
    let pos = state.pos();
    match state.len() {
        Some(len) if pos > 0 && elapsed >= 1.0 && len >= pos => {
            let left = elapsed * (len - pos) as f64 / pos as f64;
            format!(
                "{}",
                indicatif::HumanDuration(std::time::Duration::from_secs_f64(left))
            )
        }
        _ => "?".to_string(),
    }
}

/// The progress style of every bar: `{eta_left}` is [`eta_text`].
pub fn progress_style(template: &str) -> ProgressStyle {
    ProgressStyle::with_template(template)
        .expect("progress template is valid")
        .with_key(
            "eta_left",
            |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&eta_text(state));
            },
        )
        .progress_chars("=> ")
}

/// A progress bar on stderr, hidden with `--quiet`. On a terminal
/// indicatif draws it; otherwise (indicatif draws nothing there) a thread
/// writes one plain line every [`PLAIN_PROGRESS_EVERY_S`] seconds while the
/// bar lives: `lobe: rendering: 45% (1.2M of 2.6M), 12s, about 15s left`.
pub fn progress(len: u64, message: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(len);
    pb.set_style(progress_style(
        "{msg:>20} [{wide_bar}] {human_pos}/{human_len} {elapsed}<{eta_left}",
    ));
    pb.set_message(message.to_string());
    if !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        plain_lines(&pb);
    }
    pb
}

/// Writes a plain progress line of `pb` every [`PLAIN_PROGRESS_EVERY_S`]
/// seconds until it is finished or dropped.
pub fn plain_lines(pb: &ProgressBar) {
    let weak = pb.downgrade();
    // LOBE_PROGRESS_EVERY=SECONDS changes the interval (the tests use it).
    let every = std::env::var("LOBE_PROGRESS_EVERY")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v > 0.0)
        .unwrap_or(PLAIN_PROGRESS_EVERY_S);
    let every = std::time::Duration::from_secs_f64(every);
    let _ = std::thread::Builder::new()
        .name("lobe-progress".into())
        .spawn(move || {
            loop {
                std::thread::sleep(every);
                let Some(pb) = weak.upgrade() else { return };
                if pb.is_finished() {
                    return;
                }
                let state = format!(
                    "{} {}",
                    pb.message(),
                    match pb.length() {
                        Some(len) if len > 0 => format!(
                            "{:.0}% ({} of {})",
                            100.0 * pb.position() as f64 / len as f64,
                            indicatif::HumanCount(pb.position()),
                            indicatif::HumanCount(len)
                        ),
                        _ => format!("{}", indicatif::HumanCount(pb.position())),
                    }
                );
                let elapsed = indicatif::HumanDuration(pb.elapsed());
                let left = match pb.length() {
                    Some(len) if pb.position() > 0 && len >= pb.position() => {
                        let e = pb.elapsed().as_secs_f64();
                        let left = e * (len - pb.position()) as f64 / pb.position() as f64;
                        format!(
                            ", about {} left",
                            indicatif::HumanDuration(std::time::Duration::from_secs_f64(left))
                        )
                    }
                    _ => String::new(),
                };
                eprintln!("lobe: {}: {elapsed}{left}", state.trim());
            }
        });
}

/// A [`Progress`] shown as an indicatif bar on stderr (hidden with
/// `--quiet`): each task the library starts resets the bar to its label and
/// length.
pub struct Bar(pub ProgressBar);

impl Bar {
    /// A bar, hidden when `quiet`.
    #[must_use]
    pub fn new(quiet: bool) -> Self {
        Bar(progress(0, "", quiet))
    }

    /// Remove the bar from the terminal.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Progress for Bar {
    fn start(&self, label: &str, total: u64) {
        self.0.reset();
        self.0.set_length(total);
        self.0.set_message(label.to_string());
    }

    fn advance(&self, n: u64) {
        self.0.inc(n);
    }
}

/// Prepares the output directory `dir` of `flag` before any work: creates
/// it (and its parents) when missing, and checks that a file can be
/// written in it. The one check of every command's outputs, so that a
/// long computation is never lost to a path it cannot write.
pub fn prepare_output_dir(flag: &str, dir: &Path) -> Result<()> {
    let shown = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if shown.exists() && !shown.is_dir() {
        bail!("{flag} {}: is a file, not a directory", shown.display());
    }
    std::fs::create_dir_all(shown).map_err(|e| {
        anyhow!(
            "{flag} {}: cannot create the directory: {e}",
            shown.display()
        )
    })?;
    let probe = shown.join(format!(".lobe-write-probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| {
        anyhow!(
            "{flag} {}: cannot write in the directory: {e}",
            shown.display()
        )
    })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Prepares the output files `files` of `flag` before any work: their
/// directories as [`prepare_output_dir`] does, and none of them an existing
/// directory.
pub fn prepare_output_files(flag: &str, files: &[PathBuf]) -> Result<()> {
    for f in files {
        if f.is_dir() {
            bail!("{flag}: {} is a directory, not a file name", f.display());
        }
        prepare_output_dir(flag, f.parent().unwrap_or(Path::new("")))?;
    }
    Ok(())
}

/// An error that ends the program with `status` and no message of its own
/// (the command said what happened): `main` exits with it.
#[derive(Debug)]
pub struct ExitStatus(pub u8);

impl std::fmt::Display for ExitStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "exit status {}", self.0)
    }
}

impl std::error::Error for ExitStatus {}

/// The SIMD level `LOBE_SIMD` asks for, checked before any work: an unknown
/// name or a level this CPU lacks is an error naming the variable (not a
/// note of a fallback deep in the render).
pub fn check_simd_env() -> Result<()> {
    lobe::batch::SimdLevel::from_env().map(|_| ()).map_err(|e| {
        anyhow!(
            "LOBE_SIMD={}: {e}",
            std::env::var("LOBE_SIMD").unwrap_or_default()
        )
    })
}

/// `base` with `.ext` appended (keeping any dots already in the name).
#[must_use]
pub fn with_ext(base: &Path, ext: &str) -> PathBuf {
    let mut s = base.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// The base name of a command's output files: `--out NAME` with a trailing
/// extension from `written` dropped, or else the scene file's stem followed
/// by `suffix`, in the current directory.
pub fn output_base(
    out: Option<&Path>,
    scene: &Path,
    written: &[&str],
    suffix: &str,
) -> Result<PathBuf> {
    if let Some(p) = out {
        let ext = p
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        return Ok(if ext.is_some_and(|e| written.contains(&e.as_str())) {
            p.with_extension("")
        } else {
            p.to_path_buf()
        });
    }
    let stem = scene.file_stem().ok_or_else(|| {
        anyhow!(
            "{}: cannot name the output after the scene file; give --out NAME",
            scene.display()
        )
    })?;
    let mut s = stem.to_owned();
    s.push(suffix);
    Ok(PathBuf::from(s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_technique_has_a_description() {
        for n in lobe::estimator::Strategy::names().split(", ") {
            assert!(strategy_description(n).is_some(), "{n}");
        }
        assert!(strategy_help().contains(lobe::strategy::MIS_DESCRIPTION));
    }
}
