//! Which EDC regions touch: share a boundary edge or a vertex (000 §VIII-A counts open states
//! "not adjacent" to the true one). Derived from the geometry, not typed in: walk every boundary
//! curve of the canonical frame, find the vertices where other boundaries cross it, and look at
//! the regions just beside each curve close to each vertex. Every boundary edge ends in a
//! vertex, so regions sharing an edge also meet at a vertex.

use super::region::classify;
use crate::calculus::RelationSet;
use crate::geometry::{boundary_values, Point};
use std::f64::consts::TAU;

/// A boundary curve of the frame A=(0,0), B=(0,1), as a parametrisation with unit normal.
#[derive(Clone, Copy)]
enum Curve {
    /// x = 0.
    LineAB,
    /// y = c.
    Horizontal(f64),
    /// Unit circle about (0, c).
    Circle(f64),
}

impl Curve {
    const ALL: [Curve; 6] = [
        Curve::LineAB,
        Curve::Horizontal(0.0),
        Curve::Horizontal(1.0),
        Curve::Horizontal(0.5),
        Curve::Circle(0.0),
        Curve::Circle(1.0),
    ];

    fn point(self, t: f64) -> Point {
        match self {
            Curve::LineAB => Point::new(0.0, t),
            Curve::Horizontal(c) => Point::new(t, c),
            Curve::Circle(c) => Point::new(t.cos(), c + t.sin()),
        }
    }

    fn normal(self, t: f64) -> Point {
        match self {
            Curve::LineAB => Point::new(1.0, 0.0),
            Curve::Horizontal(_) => Point::new(0.0, 1.0),
            Curve::Circle(_) => Point::new(t.cos(), t.sin()),
        }
    }

    fn range(self) -> (f64, f64) {
        match self {
            Curve::Circle(_) => (0.0, TAU),
            _ => (-4.0, 4.0),
        }
    }

    /// Parameter of a point known to lie on the curve.
    fn parameter(self, p: Point) -> f64 {
        match self {
            Curve::LineAB => p.y,
            Curve::Horizontal(_) => p.x,
            Curve::Circle(c) => (p.y - c).atan2(p.x).rem_euclid(TAU),
        }
    }

    fn distance(self, p: Point) -> f64 {
        match self {
            Curve::LineAB => p.x.abs(),
            Curve::Horizontal(c) => (p.y - c).abs(),
            Curve::Circle(c) => (p.distance(Point::new(0.0, c)) - 1.0).abs(),
        }
    }
}

const A: Point = Point::new(0.0, 0.0);
const B: Point = Point::new(0.0, 1.0);

/// Points where some other boundary function changes sign along a curve.
fn vertices() -> Vec<Point> {
    let mut found: Vec<Point> = Vec::new();
    let steps = 20_000;
    for curve in Curve::ALL {
        let (t0, t1) = curve.range();
        let values = |t: f64| boundary_values(&A, &B, &curve.point(t));
        let mut prev_t = t0;
        let mut prev = values(t0);
        for s in 1..=steps {
            let t = t0 + (t1 - t0) * s as f64 / steps as f64;
            let cur = values(t);
            for k in 0..6 {
                if (prev[k] < 0.0) != (cur[k] < 0.0) {
                    let (mut lo, mut hi) = (prev_t, t);
                    for _ in 0..80 {
                        let mid = 0.5 * (lo + hi);
                        if (values(mid)[k] < 0.0) == (prev[k] < 0.0) {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    let p = curve.point(0.5 * (lo + hi));
                    if !found.iter().any(|q| q.distance(p) < 1e-7) {
                        found.push(p);
                    }
                }
            }
            prev_t = t;
            prev = cur;
        }
    }
    found
}

/// Regions whose closure contains `v`: those on either side of each curve through `v`, just
/// beside it (a step far smaller than the cusps between tangent boundaries).
fn regions_at(v: Point) -> RelationSet {
    let mut set = RelationSet::EMPTY;
    for curve in Curve::ALL {
        if curve.distance(v) > 1e-9 {
            continue;
        }
        let tv = curve.parameter(v);
        for along in [-1e-4, 1e-4] {
            let t = tv + along;
            let p = curve.point(t);
            let nrm = curve.normal(t);
            for side in [-1e-12, 1e-12] {
                if let Some(r) = classify(A, B, Point::new(p.x + side * nrm.x, p.y + side * nrm.y))
                {
                    set = set.with(r);
                }
            }
        }
    }
    set
}

/// [`adjacency`] as a table (it walks the boundary curves, which takes about half a second); a
/// test proves the two agree.
pub const ADJACENT: [RelationSet; 20] = {
    const BITS: [u32; 20] = [
        0x0003e, 0x0030d, 0x001fb, 0x003e7, 0x01c65, 0x01ddd, 0x03dbc, 0x0f36c, 0x0e2ee, 0x0e18a,
        0x51870, 0x77470, 0x36cf0, 0x3dbc0, 0xbbb80, 0xa6380, 0xe7c00, 0xdf800, 0xb0c00, 0x7c000,
    ];
    let mut table = [RelationSet::EMPTY; 20];
    let mut i = 0;
    while i < 20 {
        table[i] = RelationSet::from_bits(BITS[i]);
        i += 1;
    }
    table
};

/// The adjacency relation: `result[r − 1]` is the set of regions adjacent to region `r`
/// (irreflexive).
pub fn adjacency() -> Vec<RelationSet> {
    let mut adjacent = vec![RelationSet::EMPTY; 20];
    for v in vertices() {
        let around = regions_at(v);
        for r in around.iter() {
            adjacent[r as usize - 1] = adjacent[r as usize - 1].union(around.without(r));
        }
    }
    adjacent
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adjacency_contains_every_sampled_neighbour_pair() {
        // Independent check: two points 2·10⁻⁶ apart on either side of a boundary curve lie in
        // regions that touch there (EDC regions are far wider than that except at vertices,
        // where all the regions meeting there touch).
        use rand::{Rng, SeedableRng};
        let adj = adjacency();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut pairs = 0;
        for _ in 0..200_000 {
            let curve = Curve::ALL[rng.random_range(0..6)];
            let (t0, t1) = curve.range();
            let c = curve.point(rng.random_range(t0..t1));
            let angle = rng.random_range(0.0..TAU);
            let (dx, dy) = (1e-6 * angle.cos(), 1e-6 * angle.sin());
            let (p, q) = (
                Point::new(c.x + dx, c.y + dy),
                Point::new(c.x - dx, c.y - dy),
            );
            if let (Some(r), Some(s)) = (classify(A, B, p), classify(A, B, q)) {
                if r != s {
                    pairs += 1;
                    assert!(
                        adj[r as usize - 1].contains(s),
                        "{r} and {s} meet near {p:?}"
                    );
                }
            }
        }
        assert!(pairs > 100_000, "{pairs}");
    }

    #[test]
    fn adjacency_matches_the_figure() {
        let adj = adjacency();
        // Across the line AB above B, and between the two halves of the lune.
        assert!(adj[0].contains(2));
        assert!(adj[6].contains(13) && adj[6].contains(8));
        // Far apart: front-left outside (1) and behind-right outside (20).
        assert!(!adj[0].contains(20));
        // The cusp of region 6 between circle A and y = 1 reaches B, where 4 also meets.
        assert!(adj[5].contains(4));
        // Every region touches at least its mirror-side or row neighbours.
        assert!(adj.iter().all(|s| s.len() >= 3));
    }

    #[test]
    fn table_matches_the_geometry() {
        assert_eq!(adjacency(), ADJACENT.to_vec());
    }
}
