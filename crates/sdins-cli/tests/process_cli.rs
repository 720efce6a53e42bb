//! The process never panics and never touches anything outside its output folder
//! (reliability issue, classes 1–4): every command with stdout on `/dev/full` and on a
//! closed pipe, `[manifest]` names leading out of the folder, stale and live staging
//! folders, user errors in sdins's words with exit 2.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-proc-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn sdins(args: &[&str], stdout: Stdio) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(args)
        .stdout(stdout)
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

/// The write end of a pipe whose read end is already closed: every write gets EPIPE.
fn closed_pipe() -> Stdio {
    let mut fds = [0; 2];
    // SAFETY: pipe fills two file descriptors we then own; the read end is closed at once.
    #[allow(unsafe_code)]
    unsafe {
        assert_eq!(libc::pipe(fds.as_mut_ptr()), 0);
        libc::close(fds[0]);
        use std::os::fd::FromRawFd;
        Stdio::from(std::os::fd::OwnedFd::from_raw_fd(fds[1]))
    }
}

fn dev_full() -> Stdio {
    Stdio::from(std::fs::File::create("/dev/full").unwrap())
}

/// Every entry of `dir` (recursively), to compare an output folder before and after.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                for (n, b) in tree(&p) {
                    v.push((format!("{}/{n}", e.file_name().to_string_lossy()), b));
                }
            } else {
                v.push((
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
    }
    v.sort();
    v
}

/// Each command, with stdout on `/dev/full` and on a closed pipe: exit 1 with a message
/// (`ENOSPC`), exit 141 silently (`EPIPE`), never a panic; the output folder keeps the
/// previous run's files exactly and no staging folder is left.
#[test]
fn every_command_on_a_full_disk_and_a_closed_pipe() {
    let d = tmp("stdout");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    // inputs: a short truth/IMU pair, a Monte Carlo shard, a calibration scenario
    let short = d.join("short.toml");
    std::fs::write(
        &short,
        "name = \"short\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nspeed_mps = 10.0\n\
         [imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"cruise\"\nduration_s = 2.0\n",
    )
    .unwrap();
    let truth_dir = d.join("truth");
    let o = sdins(
        &["truth", &s(&short), "--quiet", "--out", &s(&truth_dir)],
        Stdio::null(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mc = d.join("mc");
    let o = sdins(
        &[
            "montecarlo",
            "turn-90dps",
            "--runs",
            "2",
            "--until-s",
            "2",
            "--quiet",
            "--out",
            &s(&mc),
        ],
        Stdio::null(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let cal = d.join("cal.toml");
    std::fs::write(
        &cal,
        "[start]\nlat_deg = 45.0\nlon_deg = 7.0\n[imu]\nrate_hz = 10.0\ngrade = \"tactical\"\n\
         [calibration]\nschedule = \"6-position\"\ndwell_s = 20.0\nrotation_s = 10.0\n",
    )
    .unwrap();
    let imu = s(&truth_dir.join("imu.csv"));
    let truth = s(&truth_dir.join("truth.csv"));
    let commands: Vec<Vec<String>> = [
        vec!["demo"],
        vec!["scenarios"],
        vec!["scenarios", "turn-90dps"],
        vec!["truth", &s(&short)],
        vec![
            "run",
            "turn-90dps",
            "--algo",
            "savage",
            "--until-s",
            "2",
            "--json",
        ],
        vec!["nav", "--imu", &imu, "--truth", &truth],
        vec!["allan", "--imu", &imu],
        vec!["errors", "--grade", "tactical", "--hours", "1", "--json"],
        vec!["align", "alignment", "--method", "coarse2", "--json"],
        vec!["calibrate", &s(&cal), "--json"],
        vec!["montecarlo", "turn-90dps", "--runs", "2", "--until-s", "2"],
        vec!["merge", &s(&mc)],
        vec!["fuse", "dq-paper", "--json"],
    ]
    .into_iter()
    .map(|v| v.into_iter().map(String::from).collect())
    .collect();
    let mut printing = 0;
    for (i, c) in commands.iter().enumerate() {
        let out = d.join(format!("out{i}"));
        let mut args: Vec<&str> = c.iter().map(String::as_str).collect();
        let out_s = s(&out);
        let help = sdins(&[args[0], "--help"], Stdio::piped());
        if String::from_utf8_lossy(&help.stdout).contains("\n      --quiet") {
            args.push("--quiet");
        }
        if args[0] != "scenarios" {
            args.extend(["--out", &out_s]);
        }
        // a successful run first: it prints, and it leaves the folder a later run replaces
        let ok = sdins(&args, Stdio::piped());
        assert!(
            ok.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&ok.stderr)
        );
        // a command that prints nothing (truth --quiet) must simply succeed
        let prints = !ok.stdout.is_empty();
        printing += usize::from(prints);
        let before = tree(&out);

        let full = sdins(&args, dev_full());
        let err = String::from_utf8_lossy(&full.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        if prints {
            assert_eq!(full.status.code(), Some(1), "{args:?} on /dev/full: {err}");
            assert!(
                err.contains("writing to standard output"),
                "{args:?}: {err}"
            );
            assert_eq!(
                tree(&out),
                before,
                "{args:?} on /dev/full changed the output folder"
            );
        } else {
            assert!(full.status.success(), "{args:?} on /dev/full: {err}");
        }

        let pipe = sdins(&args, closed_pipe());
        let err = String::from_utf8_lossy(&pipe.stderr);
        if prints {
            assert_eq!(
                pipe.status.code(),
                Some(141),
                "{args:?} on a closed pipe: {err}"
            );
            // silently: no error message (progress notes on stderr are the command's own)
            assert!(
                !err.contains("error") && !err.contains("panicked"),
                "{args:?} on a closed pipe printed: {err}"
            );
        } else {
            assert!(pipe.status.success(), "{args:?} on a closed pipe: {err}");
        }
        assert_eq!(
            tree(&out),
            before,
            "{args:?} on a closed pipe changed the output folder"
        );
    }
    assert!(
        printing + 1 >= commands.len(),
        "only {printing} commands printed"
    );
}

#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
#[test]
fn spp_on_a_full_disk_and_a_closed_pipe() {
    let dir = std::env::var_os("SDINS_SHARED_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
        .join("psins_gnss");
    let obs = dir.join("abpo0080.15o");
    let nav = dir.join("abpo0080.15n");
    let args = [
        "spp",
        "--obs",
        obs.to_str().unwrap(),
        "--nav",
        nav.to_str().unwrap(),
        "--every",
        "2000",
    ];
    let full = sdins(&args, dev_full());
    assert_eq!(
        full.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&full.stderr)
    );
    let pipe = sdins(&args, closed_pipe());
    assert_eq!(pipe.status.code(), Some(141));
    assert!(pipe.stderr.is_empty());
}

fn run_into(out: &Path) -> Output {
    sdins(
        &[
            "run",
            "turn-90dps",
            "--algo",
            "savage",
            "--until-s",
            "2",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ],
        Stdio::null(),
    )
}

/// A `[manifest]` name leading out of the folder (`..`, an absolute path, a folder that is
/// a symbolic link) is refused with exit 2 before anything is deleted: the file outside
/// stays.
#[test]
fn manifest_names_never_lead_out_of_the_folder() {
    let d = tmp("manifest");
    let victim = d.join("victim.txt");
    let outside = d.join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(outside.join("x.csv"), "keep").unwrap();
    let link_dir = d.join("out-link");
    for (name, planted) in [
        ("dotdot", vec!["../victim.txt".to_string()]),
        ("absolute", vec![victim.to_str().unwrap().to_string()]),
        // the link itself listed (a file of the run), and a file through it
        ("link", vec!["lnk".to_string(), "lnk/x.csv".to_string()]),
    ] {
        std::fs::write(&victim, "keep").unwrap();
        let out = if name == "link" {
            link_dir.clone()
        } else {
            d.join(name)
        };
        assert!(run_into(&out).status.success());
        if name == "link" {
            std::os::unix::fs::symlink(&outside, out.join("lnk")).unwrap();
        }
        let toml = out.join("run.toml");
        let text = std::fs::read_to_string(&toml).unwrap();
        let entries: String = planted
            .iter()
            .map(|n| format!("  {{ name = {n:?}, bytes = 4 }},\n"))
            .collect();
        let text = text.replacen("files = [\n", &format!("files = [\n{entries}"), 1);
        std::fs::write(&toml, text).unwrap();
        let o = run_into(&out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(
            err.contains("[manifest]") && err.contains("inside the output folder"),
            "{err}"
        );
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
        assert_eq!(
            std::fs::read_to_string(outside.join("x.csv")).unwrap(),
            "keep"
        );
    }
}

/// A staging folder left by a dead run is removed with a notice; one locked by a running
/// process is never touched.
#[test]
fn stale_staging_folders_go_live_ones_stay() {
    let d = tmp("stale");
    let out = d.join("out");
    assert!(run_into(&out).status.success());
    let dead = out.join(".sdins-stage-4000000");
    std::fs::create_dir_all(&dead).unwrap();
    std::fs::write(dead.join("nav_savage.csv"), "partial").unwrap();
    let live = out.join(".sdins-stage-4000001");
    std::fs::create_dir_all(&live).unwrap();
    let lock = std::fs::File::create(live.join(".lock")).unwrap();
    use std::os::fd::AsRawFd;
    // SAFETY: flock on a descriptor this test owns (held until `lock` drops)
    #[allow(unsafe_code)]
    let r = unsafe { libc::flock(lock.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    assert_eq!(r, 0);
    let o = run_into(&out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        !dead.exists(),
        "the dead run's staging folder is still there"
    );
    assert!(
        err.contains(".sdins-stage-4000000") && err.contains("did not finish"),
        "{err}"
    );
    assert!(
        live.join(".lock").exists(),
        "a live staging folder was touched"
    );
    assert!(!err.contains(".sdins-stage-4000001"), "{err}");
    drop(lock);
}

/// User errors exit 2 in sdins's words: a missing merge input, a name too long, `--out`
/// under a file, an algorithm named twice.
#[test]
fn user_errors_exit_2_in_sdins_words() {
    let d = tmp("words");
    let file = d.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let long = d.join("n".repeat(300));
    let under = file.join("sub");
    let missing = d.join("no-such-shard");
    let out = d.join("o");
    let cases: [(Vec<&str>, &str); 4] = [
        (
            vec![
                "merge",
                missing.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            "no such file or folder",
        ),
        (
            vec![
                "run",
                "turn-90dps",
                "--until-s",
                "1",
                "--out",
                long.to_str().unwrap(),
            ],
            "name too long",
        ),
        (
            vec![
                "run",
                "turn-90dps",
                "--until-s",
                "1",
                "--out",
                under.to_str().unwrap(),
            ],
            "is a file, not a folder",
        ),
        (
            vec![
                "run",
                "turn-90dps",
                "--algo",
                "savage,savage",
                "--out",
                out.to_str().unwrap(),
            ],
            "savage is named twice",
        ),
    ];
    for (args, words) in cases {
        let o = sdins(&args, Stdio::null());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(words), "{args:?}: {err}");
        assert!(!err.contains("os error"), "{args:?}: raw OS message: {err}");
    }
}
