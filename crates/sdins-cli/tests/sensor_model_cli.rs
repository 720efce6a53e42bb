//! `sdins fuse --sensor-model FILE` (issue 27 part 2): a bad key exits 2 naming the key
//! and its line; `--sensor-model` with `--grade` or `--navego-params` exits 2 naming both;
//! `--grade`'s help lists the real presets; on NaveGo's data (when `$SDINS_SHARED_DATA`
//! or `../shared/data` is present) the model used is written to run.toml.
#![allow(clippy::unwrap_used)]
use std::path::{Path, PathBuf};
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

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-sm-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Tiny IMU and GNSS files: the option errors come before any navigation.
fn files(d: &Path) -> (String, String) {
    let imu = d.join("imu.csv");
    let gnss = d.join("gnss.csv");
    let mut s =
        String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
    for i in 0..20 {
        s += &format!("{},0,0,0,0,0,-0.0980665\n", i as f64 * 0.01);
    }
    std::fs::write(&imu, s).unwrap();
    std::fs::write(&gnss, "t_s,lat_deg,lon_deg,h_m\n0,45,7,100\n0.1,45,7,100\n").unwrap();
    (
        imu.to_str().unwrap().to_string(),
        gnss.to_str().unwrap().to_string(),
    )
}

#[test]
fn bad_key_exits_2_with_key_and_line() {
    let d = tmp("badkey");
    let (imu, gnss) = files(&d);
    let m = d.join("model.toml");
    std::fs::write(
        &m,
        "[imu]\ngyro_arw_dpsh = [0.1, 0.1, 0.1]\n\ngyro_arw_dph = [1, 1, 1]\n",
    )
    .unwrap();
    let ms = m.to_str().unwrap();
    let out = d.join("out");
    let (code, _, err) = sdins(&[
        "fuse",
        "--imu",
        &imu,
        "--gnss",
        &gnss,
        "--sensor-model",
        ms,
        "--attitude-deg",
        "0,0,0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!("{ms}:4:")) && err.contains("gyro_arw_dph"),
        "{err}"
    );
    // a value out of range: its key and line
    std::fs::write(
        &m,
        "[imu]\ngyro_bias_gm_dph = [1, 1, 1]\ngyro_bias_gm_tau_s = [100, -1, 100]\n",
    )
    .unwrap();
    let (code, _, err) = sdins(&[
        "fuse",
        "--imu",
        &imu,
        "--gnss",
        &gnss,
        "--sensor-model",
        ms,
        "--attitude-deg",
        "0,0,0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!("{ms}:3: `imu.gyro_bias_gm_tau_s`")),
        "{err}"
    );
}

#[test]
fn sensor_model_with_grade_or_navego_params_exits_2_naming_both() {
    let d = tmp("both");
    let (imu, gnss) = files(&d);
    let m = d.join("model.toml");
    std::fs::write(&m, "[imu]\ngyro_arw_dpsh = [0.1, 0.1, 0.1]\n").unwrap();
    let ms = m.to_str().unwrap();
    let out = d.join("out");
    for (opt, val) in [("--grade", "tactical"), ("--navego-params", ms)] {
        let (code, _, err) = sdins(&[
            "fuse",
            "--imu",
            &imu,
            "--gnss",
            &gnss,
            "--sensor-model",
            ms,
            opt,
            val,
            "--attitude-deg",
            "0,0,0",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(opt) && err.contains("--sensor-model"), "{err}");
    }
    // and on a scenario: recorded data only
    let (code, _, err) = sdins(&[
        "fuse",
        "dq-paper",
        "--sensor-model",
        ms,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--sensor-model"), "{err}");
}

#[test]
fn grade_help_lists_the_presets() {
    let (code, out, _) = sdins(&["fuse", "--help"]);
    assert_eq!(code, 0);
    let grade = out
        .split("--grade")
        .nth(1)
        .unwrap()
        .split("--navego-params")
        .next()
        .unwrap()
        .to_string();
    for g in sdins_sim::sensors::imu_error::GRADE_NAMES {
        assert!(
            grade.contains(g),
            "{g} missing from --grade's help: {grade}"
        );
    }
}

/// The run.toml of a sensor-model run records the model used, in SI units.
#[test]
fn run_toml_records_the_sensor_model() {
    let base = std::env::var_os("SDINS_SHARED_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let nav = base.join("csv/navego");
    if !nav.is_dir() {
        println!(
            "skipped: {} not found (set SDINS_SHARED_DATA)",
            nav.display()
        );
        return;
    }
    let d = tmp("runtoml");
    let m = d.join("adis.toml");
    // NaveGo's ADIS16405 (imu1) in datasheet units, bias instability by the documented rule
    std::fs::write(
        &m,
        "[imu]\ngyro_arw_dpsh = [2, 2, 2]\naccel_vrw_mpsph = [0.2, 0.2, 0.2]\n\
         gyro_bias_dph = [10800, 10800, 10800]\naccel_bias_ug = [50000, 50000, 50000]\n\
         gyro_bias_turn_on_dph = [624, 624, 624]\naccel_bias_turn_on_ug = [2900, 2900, 2900]\n\
         gyro_bias_instability_dph = [23.3, 23.3, 23.3]\ngyro_bias_instability_tau_s = [189, 189, 189]\n\
         accel_bias_instability_ug = [186, 186, 186]\naccel_bias_instability_tau_s = [189, 189, 189]\n\
         [initial]\nattitude_deg = [0, 0, -15]\nattitude_sigma_deg = [1, 1, 2]\n",
    )
    .unwrap();
    let out = d.join("out");
    let f = |n: &str| nav.join(n).to_str().unwrap().to_string();
    let (code, _, err) = sdins(&[
        "fuse",
        "--imu",
        &f("imu1.csv"),
        "--imu-format",
        "navego",
        "--gnss",
        &f("gnss.csv"),
        "--truth",
        &f("ref.csv"),
        "--samples",
        "1",
        "--sensor-model",
        m.to_str().unwrap(),
        "--health",
        "warn",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let run: toml::Table = std::fs::read_to_string(out.join("run.toml"))
        .unwrap()
        .parse()
        .unwrap();
    let sm = run["sensor_model"].as_table().unwrap();
    assert_eq!(sm["format"].as_str(), Some("sdins-toml"));
    let tau = sm["gyro_bias_tau_s"].as_array().unwrap()[0]
        .as_float()
        .unwrap();
    assert!((tau - 100.0).abs() < 1e-9, "{tau}");
    assert!(sm.contains_key("arw_rad_per_sqrt_s"), "{sm:?}");
}
