//! Numbers and text for the page: HTML escapes, scientific notation,
//! factors, percentages, shell words.

use lobe::Rgb;
use lobe::math::luminance;

/// Escape text for HTML.
pub(super) fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The text of an HTML fragment without its tags.
pub(super) fn strip_tags(s: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for c in s.chars() {
        match c {
            '<' => inside = true,
            '>' => inside = false,
            _ if !inside => out.push(c),
            _ => {}
        }
    }
    out
}

/// `1.23×10<sup>−5</sup>`, with `digits` decimals.
pub(super) fn sci(x: f64, digits: usize) -> String {
    let s = format!("{x:.digits$e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    format!(
        "{}×10<sup>{}</sup>",
        m.replace('-', "−"),
        e.replace('-', "−")
    )
}

/// A number with about four significant digits, scientific when far from 1.
pub(super) fn num(x: f64) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    // Round to four significant digits first, so that 0.99999 reads 1.000.
    let a: f64 = format!("{:.3e}", x.abs()).parse().unwrap_or(x.abs());
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.decimals$}").replace('-', "−")
    } else {
        sci(x, 3)
    }
}

/// A factor such as a variance reduction: `12.3×`, `4.1×10³ ×`.
pub(super) fn factor(x: f64) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    if x >= 1e4 {
        format!("{}&thinsp;×", sci(x, 1))
    } else if x >= 100.0 {
        format!("{x:.0}×")
    } else if x >= 10.0 {
        format!("{x:.1}×")
    } else {
        format!("{x:.2}×")
    }
}

pub(super) fn percent(x: f64) -> String {
    if !x.is_finite() {
        "—".into()
    } else if x == 0.0 {
        "0".into()
    } else if x < 0.001 {
        "&lt;0.1%".into()
    } else {
        format!("{:.1}%", 100.0 * x)
    }
}

pub(super) fn lum(c: [f64; 3]) -> f64 {
    luminance(Rgb::from_array(c))
}

/// `s` as a shell word: bare when it is plain, else in single quotes.
pub(super) fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "@%+=:,./_-".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}
