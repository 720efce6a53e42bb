//! Vehicle kinematics (docs/scenarios.md "Vehicles"): coordinated flight and cars on the
//! analytic truth at the sample instants.
#![allow(clippy::unwrap_used)]
use sdins_core::earth::EarthModel;
use sdins_core::math::{Euler, Vec3};
use sdins_sim::truth::trajectory::{Motion, Trajectory};
use sdins_sim::truth::vehicle::{coordinated_turn, Vehicle, VehicleError};
use sdins_sim::truth::{TruthConfig, TruthGenerator};

const D2R: f64 = std::f64::consts::PI / 180.0;
const LAT0: f64 = 45.0 * D2R;
const H0: f64 = 3000.0;

fn cfg(earth: EarthModel, substeps: usize) -> TruthConfig {
    TruthConfig {
        earth,
        dt_s: 0.01,
        lat0_rad: LAT0,
        lon0_rad: 10.0 * D2R,
        h0_m: H0,
        substeps,
    }
}

/// Cruise, smooth climb, a 0.8 g-class coordinated turn (bank limit 50°, 15°/s roll rate),
/// smooth acceleration, level-off, a second turn to the left, cruise.
fn flight(alpha_deg: f64) -> Trajectory {
    let v = 200.0;
    let mut m = vec![
        (Motion::Cruise, 5.0),
        (
            Motion::ClimbSmooth {
                to_climb_rate_mps: 15.0,
            },
            10.0,
        ),
    ];
    m.extend(coordinated_turn(v, 120.0 * D2R, 50.0 * D2R, 15.0 * D2R, 0.01).unwrap());
    m.push((
        Motion::AccelerateSmooth {
            delta_speed_mps: 20.0,
        },
        8.0,
    ));
    m.push((
        Motion::ClimbSmooth {
            to_climb_rate_mps: 0.0,
        },
        10.0,
    ));
    m.extend(coordinated_turn(v + 20.0, -30.0 * D2R, 30.0 * D2R, 10.0 * D2R, 0.01).unwrap());
    m.push((Motion::Cruise, 3.0));
    Trajectory::new(v, 0.0, Euler::new(0.0, 0.0, 30.0 * D2R), &m, vec![])
        .with_vehicle(
            Vehicle::Aircraft {
                angle_of_attack_rad: alpha_deg * D2R,
            },
            EarthModel::WGS84,
            LAT0,
            H0,
        )
        .unwrap()
}

/// f^b and v^b at a truth sample, from the trajectory's analytic kinematics and the truth
/// generator's own position (Groves eq. 5.53 rearranged: f^n = v̇ + (2ω_ie + ω_en)×v − g).
fn body_f_v(tr: &Trajectory, e: &EarthModel, s: &sdins_sim::truth::TruthSample) -> (Vec3, Vec3) {
    let k = tr.kinematics(s.t_s, s.t_s - 1e-4);
    let v = k.v_n_mps;
    let w = 2.0 * e.omega_ie_n(s.lat_rad) + e.omega_en_n(s.lat_rad, s.h_m, &v);
    let f_n = k.v_dot_n_mps2 + w.cross(&v) - e.gravity_n(s.lat_rad, s.h_m);
    let c_n_b = k.c_b_n.transpose();
    (c_n_b * f_n, c_n_b * v)
}

#[test]
fn coordinated_flight_has_no_side_force_or_sideslip() {
    // f_y^b = 0 and v_y^b = 0 to 1e-12 at every sample (the bank is solved for it; the
    // remaining error is the position track's distance from the truth position times
    // ∂f/∂position, ≲ 3e-13 m/s², and rounding of |f| ≈ 15 m/s², |v| ≈ 220 m/s).
    for alpha in [0.0, 4.0] {
        let tr = flight(alpha);
        let e = EarthModel::WGS84;
        let (mut fy, mut vy, mut max_bank, mut max_pitch) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
        let mut max_fz = 0.0_f64;
        for s in TruthGenerator::new(&tr, cfg(e, 16)) {
            let (f_b, v_b) = body_f_v(&tr, &e, &s);
            fy = fy.max(f_b.y.abs());
            vy = vy.max(v_b.y.abs());
            max_fz = max_fz.max(-f_b.z);
            let eu = sdins_core::math::euler_from_c_b_n(&s.c_b_n);
            max_bank = max_bank.max(eu.roll_rad.abs());
            max_pitch = max_pitch.max(eu.pitch_rad);
        }
        eprintln!(
            "alpha {alpha} deg: max |f_y^b| {fy:e} m/s², max |v_y^b| {vy:e} m/s, max bank {:.4} deg, max pitch {:.4} deg, max load {:.4} g",
            max_bank / D2R,
            max_pitch / D2R,
            max_fz / 9.80665
        );
        assert!(fy <= 1e-12, "{fy:e}");
        assert!(vy <= 1e-12, "{vy:e}");
        if alpha != 0.0 {
            // body x is α above the velocity: pitch = γ + α in the climb
            let gamma = (15.0_f64 / 200.0).atan() / D2R;
            assert!((max_pitch / D2R - gamma - alpha).abs() < 0.05);
        }
        if alpha != 0.0 {
            continue;
        }
        // the bank reaches the 50° limit to first order (earth terms ≈ 1e-3 relative)
        assert!((max_bank / D2R - 50.0).abs() < 0.2, "{}", max_bank / D2R);
        // the climb pitches the aircraft: γ = atan(15/200) = 4.29°, plus α
        let gamma = (15.0_f64 / 200.0).atan() / D2R;
        assert!(
            (max_pitch / D2R - gamma).abs() < 0.05,
            "{}",
            max_pitch / D2R
        );
        // load factor 1/cos 50° = 1.556 in the level part of the turn
        assert!((max_fz / 9.80665 - 1.0 / (50.0 * D2R).cos()).abs() < 0.02);
    }
}

#[test]
fn coordinated_turn_respects_bank_and_roll_rate_limits() {
    // The roll rate (body-x rate relative to the wind axes, μ̇) stays within 15°/s + 1 %
    // (the limit holds to first order in the earth terms) and the bank within 50° + 0.2°.
    let tr = flight(0.0);
    let mut max_rate = 0.0_f64;
    let mut t = 0.0;
    while t < tr.duration_s {
        let h = 1e-4;
        let a = sdins_core::math::euler_from_c_b_n(&tr.kinematics(t - h, t).c_b_n).roll_rad;
        let b = sdins_core::math::euler_from_c_b_n(&tr.kinematics(t + h, t).c_b_n).roll_rad;
        max_rate = max_rate.max(((b - a) / (2.0 * h)).abs());
        t += 0.01;
    }
    eprintln!("max roll rate {:.4} deg/s", max_rate / D2R);
    assert!(max_rate / D2R < 15.0 * 1.01, "{}", max_rate / D2R);
    assert!(max_rate / D2R > 10.0);
}

fn road() -> Trajectory {
    let m = [
        (Motion::Static, 2.0),
        (Motion::Accelerate { accel_mps2: 2.0 }, 10.0),
        (
            Motion::Climb {
                to_climb_rate_mps: 1.5,
            },
            5.0,
        ),
        (Motion::TurnSmooth { angle_rad: 1.5 }, 8.0),
        (Motion::STurn { amplitude_rps: 0.2 }, 6.0),
        (
            Motion::ClimbSmooth {
                to_climb_rate_mps: -1.0,
            },
            6.0,
        ),
        (Motion::TurnRate { rate_rps: -0.1 }, 4.0),
        (
            Motion::ClimbSmooth {
                to_climb_rate_mps: 0.0,
            },
            4.0,
        ),
        (Motion::Accelerate { accel_mps2: -2.0 }, 10.0),
    ];
    Trajectory::new(0.0, 0.0, Euler::new(0.0, 0.0, -20.0 * D2R), &m, vec![])
        .with_vehicle(Vehicle::Car, EarthModel::WGS84, LAT0, 100.0)
        .unwrap()
}

#[test]
fn car_satisfies_the_nonholonomic_constraint() {
    // v_y^b = v_z^b = 0 to 1e-12 m/s at every sample, roll 0, pitch = road grade.
    let tr = road();
    let e = EarthModel::WGS84;
    let (mut lat, mut vert, mut roll) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut max_pitch = 0.0_f64;
    for s in TruthGenerator::new(&tr, cfg(e, 16)) {
        let v_b = s.c_b_n.transpose() * s.v_n_mps;
        lat = lat.max(v_b.y.abs());
        vert = vert.max(v_b.z.abs());
        let eu = sdins_core::math::euler_from_c_b_n(&s.c_b_n);
        roll = roll.max(eu.roll_rad.abs());
        max_pitch = max_pitch.max(eu.pitch_rad);
    }
    eprintln!("car: max |v_y^b| {lat:e}, max |v_z^b| {vert:e} m/s, max |roll| {roll:e} rad, max pitch {:.4} deg", max_pitch / D2R);
    assert!(lat <= 1e-12 && vert <= 1e-12, "{lat:e} {vert:e}");
    assert!(roll <= 1e-15);
    assert!((max_pitch - (1.5_f64 / 20.0).atan()).abs() < 1e-12);
}

fn num_rate(tr: &Trajectory, t: f64) -> Vec3 {
    // ω from Ċ = C[ω×], 4th-order central differences of C (h = 1e-3 s)
    let h = 1e-3;
    let c = |x: f64| tr.kinematics(x, t).c_b_n;
    let cdot = (c(t - 2.0 * h) - 8.0 * c(t - h) + 8.0 * c(t + h) - c(t + 2.0 * h)) / (12.0 * h);
    sdins_core::math::vee_antisym(&(c(t).transpose() * cdot))
}

#[test]
fn vehicle_rates_are_the_derivative_of_the_attitude() {
    // ω_nb^b of the kinematics against finite differences of C_b^n (truncation
    // h⁴|C⁽⁵⁾|/30 ≈ 1e-12·|C⁽⁵⁾|, rounding ε/h ≈ 2e-13), and v̇ against differences of v.
    for (name, tr) in [("aircraft", flight(3.0)), ("car", road())] {
        let mut worst = 0.0_f64;
        let mut t = 0.013;
        while t < tr.duration_s - 0.01 {
            let k = tr.kinematics(t, t);
            worst = worst.max((num_rate(&tr, t) - k.omega_nb_b_rps).norm());
            t += 0.377;
        }
        eprintln!("{name}: max |ω − ω_fd| {worst:e} rad/s");
        assert!(worst < 1e-9, "{name}: {worst:e}");
    }
}

fn refinement(tr: &Trajectory) -> (f64, f64) {
    let e = EarthModel::WGS84;
    let a = TruthGenerator::new(tr, cfg(e, 16));
    let b = TruthGenerator::new(tr, cfg(e, 32));
    let (mut dth, mut dv) = (0.0_f64, 0.0_f64);
    for (x, y) in a.zip(b) {
        dth = dth.max((x.inc.dtheta_b_rad - y.inc.dtheta_b_rad).norm());
        dv = dv.max((x.inc.dv_b_mps - y.inc.dv_b_mps).norm());
    }
    (dth, dv)
}

#[test]
fn vehicle_truth_refines() {
    // the truth-refinement check of the foundation (tests/truth.rs): halving the internal
    // step changes the increments by < 1e-17 rad and < 1e-15 m/s
    for (name, tr) in [("aircraft", flight(2.0)), ("car", road())] {
        let (dth, dv) = refinement(&tr);
        eprintln!("{name}: 16 vs 32 substeps: dθ {dth:e} rad, dv {dv:e} m/s");
        assert!(dth < 1e-17, "{name}: {dth:e}");
        assert!(dv < 1e-15, "{name}: {dv:e}");
    }
}

#[test]
fn aircraft_rejects_steps_in_the_acceleration() {
    let m = [
        (Motion::Cruise, 1.0),
        (
            Motion::Climb {
                to_climb_rate_mps: 5.0,
            },
            5.0,
        ),
    ];
    let r = Trajectory::new(100.0, 0.0, Euler::new(0.0, 0.0, 0.0), &m, vec![]).with_vehicle(
        Vehicle::Aircraft {
            angle_of_attack_rad: 0.0,
        },
        EarthModel::WGS84,
        LAT0,
        H0,
    );
    match r {
        Err(e @ VehicleError::Joint { index: 2, .. }) => {
            assert!(e.to_string().contains("segment 2"), "{e}")
        }
        other => panic!("{other:?}"),
    }
    // a car at rest cannot climb
    let m = [(
        Motion::Climb {
            to_climb_rate_mps: 5.0,
        },
        5.0,
    )];
    let r = Trajectory::new(0.0, 0.0, Euler::new(0.0, 0.0, 0.0), &m, vec![]).with_vehicle(
        Vehicle::Car,
        EarthModel::WGS84,
        LAT0,
        H0,
    );
    assert!(
        matches!(r, Err(VehicleError::Vertical { index: 1, .. })),
        "{r:?}"
    );
}

const FLIGHT_TOML: &str = r#"
name = "coordinated"
vehicle = "aircraft"
angle_of_attack_deg = 3.0
[start]
lat_deg = 45.0
lon_deg = 10.0
h_m = 3000.0
speed_mps = 200.0
yaw_deg = 30.0
[imu]
rate_hz = 100.0
[[segment]]
type = "cruise"
duration_s = 5.0
[[segment]]
type = "climb"
profile = "smooth"
to_climb_rate_mps = 10.0
duration_s = 10.0
[[segment]]
type = "turn"
profile = "coordinated"
angle_deg = 90.0
bank_deg = 45.0
roll_rate_dps = 15.0
[[segment]]
type = "accelerate"
profile = "smooth"
accel_mps2 = 1.0
duration_s = 10.0
[[segment]]
type = "cruise"
duration_s = 2.0
"#;

#[test]
fn scenario_file_flies_a_coordinated_turn() {
    let scn = sdins_sim::scenario::Scenario::from_toml(FLIGHT_TOML, "f.toml").unwrap();
    assert_eq!(scn.trajectory.vehicle().name(), "aircraft");
    let d = scn.duration_s() / 0.01;
    assert!((d - d.round()).abs() < 1e-6, "whole samples: {d}");
    let e = scn.nav.earth.model();
    let c = TruthConfig {
        earth: e,
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        substeps: scn.nav.substeps,
    };
    let mut fy = 0.0_f64;
    for s in TruthGenerator::new(&scn.trajectory, c) {
        fy = fy.max(body_f_v(&scn.trajectory, &e, &s).0.y.abs());
    }
    assert!(fy <= 1e-12, "{fy:e}");
}

#[test]
fn scenario_vehicle_errors_are_located() {
    let err = |text: &str| {
        sdins_sim::scenario::Scenario::from_toml(text, "f.toml")
            .unwrap_err()
            .to_string()
    };
    // a linear climb steps the acceleration: the aircraft's bank would jump
    let e = err(&FLIGHT_TOML.replacen("profile = \"smooth\"\nto_climb", "to_climb", 1));
    assert!(
        e.starts_with("f.toml:16: segment:") && e.contains("[[segment]] number 2"),
        "{e}"
    );
    let e = err(&FLIGHT_TOML.replace("\"aircraft\"", "\"boat\""));
    assert!(
        e.starts_with("f.toml:3: vehicle:") && e.contains("unknown vehicle"),
        "{e}"
    );
    let e = err(&FLIGHT_TOML.replace("yaw_deg = 30.0", "yaw_deg = 30.0\npitch_deg = 2.0"));
    assert!(
        e.contains("start.pitch_deg") && e.contains("leave this key out"),
        "{e}"
    );
    let e = err(&FLIGHT_TOML.replace("bank_deg = 45.0", "bank_deg = 95.0"));
    assert!(
        e.contains("segment.bank_deg") && e.contains("(0, 90)"),
        "{e}"
    );
    let e = err(&FLIGHT_TOML.replace(
        "roll_rate_dps = 15.0",
        "roll_rate_dps = 15.0\nduration_s = 4.0",
    ));
    assert!(
        e.contains("segment.duration_s") && e.contains("leave duration_s out"),
        "{e}"
    );
    let e = err(&FLIGHT_TOML.replace("vehicle = \"aircraft\"", "vehicle = \"car\""));
    assert!(
        e.contains("angle_of_attack_deg") && e.contains("only an aircraft"),
        "{e}"
    );
}

fn nav_max(scn: &sdins_sim::scenario::Scenario) -> sdins_sim::nav::pipeline::NavError {
    use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
    let opts = sdins_sim::nav::pipeline::RunOptions {
        algos: vec![AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 3)],
        vertical_hold: false,
        every_s: None,
        until_s: None,
        sensor_run: None,
    };
    let r = sdins_sim::nav::pipeline::run(scn, &opts, |_, _, _, _| {}, |_, _| {}).unwrap();
    r[0].max_abs
}

#[test]
fn navigation_of_mounted_imu_on_an_aircraft_tracks_the_imu_point() {
    // Song–Lee N = 3 through the coordinated flight, IMU at the reference point and at a
    // 2.3 m lever arm rotated 90° in yaw and 10° in roll: both navigate their own point
    // to the algorithm's error (which is what the bounds below measure: ≤ 1 mm and
    // ≤ 2e-10 rad, the round-trip targets of the project). A wrong lever-arm term
    // (centripetal r²·l ≈ 0.1 m/s² here) or a wrong ω would leave metres and milliradians.
    let plain = sdins_sim::scenario::Scenario::from_toml(FLIGHT_TOML, "f.toml").unwrap();
    let text = format!(
        "{FLIGHT_TOML}\n[mounting]\nimu_lever_arm_m = [2.0, -1.0, 0.5]\nimu_mount_deg = [10.0, 0.0, 90.0]\ngnss_lever_arm_m = [0.0, 0.0, -1.5]\n"
    );
    let mounted = sdins_sim::scenario::Scenario::from_toml(&text, "f.toml").unwrap();
    assert!(mounted.mounting.imu.is_some() && mounted.mounting.gnss_lever_arm_b_m.is_some());
    for (name, scn) in [("reference point", &plain), ("mounted", &mounted)] {
        let e = nav_max(scn);
        let pos = e.pos_err_ned_m.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        let att = e.att_err_rad.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        eprintln!(
            "{name}: max |pos err| {pos:e} m, max |att err| {att:e} rad, vel {:?}",
            e.vel_err_ned_mps
        );
        assert!(pos <= 1e-3, "{name}: {pos:e}");
        assert!(att <= 2e-10, "{name}: {att:e}");
    }
}
