//! Tables of the directional albedo `E(μ, α)` of a single-scattering
//! microfacet reflection lobe with `F = 1`: the energy it keeps when light
//! arrives at `cos θ = μ`, and its cosine-weighted average
//! `E_avg(α) = 2 ∫ E(μ) μ dμ`. Energy compensation ([`super::compensation`])
//! adds back `1 − E`.
//!
//! One table per normal distribution and shadowing term. Nodes:
//!
//! | axis | nodes | node `k` of `n` |
//! |---|---|---|
//! | `μ = cos θo` | `n_mu` | `μ = x²`, `x = k/(n−1)` (dense at grazing angles, where `E` falls fast); node 0 is computed at `μ = 10⁻⁴` |
//! | `α` | `n_alpha` | `α = 2y²`, `y = k/(n−1)` (dense at small `α`); node 0 is computed at `α = 10⁻⁴` |
//!
//! Between nodes `E` is bilinear in `(x, y)`; `E_avg` is the exact integral
//! of that interpolant, so that a compensated white lobe reflects
//! `E_true(μ) + 1 − E_table(μ)`: only the table's own error at `μ` remains.
//!
//! The file format (version 1) is text: a first line `lobe-energy 1`,
//! comment lines starting `#`, then per table a line
//! `table NDF SHADOWING N_MU N_ALPHA SAMPLES SEED` followed by `N_ALPHA`
//! lines of `N_MU` values of `E` (one line per `α` node) and `N_ALPHA`
//! lines of their standard errors. [`AlbedoTables::builtin`] is the file
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

/// `E(μ, α)` of one normal distribution and shadowing term, with the
/// standard error of each node.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoTable {
    pub ndf: Ndf,
    pub shadowing: Shadowing,
    pub n_mu: usize,
    pub n_alpha: usize,
    /// Samples per node of the estimate, and the seed of its streams.
    pub samples: u64,
    pub seed: u64,
    /// `E` at node `(j, i)` (`α` node `j`, `μ` node `i`) at `j·n_mu + i`.
    pub values: Vec<f64>,
    /// The standard error of each value, in the same order.
    pub std_errors: Vec<f64>,
    /// `E_avg` of each `α` node.
    averages: Vec<f64>,
}

impl AlbedoTable {
    /// A table from its values (checked: shape, every value finite and in
    /// `[0, 1.01]`, every error finite and ≥ 0); `what` names it in errors.
    pub fn new(
        ndf: Ndf,
        shadowing: Shadowing,
        (n_mu, n_alpha): (usize, usize),
        (samples, seed): (u64, u64),
        values: Vec<f64>,
        std_errors: Vec<f64>,
    ) -> std::result::Result<Self, String> {
        if n_mu < 2 || n_alpha < 2 {
            return Err(format!("needs at least 2 × 2 nodes, has {n_mu} × {n_alpha}"));
        }
        let n = n_mu * n_alpha;
        if values.len() != n || std_errors.len() != n {
            return Err(format!(
                "{n_mu} × {n_alpha} nodes need {n} values and {n} errors, found {} and {}",
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
                k / n_mu,
                k % n_mu
            ));
        }
        if let Some(k) = std_errors.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(format!(
                "standard error {} at alpha node {}, mu node {} is not a number >= 0",
                std_errors[k],
                k / n_mu,
                k % n_mu
            ));
        }
        let averages = (0..n_alpha)
            .map(|j| row_average(&values[j * n_mu..(j + 1) * n_mu]))
            .collect();
        Ok(AlbedoTable {
            ndf,
            shadowing,
            n_mu,
            n_alpha,
            samples,
            seed,
            values,
            std_errors,
            averages,
        })
    }

    /// `E(μ, α)`, bilinear between nodes (`μ`, `α` clamped to the table).
    #[inline]
    #[must_use]
    pub fn e(&self, mu: f64, alpha: f64) -> f64 {
        let (i, ti) = locate(mu.max(0.0).sqrt(), self.n_mu);
        let (j, tj) = locate((alpha.max(0.0) / MAX_TABLE_ALPHA).sqrt(), self.n_alpha);
        let row = |j: usize| {
            let r = &self.values[j * self.n_mu..];
            r[i] + (r[i + 1] - r[i]) * ti
        };
        let (a, b) = (row(j), row(j + 1));
        a + (b - a) * tj
    }

    /// `E_avg(α) = 2 ∫ E(μ, α) μ dμ` of the interpolated table, exactly.
    #[must_use]
    pub fn e_avg(&self, alpha: f64) -> f64 {
        let (j, tj) = locate((alpha.max(0.0) / MAX_TABLE_ALPHA).sqrt(), self.n_alpha);
        let (a, b) = (self.averages[j], self.averages[j + 1]);
        a + (b - a) * tj
    }

    /// This table in the file format (its `table` line and values).
    #[must_use]
    pub fn to_text(&self) -> String {
        let mut s = format!(
            "table {} {} {} {} {} {}\n",
            self.ndf.name(),
            self.shadowing.name(),
            self.n_mu,
            self.n_alpha,
            self.samples,
            self.seed
        );
        for (block, digits) in [(&self.values, 7), (&self.std_errors, 2)] {
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
    /// The table of `ndf` and `shadowing`, if the set has it.
    #[must_use]
    pub fn get(&self, ndf: Ndf, shadowing: Shadowing) -> Option<&AlbedoTable> {
        self.tables
            .iter()
            .find(|t| t.ndf == ndf && t.shadowing == shadowing)
    }

    /// The tables that come with lobe (`crates/lobe/data/energy.txt`).
    #[must_use]
    pub fn builtin() -> &'static AlbedoTables {
        static TABLES: std::sync::OnceLock<AlbedoTables> = std::sync::OnceLock::new();
        TABLES.get_or_init(|| {
            // A test parses this file: a failure here is a bug of the build.
            AlbedoTables::parse(include_str!("../../data/energy.txt"), "energy.txt (built in)")
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
            return Err(fail(1, format!("empty: a table file starts `{FORMAT} {VERSION}`")));
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
            let ["table", ndf, shadowing, n_mu, n_alpha, samples, seed] = words[..] else {
                return Err(fail(
                    n,
                    format!(
                        "expected `table NDF SHADOWING N_MU N_ALPHA SAMPLES SEED`, found `{head}`"
                    ),
                ));
            };
            let ndf: Ndf = ndf.parse().map_err(|e: Error| fail(n, e.to_string()))?;
            let shadowing: Shadowing =
                shadowing.parse().map_err(|e: Error| fail(n, e.to_string()))?;
            let count = |what: &str, s: &str| -> Result<usize> {
                s.parse::<usize>()
                    .ok()
                    .filter(|&v| (2..=4096).contains(&v))
                    .ok_or_else(|| fail(n, format!("{what} `{s}` is not a count in [2, 4096]")))
            };
            let (n_mu, n_alpha) = (count("N_MU", n_mu)?, count("N_ALPHA", n_alpha)?);
            let number = |what: &str, s: &str| -> Result<u64> {
                s.parse::<u64>()
                    .map_err(|_| fail(n, format!("{what} `{s}` is not a whole number")))
            };
            let (samples, seed) = (number("SAMPLES", samples)?, number("SEED", seed)?);
            let mut block = |what: &str| -> Result<Vec<f64>> {
                let mut out = Vec::with_capacity(n_mu * n_alpha);
                for j in 0..n_alpha {
                    let Some((ln, row)) = lines.next() else {
                        return Err(fail(
                            n,
                            format!(
                                "the table ends early: {what} has {j} of its {n_alpha} rows"
                            ),
                        ));
                    };
                    let before = out.len();
                    for w in row.split_whitespace() {
                        out.push(w.parse::<f64>().map_err(|_| {
                            fail(ln, format!("`{w}` is not a number ({what}, alpha node {j})"))
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
            if tables.get(ndf, shadowing).is_some() {
                return Err(fail(
                    n,
                    format!("a second table of {} {}", ndf.name(), shadowing.name()),
                ));
            }
            let t = AlbedoTable::new(ndf, shadowing, (n_mu, n_alpha), (samples, seed), values, errors)
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
        AlbedoTable::new(Ndf::Ggx, Shadowing::SmithCorrelated, (n_mu, n_alpha), (16, 1), values, e)
            .unwrap()
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
        let t = table((0..3).flat_map(|_| (0..4).map(|i| i as f64 / 3.0)).collect(), 4, 3);
        assert!((t.e_avg(0.3) - 0.8).abs() < 1e-14);
    }

    #[test]
    fn a_table_reads_back_what_it_wrote() {
        let t = table((0..12).map(|k| 0.5 + k as f64 / 100.0).collect(), 4, 3);
        let set = AlbedoTables { tables: vec![t] };
        let back = AlbedoTables::parse(&set.to_text("test\nsecond line"), "t").unwrap();
        assert_eq!(back.tables.len(), 1);
        for (a, b) in back.tables[0].values.iter().zip(&set.tables[0].values) {
            assert!((a - b).abs() < 1e-7);
        }
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
        let short = good.replacen("9.0000000e-1 9.0000000e-1 9.0000000e-1", "9e-1 9e-1", 1);
        let e = err(&short);
        assert!(e.contains("line 3") && e.contains("has 2 values"), "{e}");
        // A row missing.
        let lines: Vec<&str> = good.lines().collect();
        let e = err(&lines[..lines.len() - 1].join("\n"));
        assert!(e.contains("ends early"), "{e}");
        assert!(err(&good.replace("ggx", "gauss")).contains("gauss"));
        assert!(err(&good.replacen("9.0000000e-1", "nan", 1)).contains("not an albedo"));
        assert!(err(&good.replacen("9.0000000e-1", "x", 1)).contains("`x` is not a number"));
        let twice = format!("{good}{}", good.lines().skip(1).collect::<Vec<_>>().join("\n"));
        assert!(err(&twice).contains("second table"));
    }

    #[test]
    fn the_builtin_tables_parse() {
        let b = AlbedoTables::builtin();
        for ndf in [Ndf::Ggx, Ndf::Beckmann] {
            for s in [Shadowing::SmithSeparable, Shadowing::SmithCorrelated] {
                assert!(b.get(ndf, s).is_some(), "no built-in table of {ndf:?} {s:?}");
            }
        }
    }
}
