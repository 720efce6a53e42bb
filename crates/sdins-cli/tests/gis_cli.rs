//! `sdins scenarios import FILE` and a motion CSV passed as a scenario: good input prints
//! a scenario that parses; every bad input class exits 2 with a located message.
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

const GOOD: &str = "ini lat (deg),ini lon (deg),ini alt (m),ini vx_body (m/s),ini vy_body (m/s),ini vz_body (m/s),ini yaw (deg),ini pitch (deg),ini roll (deg)\n32,120,0,0,0,0,0,0,0\ncommand type,yaw (deg),pitch (deg),roll (deg),vx_body (m/s),vy_body (m/s),vz_body (m/s),command duration (s),GPS visibility\n1,0,0,0,1,0,0,5,0\n3,30,0,0,0,0,0,10,1\n";

#[test]
fn import_and_run_motion_files() {
    let dir = std::env::temp_dir().join(format!("sdins-gis-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("good.csv");
    std::fs::write(&good, GOOD).unwrap();
    let g = good.to_str().unwrap();
    let (code, out, err) = sdins(&["scenarios", "import", g, "--mode", "1.0,0.5,2.0"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("[[command]]") && out.contains("outages_s = [[0.0, 5.0]]"),
        "{out}"
    );
    // the relative yaw of 30 deg at 2 deg/s needs 30 s: extended, and said so
    assert!(out.contains("extended"), "{out}");
    let toml = dir.join("my.toml");
    std::fs::write(&toml, &out).unwrap();
    let out_dir = dir.join("out");
    let o = out_dir.to_str().unwrap();
    for scn in [g, toml.to_str().unwrap()] {
        let (code, _, err) = sdins(&["run", scn, "--quiet", "--out", o]);
        assert_eq!(code, 0, "{scn}: {err}");
    }
    let bad = dir.join("bad.csv");
    for (text, want) in [
        (GOOD.replace("3,30,", "9,30,"), "bad.csv:5:1: command type"),
        (
            GOOD.replace(",10,1", ",0,1"),
            "bad.csv:5:8: duration 0 s must be > 0",
        ),
        (GOOD.replace(",10,1", ",10"), "bad.csv:5:1: expected 9"),
        (
            GOOD.replace("32,120", "32,abc"),
            "bad.csv:2:2: `abc` is not a number",
        ),
        (
            GOOD.replace("32,120", "32,NaN"),
            "bad.csv:2:2: `NaN` is not a finite",
        ),
        (
            GOOD.replace(",5,0", ",5.005,0"),
            "bad.csv:4:8: duration 5.005 s is not a whole number",
        ),
    ] {
        std::fs::write(&bad, text).unwrap();
        let (code, _, err) = sdins(&["scenarios", "import", bad.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(want), "{want}: {err}");
        let (code, _, err) = sdins(&["run", bad.to_str().unwrap(), "--quiet", "--out", o]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(&want[..10]), "{want}: {err}");
    }
    for (args, want) in [
        (
            vec!["scenarios", "import", g, "--mode", "1,0,2"],
            "--mode: max angular acceleration",
        ),
        (
            vec!["scenarios", "import", g, "--mode", "1,nan,2"],
            "--mode",
        ),
        (
            vec!["scenarios", "import", g, "--rate-hz", "0"],
            "--rate-hz",
        ),
        (
            vec!["scenarios", "import"],
            "give the motion-definition file",
        ),
        (
            vec!["scenarios", "import", "/nonexistent/m.csv"],
            "cannot read",
        ),
    ] {
        let (code, _, err) = sdins(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(want), "{want}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
