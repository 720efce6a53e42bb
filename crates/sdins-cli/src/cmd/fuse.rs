//! `sdins fuse`: INS/GNSS filter on a scenario (truth → IMU errors → GNSS → filter →
//! errors with ±3σ). The work is `sdins_sim::fuse::fuse_scenario`; this only parses and
//! writes.

use crate::error::CliError;
use crate::output::AtomicFile;
use sdins_core::aiding::ekf::{MeasKind, CHI2_999};
use sdins_core::aiding::error_model::{I_ATT, I_POS, I_VEL};
use sdins_core::nav::AlgorithmSpec;
use sdins_sim::cancel::CancelToken;
use sdins_sim::fuse::{fuse_scenario, FuseError, FuseEvent, FuseOptions};
use sdins_sim::scenario::Scenario;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `sdins fuse`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "The scenario's [gnss] table sets the receiver (default: 1 Hz, σ 1/1/2 m, 0.05/0.05/0.1 m/s).\n\nExample:\n  sdins fuse dq-paper --out out/fuse --json"
)]
pub struct Args {
    /// built-in scenario name or scenario file
    pub scenario: String,
    /// output folder (default ./sdins-out/fuse-<scenario>)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// algorithm (savage, songlee, songlee-complete, dualquat)
    #[arg(long, default_value = "songlee-complete")]
    pub algo: String,
    /// IMU samples per navigation update (1–4; default: the scenario's)
    #[arg(long)]
    pub samples: Option<usize>,
    /// Monte Carlo run number (selects the IMU/GNSS/initial-error streams)
    #[arg(long, default_value_t = 0)]
    pub run: u64,
    /// covariance propagation rate [Hz]
    #[arg(long, default_value_t = 10.0)]
    pub cov_rate_hz: f64,
    /// no innovation gating
    #[arg(long)]
    pub no_gate: bool,
    /// start at the truth (no drawn initial errors)
    #[arg(long)]
    pub exact_start: bool,
    /// ZUPT σ [m/s] when the truth is at rest (off if absent)
    #[arg(long)]
    pub zupt_sigma_mps: Option<f64>,
    /// non-holonomic constraint σ [m/s] (off if absent)
    #[arg(long)]
    pub nhc_sigma_mps: Option<f64>,
    /// print the summary as JSON
    #[arg(long)]
    pub json: bool,
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
    let scn = Scenario::load(&args.scenario)?;
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
    let gnss = scn.gnss.clone().unwrap_or_default();
    let opts = FuseOptions {
        algo,
        cov_rate_hz: args.cov_rate_hz,
        draw_initial_errors: !args.exact_start,
        gate_chi2: if args.no_gate { None } else { Some(CHI2_999) },
        zupt: args.zupt_sigma_mps.map(|s| (s, 1e-3)),
        nhc_sigma_mps: args.nhc_sigma_mps,
        ..FuseOptions::default()
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| crate::output::default_dir("fuse-", &scn.name));
    crate::output::claim(&out)?;
    let mut nav = AtomicFile::create(&out.join("nav.csv"))?;
    let mut inn = AtomicFile::create(&out.join("innovations.csv"))?;
    let io = |name: &str, e: std::io::Error| CliError::Io {
        path: out.join(name),
        source: e,
    };
    writeln!(nav.writer(), "t_s,err_n_m,err_e_m,err_d_m,sigma_n_m,sigma_e_m,sigma_d_m,err_vn_mps,err_ve_mps,err_vd_mps,sigma_vn_mps,sigma_ve_mps,sigma_vd_mps,err_att_n_rad,err_att_e_rad,err_att_d_rad,sigma_att_n_rad,sigma_att_e_rad,sigma_att_d_rad").map_err(|e| io("nav.csv", e))?;
    writeln!(
        inn.writer(),
        "t_s,kind,dof,nis,accepted,forced,nu_1,nu_2,nu_3,nu_4,nu_5,nu_6"
    )
    .map_err(|e| io("innovations.csv", e))?;
    let mut werr: Option<std::io::Error> = None;
    let mut sq = [0.0_f64; 9];
    let mut n_ep = 0.0_f64;
    let cancel = CancelToken::new();
    let res = fuse_scenario(&scn, &gnss, &opts, args.run, &cancel, |ev| {
        let r = match ev {
            FuseEvent::Epoch(e) => {
                let mut line = format!("{}", e.t_s);
                for (i0, vals) in [
                    (I_POS, e.nav.pos_err_ned_m),
                    (I_VEL, e.nav.vel_err_ned_mps),
                    (I_ATT, e.nav.att_err_rad),
                ] {
                    for v in vals {
                        line.push_str(&format!(",{v:e}"));
                    }
                    for i in 0..3 {
                        line.push_str(&format!(",{:e}", e.sigma(i0 + i)));
                        sq[i0 + i] += vals[i] * vals[i];
                    }
                }
                n_ep += 1.0;
                writeln!(nav.writer(), "{line}")
            }
            FuseEvent::Update(u) => {
                let kind = match u.kind {
                    MeasKind::Gnss => "gnss",
                    MeasKind::Zupt => "zupt",
                    MeasKind::Nhc => "nhc",
                    _ => "other",
                };
                let mut line = format!(
                    "{},{kind},{},{:.6},{},{}",
                    u.t_s, u.dof, u.nis, u.accepted, u.forced
                );
                for v in u.innovation {
                    line.push_str(&format!(",{v:e}"));
                }
                writeln!(inn.writer(), "{line}")
            }
        };
        if let Err(e) = r {
            werr.get_or_insert(e);
        }
    });
    if let Some(e) = werr {
        return Err(io("nav.csv", e));
    }
    let s = match res {
        Ok(s) => s,
        Err(FuseError::Cancelled(_)) => return Err(CliError::Interrupted),
        Err(e) => return Err(CliError::bad(e.to_string())),
    };
    nav.commit()?;
    inn.commit()?;
    let rms: Vec<f64> = sq.iter().map(|x| (x / n_ep.max(1.0)).sqrt()).collect();
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
    let mut fields = toml::Table::new();
    fields.insert("scenario".into(), scn.name.clone().into());
    fields.insert("algo".into(), args.algo.clone().into());
    fields.insert("samples".into(), (samples as i64).into());
    fields.insert("run".into(), (args.run as i64).into());
    fields.insert("cov_rate_hz".into(), args.cov_rate_hz.into());
    fields.insert("gate".into(), (!args.no_gate).into());
    crate::report::write_run_toml(&out, fields)?;
    if args.json {
        println!("{summary:#}");
    } else {
        println!(
            "sdins fuse {}: {} fixes, {} rejected; RMS position N/E/D {:.3}/{:.3}/{:.3} m, velocity {:.4}/{:.4}/{:.4} m/s; wrote {}",
            scn.name, s.fixes, s.rejected, rms[0], rms[1], rms[2], rms[3], rms[4], rms[5],
            out.display()
        );
    }
    Ok(())
}
