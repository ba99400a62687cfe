//! qrm: qualitative relational mapping (McClelland, Campbell, Estlin; `../shared/seeds/000`).
//!
//! Stages live in one module each; see `docs/ARCHITECTURE.md`.

pub mod association;
pub mod atomic_file;
pub mod calculus;
pub mod calib;
pub mod dataset;
pub mod detection;
pub mod edc;
pub mod evaluation;
pub mod fdc;
pub mod feasibility;
pub mod generation;
pub mod geometry;
pub mod map;
pub mod measurement;
pub mod metrics;
pub mod neighborhood;
pub mod plot;
pub mod ranging;
pub mod recording;
pub mod run;
pub mod simulation;
pub mod survey;
pub mod synth;
