//! Wu's dual-quaternion SDINS (mechanization.md §6.2–§6.3; S2 eqs (1)–(13), W).
//!
//! Three unit dual quaternions, all "from I to X":
//! * T (thrust velocity): attitude B, translation `v_t^I = ∫ f^I`, twist `ω_ib^b + ε f^b`;
//! * G (gravitational velocity): attitude E, translation `v_g^I = ṙ^I(0) + ∫ G^I`,
//!   twist `ω_ie^e + ε G^e`;
//! * U (position): attitude E, translation `r^I`, twist `ω_ie^e + ε C_I^E (v_t^I + v_g^I)`.

use super::{DualQuat, InitialState, Mechanization, NavState};
use crate::coning::{compensate, ConingSet, Increment};
use crate::earth::EarthModel;
use crate::math::{Mat3, Quat, Vec3};

/// Dual-quaternion navigation state and configuration.
#[derive(Clone, Debug)]
pub struct DualQuatNav {
    earth: EarthModel,
    coning: ConingSet,
    samples: usize,
    dt_update_s: f64,
    omega_ie_e: Vec3,
    q_t: DualQuat,
    q_g: DualQuat,
    q_u: DualQuat,
    u_prev: Vec3,
    r_e: Vec3,
    v_e: Vec3,
    lat_rad: f64,
    lon_rad: f64,
    h_m: f64,
    v_n_mps: Vec3,
    c_b_n: Mat3,
    updates: u64,
    prev: Increment,
}

impl DualQuatNav {
    /// Initialise (spec §6.3 "Initialisation").
    pub fn new(
        earth: EarthModel,
        dt_s: f64,
        samples: usize,
        coning: ConingSet,
        init: &InitialState,
    ) -> Self {
        let omega_ie_e = Vec3::new(0.0, 0.0, earth.omega_ie_rps);
        let r0 = earth.ecef_from_geodetic(init.lat_rad, init.lon_rad, init.h_m);
        let c_n_e0 = EarthModel::c_e_n(init.lat_rad, init.lon_rad).transpose();
        let v_e0 = c_n_e0 * init.v_n_mps;
        let v_i0 = v_e0 + omega_ie_e.cross(&r0);
        let q_t = DualQuat {
            r: Quat::from_dcm(&(c_n_e0 * init.c_b_n)),
            d: Quat::new(0.0, 0.0, 0.0, 0.0),
        };
        let q_g = DualQuat {
            r: Quat::IDENTITY,
            d: Quat::from_parts(0.0, &v_i0).scale(0.5),
        };
        let q_u = DualQuat {
            r: Quat::IDENTITY,
            d: Quat::from_parts(0.0, &r0).scale(0.5),
        };
        let mut s = Self {
            earth,
            coning,
            samples,
            dt_update_s: dt_s * samples as f64,
            omega_ie_e,
            q_t,
            q_g,
            q_u,
            u_prev: v_i0,
            r_e: r0,
            v_e: v_e0,
            lat_rad: init.lat_rad,
            lon_rad: init.lon_rad,
            h_m: init.h_m,
            v_n_mps: init.v_n_mps,
            c_b_n: init.c_b_n,
            updates: 0,
            prev: Increment::default(),
        };
        s.c_b_n = s.attitude();
        s
    }

    /// Gravitational (mass-attraction) acceleration in ECEF:
    /// `G^e = C_n^e g^n + ω_ie^e × (ω_ie^e × r^e)` (spec §2).
    fn gravitation_e(&self, r_e: &Vec3, lat_hint: f64) -> Vec3 {
        let (lat, lon, h) = geodetic_warm(&self.earth, r_e, lat_hint);
        let c_n_e = EarthModel::c_e_n(lat, lon).transpose();
        c_n_e * self.earth.gravity_n(lat, h) + self.omega_ie_e.cross(&self.omega_ie_e.cross(r_e))
    }

    fn attitude(&self) -> Mat3 {
        EarthModel::c_e_n(self.lat_rad, self.lon_rad)
            * self.q_g.r.to_dcm().transpose()
            * self.q_t.r.to_dcm()
    }
}

/// Geodetic from ECEF, Newton-type fixed point started from a nearby latitude; converges
/// to roundoff in 2–3 iterations when started within a few metres (the full 10-iteration
/// cold start of [`EarthModel::geodetic_from_ecef`] is used otherwise).
fn geodetic_warm(e: &EarthModel, r: &Vec3, lat_hint: f64) -> (f64, f64, f64) {
    let lon = libm::atan2(r.y, r.x);
    let p = libm::sqrt(r.x * r.x + r.y * r.y);
    if p < 1e3 || !lat_hint.is_finite() {
        return e.geodetic_from_ecef(r);
    }
    let mut lat = lat_hint;
    for _ in 0..6 {
        let rn = e.radii(lat).r_n_m;
        let h = p / libm::cos(lat) - rn;
        let next = libm::atan2(r.z, p * (1.0 - e.e2 * rn / (rn + h)));
        let done = libm::fabs(next - lat) < 1e-16;
        lat = next;
        if done {
            break;
        }
    }
    let h = p / libm::cos(lat) - e.radii(lat).r_n_m;
    (lat, lon, h)
}

impl Mechanization for DualQuatNav {
    #[inline]
    fn samples_per_update(&self) -> usize {
        self.samples
    }

    fn update(&mut self, samples: &[Increment]) {
        let n = self.samples.min(samples.len());
        let dt = self.dt_update_s;
        let comp = compensate(self.coning, &samples[..n], &self.prev);

        // 1. T frame: dual coning of Δθ̂_j = Δθ_j + εΔv_j
        let sig_t = comp.dphi_b_rad;
        let sig_t_d = comp.dv_b_mps + comp.dv_scul_b_mps;
        self.q_t = self.q_t.mul(&DualQuat::exp(&sig_t, &sig_t_d)).normalized();

        // 2. G frame: mid-point gravitation
        let r_mid = self.r_e + 0.5 * dt * self.v_e;
        let g_mid = self.gravitation_e(&r_mid, self.lat_rad);
        let sig_w = self.omega_ie_e * dt;
        self.q_g = self
            .q_g
            .mul(&DualQuat::exp(&sig_w, &(g_mid * dt)))
            .normalized();

        // 3. inertial velocity resolved in E, and the U frame
        let v_t_i = self.q_t.translation_old();
        let v_g_i = self.q_g.translation_old();
        let c_i_e = self.q_g.r.to_dcm().transpose();
        let u_k = c_i_e * (v_t_i + v_g_i);
        let sig_u_d = 0.5 * (self.u_prev + u_k) * dt
            + (dt * dt / 12.0) * self.omega_ie_e.cross(&(u_k - self.u_prev));
        self.q_u = self.q_u.mul(&DualQuat::exp(&sig_w, &sig_u_d)).normalized();

        // 4. outputs
        self.r_e = self.q_u.translation_new();
        let (lat, lon, h) = geodetic_warm(&self.earth, &self.r_e, self.lat_rad);
        self.v_e = u_k - self.omega_ie_e.cross(&self.r_e);
        self.lat_rad = lat;
        self.lon_rad = lon;
        self.h_m = h;
        self.v_n_mps = EarthModel::c_e_n(lat, lon) * self.v_e;
        self.u_prev = u_k;
        self.c_b_n = self.attitude();
        self.updates += 1;
        self.prev = Increment::new(comp.dtheta_b_rad, comp.dv_b_mps);
    }

    fn state(&self) -> NavState {
        NavState {
            t_s: self.updates as f64 * self.dt_update_s,
            lat_rad: self.lat_rad,
            lon_rad: self.lon_rad,
            h_m: self.h_m,
            v_n_mps: self.v_n_mps,
            c_b_n: self.c_b_n,
        }
    }

    fn hold_vertical(&mut self, h_m: f64, v_d_mps: f64) {
        // Re-seat the U translation at the held height and the G translation so that the
        // inertial velocity carries the held v_D; attitudes are untouched.
        self.h_m = h_m;
        self.v_n_mps.z = v_d_mps;
        let r_e = self
            .earth
            .ecef_from_geodetic(self.lat_rad, self.lon_rad, h_m);
        let c_n_e = EarthModel::c_e_n(self.lat_rad, self.lon_rad).transpose();
        let v_e = c_n_e * self.v_n_mps;
        let c_e_i = self.q_g.r.to_dcm();
        let v_i = c_e_i * (v_e + self.omega_ie_e.cross(&r_e));
        let v_t_i = self.q_t.translation_old();
        let v_g_i = v_i - v_t_i;
        self.q_g.d = Quat::from_parts(0.0, &v_g_i).mul(&self.q_g.r).scale(0.5);
        self.q_u.d = self.q_u.r.mul(&Quat::from_parts(0.0, &r_e)).scale(0.5);
        self.r_e = r_e;
        self.v_e = v_e;
        self.u_prev = c_e_i.transpose() * v_i;
    }
}
