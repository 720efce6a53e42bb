//! Single-point positioning: iterative weighted least squares for the receiver position and
//! clock bias from pseudoranges (Groves 2nd ed. §9.4.1), with an elevation mask, broadcast
//! ionosphere or the ionosphere-free combination, Saastamoinen troposphere, a stated UERE
//! model, DOP and the NED position covariance.

use super::atmosphere::{
    iono_free_noise_factor, klobuchar_l1_delay_m, saastamoinen_slant_m, KlobucharCoefficients,
};
use super::geometry::{elevation_azimuth, rot_z};
use super::lsq::{Dop, Normal4};
use super::{GnssError, C_MPS, MAX_SATS, OMEGA_E_DOT_RPS};
use crate::earth::EarthModel;
use crate::math::{Mat3, Vec3};
use nalgebra::Vector4;

/// One satellite's input to [`solve_position`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppSatellite {
    /// PRN
    pub prn: u8,
    /// satellite position at its time of transmission, in the ECEF frame of that instant
    /// (computed from the pseudorange: t_tx = t_rx − P/c − Δt_sv, IS-GPS-200 §20.3.3.3.3.1)
    pub r_sat_e_m: Vec3,
    /// satellite clock correction applied to the pseudorange \[s\]: Δt_sv for the
    /// ionosphere-free combination, Δt_sv − T_GD for L1 (IS-GPS-200 §20.3.3.3.3.2)
    pub clock_bias_s: f64,
    /// measured pseudorange (L1 or ionosphere-free) \[m\]
    pub pseudorange_m: f64,
    /// signal-in-space error σ \[m\] (the broadcast URA, or the caller's own figure)
    pub sigma_sis_m: f64,
}

/// Ionosphere handling of an SPP solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IonoCorrection {
    /// ionosphere-free P1/P2 pseudoranges: no correction; code noise × 2.98
    IonoFree,
    /// single-frequency L1 with the broadcast (Klobuchar) model; residual σ = 50 % of the
    /// modelled delay (the model's design goal of removing about half the RMS delay)
    Klobuchar(KlobucharCoefficients),
    /// single-frequency L1 without correction; residual σ = `UereModel::sigma_iono_uncorrected_m`
    Uncorrected,
}

/// The pseudorange error model (user-equivalent range error) that weights the solution and
/// predicts its covariance. Per satellite at elevation el:
///
/// `σ² = σ_sis² + (k σ_code / sin el)² + σ_iono² + (σ_tropo / sin el)²`
///
/// with k = 2.98 for the ionosphere-free combination (1 otherwise), σ_iono from
/// [`IonoCorrection`], and σ_tropo the residual zenith delay after Saastamoinen (or the
/// whole zenith delay when the troposphere is not corrected).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UereModel {
    /// code noise and multipath at the zenith, one frequency \[m\]
    pub sigma_code_zenith_m: f64,
    /// residual zenith troposphere after Saastamoinen \[m\]
    pub sigma_tropo_zenith_m: f64,
    /// zenith troposphere when uncorrected \[m\]
    pub sigma_tropo_uncorrected_m: f64,
    /// ionosphere when uncorrected \[m\]
    pub sigma_iono_uncorrected_m: f64,
    /// fraction of the Klobuchar delay taken as its residual σ
    pub klobuchar_residual_fraction: f64,
}

impl Default for UereModel {
    /// σ_code = 0.3 m (code noise plus multipath of a geodetic receiver at the zenith),
    /// σ_tropo = 0.1 m (the standard atmosphere's error in wet delay and pressure),
    /// uncorrected troposphere 2.4 m and ionosphere 10 m, Klobuchar residual 50 %.
    fn default() -> Self {
        UereModel {
            sigma_code_zenith_m: 0.3,
            sigma_tropo_zenith_m: 0.1,
            sigma_tropo_uncorrected_m: 2.4,
            sigma_iono_uncorrected_m: 10.0,
            klobuchar_residual_fraction: 0.5,
        }
    }
}

/// Options of [`solve_position`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppOptions {
    /// GPS seconds of week of the reception (local time of the ionosphere model)
    pub tow_s: f64,
    /// elevation mask \[rad\]
    pub elevation_mask_rad: f64,
    /// ionosphere handling
    pub iono: IonoCorrection,
    /// apply the Saastamoinen troposphere with 1/sin(el) mapping
    pub troposphere: bool,
    /// pseudorange error model
    pub uere: UereModel,
    /// initial position (the Earth's centre is fine; see [`solve_position`]) \[m\]
    pub initial_r_e_m: Vec3,
    /// iteration cap
    pub max_iterations: usize,
}

/// A single-point position solution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionSolution {
    /// receiver antenna position, ECEF \[m\]
    pub r_e_m: Vec3,
    /// geodetic latitude \[rad\] (WGS-84)
    pub lat_rad: f64,
    /// longitude \[rad\]
    pub lon_rad: f64,
    /// ellipsoidal height \[m\]
    pub h_m: f64,
    /// receiver clock bias c·δt_r \[m\]
    pub clock_bias_m: f64,
    /// predicted position covariance resolved in NED \[m²\]: `C_e^n P_e C_n^e`
    pub cov_pos_n_m2: Mat3,
    /// predicted clock-bias σ \[m\]
    pub clock_sigma_m: f64,
    /// DOP of the satellites used
    pub dop: Dop,
    /// number of satellites used
    pub n_used: usize,
    /// PRNs used (first `n_used` entries)
    pub prn: [u8; MAX_SATS],
    /// post-fit residuals, measured − predicted at the solution \[m\]
    pub residual_m: [f64; MAX_SATS],
    /// σ of each used pseudorange from the UERE model \[m\]
    pub sigma_m: [f64; MAX_SATS],
    /// elevation of each used satellite \[rad\]
    pub elevation_rad: [f64; MAX_SATS],
    /// azimuth of each used satellite \[rad\]
    pub azimuth_rad: [f64; MAX_SATS],
    /// Σ (residual/σ)², χ² with n_used − 4 degrees of freedom when the model holds
    pub weighted_ssr: f64,
    /// iterations done
    pub iterations: usize,
}

/// Range with Earth rotation during transit: `|R3(Ω̇e τ) r_s − r_r|`, τ from two passes.
pub(crate) fn sagnac_range(r_sat_e_m: &Vec3, r_rx_e_m: &Vec3) -> (f64, Vec3) {
    let mut rho = (r_sat_e_m - r_rx_e_m).norm();
    let mut rs = *r_sat_e_m;
    for _ in 0..2 {
        rs = rot_z(OMEGA_E_DOT_RPS * rho / C_MPS) * r_sat_e_m;
        rho = (rs - r_rx_e_m).norm();
    }
    (rho, rs)
}

/// Per-satellite working values of one linearisation.
struct Rows {
    normal: Normal4,
    geom: Normal4,
    n: usize,
    prn: [u8; MAX_SATS],
    z: [f64; MAX_SATS],
    sigma: [f64; MAX_SATS],
    el: [f64; MAX_SATS],
    az: [f64; MAX_SATS],
}

/// Radius below which the current estimate is "not located yet": no elevation mask and
/// no atmosphere (the first iteration from the Earth's centre).
const UNLOCATED_RADIUS_M: f64 = 6.0e6;

fn linearize(sats: &[SppSatellite], o: &SppOptions, x: &Vector4<f64>) -> Result<Rows, GnssError> {
    let r = Vec3::new(x[0], x[1], x[2]);
    let located = r.norm() > UNLOCATED_RADIUS_M;
    let earth = EarthModel::WGS84;
    let (lat, lon, h) = if located {
        earth.geodetic_from_ecef(&r)
    } else {
        (0.0, 0.0, 0.0)
    };
    let c_e_n = EarthModel::c_e_n(lat, lon);
    let mut rows = Rows {
        normal: Normal4::new(),
        geom: Normal4::new(),
        n: 0,
        prn: [0; MAX_SATS],
        z: [0.0; MAX_SATS],
        sigma: [0.0; MAX_SATS],
        el: [0.0; MAX_SATS],
        az: [0.0; MAX_SATS],
    };
    let k_code = match o.iono {
        IonoCorrection::IonoFree => iono_free_noise_factor(),
        _ => 1.0,
    };
    for s in sats {
        let (rho, rs) = sagnac_range(&s.r_sat_e_m, &r);
        if rho.is_nan() || rho <= 0.0 {
            continue;
        }
        let u = (rs - r) / rho;
        let (el, az) = if located {
            elevation_azimuth(&c_e_n, &u)
        } else {
            (core::f64::consts::FRAC_PI_2, 0.0)
        };
        if located && el < o.elevation_mask_rad {
            continue;
        }
        let sin_el = libm::sin(el).max(1e-3);
        let (iono_m, sig_iono) = match (&o.iono, located) {
            (_, false) | (IonoCorrection::IonoFree, _) => (0.0, 0.0),
            (IonoCorrection::Klobuchar(k), true) => {
                let d = klobuchar_l1_delay_m(k, lat, lon, el, az, o.tow_s);
                (d, o.uere.klobuchar_residual_fraction * d)
            }
            (IonoCorrection::Uncorrected, true) => (0.0, o.uere.sigma_iono_uncorrected_m),
        };
        let (tropo_m, sig_tropo) = if !located {
            (0.0, 0.0)
        } else if o.troposphere {
            (
                saastamoinen_slant_m(lat, h, el),
                o.uere.sigma_tropo_zenith_m / sin_el,
            )
        } else {
            (0.0, o.uere.sigma_tropo_uncorrected_m / sin_el)
        };
        let predicted = rho + x[3] - C_MPS * s.clock_bias_s + iono_m + tropo_m;
        let z = s.pseudorange_m - predicted;
        let code = k_code * o.uere.sigma_code_zenith_m / sin_el;
        let var = s.sigma_sis_m * s.sigma_sis_m
            + code * code
            + sig_iono * sig_iono
            + sig_tropo * sig_tropo;
        if !(z.is_finite() && var.is_finite() && var > 0.0) {
            return Err(GnssError::NonFinite {
                what: "pseudorange residual or its variance",
            });
        }
        let i = rows.n;
        rows.normal
            .add(&Vector4::new(-u.x, -u.y, -u.z, 1.0), z, 1.0 / var);
        let u_n = c_e_n * u;
        rows.geom
            .add(&Vector4::new(-u_n.x, -u_n.y, -u_n.z, 1.0), 0.0, 1.0);
        rows.prn[i] = s.prn;
        rows.z[i] = z;
        rows.sigma[i] = libm::sqrt(var);
        rows.el[i] = el;
        rows.az[i] = az;
        rows.n += 1;
    }
    if rows.n < 4 {
        return Err(GnssError::TooFewSatellites {
            got: rows.n,
            need: 4,
        });
    }
    Ok(rows)
}

/// Convergence threshold on the state correction \[m\].
const CONVERGED_M: f64 = 1e-4;

/// Iterative weighted least-squares position and clock (Groves §9.4.1): linearise the
/// pseudorange `P = |R3(Ω̇e τ) r_s − r| + c δt_r − c Δt_sv + I + T` about the current
/// estimate, rows `[−uᵀ, 1]`, weights 1/σ² from [`UereModel`], until the correction is
/// below 0.1 mm. While the estimate is within 6000 km of the Earth's centre (a start from
/// the origin) the mask and the atmosphere are not applied. The covariance is
/// `(HᵀWH)⁻¹` resolved in NED at the solution; DOP uses the unweighted rows.
///
/// Refuses (typed error, never NaN) fewer than 4 usable satellites, more than
/// [`MAX_SATS`], non-finite inputs, singular geometry and non-convergence.
pub fn solve_position(
    sats: &[SppSatellite],
    o: &SppOptions,
) -> Result<PositionSolution, GnssError> {
    if sats.len() > MAX_SATS {
        return Err(GnssError::TooManySatellites { got: sats.len() });
    }
    for s in sats {
        let ok = s.r_sat_e_m.iter().all(|v| v.is_finite())
            && s.clock_bias_s.is_finite()
            && s.pseudorange_m.is_finite()
            && s.sigma_sis_m.is_finite();
        if !ok {
            return Err(GnssError::NonFinite {
                what: "satellite input",
            });
        }
    }
    let r0 = o.initial_r_e_m;
    if !r0.iter().all(|v| v.is_finite()) {
        return Err(GnssError::NonFinite {
            what: "initial position",
        });
    }
    let mut x = Vector4::new(r0.x, r0.y, r0.z, 0.0);
    for it in 0..o.max_iterations {
        let rows = linearize(sats, o, &x)?;
        let (dx, _) = rows.normal.solve()?;
        x += dx;
        if dx.norm() < CONVERGED_M {
            return finish(sats, o, &x, it + 1);
        }
    }
    Err(GnssError::NotConverged {
        iterations: o.max_iterations,
    })
}

fn finish(
    sats: &[SppSatellite],
    o: &SppOptions,
    x: &Vector4<f64>,
    iterations: usize,
) -> Result<PositionSolution, GnssError> {
    let rows = linearize(sats, o, x)?;
    let (_, q) = rows.normal.solve()?;
    let (_, g) = rows.geom.solve()?;
    let r = Vec3::new(x[0], x[1], x[2]);
    let (lat, lon, h) = EarthModel::WGS84.geodetic_from_ecef(&r);
    let c = EarthModel::c_e_n(lat, lon);
    let p_e: Mat3 = q.fixed_view::<3, 3>(0, 0).into();
    let mut weighted_ssr = 0.0;
    for i in 0..rows.n {
        weighted_ssr += (rows.z[i] / rows.sigma[i]) * (rows.z[i] / rows.sigma[i]);
    }
    Ok(PositionSolution {
        r_e_m: r,
        lat_rad: lat,
        lon_rad: lon,
        h_m: h,
        clock_bias_m: x[3],
        cov_pos_n_m2: c * p_e * c.transpose(),
        clock_sigma_m: libm::sqrt(q[(3, 3)].max(0.0)),
        dop: Dop::from_q(&g),
        n_used: rows.n,
        prn: rows.prn,
        residual_m: rows.z,
        sigma_m: rows.sigma,
        elevation_rad: rows.el,
        azimuth_rad: rows.az,
        weighted_ssr,
        iterations,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::gnss::{nominal_constellation, transit, GpsTime, KLOBUCHAR_DEFAULT};

    fn options(iono: IonoCorrection, troposphere: bool) -> SppOptions {
        SppOptions {
            tow_s: 345_600.0,
            elevation_mask_rad: 10f64.to_radians(),
            iono,
            troposphere,
            uere: UereModel::default(),
            initial_r_e_m: Vec3::zeros(),
            max_iterations: 20,
        }
    }

    /// Exact pseudoranges (light time with Earth rotation, receiver clock, modelled
    /// atmosphere) from the nominal constellation: the solution must return the truth.
    fn simulate(
        lat: f64,
        lon: f64,
        h: f64,
        o: &SppOptions,
    ) -> (Vec3, f64, [SppSatellite; 24], usize) {
        let t0 = GpsTime::new(1826, 345_600.0);
        let earth = EarthModel::WGS84;
        let r = earth.ecef_from_geodetic(lat, lon, h);
        let c = EarthModel::c_e_n(lat, lon);
        let clock_m = 12_345.678;
        let mut out = [SppSatellite {
            prn: 0,
            r_sat_e_m: Vec3::zeros(),
            clock_bias_s: 0.0,
            pseudorange_m: 0.0,
            sigma_sis_m: 1.0,
        }; 24];
        let mut n = 0;
        for e in nominal_constellation(t0).iter() {
            let tr = transit(e, &t0, &r).unwrap();
            let (el, az) = elevation_azimuth(&c, &((tr.r_sat_rx_e_m - r) / tr.range_m));
            if el < 0.0 {
                continue;
            }
            let iono = match o.iono {
                IonoCorrection::Klobuchar(k) => klobuchar_l1_delay_m(&k, lat, lon, el, az, o.tow_s),
                _ => 0.0,
            };
            let tropo = if o.troposphere {
                saastamoinen_slant_m(lat, h, el)
            } else {
                0.0
            };
            out[n] = SppSatellite {
                prn: e.prn,
                r_sat_e_m: tr.sat.r_sat_e_m,
                clock_bias_s: 0.0,
                pseudorange_m: tr.range_m + clock_m + iono + tropo,
                sigma_sis_m: 1.0,
            };
            n += 1;
        }
        (r, clock_m, out, n)
    }

    #[test]
    fn exact_pseudoranges_give_the_truth() {
        for (iono, tropo) in [
            (IonoCorrection::IonoFree, false),
            (IonoCorrection::Klobuchar(KLOBUCHAR_DEFAULT), true),
        ] {
            let o = options(iono, tropo);
            let (r, clock, sats, n) =
                simulate(-18.9_f64.to_radians(), 47.2_f64.to_radians(), 1552.0, &o);
            let s = solve_position(&sats[..n], &o).unwrap();
            assert!((s.r_e_m - r).norm() < 1e-4, "{}", (s.r_e_m - r).norm());
            assert!((s.clock_bias_m - clock).abs() < 1e-4);
            assert!(s.weighted_ssr < 1e-8);
            assert!(s.dop.pdop > 1.0 && s.dop.pdop < 6.0);
            // the covariance is the weighted (HᵀWH)⁻¹: with every σ ≥ 1 m (σ_sis) the
            // position variance is at least the unweighted PDOP² ≥ … > 1 m²
            assert!(s.cov_pos_n_m2.trace() > 1.0);
            for i in 0..s.n_used {
                assert!(s.elevation_rad[i] >= 10f64.to_radians());
            }
        }
    }

    #[test]
    fn underdetermined_and_singular_geometry_are_refused() {
        let o = options(IonoCorrection::IonoFree, false);
        let (_, _, sats, _) = simulate(0.5, 0.5, 0.0, &o);
        assert_eq!(
            solve_position(&sats[..3], &o).unwrap_err(),
            GnssError::TooFewSatellites { got: 3, need: 4 }
        );
        let same = [sats[0]; 6];
        assert_eq!(
            solve_position(&same, &o).unwrap_err(),
            GnssError::SingularGeometry
        );
        let mut bad = sats;
        bad[1].pseudorange_m = f64::NAN;
        assert!(matches!(
            solve_position(&bad[..8], &o),
            Err(GnssError::NonFinite { .. })
        ));
        let many = [sats[0]; 33];
        assert_eq!(
            solve_position(&many, &o).unwrap_err(),
            GnssError::TooManySatellites { got: 33 }
        );
    }
}
