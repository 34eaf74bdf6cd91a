//! A smooth map ([`EnvMap::smooth`]): its radiance interpolated bilinearly
//! between the texels' centres, its densities piecewise bilinear over each
//! texel's four quarters ([`Smooth`]), and the cells over which its
//! radiance is bilinear, for quadrature ([`BilinearCell`]).
//!
//! The interpolated luminance at the corners, the edges' midpoints and the
//! centre of every texel (the nodes of a grid of half texels) are the
//! densities' values there; inside each quarter texel the density is the
//! bilinear interpolation of its four nodes in `(φ, cos θ)`, where the
//! radiance is bilinear in `(φ, θ)`: the same values on the quarter's
//! edges in `φ`, within the curvature of `cos θ` over half a texel in
//! between. So the radiance over the plain density is nearly constant, a
//! sun a few texels wide included (a density constant over each texel
//! would leave the radiance's ramps across them in the estimates).
//!
//! A texel is drawn with probability ∝ its density's integral (its
//! weight, [`Smooth::plain`]), then `cos θ` from the texel's marginal
//! (piecewise linear) and `φ` from the conditional (piecewise linear):
//! the density of the draws is the piecewise bilinear function over the
//! norm, exactly, and positive wherever the radiance is. The compensated
//! density (MIS) interpolates the nodes' `max(0, lum − mean)` the same way:
//! at least the compensated interpolated luminance (`max(0, ·)` is convex).

use super::sampler::TexelSampler;
use super::texels::Texel;
use crate::math::Rgb;
use std::f64::consts::PI;

/// A smooth map's densities: the nodes, and each texel's weights.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Smooth {
    /// The interpolated luminance (before the map's scale) at node
    /// `(a, b)` of the grid of half texels, at `x = a/2` columns and
    /// `y = b/2` rows from the map's top left (`a < 2 width`, columns
    /// wrapped; `b ≤ 2 height`), row-major: `b · 2 width + a`.
    nodes: Vec<f64>,
    /// Row `j`'s `(cos θ₀ − cos θ_m) / (cos θ₀ − cos θ₁)`: where its
    /// centre `θ_m` is in `cos θ`, as a fraction of the row.
    row_tm: Vec<f64>,
    /// The compensated density's shift, `Some(mean)` (the nodes'
    /// `max(0, lum − mean)`), `None` when it is the plain density (no node
    /// above the mean).
    shift: Option<f64>,
    /// Each texel's integral of the plain density over it, per unit solid
    /// angle: the weight [`TexelSampler`] draws the texel with.
    pub(super) plain: Vec<f64>,
    /// The same of the compensated density.
    pub(super) compensated: Vec<f64>,
}

/// `x ∈ [0, 1]` drawn from `r ∈ [0, 1)` with density ∝ `(1 − x) a + x b`
/// (`a, b ≥ 0`, not both 0), by inverting its CDF (the form without
/// cancellation: pbrt-v4's `SampleLinear`).
#[inline]
fn sample_linear(r: f64, a: f64, b: f64) -> f64 {
    if a == b {
        return r;
    }
    let den = a + ((1.0 - r) * a * a + r * b * b).sqrt();
    if den <= 0.0 {
        // (r = 0 where a = 0.)
        return 0.0;
    }
    let x = r * (a + b) / den;
    x.clamp(0.0, 1.0)
}

impl Smooth {
    /// The densities of a smooth map of these texels (`row_cos` its rows'
    /// edges' `cos θ`), with their samplers, plain and compensated.
    pub(super) fn new(
        w: usize,
        h: usize,
        texels: &[Texel],
        row_cos: &[f64],
    ) -> (Self, TexelSampler, TexelSampler) {
        let lum: Vec<f64> = texels.iter().map(|t| t.lum()).collect();
        let at = |i: usize, j: usize| lum[j * w + i % w];
        // Node (a, b): the bilinear interpolation at x = a/2, y = b/2, i.e.
        // the mean of the (up to) four texels around it.
        let span = |a: usize, n: usize, wrap: bool| -> (usize, usize) {
            if a % 2 == 1 {
                ((a - 1) / 2, (a - 1) / 2)
            } else if wrap {
                ((a / 2 + n - 1) % n, (a / 2) % n)
            } else {
                ((a / 2).saturating_sub(1), (a / 2).min(n - 1))
            }
        };
        let mut nodes = Vec::with_capacity((2 * h + 1) * 2 * w);
        for b in 0..=2 * h {
            let (j0, j1) = span(b, h, false);
            for a in 0..2 * w {
                let (i0, i1) = span(a, w, true);
                nodes.push(0.25 * (at(i0, j0) + at(i1, j0) + at(i0, j1) + at(i1, j1)));
            }
        }
        let row_tm = (0..h)
            .map(|j| {
                let (c0, c1) = (row_cos[j], row_cos[j + 1]);
                let cm = (PI * (j as f64 + 0.5) / h as f64).cos();
                ((c0 - cm) / (c0 - c1)).clamp(0.0, 1.0)
            })
            .collect();
        let mut sm = Smooth {
            nodes,
            row_tm,
            shift: None,
            plain: Vec::new(),
            compensated: Vec::new(),
        };
        let texels = || (0..h).flat_map(|j| (0..w).map(move |i| (i, j)));
        sm.plain = texels().map(|k| sm.texel_weight(w, false, k)).collect();
        let plain = TexelSampler::new(w, h, None, (&sm.plain[..]).into(), false);
        // Mean luminance over the sphere (the density's integral over
        // 4π), then the part above it.
        let mean = plain.norm / (4.0 * PI);
        let compensated = if sm.nodes.iter().any(|&n| (n - mean).max(0.0) > 0.0) {
            sm.shift = Some(mean);
            sm.compensated = texels().map(|k| sm.texel_weight(w, true, k)).collect();
            TexelSampler::new(w, h, None, (&sm.compensated[..]).into(), true)
        } else {
            sm.compensated = sm.plain.clone();
            plain.clone()
        };
        (sm, plain, compensated)
    }

    /// Node `(a, b)` of the density (`compensated`: its `max(0, · − mean)`).
    #[inline(always)]
    fn node(&self, width: usize, compensated: bool, a: usize, b: usize) -> f64 {
        let n = self.nodes[b * 2 * width + a % (2 * width)];
        match (compensated, self.shift) {
            (true, Some(m)) => (n - m).max(0.0),
            _ => n,
        }
    }

    /// The density (before its norm) at `(s, t)` in texel `(i, j)`: `s` the
    /// fraction of the texel in `φ`, `t` in `cos θ` (both in `[0, 1]`).
    #[inline(always)]
    pub(super) fn density(
        &self,
        width: usize,
        compensated: bool,
        (i, j): (usize, usize),
        s: f64,
        t: f64,
    ) -> f64 {
        let tm = self.row_tm[j];
        let (bq, lt) = if t < tm {
            (0, t / tm)
        } else {
            (1, (t - tm) / (1.0 - tm))
        };
        let (aq, ls) = if s < 0.5 {
            (0, 2.0 * s)
        } else {
            (1, 2.0 * s - 1.0)
        };
        let (a, b) = (2 * i + aq, 2 * j + bq);
        let n = |da: usize, db: usize| self.node(width, compensated, a + da, b + db);
        let top = n(0, 0) * (1.0 - ls) + n(1, 0) * ls;
        let bottom = n(0, 1) * (1.0 - ls) + n(1, 1) * ls;
        top * (1.0 - lt) + bottom * lt
    }

    /// Texel `(i, j)`'s integral of the density over `(s, t) ∈ [0, 1]²`.
    fn texel_weight(&self, width: usize, compensated: bool, (i, j): (usize, usize)) -> f64 {
        let tm = self.row_tm[j];
        let n = |a: usize, b: usize| self.node(width, compensated, 2 * i + a, 2 * j + b);
        let g = |b: usize| 0.25 * (n(0, b) + 2.0 * n(1, b) + n(2, b));
        let (g0, g1, g2) = (g(0), g(1), g(2));
        tm * 0.5 * (g0 + g1) + (1.0 - tm) * 0.5 * (g1 + g2)
    }

    /// `(s, t)` in texel `(i, j)` drawn from `(ru, rv) ∈ [0, 1)²` with the
    /// density over the texel's weight: `t` from the marginal, `s` from
    /// the conditional, each piecewise linear over two halves.
    pub(super) fn draw(
        &self,
        width: usize,
        compensated: bool,
        (i, j): (usize, usize),
        ru: f64,
        rv: f64,
    ) -> (f64, f64) {
        let tm = self.row_tm[j];
        let n = |a: usize, b: usize| self.node(width, compensated, 2 * i + a, 2 * j + b);
        let g = |b: usize| 0.25 * (n(0, b) + 2.0 * n(1, b) + n(2, b));
        let (g0, g1, g2) = (g(0), g(1), g(2));
        let (top, bottom) = (tm * 0.5 * (g0 + g1), (1.0 - tm) * 0.5 * (g1 + g2));
        let x = ru * (top + bottom);
        let (t, b0, lt) = if (x < top && top > 0.0) || bottom <= 0.0 {
            let l = sample_linear((x / top).min(1.0), g0, g1);
            (l * tm, 0, l)
        } else {
            let l = sample_linear(((x - top) / bottom).clamp(0.0, 1.0), g1, g2);
            (tm + l * (1.0 - tm), 1, l)
        };
        let v = [0, 1, 2].map(|a| n(a, b0) * (1.0 - lt) + n(a, b0 + 1) * lt);
        let (left, right) = (0.25 * (v[0] + v[1]), 0.25 * (v[1] + v[2]));
        let y = rv * (left + right);
        let s = if (y < left && left > 0.0) || right <= 0.0 {
            0.5 * sample_linear((y / left).min(1.0), v[0], v[1])
        } else {
            0.5 + 0.5 * sample_linear(((y - left) / right).clamp(0.0, 1.0), v[1], v[2])
        };
        (s.clamp(0.0, 1.0), t.clamp(0.0, 1.0))
    }
}

/// A region of a smooth map over which its radiance is bilinear in
/// `(φ, θ)`: between four texels' centres (the rows' centres and a pole
/// at the caps, where it is linear in `φ` alone). See
/// [`EnvMap::bilinear_cells`](super::EnvMap::bilinear_cells).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BilinearCell {
    /// `(θ₀, θ₁)` in the map's frame.
    pub theta: (f64, f64),
    /// `(φ₀, φ₁)` in the map's frame (`φ = 2πu`; `φ₀` can be negative).
    pub phi: (f64, f64),
    /// The scaled radiance at `(φ₀, θ₀)`, `(φ₁, θ₀)`, `(φ₀, θ₁)`, `(φ₁, θ₁)`.
    corners: [Rgb; 4],
}

impl BilinearCell {
    /// The cell `theta × phi` of these corners' radiance.
    pub(super) fn new(theta: (f64, f64), phi: (f64, f64), corners: [Rgb; 4]) -> Self {
        BilinearCell {
            theta,
            phi,
            corners,
        }
    }

    /// The map's radiance at `(θ, φ)` inside the cell.
    #[inline]
    #[must_use]
    pub fn radiance(&self, theta: f64, phi: f64) -> Rgb {
        let fx = ((phi - self.phi.0) / (self.phi.1 - self.phi.0)).clamp(0.0, 1.0);
        let fy = ((theta - self.theta.0) / (self.theta.1 - self.theta.0)).clamp(0.0, 1.0);
        let [a, b, c, d] = self.corners;
        (a * (1.0 - fx) + b * fx) * (1.0 - fy) + (c * (1.0 - fx) + d * fx) * fy
    }

    /// Whether the radiance is 0 over the whole cell.
    #[must_use]
    pub fn is_black(&self) -> bool {
        self.corners.iter().all(|&c| c == Rgb::ZERO)
    }
}
