//! `sdins run`: truth → IMU → navigation → errors for algorithms side by side.

use crate::csv_out::{nav_row, CsvOut, ERR_HEADER, NAV_HEADER};
use crate::error::CliError;
use crate::output::AtomicFile;
use crate::plot::PlotScale;
use crate::progress::Progress;
use sdins_core::nav::NavState;
use sdins_sim::nav::options::{self, AlgoChoice};
use sdins_sim::nav::pipeline::{NavError, RunObserver, RunSummary};
use sdins_sim::nav::run::{self, RunRequest, SensorRun};
use sdins_sim::scenario::Scenario;
use sdins_sim::truth::TruthSample;
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
    /// stop after this many seconds of the scenario (default: its whole duration)
    #[arg(long)]
    pub until_s: Option<f64>,
    /// output epoch spacing in seconds for the CSV files (default 1 s): the rows are the
    /// updates nearest to 0, every, 2·every, … s, with their own times, and the last update
    #[arg(long, default_value_t = options::DEFAULT_EVERY_S)]
    pub every_s: f64,
    /// ignore the scenario's IMU error model (ideal sensors)
    #[arg(long)]
    pub ideal: bool,
    /// IMU grade preset replacing the scenario's error model: marine, aviation,
    /// intermediate, tactical, consumer (docs/imu-errors.md)
    #[arg(long)]
    pub grade: Option<String>,
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

/// The run as the library takes it.
pub fn request(args: &Args) -> RunRequest {
    RunRequest {
        algos: AlgoChoice {
            algos: args.algo.clone(),
            samples: args.samples,
            coning: args.coning.clone(),
            attitude: args.attitude.clone(),
            rotvec: args.rotvec.clone(),
            rot3: args.rot3,
        },
        vertical: args.vertical.clone(),
        every_s: args.every_s,
        until_s: args.until_s,
        sensors: if args.ideal {
            SensorRun::Ideal
        } else {
            SensorRun::Run(args.run)
        },
        grade: args.grade.clone(),
    }
}

/// Error-norm time series of one algorithm, at the output epochs:
/// (t, horizontal position, |down position|, velocity norm, attitude norm).
pub type ErrSeries = Vec<(f64, f64, f64, f64, f64)>;

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
    /// y scale of the per-axis figure
    pub plot_scale: PlotScale,
    /// full-rate data for the figures, min/max-decimated per pixel column
    pub plot: PlotData,
}

/// Columns of the full-rate figure data (at least the pixel width of any panel).
pub const PLOT_COLUMNS: usize = 2000;

/// Channels of [`PlotData::errors`]: the four error norms of [`ErrSeries`], then the nine
/// per-axis errors in display units (attitude μrad, velocity m/s,
/// position m), as absolute values when the plot scale is logarithmic.
const ERR_CHANNELS: usize = 13;

/// The comment line of `err_<algo>.csv`: the error definitions.
const ERR_COMMENT: &str = "attitude error eps: C_alg C_true^T = I + [eps x] (NED, rad); position error dN = dLat(R_M+h), dE = dLon(R_N+h)cosL, dD = -(h_alg - h_true)";

/// Full-rate (every navigation update) figure data of a run, decimated online with
/// min/max per column ([`crate::plot::MinMaxColumns`]) so that short manoeuvres show.
pub struct PlotData {
    /// per algorithm: [`ERR_CHANNELS`] channels
    pub errors: Vec<crate::plot::MinMaxColumns>,
    /// truth height [m], roll, pitch, yaw (unwrapped) [deg]
    pub trajectory: crate::plot::MinMaxColumns,
    /// truth ground track (east, north) [m] from the start, one point per column
    pub track_en_m: Vec<(f64, f64)>,
    track_col: Option<usize>,
    t_end_s: f64,
    lat0_lon0: Option<(f64, f64)>,
    yaw_prev_deg: Option<f64>,
    yaw_turns: f64,
}

impl PlotData {
    fn new(n_algos: usize, t_end_s: f64) -> Self {
        let cols = crate::plot::MinMaxColumns::new(0.0, t_end_s, PLOT_COLUMNS, ERR_CHANNELS);
        Self {
            errors: vec![cols; n_algos],
            trajectory: crate::plot::MinMaxColumns::new(0.0, t_end_s, PLOT_COLUMNS, 4),
            track_en_m: Vec::new(),
            track_col: None,
            t_end_s,
            lat0_lon0: None,
            yaw_prev_deg: None,
            yaw_turns: 0.0,
        }
    }

    /// Record the truth at one update: ground track relative to the first sample on the
    /// local tangent plane, `δN = δL (R_M + h)`, `δE = δλ (R_N + h) cos L` (the position
    /// error convention of docs/conventions.md), height and Euler angles.
    fn push_truth(
        &mut self,
        earth: &sdins_core::earth::EarthModel,
        tr: &sdins_sim::truth::TruthSample,
    ) {
        let d = 180.0 / std::f64::consts::PI;
        let (lat0, lon0) = *self.lat0_lon0.get_or_insert((tr.lat_rad, tr.lon_rad));
        let col = ((tr.t_s / self.t_end_s.max(1e-300)) * PLOT_COLUMNS as f64).floor() as usize;
        if self.track_col != Some(col) {
            self.track_col = Some(col);
            let r = earth.radii(tr.lat_rad);
            let n = (tr.lat_rad - lat0) * (r.r_m_m + tr.h_m);
            let e = (tr.lon_rad - lon0) * (r.r_n_m + tr.h_m) * tr.lat_rad.cos();
            self.track_en_m.push((e, n));
        }
        let eu = sdins_core::math::euler_from_c_b_n(&tr.c_b_n);
        let yaw = eu.yaw_rad * d;
        if let Some(prev) = self.yaw_prev_deg {
            let jump = yaw - prev;
            if jump > 180.0 {
                self.yaw_turns -= 1.0;
            } else if jump < -180.0 {
                self.yaw_turns += 1.0;
            }
        }
        self.yaw_prev_deg = Some(yaw);
        self.trajectory.push(
            tr.t_s,
            &[
                tr.h_m,
                eu.roll_rad * d,
                eu.pitch_rad * d,
                yaw + 360.0 * self.yaw_turns,
            ],
        );
    }
}

/// Run and return the summaries (used by `demo` too).
#[allow(dead_code)]
pub fn execute(args: &Args) -> Result<(Scenario, Vec<RunSummary>, PathBuf), CliError> {
    let o = execute_full(args)?;
    Ok((o.scn, o.sums, o.out))
}

/// The CSV files and figure data of a run, written as the library reports rows and
/// updates.
struct Sink<'f> {
    nav_csv: Vec<CsvOut<'f>>,
    err_csv: Vec<CsvOut<'f>>,
    series: Vec<ErrSeries>,
    plot: PlotData,
    log: bool,
    earth: sdins_core::earth::EarthModel,
    bar: Progress,
    io_error: Option<CliError>,
}

impl RunObserver for Sink<'_> {
    fn epoch(&mut self, i: usize, st: &NavState, _tr: &TruthSample, e: &NavError) {
        let (p, v, a, u) = (
            e.pos_err_ned_m,
            e.vel_err_ned_mps,
            e.att_err_rad,
            e.euler_err_rad,
        );
        let n3 = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        self.series[i].push((e.t_s, p[0].hypot(p[1]), p[2].abs(), n3(v), n3(a)));
        let row = [
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
            u[2],
        ];
        let r = self.nav_csv[i]
            .row(&nav_row(e.t_s, st))
            .and_then(|()| self.err_csv[i].row(&row));
        if let Err(err) = r {
            self.io_error.get_or_insert(err);
        }
    }

    fn update(&mut self, i: usize, _st: &NavState, tr: &TruthSample, e: &NavError) {
        let (p, v, a) = (e.pos_err_ned_m, e.vel_err_ned_mps, e.att_err_rad);
        let n3 = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        let mut ch = [0.0; ERR_CHANNELS];
        ch[..4].copy_from_slice(&[p[0].hypot(p[1]), p[2].abs(), n3(v), n3(a)]);
        let log = self.log;
        let f = |x: f64| if log { x.abs() } else { x };
        for k in 0..3 {
            ch[4 + k] = f(a[k] * 1e6);
            ch[7 + k] = f(v[k]);
            ch[10 + k] = f(p[k]);
        }
        self.plot.errors[i].push(e.t_s, &ch);
        if i == 0 {
            self.plot.push_truth(&self.earth, tr);
        }
    }

    fn wants_updates(&self) -> bool {
        true
    }

    fn progress(&mut self, done: u64, _total: u64) {
        self.bar.set(done);
    }
}

/// Run, write the CSV files, the report and run.toml, and return everything.
pub fn execute_full(args: &Args) -> Result<Outcome, CliError> {
    let scn = Scenario::load(&args.scenario)?;
    crate::report::print_vibration(&scn);
    let plan = run::plan(scn, &request(args)).map_err(|e| CliError::BadInput(e.to_string()))?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| crate::output::default_dir("run-", &plan.scenario.name));
    crate::output::check_size(
        "each nav_*.csv and err_*.csv",
        plan.rows as f64,
        250.0,
        "raise --every-s or lower --until-s",
    )?;
    crate::output::claim(&out)?;
    let algos = &plan.options.algos;
    let mut files = Vec::new();
    for a in algos {
        for stem in ["nav", "err"] {
            files.push(AtomicFile::create(
                &out.join(format!("{stem}_{}.csv", a.kind.name())),
            )?);
        }
    }
    let total = (plan.t_end_s / plan.dt_update_s).round() as u64; // for the progress bar
    let (summaries, series, plot) = {
        let (mut nav_csv, mut err_csv) = (Vec::new(), Vec::new());
        for (k, f) in files.iter_mut().enumerate() {
            if k % 2 == 0 {
                nav_csv.push(CsvOut::new(f, &NAV_HEADER)?);
            } else {
                err_csv.push(CsvOut::with_comments(f, &[ERR_COMMENT], &ERR_HEADER)?);
            }
        }
        let mut sink = Sink {
            nav_csv,
            err_csv,
            series: vec![Vec::new(); algos.len()],
            plot: PlotData::new(algos.len(), plan.t_end_s),
            log: args.plot_scale == PlotScale::Log,
            earth: plan.scenario.nav.earth.model(),
            bar: Progress::new(total, "navigate", args.quiet),
            io_error: None,
        };
        let summaries = run::run_plan(&plan, &crate::progress::token(), &mut sink);
        sink.bar.finish();
        if let Some(e) = sink.io_error {
            return Err(e);
        }
        let summaries = summaries?;
        for c in sink.nav_csv.into_iter().chain(sink.err_csv) {
            c.finish()?;
        }
        (summaries, sink.series, sink.plot)
    };
    for f in files {
        f.commit()?;
    }
    write_run_toml(&out, &plan.scenario, args)?;
    let outcome = Outcome {
        scn: plan.scenario,
        sums: summaries,
        out,
        series,
        plot_scale: args.plot_scale,
        plot,
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
    if let Some(v) = crate::report::vibration_toml(scn) {
        t.insert("random_vibration".into(), v);
    }
    crate::report::write_run_toml(out, t)
}

/// The error figure of a run: log-scale error norms per algorithm, from every
/// navigation update (min/max per pixel column). Attitude in μrad, the unit of
/// free-inertial attitude errors in every report.
pub fn error_figure(o: &Outcome) -> crate::plot::Figure {
    use crate::plot::{Figure, Panel, Series};
    let panel = |title: &str, unit: &str, k: usize, scale: f64| Panel {
        title: title.to_string(),
        x_label: "time [s]".into(),
        y_label: unit.to_string(),
        log_y: true,
        series: o
            .sums
            .iter()
            .zip(&o.plot.errors)
            .map(|(s, cols)| {
                Series::line(
                    s.algo.clone(),
                    cols.series(k)
                        .into_iter()
                        .map(|(t, y)| (t, y * scale))
                        .collect(),
                )
            })
            .collect(),
        ..Panel::default()
    };
    Figure {
        panels: vec![
            panel("horizontal position error", "|δN, δE| [m]", 0, 1.0),
            panel("vertical position error", "|δD| [m]", 1, 1.0),
            panel("velocity error", "|δv| [m/s]", 2, 1.0),
            panel("attitude error", "|ε| [μrad]", 3, 1e6),
        ],
        cols: 2,
        size: (1400, 900),
    }
}

/// The per-axis error figure of a run (`errors_ned`): attitude (μrad), velocity (m/s)
/// and position (m) error, N/E/D, one line per algorithm, from every navigation update
/// (min/max per pixel column). On a log scale the absolute value is drawn.
pub fn ned_figure(o: &Outcome) -> crate::plot::Figure {
    use crate::plot::{Figure, Panel, Series};
    let log = o.plot_scale == PlotScale::Log;
    let groups = [
        ("attitude error", "ε", "μrad", 4),
        ("velocity error", "δv", "m/s", 7),
        ("position error", "δp", "m", 10),
    ];
    let mut panels = Vec::new();
    for (what, sym, unit, first) in groups {
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
                    .zip(&o.plot.errors)
                    .map(|(s, cols)| Series::line(s.algo.clone(), cols.series(first + k)))
                    .collect(),
                ..Panel::default()
            });
        }
    }
    Figure {
        panels,
        cols: 3,
        size: (1500, 1150),
    }
}

/// The trajectory of a run (`trajectory`): ground track north over east from the start
/// (equal scales), height, and roll, pitch, yaw of the truth versus time (every update,
/// min/max per pixel column; yaw unwrapped).
pub fn trajectory_figure(o: &Outcome) -> crate::plot::Figure {
    use crate::plot::{Figure, Panel, Series};
    let tr = &o.plot.trajectory;
    let time = |title: &str, y: &str, min_y_span: f64, series: Vec<Series>| Panel {
        title: title.into(),
        x_label: "time [s]".into(),
        y_label: y.into(),
        min_y_span,
        series,
        ..Panel::default()
    };
    Figure {
        panels: vec![
            Panel {
                title: "ground track".into(),
                x_label: "east [m]".into(),
                y_label: "north [m]".into(),
                equal_axes: true,
                series: vec![Series::line("truth", o.plot.track_en_m.clone())],
                ..Panel::default()
            },
            time(
                "height",
                "h [m]",
                2.0,
                vec![Series::line("truth", tr.series(0))],
            ),
            time(
                "attitude",
                "angle [°]",
                2.0,
                vec![
                    Series::line("roll", tr.series(1)),
                    Series::line("pitch", tr.series(2)),
                    Series::line("yaw", tr.series(3)),
                ],
            ),
        ],
        cols: 3,
        size: (1500, 480),
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
                    .map(|x| format!("{x:.3e}"))
                    .chain(e.att_err_rad.iter().map(|x| format!("{:.3e}", x * 1e6))),
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
    "att N [μrad]",
    "att E [μrad]",
    "att D [μrad]",
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
    r.figure_file(
        &trajectory_figure(o),
        &o.out,
        "trajectory",
        "Trajectory (truth): ground track from the start, height, and roll, pitch, yaw.",
    )?;
    r.figure_file(
        &error_figure(o),
        &o.out,
        "errors",
        "Error norms against the exact truth (log scale), one line per algorithm, every navigation update (min/max per pixel column).",
    )?;
    r.figure_file(
        &ned_figure(o),
        &o.out,
        "errors_ned",
        &format!(
            "Errors per NED axis against the exact truth ({}), one line per algorithm, every navigation update: attitude ε (μrad), velocity (m/s), position (m).",
            if o.plot_scale == PlotScale::Log {
                "log scale of the absolute value"
            } else {
                "linear scale, signed"
            }
        ),
    )?;
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
    r.bars_file(
        &bars,
        &o.out,
        "timing",
        "Wall time of each algorithm's navigation loop (truth generation excluded), this machine.",
    )?;
    r.write(&o.out.join("report.html"))
}

/// Print a summary table of final errors.
pub fn print_table(scn: &Scenario, sums: &[RunSummary]) {
    outln!(
        "scenario {} ({} s, {} Hz IMU, {} samples/update)",
        scn.name,
        scn.duration_s(),
        scn.imu.rate_hz,
        sums.first().map_or(0, |s| s.samples)
    );
    outln!(
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
        outln!(
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
        outln!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| CliError::Other(e.to_string()))?
        );
    } else {
        print_table(&scn, &sums);
        outln!(
            "errors at t = {} s; files in {}",
            sums.first().map_or(0.0, |s| s.final_err.t_s),
            out.display()
        );
    }
    Ok(())
}
