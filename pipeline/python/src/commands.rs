//! The long commands — `run`, `synth`, one run of a Monte Carlo study — from command-line
//! arguments, parsed by the command line's own grammar (`qrm_cli::Cli`) so that options,
//! defaults, checks and messages are the CLI's. The GIL is released while they work; progress
//! goes to an optional Python function `progress(stage, done, total)`.

use crate::errors;
use clap::Parser;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use qrm_cli::commands::run::{execute, Listener};
use qrm_cli::commands::simulate::{study, SimulateCommand};
use qrm_cli::commands::synth::render;
use qrm_cli::commands::CalculusName;
use qrm_cli::{Cli, Command};
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::simulation::Step;
use std::sync::{Arc, Mutex};

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(synth, m)?)?;
    m.add_function(wrap_pyfunction!(montecarlo_study, m)?)?;
    m.add_function(wrap_pyfunction!(montecarlo_run, m)?)?;
    Ok(())
}

/// `pipeline ARGS…` parsed.
fn parse(args: Vec<String>) -> PyResult<Command> {
    let argv = std::iter::once("pipeline".to_string()).chain(args);
    Cli::try_parse_from(argv)
        .map(|cli| cli.command)
        .map_err(errors::arguments)
}

/// A Python progress function called from worker threads. The first exception it raises (a
/// KeyboardInterrupt among them: signals are checked at every call) is kept, later calls are
/// skipped, and the exception is raised once the command has finished. Python delivers
/// signals to the main thread only: a KeyboardInterrupt is seen at the calls made there (the
/// map stage of a run), not at those from worker threads (detection, rendering).
struct Callback {
    function: Option<Py<PyAny>>,
    failure: Mutex<Option<PyErr>>,
}

impl Callback {
    fn new(function: Option<Py<PyAny>>) -> Arc<Callback> {
        Arc::new(Callback {
            function,
            failure: Mutex::new(None),
        })
    }

    /// Calls the function with the GIL (which keeps calls one at a time). The lock guards
    /// only the stored failure, never the call: the function may itself run parallel qrm
    /// work on this thread pool.
    fn call(&self, stage: &str, done: usize, total: usize) {
        let Some(function) = &self.function else {
            return;
        };
        if self.failure.lock().expect("no panics hold it").is_some() {
            return;
        }
        let result = Python::attach(|py| {
            function
                .call1(py, (stage, done, total))
                .and_then(|_| py.check_signals())
        });
        if let Err(e) = result {
            self.failure
                .lock()
                .expect("no panics hold it")
                .get_or_insert(e);
        }
    }

    /// `result`, unless the callback failed (its exception first: a KeyboardInterrupt it
    /// caught is not lost behind the command's own error).
    fn finish<T>(&self, result: PyResult<T>) -> PyResult<T> {
        match self.failure.lock().expect("no panics hold it").take() {
            Some(e) => Err(e),
            None => result,
        }
    }
}

/// `pipeline run ARGS…` without printing: the summary (summary.json) as JSON text, with the
/// warnings by kind added as `warnings: [[count, first message], …]`.
#[pyfunction]
#[pyo3(signature = (args, progress = None))]
fn run(py: Python<'_>, args: Vec<String>, progress: Option<Py<PyAny>>) -> PyResult<String> {
    let Command::Run(args) = parse(args)? else {
        return Err(PyValueError::new_err("not a run command"));
    };
    let callback = Callback::new(progress);
    let listener: Option<Box<Listener>> = callback.function.is_some().then(|| {
        let callback = Arc::clone(&callback);
        Box::new(move |stage: &str, done, total| callback.call(stage, done, total)) as Box<Listener>
    });
    let completed = callback.finish(py.detach(|| execute(&args, listener)).map_err(errors::qrm))?;
    let mut summary = serde_json::to_value(&completed.summary)
        .map_err(|e| errors::QrmError::new_err(e.to_string()))?;
    summary["warnings"] = serde_json::json!(completed.warnings);
    Ok(summary.to_string())
}

/// `pipeline synth ARGS…` without printing: what was rendered.
#[pyfunction]
#[pyo3(signature = (args, progress = None))]
fn synth<'py>(
    py: Python<'py>,
    args: Vec<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let Command::Synth(args) = parse(args)? else {
        return Err(PyValueError::new_err("not a synth command"));
    };
    let callback = Callback::new(progress);
    let rendered = callback.finish(
        py.detach(|| render(&args, &|done, total| callback.call("render", done, total)))
            .map_err(errors::qrm),
    )?;
    let d = PyDict::new(py);
    d.set_item("preset", rendered.preset)?;
    d.set_item("rocks", rendered.rocks)?;
    d.set_item("stations", rendered.stations)?;
    d.set_item("panoramas", rendered.panoramas)?;
    d.set_item("width", rendered.width)?;
    d.set_item("height", rendered.height)?;
    d.set_item("seconds", rendered.seconds)?;
    d.set_item("variant", rendered.variant)?;
    Ok(d)
}

/// The study `pipeline simulate montecarlo ARGS…` runs.
fn study_of(args: Vec<String>) -> PyResult<(qrm_core::simulation::MonteCarlo, CalculusName)> {
    let argv = ["simulate".to_string(), "montecarlo".to_string()]
        .into_iter()
        .chain(args)
        .collect();
    let Command::Simulate(SimulateCommand::Montecarlo(args)) = parse(argv)? else {
        return Err(PyValueError::new_err("not a Monte Carlo study"));
    };
    study(&args).map_err(errors::qrm)
}

/// The scenarios of the study `pipeline simulate montecarlo ARGS…`: its size and series.
#[pyfunction]
fn montecarlo_study<'py>(py: Python<'py>, args: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
    let (study, calculus) = study_of(args)?;
    let d = PyDict::new(py);
    d.set_item("calculus", calculus_label(calculus))?;
    d.set_item("maps", study.maps)?;
    d.set_item("landmarks", study.landmarks)?;
    d.set_item("stations", study.stations)?;
    d.set_item("side", study.side)?;
    d.set_item("nearest", study.nearest.clone())?;
    d.set_item("seed", study.seed)?;
    Ok(d)
}

fn calculus_label(c: CalculusName) -> &'static str {
    match c {
        CalculusName::Edc => Edc::NAME,
        CalculusName::Fdc => Fdc::NAME,
    }
}

/// Map number `map` of the study `pipeline simulate montecarlo ARGS…` with the `nearest`
/// landmarks seen (None: all), exactly as the study runs it: one list per metric, one value
/// per image (docs/PYTHON.md).
#[pyfunction]
#[pyo3(signature = (args, map, nearest))]
fn montecarlo_run<'py>(
    py: Python<'py>,
    args: Vec<String>,
    map: usize,
    nearest: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let (study, calculus) = study_of(args)?;
    if map >= study.maps {
        return Err(PyValueError::new_err(format!(
            "map {map} is outside the study's {} maps",
            study.maps
        )));
    }
    if nearest.is_some_and(|n| n < 3) {
        return Err(PyValueError::new_err(
            "nearest must be at least 3 (a triple)",
        ));
    }
    let steps = py.detach(|| match calculus {
        CalculusName::Edc => study.run_one::<Edc>(nearest, map),
        CalculusName::Fdc => study.run_one::<Fdc>(nearest, map),
    });
    steps_dict(py, &steps)
}

/// The per-image columns of a mapping run.
fn steps_dict<'py>(py: Python<'py>, steps: &[Step]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let column = |f: &dyn Fn(&Step) -> f64| steps.iter().map(f).collect::<Vec<f64>>();
    d.set_item(
        "removed_incorrect_pct",
        column(&|s| s.metrics.removed_incorrect_pct),
    )?;
    d.set_item(
        "non_adjacent_open_pct",
        column(&|s| s.metrics.non_adjacent_open_pct),
    )?;
    d.set_item(
        "fully_constrained_pct",
        column(&|s| s.metrics.fully_constrained_pct),
    )?;
    d.set_item("open_pct", column(&|s| s.metrics.open_pct))?;
    d.set_item("rng_cost", column(&|s| s.rng_cost.unwrap_or(0.0)))?;
    d.set_item(
        "rng_precision",
        column(&|s| s.rng.map_or(f64::NAN, |c| c.precision())),
    )?;
    d.set_item(
        "rng_recall",
        column(&|s| s.rng.map_or(f64::NAN, |c| c.recall())),
    )?;
    d.set_item(
        "unsound_relations",
        steps
            .iter()
            .map(|s| s.metrics.unsound_relations)
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "contradiction",
        steps.iter().map(|s| s.contradiction).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "visible",
        steps.iter().map(|s| s.visible).collect::<Vec<_>>(),
    )?;
    d.set_item("seconds", column(&|s| s.seconds))?;
    Ok(d)
}
