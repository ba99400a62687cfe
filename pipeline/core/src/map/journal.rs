//! What went into a map, so that it can be taken out again.
//!
//! A map is an intersection: once a wrong sighting is fused, its relations and everything path
//! consistency derived from them are in, and no later observation can widen them back. Nor can
//! the measurements be kept and re-fused: each was measured against what the map allowed at
//! the time (000 §VI-B), so it already carries the wrong sighting's influence. The journal
//! keeps each fused view with the sightings it was fused as; replaying it with some sightings
//! relabelled (a landmark split in two) or dropped measures every view again against a map
//! that never held them.

use super::{Hypergraph, LandmarkId, Sighting};
use crate::calculus::Calculus;
use crate::measurement::StationView;
use std::sync::Arc;

/// One fusion: a station's view and the sightings fused from it.
#[derive(Clone, Debug, PartialEq)]
struct Entry {
    station: usize,
    view: Arc<StationView>,
    /// Every triple of these was fused, or, with `added`, every triple `added` forms with two
    /// of them (one more landmark of a view whose other sightings were fused already).
    sightings: Vec<Sighting>,
    added: Option<Sighting>,
}

/// The fusions of a map in order, replayable.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Journal {
    entries: Vec<Entry>,
}

/// The outcome of a replay: the rebuilt map, and the stations whose fusion it now rejects.
#[derive(Clone, Debug)]
pub struct Replay<C: Calculus> {
    pub map: Hypergraph<C>,
    pub journal: Journal,
    pub rejected: Vec<usize>,
}

impl Journal {
    /// Records that `sightings` of `view`, seen at `station`, were fused (with fewer than
    /// three, the landmarks entered the map unrelated).
    pub fn record(&mut self, station: usize, view: Arc<StationView>, sightings: &[Sighting]) {
        self.entries.push(Entry {
            station,
            view,
            sightings: sightings.to_vec(),
            added: None,
        });
    }

    /// Records that `added` was fused with every pair of `partners`, sightings of `view` fused
    /// before ([`Hypergraph::observations_of`]).
    pub fn record_added(
        &mut self,
        station: usize,
        view: Arc<StationView>,
        added: Sighting,
        partners: &[Sighting],
    ) {
        self.entries.push(Entry {
            station,
            view,
            sightings: partners.to_vec(),
            added: Some(added),
        });
    }

    /// Fusions recorded.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The map these fusions make when the landmark fused at `station` as `l` is taken to be
    /// `relabel(station, l)`, or left out when that is `None`. Each view is measured again
    /// against the map rebuilt so far, as it was the first time; a fusion that now contradicts
    /// the map is left out, as it would have been. With every sighting kept as it was, the
    /// map is the one the fusions made.
    pub fn replay<C: Calculus>(
        &self,
        relabel: impl Fn(usize, LandmarkId) -> Option<LandmarkId>,
    ) -> Replay<C> {
        let mut map = Hypergraph::<C>::new();
        let mut journal = Journal::default();
        let mut rejected = Vec::new();
        for entry in &self.entries {
            let relabelled = |s: &Sighting| {
                relabel(entry.station, s.landmark).map(|l| Sighting::new(s.position, l))
            };
            let sightings: Vec<Sighting> = entry.sightings.iter().filter_map(relabelled).collect();
            let added = match entry.added {
                Some(added) => match relabelled(&added) {
                    Some(s) => Some(s),
                    None => continue,
                },
                None => None,
            };
            let batch = match added {
                Some(added) => map.observations_of(&entry.view, added, &sightings),
                None if sightings.len() >= 3 => map.observations(&entry.view, &sightings),
                None => Vec::new(),
            };
            if map.fuse(&batch).is_err() {
                rejected.push(entry.station);
                continue;
            }
            let ids: Vec<LandmarkId> = added.iter().chain(&sightings).map(|s| s.landmark).collect();
            map.add_landmarks(&ids);
            journal.entries.push(Entry {
                station: entry.station,
                view: Arc::clone(&entry.view),
                sightings,
                added,
            });
        }
        Replay {
            map,
            journal,
            rejected,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calculus::Calculus;
    use crate::edc::Edc;
    use crate::geometry::Point;
    use crate::measurement::{Bearing, RangeOrder};

    /// The view from `station` of `rocks`, bearings exact to ±0.03 rad, range order total.
    fn view(station: Point, rocks: &[Point]) -> Arc<StationView> {
        let mut order: Vec<usize> = (0..rocks.len()).collect();
        order.sort_by(|&i, &j| {
            rocks[i]
                .distance(station)
                .total_cmp(&rocks[j].distance(station))
        });
        let bearings = rocks
            .iter()
            .map(|r| Bearing {
                angle: (r.y - station.y).atan2(r.x - station.x),
                uncertainty: 0.03,
            })
            .collect();
        Arc::new(StationView::new(bearings, RangeOrder::total(&order).unwrap()).unwrap())
    }

    const ROCKS: [[f64; 2]; 6] = [
        [4.0, 1.0],
        [1.0, 5.0],
        [-3.0, 2.0],
        [-2.0, -4.0],
        [3.0, -3.0],
        [-5.0, 1.5],
    ];

    /// Two stations seeing rocks 0–4 as landmarks 0–4, then a third that fuses rock 5, 2 m
    /// from rock 2, as landmark 0 (a wrong association) with rocks 1–3: the map takes it
    /// without contradiction.
    fn journal_with_a_wrong_sighting() -> (Journal, Hypergraph<Edc>) {
        let rocks: Vec<Point> = ROCKS.iter().map(|&[x, y]| Point::new(x, y)).collect();
        let mut map = Hypergraph::<Edc>::new();
        let mut journal = Journal::default();
        let stations = [[0.0, 0.0], [1.0, -1.0], [2.0, 2.5]];
        for (k, &[x, y]) in stations.iter().enumerate() {
            let station = Point::new(x, y);
            let (seen, ids): (Vec<Point>, Vec<LandmarkId>) = if k < 2 {
                (rocks[..5].to_vec(), (0..5).collect())
            } else {
                (
                    vec![rocks[5], rocks[1], rocks[2], rocks[3]],
                    vec![0, 1, 2, 3],
                )
            };
            let view = view(station, &seen);
            let sightings = Sighting::all(&ids);
            map.fuse(&map.observations(&view, &sightings)).unwrap();
            journal.record(k, view, &sightings);
        }
        (journal, map)
    }

    fn unsound(map: &Hypergraph<Edc>, rock_of: impl Fn(LandmarkId) -> usize) -> usize {
        let p = |l| {
            let [x, y] = ROCKS[rock_of(l)];
            Point::new(x, y)
        };
        let truth = |a, b, c| Edc::classify(p(a), p(b), p(c));
        crate::metrics::evaluate(map, truth, map.len()).unsound_relations
    }

    #[test]
    fn replaying_every_sighting_as_it_was_rebuilds_the_same_map() {
        let (journal, map) = journal_with_a_wrong_sighting();
        let replay = journal.replay::<Edc>(|_, l| Some(l));
        assert_eq!(replay.map, map);
        assert_eq!(replay.journal, journal);
        assert!(replay.rejected.is_empty());
    }

    #[test]
    fn a_wrong_sighting_split_off_takes_what_it_brought_with_it() {
        let (journal, map) = journal_with_a_wrong_sighting();
        // Landmark 0 is rock 0 but at station 2, where it is rock 5.
        assert!(unsound(&map, |l| l as usize) > 0);
        let split =
            journal.replay::<Edc>(|station, l| Some(if station == 2 && l == 0 { 5 } else { l }));
        assert_eq!(unsound(&split.map, |l| l as usize), 0);
        let retired = journal.replay::<Edc>(|station, l| (station != 2 || l != 0).then_some(l));
        assert_eq!(unsound(&retired.map, |l| l as usize), 0);
        assert!(!retired.map.contains(5));
    }
}
