//! GPS time: seconds since the GPS epoch (1980-01-06 00:00:00 GPST) from a calendar date,
//! and GPS − UTC from the leap-second table.

/// Seconds in a GPS week.
pub const SECONDS_PER_WEEK: f64 = 604_800.0;

/// GPS − UTC \[s\] from each date (UTC, year, month, day) on: the leap seconds inserted since
/// the GPS epoch, from IERS Bulletin C (the IERS leap-second list `Leap_Second.dat`); no leap
/// second has been announced after the one at the end of 2016, so 18 s holds from
/// 2017-01-01 until IERS announces the next.
pub const LEAP_SECONDS: [(i32, u32, u32, f64); 18] = [
    (1981, 7, 1, 1.0),
    (1982, 7, 1, 2.0),
    (1983, 7, 1, 3.0),
    (1985, 7, 1, 4.0),
    (1988, 1, 1, 5.0),
    (1990, 1, 1, 6.0),
    (1991, 1, 1, 7.0),
    (1992, 7, 1, 8.0),
    (1993, 7, 1, 9.0),
    (1994, 7, 1, 10.0),
    (1996, 1, 1, 11.0),
    (1997, 7, 1, 12.0),
    (1999, 1, 1, 13.0),
    (2006, 1, 1, 14.0),
    (2009, 1, 1, 15.0),
    (2012, 7, 1, 16.0),
    (2015, 7, 1, 17.0),
    (2017, 1, 1, 18.0),
];

/// Days from 1970-01-01 to the civil date (proleptic Gregorian), the standard
/// era/day-of-era conversion.
pub(crate) fn days_from_civil(y: i32, m: u32, d: u32) -> i64 {
    let y = i64::from(y) - i64::from(m <= 2);
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(m);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(d) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Days in a month.
pub(crate) fn days_in_month(y: i32, m: u32) -> u32 {
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        _ if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        _ => 28,
    }
}

/// Seconds since the GPS epoch of a date and time read on the same (GPS) time scale.
pub fn gps_seconds_from_date(y: i32, mo: u32, d: u32, h: u32, mi: u32, s: f64) -> f64 {
    let days = days_from_civil(y, mo, d) - days_from_civil(1980, 1, 6);
    days as f64 * 86_400.0 + f64::from(h) * 3600.0 + f64::from(mi) * 60.0 + s
}

/// GPS − UTC \[s\] on a UTC date (0 before 1981-07-01).
pub fn gps_minus_utc_s(y: i32, mo: u32, d: u32) -> f64 {
    let day = days_from_civil(y, mo, d);
    LEAP_SECONDS
        .iter()
        .rev()
        .find(|&&(ly, lm, ld, _)| day >= days_from_civil(ly, lm, ld))
        .map_or(0.0, |l| l.3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epochs_and_leaps() {
        assert_eq!(gps_seconds_from_date(1980, 1, 6, 0, 0, 0.0), 0.0);
        // GPS week 2086 starts on 2019-12-29 (its Sunday); 2086·604800 s
        assert_eq!(
            gps_seconds_from_date(2019, 12, 29, 0, 0, 0.0),
            2086.0 * SECONDS_PER_WEEK
        );
        // the first 1024-week rollover: 1999-08-22 00:00 GPST
        assert_eq!(
            gps_seconds_from_date(1999, 8, 22, 0, 0, 0.0),
            1024.0 * SECONDS_PER_WEEK
        );
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
        assert_eq!(gps_minus_utc_s(1980, 1, 6), 0.0);
        assert_eq!(gps_minus_utc_s(2016, 12, 31), 17.0);
        assert_eq!(gps_minus_utc_s(2017, 1, 1), 18.0);
        assert_eq!(gps_minus_utc_s(2026, 12, 1), 18.0);
        assert_eq!(days_in_month(2000, 2), 29);
        assert_eq!(days_in_month(1900, 2), 28);
    }
}
