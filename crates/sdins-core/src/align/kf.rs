//! Kalman filter core for the alignment filters (docs/theory/alignment.md §"Fine alignment"):
//! prediction with a given `(Φ, Q_d)` and the Joseph-form update; the covariance is re-symmetrised
//! after every step so that it stays symmetric positive definite.

use nalgebra::{SMatrix, SVector};

/// State estimate and covariance of an N-state filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kf<const N: usize> {
    /// state estimate x̂
    pub x: SVector<f64, N>,
    /// covariance P
    pub p: SMatrix<f64, N, N>,
}

impl<const N: usize> Kf<N> {
    /// Start at `x̂ = 0` with covariance `p0`.
    pub fn new(p0: SMatrix<f64, N, N>) -> Self {
        Self {
            x: SVector::zeros(),
            p: p0,
        }
    }

    /// Time update `x̂ ← Φ x̂`, `P ← Φ P Φᵀ + Q_d`.
    pub fn predict(&mut self, phi: &SMatrix<f64, N, N>, qd: &SMatrix<f64, N, N>) {
        self.x = phi * self.x;
        self.p = phi * self.p * phi.transpose() + qd;
        self.symmetrize();
    }

    /// Measurement update with `z = H x + ν`, `ν ~ N(0, R)`, Joseph form (docs/theory/alignment.md
    /// §"Fine alignment"): `K = P Hᵀ (H P Hᵀ + R)⁻¹`, `x̂ ← x̂ + K (z − H x̂)`,
    /// `P ← (I − KH) P (I − KH)ᵀ + K R Kᵀ`.
    /// Returns the innovation, or `None` (no update) if `H P Hᵀ + R` is singular.
    pub fn update<const M: usize>(
        &mut self,
        h: &SMatrix<f64, M, N>,
        z: &SVector<f64, M>,
        r: &SMatrix<f64, M, M>,
    ) -> Option<SVector<f64, M>> {
        let s = h * self.p * h.transpose() + r;
        let si = s.try_inverse()?;
        let k = self.p * h.transpose() * si;
        let innov = z - h * self.x;
        self.x += k * innov;
        let ikh = SMatrix::<f64, N, N>::identity() - k * h;
        self.p = ikh * self.p * ikh.transpose() + k * r * k.transpose();
        self.symmetrize();
        Some(innov)
    }

    /// `P ← ½ (P + Pᵀ)`.
    pub fn symmetrize(&mut self) {
        self.p = (self.p + self.p.transpose()) * 0.5;
    }

    /// Standard deviations √P_ii.
    pub fn sigma(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| libm::sqrt(self.p[(i, i)].max(0.0)))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    /// Scalar random constant: after n updates P = 1/(1/p0 + n/r).
    #[test]
    fn scalar_constant_matches_closed_form() {
        let mut kf = Kf::<1>::new(SMatrix::from_element(4.0));
        let h = SMatrix::<f64, 1, 1>::identity();
        let r = SMatrix::<f64, 1, 1>::from_element(0.5);
        for _ in 0..10 {
            kf.predict(&h, &SMatrix::zeros());
            kf.update(&h, &SVector::from_element(1.0), &r).unwrap();
        }
        let p = 1.0 / (1.0 / 4.0 + 10.0 / 0.5);
        assert!((kf.p[(0, 0)] - p).abs() < 1e-14);
        // x̂ = (n/r)/(1/p0 + n/r) · 1
        assert!((kf.x[0] - 20.0 / 20.25).abs() < 1e-14);
    }
}
