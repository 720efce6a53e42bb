//! Euler angles, 3-2-1 sequence (yaw ψ, pitch θ, roll φ): `c_b_n = Rz(ψ) Ry(θ) Rx(φ)`
//! (docs/conventions.md §"Euler angles", §"Frames").

use super::Mat3;

/// Roll, pitch, yaw in radians (3-2-1 sequence).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Euler {
    /// roll φ \[rad\], rotation about body x
    pub roll_rad: f64,
    /// pitch θ \[rad\], rotation about the intermediate y
    pub pitch_rad: f64,
    /// yaw ψ \[rad\], rotation about the navigation z (down), clockwise from north seen from above
    pub yaw_rad: f64,
}

impl Euler {
    /// Build from roll, pitch, yaw in radians.
    pub const fn new(roll_rad: f64, pitch_rad: f64, yaw_rad: f64) -> Self {
        Self {
            roll_rad,
            pitch_rad,
            yaw_rad,
        }
    }
}

/// `c_b_n = Rz(yaw) Ry(pitch) Rx(roll)`.
pub fn c_b_n_from_euler(e: &Euler) -> Mat3 {
    c_b_n_from_sin_cos(
        libm::sincos(e.roll_rad),
        libm::sincos(e.pitch_rad),
        libm::sincos(e.yaw_rad),
    )
}

/// `c_b_n = Rz(yaw) Ry(pitch) Rx(roll)` from the `(sin, cos)` pairs of roll, pitch and
/// yaw (for callers that already hold them, e.g. constant angles).
#[inline]
pub fn c_b_n_from_sin_cos(roll: (f64, f64), pitch: (f64, f64), yaw: (f64, f64)) -> Mat3 {
    let ((sf, cf), (st, ct), (sp, cp)) = (roll, pitch, yaw);
    Mat3::new(
        cp * ct,
        cp * st * sf - sp * cf,
        cp * st * cf + sp * sf,
        sp * ct,
        sp * st * sf + cp * cf,
        sp * st * cf - cp * sf,
        -st,
        ct * sf,
        ct * cf,
    )
}

/// Euler angles of `c_b_n`: roll = atan2(C32, C33), pitch = −asin(C31), yaw = atan2(C21, C11).
/// The pitch argument is clamped to \[−1, 1\] against roundoff.
pub fn euler_from_c_b_n(c: &Mat3) -> Euler {
    let s = (-c[(2, 0)]).clamp(-1.0, 1.0);
    Euler {
        roll_rad: libm::atan2(c[(2, 1)], c[(2, 2)]),
        pitch_rad: libm::asin(s),
        yaw_rad: libm::atan2(c[(1, 0)], c[(0, 0)]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_round_trip() {
        let e = Euler::new(0.2, -0.7, 2.9);
        let back = euler_from_c_b_n(&c_b_n_from_euler(&e));
        assert!((back.roll_rad - e.roll_rad).abs() < 1e-15);
        assert!((back.pitch_rad - e.pitch_rad).abs() < 1e-15);
        assert!((back.yaw_rad - e.yaw_rad).abs() < 1e-15);
    }

    #[test]
    fn yaw_90_maps_body_x_to_east() {
        let c = c_b_n_from_euler(&Euler::new(0.0, 0.0, core::f64::consts::FRAC_PI_2));
        let x_n = c * super::super::Vec3::new(1.0, 0.0, 0.0);
        assert!((x_n - super::super::Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-16);
    }
}
