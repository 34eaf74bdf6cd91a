//! The block loops, instantiated once per level: the portable one, and
//! `#[target_feature]` entry points for AVX2 + FMA and AVX-512, entered
//! only with the level's token (proof that the CPU has the features).
//!
//! A block is cut into vectors of `L::N` lanes; the last, partial vector is
//! copied into padded stack buffers, run through the same kernel and copied
//! back. Lanes never interact, so the numbers of a sample do not depend on
//! the block size, on where the block was cut, or on the thread.

use super::SimdLevel;
use super::block::{EvalIn, EvalOut, F_ONLY, PDF_ONLY, SampleIn, SampleOut};
use super::kernel::dielectric::DielectricParams;
use super::kernel::phong::{BLINN, LectureParams, PHONG};
use super::kernel::smooth::{CONDUCTOR, DIELECTRIC, PLASTIC, SmoothParams, THIN};
use super::kernel::{
    self, BECKMANN, BLINN_PHONG, BOUNDED, BRDF, CAPS, COSINE, CtParams, GGX, Sampled, UNIFORM, VNDF,
};
#[cfg(target_arch = "x86_64")]
use super::lanes::{Avx2, Avx512};
use super::lanes::{Lanes, Scalar, X2};

/// The widest lane count (two AVX-512 vectors, [`X2`]): the size of the
/// tail buffers.
const MAX_LANES: usize = 32;

/// What a [`super::BatchSampler`] runs: the model's parameters and the
/// instance of its kernel, chosen once in `BatchSampler::new`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Kernel {
    /// Cook-Torrance with distribution `ndf` and strategy `strat` (the
    /// kernel's const parameters).
    CookTorrance { ndf: u8, strat: u8, p: CtParams },
    /// A measured table (per lane, the same at every level: `super::measured`).
    Measured(Box<super::measured::MeasuredKernel>),
    /// Phong or Blinn-Phong (`model`: `PHONG`, `BLINN`) with strategy `strat`.
    Lecture {
        model: u8,
        strat: u8,
        p: LectureParams,
    },
    /// A rough dielectric with distribution `ndf` and strategy `strat`.
    Dielectric {
        ndf: u8,
        strat: u8,
        p: DielectricParams,
    },
    /// A smooth model (`model`: `smooth::CONDUCTOR`, ...), strategy brdf.
    Smooth { model: u8, p: SmoothParams },
}

/// A kernel's parameters, as the block loops run them: one vector of
/// `sample` and of `eval_pdf` for the instance `<A, B>` (the kernel's const
/// parameters: distribution or model, and strategy).
pub(crate) trait VecKernel {
    /// Whether `uc` chooses between two lobes (read from the inputs).
    fn two_lobes(&self) -> bool;
    fn sample<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        u1: L::F,
        u2: L::F,
        uc: L::F,
    ) -> Sampled<L>;
    fn eval_pdf<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        wi: [L::F; 3],
    ) -> ([L::F; 3], L::F);
}

impl VecKernel for CtParams {
    #[inline(always)]
    fn two_lobes(&self) -> bool {
        self.two_lobes
    }
    #[inline(always)]
    fn sample<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        u1: L::F,
        u2: L::F,
        uc: L::F,
    ) -> Sampled<L> {
        kernel::sample::<L, A, B>(l, self, wo, u1, u2, uc)
    }
    #[inline(always)]
    fn eval_pdf<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        wi: [L::F; 3],
    ) -> ([L::F; 3], L::F) {
        kernel::eval_pdf::<L, A, B>(l, self, wo, wi)
    }
}

impl VecKernel for LectureParams {
    #[inline(always)]
    fn two_lobes(&self) -> bool {
        self.two_lobes
    }
    #[inline(always)]
    fn sample<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        u1: L::F,
        u2: L::F,
        uc: L::F,
    ) -> Sampled<L> {
        kernel::phong::sample::<L, A, B>(l, self, wo, u1, u2, uc)
    }
    #[inline(always)]
    fn eval_pdf<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        wi: [L::F; 3],
    ) -> ([L::F; 3], L::F) {
        kernel::phong::eval_pdf::<L, A, B>(l, self, wo, wi)
    }
}

impl VecKernel for DielectricParams {
    #[inline(always)]
    fn two_lobes(&self) -> bool {
        true
    }
    #[inline(always)]
    fn sample<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        u1: L::F,
        u2: L::F,
        uc: L::F,
    ) -> Sampled<L> {
        kernel::dielectric::sample::<L, A, B>(l, self, wo, u1, u2, uc)
    }
    #[inline(always)]
    fn eval_pdf<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        wi: [L::F; 3],
    ) -> ([L::F; 3], L::F) {
        kernel::dielectric::eval_pdf::<L, A, B>(l, self, wo, wi)
    }
}

impl VecKernel for SmoothParams {
    #[inline(always)]
    fn two_lobes(&self) -> bool {
        true
    }
    #[inline(always)]
    fn sample<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        u1: L::F,
        u2: L::F,
        uc: L::F,
    ) -> Sampled<L> {
        kernel::smooth::sample::<L, A>(l, self, wo, u1, u2, uc)
    }
    #[inline(always)]
    fn eval_pdf<L: Lanes, const A: u8, const B: u8>(
        &self,
        l: L,
        wo: [L::F; 3],
        wi: [L::F; 3],
    ) -> ([L::F; 3], L::F) {
        kernel::smooth::eval_pdf::<L, A>(l, self, wo, wi)
    }
}

/// A level with its token.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Backend {
    Scalar(Scalar),
    #[cfg(target_arch = "x86_64")]
    Avx2(Avx2),
    #[cfg(target_arch = "x86_64")]
    Avx512(Avx512),
}

impl Backend {
    /// The level's token, `None` when the CPU lacks it.
    pub(crate) fn new(level: SimdLevel) -> Option<Backend> {
        match level {
            SimdLevel::Scalar => Some(Backend::Scalar(Scalar)),
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx2 => Avx2::new().map(Backend::Avx2),
            #[cfg(target_arch = "x86_64")]
            SimdLevel::Avx512 => Avx512::new().map(Backend::Avx512),
            #[cfg(not(target_arch = "x86_64"))]
            _ => None,
        }
    }

    pub(crate) fn level(self) -> SimdLevel {
        match self {
            Backend::Scalar(_) => SimdLevel::Scalar,
            #[cfg(target_arch = "x86_64")]
            Backend::Avx2(_) => SimdLevel::Avx2,
            #[cfg(target_arch = "x86_64")]
            Backend::Avx512(_) => SimdLevel::Avx512,
        }
    }
}

/// How `sample` writes its outputs: `f` at all (its slices may be empty
/// when not), and with streaming stores ([`Lanes::stream_ptr`]) or plain
/// ones (a block streams only where every output it writes is aligned for
/// the level). One branch a vector for each, not one per output: per-output
/// choices cost GGX brdf's `eval_pdf` about 14 instructions per AVX2 vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SampleWrites {
    pub f: bool,
    pub stream: bool,
}
/// An instance function of `sample` ([`instance_fns`]), which a block
/// calls back for its last, partial vector (copied into padded buffers):
/// the kernel is inlined once per instance, not twice (CI's time is mostly
/// compiling these instances).
///
/// Safety: the CPU has the target features of the level `L` stands for.
type SampleFn<L, P> = unsafe fn(L, &P, SampleIn<'_>, SampleOut<'_, '_>, SampleWrites);
/// As [`SampleFn`], for `eval_pdf`.
type EvalFn<L, P> = unsafe fn(L, &P, u8, EvalIn<'_>, EvalOut<'_, '_>, bool);

/// One vector of `sample` from the `L::N` values at `ip[i] + k`, stored at
/// `op[j] + k` (`f`, `op[3..6]`, only if `w.f`; streamed if `w.stream`) and
/// `vp + k` (`uc`, `ip[5]`, read only where `two`).
///
/// # Safety
/// Each `ip[i]`, `vp` and each `op[j]` written points at `k + L::N`
/// values; the outputs do not overlap each other or the inputs; if
/// `w.stream`, each `op[j] + k` written is aligned to `L::ALIGN` bytes.
#[inline(always)]
unsafe fn sample_vector<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &impl VecKernel,
    two: bool,
    (ip, op, vp): (&[*const f32; 6], &[*mut f32; 10], *mut u8),
    w: SampleWrites,
    k: usize,
) {
    // SAFETY: the caller's contract.
    unsafe {
        let x = |i: usize| l.load_ptr(ip[i].add(k));
        let uc = if two { x(5) } else { l.splat(0.5) };
        let s = p.sample::<L, NDF, STRAT>(l, [x(0), x(1), x(2)], x(3), x(4), uc);
        let main = [
            (0, s.wi[0]),
            (1, s.wi[1]),
            (2, s.wi[2]),
            (6, s.pdf),
            (7, s.weight[0]),
            (8, s.weight[1]),
            (9, s.weight[2]),
        ];
        put(l, w.stream, main, op, k);
        if w.f {
            put(l, w.stream, [(3, s.f[0]), (4, s.f[1]), (5, s.f[2])], op, k);
        }
        l.store_mask_ptr(s.valid, vp.add(k));
    }
}

/// One vector of `eval_pdf` from the `L::N` values at `ip[i] + k`: `f` at
/// `op[0..3] + k` if `writes.0`, the pdf at `op[3] + k` if `writes.1`,
/// streamed if `stream` (one branch a vector; the kernel compiled once,
/// for CI's compile time).
///
/// # Safety
/// Each `ip[i]` and each `op[j]` written points at `k + L::N` values; the
/// outputs do not overlap each other or the inputs; if `stream`, each
/// `op[j] + k` written is aligned to `L::ALIGN` bytes.
#[inline(always)]
unsafe fn eval_pdf_vector<L: Lanes, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &impl VecKernel,
    (ip, op): (&[*const f32; 6], &[*mut f32; 4]),
    (writes, stream): ((bool, bool), bool),
    k: usize,
) {
    // SAFETY: the caller's contract.
    unsafe {
        let x = |i: usize| l.load_ptr(ip[i].add(k));
        let (f, pdf) = p.eval_pdf::<L, NDF, STRAT>(l, [x(0), x(1), x(2)], [x(3), x(4), x(5)]);
        // The stream branch outside the two write branches: inside them
        // (two `put`s) cost GGX's eval_pdf 11% more instructions (AVX2).
        let f = [(0, f[0]), (1, f[1]), (2, f[2])];
        if stream {
            if writes.0 {
                for (j, v) in f {
                    l.stream_ptr(v, op[j].add(k));
                }
            }
            if writes.1 {
                l.stream_ptr(pdf, op[3].add(k));
            }
        } else {
            if writes.0 {
                for (j, v) in f {
                    l.store_ptr(v, op[j].add(k));
                }
            }
            if writes.1 {
                l.store_ptr(pdf, op[3].add(k));
            }
        }
    }
}

/// Each `(j, v)` of `values` into `op[j] + k`, streamed if `stream` (one
/// branch for the group, not one per store).
///
/// # Safety
/// Each `op[j] + k` points at `L::N` writable values, aligned to
/// `L::ALIGN` bytes if `stream`.
#[inline(always)]
unsafe fn put<L: Lanes, const M: usize>(
    l: L,
    stream: bool,
    values: [(usize, L::F); M],
    op: &[*mut f32],
    k: usize,
) {
    // SAFETY: the caller's contract.
    unsafe {
        if stream {
            for (j, v) in values {
                l.stream_ptr(v, op[j].add(k));
            }
        } else {
            for (j, v) in values {
                l.store_ptr(v, op[j].add(k));
            }
        }
    }
}

// The helpers below are not generic over the level or the kernel, so they
// are compiled once, not once per kernel instance: written inline as array
// `map`s in the block loops (126 instances), their iterator machinery was
// 15% of lobe's LLVM IR (`cargo llvm-lines`), for nothing the optimizer
// kept.

/// The inputs' data pointers.
#[inline]
fn in_ptrs(inp: &[&[f32]; 6]) -> [*const f32; 6] {
    let mut p = [std::ptr::null(); 6];
    for (d, s) in p.iter_mut().zip(inp) {
        *d = s.as_ptr();
    }
    p
}

/// The outputs' data pointers.
#[inline]
fn out_ptrs<const M: usize>(out: &mut [&mut [f32]; M]) -> [*mut f32; M] {
    let mut p = [std::ptr::null_mut(); M];
    for (d, s) in p.iter_mut().zip(out.iter_mut()) {
        *d = s.as_mut_ptr();
    }
    p
}

/// The first `n` values of each tail buffer.
#[inline]
fn heads<const M: usize>(b: &[[f32; MAX_LANES]; M], n: usize) -> [&[f32]; M] {
    b.each_ref().map(|b| &b[..n])
}

/// The first `n` values of each tail buffer, to write.
#[inline]
fn heads_mut<const M: usize>(b: &mut [[f32; MAX_LANES]; M], n: usize) -> [&mut [f32]; M] {
    b.each_mut().map(|b| &mut b[..n])
}

/// Whether `p` is aligned for [`Lanes::stream_ptr`] at `L`.
#[inline(always)]
fn aligned<L: Lanes>(p: *mut f32) -> bool {
    (p as usize).is_multiple_of(L::ALIGN)
}

/// `sample` over a block: whole vectors straight from and into the slices,
/// through pointers taken once (slices re-read from `out` and
/// bounds-checked at every vector cost about 110 instructions per 8-lane
/// vector of GGX brdf, callgrind, AVX2: a sixth of its work); the last,
/// partial vector through padded stack buffers. `f` is written only if
/// `w.f`; the outputs are streamed (then fenced) if `w.stream` and every
/// one written is aligned for `L`.
#[inline(always)]
fn sample_block<L: Lanes, P: VecKernel, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &P,
    inp: SampleIn<'_>,
    (out, valid): SampleOut<'_, '_>,
    w: SampleWrites,
    tail: SampleFn<L, P>,
) {
    let n = inp[0].len();
    for s in &inp {
        assert_eq!(s.len(), n);
    }
    let is_f = |j: usize| (3..6).contains(&j);
    for (j, o) in out.iter().enumerate() {
        assert!(o.len() == n || (!w.f && is_f(j)));
    }
    assert_eq!(valid.len(), n);
    let two = p.two_lobes();
    let ptrs = (&in_ptrs(&inp), &out_ptrs(out), valid.as_mut_ptr());
    let w = SampleWrites {
        f: w.f,
        stream: w.stream && (0..10).all(|j| (!w.f && is_f(j)) || aligned::<L>(ptrs.1[j])),
    };
    let mut k = 0;
    while k + L::N <= n {
        // SAFETY: every input and every output written holds `n` values
        // (asserted above) and `k + L::N <= n`; the outputs are distinct
        // `&mut` slices; if streamed, each output written starts aligned
        // to `L::ALIGN` bytes, and `k` is a multiple of `L::N` (`L::ALIGN`
        // divides `4 L::N`).
        unsafe { sample_vector::<L, NDF, STRAT>(l, p, two, ptrs, w, k) };
        k += L::N;
    }
    if w.stream {
        l.fence();
    }
    if k < n {
        let rem = n - k;
        // Padding: wo = +z, u = uc = 1/2 (a valid, harmless sample).
        let mut ib = [
            [0.0f32; MAX_LANES],
            [0.0; MAX_LANES],
            [1.0; MAX_LANES],
            [0.5; MAX_LANES],
            [0.5; MAX_LANES],
            [0.5; MAX_LANES],
        ];
        for (b, s) in ib.iter_mut().zip(inp) {
            b[..rem].copy_from_slice(&s[k..]);
        }
        let mut ob = [[0.0f32; MAX_LANES]; 10];
        let mut vb = [0u8; MAX_LANES];
        {
            let bi = heads(&ib, L::N);
            let mut bo = heads_mut(&mut ob, L::N);
            let plain = SampleWrites {
                f: w.f,
                stream: false,
            };
            // SAFETY: `tail` is this instance's function (the caller's
            // contract), at the level the caller runs at; one whole vector.
            unsafe { tail(l, p, bi, (&mut bo, &mut vb[..L::N]), plain) };
        }
        for (j, (o, b)) in out.iter_mut().zip(&ob).enumerate() {
            if w.f || !is_f(j) {
                o[k..].copy_from_slice(&b[..rem]);
            }
        }
        valid[k..].copy_from_slice(&vb[..rem]);
    }
}

/// `eval_pdf` over a block, as [`sample_block`], writing what `mode` names
/// (streamed if `stream` and every output written is aligned for `L`).
#[inline(always)]
fn eval_pdf_block<L: Lanes, P: VecKernel, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &P,
    mode: u8,
    inp: EvalIn<'_>,
    out: EvalOut<'_, '_>,
    stream: bool,
    tail: EvalFn<L, P>,
) {
    let n = inp[0].len();
    for s in &inp {
        assert_eq!(s.len(), n);
    }
    let writes = (mode != PDF_ONLY, mode != F_ONLY);
    let written = |i: usize| if i == 3 { writes.1 } else { writes.0 };
    for (i, o) in out.iter().enumerate() {
        assert!(!written(i) || o.len() == n);
    }
    let ptrs = (&in_ptrs(&inp), &out_ptrs(out));
    let stream = stream && (0..4).all(|j| !written(j) || aligned::<L>(ptrs.1[j]));
    let mut k = 0;
    while k + L::N <= n {
        // SAFETY: every input holds `n` values, every output written holds
        // `n` (asserted above), and `k + L::N <= n`; if `stream`, every
        // output written starts aligned to `L::ALIGN` bytes and `k` is a
        // multiple of `L::N` (`L::ALIGN` divides `4 L::N`).
        unsafe { eval_pdf_vector::<L, NDF, STRAT>(l, p, ptrs, (writes, stream), k) };
        k += L::N;
    }
    if stream {
        l.fence();
    }
    if k < n {
        let rem = n - k;
        // Padding: wo = wi = +z.
        let mut ib = [[0.0f32; MAX_LANES]; 6];
        ib[2] = [1.0; MAX_LANES];
        ib[5] = [1.0; MAX_LANES];
        for (b, s) in ib.iter_mut().zip(inp) {
            b[..rem].copy_from_slice(&s[k..]);
        }
        let mut ob = [[0.0f32; MAX_LANES]; 4];
        {
            let bi = heads(&ib, L::N);
            let mut bo = heads_mut(&mut ob, L::N);
            // SAFETY: `tail` is this instance's function (the caller's
            // contract), at the level the caller runs at; one whole vector.
            unsafe { tail(l, p, mode, bi, &mut bo, false) };
        }
        for (i, (o, b)) in out.iter_mut().zip(&ob).enumerate() {
            if written(i) {
                o[k..].copy_from_slice(&b[..rem]);
            }
        }
    }
}

/// One function per kernel instance and level, each compiled on its own
/// (`#[inline(never)]`): a match that inlined all of them into one function
/// per level made that function so large that LLVM spent minutes on it.
/// A call per block costs nothing against a block's work. `$feat`: the
/// level's target features (none for the portable level); the lanes type
/// is generic, so that one function serves a level and its [`X2`].
macro_rules! instance_fns {
    ($sample:ident, $eval:ident $(, $feat:literal)?) => {
        $(#[target_feature(enable = $feat)])?
        #[inline(never)]
        fn $sample<L: Lanes, P: VecKernel, const NDF: u8, const STRAT: u8>(
            l: L,
            p: &P,
            inp: SampleIn<'_>,
            out: SampleOut<'_, '_>,
            w: SampleWrites,
        ) {
            sample_block::<L, P, NDF, STRAT>(l, p, inp, out, w, $sample::<L, P, NDF, STRAT>)
        }

        $(#[target_feature(enable = $feat)])?
        #[inline(never)]
        fn $eval<L: Lanes, P: VecKernel, const NDF: u8, const STRAT: u8>(
            l: L,
            p: &P,
            mode: u8,
            inp: EvalIn<'_>,
            out: EvalOut<'_, '_>,
            stream: bool,
        ) {
            eval_pdf_block::<L, P, NDF, STRAT>(
                l,
                p,
                mode,
                inp,
                out,
                stream,
                $eval::<L, P, NDF, STRAT>,
            )
        }
    };
}

instance_fns!(sample_one, eval_pdf_one);

/// An instance inlined into its caller: the AVX-512 level's [`X2`]
/// samplers, which ran 8 to 12% slower as functions of their own (Beckmann
/// vndf, `lobe bench`, Intel Xeon; at AVX2 and for the other kernels no
/// difference was measured). Its last, partial vector goes to the instance
/// function of its own (compiled once more, as the tail of the inlined loop
/// was before).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn sample_inl<L: Lanes, P: VecKernel, const NDF: u8, const STRAT: u8>(
    l: L,
    p: &P,
    inp: SampleIn<'_>,
    out: SampleOut<'_, '_>,
    w: SampleWrites,
) {
    sample_block::<L, P, NDF, STRAT>(l, p, inp, out, w, sample_one_avx512::<L, P, NDF, STRAT>)
}
#[cfg(target_arch = "x86_64")]
instance_fns!(sample_one_avx2, eval_pdf_one_avx2, "avx2,fma");
#[cfg(target_arch = "x86_64")]
instance_fns!(
    sample_one_avx512,
    eval_pdf_one_avx512,
    "avx512f,avx512dq,avx512bw,avx512vl,avx2,fma"
);

/// Every kernel instance of one level: the match picks it once per block
/// and calls the instance function `$f` (arguments `$args`).
macro_rules! instances {
    ($k:expr, $f:ident, $l:expr, $($args:expr),*) => {
        match $k {
            Kernel::CookTorrance { ndf, strat, p } => match (*ndf, *strat) {
                (GGX, VNDF) => $f::<_, _, GGX, VNDF>($l, p, $($args),*),
                (GGX, BRDF) => $f::<_, _, GGX, BRDF>($l, p, $($args),*),
                (GGX, UNIFORM) => $f::<_, _, GGX, UNIFORM>($l, p, $($args),*),
                (GGX, COSINE) => $f::<_, _, GGX, COSINE>($l, p, $($args),*),
                (BECKMANN, VNDF) => $f::<_, _, BECKMANN, VNDF>($l, p, $($args),*),
                (BECKMANN, BRDF) => $f::<_, _, BECKMANN, BRDF>($l, p, $($args),*),
                (BECKMANN, UNIFORM) => $f::<_, _, BECKMANN, UNIFORM>($l, p, $($args),*),
                (BECKMANN, COSINE) => $f::<_, _, BECKMANN, COSINE>($l, p, $($args),*),
                (GGX, CAPS) => $f::<_, _, GGX, CAPS>($l, p, $($args),*),
                (GGX, BOUNDED) => $f::<_, _, GGX, BOUNDED>($l, p, $($args),*),
                (BLINN_PHONG, BRDF) => $f::<_, _, BLINN_PHONG, BRDF>($l, p, $($args),*),
                (BLINN_PHONG, UNIFORM) => $f::<_, _, BLINN_PHONG, UNIFORM>($l, p, $($args),*),
                (BLINN_PHONG, COSINE) => $f::<_, _, BLINN_PHONG, COSINE>($l, p, $($args),*),
                _ => unreachable!("BatchSampler::new builds only these"),
            },
            Kernel::Lecture { model, strat, p } => match (*model, *strat) {
                (PHONG, BRDF) => $f::<_, _, PHONG, BRDF>($l, p, $($args),*),
                (PHONG, UNIFORM) => $f::<_, _, PHONG, UNIFORM>($l, p, $($args),*),
                (PHONG, COSINE) => $f::<_, _, PHONG, COSINE>($l, p, $($args),*),
                (BLINN, BRDF) => $f::<_, _, BLINN, BRDF>($l, p, $($args),*),
                (BLINN, UNIFORM) => $f::<_, _, BLINN, UNIFORM>($l, p, $($args),*),
                (BLINN, COSINE) => $f::<_, _, BLINN, COSINE>($l, p, $($args),*),
                _ => unreachable!("BatchSampler::new builds only these"),
            },
            Kernel::Measured(_) => unreachable!("run before the level's dispatch"),
            Kernel::Dielectric { ndf, strat, p } => match (*ndf, *strat) {
                (GGX, VNDF) => $f::<_, _, GGX, VNDF>($l, p, $($args),*),
                (GGX, BRDF) => $f::<_, _, GGX, BRDF>($l, p, $($args),*),
                (GGX, CAPS) => $f::<_, _, GGX, CAPS>($l, p, $($args),*),
                (GGX, UNIFORM) => $f::<_, _, GGX, UNIFORM>($l, p, $($args),*),
                (GGX, COSINE) => $f::<_, _, GGX, COSINE>($l, p, $($args),*),
                (BECKMANN, VNDF) => $f::<_, _, BECKMANN, VNDF>($l, p, $($args),*),
                (BECKMANN, BRDF) => $f::<_, _, BECKMANN, BRDF>($l, p, $($args),*),
                (BECKMANN, UNIFORM) => $f::<_, _, BECKMANN, UNIFORM>($l, p, $($args),*),
                (BECKMANN, COSINE) => $f::<_, _, BECKMANN, COSINE>($l, p, $($args),*),
                _ => unreachable!("BatchSampler::new builds only these"),
            },
            Kernel::Smooth { model, p } => match *model {
                CONDUCTOR => $f::<_, _, CONDUCTOR, BRDF>($l, p, $($args),*),
                DIELECTRIC => $f::<_, _, DIELECTRIC, BRDF>($l, p, $($args),*),
                THIN => $f::<_, _, THIN, BRDF>($l, p, $($args),*),
                PLASTIC => $f::<_, _, PLASTIC, BRDF>($l, p, $($args),*),
                _ => unreachable!("BatchSampler::new builds only these"),
            },
        }
    };
}

/// The [`runs_x2`] instances: `$f` called with two vectors at a time.
macro_rules! instances_x2 {
    ($k:expr, $f:ident, $l:expr, $($args:expr),*) => {{
        let Kernel::CookTorrance { ndf, strat, p } = $k else {
            unreachable!("runs_x2 admits only Cook-Torrance")
        };
        match (*ndf, *strat) {
            (GGX, VNDF) => $f::<_, _, GGX, VNDF>(X2($l), p, $($args),*),
            (BECKMANN, VNDF) => $f::<_, _, BECKMANN, VNDF>(X2($l), p, $($args),*),
            (GGX, BRDF) => $f::<_, _, GGX, BRDF>(X2($l), p, $($args),*),
            _ => unreachable!("runs_x2 admits only these"),
        }
    }};
}

/// `sample` at a portable level `L` (the scalar level; `X2<Scalar>` in the
/// tests).
pub(super) fn sample_level<L: Lanes>(
    l: L,
    k: &Kernel,
    inp: SampleIn<'_>,
    out: SampleOut<'_, '_>,
    w: SampleWrites,
) {
    instances!(k, sample_one, l, inp, out, w)
}

/// `eval_pdf` at a portable level `L`, writing what `mode` names.
pub(super) fn eval_pdf_level<L: Lanes>(
    l: L,
    k: &Kernel,
    mode: u8,
    inp: EvalIn<'_>,
    out: EvalOut<'_, '_>,
    stream: bool,
) {
    instances!(k, eval_pdf_one, l, mode, inp, out, stream)
}

/// Whether the AVX-512 (`wide`) or AVX2 level runs `k`'s `sample`
/// (`eval = false`) or `eval_pdf` two vectors at a time ([`X2`]): the
/// visible-normal samplers (GGX and Beckmann), whose long dependency chains
/// (square root, division, reflection, square root, division; Beckmann's
/// Newton steps) leave the pipelines idle one vector at a time, and
/// Beckmann's evaluation; at AVX2 also GGX's brdf sampler (its sample
/// 20%, its s+e+p 12% faster on Zen 3, where AVX2 is the native level).
/// Where the chains are short (GGX eval_pdf; GGX brdf at AVX-512, which
/// has half as many vectors in flight for the same work) two vectors only
/// add register spills and run slower: measured by `lobe bench` on Zen 4
/// (BENCHMARKS.md). GGX vndf's sampler too at AVX-512: two 16-lane vectors
/// in flight spilled 63 of its ~370 instructions to the stack, and one at
/// a time ran its s+e+p 7–18% (one thread) and 18–23% (two) faster on Zen 4
/// (2026-12-03, three alternating runs). Beckmann's, whose chains are
/// longer still, showed no difference either way and keeps two. The
/// numbers are the same bits either way.
pub(super) fn runs_x2(k: &Kernel, eval: bool, wide: bool) -> bool {
    match k {
        Kernel::CookTorrance { ndf, strat, .. } => match *strat {
            VNDF => *ndf == BECKMANN || (*ndf == GGX && !eval && !wide),
            BRDF => *ndf == GGX && !eval && !wide,
            _ => false,
        },
        _ => false,
    }
}

/// The [`runs_x2`] instances at a portable level, two vectors of `L` at a
/// time (for the tests).
#[cfg(test)]
pub(super) fn sample_x2<L: Lanes>(
    l: L,
    k: &Kernel,
    inp: SampleIn<'_>,
    out: SampleOut<'_, '_>,
    w: SampleWrites,
) {
    instances_x2!(k, sample_one, l, inp, out, w)
}

/// As [`sample_x2`], for `eval_pdf`.
#[cfg(test)]
pub(super) fn eval_pdf_x2<L: Lanes>(
    l: L,
    k: &Kernel,
    mode: u8,
    inp: EvalIn<'_>,
    out: EvalOut<'_, '_>,
    stream: bool,
) {
    instances_x2!(k, eval_pdf_one, l, mode, inp, out, stream)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn sample_avx2(l: Avx2, k: &Kernel, inp: SampleIn<'_>, out: SampleOut<'_, '_>, w: SampleWrites) {
    if runs_x2(k, false, false) {
        instances_x2!(k, sample_one_avx2, l, inp, out, w)
    } else {
        instances!(k, sample_one_avx2, l, inp, out, w)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vl,avx2,fma")]
fn sample_avx512(
    l: Avx512,
    k: &Kernel,
    inp: SampleIn<'_>,
    out: SampleOut<'_, '_>,
    w: SampleWrites,
) {
    if runs_x2(k, false, true) {
        instances_x2!(k, sample_inl, l, inp, out, w)
    } else {
        instances!(k, sample_one_avx512, l, inp, out, w)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn eval_pdf_avx2(
    l: Avx2,
    k: &Kernel,
    mode: u8,
    inp: EvalIn<'_>,
    out: EvalOut<'_, '_>,
    stream: bool,
) {
    if runs_x2(k, true, false) {
        instances_x2!(k, eval_pdf_one_avx2, l, mode, inp, out, stream)
    } else {
        instances!(k, eval_pdf_one_avx2, l, mode, inp, out, stream)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vl,avx2,fma")]
fn eval_pdf_avx512(
    l: Avx512,
    k: &Kernel,
    mode: u8,
    inp: EvalIn<'_>,
    out: EvalOut<'_, '_>,
    stream: bool,
) {
    if runs_x2(k, true, true) {
        instances_x2!(k, eval_pdf_one_avx512, l, mode, inp, out, stream)
    } else {
        instances!(k, eval_pdf_one_avx512, l, mode, inp, out, stream)
    }
}

/// Run `sample` over a block (lengths already checked equal).
pub(crate) fn sample(
    b: Backend,
    k: &Kernel,
    inp: SampleIn<'_>,
    out: SampleOut<'_, '_>,
    w: SampleWrites,
) {
    if let Kernel::Measured(m) = k {
        return super::measured::sample_block(m, inp, out);
    }
    match b {
        Backend::Scalar(l) => sample_level(l, k, inp, out, w),
        // SAFETY: an `Avx2` token exists only if the CPU has AVX2 and FMA.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2(l) => unsafe { sample_avx2(l, k, inp, out, w) },
        // SAFETY: an `Avx512` token exists only if the CPU has AVX-512F/DQ/BW/VL and FMA
        // (AVX2 is implied by AVX-512F).
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512(l) => unsafe { sample_avx512(l, k, inp, out, w) },
    }
}

/// Run `eval_pdf` over a block (lengths already checked equal), writing
/// the outputs `mode` names ([`BOTH`], [`F_ONLY`], [`PDF_ONLY`]).
pub(crate) fn eval_pdf(
    b: Backend,
    k: &Kernel,
    mode: u8,
    inp: EvalIn<'_>,
    out: EvalOut<'_, '_>,
    stream: bool,
) {
    if let Kernel::Measured(m) = k {
        return super::measured::eval_pdf_block(m, mode, inp, out);
    }
    match b {
        Backend::Scalar(l) => eval_pdf_level(l, k, mode, inp, out, stream),
        // SAFETY: an `Avx2` token exists only if the CPU has AVX2 and FMA.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2(l) => unsafe { eval_pdf_avx2(l, k, mode, inp, out, stream) },
        // SAFETY: an `Avx512` token exists only if the CPU has AVX-512F/DQ/BW/VL and FMA.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512(l) => unsafe { eval_pdf_avx512(l, k, mode, inp, out, stream) },
    }
}

/// `sincos_turns` over slices at `level` (for the accuracy test).
#[cfg(test)]
pub(crate) fn sincos_slice(level: SimdLevel, t: &[f32], s: &mut [f32], c: &mut [f32]) {
    #[inline(always)]
    fn run<L: Lanes>(l: L, t: &[f32], s: &mut [f32], c: &mut [f32]) {
        let mut k = 0;
        while k + L::N <= t.len() {
            let (sv, cv) = super::math::sincos_turns(l, l.load(&t[k..]));
            l.store(sv, &mut s[k..]);
            l.store(cv, &mut c[k..]);
            k += L::N;
        }
        for k in k..t.len() {
            let (sv, cv) = super::math::sincos_turns(Scalar, t[k]);
            s[k] = sv;
            c[k] = cv;
        }
    }
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn avx2(l: Avx2, t: &[f32], s: &mut [f32], c: &mut [f32]) {
        run(l, t, s, c);
    }
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vl,avx2,fma")]
    fn avx512(l: Avx512, t: &[f32], s: &mut [f32], c: &mut [f32]) {
        run(l, t, s, c);
    }
    match Backend::new(level).expect("level available") {
        Backend::Scalar(l) => run(l, t, s, c),
        // SAFETY: the token proves AVX2 and FMA.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2(l) => unsafe { avx2(l, t, s, c) },
        // SAFETY: the token proves AVX-512F/DQ/BW/VL and FMA.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512(l) => unsafe { avx512(l, t, s, c) },
    }
}

/// A function of [`super::math`], for the accuracy tests.
#[cfg(test)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MathFn {
    Exp,
    Log,
    Log1p,
    /// `(erfc x, e^(−x²))`.
    ErfcExp,
    ErfinvU,
    ErfinvURefined,
    Expm1,
    /// `(1 − x)ⁿ`, `n` given by its bits.
    Pow1m(u32),
    /// `xⁿ` by `pow_cos(1 − x, x, n)`, `n` given by its bits.
    PowCos(u32),
}

/// `f` over slices at `level` (the second output only for `ErfcExp`).
#[cfg(test)]
pub(crate) fn math_slice(level: SimdLevel, f: MathFn, x: &[f32], a: &mut [f32], b: &mut [f32]) {
    #[inline(always)]
    fn one<L: Lanes>(l: L, f: MathFn, x: L::F) -> (L::F, L::F) {
        use super::math;
        let z = l.splat(0.0);
        match f {
            MathFn::Exp => (math::exp(l, x), z),
            MathFn::Log => (math::log(l, x), z),
            MathFn::Log1p => (math::log1p(l, x), z),
            MathFn::ErfcExp => math::erfc_exp(l, x),
            MathFn::ErfinvU => (math::erfinv_u(l, x), z),
            MathFn::ErfinvURefined => (math::erfinv_u_refined(l, x), z),
            MathFn::Expm1 => (math::expm1(l, x), z),
            MathFn::Pow1m(n) => (math::pow_1m(l, x, l.splat(f32::from_bits(n))), z),
            MathFn::PowCos(n) => (
                math::pow_cos(l, l.splat(1.0) - x, x, l.splat(f32::from_bits(n))),
                z,
            ),
        }
    }
    #[inline(always)]
    fn run<L: Lanes>(l: L, f: MathFn, x: &[f32], a: &mut [f32], b: &mut [f32]) {
        let mut k = 0;
        while k + L::N <= x.len() {
            let (u, v) = one(l, f, l.load(&x[k..]));
            l.store(u, &mut a[k..]);
            l.store(v, &mut b[k..]);
            k += L::N;
        }
        for k in k..x.len() {
            let (u, v) = one(Scalar, f, x[k]);
            a[k] = u;
            b[k] = v;
        }
    }
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn avx2(l: Avx2, f: MathFn, x: &[f32], a: &mut [f32], b: &mut [f32]) {
        run(l, f, x, a, b);
    }
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vl,avx2,fma")]
    fn avx512(l: Avx512, f: MathFn, x: &[f32], a: &mut [f32], b: &mut [f32]) {
        run(l, f, x, a, b);
    }
    match Backend::new(level).expect("level available") {
        Backend::Scalar(l) => run(l, f, x, a, b),
        // SAFETY: the token proves AVX2 and FMA.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx2(l) => unsafe { avx2(l, f, x, a, b) },
        // SAFETY: the token proves AVX-512F/DQ/BW/VL and FMA.
        #[cfg(target_arch = "x86_64")]
        Backend::Avx512(l) => unsafe { avx512(l, f, x, a, b) },
    }
}
