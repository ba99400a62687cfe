//! `Map`: the EDC (or FDC) map of 000 §VI — fuse measurements or whole views, merge maps,
//! close and check constraint networks, JSON in and out (docs/MAP_FORMAT.md), relations as
//! flat little-endian `uint32` buffers that the Python layer views as numpy arrays.

use crate::calculus::{calculus_named, members};
use crate::errors::{self, ContradictionError};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use qrm_cli::commands::map::constraint_lines;
use qrm_cli::commands::{rng_json, CalculusName};
use qrm_core::calculus::{Calculus, RelationSet};
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::map::{
    Contradiction, Hypergraph, LandmarkId, Network, Observation, RealizeSettings, Sighting,
    UpdateReport,
};
use qrm_core::measurement::{Bearing, RangeOrder, StationView};
use qrm_core::neighborhood::estimate;

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Map>()?;
    Ok(())
}

/// A map of either calculus.
#[derive(Clone)]
enum Inner {
    Edc(Hypergraph<Edc>),
    Fdc(Hypergraph<Fdc>),
}

/// Runs `$body` with `$m` bound to the map of whichever calculus.
macro_rules! with_map {
    ($inner:expr, $m:ident => $body:expr) => {
        match $inner {
            Inner::Edc($m) => $body,
            Inner::Fdc($m) => $body,
        }
    };
}

#[pyclass(module = "qrm._qrm")]
#[derive(Clone)]
pub struct Map {
    inner: Inner,
}

/// A relation set from its members, checked against the calculus.
fn relation_set<C: Calculus>(relations: &[u8]) -> PyResult<RelationSet> {
    let count = C::universe().len() as u8;
    if let Some(bad) = relations.iter().find(|&&r| r == 0 || r > count) {
        return Err(PyValueError::new_err(format!(
            "relation {bad} is outside 1..={count} ({})",
            C::NAME
        )));
    }
    Ok(RelationSet::from_relations(relations.iter().copied()))
}

fn report(py: Python<'_>, r: &UpdateReport) -> PyResult<Py<PyDict>> {
    let d = PyDict::new(py);
    d.set_item("new_landmarks", r.new_landmarks)?;
    d.set_item("relations_tightened", r.relations_tightened)?;
    d.set_item("triples_changed", r.triples_changed)?;
    d.set_item("compositions", r.compositions)?;
    Ok(d.unbind())
}

fn contradiction(c: Contradiction) -> PyErr {
    ContradictionError::new_err(c.to_string())
}

fn fuse_into<C: Calculus>(
    map: &mut Hypergraph<C>,
    py: Python<'_>,
    observations: &[(LandmarkId, LandmarkId, LandmarkId, Vec<u8>)],
) -> PyResult<UpdateReport> {
    let batch = observations
        .iter()
        .map(|(a, b, c, states)| Ok(Observation::new(*a, *b, *c, relation_set::<C>(states)?)))
        .collect::<PyResult<Vec<_>>>()?;
    py.detach(|| map.fuse(&batch)).map_err(contradiction)
}

fn fuse_view_into<C: Calculus>(
    map: &mut Hypergraph<C>,
    py: Python<'_>,
    view: &StationView,
    landmarks: &[LandmarkId],
) -> PyResult<UpdateReport> {
    py.detach(|| {
        let batch = map.observations(view, &Sighting::all(landmarks));
        map.fuse(&batch)
    })
    .map_err(contradiction)
}

fn network<C: Calculus>(text: &str, json: bool) -> anyhow::Result<Network<C>> {
    Ok(if json {
        Network::from_json(text)?
    } else {
        Network::from_text(text)?
    })
}

/// The conflict of an inconsistent network, one constraint `A B C {r,…}` per line, each on a
/// line of its own after the message.
fn conflict_lines<C: Calculus>(network: &Network<C>) -> String {
    let conflict = network.minimal_conflict().unwrap_or_default();
    format!("\n{}", constraint_lines(&conflict).trim_end())
}

fn close_network<C: Calculus>(py: Python<'_>, text: &str, json: bool) -> PyResult<Hypergraph<C>> {
    let network = network::<C>(text, json).map_err(errors::qrm)?;
    py.detach(|| match network.close() {
        Ok(map) => Ok(map),
        Err(c) => Err(format!(
            "the network is inconsistent ({c}); a minimal set of conflicting constraints:{}",
            conflict_lines(&network)
        )),
    })
    .map_err(ContradictionError::new_err)
}

fn check_network<C: Calculus>(
    py: Python<'_>,
    text: &str,
    json: bool,
) -> PyResult<(bool, usize, String)> {
    let network = network::<C>(text, json).map_err(errors::qrm)?;
    Ok(py.detach(|| match network.close() {
        Ok(map) => (true, network.tightened(&map), String::new()),
        Err(c) => (false, 0, format!("{c}:{}", conflict_lines(&network))),
    }))
}

/// The `calculus` field of a map file.
fn calculus_of_json(text: &str) -> PyResult<CalculusName> {
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| errors::QrmError::new_err(format!("not JSON: {e}")))?;
    match value.get("calculus").and_then(|c| c.as_str()) {
        Some(name) => calculus_named(name),
        None => Err(errors::QrmError::new_err(
            "no \"calculus\" field: not a qrm map",
        )),
    }
}

#[pymethods]
impl Map {
    /// An empty map of `calculus` ("edc" or "fdc").
    #[new]
    #[pyo3(signature = (calculus = "edc"))]
    fn new(calculus: &str) -> PyResult<Map> {
        Ok(Map {
            inner: match calculus_named(calculus)? {
                CalculusName::Edc => Inner::Edc(Hypergraph::new()),
                CalculusName::Fdc => Inner::Fdc(Hypergraph::new()),
            },
        })
    }

    /// A map from its JSON text (docs/MAP_FORMAT.md).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Map> {
        let inner = match calculus_of_json(text)? {
            CalculusName::Edc => {
                Inner::Edc(Hypergraph::from_json(text).map_err(|e| errors::qrm(e.into()))?)
            }
            CalculusName::Fdc => {
                Inner::Fdc(Hypergraph::from_json(text).map_err(|e| errors::qrm(e.into()))?)
            }
        };
        Ok(Map { inner })
    }

    /// The map as JSON text, exactly as `pipeline run` writes map.json.
    fn to_json(&self) -> String {
        with_map!(&self.inner, m => m.to_json())
    }

    /// "EDC" or "FDC".
    #[getter]
    fn calculus(&self) -> &'static str {
        match self.inner {
            Inner::Edc(_) => Edc::NAME,
            Inner::Fdc(_) => Fdc::NAME,
        }
    }

    /// Landmark ids in insertion order.
    fn landmarks(&self) -> Vec<LandmarkId> {
        with_map!(&self.inner, m => m.landmarks().to_vec())
    }

    fn __len__(&self) -> usize {
        with_map!(&self.inner, m => m.len())
    }

    /// Landmarks, triples, open states and fully constrained triples.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        with_map!(&self.inner, m => {
            d.set_item("landmarks", m.len())?;
            d.set_item("triples", m.triple_count())?;
            d.set_item("open_states", m.open_states())?;
            d.set_item("fully_constrained_triples", m.fully_constrained_triples())?;
            d.set_item("states_per_relation", universe_size(m))?;
        });
        Ok(d)
    }

    /// The possible relations AB:C, or None if a landmark is not in the map.
    fn relation(&self, a: LandmarkId, b: LandmarkId, c: LandmarkId) -> Option<Vec<u8>> {
        with_map!(&self.inner, m => m.relation(a, b, c).map(members))
    }

    /// Every stored triple: (ids, masks) as little-endian uint32 buffers of shape (T, 3) —
    /// landmark ids (a, b, c) and the bitsets of AB:C, BC:A, CA:B (bit r−1 for relation r).
    fn relation_buffers<'py>(&self, py: Python<'py>) -> (Bound<'py, PyBytes>, Bound<'py, PyBytes>) {
        let (ids, masks) = py.detach(|| {
            with_map!(&self.inner, m => {
                let mut ids = Vec::with_capacity(m.triple_count() * 12);
                let mut masks = Vec::with_capacity(m.triple_count() * 12);
                for (a, b, c, sets) in m.triples() {
                    for id in [a, b, c] {
                        ids.extend_from_slice(&id.to_le_bytes());
                    }
                    for s in sets {
                        masks.extend_from_slice(&s.bits().to_le_bytes());
                    }
                }
                (ids, masks)
            })
        });
        (PyBytes::new(py, &ids), PyBytes::new(py, &masks))
    }

    /// Fuses observations `(a, b, c, relations)` ("AB:C is one of relations") as one update
    /// (000 §VI-B); a contradiction leaves the map unchanged and raises ContradictionError.
    fn fuse(
        &mut self,
        py: Python<'_>,
        observations: Vec<(LandmarkId, LandmarkId, LandmarkId, Vec<u8>)>,
    ) -> PyResult<Py<PyDict>> {
        let r = with_map!(&mut self.inner, m => fuse_into(m, py, &observations)?);
        report(py, &r)
    }

    /// Fuses one panorama: `landmarks[i]` seen at `bearings[i]` degrees (each within
    /// ±`uncertainty`), the range order as pairs (i, j) "i is nearer than j" (000 §IV, §VI-B).
    fn fuse_view(
        &mut self,
        py: Python<'_>,
        landmarks: Vec<LandmarkId>,
        bearings: Vec<f64>,
        order: Vec<(usize, usize)>,
        uncertainty: f64,
    ) -> PyResult<Py<PyDict>> {
        if landmarks.len() != bearings.len() {
            return Err(PyValueError::new_err(format!(
                "{} landmarks but {} bearings",
                landmarks.len(),
                bearings.len()
            )));
        }
        let order = RangeOrder::from_pairs(landmarks.len(), &order)
            .map_err(|e| PyValueError::new_err(format!("range order: {e}")))?;
        let bearings = bearings
            .iter()
            .map(|deg| Bearing {
                angle: deg.to_radians(),
                uncertainty: uncertainty.to_radians(),
            })
            .collect();
        let view =
            StationView::new(bearings, order).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let r = with_map!(&mut self.inner, m => fuse_view_into(m, py, &view, &landmarks)?);
        report(py, &r)
    }

    /// Fuses another map of the same calculus over the same landmark ids.
    fn merge(&mut self, py: Python<'_>, other: &Map) -> PyResult<Py<PyDict>> {
        let r = match (&mut self.inner, &other.inner) {
            (Inner::Edc(m), Inner::Edc(o)) => py.detach(|| m.merge(o)),
            (Inner::Fdc(m), Inner::Fdc(o)) => py.detach(|| m.merge(o)),
            _ => {
                return Err(PyValueError::new_err(
                    "cannot merge maps of different calculi",
                ))
            }
        }
        .map_err(contradiction)?;
        report(py, &r)
    }

    /// The RNG estimate (000 §VII-A, Algorithm 2) as JSON text, as rng.json; EDC maps only.
    fn rng_json(&self, py: Python<'_>) -> PyResult<String> {
        match &self.inner {
            Inner::Edc(m) => Ok(py.detach(|| {
                estimate(m)
                    .map(|rng| rng_json(m, &rng))
                    .expect("EDC has a lune")
            })),
            Inner::Fdc(_) => Err(errors::QrmError::new_err(
                "FDC maps have no RNG estimate (no lune)",
            )),
        }
    }

    /// Positions under which every relation holds, found by search as `pipeline map realize`
    /// (a witness layout for drawing), with its defaults for settings not given: (landmarks,
    /// x, y, violated, constrained).
    #[pyo3(signature = (seed = None, sweeps = None, restarts = None))]
    fn realize(
        &self,
        py: Python<'_>,
        seed: Option<u64>,
        sweeps: Option<usize>,
        restarts: Option<usize>,
    ) -> (Vec<LandmarkId>, Vec<f64>, Vec<f64>, usize, usize) {
        let default = RealizeSettings::default();
        let settings = RealizeSettings {
            seed: seed.unwrap_or(default.seed),
            sweeps: sweeps.unwrap_or(default.sweeps),
            restarts: restarts.unwrap_or(default.restarts),
        };
        let found = py.detach(|| with_map!(&self.inner, m => m.realize(&settings)));
        (
            found.landmarks,
            found.positions.iter().map(|p| p.x).collect(),
            found.positions.iter().map(|p| p.y).collect(),
            found.violated,
            found.constrained,
        )
    }

    fn copy(&self) -> Map {
        self.clone()
    }

    /// Closes a constraint network (map JSON, or text with one `A B C {r,…}` per line) to
    /// full path consistency, as `pipeline map close`; an inconsistent one raises
    /// ContradictionError naming a minimal conflicting set.
    #[staticmethod]
    fn close(py: Python<'_>, text: &str, calculus: &str, json: bool) -> PyResult<Map> {
        let inner = match calculus_named(calculus)? {
            CalculusName::Edc => Inner::Edc(close_network(py, text, json)?),
            CalculusName::Fdc => Inner::Fdc(close_network(py, text, json)?),
        };
        Ok(Map { inner })
    }

    /// Checks a constraint network as `pipeline map check`: (consistent, constraints closing
    /// tightens, the contradiction and a minimal conflicting set when inconsistent).
    #[staticmethod]
    fn check(
        py: Python<'_>,
        text: &str,
        calculus: &str,
        json: bool,
    ) -> PyResult<(bool, usize, String)> {
        match calculus_named(calculus)? {
            CalculusName::Edc => check_network::<Edc>(py, text, json),
            CalculusName::Fdc => check_network::<Fdc>(py, text, json),
        }
    }
}

/// Number of base relations of a map's calculus.
fn universe_size<C: Calculus>(_: &Hypergraph<C>) -> usize {
    C::universe().len()
}
