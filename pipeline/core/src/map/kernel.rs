//! Table-driven set operators for the closure. 000 §III-C applies LEFT, RIGHT, INVERSE and
//! COMPOSE to sets as the union over members; here those unions are precomputed over 7-bit
//! chunks of a set, so a unary image costs one lookup per chunk and `COMPOSE(S1, S2)` costs
//! `min(|S1|, |S2|)` × (number of chunks) lookups. Built once per calculus.

use crate::calculus::{Calculus, OperatorTables, RelationSet};
use std::any::TypeId;
use std::collections::HashMap;
use std::sync::{OnceLock, RwLock};

const CHUNK_BITS: usize = 7;
const CHUNK_CELLS: usize = 1 << CHUNK_BITS;

/// Unions of per-relation images over every subset of each 7-bit chunk.
#[derive(Debug)]
struct ChunkTable {
    chunks: usize,
    /// `single[r − 1]`: image of relation `r` alone (the common case in a tight map).
    single: Vec<u32>,
    /// `cells[c · 128 + m]` = union of the images of relations `7c + t + 1` for bits `t` of `m`.
    cells: Vec<u32>,
}

impl ChunkTable {
    /// `image[r − 1]` is the image of base relation `r`.
    fn new(image: &[u32]) -> ChunkTable {
        let chunks = image.len().div_ceil(CHUNK_BITS);
        let mut cells = vec![0u32; chunks * CHUNK_CELLS];
        for c in 0..chunks {
            for m in 1..CHUNK_CELLS {
                let low = m.trailing_zeros() as usize;
                let rest = m & (m - 1);
                let r = c * CHUNK_BITS + low;
                let own = image.get(r).copied().unwrap_or(0);
                cells[c * CHUNK_CELLS + m] = cells[c * CHUNK_CELLS + rest] | own;
            }
        }
        ChunkTable {
            chunks,
            single: image.to_vec(),
            cells,
        }
    }

    #[inline(always)]
    fn apply(&self, set: u32) -> u32 {
        if set.is_power_of_two() {
            return self.single[set.trailing_zeros() as usize];
        }
        let mut out = 0;
        for c in 0..self.chunks {
            let m = (set >> (c * CHUNK_BITS)) as usize & (CHUNK_CELLS - 1);
            out |= self.cells[c * CHUNK_CELLS + m];
        }
        out
    }
}

/// Precomputed operators of one calculus, on raw bitsets ([`RelationSet::bits`]).
#[derive(Debug)]
pub(crate) struct Kernel {
    /// All relations possible between three distinct landmarks (`Calculus::universe`).
    pub universe: u32,
    /// `COMPOSE(S, U) ⊇ U` and `COMPOSE(U, S) ⊇ U` for every non-empty `S`, and the unary
    /// images of `U` contain `U`: a composition with an unconstrained input cannot tighten
    /// anything and is skipped, and new (unconstrained) edges need no revision.
    pub universe_neutral: bool,
    inverse: ChunkTable,
    /// `AB:C → BC:A`: `LEFT(r) ∩ INVERSE(RIGHT(INVERSE(r)))` (both are the projections of the
    /// configurations with `AB:C = r`, the second via `BA:C → CB:A → BC:A`).
    next: ChunkTable,
    /// `AB:C → CA:B`: `RIGHT(r) ∩ INVERSE(LEFT(INVERSE(r)))`.
    prev: ChunkTable,
    /// Per first relation `r1`: `COMPOSE(r1, ·)` over chunks of the second set.
    by_first: Vec<ChunkTable>,
    /// Per second relation `r2`: `COMPOSE(·, r2)` over chunks of the first set.
    by_second: Vec<ChunkTable>,
    /// `pairs[b1 · PAIR_STRIDE + b2]` = `COMPOSE` of the single relations of bits `b1`, `b2`:
    /// one load for the common case of a tight map (both inputs singletons). Row and column
    /// 32 (the `trailing_zeros` of an empty set) are empty, as `COMPOSE(∅, ·)` is.
    pairs: Box<[u32; PAIR_STRIDE * PAIR_STRIDE]>,
}

/// Row length of [`Kernel::pairs`]: bit indices 0..=31 and 32 for the empty set.
const PAIR_STRIDE: usize = 33;

impl Kernel {
    fn new(tables: &OperatorTables, universe: RelationSet) -> Kernel {
        let n = tables.relations();
        let image =
            |f: &dyn Fn(u8) -> RelationSet| -> Vec<u32> { (1..=n).map(|r| f(r).bits()).collect() };
        let inv = |s: RelationSet| tables.inverse(s);
        let next = image(&|r| {
            let s = RelationSet::single(r);
            tables.left(s).intersection(inv(tables.right(inv(s))))
        });
        let prev = image(&|r| {
            let s = RelationSet::single(r);
            tables.right(s).intersection(inv(tables.left(inv(s))))
        });
        let by_first = (1..=n)
            .map(|r1| ChunkTable::new(&image(&|r2| tables.compose_base(r1, r2))))
            .collect();
        let by_second = (1..=n)
            .map(|r2| ChunkTable::new(&image(&|r1| tables.compose_base(r1, r2))))
            .collect();
        let mut pairs = Box::new([0u32; PAIR_STRIDE * PAIR_STRIDE]);
        for r1 in 1..=n {
            for r2 in 1..=n {
                pairs[(r1 as usize - 1) * PAIR_STRIDE + r2 as usize - 1] =
                    tables.compose_base(r1, r2).bits();
            }
        }
        let u = universe.bits();
        let mut kernel = Kernel {
            universe: u,
            universe_neutral: false,
            inverse: ChunkTable::new(&image(&|r| {
                tables.unary_of(crate::calculus::UnaryOperator::Inverse, r)
            })),
            next: ChunkTable::new(&next),
            prev: ChunkTable::new(&prev),
            by_first,
            by_second,
            pairs,
        };
        let covers = |s: u32| s & u == u;
        kernel.universe_neutral = covers(kernel.inverse.apply(u))
            && covers(kernel.next.apply(u))
            && covers(kernel.prev.apply(u))
            && universe
                .iter()
                .all(|r| covers(kernel.by_first[r as usize - 1].apply(u)))
            && universe
                .iter()
                .all(|r| covers(kernel.by_second[r as usize - 1].apply(u)));
        kernel
    }

    /// The kernel of calculus `C`, built on first use.
    pub fn of<C: Calculus>() -> &'static Kernel {
        static KERNELS: OnceLock<RwLock<HashMap<TypeId, &'static Kernel>>> = OnceLock::new();
        let kernels = KERNELS.get_or_init(Default::default);
        let key = TypeId::of::<C>();
        if let Some(k) = kernels.read().unwrap_or_else(|e| e.into_inner()).get(&key) {
            return k;
        }
        let mut write = kernels.write().unwrap_or_else(|e| e.into_inner());
        write
            .entry(key)
            .or_insert_with(|| Box::leak(Box::new(Kernel::new(C::tables(), C::universe()))))
    }

    /// INVERSE of a set: `AB:C → BA:C`.
    #[inline]
    pub fn inverse(&self, s: u32) -> u32 {
        self.inverse.apply(s)
    }

    /// `COMPOSE(ab_c, bc_d) ∩ bound`, stopping early once the union covers `bound`.
    #[inline(always)]
    pub fn compose_within(&self, ab_c: u32, bc_d: u32, bound: u32) -> u32 {
        if (ab_c & ab_c.wrapping_sub(1)) | (bc_d & bc_d.wrapping_sub(1)) == 0 {
            let cell =
                ab_c.trailing_zeros() as usize * PAIR_STRIDE + bc_d.trailing_zeros() as usize;
            return self.pairs[cell] & bound;
        }
        self.compose_sets(ab_c, bc_d, bound)
    }

    /// [`Kernel::compose_within`] when an input has several members: the union over the
    /// members of the smaller input.
    #[inline(never)]
    fn compose_sets(&self, ab_c: u32, bc_d: u32, bound: u32) -> u32 {
        let (members, other, tables) = if ab_c.count_ones() <= bc_d.count_ones() {
            (ab_c, bc_d, &self.by_first)
        } else {
            (bc_d, ab_c, &self.by_second)
        };
        let mut acc = 0;
        let mut bits = members;
        while bits != 0 {
            let r = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            acc |= tables[r].apply(other);
            if acc & bound == bound {
                return bound;
            }
        }
        acc & bound
    }

    /// Closes one edge `[ij:k, jk:i, ki:j]` under the unary operators of 000 §III-A: every
    /// ordered relation of the triple (the three stored ones and their INVERSE images) is
    /// mapped by LEFT and RIGHT onto the others and intersected in, until nothing changes.
    /// Stops early when a relation becomes empty.
    pub fn close_edge(&self, [mut x, mut y, mut z]: [u32; 3]) -> [u32; 3] {
        loop {
            let before = [x, y, z];
            y &= self.next.apply(x);
            z &= self.prev.apply(x);
            z &= self.next.apply(y);
            x &= self.prev.apply(y);
            x &= self.next.apply(z);
            y &= self.prev.apply(z);
            if [x, y, z] == before || x == 0 || y == 0 || z == 0 {
                return [x, y, z];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edc::Edc;
    use crate::fdc::Fdc;

    fn check<C: Calculus>() {
        let k = Kernel::of::<C>();
        let t = C::tables();
        let u = C::universe();
        assert!(k.universe_neutral, "{}", C::NAME);
        // Set operations agree with the plain unions of OperatorTables on assorted sets.
        // Assorted sets, every singleton (the pair table) and the empty set.
        let sets: Vec<RelationSet> = (0..200u32)
            .map(|s| RelationSet::from_bits(s.wrapping_mul(2_654_435_761) & u.bits()))
            .chain(u.iter().map(RelationSet::single))
            .chain([RelationSet::EMPTY])
            .collect();
        for &a in &sets {
            assert_eq!(k.inverse(a.bits()), t.inverse(a).bits());
            for &b in &sets {
                let full = t.compose(a, b);
                assert_eq!(k.compose_within(a.bits(), b.bits(), u32::MAX), full.bits());
                assert_eq!(
                    k.compose_within(a.bits(), b.bits(), u.bits()),
                    full.intersection(u).bits()
                );
            }
        }
    }

    #[test]
    fn kernel_matches_operator_tables() {
        check::<Edc>();
        check::<Fdc>();
    }

    #[test]
    fn edge_closure_is_sound_for_the_tables_own_images() {
        // 000 Table I: AB:C = 7 gives BC:A ∈ {1,5} and CA:B ∈ {12,17}.
        let k = Kernel::of::<Edc>();
        let u = Edc::universe().bits();
        let [x, y, z] = k.close_edge([RelationSet::single(7).bits(), u, u]);
        assert_eq!(x, RelationSet::single(7).bits());
        assert!(RelationSet::from_bits(y).is_subset(RelationSet::from_relations([1, 5])));
        assert!(RelationSet::from_bits(z).is_subset(RelationSet::from_relations([12, 17])));
    }
}
