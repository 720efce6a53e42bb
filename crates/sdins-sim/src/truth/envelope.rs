//! The kinematic envelope: one check of a whole trajectory before any truth is generated.
//!
//! Every trajectory source (scenario files, built-ins, routes, imported motion files,
//! recorded references) passes its [`Trajectory`] and start position through
//! [`check_trajectory`], which walks the trajectory's exact kinematics
//! ([`Trajectory::kinematics`]) over its whole length and refuses it if the speed, the
//! acceleration, the angular rate, the height or the distance from a pole leaves the
//! [`Envelope`], or if any kinematic quantity is not finite. The error names the time, the
//! quantity, its value and limit, and the segment (and active overlays) responsible, so a
//! scenario file can point at the line.
//!
//! ## Sampling and position
//! The kinematics are evaluated at every segment boundary and midpoint and on a uniform grid
//! of step `h = min(1 s, 2π/(16 Ω_max), δt)` (Ω_max the highest frequency of any periodic
//! motion, δt the IMU period), capped at [`MAX_EVALUATIONS`] evaluations (then `h` grows).
//! Sixteen points per period see a sinusoid's peak to within `1 − cos(π/16) = 1.9 %`;
//! constant-rate and linear segments are caught exactly at their ends. Latitude and height are
//! integrated from the NED velocity with the trapezoidal rule (dL/dt = v_N/(R_M + h),
//! dh/dt = −v_D, Groves eq. 5.44), whose error over the grid is far below the limits' scale.
//! Time enters only through `t`, so the check is independent of how the truth is chunked.
//! Random vibration ([`crate::truth::random_vibration`]) is part of the kinematics and so of the
//! check; on the grid its component phases advance by a rotation per step
//! ([`Trajectory::phases_advance`]), which agrees with the direct evaluation to rounding.

use crate::cancel::{CancelToken, Cancelled, POLL_EVERY_SAMPLES};
use crate::truth::trajectory::{OverlayPhases, Trajectory};
use sdins_core::earth::EarthModel;
use std::f64::consts::PI;

/// Upper bound on kinematics evaluations of one check (≈ 0.3 s of work).
pub const MAX_EVALUATIONS: u64 = 4_000_000;

/// The documented limits (docs/scenarios.md, "Kinematic envelope").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Envelope {
    /// largest speed over the earth \[m/s\]
    pub max_speed_mps: f64,
    /// largest magnitude of the NED acceleration dv/dt \[m/s²\]
    pub max_accel_mps2: f64,
    /// largest body angular rate relative to the navigation frame |ω_nb^b| \[rad/s\]
    pub max_rate_rps: f64,
    /// lowest height above the ellipsoid \[m\]
    pub min_h_m: f64,
    /// highest height above the ellipsoid \[m\]
    pub max_h_m: f64,
    /// largest |latitude| \[rad\]: the local-level NED mechanization is singular at the poles
    /// (tan L, 1/cos L in the transport rate)
    pub max_abs_lat_rad: f64,
}

impl Envelope {
    /// The default envelope: 3000 m/s, 100 g, 3600 °/s, −1000 … 100 000 m, |L| ≤ 89.99°.
    pub const DEFAULT: Envelope = Envelope {
        max_speed_mps: 3000.0,
        max_accel_mps2: 100.0 * 9.806_65,
        max_rate_rps: 3600.0 * PI / 180.0,
        min_h_m: -1000.0,
        max_h_m: 100_000.0,
        max_abs_lat_rad: 89.99 * PI / 180.0,
    };
}

impl Default for Envelope {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The quantity that left the envelope.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Quantity {
    /// speed \[m/s\]
    Speed,
    /// acceleration \[m/s²\]
    Acceleration,
    /// angular rate \[°/s\]
    AngularRate,
    /// height \[m\]
    Height,
    /// latitude \[°\]
    Latitude,
    /// a kinematic value is NaN or infinite
    NotFinite,
}

impl Quantity {
    fn describe(self) -> &'static str {
        match self {
            Quantity::Speed => "speed",
            Quantity::Acceleration => "acceleration",
            Quantity::AngularRate => "angular rate",
            Quantity::Height => "height",
            Quantity::Latitude => "latitude",
            Quantity::NotFinite => "kinematics",
        }
    }
}

/// Why a trajectory was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EnvelopeError {
    /// A quantity leaves the envelope at `t_s`.
    #[error("{} {} at t = {t_s} s{} is outside the kinematic envelope ({limit})", .quantity.describe(), fmt_value(.quantity, *.value), where_text(.segment, .overlays))]
    Outside {
        /// which quantity
        quantity: Quantity,
        /// its value, in the unit of [`Quantity`]
        value: f64,
        /// the limit, as text with unit
        limit: String,
        /// time \[s\]
        t_s: f64,
        /// index of the segment the time falls in
        segment: Option<usize>,
        /// indices of the overlays active at that time
        overlays: Vec<usize>,
    },
    /// Stopped through the cancellation token.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
    /// The trajectory has no samples at the IMU rate.
    #[error("the trajectory lasts {duration_s} s, less than one IMU sample of {dt_s} s")]
    NoSamples {
        /// duration \[s\]
        duration_s: f64,
        /// sample interval \[s\]
        dt_s: f64,
    },
}

impl EnvelopeError {
    /// The segment index the violation falls in, if any.
    pub fn segment(&self) -> Option<usize> {
        match self {
            EnvelopeError::Outside { segment, .. } => *segment,
            EnvelopeError::NoSamples { .. } | EnvelopeError::Cancelled(_) => None,
        }
    }
}

fn fmt_value(q: &Quantity, v: f64) -> String {
    match q {
        Quantity::Speed => format!("{v:.6e} m/s"),
        Quantity::Acceleration => format!("{v:.6e} m/s²"),
        Quantity::AngularRate => format!("{v:.6e} deg/s"),
        Quantity::Height => format!("{v:.1} m"),
        Quantity::Latitude => format!("{v:.6} deg"),
        Quantity::NotFinite => "not finite".to_string(),
    }
}

fn where_text(segment: &Option<usize>, overlays: &[usize]) -> String {
    let mut s = String::new();
    if let Some(k) = segment {
        s += &format!(" (segment {}", k + 1);
        if !overlays.is_empty() {
            let list: Vec<String> = overlays.iter().map(|o| (o + 1).to_string()).collect();
            s += &format!(", overlay {}", list.join(", "));
        }
        s += ")";
    }
    s
}

/// Extremes seen by a successful check (for reports and tests).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnvelopeReport {
    /// largest speed \[m/s\]
    pub max_speed_mps: f64,
    /// largest acceleration \[m/s²\]
    pub max_accel_mps2: f64,
    /// largest angular rate \[rad/s\]
    pub max_rate_rps: f64,
    /// lowest and highest height \[m\]
    pub h_range_m: (f64, f64),
    /// largest |latitude| \[rad\]
    pub max_abs_lat_rad: f64,
    /// kinematics evaluations made
    pub evaluations: u64,
}

/// Start position of the trajectory.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StartPosition {
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// height \[m\]
    pub h_m: f64,
}

/// Check the whole trajectory against `env` (see the module documentation for how).
pub fn check_trajectory(
    traj: &Trajectory,
    start: StartPosition,
    dt_s: f64,
    env: &Envelope,
) -> Result<EnvelopeReport, EnvelopeError> {
    check_trajectory_with(traj, start, dt_s, env, &CancelToken::new())
}

/// [`check_trajectory`], polling `cancel` every [`POLL_EVERY_SAMPLES`] evaluations
/// ([`EnvelopeError::Cancelled`]). Linear in the number of evaluations and segments.
pub fn check_trajectory_with(
    traj: &Trajectory,
    start: StartPosition,
    dt_s: f64,
    env: &Envelope,
    cancel: &CancelToken,
) -> Result<EnvelopeReport, EnvelopeError> {
    let dur = traj.duration_s;
    if !(dur.is_finite() && dt_s.is_finite() && dt_s > 0.0) || dur < dt_s * (1.0 - 1e-9) {
        return Err(EnvelopeError::NoSamples {
            duration_s: dur,
            dt_s,
        });
    }
    let w_max = traj.max_frequency_rps();
    let mut h = 1.0_f64.min(dt_s);
    if w_max > 0.0 {
        h = h.min(2.0 * PI / (16.0 * w_max));
    }
    let n_grid = ((dur / h).ceil() as u64).clamp(1, MAX_EVALUATIONS);
    let h = dur / n_grid as f64;
    // grid times plus the segment boundaries (both branches) and midpoints
    let mut extra: Vec<(f64, f64)> = Vec::new();
    for s in traj.segments() {
        let (a, b) = (s.t0_s, s.t0_s + s.duration_s);
        extra.push((a, a));
        extra.push((0.5 * (a + b), 0.5 * (a + b)));
        // the end of the segment on its own branch
        extra.push((b, b - 0.25 * s.duration_s.min(dt_s)));
    }
    let earth = EarthModel::WGS84;
    let mut rep = EnvelopeReport {
        h_range_m: (start.h_m, start.h_m),
        max_abs_lat_rad: start.lat_rad.abs(),
        ..EnvelopeReport::default()
    };
    let overlays_at = |t: f64| -> Vec<usize> {
        traj.overlays()
            .iter()
            .enumerate()
            .filter(|(_, o)| t >= o.start_s && t < o.end_s)
            .map(|(i, _)| i)
            .collect()
    };
    let fail = |q: Quantity, value: f64, limit: String, t: f64| EnvelopeError::Outside {
        quantity: q,
        value,
        limit,
        t_s: t,
        segment: traj.segment_at(t),
        overlays: overlays_at(t),
    };
    // random vibration: thousands of components, whose phases on the grid advance by one
    // rotation per step instead of a sin/cos each (Trajectory::phases_advance)
    let phased = !traj.random_vibrations().is_empty();
    let mut ph = OverlayPhases::default();
    let mut ph_next = OverlayPhases::default();
    let mut ph_step = OverlayPhases::default();
    let mut ph_zero = OverlayPhases::default();
    if phased {
        traj.phases_at(0.0, &mut ph);
        traj.phases_offset(h, &mut ph_step);
        traj.phases_offset(0.0, &mut ph_zero);
    }
    let check_point = |t: f64,
                       t_sel: f64,
                       phases: Option<(&OverlayPhases, &OverlayPhases)>,
                       rep: &mut EnvelopeReport| {
        let k = match phases {
            Some((b, z)) => traj.kinematics_phased(t, 0.0, t_sel, b, z),
            None => traj.kinematics(t, t_sel),
        };
        rep.evaluations += 1;
        let finite = k.v_n_mps.iter().all(|x| x.is_finite())
            && k.v_dot_n_mps2.iter().all(|x| x.is_finite())
            && k.omega_nb_b_rps.iter().all(|x| x.is_finite())
            && k.c_b_n.iter().all(|x| x.is_finite());
        if !finite {
            return Err(fail(
                Quantity::NotFinite,
                f64::NAN,
                "finite values".into(),
                t_sel,
            ));
        }
        let speed = k.v_n_mps.norm();
        let accel = k.v_dot_n_mps2.norm();
        let rate = k.omega_nb_b_rps.norm();
        rep.max_speed_mps = rep.max_speed_mps.max(speed);
        rep.max_accel_mps2 = rep.max_accel_mps2.max(accel);
        rep.max_rate_rps = rep.max_rate_rps.max(rate);
        if speed > env.max_speed_mps {
            return Err(fail(
                Quantity::Speed,
                speed,
                format!("at most {} m/s", env.max_speed_mps),
                t_sel,
            ));
        }
        if rate > env.max_rate_rps {
            return Err(fail(
                Quantity::AngularRate,
                rate.to_degrees(),
                format!("at most {:.0} deg/s", env.max_rate_rps.to_degrees()),
                t_sel,
            ));
        }
        if accel > env.max_accel_mps2 {
            return Err(fail(
                Quantity::Acceleration,
                accel,
                format!("at most {:.1} m/s²", env.max_accel_mps2),
                t_sel,
            ));
        }
        Ok(k.v_n_mps)
    };
    for (i, &(t, t_sel)) in extra.iter().enumerate() {
        if (i as u64).is_multiple_of(POLL_EVERY_SAMPLES) {
            cancel.check()?;
        }
        check_point(t, t_sel, None, &mut rep)?;
    }
    // grid with position integration
    let (mut lat, mut hgt) = (start.lat_rad, start.h_m);
    let mut v_prev = check_point(0.0, 0.0, None, &mut rep)?;
    for i in 1..=n_grid {
        if i.is_multiple_of(POLL_EVERY_SAMPLES) {
            cancel.check()?;
        }
        let t = if i == n_grid { dur } else { i as f64 * h };
        // the last point belongs to the last segment's branch
        let t_sel = if i == n_grid { t - 0.5 * h } else { t };
        let phases = if phased && i < n_grid {
            traj.phases_advance(&ph, &ph_step, t, &mut ph_next);
            std::mem::swap(&mut ph, &mut ph_next);
            Some((&ph, &ph_zero))
        } else {
            None
        };
        let v = check_point(t, t_sel, phases, &mut rep)?;
        let r_m = earth.radii(lat).r_m_m;
        lat += 0.5 * h * (v_prev.x + v.x) / (r_m + hgt);
        hgt -= 0.5 * h * (v_prev.z + v.z);
        v_prev = v;
        rep.max_abs_lat_rad = rep.max_abs_lat_rad.max(lat.abs());
        rep.h_range_m = (rep.h_range_m.0.min(hgt), rep.h_range_m.1.max(hgt));
        if !(lat.is_finite() && hgt.is_finite()) {
            return Err(fail(
                Quantity::NotFinite,
                f64::NAN,
                "finite position".into(),
                t,
            ));
        }
        if lat.abs() > env.max_abs_lat_rad {
            return Err(fail(
                Quantity::Latitude,
                lat.to_degrees(),
                format!(
                    "|latitude| at most {:.2} deg: the NED mechanization is singular at the poles",
                    env.max_abs_lat_rad.to_degrees()
                ),
                t,
            ));
        }
        if hgt < env.min_h_m || hgt > env.max_h_m {
            return Err(fail(
                Quantity::Height,
                hgt,
                format!("height in [{}, {}] m", env.min_h_m, env.max_h_m),
                t,
            ));
        }
    }
    Ok(rep)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::truth::trajectory::Motion;
    use sdins_core::math::Euler;

    fn start() -> StartPosition {
        StartPosition {
            lat_rad: 0.5,
            h_m: 100.0,
        }
    }

    fn traj(speed: f64, climb: f64, motions: &[(Motion, f64)]) -> Trajectory {
        Trajectory::new(speed, -climb, Euler::new(0.0, 0.0, 0.0), motions, vec![])
    }

    #[test]
    fn limits_are_met_by_a_plain_cruise() {
        let t = traj(200.0, 0.0, &[(Motion::Cruise, 600.0)]);
        let r = check_trajectory(&t, start(), 0.01, &Envelope::DEFAULT).unwrap();
        assert!((r.max_speed_mps - 200.0).abs() < 1e-9);
        // 600 s north at 200 m/s: 120 km of latitude change ≈ 1.08°
        assert!(
            (r.max_abs_lat_rad - 0.5 - 120e3 / 6.36e6).abs() < 2e-4,
            "{r:?}"
        );
    }

    #[test]
    fn each_quantity_is_caught() {
        let e = Envelope::DEFAULT;
        let cases: Vec<(Trajectory, StartPosition, Quantity)> = vec![
            (
                traj(10.0, 0.0, &[(Motion::TurnRate { rate_rps: 1e300 }, 1.0)]),
                start(),
                Quantity::AngularRate,
            ),
            (
                traj(
                    0.0,
                    0.0,
                    &[(Motion::Accelerate { accel_mps2: 50.0 }, 100.0)],
                ),
                start(),
                Quantity::Speed,
            ),
            (
                traj(
                    0.0,
                    0.0,
                    &[(Motion::Accelerate { accel_mps2: 2000.0 }, 1.0)],
                ),
                start(),
                Quantity::Acceleration,
            ),
            (
                traj(
                    100.0,
                    0.0,
                    &[(
                        Motion::Climb {
                            to_climb_rate_mps: -50.0,
                        },
                        300.0,
                    )],
                ),
                start(),
                Quantity::Height,
            ),
            (
                traj(100.0, 0.0, &[(Motion::Cruise, 3600.0)]),
                StartPosition {
                    lat_rad: 89.9_f64.to_radians(),
                    h_m: 0.0,
                },
                Quantity::Latitude,
            ),
        ];
        for (i, (t, s, q)) in cases.into_iter().enumerate() {
            match check_trajectory(&t, s, 0.01, &e) {
                Err(EnvelopeError::Outside {
                    quantity, segment, ..
                }) => {
                    assert_eq!(quantity, q, "case {i}");
                    assert_eq!(segment, Some(0), "case {i}");
                }
                other => panic!("case {i}: {other:?}"),
            }
        }
    }

    #[test]
    fn too_short_is_refused() {
        let t = traj(0.0, 0.0, &[(Motion::Static, 0.001)]);
        assert!(matches!(
            check_trajectory(&t, start(), 0.01, &Envelope::DEFAULT),
            Err(EnvelopeError::NoSamples { .. })
        ));
    }
}
