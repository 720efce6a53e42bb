//! INS/GNSS filter and smoother on NaveGo's synthetic data set (`../shared/data/csv/navego`),
//! run with the data's own parameters the way NaveGo's example uses them; the RMSE table
//! is in docs/validation.md ("NaveGo INS/GNSS"), reproduced here to 1e-9 relative.
//! Release: `cargo test --release -p sdins-sim --test navego_fuse -- --ignored --nocapture`.
#![allow(clippy::unwrap_used)]

use sdins_core::nav::{AlgorithmKind, AlgorithmSpec};
use sdins_sim::cancel::CancelToken;
use sdins_sim::fusion::files::{fuse_files, FilesInput, InitSource, SensorModelSource};
use sdins_sim::fusion::records::{RecordOptions, COMPARISON_AXES};
use sdins_sim::io::gnss_file::{GnssFormat, GnssReadOptions, ImuClock};
use sdins_sim::io::imu_file::ImuFormat;
use std::path::{Path, PathBuf};

fn data() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/csv/navego");
    if d.is_dir() {
        Some(d)
    } else {
        println!("skipped: {} not found", d.display());
        None
    }
}

/// (forward RMSE, smoothed RMSE, forward inside-3σ, smoothed inside-3σ)
fn run(d: &Path, imu: &str) -> ([f64; 9], [f64; 9], [f64; 9], [f64; 9]) {
    let input = FilesInput {
        imu: (d.join(format!("{imu}.csv")), ImuFormat::NaveGo),
        gnss: (d.join("gnss.csv"), GnssFormat::NaveGo),
        gnss_options: GnssReadOptions::default(),
        clock: ImuClock::SameAsGnss,
        sensor: SensorModelSource::NavegoParams(d.join(format!("{imu}_params.txt"))),
        init: InitSource::FirstFixNavegoAttitude,
        truth: Some(d.join("ref.csv")),
        check_after_s: 30.0,
        columns: Default::default(),
        aiding: None,
    };
    let opts = RecordOptions {
        algo: AlgorithmSpec::new(AlgorithmKind::SongLeeComplete, 1),
        smooth: true,
        ..Default::default()
    };
    let r = fuse_files(&input, &opts, &CancelToken::new(), |_, _| {}).unwrap();
    let f = r.forward.unwrap();
    let s = r.smoothed.unwrap();
    println!(
        "{imu}: {} samples, {} fixes used, {} rejected, matched {} / {}",
        r.imu_samples,
        r.summary.fixes_used,
        r.summary.rejected,
        f.matched(),
        s.matched()
    );
    (f.rmse(), s.rmse(), f.inside_3sigma(), s.inside_3sigma())
}

/// docs/validation.md, "NaveGo INS/GNSS": RMSE over all 200 Hz epochs, roll, pitch, yaw
/// [deg], v_N, v_E, v_D [m/s], N, E, D [m]; (imu, forward, smoothed).
const TABLE: [(&str, [f64; 9], [f64; 9]); 2] =
    [("imu1", IMU1_FWD, IMU1_SMO), ("imu2", IMU2_FWD, IMU2_SMO)];
include!("data/navego_fuse_table.rs");

#[test]
#[ignore]
fn navego_imu1_imu2_forward_and_smoothed() {
    let Some(d) = data() else { return };
    let write = std::env::var_os("SDINS_WRITE_TABLE").is_some();
    let mut out = String::new();
    let mut md = String::from("| IMU | solution | roll [deg] | pitch [deg] | yaw [deg] | v_N [m/s] | v_E [m/s] | v_D [m/s] | N [m] | E [m] | D [m] |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (imu, want_f, want_s) in TABLE {
        let (fr, sr, fi, si) = run(&d, imu);
        let unit = |v: [f64; 9]| {
            let mut u = v;
            for x in u.iter_mut().take(3) {
                *x = x.to_degrees();
            }
            u
        };
        let (fr, sr) = (unit(fr), unit(sr));
        for i in 0..9 {
            println!(
                "{imu} {:>5}: RMSE forward {:.6e} smoothed {:.6e}; inside ±3σ after 30 s: forward {:.4}, smoothed {:.4}",
                COMPARISON_AXES[i], fr[i], sr[i], fi[i], si[i]
            );
            assert!(
                fi[i] >= 0.95 && si[i] >= 0.95,
                "{imu} {}: inside 3σ {} / {}",
                COMPARISON_AXES[i],
                fi[i],
                si[i]
            );
            assert!(
                sr[i] <= fr[i],
                "{imu} {}: smoothed RMSE above forward",
                COMPARISON_AXES[i]
            );
        }
        for (name, v) in [("FWD", fr), ("SMO", sr)] {
            out.push_str(&format!(
                "const {}_{name}: [f64; 9] = {v:?};\n",
                imu.to_uppercase()
            ));
        }
        for (name, v) in [("forward", fr), ("smoothed", sr)] {
            md.push_str(&format!("| {imu} | {name} |"));
            for x in v {
                md.push_str(&format!(" {x:.4} |"));
            }
            md.push('\n');
        }
        if !write {
            for (got, want) in [(fr, want_f), (sr, want_s)] {
                for i in 0..9 {
                    let rel = (got[i] - want[i]).abs() / want[i].abs();
                    assert!(
                        rel <= 1e-9,
                        "{imu} {}: {} vs table {} (rel {rel:e})",
                        COMPARISON_AXES[i],
                        got[i],
                        want[i]
                    );
                }
            }
        }
    }
    println!("{md}");
    let doc = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/validation.md"),
    )
    .unwrap();
    assert!(
        doc.contains(&md),
        "docs/validation.md does not hold the table:\n{md}"
    );
    if write {
        std::fs::write(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/navego_fuse_table.rs"),
            format!("// generated by `SDINS_WRITE_TABLE=1 cargo test --release -p sdins-sim --test navego_fuse -- --ignored`\n{out}"),
        )
        .unwrap();
    }
}
