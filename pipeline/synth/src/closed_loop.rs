//! Closed-loop navigation through the rendered world (issue 15 item 3; 000 §VII-B): at every
//! step the rover's stereo panorama is rendered at its true pose, the vision front end detects
//! and ranges the rocks, they are associated with the map of an earlier run
//! (`qrm_vision::localization`), and the leg follower (`qrm_core::navigation::LegFollower`)
//! turns the identified landmarks' bearings and range order into a heading. The rover then
//! drives one step that way.
//!
//! What the navigator decides from: the panorama only. It never sees the world: the route,
//! the headings, arrival and re-planning come from the map and the images. Two things use the
//! world, and neither chooses where to go: the renderer, and the hazard avoidance that stands
//! in for a rover's own hazard cameras ([`HazardAvoidance`]), which only decides how to drive
//! each step on the commanded bearing. A step that would end within [`CLEARANCE_M`] of a
//! rock's footprint is turned by 20° at a time, alternately either way, up to 100°, never back
//! to where the last step began; when every turn is blocked, the rover follows the shortest
//! clear path around the rocks within a few metres, and keeps to it while the bearing holds;
//! when that path leads nowhere because a step slipped between rocks into a pocket, the rover
//! backs out the way it came. With no clear way the rover stays put for that step. A step that
//! crosses a footprint anyway counts as a collision.
//!
//! The follower's cell is that of the nearest *identified* landmark (`navigation::cell_of`
//! over them; the first of the possible ones when the order cannot tell), as in the
//! ideal-sensor study. The route is planned from the first panorama's cell. When the next
//! landmark of the route is not identified in a panorama, the rover drives to where it was
//! last seen: by dead reckoning if it was seen in the last 12 steps with a bounded range, on
//! its last bearing if in the last 6 steps (the rover keeps its heading, so bearings stay
//! good); otherwise it re-plans from its cell: the cheapest of the 5 cheapest routes whose
//! next landmark is in view, or, with none, the cheapest route from a landmark in view that
//! the follower can start on (the rover drives to that landmark first), or, with nothing
//! identified that leads to the goal, a step on the goal's last bearing if it was ever seen
//! (at most 5 re-plans); else the trip is lost. When the follower arrives (the goal is the
//! nearest identified landmark) but a detection not identified may be nearer still, the rover
//! closes in on the goal for up to 8 more steps until the panorama proves it the nearest of
//! all.
//!
//! The camera cannot see the ground near the rover: below the panorama's bottom row lies a
//! blind zone (2.1 m of flat ground from a 1.5 m mast at marsyard's calibration). A rock the
//! rover drives up to often leaves the view through the panorama's foot before the rover is
//! in its cell, and from there no range order can show it nearest. A route landmark last
//! identified at the foot of the view (its lowest row showing ground within one step of the
//! blind zone) that is gone from there (no detection at the foot on its bearing) is therefore
//! *reached*: its leg ends as if the range order had shown it nearest.
//!
//! Between sightings the rover dead-reckons (its steps as its wheels measured them) where a
//! landmark's rock is: on its last bearing, within its range interval from all cues (ground
//! contact, stereo, size). A route landmark driven on its last bearing as far as the nearest
//! its rock's near side may be, less the clearance the hazard cameras keep, is *reached* too:
//! driving on would pass it.
//!
//! A rover that has arrived may still stand in a neighbour's cell: the goal is the nearest rock
//! the panorama shows, and a rock under the camera may be nearer. So once the follower
//! arrives, the rover closes in on the goal ([`final_approach`]): straight at the goal's rock
//! by dead reckoning, until the hazard cameras stop it [`CLEARANCE_M`] from a rock. The
//! goal's cell is convex and holds the goal, so this never leaves the cell once in it. The
//! hazard cameras (as [`HazardAvoidance`]) only say how far the way ahead is clear, never
//! where to go. Stopped there, the rover may stand where the goal's cell meets a neighbour's;
//! when dead reckoning puts another remembered landmark about as near as the goal, it rounds
//! the goal to its far side ([`far_side`]).
//!
//! The rover keeps its heading (a holonomic rover, or one that turns back after each step):
//! bearings are in the panorama's frame, and the step is taken in that frame. Success is
//! judged against the truth only after the trip: the rover stopped in the goal landmark's
//! Voronoi cell (the landmark whose rock is nearest to it).

use crate::clearance_grid::grown_footprints;
use crate::hazard_avoidance::{clear_run, toward, HazardAvoidance};
use crate::reference_path::shortest_path_m;
use crate::render::{render, Eye, Pose};
use crate::world::World;
use image::RgbImage;
use qrm_core::edc::Edc;
use qrm_core::geometry::Point;
use qrm_core::map::LandmarkId;
use qrm_core::measurement::StationView;
use qrm_core::navigation::{cell_of, Cell, Command, LegFollower, Route, RouteCost, RouteGraph};
use qrm_vision::calib::Calibration;
use qrm_vision::detection::Detection;
use qrm_vision::localization::{KnownMap, Location, Whereabouts};
use qrm_vision::ranging::{PrimaryEye, RangeInterval};
use qrm_vision::run::front_end::detect_panoramas;
use qrm_vision::run::{RunSettings, StationDetections};
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::time::Instant;

/// Nearest a step may end to a rock's footprint, metres (the rover's half-width and margin).
pub const CLEARANCE_M: f64 = 0.3;
/// How far a step may end from the straight step on the commanded bearing before it counts as
/// avoiding a rock, metres.
const AVOIDED_M: f64 = 0.01;
/// Re-plans allowed when the next landmark of the route is lost from view.
const REPLANS: usize = 5;
/// Routes considered when re-planning.
const ALTERNATIVES: usize = 5;
/// Steps for which a landmark is driven to while it is not identified, on its last bearing
/// when its range has no far bound ([`Sighted::remembered`]).
const MEMORY_STEPS: usize = 6;
/// Steps for which a landmark's rock is driven to by dead reckoning while it is not
/// identified, when its range is bounded ([`Sighted::remembered`]).
const DEAD_RECKONING_STEPS: usize = 12;
/// Steps of the final approach at most ([`final_approach`]).
const FINAL_APPROACH_STEPS: usize = 8;
/// Steps the rover closes in on the goal once it is the nearest identified landmark, until the
/// panorama proves it nearer than every detection.
const APPROACH_STEPS: usize = 8;
/// Shortest straight run of the final approach worth a step, metres.
const MIN_APPROACH_M: f64 = 0.05;
/// How far to either side of a landmark's last bearing a detection at the panorama's foot
/// shows that the landmark is still in view, radians: the bearing of a rock near the rover
/// moves with the rover's step, and the primary eye sits half the stereo baseline off the
/// mast.
const STILL_IN_VIEW_RAD: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// How the rover drives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Driving {
    /// Length of one straight step, metres.
    pub step_m: f64,
    /// Steps before the trip is given up.
    pub max_steps: usize,
    pub cost: RouteCost,
    /// How many times each step's perception (detection, and association with the map) runs
    /// to be timed, the fastest counting (`navigate drive --repeat`, as `navigate locate
    /// --repeat`): the fastest run is the code's own time, the others add what else the
    /// machine was doing. The runs are identical; the rover acts on the first. 1 but for
    /// benchmarks.
    pub perception_runs: usize,
}

/// How a trip ended, as the navigator saw it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The follower says the rover is in the goal landmark's cell.
    Arrived,
    /// The first panorama identified no landmark that may be the nearest.
    StartUnknown,
    /// No route in the map's RNG from where the rover started to the goal.
    NoRoute,
    /// The route's next landmark was lost from view more often than re-planning allows.
    Lost,
    OutOfSteps,
}

/// One trip: what the navigator did, and (from the truth, afterwards) how well.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Trip {
    /// Its place in the seeded sequence of trips it was drawn from, from 0 (`navigate drive
    /// --only` drives a few of them again); set by whoever draws the sequence, 0 otherwise.
    pub number: usize,
    pub start: [f64; 2],
    pub goal: LandmarkId,
    pub outcome: Outcome,
    /// The first route planned.
    pub route: Vec<LandmarkId>,
    pub replans: usize,
    /// Positions after every step, the start first.
    pub path: Vec<[f64; 2]>,
    /// Steps whose segment crossed a rock's footprint.
    pub collisions: usize,
    /// Steps on which the hazard avoidance left the commanded bearing or held the rover.
    pub avoided: usize,
    /// Seconds of navigator compute per step: detection to heading, rendering excluded.
    pub navigator_seconds: Vec<f64>,
    /// Truth, afterwards: the rover stopped where the goal landmark's rock is the nearest of
    /// the map's landmarks' rocks.
    pub in_goal_cell: bool,
    /// Path length, and the straight distance from the start to the goal's rock, metres.
    pub length_m: f64,
    pub straight_m: f64,
    /// Truth, afterwards: the shortest path from the start into the goal's true cell that
    /// keeps [`CLEARANCE_M`] from every rock (`reference_path`), metres; `None` when the grid
    /// has none.
    pub reference_m: Option<f64>,
    /// What the navigator saw and decided at every step (the per-step log, drive.mcap).
    #[serde(skip)]
    pub steps: Vec<StepLog>,
}

impl Trip {
    /// Takes each step's time from `again`, the same trip driven once more, where it was
    /// faster (`navigate drive --again-over`). False, and nothing taken, if `again` took
    /// other steps.
    pub fn keep_faster_steps(&mut self, again: &Trip) -> bool {
        let untimed = |s: &StepLog| StepLog {
            navigator_seconds: 0.0,
            detect_seconds: 0.0,
            ..s.clone()
        };
        let same = self.steps.len() == again.steps.len()
            && self
                .steps
                .iter()
                .zip(&again.steps)
                .all(|(a, b)| untimed(a) == untimed(b));
        if !same {
            return false;
        }
        for ((step, seconds), faster) in self
            .steps
            .iter_mut()
            .zip(&mut self.navigator_seconds)
            .zip(&again.steps)
        {
            if faster.navigator_seconds < step.navigator_seconds {
                step.navigator_seconds = faster.navigator_seconds;
                step.detect_seconds = faster.detect_seconds;
                *seconds = faster.navigator_seconds;
            }
        }
        true
    }
}

/// One step of a trip: what the navigator identified and decided, and where the rover truly
/// stood (the log's, never the navigator's).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepLog {
    pub step: usize,
    /// True position before the step, metres, and the camera's true heading (the azimuth of
    /// the panorama's zero bearing), degrees counter-clockwise from +x.
    pub position: [f64; 2],
    pub heading_deg: f64,
    /// Landmarks identified in the panorama.
    pub identified: Vec<LandmarkId>,
    /// Detections in the panorama.
    pub detections: usize,
    /// The cell the follower believes it is in (the nearest identified landmark).
    pub cell: Option<LandmarkId>,
    /// `toward`, `closing_in` (the final approach to the goal), `arrived`, `lost`, or at a
    /// first step that cannot start, `start_unknown` or `no_route`.
    pub command: &'static str,
    /// The landmark driven toward, and its bearing in the panorama's frame, degrees.
    pub target: Option<LandmarkId>,
    pub bearing_deg: Option<f64>,
    /// Re-plans so far.
    pub replans: usize,
    /// The hazard avoidance left the commanded bearing or held the rover this step.
    pub avoided: bool,
    /// Navigator compute of this step, seconds (detection to heading), and of it the
    /// detection in the stereo pair.
    pub navigator_seconds: f64,
    pub detect_seconds: f64,
}

/// The rendered world the rover drives in.
pub struct Terrain<'a> {
    pub world: &'a World,
    pub calib: &'a Calibration,
    /// The rock each map landmark stands for (the truth, for judging trips only).
    pub landmark_rocks: &'a BTreeMap<LandmarkId, u32>,
}

impl Terrain<'_> {
    /// The stereo pair at `pose`.
    fn panoramas(&self, pose: Pose) -> (RgbImage, RgbImage) {
        let image = |eye| {
            let r = render(self.world, self.calib, pose, eye);
            RgbImage::from_raw(r.width, r.height, r.rgb).expect("a render fills its image")
        };
        (image(Eye::Left), image(Eye::Right))
    }

    /// Whether `p` lies within `margin` of a rock's footprint.
    pub(crate) fn blocked(&self, p: Point, margin: f64) -> bool {
        grown_footprints(self.world, margin).any(|(centre, grown)| centre.distance(p) < grown)
    }

    /// Whether the segment `a`–`b` crosses a rock's footprint (sampled every 5 cm).
    fn crosses(&self, a: Point, b: Point) -> bool {
        let n = (a.distance(b) / 0.05).ceil().max(1.0) as usize;
        (0..=n).any(|k| {
            let t = k as f64 / n as f64;
            self.blocked(
                Point::new(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)),
                0.0,
            )
        })
    }

    /// The shortest clear path from `start` into `goal`'s true cell (judging only).
    fn reference(&self, start: Point, goal: LandmarkId) -> Option<f64> {
        shortest_path_m(self.world, start, CLEARANCE_M, |p| {
            self.in_true_cell(p, goal)
        })
    }

    /// The landmark whose true cell holds `p`: the one whose rock is the nearest to `p` of
    /// the map's landmarks' rocks (judging only). Of two landmarks of one rock, the first.
    pub fn true_cell(&self, p: Point) -> Option<LandmarkId> {
        self.landmark_rocks
            .iter()
            .map(|(&l, &r)| (l, self.world.rocks[r as usize].position.distance(p)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(l, _)| l)
    }

    /// Whether `p` lies in landmark `l`'s true cell ([`Terrain::true_cell`]). Two landmarks
    /// of one rock (a rock the map duplicated) share its cell: judged by landmark, a rover at
    /// the rock was outside the cell of whichever of them lost the tie (half-resolution
    /// marsyard seed 4: 6 trips to a duplicate landmark judged beside their goal cell while at
    /// its rock).
    fn in_true_cell(&self, p: Point, l: LandmarkId) -> bool {
        let rock = |l| self.landmark_rocks.get(&l).copied();
        self.true_cell(p)
            .is_some_and(|nearest| rock(nearest).is_some() && rock(nearest) == rock(l))
    }
}

/// A step's panorama as the navigator perceived it, and how long that took: the fastest of
/// [`Driving::perception_runs`] runs, in all and of it the detection.
struct Perceived {
    detections: StationDetections,
    location: Location,
    seconds: f64,
    detect_seconds: f64,
}

/// Detects the rocks in the stereo pair and locates them against the map, timed.
fn perceive(
    left: &RgbImage,
    right: &RgbImage,
    calib: &Calibration,
    known: &KnownMap<Edc>,
    settings: &RunSettings,
    driving: &Driving,
) -> Perceived {
    let run = || {
        let started = Instant::now();
        let detections = detect_panoramas(
            "rover",
            left,
            Some(right),
            PrimaryEye::Left,
            false,
            calib,
            &settings.detector,
        );
        let detect_seconds = started.elapsed().as_secs_f64();
        let location = known.locate(&detections, calib, &settings.sensor, &settings.association);
        Perceived {
            detections,
            location,
            seconds: started.elapsed().as_secs_f64(),
            detect_seconds,
        }
    };
    let mut first = run();
    for _ in 1..driving.perception_runs {
        let again = run();
        if again.seconds < first.seconds {
            first.seconds = again.seconds;
            first.detect_seconds = again.detect_seconds;
        }
    }
    first
}

/// Drives from `start` to the cell of landmark `goal` (see the module documentation).
pub fn drive(
    terrain: &Terrain,
    known: &KnownMap<Edc>,
    graph: &RouteGraph,
    settings: &RunSettings,
    start: Pose,
    goal: LandmarkId,
    driving: &Driving,
) -> Trip {
    let mut trip = Trip {
        number: 0,
        start: [start.position.x, start.position.y],
        goal,
        outcome: Outcome::OutOfSteps,
        route: Vec::new(),
        replans: 0,
        path: vec![[start.position.x, start.position.y]],
        collisions: 0,
        avoided: 0,
        navigator_seconds: Vec::new(),
        in_goal_cell: false,
        reference_m: None,
        steps: Vec::new(),
        length_m: 0.0,
        straight_m: terrain.landmark_rocks.get(&goal).map_or(f64::NAN, |&r| {
            terrain.world.rocks[r as usize]
                .position
                .distance(start.position)
        }),
    };
    let mut pose = start;
    let mut follower: Option<LegFollower> = None;
    // The last bearing each landmark was seen at, and how many steps ago: the rover keeps its
    // heading, so a bearing stays good for a few steps while its landmark is not identified.
    let mut last_seen: BTreeMap<LandmarkId, Sighted> = BTreeMap::new();
    let foot_row = foot_row(terrain.calib, driving.step_m);
    let mut approach = 0;
    let mut closed_in = 0;
    // The rover's dead reckoning in the panorama's frame: the sum of its steps as its wheels
    // measured them (exact in the simulation). Used only between sightings of a landmark.
    let mut odometry = Point::new(0.0, 0.0);
    let mut avoidance = HazardAvoidance::default();
    for index in 0..driving.max_steps {
        let (left, right) = terrain.panoramas(pose);
        let Perceived {
            detections,
            location,
            seconds: perceive_seconds,
            detect_seconds,
        } = perceive(&left, &right, terrain.calib, known, settings, driving);
        let started = Instant::now();
        let (visible, view) = &location.seen;
        for seen in last_seen.values_mut() {
            seen.ago += 1;
        }
        for (i, (&(d, l), bearing)) in location.identified.iter().zip(&view.bearings).enumerate() {
            debug_assert_eq!(visible[i], l);
            last_seen.insert(
                l,
                Sighted {
                    bearing: bearing.angle,
                    ago: 0,
                    at_foot: reaches_foot(&detections.primary[d], foot_row),
                    range: Some(location.ranges[d]).filter(|r| r.high.is_finite()),
                    odometry,
                },
            );
        }
        // The cell the follower believes it is in: the nearest identified landmark.
        let here = match cell_of(visible, &view.order) {
            Some(Cell::Certain(l)) => Some(l),
            Some(Cell::Possible(ls)) => ls.first().copied(),
            None => None,
        };
        // Ends the step's navigator time and logs the step with its decision.
        let log = |trip: &mut Trip, command, target, bearing: Option<f64>| {
            let seconds = perceive_seconds + started.elapsed().as_secs_f64();
            trip.navigator_seconds.push(seconds);
            trip.steps.push(StepLog {
                step: index,
                position: [pose.position.x, pose.position.y],
                heading_deg: pose.heading.to_degrees(),
                identified: visible.clone(),
                detections: detections.primary.len(),
                cell: here,
                command,
                target,
                bearing_deg: bearing.map(f64::to_degrees),
                replans: trip.replans,
                avoided: false,
                navigator_seconds: seconds,
                detect_seconds,
            });
        };
        if follower.is_none() {
            let planned = here.map(|from| graph.plan(from, goal, driving.cost));
            let Some(Ok(route)) = planned else {
                let (outcome, command) = match here {
                    None => (Outcome::StartUnknown, "start_unknown"),
                    Some(_) => (Outcome::NoRoute, "no_route"),
                };
                trip.outcome = outcome;
                log(&mut trip, command, None, None);
                break;
            };
            trip.route = route.landmarks.clone();
            follower = Some(LegFollower::new(&route));
        }
        let leg = follower.as_mut().expect("planned above");
        let mut command = leg.step(visible, view);
        // A route landmark that left the view at its foot is under the camera, and one the
        // rover has driven up to is beside it: reached.
        while let Command::TargetLost(target) = command {
            match last_seen.get(&target) {
                Some(seen)
                    if seen.remembered()
                        && (seen.driven_up_to(odometry)
                            || seen.at_foot
                                && left_view(
                                    seen.bearing,
                                    &detections.primary,
                                    terrain.calib,
                                    foot_row,
                                )) =>
                {
                    leg.reached(target);
                    command = leg.step(visible, view);
                }
                _ => break,
            }
        }
        if let Command::TargetLost(target) = command {
            command = match last_seen.get(&target) {
                Some(seen) if seen.remembered() => Command::Toward {
                    landmark: target,
                    bearing: seen.bearing_from(odometry),
                },
                _ => match replan(
                    graph,
                    here,
                    goal,
                    driving.cost,
                    (visible, view),
                    trip.replans,
                ) {
                    Some(route) => {
                        trip.replans += 1;
                        let mut next = LegFollower::new(&route);
                        let command = next.step(visible, view);
                        follower = Some(next);
                        command
                    }
                    // No route's next landmark in view: head for where the goal was last
                    // seen, if ever, and look again from there.
                    None => match last_seen.get(&goal) {
                        Some(seen) if trip.replans < REPLANS => {
                            trip.replans += 1;
                            Command::Toward {
                                landmark: goal,
                                bearing: seen.bearing,
                            }
                        }
                        _ => command,
                    },
                },
            };
        }
        // The follower arrives when the goal is the nearest *identified* landmark; a rock not
        // identified may still be nearer. Until the panorama proves the goal nearer than every
        // detection, the rover closes in on the goal for a few more steps.
        if command == Command::Arrived
            && location.whereabouts != (Whereabouts::Certain { landmark: goal })
            && approach < APPROACH_STEPS
            && closed_in == 0
        {
            if let Some(seen) = last_seen
                .get(&goal)
                .filter(|s| s.remembered() && !s.driven_up_to(odometry))
            {
                approach += 1;
                command = Command::Toward {
                    landmark: goal,
                    bearing: seen.bearing_from(odometry),
                };
            }
        }
        // Arrived: close in on the goal until the hazard cameras stop the rover at it.
        // Then, if another landmark the rover remembers is about as near, round the goal to
        // its far side.
        let closing = match command {
            Command::Arrived if closed_in < FINAL_APPROACH_STEPS => last_seen
                .get(&goal)
                .filter(|s| s.remembered())
                .and_then(|seen| {
                    final_approach(terrain, pose, seen, odometry, driving.step_m).or_else(|| {
                        let others: Vec<Point> = last_seen
                            .iter()
                            .filter(|(l, s)| **l != goal && s.remembered())
                            .filter_map(|(_, s)| s.way_from(odometry))
                            .collect();
                        let goal_way = seen.way_from(odometry)?;
                        far_side(goal_way, &others, driving.step_m)
                            .map(|(bearing, length)| (bearing, Approach::Around(length)))
                    })
                }),
            _ => None,
        };
        let (name, target, bearing) = match (command, closing) {
            (_, Some((bearing, _))) => ("closing_in", Some(goal), Some(bearing)),
            (Command::Arrived, None) => ("arrived", None, None),
            (Command::Toward { landmark, bearing }, None) => {
                ("toward", Some(landmark), Some(bearing))
            }
            (Command::TargetLost(landmark), None) => ("lost", Some(landmark), None),
        };
        log(&mut trip, name, target, bearing);
        let Some(bearing) = bearing else {
            trip.outcome = if command == Command::Arrived {
                Outcome::Arrived
            } else {
                Outcome::Lost
            };
            break;
        };
        let avoided = trip.avoided;
        if closing.is_some() {
            // The follower has arrived; the approach only brings the rover nearer.
            trip.outcome = Outcome::Arrived;
            closed_in += 1;
        }
        let next = match closing {
            Some((_, Approach::Straight(run))) => {
                toward(pose.position, pose.heading + bearing, run)
            }
            Some((_, Approach::Around(length))) => {
                step(terrain, &mut avoidance, pose, bearing, length, &mut trip)
            }
            None => step(
                terrain,
                &mut avoidance,
                pose,
                bearing,
                driving.step_m,
                &mut trip,
            ),
        };
        if let Some(log) = trip.steps.last_mut() {
            log.avoided = trip.avoided > avoided;
        }
        trip.length_m += pose.position.distance(next);
        let (dx, dy) = (next.x - pose.position.x, next.y - pose.position.y);
        let (sin, cos) = pose.heading.sin_cos();
        odometry = odometry + Point::new(dx * cos + dy * sin, dy * cos - dx * sin);
        pose.position = next;
        trip.path.push([next.x, next.y]);
    }
    trip.in_goal_cell = terrain.in_true_cell(pose.position, goal);
    trip.reference_m = terrain.reference(start.position, goal);
    trip
}

/// What the rover last saw of a landmark.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sighted {
    /// Bearing in the panorama's frame, radians.
    bearing: f64,
    /// Steps since.
    ago: usize,
    /// Its detection reached the panorama's foot ([`foot_row`]).
    at_foot: bool,
    /// Its range interval then, from all cues (`Location::ranges`), metres: from the rock's
    /// near side to the farthest its centre may be. `None` when the cues set no far bound.
    range: Option<RangeInterval>,
    /// The rover's dead reckoning then (the panorama's frame).
    odometry: Point,
}

impl Sighted {
    /// Where the rock is, by dead reckoning (the panorama's frame): its last bearing, at the
    /// middle of its range interval.
    fn rock(&self) -> Option<Point> {
        let range = self.range?;
        let middle = 0.5 * (range.low + range.high);
        let (sin, cos) = self.bearing.sin_cos();
        Some(self.odometry + Point::new(middle * cos, middle * sin))
    }

    /// Whether the rover still knows where the landmark is: seen in the last [`MEMORY_STEPS`],
    /// or in the last [`DEAD_RECKONING_STEPS`] with a bounded range, where dead reckoning
    /// keeps its place (and [`Sighted::driven_up_to`] ends the drive to it).
    fn remembered(&self) -> bool {
        self.ago <= MEMORY_STEPS || self.range.is_some() && self.ago <= DEAD_RECKONING_STEPS
    }

    /// The bearing to drive to the rock from dead reckoning `odometry`: toward its place
    /// ([`Sighted::rock`]), which stays right when the hazard avoidance turned the rover
    /// aside; its last bearing when its range has no far bound.
    fn bearing_from(&self, odometry: Point) -> f64 {
        self.way_from(odometry)
            .map_or(self.bearing, |way| way.y.atan2(way.x))
    }

    /// The way from dead reckoning `odometry` to the rock's place ([`Sighted::rock`]).
    fn way_from(&self, odometry: Point) -> Option<Point> {
        Some(self.rock()? - odometry)
    }

    /// Whether the rover, at dead reckoning `odometry`, has driven up to the rock: as far on
    /// its last bearing as the nearest its near side may be, less [`CLEARANCE_M`], where the
    /// hazard cameras keep the rover. Driving on the last bearing any farther passes the rock.
    fn driven_up_to(&self, odometry: Point) -> bool {
        let (Some(range), (sin, cos)) = (self.range, self.bearing.sin_cos()) else {
            return false;
        };
        let driven = odometry - self.odometry;
        driven.x * cos + driven.y * sin >= range.low - CLEARANCE_M
    }
}

/// How the final approach drives its step ([`final_approach`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Approach {
    /// Straight on the bearing, this many metres.
    Straight(f64),
    /// This many metres on the bearing, as the hazard avoidance drives a step: around a rock
    /// in the way that is not the goal's (farther from its place than the hazard cameras'
    /// stop), or round the goal to its far side ([`far_side`]).
    Around(f64),
}

/// The final approach's next step once the follower has arrived, from dead reckoning
/// `odometry`: the bearing of the goal's rock ([`Sighted::rock`]), and how to drive it.
/// Straight, up to the rock's estimated place, up to where the hazard cameras stop the rover
/// [`CLEARANCE_M`] from a rock ([`clear_run`]), and at most one step; around a rock that
/// stops the rover farther than that from the goal's near side. `None` when the rover can
/// drive no nearer.
///
/// Why: arriving by range order, or by the goal leaving the view at its foot, leaves the rover
/// anywhere up to the blind zone's 2.1 m from the goal, where a neighbour under the camera is
/// often nearer. A Voronoi cell is convex and holds its landmark, so driving straight at the
/// goal never leaves its cell once in it, and ends in it near enough to the rock.
fn final_approach(
    terrain: &Terrain,
    pose: Pose,
    seen: &Sighted,
    odometry: Point,
    step_m: f64,
) -> Option<(f64, Approach)> {
    let (way, range) = (seen.way_from(odometry)?, seen.range?);
    let (left, bearing) = (way.x.hypot(way.y), way.y.atan2(way.x));
    if left < MIN_APPROACH_M {
        return None;
    }
    let azimuth = pose.heading + bearing;
    let run = clear_run(
        terrain.world,
        pose.position,
        azimuth,
        left.min(step_m),
        CLEARANCE_M,
    );
    if run >= MIN_APPROACH_M {
        return Some((bearing, Approach::Straight(run)));
    }
    // Stopped: by the goal's rock, or by another one in front of it.
    let near_side = left - 0.5 * (range.high - range.low);
    (near_side > 2.0 * CLEARANCE_M).then_some((bearing, Approach::Around(step_m)))
}

/// The next step round the goal once the rover can drive no nearer to it, if another landmark
/// it remembers (`others`, the ways to their estimated places by dead reckoning, as `goal`'s)
/// is less than [`FAR_SIDE_MARGIN_M`] farther from the rover than the goal: along the circle
/// about the goal's place through the rover, the shorter way round toward the point of that
/// circle farthest into the goal's cell, at most a step. `(bearing, length)` of the chord to
/// drive, as the hazard avoidance drives a step; `None` when no point of the circle is better.
///
/// Why: closing in ends at the first rock's clearance on the way to the goal. Between two rocks
/// standing close together, that is where their cells meet (marsyard seed 11, half resolution:
/// three of 40 trips ended 0.5–0.8 m from both the goal and a neighbour, within 0.06 m of the
/// border, on the neighbour's side). The chord is driven by the hazard avoidance, which tests
/// where a step ends: held to the straight run the hazard cameras allow, a rover stopped at
/// the goal's clearance could not start round it, as every chord of the circle dips into it
/// (marsyard seed 7, full resolution: trips 33 and 94 of 100 stopped there 0.1–0.2 m from the
/// goal's cell).
fn far_side(goal: Point, others: &[Point], step_m: f64) -> Option<(f64, f64)> {
    let here = Point::new(0.0, 0.0);
    // How much nearer the goal's place is than every other landmark's.
    let margin = |x: Point| {
        others
            .iter()
            .map(|o| o.distance(x))
            .fold(f64::INFINITY, f64::min)
            - goal.distance(x)
    };
    let now = margin(here);
    if now >= FAR_SIDE_MARGIN_M {
        return None;
    }
    let radius = goal.distance(here);
    let on_circle = |angle: f64| goal + Point::new(radius * angle.cos(), radius * angle.sin());
    let start = (-goal.y).atan2(-goal.x);
    let best = (0..FAR_SIDE_DIRECTIONS)
        .map(|k| start + TAU * k as f64 / FAR_SIDE_DIRECTIONS as f64)
        .max_by(|&a, &b| margin(on_circle(a)).total_cmp(&margin(on_circle(b))))?;
    if margin(on_circle(best)) <= now + MIN_APPROACH_M {
        return None;
    }
    let turn = (best - start).sin().atan2((best - start).cos());
    let next = on_circle(start + turn.signum() * (step_m / radius).min(turn.abs()));
    let length = next.distance(here);
    (length >= MIN_APPROACH_M).then_some((next.y.atan2(next.x), length))
}

/// How much nearer than any other landmark the rover should be to the goal's estimated place
/// before it stops, metres ([`far_side`]): range intervals put places a few tenths of a metre
/// off at the ranges the rover last saw them from.
const FAR_SIDE_MARGIN_M: f64 = 0.3;

/// Points of the circle about the goal that [`far_side`] compares.
const FAR_SIDE_DIRECTIONS: usize = 36;

/// The first row of the panorama's foot: below it lies flat ground within one step of the
/// nearest ground the camera sees, so a rock reaching it may be under the camera after the
/// next step.
fn foot_row(calib: &Calibration, step_m: f64) -> f64 {
    let bottom = f64::from(calib.image.height);
    calib
        .ground_range(bottom)
        .map_or(bottom, |nearest| calib.ground_row(nearest + step_m))
}

/// Whether detection `d`'s lowest row (its bottom edge) reaches the foot ([`foot_row`]).
fn reaches_foot(d: &Detection, foot_row: f64) -> bool {
    f64::from(d.bbox[3]) + 1.0 >= foot_row
}

/// Whether no detection reaching the panorama's foot lies on `bearing` (within
/// [`STILL_IN_VIEW_RAD`]): a rock last seen at the foot on that bearing has left the view
/// under the camera. A farther rock behind it, now uncovered, does not reach the foot.
fn left_view(bearing: f64, detections: &[Detection], calib: &Calibration, foot_row: f64) -> bool {
    let width = f64::from(calib.image.width);
    let margin = STILL_IN_VIEW_RAD / calib.column_width();
    let column = calib.column(bearing);
    !detections.iter().any(|d| {
        let (first, last) = (f64::from(d.bbox[0]), f64::from(d.bbox[2]) + 1.0);
        // A blob straddling the seam has columns past the width.
        reaches_foot(d, foot_row)
            && [column, column + width]
                .iter()
                .any(|&c| c >= first - margin && c <= last + margin)
    })
}

/// A route from the rover's cell `here` to `goal` whose first landmark to drive to is in view
/// (`visible`, seen as `view`): the cheapest of the few cheapest routes. With none (the cell
/// is wrong, or its routes' next landmarks are not identified), the cheapest route from a
/// landmark in view that the follower can start on: its first target in view (a route through
/// the rover's certain cell whose next landmark is out of view would lose the trip at once).
/// None once [`REPLANS`] are used.
fn replan(
    graph: &RouteGraph,
    here: Option<LandmarkId>,
    goal: LandmarkId,
    cost: RouteCost,
    (visible, view): (&[LandmarkId], &StationView),
    replans: usize,
) -> Option<Route> {
    if replans >= REPLANS {
        return None;
    }
    let from_here = here.and_then(|here| {
        graph
            .alternatives(here, goal, cost, ALTERNATIVES)
            .ok()?
            .into_iter()
            .find(|r| {
                let next = r.landmarks.get(1).unwrap_or(&r.landmarks[0]);
                visible.contains(next)
            })
    });
    from_here.or_else(|| {
        visible
            .iter()
            .filter_map(|&v| graph.plan(v, goal, cost).ok())
            .filter(|r| {
                let first = LegFollower::new(r).step(visible, view);
                !matches!(first, Command::TargetLost(_))
            })
            .min_by(|a, b| a.cost.total_cmp(&b.cost))
    })
}

/// One step from `pose` toward `bearing` (the panorama's frame), around the rocks in the way
/// by the trip's `avoidance`; records avoidance and collisions in `trip`.
fn step(
    terrain: &Terrain,
    avoidance: &mut HazardAvoidance,
    pose: Pose,
    bearing: f64,
    length: f64,
    trip: &mut Trip,
) -> Point {
    let (from, azimuth) = (pose.position, pose.heading + bearing);
    let straight = toward(from, azimuth, length);
    let next = avoidance
        .drive(terrain.world, from, azimuth, length, CLEARANCE_M)
        .unwrap_or(from);
    if next.distance(straight) > AVOIDED_M {
        trip.avoided += 1;
    }
    if terrain.crosses(from, next) {
        trip.collisions += 1;
    }
    next
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::default_calibration;
    use qrm_core::measurement::{Bearing, RangeOrder};
    use qrm_core::neighborhood::{RngEdge, RngEstimate};
    use qrm_vision::detection::{Appearance, Separation};
    use std::f64::consts::FRAC_PI_2;

    /// A trip of one step along x for each of `seconds`, each taking that long.
    fn timed_trip(seconds: &[f64]) -> Trip {
        Trip {
            number: 0,
            start: [0.0, 0.0],
            goal: 1,
            outcome: Outcome::Arrived,
            route: vec![1],
            replans: 0,
            path: (0..=seconds.len()).map(|k| [k as f64 * 0.5, 0.0]).collect(),
            collisions: 0,
            avoided: 0,
            navigator_seconds: seconds.to_vec(),
            in_goal_cell: true,
            length_m: seconds.len() as f64 * 0.5,
            straight_m: 1.0,
            reference_m: None,
            steps: seconds
                .iter()
                .enumerate()
                .map(|(k, &s)| StepLog {
                    step: k,
                    position: [k as f64 * 0.5, 0.0],
                    heading_deg: 0.0,
                    identified: vec![1],
                    detections: 1,
                    cell: Some(1),
                    command: "toward",
                    target: Some(1),
                    bearing_deg: Some(0.0),
                    replans: 0,
                    avoided: false,
                    navigator_seconds: s,
                    detect_seconds: s / 2.0,
                })
                .collect(),
        }
    }

    #[test]
    fn a_trip_driven_again_keeps_each_steps_faster_time_only_for_the_same_steps() {
        let mut trip = timed_trip(&[0.3, 0.1, 0.25]);
        assert!(trip.keep_faster_steps(&timed_trip(&[0.2, 0.15, 0.05])));
        assert_eq!(trip.navigator_seconds, [0.2, 0.1, 0.05]);
        let detection: Vec<f64> = trip.steps.iter().map(|s| s.detect_seconds).collect();
        assert_eq!(detection, [0.1, 0.05, 0.025]);
        let mut elsewhere = timed_trip(&[0.01, 0.01, 0.01]);
        elsewhere.steps[1].command = "lost";
        assert!(!trip.keep_faster_steps(&elsewhere));
        assert!(!trip.keep_faster_steps(&timed_trip(&[0.01, 0.01])));
        assert_eq!(trip.navigator_seconds, [0.2, 0.1, 0.05]);
    }

    fn rock(columns: [u32; 2], rows: [u32; 2]) -> Detection {
        Detection {
            centroid: [
                f64::from(columns[0] + columns[1]) / 2.0 + 0.5,
                f64::from(rows[0] + rows[1]) / 2.0 + 0.5,
            ],
            bbox: [columns[0], rows[0], columns[1], rows[1]],
            pixels: 100,
            contact_row: f64::from(rows[1] + 1),
            contact_slack_rows: 0.0,
            appearance: Appearance {
                colour: [0.4, 0.33, 0.27],
                brightness: 0.8,
                texture: 0.1,
                dark_fraction: 0.2,
            },
            ambiguous: false,
            separation: Separation::Whole,
            blob: 0,
            beyond_columns: [0, 0],
            parallax_shifts: None,
            flat: false,
            surely_flat: false,
        }
    }

    #[test]
    fn the_foot_shows_ground_within_one_step_of_the_blind_zone() {
        let calib = default_calibration();
        let bottom = f64::from(calib.image.height);
        let nearest = calib
            .ground_range(bottom)
            .expect("the bottom row looks down");
        // 1.5 m mast, 35.7° below the horizon at the bottom row.
        assert!((nearest - 2.09).abs() < 0.01, "{nearest}");
        let row = foot_row(&calib, 0.5);
        assert!(row < bottom);
        let at_row = calib.ground_range(row).expect("below the horizon");
        assert!((at_row - (nearest + 0.5)).abs() < 1e-9);
    }

    #[test]
    fn a_rock_has_left_the_view_when_nothing_at_the_foot_lies_on_its_bearing() {
        let calib = default_calibration();
        let foot = foot_row(&calib, 0.5);
        let (first_foot_row, bottom) = (foot.ceil() as u32, calib.image.height - 1);
        let bearing = calib.azimuth(1000.5);
        let on_bearing = rock([990, 1010], [first_foot_row, bottom]);
        // A farther rock on the same bearing, uncovered once the near one is under the camera.
        let behind = rock([995, 1005], [200, first_foot_row - 20]);
        // A near rock 90 columns (7.9°) aside.
        let aside = rock([1091, 1150], [first_foot_row, bottom]);
        assert!(!left_view(bearing, &[on_bearing], &calib, foot));
        assert!(left_view(bearing, &[behind, aside], &calib, foot));
        assert!(left_view(bearing, &[], &calib, foot));
        // 4° past a rock's side, the rock may still be the one last seen.
        let within = rock([1046, 1100], [first_foot_row, bottom]);
        assert!(!left_view(bearing, &[within], &calib, foot));
        // A blob straddling the seam covers the first columns too.
        let width = calib.image.width;
        let straddling = rock([width - 10, width + 10], [first_foot_row, bottom]);
        assert!(!left_view(calib.azimuth(2.5), &[straddling], &calib, foot));
    }

    fn sighted(bearing: f64, range: Option<(f64, f64)>, odometry: Point) -> Sighted {
        Sighted {
            bearing,
            ago: 1,
            at_foot: true,
            range: range.map(|(low, high)| RangeInterval::new(low, high)),
            odometry,
        }
    }

    #[test]
    fn a_rock_is_driven_up_to_once_the_rover_is_as_far_on_its_bearing_as_its_near_side() {
        // Seen 2–2.4 m away at 90°, from dead reckoning (1, 0).
        let seen = sighted(FRAC_PI_2, Some((2.0, 2.4)), Point::new(1.0, 0.0));
        let rock = seen.rock().unwrap();
        assert!(rock.distance(Point::new(1.0, 2.2)) < 1e-12);
        let reach = 2.0 - CLEARANCE_M;
        assert!(!seen.driven_up_to(Point::new(1.0, reach - 0.01)));
        assert!(seen.driven_up_to(Point::new(1.0, reach + 0.01)));
        // Passing beside the rock counts: only the way along the bearing does.
        assert!(!seen.driven_up_to(Point::new(3.0, 1.0)));
        assert!(seen.driven_up_to(Point::new(0.2, 2.5)));
        // A rock whose cues set no far bound is never driven up to.
        let unranged = sighted(FRAC_PI_2, None, Point::new(1.0, 0.0));
        assert!(!unranged.driven_up_to(Point::new(1.0, 9.0)));
        assert_eq!(unranged.rock(), None);
    }

    #[test]
    fn the_final_approach_drives_at_the_goal_until_the_hazard_cameras_stop_it() {
        let calib = default_calibration();
        let world = World::generate(4, &[(Point::new(3.0, 0.0), 0.5)]);
        let rocks = BTreeMap::from([(0, 0)]);
        let terrain = Terrain {
            world: &world,
            calib: &calib,
            landmark_rocks: &rocks,
        };
        // The panorama's frame turned a quarter from the world's: bearing π/2 looks along +x.
        let at = |x: f64| Pose {
            position: Point::new(x, 0.0),
            heading: -FRAC_PI_2,
        };
        // Dead reckoning after driving `x` along world +x.
        let frame = |x: f64| Point::new(0.0, x);
        let near_side = 3.0 - world.contact_radius(0);
        // Seen from the start: a whole step at it.
        let seen = sighted(FRAC_PI_2, Some((near_side, 3.0)), frame(0.0));
        let (bearing, how) = final_approach(&terrain, at(0.0), &seen, frame(0.0), 0.5).unwrap();
        assert!((bearing - FRAC_PI_2).abs() < 1e-12 && how == Approach::Straight(0.5));
        // Near the rock: up to the clearance from its footprint, and no farther.
        let stop = near_side - CLEARANCE_M;
        let near = stop - 0.22;
        let how = final_approach(&terrain, at(near), &seen, frame(near), 0.5)
            .unwrap()
            .1;
        assert!(
            matches!(how, Approach::Straight(run) if run <= 0.22 && run > 0.22 - 0.05),
            "{how:?}"
        );
        assert_eq!(
            final_approach(&terrain, at(stop), &seen, frame(stop), 0.5),
            None
        );
        // Dead reckoning turns the bearing toward the rock after a detour.
        let aside = Pose {
            position: Point::new(1.0, 1.0),
            heading: -FRAC_PI_2,
        };
        let (bearing, _) =
            final_approach(&terrain, aside, &seen, Point::new(-1.0, 1.0), 0.5).unwrap();
        let way = Point::new(0.5 * (near_side + 3.0) - 1.0, -1.0);
        assert!((aside.heading + bearing - way.y.atan2(way.x)).abs() < 1e-12);
        // A goal seen 1 m away in open ground: the approach ends where it was estimated.
        let short = sighted(-FRAC_PI_2, Some((1.0, 1.0)), frame(0.0));
        let how = final_approach(&terrain, at(0.0), &short, frame(0.0), 1.5)
            .unwrap()
            .1;
        assert!(
            matches!(how, Approach::Straight(run) if (run - 1.0).abs() < 1e-12),
            "{how:?}"
        );
        let there = Point::new(0.0, -1.0);
        assert_eq!(final_approach(&terrain, at(0.0), &short, there, 0.5), None);
        // No far bound: no approach.
        let unranged = sighted(FRAC_PI_2, None, frame(0.0));
        assert_eq!(
            final_approach(&terrain, at(0.0), &unranged, frame(0.0), 0.5),
            None
        );
    }

    /// A map that made two landmarks of one rock: a rover at that rock is in both landmarks'
    /// true cells, whichever of them a trip was given as its goal.
    #[test]
    fn two_landmarks_of_one_rock_share_its_true_cell() {
        let calib = default_calibration();
        let placements = [(Point::new(5.0, 0.0), 0.5), (Point::new(0.0, 0.0), 0.5)];
        let world = World::generate(5, &placements);
        // Landmarks 0 and 2 both stand for rock 0 (a rock the map duplicated).
        let rocks = BTreeMap::from([(0, 0), (1, 1), (2, 0)]);
        let terrain = Terrain {
            world: &world,
            calib: &calib,
            landmark_rocks: &rocks,
        };
        let by_the_first = Point::new(4.0, 0.0);
        assert!(terrain.in_true_cell(by_the_first, 0));
        assert!(terrain.in_true_cell(by_the_first, 2));
        assert!(!terrain.in_true_cell(by_the_first, 1));
        let by_the_second = Point::new(1.0, 0.0);
        assert!(terrain.in_true_cell(by_the_second, 1));
        assert!(!terrain.in_true_cell(by_the_second, 2));
        assert!(
            !terrain.in_true_cell(by_the_second, 7),
            "a landmark the map lacks"
        );
    }

    #[test]
    fn the_final_approach_goes_around_a_rock_in_front_of_the_goal() {
        let calib = default_calibration();
        // The goal at x = 5, another rock at x = 2 on the way to it.
        let placements = [(Point::new(5.0, 0.0), 0.5), (Point::new(2.0, 0.0), 0.5)];
        let world = World::generate(5, &placements);
        let rocks = BTreeMap::from([(0, 0), (1, 1)]);
        let terrain = Terrain {
            world: &world,
            calib: &calib,
            landmark_rocks: &rocks,
        };
        let near_side = 5.0 - world.contact_radius(0);
        let seen = sighted(0.0, Some((near_side, 5.0)), Point::new(0.0, 0.0));
        let at = |x: f64| Pose {
            position: Point::new(x, 0.0),
            heading: 0.0,
        };
        let stopped = 2.0 - world.contact_radius(1) - CLEARANCE_M;
        let (bearing, how) =
            final_approach(&terrain, at(stopped), &seen, Point::new(stopped, 0.0), 0.5).unwrap();
        assert_eq!((bearing, how), (0.0, Approach::Around(0.5)));
        // Stopped by the goal itself: done.
        let at_goal = near_side - CLEARANCE_M;
        let done = final_approach(&terrain, at(at_goal), &seen, Point::new(at_goal, 0.0), 0.5);
        assert_eq!(done, None);
    }

    #[test]
    fn the_rover_rounds_the_goal_away_from_a_neighbour_as_near_as_the_goal() {
        let (goal, neighbour) = (Point::new(2.0, 0.0), Point::new(2.0, 1.2));
        let way = |from: Point, to: Point| to - from;
        // On the border of the two cells: a step round the goal into the goal's cell, as far
        // from the goal's centre as before (heading 0: the panorama's frame is the world's,
        // less the rover's position).
        let border = Point::new(1.4, 0.6);
        let (bearing, length) = far_side(way(border, goal), &[way(border, neighbour)], 0.5)
            .expect("a step round the goal");
        let next = toward(border, bearing, length);
        assert!(length > 0.3, "{length}");
        let margin = |p: Point| p.distance(neighbour) - p.distance(goal);
        assert!(margin(next) > margin(border) + 0.2, "{next:?}");
        assert!((next.distance(goal) - border.distance(goal)).abs() < 1e-9);
        // Its first step takes the shorter way round: west of the goal, away from the
        // neighbour.
        assert!(next.x < border.x && next.y < border.y, "{next:?}");
        // Clearly in the goal's cell, or with no other landmark remembered: no step.
        let inside = Point::new(1.3, -0.2);
        assert_eq!(
            far_side(way(inside, goal), &[way(inside, neighbour)], 0.5),
            None
        );
        assert_eq!(far_side(way(border, goal), &[], 0.5), None);
    }

    #[test]
    fn a_rover_stopped_at_the_goals_clearance_still_rounds_it() {
        // Closing in ends where the hazard cameras stop the rover: at the clearance of the
        // goal's footprint, here nearly on the border with a neighbour's cell.
        let (goal, neighbour) = (Point::new(2.0, 0.0), Point::new(2.0, 1.0));
        let world = World::generate(6, &[(goal, 0.2), (neighbour, 0.2)]);
        let stop_radius = world.contact_radius(0) + CLEARANCE_M + 1e-3;
        let angle = 120f64.to_radians();
        let stopped = goal + Point::new(stop_radius * angle.cos(), stop_radius * angle.sin());
        let margin = |p: Point| p.distance(neighbour) - p.distance(goal);
        assert!(margin(stopped) < FAR_SIDE_MARGIN_M, "{}", margin(stopped));
        let (bearing, length) =
            far_side(goal - stopped, &[neighbour - stopped], 0.5).expect("a step round the goal");
        // Every chord of the circle dips into the goal's clearance: the hazard cameras allow
        // no straight run along it, and a rover held to that run stood there.
        assert!(clear_run(&world, stopped, bearing, length, CLEARANCE_M) < MIN_APPROACH_M);
        // Driven as the hazard avoidance drives a step, it goes round, clear of both rocks.
        let next = HazardAvoidance::default()
            .drive(&world, stopped, bearing, length, CLEARANCE_M)
            .expect("a clear step");
        for (k, rock) in (0..).zip([goal, neighbour]) {
            assert!(next.distance(rock) >= world.contact_radius(k) + CLEARANCE_M);
        }
        assert!(margin(next) > margin(stopped) + 0.3, "{next:?}");
    }

    #[test]
    fn replanning_starts_from_a_landmark_in_view_when_no_route_from_the_cell_is() {
        // 0–1–2–3–4, goal 4.
        let rng = RngEstimate {
            edges: [(0, 1), (1, 2), (2, 3), (3, 4)]
                .iter()
                .map(|&(a, b)| RngEdge { a, b, cost: 0.0 })
                .collect(),
            pruned: 0,
        };
        let graph = RouteGraph::new(&[0, 1, 2, 3, 4], &rng);
        let cost = RouteCost { lambda: 1.0 };
        // Landmarks in view, by position; `nearest`: the one the range order shows nearest.
        let view = |n: usize, nearest: Option<usize>| {
            let order = match nearest {
                Some(k) => RangeOrder::from_pairs(
                    n,
                    &(0..n)
                        .filter(|&j| j != k)
                        .map(|j| (k, j))
                        .collect::<Vec<_>>(),
                ),
                None => Ok(RangeOrder::unordered(n)),
            };
            StationView::new(
                (0..n).map(|i| Bearing::exact(i as f64)).collect(),
                order.unwrap(),
            )
            .unwrap()
        };
        let replanned = |here, visible: &[LandmarkId], nearest, replans| {
            replan(
                &graph,
                here,
                4,
                cost,
                (visible, &view(visible.len(), nearest)),
                replans,
            )
            .map(|r| r.landmarks)
        };
        // The cell's route, its next landmark in view.
        assert_eq!(
            replanned(Some(0), &[1, 3], None, 0),
            Some(vec![0, 1, 2, 3, 4])
        );
        // Its next landmark not in view: drive to the landmark in view nearest the goal first.
        assert_eq!(replanned(Some(0), &[2, 3], None, 0), Some(vec![3, 4]));
        assert_eq!(replanned(None, &[2, 0], None, 0), Some(vec![2, 3, 4]));
        // Every route in view passes 3, whose cell the rover is certainly in, with 4 out of
        // view: each would be lost at once.
        assert_eq!(replanned(None, &[3, 1], Some(0), 0), None);
        // With a way round 3 (1–5–4), that one.
        let rng = RngEstimate {
            edges: [(1, 2), (2, 3), (3, 4), (1, 5), (5, 4)]
                .iter()
                .map(|&(a, b)| RngEdge { a, b, cost: 0.0 })
                .collect(),
            pruned: 0,
        };
        let round = RouteGraph::new(&[1, 2, 3, 4, 5], &rng);
        let in_three = view(2, Some(0));
        let route = replan(&round, None, 4, cost, (&[3, 1], &in_three), 0);
        assert_eq!(route.map(|r| r.landmarks), Some(vec![1, 5, 4]));
        assert_eq!(replanned(Some(0), &[], None, 0), None);
        assert_eq!(replanned(Some(0), &[1], None, REPLANS), None);
    }
}
