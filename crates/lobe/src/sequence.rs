//! Sample sequences for the estimators: independent PCG streams, stratified
//! (jittered) points and Owen-scrambled Sobol points, each deterministic per
//! seed and each a function of the sample index alone (chunks of samples
//! can run on any thread in any order).
//!
//! Each sample takes three numbers: `uc` (lobe choice) and `u = (u₁, u₂)`.
//!
//! Sobol is written here rather than taken from `sobol_burley`, whose
//! sequences stop at 2¹⁶ points: `lobe converge` goes to 2²⁰. The
//! generator matrices are Joe and Kuo's for the first four dimensions and
//! the scrambling is Burley's hash-based nested uniform (Owen) scramble
//! (Burley 2020, "Practical Hash-based Owen Scrambling").

use rand::RngExt;
use rand_pcg::Pcg64;

/// Samples per chunk: the unit of work and of random streams.
pub const CHUNK: usize = 4096;

/// The random stream of chunk `chunk` for `seed`.
#[must_use]
pub fn chunk_rng(seed: u64, chunk: usize) -> Pcg64 {
    // Distinct PCG streams per chunk (the increment selects the stream).
    Pcg64::new(
        0xcafe_f00d_d15e_a5e5u128 ^ (u128::from(seed) << 64),
        0x0a02_bdbf_7bb3_c0a7_ac28_fa16_a64a_bf96u128 ^ (chunk as u128),
    )
}

/// How the samples of an estimate are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sequence {
    /// Independent uniform numbers from a PCG stream per chunk.
    Independent,
    /// Jittered: one point per cell of an `nx × ny` grid over `u` when `N`
    /// factors as `nx·ny` with an aspect of at most 4 (every power of two
    /// does: `2^k × 2^k` or `2^k × 2^(k+1)`), otherwise Latin hypercube (every
    /// 1D projection stratified); `uc` is stratified in 1D. Unbiased for
    /// every `N`.
    Stratified,
    /// Owen-scrambled Sobol points, up to 2³² of them.
    Sobol,
}

impl Sequence {
    pub const ALL: [Sequence; 3] = [Sequence::Independent, Sequence::Stratified, Sequence::Sobol];

    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Sequence::Independent => "independent",
            Sequence::Stratified => "stratified",
            Sequence::Sobol => "sobol",
        }
    }
}

impl std::fmt::Display for Sequence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Sequence {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Sequence::ALL
            .into_iter()
            .find(|x| x.name() == s)
            .ok_or_else(|| crate::Error::UnknownName {
                field: "sequence".into(),
                value: s.into(),
                expected: "independent, stratified, sobol".into(),
            })
    }
}

/// The seed of stream `stream` of an estimate seeded with `seed`: stream 0
/// is `seed` itself; every other stream is an independent randomization
/// (its own scramble, permutation and jitter). Each technique of
/// multi-sample MIS draws from its own stream, so that each is as well
/// distributed as a sequence alone.
#[must_use]
pub fn stream_seed(seed: u64, stream: usize) -> u64 {
    if stream == 0 {
        seed
    } else {
        hash64(seed ^ hash64(0x4d49_535f_5354_524d ^ stream as u64))
    }
}

/// The seed of replica `replica` of an estimate seeded with `seed`: an
/// independent randomization of the whole sequence (its own scramble,
/// permutation and jitter), for error estimates from independent replicas
/// of a stratified or Sobol estimate. A domain apart from [`stream_seed`]:
/// no replica shares a seed with a stream of another (or of itself), so the
/// MIS streams inside a replica stay independent of every other replica.
#[must_use]
pub fn replica_seed(seed: u64, replica: usize) -> u64 {
    hash64(hash64(seed ^ 0x5245_504c_4943_4153) ^ hash64(0x7265_706c_6963_6100 ^ replica as u64))
}

/// Fill `out` with the points `first .. first + out.len()` of an `n`-point
/// sequence; `chunk` names the chunk (for the independent streams).
pub fn fill(seq: Sequence, seed: u64, n: usize, chunk: usize, first: usize, out: &mut [[f64; 3]]) {
    match seq {
        Sequence::Independent => {
            let mut rng = chunk_rng(seed, chunk);
            for p in out.iter_mut() {
                *p = [rng.random(), rng.random(), rng.random()];
            }
        }
        Sequence::Stratified => {
            let mut rng = chunk_rng(seed ^ 0x5354_5241_5449_4659, chunk);
            let (nx, ny) = grid_shape(n);
            let grid = nx > 0;
            let s = hash64(seed);
            for (k, p) in out.iter_mut().enumerate() {
                let i = (first + k) as u64;
                let (j1, j2, j3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
                let nn = n as u64;
                let uc = (permute(i, nn, s as u32) as f64 + j3) / n as f64;
                if grid {
                    let (x, y) = (i % nx as u64, i / nx as u64);
                    p[1] = (x as f64 + j1) / nx as f64;
                    p[2] = (y as f64 + j2) / ny as f64;
                } else {
                    p[1] = (permute(i, nn, (s >> 32) as u32) as f64 + j1) / n as f64;
                    p[2] = (permute(i, nn, (s >> 16) as u32 ^ 0x9e37) as f64 + j2) / n as f64;
                }
                p[0] = uc.min(ONE_MINUS_EPS);
                p[1] = p[1].min(ONE_MINUS_EPS);
                p[2] = p[2].min(ONE_MINUS_EPS);
            }
        }
        Sequence::Sobol => {
            let s = hash64(seed);
            let seeds = [s as u32, (s >> 32) as u32, hash64(s) as u32];
            for (k, p) in out.iter_mut().enumerate() {
                let i = (first + k) as u32;
                // Shuffle the order of the points too (Burley, section 4).
                let idx = nested_uniform_scramble(i, hash64(s ^ 0x1234) as u32);
                for d in 0..3 {
                    let x = nested_uniform_scramble(sobol(idx, d), seeds[d]);
                    p[d] = (f64::from(x) + 0.5) / 4_294_967_296.0;
                }
            }
        }
    }
}

/// `(nx, ny)` with `nx·ny = n`, `nx ≤ ny ≤ 4 nx`, `nx` as large as possible;
/// `(0, 0)` when `n` has no such factorization.
#[must_use]
pub fn grid_shape(n: usize) -> (usize, usize) {
    let mut nx = (n as f64).sqrt().floor() as usize;
    while nx > 0 {
        if n.is_multiple_of(nx) {
            let ny = n / nx;
            return if ny <= 4 * nx { (nx, ny) } else { (0, 0) };
        }
        nx -= 1;
    }
    (0, 0)
}

const ONE_MINUS_EPS: f64 = 1.0 - f64::EPSILON / 2.0;

/// Joe–Kuo direction numbers: (degree, coefficients, initial m) for
/// dimensions 2, 3, 4; dimension 1 is the van der Corput sequence.
const JOE_KUO: [(u32, u32, [u32; 3]); 3] =
    [(1, 0, [1, 0, 0]), (2, 1, [1, 3, 0]), (3, 1, [1, 3, 1])];

const fn matrices() -> [[u32; 32]; 4] {
    let mut v = [[0u32; 32]; 4];
    let mut k = 0;
    while k < 32 {
        v[0][k] = 1u32 << (31 - k);
        k += 1;
    }
    let mut d = 0;
    while d < 3 {
        let (s, a, m0) = JOE_KUO[d];
        let s = s as usize;
        let mut m = [0u32; 32];
        let mut k = 0;
        while k < 32 {
            if k < s {
                m[k] = m0[k];
            } else {
                let mut x = m[k - s] ^ (m[k - s] << s);
                let mut j = 1;
                while j < s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        x ^= m[k - j] << j;
                    }
                    j += 1;
                }
                m[k] = x;
            }
            k += 1;
        }
        let mut k = 0;
        while k < 32 {
            v[d + 1][k] = m[k] << (31 - k);
            k += 1;
        }
        d += 1;
    }
    v
}

#[cfg(test)]
static SOBOL_MATRICES: [[u32; 32]; 4] = matrices();

/// `SOBOL_BYTES[d][b][v]`: the xor of the generator columns of dimension
/// `d` selected by the bits of byte value `v` at byte `b` of the index, so
/// that a point is four table lookups instead of a loop over 32 bits.
const fn byte_tables() -> [[[u32; 256]; 4]; 4] {
    let m = matrices();
    let mut t = [[[0u32; 256]; 4]; 4];
    let mut d = 0;
    while d < 4 {
        let mut b = 0;
        while b < 4 {
            let mut v = 0;
            while v < 256 {
                let mut x = 0u32;
                let mut k = 0;
                while k < 8 {
                    if (v >> k) & 1 == 1 {
                        x ^= m[d][8 * b + k];
                    }
                    k += 1;
                }
                t[d][b][v] = x;
                v += 1;
            }
            b += 1;
        }
        d += 1;
    }
    t
}

static SOBOL_BYTES: [[[u32; 256]; 4]; 4] = byte_tables();

/// The byte tables of the bit-reversed point of a bit-reversed index:
/// `SOBOL_REV[d]` applied to `i.reverse_bits()` gives
/// `sobol(i, d).reverse_bits()`. Burley's scramble works on reversed bits,
/// so a pair stays in reversed order between its scrambles. The pairs use
/// the table-free forms ([`pascal_reversed`]); the tests check them
/// against these tables.
#[cfg(test)]
const fn reversed_tables() -> [[[u32; 256]; 4]; 4] {
    let m = matrices();
    let mut t = [[[0u32; 256]; 4]; 4];
    let mut d = 0;
    while d < 4 {
        let mut b = 0;
        while b < 4 {
            let mut v = 0;
            while v < 256 {
                let mut x = 0u32;
                let mut k = 0;
                while k < 8 {
                    if (v >> k) & 1 == 1 {
                        x ^= m[d][31 - (8 * b + k)].reverse_bits();
                    }
                    k += 1;
                }
                t[d][b][v] = x;
                v += 1;
            }
            b += 1;
        }
        d += 1;
    }
    t
}

#[cfg(test)]
static SOBOL_REV: [[[u32; 256]; 4]; 4] = reversed_tables();

/// `sobol(r.reverse_bits(), d).reverse_bits()`.
#[cfg(test)]
fn sobol_reversed(r: u32, d: usize) -> u32 {
    let t = &SOBOL_REV[d];
    t[0][(r & 0xff) as usize]
        ^ t[1][((r >> 8) & 0xff) as usize]
        ^ t[2][((r >> 16) & 0xff) as usize]
        ^ t[3][(r >> 24) as usize]
}

/// Point `i` of the unscrambled Sobol sequence in dimension `d` (< 4), as a
/// 32-bit fixed-point fraction.
#[inline]
#[must_use]
pub fn sobol(i: u32, d: usize) -> u32 {
    let t = &SOBOL_BYTES[d];
    t[0][(i & 0xff) as usize]
        ^ t[1][((i >> 8) & 0xff) as usize]
        ^ t[2][((i >> 16) & 0xff) as usize]
        ^ t[3][(i >> 24) as usize]
}

/// Point `i` of dimension `d` by the loop over the index's bits (the
/// reference for the byte tables).
#[cfg(test)]
fn sobol_by_bits(mut i: u32, d: usize) -> u32 {
    let mut x = 0;
    let mut k = 0;
    while i != 0 {
        if i & 1 == 1 {
            x ^= SOBOL_MATRICES[d][k];
        }
        i >>= 1;
        k += 1;
    }
    x
}

/// Burley's nested uniform scramble: a Laine–Karras-style hash on the
/// reversed bits, so that each bit is flipped by a hash of the bits above it.
#[must_use]
pub fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// The hash of [`nested_uniform_scramble`] on bits already reversed.
#[inline]
fn laine_karras(mut v: u32, seed: u32) -> u32 {
    v = v.wrapping_add(seed);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v
}

/// A 64-bit mixing hash (SplitMix64's finalizer).
#[must_use]
pub fn hash64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// A pseudo-random permutation of `0..n` evaluated at `i`, without memory:
/// a bijective hash on the next power of two, walked until it lands inside
/// `0..n` (cycle walking; Kensler 2013).
#[must_use]
pub fn permute(i: u64, n: u64, seed: u32) -> u64 {
    debug_assert!(i < n);
    if n <= 1 {
        return 0;
    }
    let bits = 64 - (n - 1).leading_zeros();
    let mask = if bits == 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    };
    let key = hash64(u64::from(seed));
    let mut x = i;
    loop {
        // An invertible map on `bits`-bit integers: xor-shifts and odd multiplications.
        x ^= key & mask;
        x = x.wrapping_mul(0x9e37_79b9_7f4a_7c15 | 1) & mask;
        x ^= (x >> (bits / 2 + 1)) & mask;
        x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9 | 1) & mask;
        x ^= (x >> (bits / 3 + 1)) & mask;
        x = (x ^ (key >> 32)) & mask;
        if x < n {
            return x;
        }
    }
}

/// Point `index` of an `n`-point pattern in dimension pair `dim`, for an
/// integrator that draws many dimensions per sample (a renderer's pixel:
/// the lens position, then per bounce the BSDF's direction and lobe choice,
/// the light sample, the path's continuation, Russian roulette).
///
/// Each pair is its own randomization of a 2D pattern, decorrelated from
/// every other pair by its own shuffle of the sample index (the "padding"
/// of Burley 2020, §4), so that every pair is as well distributed as a 2D
/// pattern alone, for every `n`:
/// * [`Sequence::Independent`]: hashed uniform numbers (a function of
///   `(seed, dim, index)`, so any sample can be drawn in any order);
/// * [`Sequence::Stratified`]: one jittered point per cell of an `nx × ny`
///   grid ([`grid_shape`]) in a per-pair random order, or a Latin hypercube
///   where `n` has no such grid;
/// * [`Sequence::Sobol`]: Sobol dimensions 1 and 2 (a (0, 2)-sequence),
///   the index shuffled and each coordinate Owen-scrambled per pair
///   (Burley's hash-based nested uniform scramble). Indices beyond `n` go
///   on with the same sequence (progressive rendering); `index` must be
///   below 2³².
///
/// `seed` selects the randomization (one per pixel); `n` matters only to
/// `Stratified`. The numbers are in [0, 1).
#[inline]
#[must_use]
pub fn pair_point(seq: Sequence, seed: u64, n: u64, index: u64, dim: u32) -> [f64; 2] {
    pair_point_seeded(seq, pair_seed(seed, dim), n, index)
}

/// The randomization of dimension pair `dim` under `seed`, the first step
/// of [`pair_point`]: a caller that draws many samples of one pair (a
/// renderer's pixel) computes it once and calls [`pair_point_seeded`].
#[inline]
#[must_use]
pub fn pair_seed(seed: u64, dim: u32) -> u64 {
    hash64(seed ^ hash64(0x7061_6972_0000_0000 ^ u64::from(dim)))
}

/// [`pair_point`] with the pair's randomization `s = pair_seed(seed, dim)`
/// already computed: `pair_point_seeded(q, pair_seed(seed, d), n, i)` is
/// `pair_point(q, seed, n, i, d)`, bit for bit.
#[inline]
#[must_use]
pub fn pair_point_seeded(seq: Sequence, s: u64, n: u64, index: u64) -> [f64; 2] {
    let unit = |bits: u64| (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
    match seq {
        Sequence::Independent => {
            let a = hash64(s ^ hash64(index));
            [unit(a), unit(hash64(a ^ 0x5eed))]
        }
        Sequence::Stratified => {
            let n = n.max(1);
            debug_assert!(index < n);
            let j = hash64(s ^ hash64(index ^ 0x6a69_7474_6572));
            let (jx, jy) = (unit(j), unit(hash64(j)));
            let (nx, ny) = grid_shape(n as usize);
            let (x, y) = if nx > 0 {
                let cell = permute(index, n, s as u32);
                let (cx, cy) = (cell % nx as u64, cell / nx as u64);
                ((cx as f64 + jx) / nx as f64, (cy as f64 + jy) / ny as f64)
            } else {
                let px = permute(index, n, s as u32);
                let py = permute(index, n, (s >> 32) as u32);
                ((px as f64 + jx) / n as f64, (py as f64 + jy) / n as f64)
            };
            [x.min(ONE_MINUS_EPS), y.min(ONE_MINUS_EPS)]
        }
        Sequence::Sobol => {
            debug_assert!(index <= u64::from(u32::MAX));
            let (x, y) = SobolKeys::new(s).point(index as u32);
            let k = 1.0 / 4_294_967_296.0;
            [f64::from(x) * k, f64::from(y) * k]
        }
    }
}

/// The three 32-bit keys of a Sobol pair's randomization
/// `s = pair_seed(seed, dim)`: the index shuffle's and each coordinate's
/// Owen scramble. [`sobol_pairs`] takes them computed once per pixel and
/// pair, so that its lanes need no 64-bit hash.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SobolKeys {
    index: u32,
    x: u32,
    y: u32,
}

impl SobolKeys {
    /// The keys of randomization `s` ([`pair_seed`]).
    #[inline]
    #[must_use]
    pub fn new(s: u64) -> Self {
        SobolKeys {
            index: s as u32,
            x: (s >> 32) as u32,
            y: hash64(s) as u32,
        }
    }

    /// Point `index` as 32-bit fixed-point coordinates:
    /// `nested_uniform_scramble(sobol(nested_uniform_scramble(index)))` per
    /// coordinate, kept in reversed bit order in between; dimension 0's
    /// matrix product is the bit reversal and dimension 1's
    /// [`pascal_reversed`].
    #[inline(always)]
    fn point(self, index: u32) -> (u32, u32) {
        let q = laine_karras(index.reverse_bits(), self.index).reverse_bits();
        let x = laine_karras(q, self.x).reverse_bits();
        let y = laine_karras(pascal_reversed(q), self.y).reverse_bits();
        (x, y)
    }
}

/// Sobol pairs of many samples at once: `(x[k], y[k])` is
/// `pair_point_seeded(Sequence::Sobol, s, _, index[k])` for
/// `seeds[k] = SobolKeys::new(s)`, bit for bit, computed in 32-bit SIMD
/// lanes at `level` (AVX-512 / AVX2 where the CPU has it, else portable
/// code): no table lookups, dimension 0's matrix product is a bit reversal
/// and dimension 1's five shift-and-xor steps (`pascal_reversed`).
///
/// # Panics
/// If the four slices differ in length.
pub fn sobol_pairs(
    level: crate::batch::SimdLevel,
    seeds: &[SobolKeys],
    index: &[u32],
    x: &mut [f64],
    y: &mut [f64],
) {
    assert!(
        seeds.len() == index.len() && x.len() == index.len() && y.len() == index.len(),
        "sobol_pairs: slices of different lengths"
    );
    #[cfg(target_arch = "x86_64")]
    {
        use crate::batch::SimdLevel;
        match level {
            // SAFETY: the level is available, so the CPU has its features.
            SimdLevel::Avx512 if level.is_available() => {
                return unsafe { sobol_pairs_avx512(seeds, index, x, y) };
            }
            SimdLevel::Avx2 if level.is_available() => {
                return unsafe { sobol_pairs_avx2(seeds, index, x, y) };
            }
            _ => {}
        }
    }
    let _ = level;
    sobol_pairs_lanes(seeds, index, x, y);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn sobol_pairs_avx2(seeds: &[SobolKeys], index: &[u32], x: &mut [f64], y: &mut [f64]) {
    sobol_pairs_lanes(seeds, index, x, y);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vl,avx2,fma")]
fn sobol_pairs_avx512(seeds: &[SobolKeys], index: &[u32], x: &mut [f64], y: &mut [f64]) {
    sobol_pairs_lanes(seeds, index, x, y);
}

/// `sobol_reversed(r, 1)` of `q = r.reverse_bits()`, without tables:
/// dimension 1's generator matrix is Pascal's triangle mod 2, so bit `l` of
/// the reversed point is the xor of the bits `k ⊇ l` (Lucas) of `q`: a
/// subset-sum transform over the five bit levels of the position, five
/// shift-and-xor steps on all 32 bits at once. (Dimension 0 is `q`.)
#[inline(always)]
fn pascal_reversed(q: u32) -> u32 {
    let mut w = q;
    w ^= (w >> 1) & 0x5555_5555;
    w ^= (w >> 2) & 0x3333_3333;
    w ^= (w >> 4) & 0x0f0f_0f0f;
    w ^= (w >> 8) & 0x00ff_00ff;
    w ^= (w >> 16) & 0x0000_ffff;
    w
}

/// [`sobol_pairs`] as one plain loop over the lanes (which the compiler
/// vectorizes at the caller's SIMD level).
#[inline(always)]
fn sobol_pairs_lanes(seeds: &[SobolKeys], index: &[u32], x: &mut [f64], y: &mut [f64]) {
    let k = 1.0 / 4_294_967_296.0;
    for (((&s, &i), xo), yo) in seeds.iter().zip(index).zip(x).zip(y) {
        let (xv, yv) = s.point(i);
        *xo = f64::from(xv) * k;
        *yo = f64::from(yv) * k;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pascal_reversed_is_dimension_one() {
        let mut r = 0x1234_5678u32;
        for k in 0..4000u32 {
            r = laine_karras(r, k);
            // Single bits, runs of ones, and hashed words.
            for v in [r, 1u32 << (k % 32), u32::MAX >> (k % 32)] {
                assert_eq!(
                    pascal_reversed(v.reverse_bits()),
                    sobol_reversed(v, 1),
                    "{v:#x}"
                );
                assert_eq!(v.reverse_bits(), sobol_reversed(v, 0), "{v:#x}");
            }
        }
    }

    #[test]
    fn sobol_pairs_match_pair_point_seeded_at_every_level() {
        use crate::batch::SimdLevel;
        // Lengths around the chunk size, indices of every magnitude.
        for n in [0usize, 1, 63, 64, 65, 200] {
            let seeds: Vec<u64> = (0..n as u64).map(|k| hash64(k / 7 + 3)).collect();
            let keys: Vec<SobolKeys> = seeds.iter().map(|&s| SobolKeys::new(s)).collect();
            let index: Vec<u32> = (0..n as u32)
                .map(|k| if k % 5 == 4 { u32::MAX - k } else { k * 977 })
                .collect();
            for level in SimdLevel::ALL.into_iter().filter(|l| l.is_available()) {
                let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
                sobol_pairs(level, &keys, &index, &mut x, &mut y);
                for k in 0..n {
                    let want = pair_point_seeded(Sequence::Sobol, seeds[k], 1, u64::from(index[k]));
                    assert_eq!([x[k], y[k]], want, "{level:?} lane {k} of {n}");
                }
            }
        }
    }

    /// The pairs of [`pair_point`]: every coordinate in [0, 1); Sobol's
    /// first 2^k points of a pair put one point in each of the 2^k
    /// elementary intervals of every shape (a (0, k, 2)-net), and two pairs
    /// are decorrelated (their joint 2D projection is not a net).
    #[test]
    fn pair_points_are_nets_per_pair_and_decorrelated_across_pairs() {
        let n = 256u64;
        for seq in Sequence::ALL {
            for i in 0..n {
                for d in 0..4 {
                    let p = pair_point(seq, 7, n, i, d);
                    assert!(p.iter().all(|x| (0.0..1.0).contains(x)), "{seq} {p:?}");
                }
            }
        }
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| pair_point(Sequence::Sobol, 3, n, i, 5))
            .collect();
        for kx in 0..=8u32 {
            let (bx, by) = (1u64 << kx, 1u64 << (8 - kx));
            let mut cells = vec![0u32; 256];
            for p in &pts {
                let cx = (p[0] * bx as f64) as u64;
                let cy = (p[1] * by as f64) as u64;
                cells[(cy * bx + cx) as usize] += 1;
            }
            assert!(cells.iter().all(|&c| c == 1), "shape {bx}x{by}");
        }
        // Stratified: one point per cell of the 16 × 16 grid.
        let mut cells = vec![0u32; 256];
        for i in 0..n {
            let p = pair_point(Sequence::Stratified, 3, n, i, 2);
            cells[(p[1] * 16.0) as usize * 16 + (p[0] * 16.0) as usize] += 1;
        }
        assert!(cells.iter().all(|&c| c == 1));
        // Across pairs: x of pair 0 against x of pair 1 is not a net in 16 × 16.
        let mut cells = vec![0u32; 256];
        for i in 0..n {
            let a = pair_point(Sequence::Sobol, 3, n, i, 0)[0];
            let b = pair_point(Sequence::Sobol, 3, n, i, 1)[0];
            cells[(b * 16.0) as usize * 16 + (a * 16.0) as usize] += 1;
        }
        assert!(
            cells.iter().any(|&c| c != 1),
            "pairs 0 and 1 are correlated"
        );
        // Progressive: the sequence goes on past n.
        let later = pair_point(Sequence::Sobol, 3, n, 300, 5);
        assert!(later.iter().all(|x| (0.0..1.0).contains(x)));
    }

    #[test]
    fn sobol_byte_tables_match_the_bit_loop() {
        let mut x = 0x1234_5678u32;
        for k in 0..20_000u32 {
            x = x.wrapping_mul(0x9e37_79b9).wrapping_add(k);
            let i = if k < 1000 { k } else { x };
            for d in 0..4 {
                assert_eq!(sobol(i, d), sobol_by_bits(i, d), "index {i} dimension {d}");
            }
        }
        for k in 0..5000u32 {
            let r = k.wrapping_mul(0x9e37_79b9) ^ (k << 7);
            for d in 0..4 {
                assert_eq!(
                    sobol_reversed(r, d),
                    sobol_by_bits(r.reverse_bits(), d).reverse_bits()
                );
            }
            // pair_point is the three scrambles of the definition.
            let s = pair_seed(9, k % 7);
            let i = nested_uniform_scramble(k, s as u32);
            let x = nested_uniform_scramble(sobol(i, 0), (s >> 32) as u32);
            let y = nested_uniform_scramble(sobol(i, 1), hash64(s) as u32);
            let k2 = 1.0 / 4_294_967_296.0;
            assert_eq!(
                pair_point(Sequence::Sobol, 9, 64, u64::from(k), k % 7),
                [f64::from(x) * k2, f64::from(y) * k2]
            );
        }
        assert_eq!(
            pair_point(Sequence::Sobol, 9, 64, 17, 3),
            pair_point_seeded(Sequence::Sobol, pair_seed(9, 3), 64, 17)
        );
    }

    #[test]
    fn sobol_first_points_are_the_known_ones() {
        // Dimension 2 (Joe–Kuo d=2), natural order: 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8.
        let expect = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, e) in expect.iter().enumerate() {
            assert_eq!(
                f64::from(sobol(i as u32, 1)) / 4_294_967_296.0,
                *e,
                "point {i}"
            );
        }
        // Dimension 3: 0, 1/2, 3/4, 1/4, 3/8, 7/8, 5/8, 1/8.
        let expect = [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125];
        for (i, e) in expect.iter().enumerate() {
            assert_eq!(
                f64::from(sobol(i as u32, 2)) / 4_294_967_296.0,
                *e,
                "point {i}"
            );
        }
    }

    #[test]
    fn every_power_of_two_prefix_is_stratified_after_scrambling() {
        // A (0, m, 2) net: 2^m points, one in each of 2^m elementary intervals per 1D projection.
        let n = 1 << 10;
        let mut out = vec![[0.0; 3]; n];
        fill(Sequence::Sobol, 42, n, 0, 0, &mut out);
        for d in 0..3 {
            let mut seen = vec![false; n];
            for p in &out {
                let cell = (p[d] * n as f64) as usize;
                assert!(!seen[cell], "dimension {d}: two points in cell {cell}");
                seen[cell] = true;
            }
        }
        // (u1, u2) form a (0, 2)-net: one point per 32 × 32 cell.
        let mut seen = vec![false; n];
        for p in &out {
            let c = (p[1] * 32.0) as usize * 32 + (p[2] * 32.0) as usize;
            assert!(!seen[c], "two points in 2D cell {c}");
            seen[c] = true;
        }
    }

    #[test]
    fn permutations_are_bijections() {
        for n in [1u64, 2, 3, 7, 100, 1000, 4097] {
            let mut seen = vec![false; n as usize];
            for i in 0..n {
                let j = permute(i, n, 17) as usize;
                assert!(!seen[j]);
                seen[j] = true;
            }
        }
    }

    #[test]
    fn stratified_points_are_stratified() {
        for n in [1024usize, 997] {
            let mut out = vec![[0.0; 3]; n];
            fill(Sequence::Stratified, 3, n, 0, 0, &mut out);
            for d in 0..3 {
                if n == 1024 && d > 0 {
                    continue; // jittered grid: stratified per 32×32 cell, checked below
                }
                let mut seen = vec![false; n];
                for p in &out {
                    let c = (p[d] * n as f64) as usize;
                    assert!(!seen[c], "n {n} dim {d}: cell {c} twice");
                    seen[c] = true;
                }
            }
        }
        for (n, nx, ny) in [(1024, 32, 32), (2048, 32, 64)] {
            assert_eq!(grid_shape(n), (nx, ny));
            let mut out = vec![[0.0; 3]; n];
            fill(Sequence::Stratified, 3, n, 0, 0, &mut out);
            let mut seen = vec![false; n];
            for p in &out {
                let c = (p[1] * nx as f64) as usize * ny + (p[2] * ny as f64) as usize;
                assert!(!seen[c]);
                seen[c] = true;
            }
        }
        assert_eq!(grid_shape(1000), (25, 40));
        assert_eq!(grid_shape(997), (0, 0));
    }
}
