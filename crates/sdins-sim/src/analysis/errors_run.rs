//! The `errors` procedure as one library call: stationary free-inertial error propagation
//! for a set of NED sensor biases (docs/theory/error-analysis.md §"Full stationary closed form",
//! docs/theory/error-analysis.md): the closed form, the 15-state linear model's
//! deterministic error and 1σ covariance envelope, a nonlinear free-inertial run, and the
//! per-source error budget, at the standard epochs. The CLI (`sdins errors`) and Python
//! (`sdins.errors`) only parse, call [`errors`] and format. The Schuler-share table
//! (docs/theory/error-analysis.md §"The Schuler share") is
//! [`crate::analysis::error_analysis::schuler_share::schuler_share_table_p2`].

use crate::analysis::error_analysis::grades::{grade_by_name, Grade, GRADES};
use crate::analysis::error_analysis::linear_model::{
    propagate, stationary_samples, EnvelopePoint, ErrorVector, ModelEarth, ModelOptions,
    ProcessNoise, VerticalChannel,
};
use crate::analysis::error_analysis::nonlinear::NonlinearRun;
use crate::analysis::error_analysis::periods::SchulerParams;
use crate::analysis::error_analysis::stationary::{
    StationaryClosedForm, StationaryErrors, StationarySolution,
};
use crate::analysis::error_analysis::{DEG_PER_HOUR, MICRO_G};
use crate::cancel::CancelToken;
use sdins_core::Vec3;

/// Linear-model step \[s\] (see `linear_model` docs: Taylor-3 is accurate to < 1e-4 rad of
/// Schuler phase over 24 h at this step).
pub const DT_S: f64 = 10.0;

/// Options of [`errors`]; `Default` is the CLI's default (no biases: give a grade or a
/// bias).
#[derive(Clone, Debug, PartialEq)]
pub struct ErrorsOptions {
    /// sensor grade name (its turn-on bias σ on every NED axis, its ARW/VRW for the
    /// envelope); exclusive with the biases
    pub grade: Option<String>,
    /// NED gyro bias \[°/h\] N, E, D
    pub gyro_bias_dph: Option<Vec<f64>>,
    /// NED accelerometer bias \[μg\] N, E, D
    pub accel_bias_ug: Option<Vec<f64>>,
    /// duration \[h\] (0 < H ≤ 240)
    pub hours: f64,
    /// latitude \[deg\] (|lat| ≤ 89)
    pub lat_deg: f64,
    /// run the nonlinear free-inertial simulation column
    pub nonlinear: bool,
}

impl Default for ErrorsOptions {
    fn default() -> Self {
        Self {
            grade: None,
            gyro_bias_dph: None,
            accel_bias_ug: None,
            hours: 24.0,
            lat_deg: 37.5,
            nonlinear: true,
        }
    }
}

/// Why [`errors`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorsError {
    /// an option out of range or inconsistent; the message names the CLI flag
    #[error("{message}")]
    BadOption {
        /// field name of [`ErrorsOptions`]
        option: &'static str,
        /// the located message
        message: String,
    },
    /// the computation failed (should not happen for valid options)
    #[error("{0}")]
    Failed(String),
    /// stopped through the [`CancelToken`]
    #[error("cancelled")]
    Cancelled,
}

/// One output epoch.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Epoch {
    /// time \[h\]
    pub t_h: f64,
    /// the closed form at this epoch
    pub closed_form: StationarySolution,
    /// the linear model (deterministic error and 1σ) at this epoch
    pub linear: EnvelopePoint,
    /// the nonlinear free-inertial simulation at this epoch (`null` without it)
    pub nonlinear: Option<NonlinearPoint>,
}

/// Nonlinear-simulation errors at one epoch.
#[derive(serde::Serialize, Clone, Copy, Debug, PartialEq)]
pub struct NonlinearPoint {
    /// position error N, E, D \[m\]
    pub dp_n_m: [f64; 3],
    /// attitude error ε (convention G) \[rad\]
    pub phi: [f64; 3],
}

/// The serialisable report (`sdins errors --json`).
#[derive(serde::Serialize, Clone, Debug, PartialEq)]
pub struct ErrorsReport {
    /// latitude \[deg\]
    pub lat_deg: f64,
    /// duration \[h\]
    pub hours: f64,
    /// grade name, if given
    pub grade: Option<String>,
    /// NED gyro bias \[°/h\]
    pub gyro_bias_dph_ned: [f64; 3],
    /// NED accelerometer bias \[μg\]
    pub accel_bias_ug_ned: [f64; 3],
    /// Schuler parameters (R0, g, Ω) of the closed form and the linear model
    pub params: SchulerParams,
    /// the epochs
    pub epochs: Vec<Epoch>,
}

/// Everything [`errors`] computes.
#[derive(Clone, Debug)]
pub struct ErrorsOutcome {
    /// the report at the standard epochs
    pub report: ErrorsReport,
    /// the closed form (evaluate at any time)
    pub closed: StationaryClosedForm,
    /// the linear model every [`DT_S`] seconds from 0 to the duration
    pub envelope: Vec<EnvelopePoint>,
    /// error budget at the final time
    pub budget: Vec<BudgetRow>,
}

fn vec3(option: &'static str, flag: &str, v: &Option<Vec<f64>>) -> Result<Vec3, ErrorsError> {
    match v {
        None => Ok(Vec3::zeros()),
        Some(x) if x.len() == 3 && x.iter().all(|a| a.is_finite()) => {
            Ok(Vec3::new(x[0], x[1], x[2]))
        }
        Some(x) => Err(ErrorsError::BadOption {
            option,
            message: format!("--{flag}: expected three finite numbers N,E,D, got {x:?}"),
        }),
    }
}

/// The standard epochs \[h\] of a run of `hours`: 0.5, 1, 2, 4, 6, 12, 24, 48, 96, 168 h
/// below `hours`, and `hours`.
pub fn epochs_h(hours: f64) -> Vec<f64> {
    let mut h: Vec<f64> = [0.5, 1.0, 2.0, 4.0, 6.0, 12.0, 24.0, 48.0, 96.0, 168.0]
        .into_iter()
        .filter(|h| *h < hours - 1e-9)
        .collect();
    h.push(hours);
    h
}

/// Run the stationary error analysis (closed form docs/theory/error-analysis.md; linear
/// model on the same spherical earth with the vertical channel held: the biases give the
/// deterministic error, and as 1σ bias uncertainty plus the grade's ARW/VRW the 1σ
/// envelope; the nonlinear column of [`nonlinear_column`]).
pub fn errors(o: &ErrorsOptions, token: &CancelToken) -> Result<ErrorsOutcome, ErrorsError> {
    if !(o.hours.is_finite() && o.hours > 0.0 && o.hours <= 240.0) {
        return Err(ErrorsError::BadOption {
            option: "hours",
            message: format!("--hours: must be in (0, 240], got {}", o.hours),
        });
    }
    if !(o.lat_deg.is_finite() && o.lat_deg.abs() <= 89.0) {
        return Err(ErrorsError::BadOption {
            option: "lat_deg",
            message: format!("--lat: must be within ±89°, got {}", o.lat_deg),
        });
    }
    if o.grade.is_some() && (o.gyro_bias_dph.is_some() || o.accel_bias_ug.is_some()) {
        return Err(ErrorsError::BadOption {
            option: "grade",
            message: "--grade: give either a grade or biases, not both".into(),
        });
    }
    let grade: Option<&Grade> = match &o.grade {
        Some(name) => Some(grade_by_name(name).ok_or_else(|| {
            let names: Vec<&str> = GRADES.iter().map(|g| g.name).collect();
            ErrorsError::BadOption {
                option: "grade",
                message: format!(
                    "--grade: unknown grade {name:?} (known: {})",
                    names.join(", ")
                ),
            }
        })?),
        None => None,
    };
    let (gyro_dph, accel_ug) = match grade {
        Some(g) => (
            Vec3::repeat(g.gyro_bias_turn_on_dph),
            Vec3::repeat(g.accel_bias_turn_on_ug),
        ),
        None => (
            vec3("gyro_bias_dph", "gyro-bias-dph", &o.gyro_bias_dph)?,
            vec3("accel_bias_ug", "accel-bias-ug", &o.accel_bias_ug)?,
        ),
    };
    if grade.is_none() && o.gyro_bias_dph.is_none() && o.accel_bias_ug.is_none() {
        return Err(ErrorsError::BadOption {
            option: "grade",
            message: "give --grade, --gyro-bias-dph/--accel-bias-ug, or --schuler-share".into(),
        });
    }
    let lat = o.lat_deg.to_radians();
    let earth = sdins_core::earth::EarthModel::WGS84;
    let params = SchulerParams::with_local_gravity(&earth, lat, 0.0);
    let errors = StationaryErrors {
        eps_n: gyro_dph * DEG_PER_HOUR,
        da_n: accel_ug * MICRO_G,
        ..Default::default()
    };
    let closed = StationaryClosedForm::new(lat, &errors, params);
    let opts = ModelOptions {
        earth: ModelEarth::Spherical(params),
        vertical: VerticalChannel::Held,
        bias_states: true,
    };
    let duration = o.hours * 3600.0;
    let samples = stationary_samples(lat, 0.0, duration, DT_S, &opts.earth);
    let ev = ErrorVector {
        b_a: errors.da_n,
        b_g: errors.eps_n,
        ..Default::default()
    };
    let s0 = samples
        .first()
        .copied()
        .ok_or_else(|| ErrorsError::Failed("no samples".into()))?;
    let x0 = ev.to_state(&s0, &opts.earth);
    let p0 = ev.to_diag_covariance(&s0, &opts.earth);
    let noise = grade
        .map(|g| ProcessNoise {
            arw_rad_per_sqrt_s: Vec3::repeat(g.arw_si()),
            vrw_mps_per_sqrt_s: Vec3::repeat(g.vrw_si()),
            ..Default::default()
        })
        .unwrap_or_default();
    token.check().map_err(|_| ErrorsError::Cancelled)?;
    let env = propagate(&samples, &opts, &noise, &x0, &p0)
        .map_err(|e| ErrorsError::Failed(e.to_string()))?;
    token.check().map_err(|_| ErrorsError::Cancelled)?;
    let hours = epochs_h(o.hours);
    let nonlinear = if o.nonlinear {
        nonlinear_column(lat, &params, &gyro_dph, &accel_ug, &hours, token)?
    } else {
        vec![None; hours.len()]
    };
    let epochs: Vec<Epoch> = hours
        .iter()
        .zip(nonlinear)
        .map(|(&h, nonlinear)| {
            let t = h * 3600.0;
            let k = ((t / DT_S).round() as usize).min(env.len().saturating_sub(1));
            let linear = env.get(k).copied().unwrap_or_default();
            Epoch {
                t_h: h,
                closed_form: closed.eval(t),
                linear,
                nonlinear,
            }
        })
        .collect();
    let budget = error_budget(lat, params, &gyro_dph, &accel_ug, duration);
    Ok(ErrorsOutcome {
        report: ErrorsReport {
            lat_deg: o.lat_deg,
            hours: o.hours,
            grade: grade.map(|g| g.name.to_string()),
            gyro_bias_dph_ned: gyro_dph.into(),
            accel_bias_ug_ned: accel_ug.into(),
            params,
            epochs,
        },
        closed,
        envelope: env,
        budget,
    })
}

/// The nonlinear column: a full nonlinear free-inertial run
/// ([`NonlinearRun`], docs/validation.md §"error propagation" T9 set-up): stationary, body = NED at
/// `lat_rad` (so the NED biases are the body biases, injected as a custom `ImuErrorModel` with
/// fixed `gyro_bias_dph`/`accel_bias_ug`), spherical earth with the closed form's constants (R0, g,
/// Ω), 20 Hz IMU, `songlee-complete` with N = 2, vertical channel held; run once to the last epoch
/// and read at every epoch of `hours`.
pub fn nonlinear_column(
    lat_rad: f64,
    params: &SchulerParams,
    gyro_dph: &Vec3,
    accel_ug: &Vec3,
    hours: &[f64],
    token: &CancelToken,
) -> Result<Vec<Option<NonlinearPoint>>, ErrorsError> {
    let last = hours.iter().copied().fold(0.0, f64::max);
    let mut run = NonlinearRun::stationary(lat_rad, params, last * 3600.0);
    run.gyro_bias_dph = (*gyro_dph).into();
    run.accel_bias_ug = (*accel_ug).into();
    let errs = run
        .run_cancellable(token)
        .map_err(|e| ErrorsError::Failed(e.to_string()))?
        .ok_or(ErrorsError::Cancelled)?;
    Ok(hours
        .iter()
        .map(|h| {
            let t = h * 3600.0;
            errs.iter()
                .min_by(|a, b| (a.t_s - t).abs().total_cmp(&(b.t_s - t).abs()))
                .filter(|e| (e.t_s - t).abs() <= 0.5 * run.every_s + 1e-6)
                .map(|e| NonlinearPoint {
                    dp_n_m: e.pos_err_ned_m,
                    phi: e.att_err_rad,
                })
        })
        .collect())
}

/// One error source's share of the final position error.
#[derive(Clone, Debug, PartialEq)]
pub struct BudgetRow {
    /// source name, e.g. `gyro bias E`
    pub source: String,
    /// the source's value with unit
    pub value: String,
    /// its position error N, E at the final time \[m\]
    pub dp_ne_m: [f64; 2],
}

/// Error budget at `t_s`: the closed form (docs/theory/error-analysis.md) with one nonzero bias component at a
/// time. The closed form is linear in the errors, so the rows add up (as vectors) to the
/// all-sources error.
pub fn error_budget(
    lat_rad: f64,
    params: SchulerParams,
    gyro_dph: &Vec3,
    accel_ug: &Vec3,
    t_s: f64,
) -> Vec<BudgetRow> {
    let axes = ["N", "E", "D"];
    let mut rows = Vec::new();
    for k in 0..3 {
        for (gyro, v) in [(true, gyro_dph[k]), (false, accel_ug[k])] {
            if v == 0.0 {
                continue;
            }
            let mut e = StationaryErrors::default();
            let (source, value) = if gyro {
                e.eps_n[k] = v * DEG_PER_HOUR;
                (format!("gyro bias {}", axes[k]), format!("{v} °/h"))
            } else {
                e.da_n[k] = v * MICRO_G;
                (format!("accel bias {}", axes[k]), format!("{v} μg"))
            };
            let dp = StationaryClosedForm::new(lat_rad, &e, params)
                .eval(t_s)
                .dp_n;
            rows.push(BudgetRow {
                source,
                value,
                dp_ne_m: [dp[0], dp[1]],
            });
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The budget rows add up (as vectors) to the all-sources closed form: the closed form
    /// is linear in the biases, so only rounding separates them (|δp| ~ 1e4 m: 1e-7 m).
    /// Dropping any one row would miss by at least that source's share (≥ 100 m here).
    #[test]
    fn error_budget_adds_up_to_the_total() {
        let lat = 37.5_f64.to_radians();
        let params =
            SchulerParams::with_local_gravity(&sdins_core::earth::EarthModel::WGS84, lat, 0.0);
        let g = Vec3::new(0.01, -0.02, 0.015);
        let a = Vec3::new(50.0, -80.0, 30.0);
        let t = 6.0 * 3600.0;
        let rows = error_budget(lat, params, &g, &a, t);
        assert_eq!(rows.len(), 6);
        let all = StationaryClosedForm::new(
            lat,
            &StationaryErrors {
                eps_n: g * DEG_PER_HOUR,
                da_n: a * MICRO_G,
                ..Default::default()
            },
            params,
        )
        .eval(t)
        .dp_n;
        for (k, total) in all.iter().take(2).enumerate() {
            let sum: f64 = rows.iter().map(|r| r.dp_ne_m[k]).sum();
            assert!((sum - total).abs() <= 1e-7, "axis {k}: {sum} vs {total}");
        }
        // every horizontal source matters; the down accelerometer bias has no effect
        // (vertical channel held)
        for r in &rows {
            let m = r.dp_ne_m[0].hypot(r.dp_ne_m[1]);
            if r.source == "accel bias D" {
                assert_eq!(m, 0.0);
            } else {
                assert!(m >= 100.0, "{}: {m}", r.source);
            }
        }
    }

    /// The nonlinear column follows the closed form (east gyro 0.01 °/h, 2 h: docs/validation.md
    /// §"error propagation" T9 INS −2011 m, closed form −2013 m; tolerance 1 % of the peak + 50 m).
    #[test]
    #[allow(clippy::unwrap_used)]
    fn nonlinear_column_matches_closed_form() {
        let lat = 37.5_f64.to_radians();
        let p = SchulerParams::T9;
        let col = nonlinear_column(
            lat,
            &p,
            &Vec3::new(0.0, 0.01, 0.0),
            &Vec3::zeros(),
            &[1.0, 2.0],
            &CancelToken::new(),
        )
        .unwrap();
        let closed = StationaryClosedForm::new(
            lat,
            &StationaryErrors {
                eps_n: Vec3::new(0.0, 0.01, 0.0) * DEG_PER_HOUR,
                ..Default::default()
            },
            p,
        );
        for (h, n) in [1.0, 2.0].iter().zip(&col) {
            let n = n.unwrap();
            let c = closed.eval(h * 3600.0);
            assert!((n.dp_n_m[0] - c.dp_n[0]).abs() < 0.01 * 2013.0 + 50.0);
            assert!(
                (n.phi[2] - c.phi[2]).abs() < 2e-5,
                "{} vs {}",
                n.phi[2],
                c.phi[2]
            );
        }
        assert!((col[1].unwrap().dp_n_m[0] + 2011.0).abs() < 5.0);
    }
}
