//! Simulated mapping (000 §VIII-B) against ground truth: exact measurements never remove a true
//! state, fusion order does not matter, merging maps equals fusing both streams, and the RNG
//! estimate never prunes a true RNG edge.

use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::map::{Hypergraph, Sighting};
use qrm_core::simulation::{run, MonteCarlo, Scenario, Sensor};
use qrm_tests::rng;

fn sound_runs<C: Calculus>(sensor: Sensor, seeds: std::ops::Range<u64>) {
    for seed in seeds {
        let scenario = Scenario::random(seed, 12, 15, 100.0);
        let (steps, map) = run::<C>(&scenario, &sensor, seed);
        for (i, step) in steps.iter().enumerate() {
            assert_eq!(
                step.metrics.unsound_relations,
                0,
                "seed {seed} image {}",
                i + 1
            );
            assert!(!step.contradiction, "seed {seed} image {}", i + 1);
            if let Some(rng) = step.rng {
                assert_eq!(
                    rng.pruned_true, 0,
                    "seed {seed}: a true RNG edge was pruned"
                );
                assert_eq!(
                    rng.certain_false, 0,
                    "seed {seed}: a false RNG edge is certain"
                );
            }
        }
        assert!(!map.is_empty());
    }
}

#[test]
fn exact_measurements_are_sound() {
    sound_runs::<Edc>(Sensor::exact(None), 0..6);
    sound_runs::<Edc>(Sensor::exact(Some(6)), 6..12);
    sound_runs::<Fdc>(Sensor::exact(Some(8)), 12..16);
}

#[test]
fn noisy_bearings_within_the_declared_interval_are_sound() {
    let sensor = Sensor {
        nearest: Some(7),
        bearing_noise: 0.01,
        bearing_uncertainty: 0.01,
        order_swap_probability: 0.0,
        wrong_association_probability: 0.0,
    };
    sound_runs::<Edc>(sensor, 20..24);
}

/// The panoramas of a scenario as observation batches, each measured against an empty map so
/// that batches do not depend on fusion order.
fn batches(
    scenario: &Scenario,
    sensor: &Sensor,
    seed: u64,
) -> Vec<Vec<qrm_core::map::Observation>> {
    let mut random = rng(seed);
    let empty = Hypergraph::<Edc>::new();
    scenario
        .stations
        .iter()
        .map(|&station| {
            let (ids, panorama) = sensor.observe(&scenario.landmarks, station, &mut random);
            empty.observations(&panorama, &Sighting::all(&ids))
        })
        .collect()
}

#[test]
fn fusion_order_and_merging_do_not_change_the_map() {
    let scenario = Scenario::random(5, 10, 12, 100.0);
    let sensor = Sensor::exact(Some(7));
    let batches = batches(&scenario, &sensor, 5);
    let fuse_all = |order: &[usize]| {
        let mut map = Hypergraph::<Edc>::new();
        for &i in order {
            map.fuse(&batches[i]).expect("exact measurements agree");
        }
        map
    };
    let forward: Vec<usize> = (0..batches.len()).collect();
    let backward: Vec<usize> = forward.iter().rev().copied().collect();
    let interleaved: Vec<usize> = forward.iter().map(|i| (i * 5) % batches.len()).collect();
    let reference = fuse_all(&forward);
    assert_eq!(fuse_all(&backward), reference);
    assert_eq!(fuse_all(&interleaved), reference);

    let (first, second) = forward.split_at(forward.len() / 2);
    let mut merged = fuse_all(first);
    merged.merge(&fuse_all(second)).expect("halves agree");
    assert_eq!(merged, reference);
}

#[test]
fn wrong_range_orders_are_rejected_not_fused() {
    let scenario = Scenario::random(9, 10, 30, 100.0);
    let sensor = Sensor {
        order_swap_probability: 0.3,
        ..Sensor::exact(None)
    };
    let (steps, _) = run::<Edc>(&scenario, &sensor, 9);
    assert!(
        steps.iter().any(|s| s.contradiction),
        "some panorama must contradict"
    );
}

#[test]
fn monte_carlo_reports_every_image_of_every_series() {
    let study = MonteCarlo {
        maps: 3,
        landmarks: 10,
        stations: 8,
        nearest: vec![Some(5), None],
        ..MonteCarlo::fig7()
    };
    let result = study.run::<Edc>(&|| {});
    assert_eq!(result.series.len(), 2);
    for series in &result.series {
        assert_eq!(series.removed_incorrect_pct.len(), 8);
        assert_eq!(series.unsound_relations, 0);
        let first = series.removed_incorrect_pct[0].mean;
        let last = series.removed_incorrect_pct[7].mean;
        assert!(last >= first, "states are only ever removed");
    }
    let csv = result.to_csv();
    assert_eq!(csv.lines().count(), 1 + 2 * 8);
}
