//! Numbers as labels: superscript powers, short decimals, p-values, times,
//! and the ticks of linear and logarithmic scales.

/// `n` as Unicode superscript digits, with a real minus sign.
pub fn superscript(n: i64) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

/// `base^k` for an integer-valued `k`, e.g. `2¹⁰`, `10⁻³`.
pub fn power_label(base: u32, k: f64) -> String {
    format!("{base}{}", superscript(k.round() as i64))
}

/// A short human number: `0.0123`, `4.5`, `1200`, `3.2e-7`, with `−`.
pub fn fmt_num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { format!("{v}") };
    }
    let a = v.abs();
    let s = if (1e-3..1e6).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).clamp(0, 5) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let e = a.log10().floor();
        let m = v / 10f64.powf(e);
        let m = format!("{m:.1}");
        let m = m.trim_end_matches('0').trim_end_matches('.');
        format!("{m}e{}", e as i64)
    };
    s.replace('-', "−")
}

/// The p-value as text: four decimals, or scientific below 1e-4.
pub fn fmt_p(p: f64) -> String {
    if p == 0.0 {
        "0".into()
    } else if p < 1e-4 {
        format!("{p:.1e}").replace('-', "−")
    } else {
        format!("{p:.4}")
    }
}

/// A "nice" step (1, 2 or 5 × 10^k) giving about `count` steps over `span`.
fn nice_step(span: f64, count: f64) -> f64 {
    let raw = (span / count).max(f64::MIN_POSITIVE);
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let m = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * p
}

/// Ticks (position in [0, 1] along a colour bar, label) for a log10 scale
/// from `lo` to `hi` (in log10 units): decades over a wide range, else
/// 1-2-5 (or finer) multiples.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let span = hi - lo;
    let eps = 0.01 * span;
    let mut ticks = Vec::new();
    if span >= 3.0 {
        let step = (span / 8.0).ceil().max(1.0);
        let mut k = ((lo - eps) / step).ceil() * step;
        while k <= hi + eps {
            let v = 10f64.powf(k);
            let label = if (1e-2..1e4).contains(&v) {
                fmt_num(v)
            } else {
                power_label(10, k)
            };
            ticks.push((((k - lo) / span).clamp(0.0, 1.0), label));
            k += step;
        }
    } else {
        let mantissas: &[f64] = if span < 0.6 {
            &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
        } else if span < 1.5 {
            &[1.0, 2.0, 3.0, 5.0]
        } else {
            &[1.0, 2.0, 5.0]
        };
        for d in (lo.floor() as i64)..=(hi.ceil() as i64) {
            for &m in mantissas {
                let t = (d as f64) + f64::log10(m);
                if t >= lo - eps && t <= hi + eps {
                    ticks.push((((t - lo) / span).clamp(0.0, 1.0), fmt_num(10f64.powf(t))));
                }
            }
        }
    }
    ticks
}

/// Ticks for a linear scale from 0 to `hi`.
pub fn linear_ticks(hi: f64) -> Vec<(f64, String)> {
    let step = nice_step(hi, 5.0);
    let mut ticks = Vec::new();
    let mut k = 0.0;
    while k <= hi * (1.0 + 1e-9) {
        ticks.push((k / hi, fmt_num(k)));
        k += step;
    }
    ticks
}

/// A time for captions: `4.2 ms`, `85 ms`, `0.84 s`, `12.3 s`, `95 s`.
#[must_use]
pub fn fmt_time(t: f64) -> String {
    if t < 0.01 {
        format!("{:.1} ms", t * 1e3)
    } else if t < 0.1 {
        format!("{:.0} ms", t * 1e3)
    } else if t < 10.0 {
        format!("{t:.2} s")
    } else if t < 100.0 {
        format!("{t:.1} s")
    } else {
        format!("{t:.0} s")
    }
}

/// Three significant digits, in plain decimals from 0.001 to 10000.
#[must_use]
pub fn sig3(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-3..1e4).contains(&a) {
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_well() {
        assert_eq!(fmt_num(0.0123), "0.0123");
        assert_eq!(fmt_num(1200.0), "1200");
        assert_eq!(fmt_num(-0.5), "−0.5");
        assert_eq!(fmt_num(3.2e-7), "3.2e−7");
        assert_eq!(superscript(-12), "⁻¹²");
        assert_eq!(power_label(2, 10.0), "2¹⁰");
    }
}
