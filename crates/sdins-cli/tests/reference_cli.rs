//! `sdins truth --from-reference`: a generic CSV through a column map becomes truth and
//! IMU data at reference times; every bad input exits 2 with a located message.
#![allow(clippy::unwrap_used)]
use std::process::Command;

fn sdins(args: &[&str]) -> (i32, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_sdins"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

const MAP: &str = "t_s=time,lat_deg=lat,lon_deg=lon,h_m=alt,roll_deg=r,pitch_deg=p,yaw_deg=y";

/// 4 s of a gentle turn at 10 Hz rows, starting at reference time 100 s.
fn rows() -> String {
    let mut s = String::from("time,lat,lon,alt,r,p,y\n");
    for i in 0..=40 {
        let t = i as f64 * 0.1;
        let lat = 45.0 + 1e-5 * t;
        let lon = 7.0 + 1e-5 * t * (1.0 + 0.01 * t);
        s += &format!("{},{lat},{lon},100,0.5,1.0,{}\n", 100.0 + t, 30.0 + 2.0 * t);
    }
    s
}

#[test]
fn generic_reference_to_truth_and_imu() {
    let dir = std::env::temp_dir().join(format!("sdins-ref-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("log.csv");
    std::fs::write(&f, rows()).unwrap();
    let out = dir.join("out");
    let (rc, err) = sdins(&[
        "truth",
        "--from-reference",
        f.to_str().unwrap(),
        "--columns",
        MAP,
        "--rate-hz",
        "50",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(rc, 0, "{err}");
    assert!(err.contains("41 rows over 4 s from t = 100 s"), "{err}");
    let truth = std::fs::read_to_string(out.join("truth.csv")).unwrap();
    let imu = std::fs::read_to_string(out.join("imu.csv")).unwrap();
    // reference times: the first truth row at 100 s, 200 IMU samples ending at 104 s
    assert!(
        truth
            .lines()
            .nth(1)
            .unwrap()
            .starts_with("100.0,45.0,7.0,100.0,"),
        "{truth:.200}"
    );
    assert_eq!(imu.lines().count(), 1 + 200);
    assert!(imu.lines().last().unwrap().starts_with("104.0,"));
    // the truth passes through the rows: at 102 s (row 20) the yaw is 34°
    let r = truth
        .lines()
        .find(|l| l.starts_with("102.0,"))
        .unwrap()
        .split(',')
        .map(|x| x.parse::<f64>().unwrap())
        .collect::<Vec<_>>();
    assert!(
        (r[9] - 34.0).abs() < 1e-9 && (r[7] - 0.5).abs() < 1e-9,
        "{r:?}"
    );

    let bad = |name: &str, text: &str, extra: &[&str], want: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        let o2 = dir.join("o2");
        let mut a = vec!["truth", "--from-reference", p.to_str().unwrap()];
        a.extend_from_slice(extra);
        a.extend_from_slice(&["--out", o2.to_str().unwrap(), "--quiet"]);
        let (rc, err) = sdins(&a);
        assert_eq!(rc, 2, "{name}: {err}");
        assert!(err.contains(want), "{name}: {err}");
    };
    let r = rows();
    let mut lines: Vec<&str> = r.lines().collect();
    lines[5] = "100.3,45,7,100,0.5,1.0,30";
    bad(
        "back.csv",
        &(lines.join("\n") + "\n"),
        &["--columns", MAP],
        "back.csv:6: t_s: 100.3 s does not increase",
    );
    bad(
        "short.csv",
        "time,lat,lon,alt,r,p,y\n0,45,7,1,0,0,0\n1,45,7,1,0,0,0\n",
        &["--columns", MAP],
        "at least 7 rows",
    );
    bad(
        "cols.csv",
        &r,
        &["--columns", "t_s=time"],
        "--columns: missing `lat_UNIT=COLUMN` (lat_deg or lat_rad)",
    );
    bad(
        "rate.csv",
        &r,
        &["--columns", MAP, "--rate-hz", "0"],
        "--rate-hz: 0",
    );
    bad(
        "earth.csv",
        &r,
        &["--columns", MAP, "--earth", "flat"],
        "--earth: `flat`",
    );
    bad(
        "pitch.csv",
        &r.replace(",1.0,", ",89.5,"),
        &["--columns", MAP],
        "pitch 89.500 deg is beyond ±89 deg",
    );
    // a known format with a wrong header names the file and line
    bad("auto.csv", "t_s,lat_deg,lon\n1,2,3\n", &[], "auto.csv:1:");
    let (rc, err) = sdins(&[
        "truth",
        "--from-reference",
        dir.join("nope.csv").to_str().unwrap(),
    ]);
    assert_eq!(rc, 2, "{err}");
    assert!(err.contains("nope.csv: cannot read"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
