//! The navigation study of seed digest A.8: random landmark fields, random start/goal pairs,
//! trips driven by the leg follower on the true RNG or on the RNG estimated from a map after
//! `k` simulated images; success, path-length ratio, legs and re-plans per trip.

use super::mapping::run;
use super::navigation::{drive, Drive, Outcome, Trip};
use super::scenario::Scenario;
use super::sensor::Sensor;
use crate::edc::Edc;
use crate::geometry::Point;
use crate::map::LandmarkId;
use crate::navigation::RouteGraph;
use crate::neighborhood::{estimate, true_estimate};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;

/// Which RNG the rover plans on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RngSource {
    /// The RNG of the true positions, every edge certain.
    True,
    /// Algorithm 2's estimate from an EDC map of `images` simulated panoramas, each of the
    /// `nearest` landmarks (all if `None`), exact sensing (000 §VIII-B).
    Mapped {
        images: usize,
        nearest: Option<usize>,
    },
}

/// How landmarks are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// Uniform in the square (000 §VIII-B).
    Uniform,
    /// One landmark per cell of a square grid, moved within `jitter` of the cell's side from
    /// its centre: 000 §VII-B's "more uniform" landmark distribution.
    JitteredGrid { jitter: f64 },
}

/// A navigation study.
#[derive(Clone, Debug, PartialEq)]
pub struct NavigationStudy {
    pub worlds: usize,
    pub landmarks: usize,
    /// Start/goal pairs per world.
    pub pairs: usize,
    pub side: f64,
    pub layout: Layout,
    pub source: RngSource,
    pub drive: Drive,
    pub seed: u64,
}

/// One trip of the study, scored.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TripRecord {
    pub world: usize,
    pub pair: usize,
    pub outcome: Outcome,
    /// Path length over the straight start–goal distance.
    pub length_ratio: f64,
    pub length: f64,
    pub straight: f64,
    pub route_hops: usize,
    pub legs: usize,
    pub replans: usize,
    pub steps: usize,
}

impl NavigationStudy {
    /// The landmarks of world `w`.
    pub fn world(&self, w: usize) -> Vec<Point> {
        let seed = self.seed.wrapping_mul(1_000_003).wrapping_add(w as u64);
        match self.layout {
            Layout::Uniform => Scenario::random(seed, self.landmarks, 0, self.side).landmarks,
            Layout::JitteredGrid { jitter } => {
                jittered_grid(seed, self.landmarks, self.side, jitter)
            }
        }
    }

    /// The route graph of world `w`'s landmarks `points` from the study's RNG source.
    pub fn graph(&self, w: usize, points: &[Point]) -> RouteGraph {
        let ids: Vec<LandmarkId> = (0..points.len() as LandmarkId).collect();
        let rng = match self.source {
            RngSource::True => true_estimate(points),
            RngSource::Mapped { images, nearest } => {
                let mut field = Scenario::random(self.seed ^ w as u64, 0, images, self.side);
                field.landmarks = points.to_vec();
                let (_, map) = run::<Edc>(&field, &Sensor::exact(nearest), w as u64);
                estimate(&map).expect("EDC has a lune")
            }
        };
        RouteGraph::new(&ids, &rng)
    }

    /// The start/goal pairs of world `w`.
    pub fn pairs_of(&self, w: usize) -> Vec<(Point, Point)> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed.wrapping_add(7919 * w as u64 + 1));
        let side = self.side;
        let mut point = || Point::new(rng.random_range(0.0..side), rng.random_range(0.0..side));
        (0..self.pairs).map(|_| (point(), point())).collect()
    }

    /// The trips of world `w`.
    pub fn trips(&self, w: usize, points: &[Point], graph: &RouteGraph) -> Vec<Trip> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed.wrapping_add(w as u64));
        self.pairs_of(w)
            .into_iter()
            .map(|(start, goal)| drive(points, graph, start, goal, &self.drive, &mut rng))
            .collect()
    }

    /// Every trip of every world, worlds in parallel; `tick` after each world.
    pub fn run(&self, tick: &(dyn Fn() + Sync)) -> Vec<TripRecord> {
        let mut records: Vec<TripRecord> = (0..self.worlds)
            .into_par_iter()
            .flat_map_iter(|w| {
                let points = self.world(w);
                let graph = self.graph(w, &points);
                let trips = self.trips(w, &points, &graph);
                tick();
                trips
                    .into_iter()
                    .enumerate()
                    .map(move |(pair, trip)| TripRecord {
                        world: w,
                        pair,
                        outcome: trip.outcome,
                        length_ratio: trip.length() / trip.straight().max(f64::MIN_POSITIVE),
                        length: trip.length(),
                        straight: trip.straight(),
                        route_hops: trip.route.len().saturating_sub(1),
                        legs: trip.legs.len(),
                        replans: trip.replans,
                        steps: trip.steps(),
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        records.sort_by_key(|r| (r.world, r.pair));
        records
    }
}

/// `n` landmarks, one per cell of the smallest square grid holding them (cells in row order,
/// the last ones left empty), each uniform within `jitter` × the cell side of its centre.
pub fn jittered_grid(seed: u64, n: usize, side: f64, jitter: f64) -> Vec<Point> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let per_row = (n as f64).sqrt().ceil().max(1.0) as usize;
    let cell = side / per_row as f64;
    (0..n)
        .map(|k| {
            let (i, j) = (k % per_row, k / per_row);
            let mut offset = || rng.random_range(-jitter..=jitter) * cell;
            Point::new(
                (i as f64 + 0.5) * cell + offset(),
                (j as f64 + 0.5) * cell + offset(),
            )
        })
        .collect()
}

/// What a study's trips add up to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NavigationSummary {
    pub trips: usize,
    pub success_rate: f64,
    /// Path length over straight distance, over the trips that arrived.
    pub median_length_ratio: f64,
    pub p90_length_ratio: f64,
    pub mean_legs: f64,
    pub mean_replans: f64,
    pub outcomes: BTreeMap<String, usize>,
}

impl NavigationSummary {
    pub fn of(records: &[TripRecord]) -> NavigationSummary {
        let arrived: Vec<&TripRecord> = records
            .iter()
            .filter(|r| r.outcome == Outcome::Arrived)
            .collect();
        let mut ratios: Vec<f64> = arrived.iter().map(|r| r.length_ratio).collect();
        ratios.sort_by(f64::total_cmp);
        let quantile = |q: f64| {
            if ratios.is_empty() {
                f64::NAN
            } else {
                ratios[((ratios.len() - 1) as f64 * q).round() as usize]
            }
        };
        let mean = |f: &dyn Fn(&TripRecord) -> usize| {
            records.iter().map(|r| f(r) as f64).sum::<f64>() / records.len().max(1) as f64
        };
        let mut outcomes = BTreeMap::new();
        for r in records {
            let name = serde_json::to_value(r.outcome)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default();
            *outcomes.entry(name).or_insert(0) += 1;
        }
        NavigationSummary {
            trips: records.len(),
            success_rate: arrived.len() as f64 / records.len().max(1) as f64,
            median_length_ratio: quantile(0.5),
            p90_length_ratio: quantile(0.9),
            mean_legs: mean(&|r| r.legs),
            mean_replans: mean(&|r| r.replans),
            outcomes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigation::RouteCost;
    use crate::simulation::Controller;

    fn study(source: RngSource) -> NavigationStudy {
        NavigationStudy {
            worlds: 3,
            landmarks: 20,
            pairs: 10,
            side: 100.0,
            layout: Layout::Uniform,
            source,
            drive: Drive {
                step: 0.5,
                max_steps: 4000,
                max_replans: 3,
                sensor: Sensor::exact(None),
                cost: RouteCost::default(),
                controller: Controller::Legs,
            },
            seed: 5,
        }
    }

    /// With all landmarks visible every trip arrives, on the true RNG and on the estimate of
    /// a map after a few images (a superset of the true RNG when the map is sound).
    #[test]
    fn trips_arrive_on_true_and_estimated_rngs() {
        for source in [
            RngSource::True,
            RngSource::Mapped {
                images: 5,
                nearest: Some(12),
            },
        ] {
            let records = study(source).run(&|| {});
            let summary = NavigationSummary::of(&records);
            assert_eq!(summary.trips, 30);
            assert_eq!(summary.success_rate, 1.0, "{source:?}: {summary:?}");
            assert!(summary.median_length_ratio >= 1.0);
        }
    }

    #[test]
    fn a_jittered_grid_keeps_one_landmark_per_cell() {
        let points = jittered_grid(3, 30, 100.0, 0.3);
        assert_eq!(points.len(), 30);
        let cell = 100.0 / 6.0;
        for (k, p) in points.iter().enumerate() {
            let (i, j) = ((k % 6) as f64, (k / 6) as f64);
            assert!((p.x - (i + 0.5) * cell).abs() <= 0.3 * cell + 1e-9);
            assert!((p.y - (j + 0.5) * cell).abs() <= 0.3 * cell + 1e-9);
        }
    }
}
