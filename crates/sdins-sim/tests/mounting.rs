//! IMU lever arm and mounting (truth::ImuMount): closed forms on the flat, non-rotating
//! earth, where ω_ib^b = ω_nb^b exactly.
#![allow(clippy::unwrap_used)]
use sdins_core::earth::EarthModel;
use sdins_core::math::{Euler, Vec3};
use sdins_sim::truth::trajectory::{Motion, Trajectory};
use sdins_sim::truth::{ImuMount, TruthConfig, TruthGenerator};

const DT: f64 = 0.01;

fn cfg() -> TruthConfig {
    TruthConfig {
        earth: EarthModel::flat(9.80665),
        dt_s: DT,
        lat0_rad: 0.6,
        lon0_rad: 0.1,
        h0_m: 50.0,
        substeps: 16,
    }
}

#[test]
fn constant_rate_turn_has_the_centripetal_term() {
    // cruise 1 s, then a constant 20°/s turn at 30 m/s. In the turn ω_ib^b = (0, 0, r):
    // f_imu − f_ref = ω × (ω × l) = −r² (l_x, l_y, 0), per sample times δt; the first turn
    // sample also carries the rate step's impulse [ω] × l = r (−l_y, l_x, 0). Rotated by
    // C_b^s. Tolerance 1e-15 m/s: rounding of increments of ≈ 0.1 m/s.
    let r = 20f64.to_radians();
    let tr = Trajectory::new(
        30.0,
        0.0,
        Euler::new(0.0, 0.0, 0.3),
        &[
            (Motion::Cruise, 1.0),
            (Motion::TurnRate { rate_rps: r }, 2.0),
        ],
        vec![],
    );
    let l = Vec3::new(1.2, -0.7, 0.4);
    let m = ImuMount::new(l, Euler::new(0.1, -0.2, 1.5));
    let a: Vec<_> = TruthGenerator::new(&tr, cfg()).collect();
    let b: Vec<_> = TruthGenerator::new(&tr, cfg()).with_mount(m).collect();
    let centri = Vec3::new(-r * r * l.x, -r * r * l.y, 0.0) * DT;
    let impulse = Vec3::new(-r * l.y, r * l.x, 0.0);
    let (mut worst_th, mut worst_v) = (0.0_f64, 0.0_f64);
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        let want_v = m.c_b_s
            * (x.inc.dv_b_mps
                + match k {
                    0..=99 => Vec3::zeros(),
                    100 => impulse + centri,
                    _ => centri,
                });
        worst_v = worst_v.max((y.inc.dv_b_mps - want_v).norm());
        worst_th = worst_th.max((y.inc.dtheta_b_rad - m.c_b_s * x.inc.dtheta_b_rad).norm());
        assert_eq!(x.lat_rad, y.lat_rad, "truth stays at the reference point");
    }
    eprintln!("centripetal: max |Δv − closed form| {worst_v:e} m/s, Δθ {worst_th:e} rad");
    assert!(worst_v <= 1e-15, "{worst_v:e}");
    assert!(worst_th <= 1e-17, "{worst_th:e}");
}

#[test]
fn smooth_turn_has_the_angular_acceleration_term() {
    // ψ̇ = (A/T)(1 − cos 2πx): per sample Δv_imu − Δv_ref = [ψ̇]₀¹ (−l_y, l_x, 0)
    // − ∫ψ̇² dt (l_x, l_y, 0), ∫₀^τ ψ̇² = (A/T)² (3τ/2 − (T/π) sin 2πx + (T/8π) sin 4πx).
    // The Gauss remainder of ∫ψ̇² (frequency 4π/T = 2.5 rad/s, H = 10 ms) is ≈ 1e-22. The
    // tolerance is rounding: the phase 2πτ/T ≤ 2π carries ≤ 2π·ε = 1.4e-15 rad, so each
    // end rate ψ̇ is off by ≤ (A/T)·1.4e-15 = 5.6e-16 rad/s, in the generator and in this
    // closed form: 4 × 5.6e-16 × |l| (2.3 m) = 5e-15 m/s.
    use std::f64::consts::PI;
    let (big_a, big_t) = (2.0_f64, 5.0_f64);
    let tr = Trajectory::new(
        10.0,
        0.0,
        Euler::new(0.0, 0.0, 0.0),
        &[(Motion::TurnSmooth { angle_rad: big_a }, big_t)],
        vec![],
    );
    let l = Vec3::new(0.5, 2.0, -1.0);
    let m = ImuMount::new(l, Euler::new(0.0, 0.0, 0.0));
    let rate = |t: f64| big_a / big_t * (1.0 - (2.0 * PI * t / big_t).cos());
    // ∫_{t0}^{t1} ψ̇², the sine differences by sin a − sin b = 2 cos((a+b)/2) sin((a−b)/2)
    let int_sq = |t0: f64, t1: f64| {
        let (s, d) = ((t0 + t1) / big_t, (t1 - t0) / big_t);
        (big_a / big_t).powi(2)
            * (1.5 * (t1 - t0) - big_t / PI * 2.0 * (PI * s).cos() * (PI * d).sin()
                + big_t / (8.0 * PI) * 2.0 * (2.0 * PI * s).cos() * (2.0 * PI * d).sin())
    };
    let a = TruthGenerator::new(&tr, cfg());
    let b = TruthGenerator::new(&tr, cfg()).with_mount(m);
    let mut worst = 0.0_f64;
    for (x, y) in a.zip(b) {
        let (t0, t1) = (x.t_s - DT, x.t_s);
        let want = x.inc.dv_b_mps + Vec3::new(-l.y, l.x, 0.0) * (rate(t1) - rate(t0))
            - Vec3::new(l.x, l.y, 0.0) * int_sq(t0, t1);
        let d = (y.inc.dv_b_mps - want).norm();
        worst = worst.max(d);
    }
    eprintln!("angular acceleration: max |Δv − closed form| {worst:e} m/s");
    assert!(worst <= 5e-15, "{worst:e}");
}

#[test]
fn imu_point_truth_moves_with_the_lever_arm() {
    // velocity at the IMU = v + C_b^n (ω × l): in a level turn at rate r with l along body
    // y the IMU moves r·l_y slower along the track (right turn, l on the inside).
    let r = 0.2;
    let tr = Trajectory::new(
        30.0,
        0.0,
        Euler::new(0.0, 0.0, 0.0),
        &[(Motion::TurnRate { rate_rps: r }, 1.0)],
        vec![],
    );
    let m = ImuMount::new(Vec3::new(0.0, 2.0, 0.0), Euler::new(0.0, 0.0, 0.0));
    let e = cfg().earth;
    let s = TruthGenerator::new(&tr, cfg()).nth(50).unwrap();
    let kin = tr.kinematics(s.t_s, s.t_s - 1e-6);
    let (_, _, h, v, c) = m.imu_point(&e, &s, &kin);
    let v_b = s.c_b_n.transpose() * v;
    assert!(
        (v_b - Vec3::new(30.0 - r * 2.0, 0.0, 0.0)).norm() < 1e-13,
        "{v_b:?}"
    );
    assert!((h - s.h_m).abs() < 1e-12);
    assert!((c - s.c_b_n).abs().max() < 1e-15);
}
