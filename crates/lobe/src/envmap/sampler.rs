//! The density over a map's texels, a marginal over rows and a conditional
//! within each row ([`TexelSampler`]), whose rows' tables are built in two
//! shared buffers when first drawn from ([`Columns`]).

use super::distribution::{Distribution1D, Tables};
use super::texels::Texel;
use std::f64::consts::PI;

/// What a [`TexelSampler`]'s texel weights are functions of: a map's
/// texels (their luminance, under the sampler's shift), or given values
/// (a smooth map's, [`EnvMap::smooth`](super::EnvMap::smooth)).
#[derive(Debug, Clone, Copy)]
pub(super) enum Weights<'a> {
    Texels(&'a [Texel]),
    Values(&'a [f64]),
}

impl<'a> From<&'a [Texel]> for Weights<'a> {
    fn from(t: &'a [Texel]) -> Self {
        Weights::Texels(t)
    }
}

impl<'a> From<&'a [f64]> for Weights<'a> {
    fn from(v: &'a [f64]) -> Self {
        Weights::Values(v)
    }
}

impl Weights<'_> {
    /// Texel `k`'s luminance (or value).
    #[inline(always)]
    fn lum(self, k: usize) -> f64 {
        match self {
            Weights::Texels(t) => t[k].lum(),
            Weights::Values(v) => v[k],
        }
    }
}

/// A piecewise-constant density over the texels: texel weights times their
/// solid angles, a marginal over rows and a conditional within each row.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct TexelSampler {
    /// The weight of a texel of luminance `lum`: `lum`, or with `Some(m)`
    /// `max(0, lum − m)`.
    pub(super) shift: Option<f64>,
    pub(super) rows: Distribution1D,
    pub(super) cols: Columns,
    /// Σ weight·Ω over the texels.
    pub(super) norm: f64,
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
/// ([`EnvMap::prepare_sampling`](super::EnvMap::prepare_sampling)): a renderer that draws only from the
/// compensated density never builds the plain one's.
#[derive(Debug, Clone)]
pub(super) struct Columns {
    width: usize,
    /// Each row's sum of weights, bit for bit the sum the row's tables are
    /// normalized by.
    pub(super) totals: Vec<f64>,
    pub(super) tables: std::sync::OnceLock<ColumnTables>,
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
pub(super) struct ColumnTables {
    pub(super) cdf: Vec<f64>,
    pub(super) guide: Vec<u32>,
}

/// [`Columns`] with its tables built, borrowed.
#[derive(Debug, Clone, Copy)]
pub(super) struct BuiltColumns<'a> {
    width: usize,
    pub(super) totals: &'a [f64],
    pub(super) tables: &'a ColumnTables,
}

impl<'a> BuiltColumns<'a> {
    /// Row `j`'s distribution.
    #[inline]
    pub(super) fn row(self, j: usize) -> Tables<'a> {
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
    pub(super) fn new(
        width: usize,
        height: usize,
        shift: Option<f64>,
        texels: Weights<'_>,
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

    /// `cos θ₀ − cos θ₁` of row `j`.
    pub(super) fn band(height: usize, j: usize) -> f64 {
        let t0 = PI * j as f64 / height as f64;
        let t1 = PI * (j + 1) as f64 / height as f64;
        t0.cos() - t1.cos()
    }

    /// Row `j`'s weights: each texel's weight under `shift` times its solid
    /// angle (the same for the row's texels).
    fn row_weights(
        width: usize,
        height: usize,
        shift: Option<f64>,
        texels: Weights<'_>,
        j: usize,
    ) -> impl ExactSizeIterator<Item = f64> + Clone + '_ {
        let omega = 2.0 * PI / width as f64 * Self::band(height, j);
        (j * width..(j + 1) * width).map(move |k| Self::weight_of(shift, texels.lum(k)) * omega)
    }

    /// The rows' tables and totals, each row's its own computation (the
    /// same numbers in parallel or not): on rayon's threads when `parallel`
    /// and the feature allow.
    pub(super) fn build_tables(
        width: usize,
        height: usize,
        shift: Option<f64>,
        texels: Weights<'_>,
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
    pub(super) fn columns(&self, texels: Weights<'_>) -> BuiltColumns<'_> {
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
    pub(super) fn weight_of(shift: Option<f64>, lum: f64) -> f64 {
        match shift {
            None => lum,
            Some(m) => (lum - m).max(0.0),
        }
    }

    /// The density's weight of a texel of luminance `lum`.
    #[inline]
    pub(super) fn weight(&self, lum: f64) -> f64 {
        Self::weight_of(self.shift, lum)
    }
}
