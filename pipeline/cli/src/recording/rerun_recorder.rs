//! `run.rrd` for the rerun viewer: per station (on the sequence timeline `station`) the
//! panorama with its detections boxed and labelled by association, the RNG estimate, and the
//! map metrics as curves.

use std::collections::HashMap;
use std::path::Path;

use image::imageops::FilterType;

use super::{Problem, Recorder, RecordingError, RngDrawing};
use qrm_atomic_file::Temporary;
use qrm_vision::run::{Association, StationRecord};

/// The timeline every entity is logged on: the station index.
const TIMELINE: &str = "station";

/// Panoramas wider than this are halved, which keeps a 4096-wide run's `.rrd` at a quarter of
/// the pixels while the boxes stay legible.
const MAX_WIDTH: u32 = 2048;

/// Writes `run.rrd` (see `docs/RUN_OUTPUTS.md`).
pub struct RerunRecorder {
    // Before `temporary`, so that it is dropped first: dropping the stream completes the
    // temporary file, and only then does `temporary` remove it.
    stream: rerun::RecordingStream,
    temporary: Temporary,
}

impl RerunRecorder {
    /// Starts a recording that [`Recorder::finish`] moves to `path`.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, RecordingError> {
        let path = path.as_ref();
        let temporary = Temporary::beside(path);
        // Enabled explicitly: the `RERUN` environment variable must not silently empty a file
        // the user asked for.
        let stream = rerun::RecordingStreamBuilder::new("qrm")
            .enabled(true)
            .save(temporary.path())
            .map_err(|e| RecordingError {
                path: path.to_path_buf(),
                problem: Problem::Rerun(e.to_string()),
            })?;
        Ok(Self { stream, temporary })
    }

    fn error(&self, problem: impl ToString) -> RecordingError {
        RecordingError {
            path: self.temporary.target().to_path_buf(),
            problem: Problem::Rerun(problem.to_string()),
        }
    }

    fn log_station(
        &self,
        record: &StationRecord,
        panorama: &image::RgbImage,
    ) -> rerun::RecordingStreamResult<()> {
        let stream = &self.stream;
        stream.set_time_sequence(TIMELINE, record.index as i64);

        let scale = if panorama.width() > MAX_WIDTH { 2 } else { 1 };
        let halved = (scale > 1).then(|| {
            image::imageops::resize(
                panorama,
                panorama.width() / scale,
                panorama.height() / scale,
                FilterType::Triangle,
            )
        });
        let shown = halved.as_ref().unwrap_or(panorama);
        stream.log(
            "panorama",
            &rerun::Image::from_rgb24(shown.as_raw().clone(), [shown.width(), shown.height()]),
        )?;

        // Boxes are inclusive pixel ranges; a box across the seam runs past the right edge.
        let scale = scale as f32;
        let detections = &record.detections;
        let mins = detections
            .iter()
            .map(|d| [d.bbox[0] as f32 / scale, d.bbox[1] as f32 / scale]);
        let sizes = detections.iter().map(|d| {
            [
                (d.bbox[2] + 1 - d.bbox[0]) as f32 / scale,
                (d.bbox[3] + 1 - d.bbox[1]) as f32 / scale,
            ]
        });
        stream.log(
            "panorama/detections",
            &rerun::Boxes2D::from_mins_and_sizes(mins, sizes)
                .with_labels(detections.iter().map(|d| association_label(&d.association)))
                .with_colors(
                    detections
                        .iter()
                        .map(|d| association_colour(&d.association)),
                ),
        )?;

        let m = &record.metrics;
        for (name, value) in [
            ("open_fraction", m.open_fraction),
            ("fully_constrained_fraction", m.fully_constrained_fraction),
            ("rng_cost", m.rng_cost),
            ("landmarks", m.landmarks as f64),
        ] {
            stream.log(format!("metrics/{name}"), &rerun::Scalars::single(value))?;
        }

        for warning in &record.warnings {
            stream.log(
                "warnings",
                &rerun::TextLog::new(warning.as_str()).with_level(rerun::TextLogLevel::WARN),
            )?;
        }
        Ok(())
    }

    fn log_rng(&self, index: usize, drawing: &RngDrawing) -> rerun::RecordingStreamResult<()> {
        let stream = &self.stream;
        stream.set_time_sequence(TIMELINE, index as i64);
        // The 2-D view's y axis points down; negating y keeps the layout's north up.
        let at: HashMap<u32, [f32; 2]> = drawing
            .landmarks
            .iter()
            .map(|&(id, [x, y])| (id, [x as f32, -y as f32]))
            .collect();
        let (strips, colours): (Vec<_>, Vec<_>) = drawing
            .edges
            .iter()
            .filter_map(|&(a, b, cost)| Some(([*at.get(&a)?, *at.get(&b)?], cost_colour(cost))))
            .unzip();
        stream.log(
            "rng/edges",
            &rerun::LineStrips2D::new(strips).with_colors(colours),
        )?;
        stream.log(
            "rng/landmarks",
            &rerun::Points2D::new(drawing.landmarks.iter().map(|(id, _)| at[id]))
                .with_labels(drawing.landmarks.iter().map(|(id, _)| format!("L{id}"))),
        )
    }
}

impl Recorder for RerunRecorder {
    fn station(
        &mut self,
        record: &StationRecord,
        panorama: &image::RgbImage,
    ) -> Result<(), RecordingError> {
        self.log_station(record, panorama)
            .map_err(|e| self.error(e))
    }

    fn rng(&mut self, index: usize, drawing: &RngDrawing) -> Result<(), RecordingError> {
        self.log_rng(index, drawing).map_err(|e| self.error(e))
    }

    fn finish(self: Box<Self>) -> Result<Temporary, RecordingError> {
        self.stream.flush_blocking().map_err(|e| self.error(e))?;
        let RerunRecorder { stream, temporary } = *self;
        // Writes the footer and closes the file; dropping the stream then joins its threads.
        stream.finalize_deferred_sinks();
        drop(stream);
        Ok(temporary)
    }
}

/// `L7` (matched), `new L12`, `held` (several candidates), `unused`.
fn association_label(association: &Association) -> String {
    match association {
        Association::Matched { landmark } => format!("L{landmark}"),
        Association::New { landmark } => format!("new L{landmark}"),
        Association::HeldBack { .. } => "held".to_string(),
        Association::Unused { .. } => "unused".to_string(),
    }
}

fn association_colour(association: &Association) -> rerun::Color {
    match association {
        Association::Matched { .. } => rerun::Color::from_rgb(40, 200, 40),
        Association::New { .. } => rerun::Color::from_rgb(40, 140, 255),
        Association::HeldBack { .. } => rerun::Color::from_rgb(255, 170, 0),
        Association::Unused { .. } => rerun::Color::from_rgb(150, 150, 150),
    }
}

/// Green for a certain edge (cost 0) through to red for the least certain (cost 1).
fn cost_colour(cost: f64) -> rerun::Color {
    let t = cost.clamp(0.0, 1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
    rerun::Color::from_rgb(mix(40.0, 230.0), mix(200.0, 30.0), mix(40.0, 30.0))
}
