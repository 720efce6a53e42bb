//! The linear INS error model `ẋ = F x + G w` in the local-navigation frame (Groves 2nd ed.
//! §14.2.4, eqs. (14.64)–(14.70); phi-angle form), shared by the error analysis of
//! `sdins-sim` and the INS/GNSS filter ([`super::ekf`]).
//!
//! ## State (estimate − truth), order and units
//! | index | state | unit |
//! |---|---|---|
//! | 0, 1, 2 | δL, δλ, δh (curvilinear position error, h up) | rad, rad, m |
//! | 3, 4, 5 | δv^n (N, E, D) | m/s |
//! | 6, 7, 8 | ε (N, E, D), convention G: `Ĉ_b^n = (I + [ε×]) C_b^n` | rad |
//! | 9, 10, 11 | accelerometer bias (error of the compensated specific force), body | m/s² |
//! | 12, 13, 14 | gyro bias (error of the compensated angular rate), body | rad/s |
//! | 15, 16, 17 | accelerometer scale-factor error `s − ŝ` (21-state filter only), body | 1 |
//! | 18, 19, 20 | gyro scale-factor error `s − ŝ` (21-state filter only), body | 1 |
//!
//! The scale-factor states enter as `δf^b = diag(f^b) δs_a`, `δω^b = diag(ω_ib^b) δs_g`
//! (Groves 2nd ed. §14.2, "additional IMU error states": the accelerometer and gyro error states of the
//! "scale-factor" model; the sensor model is `f̃ = (1 + s) f + b` per axis, compensated
//! as `f̂ = (f̃ − b̂)/(1 + ŝ)`, so that `f̂ − f ≈ diag(f)(s − ŝ) + (b − b̂)`).
//!
//! Groves' δψ^n_nb is the same attitude convention (`Ĉ Cᵀ ≈ I + [δψ×]`).
//!
//! ## Blocks (R_M meridian, R_N prime-vertical radius, dR/dL neglected)
//! * attitude: `ε̇ = −[ω_in^n×] ε − δω_in^n + C_b^n b_g`, `ω_in = ω_ie + ω_en`;
//! * velocity: `δv̇ = −[f^n×] ε − [(2ω_ie + ω_en)×] δv + [v×](2δω_ie + δω_en) + δg + C_b^n b_a`,
//!   `δg = [0, 0, −2g/r_eS δh]` (vertical gravity gradient, Groves (14.69));
//! * position: `δL̇ = δv_N/(R_M+h) − v_N δh/(R_M+h)²`,
//!   `δλ̇ = δv_E/((R_N+h)cos L) + v_E sin L/((R_N+h)cos²L) δL − v_E δh/((R_N+h)² cos L)`,
//!   `δḣ = −δv_D`;
//! * biases: zero rows here (random constants); the filter adds its Gauss–Markov terms.

use crate::earth::EarthModel;
use crate::math::{skew, Mat3, Vec3};
use nalgebra::{SMatrix, SVector};

/// Number of states of the navigation-error model (position, velocity, attitude, biases).
pub const N_STATES: usize = 15;
/// Number of states with the accelerometer and gyro scale factors.
pub const N_STATES_SF: usize = 21;
/// State vector.
pub type StateVec = SVector<f64, N_STATES>;
/// State matrix (F, Φ, P, Q).
pub type StateMat = SMatrix<f64, N_STATES, N_STATES>;
/// State vector of an `N`-state filter (15 or 21).
pub type StateVecN<const N: usize> = SVector<f64, N>;
/// State matrix of an `N`-state filter (15 or 21).
pub type StateMatN<const N: usize> = SMatrix<f64, N, N>;
/// Index of the first position state (δL).
pub const I_POS: usize = 0;
/// Index of the first velocity state.
pub const I_VEL: usize = 3;
/// Index of the first attitude state.
pub const I_ATT: usize = 6;
/// Index of the first accelerometer-bias state.
pub const I_BA: usize = 9;
/// Index of the first gyro-bias state.
pub const I_BG: usize = 12;
/// Index of the first accelerometer scale-factor state (21-state filter).
pub const I_SA: usize = 15;
/// Index of the first gyro scale-factor state (21-state filter).
pub const I_SG: usize = 18;

/// Everything the F matrix depends on at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelPoint {
    /// sin L, cos L of the latitude
    pub sin_cos_lat: (f64, f64),
    /// height \[m\]
    pub h_m: f64,
    /// NED velocity \[m/s\]
    pub v_n_mps: Vec3,
    /// attitude body → NED (maps the body-frame bias states)
    pub c_b_n: Mat3,
    /// specific force in NED \[m/s²\]
    pub f_n_mps2: Vec3,
    /// meridian radius R_M \[m\]
    pub r_m_m: f64,
    /// prime-vertical radius R_N \[m\]
    pub r_n_m: f64,
    /// gravity magnitude \[m/s²\]
    pub g_mps2: f64,
    /// earth rate Ω \[rad/s\]
    pub omega_ie_rps: f64,
    /// geocentric radius of the surface r_eS (Groves (2.137)) \[m\]
    pub r_es_m: f64,
}

impl ModelPoint {
    /// The point on an ellipsoidal earth model at latitude `lat_rad` (sin/cos by libm).
    pub fn on_earth(
        earth: &EarthModel,
        lat_rad: f64,
        h_m: f64,
        v_n_mps: Vec3,
        c_b_n: Mat3,
        f_n_mps2: Vec3,
    ) -> Self {
        let (s, c) = libm::sincos(lat_rad);
        let r = earth.radii(lat_rad);
        let q = 1.0 - earth.e2;
        Self {
            sin_cos_lat: (s, c),
            h_m,
            v_n_mps,
            c_b_n,
            f_n_mps2,
            r_m_m: r.r_m_m,
            r_n_m: r.r_n_m,
            g_mps2: earth.gravity(lat_rad, h_m),
            omega_ie_rps: earth.omega_ie_rps,
            r_es_m: r.r_n_m * libm::sqrt(c * c + q * q * s * s),
        }
    }
}

/// F of the navigation-error model at one point. `bias_states = false` zeroes the bias
/// columns (9-state model); `vertical_held` zeroes the δh and δv_D rows.
pub fn f_matrix(p: &ModelPoint, bias_states: bool, vertical_held: bool) -> StateMat {
    let (h, v) = (p.h_m, p.v_n_mps);
    let (sl, cl) = p.sin_cos_lat;
    let tl = sl / cl;
    let (rmh, rnh) = (p.r_m_m + h, p.r_n_m + h);
    let om = p.omega_ie_rps;
    let g = p.g_mps2;
    let (c_b_n, f_n) = (p.c_b_n, p.f_n_mps2);

    let w_ie = Vec3::new(om * cl, 0.0, -om * sl);
    let w_en = Vec3::new(v.y / rnh, -v.x / rmh, -v.y * tl / rnh);
    let w_in = w_ie + w_en;
    // ∂ω_en/∂v
    let a_v = Mat3::new(
        0.0,
        1.0 / rnh,
        0.0,
        -1.0 / rmh,
        0.0,
        0.0,
        0.0,
        -tl / rnh,
        0.0,
    );
    // ∂ω_ie/∂(L, λ, h) and ∂ω_en/∂(L, λ, h)
    let d_ie = Mat3::new(-om * sl, 0.0, 0.0, 0.0, 0.0, 0.0, -om * cl, 0.0, 0.0);
    let d_en = Mat3::new(
        0.0,
        0.0,
        -v.y / (rnh * rnh),
        0.0,
        0.0,
        v.x / (rmh * rmh),
        -v.y / (rnh * cl * cl),
        0.0,
        v.y * tl / (rnh * rnh),
    );
    let vx = skew(&v);

    let mut f = StateMat::zeros();
    // position rows
    f[(0, I_VEL)] = 1.0 / rmh;
    f[(0, 2)] = -v.x / (rmh * rmh);
    f[(1, I_VEL + 1)] = 1.0 / (rnh * cl);
    f[(1, 0)] = v.y * sl / (rnh * cl * cl);
    f[(1, 2)] = -v.y / (rnh * rnh * cl);
    f[(2, I_VEL + 2)] = -1.0;
    // velocity rows
    f.fixed_view_mut::<3, 3>(I_VEL, I_ATT)
        .copy_from(&(-skew(&f_n)));
    f.fixed_view_mut::<3, 3>(I_VEL, I_VEL)
        .copy_from(&(-skew(&(2.0 * w_ie + w_en)) + vx * a_v));
    let mut f_vp = vx * (2.0 * d_ie + d_en);
    f_vp[(2, 2)] += -2.0 * g / p.r_es_m;
    f.fixed_view_mut::<3, 3>(I_VEL, I_POS).copy_from(&f_vp);
    // attitude rows
    f.fixed_view_mut::<3, 3>(I_ATT, I_ATT)
        .copy_from(&(-skew(&w_in)));
    f.fixed_view_mut::<3, 3>(I_ATT, I_VEL).copy_from(&(-a_v));
    f.fixed_view_mut::<3, 3>(I_ATT, I_POS)
        .copy_from(&(-(d_ie + d_en)));
    if bias_states {
        f.fixed_view_mut::<3, 3>(I_VEL, I_BA).copy_from(&c_b_n);
        f.fixed_view_mut::<3, 3>(I_ATT, I_BG).copy_from(&c_b_n);
    }
    if vertical_held {
        f.row_mut(2).fill(0.0);
        f.row_mut(I_VEL + 2).fill(0.0);
    }
    f
}

/// `Φ = I + A + A²/2 + A³/6`, `A = F Δt` (third-order Taylor series, Horner form; Groves
/// (3.34) truncated; the bias → ε → δv → δp chain is nilpotent of length 3 and is
/// integrated exactly).
pub fn transition<const N: usize>(f: &StateMatN<N>, dt: f64) -> StateMatN<N> {
    let a = f * dt;
    let i = StateMatN::<N>::identity();
    i + a * (i + a * (i + a / 3.0) / 2.0)
}

/// Position scale `T = diag(R_M + h, (R_N + h) cos L, −1)`: `δp_NED = T (δL, δλ, δh)` \[m\].
pub fn position_scale(r_m_m: f64, r_n_m: f64, cos_lat: f64, h_m: f64) -> Vec3 {
    Vec3::new(r_m_m + h_m, (r_n_m + h_m) * cos_lat, -1.0)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn f_blocks_stationary() {
        let e = EarthModel::WGS84;
        let lat = 0.6;
        let g = e.gravity(lat, 0.0);
        let p = ModelPoint::on_earth(
            &e,
            lat,
            0.0,
            Vec3::zeros(),
            Mat3::identity(),
            Vec3::new(0.0, 0.0, -g),
        );
        let f = f_matrix(&p, true, false);
        // δv̇_N = −(f×ε)_N = f_D ε_E... −[f×] with f = (0,0,−g): row N, col E = −(−f_D) = f_D
        assert_eq!(f[(I_VEL, I_ATT + 1)], -g);
        assert_eq!(f[(I_VEL + 1, I_ATT)], g);
        assert_eq!(f[(2, I_VEL + 2)], -1.0);
        assert_eq!(f[(I_VEL, I_BA)], 1.0);
        assert_eq!(f[(I_ATT + 2, I_BG + 2)], 1.0);
        let fh = f_matrix(&p, false, true);
        assert_eq!(fh[(I_VEL, I_BA)], 0.0);
        assert_eq!(fh.row(2).norm(), 0.0);
    }

    #[test]
    fn transition_is_exact_for_nilpotent_chain() {
        // pure chain b → ε → δv → δp: Φ from the cubic series equals exp(FΔt)
        let mut f = StateMat::zeros();
        f[(I_ATT, I_BG)] = 1.0;
        f[(I_VEL + 1, I_ATT)] = 2.0;
        f[(1, I_VEL + 1)] = 3.0;
        let phi = transition(&f, 2.0);
        // δp_E(t) = 3·2·b·t³/6 = t³ b
        assert!((phi[(1, I_BG)] - 8.0).abs() < 1e-12);
    }
}
