//! Plots of `sdins align` (fine alignment and multi-heading Algorithm A): the time
//! histories that `align_history.csv` holds, drawn as
//!
//! * `align_attitude.svg/.png`: one panel per NED axis, the attitude error
//!   `φ = log(Ĉ Cᵀ)` (convention G, docs/conventions.md §"Errors") against the truth (scenarios) in
//!   μrad, with the filter's `±3σ = ±3 √P_φφ` as a shaded band in the same color. Without a truth
//!   (IMU files) only the `±3σ` band is drawn.
//! * `align_bias.svg/.png`: accelerometer (μg) and gyro (°/h) bias estimates in body
//!   axes, each in its own color with `b̂ ± 3σ` shaded and outlined in that color (its own
//!   legend entry), and the true bias (scenarios) dashed. σ is the body-frame 1σ of the
//!   bias state (docs/theory/alignment.md §"Fine alignment" NED states rotated with
//!   `Ĉᵀ P Ĉ`, or the body-frame states of Algorithm A). Per sensor two panels: the
//!   states the record observes, and, apart, those it does not (σ at the end still
//!   ≥ [`UNOBSERVABLE_SHARE`] of σ at the start; in a stationary fine alignment the level
//!   accelerometer biases and the east gyro bias), whose P0-sized bands would otherwise
//!   dwarf the estimates. The panel titles name the states in each.
//!
//! The y range is fitted to the last 90 % of the record (the first Kalman cycles carry
//! the P0 bounds of docs/theory/alignment.md §"Fine alignment", up to 30 mrad in heading, which
//! would flatten the converged part); values outside it leave the frame (cut at its edge).
//! Drawn by
//! [`crate::plot::Figure`] (legend above the panels, tick labels for their range).

use crate::error::CliError;
use crate::plot::{Band, Figure, Panel, Series};
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

const SIZE: (u32, u32) = (1500, 520);
const BIAS_SIZE: (u32, u32) = (1500, 900);

/// True biases when known (scenarios): accelerometer [μg] and gyro [°/h], body axes.
pub type TrueBias = ([f64; 3], [f64; 3]);

/// The x from which the y range is fitted: past the first 10 % of the record.
fn fit_from(rows: &[HistRow]) -> Option<f64> {
    let t0 = rows.first()?.t_s;
    let t1 = rows.last()?.t_s;
    Some(t0 + 0.1 * (t1 - t0))
}

fn attitude_panels(rows: &[HistRow]) -> Vec<Panel> {
    let truth = !rows.is_empty() && rows.iter().all(|r| r.phi_urad.is_some());
    let names = [
        ("φ_N", "north tilt"),
        ("φ_E", "east tilt"),
        ("φ_D", "heading"),
    ];
    names
        .iter()
        .enumerate()
        .map(|(i, (sym, what))| {
            let series = if truth {
                vec![Series::line(
                    *sym,
                    rows.iter()
                        .filter_map(|r| r.phi_urad.map(|p| (r.t_s, p[i])))
                        .collect(),
                )]
            } else {
                Vec::new()
            };
            Panel {
                title: if truth {
                    format!("{what} error {sym} (NED)")
                } else {
                    format!("{what} {sym}: ±3σ only (no truth)")
                },
                x_label: "time [s]".into(),
                y_label: format!("{sym} [μrad]"),
                y_fit_from_x: fit_from(rows),
                bands: vec![Band {
                    name: format!("{sym} ±3σ (shaded)"),
                    color_of: sym.to_string(),
                    points: rows
                        .iter()
                        .map(|r| (r.t_s, -3.0 * r.sig_phi_urad[i], 3.0 * r.sig_phi_urad[i]))
                        .collect(),
                    outline: false,
                }],
                series,
                ..Panel::default()
            }
        })
        .collect()
}

/// A bias state counts as unobservable in the record when its σ at the end is still at
/// least this share of its σ at the start (a stationary alignment cannot separate the
/// level accelerometer biases from tilt, nor the east gyro bias from heading, in
/// docs/theory/alignment.md §"Fine alignment").
pub const UNOBSERVABLE_SHARE: f64 = 0.9;

/// Whether axis `i` of the bias picked by `pick` is unobservable ([`UNOBSERVABLE_SHARE`]).
fn unobservable(rows: &[HistRow], pick: fn(&HistRow) -> ([f64; 3], [f64; 3]), i: usize) -> bool {
    let sigma = |r: &HistRow| Some(pick(r).1[i]).filter(|v| v.is_finite() && *v > 0.0);
    match (
        rows.iter().find_map(sigma),
        rows.iter().rev().find_map(sigma),
    ) {
        (Some(first), Some(last)) => last >= UNOBSERVABLE_SHARE * first,
        _ => false,
    }
}

/// Bias panels, two per sensor: the states the record observes, scaled to them, and the
/// unobservable ones (σ barely reduced, [`UNOBSERVABLE_SHARE`]) apart, so that their
/// wide bands neither hide the estimates nor blur with the others. Each estimate has its
/// own color; its ±3σ band takes that color, outlined, with its own legend entry.
fn bias_panels(rows: &[HistRow], truth: Option<TrueBias>) -> Vec<Panel> {
    type Pick = fn(&HistRow) -> ([f64; 3], [f64; 3]);
    type Spec<'a> = (&'a str, &'a str, &'a str, Pick, Option<[f64; 3]>);
    let specs: [Spec; 2] = [
        (
            "Accelerometer bias (body)",
            "accelerometer bias [μg]",
            "a",
            |r| (r.ba_ug, r.sig_ba_ug),
            truth.map(|t| t.0),
        ),
        (
            "Gyro bias (body)",
            "gyro bias [°/h]",
            "g",
            |r| (r.bg_dph, r.sig_bg_dph),
            truth.map(|t| t.1),
        ),
    ];
    let (t0, t1) = (
        rows.first().map_or(0.0, |r| r.t_s),
        rows.last().map_or(0.0, |r| r.t_s),
    );
    let share = format!("σ ≥ {:.0} % of its start", UNOBSERVABLE_SHARE * 100.0);
    let mut panels = Vec::new();
    for (title, y_desc, s, pick, tb) in specs {
        let hidden: Vec<bool> = (0..3).map(|i| unobservable(rows, pick, i)).collect();
        for group_unobservable in [false, true] {
            let axes: Vec<usize> = (0..3)
                .filter(|&i| hidden[i] == group_unobservable)
                .collect();
            let names: Vec<String> = axes
                .iter()
                .map(|&i| format!("b{s}_{}", ["x", "y", "z"][i]))
                .collect();
            let mut series = Vec::new();
            let mut bands = Vec::new();
            for (&i, name) in axes.iter().zip(&names) {
                series.push(Series::line(
                    name.clone(),
                    rows.iter().map(|r| (r.t_s, pick(r).0[i])).collect(),
                ));
                bands.push(Band {
                    name: format!("{name} ± 3σ"),
                    color_of: name.clone(),
                    points: rows
                        .iter()
                        .map(|r| {
                            let (b, sd) = pick(r);
                            (r.t_s, b[i] - 3.0 * sd[i], b[i] + 3.0 * sd[i])
                        })
                        .collect(),
                    outline: true,
                });
                if let Some(tb) = tb {
                    series.push(
                        Series::dashed(String::new(), vec![(t0, tb[i]), (t1, tb[i])])
                            .colored_as(name.clone()),
                    );
                }
            }
            if tb.is_some() && !axes.is_empty() {
                series.push(crate::plot::dashed_note("true bias"));
            }
            let (what, note) = match (group_unobservable, names.is_empty()) {
                (false, false) => (format!("observed: {}", names.join(", ")), String::new()),
                (true, false) => (
                    format!("unobservable here ({share}): {}", names.join(", ")),
                    String::new(),
                ),
                (false, true) => (
                    "observed".to_string(),
                    format!("none: every σ stays ≥ {:.0} %", UNOBSERVABLE_SHARE * 100.0),
                ),
                (true, true) => (
                    "unobservable here".to_string(),
                    format!(
                        "none: every σ fell below {:.0} % of its start",
                        UNOBSERVABLE_SHARE * 100.0
                    ),
                ),
            };
            panels.push(Panel {
                title: format!("{title}, {what}"),
                x_label: "time [s]".into(),
                y_label: y_desc.to_string(),
                y_fit_from_x: fit_from(rows),
                bands,
                series,
                note,
                ..Panel::default()
            });
        }
    }
    panels
}

fn figure(panels: Vec<Panel>) -> Figure {
    Figure {
        cols: panels.len().max(1),
        panels,
        size: SIZE,
    }
}

/// The bias figure: a 2 × 2 grid (accelerometer, gyro) × (observed, unobservable).
fn bias_figure(panels: Vec<Panel>) -> Figure {
    Figure {
        cols: 2,
        panels,
        size: BIAS_SIZE,
    }
}

#[cfg(test)]
fn svg(panels: &[Panel]) -> Result<String, CliError> {
    figure(panels.to_vec()).svg()
}

/// Write `align_attitude.svg/.png` and `align_bias.svg/.png` into `dir` and return the
/// two SVG documents (attitude, bias) for the report. Fewer than two rows (nothing to
/// draw) is a bad-input error. `truth`: the true biases, drawn dashed when known.
pub fn write_plots(
    dir: &Path,
    rows: &[HistRow],
    truth: Option<TrueBias>,
) -> Result<[String; 2], CliError> {
    if rows.len() < 2 {
        return Err(CliError::bad(format!(
            "alignment plots need at least two Kalman cycles, the history has {}",
            rows.len()
        )));
    }
    Ok([
        figure(attitude_panels(rows)).save(dir, "align_attitude")?,
        bias_figure(bias_panels(rows, truth)).save(dir, "align_bias")?,
    ])
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
    fn plots_have_labels_legends_bands_and_true_bias() {
        crate::plot::register_font().unwrap();
        let r = rows(true, 300);
        let s = svg(&attitude_panels(&r)).unwrap();
        assert!(
            s.contains("φ_N [μrad]") && s.contains("time [s]"),
            "axis labels"
        );
        assert!(s.contains("φ_D ±3σ (shaded)"), "legend");
        assert!(s.contains("<polygon"), "shaded ±3σ bands");
        let s = svg(&bias_panels(&r, None)).unwrap();
        assert!(s.contains("accelerometer bias [μg]") && s.contains("gyro bias [°/h]"));
        // each estimate's band has its own legend entry; the record's unobservable
        // states (σ not reduced: ba_x, ba_y, bg_x, bg_y here) have their own panels
        assert!(s.contains("ba_z ± 3σ") && s.contains("bg_x ± 3σ") && !s.contains("true bias"));
        assert!(s.contains("observed: ba_z") && s.contains("unobservable here"));
        assert!(s.contains("ba_x, ba_y") && s.contains("observed: bg_z"));
        let without = s.len();
        let s = svg(&bias_panels(
            &r,
            Some(([50.0, -80.0, 30.0], [0.01, -0.02, 0.015])),
        ))
        .unwrap();
        assert!(
            s.contains("true bias") && s.len() > without + 1000,
            "true bias drawn"
        );
        // no truth: bounds only; NaN and empty inputs do not panic
        let mut r = rows(false, 50);
        r[10].sig_phi_urad = [f64::NAN; 3];
        r[11].ba_ug = [f64::INFINITY; 3];
        let s = svg(&attitude_panels(&r)).unwrap();
        assert!(s.contains("no truth"));
        assert!(svg(&bias_panels(&r, None)).is_ok());
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
        assert_eq!(write_plots(&d, &r[..1], None).unwrap_err().exit_code(), 2);
        let _ = std::fs::remove_dir_all(&d);
    }
}
