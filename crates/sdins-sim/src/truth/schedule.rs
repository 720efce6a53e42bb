//! Turntable calibration schedules: static multi-position dwells joined by smooth
//! rotations about body axes (docs/theory/calibration.md §1).
//!
//! A schedule is a list of [`Step`]s, each a rotation of a whole multiple of 90° about a
//! body axis with the raised-cosine rate of [`OverlayKind::Rotation`], every step
//! followed by a dwell. The trajectory is one static segment (the position stays fixed on
//! the earth) with one rotation overlay per step, so that
//! `C_b^n(t) = C_b^n(0)·R_1(θ_1(t))·…·R_k(θ_k(t))` (each rotation about the body axis as
//! the earlier ones left it) and `ω_nb^b` is analytic: the exact truth generator
//! integrates it like every other trajectory.

use crate::truth::trajectory::{Axis, Motion, Overlay, OverlayKind, Trajectory};
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};

/// Default dwell per position \[s\].
pub const DEFAULT_DWELL_S: f64 = 300.0;
/// Default duration of one rotation step \[s\].
pub const DEFAULT_ROTATION_S: f64 = 10.0;

/// One rotation of the schedule: `angle_deg` about body `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// body axis (after the earlier steps)
    pub axis: Axis,
    /// rotation angle \[deg\] (right-handed about the axis)
    pub angle_deg: f64,
}

/// The standard schedules.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Standard {
    /// six positions, each body axis down and up once: from level (z down), x +180°
    /// (z up), y +90° (x down), y +180° (x up), z +90° (y down), z +180° (y up)
    SixPosition,
    /// twelve positions: the six of [`Standard::SixPosition`], each followed by a 180°
    /// flip about the vertical body axis (alternately +180° and −180°), so that every
    /// axis is down and up twice and every axis turns both ways
    TwelvePosition,
}

impl Standard {
    /// Name as written in scenario files (`6-position`, `12-position`).
    pub fn name(self) -> &'static str {
        match self {
            Standard::SixPosition => "6-position",
            Standard::TwelvePosition => "12-position",
        }
    }

    /// Parse a name of [`Standard::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "6-position" => Some(Standard::SixPosition),
            "12-position" => Some(Standard::TwelvePosition),
            _ => None,
        }
    }

    /// The rotation steps after the first dwell (one fewer than the positions).
    pub fn steps(self) -> Vec<Step> {
        let s = |axis, angle_deg| Step { axis, angle_deg };
        match self {
            Standard::SixPosition => vec![
                s(Axis::X, 180.0),
                s(Axis::Y, 90.0),
                s(Axis::Y, 180.0),
                s(Axis::Z, 90.0),
                s(Axis::Z, 180.0),
            ],
            Standard::TwelvePosition => vec![
                s(Axis::Z, 180.0),
                s(Axis::X, 180.0),
                s(Axis::Z, -180.0),
                s(Axis::Y, 90.0),
                s(Axis::X, 180.0),
                s(Axis::Y, 180.0),
                s(Axis::X, -180.0),
                s(Axis::Z, 90.0),
                s(Axis::Y, 180.0),
                s(Axis::Z, 180.0),
                s(Axis::Y, -180.0),
            ],
        }
    }
}

/// Why a schedule cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ScheduleError {
    /// A duration is not finite and positive, or not a whole number of IMU samples.
    #[error("{key}: {what}")]
    Duration {
        /// the key (`dwell_s`, `rotation_s`)
        key: &'static str,
        /// what is wrong
        what: String,
    },
    /// A step's angle is not finite or not a non-zero multiple of 90°.
    #[error(
        "step {index}: angle {angle_deg} deg must be a non-zero multiple of 90 deg within ±720 deg"
    )]
    Angle {
        /// 1-based step index
        index: usize,
        /// the angle given
        angle_deg: f64,
    },
}

/// A time window of the schedule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// start \[s\]
    pub start_s: f64,
    /// end \[s\]
    pub end_s: f64,
}

/// A built schedule: the dwell and rotation windows and the rotation overlays.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// the rotation steps
    pub steps: Vec<Step>,
    /// dwell windows, one per position (`steps.len() + 1`)
    pub dwells: Vec<Window>,
    /// rotation windows, one per step
    pub rotations: Vec<Window>,
    /// total duration \[s\]
    pub duration_s: f64,
}

fn whole_samples(key: &'static str, v: f64, dt_s: f64) -> Result<f64, ScheduleError> {
    if !(v.is_finite() && v > 0.0) {
        return Err(ScheduleError::Duration {
            key,
            what: format!("{v} s must be finite and > 0"),
        });
    }
    let n = (v / dt_s).round();
    if n < 1.0 || (v / dt_s - n).abs() > 1e-6 * n.max(1.0) {
        return Err(ScheduleError::Duration {
            key,
            what: format!("{v} s is not a whole number of IMU samples ({dt_s} s each)"),
        });
    }
    Ok(n * dt_s)
}

impl Schedule {
    /// Build a schedule: a dwell of `dwell_s`, then per step a rotation of `rotation_s`
    /// and a dwell of `dwell_s`. Both durations must be whole numbers of the IMU interval
    /// `dt_s` (so that every window starts on a sample boundary).
    pub fn new(
        steps: &[Step],
        dwell_s: f64,
        rotation_s: f64,
        dt_s: f64,
    ) -> Result<Self, ScheduleError> {
        let dwell = whole_samples("dwell_s", dwell_s, dt_s)?;
        let rot = whole_samples("rotation_s", rotation_s, dt_s)?;
        for (i, s) in steps.iter().enumerate() {
            let q = s.angle_deg / 90.0;
            if !(s.angle_deg.is_finite()
                && s.angle_deg != 0.0
                && s.angle_deg.abs() <= 720.0
                && q == q.round())
            {
                return Err(ScheduleError::Angle {
                    index: i + 1,
                    angle_deg: s.angle_deg,
                });
            }
        }
        let mut dwells = vec![Window {
            start_s: 0.0,
            end_s: dwell,
        }];
        let mut rotations = Vec::with_capacity(steps.len());
        let mut t = dwell;
        for _ in steps {
            rotations.push(Window {
                start_s: t,
                end_s: t + rot,
            });
            t += rot;
            dwells.push(Window {
                start_s: t,
                end_s: t + dwell,
            });
            t += dwell;
        }
        Ok(Self {
            steps: steps.to_vec(),
            dwells,
            rotations,
            duration_s: t,
        })
    }

    /// A standard schedule ([`Standard`]).
    pub fn standard(
        kind: Standard,
        dwell_s: f64,
        rotation_s: f64,
        dt_s: f64,
    ) -> Result<Self, ScheduleError> {
        Self::new(&kind.steps(), dwell_s, rotation_s, dt_s)
    }

    /// The rotation overlays ([`OverlayKind::rotation`]).
    pub fn overlays(&self) -> Vec<Overlay> {
        self.steps
            .iter()
            .zip(&self.rotations)
            .map(|(s, w)| {
                OverlayKind::rotation(s.axis, s.angle_deg.to_radians(), w.start_s, w.end_s)
            })
            .collect()
    }

    /// The trajectory: at rest for the whole schedule, starting at `start_euler`, with
    /// the rotation overlays.
    pub fn trajectory(&self, start_euler: Euler) -> Trajectory {
        Trajectory::new(
            0.0,
            0.0,
            start_euler,
            &[(Motion::Static, self.duration_s)],
            self.overlays(),
        )
    }

    /// Attitude `C_b^n` of every dwell (position) from the start attitude, by composing
    /// the steps' exact rotations (multiples of 90°).
    pub fn dwell_attitudes(&self, start_euler: Euler) -> Vec<Mat3> {
        let mut c = c_b_n_from_euler(&start_euler);
        let mut out = vec![c];
        for s in &self.steps {
            c *= quarter_turns(s.axis, s.angle_deg);
            out.push(c);
        }
        out
    }

    /// For each dwell, the body axis that points down (`"+x"`, `"-z"`, …) when the
    /// schedule starts level, or `"tilted"`.
    pub fn down_axes(&self, start_euler: Euler) -> Vec<&'static str> {
        self.dwell_attitudes(start_euler)
            .iter()
            .map(|c| {
                // body components of the down unit vector: row 2 of C_b^n
                let d = Vec3::new(c[(2, 0)], c[(2, 1)], c[(2, 2)]);
                const NAMES: [[&str; 2]; 3] = [["+x", "-x"], ["+y", "-y"], ["+z", "-z"]];
                (0..3)
                    .find(|&i| (d[i].abs() - 1.0).abs() < 1e-9)
                    .map_or("tilted", |i| NAMES[i][usize::from(d[i] < 0.0)])
            })
            .collect()
    }
}

/// `R_axis(angle)` for a multiple of 90° with exact entries (0, ±1).
fn quarter_turns(axis: Axis, angle_deg: f64) -> Mat3 {
    let q = ((angle_deg / 90.0).round() as i64).rem_euclid(4);
    let (s, c) = [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)][q as usize];
    match axis {
        Axis::X => Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        Axis::Y => Mat3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        Axis::Z => Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn standard_schedules_put_every_axis_down_and_up() {
        let level = Euler::new(0.0, 0.0, 0.0);
        let six = Schedule::standard(Standard::SixPosition, 120.0, 10.0, 0.01).unwrap();
        assert_eq!(
            six.down_axes(level),
            ["+z", "-z", "+x", "-x", "+y", "-y"],
            "6-position"
        );
        assert_eq!(six.duration_s, 6.0 * 120.0 + 5.0 * 10.0);
        let twelve = Schedule::standard(Standard::TwelvePosition, 120.0, 10.0, 0.01).unwrap();
        let d = twelve.down_axes(level);
        assert_eq!(d.len(), 12);
        for a in ["+x", "-x", "+y", "-y", "+z", "-z"] {
            assert_eq!(d.iter().filter(|x| **x == a).count(), 2, "{a}: {d:?}");
        }
        // every axis turns both ways in the 12-position schedule
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            let st = Standard::TwelvePosition.steps();
            let of_axis = st.iter().filter(|s| s.axis == axis);
            assert!(of_axis.clone().any(|s| s.angle_deg > 0.0));
            assert!(of_axis.clone().any(|s| s.angle_deg < 0.0), "{axis:?}");
        }
    }

    #[test]
    fn trajectory_holds_the_dwell_attitudes() {
        // the analytic overlays reach each exact 90°-multiple attitude (to rounding of
        // sin/cos of π/2, π: a few ulp) and are at rest in the dwells
        let e = Euler::new(0.01, -0.02, 0.3);
        let s = Schedule::standard(Standard::TwelvePosition, 20.0, 5.0, 0.01).unwrap();
        let tr = s.trajectory(e);
        for (w, c) in s.dwells.iter().zip(s.dwell_attitudes(e)) {
            let t = 0.5 * (w.start_s + w.end_s);
            let k = tr.kinematics(t, t);
            assert!((k.c_b_n - c).abs().max() < 1e-14, "t = {t}");
            assert_eq!(k.omega_nb_b_rps, Vec3::zeros());
        }
    }

    #[test]
    fn bad_durations_and_angles_are_named() {
        let e = Schedule::standard(Standard::SixPosition, 120.005, 10.0, 0.01).unwrap_err();
        assert!(e.to_string().starts_with("dwell_s:"), "{e}");
        let e = Schedule::standard(Standard::SixPosition, 120.0, -1.0, 0.01).unwrap_err();
        assert!(e.to_string().starts_with("rotation_s:"), "{e}");
        let st = [Step {
            axis: Axis::X,
            angle_deg: 45.0,
        }];
        let e = Schedule::new(&st, 120.0, 10.0, 0.01).unwrap_err();
        assert_eq!(
            e,
            ScheduleError::Angle {
                index: 1,
                angle_deg: 45.0
            }
        );
    }
}
