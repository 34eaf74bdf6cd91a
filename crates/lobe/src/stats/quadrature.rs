//! Deterministic, globally adaptive cubature in `f64`.
//!
//! Every rectangle is integrated with the tensor product of the 15-point
//! Gauss–Kronrod rule and of its embedded 7-point Gauss rule. The error of a
//! rectangle is the largest of `|K⊗K − G⊗G|`, `|K⊗K − G⊗K|` and
//! `|K⊗K − K⊗G|`, a deliberately pessimistic estimate: for smooth integrands
//! the Kronrod result is far more accurate than the estimate says.
//!
//! The rectangles live in a max-heap keyed on their error; the one with the
//! largest error is split (in two along the dimension whose error dominates,
//! or in four when both dimensions contribute) until the summed error is below
//! `max(abs, rel·|value|)` or the evaluation budget is spent.
//!
//! The integrators on the sphere parameterize a region by `(theta, phi)` with
//! the Jacobian `sin(theta)`, so narrow lobes around the poles are resolved as
//! well as anywhere else.

use glam::DVec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// An integral and an estimate of its absolute error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The integral.
    pub value: f64,
    /// Estimated absolute error of `value` (pessimistic for smooth
    /// integrands). `f64::INFINITY` when the integrand returned a non-finite
    /// value.
    pub error: f64,
    /// Number of integrand evaluations spent.
    pub evals: usize,
    /// Whether the requested tolerance was reached (`false` when the budget
    /// ran out, the rectangles could not be split any more, or the integrand
    /// was not finite).
    pub converged: bool,
}

/// Stopping rule of the adaptive integrators.
///
/// Refinement stops when the total estimated error is at most
/// `max(abs, rel·|value|)`, or when the next split would exceed `max_evals`
/// integrand evaluations (the initial grid is always evaluated in full).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Absolute error target.
    pub abs: f64,
    /// Relative error target.
    pub rel: f64,
    /// Evaluation budget (each rectangle costs 225 evaluations).
    pub max_evals: usize,
    /// Initial `nx × ny` grid of rectangles (so that narrow peaks are not
    /// missed). `None` lets each integrator choose: `1 × 1` for
    /// [`integrate_2d`] and [`integrate_sphere_region`], `32 × 64` for
    /// [`integrate_hemisphere`] and `64 × 64` for [`integrate_sphere`]
    /// (`theta × phi`).
    pub initial: Option<(usize, usize)>,
}

impl Default for Tolerance {
    /// `abs = 1e-12`, `rel = 1e-10`, `max_evals = 20_000_000`, `initial = None`.
    fn default() -> Self {
        Self {
            abs: 1e-12,
            rel: 1e-10,
            max_evals: 20_000_000,
            initial: None,
        }
    }
}

impl Tolerance {
    /// Both targets given, default budget and initial grid.
    #[must_use]
    pub fn new(abs: f64, rel: f64) -> Self {
        Self {
            abs,
            rel,
            ..Self::default()
        }
    }

    /// A purely absolute target (`rel = 0`).
    #[must_use]
    pub fn absolute(abs: f64) -> Self {
        Self::new(abs, 0.0)
    }

    /// A purely relative target (`abs = 0`).
    #[must_use]
    pub fn relative(rel: f64) -> Self {
        Self::new(0.0, rel)
    }

    /// The same tolerance with another evaluation budget.
    #[must_use]
    pub fn with_max_evals(self, max_evals: usize) -> Self {
        Self { max_evals, ..self }
    }

    /// The same tolerance with an explicit initial `nx × ny` grid (zeros are
    /// read as one).
    #[must_use]
    pub fn with_initial(self, nx: usize, ny: usize) -> Self {
        Self {
            initial: Some((nx, ny)),
            ..self
        }
    }

    /// The error allowed for an integral of value `value`.
    fn target(&self, value: f64) -> f64 {
        let abs = if self.abs.is_nan() { 0.0 } else { self.abs };
        let rel = if self.rel.is_nan() { 0.0 } else { self.rel };
        abs.max(rel * value.abs())
    }
}

/// Nodes of the 15-point Kronrod rule on [-1, 1]: `±KRONROD_X[i]`; the odd
/// indices (and the centre, index 7) are the 7-point Gauss nodes.
#[allow(clippy::excessive_precision)] // the published digits, rounded by the compiler
const KRONROD_X: [f64; 8] = [
    0.991_455_371_120_812_639_206_854_697_526_329,
    0.949_107_912_342_758_524_526_189_684_047_851,
    0.864_864_423_359_769_072_789_712_788_640_926,
    0.741_531_185_599_394_439_863_864_773_280_788,
    0.586_087_235_467_691_130_294_144_845_693_013,
    0.405_845_151_377_397_166_906_606_412_076_961,
    0.207_784_955_007_898_467_600_689_403_773_245,
    0.0,
];

/// Weights of the 15-point Kronrod rule, matching [`KRONROD_X`].
#[allow(clippy::excessive_precision)] // the published digits, rounded by the compiler
const KRONROD_W: [f64; 8] = [
    0.022_935_322_010_529_224_963_732_008_058_970,
    0.063_092_092_629_978_553_290_700_663_189_204,
    0.104_790_010_322_250_183_839_876_322_541_518,
    0.140_653_259_715_525_918_745_189_590_510_238,
    0.169_004_726_639_267_902_826_583_426_598_550,
    0.190_350_578_064_785_409_913_256_402_421_014,
    0.204_432_940_075_298_892_414_161_999_234_649,
    0.209_482_141_084_727_828_012_999_174_891_714,
];

/// Weights of the 7-point Gauss rule at `KRONROD_X[1]`, `[3]`, `[5]`, `[7]`.
#[allow(clippy::excessive_precision)] // the published digits, rounded by the compiler
const GAUSS_W: [f64; 4] = [
    0.129_484_966_168_869_693_270_611_432_679_082,
    0.279_705_391_489_276_667_901_467_771_423_780,
    0.381_830_050_505_118_944_950_369_775_488_975,
    0.417_959_183_673_469_387_755_102_040_816_327,
];

/// Number of points of the 1D rule.
const N1: usize = 15;
/// Evaluations per rectangle.
const EVALS_PER_RECT: usize = N1 * N1;

/// The 15 nodes on [-1, 1] in increasing order, with their Kronrod and Gauss
/// weights (Gauss weight 0 at the Kronrod-only nodes).
struct Rule {
    t: [f64; N1],
    wk: [f64; N1],
    wg: [f64; N1],
}

const RULE: Rule = build_rule();

const fn build_rule() -> Rule {
    let mut t = [0.0; N1];
    let mut wk = [0.0; N1];
    let mut wg = [0.0; N1];
    let mut i = 0;
    while i < 8 {
        let g = if i % 2 == 1 { GAUSS_W[i / 2] } else { 0.0 };
        // Negative side, increasing.
        t[i] = -KRONROD_X[i];
        wk[i] = KRONROD_W[i];
        wg[i] = g;
        // Positive side (mirror); index 7 is the centre, written twice.
        t[N1 - 1 - i] = KRONROD_X[i];
        wk[N1 - 1 - i] = KRONROD_W[i];
        wg[N1 - 1 - i] = g;
        i += 1;
    }
    Rule { t, wk, wg }
}

/// One rectangle of the partition with its rule results.
#[derive(Clone, Copy, Debug)]
struct Rect {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    value: f64,
    error: f64,
    /// Error attributable to the x direction.
    ex: f64,
    /// Error attributable to the y direction.
    ey: f64,
}

impl PartialEq for Rect {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Rect {}
impl PartialOrd for Rect {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Rect {
    fn cmp(&self, other: &Self) -> Ordering {
        self.error.total_cmp(&other.error)
    }
}

/// An integrand evaluated on the `15 × 15` node grid of a rectangle at once,
/// so that the sphere integrators can share the trigonometry of a row.
trait GridIntegrand {
    /// Sets `out[j][i] = f(xs[i], ys[j])`.
    fn eval_grid(&self, xs: &[f64; N1], ys: &[f64; N1], out: &mut [[f64; N1]; N1]);
}

/// A plain `f(x, y)`.
struct Plane<F>(F);

impl<F: Fn(f64, f64) -> f64> GridIntegrand for Plane<F> {
    fn eval_grid(&self, xs: &[f64; N1], ys: &[f64; N1], out: &mut [[f64; N1]; N1]) {
        for (row, &y) in out.iter_mut().zip(ys) {
            for (v, &x) in row.iter_mut().zip(xs) {
                *v = (self.0)(x, y);
            }
        }
    }
}

/// `f(ω(theta, phi)) sin(theta)` with `x = theta`, `y = phi`.
struct Spherical<F>(F);

impl<F: Fn(DVec3) -> f64> GridIntegrand for Spherical<F> {
    fn eval_grid(&self, xs: &[f64; N1], ys: &[f64; N1], out: &mut [[f64; N1]; N1]) {
        spherical_grid(xs, ys, out, |dirs, vals| {
            for (v, &w) in vals.iter_mut().zip(dirs) {
                *v = (self.0)(w);
            }
        });
    }
}

/// [`Spherical`] with `f(dirs, out)` filling `out[i] = f(dirs[i])` for a
/// whole node grid in one call.
struct SphericalMany<F>(F);

impl<F: Fn(&[DVec3], &mut [f64])> GridIntegrand for SphericalMany<F> {
    fn eval_grid(&self, xs: &[f64; N1], ys: &[f64; N1], out: &mut [[f64; N1]; N1]) {
        spherical_grid(xs, ys, out, &self.0);
    }
}

/// Sets `out[j][i] = f(ω(xs[i], ys[j])) sin(xs[i])`, evaluating `f` on the
/// nodes off the poles with one call of `many(dirs, values)`.
fn spherical_grid(
    xs: &[f64; N1],
    ys: &[f64; N1],
    out: &mut [[f64; N1]; N1],
    many: impl Fn(&[DVec3], &mut [f64]),
) {
    let st: [(f64, f64); N1] = std::array::from_fn(|i| xs[i].sin_cos());
    let mut dirs = [DVec3::ZERO; N1 * N1];
    let mut n = 0;
    for &phi in ys {
        let (sp, cp) = phi.sin_cos();
        for &(s, c) in &st {
            // At a pole the Jacobian vanishes; f is not evaluated there (it
            // may be singular, and the product is 0 anyway).
            if s != 0.0 {
                dirs[n] = DVec3::new(s * cp, s * sp, c);
                n += 1;
            }
        }
    }
    let mut vals = [0.0; N1 * N1];
    many(&dirs[..n], &mut vals[..n]);
    let mut k = 0;
    for row in out.iter_mut() {
        for (v, &(s, _)) in row.iter_mut().zip(&st) {
            *v = if s == 0.0 {
                0.0
            } else {
                k += 1;
                vals[k - 1] * s
            };
        }
    }
}

/// Applies the tensor G7/K15 rule to one rectangle.
fn eval_rect(f: &impl GridIntegrand, x0: f64, x1: f64, y0: f64, y1: f64) -> Rect {
    let (cx, hx) = (0.5 * (x0 + x1), 0.5 * (x1 - x0));
    let (cy, hy) = (0.5 * (y0 + y1), 0.5 * (y1 - y0));
    let xs: [f64; N1] = std::array::from_fn(|k| cx + hx * RULE.t[k]);
    let ys: [f64; N1] = std::array::from_fn(|k| cy + hy * RULE.t[k]);
    let mut vals = [[0.0; N1]; N1];
    f.eval_grid(&xs, &ys, &mut vals);
    // Per y-node, the Kronrod and Gauss sums along x.
    let mut kx = [0.0; N1];
    let mut gx = [0.0; N1];
    for (j, row) in vals.iter().enumerate() {
        let (mut k, mut g) = (0.0, 0.0);
        for (i, &v) in row.iter().enumerate() {
            k += RULE.wk[i] * v;
            g += RULE.wg[i] * v;
        }
        kx[j] = k;
        gx[j] = g;
    }
    let (mut kk, mut gg, mut gk, mut kg) = (0.0, 0.0, 0.0, 0.0);
    for j in 0..N1 {
        kk += RULE.wk[j] * kx[j];
        gg += RULE.wg[j] * gx[j];
        gk += RULE.wk[j] * gx[j];
        kg += RULE.wg[j] * kx[j];
    }
    let area = hx * hy;
    let (kk, gg, gk, kg) = (kk * area, gg * area, gk * area, kg * area);
    let ex = (kk - gk).abs();
    let ey = (kk - kg).abs();
    let error = (kk - gg).abs().max(ex).max(ey);
    let (error, ex, ey) = if kk.is_finite() && error.is_finite() {
        (error, ex, ey)
    } else {
        (f64::INFINITY, f64::INFINITY, f64::INFINITY)
    };
    Rect {
        x0,
        x1,
        y0,
        y1,
        value: kk,
        error,
        ex,
        ey,
    }
}

/// Whether `[a, b]` can be halved into two non-degenerate intervals.
fn splittable(a: f64, b: f64) -> bool {
    let m = 0.5 * (a + b);
    m != a && m != b
}

/// Sums of the values and errors of all rectangles.
fn totals(heap: &BinaryHeap<Rect>) -> (f64, f64) {
    heap.iter()
        .fold((0.0, 0.0), |(v, e), r| (v + r.value, e + r.error))
}

/// Integrates `f(x, y)` over `[x.0, x.1] × [y.0, y.1]` adaptively.
///
/// Reversed bounds give the negated integral; empty ranges give 0; non-finite
/// bounds or integrand values give a non-finite value with infinite error and
/// `converged == false`. The initial grid (`tol.initial`, `1 × 1` when
/// `None`) is always evaluated in full, even beyond `tol.max_evals`.
#[must_use]
pub fn integrate_2d(
    f: impl Fn(f64, f64) -> f64,
    x: (f64, f64),
    y: (f64, f64),
    tol: Tolerance,
) -> Estimate {
    integrate_2d_with_grid(&Plane(f), x, y, tol, (1, 1))
}

fn integrate_2d_with_grid(
    f: &impl GridIntegrand,
    x: (f64, f64),
    y: (f64, f64),
    tol: Tolerance,
    default_grid: (usize, usize),
) -> Estimate {
    if !(x.0.is_finite() && x.1.is_finite() && y.0.is_finite() && y.1.is_finite()) {
        return Estimate {
            value: f64::NAN,
            error: f64::INFINITY,
            evals: 0,
            converged: false,
        };
    }
    if x.0 == x.1 || y.0 == y.1 {
        return Estimate {
            value: 0.0,
            error: 0.0,
            evals: 0,
            converged: true,
        };
    }
    let (nx, ny) = tol.initial.unwrap_or(default_grid);
    let (nx, ny) = (nx.max(1), ny.max(1));

    let mut heap = BinaryHeap::with_capacity(nx * ny + 64);
    let mut evals = 0usize;
    let (mut value, mut error) = (0.0, 0.0);
    let lerp = |r: (f64, f64), i: usize, n: usize| {
        if i == n {
            r.1
        } else {
            r.0 + (r.1 - r.0) * (i as f64 / n as f64)
        }
    };
    for i in 0..nx {
        let (xa, xb) = (lerp(x, i, nx), lerp(x, i + 1, nx));
        for j in 0..ny {
            let (ya, yb) = (lerp(y, j, ny), lerp(y, j + 1, ny));
            let r = eval_rect(f, xa, xb, ya, yb);
            evals += EVALS_PER_RECT;
            value += r.value;
            error += r.error;
            heap.push(r);
        }
    }
    if !(value.is_finite() && error.is_finite()) {
        return Estimate {
            value: if value.is_finite() { f64::NAN } else { value },
            error: f64::INFINITY,
            evals,
            converged: false,
        };
    }

    let mut converged = false;
    loop {
        if error <= tol.target(value) {
            // Confirm with freshly summed totals (the running sums drift).
            (value, error) = totals(&heap);
            if error <= tol.target(value) {
                converged = true;
                break;
            }
        }
        let Some(top) = heap.pop() else {
            break;
        };
        let can_x = splittable(top.x0, top.x1);
        let can_y = splittable(top.y0, top.y1);
        let (split_x, split_y) = match (can_x, can_y) {
            (false, false) => (false, false),
            (true, false) => (true, false),
            (false, true) => (false, true),
            (true, true) => {
                let (hi, lo) = (top.ex.max(top.ey), top.ex.min(top.ey));
                if lo >= 0.25 * hi {
                    (true, true)
                } else {
                    (top.ex >= top.ey, top.ey > top.ex)
                }
            }
        };
        let pieces = match (split_x, split_y) {
            (true, true) => 4,
            (false, false) => 0,
            _ => 2,
        };
        if pieces == 0 || evals + pieces * EVALS_PER_RECT > tol.max_evals {
            heap.push(top);
            break;
        }
        let xm = 0.5 * (top.x0 + top.x1);
        let ym = 0.5 * (top.y0 + top.y1);
        let xs: &[(f64, f64)] = if split_x {
            &[(top.x0, xm), (xm, top.x1)]
        } else {
            &[(top.x0, top.x1)]
        };
        let ys: &[(f64, f64)] = if split_y {
            &[(top.y0, ym), (ym, top.y1)]
        } else {
            &[(top.y0, top.y1)]
        };
        value -= top.value;
        error -= top.error;
        for &(xa, xb) in xs {
            for &(ya, yb) in ys {
                let r = eval_rect(f, xa, xb, ya, yb);
                evals += EVALS_PER_RECT;
                value += r.value;
                error += r.error;
                heap.push(r);
            }
        }
        if !(value.is_finite() && error.is_finite()) {
            return Estimate {
                value: if value.is_finite() { f64::NAN } else { value },
                error: f64::INFINITY,
                evals,
                converged: false,
            };
        }
    }
    let (value, error) = totals(&heap);
    Estimate {
        value,
        error,
        evals,
        converged,
    }
}

pub use crate::frame::spherical_direction;

/// Nodes and weights of the 4-point Gauss–Legendre rule on `[−1, 1]`.
pub const GAUSS_LEGENDRE_4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

/// The `n`-point Gauss–Legendre rule on `[−1, 1]`: `(node, weight)`
/// pairs, the nodes the roots of the Legendre polynomial `P_n` (Newton's
/// method from Tricomi's first guess, to the last bit). Exact for
/// polynomials of degree up to `2n − 1`.
#[must_use]
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let nf = n as f64;
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                // P_n(x) and P_n'(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let kf = k as f64;
                    (p0, p1) = (p1, ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf);
                }
                let p = if n == 0 {
                    1.0
                } else if n == 1 {
                    x
                } else {
                    p1
                };
                let pm = if n == 1 { 1.0 } else { p0 };
                dp = nf * (x * p - pm) / (x * x - 1.0);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// The 4 × 4 Gauss–Legendre rule for `∫∫ f(x, y) dx dy` over
/// `[x0, x1] × [y0, y1]`, for any value that adds and scales (`f64`, RGB).
/// The widths may be signed: the result is the integral over the rectangle
/// with positive area (`Σ wᵢwⱼ f · |hx hy|`).
#[inline]
#[must_use]
pub fn gauss_legendre_4x4<T>(f: impl Fn(f64, f64) -> T, x0: f64, x1: f64, y0: f64, y1: f64) -> T
where
    T: Copy + Default + std::ops::Add<Output = T> + std::ops::Mul<f64, Output = T>,
{
    let (hx, hy) = (0.5 * (x1 - x0), 0.5 * (y1 - y0));
    let (mx, my) = (0.5 * (x1 + x0), 0.5 * (y1 + y0));
    let mut s = T::default();
    for (xi, wx) in GAUSS_LEGENDRE_4 {
        for (yi, wy) in GAUSS_LEGENDRE_4 {
            s = s + f(mx + hx * xi, my + hy * yi) * (wx * wy);
        }
    }
    s * (hx * hy).abs()
}

/// Integrates `f(ω) dω` over the spherical region
/// `theta ∈ [theta.0, theta.1]`, `phi ∈ [phi.0, phi.1]` (radians; `theta`
/// from `+z`, `phi` around it from `+x`).
///
/// The region is parameterized in `(theta, phi)` with the Jacobian
/// `sin(theta)`; `tol.initial` is `theta × phi` cells (`1 × 1` when `None`).
#[must_use]
pub fn integrate_sphere_region(
    f: impl Fn(DVec3) -> f64,
    theta: (f64, f64),
    phi: (f64, f64),
    tol: Tolerance,
) -> Estimate {
    sphere_region(&f, theta, phi, tol, (1, 1))
}

/// [`integrate_sphere_region`] for an integrand evaluated many directions
/// at a time: `f(dirs, out)` sets `out[i]` to the integrand at `dirs[i]`
/// (up to 225 directions a call, the nodes of one cubature rectangle). For
/// batch kernels, whose cost per call is far above their cost per lane.
#[must_use]
pub fn integrate_sphere_region_many(
    f: impl Fn(&[DVec3], &mut [f64]),
    theta: (f64, f64),
    phi: (f64, f64),
    tol: Tolerance,
) -> Estimate {
    integrate_2d_with_grid(&SphericalMany(f), theta, phi, tol, (1, 1))
}

fn sphere_region(
    f: &impl Fn(DVec3) -> f64,
    theta: (f64, f64),
    phi: (f64, f64),
    tol: Tolerance,
    default_grid: (usize, usize),
) -> Estimate {
    integrate_2d_with_grid(&Spherical(f), theta, phi, tol, default_grid)
}

/// Integrates `f(ω) dω` over the upper hemisphere (`z ≥ 0`).
///
/// With `tol.initial == None` it starts from a `32 (theta) × 64 (phi)` grid,
/// fine enough for lobes about 0.01 rad wide.
#[must_use]
pub fn integrate_hemisphere(f: impl Fn(DVec3) -> f64, tol: Tolerance) -> Estimate {
    sphere_region(&f, (0.0, FRAC_PI_2), (0.0, TAU), tol, (32, 64))
}

/// Integrates `f(ω) dω` over the whole sphere.
///
/// With `tol.initial == None` it starts from a `64 (theta) × 64 (phi)` grid
/// (the hemisphere's cell size), fine enough for lobes about 0.01 rad wide.
#[must_use]
pub fn integrate_sphere(f: impl Fn(DVec3) -> f64, tol: Tolerance) -> Estimate {
    sphere_region(&f, (0.0, PI), (0.0, TAU), tol, (64, 64))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule_1d(f: impl Fn(f64) -> f64, w: &[f64; N1]) -> f64 {
        (0..N1).map(|i| w[i] * f(RULE.t[i])).sum()
    }

    #[test]
    fn rule_is_exact_for_polynomials() {
        // Kronrod: exact to degree 22; Gauss: to degree 13.
        for k in 0..=22 {
            let exact = if k % 2 == 1 {
                0.0
            } else {
                2.0 / (k as f64 + 1.0)
            };
            let kr = rule_1d(|t| t.powi(k), &RULE.wk);
            assert!((kr - exact).abs() < 1e-14, "kronrod degree {k}: {kr}");
            if k <= 13 {
                let ga = rule_1d(|t| t.powi(k), &RULE.wg);
                assert!((ga - exact).abs() < 1e-14, "gauss degree {k}: {ga}");
            }
        }
        // Gauss is not exact at degree 14: the error estimate is meaningful.
        let ga = rule_1d(|t| t.powi(14), &RULE.wg);
        assert!((ga - 2.0 / 15.0).abs() > 1e-6);
        // Gauss nodes are exactly where the weights are nonzero.
        assert_eq!(RULE.wg.iter().filter(|&&w| w != 0.0).count(), 7);
    }

    #[test]
    fn smooth_1d_like_function_matches_closed_form() {
        // ∫_0^3 ∫_{-1}^{2} exp(x) / (1 + y²) dy dx = (e³ − 1)(atan 2 + atan 1)
        let est = integrate_2d(
            |x, y| x.exp() / (1.0 + y * y),
            (0.0, 3.0),
            (-1.0, 2.0),
            Tolerance::new(1e-12, 1e-12),
        );
        let exact = (3f64.exp() - 1.0) * (2f64.atan() + 1f64.atan());
        assert!(est.converged);
        assert!((est.value - exact).abs() < 1e-10, "{est:?} vs {exact}");
        assert!(est.error <= 1e-12f64.max(1e-12 * exact));
    }

    #[test]
    fn runge_function_needs_refinement_and_gets_it() {
        // ∫_{-1}^{1} 1/(1+25x²) dx = 2/5 atan 5, times the y length 0.5.
        let est = integrate_2d(
            |x, _| 1.0 / (1.0 + 25.0 * x * x),
            (-1.0, 1.0),
            (0.0, 0.5),
            Tolerance::new(1e-13, 0.0),
        );
        let exact = 0.5 * 0.4 * 5f64.atan();
        assert!(est.converged);
        assert!((est.value - exact).abs() < 1e-12, "{est:?} vs {exact}");
        assert!(est.evals > EVALS_PER_RECT);
    }

    #[test]
    fn reversed_and_empty_ranges() {
        let f = |x: f64, y: f64| x * y + 1.0;
        let fwd = integrate_2d(f, (0.0, 1.0), (0.0, 2.0), Tolerance::default());
        let rev = integrate_2d(f, (1.0, 0.0), (0.0, 2.0), Tolerance::default());
        assert!((fwd.value - 3.0).abs() < 1e-13);
        assert!((rev.value + 3.0).abs() < 1e-13);
        let empty = integrate_2d(f, (1.0, 1.0), (0.0, 2.0), Tolerance::default());
        assert_eq!(empty.value, 0.0);
        assert!(empty.converged);
    }

    #[test]
    fn non_finite_integrand_is_reported() {
        let est = integrate_2d(
            |x, _| if x > 0.5 { f64::NAN } else { 1.0 },
            (0.0, 1.0),
            (0.0, 1.0),
            Tolerance::default(),
        );
        assert!(!est.converged);
        assert!(est.value.is_nan());
        assert_eq!(est.error, f64::INFINITY);
        let est = integrate_2d(
            |x, _| x,
            (0.0, f64::INFINITY),
            (0.0, 1.0),
            Tolerance::default(),
        );
        assert!(!est.converged && est.value.is_nan());
    }

    #[test]
    fn budget_is_respected() {
        let tol = Tolerance::new(0.0, 0.0).with_max_evals(10 * EVALS_PER_RECT);
        let est = integrate_2d(
            |x, y| (x - 0.3).abs() + (y - 0.7).abs(),
            (0.0, 1.0),
            (0.0, 1.0),
            tol,
        );
        assert!(!est.converged);
        assert!(est.evals <= 10 * EVALS_PER_RECT);
        // ∫∫ |x−a| + |y−b| = (a²+(1−a)²)/2 + (b²+(1−b)²)/2
        let exact = 0.5 * (0.09 + 0.49) + 0.5 * (0.49 + 0.09);
        assert!((est.value - exact).abs() < 1e-3);
        assert!((est.value - exact).abs() <= est.error);
    }

    #[test]
    fn narrow_gaussian_peak_with_initial_grid() {
        let s: f64 = 1e-3;
        let f =
            |x: f64, y: f64| (-((x - 0.3137).powi(2) + (y - 0.6071).powi(2)) / (2.0 * s * s)).exp();
        let tol = Tolerance::new(1e-14, 1e-9).with_initial(64, 64);
        let est = integrate_2d(f, (0.0, 1.0), (0.0, 1.0), tol);
        let exact = TAU * s * s;
        assert!(est.converged, "{est:?}");
        assert!(
            ((est.value - exact) / exact).abs() < 1e-8,
            "{est:?} vs {exact}"
        );
    }

    #[test]
    fn gauss_legendre_rules_are_exact_to_their_degree() {
        for n in [1, 2, 4, 32, 128] {
            let rule = gauss_legendre(n);
            assert_eq!(rule.len(), n);
            let wsum: f64 = rule.iter().map(|r| r.1).sum();
            assert!((wsum - 2.0).abs() < 1e-13, "n {n}: Σw = {wsum}");
            // ∫ x^(2n−2) over [−1, 1] = 2/(2n − 1).
            let d = 2 * n as i32 - 2;
            let got: f64 = rule.iter().map(|&(x, w)| w * x.powi(d)).sum();
            assert!((got - 2.0 / f64::from(d + 1)).abs() < 1e-12, "n {n}: {got}");
        }
        let four = gauss_legendre(4);
        let mut xs: Vec<f64> = four.iter().map(|r| r.0.abs()).collect();
        xs.sort_by(f64::total_cmp);
        assert!((xs[0] - 0.339_981_043_584_856_3).abs() < 1e-15);
    }

    #[test]
    fn gauss_legendre_4x4_is_exact_for_degree_7() {
        let f = |x: f64, y: f64| x.powi(7) + 3.0 * x.powi(6) * y.powi(5) + y.powi(2);
        // ∫₀¹∫₋₁² f dy dx, with the x range reversed (signed width).
        let exact = 3.0 / 8.0 + 3.0 * (1.0 / 7.0) * (64.0 - 1.0) / 6.0 + 3.0 * 1.0;
        let est = gauss_legendre_4x4(f, 1.0, 0.0, -1.0, 2.0);
        assert!((est - exact).abs() < 1e-13, "{est} vs {exact}");
        let rgb = gauss_legendre_4x4(|x, y| crate::Rgb::splat(f(x, y)), 1.0, 0.0, -1.0, 2.0);
        assert_eq!(rgb, crate::Rgb::splat(est));
    }

    #[test]
    fn cosine_over_hemisphere_is_pi() {
        let est = integrate_hemisphere(|w| w.z, Tolerance::new(1e-13, 1e-13));
        assert!(est.converged);
        assert!((est.value - PI).abs() < 1e-11, "{est:?}");
    }

    #[test]
    fn one_over_sphere_is_four_pi() {
        let est = integrate_sphere(|_| 1.0, Tolerance::new(1e-13, 1e-13));
        assert!(est.converged);
        assert!((est.value - 4.0 * PI).abs() < 1e-11, "{est:?}");
    }

    #[test]
    fn sphere_region_of_a_cap() {
        // Cap theta < 0.3: area 2π (1 − cos 0.3); a phi quarter of it.
        let est =
            integrate_sphere_region(|_| 1.0, (0.0, 0.3), (0.0, FRAC_PI_2), Tolerance::default());
        let exact = FRAC_PI_2 * (1.0 - 0.3f64.cos());
        assert!((est.value - exact).abs() < 1e-14, "{est:?} vs {exact}");
        // ∫ z dω over the lower hemisphere is −π.
        let est =
            integrate_sphere_region(|w| w.z, (FRAC_PI_2, PI), (0.0, TAU), Tolerance::default());
        assert!((est.value + PI).abs() < 1e-12, "{est:?}");
    }

    #[test]
    fn narrow_tilted_lobe_integrates_to_one() {
        let n = 1e4;
        let t = 40f64.to_radians();
        let axis = spherical_direction(t, 0.0);
        let lobe = |w: DVec3| (n + 1.0) / TAU * w.dot(axis).max(0.0).powf(n);
        let est = integrate_sphere(lobe, Tolerance::new(1e-12, 1e-9));
        assert!(est.converged, "{est:?}");
        assert!((est.value - 1.0).abs() < 1e-6, "{est:?}");
        // The same lobe around the pole, on the hemisphere.
        let lobe_z = |w: DVec3| (n + 1.0) / TAU * w.z.max(0.0).powf(n);
        let est = integrate_hemisphere(lobe_z, Tolerance::new(1e-12, 1e-9));
        assert!((est.value - 1.0).abs() < 1e-6, "{est:?}");
    }

    #[test]
    fn helpers_build_what_they_say() {
        let t = Tolerance::absolute(1e-5)
            .with_max_evals(7)
            .with_initial(0, 3);
        assert_eq!(
            (t.abs, t.rel, t.max_evals, t.initial),
            (1e-5, 0.0, 7, Some((0, 3)))
        );
        let t = Tolerance::relative(1e-4);
        assert_eq!((t.abs, t.rel), (0.0, 1e-4));
        assert_eq!(t.target(-2.0), 2e-4);
        let d = spherical_direction(FRAC_PI_2, FRAC_PI_2);
        assert!((d - DVec3::Y).length() < 1e-15);
    }

    /// The many-at-a-time integrand gives the pointwise integral exactly
    /// (same nodes, same order, same sums), and is called once per
    /// rectangle with at most its 225 nodes, none at a pole.
    #[test]
    fn many_at_a_time_matches_pointwise() {
        use std::cell::Cell;
        let axis = spherical_direction(0.7, 1.1);
        let lobe = |w: DVec3| 31.0 / TAU * w.dot(axis).max(0.0).powi(30);
        let tol = Tolerance::new(1e-12, 1e-9);
        // A region touching the pole (theta from 0), where nodes are skipped.
        for theta in [(0.0, 1.2), (0.3, 1.9)] {
            let one = integrate_sphere_region(lobe, theta, (0.2, 4.0), tol);
            let calls = Cell::new(0usize);
            let many = integrate_sphere_region_many(
                |dirs: &[DVec3], out: &mut [f64]| {
                    assert!(!dirs.is_empty() && dirs.len() <= 225 && dirs.len() == out.len());
                    assert!(dirs.iter().all(|w| w.x != 0.0 || w.y != 0.0));
                    calls.set(calls.get() + 1);
                    for (o, &w) in out.iter_mut().zip(dirs) {
                        *o = lobe(w);
                    }
                },
                theta,
                (0.2, 4.0),
                tol,
            );
            assert_eq!(
                one.value.to_bits(),
                many.value.to_bits(),
                "{one:?} {many:?}"
            );
            assert_eq!((one.evals, one.converged), (many.evals, many.converged));
            assert!(calls.get() > 1 && calls.get() * 225 >= many.evals);
        }
    }
}
