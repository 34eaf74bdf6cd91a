//! The lane layer: one small trait, [`Lanes`], over which the batch kernels
//! are written once, and its three instances: [`Scalar`] (one `f32` lane,
//! portable), [`Avx2`] (8 lanes, AVX2 + FMA) and [`Avx512`] (16 lanes,
//! AVX-512F/DQ/BW/VL); and [`X2`], two vectors of a level side by side,
//! which the AVX-512 and AVX2 levels run for their longest kernels.
//!
//! A level is a zero-sized *token*: `Avx2` and `Avx512` can only be made by
//! [`Avx2::new`] / [`Avx512::new`], which check the CPU at run time, and
//! their vector and mask types can only be made through a token (their
//! fields are private). So wherever a vector value exists, the CPU has the
//! instructions its operators use: that is the argument of every `SAFETY:`
//! comment below. The kernels are `#[inline(always)]` generics, instantiated
//! inside `#[target_feature]` entry points ([`super::dispatch`]) so that the
//! intrinsics are inlined into code compiled for that level.
//!
//! Every operation is exactly rounded IEEE arithmetic (add, mul, fused
//! multiply-add, div, sqrt, round, compare, select), the same at every
//! level: the three levels give bit-identical results.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A SIMD width and its operations on `f32` lanes.
pub(crate) trait Lanes: Copy {
    /// Number of lanes.
    const N: usize;
    /// The alignment in bytes that [`Lanes::stream_ptr`] needs.
    const ALIGN: usize;
    /// A vector of `N` `f32`.
    type F: Copy
        + Add<Output = Self::F>
        + Sub<Output = Self::F>
        + Mul<Output = Self::F>
        + Div<Output = Self::F>
        + Neg<Output = Self::F>;
    /// A mask of `N` lanes.
    type M: Copy + BitAnd<Output = Self::M> + BitOr<Output = Self::M> + Not<Output = Self::M>;

    fn splat(self, x: f32) -> Self::F;
    /// The `N` values at `p`.
    ///
    /// # Safety
    /// `p` points at `N` readable `f32`.
    unsafe fn load_ptr(self, p: *const f32) -> Self::F;
    /// Into the `N` values at `p`.
    ///
    /// # Safety
    /// `p` points at `N` writable `f32`.
    unsafe fn store_ptr(self, v: Self::F, p: *mut f32);
    /// `1` where the mask is set, `0` elsewhere, into the `N` bytes at `p`.
    ///
    /// # Safety
    /// `p` points at `N` writable bytes.
    unsafe fn store_mask_ptr(self, m: Self::M, p: *mut u8);
    /// Into the `N` values at `p`, as [`Lanes::store_ptr`], with a
    /// streaming (non-temporal) store where the level has one: the line
    /// goes to memory without being read first and without taking a place
    /// in the caches. For outputs far larger than the caches; the stores
    /// are ordered by [`Lanes::fence`].
    ///
    /// # Safety
    /// `p` points at `N` writable `f32` and is aligned to [`Lanes::ALIGN`]
    /// bytes.
    unsafe fn stream_ptr(self, v: Self::F, p: *mut f32);
    /// Orders this thread's streaming stores before its later stores (a
    /// store fence where [`Lanes::stream_ptr`] streams).
    fn fence(self);
    /// The first `N` values of `s` (panics if shorter). The block loops
    /// use [`Lanes::load_ptr`]; this checked form serves the accuracy tests.
    #[cfg(test)]
    #[inline(always)]
    fn load(self, s: &[f32]) -> Self::F {
        let s = &s[..Self::N];
        // SAFETY: `s` holds `N` readable f32.
        unsafe { self.load_ptr(s.as_ptr()) }
    }
    /// Into the first `N` values of `s` (panics if shorter; for the tests,
    /// as [`Lanes::load`]).
    #[cfg(test)]
    #[inline(always)]
    fn store(self, v: Self::F, s: &mut [f32]) {
        let s = &mut s[..Self::N];
        // SAFETY: `s` holds `N` writable f32.
        unsafe { self.store_ptr(v, s.as_mut_ptr()) }
    }
    /// `a · b + c`, rounded once.
    fn mul_add(self, a: Self::F, b: Self::F, c: Self::F) -> Self::F;
    fn sqrt(self, a: Self::F) -> Self::F;
    fn min(self, a: Self::F, b: Self::F) -> Self::F;
    fn max(self, a: Self::F, b: Self::F) -> Self::F;
    /// Round to the nearest integer, ties to even.
    fn round(self, a: Self::F) -> Self::F;
    fn floor(self, a: Self::F) -> Self::F;
    /// `a < b` (false when either is NaN).
    fn lt(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a > b` (false when either is NaN).
    fn gt(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a == b` (false when either is NaN).
    fn eq(self, a: Self::F, b: Self::F) -> Self::M;
    /// `m ? a : b` lane by lane.
    fn select(self, m: Self::M, a: Self::F, b: Self::F) -> Self::F;
    fn abs(self, a: Self::F) -> Self::F;
    /// Whether any lane of the mask is set.
    fn any(self, m: Self::M) -> bool;
    /// `table[i]` lane by lane for integral `i` in `[0, table.len())`
    /// (clamped into it, so never out of bounds).
    fn gather(self, table: &[f32], i: Self::F) -> Self::F;
    /// `2ⁿ` for integral `n` in `[−126, 127]` (built from the exponent bits;
    /// other `n` give garbage the callers never use).
    fn exp2i(self, n: Self::F) -> Self::F;
    /// `(m, e)` with `x = m · 2ᵉ`, `m ∈ [1, 2)`, `e` integral, for a normal
    /// positive `x` (read from the bits; exact).
    fn frexp(self, x: Self::F) -> (Self::F, Self::F);

    /// `m ? a : b` for masks.
    #[inline(always)]
    fn select_mask(self, m: Self::M, a: Self::M, b: Self::M) -> Self::M {
        (m & a) | (!m & b)
    }

    /// Finite (neither infinite nor NaN).
    #[inline(always)]
    fn is_finite(self, a: Self::F) -> Self::M {
        self.lt(self.abs(a), self.splat(f32::INFINITY))
    }
}

// ---------------------------------------------------------------- scalar

/// One `f32` lane in portable Rust: the fallback on any CPU.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scalar;

impl Lanes for Scalar {
    const N: usize = 1;
    const ALIGN: usize = 4;
    type F = f32;
    type M = bool;

    #[inline(always)]
    fn splat(self, x: f32) -> f32 {
        x
    }
    #[inline(always)]
    unsafe fn load_ptr(self, p: *const f32) -> f32 {
        // SAFETY: the caller's contract.
        unsafe { *p }
    }
    #[inline(always)]
    unsafe fn store_ptr(self, v: f32, p: *mut f32) {
        // SAFETY: the caller's contract.
        unsafe { *p = v }
    }
    #[inline(always)]
    unsafe fn store_mask_ptr(self, m: bool, p: *mut u8) {
        // SAFETY: the caller's contract.
        unsafe { *p = u8::from(m) }
    }
    #[inline(always)]
    unsafe fn stream_ptr(self, v: f32, p: *mut f32) {
        // A plain store: the portable level has no streaming store.
        // SAFETY: the caller's contract.
        unsafe { *p = v }
    }
    #[inline(always)]
    fn fence(self) {}
    #[inline(always)]
    fn mul_add(self, a: f32, b: f32, c: f32) -> f32 {
        // Fused, as at the SIMD levels (bit-identical results).
        a.mul_add(b, c)
    }
    #[inline(always)]
    fn sqrt(self, a: f32) -> f32 {
        a.sqrt()
    }
    #[inline(always)]
    fn min(self, a: f32, b: f32) -> f32 {
        // minps semantics: the second operand when either is NaN.
        if a < b { a } else { b }
    }
    #[inline(always)]
    fn max(self, a: f32, b: f32) -> f32 {
        if a > b { a } else { b }
    }
    #[inline(always)]
    fn round(self, a: f32) -> f32 {
        a.round_ties_even()
    }
    #[inline(always)]
    fn floor(self, a: f32) -> f32 {
        a.floor()
    }
    #[inline(always)]
    fn lt(self, a: f32, b: f32) -> bool {
        a < b
    }
    #[inline(always)]
    fn gt(self, a: f32, b: f32) -> bool {
        a > b
    }
    #[inline(always)]
    fn eq(self, a: f32, b: f32) -> bool {
        a == b
    }
    #[inline(always)]
    fn select(self, m: bool, a: f32, b: f32) -> f32 {
        if m { a } else { b }
    }
    #[inline(always)]
    fn abs(self, a: f32) -> f32 {
        a.abs()
    }
    #[inline(always)]
    fn any(self, m: bool) -> bool {
        m
    }
    #[inline(always)]
    fn gather(self, table: &[f32], i: f32) -> f32 {
        table[(i.max(0.0) as usize).min(table.len() - 1)]
    }
    #[inline(always)]
    fn exp2i(self, n: f32) -> f32 {
        f32::from_bits(((n as i32).wrapping_add(127) as u32) << 23)
    }
    #[inline(always)]
    fn frexp(self, x: f32) -> (f32, f32) {
        let b = x.to_bits();
        let e = ((b >> 23) as i32) - 127;
        (f32::from_bits((b & 0x007f_ffff) | 0x3f80_0000), e as f32)
    }
}

// ---------------------------------------------------------------- x86

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{Avx2, Avx512};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::Lanes;
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

    /// Binary operators of a vector type by one intrinsic each.
    macro_rules! binary_ops {
        ($ty:ident, $($trait:ident $method:ident $intrinsic:ident),*) => {$(
            impl $trait for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $method(self, o: $ty) -> $ty {
                    // SAFETY: a value of this type exists only when its
                    // level's token was made, i.e. the CPU has the feature.
                    $ty(unsafe { $intrinsic(self.0, o.0) })
                }
            }
        )*};
    }

    // ------------------------------------------------------------ AVX2

    /// AVX2 + FMA, 8 lanes. Made only by [`Avx2::new`].
    #[derive(Debug, Clone, Copy)]
    pub(crate) struct Avx2(());

    impl Avx2 {
        /// The token, if this CPU has AVX2 and FMA.
        #[must_use]
        pub(crate) fn new() -> Option<Self> {
            (is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"))
                .then_some(Avx2(()))
        }
    }

    #[derive(Clone, Copy)]
    pub(crate) struct F8(__m256);
    /// All bits set in a lane that is true.
    #[derive(Clone, Copy)]
    pub(crate) struct M8(__m256);

    binary_ops!(F8, Add add _mm256_add_ps, Sub sub _mm256_sub_ps, Mul mul _mm256_mul_ps, Div div _mm256_div_ps);
    binary_ops!(M8, BitAnd bitand _mm256_and_ps, BitOr bitor _mm256_or_ps);

    impl Neg for F8 {
        type Output = F8;
        #[inline(always)]
        fn neg(self) -> F8 {
            // SAFETY: F8 exists only with AVX2 (see `Avx2::new`).
            F8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
        }
    }

    impl Not for M8 {
        type Output = M8;
        #[inline(always)]
        fn not(self) -> M8 {
            // SAFETY: M8 exists only with AVX2 (see `Avx2::new`).
            M8(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
        }
    }

    impl Lanes for Avx2 {
        const N: usize = 8;
        const ALIGN: usize = 32;
        type F = F8;
        type M = M8;

        #[inline(always)]
        fn splat(self, x: f32) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        unsafe fn load_ptr(self, p: *const f32) -> F8 {
            // SAFETY: the token proves AVX2; the caller, that `p` holds 8 readable f32.
            F8(unsafe { _mm256_loadu_ps(p) })
        }
        #[inline(always)]
        unsafe fn store_ptr(self, v: F8, p: *mut f32) {
            // SAFETY: the token proves AVX2; the caller, that `p` holds 8 writable f32.
            unsafe { _mm256_storeu_ps(p, v.0) }
        }
        #[inline(always)]
        unsafe fn stream_ptr(self, v: F8, p: *mut f32) {
            // SAFETY: the token proves AVX2; the caller, that `p` holds 8
            // writable f32 and is 32-byte aligned.
            unsafe { _mm256_stream_ps(p, v.0) }
        }
        #[inline(always)]
        fn fence(self) {
            // SAFETY: SSE is part of the x86-64 baseline.
            unsafe { _mm_sfence() }
        }
        #[inline(always)]
        unsafe fn store_mask_ptr(self, m: M8, p: *mut u8) {
            // SAFETY: the token proves AVX2; the caller, that `p` holds 8 writable bytes. A
            // mask lane is all ones or all zeros (compares and their bitwise
            // combinations), so the saturating packs give −1 or 0 per byte.
            unsafe {
                let v = _mm256_castps_si256(m.0);
                let w =
                    _mm_packs_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256::<1>(v));
                let b = _mm_and_si128(_mm_packs_epi16(w, w), _mm_set1_epi8(1));
                _mm_storel_epi64(p.cast(), b);
            }
        }
        #[inline(always)]
        fn mul_add(self, a: F8, b: F8, c: F8) -> F8 {
            // SAFETY: the token proves FMA.
            F8(unsafe { _mm256_fmadd_ps(a.0, b.0, c.0) })
        }
        #[inline(always)]
        fn sqrt(self, a: F8) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(unsafe { _mm256_sqrt_ps(a.0) })
        }
        #[inline(always)]
        fn min(self, a: F8, b: F8) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(unsafe { _mm256_min_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn max(self, a: F8, b: F8) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(unsafe { _mm256_max_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn round(self, a: F8) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(
                unsafe {
                    _mm256_round_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(a.0)
                },
            )
        }
        #[inline(always)]
        fn floor(self, a: F8) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(unsafe { _mm256_round_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(a.0) })
        }
        #[inline(always)]
        fn lt(self, a: F8, b: F8) -> M8 {
            // SAFETY: the token proves AVX2.
            M8(unsafe { _mm256_cmp_ps::<_CMP_LT_OQ>(a.0, b.0) })
        }
        #[inline(always)]
        fn gt(self, a: F8, b: F8) -> M8 {
            // SAFETY: the token proves AVX2.
            M8(unsafe { _mm256_cmp_ps::<_CMP_GT_OQ>(a.0, b.0) })
        }
        #[inline(always)]
        fn eq(self, a: F8, b: F8) -> M8 {
            // SAFETY: the token proves AVX2.
            M8(unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(a.0, b.0) })
        }
        #[inline(always)]
        fn select(self, m: M8, a: F8, b: F8) -> F8 {
            // SAFETY: the token proves AVX2. blendv takes the second
            // operand where the mask's sign bit is set.
            F8(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
        }
        #[inline(always)]
        fn abs(self, a: F8) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), a.0) })
        }
        #[inline(always)]
        fn any(self, m: M8) -> bool {
            // SAFETY: the token proves AVX2.
            unsafe { _mm256_movemask_ps(m.0) != 0 }
        }
        #[inline(always)]
        fn gather(self, table: &[f32], i: F8) -> F8 {
            assert!(!table.is_empty() && table.len() <= i32::MAX as usize);
            let top = (table.len() - 1) as f32;
            // SAFETY: the token proves AVX2; the indices are clamped into
            // [0, len − 1], so every lane reads inside `table`.
            F8(unsafe {
                let c = _mm256_min_ps(_mm256_max_ps(i.0, _mm256_setzero_ps()), _mm256_set1_ps(top));
                _mm256_i32gather_ps::<4>(table.as_ptr(), _mm256_cvttps_epi32(c))
            })
        }
        #[inline(always)]
        fn exp2i(self, n: F8) -> F8 {
            // SAFETY: the token proves AVX2.
            F8(unsafe {
                let i = _mm256_add_epi32(_mm256_cvtps_epi32(n.0), _mm256_set1_epi32(127));
                _mm256_castsi256_ps(_mm256_slli_epi32::<23>(i))
            })
        }
        #[inline(always)]
        fn frexp(self, x: F8) -> (F8, F8) {
            // SAFETY: the token proves AVX2.
            unsafe {
                let b = _mm256_castps_si256(x.0);
                let e = _mm256_sub_epi32(_mm256_srli_epi32::<23>(b), _mm256_set1_epi32(127));
                let m = _mm256_or_si256(
                    _mm256_and_si256(b, _mm256_set1_epi32(0x007f_ffff)),
                    _mm256_set1_epi32(0x3f80_0000),
                );
                (F8(_mm256_castsi256_ps(m)), F8(_mm256_cvtepi32_ps(e)))
            }
        }
    }

    // ------------------------------------------------------------ AVX-512

    /// AVX-512F/DQ/BW/VL, 16 lanes. Made only by [`Avx512::new`].
    #[derive(Debug, Clone, Copy)]
    pub(crate) struct Avx512(());

    impl Avx512 {
        /// The token, if this CPU has AVX-512F, DQ, BW and VL (and FMA).
        #[must_use]
        pub(crate) fn new() -> Option<Self> {
            (is_x86_feature_detected!("avx512f")
                && is_x86_feature_detected!("avx512dq")
                && is_x86_feature_detected!("avx512bw")
                && is_x86_feature_detected!("avx512vl")
                && is_x86_feature_detected!("fma"))
            .then_some(Avx512(()))
        }
    }

    #[derive(Clone, Copy)]
    pub(crate) struct F16(__m512);
    /// One bit per lane.
    #[derive(Clone, Copy)]
    pub(crate) struct M16(__mmask16);

    binary_ops!(F16, Add add _mm512_add_ps, Sub sub _mm512_sub_ps, Mul mul _mm512_mul_ps, Div div _mm512_div_ps);

    impl Neg for F16 {
        type Output = F16;
        #[inline(always)]
        fn neg(self) -> F16 {
            // SAFETY: F16 exists only with AVX-512 (see `Avx512::new`).
            F16(unsafe {
                _mm512_castsi512_ps(_mm512_xor_si512(
                    _mm512_castps_si512(self.0),
                    _mm512_set1_epi32(i32::MIN),
                ))
            })
        }
    }

    // Masks are plain bit sets: no intrinsic needed.
    impl BitAnd for M16 {
        type Output = M16;
        #[inline(always)]
        fn bitand(self, o: M16) -> M16 {
            M16(self.0 & o.0)
        }
    }
    impl BitOr for M16 {
        type Output = M16;
        #[inline(always)]
        fn bitor(self, o: M16) -> M16 {
            M16(self.0 | o.0)
        }
    }
    impl Not for M16 {
        type Output = M16;
        #[inline(always)]
        fn not(self) -> M16 {
            M16(!self.0)
        }
    }

    impl Lanes for Avx512 {
        const N: usize = 16;
        const ALIGN: usize = 64;
        type F = F16;
        type M = M16;

        #[inline(always)]
        fn splat(self, x: f32) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe { _mm512_set1_ps(x) })
        }
        #[inline(always)]
        unsafe fn load_ptr(self, p: *const f32) -> F16 {
            // SAFETY: the token proves AVX-512F; the caller, that `p` holds 16 readable f32.
            F16(unsafe { _mm512_loadu_ps(p) })
        }
        #[inline(always)]
        unsafe fn store_ptr(self, v: F16, p: *mut f32) {
            // SAFETY: the token proves AVX-512F; the caller, that `p` holds 16 writable f32.
            unsafe { _mm512_storeu_ps(p, v.0) }
        }
        #[inline(always)]
        unsafe fn stream_ptr(self, v: F16, p: *mut f32) {
            // SAFETY: the token proves AVX-512F; the caller, that `p` holds
            // 16 writable f32 and is 64-byte aligned.
            unsafe { _mm512_stream_ps(p, v.0) }
        }
        #[inline(always)]
        fn fence(self) {
            // SAFETY: SSE is part of the x86-64 baseline.
            unsafe { _mm_sfence() }
        }
        #[inline(always)]
        unsafe fn store_mask_ptr(self, m: M16, p: *mut u8) {
            // SAFETY: the token proves AVX-512BW and VL; the caller, that
            // `p` holds 16 writable bytes.
            unsafe {
                let v = _mm_maskz_mov_epi8(m.0, _mm_set1_epi8(1));
                _mm_storeu_si128(p.cast(), v);
            }
        }
        #[inline(always)]
        fn mul_add(self, a: F16, b: F16, c: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe { _mm512_fmadd_ps(a.0, b.0, c.0) })
        }
        #[inline(always)]
        fn sqrt(self, a: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe { _mm512_sqrt_ps(a.0) })
        }
        #[inline(always)]
        fn min(self, a: F16, b: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe { _mm512_min_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn max(self, a: F16, b: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe { _mm512_max_ps(a.0, b.0) })
        }
        #[inline(always)]
        fn round(self, a: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe {
                _mm512_roundscale_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(a.0)
            })
        }
        #[inline(always)]
        fn floor(self, a: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe {
                _mm512_roundscale_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(a.0)
            })
        }
        #[inline(always)]
        fn lt(self, a: F16, b: F16) -> M16 {
            // SAFETY: the token proves AVX-512F.
            M16(unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(a.0, b.0) })
        }
        #[inline(always)]
        fn gt(self, a: F16, b: F16) -> M16 {
            // SAFETY: the token proves AVX-512F.
            M16(unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(a.0, b.0) })
        }
        #[inline(always)]
        fn eq(self, a: F16, b: F16) -> M16 {
            // SAFETY: the token proves AVX-512F.
            M16(unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(a.0, b.0) })
        }
        #[inline(always)]
        fn select(self, m: M16, a: F16, b: F16) -> F16 {
            // SAFETY: the token proves AVX-512F. blend takes the second
            // operand where the mask bit is set.
            F16(unsafe { _mm512_mask_blend_ps(m.0, b.0, a.0) })
        }
        #[inline(always)]
        fn abs(self, a: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe { _mm512_abs_ps(a.0) })
        }
        #[inline(always)]
        fn any(self, m: M16) -> bool {
            m.0 != 0
        }
        #[inline(always)]
        fn gather(self, table: &[f32], i: F16) -> F16 {
            assert!(!table.is_empty() && table.len() <= i32::MAX as usize);
            let top = (table.len() - 1) as f32;
            // SAFETY: the token proves AVX-512F; the indices are clamped
            // into [0, len − 1], so every lane reads inside `table`.
            F16(unsafe {
                let c = _mm512_min_ps(_mm512_max_ps(i.0, _mm512_setzero_ps()), _mm512_set1_ps(top));
                _mm512_i32gather_ps::<4>(_mm512_cvttps_epi32(c), table.as_ptr())
            })
        }
        #[inline(always)]
        fn exp2i(self, n: F16) -> F16 {
            // SAFETY: the token proves AVX-512F.
            F16(unsafe {
                let i = _mm512_add_epi32(_mm512_cvtps_epi32(n.0), _mm512_set1_epi32(127));
                _mm512_castsi512_ps(_mm512_slli_epi32::<23>(i))
            })
        }
        #[inline(always)]
        fn frexp(self, x: F16) -> (F16, F16) {
            // SAFETY: the token proves AVX-512F.
            unsafe {
                let b = _mm512_castps_si512(x.0);
                let e = _mm512_sub_epi32(_mm512_srli_epi32::<23>(b), _mm512_set1_epi32(127));
                let m = _mm512_or_si512(
                    _mm512_and_si512(b, _mm512_set1_epi32(0x007f_ffff)),
                    _mm512_set1_epi32(0x3f80_0000),
                );
                (F16(_mm512_castsi512_ps(m)), F16(_mm512_cvtepi32_ps(e)))
            }
        }
    }
}

// ------------------------------------------------------------ two vectors

/// Two vectors of a level side by side (`2 N` lanes): every operation is
/// the level's, twice, on independent data. The kernels' dependency chains
/// (square root, division, reflection, square root, division) are long;
/// two interleaved chains keep the core's pipelines busy where one leaves
/// them waiting. Lane for lane the same operations as `L`: the same bits.
#[derive(Debug, Clone, Copy)]
pub(crate) struct X2<L>(pub L);

/// A pair of vectors or masks of [`X2`].
#[derive(Clone, Copy)]
pub(crate) struct Pair<T>(T, T);

macro_rules! pair_ops {
    ($($tr:ident $method:ident),*) => {$(
        impl<T: $tr<Output = T>> $tr for Pair<T> {
            type Output = Pair<T>;
            #[inline(always)]
            fn $method(self, o: Pair<T>) -> Pair<T> {
                Pair(self.0.$method(o.0), self.1.$method(o.1))
            }
        }
    )*};
}
pair_ops!(Add add, Sub sub, Mul mul, Div div, BitAnd bitand, BitOr bitor);

impl<T: Neg<Output = T>> Neg for Pair<T> {
    type Output = Pair<T>;
    #[inline(always)]
    fn neg(self) -> Pair<T> {
        Pair(-self.0, -self.1)
    }
}

impl<T: Not<Output = T>> Not for Pair<T> {
    type Output = Pair<T>;
    #[inline(always)]
    fn not(self) -> Pair<T> {
        Pair(!self.0, !self.1)
    }
}

impl<L: Lanes> Lanes for X2<L> {
    const N: usize = 2 * L::N;
    const ALIGN: usize = L::ALIGN;
    type F = Pair<L::F>;
    type M = Pair<L::M>;

    #[inline(always)]
    fn splat(self, x: f32) -> Self::F {
        let v = self.0.splat(x);
        Pair(v, v)
    }
    #[inline(always)]
    unsafe fn load_ptr(self, p: *const f32) -> Self::F {
        // SAFETY: the caller's `2 L::N` values are two runs of `L::N`.
        unsafe { Pair(self.0.load_ptr(p), self.0.load_ptr(p.add(L::N))) }
    }
    #[inline(always)]
    unsafe fn store_ptr(self, v: Self::F, p: *mut f32) {
        // SAFETY: as for `load_ptr`.
        unsafe {
            self.0.store_ptr(v.0, p);
            self.0.store_ptr(v.1, p.add(L::N));
        }
    }
    #[inline(always)]
    unsafe fn store_mask_ptr(self, m: Self::M, p: *mut u8) {
        // SAFETY: as for `load_ptr`.
        unsafe {
            self.0.store_mask_ptr(m.0, p);
            self.0.store_mask_ptr(m.1, p.add(L::N));
        }
    }
    #[inline(always)]
    unsafe fn stream_ptr(self, v: Self::F, p: *mut f32) {
        // SAFETY: as for `load_ptr`; `p` is aligned to `L::ALIGN` bytes,
        // and so is `p + L::N` (`L::ALIGN` divides `4 L::N`).
        unsafe {
            self.0.stream_ptr(v.0, p);
            self.0.stream_ptr(v.1, p.add(L::N));
        }
    }
    #[inline(always)]
    fn fence(self) {
        self.0.fence();
    }
    #[inline(always)]
    fn mul_add(self, a: Self::F, b: Self::F, c: Self::F) -> Self::F {
        Pair(self.0.mul_add(a.0, b.0, c.0), self.0.mul_add(a.1, b.1, c.1))
    }
    #[inline(always)]
    fn sqrt(self, a: Self::F) -> Self::F {
        Pair(self.0.sqrt(a.0), self.0.sqrt(a.1))
    }
    #[inline(always)]
    fn min(self, a: Self::F, b: Self::F) -> Self::F {
        Pair(self.0.min(a.0, b.0), self.0.min(a.1, b.1))
    }
    #[inline(always)]
    fn max(self, a: Self::F, b: Self::F) -> Self::F {
        Pair(self.0.max(a.0, b.0), self.0.max(a.1, b.1))
    }
    #[inline(always)]
    fn round(self, a: Self::F) -> Self::F {
        Pair(self.0.round(a.0), self.0.round(a.1))
    }
    #[inline(always)]
    fn floor(self, a: Self::F) -> Self::F {
        Pair(self.0.floor(a.0), self.0.floor(a.1))
    }
    #[inline(always)]
    fn lt(self, a: Self::F, b: Self::F) -> Self::M {
        Pair(self.0.lt(a.0, b.0), self.0.lt(a.1, b.1))
    }
    #[inline(always)]
    fn gt(self, a: Self::F, b: Self::F) -> Self::M {
        Pair(self.0.gt(a.0, b.0), self.0.gt(a.1, b.1))
    }
    #[inline(always)]
    fn eq(self, a: Self::F, b: Self::F) -> Self::M {
        Pair(self.0.eq(a.0, b.0), self.0.eq(a.1, b.1))
    }
    #[inline(always)]
    fn select(self, m: Self::M, a: Self::F, b: Self::F) -> Self::F {
        Pair(self.0.select(m.0, a.0, b.0), self.0.select(m.1, a.1, b.1))
    }
    #[inline(always)]
    fn abs(self, a: Self::F) -> Self::F {
        Pair(self.0.abs(a.0), self.0.abs(a.1))
    }
    #[inline(always)]
    fn any(self, m: Self::M) -> bool {
        self.0.any(m.0) | self.0.any(m.1)
    }
    #[inline(always)]
    fn gather(self, table: &[f32], i: Self::F) -> Self::F {
        Pair(self.0.gather(table, i.0), self.0.gather(table, i.1))
    }
    #[inline(always)]
    fn exp2i(self, n: Self::F) -> Self::F {
        Pair(self.0.exp2i(n.0), self.0.exp2i(n.1))
    }
    #[inline(always)]
    fn frexp(self, x: Self::F) -> (Self::F, Self::F) {
        let (m0, e0) = self.0.frexp(x.0);
        let (m1, e1) = self.0.frexp(x.1);
        (Pair(m0, m1), Pair(e0, e1))
    }
    #[inline(always)]
    fn select_mask(self, m: Self::M, a: Self::M, b: Self::M) -> Self::M {
        Pair(
            self.0.select_mask(m.0, a.0, b.0),
            self.0.select_mask(m.1, a.1, b.1),
        )
    }
    #[inline(always)]
    fn is_finite(self, a: Self::F) -> Self::M {
        Pair(self.0.is_finite(a.0), self.0.is_finite(a.1))
    }
}
