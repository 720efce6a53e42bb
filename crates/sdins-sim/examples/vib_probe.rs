#![allow(clippy::unwrap_used)]
use std::time::Instant;
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let t = Instant::now();
    let s = sdins_sim::scenario::Scenario::load(&p).unwrap();
    println!("parse {:?}", t.elapsed());
    let dt = s.imu.dt_s();
    println!("substeps {} panels {}", s.nav.substeps, s.trajectory.random_vibration_panels(dt));
    for rv in s.trajectory.random_vibrations() {
        println!("3-node {:?}", rv.gauss_remainder(dt, 1, 3));
        for p in 1..4 { println!("4-node P={p} {:?}", rv.gauss_remainder(dt, p, 4)); }
    }
    for r in &s.vibration { println!("{}", r.summary()); }
    let t = Instant::now();
    let g = sdins_sim::truth::TruthGenerator::new(&s.trajectory, s.truth_config());
    let n = g.count();
    println!("truth {n} {:?}", t.elapsed());
}
