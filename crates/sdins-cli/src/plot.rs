//! Plots (plotters): SVG strings for the self-contained HTML reports and SVG + PNG files
//! beside them. Text uses the DejaVu Sans font embedded by the `dejavu` crate, so
//! rendering needs no system fonts.
//!
//! Figure rules (docs/user-guide.md, "Figures"): tick labels formatted for their range
//! ([`tick_label`]: `1e-3`, `500`, `0.25`), a label count fitted to the panel size so
//! labels do not overlap, one legend per figure in a strip above the panels (never over
//! the data), mean ± σ and ±3σ as shaded bands ([`Band`]), and series longer than the
//! plot width decimated to the minimum and maximum of each pixel column
//! ([`MinMaxColumns`]) so that short events (a 2 s turn in an hour) stay visible.

use crate::error::CliError;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;

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

/// A legend-only entry in grey explaining what shaded bands mean.
pub fn band_note(label: &str) -> Band {
    Band {
        name: label.into(),
        color_of: STYLE_KEY.into(),
        points: Vec::new(),
    }
}

/// A legend-only entry in grey explaining what dashed lines mean.
pub fn dashed_note(label: &str) -> Series {
    Series::dashed(label, Vec::new()).colored_as(STYLE_KEY)
}

const GREY: RGBColor = RGBColor(0x70, 0x70, 0x70);

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

/// Remove trailing zeros of a decimal fraction (`"2.500"` → `"2.5"`, `"3.000"` → `"3"`).
fn trim_fraction(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// A tick label formatted for its axis: `step` is the distance between ticks (for a log
/// axis pass the value itself). Values in [0.01, 10⁵) are written as decimals with just
/// the digits the step needs (`500`, `0.25`, `12.5`); others in shortest scientific form
/// (`1e-3`, `2.5e-4`, `3e6`); zero (or a value below 10⁻⁹ steps) is `0`.
pub fn tick_label(v: f64, step: f64) -> String {
    if !v.is_finite() {
        return String::new();
    }
    let step = step.abs();
    if v == 0.0 || (step > 0.0 && v.abs() < 1e-9 * step) {
        return "0".into();
    }
    let step = if step > 0.0 && step.is_finite() {
        step
    } else {
        v.abs()
    };
    let mag = v.abs();
    if (1e-2..1e5).contains(&mag) {
        let decimals = (-(step.log10().floor()) + 1.0).clamp(0.0, 12.0) as usize;
        let s = trim_fraction(&format!("{v:.decimals$}"));
        if s == "-0" {
            "0".into()
        } else {
            s
        }
    } else {
        let digits = ((mag / step).log10().ceil() + 1.0).clamp(1.0, 8.0) as usize;
        let s = format!("{v:.digits$e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim_fraction(m)),
            None => s,
        }
    }
}

/// Tick count that fits `len_px` pixels of axis with `px_per_label` per label.
fn label_count(len_px: u32, px_per_label: u32) -> usize {
    ((len_px / px_per_label.max(1)) as usize).clamp(2, 10)
}

/// The step between "nice" ticks (1, 2, 5 × 10ᵏ) for `n` labels over `span`.
fn nice_step(span: f64, n: usize) -> f64 {
    let raw = span.abs() / n.max(1) as f64;
    if !(raw > 0.0 && raw.is_finite()) {
        return 1.0;
    }
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let k = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    k * p
}

/// (x, y) of the minimum and (x, y) of the maximum of one column.
type MinMax = ((f64, f64), (f64, f64));

/// Online min/max-per-column decimation of one or more channels sharing an x axis: the
/// x range `[x0, x1]` is cut into `cols` columns and each column keeps, per channel, the
/// sample with the smallest and the one with the largest y. Drawing the kept points in
/// x order gives, at `cols` pixel columns or fewer, the same picture as all samples:
/// every column's vertical extent is preserved exactly. Non-finite values are skipped.
#[derive(Clone, Debug)]
pub struct MinMaxColumns {
    x0: f64,
    width: f64,
    cols: usize,
    channels: usize,
    /// per column and channel: ((x, y) of the minimum, (x, y) of the maximum)
    cells: Vec<Option<MinMax>>,
}

impl MinMaxColumns {
    /// `cols` columns over `[x0, x1]` for `channels` channels.
    pub fn new(x0: f64, x1: f64, cols: usize, channels: usize) -> Self {
        let cols = cols.max(1);
        let width = if x1 > x0 { x1 - x0 } else { 1.0 };
        Self {
            x0,
            width,
            cols,
            channels,
            cells: vec![None; cols * channels],
        }
    }

    fn column(&self, x: f64) -> usize {
        let k = ((x - self.x0) / self.width * self.cols as f64).floor();
        if k.is_finite() {
            (k.max(0.0) as usize).min(self.cols - 1)
        } else {
            0
        }
    }

    /// Add one sample at `x` of every channel (`ys.len()` = channels; extra values are
    /// ignored).
    pub fn push(&mut self, x: f64, ys: &[f64]) {
        if !x.is_finite() {
            return;
        }
        let c = self.column(x);
        for (ch, &y) in ys.iter().enumerate().take(self.channels) {
            if !y.is_finite() {
                continue;
            }
            let cell = &mut self.cells[c * self.channels + ch];
            match cell {
                None => *cell = Some(((x, y), (x, y))),
                Some((lo, hi)) => {
                    if y < lo.1 {
                        *lo = (x, y);
                    }
                    if y > hi.1 {
                        *hi = (x, y);
                    }
                }
            }
        }
    }

    /// The kept points of channel `ch` in x order (one or two per non-empty column).
    pub fn series(&self, ch: usize) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        for c in 0..self.cols {
            if let Some(Some((lo, hi))) = self.cells.get(c * self.channels + ch) {
                if lo == hi {
                    out.push(*lo);
                } else if lo.0 <= hi.0 {
                    out.extend([*lo, *hi]);
                } else {
                    out.extend([*hi, *lo]);
                }
            }
        }
        out
    }
}

/// Decimate `points` (in x order) to at most two per column of `cols` columns over
/// `[x0, x1]`, keeping each column's minimum and maximum ([`MinMaxColumns`]); series of
/// at most `2 cols` points are returned unchanged.
pub fn decimate(points: &[(f64, f64)], x0: f64, x1: f64, cols: usize) -> Vec<(f64, f64)> {
    if points.len() <= 2 * cols {
        return points.to_vec();
    }
    let mut m = MinMaxColumns::new(x0, x1, cols, 1);
    for &(x, y) in points {
        m.push(x, &[y]);
    }
    m.series(0)
}

/// Decimate a band: per column the lowest low and the highest high.
fn decimate_band(
    points: &[(f64, f64, f64)],
    x0: f64,
    x1: f64,
    cols: usize,
) -> Vec<(f64, f64, f64)> {
    if points.len() <= 2 * cols {
        return points.to_vec();
    }
    let mut m = MinMaxColumns::new(x0, x1, cols, 2);
    for &(x, lo, hi) in points {
        m.push(x, &[lo, hi]);
    }
    let lo = m.series(0);
    let hi = m.series(1);
    // one point per column: column center, min of lows, max of highs
    let mut out = Vec::new();
    let (mut i, mut j) = (0, 0);
    for c in 0..m.cols {
        let in_col = |x: f64| m.column(x) == c;
        let mut l = f64::INFINITY;
        let mut h = f64::NEG_INFINITY;
        let mut xs = f64::NAN;
        while i < lo.len() && in_col(lo[i].0) {
            l = l.min(lo[i].1);
            xs = lo[i].0;
            i += 1;
        }
        while j < hi.len() && in_col(hi[j].0) {
            h = h.max(hi[j].1);
            j += 1;
        }
        if l.is_finite() && h.is_finite() {
            out.push((xs, l, h));
        }
    }
    out
}

/// Legend entries of a figure in order of first appearance: (label, color, kind).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Key {
    Line,
    Dashed,
    Points,
    Band,
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
                l.add(&b.name, c, Key::Band);
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
                    Key::Band => e(area.draw(&Rectangle::new(
                        [(x, y - 7), (x + 28, y + 7)],
                        c.mix(0.25).filled(),
                    )))?,
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

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
    legend: &Legend,
) -> Result<(), String> {
    let Some((x0, x1, y0, y1)) = bounds(p) else {
        area.titled(&format!("{} (no data)", p.title), ("sans-serif", TITLE_PX))
            .map_err(|e| e.to_string())?;
        return Ok(());
    };
    let (w, h) = area.dim_in_pixel();
    let y_area = 80;
    let x_area = 48;
    let plot_w = w.saturating_sub(y_area + 20).max(50);
    let plot_h = h.saturating_sub(x_area + TITLE_PX + 30).max(50);
    let nx = label_count(plot_w, 95);
    let ny = label_count(plot_h, 42);
    let x_step = nice_step(x1 - x0, nx);
    let y_step = nice_step(y1 - y0, ny);
    let cols = plot_w as usize;
    let clip_y = |y: f64| y.clamp(y0, y1);
    let ok = |x: f64, y: f64| {
        x.is_finite() && y.is_finite() && (!p.log_x || x > 0.0) && (!p.log_y || y > 0.0)
    };
    let (log_x, log_y) = (p.log_x, p.log_y);
    let x_fmt = move |v: &f64| tick_label(*v, if log_x { *v } else { x_step });
    let y_fmt = move |v: &f64| tick_label(*v, if log_y { *v } else { y_step });
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(p.x_label.as_str())
                .y_desc(p.y_label.as_str())
                .x_labels(nx)
                .y_labels(ny)
                .label_style(("sans-serif", LABEL_PX))
                .axis_desc_style(("sans-serif", DESC_PX))
                .light_line_style(RGBColor(0xee, 0xee, 0xee))
                .bold_line_style(RGBColor(0xd8, 0xd8, 0xd8))
                .x_label_formatter(&x_fmt)
                .y_label_formatter(&y_fmt)
                .draw()
                .map_err(|e| e.to_string())?;
            for b in &p.bands {
                let color = legend.color_of(&b.color_of);
                let pts: Vec<(f64, f64, f64)> = b
                    .points
                    .iter()
                    .copied()
                    .filter(|&(x, lo, hi)| ok(x, lo) && ok(x, hi))
                    .collect();
                let pts = decimate_band(&pts, x0, x1, cols);
                if pts.len() < 2 {
                    continue;
                }
                let mut poly: Vec<(f64, f64)> =
                    pts.iter().map(|&(x, lo, _)| (x, clip_y(lo))).collect();
                poly.extend(pts.iter().rev().map(|&(x, _, hi)| (x, clip_y(hi))));
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        poly,
                        color.mix(0.22).filled(),
                    )))
                    .map_err(|e| e.to_string())?;
            }
            for s in &p.series {
                let color = legend.color_of(s.color_key());
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|&(x, y)| ok(x, y))
                    .map(|(x, y)| (x, clip_y(y)))
                    .collect();
                match s.style {
                    Style::Line => {
                        let pts = decimate(&pts, x0, x1, cols);
                        chart
                            .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                            .map_err(|e| e.to_string())?;
                    }
                    Style::Dashed => {
                        let pts = decimate(&pts, x0, x1, cols);
                        chart
                            .draw_series(DashedLineSeries::new(pts, 8, 5, color.stroke_width(2)))
                            .map_err(|e| e.to_string())?;
                    }
                    Style::Points => {
                        for (k, &(x, y)) in s.points.iter().enumerate() {
                            if !ok(x, y) {
                                continue;
                            }
                            if let Some(&(lo, hi)) = s.y_err.get(k) {
                                if ok(x, lo) && ok(x, hi) {
                                    chart
                                        .draw_series(std::iter::once(PathElement::new(
                                            vec![(x, clip_y(lo)), (x, clip_y(hi))],
                                            color.stroke_width(1),
                                        )))
                                        .map_err(|e| e.to_string())?;
                                }
                            }
                        }
                        chart
                            .draw_series(pts.iter().map(|&q| Circle::new(q, 3, color.filled())))
                            .map_err(|e| e.to_string())?;
                    }
                }
            }
        }};
    }
    let mut b = ChartBuilder::on(area);
    b.caption(p.title.as_str(), ("sans-serif", TITLE_PX))
        .margin(10)
        .margin_right(20)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area);
    match (p.log_x, p.log_y) {
        (false, false) => body!(b
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?),
        (false, true) => body!(b
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(|e| e.to_string())?),
        (true, false) => body!(b
            .build_cartesian_2d((x0..x1).log_scale(), y0..y1)
            .map_err(|e| e.to_string())?),
        (true, true) => body!(b
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| e.to_string())?),
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, f: &Figure) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let legend = Legend::of(&f.panels);
    let lh = legend.height(f.size.0);
    let (top, grid) = root.split_vertically(lh);
    legend.draw(&top)?;
    let cols = f.cols.max(1);
    let rows = f.panels.len().div_ceil(cols).max(1);
    let areas = grid.split_evenly((rows, cols));
    for (p, a) in f.panels.iter().zip(areas.iter()) {
        draw_panel(a, p, &legend)?;
    }
    root.present().map_err(|e| e.to_string())
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
    /// (label, value) per bar
    pub bars: Vec<(String, f64)>,
    /// width, height in pixels
    pub size: (u32, u32),
}

fn draw_bars<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, b: &Bars) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let n = b.bars.len().max(1);
    let ymax = b
        .bars
        .iter()
        .map(|x| x.1)
        .filter(|v| v.is_finite())
        .fold(0.0_f64, f64::max)
        .max(1e-300)
        * 1.15;
    let ny = label_count(b.size.1.saturating_sub(100), 42);
    let step = nice_step(ymax, ny);
    let mut chart = ChartBuilder::on(&root)
        .caption(b.title.as_str(), ("sans-serif", TITLE_PX))
        .margin(10)
        .margin_right(20)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d((0..n).into_segmented(), 0.0..ymax)
        .map_err(|e| e.to_string())?;
    let labels: Vec<String> = b.bars.iter().map(|x| x.0.clone()).collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .y_desc(b.y_label.as_str())
        .x_labels(n)
        .y_labels(ny)
        .x_label_formatter(&|v| match v {
            SegmentValue::CenterOf(i) => labels.get(*i).cloned().unwrap_or_default(),
            _ => String::new(),
        })
        .y_label_formatter(&|v| tick_label(*v, step))
        .label_style(("sans-serif", LABEL_PX))
        .axis_desc_style(("sans-serif", DESC_PX))
        .draw()
        .map_err(|e| e.to_string())?;
    for (i, (_, v)) in b.bars.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [
                    (SegmentValue::Exact(i), 0.0),
                    (SegmentValue::Exact(i + 1), *v),
                ],
                color.mix(0.8).filled(),
            )))
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
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

/// Draw a bitmap with `draw` into a temporary PNG next to `dest` and rename it into place
/// (the output-file rule of `crate::output`: a complete file or none).
pub fn write_png(
    dest: &Path,
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), String>,
) -> Result<(), CliError> {
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
    let result = draw(BitMapBackend::new(&tmp, size).into_drawing_area());
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(CliError::Other(format!("PNG plot {}: {e}", dest.display())));
    }
    std::fs::rename(&tmp, dest).map_err(|source| CliError::Io {
        path: dest.to_path_buf(),
        source,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_formatted_for_their_range() {
        assert_eq!(tick_label(500.0, 100.0), "500");
        assert_eq!(tick_label(0.25, 0.05), "0.25");
        assert_eq!(tick_label(0.30000000000000004, 0.1), "0.3");
        assert_eq!(tick_label(12.5, 2.5), "12.5");
        assert_eq!(tick_label(-1500.0, 500.0), "-1500");
        assert_eq!(tick_label(0.0, 0.1), "0");
        assert_eq!(tick_label(1e-17, 0.1), "0");
        // log axes: the value is its own step
        assert_eq!(tick_label(1e-3, 1e-3), "1e-3");
        assert_eq!(tick_label(1e-6, 1e-6), "1e-6");
        assert_eq!(tick_label(100.0, 100.0), "100");
        assert_eq!(tick_label(1e6, 1e6), "1e6");
        // small steps in scientific form keep the digits that tell ticks apart
        assert_eq!(tick_label(2.5e-4, 5e-5), "2.5e-4");
        assert_eq!(tick_label(-3e-4, 1e-4), "-3e-4");
        assert_eq!(tick_label(1.0002e5, 1e1), "1.0002e5");
        // no "1.0e-3", no "500.0"
        for (v, s) in [(1e-3, 1e-3), (500.0, 100.0), (2e5, 1e5), (0.05, 0.01)] {
            let t = tick_label(v, s);
            assert!(!t.contains(".0e") && !t.ends_with(".0"), "{t}");
        }
    }

    #[test]
    fn nice_steps_are_1_2_5() {
        assert_eq!(nice_step(10.0, 5), 2.0);
        assert_eq!(nice_step(1.0, 4), 0.5);
        assert!((nice_step(3e-4, 3) - 1e-4).abs() < 1e-18);
    }

    /// The decimation keeps, per column, exactly the minimum and the maximum of the
    /// samples falling in it (so the drawn vertical extent of every column is exact).
    #[test]
    fn decimation_preserves_min_and_max_per_column() {
        let n = 100_000;
        let (x0, x1, cols) = (0.0, 100.0, 700);
        // a noisy sine plus one 2-sample spike at t = 50.005
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let x = x1 * i as f64 / n as f64;
                let noise = (((i as u64).wrapping_mul(2_654_435_761) % 1000) as f64) * 1e-3;
                let spike = if (50_005..50_007).contains(&i) {
                    40.0
                } else {
                    0.0
                };
                (x, (x * 0.3).sin() + noise + spike)
            })
            .collect();
        let d = decimate(&pts, x0, x1, cols);
        assert!(d.len() <= 2 * cols, "{}", d.len());
        assert!(d.windows(2).all(|w| w[0].0 <= w[1].0), "x order kept");
        let col = |x: f64| ((x - x0) / (x1 - x0) * cols as f64).floor() as usize;
        for c in 0..cols {
            let inside: Vec<f64> = pts.iter().filter(|p| col(p.0) == c).map(|p| p.1).collect();
            let kept: Vec<f64> = d.iter().filter(|p| col(p.0) == c).map(|p| p.1).collect();
            let lo = inside.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = inside.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let klo = kept.iter().copied().fold(f64::INFINITY, f64::min);
            let khi = kept.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            assert_eq!((lo, hi), (klo, khi), "column {c}");
        }
        assert!(d.iter().any(|p| p.1 > 40.0), "the spike survives");
        // short series are untouched
        assert_eq!(decimate(&pts[..10], x0, x1, cols), pts[..10].to_vec());
    }

    #[test]
    fn online_columns_match_batch_decimation_per_channel() {
        let mut m = MinMaxColumns::new(0.0, 10.0, 5, 2);
        for i in 0..100 {
            let x = i as f64 * 0.1;
            m.push(x, &[x, -x]);
        }
        m.push(f64::NAN, &[1.0, 1.0]);
        m.push(3.0, &[f64::NAN, f64::INFINITY]);
        let s0 = m.series(0);
        assert_eq!(s0.len(), 10);
        assert_eq!(s0[0], (0.0, 0.0));
        assert!((s0[9].1 - 9.9).abs() < 1e-12);
        let s1 = m.series(1);
        assert!((s1[9].1 + 9.9).abs() < 1e-12);
    }

    #[test]
    fn legend_is_outside_the_panels_and_figures_render() {
        register_font().unwrap();
        let f = Figure {
            panels: vec![Panel {
                title: "p".into(),
                x_label: "time [s]".into(),
                y_label: "y [m]".into(),
                bands: vec![Band {
                    name: "a ± σ".into(),
                    color_of: "a".into(),
                    points: (0..50).map(|i| (i as f64, -1.0, 1.0)).collect(),
                }],
                series: vec![
                    Series::line("a", (0..50).map(|i| (i as f64, (i as f64).sin())).collect()),
                    Series::dashed("true", vec![(0.0, 0.5), (49.0, 0.5)]),
                ],
                ..Panel::default()
            }],
            cols: 1,
            size: (600, 400),
        };
        let l = Legend::of(&f.panels);
        assert_eq!(l.entries.len(), 3);
        assert_eq!(l.height(600), LEGEND_ROW_PX + 8);
        let svg = f.svg().unwrap();
        assert!(svg.contains("a ± σ") && svg.contains("true"));
        assert!(!svg.contains("<script"));
    }
}
