//! `sdins run`: truth → IMU → navigation → errors for algorithms side by side.

use crate::error::CliError;
use crate::output::AtomicFile;
use crate::plot::PlotScale;
use crate::progress::Progress;
use sdins_core::coning::ConingSet;
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec, AttitudeMode, RotVector};
use sdins_sim::pipeline::{run_cancellable as run_pipeline, RunOptions, RunSummary};
use sdins_sim::scenario::Scenario;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `sdins run`.
#[derive(clap::Args, Debug, Clone)]
#[command(
    after_help = "Examples:\n  sdins run mach1-east --algo savage,songlee\n  sdins run my.toml --algo dualquat --samples 2 --json"
)]
pub struct Args {
    /// built-in scenario name or scenario file
    pub scenario: String,
    /// comma-separated algorithms: savage, songlee, songlee-complete, dualquat (default: the scenario's)
    #[arg(long)]
    pub algo: Option<String>,
    /// IMU samples per navigation update, 1..=4 (default: the scenario's)
    #[arg(long)]
    pub samples: Option<usize>,
    /// coning/sculling set: none, 1prev, two, three_poly, three_opt, four_poly, four_opt,
    /// polynomial, optimal (default: 1prev for one sample per update, else the polynomial set
    /// of N)
    #[arg(long)]
    pub coning: Option<String>,
    /// attitude update for local-level algorithms: transport (S1 eq. 6), five (eq. 5), savage (Savage Part 1)
    #[arg(long)]
    pub attitude: Option<String>,
    /// add the third-order rotation compensation (1/6)Δφ×(Δφ×Δv)
    #[arg(long)]
    pub rot3: bool,
    /// rotation-compensation vector: theta (½Δθ×Δv) or phi (½Δφ×Δv)
    #[arg(long)]
    pub rotvec: Option<String>,
    /// vertical channel: free (default) or hold (height and v_D from the truth every update)
    #[arg(long)]
    pub vertical: Option<String>,
    /// output folder (default ./sdins-out/run-<scenario>)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// output epoch spacing in seconds for the CSV files (default 1 s)
    #[arg(long, default_value_t = 1.0)]
    pub every_s: f64,
    /// ignore the scenario's IMU error model (ideal sensors)
    #[arg(long)]
    pub ideal: bool,
    /// run index of the sensor-error random stream (seed from the scenario)
    #[arg(long, default_value_t = 0)]
    pub run: u64,
    /// y scale of the per-axis error plot errors_ned.png: log (|error|) or linear (signed)
    #[arg(long, value_enum, default_value_t = PlotScale::Log)]
    pub plot_scale: PlotScale,
    /// print the JSON summary on stdout
    #[arg(long)]
    pub json: bool,
    /// no progress bar
    #[arg(long)]
    pub quiet: bool,
}

/// Build the algorithm list from the arguments.
pub fn algorithms(args: &Args, scn: &Scenario) -> Result<Vec<AlgorithmSpec>, CliError> {
    let n = args.samples.unwrap_or(scn.nav.samples);
    if !(1..=4).contains(&n) {
        return Err(CliError::bad(format!(
            "--samples {n}: expected 1, 2, 3 or 4"
        )));
    }
    let names: Vec<String> = match &args.algo {
        Some(s) => s
            .split(',')
            .map(|x| x.trim().to_string())
            .filter(|x| !x.is_empty())
            .collect(),
        None => scn.nav.algos.clone(),
    };
    let coning_name = args.coning.clone().or_else(|| scn.nav.coning.clone());
    let coning = match &coning_name {
        None => ConingSet::recommended_for(n),
        Some(c) => {
            let set = ConingSet::parse(c, n).ok_or_else(|| {
                CliError::bad(format!(
                    "--coning {c}: unknown set (expected none, 1prev, two, three_poly, three_opt, four_poly, four_opt, polynomial, optimal)"
                ))
            })?;
            if !set.accepts(n) {
                return Err(CliError::bad(format!(
                    "--coning {c}: the set is for {} samples, but --samples is {n}",
                    set.samples()
                )));
            }
            set
        }
    };
    let attitude = match args.attitude.as_deref() {
        None => None,
        Some("transport") => Some(AttitudeMode::Transport),
        Some("five") => Some(AttitudeMode::Five),
        Some("savage") => Some(AttitudeMode::Savage),
        Some(o) => {
            return Err(CliError::bad(format!(
                "--attitude {o}: expected transport, five or savage"
            )))
        }
    };
    let rot_vector = match args.rotvec.as_deref() {
        None => None,
        Some("theta") => Some(RotVector::Theta),
        Some("phi") => Some(RotVector::Phi),
        Some(o) => {
            return Err(CliError::bad(format!(
                "--rotvec {o}: expected theta or phi"
            )))
        }
    };
    names
        .iter()
        .map(|name| {
            let kind = AlgorithmKind::from_name(name).ok_or_else(|| {
                CliError::bad(format!(
                    "--algo: unknown algorithm `{name}` (expected savage, songlee, songlee-complete, dualquat)"
                ))
            })?;
            let mut spec = AlgorithmSpec::new(kind, n);
            spec.coning = coning;
            spec.attitude = attitude;
            spec.rot_vector = rot_vector;
            if args.rot3 {
                spec.rot3 = Some(true);
            }
            Ok(spec)
        })
        .collect()
}

/// Error-norm time series of one algorithm, at the output epochs:
/// (t, horizontal position, |down position|, velocity norm, attitude norm).
pub type ErrSeries = Vec<(f64, f64, f64, f64, f64)>;

/// Per-axis errors of one algorithm at the output epochs: (t, [attitude N, E, D \[rad\],
/// velocity N, E, D \[m/s\], position N, E, D \[m\]]).
pub type NedSeries = Vec<(f64, [f64; 9])>;

/// Everything a run produced.
pub struct Outcome {
    /// the scenario
    pub scn: Scenario,
    /// per-algorithm summaries
    pub sums: Vec<RunSummary>,
    /// output folder
    pub out: PathBuf,
    /// per-algorithm error time series
    pub series: Vec<ErrSeries>,
    /// per-algorithm per-axis error time series
    pub ned: Vec<NedSeries>,
    /// y scale of the per-axis figure
    pub plot_scale: PlotScale,
}

/// Run and return the summaries (used by `demo` too).
#[allow(dead_code)]
pub fn execute(args: &Args) -> Result<(Scenario, Vec<RunSummary>, PathBuf), CliError> {
    let o = execute_full(args)?;
    Ok((o.scn, o.sums, o.out))
}

/// Run, write the CSV files, the report and run.toml, and return everything.
pub fn execute_full(args: &Args) -> Result<Outcome, CliError> {
    let scn = Scenario::load(&args.scenario)?;
    let algos = algorithms(args, &scn)?;
    if algos.is_empty() {
        return Err(CliError::bad("--algo: no algorithm given"));
    }
    let hold = match args.vertical.as_deref() {
        None => scn.nav.vertical_hold,
        Some("free") => false,
        Some("hold") => true,
        Some(o) => {
            return Err(CliError::bad(format!(
                "--vertical {o}: expected free or hold"
            )))
        }
    };
    if !(args.every_s.is_finite() && args.every_s > 0.0) {
        return Err(CliError::bad(format!(
            "--every-s {}: expected a positive number of seconds",
            args.every_s
        )));
    }
    let n = algos[0].samples;
    let dt_u = scn.imu.dt_s() * n as f64;
    let every = ((args.every_s / dt_u).round() as u64).max(1);
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("sdins-out/run-{}", scn.name)));
    let mut nav_files = Vec::new();
    let mut err_files = Vec::new();
    for a in &algos {
        let mut nf = AtomicFile::create(&out.join(format!("nav_{}.csv", a.kind.name())))?;
        let mut ef = AtomicFile::create(&out.join(format!("err_{}.csv", a.kind.name())))?;
        writeln!(
            nf.writer(),
            "t_s,lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg"
        )
        .map_err(|source| CliError::Io {
            path: out.clone(),
            source,
        })?;
        writeln!(
            ef.writer(),
            "# attitude error eps: C_alg C_true^T = I + [eps x] (NED, rad); position error dN = dLat(R_M+h), dE = dLon(R_N+h)cosL, dD = -(h_alg - h_true)\nt_s,pos_err_n_m,pos_err_e_m,pos_err_d_m,vel_err_n_mps,vel_err_e_mps,vel_err_d_mps,att_err_n_rad,att_err_e_rad,att_err_d_rad,height_err_m,roll_err_rad,pitch_err_rad,yaw_err_rad"
        )
        .map_err(|source| CliError::Io { path: out.clone(), source })?;
        nav_files.push(nf);
        err_files.push(ef);
    }
    let total = (scn.duration_s() / dt_u).round() as u64;
    let mut bar = Progress::new(total, "navigate", args.quiet);
    let mut io_error = None;
    let mut series: Vec<ErrSeries> = vec![Vec::new(); algos.len()];
    let mut ned: Vec<NedSeries> = vec![Vec::new(); algos.len()];
    let d = 180.0 / std::f64::consts::PI;
    let opts = RunOptions {
        algos: algos.clone(),
        vertical_hold: hold,
        every,
        until_s: None,
        sensor_run: if args.ideal { None } else { Some(args.run) },
    };
    let summaries = run_pipeline(
        &scn,
        &opts,
        &crate::progress::token(),
        |i, st, _tr, e| {
            let eu = st.euler();
            let r1 = writeln!(
                nav_files[i].writer(),
                "{},{},{},{},{},{},{},{},{},{}",
                e.t_s,
                st.lat_rad * d,
                st.lon_rad * d,
                st.h_m,
                st.v_n_mps.x,
                st.v_n_mps.y,
                st.v_n_mps.z,
                eu.roll_rad * d,
                eu.pitch_rad * d,
                eu.yaw_rad * d
            );
            let (p, v, a, u) = (
                e.pos_err_ned_m,
                e.vel_err_ned_mps,
                e.att_err_rad,
                e.euler_err_rad,
            );
            let n3 = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            series[i].push((e.t_s, p[0].hypot(p[1]), p[2].abs(), n3(v), n3(a)));
            ned[i].push((
                e.t_s,
                [a[0], a[1], a[2], v[0], v[1], v[2], p[0], p[1], p[2]],
            ));
            let r2 = writeln!(
                err_files[i].writer(),
                "{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                e.t_s,
                p[0],
                p[1],
                p[2],
                v[0],
                v[1],
                v[2],
                a[0],
                a[1],
                a[2],
                e.height_err_m,
                u[0],
                u[1],
                u[2]
            );
            if let Err(err) = r1.and(r2) {
                io_error.get_or_insert(err);
            }
        },
        |done, _| bar.set(done),
    );
    bar.finish();
    if let Some(source) = io_error {
        return Err(CliError::Io { path: out, source });
    }
    let summaries = summaries?;
    for f in nav_files.into_iter().chain(err_files) {
        f.commit()?;
    }
    write_run_toml(&out, &scn, args)?;
    let outcome = Outcome {
        scn,
        sums: summaries,
        out,
        series,
        ned,
        plot_scale: args.plot_scale,
    };
    write_report(&outcome)?;
    Ok(outcome)
}

/// `run.toml`: everything needed to reproduce the run (scenario text, options, seed,
/// sdins version, git commit).
fn write_run_toml(out: &std::path::Path, scn: &Scenario, args: &Args) -> Result<(), CliError> {
    let mut t = toml::Table::new();
    t.insert("scenario_name".into(), scn.name.clone().into());
    // u64 seeds and run indices as strings: TOML integers are i64
    t.insert("seed".into(), scn.imu.seed.to_string().into());
    t.insert(
        "sensor_run".into(),
        (if args.ideal {
            "ideal".to_string()
        } else {
            args.run.to_string()
        })
        .into(),
    );
    t.insert("plot_scale".into(), args.plot_scale.name().into());
    t.insert("scenario".into(), scn.source_toml.clone().into());
    crate::report::write_run_toml(out, t)
}

/// The error figure of a run: log-scale error norms per algorithm.
pub fn error_figure(o: &Outcome) -> crate::plot::Figure {
    use crate::plot::{Figure, Panel, Series};
    let panel = |title: &str, unit: &str, k: usize| Panel {
        title: title.to_string(),
        x_label: "time [s]".into(),
        y_label: unit.to_string(),
        log_y: true,
        series: o
            .sums
            .iter()
            .zip(&o.series)
            .map(|(s, ser)| Series {
                name: s.algo.clone(),
                points: ser.iter().map(|r| (r.0, [r.1, r.2, r.3, r.4][k])).collect(),
            })
            .collect(),
    };
    Figure {
        panels: vec![
            panel("horizontal position error", "|δN, δE| [m]", 0),
            panel("vertical position error", "|δD| [m]", 1),
            panel("velocity error", "|δv| [m/s]", 2),
            panel("attitude error", "|ε| [rad]", 3),
        ],
        cols: 2,
        size: (1400, 900),
    }
}

/// Arc seconds per radian.
const ARCSEC_PER_RAD: f64 = 180.0 * 3600.0 / std::f64::consts::PI;

/// The per-axis error figure of a run (`errors_ned.png`): attitude (arcsec), velocity
/// (m/s) and position (m) error, N/E/D, one line per algorithm. On a log scale the
/// absolute value is drawn.
pub fn ned_figure(o: &Outcome) -> crate::plot::Figure {
    use crate::plot::{Figure, Panel, Series};
    let log = o.plot_scale == PlotScale::Log;
    let groups = [
        ("attitude error", "ε", "arcsec", ARCSEC_PER_RAD, 0),
        ("velocity error", "δv", "m/s", 1.0, 3),
        ("position error", "δp", "m", 1.0, 6),
    ];
    let mut panels = Vec::new();
    for (what, sym, unit, scale, first) in groups {
        for (k, axis) in ["N", "E", "D"].iter().enumerate() {
            let y_label = if log {
                format!("|{sym}_{axis}| [{unit}]")
            } else {
                format!("{sym}_{axis} [{unit}]")
            };
            panels.push(Panel {
                title: format!("{what}, {axis}"),
                x_label: "time [s]".into(),
                y_label,
                log_y: log,
                series: o
                    .sums
                    .iter()
                    .zip(&o.ned)
                    .map(|(s, ser)| Series {
                        name: s.algo.clone(),
                        points: ser
                            .iter()
                            .map(|(t, v)| {
                                let y = v[first + k] * scale;
                                (*t, if log { y.abs() } else { y })
                            })
                            .collect(),
                    })
                    .collect(),
            });
        }
    }
    Figure {
        panels,
        cols: 3,
        size: (1500, 1150),
    }
}

/// Summary rows for the report tables.
pub fn summary_rows(sums: &[RunSummary]) -> Vec<Vec<String>> {
    sums.iter()
        .map(|s| {
            let e = &s.final_err;
            let mut r = vec![s.algo.clone()];
            r.extend(
                e.pos_err_ned_m
                    .iter()
                    .chain(&e.vel_err_ned_mps)
                    .chain(&e.att_err_rad)
                    .map(|x| format!("{x:.3e}")),
            );
            r.push(format!(
                "{:.1}",
                s.wall_s / s.nav_updates.max(1) as f64 * 1e9
            ));
            r
        })
        .collect()
}

/// Header of [`summary_rows`].
pub const SUMMARY_HEADER: [&str; 11] = [
    "algorithm",
    "pos N [m]",
    "pos E [m]",
    "pos D [m]",
    "vel N [m/s]",
    "vel E [m/s]",
    "vel D [m/s]",
    "att N [rad]",
    "att E [rad]",
    "att D [rad]",
    "time [ns/update]",
];

fn write_report(o: &Outcome) -> Result<(), CliError> {
    use crate::plot::Bars;
    let mut r = crate::report::Report::new(&format!("sdins run: {}", o.scn.name));
    r.para(&format!(
        "{} — {} s, {} Hz IMU, {} samples per update. Final errors at t = {} s.",
        o.scn.description,
        o.scn.duration_s(),
        o.scn.imu.rate_hz,
        o.sums.first().map_or(0, |s| s.samples),
        o.sums.first().map_or(0.0, |s| s.final_err.t_s)
    ));
    r.table(&SUMMARY_HEADER, &summary_rows(&o.sums));
    let fig = error_figure(o);
    r.figure(
        &fig,
        "Error norms against the exact truth (log scale), one line per algorithm.",
    )?;
    fig.png(&o.out.join("errors.png"))?;
    let ned = ned_figure(o);
    r.figure(
        &ned,
        &format!(
            "Errors per NED axis against the exact truth ({}), one line per algorithm: attitude ε (arcsec), velocity (m/s), position (m). Also errors_ned.png.",
            if o.plot_scale == PlotScale::Log {
                "log scale of the absolute value"
            } else {
                "linear scale, signed"
            }
        ),
    )?;
    ned.png(&o.out.join("errors_ned.png"))?;
    let bars = Bars {
        title: "navigation time per update".into(),
        y_label: "time [ns/update]".into(),
        bars: o
            .sums
            .iter()
            .map(|s| (s.algo.clone(), s.wall_s / s.nav_updates.max(1) as f64 * 1e9))
            .collect(),
        size: (900, 400),
    };
    r.bars(
        &bars,
        "Wall time of each algorithm's navigation loop (truth generation excluded), this machine.",
    )?;
    r.write(&o.out.join("report.html"))
}

/// Print a summary table of final errors.
pub fn print_table(scn: &Scenario, sums: &[RunSummary]) {
    println!(
        "scenario {} ({} s, {} Hz IMU, {} samples/update)",
        scn.name,
        scn.duration_s(),
        scn.imu.rate_hz,
        sums.first().map_or(0, |s| s.samples)
    );
    println!(
        "{:<17} {:>11} {:>11} {:>11} | {:>10} {:>10} {:>10} | {:>10} {:>10} {:>10} | {:>8} {:>9}",
        "algo",
        "pos N m",
        "pos E m",
        "pos D m",
        "vel N m/s",
        "vel E m/s",
        "vel D m/s",
        "att N rad",
        "att E rad",
        "att D rad",
        "wall s",
        "Mupd/s"
    );
    for s in sums {
        let e = &s.final_err;
        println!(
            "{:<17} {:>11.4e} {:>11.4e} {:>11.4e} | {:>10.3e} {:>10.3e} {:>10.3e} | {:>10.3e} {:>10.3e} {:>10.3e} | {:>8.3} {:>9.2}",
            s.algo, e.pos_err_ned_m[0], e.pos_err_ned_m[1], e.pos_err_ned_m[2], e.vel_err_ned_mps[0], e.vel_err_ned_mps[1],
            e.vel_err_ned_mps[2], e.att_err_rad[0], e.att_err_rad[1], e.att_err_rad[2], s.wall_s,
            s.nav_updates as f64 / s.wall_s.max(1e-12) / 1e6
        );
    }
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let (scn, sums, out) = execute(&args)?;
    if args.json {
        let v = serde_json::json!({ "scenario": scn.name, "results": sums });
        println!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| CliError::Other(e.to_string()))?
        );
    } else {
        print_table(&scn, &sums);
        println!(
            "errors at t = {} s; files in {}",
            sums.first().map_or(0.0, |s| s.final_err.t_s),
            out.display()
        );
    }
    Ok(())
}
