//! Recordings of a run, station by station: `run.mcap` (JSON messages for Foxglove, the `mcap`
//! CLI or any MCAP reader) and, with the `rerun` feature, `run.rrd` for the rerun viewer. The
//! channels and their contents are documented in `docs/RUN_OUTPUTS.md`. Closed-loop drives
//! log every step to `drive.mcap` (`navigation_log`) and, with the feature, `drive.rrd`
//! (`navigation_rerun`; docs/NAVIGATION.md).
//!
//! Both are written through [`qrm_atomic_file::Temporary`]: the target appears only when
//! [`Recorder::finish`] succeeds, so a crashed run never leaves a truncated recording.

mod mcap_recorder;
pub mod navigation_log;
#[cfg(feature = "rerun")]
pub mod navigation_rerun;
#[cfg(feature = "rerun")]
mod rerun_recorder;
#[cfg(test)]
mod tests;

use qrm_atomic_file::Temporary;
use std::path::PathBuf;

use qrm_vision::run::StationRecord;

pub use mcap_recorder::McapRecorder;
#[cfg(feature = "rerun")]
pub use rerun_recorder::RerunRecorder;

/// What `pipeline run` feeds each output as the stations go by.
pub trait Recorder {
    /// Whether [`Recorder::station`] uses the panorama (the run decodes it again only then).
    fn wants_panorama(&self) -> bool {
        true
    }
    /// After each station: its record and its primary panorama (left or mono image; an empty
    /// image for a recorder that does not want it).
    fn station(
        &mut self,
        record: &StationRecord,
        panorama: &image::RgbImage,
    ) -> Result<(), RecordingError>;
    /// After each station: the current RNG estimate drawn over a 2-D layout of the landmarks.
    fn rng(&mut self, index: usize, drawing: &RngDrawing) -> Result<(), RecordingError>;
    /// Completes the file, still under its temporary name: the run moves it into place with
    /// its other outputs (`OutputSet::adopt`). A recorder dropped without finish, or a
    /// temporary dropped uncommitted, leaves nothing behind.
    fn finish(self: Box<Self>) -> Result<Temporary, RecordingError>;
}

/// The RNG estimate as drawn: the map has no metric positions, so the run supplies a layout.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RngDrawing {
    /// Landmark id and its `[x, y]` in the layout.
    pub landmarks: Vec<(u32, [f64; 2])>,
    /// Edges between landmark ids with their cost in `[0, 1]`, 0 = certain.
    pub edges: Vec<(u32, u32, f64)>,
}

/// A recording could not be written: which file, and why.
#[derive(Debug, thiserror::Error)]
#[error("recording {}: {problem}", path.display())]
pub struct RecordingError {
    /// The recording's target path (not its temporary file).
    pub path: PathBuf,
    pub problem: Problem,
}

/// Why a recording failed.
#[derive(Debug, thiserror::Error)]
pub enum Problem {
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error("MCAP: {0}")]
    Mcap(#[from] ::mcap::McapError),
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// The rerun SDK's errors have several types; their messages are what matters here.
    #[cfg(feature = "rerun")]
    #[error("rerun: {0}")]
    Rerun(String),
}
