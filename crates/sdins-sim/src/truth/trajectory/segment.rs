//! One motion segment evaluated exactly: the nominal speed, heading and climb of a
//! [`Segment`] at a time inside it, with the closed forms of each [`Motion`].

use super::*;

/// The smooth step `S(x) = x − sin(2πx)/(2π)` and its first two derivatives in `x`,
/// with `S(1) = 1` exactly.
pub(super) fn smooth_step(x: f64) -> (f64, f64, f64) {
    if x >= 1.0 {
        return (1.0, 0.0, 0.0);
    }
    let (s, c) = (2.0 * PI * x).sin_cos();
    (x - s / (2.0 * PI), 1.0 - c, 2.0 * PI * s)
}

#[derive(Clone, Debug, PartialEq)]
pub(super) struct KinConsts {
    /// sin φ0, cos φ0, sin θ0, cos θ0
    pub(super) roll_pitch: [f64; 4],
    /// per overlay: sin(α/2), cos(α/2), sin α, cos α (zeros for non-coning overlays)
    pub(super) overlay: Vec<[f64; 4]>,
    /// per segment: sin/cos of the start heading where the motion keeps it constant
    /// (static, cruise, accelerate, climb), so that those segments need no trigonometry
    pub(super) heading: Vec<Option<(f64, f64)>>,
}

impl KinConsts {
    pub(super) fn new(roll: f64, pitch: f64, overlays: &[Overlay], segments: &[Segment]) -> Self {
        let overlay = overlays
            .iter()
            .map(|o| match o.kind {
                OverlayKind::Coning { half_angle_rad, .. } => {
                    let (sa2, ca2) = (0.5 * half_angle_rad).sin_cos();
                    let (sa, ca) = half_angle_rad.sin_cos();
                    [sa2, ca2, sa, ca]
                }
                OverlayKind::Sway { phase_rad, .. } => {
                    let (sp, cp) = phase_rad.sin_cos();
                    [sp, cp, 0.0, 0.0]
                }
                _ => [0.0; 4],
            })
            .collect();
        let heading = segments
            .iter()
            .map(|s| match s.motion {
                Motion::Static
                | Motion::Cruise
                | Motion::Accelerate { .. }
                | Motion::Climb { .. }
                | Motion::AccelerateSmooth { .. }
                | Motion::ClimbSmooth { .. } => Some(s.heading0.sin_cos()),
                Motion::TurnRate { .. }
                | Motion::TurnSmooth { .. }
                | Motion::STurn { .. }
                | Motion::TurnRamp { .. }
                | Motion::Geodesic { .. } => None,
            })
            .collect();
        Self {
            heading,
            roll_pitch: [
                libm::sin(roll),
                libm::cos(roll),
                libm::sin(pitch),
                libm::cos(pitch),
            ],
            overlay,
        }
    }
}

/// The nominal motion of a segment at one instant: horizontal speed, heading and down
/// velocity with their first two time derivatives.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Nominal {
    pub(crate) speed: f64,
    pub(crate) speed_dot: f64,
    pub(crate) speed_ddot: f64,
    pub(crate) heading: f64,
    pub(crate) heading_dot: f64,
    pub(crate) heading_ddot: f64,
    pub(crate) v_d: f64,
    pub(crate) v_d_dot: f64,
    pub(crate) v_d_ddot: f64,
}

impl Segment {
    pub(crate) fn eval(&self, t: f64) -> Nominal {
        let tau = t - self.t0_s;
        let big_t = self.duration_s;
        let mut n = Nominal {
            speed: self.speed0,
            heading: self.heading0,
            v_d: self.v_d0,
            ..Nominal::default()
        };
        match self.motion {
            Motion::Static | Motion::Cruise => {}
            Motion::Accelerate { accel_mps2 } => {
                n.speed = if tau == big_t {
                    accelerated_speed(self.speed0, accel_mps2, big_t)
                } else {
                    self.speed0 + accel_mps2 * tau
                };
                n.speed_dot = accel_mps2;
            }
            Motion::TurnRate { rate_rps } => {
                n.heading = self.heading0 + rate_rps * tau;
                n.heading_dot = rate_rps;
            }
            Motion::TurnSmooth { angle_rad } => {
                let x = tau / big_t;
                let (s2, c2) = (2.0 * PI * x).sin_cos();
                n.heading = self.heading0 + angle_rad * (x - s2 / (2.0 * PI));
                n.heading_dot = angle_rad / big_t * (1.0 - c2);
                n.heading_ddot = angle_rad / (big_t * big_t) * 2.0 * PI * s2;
            }
            Motion::STurn { amplitude_rps } => {
                let w = 2.0 * PI / big_t;
                let (s, c) = (w * tau).sin_cos();
                n.heading = self.heading0 + amplitude_rps / w * (1.0 - c);
                n.heading_dot = amplitude_rps * s;
                n.heading_ddot = amplitude_rps * w * c;
            }
            Motion::Climb { to_climb_rate_mps } => {
                let rate = (-to_climb_rate_mps - self.v_d0) / big_t;
                n.v_d = self.v_d0 + rate * tau;
                n.v_d_dot = rate;
            }
            Motion::AccelerateSmooth { delta_speed_mps } => {
                let (st, st1, st2) = smooth_step(tau / big_t);
                n.speed = self.speed0 + delta_speed_mps * st;
                n.speed_dot = delta_speed_mps / big_t * st1;
                n.speed_ddot = delta_speed_mps / (big_t * big_t) * st2;
            }
            Motion::ClimbSmooth { to_climb_rate_mps } => {
                let d = -to_climb_rate_mps - self.v_d0;
                let (st, st1, st2) = smooth_step(tau / big_t);
                n.v_d = self.v_d0 + d * st;
                n.v_d_dot = d / big_t * st1;
                n.v_d_ddot = d / (big_t * big_t) * st2;
            }
            Motion::TurnRamp { from_rps, to_rps } => {
                let x = tau / big_t;
                let d = to_rps - from_rps;
                let (st, st1, _) = smooth_step(x);
                let int = if x >= 1.0 {
                    0.5
                } else {
                    0.5 * x * x + ((2.0 * PI * x).cos() - 1.0) / (4.0 * PI * PI)
                };
                n.heading = self.heading0 + from_rps * tau + d * big_t * int;
                n.heading_dot = from_rps + d * st;
                n.heading_ddot = d / big_t * st1;
            }
            Motion::Geodesic {
                heading_cheb,
                delta_speed_mps,
                delta_v_d_mps,
            } => {
                let x = (tau / big_t).clamp(0.0, 1.0);
                let (p, dp, ddp) = cheb_eval(&heading_cheb, x);
                let (p0, _, _) = cheb_eval(&heading_cheb, 0.0);
                n.heading = self.heading0 + (p - p0);
                n.heading_dot = dp / big_t;
                n.heading_ddot = ddp / (big_t * big_t);
                let (st, st1, st2) = smooth_step(x);
                n.speed = self.speed0 + delta_speed_mps * st;
                n.speed_dot = delta_speed_mps / big_t * st1;
                n.speed_ddot = delta_speed_mps / (big_t * big_t) * st2;
                n.v_d = self.v_d0 + delta_v_d_mps * st;
                n.v_d_dot = delta_v_d_mps / big_t * st1;
                n.v_d_ddot = delta_v_d_mps / (big_t * big_t) * st2;
            }
        }
        n
    }

    /// A segment with its start state (for [`crate::truth::route`], which integrates motions
    /// before the trajectory exists).
    pub(crate) fn with_start(
        motion: Motion,
        t0_s: f64,
        duration_s: f64,
        (speed0, heading0, v_d0): (f64, f64, f64),
    ) -> Self {
        Segment {
            motion,
            t0_s,
            duration_s,
            speed0,
            heading0,
            v_d0,
        }
    }

    /// `(speed, heading, v_D)` at the segment end (as [`Trajectory::new`] chains them).
    pub(crate) fn end(&self) -> (f64, f64, f64) {
        self.end_state()
    }

    pub(super) fn end_state(&self) -> (f64, f64, f64) {
        let n = self.eval(self.t0_s + self.duration_s);
        // Exact end values for the closed forms whose end is known analytically.
        let heading = match self.motion {
            Motion::TurnSmooth { angle_rad } => self.heading0 + angle_rad,
            Motion::STurn { .. } => self.heading0,
            Motion::TurnRamp { from_rps, to_rps } => {
                self.heading0 + self.duration_s * (from_rps + 0.5 * (to_rps - from_rps))
            }
            _ => n.heading,
        };
        (n.speed, heading, n.v_d)
    }
}
