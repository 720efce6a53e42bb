//! The raw measurements as RINEX 3.04 observation (C1C, D1C) and navigation files.

use super::{
    nav_to_rinex3, obs_to_rinex3, NavFile, ObsCode, ObsEpoch, ObsFile, ObsHeader, ObsValue, SatObs,
};
use crate::sensors::raw_gnss::RawGnssRecord;
use sdins_core::gnss::LAMBDA_L1_M;

impl RawGnssRecord {
    /// The measurements as an observation file: `C1C` \[m\] and `D1C` = −ρ̇/λ1 \[Hz\]
    /// (RINEX sign: positive for an approaching satellite), one epoch per receiver time
    /// tag, signal strength digit 8.
    pub fn to_obs_file(&self) -> ObsFile {
        let mut epochs: Vec<ObsEpoch> = Vec::new();
        let mut last_t = f64::NAN;
        for o in &self.obs {
            if o.t_s != last_t {
                epochs.push(ObsEpoch {
                    t: o.t_rx,
                    flag: 0,
                    rx_clock_offset_s: None,
                    sats: Vec::new(),
                });
                last_t = o.t_s;
            }
            let v = |value: f64| {
                Some(ObsValue {
                    value,
                    lli: None,
                    ssi: Some(8),
                })
            };
            if let Some(e) = epochs.last_mut() {
                e.sats.push(SatObs {
                    prn: o.prn,
                    values: vec![v(o.pseudorange_m), v(-o.range_rate_mps / LAMBDA_L1_M)],
                });
            }
        }
        let codes = ["C1C", "D1C"]
            .iter()
            .filter_map(|c| ObsCode::new(c))
            .collect();
        ObsFile {
            header: ObsHeader {
                version: 3.04,
                marker_name: "SDINS-SIM".into(),
                receiver_type: "SDINS RAW GNSS SIM".into(),
                approx_position_e_m: self.approx_position_e_m,
                antenna_delta_hen_m: [0.0; 3],
                gps_types: codes,
                interval_s: Some(1.0 / self.rate_hz),
                first_obs: None,
            },
            epochs,
        }
    }

    /// The ephemerides flown (nominal ones included) and the Klobuchar coefficients as a
    /// navigation file.
    pub fn to_nav_file(&self) -> NavFile {
        NavFile {
            version: 3.04,
            klobuchar: Some(self.klobuchar),
            ephemerides: self.ephemerides.clone(),
            skipped_records: 0,
        }
    }

    /// RINEX 3.04 observation text.
    pub fn obs_rinex3(&self) -> String {
        obs_to_rinex3(&self.to_obs_file())
    }

    /// RINEX 3.04 navigation text.
    pub fn nav_rinex3(&self) -> String {
        nav_to_rinex3(&self.to_nav_file())
    }
}
