//! Routes through waypoints (docs/theory/routes.md): geodesic and rhumb legs, fly-by
//! turns, limits, on the exact truth.
#![allow(clippy::unwrap_used)]
use sdins_core::earth::EarthModel;
use sdins_core::math::Euler;
use sdins_sim::route::{compile, CompiledRoute, LegKind, Route, RouteLimits, Waypoint};
use sdins_sim::trajectory::Trajectory;
use sdins_sim::truth::{TruthConfig, TruthGenerator, TruthSample};

const D2R: f64 = std::f64::consts::PI / 180.0;

fn wp(lat_deg: f64, lon_deg: f64, h_m: f64, speed_mps: f64) -> Waypoint {
    Waypoint { lat_rad: lat_deg * D2R, lon_rad: lon_deg * D2R, h_m, speed_mps, hold_s: 0.0 }
}

fn truth(route: &Route, c: &CompiledRoute, dt: f64) -> Vec<TruthSample> {
    let w = &route.waypoints[0];
    let traj = Trajectory::new(
        c.start_speed_mps,
        0.0,
        Euler::new(0.0, 0.0, c.start_heading_rad),
        &c.motions,
        vec![],
    );
    let cfg = TruthConfig { earth: EarthModel::WGS84, dt_s: dt, lat0_rad: w.lat_rad, lon0_rad: w.lon_rad, h0_m: w.h_m, substeps: 0 };
    let cfg = TruthConfig { substeps: sdins_sim::truth::auto_substeps(dt, &traj), ..cfg };
    TruthGenerator::new(&traj, cfg).collect()
}

fn ecef(lat: f64, lon: f64, h: f64) -> sdins_core::math::Vec3 {
    EarthModel::WGS84.ecef_from_geodetic(lat, lon, h)
}

#[test]
fn great_circle_leg_100km() {
    let route = Route {
        waypoints: vec![wp(45.0, 10.0, 0.0, 100.0), wp(45.5, 11.1, 0.0, 100.0)],
        legs: LegKind::GreatCircle,
        limits: RouteLimits::default(),
    };
    let dt = 0.1;
    let t0 = std::time::Instant::now();
    let c = compile(&route, EarthModel::WGS84, dt).unwrap();
    eprintln!("compile {:?} motions {}", t0.elapsed(), c.motions.len());
    let s = truth(&route, &c, dt);
    eprintln!("truth {:?} n {}", t0.elapsed(), s.len());
    let e = EarthModel::WGS84;
    let last = s.last().unwrap();
    let w = &route.waypoints[1];
    let miss = (ecef(last.lat_rad, last.lon_rad, last.h_m) - ecef(w.lat_rad, w.lon_rad, w.h_m)).norm();
    eprintln!("arrival miss {miss} report {:?}", c.report[1]);
    let clairaut = |x: &TruthSample| {
        let rn = e.radii(x.lat_rad).r_n_m + x.h_m;
        rn * x.lat_rad.cos() * x.v_n_mps.y / x.v_n_mps.x.hypot(x.v_n_mps.y)
    };
    let c0 = clairaut(&s[0]);
    let mut max_dpsi: f64 = 0.0;
    for x in &s {
        let rn = e.radii(x.lat_rad).r_n_m + x.h_m;
        let psi = x.v_n_mps.y.atan2(x.v_n_mps.x);
        let dpsi = (clairaut(x) - c0) / (rn * x.lat_rad.cos() * psi.cos());
        max_dpsi = max_dpsi.max(dpsi.abs());
    }
    eprintln!("max heading error from Clairaut {max_dpsi:e}");
}

#[test]
fn fly_by_turn_scratch() {
    let route = Route {
        waypoints: vec![wp(45.0, 10.0, 100.0, 50.0), wp(45.03, 10.0, 100.0, 60.0), wp(45.03, 10.09, 300.0, 60.0), wp(45.0, 10.11, 300.0, 60.0)],
        legs: LegKind::GreatCircle,
        limits: RouteLimits::default(),
    };
    let dt = 0.01;
    let c = compile(&route, EarthModel::WGS84, dt).unwrap();
    for (m, d) in &c.motions { eprintln!("{d:10.3} {m:?}"); }
    for r in &c.report { eprintln!("{r:?}"); }
    let s = truth(&route, &c, dt);
    for (j, w) in route.waypoints.iter().enumerate() {
        let xw = ecef(w.lat_rad, w.lon_rad, w.h_m);
        let (i, d) = s.iter().enumerate().map(|(i, x)| (i, (ecef(x.lat_rad, x.lon_rad, x.h_m) - xw).norm())).min_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
        eprintln!("wp {j}: closest {d} at t {}", s[i].t_s);
    }
}
