//! The 12-state stationary alignment error model (docs/theory/alignment.md §"Fine alignment";
//! docs/theory/alignment.md §"Observability at one heading"; docs/theory/alignment.md
//! §"Multi-heading alignment").
//!
//! State (convention G, residual biases):
//! `x = [δv_N, δv_E, δv_D, φ_N, φ_E, φ_D, δa (3), ε (3)]`, with the bias states either
//! NED-resolved (docs/theory/alignment.md §"Fine alignment", \[P1\]) or body-frame
//! (docs/theory/alignment.md §"Multi-heading alignment", needed across rotations).

use super::Site;
use crate::math::{skew, Mat3};
use nalgebra::{SMatrix, SVector};

/// 12×12 matrix.
pub type Mat12 = SMatrix<f64, 12, 12>;
/// 12-vector.
pub type Vec12 = SVector<f64, 12>;
/// 9×9 matrix (pseudo model).
pub type Mat9 = SMatrix<f64, 9, 9>;

/// Frame in which the bias states are kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BiasFrame {
    /// NED-resolved `δa = C_b^n b_a`, `ε = C_b^n b_g` (docs/theory/alignment.md §"Fine alignment";
    /// single heading only — docs/theory/alignment.md §"Multi-heading alignment" shows it fails
    /// across rotations)
    Ned,
    /// body-frame residuals, bias blocks `Ĉ_b^n(t)` (docs/theory/alignment.md
    /// §"Multi-heading alignment" Algorithm A)
    Body,
}

/// Continuous system matrix F (docs/theory/alignment.md §"Fine alignment"; docs/theory/alignment.md
/// §"Multi-heading alignment"):
///
/// ```text
/// δv̇ = g^n × φ − 2 ω_ie^n × δv + B δa
/// φ̇  = −ω_ie^n × φ + B ε            B = I3 (NED states) or Ĉ_b^n (body states)
/// F = [ −2[ω_ie×]  [g^n×]  B  0 ;  0  −[ω_ie×]  0  B ;  0 ; 0 ]
/// ```
///
/// `[g^n×]` is the F12 block `[[0, −g, 0], [g, 0, 0], [0, 0, 0]]` (equivalently `φ × f^n`
/// with `f^n = −g^n`; docs/theory/alignment.md §"Multi-heading alignment" allows `f^n = Ĉ f̂`,
/// which equals `−g^n` at rest).
pub fn f_matrix(site: &Site, frame: BiasFrame, c_b_n: &Mat3) -> Mat12 {
    let w = skew(&site.omega_ie_n());
    let gx = skew(&site.g_n());
    let b = match frame {
        BiasFrame::Ned => Mat3::identity(),
        BiasFrame::Body => *c_b_n,
    };
    let mut f = Mat12::zeros();
    f.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-2.0 * w));
    f.fixed_view_mut::<3, 3>(0, 3).copy_from(&gx);
    f.fixed_view_mut::<3, 3>(0, 6).copy_from(&b);
    f.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-w));
    f.fixed_view_mut::<3, 3>(3, 9).copy_from(&b);
    f
}

/// Zero-velocity measurement matrix `H = [I3 0]` (docs/theory/alignment.md §"Fine alignment"), 3
/// rows.
pub fn h_zupt() -> SMatrix<f64, 3, 12> {
    let mut h = SMatrix::<f64, 3, 12>::zeros();
    h.fixed_view_mut::<3, 3>(0, 0).copy_from(&Mat3::identity());
    h
}

/// Horizontal-only measurement `H = [I2 0]` (docs/theory/alignment.md §"Fine alignment"; it loses
/// rank: §"Observability at one heading").
pub fn h_horizontal() -> SMatrix<f64, 2, 12> {
    let mut h = SMatrix::<f64, 2, 12>::zeros();
    h[(0, 0)] = 1.0;
    h[(1, 1)] = 1.0;
    h
}

/// Continuous process-noise PSD `Q_c = diag(VRW² I3, ARW² I3, q_ba I3, q_bg I3)`
/// (docs/theory/alignment.md §"Fine alignment"); `vrw` \[m/s/√s\], `arw` \[rad/√s\], `q_ba`
/// \[(m/s²)²/s\], `q_bg` \[(rad/s)²/s\].
pub fn q_continuous(vrw: f64, arw: f64, q_ba: f64, q_bg: f64) -> Mat12 {
    let mut d = Vec12::zeros();
    for i in 0..3 {
        d[i] = vrw * vrw;
        d[3 + i] = arw * arw;
        d[6 + i] = q_ba;
        d[9 + i] = q_bg;
    }
    Mat12::from_diagonal(&d)
}

/// Discretisation used for the acceptance numbers (docs/theory/alignment.md §"Fine alignment",
/// "allowed simplification"): `Φ = I + FΔt + (FΔt)²/2 + (FΔt)³/6`, `Q_d = ½(Φ Q_c Φᵀ + Q_c) Δt`.
pub fn discretize(f: &Mat12, qc: &Mat12, dt: f64) -> (Mat12, Mat12) {
    let a = f * dt;
    let a2 = a * a;
    let phi = Mat12::identity() + a + a2 * 0.5 + a2 * a * (1.0 / 6.0);
    let qd = (phi * qc * phi.transpose() + qc) * (0.5 * dt);
    (phi, qd)
}

/// The exact null space of the single-heading observability matrix with NED bias states
/// (docs/theory/alignment.md §"Observability at one heading"), as columns:
///
/// ```text
/// n1: φ_N = 1, φ_D = −tan L, δa_E = −g
/// n2: φ_D = 1, ε_E = −Ω cos L
/// n3: φ_E = 1, δa_N = g, ε_N = Ω sin L, ε_D = Ω cos L
/// ```
pub fn null_space_ned(site: &Site) -> SMatrix<f64, 12, 3> {
    let mut n = SMatrix::<f64, 12, 3>::zeros();
    let g = site.g_mps2;
    n[(3, 0)] = 1.0;
    n[(5, 0)] = -site.tan_lat();
    n[(7, 0)] = -g;
    n[(5, 1)] = 1.0;
    n[(10, 1)] = -site.omega_n();
    n[(4, 2)] = 1.0;
    n[(6, 2)] = g;
    n[(9, 2)] = -site.omega_d(); // Ω sin L
    n[(11, 2)] = site.omega_n();
    n
}

/// The same null space for body-frame bias states at attitude `c_b_n`: bias blocks
/// mapped by `C_b^nᵀ`.
pub fn null_space_body(site: &Site, c_b_n: &Mat3) -> SMatrix<f64, 12, 3> {
    let mut n = null_space_ned(site);
    let ct = c_b_n.transpose();
    for j in 0..3 {
        let a = ct * n.fixed_view::<3, 1>(6, j).into_owned();
        let e = ct * n.fixed_view::<3, 1>(9, j).into_owned();
        n.fixed_view_mut::<3, 1>(6, j).copy_from(&a);
        n.fixed_view_mut::<3, 1>(9, j).copy_from(&e);
    }
    n
}

/// Pseudo (observable) coordinates `p = T x` of docs/theory/alignment.md
/// §"Observability at one heading" (NED bias states), `p = [φ'_N, φ'_E, φ'_D, ε'_N, ε'_D, δa_D]`:
///
/// ```text
/// φ'_N = φ_N + δa_E/g          φ'_E = φ_E − δa_N/g
/// φ'_D = φ_D + ε_E/(Ω cos L) − tan L · δa_E/g
/// ε'_N = ε_N − Ω sin L · δa_N/g     ε'_D = ε_D − Ω cos L · δa_N/g     δa_D
/// ```
pub fn pseudo_transform(site: &Site) -> SMatrix<f64, 6, 12> {
    let g = site.g_mps2;
    let mut t = SMatrix::<f64, 6, 12>::zeros();
    t[(0, 3)] = 1.0;
    t[(0, 7)] = 1.0 / g;
    t[(1, 4)] = 1.0;
    t[(1, 6)] = -1.0 / g;
    t[(2, 5)] = 1.0;
    t[(2, 10)] = 1.0 / site.omega_n();
    t[(2, 7)] = -site.tan_lat() / g;
    t[(3, 9)] = 1.0;
    t[(3, 6)] = site.omega_d() / g; // −Ω sin L / g
    t[(4, 11)] = 1.0;
    t[(4, 6)] = -site.omega_n() / g;
    t[(5, 8)] = 1.0;
    t
}

/// The 9 observable coordinates `[δv (3), p (6)]` (docs/theory/alignment.md
/// §"Observability at one heading" pseudo 9-state vector).
pub fn pseudo9_transform(site: &Site) -> SMatrix<f64, 9, 12> {
    let mut t = SMatrix::<f64, 9, 12>::zeros();
    t.fixed_view_mut::<3, 3>(0, 0).copy_from(&Mat3::identity());
    t.fixed_view_mut::<6, 12>(3, 0)
        .copy_from(&pseudo_transform(site));
    t
}

/// Pseudo 9-state model of docs/theory/alignment.md §"Observability at one heading", state
/// `[δv (3), φ'_N, φ'_E, φ'_D, δa_D, ε'_N, ε'_D]`:
///
/// ```text
/// δv̇_N = 2Ω_D δv_E − g φ'_E             φ̇'_N = Ω_D φ'_E + ε'_N
/// δv̇_E = −2Ω_D δv_N + 2Ω_N δv_D + g φ'_N φ̇'_E = −Ω_D φ'_N + Ω_N φ'_D
/// δv̇_D = −2Ω_N δv_E + δa_D              φ̇'_D = −Ω_N φ'_E + ε'_D
/// ```
pub fn f_pseudo9(site: &Site) -> Mat9 {
    let (on, od, g) = (site.omega_n(), site.omega_d(), site.g_mps2);
    let mut f = Mat9::zeros();
    f[(0, 1)] = 2.0 * od;
    f[(0, 4)] = -g;
    f[(1, 0)] = -2.0 * od;
    f[(1, 2)] = 2.0 * on;
    f[(1, 3)] = g;
    f[(2, 1)] = -2.0 * on;
    f[(2, 6)] = 1.0;
    f[(3, 4)] = od;
    f[(3, 7)] = 1.0;
    f[(4, 3)] = -od;
    f[(4, 5)] = on;
    f[(5, 4)] = -on;
    f[(5, 8)] = 1.0;
    f
}

/// Finite-prior asymptotic residual projector (docs/theory/alignment.md
/// §"Observability at one heading"): `Π = N (Nᵀ P0⁻¹ N)⁻¹ Nᵀ P0⁻¹`, so that the converged true
/// error is `x_res = Π x0`. `None` if P0 or the 3×3 Gram matrix is singular.
pub fn residual_projector(null: &SMatrix<f64, 12, 3>, p0: &Mat12) -> Option<Mat12> {
    let p0i = p0.try_inverse()?;
    let m = null.transpose() * p0i * null;
    let mi = m.try_inverse()?;
    Some(null * mi * null.transpose() * p0i)
}

/// Reference initial covariance of docs/theory/alignment.md §"Fine alignment":
/// `P0 = diag((0.1 m/s)² I3, (1 mrad)², (1 mrad)², (10 mrad)², (100 μg)² I3, (0.02 °/h)² I3)`.
pub fn p0_reference() -> Mat12 {
    let ug = 9.80665e-6;
    let dph = core::f64::consts::PI / 180.0 / 3600.0;
    let s = [
        0.1,
        0.1,
        0.1,
        1e-3,
        1e-3,
        10e-3,
        100.0 * ug,
        100.0 * ug,
        100.0 * ug,
        0.02 * dph,
        0.02 * dph,
        0.02 * dph,
    ];
    Mat12::from_diagonal(&Vec12::from_fn(|i, _| s[i] * s[i]))
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    fn site() -> Site {
        Site {
            lat_rad: 37.5_f64.to_radians(),
            g_mps2: 9.799490523606893,
            omega_ie_rps: 7.292115e-5,
        }
    }

    /// docs/theory/alignment.md §"Observability at one heading": every null vector is an
    /// equilibrium, F n = 0, and T n = 0.
    #[test]
    fn null_vectors_are_equilibria_and_pseudo_blind() {
        let s = site();
        let f = f_matrix(&s, BiasFrame::Ned, &Mat3::identity());
        let n = null_space_ned(&s);
        assert!((f * n).abs().max() < 1e-12);
        assert!((pseudo_transform(&s) * n).abs().max() < 1e-15);
        let c = crate::math::dcm_from_rotvec(&crate::math::Vec3::new(0.03, -0.05, 0.7));
        let fb = f_matrix(&s, BiasFrame::Body, &c);
        assert!((fb * null_space_body(&s, &c)).abs().max() < 1e-12);
    }

    /// The pseudo model is the projection of the 12-state model: T9 F = F9 T9
    /// (with the pseudo-9 state order \[δv, φ', δa_D, ε'_N, ε'_D\]).
    #[test]
    fn pseudo_model_is_consistent() {
        let s = site();
        let f = f_matrix(&s, BiasFrame::Ned, &Mat3::identity());
        let t6 = pseudo_transform(&s);
        // reorder p = [φ', ε'_N, ε'_D, δa_D] to [φ', δa_D, ε'_N, ε'_D]
        let mut t = SMatrix::<f64, 9, 12>::zeros();
        t.fixed_view_mut::<3, 3>(0, 0).copy_from(&Mat3::identity());
        for (dst, src) in [(3, 0), (4, 1), (5, 2), (6, 5), (7, 3), (8, 4)] {
            t.row_mut(dst).copy_from(&t6.row(src));
        }
        let lhs = t * f;
        let rhs = f_pseudo9(&s) * t;
        assert!(
            (lhs - rhs).abs().max() < 1e-12,
            "{}",
            (lhs - rhs).abs().max()
        );
    }
}
