//! The directed graph of legs a navigator can be told to drive (004 §4.2, made rotation
//! invariant). 004's navigator has a fixed orientation and a square view window, so a leg is
//! "the obvious / most isolated object of the window with `R` in corner `c`". A rover turns
//! and has no compass, and a qualitative map has no scale, so the window becomes a rank: the
//! **scene** of `R` with `n` objects is `R` and its `n − 1` nearest landmarks (seed digest
//! B.8), and the leg `R → T` says "of the `n − 1` landmarks nearest to you, head for the most
//! isolated". With `n = 2` that is the nearest landmark: 004's obvious edge. A leg is kept only
//! when the map proves both the scene and its most isolated member; a target reachable from
//! several scenes keeps the smallest (the most reliable, 004 §6.1.2).

use super::criteria::{routes, Arc, Path, Routes};
use super::isolation::{neighbour_ranks, Bounds, Nearness, SceneRanks};
use super::reliability::ReliabilityModel;
use rayon::prelude::*;

/// How the target of a leg is picked out of its scene (004 §4.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Descriptor {
    /// The only other object of the scene: the nearest landmark.
    Obvious,
    /// The most isolated object of the scene (largest c-value).
    Isolated,
}

/// One leg `from → to` (landmark indices of the [`Nearness`] source).
#[derive(Clone, Debug, PartialEq)]
pub struct Leg {
    pub from: usize,
    pub to: usize,
    /// `from` and its `objects − 1` nearest landmarks, `from` first, then nearest first.
    pub scene: Vec<usize>,
    /// `p_from(to)`: the target's rank among all of `from`'s neighbours (the distance proxy).
    pub rank: Bounds,
    /// The landmarks the navigator may take for the target: the scene's others, or, for a
    /// leg sampled from realizations of a partial map, every landmark that was in its scene
    /// in some realization.
    pub confusable: Vec<usize>,
    /// The fraction of the map's arrangements in which the leg holds: 1 when the map proves
    /// it, else the share of sampled realizations ([`super::sampling`]).
    pub support: f64,
    /// Whether the map's relations prove the leg (its scene and target).
    pub proven: bool,
}

impl Leg {
    /// Objects in the scene, counting `from` (004's `n`, seed digest B.4).
    pub fn objects(&self) -> usize {
        self.scene.len()
    }

    pub fn descriptor(&self) -> Descriptor {
        if self.objects() == 2 {
            Descriptor::Obvious
        } else {
            Descriptor::Isolated
        }
    }

    /// The landmarks the navigator may take for the target (004 §6.3.1).
    pub fn confusable(&self) -> impl Iterator<Item = usize> + '_ {
        self.confusable.iter().copied()
    }

    pub fn is_proven(&self) -> bool {
        self.proven
    }
}

/// The legs as a graph to route on: a leg's distance is its target's neighbour rank (upper
/// bound), a proxy for metres that needs no scale (seed digest B.8), and its unreliability is
/// `−ln (R(n, σ) · support)`: a leg the map does not prove may not exist at all.
#[derive(Clone, Debug)]
pub struct LegGraph {
    pub legs: Vec<Leg>,
    pub arcs: Vec<Arc>,
    nodes: usize,
}

impl LegGraph {
    /// The legs `source` proves.
    pub fn new(
        source: &impl Nearness,
        max_objects: usize,
        model: &ReliabilityModel,
        sigma: f64,
    ) -> LegGraph {
        LegGraph::from_legs(legs(source, max_objects), source.count(), model, sigma)
    }

    /// A graph of `legs` among `nodes` landmarks.
    pub fn from_legs(
        legs: Vec<Leg>,
        nodes: usize,
        model: &ReliabilityModel,
        sigma: f64,
    ) -> LegGraph {
        let arcs = legs
            .iter()
            .map(|l| Arc {
                from: l.from,
                to: l.to,
                d: f64::from(l.rank.high.max(1)),
                u: model.unreliability(l.objects(), sigma) - l.support.ln(),
            })
            .collect();
        LegGraph { legs, arcs, nodes }
    }

    /// Landmarks of the graph.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// The routes from `from` to `to` by every criterion, or `None` when no legs lead there.
    pub fn routes(&self, from: usize, to: usize) -> Option<Routes> {
        routes(&self.arcs, self.nodes, from, to)
    }

    /// The legs a path drives.
    pub fn legs_of(&self, path: &Path) -> Vec<&Leg> {
        path.arcs.iter().map(|&i| &self.legs[i]).collect()
    }
}

/// Every leg the map proves, with scenes of 2 to `max_objects` objects, ordered by `from`,
/// then scene size.
pub fn legs(source: &impl Nearness, max_objects: usize) -> Vec<Leg> {
    (0..source.count())
        .into_par_iter()
        .flat_map_iter(|from| legs_from(source, from, max_objects))
        .collect()
}

/// The legs starting at `from`.
pub fn legs_from(source: &impl Nearness, from: usize, max_objects: usize) -> Vec<Leg> {
    let ranks = neighbour_ranks(source, from);
    let mut legs: Vec<Leg> = Vec::new();
    for k in 1..max_objects.min(source.count()) {
        let Some(nearest) = k_nearest(&ranks, from, k) else {
            continue;
        };
        let scene: Vec<usize> = std::iter::once(from).chain(nearest).collect();
        let verdict = SceneRanks::new(source, &scene).most_isolated(Some(0));
        if let Some(t) = verdict.certain {
            let to = scene[t];
            if legs.iter().all(|l| l.to != to) {
                let confusable = scene[1..].iter().copied().filter(|&y| y != to).collect();
                legs.push(Leg {
                    from,
                    to,
                    scene,
                    rank: ranks[to],
                    confusable,
                    support: 1.0,
                    proven: true,
                });
            }
        }
    }
    legs
}

/// The `k` nearest landmarks of `from`, nearest first, when the ranks prove which they are:
/// `k` landmarks certainly rank `k` or better (then every other ranks worse, as the true
/// ranks are a permutation).
fn k_nearest(ranks: &[Bounds], from: usize, k: usize) -> Option<Vec<usize>> {
    let mut inside: Vec<usize> = (0..ranks.len())
        .filter(|&y| y != from && ranks[y].high as usize <= k)
        .collect();
    (inside.len() == k).then(|| {
        inside.sort_by_key(|&y| (ranks[y].low, y));
        inside
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::directions::isolation::Positions;
    use crate::geometry::Point;

    #[test]
    fn the_two_object_scene_is_the_nearest_landmark() {
        let points = [
            Point::new(0.0, 0.0),
            Point::new(1.0, 0.0),
            Point::new(0.0, 3.0),
            Point::new(10.0, 10.0),
        ];
        let legs = legs_from(&Positions(&points), 0, 4);
        assert_eq!(legs[0].to, 1);
        assert_eq!(legs[0].descriptor(), Descriptor::Obvious);
        assert_eq!(legs[0].rank, Bounds::exact(1));
        // Scene {0, 1, 2}: 1 and 0 are mutual nearest (c = 2), 2's closest mutual neighbour
        // is 0 (c = 1 + 2).
        assert_eq!(legs[1].to, 2);
        assert_eq!(legs[1].objects(), 3);
        // Scene {0, 1, 2, 3}: 3 is far from everything.
        assert_eq!(legs[2].to, 3);
        assert_eq!(legs[2].confusable().collect::<Vec<_>>(), vec![1, 2]);
    }
}
