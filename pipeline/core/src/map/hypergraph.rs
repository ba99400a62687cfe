//! The qualitative map `M = (P, E)` of 000 §VI-A: landmarks and one edge per unordered triple
//! storing `{p_i p_j : p_k, p_j p_k : p_i, p_k p_i : p_j}`.

use super::index::{choose3, locate, rank, unrank};
use super::kernel::Kernel;
use super::update::LandmarkId;
use crate::calculus::{Calculus, RelationSet};
use std::collections::HashMap;
use std::fmt;
use std::marker::PhantomData;

/// A 3-uniform hypergraph over landmarks with relation sets of calculus `C` on every edge,
/// kept path consistent by [`Hypergraph::fuse`] and [`Hypergraph::merge`].
///
/// Storage is dense: the edge of internal indices `i < j < k` (insertion order of the
/// landmarks) lives at `C(k,3) + C(j,2) + i` in one flat vector and holds the raw bitsets of
/// `[ij:k, jk:i, ki:j]` (12 bytes per edge; 300 landmarks ≈ 4.5 M edges ≈ 53 MB). Edges of a
/// new landmark are appended and start at `C::universe()`.
///
/// Most edges never leave the universe: on the 1 000-rock drive, 146 196 of 25.8 M (0.6 %)
/// hold anything, 105 359 of them derived by path consistency for landmarks never seen
/// together. The ranks of those that do are kept ([`Hypergraph::constrained`]), so that
/// queries over what the map knows (its metrics, the RNG estimate) visit them only.
pub struct Hypergraph<C: Calculus> {
    pub(super) landmarks: Vec<LandmarkId>,
    pub(super) index: HashMap<LandmarkId, usize>,
    pub(super) edges: Vec<[u32; 3]>,
    /// Ranks of the edges that left the universe, each once, in no particular order.
    pub(super) constrained: Vec<usize>,
    calculus: PhantomData<fn() -> C>,
}

impl<C: Calculus> Hypergraph<C> {
    /// The empty map.
    pub fn new() -> Hypergraph<C> {
        Hypergraph {
            landmarks: Vec::new(),
            index: HashMap::new(),
            edges: Vec::new(),
            constrained: Vec::new(),
            calculus: PhantomData,
        }
    }

    /// Landmarks in insertion order.
    pub fn landmarks(&self) -> &[LandmarkId] {
        &self.landmarks
    }

    /// Number of landmarks.
    pub fn len(&self) -> usize {
        self.landmarks.len()
    }

    pub fn is_empty(&self) -> bool {
        self.landmarks.is_empty()
    }

    pub fn contains(&self, id: LandmarkId) -> bool {
        self.index.contains_key(&id)
    }

    /// Number of edges, `C(len, 3)`.
    pub fn triple_count(&self) -> usize {
        self.edges.len()
    }

    /// Open states summed over every relation of every edge (003 §1.5.1's first metric).
    pub fn open_states(&self) -> usize {
        let universe = C::universe().len();
        let closed: usize = self
            .constrained
            .iter()
            .map(|&r| {
                self.edges[r]
                    .iter()
                    .map(|&s| universe - RelationSet::from_bits(s).len())
                    .sum::<usize>()
            })
            .sum();
        3 * universe * self.edges.len() - closed
    }

    /// Edges whose three relations are each a single state.
    pub fn fully_constrained_triples(&self) -> usize {
        self.constrained
            .iter()
            .filter(|&&r| {
                self.edges[r]
                    .iter()
                    .all(|&s| RelationSet::from_bits(s).len() == 1)
            })
            .count()
    }

    /// Positions `[i, j, k]` (`i < j < k` in [`Hypergraph::landmarks`]) of every edge that
    /// holds something other than the universe, in storage order; every other edge holds
    /// `C::universe()` in each relation.
    pub fn constrained(&self) -> Vec<[usize; 3]> {
        let mut ranks = self.constrained.clone();
        ranks.sort_unstable();
        ranks.into_iter().map(unrank).collect()
    }

    /// Heap bytes held by the map (edges, the ranks of the constrained ones, landmark list and
    /// id index).
    pub fn heap_bytes(&self) -> usize {
        self.edges.capacity() * std::mem::size_of::<[u32; 3]>()
            + self.constrained.capacity() * std::mem::size_of::<usize>()
            + self.landmarks.capacity() * std::mem::size_of::<LandmarkId>()
            + self.index.capacity()
                * (std::mem::size_of::<(LandmarkId, usize)>() + std::mem::size_of::<u64>())
    }

    /// The stored estimate of `AB:C` for landmarks `a`, `b`, `c` in this order, derived with
    /// INVERSE when the ordering is anti-cyclic with respect to the stored edge (000 §VI-B
    /// step 3). `None` for an unknown id or ids that are not distinct.
    pub fn relation(&self, a: LandmarkId, b: LandmarkId, c: LandmarkId) -> Option<RelationSet> {
        let (ia, ib, ic) = (
            *self.index.get(&a)?,
            *self.index.get(&b)?,
            *self.index.get(&c)?,
        );
        if ia == ib || ib == ic || ia == ic {
            return None;
        }
        Some(self.relation_at(ia, ib, ic))
    }

    /// [`Hypergraph::relation`] for landmarks at positions `ia`, `ib`, `ic` of
    /// [`Hypergraph::landmarks`] (distinct, in range): no id lookup, for queries over every
    /// triple (the RNG estimate after every station).
    pub fn relation_at(&self, ia: usize, ib: usize, ic: usize) -> RelationSet {
        let loc = locate(ia, ib, ic);
        let stored = self.edges[loc.rank][loc.slot];
        RelationSet::from_bits(if loc.inverted {
            Kernel::of::<C>().inverse(stored)
        } else {
            stored
        })
    }

    /// Every edge once, in storage order, as landmark ids `(a, b, c)` (insertion order
    /// `a` before `b` before `c`) with the relations `[AB:C, BC:A, CA:B]`.
    pub fn triples(&self) -> Triples<'_> {
        Triples {
            landmarks: &self.landmarks,
            edges: &self.edges,
            next: 0,
            ijk: [0, 1, 2],
        }
    }

    /// Appends a landmark and its edges at the universe; returns its internal index.
    pub(super) fn push_landmark(&mut self, id: LandmarkId) -> usize {
        let k = self.landmarks.len();
        self.landmarks.push(id);
        self.index.insert(id, k);
        let universe = C::universe().bits();
        self.edges.resize(choose3(k + 1), [universe; 3]);
        k
    }

    /// The map over the landmarks `keep` accepts, in this map's order: their relations as this
    /// map holds them, copied edge by edge. A restriction of a path-consistent network is path
    /// consistent, so nothing is fused or tightened; used to compare a map with ground truth on
    /// the landmarks that have one, and to publish a run's map without its uncorroborated
    /// landmarks. Kept landmarks keep their relative order, so every kept edge keeps its
    /// slots; only the edges that left the universe are visited.
    pub fn restricted(&self, keep: impl Fn(LandmarkId) -> bool) -> Hypergraph<C> {
        let mut map = Hypergraph::new();
        let mut new_index = vec![None; self.landmarks.len()];
        for (old, &id) in self.landmarks.iter().enumerate() {
            if keep(id) {
                new_index[old] = Some(map.landmarks.len());
                map.index.insert(id, map.landmarks.len());
                map.landmarks.push(id);
            }
        }
        map.edges = vec![[C::universe().bits(); 3]; choose3(map.landmarks.len())];
        for &r in &self.constrained {
            let [i, j, k] = unrank(r);
            if let (Some(i), Some(j), Some(k)) = (new_index[i], new_index[j], new_index[k]) {
                let new = rank(i, j, k);
                map.edges[new] = self.edges[r];
                map.constrained.push(new);
            }
        }
        map
    }

    /// Drops the landmarks from `count` on, with their edges.
    pub(super) fn truncate_landmarks(&mut self, count: usize) {
        for id in self.landmarks.drain(count..) {
            self.index.remove(&id);
        }
        self.edges.truncate(choose3(count));
        let edges = self.edges.len();
        self.constrained.retain(|&r| r < edges);
    }

    /// Records that edge `rank`, at the universe until now, holds something.
    pub(super) fn mark_constrained(&mut self, rank: usize) {
        self.constrained.push(rank);
    }
}

impl<C: Calculus> Default for Hypergraph<C> {
    fn default() -> Self {
        Hypergraph::new()
    }
}

impl<C: Calculus> Clone for Hypergraph<C> {
    fn clone(&self) -> Self {
        Hypergraph {
            landmarks: self.landmarks.clone(),
            index: self.index.clone(),
            edges: self.edges.clone(),
            constrained: self.constrained.clone(),
            calculus: PhantomData,
        }
    }
}

/// Two maps are equal when they know the same landmarks and agree on every relation; the
/// insertion order of the landmarks (internal indexing) is not compared.
impl<C: Calculus> PartialEq for Hypergraph<C> {
    fn eq(&self, other: &Self) -> bool {
        if self.landmarks == other.landmarks {
            return self.edges == other.edges;
        }
        if self.len() != other.len() || !self.landmarks.iter().all(|id| other.contains(*id)) {
            return false;
        }
        let to_other: Vec<usize> = self.landmarks.iter().map(|id| other.index[id]).collect();
        let kernel = Kernel::of::<C>();
        self.triples_internal().all(|([i, j, k], rel)| {
            let (a, b, c) = (to_other[i], to_other[j], to_other[k]);
            // The same ordered relations read from other's storage (INVERSE where other
            // stores the anti-cyclic ordering).
            let theirs = |x: usize, y: usize, z: usize| {
                let l = locate(x, y, z);
                let s = other.edges[l.rank][l.slot];
                if l.inverted {
                    kernel.inverse(s)
                } else {
                    s
                }
            };
            rel == [theirs(a, b, c), theirs(b, c, a), theirs(c, a, b)]
        })
    }
}

impl<C: Calculus> Eq for Hypergraph<C> {}

/// Lists the landmarks and the edges that are not entirely unconstrained.
impl<C: Calculus> fmt::Debug for Hypergraph<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let universe = C::universe();
        let constrained: Vec<String> = self
            .triples()
            .filter(|(_, _, _, r)| r.iter().any(|s| *s != universe))
            .map(|(a, b, c, [x, y, z])| format!("({a},{b},{c}): {x} {y} {z}"))
            .collect();
        f.debug_struct("Hypergraph")
            .field("calculus", &C::NAME)
            .field("landmarks", &self.landmarks)
            .field("constrained_triples", &constrained)
            .finish()
    }
}

impl<C: Calculus> Hypergraph<C> {
    /// Internal indices `[i, j, k]` and stored relations of every edge, in storage order.
    pub(super) fn triples_internal(&self) -> impl Iterator<Item = ([usize; 3], [u32; 3])> + '_ {
        let mut ijk = [0usize, 1, 2];
        self.edges.iter().enumerate().map(move |(r, e)| {
            let current = ijk;
            debug_assert_eq!(rank(current[0], current[1], current[2]), r);
            ijk = successor(ijk);
            (current, *e)
        })
    }
}

/// The next triple in rank order: `i` counts up to `j`, then `j` up to `k`, then `k`.
fn successor([i, j, k]: [usize; 3]) -> [usize; 3] {
    if i + 1 < j {
        [i + 1, j, k]
    } else if j + 1 < k {
        [0, j + 1, k]
    } else {
        [0, 1, k + 1]
    }
}

/// Iterator of [`Hypergraph::triples`].
pub struct Triples<'a> {
    landmarks: &'a [LandmarkId],
    edges: &'a [[u32; 3]],
    next: usize,
    ijk: [usize; 3],
}

impl Iterator for Triples<'_> {
    type Item = (LandmarkId, LandmarkId, LandmarkId, [RelationSet; 3]);

    fn next(&mut self) -> Option<Self::Item> {
        let edge = self.edges.get(self.next)?;
        let [i, j, k] = self.ijk;
        self.next += 1;
        self.ijk = successor(self.ijk);
        Some((
            self.landmarks[i],
            self.landmarks[j],
            self.landmarks[k],
            edge.map(RelationSet::from_bits),
        ))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.edges.len() - self.next;
        (left, Some(left))
    }
}

impl ExactSizeIterator for Triples<'_> {}

#[cfg(test)]
mod tests {
    use crate::edc::Edc;
    use crate::geometry::Point;
    use crate::map::testing::converged;
    use crate::map::{Hypergraph, Observation};

    #[test]
    fn a_restriction_keeps_the_order_the_relations_and_unrelated_landmarks() {
        let points = [
            Point::new(0.3, 0.1),
            Point::new(4.2, 1.7),
            Point::new(1.1, 5.3),
            Point::new(-3.4, 2.9),
            Point::new(2.7, -3.8),
            Point::new(-1.9, -2.3),
            Point::new(6.1, 4.4),
        ];
        let mut map = converged::<Edc>(&points);
        map.add_landmarks(&[9]);
        let dropped = [1, 4];
        let restricted = map.restricted(|l| !dropped.contains(&l));
        assert_eq!(restricted.landmarks(), &[0, 2, 3, 5, 6, 9]);
        assert_eq!(restricted.triple_count(), 20);
        for (a, b, c, [ab_c, bc_a, ca_b]) in restricted.triples() {
            assert_eq!(map.relation(a, b, c), Some(ab_c));
            assert_eq!(map.relation(b, c, a), Some(bc_a));
            assert_eq!(map.relation(c, a, b), Some(ca_b));
        }
        assert_eq!(restricted.relation(0, 1, 2), None);
        // The same map as fusing the kept triples' relations into an empty one.
        let kept: Vec<Observation> = map
            .triples()
            .filter(|&(a, b, c, _)| ![a, b, c].iter().any(|l| dropped.contains(l)))
            .flat_map(|(a, b, c, r)| Observation::of_triple([a, b, c], r))
            .collect();
        let mut fused = Hypergraph::<Edc>::new();
        fused.add_landmarks(&[0, 2, 3, 5, 6, 9]);
        fused
            .fuse(&kept)
            .expect("a converged map's relations agree");
        assert!(restricted == fused);
        assert_eq!(restricted.constrained().len(), fused.constrained().len());
    }
}
