//! Aided navigation: one fusion loop ([`engine`]) over a stream of events, fed by
//! scenarios ([`simulated`], the stream from [`scenario_stream`]) and by recorded data
//! ([`records`], with the file front end [`files`]); the Rauch–Tung–Striebel smoother
//! ([`smoother`]); the `sdins fuse` request as one library call ([`request`]). The filter
//! itself is `sdins_core::aiding`.

pub mod detector;
pub mod engine;
pub mod files;
pub mod health;
pub mod kfgins_yaml;
pub mod records;
pub mod request;
pub mod scenario_stream;
pub mod sensor_model;
pub mod simulated;
pub mod smoother;
