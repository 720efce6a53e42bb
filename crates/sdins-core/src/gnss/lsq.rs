//! Weighted least squares with four unknowns (three axes and a clock term) and the
//! dilution-of-precision figures (Groves 2nd ed. §9.4.1 "Single-Epoch Navigation Solution"
//! and §9.4.3 "Signal Geometry and Navigation Solution Accuracy").

use super::GnssError;
use nalgebra::{Matrix4, Vector4};

/// Largest accepted 1-norm condition number ‖N‖₁‖N⁻¹‖₁ of a normal matrix: beyond it the
/// geometry is refused as singular (a GPS solution with GDOP 1000 is near 1e7).
pub const MAX_CONDITION: f64 = 1e12;

/// Accumulated normal equations `N = Σ w h hᵀ`, `b = Σ w h z`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Normal4 {
    n: Matrix4<f64>,
    b: Vector4<f64>,
    rows: usize,
}

fn norm1(m: &Matrix4<f64>) -> f64 {
    (0..4)
        .map(|j| (0..4).map(|i| libm::fabs(m[(i, j)])).sum::<f64>())
        .fold(0.0, f64::max)
}

impl Normal4 {
    pub(crate) fn new() -> Self {
        Normal4 {
            n: Matrix4::zeros(),
            b: Vector4::zeros(),
            rows: 0,
        }
    }

    /// Adds one measurement row `h` with residual `z` and weight `w = 1/σ²`.
    pub(crate) fn add(&mut self, h: &Vector4<f64>, z: f64, w: f64) {
        self.n += h * h.transpose() * w;
        self.b += h * (w * z);
        self.rows += 1;
    }

    #[cfg(test)]
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// `x = N⁻¹ b` and `N⁻¹`, or [`GnssError::SingularGeometry`] when N is not positive
    /// definite or its condition number exceeds [`MAX_CONDITION`].
    pub(crate) fn solve(&self) -> Result<(Vector4<f64>, Matrix4<f64>), GnssError> {
        if !self.n.iter().chain(self.b.iter()).all(|v| v.is_finite()) {
            return Err(GnssError::NonFinite {
                what: "normal equations",
            });
        }
        let chol = self.n.cholesky().ok_or(GnssError::SingularGeometry)?;
        let q = chol.inverse();
        if !q.iter().all(|v| v.is_finite()) || norm1(&self.n) * norm1(&q) > MAX_CONDITION {
            return Err(GnssError::SingularGeometry);
        }
        let x = q * self.b;
        Ok((x, q))
    }
}

/// Dilution of precision from the unweighted geometry matrix with rows
/// `[−u_N, −u_E, −u_D, 1]` (u the NED line of sight): `Q = (GᵀG)⁻¹`,
/// GDOP = √tr Q, PDOP = √(Q_NN + Q_EE + Q_DD), HDOP = √(Q_NN + Q_EE), VDOP = √Q_DD,
/// TDOP = √Q_tt (Groves §9.4.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dop {
    /// geometric DOP
    pub gdop: f64,
    /// position DOP
    pub pdop: f64,
    /// horizontal DOP
    pub hdop: f64,
    /// vertical DOP
    pub vdop: f64,
    /// time DOP
    pub tdop: f64,
}

impl Dop {
    /// DOP from `Q = (GᵀG)⁻¹` in NED + clock order.
    pub(crate) fn from_q(q: &Matrix4<f64>) -> Self {
        let s = |v: f64| libm::sqrt(v.max(0.0));
        Dop {
            gdop: s(q.trace()),
            pdop: s(q[(0, 0)] + q[(1, 1)] + q[(2, 2)]),
            hdop: s(q[(0, 0)] + q[(1, 1)]),
            vdop: s(q[(2, 2)]),
            tdop: s(q[(3, 3)]),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn collinear_rows_are_singular() {
        let mut n = Normal4::new();
        for _ in 0..6 {
            n.add(&Vector4::new(0.6, 0.0, -0.8, 1.0), 1.0, 1.0);
        }
        assert_eq!(n.solve().unwrap_err(), GnssError::SingularGeometry);
    }

    #[test]
    fn tetrahedron_dop() {
        // a regular tetrahedron-like geometry: zenith + three at −19.47° elevation
        let s = 1.0 / 3.0;
        let c = libm::sqrt(8.0) / 3.0;
        let mut n = Normal4::new();
        n.add(&Vector4::new(0.0, 0.0, 1.0, 1.0), 0.0, 1.0);
        for k in 0..3 {
            let a = 2.0 * core::f64::consts::PI * k as f64 / 3.0;
            n.add(
                &Vector4::new(-c * libm::cos(a), -c * libm::sin(a), -s, 1.0),
                0.0,
                1.0,
            );
        }
        let (_, q) = n.solve().unwrap();
        let d = Dop::from_q(&q);
        // regular tetrahedron: Σu = 0, Σuuᵀ = (4/3) I, so GᵀG = diag(4/3, 4/3, 4/3, 4) and
        // Q = diag(3/4, 3/4, 3/4, 1/4)
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(d.pdop, 1.5) && close(d.hdop, libm::sqrt(1.5)));
        assert!(close(d.vdop, libm::sqrt(0.75)) && close(d.tdop, 0.5));
        assert!(close(d.gdop, libm::sqrt(2.5)));
    }
}
