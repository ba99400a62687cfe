//! The qualitative map of 000 §VI: a 3-uniform hypergraph over landmarks whose edges hold
//! relation sets of a calculus, updated transactionally and kept path consistent.
//!
//! - [`Hypergraph`] storage and queries (000 §VI-A);
//! - [`Hypergraph::fuse`]: one panorama's measurements, intersected in and propagated
//!   (000 §VI-B), as one transaction;
//! - [`Hypergraph::observations`]: the measured triples of a panorama's [`Sighting`]s as
//!   observations, measured against what the map still allows (000 §IV, §VI-B);
//! - [`Hypergraph::merge`]: fusing another map over the same landmark ids;
//! - [`Journal`]: the fused views, replayed to take wrong sightings back out;
//! - [`Network`]: constraint networks from outside, closed or narrowed to a minimal conflict;
//! - [`Hypergraph::realize`]: positions under which every relation holds, for drawing;
//! - JSON files (`docs/MAP_FORMAT.md`).

mod closure;
mod hypergraph;
mod index;
mod journal;
mod json;
mod kernel;
mod network;
mod observe;
mod quad;
mod realization;
mod transaction;
mod update;

#[cfg(test)]
pub(crate) mod testing;

pub use hypergraph::{Hypergraph, Triples};
pub use journal::{Journal, Replay};
pub use json::{MapFormatError, MAX_LANDMARKS};
pub use network::{Network, NetworkTextError};
pub use observe::Sighting;
pub use realization::{Realization, RealizeSettings};
pub use update::{Contradiction, ContradictionStage, LandmarkId, Observation, UpdateReport};

use crate::calculus::Calculus;
use index::{locate, slot_order, unrank};
use transaction::Transaction;

impl<C: Calculus> Hypergraph<C> {
    /// Fuses the measurements of one panorama (000 §VI-B) as one transaction: unknown
    /// landmarks are added (in order of first mention), every observation `AB:C ∈ states` is
    /// intersected into its edge (INVERSE applied for anti-cyclic orderings, the edge then
    /// closed under LEFT/RIGHT/INVERSE), and the map is closed to full path consistency (see
    /// `closure`). If any relation becomes empty, the map — landmark list included — is left
    /// exactly as before and the contradiction is returned. An observation that names a
    /// landmark twice is a contradiction (relations hold between distinct landmarks only).
    pub fn fuse(&mut self, observations: &[Observation]) -> Result<UpdateReport, Contradiction> {
        let contradiction = |relation, stage, ids: [LandmarkId; 3]| Contradiction {
            relation,
            stage,
            observations: observations
                .iter()
                .filter(|o| o.is_about(ids))
                .copied()
                .collect(),
            batch_len: observations.len(),
        };
        if let Some(o) = observations
            .iter()
            .find(|o| o.a == o.b || o.b == o.c || o.a == o.c)
        {
            let ids = [o.a, o.b, o.c];
            return Err(contradiction(
                ids,
                ContradictionStage::RepeatedLandmark,
                ids,
            ));
        }
        let old_len = self.len();
        for o in observations {
            for id in [o.a, o.b, o.c] {
                if !self.contains(id) {
                    self.push_landmark(id);
                }
            }
        }
        let mut tx = Transaction::new(self, old_len);
        let kernel = tx.kernel;
        for o in observations {
            let index = &tx.map.index;
            let loc = locate(index[&o.a], index[&o.b], index[&o.c]);
            let states = o.states.bits();
            let mut mask = [u32::MAX; 3];
            mask[loc.slot] = if loc.inverted {
                kernel.inverse(states)
            } else {
                states
            };
            if let Err(slot) = tx.intersect(loc.rank, mask) {
                let relation = tx.map.slot_ids(loc.rank, slot);
                tx.rollback();
                return Err(contradiction(
                    relation,
                    ContradictionStage::Intersection,
                    relation,
                ));
            }
        }
        if let Err((rank, slot)) = closure::close(&mut tx) {
            let relation = tx.map.slot_ids(rank, slot);
            tx.rollback();
            return Err(contradiction(
                relation,
                ContradictionStage::Closure,
                relation,
            ));
        }
        Ok(tx.commit())
    }

    /// Adds landmarks that no measurement relates yet, in order (ids the map holds are
    /// skipped): every relation with them is the universe. A station that decides a new
    /// landmark but measures no triple (it decided fewer than three) still makes it a
    /// landmark of the run, which the map then lists like every other. Universal relations
    /// keep the map closed: nothing composes with the universe to less than the universe.
    pub fn add_landmarks(&mut self, ids: &[LandmarkId]) {
        for &id in ids {
            if !self.contains(id) {
                self.push_landmark(id);
            }
        }
    }

    /// Fuses another map over the same landmark id space: the result equals fusing both
    /// measurement streams. Landmarks of `other` not known here are appended in `other`'s
    /// order, every relation `other` knows is intersected in, and the map is closed. On a
    /// contradiction the map is left exactly as before; the contradiction lists `other`'s
    /// three relations on the emptied edge as observations.
    pub fn merge(&mut self, other: &Hypergraph<C>) -> Result<UpdateReport, Contradiction> {
        let old_len = self.len();
        for &id in other.landmarks() {
            if !self.contains(id) {
                self.push_landmark(id);
            }
        }
        let to_self: Vec<usize> = other.landmarks.iter().map(|id| self.index[id]).collect();
        let mut tx = Transaction::new(self, old_len);
        let kernel = tx.kernel;
        let universe = kernel.universe;
        let mut failure = None;
        for (ijk, rel) in other.triples_internal() {
            if rel == [universe; 3] {
                continue;
            }
            let mut mask = [u32::MAX; 3];
            let [i, j, k] = ijk.map(|x| to_self[x]);
            let target = index::rank_of(i, j, k);
            for (slot, &set) in rel.iter().enumerate() {
                let [a, b, c] = slot_order([i, j, k], slot);
                let loc = locate(a, b, c);
                mask[loc.slot] &= if loc.inverted {
                    kernel.inverse(set)
                } else {
                    set
                };
            }
            if let Err(slot) = tx.intersect(target, mask) {
                failure = Some((target, slot, ContradictionStage::Intersection));
                break;
            }
        }
        if failure.is_none() {
            if let Err((rank, slot)) = closure::close(&mut tx) {
                failure = Some((rank, slot, ContradictionStage::Closure));
            }
        }
        let Some((rank, slot, stage)) = failure else {
            return Ok(tx.commit());
        };
        let relation = tx.map.slot_ids(rank, slot);
        tx.rollback();
        let observations = match (
            other.relation(relation[0], relation[1], relation[2]),
            other.relation(relation[1], relation[2], relation[0]),
            other.relation(relation[2], relation[0], relation[1]),
        ) {
            (Some(x), Some(y), Some(z)) => Observation::of_triple(relation, [x, y, z]).to_vec(),
            _ => Vec::new(),
        };
        Err(Contradiction {
            relation,
            stage,
            observations,
            batch_len: 3 * other.triple_count(),
        })
    }

    /// Landmark ids `[a, b, c]` of the ordered relation stored in `slot` of edge `rank`.
    fn slot_ids(&self, rank: usize, slot: usize) -> [LandmarkId; 3] {
        slot_order(unrank(rank), slot).map(|x| self.landmarks[x])
    }
}
