//! Sensor-grade presets (spec `alignment_and_errors.md` §4.5).
//!
//! Source of the table: spec §4.5, which quotes [P2] (Ko, Lee, Park, Kim & Song,
//! "Analysis of SDINS Performance According to Schuler Period Error Effect") for the
//! bias ranges and Groves, *Principles of GNSS, Inertial, and Multisensor Integrated
//! Navigation Systems* (2nd ed.), Tables 4.1/4.2, for the typical biases. The noise
//! values of aviation, tactical and consumer (**bold** in the spec) are those of the
//! IMU-error presets in the public companion simulation code of Groves' book; the
//! **marine and intermediate noise values are engineering interpolations** (spec
//! §4.5: "assumed"), not published figures. Groves' bias columns are quoted by the
//! spec from memory of the 2nd edition.
//!
//! | grade | accel bias (turn-on σ) | gyro bias (turn-on σ) | VRW | ARW | note |
//! |---|---|---|---|---|---|
//! | `ideal` | 0 | 0 | 0 | 0 | every term off |
//! | `marine` | 10 μg | 0.001 °/h | 15 μg/√Hz | 0.0015 °/√h | noise interpolated (spec: ≈10–20 μg/√Hz, ≤0.001–0.002 °/√h) |
//! | `aviation` | 50 μg | 0.01 °/h | 20 μg/√Hz | 0.002 °/√h | bias within 30–100 μg; noise from Groves' code |
//! | `intermediate` | 300 μg | 0.1 °/h | 50 μg/√Hz | 0.007 °/√h | bias within 100–1000 μg; noise interpolated (spec: "assumed") |
//! | `tactical` | 1000 μg | 10 °/h | 100 μg/√Hz | 0.01 °/√h | bias within 1–10 mg, 1–100 °/h; noise from Groves' code |
//! | `consumer` | 10 000 μg | 100 °/h | 1000 μg/√Hz | 1 °/√h | bias at the spec's "> 3–10 mg", "> 100 °/h"; noise from Groves' code |
//!
//! The biases are run-to-run **turn-on σ**'s ([`ImuErrorModel::gyro_bias_turn_on_dph`],
//! [`ImuErrorModel::accel_bias_turn_on_ug`]): each run draws its own bias. Where the
//! spec gives a range, the value picked inside it is this module's choice. Presets set
//! no scale factor, misalignment, bias instability, quantization or saturation (the
//! table has none); add them with [`ImuErrorModel::with_overrides`] or struct update:
//!
//! ```
//! use sdins_sim::imu_error::ImuErrorModel;
//! let m = ImuErrorModel { gyro_scale_ppm: [300.0; 3], ..ImuErrorModel::preset("tactical").unwrap() };
//! assert_eq!(m.gyro_arw_dpsh, [0.01; 3]);
//! ```

use super::{ImuErrorModel, ImuErrorModelError};

/// The preset names, best grade first.
pub const GRADE_NAMES: [&str; 6] = [
    "ideal",
    "marine",
    "aviation",
    "intermediate",
    "tactical",
    "consumer",
];

/// (accel turn-on bias μg, gyro turn-on bias °/h, VRW μg/√Hz, ARW °/√h); see the table above.
const fn grade(name: &str) -> Option<(f64, f64, f64, f64)> {
    match name.as_bytes() {
        b"ideal" => Some((0.0, 0.0, 0.0, 0.0)),
        b"marine" => Some((10.0, 0.001, 15.0, 0.0015)),
        b"aviation" => Some((50.0, 0.01, 20.0, 0.002)),
        b"intermediate" => Some((300.0, 0.1, 50.0, 0.007)),
        b"tactical" => Some((1000.0, 10.0, 100.0, 0.01)),
        b"consumer" => Some((10_000.0, 100.0, 1000.0, 1.0)),
        _ => None,
    }
}

/// The grade preset `name` (one of [`GRADE_NAMES`]).
pub fn preset(name: &str) -> Result<ImuErrorModel, ImuErrorModelError> {
    let (ba, bg, vrw, arw) =
        grade(name).ok_or_else(|| ImuErrorModelError::UnknownPreset(name.to_string()))?;
    Ok(ImuErrorModel {
        accel_bias_turn_on_ug: [ba; 3],
        gyro_bias_turn_on_dph: [bg; 3],
        accel_vrw_ugpsqrthz: [vrw; 3],
        gyro_arw_dpsh: [arw; 3],
        ..ImuErrorModel::default()
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    #[test]
    fn presets_exist_and_are_ordered() {
        let mut prev = -1.0;
        for name in GRADE_NAMES {
            let m = preset(name).unwrap();
            m.validate().unwrap();
            // grades get worse down the list: ARW strictly increases after `ideal`
            assert!(m.gyro_arw_dpsh[0] > prev, "{name}");
            prev = m.gyro_arw_dpsh[0];
        }
        assert_eq!(preset("ideal").unwrap(), ImuErrorModel::default());
        let t = preset("tactical").unwrap();
        assert_eq!(t.accel_vrw_ugpsqrthz, [100.0; 3]);
        assert_eq!(t.gyro_arw_dpsh, [0.01; 3]);
        let a = preset("aviation").unwrap();
        assert_eq!(a.accel_vrw_ugpsqrthz, [20.0; 3]);
        assert_eq!(a.gyro_arw_dpsh, [0.002; 3]);
        assert!(preset("navigation").is_err());
    }
}
