//! qrm-synth: synthetic rover panoramas with ground truth, and scoring against that truth.
//!
//! The renderer (issue 4) draws a procedural Mars plain with partly buried, irregular rocks by
//! ray casting through the cylindrical camera of [`qrm_vision::calib`]; [`dataset`] lays out
//! scenes and writes directories of panoramas with `truth.json`; [`evaluation`] and
//! [`detection_score`] score detections and runs against that truth.
//!
//! The renderer is the ground truth's other half: every pixel's ray is built from the same
//! calibration the pipeline inverts, so tests can tie rendered pixels back to rock positions.
//! Output depends only on the world, the calibration, the pose and the eye: no clocks, no
//! hash-map order, no thread-dependent reductions (rows are rendered in parallel, but each
//! pixel depends only on its coordinates).

pub mod closed_loop;
pub mod dataset;
pub mod directions_trial;
pub mod evaluation;
pub mod reference_path;

mod capture;
mod clearance_grid;
mod ellipsoid;
mod hazard_avoidance;
mod image_file;
mod noise;
mod render;
mod scene;
mod scenery;
mod shade;
mod shadow;
mod world;

pub use capture::Capture;
pub use image_file::Encoding;
pub use render::{optical_centre, render, viewing_azimuth, Eye, Pose, Render};
pub use scenery::Scenery;
pub use world::{Lump, Rock, World};

use qrm_vision::calib::Calibration;

/// The calibration of the synthetic datasets (`calib/default.toml`: 4096 × 768 stereo).
pub fn default_calibration() -> Calibration {
    Calibration::parse(
        include_str!("../../../calib/default.toml"),
        "calib/default.toml",
    )
    .expect("the committed default calibration is valid")
}
