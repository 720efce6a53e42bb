//! `sdins fuse`: INS/GNSS filter on a scenario (truth → IMU errors → GNSS → filter →
//! errors with ±3σ). The work is `sdins_sim::fusion::simulated::fuse_scenario`; this only parses and
//! writes.

use super::fuse_args::scale_factor_prior;
pub use super::fuse_args::Args;
use super::fuse_report::{ErrRow, FuseReportData, Thin};
use crate::csv_out::{innovation_row, CsvOut, INNOVATION_HEADER};
use crate::error::CliError;
use crate::output::AtomicFile;
use sdins_core::aiding::ekf::{MeasKind, CHI2_999};
use sdins_core::aiding::error_model::{I_ATT, I_POS, I_VEL};
use sdins_core::nav::AlgorithmSpec;
use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::simulated::{fuse_scenario, FuseError, FuseEvent, FuseOptions};
use sdins_sim::scenario::Scenario;

const ERR_HEADER: [&str; 19] = [
    "t_s",
    "err_n_m",
    "err_e_m",
    "err_d_m",
    "sigma_n_m",
    "sigma_e_m",
    "sigma_d_m",
    "err_vn_mps",
    "err_ve_mps",
    "err_vd_mps",
    "sigma_vn_mps",
    "sigma_ve_mps",
    "sigma_vd_mps",
    "err_att_n_rad",
    "err_att_e_rad",
    "err_att_d_rad",
    "sigma_att_n_rad",
    "sigma_att_e_rad",
    "sigma_att_d_rad",
];

/// One row of nav.csv / smoothed.csv: errors against the truth with σ.
fn epoch_row(e: &sdins_sim::fusion::simulated::FuseEpoch) -> [f64; 19] {
    let mut row = [0.0; 19];
    row[0] = e.t_s;
    for (b, (i0, vals)) in [
        (I_POS, e.nav.pos_err_ned_m),
        (I_VEL, e.nav.vel_err_ned_mps),
        (I_ATT, e.nav.att_err_rad),
    ]
    .into_iter()
    .enumerate()
    {
        for i in 0..3 {
            row[1 + 6 * b + i] = vals[i];
            row[4 + 6 * b + i] = e.sigma(i0 + i);
        }
    }
    row
}

fn err_row(e: &sdins_sim::fusion::simulated::FuseEpoch) -> ErrRow {
    let mut v = [0.0; 9];
    let mut sg = [0.0; 9];
    for i in 0..3 {
        v[i] = e.nav.pos_err_ned_m[i];
        v[3 + i] = e.nav.vel_err_ned_mps[i];
        v[6 + i] = e.nav.att_err_rad[i].to_degrees();
        sg[i] = e.sigma(I_POS + i);
        sg[3 + i] = e.sigma(I_VEL + i);
        sg[6 + i] = e.sigma(I_ATT + i).to_degrees();
    }
    (e.t_s, v, sg)
}

fn check_sigma(name: &str, v: Option<f64>) -> Result<(), CliError> {
    match v {
        Some(x) if !(x.is_finite() && x > 0.0) => Err(CliError::bad(format!(
            "{name}: must be finite and > 0, got {x}"
        ))),
        _ => Ok(()),
    }
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if let Some(imu) = args.imu.clone() {
        return super::fuse_files::run(args, imu);
    }
    let Some(name) = args.scenario.as_deref() else {
        return Err(CliError::bad("give a scenario, or --imu FILE --gnss FILE"));
    };
    for (flag, given) in [
        ("--grade", args.grade.is_some()),
        ("--navego-params", args.navego_params.is_some()),
        ("--init", args.init.is_some()),
        ("--attitude-deg", args.attitude_deg.is_some()),
        ("--static-s", args.static_s.is_some()),
        ("--truth", args.truth.is_some()),
        ("--lever-arm-m", args.lever_arm_m.is_some()),
    ] {
        if given {
            return Err(CliError::bad(format!(
                "{flag} applies to recorded data (--imu/--gnss); a scenario sets it in its [imu]/[gnss] tables"
            )));
        }
    }
    let scn = Scenario::load(name)?;
    let samples = args.samples.unwrap_or(scn.nav.samples);
    if !(1..=4).contains(&samples) {
        return Err(CliError::bad(format!(
            "--samples: must be 1..4, got {samples}"
        )));
    }
    let algo = AlgorithmSpec::from_name(&args.algo, samples)
        .ok_or_else(|| CliError::bad(format!("--algo: unknown algorithm `{}`", args.algo)))?;
    if !(args.cov_rate_hz.is_finite() && args.cov_rate_hz > 0.0) {
        return Err(CliError::bad(format!(
            "--cov-rate-hz: must be finite and > 0, got {}",
            args.cov_rate_hz
        )));
    }
    check_sigma("--zupt-sigma-mps", args.zupt_sigma_mps)?;
    check_sigma("--nhc-sigma-mps", args.nhc_sigma_mps)?;
    let scale_factors = args
        .scale_factors_ppm
        .as_deref()
        .map(scale_factor_prior)
        .transpose()?;
    let gnss = scn.gnss.clone().unwrap_or_default();
    let opts = FuseOptions {
        algo,
        cov_rate_hz: args.cov_rate_hz,
        draw_initial_errors: !args.exact_start,
        gate_chi2: if args.no_gate { None } else { Some(CHI2_999) },
        zupt: args.zupt_sigma_mps.map(|s| (s, 1e-3)),
        nhc_sigma_mps: args.nhc_sigma_mps,
        smooth: args.smooth,
        in_motion: args
            .in_motion
            .then(sdins_sim::fusion::simulated::InMotionInit::default),
        scale_factors,
        ..FuseOptions::default()
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| crate::output::default_dir("fuse-", &scn.name));
    crate::output::check_size(
        "nav.csv (and smoothed.csv)",
        scn.duration_s() * args.cov_rate_hz + 2.0,
        380.0,
        "lower --cov-rate-hz or shorten the scenario",
    )?;
    crate::output::claim(&out)?;
    let mut nav = AtomicFile::create(&out.join("nav.csv"))?;
    let mut inn = AtomicFile::create(&out.join("innovations.csv"))?;
    let mut smo = if args.smooth {
        Some(AtomicFile::create(&out.join("smoothed.csv"))?)
    } else {
        None
    };
    let mut smo_csv = match smo.as_mut() {
        Some(f) => Some(CsvOut::new(f, &ERR_HEADER)?),
        None => None,
    };
    let mut nav_csv = CsvOut::new(&mut nav, &ERR_HEADER)?;
    let mut inn_csv = CsvOut::new(&mut inn, &INNOVATION_HEADER)?;
    let mut werr: Option<CliError> = None;
    let mut sq = [0.0_f64; 9];
    let mut n_ep = 0.0_f64;
    let cancel = CancelToken::new();
    let mut fwd_rows = Thin::<ErrRow>::new();
    let mut smo_rows = Thin::<ErrRow>::new();
    let mut gnss_rows: Vec<(f64, f64, usize, bool)> = Vec::new();
    let res = fuse_scenario(&scn, &gnss, &opts, args.run, &cancel, |ev| {
        match ev {
            FuseEvent::Epoch(e) => fwd_rows.push(err_row(e)),
            FuseEvent::Smoothed(e) => smo_rows.push(err_row(e)),
            FuseEvent::Update(u) if u.kind == MeasKind::Gnss => {
                gnss_rows.push((u.t_s, u.nis, u.dof, u.accepted))
            }
            _ => {}
        }
        let r = match ev {
            FuseEvent::Epoch(e) => {
                let line = epoch_row(e);
                for (i0, vals) in [
                    (I_POS, e.nav.pos_err_ned_m),
                    (I_VEL, e.nav.vel_err_ned_mps),
                    (I_ATT, e.nav.att_err_rad),
                ] {
                    for i in 0..3 {
                        sq[i0 + i] += vals[i] * vals[i];
                    }
                }
                n_ep += 1.0;
                nav_csv.row(&line)
            }
            FuseEvent::Smoothed(e) => match smo_csv.as_mut() {
                Some(f) => f.row(&epoch_row(e)),
                None => Ok(()),
            },
            FuseEvent::Update(u) => inn_csv.row(&innovation_row(u.t_s, u)),
            _ => Ok(()),
        };
        if let Err(e) = r {
            werr.get_or_insert(e);
        }
    });
    if let Some(e) = werr {
        return Err(e);
    }
    let s = match res {
        Ok(s) => s,
        Err(FuseError::Cancelled(_)) => return Err(CliError::Interrupted),
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
    let rms: Vec<f64> = sq.iter().map(|x| (x / n_ep.max(1.0)).sqrt()).collect();
    let rms_of = |rows: &Thin<ErrRow>| {
        let n = rows.pts.len().max(1) as f64;
        let mut v = [0.0; 9];
        for (i, x) in v.iter_mut().enumerate() {
            *x = (rows.pts.iter().map(|p| p.1[i] * p.1[i]).sum::<f64>() / n).sqrt();
        }
        v
    };
    let mut rmse = vec![("forward".to_string(), {
        let mut v = [0.0; 9];
        for (i, x) in v.iter_mut().enumerate() {
            *x = if i < 6 { rms[i] } else { rms[i].to_degrees() };
        }
        v
    })];
    if args.smooth {
        rmse.push(("smoothed (plotted epochs)".to_string(), rms_of(&smo_rows)));
    }
    super::fuse_report::write(
        &out,
        &FuseReportData {
            title: format!("sdins fuse: {}", scn.name),
            intro: format!(
                "Scenario {} run {}: {} GNSS fixes ({} rejected), algorithm {} N = {samples}, covariance at {} Hz; errors against the exact truth.",
                scn.name, args.run, s.fixes, s.rejected, args.algo, args.cov_rate_hz
            ),
            att_names: ["ε_N", "ε_E", "ε_D"],
            forward: &fwd_rows,
            smoothed: args.smooth.then_some(&smo_rows),
            gnss: &gnss_rows,
            fix_interval_s: 1.0 / gnss.rate_hz,
            rmse,
        },
    )?;
    let v3 = |v: &sdins_core::math::Vec3| [v.x, v.y, v.z];
    let summary = serde_json::json!({
        "scenario": scn.name,
        "algo": args.algo,
        "samples": samples,
        "run": args.run,
        "fixes": s.fixes,
        "rejected": s.rejected,
        "rms_pos_ned_m": &rms[0..3],
        "rms_vel_ned_mps": &rms[3..6],
        "rms_att_ned_rad": &rms[6..9],
        "accel_bias_est_mps2": v3(&s.est_bias.0),
        "accel_bias_true_mps2": v3(&s.true_bias.0),
        "gyro_bias_est_rps": v3(&s.est_bias.1),
        "gyro_bias_true_rps": v3(&s.true_bias.1),
    });
    let mut summary = summary;
    if let Some((ta, tg)) = s.true_scale {
        let ppm = |v: &sdins_core::math::Vec3| [v.x * 1e6, v.y * 1e6, v.z * 1e6];
        summary["accel_scale_est_ppm"] = ppm(&s.est_scale.0).into();
        summary["accel_scale_true_ppm"] = ppm(&ta).into();
        summary["gyro_scale_est_ppm"] = ppm(&s.est_scale.1).into();
        summary["gyro_scale_true_ppm"] = ppm(&tg).into();
    }
    let mut fields = toml::Table::new();
    fields.insert("scenario".into(), scn.name.clone().into());
    fields.insert("algo".into(), args.algo.clone().into());
    fields.insert("samples".into(), (samples as i64).into());
    fields.insert("run".into(), (args.run as i64).into());
    fields.insert("cov_rate_hz".into(), args.cov_rate_hz.into());
    fields.insert("gate".into(), (!args.no_gate).into());
    if let Some(sp) = &scale_factors {
        fields.insert(
            "scale_factor_prior_accel_ppm".into(),
            sp.accel_ppm[0].into(),
        );
        fields.insert("scale_factor_prior_gyro_ppm".into(), sp.gyro_ppm[0].into());
    }
    crate::report::write_run_toml(&out, fields)?;
    if args.json {
        outln!("{summary:#}");
    } else {
        outln!(
            "sdins fuse {}: {} fixes, {} rejected; RMS position N/E/D {:.3}/{:.3}/{:.3} m, velocity {:.4}/{:.4}/{:.4} m/s; wrote {}",
            scn.name, s.fixes, s.rejected, rms[0], rms[1], rms[2], rms[3], rms[4], rms[5],
            out.display()
        );
    }
    Ok(())
}
