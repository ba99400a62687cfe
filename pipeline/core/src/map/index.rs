//! Dense indexing of the hypergraph edges `e_ijk` (000 §VI-A) by the combinatorial number
//! system: the triple of internal indices `i < j < k` has rank `C(k,3) + C(j,2) + i`, so the
//! triples of the first `n` landmarks are exactly the ranks `0..C(n,3)` and adding a landmark
//! appends its triples at the end.
//!
//! Each edge stores three relations (000 §VI-A): slot 0 is `ij:k`, slot 1 `jk:i`, slot 2 `ki:j`.
//! The other three orderings are their INVERSE images.

/// `C(x, 2)`.
pub(crate) const fn choose2(x: usize) -> usize {
    if x < 2 {
        0
    } else {
        x * (x - 1) / 2
    }
}

/// `C(x, 3)`: the number of triples among `x` landmarks.
pub(crate) const fn choose3(x: usize) -> usize {
    if x < 3 {
        0
    } else {
        x * (x - 1) * (x - 2) / 6
    }
}

/// `C(x, 4)`: the number of 4-sets among `x` landmarks.
pub(crate) const fn choose4(x: usize) -> usize {
    if x < 4 {
        0
    } else {
        choose3(x) * (x - 3) / 4
    }
}

/// Rank of the triple `i < j < k`.
pub(crate) const fn rank(i: usize, j: usize, k: usize) -> usize {
    choose3(k) + choose2(j) + i
}

/// Rank of the edge of three distinct indices in any order.
pub(crate) fn rank_of(a: usize, b: usize, c: usize) -> usize {
    let [i, j, k] = sort3(a, b, c);
    rank(i, j, k)
}

/// The three indices in increasing order.
pub(crate) fn sort3(a: usize, b: usize, c: usize) -> [usize; 3] {
    let mut t = [a, b, c];
    t.sort_unstable();
    t
}

/// The triple `(i, j, k)`, `i < j < k`, of a rank.
pub(crate) fn unrank(r: usize) -> [usize; 3] {
    // Largest k with C(k,3) <= r, then largest j with C(j,2) <= r − C(k,3).
    let (mut lo, mut hi) = (2usize, 4 + (6.0 * r as f64).cbrt() as usize);
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        if choose3(mid) <= r {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let k = lo;
    let r = r - choose3(k);
    let (mut lo, mut hi) = (1usize, k - 1);
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        if choose2(mid) <= r {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let j = lo;
    [r - choose2(j), j, k]
}

/// Where the ordered relation `ab:c` of three distinct internal indices is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Location {
    pub rank: usize,
    pub slot: usize,
    /// `ab:c` is the INVERSE of the stored relation (the ordering is anti-cyclic).
    pub inverted: bool,
}

/// The stored slot of `ab:c` in the edge `i < j < k` and whether it is read through INVERSE:
/// slot 0 holds `ij:k`, 1 `jk:i`, 2 `ki:j`.
pub(crate) const fn slot_of(a: usize, c: usize, [i, j, k]: [usize; 3]) -> (usize, bool) {
    if c == k {
        (0, a != i)
    } else if c == i {
        (1, a != j)
    } else {
        (2, a != k)
    }
}

/// Locates `ab:c` for distinct internal indices.
pub(crate) fn locate(a: usize, b: usize, c: usize) -> Location {
    let [i, j, k] = sort3(a, b, c);
    let (slot, inverted) = slot_of(a, c, [i, j, k]);
    Location {
        rank: rank(i, j, k),
        slot,
        inverted,
    }
}

/// The ordered triple stored in `slot` of the edge `i < j < k`: `(i,j,k)`, `(j,k,i)` or
/// `(k,i,j)`, read as `AB:C`.
pub(crate) const fn slot_order([i, j, k]: [usize; 3], slot: usize) -> [usize; 3] {
    match slot {
        0 => [i, j, k],
        1 => [j, k, i],
        _ => [k, i, j],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_are_dense_and_unrank_inverts_them() {
        let mut expected = 0;
        for k in 2..40 {
            for j in 1..k {
                for i in 0..j {
                    assert_eq!(rank(i, j, k), expected);
                    assert_eq!(unrank(expected), [i, j, k]);
                    expected += 1;
                }
            }
            assert_eq!(choose3(k + 1), expected);
            assert_eq!(choose4(k + 1), choose4(k) + choose3(k));
        }
    }

    #[test]
    fn locate_matches_slot_order() {
        let t = [3, 8, 11];
        for slot in 0..3 {
            let [a, b, c] = slot_order(t, slot);
            let l = locate(a, b, c);
            assert_eq!((l.slot, l.inverted), (slot, false));
            let l = locate(b, a, c);
            assert_eq!((l.slot, l.inverted), (slot, true));
            assert_eq!(l.rank, rank(3, 8, 11));
        }
    }
}
