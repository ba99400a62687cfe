//! `pipeline run --images DIR`: panoramas in, qualitative map and RNG out (docs/RUN.md).

use super::pictures::{stage_pictures, PanoramaSize, RunImages};
use super::rng_json;
use super::rng_picture::{stage_rng_png, EdgeCut, DEFAULT_MAX_COST};
use super::simulate::{EstimatorArgs, Mode};
use crate::recording::{McapRecorder, Recorder, RngDrawing};
use anyhow::{bail, Context, Result};
use clap::Args;
use image::RgbImage;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use qrm_atomic_file::OutputSet;
use qrm_core::edc::Edc;
use qrm_core::map::Hypergraph;
use qrm_core::neighborhood::RngEstimate;
use qrm_plot::{spring_layout, write_panels, Curve, Panel};
use qrm_synth::evaluation::Evaluation;
use qrm_vision::calib::Calibration;
use qrm_vision::detection::Channels;
use qrm_vision::run::beliefs::{bearing_sd, run_beliefs};
use qrm_vision::run::{
    traverse_survey, BeliefsSummary, Mapper, Progress, RunError, RunSettings, RunSummary, Stage,
    StationRecord,
};
use qrm_vision::survey::{read_image, Survey};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct RunArgs {
    /// Directory of panoramas: NAME_left/NAME_right pairs (stereo) or single images (mono).
    #[arg(long)]
    pub images: PathBuf,
    /// Camera calibration (default: calib.toml in the image directory).
    #[arg(long)]
    pub calib: Option<PathBuf>,
    /// Output directory (created if missing).
    #[arg(long, default_value = "qrm-run")]
    pub out: PathBuf,
    /// Score the run against this ground truth (default: truth.json in the image directory,
    /// if present).
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Do not score against truth.json even if the image directory has one.
    #[arg(long)]
    pub no_eval: bool,
    /// Also write OUT/run.rrd for the rerun viewer (needs a build with `--features rerun`).
    #[arg(long)]
    pub rrd: bool,
    /// What tells rocks from the ground: `luminance` uses brightness and stereo height only
    /// (grayscale cameras, and colour that cannot be trusted: JPEG, strong sensor noise);
    /// `auto` picks it for grayscale panoramas, and for stereo pairs that are JPEG or whose
    /// chroma noise is over a third of the colour test's threshold, colour otherwise.
    #[arg(long, value_enum, default_value_t = ChannelsArg::Auto)]
    pub channels: ChannelsArg,
    /// Annotated panoramas in OUT/panoramas/: `reduced` (scaled by a power of two to 1025-2048
    /// pixels wide), `full` (their own size) or `none`. The landmark contact sheet
    /// (OUT/landmarks.png) is written in every case.
    #[arg(long, value_enum, default_value_t = PanoramaSize::Reduced)]
    pub panoramas: PanoramaSize,
    /// Draw every possible RNG edge in rng.png (and rng_truth.png), not only those of cost
    /// w ≤ 0.15 (docs/RUN.md, "Pictures").
    #[arg(long)]
    pub all_edges: bool,
    /// No progress bars and no warning lines while running: the warnings are counted by kind
    /// at the end (each station's are in stations.json).
    #[arg(long)]
    pub quiet: bool,
    /// `probabilistic`: also 002's beliefs (Mor & Indelman) over the 20 EDC states of every
    /// triple fused together at two or more stations, in beliefs.json beside map.json, the
    /// motion between two stations taken from their stereo placements (docs/PROBABILISTIC.md).
    /// The map of sets is the same in both modes.
    #[arg(long, value_enum, default_value = "deterministic")]
    pub mode: Mode,
    #[command(flatten)]
    pub beliefs: EstimatorArgs,
}

/// `--channels` (`qrm_vision::detection::Channels`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ChannelsArg {
    Auto,
    Colour,
    Luminance,
}

impl From<ChannelsArg> for Channels {
    fn from(c: ChannelsArg) -> Channels {
        match c {
            ChannelsArg::Auto => Channels::Auto,
            ChannelsArg::Colour => Channels::Colour,
            ChannelsArg::Luminance => Channels::Luminance,
        }
    }
}

/// The seed of 002's particles in `--mode probabilistic`: a run's beliefs are reproducible.
const BELIEF_SEED: u64 = 1;

/// The recorders of a run, and the RNG drawing of the map's latest revision (see
/// [`record_station`]).
type Recording = (Vec<Box<dyn Recorder>>, Option<(u64, RngDrawing)>);

/// The recorders of the run: run.mcap always, run.rrd on request.
fn recorders(args: &RunArgs) -> Result<Vec<Box<dyn Recorder>>> {
    let mcap: Box<dyn Recorder> = Box::new(McapRecorder::create(args.out.join("run.mcap"))?);
    #[cfg(feature = "rerun")]
    if args.rrd {
        let rrd = crate::recording::RerunRecorder::create(args.out.join("run.rrd"))?;
        return Ok(vec![mcap, Box::new(rrd)]);
    }
    Ok(vec![mcap])
}

/// The map's RNG estimate `rng` over a graph layout, for the recorders and rng.png.
fn rng_drawing(map: &Hypergraph<Edc>, rng: &RngEstimate) -> RngDrawing {
    let ids = map.landmarks();
    // Every edge's ends by position: a search of the landmark list per edge is O(edges ×
    // landmarks), and a long drive's estimate has 10⁵ edges among hundreds of landmarks.
    let position: std::collections::HashMap<u32, usize> =
        ids.iter().enumerate().map(|(i, &l)| (l, i)).collect();
    let index = |id: u32| position[&id];
    let layout = spring_layout(
        ids.len(),
        &rng.edges
            .iter()
            .map(|e| (index(e.a), index(e.b)))
            .collect::<Vec<_>>(),
    );
    RngDrawing {
        landmarks: ids
            .iter()
            .zip(layout)
            .map(|(&id, (x, y))| (id, [x, y]))
            .collect(),
        edges: rng.edges.iter().map(|e| (e.a, e.b, e.cost)).collect(),
    }
}

/// A caller's progress function (the Python package's): `(stage, done, total)` with stage
/// `detect` or `map`, called as each stage begins and as each station is done, in order of
/// `done`, from the thread that did the station.
pub type Listener = dyn Fn(&str, usize, usize) + Send + Sync;

/// Progress bars on the terminal, one per stage (detection and mapping run at once, so both
/// may show), or a caller's [`Listener`] instead; warnings printed above the bars and kept for
/// the tally at the end. Quiet: neither bars nor warning lines.
#[derive(Default)]
struct Bars {
    terminal: MultiProgress,
    bars: Mutex<Vec<(Stage, ProgressBar)>>,
    warnings: Mutex<Vec<String>>,
    quiet: bool,
    listener: Option<Box<Listener>>,
    /// The listener's count of each stage begun: (stage, done, total).
    positions: Mutex<Vec<(Stage, usize, usize)>>,
}

/// A stage's name for the bars and the listener.
fn stage_name(stage: Stage) -> &'static str {
    match stage {
        Stage::Detect => "detect",
        Stage::Map => "map",
    }
}

impl Bars {
    fn new(quiet: bool, listener: Option<Box<Listener>>) -> Bars {
        Bars {
            quiet: quiet || listener.is_some(),
            listener,
            ..Bars::default()
        }
    }

    /// The warnings by kind (digits masked: one kind for every station and count), most
    /// frequent first, each with its first message.
    fn tally(&self) -> Vec<(usize, String)> {
        let warnings = self.warnings.lock().expect("no panics hold it");
        let mut kinds: Vec<(String, usize, String)> = Vec::new();
        for message in warnings.iter() {
            let kind: String = message
                .chars()
                .map(|c| if c.is_ascii_digit() { '#' } else { c })
                .collect();
            match kinds.iter_mut().find(|(k, _, _)| *k == kind) {
                Some((_, count, _)) => *count += 1,
                None => kinds.push((kind, 1, message.clone())),
            }
        }
        kinds.sort_by_key(|k| std::cmp::Reverse(k.1));
        kinds
            .into_iter()
            .map(|(_, n, example)| (n, example))
            .collect()
    }
}

impl Progress for Bars {
    fn begin(&self, stage: Stage, stations: usize) {
        let what = stage_name(stage);
        if let Some(listener) = &self.listener {
            let mut positions = self.positions.lock().expect("no panics hold it");
            positions.push((stage, 0, stations));
            listener(what, 0, stations);
        }
        if self.quiet {
            return;
        }
        let bar = self.terminal.add(ProgressBar::new(stations as u64));
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{spinner}} {what:<9} [{{bar:40}}] {{pos}}/{{len}} ({{elapsed}}, eta {{eta}})"
            ))
            .expect("static template")
            .progress_chars("=> "),
        );
        self.bars
            .lock()
            .expect("no panics hold it")
            .push((stage, bar));
    }

    fn advance(&self, stage: Stage) {
        if let Some(listener) = &self.listener {
            // Called under the lock, so that counts reach the listener in order: a slow
            // listener slows the stages' threads, which wait here.
            let mut positions = self.positions.lock().expect("no panics hold it");
            if let Some(position) = positions.iter_mut().find(|p| p.0 == stage) {
                position.1 += 1;
                listener(stage_name(stage), position.1, position.2);
            }
        }
        let bars = self.bars.lock().expect("no panics hold it");
        if let Some((_, bar)) = bars.iter().find(|b| b.0 == stage) {
            bar.inc(1);
        }
    }

    fn end(&self, stage: Stage) {
        let mut bars = self.bars.lock().expect("no panics hold it");
        if let Some(at) = bars.iter().position(|b| b.0 == stage) {
            bars.remove(at).1.finish_and_clear();
        }
    }

    fn warn(&self, message: &str) {
        self.warnings
            .lock()
            .expect("no panics hold it")
            .push(message.to_string());
        if !self.quiet {
            self.terminal.suspend(|| eprintln!("warning: {message}"));
        }
    }
}

/// A finished run: its summary (summary.json), the scoring against truth if there was one,
/// and the warnings by kind.
pub struct Completed {
    pub summary: RunSummary,
    pub evaluation: Option<Evaluation>,
    /// Warnings by kind, most frequent first: (count, first message).
    pub warnings: Vec<(usize, String)>,
    /// Wall seconds of the whole run, and of the scoring after the outputs.
    pub total_seconds: f64,
    pub scoring_seconds: Option<f64>,
}

/// `pipeline run`: maps, writes the outputs and prints the summary.
pub fn run(args: RunArgs) -> Result<()> {
    let completed = execute(&args, None)?;
    // Printed once every file is written: a reader that stops early ends the process.
    print_summary(&completed, &args.out);
    print_warnings(&completed.warnings, args.quiet);
    if let Some(evaluation) = &completed.evaluation {
        super::eval::print_report(evaluation);
    }
    Ok(())
}

/// Maps the panoramas of `args.images` and writes every output into `args.out`, reporting
/// progress on terminal bars, or to `listener` instead (then no bars and no warning lines).
/// Prints nothing.
pub fn execute(args: &RunArgs, listener: Option<Box<Listener>>) -> Result<Completed> {
    let started = Instant::now();
    let survey = Survey::open(&args.images)?;
    // The run's pictures (rng.png) would be read as panoramas by the next run.
    if same_directory(&args.out, &args.images) {
        bail!(
            "--out {} is the image directory: the next run would read the outputs (rng.png) as panoramas; nothing was written",
            args.out.display()
        );
    }
    let calib = load_calibration(args)?;
    let estimator = args.beliefs.estimator(args.mode)?;
    // The truth, given or found in the image directory, is read before any work: a bad one
    // would otherwise fail only once the run's outputs had replaced the earlier ones. A given
    // one must also describe every image (a found one is checked image by image when scoring,
    // so that a damaged panorama is skipped with a warning, as without truth).
    let default_truth = args.images.join("truth.json");
    let truth = match (&args.truth, args.no_eval) {
        (_, true) => None,
        (Some(truth), false) => Some((truth.clone(), true)),
        (None, false) => default_truth.exists().then_some((default_truth, false)),
    };
    if let Some((path, given)) = &truth {
        let what = if *given {
            "--truth"
        } else {
            "the image directory's truth.json (--no-eval to map without it)"
        };
        let contents = super::eval::read_truth(path)
            .with_context(|| format!("{what}; nothing was written"))?;
        if *given {
            super::eval::check_survey(&contents, &survey)
                .with_context(|| format!("{what} {}; nothing was written", path.display()))?;
        }
    }
    let checks_seconds = started.elapsed().as_secs_f64();
    let bars = Bars::new(args.quiet, listener);
    for path in &survey.unpaired {
        bars.warn(&format!(
            "{} has no _left partner and is not used",
            path.display()
        ));
    }
    for path in &survey.unnamed {
        bars.warn(&format!(
            "{} leaves no station name (NAME_left, NAME_right or NAME) and is not used",
            path.display()
        ));
    }
    for path in &survey.without_right {
        bars.warn(&format!(
            "{} has no _right partner: its station is mapped without stereo",
            path.display()
        ));
    }
    #[cfg(not(feature = "rerun"))]
    if args.rrd {
        bail!("--rrd needs a build with the rerun feature: cargo build --release -p pipeline --features rerun");
    }

    let mut settings = RunSettings::default();
    settings.detector.channels = args.channels.into();
    let mapper: Mapper<Edc> = Mapper::new(calib, settings.sensor, settings.association);
    // The output directory and recorders are made once a station could be read.
    let start = || -> Result<Recording> {
        std::fs::create_dir_all(&args.out)
            .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
        Ok((recorders(args)?, None))
    };
    let traversed = traverse_survey(
        &survey,
        &calib,
        &settings.detector,
        mapper,
        &bars,
        start,
        |(recorders, drawing), record, mapper| {
            record_station(recorders, drawing, record, mapper, &survey, &calib)
        },
    );
    let (traverse, (recorders, _)) = match traversed {
        Ok(traversed) => traversed,
        Err(RunError::Caller(e)) => return Err(e),
        // Quiet runs print no warning lines: the reasons go with the error.
        Err(e @ RunError::NothingReadable { .. }) => {
            let reasons: Vec<String> = bars
                .tally()
                .into_iter()
                .take(3)
                .map(|(_, example)| example)
                .collect();
            bail!("{e} ({}); nothing was written", reasons.join("; "))
        }
        Err(e) => bail!("{e}; nothing was written"),
    };
    let beliefs = match args.mode {
        Mode::Deterministic => None,
        Mode::Probabilistic => {
            let start = Instant::now();
            let sighted = &traverse.mapper.sighted;
            let sd = bearing_sd(sighted);
            let beliefs = run_beliefs(sighted, sd, &estimator, BELIEF_SEED);
            let summary = BeliefsSummary {
                estimator: estimator.variant.name().to_string(),
                triples_seen_twice: beliefs.seen_twice,
                triples: beliefs.triples.len(),
                bearing_sd_deg: sd.to_degrees(),
                wall_seconds: start.elapsed().as_secs_f64(),
            };
            Some((beliefs, summary))
        }
    };
    let writing = Instant::now();

    // Every output is staged and then renamed in one pass: an earlier run's files are all
    // replaced or none are (an interrupt before the pass leaves them as they were).
    let mut outputs = OutputSet::new();
    let cut = EdgeCut::new(args.all_edges);
    stage_outputs(
        &mut outputs,
        &args.out,
        &traverse.mapper,
        &traverse.records,
        cut,
    )?;
    if let Some((beliefs, _)) = &beliefs {
        stage(
            &mut outputs,
            &args.out.join("beliefs.json"),
            beliefs.to_json(&estimator).as_bytes(),
        )?;
    }
    let landmarks = traverse.mapper.landmarks();
    let images = RunImages {
        directory: &survey.directory,
        size: (calib.image.width, calib.image.height),
        records: &traverse.records,
        landmarks: &landmarks,
    };
    for warning in stage_pictures(&mut outputs, &args.out, &images, args.panoramas)? {
        bars.warn(&warning);
    }
    for recorder in recorders {
        outputs.adopt(recorder.finish()?);
    }
    let mut summary = traverse.summary();
    summary.wall_checks = checks_seconds;
    let beliefs_absent = beliefs.is_none();
    summary.beliefs = beliefs.map(|(_, summary)| summary);
    summary.wall_outputs = writing.elapsed().as_secs_f64();
    stage(
        &mut outputs,
        &args.out.join("summary.json"),
        (serde_json::to_string_pretty(&summary)? + "\n").as_bytes(),
    )?;
    // A scoring left from an earlier run into the same directory would not be this run's; the
    // new one is written after the run's files are in place.
    outputs.remove_stale(&args.out.join("eval.json"));
    outputs.remove_stale(&args.out.join("rng_truth.png"));
    if beliefs_absent {
        outputs.remove_stale(&args.out.join("beliefs.json"));
    }
    outputs
        .commit()
        .with_context(|| format!("cannot move the outputs into {}", args.out.display()))?;
    let scoring = Instant::now();
    let evaluation = match truth {
        Some((truth, _)) => Some(super::eval::score_run_files(
            &args.out, &truth, &calib, &args.out, cut,
        )?),
        None => None,
    };
    let scoring_seconds = evaluation.as_ref().map(|_| scoring.elapsed().as_secs_f64());
    Ok(Completed {
        summary,
        evaluation,
        warnings: bars.tally(),
        total_seconds: started.elapsed().as_secs_f64(),
        scoring_seconds,
    })
}

/// Whether `a` and `b` name the same existing directory.
fn same_directory(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// `--calib`, or calib.toml in the image directory.
fn load_calibration(args: &RunArgs) -> Result<Calibration> {
    let path = args
        .calib
        .clone()
        .unwrap_or_else(|| args.images.join("calib.toml"));
    if !path.exists() {
        bail!(
            "no calibration: {} does not exist (give one with --calib FILE; format in calib/README.md)",
            path.display()
        );
    }
    Ok(Calibration::load(&path)?)
}

/// Hands one mapped station to every recorder, with its panorama for those that show it.
/// `drawing` keeps the RNG drawing of the map's latest revision: laying out every edge of a
/// long drive's map takes longer than mapping a station, and an unchanged map draws the same.
fn record_station(
    recorders: &mut [Box<dyn Recorder>],
    drawing: &mut Option<(u64, RngDrawing)>,
    record: &StationRecord,
    mapper: &Mapper<Edc>,
    survey: &Survey,
    calib: &Calibration,
) -> Result<()> {
    let no_image = RgbImage::new(0, 0);
    let panorama = if recorders.iter().any(|r| r.wants_panorama()) {
        let primary = survey.directory.join(&record.files[0]);
        read_image(&primary, (calib.image.width, calib.image.height))?
    } else {
        no_image.clone()
    };
    if drawing
        .as_ref()
        .is_some_and(|(revision, _)| *revision != mapper.revision())
    {
        *drawing = None;
    }
    let (_, drawing) =
        drawing.get_or_insert_with(|| (mapper.revision(), rng_drawing(&mapper.map, mapper.rng())));
    for recorder in recorders.iter_mut() {
        let image = if recorder.wants_panorama() {
            &panorama
        } else {
            &no_image
        };
        recorder.station(record, image)?;
        recorder.rng(record.index, &*drawing)?;
    }
    Ok(())
}

fn print_summary(completed: &Completed, out: &Path) {
    println!("{}", completed.summary);
    let scoring = completed.scoring_seconds.map_or(String::new(), |s| {
        format!(" (scoring against truth, after the outputs: {s:.2} s)")
    });
    println!(
        "total {:.2} s{scoring}; outputs in {}",
        completed.total_seconds,
        out.display()
    );
    let pictures: Vec<String> = [
        (
            "rng.png",
            format!("the RNG; edges of cost w ≤ {DEFAULT_MAX_COST} unless --all-edges"),
        ),
        ("landmarks.png", "every landmark's best view".to_string()),
        ("panoramas", "each station's detections".to_string()),
    ]
    .into_iter()
    .filter(|(name, _)| {
        let path = out.join(name);
        path.is_file() || std::fs::read_dir(&path).is_ok_and(|mut d| d.next().is_some())
    })
    .map(|(name, what)| format!("{} ({what})", out.join(name).display()))
    .collect();
    if !pictures.is_empty() {
        println!("  look at {}", pictures.join(", "));
    }
    println!(
        "  the map is {} (docs/MAP_FORMAT.md); everything per station is in {} (docs/RUN_OUTPUTS.md)",
        out.join("map.json").display(),
        out.join("run.mcap").display()
    );
}

/// The warnings by kind, after the summary: a long survey prints hundreds of lines above it.
fn print_warnings(tally: &[(usize, String)], quiet: bool) {
    let total: usize = tally.iter().map(|(n, _)| n).sum();
    if total == 0 {
        return;
    }
    let shown = if quiet {
        "not printed (--quiet)"
    } else {
        "printed above"
    };
    println!(
        "warnings: {total}, {shown}; a station's are also in its stations.json record. By kind:"
    );
    const KINDS: usize = 8;
    for (count, example) in tally.iter().take(KINDS) {
        println!("  {count} × {example}");
    }
    if tally.len() > KINDS {
        println!("  … and {} more kinds", tally.len() - KINDS);
    }
}

/// Stages `bytes` as `path`.
fn stage(outputs: &mut OutputSet, path: &Path, bytes: &[u8]) -> Result<()> {
    outputs
        .stage_bytes(path, bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// map.json, rng.json, rng.png, timing.png, stations.json, landmarks.json, staged.
fn stage_outputs(
    outputs: &mut OutputSet,
    out: &Path,
    mapper: &Mapper<Edc>,
    records: &[StationRecord],
    cut: EdgeCut,
) -> Result<()> {
    stage(
        outputs,
        &out.join("map.json"),
        mapper.map.to_json().as_bytes(),
    )?;
    stage(
        outputs,
        &out.join("rng.json"),
        rng_json(&mapper.map, mapper.rng()).as_bytes(),
    )?;
    stage_rng_png(
        outputs,
        &out.join("rng.png"),
        mapper.map.landmarks(),
        mapper.rng(),
        records.len(),
        cut,
    )?;
    if !records.is_empty() {
        outputs.stage(&out.join("timing.png"), |temporary| {
            write_panels(temporary, "station", &timing_panels(records))
        })?;
    }
    stage(
        outputs,
        &out.join("stations.json"),
        (serde_json::to_string(records)? + "\n").as_bytes(),
    )?;
    stage(
        outputs,
        &out.join("landmarks.json"),
        (serde_json::to_string_pretty(&mapper.landmarks())? + "\n").as_bytes(),
    )?;
    Ok(())
}

/// timing.png: where each station's time went, and how the map grew, along the traverse (a long
/// drive's cost per station should stay flat, not grow with the map).
fn timing_panels(records: &[StationRecord]) -> Vec<Panel> {
    let curve = |label: &str, value: &dyn Fn(&StationRecord) -> f64| Curve {
        label: label.to_string(),
        mean: records.iter().map(value).collect(),
        std: Vec::new(),
        band: None,
    };
    vec![
        Panel {
            title: "(a) time per station by stage".into(),
            y_label: "seconds".into(),
            curves: vec![
                curve("decode + detect (CPU, in parallel across stations)", &|r| {
                    r.seconds.decode + r.seconds.detect
                }),
                curve("associate", &|r| r.seconds.associate),
                curve("measure and fuse", &|r| r.seconds.map),
                curve("map metrics and RNG estimate", &|r| r.seconds.metrics),
                curve("recording (MCAP)", &|r| r.seconds.recording),
            ],
            x: Vec::new(),
        },
        Panel {
            title: "(b) map size".into(),
            y_label: "landmarks".into(),
            curves: vec![curve("landmarks in the map", &|r| {
                r.metrics.landmarks as f64
            })],
            x: Vec::new(),
        },
    ]
}
