//! Profiling driver for the truth generator of a scenario, for callgrind and quick timings:
//!
//! ```text
//! cargo build --release -p sdins-sim --example profile_truth
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*truth_run*' \
//!     target/release/examples/profile_truth dq-paper 20
//! ```
//!
//! Arguments: scenario (default `dq-paper`), seconds from the start (default: all),
//! scheme (`default` or `rk4`: the reference RK4). Prints a checksum and ns per sample.

#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "../benches/common/mod.rs"]
mod common;

use common::{scenario, truth_config};
use sdins_sim::truth::TruthGenerator;
use std::time::Instant;

#[inline(never)]
fn truth_run(gen: TruthGenerator<'_>, n: u64) -> (u64, f64) {
    let mut k = 0;
    let mut sum = 0.0;
    for s in gen.take(n as usize) {
        sum += s.inc.dtheta_b_rad.x + s.inc.dv_b_mps.z + s.h_m;
        k += 1;
    }
    (k, sum)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("dq-paper", String::as_str);
    let scn = scenario(name);
    let cfg = truth_config(&scn);
    let secs: f64 = args
        .get(2)
        .map_or(scn.trajectory.duration_s, |s| s.parse().expect("seconds"));
    let n = (secs / cfg.dt_s).round() as u64;
    let gen = TruthGenerator::new(&scn.trajectory, cfg).without_closed_form();
    let gen = match args.get(3).map(String::as_str) {
        Some("rk4") => gen.reference_rk4(),
        _ => gen,
    };
    let gen_scheme = gen.scheme();
    let t0 = Instant::now();
    let (k, sum) = truth_run(gen, n);
    let el = t0.elapsed().as_secs_f64();
    println!(
        "{name}: {k} samples, {:?}, substeps {}, checksum {sum:.17e}, {:.3} s, {:.0} ns/sample",
        gen_scheme,
        cfg.substeps,
        el,
        el / k as f64 * 1e9
    );
}
