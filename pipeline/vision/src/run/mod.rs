//! `pipeline run`: panoramas in, a qualitative map and its RNG out (000 §IV, §VI-C).

pub mod front_end;
mod mapper;
mod record;
mod summary;

pub use mapper::{LandmarkRecord, Mapper, StationDetections};
pub use summary::RunSummary;

pub use record::{
    Association, DetectionRecord, FusionRecord, MetricsRecord, RangeRecord, StageSeconds,
    StationRecord,
};
