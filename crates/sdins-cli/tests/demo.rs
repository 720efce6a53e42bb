//! `sdins demo` end to end (release, `#[ignore]`): the report exists, every table row is
//! there, and its numbers equal those of the individual `sdins run` commands.
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
#[ignore = "runs the full demo (90-minute scenarios): release mode with --ignored"]
fn demo_report_complete_and_consistent_with_run() {
    let d = std::env::temp_dir().join(format!("sdins-demo-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    let (code, out, err) = sdins(&["demo", "--out", d.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(d.join("report.html")).unwrap();
    let lower = html.to_ascii_lowercase();
    for bad in [
        "<script", "<link", "<img", " src=", " href=", "url(", "@import",
    ] {
        assert!(!lower.contains(bad), "report.html contains {bad}");
    }
    for needle in [
        "1. Song–Lee Table 1",
        "2. 90°/s turn",
        "3. The dual-quaternion paper",
        "5. Schuler share",
        "Savage, S1 Table 1 (reconstructed)",
        "Song–Lee, transport attitude (S1 eq. 6)",
        "dual quaternion 2-sample",
        "<svg",
    ] {
        assert!(html.contains(needle), "report lacks {needle}");
    }
    for algo in ["savage", "songlee", "songlee-complete", "dualquat"] {
        assert!(
            html.contains(&format!("<td>{algo}</td>")),
            "report lacks row {algo}"
        );
    }
    // every Schuler-share row (12 grade corners) is printed
    assert_eq!(
        out.lines()
            .filter(|l| l.contains("share ") && l.trim_end().ends_with('%'))
            .count(),
        12,
        "{out}"
    );
    // the demo's mach1-east numbers equal those of `sdins run` on the same scenario
    let (code, json, err) = sdins(&[
        "run",
        "mach1-east",
        "--algo",
        "songlee-complete,savage",
        "--json",
        "--quiet",
        "--out",
        d.join("run").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    for r in v["results"].as_array().unwrap() {
        let algo = r["algo"].as_str().unwrap();
        let p = &r["final"]["pos_err_ned_m"];
        let row = format!(
            "{:<17} {:>11.4e} {:>11.4e} {:>11.4e}",
            algo,
            p[0].as_f64().unwrap(),
            p[1].as_f64().unwrap(),
            p[2].as_f64().unwrap()
        );
        assert!(out.contains(&row), "demo output lacks `{row}`:\n{out}");
    }
}
