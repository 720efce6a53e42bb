//! Local-level (NED) mechanizations: Savage baseline (SAV), Song–Lee paper mode (SL)
//! and Song–Lee complete (SLC) (docs/theory/mechanizations.md
//! §"Song–Lee three-sample local-level algorithm").
//!
//! Computation order per update (S1 §IV, docs/theory/mechanizations.md §"Order per update"):
//! velocity, then position, then attitude; every rate term is evaluated at t_{k−1}.

use super::{
    transport_matrix, transport_matrix_sc, wrap_pi, InitialState, Mechanization, NavState,
};
use crate::coning::{compensate, ConingSet, Increment};
use crate::earth::{sin_cos_shift, EarthModel};
use crate::math::{Mat3, Quat, Vec3};

/// Velocity-update formula (docs/theory/mechanizations.md §"Velocity").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VelocityMode {
    /// `v_k = v_{k−1} + C(Δv + ½Δθ×Δv + ΔV_scul) + ΔT[g − (2ω_ie + ω_en)×v_{k−1}]`
    Savage,
    /// SL: Savage's terms (with ½Δφ×Δv) plus S1's (29), (19), (17), signs corrected:
    /// `− (ΔT/2)[(3ω_ie + 2ω_en)×](CΔv) − (ΔT²/2)(2ω_ie + ω_en)×g`
    SongLee,
    /// SLC: SL plus the second-order homogeneous term `+ (ΔT²/2) W×(W×v_{k−1})`, W = 2ω_ie + ω_en
    SongLeeComplete,
}

/// Attitude-update formula (docs/theory/mechanizations.md §"Attitude by DCM separation";
/// docs/theory/mechanizations.md §"Order per update").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AttitudeMode {
    /// S1 eq. (6)/(32): gyro-only quaternion `Q_k = Q_{k−1} ⊗ q(Δφ)`, `C_b^n = T(L, l, t) C(Q)`
    Transport,
    /// S1 eq. (5) method: n-relative increments `Δθ_j − C_n^b ω_in ΔT/N`, then coning
    Five,
    /// Savage Part 1: `q_k = q(−ζ) ⊗ q_{k−1} ⊗ q(Δφ)`, `ζ = (ω_ie + ω_en)_{k−1} ΔT`
    Savage,
}

/// Which rotation vector the rotation compensation `½ x × Δv` uses (docs/theory/coning-sculling.md
/// §"Coning and sculling").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotVector {
    /// `½ Δθ × Δv`, Savage's `α_m × υ_m` (the summed gyro increment)
    Theta,
    /// `½ Δφ × Δv`, S1 eq. (30) (the coning-compensated rotation vector). Differs from
    /// `Theta` by O(ΔT³)·coning; under 1 Hz coning (docs/validation.md
    /// §"dual-quaternion paper case") it is the more exact one (closer to the dual-quaternion screw
    /// exponential, which contains it).
    Phi,
}

/// Configuration of a [`LocalLevel`] mechanization.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalLevelConfig {
    /// velocity formula
    pub velocity: VelocityMode,
    /// attitude formula
    pub attitude: AttitudeMode,
    /// coning/sculling coefficient set
    pub coning: ConingSet,
    /// samples per update N
    pub samples: usize,
    /// rotation vector of the rotation compensation
    pub rot_vector: RotVector,
    /// evaluate ω_ie, ω_en and g of the velocity update at the interval midpoint,
    /// extrapolated linearly from the last two updates (`1.5 x_{k−1} − 0.5 x_{k−2}`).
    /// Holding them at t_{k−1} (S1, Savage baseline) leaves a per-step error
    /// `½ΔT² Ȧ v`, i.e. first order globally; near the poles Ȧ is large (tanL grows with
    /// the northward motion) and this dominates. Used by `songlee-complete`.
    pub midpoint_rates: bool,
    /// third-order rotation compensation `+ (1/6) Δφ×(Δφ×Δv)` (docs/theory/coning-sculling.md
    /// §"Coning and sculling")
    pub rot3: bool,
    /// earth model (must equal the truth's)
    pub earth: EarthModel,
    /// sensor sample period δt \[s\]
    pub dt_s: f64,
}

/// Local-level NED strapdown mechanization (SAV, SL, SLC).
#[derive(Clone, Debug)]
pub struct LocalLevel {
    cfg: LocalLevelConfig,
    dt_update_s: f64,
    // position carried as offsets from the start (docs/theory/mechanizations.md §"Position"
    // roundoff recommendation)
    lat0_rad: f64,
    lon0_rad: f64,
    s_lat0: f64,
    c_lat0: f64,
    dlat_rad: f64,
    dlon_rad: f64,
    h_m: f64,
    v_n_mps: Vec3,
    /// gyro-only quaternion Q_b^{n0ⁱ} (Transport mode) or q_b^n (Five, Savage modes)
    q: Quat,
    c_b_n: Mat3,
    updates: u64,
    prev: Increment,
    /// ω_ie, ω_en, g at t_{k−2} (for midpoint extrapolation)
    rates_prev: Option<(Vec3, Vec3, Vec3)>,
}

impl LocalLevel {
    /// Initialise at t = 0 from the given state.
    pub fn new(cfg: LocalLevelConfig, init: &InitialState) -> Self {
        let q = Quat::from_dcm(&init.c_b_n);
        Self {
            dt_update_s: cfg.dt_s * cfg.samples as f64,
            cfg,
            lat0_rad: init.lat_rad,
            lon0_rad: init.lon_rad,
            s_lat0: libm::sin(init.lat_rad),
            c_lat0: libm::cos(init.lat_rad),
            dlat_rad: 0.0,
            dlon_rad: 0.0,
            h_m: init.h_m,
            v_n_mps: init.v_n_mps,
            q,
            c_b_n: q.to_dcm(),
            updates: 0,
            prev: Increment::default(),
            rates_prev: None,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LocalLevelConfig {
        &self.cfg
    }

    #[inline]
    fn lat(&self) -> f64 {
        self.lat0_rad + self.dlat_rad
    }
}

impl Mechanization for LocalLevel {
    #[inline]
    fn samples_per_update(&self) -> usize {
        self.cfg.samples
    }

    fn update(&mut self, samples: &[Increment]) {
        let n = self.cfg.samples.min(samples.len());
        let samples = &samples[..n];
        let e = &self.cfg.earth;
        let dt = self.dt_update_s;
        let lat = self.lat();
        let h = self.h_m;
        let v = self.v_n_mps;
        let c = self.c_b_n;

        // 1.–2. increments and rates at t_{k−1}
        let comp = compensate(self.cfg.coning, samples, &self.prev);
        let le = e.local(lat, h);
        let w_ie_k1 = e.omega_ie_n_local(&le);
        let w_en_k1 = e.omega_en_n_local(&le, h, &v);
        let g_k1 = Vec3::new(0.0, 0.0, le.g_mps2);
        let (w_ie, w_en, g_n) = match (self.cfg.midpoint_rates, self.rates_prev) {
            (true, Some((a, b, c))) => (
                1.5 * w_ie_k1 - 0.5 * a,
                1.5 * w_en_k1 - 0.5 * b,
                1.5 * g_k1 - 0.5 * c,
            ),
            _ => (w_ie_k1, w_en_k1, g_k1),
        };
        self.rates_prev = Some((w_ie_k1, w_en_k1, g_k1));
        let w_in = w_ie + w_en;
        let w_cor = 2.0 * w_ie + w_en;

        // 3. velocity
        let dphi_rot = match self.cfg.rot_vector {
            RotVector::Theta => comp.dtheta_b_rad,
            RotVector::Phi => comp.dphi_b_rad,
        };
        let mut dv_rot = 0.5 * dphi_rot.cross(&comp.dv_b_mps);
        if self.cfg.rot3 {
            dv_rot += dphi_rot.cross(&dphi_rot.cross(&comp.dv_b_mps)) / 6.0;
        }
        let c_dv = c * comp.dv_b_mps;
        let mut v_new =
            v + c * (comp.dv_b_mps + dv_rot + comp.dv_scul_b_mps) + dt * (g_n - w_cor.cross(&v));
        match self.cfg.velocity {
            VelocityMode::Savage => {}
            VelocityMode::SongLee | VelocityMode::SongLeeComplete => {
                // (29) + (19): −(ΔT/2)[(3ω_ie + 2ω_en)×](CΔv); (17): −(ΔT²/2)(2ω_ie+ω_en)×g
                v_new -= (0.5 * dt) * (w_in + w_cor).cross(&c_dv);
                v_new -= (0.5 * dt * dt) * w_cor.cross(&g_n);
                if self.cfg.velocity == VelocityMode::SongLeeComplete {
                    v_new += (0.5 * dt * dt) * w_cor.cross(&w_cor.cross(&v));
                }
            }
        }

        // 4. position, trapezoid with a latitude predictor (docs/theory/mechanizations.md
        //    §"Position")
        let h_new = h - 0.5 * (v.z + v_new.z) * dt;
        let h_bar = 0.5 * (h + h_new);
        let vn_bar = 0.5 * (v.x + v_new.x);
        let ve_bar = 0.5 * (v.y + v_new.y);
        // sin/cos of the latitudes needed below are shifted from sin/cos L_{k−1}
        // (steps are ~1e-7 rad: series exact to 1e-24), so one sin/cos serves the update.
        let (dlat_new, s_bar, c_bar) = if e.transport {
            let lat_pred = lat + vn_bar * dt / (le.r_m_m + h_bar);
            let (s_m, _) = sin_cos_shift(le.sin_lat, le.cos_lat, 0.5 * (lat_pred - lat));
            let dlat_new = self.dlat_rad + vn_bar * dt / (e.radii_sin(s_m).r_m_m + h_bar);
            let (s_bar, c_bar) =
                sin_cos_shift(le.sin_lat, le.cos_lat, 0.5 * (dlat_new - self.dlat_rad));
            (dlat_new, s_bar, c_bar)
        } else {
            let (s0, c0) = (self.s_lat0, self.c_lat0);
            (
                self.dlat_rad + vn_bar * dt / (e.radii_sin(s0).r_m_m + h_bar),
                s0,
                c0,
            )
        };
        let dlon_new = self.dlon_rad + ve_bar * dt / ((e.radii_sin(s_bar).r_n_m + h_bar) * c_bar);

        // 5. attitude
        match self.cfg.attitude {
            AttitudeMode::Transport => {
                self.q = self
                    .q
                    .mul(&Quat::from_rotvec(&comp.dphi_b_rad))
                    .normalized();
                self.updates += 1;
                let t = self.updates as f64 * dt;
                let tm = if e.transport {
                    let (s_new, c_new) =
                        sin_cos_shift(le.sin_lat, le.cos_lat, dlat_new - self.dlat_rad);
                    transport_matrix_sc(
                        s_new,
                        c_new,
                        self.s_lat0,
                        self.c_lat0,
                        dlon_new + e.omega_ie_rps * t,
                    )
                } else {
                    transport_matrix(self.lat0_rad, self.s_lat0, self.c_lat0, e.omega_ie_rps * t)
                };
                self.c_b_n = tm * self.q.to_dcm();
            }
            AttitudeMode::Savage => {
                let zeta = w_in * dt;
                self.q = Quat::from_rotvec(&(-zeta))
                    .mul(&self.q)
                    .mul(&Quat::from_rotvec(&comp.dphi_b_rad))
                    .normalized();
                self.updates += 1;
                self.c_b_n = self.q.to_dcm();
            }
            AttitudeMode::Five => {
                let w_in_b = c.transpose() * w_in * (dt / n.max(1) as f64);
                let mut rel = [Increment::default(); 4];
                for (r, s) in rel.iter_mut().zip(samples.iter()) {
                    *r = Increment::new(s.dtheta_b_rad - w_in_b, s.dv_b_mps);
                }
                let prev_rel = Increment::new(
                    self.prev.dtheta_b_rad - w_in_b * n as f64,
                    self.prev.dv_b_mps,
                );
                let comp_rel = compensate(self.cfg.coning, &rel[..n.min(4)], &prev_rel);
                self.q = self
                    .q
                    .mul(&Quat::from_rotvec(&comp_rel.dphi_b_rad))
                    .normalized();
                self.updates += 1;
                self.c_b_n = self.q.to_dcm();
            }
        }
        self.v_n_mps = v_new;
        self.h_m = h_new;
        self.dlat_rad = dlat_new;
        self.dlon_rad = dlon_new;
        self.prev = Increment::new(comp.dtheta_b_rad, comp.dv_b_mps);
    }

    fn state(&self) -> NavState {
        NavState {
            t_s: self.updates as f64 * self.dt_update_s,
            lat_rad: self.lat(),
            lon_rad: wrap_pi(self.lon0_rad + self.dlon_rad),
            h_m: self.h_m,
            v_n_mps: self.v_n_mps,
            c_b_n: self.c_b_n,
        }
    }

    fn hold_vertical(&mut self, h_m: f64, v_d_mps: f64) {
        self.h_m = h_m;
        self.v_n_mps.z = v_d_mps;
    }

    fn correct_state(&mut self, s: &NavState) {
        // offsets from the start stay continuous (no wrap of dlon across ±180°)
        self.dlat_rad += s.lat_rad - self.lat();
        self.dlon_rad += wrap_pi(s.lon_rad - wrap_pi(self.lon0_rad + self.dlon_rad));
        self.h_m = s.h_m;
        self.v_n_mps = s.v_n_mps;
        let q_new = Quat::from_dcm(&s.c_b_n);
        self.q = match self.cfg.attitude {
            AttitudeMode::Transport => {
                // c_b_n = T(L, Δλ + Ω t) · C(q): q from Tᵀ c_b_n
                let e = &self.cfg.earth;
                let t = self.updates as f64 * self.dt_update_s;
                let tm = if e.transport {
                    let (sl, cl) = libm::sincos(self.lat());
                    transport_matrix_sc(
                        sl,
                        cl,
                        self.s_lat0,
                        self.c_lat0,
                        self.dlon_rad + e.omega_ie_rps * t,
                    )
                } else {
                    transport_matrix(self.lat0_rad, self.s_lat0, self.c_lat0, e.omega_ie_rps * t)
                };
                Quat::from_dcm(&(tm.transpose() * s.c_b_n)).normalized()
            }
            AttitudeMode::Savage | AttitudeMode::Five => q_new,
        };
        self.c_b_n = s.c_b_n;
    }
}
