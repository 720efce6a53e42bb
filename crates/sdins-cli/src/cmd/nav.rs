//! `sdins nav`: run one navigation algorithm over a recorded IMU file.

use crate::csv_out::{nav_row, CsvOut, ERR_HEADER, NAV_HEADER};
use crate::error::CliError;
use crate::output::AtomicFile;
use sdins_sim::io::imu_file::{read_imu_file, ImuFormat};
use sdins_sim::io::truth_file::read_truth;
use sdins_sim::nav::options::{self, algorithms, earth_by_name, AlgoChoice};
use sdins_sim::nav::recorded;
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

/// Fail unless a reference time falls on an update epoch (see
/// [`sdins_sim::nav::recorded::check_time_bases`]).
pub fn check_time_bases(
    truth: &[sdins_sim::truth::TruthSample],
    truth_path: &std::path::Path,
    imu_path: &std::path::Path,
    t0: f64,
    dt: f64,
    samples: usize,
    n_samples: usize,
) -> Result<(), CliError> {
    recorded::check_time_bases(truth, truth_path, imu_path, t0, dt, samples, n_samples)
        .map_err(|e| CliError::BadInput(e.to_string()))
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let format: ImuFormat = args.format.parse().map_err(CliError::BadInput)?;
    let earth = earth_by_name(&args.earth).map_err(|e| CliError::BadInput(e.to_string()))?;
    let data = read_imu_file(&args.imu, format).map_err(|e| CliError::BadInput(e.to_string()))?;
    let truth = match &args.truth {
        Some(p) => Some(read_truth(p).map_err(|e| CliError::BadInput(e.to_string()))?),
        None => None,
    };
    let init = recorded::initial_state(
        args.init.as_deref(),
        match (&args.truth, &truth) {
            (Some(p), Some(t)) => Some((p.as_path(), t.as_slice())),
            _ => None,
        },
        &args.imu,
        &data,
    )
    .map_err(|e| CliError::BadInput(e.to_string()))?;
    let choice = AlgoChoice {
        algos: Some(args.algo.clone()),
        samples: Some(args.samples),
        coning: args.coning.clone(),
        ..AlgoChoice::default()
    };
    let specs = algorithms(&choice, &options::recorded_nav_defaults())
        .map_err(|e| CliError::BadInput(e.to_string()))?;
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
    crate::output::check_size(
        "nav_*.csv",
        data.increments.len() as f64 / spec.samples as f64 + 1.0,
        250.0,
        "split the IMU file",
    )?;
    crate::output::claim(&out)?;
    let mut nav_file = AtomicFile::create(&out.join(format!("nav_{}.csv", spec.kind.name())))?;
    let mut nav_csv = CsvOut::new(&mut nav_file, &NAV_HEADER)?;
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
    let rec = recorded::navigate(
        &spec,
        earth,
        data.dt_s,
        t0,
        &init,
        &data.increments,
        truth.as_deref(),
        &crate::progress::token(),
        |t, st| {
            final_state = Some((t, *st));
            if let Err(err) = nav_csv.row(&nav_row(t, st)) {
                write_err.get_or_insert(err);
            }
        },
    )?;
    let (wall, errs) = (rec.wall_s, rec.errors);
    if let Some(e) = write_err {
        return Err(e);
    }
    nav_csv.finish()?;
    nav_file.commit()?;
    if truth.is_some() {
        let mut ef = AtomicFile::create(&out.join(format!("err_{}.csv", spec.kind.name())))?;
        let mut ec = CsvOut::new(&mut ef, &ERR_HEADER[..10])?;
        for e in &errs {
            let (p, v, a) = (e.pos_err_ned_m, e.vel_err_ned_mps, e.att_err_rad);
            ec.row(&[e.t_s, p[0], p[1], p[2], v[0], v[1], v[2], a[0], a[1], a[2]])?;
        }
        ec.finish()?;
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
            "imu_detection": data.detection, "imu_warnings": data.warnings,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| CliError::Other(e.to_string()))?
        );
    } else {
        if let Some(why) = &data.detection {
            println!("{}: {why}", args.imu.display());
        }
        for w in &data.warnings {
            println!("{}: warning: {w}", args.imu.display());
        }
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
