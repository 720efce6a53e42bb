//! Overlays on a trajectory's nominal motion: attitude oscillations and rotations (coning,
//! sway, turntable rotations), linear vibration and sculling, random vibration, about body
//! axes ([`Axis`]) within time windows.

use super::*;

/// Body axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// body x (forward, roll axis)
    X,
    /// body y (right, pitch axis)
    Y,
    /// body z (down, yaw axis)
    Z,
}

impl Axis {
    pub(super) fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
    /// Place z-axis-form components `(a, b, c)` (cone about z) for a cone about this axis
    /// (cyclic permutation, docs/theory/coning-sculling.md §"Classical coning and sculling truth").
    pub(super) fn place(self, a: f64, b: f64, c: f64) -> Vec3 {
        match self {
            Axis::Z => Vec3::new(a, b, c),
            Axis::X => Vec3::new(c, a, b),
            Axis::Y => Vec3::new(b, c, a),
        }
    }
}

/// Overlay kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OverlayKind {
    /// classical coning about a body axis, relative form `C_c = C(q_c(0)* ⊗ q_c(τ))`
    /// (docs/theory/coning-sculling.md §"Classical coning and sculling truth"; docs/scenarios.md
    /// §"profile")
    Coning {
        /// cone axis
        axis: Axis,
        /// half-angle α \[rad\]
        half_angle_rad: f64,
        /// angular frequency Ω \[rad/s\]
        omega_rps: f64,
    },
    /// classical sculling: rotation θ0 sin Ωτ about body x, in phase with a specific-force
    /// oscillation A0 sin Ωτ along the nominal body y (docs/theory/coning-sculling.md
    /// §"Classical coning and sculling truth")
    Sculling {
        /// angular amplitude θ0 \[rad\]
        angle_amp_rad: f64,
        /// acceleration amplitude A0 \[m/s²\]
        accel_amp_mps2: f64,
        /// angular frequency Ω \[rad/s\]
        omega_rps: f64,
    },
    /// sinusoidal linear vibration along a nominal body axis: acceleration A cos Ωτ,
    /// velocity (A/Ω) sin Ωτ (zero at the start, bounded displacement)
    Vibration {
        /// axis of the nominal body frame
        axis: Axis,
        /// acceleration amplitude A \[m/s²\]
        accel_amp_mps2: f64,
        /// angular frequency Ω \[rad/s\]
        omega_rps: f64,
    },
    /// angular sway (ship roll/pitch/yaw at its mooring, a rocking car): rotation by
    /// `θ(τ) = A sin(Ωτ + φ)` about a body axis, `C_k = R_axis(θ)`, body rate
    /// `θ̇ = A Ω cos(Ωτ + φ)` about that axis (τ from the overlay start)
    Sway {
        /// axis of the (nominal, after earlier overlays) body frame
        axis: Axis,
        /// angular amplitude A \[rad\]
        amp_rad: f64,
        /// angular frequency Ω \[rad/s\]
        omega_rps: f64,
        /// phase φ \[rad\]
        phase_rad: f64,
    },
    /// turntable step: rotation by `angle_rad` about a body axis over the overlay window
    /// `[start_s, end_s]` (length T) with a raised-cosine rate, `θ(τ) = A·S(x)`,
    /// `S(x) = x − sin(2πx)/(2π)`, `θ̇ = (A/T)(1 − cos 2πx)`, `x = τ/T` (the profile of
    /// [`Motion::TurnSmooth`]; θ̇ and θ̈ vanish at both ends): `C_k = R_axis(θ)`, held at
    /// `R_axis(A)` after the window (docs/theory/calibration.md §1)
    Rotation {
        /// axis of the body frame after the earlier overlays
        axis: Axis,
        /// rotation angle A \[rad\] (positive: right-handed about the axis)
        angle_rad: f64,
        /// `Ω = 2π/T` of the window \[rad/s\] (set by [`OverlayKind::rotation`])
        omega_rps: f64,
    },
    /// random vibration from a PSD ([`crate::truth::random_vibration`]): linear along the nominal
    /// body axes (as [`OverlayKind::Vibration`]), angular as rotations about the body
    /// axes composed `R_x(θ_x) R_y(θ_y) R_z(θ_z)` (as [`OverlayKind::Sway`]); `id` indexes
    /// the realisations given to [`Trajectory::with_random_vibration`]
    RandomVibration {
        /// index into the trajectory's realisations
        id: usize,
    },
}

impl OverlayKind {
    /// The angular frequency Ω of the overlay \[rad/s\].
    pub fn omega_rps(&self) -> f64 {
        match *self {
            OverlayKind::Coning { omega_rps, .. }
            | OverlayKind::Sculling { omega_rps, .. }
            | OverlayKind::Vibration { omega_rps, .. }
            | OverlayKind::Sway { omega_rps, .. }
            | OverlayKind::Rotation { omega_rps, .. } => omega_rps,
            // many frequencies: their phases follow the overlay phases
            OverlayKind::RandomVibration { .. } => 0.0,
        }
    }

    /// A turntable step of `angle_rad` about `axis` over `[start_s, end_s]`
    /// ([`OverlayKind::Rotation`], `Ω = 2π/(end_s − start_s)`), as an overlay.
    pub fn rotation(axis: Axis, angle_rad: f64, start_s: f64, end_s: f64) -> Overlay {
        Overlay {
            kind: OverlayKind::Rotation {
                axis,
                angle_rad,
                omega_rps: 2.0 * PI / (end_s - start_s),
            },
            start_s,
            end_s,
        }
    }
}

/// Rotation matrix `R_axis(θ)` from `(sin θ, cos θ)` (body frame after ← before).
pub(super) fn axis_rotation(axis: Axis, (sa, ca): (f64, f64)) -> Mat3 {
    match axis {
        Axis::X => Mat3::new(1.0, 0.0, 0.0, 0.0, ca, -sa, 0.0, sa, ca),
        Axis::Y => Mat3::new(ca, 0.0, sa, 0.0, 1.0, 0.0, -sa, 0.0, ca),
        Axis::Z => Mat3::new(ca, -sa, 0.0, sa, ca, 0.0, 0.0, 0.0, 1.0),
    }
}

/// `(sin, cos)` of one phase per overlay of a trajectory, for
/// [`Trajectory::kinematics_phased`] (fill with [`Trajectory::phases_at`] or
/// [`Trajectory::phases_offset`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OverlayPhases(pub(super) Vec<(f64, f64)>);

/// `(base, offset)` phases of [`Trajectory::kinematics_phased`]
pub(super) type PhasePair<'a> = (&'a [(f64, f64)], &'a [(f64, f64)]);

/// An overlay active over `[start_s, end_s]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overlay {
    /// kind
    pub kind: OverlayKind,
    /// start time \[s\]
    pub start_s: f64,
    /// end time \[s\] (the overlay state is frozen afterwards)
    pub end_s: f64,
}
