//! RGL `.bsdf` files: the tensor file of Dupuy and Jakob 2018 ("An Adaptive
//! Parameterization for Efficient Material Acquisition and Rendering"), as
//! Mitsuba 3's `measured` plugin and pbrt-v4's `MeasuredBxDF` read it.
//!
//! A tensor file is the 12 bytes `tensor_file\0`, a version (two bytes,
//! 1.0), a `u32` field count, then per field: a `u16` name length, the
//! name, a `u16` rank, a `u8` type (1 u8, 2 i8, 3 u16, 4 i16, 5 u32, 6 i32,
//! 7 u64, 8 i64, 9 f16, 10 f32, 11 f64), a `u64` byte offset and one `u64`
//! per axis; the data of each field is at its offset, little-endian,
//! row-major.
//!
//! A BRDF file has the fields `description` (u8), `jacobian` (one u8),
//! `theta_i` and `phi_i` (f32, the viewing directions the tables are
//! measured at), `ndf` and `sigma` (f32 2D), `vndf` and `luminance` (f32
//! `[φi, θi, n, n]`), and `rgb` (f32 `[φi, θi, 3, n, n]`) or `spectra` (f32
//! `[φi, θi, λ, n, n]`) with `wavelengths` (f32, nm). The value at the
//! viewing direction `wo` and the half vector `m` is found by inverting the
//! visible-normal warp `vndf` at `u_m = (√(θm/(π/2)), (φm − φo + π)/(2π))`
//! into the unit square, where `rgb` is bilinearly interpolated (and
//! linearly between the measured views); with `jacobian = 1` it is then
//! multiplied by `ndf(u_m) / (4 sigma(u_wo))`. The result is `f_r cos θi`.
//!
//! Spectral files are reduced to RGB when read: CIE 1931 colour matching
//! functions (the multi-lobe fit of Wyman, Sloan and Shirley 2013) to XYZ,
//! then to linear Rec. 709, each channel scaled so that a constant spectrum
//! of 1 gives RGB 1 (illuminant E, white balanced).
//!
//! Only isotropic files are read (`phi_i` with at most two entries, as
//! Mitsuba decides): an anisotropic file is refused with an error.

use crate::math::Rgb;
use glam::{DVec2, DVec3};
use std::collections::HashMap;
use std::f32::consts::PI as PI32;

/// Element types of a tensor file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DType {
    U8 = 1,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F16,
    F32,
    F64,
}

impl DType {
    fn from_u8(x: u8) -> Option<DType> {
        use DType::*;
        Some(match x {
            1 => U8,
            2 => I8,
            3 => U16,
            4 => I16,
            5 => U32,
            6 => I32,
            7 => U64,
            8 => I64,
            9 => F16,
            10 => F32,
            11 => F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        use DType::*;
        match self {
            U8 | I8 => 1,
            U16 | I16 | F16 => 2,
            U32 | I32 | F32 => 4,
            U64 | I64 | F64 => 8,
        }
    }
}

/// One field of a tensor file.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub dtype: DType,
    pub shape: Vec<usize>,
    /// The field's bytes.
    pub data: Vec<u8>,
}

impl Field {
    /// A field of `f32` values.
    #[must_use]
    pub fn f32(shape: &[usize], values: &[f32]) -> Field {
        debug_assert_eq!(shape.iter().product::<usize>(), values.len());
        Field {
            dtype: DType::F32,
            shape: shape.to_vec(),
            data: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }

    /// A field of bytes.
    #[must_use]
    pub fn u8(values: &[u8]) -> Field {
        Field {
            dtype: DType::U8,
            shape: vec![values.len()],
            data: values.to_vec(),
        }
    }

    fn as_f32(&self) -> Vec<f32> {
        self.data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }
}

const MAGIC: &[u8; 12] = b"tensor_file\0";

/// Whether `bytes` start like a tensor file.
#[must_use]
pub fn looks_like(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// A little-endian reader that reports how far it got.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(format!(
                "truncated: the file ends at byte {} inside {what}",
                self.bytes.len()
            ));
        };
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.take(1, what)?[0])
    }
    fn u16(&mut self, what: &str) -> Result<u16, String> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
}

/// Parse a tensor file into its fields; the message says what is wrong.
pub fn parse_tensor(bytes: &[u8]) -> Result<HashMap<String, Field>, String> {
    if bytes.len() < 18 {
        return Err(format!(
            "truncated: {} bytes, smaller than a tensor file header (18 bytes)",
            bytes.len()
        ));
    }
    if !looks_like(bytes) {
        return Err("not a tensor file (no `tensor_file` header)".into());
    }
    let mut r = Reader { bytes, at: 12 };
    let (major, minor) = (r.u8("the version")?, r.u8("the version")?);
    if major != 1 || minor != 0 {
        return Err(format!(
            "tensor file version {major}.{minor}, expected 1.0"
        ));
    }
    let n = r.u32("the field count")?;
    let mut fields = HashMap::new();
    for i in 0..n {
        let what = format!("the header of field {i}");
        let len = r.u16(&what)? as usize;
        let name = String::from_utf8(r.take(len, &what)?.to_vec())
            .map_err(|_| format!("field {i}: its name is not UTF-8"))?;
        let ndim = r.u16(&what)? as usize;
        let dt = r.u8(&what)?;
        let dtype = DType::from_u8(dt)
            .ok_or_else(|| format!("field `{name}`: unknown element type {dt}"))?;
        let offset = r.u64(&what)?;
        let mut shape = Vec::with_capacity(ndim.min(16));
        for _ in 0..ndim {
            shape.push(r.u64(&what)?);
        }
        let count = shape
            .iter()
            .try_fold(1u64, |a, &x| a.checked_mul(x))
            .and_then(|c| c.checked_mul(dtype.size() as u64));
        let end = count.and_then(|c| c.checked_add(offset));
        let holds = bytes.len() as u64;
        let Some(end) = end.filter(|&e| e <= holds) else {
            return Err(format!(
                "field `{name}` (shape {shape:?}) claims bytes from {offset} to {} but the file holds {holds} bytes",
                end.map_or("beyond 2^64".to_string(), |e| e.to_string())
            ));
        };
        let shape: Vec<usize> = shape.into_iter().map(|x| x as usize).collect();
        let data = bytes[offset as usize..end as usize].to_vec();
        fields.insert(name, Field { dtype, shape, data });
    }
    Ok(fields)
}

/// A tensor file's bytes, the fields in the order given.
#[must_use]
pub fn write_tensor(fields: &[(&str, Field)]) -> Vec<u8> {
    let header: usize = 12
        + 2
        + 4
        + fields
            .iter()
            .map(|(n, f)| 2 + n.len() + 2 + 1 + 8 + 8 * f.shape.len())
            .sum::<usize>();
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    let mut offset = header;
    for (name, f) in fields {
        out.extend_from_slice(&(name.len() as u16).to_le_bytes());
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(&(f.shape.len() as u16).to_le_bytes());
        out.push(f.dtype as u8);
        out.extend_from_slice(&(offset as u64).to_le_bytes());
        for &s in &f.shape {
            out.extend_from_slice(&(s as u64).to_le_bytes());
        }
        offset += f.data.len();
    }
    debug_assert_eq!(out.len(), header);
    for (_, f) in fields {
        out.extend_from_slice(&f.data);
    }
    out
}

/// A 2D distribution on `[0, 1]²` given by its values at `w × h` grid
/// points (bilinear in between), with a linear interpolation between
/// slices measured at parameter values: the construction of Mitsuba 3's
/// `Marginal2D` (continuous), whose warps an RGL file's tables are.
/// Everything in `f32`, as there.
#[derive(Debug, Clone)]
pub struct Marginal2D {
    w: usize,
    h: usize,
    data: Vec<f32>,
    marg_cdf: Vec<f32>,
    cond_cdf: Vec<f32>,
    params: Vec<Vec<f32>>,
    strides: Vec<usize>,
    normalized: bool,
}

/// Slice offset and `(w0, w1)` per parameter.
struct Weights {
    offset: usize,
    w: [(f32, f32); 3],
}

impl Marginal2D {
    /// `data` holds `Π params` slices of `h` rows of `w` values. `sampling`
    /// builds the cdfs (`sample`, `invert`); `normalize` scales each slice
    /// to integrate to one.
    #[must_use]
    pub fn new(
        data: &[f32],
        w: usize,
        h: usize,
        params: Vec<Vec<f32>>,
        normalize: bool,
        sampling: bool,
    ) -> Marginal2D {
        assert!(w >= 2 && h >= 2 && params.len() <= 3);
        let mut strides = vec![0; params.len()];
        let mut slices = 1;
        for i in (0..params.len()).rev() {
            strides[i] = if params[i].len() > 1 { slices } else { 0 };
            slices *= params[i].len();
        }
        let n_data = w * h;
        assert_eq!(data.len(), slices * n_data);
        let n_cond = (w - 1) * h;
        let (sx, sy) = (0.5 / (w - 1) as f64, 0.5 / (h - 1) as f64);
        let mut out = Vec::with_capacity(data.len());
        let mut marg_cdf = Vec::new();
        let mut cond_cdf = Vec::new();
        for s in 0..slices {
            let d = &data[s * n_data..(s + 1) * n_data];
            let mut norm = 1.0f32;
            if sampling {
                let mut row_sum = vec![0.0f64; h];
                let c0 = cond_cdf.len();
                for y in 0..h {
                    let mut acc = 0.0f64;
                    for x in 0..w - 1 {
                        acc += sx * (f64::from(d[y * w + x]) + f64::from(d[y * w + x + 1]));
                        cond_cdf.push(acc as f32);
                    }
                    row_sum[y] = acc;
                }
                let m0 = marg_cdf.len();
                let mut acc = 0.0f64;
                for y in 0..h - 1 {
                    acc += sy * (row_sum[y] + row_sum[y + 1]);
                    marg_cdf.push(acc as f32);
                }
                if normalize {
                    norm = (1.0 / acc) as f32;
                }
                for v in &mut cond_cdf[c0..] {
                    *v *= norm;
                }
                for v in &mut marg_cdf[m0..] {
                    *v *= norm;
                }
            } else if normalize {
                let mut sum = 0.0f64;
                for y in 0..h - 1 {
                    for x in 0..w - 1 {
                        let i = y * w + x;
                        sum += f64::from(d[i])
                            + f64::from(d[i + 1])
                            + f64::from(d[i + w])
                            + f64::from(d[i + w + 1]);
                    }
                }
                norm = (1.0 / (sx * sy * sum)) as f32;
            }
            out.extend(d.iter().map(|v| v * norm));
        }
        debug_assert!(!sampling || cond_cdf.len() == slices * n_cond);
        Marginal2D {
            w,
            h,
            data: out,
            marg_cdf,
            cond_cdf,
            params,
            strides,
            normalized: normalize,
        }
    }

    /// Bytes held.
    #[must_use]
    pub fn memory(&self) -> usize {
        4 * (self.data.len() + self.marg_cdf.len() + self.cond_cdf.len())
    }

    fn weights(&self, param: &[f32]) -> Weights {
        let mut wts = Weights {
            offset: 0,
            w: [(1.0, 0.0); 3],
        };
        for (dim, values) in self.params.iter().enumerate() {
            if values.len() == 1 {
                continue;
            }
            // The interval [values[i], values[i+1]] holding the parameter,
            // clamped to the first and the last.
            let n = values.len();
            let i = values[1..n - 1].iter().take_while(|&&v| v < param[dim]).count();
            let (p0, p1) = (values[i], values[i + 1]);
            let w1 = ((param[dim] - p0) / (p1 - p0)).clamp(0.0, 1.0);
            let w1 = if w1.is_nan() { 0.0 } else { w1 };
            wts.w[dim] = (1.0 - w1, w1);
            wts.offset += self.strides[dim] * i;
        }
        wts
    }

    /// `table[offset + i0]` interpolated across the parameters (`size` the
    /// length of one slice of `table`): the sum over the corners of the
    /// parameters' cell of weight × value, corners of weight 0 skipped
    /// (plain products and sums: `f32::mul_add` is a library call on CPUs
    /// the binary is not compiled for, and this is the hot loop of every
    /// RGL lookup).
    #[inline]
    fn lookup(&self, table: &[f32], i0: usize, size: usize, wts: &Weights) -> f32 {
        let d = self.params.len();
        let mut acc = 0.0f32;
        for corner in 0..(1usize << d) {
            let mut w = 1.0f32;
            let mut i = i0;
            for dim in 0..d {
                if corner >> dim & 1 == 1 {
                    w *= wts.w[dim].1;
                    i += self.strides[dim] * size;
                } else {
                    w *= wts.w[dim].0;
                }
            }
            if w != 0.0 {
                acc += w * table.get(i).copied().unwrap_or(0.0);
            }
        }
        acc
    }

    /// The density (or the interpolated value, unnormalised) at `pos`.
    #[must_use]
    pub fn eval(&self, pos: [f32; 2], param: &[f32]) -> f32 {
        let wts = self.weights(param);
        let (fx, fy, x, y) = self.cell(pos);
        let n = self.w * self.h;
        let i = wts.offset * n + y * self.w + x;
        let v00 = self.lookup(&self.data, i, n, &wts);
        let v10 = self.lookup(&self.data, i + 1, n, &wts);
        let v01 = self.lookup(&self.data, i + self.w, n, &wts);
        let v11 = self.lookup(&self.data, i + self.w + 1, n, &wts);
        (1.0 - fx) * (1.0 - fy) * v00 + fx * (1.0 - fy) * v10 + (1.0 - fx) * fy * v01 + fx * fy * v11
    }

    /// `[eval(pos, [p0, p1, k]) for k in 0, 1, 2]` for a table whose third
    /// parameter is the channel `[0, 1, 2]`, the same bits, with the
    /// weights and the cell found once.
    #[must_use]
    pub fn eval_channels(&self, pos: [f32; 2], param: [f32; 2]) -> [f32; 3] {
        debug_assert!(self.params.len() == 3 && self.params[2] == [0.0, 1.0, 2.0]);
        let mut wts = self.weights(&[param[0], param[1], 0.0]);
        let base = wts.offset;
        let (fx, fy, x, y) = self.cell(pos);
        let n = self.w * self.h;
        let mut out = [0f32; 3];
        for (k, o) in out.iter_mut().enumerate() {
            // Channel k: the slice k of the third parameter, weight 1 (as
            // `weights` gives for the integral parameter k).
            wts.offset = base + self.strides[2] * k;
            wts.w[2] = if k == 0 { (1.0, 0.0) } else { (0.0, 1.0) };
            let off = if k == 0 { wts.offset } else { wts.offset - self.strides[2] };
            let i = off * n + y * self.w + x;
            let v00 = self.lookup(&self.data, i, n, &wts);
            let v10 = self.lookup(&self.data, i + 1, n, &wts);
            let v01 = self.lookup(&self.data, i + self.w, n, &wts);
            let v11 = self.lookup(&self.data, i + self.w + 1, n, &wts);
            *o = (1.0 - fx) * (1.0 - fy) * v00 + fx * (1.0 - fy) * v10 + (1.0 - fx) * fy * v01 + fx * fy * v11;
        }
        out
    }

    /// The fraction within and the index of the grid cell holding `pos`.
    fn cell(&self, pos: [f32; 2]) -> (f32, f32, usize, usize) {
        let px = pos[0].clamp(0.0, 1.0) * (self.w - 1) as f32;
        let py = pos[1].clamp(0.0, 1.0) * (self.h - 1) as f32;
        let x = (px as usize).min(self.w - 2);
        let y = (py as usize).min(self.h - 2);
        (px - x as f32, py - y as f32, x, y)
    }

    /// Warp a uniform point of the square into the distribution:
    /// `(point, density)`.
    #[must_use]
    pub fn sample(&self, u: [f32; 2], param: &[f32]) -> ([f32; 2], f32) {
        let (w, h) = (self.w, self.h);
        let (n_cond, n_marg, n_data) = (h * (w - 1), h - 1, w * h);
        let wts = self.weights(param);
        let mut sx = u[0].clamp(f32::EPSILON, 1.0 - f32::EPSILON);
        let mut sy = u[1].clamp(f32::EPSILON, 1.0 - f32::EPSILON);
        let off_marg = wts.offset * n_marg;
        let marg = |i: usize| self.lookup(&self.marg_cdf, off_marg + i, n_marg, &wts);
        if !self.normalized {
            sy *= marg(n_marg - 1);
        }
        // The first row whose cdf is ≥ sy (at most the last).
        let row = (0..n_marg - 1).take_while(|&i| marg(i) < sy).count();
        if row > 0 {
            sy -= marg(row - 1);
        }
        let off_cond = wts.offset * n_cond + row * (w - 1);
        let cond = |i: usize| self.lookup(&self.cond_cdf, off_cond + i, n_cond, &wts);
        let r0 = cond(w - 2);
        let r1 = cond(2 * (w - 1) - 1);
        sy = sample_segment(sy, (h - 1) as f32, r0, r1);
        sx *= r0 + (r1 - r0) * sy;
        let conditional = |i: usize| {
            let v0 = cond(i);
            let v1 = cond(i + w - 1);
            v0 + (v1 - v0) * sy
        };
        let col = (0..w - 2).take_while(|&i| conditional(i) < sx).count();
        if col > 0 {
            sx -= conditional(col - 1);
        }
        let i = wts.offset * n_data + row * w + col;
        let v00 = self.lookup(&self.data, i, n_data, &wts);
        let v10 = self.lookup(&self.data, i + 1, n_data, &wts);
        let v01 = self.lookup(&self.data, i + w, n_data, &wts);
        let v11 = self.lookup(&self.data, i + w + 1, n_data, &wts);
        let c0 = v00 + (v01 - v00) * sy;
        let c1 = v10 + (v11 - v10) * sy;
        sx = sample_segment(sx, (w - 1) as f32, c0, c1);
        (
            [
                (col as f32 + sx) / (w - 1) as f32,
                (row as f32 + sy) / (h - 1) as f32,
            ],
            c0 + (c1 - c0) * sx,
        )
    }

    /// The inverse of [`Marginal2D::sample`]: `(uniform point, density)`.
    #[must_use]
    pub fn invert(&self, pos: [f32; 2], param: &[f32]) -> ([f32; 2], f32) {
        let (w, h) = (self.w, self.h);
        let (n_cond, n_marg, n_data) = (h * (w - 1), h - 1, w * h);
        let wts = self.weights(param);
        let (fx, fy, x, y) = self.cell(pos);
        let i = wts.offset * n_data + y * w + x;
        let v00 = self.lookup(&self.data, i, n_data, &wts);
        let v10 = self.lookup(&self.data, i + 1, n_data, &wts);
        let v01 = self.lookup(&self.data, i + w, n_data, &wts);
        let v11 = self.lookup(&self.data, i + w + 1, n_data, &wts);
        let c0 = v00 + (v01 - v00) * fy;
        let c1 = v10 + (v11 - v10) * fy;
        let pdf = c0 + (c1 - c0) * fx;
        let mut sx = invert_segment(fx, 1.0 / (w - 1) as f32, c0, c1);
        let off_cond = wts.offset * n_cond + y * (w - 1);
        let cond = |i: usize| self.lookup(&self.cond_cdf, off_cond + i, n_cond, &wts);
        if x > 0 {
            let v0 = cond(x - 1);
            let v1 = cond(x - 1 + w - 1);
            sx += v0 + (v1 - v0) * fy;
        }
        let r0 = cond(w - 2);
        let r1 = cond(2 * (w - 1) - 1);
        sx /= r0 + (r1 - r0) * fy;
        let mut sy = invert_segment(fy, 1.0 / (h - 1) as f32, r0, r1);
        let off_marg = wts.offset * n_marg;
        if y > 0 {
            sy += self.lookup(&self.marg_cdf, off_marg + y - 1, n_marg, &wts);
        }
        if !self.normalized {
            sy /= self.lookup(&self.marg_cdf, off_marg + n_marg - 1, n_marg, &wts);
        }
        ([sx, sy], pdf)
    }
}

/// The position `x ∈ [0, 1]` in a segment of a piecewise-linear density
/// `v0 → v1` whose cdf is `sample` (times the width): the root of
/// `v0 x + (v1 − v0) x²/2 = t/2`, `t = 2 sample / width`, written as
/// `t / (v0 + √(v0² + t (v1 − v0)))`, which has no cancellation (Mitsuba's
/// `(v0 − √(v0² + t (v1 − v0)))/(v0 − v1)` is the same number, but in f32
/// its difference of nearly equal terms amplified a 1-ulp change of the
/// view's elevation into 2e-5 of the sampled direction).
fn sample_segment(sample: f32, inv_width: f32, v0: f32, v1: f32) -> f32 {
    let t = sample * 2.0 * inv_width;
    let d = v0 + (v0 * v0 + t * (v1 - v0)).max(0.0).sqrt();
    if d > 0.0 { t / d } else { 0.0 }
}

fn invert_segment(sample: f32, width: f32, v0: f32, v1: f32) -> f32 {
    sample * (v0 + (v1 - v0) * (0.5 * sample)) * width
}

/// θ of a unit vector, accurate near the pole (as Mitsuba computes it).
fn elevation(d: DVec3) -> f32 {
    let dist = (d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0)).sqrt();
    (2.0 * (0.5 * dist).clamp(-1.0, 1.0).asin()) as f32
}

fn theta2u(theta: f32) -> f32 {
    (theta * (2.0 / PI32)).max(0.0).sqrt()
}

fn phi2u(phi: f32) -> f32 {
    (phi + PI32) * (0.5 / PI32)
}

fn u2theta(u: f32) -> f32 {
    u * u * (PI32 / 2.0)
}

fn u2phi(u: f32) -> f32 {
    (2.0 * u - 1.0) * PI32
}

/// An isotropic RGL table, ready to evaluate.
#[derive(Debug, Clone)]
pub struct Rgl {
    pub description: String,
    jacobian: bool,
    ndf: Marginal2D,
    sigma: Marginal2D,
    vndf: Marginal2D,
    luminance: Marginal2D,
    rgb: Marginal2D,
    /// `(n_theta_i, grid n)`, for messages.
    pub resolution: (usize, usize),
}

/// The CIE 1931 colour matching functions, the multi-lobe fit of Wyman,
/// Sloan and Shirley (2013), at `lambda` nm.
fn cie_xyz(lambda: f64) -> [f64; 3] {
    let g = |x: f64, mu: f64, s1: f64, s2: f64| {
        let t = (x - mu) / if x < mu { s1 } else { s2 };
        (-0.5 * t * t).exp()
    };
    [
        1.056 * g(lambda, 599.8, 37.9, 31.0) + 0.362 * g(lambda, 442.0, 16.0, 26.7)
            - 0.065 * g(lambda, 501.1, 20.4, 26.2),
        0.821 * g(lambda, 568.8, 46.9, 40.5) + 0.286 * g(lambda, 530.9, 16.3, 31.1),
        1.217 * g(lambda, 437.0, 11.8, 36.0) + 0.681 * g(lambda, 459.0, 26.0, 13.8),
    ]
}

/// Weights `[channel][wavelength]` that take a sampled spectrum to linear
/// Rec. 709 (trapezoid rule over the wavelengths, white balanced).
fn spectral_weights(wavelengths: &[f32]) -> [Vec<f64>; 3] {
    const XYZ_TO_RGB: [[f64; 3]; 3] = [
        [3.2406, -1.5372, -0.4986],
        [-0.9689, 1.8758, 0.0415],
        [0.0557, -0.2040, 1.0570],
    ];
    let n = wavelengths.len();
    let mut w: [Vec<f64>; 3] = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for i in 0..n {
        let lo = if i > 0 { f64::from(wavelengths[i - 1]) } else { f64::from(wavelengths[i]) };
        let hi = if i + 1 < n { f64::from(wavelengths[i + 1]) } else { f64::from(wavelengths[i]) };
        let dl = 0.5 * (hi - lo).max(0.0) + if n == 1 { 1.0 } else { 0.0 };
        let xyz = cie_xyz(f64::from(wavelengths[i]));
        for c in 0..3 {
            w[c][i] = dl * (0..3).map(|k| XYZ_TO_RGB[c][k] * xyz[k]).sum::<f64>();
        }
    }
    for wc in &mut w {
        let s: f64 = wc.iter().sum();
        if s.abs() > 0.0 {
            for v in wc.iter_mut() {
                *v /= s;
            }
        }
    }
    w
}

impl Rgl {
    /// Read an RGL file's bytes; the message says what is wrong.
    pub fn parse(bytes: &[u8]) -> Result<Rgl, String> {
        let fields = parse_tensor(bytes)?;
        let get = |name: &str| {
            fields
                .get(name)
                .ok_or_else(|| format!("missing field `{name}` (an RGL BRDF file has description, jacobian, theta_i, phi_i, ndf, sigma, vndf, luminance and rgb or spectra + wavelengths)"))
        };
        let check = |name: &str, dtype: DType, rank: usize| -> Result<&Field, String> {
            let f = get(name)?;
            if f.dtype != dtype || f.shape.len() != rank {
                return Err(format!(
                    "field `{name}` is {:?} of rank {} (shape {:?}), expected {dtype:?} of rank {rank}",
                    f.dtype,
                    f.shape.len(),
                    f.shape
                ));
            }
            Ok(f)
        };
        let floats = |name: &str, f: &Field| -> Result<Vec<f32>, String> {
            let v = f.as_f32();
            if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(format!("field `{name}`: entry {i} is {x}"));
            }
            Ok(v)
        };
        let description = check("description", DType::U8, 1)?;
        let description = String::from_utf8_lossy(&description.data).into_owned();
        let jacobian = check("jacobian", DType::U8, 1)?;
        if jacobian.shape != [1] {
            return Err(format!(
                "field `jacobian` has shape {:?}, expected one byte",
                jacobian.shape
            ));
        }
        let jacobian = jacobian.data[0] != 0;
        let theta_i = floats("theta_i", check("theta_i", DType::F32, 1)?)?;
        let phi_i = floats("phi_i", check("phi_i", DType::F32, 1)?)?;
        if theta_i.is_empty() || phi_i.is_empty() {
            return Err("field `theta_i` or `phi_i` is empty".into());
        }
        if phi_i.len() > 2 {
            return Err(format!(
                "anisotropic table (phi_i has {} entries): lobe reads isotropic RGL files only",
                phi_i.len()
            ));
        }
        // `!(a < b)`, not `a >= b`: a NaN is not increasing either.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        let not_increasing = |v: &[f32]| v.windows(2).any(|w| !(w[0] < w[1]));
        if not_increasing(&theta_i) {
            return Err("field `theta_i` is not increasing".into());
        }
        if not_increasing(&phi_i) {
            return Err("field `phi_i` is not increasing".into());
        }
        let (np, nt) = (phi_i.len(), theta_i.len());
        let grid2 = |name: &str| -> Result<(Vec<f32>, usize, usize), String> {
            let f = check(name, DType::F32, 2)?;
            let (h, w) = (f.shape[0], f.shape[1]);
            if w < 2 || h < 2 {
                return Err(format!("field `{name}` has shape {:?}, each axis must be ≥ 2", f.shape));
            }
            Ok((floats(name, f)?, w, h))
        };
        let (ndf, nw, nh) = grid2("ndf")?;
        let (sigma, sw, sh) = grid2("sigma")?;
        let grid4 = |name: &str| -> Result<(Vec<f32>, usize, usize), String> {
            let f = check(name, DType::F32, 4)?;
            let s = &f.shape;
            if s[0] != np || s[1] != nt || s[2] < 2 || s[3] < 2 {
                return Err(format!(
                    "field `{name}` has shape {s:?}, expected [{np}, {nt}, n ≥ 2, m ≥ 2] (phi_i × theta_i × grid)"
                ));
            }
            Ok((floats(name, f)?, s[3], s[2]))
        };
        let (vndf, vw, vh) = grid4("vndf")?;
        let (luminance, lw, lh) = grid4("luminance")?;
        if lw != lh {
            return Err(format!("field `luminance` is not square ({lh}×{lw})"));
        }
        let (rgb, n_channels_in, spectral) = if fields.contains_key("wavelengths") {
            let wl = floats("wavelengths", check("wavelengths", DType::F32, 1)?)?;
            let f = check("spectra", DType::F32, 5)?;
            (f, wl, true)
        } else {
            (check("rgb", DType::F32, 5)?, vec![0.0, 1.0, 2.0], false)
        };
        let name = if spectral { "spectra" } else { "rgb" };
        let s = rgb.shape.clone();
        if s[0] != np || s[1] != nt || s[2] != n_channels_in.len() || s[3] != lh || s[4] != lw {
            return Err(format!(
                "field `{name}` has shape {s:?}, expected [{np}, {nt}, {}, {lh}, {lw}] (phi_i × theta_i × channels × the luminance grid)",
                n_channels_in.len()
            ));
        }
        let values = floats(name, rgb)?;
        let n = lw * lh;
        let values = if spectral {
            let wts = spectral_weights(&n_channels_in);
            let nl = n_channels_in.len();
            let mut out = vec![0f32; np * nt * 3 * n];
            for slice in 0..np * nt {
                for c in 0..3 {
                    for k in 0..n {
                        let v: f64 = (0..nl)
                            .map(|l| wts[c][l] * f64::from(values[(slice * nl + l) * n + k]))
                            .sum();
                        out[(slice * 3 + c) * n + k] = v as f32;
                    }
                }
            }
            out
        } else {
            values
        };
        if !values.iter().any(|&v| v > 0.0) {
            return Err(format!("no valid entry: every value of `{name}` is ≤ 0"));
        }
        // Every vndf and luminance slice must be a distribution.
        for (fname, d, w, h) in [("vndf", &vndf, vw, vh), ("luminance", &luminance, lw, lh)] {
            for (k, slice) in d.chunks_exact(w * h).enumerate() {
                if slice.iter().any(|&v| v < 0.0) || !slice.iter().any(|&v| v > 0.0) {
                    return Err(format!(
                        "field `{fname}`: slice {k} (θi {}) is not a distribution (a negative value, or all zero)",
                        theta_i[k % nt]
                    ));
                }
            }
        }
        if jacobian && (sigma.iter().any(|&v| v <= 0.0) || ndf.iter().any(|&v| v < 0.0)) {
            return Err("field `sigma` has a value ≤ 0 or `ndf` a negative one".into());
        }
        let views = vec![phi_i.clone(), theta_i.clone()];
        Ok(Rgl {
            description,
            jacobian,
            ndf: Marginal2D::new(&ndf, nw, nh, vec![], false, false),
            sigma: Marginal2D::new(&sigma, sw, sh, vec![], false, false),
            vndf: Marginal2D::new(&vndf, vw, vh, views.clone(), true, true),
            luminance: Marginal2D::new(&luminance, lw, lh, views, true, true),
            rgb: Marginal2D::new(
                &values,
                lw,
                lh,
                vec![phi_i, theta_i, vec![0.0, 1.0, 2.0]],
                false,
                false,
            ),
            resolution: (nt, lw),
        })
    }

    /// Bytes held.
    #[must_use]
    pub fn memory(&self) -> usize {
        self.ndf.memory()
            + self.sigma.memory()
            + self.vndf.memory()
            + self.luminance.memory()
            + self.rgb.memory()
    }

    /// `f_r(wo, wi) cos θi` as the file gives it (`wo` the viewer).
    #[must_use]
    pub fn eval_cos(&self, wo: DVec3, wi: DVec3) -> Rgb {
        let m = (wo + wi).normalize();
        let theta_o = elevation(wo);
        let phi_o = wo.y.atan2(wo.x) as f32;
        let theta_m = elevation(m);
        let phi_m = m.y.atan2(m.x) as f32;
        let u_wo = [theta2u(theta_o), phi2u(phi_o)];
        let mut u_m = [theta2u(theta_m), phi2u(phi_m - phi_o)];
        u_m[1] -= u_m[1].floor();
        let params = [phi_o, theta_o];
        let (s, _) = self.vndf.invert(u_m, &params);
        let c = self.rgb.eval_channels(s, [phi_o, theta_o]);
        let scale = if self.jacobian {
            self.ndf.eval(u_m, &[]) / (4.0 * self.sigma.eval(u_wo, &[]))
        } else {
            1.0
        };
        Rgb::new(c[0].into(), c[1].into(), c[2].into()) * f64::from(scale)
    }

    /// An RGL file of `f(wo, wi)` (no cosine), isotropic: `n_theta` views
    /// with θ uniform in `[0, 89°]`, an `n × n` grid. The visible-normal warp
    /// is `f cos θi` over the half vector with a floor of 1% of its mean (so
    /// that the grid spends its points on the lobe); `jacobian` is 0, so
    /// `rgb` holds `f cos θi` itself. The `luminance` table is, as in Dupuy
    /// and Jakob's files, the luminance of the data per unit area of the
    /// sample square (`lum(f cos θi)` times the density of `ω_i` per unit
    /// of the square under the vndf warp), with a floor of 1% of its mean:
    /// the two warps together then sample `lum(f cos θi)` (nearly flat
    /// where the vndf warp already follows the lobe).
    #[must_use]
    pub fn write(
        f: impl Fn(DVec3, DVec3) -> Rgb + Sync,
        n_theta: usize,
        n: usize,
        description: &str,
    ) -> Vec<u8> {
        let theta_i: Vec<f32> = (0..n_theta)
            .map(|k| (k as f32 / (n_theta - 1).max(1) as f32) * 89f32.to_radians())
            .collect();
        let phi_i = vec![0.0f32];
        let wo_of = |theta: f32| DVec3::new(f64::from(theta).sin(), 0.0, f64::from(theta).cos());
        let m_of = |u: [f32; 2]| {
            let (t, p) = (f64::from(u2theta(u[0])), f64::from(u2phi(u[1])));
            DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
        };
        let lum = |c: Rgb| crate::math::luminance(c).max(0.0);
        // f cos θi at (wo, m), 0 below the horizon.
        let fcos = |wo: DVec3, m: DVec3| {
            let wi = crate::math::reflect(wo, m);
            if wi.z <= 0.0 || wo.dot(m) <= 0.0 {
                Rgb::ZERO
            } else {
                f(wo, wi.normalize()) * wi.z
            }
        };
        let per_view = |k: usize| -> (Vec<f32>, Vec<f32>, Vec<f32>) {
            let wo = wo_of(theta_i[k]);
            // The vndf grid: f cos θi · 4 (wo·m) · |dω/du| over u_m.
            let mut vndf = vec![0f32; n * n];
            for y in 0..n {
                for x in 0..n {
                    let u = [x as f32 / (n - 1) as f32, y as f32 / (n - 1) as f32];
                    let m = m_of(u);
                    let jac = 2.0 * std::f64::consts::PI.powi(2) * f64::from(u[0]) * f64::from(u2theta(u[0])).sin();
                    vndf[y * n + x] = (lum(fcos(wo, m)) * 4.0 * wo.dot(m).max(0.0) * jac) as f32;
                }
            }
            let mean = vndf.iter().map(|&v| f64::from(v)).sum::<f64>() / (n * n) as f64;
            let floor = (0.01 * mean).max(1e-12) as f32;
            for v in &mut vndf {
                *v += floor;
            }
            let warp = Marginal2D::new(&vndf, n, n, vec![], true, true);
            let mut rgb = vec![0f32; 3 * n * n];
            let mut luminance = vec![0f32; n * n];
            for y in 0..n {
                for x in 0..n {
                    let s = [x as f32 / (n - 1) as f32, y as f32 / (n - 1) as f32];
                    let (u_m, v) = warp.sample(s, &[]);
                    let m = m_of(u_m);
                    let c = fcos(wo, m);
                    for ch in 0..3 {
                        rgb[ch * n * n + y * n + x] = c[ch] as f32;
                    }
                    // What the vndf warp leaves to correct: lum(f cos θi)
                    // times the density of ω_i per unit area of the sample
                    // square, 4 (wo·m) |dω_m/du_m| / vndf(u_m).
                    let jac = 2.0 * std::f64::consts::PI.powi(2) * f64::from(u_m[0]) * f64::from(u2theta(u_m[0])).sin();
                    let per_s = 4.0 * wo.dot(m).max(0.0) * jac / f64::from(v).max(1e-30);
                    luminance[y * n + x] = (lum(c) * per_s) as f32;
                }
            }
            let mean = luminance.iter().map(|&v| f64::from(v)).sum::<f64>() / (n * n) as f64;
            let floor = (0.01 * mean).max(1e-12) as f32;
            for v in &mut luminance {
                *v += floor;
            }
            (vndf, luminance, rgb)
        };
        #[cfg(feature = "parallel")]
        let views: Vec<_> = {
            use rayon::prelude::*;
            (0..n_theta).into_par_iter().map(per_view).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let views: Vec<_> = (0..n_theta).map(per_view).collect();
        let mut vndf = Vec::new();
        let mut luminance = Vec::new();
        let mut rgb = Vec::new();
        for (v, l, c) in views {
            vndf.extend(v);
            luminance.extend(l);
            rgb.extend(c);
        }
        let ones = vec![1.0f32; 4];
        write_tensor(&[
            ("description", Field::u8(description.as_bytes())),
            ("jacobian", Field::u8(&[0])),
            ("theta_i", Field::f32(&[n_theta], &theta_i)),
            ("phi_i", Field::f32(&[1], &phi_i)),
            ("ndf", Field::f32(&[2, 2], &ones)),
            ("sigma", Field::f32(&[2, 2], &ones)),
            ("vndf", Field::f32(&[1, n_theta, n, n], &vndf)),
            ("luminance", Field::f32(&[1, n_theta, n, n], &luminance)),
            ("rgb", Field::f32(&[1, n_theta, 3, n, n], &rgb)),
        ])
    }

    /// Dupuy and Jakob's own sampling scheme (the `vndf` strategy of an RGL
    /// material), as Mitsuba 3's `measured` plugin samples: the uniform
    /// point `(u.y, u.x)` is warped by the file's `luminance` table into
    /// the sample square, and from there by the visible-normal warp `vndf`
    /// into the half vector's `u_m = (√(θm/(π/2)), (φm − φo + π)/(2π))`;
    /// `wi` is `wo` mirrored about `m` (`None` below the horizon, or for
    /// `wo` below it). Both warps are interpolated between the file's view
    /// elevations, as the tables are when evaluating. There is no
    /// defensive mixture: where the file's warps have density zero, so
    /// does this strategy.
    #[must_use]
    pub fn sample_warps(&self, wo: DVec3, u: DVec2) -> Option<DVec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let theta_o = elevation(wo);
        let phi_o = wo.y.atan2(wo.x) as f32;
        let params = [phi_o, theta_o];
        let (s, _) = self.luminance.sample([u.y as f32, u.x as f32], &params);
        let (u_m, _) = self.vndf.sample(s, &params);
        let (t, p) = (f64::from(u2theta(u_m[0])), f64::from(u2phi(u_m[1])) + f64::from(phi_o));
        let m = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
        let wi = crate::math::reflect(wo, m);
        if wi.z <= 0.0 || !wi.is_finite() {
            return None;
        }
        Some(wi.normalize())
    }

    /// The solid-angle density of [`Rgl::sample_warps`] at `wi` (both above
    /// the horizon): with `m = (wo + wi)/‖wo + wi‖` and `s` the sample
    /// square's point that the `vndf` warp takes to `u_m` (its inverse),
    /// `luminance(s) · vndf(u_m) / (2π² u_m.x sin θm · 4 wo·m)`: the two
    /// warps' densities, then `u_m → ω_m` and `ω_m → ω_i`. The first
    /// Jacobian is kept above 1e-6, as Mitsuba does, at the pole.
    #[must_use]
    pub fn pdf_warps(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let sum = wo + wi;
        let len = sum.length();
        // Also false for NaN.
        if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return 0.0;
        }
        let m = sum / len;
        let om = wo.dot(m);
        if om.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return 0.0;
        }
        let theta_o = elevation(wo);
        let phi_o = wo.y.atan2(wo.x) as f32;
        let theta_m = elevation(m);
        let phi_m = m.y.atan2(m.x) as f32;
        let mut u_m = [theta2u(theta_m), phi2u(phi_m - phi_o)];
        u_m[1] -= u_m[1].floor();
        let params = [phi_o, theta_o];
        let (s, vndf_pdf) = self.vndf.invert(u_m, &params);
        let lum_pdf = self.luminance.eval(s, &params);
        let jac = (2.0 * std::f64::consts::PI.powi(2) * f64::from(u_m[0]) * f64::from(theta_m).sin())
            .max(1e-6)
            * 4.0
            * om;
        let p = f64::from(vndf_pdf) * f64::from(lum_pdf) / jac;
        if p.is_finite() && p > 0.0 { p } else { 0.0 }
    }

    /// The view elevations of the table are interpolated; the grid point
    /// `s` of the sample square maps to the half vector `vndf.sample(s)`.
    #[must_use]
    pub fn half_vector(&self, wo: DVec3, s: DVec2) -> DVec3 {
        let theta_o = elevation(wo);
        let phi_o = wo.y.atan2(wo.x) as f32;
        let (u, _) = self.vndf.sample([s.x as f32, s.y as f32], &[phi_o, theta_o]);
        let (t, p) = (f64::from(u2theta(u[0])), f64::from(u2phi(u[1]) + phi_o));
        DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marginal_sample_and_invert_agree() {
        let (w, h) = (5, 4);
        let data: Vec<f32> = (0..2 * w * h).map(|i| 0.2 + ((i * 7) % 11) as f32).collect();
        let m = Marginal2D::new(&data, w, h, vec![vec![0.0, 1.0]], true, true);
        for &(a, b, p) in &[(0.1, 0.2, 0.0), (0.7, 0.9, 0.3), (0.5, 0.5, 1.0), (0.95, 0.05, 0.6)] {
            let (x, pdf) = m.sample([a, b], &[p]);
            let (u, pdf2) = m.invert(x, &[p]);
            assert!((u[0] - a).abs() < 1e-4 && (u[1] - b).abs() < 1e-4, "{u:?} vs {a} {b}");
            assert!((pdf - pdf2).abs() < 1e-4 * pdf, "{pdf} {pdf2}");
            assert!((m.eval(x, &[p]) - pdf).abs() < 1e-4 * pdf);
        }
    }

    #[test]
    fn eval_channels_is_eval_per_channel() {
        let (w, h) = (4, 3);
        let data: Vec<f32> = (0..2 * 3 * 3 * w * h).map(|i| 0.1 + ((i * 13) % 17) as f32).collect();
        let m = Marginal2D::new(&data, w, h, vec![vec![0.0, 1.0], vec![0.0, 0.5, 1.5], vec![0.0, 1.0, 2.0]], false, false);
        for &(x, y, a, b) in &[(0.1, 0.2, 0.0, 0.0), (0.7, 0.9, 0.3, 1.2), (1.0, 0.5, 1.0, 0.5), (0.3, 0.0, 0.6, 2.0)] {
            let c = m.eval_channels([x, y], [a, b]);
            for (k, v) in c.iter().enumerate() {
                assert_eq!(v.to_bits(), m.eval([x, y], &[a, b, k as f32]).to_bits(), "{x} {y} {a} {b} {k}");
            }
        }
    }

    #[test]
    fn tensor_files_round_trip() {
        let bytes = write_tensor(&[
            ("a", Field::u8(b"xyz")),
            ("b", Field::f32(&[2, 2], &[1.0, 2.0, 3.0, 4.0])),
        ]);
        let f = parse_tensor(&bytes).unwrap();
        assert_eq!(f["a"].data, b"xyz");
        assert_eq!(f["b"].as_f32(), vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(f["b"].shape, vec![2, 2]);
    }

    #[test]
    fn white_spectrum_is_white() {
        let wl: Vec<f32> = (0..40).map(|i| 360.0 + 10.0 * i as f32).collect();
        let w = spectral_weights(&wl);
        for c in &w {
            assert!((c.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
    }
}
