//! `sdins run` and Python `sdins.run` as one library call: the options of a side-by-side
//! run validated into a [`RunPlan`] ([`plan`]), then the run itself ([`run_plan`]),
//! reporting its output rows (and, for figures, every update) to a
//! [`RunObserver`]. Front ends only parse, observe and render.

use crate::cancel::CancelToken;
use crate::nav::epochs::EpochGrid;
use crate::nav::options::{algorithms, apply_grade, vertical_hold, AlgoChoice, OptionError};
use crate::nav::pipeline::{run_observed, PipelineError, RunObserver, RunOptions, RunSummary};
use crate::scenario::Scenario;

/// Which sensor errors a run applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SensorRun {
    /// ideal sensors (the algorithms' own errors)
    Ideal,
    /// the scenario's IMU error model, random stream `run` of its seed
    Run(u64),
}

/// A side-by-side run as a front end gives it; `None`: the scenario's default.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRequest {
    /// algorithms and their options
    pub algos: AlgoChoice,
    /// vertical channel: `free` or `hold`
    pub vertical: Option<String>,
    /// output row spacing \[s\] ([`crate::nav::epochs`])
    pub every_s: f64,
    /// stop time \[s\]
    pub until_s: Option<f64>,
    /// sensor errors
    pub sensors: SensorRun,
    /// IMU grade preset replacing the scenario's error model (`--grade`)
    pub grade: Option<String>,
}

impl Default for RunRequest {
    fn default() -> Self {
        Self {
            algos: AlgoChoice::default(),
            vertical: None,
            every_s: crate::nav::options::DEFAULT_EVERY_S,
            until_s: None,
            sensors: SensorRun::Run(0),
            grade: None,
        }
    }
}

/// A validated run: the scenario (with its grade applied) and the pipeline options.
#[derive(Clone, Debug)]
pub struct RunPlan {
    /// the scenario
    pub scenario: Scenario,
    /// the pipeline's options
    pub options: RunOptions,
    /// the time the run ends \[s\]
    pub t_end_s: f64,
    /// navigation update interval \[s\]
    pub dt_update_s: f64,
    /// output rows per algorithm (initial state and last update included)
    pub rows: u64,
}

/// Validate a request against its scenario. Messages name the option as the command line
/// spells it (`--algo`, `--every-s`, `--until-s`, `--vertical`, `--grade`).
pub fn plan(mut scenario: Scenario, req: &RunRequest) -> Result<RunPlan, OptionError> {
    if let Some(g) = &req.grade {
        apply_grade(&mut scenario, g)?;
    }
    let algos = algorithms(&req.algos, &scenario.nav)?;
    let Some(first) = algos.first() else {
        return Err(OptionError::Bad("--algo: no algorithm given".into()));
    };
    let hold = vertical_hold(req.vertical.as_deref(), scenario.nav.vertical_hold)?;
    if let Some(t) = req.until_s {
        if !(t.is_finite() && t > 0.0) {
            return Err(OptionError::Bad(format!(
                "--until-s {t}: expected a positive number of seconds"
            )));
        }
    }
    let t_end_s = req
        .until_s
        .map_or(scenario.duration_s(), |t| t.min(scenario.duration_s()));
    let dt_update_s = scenario.imu.dt_s() * first.samples as f64;
    let grid = EpochGrid::new(req.every_s, dt_update_s)?;
    let updates = (t_end_s / dt_update_s).round() as u64;
    let rows = (t_end_s / req.every_s).floor() as u64 + 2;
    let options = RunOptions {
        algos,
        vertical_hold: hold,
        every_s: Some(grid.every_s),
        until_s: req.until_s,
        sensor_run: match req.sensors {
            SensorRun::Ideal => None,
            SensorRun::Run(r) => Some(r),
        },
    };
    Ok(RunPlan {
        scenario,
        options,
        t_end_s,
        dt_update_s,
        rows: rows.min(updates + 1),
    })
}

/// Run a plan: output rows and (if the observer wants them) every update go to `obs`.
pub fn run_plan(
    plan: &RunPlan,
    cancel: &CancelToken,
    obs: &mut impl RunObserver,
) -> Result<Vec<RunSummary>, PipelineError> {
    run_observed(&plan.scenario, &plan.options, cancel, obs)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::nav::pipeline::NavError;
    use crate::truth::TruthSample;
    use sdins_core::nav::NavState;

    #[derive(Default)]
    struct Rows(Vec<f64>);
    impl RunObserver for Rows {
        fn epoch(&mut self, _: usize, _: &NavState, _: &TruthSample, e: &NavError) {
            self.0.push(e.t_s);
        }
    }

    #[test]
    fn rows_are_on_the_grid_and_include_start_and_end() {
        let scn = Scenario::load("turn-90dps").unwrap();
        let req = RunRequest {
            algos: AlgoChoice {
                algos: Some("savage".into()),
                ..AlgoChoice::default()
            },
            every_s: 0.5,
            ..RunRequest::default()
        };
        let p = plan(scn, &req).unwrap();
        let mut rows = Rows::default();
        run_plan(&p, &CancelToken::new(), &mut rows).unwrap();
        let dt = p.dt_update_s;
        assert_eq!(rows.0[0], 0.0);
        for (k, t) in rows.0.iter().enumerate().take(rows.0.len() - 1) {
            assert!(
                (t - 0.5 * k as f64).abs() <= 0.5 * dt + 1e-12,
                "row {k}: {t}"
            );
        }
        assert!((rows.0.last().unwrap() - p.t_end_s).abs() < 1e-9);
        assert!(rows.0.len() as u64 <= p.rows);
    }

    #[test]
    fn bad_options_name_the_option() {
        let scn = Scenario::load("turn-90dps").unwrap();
        for (req, want) in [
            (
                RunRequest {
                    every_s: 0.0,
                    ..RunRequest::default()
                },
                "--every-s",
            ),
            (
                RunRequest {
                    until_s: Some(-1.0),
                    ..RunRequest::default()
                },
                "--until-s",
            ),
            (
                RunRequest {
                    grade: Some("ultra".into()),
                    ..RunRequest::default()
                },
                "--grade",
            ),
            (
                RunRequest {
                    vertical: Some("up".into()),
                    ..RunRequest::default()
                },
                "--vertical",
            ),
        ] {
            let e = plan(scn.clone(), &req).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
    }
}
