//! `pipeline synth`: render a synthetic dataset with ground truth (issue 4).

use anyhow::{bail, Context, Result};
use clap::Args;
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use qrm_synth::dataset::{write_dataset, Counts, Preset, Request, Variant, VariantTruth};
use qrm_synth::{default_calibration, Capture, Encoding, Scenery};
use qrm_vision::calib::{Calibration, ColumnDirection};
use std::path::PathBuf;
use std::sync::Mutex;
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
    /// One member per seed: the marsyard or random layout with sun, rock colours, clustering,
    /// camera effects, encoding, column direction and origin, and scale drawn from the seed.
    Stress,
}

impl From<PresetName> for Preset {
    fn from(name: PresetName) -> Self {
        match name {
            PresetName::Marsyard => Preset::Marsyard,
            PresetName::Random => Preset::Random,
            PresetName::SparseLarge => Preset::SparseLarge,
            PresetName::Stress => Preset::Stress,
        }
    }
}

/// The scene and camera options default to the preset's own look; with `--preset stress`
/// they default to the seed's draws, and each one given replaces its draw.
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
    /// Camera calibration (default: calib/default.toml, 4096 × 768). With `--preset stress`
    /// the file's column direction and origin are kept instead of drawn.
    #[arg(long)]
    calib: Option<PathBuf>,
    /// Scale the image size (and the focal length with it), e.g. 0.25 for a quick 1024 × 192
    /// set [default: 1].
    #[arg(long)]
    scale: Option<f64>,
    /// Sun elevation in degrees (2–90; default: drawn between 20 and 45 per seed); a low sun
    /// (e.g. 8) casts shadows about 7 times as long as the rock is high.
    #[arg(long)]
    sun_elevation: Option<f64>,
    /// How far rock albedo lies from the soil's (0–1): albedo = soil + K · (drawn − soil),
    /// with the soil's mean colour where the rock lies; 0 = rocks of the soil's colour and
    /// brightness, 1 = the drawn basalt-to-ochre palette [default: 1].
    #[arg(long, value_name = "K")]
    rock_albedo_contrast: Option<f64>,
    /// Fraction of the rocks (0–1) gathered into dense clusters where each touches or overlaps
    /// a neighbour; imaging points stay 0.6 m clear of every rock [default: 0].
    #[arg(long, value_name = "FRACTION")]
    cluster: Option<f64>,
    /// Exposure change in stops (e.g. -1 for an image half as bright), clipped at white
    /// [default: 0].
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<f64>,
    /// Tone curve: channel values v in [0, 1] become v^(1/GAMMA) (1 = linear, 2.2 = sRGB-like)
    /// [default: 1].
    #[arg(long)]
    gamma: Option<f64>,
    /// Light lost at the top and bottom edges, falling off quadratically from the middle row
    /// (0 = none, 0.3 = 30 % darker edges) [default: 0].
    #[arg(long)]
    vignetting: Option<f64>,
    /// Gaussian blur, standard deviation in pixels (0 = sharp) [default: 0].
    #[arg(long)]
    blur: Option<f32>,
    /// Additive Gaussian sensor noise, standard deviation in 8-bit levels (0 = none)
    /// [default: 0].
    #[arg(long)]
    noise: Option<f64>,
    /// Write 8-bit grayscale panoramas, as a monochrome navigation camera would.
    #[arg(long)]
    grayscale: bool,
    /// Write JPEG panoramas (`.jpg`) at this quality, 1–100, instead of PNG.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=100))]
    jpeg: Option<u8>,
}

/// A rendered dataset: what `pipeline synth` prints.
pub struct Rendered {
    pub preset: &'static str,
    pub rocks: usize,
    pub stations: usize,
    pub panoramas: usize,
    pub width: u32,
    pub height: u32,
    pub seconds: f64,
    /// The drawn variant of a stress preset, described.
    pub variant: Option<String>,
}

/// `pipeline synth`: renders with a progress bar and prints what was written.
pub fn run(args: SynthArgs) -> Result<()> {
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} rendering [{bar:40}] {pos}/{len} stations ({elapsed}, eta {eta})",
        )
        .expect("static template")
        .progress_chars("=> "),
    );
    let rendered = render(&args, &|done, total| {
        if bar.length() != Some(total as u64) {
            bar.set_length(total as u64);
        }
        bar.set_position(done as u64);
    })?;
    bar.finish_and_clear();
    println!(
        "{} (seed {}): {} rocks, {} stations, {} panoramas of {} × {} in {:.1} s → {}",
        rendered.preset,
        args.seed,
        rendered.rocks,
        rendered.stations,
        rendered.panoramas,
        rendered.width,
        rendered.height,
        rendered.seconds,
        args.out.display()
    );
    if let Some(v) = &rendered.variant {
        println!("{v}");
    }
    Ok(())
}

/// Renders the dataset `args` asks for into `args.out`; `progress(done, total)` after every
/// station, in order of `done` (and once with 0 at the start). Prints nothing.
pub fn render(args: &SynthArgs, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<Rendered> {
    let base = match &args.calib {
        Some(path) => Calibration::load(path)?,
        None => default_calibration(),
    };
    let preset = Preset::from(args.preset);
    let variant = variant(args, preset, &base)?;
    let calib = variant.calibration(&base)?;
    if args.rocks == Some(0) || args.stations == Some(0) {
        bail!("--rocks and --stations must be positive");
    }
    if args.rocks.is_some_and(|n| n > 2000) {
        bail!("--rocks must be at most 2000");
    }
    let request = Request {
        preset,
        seed: args.seed,
        counts: Counts {
            rocks: args.rocks,
            stations: args.stations,
        },
        stereo: !args.mono,
        scenery: variant.scenery,
        capture: variant.capture,
        encoding: variant.encoding,
    };
    let stations = preset
        .layout_clustered(args.seed, request.counts, variant.scenery.cluster)
        .stations
        .len();
    progress(0, stations);
    // Counted and reported under one lock, so that counts reach `progress` in order.
    let done = Mutex::new(0usize);
    let tick = || {
        let mut done = done.lock().expect("no panics hold it");
        *done += 1;
        progress(*done, stations);
    };
    let start = Instant::now();
    let truth = write_dataset(&args.out, &calib, request, &tick)
        .with_context(|| format!("rendering into {}", args.out.display()))?;
    Ok(Rendered {
        preset: preset.name(),
        rocks: truth.rocks.len(),
        stations: truth.stations.len(),
        panoramas: truth.images.len(),
        width: calib.image.width,
        height: calib.image.height,
        seconds: start.elapsed().as_secs_f64(),
        variant: truth.variant.as_ref().map(|v| describe(v, variant.scale)),
    })
}

/// The look asked for: the preset's own (or, for `stress`, the seed's draw), with each option
/// given replacing its value, each checked against a range a scene or camera can produce.
fn variant(args: &SynthArgs, preset: Preset, calib: &Calibration) -> Result<Variant> {
    let mut v = match preset {
        Preset::Stress => Variant::stress(args.seed),
        _ => Variant {
            layout: preset,
            scenery: Scenery::default(),
            capture: Capture::default(),
            encoding: Encoding::default(),
            column_axis: calib.azimuth,
            scale: 1.0,
        },
    };
    if args.calib.is_some() {
        v.column_axis = calib.azimuth;
    }
    let given = |option: Option<f64>, drawn: f64| option.unwrap_or(drawn);
    v.scale = given(args.scale, v.scale);
    v.scenery.sun_elevation_deg = args.sun_elevation.or(v.scenery.sun_elevation_deg);
    v.scenery.rock_albedo_contrast =
        given(args.rock_albedo_contrast, v.scenery.rock_albedo_contrast);
    v.scenery.cluster = given(args.cluster, v.scenery.cluster);
    v.capture.exposure_ev = given(args.exposure, v.capture.exposure_ev);
    v.capture.gamma = given(args.gamma, v.capture.gamma);
    v.capture.vignetting = given(args.vignetting, v.capture.vignetting);
    v.capture.blur_px = args.blur.unwrap_or(v.capture.blur_px);
    v.capture.noise = given(args.noise, v.capture.noise);
    v.encoding.grayscale |= args.grayscale;
    v.encoding.jpeg_quality = args.jpeg.or(v.encoding.jpeg_quality);
    let checks = [
        ("--scale", v.scale, 0.01, 4.0),
        (
            "--rock-albedo-contrast",
            v.scenery.rock_albedo_contrast,
            0.0,
            1.0,
        ),
        ("--cluster", v.scenery.cluster, 0.0, 1.0),
        ("--exposure", v.capture.exposure_ev, -8.0, 8.0),
        ("--gamma", v.capture.gamma, 0.2, 5.0),
        ("--vignetting", v.capture.vignetting, 0.0, 0.9),
        ("--blur", f64::from(v.capture.blur_px), 0.0, 20.0),
        ("--noise", v.capture.noise, 0.0, 64.0),
    ];
    let sun = v
        .scenery
        .sun_elevation_deg
        .map(|e| ("--sun-elevation", e, 2.0, 90.0));
    for (flag, value, low, high) in checks.into_iter().chain(sun) {
        if !(low..=high).contains(&value) {
            bail!("{flag} {value} must lie in [{low}, {high}]");
        }
    }
    Ok(v)
}

/// One line saying how a set departs from its preset's look.
fn describe(v: &VariantTruth, scale: f64) -> String {
    let parts = [
        format!("layout {}", v.layout),
        format!("sun {:.1}°", v.sun_elevation_deg),
        format!("albedo contrast {}", v.rock_albedo_contrast),
        format!("cluster {}", v.cluster),
        format!("exposure {} EV", v.exposure_ev),
        format!("gamma {}", v.gamma),
        format!("vignetting {}", v.vignetting),
        format!("blur {} px", v.blur_px),
        format!("noise {}", v.noise),
        if v.grayscale { "grayscale" } else { "colour" }.to_string(),
        match v.jpeg_quality {
            Some(q) => format!("JPEG q{q}"),
            None => "PNG".to_string(),
        },
        format!(
            "columns {} from {}°",
            match v.column_direction {
                ColumnDirection::Clockwise => "clockwise",
                ColumnDirection::CounterClockwise => "counter-clockwise",
            },
            v.column0_deg
        ),
        format!("scale {scale} ({} × {})", v.width, v.height),
    ];
    format!("variant: {}", parts.join(", "))
}
