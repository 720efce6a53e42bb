//! Routes through waypoints (docs/theory/routes.md): geodesic and rhumb legs, fly-by
//! turns, limits, truth refinement and navigation on the exact truth.
#![allow(clippy::unwrap_used)]
use sdins_core::earth::EarthModel;
use sdins_core::math::{Euler, Vec3};
use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::nav::pipeline::{run, RunOptions};
use sdins_sim::scenario::{Scenario, ScenarioError};
use sdins_sim::truth::route::{compile, CompiledRoute, LegKind, Route, RouteLimits, Waypoint};
use sdins_sim::truth::trajectory::Trajectory;
use sdins_sim::truth::{TruthConfig, TruthGenerator, TruthSample};

const D2R: f64 = std::f64::consts::PI / 180.0;
const E: EarthModel = EarthModel::WGS84;

fn wp(lat_deg: f64, lon_deg: f64, h_m: f64, speed_mps: f64) -> Waypoint {
    Waypoint {
        lat_rad: lat_deg * D2R,
        lon_rad: lon_deg * D2R,
        h_m,
        speed_mps,
        hold_s: 0.0,
    }
}

fn traj(c: &CompiledRoute) -> Trajectory {
    Trajectory::new(
        c.start_speed_mps,
        0.0,
        Euler::new(0.0, 0.0, c.start_heading_rad),
        &c.motions,
        vec![],
    )
}

fn truth(route: &Route, c: &CompiledRoute, dt: f64) -> Vec<TruthSample> {
    let w = &route.waypoints[0];
    let tr = traj(c);
    let cfg = TruthConfig {
        earth: E,
        dt_s: dt,
        lat0_rad: w.lat_rad,
        lon0_rad: w.lon_rad,
        h0_m: w.h_m,
        substeps: sdins_sim::truth::auto_substeps(dt, &tr),
    };
    TruthGenerator::new(&tr, cfg).collect()
}

fn ecef(lat: f64, lon: f64, h: f64) -> Vec3 {
    E.ecef_from_geodetic(lat, lon, h)
}

fn ecef_s(s: &TruthSample) -> Vec3 {
    ecef(s.lat_rad, s.lon_rad, s.h_m)
}

fn ecef_w(w: &Waypoint) -> Vec3 {
    ecef(w.lat_rad, w.lon_rad, w.h_m)
}

/// Arrival miss at `w` split into (along, cross) the last sample's heading \[m\].
fn arrival(s: &TruthSample, w: &Waypoint) -> (f64, f64) {
    let d = EarthModel::c_e_n(w.lat_rad, w.lon_rad) * (ecef_s(s) - ecef_w(w));
    let psi = s.v_n_mps.y.atan2(s.v_n_mps.x);
    let (sp, cp) = psi.sin_cos();
    (d.x * cp + d.y * sp, -d.x * sp + d.y * cp)
}

#[test]
fn great_circle_leg_100km_holds_the_geodesic() {
    // 45N 10E → 45.5N 11.1E (≈100 km), 100 m/s, h = 0, 10 Hz
    let route = Route {
        waypoints: vec![wp(45.0, 10.0, 0.0, 100.0), wp(45.5, 11.1, 0.0, 100.0)],
        legs: LegKind::GreatCircle,
        limits: RouteLimits::default(),
    };
    let dt = 0.1;
    let c = compile(&route, E, dt).unwrap();
    let s = truth(&route, &c, dt);
    // Clairaut's relation on the ellipsoid (h = 0): a geodesic keeps N cos L sin ψ
    // constant; its drift δc is the heading error δψ = δc/(N cos L cos ψ). Bound: the
    // heading interpolant of the RK4 solution (1 s steps, local error ~ (V/R)^4 V h^5 ≪
    // 1e-15) plus rounding: 1e-13 rad, i.e. a cross-track drift ∫V δψ dt ≤ 1e-8 m.
    let clairaut = |x: &TruthSample| {
        let rn = E.radii(x.lat_rad).r_n_m + x.h_m;
        rn * x.lat_rad.cos() * x.v_n_mps.y / x.v_n_mps.x.hypot(x.v_n_mps.y)
    };
    let c0 = clairaut(&s[0]);
    let (mut max_dpsi, mut drift) = (0.0_f64, 0.0_f64);
    for x in &s {
        let rn = E.radii(x.lat_rad).r_n_m + x.h_m;
        let psi = x.v_n_mps.y.atan2(x.v_n_mps.x);
        let dpsi = (clairaut(x) - c0) / (rn * x.lat_rad.cos() * psi.cos());
        max_dpsi = max_dpsi.max(dpsi.abs());
        drift += 100.0 * dpsi * dt;
    }
    let (along, cross) = arrival(s.last().unwrap(), &route.waypoints[1]);
    eprintln!(
        "geodesic 100 km: max heading error {max_dpsi:e} rad, cross-track drift {drift:e} m, \
         arrival along {along:e} m, cross {cross:e} m, report {:?}",
        c.report[1]
    );
    assert!(max_dpsi <= 1e-13, "{max_dpsi:e}");
    assert!(drift.abs() <= 1e-8, "{drift:e}");
    // arrival: cross-track to the shooting tolerance (1e-6 m) plus the truth's position
    // agreement with the compiler's RK4 (≪ 1 mm); along-track within half a sample of
    // travel (cruise durations are whole samples)
    assert!(cross.abs() <= 1e-3, "{cross:e}");
    assert!(along.abs() <= 0.5 * 100.0 * dt + 1e-3, "{along:e}");
    let rep = (ecef_s(s.last().unwrap()) - ecef_w(&route.waypoints[1])).norm();
    assert!(
        (rep - c.report[1].miss_m).abs() <= 1e-3,
        "{rep} vs {:?}",
        c.report[1]
    );
    // a great circle on a sphere would not do: the spherical initial course differs
    let (l1, l2, dl) = (45.0 * D2R, 45.5 * D2R, 1.1 * D2R);
    let sph = (dl.sin() * l2.cos()).atan2(l1.cos() * l2.sin() - l1.sin() * l2.cos() * dl.cos());
    eprintln!(
        "start heading {:.9} deg, spherical formula {:.9} deg",
        c.start_heading_rad / D2R,
        sph / D2R
    );
    assert!(
        (c.start_heading_rad - sph).abs() < 0.01,
        "{}",
        c.start_heading_rad - sph
    );
}

#[test]
fn rhumb_leg_keeps_its_heading() {
    let route = Route {
        waypoints: vec![wp(45.0, 10.0, 0.0, 100.0), wp(45.5, 11.1, 0.0, 100.0)],
        legs: LegKind::Rhumb,
        limits: RouteLimits::default(),
    };
    let dt = 0.1;
    let c = compile(&route, E, dt).unwrap();
    let s = truth(&route, &c, dt);
    let psi0 = c.start_heading_rad;
    let max_dpsi = s
        .iter()
        .map(|x| (x.v_n_mps.y.atan2(x.v_n_mps.x) - psi0).abs())
        .fold(0.0, f64::max);
    // the loxodrome on the ellipsoid: ψ = atan2(Δλ, Δq), q = atanh(sin L) − e atanh(e sin L)
    let e = (E.f * (2.0 - E.f)).sqrt();
    let q = |l: f64| l.sin().atanh() - e * (e * l.sin()).atanh();
    let formula = (1.1 * D2R).atan2(q(45.5 * D2R) - q(45.0 * D2R));
    // flying the formula's heading over the leg (≈100 km) would miss by |ψ − ψ_f|·100 km
    let formula_miss = (psi0 - formula).abs() * 1.0e5;
    let (along, cross) = arrival(s.last().unwrap(), &route.waypoints[1]);
    eprintln!(
        "rhumb: heading {:.12} deg, formula {:.12} deg (miss from the formula heading {formula_miss:e} m), \
         max heading change {max_dpsi:e} rad, arrival along {along:e} m cross {cross:e} m",
        psi0 / D2R,
        formula / D2R
    );
    assert!(max_dpsi <= 1e-14, "{max_dpsi:e}");
    assert!(cross.abs() <= 1e-3, "{cross:e}");
    assert!(along.abs() <= 5.0 + 1e-3, "{along:e}");
    // the shot heading is the ellipsoidal loxodrome (shooting tolerance 1e-6 m / 100 km)
    assert!(formula_miss <= 1e-3, "{formula_miss:e}");
}

fn demo_route() -> Route {
    Route {
        waypoints: vec![
            wp(45.0, 10.0, 100.0, 50.0),
            wp(45.03, 10.0, 100.0, 60.0),
            wp(45.03, 10.09, 300.0, 60.0),
            wp(45.0, 10.11, 300.0, 60.0),
        ],
        legs: LegKind::GreatCircle,
        limits: RouteLimits::default(),
    }
}

/// Signed distance of `x` from the normal-section plane through `a`, `b` and the
/// ellipsoid normal at their midpoint (within ~e²(d/R)²·d ≈ 1e-4 m of the geodesic
/// for these few-km legs) \[m\].
fn from_leg(a: &Waypoint, b: &Waypoint, x: Vec3) -> f64 {
    let (pa, pb) = (ecef_w(a), ecef_w(b));
    let lm = 0.5 * (a.lat_rad + b.lat_rad);
    let om = 0.5 * (a.lon_rad + b.lon_rad);
    let up = Vec3::new(lm.cos() * om.cos(), lm.cos() * om.sin(), lm.sin());
    let nrm = (pb - pa).cross(&up).normalize();
    (x - pa).dot(&nrm)
}

#[test]
#[allow(clippy::needless_range_loop)]
fn fly_by_turns_cut_the_corner_and_meet_the_next_leg() {
    let route = demo_route();
    let dt = 0.01;
    let c = compile(&route, E, dt).unwrap();
    let s = truth(&route, &c, dt);
    let tr = traj(&c);
    let w = &route.waypoints;
    for j in 1..3 {
        // independent closest approach on the truth samples, refined by a parabola
        let xw = ecef_w(&w[j]);
        let d: Vec<f64> = s.iter().map(|x| (ecef_s(x) - xw).norm()).collect();
        let i = (1..d.len() - 1)
            .min_by(|&a, &b| d[a].total_cmp(&d[b]))
            .unwrap();
        let (y0, y1, y2) = (d[i - 1], d[i], d[i + 1]);
        let u = 0.5 * (y0 - y2) / (y0 - 2.0 * y1 + y2);
        let closest = y1 - 0.25 * (y0 - y2) * u;
        let r = &c.report[j];
        // circular-arc estimate at the hold rate: r (1/cos(Δψ/2) − 1); the ramps turn
        // later and more gently, so the path cuts a little more (measured +0.9 %, +1.8 %)
        let rate = 9.80665 * 25f64.to_radians().tan() / w[j].speed_mps;
        let arc = w[j].speed_mps / rate * (1.0 / (0.5 * r.turn_rad).cos() - 1.0);
        eprintln!(
            "waypoint {}: reported {:.6} m at {:.3} s, truth closest {closest:.6} m at {:.3} s, arc estimate {arc:.3} m",
            j + 1,
            r.miss_m,
            r.arrival_s,
            s[i].t_s + u * dt
        );
        // the compiler's path agrees with the truth to its RK4 (≪ 1 mm) and the
        // parabola (≈ (V dt)²·κ ≪ 1 mm)
        assert!(
            (closest - r.miss_m).abs() <= 1e-3,
            "{closest} vs {}",
            r.miss_m
        );
        assert!((s[i].t_s + u * dt - r.arrival_s).abs() <= 2.0 * dt);
        assert!(
            closest >= arc && closest <= 1.05 * arc,
            "{closest} vs arc {arc}"
        );
    }
    // after each turn (and before the next) the path lies on the next leg: the turn exit
    // is placed on the ideal leg by the flat-turn geometry (error ~ d³/R² ≪ 1 mm), and
    // the previous leg's whole-sample cruise shifts the turn by ≤ V dt/2 along-track, which
    // the turn maps to ≤ V dt/2 across, shrinking linearly to 0 at the next target
    let segs = tr.segments();
    let mut worst = [0.0_f64; 3];
    for k in 1..3 {
        // the leg k pieces: motions of waypoint k after its turn
        let first = c.motion_waypoint.iter().position(|&m| m == k).unwrap() + 3;
        let last = c.motion_waypoint.iter().rposition(|&m| m == k).unwrap();
        let (t0, t1) = (segs[first].t0_s, segs[last].t0_s + segs[last].duration_s);
        for x in s.iter().filter(|x| x.t_s >= t0 && x.t_s <= t1) {
            worst[k] = worst[k].max(from_leg(&w[k], &w[k + 1], ecef_s(x)).abs());
        }
    }
    eprintln!(
        "cross-track from the next leg after the turns: {:?} m",
        &worst[1..]
    );
    for (k, v) in worst.iter().enumerate().skip(1) {
        assert!(*v <= 0.5 * w[k].speed_mps * dt + 1e-3, "leg {k}: {v}");
    }
}

#[test]
fn limits_are_honoured() {
    let route = demo_route();
    let dt = 0.01;
    let c = compile(&route, E, dt).unwrap();
    let tr = traj(&c);
    let lim = RouteLimits::default();
    let (mut rate, mut climb, mut acc) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut worst_rate_ratio = 0.0_f64;
    let n = (tr.duration_s / 0.005) as usize;
    for i in 0..=n {
        let t = i as f64 * 0.005;
        let k = tr.kinematics(t, t);
        let v = k.v_n_mps;
        let s = v.x.hypot(v.y);
        // free vehicle, roll = pitch = 0: ω_nb^b = (0, 0, ψ̇)
        let r = k.omega_nb_b_rps.z.abs();
        rate = rate.max(r);
        worst_rate_ratio = worst_rate_ratio.max(r * s / (9.80665 * 25f64.to_radians().tan()));
        climb = climb.max(-v.z);
        let a_along = (k.v_dot_n_mps2.x * v.x + k.v_dot_n_mps2.y * v.y) / s;
        acc = acc.max(a_along.abs()).max(k.v_dot_n_mps2.z.abs());
    }
    eprintln!(
        "max turn rate {:.5} deg/s (bank-limit ratio {worst_rate_ratio:.9}), max climb {climb:.9} m/s, max |accel| {acc:.9} m/s²",
        rate / D2R
    );
    assert!(worst_rate_ratio <= 1.0 + 1e-9, "{worst_rate_ratio}");
    assert!(climb <= lim.climb_rate_mps * (1.0 + 1e-12), "{climb}");
    assert!(
        climb >= 0.9 * lim.climb_rate_mps,
        "the climb should reach its limit: {climb}"
    );
    assert!(acc <= lim.accel_mps2 * (1.0 + 1e-9), "{acc}");
}

const DEMO: &str = include_str!("../scenarios/route-demo.toml");

#[test]
fn route_truth_refines_and_navigates() {
    // Gauss truth vs the RK4 reference at twice the substeps, across the turn at the
    // second waypoint (segment joints inside), as tests/truth.rs does for the built-ins
    let scn = Scenario::from_toml(DEMO, "route-demo").unwrap();
    let mut c1 = scn.truth_config();
    let base = scn.nav.substeps;
    c1.substeps = base;
    let c2 = TruthConfig {
        substeps: 2 * base,
        ..c1
    };
    let k = (40.0 / c1.dt_s).round() as u64;
    let mut a = TruthGenerator::new(&scn.trajectory, c1).starting_at_sample(k);
    let mut b = TruthGenerator::new(&scn.trajectory, c2)
        .reference_rk4()
        .starting_at_sample(k);
    let (mut dth, mut dv) = (0.0_f64, 0.0_f64);
    for _ in 0..3000 {
        let (x, y) = (a.next().unwrap(), b.next().unwrap());
        dth = dth.max((x.inc.dtheta_b_rad - y.inc.dtheta_b_rad).norm());
        dv = dv.max((x.inc.dv_b_mps - y.inc.dv_b_mps).norm());
    }
    eprintln!(
        "route Gauss ({base}) vs RK4 ({}): dθ {dth:e} rad, dv {dv:e} m/s",
        2 * base
    );
    // the bounds of the built-in scenarios' refinement checks (tests/truth.rs)
    assert!(dth <= 2e-17 * 10.0, "{dth:e}");
    assert!(dv <= 2e-15, "{dv:e}");

    // songlee N = 2 on the error-free IMU at 100 and 200 Hz: millimetre level, and the
    // velocity error falls as the second-order algorithm error (×1/4 per halving of dt;
    // a truth inconsistent with its own increments would leave a floor)
    let mut errs = Vec::new();
    for rate in [100.0, 200.0] {
        let text = DEMO.replace("rate_hz = 100.0", &format!("rate_hz = {rate:.1}"));
        let scn = Scenario::from_toml(&text, "route-demo").unwrap();
        let opts = RunOptions {
            algos: vec![AlgorithmSpec::new(AlgorithmKind::SongLee, 2)],
            vertical_hold: false,
            every_s: Some(2000.0 / rate),
            until_s: None,
            sensor_run: None,
        };
        let sum = run(&scn, &opts, |_, _, _, _| {}, |_, _| {}).unwrap();
        let m = &sum[0].max_abs;
        let p = Vec3::from(m.pos_err_ned_m).norm();
        let v = Vec3::from(m.vel_err_ned_mps).norm();
        let att = Vec3::from(m.att_err_rad).norm();
        eprintln!(
            "route songlee N=2 at {rate} Hz: max pos {p:e} m, vel {v:e} m/s, att {att:e} rad"
        );
        errs.push((p, v, att));
    }
    assert!(errs[0].0 <= 1e-2 && errs[0].2 <= 2e-9, "{:?}", errs[0]);
    let ratio = errs[0].1 / errs[1].1;
    assert!((3.0..=6.0).contains(&ratio), "velocity error ratio {ratio}");
}

fn err_of(text: &str) -> (usize, String, String) {
    match Scenario::from_toml(text, "r.toml") {
        Err(ScenarioError::Invalid {
            line, key, message, ..
        }) => (line, key, message),
        other => panic!("expected an error, got {other:?}"),
    }
}

#[test]
fn bad_routes_are_located_errors() {
    // waypoint 2 too close for the turn at it: named with its line
    let close = DEMO.replace(
        "lat_deg = 45.03\nlon_deg = 10.0\n",
        "lat_deg = 45.003\nlon_deg = 10.0\n",
    );
    let (line, key, msg) = err_of(&close);
    let wp2_line = close
        .lines()
        .position(|l| l.starts_with("lat_deg = 45.003"))
        .unwrap();
    eprintln!("{line}: {key}: {msg}");
    assert_eq!(key, "waypoint");
    assert!(msg.contains("waypoint 2"), "{msg}");
    assert_eq!(line, wp2_line, "{msg}"); // the [[waypoint]] header line precedes it
                                         // missing key
    let (_, key, msg) = err_of(&DEMO.replacen("speed_mps = 60.0\n", "", 1));
    assert!(
        key.contains("speed_mps") || msg.contains("speed_mps"),
        "{key}: {msg}"
    );
    // segments and waypoints mixed
    let mixed = format!("{DEMO}\n[[segment]]\ntype = \"cruise\"\nduration_s = 1.0\n");
    let (_, key, msg) = err_of(&mixed);
    assert_eq!(key, "segment", "{msg}");
    assert!(msg.contains("not both"), "{msg}");
    // an explicit start position
    let start = format!("{DEMO}\n[start]\nlat_deg = 45.0\nlon_deg = 10.0\n");
    let (line, key, _) = err_of(&start);
    assert_eq!(key, "start");
    assert!(line > DEMO.lines().count(), "{line}");
    // one waypoint only
    let one = DEMO
        .split("[[waypoint]]")
        .take(2)
        .collect::<Vec<_>>()
        .join("[[waypoint]]");
    let (_, key, msg) = err_of(&one);
    assert!(
        key == "waypoint" && msg.contains("at least two"),
        "{key}: {msg}"
    );
    // coincident waypoints
    let same = DEMO.replacen(
        "lat_deg = 45.03\nlon_deg = 10.0\n",
        "lat_deg = 45.0\nlon_deg = 10.0\n",
        1,
    );
    let (_, _, msg) = err_of(&same);
    assert!(msg.contains("coincides"), "{msg}");
    // NaN and a leg across a pole
    let (_, key, _) = err_of(&DEMO.replacen("h_m = 300.0", "h_m = nan", 1));
    assert_eq!(key, "waypoint.h_m");
    let polar = DEMO
        .replacen(
            "lat_deg = 45.03\nlon_deg = 10.09",
            "lat_deg = 89.0\nlon_deg = 190.0",
            1,
        )
        .replacen(
            "lat_deg = 45.0\nlon_deg = 10.11",
            "lat_deg = 88.0\nlon_deg = 10.11",
            1,
        );
    let (_, _, msg) = err_of(&polar);
    eprintln!("polar: {msg}");
    assert!(msg.contains("89.5") || msg.contains("latitude"), "{msg}");
    // bad limits
    let (_, key, _) = err_of(&DEMO.replace(
        "bank_limit_deg = 25.0",
        "bank_limit_deg = 25.0\nturn_rate_limit_dps = 3.0",
    ));
    assert_eq!(key, "route.turn_rate_limit_dps");
}

#[test]
fn car_routes_keep_the_non_holonomic_constraint_and_aircraft_are_refused() {
    let car = DEMO.replacen("\n[imu]", "vehicle = \"car\"\n\n[imu]", 1);
    let scn = Scenario::from_toml(&car, "car").unwrap();
    let mut worst = 0.0_f64;
    for s in TruthGenerator::new(&scn.trajectory, scn.truth_config()).step_by(50) {
        let v_b = s.c_b_n.transpose() * s.v_n_mps;
        worst = worst.max(v_b.y.abs()).max(v_b.z.abs());
    }
    eprintln!("car route: max |v_y^b|, |v_z^b| {worst:e} m/s");
    assert!(worst <= 1e-12, "{worst:e}");
    // aircraft: the geodesic heading's ψ̈ (≈1e-10 rad/s²) steps at the turn joints, which
    // the aircraft joint rule (jerk continuous to 1e-9) refuses, naming the waypoint
    let air = DEMO.replacen("\n[imu]", "vehicle = \"aircraft\"\n\n[imu]", 1);
    let (_, _, msg) = err_of(&air);
    assert!(msg.contains("[[waypoint]] number"), "{msg}");
}

#[test]
fn holds_rest_at_the_first_and_last_waypoints() {
    let mut route = demo_route();
    route.waypoints[0].hold_s = 10.0;
    route.waypoints[3].hold_s = 5.0;
    route.limits.accel_mps2 = 3.0;
    let dt = 0.01;
    let c = compile(&route, E, dt).unwrap();
    let tr = traj(&c);
    assert_eq!(c.start_speed_mps, 0.0);
    for t in [0.0, 5.0, 10.0, tr.duration_s - 5.0, tr.duration_s] {
        assert_eq!(tr.kinematics(t, t).v_n_mps.norm(), 0.0, "at {t} s");
    }
    let s = truth(&route, &c, dt);
    let end = (ecef_s(s.last().unwrap()) - ecef_w(&route.waypoints[3])).norm();
    eprintln!(
        "hold: rest at the last waypoint {end} m from it, report {:?}",
        c.report[3]
    );
    // the stop is flown as the last leg piece: along-track miss ≤ V dt/2
    assert!(end <= 0.5 * 60.0 * dt + 1e-3, "{end}");
    // an interior hold is refused, naming the waypoint
    route.waypoints[1].hold_s = 1.0;
    let e = compile(&route, E, dt).unwrap_err().to_string();
    assert!(e.contains("waypoint 2") && e.contains("hold_s"), "{e}");
}
