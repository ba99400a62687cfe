//! Which of a station's detections mapping uses, and what each one tells association: the
//! selection policy of `pipeline run`, in one place.

use super::mapper::StationDetections;
use super::record::Exclusion;
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

/// The indices of the detections mapping can use: those [`exclusion`] keeps.
pub(crate) fn usable(station: &StationDetections, ranged: &[Ranged], width: u32) -> Vec<usize> {
    (0..ranged.len())
        .filter(|&i| exclusion(station, ranged, i, width).is_none())
        .collect()
}

/// Why mapping leaves detection `i` out, if it does: slivers, stacks, and detections whose
/// bearing is too uncertain to measure with. Pieces touching another are used, with their
/// bearings and ranges widened over the neighbour ([`Ranged::piece`]), and so are doubted
/// detections (on marsyard seed 7, 98.9 % of their bearing intervals held the truth, against
/// 99.9 % of those used before); neither founds a landmark, and an observer ([`observes`])
/// steers no registration and anchors only as a far rock does
/// (`association::Evidence::doubtful`). The farther part of a blob separated by parallax is
/// used though the detector doubts it: the nearer part may hide some of it, which its bearing
/// (over the nearer part's columns, as a piece's) and its range (its own pixels' shifts,
/// taking in the rock's reach) allow for. On marsyard seed 7, eval's stereo cue intervals went
/// from 587 to 1 023 (the separated parts'), all holding the truth, 99.9 % of the used
/// bearings held it as before, and the fused share of correct detections rose from 55.2 % to
/// 63.4 %.
pub(super) fn exclusion(
    station: &StationDetections,
    ranged: &[Ranged],
    i: usize,
    width: u32,
) -> Option<Exclusion> {
    let d = &station.primary[i];
    if d.bbox[2] + 1 < d.bbox[0] + MIN_COLUMNS.max(width / 512) {
        Some(Exclusion::Sliver)
    } else if stacked(d) {
        Some(Exclusion::Stacked)
    } else if ranged[i].bearing.uncertainty >= MAX_BEARING_UNCERTAINTY {
        Some(Exclusion::WideBearing)
    } else {
        None
    }
}

/// The detections [`usable`] for mapping less the observers ([`observes`]): what localization
/// associates. A mapping station's observers only add sightings where registrations agree
/// across stations; a panorama localized on its own leans on every pair it makes (marsyard
/// seed 7's 40-trip drive, trip 0, on the same map: arrived in 20 steps without the doubted
/// detections, lost after 45 with them).
pub(crate) fn usable_firm(
    station: &StationDetections,
    ranged: &[Ranged],
    width: u32,
) -> Vec<usize> {
    usable(station, ranged, width)
        .into_iter()
        .filter(|&i| !observes(station, ranged, i))
        .collect()
}

/// Whether detection `i` only observes: it is paired under the motion the others' registration
/// fits, never steers the fit, and anchors only as a far rock does
/// (`association::Evidence::doubtful`). Every detection the detector doubts ([`doubted`])
/// observes, and by luminance also a piece touching another: there a blob's sides are
/// where the stereo test's window says the ground ends, columns off the rock's, so its
/// placement is looser than its interval says (stop 34 let such pieces steer registrations,
/// and stress seeds 6, 8 and 10 lost up to 43 points of removed states). Left out of mapping
/// instead, they were 53 % of JPEG marsyard seed 7's correct detections (30 % touching, 23 %
/// doubted), and their intervals were nearly as honest as the used ones': 97.7 % and 97.0 %
/// of their bearing intervals held the truth (98.8 % of the used ones'), 99.7 % and 95.5 % of
/// their fused range intervals (99.7 %). A luminance piece steers where its range is
/// corroborated ([`corroborated`]): its placement then no longer rests on where the stereo
/// window put the blob's sides (stop 59: JPEG marsyard seed 11 22.0 → 45.6 % fused, no unsound
/// relation added on 16 sets, docs/RUN.md).
fn observes(station: &StationDetections, ranged: &[Ranged], i: usize) -> bool {
    doubted(&station.primary[i])
        || (station.channels == Channels::Luminance && ranged[i].piece && !corroborated(&ranged[i]))
}

/// Whether both independent range cues, the ground contact and stereo, bound the detection
/// and agree.
fn corroborated(r: &Ranged) -> bool {
    matches!((r.ground, r.stereo), (Some(g), Some(s)) if g.intersection(s).is_some())
}

/// Whether the detector doubts the detection is one whole rock (a piece cut at a shallow
/// notch, or beside a nearer piece that may hide some of it; by luminance also a top without
/// its body). The farther part of a blob separated by parallax is flagged too, but its bearing
/// and range already allow for what the nearer part may hide.
pub(super) fn doubted(d: &Detection) -> bool {
    d.ambiguous && d.separation != Separation::Farther
}

fn stacked(d: &Detection) -> bool {
    let width = f64::from(d.bbox[2] - d.bbox[0] + 1);
    let height = f64::from(d.bbox[3] - d.bbox[1] + 1);
    height > MAX_ASPECT * width
}

/// The station as association sees it: the view of the `usable` detections, and the
/// evidence of each.
pub(crate) fn station_evidence(
    station: &StationDetections,
    ranged: &[Ranged],
    usable: &[usize],
    model: &SensorModel,
) -> StationEvidence {
    let unused: Vec<&Ranged> = (0..ranged.len())
        .filter(|i| !usable.contains(i))
        .map(|i| &ranged[i])
        .collect();
    StationEvidence {
        view: view_of(ranged, usable),
        detections: usable
            .iter()
            .map(|&i| Evidence {
                appearance: station.primary[i].appearance.clone(),
                width: width_of(&station.primary[i], &ranged[i], model),
                placed: placed(&ranged[i]),
                ray: ranged[i].ray,
                piece: ranged[i].piece,
                doubtful: observes(station, ranged, i),
                flat: station.primary[i].flat,
                surely_flat: station.primary[i].surely_flat,
                pixels: station.primary[i].pixels,
            })
            .collect(),
        colour: station.channels == Channels::Colour,
        unused: unused.iter().map(|r| r.ray).collect(),
        unused_placed: unused.iter().filter_map(|r| placed(r)).collect(),
    }
}

/// The physical width a detection implies for its rock (`ranging::width_evidence`), unless it
/// is a part of a blob separated by parallax, a piece touching another, or doubted: a false
/// cut of one large rock (its sides read farther than its middle) leaves a part narrower than
/// the rock, which would bound the landmark's width too low and put the size cue's ranges too
/// far.
fn width_of(d: &Detection, ranged: &Ranged, model: &SensorModel) -> Option<RangeInterval> {
    (d.separation == Separation::Whole && !ranged.piece && !doubted(d))
        .then(|| ranging::width_evidence(ranged, model))
        .flatten()
}

/// A detection's rough position around the station, if its range is bounded well enough to
/// place it: the middle of its range interval along its bearing.
fn placed(r: &Ranged) -> Option<Placed> {
    placement(r.bearing.angle, r.bearing.uncertainty, r.fused.as_array())
}

/// The rough position of a rock at `bearing` (± `uncertainty`) and range in `[low, high]`
/// metres: the middle of the interval along the bearing, in an ellipse reaching over the
/// interval along the bearing and over the bearing error at the far end across it; none when
/// the range is unbounded or wider than its middle.
pub(crate) fn placement(bearing: f64, uncertainty: f64, [low, high]: [f64; 2]) -> Option<Placed> {
    let middle = 0.5 * (low + high);
    (high.is_finite() && high - low < middle).then(|| {
        Placed::along(
            [middle * bearing.cos(), middle * bearing.sin()],
            bearing,
            0.5 * (high - low),
            high * uncertainty,
        )
    })
}

/// The view of the detections at `usable`: bearings, the range order among them, and the
/// range intervals that bound their ratios ([`ranging::ratio_bounds`]).
pub(super) fn view_of(ranged: &[Ranged], usable: &[usize]) -> StationView {
    let chosen: Vec<Ranged> = usable.iter().map(|&i| ranged[i]).collect();
    let bearings: Vec<Bearing> = chosen.iter().map(|r| r.bearing).collect();
    let order: RangeOrder = ranging::range_order(&chosen);
    let ranges = chosen.iter().map(ranging::ratio_bounds).collect();
    StationView::new(bearings, order)
        .and_then(|view| view.with_ranges(ranges))
        .expect("bearings are finite, in range, with uncertainty below the limit; the order is the intervals'")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detection::Appearance;
    use crate::ranging::{PrimaryEye, Ray};

    fn detection(bbox: [u32; 4], ambiguous: bool, separation: Separation) -> Detection {
        Detection {
            centroid: [
                f64::from(bbox[0] + bbox[2]) / 2.0,
                f64::from(bbox[1] + bbox[3]) / 2.0,
            ],
            bbox,
            pixels: 100,
            contact_row: f64::from(bbox[3] + 1),
            contact_slack_rows: 0.0,
            appearance: Appearance {
                colour: [0.4, 0.33, 0.27],
                brightness: 0.8,
                texture: 0.1,
                dark_fraction: 0.2,
            },
            ambiguous,
            separation,
            blob: 0,
            beyond_columns: [0, 0],
            parallax_shifts: None,
            flat: false,
            surely_flat: false,
        }
    }

    fn ranged(uncertainty: f64) -> Ranged {
        Ranged {
            bearing: Bearing {
                angle: 1.0,
                uncertainty,
            },
            ray: Ray {
                azimuth: 1.0,
                half_baseline: 0.0,
                nearest: 0.0,
            },
            stereo_column: None,
            angular_width: 0.01,
            ground: None,
            stereo: None,
            size: None,
            fused: RangeInterval::new(4.0, 5.0),
            conflict: false,
            piece: false,
        }
    }

    /// Each detection left out says why, and only those left out are not usable: pieces
    /// touching each other, doubted detections and the farther part of a blob separated by
    /// parallax are used in both modes. Doubted detections observe in both, pieces by
    /// luminance only; localization leaves the observers out.
    #[test]
    fn every_left_out_detection_has_its_reason() {
        let primary = vec![
            detection([100, 50, 130, 70], false, Separation::Whole),
            detection([300, 50, 330, 70], true, Separation::Farther),
            detection([500, 50, 530, 70], true, Separation::Whole),
            detection([700, 50, 701, 70], false, Separation::Whole),
            detection([900, 10, 910, 70], false, Separation::Whole),
            detection([1100, 50, 1130, 70], false, Separation::Whole),
            detection([1131, 55, 1160, 75], false, Separation::Whole),
            detection([1300, 50, 1330, 70], false, Separation::Whole),
        ];
        let mut all: Vec<Ranged> = (0..primary.len()).map(|_| ranged(0.01)).collect();
        all[5].piece = true;
        all[6].piece = true;
        all[6].ground = Some(RangeInterval::new(4.0, 5.0));
        all[6].stereo = Some(RangeInterval::new(4.5, 6.0));
        all[7] = ranged(MAX_BEARING_UNCERTAINTY);
        let colour = StationDetections {
            name: "s".into(),
            files: Vec::new(),
            digests: Vec::new(),
            eye: PrimaryEye::Mono,
            channels: Channels::Colour,
            primary,
            right: None,
            warnings: Vec::new(),
        };
        let luminance = StationDetections {
            channels: Channels::Luminance,
            ..colour.clone()
        };
        let model = SensorModel::default();
        for station in [&colour, &luminance] {
            let reasons: Vec<Option<Exclusion>> = (0..all.len())
                .map(|i| exclusion(station, &all, i, 4096))
                .collect();
            assert_eq!(
                reasons,
                [
                    None,
                    None,
                    None,
                    Some(Exclusion::Sliver),
                    Some(Exclusion::Stacked),
                    None,
                    None,
                    Some(Exclusion::WideBearing),
                ]
            );
            assert_eq!(usable(station, &all, 4096), [0, 1, 2, 5, 6]);
        }
        // The detector's doubt goes to association: the doubted detection observes, founds no
        // landmark and anchors only as a far rock does; by luminance so do the pieces whose
        // range the ground and stereo do not both bound.
        let observers = |station: &StationDetections, all: &[Ranged]| -> Vec<bool> {
            station_evidence(station, all, &[0, 1, 2, 5, 6], &model)
                .detections
                .iter()
                .map(|e| e.doubtful)
                .collect()
        };
        assert_eq!(observers(&colour, &all), [false, false, true, false, false]);
        assert_eq!(
            observers(&luminance, &all),
            [false, false, true, true, false]
        );
        all[6].stereo = Some(RangeInterval::new(5.5, 6.0));
        assert_eq!(
            observers(&luminance, &all),
            [false, false, true, true, true],
            "cues that disagree corroborate nothing"
        );
        // Localization leaves the observers out.
        assert_eq!(usable_firm(&colour, &all, 4096), [0, 1, 5, 6]);
        assert_eq!(usable_firm(&luminance, &all, 4096), [0, 1]);
    }
}
