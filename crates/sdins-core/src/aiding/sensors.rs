//! TEMPORARY: replaced by the sensors branch.
use super::layout::{Cov, StateLayout};
use super::meas::{
    GnssMeasurement, MeasError, MeasKind, MeasModel, MeasPoint, Measurement, Nhc, Zupt,
};

/// Any measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AidingMeas {
    /// GNSS
    Gnss(GnssMeasurement),
    /// ZUPT
    Zupt(Zupt),
    /// NHC
    Nhc(Nhc),
    /// baro
    Baro(Baro),
    /// odo
    Odometer(Odometer),
    /// dvl
    BodyVelocity(BodyVelocity),
    /// mag
    Magnetometer(Magnetometer),
    /// dual
    DualAntenna(DualAntenna),
}

impl AidingMeas {
    fn inner(&self) -> &dyn Measurement {
        match self {
            AidingMeas::Gnss(m) => m,
            AidingMeas::Zupt(m) => m,
            AidingMeas::Nhc(m) => m,
            AidingMeas::Baro(m) => m,
            _ => &Zupt {
                t_s: f64::NAN,
                sigma_mps: 1.0,
            },
        }
    }
}

impl Measurement for AidingMeas {
    fn kind(&self) -> MeasKind {
        self.inner().kind()
    }
    fn t_valid_s(&self) -> f64 {
        self.inner().t_valid_s()
    }
    fn gated(&self) -> bool {
        self.inner().gated()
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        self.inner().evaluate(at, out)
    }
    fn reset(&self, p: &mut Cov, model: &MeasModel, layout: &StateLayout) {
        self.inner().reset(p, model, layout)
    }
}

use crate::math::{Mat3, Vec3};

/// TEMP
pub fn vehicle_velocity(
    c_b_n: &Mat3,
    v_n_mps: &Vec3,
    omega_ib_b: &Vec3,
    omega_ie_n: &Vec3,
    c_b_v: &Mat3,
    lever_arm_b_m: &Vec3,
) -> Vec3 {
    let ct = c_b_n.transpose();
    let w_eb = omega_ib_b - ct * omega_ie_n;
    c_b_v * (ct * v_n_mps + w_eb.cross(lever_arm_b_m))
}
/// TEMP
pub fn baseline_az_el(c_b_n: &Mat3, baseline_b_m: &Vec3) -> (f64, f64) {
    let u = c_b_n * baseline_b_m;
    (
        libm::atan2(u.y, u.x),
        libm::atan2(-u.z, libm::hypot(u.x, u.y)),
    )
}
/// TEMP
pub fn mag_field_ned_ut(declination_rad: f64, inclination_rad: f64, intensity_ut: f64) -> Vec3 {
    let (si, ci) = libm::sincos(inclination_rad);
    let (sd, cd) = libm::sincos(declination_rad);
    Vec3::new(
        intensity_ut * ci * cd,
        intensity_ut * ci * sd,
        intensity_ut * si,
    )
}
/// TEMP
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Baro {
    pub t_s: f64,
    pub h_baro_m: f64,
    pub sigma_m: f64,
}
/// TEMP
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Odometer {
    pub t_s: f64,
    pub speed_mps: f64,
    pub sigma_mps: f64,
    pub c_b_v: Mat3,
    pub lever_arm_b_m: Vec3,
    pub nhc_sigma_mps: Option<f64>,
}
/// TEMP
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyVelocity {
    pub t_s: f64,
    pub v_v_mps: Vec3,
    pub cov_mps2: Mat3,
    pub c_b_v: Mat3,
    pub lever_arm_b_m: Vec3,
}
/// TEMP
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnetometer {
    pub t_s: f64,
    pub m_b_ut: Vec3,
    pub m_n_ut: Vec3,
    pub sigma_ut: f64,
}
/// TEMP
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualAntenna {
    pub t_s: f64,
    pub az_rad: f64,
    pub el_rad: f64,
    pub baseline_b_m: Vec3,
    pub sigma_rel_m: f64,
    pub heading_only: bool,
}

impl Measurement for Baro {
    fn kind(&self) -> MeasKind {
        MeasKind::Baro
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn gated(&self) -> bool {
        true
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        let o = at
            .layout
            .offset(super::layout::BlockKind::BaroBias)
            .ok_or(MeasError::MissingBlock(super::layout::BlockKind::BaroBias))?;
        *out = MeasModel::zeros(1);
        out.nu[0] = at.h_m + at.est[o] - self.h_baro_m;
        out.h[(0, 2)] = 1.0;
        out.h[(0, o)] = -1.0;
        out.r[(0, 0)] = self.sigma_m * self.sigma_m;
        Ok(())
    }
}
