//! Analytic trajectories: piecewise motion segments plus attitude/linear overlays,
//! evaluated exactly (value and derivative) at any time (docs/theory/mechanizations.md
//! §"Truth generation").
//!
//! The nominal vehicle moves with horizontal speed `s` along heading `ψ` (= yaw) and
//! down velocity `v_D`: `v^n = [s cosψ, s sinψ, v_D]`. Roll and pitch stay at their start
//! values (flat turns, as in the papers' scenarios). Overlays add body coning, sculling
//! and vibration on top.

use crate::truth::body_motion::BodyMotion;
use crate::truth::random_vibration::RandomVibration;
use crate::truth::reference::ReferenceTrack;
use crate::truth::vehicle::{
    aircraft_attitude, car_attitude, velocity_derivs, Track, Vehicle, VehicleError,
};
use sdins_core::earth::EarthModel;
use sdins_core::math::{Euler, Mat3, Quat, Vec3};
use std::f64::consts::PI;
use std::sync::Arc;

mod overlay;
#[allow(unused_imports)]
use overlay::*;
pub use overlay::{Axis, Overlay, OverlayKind, OverlayPhases};

mod segment;
pub(crate) use segment::Nominal;
use segment::*;

/// Longest accepted segment \[s\] (keeps sample counts far from integer overflow).
pub const MAX_SEGMENT_S: f64 = 1.0e7;

/// A motion segment (one of the `[[segment]]` tables of a scenario).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// everything constant (speed must be zero)
    Static,
    /// constant velocity and attitude
    Cruise,
    /// constant along-track acceleration \[m/s²\]
    Accelerate {
        /// acceleration along the heading \[m/s²\]
        accel_mps2: f64,
    },
    /// level turn at a constant yaw rate \[rad/s\]
    TurnRate {
        /// yaw rate \[rad/s\] (positive = right turn)
        rate_rps: f64,
    },
    /// level turn through an angle with a smooth (raised-cosine) rate:
    /// `ψ = ψ0 + A(x − sin(2πx)/(2π))`, `ψ̇ = (A/T)(1 − cos 2πx)`, `x = τ/T`
    /// (docs/scenarios.md §"profile"; peak rate 2A/T at mid-turn)
    TurnSmooth {
        /// total heading change A \[rad\]
        angle_rad: f64,
    },
    /// S-turn: `ψ̇ = a sin(2πτ/T)`, `ψ = ψ0 + a(T/2π)(1 − cos(2πτ/T))` (docs/scenarios.md
    /// §"profile")
    STurn {
        /// peak yaw rate a \[rad/s\]
        amplitude_rps: f64,
    },
    /// linear change of the climb rate to `to_climb_rate_mps` (v_D = −climb rate)
    Climb {
        /// climb rate at the end of the segment \[m/s\], positive up
        to_climb_rate_mps: f64,
    },
    /// smooth speed change by `delta_speed_mps`: `s = s0 + Δ·S(x)` with the smooth step
    /// `S(x) = x − sin(2πx)/(2π)`, `x = τ/T`: `ṡ = (Δ/T)(1 − cos 2πx)` and `s̈` vanish at
    /// both ends (peak acceleration 2Δ/T at mid-segment)
    AccelerateSmooth {
        /// speed change Δ \[m/s\]
        delta_speed_mps: f64,
    },
    /// smooth change of the climb rate to `to_climb_rate_mps`: `v_D = v_D0 + Δ·S(x)`,
    /// `Δ = −to_climb_rate − v_D0`, with the smooth step `S` of
    /// [`Motion::AccelerateSmooth`]
    ClimbSmooth {
        /// climb rate at the end of the segment \[m/s\], positive up
        to_climb_rate_mps: f64,
    },
    /// turn-rate ramp from `from_rps` to `to_rps`: `ψ̇ = r0 + (r1 − r0)·S(x)`,
    /// `ψ = ψ0 + r0 τ + (r1 − r0) T (x²/2 + (cos 2πx − 1)/(4π²))`; ψ̈ and ψ⃛ vanish at both
    /// ends (the entry and exit of a coordinated turn)
    TurnRamp {
        /// yaw rate at the start \[rad/s\]
        from_rps: f64,
        /// yaw rate at the end \[rad/s\]
        to_rps: f64,
    },
    /// a route leg piece ([`crate::truth::route`]): heading from a Chebyshev interpolant of a
    /// converged solution of the geodesic heading equation `ψ̇ = v_E tan L/(R_N + h)`
    /// (docs/theory/routes.md), `ψ = ψ0 + p(x) − p(0)`, `p(x) = Σ c_k T_k(2x − 1)`,
    /// `x = τ/T`, value and derivatives from the same polynomial (all `c_k = 0`: constant
    /// heading, a rhumb line); with smooth speed and down-velocity changes
    /// `s = s0 + Δs·S(x)`, `v_D = v_D0 + Δv_D·S(x)` (the smooth step of
    /// [`Motion::AccelerateSmooth`])
    Geodesic {
        /// Chebyshev coefficients of the heading \[rad\]
        heading_cheb: [f64; GEO_CHEB_N],
        /// speed change Δs \[m/s\]
        delta_speed_mps: f64,
        /// down-velocity change Δv_D \[m/s\]
        delta_v_d_mps: f64,
    },
}

/// Number of Chebyshev coefficients of a [`Motion::Geodesic`] heading.
pub const GEO_CHEB_N: usize = 12;

/// `(p(x), p'(x), p''(x))` of `p(x) = Σ c_k T_k(u)`, `u = 2x − 1` (derivatives in `x`),
/// by the three-term recurrences of `T_k`, `T_k'`, `T_k''`.
pub(crate) fn cheb_eval(c: &[f64; GEO_CHEB_N], x: f64) -> (f64, f64, f64) {
    let u = 2.0 * x - 1.0;
    // T_k, T_k' = dT/du, T_k'' : T_{k+1} = 2u T_k − T_{k−1}, T' and T'' by differentiation
    let (mut t0, mut t1) = (1.0, u);
    let (mut d0, mut d1) = (0.0, 1.0);
    let (mut e0, mut e1) = (0.0, 0.0);
    let mut p = c[0] + c[1] * u;
    let mut dp = c[1];
    let mut ep = 0.0;
    for ck in c.iter().skip(2) {
        let t2 = 2.0 * u * t1 - t0;
        let d2 = 2.0 * t1 + 2.0 * u * d1 - d0;
        let e2 = 4.0 * d1 + 2.0 * u * e1 - e0;
        p += ck * t2;
        dp += ck * d2;
        ep += ck * e2;
        (t0, t1, d0, d1, e0, e1) = (t1, t2, d1, d2, e1, e2);
    }
    (p, 2.0 * dp, 4.0 * ep)
}

/// Speed after accelerating at `accel_mps2` for `duration_s` from `speed0_mps`, with a
/// return to rest snapped to exactly zero: `0.1 m/s² × 3 s` then `−0.3 m/s² × 1 s` rounds to
/// 5.55e-17 m/s, which is rest to the precision of its inputs (|v| ≤ 4ε(|v0| + |aT|)).
pub fn accelerated_speed(speed0_mps: f64, accel_mps2: f64, duration_s: f64) -> f64 {
    let dv = accel_mps2 * duration_s;
    let v = speed0_mps + dv;
    if v.abs() <= 4.0 * f64::EPSILON * (speed0_mps.abs() + dv.abs()) {
        0.0
    } else {
        v
    }
}

/// A segment with its time span and its start state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// kind of motion
    pub motion: Motion,
    /// start time \[s\]
    pub t0_s: f64,
    /// duration \[s\]
    pub duration_s: f64,
    speed0: f64,
    heading0: f64,
    v_d0: f64,
}

/// Exact kinematics at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics {
    /// NED velocity \[m/s\]
    pub v_n_mps: Vec3,
    /// its time derivative \[m/s²\]
    pub v_dot_n_mps2: Vec3,
    /// attitude body→NED
    pub c_b_n: Mat3,
    /// body rate relative to the navigation frame, in body axes \[rad/s\]
    pub omega_nb_b_rps: Vec3,
}

/// A piecewise-analytic trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Trajectory {
    roll0_rad: f64,
    pitch0_rad: f64,
    segments: Vec<Segment>,
    overlays: Vec<Overlay>,
    /// total duration \[s\]
    pub duration_s: f64,
    /// per-trajectory constants of [`Trajectory::kinematics_split`]: sin/cos of roll and
    /// pitch, and per overlay sin/cos of the coning half-angle α/2 and of α
    consts: KinConsts,
    /// the vehicle whose attitude follows the motion ([`crate::truth::vehicle`])
    vehicle: Vehicle,
    /// aircraft: the position track of the earth terms
    track: Option<Box<Track>>,
    /// aircraft: sin/cos of the angle of attack
    sc_alpha: (f64, f64),
    /// random-vibration realisations ([`OverlayKind::RandomVibration`])
    random: Vec<Arc<RandomVibration>>,
    /// per overlay: where its component phases start in [`OverlayPhases`] (after the one
    /// phase per overlay), for random-vibration overlays
    rv_offset: Vec<usize>,
    /// a recorded trajectory's interpolant, in place of the segments
    /// ([`Trajectory::from_reference`])
    reference: Option<Arc<ReferenceTrack>>,
    /// "Euler angles + body velocity" base ([`crate::truth::body_motion`]) in place of the
    /// segments' nominal motion (the segments then only carry the command time spans)
    body: Option<Arc<BodyMotion>>,
}

impl Trajectory {
    /// Build from the start state and the segments `(motion, duration_s)` in order.
    pub fn new(
        start_speed_mps: f64,
        start_v_d_mps: f64,
        start_euler: Euler,
        motions: &[(Motion, f64)],
        overlays: Vec<Overlay>,
    ) -> Self {
        let mut segments = Vec::with_capacity(motions.len());
        let (mut t, mut s, mut h, mut vd) =
            (0.0, start_speed_mps, start_euler.yaw_rad, start_v_d_mps);
        for &(motion, duration_s) in motions {
            let seg = Segment {
                motion,
                t0_s: t,
                duration_s,
                speed0: s,
                heading0: h,
                v_d0: vd,
            };
            (s, h, vd) = seg.end_state();
            t += duration_s;
            segments.push(seg);
        }
        Self {
            roll0_rad: start_euler.roll_rad,
            pitch0_rad: start_euler.pitch_rad,
            consts: KinConsts::new(
                start_euler.roll_rad,
                start_euler.pitch_rad,
                &overlays,
                &segments,
            ),
            segments,
            overlays,
            duration_s: t,
            vehicle: Vehicle::Free,
            track: None,
            sc_alpha: (0.0, 1.0),
            random: Vec::new(),
            rv_offset: Vec::new(),
            reference: None,
            body: None,
        }
    }

    /// A recorded trajectory ([`crate::truth::reference`]): its interpolant gives velocity,
    /// attitude and their rates, with the overlays on top; `duration_s` (at most the
    /// track's) ends it, e.g. on a whole number of IMU samples.
    pub fn from_reference(track: ReferenceTrack, duration_s: f64, overlays: Vec<Overlay>) -> Self {
        let mut t = Self::new(0.0, 0.0, Euler::new(0.0, 0.0, 0.0), &[], overlays);
        t.duration_s = duration_s.min(track.duration_s());
        t.reference = Some(Arc::new(track));
        t
    }

    /// The recorded trajectory this one follows, if any ([`Trajectory::from_reference`]).
    pub fn reference(&self) -> Option<&ReferenceTrack> {
        self.reference.as_deref()
    }

    /// Times inside the trajectory where the motion's analytic branch changes (segment
    /// starts, reference knots): the truth generator's panels never straddle one.
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b: Vec<f64> = self.segments.iter().skip(1).map(|s| s.t0_s).collect();
        if let Some(r) = &self.reference {
            b.extend(r.knots().iter().skip(1).copied());
        }
        if let Some(bm) = &self.body {
            b.extend(bm.breaks());
        }
        b
    }

    /// A trajectory on the "Euler angles + body velocity" base ([`crate::truth::body_motion`]):
    /// one placeholder segment per command (its time span, for the envelope check and
    /// error locations) and the overlays on top, free vehicle.
    pub fn from_body_motion(body: BodyMotion, overlays: Vec<Overlay>) -> Self {
        let motions: Vec<(Motion, f64)> = body
            .pieces()
            .iter()
            .map(|p| (Motion::Cruise, p.duration_s))
            .collect();
        let mut tr = Trajectory::new(0.0, 0.0, Euler::new(0.0, 0.0, 0.0), &motions, overlays);
        // the placeholder segments start where the pieces start
        for (seg, p) in tr.segments.iter_mut().zip(body.pieces()) {
            seg.t0_s = p.t0_s;
        }
        tr.duration_s = body.duration_s;
        tr.body = Some(Arc::new(body));
        tr
    }

    /// The body-motion base, if the trajectory has one ([`Trajectory::from_body_motion`]).
    pub fn body_motion(&self) -> Option<&BodyMotion> {
        self.body.as_deref()
    }

    /// Attach the realisations that the [`OverlayKind::RandomVibration`] overlays index
    /// (each overlay's state is frozen at its window end, clipped to the duration).
    /// Panics never: an overlay whose `id` has no realisation stays at rest.
    pub fn with_random_vibration(mut self, list: Vec<RandomVibration>) -> Self {
        let mut list = list;
        for o in &self.overlays {
            if let OverlayKind::RandomVibration { id } = o.kind {
                if let Some(rv) = list.get_mut(id) {
                    rv.freeze_at(o.end_s.min(self.duration_s) - o.start_s);
                }
            }
        }
        self.random = list.into_iter().map(Arc::new).collect();
        let mut off = self.overlays.len();
        self.rv_offset = self
            .overlays
            .iter()
            .map(|o| {
                let here = off;
                if let OverlayKind::RandomVibration { id } = o.kind {
                    off += self.random.get(id).map_or(0, |r| r.len());
                }
                here
            })
            .collect();
        self
    }

    /// The random-vibration realisations.
    pub fn random_vibrations(&self) -> &[Arc<RandomVibration>] {
        &self.random
    }

    fn rv_of(&self, kind: &OverlayKind) -> Option<&RandomVibration> {
        match kind {
            OverlayKind::RandomVibration { id } => self.random.get(*id).map(|r| r.as_ref()),
            _ => None,
        }
    }

    /// The Gauss-panel count the random vibrations need at `dt_s`
    /// ([`RandomVibration::gauss_panels`]; 0: one 3-node panel suffices).
    pub fn random_vibration_panels(&self, dt_s: f64) -> usize {
        self.random
            .iter()
            .map(|r| r.gauss_panels(dt_s))
            .max()
            .unwrap_or(0)
    }

    /// The same motion flown or driven by `vehicle` ([`crate::truth::vehicle`]): the attitude
    /// follows the nominal velocity (roll and pitch of the start Euler angles are not
    /// used). An aircraft needs the earth model and start position of the truth (its bank
    /// includes gravity, Coriolis and transport rate along its position track) and
    /// segment joints that continue `v̇` and `v̈` (else [`VehicleError::Joint`]); a car or
    /// aircraft at zero speed cannot move vertically ([`VehicleError::Vertical`]).
    pub fn with_vehicle(
        mut self,
        vehicle: Vehicle,
        earth: EarthModel,
        lat0_rad: f64,
        h0_m: f64,
    ) -> Result<Self, VehicleError> {
        self.vehicle = vehicle;
        self.track = None;
        if vehicle == Vehicle::Free {
            return Ok(self);
        }
        for (i, s) in self.segments.iter().enumerate() {
            for t in [s.t0_s, s.t0_s + s.duration_s] {
                let n = s.eval(t);
                if n.speed == 0.0 && n.v_d != 0.0 {
                    return Err(VehicleError::Vertical {
                        index: i + 1,
                        vehicle: vehicle.name(),
                        v_d_mps: n.v_d,
                    });
                }
            }
        }
        if let Vehicle::Aircraft {
            angle_of_attack_rad,
        } = vehicle
        {
            for i in 1..self.segments.len() {
                let (a, b) = (&self.segments[i - 1], &self.segments[i]);
                let t = b.t0_s;
                let (na, nb) = (a.eval(t), b.eval(t));
                let va = velocity_derivs(&na, na.heading.sin_cos());
                let vb = velocity_derivs(&nb, nb.heading.sin_cos());
                for (k, quantity) in [(1, "acceleration [m/s²]"), (2, "jerk [m/s³]")] {
                    let jump = (va[k] - vb[k]).norm();
                    if jump > 1e-9 * (1.0 + va[k].norm()) {
                        return Err(VehicleError::Joint {
                            index: i + 1,
                            quantity,
                            jump,
                        });
                    }
                }
            }
            self.track = Some(Box::new(Track::build(
                &self.segments,
                earth,
                lat0_rad,
                h0_m,
            )));
            self.sc_alpha = libm::sincos(angle_of_attack_rad);
        }
        Ok(self)
    }

    /// The vehicle ([`Trajectory::with_vehicle`]).
    pub fn vehicle(&self) -> Vehicle {
        self.vehicle
    }

    /// The segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Highest angular frequency of any periodic motion (overlays, smooth turns,
    /// S-turns) \[rad/s\]; zero if none.
    pub fn max_frequency_rps(&self) -> f64 {
        let seg = self.segments.iter().map(|s| match s.motion {
            Motion::TurnSmooth { .. }
            | Motion::STurn { .. }
            | Motion::AccelerateSmooth { .. }
            | Motion::ClimbSmooth { .. }
            | Motion::TurnRamp { .. }
            | Motion::Geodesic { .. } => 2.0 * PI / s.duration_s,
            _ => 0.0,
        });
        let ov = self.overlays.iter().map(|o| match o.kind {
            OverlayKind::Coning { omega_rps, .. }
            | OverlayKind::Sculling { omega_rps, .. }
            | OverlayKind::Vibration { omega_rps, .. }
            | OverlayKind::Sway { omega_rps, .. } => omega_rps,
            // the raised-cosine profile, and the rotation it drives (peak rate 2A/T)
            OverlayKind::Rotation {
                angle_rad,
                omega_rps,
                ..
            } => omega_rps.max(omega_rps * angle_rad.abs() / PI),
            // resolved by amplitude: `Trajectory::random_vibration_panels`
            OverlayKind::RandomVibration { .. } => 0.0,
        });
        let body = self
            .body
            .as_deref()
            .map_or(0.0, BodyMotion::max_frequency_rps);
        seg.chain(ov).fold(body, f64::max)
    }

    /// The overlays.
    pub fn overlays(&self) -> &[Overlay] {
        &self.overlays
    }

    /// Whether the kinematics are constant with v_N = v_D = 0 (no overlays, only static or
    /// cruise segments): then the truth has the closed form of docs/theory/mechanizations.md
    /// §"Truth generation" (A0, A1).
    pub fn is_constant_parallel(&self) -> bool {
        self.body.is_none()
            && self.track.is_none()
            && self.reference.is_none()
            && self.overlays.is_empty()
            && self
                .segments
                .iter()
                .all(|s| matches!(s.motion, Motion::Static | Motion::Cruise))
            && self.segments.first().is_none_or(|s| {
                let k = self.kinematics(0.0, 0.0);
                s.v_d0 == 0.0 && k.v_n_mps.x.abs() < 1e-12 * (1.0 + k.v_n_mps.y.abs())
            })
    }

    /// Index of the segment whose branch `t_sel` selects.
    pub fn segment_at(&self, t_sel: f64) -> Option<usize> {
        // the last one starting ≤ t_sel (the starts ascend): a binary search, since routes
        // and command lists have up to 10⁵–10⁶ segments and this runs at every evaluation
        match self.segments.partition_point(|s| s.t0_s <= t_sel) {
            _ if self.segments.is_empty() => None,
            i => Some(i.saturating_sub(1)),
        }
    }

    /// `(sin, cos)` of `Ω_k (t_base − start_k)` for every overlay `k` into `out`: the
    /// per-sample part of the overlay phases for [`Trajectory::kinematics_phased`].
    pub fn phases_at(&self, t_base: f64, out: &mut OverlayPhases) {
        out.0.clear();
        out.0.extend(
            self.overlays
                .iter()
                .map(|o| (o.kind.omega_rps() * (t_base - o.start_s)).sin_cos()),
        );
        for o in &self.overlays {
            if let Some(rv) = self.rv_of(&o.kind) {
                rv.push_phases(t_base - o.start_s, &mut out.0);
            }
        }
    }

    /// The phases at `t_base` from those of an earlier time `prev` and the phases `step`
    /// of the time step ([`Trajectory::phases_offset`]): the periodic overlays as
    /// [`Trajectory::phases_at`], the random-vibration components by the rotation
    /// `(sin, cos)(φ + δ)` from `(sin, cos) φ` and `δ` (renormalised to unit length to
    /// first order), which is what keeps thousands of components cheap per sample.
    pub fn phases_advance(
        &self,
        prev: &OverlayPhases,
        step: &OverlayPhases,
        t_base: f64,
        out: &mut OverlayPhases,
    ) {
        let n = self.overlays.len();
        if prev.0.len() != step.0.len() || prev.0.len() <= n {
            return self.phases_at(t_base, out);
        }
        out.0.clear();
        out.0.extend(
            self.overlays
                .iter()
                .map(|o| (o.kind.omega_rps() * (t_base - o.start_s)).sin_cos()),
        );
        out.0.extend(
            prev.0[n..]
                .iter()
                .zip(&step.0[n..])
                .map(|(&(sp, cp), &(ss, cs))| {
                    let (s, c) = (sp * cs + cp * ss, cp * cs - sp * ss);
                    let r = 1.5 - 0.5 * (s * s + c * c);
                    (s * r, c * r)
                }),
        );
    }

    /// `(sin, cos)` of `Ω_k·off` for every overlay `k` into `out`: the per-node part of
    /// the overlay phases for [`Trajectory::kinematics_phased`].
    pub fn phases_offset(&self, off: f64, out: &mut OverlayPhases) {
        out.0.clear();
        out.0.extend(
            self.overlays
                .iter()
                .map(|o| (o.kind.omega_rps() * off).sin_cos()),
        );
        for o in &self.overlays {
            if let Some(rv) = self.rv_of(&o.kind) {
                rv.push_phases(off, &mut out.0);
            }
        }
    }

    /// Exact kinematics at time `t`, with the analytic branch selected by `t_sel`
    /// (the substep midpoint of the integrator, docs/theory/mechanizations.md §"Truth generation").
    pub fn kinematics(&self, t: f64, t_sel: f64) -> Kinematics {
        self.kinematics_split(t, 0.0, t_sel)
    }

    /// As [`Trajectory::kinematics`] at `t = t_base + off`, with periodic overlay phases
    /// formed as `Ω(t_base − start) + Ω·off` and combined by the angle-addition formulas,
    /// so that the large part of the phase is rounded identically for every substep of a
    /// sample (at t = 400 s one ulp of t is 5.7e-14 s, which would otherwise put ~1e-16 rad
    /// of time-quantisation noise on each increment).
    pub fn kinematics_split(&self, t_base: f64, off: f64, t_sel: f64) -> Kinematics {
        self.kinematics_impl(t_base, off, t_sel, None)
    }

    /// [`Trajectory::kinematics_split`] with the sin/cos of the overlay phases supplied:
    /// `base` from [`Trajectory::phases_at`]`(t_base)` and `offset` from
    /// [`Trajectory::phases_offset`]`(off)`. Bit-for-bit the same result, without the two
    /// `sin_cos` per periodic overlay: a sample's base phase is shared by all its nodes and
    /// the node offsets repeat from sample to sample.
    pub fn kinematics_phased(
        &self,
        t_base: f64,
        off: f64,
        t_sel: f64,
        base: &OverlayPhases,
        offset: &OverlayPhases,
    ) -> Kinematics {
        debug_assert_eq!(base.0.len(), offset.0.len());
        debug_assert!(base.0.len() >= self.overlays.len());
        self.kinematics_impl(t_base, off, t_sel, Some((&base.0, &offset.0)))
    }

    #[inline(always)]
    fn kinematics_impl(
        &self,
        t_base: f64,
        off: f64,
        t_sel: f64,
        phases: Option<PhasePair<'_>>,
    ) -> Kinematics {
        let t = t_base + off;
        if let Some(r) = &self.reference {
            let k = r.at_split(t_base, off, t_sel).kin;
            return self.apply_overlays(
                t_base,
                off,
                t_sel,
                phases,
                k.v_n_mps,
                k.v_dot_n_mps2,
                k.c_b_n,
                k.omega_nb_b_rps,
            );
        }
        let seg = self.segment_at(t_sel);
        let n = match seg {
            Some(i) => self.segments[i].eval(t),
            None => Nominal::default(),
        };
        // constant-heading segments: n.heading is their start heading, whose sin/cos is cached
        let (sh, ch) = match seg.and_then(|i| self.consts.heading[i]) {
            Some(sc) => sc,
            None => n.heading.sin_cos(),
        };
        let v = Vec3::new(n.speed * ch, n.speed * sh, n.v_d);
        let v_dot = Vec3::new(
            n.speed_dot * ch - n.speed * n.heading_dot * sh,
            n.speed_dot * sh + n.speed * n.heading_dot * ch,
            n.v_d_dot,
        );
        let (c_nom, w_nom) = match (self.vehicle, &self.track, seg) {
            (Vehicle::Car, _, _) => car_attitude(&n, (sh, ch)),
            (Vehicle::Aircraft { .. }, Some(tr), Some(i)) => {
                let p = tr.eval(i, &self.segments[i], t);
                aircraft_attitude(tr, &p, &n, (sh, ch), self.sc_alpha)
            }
            _ => {
                // c_b_n_from_euler(roll0, pitch0, heading) with the constant sin/cos of
                // roll and pitch and the heading's sin/cos from above
                let [sr, cr, sp, cp] = self.consts.roll_pitch;
                let c_nom = sdins_core::math::c_b_n_from_sin_cos((sr, cr), (sp, cp), (sh, ch));
                // ω_nb^b from Euler rates with φ̇ = θ̇ = 0 (docs/conventions.md §"Euler angles")
                let w_nom = Vec3::new(
                    -n.heading_dot * sp,
                    n.heading_dot * cp * sr,
                    n.heading_dot * cp * cr,
                );
                (c_nom, w_nom)
            }
        };
        // the body-motion base replaces the nominal motion (crate::truth::body_motion)
        let (v, v_dot, c_nom, w_nom) = match self.body.as_deref() {
            Some(b) => b.kinematics(t, t_sel),
            None => (v, v_dot, c_nom, w_nom),
        };
        self.apply_overlays(t_base, off, t_sel, phases, v, v_dot, c_nom, w_nom)
    }

    /// The overlays on top of the nominal motion `(v, v̇, C_nom, ω_nom)`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn apply_overlays(
        &self,
        t_base: f64,
        off: f64,
        t_sel: f64,
        phases: Option<PhasePair<'_>>,
        mut v: Vec3,
        mut v_dot: Vec3,
        c_nom: Mat3,
        w_nom: Vec3,
    ) -> Kinematics {
        // attitude overlays: C_b^n = C_nom C_c, ω = C_cᵀ ω_nom + ω_c (docs/theory/mechanizations.md
        // §"Truth generation")
        let mut c_c = Mat3::identity();
        let mut w_c = Vec3::zeros();
        for (j, (ov, kc)) in self.overlays.iter().zip(&self.consts.overlay).enumerate() {
            // branch by t_sel: before the window the overlay is at rest, after it frozen
            let active = t_sel >= ov.start_s && t_sel < ov.end_s;
            let (tau_base, tau_off) = if active {
                (t_base - ov.start_s, off)
            } else if t_sel < ov.start_s {
                (0.0, 0.0)
            } else {
                (ov.end_s - ov.start_s, 0.0)
            };
            let sincos = |w: f64| -> (f64, f64) {
                let ((sa, ca), (sb, cb)) = match phases {
                    // the supplied phases are those of the active branch
                    Some((b, o)) if active => (b[j], o[j]),
                    _ => ((w * tau_base).sin_cos(), (w * tau_off).sin_cos()),
                };
                (sa * cb + ca * sb, ca * cb - sa * sb)
            };
            let (c_k, w_k) = match ov.kind {
                OverlayKind::Coning {
                    axis, omega_rps, ..
                } => {
                    let [sa2, ca2, sa, ca] = *kc;
                    let (swt, cwt) = sincos(omega_rps);
                    let v0 = axis.place(sa2, 0.0, 0.0);
                    let vt = axis.place(sa2 * cwt, sa2 * swt, 0.0);
                    let q0 = Quat::from_parts(ca2, &v0);
                    let qt = Quat::from_parts(ca2, &vt);
                    let c = q0.conj().mul(&qt).to_dcm();
                    let w = axis.place(
                        -omega_rps * sa * swt,
                        omega_rps * sa * cwt,
                        -omega_rps * (1.0 - ca),
                    );
                    (c, if active { w } else { Vec3::zeros() })
                }
                OverlayKind::Sculling {
                    angle_amp_rad,
                    accel_amp_mps2,
                    omega_rps,
                } => {
                    let (swt, cwt) = sincos(omega_rps);
                    let ang = angle_amp_rad * swt;
                    let (sa, ca) = ang.sin_cos();
                    let c = Mat3::new(1.0, 0.0, 0.0, 0.0, ca, -sa, 0.0, sa, ca);
                    // linear part: body-y velocity (A0/Ω)(1 − cos Ωτ) in the nominal frame
                    let u = Vec3::new(0.0, accel_amp_mps2 / omega_rps * (1.0 - cwt), 0.0);
                    let u_dot = if active {
                        Vec3::new(0.0, accel_amp_mps2 * swt, 0.0)
                    } else {
                        Vec3::zeros()
                    };
                    v += c_nom * u;
                    v_dot += c_nom * (w_nom.cross(&u) + u_dot);
                    let w = Vec3::new(angle_amp_rad * omega_rps * cwt, 0.0, 0.0);
                    (c, if active { w } else { Vec3::zeros() })
                }
                OverlayKind::Vibration {
                    axis,
                    accel_amp_mps2,
                    omega_rps,
                } => {
                    let (swt, cwt) = sincos(omega_rps);
                    let mut u = Vec3::zeros();
                    let mut u_dot = Vec3::zeros();
                    u[axis.index()] = accel_amp_mps2 / omega_rps * swt;
                    if active {
                        u_dot[axis.index()] = accel_amp_mps2 * cwt;
                    }
                    v += c_nom * u;
                    v_dot += c_nom * (w_nom.cross(&u) + u_dot);
                    (Mat3::identity(), Vec3::zeros())
                }
                OverlayKind::Sway {
                    axis,
                    amp_rad,
                    omega_rps,
                    ..
                } => {
                    // sin/cos(Ωτ + φ) by angle addition with the cached sin/cos φ
                    let [sp, cp, _, _] = *kc;
                    let (swt, cwt) = sincos(omega_rps);
                    let (s_ph, c_ph) = (swt * cp + cwt * sp, cwt * cp - swt * sp);
                    let c = axis_rotation(axis, (amp_rad * s_ph).sin_cos());
                    let mut w = Vec3::zeros();
                    if active {
                        w[axis.index()] = amp_rad * omega_rps * c_ph;
                    }
                    (c, w)
                }
                OverlayKind::Rotation {
                    axis,
                    angle_rad,
                    omega_rps,
                } => {
                    let mut w = Vec3::zeros();
                    let theta = if active {
                        // sin/cos(2πx) = sin/cos(Ωτ); x = τ/T with T = 2π/Ω
                        let (s2, c2) = sincos(omega_rps);
                        let x = (tau_base + tau_off) * omega_rps / (2.0 * PI);
                        w[axis.index()] = angle_rad * omega_rps / (2.0 * PI) * (1.0 - c2);
                        angle_rad * (x - s2 / (2.0 * PI))
                    } else if t_sel < ov.start_s {
                        0.0
                    } else {
                        angle_rad
                    };
                    (axis_rotation(axis, theta.sin_cos()), w)
                }
                OverlayKind::RandomVibration { .. } => {
                    let Some(rv) = self.rv_of(&ov.kind) else {
                        continue;
                    };
                    let st = if active {
                        let ph = phases.map(|(b, o)| {
                            let a = self.rv_offset[j];
                            (&b[a..a + rv.len()], &o[a..a + rv.len()])
                        });
                        rv.state(tau_base + tau_off, ph)
                    } else if t_sel < ov.start_s {
                        crate::truth::random_vibration::VibState::default()
                    } else {
                        rv.frozen(tau_base)
                    };
                    let u = Vec3::from(st.u);
                    let u_dot = Vec3::from(st.u_dot);
                    v += c_nom * u;
                    v_dot += c_nom * (w_nom.cross(&u) + u_dot);
                    if !rv.has_rotation() {
                        (Mat3::identity(), Vec3::zeros())
                    } else {
                        let [tx, ty, tz] = st.theta;
                        let (sx, cx) = tx.sin_cos();
                        let (sy, cy) = ty.sin_cos();
                        let (sz, cz) = tz.sin_cos();
                        let rx = Mat3::new(1.0, 0.0, 0.0, 0.0, cx, -sx, 0.0, sx, cx);
                        let ry = Mat3::new(cy, 0.0, sy, 0.0, 1.0, 0.0, -sy, 0.0, cy);
                        let rz = Mat3::new(cz, -sz, 0.0, sz, cz, 0.0, 0.0, 0.0, 1.0);
                        // ω = R_zᵀR_yᵀ θ̇_x e_x + R_zᵀ θ̇_y e_y + θ̇_z e_z
                        let [dx, dy, dz] = st.theta_dot;
                        let w = rz.transpose()
                            * (ry.transpose() * Vec3::new(dx, 0.0, 0.0) + Vec3::new(0.0, dy, 0.0))
                            + Vec3::new(0.0, 0.0, dz);
                        (rx * ry * rz, w)
                    }
                }
            };
            // compose: C_c ← C_c C_k, ω_c ← C_kᵀ ω_c + ω_k (the first directly: the
            // products with the identity and zero would return it unchanged)
            if j == 0 {
                (c_c, w_c) = (c_k, w_k);
            } else {
                w_c = c_k.transpose() * w_c + w_k;
                c_c *= c_k;
            }
        }
        if self.overlays.is_empty() {
            return Kinematics {
                v_n_mps: v,
                v_dot_n_mps2: v_dot,
                c_b_n: c_nom,
                omega_nb_b_rps: w_nom,
            };
        }
        Kinematics {
            v_n_mps: v,
            v_dot_n_mps2: v_dot,
            c_b_n: c_nom * c_c,
            omega_nb_b_rps: c_c.transpose() * w_nom + w_c,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn num_deriv<F: Fn(f64) -> Vec3>(f: F, t: f64, h: f64) -> Vec3 {
        (f(t - 2.0 * h) - 8.0 * f(t - h) + 8.0 * f(t + h) - f(t + 2.0 * h)) / (12.0 * h)
    }

    fn rich() -> Trajectory {
        Trajectory::new(
            10.0,
            0.0,
            Euler::new(0.02, -0.03, 0.4),
            &[
                (Motion::Accelerate { accel_mps2: 2.0 }, 5.0),
                (Motion::TurnSmooth { angle_rad: 1.0 }, 4.0),
                (Motion::STurn { amplitude_rps: 0.1 }, 6.0),
                (
                    Motion::Climb {
                        to_climb_rate_mps: 3.0,
                    },
                    2.0,
                ),
            ],
            vec![
                Overlay {
                    kind: OverlayKind::Coning {
                        axis: Axis::X,
                        half_angle_rad: 0.01,
                        omega_rps: 6.0,
                    },
                    start_s: 0.0,
                    end_s: 100.0,
                },
                Overlay {
                    kind: OverlayKind::Sculling {
                        angle_amp_rad: 0.002,
                        accel_amp_mps2: 0.5,
                        omega_rps: 9.0,
                    },
                    start_s: 0.0,
                    end_s: 100.0,
                },
                Overlay {
                    kind: OverlayKind::Vibration {
                        axis: Axis::Z,
                        accel_amp_mps2: 0.3,
                        omega_rps: 20.0,
                    },
                    start_s: 0.0,
                    end_s: 100.0,
                },
                Overlay {
                    kind: OverlayKind::Sway {
                        axis: Axis::Y,
                        amp_rad: 0.08,
                        omega_rps: 1.1,
                        phase_rad: 0.7,
                    },
                    start_s: 0.0,
                    end_s: 100.0,
                },
            ],
        )
    }

    #[test]
    fn derivatives_match_finite_differences() {
        // Inside each segment, v̇ and ω_nb^b (from Ċ = C[ω×]) agree with 4th-order central
        // differences; truncation O(h⁴·|d⁵v|) with h = 1e-3 is ~1e-10, roundoff ~1e-12.
        let tr = rich();
        for &t in &[1.3, 6.7, 11.1, 16.2] {
            let k = tr.kinematics(t, t);
            let dv = num_deriv(|x| tr.kinematics(x, t).v_n_mps, t, 1e-3);
            assert!(
                (dv - k.v_dot_n_mps2).norm() < 1e-8,
                "t={t}: {}",
                (dv - k.v_dot_n_mps2).norm()
            );
            let h = 1e-4;
            let cdot = (tr.kinematics(t + h, t).c_b_n - tr.kinematics(t - h, t).c_b_n) / (2.0 * h);
            let w_skew = k.c_b_n.transpose() * cdot;
            let w = sdins_core::math::vee_antisym(&w_skew);
            assert!(
                (w - k.omega_nb_b_rps).norm() < 1e-6,
                "t={t}: {}",
                (w - k.omega_nb_b_rps).norm()
            );
        }
    }

    #[test]
    fn nominal_attitude_is_the_euler_dcm() {
        // the cached roll/pitch sin/cos build the same DCM as c_b_n_from_euler
        let tr = Trajectory::new(
            10.0,
            0.0,
            Euler::new(0.02, -0.03, 0.4),
            &[(Motion::STurn { amplitude_rps: 0.3 }, 10.0)],
            vec![],
        );
        for &t in &[0.0, 1.7, 4.2, 9.9] {
            let k = tr.kinematics(t, t);
            let yaw = tr.segments()[0].eval(t).heading;
            let want = sdins_core::math::c_b_n_from_euler(&Euler::new(0.02, -0.03, yaw));
            assert!((k.c_b_n - want).abs().max() <= 4.0 * f64::EPSILON, "t={t}");
        }
    }

    #[test]
    fn rotation_overlays_rate_and_end_attitude() {
        // two composed turntable steps: ω_nb^b agrees with the attitude's finite
        // difference (O(h²|C⃛|) ≈ 1e-9 with h = 1e-4) inside the windows, the rotation is at
        // rest before and after, and each step ends at R_axis(A) (to sin/cos rounding)
        let tr = Trajectory::new(
            0.0,
            0.0,
            Euler::new(0.0, 0.0, 0.0),
            &[(Motion::Static, 30.0)],
            vec![
                OverlayKind::rotation(Axis::X, PI, 2.0, 8.0),
                OverlayKind::rotation(Axis::Z, -0.5 * PI, 10.0, 14.0),
            ],
        );
        for &t in &[3.1, 5.0, 7.9, 11.3, 13.2] {
            let k = tr.kinematics(t, t);
            let h = 1e-4;
            let cdot = (tr.kinematics(t + h, t).c_b_n - tr.kinematics(t - h, t).c_b_n) / (2.0 * h);
            let w = sdins_core::math::vee_antisym(&(k.c_b_n.transpose() * cdot));
            assert!((w - k.omega_nb_b_rps).norm() < 1e-7, "t={t}");
        }
        for &t in &[1.0, 9.0, 20.0] {
            assert_eq!(tr.kinematics(t, t).omega_nb_b_rps, Vec3::zeros(), "t={t}");
        }
        let want = Mat3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
        let got = tr.kinematics(20.0, 20.0).c_b_n;
        assert!((got - want).abs().max() < 4.0 * f64::EPSILON, "{got}");
        // peak rate 2A/T of the first step at mid-window
        let k = tr.kinematics(5.0, 5.0);
        assert!((k.omega_nb_b_rps.x - 2.0 * PI / 6.0).abs() < 1e-15);
    }

    #[test]
    fn segments_are_continuous() {
        let tr = rich();
        for seg in tr.segments().iter().skip(1) {
            let t = seg.t0_s;
            let before = tr.kinematics(t, t - 1e-6);
            let after = tr.kinematics(t, t + 1e-6);
            assert!((before.v_n_mps - after.v_n_mps).norm() < 1e-12);
            assert!((before.c_b_n - after.c_b_n).abs().max() < 1e-14);
        }
    }
}
