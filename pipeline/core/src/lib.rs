//! qrm-core: qualitative relational mapping (McClelland, Campbell, Estlin; `000` in
//! `../shared/seeds/`) without images: the EDC and FDC calculi, the feasibility engine, the
//! measurement of landmark triples from bearings and a partial range order, the path-consistent
//! map, its Relative Neighborhood Graph, metrics and simulated mapping.
//!
//! The layers and their papers are described in `docs/ARCHITECTURE.md`.
//!
//! # A map from three panoramas
//!
//! A rover at three stations sees four rocks; each panorama gives only the bearing of each rock
//! and which rocks are nearer (000 §IV). Every triple is measured and fused into the map
//! (000 §VI), which then holds the true arrangement of every triple and excludes others.
//!
//! ```
//! use qrm_core::calculus::Calculus;
//! use qrm_core::edc::Edc;
//! use qrm_core::geometry::Point;
//! use qrm_core::map::{Hypergraph, Sighting};
//! use qrm_core::measurement::{Bearing, StationView, RangeOrder};
//!
//! let rocks: [(f64, f64); 4] = [(0.0, 0.0), (4.0, 1.0), (1.5, 5.0), (-2.0, 3.0)];
//! let stations: [(f64, f64); 3] = [(1.0, -3.0), (6.0, 4.0), (-3.0, 7.0)];
//! let mut map = Hypergraph::<Edc>::new();
//! for (x, y) in stations {
//!     // What the camera measures: bearings, and the order of the ranges (nearest first).
//!     let polar: Vec<(f64, f64)> = rocks
//!         .iter()
//!         .map(|&(rx, ry)| ((ry - y).atan2(rx - x), (rx - x).hypot(ry - y)))
//!         .collect();
//!     let mut nearest_first: Vec<usize> = (0..rocks.len()).collect();
//!     nearest_first.sort_by(|&a, &b| polar[a].1.total_cmp(&polar[b].1));
//!     let bearings = polar
//!         .iter()
//!         .map(|p| Bearing::exact(p.0.rem_euclid(std::f64::consts::TAU)))
//!         .collect();
//!     let panorama = StationView::new(bearings, RangeOrder::total(&nearest_first)?)?;
//!     // Rock i is landmark i: association is the vision crate's job.
//!     let seen = Sighting::all(&[0, 1, 2, 3]);
//!     map.fuse(&map.observations(&panorama, &seen))?;
//! }
//! let point = |i: usize| Point::new(rocks[i].0, rocks[i].1);
//! let truth = Edc::classify(point(0), point(1), point(2)).unwrap();
//! let possible = map.relation(0, 1, 2).unwrap();
//! assert!(possible.contains(truth));
//! assert!(possible.len() < Edc::universe().len());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod calculus;
pub mod directions;
pub mod edc;
pub mod fdc;
pub mod feasibility;
pub mod geometry;
pub mod map;
pub mod measurement;
pub mod metrics;
pub mod navigation;
pub mod neighborhood;
pub mod probabilistic;
pub mod simulation;
