//! Offline generation of the operator tables committed under `tables/` (000 §III). The library
//! never runs this at start-up; `tools/gen-tables` does, and the tests check that regenerating
//! reproduces the committed files.

mod edc_tables;
mod fdc_tables;
mod probabilistic_tables;

pub use edc_tables::{
    edc_composition, edc_composition_cell, edc_unary, CompositionReport, EDC_SEARCH_HALF_WIDTH,
};
pub use fdc_tables::{fdc_composition, fdc_unary};
pub use probabilistic_tables::{probabilistic_composition, region_centroids, SAMPLES_PER_REGION};
