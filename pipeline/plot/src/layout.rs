//! A drawing position for each landmark when no metric positions exist: the qualitative map
//! has none, so `pipeline run` draws the RNG as a graph, placed by a force-directed layout
//! (Fruchterman–Reingold): edges pull their ends together, all landmarks push apart. The
//! picture shows the graph's structure, not distances.

use rayon::prelude::*;
use std::f64::consts::TAU;

/// Positions in roughly `[-1, 1]²` for `n` landmarks joined by `edges` (indices into `0..n`).
/// Deterministic: a fixed start on a circle and a fixed cooling schedule.
pub fn spring_layout(n: usize, edges: &[(usize, usize)]) -> Vec<(f64, f64)> {
    let mut position: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n.max(1) as f64;
            (a.cos(), a.sin())
        })
        .collect();
    if n < 2 {
        return position;
    }
    let k = (4.0 / n as f64).sqrt();
    let iterations = 300;
    for step in 0..iterations {
        let temperature = 0.1 * (1.0 - step as f64 / iterations as f64) + 1e-3;
        // Each landmark's push summed in its own fixed order, so the rows may run in
        // parallel and the layout stays the same: O(n²) a round, 300 rounds, at every
        // station that changes the map (a long drive's ~1 000 landmarks: most of the MCAP
        // recording's time).
        let mut shift: Vec<(f64, f64)> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut push = (0.0, 0.0);
                for j in 0..n {
                    if i == j {
                        continue;
                    }
                    let (dx, dy) = (position[i].0 - position[j].0, position[i].1 - position[j].1);
                    let d2 = (dx * dx + dy * dy).max(1e-6);
                    push.0 += k * k * dx / d2;
                    push.1 += k * k * dy / d2;
                }
                push
            })
            .collect();
        for &(i, j) in edges {
            let (dx, dy) = (position[i].0 - position[j].0, position[i].1 - position[j].1);
            let d = dx.hypot(dy).max(1e-6);
            let (fx, fy) = (dx * d / k, dy * d / k);
            shift[i].0 -= fx;
            shift[i].1 -= fy;
            shift[j].0 += fx;
            shift[j].1 += fy;
        }
        for i in 0..n {
            let length = shift[i].0.hypot(shift[i].1).max(1e-12);
            let step = length.min(temperature);
            position[i].0 += shift[i].0 / length * step;
            position[i].1 += shift[i].1 / length * step;
        }
    }
    position
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joined_landmarks_end_nearer_than_strangers() {
        // Two triangles joined by one edge.
        let edges = [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (2, 3)];
        let p = spring_layout(6, &edges);
        let d = |i: usize, j: usize| (p[i].0 - p[j].0).hypot(p[i].1 - p[j].1);
        assert!(d(0, 1) < d(0, 5));
        assert!(p.iter().all(|q| q.0.is_finite() && q.1.is_finite()));
        assert_eq!(spring_layout(6, &edges), p);
    }
}
