//! Path-consistency closure of the map (000 §VI-B steps 8–9, generalised to full path
//! consistency in the sense of van Beek / Renz and Nebel cited there).
//!
//! For every four distinct landmarks and each of the 24 orderings `(A, B, C, D)` the closed map
//! satisfies `AB:D ⊆ COMPOSE(AB:C, BC:D)`. The paper's step 8 revises only `AB:X` from
//! `COMPOSE(AB:C, BC:X)` for the changed `AB:C`; here a changed edge `{X, Y, Z}` revises, for
//! every other landmark `W`, all compositions of the 4-set `{X, Y, Z, W}` in which it is an
//! input: as first input (`AB:C` over its 6 orderings, `D = W`) and as second input (`BC:D`
//! over its 6 orderings, `A = W`). Outputs are edges containing `W`; changed outputs are
//! queued (worklist).
//!
//! The worklist runs in rounds: the revisions of a batch of queued edges are computed in
//! parallel from the current relations, then intersected in sequentially. Intersection is
//! monotone and the greatest path-consistent refinement is unique, so the result does not
//! depend on the order. A composition whose first input is queued in the same round is
//! evaluated only from that edge (it is revised after the last change of either input).

use super::index::{rank, unrank};
use super::kernel::Kernel;
use super::transaction::{BitSet, Transaction};
use crate::calculus::Calculus;
use rayon::prelude::*;

/// Queued edges revised per parallel batch (bounds the memory of pending revisions).
const BATCH: usize = 8192;
/// Queued edges per parallel task.
const TASK: usize = 16;

/// Orderings of three positions.
const PERMUTATIONS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [1, 2, 0],
    [2, 0, 1],
    [1, 0, 2],
    [0, 2, 1],
    [2, 1, 0],
];

/// Runs the closure until the worklist is empty. On a contradiction returns the edge rank and
/// slot of the relation that would become empty.
pub(super) fn close<C: Calculus>(tx: &mut Transaction<'_, C>) -> Result<(), (usize, usize)> {
    let n = tx.map.len();
    let mut in_round = BitSet::new(tx.map.edges.len());
    while !tx.frontier.is_empty() {
        tx.report.rounds += 1;
        let round = std::mem::take(&mut tx.frontier);
        std::mem::swap(&mut in_round, &mut tx.queued);
        for batch in round.chunks(BATCH) {
            let kernel = tx.kernel;
            let edges = &tx.map.edges;
            let in_round = &in_round;
            let revisions: Vec<(Vec<(usize, [u32; 3])>, u64)> = batch
                .par_chunks(TASK)
                .map(|task| {
                    let mut out = Vec::new();
                    let mut count = 0;
                    for &t in task {
                        count += revise(kernel, n, edges, in_round, t, &mut out);
                    }
                    (out, count)
                })
                .collect();
            for (list, count) in revisions {
                tx.report.compositions += count;
                for (rank, mask) in list {
                    tx.intersect(rank, mask).map_err(|slot| (rank, slot))?;
                }
            }
        }
        for &t in &round {
            in_round.remove(t);
        }
    }
    Ok(())
}

/// The six ordered relations of an edge over four positions: `m[a][b]` is `p_a p_b : p_c`
/// for the third position `c` of the edge.
type Ordered = [[u32; 4]; 4];

/// Fills `m` with the ordered relations of the edge with stored relations `s`, whose positions
/// in increasing internal index are `q`.
#[inline]
fn load(kernel: &Kernel, s: [u32; 3], [q0, q1, q2]: [usize; 3], m: &mut Ordered) {
    m[q0][q1] = s[0];
    m[q1][q2] = s[1];
    m[q2][q0] = s[2];
    m[q1][q0] = kernel.inverse(s[0]);
    m[q2][q1] = kernel.inverse(s[1]);
    m[q0][q2] = kernel.inverse(s[2]);
}

/// Revises every composition of the 4-sets containing queued edge `t` in which `t` is an
/// input; appends the narrowed edges to `out` and returns the number of compositions.
fn revise(
    kernel: &Kernel,
    n: usize,
    edges: &[[u32; 3]],
    in_round: &BitSet,
    t: usize,
    out: &mut Vec<(usize, [u32; 3])>,
) -> u64 {
    let u = kernel.universe;
    let skip_universe = kernel.universe_neutral;
    let unconstrained = |s: u32| skip_universe && s == u;
    // Positions 0, 1, 2 are the edge's landmarks i < j < k, position 3 is W.
    let p3 = unrank(t);
    let mut tri: Ordered = [[0; 4]; 4];
    load(kernel, edges[t], [0, 1, 2], &mut tri);
    let mut count = 0;
    for w in 0..n {
        if p3.contains(&w) {
            continue;
        }
        // Edge e (0..3) is the one without position e: positions `others[e]` and W.
        let mut ranks = [0usize; 3];
        let mut orders = [[0usize; 3]; 3];
        let mut stored = [[0u32; 3]; 3];
        for e in 0..3 {
            let (x, y) = match e {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            let (px, py) = (p3[x], p3[y]);
            let (r, q) = if w < px {
                (rank(w, px, py), [3, x, y])
            } else if w < py {
                (rank(px, w, py), [x, 3, y])
            } else {
                (rank(px, py, w), [x, y, 3])
            };
            ranks[e] = r;
            orders[e] = q;
            stored[e] = edges[r];
        }
        if skip_universe && stored.iter().all(|s| s.iter().all(|&x| x == u)) {
            continue;
        }
        let mut m: [Ordered; 3] = [[[0; 4]; 4]; 3];
        for e in 0..3 {
            load(kernel, stored[e], orders[e], &mut m[e]);
        }
        let mut dirty = [false; 3];
        // As first input: AB:W ⊆ COMPOSE(AB:C, BC:W) for the orderings (A, B, C) of the edge.
        for [a, b, c] in PERMUTATIONS {
            let (ab_c, bc_w) = (tri[a][b], m[a][b][c]);
            if unconstrained(ab_c) || unconstrained(bc_w) {
                continue;
            }
            count += 1;
            let ab_w = m[c][a][b];
            let narrowed = kernel.compose_within(ab_c, bc_w, ab_w);
            if narrowed != ab_w {
                m[c][a][b] = narrowed;
                dirty[c] = true;
            }
        }
        // As second input: WB:D ⊆ COMPOSE(WB:C, BC:D) for the orderings (B, C, D) of the edge,
        // unless the first input {W, B, C} is queued in this round itself.
        for [b, c, d] in PERMUTATIONS {
            if in_round.contains(ranks[d]) {
                continue;
            }
            let (wb_c, bc_d) = (m[d][3][b], tri[b][c]);
            if unconstrained(wb_c) || unconstrained(bc_d) {
                continue;
            }
            count += 1;
            let wb_d = m[c][3][b];
            let narrowed = kernel.compose_within(wb_c, bc_d, wb_d);
            if narrowed != wb_d {
                m[c][3][b] = narrowed;
                dirty[c] = true;
            }
        }
        for e in 0..3 {
            if dirty[e] {
                let [q0, q1, q2] = orders[e];
                let me = &m[e];
                let new = [
                    me[q0][q1] & kernel.inverse(me[q1][q0]),
                    me[q1][q2] & kernel.inverse(me[q2][q1]),
                    me[q2][q0] & kernel.inverse(me[q0][q2]),
                ];
                if new != stored[e] {
                    out.push((ranks[e], new));
                }
            }
        }
    }
    count
}
