//! Probabilistic qualitative mapping (002 Mor & Indelman; seed digest C): a probability over
//! the 20 EDC states of a triple instead of a set of possible ones, probabilistic composition
//! with the offline tensor of 002 §III-E, and the metrics of 002 §IV.

mod belief;
pub mod map;
mod metrics;
pub mod study;
mod tensor;
mod triplet;

pub use belief::{Belief, STATES};
pub use metrics::{dmse, entropy, gmd, gt_rating, Rating};
pub use tensor::{CompositionTensor, RegionCentroids, TableError};
pub use triplet::{estimate_baseline, estimate_fast, estimate_full, Estimate, Noise, Prior, View};
