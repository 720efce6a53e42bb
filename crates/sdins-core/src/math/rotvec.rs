//! Rotation vector ↔ DCM (Rodrigues), with small-angle series.

use super::{skew, Mat3, Quat, Vec3};

/// DCM of a rotation vector: `C = I + (sin φ/φ)[φ×] + ((1 − cos φ)/φ²)[φ×]²`
/// (series below |φ| = 1e-4 rad). To first order `C = I + [φ×]` (docs/conventions.md
/// §"Quaternions").
pub fn dcm_from_rotvec(phi: &Vec3) -> Mat3 {
    let a2 = phi.norm_squared();
    let (s1, s2) = if a2 < 1e-8 {
        (
            1.0 - a2 / 6.0 + a2 * a2 / 120.0,
            0.5 - a2 / 24.0 + a2 * a2 / 720.0,
        )
    } else {
        let a = libm::sqrt(a2);
        (libm::sin(a) / a, (1.0 - libm::cos(a)) / a2)
    };
    let k = skew(phi);
    Mat3::identity() + k * s1 + k * k * s2
}

/// Rotation vector of a DCM (shortest rotation), via the quaternion.
pub fn rotvec_from_dcm(c: &Mat3) -> Vec3 {
    Quat::from_dcm(c).to_rotvec()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rodrigues_matches_quaternion() {
        for phi in [Vec3::new(0.5, -1.0, 2.0), Vec3::new(1e-5, 3e-5, -2e-5)] {
            let a = dcm_from_rotvec(&phi);
            let b = Quat::from_rotvec(&phi).to_dcm();
            assert!((a - b).abs().max() < 1e-15);
            assert!((rotvec_from_dcm(&a) - phi).norm() < 1e-15 * (1.0 + phi.norm()) * 4.0);
        }
    }
}
