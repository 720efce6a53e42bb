//! Three-axis magnetometer.

use super::{model_finite, positive};
use crate::aiding::layout::BlockKind;
use crate::aiding::meas::{finite, set3, MeasError, MeasKind, MeasModel, MeasPoint, Measurement};
use crate::math::{skew, Mat3, Vec3};

/// The reference (earth) magnetic field in NED \[µT\] from the declination D, the
/// inclination (dip) I and the total intensity F (e.g. of a geomagnetic model):
/// `(F cos I cos D, F cos I sin D, F sin I)`.
pub fn mag_field_ned_ut(declination_rad: f64, inclination_rad: f64, intensity_ut: f64) -> Vec3 {
    let (sd, cd) = libm::sincos(declination_rad);
    let (si, ci) = libm::sincos(inclination_rad);
    Vec3::new(
        intensity_ut * ci * cd,
        intensity_ut * ci * sd,
        intensity_ut * si,
    )
}

/// A three-axis magnetometer (Groves 2nd ed. ch. 6, magnetic heading; integration ch. 16).
///
/// Choice: the whole field vector in body axes is the measurement, not a heading derived
/// from it, so that roll and pitch need not be known to form it, the three axes observe
/// the hard iron, and the attitude Jacobian is exact to first order in all three angles.
/// `z = C_n^b m^n + b_hi + v`, `m^n` the reference field (NED, [`mag_field_ned_ut`]),
/// `b_hi` the hard-iron bias in body axes (block [`BlockKind::MagHardIron`], 3 states
/// \[µT\], **optional**: without it `b̂_hi = 0` and no columns), `v ~ N(0, σ² I)`. Soft iron
/// and the local disturbances of the field are not modelled (they show as a larger σ).
/// `ν = Ĉᵀ m^n + b̂_hi − z`; with `Ĉᵀ = Cᵀ(I − [ε×])`: `H_att = Ĉᵀ[m^n×]`,
/// `H_hi = −I`; `R = σ² I`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Magnetometer {
    /// time of validity \[s\]
    pub t_s: f64,
    /// measured field, body axes \[µT\]
    pub m_b_ut: Vec3,
    /// reference field, NED \[µT\]
    pub m_n_ut: Vec3,
    /// σ per axis \[µT\]
    pub sigma_ut: f64,
}

impl Measurement for Magnetometer {
    fn kind(&self) -> MeasKind {
        MeasKind::Magnetometer
    }
    fn t_valid_s(&self) -> f64 {
        self.t_s
    }
    fn gated(&self) -> bool {
        true
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        let ok = finite([self.t_s])
            && finite(self.m_b_ut.iter().chain(self.m_n_ut.iter()).copied())
            && positive(self.sigma_ut);
        if !ok {
            return Err(MeasError::NonFinite);
        }
        let ct = at.c_b_n.transpose();
        let hi = at.layout.offset(BlockKind::MagHardIron);
        let b_hat = hi.map_or(Vec3::zeros(), |o| {
            Vec3::new(at.est[o], at.est[o + 1], at.est[o + 2])
        });
        let nu = ct * self.m_n_ut + b_hat - self.m_b_ut;
        *out = MeasModel::zeros(3);
        let var = self.sigma_ut * self.sigma_ut;
        for i in 0..3 {
            out.nu[i] = nu[i];
            out.r[(i, i)] = var;
        }
        set3(&mut out.h, 0, 6, &(ct * skew(&self.m_n_ut)));
        if let Some(o) = hi {
            set3(&mut out.h, 0, o, &(-Mat3::identity()));
        }
        if !model_finite(out, at.layout.n()) {
            return Err(MeasError::NonFinite);
        }
        Ok(())
    }
}
