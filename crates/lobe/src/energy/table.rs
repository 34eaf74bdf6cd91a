//! Tables of the directional albedo `E(μ, α)` of a single-scattering
//! microfacet lobe: the energy it keeps when light arrives at `cos θ = μ`,
//! and its cosine-weighted average `E_avg(α) = 2 ∫ E(μ) μ dμ`. Energy
//! compensation ([`super::compensation`]) gives back `1 − E`.
//!
//! One table per normal distribution and [`Surface`]: a conductor's
//! reflection with `F = 1` and one of Smith's terms, or a rough dielectric
//! interface's reflection plus transmission (`R + T`, exact Fresnel, Smith's
//! separable term, energy as carried in importance mode), which depends on
//! the relative index `η` as well. Nodes:
//!
//! | axis | nodes | node `k` of `n` |
//! |---|---|---|
//! | `μ = cos θo` | `n_mu` | `μ = x²`, `x = k/(n−1)` (dense at grazing angles, where `E` falls fast); node 0 is computed at `μ = 10⁻⁴` |
//! | `α` | `n_alpha` | `α = 2y²`, `y = k/(n−1)` (dense at small `α`); node 0 is computed at `α = 10⁻⁴` |
//! | `η` (dielectric) | `n_eta` | `η = 3^(2k/(n−1) − 1)`: from 1/3 to 3, `η = 1` in the middle; `η` of the far side over the side of `wo` |
//!
//! Between nodes `E` is bilinear in `(x, y)` (and cubic, Catmull-Rom, in
//! `ln η`, where it bends sharply near total internal reflection); `E_avg` is the exact integral
//! of that interpolant, so that a compensated white lobe reflects
//! `E_true(μ) + 1 − E_table(μ)`: only the table's own error at `μ` remains.
//!
//! The file format (version 1) is text: a first line `lobe-energy 1`,
//! comment lines starting `#`, then per table a line
//! `table NDF SURFACE N_MU N_ALPHA SAMPLES SEED [N_ETA]` (`SURFACE` a
//! shadowing term's name or `dielectric`, which gives `N_ETA`) followed by
//! `N_ETA × N_ALPHA` lines of `N_MU` values of `E` (one line per `α` node,
//! `η` node by `η` node) and as many lines of their standard errors. [`AlbedoTables::builtin`] is the file
//! `crates/lobe/data/energy.txt`, made by `lobe tabulate-energy`.

use crate::error::{Error, Result};
use crate::microfacet::{MIN_ALPHA, Ndf, Shadowing};
use std::fmt::Write as _;

/// First word of the file format.
pub const FORMAT: &str = "lobe-energy";
/// The format version this build reads and writes.
pub const VERSION: u32 = 1;
/// Where node 0 of the `μ` axis is computed (`μ = 0` is degenerate).
pub const MIN_MU: f64 = 1e-4;
/// Largest `α` the tables reach (beyond it `E` is held at the last node).
pub const MAX_TABLE_ALPHA: f64 = 2.0;
/// The dielectric tables span `η ∈ [1/MAX_TABLE_ETA, MAX_TABLE_ETA]`
/// (beyond it `E` is held at the end nodes).
pub const MAX_TABLE_ETA: f64 = 3.0;

/// What a table is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Surface {
    /// A conductor's reflection with `F = 1` and this shadowing term.
    Conductor(Shadowing),
    /// A rough dielectric interface, `R + T` (Smith's separable term).
    Dielectric,
}

impl Surface {
    /// Its name in a table file: the shadowing term's, or `dielectric`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Surface::Conductor(s) => s.name(),
            Surface::Dielectric => "dielectric",
        }
    }
}

impl std::str::FromStr for Surface {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        if s == "dielectric" {
            return Ok(Surface::Dielectric);
        }
        s.parse::<Shadowing>()
            .map(Surface::Conductor)
            .map_err(|_| Error::UnknownName {
                field: "surface".into(),
                value: s.into(),
                expected: format!("{}, dielectric", Shadowing::NAMES),
            })
    }
}

/// `η` of node `k` of `n` (one node: `η = 1`).
#[must_use]
pub fn eta_node(k: usize, n: usize) -> f64 {
    if n < 2 {
        return 1.0;
    }
    MAX_TABLE_ETA.powf(2.0 * k as f64 / (n - 1) as f64 - 1.0)
}

/// `μ` of node `k` of `n`.
#[must_use]
pub fn mu_node(k: usize, n: usize) -> f64 {
    let x = k as f64 / (n - 1) as f64;
    (x * x).max(MIN_MU)
}

/// `α` of node `k` of `n`.
#[must_use]
pub fn alpha_node(k: usize, n: usize) -> f64 {
    let y = k as f64 / (n - 1) as f64;
    (MAX_TABLE_ALPHA * y * y).max(MIN_ALPHA)
}

/// The cell of `t ∈ [0, 1]` on `n` nodes and the weight of its upper node.
#[inline]
fn locate(t: f64, n: usize) -> (usize, f64) {
    let f = t.clamp(0.0, 1.0) * (n - 1) as f64;
    let k = (f as usize).min(n - 2);
    (k, f - k as f64)
}

/// `E(μ)` of a conductor's table at one `α`, its `α` cell found once: what
/// a material looks up per sample (the same numbers as
/// [`AlbedoTable::e`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlbedoRow {
    table: &'static AlbedoTable,
    j: usize,
    tj: f64,
}

impl AlbedoRow {
    /// `E(μ)` at the row's `α`, bilinear between nodes as [`AlbedoTable::e`].
    #[inline]
    #[must_use]
    pub fn e(&self, mu: f64) -> f64 {
        let t = self.table;
        let (i, ti) = locate(mu.max(0.0).sqrt(), t.n_mu);
        let at = |j: usize| {
            let r = &t.values[j * t.n_mu..];
            r[i] + (r[i + 1] - r[i]) * ti
        };
        let (a, b) = (at(self.j), at(self.j + 1));
        a + (b - a) * self.tj
    }

    /// The table's `α` the row is at.
    #[must_use]
    pub fn table(&self) -> &'static AlbedoTable {
        self.table
    }
}

/// `E(μ, α)` (and `η`) of one normal distribution and surface, with the
/// standard error of each node.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoTable {
    pub ndf: Ndf,
    pub surface: Surface,
    pub n_mu: usize,
    pub n_alpha: usize,
    /// 1 for a conductor's table.
    pub n_eta: usize,
    /// Samples per node of the estimate, and the seed of its streams.
    pub samples: u64,
    pub seed: u64,
    /// `E` at node `(k, j, i)` (`η` node `k`, `α` node `j`, `μ` node `i`)
    /// at `(k·n_alpha + j)·n_mu + i`.
    pub values: Vec<f64>,
    /// The standard error of each value, in the same order.
    pub std_errors: Vec<f64>,
    /// `E_avg` of each `(η, α)` node.
    averages: Vec<f64>,
}

impl AlbedoTable {
    /// A table from its values (checked: shape, every value finite and in
    /// `[0, 1.01]`, every error finite and ≥ 0); `what` names it in errors.
    pub fn new(
        ndf: Ndf,
        surface: Surface,
        (n_mu, n_alpha, n_eta): (usize, usize, usize),
        (samples, seed): (u64, u64),
        values: Vec<f64>,
        std_errors: Vec<f64>,
    ) -> std::result::Result<Self, String> {
        if n_mu < 2 || n_alpha < 2 {
            return Err(format!(
                "needs at least 2 × 2 nodes, has {n_mu} × {n_alpha}"
            ));
        }
        let dielectric = surface == Surface::Dielectric;
        if dielectric != (n_eta >= 2) || n_eta == 0 {
            return Err(format!(
                "{n_eta} eta nodes: a dielectric table has at least 2, a conductor's 1"
            ));
        }
        let n = n_mu * n_alpha * n_eta;
        if values.len() != n || std_errors.len() != n {
            return Err(format!(
                "{n_eta} × {n_alpha} × {n_mu} nodes need {n} values and {n} errors, found {} and {}",
                values.len(),
                std_errors.len()
            ));
        }
        if let Some(k) = values
            .iter()
            .position(|v| !(v.is_finite() && (0.0..=1.01).contains(v)))
        {
            return Err(format!(
                "value {} at alpha node {}, mu node {} is not an albedo in [0, 1]",
                values[k],
                k / n_mu % n_alpha,
                k % n_mu
            ));
        }
        if let Some(k) = std_errors
            .iter()
            .position(|v| !(v.is_finite() && *v >= 0.0))
        {
            return Err(format!(
                "standard error {} at alpha node {}, mu node {} is not a number >= 0",
                std_errors[k],
                k / n_mu % n_alpha,
                k % n_mu
            ));
        }
        let averages = values.chunks(n_mu).map(row_average).collect();
        Ok(AlbedoTable {
            ndf,
            surface,
            n_mu,
            n_alpha,
            n_eta,
            samples,
            seed,
            values,
            std_errors,
            averages,
        })
    }

    /// The row of a conductor's table at `alpha` (clamped to the table),
    /// for many lookups at one `α`.
    #[must_use]
    pub fn row(&'static self, alpha: f64) -> AlbedoRow {
        let (j, tj) = locate((alpha.max(0.0) / MAX_TABLE_ALPHA).sqrt(), self.n_alpha);
        AlbedoRow { table: self, j, tj }
    }

    /// `E(μ, α)` of a conductor's table, bilinear between nodes (`μ`, `α`
    /// clamped to the table).
    #[inline]
    #[must_use]
    pub fn e(&self, mu: f64, alpha: f64) -> f64 {
        self.e_eta(mu, alpha, 1.0)
    }

    /// `E(μ, α, η)`: trilinear between nodes in `(√μ, √(α/2), ln η)`
    /// (clamped to the table; `η` ignored by a conductor's table).
    #[inline]
    #[must_use]
    pub fn e_eta(&self, mu: f64, alpha: f64, eta: f64) -> f64 {
        let (i, ti) = locate(mu.max(0.0).sqrt(), self.n_mu);
        let (j, tj) = locate((alpha.max(0.0) / MAX_TABLE_ALPHA).sqrt(), self.n_alpha);
        let row = |k: usize, j: usize| {
            let r = &self.values[(k * self.n_alpha + j) * self.n_mu..];
            r[i] + (r[i + 1] - r[i]) * ti
        };
        let at = |k: usize| {
            let (a, b) = (row(k, j), row(k, j + 1));
            a + (b - a) * tj
        };
        self.along_eta(eta, at)
    }

    /// `at(k)` of the `η` nodes around `eta`, by Catmull-Rom (cubic) in
    /// `ln η` between them (end nodes repeated at the ends); `at(0)` for a
    /// conductor's table.
    #[inline]
    fn along_eta(&self, eta: f64, at: impl Fn(usize) -> f64) -> f64 {
        let Some((k, t)) = self.eta_cell(eta) else {
            return at(0);
        };
        let last = self.n_eta - 1;
        let (t2, t3) = (t * t, t * t * t);
        let w = [
            0.5 * (-t3 + 2.0 * t2 - t),
            0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
            0.5 * (-3.0 * t3 + 4.0 * t2 + t),
            0.5 * (t3 - t2),
        ];
        let nodes = [k.saturating_sub(1), k, k + 1, (k + 2).min(last)];
        nodes.iter().zip(w).map(|(&n, w)| w * at(n)).sum()
    }

    /// The `η` cell and weight of `eta`; `None` for a conductor's table.
    #[inline]
    fn eta_cell(&self, eta: f64) -> Option<(usize, f64)> {
        (self.n_eta > 1).then(|| {
            let t = 0.5 * (eta.max(1e-300).ln() / MAX_TABLE_ETA.ln() + 1.0);
            locate(t, self.n_eta)
        })
    }

    /// `E_avg(α) = 2 ∫ E(μ, α) μ dμ` of the interpolated table, exactly.
    #[must_use]
    pub fn e_avg(&self, alpha: f64) -> f64 {
        self.e_avg_eta(alpha, 1.0)
    }

    /// `E_avg(α, η)` of the interpolated table, exactly.
    #[must_use]
    pub fn e_avg_eta(&self, alpha: f64, eta: f64) -> f64 {
        let (j, tj) = locate((alpha.max(0.0) / MAX_TABLE_ALPHA).sqrt(), self.n_alpha);
        let at = |k: usize| {
            let r = &self.averages[k * self.n_alpha..];
            r[j] + (r[j + 1] - r[j]) * tj
        };
        self.along_eta(eta, at)
    }

    /// This table in the file format (its `table` line and values).
    #[must_use]
    pub fn to_text(&self) -> String {
        let mut s = format!(
            "table {} {} {} {} {} {}",
            self.ndf.name(),
            self.surface.name(),
            self.n_mu,
            self.n_alpha,
            self.samples,
            self.seed
        );
        if self.surface == Surface::Dielectric {
            let _ = write!(s, " {}", self.n_eta);
        }
        s.push('\n');
        for (block, digits) in [(&self.values, 6), (&self.std_errors, 1)] {
            for row in block.chunks(self.n_mu) {
                let line: Vec<String> = row.iter().map(|v| format!("{v:.digits$e}")).collect();
                let _ = writeln!(s, "{}", line.join(" "));
            }
        }
        s
    }
}

/// `2 ∫₀¹ E(μ) μ dμ` of `E` linear in `x = √μ` between the nodes of `row`:
/// `∫₀¹ E(x) 4x³ dx`, a polynomial of degree 4 on each cell, integrated
/// exactly by 3-point Gauss-Legendre.
fn row_average(row: &[f64]) -> f64 {
    let n = row.len();
    let h = 1.0 / (n - 1) as f64;
    let rule = crate::stats::quadrature::gauss_legendre(3);
    let mut sum = 0.0;
    for k in 0..n - 1 {
        for &(t, w) in &rule {
            let s = 0.5 * (t + 1.0);
            let x = (k as f64 + s) * h;
            let e = row[k] + (row[k + 1] - row[k]) * s;
            sum += 0.5 * w * h * e * 4.0 * x * x * x;
        }
    }
    sum
}

/// A set of albedo tables, at most one per distribution and shadowing term.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AlbedoTables {
    pub tables: Vec<AlbedoTable>,
}

impl AlbedoTables {
    /// The table of `ndf` and `surface`, if the set has it.
    #[must_use]
    pub fn get(&self, ndf: Ndf, surface: Surface) -> Option<&AlbedoTable> {
        self.tables
            .iter()
            .find(|t| t.ndf == ndf && t.surface == surface)
    }

    /// The tables that come with lobe (`crates/lobe/data/energy.txt`).
    #[must_use]
    pub fn builtin() -> &'static AlbedoTables {
        static TABLES: std::sync::OnceLock<AlbedoTables> = std::sync::OnceLock::new();
        TABLES.get_or_init(|| {
            // A test parses this file: a failure here is a bug of the build.
            AlbedoTables::parse(
                include_str!("../../data/energy.txt"),
                "energy.txt (built in)",
            )
            .unwrap_or_else(|e| panic!("{e}"))
        })
    }

    /// Read a table file; the error names the file, and the line where it
    /// is wrong.
    pub fn read(path: &std::path::Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::File {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        AlbedoTables::parse(&text, &path.display().to_string())
    }

    /// Parse the text of a table file; `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self> {
        let fail = |line: usize, message: String| Error::File {
            path: name.to_string(),
            message: format!("line {line}: {message}"),
        };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(k, l)| (k + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let Some((n, first)) = lines.next() else {
            return Err(fail(
                1,
                format!("empty: a table file starts `{FORMAT} {VERSION}`"),
            ));
        };
        match first.split_whitespace().collect::<Vec<_>>()[..] {
            [f, v] if f == FORMAT => {
                if v != VERSION.to_string() {
                    return Err(fail(
                        n,
                        format!("version {v}: this build of lobe reads version {VERSION}"),
                    ));
                }
            }
            _ => {
                return Err(fail(
                    n,
                    format!("`{first}`: not a lobe energy table (it starts `{FORMAT} {VERSION}`)"),
                ));
            }
        }
        let mut tables = AlbedoTables::default();
        while let Some((n, head)) = lines.next() {
            let words: Vec<&str> = head.split_whitespace().collect();
            let expected = || {
                fail(
                    n,
                    format!(
                        "expected `table NDF SURFACE N_MU N_ALPHA SAMPLES SEED` \
                         (and N_ETA for a dielectric), found `{head}`"
                    ),
                )
            };
            let [
                "table",
                ndf,
                surface,
                n_mu,
                n_alpha,
                samples,
                seed,
                ref rest @ ..,
            ] = words[..]
            else {
                return Err(expected());
            };
            let ndf: Ndf = ndf.parse().map_err(|e: Error| fail(n, e.to_string()))?;
            let surface: Surface = surface.parse().map_err(|e: Error| fail(n, e.to_string()))?;
            let count = |what: &str, s: &str| -> Result<usize> {
                s.parse::<usize>()
                    .ok()
                    .filter(|&v| (2..=4096).contains(&v))
                    .ok_or_else(|| fail(n, format!("{what} `{s}` is not a count in [2, 4096]")))
            };
            let (n_mu, n_alpha) = (count("N_MU", n_mu)?, count("N_ALPHA", n_alpha)?);
            let n_eta = match (surface, rest) {
                (Surface::Dielectric, [e]) => count("N_ETA", e)?,
                (Surface::Conductor(_), []) => 1,
                _ => return Err(expected()),
            };
            let number = |what: &str, s: &str| -> Result<u64> {
                s.parse::<u64>()
                    .map_err(|_| fail(n, format!("{what} `{s}` is not a whole number")))
            };
            let (samples, seed) = (number("SAMPLES", samples)?, number("SEED", seed)?);
            let mut block = |what: &str| -> Result<Vec<f64>> {
                let mut out = Vec::with_capacity(n_mu * n_alpha * n_eta);
                for r in 0..n_alpha * n_eta {
                    let j = r % n_alpha;
                    let Some((ln, row)) = lines.next() else {
                        return Err(fail(
                            n,
                            format!(
                                "the table ends early: {what} has {r} of its {} rows",
                                n_alpha * n_eta
                            ),
                        ));
                    };
                    let before = out.len();
                    for w in row.split_whitespace() {
                        out.push(w.parse::<f64>().map_err(|_| {
                            fail(
                                ln,
                                format!("`{w}` is not a number ({what}, alpha node {j})"),
                            )
                        })?);
                    }
                    if out.len() - before != n_mu {
                        return Err(fail(
                            ln,
                            format!(
                                "{what} row of alpha node {j} has {} values, the table says {n_mu}",
                                out.len() - before
                            ),
                        ));
                    }
                }
                Ok(out)
            };
            let values = block("E")?;
            let errors = block("standard error")?;
            if tables.get(ndf, surface).is_some() {
                return Err(fail(
                    n,
                    format!("a second table of {} {}", ndf.name(), surface.name()),
                ));
            }
            let t = AlbedoTable::new(
                ndf,
                surface,
                (n_mu, n_alpha, n_eta),
                (samples, seed),
                values,
                errors,
            )
            .map_err(|m| fail(n, m))?;
            tables.tables.push(t);
        }
        Ok(tables)
    }

    /// The whole file: its first line, `comment` (each line after `# `),
    /// and every table.
    #[must_use]
    pub fn to_text(&self, comment: &str) -> String {
        let mut s = format!("{FORMAT} {VERSION}\n");
        for l in comment.lines() {
            let _ = writeln!(s, "# {l}");
        }
        for t in &self.tables {
            s.push_str(&t.to_text());
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(values: Vec<f64>, n_mu: usize, n_alpha: usize) -> AlbedoTable {
        let e = vec![0.001; values.len()];
        let s = Surface::Conductor(Shadowing::SmithCorrelated);
        AlbedoTable::new(Ndf::Ggx, s, (n_mu, n_alpha, 1), (16, 1), values, e).unwrap()
    }

    #[test]
    fn nodes_are_found_and_interpolated() {
        // E = x + y² on the nodes: bilinear in x, linear in y between nodes.
        let (nm, na) = (5, 4);
        let v = (0..na)
            .flat_map(|j| (0..nm).map(move |i| 0.5 * (i as f64 / 4.0) + 0.1 * j as f64))
            .collect();
        let t = table(v, nm, na);
        // At a node: its value.
        assert!((t.e(mu_node(2, nm), alpha_node(1, na)) - (0.25 + 0.1)).abs() < 1e-12);
        // Halfway in x between nodes 1 and 2, at α node 3.
        let x = 1.5 / 4.0;
        assert!((t.e(x * x, MAX_TABLE_ALPHA) - (0.5 * x + 0.3)).abs() < 1e-12);
        // Clamped beyond the table.
        assert_eq!(t.e(2.0, 9.0), t.e(1.0, MAX_TABLE_ALPHA));
    }

    #[test]
    fn the_average_integrates_the_interpolant() {
        // E = 1 everywhere: E_avg = 1; E = x = √μ: 2∫√μ μ dμ = 4/5.
        let t = table(vec![1.0; 12], 4, 3);
        assert!((t.e_avg(0.3) - 1.0).abs() < 1e-14);
        let t = table(
            (0..3)
                .flat_map(|_| (0..4).map(|i| i as f64 / 3.0))
                .collect(),
            4,
            3,
        );
        assert!((t.e_avg(0.3) - 0.8).abs() < 1e-14);
    }

    #[test]
    fn a_table_reads_back_what_it_wrote() {
        let t = table((0..12).map(|k| 0.5 + k as f64 / 100.0).collect(), 4, 3);
        let set = AlbedoTables { tables: vec![t] };
        let back = AlbedoTables::parse(&set.to_text("test\nsecond line"), "t").unwrap();
        assert_eq!(back.tables.len(), 1);
        for (a, b) in back.tables[0].values.iter().zip(&set.tables[0].values) {
            assert!((a - b).abs() < 1e-6);
        }
    }

    #[test]
    fn a_dielectric_table_reads_back_and_is_cubic_in_ln_eta() {
        // E = (ln η)² on 5 η nodes, the same over μ and α: Catmull-Rom is
        // exact for it between the inner nodes.
        let (nm, na, ne) = (3, 2, 5);
        let values: Vec<f64> = (0..ne)
            .flat_map(|k| {
                let l = eta_node(k, ne).ln();
                std::iter::repeat_n(0.1 * l * l, nm * na)
            })
            .collect();
        let e = vec![0.001; values.len()];
        let t = AlbedoTable::new(
            Ndf::Ggx,
            Surface::Dielectric,
            (nm, na, ne),
            (16, 1),
            values,
            e,
        )
        .unwrap();
        let eta = 1.3f64;
        let want = 0.1 * eta.ln() * eta.ln();
        assert!(
            (t.e_eta(0.5, 0.3, eta) - want).abs() < 1e-12,
            "{}",
            t.e_eta(0.5, 0.3, eta)
        );
        assert!((t.e_avg_eta(0.3, eta) - want).abs() < 1e-12);
        let text = AlbedoTables { tables: vec![t] }.to_text("");
        assert!(text.contains("table ggx dielectric 3 2 16 1 5"), "{text}");
        let back = AlbedoTables::parse(&text, "t").unwrap();
        assert_eq!(back.tables[0].n_eta, 5);
        // A dielectric table without its N_ETA.
        let e = AlbedoTables::parse(&text.replace(" 16 1 5", " 16 1"), "t").unwrap_err();
        assert!(e.to_string().contains("N_ETA"), "{e}");
    }

    #[test]
    fn bad_files_are_refused_by_line() {
        let good = AlbedoTables {
            tables: vec![table(vec![0.9; 6], 3, 2)],
        }
        .to_text("");
        let err = |text: &str| AlbedoTables::parse(text, "my.txt").unwrap_err().to_string();
        assert!(err("").contains("my.txt"), "{}", err(""));
        assert!(err("lobe-energy 2\n").contains("version 2"));
        assert!(err("hello\n").contains("not a lobe energy table"));
        // A row one value short.
        let short = good.replacen("9.000000e-1 9.000000e-1 9.000000e-1", "9e-1 9e-1", 1);
        let e = err(&short);
        assert!(e.contains("line 3") && e.contains("has 2 values"), "{e}");
        // A row missing.
        let lines: Vec<&str> = good.lines().collect();
        let e = err(&lines[..lines.len() - 1].join("\n"));
        assert!(e.contains("ends early"), "{e}");
        assert!(err(&good.replace("ggx", "gauss")).contains("gauss"));
        assert!(err(&good.replacen("9.000000e-1", "nan", 1)).contains("not an albedo"));
        assert!(err(&good.replacen("9.000000e-1", "x", 1)).contains("`x` is not a number"));
        let twice = format!(
            "{good}{}",
            good.lines().skip(1).collect::<Vec<_>>().join("\n")
        );
        assert!(err(&twice).contains("second table"));
    }

    #[test]
    fn the_builtin_tables_parse() {
        let b = AlbedoTables::builtin();
        for (ndf, s) in crate::energy::tabulate::TABLES {
            assert!(
                b.get(ndf, s).is_some(),
                "no built-in table of {ndf:?} {s:?}"
            );
        }
    }
}
