//! Aiding sensors besides GNSS: barometer, odometer (with the non-holonomic constraint in
//! the vehicle frame), magnetometer, dual-antenna attitude and body velocity. The scenario
//! tables ([`config`]), the simulator from the exact truth ([`sim`]), and the filter's
//! sensor blocks with their priors ([`add_blocks`]) and truths ([`truth_errors`]). The
//! measurement models live in `sdins_core::aiding::sensors`; the equations are in
//! `docs/theory/aiding-sensors.md`.

pub mod config;
pub mod sim;

pub use config::{
    AidingConfig, AidingConfigError, BaroConfig, BodyVelocityConfig, DualAntennaConfig,
    MagnetometerConfig, OdometerConfig,
};
pub use sim::{AidingSimulator, SensorTruth};

use sdins_core::aiding::layout::{
    BlockKind, BlockProcess, Cov, LayoutError, Process, StateLayout, XVec,
};
use sdins_core::aiding::sensors::AidingMeas;

/// `m` with its time of validity moved by `−t0_s` (source clock → filter clock).
pub fn shifted(m: AidingMeas, t0_s: f64) -> AidingMeas {
    let mut m = m;
    match &mut m {
        AidingMeas::Gnss(x) => x.t_s -= t0_s,
        AidingMeas::Zupt(x) => x.t_s -= t0_s,
        AidingMeas::Nhc(x) => x.t_s -= t0_s,
        AidingMeas::Baro(x) => x.t_s -= t0_s,
        AidingMeas::Odometer(x) => x.t_s -= t0_s,
        AidingMeas::BodyVelocity(x) => x.t_s -= t0_s,
        AidingMeas::Magnetometer(x) => x.t_s -= t0_s,
        AidingMeas::DualAntenna(x) => x.t_s -= t0_s,
    }
    m
}

/// The sensor blocks the configured sensors need, appended to `layout`, with their prior
/// variances in `p0` (estimates start at zero):
/// barometer bias (1 state, Gauss–Markov σ, τ as simulated), odometer scale factor
/// (1, random constant), magnetometer hard iron (3, random constants).
pub fn add_blocks(
    cfg: &AidingConfig,
    layout: StateLayout,
    p0: &mut Cov,
) -> Result<StateLayout, LayoutError> {
    let mut layout = layout;
    let mut prior = |layout: &StateLayout, kind, var: f64| {
        if let Some(b) = layout.block(kind) {
            for i in 0..b.dim {
                p0[(b.offset + i, b.offset + i)] = var;
            }
        }
    };
    if let Some(c) = &cfg.baro {
        let p = Process::gauss_markov(c.bias_sigma_m, c.bias_tau_s);
        layout = layout.with(BlockKind::BaroBias, 1, BlockProcess::PerAxis([p; 3]))?;
        prior(&layout, BlockKind::BaroBias, c.bias_sigma_m.powi(2));
    }
    if let Some(c) = &cfg.odometer {
        let p = BlockProcess::PerAxis([Process::CONSTANT; 3]);
        layout = layout.with(BlockKind::OdometerScale, 1, p)?;
        prior(&layout, BlockKind::OdometerScale, c.scale_sigma.powi(2));
    }
    if let Some(c) = &cfg.magnetometer {
        let p = BlockProcess::PerAxis([Process::CONSTANT; 3]);
        layout = layout.with(BlockKind::MagHardIron, 3, p)?;
        prior(
            &layout,
            BlockKind::MagHardIron,
            c.hard_iron_sigma_ut.powi(2),
        );
    }
    Ok(layout)
}

/// The true errors `truth − estimate` of the sensor blocks into `err`.
pub fn truth_errors(layout: &StateLayout, t: &SensorTruth, est: &XVec, err: &mut XVec) {
    if let Some(o) = layout.offset(BlockKind::BaroBias) {
        err[o] = t.baro_bias_m - est[o];
    }
    if let Some(o) = layout.offset(BlockKind::OdometerScale) {
        err[o] = t.odometer_scale - est[o];
    }
    if let Some(o) = layout.offset(BlockKind::MagHardIron) {
        for i in 0..3 {
            err[o + i] = t.hard_iron_ut[i] - est[o + i];
        }
    }
}
