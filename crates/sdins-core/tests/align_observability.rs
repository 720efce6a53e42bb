//! docs/theory/alignment.md §"Observability at one heading" T3 (observability ranks, null space)
//! and T8 (Algorithm B, noise-free linear).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{SMatrix, SVector};
use sdins_core::align::model::{
    f_matrix, f_pseudo9, h_horizontal, h_zupt, null_space_ned, BiasFrame, Mat12,
};
use sdins_core::align::multiheading::{design_block, AlgorithmB, AttitudeErrorTransition};
use sdins_core::align::observability::{analyze, null_residual, scale12, scale9};
use sdins_core::align::Site;
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};

const D2R: f64 = core::f64::consts::PI / 180.0;

fn site() -> Site {
    Site {
        lat_rad: 37.5 * D2R,
        g_mps2: 9.799490523606893,
        omega_ie_rps: 7.292115e-5,
    }
}

fn c_at(yaw_deg: f64) -> Mat3 {
    c_b_n_from_euler(&Euler::new(2.0 * D2R, -3.0 * D2R, yaw_deg * D2R))
}

#[test]
fn t3_single_heading_ranks_and_null_space() {
    let s = site();
    let f = [f_matrix(&s, BiasFrame::Ned, &Mat3::identity())];
    let o3 = analyze(&f, &h_zupt(), &scale12(), 1e-9);
    let o2 = analyze(&f, &h_horizontal(), &scale12(), 1e-9);
    assert_eq!(o3.rank, 9);
    assert_eq!(o2.rank, 7);
    // docs/theory/alignment.md §"Observability at one heading": σ9/σ1 = 6.8e-2, σ10/σ1 ≈ 3e-17; T3:
    // gap > 1e10
    assert!(o3.gap() > 1e10, "gap {}", o3.gap());
    assert!(
        (o3.sigma_rel[8] - 6.8e-2).abs() < 0.05e-2,
        "σ9/σ1 = {}",
        o3.sigma_rel[8]
    );
    let n = null_space_ned(&s);
    for j in 0..3 {
        let x: SVector<f64, 12> = n.column(j).into_owned();
        let r = null_residual(&f, &h_zupt(), &scale12(), &x);
        assert!(r < 1e-12, "n{}: {r}", j + 1);
    }
    // the numerical unobservable directions span exactly span{n1, n2, n3}:
    // each lies in the span (least-squares residual in scaled coordinates)
    let d = SMatrix::<f64, 12, 12>::from_diagonal(&scale12());
    let di = d.try_inverse().unwrap();
    let ns = di * n;
    let proj = ns * (ns.transpose() * ns).try_inverse().unwrap() * ns.transpose();
    for j in 9..12 {
        let v = di * o3.directions.column(j);
        let v = v / v.norm();
        assert!((v - proj * v).norm() < 1e-9);
    }
    // pseudo 9-state model: completely observable
    let f9 = [f_pseudo9(&s)];
    let mut h9 = SMatrix::<f64, 3, 9>::zeros();
    h9.fixed_view_mut::<3, 3>(0, 0).copy_from(&Mat3::identity());
    let o9 = analyze(&f9, &h9, &scale9(), 1e-9);
    assert_eq!(o9.rank, 9);
}

#[test]
fn t3_multi_heading_som_ranks() {
    let s = site();
    let one = [f_matrix(&s, BiasFrame::Body, &c_at(40.0))];
    assert_eq!(analyze(&one, &h_zupt(), &scale12(), 1e-9).rank, 9);
    assert_eq!(analyze(&one, &h_horizontal(), &scale12(), 1e-9).rank, 7);
    for rel in [
        &[0.0, 180.0][..],
        &[0.0, 90.0],
        &[0.0, 45.0],
        &[0.0, 90.0, 180.0, 270.0],
    ] {
        let fs: Vec<Mat12> = rel
            .iter()
            .map(|r| f_matrix(&s, BiasFrame::Body, &c_at(40.0 + r)))
            .collect();
        let o3 = analyze(&fs, &h_zupt(), &scale12(), 1e-9);
        let o2 = analyze(&fs, &h_horizontal(), &scale12(), 1e-9);
        assert_eq!(o3.rank, 12, "{rel:?}");
        assert_eq!(o2.rank, 11, "{rel:?}");
        assert!(o2.gap() > 1e10, "{rel:?}: gap {}", o2.gap());
    }
    // NED-frame bias states do not gain rank from rotation (F is heading-independent)
    let fs = [
        f_matrix(&s, BiasFrame::Ned, &c_at(40.0)),
        f_matrix(&s, BiasFrame::Ned, &c_at(220.0)),
    ];
    assert_eq!(analyze(&fs, &h_zupt(), &scale12(), 1e-9).rank, 9);
}

/// T8: Algorithm B, noise-free linear: rank 6/9 for one heading, 9/9 for two and four;
/// recovery of θ = \[φ(t0), b_a, b_g\] to 1e-9 relative.
#[test]
fn t8_algorithm_b_linear() {
    let s = site();
    let ug = 9.80665e-6;
    let dph = D2R / 3600.0;
    let phi0 = Vec3::new(0.5e-3, -0.5e-3, 5e-3);
    let ba = Vec3::new(50.0, -80.0, 30.0) * ug;
    let bg = Vec3::new(0.01, -0.02, 0.015) * dph;
    let mut theta = SVector::<f64, 9>::zeros();
    theta.fixed_rows_mut::<3>(0).copy_from(&phi0);
    theta.fixed_rows_mut::<3>(3).copy_from(&ba);
    theta.fixed_rows_mut::<3>(6).copy_from(&bg);
    for (headings, expect_rank) in [
        (&[0.0][..], 6),
        (&[0.0, 180.0], 9),
        (&[0.0, 90.0], 9),
        (&[0.0, 90.0, 180.0, 270.0], 9),
    ] {
        let mut alg = AlgorithmB::new(s);
        let mut tr = AttitudeErrorTransition::default();
        let mut yaw: f64 = 40.0;
        for (k, h) in headings.iter().enumerate() {
            if k > 0 {
                // rotate at 10 °/s to the next heading, in 0.1 s steps
                let target = 40.0 + h;
                let steps = ((target - yaw) / 1.0).round() as usize;
                for _ in 0..steps {
                    yaw += 0.5;
                    tr.step(&c_at(yaw), 0.05, &s);
                    yaw += 0.5;
                    tr.step(&c_at(yaw), 0.05, &s);
                }
                yaw = target;
            }
            for _ in 0..600 {
                tr.step(&c_at(yaw), 1.0, &s);
            }
            let a = design_block(&tr, &c_at(yaw), &s);
            let p = a * theta;
            let cov = SMatrix::<f64, 6, 6>::from_diagonal(&SVector::from_fn(|i, _| {
                if i == 3 || i == 4 {
                    1e-18
                } else {
                    1e-10
                }
            }));
            assert!(alg.add_position(&tr, &c_at(yaw), &p, &cov));
        }
        assert_eq!(alg.observability(1e-9).rank, expect_rank, "{headings:?}");
        match alg.solve() {
            Some(sol) => {
                assert_eq!(expect_rank, 9);
                for (blk, name) in [(0, "phi0"), (3, "b_a"), (6, "b_g")] {
                    let est = sol.theta.fixed_rows::<3>(blk).into_owned();
                    let tru = theta.fixed_rows::<3>(blk).into_owned();
                    let rel = (est - tru).norm() / tru.norm();
                    assert!(rel < 1e-9, "{headings:?} {name}: rel error {rel}");
                }
            }
            None => assert_eq!(expect_rank, 6),
        }
    }
}
