//! The convex hull of the landmarks, read from the map (001: "we can also find the convex hull
//! — also a subgraph of the Delaunay"). Sidedness alone decides it: `AB` is a hull edge iff
//! every other landmark lies on one side of the line `AB`, which a relation `AB:C` says when
//! all its states lie left of `AB`, or all right (seed digest A.1).

use crate::calculus::{Calculus, RelationSet};
use crate::edc;
use crate::map::{Hypergraph, LandmarkId};

/// Hull edges of a map: those the map proves, and those it still allows.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Hull {
    /// Pairs `(a, b)` (in the map's landmark order) with every other landmark certainly on one
    /// side of `ab`.
    pub certain: Vec<(LandmarkId, LandmarkId)>,
    /// Pairs that may be hull edges but are not proven: every other landmark may be on one
    /// side.
    pub possible: Vec<(LandmarkId, LandmarkId)>,
}

impl Hull {
    /// Landmarks on a certain hull edge: certainly on the hull.
    pub fn certain_landmarks(&self) -> Vec<LandmarkId> {
        let mut out: Vec<LandmarkId> = self.certain.iter().flat_map(|&(a, b)| [a, b]).collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// The hull of `map`'s landmarks. With fewer than three landmarks every pair is a hull edge.
pub fn convex_hull<C: Calculus>(map: &Hypergraph<C>) -> Hull {
    let (left, right) = sides::<C>();
    let ids = map.landmarks();
    let mut hull = Hull::default();
    for (x, &a) in ids.iter().enumerate() {
        for &b in &ids[x + 1..] {
            let relations: Vec<RelationSet> = ids
                .iter()
                .filter(|&&c| c != a && c != b)
                .map(|&c| map.relation(a, b, c).expect("landmarks of the map"))
                .collect();
            let all = |test: &dyn Fn(RelationSet) -> bool| relations.iter().all(|&r| test(r));
            if all(&|r| r.is_subset(left)) || all(&|r| r.is_subset(right)) {
                hull.certain.push((a, b));
            } else if all(&|r| !r.intersection(left).is_empty())
                || all(&|r| !r.intersection(right).is_empty())
            {
                hull.possible.push((a, b));
            }
        }
    }
    hull
}

/// The relations of calculus `C` that put `C` left of `AB`, and those that put it right.
fn sides<C: Calculus>() -> (RelationSet, RelationSet) {
    let regions = |left: bool| {
        RelationSet::from_relations((1..=edc::REGIONS).filter(|&r| edc::is_left(r) == left))
    };
    (C::from_edc(regions(true)), C::from_edc(regions(false)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edc::Edc;
    use crate::fdc::Fdc;
    use crate::geometry::Point;
    use crate::map::testing::converged;
    use proptest::prelude::*;

    /// Hull edges by geometry: every other point strictly on one side.
    fn true_hull(points: &[Point]) -> Vec<(LandmarkId, LandmarkId)> {
        let side = |a: Point, b: Point, c: Point| {
            ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)).signum()
        };
        let n = points.len();
        let mut out = Vec::new();
        for a in 0..n {
            for b in a + 1..n {
                let sides: Vec<f64> = (0..n)
                    .filter(|&c| c != a && c != b)
                    .map(|c| side(points[a], points[b], points[c]))
                    .collect();
                if sides.iter().all(|&s| s > 0.0) || sides.iter().all(|&s| s < 0.0) {
                    out.push((a as LandmarkId, b as LandmarkId));
                }
            }
        }
        out
    }

    fn field() -> impl Strategy<Value = Vec<Point>> {
        prop::collection::vec((0.0f64..100.0, 0.0f64..100.0), 4..9)
            .prop_map(|xy| xy.into_iter().map(|(x, y)| Point::new(x, y)).collect())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(100))]
        /// Seed digest A.8 test 7: the hull of a converged map is the hull of the true points,
        /// in EDC and in FDC (sidedness is in both).
        #[test]
        fn a_converged_maps_hull_is_the_true_hull(points in field()) {
            prop_assume!(points.iter().enumerate().all(|(i, p)| points[..i].iter().all(|q| q.distance(*p) > 1e-3)));
            let truth = true_hull(&points);
            let edc = convex_hull(&converged::<Edc>(&points));
            prop_assert_eq!(&edc.certain, &truth);
            prop_assert!(edc.possible.is_empty());
            let fdc = convex_hull(&converged::<Fdc>(&points));
            prop_assert_eq!(&fdc.certain, &truth);
        }
    }

    /// A map that knows nothing allows every pair, and proves none.
    #[test]
    fn an_empty_map_proves_no_hull_edge() {
        let mut map = Hypergraph::<Edc>::new();
        map.add_landmarks(&[0, 1, 2, 3]);
        let hull = convex_hull(&map);
        assert!(hull.certain.is_empty());
        assert_eq!(hull.possible.len(), 6);
        assert!(hull.certain_landmarks().is_empty());
    }
}
