//! `qrm._qrm`: the Python extension module, thin glue over `qrm_cli` and `qrm_core`
//! (docs/PYTHON.md). Arguments arrive converted by the pure-Python layer
//! (`python/qrm/__init__.py`: numpy arrays to lists, keyword options to command-line flags,
//! types and ranges of ids checked); the work, its validation and its error messages are those
//! of the `pipeline` command line. Long work runs with the GIL released; progress goes to an
//! optional Python function.

mod calculus;
mod commands;
mod errors;
mod map;

use pyo3::prelude::*;

#[pymodule]
fn _qrm(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(m)?;
    calculus::register(m)?;
    map::register(m)?;
    commands::register(m)?;
    Ok(())
}
