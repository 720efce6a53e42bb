//! Plots of `sdins align` (fine alignment and multi-heading Algorithm A): the time
//! histories that `align_history.csv` holds, drawn as
//!
//! * `align_attitude.svg/.png`: one panel per NED axis, the attitude error
//!   `φ = log(Ĉ Cᵀ)` (convention G, spec §0.2) against the truth (scenarios) in μrad,
//!   with the filter's `±3σ = ±3 √P_φφ` as dashed lines in the same color. Without a
//!   truth (IMU files) only the `±3σ` bounds are drawn.
//! * `align_bias.svg/.png`: accelerometer (μg) and gyro (°/h) bias estimates in body
//!   axes, `b̂ ± 3σ` dashed in the same color. σ is the body-frame 1σ of the bias state
//!   (spec §2.1 NED states rotated with `Ĉᵀ P Ĉ`, or the body states of §3.2).
//!
//! The y range is fitted to the last 90 % of the record (the first Kalman cycles carry
//! the P0 bounds of spec §2.3, up to 30 mrad in heading, which would flatten the
//! converged part); values outside it are clipped to the frame. Text uses the DejaVu
//! Sans font embedded by the `dejavu` crate (as `sdins allan`).

use crate::error::CliError;
use crate::output::write_string;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use std::path::Path;

/// One Kalman cycle of the history (display units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HistRow {
    /// time [s]
    pub t_s: f64,
    /// attitude error against the truth, N/E/D [μrad] (scenarios only)
    pub phi_urad: Option<[f64; 3]>,
    /// 1σ of φ, N/E/D [μrad]
    pub sig_phi_urad: [f64; 3],
    /// accelerometer bias estimate, body x/y/z [μg]
    pub ba_ug: [f64; 3],
    /// its 1σ [μg]
    pub sig_ba_ug: [f64; 3],
    /// gyro bias estimate, body x/y/z [°/h]
    pub bg_dph: [f64; 3],
    /// its 1σ [°/h]
    pub sig_bg_dph: [f64; 3],
}

const SIZE: (u32, u32) = (1500, 500);
const COLORS: [RGBColor; 3] = [RED, RGBColor(0, 150, 0), BLUE];

/// One curve of a panel: the center line (optional) and its ±3σ half-width.
struct Curve {
    label: String,
    center: Option<Vec<(f64, f64)>>,
    /// (t, center, 3σ); the bounds are `center ± 3σ`
    band: Vec<(f64, f64, f64)>,
}

/// One panel: caption, y-axis label and up to three curves.
struct Panel {
    title: String,
    y_desc: String,
    curves: Vec<Curve>,
}

/// The y range of a panel from the rows with `t ≥ t_from`, padded by 10 %; `None` if
/// there is no finite value.
fn y_range(p: &Panel, t_from: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut take = |y: f64| {
        if y.is_finite() {
            lo = lo.min(y);
            hi = hi.max(y);
        }
    };
    for c in &p.curves {
        for &(_, m, s) in c.band.iter().filter(|b| b.0 >= t_from) {
            take(m - s);
            take(m + s);
        }
        if let Some(pts) = &c.center {
            for &(_, y) in pts.iter().filter(|q| q.0 >= t_from) {
                take(y);
            }
        }
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let span = (hi - lo).max(1e-9 * lo.abs().max(hi.abs())).max(1e-12);
    Some((lo - 0.1 * span, hi + 0.1 * span))
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    panels: &[Panel],
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let areas = root.split_evenly((1, panels.len().max(1)));
    for (p, area) in panels.iter().zip(areas.iter()) {
        let ts = p.curves.iter().flat_map(|c| c.band.iter().map(|b| b.0));
        let (t0, t1) = ts.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
            (a.min(t), b.max(t))
        });
        if !(t0.is_finite() && t1 > t0) {
            continue;
        }
        let Some((y0, y1)) = y_range(p, t0 + 0.1 * (t1 - t0)) else {
            continue;
        };
        let clip = |y: f64| y.clamp(y0, y1);
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(80)
            .build_cartesian_2d(t0..t1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("time [s]")
            .y_desc(p.y_desc.as_str())
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 15))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, c) in p.curves.iter().enumerate() {
            let color = COLORS[k % COLORS.len()];
            if let Some(pts) = &c.center {
                let pts: Vec<(f64, f64)> = pts
                    .iter()
                    .filter(|q| q.1.is_finite())
                    .map(|&(t, y)| (t, clip(y)))
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                    .map_err(|e| e.to_string())?
                    .label(c.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
            }
            let ok: Vec<&(f64, f64, f64)> = c
                .band
                .iter()
                .filter(|b| b.1.is_finite() && b.2.is_finite())
                .collect();
            for (n, sign) in [1.0, -1.0].into_iter().enumerate() {
                let pts: Vec<(f64, f64)> = ok
                    .iter()
                    .map(|&&(t, m, s)| (t, clip(m + sign * s)))
                    .collect();
                let series = chart
                    .draw_series(DashedLineSeries::new(pts, 6, 4, color.stroke_width(1)))
                    .map_err(|e| e.to_string())?;
                if n == 0 {
                    series
                        .label(format!("{} ±3σ", c.label))
                        .legend(move |(x, y)| {
                            DashedPathElement::new(
                                vec![(x, y), (x + 20, y)],
                                5,
                                3,
                                color.stroke_width(1),
                            )
                        });
                }
            }
        }
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

fn attitude_panels(rows: &[HistRow]) -> Vec<Panel> {
    let truth = rows.iter().all(|r| r.phi_urad.is_some());
    let names = [
        ("φ_N", "north tilt"),
        ("φ_E", "east tilt"),
        ("φ_D", "heading"),
    ];
    names
        .iter()
        .enumerate()
        .map(|(i, (sym, what))| {
            let center = truth.then(|| {
                rows.iter()
                    .filter_map(|r| r.phi_urad.map(|p| (r.t_s, p[i])))
                    .collect()
            });
            Panel {
                title: if truth {
                    format!("{what} error {sym} (G, NED)")
                } else {
                    format!("{what} {sym}: ±3σ only (no truth)")
                },
                y_desc: format!("{sym} [μrad]"),
                curves: vec![Curve {
                    label: sym.to_string(),
                    center,
                    band: rows
                        .iter()
                        .map(|r| (r.t_s, 0.0, 3.0 * r.sig_phi_urad[i]))
                        .collect(),
                }],
            }
        })
        .collect()
}

fn bias_panels(rows: &[HistRow]) -> Vec<Panel> {
    type Pick = fn(&HistRow) -> ([f64; 3], [f64; 3]);
    let specs: [(&str, &str, &str, Pick); 2] = [
        (
            "Accelerometer bias estimates (body)",
            "accelerometer bias [μg]",
            "a",
            |r| (r.ba_ug, r.sig_ba_ug),
        ),
        ("Gyro bias estimates (body)", "gyro bias [°/h]", "g", |r| {
            (r.bg_dph, r.sig_bg_dph)
        }),
    ];
    specs
        .iter()
        .map(|(title, y_desc, s, pick)| Panel {
            title: title.to_string(),
            y_desc: y_desc.to_string(),
            curves: ["x", "y", "z"]
                .iter()
                .enumerate()
                .map(|(i, ax)| Curve {
                    label: format!("b{s}_{ax}"),
                    center: Some(rows.iter().map(|r| (r.t_s, pick(r).0[i])).collect()),
                    band: rows
                        .iter()
                        .map(|r| {
                            let (b, sd) = pick(r);
                            (r.t_s, b[i], 3.0 * sd[i])
                        })
                        .collect(),
                })
                .collect(),
        })
        .collect()
}

fn svg(panels: &[Panel]) -> Result<String, CliError> {
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, SIZE).into_drawing_area();
        draw(root, panels).map_err(|e| CliError::Other(format!("SVG plot: {e}")))?;
    }
    Ok(s)
}

/// Draw to a temporary PNG next to `dest`, then rename into place.
fn png(panels: &[Panel], dest: &Path) -> Result<(), CliError> {
    crate::plot::write_png(dest, SIZE, |root| draw(root, panels))
}

/// Write `align_attitude.svg/.png` and `align_bias.svg/.png` into `dir` and return the
/// two SVG documents (attitude, bias) for the report. Fewer than two rows (nothing to
/// draw) is a bad-input error.
pub fn write_plots(dir: &Path, rows: &[HistRow]) -> Result<[String; 2], CliError> {
    if rows.len() < 2 {
        return Err(CliError::bad(format!(
            "alignment plots need at least two Kalman cycles, the history has {}",
            rows.len()
        )));
    }
    crate::plot::register_font()?;
    let mut out: [String; 2] = Default::default();
    for (k, (stem, panels)) in [
        ("align_attitude", attitude_panels(rows)),
        ("align_bias", bias_panels(rows)),
    ]
    .into_iter()
    .enumerate()
    {
        let s = svg(&panels)?;
        write_string(&dir.join(format!("{stem}.svg")), &s)?;
        png(&panels, &dir.join(format!("{stem}.png")))?;
        out[k] = s;
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    fn rows(truth: bool, n: usize) -> Vec<HistRow> {
        (0..n)
            .map(|k| {
                let t = (k + 1) as f64;
                let s = 1000.0 / t.sqrt();
                HistRow {
                    t_s: t,
                    phi_urad: truth.then_some([s * 0.3, -s * 0.2, s]),
                    sig_phi_urad: [s, s, 10.0 * s],
                    ba_ug: [50.0, -80.0, 30.0 - s / 100.0],
                    sig_ba_ug: [100.0, 100.0, s / 10.0],
                    bg_dph: [0.01, -0.02, 0.015],
                    sig_bg_dph: [0.02, 0.02, 0.02 / t.sqrt()],
                }
            })
            .collect()
    }

    #[test]
    fn plots_have_labels_legends_and_dashed_bounds() {
        crate::plot::register_font().unwrap();
        let r = rows(true, 300);
        let s = svg(&attitude_panels(&r)).unwrap();
        assert!(
            s.contains("φ_N [μrad]") && s.contains("time [s]"),
            "axis labels"
        );
        assert!(s.contains("φ_D ±3σ"), "legend");
        assert!(s.contains("stroke-dasharray") || s.matches("<polyline").count() > 9);
        let s = svg(&bias_panels(&r)).unwrap();
        assert!(s.contains("accelerometer bias [μg]") && s.contains("gyro bias [°/h]"));
        assert!(s.contains("bg_z ±3σ"));
        // no truth: bounds only; NaN and empty inputs do not panic
        let mut r = rows(false, 50);
        r[10].sig_phi_urad = [f64::NAN; 3];
        r[11].ba_ug = [f64::INFINITY; 3];
        let s = svg(&attitude_panels(&r)).unwrap();
        assert!(s.contains("no truth"));
        assert!(svg(&bias_panels(&r)).is_ok());
        assert!(svg(&attitude_panels(&[])).is_ok());
        let all_nan = vec![
            HistRow {
                sig_phi_urad: [f64::NAN; 3],
                ..rows(false, 1)[0]
            };
            5
        ];
        assert!(svg(&attitude_panels(&all_nan)).is_ok());
        let d = std::env::temp_dir().join(format!("sdins-align-plot-{}", std::process::id()));
        assert_eq!(write_plots(&d, &r[..1]).unwrap_err().exit_code(), 2);
        let _ = std::fs::remove_dir_all(&d);
    }
}
