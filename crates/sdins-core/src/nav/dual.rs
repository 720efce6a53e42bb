//! Dual quaternions `q̂ = r + ε d` (ε² = 0) and the screw exponential
//! (docs/theory/mechanizations.md §"Dual quaternion"; S2 eqs (1)–(5), (13) corrected).

use crate::math::{Quat, Vec3};

/// Dual quaternion `r + ε d` with Hamilton, scalar-first parts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualQuat {
    /// real part (rotation)
    pub r: Quat,
    /// dual part (translation: `d = ½ t^O ⊗ r = ½ r ⊗ t^N`)
    pub d: Quat,
}

impl DualQuat {
    /// Identity.
    pub const IDENTITY: DualQuat = DualQuat {
        r: Quat::IDENTITY,
        d: Quat::new(0.0, 0.0, 0.0, 0.0),
    };

    /// Product `(r₁ + εd₁)(r₂ + εd₂) = r₁r₂ + ε(r₁d₂ + d₁r₂)`.
    #[inline]
    pub fn mul(&self, o: &DualQuat) -> DualQuat {
        DualQuat {
            r: self.r.mul(&o.r),
            d: self.r.mul(&o.d).add(&self.d.mul(&o.r)),
        }
    }

    /// Translation in old-frame coordinates, `t^O = 2 d ⊗ r*` (vector part):
    /// `2 (r_w d_v − d_w r_v − d_v × r_v)`.
    #[inline]
    pub fn translation_old(&self) -> Vec3 {
        let (dv, rv) = (self.d.vec(), self.r.vec());
        (dv * self.r.w - rv * self.d.w - dv.cross(&rv)) * 2.0
    }

    /// Translation in new-frame coordinates, `t^N = 2 r* ⊗ d` (vector part).
    #[inline]
    pub fn translation_new(&self) -> Vec3 {
        self.r.conj().mul(&self.d).vec() * 2.0
    }

    /// Renormalise: unit real part, and the dual part made orthogonal to it
    /// (`r·d = 0`), the two constraints of a unit dual quaternion.
    #[inline]
    pub fn normalized(&self) -> DualQuat {
        let n = self.r.norm();
        let r = self.r.scale(1.0 / n);
        let d = self.d.scale(1.0 / n);
        let dot = r.w * d.w + r.x * d.x + r.y * d.y + r.z * d.z;
        DualQuat {
            r,
            d: d.add(&r.scale(-dot)),
        }
    }

    /// Screw exponential of the dual vector `σ̂ = σ + εσ'` (constant twist integrated over
    /// the interval): with x = |σ|, s = σ·σ', g = sin(x/2)/x, h = (½x cos(x/2) − sin(x/2))/x³,
    /// `r = [cos(x/2), gσ]`, `d = [−½ s g, gσ' + s h σ]` (series below x = 1e-4).
    #[inline]
    pub fn exp(sigma: &Vec3, sigma_d: &Vec3) -> DualQuat {
        let (c, g, h) = Self::exp_coefficients(libm::sqrt(sigma.norm_squared()));
        Self::exp_with(sigma, sigma_d, c, g, h)
    }

    /// The coefficients `(cos(x/2), g(x), h(x))` of [`DualQuat::exp`] for `|σ| = x`
    /// (precompute them when the real part is constant, e.g. the earth rotation per update).
    #[inline]
    pub fn exp_coefficients(x: f64) -> (f64, f64, f64) {
        let x2 = x * x;
        if x2 < 1e-8 {
            (
                1.0 - x2 / 8.0 + x2 * x2 / 384.0,
                0.5 - x2 / 48.0 + x2 * x2 / 3840.0,
                -1.0 / 24.0 + x2 / 960.0 - x2 * x2 / 107_520.0,
            )
        } else {
            let (sh, ch) = (libm::sin(0.5 * x), libm::cos(0.5 * x));
            (ch, sh / x, (0.5 * x * ch - sh) / (x2 * x))
        }
    }

    /// [`DualQuat::exp`] with precomputed coefficients ([`DualQuat::exp_coefficients`]).
    #[inline]
    pub fn exp_with(sigma: &Vec3, sigma_d: &Vec3, c: f64, g: f64, h: f64) -> DualQuat {
        let s = sigma.dot(sigma_d);
        DualQuat {
            r: Quat::from_parts(c, &(sigma * g)),
            d: Quat::from_parts(-0.5 * s * g, &(sigma_d * g + sigma * (s * h))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rate(q: &DualQuat, w: &Vec3, wd: &Vec3) -> DualQuat {
        // dq̂/dt = ½ q̂ ⊗ ω̂
        let tw = DualQuat {
            r: Quat::from_parts(0.0, w),
            d: Quat::from_parts(0.0, wd),
        };
        let p = q.mul(&tw);
        DualQuat {
            r: p.r.scale(0.5),
            d: p.d.scale(0.5),
        }
    }
    fn axpy(q: &DualQuat, k: &DualQuat, a: f64) -> DualQuat {
        DualQuat {
            r: q.r.add(&k.r.scale(a)),
            d: q.d.add(&k.d.scale(a)),
        }
    }

    #[test]
    fn exp_matches_rk4_of_constant_twist() {
        // Unit check: twist [0.3, −0.2, 0.5] + ε[1, 2, −0.5] over t = 2 s.
        let w = Vec3::new(0.3, -0.2, 0.5);
        let wd = Vec3::new(1.0, 2.0, -0.5);
        let t = 2.0;
        let steps = 4000;
        let hstep = t / steps as f64;
        let mut q = DualQuat::IDENTITY;
        for _ in 0..steps {
            let k1 = rate(&q, &w, &wd);
            let k2 = rate(&axpy(&q, &k1, hstep / 2.0), &w, &wd);
            let k3 = rate(&axpy(&q, &k2, hstep / 2.0), &w, &wd);
            let k4 = rate(&axpy(&q, &k3, hstep), &w, &wd);
            let sum = axpy(&axpy(&axpy(&k1, &k2, 2.0), &k3, 2.0), &k4, 1.0);
            q = axpy(&q, &sum, hstep / 6.0);
        }
        let e = DualQuat::exp(&(w * t), &(wd * t));
        let diff = [
            e.r.w - q.r.w,
            e.r.x - q.r.x,
            e.r.y - q.r.y,
            e.r.z - q.r.z,
            e.d.w - q.d.w,
            e.d.x - q.d.x,
            e.d.y - q.d.y,
            e.d.z - q.d.z,
        ];
        let m = diff.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        assert!(m < 1e-13, "{m}");
    }

    #[test]
    fn exp_is_continuous_across_the_series_switch() {
        let dir = Vec3::new(0.6, -0.48, 0.64);
        let sd = Vec3::new(1.0, 2.0, -0.5);
        let lo = DualQuat::exp(&(dir * 0.999_999e-4), &sd);
        let hi = DualQuat::exp(&(dir * 1.000_001e-4), &sd);
        // Neighbouring arguments 2e-10 apart: the values differ only by that step.
        assert!((lo.d.vec() - hi.d.vec()).norm() < 1e-12);
        assert!((lo.r.w - hi.r.w).abs() < 1e-14);
    }

    #[test]
    fn translation_extraction() {
        let r = Quat::from_rotvec(&Vec3::new(0.2, 0.4, -0.1));
        let t_old = Vec3::new(3.0, -1.0, 2.0);
        let q = DualQuat {
            r,
            d: Quat::from_parts(0.0, &t_old).mul(&r).scale(0.5),
        };
        assert!((q.translation_old() - t_old).norm() < 1e-15);
        assert!((q.translation_new() - r.conj().rotate(&t_old)).norm() < 1e-14);
    }
}
