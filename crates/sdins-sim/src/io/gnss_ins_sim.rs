//! Reader of gnss-ins-sim motion-definition CSV files and their translation to an sdins
//! scenario (docs/scenarios.md §"Importing gnss-ins-sim motion files").
//!
//! Layout: a header line; the initial state `lat (deg), lon (deg), alt (m), vx, vy, vz
//! (body, m/s), yaw, pitch, roll (deg)`; a header line; then one command per line:
//! `type (1–5), yaw, pitch, roll (deg, type 1: deg/s), vx, vy, vz (body m/s, type 1:
//! m/s²), duration (s), GPS visibility (0/1)`. The motion is compiled by
//! [`crate::truth::body_motion`]; the GPS-visibility column becomes `[gnss] outages_s`.

use crate::cancel::{CancelToken, Cancelled, POLL_EVERY_SAMPLES};
use crate::truth::body_motion::{
    BodyCommand, BodyMotion, BodyStart, CommandKind, MotionLimits, MAX_COMMANDS,
};
use std::fmt::Write as _;
use std::path::Path;

/// Columns of the initial-state and command rows.
const COLUMNS: usize = 9;

/// A located error in a motion-definition file (or in the import options).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GisError {
    /// The file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Read {
        /// file name
        file: String,
        /// OS message
        reason: String,
    },
    /// A bad value or line: file, 1-based line and column (field), what is wrong.
    #[error("{file}:{line}:{column}: {message}")]
    Invalid {
        /// file name
        file: String,
        /// 1-based line
        line: usize,
        /// 1-based column (field number; 1 for whole-line errors)
        column: usize,
        /// what is wrong and what is expected
        message: String,
    },
    /// The motion limits (`mode`) are not three finite positive numbers.
    #[error("mode: {0}")]
    Limits(String),
    /// Stopped through the cancellation token.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// A parsed motion-definition file.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionFile {
    /// initial latitude \[deg\]
    pub lat_deg: f64,
    /// initial longitude \[deg\]
    pub lon_deg: f64,
    /// initial altitude \[m\]
    pub h_m: f64,
    /// initial attitude (rad) and body velocity
    pub start: BodyStart,
    /// the commands (angles in rad, rad/s)
    pub commands: Vec<BodyCommand>,
    /// per command: GPS visible
    pub gps_visible: Vec<bool>,
    /// per command: its 1-based line in the file
    pub lines: Vec<usize>,
    /// the numbers as written: the initial-state row and the command rows (the TOML
    /// repeats them digit for digit)
    pub raw: Vec<[f64; COLUMNS]>,
}

/// Parse the text of a motion-definition file (`file` names it in errors).
pub fn parse_motion_def(text: &str, file: &str) -> Result<MotionFile, GisError> {
    parse_motion_def_with(text, file, &CancelToken::new())
}

/// [`parse_motion_def`], polling `cancel` every [`POLL_EVERY_SAMPLES`] lines; at most
/// [`MAX_COMMANDS`] commands (the next one is refused naming its line and the limit).
pub fn parse_motion_def_with(
    text: &str,
    file: &str,
    cancel: &CancelToken,
) -> Result<MotionFile, GisError> {
    let err = |line: usize, column: usize, message: String| GisError::Invalid {
        file: file.to_string(),
        line,
        column,
        message,
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // (1-based line, fields) of the non-empty lines
    let mut rows: Vec<(usize, Vec<&str>)> = Vec::new();
    for (i, l) in text.lines().enumerate() {
        if (i as u64).is_multiple_of(POLL_EVERY_SAMPLES) {
            cancel.check()?;
        }
        if l.trim().is_empty() {
            continue;
        }
        // two header lines and the initial state before the commands
        if rows.len() == MAX_COMMANDS + 3 {
            return Err(err(
                i + 1,
                1,
                format!("more than {MAX_COMMANDS} commands (the limit of one motion file): split the motion"),
            ));
        }
        rows.push((i + 1, l.split(',').map(str::trim).collect()));
    }
    if rows.len() < 4 {
        let line = rows.last().map_or(1, |r| r.0 + 1);
        return Err(err(line, 1, format!("expected a header line, the initial-state line, a header line and at least one command line; found {} non-empty lines", rows.len())));
    }
    let numbers = |(line, fields): &(usize, Vec<&str>)| -> Result<[f64; COLUMNS], GisError> {
        if fields.len() != COLUMNS {
            return Err(err(
                *line,
                1,
                format!(
                    "expected {COLUMNS} comma-separated columns, found {}",
                    fields.len()
                ),
            ));
        }
        let mut out = [0.0; COLUMNS];
        for (k, f) in fields.iter().enumerate() {
            let x: f64 = f
                .parse()
                .map_err(|_| err(*line, k + 1, format!("`{f}` is not a number")))?;
            if !x.is_finite() {
                return Err(err(*line, k + 1, format!("`{f}` is not a finite number")));
            }
            out[k] = x;
        }
        Ok(out)
    };
    let ini = numbers(&rows[1])?;
    let l1 = rows[1].0;
    if !(-90.0..=90.0).contains(&ini[0]) {
        return Err(err(
            l1,
            1,
            format!("latitude {} is outside [-90, 90] deg", ini[0]),
        ));
    }
    if !(-180.0..=360.0).contains(&ini[1]) {
        return Err(err(
            l1,
            2,
            format!("longitude {} is outside [-180, 360] deg", ini[1]),
        ));
    }
    for (k, name, lim) in [(6, "yaw", 360.0), (7, "pitch", 89.9), (8, "roll", 180.0)] {
        if ini[k].abs() > lim {
            return Err(err(
                l1,
                k + 1,
                format!("initial {name} {} is outside ±{lim} deg", ini[k]),
            ));
        }
    }
    let d2r = |x: f64| x.to_radians();
    let start = BodyStart {
        euler_ypr: [d2r(ini[6]), d2r(ini[7]), d2r(ini[8])],
        vel_b: [ini[3], ini[4], ini[5]],
    };
    let mut commands = Vec::new();
    let mut gps_visible = Vec::new();
    let mut lines = Vec::new();
    let mut raw = vec![ini];
    for (k, row) in rows[3..].iter().enumerate() {
        if (k as u64).is_multiple_of(POLL_EVERY_SAMPLES) {
            cancel.check()?;
        }
        let c = numbers(row)?;
        let line = row.0;
        let kind = if c[0].fract() == 0.0 {
            CommandKind::from_number(c[0] as i64)
        } else {
            None
        };
        let Some(kind) = kind else {
            return Err(err(
                line,
                1,
                format!("command type `{}` is not one of 1, 2, 3, 4, 5", row.1[0]),
            ));
        };
        if c[7] <= 0.0 {
            return Err(err(line, 8, format!("duration {} s must be > 0", c[7])));
        }
        if c[7] > crate::truth::trajectory::MAX_SEGMENT_S {
            return Err(err(line, 8, format!("duration {} s is too long", c[7])));
        }
        if c[8] != 0.0 && c[8] != 1.0 {
            return Err(err(
                line,
                9,
                format!("GPS visibility `{}` must be 0 or 1", row.1[8]),
            ));
        }
        commands.push(BodyCommand {
            kind,
            euler_ypr: [d2r(c[1]), d2r(c[2]), d2r(c[3])],
            vel_b: [c[4], c[5], c[6]],
            duration_s: c[7],
        });
        gps_visible.push(c[8] == 1.0);
        lines.push(line);
        raw.push(c);
    }
    Ok(MotionFile {
        lat_deg: ini[0],
        lon_deg: ini[1],
        h_m: ini[2],
        start,
        commands,
        gps_visible,
        lines,
        raw,
    })
}

/// Read and parse a motion-definition file.
pub fn read_motion_def(path: &Path) -> Result<MotionFile, GisError> {
    read_motion_def_with(path, &CancelToken::new())
}

/// [`read_motion_def`], polling `cancel` ([`parse_motion_def_with`]).
pub fn read_motion_def_with(path: &Path, cancel: &CancelToken) -> Result<MotionFile, GisError> {
    let file = path.display().to_string();
    let bytes = crate::input::read_capped(path).map_err(|e| GisError::Read {
        file: file.clone(),
        reason: e.to_string(),
    })?;
    let text = String::from_utf8(bytes).map_err(|e| GisError::Read {
        file: file.clone(),
        reason: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
    })?;
    parse_motion_def_with(&text, &file, cancel)
}

/// Whether a text looks like a gnss-ins-sim motion-definition file (its first line is the
/// initial-state header), for accepting the CSV wherever a scenario is accepted.
pub fn looks_like_motion_def(text: &str) -> bool {
    let first = text
        .strip_prefix('\u{feff}')
        .unwrap_or(text)
        .lines()
        .next()
        .unwrap_or("");
    first
        .trim_start()
        .to_ascii_lowercase()
        .starts_with("ini lat")
}

/// Import options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImportOptions {
    /// motion limits (gnss-ins-sim `mode`)
    pub limits: MotionLimits,
    /// IMU rate of the scenario \[Hz\] (command durations must be whole samples)
    pub rate_hz: f64,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            limits: MotionLimits::DEFAULT,
            rate_hz: 100.0,
        }
    }
}

/// Check `mode = [m/s², deg/s², deg/s]` and turn it into limits.
pub fn limits_from_mode(mode: [f64; 3]) -> Result<MotionLimits, GisError> {
    let names = [
        "max acceleration [m/s²]",
        "max angular acceleration [deg/s²]",
        "max angular rate [deg/s]",
    ];
    for (x, n) in mode.iter().zip(names) {
        if !(x.is_finite() && *x > 0.0) {
            return Err(GisError::Limits(format!(
                "{n} = {x}: must be a finite number > 0"
            )));
        }
    }
    Ok(MotionLimits::from_mode(mode))
}

/// GPS outages `[start_s, end_s]` from the per-command visibility on the compiled times
/// (adjacent invisible commands merged).
pub fn outages(body: &BodyMotion, visible: &[bool]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    for (p, &vis) in body.pieces().iter().zip(visible) {
        if vis {
            continue;
        }
        let (a, b) = (p.t0_s, p.t0_s + p.duration_s);
        match out.last_mut() {
            Some(last) if last[1] == a => last[1] = b,
            _ => out.push([a, b]),
        }
    }
    out
}

/// The equivalent scenario TOML (vehicle = "free", `[[command]]` tables, `[gnss]` with the
/// outages of the GPS-visibility column). `file` names the source in errors and comments.
pub fn to_scenario_toml(
    mf: &MotionFile,
    name: &str,
    file: &str,
    opts: &ImportOptions,
) -> Result<String, GisError> {
    to_scenario_toml_with(mf, name, file, opts, &CancelToken::new())
}

/// [`to_scenario_toml`], polling `cancel` every [`POLL_EVERY_SAMPLES`] commands.
pub fn to_scenario_toml_with(
    mf: &MotionFile,
    name: &str,
    file: &str,
    opts: &ImportOptions,
    cancel: &CancelToken,
) -> Result<String, GisError> {
    if !opts.limits.is_valid() {
        return Err(GisError::Limits(
            "the three limits must be finite numbers > 0".into(),
        ));
    }
    let dt = 1.0 / opts.rate_hz;
    for (c, &line) in mf.commands.iter().zip(&mf.lines) {
        let n = c.duration_s / dt;
        if n.round() < 1.0 || (n - n.round()).abs() > 1e-6 * n.max(1.0) {
            return Err(GisError::Invalid {
                file: file.to_string(),
                line,
                column: 8,
                message: format!(
                    "duration {} s is not a whole number of IMU samples at {} Hz",
                    c.duration_s, opts.rate_hz
                ),
            });
        }
    }
    // durations as the scenario parser takes them: whole samples
    let commands: Vec<BodyCommand> = mf
        .commands
        .iter()
        .map(|c| BodyCommand {
            duration_s: (c.duration_s / dt).round() * dt,
            ..*c
        })
        .collect();
    let body = BodyMotion::compile_with(mf.start, &commands, opts.limits, dt, cancel)?;
    let g = |x: f64| fmt_f64(x);
    let mut s = String::new();
    let [a, aa, ar] = opts.limits.to_mode();
    let _ = writeln!(s, "# imported from the gnss-ins-sim motion file {file}");
    let _ = writeln!(s, "name = {}", toml_str(name));
    let _ = writeln!(
        s,
        "description = {}",
        toml_str(&format!(
            "gnss-ins-sim motion file {file}, mode = [{a}, {aa}, {ar}]"
        ))
    );
    let _ = writeln!(s, "vehicle = \"free\"\n");
    let _ = writeln!(s, "[start]");
    let _ = writeln!(s, "lat_deg = {}", g(mf.lat_deg));
    let _ = writeln!(s, "lon_deg = {}", g(mf.lon_deg));
    let _ = writeln!(s, "h_m = {}", g(mf.h_m));
    let ini = mf.raw.first().copied().unwrap_or([0.0; COLUMNS]);
    let _ = writeln!(s, "yaw_deg = {}", g(ini[6]));
    let _ = writeln!(s, "pitch_deg = {}", g(ini[7]));
    let _ = writeln!(s, "roll_deg = {}\n", g(ini[8]));
    let _ = writeln!(s, "[imu]\nrate_hz = {}\n", g(opts.rate_hz));
    let _ = writeln!(s, "[body_motion]");
    let [vx, vy, vz] = mf.start.vel_b;
    let _ = writeln!(
        s,
        "vx_mps = {}\nvy_mps = {}\nvz_mps = {}",
        g(vx),
        g(vy),
        g(vz)
    );
    let _ = writeln!(
        s,
        "max_accel_mps2 = {}\nmax_angular_accel_dps2 = {}\nmax_angular_rate_dps = {}",
        g(a),
        g(aa),
        g(ar)
    );
    let ext: std::collections::HashMap<usize, f64> =
        body.extended.iter().map(|e| (e.index, e.used_s)).collect();
    for (i, (c, &line)) in mf.commands.iter().zip(&mf.lines).enumerate() {
        if (i as u64).is_multiple_of(POLL_EVERY_SAMPLES) {
            cancel.check()?;
        }
        let _ = writeln!(s, "\n[[command]] # line {line}");
        let _ = writeln!(s, "type = {}", c.kind.number());
        let row = mf.raw.get(i + 1).copied().unwrap_or([0.0; COLUMNS]);
        let [y, p, r, x1, x2, x3] = [row[1], row[2], row[3], row[4], row[5], row[6]];
        if c.kind == CommandKind::Rates {
            let _ = writeln!(
                s,
                "yaw_rate_dps = {}\npitch_rate_dps = {}\nroll_rate_dps = {}",
                g(y),
                g(p),
                g(r)
            );
            let _ = writeln!(
                s,
                "ax_mps2 = {}\nay_mps2 = {}\naz_mps2 = {}",
                g(x1),
                g(x2),
                g(x3)
            );
        } else {
            let _ = writeln!(
                s,
                "yaw_deg = {}\npitch_deg = {}\nroll_deg = {}",
                g(y),
                g(p),
                g(r)
            );
            let _ = writeln!(
                s,
                "vx_mps = {}\nvy_mps = {}\nvz_mps = {}",
                g(x1),
                g(x2),
                g(x3)
            );
        }
        let _ = write!(s, "duration_s = {}", g(c.duration_s));
        match ext.get(&i) {
            Some(u) => {
                let _ = writeln!(s, " # the limits need {} s: extended to that", g(*u));
            }
            None => s.push('\n'),
        }
    }
    let out = outages(&body, &mf.gps_visible);
    let _ = writeln!(s, "\n[gnss]");
    let _ = writeln!(s, "# outages from the GPS-visibility column (0 = no GPS)");
    let list: Vec<String> = out
        .iter()
        .map(|[a, b]| format!("[{}, {}]", g(*a), g(*b)))
        .collect();
    let _ = writeln!(s, "outages_s = [{}]", list.join(", "));
    Ok(s)
}

/// Shortest round-trip decimal, always with a decimal point or exponent (a TOML float).
fn fmt_f64(x: f64) -> String {
    let s = format!("{x:?}");
    if s.contains(['.', 'e', 'E']) || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn toml_str(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// Read a motion file and return the scenario TOML ([`to_scenario_toml`]), named after the
/// file stem.
pub fn import_file(path: &Path, opts: &ImportOptions) -> Result<String, GisError> {
    import_file_with(path, opts, &CancelToken::new())
}

/// [`import_file`], polling `cancel` ([`parse_motion_def_with`], [`to_scenario_toml_with`]).
pub fn import_file_with(
    path: &Path,
    opts: &ImportOptions,
    cancel: &CancelToken,
) -> Result<String, GisError> {
    let mf = read_motion_def_with(path, cancel)?;
    let name = path
        .file_stem()
        .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned());
    to_scenario_toml_with(&mf, &name, &path.display().to_string(), opts, cancel)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    const OK: &str = "ini lat (deg),a,b,c,d,e,f,g,h\n32,120,0,0,0,0,0,0,0\ncommand type,a,b,c,d,e,f,g,h\n1,0,0,0,1,0,0,10,0\n2,90,0,0,10,0,0,20,1\n";

    fn bad(text: &str) -> (usize, usize, String) {
        match parse_motion_def(text, "f.csv").unwrap_err() {
            GisError::Invalid {
                line,
                column,
                message,
                ..
            } => (line, column, message),
            e => panic!("{e}"),
        }
    }

    fn at(text: &str) -> (usize, usize) {
        let (l, c, _) = bad(text);
        (l, c)
    }

    #[test]
    fn parses_and_locates_errors() {
        let m = parse_motion_def(OK, "f.csv").unwrap();
        assert_eq!(m.commands.len(), 2);
        assert_eq!(m.gps_visible, vec![false, true]);
        assert_eq!(m.lines, vec![4, 5]);
        assert!(looks_like_motion_def(OK));
        let l = |s: &str| OK.replace("2,90,0,0,10,0,0,20,1", s);
        assert_eq!(bad(&l("2,90,0,0,10,0,0,20")).0, 5);
        assert_eq!(at(&l("2,90,x,0,10,0,0,20,1")), (5, 3));
        assert_eq!(at(&l("2,90,NaN,0,10,0,0,20,1")), (5, 3));
        assert_eq!(at(&l("7,90,0,0,10,0,0,20,1")), (5, 1));
        assert_eq!(at(&l("2.5,90,0,0,10,0,0,20,1")), (5, 1));
        assert_eq!(at(&l("2,90,0,0,10,0,0,0,1")), (5, 8));
        assert_eq!(at(&l("2,90,0,0,10,0,0,-1,1")), (5, 8));
        assert_eq!(at(&l("2,90,0,0,10,0,0,20,2")), (5, 9));
        assert_eq!(bad("ini lat\n1,2\n").0, 3);
        assert!(limits_from_mode([1.0, 0.0, 2.0]).is_err());
        assert!(limits_from_mode([1.0, 0.5, f64::NAN]).is_err());
        assert!(limits_from_mode([-1.0, 0.5, 2.0]).is_err());
    }
}
