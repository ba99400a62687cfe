//! `pipeline run`: panoramas in, a qualitative map and its RNG out (000 §IV, §VI-C):
//! [`traverse_survey`] with a [`Mapper`].

pub mod beliefs;
pub mod front_end;
mod mapper;
mod record;
pub(crate) mod selection;
mod summary;
mod traverse;

pub use mapper::{LandmarkRecord, Mapper, Sighted, StationDetections};
pub use summary::{BeliefsSummary, RunSummary};
pub use traverse::{traverse_survey, Progress, Quiet, RunError, RunSettings, Stage, Traverse};

pub use record::{
    Association, DetectionRecord, Exclusion, FusionRecord, LateSighting, MetricsRecord,
    RangeRecord, RegistrationRecord, StageSeconds, StationRecord,
};
