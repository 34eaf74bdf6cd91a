//! A piecewise-constant 1D distribution sampled by inversion through a
//! guide table ([`Distribution1D`]), and its tables borrowed ([`Tables`]):
//! its own, or one row's of a map.

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
    pub(super) cdf: Vec<f64>,
    total: f64,
    /// `guide[k]`: the bin of `u = k/n`.
    pub(super) guide: Vec<u32>,
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
    pub(super) fn steps(n: usize) -> Vec<f64> {
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
    pub(super) fn build(
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
/// map's [`Columns`](super::sampler::Columns) (all rows' tables in two buffers).
#[derive(Debug, Clone, Copy)]
pub(super) struct Tables<'a> {
    /// `cdf[i]` = probability of bins `0..i`; `cdf[n] = 1`.
    pub(super) cdf: &'a [f64],
    pub(super) total: f64,
    /// `guide[k]`: the bin of `u = k/n`.
    pub(super) guide: &'a [u32],
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
    pub(super) fn sample(&self, u: f64) -> Option<(usize, f64)> {
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
