//! One simulated mapping run (000 §VIII-B): at every imaging point, measure the visible
//! triples against what the map still allows, fuse, and score the map against ground truth.

use super::scenario::Scenario;
use super::sensor::Sensor;
use crate::calculus::Calculus;
use crate::map::{Hypergraph, LandmarkId, Sighting};
use crate::metrics::{evaluate, MapMetrics};
use crate::neighborhood::{compare, estimate, RngComparison};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// The state after fusing one panorama.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    pub metrics: MapMetrics,
    /// `Σ w_ij` of the RNG estimate (000 Fig. 7c); `None` for calculi without a lune.
    pub rng_cost: Option<f64>,
    pub rng: Option<RngComparison>,
    /// Wall time of measurement plus fusion (000 Fig. 7d).
    pub seconds: f64,
    /// Landmarks seen at this station.
    pub visible: usize,
    /// Whether the panorama contradicted the map and was rejected.
    pub contradiction: bool,
}

/// Maps `scenario` with `sensor`, scoring after every station; returns the scores and the
/// final map.
pub fn run<C: Calculus>(
    scenario: &Scenario,
    sensor: &Sensor,
    seed: u64,
) -> (Vec<Step>, Hypergraph<C>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut map = Hypergraph::<C>::new();
    let points = &scenario.landmarks;
    // The true relation of every ordered triple, classified once for all images.
    let n = points.len();
    let table: Vec<Option<u8>> = (0..n * n * n)
        .map(|i| {
            let (a, b, c) = (i / (n * n), i / n % n, i % n);
            C::classify(points[a], points[b], points[c])
        })
        .collect();
    let truth = |a: LandmarkId, b: LandmarkId, c: LandmarkId| {
        table[(a as usize * n + b as usize) * n + c as usize]
    };
    let mut steps = Vec::with_capacity(scenario.stations.len());
    for &station in &scenario.stations {
        let (ids, panorama) = sensor.observe(points, station, &mut rng);
        let start = Instant::now();
        let batch = map.observations(&panorama, &Sighting::all(&ids));
        let contradiction = map.fuse(&batch).is_err();
        let seconds = start.elapsed().as_secs_f64();
        let rng_estimate = estimate(&map);
        steps.push(Step {
            metrics: evaluate(&map, truth, points.len()),
            rng_cost: rng_estimate.as_ref().map(|e| e.total_cost()),
            rng: rng_estimate
                .as_ref()
                .map(|e| compare(&map, e, |id| points[id as usize])),
            seconds,
            visible: ids.len(),
            contradiction,
        });
    }
    (steps, map)
}
