//! `lobe compare`: render one scene under several strategies, at equal
//! samples and at equal time, next to a high-spp reference, and draw one
//! grid of the renders with their per-pixel error maps and RMSE.
//!
//! The renders and the numbers come from [`lobe_render::compare`]; this
//! module parses the arguments, shows progress, draws the grid
//! ([`write_grid`]) and writes NAME.json ([`summary`]). `lobe demo` draws
//! its showcase with the same pieces.

use crate::common::Bar;
use crate::figures::viridis;
use anyhow::{Result, anyhow, bail};
use clap::Args;
use lobe::estimator::Strategy;
use lobe::progress::SystemClock;
use lobe_render::compare::{
    CompareSettings, Comparison, LogScale, Shot, default_reference_spp, default_strategies,
    error_epsilon, error_map, resample, run_comparison,
};
use lobe_render::{fallbacks, load_scene};
use plotters::coord::Shift;
use plotters::element::BitMapElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The arguments of `lobe compare`.
#[derive(Args, Debug)]
#[command(
    about = "Compare strategies on a scene at equal samples and equal time, with error maps",
    long_about = "Render a scene file (the format of `lobe render --help`) with each strategy twice: at \
                  equal samples (every strategy at --spp) and at equal time (every strategy with the \
                  samples per pixel that make its render take the time mis took at max(--spp, 32) spp (more when that is under 50 ms), \
                  or the slowest strategy when mis is not compared, within 3%: each is rendered again, \
                  up to 4 times, with the spp its earlier renders' times point to). Times are of the \
                  render alone: every strategy is first rendered once untimed (the start-up: threads, \
                  tables, memory), and a render under 0.1 s is timed as the fastest of 3 runs. The \
                  budget is at least 32 spp because whole samples per pixel cannot make small budgets \
                  equal (at 4 spp one sample is 25%). A reference is rendered with mis-balance at \
                  --reference-spp, from an independent seed.\n\n\
                  The RMSE of BSDF sampling (brdf, vndf) under the built-in sky is a few fireflies': \
                  a rare sample that finds the small, bright sun puts most of the squared error into \
                  one pixel (the `worst px` column), so its RMSE changes several-fold with --seed (on \
                  examples/scene.toml at 4 spp, seeds 1 to 8: brdf 1.2 to 28, vndf 1.2 to 26, the \
                  same mean); the table says when this is so.\n\n\
                  Writes NAME.png, one figure: the reference, and for each strategy and each row (equal \
                  samples, equal time) the render (tone-mapped as `lobe render`'s PNG) with its per-pixel \
                  error map: the relative error of luminance |Y - Y_ref| / (Y_ref + eps), eps = 1% of the \
                  reference's mean luminance, on one logarithmic colour scale shared by every map. Each \
                  caption gives the strategy, spp, wall time and RMSE (over all pixels and the three \
                  channels of linear RGB, against the reference). NAME.json holds the numbers: \
                  {\"reference\":{\"spp\",\"time_s\",..},\"equal_samples\":[{\"strategy\",\"spp\",\"time_s\",\
                  \"rmse\"}],\"equal_time\":[..],..}.\n\n\
                  The renders are the same for a given seed and spp on any thread count; the equal-time \
                  spp depend on the measured times.",
    after_help = "Examples:\n  \
                  lobe compare examples/scene.toml --spp 16 --out cmp\n  \
                  lobe compare examples/scene.toml --strategy brdf,light,mis,mis-one --spp 4 --reference-spp 256 --threads 2"
)]
pub struct CompareArgs {
    /// The scene file (TOML; `lobe render --help` shows the format)
    pub scene: PathBuf,
    /// Samples per pixel of the equal-samples row (default: the scene's
    /// render.spp): a whole number such as 64, 1e3 or 2^8
    #[arg(long, value_parser = crate::common::spp_u32)]
    pub spp: Option<u32>,
    /// Seed of the random streams (default: the scene's render.seed)
    #[arg(long)]
    pub seed: Option<u64>,
    /// Sample pattern of every render: sobol, stratified or independent
    /// (default: the scene's render.sequence, itself sobol by default)
    #[arg(long)]
    pub sequence: Option<String>,
    /// Worker threads (default: one per core)
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub threads: Option<u32>,
    /// Output name: writes NAME.png and NAME.json (default: the scene file's
    /// stem followed by -compare, in the current directory)
    #[arg(long, value_name = "NAME")]
    pub out: Option<PathBuf>,
    /// Samples per pixel of the mis reference (default: 16 × spp, at least 1024)
    #[arg(long, value_name = "R", value_parser = crate::common::spp_u32)]
    pub reference_spp: Option<u32>,
    #[arg(long = "strategy", alias = "strategies", value_name = "LIST", help = strategy_help())]
    pub strategies: Option<String>,
    /// No progress bars and no notes
    #[arg(long, short)]
    pub quiet: bool,
}

/// The help of `--strategy`: every accepted name.
fn strategy_help() -> String {
    format!(
        "Comma-separated strategies (default: {}). {}",
        lobe_render::compare::DEFAULT_STRATEGIES,
        crate::common::strategy_help()
    )
}

/// Parse `--strategy`: a comma-separated list of strategy names, each once.
pub fn parse_strategies_list(spec: &str) -> Result<Vec<Strategy>> {
    let mut v = Vec::new();
    for name in spec.split(',').map(str::trim) {
        if name.is_empty() {
            bail!(
                "--strategy {spec}: an empty name; expected a comma-separated list of: {}",
                Strategy::names()
            );
        }
        let m: Strategy = name.parse().map_err(|e| anyhow!("--strategy: {e}"))?;
        if !v.contains(&m) {
            v.push(m);
        }
    }
    Ok(v)
}

/// The rows of the figure: equal samples, then equal time if rendered.
#[must_use]
pub fn sections(cmp: &Comparison) -> Vec<(String, &[Shot])> {
    let spp = cmp.equal_samples.first().map_or(0, |s| s.spp);
    let mut v = vec![(
        format!("Equal samples: {spp} spp each"),
        cmp.equal_samples.as_slice(),
    )];
    if let Some(et) = &cmp.equal_time {
        v.push((
            format!(
                "Equal time: {} each ({})",
                fmt_time(et.budget_s),
                et.budget_from
            ),
            et.shots.as_slice(),
        ));
    }
    v
}

/// Warn on stderr of every render whose path samples were not all finite
/// (an equal-time shot that is its pilot was not rendered again).
pub fn warn_nonfinite(cmp: &Comparison) {
    let spp = cmp.equal_samples.first().map_or(0, |s| s.spp);
    let rendered = cmp
        .equal_samples
        .iter()
        .chain(
            cmp.equal_time
                .iter()
                .flat_map(|e| e.shots.iter().filter(|s| s.spp != spp)),
        )
        .chain(std::iter::once(&cmp.reference));
    for s in rendered {
        if s.image.stats.nonfinite > 0 {
            eprintln!(
                "lobe: warning: {} at {} spp: {} path samples were not finite numbers and counted as 0",
                s.strategy, s.spp, s.image.stats.nonfinite
            );
        }
    }
}

/// [`run_comparison`] with a progress bar (hidden when `quiet`) and the
/// system clock, then the warnings of [`warn_nonfinite`].
#[must_use]
pub fn run_with_progress(
    scene: &lobe_render::Scene,
    settings: &CompareSettings,
    quiet: bool,
) -> Comparison {
    let bar = Bar::new(quiet);
    let cmp = run_comparison(scene, settings, &bar, &SystemClock::new());
    bar.finish();
    warn_nonfinite(&cmp);
    cmp
}

// ---------------------------------------------------------------------------
// The figure
// ---------------------------------------------------------------------------

/// A text label drawn on the reference render at pixel `(x, y)` of the
/// render (centred there; `\n` separates lines).
#[derive(Debug, Clone)]
pub struct Label {
    pub x: f64,
    pub y: f64,
    pub text: String,
}

/// What [`write_grid`] draws.
#[derive(Debug, Clone)]
pub struct FigureSpec<'a> {
    pub title: String,
    pub cmp: &'a Comparison,
    pub labels: Vec<Label>,
}

/// The layout [`write_grid`] chose, for the JSON.
#[derive(Debug, Clone, Serialize)]
pub struct FigureInfo {
    pub width: u32,
    pub height: u32,
    /// `sections-as-rows` (rows: equal samples, equal time; columns: the
    /// reference, then the strategies) or `strategies-as-rows` (the
    /// reference on top, then a row per strategy; columns: equal samples,
    /// equal time).
    pub layout: &'static str,
    /// Where each error map is: `below` or `beside` its render.
    pub error_map: &'static str,
    /// Size each render is shown at (scaled by a whole factor from the
    /// render's size when it is very small or very large).
    pub image_width: u32,
    pub image_height: u32,
    pub error_scale: LogScale,
    pub error_epsilon: f64,
}

/// The family the embedded DejaVu Sans is registered under (by `figures`).
const FONT: &str = "sans-serif";

const TEXT: RGBColor = RGBColor(30, 30, 30);
const DIM: RGBColor = RGBColor(90, 90, 90);
const MARGIN: i32 = 18;
const GAP_X: i32 = 18;
const GAP_Y: i32 = 10;
const INNER: i32 = 4;
const HEAD_H: i32 = 28;
const LINE_H: i32 = 19;
const CAPTION_SIZE: f64 = 15.0;

fn font(size: f64) -> FontDesc<'static> {
    (FONT, size).into_font()
}

fn text_width(s: &str, size: f64) -> i32 {
    font(size).box_size(s).map_or(0, |(w, _)| w as i32)
}

/// The largest size ≤ `size` (not below 9) at which `s` fits in `width`.
fn fit(s: &str, size: f64, width: i32) -> f64 {
    let mut size = size;
    while size > 9.0 && text_width(s, size) > width {
        size -= 0.5;
    }
    size
}

fn de(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("{e}")
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

fn put(
    area: &Area,
    s: &str,
    (x, y): (i32, i32),
    size: f64,
    color: RGBColor,
    (h, v): (HPos, VPos),
) -> Result<()> {
    let style = font(size).color(&color).pos(Pos::new(h, v));
    area.draw_text(s, &style, (x, y)).map_err(de)
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

/// The caption lines of a shot at `width` pixels: one line when it fits
/// at a readable size, else two.
fn caption_lines(head: &str, tail: Option<&str>, width: i32) -> Vec<String> {
    let one = match tail {
        Some(t) => format!("{head} · {t}"),
        None => head.to_string(),
    };
    if tail.is_none() || fit(&one, CAPTION_SIZE, width) >= 12.0 {
        vec![one]
    } else {
        vec![head.to_string(), tail.unwrap_or_default().to_string()]
    }
}

fn shot_caption(s: &Shot) -> (String, Option<String>) {
    (
        format!("{} · {} spp · {}", s.strategy, s.spp, fmt_time(s.time_s)),
        Some(format!("RMSE {}", sig3(s.rmse))),
    )
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Arrange {
    SectionsAsRows,
    StrategiesAsRows,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Pair {
    Below,
    Beside,
}

/// Where everything goes.
#[derive(Debug, Clone)]
struct Geometry {
    arrange: Arrange,
    pair: Pair,
    /// Display size of one image.
    dw: i32,
    dh: i32,
    caption_lines: usize,
    cell_w: i32,
    width: i32,
    height: i32,
    /// Top-left of the reference cell.
    reference: (i32, i32),
    /// Top-left of each cell, `[section][strategy]`.
    cells: Vec<Vec<(i32, i32)>>,
    /// Heading text, left x, top y and width of each heading.
    headings: Vec<(String, i32, i32, i32)>,
}

impl Geometry {
    fn content(&self) -> (i32, i32) {
        match self.pair {
            Pair::Below => (self.dw, 2 * self.dh + INNER),
            Pair::Beside => (2 * self.dw + INNER, self.dh),
        }
    }

    fn caption_h(&self) -> i32 {
        self.caption_lines as i32 * LINE_H + 4
    }

    fn cell_h(&self) -> i32 {
        self.caption_h() + self.content().1
    }

    /// Where the second image of a cell (the error map) starts, relative to
    /// the first.
    fn second(&self) -> (i32, i32) {
        match self.pair {
            Pair::Below => (0, self.dh + INNER),
            Pair::Beside => (self.dw + INNER, 0),
        }
    }
}

/// The display size of a `w × h` render: scaled up by a whole factor to
/// at least 240 pixels wide, or down to at most 720.
fn display_scale(w: usize) -> (usize, usize) {
    if w < 240 {
        (240usize.div_ceil(w.max(1)), 1)
    } else if w > 720 {
        (1, w.div_ceil(720))
    } else {
        (1, 1)
    }
}

fn layout(spec: &FigureSpec, title_h: i32, arrange: Arrange, pair: Pair) -> Geometry {
    let cmp = spec.cmp;
    let img = &cmp.reference.image;
    let (up, down) = display_scale(img.width);
    let dw = (img.width * up / down).max(1) as i32;
    let dh = (img.height * up / down).max(1) as i32;
    let sections = sections(cmp);
    let n = sections.iter().map(|s| s.1.len()).max().unwrap_or(0);
    let mut g = Geometry {
        arrange,
        pair,
        dw,
        dh,
        caption_lines: 1,
        cell_w: 0,
        width: 0,
        height: 0,
        reference: (0, 0),
        cells: Vec::new(),
        headings: Vec::new(),
    };
    let (cw, _) = g.content();
    g.cell_w = cw;
    g.caption_lines = sections
        .iter()
        .flat_map(|s| s.1.iter())
        .map(|s| {
            let (h, t) = shot_caption(s);
            caption_lines(&h, t.as_deref(), cw).len()
        })
        .max()
        .unwrap_or(1);
    let cell_h = g.cell_h();
    let x = |col: usize| MARGIN + col as i32 * (cw + GAP_X);
    match arrange {
        Arrange::SectionsAsRows => {
            let mut y = title_h;
            for (r, (heading, shots)) in sections.iter().enumerate() {
                if r == 0 {
                    g.headings.push(("Reference".into(), x(0), y, cw));
                    g.reference = (x(0), y + HEAD_H);
                }
                g.headings
                    .push((heading.clone(), x(1), y, x(n) + cw - x(1)));
                g.cells
                    .push((0..shots.len()).map(|i| (x(i + 1), y + HEAD_H)).collect());
                y += HEAD_H + cell_h + GAP_Y;
            }
            g.width = x(n) + cw + MARGIN;
            g.height = y - GAP_Y + MARGIN;
        }
        Arrange::StrategiesAsRows => {
            let mut y = title_h;
            g.headings.push(("Reference".into(), x(0), y, cw));
            g.reference = (x(0), y + HEAD_H);
            y += HEAD_H + cell_h + GAP_Y;
            for (c, (heading, _)) in sections.iter().enumerate() {
                g.headings.push((heading.clone(), x(c), y, cw));
            }
            y += HEAD_H;
            g.cells = sections.iter().map(|_| Vec::new()).collect();
            for i in 0..n {
                for (c, (_, shots)) in sections.iter().enumerate() {
                    if i < shots.len() {
                        g.cells[c].push((x(c), y));
                    }
                }
                y += cell_h + GAP_Y;
            }
            g.width = x(sections.len().max(1) - 1) + cw + MARGIN;
            g.height = y - GAP_Y + MARGIN;
        }
    }
    g
}

/// The layout whose shape is nearest 3:2 (on a log scale).
fn best_layout(spec: &FigureSpec, title_h: i32) -> Geometry {
    let mut best: Option<(f64, Geometry)> = None;
    for arrange in [Arrange::SectionsAsRows, Arrange::StrategiesAsRows] {
        for pair in [Pair::Below, Pair::Beside] {
            let g = layout(spec, title_h, arrange, pair);
            let score = (f64::from(g.width) / f64::from(g.height) / 1.5).ln().abs();
            if best.as_ref().is_none_or(|(s, _)| score < *s - 1e-9) {
                best = Some((score, g));
            }
        }
    }
    best.expect("four layouts").1
}

fn blit(area: &Area, rgb: Vec<u8>, (x, y): (i32, i32), (w, h): (i32, i32)) -> Result<()> {
    let el = BitMapElement::with_owned_buffer((x, y), (w as u32, h as u32), rgb)
        .ok_or_else(|| anyhow!("an image buffer does not match its size"))?;
    area.draw(&el).map_err(de)
}

fn error_rgb(map: &[f64], scale: &LogScale) -> Vec<u8> {
    map.iter()
        .flat_map(|e| {
            let c = viridis(scale.t(*e));
            [c.0, c.1, c.2]
        })
        .collect()
}

/// `10^k` with superscript digits.
fn decade(k: i32) -> String {
    format!("10{}", crate::figures::superscript(i64::from(k)))
}

/// The colour bar, in the reference cell's second slot.
fn draw_colorbar(
    area: &Area,
    (x, y): (i32, i32),
    (w, h): (i32, i32),
    scale: &LogScale,
) -> Result<()> {
    area.draw(&Rectangle::new(
        [(x, y), (x + w - 1, y + h - 1)],
        RGBColor(247, 247, 247).filled(),
    ))
    .map_err(de)?;
    let title = "error map: |Y − Y_ref| / (Y_ref + ε) of luminance";
    let note = "ε = 1% of the reference's mean; one scale for every map";
    let ts = fit(title, 14.0, w - 16);
    let ns = fit(note, 12.0, w - 16);
    let bar_h = (h / 8).clamp(10, 22);
    let tick_s = 12.0;
    let show_note = h >= 110;
    let block =
        ts as i32 + 8 + bar_h + 6 + tick_s as i32 + if show_note { 10 + ns as i32 } else { 0 };
    let mut cy = y + ((h - block) / 2).max(2);
    put(
        area,
        title,
        (x + w / 2, cy),
        ts,
        TEXT,
        (HPos::Center, VPos::Top),
    )?;
    cy += ts as i32 + 8;
    let bx0 = x + w / 12;
    let bw = (w - 2 * (w / 12)).max(1);
    for k in 0..bw {
        let t = (f64::from(k) + 0.5) / f64::from(bw);
        area.draw(&Rectangle::new(
            [(bx0 + k, cy), (bx0 + k + 1, cy + bar_h)],
            viridis(t).filled(),
        ))
        .map_err(de)?;
    }
    area.draw(&Rectangle::new(
        [(bx0, cy), (bx0 + bw, cy + bar_h)],
        RGBColor(120, 120, 120).stroke_width(1),
    ))
    .map_err(de)?;
    let (klo, khi) = (
        scale.lo.log10().round() as i32,
        scale.hi.log10().round() as i32,
    );
    for k in klo..=khi {
        let t = f64::from(k - klo) / f64::from((khi - klo).max(1));
        let tx = bx0 + (t * f64::from(bw)).round() as i32;
        area.draw(&PathElement::new(
            vec![(tx, cy + bar_h), (tx, cy + bar_h + 4)],
            BLACK.stroke_width(1),
        ))
        .map_err(de)?;
        let label = if k == klo {
            format!("≤{}", decade(k))
        } else {
            decade(k)
        };
        put(
            area,
            &label,
            (tx, cy + bar_h + 6),
            tick_s,
            TEXT,
            (HPos::Center, VPos::Top),
        )?;
    }
    if show_note {
        cy += bar_h + 6 + tick_s as i32 + 10;
        put(
            area,
            note,
            (x + w / 2, cy),
            ns,
            DIM,
            (HPos::Center, VPos::Top),
        )?;
    }
    Ok(())
}

/// Dark text on a translucent white box, centred at `(x, y)`, line by line.
fn draw_label(area: &Area, text: &str, (x, y): (i32, i32), size: f64) -> Result<()> {
    let lines: Vec<&str> = text.lines().collect();
    let lh = (size * 1.2).round() as i32;
    let top = y - lh * lines.len() as i32 / 2;
    let w = lines.iter().map(|l| text_width(l, size)).max().unwrap_or(0);
    area.draw(&Rectangle::new(
        [
            (x - w / 2 - 4, top - 1),
            (x + w / 2 + 4, top + lh * lines.len() as i32 + 1),
        ],
        WHITE.mix(0.6).filled(),
    ))
    .map_err(de)?;
    for (k, line) in lines.iter().enumerate() {
        put(
            area,
            line,
            (x, top + k as i32 * lh + lh / 2),
            size,
            TEXT,
            (HPos::Center, VPos::Center),
        )?;
    }
    Ok(())
}

/// Draw the comparison grid to `path` (a PNG): the reference with the
/// colour bar, and every render with its error map and caption.
pub fn write_grid(path: &Path, spec: &FigureSpec) -> Result<FigureInfo> {
    crate::figures::register_fonts()?;
    let cmp = spec.cmp;
    let reference = &cmp.reference.image;
    let eps = error_epsilon(reference);
    let sections = sections(cmp);
    let maps: Vec<Vec<Vec<f64>>> = sections
        .iter()
        .map(|(_, shots)| {
            shots
                .iter()
                .map(|s| error_map(&s.image, reference, eps))
                .collect()
        })
        .collect();
    let scale = LogScale::of(&maps.iter().flatten().cloned().collect::<Vec<_>>());

    let title_size = 21.0;
    let title_h = MARGIN + title_size as i32 + 12;
    let g = best_layout(spec, title_h);
    let (up, down) = display_scale(reference.width);
    let shown = path.display();
    let size = (g.width as u32, g.height as u32);
    let mut buffer = vec![0u8; g.width as usize * g.height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(de)?;
        let ts = fit(&spec.title, title_size, g.width - 2 * MARGIN);
        put(
            &root,
            &spec.title,
            (MARGIN, MARGIN),
            ts,
            TEXT,
            (HPos::Left, VPos::Top),
        )?;
        for (text, x, y, w) in &g.headings {
            let size = fit(text, 17.0, *w);
            put(
                &root,
                text,
                (*x, y + HEAD_H - 6),
                size,
                TEXT,
                (HPos::Left, VPos::Bottom),
            )?;
            root.draw(&PathElement::new(
                vec![(*x, y + HEAD_H - 2), (x + w, y + HEAD_H - 2)],
                RGBColor(180, 180, 180).stroke_width(1),
            ))
            .map_err(de)?;
        }
        let (w, h) = (reference.width, reference.height);
        let show = |rgb: Vec<u8>| resample(&rgb, w, h, up, down).bytes;
        let second = g.second();
        let caption = |x: i32, y: i32, head: &str, tail: Option<&str>| -> Result<()> {
            let lines = caption_lines(head, tail, g.cell_w);
            let base = y + g.caption_h() - 5 - (lines.len() as i32 - 1) * LINE_H;
            for (k, line) in lines.iter().enumerate() {
                let size = fit(line, CAPTION_SIZE, g.cell_w);
                put(
                    &root,
                    line,
                    (x, base + k as i32 * LINE_H),
                    size,
                    TEXT,
                    (HPos::Left, VPos::Bottom),
                )?;
            }
            Ok(())
        };

        // The reference, its labels, and the colour bar beside or below it.
        let (rx, ry) = g.reference;
        let r = &cmp.reference;
        caption(
            rx,
            ry,
            &format!("{} · {} spp · {}", r.strategy, r.spp, fmt_time(r.time_s)),
            None,
        )?;
        let top = ry + g.caption_h();
        blit(
            &root,
            show(reference.to_srgb8(&lobe_render::ToneMap::default())),
            (rx, top),
            (g.dw, g.dh),
        )?;
        let k = g.dw as f64 / w as f64;
        let label_size = (f64::from(g.dh) / 15.0).clamp(9.0, 13.0);
        for l in &spec.labels {
            draw_label(
                &root,
                &l.text,
                (
                    (l.x * k).round() as i32 + rx,
                    (l.y * k).round() as i32 + top,
                ),
                label_size,
            )?;
        }
        draw_colorbar(&root, (rx + second.0, top + second.1), (g.dw, g.dh), &scale)?;

        for (c, (_, shots)) in sections.iter().enumerate() {
            for (i, s) in shots.iter().enumerate() {
                let (x, y) = g.cells[c][i];
                let (head, tail) = shot_caption(s);
                caption(x, y, &head, tail.as_deref())?;
                let top = y + g.caption_h();
                blit(
                    &root,
                    show(s.image.to_srgb8(&lobe_render::ToneMap::default())),
                    (x, top),
                    (g.dw, g.dh),
                )?;
                blit(
                    &root,
                    show(error_rgb(&maps[c][i], &scale)),
                    (x + second.0, top + second.1),
                    (g.dw, g.dh),
                )?;
            }
        }
        root.present()
            .map_err(|e| anyhow!("drawing {shown}: {e}"))?;
    }
    crate::figures::write_png(path, &buffer, size)?;
    Ok(FigureInfo {
        width: g.width as u32,
        height: g.height as u32,
        layout: match g.arrange {
            Arrange::SectionsAsRows => "sections-as-rows",
            Arrange::StrategiesAsRows => "strategies-as-rows",
        },
        error_map: match g.pair {
            Pair::Below => "below",
            Pair::Beside => "beside",
        },
        image_width: g.dw as u32,
        image_height: g.dh as u32,
        error_scale: scale,
        error_epsilon: eps,
    })
}

// ---------------------------------------------------------------------------
// The numbers
// ---------------------------------------------------------------------------

#[derive(Debug, Clone, Serialize)]
pub struct ShotJson {
    pub strategy: String,
    pub spp: u32,
    pub time_s: f64,
    pub rmse: f64,
    /// The share of the squared error (RMSE²) in the worst pixel
    /// ([`worst_pixel_share`]).
    pub worst_pixel_share: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct ReferenceJson {
    pub strategy: String,
    pub spp: u32,
    pub time_s: f64,
    pub seed: u64,
}

/// NAME.json.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub scene: String,
    pub width: usize,
    pub height: usize,
    pub seed: u64,
    pub sequence: &'static str,
    pub max_depth: u32,
    pub reference: ReferenceJson,
    pub equal_samples: Vec<ShotJson>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equal_time: Option<Vec<ShotJson>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_budget_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_budget_from: Option<String>,
    pub rmse: &'static str,
    pub error_map: &'static str,
    pub figure: FigureInfo,
}

fn shots_json(shots: &[Shot], reference: &Shot) -> Vec<ShotJson> {
    shots
        .iter()
        .map(|s| ShotJson {
            strategy: s.strategy.name().to_string(),
            spp: s.spp,
            time_s: s.time_s,
            rmse: s.rmse,
            worst_pixel_share: worst_pixel_share(s, reference),
        })
        .collect()
}

/// The share of a render's squared error against the reference (the sum
/// over pixels of |render − reference|², RMSE² up to a constant) that is in
/// its worst pixel: near 1, the RMSE is one firefly's (0 for no error).
#[must_use]
pub fn worst_pixel_share(s: &Shot, reference: &Shot) -> f64 {
    let (mut sum, mut worst) = (0.0f64, 0.0f64);
    for (p, r) in s.image.pixels.iter().zip(&reference.image.pixels) {
        let e = (*p - *r).length_squared();
        sum += e;
        worst = worst.max(e);
    }
    if sum > 0.0 { worst / sum } else { 0.0 }
}

/// Above this [`worst_pixel_share`], a render's RMSE is called a firefly's
/// in the printed table.
pub const FIREFLY_SHARE: f64 = 0.25;

/// The numbers of a comparison, for NAME.json.
#[must_use]
pub fn summary(scene: &str, s: &CompareSettings, cmp: &Comparison, figure: FigureInfo) -> Summary {
    let r = &cmp.reference;
    Summary {
        scene: scene.to_string(),
        width: r.image.width,
        height: r.image.height,
        seed: s.seed,
        sequence: s.sequence.name(),
        max_depth: s.max_depth,
        reference: ReferenceJson {
            strategy: r.strategy.name().to_string(),
            spp: r.spp,
            time_s: r.time_s,
            seed: cmp.reference_seed,
        },
        equal_samples: shots_json(&cmp.equal_samples, &cmp.reference),
        equal_time: cmp
            .equal_time
            .as_ref()
            .map(|e| shots_json(&e.shots, &cmp.reference)),
        time_budget_s: cmp.equal_time.as_ref().map(|e| e.budget_s),
        time_budget_from: cmp.equal_time.as_ref().map(|e| e.budget_from.clone()),
        rmse: "root mean square over all pixels and the three channels of (render - reference), linear RGB",
        error_map: "per pixel |Y - Y_ref| / (Y_ref + eps) of luminance, eps = 1% of the reference's mean luminance",
        figure,
    }
}

/// Write `summary` as pretty JSON to `path`.
pub fn write_json(path: &Path, summary: &Summary) -> Result<()> {
    let text = serde_json::to_string_pretty(summary)?;
    std::fs::write(path, text + "\n").map_err(|e| anyhow!("{}: cannot write: {e}", path.display()))
}

/// The table of a comparison, for stdout.
pub fn print_table(cmp: &Comparison) {
    let r = &cmp.reference;
    println!(
        "reference: {} at {} spp, {}",
        r.strategy,
        r.spp,
        fmt_time(r.time_s)
    );
    let mut fireflies: Vec<String> = Vec::new();
    for (heading, shots) in sections(cmp) {
        println!("{heading}");
        println!(
            "  {:<15} {:>8} {:>10} {:>12} {:>10}",
            "strategy", "spp", "time", "RMSE", "worst px"
        );
        for s in shots {
            let share = worst_pixel_share(s, r);
            if share > FIREFLY_SHARE && !fireflies.contains(&s.strategy.name()) {
                fireflies.push(s.strategy.name());
            }
            println!(
                "  {:<15} {:>8} {:>10} {:>12} {:>9.0}%",
                s.strategy.name(),
                s.spp,
                fmt_time(s.time_s),
                sig3(s.rmse),
                100.0 * share
            );
        }
    }
    println!(
        "time: of the render alone, after an untimed warm-up (the fastest of {} runs below {}); worst px: the share of the squared error in the worst pixel",
        lobe_render::compare::SHORT_RENDER_RUNS,
        fmt_time(lobe_render::compare::SHORT_RENDER_S)
    );
    if !fireflies.is_empty() {
        println!(
            "{}: one pixel holds more than {:.0}% of the squared error: a firefly, a rare sample of a large weight (BSDF sampling that found the small, bright sun; light sampling that found a sharp highlight). Such an RMSE changes several-fold with --seed; do not rank these strategies by one seed",
            fireflies.join(", "),
            100.0 * FIREFLY_SHARE
        );
    }
}

/// Run `lobe compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    if args.spp == Some(0) {
        bail!("--spp 0: at least 1 sample per pixel");
    }
    if args.reference_spp == Some(0) {
        bail!("--reference-spp 0: at least 1 sample per pixel");
    }
    let strategies = args
        .strategies
        .as_deref()
        .map(parse_strategies_list)
        .transpose()?;
    let base = crate::common::output_base(
        args.out.as_deref(),
        &args.scene,
        &["png", "json"],
        "-compare",
    )?;
    crate::common::prepare_output_files(
        "--out",
        &["png", "json"].map(|e| crate::common::with_ext(&base, e)),
    )?;
    let scene = load_scene(&args.scene)?;
    let strategies = strategies.unwrap_or_else(|| default_strategies(&scene));
    let spp = args
        .spp
        .unwrap_or(u32::try_from(scene.settings.spp).unwrap_or(u32::MAX))
        .max(1);
    let settings = CompareSettings {
        strategies,
        spp,
        reference_spp: args
            .reference_spp
            .unwrap_or_else(|| default_reference_spp(spp)),
        seed: args.seed.unwrap_or(scene.settings.seed),
        sequence: match &args.sequence {
            Some(s) => crate::estimate::parse_sequence(s)?,
            None => scene.settings.sequence,
        },
        max_depth: scene.settings.max_depth,
        threads: args.threads.map(|t| t as usize),
        equal_time: true,
    };
    for w in &scene.warnings {
        eprintln!("lobe: warning: {w}");
    }
    if !args.quiet {
        for &m in &settings.strategies {
            for f in fallbacks(&scene, m) {
                eprintln!(
                    "lobe: note: object {} ({}): {} does not apply to its material, using {}",
                    f.object, f.model, f.requested, f.used
                );
            }
        }
        if settings.reference_spp <= spp {
            eprintln!(
                "lobe: note: the reference ({} spp) has no more samples than the compared renders ({spp} spp): its own noise will dominate the errors",
                settings.reference_spp
            );
        }
    }
    let cmp = run_with_progress(&scene, &settings, args.quiet);
    let png = crate::common::with_ext(&base, "png");
    let json = crate::common::with_ext(&base, "json");
    let (w, h) = (scene.camera.width, scene.camera.height);
    let name = args.scene.display().to_string();
    let figure = write_grid(
        &png,
        &FigureSpec {
            title: format!(
                "lobe compare: {name} · {w}×{h} · seed {} · max_depth {}",
                settings.seed, settings.max_depth
            ),
            cmp: &cmp,
            labels: Vec::new(),
        },
    )?;
    write_json(&json, &summary(&name, &settings, &cmp, figure))?;
    print_table(&cmp);
    println!("wrote {} and {}", png.display(), json.display());
    Ok(())
}
