use super::relation_set::RelationSet;
use super::table_format::{CompositionFile, TableFormatError, UnaryFile};

/// The three unary operators of 000 §III-A.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum UnaryOperator {
    /// `AB:C → BC:A`.
    Left,
    /// `AB:C → CA:B`.
    Right,
    /// `AB:C → BA:C`.
    Inverse,
}

/// Lookup tables of one calculus, applied to sets by union over members (000 §III-C).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OperatorTables {
    relations: u8,
    left: Vec<RelationSet>,
    right: Vec<RelationSet>,
    inverse: Vec<RelationSet>,
    /// `compose[(r1−1)·n + (r2−1)]` = possible `AB:D` given `AB:C = r1`, `BC:D = r2`.
    compose: Vec<RelationSet>,
}

impl OperatorTables {
    /// Builds the tables from parsed files; undecided composition entries count as possible.
    /// The two files must describe the same calculus.
    pub fn from_files(
        unary: &UnaryFile,
        composition: &CompositionFile,
    ) -> Result<OperatorTables, TableFormatError> {
        if unary.calculus != composition.calculus || unary.relations != composition.relations {
            return Err(TableFormatError {
                line: 0,
                reason: format!(
                    "unary table is {} with {} relations but composition table is {} with {}",
                    unary.calculus, unary.relations, composition.calculus, composition.relations
                ),
            });
        }
        let n = unary.relations as usize;
        let mut compose = vec![RelationSet::EMPTY; n * n];
        for e in &composition.entries {
            let cell = &mut compose[(e.ab_c as usize - 1) * n + e.bc_d as usize - 1];
            *cell = cell.with(e.ab_d);
        }
        Ok(OperatorTables {
            relations: unary.relations,
            left: unary.left.clone(),
            right: unary.right.clone(),
            inverse: unary.inverse.clone(),
            compose,
        })
    }

    pub fn relations(&self) -> u8 {
        self.relations
    }

    /// Image of one base relation.
    pub fn unary_of(&self, op: UnaryOperator, r: u8) -> RelationSet {
        let table = match op {
            UnaryOperator::Left => &self.left,
            UnaryOperator::Right => &self.right,
            UnaryOperator::Inverse => &self.inverse,
        };
        table[r as usize - 1]
    }

    /// Image of a set: union of the images of its members.
    pub fn unary(&self, op: UnaryOperator, s: RelationSet) -> RelationSet {
        s.iter()
            .fold(RelationSet::EMPTY, |acc, r| acc.union(self.unary_of(op, r)))
    }

    pub fn left(&self, s: RelationSet) -> RelationSet {
        self.unary(UnaryOperator::Left, s)
    }

    pub fn right(&self, s: RelationSet) -> RelationSet {
        self.unary(UnaryOperator::Right, s)
    }

    pub fn inverse(&self, s: RelationSet) -> RelationSet {
        self.unary(UnaryOperator::Inverse, s)
    }

    /// `COMPOSE(AB:C, BC:D) → AB:D` for base relations.
    pub fn compose_base(&self, ab_c: u8, bc_d: u8) -> RelationSet {
        self.compose[(ab_c as usize - 1) * self.relations as usize + bc_d as usize - 1]
    }

    /// `COMPOSE` on sets: union over all member pairs.
    pub fn compose(&self, ab_c: RelationSet, bc_d: RelationSet) -> RelationSet {
        let mut out = RelationSet::EMPTY;
        for r1 in ab_c.iter() {
            for r2 in bc_d.iter() {
                out = out.union(self.compose_base(r1, r2));
            }
        }
        out
    }
}
