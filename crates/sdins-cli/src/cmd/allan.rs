//! `sdins allan`: overlapping Allan deviation of the six channels of an IMU file with
//! the IEEE Std 952 noise fits (see `sdins_sim::analysis::allan`).
//!
//! Outputs (in `--out`, default the current folder): `allan.csv` (τ and the six
//! deviations: gyro in °/h, accelerometer in μg), `allan.svg` and `allan.png`
//! (log-log plots; text drawn with the DejaVu Sans font embedded by the `dejavu`
//! crate). The fits are printed as a table in datasheet units, or as JSON with `--json`.
//!
//! Example: `sdins allan --imu lasergyro.imu --out allan_lasergyro`

use crate::args::ImuFormatArg;
use crate::error::CliError;
use crate::output::write_string;
use sdins_sim::analysis::allan::{AllanCurve, AllanFit};
use sdins_sim::io::imu_file::{read_imu_file, ImuFileError};
use sdins_sim::sensors::imu_error::{
    ARCSEC, DPH, DPHPSH, DPSH, MPS_PER_SQRT_H, UG, UG_PER_SQRT_H, UG_PER_SQRT_HZ,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `sdins allan`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Example: sdins allan --imu lasergyro.imu --imu-format psins --out allan_lasergyro"
)]
pub struct Args {
    /// IMU file (sdins CSV, PSINS .imu or trj CSV, KF-GINS text, NaveGo CSV)
    #[arg(long)]
    pub imu: PathBuf,
    #[command(flatten)]
    pub imu_format: ImuFormatArg,
    /// output folder for allan.csv, allan.svg and allan.png
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// print a JSON summary on stdout
    #[arg(long)]
    pub json: bool,
}

/// Channel names, in order.
pub const CHANNELS: [&str; 6] = [
    "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z",
];

pub use sdins_sim::analysis::allan::{analyse, AllanReport};

fn file_error(e: ImuFileError) -> CliError {
    match e {
        ImuFileError::Io { file, source } => CliError::Io { path: file, source },
        other => CliError::BadInput(other.to_string()),
    }
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let (data, input) =
        if args.imu_format.imu_columns.is_some() || args.imu_format.profile.is_some() {
            args.imu_format.read(&args.imu)?
        } else {
            (
                read_imu_file(&args.imu, args.imu_format.imu_format).map_err(file_error)?,
                None,
            )
        };
    let n = data.increments.len();
    if n < 20 {
        return Err(CliError::bad(format!(
            "{}: {n} samples, expected at least 20 for an Allan deviation",
            args.imu.display()
        )));
    }
    crate::output::claim(&args.out)?;
    let report = analyse(&data.increments, data.dt_s);
    write_string(&args.out.join("allan.csv"), &csv(&report)?)?;
    let svg = plot_svg(&report)?;
    write_string(&args.out.join("allan.svg"), &svg)?;
    plot_png(&report, &args.out.join("allan.png"))?;
    // the file's warnings (a cut last line dropped, …) and the result's (a moving record)
    let warnings: Vec<String> = data
        .warnings
        .iter()
        .cloned()
        .chain(report.warnings())
        .collect();
    for w in &warnings {
        eprintln!("warning: {}: {w}", args.imu.display());
    }
    let mut toml = toml::Table::new();
    toml.insert("imu".into(), args.imu.display().to_string().into());
    toml.insert("imu_format".into(), data.format.name().into());
    let list: Vec<toml::Value> = warnings.iter().map(|w| w.as_str().into()).collect();
    toml.insert("warnings".into(), list.into());
    crate::args::inputs_toml(&mut toml, input.as_ref());
    crate::report::write_run_toml(&args.out, toml)?;
    if args.json {
        outln!("{}", json(&report, &warnings));
    } else {
        outln!(
            "{}: format {}, {n} samples, dt {} s, {:.1} s",
            args.imu.display(),
            data.format,
            data.dt_s,
            n as f64 * data.dt_s
        );
        out!("{}", table(&report));
        outln!(
            "wrote {}/allan.csv, allan.svg, allan.png",
            args.out.display()
        );
    }
    Ok(())
}

fn opt(v: Option<f64>, unit: f64) -> Option<f64> {
    v.map(|x| x / unit)
}

fn cell(v: Option<f64>) -> String {
    v.map_or_else(|| "—".to_string(), |x| format!("{x:.4e}"))
}

fn range(r: Option<(f64, f64)>) -> String {
    r.map_or_else(|| "—".to_string(), |(a, b)| format!("{a:.3}–{b:.3}"))
}

fn row(s: &mut String, cells: &[String]) {
    let _ = write!(s, "{:<8}", cells[0]);
    for c in &cells[1..] {
        let _ = write!(s, " {c:>15}");
    }
    s.push('\n');
}

fn tau(t: Option<f64>) -> String {
    t.map_or_else(|| "—".to_string(), |t| format!("{t:.3}"))
}

/// The fit table in datasheet units (— where a term was not found).
pub fn table(r: &AllanReport) -> String {
    let mut s = String::new();
    let h = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    row(
        &mut s,
        &h(&[
            "gyro",
            "ARW °/√h",
            "BI °/h",
            "BI at τ s",
            "RRW °/h/√h",
            "Q arcsec",
            "white fit τ s",
            "RRW fit τ s",
        ]),
    );
    for (name, f) in CHANNELS[..3].iter().zip(&r.fits[..3]) {
        row(
            &mut s,
            &[
                name.to_string(),
                cell(opt(f.white, DPSH)),
                cell(opt(f.bias_instability, DPH)),
                tau(f.bias_instability_tau_s),
                cell(opt(f.rate_random_walk, DPHPSH)),
                cell(opt(f.quantization, ARCSEC)),
                range(f.white_tau_s),
                range(f.rrw_tau_s),
            ],
        );
    }
    row(
        &mut s,
        &h(&[
            "accel",
            "VRW m/s/√h",
            "VRW μg/√Hz",
            "BI μg",
            "BI at τ s",
            "RRW μg/√h",
            "Q m/s",
            "white fit τ s",
            "RRW fit τ s",
        ]),
    );
    for (name, f) in CHANNELS[3..].iter().zip(&r.fits[3..]) {
        row(
            &mut s,
            &[
                name.to_string(),
                cell(opt(f.white, MPS_PER_SQRT_H)),
                cell(opt(f.white, UG_PER_SQRT_HZ)),
                cell(opt(f.bias_instability, UG)),
                tau(f.bias_instability_tau_s),
                cell(opt(f.rate_random_walk, UG_PER_SQRT_H)),
                cell(f.quantization),
                range(f.white_tau_s),
                range(f.rrw_tau_s),
            ],
        );
    }
    s
}

/// The JSON summary (`null` where a term could not be fitted).
pub fn json(r: &AllanReport, warnings: &[String]) -> String {
    let ch: Vec<serde_json::Value> = (0..6)
        .map(|c| {
            let f = &r.fits[c];
            if c < 3 {
                serde_json::json!({
                    "name": CHANNELS[c],
                    "arw_dpsh": opt(f.white, DPSH),
                    "bias_instability_dph": opt(f.bias_instability, DPH),
                    "rrw_dphph": opt(f.rate_random_walk, DPHPSH),
                    "quantization_arcsec": opt(f.quantization, ARCSEC),
                })
            } else {
                serde_json::json!({
                    "name": CHANNELS[c],
                    "vrw_mpsph": opt(f.white, MPS_PER_SQRT_H),
                    "vrw_ugpsqrthz": opt(f.white, UG_PER_SQRT_HZ),
                    "bias_instability_ug": opt(f.bias_instability, UG),
                    "rrw_ugph": opt(f.rate_random_walk, UG_PER_SQRT_H),
                    "quantization_mps": f.quantization,
                })
            }
        })
        .collect();
    serde_json::json!({ "channels": ch, "warnings": warnings }).to_string()
}

/// `allan.csv`: τ and the six deviations (gyro °/h, accelerometer μg).
pub fn csv(r: &AllanReport) -> Result<String, CliError> {
    const HEADER: [&str; 7] = [
        "tau_s",
        "gyro_x_dph",
        "gyro_y_dph",
        "gyro_z_dph",
        "accel_x_ug",
        "accel_y_ug",
        "accel_z_ug",
    ];
    let n = r.curves.iter().map(|c| c.tau_s.len()).min().unwrap_or(0);
    let rows = (0..n).map(|i| {
        let mut rec = vec![r.curves[0].tau_s[i]];
        for (ch, c) in r.curves.iter().enumerate() {
            let unit = if ch < 3 { DPH } else { UG };
            rec.push(c.adev[i] / unit);
        }
        rec
    });
    crate::csv_out::table(&HEADER, rows)
}

const SIZE: (u32, u32) = (1400, 600);

/// Relative 1σ uncertainty of an Allan deviation estimated from `k` independent
/// clusters, `1/√(2(k − 1))` (IEEE Std 952-1997 Annex C, eq. C.2; El-Sheimy, Hou & Niu
/// 2008, eq. 9); `k = N/m` with `N = count + 2m − 1` samples and cluster size `m`.
pub fn relative_sigma(count: usize, m: f64) -> f64 {
    let n = count as f64 + 2.0 * m - 1.0;
    let k = n / m.max(1.0);
    if k > 1.0 {
        1.0 / (2.0 * (k - 1.0)).sqrt()
    } else {
        f64::INFINITY
    }
}

/// The fitted lines of one channel over their fit ranges (three times wider on both
/// sides, within the curve): white noise `σ = N/√τ`, bias instability
/// `σ = 0.664 B`, rate random walk `σ = K √(τ/3)`, quantization `σ = √3 Q/τ` (IEEE Std 952
/// Annex C, Table C.1), in display units.
fn fit_lines(c: &AllanCurve, f: &AllanFit, unit: f64) -> Vec<Vec<(f64, f64)>> {
    let (Some(&lo), Some(&hi)) = (c.tau_s.first(), c.tau_s.last()) else {
        return Vec::new();
    };
    let span = |r: (f64, f64)| ((r.0 / 3.0).max(lo), (r.1 * 3.0).min(hi));
    let line = |r: (f64, f64), g: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> {
        let (a, b) = span(r);
        (0..=20)
            .map(|i| {
                let t = a * (b / a).powf(i as f64 / 20.0);
                (t, g(t) / unit)
            })
            .collect()
    };
    let mut out = Vec::new();
    if let (Some(n), Some(r)) = (f.white, f.white_tau_s) {
        out.push(line(r, &|t| n / t.sqrt()));
    }
    if let (Some(b), Some(r)) = (f.bias_instability, f.bias_instability_range_s) {
        out.push(line(r, &|_| sdins_sim::analysis::allan::FLICKER_FLOOR * b));
    }
    if let (Some(k), Some(r)) = (f.rate_random_walk, f.rrw_tau_s) {
        out.push(line(r, &|t| k * (t / 3.0).sqrt()));
    }
    if let Some(q) = f.quantization {
        out.push(line((lo, (lo * 10.0).min(hi)), &|t| 3f64.sqrt() * q / t));
    }
    out
}

/// The log-log figure: per sensor panel the three channels' deviations with their 1σ
/// confidence bars ([`relative_sigma`]) and the fitted noise lines dashed.
pub fn figure(r: &AllanReport) -> crate::plot::Figure {
    use crate::plot::{Figure, Panel, Series};
    let panels = (0..2)
        .map(|p| {
            let (unit, y_label, title) = if p == 0 {
                (DPH, "Allan deviation [°/h]", "Gyroscopes")
            } else {
                (UG, "Allan deviation [μg]", "Accelerometers")
            };
            let mut series = Vec::new();
            #[allow(clippy::needless_range_loop)] // c indexes curves, fits and names alike
            for c in 3 * p..3 * p + 3 {
                let cv = &r.curves[c];
                let dt = cv.tau_s.first().copied().unwrap_or(1.0);
                let mut pts = Vec::new();
                let mut bars = Vec::new();
                for ((t, s), n) in cv.tau_s.iter().zip(&cv.adev).zip(&cv.count) {
                    if *s > 0.0 {
                        let rel = relative_sigma(*n, (t / dt).round());
                        let y = s / unit;
                        pts.push((*t, y));
                        bars.push((y * (1.0 - rel).max(0.05), y * (1.0 + rel)));
                    }
                }
                let name = CHANNELS[c].to_string();
                series.push(Series::points(name.clone(), pts, bars));
                if let Some(f) = r.fits.get(c) {
                    for l in fit_lines(cv, f, unit) {
                        series.push(Series::dashed(String::new(), l).colored_as(name.clone()));
                    }
                }
            }
            series.push(crate::plot::dashed_note("fitted noise terms"));
            Panel {
                title: title.into(),
                x_label: "cluster time τ [s]".into(),
                y_label: y_label.into(),
                log_x: true,
                log_y: true,
                series,
                ..Panel::default()
            }
        })
        .collect();
    Figure {
        panels,
        cols: 2,
        size: SIZE,
    }
}

/// The log-log plot as an SVG string.
pub fn plot_svg(r: &AllanReport) -> Result<String, CliError> {
    figure(r).svg()
}

/// The log-log plot as a PNG file (drawn to a temporary file, then renamed).
pub fn plot_png(r: &AllanReport, dest: &Path) -> Result<(), CliError> {
    figure(r).png(dest)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use sdins_sim::io::imu_file::ImuFormat;
    use sdins_sim::sensors::imu_error::{ImuErrorModel, ImuErrorState};

    #[test]
    fn end_to_end_on_a_simulated_file() {
        // 20 min at 100 Hz of a tactical-grade IMU at rest, written as an sdins CSV
        let m = ImuErrorModel::preset("tactical").unwrap();
        let mut s = ImuErrorState::new(&m, 3, 0).unwrap();
        let dt = 0.01;
        let mut text =
            String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
        let still = sdins_core::coning::Increment::new(
            sdins_core::Vec3::zeros(),
            sdins_core::Vec3::new(0.0, 0.0, -9.8 * dt),
        );
        for k in 0..120_000 {
            let o = s.apply(&still, dt);
            let _ = writeln!(
                text,
                "{},{},{},{},{},{},{}",
                (k + 1) as f64 * dt,
                o.dtheta_b_rad[0],
                o.dtheta_b_rad[1],
                o.dtheta_b_rad[2],
                o.dv_b_mps[0],
                o.dv_b_mps[1],
                o.dv_b_mps[2]
            );
        }
        let dir = std::env::temp_dir().join(format!("sdins-allan-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("imu.csv");
        std::fs::write(&file, text).unwrap();
        let out = dir.join("out");
        crate::output::finish(run(Args {
            imu: file.clone(),
            imu_format: crate::args::ImuFormatArg::auto(),
            out: out.clone(),
            json: true,
        }))
        .unwrap();
        for f in ["allan.csv", "allan.svg", "allan.png"] {
            assert!(std::fs::metadata(out.join(f)).unwrap().len() > 100, "{f}");
        }
        let svg = std::fs::read_to_string(out.join("allan.svg")).unwrap();
        assert!(
            svg.contains("Allan deviation [°/h]") && svg.contains("gyro_x"),
            "axis label and legend"
        );
        let data = read_imu_file(&file, ImuFormat::Auto).unwrap();
        let r = analyse(&data.increments, data.dt_s);
        // tactical preset: ARW 0.01 °/√h, VRW 100 μg/√Hz; 20 min of data → 10 %
        for ch in 0..3 {
            let arw = r.fits[ch].white.unwrap() / DPSH;
            assert!((arw / 0.01 - 1.0).abs() < 0.10, "{arw}");
            let vrw = r.fits[ch + 3].white.unwrap() / UG_PER_SQRT_HZ;
            assert!((vrw / 100.0 - 1.0).abs() < 0.10, "{vrw}");
        }
        let j: serde_json::Value = serde_json::from_str(&json(&r, &[])).unwrap();
        assert_eq!(j["channels"][0]["name"], "gyro_x");
        assert!(j["channels"][0]["arw_dpsh"].as_f64().is_some());
        // a bad file is BadInput (exit code 2) naming file and line
        std::fs::write(
            dir.join("bad.csv"),
            "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n0.01,1,2\n",
        )
        .unwrap();
        let e = crate::output::finish(run(Args {
            imu: dir.join("bad.csv"),
            imu_format: crate::args::ImuFormatArg::auto(),
            out: out.clone(),
            json: false,
        }))
        .unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("bad.csv:2"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    #[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
    fn lasergyro_runs_and_reports_fits() {
        // real navigation-grade RLG IMU, parked (shared data; skipped if absent)
        let p = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/data/psins/lasergyro.imu"
        ));
        if !p.exists() {
            outln!("skipped: {} not found", p.display());
            return;
        }
        let data = read_imu_file(p, ImuFormat::Auto).unwrap();
        assert_eq!(data.format, ImuFormat::Psins);
        assert_eq!(data.increments.len(), 184_718);
        assert!((data.dt_s - 0.01).abs() < 1e-15);
        let r = analyse(&data.increments, data.dt_s);
        outln!("{}", table(&r));
        outln!("{}", json(&r, &[]));
        // parked: the mean specific force is gravity (header g = 9.780327) along −z FRD
        let n = data.increments.len() as f64;
        let fz: f64 = data.increments.iter().map(|i| i.dv_b_mps[2]).sum::<f64>() / (n * data.dt_s);
        assert!((fz + 9.78).abs() < 0.05, "{fz}");
        assert_eq!(r.curves.len(), 6);
        assert!(r.curves.iter().all(|c| c.tau_s.len() > 40));
    }
}
