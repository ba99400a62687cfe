//! `pipeline directions`: route directions a person or rover can follow (004 Park & Kender;
//! docs/DIRECTIONS.md) from a run's map, with a picture of every target rock; and `pipeline
//! simulate directions`, the Monte Carlo that refits 004's leg reliability for the rover and
//! checks predicted route reliability against simulated following.

use super::map::{calculus_of, load, read};
use super::output::stage_json;
use super::pictures::{crop_with_context, plot_image};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use image::{ImageEncoder, RgbImage};
use qrm_atomic_file::OutputSet;
use qrm_core::directions::calibration::{
    calibration_bins, follow_routes, CalibrationSettings, Followed,
};
use qrm_core::directions::isolation::neighbour_ranks;
use qrm_core::directions::reliability::{selection_rate, SelectionRate};
use qrm_core::directions::{
    criteria, custom_map, rng_degrees, sampled_legs, steps, Criterion, Descriptor, LegGraph,
    MapNearness, Path, ReliabilityModel, Routes, Step, ViewNoise,
};
use qrm_core::edc::{self, Edc};
use qrm_core::map::{Hypergraph, LandmarkId};
use qrm_core::neighborhood::estimate;
use qrm_plot::{
    write_contact_sheet, write_reliability, CalibrationPoint, CalibrationSeries, ContactSheet,
    ReliabilityPicture, SelectionSeries, Tile,
};
use qrm_vision::run::{LandmarkRecord, StationRecord};
use qrm_vision::survey::read_image;
use serde_json::json;
use std::fmt::Write;
use std::path::{Path as FsPath, PathBuf};
use std::time::Instant;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum CriterionName {
    /// Least distance (the sum of the targets' neighbour ranks).
    Shortest,
    /// Most likely to reach the goal (least U = Σ −ln R).
    Reliable,
    /// Least D/R = D·e^U (004 §5.3).
    Compromise,
}

impl CriterionName {
    fn criterion(self) -> Criterion {
        match self {
            CriterionName::Shortest => Criterion::Shortest,
            CriterionName::Reliable => Criterion::Reliable,
            CriterionName::Compromise => Criterion::Compromise,
        }
    }
}

#[derive(Args, Debug)]
pub struct DirectionsArgs {
    /// A `pipeline run` output directory (map.json, landmarks.json, stations.json).
    #[arg(long, conflicts_with = "map", required_unless_present = "map")]
    run: Option<PathBuf>,
    /// A bare EDC map.json instead of a run (no pictures).
    #[arg(long)]
    map: Option<PathBuf>,
    /// The panoramas the run mapped: with `--out`, a crop of every target rock is written.
    #[arg(long)]
    images: Option<PathBuf>,
    /// Landmark id to start at (the one you stand at).
    #[arg(long)]
    from: LandmarkId,
    /// Landmark id to reach.
    #[arg(long)]
    to: LandmarkId,
    #[arg(long, value_enum, default_value = "compromise")]
    criterion: CriterionName,
    /// Largest scene a leg may use: the landmark you are at and its n − 1 nearest.
    #[arg(long, default_value_t = 6)]
    scene: usize,
    /// The rover's relative range error σ (s.d. of ln measured/true range) in R(n, σ).
    #[arg(long, default_value_t = 0.1)]
    range_error: f64,
    /// Realizations of the map to sample legs it does not prove from (0: proven legs only);
    /// a sampled leg's cost includes −ln of the share of realizations it holds in.
    #[arg(long, default_value_t = 16)]
    samples: usize,
    /// Seed of the first realization.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Write directions.txt, directions.json (and legs.png, leg_K.png with --images) here.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// The largest scene a leg may use: the reliability model is fitted up to 8 objects.
const MAX_SCENE: usize = 8;

/// Where the map came from.
struct Source {
    map: Hypergraph<Edc>,
    map_path: PathBuf,
    run: Option<(Vec<LandmarkRecord>, Vec<StationRecord>)>,
}

fn load_source(args: &DirectionsArgs) -> Result<Source> {
    let map_path = match (&args.run, &args.map) {
        (Some(run), _) => {
            if !run.is_dir() {
                bail!("run directory {} does not exist", run.display());
            }
            run.join("map.json")
        }
        (None, Some(map)) => map.clone(),
        (None, None) => bail!("give --run RUN_DIR or --map MAP.json"),
    };
    let text = read(&map_path)?;
    let calculus = calculus_of(&map_path, &text)?;
    if calculus != "EDC" {
        bail!(
            "{}: a {calculus} map cannot rank neighbours (only EDC tells distances apart); map with --calculus edc",
            map_path.display()
        );
    }
    let map: Hypergraph<Edc> = load(&map_path, &text)?;
    let run = match &args.run {
        None => None,
        Some(dir) => {
            let stations: Vec<StationRecord> = read_record(&dir.join("stations.json"))?;
            if stations.is_empty() {
                bail!("{} lists no stations", dir.join("stations.json").display());
            }
            let landmarks: Vec<LandmarkRecord> = read_record(&dir.join("landmarks.json"))?;
            if let Some(l) = landmarks.iter().find(|l| !map.contains(l.landmark)) {
                bail!(
                    "{} names landmark {} that {} does not hold: not the same run",
                    dir.join("landmarks.json").display(),
                    l.landmark,
                    map_path.display()
                );
            }
            Some((landmarks, stations))
        }
    };
    Ok(Source { map, map_path, run })
}

fn read_record<T: serde::de::DeserializeOwned>(path: &FsPath) -> Result<T> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!(
            "cannot read {} (a run directory holds map.json, landmarks.json and stations.json)",
            path.display()
        )
    })?;
    serde_json::from_str(&text).with_context(|| format!("{} is not a run's record", path.display()))
}

/// The chosen route and everything said about it.
struct Directions {
    ids: Vec<LandmarkId>,
    graph: LegGraph,
    realizations: usize,
    routes: Routes,
    per_leg: Option<Path>,
    criterion: Criterion,
    steps: Vec<Step>,
}

pub fn run(args: &DirectionsArgs) -> Result<()> {
    if !(2..=MAX_SCENE).contains(&args.scene) {
        bail!(
            "--scene {} must be 2..={MAX_SCENE} (the reliability model's range)",
            args.scene
        );
    }
    if args.from == args.to {
        bail!(
            "--from and --to are both landmark {}: you are there",
            args.from
        );
    }
    if args.images.is_some() && args.run.is_none() {
        bail!("--images needs --run: the pictures come from the run's stations and landmarks");
    }
    if !(args.range_error >= 0.0 && args.range_error <= 1.0) {
        bail!("--range-error {} must be in 0..=1", args.range_error);
    }
    let source = load_source(args)?;
    let directions =
        plan(&source.map, args).with_context(|| format!("in {}", source.map_path.display()))?;
    let text = text(&directions, args);
    let value = to_json(&directions, args);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        print!("{text}");
    }
    if let Some(out) = &args.out {
        write_outputs(out, &directions, &source, args, &text, &value)?;
    } else if args.images.is_some() {
        eprintln!("note: --images needs --out to write the pictures of the legs");
    }
    Ok(())
}

fn plan(map: &Hypergraph<Edc>, args: &DirectionsArgs) -> Result<Directions> {
    let ids = map.landmarks().to_vec();
    let index = |id: LandmarkId| {
        ids.iter().position(|&l| l == id).with_context(|| {
            format!(
                "landmark {id} is not in the map (it holds {} landmarks)",
                ids.len()
            )
        })
    };
    let (from, to) = (index(args.from)?, index(args.to)?);
    let (graph, sampled) = rover_legs(map, args.scene, args.samples, args.seed, args.range_error);
    let Some(routes) = graph.routes(from, to) else {
        let reach = criteria::strongly_connected(&graph.arcs, graph.nodes())
            .into_iter()
            .find(|c| c.contains(&from))
            .unwrap_or_default();
        bail!(
            "no route from landmark {} to landmark {}: of {} legs ({} proven by the map, the \
             others from {} of {} realizations), none chain there (landmark {} is in a group \
             of {} that reach one another); a map with more stations proves more neighbour \
             ranks, and --samples finds more legs it allows",
            args.from,
            args.to,
            graph.legs.len(),
            graph.legs.iter().filter(|l| l.is_proven()).count(),
            sampled.realizations,
            sampled.tried,
            args.from,
            reach.len()
        );
    };
    let criterion = args.criterion.criterion();
    let rng = estimate(map).expect("EDC has a lune");
    let signatures = rng_degrees(&ids, &rng);
    let left = |r: usize, n: usize, t: usize| {
        let states: Vec<bool> = map.relation_at(r, n, t).iter().map(edc::is_left).collect();
        if states.is_empty() {
            None
        } else if states.iter().all(|&l| l) {
            Some(true)
        } else if states.iter().all(|&l| !l) {
            Some(false)
        } else {
            None
        }
    };
    let nearness = MapNearness::new(map);
    // The landmark the map proves nearest (rank 1 for certain), for the side cue.
    let nearest = |r: usize| {
        neighbour_ranks(&nearness, r)
            .iter()
            .enumerate()
            .find(|&(y, rank)| y != r && rank.high == 1)
            .map(|(y, _)| y)
    };
    let steps = steps(
        &graph.legs_of(routes.get(criterion)),
        &graph.legs,
        &signatures,
        nearest,
        left,
    );
    let per_leg = criteria::per_leg_compromise(&graph.arcs, graph.nodes(), from, to);
    Ok(Directions {
        ids,
        graph,
        realizations: sampled.realizations,
        routes,
        per_leg,
        criterion,
        steps,
    })
}

/// The legs of `map` — proven, and sampled from `samples` realizations — as a graph costed by
/// the rover's reliability model at range error `sigma`; with the sampling's counts.
fn rover_legs(
    map: &Hypergraph<Edc>,
    scene: usize,
    samples: usize,
    seed: u64,
    sigma: f64,
) -> (LegGraph, SampledRealizations) {
    let sampled = sampled_legs(map, scene, samples, seed);
    let counts = SampledRealizations {
        realizations: sampled.realizations,
        tried: sampled.tried,
    };
    let graph = LegGraph::from_legs(sampled.legs, map.len(), &ReliabilityModel::ROVER, sigma);
    (graph, counts)
}

/// How many realizations the legs were sampled from, and how many were tried.
struct SampledRealizations {
    realizations: usize,
    tried: usize,
}

fn route_names(d: &Directions, path: &Path) -> String {
    path.nodes
        .iter()
        .map(|&n| format!("L{}", d.ids[n]))
        .collect::<Vec<_>>()
        .join(" → ")
}

/// Fig. 30 style table, the three criteria, and the instructions.
fn text(d: &Directions, args: &DirectionsArgs) -> String {
    let mut s = String::new();
    let path = d.routes.get(d.criterion);
    let _ = writeln!(
        s,
        "From L{} to L{} ({:?} route over {} legs with scenes of up to {} objects: {} proven by the map, the others sampled from {} realizations; range error σ = {}):",
        args.from,
        args.to,
        d.criterion,
        d.graph.legs.len(),
        args.scene,
        d.graph.legs.iter().filter(|l| l.is_proven()).count(),
        d.realizations,
        args.range_error
    );
    let _ = writeln!(
        s,
        "\n{:<5} {:>6} {:>6} {:>9} {:>5} {:>8} {:>8} {:>8}  VERIFY",
        "LEG", "FROM", "TO", "CHOICE", "RANK", "SUPPORT", "LOGPROB", "R"
    );
    for (k, step) in d.steps.iter().enumerate() {
        let leg = &step.leg;
        let u = d.graph.arcs[path.arcs[k]].u;
        let _ = writeln!(
            s,
            "{:<5} {:>6} {:>6} {:>9} {:>5} {:>8} {:>8.3} {:>8.3}  {}",
            k + 1,
            format!("L{}", d.ids[leg.from]),
            format!("L{}", d.ids[leg.to]),
            choice(leg),
            leg.rank.to_string(),
            if leg.is_proven() {
                "proven".to_string()
            } else {
                format!("{:.2}", leg.support)
            },
            u,
            (-u).exp(),
            step.verify.map_or("-".to_string(), neighbours)
        );
    }
    let _ = writeln!(
        s,
        "{:<5} {:>6} {:>6} {:>9} {:>5} {:>8} {:>8.3} {:>8.3}",
        "TOTAL",
        "",
        "",
        format!("{} legs", path.arcs.len()),
        path.d,
        "",
        path.u,
        path.reliability()
    );
    let _ = writeln!(
        s,
        "\nRoutes by criterion (D: sum of neighbour ranks, U = Σ −ln R):"
    );
    for (name, p) in [
        ("shortest", &d.routes.shortest),
        ("most reliable", &d.routes.reliable),
        ("compromise", &d.routes.compromise),
    ] {
        let _ = writeln!(
            s,
            "  {name:<14} D {:>4}  U {:.3}  R {:.3}  D/R {:>7.1}  {}",
            p.d,
            p.u,
            p.reliability(),
            p.d_over_r(),
            route_names(d, p)
        );
    }
    if let Some(per_leg) = &d.per_leg {
        if per_leg.nodes != d.routes.compromise.nodes {
            let _ = writeln!(
                s,
                "  per-leg ln d + u (Dijkstra, as 004 may have computed the compromise) differs: D {} U {:.3} D/R {:.1} {}",
                per_leg.d,
                per_leg.u,
                per_leg.d_over_r(),
                route_names(d, per_leg)
            );
        }
    }
    let _ = writeln!(s, "\nInstructions:");
    for (k, step) in d.steps.iter().enumerate() {
        let _ = writeln!(
            s,
            "{}. {}",
            k + 1,
            instruction(d, step, k + 1 == d.steps.len())
        );
    }
    let _ = writeln!(
        s,
        "\nCustom map (004 grammar, rotation invariant): {}",
        custom_map(&d.steps)
    );
    s
}

fn choice(leg: &qrm_core::directions::Leg) -> String {
    match leg.descriptor() {
        Descriptor::Obvious => "Obvious".into(),
        Descriptor::Isolated => format!("Isol/{}", leg.objects()),
    }
}

fn instruction(d: &Directions, step: &Step, last: bool) -> String {
    let name = |i: usize| format!("L{}", d.ids[i]);
    let leg = &step.leg;
    let mut s = match leg.descriptor() {
        Descriptor::Obvious => format!(
            "At {}, head for the nearest landmark: {}.",
            name(leg.from),
            name(leg.to)
        ),
        Descriptor::Isolated => format!(
            "At {}, of the {} landmarks nearest to you, head for the most isolated (the one \
             whose closest mutual neighbour is furthest in rank): {}.",
            name(leg.from),
            leg.objects() - 1,
            name(leg.to)
        ),
    };
    if let Some(side) = step.side {
        let _ = write!(
            s,
            " Facing {} (your nearest landmark), it is on your {}.",
            name(side.towards),
            if side.left { "left" } else { "right" }
        );
    }
    let _ = write!(
        s,
        " You are at {} when it is nearer than every other landmark in view.",
        name(leg.to)
    );
    if let Some(q) = step.verify {
        let _ = write!(
            s,
            " Check: {} has {}; none of the others it can be taken for has.",
            name(leg.to),
            neighbours(q)
        );
    }
    for r in &step.recover {
        let _ = write!(
            s,
            " If the landmark you reach has {}, you are at {}: from there {}.",
            neighbours(r.signature),
            name(r.leg.from),
            match r.leg.descriptor() {
                Descriptor::Obvious => format!("head for the nearest landmark, {}", name(r.leg.to)),
                Descriptor::Isolated => format!(
                    "head for the most isolated of the {} nearest, {}",
                    r.leg.objects() - 1,
                    name(r.leg.to)
                ),
            }
        );
    }
    if last {
        s.push_str(" This is the goal.");
    }
    s
}

fn neighbours(count: u32) -> String {
    match count {
        1 => "1 RNG neighbour".into(),
        n => format!("{n} RNG neighbours"),
    }
}

fn path_json(d: &Directions, p: &Path) -> serde_json::Value {
    json!({
        "landmarks": p.nodes.iter().map(|&n| d.ids[n]).collect::<Vec<_>>(),
        "distance": p.d,
        "unreliability": p.u,
        "reliability": p.reliability(),
        "d_over_r": p.d_over_r(),
    })
}

fn to_json(d: &Directions, args: &DirectionsArgs) -> serde_json::Value {
    let path = d.routes.get(d.criterion);
    let legs: Vec<_> = d
        .steps
        .iter()
        .enumerate()
        .map(|(k, step)| {
            let leg = &step.leg;
            let u = d.graph.arcs[path.arcs[k]].u;
            json!({
                "from": d.ids[leg.from],
                "to": d.ids[leg.to],
                "descriptor": leg.descriptor(),
                "scene": leg.scene.iter().map(|&i| d.ids[i]).collect::<Vec<_>>(),
                "rank": {"low": leg.rank.low, "high": leg.rank.high},
                "proven": leg.is_proven(),
                "support": leg.support,
                "unreliability": u,
                "reliability": (-u).exp(),
                "verify_rng_degree": step.verify,
                "recover": step.recover.iter().map(|r| json!({
                    "rng_degree": r.signature,
                    "at": d.ids[r.leg.from],
                    "descriptor": r.leg.descriptor(),
                    "scene_objects": r.leg.objects(),
                })).collect::<Vec<_>>(),
                "side": step.side.map(|c| json!({
                    "facing": d.ids[c.towards],
                    "left": c.left,
                })),
                "instruction": instruction(d, step, k + 1 == d.steps.len()),
            })
        })
        .collect();
    json!({
        "format": "qrm-directions",
        "version": 1,
        "from": args.from,
        "to": args.to,
        "criterion": d.criterion,
        "scene": args.scene,
        "range_error": args.range_error,
        "model": ReliabilityModel::ROVER,
        "legs_in_map": d.graph.legs.len(),
        "legs_proven": d.graph.legs.iter().filter(|l| l.is_proven()).count(),
        "realizations": d.realizations,
        "samples": args.samples,
        "route": path_json(d, path),
        "routes": {
            "shortest": path_json(d, &d.routes.shortest),
            "reliable": path_json(d, &d.routes.reliable),
            "compromise": path_json(d, &d.routes.compromise),
            "per_leg_compromise": d.per_leg.as_ref().map(|p| path_json(d, p)),
        },
        "legs": legs,
        "custom_map": custom_map(&d.steps).to_string(),
    })
}

fn write_outputs(
    out: &FsPath,
    d: &Directions,
    source: &Source,
    args: &DirectionsArgs,
    text: &str,
    value: &serde_json::Value,
) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut outputs = OutputSet::new();
    let json = serde_json::to_string_pretty(value)? + "\n";
    for (name, bytes) in [
        ("directions.txt", text.as_bytes()),
        ("directions.json", json.as_bytes()),
    ] {
        let path = out.join(name);
        outputs
            .stage_bytes(&path, bytes)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    for stale in std::fs::read_dir(out)?
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("leg_") && n.ends_with(".png"))
        })
    {
        outputs.remove_stale(&stale);
    }
    match (&source.run, &args.images) {
        (Some((landmarks, stations)), Some(images)) => {
            stage_leg_pictures(&mut outputs, out, d, landmarks, stations, images)?;
        }
        _ => outputs.remove_stale(&out.join("legs.png")),
    }
    outputs
        .commit()
        .with_context(|| format!("cannot move the outputs into {}", out.display()))?;
    eprintln!("wrote {}", out.display());
    Ok(())
}

/// A crop of each leg's target rock from the panorama where it was seen largest, at the
/// panorama's resolution (`leg_K.png`), and all of them on one captioned sheet (`legs.png`).
fn stage_leg_pictures(
    outputs: &mut OutputSet,
    out: &FsPath,
    d: &Directions,
    landmarks: &[LandmarkRecord],
    stations: &[StationRecord],
    images: &FsPath,
) -> Result<()> {
    let sheet = out.join("legs.png");
    let first = stations
        .iter()
        .find_map(|s| s.files.first())
        .map(|f| images.join(f));
    let size = match first.as_deref().map(|f| (f, image::image_dimensions(f))) {
        Some((_, Ok(size))) => size,
        Some((f, Err(e))) => {
            eprintln!(
                "warning: no pictures of the legs: cannot read {}: {e}",
                f.display()
            );
            outputs.remove_stale(&sheet);
            return Ok(());
        }
        None => {
            eprintln!("warning: no pictures of the legs: the run's stations name no image files");
            outputs.remove_stale(&sheet);
            return Ok(());
        }
    };
    let mut tiles: Vec<(RgbImage, String, String)> = Vec::new();
    for (k, step) in d.steps.iter().enumerate() {
        let target = d.ids[step.leg.to];
        let best = landmarks
            .iter()
            .find(|l| l.landmark == target)
            .and_then(|l| {
                l.sightings.iter().copied().max_by_key(|&(s, i)| {
                    stations
                        .get(s)
                        .and_then(|r| r.detections.get(i))
                        .map_or(0, |det| det.pixels)
                })
            });
        let Some((station, detection)) = best else {
            eprintln!(
                "warning: landmark {target} has no sighting in the run: no picture for leg {}",
                k + 1
            );
            continue;
        };
        let (Some(record), Some(file)) = (
            stations.get(station),
            stations.get(station).and_then(|r| r.files.first()),
        ) else {
            continue;
        };
        let Some(det) = record.detections.get(detection) else {
            continue;
        };
        let panorama = match read_image(&images.join(file), size) {
            Ok(panorama) => panorama,
            Err(e) => {
                eprintln!("warning: no picture for leg {}: {e}", k + 1);
                continue;
            }
        };
        let (full, fitted) = crop_with_context(&panorama, det.bbox);
        let path = out.join(format!("leg_{}.png", k + 1));
        let mut bytes = Vec::new();
        image::codecs::png::PngEncoder::new(&mut bytes)
            .write_image(
                full.as_raw(),
                full.width(),
                full.height(),
                image::ExtendedColorType::Rgb8,
            )
            .context("encode a leg picture")?;
        outputs
            .stage_bytes(&path, &bytes)
            .with_context(|| format!("cannot write {}", path.display()))?;
        tiles.push((
            fitted,
            format!("leg {}: L{target}", k + 1),
            format!("{}, {}", choice(&step.leg), record.station),
        ));
    }
    if tiles.is_empty() {
        outputs.remove_stale(&sheet);
        return Ok(());
    }
    let tiles: Vec<Tile> = tiles
        .iter()
        .map(|(image, caption, note)| Tile {
            image: plot_image(image),
            caption: caption.clone(),
            note: note.clone(),
        })
        .collect();
    let title = format!(
        "Rock to head for, L{} → L{}",
        d.ids[d.routes.get(d.criterion).nodes[0]],
        d.ids[*d
            .routes
            .get(d.criterion)
            .nodes
            .last()
            .expect("a route has nodes")]
    );
    outputs.stage(&sheet, |temporary| {
        write_contact_sheet(
            temporary,
            &ContactSheet {
                title,
                tiles: &tiles,
            },
        )
    })?;
    Ok(())
}

#[derive(Args, Debug)]
pub struct DirectionsStudyArgs {
    /// Monte Carlo trials per (n, σ) setting of the reliability fit.
    #[arg(long, default_value_t = 20_000)]
    trials: usize,
    /// Routes followed for the calibration plot.
    #[arg(long, default_value_t = 400)]
    routes: usize,
    /// Landmarks of each random field the routes are planned in.
    #[arg(long, default_value_t = 40)]
    landmarks: usize,
    /// Largest scene a leg may use.
    #[arg(long, default_value_t = 6)]
    scene: usize,
    /// Bearing error s.d., degrees.
    #[arg(long, default_value_t = 0.5)]
    bearing_error: f64,
    /// Range error σ of the routes followed (the fit covers 0.05, 0.1, 0.2, 0.3).
    #[arg(long, default_value_t = 0.1)]
    range_error: f64,
    #[arg(long, value_enum, default_value = "compromise")]
    criterion: CriterionName,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory: reliability.json, reliability.png.
    #[arg(long, default_value = "directions-study")]
    out: PathBuf,
}

/// Calibration bins as the figure draws them.
fn points(bins: &[qrm_core::directions::calibration::CalibrationBin]) -> Vec<CalibrationPoint> {
    bins.iter()
        .map(|b| CalibrationPoint {
            predicted: b.predicted,
            measured: b.measured,
            low: b.low,
            high: b.high,
            routes: b.routes,
        })
        .collect()
}

/// Range errors of the fit.
const FIT_SIGMAS: [f64; 4] = [0.05, 0.1, 0.2, 0.3];
/// Scene sizes of the fit.
const FIT_OBJECTS: std::ops::RangeInclusive<usize> = 2..=MAX_SCENE;

pub fn study(args: &DirectionsStudyArgs) -> Result<()> {
    if args.trials == 0 || args.routes == 0 {
        bail!("--trials and --routes must be positive");
    }
    if !(2..=MAX_SCENE).contains(&args.scene) {
        bail!("--scene {} must be 2..={MAX_SCENE}", args.scene);
    }
    if args.landmarks < args.scene + 1 {
        bail!("--landmarks must exceed --scene");
    }
    if !(0.0..=10.0).contains(&args.bearing_error) || !(0.0..=1.0).contains(&args.range_error) {
        bail!("--bearing-error must be 0..=10 degrees and --range-error 0..=1");
    }
    let started = Instant::now();
    let bearing_sd = args.bearing_error.to_radians();
    let settings: Vec<(usize, f64)> = FIT_OBJECTS
        .flat_map(|n| FIT_SIGMAS.map(|sigma| (n, sigma)))
        .collect();
    let bar = super::simulate::progress(settings.len() as u64 + 1, "reliability fit, then routes");
    let rates: Vec<SelectionRate> = settings
        .iter()
        .map(|&(objects, sigma)| {
            let rate = selection_rate(
                objects,
                ViewNoise {
                    bearing_sd,
                    range_sd: sigma,
                    standoff: 1.0,
                },
                args.trials,
                args.seed,
            );
            bar.inc(1);
            rate
        })
        .collect();
    let model = ReliabilityModel::fit(&rates).context("the fit needs four settings")?;
    let calibration = CalibrationSettings {
        landmarks: args.landmarks,
        max_objects: args.scene,
        noise: ViewNoise {
            bearing_sd,
            range_sd: args.range_error,
            standoff: 1.0,
        },
        model,
        criterion: args.criterion.criterion(),
    };
    let followed = follow_routes(&calibration, args.routes, args.seed);
    bar.inc(1);
    bar.finish_and_clear();
    let bins = calibration_bins(&followed, 10);
    let predicted: f64 = followed.iter().map(|f| f.predicted).sum::<f64>() / followed.len() as f64;
    let measured = followed.iter().filter(|f| f.succeeded).count() as f64 / followed.len() as f64;
    let brier = followed
        .iter()
        .map(|f| (f.predicted - f64::from(u8::from(f.succeeded))).powi(2))
        .sum::<f64>()
        / followed.len() as f64;

    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let value = json!({
        "format": "qrm-directions-reliability",
        "version": 1,
        "bearing_error_deg": args.bearing_error,
        "trials": args.trials,
        "seed": args.seed,
        "model": model,
        "rates": rates,
        "calibration": {
            "settings": calibration,
            "routes": followed.len(),
            "mean_predicted": predicted,
            "measured": measured,
            "brier": brier,
            "bins": bins,
            "legs": followed.iter().map(|f: &Followed| f.legs).sum::<usize>(),
        },
    });
    let picture = ReliabilityPicture {
        title: format!(
            "Leg reliability R(n, σ) = (aσ + b)/n − cσ + d (004 Eq. 1) refitted: a = {:.3}, b = {:.3}, c = {:.3}, d = {:.3}; bearing error {}°",
            model.a, model.b, model.c, model.d, args.bearing_error
        ),
        selection: FIT_SIGMAS
            .iter()
            .map(|&sigma| SelectionSeries {
                label: format!("σ = {sigma}: measured (dots), Eq. (1) fit (line)"),
                measured: rates
                    .iter()
                    .filter(|r| r.sigma == sigma)
                    .map(|r| (r.objects as f64, r.rate()))
                    .collect(),
                fitted: FIT_OBJECTS
                    .map(|n| (n as f64, model.reliability(n, sigma)))
                    .collect(),
            })
            .collect(),
        calibration: vec![CalibrationSeries {
            label: "routes: measured success per bin, 95 % interval".into(),
            points: points(&bins),
        }],
        calibration_title: format!(
            "(b) {} {:?} routes followed, σ = {} (routes per bin)",
            followed.len(),
            calibration.criterion,
            args.range_error
        ),
    };
    let mut outputs = OutputSet::new();
    stage_json(&mut outputs, &args.out.join("reliability.json"), &value)?;
    outputs.stage(&args.out.join("reliability.png"), |t| {
        write_reliability(t, &picture)
    })?;
    outputs
        .commit()
        .with_context(|| format!("cannot move the outputs into {}", args.out.display()))?;

    println!("R(n, σ) = (aσ + b)/n − cσ + d fitted over n = 2..=8, σ ∈ {FIT_SIGMAS:?}, {} trials each, bearing error {}°:", args.trials, args.bearing_error);
    println!(
        "  a = {:.4}, b = {:.4}, c = {:.4}, d = {:.4}",
        model.a, model.b, model.c, model.d
    );
    println!(
        "{:>3} {}",
        "n",
        FIT_SIGMAS
            .map(|s| format!("  σ={s:<4} measured/model"))
            .join("")
    );
    for n in FIT_OBJECTS {
        let mut line = format!("{n:>3}");
        for sigma in FIT_SIGMAS {
            let r = rates
                .iter()
                .find(|r| r.objects == n && r.sigma == sigma)
                .expect("every setting measured");
            let _ = write!(
                line,
                "  {:>8.3} / {:<8.3}   ",
                r.rate(),
                model.reliability(n, sigma)
            );
        }
        println!("{line}");
    }
    println!(
        "{} routes ({:?}, σ = {}, {} landmarks): predicted mean reliability {:.3}, measured {:.3}, Brier score {:.3}",
        followed.len(),
        calibration.criterion,
        args.range_error,
        args.landmarks,
        predicted,
        measured,
        brier
    );
    for b in &bins {
        println!(
            "  predicted {:.2}: measured {:.2} [{:.2}, {:.2}] over {} routes",
            b.predicted, b.measured, b.low, b.high, b.routes
        );
    }
    println!(
        "wrote {} ({:.1} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

#[derive(Args, Debug)]
pub struct TrialArgs {
    /// The synthetic dataset whose world is rendered (truth.json, calib.toml).
    #[arg(long)]
    images: PathBuf,
    /// The run over that dataset whose map the routes are planned on (with eval.json, which
    /// says which rock each landmark is, for judging).
    #[arg(long)]
    run: PathBuf,
    /// Routes to follow.
    #[arg(long, default_value_t = 200)]
    routes: usize,
    #[arg(long, value_enum, default_value = "compromise")]
    criterion: CriterionName,
    /// Largest scene a leg may use.
    #[arg(long, default_value_t = 6)]
    scene: usize,
    /// Realizations of the map to sample legs from.
    #[arg(long, default_value_t = 16)]
    samples: usize,
    /// The range error σ the routes are planned with (compare the measured one it prints).
    #[arg(long, default_value_t = 0.1)]
    range_error: f64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory: trials.json, summary.json, calibration.png.
    #[arg(long, default_value = "directions-trials")]
    out: PathBuf,
}

/// Start/goal draws before the trial gives up finding routes.
const ROUTE_ATTEMPTS: usize = 100;

/// `navigate directions`: routes planned on a run's map, followed through panoramas rendered
/// in its dataset's world (`qrm_synth::directions_trial`).
pub fn trial(args: &TrialArgs) -> Result<()> {
    use qrm_synth::closed_loop::Terrain;
    use qrm_synth::directions_trial::{follow_route, RouteTrial};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rayon::prelude::*;

    if args.routes == 0 {
        bail!("--routes must be at least 1");
    }
    if !(2..=MAX_SCENE).contains(&args.scene) {
        bail!("--scene {} must be 2..={MAX_SCENE}", args.scene);
    }
    if !(0.0..=1.0).contains(&args.range_error) {
        bail!("--range-error {} must be in 0..=1", args.range_error);
    }
    let started = Instant::now();
    let (calib, world, origin) = super::drive::rendered_world(&args.images)?;
    let (known, landmark_rocks) = super::drive::run_of(&args.run, &world, &args.images)?;
    let map = &known.map;
    let ids = map.landmarks().to_vec();
    let (graph, sampled) = rover_legs(map, args.scene, args.samples, args.seed, args.range_error);
    let usable: Vec<usize> = (0..ids.len())
        .filter(|&i| landmark_rocks.contains_key(&ids[i]))
        .collect();
    // The routes: random start/goal pairs of landmarks that stand for rocks, with a route.
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut planned = Vec::new();
    let mut attempts = 0;
    while planned.len() < args.routes && usable.len() >= 2 {
        attempts += 1;
        if attempts > ROUTE_ATTEMPTS * args.routes {
            break;
        }
        let (from, to) = (
            usable[rng.random_range(0..usable.len())],
            usable[rng.random_range(0..usable.len())],
        );
        if from == to {
            continue;
        }
        if let Some(routes) = graph.routes(from, to) {
            let path = routes.get(args.criterion.criterion()).clone();
            if path
                .nodes
                .iter()
                .all(|n| landmark_rocks.contains_key(&ids[*n]))
            {
                planned.push(path);
            }
        }
    }
    if planned.is_empty() {
        bail!(
            "{}: no route between landmarks that stand for rocks ({} legs, {} landmarks with rocks)",
            args.run.display(),
            graph.legs.len(),
            usable.len()
        );
    }
    let terrain = Terrain {
        world: &world,
        calib: &calib,
        landmark_rocks: &landmark_rocks,
    };
    let settings = qrm_vision::run::RunSettings::default();
    let bar = super::simulate::progress(planned.len() as u64, "routes followed");
    let trials: Vec<RouteTrial> = planned
        .par_iter()
        .enumerate()
        .filter_map(|(k, path)| {
            let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
            rng.set_stream(k as u64 + 1);
            let trial = follow_route(&terrain, &known, &settings, &graph, path, &ids, &mut rng);
            bar.inc(1);
            trial
        })
        .collect();
    bar.finish_and_clear();

    // Route outcomes of the two rovers (qrm_synth::directions_trial).
    let outcome = |identified: bool| -> Vec<Followed> {
        trials
            .iter()
            .map(|t| Followed {
                predicted: t.predicted,
                legs: t.legs.len(),
                succeeded: if identified {
                    t.succeeded_identified
                } else {
                    t.succeeded
                },
            })
            .collect()
    };
    let (literal, identified) = (outcome(false), outcome(true));
    let scores = |followed: &[Followed]| {
        let n = followed.len() as f64;
        let measured = followed.iter().filter(|f| f.succeeded).count() as f64 / n;
        let brier = followed
            .iter()
            .map(|f| (f.predicted - f64::from(u8::from(f.succeeded))).powi(2))
            .sum::<f64>()
            / n;
        (measured, brier, calibration_bins(followed, 10))
    };
    let predicted = literal.iter().map(|f| f.predicted).sum::<f64>() / literal.len() as f64;
    let (measured_literal, brier_literal, bins_literal) = scores(&literal);
    let (measured_identified, brier_identified, bins_identified) = scores(&identified);
    let legs: Vec<&qrm_synth::directions_trial::LegTrial> =
        trials.iter().flat_map(|t| &t.legs).collect();
    let errors: Vec<f64> = legs
        .iter()
        .flat_map(|l| l.range_log_errors.iter().copied())
        .collect();
    let mean_error = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
    let sigma = (errors.iter().map(|e| (e - mean_error).powi(2)).sum::<f64>()
        / errors.len().max(1) as f64)
        .sqrt();
    // Legs that hold in truth: selection by scene size, against the model.
    let by_objects = |identified: bool| -> Vec<(usize, usize, usize)> {
        (2..=args.scene)
            .map(|objects| {
                let these: Vec<_> = legs
                    .iter()
                    .filter(|l| l.holds && l.objects == objects)
                    .collect();
                let correct = these
                    .iter()
                    .filter(|l| {
                        if identified {
                            l.correct_identified
                        } else {
                            l.correct
                        }
                    })
                    .count();
                (objects, correct, these.len())
            })
            .filter(|&(_, _, count)| count > 0)
            .collect()
    };
    let leg_count = legs.len().max(1) as f64;
    let leg_predicted = legs.iter().map(|l| l.predicted).sum::<f64>() / leg_count;
    let leg_literal = legs.iter().filter(|l| l.correct).count() as f64 / leg_count;
    let leg_identified = legs.iter().filter(|l| l.correct_identified).count() as f64 / leg_count;
    let leg_outcomes: Vec<Followed> = legs
        .iter()
        .map(|l| Followed {
            predicted: l.predicted,
            legs: 1,
            succeeded: l.correct_identified,
        })
        .collect();
    let leg_bins = calibration_bins(&leg_outcomes, 10);
    let by_json = |rows: Vec<(usize, usize, usize)>| {
        rows.iter()
            .map(|&(o, c, t)| json!({"objects": o, "correct": c, "legs": t}))
            .collect::<Vec<_>>()
    };
    let summary = json!({
        "format": "qrm-directions-trials",
        "version": 1,
        "world": origin,
        "run": args.run,
        "criterion": args.criterion.criterion(),
        "range_error_planned": args.range_error,
        "range_error_measured": {"sd": sigma, "mean": mean_error, "detections": errors.len()},
        "legs_in_map": graph.legs.len(),
        "legs_proven": graph.legs.iter().filter(|l| l.is_proven()).count(),
        "realizations": sampled.realizations,
        "routes": trials.len(),
        "mean_predicted": predicted,
        "identified": {"measured": measured_identified, "brier": brier_identified, "bins": bins_identified},
        "literal": {"measured": measured_literal, "brier": brier_literal, "bins": bins_literal},
        "legs": {
            "count": legs.len(),
            "mean_predicted": leg_predicted,
            "measured_identified": leg_identified,
            "measured_literal": leg_literal,
            "holding_in_truth": legs.iter().filter(|l| l.holds).count(),
            "target_seen": legs.iter().filter(|l| l.target_seen).count(),
            "target_identified": legs.iter().filter(|l| l.target_identified).count(),
            "bins_identified": leg_bins,
            "by_objects_holding_identified": by_json(by_objects(true)),
            "by_objects_holding_literal": by_json(by_objects(false)),
        },
        "seconds": started.elapsed().as_secs_f64(),
    });
    let picture = ReliabilityPicture {
        title: format!(
            "Directions followed through rendered panoramas ({origin}); legs planned with σ = {}, measured σ = {:.2}",
            args.range_error, sigma
        ),
        selection: [(true, "identified"), (false, "literal")]
            .into_iter()
            .map(|(identified, name)| SelectionSeries {
                label: if identified {
                    format!(
                        "identified rover, legs that hold in truth (dots); Eq. (1) at σ = {sigma:.2} (line)"
                    )
                } else {
                    format!("{name} rover, legs that hold in truth")
                },
                measured: by_objects(identified)
                    .iter()
                    .map(|&(o, c, t)| (o as f64, c as f64 / t as f64))
                    .collect(),
                fitted: if identified {
                    (2..=args.scene)
                        .map(|o| (o as f64, ReliabilityModel::ROVER.reliability(o, sigma)))
                        .collect()
                } else {
                    Vec::new()
                },
            })
            .collect(),
        calibration: vec![
            CalibrationSeries {
                label: "identified rover, legs (count per bin, 95 % interval)".into(),
                points: points(&leg_bins),
            },
            CalibrationSeries {
                label: "identified rover, whole routes".into(),
                points: points(&bins_identified),
            },
        ],
        calibration_title: format!(
            "(b) {} legs of {} {:?} routes",
            legs.len(),
            trials.len(),
            args.criterion.criterion()
        ),
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut outputs = OutputSet::new();
    stage_json(
        &mut outputs,
        &args.out.join("trials.json"),
        &serde_json::to_value(&trials)?,
    )?;
    stage_json(&mut outputs, &args.out.join("summary.json"), &summary)?;
    let figure = args.out.join("calibration.png");
    if picture.selection.iter().any(|s| !s.measured.is_empty()) {
        outputs.stage(&figure, |t| write_reliability(t, &picture))?;
    } else {
        eprintln!("note: no leg holds in truth: no calibration.png");
        outputs.remove_stale(&figure);
    }
    outputs
        .commit()
        .with_context(|| format!("cannot move the outputs into {}", args.out.display()))?;
    println!("{}", serde_json::to_string_pretty(&summary)?);
    Ok(())
}
