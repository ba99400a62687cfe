//! Measuring qualitative states from one panorama (000 §IV): bearings of the visible landmarks
//! and a range ordering give, for every triple, the relations consistent with the observation.
//!
//! Beyond the paper, for real sensors: the range order may be partial ([`RangeOrder`]), and each
//! bearing may carry an uncertainty interval. Every result is sound: an arrangement whose
//! bearings lie within their intervals and whose ranges respect the order is never excluded
//! (`docs/MEASUREMENT.md` states the numerical limits).

mod interval;
mod range_order;
mod range_ratios;
mod sweep;
mod triple;

pub use interval::by_intervals;
pub use range_order::{RangeOrder, RangeOrderError};
pub use range_ratios::{RangeBounds, RangeRatios};
pub use sweep::sweep_regions;
pub use triple::{by_search, by_sweep, measure_triple_edc, TripleRelations};

use crate::calculus::{Calculus, RelationSet};
use crate::edc::REGIONS;
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_4;
use thiserror::Error;

/// Largest accepted half-width of a bearing interval: far beyond any camera's error, and wide
/// intervals make the interval enclosures (and the search formulation's `|t| ≤ s·tan δ`)
/// useless long before the sectors reach a half plane.
pub const MAX_BEARING_UNCERTAINTY: f64 = FRAC_PI_4;

/// Largest accepted |bearing| in radians: angles are taken modulo 2π, but a huge angle has lost
/// its fractional turn to rounding and means nothing.
pub const MAX_BEARING_MAGNITUDE: f64 = 1e6;

/// The direction to a landmark in the camera frame (radians, counter-clockwise; any zero),
/// known to within `± uncertainty`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bearing {
    pub angle: f64,
    pub uncertainty: f64,
}

impl Bearing {
    pub fn exact(angle: f64) -> Bearing {
        Bearing {
            angle,
            uncertainty: 0.0,
        }
    }
}

/// How far apart two directions are, radians in `[0, π]` (whichever way round is shorter).
pub fn angular_distance(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

/// What one station sees of the landmarks in its panorama: bearings (000 §IV assumption 1) and
/// the range ordering (assumption 2), indexed by position in `bearings`. Not the image: the
/// vision crate turns images into views.
#[derive(Clone, Debug, PartialEq)]
pub struct StationView {
    pub bearings: Vec<Bearing>,
    pub order: RangeOrder,
    /// Each landmark's range interval, where ranging bounds it beyond the order
    /// ([`StationView::with_ranges`]; unbounded otherwise).
    pub ranges: Vec<RangeBounds>,
}

/// An observation that cannot be measured.
#[derive(Debug, Error, PartialEq)]
pub enum MeasurementError {
    #[error("bearing of landmark {index} is not a finite angle ({angle})")]
    BearingNotFinite { index: usize, angle: f64 },
    #[error("bearing of landmark {index} is {angle} rad; give angles within ±{max} rad")]
    BearingOutOfRange { index: usize, angle: f64, max: f64 },
    #[error(
        "bearing uncertainty of landmark {index} is {value} rad; it must lie in [0, {max}) rad"
    )]
    BadUncertainty { index: usize, value: f64, max: f64 },
    #[error("the range order covers {order} landmarks but the panorama has {bearings} bearings")]
    OrderSize { order: usize, bearings: usize },
    #[error("{ranges} range intervals given for a panorama of {bearings} bearings")]
    RangesSize { ranges: usize, bearings: usize },
    #[error(
        "range interval of landmark {index} is [{low}, {high}]; it must satisfy 0 ≤ low ≤ high"
    )]
    BadRange { index: usize, low: f64, high: f64 },
    #[error("landmark {nearer} is ordered nearer than landmark {farther}, but their range intervals say it is farther")]
    RangesContradictOrder { nearer: usize, farther: usize },
}

impl StationView {
    pub fn new(bearings: Vec<Bearing>, order: RangeOrder) -> Result<StationView, MeasurementError> {
        for (index, b) in bearings.iter().enumerate() {
            if !b.angle.is_finite() {
                return Err(MeasurementError::BearingNotFinite {
                    index,
                    angle: b.angle,
                });
            }
            if b.angle.abs() > MAX_BEARING_MAGNITUDE {
                return Err(MeasurementError::BearingOutOfRange {
                    index,
                    angle: b.angle,
                    max: MAX_BEARING_MAGNITUDE,
                });
            }
            if !(0.0..MAX_BEARING_UNCERTAINTY).contains(&b.uncertainty) {
                return Err(MeasurementError::BadUncertainty {
                    index,
                    value: b.uncertainty,
                    max: MAX_BEARING_UNCERTAINTY,
                });
            }
        }
        if order.len() != bearings.len() {
            return Err(MeasurementError::OrderSize {
                order: order.len(),
                bearings: bearings.len(),
            });
        }
        let ranges = vec![RangeBounds::UNBOUNDED; bearings.len()];
        Ok(StationView {
            bearings,
            order,
            ranges,
        })
    }

    /// The view with each landmark's range in an interval (`ranges[i]` for position `i`; any
    /// unit, only ratios are used): measured triples then also keep the ratios the intervals
    /// allow. The intervals must hold the order: a landmark ordered nearer than another cannot
    /// have its interval entirely beyond the other's.
    pub fn with_ranges(self, ranges: Vec<RangeBounds>) -> Result<StationView, MeasurementError> {
        if ranges.len() != self.bearings.len() {
            return Err(MeasurementError::RangesSize {
                ranges: ranges.len(),
                bearings: self.bearings.len(),
            });
        }
        for (index, r) in ranges.iter().enumerate() {
            if !(r.low >= 0.0 && r.low.is_finite() && r.high >= r.low) {
                return Err(MeasurementError::BadRange {
                    index,
                    low: r.low,
                    high: r.high,
                });
            }
        }
        for nearer in 0..ranges.len() {
            for farther in 0..ranges.len() {
                if self.order.is_nearer(nearer, farther)
                    && ranges[nearer].low >= ranges[farther].high
                {
                    return Err(MeasurementError::RangesContradictOrder { nearer, farther });
                }
            }
        }
        Ok(StationView { ranges, ..self })
    }

    pub fn len(&self) -> usize {
        self.bearings.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bearings.is_empty()
    }

    /// The relations `AB:C`, `BC:A`, `CA:B` of calculus `C` for landmarks `[a, b, c]` of this
    /// panorama, restricted to `open` (e.g. what the map still allows).
    pub fn measure_triple<C: Calculus>(
        &self,
        landmarks: [usize; 3],
        open: TripleRelations,
    ) -> TripleRelations {
        let bearings = landmarks.map(|i| self.bearings[i]);
        let ranges = landmarks.map(|i| self.ranges[i]);
        let nearer = self.order.restricted(&landmarks);
        match measure_triple_edc(bearings, &nearer, ranges, open.map(edc_candidates::<C>)) {
            Some(regions) => std::array::from_fn(|k| C::from_edc(regions[k]).intersection(open[k])),
            None => open,
        }
    }

    /// Every triple `i < j < k` of the panorama, measured in parallel; `open` gives the
    /// relations still possible for a triple (all of the calculus' universe for a fresh map).
    pub fn measure_all<C, F>(&self, open: F) -> Vec<TripleMeasurement>
    where
        C: Calculus,
        F: Fn([usize; 3]) -> TripleRelations + Sync,
    {
        let n = self.len();
        let triples: Vec<[usize; 3]> = (0..n)
            .flat_map(|i| (i + 1..n).flat_map(move |j| (j + 1..n).map(move |k| [i, j, k])))
            .collect();
        triples
            .into_par_iter()
            .map(|landmarks| TripleMeasurement {
                landmarks,
                states: self.measure_triple::<C>(landmarks, open(landmarks)),
            })
            .collect()
    }
}

/// The measured relations of one triple of a panorama's landmarks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TripleMeasurement {
    /// Positions `[a, b, c]` in the panorama.
    pub landmarks: [usize; 3],
    /// `[AB:C, BC:A, CA:B]`.
    pub states: [RelationSet; 3],
}

/// The EDC regions a measurement must test when the relations `open` of calculus `C` are still
/// possible: those from which some open relation can follow (000 §IV measures EDC regions, the
/// finest cells of both calculi). Here rather than on `Calculus` so that the calculus layer
/// does not depend on the EDC calculus built on it.
fn edc_candidates<C: Calculus>(open: RelationSet) -> RelationSet {
    RelationSet::from_relations((1..=REGIONS).filter(|&r| {
        !C::from_edc(RelationSet::single(r))
            .intersection(open)
            .is_empty()
    }))
}

#[cfg(test)]
mod tests {
    use super::angular_distance;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn angular_distance_takes_the_shorter_way_round() {
        assert!((angular_distance(0.1, TAU - 0.1) - 0.2).abs() < 1e-12);
        assert!((angular_distance(TAU - 0.1, 0.1) - 0.2).abs() < 1e-12);
        assert!((angular_distance(-3.0 * PI, 0.0) - PI).abs() < 1e-12);
        assert_eq!(angular_distance(1.0, 1.0 + TAU), 0.0);
    }
}
