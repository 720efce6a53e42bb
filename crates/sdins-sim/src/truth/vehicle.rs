//! Vehicle kinematics: the attitude a vehicle takes along the nominal velocity of a
//! trajectory (docs/scenarios.md, "Vehicles").
//!
//! * [`Vehicle::Free`]: roll and pitch stay at their start values, yaw = heading (the
//!   paper scenarios; the attitude of [`crate::truth::trajectory`] unchanged).
//! * [`Vehicle::Car`]: no bank; pitch follows the road grade, `θ = atan2(−v_D, s)`
//!   (`s` the horizontal speed), yaw = heading, so the velocity lies along body x and the
//!   lateral and vertical vehicle-frame velocities vanish (the non-holonomic constraint
//!   holds exactly).
//! * [`Vehicle::Aircraft`]: `C_b^n = C_w^n(χ, γ, μ)·R_y(α)` (Groves 2nd ed. §2.2 Euler
//!   form, wind axes as in Stevens & Lewis): track `χ` = heading, flight-path angle
//!   `γ = atan2(−v_D, s)`, constant angle of attack `α`, and the bank `μ` solved so that
//!   the body-y specific force vanishes exactly: with `f^n = v̇ + (2ω_ie + ω_en)×v − g`
//!   (Groves eq. 5.53 rearranged) and the axes `y₁ = (−sin χ, cos χ, 0)`,
//!   `z₁ = (sin γ cos χ, sin γ sin χ, cos γ)` of `Rz(χ)Ry(γ)`, `f_y^b = cos μ (y₁·f) +
//!   sin μ (z₁·f) = 0` gives `μ = atan2(y₁·f, −z₁·f)` (lift up; `μ ≈ atan(V χ̇/g)` only to
//!   first order). The earth terms are evaluated at a position track (below), so gravity's
//!   variation, Coriolis and transport rate are included. `ω_nb^b = R_y(α)ᵀ ω_nw^w`
//!   with the Euler-rate form `ω_nw^w = [μ̇ − χ̇ sin γ, γ̇ cos μ + χ̇ cos γ sin μ,
//!   −γ̇ sin μ + χ̇ cos γ cos μ]` and `μ̇ = (a ḃ − ȧ b)/(a² + b²)`, `a = y₁·f`, `b = z₁·f`.
//!
//! Smoothness (aircraft): the attitude is as smooth as `f^n`. Every segment joint must
//! continue `v̇` and `v̈` ([`crate::truth::trajectory::Trajectory::with_vehicle`] checks it and names the segment),
//! so `μ`, `γ` are C¹ and the attitude is C¹ everywhere (ω continuous); inside segments
//! it is analytic except at the nodes of the position track, where it is C¹ with a
//! jump in `ω̇` of order `∂μ/∂L·ΔL̈ < 1e-20 rad/s²`. The smooth profiles
//! (`accelerate`/`climb` with `profile = "smooth"`, the `coordinated` turn) keep `v̇`,
//! `v̈` continuous; linear climbs, linear accelerations, constant-rate turns entered
//! without a ramp and S-turns do not and are rejected for aircraft.
//!
//! The position track: latitude and height along the nominal velocity, integrated by RK4
//! (two steps per node interval, node spacing ≤ 50 ms, nodes on the segment boundaries)
//! and interpolated by cubic Hermite polynomials (C¹, the derivative of the interpolant
//! used for `μ̇`, so that ω is the exact derivative of the attitude). Its distance from the
//! truth generator's position is ≲ 1e-7 m (RK4 and Hermite remainders), which moves `f_y^b`
//! by ≲ 3e-6 s⁻² · 1e-7 m ≈ 3e-13 m/s² (∂g/∂h; ∂(Coriolis)/∂L is smaller).

use crate::truth::trajectory::{Nominal, Segment};
use sdins_core::earth::EarthModel;
use sdins_core::math::{c_b_n_from_sin_cos, Mat3, Vec3};

/// The vehicle whose attitude follows the motion.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[non_exhaustive]
pub enum Vehicle {
    /// roll and pitch constant, yaw = heading (default; the paper scenarios)
    #[default]
    Free,
    /// no bank, pitch = road grade, velocity along body x
    Car,
    /// coordinated flight: wind axes plus a constant angle of attack
    Aircraft {
        /// angle of attack α \[rad\] (body x above the velocity)
        angle_of_attack_rad: f64,
    },
}

impl Vehicle {
    /// Name as written in scenario files.
    pub fn name(&self) -> &'static str {
        match self {
            Vehicle::Free => "free",
            Vehicle::Car => "car",
            Vehicle::Aircraft { .. } => "aircraft",
        }
    }
}

/// Why a trajectory cannot be driven or flown by its vehicle.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum VehicleError {
    /// An aircraft segment joint steps the acceleration or its rate (the bank would jump).
    #[error(
        "segment {index} (1-based): the {quantity} jumps by {jump:.3e} at its start; an \
         aircraft's bank follows the specific force, so segment joints must continue the \
         acceleration and its rate (use profile = \"smooth\" accelerations and climbs and \
         profile = \"coordinated\" turns)"
    )]
    Joint {
        /// 1-based segment index
        index: usize,
        /// what jumps
        quantity: &'static str,
        /// size of the jump
        jump: f64,
    },
    /// The vehicle would move vertically at zero horizontal speed.
    #[error(
        "segment {index} (1-based): a {vehicle} cannot move vertically at zero horizontal \
         speed (v_D = {v_d_mps} m/s)"
    )]
    Vertical {
        /// 1-based segment index
        index: usize,
        /// vehicle name
        vehicle: &'static str,
        /// down velocity \[m/s\]
        v_d_mps: f64,
    },
}

/// Node spacing of the position track \[s\] (upper bound).
const TRACK_DT_S: f64 = 0.05;

/// Latitude and height along the nominal velocity, piecewise cubic Hermite.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Track {
    earth: EarthModel,
    lat0_rad: f64,
    /// per segment: first node index, node spacing, number of intervals
    seg: Vec<(usize, f64, usize)>,
    /// per node: L, L̇, h, ḣ
    nodes: Vec<[f64; 4]>,
}

/// Nominal NED velocity and its first two derivatives from speed, heading and v_D.
pub(crate) fn velocity_derivs(n: &Nominal, (sh, ch): (f64, f64)) -> [Vec3; 3] {
    let (s, sd, sdd) = (n.speed, n.speed_dot, n.speed_ddot);
    let (w, wd) = (n.heading_dot, n.heading_ddot);
    let v = Vec3::new(s * ch, s * sh, n.v_d);
    let v_dot = Vec3::new(sd * ch - s * w * sh, sd * sh + s * w * ch, n.v_d_dot);
    let v_ddot = Vec3::new(
        sdd * ch - 2.0 * sd * w * sh - s * wd * sh - s * w * w * ch,
        sdd * sh + 2.0 * sd * w * ch + s * wd * ch - s * w * w * sh,
        n.v_d_ddot,
    );
    [v, v_dot, v_ddot]
}

impl Track {
    /// `(L̇, ḣ)` as the truth generator integrates them (the flat model moves over the
    /// ellipsoid at the start latitude).
    fn rates(&self, lat: f64, h: f64, v: &Vec3) -> (f64, f64) {
        let l = if self.earth.transport {
            lat
        } else {
            self.lat0_rad
        };
        let r = self.earth.radii(l);
        (v.x / (r.r_m_m + h), -v.z)
    }

    pub(crate) fn build(segments: &[Segment], earth: EarthModel, lat0_rad: f64, h0_m: f64) -> Self {
        let mut tr = Track {
            earth,
            lat0_rad,
            seg: Vec::with_capacity(segments.len()),
            nodes: Vec::new(),
        };
        let vel = |s: &Segment, t: f64| -> Vec3 {
            let n = s.eval(t);
            let (sh, ch) = n.heading.sin_cos();
            Vec3::new(n.speed * ch, n.speed * sh, n.v_d)
        };
        let (mut lat, mut h) = (lat0_rad, h0_m);
        for s in segments {
            let n = ((s.duration_s / TRACK_DT_S).ceil() as usize).max(1);
            let dt = s.duration_s / n as f64;
            tr.seg.push((tr.nodes.len(), dt, n));
            let node = |tr: &Track, lat: f64, h: f64, t: f64| -> [f64; 4] {
                let (ld, hd) = tr.rates(lat, h, &vel(s, t));
                [lat, ld, h, hd]
            };
            tr.nodes.push(node(&tr, lat, h, s.t0_s));
            for k in 0..n {
                // two RK4 steps per interval
                for j in 0..2 {
                    let hs = 0.5 * dt;
                    let t = s.t0_s + k as f64 * dt + j as f64 * hs;
                    let f = |t: f64, lat: f64, h: f64| tr.rates(lat, h, &vel(s, t));
                    let k1 = f(t, lat, h);
                    let k2 = f(t + 0.5 * hs, lat + 0.5 * hs * k1.0, h + 0.5 * hs * k1.1);
                    let k3 = f(t + 0.5 * hs, lat + 0.5 * hs * k2.0, h + 0.5 * hs * k2.1);
                    let k4 = f(t + hs, lat + hs * k3.0, h + hs * k3.1);
                    lat += hs / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
                    h += hs / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
                }
                tr.nodes
                    .push(node(&tr, lat, h, s.t0_s + (k + 1) as f64 * dt));
            }
        }
        tr
    }

    /// `(L, L̇, h, ḣ)` of the interpolant on segment `i` at time `t`.
    pub(crate) fn eval(&self, i: usize, seg: &Segment, t: f64) -> [f64; 4] {
        let (first, dt, n) = self.seg[i];
        let x = (t - seg.t0_s) / dt;
        let k = (x.floor().max(0.0) as usize).min(n - 1);
        let u = x - k as f64;
        let (p0, p1) = (&self.nodes[first + k], &self.nodes[first + k + 1]);
        let (u2, u3) = (u * u, u * u * u);
        let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
        let h10 = u3 - 2.0 * u2 + u;
        let h01 = -2.0 * u3 + 3.0 * u2;
        let h11 = u3 - u2;
        let d00 = (6.0 * u2 - 6.0 * u) / dt;
        let d10 = 3.0 * u2 - 4.0 * u + 1.0;
        let d11 = 3.0 * u2 - 2.0 * u;
        let herm = |a: usize| -> (f64, f64) {
            (
                h00 * p0[a] + h10 * dt * p0[a + 1] + h01 * p1[a] + h11 * dt * p1[a + 1],
                d00 * (p0[a] - p1[a]) + d10 * p0[a + 1] + d11 * p1[a + 1],
            )
        };
        let (l, ld) = herm(0);
        let (h, hd) = herm(2);
        [l, ld, h, hd]
    }

    /// `E = (2ω_ie + ω_en)×v − g^n` at `(L, h)`.
    fn earth_terms(&self, lat: f64, h: f64, v: &Vec3) -> Vec3 {
        let e = &self.earth;
        (2.0 * e.omega_ie_n(lat) + e.omega_en_n(lat, h, v)).cross(v) - e.gravity_n(lat, h)
    }

    /// The specific force `f^n = v̇ + E` and its time derivative along the track:
    /// `ḟ = v̈ + ∂E/∂L·L̇ + ∂E/∂h·ḣ + (2ω_ie + ω_en)×v̇ + ω_en(v̇)×v` (ω_en is linear in v;
    /// the position partials by central differences of 1e-4 rad and 100 m: the gravity
    /// model is at most quadratic in h, and the latitude remainder `E'''·δL²/6` times `L̇`
    /// is below 1e-14 m/s³).
    fn specific_force(&self, p: &[f64; 4], v: &[Vec3; 3]) -> (Vec3, Vec3) {
        let e = &self.earth;
        let [lat, ld, h, hd] = *p;
        let f = v[1] + self.earth_terms(lat, h, &v[0]);
        let (dl, dh) = (1e-4, 100.0);
        let e_l = (self.earth_terms(lat + dl, h, &v[0]) - self.earth_terms(lat - dl, h, &v[0]))
            / (2.0 * dl);
        let e_h = (self.earth_terms(lat, h + dh, &v[0]) - self.earth_terms(lat, h - dh, &v[0]))
            / (2.0 * dh);
        let omega = 2.0 * e.omega_ie_n(lat) + e.omega_en_n(lat, h, &v[0]);
        let f_dot = v[2]
            + e_l * ld
            + e_h * hd
            + omega.cross(&v[1])
            + e.omega_en_n(lat, h, &v[1]).cross(&v[0]);
        (f, f_dot)
    }
}

/// `(sin γ, cos γ, γ̇)` of the flight-path (road-grade) angle `γ = atan2(−v_D, s)`.
fn path_angle(n: &Nominal) -> (f64, f64, f64) {
    let (s, vd) = (n.speed, n.v_d);
    let q = s * s + vd * vd;
    if q == 0.0 {
        return (0.0, 1.0, 0.0);
    }
    let r = q.sqrt();
    (-vd / r, s / r, (-n.v_d_dot * s + vd * n.speed_dot) / q)
}

/// Car attitude and `ω_nb^b`: `C = Rz(ψ) Ry(θ)`, `ω = [−ψ̇ sin θ, θ̇, ψ̇ cos θ]`.
pub(crate) fn car_attitude(n: &Nominal, sc_heading: (f64, f64)) -> (Mat3, Vec3) {
    let (sg, cg, gd) = path_angle(n);
    let c = c_b_n_from_sin_cos((0.0, 1.0), (sg, cg), sc_heading);
    let w = n.heading_dot;
    (c, Vec3::new(-w * sg, gd, w * cg))
}

/// Aircraft attitude and `ω_nb^b` (module documentation).
pub(crate) fn aircraft_attitude(
    track: &Track,
    p: &[f64; 4],
    n: &Nominal,
    sc_heading: (f64, f64),
    sc_alpha: (f64, f64),
) -> (Mat3, Vec3) {
    let (sh, ch) = sc_heading;
    let v = velocity_derivs(n, sc_heading);
    let (f, f_dot) = track.specific_force(p, &v);
    let (sg, cg, gd) = path_angle(n);
    let chi_d = n.heading_dot;
    let x1 = Vec3::new(cg * ch, cg * sh, -sg);
    let y1 = Vec3::new(-sh, ch, 0.0);
    let z1 = Vec3::new(sg * ch, sg * sh, cg);
    let y1_dot = Vec3::new(-ch, -sh, 0.0) * chi_d;
    let z1_dot = x1 * gd + y1 * (chi_d * sg);
    let a = y1.dot(&f);
    let b = z1.dot(&f);
    let a_dot = y1_dot.dot(&f) + y1.dot(&f_dot);
    let b_dot = z1_dot.dot(&f) + z1.dot(&f_dot);
    let q = a * a + b * b;
    let r = q.sqrt();
    let (sm, cm) = (a / r, -b / r);
    let mu_dot = (a * b_dot - a_dot * b) / q;
    let c_w_n = c_b_n_from_sin_cos((sm, cm), (sg, cg), sc_heading);
    let w_w = Vec3::new(
        mu_dot - chi_d * sg,
        gd * cm + chi_d * cg * sm,
        -gd * sm + chi_d * cg * cm,
    );
    let (sa, ca) = sc_alpha;
    if sa == 0.0 {
        return (c_w_n, w_w);
    }
    // C_b^w = R_y(α): body x pitched up by α from the velocity
    let c_b_w = c_b_n_from_sin_cos((0.0, 1.0), (sa, ca), (0.0, 1.0));
    (c_w_n * c_b_w, c_b_w.transpose() * w_w)
}

/// Why a coordinated turn cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TurnError {
    /// A limit or the speed is not positive and finite.
    #[error("{what} must be positive and finite (got {value})")]
    NotPositive {
        /// which quantity
        what: &'static str,
        /// its value
        value: f64,
    },
    /// The bank limit is not below 90°.
    #[error("bank limit {bank_deg} deg must be below 90 deg")]
    Bank {
        /// the limit \[deg\]
        bank_deg: f64,
    },
}

/// A coordinated turn through `angle_rad` at speed `speed_mps` as motion segments
/// `(motion, duration_s)`: a turn-rate ramp `0 → r` ([`crate::truth::trajectory::Motion::TurnRamp`],
/// smooth step, duration `T_r`), a constant rate `r` for `T_h` (left out when zero) and the
/// ramp `r → 0`. With `r_max = g tan μ_max / V` and the roll-rate limit `p`, the ramp time
/// `T_r = 2 tan μ_max / p` keeps the first-order bank `atan(V ψ̇ / g)` within `μ_max` and its
/// rate `(V/g) ψ̈ /(1 + (Vψ̇/g)²) ≤ (V/g)·2r/T_r` within `p`; a turn too short to reach
/// `r_max` uses `r = √(A g p/(2V))`, `T_r = 2V r/(g p)`, no hold. The total duration is
/// rounded up to a whole number of samples `dt_s` by lengthening the hold and lowering `r`
/// to `A/(T_r + T_h)` (which keeps both limits). `g` is the nominal 9.806 65 m/s²: the exact
/// bank differs from the first-order one by the earth terms (≈1e-3 relative).
pub fn coordinated_turn(
    speed_mps: f64,
    angle_rad: f64,
    max_bank_rad: f64,
    max_roll_rate_rps: f64,
    dt_s: f64,
) -> Result<Vec<(crate::truth::trajectory::Motion, f64)>, TurnError> {
    use crate::truth::trajectory::Motion;
    const G: f64 = 9.806_65;
    for (what, value) in [
        ("speed", speed_mps),
        ("bank limit", max_bank_rad),
        ("roll-rate limit", max_roll_rate_rps),
        ("sample period", dt_s),
        ("turn angle magnitude", angle_rad.abs()),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(TurnError::NotPositive { what, value });
        }
    }
    if max_bank_rad >= 0.5 * std::f64::consts::PI {
        return Err(TurnError::Bank {
            bank_deg: max_bank_rad.to_degrees(),
        });
    }
    let a = angle_rad.abs();
    let r_max = G * max_bank_rad.tan() / speed_mps;
    let tr_full = 2.0 * max_bank_rad.tan() / max_roll_rate_rps;
    let (t_r, t_h) = if a < r_max * tr_full {
        let r = (a * G * max_roll_rate_rps / (2.0 * speed_mps)).sqrt();
        (2.0 * speed_mps * r / (G * max_roll_rate_rps), 0.0)
    } else {
        (tr_full, a / r_max - tr_full)
    };
    let total = ((2.0 * t_r + t_h) / dt_s - 1e-9).ceil() * dt_s;
    let t_h = (total - 2.0 * t_r).max(0.0);
    let r = angle_rad / (t_r + t_h);
    let mut m = vec![(
        Motion::TurnRamp {
            from_rps: 0.0,
            to_rps: r,
        },
        t_r,
    )];
    if t_h > 0.0 {
        m.push((Motion::TurnRate { rate_rps: r }, t_h));
    }
    m.push((
        Motion::TurnRamp {
            from_rps: r,
            to_rps: 0.0,
        },
        t_r,
    ));
    Ok(m)
}
