//! Synthetic datasets with ground truth (issue 4; format in `datasets/README.md`): scene
//! layouts (`Preset`), rendering them with the renderer ([`crate::render`]) into a directory of panoramas, and
//! the `truth.json` that only evaluation reads.

mod layout;
mod truth;
mod variant;
mod writer;

pub use layout::{Counts, Layout, Preset};
pub use truth::{
    visible_rocks, ImageTruth, LumpTruth, RockTruth, StationTruth, Truth, VariantTruth,
    VisibleRock, FORMAT as TRUTH_FORMAT, VERSION as TRUTH_VERSION,
};
pub use variant::Variant;
pub use writer::{write_dataset, DatasetError, Request};
