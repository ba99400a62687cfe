//! `pipeline run`: panoramas in, a qualitative map and its RNG out (000 §IV, §VI-C).

mod record;

pub use record::{
    Association, DetectionRecord, FusionRecord, MetricsRecord, RangeRecord, StageSeconds,
    StationRecord,
};
