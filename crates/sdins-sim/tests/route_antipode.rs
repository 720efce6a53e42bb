//! Nearly antipodal waypoints (docs/theory/routes.md §"Nearly antipodal waypoints"): a leg
//! 0.5° from the antipode is flown to its end; a leg to the antipode, or to any point of
//! the cut locus, is refused as ambiguous naming both waypoints.
#![allow(clippy::unwrap_used)]
use sdins_core::earth::EarthModel;
use sdins_sim::truth::route::{
    compile, LegKind, Route, RouteError, RouteLimits, Waypoint, AMBIGUOUS_M,
};

const E: EarthModel = EarthModel::WGS84;

fn wp(lat_deg: f64, lon_deg: f64, speed_mps: f64) -> Waypoint {
    Waypoint {
        lat_rad: lat_deg.to_radians(),
        lon_rad: lon_deg.to_radians(),
        h_m: 0.0,
        speed_mps,
        hold_s: 0.0,
    }
}

fn route(a: Waypoint, b: Waypoint, legs: LegKind) -> Route {
    Route {
        waypoints: vec![a, b],
        legs,
        limits: RouteLimits::default(),
    }
}

#[test]
fn half_a_degree_from_the_antipode_is_flown_to_its_end() {
    // 45°N 10°E to 45°S 169.5°W: 0.5° of longitude short of the antipode (the cut locus
    // starts 0.427° from it at this latitude), 19 981 km; the geodesic heads due west
    // (azimuth −90.026°) and stays within ±45°
    let v = 150.0;
    let dt = 0.01;
    let r = route(
        wp(45.0, 10.0, v),
        wp(-45.0, -169.5, v),
        LegKind::GreatCircle,
    );
    let c = compile(&r, E, dt).unwrap();
    let last = c.report[1];
    eprintln!(
        "antipode - 0.5 deg: start heading {:.9} deg, {} s, arrival miss {:.4} m",
        c.start_heading_rad.to_degrees(),
        last.arrival_s,
        last.miss_m
    );
    // the along-track miss is at most V·dt/2 = 0.75 m (whole samples); before the fix the
    // leg was a few seconds long and missed by 12 755 km
    assert!(last.miss_m < 0.5 * v * dt + 1e-3, "{}", last.miss_m);
    assert!(last.miss_m < 1.0);
    // the flight time is the geodesic's length (19 981 349.34 m, Karney) over the speed
    assert!(
        (last.arrival_s * v - 19_981_349.343_755).abs() < 0.5 * v * dt + 1e-3,
        "{}",
        last.arrival_s * v
    );
    assert!((c.start_heading_rad.to_degrees() + 90.025_710_349).abs() < 1e-6);
}

#[test]
fn the_exact_antipode_is_ambiguous_not_coincident() {
    for legs in [LegKind::GreatCircle, LegKind::Rhumb] {
        let r = route(wp(30.0, 20.0, 100.0), wp(-30.0, -160.0, 100.0), legs);
        let e = compile(&r, E, 0.01).unwrap_err();
        let msg = e.to_string();
        match e {
            RouteError::Ambiguous {
                from,
                waypoint,
                margin_m,
                suggest_deg,
                ..
            } => {
                assert_eq!((from, waypoint), (1, 2), "{msg}");
                assert!(margin_m.abs() < 1e-6, "{msg}");
                // the suggested waypoint breaks the tie: both new legs compile
                let mid = wp(suggest_deg[0], suggest_deg[1], 100.0);
                let r2 = Route {
                    waypoints: vec![r.waypoints[0], mid, r.waypoints[1]],
                    legs,
                    limits: RouteLimits::default(),
                };
                let c = compile(&r2, E, 0.01).unwrap();
                assert!(c.report[2].miss_m < 0.5 * 100.0 * 0.01 + 1e-3, "{legs:?}");
            }
            other => panic!("{legs:?}: {other:?}"),
        }
        assert!(
            msg.contains("waypoint 1")
                && msg.contains("waypoint 2")
                && msg.contains("ambiguous")
                && msg.contains("intermediate waypoint"),
            "{msg}"
        );
    }
}

#[test]
fn the_cut_locus_is_ambiguous_and_its_neighbourhood_is_measured() {
    // on the equator the cut locus of (0, 0) spans |λ| ≥ (1 − f)·180° = 179.3965°: at
    // 179.5° two geodesics (north and south of the equator) have the same length
    let r = route(
        wp(0.0, 0.0, 100.0),
        wp(0.0, 179.5, 100.0),
        LegKind::GreatCircle,
    );
    assert!(matches!(
        compile(&r, E, 0.01),
        Err(RouteError::Ambiguous { margin_m, .. }) if margin_m < 1e-9
    ));
    // δ north of it the two lengths differ by δ (cos α₂ − cos α₁), α the azimuths there
    // (55.966°, 124.034°): 1.119 355 δ; refused below 1 mm, i.e. δ < 0.893 mm
    let d_lat = |metres: f64| (metres / E.radii(0.0).r_m_m).to_degrees();
    for (delta, refused) in [(0.5e-3, true), (2e-3, false)] {
        let r = route(
            wp(0.0, 0.0, 100.0),
            wp(d_lat(delta), 179.5, 100.0),
            LegKind::GreatCircle,
        );
        match compile(&r, E, 0.01) {
            Err(RouteError::Ambiguous { margin_m, .. }) => {
                assert!(refused, "δ = {delta}");
                assert!(
                    (margin_m - 1.119_355 * delta).abs() < 1e-6 * delta,
                    "{margin_m}"
                );
                assert!(margin_m < AMBIGUOUS_M);
            }
            // the leg is long, past the conjugate point's neighbourhood: what matters is
            // that it is not refused as ambiguous
            Ok(_) | Err(RouteError::Pole { .. }) => assert!(!refused, "δ = {delta}"),
            Err(e) => panic!("δ = {delta}: {e}"),
        }
    }
}

#[test]
fn coincident_waypoints_are_still_coincident() {
    let r = route(
        wp(10.0, 10.0, 50.0),
        wp(10.0, 10.000_001, 50.0),
        LegKind::GreatCircle,
    );
    assert!(matches!(
        compile(&r, E, 0.01),
        Err(RouteError::Coincident { waypoint: 2, .. })
    ));
}
