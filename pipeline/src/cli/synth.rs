//! `pipeline synth`: render a synthetic dataset with ground truth (issue 4).

use anyhow::{bail, Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use qrm::calib::Calibration;
use qrm::dataset::{write_dataset, Counts, Preset, Request};
use std::path::PathBuf;
use std::time::Instant;

/// The calibration of the synthetic datasets (`calib/default.toml`).
const DEFAULT_CALIBRATION: &str = include_str!("../../../calib/default.toml");

#[derive(Args, Debug)]
pub struct SynthArgs {
    #[arg(long, value_enum, default_value = "marsyard")]
    preset: Preset,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory (created; existing files of the same names are replaced).
    #[arg(long)]
    out: PathBuf,
    /// Override the preset's number of rocks.
    #[arg(long)]
    rocks: Option<usize>,
    /// Override the preset's number of imaging points.
    #[arg(long)]
    stations: Option<usize>,
    /// One mono panorama per station instead of a stereo pair.
    #[arg(long)]
    mono: bool,
    /// Camera calibration (default: calib/default.toml, 4096 × 768).
    #[arg(long)]
    calib: Option<PathBuf>,
    /// Scale the image size (and the focal length with it), e.g. 0.25 for a quick 1024 × 192 set.
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
}

pub fn run(args: SynthArgs) -> Result<()> {
    let mut calib = match &args.calib {
        Some(path) => Calibration::load(path)?,
        None => Calibration::parse(DEFAULT_CALIBRATION, "calib/default.toml")
            .expect("the committed default calibration is valid"),
    };
    if !(0.01..=4.0).contains(&args.scale) {
        bail!("--scale {} must lie in [0.01, 4]", args.scale);
    }
    if args.scale != 1.0 {
        calib = calib.scaled(args.scale)?;
    }
    if args.rocks == Some(0) || args.stations == Some(0) {
        bail!("--rocks and --stations must be positive");
    }
    if args.rocks.is_some_and(|n| n > 2000) {
        bail!("--rocks must be at most 2000");
    }
    let request = Request {
        preset: args.preset,
        seed: args.seed,
        counts: Counts {
            rocks: args.rocks,
            stations: args.stations,
        },
        stereo: !args.mono,
    };
    let stations = args.preset.layout(args.seed, request.counts).stations.len();
    let bar = ProgressBar::new(stations as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} rendering [{bar:40}] {pos}/{len} stations ({elapsed}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    let start = Instant::now();
    let truth = write_dataset(&args.out, &calib, request, &|| bar.inc(1))
        .with_context(|| format!("rendering into {}", args.out.display()))?;
    bar.finish_and_clear();
    println!(
        "{} (seed {}): {} rocks, {} stations, {} panoramas of {} × {} in {:.1} s → {}",
        args.preset.name(),
        args.seed,
        truth.rocks.len(),
        truth.stations.len(),
        truth.images.len(),
        calib.image.width,
        calib.image.height,
        start.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}
