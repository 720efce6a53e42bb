//! The raw GNSS simulator of one run: feed consecutive truth samples, receive the
//! pseudoranges and range rates of the epochs between them.

use super::config::RawGnssConfig;
use crate::sensors::gnss::exact_antenna;
use crate::truth::trajectory::Trajectory;
use crate::truth::TruthSample;
use rand::SeedableRng;
use rand_chacha::ChaCha20Rng;
use rand_distr::{Distribution, StandardNormal};
use sdins_core::earth::EarthModel;
use sdins_core::gnss::{
    elevation_azimuth, klobuchar_l1_delay_m, predict, saastamoinen_slant_m, select_ephemeris,
    ClockModel, ClockState, GpsTime, ReceiverState, C_MPS, DEFAULT_VALIDITY_S,
};
use sdins_core::math::Vec3;

/// Number of GPS PRNs simulated (1…32); every epoch draws for all of them.
const N_PRN: usize = 32;

/// The model σ a filter should give one pseudorange, by source (each already at the
/// satellite's elevation) \[m\].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Uere {
    /// white noise σ0 / sin el
    pub noise_m: f64,
    /// residual ionosphere after Klobuchar: `iono_resid_frac·K` and `|iono_scale − 1|·K`
    /// in quadrature
    pub iono_m: f64,
    /// residual troposphere after Saastamoinen, `tropo_resid_zenith_m / sin el`
    pub tropo_m: f64,
    /// signal in space (ephemeris and satellite clock), `sis_ura_scale · URA`
    pub sis_m: f64,
}

impl Uere {
    /// The total σ, the root sum of squares.
    pub fn total_m(&self) -> f64 {
        (self.noise_m.powi(2) + self.iono_m.powi(2) + self.tropo_m.powi(2) + self.sis_m.powi(2))
            .sqrt()
    }
}

/// The truth behind one raw measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawTruth {
    /// antenna position, ECEF \[m\]
    pub r_e_m: Vec3,
    /// antenna velocity relative to ECEF, ECEF axes \[m/s\]
    pub v_e_mps: Vec3,
    /// receiver clock (bias c·δt_r \[m\], drift \[m/s\]) at the epoch, jumps included
    pub clock: ClockState,
    /// geometric range (light time with Earth rotation) \[m\]
    pub range_m: f64,
    /// true L1 ionospheric delay \[m\]
    pub iono_m: f64,
    /// Klobuchar model delay \[m\]
    pub iono_model_m: f64,
    /// true slant tropospheric delay \[m\]
    pub tropo_m: f64,
    /// Saastamoinen model delay \[m\]
    pub tropo_model_m: f64,
    /// signal-in-space error \[m\]
    pub sis_m: f64,
    /// injected outlier \[m\]
    pub outlier_m: f64,
}

/// One satellite's raw measurement at one epoch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawObs {
    /// true time of reception, scenario seconds
    pub t_s: f64,
    /// the receiver's time tag (GPST read on the receiver clock, `t + δt_r`)
    pub t_rx: GpsTime,
    /// PRN
    pub prn: u8,
    /// L1 C/A pseudorange \[m\]
    pub pseudorange_m: f64,
    /// pseudorange rate \[m/s\] (the L1 Doppler is `−rate/λ1`)
    pub range_rate_mps: f64,
    /// the model σ of the pseudorange \[m\] ([`Uere::total_m`])
    pub sigma_pr_m: f64,
    /// the white range-rate σ \[m/s\]
    pub sigma_rr_mps: f64,
    /// the pseudorange σ by source
    pub uere: Uere,
    /// elevation \[rad\]
    pub elevation_rad: f64,
    /// azimuth \[rad\]
    pub azimuth_rad: f64,
    /// the truth behind it
    pub truth: RawTruth,
}

fn rng(seed: u64, run: u64, channel: u64) -> ChaCha20Rng {
    let mut r = ChaCha20Rng::seed_from_u64(seed);
    r.set_stream((1u64 << 62) | run.wrapping_mul(64).wrapping_add(channel));
    r
}

fn normal(r: &mut ChaCha20Rng) -> f64 {
    StandardNormal.sample(r)
}

/// The raw GNSS simulator of one run (see the module documentation).
#[derive(Clone, Debug)]
pub struct RawGnssSimulator {
    cfg: RawGnssConfig,
    earth: EarthModel,
    clock_model: ClockModel,
    next_j: u64,
    rng_noise: ChaCha20Rng,
    rng_clock: ChaCha20Rng,
    rng_atm: ChaCha20Rng,
    clock: ClockState,
    t_last_s: f64,
    /// residual ionosphere per PRN, as a fraction of the Klobuchar delay
    iono_res: [f64; N_PRN],
    /// residual zenith troposphere \[m\]
    tropo_res_m: f64,
    /// signal-in-space error per PRN in units of `sis_ura_scale · URA`
    sis_unit: [f64; N_PRN],
}

impl RawGnssSimulator {
    /// The simulator of run `run`. Streams `2⁶² + 64·run + channel`: channel 0 the white
    /// noise, 1 the receiver clock, 2 the atmosphere residuals, 3 the run's
    /// signal-in-space constants.
    pub fn new(cfg: &RawGnssConfig, earth: EarthModel, run: u64) -> Self {
        let t = &cfg.table;
        let mut rng_atm = rng(t.seed, run, 2);
        let iono_res = core::array::from_fn(|_| t.iono_resid_frac * normal(&mut rng_atm));
        let tropo_res_m = t.tropo_resid_zenith_m * normal(&mut rng_atm);
        let mut rng_sis = rng(t.seed, run, 3);
        let sis_unit = core::array::from_fn(|_| normal(&mut rng_sis));
        RawGnssSimulator {
            cfg: cfg.clone(),
            earth,
            clock_model: t.clock(),
            next_j: 1,
            rng_noise: rng(t.seed, run, 0),
            rng_clock: rng(t.seed, run, 1),
            rng_atm,
            clock: ClockState::default(),
            t_last_s: 0.0,
            iono_res,
            tropo_res_m,
            sis_unit,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &RawGnssConfig {
        &self.cfg
    }

    /// Advances the clock (exact two-state transition, then the jumps in `(t_last, t]`)
    /// and the Gauss–Markov residuals to `t_s`.
    fn advance(&mut self, t_s: f64) {
        let dt = t_s - self.t_last_s;
        let tb = &self.cfg.table;
        let w = [normal(&mut self.rng_clock), normal(&mut self.rng_clock)];
        if dt > 0.0 {
            self.clock = self.clock_model.step(&self.clock, dt, w);
            for j in &tb.clock_jump_t_s_ms {
                if j[0] > self.t_last_s && j[0] <= t_s {
                    self.clock.bias_m += C_MPS * j[1] * 1e-3;
                }
            }
        }
        let gm = |x: f64, sigma: f64, tau: f64, w: f64| {
            let e = (-dt.max(0.0) / tau).exp();
            e * x + sigma * (1.0 - e * e).sqrt() * w
        };
        for k in 0..N_PRN {
            let w = normal(&mut self.rng_atm);
            self.iono_res[k] = gm(self.iono_res[k], tb.iono_resid_frac, tb.iono_resid_tau_s, w);
        }
        let w = normal(&mut self.rng_atm);
        self.tropo_res_m = gm(
            self.tropo_res_m,
            tb.tropo_resid_zenith_m,
            tb.tropo_resid_tau_s,
            w,
        );
        self.t_last_s = t_s;
    }

    /// The next epoch in `(a, b]`, if any (advancing).
    fn next_epoch(&mut self, a: f64, b: f64) -> Option<f64> {
        let rate = self.cfg.table.rate_hz;
        loop {
            let t = self.next_j as f64 / rate;
            if t > b + 1e-9 / rate {
                return None;
            }
            self.next_j += 1;
            if t > a {
                return Some(t);
            }
        }
    }

    /// Measurements of the epochs `j / rate_hz` in `(a.t_s, b.t_s]`, appended to `out`
    /// in time order and PRN order within an epoch. Every epoch draws the same count of
    /// random numbers whatever is visible (outages too).
    pub fn step(
        &mut self,
        traj: &Trajectory,
        a: &TruthSample,
        b: &TruthSample,
        out: &mut Vec<RawObs>,
    ) {
        while let Some(t) = self.next_epoch(a.t_s, b.t_s) {
            self.advance(t);
            let w: [[f64; 2]; N_PRN] = core::array::from_fn(|_| {
                [normal(&mut self.rng_noise), normal(&mut self.rng_noise)]
            });
            let tb = &self.cfg.table;
            if tb.outages_s.iter().any(|o| (o[0]..o[1]).contains(&t)) {
                continue;
            }
            let (lat, lon, h, v_n) = exact_antenna(&self.earth, traj, a, b, t, &tb.lever_arm_b_m);
            self.epoch(t, lat, lon, h, &v_n, &w, out);
        }
    }

    /// The measurements of one epoch at a known antenna state (geodetic, NED velocity);
    /// `w` the epoch's standard normal numbers per PRN (pseudorange, range rate).
    #[allow(clippy::too_many_arguments)]
    fn epoch(
        &self,
        t: f64,
        lat: f64,
        lon: f64,
        h: f64,
        v_n: &Vec3,
        w: &[[f64; 2]; N_PRN],
        out: &mut Vec<RawObs>,
    ) {
        let tb = &self.cfg.table;
        let c_e_n = EarthModel::c_e_n(lat, lon);
        let r_e = self.earth.ecef_from_geodetic(lat, lon, h);
        let v_e = c_e_n.transpose() * v_n;
        let t_gps: GpsTime = self.cfg.start.add_s(t);
        let rx = ReceiverState {
            r_e_m: r_e,
            v_e_mps: v_e,
            clock_bias_m: self.clock.bias_m,
            clock_drift_mps: self.clock.drift_mps,
        };
        let t_rx = t_gps.add_s(self.clock.bias_m / C_MPS);
        let validity = if self.cfg.nominal {
            super::config::NOMINAL_REEPOCH_S
        } else {
            DEFAULT_VALIDITY_S
        };
        let mask = tb.mask_deg.to_radians();
        let half = 0.5 / tb.rate_hz;
        for prn in 1..=N_PRN as u8 {
            if !tb.prns.is_empty() && !tb.prns.contains(&prn) {
                continue;
            }
            let Some(eph) = select_ephemeris(&self.cfg.ephemerides, prn, &t_gps, validity) else {
                continue;
            };
            let Ok(p) = predict(eph, &t_gps, &rx) else {
                continue;
            };
            let (el, az) = elevation_azimuth(&c_e_n, &p.los_e);
            if el < mask || el.to_degrees() < self.cfg.sky_mask_el_deg(az.to_degrees()) {
                continue;
            }
            let k = (prn - 1) as usize;
            let sin_el = el.sin();
            let iono_model =
                klobuchar_l1_delay_m(&self.cfg.klobuchar, lat, lon, el, az, t_gps.sow_s);
            let iono = (tb.iono_scale + self.iono_res[k]) * iono_model;
            let tropo_model = saastamoinen_slant_m(lat, h, el);
            let tropo = tropo_model + self.tropo_res_m / sin_el;
            let sis_sigma = tb.sis_ura_scale * eph.sv_accuracy_m;
            let sis = sis_sigma * self.sis_unit[k];
            let outlier: f64 = tb
                .outliers_t_s_prn_m
                .iter()
                .filter(|o| o[1] as u8 == prn && (o[0] - t).abs() < half)
                .map(|o| o[2])
                .sum();
            let uere = Uere {
                noise_m: tb.sigma_pr_m / sin_el,
                iono_m: iono_model * tb.iono_resid_frac.hypot(tb.iono_scale - 1.0),
                tropo_m: tb.tropo_resid_zenith_m / sin_el,
                sis_m: sis_sigma,
            };
            let sigma_rr = tb.sigma_rr_mps / sin_el;
            // L1 C/A: the satellite clock reference is P(Y) dual-frequency, so the L1
            // pseudorange carries + c·T_GD (IS-GPS-200 §20.3.3.3.3.2)
            let pr = p.pseudorange_m
                + C_MPS * eph.tgd_s
                + iono
                + tropo
                + sis
                + outlier
                + uere.noise_m * w[k][0];
            out.push(RawObs {
                t_s: t,
                t_rx,
                prn,
                pseudorange_m: pr,
                range_rate_mps: p.pseudorange_rate_mps + sigma_rr * w[k][1],
                sigma_pr_m: uere.total_m(),
                sigma_rr_mps: sigma_rr,
                uere,
                elevation_rad: el,
                azimuth_rad: az,
                truth: RawTruth {
                    r_e_m: r_e,
                    v_e_mps: v_e,
                    clock: self.clock,
                    range_m: p.range_m,
                    iono_m: iono,
                    iono_model_m: iono_model,
                    tropo_m: tropo,
                    tropo_model_m: tropo_model,
                    sis_m: sis,
                    outlier_m: outlier,
                },
            });
        }
    }
}
