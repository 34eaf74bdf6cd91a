//! `lobe demo`: the README's main command, on built-in inputs only.
//!
//! 1. A short tour: for the lecture's models (Phong, Blinn-Phong,
//!    Cook-Torrance with GGX and Beckmann) at θo = 30° under a white
//!    furnace, uniform hemisphere sampling against the importance samplers
//!    at the same number of samples ([`lobe::experiment::table::run_table`]).
//! 2. The showcase: a row of spheres, two of each model, on a grey ground
//!    under the built-in sky, path traced (up to [`MAX_DEPTH`] bounces)
//!    with BSDF sampling, light sampling and MIS at equal samples next to a
//!    reference, drawn as the grid of `lobe compare` with error maps and
//!    RMSE, and a caption that says what each row shows.

use crate::common::Bar;
use crate::compare::{print_table, run_with_progress, summary, write_json};
use crate::compare_figure::{FigureSpec, Label, write_grid};
use crate::draw::{append_caption, fmt_time};
use anyhow::Result;
use clap::Args;
use glam::DVec3;
use lobe::estimator::Strategy;
use lobe::experiment::table::{TableSettings, run_table};
use lobe::math::luminance;
use lobe::progress::SystemClock;
use lobe::sequence::Sequence;
use lobe::{BsdfStrategy, Light, MaterialDesc, Rgb};
use lobe_render::compare::CompareSettings;
use lobe_render::{Camera, Object, Scene, load_envmap};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The arguments of `lobe demo`.
#[derive(Args, Debug)]
#[command(
    about = "Tour: uniform against importance sampling, then a rendered showcase",
    long_about = "The README's main command; it needs no file. First, for the lecture's models \
                  (Phong n=100, Blinn-Phong n=100, Cook-Torrance GGX and Beckmann alpha=0.2) at \
                  theta_o = 30° under a white furnace, it estimates the reflected radiance with uniform \
                  hemisphere sampling and with each importance sampler at the same number of samples, \
                  and prints the relative error, the per-sample variance and the variance reduction.\n\n\
                  Then it renders the showcase: twelve spheres (Phong n=20 and 300, Blinn-Phong n=80 and \
                  1200, GGX alpha=0.3 and 0.06, Beckmann gold alpha=0.3 and 0.06, smooth and rough glass, \
                  a silver mirror, rough plastic) on a grey ground under the built-in sky, by path \
                  tracing (up to 5 bounces, so that the sharp spheres mirror the ground and light \
                  passes through the glass) with brdf, light and mis at 16 samples per pixel next to \
                  a mis reference at 512, and writes DIR/showcase.png (the renders with their error maps and \
                  RMSE, as `lobe compare` draws them), DIR/showcase.json (the numbers) and each render \
                  as DIR/<strategy>.png.",
    after_help = "Examples:\n  lobe demo\n  lobe demo --out /tmp/demo --quiet"
)]
pub struct DemoArgs {
    /// Directory of the showcase images and numbers
    #[arg(long, value_name = "DIR", default_value = "lobe-demo")]
    pub out: PathBuf,
    /// Everything tiny and fast (a smoke test, not a demonstration)
    #[arg(long)]
    pub quick: bool,
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
}

/// Samples per pixel of the showcase's reference (MIS).
const REFERENCE_SPP: u32 = 512;

/// Bounces of the showcase's paths: enough for the sharp spheres to mirror
/// the ground and their neighbours, and for a ray to go into a glass
/// sphere, out of it and on to the lit ground (the integrator's next-event
/// estimation at every vertex, Russian roulette after the third bounce).
const MAX_DEPTH: u32 = 5;

/// Sizes of the run.
struct DemoSettings {
    tour_samples: usize,
    width: u32,
    height: u32,
    spp: u32,
    reference_spp: u32,
}

impl DemoSettings {
    fn new(quick: bool) -> DemoSettings {
        if quick {
            DemoSettings {
                tour_samples: 1024,
                width: 144,
                height: 30,
                spp: 2,
                reference_spp: 16,
            }
        } else {
            DemoSettings {
                tour_samples: 65536,
                width: 960,
                height: 200,
                spp: 16,
                reference_spp: REFERENCE_SPP,
            }
        }
    }
}

/// The lecture's models of the tour.
const TOUR: [(&str, &str); 4] = [
    ("Phong n=100", r#"{"type":"phong","exponent":100}"#),
    (
        "Blinn-Phong n=100",
        r#"{"type":"blinn-phong","exponent":100}"#,
    ),
    (
        "Cook-Torrance GGX α=0.2",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2}"#,
    ),
    (
        "Cook-Torrance Beckmann α=0.2",
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.2}"#,
    ),
];

/// Run `lobe demo`.
pub fn run(args: &DemoArgs) -> Result<()> {
    let t0 = Instant::now();
    let demo = DemoSettings::new(args.quick);
    crate::common::prepare_output_dir("--out", &args.out)?;
    tour(&demo, args.quiet)?;
    showcase(&demo, &args.out, args.quiet)?;
    println!("\ndone in {}", fmt_time(t0.elapsed().as_secs_f64()));
    Ok(())
}

fn tour(demo: &DemoSettings, quiet: bool) -> Result<()> {
    let wo = crate::common::theta_to_wo(30.0)?;
    let light = Light::Constant(Rgb::ONE);
    let n = demo.tour_samples;
    println!(
        "lobe demo, part 1: L_o = ∫ f_r L_i cos dω at θo = 30° under a white furnace (L_i = 1),"
    );
    println!("so L_o is the directional albedo. Each strategy gets {n} samples; the reference is");
    println!(
        "adaptive quadrature. 'vs uniform' is uniform's exact variance (by quadrature, printed"
    );
    println!(
        "beside the reference) over this strategy's measured variance (the 'variance' column):"
    );
    println!("how many times fewer samples it needs for the same noise. Uniform's own row is its");
    println!("measured variance against the exact one, so it is near, not at, 1.0x.\n");
    for (label, json) in TOUR {
        let m = MaterialDesc::from_json(json)?.build()?;
        let strategies: Vec<Strategy> = m
            .strategies()
            .into_iter()
            .filter(|s| *s != BsdfStrategy::Cosine)
            .map(Strategy::from)
            .collect();
        let bar = Bar::new(quiet);
        let mut table = run_table(
            &m,
            &lobe::estimator::ShadingPoint::local(wo),
            &light,
            &strategies,
            TableSettings {
                sequence: Sequence::Independent,
                samples: n,
                seed: 1,
                replicas: lobe::experiment::table::REPLICAS,
            },
            &bar,
            &SystemClock::new(),
        )?;
        bar.finish();
        crate::common::zero_exact_rows(&mut table);
        let u = &table.uniform_variance;
        println!(
            "{label}: reference {:.5}, uniform's exact variance {}",
            luminance(Rgb::from_array(table.reference)),
            if u.reliable {
                format!("{:.4e}", u.variance)
            } else {
                "unreliable (its quadrature did not converge)".to_string()
            }
        );
        println!(
            "  {:<15} {:>10} {:>10} {:>11} {:>11}",
            "strategy", "estimate", "rel. err", "variance", "vs uniform"
        );
        for r in &table.strategies {
            let (variance, red) = if r.variance <= 0.0 {
                ("0".to_string(), "exact".to_string())
            } else {
                (
                    format!("{:.4e}", r.variance),
                    r.variance_reduction
                        .map_or("unreliable".to_string(), crate::estimate::format_ratio),
                )
            };
            println!(
                "  {:<15} {:>10.5} {:>10.2e} {:>11} {:>11}",
                r.name,
                luminance(Rgb::from_array(r.mean)),
                r.relative_error,
                variance,
                red
            );
        }
    }
    println!(
        "\nbrdf is the lecture's sampler (Phong: a lobe about the mirror direction; Blinn-Phong: the half"
    );
    println!(
        "vector with the 1/(4 v·h) Jacobian; Cook-Torrance: D(h) cos θh); vndf, spherical-caps and"
    );
    println!("bounded-vndf sample only the microfacets the viewer sees.");
    println!(
        "More: `lobe estimate --help` (any material, light and view), `lobe report --out report`"
    );
    println!("(the full report with figures), `lobe compare --help` (your own scene).\n");
    Ok(())
}

/// The showcase's spheres, two per model: the model, the parameter, the
/// material.
const SPHERES: [(&str, &str, &str); 12] = [
    (
        "Phong",
        "n = 20",
        r#"{"type":"phong","exponent":20,"kd":[0.45,0.1,0.07],"ks":0.45}"#,
    ),
    (
        "Phong",
        "n = 300",
        r#"{"type":"phong","exponent":300,"kd":[0.45,0.1,0.07],"ks":0.45}"#,
    ),
    (
        "Blinn-Phong",
        "n = 80",
        r#"{"type":"blinn-phong","exponent":80,"kd":[0.1,0.4,0.12],"ks":0.45}"#,
    ),
    (
        "Blinn-Phong",
        "n = 1200",
        r#"{"type":"blinn-phong","exponent":1200,"kd":[0.1,0.4,0.12],"ks":0.45}"#,
    ),
    (
        "GGX",
        "α = 0.3",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.3,"kd":[0.08,0.18,0.5],"ks":0.6}"#,
    ),
    (
        "GGX",
        "α = 0.06",
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.06,"kd":[0.08,0.18,0.5],"ks":0.6}"#,
    ),
    (
        "Beckmann (gold)",
        "α = 0.3",
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.3,"fresnel":{"type":"conductor"}}"#,
    ),
    (
        "Beckmann (gold)",
        "α = 0.06",
        r#"{"type":"cook-torrance","distribution":"beckmann","alpha":0.06,"fresnel":{"type":"conductor"}}"#,
    ),
    ("Glass (BK7)", "smooth", r#"{"type":"dielectric"}"#),
    ("Glass (BK7)", "α = 0.1", r#"{"type":"roughdielectric"}"#),
    (
        "Mirror (Ag), plastic",
        "mirror",
        r#"{"type":"conductor","material":"Ag"}"#,
    ),
    (
        "Mirror (Ag), plastic",
        "α = 0.1",
        r#"{"type":"roughplastic","diffuse_reflectance":[0.45,0.07,0.05]}"#,
    ),
];

const SPACING: f64 = 1.2;
const RADIUS: f64 = 0.5;

/// The showcase scene at `width × height`, and the labels under the
/// spheres (in pixels of the render).
fn showcase_scene(width: u32, height: u32) -> Result<(Scene, Vec<Label>)> {
    let camera = Camera::new(
        DVec3::new(0.0, 1.5, 9.5),
        DVec3::new(0.0, 0.42, 0.0),
        DVec3::Y,
        18.0,
        width,
        height,
    )?;
    let (sky, _) = load_envmap(Path::new("sky"), 1.0, 0.0)?;
    let mut scene = Scene::new(camera, sky);
    let mut labels = Vec::new();
    let x0 = -0.5 * SPACING * (SPHERES.len() - 1) as f64;
    for (k, (model, param, json)) in SPHERES.iter().enumerate() {
        let m = MaterialDesc::from_json(json)?.build()?;
        let c = DVec3::new(x0 + SPACING * k as f64, RADIUS, 0.0);
        scene = scene.with(Object::sphere(c, RADIUS, m)?);
        // On the ground below the sphere in the image: its parameter, and
        // under it, between the two spheres of a model, the model's name.
        let h = f64::from(height);
        if let (Some((x, _)), Some((_, y))) = (
            camera.project(c),
            camera.project(c - DVec3::new(0.0, RADIUS, 0.0)),
        ) {
            labels.push(Label {
                x,
                y: y + 0.1 * h,
                text: (*param).to_string(),
            });
            if k % 2 == 1
                && let Some((x0, _)) = camera.project(c - DVec3::new(SPACING, 0.0, 0.0))
            {
                labels.push(Label {
                    x: 0.5 * (x0 + x),
                    y: y + 0.2 * h,
                    text: (*model).to_string(),
                });
            }
        }
    }
    let ground = MaterialDesc::from_json(r#"{"type":"lambert","albedo":0.5}"#)?.build()?;
    scene = scene.with(Object::plane(DVec3::ZERO, DVec3::Y, ground)?);
    Ok((scene, labels))
}

/// What each row of the showcase shows, under the figure.
fn showcase_caption(s: &CompareSettings) -> Vec<String> {
    vec![
        format!(
            "Rows: the reference ({}, {} spp), then each strategy at {} spp, its error map on the right; paths of up to {} bounces.",
            lobe_render::compare::REFERENCE_STRATEGY.name(),
            s.reference_spp,
            s.spp,
            s.max_depth
        ),
        "brdf samples the BSDF only: it rarely finds the small sun, so the ground shows the blue sky with sun fireflies.".to_string(),
        "light samples the sky and sun only: clean on the diffuse ground, noisy on glossy lobes, worst on sharp gold.".to_string(),
        "Light samples never hit a delta lobe: on smooth glass and the mirror, light falls back to brdf.".to_string(),
        "mis gives each pixel's draws to BSDF sampling, the balance heuristic or the light, as its pilot finds best.".to_string(),
        "The sparks under the glass are caustics: sunlight through the glass, found only when a path from the ground leaves through the sphere toward the sun.".to_string(),
    ]
}

fn showcase(demo: &DemoSettings, dir: &Path, quiet: bool) -> Result<()> {
    let (scene, labels) = showcase_scene(demo.width, demo.height)?;
    let settings = CompareSettings {
        strategies: vec![
            Strategy::Bsdf(BsdfStrategy::Brdf),
            Strategy::Light,
            Strategy::MIS,
        ],
        spp: demo.spp,
        reference_spp: demo.reference_spp,
        seed: 1,
        sequence: Sequence::Sobol,
        max_depth: MAX_DEPTH,
        threads: None,
        equal_time: false,
    };
    println!(
        "lobe demo, part 2: the showcase, {}×{}: twelve spheres (Phong, Blinn-Phong, GGX, Beckmann gold; a",
        demo.width, demo.height
    );
    println!(
        "broad and a sharp lobe each; smooth and rough glass, a mirror, rough plastic) on a grey ground"
    );
    println!(
        "under the built-in sky with its sun, rendered by BSDF sampling (brdf), light sampling and MIS at"
    );
    println!(
        "{} spp, paths of up to {} bounces; the reference is {} (MIS with the balance heuristic) at {} spp.",
        settings.spp,
        settings.max_depth,
        lobe_render::compare::REFERENCE_STRATEGY.name(),
        settings.reference_spp
    );
    let cmp = run_with_progress(&scene, &settings, quiet);
    let png = dir.join("showcase.png");
    let json = dir.join("showcase.json");
    let mut figure = write_grid(
        &png,
        &FigureSpec {
            title: format!(
                "lobe demo: BSDF sampling, light sampling and MIS at {} spp under the built-in sky ({}×{}, paths of up to {} bounces)",
                settings.spp, demo.width, demo.height, settings.max_depth
            ),
            cmp: &cmp,
            labels,
        },
    )?;
    let caption = showcase_caption(&settings);
    (figure.width, figure.height) = append_caption(&png, &caption)?;
    write_json(
        &json,
        &summary("built-in showcase", &settings, &cmp, figure),
    )?;
    let mut renders = vec![dir.join("reference.png")];
    cmp.reference
        .image
        .write_png(&renders[0], &lobe_render::ToneMap::default())?;
    for s in &cmp.equal_samples {
        let p = dir.join(format!("{}.png", s.strategy.name()));
        s.image.write_png(&p, &lobe_render::ToneMap::default())?;
        renders.push(p);
    }
    print_table(&cmp);
    println!(
        "\nwrote {} (the renders with their error maps) and {} (the numbers),",
        png.display(),
        json.display()
    );
    let names: Vec<String> = renders
        .iter()
        .map(|p| {
            p.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    println!("and the renders {} in {}", names.join(", "), dir.display());
    Ok(())
}
