//! `sdins fuse --imu FILE --gnss FILE`: the filter (and smoother) on recorded data. The
//! work is `sdins_sim::fusion::files::fuse_files`; this parses, writes the CSVs, the report
//! and prints.

use super::fuse_args::Args;
use super::fuse_report::{ErrRow, FuseReportData, Thin};
use crate::csv_out::{innovation_row, nav_row, CsvOut, INNOVATION_HEADER, NAV_HEADER};
use crate::error::CliError;
use crate::output::AtomicFile;
use sdins_core::aiding::ekf::{MeasKind, CHI2_999};
use sdins_core::nav::AlgorithmSpec;
use sdins_sim::fusion::files::{
    fuse_files, FilesError, FilesInput, InitSource, InputColumns, SensorModelSource,
};
use sdins_sim::fusion::records::{RecordEvent, RecordOptions, RecordPoint, COMPARISON_AXES};
use sdins_sim::fusion::simulated::FuseError;
use sdins_sim::io::gnss_file::{GnssFormat, GnssReadOptions, ImuClock};
use sdins_sim::io::imu_file::ImuFormat;
use std::path::PathBuf;

fn triple(name: &str, s: &str) -> Result<[f64; 3], CliError> {
    let v: Vec<&str> = s.split(',').map(str::trim).collect();
    if v.len() != 3 {
        return Err(CliError::bad(format!(
            "{name}: expected three comma-separated numbers, got `{s}`"
        )));
    }
    let mut out = [0.0; 3];
    for (o, t) in out.iter_mut().zip(&v) {
        *o = t
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| CliError::bad(format!("{name}: `{t}` is not a finite number")))?;
    }
    Ok(out)
}

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
            p.sigma_nav[0],
            p.sigma_nav[1],
            p.sigma_nav[2],
            p.sigma_nav[3],
            p.sigma_nav[4],
            p.sigma_nav[5],
            d(p.sigma_euler_rad[0]),
            d(p.sigma_euler_rad[1]),
            d(p.sigma_euler_rad[2]),
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

/// Run `sdins fuse` on files.
pub fn run(args: Args, imu: PathBuf) -> Result<(), CliError> {
    let gnss = args
        .gnss
        .clone()
        .ok_or_else(|| CliError::bad("--imu needs --gnss FILE"))?;
    if args.in_motion {
        return Err(CliError::bad(
            "--in-motion applies to scenarios; on recorded data give --attitude-deg (the heading from the first fixes' track) or --init",
        ));
    }
    let imu_format: ImuFormat = args.imu_format.parse().map_err(CliError::bad)?;
    let (imu_columns, gnss_columns) = args.columns.resolve()?;
    if imu_columns.is_some() && args.imu_format != "auto" {
        return Err(CliError::bad(
            "--imu-format: the IMU file is read through a column map (--imu-columns or the profile): give one",
        ));
    }
    if gnss_columns.is_some() && args.gnss_format != "auto" {
        return Err(CliError::bad(
            "--gnss-format: the GNSS file is read through a column map (--gnss-columns or the profile): give one",
        ));
    }
    let gnss_format: GnssFormat = args.gnss_format.parse().map_err(CliError::bad)?;
    let samples = args.samples.unwrap_or(2);
    if !(1..=4).contains(&samples) {
        return Err(CliError::bad(format!(
            "--samples: must be 1..4, got {samples}"
        )));
    }
    let algo = AlgorithmSpec::from_name(&args.algo, samples)
        .ok_or_else(|| CliError::bad(format!("--algo: unknown algorithm `{}`", args.algo)))?;
    let sensor =
        SensorModelSource::from_options(args.grade.as_deref(), args.navego_params.as_deref())
            .map_err(CliError::bad)?;
    let attitude = match &args.attitude_deg {
        Some(a) => Some(triple("--attitude-deg", a)?),
        None => None,
    };
    let attitude_sigma = match &args.attitude_sigma_deg {
        Some(s) => Some(triple("--attitude-sigma-deg", s)?),
        None => None,
    };
    let init = InitSource::from_options(
        args.init.as_deref(),
        attitude,
        attitude_sigma,
        args.static_s,
        args.navego_params.is_some(),
    )
    .map_err(CliError::bad)?;
    let lever = match &args.lever_arm_m {
        Some(s) => triple("--lever-arm-m", s)?,
        None => [0.0; 3],
    };
    if !(args.gnss_offset_s.is_finite()) {
        return Err(CliError::bad("--gnss-offset-s: must be finite"));
    }
    let input = FilesInput {
        imu: (imu.clone(), imu_format),
        gnss: (gnss.clone(), gnss_format),
        gnss_options: GnssReadOptions::default(),
        clock: if args.gnss_offset_s == 0.0 {
            ImuClock::SameAsGnss
        } else {
            ImuClock::Offset {
                t_imu_minus_t_gnss_s: args.gnss_offset_s,
            }
        },
        sensor,
        init,
        truth: args.truth.clone(),
        check_after_s: 30.0,
        columns: InputColumns {
            imu: imu_columns,
            gnss: gnss_columns,
        },
    };
    let opts = RecordOptions {
        algo,
        cov_rate_hz: args.cov_rate_hz,
        gate_chi2: if args.no_gate { None } else { Some(CHI2_999) },
        lever_arm_b_m: lever,
        nhc_sigma_mps: args.nhc_sigma_mps,
        smooth: args.smooth,
        scale_factors: args
            .scale_factors_ppm
            .as_deref()
            .map(super::fuse_args::scale_factor_prior)
            .transpose()?,
        ..RecordOptions::default()
    };
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
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("sdins-out/fuse-{stem}")));
    // nav.csv and smoothed.csv get one row per navigation update (the IMU file's size
    // bounds it; checked before anything is written)
    let imu_bytes = std::fs::metadata(&imu).map_or(0.0, |m| m.len() as f64);
    crate::output::check_size(
        "nav.csv (and smoothed.csv)",
        imu_bytes / 40.0 / samples as f64 + 1.0,
        380.0,
        "split the IMU file or raise --samples",
    )?;
    crate::output::claim(&out)?;
    let mut nav = AtomicFile::create(&out.join("nav.csv"))?;
    let mut inn = AtomicFile::create(&out.join("innovations.csv"))?;
    let mut smo = if args.smooth {
        Some(AtomicFile::create(&out.join("smoothed.csv"))?)
    } else {
        None
    };
    let point_header = [NAV_HEADER.as_slice(), &SIGMA_HEADER].concat();
    let mut nav_csv = CsvOut::new(&mut nav, &point_header)?;
    let mut smo_csv = match smo.as_mut() {
        Some(f) => Some(CsvOut::new(f, &point_header)?),
        None => None,
    };
    let mut inn_csv = CsvOut::new(&mut inn, &INNOVATION_HEADER)?;
    let mut werr: Option<CliError> = None;
    let mut last_fwd: Option<RecordPoint> = None;
    let mut t_start = None;
    let mut fwd_rows = Thin::<ErrRow>::new();
    let mut smo_rows = Thin::<ErrRow>::new();
    let mut gnss_rows: Vec<(f64, f64, usize, bool)> = Vec::new();
    let res = fuse_files(&input, &opts, &crate::progress::token(), |ev, err| {
        if let Some(e) = err {
            match ev {
                RecordEvent::Forward(p) => fwd_rows.push(err_row(p, e)),
                RecordEvent::Smoothed(p) => smo_rows.push(err_row(p, e)),
                _ => {}
            }
        }
        let r = match ev {
            RecordEvent::Forward(p) => {
                t_start.get_or_insert(p.t_s);
                last_fwd = Some(*p);
                nav_csv.row(&point_row(p))
            }
            RecordEvent::Smoothed(p) => match smo_csv.as_mut() {
                Some(f) => f.row(&point_row(p)),
                None => Ok(()),
            },
            RecordEvent::Update(u) => {
                let t = t_start.unwrap_or(0.0) + u.t_s;
                if u.kind == MeasKind::Gnss {
                    gnss_rows.push((t, u.nis, u.dof, u.accepted));
                }
                inn_csv.row(&innovation_row(t, u))
            }
            _ => Ok(()),
        };
        if let Err(e) = r {
            werr.get_or_insert(e);
        }
    });
    if let Some(e) = werr {
        return Err(e);
    }
    let r = match res {
        Ok(r) => r,
        Err(FilesError::Fuse(FuseError::Cancelled(_))) => return Err(CliError::Interrupted),
        Err(e) => return Err(CliError::bad(e.to_string())),
    };
    nav_csv.finish()?;
    inn_csv.finish()?;
    smo_csv.map(CsvOut::finish).transpose()?;
    nav.commit()?;
    inn.commit()?;
    if let Some(f) = smo {
        f.commit()?;
    }
    let v3 = |v: &sdins_core::math::Vec3| [v.x, v.y, v.z];
    let cmp = |c: &Option<sdins_sim::fusion::records::TruthComparison>| {
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
    };
    let summary = serde_json::json!({
        "imu": imu.display().to_string(),
        "imu_format": r.imu_format.name(),
        "imu_samples": r.imu_samples,
        "imu_dt_s": r.imu_dt_s,
        "gnss": gnss.display().to_string(),
        "gnss_format": r.gnss_format.name(),
        "fixes_in_span": r.fixes_in_span,
        "fixes_before_imu": r.fixes_outside.0,
        "fixes_after_imu": r.fixes_outside.1,
        "fixes_used": r.summary.fixes_used,
        "rejected": r.summary.rejected,
        "algo": args.algo,
        "samples": samples,
        "nav_updates": r.summary.nav_updates,
        "t_start_s": r.summary.t_start_s,
        "accel_bias_est_mps2": v3(&r.summary.final_bias.0),
        "gyro_bias_est_rps": v3(&r.summary.final_bias.1),
        "accel_scale_est_ppm": v3(&(r.summary.final_scale.0 * 1e6)),
        "gyro_scale_est_ppm": v3(&(r.summary.final_scale.1 * 1e6)),
        "final": last_fwd.map(|p| serde_json::json!({
            "t_s": p.t_s, "lat_deg": p.state.lat_rad.to_degrees(), "lon_deg": p.state.lon_rad.to_degrees(), "h_m": p.state.h_m
        })),
        "forward_vs_truth": cmp(&r.forward),
        "smoothed_vs_truth": cmp(&r.smoothed),
        "units": "rmse: roll/pitch/yaw deg, v m/s, N/E/D m",
    });
    let mut fields = toml::Table::new();
    fields.insert("imu".into(), imu.display().to_string().into());
    fields.insert("gnss".into(), gnss.display().to_string().into());
    fields.insert("algo".into(), args.algo.clone().into());
    fields.insert("samples".into(), (samples as i64).into());
    fields.insert("cov_rate_hz".into(), args.cov_rate_hz.into());
    fields.insert("gate".into(), (!args.no_gate).into());
    fields.insert("smooth".into(), args.smooth.into());
    if !r.inputs.is_empty() {
        let mut t = toml::Table::new();
        for rep in &r.inputs {
            t.insert(rep.kind.to_string(), rep.to_toml().into());
        }
        fields.insert("inputs".into(), t.into());
    }
    let rm = |c: &Option<sdins_sim::fusion::records::TruthComparison>, name: &str| {
        c.as_ref().map(|c| {
            let v = c.rmse();
            (
                name.to_string(),
                [
                    v[6],
                    v[7],
                    v[8],
                    v[3],
                    v[4],
                    v[5],
                    v[0].to_degrees(),
                    v[1].to_degrees(),
                    v[2].to_degrees(),
                ],
            )
        })
    };
    let rmse: Vec<(String, [f64; 9])> = [rm(&r.forward, "forward"), rm(&r.smoothed, "smoothed")]
        .into_iter()
        .flatten()
        .collect();
    if !fwd_rows.pts.is_empty() || !gnss_rows.is_empty() {
        let fix_interval = gnss_rows
            .windows(2)
            .map(|w| w[1].0 - w[0].0)
            .fold(f64::INFINITY, f64::min);
        super::fuse_report::write(
            &out,
            &FuseReportData {
                title: format!("sdins fuse: {}", imu.display()),
                intro: format!(
                    "{} ({} samples at {} Hz) with {} ({} fixes used, {} rejected), algorithm {} N = {samples}, covariance at {} Hz{}.",
                    imu.display(),
                    r.imu_samples,
                    1.0 / r.imu_dt_s,
                    gnss.display(),
                    r.summary.fixes_used,
                    r.summary.rejected,
                    args.algo,
                    args.cov_rate_hz,
                    match &args.truth {
                        Some(t) => format!("; reference {}", t.display()),
                        None => "; no reference: the error plots are empty, give --truth".into(),
                    }
                ),
                att_names: ["roll", "pitch", "yaw"],
                forward: &fwd_rows,
                smoothed: args.smooth.then_some(&smo_rows),
                gnss: &gnss_rows,
                fix_interval_s: if fix_interval.is_finite() { fix_interval } else { 1.0 },
                rmse,
            },
        )?;
    }
    crate::report::write_run_toml(&out, fields)?;
    for rep in &r.inputs {
        eprintln!("{}", rep.summary());
    }
    for w in &r.imu_warnings {
        eprintln!("warning: {}: {w}", imu.display());
    }
    for w in &r.gnss_report.warnings {
        eprintln!("warning: {}: {w}", gnss.display());
    }
    if args.json {
        println!("{summary:#}");
    } else {
        println!(
            "sdins fuse {} + {}: {} IMU samples ({}), {} fixes used ({} outside the IMU record skipped), {} rejected; wrote {}",
            imu.display(),
            gnss.display(),
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
                println!(
                    "  {name} RMSE vs truth: roll/pitch/yaw {:.4}/{:.4}/{:.4} deg, v N/E/D {:.4}/{:.4}/{:.4} m/s, N/E/D {:.3}/{:.3}/{:.3} m",
                    rm[0].to_degrees(), rm[1].to_degrees(), rm[2].to_degrees(), rm[3], rm[4], rm[5], rm[6], rm[7], rm[8]
                );
            }
        }
    }
    Ok(())
}
