//! Route criteria of 004 §5.3 and §7.2: the shortest route (least distance `D = Σ d`), the
//! most reliable (least unreliability `U = Σ −ln R`), and the D/R compromise (least
//! `D / R = D·e^U`, i.e. least `ln D + U`).
//!
//! `ln D + U` is not a sum over legs, so Dijkstra cannot minimize it; 004 says Dijkstra was used
//! and may have summed `ln d + u` per leg. All three criteria are read here from one exact
//! bi-criteria label-setting search, which keeps every Pareto-optimal `(D, U)` label per node
//! (seed digest B.5): the shortest route is the front's least `D`, the most reliable its least
//! `U`, the compromise its least `ln D + U`. The per-leg sum is offered beside it as
//! [`per_leg_compromise`].

use petgraph::algo::{astar, tarjan_scc};
use petgraph::graph::{DiGraph, NodeIndex};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A directed leg between nodes `from` and `to` of a graph with distance `d > 0` and
/// unreliability `u ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc {
    pub from: usize,
    pub to: usize,
    pub d: f64,
    pub u: f64,
}

/// A route: the arcs driven (indices into the arc list), nodes visited, and its totals.
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    pub arcs: Vec<usize>,
    pub nodes: Vec<usize>,
    pub d: f64,
    pub u: f64,
}

impl Path {
    /// `R = e^−U`: the chance that every leg is driven to the intended landmark.
    pub fn reliability(&self) -> f64 {
        (-self.u).exp()
    }

    /// `D / R = D·e^U` (004 §5.3).
    pub fn d_over_r(&self) -> f64 {
        self.d * self.u.exp()
    }
}

/// Which route to take.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Criterion {
    /// Least `D` (ties: least `U`).
    Shortest,
    /// Least `U` (ties: least `D`).
    Reliable,
    /// Least `D·e^U`.
    Compromise,
}

/// The three routes from `from` to `to`; `None` when `to` cannot be reached.
#[derive(Clone, Debug, PartialEq)]
pub struct Routes {
    pub shortest: Path,
    pub reliable: Path,
    pub compromise: Path,
    /// Every Pareto-optimal `(D, U)` at the goal, by increasing `D`.
    pub front: Vec<(f64, f64)>,
}

impl Routes {
    pub fn get(&self, criterion: Criterion) -> &Path {
        match criterion {
            Criterion::Shortest => &self.shortest,
            Criterion::Reliable => &self.reliable,
            Criterion::Compromise => &self.compromise,
        }
    }
}

/// A label of the search: totals at `node`, reached over `arc` from label `parent`.
struct Label {
    node: usize,
    d: f64,
    u: f64,
    parent: Option<(usize, usize)>,
}

/// Queue entry ordered so that the heap pops the least `(d, u)` first.
struct Queued {
    d: f64,
    u: f64,
    label: usize,
}

impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Queued {}
impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .d
            .total_cmp(&self.d)
            .then(other.u.total_cmp(&self.u))
            .then(other.label.cmp(&self.label))
    }
}

/// The shortest, most reliable and compromise routes over `arcs` among `nodes` nodes.
/// From a node to itself every route is empty.
///
/// # Panics
/// If an arc names a node `≥ nodes`, or has `d ≤ 0` or `u < 0` (the search needs positive
/// distances to end; the callers build arcs from ranks ≥ 1 and reliabilities ≤ 1).
pub fn routes(arcs: &[Arc], nodes: usize, from: usize, to: usize) -> Option<Routes> {
    assert!(from < nodes && to < nodes, "route endpoints are nodes");
    for a in arcs {
        assert!(a.from < nodes && a.to < nodes, "arc endpoints are nodes");
        assert!(a.d > 0.0 && a.u >= 0.0, "arcs have d > 0, u ≥ 0");
    }
    let mut outgoing = vec![Vec::new(); nodes];
    for (i, a) in arcs.iter().enumerate() {
        outgoing[a.from].push(i);
    }
    let mut labels = vec![Label {
        node: from,
        d: 0.0,
        u: 0.0,
        parent: None,
    }];
    // The permanent labels of each node, by increasing d (so decreasing u).
    let mut permanent: Vec<Vec<usize>> = vec![Vec::new(); nodes];
    let mut queue = BinaryHeap::from([Queued {
        d: 0.0,
        u: 0.0,
        label: 0,
    }]);
    // Labels pop in increasing (d, u): one is dominated iff a permanent label of its node has
    // u no larger.
    let dominated = |permanent: &[usize], labels: &[Label], u: f64| {
        permanent.last().is_some_and(|&p| labels[p].u <= u)
    };
    while let Some(Queued { label, .. }) = queue.pop() {
        let node = labels[label].node;
        if dominated(&permanent[node], &labels, labels[label].u) {
            continue;
        }
        permanent[node].push(label);
        if node == to {
            continue;
        }
        for &i in &outgoing[node] {
            let a = arcs[i];
            let (d, u) = (labels[label].d + a.d, labels[label].u + a.u);
            if !dominated(&permanent[a.to], &labels, u) {
                labels.push(Label {
                    node: a.to,
                    d,
                    u,
                    parent: Some((label, i)),
                });
                queue.push(Queued {
                    d,
                    u,
                    label: labels.len() - 1,
                });
            }
        }
    }
    let front = &permanent[to];
    if front.is_empty() {
        return None;
    }
    let path = |label: usize| {
        let mut arcs_driven = Vec::new();
        let mut nodes_visited = vec![labels[label].node];
        let mut at = label;
        while let Some((parent, arc)) = labels[at].parent {
            arcs_driven.push(arc);
            nodes_visited.push(labels[parent].node);
            at = parent;
        }
        arcs_driven.reverse();
        nodes_visited.reverse();
        Path {
            arcs: arcs_driven,
            nodes: nodes_visited,
            d: labels[label].d,
            u: labels[label].u,
        }
    };
    let compromise_cost = |&l: &usize| {
        if from == to {
            0.0
        } else {
            labels[l].d.ln() + labels[l].u
        }
    };
    let compromise = front
        .iter()
        .min_by(|a, b| compromise_cost(a).total_cmp(&compromise_cost(b)))
        .copied()
        .expect("front is not empty");
    Some(Routes {
        shortest: path(front[0]),
        reliable: path(*front.last().expect("front is not empty")),
        compromise: path(compromise),
        front: front.iter().map(|&l| (labels[l].d, labels[l].u)).collect(),
    })
}

/// 004's compromise as the paper may have computed it: Dijkstra over the per-leg cost
/// `ln d + u` (seed digest B.5). `None` when `to` cannot be reached; arcs with `d < 1` are
/// charged `u` alone, as a negative `ln d` would break Dijkstra.
pub fn per_leg_compromise(arcs: &[Arc], nodes: usize, from: usize, to: usize) -> Option<Path> {
    let mut graph = DiGraph::<(), usize>::new();
    let ids: Vec<NodeIndex> = (0..nodes).map(|_| graph.add_node(())).collect();
    for (i, a) in arcs.iter().enumerate() {
        graph.add_edge(ids[a.from], ids[a.to], i);
    }
    let cost = |i: usize| arcs[i].d.ln().max(0.0) + arcs[i].u;
    let (_, visited) = astar(
        &graph,
        ids[from],
        |n| n == ids[to],
        |e| cost(*e.weight()),
        |_| 0.0,
    )?;
    // The cheapest arc between consecutive nodes (parallel arcs may differ).
    let chosen: Vec<usize> = visited
        .windows(2)
        .map(|w| {
            (0..arcs.len())
                .filter(|&i| ids[arcs[i].from] == w[0] && ids[arcs[i].to] == w[1])
                .min_by(|&a, &b| cost(a).total_cmp(&cost(b)))
                .expect("astar walks arcs")
        })
        .collect();
    Some(Path {
        d: chosen.iter().map(|&i| arcs[i].d).sum(),
        u: chosen.iter().map(|&i| arcs[i].u).sum(),
        nodes: visited.iter().map(|n| n.index()).collect(),
        arcs: chosen,
    })
}

/// The strongly connected components of the leg graph (004 §4.4 measures connectivity by
/// them): nodes that can all reach one another, each component sorted.
pub fn strongly_connected(arcs: &[Arc], nodes: usize) -> Vec<Vec<usize>> {
    let mut graph = DiGraph::<(), ()>::new();
    let ids: Vec<NodeIndex> = (0..nodes).map(|_| graph.add_node(())).collect();
    for a in arcs {
        graph.add_edge(ids[a.from], ids[a.to], ());
    }
    let mut components: Vec<Vec<usize>> = tarjan_scc(&graph)
        .into_iter()
        .map(|c| {
            let mut c: Vec<usize> = c.into_iter().map(|n| n.index()).collect();
            c.sort_unstable();
            c
        })
        .collect();
    components.sort();
    components
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// 004 Table 2 (Fig. 13): nine objects a..i, rows = from (seed digest B.7).
    fn table_2() -> Vec<Arc> {
        let rows = [
            ("ab", 40.31),
            ("ba", 40.31),
            ("bc", 38.60),
            ("cb", 38.60),
            ("cf", 52.35),
            ("cg", 59.55),
            ("ch", 132.52),
            ("ci", 159.93),
            ("dc", 34.13),
            ("de", 16.76),
            ("df", 35.06),
            ("ec", 34.67),
            ("ed", 16.76),
            ("ef", 20.25),
            ("eh", 132.52),
            ("fc", 52.35),
            ("gc", 59.55),
            ("gi", 159.93),
        ];
        let node = |c: u8| (c - b'a') as usize;
        rows.iter()
            .map(|(pair, d)| {
                let p = pair.as_bytes();
                Arc {
                    from: node(p[0]),
                    to: node(p[1]),
                    d: *d,
                    u: 0.0,
                }
            })
            .collect()
    }

    #[test]
    fn table_2_components_and_shortest_route() {
        let arcs = table_2();
        // {a,b,c,f,g}, {d,e}, {h}, {i}: d and e reach c one way only (004 §4.4).
        assert_eq!(
            strongly_connected(&arcs, 9),
            vec![vec![0, 1, 2, 5, 6], vec![3, 4], vec![7], vec![8]]
        );
        let found = routes(&arcs, 9, 0, 7).expect("a reaches h");
        assert_eq!(found.shortest.nodes, vec![0, 1, 2, 7]);
        assert!((found.shortest.d - 211.43).abs() < 1e-9);
        assert!(routes(&arcs, 9, 7, 0).is_none());
    }

    #[test]
    fn the_papers_three_routes_rank_the_compromise_first() {
        // 004 §7.2.2 (Figs. 14, 15): (D, U) of the shortest, most reliable and compromise paths.
        let paths = [(444.930, 0.539), (731.506, 0.127), (457.931, 0.214)];
        let cost: Vec<f64> = paths
            .iter()
            .map(|&(d, u)| {
                Path {
                    arcs: vec![],
                    nodes: vec![],
                    d,
                    u,
                }
                .d_over_r()
            })
            .collect();
        for (c, printed) in cost.iter().zip([762.7, 830.6, 567.2]) {
            assert!((c - printed).abs() < 0.1, "{c} vs {printed}");
        }
        assert!(cost[2] < cost[0] && cost[2] < cost[1]);
        // A graph offering exactly these three routes picks them by criterion.
        let arcs: Vec<Arc> = paths
            .iter()
            .enumerate()
            .flat_map(|(k, &(d, u))| {
                [
                    Arc {
                        from: 0,
                        to: k + 1,
                        d: d / 2.0,
                        u: u / 2.0,
                    },
                    Arc {
                        from: k + 1,
                        to: 4,
                        d: d / 2.0,
                        u: u / 2.0,
                    },
                ]
            })
            .collect();
        let found = routes(&arcs, 5, 0, 4).expect("connected");
        assert_eq!(found.shortest.nodes, vec![0, 1, 4]);
        assert_eq!(found.reliable.nodes, vec![0, 2, 4]);
        assert_eq!(found.compromise.nodes, vec![0, 3, 4]);
        assert_eq!(found.front.len(), 3);
    }

    fn graph() -> impl Strategy<Value = (usize, Vec<Arc>)> {
        (3usize..9).prop_flat_map(|n| {
            let arc = (0..n, 0..n, 1.0..20.0f64, 0.0..1.5f64)
                .prop_filter("no loops", |(a, b, _, _)| a != b)
                .prop_map(|(from, to, d, u)| Arc { from, to, d, u });
            (Just(n), prop::collection::vec(arc, 0..4 * n))
        })
    }

    /// Every simple route, by depth-first enumeration (the brute force to check against).
    fn all_routes(arcs: &[Arc], from: usize, to: usize) -> Vec<(f64, f64)> {
        fn walk(
            arcs: &[Arc],
            at: usize,
            to: usize,
            seen: &mut Vec<usize>,
            d: f64,
            u: f64,
            out: &mut Vec<(f64, f64)>,
        ) {
            if at == to {
                out.push((d, u));
                return;
            }
            let next: Vec<&Arc> = arcs
                .iter()
                .filter(|a| a.from == at && !seen.contains(&a.to))
                .collect();
            for a in next {
                seen.push(a.to);
                walk(arcs, a.to, to, seen, d + a.d, u + a.u, out);
                seen.pop();
            }
        }
        let mut out = Vec::new();
        walk(arcs, from, to, &mut vec![from], 0.0, 0.0, &mut out);
        out
    }

    proptest! {
        /// The compromise is Pareto optimal, never worse in D·e^U than the other two, and each
        /// criterion's route is the brute-force optimum; U and D are the sums over legs.
        #[test]
        fn criteria_match_brute_force((n, arcs) in graph()) {
            let (from, to) = (0, n - 1);
            let brute = all_routes(&arcs, from, to);
            let Some(found) = routes(&arcs, n, from, to) else {
                prop_assert!(brute.is_empty());
                return Ok(());
            };
            let eps = 1e-9;
            for path in [&found.shortest, &found.reliable, &found.compromise] {
                let d: f64 = path.arcs.iter().map(|&i| arcs[i].d).sum();
                let u: f64 = path.arcs.iter().map(|&i| arcs[i].u).sum();
                prop_assert!((d - path.d).abs() < eps && (u - path.u).abs() < eps);
                prop_assert_eq!(path.nodes.first(), Some(&from));
                prop_assert_eq!(path.nodes.last(), Some(&to));
            }
            let c = &found.compromise;
            let dominates = |&(d, u): &(f64, f64)| {
                d <= c.d + eps && u <= c.u + eps && (d < c.d - eps || u < c.u - eps)
            };
            prop_assert!(!brute.iter().any(dominates));
            let min = |f: &dyn Fn(&(f64, f64)) -> f64| brute.iter().map(f).fold(f64::INFINITY, f64::min);
            prop_assert!((found.shortest.d - min(&|r| r.0)).abs() < eps);
            prop_assert!((found.reliable.u - min(&|r| r.1)).abs() < eps);
            prop_assert!((c.d.ln() + c.u - min(&|r| r.0.ln() + r.1)).abs() < eps);
            prop_assert!(c.d_over_r() <= found.shortest.d_over_r() + eps);
            prop_assert!(c.d_over_r() <= found.reliable.d_over_r() + eps);
            if let Some(per_leg) = per_leg_compromise(&arcs, n, from, to) {
                prop_assert!(c.d_over_r() <= per_leg.d_over_r() + eps);
            }
        }
    }
}
