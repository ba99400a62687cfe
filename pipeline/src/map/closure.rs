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

use super::index::{choose2, choose3, rank, unrank};
use super::quad::{close_quad, Revision};
use super::transaction::{BitSet, Transaction};
use crate::calculus::Calculus;

/// A round sweeps all 4-sets in storage order ([`sweep`]) instead of going through the queued
/// edges ([`around_queued`]) when at least `1 / DENSE` of the edges are queued.
const DENSE: usize = 4;

/// Runs the closure until the worklist is empty. On a contradiction returns the edge rank and
/// slot of the relation that would become empty.
pub(super) fn close<C: Calculus>(tx: &mut Transaction<'_, C>) -> Result<(), (usize, usize)> {
    let mut in_round = BitSet::new(tx.map.edges.len());
    while !tx.frontier.is_empty() {
        tx.report.rounds += 1;
        let round = std::mem::take(&mut tx.frontier);
        std::mem::swap(&mut in_round, &mut tx.queued);
        if round.len() * DENSE >= tx.map.edges.len() {
            sweep(tx, &in_round)?;
        } else {
            around_queued(tx, &round, &in_round)?;
        }
        for &t in &round {
            in_round.remove(t);
        }
    }
    Ok(())
}

/// Closes the 4-set of edges `ranks` ([`close_quad`]) and intersects what it narrowed into
/// the map, which queues those edges for the next round.
fn close_in_place<C: Calculus>(
    tx: &mut Transaction<'_, C>,
    ranks: [usize; 4],
    out: &mut Vec<Revision>,
) -> Result<(), (usize, usize)> {
    tx.report.compositions += close_quad(tx.kernel, &tx.map.edges, ranks, out);
    for (rank, mask) in out.drain(..) {
        tx.intersect(rank, mask).map_err(|slot| (rank, slot))?;
    }
    Ok(())
}

/// Closes every 4-set that contains an edge of `in_round`. The loops follow the storage
/// order: for fixed `b < c < d`, the edges `{a, b, c}`, `{a, b, d}` and `{a, c, d}` are
/// consecutive in `a`, and no rank is computed from scratch.
fn sweep<C: Calculus>(
    tx: &mut Transaction<'_, C>,
    in_round: &BitSet,
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
                    let ranks = [bcd, base_d + c2 + a, base_d + b2 + a, base_c + b2 + a];
                    if ranks.iter().any(|&r| in_round.contains(r)) {
                        close_in_place(tx, ranks, &mut out)?;
                    }
                }
            }
        }
    }
    Ok(())
}

/// Closes every 4-set that contains an edge of `round` (whose members are `in_round`), going
/// through the edges: the 4-sets `{x, y, z, w}` of queued edge `{x, y, z}` for every other
/// landmark `w`, each from the queued edge of smallest rank among its four.
fn around_queued<C: Calculus>(
    tx: &mut Transaction<'_, C>,
    round: &[usize],
    in_round: &BitSet,
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
            if ranks.iter().any(|&r| r < t && in_round.contains(r)) {
                continue;
            }
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
