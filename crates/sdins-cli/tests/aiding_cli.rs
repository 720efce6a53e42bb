//! `sdins fuse --aiding` and `--zupt-detector` from the command line: a scenario's
//! simulated sensors through files, and bad aiding files refused with exit 2 naming the
//! file, table and key.
#![allow(clippy::unwrap_used)]

use std::process::Command;

fn sdins() -> Command {
    Command::new(env!("CARGO_BIN_EXE_sdins"))
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-aiding-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A minimal IMU + GNSS pair in sdins's formats (10 s at 100 Hz, at rest) and an
/// odometer record.
fn files(dir: &std::path::Path) {
    use std::fmt::Write as _;
    let g = 9.80;
    let mut imu =
        String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
    for k in 1..=1000 {
        writeln!(imu, "{},0,0,0,0,0,{}", f64::from(k) * 0.01, -g * 0.01).unwrap();
    }
    std::fs::write(dir.join("imu.csv"), imu).unwrap();
    let mut gnss = String::from("t_s,lat_deg,lon_deg,h_m,sigma_n_m,sigma_e_m,sigma_d_m\n");
    for k in 1..=10 {
        writeln!(gnss, "{k},37.5,127.0,100.0,1,1,2").unwrap();
    }
    std::fs::write(dir.join("gnss.csv"), gnss).unwrap();
    let mut odo = String::from("t_s,speed_mps\n");
    for k in 1..=100 {
        writeln!(odo, "{},0", f64::from(k) * 0.1).unwrap();
    }
    std::fs::write(dir.join("odo.csv"), odo).unwrap();
}

fn fuse(dir: &std::path::Path, aiding: &str, extra: &[&str]) -> std::process::Output {
    std::fs::write(dir.join("aiding.toml"), aiding).unwrap();
    sdins()
        .args(["fuse", "--imu"])
        .arg(dir.join("imu.csv"))
        .arg("--imu-columns")
        .arg("t_s=t_s,dtheta_x_rad=dtheta_x_rad,dtheta_y_rad=dtheta_y_rad,dtheta_z_rad=dtheta_z_rad,dv_x_mps=dv_x_mps,dv_y_mps=dv_y_mps,dv_z_mps=dv_z_mps")
        .arg("--gnss")
        .arg(dir.join("gnss.csv"))
        .arg("--gnss-columns")
        .arg("t_s=t_s,lat_deg=lat_deg,lon_deg=lon_deg,h_m=h_m,sigma_n_m=sigma_n_m,sigma_e_m=sigma_e_m,sigma_d_m=sigma_d_m")
        .args(["--grade", "tactical", "--attitude-deg", "0,0,0", "--health", "warn"])
        .arg("--aiding")
        .arg(dir.join("aiding.toml"))
        .args(extra)
        .arg("--out")
        .arg(dir.join("out"))
        .output()
        .unwrap()
}

#[test]
fn aiding_files_are_fused_and_bad_ones_refused() {
    let dir = tmp("a");
    files(&dir);
    let o = fuse(
        &dir,
        "[odometer]\nfile = \"odo.csv\"\nnhc_sigma_mps = 0.1\n",
        &["--zupt-detector", "--zupt-sigma-mps", "0.01"],
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(out.contains("odometer"), "{out}");
    let run = std::fs::read_to_string(dir.join("out/run.toml")).unwrap();
    assert!(run.contains("[measurements.odometer]"), "{run}");
    for (toml, want) in [
        (
            "[odometer]\nfile = \"odo.csv\"\nrate_hz = 10.0\n",
            "rate_hz: a simulation key",
        ),
        ("[wheel]\nfile = \"odo.csv\"\n", "unknown table `[wheel]`"),
        (
            "[odometer]\nfile = \"odo.csv\"\nsigma_mps = -1.0\n",
            "sigma_mps",
        ),
        (
            "[odometer]\nfile = \"odo.csv\"\nsigmaa_mps = 1.0\n",
            "sigmaa_mps",
        ),
        ("[odometer]\nfile = \"missing.csv\"\n", "missing.csv"),
        (
            "[odometer]\nfile = \"odo.csv\"\ncolumns = \"t_s=t_s,speed_kmh=speed_mps\"\n",
            "speed_kmh",
        ),
    ] {
        let o = fuse(&dir, toml, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{toml}: {err}");
        assert!(err.contains(want), "{toml}: {err}");
    }
    // a ZUPT on recorded data needs the detector
    let o = fuse(&dir, "", &["--zupt-sigma-mps", "0.01"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--zupt-detector"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
