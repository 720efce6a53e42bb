//! The stateful, reproducible corruption of an increment stream.

use super::{
    ImuErrorModel, ImuErrorModelError, ARCSEC, DPH, DPHPSH, DPSH, G0, MPS_PER_SQRT_H, MRAD, PPM,
    UG, UG_PER_SQRT_H, UG_PER_SQRT_HZ,
};
use nalgebra::Matrix3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rand_distr::StandardNormal;
use sdins_core::coning::Increment;
use sdins_core::Vec3;

/// IEEE Std 952 flicker floor factor: σ_min = B·√(2 ln 2/π) ≈ 0.664·B.
pub const FLICKER_FLOOR: f64 = 0.664_282_688_505_452_4;

/// Spacing factor of the flicker Gauss–Markov correlation times.
const FLICKER_SPACING: f64 = 3.0;

/// First-order Gauss–Markov process with its cached discretization.
#[derive(Clone, Debug)]
struct GaussMarkov {
    sigma: f64,
    tau_s: f64,
    x: f64,
    dt_cached: f64,
    phi: f64,
    q: f64,
}

impl GaussMarkov {
    fn new(sigma: f64, tau_s: f64, rng: &mut ChaCha20Rng) -> Self {
        let w: f64 = rng.sample(StandardNormal);
        Self {
            sigma,
            tau_s,
            x: sigma * w,
            dt_cached: f64::NAN,
            phi: 0.0,
            q: 0.0,
        }
    }
    /// Current value, then advance one step of `dt_s`.
    fn step(&mut self, dt_s: f64, rng: &mut ChaCha20Rng) -> f64 {
        if dt_s != self.dt_cached {
            self.phi = (-dt_s / self.tau_s).exp();
            self.q = self.sigma * (1.0 - self.phi * self.phi).max(0.0).sqrt();
            self.dt_cached = dt_s;
        }
        let out = self.x;
        let w: f64 = rng.sample(StandardNormal);
        self.x = self.phi * self.x + self.q * w;
        out
    }
}

/// Allan variance of a unit-σ first-order Gauss–Markov process with correlation time
/// `t`: `AVAR(τ) = (2T/τ)·[1 − (T/2τ)(3 − 4e^(−τ/T) + e^(−2τ/T))]` (series for small τ/T).
pub(crate) fn gm_avar_unit(tau: f64, t: f64) -> f64 {
    let x = tau / t;
    let bracket = if x < 1e-3 {
        x * x / 3.0 - x * x * x / 4.0 + 7.0 * x.powi(4) / 60.0
    } else {
        1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x)
    };
    2.0 * t / tau * bracket
}

/// Correlation times and the common σ (per unit B) of the flicker approximation.
pub(crate) fn flicker_terms(lo: f64, hi: f64) -> (Vec<f64>, f64) {
    let n = ((hi / lo).ln() / FLICKER_SPACING.ln() - 1e-9)
        .ceil()
        .max(0.0) as usize
        + 1;
    let taus: Vec<f64> = (0..n)
        .map(|k| lo * FLICKER_SPACING.powi(k as i32))
        .collect();
    // log-mean of the unit-σ summed Allan variance over the plateau [4·lo, hi/2]
    // (or the whole range [lo, hi] when it is too short to have a plateau)
    let (a, b) = if 4.0 * lo < 0.5 * hi {
        ((4.0 * lo).log10(), (0.5 * hi).log10())
    } else {
        (lo.log10(), hi.log10())
    };
    let steps = ((b - a) * 50.0).ceil().max(1.0) as usize;
    let mut log_sum = 0.0;
    for i in 0..=steps {
        let tau = 10f64.powf(a + (b - a) * i as f64 / steps as f64);
        let s: f64 = taus.iter().map(|&t| gm_avar_unit(tau, t)).sum();
        log_sum += s.ln();
    }
    let max = (log_sum / (steps + 1) as f64).exp();
    let sigma_per_b = if max > 0.0 {
        FLICKER_FLOOR / max.sqrt()
    } else {
        0.0
    };
    (taus, sigma_per_b)
}

/// One sensor channel (one axis of the gyro or accelerometer), SI units
/// (rad/s or m/s²).
#[derive(Clone, Debug)]
struct Channel {
    rng: ChaCha20Rng,
    /// fixed + turn-on bias
    bias: f64,
    /// white noise density (rad/√s or m/s/√s)
    white: f64,
    /// random-walk density (rad/s/√s or m/s²/√s) and state
    rw_density: f64,
    rw: f64,
    gm: Vec<GaussMarkov>,
    scale: f64,
    asym: f64,
    quantum: f64,
    remainder: f64,
    range: f64,
}

/// Parameters of one channel in SI units.
struct ChannelSpec {
    bias: f64,
    turn_on: f64,
    gm_sigma: f64,
    gm_tau: f64,
    flicker_b: f64,
    white: f64,
    rw: f64,
    scale: f64,
    asym: f64,
    quantum: f64,
    range: f64,
}

impl Channel {
    fn new(
        spec: &ChannelSpec,
        flicker: &(Vec<f64>, f64),
        seed: u64,
        run: u64,
        channel: u64,
    ) -> Self {
        let mut rng = ChaCha20Rng::seed_from_u64(seed);
        rng.set_stream(run.wrapping_mul(6).wrapping_add(channel));
        let mut bias = spec.bias;
        if spec.turn_on > 0.0 {
            let w: f64 = rng.sample(StandardNormal);
            bias += spec.turn_on * w;
        }
        let mut gm = Vec::new();
        if spec.gm_sigma > 0.0 {
            gm.push(GaussMarkov::new(spec.gm_sigma, spec.gm_tau, &mut rng));
        }
        if spec.flicker_b > 0.0 {
            for &t in &flicker.0 {
                gm.push(GaussMarkov::new(spec.flicker_b * flicker.1, t, &mut rng));
            }
        }
        Self {
            rng,
            bias,
            white: spec.white,
            rw_density: spec.rw,
            rw: 0.0,
            gm,
            scale: spec.scale,
            asym: spec.asym,
            quantum: spec.quantum,
            remainder: 0.0,
            range: spec.range,
        }
    }

    /// Additive error of this sample (bias terms + white noise) \[rad/s or m/s²\].
    fn additive(&mut self, dt_s: f64) -> f64 {
        let mut e = self.bias;
        if self.white > 0.0 {
            let w: f64 = self.rng.sample(StandardNormal);
            e += self.white / dt_s.sqrt() * w;
        }
        for g in &mut self.gm {
            e += g.step(dt_s, &mut self.rng);
        }
        if self.rw_density > 0.0 {
            e += self.rw;
            let w: f64 = self.rng.sample(StandardNormal);
            self.rw += self.rw_density * dt_s.sqrt() * w;
        }
        e
    }

    /// Scale factor (with asymmetry) on the true component `x`.
    fn scaled(&self, x: f64) -> f64 {
        let sgn = if x > 0.0 {
            1.0
        } else if x < 0.0 {
            -1.0
        } else {
            0.0
        };
        x * (1.0 + self.scale + self.asym * sgn)
    }

    /// Saturate the rate, integrate over `dt_s` and quantize with carried remainder.
    fn output(&mut self, rate: f64, dt_s: f64) -> f64 {
        let inc = rate.clamp(-self.range, self.range) * dt_s;
        if self.quantum > 0.0 {
            self.remainder += inc;
            let pulses = (self.remainder / self.quantum).floor();
            let out = pulses * self.quantum;
            self.remainder -= out;
            out
        } else {
            inc
        }
    }
}

/// Stateful IMU error generator: corrupts a stream of exact increments sample by
/// sample (see the [module documentation](super) for the model).
///
/// Reproducibility: channel c (0–2 gyro x/y/z, 3–5 accel x/y/z) of run `run` draws
/// from its own `ChaCha20Rng::seed_from_u64(seed)` with `set_stream(6·run + c)`, so
/// the output is a pure function of (seed, run, channel, input): it does not depend on
/// threads, chunking or which other runs exist.
#[derive(Clone, Debug)]
pub struct ImuErrorState {
    gyro: [Channel; 3],
    accel: [Channel; 3],
    m_gyro: Matrix3<f64>,
    m_accel: Matrix3<f64>,
    g_sens: Matrix3<f64>,
}

fn mat(m: &[[f64; 3]; 3], unit: f64) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[i][j] * unit)
}

impl ImuErrorState {
    /// Set up run `run` of the model with the master `seed` (validates the model).
    pub fn new(model: &ImuErrorModel, seed: u64, run: u64) -> Result<Self, ImuErrorModelError> {
        model.validate()?;
        let flicker = flicker_terms(model.flicker_tau_s[0], model.flicker_tau_s[1]);
        let m = model;
        let gyro_range = m.gyro_range_dps.map(|r| r.map(|x| x * super::DEG));
        let accel_range = m.accel_range_g.map(|r| r.map(|x| x * G0));
        let gyro: [Channel; 3] = core::array::from_fn(|i| {
            let spec = ChannelSpec {
                bias: m.gyro_bias_dph[i] * DPH,
                turn_on: m.gyro_bias_turn_on_dph[i] * DPH,
                gm_sigma: m.gyro_bias_gm_dph[i] * DPH,
                gm_tau: m.gyro_bias_gm_tau_s[i],
                flicker_b: m.gyro_bias_instability_dph[i] * DPH,
                white: m.gyro_arw_dpsh[i] * DPSH,
                rw: m.gyro_rrw_dphpsh[i] * DPHPSH,
                scale: m.gyro_scale_ppm[i] * PPM,
                asym: m.gyro_scale_asym_ppm[i] * PPM,
                quantum: m.gyro_quantum_arcsec[i] * ARCSEC,
                range: gyro_range.map_or(f64::INFINITY, |r| r[i]),
            };
            Channel::new(&spec, &flicker, seed, run, i as u64)
        });
        let accel: [Channel; 3] = core::array::from_fn(|i| {
            let vrw_a = m.accel_vrw_ugpsqrthz[i] * UG_PER_SQRT_HZ;
            let vrw_b = m.accel_vrw_mpsph[i] * MPS_PER_SQRT_H;
            let spec = ChannelSpec {
                bias: m.accel_bias_ug[i] * UG,
                turn_on: m.accel_bias_turn_on_ug[i] * UG,
                gm_sigma: m.accel_bias_gm_ug[i] * UG,
                gm_tau: m.accel_bias_gm_tau_s[i],
                flicker_b: m.accel_bias_instability_ug[i] * UG,
                white: vrw_a.hypot(vrw_b),
                rw: m.accel_rrw_ugpsh[i] * UG_PER_SQRT_H,
                scale: m.accel_scale_ppm[i] * PPM,
                asym: m.accel_scale_asym_ppm[i] * PPM,
                quantum: m.accel_quantum_mps[i],
                range: accel_range.map_or(f64::INFINITY, |r| r[i]),
            };
            Channel::new(&spec, &flicker, seed, run, 3 + i as u64)
        });
        Ok(Self {
            gyro,
            accel,
            m_gyro: mat(&m.gyro_misalignment_mrad, MRAD),
            m_accel: mat(&m.accel_misalignment_mrad, MRAD),
            g_sens: mat(&m.gyro_g_sensitivity_dphpg, DPH / G0),
        })
    }

    /// The constant part of the bias of this run (fixed + drawn turn-on):
    /// gyro \[rad/s\], accel \[m/s²\].
    pub fn constant_bias(&self) -> (Vec3, Vec3) {
        (
            Vec3::new(self.gyro[0].bias, self.gyro[1].bias, self.gyro[2].bias),
            Vec3::new(self.accel[0].bias, self.accel[1].bias, self.accel[2].bias),
        )
    }

    /// Corrupt one sample of period `dt_s` \[s\]. A non-positive or non-finite `dt_s`
    /// returns the input unchanged (and consumes no random numbers).
    pub fn apply(&mut self, inc: &Increment, dt_s: f64) -> Increment {
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return *inc;
        }
        let w = inc.dtheta_b_rad / dt_s;
        let f = inc.dv_b_mps / dt_s;
        let mw = self.m_gyro * w;
        let gf = self.g_sens * f;
        let ma = self.m_accel * f;
        let mut out = Increment::default();
        for i in 0..3 {
            let g = &mut self.gyro[i];
            let rate = g.scaled(w[i]) + mw[i] + gf[i] + g.additive(dt_s);
            out.dtheta_b_rad[i] = g.output(rate, dt_s);
            let a = &mut self.accel[i];
            let sf = a.scaled(f[i]) + ma[i] + a.additive(dt_s);
            out.dv_b_mps[i] = a.output(sf, dt_s);
        }
        out
    }

    /// Corrupt a whole slice.
    pub fn apply_all(&mut self, incs: &[Increment], dt_s: f64) -> Vec<Increment> {
        incs.iter().map(|i| self.apply(i, dt_s)).collect()
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::super::*;
    use super::*;

    fn still(n: usize, dt: f64) -> Vec<Increment> {
        vec![Increment::new(Vec3::zeros(), Vec3::new(0.0, 0.0, -G0 * dt)); n]
    }

    #[test]
    fn chunking_and_run_index_do_not_change_the_stream() {
        let m = ImuErrorModel {
            gyro_bias_instability_dph: [0.5; 3],
            gyro_bias_gm_dph: [1.0; 3],
            gyro_bias_gm_tau_s: [30.0; 3],
            accel_rrw_ugpsh: [10.0; 3],
            gyro_quantum_arcsec: [0.1; 3],
            ..ImuErrorModel::preset("tactical").unwrap()
        };
        let dt = 0.01;
        let input = still(10_000, dt);
        let mut one = ImuErrorState::new(&m, 42, 3).unwrap();
        let all = one.apply_all(&input, dt);
        let mut chunked = ImuErrorState::new(&m, 42, 3).unwrap();
        let mut out = Vec::new();
        for c in input.chunks(7) {
            out.extend(chunked.apply_all(c, dt));
        }
        assert_eq!(all, out);
        // run 3 alone equals run 3 created after runs 0..3 (and in another order)
        let mut others: Vec<_> = (0..5)
            .map(|r| ImuErrorState::new(&m, 42, r).unwrap())
            .collect();
        let runs: Vec<Vec<Increment>> = others
            .iter_mut()
            .rev()
            .map(|s| s.apply_all(&input, dt))
            .collect();
        assert_eq!(runs[4 - 3], all);
        // different runs and seeds differ
        assert_ne!(runs[0], runs[1]);
        let mut other_seed = ImuErrorState::new(&m, 43, 3).unwrap();
        assert_ne!(other_seed.apply_all(&input, dt), all);
    }

    #[test]
    fn constant_bias_mean_within_4_sigma() {
        // bias + white noise: the sample mean of the rate is within 4 σ/√N of the bias,
        // σ = ARW/√dt (rate) — probability of failure ≈ 6e-5 per channel.
        let m = ImuErrorModel {
            gyro_bias_dph: [10.0, -5.0, 1.0],
            gyro_arw_dpsh: [0.1; 3],
            accel_bias_ug: [100.0, -200.0, 50.0],
            accel_vrw_ugpsqrthz: [50.0; 3],
            ..ImuErrorModel::default()
        };
        let (dt, n) = (0.01, 100_000);
        let mut s = ImuErrorState::new(&m, 7, 0).unwrap();
        let input = still(n, dt);
        let out = s.apply_all(&input, dt);
        for i in 0..3 {
            let mean_w = out.iter().map(|o| o.dtheta_b_rad[i]).sum::<f64>() / (n as f64 * dt);
            let sig = m.gyro_arw_dpsh[i] * DPSH / dt.sqrt();
            let tol = 4.0 * sig / (n as f64).sqrt();
            assert!(
                (mean_w - m.gyro_bias_dph[i] * DPH).abs() < tol,
                "gyro {i}: {mean_w} tol {tol}"
            );
            let mean_f = out
                .iter()
                .zip(&input)
                .map(|(o, t)| o.dv_b_mps[i] - t.dv_b_mps[i])
                .sum::<f64>()
                / (n as f64 * dt);
            let sig = m.accel_vrw_ugpsqrthz[i] * UG_PER_SQRT_HZ / dt.sqrt();
            let tol = 4.0 * sig / (n as f64).sqrt();
            assert!(
                (mean_f - m.accel_bias_ug[i] * UG).abs() < tol,
                "accel {i}: {mean_f} tol {tol}"
            );
        }
    }

    #[test]
    fn turn_on_bias_is_drawn_per_run() {
        // 400 runs: the sample σ of the drawn turn-on biases is within 4·σ/√(2·400)
        // of σ (standard error of a sample standard deviation ≈ σ/√(2n)).
        let m = ImuErrorModel {
            gyro_bias_turn_on_dph: [2.0; 3],
            accel_bias_turn_on_ug: [300.0; 3],
            ..Default::default()
        };
        let n = 400;
        let xs: Vec<f64> = (0..n)
            .map(|r| ImuErrorState::new(&m, 1, r).unwrap().constant_bias().0[1] / DPH)
            .collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n as f64 - 1.0)).sqrt();
        assert!(
            (sd - 2.0).abs() < 4.0 * 2.0 / (2.0 * n as f64).sqrt(),
            "sd {sd}"
        );
        assert!(mean.abs() < 4.0 * 2.0 / (n as f64).sqrt(), "mean {mean}");
    }

    #[test]
    fn white_noise_sample_sigma_matches_arw_and_vrw() {
        // Δθ noise σ = ARW·√dt; sample σ over N samples within 5 % (its standard error is
        // σ/√(2N) = 0.2 % at N = 120 000, so 5 % is 25 standard errors of margin for the
        // 2 h/100 Hz requirement while the test stays fast: 720 000 samples).
        let m = ImuErrorModel {
            gyro_arw_dpsh: [0.05; 3],
            accel_vrw_mpsph: [0.03; 3],
            ..Default::default()
        };
        let (dt, n) = (0.01, 720_000);
        let mut s = ImuErrorState::new(&m, 11, 0).unwrap();
        let zero = Increment::default();
        let mut sum = [0.0; 6];
        for _ in 0..n {
            let o = s.apply(&zero, dt);
            for i in 0..3 {
                sum[i] += o.dtheta_b_rad[i].powi(2);
                sum[3 + i] += o.dv_b_mps[i].powi(2);
            }
        }
        for i in 0..3 {
            let arw = (sum[i] / n as f64).sqrt() / dt.sqrt() / DPSH;
            assert!((arw / 0.05 - 1.0).abs() < 0.05, "arw {arw}");
            let vrw = (sum[3 + i] / n as f64).sqrt() / dt.sqrt() / MPS_PER_SQRT_H;
            assert!((vrw / 0.03 - 1.0).abs() < 0.05, "vrw {vrw}");
        }
    }

    #[test]
    fn gauss_markov_correlation_time_within_10_percent() {
        // Pure GM, τc = 2 s, dt = 0.01 s, 2000 τc of data: the lag-1 autocorrelation
        // ρ = e^(−dt/τc) estimated over N = 200 000 samples has standard error
        // ≈ √((1−ρ²)/N); the estimate τ̂ = −dt/ln ρ̂ from the lag-L = τc/dt
        // autocorrelation (e^−1) is stable to a few % over 1000 correlation times.
        let tau = 2.0;
        let m = ImuErrorModel {
            gyro_bias_gm_dph: [50.0; 3],
            gyro_bias_gm_tau_s: [tau; 3],
            ..Default::default()
        };
        let (dt, n) = (0.01, 400_000);
        let mut s = ImuErrorState::new(&m, 5, 0).unwrap();
        let zero = Increment::default();
        let x: Vec<f64> = (0..n)
            .map(|_| s.apply(&zero, dt).dtheta_b_rad[0] / dt)
            .collect();
        let mean = x.iter().sum::<f64>() / n as f64;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        let lag = (tau / dt) as usize;
        let cov = x
            .iter()
            .zip(&x[lag..])
            .map(|(a, b)| (a - mean) * (b - mean))
            .sum::<f64>()
            / (n - lag) as f64;
        let rho = cov / var;
        let tau_hat = -(lag as f64 * dt) / rho.ln();
        assert!((tau_hat / tau - 1.0).abs() < 0.10, "tau_hat {tau_hat}");
        // and the variance is the steady-state σ² (within 15 %: ≈ 2000 τc of data)
        let sd = var.sqrt() / DPH;
        assert!((sd / 50.0 - 1.0).abs() < 0.15, "sd {sd}");
    }

    #[test]
    fn quantization_keeps_cumulative_within_one_quantum() {
        let q = 0.5; // arcsec
        let m = ImuErrorModel {
            gyro_quantum_arcsec: [q; 3],
            accel_quantum_mps: [1e-3; 3],
            gyro_arw_dpsh: [0.01; 3],
            ..Default::default()
        };
        let dt = 0.005;
        let mut s = ImuErrorState::new(&m, 9, 0).unwrap();
        let mut exact = ImuErrorState::new(
            &ImuErrorModel {
                gyro_arw_dpsh: [0.01; 3],
                ..Default::default()
            },
            9,
            0,
        )
        .unwrap();
        let (mut cq, mut ce, mut aq, mut ae) =
            (Vec3::zeros(), Vec3::zeros(), Vec3::zeros(), Vec3::zeros());
        for k in 0..20_000 {
            let t = k as f64 * dt;
            let inc = Increment::new(
                Vec3::new(0.01 * t.sin(), -3e-7, 1e-5 * (3.0 * t).cos()) * dt,
                Vec3::new(0.3 * t.cos(), 0.0, -9.8) * dt,
            );
            let o = s.apply(&inc, dt);
            let e = exact.apply(&inc, dt);
            cq += o.dtheta_b_rad;
            ce += e.dtheta_b_rad;
            aq += o.dv_b_mps;
            ae += e.dv_b_mps;
            for i in 0..3 {
                let r = (o.dtheta_b_rad[i] / (q * ARCSEC)).round();
                assert!(
                    (o.dtheta_b_rad[i] - r * q * ARCSEC).abs() < 1e-15,
                    "not a multiple of the quantum"
                );
                let d = ce[i] - cq[i];
                assert!(
                    (-1e-15..q * ARCSEC + 1e-15).contains(&d),
                    "gyro cumulative off by {d}"
                );
                let d = ae[i] - aq[i];
                assert!(
                    (-1e-12..1e-3 + 1e-12).contains(&d),
                    "accel cumulative off by {d}"
                );
            }
        }
    }

    #[test]
    fn scale_factor_misalignment_g_sensitivity_exact() {
        let m = ImuErrorModel {
            gyro_scale_ppm: [100.0, 200.0, -300.0],
            gyro_scale_asym_ppm: [50.0, 0.0, 0.0],
            gyro_misalignment_mrad: [[0.0, 1.0, -2.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0]],
            gyro_g_sensitivity_dphpg: [[0.0, 0.0, 2.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
            accel_scale_ppm: [1000.0, 0.0, 0.0],
            accel_misalignment_mrad: [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [3.0, 0.0, 0.0]],
            ..Default::default()
        };
        let dt = 0.01;
        let mut s = ImuErrorState::new(&m, 0, 0).unwrap();
        let w = Vec3::new(0.1, -0.2, 0.3);
        let f = Vec3::new(1.0, 0.0, -G0);
        let o = s.apply(&Increment::new(w * dt, f * dt), dt);
        let ow = o.dtheta_b_rad / dt;
        let ex = 0.1 * (1.0 + 150e-6) + 1e-3 * -0.2 - 2e-3 * 0.3 + 2.0 * DPH * (-G0) / G0;
        assert!((ow[0] - ex).abs() < 1e-15, "{} vs {ex}", ow[0]);
        assert!((ow[1] - (-0.2 * (1.0 + 200e-6) + 0.5e-3 * 0.1)).abs() < 1e-15);
        assert!((ow[2] - 0.3 * (1.0 - 300e-6)).abs() < 1e-15);
        // negative rate on x: asymmetry subtracts
        let o = s.apply(
            &Increment::new(Vec3::new(-0.1, 0.0, 0.0) * dt, Vec3::zeros()),
            dt,
        );
        assert!((o.dtheta_b_rad[0] / dt - (-0.1 * (1.0 + 50e-6))).abs() < 1e-15);
        let of = (s.apply(&Increment::new(Vec3::zeros(), f * dt), dt).dv_b_mps) / dt;
        assert!((of[0] - 1.001).abs() < 1e-13);
        assert!((of[2] - (-G0 + 3e-3)).abs() < 1e-13);
    }

    #[test]
    fn saturation_clamps() {
        let m = ImuErrorModel {
            gyro_range_dps: Some([100.0; 3]),
            accel_range_g: Some([2.0; 3]),
            ..Default::default()
        };
        let dt = 0.01;
        let mut s = ImuErrorState::new(&m, 0, 0).unwrap();
        let w = Vec3::new(3.0, -0.5, -5.0); // rad/s: 172 °/s, 29 °/s, 286 °/s
        let f = Vec3::new(30.0, -30.0, 5.0);
        let o = s.apply(&Increment::new(w * dt, f * dt), dt);
        let lim = 100.0 * DEG * dt;
        assert!((o.dtheta_b_rad[0] - lim).abs() < 1e-15);
        assert!((o.dtheta_b_rad[1] - w[1] * dt).abs() < 1e-15);
        assert!((o.dtheta_b_rad[2] + lim).abs() < 1e-15);
        assert!((o.dv_b_mps[0] - 2.0 * G0 * dt).abs() < 1e-15);
        assert!((o.dv_b_mps[1] + 2.0 * G0 * dt).abs() < 1e-15);
        assert!((o.dv_b_mps[2] - 5.0 * dt).abs() < 1e-15);
    }

    #[test]
    fn flicker_normalization_is_0664_b_on_the_plateau() {
        let (taus, c) = flicker_terms(0.1, 1.0e4);
        assert_eq!(taus.len(), 12);
        // the summed Allan deviation stays within ±10 % of 0.664 B over the plateau
        // [4·T_lo, T_hi/2] stated in the module docs
        for tau in [0.4, 1.0, 10.0, 100.0, 1000.0, 5000.0] {
            let s: f64 = taus.iter().map(|&t| gm_avar_unit(tau, t)).sum::<f64>();
            let adev = c * s.sqrt();
            assert!((adev / FLICKER_FLOOR - 1.0).abs() < 0.10, "{tau}: {adev}");
        }
        // Allan variance of GM: short-τ limit q τ/3 with q = 2σ²/T; long-τ 2σ²T/τ
        assert!((gm_avar_unit(1e-4, 1.0) / (2.0 * 1e-4 / 3.0) - 1.0).abs() < 1e-3);
        assert!((gm_avar_unit(1e5, 1.0) / (2.0 / 1e5) - 1.0).abs() < 1e-3);
    }
}
