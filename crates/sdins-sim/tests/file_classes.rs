//! IMU and truth files as a hostile user would give them: the PSINS trajectory CSV that
//! `auto` used to read as FRD, absurd time steps and byte-order marks in truth files.
#![allow(clippy::unwrap_used)]

use sdins_sim::io::imu_file::{read_imu_file, ImuFormat};
use sdins_sim::io::truth_file::{parse_truth_str, MAX_TRUTH_STEP_S};
use std::path::Path;

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data")]
fn psins_trajectory_csv_is_detected_as_rfu() {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/csv/psins/trj10ms_imu.csv");
    if !p.exists() {
        println!("skipped: {} not found", p.display());
        return;
    }
    let d = read_imu_file(&p, ImuFormat::Auto).unwrap();
    assert_eq!(d.format, ImuFormat::PsinsCsv);
    let why = d.detection.unwrap();
    println!("{}: {why}", p.display());
    assert!(why.contains("RFU"), "{why}");
    // the same as reading it with the explicit format
    let e = read_imu_file(&p, ImuFormat::PsinsCsv).unwrap();
    assert_eq!(d.increments, e.increments);
}

const H: &str = "t_s,lat_deg,lon_deg,h_m,v_n_mps,v_e_mps,v_d_mps,roll_deg,pitch_deg,yaw_deg\n";

#[test]
fn truth_steps_bom_and_cut_lines() {
    let p = Path::new("truth.csv");
    let ok = format!("{H}0,37.5,127,10,0,0,0,1,2,3\n0.01,37.5,127,10,0,0,0,1,2,3\n");
    assert_eq!(parse_truth_str(p, &ok).unwrap().len(), 2);
    // byte-order mark accepted
    assert_eq!(
        parse_truth_str(p, &format!("\u{feff}{ok}")).unwrap().len(),
        2
    );
    // a 1e298 s step
    let t = format!("{H}0,37.5,127,10,0,0,0,1,2,3\n1e298,37.5,127,10,0,0,0,1,2,3\n");
    let e = parse_truth_str(p, &t).unwrap_err().to_string();
    assert!(
        e.starts_with("truth.csv:3: column 1 (t_s): step of 1e298 s"),
        "{e}"
    );
    // the largest accepted step
    let t = format!("{H}0,37.5,127,10,0,0,0,1,2,3\n{MAX_TRUTH_STEP_S},37.5,127,10,0,0,0,1,2,3\n");
    assert!(parse_truth_str(p, &t).is_ok());
    // last line cut inside a number without final newline
    let t = format!("{H}0,37.5,127,10,0,0,0,1,2,3\n0.01,37.5,12");
    let e = parse_truth_str(p, &t).unwrap_err().to_string();
    assert!(e.contains("truncated last line"), "{e}");
}
