//! The Relative Neighborhood Graph estimated from an EDC map (000 §VII-A, Algorithm 2), and its
//! comparison with the RNG of known landmark positions.
//!
//! Landmarks `i`, `j` are RNG neighbours when no third landmark lies in their lune, which is
//! exactly EDC regions {7, 8, 13, 14} of `ij:k` ([`Calculus::lune`]). An edge is pruned as soon as some `k` can only
//! be in the lune; otherwise its cost sums, over all `k`, the fraction of `ij:k`'s open states
//! that lie in the lune, divided by the number of landmarks. Cost 0 means a certain edge.

use crate::calculus::Calculus;
use crate::geometry::Point;
use crate::map::{Hypergraph, LandmarkId};
use rayon::prelude::*;

/// A candidate RNG edge that survived pruning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RngEdge {
    pub a: LandmarkId,
    pub b: LandmarkId,
    /// Algorithm 2's `w_ab`: 0 for an edge the map proves, up to 1.
    pub cost: f64,
}

/// The RNG estimate of one map.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RngEstimate {
    /// Surviving edges with `a < b` in insertion order of the map's landmarks.
    pub edges: Vec<RngEdge>,
    /// Pairs ruled out because a third landmark is certainly in their lune.
    pub pruned: usize,
}

impl RngEstimate {
    /// `Σ w_ij` (000 §VIII-A, third metric).
    pub fn total_cost(&self) -> f64 {
        self.edges.iter().map(|e| e.cost).sum()
    }

    /// Edges of cost 0: RNG edges whatever the remaining ambiguity.
    pub fn certain(&self) -> impl Iterator<Item = &RngEdge> {
        self.edges.iter().filter(|e| e.cost == 0.0)
    }
}

/// Algorithm 2 of 000 over every pair of landmarks in `map`; `None` for a calculus without a
/// lune (FDC cannot tell distances apart).
pub fn estimate<C: Calculus>(map: &Hypergraph<C>) -> Option<RngEstimate> {
    let lune = C::lune()?;
    let ids = map.landmarks();
    let n = ids.len();
    // Pairs are independent: each row of pairs (x, y > x) in parallel, by position in the map
    // (no id lookups), rows in order.
    let rows: Vec<(Vec<RngEdge>, usize)> = (0..n)
        .into_par_iter()
        .map(|x| {
            let mut edges = Vec::new();
            let mut pruned = 0;
            'pair: for y in x + 1..n {
                let mut cost = 0.0;
                for z in (0..n).filter(|&z| z != x && z != y) {
                    let open = map.relation_at(x, y, z);
                    let conflicts = open.intersection(lune).len();
                    if conflicts == open.len() {
                        pruned += 1;
                        continue 'pair;
                    }
                    cost += conflicts as f64 / open.len() as f64;
                }
                edges.push(RngEdge {
                    a: ids[x],
                    b: ids[y],
                    cost: cost / n as f64,
                });
            }
            (edges, pruned)
        })
        .collect();
    let mut out = RngEstimate::default();
    for (edges, pruned) in rows {
        out.edges.extend(edges);
        out.pruned += pruned;
    }
    Some(out)
}

/// The RNG of `points` (landmark `i` at `points[i]`) as an estimate whose every edge is
/// certain: what a converged map's estimate would be.
pub fn true_estimate(points: &[Point]) -> RngEstimate {
    RngEstimate {
        edges: true_rng(points)
            .into_iter()
            .map(|(a, b)| RngEdge {
                a: a as LandmarkId,
                b: b as LandmarkId,
                cost: 0.0,
            })
            .collect(),
        pruned: 0,
    }
}

/// The RNG of points: `i`–`j` unless some `k` is nearer to both than they are to each other.
pub fn true_rng(points: &[Point]) -> Vec<(usize, usize)> {
    let n = points.len();
    let mut edges = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            let d = squared_distance(points[i], points[j]);
            let blocked = (0..n).any(|k| {
                k != i
                    && k != j
                    && squared_distance(points[k], points[i]) < d
                    && squared_distance(points[k], points[j]) < d
            });
            if !blocked {
                edges.push((i, j));
            }
        }
    }
    edges
}

fn squared_distance(p: Point, q: Point) -> f64 {
    (p.x - q.x).powi(2) + (p.y - q.y).powi(2)
}

/// How an estimate compares with the true RNG of the same landmarks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RngComparison {
    /// True RNG edges among the map's landmarks.
    pub true_edges: usize,
    /// Certain (cost 0) edges that are true / false (a false one means an unsound map).
    pub certain_true: usize,
    pub certain_false: usize,
    /// Uncertain edges that are true / false.
    pub uncertain_true: usize,
    pub uncertain_false: usize,
    /// True edges that were pruned (an unsound map).
    pub pruned_true: usize,
}

impl RngComparison {
    /// Fraction of surviving edges that are true edges.
    pub fn precision(&self) -> f64 {
        let kept =
            self.certain_true + self.certain_false + self.uncertain_true + self.uncertain_false;
        if kept == 0 {
            1.0
        } else {
            (self.certain_true + self.uncertain_true) as f64 / kept as f64
        }
    }

    /// Fraction of true edges that survived.
    pub fn recall(&self) -> f64 {
        if self.true_edges == 0 {
            1.0
        } else {
            (self.certain_true + self.uncertain_true) as f64 / self.true_edges as f64
        }
    }
}

/// Compares `estimate` with the RNG of the map's landmarks at `position(id)`.
pub fn compare<C: Calculus>(
    map: &Hypergraph<C>,
    estimate: &RngEstimate,
    position: impl Fn(LandmarkId) -> Point,
) -> RngComparison {
    let ids = map.landmarks();
    let points: Vec<Point> = ids.iter().map(|&id| position(id)).collect();
    let truth: std::collections::HashSet<(LandmarkId, LandmarkId)> = true_rng(&points)
        .into_iter()
        .map(|(i, j)| ordered(ids[i], ids[j]))
        .collect();
    let mut out = RngComparison {
        true_edges: truth.len(),
        ..RngComparison::default()
    };
    let mut surviving_true = 0;
    for e in &estimate.edges {
        let is_true = truth.contains(&ordered(e.a, e.b));
        surviving_true += usize::from(is_true);
        match (e.cost == 0.0, is_true) {
            (true, true) => out.certain_true += 1,
            (true, false) => out.certain_false += 1,
            (false, true) => out.uncertain_true += 1,
            (false, false) => out.uncertain_false += 1,
        }
    }
    out.pruned_true = truth.len() - surviving_true;
    out
}

fn ordered(a: LandmarkId, b: LandmarkId) -> (LandmarkId, LandmarkId) {
    (a.min(b), a.max(b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edc::Edc;
    use crate::map::testing::converged;
    use crate::map::Observation;

    #[test]
    fn exact_map_gives_the_true_rng_with_zero_cost() {
        let points = [
            Point::new(0.0, 0.0),
            Point::new(4.0, 0.3),
            Point::new(2.1, 0.5),
            Point::new(1.0, 3.7),
            Point::new(5.2, 4.1),
        ];
        let map = converged::<Edc>(&points);
        let est = estimate(&map).expect("EDC has a lune");
        assert!(est.edges.iter().all(|e| e.cost == 0.0));
        let cmp = compare(&map, &est, |id| points[id as usize]);
        assert_eq!(cmp.true_edges, est.edges.len());
        assert_eq!((cmp.precision(), cmp.recall()), (1.0, 1.0));
        assert_eq!(est.pruned + est.edges.len(), 10);
    }

    #[test]
    fn empty_map_keeps_every_pair_with_cost() {
        let mut map = Hypergraph::<Edc>::new();
        map.fuse(&[Observation::new(0, 1, 2, Edc::universe())])
            .expect("no information is consistent");
        let est = estimate(&map).expect("EDC has a lune");
        assert_eq!(est.edges.len(), 3);
        assert!(est.edges.iter().all(|e| (e.cost - 0.2 / 3.0).abs() < 1e-12));
    }
}
