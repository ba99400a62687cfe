//! `pipeline synth`: render a synthetic dataset with ground truth (issue 4).

use anyhow::{bail, Context, Result};
use clap::Args;
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use qrm_synth::dataset::{write_dataset, Counts, Preset, Request};
use qrm_synth::{default_calibration, Capture, Encoding};
use qrm_vision::calib::Calibration;
use std::path::PathBuf;
use std::time::Instant;

/// The presets as the command line spells them (`sparse-large`).
#[derive(Clone, Copy, Debug, ValueEnum)]
enum PresetName {
    /// 30 rocks, partly clustered, in about 20 m × 20 m; a loop traverse stopping every 1–2 m.
    Marsyard,
    /// 30 rocks uniform in a 30 m square; 50 random imaging points.
    Random,
    /// 200 rocks over 200 m × 200 m; a long meandering traverse.
    SparseLarge,
}

impl From<PresetName> for Preset {
    fn from(name: PresetName) -> Self {
        match name {
            PresetName::Marsyard => Preset::Marsyard,
            PresetName::Random => Preset::Random,
            PresetName::SparseLarge => Preset::SparseLarge,
        }
    }
}

#[derive(Args, Debug)]
pub struct SynthArgs {
    #[arg(long, value_enum, default_value = "marsyard")]
    preset: PresetName,
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
    /// Exposure change in stops (e.g. -1 for an image half as bright), clipped at white.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f64,
    /// Tone curve: channel values v in [0, 1] become v^(1/GAMMA) (1 = linear, 2.2 = sRGB-like).
    #[arg(long, default_value_t = 1.0)]
    gamma: f64,
    /// Light lost at the top and bottom edges, falling off quadratically from the middle row
    /// (0 = none, 0.3 = 30 % darker edges).
    #[arg(long, default_value_t = 0.0)]
    vignetting: f64,
    /// Gaussian blur, standard deviation in pixels (0 = sharp).
    #[arg(long, default_value_t = 0.0)]
    blur: f32,
    /// Additive Gaussian sensor noise, standard deviation in 8-bit levels (0 = none).
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Write 8-bit grayscale panoramas, as a monochrome navigation camera would.
    #[arg(long)]
    grayscale: bool,
    /// Write JPEG panoramas (`.jpg`) at this quality, 1–100, instead of PNG.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=100))]
    jpeg: Option<u8>,
}

pub fn run(args: SynthArgs) -> Result<()> {
    let mut calib = match &args.calib {
        Some(path) => Calibration::load(path)?,
        None => default_calibration(),
    };
    let preset = Preset::from(args.preset);
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
    let capture = capture(&args)?;
    let request = Request {
        preset,
        seed: args.seed,
        counts: Counts {
            rocks: args.rocks,
            stations: args.stations,
        },
        stereo: !args.mono,
        capture,
        encoding: Encoding {
            grayscale: args.grayscale,
            jpeg_quality: args.jpeg,
        },
    };
    let stations = preset.layout(args.seed, request.counts).stations.len();
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
        preset.name(),
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

/// The camera effects asked for, each checked against a range a camera can produce.
fn capture(args: &SynthArgs) -> Result<Capture> {
    let checks = [
        ("--exposure", args.exposure, -8.0, 8.0),
        ("--gamma", args.gamma, 0.2, 5.0),
        ("--vignetting", args.vignetting, 0.0, 0.9),
        ("--blur", f64::from(args.blur), 0.0, 20.0),
        ("--noise", args.noise, 0.0, 64.0),
    ];
    for (flag, value, low, high) in checks {
        if !(low..=high).contains(&value) {
            bail!("{flag} {value} must lie in [{low}, {high}]");
        }
    }
    Ok(Capture {
        exposure_ev: args.exposure,
        gamma: args.gamma,
        vignetting: args.vignetting,
        blur_px: args.blur,
        noise: args.noise,
    })
}
