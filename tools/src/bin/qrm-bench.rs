//! Benchmarks of the calculus core (figures in docs/BENCHMARKS.md):
//! - median time of one 2-unknown feasibility decision (all 3 × 20 × 20 EDC unary problems),
//! - median time of one 4-unknown decision (a deterministic sample of composition triples),
//! - wall time to regenerate each table;
//! - with `--closure`: path-consistency closure of complete random maps (000 §VI-B);
//! - with `--rng`: the RNG estimate (000 Algorithm 2) of maps of N landmarks, as a run makes
//!   after every station;
//! - with `--layout`: the graph layout of the RNG drawing of N landmarks, as the MCAP
//!   recording makes at every station that changes the map;
//! - with `--render`: synthetic panoramas (issue 4), one stereo pair and a 50-station set;
//! - with `--triple-calls K`: one triple measured K times, the work of a Python `qrm.measure`.

use clap::Parser;
use qrm_core::calculus::{Calculus, RelationSet};
use qrm_core::edc::Edc;
use qrm_core::edc::{fixed_point, free_point, region_constraints};
use qrm_core::fdc::Fdc;
use qrm_core::feasibility::{BranchAndBound, Outcome, Quadratic};
use qrm_core::geometry::Point;
use qrm_core::map::{Hypergraph, Observation};
use qrm_core::measurement::{Bearing, RangeOrder, StationView};
use qrm_tools::{edc_composition, edc_unary, fdc_composition, fdc_unary};
use rand::{Rng, SeedableRng};
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(about = "Time feasibility decisions and table generation")]
struct Args {
    /// Skip regenerating the full EDC composition table (the slow part).
    #[arg(long)]
    quick: bool,
    /// Only time the EDC composition cells `R1 R2` (repeatable), with their search counts.
    #[arg(long, num_args = 2, value_names = ["AB_C", "BC_D"], value_parser = clap::value_parser!(u8).range(1..=20))]
    cell: Vec<u8>,
    /// Time the map closure instead: complete random networks of these sizes (repeatable).
    #[arg(long, num_args = 1.., value_name = "N")]
    closure: Vec<usize>,
    /// Random extra states added to the true state of every relation (with `--closure`).
    #[arg(long, default_value_t = 3)]
    extra: usize,
    /// Time the measurement of a random panorama showing this many landmarks (repeatable):
    /// every triple, every region open, total range order.
    #[arg(long, num_args = 1.., value_name = "N")]
    measure: Vec<usize>,
    /// Time this many measurements of one triple (bearings 0°, 40°, 100°, order A<B<C, EDC),
    /// one after the other on one thread, each from the bearings to the six relations: the
    /// work of one Python `qrm.measure` call (docs/PYTHON.md compares the two).
    #[arg(long, value_name = "K")]
    triple_calls: Option<u32>,
    /// Bearing uncertainty (± degrees) for `--measure` and `--triple-calls`.
    #[arg(long, default_value_t = 0.0)]
    uncertainty: f64,
    /// Fuse each closure network this many times into a fresh map; prints min and median.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    repeat: u32,
    /// Time the RNG estimate (Algorithm 2) of a map of N landmarks that knows nothing (every
    /// pair an edge, every third landmark examined: the slowest case) (repeatable).
    #[arg(long, num_args = 1.., value_name = "N")]
    rng: Vec<usize>,
    /// Time the spring layout of an RNG drawing of N landmarks (each joined to its next 3 by
    /// index, about the degree of a long drive's estimate) (repeatable).
    #[arg(long, num_args = 1.., value_name = "N")]
    layout: Vec<usize>,
    /// Time the synthetic renderer instead (30 rocks, `calib/default.toml`).
    #[arg(long)]
    render: bool,
    /// With `--render`: also save the left image of the first pair, shrunk 4×, as this PNG.
    #[arg(long, value_name = "PNG")]
    preview: Option<std::path::PathBuf>,
    /// Time the rock detector on a dataset directory (calib.toml, PNGs, optional truth.json);
    /// with truth, also prints precision, recall, bearing and contact errors.
    #[arg(long, value_name = "DIR")]
    detect: Option<std::path::PathBuf>,
}

/// Decodes every image of a dataset, detects rocks in each (single thread) as `pipeline run`
/// does (a left panorama with its right partner, for parallax), and prints the decode and
/// detection time per image and, with `truth.json`, the detector's score.
fn bench_detect(dir: &std::path::Path) -> anyhow::Result<()> {
    use qrm_synth::evaluation::{median_and_max, Detectable, DetectedBox, Score};
    use qrm_vision::detection::{detect, detect_right, DetectorSettings};
    let calib = qrm_vision::calib::Calibration::load(&dir.join("calib.toml"))?;
    let truth: Option<qrm_synth::dataset::Truth> =
        match std::fs::read_to_string(dir.join("truth.json")) {
            Ok(text) => Some(serde_json::from_str(&text)?),
            Err(_) => None,
        };
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "png"))
        .collect();
    files.sort();
    let settings = DetectorSettings::default();
    let size = (calib.image.width, calib.image.height);
    let read = |p: &std::path::Path| qrm_vision::survey::read_image(p, size);
    let (mut decode, mut choosing, mut detecting) = (0.0, 0.0, Vec::new());
    let mut score = Score::default();
    let mut ambiguous = 0;
    for file in &files {
        let start = Instant::now();
        let image = read(file)?;
        let name = file
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        // As in the run: a left image with its right partner, a right one with its left.
        let partner = |from: &str, to: &str| {
            name.strip_suffix(from)
                .map(|stem| file.with_file_name(format!("{stem}{to}")))
                .filter(|p| p.exists())
        };
        let (right, left) = (
            partner("_left.png", "_right.png"),
            partner("_right.png", "_left.png"),
        );
        let open = |p: Option<std::path::PathBuf>| p.map(|p| read(&p));
        let (right, left) = (open(right).transpose()?, open(left).transpose()?);
        decode += start.elapsed().as_secs_f64();
        // The mode as the run resolves it (`run::front_end::detect_panoramas`): from the left
        // image of a stereo pair, which may be detected by luminance for its chroma noise.
        let start = Instant::now();
        let primary = left.as_ref().unwrap_or(&image);
        let channels = settings.channels_of(primary, right.is_some() || left.is_some(), false);
        choosing += start.elapsed().as_secs_f64();
        let settings = &DetectorSettings {
            channels,
            ..settings.clone()
        };
        let start = Instant::now();
        let found = match &left {
            Some(left) => detect_right(&image, Some(left), &calib, settings),
            None => detect(&image, right.as_ref(), &calib, settings),
        };
        detecting.push(start.elapsed().as_secs_f64());
        if let Some(t) = truth
            .as_ref()
            .and_then(|t| t.images.iter().find(|i| i.file == name))
        {
            let boxes: Vec<DetectedBox> = found.iter().map(DetectedBox::from).collect();
            score.add(&boxes, &t.rocks, &calib, Detectable::of(settings));
            ambiguous += found.iter().filter(|d| d.ambiguous).count();
        }
    }
    let n = files.len().max(1) as f64;
    detecting.sort_by(f64::total_cmp);
    println!(
        "detect: {} images {}x{}: decode {:.1} ms/image (a left image's right partner included), mode choice {:.1} ms, detect mean {:.1} ms, median {:.1} ms, max {:.1} ms",
        files.len(),
        calib.image.width,
        calib.image.height,
        1e3 * decode / n,
        1e3 * choosing / n,
        1e3 * detecting.iter().sum::<f64>() / n,
        1e3 * detecting.get(detecting.len() / 2).copied().unwrap_or(0.0),
        1e3 * detecting.last().copied().unwrap_or(0.0),
    );
    if truth.is_some() {
        let (bearing_median, bearing_max) = median_and_max(&score.bearing_errors);
        let (contact_median, contact_max) = median_and_max(&score.contact_errors);
        println!(
            "detect (matched as `pipeline eval` does): {} detectable, {} found, {} false, {} splits, {} merged, {ambiguous} flagged ambiguous: precision {:.3}, recall {:.3}",
            score.detectable, score.found, score.false_alarms, score.splits, score.merged,
            score.precision(), score.recall()
        );
        println!(
            "detect: bearing error median {bearing_median:.2} px, max {bearing_max:.2} px; contact row error median {contact_median:.2} px, max {contact_max:.2} px"
        );
        let (_, worst_ratio) = median_and_max(&score.bearing_ratios);
        println!(
            "detect: bearing error over width max {worst_ratio:.2}; {} found rocks outside 1 px + 0.3 × width",
            score.outside_bound
        );
    }
    Ok(())
}

/// Renders stereo pairs of 30 random rocks in a 20 m square with the default calibration:
/// one pair from the centre (minimum and median of five), then 50 stations around a loop;
/// prints wall times and optionally saves a preview of the first left image.
fn bench_render(preview: Option<&std::path::Path>) {
    use qrm_synth::{render, Eye, Pose, World};
    let calib = qrm_synth::default_calibration();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    let placements: Vec<(Point, f64)> = (0..30)
        .map(|_| {
            (
                Point::new(rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0)),
                rng.random_range(0.1..0.45),
            )
        })
        .collect();
    let world = World::generate(4, &placements);
    let centre = Pose {
        position: Point::new(0.3, -0.4),
        heading: 0.0,
    };
    let mut times = Vec::new();
    for i in 0..5 {
        let start = Instant::now();
        let left = render(&world, &calib, centre, Eye::Left);
        let right = render(&world, &calib, centre, Eye::Right);
        times.push(start.elapsed().as_secs_f64());
        if i == 0 {
            if let Some(path) = preview {
                left.downscale(4)
                    .save(path, qrm_synth::Encoding::default())
                    .expect("preview written");
            }
            std::hint::black_box(right);
        }
    }
    times.sort_by(f64::total_cmp);
    println!(
        "render: one {}x{} stereo pair, 30 rocks: min {:.3} s, median {:.3} s",
        calib.image.width, calib.image.height, times[0], times[2]
    );
    let start = Instant::now();
    for k in 0..50 {
        let angle = std::f64::consts::TAU * f64::from(k) / 50.0;
        let pose = Pose {
            position: Point::new(6.0 * angle.cos(), 6.0 * angle.sin()),
            heading: angle + std::f64::consts::FRAC_PI_2,
        };
        std::hint::black_box(render(&world, &calib, pose, Eye::Left));
        std::hint::black_box(render(&world, &calib, pose, Eye::Right));
    }
    println!(
        "render: 50 stations (50 stereo pairs), 30 rocks: {:.2} s",
        start.elapsed().as_secs_f64()
    );
}

/// Measures one random panorama of `n` landmarks (uniform in a square around the camera,
/// bearings perturbed within `±uncertainty`), five times; prints the minimum and median wall
/// time and the mean number of open regions per relation.
fn bench_measure(n: usize, uncertainty_deg: f64) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(n as u64);
    let delta = uncertainty_deg.to_radians();
    let points: Vec<Point> = (0..n)
        .map(|_| Point::new(rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0)))
        .collect();
    let bearings = points
        .iter()
        .map(|p| Bearing {
            angle: p.y.atan2(p.x)
                + if delta > 0.0 {
                    rng.random_range(-delta..delta)
                } else {
                    0.0
                },
            uncertainty: delta,
        })
        .collect();
    let mut nearest_first: Vec<usize> = (0..n).collect();
    nearest_first.sort_by(|&i, &j| {
        points[i]
            .distance(Point::new(0.0, 0.0))
            .total_cmp(&points[j].distance(Point::new(0.0, 0.0)))
    });
    let order = RangeOrder::total(&nearest_first).expect("a chain is acyclic");
    let panorama = StationView::new(bearings, order).expect("valid panorama");
    let mut times = Vec::new();
    let mut open = 0usize;
    let mut relations = 0usize;
    for _ in 0..5 {
        let start = Instant::now();
        let measured = panorama.measure_all::<Edc, _>(|_| [Edc::universe(); 3]);
        times.push(start.elapsed().as_secs_f64());
        open = measured
            .iter()
            .flat_map(|m| m.states)
            .map(|s| s.len())
            .sum();
        relations = measured.len() * 3;
    }
    times.sort_by(f64::total_cmp);
    println!(
        "measure n={n} ±{uncertainty_deg}°: {} triples, min {:.1} ms, median {:.1} ms, {:.2} open regions per relation",
        relations / 3,
        times[0] * 1e3,
        times[2] * 1e3,
        open as f64 / relations.max(1) as f64
    );
}

/// Times `calls` measurements of the triple (0°, 40°, 100°), order A<B<C, ±`uncertainty_deg`.
fn bench_triple_calls(calls: u32, uncertainty_deg: f64) {
    let delta = uncertainty_deg.to_radians();
    let order = RangeOrder::total(&[0, 1, 2]).expect("a chain is acyclic");
    let start = Instant::now();
    let mut open = 0usize;
    for _ in 0..calls {
        let bearings = [0.0f64, 40.0, 100.0]
            .iter()
            .map(|d| Bearing {
                angle: d.to_radians(),
                uncertainty: delta,
            })
            .collect();
        let view = StationView::new(bearings, order.clone()).expect("valid panorama");
        let sets = view.measure_triple::<Edc>([0, 1, 2], [Edc::universe(); 3]);
        let inverses = sets.map(|s| Edc::tables().inverse(s));
        open += sets.iter().chain(&inverses).map(|s| s.len()).sum::<usize>();
    }
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "triple ±{uncertainty_deg}°: {calls} measurements, {:.2} µs each ({:.2} open regions per relation)",
        seconds / f64::from(calls) * 1e6,
        open as f64 / (6.0 * f64::from(calls))
    );
}

/// Fuses a complete random network of `n` landmarks in one update: every relation of every
/// triple is its true state plus `extra` random other states. Prints wall time, compositions,
/// rounds, map heap bytes and process peak RSS; with `repeat > 1` the minimum and median wall
/// time over that many fuses (the machine may be shared).
fn bench_closure<C: Calculus>(n: usize, extra: usize, repeat: u32) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(n as u64);
    let points: Vec<Point> = (0..n)
        .map(|_| {
            Point::new(
                rng.random_range(-100.0..100.0),
                rng.random_range(-100.0..100.0),
            )
        })
        .collect();
    let universe: Vec<u8> = C::universe().iter().collect();
    let mut observations = Vec::new();
    for k in 2..n {
        for j in 1..k {
            for i in 0..j {
                for [a, b, c] in [[i, j, k], [j, k, i], [k, i, j]] {
                    let Some(truth) = C::classify(points[a], points[b], points[c]) else {
                        continue;
                    };
                    let mut states = RelationSet::single(truth);
                    while states.len() < (extra + 1).min(universe.len()) {
                        states = states.with(universe[rng.random_range(0..universe.len())]);
                    }
                    observations.push(Observation::new(a as u32, b as u32, c as u32, states));
                }
            }
        }
    }
    let mut times = Vec::new();
    let (map, report) = loop {
        let mut map = Hypergraph::<C>::new();
        let start = Instant::now();
        let report = map.fuse(&observations).expect("true states are consistent");
        times.push(start.elapsed().as_secs_f64() * 1e3);
        if times.len() == repeat as usize {
            break (map, report);
        }
    };
    times.sort_by(f64::total_cmp);
    let time = if times.len() == 1 {
        format!("{:>9.3} ms", times[0])
    } else {
        format!(
            "{:>9.3} ms min, {:>9.3} ms median of {}",
            times[0],
            times[times.len() / 2],
            times.len()
        )
    };
    let mean: f64 = map
        .triples()
        .map(|(_, _, _, r)| r.iter().map(|s| s.len()).sum::<usize>() as f64)
        .sum::<f64>()
        / (3 * map.triple_count()).max(1) as f64;
    println!(
        "{} n={n:>3}: {time}, {:>11} compositions, {:>2} rounds, {:>9} relations tightened, mean |relation| {mean:.2}, map {:>6.1} MB, peak RSS {:>6.1} MB",
        C::NAME,
        report.compositions,
        report.rounds,
        report.relations_tightened,
        map.heap_bytes() as f64 / 1e6,
        peak_rss_kib() as f64 / 1024.0,
    );
}

/// `VmHWM` of this process in KiB (0 where /proc is unavailable).
fn peak_rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        })
        .unwrap_or(0)
}

/// Median and 90th percentile in microseconds, with the outcome counts.
fn time_decisions(problems: &[(Vec<f64>, Vec<f64>, Vec<Quadratic>)]) -> (f64, f64, [usize; 3]) {
    let engine = BranchAndBound::default();
    let mut times = Vec::with_capacity(problems.len());
    let mut counts = [0usize; 3];
    for (lo, hi, cs) in problems {
        let start = Instant::now();
        let outcome = engine.decide(lo, hi, cs);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        counts[match outcome {
            Outcome::Feasible(_) => 0,
            Outcome::Infeasible => 1,
            Outcome::Undecided => 2,
        }] += 1;
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], times[times.len() * 9 / 10], counts)
}

/// Times `neighborhood::estimate` on a map of `n` unrelated landmarks (the median of 5).
fn bench_rng(n: usize) {
    let mut map = Hypergraph::<Edc>::new();
    map.add_landmarks(&(0..n as u32).collect::<Vec<_>>());
    let mut times: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            let rng = qrm_core::neighborhood::estimate(&map).expect("EDC has a lune");
            assert_eq!(rng.edges.len(), n * (n - 1) / 2);
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    println!(
        "RNG estimate, {n} landmarks: median {:.1} ms ({} pairs × {} third landmarks)",
        times[2],
        n * (n - 1) / 2,
        n - 2
    );
}

/// Times `qrm_plot::spring_layout` of `n` landmarks (the median of 3).
fn bench_layout(n: usize) {
    let edges: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| (1..=3).map(move |d| (i, (i + d) % n)))
        .filter(|(i, j)| i != j)
        .collect();
    let mut times: Vec<f64> = (0..3)
        .map(|_| {
            let start = Instant::now();
            let layout = qrm_plot::spring_layout(n, &edges);
            assert_eq!(layout.len(), n);
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    println!(
        "spring layout, {n} landmarks, {} edges: median {:.1} ms",
        edges.len(),
        times[1]
    );
}

fn main() {
    let args = Args::parse();
    if !args.layout.is_empty() {
        for &n in &args.layout {
            bench_layout(n);
        }
        return;
    }
    if let Some(dir) = &args.detect {
        if let Err(e) = bench_detect(dir) {
            eprintln!("qrm-bench: {e:#}");
            std::process::exit(1);
        }
        return;
    }
    if args.render {
        bench_render(args.preview.as_deref());
        return;
    }
    if let Some(calls) = args.triple_calls {
        bench_triple_calls(calls, args.uncertainty);
        return;
    }
    if !args.measure.is_empty() {
        for &n in &args.measure {
            bench_measure(n, args.uncertainty);
        }
        return;
    }
    if !args.rng.is_empty() {
        for &n in &args.rng {
            bench_rng(n);
        }
        return;
    }
    if !args.closure.is_empty() {
        for &n in &args.closure {
            bench_closure::<Edc>(n, args.extra, args.repeat);
            bench_closure::<Fdc>(n, args.extra, args.repeat);
        }
        return;
    }
    if !args.cell.is_empty() {
        for pair in args.cell.chunks(2) {
            let start = Instant::now();
            let (entries, report) = qrm_tools::edc_composition_cell(
                pair[0],
                pair[1],
                &qrm_core::feasibility::Settings::default(),
            );
            println!(
                "cell ({},{}): {} possible, {} by sampling, {} by search, {} impossible, {} undecided, {} boxes, {:.2} s",
                pair[0], pair[1], entries.len(), report.sampled, report.searched_feasible,
                report.proved_infeasible, report.undecided, report.boxes, start.elapsed().as_secs_f64()
            );
        }
        return;
    }

    let n = 2;
    let (a, b, c) = (
        fixed_point(n, 0.0, 0.0),
        fixed_point(n, 0.0, 1.0),
        free_point(n, 0, 1),
    );
    let mut two = Vec::new();
    for r in 1..=20u8 {
        for s in 1..=20u8 {
            for (p, q, t) in [(&b, &c, &a), (&c, &a, &b), (&b, &a, &c)] {
                let mut cs = region_constraints(&a, &b, &c, r);
                cs.extend(region_constraints(p, q, t, s));
                two.push((vec![-8.0; 2], vec![8.0; 2], cs));
            }
        }
    }
    let (median, p90, counts) = time_decisions(&two);
    println!(
        "2 unknowns: {} decisions (EDC unary), median {median:.1} µs, p90 {p90:.1} µs; feasible {} infeasible {} undecided {}",
        two.len(), counts[0], counts[1], counts[2]
    );

    let n = 4;
    let (a, b, c, d) = (
        fixed_point(n, 0.0, 0.0),
        fixed_point(n, 0.0, 1.0),
        free_point(n, 0, 1),
        free_point(n, 2, 3),
    );
    let mut four = Vec::new();
    for k in 0..300u32 {
        let (r1, r2, r3) = (
            (k * 7 % 20 + 1) as u8,
            (k * 13 % 20 + 1) as u8,
            (k * 3 % 20 + 1) as u8,
        );
        let mut cs = region_constraints(&a, &b, &c, r1);
        cs.extend(region_constraints(&b, &c, &d, r2));
        cs.extend(region_constraints(&a, &b, &d, r3));
        four.push((vec![-8.0; 4], vec![8.0; 4], cs));
    }
    let (median, p90, counts) = time_decisions(&four);
    println!(
        "4 unknowns: {} decisions (EDC composition triples), median {median:.1} µs, p90 {p90:.1} µs; feasible {} infeasible {} undecided {}",
        four.len(), counts[0], counts[1], counts[2]
    );

    let settings = qrm_core::feasibility::Settings::default();
    let start = Instant::now();
    let (_, undecided) = edc_unary(&settings);
    println!(
        "EDC unary table: {:.2} s, {undecided} undecided",
        start.elapsed().as_secs_f64()
    );
    let start = Instant::now();
    fdc_unary();
    println!("FDC unary table: {:.2} s", start.elapsed().as_secs_f64());
    let start = Instant::now();
    let file = fdc_composition();
    println!(
        "FDC composition table: {:.2} s, {} entries",
        start.elapsed().as_secs_f64(),
        file.entries.len()
    );
    if !args.quick {
        let start = Instant::now();
        let (file, report) = edc_composition(&settings, || {});
        println!(
            "EDC composition table: {:.1} s on {} threads, {} entries, {} undecided",
            start.elapsed().as_secs_f64(),
            rayon::current_num_threads(),
            file.entries.len(),
            report.undecided
        );
    }
}
