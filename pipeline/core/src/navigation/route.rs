//! Landmark routes over the RNG estimate (000 §VII-B step 3).
//!
//! The rover drives landmark to landmark along RNG edges. On a converged RNG the route is the
//! one of fewest hops (Dijkstra). On an unconverged one, an edge the map may yet prune (its
//! Algorithm 2 cost `w_ij` above 0) may also be a false edge, whose far landmark is not visible
//! from the near one's cell; each edge then costs `1 + λ·w_ij`, so that a route of certain
//! edges is preferred to a shorter one through doubtful edges. 000 calls the RNG costs "a
//! heuristic to be added to fixed separation-based distance costs"; added to the edge cost,
//! they change the cost, they are no A* heuristic (seed digest A.6). `w_ij` is already divided
//! by the number of landmarks, so `λ` is on the scale of one hop.

use crate::map::LandmarkId;
use crate::neighborhood::RngEstimate;
use petgraph::algo::astar;
use petgraph::graph::{EdgeIndex, NodeIndex, UnGraph};
use petgraph::visit::{EdgeFiltered, EdgeRef};
use std::collections::HashMap;
use thiserror::Error;

/// How an RNG edge is charged: `1 + lambda · w_ij`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RouteCost {
    pub lambda: f64,
}

impl Default for RouteCost {
    /// `λ = 1` (seed digest A.6).
    fn default() -> RouteCost {
        RouteCost { lambda: 1.0 }
    }
}

impl RouteCost {
    fn of(&self, w: f64) -> f64 {
        1.0 + self.lambda * w
    }
}

/// A landmark route: the landmarks to drive to, start first, and what it costs.
#[derive(Clone, Debug, PartialEq)]
pub struct Route {
    pub landmarks: Vec<LandmarkId>,
    /// Σ `1 + λ·w` over the route's edges.
    pub cost: f64,
    /// Edges of the route the map does not prove (`w > 0`).
    pub uncertain_edges: usize,
}

impl Route {
    /// Edges driven.
    pub fn hops(&self) -> usize {
        self.landmarks.len().saturating_sub(1)
    }
}

/// Why no route was found.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum PlanError {
    #[error("landmark {0} is not in the map")]
    UnknownLandmark(LandmarkId),
    #[error("no route from landmark {from} to landmark {to}: the RNG estimate does not connect them (the map holds a wrong relation, or the landmarks were never related)")]
    Unreachable { from: LandmarkId, to: LandmarkId },
}

/// The RNG estimate of a map as a graph to plan on: one node per landmark, one edge per
/// surviving RNG edge with its Algorithm 2 cost. Pruned pairs are no edges, so no route uses
/// them.
#[derive(Clone, Debug)]
pub struct RouteGraph {
    graph: UnGraph<LandmarkId, f64>,
    nodes: HashMap<LandmarkId, NodeIndex>,
}

impl RouteGraph {
    /// The graph of `landmarks` (the map's, so that a landmark without an edge is known but
    /// unreachable) and the edges of `rng`.
    pub fn new(landmarks: &[LandmarkId], rng: &RngEstimate) -> RouteGraph {
        let mut graph = UnGraph::new_undirected();
        let nodes: HashMap<LandmarkId, NodeIndex> =
            landmarks.iter().map(|&l| (l, graph.add_node(l))).collect();
        for edge in &rng.edges {
            if let (Some(&a), Some(&b)) = (nodes.get(&edge.a), nodes.get(&edge.b)) {
                graph.add_edge(a, b, edge.cost);
            }
        }
        RouteGraph { graph, nodes }
    }

    /// The RNG neighbours of `landmark` with their edge costs `w`.
    pub fn neighbours(&self, landmark: LandmarkId) -> Vec<(LandmarkId, f64)> {
        self.nodes.get(&landmark).map_or_else(Vec::new, |&n| {
            self.graph
                .edges(n)
                .map(|e| (self.graph[e.target()], *e.weight()))
                .collect()
        })
    }

    /// The cheapest route from `from` to `to`.
    pub fn plan(
        &self,
        from: LandmarkId,
        to: LandmarkId,
        cost: RouteCost,
    ) -> Result<Route, PlanError> {
        let (start, goal) = (self.node(from)?, self.node(to)?);
        self.cheapest(start, goal, cost, &|_| true)
            .ok_or(PlanError::Unreachable { from, to })
    }

    /// The cheapest route from `from` to `to` through none of `avoid` (a landmark lost from
    /// view on the way: its leg cannot be driven).
    pub fn plan_avoiding(
        &self,
        from: LandmarkId,
        to: LandmarkId,
        cost: RouteCost,
        avoid: &[LandmarkId],
    ) -> Result<Route, PlanError> {
        let (start, goal) = (self.node(from)?, self.node(to)?);
        let closed: Vec<NodeIndex> = avoid
            .iter()
            .filter(|&&l| l != from && l != to)
            .filter_map(|l| self.nodes.get(l).copied())
            .collect();
        let open = |e: EdgeIndex| {
            let (a, b) = self.graph.edge_endpoints(e).expect("edge of the graph");
            !closed.contains(&a) && !closed.contains(&b)
        };
        self.cheapest(start, goal, cost, &open)
            .ok_or(PlanError::Unreachable { from, to })
    }

    /// Up to `k` cheapest loopless routes from `from` to `to`, cheapest first (Yen's
    /// algorithm): alternatives for when a leg fails.
    pub fn alternatives(
        &self,
        from: LandmarkId,
        to: LandmarkId,
        cost: RouteCost,
        k: usize,
    ) -> Result<Vec<Route>, PlanError> {
        let best = self.plan(from, to, cost)?;
        let goal = self.node(to)?;
        let mut found = vec![best];
        let mut candidates: Vec<Route> = Vec::new();
        while found.len() < k {
            let last = found.last().expect("one route at least").clone();
            for spur in 0..last.landmarks.len() - 1 {
                let root = &last.landmarks[..=spur];
                // Edges leaving the root that earlier routes with the same root took, and the
                // root's landmarks before the spur, are closed to the spur route.
                let closed_edges: Vec<EdgeIndex> = found
                    .iter()
                    .filter(|r| r.landmarks.len() > spur + 1 && r.landmarks[..=spur] == *root)
                    .filter_map(|r| self.edge(r.landmarks[spur], r.landmarks[spur + 1]))
                    .collect();
                let closed_nodes: Vec<NodeIndex> =
                    root[..spur].iter().map(|&l| self.nodes[&l]).collect();
                let open = |e: EdgeIndex| {
                    let (a, b) = self.graph.edge_endpoints(e).expect("edge of the graph");
                    !closed_edges.contains(&e)
                        && !closed_nodes.contains(&a)
                        && !closed_nodes.contains(&b)
                };
                let Some(tail) = self.cheapest(self.nodes[&root[spur]], goal, cost, &open) else {
                    continue;
                };
                let mut landmarks = root[..spur].to_vec();
                landmarks.extend(&tail.landmarks);
                let route = self.route(landmarks, cost);
                if !found.contains(&route) && !candidates.contains(&route) {
                    candidates.push(route);
                }
            }
            let Some(next) = (0..candidates.len()).min_by(|&a, &b| {
                candidates[a]
                    .cost
                    .total_cmp(&candidates[b].cost)
                    .then(candidates[a].landmarks.cmp(&candidates[b].landmarks))
            }) else {
                break;
            };
            found.push(candidates.swap_remove(next));
        }
        Ok(found)
    }

    fn node(&self, landmark: LandmarkId) -> Result<NodeIndex, PlanError> {
        self.nodes
            .get(&landmark)
            .copied()
            .ok_or(PlanError::UnknownLandmark(landmark))
    }

    fn edge(&self, a: LandmarkId, b: LandmarkId) -> Option<EdgeIndex> {
        self.graph.find_edge(self.nodes[&a], self.nodes[&b])
    }

    /// Dijkstra (A* with a zero heuristic) over the edges `open` lets through.
    fn cheapest(
        &self,
        start: NodeIndex,
        goal: NodeIndex,
        cost: RouteCost,
        open: &dyn Fn(EdgeIndex) -> bool,
    ) -> Option<Route> {
        let graph = EdgeFiltered::from_fn(&self.graph, |e| open(e.id()));
        let (_, path) = astar(
            &graph,
            start,
            |n| n == goal,
            |e| cost.of(*e.weight()),
            |_| 0.0,
        )?;
        Some(self.route(path.iter().map(|&n| self.graph[n]).collect(), cost))
    }

    /// `landmarks` as a route, its cost summed edge by edge.
    fn route(&self, landmarks: Vec<LandmarkId>, cost: RouteCost) -> Route {
        let weights: Vec<f64> = landmarks
            .windows(2)
            .map(|pair| {
                let e = self.edge(pair[0], pair[1]).expect("route along edges");
                self.graph[e]
            })
            .collect();
        Route {
            cost: weights.iter().map(|&w| cost.of(w)).sum(),
            uncertain_edges: weights.iter().filter(|&&w| w > 0.0).count(),
            landmarks,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighborhood::RngEdge;
    use proptest::prelude::*;

    fn graph(n: u32, edges: &[(u32, u32, f64)]) -> RouteGraph {
        let rng = RngEstimate {
            edges: edges
                .iter()
                .map(|&(a, b, cost)| RngEdge { a, b, cost })
                .collect(),
            pruned: 0,
        };
        RouteGraph::new(&(0..n).collect::<Vec<_>>(), &rng)
    }

    /// Six landmarks, worked by hand: 0–1–2–5 and 0–3–4–5 are both three hops; 0–4 is one
    /// uncertain shortcut.
    #[test]
    fn the_route_of_fewest_hops_and_of_least_doubt() {
        let g = graph(
            6,
            &[
                (0, 1, 0.0),
                (1, 2, 0.0),
                (2, 5, 0.0),
                (0, 3, 0.0),
                (3, 4, 0.0),
                (4, 5, 0.0),
                (0, 4, 0.9),
            ],
        );
        let hops = g.plan(0, 5, RouteCost { lambda: 0.0 }).unwrap();
        assert_eq!(hops.landmarks, [0, 4, 5]);
        assert_eq!(hops.uncertain_edges, 1);
        // With λ = 2 the shortcut route costs 1 + 1.8 + 1, more than three certain hops.
        let careful = g.plan(0, 5, RouteCost { lambda: 2.0 }).unwrap();
        assert_eq!(careful.hops(), 3);
        assert_eq!(careful.uncertain_edges, 0);
        assert!((careful.cost - 3.0).abs() < 1e-12);
    }

    /// Seed digest A.8 test 1: an edge of cost 1 is avoided when two certain edges go round it.
    #[test]
    fn a_doubtful_edge_is_avoided_for_two_certain_ones() {
        let g = graph(3, &[(0, 2, 1.0), (0, 1, 0.0), (1, 2, 0.0)]);
        assert_eq!(
            g.plan(0, 2, RouteCost { lambda: 1.5 }).unwrap().landmarks,
            [0, 1, 2]
        );
        assert_eq!(
            g.plan(0, 2, RouteCost { lambda: 0.5 }).unwrap().landmarks,
            [0, 2]
        );
    }

    #[test]
    fn unknown_and_unreachable_landmarks_are_errors() {
        let g = graph(4, &[(0, 1, 0.0), (2, 3, 0.0)]);
        assert_eq!(
            g.plan(0, 9, RouteCost::default()),
            Err(PlanError::UnknownLandmark(9))
        );
        assert_eq!(
            g.plan(0, 3, RouteCost::default()),
            Err(PlanError::Unreachable { from: 0, to: 3 })
        );
        assert_eq!(g.plan(2, 2, RouteCost::default()).unwrap().landmarks, [2]);
    }

    /// Every loopless path from `from` to `to`, by exhaustive search, with its cost.
    fn all_paths(
        n: u32,
        edges: &[(u32, u32, f64)],
        from: u32,
        to: u32,
        cost: RouteCost,
    ) -> Vec<(f64, Vec<u32>)> {
        fn extend(
            path: &mut Vec<u32>,
            to: u32,
            adjacent: &[Vec<(u32, f64)>],
            cost: RouteCost,
            total: f64,
            out: &mut Vec<(f64, Vec<u32>)>,
        ) {
            let here = *path.last().unwrap();
            if here == to {
                out.push((total, path.clone()));
                return;
            }
            for &(next, w) in &adjacent[here as usize] {
                if !path.contains(&next) {
                    path.push(next);
                    extend(path, to, adjacent, cost, total + cost.of(w), out);
                    path.pop();
                }
            }
        }
        let mut adjacent = vec![Vec::new(); n as usize];
        for &(a, b, w) in edges {
            adjacent[a as usize].push((b, w));
            adjacent[b as usize].push((a, w));
        }
        let mut out = Vec::new();
        extend(&mut vec![from], to, &adjacent, cost, 0.0, &mut out);
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        out
    }

    fn small_graph() -> impl Strategy<Value = (u32, Vec<(u32, u32, f64)>)> {
        (3u32..8).prop_flat_map(|n| {
            let pairs: Vec<(u32, u32)> = (0..n)
                .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
                .collect();
            let count = pairs.len();
            (
                Just(n),
                prop::collection::vec((any::<bool>(), 0.0f64..1.0), count).prop_map(
                    move |choice| {
                        pairs
                            .iter()
                            .zip(choice)
                            .filter(|(_, (keep, _))| *keep)
                            .map(|(&(a, b), (_, w))| (a, b, if w < 0.3 { 0.0 } else { w }))
                            .collect()
                    },
                ),
            )
        })
    }

    proptest! {
        /// The planner's cost is the least over every loopless path, and its `k` alternatives
        /// are the `k` cheapest paths (costs equal to brute force's, in order, all distinct).
        #[test]
        fn routes_match_brute_force((n, edges) in small_graph(), lambda in 0.0f64..3.0) {
            let g = graph(n, &edges);
            let cost = RouteCost { lambda };
            let paths = all_paths(n, &edges, 0, n - 1, cost);
            match g.plan(0, n - 1, cost) {
                Err(PlanError::Unreachable { .. }) => prop_assert!(paths.is_empty()),
                Err(e) => prop_assert!(false, "{e}"),
                Ok(route) => {
                    prop_assert!((route.cost - paths[0].0).abs() < 1e-9);
                    let k = 4;
                    let routes = g.alternatives(0, n - 1, cost, k).unwrap();
                    prop_assert_eq!(routes.len(), k.min(paths.len()));
                    for (route, path) in routes.iter().zip(&paths) {
                        prop_assert!((route.cost - path.0).abs() < 1e-9);
                        prop_assert!(paths.iter().any(|p| p.1 == route.landmarks));
                    }
                    for (i, a) in routes.iter().enumerate() {
                        prop_assert!(routes[i + 1..].iter().all(|b| b.landmarks != a.landmarks));
                    }
                }
            }
        }
    }
}
