//! The two-state receiver clock model (bias, drift) and its exact discrete form: the numbers
//! a simulator draws from and a tightly coupled filter propagates with.
//!
//! Continuous model (Brown & Hwang, *Introduction to Random Signals and Applied Kalman
//! Filtering*, 4th ed., 2012, §9.3 "GPS receiver clock model"; the section number is as
//! cited by third-party code and was not checked against the book): with the clock bias
//! `b = c·δt_r` \[m\] and drift `d = c·δṫ_r` \[m/s\],
//!
//! ```text
//! ḃ = d + w_f,   ḋ = w_g,   E[w_f w_f] = S_f δ(τ),  E[w_g w_g] = S_g δ(τ)
//! S_f = c² h0/2   (white frequency noise → bias random walk)
//! S_g = c² 2π² h₋₂ (random-walk frequency noise → drift random walk)
//! ```
//!
//! where `h_α` are the coefficients of the one-sided power spectral density of the
//! fractional frequency, `S_y(f) = h0 + h₋₁/f + h₋₂/f²` (the flicker term h₋₁ is left out,
//! as in Brown & Hwang's two-state approximation). Exact discretisation over Δt:
//!
//! ```text
//! Φ = [1 Δt; 0 1]
//! q_bb = S_f Δt + S_g Δt³/3 = c² (h0/2 Δt + 2π² h₋₂ Δt³/3)
//! q_bd = S_g Δt²/2          = c² π² h₋₂ Δt²
//! q_dd = S_g Δt             = c² 2π² h₋₂ Δt
//! ```
//!
//! and the Allan variance of the clock's fractional frequency,
//! `σ_y²(τ) = h0/(2τ) + (2π²/3) h₋₂ τ` (white FM and random-walk FM; e.g. NIST Technical
//! Note 1337, Table 1 of its introduction, or IEEE Std 1139). Because Φ and Q are the exact
//! discretisation, phase samples of the simulated clock have exactly this Allan variance at
//! every τ that is a multiple of the step.

use super::C_MPS;

/// Clock coefficients of the fractional-frequency power spectral density
/// `S_y(f) = h0 + h₋₂/f²` (one-sided), dimensionless h0 \[s\] and h₋₂ \[1/s\] in the usual
/// Allan-variance convention.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClockModel {
    /// white frequency-noise coefficient h0 \[s\]
    pub h0: f64,
    /// random-walk frequency-noise coefficient h₋₂ \[1/s\]
    pub h_minus2: f64,
}

/// Receiver clock state: bias `c·δt_r` and drift `c·δṫ_r`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ClockState {
    /// clock bias c·δt_r \[m\] (pseudorange = range + this + …)
    pub bias_m: f64,
    /// clock drift c·δṫ_r \[m/s\]
    pub drift_mps: f64,
}

/// Discrete process-noise covariance of the clock over one step (symmetric 2×2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClockNoise {
    /// var(bias) \[m²\]
    pub q_bb_m2: f64,
    /// cov(bias, drift) \[m²/s\]
    pub q_bd_m2ps: f64,
    /// var(drift) \[m²/s²\]
    pub q_dd_m2ps2: f64,
}

impl ClockModel {
    /// Temperature-compensated crystal oscillator (TCXO), the default of the raw GNSS
    /// simulator: h0 = 2e-19 s, h₋₂ = 2e-20 /s (Brown & Hwang 4th ed. Table 9.1,
    /// "compensated crystal", there with h₋₁ = 7e-21, left out here; values as cited by
    /// third-party code — navtools' `LOW_QUALITY_TCXO` — not checked against the book).
    pub const TCXO: ClockModel = ClockModel {
        h0: 2e-19,
        h_minus2: 2e-20,
    };
    /// Oven-controlled crystal oscillator (OCXO): h0 = 8e-20 s, h₋₂ = 4e-23 /s (the
    /// "ovenized crystal" row of the same table, as commonly reproduced; not checked
    /// against the book).
    pub const OCXO: ClockModel = ClockModel {
        h0: 8e-20,
        h_minus2: 4e-23,
    };
    /// Rubidium: h0 = 2e-20 s, h₋₂ = 4e-29 /s (the same table's rubidium row, as commonly
    /// reproduced; not checked against the book).
    pub const RUBIDIUM: ClockModel = ClockModel {
        h0: 2e-20,
        h_minus2: 4e-29,
    };

    /// Whether both coefficients are finite and ≥ 0.
    pub fn is_valid(&self) -> bool {
        self.h0.is_finite() && self.h_minus2.is_finite() && self.h0 >= 0.0 && self.h_minus2 >= 0.0
    }

    /// Spectral density of the bias driving noise, `S_f = c² h0/2` \[m²/s\].
    pub fn s_f_m2ps(&self) -> f64 {
        C_MPS * C_MPS * self.h0 / 2.0
    }

    /// Spectral density of the drift driving noise, `S_g = c² 2π² h₋₂` \[m²/s³\].
    pub fn s_g_m2ps3(&self) -> f64 {
        let pi = core::f64::consts::PI;
        C_MPS * C_MPS * 2.0 * pi * pi * self.h_minus2
    }

    /// The discrete process noise over `dt_s` (module equations).
    pub fn noise(&self, dt_s: f64) -> ClockNoise {
        let (sf, sg) = (self.s_f_m2ps(), self.s_g_m2ps3());
        ClockNoise {
            q_bb_m2: sf * dt_s + sg * dt_s * dt_s * dt_s / 3.0,
            q_bd_m2ps: sg * dt_s * dt_s / 2.0,
            q_dd_m2ps2: sg * dt_s,
        }
    }

    /// The deterministic transition `Φ x`: bias += drift·Δt.
    pub fn predict(state: &ClockState, dt_s: f64) -> ClockState {
        ClockState {
            bias_m: state.bias_m + state.drift_mps * dt_s,
            drift_mps: state.drift_mps,
        }
    }

    /// One exact step of the stochastic model: `x' = Φ x + L w` with `L Lᵀ = Q(Δt)` the
    /// lower Cholesky factor and `w` two independent standard normal numbers. A zero
    /// variance gives the deterministic step.
    pub fn step(&self, state: &ClockState, dt_s: f64, w: [f64; 2]) -> ClockState {
        let q = self.noise(dt_s);
        let p = Self::predict(state, dt_s);
        // Q = [a 0; b c] [a b; 0 c]: order (drift, bias) so that a pure random-walk-FM
        // clock (h0 = 0, singular Q) still factors: drift first
        let l11 = libm::sqrt(q.q_dd_m2ps2.max(0.0));
        let (l21, l22) = if l11 > 0.0 {
            let l21 = q.q_bd_m2ps / l11;
            (l21, libm::sqrt((q.q_bb_m2 - l21 * l21).max(0.0)))
        } else {
            (0.0, libm::sqrt(q.q_bb_m2.max(0.0)))
        };
        ClockState {
            bias_m: p.bias_m + l21 * w[0] + l22 * w[1],
            drift_mps: p.drift_mps + l11 * w[0],
        }
    }

    /// Allan variance of the fractional frequency at averaging time τ,
    /// `σ_y²(τ) = h0/(2τ) + (2π²/3) h₋₂ τ`.
    pub fn allan_variance(&self, tau_s: f64) -> f64 {
        let pi = core::f64::consts::PI;
        self.h0 / (2.0 * tau_s) + 2.0 * pi * pi / 3.0 * self.h_minus2 * tau_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_noise_is_the_integral_of_the_continuous_model() {
        // Q = ∫₀^Δt Φ(s) diag(S_f, S_g) Φ(s)ᵀ ds by the midpoint rule on fine steps
        let m = ClockModel::TCXO;
        let dt = 3.0;
        let n = 30_000;
        let (sf, sg) = (m.s_f_m2ps(), m.s_g_m2ps3());
        let (mut bb, mut bd, mut dd) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let s = (k as f64 + 0.5) * dt / n as f64;
            let h = dt / n as f64;
            // Φ(s) = [1 s; 0 1]: Φ G G' Φ' with G = diag
            bb += (sf + s * s * sg) * h;
            bd += s * sg * h;
            dd += sg * h;
        }
        let q = m.noise(dt);
        assert!((q.q_bb_m2 - bb).abs() < 1e-8 * bb, "{} {bb}", q.q_bb_m2);
        assert!((q.q_bd_m2ps - bd).abs() < 1e-8 * bd);
        assert!((q.q_dd_m2ps2 - dd).abs() < 1e-8 * dd);
        // the brief's closed forms
        let c2 = C_MPS * C_MPS;
        let pi2 = core::f64::consts::PI * core::f64::consts::PI;
        assert!(
            (q.q_bb_m2 - c2 * (m.h0 / 2.0 * dt + 2.0 * pi2 * m.h_minus2 * dt * dt * dt / 3.0))
                .abs()
                < 1e-12 * q.q_bb_m2
        );
        assert!((q.q_bd_m2ps - c2 * pi2 * m.h_minus2 * dt * dt).abs() < 1e-12 * q.q_bd_m2ps);
        assert!((q.q_dd_m2ps2 - c2 * 2.0 * pi2 * m.h_minus2 * dt).abs() < 1e-12 * q.q_dd_m2ps2);
    }

    #[test]
    fn the_cholesky_step_reproduces_q() {
        // x' − Φx = L w: E[(Lw)(Lw)ᵀ] = L Lᵀ, from the unit vectors
        for m in [ClockModel::TCXO, ClockModel::OCXO, ClockModel::RUBIDIUM] {
            for dt in [0.01, 1.0, 100.0] {
                let z = ClockState::default();
                let a = m.step(&z, dt, [1.0, 0.0]);
                let b = m.step(&z, dt, [0.0, 1.0]);
                let q = m.noise(dt);
                let bb = a.bias_m * a.bias_m + b.bias_m * b.bias_m;
                let bd = a.bias_m * a.drift_mps + b.bias_m * b.drift_mps;
                let dd = a.drift_mps * a.drift_mps + b.drift_mps * b.drift_mps;
                assert!((bb - q.q_bb_m2).abs() <= 1e-12 * q.q_bb_m2, "{bb} {q:?}");
                assert!((bd - q.q_bd_m2ps).abs() <= 1e-12 * q.q_bd_m2ps.abs().max(1e-300));
                assert!((dd - q.q_dd_m2ps2).abs() <= 1e-12 * q.q_dd_m2ps2);
            }
        }
        // a pure random-walk-FM clock (singular Q) factors too
        let m = ClockModel {
            h0: 0.0,
            h_minus2: 1e-20,
        };
        let s = m.step(&ClockState::default(), 1.0, [1.0, 1.0]);
        assert!(s.bias_m.is_finite() && s.drift_mps > 0.0);
    }

    /// Overlapping Allan variance of phase samples `x` \[s\] taken every `tau0_s`, at
    /// τ = m·τ0: `σ²(τ) = Σ (x_{i+2m} − 2x_{i+m} + x_i)² / (2τ²(N − 2m))`.
    fn avar(x: &[f64], tau0_s: f64, m: usize) -> f64 {
        let n = x.len() - 2 * m;
        let tau = m as f64 * tau0_s;
        let s: f64 = (0..n)
            .map(|i| {
                let d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
                d * d
            })
            .sum();
        s / (2.0 * tau * tau * n as f64)
    }

    /// The simulated clock's phase `x = b/c` has the Allan variance the model states,
    /// `h0/(2τ) + (2π²/3) h₋₂ τ`, at τ on both sides of the crossover (0.87 s for the
    /// TCXO): the mean over 12 independent realisations agrees with the formula within
    /// 4 standard errors of that mean (the spread of the realisations is the estimator's
    /// own confidence; 4 s.e. with 11 dof is a two-sided 0.2 % test), and the standard
    /// error is small enough (< 12 %) that a wrong term would show.
    #[test]
    #[allow(clippy::needless_range_loop)] // `r` is both the stream and the column
    fn allan_variance_of_the_simulated_phase_matches_the_model() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let m = ClockModel::TCXO;
        let dt = 0.01;
        const N: usize = 60_000;
        let taus = [1usize, 10, 100, 1000]; // τ = 0.01, 0.1, 1, 10 s
        let runs = 12;
        let mut est = [[0.0; 12]; 4];
        for r in 0..runs {
            let mut rng = rand_chacha::ChaCha20Rng::seed_from_u64(29);
            rng.set_stream(r as u64);
            let mut s = ClockState::default();
            let mut x = [0.0_f64; N]; // no_std: a fixed array, not a Vec
            for xi in x.iter_mut() {
                let w = [
                    StandardNormal.sample(&mut rng),
                    StandardNormal.sample(&mut rng),
                ];
                s = m.step(&s, dt, w);
                *xi = s.bias_m / C_MPS;
            }
            for (k, &mm) in taus.iter().enumerate() {
                est[k][r] = avar(&x, dt, mm);
            }
        }
        for (k, &mm) in taus.iter().enumerate() {
            let tau = mm as f64 * dt;
            let th = m.allan_variance(tau);
            let mean = est[k].iter().sum::<f64>() / runs as f64;
            let var =
                est[k].iter().map(|e| (e - mean) * (e - mean)).sum::<f64>() / (runs as f64 - 1.0);
            let se = libm::sqrt(var / runs as f64);
            assert!(se < 0.12 * th, "τ = {tau}: s.e. {se} vs {th}");
            assert!(
                libm::fabs(mean - th) < 4.0 * se,
                "τ = {tau} s: Allan variance {mean:.3e} ± {se:.1e}, model {th:.3e}"
            );
        }
    }
}
