//! The options of `sdins fuse`, shared by its scenario mode (`cmd/fuse.rs`), its
//! recorded-file mode (`cmd/fuse_files.rs`) and its Monte Carlo (`cmd/fuse_mc.rs`), and
//! their parsing into the library's typed request
//! (`sdins_sim::fusion::request::FuseRequest`).

use crate::error::CliError;
use sdins_core::aiding::meas::MeasKind;
use sdins_sim::fusion::health::HealthVerdict;
use sdins_sim::fusion::request::{
    FilesData, FuseData, FuseRequest, FuseRunError, KindTally, ScenarioData,
};
use sdins_sim::scenario::Scenario;
use std::path::PathBuf;

/// Arguments of `sdins fuse`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "The scenario's [gnss] table sets the receiver (default: 1 Hz, σ 1/1/2 m, 0.05/0.05/0.1 m/s).\n\nExample:\n  sdins fuse dq-paper --out out/fuse --json\n  sdins fuse --imu imu1.csv --gnss gnss.csv --navego-params imu1_params.txt --truth ref.csv --samples 1 --smooth\n  sdins fuse dq-paper --grade tactical --no-gate --runs 100 --seed 1 --out out/fuse-mc\n  sdins fuse dq-paper --grade tactical --no-gate --runs 100 --seed 1 --shard 0/2 --out mc/s0\n  sdins fuse --merge mc/s0 mc/s1 --out mc/all"
)]
pub struct Args {
    /// built-in scenario name or scenario file (or give --imu and --gnss)
    #[arg(required_unless_present_any = ["imu", "merge"], conflicts_with = "imu")]
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
    /// IMU grade preset (ideal, marine, aviation, intermediate, tactical, consumer): on a
    /// scenario the simulated IMU errors and the filter's model, on recorded data the
    /// filter's model
    #[arg(long)]
    pub grade: Option<String>,
    /// the filter's IMU model from a NaveGo imuN_params.txt (static bias known, ±10 % residual)
    #[arg(long)]
    pub navego_params: Option<PathBuf>,
    /// recorded data: the filter's IMU model (and optionally lever arm, scale-factor σ,
    /// initial attitude and σ) from your own file: sdins TOML, or KF-GINS kf-gins.yaml when
    /// the name ends in .yaml/.yml (docs/own-data.md "Your sensor model")
    #[arg(long, value_name = "FILE")]
    pub sensor_model: Option<PathBuf>,
    /// recorded data: the aiding sensors' TOML (barometer, odometer, magnetometer, dual
    /// antenna, body velocity: each record, its column map and the sensor's settings;
    /// docs/own-data.md "Aiding sensors")
    #[arg(long, value_name = "FILE")]
    pub aiding: Option<PathBuf>,
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
    /// ZUPT σ [m/s]: on scenarios when the truth is at rest, with --zupt-detector (also on
    /// recorded data) when the IMU's stationarity detector declares rest (off if absent)
    #[arg(long)]
    pub zupt_sigma_mps: Option<f64>,
    /// trigger the ZUPT by the IMU's stationarity detector (docs/theory/aiding-sensors.md
    /// "Stationarity detection") instead of the truth; needs --zupt-sigma-mps
    #[arg(long)]
    pub zupt_detector: bool,
    /// the detector's window [s] (the nearest of 10, 20, 50, 100, 200, 400 samples)
    #[arg(long, default_value_t = 0.5)]
    pub zupt_window_s: f64,
    /// the detector's false-alarm rate: probability that a window at rest is declared
    /// moving
    #[arg(long, default_value_t = 1e-3)]
    pub zupt_false_alarm: f64,
    /// non-holonomic constraint σ [m/s] (off if absent)
    #[arg(long)]
    pub nhc_sigma_mps: Option<f64>,
    /// output rows every S seconds (the updates nearest to k·S; default: scenarios the
    /// covariance interval, recorded data every navigation update)
    #[arg(long)]
    pub every_s: Option<f64>,
    /// scenario: stop after this time [s]
    #[arg(long)]
    pub until_s: Option<f64>,
    /// largest age of a measurement at its arrival [s] (older ones are refused and counted)
    #[arg(long)]
    pub max_latency_s: Option<f64>,
    /// a result that fails its health checks (NIS windows, rejected share, resets,
    /// horizontal σ, bias estimates; docs/user-guide.md "Health verdict"): `fail` writes
    /// the outputs and exits 3, `warn` only warns
    #[arg(long, value_enum, default_value_t = HealthMode::Fail)]
    pub health: HealthMode,
    /// the health verdict's largest horizontal σ [m] (default 100)
    #[arg(long, value_name = "M")]
    pub health_max_sigma: Option<f64>,
    /// scenario: a Monte Carlo of N runs (NEES per state block and NIS per measurement
    /// kind per output epoch; fuse_mc_stats.csv, fuse_mc_state.json)
    #[arg(long)]
    pub runs: Option<u64>,
    /// Monte Carlo seed of the IMU and GNSS errors (default: the scenario's [imu] seed)
    #[arg(long, requires = "runs")]
    pub seed: Option<u64>,
    /// Monte Carlo: compute shard i of n (0-based, whole blocks of runs)
    #[arg(long, requires = "runs")]
    pub shard: Option<String>,
    /// Monte Carlo: runs per block (all shards must use the same)
    #[arg(long, requires = "runs", default_value_t = 16)]
    pub block: u64,
    /// Monte Carlo with --scale-factors-ppm: draw each run's true scale factors from the
    /// filter's prior (instead of the scenario's)
    #[arg(long, requires = "runs")]
    pub draw_scale_factors: bool,
    /// Monte Carlo: worker threads (default: all cores)
    #[arg(long, requires = "runs")]
    pub threads: Option<usize>,
    /// merge the fuse Monte Carlo shard folders (or fuse_mc_state.json files) given
    #[arg(long, num_args = 1.., value_name = "DIR", conflicts_with_all = ["scenario", "imu"])]
    pub merge: Vec<PathBuf>,
    /// merge: accept an incomplete set of shards
    #[arg(long)]
    pub allow_partial: bool,
    /// no progress bar
    #[arg(long)]
    pub quiet: bool,
    /// print the summary as JSON
    #[arg(long)]
    pub json: bool,
    /// column maps of one's own files
    #[command(flatten)]
    pub columns: crate::args::ColumnsArgs,
}

/// Three comma-separated finite numbers.
pub fn triple(name: &str, s: &str) -> Result<[f64; 3], CliError> {
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

fn opt_triple(name: &str, s: &Option<String>) -> Result<Option<[f64; 3]>, CliError> {
    s.as_deref().map(|t| triple(name, t)).transpose()
}

/// A library error as the CLI reports it (bad input: exit 2; cancelled: interrupted).
pub fn run_err(e: FuseRunError) -> CliError {
    if e.is_cancelled() {
        CliError::Interrupted
    } else {
        CliError::bad(e.to_string())
    }
}

/// The typed request of the command line.
pub fn request(a: &Args) -> Result<FuseRequest, CliError> {
    let data = match (&a.imu, &a.scenario) {
        (Some(imu), _) => {
            if a.zupt_sigma_mps.is_some() && !a.zupt_detector {
                return Err(CliError::bad(
                    "--zupt-sigma-mps on recorded data needs --zupt-detector (the rest decision comes from the IMU's stationarity detector; there is no truth)",
                ));
            }
            for (flag, given) in [
                ("--in-motion", a.in_motion),
                ("--exact-start", a.exact_start),
                ("--runs", a.runs.is_some()),
                ("--until-s", a.until_s.is_some()),
            ] {
                if given {
                    return Err(CliError::bad(format!(
                        "{flag} applies to scenarios; on recorded data give --attitude-deg (the heading from the first fixes' track) or --init"
                    )));
                }
            }
            let gnss = a
                .gnss
                .clone()
                .ok_or_else(|| CliError::bad("--imu needs --gnss FILE"))?;
            FuseData::Files(FilesData {
                imu: (imu.clone(), a.imu_format.parse().map_err(CliError::bad)?),
                gnss: (gnss, a.gnss_format.parse().map_err(CliError::bad)?),
                gnss_offset_s: a.gnss_offset_s,
                navego_params: a.navego_params.clone(),
                sensor_model: a.sensor_model.clone(),
                init: a.init.clone(),
                attitude_deg: opt_triple("--attitude-deg", &a.attitude_deg)?,
                attitude_sigma_deg: opt_triple("--attitude-sigma-deg", &a.attitude_sigma_deg)?,
                static_s: a.static_s,
                lever_arm_m: opt_triple("--lever-arm-m", &a.lever_arm_m)?,
                truth: a.truth.clone(),
                columns: a.columns.resolve()?,
                aiding: a.aiding.clone(),
            })
        }
        (None, Some(name)) => {
            for (flag, given) in [
                ("--navego-params", a.navego_params.is_some()),
                ("--sensor-model", a.sensor_model.is_some()),
                ("--aiding", a.aiding.is_some()),
                ("--init", a.init.is_some()),
                ("--attitude-deg", a.attitude_deg.is_some()),
                ("--static-s", a.static_s.is_some()),
                ("--truth", a.truth.is_some()),
                ("--lever-arm-m", a.lever_arm_m.is_some()),
                (
                    "--imu-columns, --gnss-columns, --profile, …",
                    a.columns.options().any(),
                ),
            ] {
                if given {
                    return Err(CliError::bad(format!(
                        "{flag} applies to recorded data (--imu/--gnss); a scenario sets it in its [imu]/[gnss] tables"
                    )));
                }
            }
            FuseData::Scenario(ScenarioData {
                scenario: Scenario::load(name)?,
                run: a.run,
                exact_start: a.exact_start,
                in_motion: a.in_motion,
                zupt_sigma_mps: a.zupt_sigma_mps.filter(|_| !a.zupt_detector),
            })
        }
        (None, None) => {
            return Err(CliError::bad("give a scenario, or --imu FILE --gnss FILE"));
        }
    };
    let mut req = FuseRequest::new(data);
    req.grade = a.grade.clone();
    req.algo = a.algo.clone();
    req.samples = a.samples;
    req.cov_rate_hz = a.cov_rate_hz;
    req.gate = !a.no_gate;
    req.nhc_sigma_mps = a.nhc_sigma_mps;
    if a.zupt_detector {
        let sigma = a.zupt_sigma_mps.ok_or_else(|| {
            CliError::bad("--zupt-detector needs --zupt-sigma-mps S (the ZUPT's σ)")
        })?;
        req.zupt_detector = Some((
            sigma,
            sdins_sim::fusion::detector::DetectorSettings {
                window_s: a.zupt_window_s,
                false_alarm: a.zupt_false_alarm,
            },
        ));
    }
    req.smooth = a.smooth;
    req.scale_factors = a
        .scale_factors_ppm
        .as_deref()
        .map(scale_factor_prior)
        .transpose()?;
    req.every_s = a.every_s;
    req.until_s = a.until_s;
    req.max_latency_s = a.max_latency_s;
    req.health_max_sigma_m = a.health_max_sigma;
    req.check().map_err(run_err)?;
    Ok(req)
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

/// What an unhealthy result does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum HealthMode {
    /// write the outputs, then exit 3
    Fail,
    /// write the outputs and warn (exit 0)
    Warn,
}

/// The verdict in run.toml: `health_ok` and the failed checks.
pub fn health_toml(f: &mut toml::Table, h: &HealthVerdict) {
    f.insert("health_ok".into(), h.ok().into());
    let failed: Vec<toml::Value> = h.failures().into_iter().map(Into::into).collect();
    f.insert("health_failures".into(), failed.into());
}

/// The verdict in the `--json` summary.
pub fn health_json(h: &HealthVerdict) -> serde_json::Value {
    serde_json::json!({
        "ok": h.ok(),
        "checks": h.checks.iter().map(|c| serde_json::json!({
            "name": c.name, "passed": c.passed, "detail": c.detail,
        })).collect::<Vec<_>>(),
    })
}

/// The end of a run whose outputs are written: each failed check on stderr, then exit 3
/// (`--health fail`) or a warning (`--health warn`).
pub fn health_end(args: &Args, h: &HealthVerdict, out: &std::path::Path) -> Result<(), CliError> {
    if h.ok() {
        return Ok(());
    }
    let what = match args.health {
        HealthMode::Fail => "health",
        HealthMode::Warn => "warning: health",
    };
    for f in h.failures() {
        eprintln!("{what}: {f}");
    }
    match args.health {
        HealthMode::Warn => Ok(()),
        HealthMode::Fail => Err(CliError::ResultFailedChecks(format!(
            "the solution failed its health checks (above); the outputs are written in {} (exit 3; --health warn accepts the result)",
            out.display()
        ))),
    }
}

/// The measurement tallies in run.toml (`[measurements.KIND]` applied/rejected/late) and
/// the `--json` summary, and their one-line text (kinds other than GNSS).
pub fn measurements_toml(f: &mut toml::Table, m: &[KindTally]) {
    let mut t = toml::Table::new();
    for k in m {
        let mut e = toml::Table::new();
        e.insert("applied".into(), (k.applied as i64).into());
        e.insert("rejected".into(), (k.rejected as i64).into());
        e.insert("late".into(), (k.late as i64).into());
        t.insert(k.kind.name().into(), e.into());
    }
    f.insert("measurements".into(), t.into());
}

/// The tallies as JSON (`{"odometer": {"applied": …, "rejected": …, "late": …}, …}`).
pub fn measurements_json(m: &[KindTally]) -> serde_json::Value {
    let mut o = serde_json::Map::new();
    for k in m {
        o.insert(
            k.kind.name().into(),
            serde_json::json!({"applied": k.applied, "rejected": k.rejected, "late": k.late}),
        );
    }
    o.into()
}

/// `"; odometer 3000 (2 rejected), zupt 240"`: the kinds other than GNSS, empty without.
pub fn measurements_text(m: &[KindTally]) -> String {
    let parts: Vec<String> = m
        .iter()
        .filter(|k| k.kind != MeasKind::Gnss)
        .map(|k| {
            let mut s = format!("{} {}", k.kind.name(), k.applied);
            if k.rejected > 0 {
                s.push_str(&format!(" ({} rejected)", k.rejected));
            }
            if k.late > 0 {
                s.push_str(&format!(" ({} late)", k.late));
            }
            s
        })
        .collect();
    if parts.is_empty() {
        String::new()
    } else {
        format!("; {}", parts.join(", "))
    }
}
