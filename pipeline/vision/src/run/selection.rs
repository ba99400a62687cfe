//! Which of a station's detections mapping uses, and what each one tells association: the
//! selection policy of `pipeline run`, in one place.

use super::mapper::StationDetections;
use crate::association::{Evidence, Placed, StationEvidence};
use crate::detection::{Channels, Detection, Separation};
use crate::ranging::{self, RangeInterval, Ranged, SensorModel};
use qrm_core::measurement::{Bearing, RangeOrder, StationView, MAX_BEARING_UNCERTAINTY};

/// Narrowest usable detection, columns (at least a 512th of the view): slivers are mostly
/// pieces of larger rocks, whose centroids say little about where the rock is.
const MIN_COLUMNS: u32 = 3;

/// Tallest height-to-width ratio of a single rock's footprint: rocks are wider than they stand
/// tall (on the marsyard and random presets no visible footprint exceeds 1.44, 99 % stay under
/// 1.15). A taller blob is a farther rock seen over a nearer one, whose contact row (the
/// nearer rock's) and centroid (between the two) belong to neither.
const MAX_ASPECT: f64 = 1.5;

/// The indices of the detections mapping can use. Detections the detector doubts (possibly
/// several rocks, or part of one), slivers, pieces touching another piece, stacks, and those
/// whose bearing is too uncertain to measure with are left out.
pub(super) fn usable(station: &StationDetections, ranged: &[Ranged], width: u32) -> Vec<usize> {
    let narrowest = MIN_COLUMNS.max(width / 512);
    (0..ranged.len())
        .filter(|&i| {
            let d = &station.primary[i];
            !d.ambiguous
                && d.bbox[2] + 1 >= d.bbox[0] + narrowest
                && !stacked(d)
                && !ranging::touches_neighbour(i, &station.primary, width)
                && ranged[i].bearing.uncertainty < MAX_BEARING_UNCERTAINTY
        })
        .collect()
}

fn stacked(d: &Detection) -> bool {
    let width = f64::from(d.bbox[2] - d.bbox[0] + 1);
    let height = f64::from(d.bbox[3] - d.bbox[1] + 1);
    height > MAX_ASPECT * width
}

/// The station as association sees it: the view of the `usable` detections, and the
/// evidence of each.
pub(super) fn station_evidence(
    station: &StationDetections,
    ranged: &[Ranged],
    usable: &[usize],
    model: &SensorModel,
) -> StationEvidence {
    StationEvidence {
        view: view_of(ranged, usable),
        detections: usable
            .iter()
            .map(|&i| Evidence {
                appearance: station.primary[i].appearance.clone(),
                width: width_of(&station.primary[i], &ranged[i], model),
                placed: placed(&ranged[i]),
            })
            .collect(),
        colour: station.channels == Channels::Colour,
        unused_bearings: (0..ranged.len())
            .filter(|i| !usable.contains(i))
            .map(|i| ranged[i].bearing.angle)
            .collect(),
    }
}

/// The physical width a detection implies for its rock (`ranging::width_evidence`), unless it
/// is a part of a blob separated by parallax: a false cut of one large rock (its sides read
/// farther than its middle) leaves a part narrower than the rock, which would bound the
/// landmark's width too low and put the size cue's ranges too far.
fn width_of(d: &Detection, ranged: &Ranged, model: &SensorModel) -> Option<RangeInterval> {
    (d.separation == Separation::Whole)
        .then(|| ranging::width_evidence(ranged, model))
        .flatten()
}

/// A detection's rough position around the station, if its range is bounded well enough to
/// place it: the middle of its range interval along its bearing.
fn placed(r: &Ranged) -> Option<Placed> {
    let [low, high] = r.fused.as_array();
    let middle = 0.5 * (low + high);
    (high.is_finite() && high - low < middle).then(|| Placed {
        point: [
            middle * r.bearing.angle.cos(),
            middle * r.bearing.angle.sin(),
        ],
        radius: 0.5 * (high - low) + high * r.bearing.uncertainty,
    })
}

/// The view of the detections at `usable` (bearings and the range order among them).
pub(super) fn view_of(ranged: &[Ranged], usable: &[usize]) -> StationView {
    let chosen: Vec<Ranged> = usable.iter().map(|&i| ranged[i]).collect();
    let bearings: Vec<Bearing> = chosen.iter().map(|r| r.bearing).collect();
    let order: RangeOrder = ranging::range_order(&chosen);
    StationView::new(bearings, order)
        .expect("bearings are finite, in range, with uncertainty below the limit")
}
