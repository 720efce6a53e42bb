//! GPS system time as week number and seconds of week.

/// Seconds in a GPS week.
pub const SECONDS_PER_WEEK: f64 = 604_800.0;

/// A GPS system time: continuous week number (counted from 1980-01-06 00:00:00 GPST,
/// not modulo 1024) and seconds of week `sow_s` ∈ [0, 604 800).
///
/// An `f64` second of week resolves 1.2e-10 s at the end of the week (3.5 cm of light
/// travel): times are never differenced to form ranges here, transit times are kept as
/// their own `f64` (resolution 1e-17 s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpsTime {
    /// GPS week number (continuous)
    pub week: i32,
    /// seconds of week \[s\]
    pub sow_s: f64,
}

/// Days from 1970-01-01 to a proleptic Gregorian date (exact integer arithmetic: the
/// era/day-of-era decomposition of the civil calendar).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = if y >= 0 { y } else { y - 399 } / 400;
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Days from 1970-01-01 to the GPS epoch 1980-01-06.
const GPS_EPOCH_DAYS: i64 = 3657;

impl GpsTime {
    /// A GPS time from week and seconds of week, normalised so that `sow_s` ∈ [0, 604 800).
    pub fn new(week: i32, sow_s: f64) -> Self {
        let mut t = GpsTime { week, sow_s };
        t.normalize();
        t
    }

    fn normalize(&mut self) {
        if !self.sow_s.is_finite() {
            return;
        }
        let w = libm::floor(self.sow_s / SECONDS_PER_WEEK);
        if w != 0.0 {
            // saturating: absurd inputs (a corrupted file) give an absurd but valid time,
            // never an overflow
            self.week = self.week.saturating_add(w as i32);
            self.sow_s -= w * SECONDS_PER_WEEK;
        }
    }

    /// The GPS time of a calendar date and time of day given **in GPS time** (RINEX epochs
    /// are in GPS time for GPS files; no leap seconds are involved). Month 1–12, day 1–31;
    /// no range check beyond what the arithmetic needs (callers validate their fields).
    pub fn from_calendar(
        year: i32,
        month: u32,
        day: u32,
        hour: u32,
        minute: u32,
        sec: f64,
    ) -> Self {
        let days = days_from_civil(year as i64, month as i64, day as i64) - GPS_EPOCH_DAYS;
        let week = days.div_euclid(7);
        let dow = days.rem_euclid(7);
        let sow = dow as f64 * 86_400.0 + hour as f64 * 3600.0 + minute as f64 * 60.0 + sec;
        GpsTime::new(week as i32, sow)
    }

    /// Calendar date and time of day (year, month, day, hour, minute, second) in GPS time.
    pub fn to_calendar(&self) -> (i32, u32, u32, u32, u32, f64) {
        let sod_whole = libm::floor(self.sow_s);
        let frac = self.sow_s - sod_whole;
        let total = self.week as i64 * 7 + GPS_EPOCH_DAYS + (sod_whole as i64).div_euclid(86_400);
        let sod = (sod_whole as i64).rem_euclid(86_400);
        // civil_from_days
        let z = total + 719_468;
        let era = if z >= 0 { z } else { z - 146_096 } / 146_097;
        let doe = z - era * 146_097;
        let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
        let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
        let mp = (5 * doy + 2) / 153;
        let d = doy - (153 * mp + 2) / 5 + 1;
        let m = if mp < 10 { mp + 3 } else { mp - 9 };
        let y = yoe + era * 400 + if m <= 2 { 1 } else { 0 };
        (
            y as i32,
            m as u32,
            d as u32,
            (sod / 3600) as u32,
            ((sod % 3600) / 60) as u32,
            (sod % 60) as f64 + frac,
        )
    }

    /// `self − other` in seconds, across weeks.
    pub fn diff_s(&self, other: &GpsTime) -> f64 {
        (self.week as i64 - other.week as i64) as f64 * SECONDS_PER_WEEK
            + (self.sow_s - other.sow_s)
    }

    /// `self + dt_s`, normalised.
    pub fn add_s(&self, dt_s: f64) -> GpsTime {
        GpsTime::new(self.week, self.sow_s + dt_s)
    }
}

/// The week-crossover correction of the user algorithms (IS-GPS-200 Table 20-IV, note to
/// tk, and §20.3.3.3.3.1 for t − toc): a time difference formed from seconds of week is
/// brought into [−302 400, 302 400] s by adding or subtracting 604 800 s.
pub fn crossover_s(dt_s: f64) -> f64 {
    if dt_s > 302_400.0 {
        dt_s - SECONDS_PER_WEEK
    } else if dt_s < -302_400.0 {
        dt_s + SECONDS_PER_WEEK
    } else {
        dt_s
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn gps_epoch_and_known_dates() {
        let t = GpsTime::from_calendar(1980, 1, 6, 0, 0, 0.0);
        assert_eq!((t.week, t.sow_s), (0, 0.0));
        // 2015-01-08 is a Thursday of GPS week 1826 (the ABPO nav file: week 1826,
        // toe 352 800 s = Thursday 02:00)
        let t = GpsTime::from_calendar(2015, 1, 8, 2, 0, 0.0);
        assert_eq!((t.week, t.sow_s), (1826, 352_800.0));
        // 01.15n: 2015-01-28 06:00 is week 1829, 280 800 s
        let t = GpsTime::from_calendar(2015, 1, 28, 6, 0, 0.0);
        assert_eq!((t.week, t.sow_s), (1829, 280_800.0));
        assert_eq!(t.to_calendar(), (2015, 1, 28, 6, 0, 0.0));
        let t = GpsTime::from_calendar(2000, 2, 29, 23, 59, 59.5);
        assert_eq!(t.to_calendar(), (2000, 2, 29, 23, 59, 59.5));
    }

    #[test]
    fn week_arithmetic_and_crossover() {
        let a = GpsTime::new(1826, 604_790.0);
        let b = a.add_s(20.0);
        assert_eq!((b.week, b.sow_s), (1827, 10.0));
        assert_eq!(b.diff_s(&a), 20.0);
        assert_eq!(crossover_s(10.0 - 604_790.0), 20.0);
        assert_eq!(crossover_s(604_790.0 - 10.0), -20.0);
        assert_eq!(crossover_s(302_400.0), 302_400.0);
        let n = GpsTime::new(5, -1.0);
        assert_eq!((n.week, n.sow_s), (4, 604_799.0));
        // absurd values saturate instead of overflowing
        let big = GpsTime::new(i32::MAX, 1e95);
        assert_eq!(big.week, i32::MAX);
        assert!(big.diff_s(&GpsTime::new(i32::MIN, 0.0)).is_finite());
    }
}
