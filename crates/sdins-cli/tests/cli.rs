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

/// An input file next to the output folder `d` (inside it, it would be a file that no
/// sdins manifest lists, and sdins would refuse the folder).
fn input(d: &std::path::Path, name: &str) -> std::path::PathBuf {
    let dir = d.with_extension("in");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
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
    let p = input(&d, "s.toml");
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
    // per-axis error figure, log (default) and linear; reproduction record
    for f in [
        "report.html",
        "errors.png",
        "errors.svg",
        "errors_ned.png",
        "errors_ned.svg",
        "trajectory.png",
        "trajectory.svg",
        "timing.png",
        "run.toml",
    ] {
        assert!(d.join(f).is_file(), "{f}");
    }
    let html = std::fs::read_to_string(d.join("report.html")).unwrap();
    assert!(html.contains("|ε_N| [μrad]"), "log-scale per-axis labels");
    assert!(
        html.contains("ground track") && html.contains("north [m]"),
        "trajectory"
    );
    assert_self_contained(&html);
    let (code, _, err) = sdins(&[
        "run",
        p.to_str().unwrap(),
        "--algo",
        "songlee",
        "--plot-scale",
        "linear",
        "--quiet",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(d.join("report.html")).unwrap();
    assert!(html.contains("ε_N [μrad]") && !html.contains("|ε_N|"));
    let (code, _, err) = sdins(&["run", p.to_str().unwrap(), "--plot-scale", "cubic"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("plot-scale"), "{err}");
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
    let p = input(&d, "s.toml");
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
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
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

const IMU_H: &str = "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n";

fn imu_rows(n: usize) -> String {
    (0..n)
        .map(|k| format!("{:.2},0,0,0,0,0,-0.098\n", 0.01 * (k + 1) as f64))
        .collect()
}

/// Every IMU-file input class through `sdins nav`: exit 2, message naming the file, line,
/// column and what was expected.
#[test]
fn nav_imu_file_classes_exit_2_with_file_line_column() {
    let d = tmp("imuclasses");
    let r3 = imu_rows(3);
    let cases: Vec<(&str, String, &str)> = vec![
        ("empty.csv", String::new(), "empty.csv: empty file, expected an IMU record"),
        ("header.csv", IMU_H.into(), "header.csv:1: header only, expected data rows after it"),
        ("columns.csv", format!("{IMU_H}0.01,0,0,0,0,-0.098\n{r3}"), "columns.csv:2: expected 7 fields, found 6"),
        ("text.csv", format!("{IMU_H}{r3}0.04,0,x1,0,0,0,-0.098\n"), "text.csv:5: column 3 (dtheta_y_rad): expected a number, found `x1`"),
        ("nan.csv", format!("{IMU_H}{r3}0.04,0,0,0,NaN,0,-0.098\n"), "nan.csv:5: column 5 (dv_x_mps): expected a finite number, found `NaN`"),
        ("inf.csv", format!("{IMU_H}{r3}0.04,0,0,0,0,0,-inf\n"), "inf.csv:5: column 7 (dv_z_mps): expected a finite number, found `-inf`"),
        ("back.csv", format!("{IMU_H}{r3}0.02,0,0,0,0,0,-0.098\n"), "back.csv:5: column 1 (time): expected a time after 0.03 s, found 0.02 s"),
        ("repeat.csv", format!("{IMU_H}{r3}0.03,0,0,0,0,0,-0.098\n"), "repeat.csv:5: column 1 (time): expected a time after 0.03 s, found 0.03 s"),
        ("irregular.csv", format!("{IMU_H}{r3}0.0403,0,0,0,0,0,-0.098\n"), "irregular.csv:5: column 1 (time): sample interval"),
        ("spin.csv", format!("{IMU_H}{r3}0.04,3.2,0,0,0,0,-0.098\n"), "spin.csv:5: columns 2-4: |Δθ| per sample [rad] = 3.2e0, expected at most 3.141592653589793e0"),
        ("force.csv", format!("{IMU_H}{r3}0.04,0,0,0,0,0,-98.1\n"), "force.csv:5: columns 5-7: |f| [m/s²] = 9.81e3, expected at most 9.80665e3"),
        ("unknown.csv", "a,b,c\n1,2,3\n".into(), "unknown.csv:1: cannot detect the IMU format"),
    ];
    for (name, text, want) in cases {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        let (code, _, err) = sdins(&[
            "nav",
            "--imu",
            p.to_str().unwrap(),
            "--init",
            "37.5,127,0,0,0,0,0,0,0",
            "--out",
            d.join("o").to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(want), "{name}: want `{want}` in `{err}`");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    // (a cut last line is dropped with a warning: `cut_last_line_is_dropped_with_a_warning`)
    // nothing was written for any of them
    assert!(!d.join("o").exists() || std::fs::read_dir(d.join("o")).unwrap().count() == 0);
}

/// Scenario ranges and names: heights, latitudes beyond the pole limit, zero/negative
/// durations and rates, unknown algorithm names (with a hint), unknown keys.
#[test]
fn scenario_ranges_and_names_exit_2() {
    let d = tmp("scnranges");
    let with_nav = |nav: &str| GOOD.replace("[[segment]]", &format!("[nav]\n{nav}\n[[segment]]"));
    for (name, text, want) in [
        ("hlow.toml", GOOD.replace("lon_deg = 127.0", "lon_deg = 127.0\nh_m = -1500.0"), "hlow.toml:4: start.h_m: -1500 is out of range: expected height in [-1000, 100000] m"),
        ("hhigh.toml", GOOD.replace("lon_deg = 127.0", "lon_deg = 127.0\nh_m = 100001.0"), "hhigh.toml:4: start.h_m: 100001 is out of range: expected height in [-1000, 100000] m"),
        ("pole.toml", GOOD.replace("lat_deg = 37.5", "lat_deg = -89.995"), "pole.toml:2: start.lat_deg: -89.995 is too close to a pole"),
        ("lat.toml", GOOD.replace("lat_deg = 37.5", "lat_deg = 90.5"), "lat.toml:2: start.lat_deg: 90.5 is out of range: expected latitude in [-90, 90] deg"),
        ("latnan.toml", GOOD.replace("lat_deg = 37.5", "lat_deg = nan"), "latnan.toml:2: start.lat_deg: must be a finite number"),
        ("dur0.toml", GOOD.replace("duration_s = 1.0", "duration_s = 0.0"), "dur0.toml:8: segment.duration_s: 0 must be > 0"),
        ("durlong.toml", GOOD.replace("duration_s = 1.0", "duration_s = 1e9"), "durlong.toml:8: segment.duration_s: 1000000000 s is too long"),
        ("rateneg.toml", GOOD.replace("rate_hz = 100.0", "rate_hz = -100.0"), "rateneg.toml:5: imu.rate_hz: -100 must be > 0"),
        ("algo.toml", with_nav("algos = [\"songle\"]"), "algo.toml:7: nav.algos: unknown algorithm `songle` (did you mean `songlee`?): expected savage, songlee, songlee-complete, dualquat"),
        ("coning.toml", with_nav("samples = 2\nconing = \"three_poly\""), "coning.toml:8: nav.coning: `three_poly` is the set for 3 samples per update, but nav.samples is 2"),
        ("key.toml", with_nav("vertcal = \"hold\""), "key.toml:7: vertcal: unknown key (did you mean `vertical`?)"),
    ] {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        let (code, _, err) = sdins(&["truth", p.to_str().unwrap(), "--out", d.join("o").to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(want), "{name}: want `{want}` in `{err}`");
    }
}

fn truth_and_imu(d: &std::path::Path) {
    let p = input(d, "s.toml");
    std::fs::write(&p, GOOD).unwrap();
    let (code, _, err) = sdins(&[
        "truth",
        p.to_str().unwrap(),
        "--out",
        d.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
}

/// `sdins nav --truth` with a reference on another time base is an error naming both
/// files (it used to compare nothing), as is a reference whose first row is not at the
/// start epoch when it provides the initial state. (No command takes both a rate and an
/// IMU file: `nav` derives the rate from the file, so the time bases are what is checked.)
#[test]
fn nav_truth_time_base_mismatch_exit_2() {
    let d = tmp("timebase");
    truth_and_imu(&d);
    let truth = std::fs::read_to_string(d.join("truth.csv")).unwrap();
    // shift every reference time by 1000 s
    let shifted: String = truth
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                format!("{l}\n")
            } else {
                let (t, rest) = l.split_once(',').unwrap();
                format!("{},{rest}\n", t.parse::<f64>().unwrap() + 1000.0)
            }
        })
        .collect();
    let sh = d.join("shifted.csv");
    std::fs::write(&sh, shifted).unwrap();
    let imu = d.join("imu.csv");
    let args = |t: &std::path::Path, init: bool| {
        let mut v = vec![
            "nav".to_string(),
            "--imu".into(),
            imu.to_str().unwrap().into(),
            "--truth".into(),
            t.to_str().unwrap().into(),
            "--out".into(),
            d.join("n").to_str().unwrap().into(),
        ];
        if init {
            v.extend(["--init".into(), "37.5,127,0,0,0,0,0,0,0".into()]);
        }
        v
    };
    let run = |a: Vec<String>| sdins(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let (code, _, err) = run(args(&sh, true));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("shifted.csv: no time matches an update epoch of")
            && err.contains("imu.csv")
            && err.contains("the reference covers 1000 s to 1001 s"),
        "{err}"
    );
    let (code, _, err) = run(args(&sh, false));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(
            "shifted.csv: the first row (t = 1000 s) is not at the start of the first sample of"
        ) && err.contains("give --init"),
        "{err}"
    );
    assert!(!d.join("n").join("nav_songlee-complete.csv").exists());
    // the matching pair still works
    let (code, _, err) = run(args(&d.join("truth.csv"), false));
    assert_eq!(code, 0, "{err}");
}

/// An output folder that cannot be created (here: under a file) is the user's input error:
/// exit 2 in sdins's words, naming it, and nothing left behind.
#[test]
fn unwritable_output_leaves_no_file() {
    let d = tmp("unwritable");
    let blocker = d.join("file");
    std::fs::write(&blocker, "x").unwrap();
    let out = blocker.join("sub");
    let (code, _, err) = sdins(&[
        "truth",
        "stationary",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("file/sub") && err.contains("is a file, not a folder"),
        "{err}"
    );
    let names: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

/// Ctrl-C during `sdins truth`: the run stops with a message, a non-zero exit code and
/// neither output file nor a temporary file.
#[cfg(unix)]
#[test]
fn sigint_stops_cleanly_without_partial_files() {
    signal_stops_cleanly("INT", 130);
}

#[test]
fn sigterm_stops_cleanly_without_partial_files() {
    signal_stops_cleanly("TERM", 143);
}

/// Batch schedulers send SIGTERM, terminals SIGINT: both stop the run through the
/// library's cancellation token, remove the staged files and exit 128 + signal number.
fn signal_stops_cleanly(signal: &str, code: i32) {
    use std::time::{Duration, Instant};
    let d = tmp(&format!("sig{signal}"));
    // 90 min at 500 Hz: 2.7 M samples, several seconds of work
    let child = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args([
            "truth",
            "stationary",
            "--quiet",
            "--out",
            d.to_str().unwrap(),
        ])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // wait until the temporary files exist (the run is under way)
    let start = Instant::now();
    // (they are written in the staging folder `.sdins-stage-PID` inside `d`)
    let staged = |d: &std::path::Path| -> usize {
        std::fs::read_dir(d)
            .unwrap()
            .filter_map(|e| std::fs::read_dir(e.ok()?.path()).ok())
            .map(|r| r.count())
            .sum()
    };
    while staged(&d) < 2 && start.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(200));
    let st = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    let left: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// A report must not load anything: no script, no link, no external image or style.
fn assert_self_contained(html: &str) {
    let lower = html.to_ascii_lowercase();
    for bad in [
        "<script",
        "<link",
        "<iframe",
        "<object",
        "<embed",
        "<img",
        " src=",
        " href=",
        "xlink:href",
        "url(",
        "@import",
    ] {
        assert!(!lower.contains(bad), "report contains {bad}");
    }
}

/// One initial-state validator for every source: a PSINS header with latitude 95° and a
/// truth file whose first row moves at 1e300 m/s are refused like `--init` would be (they
/// used to give NaN with exit 0).
#[test]
fn initial_states_from_files_are_validated() {
    let d = tmp("initval");
    let imu = input(&d, "bad.imu");
    let mut text = String::from(
        "% PSINS-format SIMU log file\n0 0 -90.6 0 0 0\n95.0 108.9 380 0 10 9.78\n0.1 0.1 0.1 125 125 125\n",
    );
    for _ in 0..20 {
        text += "0 0 2 0 0 80\n";
    }
    std::fs::write(&imu, text).unwrap();
    let (code, _, err) = sdins(&["nav", "--imu", imu.to_str().unwrap(), "--format", "psins"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad.imu") && err.contains("PSINS header") && err.contains("latitude"),
        "{err}"
    );

    truth_and_imu(&d);
    let truth = std::fs::read_to_string(d.join("truth.csv")).unwrap();
    let mut lines: Vec<String> = truth.lines().map(String::from).collect();
    let mut cols: Vec<String> = lines[1].split(',').map(String::from).collect();
    cols[4] = "1e300".into();
    lines[1] = cols.join(",");
    std::fs::write(d.join("truth.csv"), lines.join("\n") + "\n").unwrap();
    let (code, _, err) = sdins(&[
        "nav",
        "--imu",
        d.join("imu.csv").to_str().unwrap(),
        "--truth",
        d.join("truth.csv").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("first row") && err.contains("speed"), "{err}");
}

/// Process conditions: a closed stdout ends the command quietly (exit 141 like other Unix
/// tools killed by SIGPIPE, no panic message), an output folder that is a file and absurd
/// resource requests are bad input (exit 2), non-UTF-8 arguments are refused by the parser.
#[test]
fn process_conditions_and_resource_bounds() {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["run", "turn-90dps", "--json", "--out"])
        .arg(tmp("pipe"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut one = [0u8; 1];
    child.stdout.take().unwrap().read_exact(&mut one).unwrap(); // then the pipe closes
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    // 141 = 128 + SIGPIPE without dying by the signal (staging folder removed), or 0 if
    // the whole output was in the pipe before it closed
    assert!(
        out.status.success() || out.status.code() == Some(141),
        "{:?} {err}",
        out.status
    );

    let file = tmp("outfile").join("a-file");
    std::fs::write(&file, "x").unwrap();
    let (code, _, err) = sdins(&["truth", "turn-90dps", "--out", file.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is an existing file"), "{err}");

    for args in [
        &["montecarlo", "turn-90dps", "--runs", "18446744073709551615"][..],
        &[
            "montecarlo",
            "turn-90dps",
            "--runs",
            "2",
            "--threads",
            "100000",
        ][..],
    ] {
        let (code, _, err) = sdins(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }

    use std::os::unix::ffi::OsStrExt;
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .arg("run")
        .arg(std::ffi::OsStr::from_bytes(b"\xff"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("invalid UTF-8"));
}

/// Provenance: run.toml holds u64 seeds losslessly (as strings: TOML integers are i64) and
/// the scenario text as it was read.
#[test]
fn run_toml_keeps_u64_seeds_and_the_scenario_text() {
    let d = tmp("prov");
    let (code, _, err) = sdins(&[
        "montecarlo",
        "turn-90dps",
        "--runs",
        "2",
        "--seed",
        "18446744073709551615",
        "--grade",
        "tactical",
        "--quiet",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let t: toml::Table = std::fs::read_to_string(d.join("run.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(t["seed"].as_str(), Some("18446744073709551615"));
    let p = d.join("s.toml");
    std::fs::write(&p, GOOD).unwrap();
    let r = d.join("run");
    let (code, _, err) = sdins(&["run", p.to_str().unwrap(), "--out", r.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let t: toml::Table = std::fs::read_to_string(r.join("run.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(t["scenario"].as_str(), Some(GOOD));
}

/// A static record with white noise (deterministic, Box–Muller over a 64-bit LCG): 200 Hz,
/// 300 s, σ 1e-3 rad/s and 0.01 m/s² per sample; `sway` adds a 1 Hz, 0.3 m/s² swing on x
/// in the second half.
fn noisy_imu(sway: bool) -> String {
    let (dt, n) = (0.005, 60_000);
    let mut state = 0x9E37_79B9_7F4A_7C15_u64;
    let mut normal = move || {
        let mut u = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (u1, u2) = (u(), u());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let mut s =
        String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
    for k in 0..n {
        let t = (k + 1) as f64 * dt;
        let a = if sway && k >= n / 2 {
            0.3 * (std::f64::consts::TAU * t).sin()
        } else {
            0.0
        };
        let w: Vec<f64> = (0..3).map(|_| 1e-3 * normal() * dt).collect();
        let f: Vec<f64> = (0..3).map(|_| 0.01 * normal() * dt).collect();
        s.push_str(&format!(
            "{t},{},{},{},{},{},{}\n",
            w[0],
            w[1],
            w[2],
            f[0] + a * dt,
            f[1],
            f[2] - 9.8 * dt
        ));
    }
    s
}

/// Reliability class 6: an Allan deviation of a record that moves warns, on stderr and in
/// `--json`; a static record does not. The sway (0.21 m/s² RMS against σ 0.01 m/s²) fails
/// every window of the second half; at rest a window fails with probability α = 1e-3.
#[test]
fn allan_of_a_moving_record_warns() {
    let d = tmp("allan-static");
    for (sway, warns) in [(false, false), (true, true)] {
        let f = input(&d, &format!("imu-{sway}.csv"));
        std::fs::write(&f, noisy_imu(sway)).unwrap();
        let out = d.join(format!("out-{sway}"));
        let (code, stdout, stderr) = sdins(&[
            "allan",
            "--imu",
            f.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]);
        assert_eq!(code, 0, "{stderr}");
        let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let w = j["warnings"].as_array().unwrap();
        assert_eq!(!w.is_empty(), warns, "{j}");
        assert_eq!(stderr.contains("does not look static"), warns, "{stderr}");
    }
}

/// The health verdict (bring-your-own-data issue, part 4): NaveGo's ADIS16488 record
/// (static biases 720 °/h and 16 mg) fused with the tactical preset diverges; the outputs
/// are written, every failed check is named on stderr, and the exit code is 3; `--health
/// warn` turns it into a warning and exit 0. The same record with NaveGo's own parameters
/// passes (exit 0).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn fuse_health_verdict_exit_3_on_a_diverged_filter() {
    let base = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/csv/navego/"
    );
    if !std::path::Path::new(base).exists() {
        eprintln!("skipped: ../shared/data not present");
        return;
    }
    let f = |n: &str| format!("{base}{n}");
    let d = tmp("health");
    let (imu, gnss, truth) = (f("imu2.csv"), f("gnss.csv"), f("ref.csv"));
    let common = [
        "fuse",
        "--imu",
        &imu,
        "--imu-format",
        "navego",
        "--gnss",
        &gnss,
        "--truth",
        &truth,
    ];
    let out = d.join("tactical");
    let mut args = common.to_vec();
    args.extend([
        "--grade",
        "tactical",
        "--attitude-deg",
        "0,0,-15",
        "--json",
        "--out",
    ]);
    args.push(out.to_str().unwrap());
    let (code, stdout, stderr) = sdins(&args);
    assert_eq!(code, 3, "{stderr}");
    for check in ["nis_windows", "rejected_share", "forced_updates", "bias"] {
        assert!(stderr.contains(&format!("health: {check}:")), "{stderr}");
    }
    let j: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(j["health"]["ok"], false, "{j}");
    for file in ["nav.csv", "innovations.csv", "report.html", "run.toml"] {
        assert!(out.join(file).exists(), "{file}");
    }
    let run = std::fs::read_to_string(out.join("run.toml")).unwrap();
    assert!(run.contains("health_ok = false"), "{run}");

    let warn = d.join("warn");
    let mut args = common.to_vec();
    args.extend([
        "--grade",
        "tactical",
        "--attitude-deg",
        "0,0,-15",
        "--health",
        "warn",
        "--out",
    ]);
    args.push(warn.to_str().unwrap());
    let (code, _, stderr) = sdins(&args);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("warning: health: rejected_share"),
        "{stderr}"
    );

    let good = d.join("good");
    let params = f("imu2_params.txt");
    let mut args = common.to_vec();
    args.extend(["--navego-params", &params, "--samples", "1", "--out"]);
    args.push(good.to_str().unwrap());
    let (code, _, stderr) = sdins(&args);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("health"), "{stderr}");
}

/// Reliability class 10: a logger killed mid-write cuts its last line; `nav` and `allan`
/// drop it with a warning on stderr (not stdout) that names the line, recorded in
/// run.toml.
#[test]
fn cut_last_line_is_dropped_with_a_warning() {
    let d = tmp("cutline");
    truth_and_imu(&d);
    let full = std::fs::read_to_string(d.join("imu.csv")).unwrap();
    let rows = full.lines().count();
    let cut = format!("{full}0.5,1e-4,2e-4");
    let f = input(&d, "cut.csv");
    std::fs::write(&f, &cut).unwrap();
    let truth = d.join("truth.csv");
    for cmd in ["nav", "allan"] {
        let out = d.with_extension(format!("out-{cmd}"));
        let mut args = vec![
            cmd,
            "--imu",
            f.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        if cmd == "nav" {
            args.extend(["--truth", truth.to_str().unwrap()]);
        }
        let (code, stdout, stderr) = sdins(&args);
        assert_eq!(code, 0, "{cmd}: {stderr}");
        let line = format!("line {}", rows + 1);
        assert!(
            stderr.contains("warning:") && stderr.contains(&line) && stderr.contains("dropped"),
            "{cmd}: {stderr}"
        );
        assert!(!stdout.contains("dropped"), "{cmd}: {stdout}");
        let run = std::fs::read_to_string(out.join("run.toml")).unwrap();
        assert!(run.contains("dropped"), "{cmd}: {run}");
    }
}
