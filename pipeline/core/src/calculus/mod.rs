//! A ternary qualitative calculus over point triples `AB:C`: its base relations, a classifier,
//! the unary operators LEFT, RIGHT, INVERSE and composition (000 §III). The map, measurement
//! and reasoning code is written once against [`Calculus`] and serves EDC and FDC alike.

mod operators;
mod relation_set;
mod table_format;

pub use operators::{OperatorTables, UnaryOperator};
pub use relation_set::{ParseRelationSetError, RelationSet};
pub use table_format::{CompositionEntry, CompositionFile, EntryKind, TableFormatError, UnaryFile};

use crate::geometry::Point;

/// A point-based ternary calculus with generated operator tables.
pub trait Calculus: Send + Sync + 'static {
    /// Short name used in file headers and on the command line (`EDC`, `FDC`).
    const NAME: &'static str;
    /// Number of base relations, numbered `1..=RELATIONS`.
    const RELATIONS: u8;

    /// The base relation of `c` with respect to the directed pair `a → b`, or `None` when it is
    /// not defined (for EDC: `c` on a boundary; for any calculus: `a == b`).
    fn classify(a: Point, b: Point, c: Point) -> Option<u8>;

    /// The committed operator tables.
    fn tables() -> &'static OperatorTables;

    /// The relation between three distinct landmarks when nothing is known.
    fn universe() -> RelationSet {
        RelationSet::all(Self::RELATIONS as usize)
    }

    /// The relations of this calculus possible for an arrangement measured to lie in one of the
    /// EDC `regions`. Measurement (000 §IV) decides EDC regions, the finest open cells of the
    /// boundaries of both calculi; a calculus whose relations include zero-area ones (lines)
    /// must add those bordering a possible cell, since a feasible set of arrangements that
    /// touches a line also reaches a cell beside it.
    fn from_edc(regions: RelationSet) -> RelationSet;

    /// The relations of `AB:C` that put C in the lune of A and B (inside both circles), if the
    /// calculus can tell: what the RNG estimate of 000 §VII-A needs.
    fn lune() -> Option<RelationSet> {
        None
    }

    /// The relations sharing a boundary edge or vertex with `r` (for 000 Fig. 7b), if defined.
    fn adjacent(_r: u8) -> Option<RelationSet> {
        None
    }
}
