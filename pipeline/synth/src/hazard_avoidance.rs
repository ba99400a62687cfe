//! The rover's local hazard avoidance in the closed loop (issue 15 item 3 allows "a simple
//! documented local avoidance"), standing in for its hazard cameras. It sees the rocks within
//! [`SIGHT_M`] of the rover, never the map or the goal: the navigator gives a bearing from the
//! panorama, and the avoidance only decides how to drive the next step that way.
//!
//! Each step, the first of these that ends clear of every rock's footprint by the clearance:
//! 1. the rest of the detour of an earlier step 4, while the commanded bearing stays within
//!    [`DETOUR_TURN_DEG`] of the one it was planned for;
//! 2. the step on the commanded bearing;
//! 3. that step turned by 20°, alternately either way, up to 100°, unless it ends within half
//!    a step of where the last step started;
//! 4. a step along the shortest clear path ([`crate::clearance_grid`]) toward the point
//!    [`LOOKAHEAD_M`] ahead on the bearing, or, when that point cannot be reached, toward
//!    the reachable point nearest to it. The step cuts straight to the farthest point of the
//!    path in clear sight, then follows the path; the rest of the path is the detour.
//! 5. when the rover is in a pocket (step 4 finds nowhere nearer to go, and a place where one
//!    of its last [`TRAIL_STEPS`] steps began lies outside the free space it can reach now):
//!    back the way it came, step by step, to the latest such place, and on along step 4's
//!    path from there; all of it is the detour.
//!
//! With none, the rover stays put for that step.
//!
//! Why in this order (`docs/NAVIGATION.md` has the closed loop's figures):
//! - With steps 2 and 3 alone, a rover that drove into the pocket between two rocks a little
//!   over its width apart stood there until its step budget ran out.
//! - Without the detour's memory, the rover freed by step 4 went back into the pocket at the
//!   next step, where the step on the bearing was clear again.
//! - A turned step may undo the last one: between two rocks that close the way ahead, the
//!   rover stepped 80° to one side, then 80° back to where it came from, until its step
//!   budget ran out (marsyard seed 7, full resolution: 5 of the 10 failures of 100 trips).
//!   Step 4 plans a way round instead.
//! - Steps 2 and 3 test only where a step ends, so a step may cross the clearance between two
//!   rocks into a pocket of free space one or two grid cells wide (marsyard seed 7: trips 70
//!   and 90 of 100 stood still there to the end). Testing every step's whole segment would
//!   avoid the pocket but change most paths through a cluster; backing out changes only the
//!   trips that would stand still. The way back was driven before, and a rover hemmed in
//!   from its start (nothing it drove lies outside its reach) still stays put.
//! - Paths taken before turns steered the rover around the rocks it was driving to: the rock a
//!   step runs into is often the landmark of the leg. The closed loop lost more trips.

use crate::clearance_grid::{grown_footprints, Cell, Grid, RESOLUTION_M};
use crate::world::World;
use pathfinding::directed::dijkstra::{build_path, dijkstra_all};
use qrm_core::geometry::Point;
use qrm_core::measurement::angular_distance;
use std::collections::HashMap;

/// How far ahead on the bearing a detour aims, metres.
const LOOKAHEAD_M: f64 = 3.0;
/// Half the side of the square around the rover in which the hazard cameras see rocks, metres:
/// beyond the lookahead, so that a path has room to go round a rock standing on it.
const SIGHT_M: f64 = 4.0;
/// Turns of a blocked step tried in order, degrees.
const TURNS_DEG: [f64; 11] = [
    0.0, 20.0, -20.0, 40.0, -40.0, 60.0, -60.0, 80.0, -80.0, 100.0, -100.0,
];
/// Widest change of the commanded bearing for which a detour is kept, degrees: the bearing to
/// a landmark swings as the rover drives round a rock, a new leg's bearing jumps.
const DETOUR_TURN_DEG: f64 = 60.0;
/// Spacing of the points at which a straight segment's clearance is tested, metres.
const SAMPLE_M: f64 = 0.05;
/// How many of its last steps the rover may back along out of a pocket (step 5).
const TRAIL_STEPS: usize = 6;

/// The hazard avoidance of one trip: the detour it is following, if any (step 4 of the
/// module), kept while the commanded bearing stays within [`DETOUR_TURN_DEG`] of the one it
/// was planned for.
#[derive(Clone, Debug, Default)]
pub struct HazardAvoidance {
    /// The rest of the detour's path, from the rover's position on.
    detour: Vec<Point>,
    /// The bearing it was planned for (world frame, radians).
    azimuth: f64,
    /// The last steps it drove (start, end), oldest first, at most [`TRAIL_STEPS`].
    driven: Vec<(Point, Point)>,
}

impl HazardAvoidance {
    /// The end of one step of `length` metres from `from`, driven toward `azimuth` (world
    /// frame, radians) and kept `clearance` from the footprints of the rocks within
    /// [`SIGHT_M`]. `None` when the rover has no clear way to move.
    pub fn drive(
        &mut self,
        world: &World,
        from: Point,
        azimuth: f64,
        length: f64,
        clearance: f64,
    ) -> Option<Point> {
        // The footprints that reach into sight of anywhere on the trail, grown by the
        // clearance.
        let reach = SIGHT_M * std::f64::consts::SQRT_2 + TRAIL_STEPS as f64 * length;
        let near: Vec<(Point, f64)> = grown_footprints(world, clearance)
            .filter(|&(p, grown)| p.distance(from) < reach + grown)
            .collect();
        let next = self.next(&near, from, azimuth, length);
        if let Some(to) = next {
            if self.driven.len() == TRAIL_STEPS {
                self.driven.remove(0);
            }
            self.driven.push((from, to));
        }
        next
    }

    /// The way the rover came to `from`: the starts of the last steps it drove in a row up to
    /// there, latest first.
    fn trail(&self, from: Point) -> Vec<Point> {
        let mut at = from;
        let mut trail = Vec::new();
        for &(start, end) in self.driven.iter().rev() {
            if end != at {
                break;
            }
            trail.push(start);
            at = start;
        }
        trail
    }

    /// [`HazardAvoidance::drive`]'s step among the grown footprints `near`.
    fn next(
        &mut self,
        near: &[(Point, f64)],
        from: Point,
        azimuth: f64,
        length: f64,
    ) -> Option<Point> {
        let detour = std::mem::take(&mut self.detour);
        if !detour.is_empty()
            && angular_distance(azimuth, self.azimuth) < DETOUR_TURN_DEG.to_radians()
        {
            let way: Vec<Point> = std::iter::once(from).chain(detour).collect();
            let (next, rest) = along(&way, length);
            if outside(near, next) {
                self.detour = rest;
                return Some(next);
            }
        }
        let came_from = self.driven.last().map(|&(start, _)| start);
        let undoes = |p: Point| came_from.is_some_and(|back| back.distance(p) < 0.5 * length);
        if let Some(next) = TURNS_DEG
            .iter()
            .map(|&t| (t, toward(from, azimuth + t.to_radians(), length)))
            .find(|&(t, p)| outside(near, p) && (t == 0.0 || !undoes(p)))
            .map(|(_, p)| p)
        {
            return Some(next);
        }
        let subgoal = toward(from, azimuth, LOOKAHEAD_M);
        let reach = Reach::from(near, from);
        let way = around(near, &reach, from, subgoal)
            .or_else(|| out_of_pocket(near, &reach, from, &self.trail(from), subgoal))?;
        let (next, rest) = along(&way, length);
        self.detour = rest;
        self.azimuth = azimuth;
        Some(next)
    }
}

/// How far the rover can drive straight from `from` toward `azimuth` (world frame, radians),
/// up to `length` metres, and keep `clearance` from every rock's footprint: where the hazard
/// cameras stop a rover closing in on a rock (the closed loop's final approach). Sampled every
/// [`SAMPLE_M`]; 0 when the first sample is already too near.
pub fn clear_run(world: &World, from: Point, azimuth: f64, length: f64, clearance: f64) -> f64 {
    let near: Vec<(Point, f64)> = grown_footprints(world, clearance)
        .filter(|&(p, grown)| p.distance(from) < length + grown)
        .collect();
    let samples = (length / SAMPLE_M).ceil() as usize;
    (1..=samples)
        .map(|k| (k as f64 * SAMPLE_M).min(length))
        .take_while(|&d| outside(&near, toward(from, azimuth, d)))
        .last()
        .unwrap_or(0.0)
}

/// The point `length` metres from `from` toward `azimuth` (world frame, radians).
pub(crate) fn toward(from: Point, azimuth: f64, length: f64) -> Point {
    Point::new(
        from.x + length * azimuth.cos(),
        from.y + length * azimuth.sin(),
    )
}

/// The shortest clear path from `from` toward `subgoal` (see the module's step 4), starting at
/// `from`; `near` are the grown footprints that reach into sight, `reach` the rover's reach
/// among them from `from`. `None` when the rover is as near to the subgoal as it can get.
fn around(near: &[(Point, f64)], reach: &Reach, from: Point, subgoal: Point) -> Option<Vec<Point>> {
    let Reach {
        grid,
        start,
        reached,
    } = reach;
    let start = *start;
    // The subgoal if the rover can get there, else as near to it as it can get; the shorter
    // way among equals.
    let (end, _) = reached
        .iter()
        .map(|(&c, &(_, cost))| (c, cost))
        .chain(std::iter::once((start, 0)))
        .min_by_key(|&(c, cost)| (Grid::micrometres(grid.point(c).distance(subgoal)), cost, c))?;
    if end == start {
        return None;
    }
    let path: Vec<Point> = build_path(&end, reached)
        .into_iter()
        .map(|c| grid.point(c))
        .collect();
    // Cut straight to the farthest point of the path in clear sight, then follow the path.
    let cut = (1..path.len())
        .rev()
        .find(|&k| straight_and_clear(near, from, path[k]))
        .unwrap_or(1);
    Some(
        std::iter::once(from)
            .chain(path[cut..].iter().copied())
            .collect(),
    )
}

/// The way out of a pocket (the module's step 5): from `from` back along `trail` (where the
/// last steps began, latest first) to the latest place outside the free space the rover can
/// reach from `from` (`reach`), then step 4's path from there toward `subgoal`. `None` when
/// every place on the trail is within reach: the rover is hemmed in, not in a pocket.
fn out_of_pocket(
    near: &[(Point, f64)],
    reach: &Reach,
    from: Point,
    trail: &[Point],
    subgoal: Point,
) -> Option<Vec<Point>> {
    let exit = trail.iter().position(|&p| {
        let cell = reach.grid.cell(p);
        reach.grid.is_free(cell) && cell != reach.start && !reach.reached.contains_key(&cell)
    })?;
    let back = std::iter::once(from).chain(trail[..=exit].iter().copied());
    let onward =
        around(near, &Reach::from(near, trail[exit]), trail[exit], subgoal).unwrap_or_default();
    Some(back.chain(onward.into_iter().skip(1)).collect())
}

/// The clearance grid over the hazard cameras' sight around a rover, and the cells it can
/// reach from the one it stands in.
struct Reach {
    grid: Grid,
    start: Cell,
    /// Each reachable cell's predecessor and cost from `start` (`dijkstra_all`).
    reached: HashMap<Cell, (Cell, u64)>,
}

impl Reach {
    /// The reach of a rover at `from` among the grown footprints `near`.
    fn from(near: &[(Point, f64)], from: Point) -> Reach {
        let sight = Point::new(SIGHT_M, SIGHT_M);
        let grid = Grid::over(near, from - sight, from + sight);
        let start = grid.cell(from);
        let reached = dijkstra_all(&start, |&c| grid.free_neighbours(c));
        Reach {
            grid,
            start,
            reached,
        }
    }
}

/// The point `length` metres along the polyline `way` (or its end, if it is shorter), and the
/// rest of the polyline beyond it.
fn along(way: &[Point], length: f64) -> (Point, Vec<Point>) {
    let mut left = length;
    for (k, leg) in way.windows(2).enumerate() {
        let span = leg[0].distance(leg[1]);
        if span >= left && span > 0.0 {
            let t = left / span;
            let at = Point::new(
                leg[0].x + t * (leg[1].x - leg[0].x),
                leg[0].y + t * (leg[1].y - leg[0].y),
            );
            return (at, way[k + 1..].to_vec());
        }
        left -= span;
    }
    (way[way.len() - 1], Vec::new())
}

/// Whether the segment from `from` to `to` stays outside every grown footprint of `near`
/// (centre, radius), except within a grid cell of `from`: a rover that starts closer than the
/// clearance may still drive away.
fn straight_and_clear(near: &[(Point, f64)], from: Point, to: Point) -> bool {
    let span = from.distance(to);
    let n = (span / SAMPLE_M).ceil().max(1.0) as usize;
    (0..=n)
        .map(|k| k as f64 / n as f64)
        .filter(|t| t * span > 1.5 * RESOLUTION_M)
        .all(|t| {
            let p = Point::new(from.x + t * (to.x - from.x), from.y + t * (to.y - from.y));
            outside(near, p)
        })
}

/// Whether `p` lies outside every grown footprint of `near` (centre, radius).
fn outside(near: &[(Point, f64)], p: Point) -> bool {
    near.iter()
        .all(|&(centre, grown)| centre.distance(p) >= grown)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::{Counts, Preset};

    const CLEARANCE: f64 = 0.3;

    fn clear_of(world: &World, p: Point) -> bool {
        world
            .rocks
            .iter()
            .all(|r| r.position.distance(p) >= world.contact_radius(r.id) + CLEARANCE)
    }

    #[test]
    fn with_nothing_in_the_way_the_step_is_the_commanded_one() {
        let world = World::generate(1, &[(Point::new(0.0, 9.0), 0.5)]);
        let azimuth = 0.3f64;
        let next = HazardAvoidance::default()
            .drive(&world, Point::new(0.0, 0.0), azimuth, 0.5, CLEARANCE)
            .unwrap();
        let straight = Point::new(0.5 * azimuth.cos(), 0.5 * azimuth.sin());
        assert!(next.distance(straight) < 1e-9, "{next:?}");
    }

    #[test]
    fn the_clear_run_stops_the_clearance_short_of_a_rock_ahead() {
        let world = World::generate(3, &[(Point::new(3.0, 0.0), 0.5)]);
        let from = Point::new(0.0, 0.0);
        let stop = 3.0 - world.contact_radius(0) - CLEARANCE;
        let run = clear_run(&world, from, 0.0, 5.0, CLEARANCE);
        assert!(run <= stop && run > stop - SAMPLE_M, "{run} against {stop}");
        assert!(clear_of(&world, Point::new(run, 0.0)));
        // Short of the rock, or away from it, the whole length is clear.
        assert_eq!(clear_run(&world, from, 0.0, 0.73, CLEARANCE), 0.73);
        assert_eq!(clear_run(&world, from, 1.5, 5.0, CLEARANCE), 5.0);
        // Already at the clearance: no way ahead.
        let at_stop = Point::new(stop + 0.01, 0.0);
        assert_eq!(clear_run(&world, at_stop, 0.0, 1.0, CLEARANCE), 0.0);
    }

    #[test]
    fn a_rock_ahead_is_driven_around_and_passed() {
        let world = World::generate(2, &[(Point::new(2.0, 0.0), 0.6)]);
        let mut avoidance = HazardAvoidance::default();
        let mut at = Point::new(0.0, 0.0);
        for _ in 0..20 {
            let next = avoidance
                .drive(&world, at, 0.0, 0.5, CLEARANCE)
                .expect("a way around");
            assert!(clear_of(&world, next), "{next:?}");
            // A step bends with the path: never longer than commanded.
            let span = at.distance(next);
            assert!(span <= 0.5 + 1e-9 && span > 0.25, "{span}");
            at = next;
        }
        assert!(at.x > 4.0, "the rover passed the rock: {at:?}");
    }

    #[test]
    fn the_pocket_between_two_close_rocks_is_left_the_way_round() {
        // Two rocks whose clearance discs overlap across the commanded bearing, and the rover
        // drives straight at the gap: turning the step alone left the rover standing there.
        let world = World::generate(
            3,
            &[(Point::new(2.0, -0.6), 0.45), (Point::new(2.0, 0.6), 0.45)],
        );
        let gap = world.rocks[1].position.distance(world.rocks[0].position)
            - world.contact_radius(0)
            - world.contact_radius(1);
        assert!(gap < 2.0 * CLEARANCE, "the rocks must close the gap: {gap}");
        let mut avoidance = HazardAvoidance::default();
        let mut at = Point::new(0.8, 0.0);
        for _ in 0..30 {
            let Some(next) = avoidance.drive(&world, at, 0.0, 0.5, CLEARANCE) else {
                panic!("stuck at {at:?}");
            };
            assert!(clear_of(&world, next), "{next:?}");
            at = next;
        }
        assert!(at.x > 3.5, "the rover went round both rocks: {at:?}");
    }

    #[test]
    fn a_detour_out_of_a_dead_end_is_followed_to_its_end() {
        // A U of rocks open toward the rover, which stands at its bottom and is sent on into
        // it: every turn is blocked there, and once out of the dead end the step on the
        // bearing is clear again and leads back in.
        let mut u: Vec<(Point, f64)> = (0..5)
            .map(|k| (Point::new(2.6, -1.0 + 0.5 * k as f64), 0.5))
            .collect();
        for k in 0..4 {
            let x = 0.6 + 0.5 * k as f64;
            u.push((Point::new(x, -1.0), 0.5));
            u.push((Point::new(x, 1.0), 0.5));
        }
        let world = World::generate(5, &u);
        let mut avoidance = HazardAvoidance::default();
        let mut at = Point::new(1.5, 0.0);
        assert!(clear_of(&world, at));
        let boxed_in = TURNS_DEG.iter().all(|t| {
            let a = t.to_radians();
            !clear_of(
                &world,
                Point::new(at.x + 0.5 * a.cos(), at.y + 0.5 * a.sin()),
            )
        });
        assert!(boxed_in, "every turn must be blocked at the bottom");
        for _ in 0..40 {
            if let Some(next) = avoidance.drive(&world, at, 0.0, 0.5, CLEARANCE) {
                assert!(clear_of(&world, next), "{next:?}");
                at = next;
            }
        }
        assert!(at.x > 3.6, "the rover left the dead end behind: {at:?}");
    }

    #[test]
    fn a_rover_hemmed_in_comes_as_near_as_it_can_and_stays_put() {
        let ring: Vec<(Point, f64)> = (0..10)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 10.0;
                (Point::new(1.0 * a.cos(), 1.0 * a.sin()), 0.6)
            })
            .collect();
        let world = World::generate(4, &ring);
        for k in 0..10 {
            let (a, b) = (&world.rocks[k], &world.rocks[(k + 1) % 10]);
            let gap = a.position.distance(b.position)
                - world.contact_radius(a.id)
                - world.contact_radius(b.id);
            assert!(gap < 2.0 * CLEARANCE, "the ring must be closed: {gap}");
        }
        let centre = Point::new(0.0, 0.0);
        let mut at = centre;
        let mut steps = 0;
        let mut avoidance = HazardAvoidance::default();
        while let Some(next) = avoidance.drive(&world, at, 0.0, 0.5, CLEARANCE) {
            assert!(clear_of(&world, next), "{next:?}");
            at = next;
            steps += 1;
            assert!(steps < 5, "the rover keeps moving: {at:?}");
        }
        assert!(at.distance(centre) < 0.5, "{at:?}");
    }

    /// The world of `pipeline synth --preset marsyard --seed 7`.
    fn marsyard_seed_7() -> World {
        let layout = Preset::Marsyard.layout(
            7,
            Counts {
                rocks: Some(30),
                stations: Some(50),
            },
        );
        World::generate(7, &layout.rocks)
    }

    /// Trip 7 of `navigate drive --trips 100 --seed 1` on marsyard seed 7 (full resolution),
    /// from its 18th step on: the rover is sent at a small rock whose neighbours close both
    /// ways to it. With turns alone it stepped 80° to one side and 80° back, to the end of
    /// the trip.
    fn trip_to_the_densest_cluster(remember: bool) -> f64 {
        let world = marsyard_seed_7();
        let goal = world.rocks[22].position;
        let mut avoidance = HazardAvoidance::default();
        let mut at = Point::new(15.70, 9.57);
        let mut nearest = f64::INFINITY;
        for _ in 0..10 {
            if !remember {
                avoidance.driven.clear();
            }
            let azimuth = (goal.y - at.y).atan2(goal.x - at.x);
            if let Some(next) = avoidance.drive(&world, at, azimuth, 0.5, CLEARANCE) {
                assert!(clear_of(&world, next), "{next:?}");
                at = next;
            }
            nearest = nearest.min(at.distance(goal) - world.contact_radius(22));
        }
        nearest
    }

    #[test]
    fn a_turn_never_takes_the_rover_back_where_its_last_step_began() {
        // How near the rover came to the goal rock's footprint, metres: a little over the
        // clearance once it is round the neighbour; 1.8 m stepping back and forth.
        let without = trip_to_the_densest_cluster(false);
        assert!(without > 1.0, "the old oscillation: {without}");
        let with = trip_to_the_densest_cluster(true);
        assert!(with < CLEARANCE + 0.2, "{with}");
    }

    /// Trip 70 of `navigate drive --trips 100 --seed 1` on marsyard seed 7 (full resolution),
    /// from its 16th step on: sent west past rock 20 toward rock 4, the rover stepped across
    /// the clearance between rocks 20 and 22 into a pocket, and stood there to the end.
    #[test]
    fn a_rover_that_stepped_into_a_pocket_backs_out_the_way_it_came() {
        let world = marsyard_seed_7();
        let goal = world.rocks[4].position;
        let to_goal = |at: Point| (goal.y - at.y).atan2(goal.x - at.x);
        let mut avoidance = HazardAvoidance::default();
        let mut at = Point::new(15.388901413668565, 7.478448110565559);
        let mut nearest = f64::INFINITY;
        for step in 0..30 {
            if step == 2 {
                // In the pocket: a rover that came from nowhere stays put here.
                let fresh =
                    HazardAvoidance::default().drive(&world, at, to_goal(at), 0.5, CLEARANCE);
                assert_eq!(fresh, None, "not a pocket at {at:?}");
            }
            let next = avoidance
                .drive(&world, at, to_goal(at), 0.5, CLEARANCE)
                .unwrap_or_else(|| panic!("stuck at {at:?} after {step} steps"));
            assert!(clear_of(&world, next), "{next:?}");
            at = next;
            nearest = nearest.min(at.distance(goal) - world.contact_radius(4));
        }
        // Round rock 20 the other way, up to the clearance of the goal rock's footprint.
        assert!(nearest < CLEARANCE + 0.1, "{nearest}");
    }
}
