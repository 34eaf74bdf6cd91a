//! MERL `.binary` tables (Matusik et al. 2003): read, evaluate, write.
//!
//! The file is three little-endian `int32` dimensions (90, 90, 180: θh,
//! θd, φd), then `3 × 90 × 90 × 180` little-endian doubles, planar (every
//! red value, then green, then blue), scaled by 1/1500, 1.15/1500 and
//! 1.66/1500. The index of an entry is `φd + 180 (θd + 90 θh)`; θh is
//! indexed by `90 √(θh / (π/2))`, θd by `90 θd / (π/2)`, φd by `180 φd / π`
//! over `[0, π)` (φd and φd + π are one entry, by reciprocity). A negative
//! value marks a missing measurement.
//!
//! The values are kept as `f32`, one RGB triple per entry (17.5 MB).

use crate::math::Rgb;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

pub const N_THETA_H: usize = 90;
pub const N_THETA_D: usize = 90;
pub const N_PHI_D: usize = 180;
/// Entries per channel.
pub const N: usize = N_THETA_H * N_THETA_D * N_PHI_D;
/// The channel scales of MERL's reader.
pub const SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// Size of a MERL file in bytes.
pub const FILE_SIZE: usize = 12 + 3 * N * 8;

/// How a MERL table is looked up between its entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Interpolation {
    /// The entry the direction falls in, as MERL's own reader does.
    Nearest,
    /// Trilinear in the index coordinates (√θh, θd, φd), φd periodic;
    /// missing neighbours are left out and the weights renormalised.
    Linear,
}

impl Interpolation {
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Nearest => "nearest",
            Interpolation::Linear => "linear",
        }
    }
}

/// A MERL table: RGB per entry (already scaled), negative = missing.
#[derive(Clone)]
pub struct Merl {
    /// `[r, g, b]` of entry `φd + 180 (θd + 90 θh)`.
    values: Vec<[f32; 3]>,
    /// Entries with a measurement.
    pub valid: usize,
}

impl std::fmt::Debug for Merl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Merl {{ {} valid entries of {N} }}", self.valid)
    }
}

/// Whether `bytes` start like a MERL file (its three dimensions).
#[must_use]
pub fn looks_like(bytes: &[u8]) -> bool {
    dims(bytes) == Some([N_THETA_H as i32, N_THETA_D as i32, N_PHI_D as i32])
}

fn dims(bytes: &[u8]) -> Option<[i32; 3]> {
    let d = |i: usize| {
        bytes
            .get(4 * i..4 * i + 4)
            .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    Some([d(0)?, d(1)?, d(2)?])
}

/// The continuous index coordinates `(θh, θd, φd)` of a pair, each in
/// `[0, n)`: `wi` expressed in the frame of the half vector.
#[inline]
fn coords(wo: DVec3, wi: DVec3) -> (f64, f64, f64) {
    let h = (wo + wi).normalize();
    let theta_h = crate::math::safe_acos(h.z);
    let phi_h = h.y.atan2(h.x);
    // Rotate wi by −φh about z, then by −θh about y.
    let (sp, cp) = phi_h.sin_cos();
    let x = cp * wi.x + sp * wi.y;
    let y = -sp * wi.x + cp * wi.y;
    let (st, ct) = theta_h.sin_cos();
    let dx = ct * x - st * wi.z;
    let dz = st * x + ct * wi.z;
    let theta_d = crate::math::safe_acos(dz);
    let mut phi_d = y.atan2(dx);
    if phi_d < 0.0 {
        phi_d += PI;
    }
    (
        N_THETA_H as f64 * (theta_h / FRAC_PI_2).max(0.0).sqrt(),
        N_THETA_D as f64 * theta_d / FRAC_PI_2,
        N_PHI_D as f64 * phi_d / PI,
    )
}

#[inline]
fn index(ih: usize, id: usize, ip: usize) -> usize {
    ip + N_PHI_D * (id + N_THETA_D * ih)
}

/// The pair `(wo, wi)` at the centre of entry `(ih, id, ip)` (φh = 0).
#[must_use]
pub fn centre(ih: usize, id: usize, ip: usize) -> (DVec3, DVec3) {
    let u = (ih as f64 + 0.5) / N_THETA_H as f64;
    let theta_h = u * u * FRAC_PI_2;
    let theta_d = (id as f64 + 0.5) / N_THETA_D as f64 * FRAC_PI_2;
    let phi_d = (ip as f64 + 0.5) / N_PHI_D as f64 * PI;
    let d = DVec3::new(
        theta_d.sin() * phi_d.cos(),
        theta_d.sin() * phi_d.sin(),
        theta_d.cos(),
    );
    // Rotate d by θh about y (the inverse of `coords`).
    let (st, ct) = theta_h.sin_cos();
    let wi = DVec3::new(ct * d.x + st * d.z, d.y, -st * d.x + ct * d.z).normalize();
    let h = DVec3::new(st, 0.0, ct);
    let wo = crate::math::reflect(wi, h).normalize();
    (wo, wi)
}

impl Merl {
    /// Read a MERL file's bytes; the message says what is wrong.
    pub fn parse(bytes: &[u8]) -> Result<Merl, String> {
        let Some(d) = dims(bytes) else {
            return Err(format!(
                "truncated: {} bytes, a MERL file starts with three int32 dimensions (12 bytes)",
                bytes.len()
            ));
        };
        if d != [N_THETA_H as i32, N_THETA_D as i32, N_PHI_D as i32] {
            let claims = d
                .iter()
                .try_fold(3u128 * 8, |acc, &x| {
                    u128::try_from(x).ok().map(|x| acc * x)
                })
                .map_or("an impossible number of".to_string(), |b| b.to_string());
            return Err(format!(
                "dimensions {}×{}×{} (claiming {claims} bytes of data), expected MERL's 90×90×180",
                d[0], d[1], d[2]
            ));
        }
        let data = &bytes[12..];
        if data.len() < 3 * N * 8 {
            return Err(format!(
                "truncated: the header claims 3×90×90×180 doubles ({} bytes) but the file holds {} bytes after it",
                3 * N * 8,
                data.len()
            ));
        }
        if data.len() > 3 * N * 8 {
            return Err(format!(
                "{} bytes after the 3×90×90×180 doubles the header announces (not a MERL file?)",
                data.len() - 3 * N * 8
            ));
        }
        let mut values = vec![[0f32; 3]; N];
        let mut valid = 0;
        for c in 0..3 {
            let plane = &data[c * N * 8..(c + 1) * N * 8];
            for (i, (chunk, v)) in plane.chunks_exact(8).zip(values.iter_mut()).enumerate() {
                let x = f64::from_le_bytes(chunk.try_into().expect("8 bytes"));
                if !x.is_finite() {
                    let (ih, rest) = (i / (N_THETA_D * N_PHI_D), i % (N_THETA_D * N_PHI_D));
                    return Err(format!(
                        "entry {i} of the {} channel (θh {ih}, θd {}, φd {}) is {x}",
                        ["red", "green", "blue"][c],
                        rest / N_PHI_D,
                        rest % N_PHI_D
                    ));
                }
                v[c] = if x < 0.0 { -1.0 } else { (x * SCALE[c]) as f32 };
            }
        }
        for v in &mut values {
            if v.iter().any(|&x| x < 0.0) {
                *v = [-1.0; 3];
            } else {
                valid += 1;
            }
        }
        if valid == 0 {
            return Err(
                "no valid entry: every value is negative (a missing measurement)".to_string(),
            );
        }
        Ok(Merl { values, valid })
    }

    /// A table from `f(wo, wi)` (no cosine) at the entries' centres; `missing`
    /// marks entries as missing measurements. An entry whose centre is below
    /// the horizon is missing too.
    pub fn from_fn(
        f: impl Fn(DVec3, DVec3) -> Rgb + Sync,
        missing: impl Fn(usize) -> bool + Sync,
    ) -> Merl {
        let row = |ih: usize| -> Vec<[f32; 3]> {
            let mut out = Vec::with_capacity(N_THETA_D * N_PHI_D);
            for id in 0..N_THETA_D {
                for ip in 0..N_PHI_D {
                    let (wo, wi) = centre(ih, id, ip);
                    let v = if wo.z <= 0.0 || wi.z <= 0.0 || missing(index(ih, id, ip)) {
                        [-1.0; 3]
                    } else {
                        let c = f(wo, wi);
                        [c.x as f32, c.y as f32, c.z as f32]
                    };
                    out.push(v);
                }
            }
            out
        };
        #[cfg(feature = "parallel")]
        let rows: Vec<Vec<[f32; 3]>> = {
            use rayon::prelude::*;
            (0..N_THETA_H).into_par_iter().map(row).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let rows: Vec<Vec<[f32; 3]>> = (0..N_THETA_H).map(row).collect();
        let values: Vec<[f32; 3]> = rows.into_iter().flatten().collect();
        let valid = values.iter().filter(|v| v[0] >= 0.0).count();
        Merl { values, valid }
    }

    /// The file's bytes (MERL's layout and scales).
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(FILE_SIZE);
        for d in [N_THETA_H, N_THETA_D, N_PHI_D] {
            out.extend_from_slice(&(d as i32).to_le_bytes());
        }
        for c in 0..3 {
            for v in &self.values {
                let x = if v[c] < 0.0 {
                    -1.0
                } else {
                    f64::from(v[c]) / SCALE[c]
                };
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        out
    }

    /// Entry `i` (already scaled), `None` when missing.
    #[must_use]
    pub fn entry(&self, i: usize) -> Option<Rgb> {
        let v = self.values[i];
        (v[0] >= 0.0).then(|| Rgb::new(v[0].into(), v[1].into(), v[2].into()))
    }

    /// Entries in the table.
    #[must_use]
    pub fn len(&self) -> usize {
        self.values.len()
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Bytes held.
    #[must_use]
    pub fn memory(&self) -> usize {
        self.values.len() * std::mem::size_of::<[f32; 3]>()
    }

    /// `f_r(wo, wi)` without the cosine; a missing entry gives zero.
    #[must_use]
    pub fn eval(&self, wo: DVec3, wi: DVec3, interpolation: Interpolation) -> Rgb {
        let (xh, xd, xp) = coords(wo, wi);
        match interpolation {
            Interpolation::Nearest => {
                let ih = (xh as usize).min(N_THETA_H - 1);
                let id = (xd as usize).min(N_THETA_D - 1);
                let ip = (xp as usize).min(N_PHI_D - 1);
                self.entry(index(ih, id, ip)).unwrap_or(Rgb::ZERO)
            }
            Interpolation::Linear => {
                // Entry centres at integer + 0.5: clamp θh and θd, wrap φd.
                let split = |x: f64, n: usize| {
                    let x = (x - 0.5).clamp(0.0, (n - 1) as f64);
                    let i = (x as usize).min(n - 2);
                    (i, x - i as f64)
                };
                let (ih, fh) = split(xh, N_THETA_H);
                let (id, fd) = split(xd, N_THETA_D);
                let xp = (xp - 0.5).rem_euclid(N_PHI_D as f64);
                let ip = (xp as usize).min(N_PHI_D - 1);
                let fp = xp - ip as f64;
                let mut sum = Rgb::ZERO;
                let mut wsum = 0.0;
                for (dh, wh) in [(0, 1.0 - fh), (1, fh)] {
                    for (dd, wd) in [(0, 1.0 - fd), (1, fd)] {
                        for (dp, wp) in [(0, 1.0 - fp), (1, fp)] {
                            let w = wh * wd * wp;
                            if w <= 0.0 {
                                continue;
                            }
                            if let Some(v) =
                                self.entry(index(ih + dh, id + dd, (ip + dp) % N_PHI_D))
                            {
                                sum += w * v;
                                wsum += w;
                            }
                        }
                    }
                }
                if wsum > 0.0 { sum / wsum } else { Rgb::ZERO }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centres_index_back_to_their_entry() {
        for &(ih, id, ip) in &[(0, 0, 0), (10, 20, 30), (45, 44, 179), (89, 3, 90), (30, 60, 1)] {
            let (wo, wi) = centre(ih, id, ip);
            let (xh, xd, xp) = coords(wo, wi);
            assert_eq!(
                (xh as usize, xd as usize, xp as usize),
                (ih, id, ip),
                "{xh} {xd} {xp}"
            );
            // Reciprocity: swapping the directions gives φd + π, one entry.
            let (xh2, xd2, xp2) = coords(wi, wo);
            assert_eq!((xh2 as usize, xd2 as usize, xp2 as usize), (ih, id, ip));
        }
    }
}
