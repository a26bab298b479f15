//! Sweeps from Python: `run_variants` runs a batch of variants of a workcell (read from
//! disk, or from files handed over in memory: what a Ray or Dask worker gets) on Rust
//! threads with the GIL released, and returns the sweep table's columns and rows;
//! `cell_files` gathers every file a workcell reads, for such a worker. `vworks.sweep`
//! (python/vworks/_sweep.py) builds on them.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};
use vworks_cell::{Disk, Files, Loader, MemoryFiles, Override};
use vworks_sweep::Table;
use vworks_sweep::run::RunOptions;
use vworks_sweep::table::Value;

use crate::errors::CellError;
use crate::units::to_ns;

/// A Python value as the workcell file would write it.
fn toml_value(v: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        Ok(toml::Value::Boolean(v.extract()?))
    } else if v.is_instance_of::<PyInt>() {
        Ok(toml::Value::Integer(v.extract()?))
    } else if v.is_instance_of::<PyFloat>() {
        Ok(toml::Value::Float(v.extract()?))
    } else if v.is_instance_of::<PyString>() {
        Ok(toml::Value::String(v.extract()?))
    } else if let Ok(x) = v.extract::<f64>() {
        // numpy scalars and the like
        Ok(toml::Value::Float(x))
    } else {
        Err(PyValueError::new_err(format!(
            "the value of `{path}` is {}, not a number, a string with a unit or a bool",
            v.repr()?
        )))
    }
}

fn py_value<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Int(i) => i.into_pyobject(py)?.into_any(),
        Value::Num(x) => x.into_pyobject(py)?.into_any(),
        Value::Text(s) => s.into_pyobject(py)?.into_any(),
        Value::Empty => py.None().into_bound(py),
    })
}

/// Runs `variants` (each a list of `(path, value)`) of the workcell `cell` and returns
/// `(columns, rows)` of the sweep table; `variables` name the variable columns (the first
/// path of each), `offset` is added to the variant numbers. With `files` (path → bytes,
/// as `cell_files` gives them) the workcell and everything it reads come from memory.
/// Ctrl-C stops the runs under way and raises `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (cell, variants, variables, jobs=None, until=None, files=None, offset=0))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_variants<'py>(
    py: Python<'py>,
    cell: PathBuf,
    variants: &Bound<'py, PyList>,
    variables: Vec<String>,
    jobs: Option<usize>,
    until: Option<f64>,
    files: Option<BTreeMap<String, Vec<u8>>>,
    offset: usize,
) -> PyResult<(Vec<String>, Bound<'py, PyList>)> {
    let mut parsed: Vec<Vec<Override>> = Vec::with_capacity(variants.len());
    for v in variants.iter() {
        let mut o = Vec::new();
        for pair in v.try_iter()? {
            let (path, value): (String, Bound<'py, PyAny>) = pair?.extract()?;
            let value = toml_value(&value, &path)?;
            o.push(Override { path, value });
        }
        parsed.push(o);
    }
    let until_ns = until.map(|t| to_ns(t, "until")).transpose()?;
    let memory = files.map(|f| MemoryFiles {
        files: f.into_iter().map(|(p, b)| (PathBuf::from(p), b)).collect(),
    });
    let fs: &(dyn Files + Sync) = match &memory {
        Some(m) => m,
        None => &Disk,
    };
    let stop = Arc::new(AtomicBool::new(false));
    let (outcome, interrupted) = crate::interrupt::interruptible(py, &stop, || {
        let loader = Loader::new(&cell, fs).map_err(|e| e.to_string())?;
        for o in parsed.iter().flatten() {
            loader.check(&o.path).map_err(|e| e.to_string())?;
        }
        let options = RunOptions {
            jobs: jobs.unwrap_or(0),
            until_ns,
            keep_logs: None,
            keep_logs_of: None,
            variant_timeout: None,
        };
        let mut rows = vworks_sweep::run_variants(&loader, &parsed, &options, &|_| {}, Some(&stop));
        for r in &mut rows {
            r.index += offset;
        }
        Ok::<_, String>(Table::of_cell(&variables, loader.base(), &rows))
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    let table = outcome.map_err(CellError::new_err)?;
    let rows = PyList::empty(py);
    for r in &table.rows {
        let row = PyList::empty(py);
        for v in r {
            row.append(py_value(py, v)?)?;
        }
        rows.append(row)?;
    }
    Ok((table.columns, rows))
}

/// Every file the workcell at `cell` reads (the workcell, its programs, URDFs and meshes),
/// path → bytes, by the paths the loader uses: what a worker on another machine needs.
#[pyfunction]
pub(crate) fn cell_files<'py>(py: Python<'py>, cell: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let loaded = py
        .detach(|| vworks_cell::load(&cell))
        .map_err(|e| CellError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    for (path, text) in &loaded.sources {
        out.set_item(path, pyo3::types::PyBytes::new(py, text.as_bytes()))?;
    }
    for (path, bytes) in &loaded.files {
        out.set_item(path, pyo3::types::PyBytes::new(py, bytes))?;
    }
    Ok(out)
}
