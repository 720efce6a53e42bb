//! One measurement interface for the error-state filter, and the measurements of the
//! loosely coupled INS/GNSS filter as its implementations: GNSS position (and velocity) of
//! an antenna at a lever arm, the zero-velocity update and the non-holonomic constraint.
//!
//! A measurement states its **time of validity** and, given the filter's estimate at that
//! time ([`MeasPoint`]: the navigation state interpolated to the time of validity, the
//! compensated body rate, the sensor-parameter estimates and the state layout), fills a
//! [`MeasModel`]: the innovation `ν = ĥ(x̂) − z` (predicted minus measured), the Jacobian
//! rows `H` over the error state (`ν = H x + v` to first order, `x` = the error state of
//! [`super::layout`]) and the covariance `R` of `v`, at most [`MAX_ROWS`] rows (more rows,
//! e.g. pseudoranges of more satellites, are applied as several measurements, valid when R
//! is block diagonal across them). The filter ([`super::ekf::Ekf::update`]) does the rest:
//! timing (a time of validity in the past is handled by back-propagation, see
//! `docs/theory/ins-gnss.md` §"Measurement timing"), the χ² gate with its reset policy for
//! gated kinds, the Joseph-form update and the report.
//!
//! Equations (Groves 2nd ed.): GNSS position of the antenna (14.110), velocity (14.111);
//! ZUPT and NHC §15.3 (zero velocity, zero lateral and vertical body velocity). The other
//! aiding sensors (barometer, odometer, magnetometer, dual-antenna GNSS, body velocity) and
//! the enum of every measurement are in [`super::sensors`].

use super::error_model::position_scale;
use super::layout::{BlockKind, Cov, StateLayout, XVec};
use super::linalg::{HMat, MVec, RMat, MAX_ROWS};
use crate::earth::EarthModel;
use crate::math::{skew, Mat3, Vec3};
use crate::nav::wrap_pi;

/// Kind of a measurement (innovation statistics and gate counters are kept per kind).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum MeasKind {
    /// GNSS position (3 rows) or position + velocity (6)
    Gnss,
    /// zero-velocity update
    Zupt,
    /// non-holonomic constraint (body y, z velocity)
    Nhc,
    /// barometric height ([`super::sensors::Baro`])
    Baro,
    /// odometer speed, optionally with the vehicle-frame NHC ([`super::sensors::Odometer`])
    Odometer,
    /// three-axis magnetometer ([`super::sensors::Magnetometer`])
    Magnetometer,
    /// dual-antenna GNSS baseline azimuth and elevation ([`super::sensors::DualAntenna`])
    DualAntenna,
    /// vehicle-frame velocity, e.g. a Doppler velocity log ([`super::sensors::BodyVelocity`])
    BodyVelocity,
}

impl MeasKind {
    /// Number of kinds.
    pub const COUNT: usize = 8;
    /// Every kind, in [`MeasKind::index`] order.
    pub const ALL: [MeasKind; MeasKind::COUNT] = [
        MeasKind::Gnss,
        MeasKind::Zupt,
        MeasKind::Nhc,
        MeasKind::Baro,
        MeasKind::Odometer,
        MeasKind::Magnetometer,
        MeasKind::DualAntenna,
        MeasKind::BodyVelocity,
    ];
    /// Index `0 … COUNT−1`.
    pub fn index(self) -> usize {
        match self {
            MeasKind::Gnss => 0,
            MeasKind::Zupt => 1,
            MeasKind::Nhc => 2,
            MeasKind::Baro => 3,
            MeasKind::Odometer => 4,
            MeasKind::Magnetometer => 5,
            MeasKind::DualAntenna => 6,
            MeasKind::BodyVelocity => 7,
        }
    }
    /// Name (CSV `kind` column).
    pub fn name(self) -> &'static str {
        match self {
            MeasKind::Gnss => "gnss",
            MeasKind::Zupt => "zupt",
            MeasKind::Nhc => "nhc",
            MeasKind::Baro => "baro",
            MeasKind::Odometer => "odometer",
            MeasKind::Magnetometer => "magnetometer",
            MeasKind::DualAntenna => "dual_antenna",
            MeasKind::BodyVelocity => "body_velocity",
        }
    }
}

/// The filter's estimate at a measurement's time of validity.
#[derive(Clone, Copy, Debug)]
pub struct MeasPoint<'a> {
    /// time of validity \[s\] (navigation time base)
    pub t_s: f64,
    /// latitude \[rad\]
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// ellipsoidal height \[m\]
    pub h_m: f64,
    /// NED velocity \[m/s\]
    pub v_n_mps: Vec3,
    /// attitude body → NED
    pub c_b_n: Mat3,
    /// compensated angular rate, body \[rad/s\]
    pub omega_ib_b: Vec3,
    /// the earth model
    pub earth: &'a EarthModel,
    /// the state layout (block offsets)
    pub layout: &'a StateLayout,
    /// sensor-parameter estimates at their block offsets (b̂_a, b̂_g, ŝ, …)
    pub est: &'a XVec,
}

/// A measurement's model at the estimate: `ν = ĥ − z` (first `dim` entries), `H`
/// (`dim × n` at the layout's offsets), `R`.
#[derive(Clone, Debug, PartialEq)]
pub struct MeasModel {
    /// number of rows (1 … [`MAX_ROWS`])
    pub dim: usize,
    /// innovation ν = ĥ − z
    pub nu: MVec,
    /// Jacobian of ν over the error state
    pub h: HMat,
    /// measurement-noise covariance
    pub r: RMat,
}

impl MeasModel {
    /// A zero model of `dim` rows (capped at [`MAX_ROWS`]).
    pub fn zeros(dim: usize) -> Self {
        Self {
            dim: dim.min(MAX_ROWS),
            nu: MVec::zeros(),
            h: HMat::zeros(),
            r: RMat::zeros(),
        }
    }
}

/// Why a measurement cannot be evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeasError {
    /// a value of the measurement is not finite
    NonFinite,
    /// the layout lacks a block the measurement needs
    MissingBlock(BlockKind),
}

/// A measurement the filter can apply.
pub trait Measurement {
    /// Its kind.
    fn kind(&self) -> MeasKind;
    /// Time of validity \[s\] on the navigation time base.
    fn t_valid_s(&self) -> f64;
    /// Whether the χ² gate (and, after repeated rejections, [`Measurement::reset`]) applies.
    fn gated(&self) -> bool {
        false
    }
    /// Fill the model at the filter's estimate `at`.
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError>;
    /// The reset policy after too many consecutive rejections: re-seed the covariance of
    /// the states this measurement observes directly (the update is then applied
    /// ungated). Default: nothing.
    fn reset(&self, _p: &mut Cov, _model: &MeasModel, _layout: &StateLayout) {}
}

/// A GNSS fix as the filter sees it: the antenna's geodetic position, optionally the NED
/// velocity, with their NED covariances, and the antenna's lever arm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GnssMeasurement {
    /// time of validity \[s\] (the navigation time base)
    pub t_s: f64,
    /// antenna latitude \[rad\]
    pub lat_rad: f64,
    /// antenna longitude \[rad\]
    pub lon_rad: f64,
    /// antenna ellipsoidal height \[m\]
    pub h_m: f64,
    /// NED position covariance \[m²\]
    pub pos_cov_ned_m2: Mat3,
    /// NED velocity \[m/s\] and covariance \[(m/s)²\]
    pub vel: Option<(Vec3, Mat3)>,
    /// antenna lever arm from the IMU, body frame \[m\]
    pub lever_arm_b_m: Vec3,
}

pub(super) fn finite(v: impl IntoIterator<Item = f64>) -> bool {
    v.into_iter().all(f64::is_finite)
}

impl Measurement for GnssMeasurement {
    fn kind(&self) -> MeasKind {
        MeasKind::Gnss
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn gated(&self) -> bool {
        true
    }

    /// Position (Groves (14.110)): `p̂_a = p̂ + Ĉ l`, `ν_p = T (L̂_a − L, λ̂_a − λ, ĥ_a − h)`
    /// with `T = diag(R_M+h, (R_N+h) cos L, −1)`, `H_p = [T, 0, −[(Ĉ l)×], 0, 0]`.
    /// Velocity (Groves (14.111)): `v̂_a = v̂ + Ĉ(ω̂_eb^b × l)`, `ω_eb^b = ω_ib^b − Ĉᵀω_ie^n`,
    /// `H_v = [0, I, −[(Ĉ(ω×l))×], 0, −Ĉ[l×]]` and `−Ĉ[l×]diag(ω_ib^b)` on the gyro scale
    /// factors when the layout has them.
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        let ok = finite([self.t_s, self.lat_rad, self.lon_rad, self.h_m])
            && finite(self.pos_cov_ned_m2.iter().copied())
            && finite(self.lever_arm_b_m.iter().copied())
            && self
                .vel
                .is_none_or(|(v, c)| finite(v.iter().chain(c.iter()).copied()));
        if !ok {
            return Err(MeasError::NonFinite);
        }
        let (lat, lon, h, c) = (at.lat_rad, at.lon_rad, at.h_m, at.c_b_n);
        let l = self.lever_arm_b_m;
        let r = at.earth.radii(lat);
        let (_, cl) = libm::sincos(lat);
        let t = position_scale(r.r_m_m, r.r_n_m, cl, h);
        let cl_n = c * l;
        *out = MeasModel::zeros(if self.vel.is_some() { 6 } else { 3 });
        out.nu[0] = (lat - self.lat_rad) * t.x + cl_n.x;
        out.nu[1] = wrap_pi(lon - self.lon_rad) * t.y + cl_n.y;
        out.nu[2] = -(h - self.h_m) + cl_n.z;
        for i in 0..3 {
            out.h[(i, i)] = t[i];
        }
        let att = -skew(&cl_n);
        set3(&mut out.h, 0, 6, &att);
        set3(&mut out.r, 0, 0, &self.pos_cov_ned_m2);
        if let Some((v_meas, v_cov)) = self.vel {
            let w_ie_n = at.earth.omega_ie_n(lat);
            let w_eb = at.omega_ib_b - c.transpose() * w_ie_n;
            let wl = c * w_eb.cross(&l);
            let nu_v = at.v_n_mps + wl - v_meas;
            for i in 0..3 {
                out.nu[3 + i] = nu_v[i];
                out.h[(3 + i, 3 + i)] = 1.0;
            }
            set3(&mut out.h, 3, 6, &(-skew(&wl)));
            let cl_x = c * skew(&l);
            let bg = at
                .layout
                .offset(BlockKind::GyroBias)
                .ok_or(MeasError::MissingBlock(BlockKind::GyroBias))?;
            set3(&mut out.h, 3, bg, &(-cl_x));
            if let Some(sg) = at.layout.offset(BlockKind::GyroScale) {
                let w = Mat3::from_diagonal(&at.omega_ib_b);
                set3(&mut out.h, 3, sg, &(-(cl_x * w)));
            }
            set3(&mut out.r, 3, 3, &v_cov);
        }
        Ok(())
    }

    /// Decorrelate position (and, with a velocity, velocity) and re-seed them with 100 R
    /// (the position block mapped to (δL, δλ, δh) by the diagonal of `H_p`).
    fn reset(&self, p: &mut Cov, model: &MeasModel, _layout: &StateLayout) {
        let with_vel = model.dim == 6;
        let t = [model.h[(0, 0)], model.h[(1, 1)], model.h[(2, 2)]];
        for i in 0..3 {
            p.row_mut(i).fill(0.0);
            p.column_mut(i).fill(0.0);
            if with_vel {
                p.row_mut(3 + i).fill(0.0);
                p.column_mut(3 + i).fill(0.0);
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                p[(i, j)] = 100.0 * model.r[(i, j)] / (t[i] * t[j]);
                if with_vel {
                    p[(3 + i, 3 + j)] = 100.0 * model.r[(3 + i, 3 + j)];
                }
            }
        }
    }
}

/// Zero-velocity update: `ν = v̂^n`, `H = [0, I, 0, …]`, `R = σ² I` (the caller decides
/// when the vehicle is at rest).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Zupt {
    /// time of validity \[s\]
    pub t_s: f64,
    /// σ per axis \[m/s\]
    pub sigma_mps: f64,
}

impl Measurement for Zupt {
    fn kind(&self) -> MeasKind {
        MeasKind::Zupt
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        if !finite([self.t_s, self.sigma_mps]) {
            return Err(MeasError::NonFinite);
        }
        *out = MeasModel::zeros(3);
        let var = self.sigma_mps * self.sigma_mps;
        for i in 0..3 {
            out.nu[i] = at.v_n_mps[i];
            out.h[(i, 3 + i)] = 1.0;
            out.r[(i, i)] = var;
        }
        Ok(())
    }
}

/// Non-holonomic constraint (body frame = vehicle frame): `ν = (Ĉᵀ v̂)_{y,z}`,
/// `H = rows y, z of [0, Ĉᵀ, Ĉᵀ[v̂×], 0, 0]`, `R = σ² I`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nhc {
    /// time of validity \[s\]
    pub t_s: f64,
    /// σ per axis \[m/s\]
    pub sigma_mps: f64,
}

impl Measurement for Nhc {
    fn kind(&self) -> MeasKind {
        MeasKind::Nhc
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        if !finite([self.t_s, self.sigma_mps]) {
            return Err(MeasError::NonFinite);
        }
        let ct = at.c_b_n.transpose();
        let v = at.v_n_mps;
        let v_b = ct * v;
        let ha = ct * skew(&v);
        *out = MeasModel::zeros(2);
        for (row, axis) in [1usize, 2].iter().enumerate() {
            for j in 0..3 {
                out.h[(row, 3 + j)] = ct[(*axis, j)];
                out.h[(row, 6 + j)] = ha[(*axis, j)];
            }
        }
        out.nu[0] = v_b.y;
        out.nu[1] = v_b.z;
        let var = self.sigma_mps * self.sigma_mps;
        out.r[(0, 0)] = var;
        out.r[(1, 1)] = var;
        Ok(())
    }
}

pub(super) fn set3<const R: usize, const C: usize>(
    m: &mut nalgebra::SMatrix<f64, R, C>,
    r0: usize,
    c0: usize,
    v: &Mat3,
) {
    for i in 0..3 {
        for j in 0..3 {
            m[(r0 + i, c0 + j)] = v[(i, j)];
        }
    }
}
