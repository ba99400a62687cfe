//! One simulated mapping run (000 §VIII-B): at every imaging point, measure the visible
//! triples against what the map still allows, fuse, and score the map against ground truth.

use super::scenario::Scenario;
use super::sensor::Sensor;
use crate::calculus::{Calculus, RelationSet};
use crate::map::{Hypergraph, LandmarkId, Observation};
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

/// The measurements of one panorama as map observations, restricted to what `map` allows.
pub fn observations<C: Calculus>(
    map: &Hypergraph<C>,
    ids: &[LandmarkId],
    panorama: &crate::measurement::Panorama,
) -> Vec<Observation> {
    let open = |[a, b, c]: [usize; 3]| -> [RelationSet; 3] {
        let (a, b, c) = (ids[a], ids[b], ids[c]);
        [
            map.relation(a, b, c).unwrap_or(C::universe()),
            map.relation(b, c, a).unwrap_or(C::universe()),
            map.relation(c, a, b).unwrap_or(C::universe()),
        ]
    };
    panorama
        .measure_all::<C, _>(open)
        .into_iter()
        .flat_map(|m| {
            let [a, b, c] = m.landmarks.map(|i| ids[i]);
            [
                Observation::new(a, b, c, m.states[0]),
                Observation::new(b, c, a, m.states[1]),
                Observation::new(c, a, b, m.states[2]),
            ]
        })
        .collect()
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
        let batch = observations(&map, &ids, &panorama);
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
