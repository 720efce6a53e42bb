//! Aided navigation: INS/GNSS fusion on scenarios ([`simulated`]) and on recorded data
//! ([`records`], with the file front end [`files`]), and the Rauch–Tung–Striebel smoother
//! ([`smoother`]). The filter itself is `sdins_core::aiding`.

pub mod files;
pub mod records;
pub mod simulated;
pub mod smoother;
