//! The run's RNG pictures (docs/RUN.md, "Pictures"): `rng.png` over a graph layout, since the
//! map has no positions, and, when the dataset has truth, `rng_truth.png` with the same edges at
//! the true positions of the landmarks' rocks and the true RNG dashed over them (000 Fig. 11).
//!
//! An unconverged map keeps most pairs as possible edges (a hairball), so by default only the
//! edges of Algorithm 2 cost `w ≤ DEFAULT_MAX_COST` are drawn; `--all-edges` draws every one.
//! rng.json always lists them all.

use anyhow::Result;
use qrm_atomic_file::OutputSet;
use qrm_core::geometry::Point;
use qrm_core::map::LandmarkId;
use qrm_core::neighborhood::{true_rng, RngEstimate};
use qrm_plot::{spring_layout, write_rng, Axes, RngPicture};
use std::collections::BTreeMap;
use std::path::Path;

/// The largest edge cost drawn by default. Chosen on the demo set and marsyard seed 7 as the
/// smallest cut that kept every true RNG edge there (docs/RUN.md, "Pictures", has the
/// precision and recall at each cut, also on sets it was not chosen on).
pub const DEFAULT_MAX_COST: f64 = 0.15;

/// Which edges a picture draws: those of cost at most `max_cost`, or all.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeCut {
    pub max_cost: Option<f64>,
}

impl EdgeCut {
    /// The default cut, or every edge with `all`.
    pub fn new(all: bool) -> EdgeCut {
        EdgeCut {
            max_cost: (!all).then_some(DEFAULT_MAX_COST),
        }
    }

    /// The edges drawn, as `(i, j, w)` over positions in `ids`.
    fn edges(&self, ids: &[LandmarkId], rng: &RngEstimate) -> Vec<(usize, usize, f64)> {
        let index = |id: LandmarkId| ids.iter().position(|&l| l == id);
        rng.edges
            .iter()
            .filter(|e| self.max_cost.is_none_or(|max| e.cost <= max))
            .filter_map(|e| Some((index(e.a)?, index(e.b)?, e.cost)))
            .collect()
    }

    /// With every edge drawn, the pairs the map rules out too (over positions in `ids`), so
    /// that certain, uncertain and pruned pairs are all told apart; none with a cut.
    fn pruned(&self, ids: &[LandmarkId], rng: &RngEstimate) -> Vec<(usize, usize)> {
        if self.max_cost.is_some() {
            return Vec::new();
        }
        let kept: std::collections::HashSet<(LandmarkId, LandmarkId)> = rng
            .edges
            .iter()
            .map(|e| (e.a.min(e.b), e.a.max(e.b)))
            .collect();
        (0..ids.len())
            .flat_map(|i| (i + 1..ids.len()).map(move |j| (i, j)))
            .filter(|&(i, j)| !kept.contains(&(ids[i].min(ids[j]), ids[i].max(ids[j]))))
            .collect()
    }

    /// The title's account of what is drawn.
    fn describe(&self, shown: usize, possible: usize) -> String {
        match self.max_cost {
            Some(max) if shown < possible => format!("{shown} of {possible} edges (w ≤ {max})"),
            _ => format!("{possible} possible edges"),
        }
    }
}

/// Stages `path` (rng.png) for the map's landmarks `ids` over a graph layout of the drawn
/// edges; removes an earlier one when the map has no landmarks.
pub fn stage_rng_png(
    outputs: &mut OutputSet,
    path: &Path,
    ids: &[LandmarkId],
    rng: &RngEstimate,
    stations: usize,
    cut: EdgeCut,
) -> Result<()> {
    if ids.is_empty() {
        outputs.remove_stale(path);
        return Ok(());
    }
    let pairs: Vec<(usize, usize)> = cut
        .edges(ids, rng)
        .iter()
        .map(|&(i, j, _)| (i, j))
        .collect();
    let positions = spring_layout(ids.len(), &pairs);
    stage_rng_over(
        outputs,
        path,
        format!("RNG after {stations} stations"),
        (ids, &positions),
        Some(rng),
        cut,
        Axes::Layout,
    )
}

/// Stages `path` (rng_truth.png): the landmarks that stand for a rock at that rock's true
/// position (`rocks`), the drawn edges between them, the true RNG of those positions dashed,
/// and the stations. With fewer than two such landmarks an earlier one is removed instead.
pub fn stage_rng_truth(
    outputs: &mut OutputSet,
    path: &Path,
    rng: &RngEstimate,
    rocks: &BTreeMap<LandmarkId, [f64; 2]>,
    stations: &[(f64, f64)],
    cut: EdgeCut,
) -> Result<()> {
    if rocks.len() < 2 {
        outputs.remove_stale(path);
        return Ok(());
    }
    let ids: Vec<LandmarkId> = rocks.keys().copied().collect();
    let positions: Vec<(f64, f64)> = rocks.values().map(|p| (p[0], p[1])).collect();
    let points: Vec<Point> = positions.iter().map(|&(x, y)| Point::new(x, y)).collect();
    let edges = cut.edges(&ids, rng);
    let possible = EdgeCut { max_cost: None }.edges(&ids, rng).len();
    let labels: Vec<String> = ids.iter().map(|id| id.to_string()).collect();
    let picture = RngPicture {
        title: format!(
            "RNG at true rock positions: {} landmarks, {}",
            ids.len(),
            cut.describe(edges.len(), possible)
        ),
        landmarks: &positions,
        labels: &labels,
        axes: Axes::Metres,
        edges: &edges,
        true_edges: &true_rng(&points),
        pruned: &cut.pruned(&ids, rng),
        stations,
    };
    outputs.stage(path, |temporary| write_rng(temporary, &picture))?;
    Ok(())
}

/// Stages `path`: the landmarks `ids` at `positions`, labelled with their ids, and the edges of
/// `rng` among them that `cut` keeps (none without an estimate: FDC has no lune); `title` is
/// followed by how many are drawn.
pub fn stage_rng_over(
    outputs: &mut OutputSet,
    path: &Path,
    title: String,
    (ids, positions): (&[LandmarkId], &[(f64, f64)]),
    rng: Option<&RngEstimate>,
    cut: EdgeCut,
    axes: Axes,
) -> Result<()> {
    let (edges, pruned, described) = match rng {
        Some(rng) => {
            let edges = cut.edges(ids, rng);
            let described = cut.describe(edges.len(), rng.edges.len());
            (edges, cut.pruned(ids, rng), described)
        }
        None => (Vec::new(), Vec::new(), "no RNG estimate".to_string()),
    };
    let labels: Vec<String> = ids.iter().map(|id| id.to_string()).collect();
    let picture = RngPicture {
        title: format!("{title}: {} landmarks, {described}", ids.len()),
        landmarks: positions,
        labels: &labels,
        axes,
        edges: &edges,
        true_edges: &[],
        pruned: &pruned,
        stations: &[],
    };
    outputs.stage(path, |temporary| write_rng(temporary, &picture))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::EdgeCut;
    use qrm_core::neighborhood::{RngEdge, RngEstimate};

    #[test]
    fn the_cut_keeps_cheap_edges_among_known_landmarks() {
        let rng = RngEstimate {
            edges: vec![
                RngEdge {
                    a: 1,
                    b: 2,
                    cost: 0.0,
                },
                RngEdge {
                    a: 2,
                    b: 5,
                    cost: 0.3,
                },
                RngEdge {
                    a: 1,
                    b: 9,
                    cost: 0.1,
                },
            ],
            pruned: 0,
        };
        let ids = [1, 2, 5];
        assert_eq!(EdgeCut::new(false).edges(&ids, &rng), vec![(0, 1, 0.0)]);
        assert_eq!(
            EdgeCut::new(true).edges(&ids, &rng),
            vec![(0, 1, 0.0), (1, 2, 0.3)]
        );
        assert_eq!(
            EdgeCut::new(false).describe(1, 3),
            "1 of 3 edges (w ≤ 0.15)"
        );
        assert_eq!(EdgeCut::new(true).describe(3, 3), "3 possible edges");
        // 1–5 is no edge: pruned, drawn only with every edge.
        assert_eq!(EdgeCut::new(true).pruned(&ids, &rng), vec![(0, 2)]);
        assert!(EdgeCut::new(false).pruned(&ids, &rng).is_empty());
    }
}
