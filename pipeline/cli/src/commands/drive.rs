//! `pipeline navigate drive`: closed-loop trips through the rendered world of a synthetic
//! dataset, navigating on the map a `pipeline run` built from it (`qrm_synth::closed_loop`,
//! docs/NAVIGATION.md "Closed loop through rendered panoramas").

use super::locate::{load_run, read_landmark_rocks};
use super::quantile;
use crate::recording::navigation_log::{self, write_drive_log};
use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use qrm_atomic_file::OutputSet;
use qrm_core::edc::Edc;
use qrm_core::geometry::Point;
use qrm_core::map::LandmarkId;
use qrm_core::navigation::{RouteCost, RouteGraph};
use qrm_core::neighborhood::{estimate, true_rng, RngEstimate};
use qrm_plot::{write_flow, FlowPicture};
use qrm_synth::closed_loop::{drive, Driving, Outcome, Terrain, Trip, CLEARANCE_M};
use qrm_synth::dataset::{Counts, Preset};
use qrm_synth::{Pose, World};
use qrm_vision::calib::Calibration;
use qrm_vision::localization::KnownMap;
use qrm_vision::run::RunSettings;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::TAU;
use std::fmt::Write;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct DriveArgs {
    /// The synthetic dataset whose world the rover drives in (its truth.json names the preset
    /// and seed the world is rendered from again, its calib.toml the camera).
    #[arg(long)]
    images: PathBuf,
    /// The map's run: `pipeline run --images DATASET --out RUN` (map.json, landmarks.json,
    /// stations.json, and eval.json, which says which rock each landmark is, for judging).
    #[arg(long)]
    run: PathBuf,
    /// Trips: random starts clear of rocks, random goal landmarks (the first three share
    /// their goal, for the figure).
    #[arg(long, default_value_t = 20)]
    trips: usize,
    /// Drive only these trips of the seeded sequence (numbered from 0, as trips.csv numbers
    /// them), each exactly as the whole drive would: to look again at a trip and its log,
    /// e.g. `--trips 100 --only 41,57`.
    #[arg(long, value_delimiter = ',')]
    only: Vec<usize>,
    #[command(flatten)]
    driving: DrivingArgs,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Time each step's navigator compute with its perception (detection and association)
    /// run this many times, the fastest counting, as `navigate locate --repeat` does: the
    /// fastest run is the code's own time, the others add what else the machine was doing.
    /// The runs are identical, and the rover acts on the first: the trips are the same.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    repeat: u32,
    /// Drive the trips that hold a step slower than this many seconds once more, and keep
    /// each step's faster time: the fastest of `--repeat` runs filters out a busy moment of
    /// the machine, not a slow spell of minutes. The trips are the same, e.g. `--repeat 3
    /// --again-over 0.2` for the step-time benchmark (docs/BENCHMARKS.md).
    #[arg(long, value_name = "SECONDS")]
    again_over: Option<f64>,
    /// Also write OUT/drive.rrd for the rerun viewer (needs a build with `--features rerun`).
    #[arg(long)]
    rrd: bool,
    /// Output directory: trips.json, trips.csv, summary.json, drive.png, drive.mcap (every
    /// step).
    #[arg(long, default_value = "drive")]
    out: PathBuf,
}

/// What `navigate drive` and `navigate flowfield` drive in and on: a synthetic dataset's world
/// rendered again, and the map of a run over it with its RNG estimate and route graph.
pub(super) struct ClosedLoop {
    pub calib: Calibration,
    pub world: World,
    /// "preset P, seed S".
    pub origin: String,
    pub known: KnownMap<Edc>,
    /// The rock each landmark stands for (eval.json), for judging.
    pub landmark_rocks: BTreeMap<LandmarkId, u32>,
    pub rng_estimate: RngEstimate,
    pub graph: RouteGraph,
}

impl ClosedLoop {
    pub fn load(images: &Path, run: &Path) -> Result<ClosedLoop> {
        let (calib, world, origin) = rendered_world(images)?;
        let (known, landmark_rocks) = run_of(run, &world, images)?;
        let rng_estimate = estimate(&known.map).expect("EDC has a lune");
        let graph = RouteGraph::new(known.map.landmarks(), &rng_estimate);
        Ok(ClosedLoop {
            calib,
            world,
            origin,
            known,
            landmark_rocks,
            rng_estimate,
            graph,
        })
    }

    pub fn terrain(&self) -> Terrain<'_> {
        Terrain {
            world: &self.world,
            calib: &self.calib,
            landmark_rocks: &self.landmark_rocks,
        }
    }
}

/// How the rover drives (`navigate drive` and `navigate flowfield`).
#[derive(Args, Debug)]
pub(super) struct DrivingArgs {
    /// Step length, metres.
    #[arg(long, default_value_t = 0.5)]
    step: f64,
    /// Steps before a trip is given up.
    #[arg(long, default_value_t = 120)]
    max_steps: usize,
    /// Weight λ of an edge's RNG cost against one hop.
    #[arg(long, default_value_t = 1.0)]
    lambda: f64,
}

impl DrivingArgs {
    pub fn driving(&self) -> Result<Driving> {
        if !(self.step > 0.0 && self.step.is_finite()) {
            bail!("--step {} must be a positive length", self.step);
        }
        if !(self.lambda >= 0.0 && self.lambda.is_finite()) {
            bail!("--lambda {} must be a finite number ≥ 0", self.lambda);
        }
        Ok(Driving {
            step_m: self.step,
            max_steps: self.max_steps,
            cost: RouteCost {
                lambda: self.lambda,
            },
            perception_runs: 1,
        })
    }
}

pub fn run(args: &DriveArgs) -> Result<()> {
    if args.trips == 0 {
        bail!("--trips must be at least 1");
    }
    if let Some(k) = args.only.iter().find(|&&k| k >= args.trips) {
        bail!(
            "--only {k}: the drive has trips 0 to {} (--trips {})",
            args.trips - 1,
            args.trips
        );
    }
    let driving = Driving {
        perception_runs: args.repeat as usize,
        ..args.driving.driving()?
    };
    if let Some(limit) = args.again_over.filter(|l| !(l.is_finite() && *l >= 0.0)) {
        bail!("--again-over {limit} must be a finite number of seconds ≥ 0");
    }
    #[cfg(not(feature = "rerun"))]
    if args.rrd {
        bail!("--rrd needs a build with the rerun feature: cargo build --release -p pipeline --features rerun");
    }
    let closed = ClosedLoop::load(&args.images, &args.run)?;
    let terrain = closed.terrain();
    let ClosedLoop {
        world,
        origin,
        known,
        landmark_rocks,
        rng_estimate,
        graph,
        ..
    } = &closed;
    let goals: Vec<LandmarkId> = landmark_rocks.keys().copied().collect();
    if goals.is_empty() {
        bail!("the run's map has no landmark standing for a rock: nothing to drive to");
    }
    let settings = RunSettings::default();
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    // The trips driven: all, or those `--only` names.
    let only: BTreeSet<usize> = args.only.iter().copied().collect();
    let bar = ProgressBar::new(if only.is_empty() {
        args.trips
    } else {
        only.len()
    } as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} drive     [{bar:40}] {pos}/{len} trips ({elapsed}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    let mut trips = Vec::new();
    // Each trip's start and goal, to drive it again.
    let mut drawn = Vec::new();
    let mut shared_goal = None;
    for k in 0..args.trips {
        let start = random_start(world, &mut rng, &args.images)?;
        let goal = match (k < 3, shared_goal) {
            (true, Some(goal)) => goal,
            _ => goals[rng.random_range(0..goals.len())],
        };
        shared_goal.get_or_insert(goal);
        if !only.is_empty() && !only.contains(&k) {
            continue;
        }
        let mut trip = drive(&terrain, known, graph, &settings, start, goal, &driving);
        trip.number = k;
        trips.push(trip);
        drawn.push((start, goal));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let mut timing = Timing {
        fastest_of_runs: driving.perception_runs,
        again_over: args.again_over,
        driven_again: 0,
    };
    if let Some(limit) = args.again_over {
        let slow: Vec<usize> = (0..trips.len())
            .filter(|&t| trips[t].navigator_seconds.iter().any(|&s| s > limit))
            .collect();
        let bar = super::simulate::progress(slow.len() as u64, "trips driven again");
        for t in slow {
            let (start, goal) = drawn[t];
            let again = drive(&terrain, known, graph, &settings, start, goal, &driving);
            if !trips[t].keep_faster_steps(&again) {
                bail!(
                    "trip {} took other steps when driven again: the drive is not repeatable",
                    trips[t].number
                );
            }
            timing.driven_again += 1;
            bar.inc(1);
        }
        bar.finish_and_clear();
    }

    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let summary = summarize(&trips, &timing);
    // The files replace an earlier drive's together.
    let mut outputs = OutputSet::new();
    for (name, text) in [
        ("trips.json", serde_json::to_string_pretty(&trips)? + "\n"),
        ("trips.csv", trips_csv(&trips)),
        (
            "summary.json",
            serde_json::to_string_pretty(&summary)? + "\n",
        ),
    ] {
        let path = args.out.join(name);
        outputs
            .stage_bytes(&path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let picture = figure(
        world,
        landmark_rocks,
        rng_estimate,
        &trips,
        trips[0].goal,
        Grid {
            arrow_length: 1.0,
            ..Grid::default()
        },
        format!(
            "Closed loop through rendered panoramas: {} trips to landmark {}",
            trips
                .iter()
                .filter(|t| t.goal == trips[0].goal)
                .take(3)
                .count(),
            trips[0].goal
        ),
    );
    outputs.stage(&args.out.join("drive.png"), |temporary| {
        write_flow(temporary, &picture)
    })?;
    let log = args.out.join("drive.mcap");
    outputs
        .stage(&log, |temporary| write_drive_log(temporary, &trips))
        .with_context(|| format!("cannot write {}", log.display()))?;
    #[cfg(feature = "rerun")]
    if args.rrd {
        use crate::recording::navigation_rerun::{write_drive_rrd, DriveScene};
        let scene = DriveScene {
            rocks: world
                .rocks
                .iter()
                .map(|r| ([r.position.x, r.position.y], world.contact_radius(r.id)))
                .collect(),
            landmarks: landmark_rocks
                .iter()
                .map(|(&l, &r)| {
                    let p = world.rocks[r as usize].position;
                    (l, [p.x, p.y])
                })
                .collect(),
        };
        let rrd = args.out.join("drive.rrd");
        outputs
            .stage(&rrd, |temporary| write_drive_rrd(temporary, &scene, &trips))
            .with_context(|| format!("cannot write {}", rrd.display()))?;
    }
    outputs
        .commit()
        .with_context(|| format!("cannot move the outputs into {}", args.out.display()))?;
    println!(
        "{} trips in {} ({origin}), map of {} landmarks from {}:",
        trips.len(),
        args.images.display(),
        known.map.len(),
        args.run.display()
    );
    println!("{}", serde_json::to_string_pretty(&summary)?);
    println!(
        "wrote {}, trips.csv, {}, {} and {} (every step, topic {})",
        args.out.join("trips.json").display(),
        args.out.join("summary.json").display(),
        args.out.join("drive.png").display(),
        args.out.join("drive.mcap").display(),
        navigation_log::TOPIC
    );
    Ok(())
}

/// A random pose among the rocks, clear of them (twice the hazard clearance from every
/// footprint), facing a random way: a trip's start.
pub(super) fn random_start(world: &World, rng: &mut ChaCha8Rng, images: &Path) -> Result<Pose> {
    let (low, high) = extent(world);
    if !(low.x < high.x && low.y < high.y) {
        bail!(
            "{}: the rocks span too little ground to draw starts among them",
            images.display()
        );
    }
    for _ in 0..10_000 {
        let p = Point::new(
            rng.random_range(low.x..high.x),
            rng.random_range(low.y..high.y),
        );
        if clear_of_rocks(world, p) {
            return Ok(Pose {
                position: p,
                heading: rng.random_range(0.0..TAU),
            });
        }
    }
    bail!(
        "{}: no start point clear of the rocks in 10 000 draws",
        images.display()
    )
}

/// Whether `p` lies at least twice the hazard clearance from every rock's footprint.
pub(super) fn clear_of_rocks(world: &World, p: Point) -> bool {
    world
        .rocks
        .iter()
        .all(|r| r.position.distance(p) > world.contact_radius(r.id) + 2.0 * CLEARANCE_M)
}

/// The box the rocks lie in, shrunk by a metre: where starts are drawn.
fn extent(world: &World) -> (Point, Point) {
    let (low, high) = bounds(world.rocks.iter().map(|r| r.position));
    (
        Point::new(low.x + 1.0, low.y + 1.0),
        Point::new(high.x - 1.0, high.y - 1.0),
    )
}

/// The smallest box holding `points`, as its lower and upper corners.
pub(super) fn bounds(points: impl Iterator<Item = Point>) -> (Point, Point) {
    points.fold(
        (
            Point::new(f64::INFINITY, f64::INFINITY),
            Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(low, high), p| {
            (
                Point::new(low.x.min(p.x), low.y.min(p.y)),
                Point::new(high.x.max(p.x), high.y.max(p.y)),
            )
        },
    )
}

/// trips.csv: one row per trip (docs/NAVIGATION.md): the statistics of trips.json without
/// the paths and steps.
fn trips_csv(trips: &[Trip]) -> String {
    let mut csv = String::from(
        "trip,start_x,start_y,goal,outcome,in_goal_cell,steps,replans,collisions,avoided,length_m,straight_m,reference_m,navigator_median_s,navigator_max_s\n",
    );
    for t in trips {
        let mut seconds = t.navigator_seconds.clone();
        seconds.sort_by(f64::total_cmp);
        let outcome = serde_json::to_value(t.outcome).expect("outcome serialises");
        let _ = writeln!(
            csv,
            "{},{:.3},{:.3},{},{},{},{},{},{},{},{:.3},{:.3},{},{:.4},{:.4}",
            t.number,
            t.start[0],
            t.start[1],
            t.goal,
            outcome.as_str().unwrap_or("?"),
            t.in_goal_cell,
            t.navigator_seconds.len(),
            t.replans,
            t.collisions,
            t.avoided,
            t.length_m,
            t.straight_m,
            t.reference_m.map_or(String::new(), |r| format!("{r:.3}")),
            quantile(&seconds, 0.5),
            quantile(&seconds, 1.0)
        );
    }
    csv
}

/// How the drive timed its steps (`--repeat`, `--again-over`), for the summary.
struct Timing {
    fastest_of_runs: usize,
    again_over: Option<f64>,
    /// Trips driven once more for a step over `again_over`.
    driven_again: usize,
}

/// Success, collisions, steps, re-plans, path length and navigator time over the trips.
fn summarize(trips: &[Trip], timing: &Timing) -> serde_json::Value {
    let n = trips.len() as f64;
    let count = |f: &dyn Fn(&Trip) -> bool| trips.iter().filter(|t| f(t)).count();
    let outcomes: BTreeMap<String, usize> = [
        Outcome::Arrived,
        Outcome::StartUnknown,
        Outcome::NoRoute,
        Outcome::Lost,
        Outcome::OutOfSteps,
    ]
    .iter()
    .map(|&o| {
        (
            serde_json::to_value(o)
                .expect("serialises")
                .as_str()
                .unwrap_or("")
                .to_string(),
            count(&|t| t.outcome == o),
        )
    })
    .collect();
    let mut seconds: Vec<f64> = trips
        .iter()
        .flat_map(|t| t.navigator_seconds.clone())
        .collect();
    seconds.sort_by(f64::total_cmp);
    let mut detection: Vec<f64> = trips
        .iter()
        .flat_map(|t| t.steps.iter().map(|s| s.detect_seconds))
        .collect();
    detection.sort_by(f64::total_cmp);
    let mut ratios: Vec<f64> = trips
        .iter()
        .filter(|t| t.outcome == Outcome::Arrived && t.in_goal_cell && t.length_m > 0.0)
        .map(|t| t.length_m / t.straight_m)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let mut over_reference: Vec<f64> = trips
        .iter()
        .filter(|t| t.outcome == Outcome::Arrived && t.in_goal_cell)
        .filter_map(|t| Some(t.length_m / t.reference_m.filter(|&r| r > 0.0)?))
        .collect();
    over_reference.sort_by(f64::total_cmp);
    json!({
        "trips": trips.len(),
        "success": count(&|t| t.outcome == Outcome::Arrived && t.in_goal_cell) as f64 / n,
        "arrived_but_not_in_goal_cell": count(&|t| t.outcome == Outcome::Arrived && !t.in_goal_cell),
        "outcomes": outcomes,
        "collisions": trips.iter().map(|t| t.collisions).sum::<usize>(),
        "steps_avoided": trips.iter().map(|t| t.avoided).sum::<usize>(),
        "replans": trips.iter().map(|t| t.replans).sum::<usize>(),
        "steps": trips.iter().map(|t| t.navigator_seconds.len()).sum::<usize>(),
        "median_length_over_straight": quantile(&ratios, 0.5),
        "median_length_over_reference": quantile(&over_reference, 0.5),
        "navigator_seconds_per_step": {
            "fastest_of_runs": timing.fastest_of_runs,
            "again_over": timing.again_over,
            "trips_driven_again": timing.driven_again,
            "median": quantile(&seconds, 0.5),
            "p90": quantile(&seconds, 0.9),
            "p99": quantile(&seconds, 0.99),
            "max": quantile(&seconds, 1.0),
            "median_detection": quantile(&detection, 0.5),
        },
    })
}

/// What the navigator decided at the points of a grid (`navigate flowfield`), world
/// coordinates: a heading (unit vector), arrived, or no heading.
#[derive(Debug, Default)]
pub(super) struct Grid {
    pub arrows: Vec<(Point, (f64, f64))>,
    /// Metres, drawn; a fraction of the grid's spacing.
    pub arrow_length: f64,
    pub arrived: Vec<Point>,
    pub undecided: Vec<Point>,
}

/// 000 Fig. 6 over the rendered world: the map's landmarks at their rocks' positions, the RNG
/// estimate, Voronoi borders, the navigator's decisions over a grid, and the first three trips
/// to `goal`.
pub(super) fn figure(
    world: &World,
    landmark_rocks: &BTreeMap<LandmarkId, u32>,
    rng: &RngEstimate,
    trips: &[Trip],
    goal: LandmarkId,
    grid: Grid,
    title: String,
) -> FlowPicture {
    let ids: Vec<LandmarkId> = landmark_rocks.keys().copied().collect();
    let raw: Vec<Point> = landmark_rocks
        .values()
        .map(|&r| world.rocks[r as usize].position)
        .collect();
    let shown: Vec<&Trip> = trips.iter().filter(|t| t.goal == goal).take(3).collect();
    let (low, high) = bounds(
        raw.iter()
            .copied()
            .chain(
                shown
                    .iter()
                    .flat_map(|t| t.path.iter().map(|p| Point::new(p[0], p[1]))),
            )
            .chain(grid.arrows.iter().map(|a| a.0))
            .chain(grid.arrived.iter().copied())
            .chain(grid.undecided.iter().copied()),
    );
    let (x0, y0, x1, y1) = (low.x, low.y, high.x, high.y);
    let shift = |x: f64, y: f64| (x - x0 + 1.0, y - y0 + 1.0);
    let side = (x1 - x0).max(y1 - y0) + 2.0;
    let index = |l: LandmarkId| ids.iter().position(|&i| i == l);
    let edges: Vec<(usize, usize, f64)> = rng
        .edges
        .iter()
        .filter_map(|e| Some((index(e.a)?, index(e.b)?, e.cost)))
        .collect();
    let goal = landmark_rocks
        .get(&goal)
        .map_or(raw[0], |&r| world.rocks[r as usize].position);
    let shifted = |points: Vec<Point>| points.iter().map(|p| shift(p.x, p.y)).collect();
    FlowPicture {
        title,
        landmarks: raw.iter().map(|p| shift(p.x, p.y)).collect(),
        edges,
        true_edges: true_rng(&raw),
        arrows: grid
            .arrows
            .iter()
            .map(|&(p, direction)| (shift(p.x, p.y), direction))
            .collect(),
        arrow_length: grid.arrow_length,
        rocks: world
            .rocks
            .iter()
            .map(|r| {
                (
                    shift(r.position.x, r.position.y),
                    world.contact_radius(r.id),
                )
            })
            .collect(),
        arrived: shifted(grid.arrived),
        undecided: shifted(grid.undecided),
        goal: shift(goal.x, goal.y),
        trips: shown
            .iter()
            .map(|t| t.path.iter().map(|p| shift(p[0], p[1])).collect())
            .collect(),
        side,
    }
}

/// The world of a synthetic dataset, rendered again from the preset and seed its truth.json
/// names (checked against the rocks it lists), its camera, and "preset P, seed S".
pub(super) fn rendered_world(images: &Path) -> Result<(Calibration, World, String)> {
    let truth = super::eval::read_truth(&images.join("truth.json"))?;
    if truth.variant.is_some() {
        bail!(
            "{}: a set rendered with variations (stress, scene or camera options) cannot be rendered again here; use a plain preset",
            images.display()
        );
    }
    let preset = [Preset::Marsyard, Preset::Random, Preset::SparseLarge]
        .into_iter()
        .find(|p| p.name() == truth.preset)
        .with_context(|| format!("unknown preset {:?} in the truth file", truth.preset))?;
    let calib = Calibration::load(&images.join("calib.toml"))?;
    let layout = preset.layout(
        truth.seed,
        Counts {
            rocks: Some(truth.rocks.len()),
            stations: Some(truth.stations.len()),
        },
    );
    let world = World::generate(truth.seed, &layout.rocks);
    if world.rocks.iter().zip(&truth.rocks).any(|(r, t)| {
        r.position
            .distance(Point::new(t.position[0], t.position[1]))
            > 1e-9
    }) {
        bail!(
            "{}: the world rendered again from preset {} seed {} is not the one in its truth file",
            images.display(),
            truth.preset,
            truth.seed
        );
    }
    Ok((
        calib,
        world,
        format!("preset {}, seed {}", truth.preset, truth.seed),
    ))
}

/// The map of a run over `images`' world, and the rock each landmark stands for (eval.json).
pub(super) fn run_of(
    run: &Path,
    world: &World,
    images: &Path,
) -> Result<(KnownMap<Edc>, BTreeMap<LandmarkId, u32>)> {
    let known = load_run(&run.join("map.json"))?;
    let landmark_rocks = read_landmark_rocks(run)?;
    if let Some((l, r)) = landmark_rocks
        .iter()
        .find(|(_, &r)| r as usize >= world.rocks.len())
    {
        bail!(
            "{}: landmark {l} stands for rock {r}, which {} does not have: not the run of this dataset",
            run.join("eval.json").display(),
            images.display()
        );
    }
    Ok((known, landmark_rocks))
}
