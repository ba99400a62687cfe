//! Free space around the rocks of a world, rasterized on a square grid: where the rover's
//! centre may be while keeping a clearance from every rock's footprint. The reference path
//! (`reference_path`, judging) searches it over the whole world; the hazard avoidance
//! (`hazard_avoidance`, standing in for the rover's hazard cameras) over the few metres
//! around the rover.

use crate::world::World;
use qrm_core::geometry::Point;

/// Grid spacing, metres.
pub const RESOLUTION_M: f64 = 0.1;
/// Search costs are integers: micrometres.
const MICROMETRES: f64 = 1e6;

/// A grid cell, by column and row.
pub type Cell = (i64, i64);

/// Every rock's footprint grown by `clearance`, as discs (centre, radius): where the rover's
/// centre may not be (`World::contact_radius`).
pub fn grown_footprints(world: &World, clearance: f64) -> impl Iterator<Item = (Point, f64)> + '_ {
    world
        .rocks
        .iter()
        .map(move |r| (r.position, world.contact_radius(r.id) + clearance))
}

/// Which grid points keep the clearance from every rock.
pub struct Grid {
    origin: Point,
    width: i64,
    height: i64,
    free: Vec<bool>,
}

impl Grid {
    /// The grid over the rectangle from `low` to `high`; a point is free when it lies outside
    /// every disc of `discs` (centre, radius: footprints grown by the clearance,
    /// [`grown_footprints`]).
    pub fn over(discs: &[(Point, f64)], low: Point, high: Point) -> Grid {
        let width = ((high.x - low.x) / RESOLUTION_M).ceil() as i64 + 1;
        let height = ((high.y - low.y) / RESOLUTION_M).ceil() as i64 + 1;
        let mut free = vec![true; (width * height) as usize];
        for &(centre, reach) in discs {
            let (cx, cy) = (
                (centre.x - low.x) / RESOLUTION_M,
                (centre.y - low.y) / RESOLUTION_M,
            );
            let cells = (reach / RESOLUTION_M).ceil() as i64 + 1;
            for y in (cy as i64 - cells).max(0)..=(cy as i64 + cells).min(height - 1) {
                for x in (cx as i64 - cells).max(0)..=(cx as i64 + cells).min(width - 1) {
                    let p = Point::new(
                        low.x + x as f64 * RESOLUTION_M,
                        low.y + y as f64 * RESOLUTION_M,
                    );
                    if p.distance(centre) < reach {
                        free[(y * width + x) as usize] = false;
                    }
                }
            }
        }
        Grid {
            origin: low,
            width,
            height,
            free,
        }
    }

    /// The cell nearest to `p`.
    pub fn cell(&self, p: Point) -> Cell {
        (
            ((p.x - self.origin.x) / RESOLUTION_M).round() as i64,
            ((p.y - self.origin.y) / RESOLUTION_M).round() as i64,
        )
    }

    /// The point of cell `(x, y)`.
    pub fn point(&self, (x, y): Cell) -> Point {
        Point::new(
            self.origin.x + x as f64 * RESOLUTION_M,
            self.origin.y + y as f64 * RESOLUTION_M,
        )
    }

    /// Whether cell `(x, y)` lies on the grid and keeps the clearance.
    pub fn is_free(&self, (x, y): Cell) -> bool {
        (0..self.width).contains(&x)
            && (0..self.height).contains(&y)
            && self.free[(y * self.width + x) as usize]
    }

    /// The free cells of the 8 around `(x, y)`, with the cost of the move (micrometres; √2
    /// rounded per diagonal move).
    pub fn free_neighbours(&self, (x, y): Cell) -> impl Iterator<Item = (Cell, u64)> + '_ {
        let straight = (RESOLUTION_M * MICROMETRES).round() as u64;
        let diagonal = (RESOLUTION_M * std::f64::consts::SQRT_2 * MICROMETRES).round() as u64;
        [
            (1, 0, straight),
            (-1, 0, straight),
            (0, 1, straight),
            (0, -1, straight),
            (1, 1, diagonal),
            (1, -1, diagonal),
            (-1, 1, diagonal),
            (-1, -1, diagonal),
        ]
        .into_iter()
        .map(move |(dx, dy, c)| ((x + dx, y + dy), c))
        .filter(move |&(n, _)| self.is_free(n))
    }

    /// A search cost in metres.
    pub fn metres(cost: u64) -> f64 {
        cost as f64 / MICROMETRES
    }

    /// A length in metres as a search cost.
    pub fn micrometres(metres: f64) -> u64 {
        (metres * MICROMETRES).round() as u64
    }
}
