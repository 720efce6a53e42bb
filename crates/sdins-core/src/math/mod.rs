//! Attitude mathematics: vectors, skew matrices, quaternions, DCMs, rotation vectors,
//! Euler angles. Vectors and matrices are nalgebra's fixed-size `f64` types; the
//! quaternion is our own small scalar-first type so that every operation order follows
//! the written formulas literally (docs/conventions.md §"Quaternions").

mod euler;
mod quat;
mod rotvec;

pub use euler::{c_b_n_from_euler, c_b_n_from_sin_cos, euler_from_c_b_n, Euler};
pub use quat::Quat;
pub use rotvec::{dcm_from_rotvec, rotvec_from_dcm};

/// 3-vector of `f64`.
pub type Vec3 = nalgebra::Vector3<f64>;
/// 3×3 matrix of `f64`.
pub type Mat3 = nalgebra::Matrix3<f64>;

/// Skew-symmetric (cross-product) matrix: `skew(a) * b == a.cross(&b)`.
#[inline]
pub fn skew(a: &Vec3) -> Mat3 {
    Mat3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Inverse of [`skew`] for the skew-symmetric part: `vee(M) = ½ (M − Mᵀ)` read as a vector.
///
/// This is the attitude-error extraction of docs/conventions.md §"Errors": `ε = ½ vee(M − Mᵀ)`.
#[inline]
pub fn vee_antisym(m: &Mat3) -> Vec3 {
    Vec3::new(
        0.5 * (m[(2, 1)] - m[(1, 2)]),
        0.5 * (m[(0, 2)] - m[(2, 0)]),
        0.5 * (m[(1, 0)] - m[(0, 1)]),
    )
}

/// Orthonormalise a nearly orthonormal DCM by the symmetric (polar) correction
/// `C ← C (CᵀC)^{-1/2}`, computed with two Newton steps `C ← ½ (C + C^{-T})`
/// (exact to roundoff for errors below ~1e-4; otherwise iterated until converged).
pub fn orthonormalize(c: &Mat3) -> Mat3 {
    let mut m = *c;
    for _ in 0..20 {
        let Some(inv) = m.try_inverse() else {
            return m;
        };
        let next = 0.5 * (m + inv.transpose());
        let diff = (next - m).abs().max();
        m = next;
        if diff < 1e-16 {
            break;
        }
    }
    m
}

/// Attitude error vector of docs/conventions.md §"Errors" (convention G):
/// `c_est c_trueᵀ = I + [ε×] + O(ε²)`, `ε = ½ vee(M − Mᵀ)`, resolved in the navigation frame.
#[inline]
pub fn attitude_error(c_b_n_est: &Mat3, c_b_n_true: &Mat3) -> Vec3 {
    vee_antisym(&(c_b_n_est * c_b_n_true.transpose()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skew_is_cross_product() {
        let a = Vec3::new(0.3, -1.2, 2.5);
        let b = Vec3::new(-0.7, 0.1, 4.0);
        assert!((skew(&a) * b - a.cross(&b)).norm() < 1e-15);
        assert!((vee_antisym(&skew(&a)) - a).norm() < 1e-15);
    }

    #[test]
    fn orthonormalize_restores_rotation() {
        let c = dcm_from_rotvec(&Vec3::new(0.4, -0.2, 1.1));
        let pert = c + Mat3::new(1e-6, 2e-7, -3e-7, 0.0, -1e-6, 4e-7, 2e-7, 0.0, 5e-7);
        let o = orthonormalize(&pert);
        assert!((o * o.transpose() - Mat3::identity()).abs().max() < 2e-16 * 8.0);
        // The polar correction moves C by no more than the perturbation size.
        assert!((o - c).abs().max() < 2e-6);
    }
}
