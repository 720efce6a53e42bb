//! Wu's dual-quaternion SDINS (docs/theory/mechanizations.md §"Dual quaternion"; S2 eqs (1)–(13),
//! W).
//!
//! Three unit dual quaternions, all "from I to X":
//! * T (thrust velocity): attitude B, translation `v_t^I = ∫ f^I`, twist `ω_ib^b + ε f^b`;
//! * G (gravitational velocity): attitude E, translation `v_g^I = ṙ^I(0) + ∫ G^I`,
//!   twist `ω_ie^e + ε G^e`;
//! * U (position): attitude E, translation `r^I`, twist `ω_ie^e + ε C_I^E (v_t^I + v_g^I)`.
//!
//! Cost notes: the real part of the G and U screws (`ω_ie^e ΔT`) is constant, so its
//! exponential coefficients are computed once; the mid-point gravitation uses the
//! geodetic position extrapolated from the last update (no iteration; the chord-versus-
//! ellipsoid difference is second order, ~1e-14 rad in direction at Mach 1), and the
//! geodetic output is a warm-started fixed point that contracts by e² sin²L per
//! iteration (one or two iterations in flight).

use super::{DualQuat, InitialState, Mechanization, NavState};
use crate::coning::{compensate, ConingSet, Increment};
use crate::earth::{sin_cos_shift, EarthModel};
use crate::math::{Mat3, Quat, Vec3};

/// Geodetic position with the sines and cosines the mechanization reuses.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Geo {
    lat: f64,
    lon: f64,
    h: f64,
    sl: f64,
    cl: f64,
    so: f64,
    co: f64,
}

impl Geo {
    fn new(lat: f64, lon: f64, h: f64) -> Self {
        Geo {
            lat,
            lon,
            h,
            sl: libm::sin(lat),
            cl: libm::cos(lat),
            so: libm::sin(lon),
            co: libm::cos(lon),
        }
    }
    /// `C_e^n(L, λ)` from the stored sines and cosines.
    fn c_e_n(&self) -> Mat3 {
        let (sl, cl, so, co) = (self.sl, self.cl, self.so, self.co);
        Mat3::new(
            -sl * co,
            -sl * so,
            cl,
            -so,
            co,
            0.0,
            -cl * co,
            -cl * so,
            -sl,
        )
    }
}

/// A rotation quaternion about z, `[c, 0, 0, s]`. The G and U frames share this real
/// part exactly (both start at the identity and turn by `exp(ω_ie^e ΔT)` each update), so
/// their products exploit the sparsity; this is the same algorithm, not an approximation.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ZRot {
    c: f64,
    s: f64,
}

impl ZRot {
    fn quat(self) -> Quat {
        Quat::new(self.c, 0.0, 0.0, self.s)
    }
    /// `self ⊗ p`
    #[inline]
    fn mul_left(self, p: &Quat) -> Quat {
        let (c, s) = (self.c, self.s);
        Quat::new(
            c * p.w - s * p.z,
            c * p.x - s * p.y,
            c * p.y + s * p.x,
            c * p.z + s * p.w,
        )
    }
    /// `p ⊗ self`
    #[inline]
    fn mul_right(self, p: &Quat) -> Quat {
        let (c, s) = (self.c, self.s);
        Quat::new(
            p.w * c - p.z * s,
            p.x * c + p.y * s,
            p.y * c - p.x * s,
            p.z * c + p.w * s,
        )
    }
    /// `C(self)ᵀ v` (= `C_I^E v` for the G/U real part)
    #[inline]
    fn rotate_inv(self, v: &Vec3) -> Vec3 {
        let (c2, s2) = (self.c * self.c - self.s * self.s, 2.0 * self.c * self.s);
        Vec3::new(c2 * v.x + s2 * v.y, -s2 * v.x + c2 * v.y, v.z)
    }
    /// `C(self) v`
    #[inline]
    fn rotate(self, v: &Vec3) -> Vec3 {
        let (c2, s2) = (self.c * self.c - self.s * self.s, 2.0 * self.c * self.s);
        Vec3::new(c2 * v.x - s2 * v.y, s2 * v.x + c2 * v.y, v.z)
    }
}

/// One screw step of a dual quaternion whose real part is the z-rotation `r`:
/// `(r + εd) ⊗ (e_r + εe_d)` with `e_r` also about z; returns the new dual part
/// `r e_d + d e_r` (the new real part is `r e_r`, computed once for G and U).
#[inline]
fn screw_dual(r: ZRot, d: &Quat, e_r: ZRot, e_d: &Quat) -> Quat {
    r.mul_left(e_d).add(&e_r.mul_right(d))
}

/// Dual part of the screw exponential (docs/theory/mechanizations.md §"Dual quaternion") for
/// `σ = [0, 0, x]`: `[−½ s g, g σ' + s h σ]` with `s = σ·σ' = x σ'_z`.
#[inline]
fn dual_of_z_screw(x: f64, sigma_d: &Vec3, g: f64, h: f64) -> Quat {
    let s = x * sigma_d.z;
    Quat::new(
        -0.5 * s * g,
        g * sigma_d.x,
        g * sigma_d.y,
        g * sigma_d.z + s * h * x,
    )
}

/// Make the dual part orthogonal to the real part (`r·d = 0`).
#[inline]
fn orthogonalize(r: ZRot, d: &Quat) -> Quat {
    let dot = r.c * d.w + r.s * d.z;
    Quat::new(d.w - dot * r.c, d.x, d.y, d.z - dot * r.s)
}

/// Dual-quaternion navigation state and configuration.
#[derive(Clone, Debug)]
pub struct DualQuatNav {
    earth: EarthModel,
    coning: ConingSet,
    samples: usize,
    dt_update_s: f64,
    omega_ie_e: Vec3,
    /// exp coefficients of σ = ω_ie^e ΔT
    exp_w: (f64, f64, f64),
    q_t: DualQuat,
    /// common real part of the G and U dual quaternions, `C_E^I = R3(Ω_e t)`: a rotation
    /// about z, stored as its two non-zero components `[cos(Ω_e t/2), sin(Ω_e t/2)]`
    z_rot: ZRot,
    /// dual part of G (`½ v_g^I ⊗ r`)
    d_g: Quat,
    /// dual part of U (`½ r ⊗ r^e`)
    d_u: Quat,
    u_prev: Vec3,
    r_e: Vec3,
    v_e: Vec3,
    geo: Geo,
    v_n_mps: Vec3,
    updates: u64,
    prev: Increment,
}

impl DualQuatNav {
    /// Initialise (docs/theory/mechanizations.md §"Dual quaternion").
    pub fn new(
        earth: EarthModel,
        dt_s: f64,
        samples: usize,
        coning: ConingSet,
        init: &InitialState,
    ) -> Self {
        let omega_ie_e = Vec3::new(0.0, 0.0, earth.omega_ie_rps);
        let geo = Geo::new(init.lat_rad, init.lon_rad, init.h_m);
        let r0 = earth.ecef_from_geodetic(init.lat_rad, init.lon_rad, init.h_m);
        let c_n_e0 = geo.c_e_n().transpose();
        let v_e0 = c_n_e0 * init.v_n_mps;
        let v_i0 = v_e0 + omega_ie_e.cross(&r0);
        let q_t = DualQuat {
            r: Quat::from_dcm(&(c_n_e0 * init.c_b_n)),
            d: Quat::new(0.0, 0.0, 0.0, 0.0),
        };
        let d_g = Quat::from_parts(0.0, &v_i0).scale(0.5);
        let d_u = Quat::from_parts(0.0, &r0).scale(0.5);
        let dt_update_s = dt_s * samples as f64;
        Self {
            earth,
            coning,
            samples,
            dt_update_s,
            omega_ie_e,
            exp_w: DualQuat::exp_coefficients(earth.omega_ie_rps * dt_update_s),
            q_t,
            z_rot: ZRot { c: 1.0, s: 0.0 },
            d_g,
            d_u,
            u_prev: v_i0,
            r_e: r0,
            v_e: v_e0,
            geo,
            v_n_mps: init.v_n_mps,
            updates: 0,
            prev: Increment::default(),
        }
    }

    /// Gravitational (mass-attraction) acceleration in ECEF at the interval mid-point
    /// `r_mid = r_{k−1} + ½ΔT v^e_{k−1}`: `G^e = C_n^e g^n + ω_ie^e × (ω_ie^e × r^e)`
    /// (docs/theory/mechanizations.md §"Earth model"; docs/theory/mechanizations.md
    /// §"Dual quaternion" step 2), with the mid-point's geodetic coordinates extrapolated from the
    /// last update's.
    fn gravitation_mid(&self, r_mid: &Vec3, le0: &crate::earth::LocalEarth) -> Vec3 {
        let e = &self.earth;
        let g0 = &self.geo;
        let half = 0.5 * self.dt_update_s;
        let v = &self.v_n_mps;
        let dlat = half * v.x / (le0.r_m_m + g0.h);
        let (sl, cl) = sin_cos_shift(g0.sl, g0.cl, dlat);
        let dlon = if libm::fabs(g0.cl) > 1e-9 {
            half * v.y / ((le0.r_n_m + g0.h) * g0.cl)
        } else {
            0.0
        };
        let (so, co) = sin_cos_shift(g0.so, g0.co, dlon);
        let le = e.local_sc(sl, cl, g0.h - half * v.z);
        // C_n^e [0, 0, g] = g · (third row of C_e^n)
        let down_e = Vec3::new(-cl * co, -cl * so, -sl);
        // ω×(ω×r) with ω = Ω ẑ is −Ω² [x, y, 0]
        let w2 = self.earth.omega_ie_rps * self.earth.omega_ie_rps;
        down_e * le.g_mps2 - Vec3::new(w2 * r_mid.x, w2 * r_mid.y, 0.0)
    }

    fn attitude(&self, c_e_n: &Mat3) -> Mat3 {
        c_e_n * self.z_rot.quat().to_dcm().transpose() * self.q_t.r.to_dcm()
    }
}

/// Geodetic from ECEF by the fixed point `L ← atan2(z, p(1 − e² R_N/(R_N + h)))`, warm
/// started at `lat_hint`; it contracts by about e² sin²L ≤ 0.0067 per iteration, so it stops
/// when a step is below 1e-14 rad (the remaining error is then below 1e-16 rad). The cold
/// start of [`EarthModel::geodetic_from_ecef`] is used near the polar axis.
fn geodetic_warm(e: &EarthModel, r: &Vec3, lat_hint: f64) -> Geo {
    let p = libm::sqrt(r.x * r.x + r.y * r.y);
    if p < 1e3 || !lat_hint.is_finite() {
        let (lat, lon, h) = e.geodetic_from_ecef(r);
        return Geo::new(lat, lon, h);
    }
    let (so, co) = (r.y / p, r.x / p);
    let mut lat = lat_hint;
    let (mut sl, mut cl) = (libm::sin(lat), libm::cos(lat));
    for _ in 0..8 {
        let rn = e.radii_sin(sl).r_n_m;
        let h = p / cl - rn;
        let next = libm::atan2(r.z, p * (1.0 - e.e2 * rn / (rn + h)));
        let step = next - lat;
        (sl, cl) = sin_cos_shift(sl, cl, step);
        lat = next;
        if libm::fabs(step) < 1e-14 {
            break;
        }
    }
    // well conditioned at every latitude: h = p cosL + z sinL − a√(1 − e² sin²L)
    let h = p * cl + r.z * sl - e.a_m * libm::sqrt(1.0 - e.e2 * sl * sl);
    Geo {
        lat,
        lon: libm::atan2(r.y, r.x),
        h,
        sl,
        cl,
        so,
        co,
    }
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
        let (cw, gw, hw) = self.exp_w;
        let sig_w = self.omega_ie_e * dt;

        // 1. T frame: dual coning of Δθ̂_j = Δθ_j + εΔv_j
        let sig_t = comp.dphi_b_rad;
        let sig_t_d = comp.dv_b_mps + comp.dv_scul_b_mps;
        self.q_t = self.q_t.mul(&DualQuat::exp(&sig_t, &sig_t_d)).normalized();

        // 2. G frame: mid-point gravitation. G and U share the real part r (a z-rotation)
        //    and the real part of their screw, e_r = [cos(x/2), g(x)·ΩΔT ẑ].
        let r_mid = self.r_e + 0.5 * dt * self.v_e;
        let le0 = self.earth.local_sc(self.geo.sl, self.geo.cl, self.geo.h);
        let g_mid = self.gravitation_mid(&r_mid, &le0);
        let e_r = ZRot {
            c: cw,
            s: gw * sig_w.z,
        };
        let e_g = dual_of_z_screw(sig_w.z, &(g_mid * dt), gw, hw);
        let r_old = self.z_rot;
        // new real part, renormalised; the dual parts are divided by the same norm so that
        // the translations 2 d ⊗ r* are unchanged by the renormalisation
        let (r_new, inv_n) = {
            let q = r_old.mul_left(&e_r.quat());
            let inv_n = 1.0 / libm::sqrt(q.w * q.w + q.z * q.z);
            (
                ZRot {
                    c: q.w * inv_n,
                    s: q.z * inv_n,
                },
                inv_n,
            )
        };
        self.d_g = orthogonalize(r_new, &screw_dual(r_old, &self.d_g, e_r, &e_g).scale(inv_n));

        // 3. inertial velocity resolved in E, and the U frame
        let v_t_i = self.q_t.translation_old();
        // v_g^I = 2 d_G ⊗ r*  (vector part)
        let v_g_i = {
            let q = ZRot {
                c: r_new.c,
                s: -r_new.s,
            }
            .mul_right(&self.d_g);
            q.vec() * 2.0
        };
        let u_k = r_new.rotate_inv(&(v_t_i + v_g_i));
        let du = u_k - self.u_prev;
        let w_cross_du = Vec3::new(-self.omega_ie_e.z * du.y, self.omega_ie_e.z * du.x, 0.0);
        let sig_u_d = 0.5 * (self.u_prev + u_k) * dt + (dt * dt / 12.0) * w_cross_du;
        let e_u = dual_of_z_screw(sig_w.z, &sig_u_d, gw, hw);
        self.d_u = orthogonalize(r_new, &screw_dual(r_old, &self.d_u, e_r, &e_u).scale(inv_n));
        self.z_rot = r_new;
        let c_i_e_t = r_new; // kept for the attitude below

        // 4. outputs; the latitude is predicted to start the geodetic fixed point
        // r^e = 2 r* ⊗ d_U (vector part)
        self.r_e = ZRot {
            c: r_new.c,
            s: -r_new.s,
        }
        .mul_left(&self.d_u)
        .vec()
            * 2.0;
        let lat_pred = self.geo.lat + dt * self.v_n_mps.x / (le0.r_m_m + self.geo.h);
        self.geo = geodetic_warm(&self.earth, &self.r_e, lat_pred);
        self.v_e = u_k
            - Vec3::new(
                -self.omega_ie_e.z * self.r_e.y,
                self.omega_ie_e.z * self.r_e.x,
                0.0,
            );
        let c_e_n = self.geo.c_e_n();
        self.v_n_mps = c_e_n * self.v_e;
        self.u_prev = u_k;
        let _ = c_i_e_t; // the attitude C_e^n C_I^E C_B^I is formed on demand in state()
        self.updates += 1;
        self.prev = Increment::new(comp.dtheta_b_rad, comp.dv_b_mps);
    }

    fn state(&self) -> NavState {
        NavState {
            t_s: self.updates as f64 * self.dt_update_s,
            lat_rad: self.geo.lat,
            lon_rad: self.geo.lon,
            h_m: self.geo.h,
            v_n_mps: self.v_n_mps,
            c_b_n: self.attitude(&self.geo.c_e_n()),
        }
    }

    fn correct_state(&mut self, s: &NavState) {
        // Re-initialise at the corrected state: the inertial frame is re-defined to
        // coincide with the earth frame at this instant (any fixed i frame is valid);
        // the time and the previous-sample memory are kept.
        let (updates, prev) = (self.updates, self.prev);
        let init = InitialState {
            lat_rad: s.lat_rad,
            lon_rad: s.lon_rad,
            h_m: s.h_m,
            v_n_mps: s.v_n_mps,
            c_b_n: s.c_b_n,
        };
        let dt_s = self.dt_update_s / self.samples.max(1) as f64;
        *self = DualQuatNav::new(self.earth, dt_s, self.samples, self.coning, &init);
        self.updates = updates;
        self.prev = prev;
    }

    fn hold_vertical(&mut self, h_m: f64, v_d_mps: f64) {
        // Re-seat the U translation at the held height and the G translation so that the
        // inertial velocity carries the held v_D; attitudes are untouched.
        self.geo.h = h_m;
        self.v_n_mps.z = v_d_mps;
        let r_e = self
            .earth
            .ecef_from_geodetic(self.geo.lat, self.geo.lon, h_m);
        let c_n_e = self.geo.c_e_n().transpose();
        let v_e = c_n_e * self.v_n_mps;
        let r = self.z_rot;
        let v_i = r.rotate(&(v_e + self.omega_ie_e.cross(&r_e)));
        let v_t_i = self.q_t.translation_old();
        let v_g_i = v_i - v_t_i;
        self.d_g = r.mul_right(&Quat::from_parts(0.0, &v_g_i)).scale(0.5);
        self.d_u = r.mul_left(&Quat::from_parts(0.0, &r_e)).scale(0.5);
        self.r_e = r_e;
        self.v_e = v_e;
        self.u_prev = r.rotate_inv(&v_i);
    }
}
