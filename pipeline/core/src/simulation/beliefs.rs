//! The probabilistic map of 002 beside the deterministic one, in the simulator
//! (`crate::probabilistic::map`): the views are the panoramas the deterministic run measured
//! (the same seed draws the same noise; `Sensor::observe` is the only draw of `mapping::run`),
//! those the map rejected included, and the motion command between two views is the true
//! heading of the displacement (the simulated camera faces the world's x axis) with Gaussian
//! noise.

use super::scenario::Scenario;
use super::sensor::Sensor;
use crate::edc::{self, Edc};
use crate::map::{Hypergraph, LandmarkId};
use crate::probabilistic::map::{
    self as belief_map, BeliefComparison, BeliefMap, Estimator, Heading,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::collections::BTreeMap;

/// How the simulator's beliefs are made.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BeliefSettings {
    #[serde(flatten)]
    pub estimator: Estimator,
    /// Motion-command noise s.d., radians.
    pub motion_noise: f64,
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
    let noise = Normal::new(0.0, settings.motion_noise.max(0.0)).expect("finite s.d.");
    belief_map::beliefs(
        &seen,
        &|from, to, rng| {
            let (a, b) = (scenario.stations[from], scenario.stations[to]);
            Some(Heading {
                angle: (b.y - a.y).atan2(b.x - a.x) + noise.sample(rng),
                sd: settings.motion_noise,
            })
        },
        bearing_sd(sensor),
        &settings.estimator,
        seed,
    )
}

/// Compares `beliefs` and the deterministic `map` with the truth of `scenario`.
pub fn compare(
    beliefs: &BeliefMap,
    map: &Hypergraph<Edc>,
    scenario: &Scenario,
) -> BeliefComparison {
    belief_map::compare(beliefs, map, &|ids| {
        let [a, b, c] = ids.map(|id| scenario.landmarks[id as usize]);
        edc::classify(a, b, c)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::probabilistic::map::{conditioned, Variant};
    use crate::simulation::run;

    /// Without noise the beliefs put the truth first, inside the deterministic map's sets,
    /// and are normalized; the deterministic map stays sound.
    #[test]
    fn exact_views_give_beliefs_that_agree_with_the_map_and_the_truth() {
        let scenario = Scenario::random(4, 10, 8, 100.0);
        let sensor = Sensor::exact(None);
        let settings = BeliefSettings {
            estimator: Estimator {
                variant: Variant::Fast,
                views: 3,
                particles: 300,
            },
            motion_noise: 0.05f64.to_radians(),
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
