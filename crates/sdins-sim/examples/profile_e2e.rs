//! Profiling driver for the navigation loops, for callgrind (docs/performance.md §5):
//!
//! * `e2e` (default): the end-to-end loop of `benches/end_to_end.rs` (navigation +
//!   `nav_error` after every update, increments from memory), collected as `full_run`;
//! * `nav`: what `sdins nav` times, i.e. [`recorded::navigate`] without a reference —
//!   every update followed by the state hand-off (`state()` pushed into the block
//!   buffer), collected as `nav_handoff`;
//! * `update`: the updates alone, no state taken (`nav_only`).
//!
//! ```text
//! cargo build --release -p sdins-sim --example profile_e2e
//! # the default `sdins nav` configuration (songlee-complete, N = 1, 1prev) and N = 3:
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*nav_handoff*' \
//!     target/release/examples/profile_e2e songlee-complete 60 mach1-east 1 nav
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*nav_handoff*' \
//!     target/release/examples/profile_e2e songlee-complete 60 mach1-east 3 nav
//! # end to end with errors:
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*full_run*' \
//!     target/release/examples/profile_e2e savage 60
//! ```
//!
//! Arguments: algorithm (default `savage`), seconds of the scenario (default 60),
//! scenario (default `mach1-east`), samples per update N (default the scenario's), mode
//! (`e2e`, `nav`, `update`; default `e2e`). The coning set is the one a user gets when
//! naming none ([`ConingSet::recommended_for`]: `1prev` for N = 1, the polynomial set
//! otherwise), as in `sdins nav` and `sdins run`. Prints the samples, the instructions
//! divisor and the wall time. `SDINS_NAV_ONLY=1` is the old spelling of mode `update`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "../benches/common/mod.rs"]
mod common;

use common::{full_run, record, scenario, Recorded};
use sdins_core::coning::ConingSet;
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, Mechanization};
use sdins_sim::cancel::CancelToken;
use sdins_sim::nav::recorded;
use std::hint::black_box;
use std::time::Instant;

/// The navigation loop alone (same buffer), for the split between update and errors.
#[inline(never)]
fn nav_only(rec: &Recorded, spec: &AlgorithmSpec) -> f64 {
    let n = rec.n;
    let mut m = AnyMechanization::new(spec, rec.earth, rec.dt_s, &rec.init);
    for chunk in rec.incs.chunks_exact(n) {
        m.update(chunk);
    }
    m.state().h_m
}

/// `sdins nav`'s loop: [`recorded::navigate`] without a reference, with an observer that
/// only keeps the last height (the CSV formatting of `sdins nav` is outside its `wall_s`
/// and outside this count).
#[inline(never)]
fn nav_handoff(rec: &Recorded, spec: &AlgorithmSpec) -> (f64, f64) {
    let mut h = 0.0;
    let run = recorded::navigate(
        spec,
        rec.earth,
        rec.dt_s,
        0.0,
        &rec.init,
        &rec.incs,
        None,
        &CancelToken::new(),
        |_, s| h = s.h_m,
    )
    .expect("not cancelled");
    (h, run.wall_s)
}

/// CPU time of this thread \[s\] from /proc (10 ms resolution; None off Linux): on a
/// loaded machine the wall clock counts the time other processes had the core.
fn thread_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    // fields after the parenthesised command name: utime and stime are 14 and 15
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let algo = args.get(1).map_or("savage", String::as_str);
    let secs: f64 = args.get(2).map_or(60.0, |s| s.parse().expect("seconds"));
    let name = args.get(3).map_or("mach1-east", String::as_str);
    let scn = scenario(name);
    let n: usize = args
        .get(4)
        .map_or(scn.nav.samples, |s| s.parse().expect("samples per update"));
    let mode = match args.get(5).map(String::as_str) {
        Some(m) => m.to_string(),
        None if std::env::var_os("SDINS_NAV_ONLY").is_some() => "update".to_string(),
        None => "e2e".to_string(),
    };
    let max = (secs * scn.imu.rate_hz).round() as usize;
    let rec = record(&scn, n, Some(max));
    let mut spec = AlgorithmSpec::from_name(algo, n).expect("algorithm name");
    spec.coning = ConingSet::recommended_for(n);
    let m = rec.incs.len() as f64 / 1e6;
    let head = format!(
        "{algo} N={n} coning {} {name}: {} samples, {} updates",
        spec.coning.name(),
        rec.incs.len(),
        rec.incs.len() / n
    );
    match mode.as_str() {
        "update" => {
            let t0 = Instant::now();
            let h = black_box(nav_only(&rec, &spec));
            let wall = t0.elapsed().as_secs_f64();
            println!(
                "{head}; updates only: wall {wall:.4} s = {:.3} M samples/s (h {h:.3} m)",
                m / wall
            );
        }
        "nav" => {
            let t0 = Instant::now();
            let (h, wall_s) = black_box(nav_handoff(&rec, &spec));
            let wall = t0.elapsed().as_secs_f64();
            println!(
                "{head}; updates + state hand-off (sdins nav): wall {wall:.4} s = {:.3} M samples/s, its wall_s {wall_s:.4} s (h {h:.3} m)",
                m / wall
            );
        }
        "e2e" => {
            let c0 = thread_cpu_s();
            let t0 = Instant::now();
            let e = full_run(&rec, &spec);
            let wall = t0.elapsed().as_secs_f64();
            let cpu = c0.and_then(|c0| thread_cpu_s().map(|c1| c1 - c0));
            println!(
                "{head}; end to end: wall {wall:.4} s = {:.3} M samples/s; cpu {} ; max |pos err| {:?} m",
                m / wall,
                cpu.map_or("n/a".to_string(), |c| format!("{c:.2} s = {:.2} M samples/s", m / c)),
                e.pos_err_ned_m
            );
        }
        o => panic!("mode {o}: expected e2e, nav or update"),
    }
}
