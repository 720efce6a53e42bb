//! Initial states: the one validator every source goes through ([`validate_initial_state`]:
//! `--init`, a PSINS `.imu` header, the first row of a truth file, a scenario start, a GNSS
//! first fix), and the value list of `sdins nav --init`:
//! `lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg` (NED, FRD).
//!
//! The limits are those of the kinematic envelope ([`crate::truth::envelope::Envelope::DEFAULT`]):
//! |latitude| ≤ 89.99°, height in \[−1000, 100 000\] m, speed ≤ 3000 m/s, and an attitude
//! matrix that is a rotation (‖CᵀC − I‖ ≤ 1e-6, det C > 0).

use crate::truth::envelope::Envelope;
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};
use sdins_core::nav::InitialState;

const D2R: f64 = std::f64::consts::PI / 180.0;

/// What is wrong with an initial state. The caller prefixes the source (option, file and
/// line); the message names the field.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InitialStateError {
    /// A value is NaN or infinite.
    #[error("{field} is not finite ({value})")]
    NotFinite {
        /// field name with unit
        field: &'static str,
        /// the value
        value: f64,
    },
    /// A value is outside its range.
    #[error("{field} = {value} is outside {range}")]
    OutOfRange {
        /// field name with unit
        field: &'static str,
        /// the value in the field's unit
        value: f64,
        /// the accepted range, as text
        range: String,
    },
    /// The attitude is not a rotation matrix.
    #[error("attitude c_b_n is not a rotation (‖CᵀC − I‖ = {defect:.3e}, det = {det:.6})")]
    NotRotation {
        /// orthonormality defect
        defect: f64,
        /// determinant
        det: f64,
    },
}

/// Check an initial state against the envelope. Every initial-state source calls this.
pub fn validate_initial_state(s: &InitialState) -> Result<(), InitialStateError> {
    let env = Envelope::DEFAULT;
    let fin = |field: &'static str, value: f64| {
        if value.is_finite() {
            Ok(())
        } else {
            Err(InitialStateError::NotFinite { field, value })
        }
    };
    fin("latitude [deg]", s.lat_rad.to_degrees())?;
    fin("longitude [deg]", s.lon_rad.to_degrees())?;
    fin("height [m]", s.h_m)?;
    for (f, v) in ["v_n [m/s]", "v_e [m/s]", "v_d [m/s]"]
        .into_iter()
        .zip(s.v_n_mps.iter())
    {
        fin(f, *v)?;
    }
    if s.c_b_n.iter().any(|x| !x.is_finite()) {
        return Err(InitialStateError::NotFinite {
            field: "attitude c_b_n",
            value: f64::NAN,
        });
    }
    let lim = env.max_abs_lat_rad.to_degrees();
    if s.lat_rad.abs() > env.max_abs_lat_rad {
        return Err(InitialStateError::OutOfRange {
            field: "latitude [deg]",
            value: s.lat_rad.to_degrees(),
            range: format!(
                "[-{lim:.2}, {lim:.2}] deg (the NED mechanization is singular at the poles)"
            ),
        });
    }
    if s.lon_rad.abs() > 2.0 * std::f64::consts::PI {
        return Err(InitialStateError::OutOfRange {
            field: "longitude [deg]",
            value: s.lon_rad.to_degrees(),
            range: "[-360, 360] deg".into(),
        });
    }
    if s.h_m < env.min_h_m || s.h_m > env.max_h_m {
        return Err(InitialStateError::OutOfRange {
            field: "height [m]",
            value: s.h_m,
            range: format!("[{}, {}] m", env.min_h_m, env.max_h_m),
        });
    }
    let speed = s.v_n_mps.norm();
    if speed > env.max_speed_mps {
        return Err(InitialStateError::OutOfRange {
            field: "speed [m/s]",
            value: speed,
            range: format!("[0, {}] m/s", env.max_speed_mps),
        });
    }
    let defect = (s.c_b_n.transpose() * s.c_b_n - Mat3::identity())
        .abs()
        .max();
    let det = s.c_b_n.determinant();
    if defect > 1e-6 || det <= 0.0 {
        return Err(InitialStateError::NotRotation { defect, det });
    }
    Ok(())
}

/// Parse and validate the nine comma-separated values; the error says which value is
/// wrong and what is expected.
pub fn parse_initial_state(s: &str) -> Result<InitialState, String> {
    let mut v = Vec::with_capacity(9);
    for (i, x) in s.split(',').enumerate() {
        let x = x.trim();
        let val: f64 = x
            .parse()
            .map_err(|_| format!("--init: value {} `{x}` is not a number", i + 1))?;
        v.push(val);
    }
    let [lat, lon, h, vn, ve, vd, roll, pitch, yaw] = v[..] else {
        return Err(format!(
            "--init: expected 9 values lat,lon,h,vn,ve,vd,roll,pitch,yaw, got {}",
            v.len()
        ));
    };
    if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(format!("--init: value {} is not finite ({x})", i + 1));
    }
    if roll.abs() > 360.0 || pitch.abs() > 90.0 || yaw.abs() > 360.0 {
        return Err(
            "--init: angles out of range: |roll|, |yaw| ≤ 360 deg, |pitch| ≤ 90 deg".into(),
        );
    }
    let s = InitialState {
        lat_rad: lat * D2R,
        lon_rad: lon * D2R,
        h_m: h,
        v_n_mps: Vec3::new(vn, ve, vd),
        c_b_n: c_b_n_from_euler(&Euler::new(roll * D2R, pitch * D2R, yaw * D2R)),
    };
    validate_initial_state(&s).map_err(|e| format!("--init: {e}"))?;
    Ok(s)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn good_and_bad_lists() {
        let s = parse_initial_state("37.5, 127, 10, 0, 340.29, 0, 0, 0, 90").unwrap();
        assert!((s.lat_rad - 37.5 * D2R).abs() < 1e-15 && (s.v_n_mps.y - 340.29).abs() < 1e-12);
        for (bad, what) in [
            ("1,2,3", "expected 9 values"),
            ("1,2,3,4,5,6,7,8,x", "value 9 `x`"),
            ("95,0,0,0,0,0,0,0,0", "latitude [deg] = 95"),
            ("0,0,-2000,0,0,0,0,0,0", "height [m] = -2000"),
            ("0,0,0,NaN,0,0,0,0,0", "value 4 is not finite"),
            ("0,0,0,5000,0,0,0,0,0", "speed"),
            ("0,0,0,0,0,0,0,95,0", "angles"),
            ("0,400,0,0,0,0,0,0,0", "longitude"),
        ] {
            let e = parse_initial_state(bad).err().unwrap();
            assert!(e.contains(what), "{bad}: {e}");
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod validator_tests {
    use super::*;

    fn good() -> InitialState {
        parse_initial_state("37.5,127,10,0,340.29,0,0,0,90").unwrap()
    }

    #[test]
    fn each_field_is_checked() {
        assert!(validate_initial_state(&good()).is_ok());
        let mut cases: Vec<(InitialState, &str)> = Vec::new();
        let mut s = good();
        s.lat_rad = 95.0 * D2R;
        cases.push((s, "latitude"));
        let mut s = good();
        s.v_n_mps.x = 1e300;
        cases.push((s, "speed"));
        let mut s = good();
        s.h_m = f64::NAN;
        cases.push((s, "height [m] is not finite"));
        let mut s = good();
        s.c_b_n *= 2.0;
        cases.push((s, "not a rotation"));
        let mut s = good();
        s.c_b_n = -s.c_b_n;
        cases.push((s, "not a rotation"));
        for (s, want) in cases {
            let e = validate_initial_state(&s).unwrap_err().to_string();
            assert!(e.contains(want), "{e} lacks {want}");
        }
    }
}
