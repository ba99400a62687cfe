//! The probabilistic map of 002 beside the deterministic one, in the simulator: every triple
//! seen together at some imaging points gets a belief over its 20 EDC states from the first
//! few of those views (002 Algorithm 1, full or fast), computed from the panoramas the
//! deterministic run measured (the same seed draws the same noise; `Sensor::observe` is the
//! only draw of `mapping::run`), those the map rejected included.
//!
//! What 002 assumes and the deterministic map does not: a motion command between the views,
//! the heading of the displacement in the earlier camera's frame, with Gaussian noise. The
//! prior is a disc of [`PRIOR_RADIUS`] `|AB|` about AB's midpoint: the simulator's square in
//! metres is not known in the frame of a triple without metric positions.

use super::scenario::Scenario;
use super::sensor::Sensor;
use crate::calculus::RelationSet;
use crate::edc::{self, Edc};
use crate::geometry::Point;
use crate::map::{Hypergraph, LandmarkId};
use crate::probabilistic::{estimate_fast, estimate_full, Belief, Noise, Prior, View};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::TAU;

/// Radius of the prior disc, in `|AB|`.
pub const PRIOR_RADIUS: f64 = 1000.0;

/// Which of 002's estimators makes the beliefs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Variant {
    Full,
    Fast,
}

/// How the beliefs are made.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BeliefSettings {
    pub variant: Variant,
    /// Views used per triple: the first ones that see it (002: 3 time steps).
    pub views: usize,
    /// Motion-command noise s.d., radians.
    pub motion_noise: f64,
    pub particles: usize,
}

/// The belief over `AB:C` of landmarks `a < b < c` (ids), from `views` views.
#[derive(Clone, Debug, PartialEq)]
pub struct TripleBelief {
    pub ids: [LandmarkId; 3],
    pub views: usize,
    pub belief: Belief,
}

/// Every co-observed triple's belief (a triple seen at one station only gets none: 002 needs
/// two views to resect `C`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BeliefMap {
    pub triples: Vec<TripleBelief>,
}

/// The bearing s.d. the estimators assume for the sensor's uniform errors in `±noise`
/// (the uniform's s.d., floored so that exact bearings still weight particles).
pub fn bearing_sd(sensor: &Sensor) -> f64 {
    (sensor.bearing_noise / 3f64.sqrt()).max(0.05f64.to_radians())
}

/// The beliefs of every triple seen together at two or more imaging points of `scenario`,
/// observed by `sensor` with the draws of `mapping::run(scenario, sensor, seed)`.
pub fn beliefs(
    scenario: &Scenario,
    sensor: &Sensor,
    seed: u64,
    settings: &BeliefSettings,
) -> BeliefMap {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Per station: landmark id → world bearing, as mapping::run draws them.
    let seen: Vec<BTreeMap<LandmarkId, f64>> = scenario
        .stations
        .iter()
        .map(|&station| {
            let (ids, view) = sensor.observe(&scenario.landmarks, station, &mut rng);
            ids.into_iter()
                .zip(view.bearings.iter().map(|b| b.angle))
                .collect()
        })
        .collect();
    let mut triples: BTreeMap<[LandmarkId; 3], Vec<usize>> = BTreeMap::new();
    for (s, station) in seen.iter().enumerate() {
        let ids: Vec<LandmarkId> = station.keys().copied().collect();
        for i in 0..ids.len() {
            for j in i + 1..ids.len() {
                for k in j + 1..ids.len() {
                    let stations = triples.entry([ids[i], ids[j], ids[k]]).or_default();
                    if stations.len() < settings.views {
                        stations.push(s);
                    }
                }
            }
        }
    }
    let noise = Noise {
        bearing: bearing_sd(sensor),
        motion: settings.motion_noise,
    };
    let motion = Normal::new(0.0, settings.motion_noise.max(0.0)).expect("finite s.d.");
    let triples: Vec<TripleBelief> = triples
        .into_iter()
        .filter(|(_, stations)| stations.len() >= 2)
        .collect::<Vec<_>>()
        .into_par_iter()
        .filter_map(|(ids, stations)| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xbe11ef);
            let stream = ids.iter().fold(0u64, |h, &id| {
                h.wrapping_mul(1_000_003).wrapping_add(u64::from(id))
            });
            rng.set_stream(stream);
            let views: Vec<View> = stations
                .iter()
                .enumerate()
                .map(|(k, &s)| View {
                    bearings: ids.map(|id| seen[s][&id]),
                    // The simulated camera's heading is the world's x axis.
                    motion: (k > 0).then(|| {
                        let (from, to) = (scenario.stations[stations[k - 1]], scenario.stations[s]);
                        (to.y - from.y).atan2(to.x - from.x) + motion.sample(&mut rng)
                    }),
                })
                .collect();
            let prior = disc_prior();
            let estimate = match settings.variant {
                Variant::Full => estimate_full(&views, &prior, noise, settings.particles, &mut rng),
                Variant::Fast => {
                    estimate_fast(&views, &prior, noise.bearing, settings.particles, &mut rng)
                }
            }?;
            Some(TripleBelief {
                ids,
                views: views.len(),
                belief: estimate.landmark,
            })
        })
        .collect();
    BeliefMap { triples }
}

/// The prior: a 32-gon of radius [`PRIOR_RADIUS`] about AB's midpoint.
fn disc_prior() -> Prior {
    Prior {
        polygon: (0..32)
            .map(|k| {
                let t = TAU * f64::from(k) / 32.0;
                Point::new(PRIOR_RADIUS * t.cos(), 0.5 + PRIOR_RADIUS * t.sin())
            })
            .collect(),
    }
}

/// How the beliefs and the deterministic map's sets compare with the truth, over the triples
/// that have a belief.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct BeliefComparison {
    pub triples: usize,
    /// The truth is the most likely state.
    pub truth_most_likely: usize,
    /// The truth has positive belief (the belief's support, as a set, is sound).
    pub truth_in_support: usize,
    /// Median DMSE of the beliefs.
    pub median_dmse: f64,
    /// The deterministic map's relation holds the truth (sound).
    pub truth_in_set: usize,
    /// Mean number of states in the deterministic relation, and in the belief's support.
    pub mean_set_size: f64,
    pub mean_support_size: f64,
    /// The belief's most likely state lies in the deterministic relation.
    pub most_likely_in_set: usize,
    /// Beliefs conditioned on the deterministic map (restricted to its set, renormalized):
    /// the truth is then the most likely state.
    pub conditioned_truth_most_likely: usize,
}

/// What [`conditioned`] adds to every state of the deterministic set: finite particles can
/// miss a state that sound constraints still allow.
pub const FLOOR: f64 = 1e-3;

/// The probabilistic map's belief of a relation: the estimate restricted to the deterministic
/// map's `set` (sound within the sensor's error model), [`FLOOR`] added to each state of the
/// set, renormalized. Its support is exactly `set`: the set view of the probabilistic
/// map is the deterministic map, and the belief ranks its states. An empty set (which a
/// consistent map never holds) gives the estimate unchanged.
pub fn conditioned(belief: &Belief, set: RelationSet) -> Belief {
    let mut weights = [0.0; crate::probabilistic::STATES];
    for r in set.iter() {
        weights[r as usize - 1] = belief.probability(r) + FLOOR;
    }
    Belief::from_weights(weights).unwrap_or(*belief)
}

/// Compares `beliefs` and the deterministic `map` with the truth of `scenario`.
pub fn compare(
    beliefs: &BeliefMap,
    map: &Hypergraph<Edc>,
    scenario: &Scenario,
) -> BeliefComparison {
    let mut c = BeliefComparison::default();
    let mut dmses = Vec::new();
    let (mut set_sizes, mut support_sizes) = (0usize, 0usize);
    for t in &beliefs.triples {
        let [a, b, x] = t.ids.map(|id| scenario.landmarks[id as usize]);
        let Some(truth) = edc::classify(a, b, x) else {
            continue;
        };
        let set = map
            .relation(t.ids[0], t.ids[1], t.ids[2])
            .unwrap_or_else(|| RelationSet::all(crate::probabilistic::STATES));
        c.triples += 1;
        let top = t.belief.most_likely();
        c.truth_most_likely += usize::from(top == truth);
        c.truth_in_support += usize::from(t.belief.probability(truth) > 0.0);
        c.truth_in_set += usize::from(set.contains(truth));
        c.most_likely_in_set += usize::from(set.contains(top));
        c.conditioned_truth_most_likely +=
            usize::from(conditioned(&t.belief, set).most_likely() == truth);
        set_sizes += set.len();
        support_sizes += t.belief.support().len();
        dmses.push(crate::probabilistic::dmse(&t.belief, truth));
    }
    if c.triples > 0 {
        c.mean_set_size = set_sizes as f64 / c.triples as f64;
        c.mean_support_size = support_sizes as f64 / c.triples as f64;
        c.median_dmse = crate::probabilistic::study::quartiles(&mut dmses)[1];
    }
    c
}

impl BeliefMap {
    /// The beliefs as JSON (docs/MAP_FORMAT.md, "Beliefs"): per triple `a < b < c`, the
    /// number of views and `P(AB:C = r)` for r = 1..=20.
    pub fn to_json(&self, settings: &BeliefSettings) -> String {
        let triples: Vec<serde_json::Value> = self
            .triples
            .iter()
            .map(|t| {
                serde_json::json!({
                    "a": t.ids[0], "b": t.ids[1], "c": t.ids[2],
                    "views": t.views,
                    "ab_c": t.belief.probabilities(),
                })
            })
            .collect();
        let value = serde_json::json!({
            "format": "qrm-beliefs",
            "version": 1,
            "calculus": "EDC",
            "settings": settings,
            "triples": triples,
        });
        serde_json::to_string_pretty(&value).expect("JSON values serialise") + "\n"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::run;

    /// Without noise the beliefs put the truth first, inside the deterministic map's sets,
    /// and are normalized; the deterministic map stays sound.
    #[test]
    fn exact_views_give_beliefs_that_agree_with_the_map_and_the_truth() {
        let scenario = Scenario::random(4, 10, 8, 100.0);
        let sensor = Sensor::exact(None);
        let settings = BeliefSettings {
            variant: Variant::Fast,
            views: 3,
            motion_noise: 0.05f64.to_radians(),
            particles: 300,
        };
        let (_, map) = run::<Edc>(&scenario, &sensor, 9);
        let beliefs = beliefs(&scenario, &sensor, 9, &settings);
        assert_eq!(
            beliefs.triples.len(),
            120,
            "every triple is seen from 8 stations"
        );
        for t in &beliefs.triples {
            let set = map.relation(t.ids[0], t.ids[1], t.ids[2]).unwrap();
            let belief = conditioned(&t.belief, set);
            for b in [&t.belief, &belief] {
                let total: f64 = b.probabilities().iter().sum();
                assert!((total - 1.0).abs() < 1e-9);
            }
            assert_eq!(
                belief.support(),
                set,
                "the set view is the deterministic map"
            );
        }
        let c = compare(&beliefs, &map, &scenario);
        assert_eq!(c.truth_in_set, c.triples, "the deterministic map is sound");
        assert!(
            c.truth_most_likely as f64 >= 0.9 * c.triples as f64,
            "{c:?}"
        );
        assert!(
            c.conditioned_truth_most_likely as f64 >= 0.95 * c.triples as f64,
            "{c:?}"
        );
    }
}
