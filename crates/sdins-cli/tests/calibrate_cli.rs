//! `sdins calibrate` end to end: table, JSON, output files, Monte Carlo summary and bad
//! options (exit 2 naming the option).
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

/// A short 6-position schedule at 10 Hz (7.5k samples: fast in a debug build).
fn small_scenario(dir: &std::path::Path) -> String {
    let p = dir.join("cal.toml");
    std::fs::write(
        &p,
        "[start]\nlat_deg = 45.0\nlon_deg = 7.0\n[imu]\nrate_hz = 10.0\ngrade = \"tactical\"\n\
         [calibration]\nschedule = \"6-position\"\ndwell_s = 120.0\nrotation_s = 10.0\n",
    )
    .unwrap();
    p.display().to_string()
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-cal-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn calibrate_json_files_and_monte_carlo() {
    let d = tmp("ok");
    let scn = small_scenario(&d);
    let out = d.join("out");
    let (code, stdout, err) = sdins(&["calibrate", &scn, "--json", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let params = v["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 24);
    assert_eq!(v["nees_dof"], 24);
    // every estimate within 5σ of the truth (a consistent estimator: |z| > 5 has
    // probability 6e-7 per parameter)
    for p in params {
        let z = (p["estimate"].as_f64().unwrap() - p["truth"].as_f64().unwrap())
            / p["sigma"].as_f64().unwrap();
        assert!(z.abs() < 5.0, "{p}");
    }
    for f in [
        "calibration.csv",
        "calibration.json",
        "report.html",
        "run.toml",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let csv = std::fs::read_to_string(out.join("calibration.csv")).unwrap();
    assert_eq!(csv.lines().count(), 25);
    assert!(csv.starts_with("parameter,unit,estimate,sigma,truth"));
    // Monte Carlo: text summary and per-run file
    let out2 = d.join("mc");
    let (code, stdout, err) = sdins(&[
        "calibrate",
        &scn,
        "--runs",
        "4",
        "--out",
        out2.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("Monte Carlo, 4 runs: mean NEES"),
        "{stdout}"
    );
    let runs = std::fs::read_to_string(out2.join("calibration_runs.csv")).unwrap();
    assert_eq!(runs.lines().count(), 5);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn calibrate_bad_options_exit_2_naming_the_option() {
    let d = tmp("bad");
    let scn = small_scenario(&d);
    for (args, needle) in [
        (vec!["--runs", "0"], "--runs"),
        (vec!["--draw-scale-ppm", "100"], "--draw-scale-ppm"),
        (vec!["--draw-scale-ppm", "500,100"], "--draw-scale-ppm"),
        (
            vec!["--draw-misalignment-mrad", "0.1,nan"],
            "--draw-misalignment-mrad",
        ),
        (
            vec!["--draw-misalignment-mrad", "-1,1"],
            "--draw-misalignment-mrad",
        ),
        (
            vec!["--draw-misalignment-mrad", "1,1000"],
            "--draw-misalignment-mrad",
        ),
    ] {
        let mut a = vec!["calibrate", scn.as_str()];
        a.extend(args.iter().copied());
        let (code, _, err) = sdins(&a);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    // a bad schedule key: file, line and key
    let bad = d.join("bad.toml");
    std::fs::write(
        &bad,
        "[start]\nlat_deg = 45.0\nlon_deg = 7.0\n[imu]\nrate_hz = 10.0\n[calibration]\nschedule = \"9-position\"\n",
    )
    .unwrap();
    let (code, _, err) = sdins(&["calibrate", bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("bad.toml:7: calibration.schedule"), "{err}");
    // a schedule without rotations about every axis: the gyro parameters are unobservable
    let flat = d.join("flat.toml");
    std::fs::write(
        &flat,
        "[start]\nlat_deg = 45.0\nlon_deg = 7.0\n[imu]\nrate_hz = 10.0\ngrade = \"tactical\"\n\
         [[segment]]\ntype = \"static\"\nduration_s = 100.0\n",
    )
    .unwrap();
    let (code, _, err) = sdins(&["calibrate", flat.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not observable"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn calibrate_recorded_file_against_the_schedule() {
    // The exact increments of the schedule written by `sdins truth` (noise-free, printed
    // with round-trip precision): every estimate is zero to far below its 1σ (the
    // tactical grade's), and a truncated record is refused.
    let d = tmp("rec");
    let scn = small_scenario(&d);
    let tdir = d.join("truth");
    let (code, _, err) = sdins(&["truth", &scn, "--out", tdir.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let imu = tdir.join("imu.csv");
    let (code, stdout, err) = sdins(&[
        "calibrate",
        &scn,
        "--imu",
        imu.to_str().unwrap(),
        "--format",
        "sdins",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(v["nees"].is_null());
    let params = v["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 24);
    for p in params {
        let (e, s) = (
            p["estimate"].as_f64().unwrap(),
            p["sigma"].as_f64().unwrap(),
        );
        assert!(p["truth"].is_null());
        assert!(e.abs() < 1e-3 * s, "{p}");
    }
    // drop the last sample: located refusal
    let text = std::fs::read_to_string(&imu).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.pop();
    let short = d.join("short.csv");
    std::fs::write(&short, lines.join("\n") + "\n").unwrap();
    let (code, _, err) = sdins(&[
        "calibrate",
        &scn,
        "--imu",
        short.to_str().unwrap(),
        "--format",
        "sdins",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("does not fit the schedule"), "{err}");
    let (code, _, err) = sdins(&[
        "calibrate",
        &scn,
        "--imu",
        imu.to_str().unwrap(),
        "--format",
        "sdins",
        "--runs",
        "3",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--runs"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
