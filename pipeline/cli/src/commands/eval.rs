//! `pipeline eval --run OUT --truth truth.json`: scores a run against the renderer's truth
//! (docs/RUN.md): eval.json, rng_truth.png and a printed report.

use super::rng_picture::{stage_rng_truth, EdgeCut};
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use qrm_atomic_file::OutputSet;
use qrm_core::edc::Edc;
use qrm_core::map::{Hypergraph, LandmarkId};
use qrm_core::neighborhood::estimate;
use qrm_core::probabilistic::map::BeliefMap;
use qrm_synth::dataset::{Truth, TRUTH_FORMAT, TRUTH_VERSION};
use qrm_synth::evaluation::{self, Detectable, Evaluation, RunFiles};
use qrm_vision::calib::Calibration;
use qrm_vision::detection::DetectorSettings;
use qrm_vision::run::{LandmarkRecord, StationRecord};
use qrm_vision::survey::{self, Survey};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct EvalArgs {
    /// Output directory of `pipeline run`.
    #[arg(long)]
    pub run: PathBuf,
    /// The dataset's truth.json.
    #[arg(long)]
    pub truth: PathBuf,
    /// The calibration the run used (default: calib.toml beside the truth file).
    #[arg(long)]
    pub calib: Option<PathBuf>,
    /// Where eval.json and rng_truth.png go (default: the run directory).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Draw every possible RNG edge in rng_truth.png, not only those of cost w ≤ 0.15.
    #[arg(long)]
    pub all_edges: bool,
}

pub fn run(args: EvalArgs) -> Result<()> {
    let out = args.out.clone().unwrap_or_else(|| args.run.clone());
    let calib_path = args
        .calib
        .clone()
        .unwrap_or_else(|| args.truth.with_file_name("calib.toml"));
    // The truth first: a missing one is named, not the calibration missing beside it.
    read_truth(&args.truth)?;
    let calib = Calibration::load(&calib_path)?;
    let cut = EdgeCut::new(args.all_edges);
    print_report(&score_run_files(&args.run, &args.truth, &calib, &out, cut)?);
    Ok(())
}

fn read<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text)
        .with_context(|| format!("{} is not a valid file of its kind", path.display()))
}

/// Reads and parses a truth file: `pipeline run` checks an explicit `--truth` before any
/// work, so that a bad one fails with nothing written. Its `format` and `version` are those of
/// datasets/README.md: another file of the same fields is not a truth file.
pub fn read_truth(path: &Path) -> Result<Truth> {
    let truth: Truth = read(path)?;
    if truth.format != TRUTH_FORMAT {
        bail!(
            "{}: \"format\" is {:?}, expected {TRUTH_FORMAT:?}: not a truth file",
            path.display(),
            truth.format
        );
    }
    if truth.version != TRUTH_VERSION {
        bail!(
            "{}: truth file version {}, this reader knows version {TRUTH_VERSION}",
            path.display(),
            truth.version
        );
    }
    Ok(truth)
}

/// Whether `truth` describes every image of `survey`, file by file (names and fingerprints:
/// `evaluation::describes`), checked before a run does any work.
pub fn check_survey(truth: &Truth, survey: &Survey) -> Result<()> {
    for station in &survey.stations {
        for path in std::iter::once(&station.primary).chain(&station.right) {
            let file = path.strip_prefix(&survey.directory).unwrap_or(path);
            let digest =
                survey::digest(path).with_context(|| format!("cannot read {}", path.display()))?;
            evaluation::describes(truth, &file.display().to_string(), Some(&digest))
                .map_err(|problem| anyhow!("{problem}"))?;
        }
    }
    Ok(())
}

/// Scores the run in `run_dir` against `truth_path`, writing `eval.json` and `rng_truth.png`
/// (the RNG estimate at the true rock positions, edges cut by `cut`) into `out`, together.
pub fn score_run_files(
    run_dir: &Path,
    truth_path: &Path,
    calib: &Calibration,
    out: &Path,
    cut: EdgeCut,
) -> Result<Evaluation> {
    let truth = read_truth(truth_path)?;
    let records: Vec<StationRecord> = read(&run_dir.join("stations.json"))?;
    let landmarks: Vec<LandmarkRecord> = read(&run_dir.join("landmarks.json"))?;
    let map_path = run_dir.join("map.json");
    let map_text = std::fs::read_to_string(&map_path)
        .with_context(|| format!("cannot read {}", map_path.display()))?;
    let map = Hypergraph::<Edc>::from_json(&map_text)
        .with_context(|| format!("{}", map_path.display()))?;
    let beliefs_path = run_dir.join("beliefs.json");
    let beliefs = match std::fs::read_to_string(&beliefs_path) {
        Ok(text) => Some(
            BeliefMap::from_json(&text).with_context(|| format!("{}", beliefs_path.display()))?,
        ),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", beliefs_path.display())),
    };
    if let Err(problem) = evaluation::check_files(&truth, &records, &landmarks) {
        bail!(
            "{} does not fit the run in {}: {problem}",
            truth_path.display(),
            run_dir.display()
        );
    }
    let settings = DetectorSettings::default();
    let eval = evaluation::score_run(
        &RunFiles {
            records: &records,
            landmarks: &landmarks,
            map: &map,
            beliefs: beliefs.as_ref(),
        },
        &truth,
        calib,
        Detectable::of(&settings),
    );
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create directory {}", out.display()))?;
    let mut outputs = OutputSet::new();
    let eval_path = out.join("eval.json");
    outputs
        .stage_bytes(
            &eval_path,
            (serde_json::to_string_pretty(&eval)? + "\n").as_bytes(),
        )
        .with_context(|| format!("cannot write {}", eval_path.display()))?;
    let rocks: BTreeMap<LandmarkId, [f64; 2]> = eval
        .landmark_rocks
        .iter()
        .filter(|(l, _)| map.landmarks().contains(l))
        .map(|(&l, &r)| (l, truth.rocks[r as usize].position))
        .collect();
    let stations: Vec<(f64, f64)> = records
        .iter()
        .filter_map(|r| {
            let image = truth
                .images
                .iter()
                .find(|i| Some(&i.file) == r.files.first())?;
            let p = truth.stations.get(image.station)?.position;
            Some((p[0], p[1]))
        })
        .collect();
    let rng = estimate(&map).unwrap_or_default();
    stage_rng_truth(
        &mut outputs,
        &out.join("rng_truth.png"),
        &rng,
        &rocks,
        &stations,
        cut,
    )?;
    outputs
        .commit()
        .with_context(|| format!("cannot move the scores into {}", out.display()))?;
    Ok(eval)
}

pub fn print_report(e: &Evaluation) {
    let f = &e.front_end;
    let d = &f.detection;
    println!("evaluation against truth:");
    println!(
        "  detection: precision {:.3} ({} of {}), recall {:.3} ({} of {} detectable) over {} images",
        d.precision, d.true_detections, d.detections, d.recall, d.detectable_found, d.detectable, d.images
    );
    for (name, b) in [
        ("all", &f.bearing),
        ("used", &f.bearing_used),
        ("fused", &f.bearing_fused),
        ("fused pieces", &f.bearing_pieces),
    ] {
        if b.count == 0 {
            println!("  bearing error ({name}): none");
            continue;
        }
        println!(
            "  bearing error ({name}): {} bearings, median {:.3}°, worst {:.3}°; inside its interval {:.1} % (worst error/interval {:.2})",
            b.count,
            b.median_error_deg,
            b.worst_error_deg,
            100.0 * b.within_interval,
            b.worst_error_ratio
        );
    }
    let r = &f.range;
    for (name, c) in [
        ("ground", &r.ground),
        ("stereo", &r.stereo),
        ("size", &r.size),
        ("fused", &r.fused),
    ] {
        println!(
            "  range cue {name:<6}: {} intervals, {:.1} % hold the truth, median width {:.0} % of range",
            c.count,
            100.0 * c.holds_truth,
            100.0 * c.median_relative_width
        );
    }
    println!(
        "  range order: {} of the {} pairs of detections matched to rocks asserted, {} wrong ({} asserted between sightings that reached the map, {} wrong); {} cue conflicts",
        r.asserted_pairs, r.pairs, r.wrong_pairs, r.fused_asserted_pairs, r.fused_wrong_pairs, r.conflicts
    );
    println!(
        "  of all {} asserted pairs (matched to rocks or not), separated by ground alone {}, stereo alone {}, size alone {}, only by the fusion {}",
        r.asserted_all,
        r.separated_by_ground, r.separated_by_stereo, r.separated_by_size, r.separated_only_fused
    );
    let a = &e.association;
    println!(
        "  association: accuracy {:.3} ({} of {} sightings), purity {:.3} (false detections aside; {:.3} by nearest centroid alone, {} sightings of blobs over several rocks counted for the landmark's rock their measurement holds), {} landmarks, {} rocks duplicated, {} landmarks mixed, {} sightings of false detections",
        a.accuracy, a.correct_sightings, a.sightings, a.purity, a.purity_nearest_centroid, a.credited_by_measurement, a.landmarks, a.duplicated_rocks, a.mixed_landmarks, a.unmatched_sightings
    );
    println!(
        "  reached the map: {:.1} % of detections matched to rocks; {} of the {} rocks detected at 3 or more stations have a landmark ({:.1} %)",
        100.0 * a.fused_fraction, a.rocks_seen_thrice_mapped, a.rocks_seen_thrice, 100.0 * a.mapped_fraction
    );
    for (name, m) in [
        ("run", &e.map.run),
        ("exact", &e.map.exact),
        ("true bearings", &e.map.true_bearings),
    ] {
        println!(
            "  map ({name}): {} landmarks, {} triples, {:.1} % open ({:.1} % among landmarks of one rock each), {:.1} % of incorrect states removed ({:.1} % among landmarks of one rock each), {:.1} % fully constrained, {} unsound relations",
            m.landmarks, m.triples, m.open_pct, m.open_pct_defined, m.removed_incorrect_pct, m.removed_incorrect_pct_defined, m.fully_constrained_pct, m.unsound_relations
        );
        if !m.unsound_landmarks.is_empty() {
            let worst: Vec<String> = m
                .unsound_landmarks
                .iter()
                .take(5)
                .map(|(l, n)| format!("{l} ({n})"))
                .collect();
            println!(
                "    landmarks in most unsound relations: {}",
                worst.join(", ")
            );
        }
    }
    if let Some(c) = &e.beliefs {
        let pct = |n: usize| 100.0 * n as f64 / c.triples.max(1) as f64;
        println!(
            "  002 beliefs ({} triples with a belief and a truth): truth most likely {:.1} %, in the belief's support {:.1} %, median DMSE {:.3}; the map's set holds the truth {:.1} % (mean {:.2} states); beliefs conditioned on the map put the truth first {:.1} %",
            c.triples,
            pct(c.truth_most_likely),
            pct(c.truth_in_support),
            c.median_dmse,
            pct(c.truth_in_set),
            c.mean_set_size,
            pct(c.conditioned_truth_most_likely)
        );
    }
    for (name, rng) in [
        ("run", &e.map.rng),
        ("exact", &e.map.rng_exact),
        ("true bearings", &e.map.rng_true_bearings),
    ] {
        if let Some(rng) = rng {
            println!(
                "  RNG ({name}): precision {:.2}, recall {:.2}, {} true edges pruned, over the {} one-rock landmarks",
                rng.precision, rng.recall, rng.true_edges_pruned, rng.landmarks
            );
            let cuts: Vec<String> = rng
                .by_cost
                .iter()
                .map(|c| {
                    format!(
                        "w ≤ {:.2}: {} edges, {:.2}/{:.2}",
                        c.max_cost, c.edges, c.precision, c.recall
                    )
                })
                .collect();
            println!("    by cost (precision/recall): {}", cuts.join("; "));
        }
    }
}
