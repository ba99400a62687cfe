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

/// A narrowed edge: its rank and the relations to intersect in.
type Revision = (usize, [u32; 3]);

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
            let revisions: Vec<(Vec<Revision>, u64)> = batch
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

/// The four ordered relations of an edge `{x, y, W}` (`x < y` positions of the queued edge)
/// that the compositions read and narrow: `[xy:W, yx:W, Wx:y, Wy:x]`.
type Around = [u32; 4];
const XY_W: usize = 0;
const YX_W: usize = 1;
const WX_Y: usize = 2;
const WY_X: usize = 3;

/// Where W lies among the edge's landmarks `x < y` in internal index order; fixes which
/// stored slot holds which ordered relation.
#[derive(Clone, Copy)]
enum Place {
    /// Stored as `(W, x, y)`: `[Wx:y, xy:W, yW:x]`.
    Before,
    /// Stored as `(x, W, y)`: `[xW:y, Wy:x, yx:W]`.
    Between,
    /// Stored as `(x, y, W)`: `[xy:W, yW:x, Wx:y]`.
    After,
}

fn around(kernel: &Kernel, s: [u32; 3], place: Place) -> Around {
    match place {
        Place::Before => [s[1], kernel.inverse(s[1]), s[0], kernel.inverse(s[2])],
        Place::Between => [kernel.inverse(s[2]), s[2], kernel.inverse(s[0]), s[1]],
        Place::After => [s[0], kernel.inverse(s[0]), s[2], kernel.inverse(s[1])],
    }
}

/// The stored relations after narrowing the ordered ones to `v` (INVERSE is one-to-one, so
/// intersecting both orderings of a pair loses nothing).
fn stored(kernel: &Kernel, s: [u32; 3], v: Around, place: Place) -> [u32; 3] {
    let inv = |x| kernel.inverse(x);
    match place {
        Place::Before => [s[0] & v[WX_Y], v[XY_W] & inv(v[YX_W]), s[2] & inv(v[WY_X])],
        Place::Between => [s[0] & inv(v[WX_Y]), s[1] & v[WY_X], v[YX_W] & inv(v[XY_W])],
        Place::After => [v[XY_W] & inv(v[YX_W]), s[1] & inv(v[WY_X]), s[2] & v[WX_Y]],
    }
}

/// One composition of a 4-set `{0, 1, 2, W}` (positions 0 < 1 < 2 of the queued edge):
/// `out ⊆ COMPOSE(first, second)`, where one input is an ordered relation of the queued edge
/// (`edge_pair`) and the other and the output are ordered relations of edges containing W
/// (edge `e` is the one without position `e`).
struct Step {
    edge_pair: (usize, usize),
    /// The W-edge input `(e, which)`.
    input: (usize, usize),
    /// The W-edge output `(e, which)`.
    output: (usize, usize),
}

/// Index into [`Around`] of `pq:W` for positions `p != q` of the queued edge.
const fn pair_w(p: usize, q: usize) -> usize {
    if p < q {
        XY_W
    } else {
        YX_W
    }
}

/// Index into [`Around`] of `Wp:q`.
const fn w_pair(p: usize, q: usize) -> usize {
    if p < q {
        WX_Y
    } else {
        WY_X
    }
}

/// The queued edge as first input: `AB:W ⊆ COMPOSE(AB:C, BC:W)` for its orderings `(A,B,C)`.
const FIRST: [Step; 6] = {
    let mut steps = [const {
        Step {
            edge_pair: (0, 0),
            input: (0, 0),
            output: (0, 0),
        }
    }; 6];
    let mut n = 0;
    while n < 6 {
        let [a, b, c] = PERMUTATIONS[n];
        steps[n] = Step {
            edge_pair: (a, b),
            input: (a, pair_w(b, c)),
            output: (c, pair_w(a, b)),
        };
        n += 1;
    }
    steps
};

/// The queued edge as second input: `WB:D ⊆ COMPOSE(WB:C, BC:D)` for its orderings `(B,C,D)`;
/// `input.0` is the edge `{W, B, C}` (without `D`).
const SECOND: [Step; 6] = {
    let mut steps = [const {
        Step {
            edge_pair: (0, 0),
            input: (0, 0),
            output: (0, 0),
        }
    }; 6];
    let mut n = 0;
    while n < 6 {
        let [b, c, d] = PERMUTATIONS[n];
        steps[n] = Step {
            edge_pair: (b, c),
            input: (d, w_pair(b, c)),
            output: (c, w_pair(b, d)),
        };
        n += 1;
    }
    steps
};

/// Revises every composition of the 4-sets containing queued edge `t` in which `t` is an
/// input; appends the narrowed edges to `out` and returns the number of compositions.
fn revise(
    kernel: &Kernel,
    n: usize,
    edges: &[[u32; 3]],
    in_round: &BitSet,
    t: usize,
    out: &mut Vec<Revision>,
) -> u64 {
    let u = kernel.universe;
    let skip_universe = kernel.universe_neutral;
    let unconstrained = |s: u32| skip_universe && s == u;
    let p = unrank(t);
    // Ordered relations of the queued edge: tri[a][b] = p_a p_b : p_c.
    let s = edges[t];
    let mut tri = [[0u32; 3]; 3];
    tri[0][1] = s[0];
    tri[1][2] = s[1];
    tri[2][0] = s[2];
    tri[1][0] = kernel.inverse(s[0]);
    tri[2][1] = kernel.inverse(s[1]);
    tri[0][2] = kernel.inverse(s[2]);
    // The W-edge without position e holds positions OTHERS[e] (in increasing order) and W.
    const OTHERS: [(usize, usize); 3] = [(1, 2), (0, 2), (0, 1)];
    let mut count = 0;
    for w in 0..n {
        if p.contains(&w) {
            continue;
        }
        let mut ranks = [0usize; 3];
        let mut places = [Place::After; 3];
        let mut old = [[0u32; 3]; 3];
        for e in 0..3 {
            let (x, y) = OTHERS[e];
            let (px, py) = (p[x], p[y]);
            (ranks[e], places[e]) = if w < px {
                (rank(w, px, py), Place::Before)
            } else if w < py {
                (rank(px, w, py), Place::Between)
            } else {
                (rank(px, py, w), Place::After)
            };
            old[e] = edges[ranks[e]];
        }
        if skip_universe && old.iter().all(|s| *s == [u; 3]) {
            continue;
        }
        let mut v: [Around; 3] = [
            around(kernel, old[0], places[0]),
            around(kernel, old[1], places[1]),
            around(kernel, old[2], places[2]),
        ];
        let mut dirty = [false; 3];
        let mut apply = |v: &mut [Around; 3], step: &Step, first: u32, second: u32| {
            if unconstrained(first) || unconstrained(second) {
                return;
            }
            count += 1;
            let (oe, ok) = step.output;
            let narrowed = kernel.compose_within(first, second, v[oe][ok]);
            if narrowed != v[oe][ok] {
                v[oe][ok] = narrowed;
                dirty[oe] = true;
            }
        };
        for step in &FIRST {
            let (a, b) = step.edge_pair;
            let (ie, ik) = step.input;
            let bc_w = v[ie][ik];
            apply(&mut v, step, tri[a][b], bc_w);
        }
        for step in &SECOND {
            let (ie, ik) = step.input;
            // Evaluated from the first input's own revision when that edge is queued too.
            if in_round.contains(ranks[ie]) {
                continue;
            }
            let (b, c) = step.edge_pair;
            let wb_c = v[ie][ik];
            apply(&mut v, step, wb_c, tri[b][c]);
        }
        for e in 0..3 {
            if dirty[e] {
                let new = stored(kernel, old[e], v[e], places[e]);
                if new != old[e] {
                    out.push((ranks[e], new));
                }
            }
        }
    }
    count
}
