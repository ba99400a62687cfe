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
///
/// A third landmark the map knows nothing about adds the universe's share of lune states to a
/// pair's cost, so only the edges the map constrains ([`Hypergraph::constrained`]) are
/// visited: O(n² + constrained edges) instead of every pair against every third, which on a
/// long drive was most of each station's time (the 1 000-rock drive: 202 of 405 s).
pub fn estimate<C: Calculus>(map: &Hypergraph<C>) -> Option<RngEstimate> {
    let lune = C::lune()?;
    let ids = map.landmarks();
    let n = ids.len();
    let universe = C::universe();
    let unknown = universe.intersection(lune).len() as f64 / universe.len() as f64;
    // Per pair `x < y`, at `y (y − 1) / 2 + x`: the thirds the map constrains, their summed
    // lune shares, and whether one of them can only be in the lune.
    let pair = |x: usize, y: usize| y * (y - 1) / 2 + x;
    let pairs = n * n.saturating_sub(1) / 2;
    let mut known = vec![0usize; pairs];
    let mut share = vec![0.0f64; pairs];
    let mut in_lune = vec![false; pairs];
    for [i, j, k] in map.constrained() {
        for (x, y, z) in [(i, j, k), (i, k, j), (j, k, i)] {
            let open = map.relation_at(x, y, z);
            let conflicts = open.intersection(lune).len();
            let p = pair(x, y);
            known[p] += 1;
            if conflicts == open.len() {
                in_lune[p] = true;
            } else {
                share[p] += conflicts as f64 / open.len() as f64;
            }
        }
    }
    let mut out = RngEstimate::default();
    for x in 0..n {
        for y in x + 1..n {
            let p = pair(x, y);
            if in_lune[p] {
                out.pruned += 1;
                continue;
            }
            let unconstrained = (n - 2 - known[p]) as f64;
            out.edges.push(RngEdge {
                a: ids[x],
                b: ids[y],
                cost: (share[p] + unconstrained * unknown) / n as f64,
            });
        }
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

    /// Algorithm 2 as written: every pair against every third landmark.
    fn every_pair_against_every_third(map: &Hypergraph<Edc>) -> RngEstimate {
        let lune = Edc::lune().expect("EDC has a lune");
        let (ids, n) = (map.landmarks(), map.len());
        let mut out = RngEstimate::default();
        for x in 0..n {
            'pair: for y in x + 1..n {
                let mut cost = 0.0;
                for z in (0..n).filter(|&z| z != x && z != y) {
                    let open = map.relation_at(x, y, z);
                    let conflicts = open.intersection(lune).len();
                    if conflicts == open.len() {
                        out.pruned += 1;
                        continue 'pair;
                    }
                    cost += conflicts as f64 / open.len() as f64;
                }
                out.edges.push(RngEdge {
                    a: ids[x],
                    b: ids[y],
                    cost: cost / n as f64,
                });
            }
        }
        out
    }

    proptest::proptest! {
        /// Visiting only the constrained edges gives Algorithm 2's estimate: maps of 4–9
        /// landmarks seen from 1–3 stations with loose bearings, where most triples stay open.
        #[test]
        fn the_estimate_over_constrained_edges_is_algorithm_2(
            rocks in proptest::collection::vec((-10.0f64..10.0, -10.0f64..10.0), 4..10),
            stations in proptest::collection::vec((-12.0f64..12.0, -12.0f64..12.0), 1..4),
            seen in proptest::collection::vec(proptest::bool::weighted(0.7), 9),
        ) {
            use crate::map::Sighting;
            use crate::measurement::{Bearing, RangeOrder, StationView};
            let rocks: Vec<Point> = rocks.iter().map(|&(x, y)| Point::new(x, y)).collect();
            let mut map = Hypergraph::<Edc>::new();
            for (s, &(x, y)) in stations.iter().enumerate() {
                let station = Point::new(x, y);
                // Each station sees its own subset, so that some triples are never co-observed.
                let ids: Vec<usize> = (0..rocks.len())
                    .filter(|&r| seen[(r + 3 * s) % seen.len()])
                    .filter(|&r| rocks[r].distance(station) > 0.5)
                    .collect();
                if ids.len() < 3 {
                    continue;
                }
                let view = StationView::new(
                    ids.iter()
                        .map(|&r| Bearing {
                            angle: (rocks[r].y - y).atan2(rocks[r].x - x),
                            uncertainty: 0.05,
                        })
                        .collect(),
                    RangeOrder::unordered(ids.len()),
                )
                .expect("a valid view");
                let sightings: Vec<Sighting> = ids
                    .iter()
                    .enumerate()
                    .map(|(k, &r)| Sighting::new(k, r as u32))
                    .collect();
                // Views of nearly collinear rocks may contradict: such a station is left out.
                let _ = map.fuse(&map.observations(&view, &sightings));
            }
            let brute: Vec<[u32; 3]> = map
                .triples()
                .filter(|(_, _, _, r)| r.iter().any(|s| *s != Edc::universe()))
                .map(|(a, b, c, _)| [a, b, c])
                .collect();
            let ids = map.landmarks();
            let constrained: Vec<[u32; 3]> =
                map.constrained().iter().map(|t| t.map(|i| ids[i])).collect();
            proptest::prop_assert_eq!(&constrained, &brute);
            let reread = Hypergraph::<Edc>::from_json(&map.to_json()).expect("a map it wrote");
            let ids = reread.landmarks();
            let constrained: Vec<[u32; 3]> =
                reread.constrained().iter().map(|t| t.map(|i| ids[i])).collect();
            proptest::prop_assert_eq!(constrained, brute);
            let fast = estimate(&map).expect("EDC has a lune");
            let slow = every_pair_against_every_third(&map);
            proptest::prop_assert_eq!(fast.pruned, slow.pruned);
            proptest::prop_assert_eq!(fast.edges.len(), slow.edges.len());
            for (f, s) in fast.edges.iter().zip(&slow.edges) {
                proptest::prop_assert_eq!((f.a, f.b), (s.a, s.b));
                proptest::prop_assert!((f.cost - s.cost).abs() < 1e-12);
                proptest::prop_assert_eq!(f.cost == 0.0, s.cost == 0.0);
            }
            let open: usize = map.triples().map(|(_, _, _, r)| r.iter().map(|s| s.len()).sum::<usize>()).sum();
            proptest::prop_assert_eq!(map.open_states(), open);
        }
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
