//! `sdins nav`: run one navigation algorithm over a recorded IMU file.

use super::run::{algorithms, Args as RunArgs};
use crate::error::CliError;
use crate::output::AtomicFile;
use sdins_core::earth::EarthModel;
use sdins_core::math::Vec3;
use sdins_core::nav::InitialState;
use sdins_sim::imu_file::{read_imu_file, ImuFormat};
use sdins_sim::initial::validate_initial_state;
use sdins_sim::pipeline::{nav_error, navigate_recorded_timed, NavError};
use sdins_sim::scenario::Scenario;
use sdins_sim::truth_file::{c_b_n_from_psins, read_truth};
use std::io::Write;
use std::path::PathBuf;

const D2R: f64 = std::f64::consts::PI / 180.0;

/// Arguments of `sdins nav`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  sdins truth turn-90dps --out t && sdins nav --imu t/imu.csv --truth t/truth.csv --algo songlee --samples 3\n  sdins nav --imu trj10ms_imu.csv --format psins-csv --earth psins --truth trj10ms_avp.csv --init 34.246048,108.909664,380,0,0,0,0,0,0"
)]
pub struct Args {
    /// IMU file: sdins CSV, PSINS .imu, PSINS trj CSV (psins-csv), KF-GINS text, NaveGo CSV
    #[arg(long)]
    pub imu: PathBuf,
    /// file format: auto, sdins, psins, psins-csv, kfgins, navego
    #[arg(long, default_value = "auto")]
    pub format: String,
    /// initial state lat_deg,lon_deg,h_m,v_n,v_e,v_d,roll_deg,pitch_deg,yaw_deg (NED, FRD);
    /// default: the first row of --truth, or the PSINS .imu header
    #[arg(long, allow_hyphen_values = true)]
    pub init: Option<String>,
    /// algorithm: savage, songlee, songlee-complete, dualquat
    #[arg(long, default_value = "songlee-complete")]
    pub algo: String,
    /// IMU samples per navigation update (1..=4)
    #[arg(long, default_value_t = 1)]
    pub samples: usize,
    /// coning/sculling set (default: 1prev for one sample per update, else the polynomial
    /// set of N; `none` switches the correction off)
    #[arg(long)]
    pub coning: Option<String>,
    /// earth model: wgs84, wgs84-linear (gravity γ(L)(1 − 2h/a), as pyins), psins, flat
    #[arg(long, default_value = "wgs84")]
    pub earth: String,
    /// reference trajectory (sdins truth.csv or PSINS avp CSV); errors are written too
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// output folder (default ./sdins-out/nav)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// print a JSON summary
    #[arg(long)]
    pub json: bool,
}

fn parse_init(s: &str) -> Result<InitialState, CliError> {
    sdins_sim::initial::parse_initial_state(s).map_err(CliError::BadInput)
}

/// Fail unless at least one reference time falls on a navigation update epoch
/// `t0 + k N δt` (k = 1..=updates) within 0.1 δt: otherwise `--truth` would silently
/// compare nothing (different time bases, another trajectory, a decimated file that
/// misses every epoch).
pub fn check_time_bases(
    truth: &[sdins_sim::truth::TruthSample],
    truth_path: &std::path::Path,
    imu_path: &std::path::Path,
    t0: f64,
    dt: f64,
    samples: usize,
    n_samples: usize,
) -> Result<(), CliError> {
    let upd = dt * samples.max(1) as f64;
    let n_upd = n_samples / samples.max(1);
    let tol = 0.1 * dt;
    let matched = truth.iter().any(|r| {
        let k = ((r.t_s - t0) / upd).round();
        k >= 1.0 && k <= n_upd as f64 && (r.t_s - (t0 + k * upd)).abs() <= tol
    });
    if matched {
        return Ok(());
    }
    let (first, last) = match (truth.first(), truth.last()) {
        (Some(a), Some(b)) => (a.t_s, b.t_s),
        _ => (f64::NAN, f64::NAN),
    };
    Err(CliError::bad(format!(
        "{}: no time matches an update epoch of {}: the updates are at {} s + k·{} s up to {} s, the reference covers {} s to {} s (expected equal times within {} s; are the time bases the same?)",
        truth_path.display(),
        imu_path.display(),
        t0,
        upd,
        t0 + n_upd as f64 * upd,
        first,
        last,
        tol
    )))
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let format: ImuFormat = args.format.parse().map_err(CliError::BadInput)?;
    let earth = match args.earth.as_str() {
        "wgs84" => EarthModel::WGS84,
        "wgs84-linear" => EarthModel::WGS84_LINEAR_G,
        "psins" => EarthModel::PSINS,
        "flat" => EarthModel::flat(9.806_65),
        o => {
            return Err(CliError::bad(format!(
                "--earth {o}: expected wgs84, wgs84-linear, psins or flat"
            )))
        }
    };
    let data = read_imu_file(&args.imu, format).map_err(|e| CliError::BadInput(e.to_string()))?;
    let truth = match &args.truth {
        Some(p) => Some(read_truth(p).map_err(|e| CliError::BadInput(e.to_string()))?),
        None => None,
    };
    let init = match (&args.init, &truth, &data.psins) {
        (Some(s), _, _) => parse_init(s)?,
        (None, Some(tr), _) if !tr.is_empty() => {
            // the state at the start of the first IMU sample: the truth's first row must be
            // at that epoch, else the run would start from a wrong state
            let r = &tr[0];
            let t_start = data.t0_s - data.dt_s;
            if (r.t_s - t_start).abs() > 0.1 * data.dt_s {
                return Err(CliError::bad(format!(
                    "{}: the first row (t = {} s) is not at the start of the first sample of {} (t = {} s, its first time stamp {} s minus the interval {} s): give --init",
                    args.truth.as_deref().unwrap_or(std::path::Path::new("")).display(),
                    r.t_s,
                    args.imu.display(),
                    t_start,
                    data.t0_s,
                    data.dt_s
                )));
            }
            let s = InitialState {
                lat_rad: r.lat_rad,
                lon_rad: r.lon_rad,
                h_m: r.h_m,
                v_n_mps: r.v_n_mps,
                c_b_n: r.c_b_n,
            };
            validate_initial_state(&s).map_err(|e| {
                CliError::bad(format!(
                    "{}: first row (the initial state): {e}",
                    args.truth
                        .as_deref()
                        .unwrap_or(std::path::Path::new(""))
                        .display()
                ))
            })?;
            s
        }
        (None, _, Some(h)) => {
            let s = InitialState {
                lat_rad: h.lat_deg * D2R,
                lon_rad: h.lon_deg * D2R,
                h_m: h.h_m,
                v_n_mps: Vec3::new(h.vel0_enu_mps[1], h.vel0_enu_mps[0], -h.vel0_enu_mps[2]),
                c_b_n: c_b_n_from_psins(
                    h.att0_deg[0] * D2R,
                    h.att0_deg[1] * D2R,
                    h.att0_deg[2] * D2R,
                ),
            };
            validate_initial_state(&s).map_err(|e| {
                CliError::bad(format!(
                    "{}: PSINS header (the initial state): {e}",
                    args.imu.display()
                ))
            })?;
            s
        }
        _ => {
            return Err(CliError::bad(
                "--init is required (no truth file or PSINS header to take it from)",
            ))
        }
    };
    // reuse `run`'s algorithm parsing
    let run_args = RunArgs {
        scenario: String::new(),
        algo: Some(args.algo.clone()),
        samples: Some(args.samples),
        coning: args.coning.clone(),
        attitude: None,
        rot3: false,
        rotvec: None,
        vertical: None,
        out: None,
        every_s: 1.0,
        ideal: true,
        run: 0,
        plot_scale: crate::plot::PlotScale::Log,
        json: false,
        quiet: true,
    };
    let dummy = Scenario::load("stationary")?;
    let specs = algorithms(&run_args, &dummy)?;
    let Some(spec) = specs.first().copied() else {
        return Err(CliError::bad("--algo: no algorithm given"));
    };
    if specs.len() > 1 {
        return Err(CliError::bad("--algo: `nav` runs one algorithm"));
    }
    let t0 = data.t0_s - data.dt_s; // state epoch before the first sample
    if let (Some(tr), Some(tp)) = (&truth, &args.truth) {
        check_time_bases(
            tr,
            tp,
            &args.imu,
            t0,
            data.dt_s,
            spec.samples,
            data.increments.len(),
        )?;
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("sdins-out/nav"));
    let mut nav_file = AtomicFile::create(&out.join(format!("nav_{}.csv", spec.kind.name())))?;
    let io = |source| CliError::Io {
        path: out.clone(),
        source,
    };
    writeln!(
        nav_file.writer(),
        "t_s,lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg"
    )
    .map_err(io)?;
    let mut errs: Vec<NavError> = Vec::new();
    let mut ti = 0usize;
    let mut write_err = None;
    let mut final_state = None;
    // what was used, so that nobody has to guess a default
    eprintln!(
        "sdins nav: {} format {}, algorithm {}, N = {}, coning {}, earth {}",
        args.imu.display(),
        if format == ImuFormat::Auto {
            format!("{} (detected)", data.format.name())
        } else {
            data.format.name().to_string()
        },
        spec.kind.name(),
        spec.samples,
        spec.coning.name(),
        args.earth
    );
    let wall = navigate_recorded_timed(&spec, earth, data.dt_s, &init, &data.increments, |st| {
        let t = t0 + st.t_s;
        final_state = Some((t, *st));
        let e = st.euler();
        if let Err(err) = writeln!(
            nav_file.writer(),
            "{},{},{},{},{},{},{},{},{},{}",
            t,
            st.lat_rad / D2R,
            st.lon_rad / D2R,
            st.h_m,
            st.v_n_mps.x,
            st.v_n_mps.y,
            st.v_n_mps.z,
            e.roll_rad / D2R,
            e.pitch_rad / D2R,
            e.yaw_rad / D2R
        ) {
            write_err.get_or_insert(err);
        }
        if let Some(tr) = &truth {
            while ti < tr.len() && tr[ti].t_s < t - 0.1 * data.dt_s {
                ti += 1;
            }
            if let Some(r) = tr.get(ti) {
                if (r.t_s - t).abs() <= 0.1 * data.dt_s {
                    let mut e = nav_error(&earth, st, r);
                    e.t_s = t;
                    errs.push(e);
                }
            }
        }
    });
    if let Some(e) = write_err {
        return Err(io(e));
    }
    nav_file.commit()?;
    if truth.is_some() {
        let mut ef = AtomicFile::create(&out.join(format!("err_{}.csv", spec.kind.name())))?;
        writeln!(ef.writer(), "t_s,pos_err_n_m,pos_err_e_m,pos_err_d_m,vel_err_n_mps,vel_err_e_mps,vel_err_d_mps,att_err_n_rad,att_err_e_rad,att_err_d_rad").map_err(io)?;
        for e in &errs {
            let (p, v, a) = (e.pos_err_ned_m, e.vel_err_ned_mps, e.att_err_rad);
            writeln!(
                ef.writer(),
                "{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                e.t_s,
                p[0],
                p[1],
                p[2],
                v[0],
                v[1],
                v[2],
                a[0],
                a[1],
                a[2]
            )
            .map_err(io)?;
        }
        ef.commit()?;
    }
    let last = errs.last();
    if args.json {
        let state = final_state.map(|(t, st)| {
            let e = st.euler();
            serde_json::json!({
                "t_s": t, "lat_deg": st.lat_rad / D2R, "lon_deg": st.lon_rad / D2R, "h_m": st.h_m,
                "v_ned_mps": [st.v_n_mps.x, st.v_n_mps.y, st.v_n_mps.z],
                "roll_deg": e.roll_rad / D2R, "pitch_deg": e.pitch_rad / D2R, "yaw_deg": e.yaw_rad / D2R,
            })
        });
        let v = serde_json::json!({
            "algo": spec.kind.name(), "samples": spec.samples, "coning": spec.coning.name(),
            "earth": args.earth, "format": data.format.name(), "imu_samples": data.increments.len(),
            "dt_s": data.dt_s, "wall_s": wall, "final": last, "final_state": state,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| CliError::Other(e.to_string()))?
        );
    } else {
        println!(
            "{}: {} samples at {} s, {} updates in {:.3} s (navigation only)",
            spec.kind.name(),
            data.increments.len(),
            data.dt_s,
            data.increments.len() / spec.samples.max(1),
            wall
        );
        if let Some(e) = last {
            println!(
                "final errors at t = {} s: pos N,E,D {:.4e} {:.4e} {:.4e} m; vel {:.3e} {:.3e} {:.3e} m/s; att {:.3e} {:.3e} {:.3e} rad",
                e.t_s, e.pos_err_ned_m[0], e.pos_err_ned_m[1], e.pos_err_ned_m[2], e.vel_err_ned_mps[0], e.vel_err_ned_mps[1],
                e.vel_err_ned_mps[2], e.att_err_rad[0], e.att_err_rad[1], e.att_err_rad[2]
            );
        }
        println!("files in {}", out.display());
    }
    Ok(())
}
