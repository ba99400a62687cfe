//! Path-consistency closure of the map (000 §VI-B steps 8–9, generalised to full path
//! consistency in the sense of van Beek / Renz and Nebel cited there).
//!
//! For every four distinct landmarks and each of the 24 orderings `(A, B, C, D)` the closed map
//! satisfies `AB:D ⊆ COMPOSE(AB:C, BC:D)`. The paper's step 8 revises only `AB:X` from
//! `COMPOSE(AB:C, BC:X)` for the changed `AB:C`; here a changed edge `{X, Y, Z}` has every
//! 4-set `{X, Y, Z, W}` closed (all 24 compositions, `quad`), and the edges those narrow are
//! queued in turn (worklist).
//!
//! The worklist runs in rounds: each round closes every 4-set containing an edge changed in the
//! round before, once, in place (a 4-set reads the relations as narrowed by those before it).
//! Edges narrowed during the round are queued for the next one. Intersection is monotone and
//! the greatest path-consistent refinement is unique, so the result does not depend on the
//! order.

use super::index::{choose2, choose3, choose4, rank, unrank};
use super::quad::{close_quad, Revision};
use super::transaction::{BitSet, Transaction};
use crate::calculus::Calculus;

/// A round sweeps all 4-sets in storage order ([`sweep`]) instead of going through the queued
/// edges ([`around_queued`]) when at least `1 / DENSE` of the edges are queued.
const DENSE: usize = 4;

/// Which 4-sets a round must close: those containing an edge of the round (`queued`) that
/// may have changed after the 4-set was last closed. `since[e]`, when present, is the
/// storage-order position ([`key`]) of the 4-set that last narrowed `e` during the round
/// before, which closed every 4-set in that order: the 4-sets from there on were closed with
/// `e` as it is now, so only those before need closing again for `e`. This spares most of
/// the second round after a complete sweep, where the edges narrowed were mostly narrowed
/// early in their 4-sets.
struct Pending<'a> {
    queued: &'a BitSet,
    since: Option<&'a [u64]>,
}

impl Pending<'_> {
    /// Whether edge `e` makes the 4-set at position `key` need closing.
    #[inline]
    fn needs(&self, e: usize, key: u64) -> bool {
        self.queued.contains(e) && self.since.is_none_or(|since| key < since[e])
    }
}

/// Storage-order position of the 4-set `{a, b, c, d}`, `a < b < c < d`, whose edge without
/// `d` has rank `abc`: its rank in the combinatorial number system, `C(d,4) + rank(a,b,c)`.
fn key(d: usize, abc: usize) -> u64 {
    (choose4(d) + abc) as u64
}

/// Runs the closure until the worklist is empty. On a contradiction returns the edge rank and
/// slot of the relation that would become empty.
pub(super) fn close<C: Calculus>(tx: &mut Transaction<'_, C>) -> Result<(), (usize, usize)> {
    let edges = tx.map.edges.len();
    let mut in_round = BitSet::new(edges);
    let mut since: Option<Vec<u64>> = None;
    while !tx.frontier.is_empty() {
        tx.report.rounds += 1;
        let round = std::mem::take(&mut tx.frontier);
        std::mem::swap(&mut in_round, &mut tx.queued);
        let previous = since.take();
        let pending = Pending {
            queued: &in_round,
            since: previous.as_deref(),
        };
        if round.len() == edges {
            // Every 4-set is closed in storage order: record where each edge last changed.
            let mut narrowed_at = vec![u64::MAX; edges];
            sweep(tx, &pending, Some(&mut narrowed_at))?;
            since = Some(narrowed_at);
        } else if round.len() * DENSE >= edges {
            sweep(tx, &pending, None)?;
        } else {
            around_queued(tx, &round, &pending)?;
        }
        for &t in &round {
            in_round.remove(t);
        }
    }
    Ok(())
}

/// Closes the 4-set of edges `ranks` ([`close_quad`]) and intersects what it narrowed into
/// the map, which queues those edges for the next round; the narrowed edges are left in
/// `out`.
fn close_in_place<C: Calculus>(
    tx: &mut Transaction<'_, C>,
    ranks: [usize; 4],
    out: &mut Vec<Revision>,
) -> Result<(), (usize, usize)> {
    tx.report.compositions += close_quad(tx.kernel, &tx.map.edges, ranks, out);
    for &(rank, mask) in out.iter() {
        tx.intersect(rank, mask).map_err(|slot| (rank, slot))?;
    }
    Ok(())
}

/// Closes every 4-set that `pending` asks for, in storage order; with `narrowed_at`, records
/// for every edge narrowed the [`key`] of the 4-set that last narrowed it. The loops follow
/// the storage order: for fixed `b < c < d`, the edges `{a, b, c}`, `{a, b, d}` and
/// `{a, c, d}` are consecutive in `a`, and no rank is computed from scratch.
fn sweep<C: Calculus>(
    tx: &mut Transaction<'_, C>,
    pending: &Pending<'_>,
    mut narrowed_at: Option<&mut Vec<u64>>,
) -> Result<(), (usize, usize)> {
    let n = tx.map.len();
    let mut out = Vec::new();
    for d in 3..n {
        let base_d = choose3(d);
        for c in 2..d {
            let (base_c, c2) = (choose3(c), choose2(c));
            for b in 1..c {
                let b2 = choose2(b);
                let bcd = base_d + c2 + b;
                for a in 0..b {
                    let abc = base_c + b2 + a;
                    let ranks = [bcd, base_d + c2 + a, base_d + b2 + a, abc];
                    let key = key(d, abc);
                    if !ranks.iter().any(|&r| pending.needs(r, key)) {
                        continue;
                    }
                    out.clear();
                    close_in_place(tx, ranks, &mut out)?;
                    if let Some(at) = narrowed_at.as_deref_mut() {
                        for &(rank, _) in &out {
                            at[rank] = key;
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

/// Closes every 4-set that `pending` asks for, going through the edges of `round`: the
/// 4-sets `{x, y, z, w}` of edge `{x, y, z}` for every other landmark `w`, each from the
/// edge of smallest rank among its four that asks for it.
fn around_queued<C: Calculus>(
    tx: &mut Transaction<'_, C>,
    round: &[usize],
    pending: &Pending<'_>,
) -> Result<(), (usize, usize)> {
    let n = tx.map.len();
    let mut out = Vec::new();
    for &t in round {
        let [x, y, z] = unrank(t);
        for w in 0..n {
            let q = match w {
                _ if w < x => [w, x, y, z],
                _ if x < w && w < y => [x, w, y, z],
                _ if y < w && w < z => [x, y, w, z],
                _ if z < w => [x, y, z, w],
                _ => continue,
            };
            let ranks = quad_ranks(q);
            let key = key(q[3], ranks[3]);
            if !pending.needs(t, key) || ranks.iter().any(|&r| r < t && pending.needs(r, key)) {
                continue;
            }
            out.clear();
            close_in_place(tx, ranks, &mut out)?;
        }
    }
    Ok(())
}

/// Ranks of the four edges of the 4-set `q[0] < q[1] < q[2] < q[3]`, the edge without `q[e]`
/// at `e` (the order of [`close_quad`]).
fn quad_ranks([a, b, c, d]: [usize; 4]) -> [usize; 4] {
    [rank(b, c, d), rank(a, c, d), rank(a, b, d), rank(a, b, c)]
}
