//! `sdins._sdins`: the native part of the Python package `sdins`.
//!
//! Every function calls the same `sdins-sim` library function as the CLI command of the
//! same name; arrays go in and out as float64 numpy arrays (no per-sample Python
//! objects). Long calls run on a worker thread with the GIL released while the calling
//! thread polls `Python::check_signals` and sets the library's `CancelToken` on
//! KeyboardInterrupt (`interrupt.rs`). The Python layer (`python/sdins/__init__.py`)
//! wraps the returned dicts into result classes with `.to_pandas()`.

use pyo3::prelude::*;

mod align;
mod arrays;
mod error;
mod fuse;
mod imu;
mod interrupt;
mod mc;
mod nav;
mod scenario;
mod truth;

#[pymodule]
fn _sdins(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SdinsError", m.py().get_type::<error::SdinsError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scenario::Scenario>()?;
    m.add_class::<mc::McState>()?;
    m.add_class::<fuse::FuseMcState>()?;
    m.add_function(wrap_pyfunction!(scenario::scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(truth::truth, m)?)?;
    m.add_function(wrap_pyfunction!(imu::corrupt, m)?)?;
    m.add_function(wrap_pyfunction!(imu::read_imu, m)?)?;
    m.add_function(wrap_pyfunction!(imu::allan, m)?)?;
    m.add_function(wrap_pyfunction!(nav::navigate, m)?)?;
    m.add_function(wrap_pyfunction!(nav::run, m)?)?;
    m.add_function(wrap_pyfunction!(mc::montecarlo, m)?)?;
    m.add_function(wrap_pyfunction!(mc::merge, m)?)?;
    m.add_function(wrap_pyfunction!(align::align, m)?)?;
    m.add_function(wrap_pyfunction!(align::errors, m)?)?;
    m.add_function(wrap_pyfunction!(align::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(fuse::fuse, m)?)?;
    m.add_function(wrap_pyfunction!(fuse::fuse_files, m)?)?;
    m.add_function(wrap_pyfunction!(fuse::fuse_montecarlo, m)?)?;
    m.add_function(wrap_pyfunction!(fuse::fuse_merge, m)?)?;
    m.add_function(wrap_pyfunction!(align::schuler_share_json, m)?)?;
    Ok(())
}
