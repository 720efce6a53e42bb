//! `sdins calibrate`: simulated turntable calibration of a scenario's IMU
//! (docs/theory/calibration.md): the least-squares estimate of the 24 bias, scale-factor
//! and misalignment parameters with 1σ, against the truth, and (with `--runs N`) the Monte
//! Carlo consistency (mean NEES and its χ² band) and the largest errors per group.
//!
//! With `--imu FILE` the scenario gives only the schedule (site, start attitude, rotations,
//! sample rate) and the file the measured increments: the estimate with 1σ, no truth.
//!
//! Outputs in `--out` (if given): `calibration.csv` (one row per parameter; with
//! `--runs`, the first run), `calibration_runs.csv` (per run: NEES and max errors),
//! `calibration.json` (the same as `--json`), `report.html` and `run.toml`.

use crate::args::ImuFormatArg;
use crate::error::CliError;
use crate::output::write_string;
use sdins_sim::align::calibration::request::{calibrate, CalibrateRequest, CalibrateResult};
use sdins_sim::align::calibration::run::{group_errors, CalibrationError, MonteCarloSummary};
use sdins_sim::align::calibration::table::ParamRow;
use sdins_sim::align::calibration::DrawSpec;
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::imu_error::{DPH, UG};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `sdins calibrate`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:\n  sdins calibrate calibration\n  \
    sdins calibrate calibration --runs 20 --out cal-mc\n  \
    sdins scenarios calibration > my-cal.toml\n  sdins calibrate my-cal.toml --no-draw --json\n  \
    sdins truth calibration --out cal-imu --every 100 --quiet\n  \
    sdins calibrate calibration --imu cal-imu/imu.csv --imu-format sdins")]
pub struct Args {
    /// scenario (built-in name or file), normally with a [calibration] schedule
    pub scenario: String,
    /// recorded IMU file of the schedule (sdins CSV, PSINS .imu, KF-GINS text, ...): one
    /// sample per truth sample of the scenario, at its rate
    #[arg(long)]
    pub imu: Option<PathBuf>,
    #[command(flatten)]
    pub imu_format: ImuFormatArg,
    /// error-model run index of a single run
    #[arg(long, default_value_t = 0)]
    pub run: u64,
    /// number of Monte Carlo runs (indices 0..N; 1 = the single run --run)
    #[arg(long, default_value_t = 1)]
    pub runs: usize,
    /// drawn scale-factor magnitudes LO,HI [ppm] (random sign, every axis, every run)
    #[arg(long, default_value = "100,1000", allow_hyphen_values = true)]
    pub draw_scale_ppm: String,
    /// drawn misalignment magnitudes LO,HI [mrad] (random sign, every off-diagonal entry)
    #[arg(long, default_value = "0.1,1", allow_hyphen_values = true)]
    pub draw_misalignment_mrad: String,
    /// keep the scenario's own scale factors and misalignments ([imu.errors]) instead of
    /// drawing them
    #[arg(long)]
    pub no_draw: bool,
    /// output folder
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// print a JSON summary on stdout
    #[arg(long)]
    pub json: bool,
}

fn pair(option: &str, s: &str) -> Result<(f64, f64), CliError> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let bad = || {
        CliError::bad(format!(
            "--{option}: `{s}` must be two finite numbers LO,HI with 0 ≤ LO ≤ HI"
        ))
    };
    let [a, b] = parts.as_slice() else {
        return Err(bad());
    };
    let (lo, hi): (f64, f64) = (a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?);
    if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi) {
        return Err(bad());
    }
    Ok((lo, hi))
}

impl Args {
    /// The draw of these options (`None` with `--no-draw`), validated.
    fn draw(&self) -> Result<Option<DrawSpec>, CliError> {
        let scale = pair("draw-scale-ppm", &self.draw_scale_ppm)?;
        let mis = pair("draw-misalignment-mrad", &self.draw_misalignment_mrad)?;
        Ok((!self.no_draw).then_some(DrawSpec {
            scale_ppm: scale,
            misalignment_mrad: mis,
        }))
    }
}

fn cal_error(e: CalibrationError) -> CliError {
    match e {
        CalibrationError::Cancelled(_) => CliError::Interrupted,
        CalibrationError::ImuIo(m) => CliError::Other(m),
        CalibrationError::Draw { key, what } => {
            CliError::BadInput(format!("--draw-{}: {what}", key.replace('_', "-")))
        }
        other => CliError::BadInput(other.to_string()),
    }
}

fn params_csv(rows: &[ParamRow]) -> String {
    let mut s = String::from("parameter,unit,estimate,sigma,truth,error,normalised_error\n");
    for r in rows {
        let t = r.truth.map_or(String::new(), |t| format!("{t:.9e}"));
        let e = r
            .truth
            .map_or(String::new(), |t| format!("{:.9e}", r.estimate - t));
        let n = r
            .normalised_error()
            .map_or(String::new(), |x| format!("{x:.4}"));
        let _ = writeln!(
            s,
            "{},{},{:.9e},{:.9e},{t},{e},{n}",
            r.name, r.unit, r.estimate, r.sigma
        );
    }
    s
}

fn param_table(rows: &[ParamRow]) -> Vec<Vec<String>> {
    rows.iter()
        .map(|r| {
            let prec = if r.unit == "mrad" || r.unit == "deg/h" {
                5
            } else {
                2
            };
            vec![
                r.name.clone(),
                r.unit.to_string(),
                format!("{:.prec$}", r.estimate),
                format!("{:.prec$}", r.sigma),
                r.truth.map_or(String::new(), |t| format!("{t:.prec$}")),
                r.normalised_error()
                    .map_or(String::new(), |x| format!("{x:+.2}")),
            ]
        })
        .collect()
}

fn mc_rows(m: &MonteCarloSummary) -> Vec<Vec<String>> {
    vec![
        vec![
            "gyro".into(),
            format!("{:.5} °/h", m.gyro_max.bias),
            format!("{:.3}", m.gyro_max.scale_ppm),
            format!("{:.5}", m.gyro_max.misalignment_mrad),
        ],
        vec![
            "accelerometer".into(),
            format!("{:.3} μg", m.accel_max.bias),
            format!("{:.3}", m.accel_max.scale_ppm),
            format!("{:.5}", m.accel_max.misalignment_mrad),
        ],
    ]
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.imu_format.imu_columns.is_some() || args.imu_format.profile.is_some() {
        return Err(CliError::bad(
            "--imu-columns/--profile: calibrate does not read column maps yet: convert the file to sdins's imu.csv",
        ));
    }
    let scn = Scenario::load(&args.scenario)?;
    let req = CalibrateRequest {
        imu: args.imu.clone(),
        imu_format: args.imu_format.imu_format,
        run: args.run,
        runs: args.runs,
        draw: args.draw()?,
    };
    let res = calibrate(&scn, &req, &crate::progress::token()).map_err(cal_error)?;
    for w in &res.warnings {
        eprintln!("warning: {w}");
    }
    finish(&args, &scn, &res)
}

/// Write the outputs and print the table.
fn finish(args: &Args, scn: &Scenario, o: &CalibrateResult) -> Result<(), CliError> {
    let (json, note) = (o.summary_json(scn), &o.note);
    if let Some(dir) = &args.out {
        crate::output::claim(dir)?;
        write_string(&dir.join("calibration.csv"), &params_csv(&o.rows))?;
        if !o.all.is_empty() {
            let mut s = String::from(
                "run,nees,gyro_bias_dph,gyro_scale_ppm,gyro_misalignment_mrad,accel_bias_ug,accel_scale_ppm,accel_misalignment_mrad\n",
            );
            for r in &o.all {
                let g = group_errors(&r.gyro, &r.gyro_truth, DPH);
                let a = group_errors(&r.accel, &r.accel_truth, UG);
                let _ = writeln!(
                    s,
                    "{},{:.6},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
                    r.run,
                    r.nees,
                    g.bias,
                    g.scale_ppm,
                    g.misalignment_mrad,
                    a.bias,
                    a.scale_ppm,
                    a.misalignment_mrad
                );
            }
            write_string(&dir.join("calibration_runs.csv"), &s)?;
        }
        write_string(
            &dir.join("calibration.json"),
            &serde_json::to_string_pretty(&json).map_err(|e| CliError::Other(e.to_string()))?,
        )?;
        write_report(dir, args, scn, o, note)?;
        let mut t = toml::Table::new();
        t.insert("scenario_name".into(), scn.name.clone().into());
        t.insert(
            "scenario".into(),
            crate::provenance::scenario_text(&args.scenario).into(),
        );
        t.insert("seed".into(), scn.imu.seed.to_string().into());
        if let Some(p) = &args.imu {
            let abs = std::fs::canonicalize(p).unwrap_or_else(|_| p.clone());
            t.insert("imu_file".into(), abs.display().to_string().into());
            t.insert(
                "imu_format".into(),
                args.imu_format.imu_format.name().into(),
            );
        } else {
            t.insert("run".into(), args.run.to_string().into());
            t.insert("runs".into(), args.runs.to_string().into());
            t.insert("draw".into(), (!args.no_draw).into());
            t.insert("draw_scale_ppm".into(), args.draw_scale_ppm.clone().into());
            t.insert(
                "draw_misalignment_mrad".into(),
                args.draw_misalignment_mrad.clone().into(),
            );
        }
        crate::report::write_run_toml(dir, t)?;
    }
    if args.json {
        outln!("{json}");
        return Ok(());
    }
    outln!(
        "{}: {} samples at {} Hz ({:.0} s); {note}",
        scn.name,
        o.samples,
        scn.imu.rate_hz,
        scn.duration_s(),
    );
    outln!(
        "{:<8} {:>6} {:>14} {:>12} {:>14} {:>8}",
        "param",
        "unit",
        "estimate",
        "1σ",
        "truth",
        "err/σ"
    );
    for r in param_table(&o.rows) {
        outln!(
            "{:<8} {:>6} {:>14} {:>12} {:>14} {:>8}",
            r[0],
            r[1],
            r[2],
            r[3],
            r[4],
            r[5]
        );
    }
    if let Some(m) = &o.mc {
        outln!(
            "Monte Carlo, {} runs: mean NEES {:.2} (95 % band of χ²(24·{0})/{0}: [{:.2}, {:.2}])",
            m.runs,
            m.mean_nees,
            m.nees_band.0,
            m.nees_band.1
        );
        outln!("max |error| over runs and axes: bias, scale [ppm], misalignment [mrad]");
        for r in mc_rows(m) {
            outln!("  {:<14} {:>14} {:>10} {:>10}", r[0], r[1], r[2], r[3]);
        }
    }
    if let Some(d) = &args.out {
        outln!(
            "wrote {0}/calibration.csv, {0}/calibration.json, {0}/report.html, {0}/run.toml{1}",
            d.display(),
            if o.all.is_empty() {
                String::new()
            } else {
                format!(", {}/calibration_runs.csv", d.display())
            }
        );
    }
    Ok(())
}

fn write_report(
    dir: &std::path::Path,
    args: &Args,
    scn: &Scenario,
    o: &CalibrateResult,
    note: &str,
) -> Result<(), CliError> {
    let mut r = crate::report::Report::new(&format!("sdins calibrate: {}", scn.name));
    let source = match &args.imu {
        Some(p) => format!("recorded IMU file {} on the schedule of the scenario", p.display()),
        None if args.no_draw => "simulated; scale factors and misalignments as in the scenario".to_string(),
        None => format!(
            "simulated; scale factors and misalignments drawn per run: {} ppm, {} mrad, random signs",
            args.draw_scale_ppm, args.draw_misalignment_mrad
        ),
    };
    r.para(&format!(
        "Scenario {}: {} samples at {} Hz ({:.0} s), {source}. Model f̃ = b + (I + K) f + n per \
         sample (docs/theory/calibration.md): K has the scale-factor errors on its diagonal and \
         the misalignments (output axis i per true axis j, full 3×3, body = table frame) off it. \
         Least squares over every sample with the covariance of the white-noise densities.",
        scn.name,
        o.samples,
        scn.imu.rate_hz,
        scn.duration_s(),
    ));
    r.heading("Estimate");
    r.para(note);
    r.table(
        &[
            "parameter",
            "unit",
            "estimate",
            "1σ",
            "truth",
            "(est − truth)/σ",
        ],
        &param_table(&o.rows),
    );
    if let Some(m) = &o.mc {
        r.heading(&format!("Monte Carlo: {} runs", m.runs));
        r.para(&format!(
            "Mean NEES of the 24-vector {:.2}; two-sided 95 % band of χ²(24·{n})/{n}: [{:.2}, {:.2}].",
            m.mean_nees,
            m.nees_band.0,
            m.nees_band.1,
            n = m.runs
        ));
        r.table(
            &[
                "sensor",
                "max |bias error|",
                "max |scale error| [ppm]",
                "max |misalignment error| [mrad]",
            ],
            &mc_rows(m),
        );
    }
    if let Some(f) = o.first.as_ref().filter(|f| !f.unmodelled.is_empty()) {
        r.para(&format!(
            "Warning: the IMU model has terms the estimator does not model ({}): the 1σ is optimistic.",
            f.unmodelled.join(", ")
        ));
    }
    r.write(&dir.join("report.html"))
}
