//! The reference for a closed-loop trip's path length (issue 15 item 4): the shortest path
//! from the start into the goal landmark's true Voronoi cell that keeps the rover's clearance
//! from every rock, by Dijkstra (A* without a heuristic: the goal is a region) on an
//! 8-connected grid over the true world. Judging only: the navigator never sees it.
//!
//! An 8-connected grid path is at most `1 / cos(22.5°) − 1 ≈ 8.2 %` longer than the
//! straight-line path it stands for; clearance is tested at grid points only (a diagonal move
//! may graze a clearance disc), the start is rounded to the grid, and a gap narrower than a
//! cell may close. The reference is the true shortest path to within those approximations.

use crate::clearance_grid::{grown_footprints, Grid};
use crate::world::World;
use pathfinding::directed::dijkstra::dijkstra;
use qrm_core::geometry::Point;

/// How far beyond the rocks and the start the grid reaches, metres.
const BORDER_M: f64 = 3.0;

/// Length in metres of the shortest path from `start` to a point where `in_goal` holds, kept
/// `clearance` from every rock's footprint (the start itself is allowed to be closer); `None`
/// if no such path exists on the grid.
pub fn shortest_path_m(
    world: &World,
    start: Point,
    clearance: f64,
    in_goal: impl Fn(Point) -> bool,
) -> Option<f64> {
    let (mut low, mut high) = (start, start);
    for r in &world.rocks {
        low = Point::new(low.x.min(r.position.x), low.y.min(r.position.y));
        high = Point::new(high.x.max(r.position.x), high.y.max(r.position.y));
    }
    let border = Point::new(BORDER_M, BORDER_M);
    let discs: Vec<(Point, f64)> = grown_footprints(world, clearance).collect();
    let grid = Grid::over(&discs, low - border, high + border);
    let (_, cost) = dijkstra(
        &grid.cell(start),
        |&c| grid.free_neighbours(c),
        |&c| in_goal(grid.point(c)),
    )?;
    Some(Grid::metres(cost))
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
