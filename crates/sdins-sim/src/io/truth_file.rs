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

/// Largest accepted |latitude| \[deg\] in a reference trajectory.
pub const MAX_LAT_DEG: f64 = 90.0;
/// Accepted height range \[m\] (the same as the scenario parser's).
pub const H_RANGE_M: (f64, f64) = (-1000.0, 100_000.0);
/// Largest accepted step between two reference rows \[s\] (a larger step is a wrong time
/// unit or a corrupt file; comparisons interpolate between rows).
pub const MAX_TRUTH_STEP_S: f64 = 60.0;

/// Parse the rows of a reference-trajectory CSV: the header must start with `expect`;
/// every row needs at least `expect.len()` finite numbers and a strictly increasing time.
fn parse_rows(path: &Path, text: &str, expect: &[&str]) -> Result<Vec<Vec<f64>>, TruthFileError> {
    // a UTF-8 byte-order mark is accepted and skipped
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i, l.trim_end_matches('\r')))
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'))
        .peekable();
    let bad = |line: usize, field: String, message: String| TruthFileError::Invalid {
        file: path.into(),
        line,
        field,
        message,
    };
    let col = |i: usize| {
        format!(
            "column {} ({})",
            i + 1,
            expect.get(i).copied().unwrap_or("?")
        )
    };
    let Some((hl, header)) = lines.next() else {
        return Err(bad(
            1,
            "(header)".into(),
            format!(
                "empty file, expected the header `{}` and data rows",
                expect.join(",")
            ),
        ));
    };
    let cols: Vec<&str> = header
        .split(',')
        .map(|c| c.trim().trim_matches('"'))
        .collect();
    for (i, e) in expect.iter().enumerate() {
        if cols.get(i) != Some(e) {
            return Err(bad(
                hl + 1,
                col(i),
                format!(
                    "expected column {} to be `{e}`, header is `{}`",
                    i + 1,
                    header.chars().take(200).collect::<String>()
                ),
            ));
        }
    }
    if lines.peek().is_none() {
        return Err(bad(
            hl + 1,
            "(header)".into(),
            "header only, expected data rows after it".into(),
        ));
    }
    let ends_with_newline = text.ends_with('\n');
    let mut rows: Vec<Vec<f64>> = Vec::new();
    while let Some((ln, l)) = lines.next() {
        let f: Vec<&str> = l.split(',').collect();
        if f.len() < expect.len() {
            let last = lines.peek().is_none() && !ends_with_newline;
            return Err(bad(
                ln + 1,
                "(row)".into(),
                if last {
                    format!(
                        "truncated last line: {} of {} fields and no final newline",
                        f.len(),
                        expect.len()
                    )
                } else {
                    format!("{} fields, expected at least {}", f.len(), expect.len())
                },
            ));
        }
        let mut r = Vec::with_capacity(expect.len());
        for (i, text) in f.iter().take(expect.len()).enumerate() {
            let text = text.trim();
            let v: f64 = text
                .parse()
                .map_err(|_| bad(ln + 1, col(i), format!("expected a number, found `{text}`")))?;
            if !v.is_finite() {
                return Err(bad(
                    ln + 1,
                    col(i),
                    format!("expected a finite number, found `{text}`"),
                ));
            }
            r.push(v);
        }
        if let Some(prev) = rows.last().and_then(|p| p.first().copied()) {
            if r[0] <= prev {
                return Err(bad(
                    ln + 1,
                    col(0),
                    format!("expected a time after {prev} s, found {} s", r[0]),
                ));
            }
            if r[0] - prev > MAX_TRUTH_STEP_S {
                return Err(bad(
                    ln + 1,
                    col(0),
                    format!(
                        "step of {:e} s from the row before, expected at most {MAX_TRUTH_STEP_S} s",
                        r[0] - prev
                    ),
                ));
            }
        }
        rows.push(r);
    }
    Ok(rows)
}

/// Check that `v` (column `i` of `row` on file line `line`) lies in `[lo, hi]`.
fn check_range(
    path: &Path,
    line: usize,
    expect: &[&str],
    i: usize,
    v: f64,
    (lo, hi): (f64, f64),
) -> Result<(), TruthFileError> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(TruthFileError::Invalid {
            file: path.into(),
            line,
            field: format!(
                "column {} ({})",
                i + 1,
                expect.get(i).copied().unwrap_or("?")
            ),
            message: format!("{v} is out of range: expected [{lo}, {hi}]"),
        })
    }
}

/// 1-based file line of data row `k` (comments and blank lines skipped as in `parse_rows`).
fn data_line(text: &str, k: usize) -> usize {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'))
        .nth(k + 1)
        .map_or(0, |(i, _)| i + 1)
}

fn sample(t_s: f64, lat: f64, lon: f64, h: f64, v: Vec3, c: Mat3) -> TruthSample {
    TruthSample::new(t_s, Increment::default(), lat, lon, h, v, c)
}

/// Column names of an sdins `truth.csv` (further columns, e.g. the quaternion, are ignored).
pub const SDINS_TRUTH_COLUMNS: [&str; 10] = [
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

/// The full header `sdins truth` writes: [`SDINS_TRUTH_COLUMNS`] and the attitude
/// quaternion `q_b_n` (Hamilton, scalar first).
pub const SDINS_TRUTH_HEADER: [&str; 14] = [
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
    "q_w",
    "q_x",
    "q_y",
    "q_z",
];

/// Parse the text of an sdins `truth.csv`; `path` names it in error messages.
pub fn parse_sdins_truth(path: &Path, text: &str) -> Result<Vec<TruthSample>, TruthFileError> {
    let cols = SDINS_TRUTH_COLUMNS;
    let rows = parse_rows(path, text, &cols)?;
    let mut out = Vec::with_capacity(rows.len());
    for (k, r) in rows.iter().enumerate() {
        if r[1].abs() > MAX_LAT_DEG || !(H_RANGE_M.0..=H_RANGE_M.1).contains(&r[3]) {
            let line = data_line(text, k);
            check_range(path, line, &cols, 1, r[1], (-MAX_LAT_DEG, MAX_LAT_DEG))?;
            check_range(path, line, &cols, 3, r[3], H_RANGE_M)?;
        }
        let c = c_b_n_from_euler(&Euler::new(r[7] * D2R, r[8] * D2R, r[9] * D2R));
        out.push(sample(
            r[0],
            r[1] * D2R,
            r[2] * D2R,
            r[3],
            Vec3::new(r[4], r[5], r[6]),
            c,
        ));
    }
    Ok(out)
}

/// Read an sdins `truth.csv`.
pub fn read_sdins_truth(path: &Path) -> Result<Vec<TruthSample>, TruthFileError> {
    parse_sdins_truth(path, &read_text(path)?)
}

/// The file's text, its header line checked before the rest is read (a first line that
/// is neither blank nor a `#` comment must be the header of one of the formats).
fn read_text(path: &Path) -> Result<String, TruthFileError> {
    let check = |first: &str| {
        let first = first.strip_prefix('\u{feff}').unwrap_or(first);
        if first.trim().is_empty() || first.starts_with('#') {
            return Ok(());
        }
        match parse_truth_str(path, first) {
            // "header only": the header itself is right
            Ok(_) => Ok(()),
            Err(TruthFileError::Invalid { field, .. }) if field == "(header)" => Ok(()),
            Err(e) => Err(e),
        }
    };
    let bytes = crate::input::read_capped_with(path, check).map_err(|e| match e {
        crate::input::Refused::Io(source) => TruthFileError::Io {
            file: path.into(),
            source,
        },
        crate::input::Refused::Header(e) => e,
    })?;
    Ok(crate::input::text_lossy(bytes))
}

/// Column names of a PSINS `*_avp.csv`.
pub const PSINS_AVP_COLUMNS: [&str; 10] = [
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

/// Parse the text of a PSINS `*_avp.csv` (converted by the shared data tools):
/// `t_s,pitch_rad,roll_rad,yaw_rad,v_e_mps,v_n_mps,v_u_mps,lat_rad,lon_rad,h_m`.
pub fn parse_psins_avp(path: &Path, text: &str) -> Result<Vec<TruthSample>, TruthFileError> {
    let cols = PSINS_AVP_COLUMNS;
    let rows = parse_rows(path, text, &cols)?;
    let lat_max = MAX_LAT_DEG * D2R;
    let mut out = Vec::with_capacity(rows.len());
    for (k, r) in rows.iter().enumerate() {
        if r[7].abs() > lat_max || !(H_RANGE_M.0..=H_RANGE_M.1).contains(&r[9]) {
            let line = data_line(text, k);
            check_range(path, line, &cols, 7, r[7], (-lat_max, lat_max))?;
            check_range(path, line, &cols, 9, r[9], H_RANGE_M)?;
        }
        out.push(sample(
            r[0],
            r[7],
            r[8],
            r[9],
            Vec3::new(r[5], r[4], -r[6]),
            c_b_n_from_psins(r[1], r[2], r[3]),
        ));
    }
    Ok(out)
}

/// Read a PSINS `*_avp.csv` (see [`parse_psins_avp`]).
pub fn read_psins_avp(path: &Path) -> Result<Vec<TruthSample>, TruthFileError> {
    parse_psins_avp(path, &read_text(path)?)
}

/// Column names of a NaveGo reference trajectory (`ref.csv` as converted from NaveGo's
/// `ref.mat`: NED velocity, ZYX Euler angles of body FRD to NED, radians).
pub const NAVEGO_REF_COLUMNS: [&str; 10] = [
    "t_s",
    "lat_rad",
    "lon_rad",
    "h_m",
    "v_n_mps",
    "v_e_mps",
    "v_d_mps",
    "roll_rad",
    "pitch_rad",
    "yaw_rad",
];

/// Parse the text of a NaveGo reference trajectory (see [`NAVEGO_REF_COLUMNS`]).
pub fn parse_navego_ref(path: &Path, text: &str) -> Result<Vec<TruthSample>, TruthFileError> {
    let cols = NAVEGO_REF_COLUMNS;
    let rows = parse_rows(path, text, &cols)?;
    let lat_max = MAX_LAT_DEG * D2R;
    let mut out = Vec::with_capacity(rows.len());
    for (k, r) in rows.iter().enumerate() {
        if r[1].abs() > lat_max || !(H_RANGE_M.0..=H_RANGE_M.1).contains(&r[3]) {
            let line = data_line(text, k);
            check_range(path, line, &cols, 1, r[1], (-lat_max, lat_max))?;
            check_range(path, line, &cols, 3, r[3], H_RANGE_M)?;
        }
        let c = c_b_n_from_euler(&Euler::new(r[7], r[8], r[9]));
        out.push(sample(
            r[0],
            r[1],
            r[2],
            r[3],
            Vec3::new(r[4], r[5], r[6]),
            c,
        ));
    }
    Ok(out)
}

/// Parse any of the formats, told apart by the header (`pitch_rad` first → PSINS avp,
/// `lat_rad` second → NaveGo, else sdins).
pub fn parse_truth_str(path: &Path, text: &str) -> Result<Vec<TruthSample>, TruthFileError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let header = text
        .lines()
        .find(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .unwrap_or("");
    if header.trim_start().starts_with("t_s,lat_rad") {
        parse_navego_ref(path, text)
    } else if header.contains("pitch_rad") {
        parse_psins_avp(path, text)
    } else {
        parse_sdins_truth(path, text)
    }
}

/// Read either format, told apart by the header.
pub fn read_truth(path: &Path) -> Result<Vec<TruthSample>, TruthFileError> {
    parse_truth_str(path, &read_text(path)?)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use sdins_core::math::euler_from_c_b_n;

    const H: &str = "t_s,lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg,q_w,q_x,q_y,q_z\n";
    const ROW0: &str = "0,37.5,127,10,0,0,0,1,2,3,1,0,0,0\n";
    const ROW1: &str = "0.01,37.5,127,10,0,0,0,1,2,3,1,0,0,0\n";

    fn msg(text: &str) -> String {
        parse_truth_str(Path::new("truth.csv"), text)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn validation_classes_name_file_line_column() {
        let ok = parse_truth_str(Path::new("truth.csv"), &format!("{H}{ROW0}{ROW1}")).unwrap();
        assert_eq!(ok.len(), 2);
        assert!((ok[1].lat_rad - 37.5 * D2R).abs() < 1e-15);
        for (text, want) in [
            (String::new(), "truth.csv:1: (header): empty file"),
            (H.to_string(), "truth.csv:1: (header): header only, expected data rows"),
            (
                "t_s,lat_deg\n0,1\n".to_string(),
                "truth.csv:1: column 3 (lon_deg): expected column 3 to be `lon_deg`",
            ),
            (
                format!("{H}{ROW0}0.01,37.5,127"),
                "truth.csv:3: (row): truncated last line: 3 of 10 fields and no final newline",
            ),
            (
                format!("{H}0,37.5,127\n{ROW1}"),
                "truth.csv:2: (row): 3 fields, expected at least 10",
            ),
            (
                format!("{H}{ROW0}0.01,37.5,abc,10,0,0,0,1,2,3\n"),
                "truth.csv:3: column 3 (lon_deg): expected a number, found `abc`",
            ),
            (
                format!("{H}{ROW0}0.01,37.5,127,NaN,0,0,0,1,2,3\n"),
                "truth.csv:3: column 4 (h_m): expected a finite number, found `NaN`",
            ),
            (
                format!("{H}{ROW0}0.01,37.5,127,10,inf,0,0,1,2,3\n"),
                "truth.csv:3: column 5 (v_n_mps): expected a finite number, found `inf`",
            ),
            (
                format!("{H}{ROW1}{ROW0}"),
                "truth.csv:3: column 1 (t_s): expected a time after 0.01 s, found 0 s",
            ),
            (
                format!("{H}{ROW0}{ROW0}"),
                "truth.csv:3: column 1 (t_s): expected a time after 0 s, found 0 s",
            ),
            (
                format!("{H}{ROW0}# c\n0.01,90.5,127,10,0,0,0,1,2,3\n"),
                "truth.csv:4: column 2 (lat_deg): 90.5 is out of range: expected [-90, 90]",
            ),
            (
                format!("{H}{ROW0}0.01,37.5,127,-1500,0,0,0,1,2,3\n"),
                "truth.csv:3: column 4 (h_m): -1500 is out of range: expected [-1000, 100000]",
            ),
            (
                format!("{H}{ROW0}0.01,37.5,127,100001,0,0,0,1,2,3\n"),
                "truth.csv:3: column 4 (h_m): 100001 is out of range: expected [-1000, 100000]",
            ),
            (
                "t_s,pitch_rad,roll_rad,yaw_rad,v_e_mps,v_n_mps,v_u_mps,lat_rad,lon_rad,h_m\n0,0,0,0,0,0,0,1.6,2,3\n".to_string(),
                "truth.csv:2: column 8 (lat_rad): 1.6 is out of range",
            ),
        ] {
            let m = msg(&text);
            assert!(m.starts_with(want), "want `{want}`, got `{m}`");
        }
    }

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
