//! The colours the figures share: text, grid lines, outlines, and the
//! viridis colour map of every heat map and error map.

use plotters::style::RGBColor;

/// Text.
pub const TEXT: RGBColor = RGBColor(30, 30, 30);
/// Secondary text: axis ticks, notes, keys.
pub const DIM_TEXT: RGBColor = RGBColor(100, 100, 100);
/// Major grid lines.
pub const GRID: RGBColor = RGBColor(215, 215, 215);
/// Minor grid lines.
pub const LIGHT_GRID: RGBColor = RGBColor(238, 238, 238);
/// Frames of maps and colour bars.
pub const OUTLINE: RGBColor = RGBColor(120, 120, 120);

/// The viridis colour map (perceptually uniform, readable in grey and by
/// colour-blind readers) at `t ∈ [0, 1]` (clamped; NaN gives the low end).
/// Linear interpolation between ten anchors of the published map.
#[must_use]
pub fn viridis(t: f64) -> RGBColor {
    const ANCHORS: [(u8, u8, u8); 10] = [
        (0x44, 0x01, 0x54),
        (0x48, 0x28, 0x78),
        (0x3e, 0x4a, 0x89),
        (0x31, 0x68, 0x8e),
        (0x26, 0x82, 0x8e),
        (0x1f, 0x9e, 0x89),
        (0x35, 0xb7, 0x79),
        (0x6d, 0xcd, 0x59),
        (0xb4, 0xde, 0x2c),
        (0xfd, 0xe7, 0x25),
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (ANCHORS.len() - 1) as f64;
    let k = (s.floor() as usize).min(ANCHORS.len() - 2);
    let f = s - k as f64;
    let (a, b) = (ANCHORS[k], ANCHORS[k + 1]);
    let mix = |x: u8, y: u8| (f64::from(x) + f * (f64::from(y) - f64::from(x))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The names whose colour is fixed, so that a strategy has the same colour
/// in every figure: every strategy lobe knows, in [`lobe::Strategy::all`] order.
fn strategy_order() -> Vec<String> {
    lobe::Strategy::all().iter().map(|s| s.name()).collect()
}

/// Twelve colours that stay apart: Okabe–Ito's seven (yellow left out),
/// then purple, brown, crimson, olive and indigo.
const STRATEGY_PALETTE: [RGBColor; 12] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(117, 60, 160),
    RGBColor(140, 86, 40),
    RGBColor(170, 30, 60),
    RGBColor(110, 130, 0),
    RGBColor(50, 50, 140),
];

/// The colour of the strategy `names[k]`: fixed for the known names, else
/// the next colour after them in order of first appearance.
pub fn strategy_color(names: &[&str], k: usize) -> RGBColor {
    let name = names[k];
    let order = strategy_order();
    if let Some(i) = order.iter().position(|n| n == name) {
        return STRATEGY_PALETTE[i];
    }
    let mut unknown: Vec<&str> = Vec::new();
    for n in names {
        if !order.iter().any(|o| o == n) && !unknown.contains(n) {
            unknown.push(n);
        }
    }
    let i = unknown.iter().position(|n| *n == name).unwrap_or(0);
    STRATEGY_PALETTE[(order.len() + i) % STRATEGY_PALETTE.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends() {
        assert_eq!(viridis(0.0), RGBColor(0x44, 0x01, 0x54));
        assert_eq!(viridis(1.0), RGBColor(0xfd, 0xe7, 0x25));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }
}
