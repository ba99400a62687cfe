//! `pipeline navigate flowfield`: 000 Fig. 6 for the closed loop through rendered panoramas.
//! At every point of a grid over a synthetic dataset's world, the stereo panorama is rendered
//! and the navigator of `navigate drive` decides its first step toward a goal landmark's cell
//! from it alone (detection, association with the run's map, route, leg follower); the arrow
//! is that heading. Three closed-loop trips to the same goal are drawn over it
//! (docs/NAVIGATION.md, "The flow field of the closed loop").

use super::drive::{clear_of_rocks, figure, random_start, ClosedLoop, DrivingArgs, Grid};
use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use qrm_atomic_file::OutputSet;
use qrm_core::geometry::Point;
use qrm_core::map::LandmarkId;
use qrm_plot::write_flow;
use qrm_synth::closed_loop::{drive, Driving, Trip};
use qrm_synth::{Pose, World};
use qrm_vision::run::RunSettings;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct FlowfieldArgs {
    /// The synthetic dataset whose world is rendered (as for `navigate drive`).
    #[arg(long)]
    images: PathBuf,
    /// The map's run over that dataset (map.json, landmarks.json, stations.json, eval.json).
    #[arg(long)]
    run: PathBuf,
    /// The goal landmark: an id of the run's map that stands for a rock (eval.json).
    #[arg(long)]
    goal: LandmarkId,
    /// Grid points per side, over the box the map's landmarks' rocks lie in, grown by a metre.
    /// Each point costs a rendered stereo panorama and a navigator step: 4 min for the 112
    /// points and 3 trips of a 4096 × 768 marsyard set on 2 cores, 1 min at half resolution.
    #[arg(long, default_value_t = 12)]
    grid: usize,
    /// Closed-loop trips to the goal from random starts, drawn as trajectories.
    #[arg(long, default_value_t = 3)]
    trips: usize,
    #[command(flatten)]
    driving: DrivingArgs,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory: flowfield.png, flowfield.svg, headings.csv, trips.json.
    #[arg(long, default_value = "flowfield")]
    out: PathBuf,
}

/// The navigator's first step from one grid point.
struct Heading {
    at: Point,
    /// `toward`, `closing_in`, `arrived`, `start_unknown`, `no_route` or `lost` (the per-step
    /// log's commands).
    command: &'static str,
    target: Option<LandmarkId>,
    /// World frame, degrees counter-clockwise from +x.
    bearing_deg: Option<f64>,
    /// The cell the navigator believed it was in, and the truth's: the landmark whose rock is
    /// nearest.
    cell: Option<LandmarkId>,
    true_cell: Option<LandmarkId>,
}

pub fn run(args: &FlowfieldArgs) -> Result<()> {
    if args.grid < 2 {
        bail!("--grid {} must be at least 2 points per side", args.grid);
    }
    let driving = args.driving.driving()?;
    let closed = ClosedLoop::load(&args.images, &args.run)?;
    let terrain = closed.terrain();
    let (world, known, landmark_rocks) = (&closed.world, &closed.known, &closed.landmark_rocks);
    if !landmark_rocks.contains_key(&args.goal) {
        bail!(
            "landmark {} is not a landmark of {} that stands for a rock (eval.json lists {})",
            args.goal,
            args.run.display(),
            landmark_rocks
                .keys()
                .map(LandmarkId::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let settings = RunSettings::default();
    let (points, spacing) = grid_points(world, landmark_rocks, args.grid);
    let bar = ProgressBar::new((points.len() + args.trips) as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} flowfield [{bar:40}] {pos}/{len} grid points and trips ({elapsed}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    let first_step = Driving {
        max_steps: 1,
        ..driving
    };
    let headings: Vec<Heading> = points
        .par_iter()
        .map(|&at| {
            let pose = Pose {
                position: at,
                heading: 0.0,
            };
            let trip = drive(
                &terrain,
                known,
                &closed.graph,
                &settings,
                pose,
                args.goal,
                &first_step,
            );
            bar.inc(1);
            let step = &trip.steps[0];
            Heading {
                at,
                command: step.command,
                target: step.target,
                bearing_deg: step.bearing_deg.map(|b| b + step.heading_deg),
                cell: step.cell,
                true_cell: terrain.true_cell(at),
            }
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut trips: Vec<Trip> = Vec::new();
    for _ in 0..args.trips {
        let start = random_start(world, &mut rng, &args.images)?;
        trips.push(drive(
            &terrain,
            known,
            &closed.graph,
            &settings,
            start,
            args.goal,
            &driving,
        ));
        bar.inc(1);
    }
    bar.finish_and_clear();

    let mut grid = Grid {
        arrow_length: 0.4 * spacing,
        ..Grid::default()
    };
    for h in &headings {
        match (h.command, h.bearing_deg) {
            (_, Some(b)) => grid
                .arrows
                .push((h.at, (b.to_radians().cos(), b.to_radians().sin()))),
            ("arrived", None) => grid.arrived.push(h.at),
            _ => grid.undecided.push(h.at),
        }
    }
    let counts = (grid.arrows.len(), grid.arrived.len(), grid.undecided.len());
    let picture = figure(
        world,
        landmark_rocks,
        &closed.rng_estimate,
        &trips,
        args.goal,
        grid,
        format!(
            "Closed-loop flow field to landmark {} ({} of {} grid points decided)",
            args.goal,
            counts.0 + counts.1,
            headings.len()
        ),
    );
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    // The four files replace an earlier run's together.
    let mut outputs = OutputSet::new();
    for name in ["flowfield.png", "flowfield.svg"] {
        outputs.stage(&args.out.join(name), |temporary| {
            write_flow(temporary, &picture)
        })?;
    }
    for (name, text) in [
        ("headings.csv", headings_csv(&headings)),
        ("trips.json", serde_json::to_string_pretty(&trips)? + "\n"),
    ] {
        let path = args.out.join(name);
        outputs
            .stage_bytes(&path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    outputs
        .commit()
        .with_context(|| format!("cannot move the outputs into {}", args.out.display()))?;
    let in_goal = trips.iter().filter(|t| t.in_goal_cell).count();
    println!(
        "{} grid points in {} ({}), map of {} landmarks from {}: {} headings, {} arrived, {} without a heading; {} of {} trips ended in the goal's cell",
        headings.len(),
        args.images.display(),
        closed.origin,
        known.map.len(),
        args.run.display(),
        counts.0,
        counts.1,
        counts.2,
        in_goal,
        trips.len()
    );
    println!(
        "wrote {}/flowfield.png, flowfield.svg, headings.csv, trips.json",
        args.out.display()
    );
    Ok(())
}

/// The centres of a `side` × `side` grid over the box the landmarks' rocks lie in, grown by a
/// metre, that are clear of every rock (a rover cannot stand inside one), and the grid's
/// smaller spacing.
fn grid_points(
    world: &World,
    landmark_rocks: &BTreeMap<LandmarkId, u32>,
    side: usize,
) -> (Vec<Point>, f64) {
    let (low, high) = super::drive::bounds(
        landmark_rocks
            .values()
            .map(|&r| world.rocks[r as usize].position),
    );
    let (x0, y0) = (low.x - 1.0, low.y - 1.0);
    let (dx, dy) = (
        (high.x - low.x + 2.0) / side as f64,
        (high.y - low.y + 2.0) / side as f64,
    );
    let points = (0..side)
        .flat_map(|i| (0..side).map(move |j| (i, j)))
        .map(|(i, j)| Point::new(x0 + (i as f64 + 0.5) * dx, y0 + (j as f64 + 0.5) * dy))
        .filter(|&p| clear_of_rocks(world, p))
        .collect();
    (points, dx.min(dy))
}

/// headings.csv: one row per grid point (docs/NAVIGATION.md).
fn headings_csv(headings: &[Heading]) -> String {
    let mut csv = String::from("x,y,command,target,bearing_deg,believed_cell,true_cell\n");
    let id = |l: Option<LandmarkId>| l.map_or(String::new(), |l| l.to_string());
    for h in headings {
        let _ = writeln!(
            csv,
            "{:.3},{:.3},{},{},{},{},{}",
            h.at.x,
            h.at.y,
            h.command,
            id(h.target),
            h.bearing_deg
                .map_or(String::new(), |b| format!("{:.2}", b.rem_euclid(360.0))),
            id(h.cell),
            id(h.true_cell)
        );
    }
    csv
}
