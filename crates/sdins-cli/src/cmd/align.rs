//! `sdins align`: initial alignment of a stationary IMU (docs/theory/alignment.md): coarse 1-step /
//! 2-step, 12-state Kalman fine alignment, multi-heading (Algorithm A, or B for scenarios), and the
//! observability rank tables.
//!
//! Input is an IMU file (`--imu`) or a scenario (built-in name or file; its IMU error
//! model applies with run index `--run`). Outputs in `--out` (if given):
//! `align_result.csv` (one row: method, attitude, biases and 1σ) and, for the filters
//! (fine, multi-heading Algorithm A), `align_history.csv` (per Kalman update: attitude,
//! 1σ, biases, and the attitude error against the truth for scenarios) with its plots
//! `align_attitude.svg/.png` and `align_bias.svg/.png` (attitude error and bias
//! estimates with ±3σ bounds, see [`super::align_plot`]).
//!
//! Attitude errors use convention G (`Ĉ = (I + [φ×]) C`, NED). Biases are body (FRD) axes,
//! μg and °/h.

use super::align_plot::{write_plots, HistRow};
use crate::args::{ImuFormatArg, OutArg};
use crate::error::CliError;
use crate::output::write_string;
use sdins_core::align::fine::FineConfig;
use sdins_core::align::model::{f_matrix, f_pseudo9, h_horizontal, h_zupt, BiasFrame, Mat12};
use sdins_core::align::observability::{analyze, scale12, scale9};
use sdins_core::align::Site;
use sdins_core::earth::EarthModel;
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};
use sdins_sim::align::run::{
    align, check_options, check_site, AlignInput, AlignMethod, AlignOptions, AlignOutcome,
    AlignRunError, FineStart, MultiheadingAlg,
};
use sdins_sim::io::imu_file::{read_imu_file, ImuFileError};
use sdins_sim::scenario::Scenario;
use sdins_sim::sensors::imu_error::{DPH, DPSH, UG};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Alignment method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// 1-step analytic (TRIAD-type), polar-orthonormalised (docs/theory/alignment.md
    /// §"Coarse alignment")
    Coarse1,
    /// 2-step: levelling + gyrocompassing (docs/theory/alignment.md §"Coarse alignment")
    Coarse2,
    /// inertial-frame coarse alignment, robust to sway, rocking, heave and surge
    /// (docs/alignment_i0.md); the attitude at the end of the window
    I0,
    /// 12-state zero-velocity Kalman fine alignment (docs/theory/alignment.md §"Fine alignment")
    Fine,
    /// multi-heading: one filter with body-frame bias states across rotations
    /// (docs/theory/alignment.md §"Multi-heading alignment")
    Multiheading,
}

/// Multi-heading algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Alg {
    /// Algorithm A (docs/theory/alignment.md §"Multi-heading alignment"), recommended
    A,
    /// Algorithm B (docs/theory/alignment.md §"Multi-heading alignment", pseudo-error least
    /// squares; scenarios only: needs the static phases)
    B,
}

/// Start of the fine filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Start {
    /// inertial-frame alignment over --window-s (disturbed bases)
    I0,
    /// 2-step coarse alignment over --window-s (benign pad)
    Coarse2,
}

/// Arguments of `sdins align`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  sdins align alignment --method fine --run 3 --json\n  \
    sdins align --imu lasergyro.imu --imu-format psins --method coarse2 --window-s 300\n  \
    sdins align moored-ship --method i0 --window-s 300\n  \
    sdins align --observability"
)]
pub struct Args {
    /// scenario (built-in name or file); omit when using --imu
    pub scenario: Option<String>,
    /// IMU file (sdins CSV, PSINS .imu, KF-GINS text, ...)
    #[arg(long)]
    pub imu: Option<PathBuf>,
    #[command(flatten)]
    pub imu_format: ImuFormatArg,
    /// method
    #[arg(long, value_enum, default_value = "fine")]
    pub method: Method,
    /// multi-heading algorithm
    #[arg(long, value_enum, default_value = "a")]
    pub alg: Alg,
    /// start of the fine filter: i0 (default; σ_z sized from the disturbance, start
    /// refined once, docs/alignment_i0.md §6) or coarse2 (2-step, σ_z as given)
    #[arg(long, value_enum, default_value = "i0")]
    pub start: Start,
    /// latitude [deg] (files without one in the header; overrides a header)
    #[arg(long, allow_hyphen_values = true)]
    pub lat: Option<f64>,
    /// height [m]
    #[arg(long)]
    pub h: Option<f64>,
    /// coarse-alignment averaging window [s] (also the coarse start of the filters)
    #[arg(long, default_value_t = 60.0)]
    pub window_s: f64,
    /// use only the first S seconds of the record
    #[arg(long)]
    pub duration_s: Option<f64>,
    /// error-model run index (scenarios)
    #[arg(long, default_value_t = 0)]
    pub run: u64,
    /// filter: zero-velocity measurement σ [m/s] (with --start i0 a floor: the i0 fit's
    /// velocity residual sizes it on a disturbed base)
    #[arg(long, default_value_t = 1e-3)]
    pub sigma_z: f64,
    /// filter: VRW [μg/√Hz] (default: the scenario's, else aviation grade 20)
    #[arg(long)]
    pub vrw: Option<f64>,
    /// filter: ARW [°/√h] (default: the scenario's, else aviation grade 0.002)
    #[arg(long)]
    pub arw: Option<f64>,
    /// output folder for align_result.csv, align_history.csv, plots and report
    #[command(flatten)]
    pub out: OutArg,
    /// print a JSON summary on stdout
    #[arg(long)]
    pub json: bool,
    /// print the observability rank tables (docs/theory/alignment.md
    /// §"Observability at one heading") and exit
    #[arg(long)]
    pub observability: bool,
}

fn file_error(e: ImuFileError) -> CliError {
    match e {
        ImuFileError::Io { file, source } => CliError::Io { path: file, source },
        other => CliError::BadInput(other.to_string()),
    }
}

fn run_error(e: AlignRunError) -> CliError {
    match e {
        AlignRunError::Cancelled => CliError::Interrupted,
        other => CliError::BadInput(other.to_string()),
    }
}

impl Args {
    /// The library options of these arguments.
    fn options(&self) -> AlignOptions {
        AlignOptions {
            method: match self.method {
                Method::Coarse1 => AlignMethod::Coarse1,
                Method::Coarse2 => AlignMethod::Coarse2,
                Method::I0 => AlignMethod::I0,
                Method::Fine => AlignMethod::Fine,
                Method::Multiheading => AlignMethod::Multiheading,
            },
            alg: match self.alg {
                Alg::A => MultiheadingAlg::A,
                Alg::B => MultiheadingAlg::B,
            },
            start: match self.start {
                Start::I0 => FineStart::I0,
                Start::Coarse2 => FineStart::Coarse2,
            },
            window_s: self.window_s,
            duration_s: self.duration_s,
            sigma_z_mps: self.sigma_z,
            vrw_ug_per_sqrt_hz: self.vrw,
            arw_deg_per_sqrt_h: self.arw,
        }
    }
}

fn load(args: &Args) -> Result<AlignInput, CliError> {
    match (&args.scenario, &args.imu) {
        (Some(_), Some(_)) => Err(CliError::bad("give either a scenario or --imu, not both")),
        (None, None) => Err(CliError::bad(
            "nothing to align: give a scenario (e.g. `alignment`) or --imu FILE",
        )),
        (Some(name), None) => {
            let scn = Scenario::load(name)?;
            AlignInput::from_scenario(&scn, args.run, args.lat).map_err(run_error)
        }
        (None, Some(path)) => {
            let data = if args.imu_format.imu_columns.is_some() || args.imu_format.profile.is_some()
            {
                args.imu_format.read(path)?.0
            } else {
                read_imu_file(path, args.imu_format.imu_format).map_err(file_error)?
            };
            AlignInput::from_imu_data(&path.display().to_string(), data, args.lat, args.h)
                .map_err(run_error)
        }
    }
}

/// Header of `align_history.csv`.
const HISTORY_HEADER: [&str; 22] = [
    "t_s",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "sig_phi_n_urad",
    "sig_phi_e_urad",
    "sig_phi_d_urad",
    "ba_x_ug",
    "ba_y_ug",
    "ba_z_ug",
    "sig_ba_x_ug",
    "sig_ba_y_ug",
    "sig_ba_z_ug",
    "bg_x_dph",
    "bg_y_dph",
    "bg_z_dph",
    "sig_bg_x_dph",
    "sig_bg_y_dph",
    "sig_bg_z_dph",
    "phi_n_urad",
    "phi_e_urad",
    "phi_d_urad",
];

/// The per-update history as `align_history.csv` text and plot rows (the true attitude
/// error φ only when the truth is known: empty cells otherwise).
fn history(res: &AlignOutcome) -> Result<(String, Vec<HistRow>), CliError> {
    let mut rows = Vec::with_capacity(res.history.len());
    let mut records = Vec::with_capacity(res.history.len());
    for h in &res.history {
        let e = h.euler;
        let sa = h.attitude_sigma / 1e-6;
        let ba = h.accel_bias_b / UG;
        let sba = h.accel_bias_sigma_b / UG;
        let bg = h.gyro_bias_b / DPH;
        let sbg = h.gyro_bias_sigma_b / DPH;
        let phi = h.phi_true.map(|p| p / 1e-6);
        let mut rec: Vec<Option<f64>> = vec![
            Some(h.t_s),
            Some(e.roll_rad.to_degrees()),
            Some(e.pitch_rad.to_degrees()),
            Some(e.yaw_rad.to_degrees()),
        ];
        for v in [sa, ba, sba, bg, sbg] {
            rec.extend(v.iter().map(|x| Some(*x)));
        }
        rec.extend((0..3).map(|i| phi.map(|p| p[i])));
        records.push(rec);
        let a = |v: Vec3| [v.x, v.y, v.z];
        rows.push(HistRow {
            t_s: h.t_s,
            phi_urad: phi.map(a),
            sig_phi_urad: a(sa),
            ba_ug: a(ba),
            sig_ba_ug: a(sba),
            bg_dph: a(bg),
            sig_bg_dph: a(sbg),
        });
    }
    Ok((crate::csv_out::table(&HISTORY_HEADER, records)?, rows))
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.observability {
        let lat = args.lat.unwrap_or(37.5);
        out!("{}", observability_tables(lat)?);
        return Ok(());
    }
    let opts = args.options();
    check_options(&opts).map_err(run_error)?;
    check_site(args.lat, args.h).map_err(run_error)?;
    let inp = load(&args)?;
    let res = align(&inp, &opts, &crate::progress::token()).map_err(run_error)?;
    for w in &res.warnings {
        eprintln!("warning: {w}");
    }
    if let (Some(sz), false) = (res.sigma_z_used_mps, args.json) {
        outln!("fine filter from i0: zero-velocity σ_z {sz:.5} m/s (from the disturbance)");
    }
    let (hist, rows) = history(&res)?;
    let (e, phi) = (res.euler, res.phi_true);
    if let Some(dir) = &args.out.out {
        write_outputs(dir, &args, &inp, &res, &hist, &rows)?;
    }
    if args.json {
        outln!("{}", result_json(&res, &e, phi, inp.true_bias));
    } else {
        print_text(&args, &inp, &res, rows.len());
    }
    Ok(())
}

/// `align_result.csv`, `align_history.csv` with its plots, the report and run.toml.
fn write_outputs(
    dir: &std::path::Path,
    args: &Args,
    inp: &AlignInput,
    res: &AlignOutcome,
    hist: &str,
    rows: &[HistRow],
) -> Result<(), CliError> {
    let (e, phi) = (res.euler, res.phi_true);
    crate::output::claim(dir)?;
    write_string(&dir.join("align_result.csv"), &result_csv(res, &e, phi)?)?;
    let mut svgs = None;
    if res.has_history {
        write_string(&dir.join("align_history.csv"), hist)?;
        if rows.len() >= 2 {
            let tb = inp.true_bias.map(|(ba, bg)| {
                let a = |v: Vec3, u: f64| [v.x / u, v.y / u, v.z / u];
                (a(ba, UG), a(bg, DPH))
            });
            svgs = Some(write_plots(dir, rows, tb)?);
        } else {
            eprintln!(
                "note: {} Kalman cycle(s): too short for the alignment plots",
                rows.len()
            );
        }
    }
    write_report(dir, args, inp, res, &e, phi, svgs.as_ref())?;
    write_align_toml(dir, args, inp, &res.config)?;
    Ok(())
}

/// The plain-text summary of an alignment.
fn print_text(args: &Args, inp: &AlignInput, res: &AlignOutcome, history_rows: usize) {
    let (dt, e, phi) = (inp.dt_s, res.euler, res.phi_true);
    let t_end = res.samples as f64 * dt;
    let rows_len = history_rows;
    outln!(
        "{}: {} samples, dt {} s, {:.1} s, latitude {:.6}°, g {:.6} m/s²",
        inp.name,
        res.samples,
        dt,
        t_end,
        inp.site.lat_rad.to_degrees(),
        inp.site.g_mps2
    );
    outln!(
        "method {}: roll {:.6}°, pitch {:.6}°, yaw {:.6}° (NED, clockwise from north)",
        res.method,
        e.roll_rad.to_degrees(),
        e.pitch_rad.to_degrees(),
        e.yaw_rad.to_degrees()
    );
    if let Some(s) = res.attitude_sigma {
        outln!(
            "  1σ φ N/E/D: {:.1} / {:.1} / {:.1} μrad (includes the unobservable part)",
            s.x / 1e-6,
            s.y / 1e-6,
            s.z / 1e-6
        );
    }
    if let Some((b, s)) = res.accel_bias {
        let (b, s) = (b / UG, s / UG);
        outln!(
            "  accel bias [μg]: {:.2} ± {:.2}, {:.2} ± {:.2}, {:.2} ± {:.2}",
            b.x,
            s.x,
            b.y,
            s.y,
            b.z,
            s.z
        );
    }
    if let Some((b, s)) = res.gyro_bias {
        let (b, s) = (b / DPH, s / DPH);
        outln!(
            "  gyro bias [°/h]: {:.5} ± {:.5}, {:.5} ± {:.5}, {:.5} ± {:.5}",
            b.x,
            s.x,
            b.y,
            s.y,
            b.z,
            s.z
        );
    }
    if let Some(p) = phi {
        outln!(
            "  attitude error φ (G, NED) vs truth: {:.2}, {:.2}, {:.2} μrad",
            p.x / 1e-6,
            p.y / 1e-6,
            p.z / 1e-6
        );
    }
    if let Some((ba, bg)) = inp.true_bias {
        outln!(
            "  true biases: accel {:.2?} μg, gyro {:.5?} °/h",
            (ba / UG).as_slice(),
            (bg / DPH).as_slice()
        );
    }
    if let Some(d) = &args.out.out {
        if rows_len >= 2 {
            outln!(
                "wrote {0}/align_result.csv, {0}/align_history.csv, plots {0}/align_attitude.svg/.png, {0}/align_bias.svg/.png, {0}/report.html, {0}/run.toml",
                d.display()
            );
        } else {
            outln!(
                "wrote {0}/align_result.csv, {0}/report.html, {0}/run.toml",
                d.display()
            );
        }
    }
}

/// `report.html` of an alignment: input, result tables and (filters) the ±3σ plots.
fn write_report(
    dir: &std::path::Path,
    args: &Args,
    inp: &AlignInput,
    res: &AlignOutcome,
    e: &Euler,
    phi: Option<Vec3>,
    svgs: Option<&[String; 2]>,
) -> Result<(), CliError> {
    let mut r = crate::report::Report::new(&format!("sdins align: {}", inp.name));
    r.para(&format!(
        "Input {}: {} samples, dt {} s ({:.1} s), latitude {:.6}°, height {} m, g {:.6} m/s². \
         Method {}, coarse window {} s. Attitude errors in convention G (Ĉ = (I + [φ×]) C, NED); \
         biases in body axes (FRD).",
        inp.name,
        res.samples,
        inp.dt_s,
        res.samples as f64 * inp.dt_s,
        inp.lat_deg,
        inp.h_m,
        inp.site.g_mps2,
        res.method,
        args.window_s
    ));
    r.heading("Result");
    r.table(
        &["method", "roll [°]", "pitch [°]", "yaw [°]"],
        &[vec![
            res.method.clone(),
            format!("{:.6}", e.roll_rad.to_degrees()),
            format!("{:.6}", e.pitch_rad.to_degrees()),
            format!("{:.6}", e.yaw_rad.to_degrees()),
        ]],
    );
    let pm = |v: Vec3, s: Vec3, unit: f64, prec: usize| -> Vec<String> {
        (0..3)
            .map(|i| format!("{:.prec$} ± {:.prec$}", v[i] / unit, s[i] / unit))
            .collect()
    };
    let plain = |v: Vec3, unit: f64, prec: usize| -> Vec<String> {
        (0..3).map(|i| format!("{:.prec$}", v[i] / unit)).collect()
    };
    let mut rows: Vec<Vec<String>> = Vec::new();
    let mut row = |name: &str, cells: Vec<String>| {
        let mut x = vec![name.to_string()];
        x.extend(cells);
        rows.push(x);
    };
    if let Some((b, s)) = res.accel_bias {
        row("accelerometer bias estimate ± 1σ [μg]", pm(b, s, UG, 2));
    }
    if let Some((b, s)) = res.gyro_bias {
        row("gyro bias estimate ± 1σ [°/h]", pm(b, s, DPH, 5));
    }
    if let Some((ba, bg)) = inp.true_bias {
        row("true accelerometer bias [μg]", plain(ba, UG, 2));
        row("true gyro bias [°/h]", plain(bg, DPH, 5));
    }
    if let Some(s) = res.attitude_sigma {
        row("attitude 1σ φ N/E/D [μrad]", plain(s, 1e-6, 1));
    }
    if let Some(p) = phi {
        row("attitude error φ N/E/D vs truth [μrad]", plain(p, 1e-6, 2));
    }
    if rows.is_empty() {
        r.para("The coarse methods estimate the attitude only (no biases, no covariance).");
    } else {
        r.table(&["quantity", "x / N", "y / E", "z / D"], &rows);
    }
    if let Some([att, bias]) = svgs {
        r.heading("Convergence");
        r.svg(
            att,
            "Attitude error φ against the truth (solid, scenarios) with the filter's ±3σ bounds (shaded), μrad (align_attitude.svg, align_attitude.png).",
        );
        r.svg(
            bias,
            "Bias estimates (solid) with ±3σ (shaded and outlined in the estimate's color) and, for scenarios, the true bias (dashed), body axes; the states the record does not observe (σ not reduced below 90 % of its start) in their own panels (align_bias.svg, align_bias.png).",
        );
    }
    r.write(&dir.join("report.html"))
}

/// `run.toml` of an alignment: the input (scenario text and error-model run, or the IMU
/// file, format and latitude) and every option of the method.
fn write_align_toml(
    dir: &std::path::Path,
    args: &Args,
    inp: &AlignInput,
    cfg: &FineConfig,
) -> Result<(), CliError> {
    let mut t = toml::Table::new();
    if let Some(name) = &args.scenario {
        t.insert("scenario_name".into(), inp.name.clone().into());
        t.insert(
            "scenario".into(),
            crate::provenance::scenario_text(name).into(),
        );
        t.insert("run".into(), args.run.to_string().into());
    }
    if let Some(seed) = inp.seed {
        t.insert("seed".into(), seed.to_string().into());
    }
    if let Some(p) = &args.imu {
        let abs = std::fs::canonicalize(p).unwrap_or_else(|_| p.clone());
        t.insert("imu_file".into(), abs.display().to_string().into());
        t.insert(
            "imu_format".into(),
            args.imu_format.imu_format.name().into(),
        );
    }
    if let Some(f) = inp.format {
        t.insert("imu_format_read".into(), f.name().into());
    }
    t.insert("lat_deg".into(), inp.lat_deg.into());
    t.insert("h_m".into(), inp.h_m.into());
    let method = match args.method {
        Method::Coarse1 => "coarse1",
        Method::Coarse2 => "coarse2",
        Method::I0 => "i0",
        Method::Fine => "fine",
        Method::Multiheading => "multiheading",
    };
    t.insert("method".into(), method.into());
    if args.method == Method::Multiheading {
        t.insert(
            "alg".into(),
            (if args.alg == Alg::A { "a" } else { "b" }).into(),
        );
    }
    t.insert("window_s".into(), args.window_s.into());
    if let Some(d) = args.duration_s {
        t.insert("duration_s".into(), d.into());
    }
    t.insert("sigma_z_mps".into(), cfg.sigma_z_mps.into());
    t.insert(
        "vrw_ug_per_sqrt_hz".into(),
        (args.vrw.unwrap_or(inp.vrw_mps_per_sqrt_s / UG)).into(),
    );
    t.insert(
        "arw_deg_per_sqrt_h".into(),
        (args.arw.unwrap_or(inp.arw_rad_per_sqrt_s / DPSH)).into(),
    );
    crate::report::write_run_toml(dir, t)
}

fn v3(v: &Vec3, unit: f64) -> serde_json::Value {
    serde_json::json!([v.x / unit, v.y / unit, v.z / unit])
}

fn result_json(r: &AlignOutcome, e: &Euler, phi: Option<Vec3>, tb: Option<(Vec3, Vec3)>) -> String {
    let mut m = serde_json::Map::new();
    m.insert("method".into(), r.method.to_string().into());
    m.insert("roll_deg".into(), e.roll_rad.to_degrees().into());
    m.insert("pitch_deg".into(), e.pitch_rad.to_degrees().into());
    m.insert("yaw_deg".into(), e.yaw_rad.to_degrees().into());
    if let Some((b, sd)) = r.accel_bias {
        m.insert("accel_bias_ug".into(), v3(&b, UG));
        m.insert("accel_bias_sigma_ug".into(), v3(&sd, UG));
    }
    if let Some((b, sd)) = r.gyro_bias {
        m.insert("gyro_bias_dph".into(), v3(&b, DPH));
        m.insert("gyro_bias_sigma_dph".into(), v3(&sd, DPH));
    }
    if let Some(a) = r.attitude_sigma {
        m.insert("attitude_sigma_urad".into(), v3(&a, 1e-6));
    }
    if let Some(p) = phi {
        m.insert("phi_urad".into(), v3(&p, 1e-6));
    }
    if let Some((ba, bg)) = tb {
        m.insert("true_accel_bias_ug".into(), v3(&ba, UG));
        m.insert("true_gyro_bias_dph".into(), v3(&bg, DPH));
    }
    serde_json::Value::Object(m).to_string()
}

fn result_csv(r: &AlignOutcome, e: &Euler, phi: Option<Vec3>) -> Result<String, CliError> {
    const HEADER: [&str; 19] = [
        "method",
        "roll_deg",
        "pitch_deg",
        "yaw_deg",
        "ba_x_ug",
        "ba_y_ug",
        "ba_z_ug",
        "sig_ba_x_ug",
        "sig_ba_y_ug",
        "sig_ba_z_ug",
        "bg_x_dph",
        "bg_y_dph",
        "bg_z_dph",
        "sig_bg_x_dph",
        "sig_bg_y_dph",
        "sig_bg_z_dph",
        "phi_n_urad",
        "phi_e_urad",
        "phi_d_urad",
    ];
    let mut cells: Vec<Option<f64>> = vec![
        Some(e.roll_rad.to_degrees()),
        Some(e.pitch_rad.to_degrees()),
        Some(e.yaw_rad.to_degrees()),
    ];
    for (v, unit) in [
        (r.accel_bias.map(|b| b.0), UG),
        (r.accel_bias.map(|b| b.1), UG),
        (r.gyro_bias.map(|b| b.0), DPH),
        (r.gyro_bias.map(|b| b.1), DPH),
        (phi, 1e-6),
    ] {
        cells.extend((0..3).map(|i| v.map(|v| v[i] / unit)));
    }
    crate::csv_out::table(&HEADER, [(r.method.to_string(), cells)])
}

/// The observability rank tables of docs/theory/alignment.md §"Observability at one heading"
/// (single heading, NED bias states; pseudo 9-state model) and of the multi-heading case
/// (stripped observability matrix, body-frame bias states, attitude roll 2°, pitch −3°, base heading 40°), at latitude `lat_deg`.
pub fn observability_tables(lat_deg: f64) -> Result<String, CliError> {
    if !(lat_deg.is_finite() && lat_deg.abs() <= 80.0) {
        return Err(CliError::bad(format!(
            "--lat {lat_deg}: expected a latitude within ±80°"
        )));
    }
    let d2r = std::f64::consts::PI / 180.0;
    let site = Site::from_earth(&EarthModel::WGS84, lat_deg * d2r, 0.0);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Observability (docs/theory/alignment.md; procedure: columns scaled by D, unit rows, σ_i > 1e-9 σ_1), latitude {lat_deg}°"
    );
    let f1 = [f_matrix(&site, BiasFrame::Ned, &Mat3::identity())];
    let o3 = analyze(&f1, &h_zupt(), &scale12(), 1e-9);
    let o2 = analyze(&f1, &h_horizontal(), &scale12(), 1e-9);
    let mut h9 = nalgebra::SMatrix::<f64, 3, 9>::zeros();
    for i in 0..3 {
        h9[(i, i)] = 1.0;
    }
    let o9 = analyze(&[f_pseudo9(&site)], &h9, &scale9(), 1e-9);
    let _ = writeln!(
        s,
        "\n| model | rank (3-axis vel.) | rank (horizontal vel.) | σ_r/σ_1 | σ_r+1/σ_1 |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|");
    let _ = writeln!(
        s,
        "| 12-state, NED biases, 1 heading | {} / 12 | {} | {:.2e} | {:.1e} |",
        o3.rank,
        o2.rank,
        o3.sigma_rel[o3.rank - 1],
        o3.sigma_rel.get(o3.rank).copied().unwrap_or(0.0)
    );
    let _ = writeln!(
        s,
        "| pseudo 9-state | {} / 9 | – | {:.2e} | – |",
        o9.rank, o9.sigma_rel[8]
    );
    let _ = writeln!(
        s,
        "\nStripped observability matrix, body-frame bias states (docs/theory/alignment.md):\n"
    );
    let _ = writeln!(
        s,
        "| headings (relative) | rank SOM (3-axis vel.) | rank SOM (horizontal vel.) |"
    );
    let _ = writeln!(s, "|---|---|---|");
    let att = |rel: f64| c_b_n_from_euler(&Euler::new(2.0 * d2r, -3.0 * d2r, (40.0 + rel) * d2r));
    for rel in [
        &[0.0][..],
        &[0.0, 180.0],
        &[0.0, 90.0],
        &[0.0, 45.0],
        &[0.0, 90.0, 180.0, 270.0],
    ] {
        let fs: Vec<Mat12> = rel
            .iter()
            .map(|r| f_matrix(&site, BiasFrame::Body, &att(*r)))
            .collect();
        let a = analyze(&fs, &h_zupt(), &scale12(), 1e-9);
        let b = analyze(&fs, &h_horizontal(), &scale12(), 1e-9);
        let names: Vec<String> = rel.iter().map(|r| format!("{r}°")).collect();
        let _ = writeln!(s, "| {} | {} / 12 | {} |", names.join(", "), a.rank, b.rank);
    }
    let _ = writeln!(
        s,
        "\nUnobservable directions, 1 heading (docs/theory/alignment.md): n1 = φ_N + (−tan L) φ_D + (−g) δa_E; \
         n2 = φ_D + (−Ω cos L) ε_E; n3 = φ_E + g δa_N + Ω sin L ε_N + Ω cos L ε_D"
    );
    Ok(s)
}
