//! One column-map mechanism for every tabular input (IMU, GNSS, reference/truth, and the
//! aiding sensors' files to come): the text form `quantity_unit=COLUMN,…` of `--columns`,
//! the unit suffixes, the axis map and the settings a map may carry, parsed in one place
//! (docs/own-data.md §"The map").
//!
//! * A **column key** is a quantity and a unit suffix, `gyro_x_dps`, `t_ms`, `lat_deg`,
//!   `accel_z_mps_inc` (a velocity increment); `COLUMN` is the file's column name or its
//!   1-based index (a field made only of digits is an index).
//! * A **setting** is one of [`SETTINGS`]: `axes=x:+y,y:+x,z:-z` (body FRD axis = ± sensor
//!   axis; a proper rotation only), `mount_deg=r:p:y` (the mounting rotation `C_s^b`),
//!   `time=relative|gps-sow|unix`, `yaw=ned|enu|enu-east`, `delim=auto|comma|whitespace|semicolon`,
//!   `header=auto|yes|no`, `rates=trapezoid|hold`.
//!
//! Units ([`UNITS`]): angle `_rad`/`_deg`; angular rate `_radps` (`_rps`)/`_dps`/`_dph`;
//! specific force `_mps2`/`_g`/`_mg` (g = [`G0`] unless the profile gives another);
//! time `_s`/`_ms`/`_us`/`_ns`; length `_m`; speed `_mps`; increments `_rad_inc`/`_deg_inc`
//! (angle) and `_mps_inc` (velocity); magnetic field `_ut`/`_nt`/`_gauss` (aiding files, in µT).
//! The sdins header spellings `dtheta_x_rad` and
//! `dv_x_mps` are increments too.

use sdins_core::math::{c_b_n_from_euler, Euler, Mat3};
use std::fmt;
use std::path::PathBuf;

/// Standard gravity g0 \[m/s²\] of the `_g` and `_mg` suffixes (the project's g0).
pub const G0: f64 = 9.80665;
/// One degree \[rad\].
pub const DEG: f64 = core::f64::consts::PI / 180.0;

/// What a unit measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Dim {
    /// time
    Time,
    /// angle (attitude, latitude, longitude)
    Angle,
    /// angular rate
    Rate,
    /// specific force
    Accel,
    /// angle increment over a sample
    AngleInc,
    /// velocity increment over a sample
    VelInc,
    /// length
    Length,
    /// speed
    Speed,
    /// a count without unit (the GPS week)
    Count,
    /// magnetic flux density (µT is the base: `to_si` gives µT)
    Field,
}

/// One unit suffix: its spelling, what it measures and its factor to SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unit {
    /// the suffix without the leading `_` (`dps`, `rad_inc`, …)
    pub suffix: &'static str,
    /// what it measures
    pub dim: Dim,
    /// SI value of one unit (rad, rad/s, m/s², s, m, m/s); `_g`/`_mg` are multiplied by the
    /// profile's g instead of [`G0`] when one is given
    pub to_si: f64,
    /// decimal exponent of a time unit (s 0, ms 3, µs 6, ns 9): times are shifted in the
    /// text, so that integer stamps stay exact (no f64 rounding above 2^53)
    pub time_exp10: u32,
}

const fn u(suffix: &'static str, dim: Dim, to_si: f64) -> Unit {
    Unit {
        suffix,
        dim,
        to_si,
        time_exp10: 0,
    }
}
const fn t(suffix: &'static str, exp: u32) -> Unit {
    Unit {
        suffix,
        dim: Dim::Time,
        to_si: 1.0,
        time_exp10: exp,
    }
}

/// Every unit suffix (one list for every input kind and for sensor-model files).
pub const UNITS: [Unit; 22] = [
    t("s", 0),
    t("ms", 3),
    t("us", 6),
    t("ns", 9),
    u("rad_inc", Dim::AngleInc, 1.0),
    u("deg_inc", Dim::AngleInc, DEG),
    u("mps_inc", Dim::VelInc, 1.0),
    u("rad", Dim::Angle, 1.0),
    u("deg", Dim::Angle, DEG),
    u("radps", Dim::Rate, 1.0),
    u("rps", Dim::Rate, 1.0),
    u("dps", Dim::Rate, DEG),
    u("dph", Dim::Rate, DEG / 3600.0),
    u("mps2", Dim::Accel, 1.0),
    u("g", Dim::Accel, G0),
    u("mg", Dim::Accel, 1e-3 * G0),
    u("m", Dim::Length, 1.0),
    u("mps", Dim::Speed, 1.0),
    u("", Dim::Count, 1.0),
    u("ut", Dim::Field, 1.0),
    u("nt", Dim::Field, 1e-3),
    u("gauss", Dim::Field, 100.0),
];

/// Which kind of input a map is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum InputKind {
    /// IMU record
    Imu,
    /// GNSS solutions
    Gnss,
    /// reference (truth) trajectory
    Reference,
    /// an aiding sensor's record (barometer, odometer, magnetometer, dual antenna, body
    /// velocity)
    Aiding,
}

impl InputKind {
    /// Name in messages and profile tables (`imu`, `gnss`, `reference`).
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Imu => "imu",
            InputKind::Gnss => "gnss",
            InputKind::Reference => "reference",
            InputKind::Aiding => "aiding",
        }
    }
}

/// Quantities and the dimensions their unit may have, by input kind.
fn quantities(kind: InputKind) -> &'static [(&'static str, &'static [Dim])] {
    const TIME: (&str, &[Dim]) = ("t", &[Dim::Time]);
    const WEEK: (&str, &[Dim]) = ("week", &[Dim::Count]);
    const G: &[Dim] = &[Dim::Rate, Dim::AngleInc];
    const A: &[Dim] = &[Dim::Accel, Dim::VelInc];
    const ANG: &[Dim] = &[Dim::Angle];
    const LEN: &[Dim] = &[Dim::Length];
    const SPD: &[Dim] = &[Dim::Speed];
    match kind {
        InputKind::Imu => &[
            TIME,
            WEEK,
            ("gyro_x", G),
            ("gyro_y", G),
            ("gyro_z", G),
            ("accel_x", A),
            ("accel_y", A),
            ("accel_z", A),
            ("dtheta_x", &[Dim::Angle]),
            ("dtheta_y", &[Dim::Angle]),
            ("dtheta_z", &[Dim::Angle]),
            ("dv_x", &[Dim::Speed]),
            ("dv_y", &[Dim::Speed]),
            ("dv_z", &[Dim::Speed]),
        ],
        InputKind::Gnss => &[
            TIME,
            WEEK,
            ("lat", ANG),
            ("lon", ANG),
            ("h", LEN),
            ("alt_msl", LEN),
            ("undulation", LEN),
            ("sigma_n", LEN),
            ("sigma_e", LEN),
            ("sigma_d", LEN),
            ("sigma_u", LEN),
            ("v_n", SPD),
            ("v_e", SPD),
            ("v_d", SPD),
            ("v_u", SPD),
            ("sigma_vn", SPD),
            ("sigma_ve", SPD),
            ("sigma_vd", SPD),
            ("sigma_vu", SPD),
        ],
        InputKind::Aiding => &[
            TIME,
            WEEK,
            ("h", LEN),
            ("speed", SPD),
            ("v_x", SPD),
            ("v_y", SPD),
            ("v_z", SPD),
            ("m_x", &[Dim::Field]),
            ("m_y", &[Dim::Field]),
            ("m_z", &[Dim::Field]),
            ("az", ANG),
            ("el", ANG),
        ],
        InputKind::Reference => &[
            TIME,
            WEEK,
            ("lat", ANG),
            ("lon", ANG),
            ("h", LEN),
            ("alt_msl", LEN),
            ("undulation", LEN),
            ("roll", ANG),
            ("pitch", ANG),
            ("yaw", ANG),
            ("v_n", SPD),
            ("v_e", SPD),
            ("v_d", SPD),
            ("v_u", SPD),
        ],
    }
}

/// The setting names a map may carry besides its columns.
pub const SETTINGS: [&str; 7] = [
    "axes",
    "mount_deg",
    "time",
    "yaw",
    "delim",
    "header",
    "rates",
];

/// Where a map came from, for messages: an option or a profile file and line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MapOrigin {
    /// a command-line option (`--columns`) or a Python argument (`columns=`)
    Option(String),
    /// a profile file and the 1-based line of the key
    Profile {
        /// the profile
        file: PathBuf,
        /// 1-based line
        line: usize,
    },
}

impl fmt::Display for MapOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MapOrigin::Option(o) => f.write_str(o),
            MapOrigin::Profile { file, line } => write!(f, "--profile {}:{line}", file.display()),
        }
    }
}

impl Default for MapOrigin {
    fn default() -> Self {
        MapOrigin::Option("--columns".into())
    }
}

/// Why a column map, a profile or a file read through one was refused.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ColumnsError {
    /// The map itself (or a profile key): names the option or `profile:line`.
    #[error("{origin}: {message}")]
    Map {
        /// where the map came from
        origin: MapOrigin,
        /// what is wrong
        message: String,
    },
    /// A file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// the file
        file: PathBuf,
        /// the cause
        source: std::io::Error,
    },
    /// A row or field of the data file.
    #[error("{}:{line}: {field}: {message}", file.display())]
    Data {
        /// the file
        file: PathBuf,
        /// 1-based line
        line: usize,
        /// the column (or `(row)`, `(header)`)
        field: String,
        /// what is wrong
        message: String,
    },
}

impl ColumnsError {
    pub(crate) fn map(origin: &MapOrigin, message: impl Into<String>) -> Self {
        ColumnsError::Map {
            origin: origin.clone(),
            message: message.into(),
        }
    }
}

/// A column of the file: its header name or its 1-based index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ColumnRef {
    /// by header name
    Name(String),
    /// by 1-based index
    Index(usize),
}

impl fmt::Display for ColumnRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ColumnRef::Name(n) => f.write_str(n),
            ColumnRef::Index(i) => write!(f, "column {i}"),
        }
    }
}

/// One mapped column: the quantity (`gyro_x`, `lat`, `t`), its unit and where it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// the quantity
    pub quantity: &'static str,
    /// its unit
    pub unit: Unit,
    /// the column
    pub column: ColumnRef,
    /// the key as written (`gyro_x_dps`)
    pub key: String,
}

/// Time base of a time column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum TimeKind {
    /// relative seconds on the file's own clock (kept as given)
    #[default]
    Relative,
    /// GPS seconds of week (a week column, `gps_week`, or none: the week is unknown)
    GpsSow,
    /// UNIX time (UTC), converted to GPST with the leap-second table
    Unix,
}

impl TimeKind {
    fn parse(s: &str) -> Option<Self> {
        match s {
            "relative" => Some(TimeKind::Relative),
            "gps-sow" => Some(TimeKind::GpsSow),
            "unix" => Some(TimeKind::Unix),
            _ => None,
        }
    }
    /// Spelling in maps and profiles.
    pub fn name(self) -> &'static str {
        match self {
            TimeKind::Relative => "relative",
            TimeKind::GpsSow => "gps-sow",
            TimeKind::Unix => "unix",
        }
    }
}

/// Yaw (attitude) convention of a reference file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum YawConvention {
    /// NED navigation frame, FRD body, Z-Y-X Euler angles, yaw clockwise from north (sdins)
    #[default]
    Ned,
    /// ENU frame, RFU body, PSINS's Z-X-Y angles: yaw counter-clockwise from north
    Enu,
    /// ENU frame, FLU body, Z-Y-X angles, yaw counter-clockwise from east (KITTI/OXTS)
    EnuEast,
}

impl YawConvention {
    fn parse(s: &str) -> Option<Self> {
        match s {
            "ned" => Some(YawConvention::Ned),
            "enu" => Some(YawConvention::Enu),
            "enu-east" => Some(YawConvention::EnuEast),
            _ => None,
        }
    }
    /// Spelling in maps and profiles.
    pub fn name(self) -> &'static str {
        match self {
            YawConvention::Ned => "ned",
            YawConvention::Enu => "enu",
            YawConvention::EnuEast => "enu-east",
        }
    }
}

/// Field delimiter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Delimiter {
    /// comma if the header (or first data line) has one, else semicolon if it has one,
    /// else whitespace
    #[default]
    Auto,
    /// `,`
    Comma,
    /// runs of spaces and tabs
    Whitespace,
    /// `;`
    Semicolon,
}

/// Whether the first non-comment line is a header.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum HeaderMode {
    /// a header when the first non-comment line has a field that is not a number
    #[default]
    Auto,
    /// always a header
    Yes,
    /// no header (columns by index only)
    No,
}

/// How angular rates and specific forces become increments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum RateRule {
    /// `Δθ_k = ½(ω_{k−1} + ω_k)(t_k − t_{k−1})` (rates tagged at the sample end, first
    /// sample dropped): second order in the rate's time variation, loses coning
    #[default]
    Trapezoid,
    /// `Δθ_k = ω_k·δt` with δt the mean interval (every sample kept, the rate held over
    /// the interval ending at its stamp): what the sdins and NaveGo rate readers do
    Hold,
}

/// Parse an axis map `x:+y,y:+x,z:-z` (body FRD axis = ± sensor axis) into `C_s^b`;
/// refused unless it is a proper rotation (det = +1).
pub fn parse_axes(text: &str, origin: &MapOrigin) -> Result<Mat3, ColumnsError> {
    let bad = |m: String| ColumnsError::map(origin, format!("axes=`{text}`: {m}"));
    let mut c = Mat3::zeros();
    let mut seen_body = [false; 3];
    let mut seen_sensor = [false; 3];
    let axis = |ch: char| match ch {
        'x' => Some(0),
        'y' => Some(1),
        'z' => Some(2),
        _ => None,
    };
    for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let cs: Vec<char> = item.chars().collect();
        let parsed = match cs.as_slice() {
            [b, ':', s, a] if *s == '+' || *s == '-' => {
                axis(*b).zip(axis(*a)).map(|(b, a)| (b, a, *s == '-'))
            }
            [b, ':', a] => axis(*b).zip(axis(*a)).map(|(b, a)| (b, a, false)),
            _ => None,
        };
        let Some((b, s, neg)) = parsed else {
            return Err(bad(format!(
                "`{item}`: expected BODY:±SENSOR with axes x, y, z (for example `x:+y`)"
            )));
        };
        if seen_body[b] {
            return Err(bad(format!("body axis {} given twice", ["x", "y", "z"][b])));
        }
        if seen_sensor[s] {
            return Err(bad(format!(
                "sensor axis {} used twice",
                ["x", "y", "z"][s]
            )));
        }
        seen_body[b] = true;
        seen_sensor[s] = true;
        c[(b, s)] = if neg { -1.0 } else { 1.0 };
    }
    if seen_body.iter().any(|s| !s) {
        return Err(bad("give all three body axes x, y, z".into()));
    }
    if c.determinant() < 0.0 {
        return Err(bad(
            "this map is a reflection (determinant −1), not a rotation: angular rate is an axial vector, so one reflection cannot be applied to both the gyro and the accelerometer triad; flip one more axis (a left-handed logger frame needs its gyro signs checked against a known turn)".into(),
        ));
    }
    Ok(c)
}

/// `C_s^b` of a mounting rotation given as roll, pitch, yaw \[deg\] of the sensor frame
/// in the body frame (Z-Y-X, as attitude angles): `v_b = C_s^b v_s`.
pub fn mount_c_s_b(rpy_deg: [f64; 3]) -> Mat3 {
    c_b_n_from_euler(&Euler::new(
        rpy_deg[0] * DEG,
        rpy_deg[1] * DEG,
        rpy_deg[2] * DEG,
    ))
}

/// A parsed column map for one input kind: the columns and the settings given with them.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnMap {
    /// the input kind
    pub kind: InputKind,
    /// the mapped columns, in the order given
    pub columns: Vec<Column>,
    /// axis map (IMU), `C_s^b`
    pub axes: Option<Mat3>,
    /// mounting rotation roll, pitch, yaw \[deg\] (IMU)
    pub mount_deg: Option<[f64; 3]>,
    /// time base
    pub time: Option<TimeKind>,
    /// yaw convention (reference)
    pub yaw: Option<YawConvention>,
    /// delimiter
    pub delim: Option<Delimiter>,
    /// header line
    pub header: Option<HeaderMode>,
    /// rate integration (IMU)
    pub rates: Option<RateRule>,
    /// where the map came from
    pub origin: MapOrigin,
}

/// Split a key into its quantity and unit for `kind`.
pub fn parse_key(kind: InputKind, key: &str) -> Option<(&'static str, Unit)> {
    for &(q, dims) in quantities(kind) {
        let rest = if key == q {
            Some("")
        } else {
            key.strip_prefix(q).and_then(|r| r.strip_prefix('_'))
        };
        let Some(rest) = rest else { continue };
        if let Some(unit) = UNITS
            .iter()
            .find(|un| un.suffix == rest && dims.contains(&un.dim))
        {
            return Some((q, *unit));
        }
    }
    None
}

/// The keys a kind accepts, for messages: `t_s|t_ms|…`.
pub fn vocabulary(kind: InputKind) -> String {
    quantities(kind)
        .iter()
        .map(|(q, dims)| {
            let units: Vec<&str> = UNITS
                .iter()
                .filter(|un| dims.contains(&un.dim))
                .map(|un| un.suffix)
                .collect();
            if units == [""] {
                q.to_string()
            } else {
                format!("{q}_{{{}}}", units.join("|"))
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn column_ref(v: &str) -> ColumnRef {
    if !v.is_empty() && v.bytes().all(|b| b.is_ascii_digit()) {
        ColumnRef::Index(v.parse().unwrap_or(0))
    } else {
        ColumnRef::Name(v.trim_matches('"').to_string())
    }
}

impl ColumnMap {
    /// An empty map of `kind` (settings unset).
    pub fn empty(kind: InputKind, origin: MapOrigin) -> Self {
        Self {
            kind,
            columns: Vec::new(),
            axes: None,
            mount_deg: None,
            time: None,
            yaw: None,
            delim: None,
            header: None,
            rates: None,
            origin,
        }
    }

    /// Parse the text form `KEY=COLUMN,…` (with settings, see the module docs).
    pub fn parse(kind: InputKind, text: &str, origin: MapOrigin) -> Result<Self, ColumnsError> {
        let mut m = Self::empty(kind, origin);
        m.merge_text(text)?;
        Ok(m)
    }

    /// Add the items of a text form to this map (a key given twice is an error).
    pub fn merge_text(&mut self, text: &str) -> Result<(), ColumnsError> {
        let origin = self.origin.clone();
        let bad = |m: String| ColumnsError::map(&origin, m);
        // `axes=x:+y,y:+x,z:-z` continues over the next two comma-separated items
        let mut items: Vec<String> = Vec::new();
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let is_axis_tail = !item.contains('=')
                && item.contains(':')
                && items.last().is_some_and(|l| l.starts_with("axes="));
            match items.last_mut() {
                Some(last) if is_axis_tail => {
                    last.push(',');
                    last.push_str(item);
                }
                _ => items.push(item.to_string()),
            }
        }
        for item in &items {
            let Some((k, v)) = item.split_once('=') else {
                return Err(bad(format!("`{item}`: expected KEY=COLUMN")));
            };
            let (k, v) = (k.trim(), v.trim());
            if v.is_empty() {
                return Err(bad(format!("`{item}`: empty value")));
            }
            self.set(k, v)?;
        }
        Ok(())
    }

    /// Set one key (a column key or a setting).
    pub fn set(&mut self, k: &str, v: &str) -> Result<(), ColumnsError> {
        let origin = self.origin.clone();
        let bad = |m: String| ColumnsError::map(&origin, m);
        let twice = || bad(format!("`{k}` given twice"));
        let choice = |what: &str, ok: &[&str]| {
            bad(format!(
                "{k}=`{v}`: unknown {what}, expected one of {}",
                ok.join(", ")
            ))
        };
        match k {
            "axes" => {
                if self.axes.is_some() {
                    return Err(twice());
                }
                if self.kind != InputKind::Imu {
                    return Err(bad("`axes` applies to IMU maps only".into()));
                }
                self.axes = Some(parse_axes(v, &origin)?);
            }
            "mount_deg" => {
                if self.mount_deg.is_some() {
                    return Err(twice());
                }
                if self.kind != InputKind::Imu {
                    return Err(bad("`mount_deg` applies to IMU maps only".into()));
                }
                let parts: Vec<&str> = v.split(':').map(str::trim).collect();
                let nums: Vec<f64> = parts.iter().filter_map(|p| p.parse().ok()).collect();
                if parts.len() != 3 || nums.len() != 3 || nums.iter().any(|x| !x.is_finite()) {
                    return Err(bad(format!(
                        "mount_deg=`{v}`: expected ROLL:PITCH:YAW in degrees (three finite numbers)"
                    )));
                }
                self.mount_deg = Some([nums[0], nums[1], nums[2]]);
            }
            "time" => {
                if self.time.is_some() {
                    return Err(twice());
                }
                self.time = Some(
                    TimeKind::parse(v)
                        .ok_or_else(|| choice("time base", &["relative", "gps-sow", "unix"]))?,
                );
            }
            "yaw" => {
                if self.yaw.is_some() {
                    return Err(twice());
                }
                if self.kind != InputKind::Reference {
                    return Err(bad(
                        "`yaw` (the attitude convention) applies to reference maps only".into(),
                    ));
                }
                self.yaw = Some(
                    YawConvention::parse(v)
                        .ok_or_else(|| choice("yaw convention", &["ned", "enu", "enu-east"]))?,
                );
            }
            "delim" => {
                if self.delim.is_some() {
                    return Err(twice());
                }
                self.delim = Some(match v {
                    "auto" => Delimiter::Auto,
                    "comma" | "," => Delimiter::Comma,
                    "whitespace" | "space" | "tab" => Delimiter::Whitespace,
                    "semicolon" | ";" => Delimiter::Semicolon,
                    _ => {
                        return Err(choice(
                            "delimiter",
                            &["auto", "comma", "whitespace", "semicolon"],
                        ))
                    }
                });
            }
            "header" => {
                if self.header.is_some() {
                    return Err(twice());
                }
                self.header = Some(match v {
                    "auto" => HeaderMode::Auto,
                    "yes" | "true" => HeaderMode::Yes,
                    "no" | "false" => HeaderMode::No,
                    _ => return Err(choice("header mode", &["auto", "yes", "no"])),
                });
            }
            "rates" => {
                if self.rates.is_some() {
                    return Err(twice());
                }
                if self.kind != InputKind::Imu {
                    return Err(bad("`rates` applies to IMU maps only".into()));
                }
                self.rates = Some(match v {
                    "trapezoid" => RateRule::Trapezoid,
                    "hold" => RateRule::Hold,
                    _ => return Err(choice("rate rule", &["trapezoid", "hold"])),
                });
            }
            _ => {
                let Some((quantity, unit)) = parse_key(self.kind, k) else {
                    return Err(bad(format!(
                        "unknown key `{k}` for a {} file: expected a setting ({}) or one of {}",
                        self.kind.name(),
                        SETTINGS.join(", "),
                        vocabulary(self.kind)
                    )));
                };
                if let Some(c) = self.columns.iter().find(|c| c.quantity == quantity) {
                    return Err(if c.key == k {
                        twice()
                    } else {
                        bad(format!(
                            "`{k}` and `{}` map the same quantity: give one",
                            c.key
                        ))
                    });
                }
                let column = column_ref(v);
                if column == ColumnRef::Index(0) {
                    return Err(bad(format!("{k}={v}: column indices start at 1")));
                }
                self.columns.push(Column {
                    quantity,
                    unit,
                    column,
                    key: k.to_string(),
                });
            }
        }
        Ok(())
    }

    /// The column of `quantity`, if mapped.
    pub fn get(&self, quantity: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.quantity == quantity)
    }

    /// The column of `quantity`, or an error naming the keys that would give it.
    pub fn need(&self, quantity: &str, hint: &str) -> Result<&Column, ColumnsError> {
        self.get(quantity).ok_or_else(|| {
            ColumnsError::map(
                &self.origin,
                format!("missing `{quantity}_UNIT=COLUMN` ({hint})"),
            )
        })
    }

    /// `C_s^b` of the axis map or the mounting rotation (identity when neither is given;
    /// refused when both are).
    pub fn c_s_b(&self) -> Result<Mat3, ColumnsError> {
        match (self.axes, self.mount_deg) {
            (Some(_), Some(_)) => Err(ColumnsError::map(
                &self.origin,
                "give `axes` or `mount_deg`, not both (compose them into one mounting rotation)",
            )),
            (Some(c), None) => Ok(c),
            (None, Some(r)) => Ok(mount_c_s_b(r)),
            (None, None) => Ok(Mat3::identity()),
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn keys_split_into_quantity_and_unit() {
        let k = |s| parse_key(InputKind::Imu, s).map(|(q, u)| (q, u.suffix));
        assert_eq!(k("gyro_x_dps"), Some(("gyro_x", "dps")));
        assert_eq!(k("gyro_z_rad_inc"), Some(("gyro_z", "rad_inc")));
        assert_eq!(k("accel_y_mg"), Some(("accel_y", "mg")));
        assert_eq!(k("accel_y_mps_inc"), Some(("accel_y", "mps_inc")));
        assert_eq!(k("dtheta_x_rad"), Some(("dtheta_x", "rad")));
        assert_eq!(k("t_ns"), Some(("t", "ns")));
        assert_eq!(k("week"), Some(("week", "")));
        assert_eq!(k("gyro_x_mps2"), None);
        assert_eq!(k("gyro_x"), None);
        let g = |s| parse_key(InputKind::Gnss, s).map(|(q, u)| (q, u.suffix));
        assert_eq!(g("alt_msl_m"), Some(("alt_msl", "m")));
        assert_eq!(g("sigma_vn_mps"), Some(("sigma_vn", "mps")));
        assert_eq!(g("roll_deg"), None);
    }

    #[test]
    fn axes_rotation_and_reflection() {
        let o = MapOrigin::default();
        let c = parse_axes("x:+y,y:+x,z:-z", &o).unwrap();
        assert_eq!(c.determinant(), 1.0);
        let v = c * sdins_core::math::Vec3::new(1.0, 2.0, 3.0);
        assert_eq!([v.x, v.y, v.z], [2.0, 1.0, -3.0]);
        let e = parse_axes("x:+x,y:+y,z:-z", &o).unwrap_err().to_string();
        assert!(
            e.starts_with("--columns: axes=") && e.contains("reflection"),
            "{e}"
        );
        for (bad, what) in [
            ("x:+y,y:+y,z:+z", "used twice"),
            ("x:+y,x:+x,z:+z", "given twice"),
            ("x:+y,y:+x", "all three"),
            ("x:+w,y:+x,z:+z", "BODY:±SENSOR"),
        ] {
            let e = parse_axes(bad, &o).unwrap_err().to_string();
            assert!(e.contains(what), "{bad}: {e}");
        }
    }

    #[test]
    fn maps_parse_with_settings_and_refuse_mistakes() {
        let m = ColumnMap::parse(
            InputKind::Imu,
            "t_ms=time,gyro_x_dps=gx,gyro_y_dps=2,gyro_z_dps=gz,accel_x_g=ax,accel_y_g=ay,accel_z_g=az,axes=x:+y,y:+x,z:-z,delim=whitespace,time=unix",
            MapOrigin::default(),
        )
        .unwrap();
        assert_eq!(m.columns.len(), 7);
        assert_eq!(m.get("gyro_y").unwrap().column, ColumnRef::Index(2));
        assert!(m.axes.is_some());
        assert_eq!(m.delim, Some(Delimiter::Whitespace));
        assert_eq!(m.time, Some(TimeKind::Unix));
        for (text, what) in [
            ("t_s=a,t_ms=b", "map the same quantity"),
            ("t_s=a,t_s=b", "twice"),
            ("speed_mps=a", "unknown key `speed_mps`"),
            ("t_s", "KEY=COLUMN"),
            ("t_s=", "empty value"),
            ("t_s=0", "start at 1"),
            ("time=utc", "unknown time base"),
            ("yaw=ned", "reference maps only"),
            ("axes=x:+x,y:+y,z:+z,mount_deg=1:2", "ROLL:PITCH:YAW"),
        ] {
            let e = ColumnMap::parse(InputKind::Imu, text, MapOrigin::default())
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with("--columns: ") && e.contains(what),
                "{text}: {e}"
            );
        }
        let both = ColumnMap::parse(
            InputKind::Imu,
            "axes=x:+x,y:+y,z:+z,mount_deg=0:0:90",
            MapOrigin::default(),
        )
        .unwrap();
        assert!(both.c_s_b().is_err());
    }

    #[test]
    fn mount_rotation_is_proper() {
        let c = mount_c_s_b([10.0, -20.0, 135.0]);
        assert!((c.determinant() - 1.0).abs() < 1e-15);
        let c = mount_c_s_b([0.0, 0.0, 90.0]);
        let v = c * sdins_core::math::Vec3::new(1.0, 0.0, 0.0);
        assert!((v.y - 1.0).abs() < 1e-15);
    }
}
