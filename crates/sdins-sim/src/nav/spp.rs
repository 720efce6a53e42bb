//! File-level single-point positioning and Doppler velocity: RINEX observations and
//! navigation → per-epoch solutions and summary statistics against a known position.

use crate::cancel::CancelToken;
use crate::io::rinex::{NavFile, ObsEpoch, ObsFile};
use sdins_core::earth::EarthModel;
use sdins_core::gnss::{
    iono_free_m, select_ephemeris, solve_position, solve_velocity, DopplerSatellite, GnssError,
    GpsEphemeris, GpsTime, IonoCorrection, KlobucharCoefficients, PositionSolution, SppOptions,
    SppSatellite, UereModel, VelocityOptions, VelocitySolution, C_MPS, DEFAULT_VALIDITY_S,
    KLOBUCHAR_DEFAULT, LAMBDA_L1_M, MAX_SATS,
};
use sdins_core::math::Vec3;

/// Why a file-level SPP run could not be done (per-epoch failures are reported in the
/// result, not as errors).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SppRunError {
    /// The options are not usable.
    #[error("invalid SPP option {option}: {problem}")]
    Option {
        /// option name
        option: &'static str,
        /// what is wrong
        problem: String,
    },
    /// The observation file lacks an observable the mode needs.
    #[error("the observation file has no {code} observations (needed by {mode})")]
    MissingObservable {
        /// RINEX 3 code
        code: String,
        /// the processing mode
        mode: &'static str,
    },
    /// Cancelled through the token.
    #[error(transparent)]
    Cancelled(#[from] crate::cancel::Cancelled),
    /// A core computation refused its input outside the per-epoch loop.
    #[error("{0}")]
    Gnss(GnssError),
}

/// Default signal-in-space range error σ of GPS broadcast orbits and clocks \[m\]: about
/// 0.7 m RMS in 2013–2015 (Montenbruck, Steigenberger & Hauschild 2015, "Broadcast
/// versus precise ephemerides: a multi-GNSS perspective", GPS Solutions 19:321–333). The
/// broadcast URA (2.0 m for index 0) is an upper bound: with it the predicted 95 %
/// ellipse held every ABPO ionosphere-free epoch (docs/theory/gnss.md).
pub const SISRE_GPS_M: f64 = 0.7;

/// Pseudorange processing mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SppMode {
    /// L1 C/A (`C1C`, else `C1W`) with the Klobuchar model and T_GD
    L1Klobuchar,
    /// ionosphere-free `C1W`/`C2W` (P1/P2; `C1C` stands in for a missing P1), no T_GD
    IonoFree,
}

/// Options of [`run_spp`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppRunOptions {
    /// pseudorange mode
    pub mode: SppMode,
    /// elevation mask \[deg\]
    pub elevation_mask_deg: f64,
    /// process every n-th epoch (1 = all)
    pub every: usize,
    /// Saastamoinen troposphere on/off
    pub troposphere: bool,
    /// ionosphere coefficients overriding the file's (`None`: the file's, else
    /// [`KLOBUCHAR_DEFAULT`])
    pub klobuchar: Option<KlobucharCoefficients>,
    /// known antenna position for the statistics \[m, ECEF\]
    pub known_position_e_m: Option<[f64; 3]>,
    /// pseudorange error model
    pub uere: UereModel,
    /// also solve the velocity from `D1C` Dopplers when the file has them
    pub doppler: bool,
    /// Doppler range-rate σ at the zenith \[m/s\]
    pub doppler_sigma_zenith_mps: f64,
    /// optional clock-drift prior (mean, σ) \[m/s\]
    pub drift_prior_mps: Option<(f64, f64)>,
    /// ephemeris validity around toe \[s\]
    pub validity_s: f64,
    /// signal-in-space σ \[m\]: `None` takes each ephemeris's broadcast URA (an upper
    /// bound, conservative), `Some(σ)` a fixed figure
    pub sigma_sis_m: Option<f64>,
}

impl Default for SppRunOptions {
    /// Ionosphere-free, 10° mask, every epoch, Saastamoinen on, default UERE model with
    /// σ_sis = [`SISRE_GPS_M`], Doppler on with σ = 0.05 m/s at the zenith, no drift
    /// prior, 2 h validity.
    fn default() -> Self {
        SppRunOptions {
            mode: SppMode::IonoFree,
            elevation_mask_deg: 10.0,
            every: 1,
            troposphere: true,
            klobuchar: None,
            known_position_e_m: None,
            uere: UereModel::default(),
            doppler: true,
            doppler_sigma_zenith_mps: 0.05,
            drift_prior_mps: None,
            validity_s: DEFAULT_VALIDITY_S,
            sigma_sis_m: Some(SISRE_GPS_M),
        }
    }
}

/// One solved epoch.
#[derive(Clone, Debug, PartialEq)]
pub struct SppEpoch {
    /// receiver time tag of the epoch
    pub t_rx: GpsTime,
    /// GPS time of the solution, t_rx − δt_r
    pub t: GpsTime,
    /// position solution
    pub solution: PositionSolution,
    /// Doppler velocity, when requested and possible
    pub velocity: Option<VelocitySolution>,
    /// why the velocity could not be solved, when requested
    pub velocity_error: Option<GnssError>,
    /// error against the known position, NED \[m\]
    pub error_n_m: Option<Vec3>,
    /// whether the horizontal error lies inside the predicted 95 % ellipse
    pub in_95_ellipse: Option<bool>,
}

/// An epoch without a solution.
#[derive(Clone, Debug, PartialEq)]
pub struct SppFailure {
    /// receiver time tag
    pub t_rx: GpsTime,
    /// why
    pub error: GnssError,
}

/// Statistics of the solutions against the known position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppSummary {
    /// epochs processed (after `every`)
    pub n_epochs: usize,
    /// epochs with a solution
    pub n_solutions: usize,
    /// RMS of the horizontal error \[m\]
    pub horizontal_rms_m: f64,
    /// 95th percentile (nearest rank) of the horizontal error \[m\]
    pub horizontal_95_m: f64,
    /// RMS of the vertical error \[m\]
    pub vertical_rms_m: f64,
    /// 95th percentile of |vertical error| \[m\]
    pub vertical_95_m: f64,
    /// mean error per NED axis \[m\]
    pub mean_error_n_m: [f64; 3],
    /// fraction of solutions whose horizontal error is inside the predicted 95 % ellipse
    /// (`dᵀ P_h⁻¹ d ≤ χ²₂(0.95) = 5.991`)
    pub fraction_in_95_ellipse: f64,
    /// mean PDOP
    pub mean_pdop: f64,
}

/// The result of [`run_spp`].
#[derive(Clone, Debug, PartialEq)]
pub struct SppRun {
    /// solved epochs
    pub epochs: Vec<SppEpoch>,
    /// epochs without a solution
    pub failures: Vec<SppFailure>,
    /// statistics, when a known position was given and an epoch was solved
    pub summary: Option<SppSummary>,
}

/// χ²(2 dof) 95 % quantile, −2 ln 0.05.
const CHI2_2_95: f64 = 5.991_464_547_107_979;

struct Codes {
    p1: usize,
    p2: Option<usize>,
    d1: Option<usize>,
}

fn codes(obs: &ObsFile, o: &SppRunOptions) -> Result<Codes, SppRunError> {
    let miss = |code: &str, mode| SppRunError::MissingObservable {
        code: code.into(),
        mode,
    };
    let d1 = if o.doppler {
        obs.code_index("D1C")
    } else {
        None
    };
    match o.mode {
        SppMode::L1Klobuchar => {
            let (p1, _) = obs
                .first_code_index(&["C1C", "C1W"])
                .ok_or_else(|| miss("C1C", "L1"))?;
            Ok(Codes { p1, p2: None, d1 })
        }
        SppMode::IonoFree => {
            let (p1, _) = obs
                .first_code_index(&["C1W", "C1C"])
                .ok_or_else(|| miss("C1W", "ionosphere-free"))?;
            let p2 = obs
                .code_index("C2W")
                .ok_or_else(|| miss("C2W", "ionosphere-free"))?;
            Ok(Codes {
                p1,
                p2: Some(p2),
                d1,
            })
        }
    }
}

/// Satellite inputs of one epoch: (SPP inputs, Doppler inputs).
fn satellites(
    e: &ObsEpoch,
    ephs: &[GpsEphemeris],
    c: &Codes,
    o: &SppRunOptions,
) -> (Vec<SppSatellite>, Vec<DopplerSatellite>) {
    let l1 = o.mode == SppMode::L1Klobuchar;
    let mut spp = Vec::new();
    let mut dop = Vec::new();
    for s in &e.sats {
        if spp.len() >= MAX_SATS {
            break;
        }
        let val = |i: usize| s.values.get(i).copied().flatten().map(|v| v.value);
        let Some(p1) = val(c.p1) else { continue };
        let p = match c.p2 {
            Some(i2) => match val(i2) {
                Some(p2) => iono_free_m(p1, p2),
                None => continue,
            },
            None => p1,
        };
        let Some(eph) = select_ephemeris(ephs, s.prn, &e.t, o.validity_s) else {
            continue;
        };
        let t_sv = e.t.add_s(-p / C_MPS);
        let Ok(t_tx) = eph.transmit_time(&t_sv, l1) else {
            continue;
        };
        let Ok(st) = eph.state(&t_tx) else { continue };
        let clock = if l1 {
            eph.l1_clock_bias_s(&st)
        } else {
            st.clock_bias_s
        };
        spp.push(SppSatellite {
            prn: s.prn,
            r_sat_e_m: st.r_sat_e_m,
            clock_bias_s: clock,
            pseudorange_m: p,
            sigma_sis_m: o.sigma_sis_m.unwrap_or(eph.sv_accuracy_m),
        });
        if let Some(d) = c.d1.and_then(val) {
            dop.push(DopplerSatellite {
                prn: s.prn,
                r_sat_e_m: st.r_sat_e_m,
                v_sat_e_mps: st.v_sat_e_mps,
                clock_drift_sps: st.clock_drift_sps,
                range_rate_mps: -LAMBDA_L1_M * d,
            });
        }
    }
    (spp, dop)
}

/// Single-point positioning (and Doppler velocity) of every `every`-th epoch of `obs`
/// with the GPS ephemerides of `nav`; per-epoch failures are collected, not fatal. No
/// printing. Polls `cancel` every epoch.
pub fn run_spp(
    obs: &ObsFile,
    nav: &NavFile,
    o: &SppRunOptions,
    cancel: &CancelToken,
) -> Result<SppRun, SppRunError> {
    if o.every == 0 {
        return Err(SppRunError::Option {
            option: "every",
            problem: "must be at least 1".into(),
        });
    }
    if !(0.0..90.0).contains(&o.elevation_mask_deg) {
        return Err(SppRunError::Option {
            option: "elevation_mask_deg",
            problem: format!("{} is not in [0, 90)", o.elevation_mask_deg),
        });
    }
    let c = codes(obs, o)?;
    let iono = match o.mode {
        SppMode::IonoFree => IonoCorrection::IonoFree,
        SppMode::L1Klobuchar => {
            IonoCorrection::Klobuchar(o.klobuchar.or(nav.klobuchar).unwrap_or(KLOBUCHAR_DEFAULT))
        }
    };
    let known = o.known_position_e_m.map(|p| Vec3::new(p[0], p[1], p[2]));
    let c_known = known.map(|r| {
        let (lat, lon, _) = EarthModel::WGS84.geodetic_from_ecef(&r);
        EarthModel::c_e_n(lat, lon)
    });
    let mut run = SppRun {
        epochs: Vec::new(),
        failures: Vec::new(),
        summary: None,
    };
    let mut r0 = Vec3::zeros();
    let mut n_epochs = 0;
    for e in obs.epochs.iter().step_by(o.every) {
        cancel.check()?;
        n_epochs += 1;
        let (sats, dops) = satellites(e, &nav.ephemerides, &c, o);
        let so = SppOptions {
            tow_s: e.t.sow_s,
            elevation_mask_rad: o.elevation_mask_deg.to_radians(),
            iono,
            troposphere: o.troposphere,
            uere: o.uere,
            initial_r_e_m: r0,
            max_iterations: 20,
        };
        let sol = match solve_position(&sats, &so) {
            Ok(s) => s,
            Err(error) => {
                run.failures.push(SppFailure { t_rx: e.t, error });
                continue;
            }
        };
        r0 = sol.r_e_m;
        let (velocity, velocity_error) = if c.d1.is_some() {
            let vo = VelocityOptions {
                r_rx_e_m: sol.r_e_m,
                elevation_mask_rad: so.elevation_mask_rad,
                sigma_zenith_mps: o.doppler_sigma_zenith_mps,
                drift_prior_mps: o.drift_prior_mps,
            };
            match solve_velocity(&dops, &vo) {
                Ok(v) => (Some(v), None),
                Err(err) => (None, Some(err)),
            }
        } else {
            (None, None)
        };
        let (error_n_m, in_95_ellipse) = match (known, c_known) {
            (Some(r), Some(c)) => {
                let d = c * (sol.r_e_m - r);
                let p = sol.cov_pos_n_m2.fixed_view::<2, 2>(0, 0).into_owned();
                let inside = p.try_inverse().map(|pi| {
                    let dh = nalgebra::Vector2::new(d.x, d.y);
                    (dh.transpose() * pi * dh)[(0, 0)] <= CHI2_2_95
                });
                (Some(d), inside)
            }
            _ => (None, None),
        };
        run.epochs.push(SppEpoch {
            t_rx: e.t,
            t: e.t.add_s(-sol.clock_bias_m / C_MPS),
            solution: sol,
            velocity,
            velocity_error,
            error_n_m,
            in_95_ellipse,
        });
    }
    run.summary = summarize(&run.epochs, n_epochs);
    Ok(run)
}

fn percentile95(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let k = ((0.95 * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[k]
}

fn summarize(epochs: &[SppEpoch], n_epochs: usize) -> Option<SppSummary> {
    let errs: Vec<(Vec3, Option<bool>, f64)> = epochs
        .iter()
        .filter_map(|e| {
            e.error_n_m
                .map(|d| (d, e.in_95_ellipse, e.solution.dop.pdop))
        })
        .collect();
    if errs.is_empty() {
        return None;
    }
    let n = errs.len() as f64;
    let h: Vec<f64> = errs.iter().map(|(d, _, _)| d.x.hypot(d.y)).collect();
    let v: Vec<f64> = errs.iter().map(|(d, _, _)| d.z.abs()).collect();
    let rms = |x: &[f64]| (x.iter().map(|a| a * a).sum::<f64>() / n).sqrt();
    let mean = |k: usize| errs.iter().map(|(d, _, _)| d[k]).sum::<f64>() / n;
    Some(SppSummary {
        n_epochs,
        n_solutions: epochs.len(),
        horizontal_rms_m: rms(&h),
        horizontal_95_m: percentile95(h.clone()),
        vertical_rms_m: rms(&v),
        vertical_95_m: percentile95(v.clone()),
        mean_error_n_m: [mean(0), mean(1), mean(2)],
        fraction_in_95_ellipse: errs.iter().filter(|(_, i, _)| *i == Some(true)).count() as f64 / n,
        mean_pdop: errs.iter().map(|(_, _, p)| p).sum::<f64>() / n,
    })
}
