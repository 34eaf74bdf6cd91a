//! The array engine behind `lobe.Material`: blocks of inputs in any dtype
//! (f32 or f64) and any memory order, checked, run on the batch SIMD
//! kernels of [`lobe::batch`] where they cover the material and strategy and
//! on the scalar f64 path otherwise, split over rayon's threads in fixed
//! blocks of [`BLOCK`] samples.
//!
//! Pure Rust (no Python): the bindings (`py.rs`) only turn NumPy arrays into
//! the views of this module and back.
//!
//! Conventions (the library's): local shading frame, `+z` the normal; `wo`
//! toward the viewer, `wi` toward the light, unit, away from the surface;
//! `f` is `f_r` **without** the cosine; pdfs are solid-angle densities;
//! `weight = f · cos θi / pdf`; a failed sample is `valid = false` with
//! every other output 0.

use glam::{DVec2, DVec3};
use lobe::batch::{
    BatchSampler, Dirs, DirsMut, EvalPdfOutput, RgbMut, SampleInput, SampleOutput, Store,
};
use lobe::{BsdfSampler, BsdfStrategy, Material};
use ndarray::{ArrayView1, ArrayView2, Axis};
use rayon::prelude::*;

/// Samples per block: every block is one call of the batch kernels, whose
/// scratch stays in the caches. Blocks are independent, so the results do
/// not depend on the thread count.
pub const BLOCK: usize = 4096;

/// Largest accepted `|‖w‖² − 1|` of an input direction.
pub const UNIT_TOLERANCE: f64 = 1e-4;

/// An `(N, 3)` (or `(N, 2)`) input in f32 or f64, any strides.
#[derive(Debug, Clone)]
pub enum In2<'a> {
    F32(ArrayView2<'a, f32>),
    F64(ArrayView2<'a, f64>),
}

/// An `(N,)` input in f32 or f64, any stride.
#[derive(Debug, Clone)]
pub enum In1<'a> {
    F32(ArrayView1<'a, f32>),
    F64(ArrayView1<'a, f64>),
}

impl In2<'_> {
    #[must_use]
    pub fn rows(&self) -> usize {
        match self {
            In2::F32(a) => a.nrows(),
            In2::F64(a) => a.nrows(),
        }
    }
    #[must_use]
    pub fn cols(&self) -> usize {
        match self {
            In2::F32(a) => a.ncols(),
            In2::F64(a) => a.ncols(),
        }
    }
}

impl In1<'_> {
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            In1::F32(a) => a.len(),
            In1::F64(a) => a.len(),
        }
    }
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// An input value that is wrong: which array, which row (and column), and
/// what is wrong, in words.
#[derive(Debug, Clone, PartialEq)]
pub struct BadInput {
    pub row: usize,
    pub message: String,
}

impl std::fmt::Display for BadInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// A float type the engine computes in: f32 (the batch kernels) or f64
/// (the scalar reference).
pub trait Real:
    Copy + Send + Sync + Default + PartialOrd + std::ops::Sub<Output = Self> + 'static
{
    /// `a² + b² + c²`.
    fn mul_add3(a: Self, b: Self, c: Self) -> Self;
    fn neg(self) -> Self;
    /// The shortest text that reads back as this value.
    fn show(self) -> String;
    fn from_f32(x: f32) -> Self;
    fn from_f64(x: f64) -> Self;
    fn to_f64(self) -> f64;
    /// The largest value below one.
    const BELOW_ONE: Self;
    /// The contiguous part `r` of column `c` when the source has this type.
    fn column<'a>(src: &'a In2<'_>, c: usize, r: std::ops::Range<usize>) -> Option<&'a [Self]>;
    fn column1<'a>(src: &'a In1<'_>, r: std::ops::Range<usize>) -> Option<&'a [Self]>;
}

impl Real for f32 {
    fn mul_add3(a: f32, b: f32, c: f32) -> f32 {
        a * a + b * b + c * c
    }
    fn neg(self) -> f32 {
        -self
    }
    fn show(self) -> String {
        self.to_string()
    }
    fn from_f32(x: f32) -> Self {
        x
    }
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;
    fn column<'a>(src: &'a In2<'_>, c: usize, r: std::ops::Range<usize>) -> Option<&'a [f32]> {
        match src {
            In2::F32(a) => column_slice(a, c, r),
            In2::F64(_) => None,
        }
    }
    fn column1<'a>(src: &'a In1<'_>, r: std::ops::Range<usize>) -> Option<&'a [f32]> {
        match src {
            In1::F32(a) => slice1(a, r),
            In1::F64(_) => None,
        }
    }
}

impl Real for f64 {
    fn mul_add3(a: f64, b: f64, c: f64) -> f64 {
        a * a + b * b + c * c
    }
    fn neg(self) -> f64 {
        -self
    }
    fn show(self) -> String {
        self.to_string()
    }
    fn from_f32(x: f32) -> Self {
        f64::from(x)
    }
    fn from_f64(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;
    fn column<'a>(src: &'a In2<'_>, c: usize, r: std::ops::Range<usize>) -> Option<&'a [f64]> {
        match src {
            In2::F64(a) => column_slice(a, c, r),
            In2::F32(_) => None,
        }
    }
    fn column1<'a>(src: &'a In1<'_>, r: std::ops::Range<usize>) -> Option<&'a [f64]> {
        match src {
            In1::F64(a) => slice1(a, r),
            In1::F32(_) => None,
        }
    }
}

fn column_slice<'a, T>(
    a: &'a ArrayView2<'_, T>,
    c: usize,
    r: std::ops::Range<usize>,
) -> Option<&'a [T]> {
    // A column is contiguous when the row stride is 1 (Fortran order).
    if a.strides()[0] != 1 || a.nrows() == 0 {
        return None;
    }
    let col = a.index_axis(Axis(1), c);
    let ptr = col.as_ptr();
    // SAFETY: the column has `nrows` elements at stride 1 starting at `ptr`,
    // borrowed from `a` for 'a; `r` is within `0..nrows` (checked).
    if r.end > a.nrows() {
        return None;
    }
    Some(unsafe { std::slice::from_raw_parts(ptr.add(r.start), r.len()) })
}

fn slice1<'a, T>(a: &'a ArrayView1<'_, T>, r: std::ops::Range<usize>) -> Option<&'a [T]> {
    if r.end > a.len() {
        return None;
    }
    if a.strides()[0] == 1 || a.len() <= 1 {
        let ptr = a.as_ptr();
        // SAFETY: stride 1, `r` within the length, borrowed for 'a.
        return Some(unsafe { std::slice::from_raw_parts(ptr.add(r.start), r.len()) });
    }
    None
}

/// Reads rows `r` of column `c` of `src` as `T` into `buf` (unless the
/// source already is a contiguous `T` column) and returns the slice.
fn load_col<'a, T: Real>(
    src: &'a In2<'_>,
    c: usize,
    r: std::ops::Range<usize>,
    buf: &'a mut Vec<T>,
) -> &'a [T] {
    if let Some(s) = T::column(src, c, r.clone()) {
        return s;
    }
    buf.clear();
    match src {
        In2::F32(a) => buf.extend(a.slice(ndarray::s![r, c]).iter().map(|&x| T::from_f32(x))),
        In2::F64(a) => buf.extend(a.slice(ndarray::s![r, c]).iter().map(|&x| T::from_f64(x))),
    }
    buf
}

fn load_1<'a, T: Real>(
    src: &'a In1<'_>,
    r: std::ops::Range<usize>,
    buf: &'a mut Vec<T>,
) -> &'a [T] {
    if let Some(s) = T::column1(src, r.clone()) {
        return s;
    }
    buf.clear();
    match src {
        In1::F32(a) => buf.extend(a.slice(ndarray::s![r]).iter().map(|&x| T::from_f32(x))),
        In1::F64(a) => buf.extend(a.slice(ndarray::s![r]).iter().map(|&x| T::from_f64(x))),
    }
    buf
}

/// Runs `f` compiled for AVX-512 or else AVX2 + FMA where the CPU has
/// them, so that the checks and copies around the kernels (loops the
/// compiler vectorizes) run 16 or 8 lanes wide instead of the x86-64
/// baseline's 4; the same values at any width (comparisons and IEEE
/// arithmetic only).
#[inline(always)]
fn wide<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2,fma")]
        fn avx2<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,fma")]
        fn avx512<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        if is_x86_feature_detected!("avx512f")
            && is_x86_feature_detected!("avx512bw")
            && is_x86_feature_detected!("avx512vl")
            && is_x86_feature_detected!("avx512dq")
        {
            // SAFETY: the CPU has these AVX-512 subsets (checked just above).
            return unsafe { avx512(f) };
        }
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has AVX2 and FMA (checked just above).
            return unsafe { avx2(f) };
        }
    }
    f()
}

/// Whether every `(x, y, z)` is unit within `tol` (or, with `zero_ok`,
/// zero), and whether any is zero: one branch-free pass.
#[inline(always)]
fn unit_or_zero<T: Real>(
    x: &[T],
    y: &[T],
    z: &[T],
    tol: T,
    one: T,
    zero: T,
    zero_ok: bool,
) -> (bool, bool) {
    x.iter()
        .zip(y)
        .zip(z)
        .fold((true, false), |(ok, zs), ((&a, &b), &c)| {
            let n2 = T::mul_add3(a, b, c);
            let d = n2 - one;
            let is_zero = zero_ok & (n2 == zero);
            (
                ok & (((d <= tol) & (d >= T::neg(tol))) | is_zero),
                zs | is_zero,
            )
        })
}

/// Whether every value is in `[0, 1)`: one branch-free pass.
#[inline(always)]
fn in_unit_interval<T: Real>(v: &[T], zero: T, one: T) -> bool {
    v.iter().fold(true, |ok, &x| ok & (x >= zero) & (x < one))
}

/// Checks a block of directions (rows from `start`): finite and unit.
fn check_dirs<T: Real>(
    name: &str,
    x: &[T],
    y: &[T],
    z: &[T],
    start: usize,
    zero_ok: bool,
) -> Result<bool, BadInput> {
    // The common case first, in one branch-free (vectorizable) pass: every
    // direction unit, or (where allowed) the zero vector of a failed sample.
    let tol = T::from_f64(UNIT_TOLERANCE);
    let one = T::from_f64(1.0);
    let zero = T::from_f64(0.0);
    let (all_ok, any_zero) = wide(|| unit_or_zero(x, y, z, tol, one, zero, zero_ok));
    if all_ok {
        return Ok(any_zero);
    }
    let mut zeros = false;
    for i in 0..x.len() {
        let (a, b, c) = (x[i].to_f64(), y[i].to_f64(), z[i].to_f64());
        let n2 = a * a + b * b + c * c;
        if zero_ok && n2 == 0.0 {
            zeros = true;
            continue;
        }
        // NaN fails the comparison.
        // NaN fails `is_some_and`.
        if !(n2 - 1.0)
            .abs()
            .partial_cmp(&UNIT_TOLERANCE)
            .is_some_and(|o| o.is_le())
        {
            let row = start + i;
            let what = if !(a.is_finite() && b.is_finite() && c.is_finite()) {
                "is not finite".to_string()
            } else {
                format!(
                    "is not a unit vector (length {:.6}); directions must be unit vectors in the local frame (+z the normal)",
                    n2.sqrt()
                )
            };
            return Err(BadInput {
                row,
                message: format!(
                    "{name}[{row}] = ({}, {}, {}) {what}",
                    x[i].show(),
                    y[i].show(),
                    z[i].show()
                ),
            });
        }
    }
    Ok(zeros)
}

/// `w` (unit within [`UNIT_TOLERANCE`], as checked) for the f64 reference
/// path: as given where the core takes it as unit (`1e-6` in `|w|²`,
/// [`lobe::math::is_unit`]), so that the reference computes on the very
/// vector the batch kernels get (an f32 direction is not unit to f64
/// precision; where `wi ≈ −wo` at grazing angles the result depends on
/// that length); normalized otherwise. (The CLI's f64 path normalizes
/// anything further than 4 ulp from unit.)
fn unit(w: DVec3) -> DVec3 {
    if lobe::math::is_unit(w) {
        w
    } else {
        w.normalize()
    }
}

/// Checks a block of uniforms: in `[0, 1]`; returns them with 1 moved to
/// the largest value below one (an f64 just below one rounds to 1 in f32).
fn check_uniform<'a, T: Real>(
    name: &str,
    v: &'a [T],
    start: usize,
    buf: &'a mut Vec<T>,
) -> Result<&'a [T], BadInput> {
    let (zero, one) = (T::from_f64(0.0), T::from_f64(1.0));
    if wide(|| in_unit_interval(v, zero, one)) {
        return Ok(v);
    }
    let mut has_one = false;
    for (i, &x) in v.iter().enumerate() {
        let f = x.to_f64();
        if !(0.0..=1.0).contains(&f) {
            let row = start + i;
            return Err(BadInput {
                row,
                message: format!(
                    "{name}[{row}] = {} is not a uniform number in [0, 1)",
                    x.show()
                ),
            });
        }
        has_one |= f == 1.0;
    }
    if !has_one {
        return Ok(v);
    }
    buf.clear();
    buf.extend(
        v.iter()
            .map(|&x| if x.to_f64() == 1.0 { T::BELOW_ONE } else { x }),
    );
    Ok(buf)
}

/// How one call runs.
#[derive(Debug, Clone)]
pub struct Engine<'m> {
    pub material: &'m Material,
    /// The strategy, resolved for the material (the scalar f64 path).
    pub sampler: BsdfSampler<'m>,
    /// The batch kernels, where they cover the material and strategy.
    pub batch: Option<BatchSampler>,
}

impl<'m> Engine<'m> {
    /// For `material` and `strategy` (checked: an error says why the strategy
    /// does not apply). `reference` forces the scalar f64 path.
    pub fn new(
        material: &'m Material,
        strategy: BsdfStrategy,
        reference: bool,
    ) -> Result<Self, lobe::Error> {
        let sampler = material.sampler(strategy)?;
        let batch = if reference {
            None
        } else {
            BatchSampler::new(material, strategy).ok()
        };
        Ok(Engine {
            material,
            sampler,
            batch,
        })
    }

    /// For `eval` alone (no strategy): the batch kernels of the first
    /// strategy they cover (`f` does not depend on the strategy; the
    /// kernels of different strategies compute it along different f32
    /// paths, which agree within about 1e-6 relative, not bit for bit),
    /// else the scalar path (`strategy` is then only a placeholder).
    #[must_use]
    pub fn for_eval(material: &'m Material, reference: bool) -> Self {
        let strategies = material.strategies();
        if !reference {
            for &s in &strategies {
                if let (Ok(b), Ok(sampler)) = (BatchSampler::new(material, s), material.sampler(s))
                {
                    return Engine {
                        material,
                        sampler,
                        batch: Some(b),
                    };
                }
            }
        }
        let first = strategies.first().copied().unwrap_or(BsdfStrategy::Uniform);
        Engine {
            material,
            sampler: material
                .sampler(first)
                .expect("a strategy of the material's own list applies to it"),
            batch: None,
        }
    }
}

/// The outputs of [`sample`], Fortran order for the `(N, 3)` ones (each
/// component contiguous: `wi[c * n + i]`); `valid` is 1 or 0.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleOut<T> {
    pub n: usize,
    pub wi: Vec<T>,
    pub pdf: Vec<T>,
    pub weight: Vec<T>,
    pub valid: Vec<u8>,
}

/// The outputs of [`eval_pdf`]: `f` in Fortran order, `pdf`.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalPdfOut<T> {
    pub n: usize,
    pub f: Vec<T>,
    pub pdf: Vec<T>,
}

/// What [`eval_pdf`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Want {
    Eval,
    Pdf,
    Both,
}

/// `n` zeros, from fresh zeroed pages where the allocator maps them, which
/// are advised to be huge pages before the first touch (fewer page faults
/// when the blocks fill them).
fn zeros<T: Copy + Default>(n: usize) -> Vec<T> {
    let v = vec![T::default(); n];
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let bytes = n * std::mem::size_of::<T>();
        if bytes >= 2 * HUGE {
            let start = v.as_ptr() as usize;
            let first = start.next_multiple_of(HUGE);
            let end = (start + bytes) / HUGE * HUGE;
            if end > first {
                // SAFETY: advice on whole pages inside the allocation; it does
                // not change the contents (zero), only how they are mapped.
                unsafe {
                    libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
                }
            }
        }
    }
    v
}

/// Memory for `n` outputs: a kept buffer of a previous result (see
/// [`crate::pool`]; it holds old values, and every caller here writes all
/// of them), else [`zeros`].
fn fresh<T: crate::pool::Element>(n: usize) -> Vec<T> {
    crate::pool::take(n).unwrap_or_else(|| zeros(n))
}

/// Where the blocks of `n` values start, and the first block's length:
/// `head` values (when `0 < head < n`), then [`BLOCK`] at a time.
#[derive(Debug, Clone, Copy)]
struct Cuts {
    n: usize,
    head: usize,
}

impl Cuts {
    /// Blocks over `n` values whose later blocks start 64-byte aligned in
    /// an array at `p` (so that the kernels' streaming stores apply: large
    /// NumPy and Rust allocations start 16 bytes past a page). Results do
    /// not depend on where the blocks are cut.
    fn aligned<T>(n: usize, p: *const T) -> Cuts {
        let a = p.align_offset(64);
        let head = if a < BLOCK.min(n) { a } else { 0 };
        Cuts { n, head }
    }

    /// The block lengths, in order.
    fn lengths(self) -> impl Iterator<Item = usize> {
        let rest = self.n - self.head;
        (self.head > 0)
            .then_some(self.head)
            .into_iter()
            .chain((0..rest.div_ceil(BLOCK)).map(move |k| BLOCK.min(rest - k * BLOCK)))
    }

    /// `v` (of `n` values) cut into the blocks.
    fn split<T>(self, mut v: &mut [T]) -> Vec<&mut [T]> {
        debug_assert_eq!(v.len(), self.n);
        let mut parts = Vec::new();
        for len in self.lengths() {
            let (a, b) = std::mem::take(&mut v).split_at_mut(len);
            parts.push(a);
            v = b;
        }
        parts
    }

    /// Three component vectors of length `n` (Fortran order `3n`) cut into
    /// the blocks.
    fn split3<T>(self, v: &mut [T]) -> Vec<[&mut [T]; 3]> {
        let (a, rest) = v.split_at_mut(self.n);
        let (b, c) = rest.split_at_mut(self.n);
        self.split(a)
            .into_iter()
            .zip(self.split(b))
            .zip(self.split(c))
            .map(|((a, b), c)| [a, b, c])
            .collect()
    }

    /// Where each block starts.
    fn starts(self) -> Vec<usize> {
        self.lengths()
            .scan(0, |s, len| {
                let start = *s;
                *s += len;
                Some(start)
            })
            .collect()
    }
}

/// The first error of the blocks (lowest row).
fn first_error(errors: impl Iterator<Item = Result<(), BadInput>>) -> Result<(), BadInput> {
    let mut worst: Option<BadInput> = None;
    for e in errors {
        if let Err(e) = e
            && worst.as_ref().is_none_or(|w| e.row < w.row)
        {
            worst = Some(e);
        }
    }
    worst.map_or(Ok(()), Err)
}

/// Per-thread scratch of the batch path.
struct Scratch32 {
    wo: [Vec<f32>; 3],
    wi: [Vec<f32>; 3],
    u: [Vec<f32>; 3],
    fix: [Vec<f32>; 3],
}

impl Scratch32 {
    fn new() -> Self {
        let v = || Vec::with_capacity(BLOCK);
        Scratch32 {
            wo: [v(), v(), v()],
            wi: [v(), v(), v()],
            u: [v(), v(), v()],
            fix: [v(), v(), v()],
        }
    }
}

/// Calls of at least this many samples write their results with streaming
/// stores ([`Store::Streamed`]); smaller ones through the caches, where
/// their results may still be when the caller reads them. Measured on an
/// Intel Xeon with AVX-512 (4 MiB of L2 a core), `eval_pdf` of GGX vndf on
/// one thread, ns a sample, streamed / cached: 2¹⁴ samples 6.8 / 3.6, 2¹⁶
/// 5.0 / 2.8, 2¹⁷ to 2²⁰ the same within 2%, 2²² 4.1 / 4.7.
pub const STREAM_MIN: usize = 1 << 17;

/// How a call of `n` samples stores its results (see [`STREAM_MIN`]).
fn out_store(n: usize) -> Store {
    if n >= STREAM_MIN {
        Store::Streamed
    } else {
        Store::Cached
    }
}

/// One block of sample outputs.
type SampleBlock<'a, T> = (
    usize,
    [&'a mut [T]; 3],
    [&'a mut [T]; 3],
    &'a mut [T],
    &'a mut [u8],
);

/// Caller-owned outputs of [`sample32_into`]: `wi` and `weight` in
/// Fortran order (`3n`), `pdf` and `valid` (`n`).
#[derive(Debug)]
pub struct SampleSlices<'a, T> {
    pub n: usize,
    pub wi: &'a mut [T],
    pub pdf: &'a mut [T],
    pub weight: &'a mut [T],
    pub valid: &'a mut [u8],
}

impl<T> SampleOut<T> {
    /// The outputs as slices.
    pub fn slices(&mut self) -> SampleSlices<'_, T> {
        SampleSlices {
            n: self.n,
            wi: &mut self.wi,
            pdf: &mut self.pdf,
            weight: &mut self.weight,
            valid: &mut self.valid,
        }
    }
}

fn sample_blocks<'a, T>(out: SampleSlices<'a, T>) -> Vec<SampleBlock<'a, T>> {
    let n = out.n;
    assert!(
        out.wi.len() == 3 * n
            && out.weight.len() == 3 * n
            && out.pdf.len() == n
            && out.valid.len() == n
    );
    let cuts = Cuts::aligned(n, out.wi.as_ptr());
    cuts.split3(out.wi)
        .into_iter()
        .zip(cuts.split3(out.weight))
        .zip(cuts.split(out.pdf).into_iter().zip(cuts.split(out.valid)))
        .zip(cuts.starts())
        .map(|(((wi, w), (pdf, valid)), start)| (start, wi, w, pdf, valid))
        .collect()
}

fn new_sample_out<T: crate::pool::Element>(n: usize) -> SampleOut<T> {
    SampleOut {
        n,
        wi: fresh(3 * n),
        pdf: fresh(n),
        weight: fresh(3 * n),
        valid: fresh(n),
    }
}

/// Sample `wi` for each `(wo[i], u[i], uc[i])`: on the batch kernels where
/// the engine has them (f32), else on the scalar f64 path with `T` outputs.
/// `wo` is `(N, 3)`, `u` `(N, 2)`, `uc` `(N,)` or absent (then 0.5; it only
/// matters where the material chooses between two lobes, where the caller
/// must give it).
pub fn sample32(
    e: &Engine<'_>,
    wo: &In2<'_>,
    u: &In2<'_>,
    uc: Option<&In1<'_>>,
) -> Result<SampleOut<f32>, BadInput> {
    let mut out = new_sample_out::<f32>(wo.rows());
    sample32_into(e, wo, u, uc, out.slices())?;
    Ok(out)
}

/// [`sample32`] into caller-owned outputs of `wo.rows()` samples (on an
/// error their contents are unspecified).
pub fn sample32_into(
    e: &Engine<'_>,
    wo: &In2<'_>,
    u: &In2<'_>,
    uc: Option<&In1<'_>>,
    out: SampleSlices<'_, f32>,
) -> Result<(), BadInput> {
    let Some(b) = &e.batch else {
        return sample_scalar_into::<f32>(e, wo, u, uc, out);
    };
    let n = wo.rows();
    debug_assert!(u.rows() == n && uc.is_none_or(|c| c.len() == n) && out.n == n);
    let results: Vec<Result<(), BadInput>> = sample_blocks(out)
        .into_par_iter()
        .map_init(Scratch32::new, |s, (start, wi, w, pdf, valid)| {
            let r = start..start + pdf.len();
            let Scratch32 {
                wo: wb, u: ub, fix, ..
            } = s;
            let [wx, wy, wz] = wi;
            let [wr, wg, wb2] = w;
            let [b0, b1, b2] = wb;
            let (x, y, z) = (
                load_col::<f32>(wo, 0, r.clone(), b0),
                load_col::<f32>(wo, 1, r.clone(), b1),
                load_col::<f32>(wo, 2, r.clone(), b2),
            );
            let [ub0, ub1, ub2] = ub;
            let u1raw = load_col::<f32>(u, 0, r.clone(), ub0);
            let u2raw = load_col::<f32>(u, 1, r.clone(), ub1);
            let ucraw = uc.map(|c| load_1::<f32>(c, r.clone(), ub2));
            // Straight into the caller's arrays, with streaming stores in
            // a large call ([`STREAM_MIN`]): interleaved with the
            // arithmetic, so the writes overlap it (a copy from scratch
            // afterwards was a burst of writes the core waited for). `f`,
            // which `Material.sample` does not return, not at all.
            let mut run = |u1: &[f32], u2: &[f32], uc: Option<&[f32]>| {
                b.sample_with(
                    SampleInput {
                        wo: Dirs { x, y, z },
                        u1,
                        u2,
                        uc,
                    },
                    SampleOutput {
                        wi: DirsMut {
                            x: &mut *wx,
                            y: &mut *wy,
                            z: &mut *wz,
                        },
                        f: RgbMut {
                            r: &mut [],
                            g: &mut [],
                            b: &mut [],
                        },
                        pdf: &mut *pdf,
                        weight: RgbMut {
                            r: &mut *wr,
                            g: &mut *wg,
                            b: &mut *wb2,
                        },
                        valid: &mut *valid,
                    },
                    out_store(n),
                )
                .expect("every block slice has the block's length");
            };
            // The kernel first, on the inputs as given: it reads them from
            // memory interleaved with its arithmetic, which hides the
            // latency; the checks then read them from the cache. The
            // kernels are plain arithmetic on any f32 (no panic on bad
            // values); where a check fails, the call raises and its
            // outputs are not returned (with `out=`, their contents are
            // unspecified, as documented).
            run(u1raw, u2raw, ucraw);
            check_dirs("wo", x, y, z, start, false)?;
            let [f0, f1, f2] = fix;
            let u1 = check_uniform("u", u1raw, start, f0)?;
            let u2 = check_uniform("u", u2raw, start, f1)?;
            let ucs = match ucraw {
                Some(c) => Some(check_uniform("uc", c, start, f2)?),
                None => None,
            };
            // A 1 moved below one (see `check_uniform`): again, on the fixed values.
            let moved = |a: &[f32], b: &[f32]| !std::ptr::eq(a.as_ptr(), b.as_ptr());
            if moved(u1, u1raw)
                || moved(u2, u2raw)
                || ucs.zip(ucraw).is_some_and(|(a, b)| moved(a, b))
            {
                run(u1, u2, ucs);
            }
            Ok(())
        })
        .collect();
    first_error(results.into_iter())
}

/// [`sample32`] on the scalar f64 path, outputs in `T`.
pub fn sample_scalar<T: Real + crate::pool::Element>(
    e: &Engine<'_>,
    wo: &In2<'_>,
    u: &In2<'_>,
    uc: Option<&In1<'_>>,
) -> Result<SampleOut<T>, BadInput> {
    let mut out = new_sample_out::<T>(wo.rows());
    sample_scalar_into(e, wo, u, uc, out.slices())?;
    Ok(out)
}

/// [`sample_scalar`] into caller-owned outputs.
pub fn sample_scalar_into<T: Real>(
    e: &Engine<'_>,
    wo: &In2<'_>,
    u: &In2<'_>,
    uc: Option<&In1<'_>>,
    out: SampleSlices<'_, T>,
) -> Result<(), BadInput> {
    let n = wo.rows();
    debug_assert!(u.rows() == n && uc.is_none_or(|c| c.len() == n) && out.n == n);
    let sampler = e.sampler;
    let results: Vec<Result<(), BadInput>> = sample_blocks(out)
        .into_par_iter()
        .map_init(
            || [(); 8].map(|()| Vec::<f64>::with_capacity(BLOCK)),
            |s, (start, wi, w, pdf, valid)| {
                let r = start..start + pdf.len();
                let [b0, b1, b2, b3, b4, b5, f0, f1] = s;
                let (x, y, z) = (
                    load_col::<f64>(wo, 0, r.clone(), b0),
                    load_col::<f64>(wo, 1, r.clone(), b1),
                    load_col::<f64>(wo, 2, r.clone(), b2),
                );
                check_dirs("wo", x, y, z, start, false)?;
                let u1 = check_uniform("u", load_col::<f64>(u, 0, r.clone(), b3), start, f0)?;
                let u2 = check_uniform("u", load_col::<f64>(u, 1, r.clone(), b4), start, f1)?;
                let ucs = match uc {
                    Some(c) => {
                        let v = load_1::<f64>(c, r.clone(), b5);
                        let mut tmp = Vec::new();
                        Some(check_uniform("uc", v, start, &mut tmp)?.to_vec())
                    }
                    None => None,
                };
                for i in 0..pdf.len() {
                    let wo = unit(DVec3::new(x[i], y[i], z[i]));
                    let ucv = ucs.as_ref().map_or(0.5, |c| c[i]);
                    let s = sampler.sample(wo, ucv, DVec2::new(u1[i], u2[i]));
                    // A failed sample: zeros.
                    let (v_wi, v_weight, v_pdf) = s
                        .map_or((DVec3::ZERO, lobe::Rgb::ZERO, 0.0), |v| {
                            (v.wi, v.weight, v.pdf)
                        });
                    for c in 0..3 {
                        wi[c][i] = T::from_f64(v_wi[c]);
                        w[c][i] = T::from_f64(v_weight[c]);
                    }
                    pdf[i] = T::from_f64(v_pdf);
                    valid[i] = u8::from(s.is_some());
                }
                Ok(())
            },
        )
        .collect();
    first_error(results.into_iter())
}

/// One block of eval_pdf outputs (`None`: not wanted).
type EvalBlock<'a, T> = (usize, usize, Option<[&'a mut [T]; 3]>, Option<&'a mut [T]>);

/// Caller-owned outputs of [`eval_pdf32_into`]: `f` in Fortran order
/// (`3n`, or empty when not wanted), `pdf` (`n`, or empty).
#[derive(Debug)]
pub struct EvalSlices<'a, T> {
    pub n: usize,
    pub f: &'a mut [T],
    pub pdf: &'a mut [T],
}

impl<T> EvalPdfOut<T> {
    pub fn slices(&mut self) -> EvalSlices<'_, T> {
        EvalSlices {
            n: self.n,
            f: &mut self.f,
            pdf: &mut self.pdf,
        }
    }
}

fn eval_blocks<'a, T>(out: EvalSlices<'a, T>) -> Vec<EvalBlock<'a, T>> {
    let n = out.n;
    assert!(
        (out.f.is_empty() || out.f.len() == 3 * n) && (out.pdf.is_empty() || out.pdf.len() == n)
    );
    let cuts = if out.f.is_empty() {
        Cuts::aligned(n, out.pdf.as_ptr())
    } else {
        Cuts::aligned(n, out.f.as_ptr())
    };
    let starts = cuts.starts();
    let nblocks = starts.len();
    let fblocks: Vec<Option<[&mut [T]; 3]>> = if out.f.is_empty() {
        (0..nblocks).map(|_| None).collect()
    } else {
        cuts.split3(out.f).into_iter().map(Some).collect()
    };
    let pblocks: Vec<Option<&mut [T]>> = if out.pdf.is_empty() {
        (0..nblocks).map(|_| None).collect()
    } else {
        cuts.split(out.pdf).into_iter().map(Some).collect()
    };
    fblocks
        .into_iter()
        .zip(pblocks)
        .zip(cuts.lengths().zip(starts))
        .map(|((f, p), (len, start))| (start, start + len, f, p))
        .collect()
}

fn new_eval_out<T: crate::pool::Element>(n: usize, want: Want) -> EvalPdfOut<T> {
    EvalPdfOut {
        n,
        f: if want != Want::Pdf {
            fresh(3 * n)
        } else {
            Vec::new()
        },
        pdf: if want != Want::Eval {
            fresh(n)
        } else {
            Vec::new()
        },
    }
}

/// `f` (no cosine) and/or the pdf (solid angle, of the engine's strategy)
/// for each `(wo[i], wi[i])`, zero below the horizon and for a zero `wi`
/// (a failed sample's): on the batch kernels where the engine has them,
/// else the scalar f64 path. Outputs not wanted are left empty.
pub fn eval_pdf32(
    e: &Engine<'_>,
    wo: &In2<'_>,
    wi: &In2<'_>,
    want: Want,
) -> Result<EvalPdfOut<f32>, BadInput> {
    let mut out = new_eval_out::<f32>(wo.rows(), want);
    eval_pdf32_into(e, wo, wi, out.slices())?;
    Ok(out)
}

/// [`eval_pdf32`] into caller-owned outputs (an empty `f` or `pdf`: not wanted).
pub fn eval_pdf32_into(
    e: &Engine<'_>,
    wo: &In2<'_>,
    wi: &In2<'_>,
    out: EvalSlices<'_, f32>,
) -> Result<(), BadInput> {
    let Some(b) = &e.batch else {
        return eval_pdf_scalar_into::<f32>(e, wo, wi, out);
    };
    let n = wo.rows();
    debug_assert!(wi.rows() == n && out.n == n);
    let results: Vec<Result<(), BadInput>> = eval_blocks(out)
        .into_par_iter()
        .map_init(Scratch32::new, |s, (start, end, f, p)| {
            let r = start..end;
            let len = r.len();
            let Scratch32 { wo: wb, wi: ib, .. } = s;
            let [b0, b1, b2] = wb;
            let wo3 = Dirs {
                x: load_col::<f32>(wo, 0, r.clone(), b0),
                y: load_col::<f32>(wo, 1, r.clone(), b1),
                z: load_col::<f32>(wo, 2, r.clone(), b2),
            };
            let [i0, i1, i2] = ib;
            let wi3 = Dirs {
                x: load_col::<f32>(wi, 0, r.clone(), i0),
                y: load_col::<f32>(wi, 1, r.clone(), i1),
                z: load_col::<f32>(wi, 2, r.clone(), i2),
            };
            // Straight into the caller's arrays (streamed in a large call,
            // as in `sample32_into`), then the checks; what the caller did
            // not ask for is not written at all.
            let (mut f, mut p) = (f, p);
            let ran = match (&mut f, &mut p) {
                (Some([dr, dg, db]), Some(dp)) => b.eval_pdf_with(
                    wo3,
                    wi3,
                    EvalPdfOutput {
                        f: RgbMut {
                            r: dr,
                            g: dg,
                            b: db,
                        },
                        pdf: dp,
                    },
                    out_store(n),
                ),
                (Some([dr, dg, db]), None) => b.eval_with(
                    wo3,
                    wi3,
                    RgbMut {
                        r: dr,
                        g: dg,
                        b: db,
                    },
                    out_store(n),
                ),
                (None, Some(dp)) => b.pdf_with(wo3, wi3, dp, out_store(n)),
                (None, None) => Ok(()),
            };
            ran.expect("every block slice has the block's length");
            check_dirs("wo", wo3.x, wo3.y, wo3.z, start, false)?;
            let zeros = check_dirs("wi", wi3.x, wi3.y, wi3.z, start, true)?;
            // A failed sample's wi (the zero vector): no direction, zero
            // (rare: a plain pass over the block where there is one).
            if zeros {
                for i in 0..len {
                    if wi3.x[i] == 0.0 && wi3.y[i] == 0.0 && wi3.z[i] == 0.0 {
                        if let Some(fs) = &mut f {
                            for c in fs.iter_mut() {
                                c[i] = 0.0;
                            }
                        }
                        if let Some(dp) = &mut p {
                            dp[i] = 0.0;
                        }
                    }
                }
            }
            Ok(())
        })
        .collect();
    first_error(results.into_iter())
}

/// [`eval_pdf32`] on the scalar f64 path, outputs in `T`.
pub fn eval_pdf_scalar<T: Real + crate::pool::Element>(
    e: &Engine<'_>,
    wo: &In2<'_>,
    wi: &In2<'_>,
    want: Want,
) -> Result<EvalPdfOut<T>, BadInput> {
    let mut out = new_eval_out::<T>(wo.rows(), want);
    eval_pdf_scalar_into(e, wo, wi, out.slices())?;
    Ok(out)
}

/// [`eval_pdf_scalar`] into caller-owned outputs.
pub fn eval_pdf_scalar_into<T: Real>(
    e: &Engine<'_>,
    wo: &In2<'_>,
    wi: &In2<'_>,
    out: EvalSlices<'_, T>,
) -> Result<(), BadInput> {
    let n = wo.rows();
    debug_assert!(wi.rows() == n && out.n == n);
    let want = match (out.f.is_empty() && n > 0, out.pdf.is_empty() && n > 0) {
        (true, _) => Want::Pdf,
        (_, true) => Want::Eval,
        _ => Want::Both,
    };
    let m = e.material;
    let sampler = e.sampler;
    let results: Vec<Result<(), BadInput>> = eval_blocks(out)
        .into_par_iter()
        .map_init(
            || [(); 6].map(|()| Vec::<f64>::with_capacity(BLOCK)),
            |s, (start, end, mut f, mut p)| {
                let r = start..end;
                let [b0, b1, b2, b3, b4, b5] = s;
                let (x, y, z) = (
                    load_col::<f64>(wo, 0, r.clone(), b0),
                    load_col::<f64>(wo, 1, r.clone(), b1),
                    load_col::<f64>(wo, 2, r.clone(), b2),
                );
                check_dirs("wo", x, y, z, start, false)?;
                let (ix, iy, iz) = (
                    load_col::<f64>(wi, 0, r.clone(), b3),
                    load_col::<f64>(wi, 1, r.clone(), b4),
                    load_col::<f64>(wi, 2, r.clone(), b5),
                );
                check_dirs("wi", ix, iy, iz, start, true)?;
                for i in 0..r.len() {
                    let a = unit(DVec3::new(x[i], y[i], z[i]));
                    let b = DVec3::new(ix[i], iy[i], iz[i]);
                    let (fv, pv) = if b == DVec3::ZERO {
                        (lobe::Rgb::ZERO, 0.0) // a failed sample's wi: zero
                    } else {
                        let b = unit(b);
                        match want {
                            Want::Eval => (m.eval(a, b), 0.0),
                            Want::Pdf => (lobe::Rgb::ZERO, sampler.pdf(a, b)),
                            Want::Both => sampler.eval_pdf(a, b),
                        }
                    };
                    if let Some(f) = f.as_mut() {
                        for c in 0..3 {
                            f[c][i] = T::from_f64(fv[c]);
                        }
                    }
                    if let Some(p) = p.as_mut() {
                        p[i] = T::from_f64(pv);
                    }
                }
                Ok(())
            },
        )
        .collect();
    first_error(results.into_iter())
}

#[cfg(test)]
mod tests {
    use super::*;
    use lobe::batch::SampleBuffers;
    use ndarray::{Array1, Array2, ShapeBuilder};

    fn ggx() -> Material {
        Material::load(r#"{"type":"cook-torrance","distribution":"ggx","alpha":0.2}"#).unwrap()
    }

    fn inputs(n: usize) -> (Array2<f64>, Array2<f64>) {
        let mut wo = Array2::<f64>::zeros((n, 3));
        let mut u = Array2::<f64>::zeros((n, 2));
        for i in 0..n {
            let t = 1.4 * (i as f64 + 0.5) / n as f64;
            let p = 0.37 * i as f64;
            wo.row_mut(i).assign(&Array1::from(vec![
                t.sin() * p.cos(),
                t.sin() * p.sin(),
                t.cos(),
            ]));
            u[[i, 0]] = ((i * 7919) % n) as f64 / n as f64;
            u[[i, 1]] = ((i * 104_729) % n) as f64 / n as f64;
        }
        (wo, u)
    }

    #[test]
    fn batch_path_equals_the_kernels_in_any_order_and_dtype() {
        let m = ggx();
        let n = 3 * BLOCK + 17;
        let (wo, u) = inputs(n);
        let e = Engine::new(&m, BsdfStrategy::Vndf, false).unwrap();
        assert!(e.batch.is_some());
        let wo32 = wo.mapv(|x| x as f32);
        let u32_ = u.mapv(|x| x as f32);
        let c = sample32(&e, &In2::F32(wo32.view()), &In2::F32(u32_.view()), None).unwrap();
        // Fortran order, and f64 inputs: the same bits.
        let mut wof = Array2::<f32>::zeros((n, 3).f());
        wof.assign(&wo32);
        let fo = sample32(&e, &In2::F32(wof.view()), &In2::F32(u32_.view()), None).unwrap();
        assert_eq!(c, fo);
        let d = sample32(
            &e,
            &In2::F64(wo32.mapv(f64::from).view()),
            &In2::F64(u32_.mapv(f64::from).view()),
            None,
        )
        .unwrap();
        assert_eq!(c, d);
        // The kernels called directly on the whole array.
        let b = e.batch.unwrap();
        let col = |a: &Array2<f32>, j: usize| a.column(j).to_vec();
        let (x, y, z, u1, u2) = (
            col(&wo32, 0),
            col(&wo32, 1),
            col(&wo32, 2),
            col(&u32_, 0),
            col(&u32_, 1),
        );
        let mut bufs = SampleBuffers::new(n);
        b.sample(
            SampleInput {
                wo: Dirs {
                    x: &x,
                    y: &y,
                    z: &z,
                },
                u1: &u1,
                u2: &u2,
                uc: None,
            },
            bufs.output(),
        )
        .unwrap();
        assert_eq!(&c.wi[..n], &bufs.wi[0][..]);
        assert_eq!(&c.wi[2 * n..], &bufs.wi[2][..]);
        assert_eq!(&c.weight[n..2 * n], &bufs.weight[1][..]);
        assert_eq!(c.pdf, bufs.pdf);
        assert_eq!(c.valid, bufs.valid);
        // The scalar reference within the documented f32 error.
        let r = sample_scalar::<f64>(
            &Engine::new(&m, BsdfStrategy::Vndf, true).unwrap(),
            &In2::F64(wo.view()),
            &In2::F64(u.view()),
            None,
        )
        .unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..n {
            if r.valid[i] == 1 && c.valid[i] == 1 && r.pdf[i] > 1e-3 {
                worst = worst.max((f64::from(c.pdf[i]) - r.pdf[i]).abs() / r.pdf[i]);
            }
        }
        assert!(worst < 1e-3, "{worst}");
    }

    #[test]
    fn a_uniform_of_one_is_sampled_as_the_value_below_one() {
        // The kernels run before the checks; a block with u = 1 runs again
        // on the moved values (`check_uniform`), so the result is that of
        // the largest f32 below one, in that block and in no other.
        let m = ggx();
        let n = 2 * BLOCK + 9;
        let (wo, u) = inputs(n);
        let e = Engine::new(&m, BsdfStrategy::Vndf, false).unwrap();
        let wo32 = wo.mapv(|x| x as f32);
        let mut with_one = u.mapv(|x| x as f32);
        let mut below = with_one.clone();
        for &(r, c) in &[(3, 0), (BLOCK + 5, 1), (2 * BLOCK + 8, 0)] {
            with_one[[r, c]] = 1.0;
            below[[r, c]] = f32::BELOW_ONE;
        }
        let a = sample32(&e, &In2::F32(wo32.view()), &In2::F32(with_one.view()), None).unwrap();
        let b = sample32(&e, &In2::F32(wo32.view()), &In2::F32(below.view()), None).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn blocks_cut_after_an_aligning_head() {
        for (n, head) in [
            (0, 0),
            (5, 0),
            (5, 3),
            (BLOCK, 12),
            (3 * BLOCK + 7, 12),
            (BLOCK + 1, 0),
        ] {
            let c = Cuts { n, head };
            let lens: Vec<usize> = c.lengths().collect();
            assert_eq!(lens.iter().sum::<usize>(), n, "{n} {head}");
            assert!(lens.iter().all(|&l| l > 0 && l <= BLOCK));
            let starts = c.starts();
            assert_eq!(starts.len(), lens.len());
            if head > 0 && head < n {
                assert_eq!(lens[0], head);
                assert!(starts[1..].iter().all(|s| (s - head) % BLOCK == 0));
            }
            let mut v: Vec<u32> = (0..3 * n as u32).collect();
            let parts = c.split3(&mut v);
            for (k, [a, b, cc]) in parts.iter().enumerate() {
                assert_eq!(a.len(), lens[k]);
                assert_eq!(a[0] as usize, starts[k]);
                assert_eq!(b[0] as usize, n + starts[k]);
                assert_eq!(cc[0] as usize, 2 * n + starts[k]);
            }
        }
        let v = vec![0f32; 100];
        let c = Cuts::aligned(100, v.as_ptr());
        assert!(c.head < 16 && v[c.head..].as_ptr().align_offset(64) == 0);
    }

    #[test]
    fn eval_pdf_batch_and_scalar_agree() {
        let m = ggx();
        let n = BLOCK + 5;
        let (wo, u) = inputs(n);
        let e = Engine::new(&m, BsdfStrategy::Vndf, false).unwrap();
        let s = sample32(&e, &In2::F64(wo.view()), &In2::F64(u.view()), None).unwrap();
        let wi = Array2::from_shape_vec((n, 3).f(), s.wi.clone()).unwrap();
        let wo32 = wo.mapv(|x| x as f32);
        let both =
            eval_pdf32(&e, &In2::F32(wo32.view()), &In2::F32(wi.view()), Want::Both).unwrap();
        for i in 0..n {
            if s.valid[i] == 1 {
                assert!((both.pdf[i] - s.pdf[i]).abs() <= 1e-4 * s.pdf[i], "{i}");
            }
        }
        let pdf = eval_pdf32(&e, &In2::F32(wo32.view()), &In2::F32(wi.view()), Want::Pdf).unwrap();
        assert_eq!(pdf.pdf, both.pdf);
        assert!(pdf.f.is_empty());
        let r = eval_pdf_scalar::<f64>(
            &Engine::new(&m, BsdfStrategy::Vndf, true).unwrap(),
            &In2::F64(wo32.mapv(f64::from).view()),
            &In2::F64(wi.mapv(f64::from).view()),
            Want::Both,
        )
        .unwrap();
        for i in 0..n {
            if r.pdf[i] > 1e-2 {
                assert!(
                    (f64::from(both.pdf[i]) - r.pdf[i]).abs() < 1e-4 * r.pdf[i],
                    "{i}: {} {}",
                    both.pdf[i],
                    r.pdf[i]
                );
            }
        }
    }

    #[test]
    fn bad_inputs_name_the_row() {
        let m = ggx();
        let n = 2 * BLOCK + 3;
        let (mut wo, mut u) = inputs(n);
        let e = Engine::new(&m, BsdfStrategy::Vndf, false).unwrap();
        wo[[BLOCK + 4, 0]] = f64::NAN;
        let err = sample32(&e, &In2::F64(wo.view()), &In2::F64(u.view()), None).unwrap_err();
        assert_eq!(err.row, BLOCK + 4);
        assert!(
            err.message
                .starts_with(&format!("wo[{}] = (NaN", BLOCK + 4)),
            "{}",
            err.message
        );
        assert!(err.message.ends_with("is not finite"), "{}", err.message);
        wo[[BLOCK + 4, 0]] = 0.0;
        wo[[7, 2]] = 3.0;
        let err = sample_scalar::<f64>(
            &Engine::new(&m, BsdfStrategy::Vndf, true).unwrap(),
            &In2::F64(wo.view()),
            &In2::F64(u.view()),
            None,
        )
        .unwrap_err();
        assert!(
            err.message.starts_with("wo[7] = (") && err.message.contains("not a unit vector"),
            "{}",
            err.message
        );
        let (wo, _) = inputs(n);
        u[[9, 1]] = 1.5;
        let err = sample32(&e, &In2::F64(wo.view()), &In2::F64(u.view()), None).unwrap_err();
        assert_eq!(err.message, "u[9] = 1.5 is not a uniform number in [0, 1)");
        // One is moved below one, not an error.
        u[[9, 1]] = 1.0;
        assert!(sample32(&e, &In2::F64(wo.view()), &In2::F64(u.view()), None).is_ok());
    }

    #[test]
    fn measured_table_with_a_diffuse_term_runs_on_the_batch_path() {
        // The kernels cover every model; a measured table with a diffuse
        // term runs lane by lane through the scalar mixture, with `uc`.
        let g = Material::load(r#"{"type":"cook-torrance","alpha":0.3}"#).unwrap();
        let dir = std::env::temp_dir().join(format!("lobe-py-engine-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.bsdf");
        std::fs::write(
            &path,
            lobe::models::measured::rgl::Rgl::write(|o, i| g.eval(o, i), 4, 8, "t"),
        )
        .unwrap();
        let table = Material::load(&format!(
            r#"{{"type":"measured","path":{:?}}}"#,
            path.display().to_string()
        ))
        .unwrap();
        let m = Material::with_diffuse(lobe::Rgb::splat(0.3), table.glossy).unwrap();
        assert!(BatchSampler::new(&m, BsdfStrategy::Brdf).is_ok());
        let e = Engine::new(&m, BsdfStrategy::Brdf, false).unwrap();
        assert!(e.batch.is_some());
        let n = 1000;
        let (wo, u) = inputs(n);
        let uc = Array1::from_shape_fn(n, |i| (i as f64 * 0.618).fract());
        let s = sample32(
            &e,
            &In2::F64(wo.view()),
            &In2::F64(u.view()),
            Some(&In1::F64(uc.view())),
        )
        .unwrap();
        // The batch path's numbers are the scalar path's at the f32 inputs
        // (the directions renormalized in f64), rounded once.
        let r32 = |x: f64| f64::from(x as f32);
        for i in 0..n {
            let w = DVec3::new(r32(wo[[i, 0]]), r32(wo[[i, 1]]), r32(wo[[i, 2]])).normalize();
            let r = m.sampler(BsdfStrategy::Brdf).unwrap().sample(
                w,
                r32(uc[i]),
                DVec2::new(r32(u[[i, 0]]), r32(u[[i, 1]])),
            );
            assert_eq!(r.is_some(), s.valid[i] == 1);
            if let Some(r) = r {
                assert_eq!(s.pdf[i], r.pdf as f32);
            }
        }
        assert!(Engine::new(&m, BsdfStrategy::SphericalCaps, false).is_err());
    }
}
