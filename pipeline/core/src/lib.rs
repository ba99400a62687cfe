//! qrm-core: qualitative relational mapping (McClelland, Campbell, Estlin; `000` in
//! `../shared/seeds/`) without images: the EDC and FDC calculi, the feasibility engine, the
//! measurement of landmark triples from bearings and a partial range order, the path-consistent
//! map, its Relative Neighborhood Graph, metrics and simulated mapping.
//!
//! The layers and their papers are described in `docs/ARCHITECTURE.md`.

pub mod calculus;
pub mod edc;
pub mod fdc;
pub mod feasibility;
pub mod geometry;
pub mod map;
pub mod measurement;
pub mod metrics;
pub mod neighborhood;
pub mod simulation;
