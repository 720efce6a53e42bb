//! `sdins errors`: analytic INS error propagation.
//!
//! Prints the full stationary closed form (docs/theory/error-analysis.md
//! §"Full stationary closed form") for a set of NED sensor biases, next to the 15-state linear
//! model's deterministic error and 1σ covariance envelope, at a few epochs; or, with
//! `--schuler-share`, the reconstruction of \[P2\] Table 1 (docs/theory/error-analysis.md
//! §"The Schuler share").
//!
//! Examples:
//! ```text
//! sdins errors --grade aviation --hours 24
//! sdins errors --gyro-bias-dph 0,0.01,0 --accel-bias-ug 30,0,0 --lat 37.5 --json
//! sdins errors --schuler-share --json
//! ```

use crate::error::CliError;
use sdins_sim::analysis::error_analysis::grades::grade_by_name;
use sdins_sim::analysis::error_analysis::linear_model::EnvelopePoint;
use sdins_sim::analysis::error_analysis::schuler_share::{
    schuler_share_table_p2, ShareRow, T_STAR_S,
};
use sdins_sim::analysis::error_analysis::stationary::{StationaryClosedForm, StationarySolution};
use sdins_sim::analysis::errors_run::{
    errors, BudgetRow, ErrorsError, ErrorsOptions, ErrorsReport,
};

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

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.schuler_share {
        return print_share(args.json);
    }
    let opts = ErrorsOptions {
        grade: args.grade.clone(),
        gyro_bias_dph: args.gyro_bias_dph.clone(),
        accel_bias_ug: args.accel_bias_ug.clone(),
        hours: args.hours,
        lat_deg: args.lat,
        nonlinear: !args.no_nonlinear,
    };
    let out = errors(&opts, &crate::progress::token()).map_err(|e| match e {
        ErrorsError::BadOption { message, .. } => CliError::BadInput(message),
        ErrorsError::Cancelled => CliError::Interrupted,
        other => CliError::Other(other.to_string()),
    })?;
    let report = &out.report;
    if args.json {
        let s = serde_json::to_string_pretty(report).map_err(|e| CliError::Other(e.to_string()))?;
        outln!("{s}");
    } else {
        print_table(report);
    }
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| std::path::PathBuf::from("sdins-out/errors"));
    crate::output::claim(&dir)?;
    write_folder(&dir, &args, report, &out.closed, &out.envelope, &out.budget)?;
    eprintln!(
        "wrote {0}/errors.csv, {0}/errors.png, {0}/budget.png, {0}/report.html, {0}/run.toml",
        dir.display()
    );
    Ok(())
}

/// errors.csv, the figures, report.html and run.toml of `sdins errors`.
fn write_folder(
    out: &std::path::Path,
    args: &Args,
    r: &ErrorsReport,
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
            outline: false,
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
        r.grade.as_ref().map(|g| format!(" (grade {g})")).unwrap_or_default()
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

fn print_table(r: &ErrorsReport) {
    outln!(
        "Stationary free-inertial errors, L = {:.3}°, vertical channel held, R0 = {:.0} m, g = {:.6} m/s²",
        r.lat_deg, r.params.r0_m, r.params.g_mps2
    );
    outln!(
        "NED gyro bias [°/h] = {:?}, accel bias [μg] = {:?}{}",
        r.gyro_bias_dph_ned,
        r.accel_bias_ug_ned,
        r.grade
            .as_ref()
            .map(|g| format!(" (grade {g}, turn-on bias σ, ARW/VRW in σ)"))
            .unwrap_or_default()
    );
    outln!(
        "closed = closed form of docs/theory/error-analysis.md; nonlin = nonlinear INS (body = NED, spherical earth R0/g, 20 Hz, songlee-complete, vertical held);\nlinear = 15-state model (same biases); 1σ = covariance with the biases as 1σ"
    );
    outln!(
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
        let nl = |f: &dyn Fn(&sdins_sim::analysis::errors_run::NonlinearPoint) -> String| {
            e.nonlinear
                .as_ref()
                .map(f)
                .unwrap_or_else(|| "—".to_string())
        };
        outln!(
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
        outln!("{s}");
        return Ok(());
    }
    outln!(
        "Schuler share (reconstruction of [P2] Table 1, docs/theory/error-analysis.md): t* = {T_STAR_S} s, L = 37.5°, R0 = 6371 km, g = 9.80665"
    );
    outln!(
        "{:>13} {:>10} {:>10} {:>10} {:>14}",
        "grade",
        "accel [μg]",
        "gyro [°/h]",
        "share [%]",
        "paper [%]"
    );
    for r in &rows {
        let paper = grade_by_name(&r.grade)
            .and_then(|g| g.p2.map(|b| b.share_pct))
            .map(|(a, b)| format!("{a:.1}–{b:.1}"))
            .unwrap_or_default();
        outln!(
            "{:>13} {:>10.1} {:>10.4} {:>10.2} {:>14}",
            r.grade,
            r.accel_bias_ug,
            r.gyro_bias_dph,
            r.share_pct,
            paper
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
}
