//! From a measured view to map observations (000 §VI-B): every triple of landmarks seen in
//! it is measured against what the map still allows, and its three relations become
//! observations to fuse. The simulator, `pipeline run` and scoring all fuse through here.

use super::{Hypergraph, LandmarkId, Observation};
use crate::calculus::Calculus;
use crate::measurement::StationView;
use rayon::prelude::*;

/// A map landmark seen at a position (an index into the bearings) of a view.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sighting {
    pub position: usize,
    pub landmark: LandmarkId,
}

impl Sighting {
    pub fn new(position: usize, landmark: LandmarkId) -> Sighting {
        Sighting { position, landmark }
    }

    /// Position `i` of a view seen as `ids[i]`, for every position.
    pub fn all(ids: &[LandmarkId]) -> Vec<Sighting> {
        ids.iter()
            .enumerate()
            .map(|(position, &landmark)| Sighting { position, landmark })
            .collect()
    }
}

impl<C: Calculus> Hypergraph<C> {
    /// The observations of every triple `i < j < k` of `sightings` in `view`, each
    /// measured against the relations the map still allows for it (000 §IV, §VI-B).
    pub fn observations(&self, view: &StationView, sightings: &[Sighting]) -> Vec<Observation> {
        let n = sightings.len();
        let triples: Vec<[Sighting; 3]> = (0..n)
            .flat_map(|i| (i + 1..n).flat_map(move |j| (j + 1..n).map(move |k| [i, j, k])))
            .map(|t| t.map(|i| sightings[i]))
            .collect();
        self.measure(view, &triples)
    }

    /// The observations of the triples `sighting` forms with every pair of `partners`: one
    /// more landmark of a view whose other sightings were fused already.
    pub fn observations_of(
        &self,
        view: &StationView,
        sighting: Sighting,
        partners: &[Sighting],
    ) -> Vec<Observation> {
        let n = partners.len();
        let triples: Vec<[Sighting; 3]> = (0..n)
            .flat_map(|x| (x + 1..n).map(move |y| [sighting, partners[x], partners[y]]))
            .collect();
        self.measure(view, &triples)
    }

    /// Measures `triples` in parallel; the observations come in the order of `triples`, as
    /// `AB:C, BC:A, CA:B` of each.
    fn measure(&self, view: &StationView, triples: &[[Sighting; 3]]) -> Vec<Observation> {
        let open = |a, b, c| self.relation(a, b, c).unwrap_or(C::universe());
        triples
            .par_iter()
            .flat_map_iter(|triple| {
                let ids = triple.map(|s| s.landmark);
                let [a, b, c] = ids;
                let states = view.measure_triple::<C>(
                    triple.map(|s| s.position),
                    [open(a, b, c), open(b, c, a), open(c, a, b)],
                );
                Observation::of_triple(ids, states)
            })
            .collect()
    }
}
