#![allow(clippy::unwrap_used)]
mod common;
use common::*;
use sdins_core::nav::AlgorithmKind as K;
use sdins_sim::scenario::Scenario;

#[test]
#[ignore]
fn explore() {
    let name = std::env::var("SCN").unwrap_or("mach1-east".into());
    let scn = Scenario::load(&name).unwrap();
    let n = scn.nav.samples;
    let epochs: Vec<f64> = std::env::var("EPOCHS").unwrap_or("1800,3600,5400".into()).split(',').map(|x| x.parse().unwrap()).collect();
    let t0 = std::time::Instant::now();
    let (s, got) = run_at(&scn, vec![spec(K::Savage, n), spec(K::SongLee, n), spec(K::SongLeeComplete, n), spec(K::DualQuat, n)], &epochs, false);
    for (i, g) in got.iter().enumerate() {
        for e in g {
            print(&s[i].algo, e);
        }
        eprintln!("{} wall {:.3}s", s[i].algo, s[i].wall_s);
    }
    eprintln!("total {:?}", t0.elapsed());
}
