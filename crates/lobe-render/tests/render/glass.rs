//! Glass, mirrors and plastic in the renderer (issue 42): refraction into
//! and out of closed objects (spheres and meshes) in white furnaces, an
//! index-matched sphere that is invisible, light sampling's fallback on
//! delta lobes, and MIS against its parts with glass in the scene.

use super::*;

fn load(json: &str) -> Material {
    Material::load(json).unwrap_or_else(|e| panic!("{json}: {e}"))
}

/// One sphere of `m` in the middle of the view under `env`.
fn sphere_scene(m: Material, env: EnvMap) -> Scene {
    let camera = Camera::new(
        DVec3::new(0.0, 0.0, 3.5),
        DVec3::ZERO,
        DVec3::Y,
        40.0,
        32,
        24,
    )
    .unwrap();
    Scene::new(camera, env).with(Object::sphere(DVec3::ZERO, 1.0, m).unwrap())
}

/// Every strategy the renderer takes at one vertex, as a user names them.
fn strategies() -> [Strategy; 5] {
    [
        Strategy::Bsdf(BsdfStrategy::Brdf),
        Strategy::Light,
        Strategy::MIS,
        Strategy::mis(Heuristic::Balance),
        Strategy::mis(Heuristic::Power),
    ]
}

#[test]
fn a_white_mirror_sphere_is_white_and_light_sampling_falls_back() {
    // A delta mirror with F = 1: every camera ray that hits it reflects
    // once and escapes with weight 1, exactly, whatever the strategy: light
    // samples never hit a delta lobe, so `light` falls back to BSDF
    // sampling on it (and says so).
    let scene = sphere_scene(
        load(r#"{"type":"conductor","material":"none"}"#),
        EnvMap::constant(Rgb::ONE),
    );
    let px = covered(&scene, 0);
    assert!(px.len() > 150);
    for method in strategies() {
        let img = render(&scene, &opts(method, 4), |_| {});
        for &(x, y) in &px {
            let v = img.get(x, y);
            assert!(
                (v - Rgb::ONE).abs().max_element() < 1e-12,
                "{method}: ({x}, {y}) = {v}"
            );
        }
    }
    let f = lobe_render::fallbacks(&scene, Strategy::Light);
    assert_eq!(f.len(), 1);
    assert_eq!(f[0].used, Strategy::Bsdf(BsdfStrategy::Brdf), "{f:?}");
    assert!(lobe_render::fallbacks(&scene, Strategy::MIS).is_empty());
}

#[test]
fn glass_in_a_white_furnace_is_white() {
    // Smooth glass and a thin pane neither absorb nor lose light: every
    // path enters and leaves (radiance's 1/η² on the way in is η² on the
    // way out) and the image is 1 up to Russian roulette's noise and the
    // depth limit (64 bounces, where a path is left with almost nothing).
    // Seen from outside and, through the sphere's far side, from inside.
    for json in [
        r#"{"type":"dielectric"}"#,
        r#"{"type":"dielectric","int_ior":"diamond"}"#,
        r#"{"type":"dielectric","int_ior":1.0,"ext_ior":1.5}"#,
        r#"{"type":"thindielectric"}"#,
    ] {
        let scene = sphere_scene(load(json), EnvMap::constant(Rgb::ONE));
        let px = covered(&scene, 0);
        for method in strategies() {
            let o = RenderSettings {
                max_depth: 64,
                ..opts(method, 16)
            };
            let img = render(&scene, &o, |_| {});
            assert_eq!(img.stats.nonfinite, 0);
            let (m, se) = mean_se(&img, &px, |p| p.y);
            assert!(
                (m - 1.0).abs() < 4.0 * se + 1e-3,
                "{json} {method}: mean {m} ± {se}"
            );
        }
    }
}

#[test]
fn a_closed_glass_mesh_in_a_white_furnace_is_white() {
    // The octahedron of `white_furnace_convex_mesh_is_exact`, outward
    // faces, smooth glass: flat faces trap light by total internal
    // reflection for many bounces; at depth 64 what is left is small.
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
    let scene = Scene::new(camera, EnvMap::constant(Rgb::ONE))
        .with(Object::mesh(mesh, load(r#"{"type":"dielectric"}"#)));
    let px = covered(&scene, 0);
    assert!(px.len() > 100);
    let o = RenderSettings {
        max_depth: 64,
        ..opts(Strategy::MIS, 32)
    };
    let img = render(&scene, &o, |_| {});
    let (m, se) = mean_se(&img, &px, |p| p.y);
    assert!((m - 1.0).abs() < 4.0 * se + 3e-3, "mean {m} ± {se}");
}

#[test]
fn rough_glass_loses_light_and_never_gains() {
    // Rough glass loses the light that scatters between microfacets more
    // than once: in a white furnace its sphere is at most 1, and the
    // rougher the darker.
    let mut means = Vec::new();
    for alpha in [0.1, 0.5] {
        let json = format!(r#"{{"type":"roughdielectric","alpha":{alpha}}}"#);
        let scene = sphere_scene(load(&json), EnvMap::constant(Rgb::ONE));
        let px = covered(&scene, 0);
        for method in [Strategy::Bsdf(BsdfStrategy::Vndf), Strategy::MIS] {
            let o = RenderSettings {
                max_depth: 64,
                ..opts(method, 16)
            };
            let img = render(&scene, &o, |_| {});
            assert_eq!(img.stats.nonfinite, 0);
            let (m, se) = mean_se(&img, &px, |p| p.y);
            assert!(m < 1.0 + 4.0 * se && m > 0.8, "{json} {method}: {m} ± {se}");
            if method == Strategy::MIS {
                means.push((m, se));
            }
        }
    }
    let ((smooth, a), (rough, b)) = (means[0], means[1]);
    assert!(rough + 4.0 * (a * a + b * b).sqrt() < smooth, "{means:?}");
}

#[test]
fn an_index_matched_sphere_is_invisible() {
    // η = 1: the interface does nothing, light goes straight through (a
    // delta transmission with weight 1), and the image is the sky's.
    let empty = Scene::new(
        sphere_scene(lambert(0.5), smooth_env()).camera,
        smooth_env(),
    );
    for json in [
        r#"{"type":"dielectric","int_ior":1.5,"ext_ior":1.5}"#,
        r#"{"type":"roughdielectric","alpha":0.3,"int_ior":"water","ext_ior":"water"}"#,
    ] {
        let scene = sphere_scene(load(json), smooth_env());
        let px = covered(&scene, 0);
        let o = RenderSettings {
            max_depth: 4,
            ..opts(Strategy::MIS, 8)
        };
        let a = render(&scene, &o, |_| {});
        let b = render(&empty, &o, |_| {});
        for &(x, y) in &px {
            let (va, vb) = (a.get(x, y), b.get(x, y));
            assert!(
                (va - vb).abs().max_element() < 1e-9 * (1.0 + vb.max_element()),
                "{json}: ({x}, {y}) {va} against the sky's {vb}"
            );
        }
    }
}

/// Smooth glass, rough glass, rough plastic and a mirror on a grey plane
/// under the smooth sky, 32 × 24.
fn glass_scene() -> Scene {
    let camera = Camera::new(
        DVec3::new(0.0, 1.2, 4.0),
        DVec3::new(0.0, 0.5, 0.0),
        DVec3::Y,
        45.0,
        32,
        24,
    )
    .unwrap();
    let spheres = [
        (-1.5, r#"{"type":"dielectric"}"#),
        (-0.5, r#"{"type":"roughdielectric","alpha":0.2}"#),
        (
            0.5,
            r#"{"type":"roughplastic","alpha":0.2,"diffuse_reflectance":[0.6,0.2,0.1]}"#,
        ),
        (1.5, r#"{"type":"conductor","material":"Au"}"#),
    ];
    let mut scene = Scene::new(camera, smooth_env())
        .with(Object::plane(DVec3::ZERO, DVec3::Y, lambert(0.6)).unwrap());
    for (x, json) in spheres {
        scene = scene.with(Object::sphere(DVec3::new(x, 0.45, 0.0), 0.45, load(json)).unwrap());
    }
    scene
}

/// Per-pixel squared error of `img` against `reference` over `px`, summed.
fn squared_error(img: &Image, reference: &Image, px: &[(usize, usize)]) -> f64 {
    px.iter()
        .map(|&(x, y)| {
            let d = img.get(x, y) - reference.get(x, y);
            d.dot(d)
        })
        .sum()
}

#[test]
fn strategies_agree_with_glass_and_mis_is_never_much_worse_than_its_parts() {
    // Every strategy renders the same image of glass, plastic and a mirror
    // (per-pixel differences from a reference have mean zero), and MIS's
    // error is within 1.5× the better of BSDF and light sampling's, object
    // by object, over 4 seeds.
    let scene = glass_scene();
    let depth = |o: RenderSettings| RenderSettings { max_depth: 8, ..o };
    let mut reference = depth(opts(Strategy::MIS, 512));
    reference.seed = 99;
    let reference = render(&scene, &reference, |_| {});
    assert_eq!(reference.stats.nonfinite, 0);
    let objects: Vec<Vec<(usize, usize)>> = (0..scene.objects.len())
        .map(|i| covered(&scene, i))
        .collect();
    for (i, px) in objects.iter().enumerate() {
        assert!(px.len() > 8, "object {i}: {} pixels", px.len());
    }
    let mut errors = Vec::new();
    for method in [
        Strategy::Bsdf(BsdfStrategy::Vndf),
        Strategy::Light,
        Strategy::MIS,
    ] {
        let mut err = vec![0.0; objects.len()];
        for seed in 0..4 {
            let mut o = depth(opts(method, 16));
            o.seed = seed;
            let img = render(&scene, &o, |_| {});
            assert_eq!(img.stats.nonfinite, 0);
            for (i, px) in objects.iter().enumerate() {
                err[i] += squared_error(&img, &reference, px);
            }
            let diff = difference(&img, &reference);
            let all: Vec<_> = objects.iter().flatten().copied().collect();
            let (m, se) = mean_se(&diff, &all, lobe::math::luminance);
            assert!(
                m.abs() < 4.5 * se,
                "{method} seed {seed}: mean difference {m} ± {se}"
            );
        }
        errors.push(err);
    }
    let [bsdf, light, mis] = &errors[..] else {
        unreachable!("three strategies")
    };
    for (i, ((b, l), m)) in bsdf.iter().zip(light).zip(mis).enumerate() {
        assert!(
            *m <= 1.5 * b.min(*l),
            "object {i}: mis {m} against bsdf {b} and light {l}"
        );
    }
}

#[test]
fn glass_renders_on_the_scalar_loop_and_the_batch_loop_says_why() {
    let scene = glass_scene();
    let why = lobe_render::integrator::batch_refusal(&scene, Strategy::MIS, 1).unwrap();
    assert!(why.contains("glass takes the scalar loop"), "{why}");
    let o = opts(Strategy::MIS, 2);
    let batch = render(&scene, &o, |_| {});
    let scalar = render(
        &scene,
        &RenderSettings {
            render_loop: RenderLoop::Scalar,
            ..o
        },
        |_| {},
    );
    assert_eq!(batch.pixels, scalar.pixels);
}

#[test]
fn a_shallow_render_of_glass_says_so() {
    let scene = glass_scene();
    let n = lobe_render::integrator::shallow_glass(&scene, 1).unwrap();
    assert!(
        n.contains("object 1 (dielectric)") && n.contains("max_depth 1"),
        "{n}"
    );
    assert!(lobe_render::integrator::shallow_glass(&scene, 3).is_none());
    let opaque = sphere_scene(load(r#"{"type":"conductor"}"#), smooth_env());
    assert!(lobe_render::integrator::shallow_glass(&opaque, 1).is_none());
}

#[test]
fn a_failed_bsdf_draw_ends_the_path_whatever_the_strategy() {
    // A BSDF draw that fails (brdf sampling of a microfacet lobe draws
    // normals that send light below the horizon, or into the wrong side of
    // glass) counts zero and ends the path; drawing again would give the
    // path a second chance and more light than the scene has. Strategies
    // that fail at different rates must agree: in a white furnace, rough
    // glass and a rough conductor on a white plane, 4 bounces.
    for json in [
        r#"{"type":"roughdielectric","distribution":"ggx","alpha":0.3}"#,
        r#"{"type":"roughconductor","distribution":"ggx","alpha":0.6,"material":"none"}"#,
    ] {
        let mut scene = sphere_scene(load(json), EnvMap::constant(Rgb::ONE));
        scene =
            scene.with(Object::plane(DVec3::new(0.0, -1.0, 0.0), DVec3::Y, lambert(0.8)).unwrap());
        let px = covered(&scene, 0);
        let images: Vec<(Strategy, Image)> = [
            Strategy::Bsdf(BsdfStrategy::Brdf),
            Strategy::Bsdf(BsdfStrategy::Vndf),
            Strategy::Light,
        ]
        .into_iter()
        .map(|method| {
            let o = RenderSettings {
                max_depth: 4,
                sequence: lobe::sequence::Sequence::Independent,
                ..opts(method, 128)
            };
            (method, render(&scene, &o, |_| {}))
        })
        .collect();
        // Pixel by pixel: the differences have mean zero.
        for (a, ia) in &images {
            for (b, ib) in &images {
                if a == b {
                    continue;
                }
                let diff = difference(ia, ib);
                let (m, se) = mean_se(&diff, &px, |p| p.y);
                assert!(m.abs() < 4.5 * se, "{json}: {a} − {b}: {m} ± {se}");
            }
        }
    }
}
