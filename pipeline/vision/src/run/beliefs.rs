//! 002's probabilistic map from a run's panoramas (`pipeline run --mode probabilistic`): the
//! beliefs of `qrm_core::probabilistic::map` over every triple fused together at two or more
//! stations, beside the map of sets.
//!
//! 002 needs a motion command between two views, which a rover mapping without odometry does
//! not have. It is taken from the stereo placements instead: the rigid motion that brings
//! the landmarks two stations placed onto each other ([`displacement`]) gives the heading of
//! the later station from the earlier one, with an s.d. from the placements' radii. Stations
//! between which no such motion is found are not chained.

use super::mapper::Sighted;
use crate::association::displacement;
use qrm_core::map::LandmarkId;
use qrm_core::probabilistic::map::{beliefs, BeliefMap, Estimator, Heading};
use std::collections::BTreeMap;

/// The bearing s.d. the estimators assume: the median of the fused bearings' bounds, read as
/// uniform errors (s.d. = bound / √3), floored at 0.05°.
pub fn bearing_sd(sighted: &[Sighted]) -> f64 {
    let mut bounds: Vec<f64> = sighted
        .iter()
        .flat_map(|s| s.bearings.values().map(|b| b.uncertainty))
        .collect();
    bounds.sort_by(f64::total_cmp);
    let median = bounds.get(bounds.len() / 2).copied().unwrap_or(0.0);
    (median / 3f64.sqrt()).max(0.05f64.to_radians())
}

/// The beliefs of every triple fused together at two or more of the `sighted` stations,
/// bearings of s.d. `bearing_sd` ([`bearing_sd`]).
pub fn run_beliefs(
    sighted: &[Sighted],
    bearing_sd: f64,
    estimator: &Estimator,
    seed: u64,
) -> BeliefMap {
    let stations: Vec<BTreeMap<LandmarkId, f64>> = sighted
        .iter()
        .map(|s| s.bearings.iter().map(|(&l, b)| (l, b.angle)).collect())
        .collect();
    beliefs(
        &stations,
        &|from, to, _| {
            displacement(&sighted[from].frame, &sighted[to].frame)
                .map(|(angle, sd)| Heading { angle, sd })
        },
        bearing_sd,
        estimator,
        seed,
    )
}
