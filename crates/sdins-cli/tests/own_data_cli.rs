//! `sdins fuse` on one's own files through column maps (docs/own-data.md): the worked
//! example of the docs (increments), run on a logger layout written from an `sdins truth`
//! record, equals the run on sdins's own files to round-off; a rate logger (deg/s, g, RFU
//! axes, GPS seconds of week) equals it within the trapezoid rule's error; bad maps, units
//! and gaps exit 2 naming the option or the file and line.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const SCN: &str = "name = \"own-data\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 10.0\n[imu]\nrate_hz = 100.0\ngrade = \"tactical\"\n[nav]\nsamples = 2\n[[segment]]\ntype = \"turn\"\nrate_dps = 3.0\nduration_s = 30.0\n";

const INIT: &str = "37.5,127,0,10,0,0,0,0,0";

/// The first ```toml block of docs/own-data.md: the worked example's profile.
fn doc_profile() -> String {
    let doc = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/own-data.md"),
    )
    .unwrap();
    let start = doc.find("```toml\n").unwrap() + "```toml\n".len();
    let end = start + doc[start..].find("```").unwrap();
    doc[start..end].to_string()
}

struct Files {
    dir: PathBuf,
    imu: PathBuf,
    gnss: PathBuf,
    truth: PathBuf,
    imu_txt: PathBuf,
    gnss_own: PathBuf,
}

/// An `sdins truth` record, its fixes as an sdins GNSS CSV (σ 1, 1, 2 m) and the same
/// data in the logger's layout: increments in degrees and m/s on RFU axes, milliseconds,
/// whitespace, reordered columns; GNSS heights above mean sea level (N = 30 m), no σ.
fn files(tag: &str) -> Files {
    let dir = std::env::temp_dir().join(format!("sdins-own-{tag}-{}", std::process::id()));
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
    let mut own = String::from("time,latitude,longitude,alt\n");
    for l in truth.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        let t: f64 = f[0].parse().unwrap();
        if t > 0.0 && (t * 2.0 - (t * 2.0).round()).abs() < 1e-9 {
            g.push_str(&format!("{},{},{},{},1,1,2\n", f[0], f[1], f[2], f[3]));
            let h: f64 = f[3].parse().unwrap();
            own.push_str(&format!("{},{},{},{}\n", f[0], f[1], f[2], h - 30.0));
        }
    }
    let gnss = dir.join("g.csv");
    std::fs::write(&gnss, &g).unwrap();
    let gnss_own = dir.join("gnss.csv");
    std::fs::write(&gnss_own, &own).unwrap();
    let imu = rec.join("imu.csv");
    let text = std::fs::read_to_string(&imu).unwrap();
    let mut out = String::from("# logger v1\nfx fy fz stamp wz wy wx\n");
    for l in text.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        // FRD body → RFU sensor: s = (b_y, b_x, −b_z)
        let (dth, dv) = ([v[1], v[2], v[3]], [v[4], v[5], v[6]]);
        let ws = [dth[1], dth[0], -dth[2]].map(f64::to_degrees);
        let fs = [dv[1], dv[0], -dv[2]];
        let ms = (v[0] * 1000.0).round() as i64;
        out.push_str(&format!(
            "{} {} {}   {ms} {} {} {}\n",
            fs[0], fs[1], fs[2], ws[2], ws[1], ws[0]
        ));
    }
    let imu_txt = dir.join("imu.txt");
    std::fs::write(&imu_txt, out).unwrap();
    Files {
        truth: rec.join("truth.csv"),
        dir,
        imu,
        gnss,
        imu_txt,
        gnss_own,
    }
}

fn fuse(f: &Files, imu: &Path, gnss: &Path, out: &str, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["fuse", "--imu"])
        .arg(imu)
        .arg("--gnss")
        .arg(gnss)
        // the fixes are exact (no noise): the NIS is ~0, outside its χ² band, and the
        // health check would exit 3; these runs compare solutions, not the filter's tuning
        .args([
            "--grade", "tactical", "--init", INIT, "--json", "--health", "warn", "--out",
        ])
        .arg(f.dir.join(out))
        .arg("--truth")
        .arg(&f.truth)
        .args(extra)
        .output()
        .unwrap()
}

fn rmse(o: &Output) -> Vec<f64> {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    ["roll", "pitch", "yaw", "v_N", "v_E", "v_D", "N", "E", "D"]
        .iter()
        .map(|k| {
            j["forward_vs_truth"]
                .as_object()
                .unwrap()
                .iter()
                .find(|(name, _)| name.as_str() == *k)
                .map_or_else(
                    || panic!("{k} in {}", j["forward_vs_truth"]),
                    |(_, v)| v["rmse"].as_f64().unwrap(),
                )
        })
        .collect()
}

#[test]
fn worked_example_matches_sdins_files() {
    let f = files("ex");
    let want = rmse(&fuse(&f, &f.imu, &f.gnss, "canonical", &[]));
    let profile = f.dir.join("logger.toml");
    std::fs::write(&profile, doc_profile()).unwrap();
    let o = fuse(
        &f,
        &f.imu_txt,
        &f.gnss_own,
        "profile",
        &["--profile", profile.to_str().unwrap()],
    );
    let got = rmse(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("imu: 3000 rows, time relative"), "{err}");
    let run = std::fs::read_to_string(f.dir.join("profile/run.toml")).unwrap();
    assert!(
        run.contains("[inputs.imu]") && run.contains("[inputs.gnss]"),
        "{run}"
    );
    // the same maps on the command line
    let imu_map = "t_ms=stamp,gyro_x_deg_inc=wx,gyro_y_deg_inc=wy,gyro_z_deg_inc=wz,accel_x_mps_inc=fx,accel_y_mps_inc=fy,accel_z_mps_inc=fz,axes=x:+y,y:+x,z:-z";
    let gnss_map = "t_s=time,lat_deg=latitude,lon_deg=longitude,alt_msl_m=alt";
    let args = [
        "--imu-columns",
        imu_map,
        "--gnss-columns",
        gnss_map,
        "--undulation-m",
        "30",
        "--gnss-sigma",
        "1,1,2",
    ];
    let cli = rmse(&fuse(&f, &f.imu_txt, &f.gnss_own, "cli", &args));
    for i in 0..9 {
        let rel = |a: f64| (a - want[i]).abs() / want[i].abs().max(1e-12);
        println!("{i}: {} {} {}", want[i], got[i], cli[i]);
        assert!(rel(got[i]) < 1e-9, "{i}: {} vs {}", got[i], want[i]);
        assert!(rel(cli[i]) < 1e-9, "{i}: {} vs {}", cli[i], want[i]);
    }
    std::fs::remove_dir_all(&f.dir).ok();
}

#[test]
fn bad_maps_exit_2_naming_the_option() {
    let f = files("bad");
    let imu_map = "t_ms=stamp,gyro_x_deg_inc=wx,gyro_y_deg_inc=wy,gyro_z_deg_inc=wz,accel_x_mps_inc=fx,accel_y_mps_inc=fy,accel_z_mps_inc=fz";
    let gnss_ok = "t_s=time,lat_deg=latitude,lon_deg=longitude,alt_msl_m=alt";
    let reflect = format!("{imu_map},axes=x:+y,y:+x,z:+z");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "--imu-columns",
                &reflect,
                "--gnss-columns",
                gnss_ok,
                "--undulation-m",
                "30",
                "--gnss-sigma",
                "1,1,2",
            ],
            "--imu-columns",
        ),
        (
            vec![
                "--imu-columns",
                imu_map,
                "--gnss-columns",
                gnss_ok,
                "--gnss-sigma",
                "1,1,2",
            ],
            "--gnss-columns",
        ),
        (
            vec![
                "--imu-columns",
                imu_map,
                "--gnss-columns",
                gnss_ok,
                "--undulation-m",
                "30",
            ],
            "--gnss-sigma",
        ),
        (
            vec![
                "--imu-columns",
                "t_ms=stamp,gyro_x_dps=nope",
                "--gnss-columns",
                gnss_ok,
            ],
            "imu.txt:2: gyro_x_dps",
        ),
        (
            vec![
                "--imu-columns",
                imu_map,
                "--gnss-columns",
                gnss_ok,
                "--undulation-m",
                "30",
                "--gnss-sigma",
                "1,1",
            ],
            "--gnss-sigma",
        ),
        (vec!["--gnss-sigma", "1,1,2"], "--gnss-sigma"),
    ];
    let want_words = [
        "reflection",
        "undulation",
        "--gnss-sigma",
        "no column `nope`",
        "3 or 6",
        "column map",
    ];
    for ((args, option), word) in cases.iter().zip(want_words) {
        let o = fuse(&f, &f.imu_txt, &f.gnss_own, "bad", args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(option) && err.contains(word),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    // a bad row is located: file, line, column
    let text = std::fs::read_to_string(&f.imu_txt).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[9] = {
        let mut v: Vec<&str> = lines[9].split_whitespace().collect();
        v[0] = "oops";
        v.join(" ")
    };
    let bad = f.dir.join("bad.txt");
    std::fs::write(&bad, lines.join("\n") + "\n").unwrap();
    let o = fuse(
        &f,
        &bad,
        &f.gnss_own,
        "bad",
        &[
            "--imu-columns",
            imu_map,
            "--gnss-columns",
            gnss_ok,
            "--undulation-m",
            "30",
            "--gnss-sigma",
            "1,1,2",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("bad.txt:10: accel_x_mps_inc: `oops` is not a number"),
        "{err}"
    );
    std::fs::remove_dir_all(&f.dir).ok();
}

/// GPS seconds of week of the record's t = 0 (a whole second: the run clock's origin is
/// then t = 0 and the times match the native files exactly).
const SOW0: f64 = 345_600.0;

/// The rate logger's files: `time,gx,gy,gz,ax,ay,az` in GPS seconds of week, deg/s and g
/// on right-forward-up axes, one row per sample t_k = kδt, k = 0..N (a rate sensor's
/// samples include t = 0); the rate at t_k is the native increment of the interval ending
/// at t_k divided by δt (at t_0 that of the first interval). GNSS `time,lat,lon,alt` in
/// seconds of week with ellipsoidal heights and no σ. Returns the paths and, from the
/// native increments, the bounds of the trapezoid rule's error (below).
fn rate_files(f: &Files) -> (PathBuf, PathBuf, [f64; 2]) {
    let text = std::fs::read_to_string(&f.imu).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let dt = rows[0][0];
    let g0 = 9.80665;
    let mut out = String::from("time,gx,gy,gz,ax,ay,az\n");
    let mut line = |t: f64, v: &[f64]| {
        // FRD body → RFU sensor: s = (b_y, b_x, −b_z)
        let w = [v[2], v[1], -v[3]].map(|x| (x / dt).to_degrees());
        let a = [v[5], v[4], -v[6]].map(|x| x / dt / g0);
        out.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            SOW0 + t,
            w[0],
            w[1],
            w[2],
            a[0],
            a[1],
            a[2]
        ));
    };
    line(0.0, &rows[0]);
    for r in &rows {
        line(r[0], r);
    }
    // Trapezoid error: with ω_k = Δθ_k/δt (ω_0 = ω_1), Δθ'_k = ½(Δθ_{k−1} + Δθ_k), so
    // Σ_{j≤k} Δθ'_j − Δθ_j = ½(Δθ_1 − Δθ_k): the attitude the mapped record integrates
    // differs by at most ½ max_k |Δθ_k − Δθ_1| [rad], the velocity by ½ max_k |Δv_k − Δv_1|
    // [m/s] (the same telescoping sum).
    let mut bound = [0.0f64; 2];
    for r in &rows {
        for i in 0..3 {
            bound[0] = bound[0].max(0.5 * (r[1 + i] - rows[0][1 + i]).abs());
            bound[1] = bound[1].max(0.5 * (r[4 + i] - rows[0][4 + i]).abs());
        }
    }
    let imu = f.dir.join("rates.csv");
    std::fs::write(&imu, out).unwrap();
    let g = std::fs::read_to_string(&f.gnss).unwrap();
    let mut own = String::from("time,lat,lon,alt\n");
    for l in g.lines().skip(1) {
        let v: Vec<&str> = l.split(',').collect();
        let t: f64 = v[0].parse().unwrap();
        own.push_str(&format!("{},{},{},{}\n", SOW0 + t, v[1], v[2], v[3]));
    }
    let gnss = f.dir.join("fixes.csv");
    std::fs::write(&gnss, own).unwrap();
    (imu, gnss, bound)
}

const RATE_MAP: &str = "t_s=time,gyro_x_dps=gx,gyro_y_dps=gy,gyro_z_dps=gz,accel_x_g=ax,accel_y_g=ay,accel_z_g=az,axes=x:+y,y:+x,z:-z,time=gps-sow";
const FIX_MAP: &str = "t_s=time,lat_deg=lat,lon_deg=lon,h_m=alt,time=gps-sow";

#[test]
fn rate_logger_matches_sdins_files_within_the_trapezoid_error() {
    let f = files("rates");
    let (imu, gnss, bound) = rate_files(&f);
    let want = rmse(&fuse(&f, &f.imu, &f.gnss, "canonical", &[]));
    let args = [
        "--imu-columns",
        RATE_MAP,
        "--gnss-columns",
        FIX_MAP,
        "--gnss-sigma",
        "1,1,2",
    ];
    let o = fuse(&f, &imu, &gnss, "rates", &args);
    let got = rmse(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("imu: 3001 rows, time gps-sow"), "{err}");
    let run = std::fs::read_to_string(f.dir.join("rates/run.toml")).unwrap();
    assert!(
        run.contains("[inputs.imu]") && run.contains("time_base = \"gps-sow\""),
        "{run}"
    );
    // |RMSE_a − RMSE_b| ≤ RMS(a − b) ≤ max |a − b|. Attitude: the integrated angle bound
    // ε [rad] (plus the round-off of the decimal deg/s and g text, 1e-12 rad); velocity:
    // the Δv bound plus the tilt it causes, ε g T; position: the velocity bound times T.
    let t_end = 30.0;
    let eps = bound[0] + 1e-12;
    let v_tol = bound[1] + eps * 9.81 * t_end + 1e-12;
    let tol = [
        eps.to_degrees(),
        eps.to_degrees(),
        eps.to_degrees(),
        v_tol,
        v_tol,
        v_tol,
        v_tol * t_end,
        v_tol * t_end,
        v_tol * t_end,
    ];
    println!("trapezoid bound: {} rad, {} m/s", bound[0], bound[1]);
    // the reference through --truth-columns: the same rows in seconds of week, reordered,
    // yaw in radians → the same comparison to round-off
    let tr = std::fs::read_to_string(&f.truth).unwrap();
    let mut own = String::from("sow,yaw,lat,lon,h,vn,ve,vd,roll,pitch\n");
    for l in tr.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        own.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            SOW0 + v[0],
            v[9].to_radians(),
            v[1],
            v[2],
            v[3],
            v[4],
            v[5],
            v[6],
            v[7],
            v[8]
        ));
    }
    let ref_own = f.dir.join("ref_own.csv");
    std::fs::write(&ref_own, own).unwrap();
    let mut a2 = args.to_vec();
    a2.extend(["--truth-columns", "t_s=sow,lat_deg=lat,lon_deg=lon,h_m=h,v_n_mps=vn,v_e_mps=ve,v_d_mps=vd,roll_deg=roll,pitch_deg=pitch,yaw_rad=yaw,time=gps-sow"]);
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["fuse", "--imu"])
        .arg(&imu)
        .arg("--gnss")
        .arg(&gnss)
        .args([
            "--grade", "tactical", "--init", INIT, "--json", "--health", "warn", "--out",
        ])
        .arg(f.dir.join("rates-ref"))
        .arg("--truth")
        .arg(&ref_own)
        .args(&a2)
        .output()
        .unwrap();
    let via_map = rmse(&o);
    for i in 0..9 {
        let d = (via_map[i] - got[i]).abs();
        assert!(
            d <= 1e-9 * got[i].abs().max(1e-9),
            "{i}: {} vs {}",
            via_map[i],
            got[i]
        );
    }
    for i in 0..9 {
        println!("{i}: {} {} (tol {})", want[i], got[i], tol[i]);
        assert!(
            (got[i] - want[i]).abs() <= tol[i],
            "{i}: {} vs {} (tol {})",
            got[i],
            want[i],
            tol[i]
        );
    }
    std::fs::remove_dir_all(&f.dir).ok();
}

#[test]
fn rate_logger_errors_exit_2_located() {
    let f = files("rate-err");
    let (imu, gnss, _) = rate_files(&f);
    let run = |imu_map: &str, imu: &Path| {
        let o = fuse(
            &f,
            imu,
            &gnss,
            "err",
            &[
                "--imu-columns",
                imu_map,
                "--gnss-columns",
                FIX_MAP,
                "--gnss-sigma",
                "1,1,2",
            ],
        );
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        err
    };
    // a reflection (z not flipped with x↔y swapped)
    let e = run(&RATE_MAP.replace("z:-z", "z:+z"), &imu);
    assert!(
        e.contains("--imu-columns") && e.contains("reflection"),
        "{e}"
    );
    // an unknown unit
    let e = run(&RATE_MAP.replace("gyro_x_dps", "gyro_x_rpm"), &imu);
    assert!(
        e.contains("--imu-columns") && e.contains("gyro_x_rpm"),
        "{e}"
    );
    // a gap: lines 102..=104 (samples 100..=102) removed
    let text = std::fs::read_to_string(&imu).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.drain(101..104);
    let gap = f.dir.join("gap.csv");
    std::fs::write(&gap, lines.join("\n") + "\n").unwrap();
    let e = run(RATE_MAP, &gap);
    assert!(
        e.contains("gap.csv:102: t_s: sample interval") && e.contains("a gap"),
        "{e}"
    );
    std::fs::remove_dir_all(&f.dir).ok();
}

/// `nav` and `allan` read the same logger through `--imu-columns` (the IMU-file options
/// every command shares).
#[test]
fn nav_and_allan_read_the_rate_logger() {
    let f = files("nav");
    let (imu, _, bound) = rate_files(&f);
    let nav = |imu: &Path, extra: &[&str], out: &str| {
        let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
            .args(["nav", "--imu"])
            .arg(imu)
            .arg("--truth")
            .arg(&f.truth)
            .args(["--init", INIT, "--json", "--out"])
            .arg(f.dir.join(out))
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let p: Vec<f64> = j["final"]["pos_err_ned_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        (p, String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (want, _) = nav(&f.imu, &[], "nav-native");
    let (got, err) = nav(&imu, &["--imu-columns", RATE_MAP], "nav-map");
    assert!(err.contains("imu: 3001 rows, time gps-sow"), "{err}");
    let run = std::fs::read_to_string(f.dir.join("nav-map/run.toml")).unwrap();
    assert!(
        run.contains("[inputs.imu]") && run.contains("gps-sow"),
        "{run}"
    );
    // free inertial over T = 30 s: the attitude bound ε tilts g into a velocity error
    // ε g T, which integrates to ½ ε g T² in position; plus the Δv bound times T
    let t = 30.0;
    let tol = 0.5 * bound[0] * 9.81 * t * t + bound[1] * t + 1e-9;
    for i in 0..3 {
        println!("nav {i}: {} {} (tol {tol})", want[i], got[i]);
        assert!(
            (got[i] - want[i]).abs() <= tol,
            "{i}: {} vs {}",
            got[i],
            want[i]
        );
    }
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["allan", "--imu"])
        .arg(&imu)
        .args(["--imu-columns", RATE_MAP, "--json", "--out"])
        .arg(f.dir.join("allan"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("imu: 3001 rows"), "{err}");
    // a reflection is refused on nav as on fuse
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(["nav", "--imu"])
        .arg(&imu)
        .args([
            "--init",
            INIT,
            "--imu-columns",
            &RATE_MAP.replace("z:-z", "z:+z"),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--imu-columns") && err.contains("reflection"),
        "{err}"
    );
    std::fs::remove_dir_all(&f.dir).ok();
}
