//! Sensor-grade presets (docs/imu-errors.md §"Grades").
//!
//! Sources of the table: \[P2\] (Ko, Lee, Park, Kim & Song,
//! "Analysis of SDINS Performance According to Schuler Period Error Effect") for the
//! bias ranges and Groves, *Principles of GNSS, Inertial, and Multisensor Integrated
//! Navigation Systems* (2nd ed.), Tables 4.1/4.2, for the typical biases. The noise
//! values of aviation, tactical and consumer (the published ones) are those of the
//! IMU-error presets in the public companion simulation code of Groves' book; the
//! **marine and intermediate noise values are engineering interpolations** ("assumed"),
//! not published figures. Groves' bias columns are the commonly quoted values of the 2nd
//! edition.
//!
//! **This is the only grade table in sdins** ([`GRADES`]): scenario presets (`grade =`),
//! `sdins errors --grade`, the Monte Carlo and the tests all read it. Its Markdown form is in
//! `docs/imu-errors.md` ([`markdown_table`], kept equal by a test).
//!
//! | grade | accel bias (turn-on σ) | gyro bias (turn-on σ) | VRW | ARW | note |
//! |---|---|---|---|---|---|
//! | `ideal` | 0 | 0 | 0 | 0 | every term off |
//! | `marine` | 10 μg | 0.001 °/h | 15 μg/√Hz | 0.0015 °/√h | noise interpolated (between ≈10–20 μg/√Hz, ≤0.001–0.002 °/√h) |
//! | `aviation` | 50 μg | 0.01 °/h | 20 μg/√Hz | 0.002 °/√h | bias within 30–100 μg; noise from Groves' code |
//! | `intermediate` | 300 μg | 0.1 °/h | 50 μg/√Hz | 0.007 °/√h | bias within 100–1000 μg; noise interpolated ("assumed") |
//! | `tactical` | 1000 μg | 10 °/h | 100 μg/√Hz | 0.01 °/√h | bias within 1–10 mg, 1–100 °/h; noise from Groves' code |
//! | `consumer` | 10 000 μg | 100 °/h | 1000 μg/√Hz | 1 °/√h | bias at the quoted "> 3–10 mg", "> 100 °/h"; noise from Groves' code |
//!
//! Each grade of \[P2\] also carries the paper's own bias box ([`P2Box`]): the ranges the
//! paper sweeps for its Schuler-share table. That is a deliberate second column, not a
//! second sensor: `sdins errors --schuler-share` reproduces the paper over its boxes, while
//! `sdins errors --grade NAME` propagates the row's turn-on σ's. (Until this table was
//! unified the error analysis used its own copy with the lower ends of Groves' ranges —
//! aviation 30 μg, tactical 1 °/h — so its `--grade` results changed with the unification.)
//!
//! The biases are run-to-run **turn-on σ**'s ([`ImuErrorModel::gyro_bias_turn_on_dph`],
//! [`ImuErrorModel::accel_bias_turn_on_ug`]): each run draws its own bias. Where the
//! sources give a range, the value picked inside it is this module's choice. Presets set
//! no scale factor, misalignment, bias instability, quantization or saturation (the
//! table has none); add them with [`ImuErrorModel::with_overrides`] or struct update:
//!
//! ```
//! use sdins_sim::sensors::imu_error::ImuErrorModel;
//! let m = ImuErrorModel { gyro_scale_ppm: [300.0; 3], ..ImuErrorModel::preset("tactical").unwrap() };
//! assert_eq!(m.gyro_arw_dpsh, [0.01; 3]);
//! ```

use super::{ImuErrorModel, ImuErrorModelError, DEG, UG};
use serde::Serialize;

/// \[P2\]'s grade box of one grade: the bias ranges and Schuler-share range the paper
/// reports (docs/theory/error-analysis.md §"The Schuler share"). These are the *paper's* boxes,
/// used only to reproduce its Schuler
/// share table (`sdins errors --schuler-share`); they are not a second set of sensor values
/// (a grade's sensor is the row's turn-on biases and noise).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct P2Box {
    /// accelerometer-bias range \[μg\] (min, max)
    pub accel_bias_ug: (f64, f64),
    /// gyro-bias range \[°/h\] (min, max)
    pub gyro_bias_dph: (f64, f64),
    /// reported Schuler share \[%\] (min, max)
    pub share_pct: (f64, f64),
}

/// One sensor grade: the single source of every grade value in sdins (scenario presets,
/// `sdins errors --grade`, Monte Carlo, tests).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Grade {
    /// grade name (lower case, as accepted by `grade =` and `--grade`)
    pub name: &'static str,
    /// accelerometer turn-on bias σ \[μg\]
    pub accel_bias_turn_on_ug: f64,
    /// gyro turn-on bias σ \[°/h\]
    pub gyro_bias_turn_on_dph: f64,
    /// velocity random walk \[μg/√Hz\]
    pub accel_vrw_ugpsqrthz: f64,
    /// angle random walk \[°/√h\]
    pub gyro_arw_dpsh: f64,
    /// true when the noise values are an engineering interpolation
    pub noise_interpolated: bool,
    /// \[P2\]'s box for this grade, if the paper has one
    pub p2: Option<P2Box>,
}

impl Grade {
    /// VRW in m/s/√s.
    pub fn vrw_si(&self) -> f64 {
        self.accel_vrw_ugpsqrthz * UG
    }
    /// ARW in rad/√s.
    pub fn arw_si(&self) -> f64 {
        self.gyro_arw_dpsh * DEG / 60.0
    }
    /// Accelerometer turn-on bias σ \[m/s²\].
    pub fn accel_bias_si(&self) -> f64 {
        self.accel_bias_turn_on_ug * UG
    }
    /// Gyro turn-on bias σ \[rad/s\].
    pub fn gyro_bias_si(&self) -> f64 {
        self.gyro_bias_turn_on_dph * DEG / 3600.0
    }
    /// The error model of this grade (turn-on biases and white noise, per axis).
    pub fn model(&self) -> ImuErrorModel {
        ImuErrorModel {
            accel_bias_turn_on_ug: [self.accel_bias_turn_on_ug; 3],
            gyro_bias_turn_on_dph: [self.gyro_bias_turn_on_dph; 3],
            accel_vrw_ugpsqrthz: [self.accel_vrw_ugpsqrthz; 3],
            gyro_arw_dpsh: [self.gyro_arw_dpsh; 3],
            ..ImuErrorModel::default()
        }
    }
}

const fn row(
    name: &'static str,
    (ba, bg, vrw, arw): (f64, f64, f64, f64),
    noise_interpolated: bool,
    p2: Option<P2Box>,
) -> Grade {
    Grade {
        name,
        accel_bias_turn_on_ug: ba,
        gyro_bias_turn_on_dph: bg,
        accel_vrw_ugpsqrthz: vrw,
        gyro_arw_dpsh: arw,
        noise_interpolated,
        p2,
    }
}

const fn p2(a: (f64, f64), g: (f64, f64), s: (f64, f64)) -> Option<P2Box> {
    Some(P2Box {
        accel_bias_ug: a,
        gyro_bias_dph: g,
        share_pct: s,
    })
}

/// The grade table (see the module documentation for sources), best grade first.
pub const GRADES: [Grade; 6] = [
    row("ideal", (0.0, 0.0, 0.0, 0.0), false, None),
    row(
        "marine",
        (10.0, 0.001, 15.0, 0.0015),
        true,
        p2((20.0, 30.0), (0.0035, 0.01), (17.5, 33.9)),
    ),
    row(
        "aviation",
        (50.0, 0.01, 20.0, 0.002),
        false,
        p2((30.0, 100.0), (0.01, 0.1), (13.0, 21.2)),
    ),
    row(
        "intermediate",
        (300.0, 0.1, 50.0, 0.007),
        true,
        p2((100.0, 150.0), (0.1, 0.5), (12.8, 16.2)),
    ),
    row("tactical", (1000.0, 10.0, 100.0, 0.01), false, None),
    row("consumer", (10_000.0, 100.0, 1000.0, 1.0), false, None),
];

/// The preset names, best grade first.
pub const GRADE_NAMES: [&str; 6] = [
    GRADES[0].name,
    GRADES[1].name,
    GRADES[2].name,
    GRADES[3].name,
    GRADES[4].name,
    GRADES[5].name,
];

/// Look a grade up by name (case-insensitive; `navigation` is an alias of `aviation`,
/// `automotive` of `consumer`).
pub fn grade(name: &str) -> Option<&'static Grade> {
    let n = name.to_ascii_lowercase();
    let n = match n.as_str() {
        "navigation" => "aviation",
        "automotive" => "consumer",
        other => other,
    };
    GRADES.iter().find(|g| g.name == n)
}

/// The grade preset `name` (one of [`GRADE_NAMES`] or an alias of [`grade`]).
pub fn preset(name: &str) -> Result<ImuErrorModel, ImuErrorModelError> {
    grade(name)
        .map(Grade::model)
        .ok_or_else(|| ImuErrorModelError::UnknownPreset(name.to_string()))
}

/// The grade table as Markdown (docs/imu-errors.md holds this text; a test keeps it equal).
pub fn markdown_table() -> String {
    let mut s = String::from(
        "| grade | accel turn-on bias σ [μg] | gyro turn-on bias σ [°/h] | VRW [μg/√Hz] | ARW [°/√h] | noise source | [P2] box: accel [μg], gyro [°/h], share [%] |\n|---|---|---|---|---|---|---|\n",
    );
    for g in &GRADES {
        let p2 = g.p2.map_or("—".to_string(), |b| {
            format!(
                "{}–{}, {}–{}, {}–{}",
                b.accel_bias_ug.0,
                b.accel_bias_ug.1,
                b.gyro_bias_dph.0,
                b.gyro_bias_dph.1,
                b.share_pct.0,
                b.share_pct.1
            )
        });
        s += &format!(
            "| `{}` | {} | {} | {} | {} | {} | {} |\n",
            g.name,
            g.accel_bias_turn_on_ug,
            g.gyro_bias_turn_on_dph,
            g.accel_vrw_ugpsqrthz,
            g.gyro_arw_dpsh,
            if g.name == "ideal" {
                "—"
            } else if g.noise_interpolated {
                "interpolated"
            } else {
                "Groves' companion code"
            },
            p2
        );
    }
    s
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
        assert_eq!(preset("navigation").unwrap(), a);
        assert!(preset("bogus").is_err());
    }
}
