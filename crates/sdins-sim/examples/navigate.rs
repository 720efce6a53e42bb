//! Library tour: load a built-in scenario, generate exact truth and IMU increments,
//! run two mechanizations side by side and print their final errors.
//!
//! `cargo run --release -p sdins-sim --example navigate`
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::nav::pipeline::{run, RunOptions};
use sdins_sim::scenario::Scenario;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scn = Scenario::load("turn-90dps")?;
    let algos = vec![
        AlgorithmSpec::new(AlgorithmKind::SongLee, 3),
        AlgorithmSpec::new(AlgorithmKind::DualQuat, 3),
    ];
    let opts = RunOptions {
        algos,
        vertical_hold: false,
        every_s: Some(1.0),
        until_s: None,
        sensor_run: None,
    };
    let summaries = run(&scn, &opts, |_, _, _, _| {}, |_, _| {})?;
    for s in &summaries {
        let e = &s.final_err;
        println!(
            "{:<10} t = {:5.1} s  position error N,E,D = {:+.3e} {:+.3e} {:+.3e} m  attitude |ε| = {:.3e} rad",
            s.algo,
            e.t_s,
            e.pos_err_ned_m[0],
            e.pos_err_ned_m[1],
            e.pos_err_ned_m[2],
            (e.att_err_rad[0].powi(2) + e.att_err_rad[1].powi(2) + e.att_err_rad[2].powi(2)).sqrt()
        );
    }
    Ok(())
}
