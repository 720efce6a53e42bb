//! `sdins truth`: write the exact truth trajectory and IMU increments, streaming.

use crate::csv_out::CsvOut;
use crate::error::CliError;
use crate::output::AtomicFile;
use crate::progress::Progress;
use sdins_core::math::{euler_from_c_b_n, Mat3, Quat, Vec3};
use sdins_sim::io::truth_file::SDINS_TRUTH_HEADER as TRUTH_HEADER;
use sdins_sim::scenario::Scenario;
use sdins_sim::truth::TruthGenerator;
use std::path::PathBuf;

/// Arguments of `sdins truth`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  sdins truth turn-90dps --out out/turn\n  sdins truth --from-reference ref.csv --rate-hz 200 --out out/ref\n  sdins truth --from-reference log.csv --columns t_s=time,lat_deg=lat,lon_deg=lon,h_m=alt,roll_deg=roll,pitch_deg=pitch,yaw_deg=yaw,v_n_mps=vn,v_e_mps=ve,v_d_mps=vd --rate-hz 500 --out out/log"
)]
pub struct Args {
    /// built-in scenario name or scenario file
    #[arg(required_unless_present = "from_reference")]
    pub scenario: Option<String>,
    /// a recorded trajectory instead of a scenario: an sdins truth.csv, a PSINS avp CSV,
    /// NaveGo's ref.csv (told apart by the header), or any CSV with --columns; its C²
    /// interpolant becomes the truth (docs/scenarios.md §"Recorded trajectories")
    #[arg(long, value_name = "FILE", conflicts_with = "scenario")]
    pub from_reference: Option<PathBuf>,
    /// IMU rate for --from-reference [Hz]
    #[arg(long, default_value_t = 100.0, requires = "from_reference")]
    pub rate_hz: f64,
    /// column map of a generic --from-reference CSV:
    /// t_s=COL,lat_deg=COL,lon_deg=COL,h_m=COL,roll_deg=COL,pitch_deg=COL,yaw_deg=COL
    /// (`_rad` for radians; optional v_n_mps=,v_e_mps=,v_d_mps=)
    #[arg(long, value_name = "MAP", requires = "from_reference")]
    pub columns: Option<String>,
    /// earth model for --from-reference: wgs84 or psins
    #[arg(long, default_value = "wgs84", requires = "from_reference")]
    pub earth: String,
    /// output folder (default ./sdins-out/truth-<scenario>)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// write truth.csv every N samples (imu.csv always has every sample)
    #[arg(long, default_value_t = 1)]
    pub every: u64,
    /// no progress bar
    #[arg(long)]
    pub quiet: bool,
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let (scn, t_offset) = match (&args.from_reference, &args.scenario) {
        (Some(file), _) => from_reference(file, &args)?,
        (None, Some(name)) => (Scenario::load_with(name, &crate::progress::token())?, 0.0),
        (None, None) => return Err(CliError::bad("give a scenario or --from-reference FILE")),
    };
    crate::report::print_vibration(&scn);
    if args.every == 0 {
        return Err(CliError::bad("--every: must be at least 1"));
    }
    let out = args
        .out
        .unwrap_or_else(|| crate::output::default_dir("truth-", &scn.name));
    crate::output::claim(&out)?;
    let mut gen = TruthGenerator::new(&scn.trajectory, scn.truth_config());
    // truth.csv stays at the vehicle reference point; imu.csv is sensed at the IMU
    let init = gen.initial_state();
    if let Some(m) = scn.mounting.imu {
        gen = gen.with_mount(m);
        eprintln!("note: imu.csv is sensed at the IMU lever arm and mounting ([mounting]); truth.csv is at the vehicle reference point");
    }
    let total = gen.len_samples();
    crate::output::check_size(
        "imu.csv",
        total as f64,
        160.0,
        "shorten the scenario or lower imu.rate_hz",
    )?;
    crate::output::check_size(
        "truth.csv",
        total as f64 / args.every as f64,
        280.0,
        "raise --every",
    )?;
    let mut truth = AtomicFile::create(&out.join("truth.csv"))?;
    let mut imu = AtomicFile::create(&out.join("imu.csv"))?;
    let mut truth_csv = CsvOut::new(&mut truth, &TRUTH_HEADER)?;
    let mut imu_csv = CsvOut::new(&mut imu, &sdins_sim::io::imu_file::SDINS_INCREMENT_HEADER)?;
    let d = 180.0 / std::f64::consts::PI;
    let truth_row = |t_s: f64, lat: f64, lon: f64, h: f64, v: &Vec3, c: &Mat3| {
        let e = euler_from_c_b_n(c);
        let q = Quat::from_dcm(c);
        [
            t_s,
            lat * d,
            lon * d,
            h,
            v.x,
            v.y,
            v.z,
            e.roll_rad * d,
            e.pitch_rad * d,
            e.yaw_rad * d,
            q.w,
            q.x,
            q.y,
            q.z,
        ]
    };
    truth_csv.row(&truth_row(
        t_offset,
        init.lat_rad,
        init.lon_rad,
        init.h_m,
        &init.v_n_mps,
        &init.c_b_n,
    ))?;
    let mut bar = Progress::new(total, "truth", args.quiet);
    for (k, s) in gen.enumerate() {
        let i = &s.inc;
        imu_csv.row(&[
            s.t_s + t_offset,
            i.dtheta_b_rad.x,
            i.dtheta_b_rad.y,
            i.dtheta_b_rad.z,
            i.dv_b_mps.x,
            i.dv_b_mps.y,
            i.dv_b_mps.z,
        ])?;
        if (k as u64 + 1).is_multiple_of(args.every) {
            truth_csv.row(&truth_row(
                s.t_s + t_offset,
                s.lat_rad,
                s.lon_rad,
                s.h_m,
                &s.v_n_mps,
                &s.c_b_n,
            ))?;
        }
        if k % 65536 == 0 {
            bar.set(k as u64);
            if crate::progress::interrupted() {
                return Err(CliError::Interrupted);
            }
        }
    }
    truth_csv.finish()?;
    imu_csv.finish()?;
    bar.finish();
    truth.commit()?;
    imu.commit()?;
    eprintln!(
        "wrote {} and {} ({} samples at {} Hz, {} s)",
        out.join("truth.csv").display(),
        out.join("imu.csv").display(),
        total,
        scn.imu.rate_hz,
        scn.duration_s()
    );
    Ok(())
}

/// The scenario of `--from-reference` and the reference time of its first row.
fn from_reference(file: &std::path::Path, args: &Args) -> Result<(Scenario, f64), CliError> {
    use sdins_sim::scenario::from_reference::{scenario_from_reference, ReferenceOptions};
    let opts = ReferenceOptions::from_names(args.rate_hz, args.columns.as_deref(), &args.earth)
        .map_err(|e| CliError::bad(e.to_string()))?;
    let (scn, sum) =
        scenario_from_reference(file, &opts).map_err(|e| CliError::bad(e.to_string()))?;
    eprintln!(
        "reference: {} rows over {} s from t = {} s; truth {} s at {} Hz (C² interpolant through every row)",
        sum.rows, sum.span_s, sum.t0_s, sum.duration_s, args.rate_hz
    );
    if let Some(v) = sum.velocity {
        eprintln!(
            "reference velocity columns against the interpolant's velocity: RMS {:.3e} m/s, max {:.3e} m/s at t = {} s",
            v.rms_mps, v.max_mps, v.t_max_s
        );
    }
    Ok((scn, sum.t0_s))
}
