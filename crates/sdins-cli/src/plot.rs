//! Plots (plotters): SVG strings for the self-contained HTML reports and SVG + PNG files
//! beside them. Text uses the DejaVu Sans font embedded by the `dejavu` crate, so
//! rendering needs no system fonts; PNGs are drawn by [`raster::Raster`], which places
//! every glyph exactly (plotters' own font path misplaces flat-topped letters at odd
//! sizes: "ForWard") and draws thick lines without miter spikes.
//!
//! Figure rules (docs/user-guide.md, "Figures"): one tick notation per axis chosen from
//! its range ([`ticks::Ticks`]: plain decimals, or plain mantissas with a shared power of
//! ten stated in the axis description; every decade of a log axis labelled, top one
//! included), a label count fitted to the panel size so labels do not overlap, one
//! legend per figure in a strip above the panels (never over the data), mean ± σ and ±3σ
//! as shaded bands ([`Band`]) whose legend swatch has their color, everything cut to its
//! panel ([`clip`]: data beyond the axis range leave the frame, in PNG as in SVG), and
//! series longer than the plot width decimated to the minimum and maximum of each pixel
//! column ([`MinMaxColumns`]) so that short events (a 2 s turn in an hour) stay visible.

mod clip;
mod decimate;
mod raster;
mod ticks;

pub use decimate::MinMaxColumns;

use crate::error::CliError;
use decimate::{decimate, decimate_band};
use plotters::coord::combinators::LogCoord;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;
use raster::Raster;
use std::ops::Range;
use std::path::Path;
use ticks::{Axis, Ticks};

/// Y-axis scale of time-series plots (`--plot-scale`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum PlotScale {
    /// logarithmic: the absolute value |y| is drawn
    #[default]
    Log,
    /// linear: signed values
    Linear,
}

impl PlotScale {
    /// The option value (`log`, `linear`).
    pub fn name(self) -> &'static str {
        match self {
            PlotScale::Log => "log",
            PlotScale::Linear => "linear",
        }
    }
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Style {
    /// solid line
    #[default]
    Line,
    /// dashed line (reference values, e.g. the true bias or a fitted slope)
    Dashed,
    /// markers, with vertical error bars when `Series::y_err` is given
    Points,
}

/// One line of a panel.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// legend name; it also picks the color (same name, same color in every panel)
    pub name: String,
    /// (x, y) points
    pub points: Vec<(f64, f64)>,
    /// drawing style
    pub style: Style,
    /// per point (low, high) of a confidence bar (`Style::Points`); empty: none
    pub y_err: Vec<(f64, f64)>,
    /// take the color of the series of this name (empty: the series' own name)
    pub color_of: String,
}

impl Series {
    /// A solid line.
    pub fn line(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            name: name.into(),
            points,
            ..Self::default()
        }
    }

    /// A dashed line.
    pub fn dashed(name: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            style: Style::Dashed,
            ..Self::line(name, points)
        }
    }

    /// The same series drawn in the color of the series named `other`.
    pub fn colored_as(mut self, other: impl Into<String>) -> Self {
        self.color_of = other.into();
        self
    }

    /// Markers with confidence bars `(low, high)` per point.
    pub fn points(
        name: impl Into<String>,
        points: Vec<(f64, f64)>,
        y_err: Vec<(f64, f64)>,
    ) -> Self {
        Self {
            style: Style::Points,
            y_err,
            ..Self::line(name, points)
        }
    }
}

impl Series {
    fn color_key(&self) -> &str {
        if self.color_of.is_empty() {
            &self.name
        } else {
            &self.color_of
        }
    }
}

/// A shaded band between a low and a high curve (mean ± σ, estimate ± 3σ).
#[derive(Clone, Debug, Default)]
pub struct Band {
    /// legend label
    pub name: String,
    /// the series name whose color the band takes (lighter)
    pub color_of: String,
    /// (x, low, high)
    pub points: Vec<(f64, f64, f64)>,
    /// also draw the low and high curves as thin lines in the full color, so that
    /// overlapping bands stay apart (the legend swatch is outlined too)
    pub outline: bool,
}

/// One panel: axes, labels, bands and lines.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// panel title
    pub title: String,
    /// x-axis label with unit
    pub x_label: String,
    /// y-axis label with unit
    pub y_label: String,
    /// logarithmic x axis (values ≤ 0 are dropped)
    pub log_x: bool,
    /// logarithmic y axis (values ≤ 0 are dropped)
    pub log_y: bool,
    /// fit the y range to the points with `x ≥ y_fit_from_x` only (the rest is clipped
    /// to the frame), e.g. to skip a filter's large initial covariance
    pub y_fit_from_x: Option<f64>,
    /// equal metres per pixel on both axes (ground tracks)
    pub equal_axes: bool,
    /// smallest y span of a linear axis (e.g. 1 m for a height that stays constant up to
    /// rounding), so that noise at the 1e-13 level is not blown up to the full panel
    pub min_y_span: f64,
    /// shaded bands, drawn under the lines
    pub bands: Vec<Band>,
    /// the lines
    pub series: Vec<Series>,
    /// a remark written in grey across the middle of the plotting area (e.g. why a channel
    /// is zero); empty: none
    pub note: String,
}

/// A figure of panels (`cols` per row) under one legend strip.
#[derive(Clone, Debug)]
pub struct Figure {
    /// panels, row by row
    pub panels: Vec<Panel>,
    /// panels per row
    pub cols: usize,
    /// width, height in pixels
    pub size: (u32, u32),
}

const COLORS: [RGBColor; 8] = [
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0x17, 0xbe, 0xcf),
    RGBColor(0x7f, 0x7f, 0x7f),
];

/// Color key of legend-only entries that explain a style (e.g. "shaded: ±3σ") rather
/// than name a quantity: drawn in grey, they take no palette color.
pub const STYLE_KEY: &str = "\u{0}style";

/// A legend-only entry in grey explaining what dashed lines mean.
pub fn dashed_note(label: &str) -> Series {
    Series::dashed(label, Vec::new()).colored_as(STYLE_KEY)
}

const GREY: RGBColor = RGBColor(0x70, 0x70, 0x70);

/// Opacity of band fills and their legend swatches.
const BAND_ALPHA: f64 = 0.22;
/// Opacity of the fill of outlined bands ([`Band::outline`]): lighter, so that where
/// bands overlap the outlines still tell them apart.
const OUTLINED_BAND_ALPHA: f64 = 0.12;
/// Opacity of the fill of a band (and of its legend swatch).
fn band_alpha(outline: bool) -> f64 {
    if outline {
        OUTLINED_BAND_ALPHA
    } else {
        BAND_ALPHA
    }
}
/// Opacity of the edge lines of outlined bands ([`Band::outline`]).
const OUTLINE_ALPHA: f64 = 0.8;
/// Opacity of bars.
const BAR_ALPHA: f64 = 0.8;
/// Radius of point markers [px].
const MARKER_PX: i32 = 3;

/// Tick label font size [px].
const LABEL_PX: u32 = 14;
/// Axis description font size [px].
const DESC_PX: u32 = 15;
/// Panel title font size [px].
const TITLE_PX: u32 = 17;
/// Height of one legend row [px].
const LEGEND_ROW_PX: u32 = 24;

/// Register the embedded DejaVu Sans as the plotters `sans-serif` font.
pub fn register_font() -> Result<(), CliError> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
        .map_err(|_| CliError::Other("cannot load the embedded DejaVu Sans font".into()))
}

/// Legend entries of a figure in order of first appearance: (label, color, kind).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Key {
    Line,
    Dashed,
    Points,
    Band,
    OutlinedBand,
}

struct Legend {
    names: Vec<String>,
    entries: Vec<(String, RGBColor, Key)>,
}

impl Legend {
    fn of(panels: &[Panel]) -> Self {
        let mut l = Legend {
            names: Vec::new(),
            entries: Vec::new(),
        };
        for p in panels {
            for s in &p.series {
                let c = l.color(s.color_key());
                let k = match s.style {
                    Style::Line => Key::Line,
                    Style::Dashed => Key::Dashed,
                    Style::Points => Key::Points,
                };
                l.add(&s.name, c, k);
            }
            for b in &p.bands {
                let c = l.color(&b.color_of);
                let k = if b.outline {
                    Key::OutlinedBand
                } else {
                    Key::Band
                };
                l.add(&b.name, c, k);
            }
        }
        l
    }

    fn color(&mut self, name: &str) -> RGBColor {
        if name == STYLE_KEY {
            return GREY;
        }
        let i = match self.names.iter().position(|n| n == name) {
            Some(i) => i,
            None => {
                self.names.push(name.to_string());
                self.names.len() - 1
            }
        };
        COLORS[i % COLORS.len()]
    }

    fn color_of(&self, name: &str) -> RGBColor {
        if name == STYLE_KEY {
            return GREY;
        }
        let i = self.names.iter().position(|n| n == name).unwrap_or(0);
        COLORS[i % COLORS.len()]
    }

    fn add(&mut self, label: &str, c: RGBColor, k: Key) {
        if !label.is_empty() && !self.entries.iter().any(|e| e.0 == label) {
            self.entries.push((label.to_string(), c, k));
        }
    }

    /// Entry width estimate [px]: symbol, gap and text (DejaVu Sans ≈ 0.6 em per char).
    fn entry_px(label: &str) -> u32 {
        36 + (label.chars().count() as u32 * LABEL_PX * 6).div_ceil(10) + 18
    }

    /// Rows of entries that fit `width` pixels.
    fn rows(&self, width: u32) -> Vec<Vec<usize>> {
        let mut rows: Vec<Vec<usize>> = Vec::new();
        let mut used = 0;
        for (i, e) in self.entries.iter().enumerate() {
            let w = Self::entry_px(&e.0);
            match rows.last_mut() {
                Some(r) if used + w <= width.saturating_sub(20) => {
                    r.push(i);
                    used += w;
                }
                _ => {
                    rows.push(vec![i]);
                    used = w;
                }
            }
        }
        rows
    }

    fn height(&self, width: u32) -> u32 {
        let n = self.rows(width).len() as u32;
        if n == 0 {
            0
        } else {
            n * LEGEND_ROW_PX + 8
        }
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (w, _) = area.dim_in_pixel();
        let font = ("sans-serif", LABEL_PX).into_font();
        for (r, row) in self.rows(w).iter().enumerate() {
            let y = 4 + r as i32 * LEGEND_ROW_PX as i32 + LEGEND_ROW_PX as i32 / 2;
            let total: u32 = row
                .iter()
                .map(|&i| Self::entry_px(&self.entries[i].0))
                .sum();
            let mut x = (w.saturating_sub(total) / 2) as i32;
            for &i in row {
                let (label, c, k) = &self.entries[i];
                let e = |r: Result<(), DrawingAreaErrorKind<DB::ErrorType>>| {
                    r.map_err(|e| e.to_string())
                };
                match k {
                    Key::Line => e(area.draw(&PathElement::new(
                        vec![(x, y), (x + 28, y)],
                        c.stroke_width(2),
                    )))?,
                    Key::Dashed => {
                        for s in 0..3 {
                            let a = x + s * 10;
                            e(area.draw(&PathElement::new(
                                vec![(a, y), (a + 6, y)],
                                c.stroke_width(2),
                            )))?;
                        }
                    }
                    Key::Points => {
                        e(area.draw(&Circle::new((x + 14, y), 4, c.filled())))?;
                        e(area.draw(&PathElement::new(
                            vec![(x + 14, y - 8), (x + 14, y + 8)],
                            c.stroke_width(1),
                        )))?;
                    }
                    Key::Band | Key::OutlinedBand => {
                        e(area.draw(&Rectangle::new(
                            [(x, y - 7), (x + 28, y + 7)],
                            c.mix(band_alpha(*k == Key::OutlinedBand)).filled(),
                        )))?;
                        if *k == Key::OutlinedBand {
                            for yy in [y - 7, y + 7] {
                                e(area.draw(&PathElement::new(
                                    vec![(x, yy), (x + 28, yy)],
                                    c.mix(OUTLINE_ALPHA).stroke_width(1),
                                )))?;
                            }
                        }
                    }
                }
                e(area.draw(&Text::new(
                    label.clone(),
                    (x + 36, y - (LABEL_PX as i32) / 2 - 1),
                    font.clone().color(&BLACK),
                )))?;
                x += Self::entry_px(label) as i32;
            }
        }
        Ok(())
    }
}

/// Data bounds of a panel (x0, x1, y0, y1), padded; `None` without drawable data.
fn bounds(p: &Panel) -> Option<(f64, f64, f64, f64)> {
    let ok_x = |x: f64| x.is_finite() && (!p.log_x || x > 0.0);
    let ok_y = |y: f64| y.is_finite() && (!p.log_y || y > 0.0);
    let from = p.y_fit_from_x.unwrap_or(f64::NEG_INFINITY);
    let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut take = |x: f64, y: f64| {
        if ok_x(x) && ok_y(y) {
            x0 = x0.min(x);
            x1 = x1.max(x);
            if x >= from {
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    };
    for s in &p.series {
        for (k, &(x, y)) in s.points.iter().enumerate() {
            take(x, y);
            if let Some(&(lo, hi)) = s.y_err.get(k) {
                take(x, lo);
                take(x, hi);
            }
        }
    }
    for b in &p.bands {
        for &(x, lo, hi) in &b.points {
            take(x, lo);
            take(x, hi);
        }
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return None;
    }
    if x1 <= x0 {
        if p.log_x {
            (x0, x1) = (x0 / 2.0, x0 * 2.0);
        } else {
            x1 = x0 + 1.0;
        }
    }
    if p.log_x {
        x0 /= 1.25;
        x1 *= 1.25;
    }
    if p.log_y {
        y0 /= 1.6;
        y1 *= 1.6;
    } else if y1 - y0 < p.min_y_span {
        let c = 0.5 * (y0 + y1);
        (y0, y1) = (c - 0.5 * p.min_y_span, c + 0.5 * p.min_y_span);
    } else {
        let span = y1 - y0;
        let pad = if span > 0.0 {
            0.05 * span
        } else {
            0.5 * y0.abs().max(1e-12)
        };
        y0 -= pad;
        y1 += pad;
    }
    if p.equal_axes && !p.log_x && !p.log_y {
        // widen the narrower range so both have the same units per unit of the other
        let (dx, dy) = (x1 - x0, y1 - y0);
        if dx > dy {
            let c = 0.5 * (y0 + y1);
            (y0, y1) = (c - 0.5 * dx, c + 0.5 * dx);
        } else {
            let c = 0.5 * (x0 + x1);
            (x0, x1) = (c - 0.5 * dy, c + 0.5 * dy);
        }
    }
    Some((x0, x1, y0, y1))
}

/// Pixel rectangle of a panel's plotting area in the figure: x range, y range (ends
/// exclusive).
pub type PixelRect = (Range<i32>, Range<i32>);

/// Error of a drawing step as text.
fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// The remark of a panel in grey on a white box, centred a quarter of the way down
/// `area` (clear of a zero line in the middle).
fn draw_note<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, note: &str) -> Result<(), String> {
    if note.is_empty() {
        return Ok(());
    }
    let (w, h) = area.dim_in_pixel();
    let style = ("sans-serif", DESC_PX)
        .into_font()
        .color(&GREY)
        .pos(Pos::new(HPos::Center, VPos::Center));
    let (tw, th) = area.estimate_text_size(note, &style).map_err(err)?;
    let (cx, cy) = (w as i32 / 2, h as i32 / 4);
    let (hw, hh) = (tw as i32 / 2 + 6, th as i32 / 2 + 4);
    area.draw(&Rectangle::new(
        [(cx - hw, cy - hh), (cx + hw, cy + hh)],
        WHITE.filled(),
    ))
    .map_err(err)?;
    area.draw(&Text::new(note.to_string(), (cx, cy), style))
        .map_err(err)
}

/// Draw one panel; returns its plotting area (`None`: no drawable data).
///
/// Everything is cut to the plotting area ([`clip`]) in coordinates that are linear in
/// the panel (log₁₀ of log axes): lines and error bars where they leave it, bands along
/// its edges, markers at its border. Data beyond the axis range leave the frame; they
/// are not flattened along its edge.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
    legend: &Legend,
) -> Result<Option<PixelRect>, String> {
    let Some((x0, x1, y0, y1)) = bounds(p) else {
        let title = if p.note.is_empty() {
            format!("{} (no data)", p.title)
        } else {
            p.title.clone()
        };
        let inner = area.titled(&title, ("sans-serif", TITLE_PX)).map_err(err)?;
        draw_note(&inner, &p.note)?;
        return Ok(None);
    };
    let (w, h) = area.dim_in_pixel();
    let y_area = 80;
    let x_area = 48;
    let plot_w = w.saturating_sub(y_area + 20).max(50);
    let plot_h = h.saturating_sub(x_area + TITLE_PX + 30).max(50);
    let (log_x, log_y) = (p.log_x, p.log_y);
    let xt = if log_x {
        Ticks::log(x0, x1, (plot_w / 70) as usize)
    } else {
        Ticks::linear(x0, x1, ticks::label_count(plot_w, 95))
    };
    let yt = if log_y {
        Ticks::log(y0, y1, (plot_h / 24) as usize)
    } else {
        Ticks::linear(y0, y1, ticks::label_count(plot_h, 42))
    };
    let x_desc = xt.describe(&p.x_label);
    let y_desc = yt.describe(&p.y_label);
    let cols = plot_w as usize;
    // panel-linear coordinates (log₁₀ of log axes) and back
    let fx = move |x: f64| if log_x { x.log10() } else { x };
    let fy = move |y: f64| if log_y { y.log10() } else { y };
    let gx = move |u: f64| if log_x { 10f64.powf(u) } else { u };
    let gy = move |v: f64| if log_y { 10f64.powf(v) } else { v };
    let frame = clip::Rect {
        x0: fx(x0),
        x1: fx(x1),
        y0: fy(y0),
        y1: fy(y1),
    };
    let back = move |pts: Vec<clip::P>| -> Vec<(f64, f64)> {
        pts.into_iter().map(|(u, v)| (gx(u), gy(v))).collect()
    };
    let ok = |x: f64, y: f64| {
        x.is_finite() && y.is_finite() && (!log_x || x > 0.0) && (!log_y || y > 0.0)
    };
    let x_fmt = |v: &f64| xt.label(*v);
    let y_fmt = |v: &f64| yt.label(*v);
    let plot_rect;
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(x_desc.as_str())
                .y_desc(y_desc.as_str())
                .label_style(("sans-serif", LABEL_PX))
                .axis_desc_style(("sans-serif", DESC_PX))
                .light_line_style(RGBColor(0xee, 0xee, 0xee))
                .bold_line_style(RGBColor(0xd8, 0xd8, 0xd8))
                .x_label_formatter(&x_fmt)
                .y_label_formatter(&y_fmt)
                .draw()
                .map_err(err)?;
            let rect = chart.plotting_area().get_pixel_range();
            for b in &p.bands {
                let color = legend.color_of(&b.color_of);
                let pts: Vec<(f64, f64, f64)> = b
                    .points
                    .iter()
                    .copied()
                    .filter(|&(x, lo, hi)| ok(x, lo) && ok(x, hi))
                    .map(|(x, lo, hi)| (fx(x), fy(lo), fy(hi)))
                    .collect();
                let pts = decimate_band(&pts, frame.x0, frame.x1, cols);
                if pts.len() < 2 {
                    continue;
                }
                let lows: Vec<clip::P> = pts.iter().map(|&(u, lo, _)| (u, lo)).collect();
                let highs: Vec<clip::P> = pts.iter().map(|&(u, _, hi)| (u, hi)).collect();
                let mut ring = lows.clone();
                ring.extend(highs.iter().rev());
                let poly = clip::polygon(&ring, frame);
                if poly.len() >= 3 {
                    chart
                        .draw_series(std::iter::once(Polygon::new(
                            back(poly),
                            color.mix(band_alpha(b.outline)).filled(),
                        )))
                        .map_err(err)?;
                }
                if b.outline {
                    for edge in [lows, highs] {
                        for piece in clip::polyline(&edge, frame) {
                            chart
                                .draw_series(std::iter::once(PathElement::new(
                                    back(piece),
                                    color.mix(OUTLINE_ALPHA).stroke_width(1),
                                )))
                                .map_err(err)?;
                        }
                    }
                }
            }
            for s in &p.series {
                let color = legend.color_of(s.color_key());
                let pts: Vec<clip::P> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|&(x, y)| ok(x, y))
                    .map(|(x, y)| (fx(x), fy(y)))
                    .collect();
                match s.style {
                    Style::Line | Style::Dashed => {
                        let pts = decimate(&pts, frame.x0, frame.x1, cols);
                        for piece in clip::polyline(&pts, frame) {
                            let piece = back(piece);
                            if s.style == Style::Line {
                                chart
                                    .draw_series(LineSeries::new(piece, color.stroke_width(2)))
                                    .map_err(err)?;
                            } else {
                                chart
                                    .draw_series(DashedLineSeries::new(
                                        piece,
                                        8,
                                        5,
                                        color.stroke_width(2),
                                    ))
                                    .map_err(err)?;
                            }
                        }
                    }
                    Style::Points => {
                        for (k, &(x, y)) in s.points.iter().enumerate() {
                            let Some(&(lo, hi)) = s.y_err.get(k) else {
                                continue;
                            };
                            if !(ok(x, y) && ok(x, lo) && ok(x, hi)) {
                                continue;
                            }
                            let bar = clip::segment((fx(x), fy(lo)), (fx(x), fy(hi)), frame);
                            if let Some((a, b)) = bar {
                                chart
                                    .draw_series(std::iter::once(PathElement::new(
                                        back(vec![a, b]),
                                        color.stroke_width(1),
                                    )))
                                    .map_err(err)?;
                            }
                        }
                        // whole discs inside the frame; discs on its border cut
                        let (mut whole, mut cut) = (Vec::new(), Vec::new());
                        for &q in pts.iter().filter(|q| frame.contains(**q)) {
                            let q = (gx(q.0), gy(q.1));
                            let c = chart.backend_coord(&q);
                            let m = MARKER_PX + 1;
                            if c.0 - m >= rect.0.start - 1
                                && c.0 + m <= rect.0.end
                                && c.1 - m >= rect.1.start - 1
                                && c.1 + m <= rect.1.end
                            {
                                whole.push(q);
                            } else {
                                cut.push(c);
                            }
                        }
                        chart
                            .draw_series(
                                whole
                                    .into_iter()
                                    .map(|q| Circle::new(q, MARKER_PX, color.filled())),
                            )
                            .map_err(err)?;
                        let pa = chart.plotting_area().strip_coord_spec();
                        let base = chart.plotting_area().get_base_pixel();
                        for c in cut {
                            let poly = clip::disc(c, MARKER_PX, &rect, base);
                            if poly.len() >= 3 {
                                pa.draw(&Polygon::new(poly, color.filled())).map_err(err)?;
                            }
                        }
                    }
                }
            }
            draw_note(&chart.plotting_area().strip_coord_spec(), &p.note)?;
            plot_rect = Some(rect);
        }};
    }
    let mut b = ChartBuilder::on(area);
    b.caption(p.title.as_str(), ("sans-serif", TITLE_PX))
        .margin(10)
        .margin_right(20)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area);
    let lin = |lo: f64, hi: f64, t: &Ticks| Axis::new(RangedCoordf64::from(lo..hi), t);
    let log = |lo: f64, hi: f64, t: &Ticks| Axis::new(LogCoord::from((lo..hi).log_scale()), t);
    match (log_x, log_y) {
        (false, false) => body!(b
            .build_cartesian_2d(lin(x0, x1, &xt), lin(y0, y1, &yt))
            .map_err(err)?),
        (false, true) => body!(b
            .build_cartesian_2d(lin(x0, x1, &xt), log(y0, y1, &yt))
            .map_err(err)?),
        (true, false) => body!(b
            .build_cartesian_2d(log(x0, x1, &xt), lin(y0, y1, &yt))
            .map_err(err)?),
        (true, true) => body!(b
            .build_cartesian_2d(log(x0, x1, &xt), log(y0, y1, &yt))
            .map_err(err)?),
    }
    Ok(plot_rect)
}

/// Draw a figure; returns the plotting area of each panel.
fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    f: &Figure,
) -> Result<Vec<Option<PixelRect>>, String> {
    root.fill(&WHITE).map_err(err)?;
    let legend = Legend::of(&f.panels);
    let lh = legend.height(f.size.0);
    let (top, grid) = root.split_vertically(lh);
    legend.draw(&top)?;
    let cols = f.cols.max(1);
    let rows = f.panels.len().div_ceil(cols).max(1);
    let areas = grid.split_evenly((rows, cols));
    let mut rects = Vec::new();
    for (p, a) in f.panels.iter().zip(areas.iter()) {
        rects.push(draw_panel(a, p, &legend)?);
    }
    root.present().map_err(err)?;
    Ok(rects)
}

impl Figure {
    /// The figure as an SVG document string.
    pub fn svg(&self) -> Result<String, CliError> {
        register_font()?;
        let mut s = String::new();
        {
            let root = SVGBackend::with_string(&mut s, self.size).into_drawing_area();
            draw(root, self).map_err(|e| CliError::Other(format!("SVG plot: {e}")))?;
        }
        Ok(s)
    }

    /// Write the figure as a PNG file (temporary file, then rename).
    pub fn png(&self, dest: &Path) -> Result<(), CliError> {
        self.png_rects(dest).map(|_| ())
    }

    /// Write the figure as a PNG file and return the plotting area of each panel in it
    /// (`None`: a panel without data).
    pub fn png_rects(&self, dest: &Path) -> Result<Vec<Option<PixelRect>>, CliError> {
        write_png(dest, self.size, |root| draw(root, self))
    }

    /// Write `dir/stem.svg` and `dir/stem.png`; returns the SVG for a report.
    pub fn save(&self, dir: &Path, stem: &str) -> Result<String, CliError> {
        let s = self.svg()?;
        crate::output::write_string(&dir.join(format!("{stem}.svg")), &s)?;
        self.png(&dir.join(format!("{stem}.png")))?;
        Ok(s)
    }
}

/// A bar chart (one bar per label), e.g. execution time per algorithm.
#[derive(Clone, Debug)]
pub struct Bars {
    /// title
    pub title: String,
    /// y-axis label with unit
    pub y_label: String,
    /// (label, value) per bar; a non-finite value draws no bar
    pub bars: Vec<(String, f64)>,
    /// width, height in pixels
    pub size: (u32, u32),
}

/// The y range of a bar chart: from 0 (or the lowest negative bar) to the highest bar,
/// with 15 % headroom.
fn bar_range(bars: &[(String, f64)]) -> (f64, f64) {
    let vals = bars.iter().map(|b| b.1).filter(|v| v.is_finite());
    let (lo, hi) = vals.fold((0.0_f64, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = (lo * 1.15, hi * 1.15);
    if hi - lo > 0.0 {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}

fn draw_bars<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    b: &Bars,
) -> Result<PixelRect, String> {
    root.fill(&WHITE).map_err(err)?;
    let n = b.bars.len().max(1);
    let (y0, y1) = bar_range(&b.bars);
    let yt = Ticks::linear(y0, y1, ticks::label_count(b.size.1.saturating_sub(100), 42));
    let y_desc = yt.describe(&b.y_label);
    // one slot per bar, labelled at its centre
    let centres: Vec<f64> = (0..n).map(|i| i as f64 + 0.5).collect();
    let mut chart = ChartBuilder::on(&root)
        .caption(b.title.as_str(), ("sans-serif", TITLE_PX))
        .margin(10)
        .margin_right(20)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(
            Axis::labelled(RangedCoordf64::from(0.0..n as f64), centres),
            Axis::new(RangedCoordf64::from(y0..y1), &yt),
        )
        .map_err(err)?;
    let labels: Vec<String> = b.bars.iter().map(|x| x.0.clone()).collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .y_desc(y_desc.as_str())
        .x_label_formatter(&|v| {
            let i = v.floor();
            if i >= 0.0 {
                labels.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .y_label_formatter(&|v| yt.label(*v))
        .label_style(("sans-serif", LABEL_PX))
        .axis_desc_style(("sans-serif", DESC_PX))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .bold_line_style(RGBColor(0xd8, 0xd8, 0xd8))
        .draw()
        .map_err(err)?;
    for (i, (_, v)) in b.bars.iter().enumerate() {
        if !v.is_finite() {
            continue;
        }
        let color = COLORS[i % COLORS.len()];
        let (lo, hi) = (v.min(0.0).max(y0), v.max(0.0).min(y1));
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(i as f64 + 0.12, lo), (i as f64 + 0.88, hi)],
                color.mix(BAR_ALPHA).filled(),
            )))
            .map_err(err)?;
    }
    let rect = chart.plotting_area().get_pixel_range();
    root.present().map_err(err)?;
    Ok(rect)
}

impl Bars {
    /// SVG string.
    pub fn svg(&self) -> Result<String, CliError> {
        register_font()?;
        let mut s = String::new();
        {
            let root = SVGBackend::with_string(&mut s, self.size).into_drawing_area();
            draw_bars(root, self).map_err(|e| CliError::Other(format!("SVG plot: {e}")))?;
        }
        Ok(s)
    }

    /// Write the chart as a PNG file (temporary file, then rename).
    pub fn png(&self, dest: &Path) -> Result<(), CliError> {
        self.png_rect(dest).map(|_| ())
    }

    /// Write the chart as a PNG file and return its plotting area in it.
    pub fn png_rect(&self, dest: &Path) -> Result<PixelRect, CliError> {
        write_png(dest, self.size, |root| draw_bars(root, self))
    }

    /// Write `dir/stem.svg` and `dir/stem.png`; returns the SVG for a report.
    pub fn save(&self, dir: &Path, stem: &str) -> Result<String, CliError> {
        let s = self.svg()?;
        crate::output::write_string(&dir.join(format!("{stem}.svg")), &s)?;
        self.png(&dir.join(format!("{stem}.png")))?;
        Ok(s)
    }
}

/// Draw a bitmap with `draw` ([`raster::Raster`]: plotters' bitmap backend with exact
/// glyph placement and joint-safe thick lines) into a temporary PNG next to `dest` and
/// rename it into place (the output-file rule of `crate::output`: a complete file or
/// none).
fn write_png<T>(
    dest: &Path,
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<Raster<'_>, Shift>) -> Result<T, String>,
) -> Result<T, CliError> {
    register_font()?;
    let dest = &crate::output::route(dest)?;
    if let Some(dir) = dest.parent() {
        if !dir.as_os_str().is_empty() {
            std::fs::create_dir_all(dir).map_err(|source| CliError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
        }
    }
    let name = dest
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dest.with_file_name(format!(".{name}.tmp-{}.png", std::process::id()));
    let result = Raster::new(BitMapBackend::new(&tmp, size), dejavu::sans::regular())
        .and_then(|backend| draw(backend.into_drawing_area()));
    match result {
        Ok(v) => {
            std::fs::rename(&tmp, dest).map_err(|source| CliError::Io {
                path: dest.to_path_buf(),
                source,
            })?;
            Ok(v)
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(CliError::Other(format!("PNG plot {}: {e}", dest.display())))
        }
    }
}

#[cfg(test)]
mod figure_tests;
#[cfg(test)]
mod tests;
