//! `lobe render`: render a scene file to OpenEXR and PNG.

use crate::common::progress;
use anyhow::{Result, anyhow, bail};
use clap::Args;
use lobe::estimator::Strategy;
use lobe_render::SppAllocation;
use lobe_render::integrator::{
    MAX_SPP_FACTOR, RenderLoop, batch_refusal, max_pixel_spp, render_until,
};
use lobe_render::{fallbacks, load_scene};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// The arguments of `lobe render`.
#[derive(Args, Debug)]
#[command(
    about = "Render a scene under an environment map to NAME.exr and NAME.png",
    long_about = "Render a scene file: spheres, planes and OBJ meshes with lobe materials, lit by an \
                  environment map (the only light), seen by a pinhole camera. Each camera ray's hit \
                  estimates the reflected radiance with the chosen strategy exactly as `lobe estimate` \
                  does, plus a shadow ray: a BSDF sampling strategy, `light` (environment-map sampling) \
                  or MIS (see --strategy; `mis`, the default, is adaptive MIS). A BSDF strategy that \
                  does not apply to an object's material (vndf on a Phong sphere, say) falls back to \
                  brdf for that object, with a note. max_depth > 1 in the scene adds path tracing.\n\n\
                  Writes NAME.exr (linear RGB, 32-bit float) and NAME.png (scaled by 2^--exposure, \
                  a filmic curve (ACES fit) on luminance that keeps each pixel's hue, sRGB-encoded, \
                  8 bits). Every pixel has its own randomization of the sample pattern (--sequence: \
                  Owen-scrambled Sobol by default, in its own dimensions for the pixel position, each \
                  BSDF and light draw and each bounce), so the image is the same for any --threads. \
                  --time renders whole passes until the time is up. The samples are shared out \
                  among the pixels by their noise, as a pilot estimates it (--spp-allocation \
                  variance, the default; the same total; NAME.spp.png shows where they went): the \
                  fastest way to a clean image where a few pixels (a highlight, an edge) hold most \
                  of the noise; --spp-allocation uniform gives every pixel --spp.\n\n\
                  Ctrl-C (SIGINT) or SIGTERM stops the render within a block of samples: the passes \
                  finished so far are written (a --time render's; the spp done in the EXR's \
                  `spp` attribute and on stderr) and lobe exits with 130 (SIGINT) or 143 \
                  (SIGTERM); if no pass finished (a render without --time is one pass), nothing \
                  is written. A second Ctrl-C ends lobe at once.",
    after_help = "Example:\n  lobe render examples/scene.toml --spp 16 --strategy mis-power --out preview",
    after_long_help = SCENE_HELP
)]
pub struct RenderArgs {
    /// The scene file (TOML; `lobe render --help` shows the format)
    pub scene: PathBuf,
    /// Samples per pixel, 1 to 2^64 − 1, such as 64, 1e3 or 2^10 (overrides
    /// the scene's render.spp)
    #[arg(long, value_parser = crate::common::spp_u64)]
    pub spp: Option<u64>,
    #[arg(long, help = strategy_help())]
    pub strategy: Option<String>,
    /// Seed of the random streams (overrides the scene's render.seed)
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sample pattern in every dimension of a pixel's samples: sobol
    /// (Owen-scrambled, the default), stratified or independent (overrides
    /// the scene's render.sequence)
    #[arg(long)]
    pub sequence: Option<String>,
    /// How the width × height × spp samples are shared out among the
    /// pixels: variance (the default: in proportion to each pixel's noise
    /// as a pilot of spp/8 (2 to 8) extra samples per pixel estimates it;
    /// at least spp/16 and at most 64 × spp per pixel; the same total;
    /// NAME.spp.png shows the counts) or uniform (spp each) (overrides the
    /// scene's render.spp_allocation)
    #[arg(long, value_name = "ALLOCATION")]
    pub spp_allocation: Option<String>,
    /// Render whole passes of --spp samples per pixel until SECONDS have
    /// passed (at least one pass), and print the spp reached; the image
    /// depends only on the number of passes
    #[arg(long, value_name = "SECONDS")]
    pub time: Option<f64>,
    /// Worker threads (default: one per core)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// The loop that renders: batch (the default: blocks of samples on the
    /// f32 SIMD kernels of lobe::batch, direct lighting; a scene or
    /// strategy it does not cover is rendered by the scalar loop, with a
    /// note) or scalar (the f64 reference loop)
    #[arg(long = "loop", value_name = "LOOP")]
    pub render_loop: Option<String>,
    /// Output name: writes NAME.exr (linear) and NAME.png (tone-mapped,
    /// sRGB) (default: the scene file's stem, in the current directory)
    #[arg(long, value_name = "NAME")]
    pub out: Option<PathBuf>,
    /// Exposure of the PNG in stops: the linear image times 2^EV before the
    /// tone curve (the EXR stays linear)
    #[arg(
        long,
        value_name = "EV",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub exposure: f64,
    /// No progress bar and no notes
    #[arg(long, short)]
    pub quiet: bool,
}

const SCENE_HELP: &str = "\
Scene file (TOML; unknown keys are errors; paths are relative to the scene file):
  [camera]
  origin = [0, 1, 4]
  target = [0, 1, 0]
  up = [0, 1, 0]       # default [0, 1, 0]
  fov_y = 40           # vertical, degrees, in (0, 180); default 40
  width = 320          # 1 to 16384; default 320
  height = 240         # 1 to 16384; default 240

  [environment]
  path = \"forest.hdr\"  # .hdr or .exr (equirectangular, +Y up), or \"sky\"
  # or, instead of path, the built-in sky with its sun placed, in degrees
  # (as --light sky:E:A takes them: elevation in [0, 90] above the horizon,
  # azimuth 0 toward -Z; a key left out takes the built-in sky's 35 and 40,
  # as path = \"sky\" does):
  # sky = { sun_elevation = 20, sun_azimuth = 120 }
  scale = 1.0          # default 1
  rotation_y = 0.0     # degrees about +Y; default 0

  [[object]]           # any number of them
  type = \"sphere\"      # sphere: center, radius
  center = [0, 1, 0]   # plane: point, normal
  radius = 1           # mesh: path (Wavefront OBJ)
  material = { type = \"cook-torrance\", distribution = \"ggx\", alpha = 0.3 }

  [render]             # every key optional
  spp = 64
  strategy = \"mis\"     # a --strategy name; default mis (adaptive MIS)
  seed = 1
  sequence = \"sobol\"   # sobol (default), stratified or independent
  max_depth = 1        # 1 = direct lighting; more adds bounces
  spp_allocation = \"variance\"  # variance (default) or uniform

Materials take the keys of `lobe eval --help`.

Examples:
  lobe render examples/scene.toml
  lobe render examples/scene.toml --spp 16 --strategy light --out light-16
  lobe render examples/scene.toml --threads 1 --seed 7 --quiet
  lobe render examples/scene.toml --spp 4 --time 2 --sequence sobol
  lobe render examples/scene.toml --spp 16 --spp-allocation variance";

/// The help of `--strategy`: every accepted name.
fn strategy_help() -> String {
    format!(
        "One strategy (overrides the scene's render.strategy; default mis). {}",
        crate::common::strategy_help()
    )
}

/// Run `lobe render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    let base = crate::common::output_base(args.out.as_deref(), &args.scene, &["exr", "png"], "")?;
    crate::common::prepare_output_files(
        "--out",
        &["exr", "png", "spp.png"].map(|e| crate::common::with_ext(&base, e)),
    )?;
    if !args.exposure.is_finite() || args.exposure.abs() > 64.0 {
        bail!(
            "--exposure {}: must be a number of stops in [-64, 64]",
            args.exposure
        );
    }
    if args.spp == Some(0) {
        bail!("--spp 0: at least 1 sample per pixel");
    }
    let method: Option<Strategy> = match &args.strategy {
        Some(s) => Some(s.parse().map_err(|m| anyhow!("--strategy: {m}"))?),
        None => None,
    };
    // `--threads` for all of the command's work, the map's loading too:
    // rayon's global pool, which the render then runs on (a pool of the
    // same size, see `RenderSettings::threads`).
    if let Some(n) = args.threads {
        // (Fails only if the pool exists already; the render then starts a
        // pool of its own, of `n` threads.)
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global();
    }
    let mut scene = load_scene(&args.scene)?;
    crate::common::warn_scene_energy_gain(&scene, &args.scene);
    let mut opts = scene.settings;
    if let Some(n) = args.spp {
        opts.spp = n;
    }
    if let Some(m) = method {
        opts.strategy = m;
    }
    if let Some(s) = args.seed {
        opts.seed = s;
    }
    if let Some(s) = &args.sequence {
        opts.sequence = crate::estimate::parse_sequence(s)?;
    }
    if let Some(a) = &args.spp_allocation {
        opts.spp_allocation = a.parse().map_err(|m| anyhow!("--spp-allocation: {m}"))?;
    }
    let budget = match args.time {
        None => None,
        Some(t) if t.is_finite() && t > 0.0 && t <= 1e7 => {
            Some(std::time::Duration::from_secs_f64(t))
        }
        Some(t) => bail!("--time {t}: must be a number of seconds in (0, 1e7]"),
    };
    opts.threads = args.threads.map(|t| t as usize);
    if let Some(l) = &args.render_loop {
        opts.render_loop = l.parse().map_err(|m| anyhow!("--loop: {m}"))?;
    }
    scene.settings = opts;
    for w in &scene.warnings {
        eprintln!("lobe: warning: {w}");
    }
    if let Some(n) = lobe_render::integrator::shallow_glass(&scene, opts.max_depth) {
        eprintln!("lobe: note: {n}");
    }
    if !args.quiet {
        for f in fallbacks(&scene, opts.strategy) {
            eprintln!(
                "lobe: note: object {} ({}): {} does not apply to its material, using {}",
                f.object, f.model, f.requested, f.used
            );
        }
    }
    let (w, h) = (scene.camera.width, scene.camera.height);
    let total = (u64::from(w) * u64::from(h))
        .checked_mul(opts.spp)
        .ok_or_else(|| {
            anyhow!(
                "--spp {}: {w}×{h} pixels × {} spp is more samples than fit in 64 bits",
                opts.spp,
                opts.spp
            )
        })?;
    if opts.sequence == lobe::sequence::Sequence::Sobol
        && max_pixel_spp(&opts) > lobe_render::integrator::SOBOL_MAX_SAMPLES
    {
        bail!(
            "--spp {}: the sobol sequence has 2^32 points per pixel{}; use fewer spp or --sequence stratified",
            opts.spp,
            match opts.spp_allocation {
                SppAllocation::Uniform => String::new(),
                SppAllocation::Variance =>
                    format!(" (the variance allocation gives a pixel up to {MAX_SPP_FACTOR} × spp)"),
            }
        );
    }
    // Said after every check of the arguments, so that an error stays one line.
    if !args.quiet
        && opts.render_loop == RenderLoop::Batch
        && let Some(why) = batch_refusal(&scene, opts.strategy, opts.max_depth)
    {
        eprintln!("lobe: note: the scalar loop renders this: {why}");
    }
    let pb = progress(total, "rendering", args.quiet);
    let template = if budget.is_some() {
        // Passes until the time is up: no known length.
        "{msg:>12} {spinner} {human_pos} samples, {per_sec}, {elapsed}"
    } else {
        "{msg:>12} [{wide_bar}] {human_pos}/{human_len} samples, {per_sec}, {elapsed}<{eta_left}"
    };
    pb.set_style(crate::common::progress_style(template));
    let interrupt = Interrupt::catch()?;
    let t0 = Instant::now();
    // Without --time, one pass of --spp; with it, passes until the time is
    // up. Either stops at the next row on a signal.
    let max_passes = if budget.is_some() { u64::MAX } else { 1 };
    let image = render_until(&scene, &opts, budget, max_passes, &interrupt.stop, |n| {
        pb.inc(n)
    });
    let secs = t0.elapsed().as_secs_f64();
    pb.finish_and_clear();
    let signal = interrupt.signal();
    let Some(image) = image else {
        let (name, status) = signal
            .ok_or_else(|| anyhow!("the render stopped before its first pass, with no signal"))?;
        eprintln!(
            "lobe: interrupted ({name}) after {secs:.1} s, before the first pass{} finished: nothing written",
            if budget.is_some() {
                format!(" of {} spp", opts.spp)
            } else {
                format!(
                    " (the whole render, {} spp; --time renders in passes)",
                    opts.spp
                )
            }
        );
        return Err(crate::common::ExitStatus(status).into());
    };
    if image.stats.nonfinite > 0 {
        eprintln!(
            "lobe: warning: {} path samples were not finite numbers and counted as 0",
            image.stats.nonfinite
        );
    }
    let exr = crate::common::with_ext(&base, "exr");
    let png = crate::common::with_ext(&base, "png");
    // Where the samples went, when the variance allocation placed them.
    let spp_png = crate::common::with_ext(&base, "spp.png");
    // The three files written at once on the pool's threads.
    let passes = image.stats.passes.max(1);
    let note = signal.map(|(name, _)| {
        format!(
            "interrupted ({name}): {} spp done, in passes of {}",
            passes * opts.spp,
            opts.spp
        )
    });
    let (png_written, (spp_written, exr_written)) = rayon::join(
        || {
            image.write_png(
                &png,
                &lobe_render::ToneMap {
                    exposure: args.exposure,
                },
            )
        },
        || {
            rayon::join(
                || image.write_spp_png(&spp_png),
                || image.write_exr_noted(&exr, note.as_deref()),
            )
        },
    );
    exr_written?;
    png_written?;
    let wrote_spp = spp_written?;
    let samples = image.stats.camera_rays as f64;
    let spp = if budget.is_some() {
        format!(
            "{} spp ({passes} passes of {})",
            passes * opts.spp,
            opts.spp
        )
    } else {
        format!("{} spp", opts.spp)
    };
    // (Per-pixel counts exist only under the variance allocation.)
    let spp = match &image.spp {
        Some(c) => format!(
            "{spp} on average, allocated by variance: {} to {} per pixel{}",
            c.iter().min().unwrap_or(&0),
            c.iter().max().unwrap_or(&0),
            if budget.is_some() { " per pass" } else { "" }
        ),
        None => spp,
    };
    let written = if wrote_spp {
        format!(
            "{}, {} and {} (samples per pixel)",
            exr.display(),
            png.display(),
            spp_png.display()
        )
    } else {
        format!("{} and {}", exr.display(), png.display())
    };
    if let Some((name, status)) = signal {
        // (The spp a pixel got on average: the variance allocation keeps
        // the total.)
        eprintln!(
            "lobe: interrupted ({name}) after {passes}{} passes ({} spp{}{}) in {secs:.1} s{}; wrote {written}",
            if budget.is_some() { "" } else { " of 1" },
            passes * opts.spp,
            if image.spp.is_some() {
                " on average"
            } else {
                ""
            },
            if budget.is_some() {
                format!(", {} a pass", opts.spp)
            } else {
                String::new()
            },
            match budget {
                Some(b) => format!(" of --time {}", b.as_secs_f64()),
                None => String::new(),
            },
        );
        return Err(crate::common::ExitStatus(status).into());
    }
    println!(
        "wrote {written} ({w}x{h}, {spp}, {}, {}, max_depth {}): {:.2} s, {:.2} M samples/s, {:.2} M rays/s",
        opts.sequence,
        opts.strategy,
        opts.max_depth,
        secs,
        samples / secs.max(1e-9) / 1e6,
        image.stats.rays as f64 / secs.max(1e-9) / 1e6
    );
    Ok(())
}

/// SIGINT and SIGTERM during a render: the first sets `stop`, which the
/// render reads at every block of samples (and records which signal it
/// was); a second
/// one ends the process at once with 128 + its number, as a shell expects.
/// The handlers stay until the process exits.
struct Interrupt {
    stop: Arc<AtomicBool>,
    /// The first signal's number (0: none).
    which: Arc<AtomicUsize>,
}

impl Interrupt {
    fn catch() -> Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use signal_hook::flag;
        let stop = Arc::new(AtomicBool::new(false));
        let which = Arc::new(AtomicUsize::new(0));
        for sig in [SIGINT, SIGTERM] {
            let err = |e| anyhow!("cannot catch signal {sig}: {e}");
            // In this order: a signal that finds `stop` set already exits;
            // else it records itself and sets `stop`.
            flag::register_conditional_shutdown(sig, 128 + sig, Arc::clone(&stop)).map_err(err)?;
            flag::register_usize(sig, Arc::clone(&which), sig as usize).map_err(err)?;
            flag::register(sig, Arc::clone(&stop)).map_err(err)?;
        }
        Ok(Interrupt { stop, which })
    }

    /// The signal that stopped the render, by name, and the exit status it
    /// asks for (128 + its number); `None` when none came.
    fn signal(&self) -> Option<(&'static str, u8)> {
        if !self.stop.load(Ordering::SeqCst) {
            return None;
        }
        let sig = self.which.load(Ordering::SeqCst) as i32;
        let name = signal_hook::low_level::signal_name(sig).unwrap_or("a signal");
        Some((name, u8::try_from(128 + sig).unwrap_or(1)))
    }
}
