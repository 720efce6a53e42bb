//! Tests of the aiding-sensor models: the first-order exactness of every `H` (second-order
//! remainder, central differences), dimensions, refusals and the delegation of
//! [`AidingMeas`].
#![allow(clippy::unwrap_used)]

extern crate std;

use super::*;
use crate::aiding::layout::{BlockKind, BlockProcess, Cov, Process, StateLayout, XVec};
use crate::aiding::meas::{
    GnssMeasurement, MeasError, MeasKind, MeasModel, MeasPoint, Measurement, Nhc, Zupt,
};
use crate::earth::EarthModel;
use crate::math::{c_b_n_from_euler, dcm_from_rotvec, Euler, Mat3, Vec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use std::{format, println, string::String, vec::Vec};

const EARTH: EarthModel = EarthModel::WGS84;

/// The truth of a test case and the layout of the filter.
#[derive(Clone, Copy)]
struct Truth {
    lat: f64,
    lon: f64,
    h: f64,
    v_n: Vec3,
    c_b_n: Mat3,
    /// true angular rate, body \[rad/s\]
    omega_ib_b: Vec3,
    /// true sensor parameters at the layout's offsets (non-navigation blocks)
    params: XVec,
    layout: StateLayout,
}

/// Odometer geometry: vehicle frame misaligned by (0.01, −0.02, 0.015) rad, rear axle
/// 1.2 m behind, 0.3 m left of and 0.5 m below the IMU.
fn odo_geometry() -> (Mat3, Vec3) {
    (
        dcm_from_rotvec(&Vec3::new(0.01, -0.02, 0.015)),
        Vec3::new(-1.2, -0.3, 0.5),
    )
}

/// Doppler-log geometry: rotated 90° about z (a sideways-mounted log), 0.8 m ahead, 1 m down.
fn dvl_geometry() -> (Mat3, Vec3) {
    (
        dcm_from_rotvec(&Vec3::new(0.0, 0.0, core::f64::consts::FRAC_PI_2)),
        Vec3::new(0.8, 0.1, 1.0),
    )
}

fn constant() -> BlockProcess {
    BlockProcess::PerAxis([Process::CONSTANT; 3])
}

/// `ins` (+ scale factors) + the sensor blocks asked for.
fn layout(scale: bool, baro: bool, odo: bool, hi: bool) -> StateLayout {
    let mut l = StateLayout::ins([Process::CONSTANT; 3], [Process::CONSTANT; 3]);
    if scale {
        l = l.with_scale_factors().unwrap();
    }
    if baro {
        l = l.with(BlockKind::BaroBias, 1, constant()).unwrap();
    }
    if odo {
        l = l.with(BlockKind::OdometerScale, 1, constant()).unwrap();
    }
    if hi {
        l = l.with(BlockKind::MagHardIron, 3, constant()).unwrap();
    }
    l
}

/// The full layout (26 states) and the plain one (`ins` + the required baro bias).
fn layouts() -> [StateLayout; 2] {
    [
        layout(true, true, true, true),
        layout(false, true, false, false),
    ]
}

fn truth(layout: StateLayout) -> Truth {
    let c_b_n = c_b_n_from_euler(&Euler::new(0.15, -0.1, 2.2));
    let omega_ib_b = Vec3::new(0.05, -0.03, 0.2);
    let (lat, h) = (0.6, 150.0);
    // v^n such that the rear-axle centre moves at 15 m/s along the vehicle x axis only
    // (the truth satisfies the non-holonomic constraint)
    let (c_b_v, l) = odo_geometry();
    let w_eb = omega_ib_b - c_b_n.transpose() * EARTH.omega_ie_n(lat);
    let v_n = c_b_n * (c_b_v.transpose() * Vec3::new(15.0, 0.0, 0.0) - w_eb.cross(&l));
    let mut params = XVec::zeros();
    for b in layout.blocks() {
        let vals: [f64; 3] = match b.kind {
            BlockKind::AccelBias => [0.02, -0.01, 0.03],
            BlockKind::GyroBias => [2e-5, -1e-5, 3e-5],
            BlockKind::AccelScale => [3e-4, -2e-4, 1e-4],
            BlockKind::GyroScale => [-2e-4, 4e-4, 3e-4],
            BlockKind::OdometerScale => [0.02, 0.0, 0.0],
            BlockKind::BaroBias => [12.0, 0.0, 0.0],
            BlockKind::MagHardIron => [3.0, -2.0, 1.5],
            _ => [0.0; 3],
        };
        for i in 0..b.dim {
            params[b.offset + i] = vals[i];
        }
    }
    Truth {
        lat,
        lon: -1.2,
        h,
        v_n,
        c_b_n,
        omega_ib_b,
        params,
        layout,
    }
}

fn param(t: &Truth, kind: BlockKind, i: usize) -> f64 {
    t.layout.offset(kind).map_or(0.0, |o| t.params[o + i])
}

/// Noise-free measurements of the truth.
fn baro(t: &Truth) -> Baro {
    Baro {
        t_s: 10.0,
        h_baro_m: t.h + param(t, BlockKind::BaroBias, 0),
        sigma_m: 0.5,
    }
}

fn odometer(t: &Truth, nhc: bool) -> Odometer {
    let (c_b_v, l) = odo_geometry();
    let w_ie = EARTH.omega_ie_n(t.lat);
    let v = vehicle_velocity(&t.c_b_n, &t.v_n, &t.omega_ib_b, &w_ie, &c_b_v, &l);
    Odometer {
        t_s: 10.0,
        speed_mps: (1.0 + param(t, BlockKind::OdometerScale, 0)) * v.x,
        sigma_mps: 0.05,
        c_b_v,
        lever_arm_b_m: l,
        nhc_sigma_mps: nhc.then_some(0.1),
        nhc_v_mps: [0.0; 2],
    }
}

fn body_velocity(t: &Truth) -> BodyVelocity {
    let (c_b_v, l) = dvl_geometry();
    let w_ie = EARTH.omega_ie_n(t.lat);
    BodyVelocity {
        t_s: 10.0,
        v_v_mps: vehicle_velocity(&t.c_b_n, &t.v_n, &t.omega_ib_b, &w_ie, &c_b_v, &l),
        cov_mps2: Mat3::from_diagonal(&Vec3::new(0.01, 0.01, 0.04)),
        c_b_v,
        lever_arm_b_m: l,
    }
}

fn magnetometer(t: &Truth) -> Magnetometer {
    let m_n = mag_field_ned_ut(0.1, 1.1, 50.0);
    let b = Vec3::from_fn(|i, _| param(t, BlockKind::MagHardIron, i));
    Magnetometer {
        t_s: 10.0,
        m_b_ut: t.c_b_n.transpose() * m_n + b,
        m_n_ut: m_n,
        sigma_ut: 0.3,
    }
}

fn dual_antenna(t: &Truth, heading_only: bool) -> DualAntenna {
    let b = Vec3::new(1.2, 0.3, -0.1);
    let (az, el) = baseline_az_el(&t.c_b_n, &b);
    DualAntenna {
        t_s: 10.0,
        az_rad: az,
        el_rad: el,
        baseline_b_m: b,
        sigma_rel_m: 0.005,
        heading_only,
    }
}

/// Evaluate at the estimate `truth ⊕ x`: navigation estimate − truth, attitude
/// `Ĉ = exp([ε×]) C`, compensated rate `ω̂ = ω + x_bg + diag(ω) x_sg`, sensor parameters
/// `p̂ = p − x_p`.
fn eval<M: Measurement>(m: &M, t: &Truth, x: &XVec) -> Result<MeasModel, MeasError> {
    let lo = &t.layout;
    let eps = Vec3::new(x[6], x[7], x[8]);
    let mut w = t.omega_ib_b + Vec3::new(x[12], x[13], x[14]);
    if let Some(o) = lo.offset(BlockKind::GyroScale) {
        w += t
            .omega_ib_b
            .component_mul(&Vec3::new(x[o], x[o + 1], x[o + 2]));
    }
    let mut est = XVec::zeros();
    for b in lo.blocks().iter().filter(|b| !b.kind.is_navigation()) {
        for i in b.offset..b.offset + b.dim {
            est[i] = t.params[i] - x[i];
        }
    }
    let at = MeasPoint {
        t_s: m.t_valid_s(),
        lat_rad: t.lat + x[0],
        lon_rad: t.lon + x[1],
        h_m: t.h + x[2],
        v_n_mps: t.v_n + Vec3::new(x[3], x[4], x[5]),
        c_b_n: dcm_from_rotvec(&eps) * t.c_b_n,
        omega_ib_b: w,
        earth: &EARTH,
        layout: lo,
        est: &est,
    };
    let mut out = MeasModel::zeros(1);
    m.evaluate(&at, &mut out)?;
    Ok(out)
}

/// Realistic scale of every state: position 1e-6 rad / 1 m, velocity 0.1 m/s, attitude
/// 1e-3 rad, accelerometer bias 1e-3 m/s², gyro bias 1e-5 rad/s, IMU scale factors 1e-4,
/// odometer scale factor 1e-3, baro bias 1 m, hard iron 0.5 µT.
fn scales(lo: &StateLayout) -> XVec {
    let mut s = XVec::zeros();
    for b in lo.blocks() {
        let v: [f64; 3] = match b.kind {
            BlockKind::Position => [1e-6, 1e-6, 1.0],
            BlockKind::Velocity => [0.1; 3],
            BlockKind::Attitude => [1e-3; 3],
            BlockKind::AccelBias => [1e-3; 3],
            BlockKind::GyroBias => [1e-5; 3],
            BlockKind::AccelScale | BlockKind::GyroScale => [1e-4; 3],
            BlockKind::OdometerScale => [1e-3; 3],
            BlockKind::BaroBias => [1.0; 3],
            BlockKind::MagHardIron => [0.5; 3],
            _ => [0.0; 3],
        };
        for i in 0..b.dim {
            s[b.offset + i] = v[i];
        }
    }
    s
}

fn random_x(lo: &StateLayout, seed: u64) -> XVec {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let s = scales(lo);
    XVec::from_fn(|i, _| {
        let g: f64 = StandardNormal.sample(&mut rng);
        g * s[i]
    })
}

/// `x` with only the states of one block kept.
fn restrict(x: &XVec, lo: &StateLayout, kind: BlockKind) -> XVec {
    let mut y = XVec::zeros();
    if let Some(b) = lo.block(kind) {
        for i in b.offset..b.offset + b.dim {
            y[i] = x[i];
        }
    }
    y
}

/// A row's remainder `r(α) = ν(αx) − ν(0) − α H(0) x` is "exact" below
/// `FLOOR · max(1, |ν(αx)|, |αHx|)` (roundoff, and the neglected `Ω_e δL |l|` ≈ 1e-10 m/s
/// of the lever-arm rate); above it, `|r(α)|/|r(α/2)|` must be in [3, 5] (second order).
const FLOOR: f64 = 1e-9;

/// The second-order check of `H` along `x`: the ratios `|r(α)|/|r(α/2)|` of the rows above
/// the floor, for α = 1 and 0.5 (a row at or below the floor, exact to first order, counts
/// as ratio 0), or a description of the failure.
fn second_order<M: Measurement>(m: &M, t: &Truth, x: &XVec) -> Result<Vec<f64>, String> {
    let n = t.layout.n();
    let m0 = eval(m, t, &XVec::zeros()).map_err(|e| format!("{e:?}"))?;
    let hx = |i: usize| (0..n).map(|j| m0.h[(i, j)] * x[j]).sum::<f64>();
    let remainder = |alpha: f64| -> Result<Vec<(f64, f64)>, String> {
        let ma = eval(m, t, &(x * alpha)).map_err(|e| format!("{e:?}"))?;
        Ok((0..m0.dim)
            .map(|i| {
                let lin = alpha * hx(i);
                let r = ma.nu[i] - m0.nu[i] - lin;
                (r, FLOOR * 1f64.max(ma.nu[i].abs()).max(lin.abs()))
            })
            .collect())
    };
    let mut ratios = Vec::new();
    for alpha in [1.0, 0.5] {
        let (ra, rb) = (remainder(alpha)?, remainder(alpha / 2.0)?);
        for (i, ((r1, floor), (r2, _))) in ra.iter().zip(rb.iter()).enumerate() {
            if r1.abs() <= *floor {
                ratios.push(0.0);
                continue;
            }
            let q = r1.abs() / r2.abs();
            if !(3.0..=5.0).contains(&q) {
                return Err(format!(
                    "{:?} row {i} α {alpha}: r = {r1:e}, r(α/2) = {r2:e}, ratio {q:.3}",
                    m.kind()
                ));
            }
            ratios.push(q);
        }
    }
    Ok(ratios)
}

/// Central differences of ν over every state (step 1e-2 of the state's scale) against
/// `H(0)`, each column scaled by the state's scale: `|(H_fd − H)_ij| s_j ≤ FLOOR ·
/// max(1, |H_ij| s_j)`.
fn central_differences<M: Measurement>(m: &M, t: &Truth) -> Result<(), String> {
    let s = scales(&t.layout);
    let m0 = eval(m, t, &XVec::zeros()).map_err(|e| format!("{e:?}"))?;
    for j in 0..t.layout.n() {
        let mut x = XVec::zeros();
        x[j] = 1e-2 * s[j];
        let p = eval(m, t, &x).map_err(|e| format!("{e:?}"))?;
        let q = eval(m, t, &(-x)).map_err(|e| format!("{e:?}"))?;
        for i in 0..m0.dim {
            let fd = (p.nu[i] - q.nu[i]) / (2.0 * x[j]);
            let err = (fd - m0.h[(i, j)]).abs() * s[j];
            if err > FLOOR * 1f64.max(m0.h[(i, j)].abs() * s[j]) {
                return Err(format!(
                    "{:?} H[{i}, {j}] = {:e}, central difference {fd:e}",
                    m.kind(),
                    m0.h[(i, j)]
                ));
            }
        }
    }
    Ok(())
}

/// The whole check of a model: `ν(0) = 0` (the measurement is the truth's), the second-order
/// remainder along a random `x` over every state and along each block alone (three seeds),
/// and the central differences. Returns the ratios.
fn check<M: Measurement>(m: &M, t: &Truth) -> Result<Vec<f64>, String> {
    let m0 = eval(m, t, &XVec::zeros()).map_err(|e| format!("{e:?}"))?;
    for i in 0..m0.dim {
        if m0.nu[i].abs() > 1e-9 {
            return Err(format!("{:?}: ν(0)[{i}] = {:e}", m.kind(), m0.nu[i]));
        }
    }
    let mut ratios = Vec::new();
    for seed in 1..=3 {
        let x = random_x(&t.layout, seed);
        ratios.extend(second_order(m, t, &x)?);
        for b in t.layout.blocks() {
            ratios.extend(second_order(m, t, &restrict(&x, &t.layout, b.kind))?);
        }
    }
    central_differences(m, t)?;
    Ok(ratios)
}

/// A model with the columns of one block zeroed (a wrong `H`).
struct Corrupt<M> {
    inner: M,
    cols: core::ops::Range<usize>,
}

impl<M: Measurement> Measurement for Corrupt<M> {
    fn kind(&self) -> MeasKind {
        self.inner.kind()
    }
    fn t_valid_s(&self) -> f64 {
        self.inner.t_valid_s()
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        self.inner.evaluate(at, out)?;
        for i in 0..out.dim {
            for j in self.cols.clone() {
                out.h[(i, j)] = 0.0;
            }
        }
        Ok(())
    }
}

/// Every model of the crate's sensors, noise-free, for a truth.
fn models(t: &Truth) -> Vec<AidingMeas> {
    std::vec![
        baro(t).into(),
        odometer(t, false).into(),
        odometer(t, true).into(),
        body_velocity(t).into(),
        magnetometer(t).into(),
        dual_antenna(t, false).into(),
        dual_antenna(t, true).into(),
    ]
}

/// (rows exact to first order, rows of second order, their smallest and largest ratio)
fn summary(r: &[f64]) -> (usize, usize, f64, f64) {
    let q: Vec<f64> = r.iter().copied().filter(|q| *q > 0.0).collect();
    let lo = q.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = q.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (r.len() - q.len(), q.len(), lo, hi)
}

#[test]
fn every_jacobian_is_exact_to_first_order() {
    for lo in layouts() {
        let t = truth(lo);
        for m in models(&t) {
            // directly and through the enum
            let r = match m {
                AidingMeas::Baro(b) => check(&b, &t),
                AidingMeas::Odometer(o) => check(&o, &t),
                AidingMeas::BodyVelocity(b) => check(&b, &t),
                AidingMeas::Magnetometer(g) => check(&g, &t),
                AidingMeas::DualAntenna(d) => check(&d, &t),
                _ => unreachable!(),
            };
            let r = r.unwrap();
            assert_eq!(check(&m, &t).unwrap(), r);
            let (exact, count, min, max) = summary(&r);
            // every model is non-linear in some state but the barometer
            assert_eq!(count == 0, m.kind() == MeasKind::Baro);
            println!(
                "n = {:2} {:<13} dim {}: {exact:3} row checks exact, {count:3} second order, \
                 ratios in [{min:.4}, {max:.4}]",
                lo.n(),
                m.kind().name(),
                eval(&m, &t, &XVec::zeros()).unwrap().dim,
            );
        }
    }
}

/// The check can fail: with the columns of any block whose `H` is not zero removed, the
/// remainder along that block is first order (ratio ≈ 2) and the central differences
/// disagree.
#[test]
fn the_check_detects_a_wrong_column_block() {
    for lo in layouts() {
        let t = truth(lo);
        let x = random_x(&lo, 7);
        for m in models(&t) {
            let m0 = eval(&m, &t, &XVec::zeros()).unwrap();
            let mut tested = 0;
            for b in lo.blocks() {
                let cols = b.offset..b.offset + b.dim;
                let nonzero = (0..m0.dim).any(|i| cols.clone().any(|j| m0.h[(i, j)] != 0.0));
                if !nonzero {
                    continue;
                }
                tested += 1;
                let bad = Corrupt { inner: m, cols };
                let e = second_order(&bad, &t, &restrict(&x, &lo, b.kind));
                assert!(e.is_err(), "{:?} without {:?} passed", m.kind(), b.kind);
                assert!(central_differences(&bad, &t).is_err());
                assert!(check(&bad, &t).is_err());
            }
            assert!(tested >= 1);
        }
    }
    // and a 1 % error of a single column of a single row
    let t = truth(layouts()[0]);
    struct Scaled(Odometer, usize);
    impl Measurement for Scaled {
        fn kind(&self) -> MeasKind {
            self.0.kind()
        }
        fn t_valid_s(&self) -> f64 {
            self.0.t_s
        }
        fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
            self.0.evaluate(at, out)?;
            out.h[(0, self.1)] *= 1.01;
            Ok(())
        }
    }
    for j in [3, 7, 13, 18 + 2] {
        assert!(check(&Scaled(odometer(&t, true), j), &t).is_err(), "{j}");
    }
}

#[test]
fn rows_and_columns_of_the_variants() {
    for lo in layouts() {
        let t = truth(lo);
        let zero = XVec::zeros();
        let odo_col = lo.offset(BlockKind::OdometerScale);
        let o1 = eval(&odometer(&t, false), &t, &zero).unwrap();
        let o3 = eval(&odometer(&t, true), &t, &zero).unwrap();
        assert_eq!((o1.dim, o3.dim), (1, 3));
        assert_eq!(o1.h.row(0), o3.h.row(0));
        assert_eq!(
            (o3.r[(0, 0)], o3.r[(1, 1)], o3.r[(2, 2)]),
            (0.05 * 0.05, 0.1 * 0.1, 0.1 * 0.1)
        );
        let speed = odometer(&t, false).speed_mps;
        let s = param(&t, BlockKind::OdometerScale, 0);
        match odo_col {
            Some(o) => assert!((o1.h[(0, o)] + speed / (1.0 + s)).abs() < 1e-12),
            None => assert_eq!(lo.n(), 15 + 1),
        }
        let d2 = eval(&dual_antenna(&t, false), &t, &zero).unwrap();
        let d1 = eval(&dual_antenna(&t, true), &t, &zero).unwrap();
        assert_eq!((d2.dim, d1.dim), (2, 1));
        assert_eq!(d1.h.row(0), d2.h.row(0));
        assert_eq!(d1.r[(0, 0)], d2.r[(0, 0)]);
        // σ_az = σ_rel/(L cos el), σ_el = σ_rel/L
        let d = dual_antenna(&t, false);
        let len = d.baseline_b_m.norm();
        let s_el = d.sigma_rel_m / len;
        assert!((d2.r[(1, 1)] - s_el * s_el).abs() < 1e-18);
        let s_az = s_el / libm::cos(d.el_rad);
        assert!((d2.r[(0, 0)] / (s_az * s_az) - 1.0).abs() < 1e-12);
        // only attitude columns
        for j in (0..lo.n()).filter(|j| !(6..9).contains(j)) {
            assert_eq!((d2.h[(0, j)], d2.h[(1, j)]), (0.0, 0.0));
        }
        let g = eval(&magnetometer(&t), &t, &zero).unwrap();
        assert_eq!(g.dim, 3);
        match lo.offset(BlockKind::MagHardIron) {
            Some(o) => assert_eq!(g.h[(1, o + 1)], -1.0),
            None => assert!((9..lo.n()).all(|j| g.h.column(j).iter().all(|v| *v == 0.0))),
        }
        let b = eval(&baro(&t), &t, &zero).unwrap();
        let o = lo.offset(BlockKind::BaroBias).unwrap();
        assert_eq!(
            (b.dim, b.h[(0, 2)], b.h[(0, o)], b.r[(0, 0)]),
            (1, 1.0, -1.0, 0.25)
        );
        assert_eq!(eval(&body_velocity(&t), &t, &zero).unwrap().dim, 3);
    }
}

#[test]
fn baro_needs_its_bias_block() {
    let t = truth(layout(true, false, true, true));
    let b = Baro {
        t_s: 1.0,
        h_baro_m: 100.0,
        sigma_m: 1.0,
    };
    assert_eq!(
        eval(&b, &t, &XVec::zeros()),
        Err(MeasError::MissingBlock(BlockKind::BaroBias))
    );
}

#[test]
fn non_finite_and_degenerate_inputs_are_refused() {
    let t = truth(layouts()[0]);
    let nan = f64::NAN;
    let z = XVec::zeros();
    let err = |r: Result<MeasModel, MeasError>| assert_eq!(r, Err(MeasError::NonFinite));
    let b = baro(&t);
    err(eval(&Baro { h_baro_m: nan, ..b }, &t, &z));
    err(eval(&Baro { t_s: nan, ..b }, &t, &z));
    err(eval(&Baro { sigma_m: 0.0, ..b }, &t, &z));
    err(eval(
        &Baro {
            sigma_m: f64::INFINITY,
            ..b
        },
        &t,
        &z,
    ));
    let o = odometer(&t, true);
    err(eval(
        &Odometer {
            speed_mps: nan,
            ..o
        },
        &t,
        &z,
    ));
    err(eval(
        &Odometer {
            sigma_mps: -1.0,
            ..o
        },
        &t,
        &z,
    ));
    err(eval(
        &Odometer {
            nhc_sigma_mps: Some(0.0),
            ..o
        },
        &t,
        &z,
    ));
    err(eval(
        &Odometer {
            nhc_sigma_mps: Some(nan),
            ..o
        },
        &t,
        &z,
    ));
    err(eval(
        &Odometer {
            nhc_v_mps: [0.0, nan],
            ..o
        },
        &t,
        &z,
    ));
    let mut c = o.c_b_v;
    c[(1, 2)] = nan;
    err(eval(&Odometer { c_b_v: c, ..o }, &t, &z));
    err(eval(
        &Odometer {
            lever_arm_b_m: Vec3::new(0.0, nan, 0.0),
            ..o
        },
        &t,
        &z,
    ));
    let v = body_velocity(&t);
    err(eval(
        &BodyVelocity {
            v_v_mps: Vec3::new(nan, 0.0, 0.0),
            ..v
        },
        &t,
        &z,
    ));
    err(eval(
        &BodyVelocity {
            cov_mps2: Mat3::zeros(),
            ..v
        },
        &t,
        &z,
    ));
    err(eval(
        &BodyVelocity {
            cov_mps2: Mat3::identity() * nan,
            ..v
        },
        &t,
        &z,
    ));
    err(eval(
        &BodyVelocity {
            t_s: f64::INFINITY,
            ..v
        },
        &t,
        &z,
    ));
    let g = magnetometer(&t);
    err(eval(
        &Magnetometer {
            m_b_ut: Vec3::new(0.0, 0.0, nan),
            ..g
        },
        &t,
        &z,
    ));
    err(eval(
        &Magnetometer {
            m_n_ut: Vec3::new(nan, 0.0, 0.0),
            ..g
        },
        &t,
        &z,
    ));
    err(eval(&Magnetometer { sigma_ut: 0.0, ..g }, &t, &z));
    let d = dual_antenna(&t, false);
    err(eval(&DualAntenna { az_rad: nan, ..d }, &t, &z));
    err(eval(&DualAntenna { el_rad: nan, ..d }, &t, &z));
    err(eval(
        &DualAntenna {
            sigma_rel_m: 0.0,
            ..d
        },
        &t,
        &z,
    ));
    err(eval(
        &DualAntenna {
            baseline_b_m: Vec3::zeros(),
            ..d
        },
        &t,
        &z,
    ));
    // a baseline pointing straight up (predicted elevation 90°), and a measured 90°
    let up = t.c_b_n.transpose() * Vec3::new(0.0, 0.0, -1.0);
    err(eval(
        &DualAntenna {
            baseline_b_m: up,
            ..d
        },
        &t,
        &z,
    ));
    let near_up = t.c_b_n.transpose() * Vec3::new(1e-8, 0.0, -1.0);
    err(eval(
        &DualAntenna {
            baseline_b_m: near_up,
            heading_only: true,
            ..d
        },
        &t,
        &z,
    ));
    err(eval(
        &DualAntenna {
            el_rad: core::f64::consts::FRAC_PI_2,
            heading_only: true,
            ..d
        },
        &t,
        &z,
    ));
    // a steep but usable baseline is accepted
    let steep = t.c_b_n.transpose() * Vec3::new(1e-3, 0.0, -1.0);
    assert!(eval(
        &DualAntenna {
            baseline_b_m: steep,
            ..d
        },
        &t,
        &z
    )
    .is_ok());
}

#[test]
fn azimuth_innovation_is_wrapped() {
    let t = truth(layouts()[0]);
    let d = dual_antenna(&t, true);
    let z = XVec::zeros();
    let tau = 2.0 * core::f64::consts::PI;
    let x = random_x(&t.layout, 3);
    let a = eval(&d, &t, &x).unwrap();
    for shift in [tau, -tau, 2.0 * tau] {
        let s = eval(
            &DualAntenna {
                az_rad: d.az_rad + shift,
                ..d
            },
            &t,
            &x,
        )
        .unwrap();
        assert!((s.nu[0] - a.nu[0]).abs() < 1e-12);
    }
    // a baseline pointing south: predicted az near ±π, measured on the other side
    let south = t.c_b_n.transpose() * Vec3::new(-1.0, 1e-4, 0.0);
    let (az, el) = baseline_az_el(&t.c_b_n, &south);
    assert!(az > core::f64::consts::PI - 1e-3);
    let m = DualAntenna {
        az_rad: az + 3e-4 - tau,
        el_rad: el,
        baseline_b_m: south,
        ..d
    };
    let r = eval(&m, &t, &z).unwrap();
    assert!((r.nu[0] + 3e-4).abs() < 1e-12, "{}", r.nu[0]);
    assert!(r.nu[0].abs() <= core::f64::consts::PI);
}

#[test]
fn forward_functions() {
    let d = 10f64.to_radians();
    let i = 60f64.to_radians();
    let m = mag_field_ned_ut(d, i, 50.0);
    assert!((m.norm() - 50.0).abs() < 1e-12);
    assert!((m.z - 50.0 * i.sin()).abs() < 1e-12);
    assert!((libm::atan2(m.y, m.x) - d).abs() < 1e-12);
    let id = Mat3::identity();
    let (az, el) = baseline_az_el(&id, &Vec3::new(1.0, 1.0, 0.0));
    assert!((az - core::f64::consts::FRAC_PI_4).abs() < 1e-15 && el.abs() < 1e-15);
    let (az, el) = baseline_az_el(&id, &Vec3::new(0.0, -2.0, -2.0));
    assert!((az + core::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert!((el - core::f64::consts::FRAC_PI_4).abs() < 1e-15);
    // yaw 30°: a forward baseline points at 30°
    let c = c_b_n_from_euler(&Euler::new(0.0, 0.0, 30f64.to_radians()));
    let (az, _) = baseline_az_el(&c, &Vec3::new(3.0, 0.0, 0.0));
    assert!((az - 30f64.to_radians()).abs() < 1e-12);
    // vehicle velocity: straight level motion, no rotation, identity frames
    let v = vehicle_velocity(
        &id,
        &Vec3::new(10.0, 0.0, 0.0),
        &Vec3::zeros(),
        &Vec3::zeros(),
        &id,
        &Vec3::new(-1.0, 0.0, 0.0),
    );
    assert_eq!(v, Vec3::new(10.0, 0.0, 0.0));
    // yawing at 0.1 rad/s: a point 2 m behind moves 0.2 m/s to the left (−y)
    let v = vehicle_velocity(
        &id,
        &Vec3::zeros(),
        &Vec3::new(0.0, 0.0, 0.1),
        &Vec3::zeros(),
        &id,
        &Vec3::new(-2.0, 0.0, 0.0),
    );
    assert!((v - Vec3::new(0.0, -0.2, 0.0)).norm() < 1e-15);
    let j = vehicle_velocity_jacobian(
        &id,
        &Vec3::zeros(),
        &Vec3::new(0.0, 0.0, 0.1),
        &Vec3::zeros(),
        &id,
        &Vec3::new(-2.0, 0.0, 0.0),
    );
    assert_eq!(j.v_v_mps, v);
}

#[test]
fn the_enum_delegates() {
    let t = truth(layouts()[0]);
    let z = XVec::zeros();
    let zupt = Zupt {
        t_s: 3.0,
        sigma_mps: 0.1,
    };
    let nhc = Nhc {
        t_s: 4.0,
        sigma_mps: 0.1,
    };
    let gnss = GnssMeasurement {
        t_s: 5.0,
        lat_rad: t.lat,
        lon_rad: t.lon,
        h_m: t.h,
        pos_cov_ned_m2: Mat3::identity() * 4.0,
        vel: Some((t.v_n, Mat3::identity() * 0.01)),
        lever_arm_b_m: Vec3::new(0.1, 0.2, -1.0),
    };
    let mut all = models(&t);
    all.extend([AidingMeas::from(zupt), nhc.into(), gnss.into()]);
    let kinds: Vec<MeasKind> = all.iter().map(|m| m.kind()).collect();
    for k in MeasKind::ALL {
        assert!(kinds.contains(&k), "{k:?}");
    }
    for m in &all {
        let (kind, t_v, gated, r) = match m {
            AidingMeas::Gnss(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
            AidingMeas::Zupt(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
            AidingMeas::Nhc(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
            AidingMeas::Baro(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
            AidingMeas::Odometer(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
            AidingMeas::BodyVelocity(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
            AidingMeas::Magnetometer(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
            AidingMeas::DualAntenna(g) => (g.kind(), g.t_valid_s(), g.gated(), eval(g, &t, &z)),
        };
        assert_eq!(m.kind(), kind);
        assert_eq!(m.t_valid_s(), t_v);
        assert_eq!(m.gated(), gated);
        let e = eval(m, &t, &z);
        assert_eq!(e, r);
        assert_eq!(e.unwrap().dim, r.clone().unwrap().dim);
        // every new sensor is gated; ZUPT and NHC are not
        let new = !matches!(
            m,
            AidingMeas::Gnss(_) | AidingMeas::Zupt(_) | AidingMeas::Nhc(_)
        );
        if new {
            assert!(m.gated());
        }
        // reset: GNSS keeps its own, the others do nothing
        let model = r.unwrap();
        let mut p = Cov::identity() * 3.0;
        p[(0, 4)] = 0.5;
        let mut q = p;
        m.reset(&mut p, &model, &t.layout);
        if let AidingMeas::Gnss(g) = m {
            g.reset(&mut q, &model, &t.layout);
            assert_ne!(q, Cov::identity() * 3.0);
        }
        assert_eq!(p, q);
    }
    assert!(!AidingMeas::from(zupt).gated() && AidingMeas::from(gnss).gated());
}

#[test]
fn kinds_are_complete() {
    assert_eq!(MeasKind::ALL.len(), MeasKind::COUNT);
    for (i, k) in MeasKind::ALL.iter().enumerate() {
        assert_eq!(k.index(), i);
    }
    let names: Vec<&str> = MeasKind::ALL.iter().map(|k| k.name()).collect();
    assert_eq!(
        names,
        [
            "gnss",
            "zupt",
            "nhc",
            "baro",
            "odometer",
            "magnetometer",
            "dual_antenna",
            "body_velocity"
        ]
    );
}
