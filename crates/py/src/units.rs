//! Times between Python (seconds, floats) and the engine (integer nanoseconds).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

const NS: f64 = 1e9;

pub(crate) fn secs(ns: i64) -> f64 {
    ns as f64 / NS
}

/// A time to stop at, in seconds (a float or an int), to integer nanoseconds: any time
/// from 0, as `vworks run --until` and sweeps take it ([`vworks_app::until_ns`]).
pub(crate) fn to_ns(seconds: f64, what: &str) -> PyResult<i64> {
    vworks_app::until_ns(seconds).map_err(|_| {
        PyValueError::new_err(format!(
            "{what} must be a time in seconds, at least 0 (got {seconds})"
        ))
    })
}
