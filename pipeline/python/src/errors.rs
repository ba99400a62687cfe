//! Errors as Python exceptions: `QrmError` for what the command line reports as `error: …`
//! (same message, with its causes), `ContradictionError` for measurements the map rules out,
//! and `ValueError` for arguments the command-line grammar rejects.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;

create_exception!(
    _qrm,
    QrmError,
    PyException,
    "A qrm operation failed; the message is the command line's."
);
create_exception!(
    _qrm,
    ContradictionError,
    QrmError,
    "Measurements or constraints contradict the map (nothing was changed)."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("QrmError", m.py().get_type::<QrmError>())?;
    m.add(
        "ContradictionError",
        m.py().get_type::<ContradictionError>(),
    )?;
    Ok(())
}

/// An error of the command line's, with its chain of causes as `pipeline` prints it.
pub fn qrm(e: anyhow::Error) -> PyErr {
    QrmError::new_err(format!("{e:#}"))
}

/// An argument the command-line grammar rejects: clap's message (with the possible values
/// or a suggestion) without its usage lines.
pub fn arguments(e: clap::Error) -> PyErr {
    let text = e.to_string();
    let message: Vec<&str> = text
        .lines()
        .map(str::trim)
        .take_while(|line| !line.starts_with("Usage:") && !line.starts_with("For more information"))
        .filter(|line| !line.is_empty())
        .collect();
    PyValueError::new_err(message.join(" ").trim_start_matches("error: ").to_string())
}
