//! `sdins truth`: write the exact truth trajectory and IMU increments, streaming.

use crate::csv_out::CsvOut;
use crate::error::CliError;
use crate::output::AtomicFile;
use crate::progress::Progress;
use sdins_core::coning::Increment;
use sdins_core::math::{euler_from_c_b_n, Quat};
use sdins_sim::io::imu_file::SDINS_INCREMENT_HEADER;
use sdins_sim::io::truth_file::SDINS_TRUTH_HEADER as TRUTH_HEADER;
use sdins_sim::nav::truth_rows::{self, TruthObserver, TruthRequest, TruthRow};
use sdins_sim::scenario::Scenario;
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

/// `truth.csv` and `imu.csv` as the library reports their rows.
struct Sink<'f> {
    truth: CsvOut<'f>,
    imu: CsvOut<'f>,
    bar: Progress,
    error: Option<CliError>,
}

impl TruthObserver for Sink<'_> {
    fn imu(&mut self, t_s: f64, i: &Increment) {
        let (a, v) = (i.dtheta_b_rad, i.dv_b_mps);
        if let Err(e) = self.imu.row(&[t_s, a.x, a.y, a.z, v.x, v.y, v.z]) {
            self.error.get_or_insert(e);
        }
    }
    fn row(&mut self, r: &TruthRow) {
        let d = 180.0 / std::f64::consts::PI;
        let (e, q, v) = (
            euler_from_c_b_n(&r.c_b_n),
            Quat::from_dcm(&r.c_b_n),
            r.v_n_mps,
        );
        let row = [
            r.t_s,
            r.lat_rad * d,
            r.lon_rad * d,
            r.h_m,
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
        ];
        if let Err(e) = self.truth.row(&row) {
            self.error.get_or_insert(e);
        }
    }
    fn progress(&mut self, done: u64, _total: u64) {
        self.bar.set(done);
    }
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let (scn, t_offset) = match (&args.from_reference, &args.scenario) {
        (Some(file), _) => from_reference(file, &args)?,
        (None, Some(name)) => (Scenario::load_with(name, &crate::progress::token())?, 0.0),
        (None, None) => return Err(CliError::bad("give a scenario or --from-reference FILE")),
    };
    crate::report::print_vibration(&scn);
    let req = TruthRequest {
        every: args.every,
        t_offset_s: t_offset,
        ..TruthRequest::default()
    };
    let plan = truth_rows::plan(&scn, req).map_err(|e| CliError::bad(e.to_string()))?;
    let out = args
        .out
        .unwrap_or_else(|| crate::output::default_dir("truth-", &scn.name));
    let tip = "shorten the scenario or lower imu.rate_hz";
    crate::output::check_size("imu.csv", plan.samples as f64, 160.0, tip)?;
    crate::output::check_size("truth.csv", plan.rows as f64, 280.0, "raise --every")?;
    crate::output::claim(&out)?;
    if plan.imu_mounted {
        eprintln!("note: imu.csv is sensed at the IMU lever arm and mounting ([mounting]); truth.csv is at the vehicle reference point");
    }
    let mut truth = AtomicFile::create(&out.join("truth.csv"))?;
    let mut imu = AtomicFile::create(&out.join("imu.csv"))?;
    {
        let mut sink = Sink {
            truth: CsvOut::new(&mut truth, &TRUTH_HEADER)?,
            imu: CsvOut::new(&mut imu, &SDINS_INCREMENT_HEADER)?,
            bar: Progress::new(plan.samples, "truth", args.quiet),
            error: None,
        };
        truth_rows::run(&scn, &plan, &crate::progress::token(), &mut sink)
            .map_err(|_| CliError::Interrupted)?;
        if let Some(e) = sink.error {
            return Err(e);
        }
        sink.truth.finish()?;
        sink.imu.finish()?;
        sink.bar.finish();
    }
    truth.commit()?;
    imu.commit()?;
    eprintln!(
        "wrote {} and {} ({} samples at {} Hz, {} s)",
        out.join("truth.csv").display(),
        out.join("imu.csv").display(),
        plan.samples,
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
