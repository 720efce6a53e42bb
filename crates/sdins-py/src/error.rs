//! `sdins.SdinsError`: a `ValueError` carrying the library's located message (the same
//! text the CLI prints after `sdins: error:`).

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::PyErr;

create_exception!(
    sdins,
    SdinsError,
    PyValueError,
    "Bad input to sdins: the message says what is wrong and where (file:line:column, key or parameter)."
);

/// Wrap any library error.
pub fn err(e: impl std::fmt::Display) -> PyErr {
    SdinsError::new_err(e.to_string())
}
