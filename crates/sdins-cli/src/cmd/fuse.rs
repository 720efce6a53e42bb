//! `sdins fuse`: the INS/GNSS filter on a scenario (truth → IMU errors → GNSS → filter →
//! errors with ±3σ), on recorded files (`cmd/fuse_files.rs`), or as a Monte Carlo
//! (`cmd/fuse_mc.rs`). The work is one library call,
//! `sdins_sim::fusion::request::fuse`; this parses the request, writes its rows and
//! renders the result.

use super::fuse_args::{request, run_err};
pub use super::fuse_args::{scale_factor_prior, Args};
use super::fuse_out::{rmse_rows, with_tables, Plotted};
use super::fuse_report::{ErrRow, FuseReportData};
use crate::error::CliError;
use sdins_core::aiding::error_model::{I_ATT, I_POS, I_VEL};
use sdins_sim::fusion::request::{
    fuse, FuseData, FuseDetails, FuseOutcome, FuseOutput, FuseRequest, FuseRow,
};
use sdins_sim::fusion::simulated::{layout_names, FuseEpoch};
use std::path::Path;

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
fn epoch_row(e: &FuseEpoch) -> [f64; 19] {
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

fn err_row(e: &FuseEpoch) -> ErrRow {
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

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if !args.merge.is_empty() {
        return super::fuse_mc::merge(&args);
    }
    let req = request(&args)?;
    if args.runs.is_some() {
        return super::fuse_mc::run(&args, &req);
    }
    let FuseData::Scenario(d) = &req.data else {
        return super::fuse_files::run(&args, &req);
    };
    let name = d.scenario.name.clone();
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| crate::output::default_dir("fuse-", &name));
    let every = req.every_s.unwrap_or(1.0 / req.cov_rate_hz);
    crate::output::check_size(
        "nav.csv (and smoothed.csv)",
        d.scenario.duration_s() / every + 2.0,
        380.0,
        "raise --every-s or shorten the scenario",
    )?;
    crate::output::claim(&out)?;
    let mut plot = Plotted::default();
    let cancel = crate::progress::token();
    let outcome = with_tables(&out, req.smooth, &ERR_HEADER, |t| {
        fuse(&req, &cancel, &mut |ev| match ev {
            FuseOutput::Forward(FuseRow::Scenario(e)) => {
                plot.forward.push(err_row(e));
                t.nav(&epoch_row(e));
            }
            FuseOutput::Smoothed(FuseRow::Scenario(e)) => {
                plot.smoothed.push(err_row(e));
                t.smoothed(&epoch_row(e));
            }
            FuseOutput::Update(u) => {
                plot.update(u);
                t.update(u);
            }
            _ => {}
        })
        .map_err(run_err)
    })?;
    report(&out, &args, &req, &outcome, &plot)?;
    let mut toml = run_toml(&args, &outcome);
    super::fuse_args::health_toml(&mut toml, &outcome.health);
    super::fuse_args::measurements_toml(&mut toml, &outcome.measurements);
    crate::report::write_run_toml(&out, toml)?;
    let mut s = summary(&args, &outcome);
    s["health"] = super::fuse_args::health_json(&outcome.health);
    s["measurements"] = super::fuse_args::measurements_json(&outcome.measurements);
    if args.json {
        outln!("{s:#}");
    } else {
        let r = outcome.rms_forward.unwrap_or_default();
        outln!(
            "sdins fuse {name}: {} fixes, {} rejected{}; RMS position N/E/D {:.3}/{:.3}/{:.3} m, velocity {:.4}/{:.4}/{:.4} m/s; wrote {}",
            outcome.fixes, outcome.rejected,
            super::fuse_args::measurements_text(&outcome.measurements),
            r[0], r[1], r[2], r[3], r[4], r[5],
            out.display()
        );
    }
    super::fuse_args::health_end(&args, &outcome.health, &out)
}

fn report(
    out: &Path,
    args: &Args,
    req: &FuseRequest,
    o: &FuseOutcome,
    plot: &Plotted,
) -> Result<(), CliError> {
    let FuseDetails::Scenario {
        name,
        run,
        gnss_rate_hz,
        ..
    } = &o.details
    else {
        return Ok(());
    };
    super::fuse_report::write(
        out,
        &FuseReportData {
            title: format!("sdins fuse: {name}"),
            intro: format!(
                "Scenario {name} run {run}: {} GNSS fixes ({} rejected, {} late){}, algorithm {} N = {}, covariance at {} Hz{}; errors against the exact truth.",
                o.fixes,
                o.rejected,
                o.late,
                super::fuse_args::measurements_text(&o.measurements),
                args.algo,
                o.algo.samples,
                args.cov_rate_hz,
                req.grade
                    .as_ref()
                    .map_or(String::new(), |g| format!(", grade {g}"))
            ),
            att_names: ["ε_N", "ε_E", "ε_D"],
            forward: &plot.forward,
            smoothed: args.smooth.then_some(&plot.smoothed),
            gnss: &plot.gnss,
            fix_interval_s: 1.0 / gnss_rate_hz,
            rmse: rmse_rows(
                &[("forward", o.rms_forward), ("smoothed", o.rms_smoothed)],
                6,
            ),
        },
    )
}

fn summary(args: &Args, o: &FuseOutcome) -> serde_json::Value {
    let v3 = |v: &sdins_core::math::Vec3| [v.x, v.y, v.z];
    let rms = o.rms_forward.unwrap_or_default();
    let FuseDetails::Scenario {
        name, run, summary, ..
    } = &o.details
    else {
        return serde_json::Value::Null;
    };
    let mut s = serde_json::json!({
        "scenario": name,
        "algo": args.algo,
        "samples": o.algo.samples,
        "run": run,
        "grade": args.grade,
        "states": o.layout.n(),
        "blocks": layout_names(&o.layout),
        "fixes": o.fixes,
        "rejected": o.rejected,
        "late": o.late,
        "nav_updates": o.nav_updates,
        "rms_pos_ned_m": &rms[0..3],
        "rms_vel_ned_mps": &rms[3..6],
        "rms_att_ned_rad": &rms[6..9],
        "accel_bias_est_mps2": v3(&summary.est_bias.0),
        "accel_bias_true_mps2": v3(&summary.true_bias.0),
        "gyro_bias_est_rps": v3(&summary.est_bias.1),
        "gyro_bias_true_rps": v3(&summary.true_bias.1),
    });
    if let Some(r) = o.rms_smoothed {
        s["smoothed_rms_pos_ned_m"] = r[0..3].into();
        s["smoothed_rms_vel_ned_mps"] = r[3..6].into();
        s["smoothed_rms_att_ned_rad"] = r[6..9].into();
    }
    if let Some((ta, tg)) = summary.true_scale {
        let ppm = |v: &sdins_core::math::Vec3| [v.x * 1e6, v.y * 1e6, v.z * 1e6];
        s["accel_scale_est_ppm"] = ppm(&summary.est_scale.0).into();
        s["accel_scale_true_ppm"] = ppm(&ta).into();
        s["gyro_scale_est_ppm"] = ppm(&summary.est_scale.1).into();
        s["gyro_scale_true_ppm"] = ppm(&tg).into();
    }
    s
}

fn run_toml(args: &Args, o: &FuseOutcome) -> toml::Table {
    let mut f = toml::Table::new();
    if let FuseDetails::Scenario { name, .. } = &o.details {
        f.insert("scenario".into(), name.clone().into());
    }
    f.insert("algo".into(), args.algo.clone().into());
    f.insert("samples".into(), (o.algo.samples as i64).into());
    f.insert("run".into(), (args.run as i64).into());
    f.insert("cov_rate_hz".into(), args.cov_rate_hz.into());
    f.insert("gate".into(), (!args.no_gate).into());
    f.insert("smooth".into(), args.smooth.into());
    if let Some(g) = &args.grade {
        f.insert("grade".into(), g.clone().into());
    }
    if let Some(e) = args.every_s {
        f.insert("every_s".into(), e.into());
    }
    if let Some(sp) = &args.scale_factors_ppm {
        if let Ok(p) = scale_factor_prior(sp) {
            f.insert("scale_factor_prior_accel_ppm".into(), p.accel_ppm[0].into());
            f.insert("scale_factor_prior_gyro_ppm".into(), p.gyro_ppm[0].into());
        }
    }
    f
}
