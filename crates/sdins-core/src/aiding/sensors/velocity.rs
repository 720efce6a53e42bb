//! Velocity of a point of the vehicle in the vehicle frame: the shared model of the
//! odometer (with its non-holonomic constraint) and of a body-velocity sensor (Doppler
//! velocity log).

use super::{model_finite, positive};
use crate::aiding::layout::BlockKind;
use crate::aiding::meas::{finite, set3, MeasError, MeasKind, MeasModel, MeasPoint, Measurement};
use crate::math::{skew, Mat3, Vec3};

/// Velocity of the point at lever arm `l^b` from the IMU, resolved in the vehicle frame
/// (axes `C_b^v` from the body axes): `v^v = C_b^v (C_n^b v^n + ω_eb^b × l^b)`,
/// `ω_eb^b = ω_ib^b − C_n^b ω_ie^n` (the transport rate neglected, as in the GNSS lever arm
/// of [`crate::aiding::meas::GnssMeasurement`]).
pub fn vehicle_velocity(
    c_b_n: &Mat3,
    v_n_mps: &Vec3,
    omega_ib_b: &Vec3,
    omega_ie_n: &Vec3,
    c_b_v: &Mat3,
    lever_arm_b_m: &Vec3,
) -> Vec3 {
    let c_n_b = c_b_n.transpose();
    let w_eb = omega_ib_b - c_n_b * omega_ie_n;
    c_b_v * (c_n_b * v_n_mps + w_eb.cross(lever_arm_b_m))
}

/// [`vehicle_velocity`] and its Jacobian blocks over the error state (at the estimate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VehicleVelocity {
    /// predicted velocity of the point, vehicle frame \[m/s\]
    pub v_v_mps: Vec3,
    /// over δv^n: `C_b^v Ĉᵀ`
    pub h_vel: Mat3,
    /// over ε: `C_b^v (Ĉᵀ[v̂^n×] + [l×] Ĉᵀ[ω_ie^n×])`
    pub h_att: Mat3,
    /// over the gyro bias `x_bg`: `−C_b^v [l×]`
    pub h_gyro_bias: Mat3,
    /// over the gyro scale factors `x_sg`: `−C_b^v [l×] diag(ω̂_ib^b)`
    pub h_gyro_scale: Mat3,
}

/// [`vehicle_velocity`] with its Jacobian: with `Ĉᵀ = Cᵀ(I − [ε×])`,
/// `ω̂_ib^b = ω_ib^b + x_bg + diag(ω_ib^b) x_sg`,
/// `δv^v = C_b^v (Ĉᵀ δv^n + Ĉᵀ[v̂×] ε + [l×] Ĉᵀ[ω_ie^n×] ε − [l×] x_bg − [l×] diag(ω̂) x_sg)`
/// to first order (the dependence of ω_ie^n on the latitude error is neglected:
/// `Ω_e δL |l|`, 1e-10 m/s for 1e-6 rad and 1 m).
pub fn vehicle_velocity_jacobian(
    c_b_n: &Mat3,
    v_n_mps: &Vec3,
    omega_ib_b: &Vec3,
    omega_ie_n: &Vec3,
    c_b_v: &Mat3,
    lever_arm_b_m: &Vec3,
) -> VehicleVelocity {
    let ct = c_b_n.transpose();
    let lx = skew(lever_arm_b_m);
    VehicleVelocity {
        v_v_mps: vehicle_velocity(c_b_n, v_n_mps, omega_ib_b, omega_ie_n, c_b_v, lever_arm_b_m),
        h_vel: c_b_v * ct,
        h_att: c_b_v * (ct * skew(v_n_mps) + lx * ct * skew(omega_ie_n)),
        h_gyro_bias: -(c_b_v * lx),
        h_gyro_scale: -(c_b_v * lx * Mat3::from_diagonal(omega_ib_b)),
    }
}

/// The model at the filter's estimate.
fn at_estimate(at: &MeasPoint<'_>, c_b_v: &Mat3, lever_arm_b_m: &Vec3) -> VehicleVelocity {
    let w_ie = at.earth.omega_ie_n(at.lat_rad);
    vehicle_velocity_jacobian(
        &at.c_b_n,
        &at.v_n_mps,
        &at.omega_ib_b,
        &w_ie,
        c_b_v,
        lever_arm_b_m,
    )
}

/// Write component `axis` of the vehicle velocity's Jacobian, times `scale`, into row `row`
/// of `out` (velocity, attitude, gyro bias and, when the layout has them, gyro scale).
fn put_row(
    out: &mut MeasModel,
    row: usize,
    axis: usize,
    scale: f64,
    vv: &VehicleVelocity,
    at: &MeasPoint<'_>,
) -> Result<(), MeasError> {
    let bg = at
        .layout
        .offset(BlockKind::GyroBias)
        .ok_or(MeasError::MissingBlock(BlockKind::GyroBias))?;
    let sg = at.layout.offset(BlockKind::GyroScale);
    for j in 0..3 {
        out.h[(row, 3 + j)] = scale * vv.h_vel[(axis, j)];
        out.h[(row, 6 + j)] = scale * vv.h_att[(axis, j)];
        out.h[(row, bg + j)] = scale * vv.h_gyro_bias[(axis, j)];
        if let Some(sg) = sg {
            out.h[(row, sg + j)] = scale * vv.h_gyro_scale[(axis, j)];
        }
    }
    Ok(())
}

/// Odometer speed, optionally with the non-holonomic constraint of the same point, in the
/// vehicle frame (Groves 2nd ed. ch. 6, odometry; integration ch. 16).
///
/// The odometer measures the speed of the rear-axle centre along the vehicle x axis (the
/// point at `lever_arm_b_m` from the IMU, vehicle axes `c_b_v` from the body axes; `v^v`
/// of [`vehicle_velocity`]): `z = (1 + s) v_x^v + v`, `s` the odometer scale-factor error
/// (block [`BlockKind::OdometerScale`], 1 state, **optional**: without it `ŝ = 0` and no
/// column).
/// * Row 0: `ν = (1 + ŝ) v̂_x^v − z`; `H = (1 + ŝ) ∂v_x^v/∂x` (velocity, attitude, gyro bias
///   and gyro scale rows of [`vehicle_velocity_jacobian`]) and `H_s = −v̂_x^v`;
///   `R = σ²` (`sigma_mps`).
/// * With `nhc_sigma_mps = Some(σ_n)`, rows 1, 2: the constraint that the point does not
///   slip sideways or leave the road, `z = nhc_v_mps` (zero on a vehicle: the model is
///   `v_y^v, v_z^v` white with σ_n, and a simulation draws that violation into `z`),
///   `ν = v̂_y^v − z_y`, `v̂_z^v − z_z`, `H` the y, z rows of the Jacobian, `R = σ_n²` each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Odometer {
    /// time of validity \[s\]
    pub t_s: f64,
    /// measured speed along the vehicle x axis \[m/s\]
    pub speed_mps: f64,
    /// σ of the speed noise \[m/s\]
    pub sigma_mps: f64,
    /// body → vehicle frame
    pub c_b_v: Mat3,
    /// rear-axle centre from the IMU, body frame \[m\]
    pub lever_arm_b_m: Vec3,
    /// σ of the lateral and vertical constraint \[m/s\] (None: speed only)
    pub nhc_sigma_mps: Option<f64>,
    /// the lateral and vertical velocity taken as measured by the constraint \[m/s\]:
    /// zero on a vehicle; a simulation puts the drawn violation here
    pub nhc_v_mps: [f64; 2],
}

impl Measurement for Odometer {
    fn kind(&self) -> MeasKind {
        MeasKind::Odometer
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn gated(&self) -> bool {
        true
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        let ok = finite([
            self.t_s,
            self.speed_mps,
            self.nhc_v_mps[0],
            self.nhc_v_mps[1],
        ]) && positive(self.sigma_mps)
            && finite(self.c_b_v.iter().chain(self.lever_arm_b_m.iter()).copied())
            && self.nhc_sigma_mps.is_none_or(positive);
        if !ok {
            return Err(MeasError::NonFinite);
        }
        let vv = at_estimate(at, &self.c_b_v, &self.lever_arm_b_m);
        let so = at.layout.offset(BlockKind::OdometerScale);
        let s_hat = so.map_or(0.0, |o| at.est[o]);
        *out = MeasModel::zeros(if self.nhc_sigma_mps.is_some() { 3 } else { 1 });
        out.nu[0] = (1.0 + s_hat) * vv.v_v_mps.x - self.speed_mps;
        put_row(out, 0, 0, 1.0 + s_hat, &vv, at)?;
        if let Some(o) = so {
            out.h[(0, o)] = -vv.v_v_mps.x;
        }
        out.r[(0, 0)] = self.sigma_mps * self.sigma_mps;
        if let Some(s) = self.nhc_sigma_mps {
            for row in 1..3 {
                out.nu[row] = vv.v_v_mps[row] - self.nhc_v_mps[row - 1];
                put_row(out, row, row, 1.0, &vv, at)?;
                out.r[(row, row)] = s * s;
            }
        }
        if !model_finite(out, at.layout.n()) {
            return Err(MeasError::NonFinite);
        }
        Ok(())
    }
}

/// A velocity measured in the vehicle frame, e.g. by a Doppler velocity log (Groves 2nd ed.
/// ch. 6, Doppler radar and sonar; integration ch. 16); the `BodyVelocity` measurement of
/// pyins.
///
/// `z = v^v + v`, `v^v` the velocity of the sensor's point (at `lever_arm_b_m` from the
/// IMU) in the vehicle frame (`c_b_v`) of [`vehicle_velocity`], `v ~ N(0, cov)`.
/// `ν = v̂^v − z` (3 rows), `H` the rows of [`vehicle_velocity_jacobian`] (velocity,
/// attitude, gyro bias, gyro scale when present), `R = cov`. No sensor block: a
/// scale-factor or misalignment error of the log is not modelled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyVelocity {
    /// time of validity \[s\]
    pub t_s: f64,
    /// measured velocity, vehicle frame \[m/s\]
    pub v_v_mps: Vec3,
    /// its covariance \[(m/s)²\]
    pub cov_mps2: Mat3,
    /// body → vehicle frame
    pub c_b_v: Mat3,
    /// the sensor from the IMU, body frame \[m\]
    pub lever_arm_b_m: Vec3,
}

impl Measurement for BodyVelocity {
    fn kind(&self) -> MeasKind {
        MeasKind::BodyVelocity
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn gated(&self) -> bool {
        true
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        let ok = finite([self.t_s])
            && finite(
                self.v_v_mps
                    .iter()
                    .chain(self.cov_mps2.iter())
                    .chain(self.c_b_v.iter())
                    .chain(self.lever_arm_b_m.iter())
                    .copied(),
            )
            && (0..3).all(|i| positive(self.cov_mps2[(i, i)]));
        if !ok {
            return Err(MeasError::NonFinite);
        }
        let vv = at_estimate(at, &self.c_b_v, &self.lever_arm_b_m);
        *out = MeasModel::zeros(3);
        for row in 0..3 {
            out.nu[row] = vv.v_v_mps[row] - self.v_v_mps[row];
            put_row(out, row, row, 1.0, &vv, at)?;
        }
        set3(&mut out.r, 0, 0, &self.cov_mps2);
        if !model_finite(out, at.layout.n()) {
            return Err(MeasError::NonFinite);
        }
        Ok(())
    }
}
