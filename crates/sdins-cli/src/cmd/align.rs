//! `sdins align`: initial alignment of a stationary IMU (spec `alignment_and_errors.md`
//! §1–§3): coarse 1-step / 2-step, 12-state Kalman fine alignment, multi-heading
//! (Algorithm A, or B for scenarios), and the observability rank tables.
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
use crate::error::CliError;
use crate::output::write_string;
use sdins_core::align::coarse::CoarseMethod;
use sdins_core::align::fine::{reference_config, FineAlign, FineConfig};
use sdins_core::align::model::{f_matrix, f_pseudo9, h_horizontal, h_zupt, BiasFrame, Mat12};
use sdins_core::align::observability::{analyze, scale12, scale9};
use sdins_core::align::Site;
use sdins_core::coning::Increment;
use sdins_core::earth::EarthModel;
use sdins_core::math::{attitude_error, c_b_n_from_euler, euler_from_c_b_n, Euler, Mat3, Vec3};
use sdins_sim::align::{
    algorithm_a, algorithm_b, coarse_window, corrupt, fine_from_i0, i0_window, truth_record,
};
use sdins_sim::imu_error::{DPH, DPSH, UG};
use sdins_sim::imu_file::{read_imu_file, ImuFileError, ImuFormat};
use sdins_sim::scenario::Scenario;
use sdins_sim::trajectory::Motion;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Alignment method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Method {
    /// 1-step analytic (TRIAD-type), polar-orthonormalised (spec §1.1)
    Coarse1,
    /// 2-step: levelling + gyrocompassing (spec §1.2)
    Coarse2,
    /// inertial-frame coarse alignment, robust to sway, rocking, heave and surge
    /// (docs/alignment_i0.md); the attitude at the end of the window
    I0,
    /// 12-state zero-velocity Kalman fine alignment (spec §2)
    Fine,
    /// multi-heading: one filter with body-frame bias states across rotations (spec §3.2)
    Multiheading,
}

/// Multi-heading algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Alg {
    /// Algorithm A (spec §3.2), recommended
    A,
    /// Algorithm B (spec §3.3, pseudo-error least squares; scenarios only: needs the
    /// static phases)
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
    sdins align --imu lasergyro.imu --format psins --method coarse2 --window-s 300\n  \
    sdins align moored-ship --method i0 --window-s 300\n  \
    sdins align --observability"
)]
pub struct Args {
    /// scenario (built-in name or file); omit when using --imu
    pub scenario: Option<String>,
    /// IMU file (sdins CSV, PSINS .imu, KF-GINS text, ...)
    #[arg(long)]
    pub imu: Option<PathBuf>,
    /// IMU file format: auto, sdins, psins, psins-csv, kfgins, navego
    #[arg(long, default_value = "auto", value_parser = parse_format)]
    pub format: ImuFormat,
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
    /// output folder for align_result.csv and align_history.csv
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// print a JSON summary on stdout
    #[arg(long)]
    pub json: bool,
    /// print the observability rank tables (spec §2.4, §3.1) and exit
    #[arg(long)]
    pub observability: bool,
}

fn parse_format(s: &str) -> Result<ImuFormat, String> {
    s.parse()
}

fn file_error(e: ImuFileError) -> CliError {
    match e {
        ImuFileError::Io { file, source } => CliError::Io { path: file, source },
        other => CliError::BadInput(other.to_string()),
    }
}

/// Loaded input.
struct Input {
    name: String,
    dt_s: f64,
    incs: Vec<Increment>,
    site: Site,
    /// true attitude per sample (scenarios)
    truth: Option<Vec<Mat3>>,
    /// true body biases (scenarios): accel [m/s²], gyro [rad/s]
    true_bias: Option<(Vec3, Vec3)>,
    /// static phases (scenarios)
    phases: Vec<(f64, f64)>,
    vrw: f64,
    arw: f64,
    /// error-model seed (scenarios)
    seed: Option<u64>,
    /// the format actually read (IMU files)
    format: Option<ImuFormat>,
    /// latitude [deg] and height [m] used
    lat_deg: f64,
    h_m: f64,
}

fn load(args: &Args) -> Result<Input, CliError> {
    let d2r = std::f64::consts::PI / 180.0;
    match (&args.scenario, &args.imu) {
        (Some(_), Some(_)) => Err(CliError::bad("give either a scenario or --imu, not both")),
        (None, None) => Err(CliError::bad(
            "nothing to align: give a scenario (e.g. `alignment`) or --imu FILE",
        )),
        (Some(name), None) => {
            let scn = Scenario::load(name)?;
            let earth = scn.nav.earth.model();
            let lat = args.lat.map_or(scn.start.lat_rad, |l| l * d2r);
            let tr = truth_record(
                &scn.trajectory,
                earth,
                scn.imu.dt_s(),
                lat,
                scn.start.lon_rad,
                scn.start.h_m,
            );
            let model = &scn.imu.model;
            let incs = corrupt(&tr.increments, tr.dt_s, model, scn.imu.seed, args.run)
                .map_err(|e| CliError::bad(format!("{name}: imu.errors: {e}")))?;
            let st = sdins_sim::imu_error::ImuErrorState::new(model, scn.imu.seed, args.run)
                .map_err(|e| CliError::bad(format!("{name}: imu.errors: {e}")))?;
            let (bg, ba) = st.constant_bias();
            let phases = scn
                .trajectory
                .segments()
                .iter()
                .filter(|s| matches!(s.motion, Motion::Static))
                .map(|s| (s.t0_s, s.duration_s))
                .collect();
            let vrw = model.accel_vrw_ugpsqrthz[0].max(1e-3) * UG;
            let arw = model.gyro_arw_dpsh[0].max(1e-6) * DPSH;
            Ok(Input {
                name: scn.name.clone(),
                dt_s: tr.dt_s,
                incs,
                site: tr.site,
                truth: Some(tr.c_b_n),
                true_bias: Some((ba, bg)),
                phases,
                vrw,
                arw,
                seed: Some(scn.imu.seed),
                format: None,
                lat_deg: lat.to_degrees(),
                h_m: scn.start.h_m,
            })
        }
        (None, Some(path)) => {
            let data = read_imu_file(path, args.format).map_err(file_error)?;
            let (earth, lat_hdr, h_hdr) = match &data.psins {
                Some(p) => (EarthModel::PSINS, Some(p.lat_deg), p.h_m),
                None => (EarthModel::WGS84, None, 0.0),
            };
            let lat = args.lat.or(lat_hdr).ok_or_else(|| {
                CliError::bad(format!(
                    "{}: no latitude in the file: give --lat DEG",
                    path.display()
                ))
            })?;
            if !(lat.is_finite() && lat.abs() <= 80.0) {
                return Err(CliError::bad(format!(
                    "--lat {lat}: expected a latitude within ±80° (docs/theory/alignment.md)"
                )));
            }
            let h = args.h.unwrap_or(h_hdr);
            Ok(Input {
                name: path.display().to_string(),
                dt_s: data.dt_s,
                incs: data.increments,
                site: Site::from_earth(&earth, lat * d2r, h),
                truth: None,
                true_bias: None,
                phases: Vec::new(),
                vrw: 20.0 * UG,
                arw: 0.002 * DPSH,
                seed: None,
                format: Some(data.format),
                lat_deg: lat,
                h_m: h,
            })
        }
    }
}

/// One alignment result.
struct Result1 {
    method: String,
    c_b_n: Mat3,
    accel_bias: Option<(Vec3, Vec3)>,
    gyro_bias: Option<(Vec3, Vec3)>,
    att_sigma: Option<Vec3>,
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.observability {
        let lat = args.lat.unwrap_or(37.5);
        print!("{}", observability_tables(lat)?);
        return Ok(());
    }
    if !(args.window_s.is_finite() && args.window_s > 0.0) {
        return Err(CliError::bad(format!(
            "--window-s {}: expected a positive number of seconds",
            args.window_s
        )));
    }
    if !(args.sigma_z.is_finite() && args.sigma_z > 0.0) {
        return Err(CliError::bad(format!(
            "--sigma-z {}: expected a positive velocity σ in m/s",
            args.sigma_z
        )));
    }
    // every numeric option finite and in range (a NaN noise value used to give NaN results)
    for (name, v, lo, lo_open, hi) in [
        ("--vrw", args.vrw, 0.0, false, 1e6),
        ("--arw", args.arw, 0.0, false, 1e3),
        ("--duration-s", args.duration_s, 0.0, true, 1e7),
        ("--lat", args.lat, -89.99, false, 89.99),
        ("--h", args.h, -1000.0, false, 100_000.0),
    ] {
        if let Some(x) = v {
            let low_ok = if lo_open { x > lo } else { x >= lo };
            if !(x.is_finite() && low_ok && x <= hi) {
                return Err(CliError::bad(format!(
                    "{name} {x}: expected a finite value in {}{lo}, {hi}]",
                    if lo_open { "(" } else { "[" }
                )));
            }
        }
    }
    let mut inp = load(&args)?;
    if let Some(d) = args.duration_s {
        let n = (d / inp.dt_s).round().max(0.0) as usize;
        inp.incs.truncate(n);
    }
    let nw = (args.window_s / inp.dt_s).round() as usize;
    if nw == 0 || nw > inp.incs.len() {
        return Err(CliError::bad(format!(
            "{}: --window-s {} needs {nw} samples, the record has {}",
            inp.name,
            args.window_s,
            inp.incs.len()
        )));
    }
    let mut cfg: FineConfig = reference_config(
        inp.site,
        args.vrw.map_or(inp.vrw, |v| v * UG),
        args.arw.map_or(inp.arw, |v| v * DPSH),
    );
    cfg.sigma_z_mps = args.sigma_z;
    let mut hist = String::from(
        "t_s,roll_deg,pitch_deg,yaw_deg,sig_phi_n_urad,sig_phi_e_urad,sig_phi_d_urad,\
         ba_x_ug,ba_y_ug,ba_z_ug,sig_ba_x_ug,sig_ba_y_ug,sig_ba_z_ug,\
         bg_x_dph,bg_y_dph,bg_z_dph,sig_bg_x_dph,sig_bg_y_dph,sig_bg_z_dph,\
         phi_n_urad,phi_e_urad,phi_d_urad\n",
    );
    let mut rows: Vec<HistRow> = Vec::new();
    let truth = inp.truth.clone();
    let dt = inp.dt_s;
    let mut record = |j: usize, fa: &FineAlign| {
        let e = euler_from_c_b_n(&fa.c_b_n());
        let sa = fa.attitude_sigma() / 1e-6;
        let ba = fa.accel_bias_b() / UG;
        let sba = fa.accel_bias_sigma_b() / UG;
        let bg = fa.gyro_bias_b() / DPH;
        let sbg = fa.gyro_bias_sigma_b() / DPH;
        let phi = truth
            .as_ref()
            .and_then(|t| t.get(j))
            .map(|c| attitude_error(&fa.c_b_n(), c) / 1e-6);
        let _ = write!(
            hist,
            "{:.3},{:.9},{:.9},{:.9},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            (j + 1) as f64 * dt,
            e.roll_rad.to_degrees(),
            e.pitch_rad.to_degrees(),
            e.yaw_rad.to_degrees(),
            sa.x, sa.y, sa.z, ba.x, ba.y, ba.z, sba.x, sba.y, sba.z, bg.x, bg.y, bg.z, sbg.x, sbg.y, sbg.z
        );
        match phi {
            Some(p) => {
                let _ = writeln!(hist, ",{:.4},{:.4},{:.4}", p.x, p.y, p.z);
            }
            None => hist.push_str(",,,\n"),
        }
        let a = |v: Vec3| [v.x, v.y, v.z];
        rows.push(HistRow {
            t_s: (j + 1) as f64 * dt,
            phi_urad: phi.map(a),
            sig_phi_urad: a(sa),
            ba_ug: a(ba),
            sig_ba_ug: a(sba),
            bg_dph: a(bg),
            sig_bg_dph: a(sbg),
        });
    };
    let bad = |e: sdins_core::align::AlignError| CliError::bad(format!("{}: {e}", inp.name));
    let res = match args.method {
        Method::Coarse1 | Method::Coarse2 => {
            let m = if args.method == Method::Coarse1 {
                CoarseMethod::OneStep
            } else {
                CoarseMethod::TwoStep
            };
            let c = coarse_window(&inp.incs, dt, 0, nw, &inp.site, m).map_err(bad)?;
            Result1 {
                method: if m == CoarseMethod::OneStep {
                    "coarse1"
                } else {
                    "coarse2"
                }
                .into(),
                c_b_n: c,
                accel_bias: None,
                gyro_bias: None,
                att_sigma: None,
            }
        }
        Method::I0 => Result1 {
            method: "i0".into(),
            c_b_n: i0_window(&inp.incs, dt, 0, nw, &inp.site).map_err(bad)?,
            accel_bias: None,
            gyro_bias: None,
            att_sigma: None,
        },
        Method::Fine => {
            let fa = match args.start {
                Start::Coarse2 => {
                    let c0 = coarse_window(&inp.incs, dt, 0, nw, &inp.site, CoarseMethod::TwoStep)
                        .map_err(bad)?;
                    let mut fa = FineAlign::new(cfg, &c0);
                    for (j, inc) in inp.incs.iter().enumerate() {
                        if fa.step(inc, dt) {
                            record(j, &fa);
                        }
                    }
                    fa
                }
                Start::I0 => {
                    let (fa, _, sz) =
                        fine_from_i0(&inp.incs, dt, cfg, nw, |j, fa| record(j, fa)).map_err(bad)?;
                    if !args.json {
                        println!("fine filter from i0: zero-velocity σ_z {sz:.5} m/s (from the disturbance)");
                    }
                    fa
                }
            };
            Result1 {
                method: "fine".into(),
                c_b_n: fa.c_b_n(),
                accel_bias: Some((fa.accel_bias_b(), fa.accel_bias_sigma_b())),
                gyro_bias: Some((fa.gyro_bias_b(), fa.gyro_bias_sigma_b())),
                att_sigma: Some(fa.attitude_sigma()),
            }
        }
        Method::Multiheading => {
            let r = match args.alg {
                Alg::A => algorithm_a(&inp.incs, dt, cfg, args.window_s, |j, fa| record(j, fa))
                    .map_err(bad)?,
                Alg::B => {
                    if inp.phases.len() < 2 {
                        return Err(CliError::bad(format!(
                            "{}: Algorithm B needs a scenario with at least two static segments at different headings",
                            inp.name
                        )));
                    }
                    algorithm_b(&inp.incs, dt, cfg, args.window_s, &inp.phases).map_err(bad)?
                }
            };
            Result1 {
                method: format!(
                    "multiheading-{}",
                    if args.alg == Alg::A { "a" } else { "b" }
                ),
                c_b_n: r.c_b_n,
                accel_bias: Some((r.accel_bias_b, r.accel_bias_sigma_b)),
                gyro_bias: Some((r.gyro_bias_b, r.gyro_bias_sigma_b)),
                att_sigma: None,
            }
        }
    };
    let t_end = inp.incs.len() as f64 * dt;
    let c_true_end = inp.truth.as_ref().and_then(|t| {
        let j = match args.method {
            Method::Coarse1 | Method::Coarse2 => 0,
            Method::I0 => nw - 1,
            _ => inp.incs.len().saturating_sub(1),
        };
        t.get(j).copied()
    });
    let phi = c_true_end.map(|c| attitude_error(&res.c_b_n, &c));
    let e = euler_from_c_b_n(&res.c_b_n);
    if let Some(dir) = &args.out {
        crate::output::claim(dir)?;
        write_string(&dir.join("align_result.csv"), &result_csv(&res, &e, phi))?;
        let mut svgs = None;
        if matches!(args.method, Method::Fine | Method::Multiheading) && args.alg == Alg::A
            || args.method == Method::Fine
        {
            write_string(&dir.join("align_history.csv"), &hist)?;
            if rows.len() >= 2 {
                let tb = inp.true_bias.map(|(ba, bg)| {
                    let a = |v: Vec3, u: f64| [v.x / u, v.y / u, v.z / u];
                    (a(ba, UG), a(bg, DPH))
                });
                svgs = Some(write_plots(dir, &rows, tb)?);
            } else {
                eprintln!(
                    "note: {} Kalman cycle(s): too short for the alignment plots",
                    rows.len()
                );
            }
        }
        write_report(dir, &args, &inp, &res, &e, phi, svgs.as_ref())?;
        write_align_toml(dir, &args, &inp, &cfg)?;
    }
    if args.json {
        println!("{}", result_json(&res, &e, phi, inp.true_bias));
    } else {
        println!(
            "{}: {} samples, dt {} s, {:.1} s, latitude {:.6}°, g {:.6} m/s²",
            inp.name,
            inp.incs.len(),
            dt,
            t_end,
            inp.site.lat_rad.to_degrees(),
            inp.site.g_mps2
        );
        println!(
            "method {}: roll {:.6}°, pitch {:.6}°, yaw {:.6}° (NED, clockwise from north)",
            res.method,
            e.roll_rad.to_degrees(),
            e.pitch_rad.to_degrees(),
            e.yaw_rad.to_degrees()
        );
        if let Some(s) = res.att_sigma {
            println!(
                "  1σ φ N/E/D: {:.1} / {:.1} / {:.1} μrad (includes the unobservable part)",
                s.x / 1e-6,
                s.y / 1e-6,
                s.z / 1e-6
            );
        }
        if let Some((b, s)) = res.accel_bias {
            let (b, s) = (b / UG, s / UG);
            println!(
                "  accel bias [μg]: {:.2} ± {:.2}, {:.2} ± {:.2}, {:.2} ± {:.2}",
                b.x, s.x, b.y, s.y, b.z, s.z
            );
        }
        if let Some((b, s)) = res.gyro_bias {
            let (b, s) = (b / DPH, s / DPH);
            println!(
                "  gyro bias [°/h]: {:.5} ± {:.5}, {:.5} ± {:.5}, {:.5} ± {:.5}",
                b.x, s.x, b.y, s.y, b.z, s.z
            );
        }
        if let Some(p) = phi {
            println!(
                "  attitude error φ (G, NED) vs truth: {:.2}, {:.2}, {:.2} μrad",
                p.x / 1e-6,
                p.y / 1e-6,
                p.z / 1e-6
            );
        }
        if let Some((ba, bg)) = inp.true_bias {
            println!(
                "  true biases: accel {:.2?} μg, gyro {:.5?} °/h",
                (ba / UG).as_slice(),
                (bg / DPH).as_slice()
            );
        }
        if let Some(d) = &args.out {
            if rows.len() >= 2 {
                println!(
                    "wrote {0}/align_result.csv, {0}/align_history.csv, plots {0}/align_attitude.svg/.png, {0}/align_bias.svg/.png, {0}/report.html, {0}/run.toml",
                    d.display()
                );
            } else {
                println!(
                    "wrote {0}/align_result.csv, {0}/report.html, {0}/run.toml",
                    d.display()
                );
            }
        }
    }
    Ok(())
}

/// `report.html` of an alignment: input, result tables and (filters) the ±3σ plots.
fn write_report(
    dir: &std::path::Path,
    args: &Args,
    inp: &Input,
    res: &Result1,
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
        inp.incs.len(),
        inp.dt_s,
        inp.incs.len() as f64 * inp.dt_s,
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
    if let Some(s) = res.att_sigma {
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
            "Bias estimates (solid) with ±3σ (shaded) and, for scenarios, the true bias (dashed), body axes (align_bias.svg, align_bias.png).",
        );
    }
    r.write(&dir.join("report.html"))
}

/// `run.toml` of an alignment: the input (scenario text and error-model run, or the IMU
/// file, format and latitude) and every option of the method.
fn write_align_toml(
    dir: &std::path::Path,
    args: &Args,
    inp: &Input,
    cfg: &FineConfig,
) -> Result<(), CliError> {
    let mut t = toml::Table::new();
    if let Some(name) = &args.scenario {
        t.insert("scenario_name".into(), inp.name.clone().into());
        t.insert("scenario".into(), crate::report::scenario_text(name).into());
        t.insert("run".into(), args.run.to_string().into());
    }
    if let Some(seed) = inp.seed {
        t.insert("seed".into(), seed.to_string().into());
    }
    if let Some(p) = &args.imu {
        let abs = std::fs::canonicalize(p).unwrap_or_else(|_| p.clone());
        t.insert("imu_file".into(), abs.display().to_string().into());
        t.insert("imu_format".into(), args.format.name().into());
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
        (args.vrw.unwrap_or(inp.vrw / UG)).into(),
    );
    t.insert(
        "arw_deg_per_sqrt_h".into(),
        (args.arw.unwrap_or(inp.arw / DPSH)).into(),
    );
    crate::report::write_run_toml(dir, t)
}

fn v3(v: &Vec3, unit: f64) -> String {
    format!("[{}, {}, {}]", v.x / unit, v.y / unit, v.z / unit)
}

fn result_json(r: &Result1, e: &Euler, phi: Option<Vec3>, tb: Option<(Vec3, Vec3)>) -> String {
    let mut s = format!(
        "{{\"method\": \"{}\", \"roll_deg\": {}, \"pitch_deg\": {}, \"yaw_deg\": {}",
        r.method,
        e.roll_rad.to_degrees(),
        e.pitch_rad.to_degrees(),
        e.yaw_rad.to_degrees()
    );
    if let Some((b, sd)) = r.accel_bias {
        let _ = write!(
            s,
            ", \"accel_bias_ug\": {}, \"accel_bias_sigma_ug\": {}",
            v3(&b, UG),
            v3(&sd, UG)
        );
    }
    if let Some((b, sd)) = r.gyro_bias {
        let _ = write!(
            s,
            ", \"gyro_bias_dph\": {}, \"gyro_bias_sigma_dph\": {}",
            v3(&b, DPH),
            v3(&sd, DPH)
        );
    }
    if let Some(a) = r.att_sigma {
        let _ = write!(s, ", \"attitude_sigma_urad\": {}", v3(&a, 1e-6));
    }
    if let Some(p) = phi {
        let _ = write!(s, ", \"phi_urad\": {}", v3(&p, 1e-6));
    }
    if let Some((ba, bg)) = tb {
        let _ = write!(
            s,
            ", \"true_accel_bias_ug\": {}, \"true_gyro_bias_dph\": {}",
            v3(&ba, UG),
            v3(&bg, DPH)
        );
    }
    s.push('}');
    s
}

fn result_csv(r: &Result1, e: &Euler, phi: Option<Vec3>) -> String {
    let mut s = String::from(
        "method,roll_deg,pitch_deg,yaw_deg,ba_x_ug,ba_y_ug,ba_z_ug,sig_ba_x_ug,sig_ba_y_ug,sig_ba_z_ug,\
         bg_x_dph,bg_y_dph,bg_z_dph,sig_bg_x_dph,sig_bg_y_dph,sig_bg_z_dph,phi_n_urad,phi_e_urad,phi_d_urad\n",
    );
    let _ = write!(
        s,
        "{},{:.9},{:.9},{:.9}",
        r.method,
        e.roll_rad.to_degrees(),
        e.pitch_rad.to_degrees(),
        e.yaw_rad.to_degrees()
    );
    let mut cells = |v: Option<Vec3>, unit: f64| match v {
        Some(v) => {
            let _ = write!(s, ",{},{},{}", v.x / unit, v.y / unit, v.z / unit);
        }
        None => s.push_str(",,,"),
    };
    cells(r.accel_bias.map(|b| b.0), UG);
    cells(r.accel_bias.map(|b| b.1), UG);
    cells(r.gyro_bias.map(|b| b.0), DPH);
    cells(r.gyro_bias.map(|b| b.1), DPH);
    cells(phi, 1e-6);
    s.push('\n');
    s
}

/// The observability rank tables of spec §2.4 (single heading, NED bias states; pseudo
/// 9-state model) and §3.1 (stripped observability matrix, body-frame bias states,
/// attitude roll 2°, pitch −3°, base heading 40°), at latitude `lat_deg`.
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
        "\nUnobservable directions, 1 heading (spec §2.4): n1 = φ_N + (−tan L) φ_D + (−g) δa_E; \
         n2 = φ_D + (−Ω cos L) ε_E; n3 = φ_E + g δa_N + Ω sin L ε_N + Ω cos L ε_D"
    );
    Ok(s)
}
