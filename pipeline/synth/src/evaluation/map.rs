//! Scoring the map: the run's map, one built from exact measurements of the same landmarks at
//! the same stations, and one from true bearings with the run's own range evidence, against
//! the classification of the true rock positions.

use super::association::LandmarkRocks;
use super::detection::ratio;
use super::{eval_records, CostCut, MapMetricsScore, MapScore, RngScore, RunFiles, COST_CUTS};
use crate::dataset::Truth;
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::geometry::Point;
use qrm_core::map::{Hypergraph, LandmarkId, Sighting};
use qrm_core::measurement::{Bearing, RangeOrder, StationView};
use qrm_core::metrics::evaluate;
use qrm_core::neighborhood::{compare, estimate, RngEstimate};
use std::collections::HashMap;
use std::f64::consts::TAU;

/// The true `AB:C` of landmarks `[a, b, c]`, each held to its majority rock. Soundness is
/// checked on every landmark with one: a duplicate shares its rock's position (triples of two
/// such landmarks are degenerate, so undefined), and a mixed landmark is held to its majority
/// rock.
pub(super) fn majority_relation(
    truth: &Truth,
    rocks: &LandmarkRocks,
    landmarks: [LandmarkId; 3],
) -> Option<u8> {
    let [a, b, c] = landmarks.map(|l| {
        let p = truth.rocks[rocks.majority(l)? as usize].position;
        Some(Point::new(p[0], p[1]))
    });
    Edc::classify(a?, b?, c?)
}

pub(super) fn score(run: &RunFiles, truth: &Truth, rocks: &LandmarkRocks) -> MapScore {
    let rock = |id: u32| {
        let p = truth.rocks[id as usize].position;
        Point::new(p[0], p[1])
    };
    let defined = |l: LandmarkId| rocks.defined(l).is_some();
    let position = |l: LandmarkId| rocks.defined(l).map(rock);
    let majority_truth =
        |a: LandmarkId, b: LandmarkId, c: LandmarkId| majority_relation(truth, rocks, [a, b, c]);
    let defined_truth = |a: LandmarkId, b: LandmarkId, c: LandmarkId| {
        Edc::classify(position(a)?, position(b)?, position(c)?)
    };
    let exact = reference_map(run, truth, rocks, Reference::Exact);
    let true_bearings = reference_map(run, truth, rocks, Reference::TrueBearings);
    let rng = |map: &Hypergraph<Edc>| {
        let map = map.restricted(defined);
        if map.len() < 3 {
            return None;
        }
        let estimate = estimate(&map)?;
        let at = |l: LandmarkId| position(l).expect("restricted");
        let comparison = compare(&map, &estimate, at);
        let by_cost = COST_CUTS
            .iter()
            .map(|&max_cost| {
                let kept = RngEstimate {
                    edges: estimate
                        .edges
                        .iter()
                        .filter(|e| e.cost <= max_cost)
                        .copied()
                        .collect(),
                    pruned: estimate.pruned,
                };
                let cut = compare(&map, &kept, at);
                CostCut {
                    max_cost,
                    edges: kept.edges.len(),
                    precision: cut.precision(),
                    recall: cut.recall(),
                }
            })
            .collect();
        Some(RngScore {
            landmarks: map.len(),
            precision: comparison.precision(),
            recall: comparison.recall(),
            true_edges_pruned: comparison.pruned_true,
            by_cost,
        })
    };
    MapScore {
        run: map_score(run.map, &majority_truth, &defined),
        exact: map_score(&exact, &defined_truth, &defined),
        true_bearings: map_score(&true_bearings, &defined_truth, &defined),
        rng: rng(run.map),
        rng_exact: rng(&exact),
        rng_true_bearings: rng(&true_bearings),
    }
}

/// What a reference map measures the run's sightings with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Reference {
    /// True bearings from the station centre and the true total range order: the paper's
    /// exact observations (000 §IV).
    Exact,
    /// True bearings with the run's own range evidence: its asserted "nearer than" pairs and
    /// its range-ratio bounds. Between the run's map and this one lies what the bearings'
    /// intervals cost; between this one and the exact map, what the range evidence leaves
    /// out.
    TrueBearings,
}

/// The map from `reference` measurements of the same landmarks at the same stations.
fn reference_map(
    run: &RunFiles,
    truth: &Truth,
    rocks: &LandmarkRocks,
    reference: Reference,
) -> Hypergraph<Edc> {
    let mut map = Hypergraph::<Edc>::new();
    for (record, image) in eval_records(run.records, truth) {
        let station = &truth.stations[image.station];
        // Each one-rock landmark the station fused, with the detection it fused.
        let mut sighted: Vec<(LandmarkId, usize)> = run
            .landmarks
            .iter()
            .filter(|l| rocks.defined(l.landmark).is_some())
            .filter_map(|l| {
                let s = l.sightings.iter().find(|s| s.0 == record.index)?;
                Some((l.landmark, s.1))
            })
            .collect();
        sighted.sort_unstable();
        let ids: Vec<LandmarkId> = sighted.iter().map(|s| s.0).collect();
        if ids.len() < 3 {
            continue;
        }
        let polar: Vec<(f64, f64)> = ids
            .iter()
            .map(|&l| {
                let p = truth.rocks[rocks.defined(l).expect("filtered") as usize].position;
                let (dx, dy) = (p[0] - station.position[0], p[1] - station.position[1]);
                (
                    (dy.atan2(dx) - station.heading).rem_euclid(TAU),
                    dx.hypot(dy),
                )
            })
            .collect();
        let bearings = polar.iter().map(|p| Bearing::exact(p.0)).collect();
        let panorama = match reference {
            Reference::Exact => {
                let mut nearest_first: Vec<usize> = (0..ids.len()).collect();
                nearest_first.sort_by(|&a, &b| polar[a].1.total_cmp(&polar[b].1));
                let order = RangeOrder::total(&nearest_first).expect("a permutation");
                StationView::new(bearings, order)
            }
            Reference::TrueBearings => {
                let position = |detection: usize| sighted.iter().position(|s| s.1 == detection);
                let nearer: Vec<(usize, usize)> = record
                    .order
                    .iter()
                    .filter_map(|&(a, b)| Some((position(a)?, position(b)?)))
                    .collect();
                let ranges = sighted
                    .iter()
                    .map(|s| record.detections.get(s.1).map(|d| d.range.ratio_bounds()))
                    .collect::<Option<Vec<_>>>();
                let (Ok(order), Some(ranges)) =
                    (RangeOrder::from_pairs(ids.len(), &nearer), ranges)
                else {
                    continue;
                };
                StationView::new(bearings, order).and_then(|view| view.with_ranges(ranges))
            }
        };
        let Ok(panorama) = panorama else {
            continue;
        };
        let batch = map.observations(&panorama, &Sighting::all(&ids));
        let _ = map.fuse(&batch);
    }
    map
}

fn map_score<C: Calculus>(
    map: &Hypergraph<C>,
    truth: &impl Fn(LandmarkId, LandmarkId, LandmarkId) -> Option<u8>,
    defined: &dyn Fn(LandmarkId) -> bool,
) -> MapMetricsScore {
    let m = evaluate(map, truth, map.len());
    let universe = C::universe().len();
    let mut unsound: HashMap<LandmarkId, usize> = HashMap::new();
    let (mut open, mut states, mut removed) = (0usize, 0usize, 0usize);
    for (a, b, c, relations) in map.triples() {
        let ordered = [(a, b, c), (b, c, a), (c, a, b)];
        if defined(a) && defined(b) && defined(c) {
            open += relations.iter().map(|s| s.len()).sum::<usize>();
            states += 3 * universe;
            removed += relations
                .iter()
                .zip(ordered)
                .filter(|(set, (x, y, z))| truth(*x, *y, *z).is_some_and(|t| set.contains(t)))
                .map(|(set, _)| universe - set.len())
                .sum::<usize>();
        }
        for (set, (x, y, z)) in relations.iter().zip(ordered) {
            if truth(x, y, z).is_some_and(|t| !set.contains(t)) {
                for l in [x, y, z] {
                    *unsound.entry(l).or_default() += 1;
                }
            }
        }
    }
    // Over every triple of one-rock landmarks, measured or not, as `evaluate` counts the
    // paper's figure over every triple of the map's landmarks (000 Fig. 7a).
    let n = map.landmarks().iter().filter(|&&l| defined(l)).count();
    let incorrect = n * n.saturating_sub(1) * n.saturating_sub(2) / 6 * 3 * (universe - 1);
    let mut unsound_landmarks: Vec<(LandmarkId, usize)> = unsound.into_iter().collect();
    unsound_landmarks.sort_by_key(|&(l, n)| (std::cmp::Reverse(n), l));
    MapMetricsScore {
        unsound_landmarks,
        landmarks: map.len(),
        triples: map.triple_count(),
        open_pct: m.open_pct,
        open_pct_defined: 100.0 * ratio(open, states),
        removed_incorrect_pct: m.removed_incorrect_pct,
        removed_incorrect_pct_defined: 100.0 * ratio(removed, incorrect),
        fully_constrained_pct: m.fully_constrained_pct,
        unsound_relations: m.unsound_relations,
        undefined_triples: m.undefined_triples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Landmarks 0–3 seen exactly from two stations; landmark 3 is a false detection's, with
    /// no true state in any triple.
    fn two_station_map() -> (Hypergraph<Edc>, [Point; 4]) {
        let rocks = [
            Point::new(4.0, 1.0),
            Point::new(6.0, -3.0),
            Point::new(9.0, 2.0),
            Point::new(3.0, 5.0),
        ];
        let mut map = Hypergraph::<Edc>::new();
        for station in [Point::new(0.0, 0.0), Point::new(1.0, -6.0)] {
            let polar: Vec<(f64, f64)> = rocks
                .iter()
                .map(|p| {
                    let (dx, dy) = (p.x - station.x, p.y - station.y);
                    (dy.atan2(dx).rem_euclid(TAU), dx.hypot(dy))
                })
                .collect();
            let mut nearest_first: Vec<usize> = (0..rocks.len()).collect();
            nearest_first.sort_by(|&a, &b| polar[a].1.total_cmp(&polar[b].1));
            let order = RangeOrder::total(&nearest_first).expect("a permutation");
            let view = StationView::new(polar.iter().map(|p| Bearing::exact(p.0)).collect(), order)
                .expect("a valid view");
            let batch = map.observations(&view, &Sighting::all(&[0, 1, 2, 3]));
            map.fuse(&batch).expect("exact measurements agree");
        }
        (map, rocks)
    }

    #[test]
    fn removed_states_among_one_rock_landmarks_leave_a_false_detections_triples_out() {
        let (map, rocks) = two_station_map();
        let defined = |l: LandmarkId| l < 3;
        let truth = |a: LandmarkId, b: LandmarkId, c: LandmarkId| {
            [a, b, c]
                .iter()
                .all(|&l| defined(l))
                .then(|| Edc::classify(rocks[a as usize], rocks[b as usize], rocks[c as usize]))
                .flatten()
        };
        let score = map_score(&map, &truth, &defined);
        let alone = evaluate(&map.restricted(defined), truth, 3);
        assert!(alone.removed_incorrect_pct > 0.0);
        assert!((score.removed_incorrect_pct_defined - alone.removed_incorrect_pct).abs() < 1e-9);
        // Over all four landmarks, the three triples with landmark 3 count as unresolved.
        let over_all = score.removed_incorrect_pct_defined / 4.0;
        assert!((score.removed_incorrect_pct - over_all).abs() < 1e-9);
        assert_eq!(score.unsound_relations, 0);
    }
}
