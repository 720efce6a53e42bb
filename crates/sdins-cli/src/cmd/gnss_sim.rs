//! `sdins gnss-sim`: the raw GNSS measurements of a scenario's `[raw_gnss]` table as RINEX
//! 3.04 observation and navigation files, and a CSV with the truth behind each measurement
//! (see `Scenario::simulate_raw_gnss`, docs/theory/raw-gnss.md).

use crate::error::CliError;
use sdins_sim::scenario::Scenario;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `sdins gnss-sim`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Example: sdins gnss-sim canyon.toml --out out/canyon\nRTKLIB: rnx2rtkp -k spp.conf -o out/canyon/raw.pos out/canyon/raw.obs out/canyon/raw.nav\n(spp.conf: pos1-posmode=single, pos1-frequency=l1, pos1-ionoopt=brdc, pos1-tropopt=saas, pos1-elmask=10)"
)]
pub struct Args {
    /// built-in scenario name or scenario file (with a `[raw_gnss]` table)
    pub scenario: String,
    /// output folder (default ./sdins-out/gnss-sim-<scenario>)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Monte Carlo run number (selects the random streams)
    #[arg(long, default_value_t = 0)]
    pub run: u64,
}

/// Run the command: `raw.obs` (C1C, D1C), `raw.nav` (the ephemerides flown, nominal ones
/// included, with the Klobuchar coefficients) and `raw.csv`.
pub fn run(args: Args) -> Result<(), CliError> {
    let scn = Scenario::load_with(&args.scenario, &crate::progress::token())?;
    let rec = scn
        .simulate_raw_gnss(args.run)
        .map_err(|e| CliError::bad(e.to_string()))?;
    let out = args
        .out
        .unwrap_or_else(|| crate::output::default_dir("gnss-sim-", &scn.name));
    crate::output::check_size(
        "raw.csv",
        rec.obs.len() as f64,
        400.0,
        "lower raw_gnss.rate_hz",
    )?;
    crate::output::claim(&out)?;
    let mut csv = String::from("t_s,week,tow_rx_s,prn,pseudorange_m,range_rate_mps,sigma_pr_m,sigma_rr_mps,el_deg,az_deg,sigma_noise_m,sigma_iono_m,sigma_tropo_m,sigma_sis_m,true_range_m,true_clock_bias_m,true_clock_drift_mps,true_iono_m,model_iono_m,true_tropo_m,model_tropo_m,true_sis_m,outlier_m\n");
    for o in &rec.obs {
        let t = &o.truth;
        let _ = writeln!(
            csv,
            "{},{},{:.9},{},{:.4},{:.5},{:.4},{:.5},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.5},{:.4},{:.4},{:.4},{:.4},{:.4},{:.3}",
            o.t_s,
            o.t_rx.week,
            o.t_rx.sow_s,
            o.prn,
            o.pseudorange_m,
            o.range_rate_mps,
            o.sigma_pr_m,
            o.sigma_rr_mps,
            o.elevation_rad.to_degrees(),
            o.azimuth_rad.to_degrees(),
            o.uere.noise_m,
            o.uere.iono_m,
            o.uere.tropo_m,
            o.uere.sis_m,
            t.range_m,
            t.clock.bias_m,
            t.clock.drift_mps,
            t.iono_m,
            t.iono_model_m,
            t.tropo_m,
            t.tropo_model_m,
            t.sis_m,
            t.outlier_m
        );
    }
    crate::output::write_string(&out.join("raw.obs"), &rec.obs_rinex3())?;
    crate::output::write_string(&out.join("raw.nav"), &rec.nav_rinex3())?;
    crate::output::write_string(&out.join("raw.csv"), &csv)?;
    let epochs = {
        let mut n = 0usize;
        let mut last = f64::NAN;
        for o in &rec.obs {
            if o.t_s != last {
                n += 1;
                last = o.t_s;
            }
        }
        n
    };
    eprintln!(
        "wrote {} ({} epochs, {} measurements), {} ({} ephemerides) and {}",
        out.join("raw.obs").display(),
        epochs,
        rec.obs.len(),
        out.join("raw.nav").display(),
        rec.ephemerides.len(),
        out.join("raw.csv").display()
    );
    Ok(())
}
