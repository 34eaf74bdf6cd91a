//! Equirectangular environment maps in Mitsuba 3's convention, and their
//! importance sampling.
//!
//! | parameter | meaning |
//! |---|---|
//! | texels | `width × height` linear RGB, row 0 at the top (+Y) |
//! | `scale` | multiplies the radiance |
//! | `rotation_y` | degrees, a rotation of the map about world +Y |
//!
//! World +Y is up. A world direction `d` (after undoing the rotation) maps to
//! `u = atan2(d.x, −d.z) / (2π)` wrapped into [0, 1) and `v = acos(d.y) / π`;
//! texel `(i, j)` covers `u ∈ [i, i+1)/width`, `v ∈ [j, j+1)/height`, and the
//! radiance is constant over it (nearest texel), so that light sampling can be
//! exactly proportional to it.
//!
//! Light sampling picks a texel with probability proportional to its
//! luminance times its solid angle `(2π/width)(cos θ₀ − cos θ₁)` (the sin θ
//! weighting of a latitude-longitude map, integrated exactly over the texel),
//! from a marginal distribution over rows and a conditional one within the
//! row, then a uniform direction inside the texel. The density in solid angle
//! is `lum(texel) / Σ lum·Ω`: proportional to the map's luminance.

use crate::batch::{SimdLevel, Step};
use crate::math::{Rgb, luminance};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// A piecewise-constant 1D distribution over `n` bins, sampled by inversion
/// of its CDF in O(1) expected time: a guide table (Chen and Asau 1974)
/// gives, for each of `n` equal intervals of `u`, the first and the last bin
/// `u` can fall in, so a sample searches those (about one bin on average,
/// the bins of one interval at most) instead of all `n`. Inversion keeps
/// the map from `u` to the bin monotone, so stratified and Sobol numbers
/// stay stratified over the texels (an alias table would not).
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution1D {
    /// `cdf[i]` = probability of bins `0..i`; `cdf[n] = 1`.
    cdf: Vec<f64>,
    total: f64,
    /// `guide[k]`: the bin of `u = k/n`.
    guide: Vec<u32>,
}

impl Distribution1D {
    /// From non-negative finite weights. `total()` is their sum; with a zero
    /// sum every bin has probability 0 and `sample` returns `None`.
    #[must_use]
    pub fn new(weights: &[f64]) -> Self {
        Self::from_weights(weights.iter().copied())
    }

    /// [`Distribution1D::new`] of the weights an iterator gives (no slice
    /// of them needed).
    #[must_use]
    pub fn from_weights(weights: impl ExactSizeIterator<Item = f64>) -> Self {
        let steps = Self::steps(weights.len());
        Self::with_steps(weights, &steps)
    }

    /// `k / n` for `k = 0..n`: the points of the guide table of `n` bins,
    /// the same for every distribution of `n` bins (a map's rows share
    /// them: one division per column instead of one per texel).
    fn steps(n: usize) -> Vec<f64> {
        (0..n).map(|k| k as f64 / n as f64).collect()
    }

    /// [`Distribution1D::from_weights`] with the guide table's points,
    /// [`Distribution1D::steps`] of the number of weights.
    fn with_steps(weights: impl ExactSizeIterator<Item = f64>, steps: &[f64]) -> Self {
        let n = weights.len();
        let (mut cdf, mut guide) = (vec![0.0; n + 1], vec![0u32; n]);
        let total = Self::build(weights, steps, &mut cdf, &mut guide);
        Distribution1D { cdf, total, guide }
    }

    /// Write the tables of the distribution of `weights` (`n` of them)
    /// into `cdf` (`n + 1` entries) and `guide` (`n`, the guide table of
    /// the points `steps`, [`Distribution1D::steps`] of `n`), and return
    /// the weights' sum.
    fn build(
        weights: impl ExactSizeIterator<Item = f64>,
        steps: &[f64],
        cdf: &mut [f64],
        guide: &mut [u32],
    ) -> f64 {
        let n = weights.len();
        assert!(
            u32::try_from(n).is_ok(),
            "Distribution1D: more than 2^32 - 1 bins"
        );
        assert!(
            cdf.len() == n + 1 && guide.len() == n && steps.len() == n,
            "Distribution1D: tables of the wrong size"
        );
        let mut acc = 0.0;
        cdf[0] = 0.0;
        for (c, w) in cdf[1..].iter_mut().zip(weights) {
            acc += w.max(0.0);
            *c = acc;
        }
        if acc > 0.0 {
            for c in cdf.iter_mut() {
                *c /= acc;
            }
            cdf[n] = 1.0;
        } else {
            // No bin can be drawn: the guide stays as it was given (zeros),
            // as the tables of a map's black row stay ([`TexelSampler::new`]).
            return acc;
        }
        let mut i = 0usize;
        // `upper[i]` = `cdf[i + 1]` for the bins before the last.
        let upper = &cdf[1..n.max(1)];
        for (g, &u) in guide.iter_mut().zip(steps) {
            while i < upper.len() && upper[i] <= u {
                i += 1;
            }
            *g = i as u32;
        }
        acc
    }

    /// The tables, borrowed.
    #[inline]
    fn tables(&self) -> Tables<'_> {
        Tables {
            cdf: &self.cdf,
            total: self.total,
            guide: &self.guide,
        }
    }

    /// [`Tables::bin`] (for the tests).
    #[cfg(test)]
    fn bin(&self, u: f64) -> usize {
        self.tables().bin(u)
    }

    /// The bin of `u` by binary search (the reference for the guide table).
    #[cfg(test)]
    fn bin_by_search(&self, u: f64) -> usize {
        self.cdf.partition_point(|&c| c <= u).clamp(1, self.len()) - 1
    }

    #[must_use]
    pub fn total(&self) -> f64 {
        self.total
    }

    #[must_use]
    pub fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Probability of bin `i`.
    #[must_use]
    #[inline]
    pub fn prob(&self, i: usize) -> f64 {
        self.tables().prob(i)
    }

    /// A bin and the position of `u` inside it, rescaled to [0, 1).
    #[must_use]
    #[inline]
    pub fn sample(&self, u: f64) -> Option<(usize, f64)> {
        self.tables().sample(u)
    }
}

/// The tables of a [`Distribution1D`], borrowed: its own, or one row's of a
/// map's [`Columns`] (all rows' tables in two buffers).
#[derive(Debug, Clone, Copy)]
struct Tables<'a> {
    /// `cdf[i]` = probability of bins `0..i`; `cdf[n] = 1`.
    cdf: &'a [f64],
    total: f64,
    /// `guide[k]`: the bin of `u = k/n`.
    guide: &'a [u32],
}

impl Tables<'_> {
    #[inline]
    fn len(&self) -> usize {
        self.cdf.len() - 1
    }

    /// The bin of `u ∈ [0, 1)`: the one with `cdf[i] ≤ u < cdf[i + 1]`
    /// (empty bins skipped), from the guide table: at or after the bin of
    /// `k/n` and at or before the bin of `(k + 1)/n ≥ u`, found by a
    /// binary search between the two (a bin that takes much of the
    /// probability next to many that take little, a sun in a sky, puts
    /// many bins inside one interval of the guide).
    #[inline]
    fn bin(&self, u: f64) -> usize {
        let n = self.len();
        // (Through `u32`, which `n` fits: shorter conversions than from
        // and to `usize`, the same bin.)
        let k = ((u * f64::from(n as u32)) as u32 as usize).min(n - 1);
        let lo = self.guide[k] as usize;
        let hi = match self.guide.get(k + 1) {
            Some(&g) => g as usize,
            None => n - 1,
        };
        // The first `i ≥ lo` with `cdf[i + 1] > u`, or `hi`.
        lo + self.cdf[lo + 1..=hi].partition_point(|&c| c <= u)
    }

    #[inline]
    fn prob(&self, i: usize) -> f64 {
        if self.total > 0.0 {
            self.cdf[i + 1] - self.cdf[i]
        } else {
            0.0
        }
    }

    #[inline]
    fn sample(&self, u: f64) -> Option<(usize, f64)> {
        if self.total <= 0.0 {
            return None;
        }
        // First bin whose upper edge exceeds u, skipping empty bins.
        let i = self.bin(u);
        let p = self.prob(i);
        if p <= 0.0 {
            return None;
        }
        let rest = ((u - self.cdf[i]) / p).clamp(0.0, 1.0 - f64::EPSILON / 2.0);
        Some((i, rest))
    }
}

/// Radiance and the two light-sampling densities of one direction
/// ([`EnvMap::lookup`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnvLookup {
    /// The radiance arriving from the direction ([`EnvMap::eval`]).
    pub radiance: Rgb,
    /// [`EnvMap::pdf`], solid angle.
    pub pdf: f64,
    /// [`EnvMap::pdf_compensated`], solid angle.
    pub pdf_compensated: f64,
}

/// `atan(t)` for `t ∈ [0, 1]` within 2e-5 (a polynomial: a guess that
/// [`EnvMap::texel_index`] corrects).
#[inline]
fn atan_01(t: f64) -> f64 {
    let t2 = t * t;
    t * (0.999_866 + t2 * (-0.330_299_5 + t2 * (0.180_141 + t2 * (-0.085_133 + t2 * 0.020_835_1))))
}

/// `acos(y)` within 1e-4 (Abramowitz and Stegun 4.4.45), a guess.
#[inline]
fn acos_guess(y: f64) -> f64 {
    let x = y.abs();
    let r = (1.0 - x).max(0.0).sqrt()
        * (1.570_728_8 + x * (-0.212_114_4 + x * (0.074_261 - 0.018_729_3 * x)));
    if y < 0.0 { PI - r } else { r }
}

/// Draws or directions per step of [`EnvMap::sample_lookup_many`] and
/// [`EnvMap::lookup_many`].
const LOOKUP_CHUNK: usize = 64;

/// Ask the CPU to bring `v`'s cache line in (a hint: no effect on any
/// value, and none on other architectures), so that the reads of a chunk's
/// texels, which miss the caches for a large map, overlap.
#[inline(always)]
fn prefetch<T>(v: &T) {
    // SAFETY: SSE is in every x86-64 CPU (the target's baseline), and a
    // prefetch reads nothing and never faults, whatever the address.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
            std::ptr::from_ref(v).cast::<i8>(),
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = v;
}

/// [`EnvMap::sample_lookup_many`]'s work, run at a SIMD level: per chunk
/// of draws, the rows drawn, then the columns, the texels' cache lines
/// asked for, then each draw finished.
struct SampleLookups<'a> {
    map: &'a EnvMap,
    draws: &'a [(bool, DVec2)],
    out: &'a mut [Option<(DVec3, EnvLookup)>],
}

impl Step for SampleLookups<'_> {
    #[inline(always)]
    fn run(self) {
        let SampleLookups { map, draws, out } = self;
        // (A chunk's rows and columns as plain arrays, `NONE` where the
        // draw has none: no `Option`s to write and test.)
        const NONE: u32 = u32::MAX;
        for (dc, oc) in draws.chunks(LOOKUP_CHUNK).zip(out.chunks_mut(LOOKUP_CHUNK)) {
            let n = dc.len();
            let (mut rj, mut ru) = ([NONE; LOOKUP_CHUNK], [0.0; LOOKUP_CHUNK]);
            for ((j, r), &(comp, u)) in rj.iter_mut().zip(&mut ru).zip(dc) {
                if let Some((jj, rr)) = map.sampler(comp).rows.sample(u.x) {
                    (*j, *r) = (jj as u32, rr);
                }
            }
            let (mut ci, mut rv) = ([NONE; LOOKUP_CHUNK], [0.0; LOOKUP_CHUNK]);
            for (k, &(comp, u)) in dc.iter().enumerate() {
                if rj[k] == NONE {
                    continue;
                }
                let j = rj[k] as usize;
                if let Some((i, r)) = map.sampler(comp).columns(&map.texels).row(j).sample(u.y) {
                    (ci[k], rv[k]) = (i as u32, r);
                    prefetch(&map.texels[j * map.width + i]);
                }
            }
            for (k, o) in oc[..n].iter_mut().enumerate() {
                *o = if ci[k] == NONE {
                    None
                } else {
                    map.finish_sample(dc[k].0, (rj[k] as usize, ru[k]), (ci[k] as usize, rv[k]))
                };
            }
        }
    }
}

/// The texels `j · width + i` of up to [`LOOKUP_CHUNK`] directions, as
/// [`EnvMap::texel_index`] finds them: the guesses of the whole chunk first,
/// in a loop without branches that the compiler vectorizes, then each
/// one's corrections.
struct TexelIndices<'a> {
    map: &'a EnvMap,
    dirs: &'a [DVec3],
    out: &'a mut [usize; LOOKUP_CHUNK],
}

impl Step for TexelIndices<'_> {
    #[inline(always)]
    fn run(self) {
        let TexelIndices { map, dirs, out } = self;
        let (w, h) = (map.width, map.height);
        let n = dirs.len().min(LOOKUP_CHUNK);
        let (mut sx, mut cx, mut y) = (
            [0.0; LOOKUP_CHUNK],
            [0.0; LOOKUP_CHUNK],
            [0.0; LOOKUP_CHUNK],
        );
        for (k, d) in dirs[..n].iter().enumerate() {
            let d = map.unrotate(*d);
            (sx[k], cx[k], y[k]) = (d.x, -d.z, d.y.clamp(-1.0, 1.0));
        }
        let (mut gi, mut gj) = ([0u32; LOOKUP_CHUNK], [0u32; LOOKUP_CHUNK]);
        let (wf, hf) = (w as f64, h as f64 / PI);
        let (wm, hm) = ((w - 1) as u32, (h - 1) as u32);
        for k in 0..LOOKUP_CHUNK {
            let (ax, ay) = (cx[k].abs(), sx[k].abs());
            let steep = ay > ax;
            let (lo, hi) = if steep { (ax, ay) } else { (ay, ax) };
            let a = atan_01(lo / hi);
            let a = if steep { 0.5 * PI - a } else { a };
            let a = if cx[k] < 0.0 { PI - a } else { a };
            let u = a / (2.0 * PI);
            let u = if sx[k] < 0.0 { 1.0 - u } else { u };
            let u = if u >= 1.0 { 0.0 } else { u };
            // (NaN, at a pole, converts to 0; the pole is column 0 below.)
            gi[k] = if hi > 0.0 {
                ((u * wf) as u32).min(wm)
            } else {
                0
            };
            gj[k] = ((acos_guess(y[k]) * hf) as u32).min(hm);
        }
        for k in 0..n {
            let (sx, cx, y) = (sx[k], cx[k], y[k]);
            let mut i = gi[k] as usize;
            if w > 1 && (sx != 0.0 || cx != 0.0) {
                let past = |k: usize| sx * map.col_cs[k].1 - cx * map.col_cs[k].0 >= 0.0;
                while i > 0 && !past(i) {
                    i -= 1;
                }
                while i + 1 < w && past(i + 1) {
                    i += 1;
                }
            } else {
                i = 0;
            }
            let mut j = gj[k] as usize;
            while j > 0 && y > map.row_cos[j] {
                j -= 1;
            }
            while j + 1 < h && y <= map.row_cos[j + 1] {
                j += 1;
            }
            out[k] = j * w + i;
        }
    }
}

/// An equirectangular environment map with its sampling distribution.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvMap {
    width: usize,
    height: usize,
    /// `cos(π j / height)` for `j = 0..=height`: the rows' edges.
    row_cos: Vec<f64>,
    /// `(sin, cos)(2π i / width)` for `i = 0..=width`: the columns' edges.
    col_cs: Vec<(f64, f64)>,
    /// Radiance per texel in `f32`, 16 bytes each: a lookup reads one
    /// aligned block, and computes the luminance the densities are
    /// functions of ([`TexelSampler::weight`]) from it.
    texels: Vec<Texel>,
    scale: f64,
    /// cos and sin of the rotation about +Y.
    rot: (f64, f64),
    /// Density ∝ luminance.
    plain: TexelSampler,
    /// Density ∝ max(0, luminance − its mean): for MIS with BSDF sampling.
    compensated: TexelSampler,
}

/// One texel's radiance (before `scale`), in `f32` as map files hold it
/// (an `.exr`'s half or float, an `.hdr`'s RGBE: no rounding), padded to
/// 16 bytes so that none straddles a cache line.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(16))]
struct Texel {
    rgb: [f32; 3],
}

impl Texel {
    #[inline]
    fn rgb(self) -> Rgb {
        Rgb::new(
            f64::from(self.rgb[0]),
            f64::from(self.rgb[1]),
            f64::from(self.rgb[2]),
        )
    }

    /// The luminance, in `f64` from the `f64` radiance: the same bits
    /// wherever it is computed (the densities' build and every lookup).
    #[inline]
    fn lum(self) -> f64 {
        luminance(self.rgb())
    }
}

/// The texels of a map being decoded, in the map's own storage, zero until
/// set: a decoder writes each texel where it belongs ([`TexelBuffer::set`],
/// or a line's channel at a time into a band of rows,
/// [`TexelBuffer::bands`]) and [`EnvMap::from_texel_buffer`] takes the
/// storage as it is.
#[derive(Debug, Clone, PartialEq)]
pub struct TexelBuffer {
    width: usize,
    height: usize,
    texels: Vec<Texel>,
}

impl TexelBuffer {
    /// `width × height` black texels.
    ///
    /// # Panics
    /// If `width × height` overflows `usize`.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        let n = width
            .checked_mul(height)
            .expect("TexelBuffer: width × height overflows");
        let black = Texel { rgb: [0.0; 3] };
        // Written on rayon's threads when there are: the first touch of
        // each page of a large map (a page fault each, 2048 for 1024 × 512)
        // shared out.
        #[cfg(feature = "parallel")]
        let texels = {
            use rayon::prelude::*;
            let mut t = Vec::with_capacity(n);
            t.par_extend(rayon::iter::repeat_n(black, n));
            t
        };
        #[cfg(not(feature = "parallel"))]
        let texels = vec![black; n];
        TexelBuffer {
            width,
            height,
            texels,
        }
    }

    /// Set texel `(i, j)` (column, row from the top) to `rgb` (before the
    /// map's scale; clamped as [`EnvMap::new`] clamps when the map is built).
    ///
    /// # Panics
    /// If `(i, j)` is outside the buffer.
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, rgb: [f32; 3]) {
        assert!(
            i < self.width && j < self.height,
            "TexelBuffer::set: ({i}, {j}) outside {}×{}",
            self.width,
            self.height
        );
        self.texels[j * self.width + i] = Texel { rgb };
    }

    /// The buffer cut into bands of `rows` rows each from the top (the last
    /// one shorter when `rows` does not divide the height), each one borrowed
    /// on its own: a decoder's threads can set a band each
    /// ([`TexelBand::set_channel_run`]). None for a buffer without texels.
    ///
    /// # Panics
    /// If `rows` is 0.
    pub fn bands(&mut self, rows: usize) -> impl Iterator<Item = TexelBand<'_>> {
        assert!(rows > 0, "TexelBuffer::bands: bands of 0 rows");
        let width = self.width;
        // (`max(1)`: a buffer of width 0 has no texels, so no chunk.)
        self.texels
            .chunks_mut(rows.saturating_mul(width).max(1))
            .enumerate()
            .map(move |(k, texels)| TexelBand {
                width,
                first_row: k * rows,
                rows: texels.len() / width,
                texels,
            })
    }

    /// `(width, height)`.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

/// Rows of a [`TexelBuffer`], borrowed to be set ([`TexelBuffer::bands`]).
#[derive(Debug)]
pub struct TexelBand<'a> {
    width: usize,
    first_row: usize,
    rows: usize,
    texels: &'a mut [Texel],
}

impl TexelBand<'_> {
    /// The buffer's rows the band holds.
    #[must_use]
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.first_row..self.first_row + self.rows
    }

    /// The buffer's width in texels.
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Set channel `c` (0 red, 1 green, 2 blue) of the run of texels
    /// starting at `(i0, j)` (`j` counted from the top of the buffer):
    /// `values[k]` to texel `(i0 + k, j)` (a decoder's line of one channel,
    /// as [`TexelBuffer::set`] sets texels). A whole buffer is one band
    /// (`bands(height)`).
    ///
    /// # Panics
    /// If the run leaves row `j` or the band, or `c > 2`.
    #[inline]
    pub fn set_channel_run(
        &mut self,
        i0: usize,
        j: usize,
        c: usize,
        values: impl ExactSizeIterator<Item = f32>,
    ) {
        let n = values.len();
        assert!(
            c < 3 && self.rows().contains(&j) && i0.checked_add(n).is_some_and(|e| e <= self.width),
            "TexelBand::set_channel_run: channel {c}, {n} texels from ({i0}, {j}) outside rows {:?} of width {}",
            self.rows(),
            self.width
        );
        let start = (j - self.first_row) * self.width + i0;
        for (t, v) in self.texels[start..start + n].iter_mut().zip(values) {
            t.rgb[c] = v;
        }
    }
}

/// A piecewise-constant density over the texels: texel weights times their
/// solid angles, a marginal over rows and a conditional within each row.
#[derive(Debug, Clone, PartialEq)]
struct TexelSampler {
    /// The weight of a texel of luminance `lum`: `lum`, or with `Some(m)`
    /// `max(0, lum − m)`.
    shift: Option<f64>,
    rows: Distribution1D,
    cols: Columns,
    /// Σ weight·Ω over the texels.
    norm: f64,
}

/// The conditional distributions of a map's rows over their `width`
/// columns, each one a [`Distribution1D`]'s tables, all of them in two
/// buffers (row `j`'s CDF at `cdf[j (width + 1)..]`, its guide table at
/// `guide[j width..]`): two allocations instead of two per row, which the
/// threads that build the rows fill in place.
///
/// The rows' totals (the marginal's weights, and so the density) are
/// computed when the sampler is; the tables, needed only to draw from it,
/// when they are first asked for ([`TexelSampler::columns`]), or up front
/// ([`EnvMap::prepare_sampling`]): a renderer that draws only from the
/// compensated density never builds the plain one's.
#[derive(Debug, Clone)]
struct Columns {
    width: usize,
    /// Each row's sum of weights, bit for bit the sum the row's tables are
    /// normalized by.
    totals: Vec<f64>,
    tables: std::sync::OnceLock<ColumnTables>,
}

/// Two samplers of the same texels are equal when their weights are: the
/// tables are a function of them, built or not.
impl PartialEq for Columns {
    fn eq(&self, other: &Self) -> bool {
        self.width == other.width && self.totals == other.totals
    }
}

/// The buffers of [`Columns`].
#[derive(Debug, Clone)]
struct ColumnTables {
    cdf: Vec<f64>,
    guide: Vec<u32>,
}

/// [`Columns`] with its tables built, borrowed.
#[derive(Debug, Clone, Copy)]
struct BuiltColumns<'a> {
    width: usize,
    totals: &'a [f64],
    tables: &'a ColumnTables,
}

impl<'a> BuiltColumns<'a> {
    /// Row `j`'s distribution.
    #[inline]
    fn row(self, j: usize) -> Tables<'a> {
        let w = self.width;
        Tables {
            cdf: &self.tables.cdf[j * (w + 1)..(j + 1) * (w + 1)],
            total: self.totals[j],
            guide: &self.tables.guide[j * w..(j + 1) * w],
        }
    }
}

impl TexelSampler {
    /// The sampler of the texels' weights under `shift`: the rows' totals,
    /// the marginal and the norm now; with `tables`, the rows' tables too
    /// (else when first drawn from).
    fn new(
        width: usize,
        height: usize,
        shift: Option<f64>,
        texels: &[Texel],
        tables: bool,
    ) -> Self {
        let (totals, built) = if tables {
            let (t, c) = Self::build_tables(width, height, shift, texels, true);
            (t, Some(c))
        } else {
            // Each row's sum in the order `Distribution1D::build` sums it:
            // the same bits as the tables' totals.
            let row = |j: usize| {
                Self::row_weights(width, height, shift, texels, j)
                    .fold(0.0, |acc, w| acc + w.max(0.0))
            };
            #[cfg(feature = "parallel")]
            let totals: Vec<f64> = {
                use rayon::prelude::*;
                (0..height).into_par_iter().map(row).collect()
            };
            #[cfg(not(feature = "parallel"))]
            let totals: Vec<f64> = (0..height).map(row).collect();
            (totals, None)
        };
        let rows = Distribution1D::new(&totals);
        let norm = rows.total();
        TexelSampler {
            shift,
            rows,
            cols: Columns {
                width,
                totals,
                tables: built.map_or_else(std::sync::OnceLock::new, std::sync::OnceLock::from),
            },
            norm,
        }
    }

    /// Row `j`'s weights: each texel's weight under `shift` times its solid
    /// angle (the same for the row's texels).
    fn row_weights(
        width: usize,
        height: usize,
        shift: Option<f64>,
        texels: &[Texel],
        j: usize,
    ) -> impl ExactSizeIterator<Item = f64> + Clone + '_ {
        let omega = 2.0 * PI / width as f64 * EnvMap::band(height, j);
        texels[j * width..(j + 1) * width]
            .iter()
            .map(move |t| Self::weight_of(shift, t.lum()) * omega)
    }

    /// The rows' tables and totals, each row's its own computation (the
    /// same numbers in parallel or not): on rayon's threads when `parallel`
    /// and the feature allow.
    fn build_tables(
        width: usize,
        height: usize,
        shift: Option<f64>,
        texels: &[Texel],
        parallel: bool,
    ) -> (Vec<f64>, ColumnTables) {
        let steps = Distribution1D::steps(width);
        // (Zeros from the allocator: pages that the rows' threads touch
        // first.)
        let mut cdf = vec![0.0; height * (width + 1)];
        let mut guide = vec![0u32; height * width];
        let row = |(j, (c, g)): (usize, (&mut [f64], &mut [u32]))| {
            let weights = Self::row_weights(width, height, shift, texels, j);
            // A row of weight 0 (most of a compensated sampler's rows
            // under a sky with a sun) leaves its tables as allocated, the
            // zeros `Distribution1D::build` would leave too: pages of them
            // that are never touched cost neither a fault nor a clearing.
            if !weights.clone().any(|w| w > 0.0) {
                return 0.0;
            }
            Distribution1D::build(weights, &steps, c, g)
        };
        #[cfg(feature = "parallel")]
        if parallel {
            use rayon::prelude::*;
            let totals = cdf
                .par_chunks_mut(width + 1)
                .zip(guide.par_chunks_mut(width))
                .enumerate()
                .map(row)
                .collect();
            return (totals, ColumnTables { cdf, guide });
        }
        #[cfg(not(feature = "parallel"))]
        let _ = parallel;
        let totals = cdf
            .chunks_mut(width + 1)
            .zip(guide.chunks_mut(width))
            .enumerate()
            .map(row)
            .collect();
        (totals, ColumnTables { cdf, guide })
    }

    /// The rows' tables, built on the first call. Built on rayon's threads
    /// unless the caller is one of them: a thread of the pool that waited
    /// for the rows' jobs could take another job of its own that asks for
    /// the same tables, inside their construction.
    #[inline]
    fn columns(&self, texels: &[Texel]) -> BuiltColumns<'_> {
        let tables = self.cols.tables.get_or_init(|| {
            #[cfg(feature = "parallel")]
            let parallel = rayon::current_thread_index().is_none();
            #[cfg(not(feature = "parallel"))]
            let parallel = false;
            let height = self.cols.totals.len();
            let (totals, tables) =
                Self::build_tables(self.cols.width, height, self.shift, texels, parallel);
            debug_assert!(
                totals
                    .iter()
                    .zip(&self.cols.totals)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "TexelSampler: the tables' totals differ from the rows' sums"
            );
            tables
        });
        BuiltColumns {
            width: self.cols.width,
            totals: &self.cols.totals,
            tables,
        }
    }
}

impl TexelSampler {
    #[inline]
    fn weight_of(shift: Option<f64>, lum: f64) -> f64 {
        match shift {
            None => lum,
            Some(m) => (lum - m).max(0.0),
        }
    }

    /// The density's weight of a texel of luminance `lum`.
    #[inline]
    fn weight(&self, lum: f64) -> f64 {
        Self::weight_of(self.shift, lum)
    }
}

/// What went wrong building a map.
#[derive(Debug, Clone, PartialEq)]
pub enum EnvMapError {
    Empty {
        width: usize,
        height: usize,
    },
    Size {
        width: usize,
        height: usize,
        got: usize,
    },
    Scale(f64),
    Rotation(f64),
}

impl std::fmt::Display for EnvMapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            EnvMapError::Empty { width, height } => {
                write!(f, "the map is empty ({width}×{height})")
            }
            EnvMapError::Size { width, height, got } => write!(
                f,
                "the map has {got} texels, expected {width}×{height} = {}",
                width * height
            ),
            EnvMapError::Scale(v) => write!(f, "scale {v} must be a finite number >= 0"),
            EnvMapError::Rotation(v) => write!(f, "rotation_y {v} must be a finite number"),
        }
    }
}

impl std::error::Error for EnvMapError {}

impl EnvMap {
    /// A map from row-major texels, row 0 at the top, stored in `f32`
    /// (rounded to nearest; a map file's values are `f32` already). Negative,
    /// infinite or NaN channels are clamped to 0, finite ones above
    /// `f32::MAX` to `f32::MAX`; the count of clamped texels is returned
    /// beside the map so that the caller can warn once.
    pub fn new(
        width: usize,
        height: usize,
        texels: Vec<Rgb>,
        scale: f64,
        rotation_y_deg: f64,
    ) -> Result<(Self, usize), EnvMapError> {
        Self::from_channels(
            width,
            height,
            texels.iter().map(|t| t.to_array()),
            scale,
            rotation_y_deg,
        )
    }

    /// [`EnvMap::new`] from `f32` RGB texels, as an image decoder gives
    /// them (stored as they are: no rounding, no `f64` copy of the map).
    pub fn from_rgb32f(
        width: usize,
        height: usize,
        texels: &[[f32; 3]],
        scale: f64,
        rotation_y_deg: f64,
    ) -> Result<(Self, usize), EnvMapError> {
        // (`from_texel_buffer` checks the size and the parameters.)
        let texels: Vec<Texel> = texels.iter().map(|&rgb| Texel { rgb }).collect();
        Self::from_texel_buffer(
            TexelBuffer {
                width,
                height,
                texels,
            },
            scale,
            rotation_y_deg,
        )
    }

    /// [`EnvMap::new`] from a [`TexelBuffer`] a decoder has filled, taking
    /// its storage as the map's (no copy of the texels).
    pub fn from_texel_buffer(
        buffer: TexelBuffer,
        scale: f64,
        rotation_y_deg: f64,
    ) -> Result<(Self, usize), EnvMapError> {
        let TexelBuffer {
            width,
            height,
            mut texels,
        } = buffer;
        Self::check(width, height, texels.len(), scale, rotation_y_deg)?;
        // As `from_channels` clamps, in `f32` (a finite `f32` is at most
        // `f32::MAX`): the same texels without a round trip through `f64`.
        // A count of the texels to clamp first, in a loop without branches
        // (vectorized), then the clamping only if there are any.
        // `!(c >= 0.0 && c.is_finite())` on the bits: negative (but −0),
        // infinite or NaN, an integer comparison that vectorizes.
        let bad = |c: f32| {
            let b = c.to_bits();
            b > 0x7f7f_ffff && b != 0x8000_0000
        };
        // (Chunks on rayon's threads when there are: a sum of integers, the
        // same in any order.)
        let count = |c: &[Texel]| {
            c.iter()
                .map(|t| u32::from(bad(t.rgb[0]) | bad(t.rgb[1]) | bad(t.rgb[2])))
                .sum::<u32>() as usize
        };
        #[cfg(feature = "parallel")]
        let clamped: usize = {
            use rayon::prelude::*;
            texels.par_chunks(1 << 16).map(count).sum()
        };
        #[cfg(not(feature = "parallel"))]
        let clamped: usize = texels.chunks(1 << 16).map(count).sum();
        if clamped > 0 {
            for t in &mut texels {
                t.rgb = t.rgb.map(|c| if bad(c) { 0.0 } else { c });
            }
        }
        Ok((
            Self::from_texels(width, height, texels, scale, rotation_y_deg),
            clamped,
        ))
    }

    /// The errors of a map's size and parameters.
    fn check(
        width: usize,
        height: usize,
        got: usize,
        scale: f64,
        rotation_y_deg: f64,
    ) -> Result<(), EnvMapError> {
        if width == 0 || height == 0 {
            return Err(EnvMapError::Empty { width, height });
        }
        if got != width * height {
            return Err(EnvMapError::Size { width, height, got });
        }
        if !scale.is_finite() || scale < 0.0 {
            return Err(EnvMapError::Scale(scale));
        }
        if !rotation_y_deg.is_finite() {
            return Err(EnvMapError::Rotation(rotation_y_deg));
        }
        Ok(())
    }

    fn from_channels(
        width: usize,
        height: usize,
        texels: impl ExactSizeIterator<Item = [f64; 3]>,
        scale: f64,
        rotation_y_deg: f64,
    ) -> Result<(Self, usize), EnvMapError> {
        Self::check(width, height, texels.len(), scale, rotation_y_deg)?;
        let mut clamped = 0;
        let top = f64::from(f32::MAX);
        let texels: Vec<Texel> = texels
            .map(|t| {
                let c = t.map(|c| {
                    if c >= 0.0 && c.is_finite() {
                        c.min(top)
                    } else {
                        0.0
                    }
                });
                // (A NaN channel compares unequal too.)
                if c != t {
                    clamped += 1;
                }
                Texel {
                    rgb: c.map(|c| c as f32),
                }
            })
            .collect();
        Ok((
            Self::from_texels(width, height, texels, scale, rotation_y_deg),
            clamped,
        ))
    }

    /// The map of valid texels (clamped) and parameters (checked).
    fn from_texels(
        width: usize,
        height: usize,
        texels: Vec<Texel>,
        scale: f64,
        rotation_y_deg: f64,
    ) -> Self {
        // The plain density's tables only when something draws from it (light
        // sampling alone; MIS draws from the compensated one).
        let plain = TexelSampler::new(width, height, None, &texels, false);
        // Mean luminance over the sphere, then the part above it.
        let mean = plain.norm / (4.0 * PI);
        let compensated = if texels.iter().any(|t| (t.lum() - mean).max(0.0) > 0.0) {
            TexelSampler::new(width, height, Some(mean), &texels, true)
        } else {
            plain.clone()
        };
        let r = rotation_y_deg.to_radians();
        EnvMap {
            width,
            height,
            row_cos: (0..=height)
                .map(|j| (PI * j as f64 / height as f64).cos())
                .collect(),
            col_cs: (0..=width)
                .map(|i| (2.0 * PI * i as f64 / width as f64).sin_cos())
                .collect(),
            texels,
            scale,
            rot: (r.cos(), r.sin()),
            plain,
            compensated,
        }
    }

    /// A map of one constant radiance (one texel).
    #[must_use]
    pub fn constant(c: Rgb) -> Self {
        EnvMap::new(1, 1, vec![c], 1.0, 0.0)
            .expect("a 1×1 map is valid")
            .0
    }

    /// `cos θ₀ − cos θ₁` of row `j`.
    fn band(height: usize, j: usize) -> f64 {
        let t0 = PI * j as f64 / height as f64;
        let t1 = PI * (j + 1) as f64 / height as f64;
        t0.cos() - t1.cos()
    }

    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    #[must_use]
    pub fn texel(&self, i: usize, j: usize) -> Rgb {
        self.radiance_at(j * self.width + i)
    }

    /// The scaled radiance of texel `k` (row-major).
    #[inline]
    fn radiance_at(&self, k: usize) -> Rgb {
        self.texels[k].rgb() * self.scale
    }

    /// Map coordinates `(u, v)` of a world direction.
    #[must_use]
    pub fn direction_to_uv(&self, d: DVec3) -> DVec2 {
        let d = self.unrotate(d);
        let mut u = d.x.atan2(-d.z) / (2.0 * PI);
        if u < 0.0 {
            u += 1.0;
        }
        if u >= 1.0 {
            u = 0.0;
        }
        DVec2::new(u, crate::math::safe_acos(d.y) / PI)
    }

    /// The world direction of map coordinates `(u, v)`.
    #[must_use]
    pub fn uv_to_direction(&self, uv: DVec2) -> DVec3 {
        let (st, ct) = (PI * uv.y).sin_cos();
        let (sp, cp) = (2.0 * PI * uv.x).sin_cos();
        self.rotate(DVec3::new(st * sp, ct, -st * cp))
    }

    /// Apply the map's rotation about +Y (map frame → world).
    fn rotate(&self, d: DVec3) -> DVec3 {
        let (c, s) = self.rot;
        DVec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z)
    }

    fn unrotate(&self, d: DVec3) -> DVec3 {
        let (c, s) = self.rot;
        DVec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
    }

    /// The texel of unit world direction `d`, as `direction_to_uv`'s
    /// `(⌊u·width⌋, ⌊v·height⌋)` would give it, without `atan2` and `acos`:
    /// a polynomial guess of `φ` and `θ` (error under 1e-4 rad), corrected
    /// by exact comparisons with the texel edges (the signs of
    /// `sin(φ − φ_k)` and of `cos θ − cos θ_k`). The two differ only for a
    /// direction within rounding of an edge.
    #[inline]
    fn texel_index(&self, d: DVec3) -> (usize, usize) {
        let d = self.unrotate(d);
        let (w, h) = (self.width, self.height);
        // φ = atan2(sx, cx) in (−π, π]: u = φ / 2π, wrapped.
        let (sx, cx) = (d.x, -d.z);
        let mut i = 0;
        let (ax, ay) = (cx.abs(), sx.abs());
        let (lo, hi) = if ay > ax { (ax, ay) } else { (ay, ax) };
        // (hi = 0: a pole, column 0.)
        if w > 1 && hi > 0.0 {
            let t = lo / hi;
            let mut a = atan_01(t);
            if ay > ax {
                a = 0.5 * PI - a;
            }
            if cx < 0.0 {
                a = PI - a;
            }
            let mut u = a / (2.0 * PI);
            if sx < 0.0 {
                u = 1.0 - u;
            }
            // As `direction_to_uv`: a u that rounds to 1 is 0.
            if u >= 1.0 {
                u = 0.0;
            }
            i = ((u * w as f64) as usize).min(w - 1);
            // sin(φ − φ_k) ≥ 0: at or past edge k.
            let past = |k: usize| sx * self.col_cs[k].1 - cx * self.col_cs[k].0 >= 0.0;
            while i > 0 && !past(i) {
                i -= 1;
            }
            while i + 1 < w && past(i + 1) {
                i += 1;
            }
        }
        // Row j: cos θ_{j+1} < y ≤ cos θ_j.
        let y = d.y.clamp(-1.0, 1.0);
        let mut j = ((acos_guess(y) * (h as f64 / PI)) as usize).min(h - 1);
        while j > 0 && y > self.row_cos[j] {
            j -= 1;
        }
        while j + 1 < h && y <= self.row_cos[j + 1] {
            j += 1;
        }
        (i, j)
    }

    /// The texel by `direction_to_uv` (the reference of `texel_index`).
    #[cfg(test)]
    fn texel_index_by_uv(&self, d: DVec3) -> (usize, usize) {
        let uv = self.direction_to_uv(d);
        let i = ((uv.x * self.width as f64) as usize).min(self.width - 1);
        let j = ((uv.y * self.height as f64) as usize).min(self.height - 1);
        (i, j)
    }

    /// Radiance arriving from world direction `d` (unit).
    #[inline]
    #[must_use]
    pub fn eval(&self, d: DVec3) -> Rgb {
        let (i, j) = self.texel_index(d);
        self.texel(i, j)
    }

    /// Build the tables that drawing from the map needs now, for both
    /// densities ([`EnvMap::sample`]'s is otherwise built by the first draw
    /// from it): on rayon's threads, where a first draw on one of them
    /// builds them on that thread alone. The same draws either way.
    pub fn prepare_sampling(&self) {
        let _ = self.plain.columns(&self.texels);
        let _ = self.compensated.columns(&self.texels);
    }

    /// Draw a world direction with density ∝ luminance; `None` for a black map.
    #[must_use]
    pub fn sample(&self, u: DVec2) -> Option<(DVec3, f64)> {
        self.sample_with(&self.plain, u)
    }

    /// Density in solid angle of [`EnvMap::sample`] at world direction `d`.
    #[inline]
    #[must_use]
    pub fn pdf(&self, d: DVec3) -> f64 {
        self.pdf_with(&self.plain, d)
    }

    /// Draw with density ∝ `max(0, lum − mean lum)` (MIS compensation,
    /// Karlík et al. 2019): where the map is dimmer than its mean, BSDF
    /// sampling takes over inside MIS. Only for MIS: alone it would miss
    /// those directions. Falls back to [`EnvMap::sample`] for a uniform map.
    #[must_use]
    pub fn sample_compensated(&self, u: DVec2) -> Option<(DVec3, f64)> {
        self.sample_with(&self.compensated, u)
    }

    /// Density of [`EnvMap::sample_compensated`].
    #[inline]
    #[must_use]
    pub fn pdf_compensated(&self, d: DVec3) -> f64 {
        self.pdf_with(&self.compensated, d)
    }

    fn sample_with(&self, t: &TexelSampler, u: DVec2) -> Option<(DVec3, f64)> {
        let (j, ru) = t.rows.sample(u.x)?;
        let (i, rv) = t.columns(&self.texels).row(j).sample(u.y)?;
        // Uniform in solid angle inside the texel: uniform in cos θ and φ.
        let t0 = PI * j as f64 / self.height as f64;
        let t1 = PI * (j + 1) as f64 / self.height as f64;
        let (c0, c1) = (t0.cos(), t1.cos());
        let ct = c0 + (c1 - c0) * ru;
        let v = crate::math::safe_acos(ct) / PI;
        let uu = (i as f64 + rv) / self.width as f64;
        let d = self.uv_to_direction(DVec2::new(uu, v.clamp(t0 / PI, t1 / PI)));
        let pdf = self.pdf_with(t, d);
        (pdf > 0.0).then_some((d, pdf))
    }

    #[inline]
    fn pdf_with(&self, t: &TexelSampler, d: DVec3) -> f64 {
        if t.norm <= 0.0 {
            return 0.0;
        }
        let (i, j) = self.texel_index(d);
        t.weight(self.texels[j * self.width + i].lum()) / t.norm
    }

    /// Radiance and both densities ([`EnvMap::pdf`],
    /// [`EnvMap::pdf_compensated`]) at world direction `d` (unit), from one
    /// texel lookup: the same values as the three calls.
    #[inline]
    #[must_use]
    pub fn lookup(&self, d: DVec3) -> EnvLookup {
        let (i, j) = self.texel_index(d);
        self.texel_lookup(j * self.width + i)
    }

    #[inline(always)]
    fn texel_lookup(&self, k: usize) -> EnvLookup {
        let texel = self.texels[k];
        let lum = texel.lum();
        let pdf = |t: &TexelSampler| {
            if t.norm > 0.0 {
                t.weight(lum) / t.norm
            } else {
                0.0
            }
        };
        EnvLookup {
            radiance: self.radiance_at(k),
            pdf: pdf(&self.plain),
            pdf_compensated: pdf(&self.compensated),
        }
    }

    /// Draw a world direction as [`EnvMap::sample`] (`compensated = false`)
    /// or [`EnvMap::sample_compensated`] (`true`) do, from the same
    /// distribution over the texels and uniformly in solid angle inside the
    /// texel, and return it with the [`EnvLookup`] of the texel it was drawn
    /// in (no second lookup, and no `acos`: `sin θ` comes from `cos θ`).
    /// `None` for a black map. The direction can differ from
    /// [`EnvMap::sample`]'s in its last bits.
    #[inline]
    #[must_use]
    pub fn sample_lookup(&self, compensated: bool, u: DVec2) -> Option<(DVec3, EnvLookup)> {
        let t = self.sampler(compensated);
        let (j, ru) = t.rows.sample(u.x)?;
        let (i, rv) = t.columns(&self.texels).row(j).sample(u.y)?;
        self.finish_sample(compensated, (j, ru), (i, rv))
    }

    fn sampler(&self, compensated: bool) -> &TexelSampler {
        if compensated {
            &self.compensated
        } else {
            &self.plain
        }
    }

    /// [`EnvMap::sample_lookup`] of many draws `(compensated, u)`:
    /// `out[k] = self.sample_lookup(draws[k].0, draws[k].1)`, bit for bit.
    /// Each step (the row, the column, the texel) is taken for a chunk of
    /// draws before the next, so that their reads of a map larger than the
    /// caches overlap instead of waiting in turn.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn sample_lookup_many(
        &self,
        draws: &[(bool, DVec2)],
        out: &mut [Option<(DVec3, EnvLookup)>],
    ) {
        assert_eq!(draws.len(), out.len(), "sample_lookup_many: lengths differ");
        // Compiled for the CPU's widest level (the same arithmetic, so the
        // same bits at every level).
        SimdLevel::best().run(SampleLookups {
            map: self,
            draws,
            out,
        });
    }

    /// [`EnvMap::lookup`] of many directions: `out[k] = self.lookup(dirs[k])`,
    /// bit for bit, the texel searches of a chunk first and then its reads,
    /// which overlap.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn lookup_many(&self, dirs: &[DVec3], out: &mut [EnvLookup]) {
        self.lookup_many_at(SimdLevel::best(), dirs, out);
    }

    /// [`EnvMap::lookup_many`] with the texel guesses compiled for `level`
    /// (the same bits at every level).
    fn lookup_many_at(&self, level: SimdLevel, dirs: &[DVec3], out: &mut [EnvLookup]) {
        assert_eq!(dirs.len(), out.len(), "lookup_many: lengths differ");
        self.texels_many(level, dirs, out, |k| self.texel_lookup(k));
    }

    /// [`EnvMap::eval`] of many directions, the radiance alone (no
    /// densities): `out[k] = self.eval(dirs[k])`, bit for bit, as
    /// [`EnvMap::lookup_many`] finds the texels.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn eval_many(&self, dirs: &[DVec3], out: &mut [Rgb]) {
        self.eval_many_at(SimdLevel::best(), dirs, out);
    }

    fn eval_many_at(&self, level: SimdLevel, dirs: &[DVec3], out: &mut [Rgb]) {
        assert_eq!(dirs.len(), out.len(), "eval_many: lengths differ");
        self.texels_many(level, dirs, out, |k| self.radiance_at(k));
    }

    /// `out[k] = at(texel index of dirs[k])`, the indices of a chunk found
    /// together at `level` first.
    #[inline]
    fn texels_many<T>(
        &self,
        level: SimdLevel,
        dirs: &[DVec3],
        out: &mut [T],
        at: impl Fn(usize) -> T,
    ) {
        for (dc, oc) in dirs.chunks(LOOKUP_CHUNK).zip(out.chunks_mut(LOOKUP_CHUNK)) {
            let mut idx = [0usize; LOOKUP_CHUNK];
            level.run(TexelIndices {
                map: self,
                dirs: dc,
                out: &mut idx,
            });
            for &k in &idx[..dc.len()] {
                prefetch(&self.texels[k]);
            }
            for (o, &k) in oc.iter_mut().zip(&idx) {
                *o = at(k);
            }
        }
    }

    /// `sin_cos` of `φ = 2π (i + rv) / width`, `rv ∈ [0, 1)`: column
    /// `i`'s edge from the table turned by `δ = 2π rv / width`, whose sine
    /// and cosine are Taylor polynomials exact to f64 rounding for
    /// `δ < 2π/256` (the terms left out are below 1e-18 of the result);
    /// narrower maps call `sin_cos`.
    #[inline(always)]
    fn column_sin_cos(&self, i: usize, rv: f64) -> (f64, f64) {
        let w = self.width as f64;
        if self.width < 256 {
            return (2.0 * PI * (i as f64 + rv) / w).sin_cos();
        }
        let d = 2.0 * PI * rv / w;
        let d2 = d * d;
        let sd =
            d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0) * (1.0 - d2 * (1.0 / 42.0))));
        let cd = 1.0
            - d2 * 0.5
                * (1.0 - d2 * (1.0 / 12.0) * (1.0 - d2 * (1.0 / 30.0) * (1.0 - d2 * (1.0 / 56.0))));
        let (s, c) = self.col_cs[i];
        (s * cd + c * sd, c * cd - s * sd)
    }

    /// The direction and lookup of a draw in texel `(i, j)` at `(ru, rv)`.
    #[inline(always)]
    fn finish_sample(
        &self,
        compensated: bool,
        (j, ru): (usize, f64),
        (i, rv): (usize, f64),
    ) -> Option<(DVec3, EnvLookup)> {
        let (c0, c1) = (self.row_cos[j], self.row_cos[j + 1]);
        let ct = (c0 + (c1 - c0) * ru).clamp(c1.min(c0), c0.max(c1));
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let (sp, cp) = self.column_sin_cos(i, rv);
        let d = self.rotate(DVec3::new(st * sp, ct, -st * cp));
        let l = self.texel_lookup(j * self.width + i);
        let p = if compensated {
            l.pdf_compensated
        } else {
            l.pdf
        };
        (p > 0.0).then_some((d, l))
    }

    /// The solid-angle region of texel `(i, j)`: `(θ₀, θ₁)`, `(φ₀, φ₁)` in the
    /// map's own frame, where `φ = 2πu`.
    #[must_use]
    pub fn texel_region(&self, i: usize, j: usize) -> ((f64, f64), (f64, f64)) {
        let h = self.height as f64;
        let w = self.width as f64;
        (
            (PI * j as f64 / h, PI * (j + 1) as f64 / h),
            (2.0 * PI * i as f64 / w, 2.0 * PI * (i + 1) as f64 / w),
        )
    }

    /// World direction of map-frame spherical coordinates `(θ, φ)`.
    #[must_use]
    pub fn spherical_to_direction(&self, theta: f64, phi: f64) -> DVec3 {
        self.uv_to_direction(DVec2::new(phi / (2.0 * PI), theta / PI))
    }

    /// A procedural sky with a sun, the embedded default: a blue gradient
    /// above the horizon, a dim ground, and a small bright sun at elevation
    /// `sun_elevation_deg` toward azimuth `sun_azimuth_deg` (degrees; 0 is −Z).
    #[must_use]
    pub fn sky(width: usize, height: usize, sun_elevation_deg: f64, sun_azimuth_deg: f64) -> Self {
        let (el, az) = (sun_elevation_deg.to_radians(), sun_azimuth_deg.to_radians());
        let sun = DVec3::new(el.cos() * az.sin(), el.sin(), -el.cos() * az.cos());
        let sun_cos = 1.0f64.to_radians().cos(); // a disc of 1° radius
        let mut tex = Vec::with_capacity(width * height);
        let probe = EnvMap::constant(Rgb::ONE);
        for j in 0..height {
            for i in 0..width {
                let d = probe.uv_to_direction(DVec2::new(
                    (i as f64 + 0.5) / width as f64,
                    (j as f64 + 0.5) / height as f64,
                ));
                let c = if d.y > 0.0 {
                    let t = d.y.powf(0.4);
                    Rgb::new(0.9, 0.95, 1.0) * (1.0 - t) + Rgb::new(0.25, 0.45, 0.95) * t
                } else {
                    Rgb::new(0.25, 0.22, 0.2) * (1.0 + d.y).max(0.2)
                };
                let glow = (d.dot(sun).max(0.0)).powf(64.0) * Rgb::new(2.0, 1.6, 1.0);
                let disc = if d.dot(sun) > sun_cos {
                    Rgb::new(9000.0, 8100.0, 6900.0)
                } else {
                    Rgb::ZERO
                };
                tex.push(c + glow + disc);
            }
        }
        EnvMap::new(width, height, tex, 1.0, 0.0)
            .expect("the sky is a valid map")
            .0
    }
}

#[cfg(test)]
mod tests {
    /// `w × h` texels (at least 41 × 10) with a black row (5), a sun (one
    /// texel, (40, 9)) and a sky that varies along both axes.
    fn black_row_and_sun(w: usize, h: usize) -> Vec<Rgb> {
        (0..w * h)
            .map(|k| {
                let (i, j) = (k % w, k / w);
                if j == 5 {
                    Rgb::ZERO
                } else if (i, j) == (40, 9) {
                    Rgb::splat(5e4)
                } else {
                    Rgb::new(0.2 + (i as f64 * 0.37).sin().abs(), 0.5, 1.0 + j as f64)
                }
            })
            .collect()
    }

    /// The plain density's tables wait for the first draw: a map fresh from
    /// `EnvMap::new` has the compensated one's only. Built by draws on
    /// the threads of a pool (several asking at once, each of them a thread
    /// that could otherwise take a job of the build), they are the tables
    /// [`EnvMap::prepare_sampling`] builds on the calling thread, and they
    /// draw the same directions and densities, bit for bit; their rows'
    /// totals are the sums the density had before.
    #[test]
    fn plain_tables_are_built_on_first_draw() {
        use rayon::prelude::*;
        let (w, h) = (64, 16);
        let rgb = black_row_and_sun(w, h);
        let lazy = EnvMap::new(w, h, rgb.clone(), 1.5, 20.0).unwrap().0;
        let eager = EnvMap::new(w, h, rgb, 1.5, 20.0).unwrap().0;
        assert!(lazy.plain.cols.tables.get().is_none());
        assert!(lazy.compensated.cols.tables.get().is_some());
        eager.prepare_sampling();
        assert!(eager.plain.cols.tables.get().is_some());
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let us: Vec<DVec2> = (0..4000)
            .map(|k| DVec2::new((k as f64 * 0.618_034) % 1.0, (k as f64 * 0.754_877) % 1.0))
            .collect();
        let drawn: Vec<_> = pool.install(|| {
            us.par_iter()
                .with_max_len(1)
                .map(|&u| (lazy.sample(u), lazy.sample_lookup(false, u)))
                .collect()
        });
        for (&u, (s, l)) in us.iter().zip(&drawn) {
            assert_eq!(*s, eager.sample(u), "u {u}");
            assert_eq!(*l, eager.sample_lookup(false, u), "u {u}");
        }
        let (a, b) = (
            lazy.plain.columns(&lazy.texels),
            eager.plain.columns(&eager.texels),
        );
        assert_eq!(a.tables.cdf, b.tables.cdf);
        assert_eq!(a.tables.guide, b.tables.guide);
        let (_, built) = TexelSampler::build_tables(w, h, None, &lazy.texels, false);
        assert_eq!(a.tables.cdf, built.cdf);
        for j in 0..h {
            assert_eq!(a.row(j).total.to_bits(), a.totals[j].to_bits());
        }
        let (totals, _) = TexelSampler::build_tables(w, h, None, &lazy.texels, true);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&totals), bits(&lazy.plain.cols.totals));
    }

    /// A sampler's rows, built in place in its two shared buffers
    /// ([`Columns`]), are the distributions [`Distribution1D::from_weights`]
    /// builds alone, bit for bit, and sample alike (a sun in a sky, a
    /// black row).
    #[test]
    fn columns_are_the_rows_distributions() {
        let (w, h) = (64usize, 16usize);
        let m = EnvMap::new(w, h, black_row_and_sun(w, h), 1.0, 0.0)
            .unwrap()
            .0;
        for t in [&m.plain, &m.compensated] {
            let dphi = 2.0 * PI / w as f64;
            for j in 0..h {
                let omega = dphi * EnvMap::band(h, j);
                let alone = Distribution1D::from_weights(
                    m.texels[j * w..(j + 1) * w]
                        .iter()
                        .map(|x| TexelSampler::weight_of(t.shift, x.lum()) * omega),
                );
                let row = t.columns(&m.texels).row(j);
                assert_eq!(row.cdf, &alone.cdf[..], "row {j}");
                assert_eq!(row.guide, &alone.guide[..], "row {j}");
                assert_eq!(row.total.to_bits(), alone.total().to_bits(), "row {j}");
                for k in 0..200 {
                    let u = k as f64 / 200.0 + 1e-3;
                    assert_eq!(row.sample(u), alone.sample(u), "row {j} u {u}");
                }
            }
        }
    }

    /// The column's sine and cosine from the table and the polynomials
    /// are `sin_cos`'s within 4e-15 (both round the angle, whose unit in
    /// the last place is up to 8.9e-16).
    #[test]
    fn column_sin_cos_is_sin_cos() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
        for w in [1usize, 3, 255, 256, 1024, 4096] {
            let m = EnvMap::new(w, 2, vec![Rgb::ONE; 2 * w], 1.0, 0.0)
                .unwrap()
                .0;
            for k in 0..5000 {
                let i = rng.random_range(0..w);
                let rv = match k {
                    0 => 0.0,
                    1 => 1.0 - f64::EPSILON / 2.0,
                    _ => rng.random::<f64>(),
                };
                let (s, c) = m.column_sin_cos(i, rv);
                let (s0, c0) = (2.0 * PI * (i as f64 + rv) / w as f64).sin_cos();
                assert!(
                    (s - s0).abs() <= 4e-15 && (c - c0).abs() <= 4e-15,
                    "w {w} i {i} rv {rv}: {s} {c} against {s0} {c0}"
                );
            }
        }
    }

    /// The guide table finds the bin a binary search finds, for every `u`
    /// of a fine grid and random ones, with empty bins and spikes.
    #[test]
    fn guide_table_agrees_with_binary_search() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(4);
        for case in 0..240 {
            // Short ones with many spikes; from 200 on, long ones with a
            // few (a sun in a sky: many bins in one guide interval).
            let (n, spikes) = if case < 200 {
                (1 + case % 37, 4)
            } else {
                (500 + 13 * case, 2000)
            };
            let w: Vec<f64> = (0..n)
                .map(|_| match rng.random_range(0..spikes) {
                    0 => 0.0,
                    1 => rng.random::<f64>() * 1e6,
                    _ => rng.random::<f64>(),
                })
                .collect();
            let d = Distribution1D::new(&w);
            if d.total() <= 0.0 {
                continue;
            }
            for k in 0..1000 {
                let u = k as f64 / 1000.0;
                assert_eq!(d.bin(u), d.bin_by_search(u), "{w:?} u {u}");
            }
            // The guide's own edges.
            for k in 0..n {
                let u = k as f64 / n as f64;
                assert_eq!(d.bin(u), d.bin_by_search(u), "{w:?} u {u}");
            }
            for _ in 0..1000 {
                let u: f64 = rng.random();
                assert_eq!(d.bin(u), d.bin_by_search(u), "{w:?} u {u}");
            }
            for &c in &d.cdf {
                let u = c.min(1.0 - f64::EPSILON / 2.0);
                assert_eq!(d.bin(u), d.bin_by_search(u), "{w:?} u {u} (an edge)");
            }
        }
    }

    use super::*;

    #[test]
    fn mitsuba_convention() {
        let m = EnvMap::constant(Rgb::ONE);
        // +Y is v = 0; -Z is u = 0; +X is u = 1/4.
        assert!(m.direction_to_uv(DVec3::Y).y.abs() < 1e-12);
        assert!((m.direction_to_uv(-DVec3::Y).y - 1.0).abs() < 1e-12);
        let uv = m.direction_to_uv(-DVec3::Z);
        assert!(uv.x.abs() < 1e-12 && (uv.y - 0.5).abs() < 1e-12);
        assert!((m.direction_to_uv(DVec3::X).x - 0.25).abs() < 1e-12);
        assert!((m.direction_to_uv(DVec3::Z).x - 0.5).abs() < 1e-12);
        for &(u, v) in &[(0.1, 0.2), (0.7, 0.9), (0.5, 0.5)] {
            let d = m.uv_to_direction(DVec2::new(u, v));
            let back = m.direction_to_uv(d);
            assert!((back - DVec2::new(u, v)).length() < 1e-12);
        }
    }

    #[test]
    fn rotation_turns_the_map_about_y() {
        let (m, _) = EnvMap::new(
            4,
            2,
            (0..8).map(|k| Rgb::splat(k as f64)).collect(),
            1.0,
            90.0,
        )
        .unwrap();
        // Rotating by 90° moves what was at -Z (u = 0) to -X... (R_y(90°) maps -Z to -X).
        let plain = EnvMap::new(
            4,
            2,
            (0..8).map(|k| Rgb::splat(k as f64)).collect(),
            1.0,
            0.0,
        )
        .unwrap()
        .0;
        let d = DVec3::new(0.0, 0.3, -1.0).normalize();
        let rd = DVec3::new(-d.z * 1.0, d.y, d.x).normalize(); // R_y(90°) d: (x,z) -> (z, -x)
        assert_eq!(m.eval(DVec3::new(d.z, d.y, -d.x)), plain.eval(d), "{rd}");
    }

    #[test]
    fn negative_nan_and_huge_texels_are_clamped_and_counted() {
        let (m, n) = EnvMap::new(
            2,
            1,
            vec![
                Rgb::new(-1.0, 0.5, f64::NAN),
                Rgb::new(f64::INFINITY, 1.0, 1.0),
            ],
            1.0,
            0.0,
        )
        .unwrap();
        assert_eq!(n, 2);
        assert_eq!(m.texel(0, 0), Rgb::new(0.0, 0.5, 0.0));
        assert_eq!(m.texel(1, 0), Rgb::new(0.0, 1.0, 1.0));
        // Beyond f32: the largest f32, and counted; an f64 value is
        // rounded to the nearest f32. (+∞ is clamped to 0 like NaN.)
        let big = f64::from(f32::MAX);
        let (m, n) = EnvMap::new(
            3,
            1,
            vec![Rgb::new(1e300, 0.1, 2e38), Rgb::splat(big), Rgb::ONE],
            1.0,
            0.0,
        )
        .unwrap();
        assert_eq!(n, 1);
        assert_eq!(
            m.texel(0, 0),
            Rgb::new(big, f64::from(0.1f32), f64::from(2e38f32))
        );
        assert_eq!(m.texel(1, 0), Rgb::splat(big));
        assert!(m.lookup(DVec3::X).pdf.is_finite());
    }

    /// `from_rgb32f` builds the map `new` builds from the same values
    /// (clamps and counts included), and refuses a wrong texel count.
    #[test]
    fn f32_texels_make_the_same_map() {
        let rgb: Vec<[f32; 3]> = (0..32 * 16)
            .map(|k| match k % 97 {
                0 => [-1.0, f32::NAN, 2.0],
                1 => [f32::INFINITY, 1.0, 0.5],
                2 => [-0.0, f32::NEG_INFINITY, 1.0],
                3 => [-f32::NAN, 0.0, 0.0],
                // −0 is not clamped; the largest finite and the smallest
                // subnormal are kept, a negative subnormal is not.
                4 => [-0.0, -0.0, -0.0],
                5 => [f32::MAX, 1e-45, -1e-45],
                _ => [k as f32 * 0.37, (k % 13) as f32, 1e-3 * k as f32],
            })
            .collect();
        let wide: Vec<Rgb> = rgb
            .iter()
            .map(|c| Rgb::from_array(c.map(f64::from)))
            .collect();
        let a = EnvMap::from_rgb32f(32, 16, &rgb, 1.5, 20.0).unwrap();
        let b = EnvMap::new(32, 16, wide, 1.5, 20.0).unwrap();
        assert_eq!(a.1, 30);
        assert_eq!(b.1, 30);
        assert_eq!(a, b);
        // Filled texel by texel, in any order, as a decoder fills it.
        let mut buf = TexelBuffer::new(32, 16);
        assert_eq!(buf.size(), (32, 16));
        for k in (0..rgb.len()).rev() {
            buf.set(k % 32, k / 32, rgb[k]);
        }
        assert_eq!(EnvMap::from_texel_buffer(buf, 1.5, 20.0).unwrap(), a);
        // Filled a channel run at a time in bands of 5 rows (the last of 1),
        // in any order of the bands, as a decoder's threads fill it.
        let mut buf = TexelBuffer::new(32, 16);
        let mut bands: Vec<TexelBand<'_>> = buf.bands(5).collect();
        let rows: Vec<_> = bands.iter().map(TexelBand::rows).collect();
        assert_eq!(rows, [0..5, 5..10, 10..15, 15..16]);
        for band in bands.iter_mut().rev() {
            for j in band.rows() {
                for c in 0..3 {
                    band.set_channel_run(0, j, c, rgb[j * 32..(j + 1) * 32].iter().map(|t| t[c]));
                }
            }
        }
        assert_eq!(EnvMap::from_texel_buffer(buf, 1.5, 20.0).unwrap(), a);
        let short = TexelBuffer::new(32, 15);
        assert!(EnvMap::from_texel_buffer(short, 1.0, f64::NAN).is_err());
        assert!(EnvMap::from_rgb32f(32, 15, &rgb, 1.0, 0.0).is_err());
    }

    #[test]
    fn bad_maps_are_refused() {
        assert!(EnvMap::new(0, 1, vec![], 1.0, 0.0).is_err());
        assert!(EnvMap::new(2, 2, vec![Rgb::ONE; 3], 1.0, 0.0).is_err());
        assert!(EnvMap::new(1, 1, vec![Rgb::ONE], f64::NAN, 0.0).is_err());
        assert!(EnvMap::new(1, 1, vec![Rgb::ONE], 1.0, f64::INFINITY).is_err());
    }

    #[test]
    fn sampled_pdf_matches_pdf_and_black_maps_fail() {
        let m = EnvMap::sky(64, 32, 30.0, 40.0);
        for k in 0..1000 {
            let u = DVec2::new(
                (k as f64 * 0.618_033_988_7) % 1.0,
                (k as f64 * 0.414_213_562) % 1.0,
            );
            let (d, p) = m.sample(u).unwrap();
            assert!((p - m.pdf(d)).abs() <= 1e-9 * p);
        }
        assert!(
            EnvMap::constant(Rgb::ZERO)
                .sample(DVec2::splat(0.5))
                .is_none()
        );
    }

    /// The fast texel search agrees with `direction_to_uv`'s texel except
    /// within rounding of an edge; the guesses are within their bounds.
    #[test]
    fn texel_index_agrees_with_direction_to_uv() {
        let mut worst: f64 = 0.0;
        for k in 0..=1000 {
            let t = k as f64 / 1000.0;
            worst = worst.max((atan_01(t) - t.atan()).abs());
            let y = 2.0 * t - 1.0;
            assert!((acos_guess(y) - y.acos()).abs() < 1e-4, "acos {y}");
        }
        assert!(worst < 2e-5, "atan {worst}");
        for (w, h, rot) in [(64, 32, 33.0), (1024, 512, 0.0), (3, 2, -10.0), (1, 1, 0.0)] {
            let (m, _) = EnvMap::new(w, h, vec![Rgb::ONE; w * h], 1.0, rot).unwrap();
            let mut state = 0x9e37_79b9_7f4a_7c15u64;
            let mut next = || {
                state = crate::sequence::hash64(state);
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            for _ in 0..20_000 {
                let d = crate::warp::square_to_uniform_sphere(DVec2::new(next(), next()));
                let (a, b) = (m.texel_index(d), m.texel_index_by_uv(d));
                if a != b {
                    let uv = m.direction_to_uv(d);
                    let (fu, fv) = (uv.x * w as f64, uv.y * h as f64);
                    let edge = |x: f64| (x - x.round()).abs() < 1e-9;
                    assert!(edge(fu) || edge(fv), "{w}x{h} {d}: {a:?} vs {b:?}");
                }
            }
            // Poles, the seam and the axes.
            for d in [
                DVec3::Y,
                -DVec3::Y,
                DVec3::X,
                -DVec3::X,
                DVec3::Z,
                -DVec3::Z,
            ] {
                let (i, j) = m.texel_index(d);
                assert!(i < w && j < h);
            }
        }
    }

    /// The built-in sky at 64 × 32 through `EnvMap::new`, scaled by 1.5
    /// and rotated by 33°.
    fn scaled_sky() -> EnvMap {
        let texels = EnvMap::sky(64, 32, 30.0, 40.0)
            .texels
            .iter()
            .map(|t| t.rgb())
            .collect();
        EnvMap::new(64, 32, texels, 1.5, 33.0).unwrap().0
    }

    /// The block forms give the single calls' values, bit for bit (over
    /// more than two chunks, with both distributions).
    #[test]
    fn the_many_lookups_are_the_single_ones() {
        let m = scaled_sky();
        let n = 150;
        let u = |k: usize| {
            let a = crate::sequence::hash64(k as u64);
            DVec2::new(
                (a >> 40) as f64 / (1u64 << 24) as f64,
                (a & 0xffffff) as f64 / (1u64 << 24) as f64,
            )
        };
        let draws: Vec<(bool, DVec2)> = (0..n).map(|k| (k % 3 == 0, u(k))).collect();
        let mut got = vec![None; n];
        m.sample_lookup_many(&draws, &mut got);
        for (k, &(c, uk)) in draws.iter().enumerate() {
            assert_eq!(got[k], m.sample_lookup(c, uk), "draw {k}");
        }
        // Lookups at every SIMD level, on maps of one texel, one column,
        // a few and many; the poles, the axes and the seam included.
        let mut dirs: Vec<DVec3> = (0..2000).map(|k| m.uv_to_direction(u(k + n))).collect();
        for d in [DVec3::X, DVec3::Y, DVec3::Z] {
            dirs.extend([d, -d]);
        }
        dirs.extend((0..100).map(|k| DVec3::new(-1e-9 * k as f64, 0.3, 1.0).normalize()));
        let one = EnvMap::new(1, 2, vec![Rgb::ONE, Rgb::splat(2.0)], 1.0, 0.0)
            .unwrap()
            .0;
        let few = EnvMap::new(
            3,
            2,
            (0..6).map(|k| Rgb::splat(k as f64)).collect(),
            1.0,
            -10.0,
        )
        .unwrap()
        .0;
        for map in [&m, &one, &few, &EnvMap::constant(Rgb::ONE)] {
            for level in SimdLevel::ALL.into_iter().filter(|l| l.is_available()) {
                let mut looked = vec![EnvLookup::default(); dirs.len()];
                map.lookup_many_at(level, &dirs, &mut looked);
                let mut radiance = vec![Rgb::ZERO; dirs.len()];
                map.eval_many_at(level, &dirs, &mut radiance);
                for (k, &d) in dirs.iter().enumerate() {
                    assert_eq!(looked[k], map.lookup(d), "{level:?} direction {k} {d}");
                    assert_eq!(radiance[k], map.eval(d), "{level:?} direction {k} {d}");
                }
            }
        }
    }

    /// `sample_lookup` draws inside the texel whose lookup it returns, that
    /// lookup is `lookup` of the direction, and it is `sample`'s
    /// distribution (the same texel for the same numbers).
    #[test]
    fn sample_lookup_agrees_with_sample_and_lookup() {
        let m = scaled_sky();
        for comp in [false, true] {
            for k in 0..2000 {
                let u = DVec2::new(
                    (k as f64 * 0.618_033_988_7 + 0.01) % 1.0,
                    (k as f64 * 0.414_213_562 + 0.02) % 1.0,
                );
                let (d, l) = m.sample_lookup(comp, u).unwrap();
                assert!((d.length() - 1.0).abs() < 1e-12);
                let (d0, p0) = if comp {
                    m.sample_compensated(u).unwrap()
                } else {
                    m.sample(u).unwrap()
                };
                assert!((d - d0).length() < 1e-9, "{d} {d0}");
                let p = if comp { l.pdf_compensated } else { l.pdf };
                assert!((p - p0).abs() <= 1e-12 * p0);
                assert_eq!(m.lookup(d), l);
                assert_eq!(l.radiance, m.eval(d));
                assert_eq!(l.pdf, m.pdf(d));
                assert_eq!(l.pdf_compensated, m.pdf_compensated(d));
            }
        }
    }
}
