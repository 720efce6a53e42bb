//! Barometric altimeter.

use super::positive;
use crate::aiding::layout::BlockKind;
use crate::aiding::meas::{finite, MeasError, MeasKind, MeasModel, MeasPoint, Measurement};

/// A barometric height (Groves 2nd ed. ch. 6, barometric altimeter; integration ch. 16).
///
/// Measurement: `z = h + b + v`, `h` the ellipsoidal height of the IMU, `b` the barometer
/// bias (block [`BlockKind::BaroBias`], 1 state \[m\], **required**: without it
/// [`MeasError::MissingBlock`]), `v ~ N(0, σ²)`.
/// Innovation `ν = ĥ + b̂ − z`; with `ĥ − h = δh`, `b − b̂ = x_b`: `ν = δh − x_b`, so
/// `H` is `+1` at the position index 2 (δh) and `−1` at the `BaroBias` offset (exact: the
/// model is linear). `R = σ²`. The height offset between the barometer and the IMU, and
/// the difference between the pressure height and the ellipsoidal height, are left to the
/// bias state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Baro {
    /// time of validity \[s\]
    pub t_s: f64,
    /// measured barometric height \[m\]
    pub h_baro_m: f64,
    /// σ of the height noise \[m\]
    pub sigma_m: f64,
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
        if !finite([self.t_s, self.h_baro_m]) || !positive(self.sigma_m) {
            return Err(MeasError::NonFinite);
        }
        let o = at
            .layout
            .offset(BlockKind::BaroBias)
            .ok_or(MeasError::MissingBlock(BlockKind::BaroBias))?;
        *out = MeasModel::zeros(1);
        out.nu[0] = at.h_m + at.est[o] - self.h_baro_m;
        out.h[(0, 2)] = 1.0;
        out.h[(0, o)] = -1.0;
        out.r[(0, 0)] = self.sigma_m * self.sigma_m;
        if !out.nu[0].is_finite() {
            return Err(MeasError::NonFinite);
        }
        Ok(())
    }
}
