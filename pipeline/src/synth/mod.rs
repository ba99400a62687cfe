//! Synthetic rover panoramas (issue 4): a procedural Mars plain with partly buried, irregular
//! rocks, rendered by ray casting through the cylindrical camera of [`crate::calib`].
//!
//! The renderer is the ground truth's other half: every pixel's ray is built from the same
//! calibration the pipeline inverts, so tests can tie rendered pixels back to rock positions.
//! Output depends only on the world, the calibration, the pose and the eye: no clocks, no
//! hash-map order, no thread-dependent reductions (rows are rendered in parallel, but each
//! pixel depends only on its coordinates).

mod ellipsoid;
mod image_file;
mod noise;
mod render;
mod scene;
mod shade;
mod shadow;
mod world;

pub use render::{optical_centre, render, Eye, Pose, Render};
pub use world::{Lump, Rock, World};
