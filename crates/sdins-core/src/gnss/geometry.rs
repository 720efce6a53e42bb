//! Signal transit time with Earth rotation (Sagnac), predicted range and range rate, line
//! of sight, elevation and azimuth (Groves 2nd ed. §8.5.3 "Range, Range Rate, and Line of
//! Sight" and §8.5.4 "Elevation and Azimuth").

use super::ephemeris::{GpsEphemeris, SatState};
use super::time::GpsTime;
use super::{GnssError, C_MPS, OMEGA_E_DOT_RPS};
use crate::math::{Mat3, Vec3};

/// Receiver kinematic state at the true (GPS system) time of reception.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReceiverState {
    /// antenna position, ECEF \[m\]
    pub r_e_m: Vec3,
    /// antenna velocity relative to ECEF, resolved in ECEF \[m/s\]
    pub v_e_mps: Vec3,
    /// receiver clock bias c·δt_r \[m\] (pseudorange = range + this − c·Δt_sv + …)
    pub clock_bias_m: f64,
    /// receiver clock drift c·δṫ_r \[m/s\]
    pub clock_drift_mps: f64,
}

/// The solved signal path from one satellite to the receiver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transit {
    /// geometric transit time τ \[s\]
    pub tau_s: f64,
    /// GPS system time of transmission t_rx − τ
    pub t_tx: GpsTime,
    /// satellite state at t_tx, in the ECEF frame of t_tx
    pub sat: SatState,
    /// satellite position at t_tx resolved in the ECEF frame of t_rx,
    /// `R3(Ω̇e τ) r_sat(t_tx)` \[m\]
    pub r_sat_rx_e_m: Vec3,
    /// inertial satellite velocity `v + Ω×r` at t_tx, resolved in the ECEF axes of t_rx \[m/s\]
    pub v_sat_inertial_rx_e_mps: Vec3,
    /// geometric range c·τ \[m\]
    pub range_m: f64,
}

/// `R3(θ)`: coordinates of a vector in a frame rotated by +θ about z (the ECEF frame of
/// the reception time is the transmission-time frame turned by θ = Ω̇e τ).
pub fn rot_z(theta_rad: f64) -> Mat3 {
    let (s, c) = (libm::sin(theta_rad), libm::cos(theta_rad));
    Mat3::new(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0)
}

fn omega_e() -> Vec3 {
    Vec3::new(0.0, 0.0, OMEGA_E_DOT_RPS)
}

const TRANSIT_TOL_S: f64 = 1e-14;

/// Solves the light-time equation in the ECEF frame of the reception time:
/// `c τ = |R3(Ω̇e τ) r_sat(t_rx − τ) − r_rx|`, iterating τ from 0.075 s (each iteration
/// shrinks the error by |v_sat|/c ≈ 1e-5, so three reach 1e-14 s; Groves §8.5.3, the
/// Sagnac correction as a frame rotation). `t_rx` is the true GPS system time of
/// reception; the satellite clock does not enter.
pub fn transit(eph: &GpsEphemeris, t_rx: &GpsTime, r_rx_e_m: &Vec3) -> Result<Transit, GnssError> {
    if !(r_rx_e_m.iter().all(|v| v.is_finite()) && t_rx.sow_s.is_finite()) {
        return Err(GnssError::NonFinite {
            what: "receiver position or time",
        });
    }
    let mut tau = 0.075;
    for _ in 0..10 {
        let t_tx = t_rx.add_s(-tau);
        let sat = eph.state(&t_tx)?;
        let rot = rot_z(OMEGA_E_DOT_RPS * tau);
        let r_sat_rx = rot * sat.r_sat_e_m;
        let range = (r_sat_rx - r_rx_e_m).norm();
        let tau_new = range / C_MPS;
        let done = libm::fabs(tau_new - tau) < TRANSIT_TOL_S;
        tau = tau_new;
        if done {
            let t_tx = t_rx.add_s(-tau);
            let sat = eph.state(&t_tx)?;
            let rot = rot_z(OMEGA_E_DOT_RPS * tau);
            let r_sat_rx_e_m = rot * sat.r_sat_e_m;
            return Ok(Transit {
                tau_s: tau,
                t_tx,
                sat,
                r_sat_rx_e_m,
                v_sat_inertial_rx_e_mps: rot * (sat.v_sat_e_mps + omega_e().cross(&sat.r_sat_e_m)),
                range_m: (r_sat_rx_e_m - r_rx_e_m).norm(),
            });
        }
    }
    Err(GnssError::TransitNotConverged)
}

/// Unit line-of-sight vector from the receiver to the satellite, `u = (r_s − r_r)/|r_s − r_r|`,
/// with `r_s` already resolved in the receiver's ECEF frame. `None` for coincident points.
pub fn line_of_sight(r_sat_e_m: &Vec3, r_rx_e_m: &Vec3) -> Option<(Vec3, f64)> {
    let d = r_sat_e_m - r_rx_e_m;
    let n = d.norm();
    if n > 0.0 && n.is_finite() {
        Some((d / n, n))
    } else {
        None
    }
}

/// Elevation and azimuth \[rad\] of a line of sight `los_e` (ECEF unit vector) at a site
/// with `C_e^n` (the project's **NED** frame): `u^n = C_e^n u^e`,
/// el = asin(−u_D), az = atan2(u_E, u_N) ∈ [0, 2π) clockwise from north (Groves §8.5.4).
pub fn elevation_azimuth(c_e_n: &Mat3, los_e: &Vec3) -> (f64, f64) {
    let u = c_e_n * los_e;
    let el = libm::asin((-u.z).clamp(-1.0, 1.0));
    let mut az = libm::atan2(u.y, u.x);
    if az < 0.0 {
        az += 2.0 * core::f64::consts::PI;
    }
    (el, az)
}

/// Geometric range rate from the transit solution and the receiver's ECEF velocity:
/// the derivative of the light-time range with respect to the reception time,
/// `ρ̇ = u·(v_s^I − v_r^I) / (1 + u·v_s^I / c)`, with the inertial velocities
/// `v^I = v + Ω̇e × r` resolved in the ECEF axes of t_rx and `u` the line of sight. The
/// denominator (from dt_tx/dt_rx = 1 − ρ̇/c) is a 3e-6 relative effect, up to 3 mm/s.
pub fn range_rate_mps(tr: &Transit, r_rx_e_m: &Vec3, v_rx_e_mps: &Vec3) -> f64 {
    let u = (tr.r_sat_rx_e_m - r_rx_e_m) / tr.range_m;
    let v_rx_i = v_rx_e_mps + omega_e().cross(r_rx_e_m);
    let us = u.dot(&tr.v_sat_inertial_rx_e_mps);
    (us - u.dot(&v_rx_i)) / (1.0 + us / C_MPS)
}

/// Everything a simulator or a tightly coupled filter predicts for one satellite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prediction {
    /// the light-time solution
    pub transit: Transit,
    /// geometric range ρ \[m\]
    pub range_m: f64,
    /// geometric range rate ρ̇ \[m/s\]
    pub range_rate_mps: f64,
    /// dual-frequency (P(Y) reference) pseudorange without atmosphere:
    /// `ρ + c δt_r − c Δt_sv(t_tx)` \[m\] (IS-GPS-200 §20.3.3.3.3.1). A single-frequency L1
    /// pseudorange adds `c T_GD` (§20.3.3.3.3.2) and the L1 ionospheric and tropospheric delays.
    pub pseudorange_m: f64,
    /// pseudorange rate `ρ̇ + c δṫ_r − c Δṫ_sv` \[m/s\]; the L1 Doppler is `−rate / λ1`
    pub pseudorange_rate_mps: f64,
    /// line of sight, ECEF unit vector receiver → satellite
    pub los_e: Vec3,
}

/// Predicted range, range rate and pseudoranges for a receiver state at the true time of
/// reception `t_rx` (see [`transit`] and [`range_rate_mps`]).
pub fn predict(
    eph: &GpsEphemeris,
    t_rx: &GpsTime,
    rx: &ReceiverState,
) -> Result<Prediction, GnssError> {
    let tr = transit(eph, t_rx, &rx.r_e_m)?;
    let rr = range_rate_mps(&tr, &rx.r_e_m, &rx.v_e_mps);
    let los_e = (tr.r_sat_rx_e_m - rx.r_e_m) / tr.range_m;
    Ok(Prediction {
        transit: tr,
        range_m: tr.range_m,
        range_rate_mps: rr,
        pseudorange_m: tr.range_m + rx.clock_bias_m - C_MPS * tr.sat.clock_bias_s,
        pseudorange_rate_mps: rr + rx.clock_drift_mps - C_MPS * tr.sat.clock_drift_sps,
        los_e,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::earth::EarthModel;
    use crate::gnss::ephemeris::tests::g02;

    fn site() -> Vec3 {
        // ABPO
        Vec3::new(4_097_216.680_5, 4_429_119.028_7, -2_065_771.367_6)
    }

    #[test]
    fn transit_satisfies_its_equation_and_sagnac_matches_the_first_order_formula() {
        let eph = g02();
        let t = eph.toe.add_s(-3000.0);
        let tr = transit(&eph, &t, &site()).unwrap();
        let r_tx = tr.sat.r_sat_e_m;
        let lhs = C_MPS * tr.tau_s;
        let rhs = (rot_z(OMEGA_E_DOT_RPS * tr.tau_s) * r_tx - site()).norm();
        assert!((lhs - rhs).abs() < 1e-5, "{}", lhs - rhs);
        // Sagnac: ρ − |r_s − r_r| ≈ Ω̇e (x_s y_r − y_s x_r)/c (Groves §8.5.3); second
        // order ≈ (Ω̇e τ)² r ≈ 0.5 mm
        let plain = (r_tx - site()).norm();
        let sagnac = OMEGA_E_DOT_RPS * (r_tx.x * site().y - r_tx.y * site().x) / C_MPS;
        assert!(
            (tr.range_m - plain - sagnac).abs() < 2e-3,
            "{}",
            tr.range_m - plain - sagnac
        );
    }

    #[test]
    fn elevation_azimuth_in_ned() {
        let e = EarthModel::WGS84;
        let (lat, lon) = (0.3_f64, -1.2_f64);
        let c = EarthModel::c_e_n(lat, lon);
        let r = e.ecef_from_geodetic(lat, lon, 100.0);
        // straight up
        let up = e.ecef_from_geodetic(lat, lon, 20_000e3) - r;
        let (el, _) = elevation_azimuth(&c, &(up / up.norm()));
        assert!((el - core::f64::consts::FRAC_PI_2).abs() < 1e-9);
        // due east on the horizon: NED (0,1,0)
        let east_e = c.transpose() * Vec3::new(0.0, 1.0, 0.0);
        let (el, az) = elevation_azimuth(&c, &east_e);
        assert!(el.abs() < 1e-12 && (az - core::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // north-west, 30° up
        let v = Vec3::new(
            libm::cos(0.6) * libm::cos(-0.9),
            libm::cos(0.6) * libm::sin(-0.9),
            -libm::sin(0.6),
        );
        let (el, az) = elevation_azimuth(&c, &(c.transpose() * v));
        assert!(
            (el - 0.6).abs() < 1e-12 && (az - (2.0 * core::f64::consts::PI - 0.9)).abs() < 1e-12
        );
    }

    #[test]
    fn range_rate_is_the_derivative_of_the_range() {
        let eph = g02();
        let t = eph.toe.add_s(1200.0);
        let v = Vec3::new(30.0, -20.0, 5.0);
        let h = 0.01;
        let rng = |dt: f64| {
            transit(&eph, &t.add_s(dt), &(site() + v * dt))
                .unwrap()
                .range_m
        };
        let rr_cd = (rng(h) - rng(-h)) / (2.0 * h);
        let tr = transit(&eph, &t, &site()).unwrap();
        let rr = range_rate_mps(&tr, &site(), &v);
        assert!((rr - rr_cd).abs() < 1e-5, "{rr} {rr_cd}");
    }
}
