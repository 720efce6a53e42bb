//! `sdins truth`: write the exact truth trajectory and IMU increments, streaming.

use crate::error::CliError;
use crate::output::AtomicFile;
use crate::progress::Progress;
use sdins_core::math::{euler_from_c_b_n, Quat};
use sdins_sim::scenario::Scenario;
use sdins_sim::truth::{TruthConfig, TruthGenerator};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `sdins truth`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Example:\n  sdins truth turn-90dps --out out/turn")]
pub struct Args {
    /// built-in scenario name or scenario file
    pub scenario: String,
    /// output folder (default ./sdins-out/truth-<scenario>)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// write truth.csv every N samples (imu.csv always has every sample)
    #[arg(long, default_value_t = 1)]
    pub every: u64,
    /// no progress bar
    #[arg(long)]
    pub quiet: bool,
}

/// Run the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let scn = Scenario::load(&args.scenario)?;
    crate::report::print_vibration(&scn);
    if args.every == 0 {
        return Err(CliError::bad("--every: must be at least 1"));
    }
    let out = args
        .out
        .unwrap_or_else(|| crate::output::default_dir("truth-", &scn.name));
    crate::output::claim(&out)?;
    let cfg = TruthConfig {
        earth: scn.nav.earth.model(),
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        substeps: scn.nav.substeps,
    };
    let mut gen = TruthGenerator::new(&scn.trajectory, cfg);
    // truth.csv stays at the vehicle reference point; imu.csv is sensed at the IMU
    let init = gen.initial_state();
    if let Some(m) = scn.mounting.imu {
        gen = gen.with_mount(m);
        eprintln!("note: imu.csv is sensed at the IMU lever arm and mounting ([mounting]); truth.csv is at the vehicle reference point");
    }
    let total = gen.len_samples();
    crate::output::check_size(
        "imu.csv",
        total as f64,
        160.0,
        "shorten the scenario or lower imu.rate_hz",
    )?;
    crate::output::check_size(
        "truth.csv",
        total as f64 / args.every as f64,
        280.0,
        "raise --every",
    )?;
    let mut truth = AtomicFile::create(&out.join("truth.csv"))?;
    let mut imu = AtomicFile::create(&out.join("imu.csv"))?;
    writeln!(truth.writer(), "t_s,lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg,q_w,q_x,q_y,q_z")
        .map_err(|e| io_err(&out, "truth.csv", e))?;
    writeln!(
        imu.writer(),
        "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps"
    )
    .map_err(|e| io_err(&out, "imu.csv", e))?;
    let e0 = euler_from_c_b_n(&init.c_b_n);
    let q0 = Quat::from_dcm(&init.c_b_n);
    let d = 180.0 / std::f64::consts::PI;
    writeln!(
        truth.writer(),
        "0,{:.15},{:.15},{:.6},{:.12},{:.12},{:.12},{:.12},{:.12},{:.12},{:.17},{:.17},{:.17},{:.17}",
        init.lat_rad * d, init.lon_rad * d, init.h_m, init.v_n_mps.x, init.v_n_mps.y, init.v_n_mps.z,
        e0.roll_rad * d, e0.pitch_rad * d, e0.yaw_rad * d, q0.w, q0.x, q0.y, q0.z
    )
    .map_err(|e| io_err(&out, "truth.csv", e))?;
    let mut bar = Progress::new(total, "truth", args.quiet);
    for (k, s) in gen.enumerate() {
        let i = &s.inc;
        writeln!(
            imu.writer(),
            "{},{:e},{:e},{:e},{:e},{:e},{:e}",
            s.t_s,
            i.dtheta_b_rad.x,
            i.dtheta_b_rad.y,
            i.dtheta_b_rad.z,
            i.dv_b_mps.x,
            i.dv_b_mps.y,
            i.dv_b_mps.z
        )
        .map_err(|e| io_err(&out, "imu.csv", e))?;
        if (k as u64 + 1).is_multiple_of(args.every) {
            let e = euler_from_c_b_n(&s.c_b_n);
            let q = Quat::from_dcm(&s.c_b_n);
            writeln!(
                truth.writer(),
                "{},{:.15},{:.15},{:.6},{:.12},{:.12},{:.12},{:.12},{:.12},{:.12},{:.17},{:.17},{:.17},{:.17}",
                s.t_s, s.lat_rad * d, s.lon_rad * d, s.h_m, s.v_n_mps.x, s.v_n_mps.y, s.v_n_mps.z,
                e.roll_rad * d, e.pitch_rad * d, e.yaw_rad * d, q.w, q.x, q.y, q.z
            )
            .map_err(|e| io_err(&out, "truth.csv", e))?;
        }
        if k % 65536 == 0 {
            bar.set(k as u64);
            if crate::progress::interrupted() {
                return Err(CliError::Interrupted);
            }
        }
    }
    bar.finish();
    truth.commit()?;
    imu.commit()?;
    eprintln!(
        "wrote {} and {} ({} samples at {} Hz, {} s)",
        out.join("truth.csv").display(),
        out.join("imu.csv").display(),
        total,
        scn.imu.rate_hz,
        scn.duration_s()
    );
    Ok(())
}

fn io_err(dir: &std::path::Path, name: &str, source: std::io::Error) -> CliError {
    CliError::Io {
        path: dir.join(name),
        source,
    }
}
