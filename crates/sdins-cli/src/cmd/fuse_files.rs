//! `sdins fuse --imu FILE --gnss FILE`: the filter (and smoother) on recorded data. The
//! work is the library call `sdins_sim::fusion::request::fuse`; this writes the CSVs,
//! the report and prints.

use super::fuse_args::{run_err, Args};
use super::fuse_out::{rmse_rows, with_tables, Plotted};
use super::fuse_report::{ErrRow, FuseReportData};
use crate::csv_out::{nav_row, NAV_HEADER};
use crate::error::CliError;
use sdins_sim::fusion::files::FilesResult;
use sdins_sim::fusion::records::{RecordPoint, TruthComparison, COMPARISON_AXES};
use sdins_sim::fusion::request::{
    fuse, FilesData, FuseData, FuseDetails, FuseOutcome, FuseOutput, FuseRequest, FuseRow,
};
use std::path::{Path, PathBuf};

fn point_row(p: &RecordPoint) -> [f64; 19] {
    let mut row = [0.0; 19];
    row[..10].copy_from_slice(&nav_row(p.t_s, &p.state));
    row[10..16].copy_from_slice(&p.sigma_nav[0..6]);
    for (r, v) in row[16..].iter_mut().zip(&p.sigma_euler_rad) {
        *r = v.to_degrees();
    }
    row
}

fn err_row(p: &RecordPoint, e: &[f64; 9]) -> ErrRow {
    let d = f64::to_degrees;
    let s = &p.sigma_nav;
    let se = &p.sigma_euler_rad;
    (
        p.t_s,
        [
            e[6],
            e[7],
            e[8],
            e[3],
            e[4],
            e[5],
            d(e[0]),
            d(e[1]),
            d(e[2]),
        ],
        [
            s[0],
            s[1],
            s[2],
            s[3],
            s[4],
            s[5],
            d(se[0]),
            d(se[1]),
            d(se[2]),
        ],
    )
}

/// The σ columns that nav.csv / smoothed.csv on recorded data add to
/// [`crate::csv_out::NAV_HEADER`].
const SIGMA_HEADER: [&str; 9] = [
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
    "sigma_vn_mps",
    "sigma_ve_mps",
    "sigma_vd_mps",
    "sigma_roll_deg",
    "sigma_pitch_deg",
    "sigma_yaw_deg",
];

/// The default output folder: `sdins-out/fuse-<IMU file stem>`.
fn default_out(imu: &Path) -> PathBuf {
    let stem = imu
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "imu".into());
    let stem: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    PathBuf::from(format!("sdins-out/fuse-{stem}"))
}

/// Run `sdins fuse` on files.
pub fn run(args: &Args, req: &FuseRequest) -> Result<(), CliError> {
    let FuseData::Files(d) = &req.data else {
        return Err(CliError::bad("give --imu FILE --gnss FILE"));
    };
    let out = args.out.clone().unwrap_or_else(|| default_out(&d.imu.0));
    // nav.csv and smoothed.csv get one row per navigation update (the IMU file's size
    // bounds it; checked before anything is written)
    let imu_bytes = std::fs::metadata(&d.imu.0).map_or(0.0, |m| m.len() as f64);
    let samples = req.samples.unwrap_or(2) as f64;
    crate::output::check_size(
        "nav.csv (and smoothed.csv)",
        imu_bytes / 40.0 / samples + 1.0,
        380.0,
        "split the IMU file or raise --samples",
    )?;
    crate::output::claim(&out)?;
    let mut plot = Plotted::default();
    let mut last: Option<RecordPoint> = None;
    let header = [NAV_HEADER.as_slice(), &SIGMA_HEADER].concat();
    let cancel = crate::progress::token();
    let o = with_tables(&out, req.smooth, &header, |t| {
        fuse(req, &cancel, &mut |ev| match ev {
            FuseOutput::Forward(FuseRow::Files(p, err)) => {
                if let Some(e) = err {
                    plot.forward.push(err_row(p, e));
                }
                last = Some(*p);
                t.nav(&point_row(p));
            }
            FuseOutput::Smoothed(FuseRow::Files(p, err)) => {
                if let Some(e) = err {
                    plot.smoothed.push(err_row(p, e));
                }
                t.smoothed(&point_row(p));
            }
            FuseOutput::Update(u) => {
                plot.update(u);
                t.update(u);
            }
            _ => {}
        })
        .map_err(run_err)
    })?;
    let FuseDetails::Files(r) = &o.details else {
        return Err(CliError::Other(
            "fuse on files returned no file result".into(),
        ));
    };
    if !plot.forward.pts.is_empty() || !plot.gnss.is_empty() {
        report(&out, args, d, &o, r, &plot)?;
    }
    let mut toml = run_toml(args, d, r);
    super::fuse_args::health_toml(&mut toml, &o.health);
    super::fuse_args::measurements_toml(&mut toml, &o.measurements);
    crate::report::write_run_toml(&out, toml)?;
    for rep in &r.inputs {
        eprintln!("{}", rep.summary());
    }
    for w in &r.imu_warnings {
        eprintln!("warning: {}: {w}", d.imu.0.display());
    }
    for w in &r.gnss_report.warnings {
        eprintln!("warning: {}: {w}", d.gnss.0.display());
    }
    if args.json {
        let mut s = summary(args, d, &o, r, last.as_ref());
        s["health"] = super::fuse_args::health_json(&o.health);
        s["measurements"] = super::fuse_args::measurements_json(&o.measurements);
        outln!("{s:#}");
    } else {
        print(
            d,
            r,
            &out,
            &super::fuse_args::measurements_text(&o.measurements),
        );
    }
    super::fuse_args::health_end(args, &o.health, &out)
}

fn report(
    out: &Path,
    args: &Args,
    d: &FilesData,
    o: &FuseOutcome,
    r: &FilesResult,
    plot: &Plotted,
) -> Result<(), CliError> {
    // the comparison gives roll, pitch, yaw, v, N, E, D; the report N, E, D, v, attitude
    let order = |v: [f64; 9]| [v[6], v[7], v[8], v[3], v[4], v[5], v[0], v[1], v[2]];
    super::fuse_report::write(
        out,
        &FuseReportData {
            title: format!("sdins fuse: {}", d.imu.0.display()),
            intro: format!(
                "{} ({} samples at {} Hz) with {} ({} fixes used, {} rejected, {} late), algorithm {} N = {}, covariance at {} Hz{}.",
                d.imu.0.display(),
                r.imu_samples,
                1.0 / r.imu_dt_s,
                d.gnss.0.display(),
                o.fixes,
                o.rejected,
                o.late,
                args.algo,
                o.algo.samples,
                args.cov_rate_hz,
                match &d.truth {
                    Some(t) => format!("; reference {}", t.display()),
                    None => "; no reference: the error plots are empty, give --truth".into(),
                }
            ),
            att_names: ["roll", "pitch", "yaw"],
            forward: &plot.forward,
            smoothed: args.smooth.then_some(&plot.smoothed),
            gnss: &plot.gnss,
            fix_interval_s: plot.fix_interval_s(),
            rmse: rmse_rows(
                &[
                    ("forward", o.rms_forward.map(order)),
                    ("smoothed", o.rms_smoothed.map(order)),
                ],
                6,
            ),
        },
    )
}

fn cmp_json(c: &Option<TruthComparison>) -> Option<serde_json::Value> {
    c.as_ref().map(|c| {
        let rmse = c.rmse();
        let inside = c.inside_3sigma();
        let mut m = serde_json::Map::new();
        for (i, name) in COMPARISON_AXES.iter().enumerate() {
            let v = if i < 3 { rmse[i].to_degrees() } else { rmse[i] };
            m.insert(
                (*name).to_string(),
                serde_json::json!({"rmse": v, "inside_3sigma": inside[i]}),
            );
        }
        m.insert("matched_epochs".into(), c.matched().into());
        serde_json::Value::Object(m)
    })
}

fn summary(
    args: &Args,
    d: &FilesData,
    o: &FuseOutcome,
    r: &FilesResult,
    last: Option<&RecordPoint>,
) -> serde_json::Value {
    let v3 = |v: &sdins_core::math::Vec3| [v.x, v.y, v.z];
    serde_json::json!({
        "imu": d.imu.0.display().to_string(),
        "imu_format": r.imu_format.name(),
        "imu_samples": r.imu_samples,
        "imu_dt_s": r.imu_dt_s,
        "gnss": d.gnss.0.display().to_string(),
        "gnss_format": r.gnss_format.name(),
        "fixes_in_span": r.fixes_in_span,
        "fixes_before_imu": r.fixes_outside.0,
        "fixes_after_imu": r.fixes_outside.1,
        "fixes_used": o.fixes,
        "rejected": o.rejected,
        "late": o.late,
        "algo": args.algo,
        "samples": o.algo.samples,
        "grade": args.grade,
        "sensor_model": d.sensor_model.as_ref().map(|p| p.display().to_string()),
        "states": o.layout.n(),
        "nav_updates": o.nav_updates,
        "t_start_s": r.summary.t_start_s,
        "accel_bias_est_mps2": v3(&o.bias_est.0),
        "gyro_bias_est_rps": v3(&o.bias_est.1),
        "accel_scale_est_ppm": v3(&(o.scale_est.0 * 1e6)),
        "gyro_scale_est_ppm": v3(&(o.scale_est.1 * 1e6)),
        "final": last.map(|p| serde_json::json!({
            "t_s": p.t_s, "lat_deg": p.state.lat_rad.to_degrees(), "lon_deg": p.state.lon_rad.to_degrees(), "h_m": p.state.h_m
        })),
        "forward_vs_truth": cmp_json(&r.forward),
        "smoothed_vs_truth": cmp_json(&r.smoothed),
        "inputs": r.inputs.iter().map(|rep| (rep.kind.to_string(), serde_json::Value::String(rep.summary()))).collect::<serde_json::Map<_, _>>(),
        "units": "rmse: roll/pitch/yaw deg, v m/s, N/E/D m",
    })
}

fn run_toml(args: &Args, d: &FilesData, r: &FilesResult) -> toml::Table {
    let mut f = toml::Table::new();
    f.insert("imu".into(), d.imu.0.display().to_string().into());
    f.insert("gnss".into(), d.gnss.0.display().to_string().into());
    f.insert("algo".into(), args.algo.clone().into());
    f.insert("samples".into(), (args.samples.unwrap_or(2) as i64).into());
    f.insert("cov_rate_hz".into(), args.cov_rate_hz.into());
    f.insert("gate".into(), (!args.no_gate).into());
    f.insert("smooth".into(), args.smooth.into());
    if let Some(g) = &args.grade {
        f.insert("grade".into(), g.clone().into());
    }
    if let Some(p) = &d.navego_params {
        f.insert("navego_params".into(), p.display().to_string().into());
    }
    if let Some(m) = &r.sensor_model {
        // the model the filter used, in SI units (docs/own-data.md "Your sensor model")
        f.insert("sensor_model".into(), m.to_toml().into());
    }
    if let Some(e) = args.every_s {
        f.insert("every_s".into(), e.into());
    }
    if !r.inputs.is_empty() {
        // the column maps' time bases, clock origin and offsets (docs/own-data.md)
        let mut t = toml::Table::new();
        for rep in &r.inputs {
            t.insert(rep.kind.to_string(), rep.to_toml().into());
        }
        f.insert("inputs".into(), t.into());
    }
    f
}

fn print(d: &FilesData, r: &FilesResult, out: &Path, other: &str) {
    outln!(
        "sdins fuse {} + {}: {} IMU samples ({}), {} fixes used ({} outside the IMU record skipped), {} rejected{other}; wrote {}",
        d.imu.0.display(),
        d.gnss.0.display(),
        r.imu_samples,
        r.imu_format.name(),
        r.summary.fixes_used,
        r.fixes_outside.0 + r.fixes_outside.1,
        r.summary.rejected,
        out.display()
    );
    for (name, c) in [("forward", &r.forward), ("smoothed", &r.smoothed)] {
        if let Some(c) = c {
            let rm = c.rmse();
            outln!(
                "  {name} RMSE vs truth: roll/pitch/yaw {:.4}/{:.4}/{:.4} deg, v N/E/D {:.4}/{:.4}/{:.4} m/s, N/E/D {:.3}/{:.3}/{:.3} m",
                rm[0].to_degrees(), rm[1].to_degrees(), rm[2].to_degrees(), rm[3], rm[4], rm[5], rm[6], rm[7], rm[8]
            );
        }
    }
}
