//! The calculus (000 §III): classification of a point, the operators on relation sets, and the
//! measurement of one triple (000 §IV), as `pipeline classify|compose|unary|measure` do them.

use crate::errors;
use clap::ValueEnum;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use qrm_cli::commands::measure::{relations, RELATION_NAMES};
use qrm_cli::commands::CalculusName;
use qrm_cli::Operator;
use qrm_core::calculus::RelationSet;
use qrm_core::geometry::Point;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(classify, m)?)?;
    m.add_function(wrap_pyfunction!(compose, m)?)?;
    m.add_function(wrap_pyfunction!(unary, m)?)?;
    m.add_function(wrap_pyfunction!(measure, m)?)?;
    m.add("RELATION_NAMES", RELATION_NAMES)?;
    Ok(())
}

/// `edc` or `fdc`, any case.
pub fn calculus_named(name: &str) -> PyResult<CalculusName> {
    CalculusName::from_str(name, true).map_err(|_| {
        PyValueError::new_err(format!("unknown calculus {name:?}: use \"edc\" or \"fdc\""))
    })
}

/// The members of a relation set, ascending.
pub fn members(set: RelationSet) -> Vec<u8> {
    set.iter().collect()
}

/// The relation number of C to the directed pair A→B; `None` on a boundary.
#[pyfunction]
fn classify(calculus: &str, a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> PyResult<Option<u8>> {
    let point = |(x, y): (f64, f64)| -> PyResult<Point> {
        if !x.is_finite() || !y.is_finite() {
            return Err(PyValueError::new_err(format!(
                "point ({x}, {y}) must have finite coordinates"
            )));
        }
        Ok(Point::new(x, y))
    };
    qrm_cli::classify(calculus_named(calculus)?, point(a)?, point(b)?, point(c)?)
        .map_err(errors::qrm)
}

/// COMPOSE(AB:C, BC:D) of relation sets written as the command line takes them (`1,5,11`).
#[pyfunction]
fn compose(calculus: &str, ab_c: &str, bc_d: &str) -> PyResult<Vec<u8>> {
    qrm_cli::compose(calculus_named(calculus)?, ab_c, bc_d)
        .map(members)
        .map_err(errors::qrm)
}

/// LEFT, RIGHT or INVERSE (`operator`, any case) of a relation set.
#[pyfunction]
fn unary(calculus: &str, operator: &str, set: &str) -> PyResult<Vec<u8>> {
    let operator = Operator::from_str(operator, true).map_err(|_| {
        PyValueError::new_err(format!(
            "unknown operator {operator:?}: use \"left\", \"right\" or \"inverse\""
        ))
    })?;
    qrm_cli::unary(calculus_named(calculus)?, operator, set)
        .map(members)
        .map_err(errors::qrm)
}

/// The relations AB:C, BC:A, CA:B, BA:C, CB:A, AC:B of one triple from its bearings in degrees,
/// range order and range intervals (`pipeline measure --ranges`; 000 §IV).
#[pyfunction]
fn measure(
    calculus: &str,
    bearings: [f64; 3],
    order: &str,
    uncertainty: f64,
    ranges: &str,
) -> PyResult<Vec<Vec<u8>>> {
    let sets = relations(
        calculus_named(calculus)?,
        bearings,
        order,
        uncertainty,
        ranges,
    )
    .map_err(errors::qrm)?;
    Ok(sets.into_iter().map(members).collect())
}
