//! Plots (plotters): SVG strings for the self-contained HTML reports and PNG files beside
//! them. Text uses the DejaVu Sans font embedded by the `dejavu` crate, so rendering needs
//! no system fonts.

use crate::error::CliError;
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

/// One line of a panel.
#[derive(Clone, Debug)]
pub struct Series {
    /// legend name
    pub name: String,
    /// (x, y) points
    pub points: Vec<(f64, f64)>,
}

/// One panel: axes, labels and lines.
#[derive(Clone, Debug)]
pub struct Panel {
    /// panel title
    pub title: String,
    /// x-axis label with unit
    pub x_label: String,
    /// y-axis label with unit
    pub y_label: String,
    /// logarithmic y axis (values ≤ 0 are dropped)
    pub log_y: bool,
    /// the lines
    pub series: Vec<Series>,
}

/// A figure of panels side by side (`cols` per row).
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

/// Register the embedded DejaVu Sans as the plotters `sans-serif` font.
pub fn register_font() -> Result<(), CliError> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
        .map_err(|_| CliError::Other("cannot load the embedded DejaVu Sans font".into()))
}

fn bounds(p: &Panel) -> Option<(f64, f64, f64, f64)> {
    let mut b = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    let mut any = false;
    for s in &p.series {
        for &(x, y) in &s.points {
            if !x.is_finite() || !y.is_finite() || (p.log_y && y <= 0.0) {
                continue;
            }
            any = true;
            b = (b.0.min(x), b.1.max(x), b.2.min(y), b.3.max(y));
        }
    }
    if !any {
        return None;
    }
    if b.1 <= b.0 {
        b.1 = b.0 + 1.0;
    }
    if p.log_y {
        b.2 *= 0.5;
        b.3 *= 2.0;
    } else {
        let pad = 0.05 * (b.3 - b.2).max(1e-300);
        b.2 -= pad;
        b.3 += pad;
        if b.3 <= b.2 {
            b.3 = b.2 + 1.0;
        }
    }
    Some(b)
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    p: &Panel,
) -> Result<(), String> {
    let Some((x0, x1, y0, y1)) = bounds(p) else {
        area.titled(&format!("{} (no data)", p.title), ("sans-serif", 18))
            .map_err(|e| e.to_string())?;
        return Ok(());
    };
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(p.x_label.as_str())
                .y_desc(p.y_label.as_str())
                .label_style(("sans-serif", 13))
                .axis_desc_style(("sans-serif", 15))
                .y_label_formatter(&|v| {
                    let big = y0.abs().max(y1.abs());
                    if p.log_y || !(1e-2..1e4).contains(&big) {
                        format!("{:.1e}", v)
                    } else {
                        format!("{:.3}", v)
                    }
                })
                .draw()
                .map_err(|e| e.to_string())?;
            for (k, s) in p.series.iter().enumerate() {
                let color = COLORS[k % COLORS.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|(x, y)| x.is_finite() && y.is_finite() && (!p.log_y || *y > 0.0))
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                    .map_err(|e| e.to_string())?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 13))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperLeft)
                .draw()
                .map_err(|e| e.to_string())?;
        }};
    }
    let mut b = ChartBuilder::on(area);
    b.caption(p.title.as_str(), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(45)
        .y_label_area_size(75);
    if p.log_y {
        body!(b
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(|e| e.to_string())?);
    } else {
        body!(b
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?);
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    f: &Figure,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let cols = f.cols.max(1);
    let rows = f.panels.len().div_ceil(cols).max(1);
    let areas = root.split_evenly((rows, cols));
    for (p, a) in f.panels.iter().zip(areas.iter()) {
        draw_panel(a, p)?;
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

fn draw_bars<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    b: &Bars,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let n = b.bars.len().max(1);
    let ymax = b
        .bars
        .iter()
        .map(|x| x.1)
        .fold(0.0_f64, f64::max)
        .max(1e-300)
        * 1.15;
    let mut chart = ChartBuilder::on(&root)
        .caption(b.title.as_str(), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(75)
        .build_cartesian_2d((0..n).into_segmented(), 0.0..ymax)
        .map_err(|e| e.to_string())?;
    let labels: Vec<String> = b.bars.iter().map(|x| x.0.clone()).collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .y_desc(b.y_label.as_str())
        .x_labels(n)
        .x_label_formatter(&|v| match v {
            SegmentValue::CenterOf(i) => labels.get(*i).cloned().unwrap_or_default(),
            _ => String::new(),
        })
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 15))
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
}

/// Draw a bitmap with `draw` into a temporary PNG next to `dest` and rename it into place
/// (the output-file rule of `crate::output`: a complete file or none).
pub fn write_png(
    dest: &Path,
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<(), String>,
) -> Result<(), CliError> {
    register_font()?;
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
