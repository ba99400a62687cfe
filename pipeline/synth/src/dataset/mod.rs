//! Synthetic datasets with ground truth (issue 4; format in `datasets/README.md`): scene
//! layouts (`Preset`), rendering them with the renderer ([`crate::render`]) into a directory of panoramas, and
//! the `truth.json` that only evaluation reads.

mod layout;
mod truth;
mod writer;

pub use layout::{Counts, Layout, Preset};
pub use truth::{
    visible_rocks, ImageTruth, LumpTruth, RockTruth, StationTruth, Truth, VisibleRock,
};
pub use writer::{write_dataset, DatasetError, Request};
