//! `sdins truth` with a `random_vibration` overlay: bad PSD input exits 2 with a located
//! message; a good one prints the realised and dropped power.
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

#[test]
fn truth_with_random_vibration() {
    let dir = std::env::temp_dir().join(format!("sdins-vib-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scn = |overlay: &str| {
        format!("[start]\nlat_deg = 30.0\nlon_deg = 120.0\n[imu]\nrate_hz = 100.0\n[[segment]]\ntype = \"static\"\nduration_s = 2.0\n[[overlay]]\ntype = \"random_vibration\"\n{overlay}\n")
    };
    std::fs::write(
        dir.join("bad.csv"),
        "freq,x,y,z\n0,1e-3,1e-3,1e-3\n2,1e-3,-1,1e-3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("good.csv"),
        "freq,x,y,z\n0,1e-3,1e-3,1e-3\n20,1e-3,1e-3,1e-3\n",
    )
    .unwrap();
    for (overlay, want) in [
        (
            "accel_psd_file = \"bad.csv\"",
            "bad.csv:3:8: negative PSD -1",
        ),
        (
            "accel_psd_file = \"missing.csv\"",
            "missing.csv: cannot read PSD table",
        ),
        (
            "gyro_psd_breakpoints = [[2.0, 1e-6], [1.0, 1e-6]]",
            "breakpoint 2, entry 1",
        ),
    ] {
        let f = dir.join("s.toml");
        std::fs::write(&f, scn(overlay)).unwrap();
        let (code, err) = sdins(&[
            "truth",
            f.to_str().unwrap(),
            "--quiet",
            "--out",
            dir.join("o").to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(want) && err.contains("s.toml:11"), "{err}");
    }
    let f = dir.join("s.toml");
    std::fs::write(&f, scn("accel_psd_file = \"good.csv\"")).unwrap();
    let (code, err) = sdins(&[
        "truth",
        f.to_str().unwrap(),
        "--quiet",
        "--out",
        dir.join("ok").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    // 2 s window: components at k/2 Hz, k = 1..40 (20 Hz is in the table); DC band [0, 0.25) Hz dropped
    assert!(
        err.contains("random vibration: 40 components, Δf = 0.500000 Hz"),
        "{err}"
    );
    assert!(err.contains("DC 2.500e-4"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
