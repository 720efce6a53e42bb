//! `sdins nav`: run one navigation algorithm over a recorded IMU file.

use crate::args::{ImuFormatArg, OutArg};
use crate::csv_out::{nav_row, CsvOut, ERR_HEADER, NAV_HEADER};
use crate::error::CliError;
use crate::output::AtomicFile;
use sdins_core::nav::NavState;
use sdins_sim::io::imu_file::ImuFormat;
use sdins_sim::nav::pipeline::NavError;
use sdins_sim::nav::recorded::{self, NavFileRequest};
use std::path::PathBuf;

const D2R: f64 = std::f64::consts::PI / 180.0;

/// Arguments of `sdins nav`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  sdins truth turn-90dps --out t && sdins nav --imu t/imu.csv --truth t/truth.csv --algo songlee --samples 3\n  sdins nav --imu trj10ms_imu.csv --imu-format psins-csv --earth psins --truth trj10ms_avp.csv --init 34.246048,108.909664,380,0,0,0,0,0,0"
)]
pub struct Args {
    /// IMU file: sdins CSV, PSINS .imu, PSINS trj CSV (psins-csv), KF-GINS text, NaveGo CSV
    #[arg(long)]
    pub imu: PathBuf,
    #[command(flatten)]
    pub imu_format: ImuFormatArg,
    /// initial state lat_deg,lon_deg,h_m,v_n,v_e,v_d,roll_deg,pitch_deg,yaw_deg (NED, FRD);
    /// default: the first row of --truth, or the PSINS .imu header
    #[arg(long, allow_hyphen_values = true)]
    pub init: Option<String>,
    /// algorithm: savage, songlee, songlee-complete, dualquat
    #[arg(long, default_value = "songlee-complete")]
    pub algo: String,
    /// IMU samples per navigation update (1..=4)
    #[arg(long, default_value_t = 1)]
    pub samples: usize,
    /// coning/sculling set (default: 1prev for one sample per update, else the polynomial
    /// set of N; `none` switches the correction off)
    #[arg(long)]
    pub coning: Option<String>,
    /// earth model: wgs84, wgs84-linear (gravity γ(L)(1 − 2h/a), as pyins), psins, flat
    #[arg(long, default_value = "wgs84")]
    pub earth: String,
    /// reference trajectory (sdins truth.csv or PSINS avp CSV); errors are written too
    #[arg(long)]
    pub truth: Option<PathBuf>,
    #[command(flatten)]
    pub out: OutArg,
    /// print a JSON summary
    #[arg(long)]
    pub json: bool,
}

/// The run as the library takes it.
fn request(args: &Args) -> Result<NavFileRequest, CliError> {
    Ok(NavFileRequest {
        imu: args.imu.clone(),
        imu_format: args.imu_format.imu_format,
        init: args.init.clone(),
        algo: args.algo.clone(),
        samples: args.samples,
        coning: args.coning.clone(),
        earth: args.earth.clone(),
        truth: args.truth.clone(),
        imu_columns: args.imu_format.columns()?,
    })
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let plan =
        recorded::prepare(&request(&args)?).map_err(|e| CliError::BadInput(e.to_string()))?;
    let spec = plan.spec;
    let out = args
        .out
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("sdins-out/nav"));
    crate::output::check_size(
        "nav_*.csv",
        plan.updates as f64 + 1.0,
        250.0,
        "split the IMU file",
    )?;
    crate::output::claim(&out)?;
    let mut nav_file = AtomicFile::create(&out.join(format!("nav_{}.csv", spec.kind.name())))?;
    let mut nav_csv = CsvOut::new(&mut nav_file, &NAV_HEADER)?;
    let (mut write_err, mut final_state) = (None, None);
    // what was used, so that nobody has to guess a default
    eprintln!("{}", used(&args, &plan));
    if let Some(r) = &plan.imu_report {
        eprintln!("{}", r.summary());
    }
    let rec = recorded::run_plan(&plan, &crate::progress::token(), |t, st| {
        final_state = Some((t, *st));
        if let Err(err) = nav_csv.row(&nav_row(t, st)) {
            write_err.get_or_insert(err);
        }
    })?;
    if let Some(e) = write_err {
        return Err(e);
    }
    nav_csv.finish()?;
    nav_file.commit()?;
    if plan.truth.is_some() {
        write_errors(&out, spec.kind.name(), &rec.errors)?;
    }
    // warnings (a cut last line dropped, …) on stderr and in run.toml
    for w in &plan.data.warnings {
        eprintln!("warning: {}: {w}", args.imu.display());
    }
    let mut toml = toml::Table::new();
    toml.insert("imu".into(), args.imu.display().to_string().into());
    toml.insert("imu_format".into(), plan.data.format.name().into());
    toml.insert("algo".into(), spec.kind.name().into());
    toml.insert("samples".into(), (spec.samples as i64).into());
    let warnings: Vec<toml::Value> = plan
        .data
        .warnings
        .iter()
        .map(|w| w.as_str().into())
        .collect();
    toml.insert("warnings".into(), warnings.into());
    crate::args::inputs_toml(&mut toml, plan.imu_report.as_ref());
    crate::report::write_run_toml(&out, toml)?;
    if args.json {
        let v = summary_json(&args, &plan, rec.wall_s, rec.errors.last(), final_state);
        outln!(
            "{}",
            serde_json::to_string_pretty(&v).map_err(|e| CliError::Other(e.to_string()))?
        );
    } else {
        print_summary(&args, &plan, rec.wall_s, rec.errors.last(), &out);
    }
    Ok(())
}

/// The line saying which format, algorithm and earth model were used.
fn used(args: &Args, plan: &recorded::NavFilePlan) -> String {
    let (data, spec) = (&plan.data, &plan.spec);
    format!(
        "sdins nav: {} format {}, algorithm {}, N = {}, coning {}, earth {}",
        args.imu.display(),
        if plan.imu_report.is_some() {
            "read through the column map".to_string()
        } else if args.imu_format.imu_format == ImuFormat::Auto {
            format!("{} (detected)", data.format.name())
        } else {
            data.format.name().to_string()
        },
        spec.kind.name(),
        spec.samples,
        spec.coning.name(),
        args.earth
    )
}

/// `err_<algo>.csv`: the errors at the reference rows.
fn write_errors(out: &std::path::Path, algo: &str, errs: &[NavError]) -> Result<(), CliError> {
    let mut ef = AtomicFile::create(&out.join(format!("err_{algo}.csv")))?;
    let mut ec = CsvOut::new(&mut ef, &ERR_HEADER[..10])?;
    for e in errs {
        let (p, v, a) = (e.pos_err_ned_m, e.vel_err_ned_mps, e.att_err_rad);
        ec.row(&[e.t_s, p[0], p[1], p[2], v[0], v[1], v[2], a[0], a[1], a[2]])?;
    }
    ec.finish()?;
    ef.commit()
}

/// The `--json` summary.
fn summary_json(
    args: &Args,
    plan: &recorded::NavFilePlan,
    wall: f64,
    last: Option<&NavError>,
    final_state: Option<(f64, NavState)>,
) -> serde_json::Value {
    let (data, spec) = (&plan.data, &plan.spec);
    let state = final_state.map(|(t, st)| {
        let e = st.euler();
        serde_json::json!({
            "t_s": t, "lat_deg": st.lat_rad / D2R, "lon_deg": st.lon_rad / D2R, "h_m": st.h_m,
            "v_ned_mps": [st.v_n_mps.x, st.v_n_mps.y, st.v_n_mps.z],
            "roll_deg": e.roll_rad / D2R, "pitch_deg": e.pitch_rad / D2R, "yaw_deg": e.yaw_rad / D2R,
        })
    });
    serde_json::json!({
        "algo": spec.kind.name(), "samples": spec.samples, "coning": spec.coning.name(),
        "earth": args.earth, "format": data.format.name(), "imu_samples": data.increments.len(),
        "dt_s": data.dt_s, "wall_s": wall, "final": last, "final_state": state,
        "imu_detection": data.detection, "imu_warnings": data.warnings,
    })
}

/// The plain-text summary.
fn print_summary(
    args: &Args,
    plan: &recorded::NavFilePlan,
    wall: f64,
    last: Option<&NavError>,
    out: &std::path::Path,
) {
    let (data, spec) = (&plan.data, &plan.spec);
    if let Some(why) = &data.detection {
        outln!("{}: {why}", args.imu.display());
    }
    outln!(
        "{}: {} samples at {} s, {} updates in {:.3} s (navigation only)",
        spec.kind.name(),
        data.increments.len(),
        data.dt_s,
        plan.updates,
        wall
    );
    if let Some(e) = last {
        outln!(
            "final errors at t = {} s: pos N,E,D {:.4e} {:.4e} {:.4e} m; vel {:.3e} {:.3e} {:.3e} m/s; att {:.3e} {:.3e} {:.3e} rad",
            e.t_s, e.pos_err_ned_m[0], e.pos_err_ned_m[1], e.pos_err_ned_m[2], e.vel_err_ned_mps[0], e.vel_err_ned_mps[1],
            e.vel_err_ned_mps[2], e.att_err_rad[0], e.att_err_rad[1], e.att_err_rad[2]
        );
    }
    outln!("files in {}", out.display());
}
