//! # sdins-core
//!
//! `#![no_std]`, allocation-free strapdown inertial navigation mathematics: attitude
//! representations, the WGS-84 earth model and its variants, coning/sculling
//! compensation and the navigation mechanizations. This crate is what would run on a
//! flight computer; everything here works on fixed-size values.
//!
//! Conventions (stated once for the whole project, see `docs/conventions.md`):
//! * navigation frame `n` is local-level **NED**, body frame `b` is **FRD**;
//! * `c_b_n` is the direction-cosine matrix taking body coordinates to navigation
//!   coordinates, `v_n = c_b_n * v_b`;
//! * quaternions are **Hamilton, scalar first**: `q_b_n` satisfies
//!   `(0, v_n) = q_b_n ⊗ (0, v_b) ⊗ q_b_n*`;
//! * Euler angles are 3-2-1 (yaw, pitch, roll): `c_b_n = Rz(yaw) Ry(pitch) Rx(roll)`;
//! * attitude errors use spec convention G: `c_b_n_est = (I + [eps×]) c_b_n_true`.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod aiding;
pub mod align;
pub mod coning;
pub mod earth;
pub mod math;
pub mod nav;

pub use math::{Mat3, Vec3};
