//! `pipeline navigate`: landmark routes and the convex hull from a saved map, and simulated
//! navigation over the RNG (000 §VII-B; seed digest A).

use super::map::{calculus_of, load, read};
use super::output::write_atomic;
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::geometry::Point;
use qrm_core::map::{Hypergraph, LandmarkId};
use qrm_core::navigation::{convex_hull, Command, LegFollower, RouteCost, RouteGraph};
use qrm_core::neighborhood::{estimate, true_rng};
use qrm_core::simulation::{
    drive, nearest, Controller, Drive, Layout, NavigationStudy, NavigationSummary, RngSource,
    Sensor, TripRecord,
};
use qrm_plot::{write_flow, write_panels, Curve, FlowPicture, Panel};
use rand::SeedableRng;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Subcommand, Debug)]
pub enum NavigateCommand {
    /// The landmark route from one landmark to another over the map's RNG estimate, e.g.
    /// `navigate plan --map run/map.json --from 3 --to 17`. Pruned pairs are never used; each
    /// edge costs 1 + λ·w (w: the edge's Algorithm 2 cost, 0 for an edge the map proves), so
    /// with λ > 0 edges the map may yet prune are avoided when a route of certain edges is not
    /// much longer.
    Plan(PlanArgs),
    /// The convex hull of the map's landmarks: the edges the map proves, and those it allows.
    Hull {
        #[arg(long)]
        map: PathBuf,
    },
    /// Which landmark's Voronoi cell a panorama was taken in, against the map of an earlier
    /// `pipeline run` (its map.json, with landmarks.json and stations.json beside it): the
    /// panorama's detections are associated with the run's landmarks (nothing is fused), and
    /// the range order says which identified one is nearest, e.g. `navigate locate --map
    /// run/map.json --image more/station_050_left.png`. Certain only when an identified
    /// landmark is known nearer than every other detection (any unidentified rock may be a
    /// landmark); otherwise the possible cells, or unknown.
    Locate(super::locate::LocateArgs),
    /// Closed-loop trips through the rendered world of a synthetic dataset: at every step the
    /// stereo panorama is rendered at the rover's pose, detected, associated with the map of a
    /// `pipeline run` over that dataset, and the leg follower picks the heading; rocks are
    /// obstacles (a hazard avoidance drives each step around the rocks within 4 m). Writes
    /// trips.json, trips.csv, summary.json, drive.png (000 Fig. 6 with the first three trips)
    /// and drive.mcap (every step), e.g. `navigate drive --images data/marsyard --run
    /// marsyard-run --trips 20`.
    Drive(super::drive::DriveArgs),
    /// 000 Fig. 6 for the closed loop: at every point of a grid over a synthetic dataset's
    /// world, the heading the navigator of `navigate drive` picks from the stereo panorama
    /// rendered there toward a goal landmark's cell (its first step, from the panorama alone),
    /// with the run's RNG estimate, the Voronoi borders and three closed-loop trips to the goal.
    /// Writes flowfield.png/.svg, headings.csv and trips.json, e.g. `navigate flowfield
    /// --images data/marsyard --run marsyard-run --goal 10`.
    Flowfield(super::flowfield::FlowfieldArgs),
    /// Route directions (docs/DIRECTIONS.md) followed through panoramas rendered in a synthetic
    /// dataset's world: routes planned on the map of a `pipeline run` over it, each leg's
    /// target picked as the most isolated of the rover's own detections; predicted route
    /// reliability against the measured success. Writes trials.json, summary.json and
    /// calibration.png, e.g. `navigate directions --images data/marsyard --run marsyard-run`.
    Directions(super::directions::TrialArgs),
    /// Simulated navigation with an ideal sensor (bearings and range order of the landmarks,
    /// no rendering): random fields, random start/goal pairs, the leg follower of 000 §VII-B
    /// planning on the true RNG or on the RNG of a map after `--images` simulated panoramas.
    /// Writes trips.csv, summary.json and a figure like 000 Fig. 6 (flowfield.png/.svg); with
    /// several `--images` (and `--lambda`) values, a sweep: sweep.csv and sweep.png/.svg,
    /// success, re-plans and path length against the images mapped.
    Simulate(SimulateArgs),
}

#[derive(Args, Debug)]
pub struct PlanArgs {
    /// A saved EDC map (`pipeline run`'s map.json, docs/MAP_FORMAT.md).
    #[arg(long)]
    map: PathBuf,
    /// Landmark id to start from (the one whose cell the rover is in).
    #[arg(long)]
    from: LandmarkId,
    /// Landmark id to reach.
    #[arg(long)]
    to: LandmarkId,
    /// Weight λ of an edge's RNG cost against one hop.
    #[arg(long, default_value_t = 1.0)]
    lambda: f64,
    /// How many routes to list, cheapest first (alternatives for when a leg fails).
    #[arg(long, default_value_t = 1)]
    routes: usize,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum LayoutName {
    /// Landmarks uniform in the square (000 §VIII-B).
    Uniform,
    /// One landmark per grid cell, jittered by `--jitter` of the cell side.
    Grid,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ControllerName {
    Legs,
    Flow,
}

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Random landmark fields.
    #[arg(long, default_value_t = 10)]
    worlds: usize,
    #[arg(long, default_value_t = 30)]
    landmarks: usize,
    /// Start/goal pairs per field.
    #[arg(long, default_value_t = 100)]
    pairs: usize,
    /// Side of the square field.
    #[arg(long, default_value_t = 100.0)]
    side: f64,
    #[arg(long, value_enum, default_value = "uniform")]
    layout: LayoutName,
    /// Jitter of the grid layout, as a fraction of a cell's side.
    #[arg(long, default_value_t = 0.3)]
    jitter: f64,
    /// Plan on the RNG estimated from an EDC map of this many simulated panoramas (exact
    /// sensing) instead of the true RNG. Several (`--images 5,10,20,50`) run a sweep: the
    /// study once per number of images (and per `--lambda`), with sweep.csv and a figure of
    /// success, re-plans and path length against the images mapped (sweep.png/.svg).
    #[arg(long, value_delimiter = ',')]
    images: Vec<usize>,
    /// Landmarks each mapping panorama sees (the n nearest; default all).
    #[arg(long)]
    nearest: Option<usize>,
    /// Landmarks the rover sees while driving (the n nearest; default all, the guarantee's
    /// case: "landmarks visible from adjacent cells").
    #[arg(long)]
    visible: Option<usize>,
    /// Weight λ of an edge's RNG cost against one hop; several (`--lambda 0,10`) compare them
    /// in a sweep, one curve each.
    #[arg(long, value_delimiter = ',', default_values_t = [1.0])]
    lambda: Vec<f64>,
    /// Step length, as a fraction of the side (seed digest A.7: 0.5 %).
    #[arg(long, default_value_t = 0.005)]
    step: f64,
    /// `legs`: plan once and follow the route leg by leg (000 §VII-B); `flow`: memoryless, in
    /// each cell head for the next hop of the route from that cell (000 Fig. 6), which can
    /// cycle.
    #[arg(long, value_enum, default_value = "legs")]
    controller: ControllerName,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory.
    #[arg(long, default_value = "navigation")]
    out: PathBuf,
}

pub fn run_command(command: NavigateCommand) -> Result<()> {
    match command {
        NavigateCommand::Plan(args) => plan(&args),
        NavigateCommand::Hull { map } => {
            let text = read(&map)?;
            match calculus_of(&map, &text)?.as_str() {
                "EDC" => hull(&load::<Edc>(&map, &text)?),
                "FDC" => hull(&load::<Fdc>(&map, &text)?),
                other => bail!("{}: unknown calculus {other:?}", map.display()),
            }
        }
        NavigateCommand::Simulate(args) => simulate(&args),
        NavigateCommand::Locate(args) => super::locate::locate(&args),
        NavigateCommand::Drive(args) => super::drive::run(&args),
        NavigateCommand::Flowfield(args) => super::flowfield::run(&args),
        NavigateCommand::Directions(args) => super::directions::trial(&args),
    }
}

fn plan(args: &PlanArgs) -> Result<()> {
    if !(args.lambda >= 0.0 && args.lambda.is_finite()) {
        bail!("--lambda {} must be a finite number ≥ 0", args.lambda);
    }
    if args.routes == 0 {
        bail!("--routes must be at least 1");
    }
    let text = read(&args.map)?;
    let calculus = calculus_of(&args.map, &text)?;
    if calculus != "EDC" {
        bail!(
            "{}: a {calculus} map has no RNG estimate (only EDC tells distances apart); map with --calculus edc",
            args.map.display()
        );
    }
    let map: Hypergraph<Edc> = load(&args.map, &text)?;
    let rng = estimate(&map).expect("EDC has a lune");
    let graph = RouteGraph::new(map.landmarks(), &rng);
    let cost = RouteCost {
        lambda: args.lambda,
    };
    let routes = graph
        .alternatives(args.from, args.to, cost, args.routes)
        .with_context(|| format!("in {}", args.map.display()))?;
    for (k, route) in routes.iter().enumerate() {
        let names: Vec<String> = route.landmarks.iter().map(|l| l.to_string()).collect();
        println!(
            "route {}: {}  ({} hops, {} not proven by the map, cost {:.3})",
            k + 1,
            names.join(" → "),
            route.hops(),
            route.uncertain_edges,
            route.cost
        );
    }
    if routes.len() < args.routes {
        println!("(no other loopless route)");
    }
    Ok(())
}

fn hull<C: Calculus>(map: &Hypergraph<C>) -> Result<()> {
    let hull = convex_hull(map);
    let list = |edges: &[(LandmarkId, LandmarkId)]| {
        edges
            .iter()
            .map(|(a, b)| format!("{a}–{b}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "{} map, {} landmarks: {} hull edges proven, {} more possible",
        C::NAME,
        map.len(),
        hull.certain.len(),
        hull.possible.len()
    );
    if !hull.certain.is_empty() {
        println!("proven: {}", list(&hull.certain));
        let on: Vec<String> = hull
            .certain_landmarks()
            .iter()
            .map(|l| l.to_string())
            .collect();
        println!("landmarks certainly on the hull: {}", on.join(", "));
    }
    if !hull.possible.is_empty() {
        println!("possible: {}", list(&hull.possible));
    }
    Ok(())
}

/// The study of `args` planning on the RNG after `images` mapped panoramas (`None`: the true
/// RNG) with edge weight `lambda`.
fn study(args: &SimulateArgs, images: Option<usize>, lambda: f64) -> Result<NavigationStudy> {
    if args.worlds == 0 || args.pairs == 0 {
        bail!("--worlds and --pairs must be positive");
    }
    if args.landmarks < 3 {
        bail!("--landmarks must be at least 3");
    }
    if !(args.side > 0.0 && args.side.is_finite()) {
        bail!("--side {} must be a positive length", args.side);
    }
    if !(args.step > 0.0 && args.step < 0.5) {
        bail!(
            "--step {} must be a fraction of the side in (0, 0.5)",
            args.step
        );
    }
    if !(0.0..0.5).contains(&args.jitter) {
        bail!("--jitter {} must lie in [0, 0.5)", args.jitter);
    }
    if !(lambda >= 0.0 && lambda.is_finite()) {
        bail!("--lambda {lambda} must be a finite number ≥ 0");
    }
    if args.nearest.is_some_and(|n| n < 3) || args.visible.is_some_and(|n| n < 1) {
        bail!("--nearest must be at least 3 and --visible at least 1");
    }
    let step = args.step * args.side;
    Ok(NavigationStudy {
        worlds: args.worlds,
        landmarks: args.landmarks,
        pairs: args.pairs,
        side: args.side,
        layout: match args.layout {
            LayoutName::Uniform => Layout::Uniform,
            LayoutName::Grid => Layout::JitteredGrid {
                jitter: args.jitter,
            },
        },
        source: match images {
            None => RngSource::True,
            Some(images) => RngSource::Mapped {
                images,
                nearest: args.nearest,
            },
        },
        drive: Drive {
            step,
            // Ten times the longest straight crossing of the field.
            max_steps: (10.0 * std::f64::consts::SQRT_2 / args.step).ceil() as usize,
            max_replans: 5,
            sensor: Sensor::exact(args.visible),
            cost: RouteCost { lambda },
            controller: match args.controller {
                ControllerName::Legs => Controller::Legs,
                ControllerName::Flow => Controller::Flow,
            },
        },
        seed: args.seed,
    })
}

fn simulate(args: &SimulateArgs) -> Result<()> {
    let images: Vec<Option<usize>> = if args.images.is_empty() {
        vec![None]
    } else {
        args.images.iter().map(|&k| Some(k)).collect()
    };
    if args.lambda.is_empty() {
        bail!("--lambda needs a value");
    }
    let settings: Vec<(Option<usize>, f64)> = images
        .iter()
        .flat_map(|&k| args.lambda.iter().map(move |&lambda| (k, lambda)))
        .collect();
    match settings.as_slice() {
        [(images, lambda)] => simulate_one(args, study(args, *images, *lambda)?),
        _ if args.images.is_empty() => bail!(
            "a sweep draws its figures against the images mapped: give --images k1,k2,… with several --lambda values"
        ),
        _ => sweep(args, &settings),
    }
}

fn simulate_one(args: &SimulateArgs, study: NavigationStudy) -> Result<()> {
    let bar = ProgressBar::new(study.worlds as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} fields [{bar:40}] {pos}/{len} ({elapsed}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    let start = Instant::now();
    let records = study.run(&|| bar.inc(1));
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let summary = NavigationSummary::of(&records);
    write_atomic(
        &args.out.join("trips.csv"),
        trips_csv(&[(&study, records.as_slice())]).as_bytes(),
    )?;
    let json = serde_json::json!({
        "format": "qrm-navigation-study",
        "version": 1,
        "worlds": study.worlds,
        "landmarks": study.landmarks,
        "pairs": study.pairs,
        "side": study.side,
        "layout": study.layout,
        "rng": study.source,
        "lambda": study.drive.cost.lambda,
        "controller": study.drive.controller,
        "step": study.drive.step,
        "visible": args.visible,
        "seed": study.seed,
        "seconds": seconds,
        "summary": summary,
    });
    write_atomic(
        &args.out.join("summary.json"),
        (serde_json::to_string_pretty(&json).expect("JSON values serialise") + "\n").as_bytes(),
    )?;
    for name in ["flowfield.png", "flowfield.svg"] {
        write_flow(&args.out.join(name), &flow_picture(&study)?)?;
    }
    print!("{}", summary_text(&study, &summary, seconds));
    println!(
        "wrote {}/trips.csv, summary.json, flowfield.png, flowfield.svg",
        args.out.display()
    );
    Ok(())
}

/// One study of a sweep: its setting, trips and summary, and its wall time.
struct Setting {
    study: NavigationStudy,
    records: Vec<TripRecord>,
    summary: NavigationSummary,
    seconds: f64,
}

/// The study once per (images, λ) in `settings`: trips.csv, summary.json, sweep.csv and
/// sweep.png/.svg (success, re-plans and path length against the images mapped, a curve per
/// λ; docs/NAVIGATION.md).
fn sweep(args: &SimulateArgs, settings: &[(Option<usize>, f64)]) -> Result<()> {
    let studies: Vec<NavigationStudy> = settings
        .iter()
        .map(|&(images, lambda)| study(args, images, lambda))
        .collect::<Result<_>>()?;
    let bar = ProgressBar::new((studies.len() * args.worlds) as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} fields [{bar:40}] {pos}/{len} over all settings ({elapsed}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    let done: Vec<Setting> = studies
        .into_iter()
        .map(|study| {
            let start = Instant::now();
            let records = study.run(&|| bar.inc(1));
            Setting {
                summary: NavigationSummary::of(&records),
                seconds: start.elapsed().as_secs_f64(),
                study,
                records,
            }
        })
        .collect();
    bar.finish_and_clear();
    let runs: Vec<(&NavigationStudy, &[TripRecord])> = done
        .iter()
        .map(|s| (&s.study, s.records.as_slice()))
        .collect();
    write_atomic(&args.out.join("trips.csv"), trips_csv(&runs).as_bytes())?;
    write_atomic(&args.out.join("sweep.csv"), sweep_csv(&done).as_bytes())?;
    let first = &done[0].study;
    let json = serde_json::json!({
        "format": "qrm-navigation-sweep",
        "version": 1,
        "worlds": first.worlds,
        "landmarks": first.landmarks,
        "pairs": first.pairs,
        "side": first.side,
        "layout": first.layout,
        "controller": first.drive.controller,
        "step": first.drive.step,
        "visible": args.visible,
        "seed": first.seed,
        "settings": done.iter().map(|s| serde_json::json!({
            "rng": s.study.source,
            "lambda": s.study.drive.cost.lambda,
            "seconds": s.seconds,
            "summary": s.summary,
        })).collect::<Vec<_>>(),
    });
    write_atomic(
        &args.out.join("summary.json"),
        (serde_json::to_string_pretty(&json).expect("JSON values serialise") + "\n").as_bytes(),
    )?;
    let panels = sweep_panels(&done);
    for name in ["sweep.png", "sweep.svg"] {
        write_panels(&args.out.join(name), "images mapped (k)", &panels)?;
    }
    print!("{}", sweep_text(&done, args));
    println!(
        "wrote {}/trips.csv, sweep.csv, summary.json, sweep.png, sweep.svg",
        args.out.display()
    );
    Ok(())
}

/// The images a study's map was built from (`None`: the true RNG).
fn images_of(study: &NavigationStudy) -> Option<usize> {
    match study.source {
        RngSource::True => None,
        RngSource::Mapped { images, .. } => Some(images),
    }
}

/// sweep.csv: one row per setting.
fn sweep_csv(done: &[Setting]) -> String {
    let mut out = String::from(
        "images,lambda,trips,success,mean_replans,mean_legs,median_length_ratio,p90_length_ratio\n",
    );
    for s in done {
        let m = &s.summary;
        let _ = writeln!(
            out,
            "{},{},{},{:.4},{:.3},{:.3},{:.4},{:.4}",
            images_of(&s.study).map_or(String::new(), |k| k.to_string()),
            s.study.drive.cost.lambda,
            m.trips,
            m.success_rate,
            m.mean_replans,
            m.mean_legs,
            m.median_length_ratio,
            m.p90_length_ratio
        );
    }
    out
}

/// Success, re-plans and path length against the images mapped, a curve per λ (the layout of
/// 000 Fig. 7's panels).
fn sweep_panels(done: &[Setting]) -> Vec<Panel> {
    let mut xs: Vec<usize> = done.iter().filter_map(|s| images_of(&s.study)).collect();
    xs.sort_unstable();
    xs.dedup();
    let mut lambdas: Vec<f64> = done.iter().map(|s| s.study.drive.cost.lambda).collect();
    lambdas.sort_by(f64::total_cmp);
    lambdas.dedup();
    let panel = |title: &str, y_label: &str, metric: &dyn Fn(&NavigationSummary) -> f64| Panel {
        title: title.into(),
        y_label: y_label.into(),
        x: xs.iter().map(|&k| k as f64).collect(),
        curves: lambdas
            .iter()
            .map(|&lambda| Curve {
                label: format!("λ = {lambda}"),
                mean: xs
                    .iter()
                    .map(|&k| {
                        done.iter()
                            .find(|s| {
                                images_of(&s.study) == Some(k)
                                    && s.study.drive.cost.lambda == lambda
                            })
                            .map_or(f64::NAN, |s| metric(&s.summary))
                    })
                    .collect(),
                std: Vec::new(),
                band: None,
            })
            .collect(),
    };
    vec![
        panel("(a) trips that arrive", "success (%)", &|m| {
            100.0 * m.success_rate
        }),
        panel("(b) re-plans", "mean re-plans per trip", &|m| {
            m.mean_replans
        }),
        panel(
            "(c) path length, trips that arrive",
            "median path / straight distance",
            &|m| m.median_length_ratio,
        ),
    ]
}

fn sweep_text(done: &[Setting], args: &SimulateArgs) -> String {
    let mut out = format!(
        "{} worlds × {} pairs per setting, {} landmarks, rover sees {}:\n  images  λ      success  re-plans  length ratio (median)\n",
        args.worlds,
        args.pairs,
        args.landmarks,
        args.visible
            .map_or("all".to_string(), |n| format!("the {n} nearest")),
    );
    for s in done {
        let _ = writeln!(
            out,
            "  {:>6}  {:<5}  {:>6.1} %  {:>8.2}  {:.3}",
            images_of(&s.study).map_or("true".to_string(), |k| k.to_string()),
            s.study.drive.cost.lambda,
            100.0 * s.summary.success_rate,
            s.summary.mean_replans,
            s.summary.median_length_ratio
        );
    }
    out
}

/// trips.csv: one row per trip of each study, with the images its map was built from (empty:
/// the true RNG) and λ.
fn trips_csv(runs: &[(&NavigationStudy, &[TripRecord])]) -> String {
    let mut out = String::from(
        "images,lambda,world,pair,outcome,length_ratio,length,straight,route_hops,legs,replans,steps\n",
    );
    for (study, records) in runs {
        let images = images_of(study).map_or(String::new(), |k| k.to_string());
        for r in records.iter() {
            let outcome = serde_json::to_value(r.outcome).expect("outcome serialises");
            let _ = writeln!(
                out,
                "{images},{},{},{},{},{:.4},{:.3},{:.3},{},{},{},{}",
                study.drive.cost.lambda,
                r.world,
                r.pair,
                outcome.as_str().unwrap_or("?"),
                r.length_ratio,
                r.length,
                r.straight,
                r.route_hops,
                r.legs,
                r.replans,
                r.steps
            );
        }
    }
    out
}

fn summary_text(study: &NavigationStudy, s: &NavigationSummary, seconds: f64) -> String {
    let source = match study.source {
        RngSource::True => "the true RNG".to_string(),
        RngSource::Mapped { images, nearest } => format!(
            "the RNG estimate after {images} images ({} landmarks each)",
            nearest.map_or("all".to_string(), |n| n.to_string())
        ),
    };
    let outcomes: Vec<String> = s.outcomes.iter().map(|(k, v)| format!("{k} {v}")).collect();
    format!(
        "{} trips over {} fields of {} landmarks, planning on {source} (λ = {}), {}:\n  \
         success {:.1} %  ({})\n  path length / straight distance: median {:.3}, 90th percentile {:.3}\n  \
         mean legs {:.2}, mean re-plans {:.2}; {:.1} s\n",
        s.trips,
        study.worlds,
        study.landmarks,
        study.drive.cost.lambda,
        match study.drive.controller {
            Controller::Legs => "following legs",
            Controller::Flow => "memoryless (flow field)",
        },
        100.0 * s.success_rate,
        outcomes.join(", "),
        s.median_length_ratio,
        s.p90_length_ratio,
        s.mean_legs,
        s.mean_replans,
        seconds
    )
}

/// 000 Fig. 6 for the study's first field: Voronoi borders, the RNG planned on, the direction
/// the leg follower takes at each point of a grid toward the cell of the landmark nearest one
/// goal, and three trips from random starts.
fn flow_picture(study: &NavigationStudy) -> Result<FlowPicture> {
    let points = study.world(0);
    let graph = study.graph(0, &points);
    let pairs = study.pairs_of(0);
    let goal = pairs[0].1;
    let goal_landmark = nearest(&points, goal);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(study.seed);
    let trips: Vec<Vec<(f64, f64)>> = pairs
        .iter()
        .take(3)
        .map(|&(start, _)| {
            let trip = drive(&points, &graph, start, goal, &study.drive, &mut rng);
            trip.path.iter().map(|p| (p.x, p.y)).collect()
        })
        .collect();
    let arrows = flow_arrows(study, &points, &graph, goal_landmark);
    let edges: Vec<(usize, usize, f64)> = (0..points.len() as LandmarkId)
        .flat_map(|a| {
            graph
                .neighbours(a)
                .into_iter()
                .filter(move |&(b, _)| a < b)
                .map(move |(b, w)| (a as usize, b as usize, w.clamp(0.0, 1.0)))
        })
        .collect();
    let true_edges = match study.source {
        RngSource::True => Vec::new(),
        RngSource::Mapped { .. } => true_rng(&points),
    };
    Ok(FlowPicture {
        title: format!(
            "000 Fig. 6 flow field · {}",
            match study.source {
                RngSource::True => "true RNG".to_string(),
                RngSource::Mapped { images, .. } => format!("RNG estimate after {images} images"),
            }
        ),
        landmarks: points.iter().map(|p| (p.x, p.y)).collect(),
        edges,
        true_edges,
        arrows,
        arrow_length: 0.02 * study.side,
        rocks: Vec::new(),
        arrived: Vec::new(),
        undecided: Vec::new(),
        goal: (goal.x, goal.y),
        trips,
        side: study.side,
    })
}

/// At the centre of each cell of a 20 × 20 grid, the direction the leg follower drives on a
/// route planned from the landmark whose cell the point is in (000 Fig. 6's red arrows).
fn flow_arrows(
    study: &NavigationStudy,
    points: &[Point],
    graph: &RouteGraph,
    goal: LandmarkId,
) -> Vec<((f64, f64), (f64, f64))> {
    let cells = 20;
    let spacing = study.side / f64::from(cells);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(study.seed);
    let mut arrows = Vec::new();
    for i in 0..cells {
        for j in 0..cells {
            let p = Point::new(
                (f64::from(i) + 0.5) * spacing,
                (f64::from(j) + 0.5) * spacing,
            );
            let (visible, view) = Sensor::exact(None).observe(points, p, &mut rng);
            let Ok(route) = graph.plan(nearest(points, p), goal, study.drive.cost) else {
                continue;
            };
            if let Command::Toward { bearing, .. } = LegFollower::new(&route).step(&visible, &view)
            {
                arrows.push(((p.x, p.y), (bearing.cos(), bearing.sin())));
            }
        }
    }
    arrows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_csv_has_a_row_per_trip() {
        let records = vec![TripRecord {
            world: 0,
            pair: 3,
            outcome: qrm_core::simulation::Outcome::Arrived,
            length_ratio: 1.25,
            length: 50.0,
            straight: 40.0,
            route_hops: 3,
            legs: 3,
            replans: 0,
            steps: 100,
        }];
        let args = simulate_args(&["--images", "5", "--lambda", "10"]);
        let study = study(&args, Some(5), 10.0).unwrap();
        let csv = trips_csv(&[(&study, &records)]);
        assert_eq!(csv.lines().count(), 2);
        assert!(csv
            .lines()
            .nth(1)
            .unwrap()
            .starts_with("5,10,0,3,arrived,1.2500,"));
    }

    /// `navigate simulate` with `flags`.
    fn simulate_args(flags: &[&str]) -> SimulateArgs {
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            args: SimulateArgs,
        }
        <Cli as clap::Parser>::parse_from(std::iter::once("simulate").chain(flags.iter().copied()))
            .args
    }

    /// A sweep's table and figure hold one point per images mapped and one curve per λ, in
    /// the order of the images.
    #[test]
    fn a_sweep_has_a_curve_per_lambda_over_the_images() {
        let args = simulate_args(&[
            "--worlds", "2", "--pairs", "5", "--images", "10,5", "--lambda", "0,10",
        ]);
        let done: Vec<Setting> = [(10, 0.0), (10, 10.0), (5, 0.0), (5, 10.0)]
            .into_iter()
            .map(|(k, lambda)| {
                let study = study(&args, Some(k), lambda).unwrap();
                let records = study.run(&|| ());
                Setting {
                    summary: NavigationSummary::of(&records),
                    seconds: 0.0,
                    study,
                    records,
                }
            })
            .collect();
        let csv = sweep_csv(&done);
        assert_eq!(csv.lines().count(), 5);
        assert!(csv.lines().nth(3).unwrap().starts_with("5,0,10,"));
        let panels = sweep_panels(&done);
        assert_eq!(panels.len(), 3);
        for panel in &panels {
            assert_eq!(panel.x, [5.0, 10.0]);
            let labels: Vec<&str> = panel.curves.iter().map(|c| c.label.as_str()).collect();
            assert_eq!(labels, ["λ = 0", "λ = 10"]);
        }
        // Success at k = 5, λ = 0 is the third setting's.
        assert_eq!(
            panels[0].curves[0].mean[0],
            100.0 * done[2].summary.success_rate
        );
    }
}
