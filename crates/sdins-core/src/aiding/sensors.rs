//! Measurement models of the aiding sensors besides GNSS position/velocity, ZUPT and the
//! body-frame NHC of [`super::meas`]: barometric height ([`Baro`]), odometer speed with the
//! optional vehicle-frame non-holonomic constraint ([`Odometer`]), a vehicle-frame velocity
//! such as a Doppler velocity log ([`BodyVelocity`]), the three-axis magnetometer
//! ([`Magnetometer`]) and the dual-antenna GNSS baseline ([`DualAntenna`]); and
//! [`AidingMeas`], one `Copy` enum of every measurement of the crate.
//!
//! Every model follows the conventions of [`super::layout`]: navigation states estimate −
//! truth (δL, δλ, δh; δv^n; ε with `Ĉ_b^n = (I + [ε×]) C_b^n`), sensor-parameter blocks
//! truth − estimate (`x_b = b − b̂`), compensated rate `ω̂_ib^b − ω_ib^b = x_bg +
//! diag(ω_ib^b) x_sg`; innovation `ν = ĥ(x̂) − z = H x + v` to first order. Every model is
//! gated (χ² test of [`super::ekf`]) and refuses non-finite inputs or a non-positive σ
//! with [`MeasError::NonFinite`].
//!
//! Sources: Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
//! Systems*, 2nd ed. (2013): ch. 6 (magnetometer, barometric altimeter, odometer, Doppler
//! velocity), ch. 10 (GNSS attitude), ch. 16 (INS/other-sensor integration). Theory and the
//! choices made: `docs/theory/aiding-sensors.md`.

mod baro;
mod dual_antenna;
mod magnetometer;
mod velocity;

#[cfg(test)]
mod tests;

pub use baro::Baro;
pub use dual_antenna::{baseline_az_el, DualAntenna};
pub use magnetometer::{mag_field_ned_ut, Magnetometer};
pub use velocity::{
    vehicle_velocity, vehicle_velocity_jacobian, BodyVelocity, Odometer, VehicleVelocity,
};

use super::layout::{Cov, StateLayout};
use super::meas::{
    GnssMeasurement, MeasError, MeasKind, MeasModel, MeasPoint, Measurement, Nhc, Zupt,
};

/// Every measurement of the crate in one `Copy` value (a queue of mixed measurements),
/// implementing [`Measurement`] by delegation to the wrapped model.
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum AidingMeas {
    /// GNSS position (and velocity) of the antenna
    Gnss(GnssMeasurement),
    /// zero-velocity update
    Zupt(Zupt),
    /// body-frame non-holonomic constraint
    Nhc(Nhc),
    /// barometric height
    Baro(Baro),
    /// odometer speed (+ vehicle-frame NHC)
    Odometer(Odometer),
    /// vehicle-frame velocity (Doppler velocity log)
    BodyVelocity(BodyVelocity),
    /// three-axis magnetometer
    Magnetometer(Magnetometer),
    /// dual-antenna GNSS baseline azimuth (and elevation)
    DualAntenna(DualAntenna),
}

macro_rules! delegate {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            AidingMeas::Gnss($m) => $e,
            AidingMeas::Zupt($m) => $e,
            AidingMeas::Nhc($m) => $e,
            AidingMeas::Baro($m) => $e,
            AidingMeas::Odometer($m) => $e,
            AidingMeas::BodyVelocity($m) => $e,
            AidingMeas::Magnetometer($m) => $e,
            AidingMeas::DualAntenna($m) => $e,
        }
    };
}

impl Measurement for AidingMeas {
    fn kind(&self) -> MeasKind {
        delegate!(self, m => m.kind())
    }
    fn t_valid_s(&self) -> f64 {
        delegate!(self, m => m.t_valid_s())
    }
    fn gated(&self) -> bool {
        delegate!(self, m => m.gated())
    }
    fn evaluate(&self, at: &MeasPoint<'_>, out: &mut MeasModel) -> Result<(), MeasError> {
        delegate!(self, m => m.evaluate(at, out))
    }
    fn reset(&self, p: &mut Cov, model: &MeasModel, layout: &StateLayout) {
        delegate!(self, m => m.reset(p, model, layout))
    }
}

macro_rules! from_variant {
    ($($v:ident($t:ty)),*) => {$(
        impl From<$t> for AidingMeas {
            fn from(m: $t) -> Self {
                AidingMeas::$v(m)
            }
        }
    )*};
}

from_variant!(
    Gnss(GnssMeasurement),
    Zupt(Zupt),
    Nhc(Nhc),
    Baro(Baro),
    Odometer(Odometer),
    BodyVelocity(BodyVelocity),
    Magnetometer(Magnetometer),
    DualAntenna(DualAntenna)
);

/// Whether a σ is finite and positive.
fn positive(sigma: f64) -> bool {
    sigma.is_finite() && sigma > 0.0
}

/// Whether the first `dim` rows of a filled model are finite (over the layout's `n` columns).
fn model_finite(out: &MeasModel, n: usize) -> bool {
    (0..out.dim).all(|i| {
        out.nu[i].is_finite()
            && (0..n).all(|j| out.h[(i, j)].is_finite())
            && (0..out.dim).all(|j| out.r[(i, j)].is_finite())
    })
}
