//! Legs of a partial map, sampled from its realizations. A map from real panoramas leaves most
//! distance comparisons open, so it proves few legs ([`super::legs`]); but every layout that
//! satisfies all its relations ([`Hypergraph::realize`]) is an arrangement the map allows. The
//! legs of several realizations, found from independent random starts, estimate how often a
//! leg holds among those arrangements: its **support**. A leg the map proves holds in every
//! realization (support 1); a leg held in 3 of 16 has support 3/16, which the route cost
//! charges as `−ln(3/16)` on top of the leg's own unreliability. Realizations are not a
//! uniform sample of the map's arrangements, so support is an estimate, not a probability the
//! map proves (docs/DIRECTIONS.md).

use super::isolation::{Bounds, MapNearness, Positions};
use super::legs::{legs, Leg};
use crate::edc::Edc;
use crate::map::{Hypergraph, RealizeSettings};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// What the sampling found.
#[derive(Clone, Debug)]
pub struct SampledLegs {
    /// Proven legs (support 1), then the others by decreasing support.
    pub legs: Vec<Leg>,
    /// Realizations that satisfied every relation of the map (the others are not used).
    pub realizations: usize,
    /// Realizations tried.
    pub tried: usize,
}

/// Sweeps of each realization search: a fifth of [`RealizeSettings`]' default, enough for
/// the run maps tried (docs/DIRECTIONS.md); a layout that still violates a relation is
/// dropped.
const SWEEPS: usize = 400;

/// The legs of `map` with scenes of up to `max_objects`: proven ones from the map's relations,
/// and those of `samples` realizations (seeds `seed..seed + samples`) with their support.
pub fn sampled_legs(
    map: &Hypergraph<Edc>,
    max_objects: usize,
    samples: usize,
    seed: u64,
) -> SampledLegs {
    let proven = legs(&MapNearness::new(map), max_objects);
    let layouts: Vec<Vec<Leg>> = (0..samples as u64)
        .into_par_iter()
        .filter_map(|k| {
            let realization = map.realize(&RealizeSettings {
                seed: seed.wrapping_add(k),
                sweeps: SWEEPS,
                restarts: 1,
            });
            realization
                .is_exact()
                .then(|| legs(&Positions(&realization.positions), max_objects))
        })
        .collect();
    let realizations = layouts.len();
    // (from, to, objects) → the first scene seen, every confusable landmark, rank span, count.
    let mut seen: BTreeMap<(usize, usize, usize), (Leg, usize)> = BTreeMap::new();
    for leg in layouts.into_iter().flatten() {
        let key = (leg.from, leg.to, leg.objects());
        match seen.get_mut(&key) {
            None => {
                seen.insert(key, (leg, 1));
            }
            Some((kept, count)) => {
                *count += 1;
                for y in leg.confusable {
                    if !kept.confusable.contains(&y) {
                        kept.confusable.push(y);
                    }
                }
                kept.rank = Bounds {
                    low: kept.rank.low.min(leg.rank.low),
                    high: kept.rank.high.max(leg.rank.high),
                };
            }
        }
    }
    let mut sampled: Vec<Leg> = seen
        .into_values()
        .filter(|(leg, _)| {
            !proven
                .iter()
                .any(|p| p.from == leg.from && p.to == leg.to && p.objects() <= leg.objects())
        })
        .map(|(mut leg, count)| {
            leg.support = count as f64 / realizations as f64;
            leg.proven = false;
            leg
        })
        .collect();
    sampled.sort_by(|a, b| {
        b.support
            .total_cmp(&a.support)
            .then((a.from, a.to, a.objects()).cmp(&(b.from, b.to, b.objects())))
    });
    SampledLegs {
        legs: proven.into_iter().chain(sampled).collect(),
        realizations,
        tried: samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Point;
    use crate::map::testing::converged;

    #[test]
    fn a_converged_map_has_only_proven_legs_and_every_realization_agrees() {
        let points: Vec<Point> = [(0.0, 0.0), (3.1, 1.2), (1.3, 4.6), (-2.2, 2.9), (5.4, 6.1)]
            .iter()
            .map(|&(x, y)| Point::new(x, y))
            .collect();
        let map = converged::<Edc>(&points);
        let sampled = sampled_legs(&map, 4, 4, 1);
        assert_eq!(sampled.legs, legs(&Positions(&points), 4));
        assert!(sampled.legs.iter().all(Leg::is_proven));
    }

    #[test]
    fn an_empty_map_samples_legs_of_partial_support() {
        let mut map = Hypergraph::<Edc>::new();
        map.add_landmarks(&[0, 1, 2, 3, 4, 5]);
        let sampled = sampled_legs(&map, 3, 8, 1);
        assert_eq!(sampled.realizations, 8);
        assert!(!sampled.legs.is_empty());
        assert!(sampled
            .legs
            .iter()
            .all(|l| !l.is_proven() && l.support > 0.0 && l.support <= 1.0));
        assert!(sampled.legs.iter().any(|l| l.support < 1.0));
    }
}
