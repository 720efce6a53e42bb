//! Dual-antenna GNSS attitude (the baseline's azimuth and elevation).

use super::{model_finite, positive};
use crate::aiding::meas::{finite, MeasError, MeasKind, MeasModel, MeasPoint, Measurement};
use crate::math::{skew, Mat3, Vec3};
use crate::nav::wrap_pi;

/// Smallest `cos el` of a usable baseline (elevation within ~1e-6 rad of ±90°: no azimuth).
const MIN_COS_EL: f64 = 1e-6;

/// Azimuth (clockwise from north, `atan2(u_E, u_N)`) and elevation (up positive,
/// `atan2(−u_D, hypot(u_N, u_E))`) \[rad\] of the baseline `b^b` (body frame, any
/// length) resolved in NED, `u^n = C_b^n b^b`.
pub fn baseline_az_el(c_b_n: &Mat3, baseline_b_m: &Vec3) -> (f64, f64) {
    let u = c_b_n * baseline_b_m;
    (
        libm::atan2(u.y, u.x),
        libm::atan2(-u.z, libm::hypot(u.x, u.y)),
    )
}

/// The azimuth and elevation of the baseline between two GNSS antennas, from a
/// carrier-phase attitude solution (Groves 2nd ed. ch. 10, GNSS attitude determination;
/// integration ch. 16).
///
/// `u^n = C_b^n b^b/L`, `L = |b^b|`, `az = atan2(u_E, u_N)`,
/// `el = atan2(−u_D, hypot(u_N, u_E))` ([`baseline_az_el`]); `z = (az, el) + v`.
/// * `ν_az = wrap(âz − z_az)` to (−π, π], `ν_el = êl − z_el` (dropped when `heading_only`:
///   one row).
/// * With `û = (I + [ε×]) u`: `∂u/∂ε = −[u×]`; `∂az/∂u = (−u_E, u_N, 0)/ρ²`,
///   `∂el/∂u = (u_D u_N/ρ, u_D u_E/ρ, −ρ)` (`ρ = hypot(u_N, u_E) = cos el`), so
///   `H_az = −(∂az/∂u)[u×]`, `H_el = −(∂el/∂u)[u×]` on the attitude columns only.
/// * `R = diag(σ_az², σ_el²)`, `σ_az = σ_rel/(L cos êl)`, `σ_el = σ_rel/L` (`σ_rel` the
///   relative-position σ of one antenna with respect to the other, per axis; the predicted
///   elevation).
///
/// Refused with [`MeasError::NonFinite`]: a zero-length baseline, a predicted or measured
/// elevation within ~1e-6 rad of ±90° (no azimuth).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualAntenna {
    /// time of validity \[s\]
    pub t_s: f64,
    /// measured azimuth of the baseline, clockwise from north \[rad\]
    pub az_rad: f64,
    /// measured elevation of the baseline, up positive \[rad\] (ignored when `heading_only`
    /// except for the ±90° check)
    pub el_rad: f64,
    /// baseline from the first to the second antenna, body frame \[m\]
    pub baseline_b_m: Vec3,
    /// σ of the relative antenna position per axis \[m\]
    pub sigma_rel_m: f64,
    /// azimuth row only
    pub heading_only: bool,
}

impl Measurement for DualAntenna {
    fn kind(&self) -> MeasKind {
        MeasKind::DualAntenna
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn gated(&self) -> bool {
        true
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        let ok = finite([self.t_s, self.az_rad, self.el_rad])
            && finite(self.baseline_b_m.iter().copied())
            && positive(self.sigma_rel_m);
        if !ok {
            return Err(MeasError::NonFinite);
        }
        let len = self.baseline_b_m.norm();
        if len <= 0.0 || !len.is_finite() || libm::cos(self.el_rad) < MIN_COS_EL {
            return Err(MeasError::NonFinite);
        }
        let u = at.c_b_n * self.baseline_b_m / len;
        let rho = libm::hypot(u.x, u.y);
        if rho < MIN_COS_EL {
            return Err(MeasError::NonFinite);
        }
        let az = libm::atan2(u.y, u.x);
        let el = libm::atan2(-u.z, rho);
        let du = -skew(&u);
        let d_az = Vec3::new(-u.y, u.x, 0.0) / (rho * rho);
        let d_el = Vec3::new(u.z * u.x / rho, u.z * u.y / rho, -rho);
        let (h_az, h_el) = (d_az.transpose() * du, d_el.transpose() * du);
        let s_el = self.sigma_rel_m / len;
        let s_az = s_el / rho;
        *out = MeasModel::zeros(if self.heading_only { 1 } else { 2 });
        out.nu[0] = wrap_pi(az - self.az_rad);
        out.r[(0, 0)] = s_az * s_az;
        for j in 0..3 {
            out.h[(0, 6 + j)] = h_az[j];
        }
        if !self.heading_only {
            out.nu[1] = el - self.el_rad;
            out.r[(1, 1)] = s_el * s_el;
            for j in 0..3 {
                out.h[(1, 6 + j)] = h_el[j];
            }
        }
        if !model_finite(out, at.layout.n()) {
            return Err(MeasError::NonFinite);
        }
        Ok(())
    }
}
