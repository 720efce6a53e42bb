//! `sdins align` end to end: JSON shape, output files, observability table, bad input.
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

#[test]
fn align_scenario_coarse_and_fine_json() {
    let d = std::env::temp_dir().join(format!("sdins-align-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    let (code, out, err) = sdins(&[
        "align",
        "alignment",
        "--method",
        "coarse2",
        "--json",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(v["method"], "coarse2");
    // aviation-grade run 0: 2-step coarse is within a few mrad of 2/−3/40°
    assert!((v["roll_deg"].as_f64().unwrap() - 2.0).abs() < 0.05);
    assert!((v["pitch_deg"].as_f64().unwrap() + 3.0).abs() < 0.05);
    assert!((v["yaw_deg"].as_f64().unwrap() - 40.0).abs() < 1.0);
    assert!(d.join("align_result.csv").exists());
    let (code, out, err) = sdins(&[
        "align",
        "alignment",
        "--method",
        "fine",
        "--duration-s",
        "300",
        "--json",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(v["accel_bias_ug"].as_array().unwrap().len(), 3);
    assert_eq!(v["gyro_bias_dph"].as_array().unwrap().len(), 3);
    let hist = std::fs::read_to_string(d.join("align_history.csv")).unwrap();
    assert_eq!(hist.lines().count(), 301);
    let _ = std::fs::remove_dir_all(&d);
}

/// `--out` with the fine filter writes the history plots (attitude error and bias
/// estimates with ±3σ), SVG and PNG.
#[test]
fn align_fine_writes_plots() {
    let d = std::env::temp_dir().join(format!("sdins-align-plots-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    let (code, _, err) = sdins(&[
        "align",
        "alignment",
        "--method",
        "fine",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    for f in [
        "align_attitude.svg",
        "align_attitude.png",
        "align_bias.svg",
        "align_bias.png",
    ] {
        let len = std::fs::metadata(d.join(f)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 1000, "{f}: {len} bytes");
    }
    let svg = std::fs::read_to_string(d.join("align_attitude.svg")).unwrap();
    assert!(svg.contains("φ_D [μrad]") && svg.contains("time [s]") && svg.contains("±3σ"));
    let svg = std::fs::read_to_string(d.join("align_bias.svg")).unwrap();
    assert!(svg.contains("accelerometer bias [μg]") && svg.contains("gyro bias [°/h]"));
    let png = std::fs::read(d.join("align_bias.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // the folder's report and reproduction record
    let html = std::fs::read_to_string(d.join("report.html")).unwrap();
    assert!(
        html.contains("<svg") && html.contains("roll"),
        "report.html"
    );
    let lower = html.to_ascii_lowercase();
    for bad in [
        "<script", "<link", "<img", " src=", " href=", "url(", "@import",
    ] {
        assert!(!lower.contains(bad), "report.html contains {bad}");
    }
    let t: toml::Table = std::fs::read_to_string(d.join("run.toml"))
        .unwrap()
        .parse()
        .unwrap();
    for k in ["sdins_version", "git_commit", "command"] {
        assert!(t.contains_key(k), "run.toml lacks {k}: {t:?}");
    }
    let text = toml::to_string(&t).unwrap();
    assert!(
        text.contains("fine") && text.contains("alignment"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn align_observability_table() {
    let (code, out, err) = sdins(&["align", "--observability"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("| 12-state, NED biases, 1 heading | 9 / 12 | 7 |"),
        "{out}"
    );
    assert!(out.contains("| pseudo 9-state | 9 / 9 |"), "{out}");
    assert!(out.contains("| 0°, 180° | 12 / 12 | 11 |"), "{out}");
    assert!(
        out.contains("| 0°, 90°, 180°, 270° | 12 / 12 | 11 |"),
        "{out}"
    );
}

#[test]
fn align_bad_input_exits_2() {
    let (code, _, err) = sdins(&["align"]);
    assert_eq!(code, 2, "{err}");
    let d = std::env::temp_dir().join(format!("sdins-align-bad-{}.csv", std::process::id()));
    std::fs::write(&d, "t,gx,gy,gz,ax,ay,az\n0,1,2,x,4,5,6\n").unwrap();
    let (code, _, err) = sdins(&["align", "--imu", d.to_str().unwrap(), "--lat", "30"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(d.to_str().unwrap()), "{err}");
    let _ = std::fs::remove_file(&d);
    let (code, _, err) = sdins(&["align", "alignment", "--window-s", "0"]);
    assert_eq!(code, 2, "{err}");
    // numeric options: NaN and negative noise values are bad input naming the option
    for (opt, val) in [("--vrw", "nan"), ("--arw", "-1"), ("--duration-s", "0")] {
        let a = format!("{opt}={val}");
        let (code, _, err) = sdins(&["align", "alignment", "--method", "fine", &a]);
        assert_eq!(code, 2, "{a}: {err}");
        assert!(err.contains(opt), "{a}: {err}");
    }
}

/// `--method i0` on the moored ship recovers the heading at the window end within 0.05°
/// (marine grade, 300 s: closed-form σ ≈ 0.03°, docs/alignment_i0.md §3), and a bad
/// `--sigma-z` exits 2 naming the option.
#[test]
fn align_i0_moored_ship_and_sigma_z_validation() {
    let (code, out, err) = sdins(&[
        "align",
        "moored-ship",
        "--method",
        "i0",
        "--window-s",
        "300",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(v["method"], "i0");
    let p = v["phi_urad"].as_array().unwrap()[2].as_f64().unwrap();
    assert!(p.abs() < 0.05f64.to_radians() * 1e6, "{p}");
    let (code, _, err) = sdins(&["align", "moored-ship", "--sigma-z=-1"]);
    assert_eq!(code, 2);
    assert!(err.contains("--sigma-z"), "{err}");
}

/// A stationary-only method on a moving scenario exits 2 naming the time and speed and
/// suggesting i0; i0 runs.
#[test]
fn align_refuses_a_moving_scenario() {
    let (code, _, err) = sdins(&["align", "mach1-east", "--method", "coarse2", "--json"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("truth speed is 340.")
            && err.contains("t = 0.")
            && err.contains("--method i0"),
        "{err}"
    );
    let (code, out, err) = sdins(&[
        "align",
        "moored-ship",
        "--method",
        "i0",
        "--window-s",
        "300",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["method"], "i0");
}
