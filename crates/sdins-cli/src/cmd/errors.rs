//! `sdins errors`: analytic INS error propagation.
//!
//! Prints the full stationary closed form (spec `alignment_and_errors.md` §4.3) for a
//! set of NED sensor biases, next to the 15-state linear model's deterministic error and
//! 1σ covariance envelope, at a few epochs; or, with `--schuler-share`, the
//! reconstruction of \[P2\] Table 1 (spec §4.4).
//!
//! Examples:
//! ```text
//! sdins errors --grade aviation --hours 24
//! sdins errors --gyro-bias-dph 0,0.01,0 --accel-bias-ug 30,0,0 --lat 37.5 --json
//! sdins errors --schuler-share --json
//! ```

use crate::error::CliError;
use sdins_core::Vec3;
use sdins_sim::error_analysis::grades::{grade_by_name, Grade, GRADES};
use sdins_sim::error_analysis::linear_model::{
    propagate, stationary_samples, EnvelopePoint, ErrorVector, ModelEarth, ModelOptions,
    ProcessNoise, VerticalChannel,
};
use sdins_sim::error_analysis::nonlinear::NonlinearRun;
use sdins_sim::error_analysis::periods::SchulerParams;
use sdins_sim::error_analysis::schuler_share::{schuler_share_table_p2, ShareRow, T_STAR_S};
use sdins_sim::error_analysis::stationary::{
    StationaryClosedForm, StationaryErrors, StationarySolution,
};
use sdins_sim::error_analysis::{DEG_PER_HOUR, MICRO_G};

/// Arguments of `sdins errors`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  sdins errors --grade aviation --hours 24\n  \
    sdins errors --gyro-bias-dph 0,0.01,0 --accel-bias-ug 30,0,0 --json\n  \
    sdins errors --schuler-share --json"
)]
pub struct Args {
    /// sensor grade (the grade table of docs/imu-errors.md: marine, aviation, intermediate,
    /// tactical, consumer): its turn-on bias σ on every NED axis, and its ARW/VRW for the
    /// covariance envelope
    #[arg(long, conflicts_with_all = ["gyro_bias_dph", "accel_bias_ug"])]
    pub grade: Option<String>,
    /// NED gyro bias [°/h] as N,E,D
    #[arg(long, value_delimiter = ',', num_args = 1, allow_hyphen_values = true)]
    pub gyro_bias_dph: Option<Vec<f64>>,
    /// NED accelerometer bias [μg] as N,E,D
    #[arg(long, value_delimiter = ',', num_args = 1, allow_hyphen_values = true)]
    pub accel_bias_ug: Option<Vec<f64>>,
    /// duration [h] (0 < H ≤ 240)
    #[arg(long, default_value_t = 24.0)]
    pub hours: f64,
    /// latitude [deg] (|lat| ≤ 89)
    #[arg(long, default_value_t = 37.5, allow_hyphen_values = true)]
    pub lat: f64,
    /// print the Schuler-share table (reconstruction of [P2] Table 1) instead
    #[arg(long)]
    pub schuler_share: bool,
    /// skip the nonlinear simulation column
    #[arg(long)]
    pub no_nonlinear: bool,
    /// JSON output on stdout
    #[arg(long)]
    pub json: bool,
    /// output folder: errors.csv, report.html (tables, error and budget plots), errors.png,
    /// budget.png, run.toml [default: sdins-out/errors]
    #[arg(long)]
    pub out: Option<std::path::PathBuf>,
}

/// Linear-model step [s] (see `linear_model` docs: Taylor-3 is accurate to < 1e-4 rad of
/// Schuler phase over 24 h at this step).
const DT_S: f64 = 10.0;

/// One output epoch.
#[derive(serde::Serialize)]
struct Epoch {
    t_h: f64,
    closed_form: StationarySolution,
    linear: EnvelopePoint,
    /// the nonlinear free-inertial simulation at this epoch (`null` with `--no-nonlinear`)
    nonlinear: Option<NonlinearPoint>,
}

/// Nonlinear-simulation errors at one epoch.
#[derive(serde::Serialize, Clone, Copy)]
struct NonlinearPoint {
    /// position error N, E, D \[m\]
    dp_n_m: [f64; 3],
    /// attitude error ε (convention G) \[rad\]
    phi: [f64; 3],
}

/// The nonlinear column: a full nonlinear free-inertial run
/// ([`NonlinearRun`], spec §6 T9 set-up): stationary, body = NED at `lat_rad` (so the NED
/// biases are the body biases, injected as a custom `ImuErrorModel` with fixed
/// `gyro_bias_dph`/`accel_bias_ug`), spherical earth with the closed form's constants
/// (R0, g, Ω), 20 Hz IMU, `songlee-complete` with N = 2, vertical channel held; run once
/// to the last epoch and read at every epoch of `hours`.
fn nonlinear_column(
    lat_rad: f64,
    params: &SchulerParams,
    gyro_dph: &Vec3,
    accel_ug: &Vec3,
    hours: &[f64],
) -> Result<Vec<Option<NonlinearPoint>>, CliError> {
    let last = hours.iter().copied().fold(0.0, f64::max);
    let mut run = NonlinearRun::stationary(lat_rad, params, last * 3600.0);
    run.gyro_bias_dph = (*gyro_dph).into();
    run.accel_bias_ug = (*accel_ug).into();
    let errs = run.run().map_err(|e| CliError::Other(e.to_string()))?;
    Ok(hours
        .iter()
        .map(|h| {
            let t = h * 3600.0;
            errs.iter()
                .min_by(|a, b| (a.t_s - t).abs().total_cmp(&(b.t_s - t).abs()))
                .filter(|e| (e.t_s - t).abs() <= 0.5 * run.every_s + 1e-6)
                .map(|e| NonlinearPoint {
                    dp_n_m: e.pos_err_ned_m,
                    phi: e.att_err_rad,
                })
        })
        .collect())
}

#[derive(serde::Serialize)]
struct Report<'a> {
    lat_deg: f64,
    hours: f64,
    grade: Option<&'a str>,
    gyro_bias_dph_ned: [f64; 3],
    accel_bias_ug_ned: [f64; 3],
    params: SchulerParams,
    epochs: Vec<Epoch>,
}

fn vec3(name: &str, v: &Option<Vec<f64>>) -> Result<Vec3, CliError> {
    match v {
        None => Ok(Vec3::zeros()),
        Some(x) if x.len() == 3 && x.iter().all(|a| a.is_finite()) => {
            Ok(Vec3::new(x[0], x[1], x[2]))
        }
        Some(x) => Err(CliError::bad(format!(
            "--{name}: expected three finite numbers N,E,D, got {x:?}"
        ))),
    }
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.schuler_share {
        return print_share(args.json);
    }
    if !(args.hours.is_finite() && args.hours > 0.0 && args.hours <= 240.0) {
        return Err(CliError::bad(format!(
            "--hours: must be in (0, 240], got {}",
            args.hours
        )));
    }
    if !(args.lat.is_finite() && args.lat.abs() <= 89.0) {
        return Err(CliError::bad(format!(
            "--lat: must be within ±89°, got {}",
            args.lat
        )));
    }
    let grade: Option<&Grade> = match &args.grade {
        Some(name) => Some(grade_by_name(name).ok_or_else(|| {
            let names: Vec<&str> = GRADES.iter().map(|g| g.name).collect();
            CliError::bad(format!(
                "--grade: unknown grade {name:?} (known: {})",
                names.join(", ")
            ))
        })?),
        None => None,
    };
    let (gyro_dph, accel_ug) = match grade {
        Some(g) => (
            Vec3::repeat(g.gyro_bias_turn_on_dph),
            Vec3::repeat(g.accel_bias_turn_on_ug),
        ),
        None => (
            vec3("gyro-bias-dph", &args.gyro_bias_dph)?,
            vec3("accel-bias-ug", &args.accel_bias_ug)?,
        ),
    };
    if grade.is_none() && args.gyro_bias_dph.is_none() && args.accel_bias_ug.is_none() {
        return Err(CliError::bad(
            "give --grade, --gyro-bias-dph/--accel-bias-ug, or --schuler-share",
        ));
    }
    let lat = args.lat.to_radians();
    let earth = sdins_core::earth::EarthModel::WGS84;
    let params = SchulerParams::with_local_gravity(&earth, lat, 0.0);
    let errors = StationaryErrors {
        eps_n: gyro_dph * DEG_PER_HOUR,
        da_n: accel_ug * MICRO_G,
        ..Default::default()
    };
    let closed = StationaryClosedForm::new(lat, &errors, params);

    // linear model on the same spherical earth: deterministic error from the biases, and a
    // 1σ envelope with the biases as 1σ bias uncertainty plus the grade's ARW/VRW
    let opts = ModelOptions {
        earth: ModelEarth::Spherical(params),
        vertical: VerticalChannel::Held,
        bias_states: true,
    };
    let duration = args.hours * 3600.0;
    let samples = stationary_samples(lat, 0.0, duration, DT_S, &opts.earth);
    let ev = ErrorVector {
        b_a: errors.da_n,
        b_g: errors.eps_n,
        ..Default::default()
    };
    let s0 = samples
        .first()
        .copied()
        .ok_or_else(|| CliError::Other("no samples".into()))?;
    let x0 = ev.to_state(&s0, &opts.earth);
    let p0 = ev.to_diag_covariance(&s0, &opts.earth);
    let noise = grade
        .map(|g| ProcessNoise {
            arw_rad_per_sqrt_s: Vec3::repeat(g.arw_si()),
            vrw_mps_per_sqrt_s: Vec3::repeat(g.vrw_si()),
            ..Default::default()
        })
        .unwrap_or_default();
    let env =
        propagate(&samples, &opts, &noise, &x0, &p0).map_err(|e| CliError::Other(e.to_string()))?;

    let mut hours: Vec<f64> = [0.5, 1.0, 2.0, 4.0, 6.0, 12.0, 24.0, 48.0, 96.0, 168.0]
        .into_iter()
        .filter(|h| *h < args.hours - 1e-9)
        .collect();
    hours.push(args.hours);
    let nonlinear = if args.no_nonlinear {
        vec![None; hours.len()]
    } else {
        nonlinear_column(lat, &params, &gyro_dph, &accel_ug, &hours)?
    };
    let epochs: Vec<Epoch> = hours
        .iter()
        .zip(nonlinear)
        .map(|(&h, nonlinear)| {
            let t = h * 3600.0;
            let k = ((t / DT_S).round() as usize).min(env.len().saturating_sub(1));
            let linear = env.get(k).copied().unwrap_or_default();
            Epoch {
                t_h: h,
                closed_form: closed.eval(t),
                linear,
                nonlinear,
            }
        })
        .collect();

    let report = Report {
        lat_deg: args.lat,
        hours: args.hours,
        grade: grade.map(|g| g.name),
        gyro_bias_dph_ned: gyro_dph.into(),
        accel_bias_ug_ned: accel_ug.into(),
        params,
        epochs,
    };
    if args.json {
        let s =
            serde_json::to_string_pretty(&report).map_err(|e| CliError::Other(e.to_string()))?;
        println!("{s}");
    } else {
        print_table(&report);
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| std::path::PathBuf::from("sdins-out/errors"));
    crate::output::claim(&out)?;
    let budget = error_budget(lat, params, &gyro_dph, &accel_ug, duration);
    write_folder(&out, &args, &report, &closed, &env, &budget)?;
    eprintln!(
        "wrote {0}/errors.csv, {0}/errors.png, {0}/budget.png, {0}/report.html, {0}/run.toml",
        out.display()
    );
    Ok(())
}

/// One error source's share of the final position error.
#[derive(Clone, Debug, PartialEq)]
pub struct BudgetRow {
    /// source name, e.g. `gyro bias E`
    pub source: String,
    /// the source's value with unit
    pub value: String,
    /// its position error N, E at the final time \[m\]
    pub dp_ne_m: [f64; 2],
}

/// Error budget at `t_s`: the closed form (docs/theory/error-analysis.md) with one nonzero bias component at a
/// time. The closed form is linear in the errors, so the rows add up (as vectors) to the
/// all-sources error.
pub fn error_budget(
    lat_rad: f64,
    params: SchulerParams,
    gyro_dph: &Vec3,
    accel_ug: &Vec3,
    t_s: f64,
) -> Vec<BudgetRow> {
    let axes = ["N", "E", "D"];
    let mut rows = Vec::new();
    for k in 0..3 {
        for (gyro, v) in [(true, gyro_dph[k]), (false, accel_ug[k])] {
            if v == 0.0 {
                continue;
            }
            let mut e = StationaryErrors::default();
            let (source, value) = if gyro {
                e.eps_n[k] = v * DEG_PER_HOUR;
                (format!("gyro bias {}", axes[k]), format!("{v} °/h"))
            } else {
                e.da_n[k] = v * MICRO_G;
                (format!("accel bias {}", axes[k]), format!("{v} μg"))
            };
            let dp = StationaryClosedForm::new(lat_rad, &e, params)
                .eval(t_s)
                .dp_n;
            rows.push(BudgetRow {
                source,
                value,
                dp_ne_m: [dp[0], dp[1]],
            });
        }
    }
    rows
}

/// errors.csv, the figures, report.html and run.toml of `sdins errors`.
fn write_folder(
    out: &std::path::Path,
    args: &Args,
    r: &Report<'_>,
    closed: &StationaryClosedForm,
    env: &[EnvelopePoint],
    budget: &[BudgetRow],
) -> Result<(), CliError> {
    use crate::plot::{Band, Bars, Figure, Panel, Series};
    // time histories: closed form and linear model on the linear model's grid (≤ 400 points)
    let stride = (env.len() / 400).max(1);
    let pts: Vec<(f64, StationarySolution, &EnvelopePoint)> = env
        .iter()
        .step_by(stride)
        .map(|e| (e.t_s, closed.eval(e.t_s), e))
        .collect();
    let mut csv = String::from(
        "t_s,dp_n_closed_m,dp_e_closed_m,dp_n_linear_m,dp_e_linear_m,sigma_p_n_m,sigma_p_e_m,phi_d_closed_rad,sigma_phi_d_rad\n",
    );
    for (t, c, e) in &pts {
        csv.push_str(&format!(
            "{t},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}\n",
            c.dp_n[0],
            c.dp_n[1],
            e.dp_n_m[0],
            e.dp_n_m[1],
            e.sigma_p_m[0],
            e.sigma_p_m[1],
            c.phi[2],
            e.sigma_phi[2]
        ));
    }
    crate::output::write_string(&out.join("errors.csv"), &csv)?;
    let h = |t: f64| t / 3600.0;
    let line = |name: &str, f: &dyn Fn(&(f64, StationarySolution, &EnvelopePoint)) -> f64| {
        Series::line(name, pts.iter().map(|p| (h(p.0), f(p))).collect())
    };
    let panel = |axis: usize, title: &str| Panel {
        title: title.to_string(),
        x_label: "time [h]".into(),
        y_label: "position error [m]".into(),
        bands: vec![Band {
            name: "linear model ± 1σ".into(),
            color_of: "linear model".into(),
            points: pts
                .iter()
                .map(|p| {
                    let s = p.2.sigma_p_m[axis];
                    (h(p.0), p.2.dp_n_m[axis] - s, p.2.dp_n_m[axis] + s)
                })
                .collect(),
        }],
        series: vec![
            line("closed form", &|p| p.1.dp_n[axis]),
            line("linear model", &|p| p.2.dp_n_m[axis]),
        ],
        ..Panel::default()
    };
    let fig = Figure {
        panels: vec![
            panel(0, "north position error"),
            panel(1, "east position error"),
        ],
        cols: 2,
        size: (1200, 450),
    };
    let bars = Bars {
        title: format!(
            "error budget: horizontal position error at {:.3} h",
            r.hours
        ),
        y_label: "|δp_horizontal| [m]".into(),
        bars: budget
            .iter()
            .map(|b| (b.source.clone(), b.dp_ne_m[0].hypot(b.dp_ne_m[1])))
            .collect(),
        size: (900, 420),
    };

    let mut rep = crate::report::Report::new("sdins errors");
    rep.para(&format!(
        "Stationary free-inertial error propagation at L = {:.3}°, vertical channel held, {} h; NED gyro bias {:?} °/h, accelerometer bias {:?} μg{}.",
        r.lat_deg,
        r.hours,
        r.gyro_bias_dph_ned,
        r.accel_bias_ug_ned,
        r.grade.map(|g| format!(" (grade {g})")).unwrap_or_default()
    ));
    let rows: Vec<Vec<String>> = r
        .epochs
        .iter()
        .map(|e| {
            let nl = |k: usize| {
                e.nonlinear
                    .map_or("—".to_string(), |n| format!("{:.1}", n.dp_n_m[k]))
            };
            vec![
                format!("{:.2}", e.t_h),
                format!("{:.1}", e.closed_form.dp_n[0]),
                format!("{:.1}", e.closed_form.dp_n[1]),
                nl(0),
                nl(1),
                format!("{:.1}", e.linear.dp_n_m[0]),
                format!("{:.1}", e.linear.dp_n_m[1]),
                format!("{:.1}", e.linear.sigma_p_m[0]),
                format!("{:.1}", e.linear.sigma_p_m[1]),
            ]
        })
        .collect();
    rep.table(
        &[
            "t [h]",
            "δN closed [m]",
            "δE closed [m]",
            "δN nonlinear [m]",
            "δE nonlinear [m]",
            "δN linear [m]",
            "δE linear [m]",
            "1σ N [m]",
            "1σ E [m]",
        ],
        &rows,
    );
    rep.figure_file(
        &fig,
        out,
        "errors",
        "Position error vs time: closed form (docs/theory/error-analysis.md), 15-state linear model, and its 1σ envelope (biases as 1σ uncertainty plus the grade's noise).",
    )?;
    let brows: Vec<Vec<String>> = budget
        .iter()
        .map(|b| {
            vec![
                b.source.clone(),
                b.value.clone(),
                format!("{:.1}", b.dp_ne_m[0]),
                format!("{:.1}", b.dp_ne_m[1]),
                format!("{:.1}", b.dp_ne_m[0].hypot(b.dp_ne_m[1])),
            ]
        })
        .collect();
    rep.heading("Error budget");
    rep.table(&["source", "value", "δN [m]", "δE [m]", "|δp| [m]"], &brows);
    rep.bars_file(
        &bars,
        out,
        "budget",
        "Each source alone through the closed form at the final time (the closed form is linear: the rows add up as vectors to the all-sources error).",
    )?;
    rep.write(&out.join("report.html"))?;

    let mut t = toml::Table::new();
    t.insert("lat_deg".into(), args.lat.into());
    t.insert("hours".into(), args.hours.into());
    if let Some(g) = &args.grade {
        t.insert("grade".into(), g.clone().into());
    }
    t.insert(
        "gyro_bias_dph_ned".into(),
        r.gyro_bias_dph_ned.to_vec().into(),
    );
    t.insert(
        "accel_bias_ug_ned".into(),
        r.accel_bias_ug_ned.to_vec().into(),
    );
    t.insert("nonlinear".into(), (!args.no_nonlinear).into());
    crate::report::write_run_toml(out, t)
}

fn print_table(r: &Report<'_>) {
    println!(
        "Stationary free-inertial errors, L = {:.3}°, vertical channel held, R0 = {:.0} m, g = {:.6} m/s²",
        r.lat_deg, r.params.r0_m, r.params.g_mps2
    );
    println!(
        "NED gyro bias [°/h] = {:?}, accel bias [μg] = {:?}{}",
        r.gyro_bias_dph_ned,
        r.accel_bias_ug_ned,
        r.grade
            .map(|g| format!(" (grade {g}, turn-on bias σ, ARW/VRW in σ)"))
            .unwrap_or_default()
    );
    println!(
        "closed = closed form of docs/theory/error-analysis.md; nonlin = nonlinear INS (body = NED, spherical earth R0/g, 20 Hz, songlee-complete, vertical held);\nlinear = 15-state model (same biases); 1σ = covariance with the biases as 1σ"
    );
    println!(
        "{:>6} | {:>10} {:>10} | {:>10} {:>10} | {:>10} {:>10} | {:>9} {:>9} | {:>9} {:>9} {:>9}",
        "t [h]",
        "dpN clsd",
        "dpE clsd",
        "dpN nonlin",
        "dpE nonlin",
        "dpN lin",
        "dpE lin",
        "1σ N",
        "1σ E",
        "φD [mrad]",
        "φD nonlin",
        "1σ φD"
    );
    for e in &r.epochs {
        let nl = |f: &dyn Fn(&NonlinearPoint) -> String| {
            e.nonlinear
                .as_ref()
                .map(f)
                .unwrap_or_else(|| "—".to_string())
        };
        println!(
            "{:>6.2} | {:>10.1} {:>10.1} | {:>10} {:>10} | {:>10.1} {:>10.1} | {:>9.1} {:>9.1} | {:>9.4} {:>9} {:>9.4}",
            e.t_h,
            e.closed_form.dp_n[0],
            e.closed_form.dp_n[1],
            nl(&|n| format!("{:.1}", n.dp_n_m[0])),
            nl(&|n| format!("{:.1}", n.dp_n_m[1])),
            e.linear.dp_n_m[0],
            e.linear.dp_n_m[1],
            e.linear.sigma_p_m[0],
            e.linear.sigma_p_m[1],
            e.closed_form.phi[2] * 1e3,
            nl(&|n| format!("{:.4}", n.phi[2] * 1e3)),
            e.linear.sigma_phi[2] * 1e3
        );
    }
}

fn print_share(json: bool) -> Result<(), CliError> {
    let rows: Vec<ShareRow> = schuler_share_table_p2();
    if json {
        let s = serde_json::to_string_pretty(&rows).map_err(|e| CliError::Other(e.to_string()))?;
        println!("{s}");
        return Ok(());
    }
    println!(
        "Schuler share (reconstruction of [P2] Table 1, docs/theory/error-analysis.md): t* = {T_STAR_S} s, L = 37.5°, R0 = 6371 km, g = 9.80665"
    );
    println!(
        "{:>13} {:>10} {:>10} {:>10} {:>14}",
        "grade", "accel [μg]", "gyro [°/h]", "share [%]", "paper [%]"
    );
    for r in &rows {
        let paper = grade_by_name(&r.grade)
            .and_then(|g| g.p2.map(|b| b.share_pct))
            .map(|(a, b)| format!("{a:.1}–{b:.1}"))
            .unwrap_or_default();
        println!(
            "{:>13} {:>10.1} {:>10.4} {:>10.2} {:>14}",
            r.grade, r.accel_bias_ug, r.gyro_bias_dph, r.share_pct, paper
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args() -> Args {
        Args {
            grade: None,
            gyro_bias_dph: Some(vec![0.0, 0.01, 0.0]),
            accel_bias_ug: None,
            hours: 2.0,
            lat: 37.5,
            schuler_share: false,
            no_nonlinear: false,
            json: true,
            out: Some(
                std::env::temp_dir().join(format!("sdins-errors-unit-{}", std::process::id())),
            ),
        }
    }

    /// The budget rows add up (as vectors) to the all-sources closed form: the closed form
    /// is linear in the biases, so only rounding separates them (|δp| ~ 1e4 m: 1e-7 m).
    /// Dropping any one row would miss by at least that source's share (≥ 100 m here).
    #[test]
    fn error_budget_adds_up_to_the_total() {
        let lat = 37.5_f64.to_radians();
        let params =
            SchulerParams::with_local_gravity(&sdins_core::earth::EarthModel::WGS84, lat, 0.0);
        let g = Vec3::new(0.01, -0.02, 0.015);
        let a = Vec3::new(50.0, -80.0, 30.0);
        let t = 6.0 * 3600.0;
        let rows = error_budget(lat, params, &g, &a, t);
        assert_eq!(rows.len(), 6);
        let all = StationaryClosedForm::new(
            lat,
            &StationaryErrors {
                eps_n: g * DEG_PER_HOUR,
                da_n: a * MICRO_G,
                ..Default::default()
            },
            params,
        )
        .eval(t)
        .dp_n;
        for (k, total) in all.iter().take(2).enumerate() {
            let sum: f64 = rows.iter().map(|r| r.dp_ne_m[k]).sum();
            assert!((sum - total).abs() <= 1e-7, "axis {k}: {sum} vs {total}");
        }
        // every horizontal source matters; the down accelerometer bias has no effect
        // (vertical channel held)
        for r in &rows {
            let m = r.dp_ne_m[0].hypot(r.dp_ne_m[1]);
            if r.source == "accel bias D" {
                assert_eq!(m, 0.0);
            } else {
                assert!(m >= 100.0, "{}: {m}", r.source);
            }
        }
    }

    #[test]
    #[allow(clippy::unwrap_used)]
    fn output_folder_has_report_and_run_toml() {
        let mut a = args();
        a.no_nonlinear = true;
        let dir = a.out.clone().unwrap();
        crate::output::finish(run(a)).unwrap();
        for f in [
            "errors.csv",
            "errors.png",
            "budget.png",
            "report.html",
            "run.toml",
        ] {
            assert!(dir.join(f).is_file(), "{f}");
        }
        let t: toml::Table = std::fs::read_to_string(dir.join("run.toml"))
            .unwrap()
            .parse()
            .unwrap();
        for k in [
            "sdins_version",
            "git_commit",
            "command",
            "lat_deg",
            "hours",
            "gyro_bias_dph_ned",
        ] {
            assert!(t.contains_key(k), "{k}");
        }
        let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
        assert!(html.contains("Error budget") && html.matches("<svg").count() >= 2);
        let csv = std::fs::read_to_string(dir.join("errors.csv")).unwrap();
        assert!(csv.lines().count() > 100);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn bad_inputs_exit_2() {
        let mut a = args();
        a.hours = -1.0;
        assert!(matches!(
            crate::output::finish(run(a)),
            Err(CliError::BadInput(_))
        ));
        let mut a = args();
        a.lat = 91.0;
        assert!(matches!(
            crate::output::finish(run(a)),
            Err(CliError::BadInput(_))
        ));
        let mut a = args();
        a.gyro_bias_dph = Some(vec![1.0]);
        assert!(matches!(
            crate::output::finish(run(a)),
            Err(CliError::BadInput(_))
        ));
        let mut a = args();
        a.gyro_bias_dph = None;
        assert!(matches!(
            crate::output::finish(run(a)),
            Err(CliError::BadInput(_))
        ));
        let mut a = args();
        a.gyro_bias_dph = None;
        a.grade = Some("nope".into());
        assert!(matches!(
            crate::output::finish(run(a)),
            Err(CliError::BadInput(_))
        ));
        assert_eq!(CliError::bad("x").exit_code(), 2);
    }

    /// The nonlinear column follows the closed form (east gyro 0.01 °/h, 2 h: spec §6 T9
    /// INS −2011 m, closed form −2013 m; tolerance 1 % of the peak + 50 m).
    #[test]
    #[allow(clippy::unwrap_used)]
    fn nonlinear_column_matches_closed_form() {
        let lat = 37.5_f64.to_radians();
        let p = SchulerParams::T9;
        let col = nonlinear_column(
            lat,
            &p,
            &Vec3::new(0.0, 0.01, 0.0),
            &Vec3::zeros(),
            &[1.0, 2.0],
        )
        .unwrap();
        let closed = StationaryClosedForm::new(
            lat,
            &StationaryErrors {
                eps_n: Vec3::new(0.0, 0.01, 0.0) * DEG_PER_HOUR,
                ..Default::default()
            },
            p,
        );
        for (h, n) in [1.0, 2.0].iter().zip(&col) {
            let n = n.unwrap();
            let c = closed.eval(h * 3600.0);
            assert!((n.dp_n_m[0] - c.dp_n[0]).abs() < 0.01 * 2013.0 + 50.0);
            assert!(
                (n.phi[2] - c.phi[2]).abs() < 2e-5,
                "{} vs {}",
                n.phi[2],
                c.phi[2]
            );
        }
        assert!((col[1].unwrap().dp_n_m[0] + 2011.0).abs() < 5.0);
    }
}
