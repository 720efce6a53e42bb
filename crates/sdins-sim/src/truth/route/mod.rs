//! Routes through waypoints compiled into motion segments (docs/theory/routes.md,
//! docs/scenarios.md §"Routes").
//!
//! A route is a list of waypoints (latitude, longitude, height, speed) joined by legs
//! along geodesics ("great circles" of the ellipsoid: the heading obeys
//! `ψ̇ = v_E tan L/(R_N + h)`, the transport-rate term `ω_en,D = −v_E tan L/(R_N + h)` of
//! Groves 2nd ed. eq. 5.44 that a geodesic cancels, with `L̇`, `λ̇` of eq. 2.111) or rhumb
//! lines (constant heading). [`compile`] turns it into [`Motion`] segments:
//!
//! * on each leg, right after the turn at its start: a smooth speed change at the
//!   acceleration limit, then a smooth climb (ramp in, constant rate at the climb-rate
//!   limit, ramp out; the ramps at the acceleration limit), then cruise;
//! * at each interior waypoint a fly-by turn: turn-rate ramp in, constant rate at the
//!   limit, ramp out ([`crate::truth::vehicle::coordinated_turn`] timing), the ramps running
//!   between the geodesic heading rates of the legs, so ψ̇ is continuous;
//! * every leg piece is a [`Motion::Geodesic`]: its heading is a Chebyshev interpolant
//!   of the geodesic ODE solved along the leg (RK4, converged), so the truth is exact for
//!   that motion and holds the geodesic to the interpolant's accuracy.
//!
//! Each leg is shot (Newton on its start heading and cruise time) from the actual end of
//! the previous turn to the entry point of the next turn on the ideal waypoint-to-waypoint
//! leg; the turn angle is iterated so that the turn ends on the shot heading. Cruise
//! durations are whole IMU samples, so a leg ends within `V·dt/2` along-track of its
//! target ([`WaypointReport::miss_m`] at the last waypoint).

use crate::cancel::{CancelToken, Cancelled};
use crate::truth::trajectory::{Motion, Segment, GEO_CHEB_N};
use sdins_core::earth::EarthModel;
use sdins_core::math::Vec3;
use std::f64::consts::PI;

mod geodesic;
mod legs;
pub use geodesic::AMBIGUOUS_M;
use geodesic::*;
use legs::*;

const G: f64 = 9.806_65;
/// Longest cruise piece with one heading interpolant \[s\].
const MAX_PIECE_S: f64 = 600.0;
/// Farthest latitude a leg may reach \[rad\] (89.5°: the NED mechanization is singular at
/// the poles).
const MAX_LAT_RAD: f64 = 89.5 * PI / 180.0;

/// A waypoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// speed when passing the waypoint \[m/s\] (reached on the leg before it)
    pub speed_mps: f64,
    /// time at rest at the waypoint \[s\] (first waypoint: before departure; last: after
    /// arrival; zero elsewhere)
    pub hold_s: f64,
}

/// How legs join waypoints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LegKind {
    /// geodesic of the ellipsoid (the great circle of a sphere)
    #[default]
    GreatCircle,
    /// rhumb line (loxodrome): constant heading
    Rhumb,
}

/// The turn limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TurnLimit {
    /// turn rate \[rad/s\]
    Rate(f64),
    /// bank angle μ \[rad\]: turn rate `g tan μ / V`
    Bank(f64),
}

/// The limits a route is flown at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RouteLimits {
    /// turn limit (default bank 25°)
    pub turn: TurnLimit,
    /// roll-rate limit of the turn ramps \[rad/s\] (default 10°/s)
    pub roll_rate_rps: f64,
    /// climb-rate limit \[m/s\] (default 5 m/s)
    pub climb_rate_mps: f64,
    /// acceleration limit along track and vertically \[m/s²\] (default 1 m/s²)
    pub accel_mps2: f64,
}

impl Default for RouteLimits {
    fn default() -> Self {
        Self {
            turn: TurnLimit::Bank(25.0f64.to_radians()),
            roll_rate_rps: 10.0f64.to_radians(),
            climb_rate_mps: 5.0,
            accel_mps2: 1.0,
        }
    }
}

/// A route.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    /// the waypoints (at least two)
    pub waypoints: Vec<Waypoint>,
    /// leg kind
    pub legs: LegKind,
    /// limits
    pub limits: RouteLimits,
}

/// What the compiler reports for one waypoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaypointReport {
    /// arrival time \[s\]: closest approach (interior), departure (first), end of the leg
    /// (last)
    pub arrival_s: f64,
    /// distance from the waypoint to the flown path \[m\] (fly-by turns cut the corner;
    /// last waypoint: the arrival miss)
    pub miss_m: f64,
    /// heading change of the turn at the waypoint \[rad\]
    pub turn_rad: f64,
    /// distance before the waypoint where the turn starts \[m\]
    pub lead_m: f64,
}

/// The compiled route: motion segments and the per-waypoint report.
#[derive(Clone, Debug, PartialEq)]
pub struct CompiledRoute {
    /// motion segments `(motion, duration_s)`, every duration a whole number of samples
    pub motions: Vec<(Motion, f64)>,
    /// 0-based waypoint whose leg or turn each motion belongs to
    pub motion_waypoint: Vec<usize>,
    /// start heading \[rad\]
    pub start_heading_rad: f64,
    /// start speed \[m/s\]
    pub start_speed_mps: f64,
    /// per waypoint
    pub report: Vec<WaypointReport>,
}

/// Why a route cannot be flown. `waypoint` is 1-based (the `[[waypoint]]` number).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RouteError {
    /// Fewer than two waypoints.
    #[error("a route needs at least two waypoints (got {count})")]
    TooFew {
        /// waypoints given
        count: usize,
    },
    /// A value is not finite or out of range.
    #[error("waypoint {waypoint}: {what}")]
    Value {
        /// 1-based waypoint
        waypoint: usize,
        /// what is wrong
        what: String,
    },
    /// Two consecutive waypoints coincide.
    #[error("waypoint {waypoint} coincides with the previous waypoint (leg of {distance_m:.3} m)")]
    Coincident {
        /// 1-based waypoint
        waypoint: usize,
        /// leg length \[m\]
        distance_m: f64,
    },
    /// The waypoint lies on or next to the cut locus of the previous one (nearly
    /// antipodal): two geodesics (or, for rhumb legs, the rhumb lines east and west)
    /// join them with lengths within [`AMBIGUOUS_M`], so the leg is not determined.
    #[error("the leg from waypoint {from} to waypoint {waypoint} is ambiguous: waypoint {waypoint} is (nearly) antipodal to waypoint {from}, and two {} of {:.3} km join them whose lengths differ by {margin_m:.3e} m (less than 1 mm); add an intermediate waypoint to choose the way, e.g. lat_deg = {:.4}, lon_deg = {:.4}", kind_ways(.kind), .length_m / 1e3, .suggest_deg[0], .suggest_deg[1])]
    Ambiguous {
        /// 1-based start waypoint of the leg
        from: usize,
        /// 1-based end waypoint of the leg
        waypoint: usize,
        /// leg kind
        kind: LegKind,
        /// length of the shortest way \[m\]
        length_m: f64,
        /// how much longer the other way is \[m\]
        margin_m: f64,
        /// a waypoint between them `[lat, lon]` \[deg\] that resolves it
        suggest_deg: [f64; 2],
    },
    /// The leg to the waypoint passes too close to a pole.
    #[error("the leg to waypoint {waypoint} reaches latitude {lat_deg:.3} deg: legs must stay within ±89.5 deg (the NED mechanization is singular at the poles)")]
    Pole {
        /// 1-based waypoint
        waypoint: usize,
        /// latitude reached \[deg\]
        lat_deg: f64,
    },
    /// The turn, speed change and climb do not fit their leg.
    #[error("waypoint {waypoint}: the leg before it is {have_m:.1} m long but needs {need_m:.1} m ({what}); move the waypoints apart or raise the limits")]
    TooShort {
        /// 1-based waypoint
        waypoint: usize,
        /// what needs the room
        what: String,
        /// length needed \[m\]
        need_m: f64,
        /// length available \[m\]
        have_m: f64,
    },
    /// The turn at the waypoint cannot be flown (a reversal, or a limit rejected).
    #[error("waypoint {waypoint}: turn of {turn_deg:.2} deg cannot be flown: {why}")]
    Turn {
        /// 1-based waypoint
        waypoint: usize,
        /// heading change \[deg\]
        turn_deg: f64,
        /// why
        why: String,
    },
    /// The leg could not be solved (shooting did not converge).
    #[error("the leg to waypoint {waypoint} could not be solved: {why}")]
    Solve {
        /// 1-based waypoint
        waypoint: usize,
        /// why
        why: String,
    },
    /// The earth model has no ellipsoid (flat earth).
    #[error("routes need an ellipsoidal earth model (nav.earth = \"wgs84\" or \"psins\")")]
    FlatEarth,
    /// More waypoints than [`MAX_WAYPOINTS`].
    #[error("the route has {count} waypoints, more than the limit of {MAX_WAYPOINTS}: split it into several scenarios")]
    TooMany {
        /// waypoints given
        count: usize,
    },
    /// Stopped through the cancellation token.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// Most waypoints in one route (docs/scenarios.md §"Routes"): compilation is linear in
/// their number (bench/scale.sh), about 10 ms each.
pub const MAX_WAYPOINTS: usize = 100_000;

fn kind_ways(k: &LegKind) -> &'static str {
    match k {
        LegKind::GreatCircle => "geodesics",
        LegKind::Rhumb => "rhumb lines (east and west)",
    }
}

struct Ctx<'a> {
    earth: EarthModel,
    dt: f64,
    legs: LegKind,
    cancel: &'a CancelToken,
}

/// Compile a route for IMU interval `dt_s` on `earth` ([`compile_with`] without a
/// cancellation token).
pub fn compile(route: &Route, earth: EarthModel, dt_s: f64) -> Result<CompiledRoute, RouteError> {
    compile_with(route, earth, dt_s, &CancelToken::new())
}

/// Compile a route for IMU interval `dt_s` on `earth`, polling `cancel` at every leg and
/// every shooting iteration ([`RouteError::Cancelled`] once it is set). Linear in the
/// number of waypoints (at most [`MAX_WAYPOINTS`]).
pub fn compile_with(
    route: &Route,
    earth: EarthModel,
    dt_s: f64,
    cancel: &CancelToken,
) -> Result<CompiledRoute, RouteError> {
    let wps = &route.waypoints;
    let n = wps.len();
    if n < 2 {
        return Err(RouteError::TooFew { count: n });
    }
    if n > MAX_WAYPOINTS {
        return Err(RouteError::TooMany { count: n });
    }
    if !earth.transport || earth.a_m <= 0.0 {
        return Err(RouteError::FlatEarth);
    }
    let lim = &route.limits;
    for (i, w) in wps.iter().enumerate() {
        let bad = |what: String| {
            Err(RouteError::Value {
                waypoint: i + 1,
                what,
            })
        };
        for (name, v) in [
            ("lat_deg", w.lat_rad),
            ("lon_deg", w.lon_rad),
            ("h_m", w.h_m),
            ("speed_mps", w.speed_mps),
            ("hold_s", w.hold_s),
        ] {
            if !v.is_finite() {
                return bad(format!("{name} must be a finite number"));
            }
        }
        if w.lat_rad.abs() > MAX_LAT_RAD {
            return Err(RouteError::Pole {
                waypoint: i + 1,
                lat_deg: w.lat_rad.to_degrees(),
            });
        }
        if w.speed_mps <= 0.0 {
            return bad(format!("speed_mps {} must be > 0", w.speed_mps));
        }
        if w.hold_s < 0.0 || (w.hold_s > 0.0 && i != 0 && i != n - 1) {
            return bad("hold_s (time at rest) must be ≥ 0 and is accepted on the first and last waypoints only".into());
        }
    }
    for (what, v) in [
        ("roll-rate limit", lim.roll_rate_rps),
        ("climb-rate limit", lim.climb_rate_mps),
        ("acceleration limit", lim.accel_mps2),
        ("sample period", dt_s),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(RouteError::Value {
                waypoint: 1,
                what: format!("{what} must be positive and finite (got {v})"),
            });
        }
    }
    let ctx = Ctx {
        earth,
        dt: dt_s,
        legs: route.legs,
        cancel,
    };
    // ideal legs
    let mut ideal = Vec::with_capacity(n - 1);
    for k in 0..n - 1 {
        cancel.check()?;
        let l = ctx.ideal_leg(&wps[k], &wps[k + 1], k + 2)?;
        if l.3 > MAX_LAT_RAD {
            return Err(RouteError::Pole {
                waypoint: k + 2,
                lat_deg: l.3.to_degrees(),
            });
        }
        ideal.push(l);
    }
    // turn designs at interior waypoints: timing, angle, leads
    let mut timing = vec![(0.0, 0.0); n];
    let mut dpsi0 = vec![0.0; n];
    let mut lead_in = vec![0.0; n];
    let mut lead_out = vec![0.0; n];
    for j in 1..n - 1 {
        cancel.check()?;
        let d = wrap(ideal[j].0 - ideal[j - 1].1);
        dpsi0[j] = d;
        if d.abs() < 1e-9 {
            continue;
        }
        if d.abs() > 170f64.to_radians() {
            return Err(RouteError::Turn {
                waypoint: j + 1,
                turn_deg: d.to_degrees(),
                why: "turns above 170 deg (reversals) are not supported".into(),
            });
        }
        let v = wps[j].speed_mps;
        // designed at (1 − 1e-4) of the limit: the angle iteration and the geodesic rates
        // at the ramp ends move the hold rate by far less
        let bank = match lim.turn {
            TurnLimit::Bank(b) => (b.tan() * (1.0 - 1e-4)).atan(),
            TurnLimit::Rate(r) => (r * (1.0 - 1e-4) * v / G).atan(),
        };
        let parts = crate::truth::vehicle::coordinated_turn(v, d, bank, lim.roll_rate_rps, dt_s)
            .map_err(|e| RouteError::Turn {
                waypoint: j + 1,
                turn_deg: d.to_degrees(),
                why: e.to_string(),
            })?;
        let t_r = parts[0].1;
        let t_h = if parts.len() == 3 { parts[1].1 } else { 0.0 };
        timing[j] = (t_r, t_h);
        let (x, y) = turn_displacement(&turn_motions(timing[j], d, 0.0, 0.0), v);
        let d_out = y / d.sin();
        lead_out[j] = d_out;
        lead_in[j] = x - d_out * d.cos();
    }
    // room on each leg
    let stop_last = wps[n - 1].hold_s > 0.0;
    let start_speed = if wps[0].hold_s > 0.0 {
        0.0
    } else {
        wps[0].speed_mps
    };
    let mut pieces = Vec::with_capacity(n - 1);
    for k in 0..n - 1 {
        let v0 = if k == 0 {
            start_speed
        } else {
            wps[k].speed_mps
        };
        let pc = leg_pieces(
            &ctx,
            lim,
            v0,
            wps[k + 1].speed_mps,
            wps[k + 1].h_m - wps[k].h_m,
            stop_last && k == n - 2,
        );
        let need = pc.2 + lead_out[k] + lead_in[k + 1];
        if need > ideal[k].2 {
            return Err(RouteError::TooShort {
                waypoint: k + 2,
                what: format!(
                    "turn leads {:.1} m + {:.1} m, speed change and climb {:.1} m",
                    lead_out[k],
                    lead_in[k + 1],
                    pc.2
                ),
                need_m: need,
                have_m: ideal[k].2,
            });
        }
        pieces.push(pc);
    }
    // fly
    let mut motions: Vec<(Motion, f64)> = Vec::new();
    let mut motion_wp = Vec::new();
    let mut report = vec![
        WaypointReport {
            arrival_s: 0.0,
            miss_m: 0.0,
            turn_rad: 0.0,
            lead_m: 0.0
        };
        n
    ];
    let mut t = 0.0;
    if wps[0].hold_s > 0.0 {
        let d = ctx.round_dt(wps[0].hold_s);
        motions.push((Motion::Static, d));
        motion_wp.push(0);
        t += d;
    }
    report[0].arrival_s = t;
    let w0 = &wps[0];
    let mut p = P {
        lat: w0.lat_rad,
        lon: w0.lon_rad,
        h: w0.h_m,
        psi: ideal[0].0,
    };
    let mut start_heading = p.psi;
    let mut rate_in = 0.0; // heading rate at the end of the previous leg
    for k in 0..n - 1 {
        cancel.check()?;
        let (pre, post, _) = &pieces[k];
        let v0 = if k == 0 {
            start_speed
        } else {
            wps[k].speed_mps
        };
        let v1 = wps[k + 1].speed_mps;
        let wn = &wps[k + 1];
        // the target: entry point of the next turn on the ideal leg, or the last waypoint
        let pw = P {
            lat: wn.lat_rad,
            lon: wn.lon_rad,
            h: wn.h_m,
            psi: wrap(ideal[k].1 + PI),
        };
        let target = if k + 1 == n - 1 || lead_in[k + 1] == 0.0 {
            pw
        } else {
            ctx.arc(pw, lead_in[k + 1]).0
        };
        let pre_len: f64 = pieces[k].2;
        let guess_tc = ((ideal[k].2 - lead_out[k] - lead_in[k + 1] - pre_len) / v1).max(0.0);
        // turn at waypoint k (interior): iterate the angle on the shot heading
        let (leg, psi0, turn, p_exit) = if k == 0 {
            let (psi0, leg) = ctx.shoot((pre, post), (v0, v1), p, &target, guess_tc, k + 2)?;
            start_heading = psi0;
            (leg, psi0, Vec::new(), P { psi: psi0, ..p })
        } else if timing[k].0 == 0.0 {
            let (psi0, leg) = ctx.shoot((pre, post), (v0, v1), p, &target, guess_tc, k + 2)?;
            if (wrap(psi0 - p.psi)).abs() > 1e-6 {
                return Err(RouteError::Turn {
                    waypoint: k + 1,
                    turn_deg: wrap(psi0 - p.psi).to_degrees(),
                    why: "a straight-through waypoint needs a heading change after all".into(),
                });
            }
            (leg, p.psi, Vec::new(), p)
        } else {
            let v = wps[k].speed_mps;
            let mut dpsi = dpsi0[k];
            let mut b = ctx.geo_rate(
                &P {
                    psi: p.psi + dpsi,
                    ..p
                },
                v,
            );
            let mut best = None;
            for _ in 0..8 {
                let tm = turn_motions(timing[k], dpsi, rate_in, b);
                let mut q = p;
                let mut tt = 0.0;
                let mut psi_h = p.psi;
                for &(m, d) in &tm {
                    let seg = Segment::with_start(m, tt, d, (v, psi_h, 0.0));
                    q = ctx.fly(&seg, q, (tt, tt + d), 0.01, false, |_, _| {});
                    psi_h = seg.end().1;
                    tt += d;
                }
                q.psi = psi_h;
                let (psi0, leg) = ctx.shoot((pre, post), (v, v1), q, &target, guess_tc, k + 2)?;
                let err = wrap(psi0 - q.psi);
                dpsi += err;
                b = ctx.geo_rate(&P { psi: psi0, ..q }, v);
                best = Some((leg, psi0, tm, q));
                if err.abs() < 1e-13 {
                    break;
                }
            }
            match best {
                Some(b) => b,
                None => {
                    return Err(RouteError::Solve {
                        waypoint: k + 1,
                        why: "turn iteration".into(),
                    })
                }
            }
        };
        // the turn (exact heading chain: integrate with the trajectory's closed forms)
        if !turn.is_empty() {
            let wk = &wps[k];
            let pk = P {
                lat: wk.lat_rad,
                lon: wk.lon_rad,
                h: wk.h_m,
                psi: 0.0,
            };
            let xw = ctx.ecef(&pk);
            let v = wk.speed_mps;
            let mut best = (f64::INFINITY, t);
            let mut q = p;
            let mut tt = t;
            let mut psi_h = p.psi;
            let mut prev: Vec<(f64, f64)> = Vec::new();
            for &(m, d) in &turn {
                let seg = Segment::with_start(m, tt, d, (v, psi_h, 0.0));
                q = ctx.fly(&seg, q, (tt, tt + d), 0.005, false, |ts, qq| {
                    let dist = (ctx.ecef(qq) - xw).norm();
                    prev.push((ts, dist));
                    if dist < best.0 {
                        best = (dist, ts);
                    }
                });
                psi_h = seg.end().1;
                tt += d;
                motions.push((m, d));
                motion_wp.push(k);
            }
            // parabolic refinement of the closest approach
            if let Some(i) = prev.iter().position(|x| x.1 == best.0) {
                if i > 0 && i + 1 < prev.len() {
                    let (y0, y1, y2) = (prev[i - 1].1, prev[i].1, prev[i + 1].1);
                    let h = prev[i + 1].0 - prev[i].0;
                    let den = y0 - 2.0 * y1 + y2;
                    if den > 0.0 {
                        let u = 0.5 * (y0 - y2) / den;
                        best = (y1 - 0.25 * (y0 - y2) * u, prev[i].0 + u * h);
                    }
                }
            }
            report[k].arrival_s = best.1;
            report[k].miss_m = best.0;
            report[k].turn_rad = wrap(psi0 - p.psi);
            report[k].lead_m = lead_in[k];
            t = tt;
            p = P { psi: psi_h, ..q };
            let _ = p_exit;
        }
        // the leg
        let (lm, q) = ctx.leg_motions(&leg, P { psi: psi0, ..p });
        for (m, d) in lm {
            motions.push((m, d));
            motion_wp.push(k);
            t += d;
        }
        rate_in = ctx.geo_rate(&q, v1 * if stop_last && k == n - 2 { 0.0 } else { 1.0 });
        p = q;
    }
    // arrival at the last waypoint
    let wl = &wps[n - 1];
    let pl = P {
        lat: wl.lat_rad,
        lon: wl.lon_rad,
        h: wl.h_m,
        psi: 0.0,
    };
    report[n - 1].arrival_s = t;
    report[n - 1].miss_m = (ctx.ecef(&p) - ctx.ecef(&pl)).norm();
    if stop_last {
        let d = ctx.round_dt(wl.hold_s);
        motions.push((Motion::Static, d));
        motion_wp.push(n - 1);
    }
    Ok(CompiledRoute {
        motions,
        motion_waypoint: motion_wp,
        start_heading_rad: start_heading,
        start_speed_mps: start_speed,
        report,
    })
}

impl CompiledRoute {
    /// One line per waypoint: arrival time, distance from the waypoint to the flown path,
    /// turn angle and lead distance (what `sdins truth` and `sdins run` print).
    pub fn summary(&self) -> Vec<String> {
        let n = self.report.len();
        self.report
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let what = if i == 0 {
                    "start"
                } else if i + 1 == n {
                    "arrival miss"
                } else {
                    "distance to path"
                };
                format!(
                    "route: waypoint {} at t = {:.3} s: {what} {:.4} m, turn {:.3} deg, lead {:.2} m",
                    i + 1,
                    r.arrival_s,
                    r.miss_m,
                    r.turn_rad.to_degrees(),
                    r.lead_m
                )
            })
            .collect()
    }
}
