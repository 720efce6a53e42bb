//! Inertial-frame ("i0") coarse alignment on a disturbed base (docs/alignment_i0.md).
//!
//! The method of Gu, El-Sheimy, Hassan & Syed, "Coarse alignment for marine SINS using
//! gravity in the inertial frame as a reference" (IEEE/ION PLANS 2008), and of Qin
//! Yongyuan's and Yan Gongmin's textbooks (the `aligni0` of PSINS): the attitude is split
//! as
//!
//! ```text
//! C_b^n(t) = C_{n0}^{n(t)} · C_{ib0}^{n0} · C_b^{ib0}(t)
//! ```
//!
//! with `n0` the navigation frame and `ib0` the body frame frozen in inertial space at
//! the start. `C_b^{ib0}(t)` follows from the gyros alone (`Ċ = C [ω_ib^b ×]`), so body
//! sway and rocking are tracked exactly; `C_{n(t)}^{n0} = exp([ω_ie^n ×] t)` is known.
//! The constant `C_{ib0}^{n0}` is the rotation that maps the apparent motion of gravity
//! in `ib0` onto its known motion in `n0`. Both are integrated once to velocities so that
//! heave and surge (bounded velocity) average out:
//!
//! ```text
//! v^{ib0}(t) = ∫₀ᵗ C_b^{ib0} f^b dτ,     v^{n0}(t) = ∫₀ᵗ C_{n}^{n0}(τ) f^n dτ,  f^n = [0, 0, −g]
//! v^{n0}(t) = [ t I + (1 − cos Ωt)/Ω² [ω×] + (t − sin(Ωt)/Ω)/Ω² [ω×]² ] f^n
//! ```
//!
//! and `C_{ib0}^{n0}` solves the weighted Wahba problem
//! `min Σ_k w_k |v^{n0}(t_k) − C v^{ib0}(t_k)|²` over all samples, i.e. maximises
//! `tr(Cᵀ B)`, `B = Σ_k w_k v^{n0}_k (v^{ib0}_k)ᵀ`, with the taper `w_k = 1 − t_k/T`: it
//! makes the estimator's kernel vanish at the window end, so that an oscillating
//! (heave, surge) velocity leaks into the heading as `O(1/(ωT)²)` instead of
//! `O(1/(ωT))` (docs/alignment_i0.md §4). `B = B₀ − B₁/T` from the online sums
//! `B₀ = Σ v^{n0} v^{ib0ᵀ}`, `B₁ = Σ t_k v^{n0} v^{ib0ᵀ}`. `B` is
//! nearly rank one (gravity dominates its sweep by `(ΩT)²`, singular-value ratio ~1e-6),
//! which makes an SVD lose the heading; instead a TRIAD start from `v(T)` and `Σ v(t_k)`
//! is refined by Newton steps on the rotation vector (see [`InertialAlign::c_ib0_n0`]).
//! Everything is accumulated online (no storage of the record), `no_std`.
//!
//! First-order errors (docs/alignment_i0.md): for constant biases the heading error is
//! the gyrocompassing floor `δψ = −ε_E/(Ω cos L) + (∇_E/g) tan L` (convention G,
//! `φ_D = −δψ`… see the doc for signs), independent of the window; the angle random walk
//! `σ_g` and velocity random walk `σ_a` give
//! `σ_ψ² = 4 (g² σ_g² T³ K₁ + σ_a² T K₂) / (T⁴ (g Ω cos L)²) + σ_g² T` with the exact
//! constants [`K1`], [`K2`] of the tapered velocity fit.

use super::{AlignError, Site};
use crate::coning::Increment;
use crate::math::{dcm_from_rotvec, skew, Mat3, Quat, Vec3};

/// `K₁ = ∫₀¹ k(v)² dv = 260/693`, `k(v) = 5v − 30v³ + 40v⁴ − 15v⁵`: gyro angle random
/// walk weight of the heading estimate (docs/alignment_i0.md §3).
pub const K1: f64 = 260.0 / 693.0;
/// `K₂ = ∫₀¹ j(v)² dv = 40/7`, `j(v) = −5 + 90v² − 160v³ + 75v⁴`: accelerometer
/// velocity random walk weight (docs/alignment_i0.md §3).
pub const K2: f64 = 40.0 / 7.0;

/// Online inertial-frame coarse alignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InertialAlign {
    site: Site,
    q_b_ib0: Quat,
    v_ib0: Vec3,
    t_s: f64,
    b: Mat3,
    b1: Mat3,
    sum_v_ib0: Vec3,
    sum_v_n0: Vec3,
    sum_sq: [f64; 2],
    sum_w: [f64; 2],
    n: u64,
}

/// `v^{n0}(t)` of a stationary site: the closed-form integral of `exp([ω×]τ) f^n`,
/// `f^n = [0, 0, −g]` (module doc); series in `Ωt` below 1e-3 rad.
pub fn gravity_velocity_n0(site: &Site, t_s: f64) -> Vec3 {
    let w = site.omega_ie_n();
    let om = site.omega_ie_rps;
    let (c1, c2) = sweep_coeffs(om, t_s, libm::fabs(om * t_s) < 1e-3);
    let k = skew(&w);
    let f_n = Vec3::new(0.0, 0.0, -site.g_mps2);
    (Mat3::identity() * t_s + k * c1 + k * k * c2) * f_n
}

/// `c1 = (1 − cos Ωt)/Ω²`, `c2 = (t − sin(Ωt)/Ω)/Ω²`, by their Taylor series in
/// `x = Ωt` (truncation x⁶/8!·t² relative ≈ 2e-23 at x = 1e-3) or the closed form.
fn sweep_coeffs(om: f64, t_s: f64, series: bool) -> (f64, f64) {
    let x = om * t_s;
    if series {
        let x2 = x * x;
        (
            t_s * t_s * (0.5 - x2 / 24.0 + x2 * x2 / 720.0),
            t_s * t_s * t_s * (1.0 / 6.0 - x2 / 120.0 + x2 * x2 / 5040.0),
        )
    } else {
        let s = libm::sin(0.5 * x);
        (
            2.0 * s * s / (om * om),
            (t_s - libm::sin(x) / om) / (om * om),
        )
    }
}

impl InertialAlign {
    /// Start at t = 0 with `ib0` = the body frame now.
    pub fn new(site: Site) -> Self {
        Self {
            site,
            q_b_ib0: Quat::IDENTITY,
            v_ib0: Vec3::zeros(),
            t_s: 0.0,
            b: Mat3::zeros(),
            b1: Mat3::zeros(),
            sum_v_ib0: Vec3::zeros(),
            sum_v_n0: Vec3::zeros(),
            sum_sq: [0.0; 2],
            sum_w: [0.0; 2],
            n: 0,
        }
    }

    /// Add one sample: `v^{ib0} += C_b^{ib0}(mid) Δv` with the mid-sample attitude
    /// `C_b^{ib0}(t_{k−1}) exp(½Δθ)` (rotation compensation to second order), then
    /// `C_b^{ib0} ← C_b^{ib0} exp(Δθ)`, and the Wahba sums `B₀ += v^{n0}(t_k) v^{ib0}(t_k)ᵀ`, `B₁ += t_k v^{n0} v^{ib0ᵀ}`.
    pub fn add(&mut self, inc: &Increment, dt_s: f64) {
        let half = Quat::from_rotvec(&(0.5 * inc.dtheta_b_rad));
        let q_mid = self.q_b_ib0.mul(&half);
        self.v_ib0 += q_mid.rotate(&inc.dv_b_mps);
        self.q_b_ib0 = q_mid.mul(&half).normalized();
        self.t_s += dt_s;
        self.n += 1;
        let v_n0 = gravity_velocity_n0(&self.site, self.t_s);
        let outer = v_n0 * self.v_ib0.transpose();
        self.b += outer;
        self.b1 += outer * self.t_s;
        let sq = v_n0.norm_squared() + self.v_ib0.norm_squared();
        self.sum_sq[0] += sq;
        self.sum_sq[1] += sq * self.t_s;
        self.sum_w[0] += 1.0;
        self.sum_w[1] += self.t_s;
        self.sum_v_ib0 += self.v_ib0;
        self.sum_v_n0 += v_n0;
    }

    /// Elapsed time \[s\].
    pub fn duration_s(&self) -> f64 {
        self.t_s
    }

    /// Number of samples added.
    pub fn samples(&self) -> u64 {
        self.n
    }

    /// Current `C_b^{ib0}` from the gyros.
    pub fn c_b_ib0(&self) -> Mat3 {
        self.q_b_ib0.to_dcm()
    }

    /// `C_{ib0}^{n0}` from the tapered Wahba problem (module doc).
    pub fn c_ib0_n0(&self) -> Result<Mat3, AlignError> {
        if self.n < 2 {
            return Err(AlignError::NoData);
        }
        if libm::fabs(self.site.lat_rad) > 80.0_f64.to_radians() {
            return Err(AlignError::LatitudeTooHigh);
        }
        let b = self.b - self.b1 / self.t_s;
        if !b.iter().all(|x| x.is_finite()) || self.site.g_mps2 <= 0.0 {
            return Err(AlignError::Degenerate);
        }
        // start: TRIAD of (v(T), Σ v(t_k)) in both frames
        let v_n0 = gravity_velocity_n0(&self.site, self.t_s);
        let mut c = triad(&v_n0, &self.sum_v_n0, &self.v_ib0, &self.sum_v_ib0)?;
        // Newton on F(C) = tr(Cᵀ B), C = exp([φ×]) C₀ (module doc): M = B C₀ᵀ,
        // F ≈ F₀ + 2 φ·vee(M) − ½ φᵀ (tr M·I − sym M) φ, so φ = 2 H⁻¹ vee(M) with
        // H = tr M·I − sym M (positive definite while gravity sweeps: two non-zero
        // singular values of B). Three steps reach roundoff from the TRIAD start.
        for _ in 0..3 {
            let m = b * c.transpose();
            let h = Mat3::identity() * m.trace() - 0.5 * (m + m.transpose());
            let Some(h_inv) = h.try_inverse() else {
                return Err(AlignError::Degenerate);
            };
            let phi = 2.0 * h_inv * crate::math::vee_antisym(&m);
            if !phi.iter().all(|x| x.is_finite()) {
                return Err(AlignError::Degenerate);
            }
            c = dcm_from_rotvec(&phi) * c;
        }
        Ok(c)
    }

    /// RMS velocity residual of the fit \[m/s\],
    /// `√(Σ w_k |v^{n0}_k − C v^{ib0}_k|² / Σ w_k) = √((Σ w |v^{n0}|² + Σ w |v^{ib0}|² − 2 tr(Cᵀ B)) / Σ w)`:
    /// the disturbance (heave, surge, sway about an offset centre) velocity of the base
    /// plus the sensor-noise walk; the scale of the zero-velocity measurement error of a
    /// fine filter on this base (docs/alignment_i0.md §6). Roundoff ≈ `ε g T` m/s.
    pub fn residual_rms_mps(&self) -> Result<f64, AlignError> {
        let c = self.c_ib0_n0()?;
        let t = self.t_s;
        let b = self.b - self.b1 / t;
        let sq = self.sum_sq[0] - self.sum_sq[1] / t;
        let w = self.sum_w[0] - self.sum_w[1] / t;
        let rss = sq - 2.0 * (c.transpose() * b).trace();
        if !(w.is_finite() && w > 0.0 && rss.is_finite()) {
            return Err(AlignError::Degenerate);
        }
        Ok(libm::sqrt(rss.max(0.0) / w))
    }

    /// The attitude `C_b^n` at the end of the samples added so far (module doc).
    pub fn c_b_n(&self) -> Result<Mat3, AlignError> {
        let c = self.c_ib0_n0()?;
        let r_t = dcm_from_rotvec(&(self.site.omega_ie_n() * self.t_s));
        Ok(r_t.transpose() * c * self.c_b_ib0())
    }

    /// `C_b^n` at the start of the window (t = 0): `C_{ib0}^{n0}`.
    pub fn c_b_n0(&self) -> Result<Mat3, AlignError> {
        self.c_ib0_n0()
    }
}

/// TRIAD rotation `C` with `C b1 ∥ a1` and `C (b1 × b2) ∥ a1 × a2`.
fn triad(a1: &Vec3, a2: &Vec3, b1: &Vec3, b2: &Vec3) -> Result<Mat3, AlignError> {
    let frame = |x: &Vec3, y: &Vec3| -> Option<Mat3> {
        let e1 = x.try_normalize(0.0)?;
        let e2 = x.cross(y).try_normalize(0.0)?;
        let e3 = e1.cross(&e2);
        Some(Mat3::from_columns(&[e1, e2, e3]))
    };
    match (frame(a1, a2), frame(b1, b2)) {
        (Some(ta), Some(tb)) if ta.iter().chain(tb.iter()).all(|x| x.is_finite()) => {
            Ok(ta * tb.transpose())
        }
        _ => Err(AlignError::Degenerate),
    }
}

/// Theoretical 1σ heading error \[rad\] of [`InertialAlign`] over a window `t_s` from
/// angle random walk `arw` \[rad/√s\] and velocity random walk `vrw` \[m/s/√s\]
/// (docs/alignment_i0.md §3): the fit part
/// `4 (g² σ_g² T³ K₁ + σ_a² T K₂)/(T⁴ (g Ω cos L)²)` plus the gyro walk `σ_g² T` of
/// `C_b^{ib0}(T)` about the vertical.
pub fn heading_sigma_rad(site: &Site, t_s: f64, arw: f64, vrw: f64) -> f64 {
    let g = site.g_mps2;
    let a = g * site.omega_n();
    let t = t_s;
    let fit =
        4.0 * (g * g * arw * arw * t * t * t * K1 + vrw * vrw * t * K2) / (t * t * t * t * a * a);
    libm::sqrt(fit + arw * arw * t)
}

/// First-order heading error \[rad\] of [`InertialAlign`] at the end of a `t_s` window for
/// constant NED biases `eps_n` \[rad/s\] and `nabla_n` \[m/s²\]: the gyrocompassing floor
/// `δψ = −ε_E/(Ω cos L) + (∇_E/g) tan L` plus the drift `ε_D T` of `C_b^{ib0}` over the
/// window (heading estimate minus truth = `φ_D` of convention G; docs/alignment_i0.md §2).
pub fn heading_floor_rad(site: &Site, eps_n: &Vec3, nabla_n: &Vec3, t_s: f64) -> f64 {
    -eps_n.y / site.omega_n() + nabla_n.y / site.g_mps2 * site.tan_lat() + eps_n.z * t_s
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::math::{c_b_n_from_euler, Euler};

    fn site() -> Site {
        Site {
            lat_rad: 34.0_f64.to_radians(),
            g_mps2: 9.79,
            omega_ie_rps: 7.292115e-5,
        }
    }

    #[test]
    fn constants_are_the_integrals() {
        // midpoint quadrature of k(v)² and h₁(v)² (error O(1/n²) ≈ 1e-9)
        let n = 20000;
        let (mut k1, mut k2) = (0.0, 0.0);
        for i in 0..n {
            let v = (i as f64 + 0.5) / n as f64;
            let k = 5.0 * v - 30.0 * v.powi(3) + 40.0 * v.powi(4) - 15.0 * v.powi(5);
            let h = -5.0 + 90.0 * v * v - 160.0 * v.powi(3) + 75.0 * v.powi(4);
            k1 += k * k / n as f64;
            k2 += h * h / n as f64;
        }
        assert!((k1 - K1).abs() < 1e-8, "{k1} {K1}");
        assert!((k2 - K2).abs() < 1e-7, "{k2} {K2}");
    }

    #[test]
    fn gravity_velocity_series_and_closed_form_agree() {
        let s = site();
        // around the switch point x = 1e-3 (t ≈ 13.7 s) both branches agree to roundoff
        // (the closed form loses ~eps/x² ≈ 2e-10 relative of c2 to cancellation there)
        let t = 1e-3 / s.omega_ie_rps;
        let (a1, a2) = sweep_coeffs(s.omega_ie_rps, t, true);
        let (b1, b2) = sweep_coeffs(s.omega_ie_rps, t, false);
        assert!((a1 - b1).abs() < 1e-14 * a1, "{a1} {b1}");
        assert!((a2 - b2).abs() < 1e-9 * a2, "{a2} {b2}");
        // d/dt v = exp([ω×]t) f^n (central difference, h = 1e-3 s)
        let t = 500.0;
        let h = 1e-3;
        let d = (gravity_velocity_n0(&s, t + h) - gravity_velocity_n0(&s, t - h)) / (2.0 * h);
        let want = dcm_from_rotvec(&(s.omega_ie_n() * t)) * Vec3::new(0.0, 0.0, -s.g_mps2);
        assert!((d - want).norm() < 1e-9, "{}", (d - want).norm());
    }

    /// Exact stationary increments (closed form): body fixed to the earth, the frames
    /// rotate at ω_ie; Δθ = C_n^b ω_ie^n dt, Δv = C_n^b f^n dt exactly (constant).
    #[test]
    fn exact_static_data_recover_the_attitude() {
        let s = site();
        let c = c_b_n_from_euler(&Euler::new(0.03, -0.02, 2.5));
        let dt = 0.01;
        let inc = Increment {
            dtheta_b_rad: c.transpose() * s.omega_ie_n() * dt,
            dv_b_mps: c.transpose() * Vec3::new(0.0, 0.0, -s.g_mps2) * dt,
        };
        let mut a = InertialAlign::new(s);
        for _ in 0..12000 {
            a.add(&inc, dt);
        }
        // the mid-sample rotation compensation is exact to O(|Δθ|²) ≈ 5e-13 relative and
        // the Wahba fit of exact data is exact: roundoff over 12000 sums, tolerance 1e-9 rad
        // (a 1e-9 rad error would need a 1e-9 relative error in B).
        let phi = crate::math::attitude_error(&a.c_b_n().unwrap(), &c);
        assert!(phi.amax() < 1e-9, "{phi:?}");
        assert!(crate::math::attitude_error(&a.c_b_n0().unwrap(), &c).amax() < 1e-9);
    }

    #[test]
    fn empty_and_degenerate_inputs_are_errors() {
        let a = InertialAlign::new(site());
        assert_eq!(a.c_b_n(), Err(AlignError::NoData));
        let mut a = InertialAlign::new(site());
        let z = Increment {
            dtheta_b_rad: Vec3::zeros(),
            dv_b_mps: Vec3::zeros(),
        };
        for _ in 0..10 {
            a.add(&z, 0.01);
        }
        // zero specific force: B has rank 0
        assert!(a.c_b_n().is_err());
    }
}
