//! The renderer against answers known in closed form: the white furnace,
//! agreement between strategies, thread-count independence, orientation,
//! and scene-file errors.

use glam::DVec3;
use lobe::envmap::EnvMap;
use lobe::estimator::{Heuristic, Strategy};
use lobe::{BsdfStrategy, Material, MaterialDesc, Rgb};
use lobe_render::integrator::RenderLoop;
use lobe_render::{
    Camera, Image, Mesh, Object, RenderSettings, Scene, SppAllocation, load_scene, render,
};
use std::path::PathBuf;
use std::sync::Arc;

#[path = "render/glass.rs"]
mod glass;

fn lambert(a: f64) -> Material {
    Material::lambert(Rgb::splat(a)).unwrap()
}

fn opts(method: Strategy, spp: u64) -> RenderSettings {
    RenderSettings {
        spp,
        strategy: method,
        seed: 3,
        sequence: lobe::sequence::Sequence::Sobol,
        max_depth: 1,
        threads: None,
        render_loop: RenderLoop::Batch,
        spp_allocation: SppAllocation::Uniform,
    }
}

/// Pixels whose four corners all see `object` (fully covered pixels).
fn covered(scene: &Scene, object: usize) -> Vec<(usize, usize)> {
    let c = &scene.camera;
    let mut v = Vec::new();
    for y in 0..c.height as usize {
        for x in 0..c.width as usize {
            let all = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .all(|&(dx, dy)| {
                    let r = c.ray(x as f64 + dx, y as f64 + dy);
                    scene
                        .intersect(&r, f64::INFINITY)
                        .is_some_and(|(_, o)| o == object)
                });
            if all {
                v.push((x, y));
            }
        }
    }
    v
}

/// Mean and standard error of the mean of the luminance of `px` over
/// `pixels` (each pixel an independent estimate).
fn mean_se(img: &Image, pixels: &[(usize, usize)], f: impl Fn(Rgb) -> f64) -> (f64, f64) {
    let v: Vec<f64> = pixels.iter().map(|&(x, y)| f(img.get(x, y))).collect();
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// `a − b`, pixel by pixel.
fn difference(a: &Image, b: &Image) -> Image {
    Image {
        pixels: a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(x, y)| *x - *y)
            .collect(),
        ..a.clone()
    }
}

fn furnace_scene(width: u32, height: u32) -> Scene {
    let camera = Camera::new(
        DVec3::new(0.0, 0.0, 3.5),
        DVec3::ZERO,
        DVec3::Y,
        40.0,
        width,
        height,
    )
    .unwrap();
    Scene::new(camera, EnvMap::constant(Rgb::ONE))
        .with(Object::sphere(DVec3::ZERO, 1.0, lambert(1.0)).unwrap())
}

#[test]
fn white_furnace_every_method() {
    let scene = furnace_scene(32, 24);
    let px = covered(&scene, 0);
    assert!(px.len() > 150, "{} covered pixels", px.len());
    let allocations = Strategy::all().into_iter().flat_map(|m| {
        // The variance allocation on the strategies whose pixels differ
        // in noise (every pixel of the exact ones has none).
        let variance = !matches!(m, Strategy::Bsdf(s) if s != BsdfStrategy::Uniform);
        std::iter::once((m, SppAllocation::Uniform))
            .chain(variance.then_some((m, SppAllocation::Variance)))
    });
    for (method, spp_allocation) in allocations {
        let o = RenderSettings {
            spp_allocation,
            ..opts(method, 16)
        };
        let img = render(&scene, &o, |_| {});
        assert_eq!(img.stats.nonfinite, 0);
        assert_eq!(
            img.stats.camera_rays,
            32 * 24 * 16,
            "{method} {spp_allocation}"
        );
        // The background is the environment, 1.
        assert_eq!(img.get(0, 0), Rgb::ONE, "{method}");
        // Cosine and brdf sampling of a Lambertian (and the strategies that
        // fall back to brdf) have weight f cos / p = 1 exactly, and nothing
        // shadows a lone convex sphere.
        // Adaptive MIS gives both draws to BSDF (cosine) sampling here, as
        // its pilot finds zero variance there.
        let exact = matches!(method, Strategy::Bsdf(s) if s != BsdfStrategy::Uniform)
            || method == Strategy::MIS;
        for c in 0..3 {
            let (m, se) = mean_se(&img, &px, |p| p[c]);
            if exact {
                for &(x, y) in &px {
                    let v = img.get(x, y)[c];
                    assert!((v - 1.0).abs() < 1e-6, "{method}: pixel ({x}, {y}) = {v}");
                }
            } else {
                assert!(se > 0.0, "{method}");
                assert!(
                    (m - 1.0).abs() < 4.0 * se,
                    "{method}: mean {m} ± {se} over {} pixels",
                    px.len()
                );
            }
        }
    }
}

#[test]
fn white_furnace_convex_mesh_is_exact() {
    // An octahedron with flat faces, white Lambert: every pixel on it is 1.
    let obj = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
               f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
    let mesh = Arc::new(Mesh::parse_obj(obj).unwrap());
    let camera = Camera::new(
        DVec3::new(1.0, 2.0, 3.0),
        DVec3::ZERO,
        DVec3::Y,
        40.0,
        24,
        24,
    )
    .unwrap();
    let scene =
        Scene::new(camera, EnvMap::constant(Rgb::ONE)).with(Object::mesh(mesh, lambert(1.0)));
    let px = covered(&scene, 0);
    assert!(px.len() > 100);
    let img = render(
        &scene,
        &opts(Strategy::Bsdf(BsdfStrategy::Cosine), 8),
        |_| {},
    );
    for &(x, y) in &px {
        let v = img.get(x, y);
        assert!(
            (v - Rgb::ONE).abs().max_element() < 1e-6,
            "({x}, {y}) = {v}"
        );
    }
}

#[test]
fn white_furnace_with_bounces() {
    // A white sphere above a white plane: with every bounce, the furnace
    // gives 1 everywhere; depth 32 leaves a negligible truncation.
    let camera = Camera::new(
        DVec3::new(0.0, 2.0, 5.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::Y,
        45.0,
        24,
        18,
    )
    .unwrap();
    let scene = Scene::new(camera, EnvMap::constant(Rgb::ONE))
        .with(Object::sphere(DVec3::new(0.0, 1.5, 0.0), 1.0, lambert(1.0)).unwrap())
        .with(Object::plane(DVec3::ZERO, DVec3::Y, lambert(1.0)).unwrap());
    let mut px = covered(&scene, 0);
    px.extend(covered(&scene, 1));
    for method in [
        Strategy::Bsdf(BsdfStrategy::Cosine),
        Strategy::Light,
        Strategy::mis(Heuristic::Balance),
        Strategy::mis(Heuristic::Power),
    ] {
        let o = RenderSettings {
            max_depth: 32,
            ..opts(method, 16)
        };
        let img = render(&scene, &o, |_| {});
        let (m, se) = mean_se(&img, &px, |p| p.y);
        assert!(
            (m - 1.0).abs() < 4.0 * se + 1e-3,
            "{method}: mean {m} ± {se}"
        );
        // Direct light alone is less than 1 where the sphere and the plane
        // hide part of the sky from each other.
        let direct = render(&scene, &opts(method, 16), |_| {});
        let (md, _) = mean_se(&direct, &px, |p| p.y);
        assert!(md < m - 0.02, "{method}: direct {md} vs paths {m}");
    }
}

/// A smooth environment (no sun): a sky gradient with a warm patch.
fn smooth_env() -> EnvMap {
    let (w, h) = (32, 16);
    let mut t = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let v = j as f64 / h as f64;
            let u = i as f64 / w as f64;
            let patch = if (0.2..0.35).contains(&u) && (0.2..0.4).contains(&v) {
                8.0
            } else {
                0.0
            };
            t.push(Rgb::new(0.3 + patch, 0.5 + 0.5 * (1.0 - v), 1.0 - 0.7 * v));
        }
    }
    EnvMap::new(w, h, t, 1.0, 30.0).unwrap().0
}

#[test]
fn techniques_agree_pixel_by_pixel() {
    // Every strategy estimates the same image: the per-pixel difference of
    // two renders with different seeds has mean zero.
    let ggx = MaterialDesc::from_json(
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.25,"kd":0.3}"#,
    )
    .unwrap()
    .build()
    .unwrap();
    let camera = Camera::new(
        DVec3::new(0.0, 1.0, 3.0),
        DVec3::new(0.0, 0.6, 0.0),
        DVec3::Y,
        40.0,
        24,
        20,
    )
    .unwrap();
    let scene = Scene::new(camera, smooth_env())
        .with(Object::sphere(DVec3::new(0.0, 0.6, 0.0), 0.6, ggx).unwrap())
        .with(Object::plane(DVec3::ZERO, DVec3::Y, lambert(0.5)).unwrap());
    let mut px = covered(&scene, 0);
    px.extend(covered(&scene, 1));
    let reference = render(&scene, &opts(Strategy::mis(Heuristic::Balance), 64), |_| {});
    for method in Strategy::all() {
        let mut o = opts(method, 32);
        o.seed = 11;
        let img = render(&scene, &o, |_| {});
        let diff = difference(&img, &reference);
        let (m, se) = mean_se(&diff, &px, lobe::math::luminance);
        assert!(m.abs() < 4.5 * se, "{method}: mean difference {m} ± {se}");
    }
}

/// The scene of `techniques_agree_pixel_by_pixel`: a GGX sphere with a
/// diffuse term on a Lambertian plane under a smooth sky; and its covered
/// pixels.
fn sphere_on_plane() -> (Scene, Vec<(usize, usize)>) {
    let ggx = MaterialDesc::from_json(
        r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.25,"kd":0.3}"#,
    )
    .unwrap()
    .build()
    .unwrap();
    let camera = Camera::new(
        DVec3::new(0.0, 1.0, 3.0),
        DVec3::new(0.0, 0.6, 0.0),
        DVec3::Y,
        40.0,
        24,
        20,
    )
    .unwrap();
    let scene = Scene::new(camera, smooth_env())
        .with(Object::sphere(DVec3::new(0.0, 0.6, 0.0), 0.6, ggx).unwrap())
        .with(Object::plane(DVec3::ZERO, DVec3::Y, lambert(0.5)).unwrap());
    let mut px = covered(&scene, 0);
    px.extend(covered(&scene, 1));
    (scene, px)
}

/// Issue 10: the batch loop (f32 kernels, blocks of samples) against the
/// scalar f64 loop, its reference, for every strategy it covers. With the
/// same seed both draw the same numbers, so the images agree to f32
/// rounding; with different seeds the per-pixel differences have mean zero
/// (within 4.5 standard errors). What the batch loop refuses is rendered
/// by the scalar loop, the same bits as `RenderLoop::Scalar`.
#[test]
fn batch_loop_matches_the_scalar_loop() {
    use lobe_render::integrator::batch_refusal;
    let (scene, px) = sphere_on_plane();
    let scalar = |o: RenderSettings| RenderSettings {
        render_loop: RenderLoop::Scalar,
        ..o
    };
    let mean = |img: &Image| mean_se(img, &px, lobe::math::luminance).0;
    for method in [
        Strategy::Bsdf(BsdfStrategy::Vndf),
        Strategy::Bsdf(BsdfStrategy::Cosine),
        Strategy::Light,
        Strategy::mis(Heuristic::Balance),
        Strategy::mis(Heuristic::Power),
        Strategy::MIS,
    ] {
        assert_eq!(batch_refusal(&scene, method, 1), None, "{method}");
        let o = opts(method, 32);
        let reference = render(&scene, &scalar(o), |_| {});
        let same = render(&scene, &o, |_| {});
        let (a, b) = (mean(&same), mean(&reference));
        assert!(
            (a - b).abs() < 2e-4 * b,
            "{method}: same seed, batch {a} scalar {b}"
        );
        let other = render(&scene, &RenderSettings { seed: 11, ..o }, |_| {});
        let diff = difference(&other, &reference);
        let (m, se) = mean_se(&diff, &px, lobe::math::luminance);
        assert!(m.abs() < 4.5 * se, "{method}: mean difference {m} ± {se}");
        assert_eq!(same.stats.camera_rays, reference.stats.camera_rays);
    }
    // A measured table with a diffuse term runs on the batch loop too
    // (lane by lane through the scalar mixture): the same image as the
    // scalar loop's within the f32 rounding. Refused: bounces, one-sample
    // MIS.
    let ggx = Material::load(r#"{"type":"cook-torrance","alpha":0.3}"#).unwrap();
    let dir = std::env::temp_dir().join(format!("lobe-render-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("t.bsdf");
    std::fs::write(
        &path,
        lobe::models::measured::rgl::Rgl::write(|o, i| ggx.eval(o, i), 4, 8, "t"),
    )
    .unwrap();
    let table = Material::load(&format!(
        r#"{{"type":"measured","path":{:?}}}"#,
        path.display().to_string()
    ))
    .unwrap();
    let mut with_table = scene.clone();
    with_table.objects[0].material = Material::with_diffuse(Rgb::splat(0.3), table.glossy).unwrap();
    assert_eq!(batch_refusal(&with_table, Strategy::MIS, 1), None);
    let o = opts(Strategy::MIS, 8);
    let (a, b) = (
        mean(&render(&with_table, &o, |_| {})),
        mean(&render(&with_table, &scalar(o), |_| {})),
    );
    assert!(
        (a - b).abs() < 2e-4 * b,
        "measured + kd: same seed, batch {a} scalar {b}"
    );
    let one_sample: Strategy = "mis-one".parse().unwrap();
    for (sc, method, depth) in [(&scene, Strategy::MIS, 2), (&scene, one_sample, 1)] {
        let why = batch_refusal(sc, method, depth);
        assert!(why.is_some(), "{method} depth {depth}");
        let o = RenderSettings {
            max_depth: depth,
            ..opts(method, 2)
        };
        assert_eq!(
            render(sc, &o, |_| {}),
            render(sc, &scalar(o), |_| {}),
            "{why:?}"
        );
    }
}

/// Issue 10: every sequence is unbiased, and at equal spp the stratified
/// and Sobol patterns have less error than independent samples (measured:
/// 0.67× and 0.60× the RMSE of independent at 64 spp, seed 5; the
/// visibility edges and the sphere's outline limit the gain).
#[test]
fn every_sequence_is_unbiased_and_qmc_has_less_error() {
    use lobe::sequence::Sequence;
    let (scene, px) = sphere_on_plane();
    let mut r = opts(Strategy::mis(Heuristic::Balance), 2048);
    r.seed = 99;
    let reference = render(&scene, &r, |_| {});
    let err = |img: &Image| -> (f64, f64, f64) {
        let d: Vec<f64> = px
            .iter()
            .map(|&(x, y)| lobe::math::luminance(img.get(x, y) - reference.get(x, y)))
            .collect();
        let n = d.len() as f64;
        let m = d.iter().sum::<f64>() / n;
        let var = d.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
        let rmse = (d.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
        (m, (var / n).sqrt(), rmse)
    };
    let mut rmse = Vec::new();
    for seq in Sequence::ALL {
        let mut o = opts(Strategy::mis(Heuristic::Balance), 64);
        o.seed = 5;
        o.sequence = seq;
        let (m, se, e) = err(&render(&scene, &o, |_| {}));
        eprintln!("{seq}: mean difference {m:.2e} ± {se:.2e}, rmse {e:.4}");
        assert!(m.abs() < 4.5 * se, "{seq}: mean difference {m} ± {se}");
        rmse.push(e);
    }
    let [indep, strat, sobol] = rmse[..] else {
        unreachable!()
    };
    assert!(
        strat < 0.85 * indep,
        "stratified {strat} vs independent {indep}"
    );
    assert!(sobol < 0.8 * indep, "sobol {sobol} vs independent {indep}");
    // Adaptive MIS (the default `mis`) per pixel: unbiased, and no worse
    // than the better of BSDF and light sampling, nor than the balance
    // heuristic, beyond noise.
    let mut by = Vec::new();
    for t in [
        Strategy::Bsdf(BsdfStrategy::Vndf),
        Strategy::Light,
        Strategy::mis(Heuristic::Balance),
        Strategy::MIS,
    ] {
        let mut o = opts(t, 64);
        o.seed = 5;
        let (m, se, e) = err(&render(&scene, &o, |_| {}));
        eprintln!("{t}: mean difference {m:.2e} ± {se:.2e}, rmse {e:.4}");
        assert!(m.abs() < 4.5 * se, "{t}: mean difference {m} ± {se}");
        by.push(e);
    }
    let best = by[0].min(by[1]);
    assert!(
        by[3] < 1.1 * best,
        "mis {} vs the better strategy {best}",
        by[3]
    );
    assert!(
        by[3] < 1.1 * by[2],
        "mis {} vs mis-balance {}",
        by[3],
        by[2]
    );
}

/// Issue 10: the variance allocation of samples. A shiny sphere reflecting
/// a small bright sun, on a diffuse plane, with sky around them: the
/// pixels' noise differs by orders of magnitude. At the same total number
/// of samples the variance allocation is unbiased (against a reference of
/// many samples, pixel by pixel over the covered pixels), has clearly less
/// error than `spp` in every pixel (measured: the RMSEs of 8 seeds at 32
/// spp add up to 0.24× uniform's; the test asks for 0.5×), and the batch
/// loop agrees with the scalar loop for one seed.
#[test]
fn variance_allocation_is_unbiased_and_has_less_error() {
    let ggx = Material::load(r#"{"type":"cook-torrance","alpha":0.05}"#).unwrap();
    let camera = Camera::new(
        DVec3::new(0.0, 1.0, 3.0),
        DVec3::new(0.0, 0.6, 0.0),
        DVec3::Y,
        40.0,
        32,
        24,
    )
    .unwrap();
    // The sun behind the camera, high: its reflection is on the sphere.
    let scene = Scene::new(camera, EnvMap::sky(256, 128, 35.0, 180.0))
        .with(Object::sphere(DVec3::new(0.0, 0.6, 0.0), 0.6, ggx).unwrap())
        .with(Object::plane(DVec3::ZERO, DVec3::Y, lambert(0.5)).unwrap());
    let mut px = covered(&scene, 0);
    px.extend(covered(&scene, 1));
    let mut r = opts(Strategy::mis(Heuristic::Balance), 4096);
    r.seed = 99;
    let reference = render(&scene, &r, |_| {});
    let all: Vec<(usize, usize)> = (0..24).flat_map(|y| (0..32).map(move |x| (x, y))).collect();
    // (mean difference, its standard error) over the covered pixels, and
    // the RMSE over every pixel.
    let err = |img: &Image| -> (f64, f64, f64) {
        let d =
            |&(x, y): &(usize, usize)| lobe::math::luminance(img.get(x, y) - reference.get(x, y));
        let v: Vec<f64> = px.iter().map(d).collect();
        let n = v.len() as f64;
        let m = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0);
        let rmse = (all.iter().map(|p| d(p) * d(p)).sum::<f64>() / all.len() as f64).sqrt();
        (m, (var / n).sqrt(), rmse)
    };
    let (mut uniform, mut variance) = (0.0, 0.0);
    for seed in 5..13 {
        let mut o = opts(Strategy::MIS, 32);
        o.seed = seed;
        let (m, se, e_u) = err(&render(&scene, &o, |_| {}));
        assert!(m.abs() < 4.5 * se, "uniform, seed {seed}: {m} ± {se}");
        o.spp_allocation = SppAllocation::Variance;
        let img = render(&scene, &o, |_| {});
        assert_eq!(img.stats.camera_rays, 32 * 24 * 32);
        let (m, se, e_v) = err(&img);
        assert!(m.abs() < 4.5 * se, "variance, seed {seed}: {m} ± {se}");
        eprintln!("seed {seed}: rmse uniform {e_u:.4}, variance {e_v:.4}");
        uniform += e_u;
        variance += e_v;
    }
    assert!(
        variance < 0.5 * uniform,
        "variance allocation {variance} vs uniform {uniform} (sum of 8 RMSEs)"
    );
    // Batch against scalar, one seed: the same allocation (the pilot's
    // values agree to f32 rounding), the same image to f32 rounding.
    let mut o = opts(Strategy::mis(Heuristic::Balance), 8);
    o.spp_allocation = SppAllocation::Variance;
    let mean = |img: &Image| mean_se(img, &px, lobe::math::luminance).0;
    let batch = render(&scene, &o, |_| {});
    o.render_loop = RenderLoop::Scalar;
    let scalar = render(&scene, &o, |_| {});
    let (a, b) = (mean(&batch), mean(&scalar));
    assert!((a - b).abs() < 2e-4 * b, "batch {a} scalar {b}");
}

/// Issue 10's case in the renderer: a shiny GGX sphere (α = 0.05) under an
/// even bright sky. The balance heuristic is several times worse than
/// visible-normal sampling alone; adaptive MIS (`mis`) is not.
#[test]
fn adaptive_mis_on_a_shiny_sphere_under_an_even_sky() {
    let ggx = MaterialDesc::from_json(r#"{"type":"cook-torrance","alpha":0.05}"#)
        .unwrap()
        .build()
        .unwrap();
    let camera = Camera::new(
        DVec3::new(0.0, 0.0, 3.0),
        DVec3::ZERO,
        DVec3::Y,
        40.0,
        24,
        20,
    )
    .unwrap();
    let scene = Scene::new(camera, EnvMap::constant(Rgb::ONE))
        .with(Object::sphere(DVec3::ZERO, 1.0, ggx).unwrap());
    let px = covered(&scene, 0);
    let mut r = opts(Strategy::Bsdf(BsdfStrategy::Vndf), 1024);
    r.seed = 77;
    let reference = render(&scene, &r, |_| {});
    let rmse = |t: Strategy| {
        let mut o = opts(t, 32);
        o.seed = 8;
        let img = render(&scene, &o, |_| {});
        let d: Vec<f64> = px
            .iter()
            .map(|&(x, y)| lobe::math::luminance(img.get(x, y) - reference.get(x, y)))
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        eprintln!("{t}: mean difference {mean:.2e}");
        (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt()
    };
    let vndf = rmse(Strategy::Bsdf(BsdfStrategy::Vndf));
    let light = rmse(Strategy::Light);
    let balance = rmse(Strategy::mis(Heuristic::Balance));
    let mis = rmse(Strategy::MIS);
    eprintln!("vndf {vndf:.4}, light {light:.4}, mis-balance {balance:.4}, mis {mis:.4}");
    assert!(
        balance > 1.3 * vndf, // 1.49x in RMSE (2.2x in variance) at seed 8
        "the balance heuristic's weakness is gone?"
    );
    assert!(
        mis < 1.1 * vndf.min(light),
        "mis {mis} vs vndf {vndf}, light {light}"
    );
}

/// Adaptive MIS's pilot: an eighth of the spp, at least one sample per
/// pixel and at most `MAX_PILOT_SPP` (the allocation pools 7 × 7 pixels'
/// pilots, so a few samples each suffice; the test above runs at 4).
#[test]
fn the_pilot_is_an_eighth_of_the_spp_within_its_bounds() {
    use lobe_render::integrator::{MAX_PILOT_SPP, pilot_spp};
    assert_eq!(pilot_spp(1), 1);
    assert_eq!(pilot_spp(15), 1);
    assert_eq!(pilot_spp(32), 4);
    assert_eq!(pilot_spp(64), MAX_PILOT_SPP);
    assert_eq!(pilot_spp(1 << 20), MAX_PILOT_SPP);
}

/// `render_progressive` returns the mean of whole passes, the same bits as
/// averaging `render_pass` 0, 1, 2 by hand, whatever the time it was given.
#[test]
fn progressive_passes_are_reproducible() {
    use lobe::sequence::Sequence;
    use lobe_render::integrator::{render_pass, render_progressive};
    let (scene, _) = sphere_on_plane();
    for (seq, strategy, spp_allocation) in Sequence::ALL
        .into_iter()
        .map(|q| (q, Strategy::mis(Heuristic::Balance), SppAllocation::Uniform))
        .chain([
            (Sequence::Sobol, Strategy::MIS, SppAllocation::Uniform),
            (Sequence::Sobol, Strategy::MIS, SppAllocation::Variance),
            (
                Sequence::Stratified,
                Strategy::Light,
                SppAllocation::Variance,
            ),
        ])
    {
        let mut o = opts(strategy, 8);
        o.sequence = seq;
        o.spp_allocation = spp_allocation;
        o.max_depth = 3;
        let hour = std::time::Duration::from_secs(3600);
        let p = render_progressive(&scene, &o, hour, 3, |_| {});
        assert_eq!(p.stats.passes, 3);
        let passes: Vec<Image> = (0..3).map(|k| render_pass(&scene, &o, k, |_| {})).collect();
        assert_ne!(passes[0].pixels, passes[1].pixels, "{seq}: passes differ");
        for (i, px) in p.pixels.iter().enumerate() {
            let mean =
                (passes[0].pixels[i] + passes[1].pixels[i] + passes[2].pixels[i]) * (1.0 / 3.0);
            assert_eq!(*px, mean, "{seq}: pixel {i}");
        }
        // A tiny budget still gives one whole pass.
        let one = render_progressive(&scene, &o, std::time::Duration::ZERO, 100, |_| {});
        assert_eq!(one.stats.passes, 1);
        assert_eq!(one.pixels, passes[0].pixels);
    }
}

/// Issue 41: a cancelled render keeps its finished passes. `render_until`
/// stops at the next row once the flag is set: the pass then running is
/// abandoned, and the image is the mean of the passes before it, the same
/// bits as an uncancelled render of that many passes; a flag set before
/// the first pass finished gives no image.
#[test]
fn a_cancelled_render_keeps_its_finished_passes() {
    use lobe_render::integrator::{render_pass, render_progressive, render_until};
    use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
    let (scene, _) = sphere_on_plane();
    for (strategy, spp_allocation, render_loop) in [
        (
            Strategy::mis(Heuristic::Balance),
            SppAllocation::Uniform,
            RenderLoop::Batch,
        ),
        (Strategy::MIS, SppAllocation::Variance, RenderLoop::Batch),
        (Strategy::MIS, SppAllocation::Variance, RenderLoop::Scalar),
    ] {
        let mut o = opts(strategy, 4);
        o.spp_allocation = spp_allocation;
        o.render_loop = render_loop;
        // One thread: the flag is set during pass 1's first row, so the
        // rows after it are skipped whatever the machine.
        o.threads = Some(1);
        let first = render_pass(&scene, &o, 0, |_| {});
        let per_pass = first.stats.camera_rays;
        assert!(per_pass > 0);
        let done = AtomicU64::new(0);
        let cancel = AtomicBool::new(false);
        let img = render_until(&scene, &o, None, 100, &cancel, |n| {
            if done.fetch_add(n, Ordering::Relaxed) + n > per_pass {
                cancel.store(true, Ordering::Relaxed);
            }
        })
        .expect("pass 0 finished before the flag was set");
        assert_eq!(img.stats.passes, 1, "{strategy}");
        assert_eq!(img.stats.camera_rays, per_pass);
        assert_eq!(img.pixels, first.pixels, "{strategy}");
        assert!(done.load(Ordering::Relaxed) < 2 * per_pass, "{strategy}");

        // Set after two passes: the mean of the two, as render_progressive
        // gives it.
        let done = AtomicU64::new(0);
        let cancel = AtomicBool::new(false);
        let img = render_until(&scene, &o, None, 100, &cancel, |n| {
            if done.fetch_add(n, Ordering::Relaxed) + n > 2 * per_pass {
                cancel.store(true, Ordering::Relaxed);
            }
        })
        .unwrap();
        let two = render_progressive(&scene, &o, std::time::Duration::from_secs(3600), 2, |_| {});
        assert_eq!((img.stats.passes, two.stats.passes), (2, 2));
        assert_eq!(img.pixels, two.pixels, "{strategy}");

        // Without a budget or a flag: max_passes.
        let never = AtomicBool::new(false);
        let three = render_until(&scene, &o, None, 3, &never, |_| {}).unwrap();
        assert_eq!(three.stats.passes, 3);
        assert_eq!(three.stats.camera_rays, 3 * per_pass);

        // Set before the first pass (in the pilot, or at the first row):
        // nothing.
        let set = AtomicBool::new(true);
        assert!(render_until(&scene, &o, None, 100, &set, |_| {}).is_none());
        let hour = Some(std::time::Duration::from_secs(3600));
        assert!(render_until(&scene, &o, hour, 100, &set, |_| {}).is_none());
    }
}

#[test]
fn the_same_image_for_any_thread_count() {
    let obj = "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0 0.9 0\nv 0 0 0.6\n\
               vn 0 -1 0\nvn 0 1 0\nvn 1 0 0\nvn 0 0 1\n\
               f 1//1 2//1 4//1\nf 1//2 3//2 2//2\nf 2//3 3//3 4//3\nf 4//4 3//4 1//4\n";
    let mesh = Arc::new(Mesh::parse_obj(obj).unwrap());
    let ggx = MaterialDesc::from_json(r#"{"type":"cook-torrance","alpha":0.2}"#)
        .unwrap()
        .build()
        .unwrap();
    let camera = Camera::new(
        DVec3::new(0.5, 1.0, 3.0),
        DVec3::new(0.0, 0.4, 0.0),
        DVec3::Y,
        50.0,
        37,
        23,
    )
    .unwrap();
    let scene = Scene::new(camera, EnvMap::sky(64, 32, 30.0, 20.0))
        .with(Object::mesh(mesh, lambert(0.7)))
        .with(Object::sphere(DVec3::new(-0.9, 0.4, 0.0), 0.4, ggx).unwrap())
        .with(Object::plane(DVec3::ZERO, DVec3::Y, lambert(0.5)).unwrap());
    for (method, depth) in [
        (Strategy::mis(Heuristic::Power), 6),
        (Strategy::Bsdf(BsdfStrategy::Vndf), 6),
        (Strategy::Light, 6),
        // Direct lighting: the batch loop.
        (Strategy::MIS, 1),
        (Strategy::Bsdf(BsdfStrategy::Vndf), 1),
        // Samples allocated by the pilot's variances (batch, then scalar).
        (Strategy::mis(Heuristic::Balance), 1),
        (Strategy::mis(Heuristic::Balance), 2),
    ] {
        let mut o = opts(method, 4);
        o.max_depth = depth;
        if method == Strategy::mis(Heuristic::Balance) {
            o.spp_allocation = SppAllocation::Variance;
        }
        let one = render(
            &scene,
            &RenderSettings {
                threads: Some(1),
                ..o
            },
            |_| {},
        );
        let two = render(
            &scene,
            &RenderSettings {
                threads: Some(2),
                ..o
            },
            |_| {},
        );
        let bits = |i: &Image| -> Vec<u64> {
            i.pixels
                .iter()
                .flat_map(|p| p.to_array().map(f64::to_bits))
                .collect()
        };
        assert_eq!(bits(&one), bits(&two), "{method}");
        assert_eq!(one.stats, two.stats);
        assert_eq!(one.stats.camera_rays, 37 * 23 * 4);
        let mut o2 = o;
        o2.seed += 1;
        assert_ne!(
            bits(&one),
            bits(&render(&scene, &o2, |_| {})),
            "the seed matters"
        );
    }
}

#[test]
fn right_and_top_of_the_scene_are_right_and_top_of_the_image() {
    // A black sphere up and to the camera's right, on a white background.
    let camera = Camera::new(
        DVec3::new(0.0, 0.0, 5.0),
        DVec3::ZERO,
        DVec3::Y,
        40.0,
        40,
        30,
    )
    .unwrap();
    let center = DVec3::new(0.9, 0.6, 0.0);
    let scene = Scene::new(camera, EnvMap::constant(Rgb::ONE))
        .with(Object::sphere(center, 0.3, lambert(0.0)).unwrap());
    let img = render(
        &scene,
        &opts(Strategy::Bsdf(BsdfStrategy::Cosine), 4),
        |_| {},
    );
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            if img.get(x, y).x < 0.5 {
                sx += x as f64 + 0.5;
                sy += y as f64 + 0.5;
                n += 1.0;
            }
        }
    }
    assert!(n > 10.0);
    let (cx, cy) = (sx / n, sy / n);
    assert!(cx > 0.6 * img.width as f64, "dark centroid x {cx}");
    assert!(cy < 0.4 * img.height as f64, "dark centroid y {cy}");
    let (px, py) = scene.camera.project(center).unwrap();
    assert!((px - cx).abs() < 1.0 && (py - cy).abs() < 1.0);
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("lobe-render-it-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

const SCENE: &str = r#"[camera]
origin = [0, 1, 4]
target = [0, 1, 0]
width = 16
height = 12

[environment]
path = "sky"

[[object]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = { type = "phong", exponent = 50 }

[[object]]
type = "mesh"
path = "tri.obj"
material = { type = "lambert", albedo = 0.5 }

[render]
spp = 2
strategy = "vndf"
"#;

#[test]
fn scene_files_load_and_their_errors_name_file_line_and_field() {
    let dir = tmp("scenes");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("tri.obj"),
        "v -5 0 -5\nv 5 0 -5\nv 0 0 5\nf 1 2 3\n",
    )
    .unwrap();
    let good = dir.join("good.toml");
    std::fs::write(&good, SCENE).unwrap();
    let scene = load_scene(&good).unwrap();
    assert_eq!(scene.objects.len(), 2);
    // vndf does not apply to Phong or Lambert: both fall back to brdf.
    assert_eq!(
        lobe_render::fallbacks(&scene, scene.settings.strategy).len(),
        2
    );
    let img = render(&scene, &scene.settings, |_| {});
    assert!(img.pixels.iter().all(|p| p.is_finite()));

    let bad = dir.join("bad.toml");
    std::fs::write(&bad, SCENE.replace("radius = 1", "radius = \"a\"")).unwrap();
    let e = load_scene(&bad).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "{}:13:10: field object[0].radius: invalid type: string \"a\", expected f64",
            bad.display()
        )
    );
    std::fs::write(&bad, SCENE.replace("exponent = 50", "exponent = -50")).unwrap();
    let e = load_scene(&bad).unwrap_err().to_string();
    assert!(
        e.contains("bad.toml:14:") && e.contains("field object[0].material.exponent: "),
        "{e}"
    );

    std::fs::write(&bad, SCENE.replace("\"sky\"", "\"maps/forest.hdr\"")).unwrap();
    let e = load_scene(&bad).unwrap_err().to_string();
    assert!(e.contains("field environment.path: "), "{e}");
    assert!(
        e.contains(&dir.join("maps/forest.hdr").display().to_string()),
        "{e}"
    );

    std::fs::write(&bad, SCENE.replace("tri.obj", "bunny.obj")).unwrap();
    let e = load_scene(&bad).unwrap_err().to_string();
    assert!(e.contains("field object[1].path: "), "{e}");
    assert!(
        e.contains(&dir.join("bunny.obj").display().to_string()),
        "{e}"
    );

    std::fs::write(dir.join("broken.obj"), "v 0 0 0\nv 1 0 0\nf 1 2 7\n").unwrap();
    std::fs::write(&bad, SCENE.replace("tri.obj", "broken.obj")).unwrap();
    let e = load_scene(&bad).unwrap_err().to_string();
    assert!(e.contains("broken.obj:3: "), "{e}");

    let e = load_scene(&dir.join("none.toml")).unwrap_err().to_string();
    assert!(e.contains("none.toml"), "{e}");

    std::fs::write(&bad, format!("{SCENE}spp_allocation = \"uniform\"\n")).unwrap();
    let s = load_scene(&bad).unwrap();
    assert_eq!(s.settings.spp_allocation, SppAllocation::Uniform);
    assert_eq!(scene.settings.spp_allocation, SppAllocation::Variance);
    std::fs::write(&bad, format!("{SCENE}spp_allocation = \"even\"\n")).unwrap();
    let e = load_scene(&bad).unwrap_err().to_string();
    assert!(
        e.contains("field render.spp_allocation: unknown spp allocation `even`, expected one of: uniform, variance"),
        "{e}"
    );
}

#[test]
fn the_shipped_scenes_and_the_showcase_render() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let file = load_scene(&dir.join("spheres-ground.toml")).unwrap();
    load_scene(&dir.join("spheres.toml")).unwrap();
    let built = lobe_render::showcase(32, 24).unwrap();
    assert_eq!(file.objects.len(), built.objects.len());
    for (a, b) in file.objects.iter().zip(&built.objects) {
        assert_eq!(a.material, b.material);
    }
    let img = render(&built, &opts(Strategy::mis(Heuristic::Power), 2), |_| {});
    assert!(
        img.pixels
            .iter()
            .all(|p| p.is_finite() && p.min_element() >= 0.0)
    );
    assert_eq!(img.stats.camera_rays, 32 * 24 * 2);
}

/// Progress comes in samples, several times within a pixel with many
/// samples, and adds up to width × height × spp (issue 8, item 7).
#[test]
fn progress_counts_samples_within_a_pixel() {
    use std::sync::atomic::{AtomicU64, Ordering};
    let scene = furnace_scene(2, 1);
    let (calls, total) = (AtomicU64::new(0), AtomicU64::new(0));
    let _ = render(
        &scene,
        &opts(Strategy::Bsdf(BsdfStrategy::Cosine), 10_000),
        |n| {
            calls.fetch_add(1, Ordering::Relaxed);
            total.fetch_add(n, Ordering::Relaxed);
        },
    );
    assert_eq!(total.load(Ordering::Relaxed), 2 * 10_000);
    assert!(calls.load(Ordering::Relaxed) >= 6, "{calls:?}");
}
