//! `sdins fuse`: outputs and bad options.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

const SCN: &str = "name = \"fuse-cli\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 10.0\n[imu]\nrate_hz = 100.0\ngrade = \"tactical\"\n[nav]\nsamples = 2\n[[segment]]\ntype = \"turn\"\nrate_dps = 3.0\nduration_s = 30.0\n[gnss]\nrate_hz = 2.0\nlever_arm_b_m = [1.0, 0.0, -0.5]\n";

#[test]
fn fuse_writes_outputs_and_rejects_bad_options() {
    let dir = std::env::temp_dir().join(format!("sdins-fuse-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scn = dir.join("s.toml");
    std::fs::write(&scn, SCN).unwrap();
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args([
            "fuse",
            scn.to_str().unwrap(),
            "--json",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["fixes"], 60);
    for f in [
        "nav.csv",
        "innovations.csv",
        "run.toml",
        "report.html",
        "fuse_nis.svg",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let nav = std::fs::read_to_string(out.join("nav.csv")).unwrap();
    assert!(nav.lines().count() > 290);
    assert!(j.get("gyro_scale_est_ppm").is_none());
    // the 21-state filter: its estimates and the truth in the summary and run.toml
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["fuse", scn.to_str().unwrap(), "--json", "--out"])
        .arg(&out)
        .args(["--scale-factors-ppm", "300,500"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["gyro_scale_true_ppm"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(j["gyro_scale_est_ppm"].as_array().unwrap().len(), 3);
    let run = std::fs::read_to_string(out.join("run.toml")).unwrap();
    assert!(run.contains("scale_factor_prior_gyro_ppm = 500"), "{run}");
    for bad in [
        ["--cov-rate-hz", "nan"],
        ["--nhc-sigma-mps=-1", ""],
        ["--samples", "5"],
        ["--algo", "kalman"],
        ["--scale-factors-ppm", "300"],
        ["--scale-factors-ppm", "300,nan"],
        ["--scale-factors-ppm", "0,300"],
        ["--scale-factors-ppm", "300,1e6"],
    ] {
        let bad: Vec<&str> = bad.iter().copied().filter(|a| !a.is_empty()).collect();
        let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
            .args([
                "fuse",
                scn.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ])
            .args(&bad)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        let name = bad[0].split('=').next().unwrap();
        assert!(String::from_utf8_lossy(&o.stderr).contains(name), "{bad:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Recorded data: `sdins truth` of the test scenario gives imu.csv and truth.csv; an sdins
/// GNSS CSV is written from the truth rows (exact positions, stated σ). The exact IMU and
/// exact fixes must give a solution at the truth within a few σ, and every input class
/// of the GNSS file is refused with file:line and exit 2.
#[test]
fn fuse_on_recorded_files_and_bad_gnss_files() {
    let dir = std::env::temp_dir().join(format!("sdins-fuse-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scn = dir.join("s.toml");
    std::fs::write(&scn, SCN).unwrap();
    let rec = dir.join("rec");
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args([
            "truth",
            scn.to_str().unwrap(),
            "--out",
            rec.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let truth = std::fs::read_to_string(rec.join("truth.csv")).unwrap();
    let mut g = String::from("t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m\n");
    for l in truth.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        let t: f64 = f[0].parse().unwrap();
        if t > 0.0 && (t * 2.0 - (t * 2.0).round()).abs() < 1e-9 {
            g.push_str(&format!("{},{},{},{},1,1,2\n", f[0], f[1], f[2], f[3]));
        }
    }
    let gnss = dir.join("g.csv");
    std::fs::write(&gnss, &g).unwrap();
    let first: Vec<&str> = truth.lines().nth(1).unwrap().split(',').collect();
    let init = format!(
        "{},{},{},{},{},{},{},{},{}",
        first[1], first[2], first[3], first[4], first[5], first[6], first[7], first[8], first[9]
    );
    let run = |gnss: &std::path::Path, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_sdins"))
            .args(["fuse", "--imu"])
            .arg(rec.join("imu.csv"))
            .arg("--gnss")
            .arg(gnss)
            .args(["--grade", "tactical", "--init", &init, "--json", "--out"])
            .arg(dir.join("out"))
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(
        &gnss,
        &[
            "--truth",
            rec.join("truth.csv").to_str().unwrap(),
            "--smooth",
            "--health",
            "warn",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // the fixes are the exact truth with a stated σ of 1, 1, 2 m: the innovations are far
    // smaller than the filter expects, and the health verdict says so (a warning here)
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning: health: nis_windows") && err.contains("mean NIS per fix 0.00"),
        "{err}"
    );
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["fixes_used"], 60);
    assert_eq!(j["health"]["ok"], false);
    assert_eq!(j["rejected"], 0);
    for f in [
        "nav.csv",
        "smoothed.csv",
        "innovations.csv",
        "run.toml",
        "report.html",
        "fuse_forward.png",
        "fuse_smoothed.png",
        "fuse_nis.png",
    ] {
        assert!(dir.join("out").join(f).exists(), "{f}");
    }
    // 60 fixes of σ 1 m: the position RMSE is well inside the fix σ
    for ax in ["N", "E"] {
        let r = j["forward_vs_truth"][ax]["rmse"].as_f64().unwrap();
        assert!(r < 1.0, "{ax}: {r}");
        let s = j["smoothed_vs_truth"][ax]["rmse"].as_f64().unwrap();
        assert!(s < 1.0, "{ax}: {s}");
    }
    // input classes of the GNSS file
    let header = "t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m\n";
    let cases = [
        ("empty", String::new(), "g-empty.csv"),
        ("header only", header.to_string(), "g-header.csv:1"),
        (
            "NaN",
            format!("{header}1,37.5,127,0,1,1,nan\n"),
            "g-nan.csv:2",
        ),
        (
            "time backwards",
            format!("{header}2,37.5,127,0,1,1,2\n1,37.5,127,0,1,1,2\n"),
            "g-back.csv:3",
        ),
        (
            "sigma <= 0",
            format!("{header}1,37.5,127,0,0,1,2\n"),
            "g-sigma.csv:2",
        ),
        (
            "latitude",
            format!("{header}1,95,127,0,1,1,2\n"),
            "g-lat.csv:2",
        ),
        (
            "no overlap",
            format!("{header}1000,37.5,127,0,1,1,2\n"),
            "g-late.csv",
        ),
    ];
    for (what, text, want) in cases {
        let name = want.split(':').next().unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        let o = run(&p, &["--gnss-format", "sdins"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert!(err.contains(want), "{what}: `{err}` lacks `{want}`");
    }
    // the model and the initial state are required
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["fuse", "--imu"])
        .arg(rec.join("imu.csv"))
        .arg("--gnss")
        .arg(&gnss)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--grade"));
    std::fs::remove_dir_all(&dir).ok();
}

/// Output size cap (nothing silent, resource bounds): an IMU file whose rows would give a
/// nav.csv above the per-file cap is refused before anything is read or written (a sparse
/// 10 GB file: no disk space used).
#[test]
fn fuse_refuses_outputs_above_the_size_cap() {
    let dir = std::env::temp_dir().join(format!("sdins-fuse-cap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let imu = dir.join("huge.csv");
    let f = std::fs::File::create(&imu).unwrap();
    f.set_len(10_000_000_000).unwrap();
    let g = dir.join("g.csv");
    std::fs::write(
        &g,
        "t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m\n1,37.5,127,0,1,1,2\n",
    )
    .unwrap();
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["fuse", "--imu"])
        .arg(&imu)
        .arg("--gnss")
        .arg(&g)
        .args([
            "--grade",
            "tactical",
            "--init",
            "37.5,127,0,0,0,0,0,0,0",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("cap"), "{err}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).ok();
}
