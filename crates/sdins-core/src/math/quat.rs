//! Hamilton, scalar-first quaternion (docs/conventions.md §"Quaternions").

use super::{Mat3, Vec3};

/// Hamilton quaternion `[w, x, y, z]`, scalar first.
///
/// `q_b_n` (body to navigation) rotates vectors as `(0, v_n) = q ⊗ (0, v_b) ⊗ q*`
/// and its DCM [`Quat::to_dcm`] is `c_b_n` (S1 eq. 12).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quat {
    /// scalar part
    pub w: f64,
    /// vector part, x
    pub x: f64,
    /// vector part, y
    pub y: f64,
    /// vector part, z
    pub z: f64,
}

impl Default for Quat {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Quat {
    /// The identity rotation.
    pub const IDENTITY: Quat = Quat {
        w: 1.0,
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };

    /// Build from components, scalar first.
    #[inline]
    pub const fn new(w: f64, x: f64, y: f64, z: f64) -> Self {
        Self { w, x, y, z }
    }

    /// Build from a scalar and a vector part.
    #[inline]
    pub fn from_parts(w: f64, v: &Vec3) -> Self {
        Self {
            w,
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }

    /// Vector part.
    #[inline]
    pub fn vec(&self) -> Vec3 {
        Vec3::new(self.x, self.y, self.z)
    }

    /// Conjugate `q*`.
    #[inline]
    pub fn conj(&self) -> Self {
        Self {
            w: self.w,
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    /// Euclidean norm.
    #[inline]
    pub fn norm(&self) -> f64 {
        libm::sqrt(self.w * self.w + self.x * self.x + self.y * self.y + self.z * self.z)
    }

    /// Unit-norm copy (the identity if the norm is zero or not finite).
    #[inline]
    pub fn normalized(&self) -> Self {
        let n = self.norm();
        if n.is_nan() || n <= 0.0 || !n.is_finite() {
            return Self::IDENTITY;
        }
        self.scale(1.0 / n)
    }

    /// `q/|q|` for a quaternion that is already unit to within ~1e-8 (a product of unit
    /// quaternions, rounded), by one Newton step of `1/√(q·q)` at 1:
    /// `q (3 − q·q)/2`. For `q·q = 1 + δ` the result has `|q|² = 1 − ¾δ² + O(δ³)`, i.e. it
    /// is unit to rounding, without a square root or a division (the per-update
    /// renormalization of the mechanizations). Far from unit norm use [`Quat::normalized`].
    #[inline]
    pub fn renormalized(&self) -> Self {
        let n2 = self.w * self.w + self.x * self.x + self.y * self.y + self.z * self.z;
        self.scale(1.5 - 0.5 * n2)
    }

    /// Multiply every component by `s`.
    #[inline]
    pub fn scale(&self, s: f64) -> Self {
        Self {
            w: self.w * s,
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Component-wise sum.
    #[inline]
    pub fn add(&self, o: &Self) -> Self {
        Self {
            w: self.w + o.w,
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    /// Hamilton product `self ⊗ o`:
    /// `(s₁,u₁)⊗(s₂,u₂) = (s₁s₂ − u₁·u₂, s₁u₂ + s₂u₁ + u₁×u₂)`.
    #[inline]
    pub fn mul(&self, o: &Self) -> Self {
        Self {
            w: self.w * o.w - self.x * o.x - self.y * o.y - self.z * o.z,
            x: self.w * o.x + self.x * o.w + self.y * o.z - self.z * o.y,
            y: self.w * o.y - self.x * o.z + self.y * o.w + self.z * o.x,
            z: self.w * o.z + self.x * o.y - self.y * o.x + self.z * o.w,
        }
    }

    /// Rotate a vector: `q ⊗ (0,v) ⊗ q*`, i.e. `C(q) v`.
    #[inline]
    pub fn rotate(&self, v: &Vec3) -> Vec3 {
        let u = self.vec();
        let t = 2.0 * u.cross(v);
        v + self.w * t + u.cross(&t)
    }

    /// Direction-cosine matrix, S1 eq. (12); for `q_b_n` this is `c_b_n`.
    #[inline]
    pub fn to_dcm(&self) -> Mat3 {
        let (q0, q1, q2, q3) = (self.w, self.x, self.y, self.z);
        Mat3::new(
            q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3,
            2.0 * (q1 * q2 - q0 * q3),
            2.0 * (q1 * q3 + q0 * q2),
            2.0 * (q1 * q2 + q0 * q3),
            q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3,
            2.0 * (q2 * q3 - q0 * q1),
            2.0 * (q1 * q3 - q0 * q2),
            2.0 * (q2 * q3 + q0 * q1),
            q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3,
        )
    }

    /// Quaternion of a rotation matrix (Shepperd's method: the largest of the four
    /// candidate pivots is used, so it is accurate for every rotation). Returns the
    /// representative with `w ≥ 0`.
    pub fn from_dcm(c: &Mat3) -> Self {
        let tr = c[(0, 0)] + c[(1, 1)] + c[(2, 2)];
        let q = if tr >= c[(0, 0)] && tr >= c[(1, 1)] && tr >= c[(2, 2)] {
            let s = 2.0 * libm::sqrt(1.0 + tr);
            Quat::new(
                0.25 * s,
                (c[(2, 1)] - c[(1, 2)]) / s,
                (c[(0, 2)] - c[(2, 0)]) / s,
                (c[(1, 0)] - c[(0, 1)]) / s,
            )
        } else if c[(0, 0)] >= c[(1, 1)] && c[(0, 0)] >= c[(2, 2)] {
            let s = 2.0 * libm::sqrt(1.0 + c[(0, 0)] - c[(1, 1)] - c[(2, 2)]);
            Quat::new(
                (c[(2, 1)] - c[(1, 2)]) / s,
                0.25 * s,
                (c[(0, 1)] + c[(1, 0)]) / s,
                (c[(0, 2)] + c[(2, 0)]) / s,
            )
        } else if c[(1, 1)] >= c[(2, 2)] {
            let s = 2.0 * libm::sqrt(1.0 + c[(1, 1)] - c[(0, 0)] - c[(2, 2)]);
            Quat::new(
                (c[(0, 2)] - c[(2, 0)]) / s,
                (c[(0, 1)] + c[(1, 0)]) / s,
                0.25 * s,
                (c[(1, 2)] + c[(2, 1)]) / s,
            )
        } else {
            let s = 2.0 * libm::sqrt(1.0 + c[(2, 2)] - c[(0, 0)] - c[(1, 1)]);
            Quat::new(
                (c[(1, 0)] - c[(0, 1)]) / s,
                (c[(0, 2)] + c[(2, 0)]) / s,
                (c[(1, 2)] + c[(2, 1)]) / s,
                0.25 * s,
            )
        };
        let q = q.normalized();
        if q.w < 0.0 {
            q.scale(-1.0)
        } else {
            q
        }
    }

    /// Quaternion of a rotation vector (S1 eq. 2): `q(φ) = [cos(φ/2), (φ/|φ|) sin(φ/2)]`,
    /// with the Taylor series below |φ| = 1e-2 rad (two terms below 1e-6 rad).
    ///
    /// Series (φ² = |φ|²): `cos(φ/2) = 1 − (φ²/8)(1 − (φ²/48)(1 − φ²/120))` and
    /// `sin(φ/2)/φ = ½(1 − (φ²/24)(1 − (φ²/80)(1 − φ²/168)))`, the first omitted terms
    /// `φ⁸/10 321 920` and `φ⁸/185 794 560` being below 1e-23 at |φ| = 1e-2 (rounding is
    /// 1.1e-16). Every navigation update below 1 rad/s at 100 Hz takes this branch: no
    /// square root, division or libm call.
    #[inline]
    pub fn from_rotvec(phi: &Vec3) -> Self {
        let a2 = phi.norm_squared();
        // |φ| < 1e-2 ⇔ |φ|² < 1e-4: the square root is only taken where it is used
        let (c, s_over) = if a2 < 1e-12 {
            // |φ| < 1e-6: the next terms φ⁴/384 and φ⁴/3840 are below 3e-27
            (1.0 - 0.125 * a2, 0.5 - a2 * (1.0 / 48.0))
        } else if a2 < 1e-4 {
            (
                1.0 - (0.125 * a2) * (1.0 - (a2 * (1.0 / 48.0)) * (1.0 - a2 * (1.0 / 120.0))),
                0.5 - (0.5 / 24.0 * a2) * (1.0 - (a2 * (1.0 / 80.0)) * (1.0 - a2 * (1.0 / 168.0))),
            )
        } else {
            let a = libm::sqrt(a2);
            let (s, c) = libm::sincos(0.5 * a);
            (c, s / a)
        };
        Quat::from_parts(c, &(phi * s_over))
    }

    /// Rotation vector of the quaternion (shortest rotation, |φ| ≤ π), inverse of
    /// [`Quat::from_rotvec`].
    pub fn to_rotvec(&self) -> Vec3 {
        let q = if self.w < 0.0 {
            self.scale(-1.0)
        } else {
            *self
        };
        let v = q.vec();
        let s = v.norm();
        if s < 1e-8 {
            // φ = 2 atan2(s, w) · v/s ≈ (2/w)(1 − s²/(3w²)) v
            let w = q.w;
            return v * (2.0 / w) * (1.0 - s * s / (3.0 * w * w));
        }
        v * (2.0 * libm::atan2(s, q.w) / s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Mat3, b: &Mat3, tol: f64) -> bool {
        (a - b).abs().max() <= tol
    }

    #[test]
    fn product_matches_dcm_composition() {
        let a = Quat::from_rotvec(&Vec3::new(0.3, -0.5, 0.9));
        let b = Quat::from_rotvec(&Vec3::new(-1.1, 0.2, 0.4));
        assert!(close(
            &a.mul(&b).to_dcm(),
            &(a.to_dcm() * b.to_dcm()),
            1e-15
        ));
    }

    #[test]
    fn rotate_matches_dcm_and_sandwich() {
        let q = Quat::from_rotvec(&Vec3::new(0.7, 0.1, -2.0));
        let v = Vec3::new(1.0, -2.0, 0.5);
        let sandwich = q.mul(&Quat::from_parts(0.0, &v)).mul(&q.conj());
        assert!((q.rotate(&v) - q.to_dcm() * v).norm() < 1e-15);
        assert!((sandwich.vec() - q.to_dcm() * v).norm() < 1e-15);
    }

    #[test]
    fn dcm_round_trip_all_branches() {
        // Rotations by ~π about each axis exercise every Shepperd branch.
        for phi in [
            Vec3::new(0.1, 0.2, 0.3),
            Vec3::new(3.1, 0.0, 0.1),
            Vec3::new(0.0, 3.1, 0.1),
            Vec3::new(0.1, 0.0, 3.1),
        ] {
            let q = Quat::from_rotvec(&phi);
            let q2 = Quat::from_dcm(&q.to_dcm());
            let q = if q.w < 0.0 { q.scale(-1.0) } else { q };
            assert!((q.w - q2.w).abs() < 1e-15 && (q.vec() - q2.vec()).norm() < 1e-15);
        }
    }

    #[test]
    fn rotvec_round_trip_and_small_angle_continuity() {
        for phi in [
            Vec3::new(0.3, -2.0, 1.0),
            Vec3::new(1e-3, -2e-3, 5e-4),
            Vec3::new(4e-7, 1e-7, -3e-7),
            Vec3::new(1e-12, 0.0, 0.0),
        ] {
            let back = Quat::from_rotvec(&phi).to_rotvec();
            assert!((back - phi).norm() <= 1e-15 * (1.0 + phi.norm()), "{phi:?}");
        }
        // The series against the closed form below 1e-2 rad, and across both switches
        for a in [5e-7, 2e-6, 1e-4, 3e-3, 9.99e-3] {
            let phi = Vec3::new(0.6, -0.48, 0.64) * a; // |(0.6, −0.48, 0.64)| = 1
            let q = Quat::from_rotvec(&phi);
            let (s, c) = (0.5 * a).sin_cos();
            assert!((q.w - c).abs() < 2e-16 && (q.vec() - phi * (s / a)).norm() < 2e-16 * a);
        }
        for a in [1e-6, 1e-2] {
            let below = Quat::from_rotvec(&Vec3::new(a * (1.0 - 1e-15), 0.0, 0.0));
            let above = Quat::from_rotvec(&Vec3::new(a * (1.0 + 1e-15), 0.0, 0.0));
            assert!((above.w - below.w).abs() < 3e-16 && (above.x - below.x).abs() < 3e-16);
        }
        let q = Quat::new(1.0 + 3e-12, 2e-12, -1e-12, 0.0).renormalized();
        assert!((q.norm() - 1.0).abs() < 2e-16);
        // Series and closed form agree across the 1e-6 switch to roundoff.
        let below = Quat::from_rotvec(&Vec3::new(0.999_999_9e-6, 0.0, 0.0));
        let above = Quat::from_rotvec(&Vec3::new(1.000_000_1e-6, 0.0, 0.0));
        assert!((above.x - below.x - 1e-13).abs() < 1e-20 + 1e-16);
    }
}
