//! `report.html` of `sdins fuse`: per-axis error with its ±3σ band (forward and
//! smoothed), the GNSS innovations and their NIS, GNSS outages shaded, and the RMSE table.
//! The numbers come from the library's events; this only collects and draws them.

use crate::error::CliError;
use crate::plot::{Band, Figure, Panel, Series};
use crate::report::Report;
use std::path::Path;

/// Keeps at most `MAX` points per series by doubling its stride when full (the plots
/// decimate further to the pixel columns; this bounds memory on long records).
#[derive(Clone, Debug, Default)]
pub struct Thin<T> {
    pub pts: Vec<T>,
    stride: usize,
    seen: usize,
}

const MAX: usize = 40_000;

impl<T> Thin<T> {
    pub fn new() -> Self {
        Self {
            pts: Vec::new(),
            stride: 1,
            seen: 0,
        }
    }
    pub fn push(&mut self, v: T) {
        if self.seen.is_multiple_of(self.stride) {
            self.pts.push(v);
            if self.pts.len() >= MAX {
                let mut i = 0;
                self.pts.retain(|_| {
                    i += 1;
                    (i - 1) % 2 == 0
                });
                self.stride *= 2;
            }
        }
        self.seen += 1;
    }
}

/// One row for the error plots: time, 9 errors (N, E, D [m]; v N, E, D [m/s]; attitude
/// three [deg]) and their σ.
pub type ErrRow = (f64, [f64; 9], [f64; 9]);

/// What the report shows.
pub struct FuseReportData<'a> {
    pub title: String,
    pub intro: String,
    /// attitude axis names (ε N/E/D for scenarios, roll/pitch/yaw for files)
    pub att_names: [&'a str; 3],
    pub forward: &'a Thin<ErrRow>,
    pub smoothed: Option<&'a Thin<ErrRow>>,
    /// (t, nis, dof, accepted) of GNSS updates
    pub gnss: &'a [(f64, f64, usize, bool)],
    /// expected fix interval [s] (gaps longer than 1.5 of it are outages)
    pub fix_interval_s: f64,
    /// RMSE rows (name, 9 values)
    pub rmse: Vec<(String, [f64; 9])>,
}

fn outages(gnss: &[(f64, f64, usize, bool)], interval: f64) -> Vec<(f64, f64)> {
    gnss.windows(2)
        .filter(|w| w[1].0 - w[0].0 > 1.5 * interval)
        .map(|w| (w[0].0, w[1].0))
        .collect()
}

/// Write `report.html` (and its figures as SVG/PNG) into `dir`.
pub fn write(dir: &Path, d: &FuseReportData<'_>) -> Result<(), CliError> {
    let mut r = Report::new(&d.title);
    r.para(&d.intro);
    let gaps = outages(d.gnss, d.fix_interval_s);
    let names = [
        "N [m]".to_string(),
        "E [m]".into(),
        "D [m]".into(),
        "v_N [m/s]".into(),
        "v_E [m/s]".into(),
        "v_D [m/s]".into(),
        format!("{} [deg]", d.att_names[0]),
        format!("{} [deg]", d.att_names[1]),
        format!("{} [deg]", d.att_names[2]),
    ];
    if !d.rmse.is_empty() {
        r.heading("RMSE against the reference");
        let mut header = vec!["solution"];
        header.extend(names.iter().map(String::as_str));
        let rows: Vec<Vec<String>> = d
            .rmse
            .iter()
            .map(|(n, v)| {
                let mut row = vec![n.clone()];
                row.extend(v.iter().map(|x| format!("{x:.4}")));
                row
            })
            .collect();
        r.table(&header, &rows);
    }
    if !gaps.is_empty() {
        let list: Vec<String> = gaps
            .iter()
            .map(|(a, b)| format!("{a:.1}–{b:.1} s"))
            .collect();
        r.para(&format!(
            "GNSS outages (gaps longer than 1.5 fix intervals), shaded grey in the plots: {}.",
            list.join(", ")
        ));
    }
    let t_fit = d.forward.pts.first().map(|p| p.0 + 30.0);
    for (stem, title, sol) in [
        ("fuse_forward", "Forward filter", Some(d.forward)),
        ("fuse_smoothed", "RTS smoother", d.smoothed),
    ] {
        let Some(sol) = sol else { continue };
        let mut panels = Vec::new();
        for (i, name) in names.iter().enumerate() {
            let err: Vec<(f64, f64)> = sol.pts.iter().map(|p| (p.0, p.1[i])).collect();
            let band: Vec<(f64, f64, f64)> = sol
                .pts
                .iter()
                .map(|p| (p.0, -3.0 * p.2[i], 3.0 * p.2[i]))
                .collect();
            let after = |t: f64| t_fit.is_none_or(|t0| t >= t0);
            let ymax = sol
                .pts
                .iter()
                .filter(|p| after(p.0))
                .map(|p| (3.0 * p.2[i]).max(p.1[i].abs()))
                .fold(0.0, f64::max);
            let mut bands = vec![Band {
                name: "±3σ".into(),
                color_of: "error".into(),
                points: band,
                outline: false,
            }];
            for (k, (a, b)) in gaps.iter().enumerate() {
                bands.push(Band {
                    name: if k == 0 {
                        "GNSS outage".into()
                    } else {
                        String::new()
                    },
                    color_of: crate::plot::STYLE_KEY.into(),
                    points: vec![(*a, -ymax, ymax), (*b, -ymax, ymax)],
                    outline: false,
                });
            }
            panels.push(Panel {
                title: format!("{title}: error {name}"),
                x_label: "t [s]".into(),
                y_label: name.clone(),
                y_fit_from_x: t_fit,
                bands,
                series: vec![Series::line("error", err)],
                ..Panel::default()
            });
        }
        let fig = Figure {
            panels,
            cols: 3,
            size: (1500, 1050),
        };
        r.heading(&format!("{title}: errors against the reference with ±3σ"));
        r.figure_file(
            &fig,
            dir,
            stem,
            &format!("{title}: error (estimate − reference) per axis, shaded ±3σ of the filter's covariance; the y range is fitted to t ≥ 30 s after the start, so the initial transient leaves the frame (cut at its edge, not flattened along it)"),
        )?;
    }
    // innovations: NIS per GNSS fix with its 99.9 % gate
    if !d.gnss.is_empty() {
        let acc: Vec<(f64, f64)> = d
            .gnss
            .iter()
            .filter(|g| g.3)
            .map(|g| (g.0, g.1.max(1e-6)))
            .collect();
        let rej: Vec<(f64, f64)> = d
            .gnss
            .iter()
            .filter(|g| !g.3)
            .map(|g| (g.0, g.1.max(1e-6)))
            .collect();
        let dof = d.gnss[0].2;
        let gate = sdins_core::aiding::ekf::CHI2_999[dof.clamp(1, 6) - 1];
        let t0 = d.gnss[0].0;
        let t1 = d.gnss[d.gnss.len() - 1].0;
        let mut series = vec![Series::points("NIS accepted", acc, Vec::new())];
        if !rej.is_empty() {
            series.push(Series::points("NIS rejected", rej, Vec::new()));
        }
        series.push(Series::dashed(
            format!("99.9 % gate ({dof} dof)"),
            vec![(t0, gate), (t1, gate)],
        ));
        series.push(Series::dashed(
            format!("mean {dof}"),
            vec![(t0, dof as f64), (t1, dof as f64)],
        ));
        let lo = d
            .gnss
            .iter()
            .map(|g| g.1)
            .fold(f64::INFINITY, f64::min)
            .max(1e-6)
            * 0.5;
        let hi = d.gnss.iter().map(|g| g.1).fold(gate, f64::max) * 2.0;
        let mut bands = Vec::new();
        for (k, (a, b)) in gaps.iter().enumerate() {
            bands.push(Band {
                name: if k == 0 {
                    "GNSS outage".into()
                } else {
                    String::new()
                },
                color_of: crate::plot::STYLE_KEY.into(),
                points: vec![(*a, lo, hi), (*b, lo, hi)],
                outline: false,
            });
        }
        let fig = Figure {
            panels: vec![Panel {
                title: "GNSS innovations: normalised innovation squared".into(),
                x_label: "t [s]".into(),
                y_label: "NIS".into(),
                log_y: true,
                bands,
                series,
                ..Panel::default()
            }],
            cols: 1,
            size: (1500, 450),
        };
        let n_rej = d.gnss.iter().filter(|g| !g.3).count();
        let mean = d.gnss.iter().map(|g| g.1).sum::<f64>() / d.gnss.len() as f64;
        r.heading("GNSS innovations");
        r.para(&format!(
            "{} fixes, {n_rej} rejected by the 99.9 % χ² gate; mean NIS {mean:.3} (expected {dof} for a consistent filter).",
            d.gnss.len()
        ));
        r.figure_file(
            &fig,
            dir,
            "fuse_nis",
            "NIS per GNSS fix (log scale), its 99.9 % gate and expected mean",
        )?;
    }
    r.write(&dir.join("report.html"))
}
