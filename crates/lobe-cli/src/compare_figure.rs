//! The figure of `lobe compare` (and of `lobe demo`'s showcase): one grid
//! of the reference and of every render at equal samples and equal time,
//! each with its per-pixel error map on one logarithmic colour scale, its
//! caption (strategy, spp, time, RMSE), and the colour bar of the maps.

use crate::draw::{
    DIM_TEXT, Orientation, TEXT, draw_colorbar, drawing_error, fit_size, fmt_time, paint_png,
    power_label, put_text, sig3, text_width, viridis,
};
use anyhow::{Result, anyhow};
use lobe_render::compare::{Comparison, LogScale, Shot, error_epsilon, error_map, resample};
use plotters::coord::Shift;
use plotters::element::BitMapElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use serde::Serialize;
use std::path::Path;

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

const MARGIN: i32 = 18;
const GAP_X: i32 = 18;
const GAP_Y: i32 = 10;
const INNER: i32 = 4;
const HEAD_H: i32 = 28;
const LINE_H: i32 = 19;
const CAPTION_SIZE: f64 = 15.0;

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// The caption lines of a shot at `width` pixels: one line when it fits
/// at a readable size, else two.
fn caption_lines(head: &str, tail: Option<&str>, width: i32) -> Vec<String> {
    let one = match tail {
        Some(t) => format!("{head} · {t}"),
        None => head.to_string(),
    };
    if tail.is_none() || fit_size(&one, CAPTION_SIZE, width) >= 12.0 {
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
    area.draw(&el).map_err(drawing_error)
}

fn error_rgb(map: &[f64], scale: &LogScale) -> Vec<u8> {
    map.iter()
        .flat_map(|e| {
            let c = viridis(scale.t(*e));
            [c.0, c.1, c.2]
        })
        .collect()
}

/// The key of the error maps, in the reference cell's second slot: a
/// title, the colour bar with a tick per decade, and a note.
fn draw_error_key(
    area: &Area,
    (x, y): (i32, i32),
    (w, h): (i32, i32),
    scale: &LogScale,
) -> Result<()> {
    area.draw(&Rectangle::new(
        [(x, y), (x + w - 1, y + h - 1)],
        RGBColor(247, 247, 247).filled(),
    ))
    .map_err(drawing_error)?;
    let title = "error map: |Y − Y_ref| / (Y_ref + ε) of luminance";
    let note = "ε = 1% of the reference's mean; one scale for every map";
    let ts = fit_size(title, 14.0, w - 16);
    let ns = fit_size(note, 12.0, w - 16);
    let bar_h = (h / 8).clamp(10, 22);
    let tick_s = 12;
    let show_note = h >= 110;
    let block = ts as i32 + 8 + bar_h + 6 + tick_s + if show_note { 10 + ns as i32 } else { 0 };
    let mut cy = y + ((h - block) / 2).max(2);
    put_text(
        area,
        title,
        (x + w / 2, cy),
        ts,
        TEXT,
        (HPos::Center, VPos::Top),
    )
    .map_err(drawing_error)?;
    cy += ts as i32 + 8;
    let (klo, khi) = (
        scale.lo.log10().round() as i32,
        scale.hi.log10().round() as i32,
    );
    let ticks: Vec<(f64, String)> = (klo..=khi)
        .map(|k| {
            let t = f64::from(k - klo) / f64::from((khi - klo).max(1));
            let label = power_label(10, f64::from(k));
            (
                t,
                if k == klo {
                    format!("≤{label}")
                } else {
                    label
                },
            )
        })
        .collect();
    draw_colorbar(
        area,
        (x + w / 12, cy),
        (w - 2 * (w / 12), bar_h),
        Orientation::Horizontal,
        &ticks,
    )
    .map_err(drawing_error)?;
    if show_note {
        cy += bar_h + 6 + tick_s + 10;
        put_text(
            area,
            note,
            (x + w / 2, cy),
            ns,
            DIM_TEXT,
            (HPos::Center, VPos::Top),
        )
        .map_err(drawing_error)?;
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
    .map_err(drawing_error)?;
    for (k, line) in lines.iter().enumerate() {
        put_text(
            area,
            line,
            (x, top + k as i32 * lh + lh / 2),
            size,
            TEXT,
            (HPos::Center, VPos::Center),
        )
        .map_err(drawing_error)?;
    }
    Ok(())
}

/// Draw the comparison grid to `path` (a PNG): the reference with the
/// colour bar, and every render with its error map and caption.
pub fn write_grid(path: &Path, spec: &FigureSpec) -> Result<FigureInfo> {
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
    let size = (g.width as u32, g.height as u32);
    paint_png(path, Vec::new(), size, |root| {
        root.fill(&WHITE).map_err(drawing_error)?;
        let ts = fit_size(&spec.title, title_size, g.width - 2 * MARGIN);
        put_text(
            root,
            &spec.title,
            (MARGIN, MARGIN),
            ts,
            TEXT,
            (HPos::Left, VPos::Top),
        )
        .map_err(drawing_error)?;
        for (text, x, y, w) in &g.headings {
            let size = fit_size(text, 17.0, *w);
            put_text(
                root,
                text,
                (*x, y + HEAD_H - 6),
                size,
                TEXT,
                (HPos::Left, VPos::Bottom),
            )
            .map_err(drawing_error)?;
            root.draw(&PathElement::new(
                vec![(*x, y + HEAD_H - 2), (x + w, y + HEAD_H - 2)],
                RGBColor(180, 180, 180).stroke_width(1),
            ))
            .map_err(drawing_error)?;
        }
        let (w, h) = (reference.width, reference.height);
        let show = |rgb: Vec<u8>| resample(&rgb, w, h, up, down).bytes;
        let second = g.second();
        let caption = |x: i32, y: i32, head: &str, tail: Option<&str>| -> Result<()> {
            let lines = caption_lines(head, tail, g.cell_w);
            let base = y + g.caption_h() - 5 - (lines.len() as i32 - 1) * LINE_H;
            for (k, line) in lines.iter().enumerate() {
                let size = fit_size(line, CAPTION_SIZE, g.cell_w);
                put_text(
                    root,
                    line,
                    (x, base + k as i32 * LINE_H),
                    size,
                    TEXT,
                    (HPos::Left, VPos::Bottom),
                )
                .map_err(drawing_error)?;
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
            root,
            show(reference.to_srgb8(&lobe_render::ToneMap::default())),
            (rx, top),
            (g.dw, g.dh),
        )?;
        let k = g.dw as f64 / w as f64;
        let label_size = (f64::from(g.dh) / 15.0).clamp(9.0, 13.0);
        for l in &spec.labels {
            draw_label(
                root,
                &l.text,
                (
                    (l.x * k).round() as i32 + rx,
                    (l.y * k).round() as i32 + top,
                ),
                label_size,
            )?;
        }
        draw_error_key(root, (rx + second.0, top + second.1), (g.dw, g.dh), &scale)?;

        for (c, (_, shots)) in sections.iter().enumerate() {
            for (i, s) in shots.iter().enumerate() {
                let (x, y) = g.cells[c][i];
                let (head, tail) = shot_caption(s);
                caption(x, y, &head, tail.as_deref())?;
                let top = y + g.caption_h();
                blit(
                    root,
                    show(s.image.to_srgb8(&lobe_render::ToneMap::default())),
                    (x, top),
                    (g.dw, g.dh),
                )?;
                blit(
                    root,
                    show(error_rgb(&maps[c][i], &scale)),
                    (x + second.0, top + second.1),
                    (g.dw, g.dh),
                )?;
            }
        }
        Ok(())
    })?;
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
