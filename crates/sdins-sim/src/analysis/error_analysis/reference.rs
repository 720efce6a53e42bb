//! Bridges from scenarios and IMU error models to the linear error model
//! ([`super::linear_model`]): the reference trajectory sampled from a scenario's exact
//! truth, and the initial mean/covariance and process noise implied by an
//! [`ImuErrorModel`].
//!
//! * Trajectory: every `step_s` the truth sample gives t, L, h, v^n, `C_b^n` and
//!   `f^b = Δv/δt` (the mean specific force over that IMU sample) → [`SpecificForce::Body`].
//! * Model: fixed biases → the deterministic initial bias state `x0`; turn-on bias σ →
//!   the diagonal of `P0` (random constants); ARW and VRW (μg/√Hz and m/s/√h added in
//!   quadrature) → white process noise; rate random walks → bias random walks. Terms the
//!   linear model does not have (scale factor, misalignment, Gauss–Markov, flicker,
//!   quantization, saturation) are reported by [`unmodelled_terms`].

use super::linear_model::{
    ErrorVector, ModelEarth, ProcessNoise, SpecificForce, StateMat, StateVec, TrajectorySample,
};
use crate::scenario::Scenario;
use crate::sensors::imu_error::{
    ImuErrorModel, DPH, DPHPSH, DPSH, MPS_PER_SQRT_H, UG, UG_PER_SQRT_H, UG_PER_SQRT_HZ,
};
use crate::truth::{TruthConfig, TruthGenerator};
use sdins_core::Vec3;

/// Reference samples of the scenario's truth every `step_s` seconds (rounded to whole IMU
/// samples), from t = 0 to `until_s` (or the end).
pub fn samples_from_scenario(
    scn: &Scenario,
    step_s: f64,
    until_s: Option<f64>,
) -> Vec<TrajectorySample> {
    let earth = scn.nav.earth.model();
    let cfg = TruthConfig {
        earth,
        dt_s: scn.imu.dt_s(),
        lat0_rad: scn.start.lat_rad,
        lon0_rad: scn.start.lon_rad,
        h0_m: scn.start.h_m,
        substeps: scn.nav.substeps,
    };
    let dt = cfg.dt_s;
    let every = ((step_s / dt).round() as u64).max(1);
    let end = until_s.unwrap_or(f64::INFINITY);
    let mut gen = TruthGenerator::new(&scn.trajectory, cfg);
    let init = gen.initial_state();
    let mut out = Vec::new();
    let mut k: u64 = 0;
    let mut first_fb: Option<Vec3> = None;
    let mut pending_first = true;
    for s in gen.by_ref() {
        k += 1;
        if pending_first {
            // the first sample's mean specific force stands for t = 0
            first_fb = Some(s.inc.dv_b_mps / dt);
            pending_first = false;
        }
        if k.is_multiple_of(every) {
            if s.t_s > end + 0.5 * dt {
                break;
            }
            out.push(TrajectorySample {
                t_s: s.t_s,
                lat_rad: s.lat_rad,
                h_m: s.h_m,
                v_n: s.v_n_mps,
                force: SpecificForce::Body {
                    c_b_n: s.c_b_n,
                    f_b: s.inc.dv_b_mps / dt,
                },
            });
        }
    }
    let s0 = TrajectorySample {
        t_s: 0.0,
        lat_rad: init.lat_rad,
        h_m: init.h_m,
        v_n: init.v_n_mps,
        force: SpecificForce::Body {
            c_b_n: init.c_b_n,
            f_b: first_fb.unwrap_or_else(Vec3::zeros),
        },
    };
    out.insert(0, s0);
    out
}

fn v3(a: [f64; 3], unit: f64) -> Vec3 {
    Vec3::new(a[0], a[1], a[2]) * unit
}

/// Initial mean `x0` (fixed biases), covariance `P0` (turn-on bias σ²) and process noise
/// of an error model, at the first reference sample.
pub fn model_statistics(
    model: &ImuErrorModel,
    s0: &TrajectorySample,
    earth: &ModelEarth,
) -> (StateVec, StateMat, ProcessNoise) {
    let mean = ErrorVector {
        b_a: v3(model.accel_bias_ug, UG),
        b_g: v3(model.gyro_bias_dph, DPH),
        ..Default::default()
    };
    let sigma = ErrorVector {
        b_a: v3(model.accel_bias_turn_on_ug, UG),
        b_g: v3(model.gyro_bias_turn_on_dph, DPH),
        ..Default::default()
    };
    let vrw_a = v3(model.accel_vrw_ugpsqrthz, UG_PER_SQRT_HZ);
    let vrw_b = v3(model.accel_vrw_mpsph, MPS_PER_SQRT_H);
    let noise = ProcessNoise {
        arw_rad_per_sqrt_s: v3(model.gyro_arw_dpsh, DPSH),
        vrw_mps_per_sqrt_s: (vrw_a.component_mul(&vrw_a) + vrw_b.component_mul(&vrw_b))
            .map(f64::sqrt),
        accel_bias_rw: v3(model.accel_rrw_ugpsh, UG_PER_SQRT_H),
        gyro_bias_rw: v3(model.gyro_rrw_dphpsh, DPHPSH),
    };
    (
        mean.to_state(s0, earth),
        sigma.to_diag_covariance(s0, earth),
        noise,
    )
}

/// Names of the error-model terms that are set but not represented in the linear model.
pub fn unmodelled_terms(m: &ImuErrorModel) -> Vec<&'static str> {
    let nz3 = |a: &[f64; 3]| a.iter().any(|x| *x != 0.0);
    let nz33 = |a: &[[f64; 3]; 3]| a.iter().flatten().any(|x| *x != 0.0);
    let mut v = Vec::new();
    for (name, on) in [
        ("gyro_bias_gm_dph", nz3(&m.gyro_bias_gm_dph)),
        (
            "gyro_bias_instability_dph",
            nz3(&m.gyro_bias_instability_dph),
        ),
        ("gyro_scale_ppm", nz3(&m.gyro_scale_ppm)),
        ("gyro_scale_asym_ppm", nz3(&m.gyro_scale_asym_ppm)),
        ("gyro_misalignment_mrad", nz33(&m.gyro_misalignment_mrad)),
        (
            "gyro_g_sensitivity_dphpg",
            nz33(&m.gyro_g_sensitivity_dphpg),
        ),
        ("gyro_quantum_arcsec", nz3(&m.gyro_quantum_arcsec)),
        ("gyro_range_dps", m.gyro_range_dps.is_some()),
        ("accel_bias_gm_ug", nz3(&m.accel_bias_gm_ug)),
        (
            "accel_bias_instability_ug",
            nz3(&m.accel_bias_instability_ug),
        ),
        ("accel_scale_ppm", nz3(&m.accel_scale_ppm)),
        ("accel_scale_asym_ppm", nz3(&m.accel_scale_asym_ppm)),
        ("accel_misalignment_mrad", nz33(&m.accel_misalignment_mrad)),
        ("accel_quantum_mps", nz3(&m.accel_quantum_mps)),
        ("accel_range_g", m.accel_range_g.is_some()),
    ] {
        if on {
            v.push(name);
        }
    }
    v
}
