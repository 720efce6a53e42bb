//! End-to-end tests of `sdins montecarlo` and `sdins merge`: shards merged in separate
//! processes give byte-identical statistics to one unsharded run; bad input exits 2.
#![allow(clippy::unwrap_used)]
use std::path::Path;
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

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sdins-mc-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const SMALL: &str = "name = \"small\"\n[start]\nlat_deg = 37.5\nlon_deg = 127.0\nyaw_deg = 30.0\n[imu]\nrate_hz = 50.0\ngrade = \"aviation\"\n[nav]\nsamples = 2\n[[segment]]\ntype = \"static\"\nduration_s = 30.0\n";

fn p(d: &Path, s: &str) -> String {
    d.join(s).display().to_string()
}

#[test]
fn shards_merge_to_the_single_run_byte_for_byte() {
    let d = tmp("shards");
    let scn = p(&d, "small.toml");
    std::fs::write(&scn, SMALL).unwrap();
    let common = [
        "--runs",
        "40",
        "--seed",
        "9",
        "--every-s",
        "5",
        "--block",
        "4",
        "--quiet",
    ];
    let single = p(&d, "single");
    let mut a = vec!["montecarlo", scn.as_str()];
    a.extend(common);
    a.extend(["--threads", "2", "--out", single.as_str()]);
    let (code, out, err) = sdins(&a);
    assert_eq!(code, 0, "{out}{err}");
    let mut shard_dirs = Vec::new();
    for i in 0..4 {
        let dir = p(&d, &format!("s{i}"));
        let sh = format!("{i}/4");
        let mut a = vec!["montecarlo", scn.as_str()];
        a.extend(common);
        a.extend([
            "--threads",
            "1",
            "--shard",
            sh.as_str(),
            "--out",
            dir.as_str(),
            "--json",
        ]);
        let (code, out, err) = sdins(&a);
        assert_eq!(code, 0, "{out}{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["complete"], false);
        shard_dirs.push(dir);
    }
    let all = p(&d, "all");
    let mut m = vec!["merge"];
    m.extend(shard_dirs.iter().rev().map(String::as_str));
    m.extend(["--out", all.as_str(), "--json"]);
    let (code, out, err) = sdins(&m);
    assert_eq!(code, 0, "{out}{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["complete"], true);
    assert_eq!(v["runs_included"], 40);
    let a = std::fs::read(Path::new(&single).join("mc_stats.csv")).unwrap();
    let b = std::fs::read(Path::new(&all).join("mc_stats.csv")).unwrap();
    assert_eq!(a, b);
    let text = String::from_utf8(a).unwrap();
    assert!(text
        .lines()
        .nth(1)
        .unwrap()
        .starts_with("t_s,pos_n_m_mean,pos_n_m_sigma,pos_n_m_p05,pos_n_m_p50,pos_n_m_p95"));
    // rows 0, 5, …, 30 s: the epoch rule keeps the initial state (docs/conventions.md)
    assert_eq!(text.lines().count(), 2 + 7);
    assert!(text.lines().nth(2).unwrap().starts_with("0.0,"));

    // incomplete or overlapping sets are refused with exit code 2
    let (code, _, err) = sdins(&[
        "merge",
        &shard_dirs[0],
        &shard_dirs[2],
        "--out",
        &p(&d, "x"),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("missing"), "{err}");
    let (code, _, err) = sdins(&[
        "merge",
        &shard_dirs[1],
        &shard_dirs[1],
        "--out",
        &p(&d, "x"),
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = sdins(&[
        "merge",
        &shard_dirs[0],
        &shard_dirs[2],
        "--out",
        &p(&d, "x"),
        "--allow-partial",
        "--quiet",
    ]);
    assert_eq!(code, 0);
}

#[test]
fn montecarlo_bad_input_exits_2() {
    let d = tmp("bad");
    let scn = p(&d, "small.toml");
    std::fs::write(&scn, SMALL).unwrap();
    for extra in [
        vec!["--shard", "4/4"],
        vec!["--shard", "x"],
        vec!["--algo", "nope"],
        vec!["--grade", "nope"],
        vec!["--every-s", "0"],
        vec!["--vertical", "up"],
    ] {
        let mut a = vec![
            "montecarlo",
            scn.as_str(),
            "--runs",
            "2",
            "--seed",
            "1",
            "--quiet",
        ];
        a.extend(extra.iter().copied());
        let out = p(&d, "o");
        a.extend(["--out", out.as_str()]);
        let (code, _, err) = sdins(&a);
        assert_eq!(code, 2, "{extra:?}: {err}");
    }
    let (code, _, err) = sdins(&["merge", &scn, "--out", &p(&d, "m")]);
    assert_eq!(code, 2, "{err}");
}
