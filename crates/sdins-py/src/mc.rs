//! `sdins.montecarlo` (one shard of a job) and `sdins.merge` (exact merge of shards):
//! the work of `sdins montecarlo --shard i/n` and `sdins merge` (docs/montecarlo.md).
//! A state pickles as the CLI's `mc_state.json` text (floats stored as IEEE-754 bit
//! patterns), so states cross processes and machines without changing a bit.

use crate::arrays::{matrix, vector};
use crate::error::err;
use crate::interrupt;
use crate::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sdins_sim::analysis::montecarlo::{plan as mc_plan, McChoice, McRequest};
use sdins_sim::analysis::montecarlo::{McState as State, Shard, CHANNELS};

/// Accumulator state of a Monte Carlo job or shard (picklable).
#[pyclass(module = "sdins", frozen)]
pub struct McState {
    pub(crate) state: State,
}

#[pymethods]
impl McState {
    /// Restore a state from its JSON text (`mc_state.json` of `sdins montecarlo`).
    #[new]
    fn new(json: &str) -> PyResult<Self> {
        let state: State =
            serde_json::from_str(json).map_err(|e| err(format!("not a Monte Carlo state: {e}")))?;
        state.validate().map_err(err)?;
        Ok(McState { state })
    }

    /// Read `mc_state.json` (or a folder holding it) written by the CLI.
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<Self> {
        let file = if path.is_dir() {
            path.join("mc_state.json")
        } else {
            path
        };
        let text = std::fs::read_to_string(&file)
            .map_err(|e| err(format!("{}: cannot read: {e}", file.display())))?;
        McState::new(&text).map_err(|e| err(format!("{}: {e}", file.display())))
    }

    /// The state as JSON text (the CLI's `mc_state.json`).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.state).map_err(err)
    }

    /// Statistics of the blocks present: an `sdins.McStatistics`, the type `sdins.merge`
    /// returns.
    fn statistics<'py>(slf: &Bound<'py, Self>, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = stats_dict(py, &slf.borrow().state)?;
        py.import("sdins._results")?
            .getattr("McStatistics")?
            .call1((d, slf.clone()))
    }

    /// Block indices not yet computed.
    fn missing_blocks(&self) -> Vec<u64> {
        self.state.missing_blocks()
    }

    /// The job: scenario, fingerprint, algo, samples, runs, seed, block, every, until_s,
    /// vertical_hold.
    #[getter]
    fn job<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let j = &self.state.job;
        let d = PyDict::new(py);
        d.set_item("scenario", &j.scenario)?;
        d.set_item("fingerprint", &j.fingerprint)?;
        d.set_item("algo", &j.algo)?;
        d.set_item("samples", j.samples)?;
        d.set_item("runs", j.runs)?;
        d.set_item("seed", j.seed)?;
        d.set_item("block", j.block)?;
        d.set_item("every_s", j.every_s)?;
        d.set_item("until_s", j.until_s)?;
        d.set_item("vertical_hold", j.vertical_hold)?;
        Ok(d)
    }

    fn __getnewargs__(&self) -> PyResult<(String,)> {
        Ok((self.to_json()?,))
    }

    fn __eq__(&self, other: &McState) -> bool {
        self.state == other.state
    }

    fn __repr__(&self) -> String {
        let j = &self.state.job;
        format!(
            "McState({:?}, {}, {} runs, {} of {} blocks)",
            j.scenario,
            j.algo,
            j.runs,
            self.state.blocks.len(),
            sdins_sim::analysis::montecarlo::plan::block_count(j.runs, j.block)
        )
    }
}

/// Statistics as arrays: `times_s` (m,), `mean`, `sigma`, `p05`, `p50`, `p95` (m, 9) in
/// the channel order of `channels` (pos N/E/D m, vel N/E/D m/s, att N/E/D rad).
fn stats_dict<'py>(py: Python<'py>, st: &State) -> PyResult<Bound<'py, PyDict>> {
    let s = st.statistics();
    let m = s.times_s.len();
    let mut cols: [Vec<f64>; 5] = std::array::from_fn(|_| Vec::with_capacity(m * 9));
    for row in &s.cells {
        for c in row {
            cols[0].push(c.mean);
            cols[1].push(c.sigma);
            cols[2].push(c.p05);
            cols[3].push(c.p50);
            cols[4].push(c.p95);
        }
    }
    let d = PyDict::new(py);
    d.set_item("runs", s.runs)?;
    d.set_item("complete", s.complete)?;
    d.set_item("channels", CHANNELS.to_vec())?;
    d.set_item("times_s", vector(py, s.times_s))?;
    let [mean, sigma, p05, p50, p95] = cols;
    d.set_item("mean", matrix(py, mean, 9)?)?;
    d.set_item("sigma", matrix(py, sigma, 9)?)?;
    d.set_item("p05", matrix(py, p05, 9)?)?;
    d.set_item("p50", matrix(py, p50, 9)?)?;
    d.set_item("p95", matrix(py, p95, 9)?)?;
    Ok(d)
}

/// Compute shard `shard = (i, n)` of a Monte Carlo job (see the wrapper's docstring).
#[pyfunction]
#[pyo3(signature = (scenario, runs, seed=None, shard=None, algo=None, samples=None, grade=None, every_s=None, until_s=None, vertical=None, block=None, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn montecarlo(
    py: Python<'_>,
    scenario: &Scenario,
    runs: u64,
    seed: Option<u64>,
    shard: Option<(u64, u64)>,
    algo: Option<String>,
    samples: Option<usize>,
    grade: Option<String>,
    every_s: Option<f64>,
    until_s: Option<f64>,
    vertical: Option<String>,
    block: Option<u64>,
    threads: Option<usize>,
) -> PyResult<McState> {
    let req = McRequest {
        choice: McChoice {
            runs,
            seed,
            algo,
            samples,
            every_s,
            until_s,
            vertical,
            block,
        },
        grade,
        shard: shard.map(|(index, count)| Shard { index, count }),
        threads,
    };
    let plan = mc_plan(scenario.scn.clone(), &req).map_err(err)?;
    let result = interrupt::run(py, |tok| {
        let cancelled = || tok.is_cancelled();
        plan.run(&|| {}, &cancelled)
    })?;
    Ok(McState {
        state: result.map_err(err)?,
    })
}

/// Merge shard states exactly (any order) and return the statistics.
#[pyfunction]
#[pyo3(signature = (states, allow_partial=None))]
pub fn merge<'py>(
    py: Python<'py>,
    states: Vec<PyRef<'py, McState>>,
    allow_partial: Option<bool>,
) -> PyResult<(McState, Bound<'py, PyDict>)> {
    let v: Vec<State> = states.iter().map(|s| s.state.clone()).collect();
    let merged = State::merge(&v).map_err(err)?;
    let missing = merged.missing_blocks();
    if !missing.is_empty() && !allow_partial.unwrap_or(false) {
        return Err(err(format!(
            "{} of {} blocks missing (first missing block {}; runs {}..): give every shard, or allow_partial=True",
            missing.len(),
            sdins_sim::analysis::montecarlo::plan::block_count(merged.job.runs, merged.job.block),
            missing[0],
            missing[0] * merged.job.block
        )));
    }
    let stats = stats_dict(py, &merged)?;
    Ok((McState { state: merged }, stats))
}
