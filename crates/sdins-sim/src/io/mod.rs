//! Readers (and parsers) of outside formats: IMU records ([`imu_file`]), GNSS solutions
//! ([`gnss_file`]), reference trajectories ([`truth_file`], [`reference_file`]), NaveGo
//! parameter files ([`navego_params`]), gnss-ins-sim motion files ([`gnss_ins_sim`]) and
//! initial states ([`initial`]), any delimited text through a column map ([`columns`],
//! [`imu_columns`], [`gnss_columns`], input profiles [`profile`], time bases [`time`]),
//! RINEX GNSS observations and ephemerides ([`rinex`]). Readers never import the scenario format: the scenario
//! loader calls them.

pub mod aiding_file;
pub mod columns;
pub mod gnss_columns;
pub mod gnss_file;
pub mod gnss_ins_sim;
pub mod imu_columns;
pub mod imu_file;
pub mod initial;
pub mod navego_params;
pub mod profile;
pub mod reference_file;
pub mod rinex;
pub mod table;
pub mod time;
pub mod truth_file;
