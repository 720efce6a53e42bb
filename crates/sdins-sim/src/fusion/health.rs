//! The health verdict of a fusion run: can the solution be trusted? (bring-your-own-data
//! issue, part 4; exit 3 in the exit-code table of docs/user-guide.md). A run whose
//! filter diverged (its innovations no longer match its covariance, it rejects the
//! measurements, its σ grows without bound, its bias estimates leave their prior) must not
//! read as a success.
//!
//! The checks, each with its false-alarm rate on a consistent filter:
//!
//! * **NIS windows.** The GNSS fixes in order, cut into disjoint windows of [`W_FIXES`]
//!   fixes; **all** fixes count, applied and rejected (the gate truncates the applied ones:
//!   leaving the rejected out would hide a divergence). On a consistent filter the NIS of a
//!   fix with d rows is χ²(d) and the fixes' innovations are independent (the innovation
//!   sequence is white: Groves (2013) §3.4.2, eq. 3.83; Bar-Shalom, Li & Kirubarajan (2001)
//!   §5.4.2), so a window's sum is χ²(D), D the sum of its d. A window fails outside
//!   `[χ²_{α/2}(D), χ²_{1−α/2}(D)]` with `α = 0.01/K` over the K complete windows
//!   (Bonferroni: at most 1 % of consistent runs fail this check). The mean per fix is
//!   reported (W = 60, d = 6, K = 60, an hour of 1 Hz fixes: band [4.46, 7.83]).
//! * **Rejected share.** The gate rejects a consistent fix with probability
//!   [`GATE_FALSE_REJECTION`] (χ²_{0.999}); more than `max(5 %, 10 × 0.1 %)` of the fixes
//!   rejected fails. With n fixes the count is Binomial(n, 1e-3): above 5 % it has
//!   probability below 1e-9 for n ≥ 100. A run where no fix reached the filter fails
//!   here (a free-inertial solution is not an INS/GNSS one).
//! * **Forced updates.** The filter's reset policy applies a fix after a run of rejections
//!   (`forced`); more than one such reset fails (a consistent run of an hour at 1 Hz has
//!   one with probability ~ 3600 × (1e-3)^k, k the policy's run length).
//! * **Horizontal σ.** `√(σ_N² + σ_E²)` of any output row above `max_sigma_h_m` (100 m
//!   unless given) fails: the filter itself says it no longer knows where it is (the check
//!   is on the filter's covariance, so a consistent filter fails it only where the data
//!   leave it without position measurements for that long).
//! * **Bias estimates.** `|b̂ − b̂₀|/σ_prior > 4` for any accelerometer or gyro bias
//!   component, b̂₀ and σ_prior the filter's estimate and σ of that state at the first
//!   output row: an estimate four prior σ out means the model of the sensor is wrong (the
//!   true bias is N(b̂₀, σ_prior²) under the model: probability 6.3e-5 per component,
//!   3.8e-4 for six).
//!
//! Monte Carlo (test `health_false_alarms_on_consistent_runs` and its 200-run release
//! version): consistent runs fail at most at the summed rates above (≈ 1.1 %).

use super::request::{FuseOutput, FuseRow};
use sdins_core::aiding::layout::BlockKind;
use sdins_core::aiding::meas::MeasKind;
use sdins_core::aiding::stationarity::chi2::chi2_quantile;
use serde::Serialize;
use std::cmp::Ordering::{Equal, Less};

/// Fixes per NIS window.
pub const W_FIXES: usize = 60;
/// Family-wise false-alarm rate of the NIS windows.
pub const NIS_ALPHA: f64 = 0.01;
/// The gate's false-rejection rate (χ²_{0.999}).
pub const GATE_FALSE_REJECTION: f64 = 1e-3;
/// Largest rejected share: max(5 %, 10 × the gate's false-rejection rate).
pub const MAX_REJECTED_SHARE: f64 = 0.05;
/// Largest number of forced updates (covariance resets of the reset policy).
pub const MAX_FORCED: u64 = 1;
/// Default largest horizontal σ \[m\].
pub const DEFAULT_MAX_SIGMA_H_M: f64 = 100.0;
/// Largest |b̂ − b̂₀|/σ_prior.
pub const MAX_BIAS_RATIO: f64 = 4.0;

/// One check of the verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HealthCheck {
    /// short name (`nis_windows`, `rejected_share`, `forced_updates`, `sigma_h`, `bias`)
    pub name: &'static str,
    /// passed
    pub passed: bool,
    /// what was found, in words with numbers
    pub detail: String,
}

/// The verdict: every check, passed or not.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct HealthVerdict {
    /// the checks in a fixed order
    pub checks: Vec<HealthCheck>,
}

impl HealthVerdict {
    /// Every check passed.
    pub fn ok(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }
    /// The failed checks' details, one line each.
    pub fn failures(&self) -> Vec<String> {
        self.checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| format!("{}: {}", c.name, c.detail))
            .collect()
    }
}

/// Accumulates what the verdict needs from the observer's stream of a run.
#[derive(Clone, Debug)]
pub struct HealthMonitor {
    max_sigma_h_m: f64,
    /// NIS sum and degrees of freedom of the window being filled, its fix count, start time
    win: (f64, f64, usize, f64),
    /// complete windows: (t_start, t_end, NIS sum, dof sum)
    windows: Vec<(f64, f64, f64, f64)>,
    fixes: u64,
    rejected: u64,
    forced: u64,
    /// largest horizontal σ and its time
    sigma_h: (f64, f64),
    /// the first row's bias estimates and σ of the six bias states (accelerometer, gyro):
    /// the prior N(b̂₀, σ²)
    prior: Option<([f64; 6], [f64; 6])>,
    /// the last row's bias estimates
    last_bias: [f64; 6],
}

impl HealthMonitor {
    /// A monitor with the horizontal-σ limit `max_sigma_h_m` \[m\].
    pub fn new(max_sigma_h_m: f64) -> Self {
        HealthMonitor {
            max_sigma_h_m,
            win: (0.0, 0.0, 0, 0.0),
            windows: Vec::new(),
            fixes: 0,
            rejected: 0,
            forced: 0,
            sigma_h: (0.0, 0.0),
            prior: None,
            last_bias: [0.0; 6],
        }
    }

    /// Feed one output of [`super::request::fuse`] (forward rows and updates count).
    pub fn observe(&mut self, ev: &FuseOutput<'_>) {
        match ev {
            FuseOutput::Update(u) if u.kind == MeasKind::Gnss && !u.late => {
                self.fixes += 1;
                self.rejected += u64::from(!u.accepted);
                self.forced += u64::from(u.forced);
                if u.nis.is_finite() {
                    if self.win.2 == 0 {
                        self.win.3 = u.t_s;
                    }
                    self.win.0 += u.nis;
                    self.win.1 += u.dof as f64;
                    self.win.2 += 1;
                    if self.win.2 == W_FIXES {
                        self.windows
                            .push((self.win.3, u.t_s, self.win.0, self.win.1));
                        self.win = (0.0, 0.0, 0, 0.0);
                    }
                }
            }
            FuseOutput::Forward(row) => {
                let (t, sigma_ne, bias, sigma_bias) = match row {
                    FuseRow::Files(p, _) => {
                        let mut b = [0.0; 6];
                        for i in 0..3 {
                            b[i] = p.bias.0[i];
                            b[i + 3] = p.bias.1[i];
                        }
                        (p.t_s, [p.sigma_nav[0], p.sigma_nav[1]], b, p.sigma_bias)
                    }
                    FuseRow::Scenario(e) => {
                        let pos = e.layout.offset(BlockKind::Position).unwrap_or(0);
                        let sd = |i: usize| e.p[(i, i)].max(0.0).sqrt();
                        let ne = [sd(pos) * e.pos_scale[0], sd(pos + 1) * e.pos_scale[1]];
                        let (mut b, mut s) = ([0.0; 6], [0.0; 6]);
                        for (k, kind) in [BlockKind::AccelBias, BlockKind::GyroBias]
                            .into_iter()
                            .enumerate()
                        {
                            if let Some(o) = e.layout.offset(kind) {
                                for i in 0..3 {
                                    b[3 * k + i] = e.est[o + i];
                                    s[3 * k + i] = sd(o + i);
                                }
                            }
                        }
                        (e.t_s, ne, b, s)
                    }
                };
                let h = sigma_ne[0].hypot(sigma_ne[1]);
                if !matches!(h.partial_cmp(&self.sigma_h.0), Some(Less | Equal)) {
                    self.sigma_h = (h, t);
                }
                self.prior.get_or_insert((bias, sigma_bias));
                self.last_bias = bias;
            }
            _ => {}
        }
    }

    /// The verdict over what was observed.
    pub fn verdict(&self) -> HealthVerdict {
        let mut checks = Vec::with_capacity(5);
        // NIS windows
        let k = self.windows.len();
        let alpha = NIS_ALPHA / k.max(1) as f64;
        let mut worst: Option<(f64, f64, f64, f64, f64)> = None;
        let mut failed = 0;
        for &(t0, t1, sum, dof) in &self.windows {
            let lo = chi2_quantile(alpha / 2.0, dof).unwrap_or(0.0);
            let hi = chi2_quantile(1.0 - alpha / 2.0, dof).unwrap_or(f64::INFINITY);
            if !(lo..=hi).contains(&sum) {
                failed += 1;
                let n = W_FIXES as f64;
                worst.get_or_insert((t0, t1, sum / n, lo / n, hi / n));
            }
        }
        checks.push(HealthCheck {
            name: "nis_windows",
            passed: failed == 0,
            detail: match worst {
                None if k == 0 => format!(
                    "fewer than {W_FIXES} fixes: no NIS window to test"
                ),
                None => format!(
                    "{k} windows of {W_FIXES} fixes, all inside their χ² bands (family-wise α {NIS_ALPHA})"
                ),
                Some((t0, t1, m, lo, hi)) => format!(
                    "{failed} of {k} windows of {W_FIXES} fixes outside their χ² band; the first, {t0:.1}–{t1:.1} s: mean NIS per fix {m:.2}, band [{lo:.2}, {hi:.2}] (family-wise α {NIS_ALPHA})"
                ),
            },
        });
        let share = if self.fixes == 0 {
            1.0
        } else {
            self.rejected as f64 / self.fixes as f64
        };
        checks.push(HealthCheck {
            name: "rejected_share",
            passed: share <= MAX_REJECTED_SHARE,
            detail: if self.fixes == 0 {
                "no GNSS fix reached the filter: the solution is free inertial".to_string()
            } else {
                format!(
                    "{} of {} fixes rejected by the gate ({:.1} %, limit {:.0} %)",
                    self.rejected,
                    self.fixes,
                    100.0 * share,
                    100.0 * MAX_REJECTED_SHARE
                )
            },
        });
        checks.push(HealthCheck {
            name: "forced_updates",
            passed: self.forced <= MAX_FORCED,
            detail: format!(
                "{} fixes applied by the reset policy after consecutive rejections (limit {MAX_FORCED})",
                self.forced
            ),
        });
        checks.push(HealthCheck {
            name: "sigma_h",
            passed: self.sigma_h.0 <= self.max_sigma_h_m,
            detail: format!(
                "largest horizontal σ {:.3} m at {:.1} s (limit {} m)",
                self.sigma_h.0, self.sigma_h.1, self.max_sigma_h_m
            ),
        });
        const NAMES: [&str; 6] = [
            "accel x", "accel y", "accel z", "gyro x", "gyro y", "gyro z",
        ];
        let mut worst = (0.0_f64, 0usize);
        if let Some((b0, prior)) = self.prior {
            for i in 0..6 {
                if prior[i] > 0.0 {
                    let r = (self.last_bias[i] - b0[i]).abs() / prior[i];
                    if !matches!(r.partial_cmp(&worst.0), Some(Less | Equal)) {
                        worst = (r, i);
                    }
                }
            }
        }
        checks.push(HealthCheck {
            name: "bias",
            passed: worst.0 <= MAX_BIAS_RATIO,
            detail: format!(
                "largest |bias estimate − prior mean| / prior σ {:.2} ({} bias; limit {MAX_BIAS_RATIO})",
                worst.0, NAMES[worst.1]
            ),
        });
        HealthVerdict { checks }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn update(nis: f64, accepted: bool, forced: bool) -> sdins_core::aiding::ekf::UpdateReport {
        sdins_core::aiding::ekf::UpdateReport {
            t_s: 0.0,
            t_valid_s: 0.0,
            kind: MeasKind::Gnss,
            dof: 6,
            innovation: [0.0; sdins_core::aiding::linalg::MAX_ROWS],
            sigma: [1.0; sdins_core::aiding::linalg::MAX_ROWS],
            nis,
            accepted,
            forced,
            late: false,
        }
    }

    /// No fix at all fails; 60 fixes of NIS 6 (the mean) pass every GNSS check; a burst
    /// of far-off fixes (NIS 100, rejected, then forced) fails the window, the rejected
    /// share and the forced updates.
    #[test]
    fn verdicts_on_constructed_streams() {
        let m = HealthMonitor::new(DEFAULT_MAX_SIGMA_H_M);
        let v = m.verdict();
        assert!(!v.ok());
        assert!(
            v.failures()[0].contains("no GNSS fix"),
            "{:?}",
            v.failures()
        );

        let mut m = HealthMonitor::new(DEFAULT_MAX_SIGMA_H_M);
        for _ in 0..60 {
            m.observe(&FuseOutput::Update(&update(6.0, true, false)));
        }
        assert!(m.verdict().ok(), "{:?}", m.verdict().failures());

        let mut m = HealthMonitor::new(DEFAULT_MAX_SIGMA_H_M);
        for k in 0..60 {
            let far = (20..30).contains(&k);
            m.observe(&FuseOutput::Update(&update(
                if far { 100.0 } else { 6.0 },
                !far || k % 5 == 4,
                far && k % 5 == 4,
            )));
        }
        let names: Vec<&str> = m
            .verdict()
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.name)
            .collect();
        assert_eq!(names, ["nis_windows", "rejected_share", "forced_updates"]);
    }

    /// The band of the module docs: W = 60, d = 6, K = 60 (an hour of 1 Hz fixes).
    #[test]
    fn nis_band_of_the_docs() {
        let alpha = NIS_ALPHA / 60.0;
        let lo = chi2_quantile(alpha / 2.0, 360.0).unwrap() / 60.0;
        let hi = chi2_quantile(1.0 - alpha / 2.0, 360.0).unwrap() / 60.0;
        assert!(
            (lo - 4.46).abs() < 0.01 && (hi - 7.83).abs() < 0.01,
            "{lo} {hi}"
        );
    }
}
