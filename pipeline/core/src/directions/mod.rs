//! Route directions a person or rover can follow (004 Park & Kender; seed digest B): isolation
//! descriptors read from the map's EDC relations, the directed graph of legs ("of the `n − 1`
//! landmarks nearest to you, head for the most isolated"), leg reliability refitted for the
//! rover by simulation, routes by distance, reliability or their compromise, and the custom map
//! with verification and recovery items.

pub mod calibration;
pub mod criteria;
pub mod custom_map;
pub mod instructions;
pub mod isolation;
pub mod legs;
pub mod reliability;
pub mod sampling;

pub use criteria::{Criterion, Path, Routes};
pub use custom_map::CustomMap;
pub use instructions::{custom_map, rng_degrees, steps, Step};
pub use isolation::{Bounds, MapNearness, Nearness, Positions, SceneRanks};
pub use legs::{Descriptor, Leg, LegGraph};
pub use reliability::{ReliabilityModel, ViewNoise};
pub use sampling::{sampled_legs, SampledLegs};
