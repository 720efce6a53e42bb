//! numpy in and out: float64 arrays taken by reference, results moved into numpy
//! without a copy (`PyArray1::from_vec` keeps the Rust allocation).

use crate::error::err;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use sdins_core::coning::Increment;
use sdins_core::math::Vec3;

/// A `(rows, cols)` array from a row-major vector (no copy).
pub fn matrix<'py>(py: Python<'py>, v: Vec<f64>, cols: usize) -> PyResult<Bound<'py, PyAny>> {
    let rows = v.len() / cols.max(1);
    Ok(PyArray1::from_vec(py, v).reshape([rows, cols])?.into_any())
}

/// A 1-D array (no copy).
pub fn vector(py: Python<'_>, v: Vec<f64>) -> Bound<'_, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// Increments from `dtheta` (n, 3) [rad] and `dv` (n, 3) [m/s], body FRD.
pub fn increments(
    dtheta: &PyReadonlyArray2<'_, f64>,
    dv: &PyReadonlyArray2<'_, f64>,
) -> PyResult<Vec<Increment>> {
    let (a, b) = (dtheta.shape(), dv.shape());
    if a[1] != 3 || b[1] != 3 || a[0] != b[0] {
        return Err(err(format!(
            "dtheta and dv: expected two (n, 3) arrays of the same n, got {a:?} and {b:?}"
        )));
    }
    let (x, y) = (dtheta.as_array(), dv.as_array());
    let mut out = Vec::with_capacity(a[0]);
    for k in 0..a[0] {
        let inc = Increment {
            dtheta_b_rad: Vec3::new(x[[k, 0]], x[[k, 1]], x[[k, 2]]),
            dv_b_mps: Vec3::new(y[[k, 0]], y[[k, 1]], y[[k, 2]]),
        };
        if !(inc.dtheta_b_rad.iter().all(|v| v.is_finite())
            && inc.dv_b_mps.iter().all(|v| v.is_finite()))
        {
            return Err(err(format!("dtheta/dv row {k}: not finite")));
        }
        out.push(inc);
    }
    Ok(out)
}

/// Split increments into the (n, 3) Δθ and Δv arrays.
pub fn from_increments<'py>(
    py: Python<'py>,
    incs: &[Increment],
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let mut a = Vec::with_capacity(incs.len() * 3);
    let mut b = Vec::with_capacity(incs.len() * 3);
    for i in incs {
        a.extend_from_slice(&[i.dtheta_b_rad.x, i.dtheta_b_rad.y, i.dtheta_b_rad.z]);
        b.extend_from_slice(&[i.dv_b_mps.x, i.dv_b_mps.y, i.dv_b_mps.z]);
    }
    Ok((matrix(py, a, 3)?, matrix(py, b, 3)?))
}
