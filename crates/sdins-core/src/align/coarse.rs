//! Coarse (analytic) alignment of a stationary IMU (docs/theory/alignment.md §"Coarse alignment").
//!
//! Inputs are the sensor outputs averaged over a static window (docs/theory/alignment.md
//! §"Coarse alignment": T_c ≥ 30 s): `f̄^b = Σ Δv / T`, `ω̄^b = Σ Δθ / T` ([`StaticMean`]). At rest
//! `f^n = [0, 0, −g]` and `ω^n = ω_ie^n = Ω [cos L, 0, −sin L]`.

use super::{AlignError, Site};
use crate::coning::Increment;
use crate::math::{c_b_n_from_euler, orthonormalize, Euler, Mat3, Vec3};

/// Running mean of static increments: `f̄^b = Σ Δv_j / Σ δt_j`, `ω̄^b = Σ Δθ_j / Σ δt_j`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StaticMean {
    sum_dtheta: Vec3,
    sum_dv: Vec3,
    t_s: f64,
    n: u64,
}

impl StaticMean {
    /// Empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }
    /// Add one sample of period `dt_s`.
    pub fn add(&mut self, inc: &Increment, dt_s: f64) {
        self.sum_dtheta += inc.dtheta_b_rad;
        self.sum_dv += inc.dv_b_mps;
        self.t_s += dt_s;
        self.n += 1;
    }
    /// Window length \[s\].
    pub fn duration_s(&self) -> f64 {
        self.t_s
    }
    /// Number of samples.
    pub fn samples(&self) -> u64 {
        self.n
    }
    /// Mean specific force f̄^b \[m/s²\] (None for an empty window).
    pub fn f_b(&self) -> Option<Vec3> {
        (self.t_s > 0.0).then(|| self.sum_dv / self.t_s)
    }
    /// Mean angular rate ω̄^b \[rad/s\] (None for an empty window).
    pub fn omega_b(&self) -> Option<Vec3> {
        (self.t_s > 0.0).then(|| self.sum_dtheta / self.t_s)
    }
}

/// Coarse-alignment method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoarseMethod {
    /// 1-step analytic (TRIAD-type) alignment, polar-orthonormalised (docs/theory/alignment.md
    /// §"Coarse alignment")
    OneStep,
    /// 2-step: levelling, then gyrocompassing (docs/theory/alignment.md §"Coarse alignment")
    TwoStep,
}

fn check(f_b: &Vec3, w_b: &Vec3, site: &Site) -> Result<(), AlignError> {
    if libm::fabs(site.lat_rad) > 80.0_f64.to_radians() {
        return Err(AlignError::LatitudeTooHigh);
    }
    let ok = |v: &Vec3| v.iter().all(|x| x.is_finite());
    if !ok(f_b) || !ok(w_b) || f_b.norm() == 0.0 || site.g_mps2 <= 0.0 || site.omega_ie_rps <= 0.0 {
        return Err(AlignError::Degenerate);
    }
    Ok(())
}

/// 1-step analytic alignment (docs/theory/alignment.md §"Coarse alignment"), closed form without
/// matrix inversion:
///
/// ```text
/// d_b = −f̄^b / g
/// n_b = ω̄^b / (Ω cos L) − tan L · f̄^b / g
/// e_b = −(f̄^b × ω̄^b) / (g Ω cos L)
/// C_n^b(raw) = [n_b  e_b  d_b],   C_b^n(raw) = C_n^b(raw)ᵀ
/// ```
///
/// followed by the **symmetric (polar) orthonormalisation** `Ĉ = U Vᵀ` (docs/theory/alignment.md
/// §"Coarse alignment": only then does the error table of docs/theory/alignment.md
/// §"Coarse alignment" hold; `C_n^b` and `M_n M_b^{-1}` share the polar factor).
pub fn one_step(f_b: &Vec3, w_b: &Vec3, site: &Site) -> Result<Mat3, AlignError> {
    check(f_b, w_b, site)?;
    let g = site.g_mps2;
    let oc = site.omega_n();
    let d_b = -f_b / g;
    let n_b = w_b / oc - f_b * (site.tan_lat() / g);
    let e_b = -f_b.cross(w_b) / (g * oc);
    let c_n_b = Mat3::from_columns(&[n_b, e_b, d_b]);
    if c_n_b.determinant().abs() < 1e-6 {
        return Err(AlignError::Degenerate);
    }
    Ok(orthonormalize(&c_n_b.transpose()))
}

/// 2-step alignment (docs/theory/alignment.md §"Coarse alignment"): levelling
/// `roll = atan2(−f̄_y, −f̄_z)`, `pitch = atan2(f̄_x, √(f̄_y² + f̄_z²))`, then
/// gyrocompassing in the levelled frame `ω^L = Ry(pitch) Rx(roll) ω̄^b`:
/// `yaw = atan2(−ω^L_y, ω^L_x)`; `Ĉ_b^n = Rz(yaw) Ry(pitch) Rx(roll)`.
pub fn two_step(f_b: &Vec3, w_b: &Vec3, site: &Site) -> Result<Mat3, AlignError> {
    check(f_b, w_b, site)?;
    let roll = libm::atan2(-f_b.y, -f_b.z);
    let pitch = libm::atan2(f_b.x, libm::hypot(f_b.y, f_b.z));
    let (sr, cr) = (libm::sin(roll), libm::cos(roll));
    let (sp, cp) = (libm::sin(pitch), libm::cos(pitch));
    let wlx = cp * w_b.x + sp * (sr * w_b.y + cr * w_b.z);
    let wly = cr * w_b.y - sr * w_b.z;
    let yaw = libm::atan2(-wly, wlx);
    Ok(c_b_n_from_euler(&Euler::new(roll, pitch, yaw)))
}

/// Coarse alignment with either method from a [`StaticMean`].
pub fn align(method: CoarseMethod, mean: &StaticMean, site: &Site) -> Result<Mat3, AlignError> {
    let (Some(f), Some(w)) = (mean.f_b(), mean.omega_b()) else {
        return Err(AlignError::NoData);
    };
    match method {
        CoarseMethod::OneStep => one_step(&f, &w, site),
        CoarseMethod::TwoStep => two_step(&f, &w, site),
    }
}

/// First-order coarse-alignment error, the **corrected** table of docs/theory/alignment.md
/// §"Coarse alignment" (convention G; `da_n = C_b^n b_a`, `eps_n = C_b^n b_g` NED-resolved biases
/// at the true attitude):
///
/// | axis | 1-step | 2-step |
/// |---|---|---|
/// | φ_N | −δa_E/g | −δa_E/g |
/// | φ_E | ½(δa_N/g − δa_D tan L/g + ε_D sec L/Ω) | δa_N/g |
/// | φ_D | −ε_E sec L/Ω + δa_E tan L/g | −ε_E sec L/Ω + δa_E tan L/g |
pub fn error_table(method: CoarseMethod, da_n: &Vec3, eps_n: &Vec3, site: &Site) -> Vec3 {
    let g = site.g_mps2;
    let oc = site.omega_n();
    let t = site.tan_lat();
    let phi_n = -da_n.y / g;
    let phi_d = -eps_n.y / oc + da_n.y * t / g;
    let phi_e = match method {
        CoarseMethod::OneStep => 0.5 * (da_n.x / g - da_n.z * t / g + eps_n.z / oc),
        CoarseMethod::TwoStep => da_n.x / g,
    };
    Vec3::new(phi_n, phi_e, phi_d)
}

/// Noise-limited 1σ of a T_c-second average (docs/theory/alignment.md §"Coarse alignment"), `vrw`
/// \[m/s/√s\], `arw` \[rad/√s\]: returns `(σ_tilt, σ_yaw, σ_φE(1-step))` with
/// `σ_tilt = VRW/(g√T_c)`, `σ_yaw = √((ARW/(Ω cos L))²/T_c + (tan L σ_tilt)²)`,
/// `σ_φE,1 = ½ √(VRW²(1 + tan²L)/g² + ARW²/(Ω cos L)²)/√T_c`.
pub fn noise_sigma(vrw: f64, arw: f64, t_c: f64, site: &Site) -> (f64, f64, f64) {
    let g = site.g_mps2;
    let oc = site.omega_n();
    let t = site.tan_lat();
    let st = libm::sqrt(t_c);
    let tilt = vrw / (g * st);
    let a = arw / oc;
    let yaw = libm::sqrt(a * a / t_c + (t * tilt) * (t * tilt));
    let e1 = 0.5 * libm::sqrt(vrw * vrw * (1.0 + t * t) / (g * g) + a * a) / st;
    (tilt, yaw, e1)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::math::attitude_error;

    fn site() -> Site {
        Site {
            lat_rad: 37.5_f64.to_radians(),
            g_mps2: 9.799490523606893,
            omega_ie_rps: 7.292115e-5,
        }
    }

    #[test]
    fn noise_free_error_free_is_exact() {
        let s = site();
        let c = c_b_n_from_euler(&Euler::new(0.3, -0.2, 2.5));
        let f = c.transpose() * (-s.g_n());
        let w = c.transpose() * s.omega_ie_n();
        for m in [CoarseMethod::OneStep, CoarseMethod::TwoStep] {
            let c1 = match m {
                CoarseMethod::OneStep => one_step(&f, &w, &s).unwrap(),
                CoarseMethod::TwoStep => two_step(&f, &w, &s).unwrap(),
            };
            assert!(attitude_error(&c1, &c).norm() < 1e-12, "{m:?}");
        }
    }

    /// docs/validation.md §"coarse alignment (1-/2-step)" T1 single-bias sanity checks at body =
    /// NED, g = 9.80.
    #[test]
    fn single_bias_table_values() {
        let s = Site {
            g_mps2: 9.80,
            ..site()
        };
        let ug = 9.80665e-6;
        let dph = 4.8481368e-6;
        let z = Vec3::zeros();
        let e1 = error_table(
            CoarseMethod::OneStep,
            &Vec3::new(100.0 * ug, 0.0, 0.0),
            &z,
            &s,
        );
        let e2 = error_table(
            CoarseMethod::TwoStep,
            &Vec3::new(100.0 * ug, 0.0, 0.0),
            &z,
            &s,
        );
        assert!((e2.y - 0.1001e-3).abs() < 1e-7 && (e1.y - 0.0500e-3).abs() < 1e-7);
        let e = error_table(
            CoarseMethod::TwoStep,
            &Vec3::new(0.0, 100.0 * ug, 0.0),
            &z,
            &s,
        );
        assert!((e.x + 0.1001e-3).abs() < 1e-7 && (e.z - 0.0768e-3).abs() < 1e-7);
        let e = error_table(
            CoarseMethod::OneStep,
            &z,
            &Vec3::new(0.0, 0.01 * dph, 0.0),
            &s,
        );
        assert!((e.z + 0.8380e-3).abs() < 1e-7);
        let e = error_table(
            CoarseMethod::OneStep,
            &z,
            &Vec3::new(0.0, 0.0, 0.01 * dph),
            &s,
        );
        assert!((e.y - 0.4190e-3).abs() < 1e-7);
        let e = error_table(
            CoarseMethod::OneStep,
            &Vec3::new(0.0, 0.0, 100.0 * ug),
            &z,
            &s,
        );
        assert!((e.y + 0.0384e-3).abs() < 1e-7);
    }
}
