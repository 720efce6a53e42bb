//! Output folders: a run's files all or none (staging, then swap), `run.toml` manifests,
//! reused folders, user files never deleted, names that cannot leave the folder, disk full
//! through RLIMIT_FSIZE, and the per-file size cap.
#![allow(clippy::unwrap_used)]
use std::collections::BTreeMap;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::Command;

fn run(args: &[&str], fsize_limit: Option<u64>) -> (i32, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_sdins"));
    c.args(args);
    if let Some(lim) = fsize_limit {
        // SAFETY: only async-signal-safe calls (signal, setrlimit) between fork and exec
        #[allow(unsafe_code)]
        unsafe {
            c.pre_exec(move || {
                // SIGXFSZ ignored: a write past the limit returns EFBIG instead of killing
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let r = libc::rlimit {
                    rlim_cur: lim,
                    rlim_max: lim,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &r) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    let o = c.output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-outputs-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    let _ = std::fs::remove_dir_all(d.with_extension("in"));
    std::fs::create_dir_all(d.with_extension("in")).unwrap();
    d
}

fn scenario(d: &Path, duration_s: f64) -> String {
    let p = d.with_extension("in").join(format!("s{duration_s}.toml"));
    std::fs::write(
        &p,
        format!("[start]\nlat_deg = 37.5\nlon_deg = 127.0\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"static\"\nduration_s = {duration_s}\n"),
    )
    .unwrap();
    p.to_str().unwrap().to_string()
}

/// Every file below `d` with its content.
fn snapshot(d: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(base: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                let rel = p.strip_prefix(base).unwrap().to_string_lossy().into_owned();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    let mut m = BTreeMap::new();
    walk(d, d, &mut m);
    m
}

fn manifest(d: &Path) -> BTreeMap<String, u64> {
    let t: toml::Table = std::fs::read_to_string(d.join("run.toml"))
        .unwrap()
        .parse()
        .unwrap();
    t["manifest"]["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["name"].as_str().unwrap().to_string(),
                f["bytes"].as_integer().unwrap() as u64,
            )
        })
        .collect()
}

#[test]
fn manifest_lists_every_file_and_a_reused_folder_holds_only_the_new_run() {
    let d = tmp("reuse");
    let out = d.to_str().unwrap();
    let (code, err) = run(
        &["truth", &scenario(&d, 1.0), "--out", out, "--quiet"],
        None,
    );
    assert_eq!(code, 0, "{err}");
    let snap = snapshot(&d);
    let m = manifest(&d);
    // the manifest lists exactly the files of the folder besides run.toml, with their sizes
    let listed: BTreeMap<String, u64> = snap
        .iter()
        .filter(|(n, _)| *n != "run.toml")
        .map(|(n, c)| (n.clone(), c.len() as u64))
        .collect();
    assert_eq!(m, listed);
    assert!(
        m.contains_key("truth.csv") && m.contains_key("imu.csv"),
        "{m:?}"
    );

    // another command into the same folder: the truth files of the old run go
    let (code, err) = run(
        &[
            "run",
            &scenario(&d, 2.0),
            "--algo",
            "savage",
            "--out",
            out,
            "--quiet",
        ],
        None,
    );
    assert_eq!(code, 0, "{err}");
    let snap2 = snapshot(&d);
    assert!(
        !snap2.contains_key("truth.csv") && !snap2.contains_key("imu.csv"),
        "{:?}",
        snap2.keys()
    );
    assert!(snap2.contains_key("nav_savage.csv"));
    let m2 = manifest(&d);
    assert_eq!(m2.len() + 1, snap2.len(), "{m2:?} vs {:?}", snap2.keys());
    for (n, c) in &snap2 {
        if n != "run.toml" {
            assert_eq!(m2[n], c.len() as u64, "{n}");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
    let _ = std::fs::remove_dir_all(d.with_extension("in"));
}

#[test]
fn a_folder_with_files_no_manifest_lists_is_refused_and_kept() {
    let d = tmp("foreign");
    let out = d.to_str().unwrap();
    let (code, err) = run(
        &["truth", &scenario(&d, 1.0), "--out", out, "--quiet"],
        None,
    );
    assert_eq!(code, 0, "{err}");
    std::fs::write(d.join("my notes.txt"), "mine").unwrap();
    let before = snapshot(&d);
    let (code, err) = run(
        &["truth", &scenario(&d, 2.0), "--out", out, "--quiet"],
        None,
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("my notes.txt") && err.contains("manifest"),
        "{err}"
    );
    assert_eq!(snapshot(&d), before);
    // a folder of another program's files (no run.toml) is refused too
    let d2 = tmp("foreign2");
    std::fs::create_dir_all(&d2).unwrap();
    std::fs::write(d2.join("data.csv"), "x").unwrap();
    let (code, err) = run(
        &[
            "truth",
            &scenario(&d2, 1.0),
            "--out",
            d2.to_str().unwrap(),
            "--quiet",
        ],
        None,
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("data.csv"), "{err}");
    assert_eq!(std::fs::read_to_string(d2.join("data.csv")).unwrap(), "x");
    assert_eq!(std::fs::read_dir(&d2).unwrap().count(), 1);
    // a nested folder of another run (its own manifest) is neither foreign nor replaced
    let d3 = tmp("nested");
    let (code, err) = run(
        &[
            "truth",
            &scenario(&d3, 1.0),
            "--out",
            d3.to_str().unwrap(),
            "--quiet",
        ],
        None,
    );
    assert_eq!(code, 0, "{err}");
    let inner = d3.join("shard0");
    let (code, err) = run(
        &[
            "truth",
            &scenario(&d3, 1.0),
            "--out",
            inner.to_str().unwrap(),
            "--quiet",
        ],
        None,
    );
    assert_eq!(code, 0, "{err}");
    let inner_before = snapshot(&inner);
    let (code, err) = run(
        &[
            "truth",
            &scenario(&d3, 2.0),
            "--out",
            d3.to_str().unwrap(),
            "--quiet",
        ],
        None,
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(snapshot(&inner), inner_before);
    assert!(!manifest(&d3).keys().any(|k| k.starts_with("shard0")));
    let _ = std::fs::remove_dir_all(&d3);
    let _ = std::fs::remove_dir_all(d3.with_extension("in"));
    for p in [&d, &d2] {
        let _ = std::fs::remove_dir_all(p);
        let _ = std::fs::remove_dir_all(p.with_extension("in"));
    }
}

#[test]
fn a_file_size_limit_leaves_the_previous_run_untouched() {
    let d = tmp("fsize");
    let out = d.to_str().unwrap();
    let (code, err) = run(
        &["truth", &scenario(&d, 1.0), "--out", out, "--quiet"],
        None,
    );
    assert_eq!(code, 0, "{err}");
    let before = snapshot(&d);
    // 60 s at 100 Hz: imu.csv and truth.csv are each ≥ 6000 rows, far above 64 KiB
    let (code, err) = run(
        &["truth", &scenario(&d, 60.0), "--out", out, "--quiet"],
        Some(64 * 1024),
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("File too large"), "{err}");
    // the previous run's files, byte for byte, and nothing staged left behind
    assert_eq!(snapshot(&d), before);
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), before.len());
    // into a new folder: no folder, no file
    let fresh = d.join("..").join(format!(
        "{}-fresh",
        d.file_name().unwrap().to_string_lossy()
    ));
    let _ = std::fs::remove_dir_all(&fresh);
    let (code, err) = run(
        &[
            "truth",
            &scenario(&d, 60.0),
            "--out",
            fresh.to_str().unwrap(),
            "--quiet",
        ],
        Some(64 * 1024),
    );
    assert_eq!(code, 1, "{err}");
    assert!(!fresh.exists());
    let _ = std::fs::remove_dir_all(&d);
    let _ = std::fs::remove_dir_all(d.with_extension("in"));
}

#[test]
fn output_size_caps_are_checked_before_writing() {
    let d = tmp("cap");
    let out = d.join("o");
    // 1e6 s at 1 kHz = 1e9 IMU rows, over the 1e8-row cap
    let p = d.with_extension("in").join("long.toml");
    std::fs::write(
        &p,
        "[start]\nlat_deg = 37.5\nlon_deg = 127.0\n[imu]\nrate_hz = 1000.0\n[[segment]]\ntype = \"static\"\nduration_s = 1e6\n",
    )
    .unwrap();
    let (code, err) = run(
        &["truth", p.to_str().unwrap(), "--out", out.to_str().unwrap()],
        None,
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("imu.csv") && err.contains("1.000e9 rows") && err.contains("imu.rate_hz"),
        "{err}"
    );
    let (code, err) = run(
        &[
            "run",
            p.to_str().unwrap(),
            "--algo",
            "savage",
            "--every-s",
            "0.001",
            "--out",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--every-s") && err.contains("rows"), "{err}");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&d);
    let _ = std::fs::remove_dir_all(d.with_extension("in"));
}

/// The epoch rule (docs/conventions.md §"Output epochs") end to end: `sdins run
/// mach1-east --every-s 1` writes 5 401 rows, row k within 3 ms of k s (Δt = 6 ms), the
/// last at 5400.000 s, each with its update's own time.
#[test]
#[ignore = "5400 s at 500 Hz: release mode with --ignored"]
fn run_rows_fall_on_the_grid_without_drift() {
    let dir = std::env::temp_dir().join(format!("sdins-epochs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let st = std::process::Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args([
            "run",
            "mach1-east",
            "--algo",
            "savage",
            "--every-s",
            "1",
            "--quiet",
            "--out",
        ])
        .arg(&dir)
        .status()
        .unwrap();
    assert!(st.success());
    let text = std::fs::read_to_string(dir.join("err_savage.csv")).unwrap();
    let times: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("t_s"))
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(times.len(), 5401);
    for (k, t) in times.iter().enumerate() {
        assert!((t - k as f64).abs() <= 0.003 + 1e-9, "row {k}: t = {t}");
        // the update's own time: a multiple of Δt = 6 ms
        let j = t / 0.006;
        assert!(
            (j - j.round()).abs() < 1e-6,
            "row {k}: t = {t} is not an update time"
        );
    }
    assert_eq!(*times.last().unwrap(), 5400.0);
    let _ = std::fs::remove_dir_all(&dir);
}
