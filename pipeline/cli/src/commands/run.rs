//! `pipeline run --images DIR`: panoramas in, qualitative map and RNG out (docs/RUN.md).

use super::output::write_atomic;
use super::rng_json;
use crate::recording::{McapRecorder, Recorder, RngDrawing};
use anyhow::{bail, Context, Result};
use clap::Args;
use image::RgbImage;
use indicatif::{ProgressBar, ProgressStyle};
use qrm_core::edc::Edc;
use qrm_core::map::Hypergraph;
use qrm_core::neighborhood::estimate;
use qrm_plot::{spring_layout, write_rng, RngPicture};
use qrm_vision::association::AssociationSettings;
use qrm_vision::calib::Calibration;
use qrm_vision::detection::DetectorSettings;
use qrm_vision::ranging::SensorModel;
use qrm_vision::run::front_end::{detect_station, FrontEndResult};
use qrm_vision::run::{Mapper, RunSummary, StationRecord};
use qrm_vision::survey::{read_image, Survey};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
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
}

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

/// The RNG estimate of the map over a graph layout, for the recorders and rng.png.
fn rng_drawing(map: &Hypergraph<Edc>) -> RngDrawing {
    let ids = map.landmarks();
    let rng = estimate(map).unwrap_or_default();
    let index = |id: u32| ids.iter().position(|&l| l == id).expect("edge of the map");
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

fn bar(len: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} {what:<9} [{{bar:40}}] {{pos}}/{{len}} ({{elapsed}}, eta {{eta}})"
        ))
        .expect("static template")
        .progress_chars("=> "),
    );
    bar
}

pub fn run(args: RunArgs) -> Result<()> {
    let started = Instant::now();
    let survey = Survey::open(&args.images)?;
    let calib_path = args
        .calib
        .clone()
        .unwrap_or_else(|| args.images.join("calib.toml"));
    if !calib_path.exists() {
        bail!(
            "no calibration: {} does not exist (give one with --calib FILE; format in calib/README.md)",
            calib_path.display()
        );
    }
    let calib = Calibration::load(&calib_path)?;
    for path in &survey.unpaired {
        eprintln!(
            "warning: {} has no _left partner and is not used",
            path.display()
        );
    }
    #[cfg(not(feature = "rerun"))]
    if args.rrd {
        bail!("--rrd needs a build with the rerun feature: cargo build --release -p pipeline --features rerun");
    }

    let detector = DetectorSettings::default();
    let progress = bar(survey.stations.len(), "detect");
    let front: Vec<FrontEndResult> = survey
        .stations
        .par_iter()
        .map(|station| {
            let result = detect_station(station, &survey.directory, &calib, &detector);
            progress.inc(1);
            result
        })
        .collect();
    progress.finish_and_clear();
    let detect_wall = started.elapsed().as_secs_f64();

    if front.iter().all(|r| r.station.is_err()) {
        for result in &front {
            if let Err(warning) = &result.station {
                eprintln!("warning: {warning}");
            }
        }
        bail!(
            "none of the {} stations in {} could be read; nothing was written",
            survey.stations.len(),
            survey.directory.display()
        );
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    let mut recorders = recorders(&args)?;
    let wants_panorama = recorders.iter().any(|r| r.wants_panorama());
    let no_image = RgbImage::new(0, 0);
    let mut mapper: Mapper<Edc> = Mapper::new(
        calib,
        SensorModel::default(),
        AssociationSettings::default(),
    );
    let mut records: Vec<StationRecord> = Vec::new();
    let mut skipped = Vec::new();
    let progress = bar(front.len(), "map");
    let map_started = Instant::now();
    for result in &front {
        progress.inc(1);
        let station = match &result.station {
            Ok(station) => station,
            Err(warning) => {
                progress.suspend(|| eprintln!("warning: {warning}"));
                skipped.push(warning.clone());
                continue;
            }
        };
        let mut record = mapper.process(records.len(), station);
        record.seconds.decode = result.decode_seconds;
        record.seconds.detect = result.detect_seconds;
        for warning in &record.warnings {
            progress.suspend(|| eprintln!("warning: {warning}"));
        }
        let panorama = if wants_panorama {
            let primary = survey.directory.join(&station.files[0]);
            read_image(&primary, (calib.image.width, calib.image.height))?
        } else {
            no_image.clone()
        };
        let drawing = rng_drawing(&mapper.map);
        for recorder in &mut recorders {
            let image = if recorder.wants_panorama() {
                &panorama
            } else {
                &no_image
            };
            recorder.station(&record, image)?;
            recorder.rng(record.index, &drawing)?;
        }
        records.push(record);
    }
    progress.finish_and_clear();
    let map_wall = map_started.elapsed().as_secs_f64();

    write_outputs(&args.out, &mapper, &records)?;
    for recorder in recorders {
        recorder.finish()?;
    }
    let summary = RunSummary::of(&records, &mapper, skipped.len(), detect_wall, map_wall);
    write_atomic(
        &args.out.join("summary.json"),
        (serde_json::to_string_pretty(&summary)? + "\n").as_bytes(),
    )?;
    println!("{summary}");
    println!(
        "total {:.2} s; outputs in {}",
        started.elapsed().as_secs_f64(),
        args.out.display()
    );
    if args.out.join("rng.png").exists() {
        println!("  look at {} (the RNG)", args.out.join("rng.png").display());
    }
    println!(
        "  the map is {} (docs/MAP_FORMAT.md); everything per station is in {} (docs/RUN_OUTPUTS.md)",
        args.out.join("map.json").display(),
        args.out.join("run.mcap").display()
    );

    let truth = args.truth.clone().or_else(|| {
        let default = args.images.join("truth.json");
        default.exists().then_some(default)
    });
    match (truth, args.no_eval) {
        (Some(truth), false) => super::eval::evaluate_run(&args.out, &truth, &calib, &args.out)?,
        // A scoring left from an earlier run into the same directory would not be this run's.
        _ => remove_stale(&args.out.join("eval.json"))?,
    }
    Ok(())
}

/// Removes an output of an earlier run into the same directory that this run does not write.
fn remove_stale(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("cannot remove the stale {}", path.display()))
        }
        _ => Ok(()),
    }
}

/// map.json, rng.json, rng.png, stations.json, landmarks.json.
fn write_outputs(out: &Path, mapper: &Mapper<Edc>, records: &[StationRecord]) -> Result<()> {
    write_atomic(&out.join("map.json"), mapper.map.to_json().as_bytes())?;
    let rng = estimate(&mapper.map).expect("EDC has a lune");
    write_atomic(
        &out.join("rng.json"),
        rng_json(&mapper.map, &rng).as_bytes(),
    )?;
    let drawing = rng_drawing(&mapper.map);
    if !drawing.landmarks.is_empty() {
        let index = |id: u32| {
            drawing
                .landmarks
                .iter()
                .position(|l| l.0 == id)
                .expect("edge of the map")
        };
        let positions: Vec<(f64, f64)> =
            drawing.landmarks.iter().map(|l| (l.1[0], l.1[1])).collect();
        let edges: Vec<(usize, usize, f64)> = drawing
            .edges
            .iter()
            .map(|&(a, b, cost)| (index(a), index(b), cost))
            .collect();
        write_rng(
            &out.join("rng.png"),
            &RngPicture {
                title: format!(
                    "RNG after {} stations ({} landmarks; graph layout, not metric)",
                    records.len(),
                    positions.len()
                ),
                landmarks: &positions,
                edges: &edges,
                true_edges: &[],
                stations: &[],
            },
        )?;
    } else {
        remove_stale(&out.join("rng.png"))?;
    }
    write_atomic(
        &out.join("stations.json"),
        (serde_json::to_string(records)? + "\n").as_bytes(),
    )?;
    write_atomic(
        &out.join("landmarks.json"),
        (serde_json::to_string_pretty(&mapper.landmarks())? + "\n").as_bytes(),
    )?;
    Ok(())
}
