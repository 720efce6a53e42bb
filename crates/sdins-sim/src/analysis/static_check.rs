//! Is a record static? The one stationarity detector (SHOE, `sdins_core::aiding::stationarity`)
//! run over a record with a noise model taken from the record itself, for the commands whose
//! result assumes a static IMU (Allan variance; static alignment windows) and must say so
//! when the record moves (reliability issue, class 6).
//!
//! The model, with no prior knowledge of the sensor:
//! * white noise per sample: σ_g, σ_a = the largest Allan deviation of the three gyro and the
//!   three accelerometer channels at τ = δt (IEEE Std 952: at the shortest τ the white noise
//!   dominates, σ(δt) = N/√δt, exactly the per-sample σ of the detector);
//! * the rate and specific force expected at rest are the medians, per channel, of the
//!   means of the disjoint windows (bias plus earth rate; g is the norm of the specific
//!   force's), and the residual "bias" σ_b, how far a window's mean may wander from them at
//!   rest, is a robust scale of the spread of those window means: the lower quartile of
//!   their absolute deviation from the median over 0.3186 (the lower quartile of |Z|, Z
//!   normal), largest of the three channels of a type. It holds the white noise of a window
//!   mean, bias instability and rate random walk, and motion in up to three windows in
//!   four does not inflate it (an Allan deviation at τ ≥ W·δt would: a sway at half the
//!   window's frequency is its largest term).
//!
//! Disjoint windows of [`WINDOW`] samples are tested at false-alarm rate [`ALPHA`]: on a
//! static record the expected share of windows declared moving is ≤ α (plus what the record's
//! own wander exceeds the bound), so a share above [`MAX_MOVING_SHARE`] means motion.
//! Motion the record holds at every window (a steady turn at constant speed) cannot be told
//! apart from a static record by any IMU-only test (docs/theory/aiding-sensors.md).

use super::allan::AllanReport;

use sdins_core::aiding::stationarity::{NoiseModel, StationarityDetector};
use sdins_core::coning::Increment;
use sdins_core::math::Vec3;

/// Samples per tested window.
pub const WINDOW: usize = 100;
/// False-alarm rate of each window test.
pub const ALPHA: f64 = 1e-3;
/// Largest share of windows declared moving for a record still called static.
pub const MAX_MOVING_SHARE: f64 = 0.10;

/// The lower quartile of |Z|, Z standard normal (Φ⁻¹(0.625)).
const LOWER_QUARTILE_ABS_NORMAL: f64 = 0.318_639_363_964_375;

/// The `p`-quantile of `v` (nearest rank; sorts `v`).
fn quantile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    let k = ((v.len() as f64 - 1.0) * p).round() as usize;
    v.get(k).copied().unwrap_or(0.0)
}

/// The verdict over one record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticCheck {
    /// disjoint windows tested
    pub windows: u64,
    /// windows declared moving
    pub moving: u64,
}

impl StaticCheck {
    /// Share of the windows declared moving.
    pub fn moving_share(&self) -> f64 {
        if self.windows == 0 {
            0.0
        } else {
            self.moving as f64 / self.windows as f64
        }
    }

    /// A warning for a command that assumes a static record (`what`, e.g. "an Allan
    /// deviation"), or None if the record passes.
    pub fn warning(&self, what: &str) -> Option<String> {
        (self.moving_share() > MAX_MOVING_SHARE).then(|| {
            format!(
                "the record does not look static: {} of {} windows of {WINDOW} samples ({:.1} %) fail the stationarity test (SHOE, false-alarm rate {ALPHA} per window, noise from the record's own Allan deviation); {what} assumes a static IMU",
                self.moving,
                self.windows,
                100.0 * self.moving_share()
            )
        })
    }
}

/// Test the disjoint windows of a record whose Allan report is `allan`. None when the
/// record is shorter than two windows or its noise is degenerate (an ideal record with no
/// noise at all: σ(δt) = 0 in a channel type).
pub fn check(incs: &[Increment], dt_s: f64, allan: &AllanReport) -> Option<StaticCheck> {
    if incs.len() < 2 * WINDOW || allan.curves.len() != 6 {
        return None;
    }
    let first = |r: std::ops::Range<usize>| {
        allan.curves[r]
            .iter()
            .filter_map(|c| c.adev.first().copied())
            .fold(0.0_f64, f64::max)
    };
    // per channel: the means of the disjoint windows, their median, and a robust scale of
    // their spread about it (the lower quartile of |deviation| over 0.3186, the lower
    // quartile of |Z| for Z normal): unaffected by up to three windows in four moving
    let windows = incs.len() / WINDOW;
    let channel = |ch: usize| -> (f64, f64) {
        let mut means: Vec<f64> = (0..windows)
            .map(|w| {
                incs[w * WINDOW..(w + 1) * WINDOW]
                    .iter()
                    .map(|i| {
                        if ch < 3 {
                            i.dtheta_b_rad[ch]
                        } else {
                            i.dv_b_mps[ch - 3]
                        }
                    })
                    .sum::<f64>()
                    / (WINDOW as f64 * dt_s)
            })
            .collect();
        let med = quantile(&mut means, 0.5);
        let mut dev: Vec<f64> = means.iter().map(|m| (m - med).abs()).collect();
        (med, quantile(&mut dev, 0.25) / LOWER_QUARTILE_ABS_NORMAL)
    };
    let ch: Vec<(f64, f64)> = (0..6).map(channel).collect();
    let wander = |r: std::ops::Range<usize>| ch[r].iter().map(|c| c.1).fold(0.0_f64, f64::max);
    let noise = NoiseModel {
        sigma_accel_mps2: first(3..6),
        sigma_gyro_rps: first(0..3),
        sigma_accel_bias_mps2: wander(3..6),
        sigma_gyro_bias_rps: wander(0..3),
    };
    let mean_w = Vec3::new(ch[0].0, ch[1].0, ch[2].0);
    let mean_f = Vec3::new(ch[3].0, ch[4].0, ch[5].0);
    let mut det =
        StationarityDetector::<WINDOW>::from_noise_model(noise, dt_s, mean_f.norm(), ALPHA).ok()?;
    det.set_gyro_bias_rps(&mean_w).ok()?;
    let mut c = StaticCheck {
        windows: 0,
        moving: 0,
    };
    for (k, inc) in incs.iter().enumerate() {
        let report = det.push(inc).ok()?;
        if let Some(r) = report {
            // disjoint windows: the one ending at every WINDOW-th sample
            if (k + 1) % WINDOW == 0 {
                c.windows += 1;
                c.moving += u64::from(!r.stationary);
            }
        }
    }
    Some(c)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::sensors::imu_error::{ImuErrorModel, ImuErrorState};

    /// A static tactical-grade record (gravity, earth rate, the grade's noise and biases)
    /// passes; the same record with a 1 Hz, 0.2 m/s² sway on x in its second half fails
    /// with about half its windows moving.
    #[test]
    fn static_passes_swaying_fails() {
        let dt = 0.01;
        let n = 60_000; // 600 s
        let m = ImuErrorModel::preset("tactical").unwrap();
        let mut s = ImuErrorState::new(&m, 7, 0).unwrap();
        let g = 9.8;
        let w_ie = 7.292115e-5 * 0.6;
        let ideal = |k: usize, sway: bool| {
            let t = k as f64 * dt;
            let a = if sway {
                0.2 * (2.0 * std::f64::consts::PI * t).sin()
            } else {
                0.0
            };
            Increment {
                dtheta_b_rad: Vec3::new(w_ie, 0.0, 0.0) * dt,
                dv_b_mps: Vec3::new(a, 0.0, -g) * dt,
            }
        };
        let still: Vec<Increment> = (0..n).map(|k| s.apply(&ideal(k, false), dt)).collect();
        let rep = super::super::allan::analyse(&still, dt);
        let c = check(&still, dt, &rep).unwrap();
        assert_eq!(c.windows, (n / WINDOW) as u64);
        // at rest: the moving share is a binomial count with p ≤ α (the bias σ bound is
        // conservative); 5 false alarms in 600 windows at α = 1e-3 has probability < 1e-4
        assert!(c.moving <= 5, "{c:?}");
        assert!(c.warning("an Allan deviation").is_none());

        let mut s = ImuErrorState::new(&m, 7, 0).unwrap();
        let half: Vec<Increment> = (0..n).map(|k| s.apply(&ideal(k, k >= n / 2), dt)).collect();
        let rep = super::super::allan::analyse(&half, dt);
        let c = check(&half, dt, &rep).unwrap();
        // the sway is 0.14 m/s² RMS against σ_a ≈ a few mm/s² per sample: every swaying
        // window fails its scatter term
        assert!(c.moving_share() > 0.45, "{c:?}");
        let w = c.warning("an Allan deviation").unwrap();
        assert!(
            w.contains("does not look static") && w.contains("Allan"),
            "{w}"
        );
    }
}
