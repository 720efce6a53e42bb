//! The initial-state value list of `sdins nav --init`:
//! `lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg` (NED, FRD).

use sdins_core::math::{c_b_n_from_euler, Euler, Vec3};
use sdins_core::nav::InitialState;

const D2R: f64 = std::f64::consts::PI / 180.0;

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
    if v.iter().any(|x| !x.is_finite()) {
        return Err("--init: values must be finite".into());
    }
    if lat.abs() > 89.99 {
        return Err(format!(
            "--init: latitude {lat} is outside [-89.99, 89.99] deg"
        ));
    }
    if !(-1000.0..=100_000.0).contains(&h) {
        return Err(format!("--init: height {h} m is outside [-1000, 100000]"));
    }
    if Vec3::new(vn, ve, vd).norm() > 3000.0 {
        return Err(format!(
            "--init: speed {} m/s is beyond 3000 m/s",
            Vec3::new(vn, ve, vd).norm()
        ));
    }
    if lon.abs() > 360.0 || roll.abs() > 360.0 || pitch.abs() > 90.0 || yaw.abs() > 360.0 {
        return Err(
            "--init: angles out of range: |lon|, |roll|, |yaw| ≤ 360 deg, |pitch| ≤ 90 deg".into(),
        );
    }
    Ok(InitialState {
        lat_rad: lat * D2R,
        lon_rad: lon * D2R,
        h_m: h,
        v_n_mps: Vec3::new(vn, ve, vd),
        c_b_n: c_b_n_from_euler(&Euler::new(roll * D2R, pitch * D2R, yaw * D2R)),
    })
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
            ("95,0,0,0,0,0,0,0,0", "latitude 95"),
            ("0,0,-2000,0,0,0,0,0,0", "height -2000"),
            ("0,0,0,NaN,0,0,0,0,0", "finite"),
            ("0,0,0,5000,0,0,0,0,0", "speed"),
            ("0,0,0,0,0,0,0,95,0", "angles"),
        ] {
            let e = parse_initial_state(bad).err().unwrap();
            assert!(e.contains(what), "{bad}: {e}");
        }
    }
}
