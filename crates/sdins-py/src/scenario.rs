//! `sdins.Scenario` and `sdins.scenarios()`: the scenario files of docs/scenarios.md.

use crate::error::err;
use pyo3::prelude::*;
use sdins_sim::scenario::{builtin, Scenario as Scn, BUILTINS};
use std::path::Path;

/// A scenario: trajectory, start, IMU and navigation settings (docs/scenarios.md).
/// Picklable (it carries its TOML text).
#[pyclass(module = "sdins", frozen)]
pub struct Scenario {
    pub(crate) scn: Scn,
    text: String,
    label: String,
    /// the `from_reference` arguments, for pickling a recorded-trajectory scenario
    reference: Option<(std::path::PathBuf, f64, Option<String>, String)>,
}

impl Scenario {
    fn parse(text: &str, label: &str) -> PyResult<Self> {
        Ok(Scenario {
            scn: Scn::from_toml(text, label).map_err(err)?,
            text: text.to_string(),
            label: label.to_string(),
            reference: None,
        })
    }
}

#[pymethods]
impl Scenario {
    /// Parse scenario TOML; `file` names it in error messages (default `<string>`).
    #[new]
    #[pyo3(signature = (text, file=None))]
    fn new(text: &str, file: Option<&str>) -> PyResult<Self> {
        Scenario::parse(text, file.unwrap_or("<string>"))
    }

    /// A built-in scenario by name (see `sdins.scenarios()`).
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<Self> {
        match builtin(name) {
            Some(b) => Scenario::parse(b.toml, &format!("<built-in {}>", b.name)),
            None => Err(err(sdins_sim::scenario::ScenarioError::Unknown {
                name: name.to_string(),
                known: BUILTINS
                    .iter()
                    .map(|b| b.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })),
        }
    }

    /// Parse scenario TOML text; `file` names it in error messages.
    #[staticmethod]
    #[pyo3(signature = (text, file=None))]
    fn from_toml(text: &str, file: Option<&str>) -> PyResult<Self> {
        Scenario::parse(text, file.unwrap_or("<string>"))
    }

    /// Read a scenario file, or a gnss-ins-sim motion CSV (imported with the default
    /// options); errors name `path:line:column`.
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<Self> {
        let scn = Scn::from_file(Path::new(&path)).map_err(err)?;
        // the TOML the scenario was parsed from: the file's text, or a motion CSV's import
        let text = scn.source_toml.clone();
        Ok(Scenario {
            scn,
            text,
            label: path.display().to_string(),
            reference: None,
        })
    }

    /// A recorded trajectory as a scenario (docs/scenarios.md §"Recorded trajectories"):
    /// an sdins truth.csv, a PSINS avp CSV or NaveGo's ref.csv (told apart by the header),
    /// or any CSV with `columns` = "t_s=COL,lat_deg=COL,lon_deg=COL,h_m=COL,roll_deg=COL,
    /// pitch_deg=COL,yaw_deg=COL"; its C² interpolant is the truth, with an ideal IMU at
    /// `rate_hz` under `earth` ("wgs84" or "psins"). Truth time 0 is the first row.
    #[staticmethod]
    #[pyo3(signature = (path, rate_hz=100.0, columns=None, earth="wgs84"))]
    fn from_reference(
        path: std::path::PathBuf,
        rate_hz: f64,
        columns: Option<String>,
        earth: &str,
    ) -> PyResult<Self> {
        use sdins_sim::scenario::from_reference::{scenario_from_reference, ReferenceOptions};
        let opts = ReferenceOptions::from_names(rate_hz, columns.as_deref(), earth).map_err(err)?;
        let (scn, _) = scenario_from_reference(Path::new(&path), &opts).map_err(err)?;
        Ok(Scenario {
            text: scn.source_toml.clone(),
            label: path.display().to_string(),
            scn,
            reference: Some((path, rate_hz, columns, earth.to_string())),
        })
    }

    /// The scenario as TOML text (the text it was read from).
    fn to_toml(&self) -> String {
        self.text.clone()
    }

    /// Scenario name.
    #[getter]
    fn name(&self) -> String {
        self.scn.name.clone()
    }

    /// Duration [s].
    #[getter]
    fn duration_s(&self) -> f64 {
        self.scn.duration_s()
    }

    /// IMU sample interval δt [s].
    #[getter]
    fn dt_s(&self) -> f64 {
        self.scn.imu.dt_s()
    }

    /// IMU samples per navigation update N.
    #[getter]
    fn samples(&self) -> usize {
        self.scn.nav.samples
    }

    /// The scenario's default algorithms.
    #[getter]
    fn algos(&self) -> Vec<String> {
        self.scn.nav.algos.clone()
    }

    /// Earth model name.
    #[getter]
    fn earth(&self) -> &'static str {
        self.scn.nav.earth.name()
    }

    /// Start (lat_rad, lon_rad, h_m).
    #[getter]
    fn start(&self) -> (f64, f64, f64) {
        (
            self.scn.start.lat_rad,
            self.scn.start.lon_rad,
            self.scn.start.h_m,
        )
    }

    /// Pickling: the TOML text, or the `from_reference` arguments.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, pyo3::types::PyTuple>)> {
        let py = slf.py();
        let me = slf.get();
        let cls = py.get_type::<Scenario>();
        match &me.reference {
            Some((p, r, c, e)) => Ok((
                cls.getattr("from_reference")?,
                (p.clone(), *r, c.clone(), e.clone()).into_pyobject(py)?,
            )),
            None => Ok((
                cls.into_any(),
                (me.text.clone(), me.label.clone()).into_pyobject(py)?,
            )),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Scenario({:?}, {} s, {} Hz IMU, N = {})",
            self.scn.name,
            self.scn.duration_s(),
            1.0 / self.scn.imu.dt_s(),
            self.scn.nav.samples
        )
    }
}

/// The built-in scenarios: a list of (name, summary).
#[pyfunction]
pub fn scenarios() -> Vec<(&'static str, &'static str)> {
    BUILTINS.iter().map(|b| (b.name, b.summary)).collect()
}
