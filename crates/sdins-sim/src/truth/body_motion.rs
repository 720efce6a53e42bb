//! "Euler angles + body velocity" motion base: the motion commands of gnss-ins-sim's
//! motion-definition files (docs/scenarios.md §"Importing gnss-ins-sim motion files"),
//! each channel a closed-form piecewise function of time with exact derivatives
//! (docs/theory/mechanizations.md §"Truth generation", "Body-velocity motion").
//!
//! Six channels: yaw ψ, pitch θ, roll φ (3-2-1 Euler angles, docs/conventions.md
//! §"Euler angles") and the body-frame velocity `v^b = (v_x, v_y, v_z)` (FRD). Then
//!
//! - `C_b^n = R_z(ψ) R_y(θ) R_x(φ)`,
//! - `ω_nb^b = (φ̇ − ψ̇ sinθ, θ̇ cosφ + ψ̇ cosθ sinφ, −θ̇ sinφ + ψ̇ cosθ cosφ)` (the
//!   Euler-rate matrix, Groves 2nd ed. eq. 2.58 inverted; exact, no singularity in this
//!   direction),
//! - `v^n = C_b^n v^b`, `v̇^n = C_b^n (v̇^b + ω_nb^b × v^b)` (from `Ċ_b^n = C_b^n [ω_nb^b×]`,
//!   Groves eq. 2.56).
//!
//! A command moves each channel either at a constant rate ([`Channel::Linear`], command
//! type 1) or from its start value `x0` to a target `x0 + Δ` by the smooth step
//! `x = x0 + Δ·S(τ/T_c)`, `S(u) = u − sin(2πu)/(2π)` ([`Channel::Smooth`], types 2–5), then
//! holds the target for the rest of the command. `T_c` is the shortest time within the
//! limits ([`MotionLimits`]): the smooth step's peak rate is `2Δ/T_c` and its peak second
//! derivative `2πΔ/T_c²`, so
//!
//! - angles: `T_c = max(2|Δ|/ω_max, √(2π|Δ|/α_max))`,
//! - body velocity: `T_c = 2|Δ|/a_max` (gnss-ins-sim limits velocity rates only).
//!
//! A command shorter than its slowest channel's `T_c` is extended to that time, rounded up
//! to a whole number of IMU samples ([`BodyMotion::extended`] lists them).

use crate::cancel::{CancelToken, Cancelled, POLL_EVERY_SAMPLES};
use sdins_core::math::{c_b_n_from_sin_cos, Mat3, Vec3};
use std::f64::consts::PI;

/// Motion limits (gnss-ins-sim's `mode`): per channel, as their generator applies them to
/// the Euler-angle rates and body-velocity rates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionLimits {
    /// max |v̇^b| per axis \[m/s²\]
    pub max_accel_mps2: f64,
    /// max |Euler-angle second derivative| \[rad/s²\]
    pub max_angular_accel_rps2: f64,
    /// max |Euler-angle rate| \[rad/s\]
    pub max_angular_rate_rps: f64,
}

impl MotionLimits {
    /// gnss-ins-sim's demo `mode = [1.0, 0.5, 2.0]` in their documented units
    /// `[m/s², deg/s², deg/s]`.
    pub const DEFAULT: MotionLimits = MotionLimits::from_mode([1.0, 0.5, 2.0]);

    /// From a gnss-ins-sim `mode` array `[m/s², deg/s², deg/s]`.
    pub const fn from_mode(mode: [f64; 3]) -> Self {
        Self {
            max_accel_mps2: mode[0],
            max_angular_accel_rps2: mode[1] * (PI / 180.0),
            max_angular_rate_rps: mode[2] * (PI / 180.0),
        }
    }

    /// Back to `[m/s², deg/s², deg/s]`.
    pub fn to_mode(&self) -> [f64; 3] {
        [
            self.max_accel_mps2,
            self.max_angular_accel_rps2.to_degrees(),
            self.max_angular_rate_rps.to_degrees(),
        ]
    }

    /// Whether all three limits are finite and positive.
    pub fn is_valid(&self) -> bool {
        [
            self.max_accel_mps2,
            self.max_angular_accel_rps2,
            self.max_angular_rate_rps,
        ]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0)
    }
}

impl Default for MotionLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Command type (gnss-ins-sim's column 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommandKind {
    /// 1: constant Euler-angle rates \[rad/s\] and body-velocity rates \[m/s²\]
    Rates,
    /// 2: absolute attitude and absolute body velocity
    Absolute,
    /// 3: relative attitude and relative body velocity
    Relative,
    /// 4: absolute attitude, relative body velocity
    AbsAttRelVel,
    /// 5: relative attitude, absolute body velocity
    RelAttAbsVel,
}

impl CommandKind {
    /// From gnss-ins-sim's number 1–5.
    pub fn from_number(n: i64) -> Option<Self> {
        Some(match n {
            1 => Self::Rates,
            2 => Self::Absolute,
            3 => Self::Relative,
            4 => Self::AbsAttRelVel,
            5 => Self::RelAttAbsVel,
            _ => return None,
        })
    }
    /// gnss-ins-sim's number 1–5.
    pub fn number(self) -> i64 {
        match self {
            Self::Rates => 1,
            Self::Absolute => 2,
            Self::Relative => 3,
            Self::AbsAttRelVel => 4,
            Self::RelAttAbsVel => 5,
        }
    }
    fn att_relative(self) -> bool {
        matches!(self, Self::Relative | Self::RelAttAbsVel)
    }
    fn vel_relative(self) -> bool {
        matches!(self, Self::Relative | Self::AbsAttRelVel)
    }
}

/// One motion command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyCommand {
    /// command type
    pub kind: CommandKind,
    /// yaw, pitch, roll \[rad\] (type 1: their rates \[rad/s\])
    pub euler_ypr: [f64; 3],
    /// body velocity x, y, z \[m/s\] (type 1: its rate \[m/s²\])
    pub vel_b: [f64; 3],
    /// duration \[s\] (types 2–5: extended if the limits need longer)
    pub duration_s: f64,
}

/// Start state of the channels.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BodyStart {
    /// yaw, pitch, roll \[rad\]
    pub euler_ypr: [f64; 3],
    /// body velocity \[m/s\]
    pub vel_b: [f64; 3],
}

/// One channel over one command (τ from the command start).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Channel {
    /// `x = x0 + r τ`
    Linear {
        /// start value
        x0: f64,
        /// rate
        rate: f64,
    },
    /// `x = x0 + Δ S(τ/T_c)` for τ < T_c, `x0 + Δ` after
    Smooth {
        /// start value
        x0: f64,
        /// change Δ
        delta: f64,
        /// time to reach it T_c \[s\] (> 0)
        t_c: f64,
    },
}

impl Channel {
    /// Value, first and second derivative at τ.
    pub fn eval(&self, tau: f64) -> (f64, f64, f64) {
        match *self {
            Channel::Linear { x0, rate } => (x0 + rate * tau, rate, 0.0),
            Channel::Smooth { x0, delta, t_c } => {
                if tau >= t_c {
                    return (x0 + delta, 0.0, 0.0);
                }
                let u = (tau / t_c).max(0.0);
                let (s, c) = (2.0 * PI * u).sin_cos();
                (
                    x0 + delta * (u - s / (2.0 * PI)),
                    delta / t_c * (1.0 - c),
                    delta / (t_c * t_c) * 2.0 * PI * s,
                )
            }
        }
    }

    /// Value at the end of a command of length `d` (exact for the held target).
    fn end_value(&self, d: f64) -> f64 {
        match *self {
            Channel::Smooth { x0, delta, t_c } if d >= t_c => x0 + delta,
            _ => self.eval(d).0,
        }
    }

    /// Time at which the channel's profile changes form inside the command (T_c), if any.
    fn inner_break(&self) -> Option<f64> {
        match *self {
            Channel::Smooth { t_c, .. } => Some(t_c),
            Channel::Linear { .. } => None,
        }
    }
}

/// One compiled command: its time span and six channels (yaw, pitch, roll, v_x, v_y, v_z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// start time \[s\]
    pub t0_s: f64,
    /// duration \[s\]
    pub duration_s: f64,
    /// channels yaw, pitch, roll, vx, vy, vz
    pub channels: [Channel; 6],
}

/// A command that needed longer than its duration under the limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extension {
    /// command index (0-based)
    pub index: usize,
    /// the duration given \[s\]
    pub given_s: f64,
    /// the duration used \[s\]
    pub used_s: f64,
}

/// The channel values and derivatives at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// yaw, pitch, roll \[rad\]
    pub euler_ypr: [f64; 3],
    /// their rates \[rad/s\]
    pub euler_rate_ypr: [f64; 3],
    /// their second derivatives \[rad/s²\]
    pub euler_accel_ypr: [f64; 3],
    /// body velocity \[m/s\]
    pub vel_b: Vec3,
    /// its rate \[m/s²\]
    pub vel_dot_b: Vec3,
}

/// The compiled motion.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyMotion {
    pieces: Vec<Piece>,
    /// total duration \[s\]
    pub duration_s: f64,
    /// the limits it was compiled with
    pub limits: MotionLimits,
    /// the commands extended to reach their targets
    pub extended: Vec<Extension>,
}

/// Smooth-step time of a change Δ under (rate, second-derivative) limits, or a rate-free
/// (velocity) limit when `rate_max` is infinite.
fn reach_time(delta: f64, rate_max: f64, accel_max: f64) -> f64 {
    let d = delta.abs();
    if d == 0.0 {
        return 0.0;
    }
    if rate_max.is_finite() {
        (2.0 * d / rate_max).max((2.0 * PI * d / accel_max).sqrt())
    } else {
        2.0 * d / accel_max
    }
}

/// Most commands in one motion (docs/scenarios.md §"Importing gnss-ins-sim motion files"):
/// reading, compiling and checking them is linear in their number (bench/scale.sh).
pub const MAX_COMMANDS: usize = 1_000_000;

impl BodyMotion {
    /// Compile the commands from `start` under `limits`; extended durations are rounded up
    /// to whole multiples of `dt_s` (the IMU sample period).
    pub fn compile(
        start: BodyStart,
        commands: &[BodyCommand],
        limits: MotionLimits,
        dt_s: f64,
    ) -> Self {
        match Self::build(start, commands, limits, dt_s, || {
            Ok::<(), std::convert::Infallible>(())
        }) {
            Ok(m) => m,
            Err(never) => match never {},
        }
    }

    /// [`BodyMotion::compile`], polling `cancel` every
    /// [`POLL_EVERY_SAMPLES`] commands.
    pub fn compile_with(
        start: BodyStart,
        commands: &[BodyCommand],
        limits: MotionLimits,
        dt_s: f64,
        cancel: &CancelToken,
    ) -> Result<Self, Cancelled> {
        Self::build(start, commands, limits, dt_s, || cancel.check())
    }

    fn build<E>(
        start: BodyStart,
        commands: &[BodyCommand],
        limits: MotionLimits,
        dt_s: f64,
        mut poll: impl FnMut() -> Result<(), E>,
    ) -> Result<Self, E> {
        let mut x = [
            start.euler_ypr[0],
            start.euler_ypr[1],
            start.euler_ypr[2],
            start.vel_b[0],
            start.vel_b[1],
            start.vel_b[2],
        ];
        // start times as whole sample counts × δt while the durations are whole samples
        // (then the boundaries are the sample grid's own k·δt), else the running sum
        let (mut t, mut n_sum, mut whole) = (0.0, 0.0, true);
        let mut pieces = Vec::with_capacity(commands.len());
        let mut extended = Vec::new();
        for (index, c) in commands.iter().enumerate() {
            if (index as u64).is_multiple_of(POLL_EVERY_SAMPLES) {
                poll()?;
            }
            let cmd = [
                c.euler_ypr[0],
                c.euler_ypr[1],
                c.euler_ypr[2],
                c.vel_b[0],
                c.vel_b[1],
                c.vel_b[2],
            ];
            let mut duration = c.duration_s;
            let channels: [Channel; 6] = std::array::from_fn(|k| {
                if c.kind == CommandKind::Rates {
                    return Channel::Linear {
                        x0: x[k],
                        rate: cmd[k],
                    };
                }
                let angle = k < 3;
                let relative = if angle {
                    c.kind.att_relative()
                } else {
                    c.kind.vel_relative()
                };
                let delta = if relative { cmd[k] } else { cmd[k] - x[k] };
                let t_c = if angle {
                    reach_time(
                        delta,
                        limits.max_angular_rate_rps,
                        limits.max_angular_accel_rps2,
                    )
                } else {
                    reach_time(delta, f64::INFINITY, limits.max_accel_mps2)
                };
                if t_c == 0.0 {
                    Channel::Linear {
                        x0: x[k],
                        rate: 0.0,
                    }
                } else {
                    Channel::Smooth {
                        x0: x[k],
                        delta,
                        t_c,
                    }
                }
            });
            let need = channels
                .iter()
                .filter_map(Channel::inner_break)
                .fold(0.0, f64::max);
            if need > duration {
                let n = (need / dt_s * (1.0 - 1e-12)).ceil().max(1.0);
                let used = n * dt_s;
                extended.push(Extension {
                    index,
                    given_s: duration,
                    used_s: used,
                });
                duration = used;
            }
            for k in 0..6 {
                x[k] = channels[k].end_value(duration);
            }
            let n = (duration / dt_s).round();
            whole &= (n * dt_s - duration).abs() <= 1e-9 * duration;
            let t0_s = if whole { n_sum * dt_s } else { t };
            pieces.push(Piece {
                t0_s,
                duration_s: duration,
                channels,
            });
            t = t0_s + duration;
            n_sum += n;
            if whole {
                t = n_sum * dt_s;
            }
        }
        Ok(Self {
            pieces,
            duration_s: t,
            limits,
            extended,
        })
    }

    /// The compiled pieces (one per command).
    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// Times inside the motion where a channel changes form: the command starts after the
    /// first, and each smooth step's end `t0 + T_c` inside its command.
    pub fn breaks(&self) -> Vec<f64> {
        let mut b = Vec::new();
        for (i, p) in self.pieces.iter().enumerate() {
            if i > 0 {
                b.push(p.t0_s);
            }
            for c in &p.channels {
                if let Some(tc) = c.inner_break() {
                    if tc < p.duration_s {
                        b.push(p.t0_s + tc);
                    }
                }
            }
        }
        b
    }

    /// Highest "frequency" of the smooth steps, 2π/T_c \[rad/s\] (for the truth resolution).
    pub fn max_frequency_rps(&self) -> f64 {
        self.pieces
            .iter()
            .flat_map(|p| p.channels.iter())
            .filter_map(Channel::inner_break)
            .map(|tc| 2.0 * PI / tc)
            .fold(0.0, f64::max)
    }

    /// Index of the piece whose branch `t_sel` selects.
    pub fn piece_at(&self, t_sel: f64) -> usize {
        self.pieces
            .partition_point(|p| p.t0_s <= t_sel)
            .saturating_sub(1)
    }

    /// Channel values at `t` on the branch of `t_sel`.
    pub fn state(&self, t: f64, t_sel: f64) -> BodyState {
        let Some(p) = self.pieces.get(self.piece_at(t_sel)) else {
            return BodyState {
                euler_ypr: [0.0; 3],
                euler_rate_ypr: [0.0; 3],
                euler_accel_ypr: [0.0; 3],
                vel_b: Vec3::zeros(),
                vel_dot_b: Vec3::zeros(),
            };
        };
        let tau = t - p.t0_s;
        let e = p.channels.map(|c| c.eval(tau));
        BodyState {
            euler_ypr: [e[0].0, e[1].0, e[2].0],
            euler_rate_ypr: [e[0].1, e[1].1, e[2].1],
            euler_accel_ypr: [e[0].2, e[1].2, e[2].2],
            vel_b: Vec3::new(e[3].0, e[4].0, e[5].0),
            vel_dot_b: Vec3::new(e[3].1, e[4].1, e[5].1),
        }
    }

    /// `(v^n, v̇^n, C_b^n, ω_nb^b)` at `t` on the branch of `t_sel` (module docs).
    pub fn kinematics(&self, t: f64, t_sel: f64) -> (Vec3, Vec3, Mat3, Vec3) {
        let s = self.state(t, t_sel);
        let [psi, theta, phi] = s.euler_ypr;
        let [dpsi, dtheta, dphi] = s.euler_rate_ypr;
        let (sf, cf) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let c = c_b_n_from_sin_cos((sf, cf), (st, ct), psi.sin_cos());
        let w = Vec3::new(
            dphi - dpsi * st,
            dtheta * cf + dpsi * ct * sf,
            -dtheta * sf + dpsi * ct * cf,
        );
        let v = c * s.vel_b;
        let v_dot = c * (s.vel_dot_b + w.cross(&s.vel_b));
        (v, v_dot, c, w)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn smooth_step_meets_its_limits_and_holds() {
        let lim = MotionLimits::DEFAULT;
        let cmd = BodyCommand {
            kind: CommandKind::Absolute,
            euler_ypr: [90f64.to_radians(), 0.0, 0.0],
            vel_b: [10.0, 0.0, 0.0],
            duration_s: 100.0,
        };
        let m = BodyMotion::compile(BodyStart::default(), &[cmd], lim, 0.01);
        // yaw: T = max(2·90/2, √(2π·90/0.5)) = max(90, 33.6) s: rate-limited
        let Channel::Smooth { t_c, .. } = m.pieces()[0].channels[0] else {
            panic!()
        };
        assert!((t_c - 90.0).abs() < 1e-12);
        let end = m.state(100.0, 99.0);
        assert_eq!(end.euler_ypr[0], 90f64.to_radians());
        assert_eq!(end.vel_b.x, 10.0);
        assert!(m.extended.is_empty());
    }

    #[test]
    fn short_command_is_extended_to_whole_samples() {
        let cmd = BodyCommand {
            kind: CommandKind::Relative,
            euler_ypr: [90f64.to_radians(), 0.0, 0.0],
            vel_b: [0.0; 3],
            duration_s: 15.0,
        };
        let m = BodyMotion::compile(BodyStart::default(), &[cmd], MotionLimits::DEFAULT, 0.01);
        assert_eq!(m.extended.len(), 1);
        assert!((m.duration_s - 90.0).abs() < 1e-9);
    }
}
