//! Which of a few discs may hold a point, in constant time.
//!
//! A registration asks, for every detection under every motion hypothesis, which of its
//! look-alike landmarks the motion brings it within reach of (about a million questions per
//! panorama against the 50 stations of a marsyard run), and most of the time the answer is
//! none. Cells over the discs answer with the few discs overlapping the point's cell, or none
//! outside them, without testing each disc.

/// Cells over some discs, each listing the discs that overlap it.
pub(super) struct DiscGrid {
    /// The cells' lower left corner, and their count along x and y.
    origin: [f64; 2],
    columns: usize,
    rows: usize,
    /// Cells per metre.
    per_metre: f64,
    /// Cell `c`'s discs are `members[starts[c]..starts[c + 1]]` (cells row by row).
    starts: Vec<usize>,
    members: Vec<usize>,
}

impl DiscGrid {
    /// At most this many cells along a side: the grid is built for every registration, and
    /// far more cells than discs would cost more to build than they save (32 took the same
    /// time on marsyard seed 7: the widest disc sets the cells' size there).
    const SIDE: f64 = 16.0;

    /// The grid over `discs`, `(centre, radius)` in metres, numbered in order.
    pub(super) fn new(discs: &[([f64; 2], f64)]) -> DiscGrid {
        let (mut low, mut high, mut widest) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2], 0.0);
        for (centre, radius) in discs {
            for axis in 0..2 {
                low[axis] = low[axis].min(centre[axis] - radius);
                high[axis] = high[axis].max(centre[axis] + radius);
            }
            widest = f64::max(widest, *radius);
        }
        // Cells no smaller than the widest disc, so that each disc overlaps at most three
        // along a side.
        let size = f64::max(
            widest,
            (high[0] - low[0]).max(high[1] - low[1]) / Self::SIDE,
        );
        let mut grid = DiscGrid {
            origin: low,
            columns: 0,
            rows: 0,
            per_metre: 1.0 / size,
            starts: Vec::new(),
            members: Vec::new(),
        };
        if discs.is_empty() || !size.is_finite() || size <= 0.0 {
            return grid;
        }
        grid.columns = grid.cell(high[0], 0) + 1;
        grid.rows = grid.cell(high[1], 1) + 1;
        // The cells a disc overlaps: those of its bounding square's corners and between.
        let span = |grid: &DiscGrid, (centre, radius): &([f64; 2], f64)| {
            let (x, y) = (centre[0], centre[1]);
            (
                grid.cell(x - radius, 0)..=grid.cell(x + radius, 0).min(grid.columns - 1),
                grid.cell(y - radius, 1)..=grid.cell(y + radius, 1).min(grid.rows - 1),
            )
        };
        let mut starts = vec![0; grid.columns * grid.rows + 1];
        for disc in discs {
            let (columns, rows) = span(&grid, disc);
            for row in rows {
                for column in columns.clone() {
                    starts[row * grid.columns + column + 1] += 1;
                }
            }
        }
        for c in 1..starts.len() {
            starts[c] += starts[c - 1];
        }
        let mut next = starts.clone();
        let mut members = vec![0; starts[starts.len() - 1]];
        for (k, disc) in discs.iter().enumerate() {
            let (columns, rows) = span(&grid, disc);
            for row in rows {
                for column in columns.clone() {
                    let c = row * grid.columns + column;
                    members[next[c]] = k;
                    next[c] += 1;
                }
            }
        }
        grid.starts = starts;
        grid.members = members;
        grid
    }

    /// The cell along `axis` of a coordinate at or above the origin's.
    fn cell(&self, coordinate: f64, axis: usize) -> usize {
        ((coordinate - self.origin[axis]) * self.per_metre) as usize
    }

    /// The discs that may hold `point`, by number: every disc that holds it with some room
    /// (a disc's cells are found from its bounding square, so a point on the edge may be
    /// missed by rounding), and some that do not.
    pub(super) fn near(&self, point: [f64; 2]) -> &[usize] {
        let x = (point[0] - self.origin[0]) * self.per_metre;
        let y = (point[1] - self.origin[1]) * self.per_metre;
        // Also false for NaN.
        if x >= 0.0 && y >= 0.0 && x < self.columns as f64 && y < self.rows as f64 {
            let c = y as usize * self.columns + x as usize;
            &self.members[self.starts[c]..self.starts[c + 1]]
        } else {
            &[]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Every disc holding a point, a hair inside its edge, is among those the grid lists
        /// for it: for discs of every size, close together or far apart, and points anywhere.
        #[test]
        fn the_discs_listed_for_a_point_hold_every_disc_that_holds_it(
            discs in prop::collection::vec(
                ((-60.0f64..60.0, -60.0f64..60.0), 0.01f64..6.0), 1..30),
            points in prop::collection::vec((-70.0f64..70.0, -70.0f64..70.0), 50),
        ) {
            let discs: Vec<([f64; 2], f64)> =
                discs.into_iter().map(|((x, y), r)| ([x, y], r)).collect();
            let grid = DiscGrid::new(&discs);
            // Points in the discs, near their edges, and anywhere.
            let edges = discs.iter().enumerate().map(|(k, (c, r))| {
                let angle = k as f64;
                [c[0] + r * (1.0 - 1e-9) * angle.cos(), c[1] + r * (1.0 - 1e-9) * angle.sin()]
            });
            for point in edges.chain(points.into_iter().map(|(x, y)| [x, y])) {
                let listed = grid.near(point);
                for (k, (centre, radius)) in discs.iter().enumerate() {
                    let inside = (point[0] - centre[0]).hypot(point[1] - centre[1])
                        <= radius * (1.0 - 1e-9);
                    prop_assert!(!inside || listed.contains(&k), "disc {k} holds {point:?}");
                }
            }
        }
    }

    #[test]
    fn a_point_far_from_every_disc_or_undefined_has_none_listed() {
        let grid = DiscGrid::new(&[([0.0, 0.0], 1.0), ([5.0, 5.0], 0.5)]);
        assert!(grid.near([20.0, 0.0]).is_empty());
        assert!(grid.near([-3.0, 0.0]).is_empty());
        assert!(grid.near([f64::NAN, 0.0]).is_empty());
        assert_eq!(grid.near([0.1, 0.0]), &[0]);
        assert!(DiscGrid::new(&[]).near([0.0, 0.0]).is_empty());
    }
}
