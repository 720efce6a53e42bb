//! Broadcast orbits and clocks against RTKLIB 2.4.3 b34 on every ephemeris of the ABPO
//! navigation file (fixture by tools/rtklib_fixture/orbit_fixture.c).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sdins_core::gnss::GpsTime;
use sdins_sim::io::rinex::read_nav;
use std::path::PathBuf;

/// `rel` under the shared data folder, read in place: `../shared/data` beside the
/// repository (`../../../shared/data` from this crate), or `$SDINS_SHARED_DATA`. `None`
/// (with a visible skip message) when absent.
fn shared_data(rel: &str) -> Option<PathBuf> {
    let mut roots = vec![PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data"
    ))];
    if let Some(p) = std::env::var_os("SDINS_SHARED_DATA") {
        roots.push(PathBuf::from(p));
    }
    for r in roots {
        let p = r.join(rel);
        if p.exists() {
            return Some(p);
        }
    }
    let msg = format!("SKIPPED: {rel} not found under ../shared/data or $SDINS_SHARED_DATA");
    eprintln!("{msg}");
    println!("{msg}");
    None
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn every_abpo_ephemeris_matches_rtklib_eph2pos() {
    let Some(nav_path) = shared_data("psins_gnss/abpo0080.15n") else {
        return;
    };
    let nav = read_nav(&nav_path).unwrap();
    assert_eq!(nav.ephemerides.len(), 167);
    assert!(
        nav.klobuchar.is_none(),
        "the ABPO file carries no ION ALPHA/BETA"
    );
    let fixture = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/abpo_rtklib_orbits.csv"
    ))
    .unwrap();
    let (mut n, mut max_pos, mut max_clk) = (0usize, 0.0f64, 0.0f64);
    let mut seen = std::collections::HashSet::new();
    for line in fixture.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        let (prn, iode, week, toe) = (f[0] as u8, f[1] as u32, f[2] as i32, f[3]);
        let eph = nav
            .ephemerides
            .iter()
            .find(|e| e.prn == prn && e.iode == iode && e.toe.week == week && e.toe.sow_s == toe)
            .unwrap_or_else(|| panic!("G{prn:02} IODE {iode} toe {toe} not read"));
        seen.insert((prn, iode, toe as i64));
        let t = GpsTime::new(week, toe).add_s(f[4]);
        let s = eph.state(&t).unwrap();
        let d = (s.r_sat_e_m - sdins_core::math::Vec3::new(f[5], f[6], f[7])).norm();
        // RTKLIB's eph2pos clock: af0 + af1 dt + af2 dt² + relativistic term, no T_GD,
        // which is our clock_bias_s
        let dc = (s.clock_bias_s - f[8]).abs();
        max_pos = max_pos.max(d);
        max_clk = max_clk.max(dc);
        n += 1;
    }
    println!(
        "{n} epochs of {} ephemerides: max |Δr| = {max_pos:.3e} m, max |Δclock| = {max_clk:.3e} s",
        seen.len()
    );
    assert_eq!(seen.len(), 167, "every ephemeris is in the fixture");
    assert_eq!(n, 167 * 13);
    // the fixture prints positions to 1e-5 m and clocks to 16 digits; the algorithms
    // are the same (IS-GPS-200 Table 20-IV), so anything above that is a defect
    assert!(max_pos <= 1e-3, "{max_pos}");
    assert!(max_clk <= 1e-12, "{max_clk}");
}
