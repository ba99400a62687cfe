//! Path consistency of one 4-set of landmarks: its four edges (one per triple) are loaded
//! once, all 24 compositions `AB:D ⊆ COMPOSE(AB:C, BC:D)` over the orderings `(A, B, C, D)`
//! are applied locally until none narrows anything, and the narrowed edges are returned.
//! Checking a whole 4-set at a time is what makes a dense closure cheap: every relation is
//! read once per 4-set instead of once per composition, and a narrowing is used by the
//! remaining compositions of the 4-set immediately.

use super::index::slot_of;
use super::kernel::Kernel;

/// A narrowed edge: its rank and the relations to intersect in.
pub(super) type Revision = (usize, [u32; 3]);

/// The 24 ordered relations of a 4-set with positions `0 < 1 < 2 < 3` (internal index order).
/// Relation `6e + o` lies in edge `e`, the triple without position `e`: for `o < 3` it is
/// stored slot `o` of that edge (see `index`), for `o ≥ 3` the INVERSE of slot `o − 3`.
/// Indices are masked with `SLOTS − 1` (always in bounds, no check in the hot loop); entries
/// 24..32 are unused.
type Relations = [u32; SLOTS];
const SLOTS: usize = 32;

/// Index into [`Relations`] of `ab:c` for distinct positions (the rule of `index::locate`).
const fn ordered(a: usize, b: usize, c: usize) -> usize {
    let missing = 6 - a - b - c;
    // The edge's positions in increasing order.
    let (i, j, k) = match missing {
        0 => (1, 2, 3),
        1 => (0, 2, 3),
        2 => (0, 1, 3),
        _ => (0, 1, 2),
    };
    let (slot, inverted) = slot_of(a, c, [i, j, k]);
    6 * missing + slot + if inverted { 3 } else { 0 }
}

/// `[AB:C, BC:D, AB:D]` as [`Relations`] indices for each ordering `(A, B, C, D)`.
const COMPOSITIONS: [[usize; 3]; 24] = {
    let mut out = [[0; 3]; 24];
    let mut n = 0;
    let mut a = 0;
    while a < 4 {
        let mut b = 0;
        while b < 4 {
            let mut c = 0;
            while c < 4 {
                if a != b && b != c && a != c {
                    let d = 6 - a - b - c;
                    out[n] = [ordered(a, b, c), ordered(b, c, d), ordered(a, b, d)];
                    n += 1;
                }
                c += 1;
            }
            b += 1;
        }
        a += 1;
    }
    out
};

/// Closes the 4-set whose edges (the triple without position `e`, for `e = 0..4`) have ranks
/// `ranks`, reading them from `edges`. Appends every narrowed edge (closed under the unary
/// operators) to `out` and returns the number of compositions evaluated. Stops at the first
/// emptied relation; its edge is appended, so intersecting `out` reports the contradiction.
pub(super) fn close_quad(
    kernel: &Kernel,
    edges: &[[u32; 3]],
    ranks: [usize; 4],
    out: &mut Vec<Revision>,
) -> u64 {
    let u = kernel.universe;
    let stored = ranks.map(|r| edges[r]);
    // Every composition reads two different edges: with fewer than two constrained ones
    // nothing can be narrowed.
    if kernel.universe_neutral && stored.iter().filter(|s| **s != [u; 3]).count() < 2 {
        return 0;
    }
    // An input equal to `skip` is unconstrained: the composition cannot narrow anything.
    // (Stored relations are subsets of the universe, never `u32::MAX`.)
    let skip = if kernel.universe_neutral { u } else { u32::MAX };
    let mut v: Relations = [0; SLOTS];
    for (e, s) in stored.iter().enumerate() {
        set_edge(kernel, &mut v, e, *s);
    }
    let mut count = 0;
    let mut dirty = 0u8;
    'stable: loop {
        let mut changed = false;
        for &[ab_c, bc_d, ab_d] in &COMPOSITIONS {
            let (ab_c, bc_d, ab_d) = (ab_c & (SLOTS - 1), bc_d & (SLOTS - 1), ab_d & (SLOTS - 1));
            let (first, second) = (v[ab_c], v[bc_d]);
            if first == skip || second == skip {
                continue;
            }
            count += 1;
            let narrowed = kernel.compose_within(first, second, v[ab_d]);
            if narrowed == v[ab_d] {
                continue;
            }
            let e = ab_d / 6;
            let o = ab_d % 6;
            let mut s = [v[6 * e], v[6 * e + 1], v[6 * e + 2]];
            if o < 3 {
                s[o] = narrowed;
            } else {
                s[o - 3] &= kernel.inverse(narrowed);
            }
            let s = kernel.close_edge(s);
            set_edge(kernel, &mut v, e, s);
            dirty |= 1 << e;
            changed = true;
            if s.contains(&0) {
                break 'stable;
            }
        }
        if !changed {
            break;
        }
    }
    for (e, &rank) in ranks.iter().enumerate() {
        if dirty & 1 << e != 0 {
            out.push((rank, [v[6 * e], v[6 * e + 1], v[6 * e + 2]]));
        }
    }
    count
}

/// Writes the stored relations `s` of edge `e` and their INVERSE images into `v`.
#[inline(always)]
fn set_edge(kernel: &Kernel, v: &mut Relations, e: usize, s: [u32; 3]) {
    for (o, x) in s.into_iter().enumerate() {
        v[6 * e + o] = x;
        v[6 * e + 3 + o] = kernel.inverse(x);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::index::{locate, rank_of};

    #[test]
    fn ordered_relations_match_the_storage_rule() {
        // Positions 0..4 as internal indices 10 < 20 < 30 < 40.
        let q = [10, 20, 30, 40];
        let ranks = [0, 1, 2, 3].map(|m| {
            let t: Vec<usize> = (0..4).filter(|&p| p != m).map(|p| q[p]).collect();
            rank_of(t[0], t[1], t[2])
        });
        let mut seen = [false; 24];
        for a in 0..4 {
            for b in 0..4 {
                for c in 0..4 {
                    if a == b || b == c || a == c {
                        continue;
                    }
                    let id = ordered(a, b, c);
                    let loc = locate(q[a], q[b], q[c]);
                    assert_eq!(ranks[id / 6], loc.rank);
                    assert_eq!((id % 6 % 3, id % 6 >= 3), (loc.slot, loc.inverted));
                    seen[id] = true;
                }
            }
        }
        assert!(seen.iter().all(|&s| s));
    }
}
