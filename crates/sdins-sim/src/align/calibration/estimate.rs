//! Least-squares estimation of a sensor triad's bias, scale factors and misalignments
//! from measured and exact increments (docs/theory/calibration.md §2–§3).
//!
//! Model (per sample k of period δt, average rate or specific force over the sample):
//!
//! ```text
//! y_k = b + (I + K) x_k + n_k,     n_k ~ N(0, diag(N_i²/δt))
//! K = [ s_x   m_xy  m_xz ]
//!     [ m_yx  s_y   m_yz ]        s_i scale-factor errors, m_ij misalignments
//!     [ m_zx  m_zy  s_z  ]
//! ```
//!
//! with `x_k` the exact value (truth increment / δt), `y_k` the measured one and `N_i`
//! the white-noise density (ARW in rad/√s, VRW in m/s/√s). Row i of the model involves
//! only the four unknowns `θ_i = [b_i, K_i0, K_i1, K_i2]` and the regressor
//! `φ_k = [1, x_k0, x_k1, x_k2]`, so the 12-parameter problem separates into three
//! 4-parameter linear least-squares problems with a common normal matrix
//! `A = Σ φ_k φ_kᵀ`: `θ̂_i = A⁻¹ Σ φ_k (y_ki − x_ki)`, `cov θ̂_i = (N_i²/δt) A⁻¹`
//! (Gauss–Markov theorem; the estimate is exact for noise-free data whatever the
//! schedule, provided `A` is non-singular). The sums stream over the samples: nothing is
//! stored.

use nalgebra::{Matrix3, Matrix4, Matrix4x3, Vector4};
use sdins_core::math::Vec3;

/// Why an estimate cannot be formed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EstimateError {
    /// The normal matrix is singular: the schedule does not excite every axis (for
    /// gyros: rotations about all three axes; for accelerometers: gravity along at least
    /// three independent directions and the bias separable).
    #[error("the {sensor} parameters are not observable from this schedule (normal matrix not positive definite{hint})")]
    Unobservable {
        /// `gyro` or `accelerometer`
        sensor: &'static str,
        /// extra hint
        hint: String,
    },
    /// Fewer samples than parameters.
    #[error("{sensor}: {n} samples are too few for 4 unknowns per axis")]
    TooFewSamples {
        /// `gyro` or `accelerometer`
        sensor: &'static str,
        /// number of samples
        n: u64,
    },
}

/// Streaming accumulator of one triad's normal equations.
#[derive(Clone, Debug, PartialEq)]
pub struct TriadAccumulator {
    a: Matrix4<f64>,
    r: Matrix4x3<f64>,
    /// Σ (y − x)_i² for the residual sum of squares
    ee: Vec3,
    n: u64,
}

impl Default for TriadAccumulator {
    fn default() -> Self {
        Self {
            a: Matrix4::zeros(),
            r: Matrix4x3::zeros(),
            ee: Vec3::zeros(),
            n: 0,
        }
    }
}

/// One triad's estimate: bias, `K` and the 4×4 covariance of each output axis' row.
#[derive(Clone, Debug, PartialEq)]
pub struct TriadEstimate {
    /// bias b (rad/s or m/s²)
    pub bias: Vec3,
    /// `K` (scale-factor errors on the diagonal, misalignments off it), dimensionless
    pub k: Matrix3<f64>,
    /// per output axis i, the covariance of `[b_i, K_i0, K_i1, K_i2]`
    pub cov_rows: [Matrix4<f64>; 3],
    /// per axis, the noise density used for the covariance (rad/√s or m/s/√s)
    pub density: Vec3,
    /// per axis, the density estimated from the residuals, `√(RSS/(n − 4)·δt)`
    pub density_residual: Vec3,
    /// number of samples
    pub samples: u64,
}

impl TriadAccumulator {
    /// Add one sample: exact value `x` and measured value `y` (rates or specific forces).
    #[inline]
    pub fn add(&mut self, x: &Vec3, y: &Vec3) {
        let phi = Vector4::new(1.0, x.x, x.y, x.z);
        let e = y - x;
        // symmetric rank-one update (upper triangle; mirrored in `solve`)
        for j in 0..4 {
            for i in 0..=j {
                self.a[(i, j)] += phi[i] * phi[j];
            }
            for c in 0..3 {
                self.r[(j, c)] += phi[j] * e[c];
            }
        }
        self.ee += e.component_mul(&e);
        self.n += 1;
    }

    /// Number of samples added.
    pub fn samples(&self) -> u64 {
        self.n
    }

    /// Solve the normal equations. `density` is the per-axis white-noise density for
    /// the covariance (`None`: the residual estimate), `dt_s` the sample period.
    pub fn solve(
        &self,
        sensor: &'static str,
        density: Option<Vec3>,
        dt_s: f64,
    ) -> Result<TriadEstimate, EstimateError> {
        if self.n <= 4 {
            return Err(EstimateError::TooFewSamples { sensor, n: self.n });
        }
        let mut a = self.a;
        for j in 0..4 {
            for i in 0..j {
                a[(j, i)] = a[(i, j)];
            }
        }
        // equilibrate (the columns differ in scale by up to g/ω_ie ~ 1e5) before Cholesky
        let d = Vector4::from_fn(|i, _| 1.0 / a[(i, i)].sqrt());
        if d.iter().any(|x| !x.is_finite()) {
            return Err(EstimateError::Unobservable {
                sensor,
                hint: ": an axis is never excited".into(),
            });
        }
        let scaled = Matrix4::from_fn(|i, j| a[(i, j)] * d[i] * d[j]);
        let Some(ch) = scaled.cholesky() else {
            return Err(EstimateError::Unobservable {
                sensor,
                hint: String::new(),
            });
        };
        let inv_scaled = ch.inverse();
        // reciprocal condition guard: a rank-deficient schedule leaves a pivot at rounding level
        let diag_min = ch
            .l()
            .diagonal()
            .iter()
            .fold(f64::INFINITY, |m, x| m.min(*x));
        if diag_min < 1e-7 {
            return Err(EstimateError::Unobservable {
                sensor,
                hint: format!(": smallest scaled pivot {diag_min:.1e}"),
            });
        }
        let a_inv = Matrix4::from_fn(|i, j| inv_scaled[(i, j)] * d[i] * d[j]);
        let theta = a_inv * self.r;
        let mut bias = Vec3::zeros();
        let mut k = Matrix3::zeros();
        let mut density_residual = Vec3::zeros();
        for i in 0..3 {
            let t = theta.column(i);
            bias[i] = t[0];
            for j in 0..3 {
                k[(i, j)] = t[1 + j];
            }
            // RSS = Σe² − θᵀ r (normal equations)
            let rss = (self.ee[i] - t.dot(&self.r.column(i))).max(0.0);
            density_residual[i] = (rss / (self.n - 4) as f64 * dt_s).sqrt();
        }
        let density = density.unwrap_or(density_residual);
        let cov_rows = core::array::from_fn(|i| a_inv * (density[i] * density[i] / dt_s));
        Ok(TriadEstimate {
            bias,
            k,
            cov_rows,
            density,
            density_residual,
            samples: self.n,
        })
    }
}

impl TriadEstimate {
    /// Normalised estimation error squared of the 12 parameters against the true `bias`
    /// and `k`: `Σ_i eᵢᵀ P_i⁻¹ eᵢ`, `e_i = θ̂_i − θ_i` (χ²(12) for a consistent estimate).
    pub fn nees(&self, bias: &Vec3, k: &Matrix3<f64>) -> f64 {
        (0..3)
            .map(|i| {
                let e = Vector4::new(
                    self.bias[i] - bias[i],
                    self.k[(i, 0)] - k[(i, 0)],
                    self.k[(i, 1)] - k[(i, 1)],
                    self.k[(i, 2)] - k[(i, 2)],
                );
                self.cov_rows[i]
                    .cholesky()
                    .map_or(f64::INFINITY, |c| e.dot(&c.solve(&e)))
            })
            .sum()
    }

    /// 1σ of the bias (per axis).
    pub fn bias_sigma(&self) -> Vec3 {
        Vec3::from_fn(|i, _| self.cov_rows[i][(0, 0)].sqrt())
    }

    /// 1σ of every entry of `K`.
    pub fn k_sigma(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.cov_rows[i][(1 + j, 1 + j)].sqrt())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn noise_free_linear_data_is_recovered_exactly() {
        let b = Vec3::new(1e-3, -2e-3, 3e-4);
        let k = Matrix3::new(1e-4, 2e-4, -3e-4, 4e-4, -5e-4, 6e-4, -7e-4, 8e-4, 9e-4);
        let mut acc = TriadAccumulator::default();
        for j in 0..200 {
            let t = j as f64 * 0.1;
            let x = Vec3::new(t.sin(), (1.3 * t).cos(), (0.7 * t).sin() + 0.3);
            let y = b + x + k * x;
            acc.add(&x, &y);
        }
        let est = acc.solve("gyro", Some(Vec3::repeat(1e-6)), 0.01).unwrap();
        assert!((est.bias - b).amax() < 1e-15);
        assert!((est.k - k).amax() < 1e-15);
        assert!(est.density_residual.amax() < 1e-12);
    }

    #[test]
    fn a_missing_axis_is_unobservable() {
        let mut acc = TriadAccumulator::default();
        for j in 0..100 {
            let x = Vec3::new((j as f64).sin(), (j as f64).cos(), 0.0);
            acc.add(&x, &x);
        }
        let e = acc.solve("gyro", None, 0.01).unwrap_err();
        assert!(matches!(e, EstimateError::Unobservable { .. }), "{e}");
    }
}
