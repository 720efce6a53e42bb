//! `sdins errors` end to end: the JSON is the library's report (`errors_run::errors`)
//! to the last bit, the Schuler-share table likewise, bad input exits 2.
#![allow(clippy::unwrap_used)]
use sdins_sim::analysis::errors_run::{errors, ErrorsOptions};
use sdins_sim::cancel::CancelToken;
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
fn errors_json_is_the_library_report() {
    let dir = std::env::temp_dir().join(format!("sdins-errors-cli-{}", std::process::id()));
    let (code, out, err) = sdins(&[
        "errors",
        "--gyro-bias-dph",
        "0,0.01,0",
        "--accel-bias-ug",
        "30,0,0",
        "--hours",
        "2",
        "--no-nonlinear",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let cli: serde_json::Value = serde_json::from_str(&out).unwrap();
    let lib = errors(
        &ErrorsOptions {
            gyro_bias_dph: Some(vec![0.0, 0.01, 0.0]),
            accel_bias_ug: Some(vec![30.0, 0.0, 0.0]),
            hours: 2.0,
            nonlinear: false,
            ..ErrorsOptions::default()
        },
        &CancelToken::new(),
    )
    .unwrap();
    // byte for byte (serde_json's own float parsing is not round-trip exact, so compare text)
    assert_eq!(
        out.trim_end(),
        serde_json::to_string_pretty(&lib.report).unwrap()
    );
    // epochs 0.5, 1, 2 h; the east gyro bias gives the docs/validation.md §"error propagation" T9
    // closed form ≈ −2013 m N at 2 h (with the accelerometer's share): a finite, nonzero number
    let ep = cli["epochs"].as_array().unwrap();
    assert_eq!(ep.len(), 3);
    assert!(ep[2]["nonlinear"].is_null());
    let _ = std::fs::remove_dir_all(&dir);

    let (code, out, _) = sdins(&["errors", "--schuler-share", "--json"]);
    assert_eq!(code, 0);
    assert_eq!(
        out.trim_end(),
        serde_json::to_string_pretty(
            &sdins_sim::analysis::error_analysis::schuler_share::schuler_share_table_p2()
        )
        .unwrap()
    );

    let (code, _, err) = sdins(&["errors", "--hours=-1", "--grade", "aviation"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--hours: must be in (0, 240], got -1"),
        "{err}"
    );
}
