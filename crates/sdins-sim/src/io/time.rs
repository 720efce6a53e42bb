//! Time bases of tabular inputs and the one clock of a run.
//!
//! A time column is relative seconds (the file's own clock), GPS seconds of week (with a
//! week column, a given week, or none), or UNIX time (UTC, converted to GPST with the
//! leap-second table of the maintained `hifitime` crate). Every input of a run is put on
//! one clock ([`RunClock`]): GPST whole seconds at an origin (the first IMU epoch's whole
//! second) plus f64 seconds after it, so that stamps of 1.4e9 s keep their microseconds and
//! integer ns/µs stamps (parsed in the text, never through f64, exact above 2^53) stay
//! exact. Relative files keep their own seconds (origin 0).
//!
//! A time field is split in its text into whole seconds (i64) and the decimal digits after
//! the point; the time after the origin is the decimal `(whole − origin).digits` read once
//! (correctly rounded), so a relative file's `t_s` is read to the same f64 as by the
//! canonical readers. A constant offset is added after that.

use crate::io::columns::TimeKind;

/// The GPS epoch 1980-01-06 00:00:00 in UNIX seconds (UTC; no leap seconds before it
/// count: GPS − UTC was 0 then).
pub const GPS_EPOCH_UNIX_S: i64 = 315_964_800;
/// Seconds in a GPS week.
pub const WEEK_S: i64 = 604_800;

/// What the seconds of a run's clock count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ClockScale {
    /// a file's own seconds (relative time): every input of the run must share them
    File,
    /// GPS seconds of week with the week unknown (week 0 assumed; rollovers unwrapped)
    GpsWeekUnknown,
    /// GPST: seconds since 1980-01-06 00:00:00 GPST
    Gpst,
}

impl ClockScale {
    /// Name in messages and run.toml.
    pub fn name(self) -> &'static str {
        match self {
            ClockScale::File => "file seconds",
            ClockScale::GpsWeekUnknown => "GPS seconds of week (week unknown)",
            ClockScale::Gpst => "GPST",
        }
    }
}

/// The one clock of a run: `t_s` of every input counts seconds after `origin_s` whole
/// seconds of `scale`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunClock {
    /// what the seconds count
    pub scale: ClockScale,
    /// whole seconds of `scale` at `t_s = 0` (0 for file seconds)
    pub origin_s: i64,
}

/// How a file's time column is read.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TimeSpec {
    /// the time base
    pub kind: TimeKind,
    /// GPS week of a seconds-of-week file without week column
    pub gps_week: Option<u32>,
    /// the file has a GPS week column (the week is then known row by row)
    pub week_column: bool,
    /// constant added to every time \[s\] (the file's clock error: t_gpst = t_file + offset)
    pub offset_s: f64,
}

/// A time field split in its text: whole seconds and the decimal digits after the point
/// (`None` digits: not a plain decimal, read through f64).
#[derive(Clone, Debug, PartialEq)]
pub struct Stamp {
    /// whole seconds (floor)
    pub whole: i64,
    /// the decimal digits after the point, or the fraction in [0, 1) when the text was
    /// not a plain decimal (exponent form, negative)
    pub frac: Frac,
}

/// Fraction of a [`Stamp`].
#[derive(Clone, Debug, PartialEq)]
pub enum Frac {
    /// decimal digits after the point (exact)
    Digits(String),
    /// a fraction in [0, 1) (rounded)
    Value(f64),
}

/// Split `text`, a time in units of 10^−`exp10` s, into whole seconds and a fraction.
pub fn parse_stamp(text: &str, exp10: u32) -> Result<Stamp, String> {
    let s = text.trim();
    let plain = !s.is_empty()
        && s.bytes().all(|b| b.is_ascii_digit() || b == b'.')
        && s.bytes().filter(|&b| b == b'.').count() <= 1
        && s.bytes().any(|b| b.is_ascii_digit());
    if plain {
        let (int, frac) = s.split_once('.').unwrap_or((s, ""));
        let mut digits = String::with_capacity(int.len() + frac.len() + exp10 as usize);
        digits.push_str(int);
        digits.push_str(frac);
        // the point moves exp10 places to the left
        let point = int.len() as i64 - i64::from(exp10);
        let (w, f) = if point <= 0 {
            (String::new(), "0".repeat((-point) as usize) + &digits)
        } else {
            let p = point as usize;
            (digits[..p].to_string(), digits[p..].to_string())
        };
        let w = w.trim_start_matches('0');
        let whole = if w.is_empty() {
            0
        } else {
            w.parse::<i64>()
                .map_err(|_| format!("`{text}`: the time does not fit in 64-bit seconds"))?
        };
        return Ok(Stamp {
            whole,
            frac: Frac::Digits(f.trim_end_matches('0').to_string()),
        });
    }
    let v: f64 = s.parse().map_err(|_| format!("`{text}` is not a number"))?;
    if !v.is_finite() {
        return Err(format!("`{text}` is not finite"));
    }
    let v = v / 10f64.powi(exp10 as i32);
    if v.abs() > 9.0e15 {
        return Err(format!("`{text}`: the time does not fit in 64-bit seconds"));
    }
    let whole = v.floor();
    Ok(Stamp {
        whole: whole as i64,
        frac: Frac::Value(v - whole),
    })
}

/// GPS − UTC \[s\] at a UTC instant given in whole UNIX seconds, from `hifitime`'s
/// leap-second table (IERS; 18 s since 2017-01-01).
pub fn gps_minus_utc_at_unix_s(unix_s: i64) -> i64 {
    let e = hifitime::Epoch::from_unix_seconds(unix_s as f64);
    let gpst = e.to_gpst_seconds();
    (gpst - (unix_s - GPS_EPOCH_UNIX_S) as f64).round() as i64
}

/// Puts the rows of one file on the run's clock, row by row.
#[derive(Clone, Debug)]
pub struct TimeConverter {
    spec: TimeSpec,
    scale: ClockScale,
    origin: Option<i64>,
    weeks_added: i64,
    prev_sow: Option<i64>,
    leap_cache: Option<(i64, i64)>,
    /// week rollovers unwrapped (GPS seconds of week without week column)
    pub rollovers: usize,
}

impl TimeConverter {
    /// A converter for `spec`; `clock` the run's clock when another input set it (its
    /// scale must match), else the first row sets it.
    pub fn new(spec: &TimeSpec, clock: Option<&RunClock>) -> Result<Self, String> {
        if !spec.offset_s.is_finite() {
            return Err(format!("time offset {} s is not finite", spec.offset_s));
        }
        let scale = match spec.kind {
            TimeKind::Relative => ClockScale::File,
            TimeKind::GpsSow if spec.gps_week.is_none() && !spec.week_column => {
                ClockScale::GpsWeekUnknown
            }
            TimeKind::GpsSow | TimeKind::Unix => ClockScale::Gpst,
        };
        if let Some(c) = clock {
            if c.scale != scale {
                let hint = match (c.scale, scale) {
                    (ClockScale::GpsWeekUnknown, _) | (_, ClockScale::GpsWeekUnknown) => {
                        " (give the GPS week: a week column or --gps-week)"
                    }
                    _ => " (state each file's time base: time=relative|gps-sow|unix, with an offset where the clocks differ)",
                };
                return Err(format!(
                    "the time base `{}` ({}) does not match the run's clock ({}){hint}",
                    spec.kind.name(),
                    scale.name(),
                    c.scale.name()
                ));
            }
        }
        Ok(Self {
            spec: *spec,
            scale,
            origin: clock.map(|c| c.origin_s),
            weeks_added: 0,
            prev_sow: None,
            leap_cache: None,
            rollovers: 0,
        })
    }

    /// The run's clock (after the first row).
    pub fn clock(&self) -> Option<RunClock> {
        self.origin.map(|origin_s| RunClock {
            scale: self.scale,
            origin_s,
        })
    }

    /// One row: the time field's text in units of 10^−`exp10` s and the week column's
    /// value, if any; returns seconds on the run's clock.
    pub fn convert(&mut self, text: &str, exp10: u32, week: Option<f64>) -> Result<f64, String> {
        let st = parse_stamp(text, exp10)?;
        let mut whole = st.whole;
        match self.spec.kind {
            TimeKind::Relative => {}
            TimeKind::GpsSow => {
                if !(-1..=WEEK_S + 1).contains(&whole) {
                    return Err(format!(
                        "{text}: GPS seconds of week outside 0 .. 604800 (is the unit or the time base wrong?)"
                    ));
                }
                let week = match week {
                    Some(w) => {
                        if !(w.fract() == 0.0 && (0.0..=1.0e5).contains(&w)) {
                            return Err(format!(
                                "GPS week {w} is not a whole week number in 0 .. 100000"
                            ));
                        }
                        w as i64
                    }
                    None => {
                        // a drop of more than half a week is a rollover
                        if let Some(p) = self.prev_sow {
                            if whole < p - WEEK_S / 2 {
                                self.weeks_added += 1;
                                self.rollovers += 1;
                            }
                        }
                        self.prev_sow = Some(whole);
                        i64::from(self.spec.gps_week.unwrap_or(0)) + self.weeks_added
                    }
                };
                whole += week * WEEK_S;
            }
            TimeKind::Unix => {
                let day = whole.div_euclid(86_400);
                let leap = match self.leap_cache {
                    Some((d, l)) if d == day => l,
                    _ => {
                        let l = gps_minus_utc_at_unix_s(whole);
                        self.leap_cache = Some((day, l));
                        l
                    }
                };
                whole = whole - GPS_EPOCH_UNIX_S + leap;
            }
        }
        let origin = match self.origin {
            Some(o) => o,
            None => {
                let o = if self.scale == ClockScale::File {
                    0
                } else {
                    whole
                };
                self.origin = Some(o);
                o
            }
        };
        let rel = whole - origin;
        let t = match &st.frac {
            Frac::Digits(d) if d.is_empty() => rel as f64,
            Frac::Digits(d) if rel >= 0 => format!("{rel}.{d}")
                .parse::<f64>()
                .map_err(|_| format!("`{text}` is not a number"))?,
            Frac::Digits(d) => rel as f64 + format!("0.{d}").parse::<f64>().unwrap_or(0.0),
            Frac::Value(f) => rel as f64 + f,
        };
        Ok(t + self.spec.offset_s)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn rel(text: &str, exp: u32) -> f64 {
        let mut c = TimeConverter::new(&TimeSpec::default(), None).unwrap();
        c.convert(text, exp, None).unwrap()
    }

    #[test]
    fn decimal_shift_is_exact() {
        assert_eq!(rel("5", 3), 0.005);
        assert_eq!(rel("12.5", 3), 0.0125);
        assert_eq!(rel("1234567.891", 0), 1234567.891);
        assert_eq!(rel("0.0050000000000000001", 0), 0.005);
        assert_eq!(rel("1500", 6), 0.0015);
        assert_eq!(rel("2.5e3", 3), 2.5);
        // 19-digit ns stamps: exact in i64, the origin taken off in the text
        let mut c = TimeConverter::new(
            &TimeSpec {
                kind: TimeKind::Unix,
                ..TimeSpec::default()
            },
            None,
        )
        .unwrap();
        let a = c.convert("1700000000000000001", 9, None).unwrap();
        let b = c.convert("1700000000000000003", 9, None).unwrap();
        assert_eq!(a, 1e-9);
        assert_eq!(b, 3e-9);
    }

    #[test]
    fn unix_to_gpst_uses_the_leap_seconds() {
        assert_eq!(gps_minus_utc_at_unix_s(GPS_EPOCH_UNIX_S), 0);
        assert_eq!(gps_minus_utc_at_unix_s(1_483_228_800), 18); // 2017-01-01
        assert_eq!(gps_minus_utc_at_unix_s(1_483_228_799), 17);
        // against the project's own table
        for &(y, m, d, l) in crate::io::gnss_file::LEAP_SECONDS.iter() {
            let unix = crate::io::gnss_file::gps_seconds_from_date(y, m, d, 0, 0, 0.0) as i64
                + GPS_EPOCH_UNIX_S;
            assert_eq!(gps_minus_utc_at_unix_s(unix), l as i64, "{y}-{m}-{d}");
        }
        let mut c = TimeConverter::new(
            &TimeSpec {
                kind: TimeKind::Unix,
                ..TimeSpec::default()
            },
            None,
        )
        .unwrap();
        c.convert("1700000000.25", 0, None).unwrap();
        let clock = c.clock().unwrap();
        assert_eq!(clock.scale, ClockScale::Gpst);
        assert_eq!(clock.origin_s, 1_700_000_000 - GPS_EPOCH_UNIX_S + 18);
    }

    #[test]
    fn seconds_of_week_roll_over_and_weeks_count() {
        let spec = TimeSpec {
            kind: TimeKind::GpsSow,
            gps_week: Some(2000),
            week_column: false,
            offset_s: 0.0,
        };
        let mut c = TimeConverter::new(&spec, None).unwrap();
        assert_eq!(c.convert("604799.5", 0, None).unwrap(), 0.5);
        assert_eq!(c.convert("0.5", 0, None).unwrap(), 1.5);
        assert_eq!(c.rollovers, 1);
        assert_eq!(c.clock().unwrap().origin_s, 2000 * WEEK_S + 604_799);
        let mut w = TimeConverter::new(
            &TimeSpec {
                kind: TimeKind::GpsSow,
                ..TimeSpec::default()
            },
            None,
        )
        .unwrap();
        assert_eq!(w.convert("100", 0, Some(2001.0)).unwrap(), 0.0);
        assert!(w.convert("100", 0, Some(2001.5)).is_err());
        assert!(w.convert("700000", 0, Some(2001.0)).is_err());
        // a week-less clock does not mix with GPST
        let e = TimeConverter::new(&TimeSpec::default(), c.clock().as_ref()).unwrap_err();
        assert!(e.contains("does not match"), "{e}");
    }

    #[test]
    fn offsets_add() {
        let spec = TimeSpec {
            offset_s: 0.25,
            ..TimeSpec::default()
        };
        let mut c = TimeConverter::new(&spec, None).unwrap();
        assert_eq!(c.convert("1", 0, None).unwrap(), 1.25);
    }
}
