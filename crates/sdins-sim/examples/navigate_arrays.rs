//! The work of Python's `sdins.navigate`, in Rust alone (bench/python_bench.py compares
//! the two): flat row-major Δθ/Δv arrays of 360 000 samples (mach1-east, first 720 s)
//! → increments → songlee-complete with N = 3 → per-update columns t, lat, lon, h,
//! v_NED, Euler angles and q_b_n. Prints the median time of 5 repetitions in ms.
//!
//! `cargo run --release -p sdins-sim --example navigate_arrays`

use sdins_core::coning::Increment;
use sdins_core::math::Vec3;
use sdins_core::nav::AlgorithmSpec;
use sdins_sim::cancel::CancelToken;
use sdins_sim::nav::recorded::navigate;
use sdins_sim::scenario::Scenario;
use sdins_sim::truth::{TruthConfig, TruthGenerator};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scn = Scenario::load("mach1-east")?;
    let cfg = TruthConfig {
        earth: scn.nav.earth.model(),
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        substeps: scn.nav.substeps,
    };
    let gen = TruthGenerator::new(&scn.trajectory, cfg);
    let init = gen.initial_state();
    let (mut dth, mut dv) = (Vec::new(), Vec::new());
    for s in gen.take(360_000) {
        dth.extend_from_slice(&[
            s.inc.dtheta_b_rad.x,
            s.inc.dtheta_b_rad.y,
            s.inc.dtheta_b_rad.z,
        ]);
        dv.extend_from_slice(&[s.inc.dv_b_mps.x, s.inc.dv_b_mps.y, s.inc.dv_b_mps.z]);
    }
    let spec = AlgorithmSpec::from_name("songlee-complete", 3).ok_or("algorithm")?;
    let mut times = Vec::new();
    let mut loops = Vec::new();
    for _ in 0..5 {
        let t0 = Instant::now();
        let incs: Vec<Increment> = dth
            .chunks_exact(3)
            .zip(dv.chunks_exact(3))
            .map(|(p, q)| Increment {
                dtheta_b_rad: Vec3::new(p[0], p[1], p[2]),
                dv_b_mps: Vec3::new(q[0], q[1], q[2]),
            })
            .collect();
        let n = incs.len() / 3;
        let mut cols: [Vec<f64>; 7] =
            std::array::from_fn(|k| Vec::with_capacity(n * [1, 1, 1, 1, 3, 3, 4][k]));
        let r = navigate(
            &spec,
            cfg.earth,
            cfg.dt_s,
            0.0,
            &init,
            &incs,
            None,
            &CancelToken::new(),
            |t, s| {
                let e = s.euler();
                let q = s.q_b_n();
                cols[0].push(t);
                cols[1].push(s.lat_rad);
                cols[2].push(s.lon_rad);
                cols[3].push(s.h_m);
                cols[4].extend_from_slice(&[s.v_n_mps.x, s.v_n_mps.y, s.v_n_mps.z]);
                cols[5].extend_from_slice(&[e.roll_rad, e.pitch_rad, e.yaw_rad]);
                cols[6].extend_from_slice(&[q.w, q.x, q.y, q.z]);
            },
        )
        .map_err(|_| "cancelled")?;
        times.push(t0.elapsed().as_secs_f64());
        loops.push(r.wall_s);
        std::hint::black_box(&cols);
    }
    times.sort_by(f64::total_cmp);
    loops.sort_by(f64::total_cmp);
    println!(
        "rust arrays-in/arrays-out navigate: {:.1} ms (navigation loop {:.1} ms), median of 5",
        times[2] * 1e3,
        loops[2] * 1e3
    );
    Ok(())
}
