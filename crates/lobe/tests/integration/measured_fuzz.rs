//! Fuzzing of the MERL and RGL readers: seeded mutations of valid files
//! (random bytes, special values, truncation, extension, header fields
//! overwritten with large numbers, chunks swapped) must never panic; a file
//! that is accepted must evaluate to finite, non-negative values without
//! panicking. The corpus of past crashers in `tests/corpus/` is replayed.
//!
//! An accepted RGL file's own warps are drawn from and their pdf
//! evaluated; every 100th accepted file (10th in the long run) also builds
//! the tabulated sampler, which is drawn from and evaluated.
//!
//! `cargo test -p lobe --test integration measured_fuzz::` runs a short
//! round (a few s); the long run is `LOBE_FUZZ_SECONDS=600 cargo test -p
//! lobe --release --test integration measured_fuzz:: -- --ignored
//! --nocapture` (crashers are written to `target/fuzz-crashers/`).

use glam::{DVec2, DVec3};
use lobe::models::measured::merl::Interpolation;
use lobe::models::measured::rgl::Rgl;
use lobe::models::measured::{MeasuredData, Table, merl::Merl};
use rand::{Rng, RngExt, SeedableRng};
use rand_pcg::Pcg64;
use std::panic::{AssertUnwindSafe, catch_unwind};

fn seed_rgl(n_theta: usize, n: usize) -> Vec<u8> {
    Rgl::write(
        |wo: DVec3, wi: DVec3| {
            let h = (wo + wi).normalize();
            lobe::Rgb::new(0.2, 0.3, 0.1) + lobe::Rgb::splat(3.0 * h.z.powi(40))
        },
        n_theta,
        n,
        "fuzz seed",
    )
}

fn seed_merl() -> Vec<u8> {
    Merl::from_fn(
        |wo, wi| lobe::Rgb::splat(0.1 + (wo + wi).normalize().z.powi(20)),
        |i| i % 13 == 0,
    )
    .to_bytes()
}

/// One mutation of `bytes` (in place or replacing it).
fn mutate(rng: &mut Pcg64, bytes: &mut Vec<u8>) {
    let len = bytes.len().max(1);
    match rng.random_range(0..8) {
        0 => {
            for _ in 0..rng.random_range(1..8) {
                let i = rng.random_range(0..len);
                if let Some(b) = bytes.get_mut(i) {
                    *b ^= 1 << rng.random_range(0..8);
                }
            }
        }
        1 => {
            let i = rng.random_range(0..len);
            let v: u8 =
                [0x00, 0xff, 0x7f, 0x80, 0x7f80_0000u32.to_le_bytes()[2]][rng.random_range(0..5)];
            if let Some(b) = bytes.get_mut(i) {
                *b = v;
            }
        }
        2 => {
            let keep = rng.random_range(0..len);
            bytes.truncate(keep);
        }
        3 => {
            let extra = rng.random_range(1..64);
            bytes.extend((0..extra).map(|_| rng.random::<u8>()));
        }
        4 => {
            // A header-sized field: a large or small integer at an offset
            // within the first few hundred bytes.
            let i = rng.random_range(0..len.min(400));
            let v: u64 = match rng.random_range(0..4) {
                0 => u64::MAX,
                1 => rng.random::<u64>(),
                2 => rng.random_range(0..1000),
                _ => 1 << rng.random_range(0..63),
            };
            let w = [1usize, 2, 4, 8][rng.random_range(0..4)];
            for (k, b) in v.to_le_bytes().iter().take(w).enumerate() {
                if let Some(x) = bytes.get_mut(i + k) {
                    *x = *b;
                }
            }
        }
        5 => {
            // An f32 or f64 special value anywhere.
            let i = rng.random_range(0..len);
            let specials32 = [f32::NAN, f32::INFINITY, -1.0, 0.0, 1e38, -0.0];
            let specials64 = [f64::NAN, f64::NEG_INFINITY, -1.0, 1e308];
            if rng.random::<bool>() {
                let v = specials32[rng.random_range(0..specials32.len())].to_le_bytes();
                for (k, b) in v.iter().enumerate() {
                    if let Some(x) = bytes.get_mut(i + k) {
                        *x = *b;
                    }
                }
            } else {
                let v = specials64[rng.random_range(0..specials64.len())].to_le_bytes();
                for (k, b) in v.iter().enumerate() {
                    if let Some(x) = bytes.get_mut(i + k) {
                        *x = *b;
                    }
                }
            }
        }
        6 => {
            // Swap two chunks.
            if len > 16 {
                let n = rng.random_range(1..len.min(64) / 2);
                let a = rng.random_range(0..len - n);
                let b = rng.random_range(0..len - n);
                for k in 0..n {
                    bytes.swap(a + k, b + k);
                }
            }
        }
        _ => {
            // Random bytes of a random length, behind a valid magic.
            let n = rng.random_range(0..256);
            let magic: &[u8] = if rng.random::<bool>() {
                b"tensor_file\0\x01\x00"
            } else {
                &[90, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0]
            };
            *bytes = magic
                .iter()
                .copied()
                .chain((0..n).map(|_| rng.random::<u8>()))
                .collect();
        }
    }
}

/// Parse, and when accepted evaluate at a few pairs (and an RGL file's
/// warps; with `build` also build the tabulated sampler and draw from it):
/// `Err` describes a panic or a bad value.
fn check(bytes: &[u8], rng: &mut impl Rng, build: bool) -> Result<bool, String> {
    let parsed = catch_unwind(AssertUnwindSafe(|| Table::parse(bytes, "fuzz")))
        .map_err(|_| "Table::parse panicked".to_string())?;
    let Ok(table) = parsed else { return Ok(false) };
    let pairs: Vec<(DVec3, DVec3)> = (0..16)
        .map(|_| {
            let d = |rng: &mut dyn FnMut() -> f64| {
                let (a, b) = (rng(), rng());
                let t = (a * 0.999).acos();
                let p = std::f64::consts::TAU * b;
                DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
            };
            let mut r = || rng.random::<f64>();
            (d(&mut r), d(&mut r))
        })
        .collect();
    let us: Vec<DVec2> = (0..pairs.len())
        .map(|_| DVec2::new(rng.random(), rng.random()))
        .collect();
    catch_unwind(AssertUnwindSafe(|| {
        for ((wo, wi), u) in pairs.iter().zip(&us) {
            for interp in [Interpolation::Nearest, Interpolation::Linear] {
                let f = table.eval(*wo, *wi, interp);
                if !(f.is_finite() && f.min_element() >= 0.0) {
                    return Err(format!("eval({wo}, {wi}) = {f}"));
                }
            }
            // An RGL file's own warps (the `vndf` strategy).
            if let Table::Rgl(r) = &table {
                let p = r.pdf_warps(*wo, *wi);
                if !(p.is_finite() && p >= 0.0) {
                    return Err(format!("pdf_warps({wo}, {wi}) = {p}"));
                }
                if let Some(s) = r.sample_warps(*wo, *u)
                    && !(s.is_finite() && s.z > 0.0 && (s.length() - 1.0).abs() < 1e-9)
                {
                    return Err(format!("sample_warps({wo}, {u}) = {s}"));
                }
            }
        }
        Ok(())
    }))
    .map_err(|_| "eval or the RGL warps panicked".to_string())??;
    if build {
        // The tabulated sampler built from the table (`brdf`).
        catch_unwind(AssertUnwindSafe(|| {
            let data = MeasuredData::new("fuzz".into(), table, Interpolation::Nearest, 0.0);
            for ((wo, wi), u) in pairs.iter().zip(&us) {
                let p = data.sampler.pdf(*wo, *wi);
                if !(p.is_finite() && p > 0.0) {
                    return Err(format!("sampler pdf({wo}, {wi}) = {p}"));
                }
                if let Some(s) = data.sampler.sample(*wo, *u) {
                    let p = data.sampler.pdf(*wo, s);
                    if !(s.is_finite() && s.z > 0.0 && p.is_finite() && p > 0.0) {
                        return Err(format!("sampler sample({wo}, {u}) = {s}, pdf {p}"));
                    }
                }
            }
            Ok(())
        }))
        .map_err(|_| "building or using the sampler panicked".to_string())??;
    }
    Ok(true)
}

/// Run mutations from the seeds until `deadline` or `iterations` (every
/// `build_every`-th accepted file also builds the tabulated sampler);
/// returns the number run, the number accepted and the crashers found.
fn fuzz(
    seed: u64,
    iterations: usize,
    deadline: Option<std::time::Instant>,
    build_every: usize,
) -> (usize, usize, Vec<(String, Vec<u8>)>) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let seeds = [seed_rgl(3, 6), seed_rgl(2, 2), seed_rgl(5, 9)];
    let merl = seed_merl();
    let mut crashers = Vec::new();
    let mut done = 0;
    let mut accepted = 0;
    while done < iterations && deadline.is_none_or(|d| std::time::Instant::now() < d) {
        // MERL files are 35 MB: one in 200.
        let mut bytes = if done % 200 == 199 {
            merl.clone()
        } else {
            seeds[rng.random_range(0..seeds.len())].clone()
        };
        for _ in 0..rng.random_range(1..4) {
            mutate(&mut rng, &mut bytes);
        }
        // Every `build_every`-th accepted file also builds its sampler.
        let build = accepted % build_every == build_every - 1;
        match check(&bytes, &mut rng, build) {
            Ok(ok) => accepted += usize::from(ok),
            Err(e) => crashers.push((e, bytes)),
        }
        done += 1;
    }
    (done, accepted, crashers)
}

fn report(crashers: &[(String, Vec<u8>)]) {
    if crashers.is_empty() {
        return;
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/fuzz-crashers");
    let _ = std::fs::create_dir_all(&dir);
    for (i, (_, b)) in crashers.iter().enumerate() {
        let _ = std::fs::write(dir.join(format!("crash-{i}.bin")), b);
    }
    panic!(
        "{} crashers (written to {}): {:?}",
        crashers.len(),
        dir.display(),
        crashers.iter().map(|c| &c.0).take(5).collect::<Vec<_>>()
    );
}

#[test]
fn mutated_files_never_panic() {
    let (n, accepted, crashers) = fuzz(1, 2000, None, 100);
    assert_eq!(n, 2000);
    // The mutations must leave some files valid, so that eval is fuzzed too.
    assert!(accepted > 100, "{accepted} of {n} accepted");
    report(&crashers);
}

/// The long run: `LOBE_FUZZ_SECONDS` (default 600) seconds.
#[test]
#[ignore]
fn fuzz_for_a_long_time() {
    let secs: u64 = std::env::var("LOBE_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(600);
    let t0 = std::time::Instant::now();
    let deadline = t0 + std::time::Duration::from_secs(secs);
    let seed: u64 = std::env::var("LOBE_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2);
    let (n, accepted, crashers) = fuzz(seed, usize::MAX, Some(deadline), 10);
    eprintln!(
        "fuzzed {n} files in {:.0} s (seed {seed}): {accepted} accepted and evaluated, {} crashers",
        t0.elapsed().as_secs_f64(),
        crashers.len()
    );
    report(&crashers);
}

/// The corpus of files that once crashed a reader (and the hand-made edge
/// cases next to them) parse or fail without a panic.
#[test]
fn corpus_replays_without_panics() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let mut rng = Pcg64::seed_from_u64(3);
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        check(&bytes, &mut rng, true).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        n += 1;
    }
    assert!(n > 0, "empty corpus in {}", dir.display());
}
