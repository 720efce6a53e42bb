//! Navigation mechanizations sharing one trait, [`Mechanization`], so that the simulator,
//! benchmarks and Monte Carlo pick an algorithm by name ([`AlgorithmSpec::from_name`]).
//!
//! * [`LocalLevel`]: local-level NED mechanizations: the Savage baseline (`savage`), the
//!   Song–Lee three-sample algorithm (`songlee`) and our complete version
//!   (`songlee-complete`) (docs/theory/mechanizations.md
//!   §"Song–Lee three-sample local-level algorithm").
//! * [`DualQuatNav`]: Wu's dual-quaternion mechanization (`dualquat`, docs/theory/mechanizations.md
//!   §"Dual quaternion").

mod dual;
mod dualquat;
mod local_level;
mod transport;

pub use dual::DualQuat;
pub use dualquat::DualQuatNav;
pub use local_level::{AttitudeMode, LocalLevel, LocalLevelConfig, RotVector, VelocityMode};
pub use transport::{transport_matrix, transport_matrix_sc, transport_matrix_trig};

use crate::coning::{ConingSet, Increment};
use crate::earth::EarthModel;
use crate::math::{euler_from_c_b_n, Euler, Mat3, Quat, Vec3};

/// Navigation state at one update epoch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NavState {
    /// time since start \[s\]
    pub t_s: f64,
    /// geodetic latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\], wrapped to (−π, π]
    pub lon_rad: f64,
    /// height above the ellipsoid \[m\]
    pub h_m: f64,
    /// velocity over the earth in NED \[m/s\]
    pub v_n_mps: Vec3,
    /// attitude, body to NED
    pub c_b_n: Mat3,
}

impl NavState {
    /// Euler angles of the attitude.
    pub fn euler(&self) -> Euler {
        euler_from_c_b_n(&self.c_b_n)
    }
    /// Attitude quaternion `q_b_n` (w ≥ 0).
    pub fn q_b_n(&self) -> Quat {
        Quat::from_dcm(&self.c_b_n)
    }
}

/// Initial conditions of a navigation run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialState {
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// height \[m\]
    pub h_m: f64,
    /// NED velocity \[m/s\]
    pub v_n_mps: Vec3,
    /// attitude body to NED
    pub c_b_n: Mat3,
}

/// Vertical-channel mode (docs/theory/mechanizations.md §"Earth model").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum VerticalMode {
    /// free inertial vertical channel (what the papers run)
    #[default]
    Free,
    /// height and v_D replaced by a reference every update (see [`Mechanization::hold_vertical`])
    Hold,
}

/// One strapdown mechanization: consumes the N sensor samples of each navigation update.
pub trait Mechanization {
    /// Sensor samples per navigation update (N).
    fn samples_per_update(&self) -> usize;
    /// Advance one navigation update with exactly N samples (fewer or more are a caller
    /// bug; the implementation uses the first N and treats missing ones as zero).
    fn update(&mut self, samples: &[Increment]);
    /// Current navigation state.
    fn state(&self) -> NavState;
    /// Write the current state into `out`: `*out = self.state()`, for loops that hand
    /// every state over into a buffer (implementations may write it without the
    /// intermediate copy).
    #[inline]
    fn state_into(&self, out: &mut NavState) {
        *out = self.state();
    }
    /// Run one update per N samples of `samples` (a trailing partial update is ignored)
    /// and write the state after each into the next slot of `states`; stops when either
    /// runs out and returns the number of updates done. The same states as
    /// [`Mechanization::update`] followed by [`Mechanization::state`], for loops that keep
    /// every state (implementations may dispatch on their options once per call).
    fn update_many(&mut self, samples: &[Increment], states: &mut [NavState]) -> usize {
        let n = self.samples_per_update().max(1);
        let mut k = 0;
        for (chunk, slot) in samples.chunks_exact(n).zip(states.iter_mut()) {
            self.update(chunk);
            self.state_into(slot);
            k += 1;
        }
        k
    }
    /// Replace height and down velocity by a reference (vertical channel `hold`).
    fn hold_vertical(&mut self, h_m: f64, v_d_mps: f64);
    /// Replace position, velocity and attitude by `s` (its `t_s` is ignored), keeping the
    /// time and the previous-sample memory of the coning/sculling corrections: the
    /// closed-loop correction of an aided filter (Groves §14.1.1).
    fn correct_state(&mut self, s: &NavState);
}

/// Which algorithm and options, by the CLI names (`savage`, `songlee`,
/// `songlee-complete`, `dualquat`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlgorithmSpec {
    /// algorithm family
    pub kind: AlgorithmKind,
    /// samples per update N (1..=4)
    pub samples: usize,
    /// coning/sculling coefficient set
    pub coning: ConingSet,
    /// attitude option override (local-level algorithms only)
    pub attitude: Option<AttitudeMode>,
    /// third-order rotation compensation override
    pub rot3: Option<bool>,
    /// rotation-compensation vector override (`Theta` = ½Δθ×Δv, `Phi` = ½Δφ×Δv)
    pub rot_vector: Option<RotVector>,
}

/// Algorithm family.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum AlgorithmKind {
    /// Savage baseline (SAV)
    Savage,
    /// Song–Lee paper mode (SL)
    SongLee,
    /// Song–Lee complete + rot3 (SLC)
    SongLeeComplete,
    /// Wu dual quaternion (DQ)
    DualQuat,
}

impl AlgorithmKind {
    /// Every algorithm, in CLI order.
    pub const ALL: [AlgorithmKind; 4] = [
        AlgorithmKind::Savage,
        AlgorithmKind::SongLee,
        AlgorithmKind::SongLeeComplete,
        AlgorithmKind::DualQuat,
    ];

    /// CLI name.
    pub const fn name(self) -> &'static str {
        match self {
            AlgorithmKind::Savage => "savage",
            AlgorithmKind::SongLee => "songlee",
            AlgorithmKind::SongLeeComplete => "songlee-complete",
            AlgorithmKind::DualQuat => "dualquat",
        }
    }

    /// Parse a CLI name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|k| k.name() == name)
    }
}

impl AlgorithmSpec {
    /// Default options for an algorithm with N samples per update: the polynomial
    /// coefficient set of N (S1's `three_poly` for N = 3).
    pub const fn new(kind: AlgorithmKind, samples: usize) -> Self {
        Self {
            kind,
            samples,
            coning: ConingSet::default_for(samples),
            attitude: None,
            rot3: None,
            rot_vector: None,
        }
    }

    /// Look up by CLI name.
    pub fn from_name(name: &str, samples: usize) -> Option<Self> {
        AlgorithmKind::from_name(name).map(|k| Self::new(k, samples))
    }
}

/// Any mechanization, dispatched statically (no allocation, usable on a flight computer).
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum AnyMechanization {
    /// local-level (SAV, SL, SLC)
    LocalLevel(LocalLevel),
    /// dual quaternion (DQ)
    DualQuat(DualQuatNav),
}

impl AnyMechanization {
    /// Build the mechanization named by `spec`, with sensor period `dt_s` and the given
    /// earth model and initial state.
    pub fn new(spec: &AlgorithmSpec, earth: EarthModel, dt_s: f64, init: &InitialState) -> Self {
        match spec.kind {
            AlgorithmKind::DualQuat => AnyMechanization::DualQuat(DualQuatNav::new(
                earth,
                dt_s,
                spec.samples,
                spec.coning,
                init,
            )),
            kind => {
                let (velocity, attitude, rot3, rotv) = match kind {
                    AlgorithmKind::Savage => (
                        VelocityMode::Savage,
                        AttitudeMode::Savage,
                        false,
                        RotVector::Theta,
                    ),
                    AlgorithmKind::SongLee => (
                        VelocityMode::SongLee,
                        AttitudeMode::Transport,
                        false,
                        RotVector::Phi,
                    ),
                    _ => (
                        VelocityMode::SongLeeComplete,
                        AttitudeMode::Transport,
                        true,
                        RotVector::Phi,
                    ),
                };
                let cfg = LocalLevelConfig {
                    velocity,
                    attitude: spec.attitude.unwrap_or(attitude),
                    coning: spec.coning,
                    samples: spec.samples,
                    rot3: spec.rot3.unwrap_or(rot3),
                    rot_vector: spec.rot_vector.unwrap_or(rotv),
                    midpoint_rates: kind == AlgorithmKind::SongLeeComplete,
                    earth,
                    dt_s,
                };
                AnyMechanization::LocalLevel(LocalLevel::new(cfg, init))
            }
        }
    }
}

impl Mechanization for AnyMechanization {
    #[inline]
    fn samples_per_update(&self) -> usize {
        match self {
            AnyMechanization::LocalLevel(m) => m.samples_per_update(),
            AnyMechanization::DualQuat(m) => m.samples_per_update(),
        }
    }
    #[inline]
    fn update(&mut self, samples: &[Increment]) {
        match self {
            AnyMechanization::LocalLevel(m) => m.update(samples),
            AnyMechanization::DualQuat(m) => m.update(samples),
        }
    }
    #[inline]
    fn state(&self) -> NavState {
        match self {
            AnyMechanization::LocalLevel(m) => m.state(),
            AnyMechanization::DualQuat(m) => m.state(),
        }
    }
    #[inline]
    fn state_into(&self, out: &mut NavState) {
        match self {
            AnyMechanization::LocalLevel(m) => m.state_into(out),
            AnyMechanization::DualQuat(m) => m.state_into(out),
        }
    }
    #[inline]
    fn update_many(&mut self, samples: &[Increment], states: &mut [NavState]) -> usize {
        match self {
            AnyMechanization::LocalLevel(m) => m.update_many(samples, states),
            AnyMechanization::DualQuat(m) => m.update_many(samples, states),
        }
    }
    #[inline]
    fn hold_vertical(&mut self, h_m: f64, v_d_mps: f64) {
        match self {
            AnyMechanization::LocalLevel(m) => m.hold_vertical(h_m, v_d_mps),
            AnyMechanization::DualQuat(m) => m.hold_vertical(h_m, v_d_mps),
        }
    }
    #[inline]
    fn correct_state(&mut self, s: &NavState) {
        match self {
            AnyMechanization::LocalLevel(m) => m.correct_state(s),
            AnyMechanization::DualQuat(m) => m.correct_state(s),
        }
    }
}

/// Wrap a longitude to (−π, π].
///
/// Values already in range are returned unchanged (bit for bit): the `fmod` route would
/// round `(a + π) − π` and cost a library call on every navigation state.
#[inline]
pub fn wrap_pi(a: f64) -> f64 {
    if a > -core::f64::consts::PI && a <= core::f64::consts::PI {
        return a;
    }
    let two_pi = 2.0 * core::f64::consts::PI;
    let mut x = libm::fmod(a + core::f64::consts::PI, two_pi);
    if x <= 0.0 {
        x += two_pi;
    }
    x - core::f64::consts::PI
}
