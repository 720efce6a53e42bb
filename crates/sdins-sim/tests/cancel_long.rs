//! The long set-up steps stop when their cancellation token is set from another thread
//! (route compilation, the envelope check, gnss-ins-sim command lists), and their size
//! limits are stated errors (issue "Nothing silent, round two", class 7). Linearity is
//! shown by bench/scale.sh, not by a timed test: the times printed here are for the log.
#![allow(clippy::unwrap_used)]
use sdins_core::earth::EarthModel;
use sdins_core::math::Euler;
use sdins_sim::cancel::CancelToken;
use sdins_sim::io::gnss_ins_sim::{parse_motion_def_with, GisError};
use sdins_sim::truth::body_motion::MAX_COMMANDS;
use sdins_sim::truth::envelope::{check_trajectory_with, Envelope, EnvelopeError, StartPosition};
use sdins_sim::truth::route::{
    compile_with, LegKind, Route, RouteError, RouteLimits, Waypoint, MAX_WAYPOINTS,
};
use sdins_sim::truth::trajectory::{Motion, Trajectory};
use std::time::{Duration, Instant};

/// A token that another thread sets after `ms` milliseconds.
fn cancel_after(ms: u64) -> CancelToken {
    let t = CancelToken::new();
    let c = t.clone();
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(ms));
        c.cancel();
    });
    t
}

/// `n` waypoints 4 km apart on a 51 km circle around 45°N 10°E (4.5° turns).
fn circle_route(n: usize) -> Route {
    let waypoints = (0..n)
        .map(|k| {
            let th = 2.0 * std::f64::consts::PI * (k % 80) as f64 / 80.0;
            Waypoint {
                lat_rad: (45.0 + 0.459 * th.cos()).to_radians(),
                lon_rad: (10.0 + 0.649 * th.sin()).to_radians(),
                h_m: 0.0,
                speed_mps: 100.0,
                hold_s: 0.0,
            }
        })
        .collect();
    Route {
        waypoints,
        legs: LegKind::GreatCircle,
        limits: RouteLimits::default(),
    }
}

#[test]
fn route_compilation_stops_when_cancelled_from_another_thread() {
    // 20 000 waypoints: minutes of work without the token (about 10 ms each)
    let route = circle_route(20_000);
    let token = cancel_after(300);
    let t0 = Instant::now();
    let r = compile_with(&route, EarthModel::WGS84, 1.0, &token);
    let dt = t0.elapsed();
    eprintln!("route: cancelled after {dt:?}");
    assert!(matches!(r, Err(RouteError::Cancelled(_))), "{:?}", r.err());
    // far below the full compilation (one poll per leg and per shooting iteration)
    assert!(dt < Duration::from_secs(30), "{dt:?}");
}

#[test]
fn route_size_limit_is_stated() {
    let route = circle_route(MAX_WAYPOINTS + 1);
    let e = compile_with(&route, EarthModel::WGS84, 1.0, &CancelToken::new()).unwrap_err();
    assert!(matches!(e, RouteError::TooMany { count } if count == MAX_WAYPOINTS + 1));
    assert!(e.to_string().contains("limit of 100000"), "{e}");
}

#[test]
fn envelope_check_stops_when_cancelled_from_another_thread() {
    // a million segments and 4 million grid points: about a second of evaluations
    let motions: Vec<(Motion, f64)> = (0..1_000_000)
        .map(|k| {
            let m = if k % 2 == 0 {
                Motion::TurnRate { rate_rps: 0.01 }
            } else {
                Motion::TurnRate { rate_rps: -0.01 }
            };
            (m, 1.0)
        })
        .collect();
    let traj = Trajectory::new(0.1, 0.0, Euler::new(0.0, 0.0, 0.0), &motions, vec![]);
    let start = StartPosition {
        lat_rad: 0.5,
        h_m: 0.0,
    };
    // set before the call: the first poll sees it
    let set = CancelToken::new();
    set.cancel();
    assert!(matches!(
        check_trajectory_with(&traj, start, 0.01, &Envelope::DEFAULT, &set),
        Err(EnvelopeError::Cancelled(_))
    ));
    // set from another thread meanwhile
    let token = cancel_after(30);
    let t0 = Instant::now();
    let r = check_trajectory_with(&traj, start, 0.01, &Envelope::DEFAULT, &token);
    eprintln!("envelope: cancelled after {:?}", t0.elapsed());
    assert!(matches!(r, Err(EnvelopeError::Cancelled(_))), "{r:?}");
    // and without a token the same check passes
    let ok = check_trajectory_with(&traj, start, 0.01, &Envelope::DEFAULT, &CancelToken::new());
    assert!(ok.is_ok(), "{ok:?}");
}

fn motion_file(commands: usize) -> String {
    let mut s = String::from(
        "ini lat (deg),a,b,c,d,e,f,g,h\n32,120,0,0,0,0,0,0,0\ncommand type,a,b,c,d,e,f,g,h\n",
    );
    s.reserve(commands * 20);
    for k in 0..commands {
        s.push_str(if k % 2 == 0 {
            "1,0.5,0,0,0,0,0,1,1\n"
        } else {
            "1,-0.5,0,0,0,0,0,1,1\n"
        });
    }
    s
}

#[test]
fn command_lists_stop_when_cancelled_and_have_a_stated_limit() {
    let text = motion_file(MAX_COMMANDS);
    let set = CancelToken::new();
    set.cancel();
    assert!(matches!(
        parse_motion_def_with(&text, "m.csv", &set),
        Err(GisError::Cancelled(_))
    ));
    let token = cancel_after(20);
    let t0 = Instant::now();
    let r = parse_motion_def_with(&text, "m.csv", &token);
    eprintln!("commands: cancelled after {:?}", t0.elapsed());
    assert!(matches!(r, Err(GisError::Cancelled(_))), "{:?}", r.err());
    // exactly the limit is read; one more is refused naming its line and the limit
    let m = parse_motion_def_with(&text, "m.csv", &CancelToken::new()).unwrap();
    assert_eq!(m.commands.len(), MAX_COMMANDS);
    let text = motion_file(MAX_COMMANDS + 1);
    match parse_motion_def_with(&text, "m.csv", &CancelToken::new()) {
        Err(GisError::Invalid { line, message, .. }) => {
            assert_eq!(line, MAX_COMMANDS + 4);
            assert!(message.contains("1000000 commands"), "{message}");
        }
        other => panic!("{:?}", other.map(|m| m.commands.len())),
    }
}
