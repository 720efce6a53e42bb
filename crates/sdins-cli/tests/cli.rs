//! End-to-end CLI tests: exit codes and messages for bad input, outputs for good input.
#![allow(clippy::unwrap_used)]
use std::process::Command;

fn sdins(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-cli-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const GOOD: &str = "[start]\nlat_deg = 37.5\nlon_deg = 127.0\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"static\"\nduration_s = 1.0\n";

#[test]
fn bad_scenario_files_exit_2_with_file_line_key() {
    let d = tmp("bad");
    for (name, text, line, key) in [
        (
            "unknown.toml",
            GOOD.replace("lon_deg = 127.0", "lon_deg = 127.0\nheigth_m = 3.0"),
            4,
            "heigth_m",
        ),
        (
            "missing.toml",
            GOOD.replace("lat_deg = 37.5\n", ""),
            1,
            "lat_deg",
        ),
        (
            "negdur.toml",
            GOOD.replace("duration_s = 1.0", "duration_s = -5.0"),
            8,
            "segment.duration_s",
        ),
        (
            "rate0.toml",
            GOOD.replace("rate_hz = 100.0", "rate_hz = 0.0"),
            5,
            "imu.rate_hz",
        ),
        (
            "lat95.toml",
            GOOD.replace("lat_deg = 37.5", "lat_deg = 95.0"),
            2,
            "start.lat_deg",
        ),
        ("syntax.toml", GOOD.replace("[imu]", "[imu"), 4, ""),
    ] {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        let (code, _out, err) = sdins(&[
            "truth",
            p.to_str().unwrap(),
            "--out",
            d.join("o").to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(name), "{name}: {err}");
        assert!(
            err.contains(&format!(":{line}:")),
            "{name}: want line {line}: {err}"
        );
        assert!(err.contains(key), "{name}: want key {key}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    // "did you mean" hint
    let (_, _, err) = sdins(&["truth", d.join("unknown.toml").to_str().unwrap()]);
    assert!(err.contains("did you mean `h_m`"), "{err}");
}

#[test]
fn unknown_algorithm_and_scenario_exit_2() {
    let (code, _, err) = sdins(&["run", "turn-90dps", "--algo", "songlee,kalman"]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown algorithm `kalman`"), "{err}");
    let (code, _, err) = sdins(&["run", "no-such-scenario"]);
    assert_eq!(code, 2);
    assert!(err.contains("built-ins"), "{err}");
}

#[test]
fn truth_writes_both_files_and_run_json_shape() {
    let d = tmp("good");
    let p = d.join("s.toml");
    std::fs::write(&p, GOOD).unwrap();
    let (code, _, err) = sdins(&[
        "truth",
        p.to_str().unwrap(),
        "--out",
        d.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let imu = std::fs::read_to_string(d.join("imu.csv")).unwrap();
    assert_eq!(imu.lines().count(), 101);
    assert!(
        imu.starts_with("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps")
    );
    let truth = std::fs::read_to_string(d.join("truth.csv")).unwrap();
    assert!(truth
        .starts_with("t_s,lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg"));
    // no temporary files left behind
    assert!(std::fs::read_dir(&d).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .contains(".tmp")));

    let (code, out, err) = sdins(&[
        "run",
        p.to_str().unwrap(),
        "--algo",
        "songlee,dualquat",
        "--json",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["results"].as_array().unwrap().len(), 2);
    let r = &v["results"][0];
    assert_eq!(r["algo"], "songlee");
    assert_eq!(r["samples"], 3);
    assert_eq!(r["nav_updates"], 33);
    for key in [
        "pos_err_ned_m",
        "vel_err_ned_mps",
        "att_err_rad",
        "euler_err_rad",
    ] {
        assert_eq!(r["final"][key].as_array().unwrap().len(), 3, "{key}");
        assert_eq!(r["max_abs"][key].as_array().unwrap().len(), 3, "{key}");
    }
    assert!(r["final"]["height_err_m"].is_number() && r["wall_s"].is_number());
    assert!(d.join("nav_songlee.csv").exists() && d.join("err_dualquat.csv").exists());
}

#[test]
fn scenarios_lists_and_prints_parseable_files() {
    let (code, out, _) = sdins(&["scenarios"]);
    assert_eq!(code, 0);
    for name in [
        "stationary",
        "mach1-east",
        "turn-90dps",
        "dq-paper",
        "alignment",
    ] {
        assert!(out.contains(name), "{out}");
        let (code, text, _) = sdins(&["scenarios", name]);
        assert_eq!(code, 0);
        assert!(sdins_sim::scenario::Scenario::from_toml(&text, name).is_ok());
    }
}

#[test]
fn nav_over_a_recorded_file_matches_run() {
    // `sdins truth` then `sdins nav` over its imu.csv with its truth.csv reproduces the
    // errors of `sdins run` on the same scenario (same increments, same algorithm).
    let d = tmp("nav");
    let p = d.join("s.toml");
    std::fs::write(
        &p,
        GOOD.replace(
            "type = \"static\"\nduration_s = 1.0",
            "type = \"static\"\nduration_s = 3.0",
        ),
    )
    .unwrap();
    let (code, _, err) = sdins(&[
        "truth",
        p.to_str().unwrap(),
        "--out",
        d.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = sdins(&[
        "nav",
        "--imu",
        d.join("imu.csv").to_str().unwrap(),
        "--truth",
        d.join("truth.csv").to_str().unwrap(),
        "--algo",
        "songlee",
        "--samples",
        "3",
        "--out",
        d.join("n").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (code, out2, err) = sdins(&[
        "run",
        p.to_str().unwrap(),
        "--algo",
        "songlee",
        "--json",
        "--out",
        d.join("r").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let w: serde_json::Value = serde_json::from_str(&out2).unwrap();
    // the truth file carries 12-15 significant digits, so agree to that level
    let a = v["final"]["att_err_rad"][2].as_f64().unwrap();
    let b = w["results"][0]["final"]["att_err_rad"][2].as_f64().unwrap();
    assert!((a - b).abs() < 1e-11, "{a:e} vs {b:e}");
}

#[test]
fn nav_bad_inputs_exit_2() {
    let d = tmp("navbad");
    let imu = d.join("imu.csv");
    std::fs::write(&imu, "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n0.01,0,0,0,0,0,-0.098\n0.02,0,0,nan,0,0,-0.098\n").unwrap();
    let (code, _, err) = sdins(&[
        "nav",
        "--imu",
        imu.to_str().unwrap(),
        "--init",
        "37.5,127,0,0,0,0,0,0,0",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("imu.csv") && err.contains(":3"), "{err}");
    let (code, _, err) = sdins(&[
        "nav",
        "--imu",
        imu.to_str().unwrap(),
        "--init",
        "95,127,0,0,0,0,0,0,0",
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = sdins(&[
        "nav",
        "--imu",
        d.join("missing.csv").to_str().unwrap(),
        "--init",
        "1,2,3,0,0,0,0,0,0",
    ]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("missing.csv"), "{err}");
}

#[test]
fn nav_psins_trj10ms_through_the_cli() {
    // Issue 3 external check through `sdins nav --format psins`: PSINS's own truth at 900 s
    // (attitude ≤ 0.1″, velocity ≤ 1 mm/s, horizontal position ≤ 0.5 m).
    let base = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/csv/psins/"
    );
    let imu = format!("{base}trj10ms_imu.csv");
    if !std::path::Path::new(&imu).exists() {
        eprintln!("skipped: ../shared/data not present");
        return;
    }
    let d = tmp("psins");
    let init = format!(
        "{},{},380,0,0,0,0,0,0",
        0.597_706_293_396_019_1_f64.to_degrees(),
        1.900_832_224_040_737_8_f64.to_degrees()
    );
    let (code, _, err) = sdins(&[
        "nav",
        "--imu",
        &imu,
        "--format",
        "psins",
        "--earth",
        "psins",
        "--truth",
        &format!("{base}trj10ms_avp.csv"),
        "--algo",
        "songlee-complete",
        "--samples",
        "1",
        "--coning",
        "1prev",
        "--init",
        &init,
        "--out",
        d.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let errs = std::fs::read_to_string(d.join("err_songlee-complete.csv")).unwrap();
    let row: Vec<f64> = errs
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|x| x.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .find(|r| (r[0] - 900.0).abs() < 1e-6)
        .unwrap();
    let arcsec = std::f64::consts::PI / 180.0 / 3600.0;
    assert!(row[1].hypot(row[2]) <= 0.5, "{row:?}");
    assert!(row[4..7].iter().all(|v| v.abs() <= 1e-3), "{row:?}");
    assert!(
        row[7..10].iter().all(|a| a.abs() <= 0.1 * arcsec),
        "{row:?}"
    );
}
