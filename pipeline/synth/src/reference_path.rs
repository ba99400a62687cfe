//! The reference for a closed-loop trip's path length (issue 15 item 4): the shortest path
//! from the start into the goal landmark's true Voronoi cell that keeps the rover's clearance
//! from every rock, by Dijkstra (A* without a heuristic: the goal is a region) on an
//! 8-connected grid over the true world. Judging only: the navigator never sees it.
//!
//! An 8-connected grid path is at most `1 / cos(22.5°) − 1 ≈ 8.2 %` longer than the
//! straight-line path it stands for; clearance is tested at grid points only (a diagonal move
//! may graze a clearance disc), the start is rounded to the grid, and a gap narrower than a
//! cell may close. The reference is the true shortest path to within those approximations.

use crate::world::World;
use pathfinding::directed::dijkstra::dijkstra;
use qrm_core::geometry::Point;

/// Grid spacing, metres.
pub const RESOLUTION_M: f64 = 0.1;
/// How far beyond the rocks and the start the grid reaches, metres.
const BORDER_M: f64 = 3.0;

/// Free space around the rocks of `world`, rasterized.
struct Grid {
    origin: Point,
    width: i64,
    height: i64,
    free: Vec<bool>,
}

impl Grid {
    fn new(world: &World, start: Point, clearance: f64) -> Grid {
        let (mut low, mut high) = (start, start);
        for r in &world.rocks {
            low = Point::new(low.x.min(r.position.x), low.y.min(r.position.y));
            high = Point::new(high.x.max(r.position.x), high.y.max(r.position.y));
        }
        let origin = Point::new(low.x - BORDER_M, low.y - BORDER_M);
        let width = ((high.x - low.x + 2.0 * BORDER_M) / RESOLUTION_M).ceil() as i64 + 1;
        let height = ((high.y - low.y + 2.0 * BORDER_M) / RESOLUTION_M).ceil() as i64 + 1;
        let mut free = vec![true; (width * height) as usize];
        for r in &world.rocks {
            let reach = world.contact_radius(r.id) + clearance;
            let (cx, cy) = (
                (r.position.x - origin.x) / RESOLUTION_M,
                (r.position.y - origin.y) / RESOLUTION_M,
            );
            let cells = (reach / RESOLUTION_M).ceil() as i64 + 1;
            for y in (cy as i64 - cells).max(0)..=(cy as i64 + cells).min(height - 1) {
                for x in (cx as i64 - cells).max(0)..=(cx as i64 + cells).min(width - 1) {
                    let p = Point::new(
                        origin.x + x as f64 * RESOLUTION_M,
                        origin.y + y as f64 * RESOLUTION_M,
                    );
                    if p.distance(r.position) < reach {
                        free[(y * width + x) as usize] = false;
                    }
                }
            }
        }
        Grid {
            origin,
            width,
            height,
            free,
        }
    }

    fn cell(&self, p: Point) -> (i64, i64) {
        (
            ((p.x - self.origin.x) / RESOLUTION_M).round() as i64,
            ((p.y - self.origin.y) / RESOLUTION_M).round() as i64,
        )
    }

    fn point(&self, (x, y): (i64, i64)) -> Point {
        Point::new(
            self.origin.x + x as f64 * RESOLUTION_M,
            self.origin.y + y as f64 * RESOLUTION_M,
        )
    }

    fn is_free(&self, (x, y): (i64, i64)) -> bool {
        (0..self.width).contains(&x)
            && (0..self.height).contains(&y)
            && self.free[(y * self.width + x) as usize]
    }
}

/// Length in metres of the shortest path from `start` to a point where `in_goal` holds, kept
/// `clearance` from every rock's footprint (the start itself is allowed to be closer); `None`
/// if no such path exists on the grid.
pub fn shortest_path_m(
    world: &World,
    start: Point,
    clearance: f64,
    in_goal: impl Fn(Point) -> bool,
) -> Option<f64> {
    let grid = Grid::new(world, start, clearance);
    let from = grid.cell(start);
    // Integer costs (micrometres) for the search; √2 rounded per diagonal move.
    let straight = (RESOLUTION_M * 1e6).round() as u64;
    let diagonal = (RESOLUTION_M * std::f64::consts::SQRT_2 * 1e6).round() as u64;
    let (_, cost) = dijkstra(
        &from,
        |&(x, y)| {
            let grid = &grid;
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
            .filter(move |&(n, _)| grid.is_free(n))
        },
        |&c| in_goal(grid.point(c)),
    )?;
    Some(cost as f64 * 1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_open_field_gives_the_straight_line_within_the_grid_bound() {
        // One small rock out of the way: the grid spans the rocks and the start.
        let world = World::generate(1, &[(Point::new(9.0, 8.0), 0.2)]);
        let start = Point::new(0.0, 0.0);
        let goal = Point::new(7.0, 3.0);
        let length = shortest_path_m(&world, start, 0.3, |p| p.distance(goal) < 0.05).unwrap();
        let straight = start.distance(goal);
        assert!(
            length >= straight - 0.1 && length <= straight * 1.083 + 0.1,
            "{length}"
        );
    }

    #[test]
    fn a_rock_in_the_way_is_walked_around() {
        let world = World::generate(2, &[(Point::new(3.0, 0.0), 1.0)]);
        let start = Point::new(0.0, 0.0);
        let goal = Point::new(6.0, 0.0);
        let radius = world.contact_radius(world.rocks[0].id) + 0.3;
        let length = shortest_path_m(&world, start, 0.3, |p| p.distance(goal) < 0.05).unwrap();
        // Around a disc of radius r blocking the straight line: two tangents and an arc.
        let half = 3.0f64;
        let tangent = (half * half - radius * radius).sqrt();
        let arc = radius * (std::f64::consts::FRAC_PI_2 - (radius / half).acos()) * 2.0;
        let around = 2.0 * tangent + arc;
        assert!(
            length > 6.0 + 0.05,
            "{length} must exceed the straight line"
        );
        assert!(
            length >= around - 0.15 && length <= around * 1.083 + 0.15,
            "{length} vs {around}"
        );
    }

    #[test]
    fn an_enclosed_goal_has_no_path() {
        let world = World::generate(3, &[(Point::new(0.0, 0.0), 2.0)]);
        let inside = Point::new(0.0, 0.0);
        assert!(
            shortest_path_m(&world, Point::new(6.0, 0.0), 0.3, |p| p.distance(inside)
                < 0.2)
            .is_none()
        );
    }
}
