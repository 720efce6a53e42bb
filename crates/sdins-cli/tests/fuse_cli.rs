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
    for f in ["nav.csv", "innovations.csv", "run.toml"] {
        assert!(out.join(f).exists(), "{f}");
    }
    let nav = std::fs::read_to_string(out.join("nav.csv")).unwrap();
    assert!(nav.lines().count() > 290);
    for bad in [
        ["--cov-rate-hz", "nan"],
        ["--nhc-sigma-mps=-1", ""],
        ["--samples", "5"],
        ["--algo", "kalman"],
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
