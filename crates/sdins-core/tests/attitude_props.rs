//! Property tests of the attitude mathematics (proptest): round trips, norms, composition.
#![allow(clippy::unwrap_used)]
use proptest::prelude::*;
use sdins_core::math::{
    c_b_n_from_euler, dcm_from_rotvec, euler_from_c_b_n, orthonormalize, rotvec_from_dcm, Euler,
    Mat3, Quat, Vec3,
};

fn vec3(max: f64) -> impl Strategy<Value = Vec3> {
    (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vec3::new(a, b, c))
}

fn rotation() -> impl Strategy<Value = Quat> {
    vec3(3.0)
        .prop_filter("|φ| < π", |v| v.norm() < 3.1)
        .prop_map(|v| Quat::from_rotvec(&v))
}

proptest! {
    // fixed seed: the same cases on every run (CI must not be flaky)
    #![proptest_config(ProptestConfig { cases: 512, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5d_1a5), ..ProptestConfig::default() })]

    #[test]
    fn quaternion_is_unit_and_dcm_orthonormal(q in rotation()) {
        prop_assert!((q.norm() - 1.0).abs() < 4e-16);
        let c = q.to_dcm();
        // |q| = 1 ± 2ε puts 4ε on the DCM scale, plus ~3ε from each 3-term dot product
        prop_assert!((c * c.transpose() - Mat3::identity()).abs().max() < 10.0 * f64::EPSILON);
        // det is a sum of six triple products: ~6·3ε of roundoff
        prop_assert!((c.determinant() - 1.0).abs() < 20.0 * f64::EPSILON);
    }

    #[test]
    fn quaternion_dcm_round_trip(q in rotation()) {
        let back = Quat::from_dcm(&q.to_dcm());
        let q = if q.w < 0.0 { q.scale(-1.0) } else { q };
        prop_assert!((back.w - q.w).abs() < 1e-15 && (back.vec() - q.vec()).norm() < 1e-15);
    }

    #[test]
    fn composition_matches_dcm_product(a in rotation(), b in rotation(), v in vec3(10.0)) {
        let ab = a.mul(&b);
        prop_assert!((ab.to_dcm() - a.to_dcm() * b.to_dcm()).abs().max() < 1e-15);
        prop_assert!((ab.rotate(&v) - a.rotate(&b.rotate(&v))).norm() < 1e-14 * (1.0 + v.norm()));
        // the conjugate is the inverse
        let id = a.mul(&a.conj());
        prop_assert!((id.w - 1.0).abs() < 1e-15 && id.vec().norm() < 1e-15);
    }

    #[test]
    fn rotation_vector_round_trip(phi in vec3(1.8)) {
        prop_assume!(phi.norm() < 3.1);
        let q = Quat::from_rotvec(&phi);
        prop_assert!((q.to_rotvec() - phi).norm() <= 4e-16 * (1.0 + phi.norm()) * 4.0);
        prop_assert!((rotvec_from_dcm(&dcm_from_rotvec(&phi)) - phi).norm() <= 1e-14);
        prop_assert!((dcm_from_rotvec(&phi) - q.to_dcm()).abs().max() < 1e-15);
    }

    #[test]
    fn euler_round_trip(r in -3.1..3.1_f64, p in -1.5..1.5_f64, y in -3.1..3.1_f64) {
        let e = euler_from_c_b_n(&c_b_n_from_euler(&Euler::new(r, p, y)));
        // conditioning of roll/yaw degrades as 1/cos(pitch) near ±90°
        let tol = 1e-14 / p.cos();
        prop_assert!((e.roll_rad - r).abs() < tol && (e.pitch_rad - p).abs() < 1e-14 && (e.yaw_rad - y).abs() < tol);
    }

    #[test]
    fn orthonormalize_projects_to_nearest_rotation(q in rotation(), noise in vec3(1e-6), noise2 in vec3(1e-6)) {
        let c = q.to_dcm();
        let mut m = c;
        for i in 0..3 {
            m[(0, i)] += noise[i];
            m[(1, i)] += noise2[i];
        }
        let o = orthonormalize(&m);
        prop_assert!((o * o.transpose() - Mat3::identity()).abs().max() < 1e-15);
        prop_assert!((o - c).abs().max() < 4e-6);
    }
}
