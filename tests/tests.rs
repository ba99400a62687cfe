//! qrm checked against independent references: the paper's tables, sampled geometry,
//! brute-force enumeration, rendered ground truth. One test binary, a module per subject;
//! shared helpers in the `qrm_tests` library (`support.rs`).

mod dataset;
mod detection;
mod edc_composition;
mod edc_unary;
mod fdc_tables;
mod feasibility;
mod map;
mod measurement;
mod probabilistic_tables;
mod simulation;
mod synth;
