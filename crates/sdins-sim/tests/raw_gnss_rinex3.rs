//! RINEX 3 reading and writing: a round trip through our writer and reader, RINEX 3.03
//! produced by RTKLIB's `convbin` read by ours, and our RINEX 3.04 read by RTKLIB's
//! `rnx2rtkp` (the RTKLIB checks skip visibly when RTKLIB is not installed).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sdins_core::gnss::{nominal_constellation, GpsTime, KLOBUCHAR_DEFAULT};
use sdins_sim::io::rinex::{
    nav_to_rinex3, obs_to_rinex3, parse_nav, parse_obs, read_nav, read_obs, NavFile, ObsCode,
    ObsEpoch, ObsFile, ObsHeader, ObsValue, SatObs,
};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `rel` under the shared data folder (`../../../shared/data` from this crate, or
/// `$SDINS_SHARED_DATA`); `None` with a visible skip message when absent.
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

/// Whether an RTKLIB program runs here; prints a visible skip message when not.
fn have(program: &str) -> bool {
    let ok = Command::new(program).arg("-?").output().is_ok();
    if !ok {
        let msg = format!("SKIPPED: {program} (RTKLIB) is not installed: apt-get install rtklib");
        eprintln!("{msg}");
        println!("{msg}");
    }
    ok
}

fn tmp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn synthetic_obs() -> ObsFile {
    let codes = ["C1C", "L1C", "D1C", "S1C", "C2W", "L2W"].map(|c| ObsCode::new(c).unwrap());
    let t0 = GpsTime::from_calendar(2024, 2, 29, 23, 59, 50.0);
    let epochs = (0..5)
        .map(|k| ObsEpoch {
            t: t0.add_s(5.0 * k as f64),
            flag: 0,
            rx_clock_offset_s: (k % 2 == 0).then_some(1.25e-4),
            sats: (1..=14)
                .map(|prn| SatObs {
                    prn,
                    values: (0..codes.len())
                        .map(|j| {
                            ((j + prn as usize + k) % 5 >= 1).then(|| ObsValue {
                                // values a RINEX F14.3 field holds exactly
                                value: ((-1.0e6 + 1234.567 * (prn as f64) + 17.125 * j as f64
                                    - 0.001 * k as f64)
                                    * 1e3)
                                    .round()
                                    / 1e3,
                                lli: (j == 1).then_some(1),
                                ssi: Some(((prn as usize + j) % 9 + 1) as u8),
                            })
                        })
                        .collect(),
                })
                .collect(),
        })
        .collect();
    ObsFile {
        header: ObsHeader {
            version: 3.04,
            marker_name: "SYNTH".into(),
            receiver_type: "SDINS".into(),
            approx_position_e_m: Some([4_097_216.680_5, 4_429_119.028_7, -2_065_771.367_6]),
            antenna_delta_hen_m: [0.0083, 0.0, 0.0],
            gps_types: codes.to_vec(),
            interval_s: Some(5.0),
            first_obs: Some(t0),
        },
        epochs,
    }
}

#[test]
fn observation_and_navigation_files_survive_a_rinex3_round_trip() {
    let obs = synthetic_obs();
    let text = obs_to_rinex3(&obs);
    let back = parse_obs(text.as_bytes(), "synthetic.obs").unwrap();
    assert_eq!(back, obs);
    // 14 satellites: more than the 12 of a RINEX 2 line, one line each in RINEX 3
    assert!(text.lines().any(|l| l.starts_with("G14")));

    let t0 = GpsTime::from_calendar(2024, 2, 29, 22, 0, 0.0);
    let mut ephs = nominal_constellation(t0).to_vec();
    for (k, e) in ephs.iter_mut().enumerate() {
        e.af0_s = 1e-5 * (k as f64 - 12.0);
        e.af1_sps = -3.2e-12;
        e.tgd_s = -4.5e-9;
    }
    let nav = NavFile {
        version: 3.04,
        klobuchar: Some(KLOBUCHAR_DEFAULT),
        ephemerides: ephs,
        skipped_records: 0,
    };
    let back = parse_nav(nav_to_rinex3(&nav).as_bytes(), "synthetic.nav").unwrap();
    assert_eq!(back.klobuchar, nav.klobuchar);
    assert_eq!(back.ephemerides.len(), 24);
    for (a, b) in back.ephemerides.iter().zip(&nav.ephemerides) {
        // D19.12 keeps 13 significant digits (a half-unit rounding of 5e-13 relative): an
        // angle near 2π moves by 3e-12 rad, 8e-5 m along a 26 560 km orbit; √A by
        // 2.6e-9 √m, 3e-5 m of radius. (Values read from a RINEX file come back exactly:
        // see the ABPO round trip.)
        let s1 = a.state(&t0.add_s(3000.0)).unwrap();
        let s2 = b.state(&t0.add_s(3000.0)).unwrap();
        assert!(
            (s1.r_sat_e_m - s2.r_sat_e_m).norm() < 2e-4,
            "{}",
            (s1.r_sat_e_m - s2.r_sat_e_m).norm()
        );
        assert!((s1.clock_bias_s - s2.clock_bias_s).abs() < 1e-17);
        assert_eq!(
            (a.prn, a.toe, a.toc, a.iode, a.health),
            (b.prn, b.toe, b.toc, b.iode, b.health)
        );
    }
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn abpo_survives_a_rinex3_round_trip_exactly() {
    let (Some(o), Some(n)) = (
        shared_data("psins_gnss/abpo0080.15o"),
        shared_data("psins_gnss/abpo0080.15n"),
    ) else {
        return;
    };
    let (obs, nav) = (read_obs(&o).unwrap(), read_nav(&n).unwrap());
    let back = parse_obs(obs_to_rinex3(&obs).as_bytes(), "abpo.obs").unwrap();
    assert_eq!(back.epochs, obs.epochs);
    assert_eq!(back.header.gps_types, obs.header.gps_types);
    let back = parse_nav(nav_to_rinex3(&nav).as_bytes(), "abpo.nav").unwrap();
    assert_eq!(
        back.ephemerides, nav.ephemerides,
        "values written D19.12 read back bit for bit"
    );
}

/// RINEX 3.03 written by RTKLIB's convbin from the RINEX 2.11 ABPO file reads back as the
/// same observations as the original through our 2.11 reader.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn rtklib_convbin_rinex3_reads_like_the_rinex2_original() {
    let Some(o) = shared_data("psins_gnss/abpo0080.15o") else {
        return;
    };
    if !have("convbin") {
        return;
    }
    let dir = tmp_dir("convbin");
    let out = dir.join("abpo.obs");
    let st = Command::new("convbin")
        .args(["-r", "rinex", "-v", "3.03", "-o"])
        .arg(&out)
        .arg(&o)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let v2 = read_obs(&o).unwrap();
    let v3 = read_obs(&out).unwrap();
    assert_eq!(v3.header.version, 3.03);
    assert_eq!(v3.epochs.len(), v2.epochs.len());
    let mut compared = 0usize;
    for code in ["C1C", "L1C", "C1W", "C2W", "L2W"] {
        let (i2, i3) = (v2.code_index(code).unwrap(), v3.code_index(code).unwrap());
        for (e2, e3) in v2.epochs.iter().zip(&v3.epochs) {
            assert_eq!(e2.t, e3.t);
            for (s2, s3) in e2.sats.iter().zip(&e3.sats) {
                assert_eq!(s2.prn, s3.prn);
                assert_eq!(
                    s2.values[i2].map(|v| v.value),
                    s3.values[i3].map(|v| v.value),
                    "{code} G{:02}",
                    s2.prn
                );
                compared += 1;
            }
        }
    }
    println!("convbin RINEX 3.03: {compared} observations equal to the RINEX 2.11 original");
    std::fs::remove_dir_all(&dir).ok();
}

fn rnx2rtkp_xyz(dir: &Path, obs: &Path, nav: &Path, conf: &str, out: &str) -> Vec<[f64; 3]> {
    let conf_path = dir.join("opts.conf");
    std::fs::write(&conf_path, conf).unwrap();
    let out = dir.join(out);
    let st = Command::new("rnx2rtkp")
        .arg("-k")
        .arg(&conf_path)
        .arg("-o")
        .arg(&out)
        .arg(obs)
        .arg(nav)
        .stderr(std::process::Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('%'))
        .map(|l| {
            let f: Vec<f64> = l
                .split_whitespace()
                .skip(2)
                .take(3)
                .map(|s| s.parse().unwrap())
                .collect();
            [f[0], f[1], f[2]]
        })
        .collect()
}

/// RTKLIB reads our RINEX 3.04 observation and navigation files: its single-point
/// solutions of the first two hours of ABPO from our files equal (to 0.1 mm) its
/// solutions from the original RINEX 2 files.
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn rtklib_reads_our_rinex3_files() {
    let (Some(o), Some(n)) = (
        shared_data("psins_gnss/abpo0080.15o"),
        shared_data("psins_gnss/abpo0080.15n"),
    ) else {
        return;
    };
    if !have("rnx2rtkp") {
        return;
    }
    let dir = tmp_dir("rnx3");
    let mut obs = read_obs(&o).unwrap();
    obs.epochs.truncate(240);
    let nav = read_nav(&n).unwrap();
    let (our_obs, our_nav) = (dir.join("abpo.obs"), dir.join("abpo.nav"));
    std::fs::write(&our_obs, obs_to_rinex3(&obs)).unwrap();
    std::fs::write(&our_nav, nav_to_rinex3(&nav)).unwrap();
    let conf = "pos1-posmode =single\npos1-frequency =l1\npos1-elmask =10\npos1-ionoopt =brdc\npos1-tropopt =saas\npos1-navsys =1\nout-solformat =xyz\n";
    let ours = rnx2rtkp_xyz(&dir, &our_obs, &our_nav, conf, "ours.pos");
    let mut orig = rnx2rtkp_xyz(&dir, &o, &n, conf, "orig.pos");
    orig.truncate(ours.len());
    assert_eq!(ours.len(), 240);
    let worst = ours
        .iter()
        .zip(&orig)
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    println!("rnx2rtkp on our RINEX 3.04 vs the original RINEX 2: {} epochs, max coordinate difference {worst:.2e} m", ours.len());
    assert!(worst <= 1e-4, "{worst}");
    std::fs::remove_dir_all(&dir).ok();
}
