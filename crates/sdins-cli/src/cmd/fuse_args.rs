//! The options of `sdins fuse`, shared by its scenario mode (`cmd/fuse.rs`) and its
//! recorded-file mode (`cmd/fuse_files.rs`).

use crate::error::CliError;
use std::path::PathBuf;

/// Arguments of `sdins fuse`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "The scenario's [gnss] table sets the receiver (default: 1 Hz, σ 1/1/2 m, 0.05/0.05/0.1 m/s).\n\nExample:\n  sdins fuse dq-paper --out out/fuse --json\n  sdins fuse --imu imu1.csv --gnss gnss.csv --navego-params imu1_params.txt --truth ref.csv --samples 1 --smooth"
)]
pub struct Args {
    /// built-in scenario name or scenario file (or give --imu and --gnss)
    #[arg(required_unless_present = "imu", conflicts_with = "imu")]
    pub scenario: Option<String>,
    /// recorded IMU file (with --gnss: fuse recorded data instead of a scenario)
    #[arg(long)]
    pub imu: Option<PathBuf>,
    /// IMU file format (auto, sdins, psins, psins-csv, kfgins, navego)
    #[arg(long, default_value = "auto")]
    pub imu_format: String,
    /// GNSS file (sdins CSV, NaveGo gnss.csv, KF-GINS text, RTKLIB .pos)
    #[arg(long, requires = "imu")]
    pub gnss: Option<PathBuf>,
    /// GNSS file format (auto, sdins, navego, kfgins, rtklib)
    #[arg(long, default_value = "auto")]
    pub gnss_format: String,
    /// t_imu − t_gnss [s] when the two files' clocks differ by a constant
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub gnss_offset_s: f64,
    /// the filter's IMU model from a grade preset (consumer, industrial, tactical, aviation, ...)
    #[arg(long)]
    pub grade: Option<String>,
    /// the filter's IMU model from a NaveGo imuN_params.txt (static bias known, ±10 % residual)
    #[arg(long)]
    pub navego_params: Option<PathBuf>,
    /// initial state lat_deg,lon_deg,h_m,v_n,v_e,v_d,roll_deg,pitch_deg,yaw_deg at the IMU record's start
    #[arg(long, allow_hyphen_values = true)]
    pub init: Option<String>,
    /// initial attitude roll,pitch,yaw [deg]; position and velocity from the first fix
    #[arg(long, allow_hyphen_values = true)]
    pub attitude_deg: Option<String>,
    /// σ of --attitude-deg roll,pitch,yaw [deg] (default 1,1,2)
    #[arg(long)]
    pub attitude_sigma_deg: Option<String>,
    /// at rest for the first S seconds: coarse alignment, position from the first fix
    #[arg(long)]
    pub static_s: Option<f64>,
    /// GNSS antenna lever arm from the IMU, body FRD x,y,z [m]
    #[arg(long, allow_hyphen_values = true)]
    pub lever_arm_m: Option<String>,
    /// reference trajectory to compare with (sdins truth.csv, PSINS avp, NaveGo ref.csv)
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// run the Rauch–Tung–Striebel smoother after the forward filter (smoothed.csv)
    #[arg(long)]
    pub smooth: bool,
    /// scenario: in-motion alignment from an unknown heading (start at the first fix at
    /// ≥ 5 m/s, heading from the GNSS track)
    #[arg(long)]
    pub in_motion: bool,
    /// also estimate accelerometer and gyro scale factors (21 states) with prior σ
    /// ACCEL_PPM,GYRO_PPM per axis
    #[arg(long)]
    pub scale_factors_ppm: Option<String>,
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
    /// column maps of one's own files
    #[command(flatten)]
    pub columns: crate::args::ColumnsArgs,
}

/// `--scale-factors-ppm ACCEL,GYRO`: prior σ of the scale-factor states, in (0, 1e5] ppm.
pub fn scale_factor_prior(
    s: &str,
) -> Result<sdins_sim::fusion::simulated::ScaleFactorPrior, CliError> {
    let v: Vec<&str> = s.split(',').map(str::trim).collect();
    let parsed: Vec<f64> = v.iter().filter_map(|t| t.parse::<f64>().ok()).collect();
    let prior = match parsed[..] {
        [a, g] if v.len() == 2 && a > 0.0 && g > 0.0 => Some(
            sdins_sim::fusion::simulated::ScaleFactorPrior::uniform(a, g),
        ),
        _ => None,
    };
    match prior {
        Some(p) if p.validate().is_ok() => Ok(p),
        _ => Err(CliError::bad(format!(
            "--scale-factors-ppm: expected ACCEL_PPM,GYRO_PPM, two numbers in (0, 100000], got `{s}`"
        ))),
    }
}
