//! Maps for the crate's tests.

use super::{Hypergraph, Observation};
use crate::calculus::{Calculus, RelationSet};
use crate::geometry::Point;

/// The map that knows every triple's true relation among `points` (landmark `i` at
/// `points[i]`, in general position).
pub(crate) fn converged<C: Calculus>(points: &[Point]) -> Hypergraph<C> {
    let n = points.len() as u32;
    let mut observations = Vec::new();
    for a in 0..n {
        for b in 0..n {
            for c in 0..n {
                if a != b && b != c && a != c {
                    let r = C::classify(points[a as usize], points[b as usize], points[c as usize])
                        .expect("points in general position");
                    observations.push(Observation::new(a, b, c, RelationSet::single(r)));
                }
            }
        }
    }
    let mut map = Hypergraph::new();
    map.fuse(&observations).expect("true relations agree");
    map
}
