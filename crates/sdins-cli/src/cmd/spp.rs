//! `sdins spp`: single-point positioning (and Doppler velocity) of a RINEX observation file
//! with a RINEX navigation file (see `sdins_sim::nav::spp::run_spp`, docs/theory/gnss.md).
//!
//! Example: `sdins spp --obs abpo0080.15o --nav abpo0080.15n --every 10 --known-header`

use crate::error::CliError;
use sdins_sim::io::rinex::{read_nav, read_obs, RinexError};
use sdins_sim::nav::spp::{run_spp, SppMode, SppRunError, SppRunOptions};
use std::path::PathBuf;

/// Arguments of `sdins spp`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Example: sdins spp --obs abpo0080.15o --nav abpo0080.15n --mode iono-free --every 10 --known-header"
)]
pub struct Args {
    /// RINEX observation file (2.10/2.11/3.0x)
    #[arg(long)]
    pub obs: PathBuf,
    /// RINEX GPS navigation file (2.10/2.11/3.0x)
    #[arg(long)]
    pub nav: PathBuf,
    /// iono-free (P1/P2) or l1 (C/A with the Klobuchar model)
    #[arg(long, default_value = "iono-free", value_parser = ["iono-free", "l1"])]
    pub mode: String,
    /// elevation mask [deg]
    #[arg(long, default_value_t = 10.0)]
    pub mask_deg: f64,
    /// process every n-th epoch
    #[arg(long, default_value_t = 1)]
    pub every: usize,
    /// no Saastamoinen troposphere
    #[arg(long)]
    pub no_troposphere: bool,
    /// statistics against the observation header's APPROX POSITION XYZ
    #[arg(long)]
    pub known_header: bool,
}

fn rinex(e: RinexError) -> CliError {
    match e {
        RinexError::Io { file, source } => CliError::Io {
            path: file.into(),
            source,
        },
        other => CliError::bad(other.to_string()),
    }
}

/// Run the command: one line per solved epoch (GPS week, seconds of week, ECEF position,
/// clock, satellites, PDOP, NED velocity when Dopplers exist), then the summary.
pub fn run(args: Args) -> Result<(), CliError> {
    let obs = read_obs(&args.obs).map_err(rinex)?;
    let nav = read_nav(&args.nav).map_err(rinex)?;
    let known =
        if args.known_header {
            Some(obs.header.approx_position_e_m.ok_or_else(|| {
                CliError::bad("--known-header: the file has no APPROX POSITION XYZ")
            })?)
        } else {
            None
        };
    let mode = if args.mode == "l1" {
        SppMode::L1Klobuchar
    } else {
        SppMode::IonoFree
    };
    let opts = SppRunOptions {
        mode,
        elevation_mask_deg: args.mask_deg,
        every: args.every,
        troposphere: !args.no_troposphere,
        known_position_e_m: known,
        ..SppRunOptions::default()
    };
    let run = run_spp(&obs, &nav, &opts, &crate::progress::token()).map_err(|e| match e {
        SppRunError::Cancelled(_) => CliError::Interrupted,
        other => CliError::bad(other.to_string()),
    })?;
    outln!("week,tow_s,x_m,y_m,z_m,clock_bias_m,n_sats,pdop,v_n_mps,v_e_mps,v_d_mps");
    for e in &run.epochs {
        let s = &e.solution;
        let v = e
            .velocity
            .map(|v| format!("{:.3},{:.3},{:.3}", v.v_n_mps.x, v.v_n_mps.y, v.v_n_mps.z))
            .unwrap_or_else(|| ",,".into());
        outln!(
            "{},{:.3},{:.3},{:.3},{:.3},{:.3},{},{:.2},{v}",
            e.t.week,
            e.t.sow_s,
            s.r_e_m.x,
            s.r_e_m.y,
            s.r_e_m.z,
            s.clock_bias_m,
            s.n_used,
            s.dop.pdop
        );
    }
    eprintln!(
        "{} epochs solved, {} without a solution",
        run.epochs.len(),
        run.failures.len()
    );
    if let Some(s) = run.summary {
        eprintln!(
            "against the header position: horizontal RMS {:.2} m (95 % {:.2} m), vertical RMS {:.2} m (95 % {:.2} m), mean NED [{:.2}, {:.2}, {:.2}] m, {:.1} % inside the predicted 95 % ellipse",
            s.horizontal_rms_m, s.horizontal_95_m, s.vertical_rms_m, s.vertical_95_m, s.mean_error_n_m[0], s.mean_error_n_m[1], s.mean_error_n_m[2], 100.0 * s.fraction_in_95_ellipse
        );
    }
    Ok(())
}
