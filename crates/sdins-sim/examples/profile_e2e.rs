//! Profiling driver for the end-to-end loop of `benches/end_to_end.rs` (navigation +
//! `nav_error` after every update, increments from memory), for callgrind:
//!
//! ```text
//! cargo build --release -p sdins-sim --example profile_e2e
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*full_run*' \
//!     target/release/examples/profile_e2e savage 60
//! ```
//!
//! Arguments: algorithm (default `savage`), seconds of `mach1-east` (default 60),
//! scenario (default `mach1-east`). Prints the errors and the wall time. With
//! `SDINS_NAV_ONLY=1` it times the navigation updates alone (no `nav_error`).

#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "../benches/common/mod.rs"]
mod common;

use common::{full_run, record, scenario, Recorded};
use sdins_core::nav::{AlgorithmSpec, AnyMechanization, Mechanization};
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
    let n = scn.nav.samples;
    let max = (secs * scn.imu.rate_hz).round() as usize;
    let rec = record(&scn, n, Some(max));
    let spec = AlgorithmSpec::from_name(algo, n).expect("algorithm name");
    if std::env::var_os("SDINS_NAV_ONLY").is_some() {
        let t0 = Instant::now();
        let h = nav_only(&rec, &spec);
        let wall = t0.elapsed().as_secs_f64();
        println!(
            "{algo} N={n} navigation only: wall {wall:.4} s = {:.3} M samples/s (h {h:.3} m)",
            rec.incs.len() as f64 / 1e6 / wall
        );
        return;
    }
    let c0 = thread_cpu_s();
    let t0 = Instant::now();
    let e = full_run(&rec, &spec);
    let wall = t0.elapsed().as_secs_f64();
    let cpu = c0.and_then(|c0| thread_cpu_s().map(|c1| c1 - c0));
    let m = rec.incs.len() as f64 / 1e6;
    println!(
        "{algo} N={n} {} samples: wall {wall:.4} s = {:.3} M samples/s; cpu {} ; max |pos err| {:?} m",
        rec.incs.len(),
        m / wall,
        cpu.map_or("n/a".to_string(), |c| format!("{c:.2} s = {:.2} M samples/s", m / c)),
        e.pos_err_ned_m
    );
}
