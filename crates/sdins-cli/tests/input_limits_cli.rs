//! Cheap checks before expensive reads, and long set-up steps that stop on Ctrl-C (issue
//! "Nothing silent, round two", classes 7 and 8): a 2 GiB file of NUL bytes given as an
//! IMU, GNSS or reference file is refused on its line 1 without being read (the child's
//! peak resident memory stays below 100 MB); SIGINT during the compilation of a huge route
//! exits 130 at once.
#![allow(clippy::unwrap_used, clippy::expect_used)]
use std::io::Read;
use std::process::{Command, Stdio};

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-limits-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run `sdins args`, returning (exit code, stderr, peak resident set size \[MB\]) from
/// `wait4`'s resource usage of that child alone.
// the child is reaped by `wait4` (for its own resource usage), not by `Child::wait`
#[allow(clippy::zombie_processes)]
fn run_measured(args: &[&str]) -> (i32, String, f64) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value; wait4 writes it and the status for
    // our own child, which is not waited for elsewhere
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut ru) };
    assert_eq!(r, pid);
    let code = if libc::WIFEXITED(status) {
        libc::WEXITSTATUS(status)
    } else {
        -1
    };
    // ru_maxrss is in KiB on Linux
    (code, err, ru.ru_maxrss as f64 / 1024.0)
}

/// A sparse file of 2 GiB of NUL bytes (no disk blocks).
fn sparse(d: &std::path::Path, name: &str) -> std::path::PathBuf {
    let p = d.join(name);
    let f = std::fs::File::create(&p).unwrap();
    f.set_len(2 * 1024 * 1024 * 1024).unwrap();
    p
}

#[test]
fn two_gib_of_nul_bytes_are_refused_on_line_1_without_reading_them() {
    let d = tmp("nul");
    let big = sparse(&d, "big.csv");
    let big_s = big.to_str().unwrap();
    // a small valid IMU file for `fuse --imu ... --gnss big`
    let imu = d.join("imu.csv");
    let mut text =
        String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
    for k in 1..=200 {
        text += &format!("{},0,0,0,0,0,-0.0980665\n", k as f64 * 0.01);
    }
    std::fs::write(&imu, text).unwrap();
    let imu_s = imu.to_str().unwrap();
    let out = d.join("out");
    let out_s = out.to_str().unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec!["nav", "--imu", big_s],
        vec![
            "fuse",
            "--imu",
            imu_s,
            "--gnss",
            big_s,
            "--grade",
            "tactical",
            "--static-s",
            "1",
            "--out",
            out_s,
        ],
        vec!["truth", "--from-reference", big_s, "--out", out_s],
    ];
    for args in cases {
        let (code, err, rss_mb) = run_measured(&args);
        eprintln!(
            "{args:?}: exit {code}, peak RSS {rss_mb:.1} MB: {}",
            err.trim()
        );
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("big.csv") && err.contains("line 1"),
            "{args:?}: {err}"
        );
        // before: the whole file was read (2 GiB, then a second copy of it)
        assert!(rss_mb < 100.0, "{args:?}: peak RSS {rss_mb} MB");
    }
    std::fs::remove_dir_all(&d).ok();
}

/// SIGINT while `sdins truth` compiles a 40 000-waypoint route (tens of seconds of work
/// before any sample): the route compilation polls the token, so the command stops within
/// a second with the documented exit code 130 and no output.
#[test]
fn sigint_stops_the_compilation_of_a_huge_route() {
    use std::fmt::Write as _;
    use std::time::{Duration, Instant};
    let d = tmp("route");
    let mut toml = String::from("[imu]\nrate_hz = 1.0\n");
    for k in 0..40_000 {
        let th = 2.0 * std::f64::consts::PI * (k % 80) as f64 / 80.0;
        let _ = write!(
            toml,
            "[[waypoint]]\nlat_deg = {:.9}\nlon_deg = {:.9}\nspeed_mps = 100.0\n",
            45.0 + 0.459 * th.cos(),
            10.0 + 0.649 * th.sin()
        );
    }
    let scn = d.join("huge-route.toml");
    std::fs::write(&scn, toml).unwrap();
    let out = d.join("out");
    let child = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args([
            "truth",
            scn.to_str().unwrap(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // parsing the TOML takes well under this; the compilation much longer
    std::thread::sleep(Duration::from_millis(2500));
    let sent = Instant::now();
    let st = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let res = child.wait_with_output().unwrap();
    let waited = sent.elapsed();
    let err = String::from_utf8_lossy(&res.stderr);
    assert_eq!(res.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    assert!(
        waited < Duration::from_secs(2),
        "stopped {waited:?} after SIGINT"
    );
    assert!(!out.join("truth.csv").exists());
    std::fs::remove_dir_all(&d).ok();
}

/// One waypoint or command over the stated limit is refused naming the limit and the
/// line, exit 2 (docs/scenarios.md §"Routes", §"Importing gnss-ins-sim motion files").
#[test]
fn size_limits_are_stated_errors() {
    use std::fmt::Write as _;
    let d = tmp("sizes");
    let mut toml = String::from("[imu]\nrate_hz = 1.0\n");
    for k in 0..100_001 {
        let th = 2.0 * std::f64::consts::PI * (k % 80) as f64 / 80.0;
        let _ = write!(
            toml,
            "[[waypoint]]\nlat_deg = {:.6}\nlon_deg = {:.6}\nspeed_mps = 100.0\n",
            45.0 + 0.459 * th.cos(),
            10.0 + 0.649 * th.sin()
        );
    }
    let scn = d.join("too-many-waypoints.toml");
    std::fs::write(&scn, toml).unwrap();
    let (code, err, _) = run_measured(&["truth", scn.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 2, "{err}");
    // the 100 001st [[waypoint]] is on lines 400 003–400 006
    assert!(
        err.contains("100000 [[waypoint]]") && err.contains("too-many-waypoints.toml:40000"),
        "{err}"
    );
    let mut csv = String::from(
        "ini lat (deg),a,b,c,d,e,f,g,h\n32,120,0,0,0,0,0,0,0\ncommand type,a,b,c,d,e,f,g,h\n",
    );
    for _ in 0..1_000_001 {
        csv.push_str("1,0.5,0,0,0,0,0,1,1\n");
    }
    let m = d.join("too-many-commands.csv");
    std::fs::write(&m, csv).unwrap();
    let (code, err, _) = run_measured(&["truth", m.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("1000000 commands") && err.contains("too-many-commands.csv:1000004"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).ok();
}
