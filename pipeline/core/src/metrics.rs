//! Map quality against ground truth (000 §VIII-A; 003 §1.5.1).
//!
//! Denominators follow the papers' figures: percentages are of the *final* map over all
//! `total_landmarks` (Fig. 7a: "percentage of the total number of possible incorrect states for
//! 30 landmarks"), so landmarks not yet observed count as unresolved.

use crate::calculus::Calculus;
use crate::map::{Hypergraph, LandmarkId};

/// One evaluation of a map.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MapMetrics {
    /// Incorrect states removed, % of all incorrect states of the final map (Fig. 7a).
    pub removed_incorrect_pct: f64,
    /// Open states neither true nor adjacent to the true state, % of open states (Fig. 7b),
    /// over the relations that still hold their true state; 0 for a calculus without an
    /// adjacency relation ([`Calculus::adjacent`]).
    pub non_adjacent_open_pct: f64,
    /// Triples whose three relations are single states, % of the final map's triples.
    pub fully_constrained_pct: f64,
    /// Open states, % of all states of the final map (003 Fig. 1.6).
    pub open_pct: f64,
    /// Relations whose true state was removed: must be 0 for exact measurements.
    pub unsound_relations: usize,
    /// Triples whose truth is undefined (a landmark on a boundary) and were skipped.
    pub undefined_triples: usize,
}

fn choose3(n: usize) -> f64 {
    (n * n.saturating_sub(1) * n.saturating_sub(2)) as f64 / 6.0
}

/// Evaluates `map` against `truth(a, b, c)` = the true relation `AB:C` (None when undefined).
pub fn evaluate<C: Calculus>(
    map: &Hypergraph<C>,
    truth: impl Fn(LandmarkId, LandmarkId, LandmarkId) -> Option<u8>,
    total_landmarks: usize,
) -> MapMetrics {
    let universe = C::universe();
    let states = universe.len() as f64;
    let final_triples = choose3(total_landmarks.max(map.len()));
    let mut removed_incorrect = 0usize;
    let mut open_states = 0usize;
    let mut open_total = 0usize;
    let mut non_adjacent = 0usize;
    let mut full = 0usize;
    let mut out = MapMetrics::default();
    for (a, b, c, relations) in map.triples() {
        let ordered = [(a, b, c), (b, c, a), (c, a, b)];
        let mut truths = [0u8; 3];
        let mut defined = true;
        for (k, &(x, y, z)) in ordered.iter().enumerate() {
            match truth(x, y, z) {
                Some(t) => truths[k] = t,
                None => defined = false,
            }
        }
        open_states += relations.iter().map(|s| s.len()).sum::<usize>();
        if !defined {
            out.undefined_triples += 1;
            continue;
        }
        if relations.iter().all(|s| s.len() == 1) {
            full += 1;
        }
        for (set, &t) in relations.iter().zip(&truths) {
            if !set.contains(t) {
                out.unsound_relations += 1;
                continue;
            }
            removed_incorrect += universe.len() - set.len();
            open_total += set.len();
            if let Some(adjacent) = C::adjacent(t) {
                non_adjacent += set.difference(adjacent.with(t)).len();
            }
        }
    }
    let unseen_triples = final_triples - map.triple_count() as f64;
    let all_states = final_triples * 3.0 * states;
    if final_triples > 0.0 {
        out.removed_incorrect_pct =
            100.0 * removed_incorrect as f64 / (final_triples * 3.0 * (states - 1.0));
        out.fully_constrained_pct = 100.0 * full as f64 / final_triples;
        out.open_pct = 100.0 * (open_states as f64 + unseen_triples * 3.0 * states) / all_states;
    }
    if open_total > 0 {
        out.non_adjacent_open_pct = 100.0 * non_adjacent as f64 / open_total as f64;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calculus::RelationSet;
    use crate::edc::Edc;
    use crate::geometry::Point;
    use crate::map::Observation;

    fn points() -> [Point; 4] {
        [
            Point::new(0.0, 0.0),
            Point::new(3.0, 0.4),
            Point::new(1.2, 2.5),
            Point::new(-0.7, 1.9),
        ]
    }

    fn truth(a: LandmarkId, b: LandmarkId, c: LandmarkId) -> Option<u8> {
        let p = points();
        Edc::classify(p[a as usize], p[b as usize], p[c as usize])
    }

    #[test]
    fn exact_map_is_fully_resolved() {
        let mut observations = Vec::new();
        for (a, b, c) in [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)] {
            for (x, y, z) in [(a, b, c), (b, c, a), (c, a, b)] {
                let r = truth(x, y, z).unwrap();
                observations.push(Observation::new(x, y, z, RelationSet::single(r)));
            }
        }
        let mut map = Hypergraph::<Edc>::new();
        map.fuse(&observations).unwrap();
        let m = evaluate(&map, truth, 4);
        assert_eq!(m.unsound_relations, 0);
        assert!((m.removed_incorrect_pct - 100.0).abs() < 1e-9, "{m:?}");
        assert!((m.fully_constrained_pct - 100.0).abs() < 1e-9);
        assert_eq!(m.non_adjacent_open_pct, 0.0);
        assert!((m.open_pct - 5.0).abs() < 1e-9);
    }

    #[test]
    fn unseen_landmarks_count_as_unresolved_and_wrong_states_as_unsound() {
        let wrong = truth(0, 1, 2).unwrap() % 20 + 1;
        let mut map = Hypergraph::<Edc>::new();
        map.fuse(&[Observation::new(0, 1, 2, RelationSet::single(wrong))])
            .unwrap();
        let m = evaluate(&map, truth, 4);
        assert!(m.unsound_relations >= 1);
        assert!(m.fully_constrained_pct <= 25.0);
    }
}
