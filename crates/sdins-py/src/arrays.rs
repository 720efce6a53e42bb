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
    // the wrapper passes C-contiguous arrays: read them as flat row-major slices
    let (x, y) = match (dtheta.as_slice(), dv.as_slice()) {
        (Ok(x), Ok(y)) => (x, y),
        _ => return Err(err("dtheta and dv: expected C-contiguous float64 arrays")),
    };
    // one branch-free finiteness pass over each flat slice, then one conversion pass
    // (the work of examples/navigate_arrays); the row is located only on failure
    if !(x.iter().all(|v| v.is_finite()) && y.iter().all(|v| v.is_finite())) {
        let k = x
            .chunks_exact(3)
            .zip(y.chunks_exact(3))
            .position(|(p, q)| !(p.iter().chain(q).all(|v| v.is_finite())))
            .unwrap_or(0);
        return Err(err(format!("dtheta/dv row {k}: not finite")));
    }
    let out: Vec<Increment> = x
        .chunks_exact(3)
        .zip(y.chunks_exact(3))
        .map(|(p, q)| Increment {
            dtheta_b_rad: Vec3::new(p[0], p[1], p[2]),
            dv_b_mps: Vec3::new(q[0], q[1], q[2]),
        })
        .collect();
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
