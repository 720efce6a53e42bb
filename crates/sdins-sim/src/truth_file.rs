//! Reference-trajectory files for `sdins nav --truth`: the sdins `truth.csv` written by
//! `sdins truth` (NED, FRD, degrees) and PSINS `avp` CSVs (ENU, RFU, PSINS 3-1-2 Euler
//! angles), converted to sdins conventions at the edge.

use crate::truth::TruthSample;
use sdins_core::coning::Increment;
use sdins_core::math::{c_b_n_from_euler, Euler, Mat3, Vec3};
use std::path::{Path, PathBuf};

const D2R: f64 = std::f64::consts::PI / 180.0;

/// Why a truth file could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TruthFileError {
    /// I/O error.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// the file
        file: PathBuf,
        /// cause
        source: std::io::Error,
    },
    /// Content error.
    #[error("{}:{line}: {field}: {message}", file.display())]
    Invalid {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// column name
        field: String,
        /// what is wrong
        message: String,
    },
}

/// `C_b^n` (FRD→NED) from PSINS attitude `[pitch, roll, yaw]` (rad): PSINS's
/// `C_b^n(RFU→ENU) = Rz(yaw) Rx(pitch) Ry(roll)` (yaw counter-clockwise from north), then
/// `C = P C_psins P` with `P = [[0,1,0],[1,0,0],[0,0,−1]]` mapping ENU→NED and FRD→RFU.
pub fn c_b_n_from_psins(pitch: f64, roll: f64, yaw: f64) -> Mat3 {
    let (sp, cp) = pitch.sin_cos();
    let (sr, cr) = roll.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    let rz = Mat3::new(cy, -sy, 0.0, sy, cy, 0.0, 0.0, 0.0, 1.0);
    let rx = Mat3::new(1.0, 0.0, 0.0, 0.0, cp, -sp, 0.0, sp, cp);
    let ry = Mat3::new(cr, 0.0, sr, 0.0, 1.0, 0.0, -sr, 0.0, cr);
    let p = Mat3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
    p * (rz * rx * ry) * p
}

fn parse_rows(path: &Path, expect: &[&str]) -> Result<Vec<Vec<f64>>, TruthFileError> {
    let text = std::fs::read_to_string(path).map_err(|source| TruthFileError::Io {
        file: path.into(),
        source,
    })?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let bad = |line: usize, field: &str, message: String| TruthFileError::Invalid {
        file: path.into(),
        line,
        field: field.into(),
        message,
    };
    let Some((hl, header)) = lines.next() else {
        return Err(bad(1, "(header)", "empty file".into()));
    };
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    for (i, e) in expect.iter().enumerate() {
        if cols.get(i) != Some(e) {
            return Err(bad(
                hl + 1,
                e,
                format!(
                    "expected column {} to be `{e}`, header is `{header}`",
                    i + 1
                ),
            ));
        }
    }
    let mut rows = Vec::new();
    for (ln, l) in lines {
        let f: Vec<&str> = l.split(',').collect();
        if f.len() < expect.len() {
            return Err(bad(
                ln + 1,
                "(row)",
                format!("{} fields, expected at least {}", f.len(), expect.len()),
            ));
        }
        let mut r = Vec::with_capacity(expect.len());
        for (i, name) in expect.iter().enumerate() {
            let v: f64 = f[i]
                .trim()
                .parse()
                .map_err(|_| bad(ln + 1, name, format!("`{}` is not a number", f[i].trim())))?;
            if !v.is_finite() {
                return Err(bad(ln + 1, name, "not finite".into()));
            }
            r.push(v);
        }
        if let Some(prev) = rows.last().map(|p: &Vec<f64>| p[0]) {
            if r[0] <= prev {
                return Err(bad(
                    ln + 1,
                    expect[0],
                    format!("time {} does not increase (previous {prev})", r[0]),
                ));
            }
        }
        rows.push(r);
    }
    Ok(rows)
}

fn sample(t_s: f64, lat: f64, lon: f64, h: f64, v: Vec3, c: Mat3) -> TruthSample {
    TruthSample {
        t_s,
        inc: Increment::default(),
        lat_rad: lat,
        lon_rad: lon,
        h_m: h,
        v_n_mps: v,
        c_b_n: c,
    }
}

/// Read an sdins `truth.csv`.
pub fn read_sdins_truth(path: &Path) -> Result<Vec<TruthSample>, TruthFileError> {
    let cols = [
        "t_s",
        "lat_deg",
        "lon_deg",
        "h_m",
        "v_n_mps",
        "v_e_mps",
        "v_d_mps",
        "roll_deg",
        "pitch_deg",
        "yaw_deg",
    ];
    Ok(parse_rows(path, &cols)?
        .into_iter()
        .map(|r| {
            let c = c_b_n_from_euler(&Euler::new(r[7] * D2R, r[8] * D2R, r[9] * D2R));
            sample(
                r[0],
                r[1] * D2R,
                r[2] * D2R,
                r[3],
                Vec3::new(r[4], r[5], r[6]),
                c,
            )
        })
        .collect())
}

/// Read a PSINS `*_avp.csv` (converted by the shared data tools):
/// `t_s,pitch_rad,roll_rad,yaw_rad,v_e_mps,v_n_mps,v_u_mps,lat_rad,lon_rad,h_m`.
pub fn read_psins_avp(path: &Path) -> Result<Vec<TruthSample>, TruthFileError> {
    let cols = [
        "t_s",
        "pitch_rad",
        "roll_rad",
        "yaw_rad",
        "v_e_mps",
        "v_n_mps",
        "v_u_mps",
        "lat_rad",
        "lon_rad",
        "h_m",
    ];
    Ok(parse_rows(path, &cols)?
        .into_iter()
        .map(|r| {
            sample(
                r[0],
                r[7],
                r[8],
                r[9],
                Vec3::new(r[5], r[4], -r[6]),
                c_b_n_from_psins(r[1], r[2], r[3]),
            )
        })
        .collect())
}

/// Read either format, told apart by the header.
pub fn read_truth(path: &Path) -> Result<Vec<TruthSample>, TruthFileError> {
    let head = std::fs::read_to_string(path).map_err(|source| TruthFileError::Io {
        file: path.into(),
        source,
    })?;
    if head
        .lines()
        .find(|l| !l.starts_with('#'))
        .is_some_and(|l| l.contains("pitch_rad"))
    {
        read_psins_avp(path)
    } else {
        read_sdins_truth(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sdins_core::math::euler_from_c_b_n;

    #[test]
    fn psins_level_yaw_is_negated_heading() {
        let c = c_b_n_from_psins(0.0, 0.0, 0.3);
        let e = euler_from_c_b_n(&c);
        assert!(
            (e.yaw_rad + 0.3).abs() < 1e-15
                && e.roll_rad.abs() < 1e-15
                && e.pitch_rad.abs() < 1e-15
        );
        // PSINS pitch (nose up about the right axis) is NED pitch; PSINS roll (right wing
        // down about the forward axis) is NED roll.
        let e = euler_from_c_b_n(&c_b_n_from_psins(0.1, 0.0, 0.0));
        assert!((e.pitch_rad - 0.1).abs() < 1e-15);
        let e = euler_from_c_b_n(&c_b_n_from_psins(0.0, 0.2, 0.0));
        assert!((e.roll_rad - 0.2).abs() < 1e-15);
    }
}
