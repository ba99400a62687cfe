//! `pipeline simulate`: simulated mapping with ground truth (000 §VIII-B; 003 §1.5.2).

use super::output::write_atomic;
use super::CalculusName;
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::geometry::Point;
use qrm_core::map::{Hypergraph, Sighting};
use qrm_core::measurement::MAX_BEARING_UNCERTAINTY;
use qrm_core::neighborhood::{estimate, true_rng};
use qrm_core::probabilistic::map::{Estimator, Variant};
use qrm_core::simulation::beliefs::{beliefs, compare, BeliefSettings};
use qrm_core::simulation::{
    run, MonteCarlo, MonteCarloResult, Scenario, Sensor, Series, Statistic,
};
use qrm_plot::{write_panels, write_rng, Axes, Curve, Panel, RngPicture};
use rand::SeedableRng;
use std::fmt::Write;
use std::path::PathBuf;
use std::time::Instant;

/// Largest simulated map: 300 landmarks are 4.5 M triples (about 60 MB) and take minutes.
const MAX_SIMULATED_LANDMARKS: usize = 300;

#[derive(Subcommand, Debug)]
pub enum SimulateCommand {
    /// Monte Carlo study over random maps; `--study fig7` reproduces 000 Fig. 7, `--study
    /// dissertation` 003 Fig. 1.6b. Writes montecarlo.csv and the panels as PNG and SVG.
    Montecarlo(MonteCarloArgs),
    /// One random map: writes the final map (JSON), its RNG (JSON), and per-image metrics (CSV).
    Single(SingleArgs),
    /// 003 Fig. 1.5: four landmarks, imaging points chosen one by one where they constrain the
    /// map most, until it is fully constrained.
    Basic(BasicArgs),
    /// The reliability of route-direction legs (004 §6.1.2) refitted for the rover by Monte
    /// Carlo (Eq. 1 over scene size n and range error σ), and routes followed with noisy
    /// perception against their predicted reliability. Writes reliability.json and
    /// reliability.png (docs/DIRECTIONS.md).
    Directions(super::directions::DirectionsStudyArgs),
    /// 002's Table I (Mor & Indelman): random triplets seen from three camera poses with
    /// noisy bearings and motion, estimated by the full, fast and baseline probabilistic
    /// algorithms; DMSE, gmd and entropy percentiles printed beside the paper's.
    Probabilistic(super::probabilistic::ProbabilisticArgs),
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Study {
    Fig7,
    Dissertation,
}

/// Sensor options shared by the studies.
#[derive(Args, Debug, Clone)]
pub struct SensorArgs {
    /// Bearing noise: errors uniform within ± this many degrees (the measurement is told so).
    #[arg(long, default_value_t = 0.0)]
    bearing_noise: f64,
    /// Probability of swapping each adjacent pair of the true range order (range-order errors;
    /// rejected panoramas are counted as contradictions).
    #[arg(long, default_value_t = 0.0)]
    order_swaps: f64,
    /// Probability that a sighting is reported as another landmark, one not seen at that
    /// imaging point (association errors: a look-alike from elsewhere in the field).
    #[arg(long, default_value_t = 0.0)]
    wrong_associations: f64,
}

impl SensorArgs {
    fn sensor(&self, nearest: Option<usize>) -> Result<Sensor> {
        if !(0.0..=1.0).contains(&self.wrong_associations) {
            bail!(
                "--wrong-associations {} must be a probability",
                self.wrong_associations
            );
        }
        Ok(Sensor {
            wrong_association_probability: self.wrong_associations,
            ..sensor(self.bearing_noise, self.order_swaps, nearest)?
        })
    }
}

/// The simulated sensor: bearing errors uniform within ±`bearing_noise` degrees (and the
/// measurement told so), each adjacent pair of the range order swapped with probability
/// `order_swaps`, the `nearest` landmarks seen (all: `None`), no association errors.
pub fn sensor(bearing_noise: f64, order_swaps: f64, nearest: Option<usize>) -> Result<Sensor> {
    if nearest.is_some_and(|n| n < 3) {
        bail!("--nearest must be at least 3 (a triple)");
    }
    if !(0.0..MAX_BEARING_UNCERTAINTY.to_degrees()).contains(&bearing_noise) {
        bail!(
            "--bearing-noise {} must lie in [0, {}) degrees",
            bearing_noise,
            MAX_BEARING_UNCERTAINTY.to_degrees()
        );
    }
    if !(0.0..=1.0).contains(&order_swaps) {
        bail!("--order-swaps {} must be a probability", order_swaps);
    }
    Ok(Sensor {
        nearest,
        bearing_noise: bearing_noise.to_radians(),
        bearing_uncertainty: bearing_noise.to_radians(),
        order_swap_probability: order_swaps,
        wrong_association_probability: 0.0,
    })
}

#[derive(Args, Debug)]
pub struct MonteCarloArgs {
    #[arg(long, value_enum, default_value = "fig7")]
    study: Study,
    /// Override the number of random maps.
    #[arg(long)]
    maps: Option<usize>,
    /// Override the number of imaging points per map.
    #[arg(long)]
    stations: Option<usize>,
    /// Override the nearest-landmark counts, e.g. `6,9,12,18,24,30`.
    #[arg(long, value_delimiter = ',')]
    nearest: Vec<usize>,
    #[arg(long, value_enum)]
    calculus: Option<CalculusName>,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    #[command(flatten)]
    sensor: SensorArgs,
    /// Output directory.
    #[arg(long, default_value = "montecarlo")]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct SingleArgs {
    #[arg(long, default_value_t = 30)]
    landmarks: usize,
    #[arg(long, default_value_t = 50)]
    stations: usize,
    /// Use the n nearest landmarks at each imaging point (default: all).
    #[arg(long)]
    nearest: Option<usize>,
    #[arg(long, value_enum, default_value = "edc")]
    calculus: CalculusName,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    #[command(flatten)]
    sensor: SensorArgs,
    /// `probabilistic`: also 002's beliefs (Mor & Indelman) over the 20 EDC states of every
    /// triple seen together at two or more imaging points, beside the deterministic map:
    /// beliefs.json and a comparison of both with the truth (docs/PROBABILISTIC.md). EDC only.
    #[arg(long, value_enum, default_value = "deterministic")]
    mode: Mode,
    #[command(flatten)]
    beliefs: BeliefArgs,
    /// Output directory.
    #[arg(long, default_value = "simulation")]
    out: PathBuf,
}

/// What `simulate single` maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// The map of sets (000).
    Deterministic,
    /// The map of sets, and 002's beliefs beside it.
    Probabilistic,
}

/// How `--mode probabilistic` makes its beliefs in the simulator.
#[derive(Args, Debug)]
pub struct BeliefArgs {
    #[command(flatten)]
    estimator: EstimatorArgs,
    /// Noise of 002's motion command (heading of the displacement between two views, which
    /// the deterministic map does not use), s.d. in degrees (default 2).
    #[arg(long)]
    motion_noise: Option<f64>,
}

/// Which of 002's estimators makes the beliefs of `--mode probabilistic`, and how. Given
/// without that mode, they are refused rather than ignored.
#[derive(Args, Debug)]
pub struct EstimatorArgs {
    /// 002's estimator: `fast` (§III-D, the default) or `full` (Algorithm 1).
    #[arg(long, value_enum)]
    estimator: Option<EstimatorName>,
    /// Views per triple: the first stations that see it (002: 3 time steps; the default).
    #[arg(long)]
    views: Option<usize>,
    /// Particles per triple (default 300).
    #[arg(long)]
    particles: Option<usize>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EstimatorName {
    Fast,
    Full,
}

impl EstimatorArgs {
    /// The estimator these options choose, for `mode`; an error if they were given for the
    /// deterministic mode, which makes no beliefs.
    pub(super) fn estimator(&self, mode: Mode) -> Result<Estimator> {
        let given = self.estimator.is_some() || self.views.is_some() || self.particles.is_some();
        if mode == Mode::Deterministic && given {
            bail!("--estimator, --views and --particles shape 002's beliefs: give them with --mode probabilistic");
        }
        let views = self.views.unwrap_or(3);
        let particles = self.particles.unwrap_or(300);
        if views < 2 {
            bail!("--views must be at least 2: 002 resects C from two views or more");
        }
        if particles == 0 {
            bail!("--particles must be positive");
        }
        Ok(Estimator {
            variant: match self.estimator.unwrap_or(EstimatorName::Fast) {
                EstimatorName::Fast => Variant::Fast,
                EstimatorName::Full => Variant::Full,
            },
            views,
            particles,
        })
    }
}

impl BeliefArgs {
    /// The simulator's belief settings for `mode` (refused if given for the deterministic one).
    fn settings(&self, mode: Mode) -> Result<BeliefSettings> {
        if mode == Mode::Deterministic && self.motion_noise.is_some() {
            bail!("--motion-noise is the noise of 002's motion command: give it with --mode probabilistic");
        }
        let motion_noise = self.motion_noise.unwrap_or(2.0);
        if !(0.0..=60.0).contains(&motion_noise) {
            bail!("--motion-noise {motion_noise} must lie in [0, 60] degrees");
        }
        Ok(BeliefSettings {
            estimator: self.estimator.estimator(mode)?,
            motion_noise: motion_noise.to_radians(),
        })
    }
}

#[derive(Args, Debug)]
pub struct BasicArgs {
    #[arg(long, value_enum, default_value = "edc")]
    calculus: CalculusName,
    #[arg(long, default_value_t = 3)]
    seed: u64,
}

pub fn run_command(command: SimulateCommand) -> Result<()> {
    match command {
        SimulateCommand::Montecarlo(args) => montecarlo(args),
        SimulateCommand::Directions(args) => super::directions::study(&args),
        SimulateCommand::Probabilistic(args) => super::probabilistic::run(&args),
        SimulateCommand::Single(args) => {
            let settings = args.beliefs.settings(args.mode)?;
            match (args.calculus, args.mode) {
                (CalculusName::Edc, Mode::Probabilistic) => {
                    let simulated = single::<Edc>(&args)?;
                    probabilistic_single(&args, &settings, &simulated)
                }
                (CalculusName::Fdc, Mode::Probabilistic) => bail!(
                    "--mode probabilistic needs --calculus edc: 002's beliefs are over the 20 EDC states"
                ),
                (CalculusName::Edc, Mode::Deterministic) => single::<Edc>(&args).map(drop),
                (CalculusName::Fdc, Mode::Deterministic) => single::<Fdc>(&args).map(drop),
            }
        }
        SimulateCommand::Basic(args) => match args.calculus {
            CalculusName::Edc => basic::<Edc>(args.seed),
            CalculusName::Fdc => basic::<Fdc>(args.seed),
        },
    }
}

/// The study `simulate montecarlo` runs for `args`, and its calculus.
pub fn study(args: &MonteCarloArgs) -> Result<(MonteCarlo, CalculusName)> {
    let (mut study, default_calculus) = match args.study {
        Study::Fig7 => (MonteCarlo::fig7(), CalculusName::Edc),
        Study::Dissertation => (MonteCarlo::dissertation_random(), CalculusName::Fdc),
    };
    if let Some(maps) = args.maps {
        study.maps = maps;
    }
    if let Some(stations) = args.stations {
        study.stations = stations;
    }
    if !args.nearest.is_empty() {
        study.nearest = args.nearest.iter().map(|&n| Some(n)).collect();
    }
    if study.maps == 0 || study.stations == 0 {
        bail!("--maps and --stations must be positive");
    }
    if study.nearest.iter().flatten().any(|&n| n < 3) {
        bail!("--nearest values must be at least 3 (a triple)");
    }
    study.sensor = args.sensor.sensor(None)?;
    study.seed = args.seed;
    Ok((study, args.calculus.unwrap_or(default_calculus)))
}

fn montecarlo(args: MonteCarloArgs) -> Result<()> {
    let (study, calculus) = study(&args)?;
    let bar = progress(study.runs() as u64, "mapping runs");
    let start = Instant::now();
    let result = match calculus {
        CalculusName::Edc => study.run::<Edc>(&|| bar.inc(1)),
        CalculusName::Fdc => study.run::<Fdc>(&|| bar.inc(1)),
    };
    bar.finish_and_clear();
    let elapsed = start.elapsed().as_secs_f64();
    write_atomic(&args.out.join("montecarlo.csv"), result.to_csv().as_bytes())?;
    let summary = summary(&result, elapsed);
    write_atomic(&args.out.join("summary.txt"), summary.as_bytes())?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create directory {}", args.out.display()))?;
    let panels = montecarlo_panels(&result);
    for name in ["montecarlo.png", "montecarlo.svg"] {
        write_panels(&args.out.join(name), "image number", &panels)?;
    }
    print!("{summary}");
    println!(
        "wrote {}/montecarlo.csv, summary.txt, montecarlo.png, montecarlo.svg",
        args.out.display()
    );
    Ok(())
}

/// 000 Fig. 7 (a)–(d) for a calculus with a lune; 003 Fig. 1.6b otherwise.
fn montecarlo_panels(result: &MonteCarloResult) -> Vec<Panel> {
    let curves = |pick: &dyn Fn(&Series) -> &Vec<Statistic>, scale: f64, band: bool| {
        result
            .series
            .iter()
            .map(|s| Curve {
                label: s.label(),
                mean: pick(s).iter().map(|x| x.mean * scale).collect(),
                std: if band {
                    pick(s).iter().map(|x| x.std * scale).collect()
                } else {
                    Vec::new()
                },
                band: None,
            })
            .collect::<Vec<_>>()
    };
    let panel = |title: &str, y: &str, curves: Vec<Curve>| Panel {
        title: title.to_string(),
        y_label: y.to_string(),
        curves,
        x: Vec::new(),
    };
    let time = panel(
        "(d) time per update",
        "ms",
        curves(&|s| &s.seconds, 1e3, false),
    );
    if result.calculus == Edc::NAME {
        vec![
            panel(
                "(a) incorrect states removed",
                "% of incorrect states",
                curves(&|s| &s.removed_incorrect_pct, 1.0, true),
            ),
            panel(
                "(b) open states not adjacent to the true state",
                "% of open states",
                curves(&|s| &s.non_adjacent_open_pct, 1.0, true),
            ),
            panel(
                "(c) total RNG edge cost",
                "sum of w_ij",
                curves(&|s| &s.rng_cost, 1.0, true),
            ),
            time,
        ]
    } else {
        vec![
            panel(
                "(a) open states",
                "% of all states",
                curves(&|s| &s.open_pct, 1.0, true),
            ),
            panel(
                "(b) fully constrained triples",
                "% of triples",
                curves(&|s| &s.fully_constrained_pct, 1.0, true),
            ),
            panel(
                "(c) incorrect states removed",
                "% of incorrect states",
                curves(&|s| &s.removed_incorrect_pct, 1.0, true),
            ),
            time,
        ]
    }
}

/// The figures the papers comment on, per series.
fn summary(result: &MonteCarloResult, seconds: f64) -> String {
    let s = &result.study;
    let mut out = format!(
        "{} Monte Carlo: {} maps × {} landmarks × {} imaging points, {:.1} s wall\n",
        result.calculus, s.maps, s.landmarks, s.stations, seconds
    );
    let _ = writeln!(
        out,
        "{:>6} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>8} {:>8}",
        "series",
        "removed@1",
        "removed@10",
        "removed@end",
        "nonadj@end",
        "full@end",
        "open@end",
        "rngcost@end",
        "rng prec",
        "rng rec",
        "ms/upd",
        "unsound"
    );
    for series in &result.series {
        let last = series.seconds.len() - 1;
        let at10 = 9.min(last);
        let mean_ms =
            1e3 * series.seconds.iter().map(|x| x.mean).sum::<f64>() / series.seconds.len() as f64;
        // Adjacency and the RNG are EDC notions (lune, region adjacency).
        let edc_only = |v: f64, digits: usize| {
            if result.calculus == Edc::NAME {
                format!("{v:.digits$}")
            } else {
                "-".to_string()
            }
        };
        let _ = writeln!(
            out,
            "{:>6} {:>10.1} {:>10.1} {:>11.1} {:>10} {:>10.1} {:>10.1} {:>11} {:>9} {:>9} {:>8.2} {:>8}",
            series.label(),
            series.removed_incorrect_pct[0].mean,
            series.removed_incorrect_pct[at10].mean,
            series.removed_incorrect_pct[last].mean,
            edc_only(series.non_adjacent_open_pct[last].mean, 1),
            series.fully_constrained_pct[last].mean,
            series.open_pct[last].mean,
            edc_only(series.rng_cost[last].mean, 3),
            edc_only(series.rng_precision.mean, 3),
            edc_only(series.rng_recall.mean, 3),
            mean_ms,
            series.unsound_relations
        );
        if series.contradictions > 0 {
            let _ = writeln!(
                out,
                "       {} panoramas rejected as contradictions",
                series.contradictions
            );
        }
    }
    out
}

/// A simulated map with what made it.
struct Simulated<C: Calculus> {
    scenario: Scenario,
    sensor: Sensor,
    map: Hypergraph<C>,
}

fn single<C: Calculus>(args: &SingleArgs) -> Result<Simulated<C>> {
    if args.landmarks < 3 || args.stations == 0 {
        bail!("need at least 3 landmarks and 1 imaging point");
    }
    if args.landmarks > MAX_SIMULATED_LANDMARKS {
        bail!(
            "--landmarks {} is more than this simulation handles ({MAX_SIMULATED_LANDMARKS}): the map grows as n³",
            args.landmarks
        );
    }
    let scenario = Scenario::random(args.seed, args.landmarks, args.stations, 100.0);
    let sensor = args.sensor.sensor(args.nearest)?;
    let start = Instant::now();
    let (steps, map) = run::<C>(&scenario, &sensor, args.seed);
    let elapsed = start.elapsed().as_secs_f64();
    let mut csv = String::from(
        "image,visible,removed_incorrect_pct,non_adjacent_open_pct,fully_constrained_pct,open_pct,rng_cost,rng_precision,rng_recall,seconds,contradiction,unsound_relations\n",
    );
    for (i, s) in steps.iter().enumerate() {
        let _ = writeln!(
            csv,
            "{},{},{:.4},{:.4},{:.4},{:.4},{:.6},{:.4},{:.4},{:.6},{},{}",
            i + 1,
            s.visible,
            s.metrics.removed_incorrect_pct,
            s.metrics.non_adjacent_open_pct,
            s.metrics.fully_constrained_pct,
            s.metrics.open_pct,
            s.rng_cost.unwrap_or(0.0),
            s.rng.map_or(f64::NAN, |c| c.precision()),
            s.rng.map_or(f64::NAN, |c| c.recall()),
            s.seconds,
            s.contradiction,
            s.metrics.unsound_relations
        );
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create directory {}", args.out.display()))?;
    // The picture is the only output that can fail on the data, so it goes first.
    let mut rng_line = None;
    if let Some(rng) = estimate(&map) {
        let landmarks: Vec<(f64, f64)> = map
            .landmarks()
            .iter()
            .map(|&id| {
                let p = scenario.landmarks[id as usize];
                (p.x, p.y)
            })
            .collect();
        let labels: Vec<String> = map.landmarks().iter().map(u32::to_string).collect();
        let index = |id: u32| {
            map.landmarks()
                .iter()
                .position(|&x| x == id)
                .expect("map landmark")
        };
        let edges: Vec<(usize, usize, f64)> = rng
            .edges
            .iter()
            .map(|e| (index(e.a), index(e.b), e.cost))
            .collect();
        let mapped: Vec<Point> = landmarks.iter().map(|&(x, y)| Point::new(x, y)).collect();
        let true_edges = true_rng(&mapped);
        let stations: Vec<(f64, f64)> = scenario.stations.iter().map(|p| (p.x, p.y)).collect();
        write_rng(
            &args.out.join("rng.png"),
            &RngPicture {
                title: format!("RNG estimate after {} images", steps.len()),
                landmarks: &landmarks,
                labels: &labels,
                axes: Axes::Metres,
                edges: &edges,
                true_edges: &true_edges,
                pruned: &[],
                stations: &stations,
            },
        )?;
        write_atomic(
            &args.out.join("rng.json"),
            super::rng_json(&map, &rng).as_bytes(),
        )?;
        rng_line = Some(format!(
            "RNG: {} edges kept ({} certain), {} pruned; true RNG has {} edges",
            rng.edges.len(),
            rng.certain().count(),
            rng.pruned,
            true_edges.len()
        ));
    }
    write_atomic(&args.out.join("steps.csv"), csv.as_bytes())?;
    write_atomic(&args.out.join("map.json"), map.to_json().as_bytes())?;
    // Printed once every file is written: a reader that stops early ends the process.
    if let Some(line) = rng_line {
        println!("{line}");
    }
    let last = steps.last().expect("at least one station");
    println!(
        "{} map of {} landmarks after {} images in {:.2} s: {:.1}% incorrect states removed, {:.1}% triples fully constrained, {} unsound relations, {} contradictions",
        C::NAME,
        map.len(),
        steps.len(),
        elapsed,
        last.metrics.removed_incorrect_pct,
        last.metrics.fully_constrained_pct,
        last.metrics.unsound_relations,
        steps.iter().filter(|s| s.contradiction).count()
    );
    println!(
        "wrote {}/steps.csv, map.json{}",
        args.out.display(),
        if C::lune().is_some() {
            ", rng.json, rng.png"
        } else {
            ""
        }
    );
    Ok(Simulated {
        scenario,
        sensor,
        map,
    })
}

/// `--mode probabilistic`: 002's beliefs from the panoramas the map was built from, written
/// to beliefs.json, and both maps compared with the truth.
fn probabilistic_single(
    args: &SingleArgs,
    settings: &BeliefSettings,
    simulated: &Simulated<Edc>,
) -> Result<()> {
    let start = Instant::now();
    let beliefs = beliefs(&simulated.scenario, &simulated.sensor, args.seed, settings);
    let c = compare(&beliefs, &simulated.map, &simulated.scenario);
    let elapsed = start.elapsed().as_secs_f64();
    write_atomic(
        &args.out.join("beliefs.json"),
        beliefs.to_json(settings).as_bytes(),
    )?;
    let pct = |n: usize| 100.0 * n as f64 / c.triples.max(1) as f64;
    println!(
        "002 beliefs ({} estimator, ≤ {} views, motion noise {:.1}°) for {} triples seen from two or more points, in {elapsed:.2} s:",
        settings.estimator.variant.name(),
        settings.estimator.views,
        settings.motion_noise.to_degrees(),
        c.triples
    );
    println!(
        "  truth most likely {:.1}%, truth in the belief's support {:.1}%, median DMSE {:.3}, mean support {:.2} states",
        pct(c.truth_most_likely),
        pct(c.truth_in_support),
        c.median_dmse,
        c.mean_support_size
    );
    println!(
        "  deterministic map on the same triples: truth in the set {:.1}%, mean set {:.2} states; the belief's most likely state in the set {:.1}%",
        pct(c.truth_in_set),
        c.mean_set_size,
        pct(c.most_likely_in_set)
    );
    println!(
        "  beliefs conditioned on the map (its set, each state floored): truth most likely {:.1}%",
        pct(c.conditioned_truth_most_likely)
    );
    println!("wrote {}/beliefs.json", args.out.display());
    Ok(())
}

/// Greedy choice of imaging points for a small map (003 Fig. 1.5): each next point is the one
/// of a grid that leaves the fewest open states.
fn basic<C: Calculus>(seed: u64) -> Result<()> {
    let scenario = Scenario::random(seed, 4, 0, 100.0);
    let sensor = Sensor::exact(None);
    let candidates: Vec<Point> = (0..40)
        .flat_map(|i| {
            (0..40).map(move |j| Point::new(2.5 * i as f64 + 1.25, 2.5 * j as f64 + 1.25))
        })
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut map = Hypergraph::<C>::new();
    println!(
        "{} map of 4 landmarks {:?}",
        C::NAME,
        scenario
            .landmarks
            .iter()
            .map(|p| (p.x.round(), p.y.round()))
            .collect::<Vec<_>>()
    );
    for image in 1..=7 {
        let best = candidates
            .iter()
            .map(|&station| {
                let (ids, panorama) = sensor.observe(&scenario.landmarks, station, &mut rng);
                let mut trial = map.clone();
                let _ = trial.fuse(&trial.observations(&panorama, &Sighting::all(&ids)));
                (trial.open_states(), station, trial)
            })
            .min_by_key(|(open, _, _)| *open)
            .expect("candidates");
        map = best.2;
        let full = map.fully_constrained_triples();
        println!(
            "image {image} at ({:.1}, {:.1}): {} open states in {} triples, {} fully constrained",
            best.1.x,
            best.1.y,
            best.0,
            map.triple_count(),
            full
        );
        if full == map.triple_count() {
            println!(
                "fully constrained after {image} images (003 Fig. 1.6a: 7 hand-picked images)"
            );
            break;
        }
    }
    Ok(())
}

pub(super) fn progress(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} {msg} [{bar:40}] {pos}/{len} ({elapsed}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}
