//! Receiver velocity and clock drift from Doppler (pseudorange-rate) measurements by
//! least squares (Groves 2nd ed. §9.4.1, velocity part).

use super::geometry::{elevation_azimuth, rot_z};
use super::lsq::{Dop, Normal4};
use super::spp::sagnac_range;
use super::{GnssError, C_MPS, MAX_SATS, OMEGA_E_DOT_RPS};
use crate::earth::EarthModel;
use crate::math::{Mat3, Vec3};
use nalgebra::Vector4;

/// One satellite's input to [`solve_velocity`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DopplerSatellite {
    /// PRN
    pub prn: u8,
    /// satellite position at transmission, ECEF of that instant \[m\]
    pub r_sat_e_m: Vec3,
    /// satellite velocity at transmission, relative to ECEF \[m/s\]
    pub v_sat_e_mps: Vec3,
    /// satellite clock drift Δṫ_sv \[s/s\]
    pub clock_drift_sps: f64,
    /// measured pseudorange rate \[m/s\]: `−λ1 D1` for an L1 Doppler D1 in Hz (RINEX sign:
    /// positive for an approaching satellite)
    pub range_rate_mps: f64,
}

/// Options of [`solve_velocity`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocityOptions {
    /// receiver position (from SPP) \[m\]
    pub r_rx_e_m: Vec3,
    /// elevation mask \[rad\]
    pub elevation_mask_rad: f64,
    /// range-rate σ at the zenith \[m/s\]; a satellite at elevation el gets σ / sin el
    pub sigma_zenith_mps: f64,
    /// optional prior on the clock drift, (mean, σ) \[m/s\] (a pseudo-measurement; a
    /// free-running receiver oscillator can drift by tens of m/s, so σ ≥ 100 m/s unless
    /// the drift is known)
    pub drift_prior_mps: Option<(f64, f64)>,
}

/// A Doppler velocity solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocitySolution {
    /// velocity relative to ECEF, resolved in ECEF \[m/s\]
    pub v_e_mps: Vec3,
    /// the same resolved in NED \[m/s\]
    pub v_n_mps: Vec3,
    /// receiver clock drift c·δṫ_r \[m/s\]
    pub clock_drift_mps: f64,
    /// predicted velocity covariance in NED \[(m/s)²\]
    pub cov_vel_n_m2ps2: Mat3,
    /// DOP of the satellites used (infinite when a clock-drift prior let fewer than four
    /// satellites through)
    pub dop: Dop,
    /// satellites used
    pub n_used: usize,
    /// PRNs used (first `n_used`)
    pub prn: [u8; MAX_SATS],
    /// post-fit residuals \[m/s\]
    pub residual_mps: [f64; MAX_SATS],
}

/// Least-squares velocity and clock drift. The measurement model is the derivative of the
/// light-time range (see [`super::geometry::range_rate_mps`]):
/// `ρ̇ = u·(R3(Ω̇e τ)(v_s + Ω̇e×r_s) − (v_r + Ω̇e×r_r)) / (1 + u·v_s^I/c) + c δṫ_r − c Δṫ_sv`,
/// linear in `(v_r, c δṫ_r)` with rows `[−uᵀ/(1 + u·v_s^I/c), 1]`, so one solve is exact.
/// Weights 1/σ², σ = `sigma_zenith_mps / sin el`.
pub fn solve_velocity(
    sats: &[DopplerSatellite],
    o: &VelocityOptions,
) -> Result<VelocitySolution, GnssError> {
    if sats.len() > MAX_SATS {
        return Err(GnssError::TooManySatellites { got: sats.len() });
    }
    let r = o.r_rx_e_m;
    if !(r.iter().all(|v| v.is_finite()) && o.sigma_zenith_mps > 0.0) {
        return Err(GnssError::NonFinite {
            what: "velocity options",
        });
    }
    let (lat, lon, _) = EarthModel::WGS84.geodetic_from_ecef(&r);
    let c = EarthModel::c_e_n(lat, lon);
    let w = Vec3::new(0.0, 0.0, OMEGA_E_DOT_RPS);
    let v_rx_rot = w.cross(&r); // Ω×r of the receiver
    let mut normal = Normal4::new();
    let mut geom = Normal4::new();
    let mut prn = [0u8; MAX_SATS];
    let mut rows = [(Vector4::zeros(), 0.0); MAX_SATS];
    let mut n = 0;
    for s in sats {
        let vals = [s.range_rate_mps, s.clock_drift_sps];
        if !(vals.iter().all(|v| v.is_finite())
            && s.r_sat_e_m
                .iter()
                .chain(s.v_sat_e_mps.iter())
                .all(|v| v.is_finite()))
        {
            return Err(GnssError::NonFinite {
                what: "Doppler satellite input",
            });
        }
        let (rho, rs) = sagnac_range(&s.r_sat_e_m, &r);
        if rho.is_nan() || rho <= 0.0 {
            continue;
        }
        let u = (rs - r) / rho;
        let (el, _) = elevation_azimuth(&c, &u);
        if el < o.elevation_mask_rad {
            continue;
        }
        let rot = rot_z(OMEGA_E_DOT_RPS * rho / C_MPS);
        let vs_i = rot * (s.v_sat_e_mps + w.cross(&s.r_sat_e_m));
        let k = 1.0 + u.dot(&vs_i) / C_MPS;
        // predicted with v_r = 0, drift = 0:
        let pred0 = (u.dot(&vs_i) - u.dot(&v_rx_rot)) / k - C_MPS * s.clock_drift_sps;
        let h = Vector4::new(-u.x / k, -u.y / k, -u.z / k, 1.0);
        let z = s.range_rate_mps - pred0;
        let sig = o.sigma_zenith_mps / libm::sin(el).max(1e-3);
        normal.add(&h, z, 1.0 / (sig * sig));
        let u_n = c * u;
        geom.add(&Vector4::new(-u_n.x, -u_n.y, -u_n.z, 1.0), 0.0, 1.0);
        prn[n] = s.prn;
        rows[n] = (h, z);
        n += 1;
    }
    let need = if o.drift_prior_mps.is_some() { 3 } else { 4 };
    if n < need {
        return Err(GnssError::TooFewSatellites { got: n, need });
    }
    if let Some((mean, sigma)) = o.drift_prior_mps {
        if !(mean.is_finite() && sigma > 0.0 && sigma.is_finite()) {
            return Err(GnssError::NonFinite {
                what: "clock-drift prior",
            });
        }
        normal.add(
            &Vector4::new(0.0, 0.0, 0.0, 1.0),
            mean,
            1.0 / (sigma * sigma),
        );
    }
    let (x, q) = normal.solve()?;
    let dop = match geom.solve() {
        Ok((_, g)) => Dop::from_q(&g),
        Err(_) => Dop {
            gdop: f64::INFINITY,
            pdop: f64::INFINITY,
            hdop: f64::INFINITY,
            vdop: f64::INFINITY,
            tdop: f64::INFINITY,
        },
    };
    let v_e = Vec3::new(x[0], x[1], x[2]);
    let p_e: Mat3 = q.fixed_view::<3, 3>(0, 0).into();
    let mut residual = [0.0; MAX_SATS];
    for i in 0..n {
        residual[i] = rows[i].1 - rows[i].0.dot(&x);
    }
    Ok(VelocitySolution {
        v_e_mps: v_e,
        v_n_mps: c * v_e,
        clock_drift_mps: x[3],
        cov_vel_n_m2ps2: c * p_e * c.transpose(),
        dop,
        n_used: n,
        prn,
        residual_mps: residual,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::gnss::{nominal_constellation, predict, GpsTime, ReceiverState, LAMBDA_L1_M};

    #[test]
    fn exact_range_rates_give_the_velocity_and_drift() {
        let t0 = GpsTime::new(1826, 345_600.0);
        let earth = EarthModel::WGS84;
        let (lat, lon) = (0.6, 2.1);
        let r = earth.ecef_from_geodetic(lat, lon, 300.0);
        let c = EarthModel::c_e_n(lat, lon);
        let v_n = Vec3::new(12.0, -7.5, 0.8);
        let rx = ReceiverState {
            r_e_m: r,
            v_e_mps: c.transpose() * v_n,
            clock_bias_m: 1e4,
            clock_drift_mps: 38.0,
        };
        let mut sats = [DopplerSatellite {
            prn: 0,
            r_sat_e_m: Vec3::zeros(),
            v_sat_e_mps: Vec3::zeros(),
            clock_drift_sps: 0.0,
            range_rate_mps: 0.0,
        }; 24];
        let mut n = 0;
        for e in nominal_constellation(t0).iter() {
            let p = predict(e, &t0, &rx).unwrap();
            // through the Doppler in Hz and back, as a reader would
            let d1_hz = -p.pseudorange_rate_mps / LAMBDA_L1_M;
            sats[n] = DopplerSatellite {
                prn: e.prn,
                r_sat_e_m: p.transit.sat.r_sat_e_m,
                v_sat_e_mps: p.transit.sat.v_sat_e_mps,
                clock_drift_sps: p.transit.sat.clock_drift_sps,
                range_rate_mps: -LAMBDA_L1_M * d1_hz,
            };
            n += 1;
        }
        let o = VelocityOptions {
            r_rx_e_m: r,
            elevation_mask_rad: 0.1,
            sigma_zenith_mps: 0.05,
            drift_prior_mps: None,
        };
        let s = solve_velocity(&sats[..n], &o).unwrap();
        assert!(
            (s.v_n_mps - v_n).norm() < 1e-6,
            "{}",
            (s.v_n_mps - v_n).norm()
        );
        assert!((s.clock_drift_mps - 38.0).abs() < 1e-6);
        assert!(s.n_used >= 4);
        // with a drift prior 3 satellites suffice; without, they are refused
        let o3 = VelocityOptions {
            elevation_mask_rad: -1.6,
            ..o
        };
        assert_eq!(
            solve_velocity(&sats[..3], &o3).unwrap_err(),
            GnssError::TooFewSatellites { got: 3, need: 4 }
        );
        let o3p = VelocityOptions {
            drift_prior_mps: Some((38.0, 1e-3)),
            ..o3
        };
        let s3 = solve_velocity(&sats[..3], &o3p).unwrap();
        assert!(
            (s3.v_n_mps - v_n).norm() < 1e-4,
            "{}",
            (s3.v_n_mps - v_n).norm()
        );
    }
}
