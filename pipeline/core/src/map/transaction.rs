//! One map update as a transaction: every change to an edge is logged with its previous value
//! so that a contradiction restores the map (landmarks included) exactly. Intersections close
//! the edge under the unary operators (000 §VI-B steps 4–7) and queue it for composition.

use super::hypergraph::Hypergraph;
use super::kernel::Kernel;
use super::update::UpdateReport;
use crate::calculus::Calculus;

/// A bitset over edge ranks.
pub(super) struct BitSet(Vec<u64>);

impl BitSet {
    pub fn new(len: usize) -> BitSet {
        BitSet(vec![0; len.div_ceil(64)])
    }

    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        self.0[i / 64] >> (i % 64) & 1 != 0
    }

    /// Sets bit `i`; returns whether it was clear.
    #[inline]
    pub fn insert(&mut self, i: usize) -> bool {
        let word = &mut self.0[i / 64];
        let bit = 1u64 << (i % 64);
        let was_clear = *word & bit == 0;
        *word |= bit;
        was_clear
    }

    #[inline]
    pub fn remove(&mut self, i: usize) {
        self.0[i / 64] &= !(1u64 << (i % 64));
    }
}

/// An update in progress on `map`. Dropping it without [`Transaction::commit`] does not roll
/// back; callers call [`Transaction::rollback`] on failure.
pub(super) struct Transaction<'m, C: Calculus> {
    pub map: &'m mut Hypergraph<C>,
    pub kernel: &'static Kernel,
    old_len: usize,
    old_edges: usize,
    touched: BitSet,
    /// Previous value of every edge changed so far (first change only).
    undo: Vec<(usize, [u32; 3])>,
    /// Edges changed and not yet revised by composition, and their membership.
    pub frontier: Vec<usize>,
    pub queued: BitSet,
    pub report: UpdateReport,
}

impl<'m, C: Calculus> Transaction<'m, C> {
    /// Starts a transaction after the landmarks from `old_len` on were added to `map`.
    pub fn new(map: &'m mut Hypergraph<C>, old_len: usize) -> Transaction<'m, C> {
        let edges = map.edges.len();
        Transaction {
            kernel: Kernel::of::<C>(),
            old_len,
            old_edges: super::index::choose3(old_len),
            touched: BitSet::new(edges),
            undo: Vec::new(),
            frontier: Vec::new(),
            queued: BitSet::new(edges),
            report: UpdateReport {
                new_landmarks: map.len() - old_len,
                ..UpdateReport::default()
            },
            map,
        }
    }

    /// Intersects `mask` into edge `rank`, closes the edge under the unary operators and
    /// queues it if it changed. Returns whether it changed, or the slot of a relation that
    /// would become empty (the edge is then left as it was).
    pub fn intersect(&mut self, rank: usize, mask: [u32; 3]) -> Result<bool, usize> {
        let current = self.map.edges[rank];
        let narrowed = [
            current[0] & mask[0],
            current[1] & mask[1],
            current[2] & mask[2],
        ];
        if narrowed == current {
            return Ok(false);
        }
        let closed = self.kernel.close_edge(narrowed);
        if let Some(slot) = closed.iter().position(|&s| s == 0) {
            return Err(slot);
        }
        if self.touched.insert(rank) {
            self.undo.push((rank, current));
        }
        self.map.edges[rank] = closed;
        self.queue(rank);
        Ok(true)
    }

    /// Queues edge `rank` for revision by composition without changing it.
    pub fn queue(&mut self, rank: usize) {
        if self.queued.insert(rank) {
            self.frontier.push(rank);
        }
    }

    /// Restores the map as it was before the update.
    pub fn rollback(self) {
        for &(rank, old) in &self.undo {
            if rank < self.old_edges {
                self.map.edges[rank] = old;
            }
        }
        self.map.truncate_landmarks(self.old_len);
    }

    /// Finishes the update and returns its statistics.
    pub fn commit(mut self) -> UpdateReport {
        let universe = [C::universe().bits(); 3];
        for &(rank, old) in &self.undo {
            let new = self.map.edges[rank];
            if old == universe && new != universe {
                self.map.mark_constrained(rank);
            }
            let tightened = (0..3).filter(|&s| new[s] != old[s]).count();
            self.report.relations_tightened += tightened;
            self.report.triples_changed += usize::from(tightened > 0);
        }
        self.report
    }
}
