//! The transport matrix `T(L, l, t) = C_{n0ⁱ}^{n(t)} = C_e^n(L, l + Ω_e t) C_e^n(L0, l0)ᵀ`
//! (docs/theory/mechanizations.md §"Attitude by DCM separation", S1 eq. (32), corrected).

use crate::math::Mat3;

/// S1 eq. (32) with `Δ = (l − l0) + Ω_e t`:
///
/// ```text
/// T = [ sL sL0 cΔ + cL cL0    −sL sΔ    sL cL0 cΔ − cL sL0
///       sL0 sΔ                 cΔ       cL0 sΔ
///       cL sL0 cΔ − sL cL0    −cL sΔ    cL cL0 cΔ + sL sL0 ]
/// ```
///
/// `sin/cos(L0)` are passed precomputed; `delta_rad` = l − l0 + Ω_e t.
#[inline]
pub fn transport_matrix(lat_rad: f64, s_l0: f64, c_l0: f64, delta_rad: f64) -> Mat3 {
    let (sl, cl) = (libm::sin(lat_rad), libm::cos(lat_rad));
    transport_matrix_sc(sl, cl, s_l0, c_l0, delta_rad)
}

/// [`transport_matrix`] from precomputed `sin L`, `cos L`.
#[inline]
pub fn transport_matrix_sc(sl: f64, cl: f64, s_l0: f64, c_l0: f64, delta_rad: f64) -> Mat3 {
    let (sd, cd) = (libm::sin(delta_rad), libm::cos(delta_rad));
    transport_matrix_trig(sl, cl, s_l0, c_l0, sd, cd)
}

/// [`transport_matrix`] from precomputed `sin L`, `cos L`, `sin Δ`, `cos Δ` (no
/// trigonometry: the mechanizations carry these along the trajectory).
#[inline]
pub fn transport_matrix_trig(sl: f64, cl: f64, s_l0: f64, c_l0: f64, sd: f64, cd: f64) -> Mat3 {
    Mat3::new(
        sl * s_l0 * cd + cl * c_l0,
        -sl * sd,
        sl * c_l0 * cd - cl * s_l0,
        s_l0 * sd,
        cd,
        c_l0 * sd,
        cl * s_l0 * cd - sl * c_l0,
        -cl * sd,
        cl * c_l0 * cd + sl * s_l0,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::EarthModel;
    use crate::math::{skew, Vec3};

    #[test]
    fn equals_c_e_n_product_and_is_orthonormal() {
        let (l0, lon0) = (0.65_f64, 2.2_f64);
        let (l, lon, t) = (0.66_f64, 2.25_f64, 1234.5_f64);
        let w = 7.292115e-5;
        let tm = transport_matrix(l, l0.sin(), l0.cos(), lon - lon0 + w * t);
        let reference = EarthModel::c_e_n(l, lon + w * t) * EarthModel::c_e_n(l0, lon0).transpose();
        assert!((tm - reference).abs().max() < 1e-15);
        assert!((tm * tm.transpose() - Mat3::identity()).abs().max() < 1e-15);
        assert!((tm.determinant() - 1.0).abs() < 1e-15);
        let id = transport_matrix(l0, l0.sin(), l0.cos(), 0.0);
        assert!((id - Mat3::identity()).abs().max() < 1e-16);
    }

    #[test]
    fn derivative_is_minus_omega_in() {
        // Unit check: Ṫ Tᵀ = −[(ω_ie + ω_en)×] for a vehicle moving over the ellipsoid.
        let e = EarthModel::WGS84;
        let (l0, lon0, h) = (0.6_f64, 2.0_f64, 0.0);
        let v = Vec3::new(150.0, 300.0, 0.0);
        let (lat, lon, t) = (0.61_f64, 2.03_f64, 100.0_f64);
        let r = e.radii(lat);
        let ldot = v.x / (r.r_m_m + h);
        let lodot = v.y / ((r.r_n_m + h) * lat.cos());
        let tt = |dt: f64| {
            transport_matrix(
                lat + ldot * dt,
                l0.sin(),
                l0.cos(),
                lon + lodot * dt - lon0 + e.omega_ie_rps * (t + dt),
            )
        };
        // fourth-order central difference; with d = 2 s the truncation error (d⁴/30)|ω|⁵ ≈ 2e-19
        // and the roundoff 18ε/(12d) ≈ 8e-17 stay below 1e-12 of |ω_in| ≈ 1.3e-4 rad/s.
        let d = 2.0;
        let tdot = (tt(-2.0 * d) - 8.0 * tt(-d) + 8.0 * tt(d) - tt(2.0 * d)) / (12.0 * d);
        let lhs = tdot * tt(0.0).transpose();
        let w_in = e.omega_ie_n(lat) + e.omega_en_n(lat, h, &v);
        let rhs = -skew(&w_in);
        assert!(
            (lhs - rhs).abs().max() < 1e-12 * w_in.norm(),
            "{}",
            (lhs - rhs).abs().max()
        );
    }
}
