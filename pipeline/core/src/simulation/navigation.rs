//! Simulated navigation (seed digest A.7): a rover at a point of a landmark field is given a
//! goal, observes the landmarks with a simulated [`Sensor`] (bearings and range order, exact
//! or noisy), plans a landmark route on an RNG and follows it leg by leg (000 §VII-B), in
//! straight steps. Only the start's and goal's cells come from the truth (the task: "go from
//! here to the landmark nearest there"); every decision on the way is the [`LegFollower`]'s,
//! from observations alone.

use super::sensor::Sensor;
use crate::geometry::Point;
use crate::map::LandmarkId;
use crate::navigation::{cell_of, Cell, Command, LegFollower, RouteCost, RouteGraph};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// How the simulated rover drives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Length of one straight step.
    pub step: f64,
    /// Steps before the trip is given up.
    pub max_steps: usize,
    /// Re-plans (after a lost target) before the trip is given up.
    pub max_replans: usize,
    pub sensor: Sensor,
    pub cost: RouteCost,
    pub controller: Controller,
}

/// How the rover picks its heading (seed digest A.6, item 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Controller {
    /// 000 §VII-B's steps: plan once, then follow the route leg by leg ([`LegFollower`]).
    Legs,
    /// Memoryless, as 000 Fig. 6 draws it: in whichever cell the rover is, head for the next
    /// hop of the cheapest route from that cell's landmark to the goal's. Driving toward the
    /// next hop can cross a third cell no closer in hops, so this one can cycle.
    Flow,
}

/// Entries into one cell after which a memoryless trip counts as cycling.
const CYCLE_ENTRIES: usize = 3;

/// How a trip ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// In the goal landmark's cell, then straight to the goal point.
    Arrived,
    /// The start panorama did not say which cell the rover is in.
    StartUnknown,
    /// The RNG does not connect the start's and the goal's landmarks.
    NoRoute,
    /// A route landmark went out of view more often than re-planning allows.
    TargetLost,
    /// The step budget ran out.
    OutOfSteps,
    /// The memoryless controller entered one cell [`CYCLE_ENTRIES`] times.
    Cycled,
}

/// One simulated trip.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Trip {
    pub start: Point,
    pub goal: Point,
    /// The first landmark route planned.
    pub route: Vec<LandmarkId>,
    /// Positions driven through, start first.
    pub path: Vec<Point>,
    pub outcome: Outcome,
    /// The legs driven, in order.
    pub legs: Vec<Leg>,
    pub replans: usize,
}

/// One leg: straight steps toward one route landmark until in its cell (or the trip ended).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Leg {
    pub target: LandmarkId,
    /// Where the leg began.
    pub from: Point,
    pub steps: usize,
}

impl Trip {
    /// Length of the path driven.
    pub fn length(&self) -> f64 {
        self.path.windows(2).map(|w| w[0].distance(w[1])).sum()
    }

    /// Straight-line distance from start to goal.
    pub fn straight(&self) -> f64 {
        self.start.distance(self.goal)
    }

    /// Steps driven.
    pub fn steps(&self) -> usize {
        self.path.len().saturating_sub(1)
    }
}

/// Drives from `start` toward the cell of the landmark of `world` nearest `goal`, planning on
/// `graph`, and then straight to `goal` (000 §VII-B step 7, the local planner).
pub fn drive(
    world: &[Point],
    graph: &RouteGraph,
    start: Point,
    goal: Point,
    drive: &Drive,
    rng: &mut ChaCha8Rng,
) -> Trip {
    let mut trip = Trip {
        start,
        goal,
        route: Vec::new(),
        path: vec![start],
        outcome: Outcome::OutOfSteps,
        legs: Vec::new(),
        replans: 0,
    };
    let goal_landmark = nearest(world, goal);
    let (visible, view) = drive.sensor.observe(world, start, rng);
    let Some(Cell::Certain(first)) = cell_of(&visible, &view.order) else {
        trip.outcome = Outcome::StartUnknown;
        return trip;
    };
    let Ok(route) = graph.plan(first, goal_landmark, drive.cost) else {
        trip.outcome = Outcome::NoRoute;
        return trip;
    };
    trip.route = route.landmarks.clone();
    let mut follower = LegFollower::new(&route);
    let mut here = start;
    let mut lost = Vec::new();
    let mut entered: Vec<LandmarkId> = Vec::new();
    while trip.steps() < drive.max_steps {
        let (visible, view) = drive.sensor.observe(world, here, rng);
        if drive.controller == Controller::Flow {
            if let Some(Cell::Certain(cell)) = cell_of(&visible, &view.order) {
                if entered.last() != Some(&cell) {
                    entered.push(cell);
                    if entered.iter().filter(|&&c| c == cell).count() >= CYCLE_ENTRIES {
                        trip.outcome = Outcome::Cycled;
                        return trip;
                    }
                }
                if let Ok(route) = graph.plan(cell, goal_landmark, drive.cost) {
                    follower = LegFollower::new(&route);
                }
            }
        }
        match follower.step(&visible, &view) {
            Command::Toward { landmark, bearing } => {
                match trip.legs.last_mut() {
                    Some(leg) if leg.target == landmark => leg.steps += 1,
                    _ => trip.legs.push(Leg {
                        target: landmark,
                        from: here,
                        steps: 1,
                    }),
                }
                here = Point::new(
                    here.x + drive.step * bearing.cos(),
                    here.y + drive.step * bearing.sin(),
                );
                trip.path.push(here);
            }
            Command::Arrived => {
                while here.distance(goal) > drive.step && trip.steps() < drive.max_steps {
                    let (dx, dy) = (goal.x - here.x, goal.y - here.y);
                    let d = dx.hypot(dy);
                    here = Point::new(here.x + drive.step * dx / d, here.y + drive.step * dy / d);
                    trip.path.push(here);
                }
                if trip.steps() < drive.max_steps {
                    trip.path.push(goal);
                    trip.outcome = Outcome::Arrived;
                }
                return trip;
            }
            Command::TargetLost(target) => {
                lost.push(target);
                let replanned = match cell_of(&visible, &view.order) {
                    Some(Cell::Certain(now)) if trip.replans < drive.max_replans => graph
                        .plan_avoiding(now, goal_landmark, drive.cost, &lost)
                        .ok(),
                    _ => None,
                };
                let Some(route) = replanned else {
                    trip.outcome = Outcome::TargetLost;
                    return trip;
                };
                trip.replans += 1;
                follower = LegFollower::new(&route);
            }
        }
    }
    trip
}

/// The landmark of `world` nearest `p`.
pub fn nearest(world: &[Point], p: Point) -> LandmarkId {
    (0..world.len())
        .min_by(|&a, &b| world[a].distance(p).total_cmp(&world[b].distance(p)))
        .expect("a world with landmarks") as LandmarkId
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighborhood::{true_estimate, RngEdge, RngEstimate};
    use crate::simulation::Scenario;
    use rand::{Rng, SeedableRng};

    /// The true RNG of `points`, every edge certain.
    fn true_graph(points: &[Point]) -> RouteGraph {
        let ids: Vec<LandmarkId> = (0..points.len() as LandmarkId).collect();
        RouteGraph::new(&ids, &true_estimate(points))
    }

    fn ideal() -> Drive {
        Drive {
            step: 0.5,
            max_steps: 4000,
            max_replans: 3,
            sensor: Sensor::exact(None),
            cost: RouteCost::default(),
            controller: Controller::Legs,
        }
    }

    /// Seed digest A.8 test 2 (smaller here; `pipeline navigate simulate` runs the full one):
    /// with exact sensing, all landmarks visible and the true RNG, every trip arrives, and
    /// every leg ends within `|x − q_k| / δ + 1` steps of its start.
    #[test]
    fn every_trip_arrives_on_the_true_rng() {
        for world in 0..5u64 {
            let points = Scenario::random(world, 30, 0, 100.0).landmarks;
            let graph = true_graph(&points);
            let mut rng = ChaCha8Rng::seed_from_u64(world);
            for _ in 0..20 {
                let mut point =
                    || Point::new(rng.random_range(0.0..100.0), rng.random_range(0.0..100.0));
                let (start, goal) = (point(), point());
                let trip = drive(&points, &graph, start, goal, &ideal(), &mut rng);
                assert_eq!(trip.outcome, Outcome::Arrived, "world {world}: {trip:?}");
                assert_eq!(trip.route.first(), Some(&nearest(&points, start)));
                assert_eq!(trip.route.last(), Some(&nearest(&points, goal)));
                for leg in &trip.legs {
                    let bound = leg.from.distance(points[leg.target as usize]) / 0.5 + 1.0;
                    assert!(leg.steps as f64 <= bound, "{leg:?}: bound {bound}");
                }
                // Legs follow the route (one cut short into a later landmark's cell skips the
                // landmarks between).
                let mut ahead = trip.route[1..].iter();
                assert!(trip.legs.iter().all(|leg| ahead.any(|&l| l == leg.target)));
            }
        }
    }

    /// The memoryless controller of 000 Fig. 6 either arrives or is caught cycling; it never
    /// wanders until the step budget runs out.
    #[test]
    fn a_memoryless_trip_arrives_or_is_caught_cycling() {
        let flow = Drive {
            controller: Controller::Flow,
            ..ideal()
        };
        for world in 0..3u64 {
            let points = Scenario::random(world, 30, 0, 100.0).landmarks;
            let graph = true_graph(&points);
            let mut rng = ChaCha8Rng::seed_from_u64(world);
            for _ in 0..20 {
                let mut point =
                    || Point::new(rng.random_range(0.0..100.0), rng.random_range(0.0..100.0));
                let (start, goal) = (point(), point());
                let trip = drive(&points, &graph, start, goal, &flow, &mut rng);
                assert!(
                    matches!(trip.outcome, Outcome::Arrived | Outcome::Cycled),
                    "{trip:?}"
                );
            }
        }
    }

    #[test]
    fn a_goal_beyond_the_rng_is_no_route() {
        let points = [
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(50.0, 50.0),
        ];
        let rng = RngEstimate {
            edges: vec![RngEdge {
                a: 0,
                b: 1,
                cost: 0.0,
            }],
            pruned: 0,
        };
        let graph = RouteGraph::new(&[0, 1, 2], &rng);
        let mut random = ChaCha8Rng::seed_from_u64(1);
        let trip = drive(
            &points,
            &graph,
            Point::new(1.0, 1.0),
            Point::new(49.0, 49.0),
            &ideal(),
            &mut random,
        );
        assert_eq!(trip.outcome, Outcome::NoRoute);
    }

    /// With only the nearest landmarks in view, a far route landmark is lost, the rover
    /// re-plans around it, and a trip that still cannot see ahead ends as lost, not stuck.
    #[test]
    fn a_target_out_of_view_is_replanned_around_or_reported() {
        let points = Scenario::random(3, 30, 0, 100.0).landmarks;
        let graph = true_graph(&points);
        let short_sighted = Drive {
            sensor: Sensor::exact(Some(2)),
            ..ideal()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let outcomes: Vec<Outcome> = (0..30)
            .map(|_| {
                let mut point =
                    || Point::new(rng.random_range(0.0..100.0), rng.random_range(0.0..100.0));
                let (start, goal) = (point(), point());
                drive(&points, &graph, start, goal, &short_sighted, &mut rng).outcome
            })
            .collect();
        assert!(outcomes.contains(&Outcome::TargetLost), "{outcomes:?}");
        assert!(!outcomes.contains(&Outcome::OutOfSteps), "{outcomes:?}");
    }
}
