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
    } else if ranged[i].measured_bearing().uncertainty >= MAX_BEARING_UNCERTAINTY {
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

/// Whether the detection's range rests on what measures the rock itself: both cues agreeing,
/// or stereo where no ground cue applies (its contact hidden by a nearer detection or below
/// the image). A ground cue alone may be off by a whole rock: a lit top taken for the rock
/// puts its contact on the rock's own body (`association::Evidence::range_trusted`). So may
/// one that meets the stereo cue only at its far end ([`contact_above_ground`]).
fn range_trusted(r: &Ranged) -> bool {
    (corroborated(r) && !contact_above_ground(r)) || (r.ground.is_none() && r.stereo.is_some())
}

/// Whether the ground cue lies wholly beyond the middle of the stereo cue and reaches past its
/// far end: the two agree only where stereo is least likely, as they do when the detection's
/// bottom is not the rock's contact but a row of its body (stress s49 after stop 82: the
/// upper piece of a rock 12.1 m away, ground 13.5–14.4 m, stereo 9.9–13.9 m). Over stop 83's
/// runs of 53 sets, 52 of 72 such detections of rocks were ranged past their rock, against
/// 236 of 36 590 whose ground cue lay within the stereo cue.
fn contact_above_ground(r: &Ranged) -> bool {
    matches!((r.ground, r.stereo), (Some(g), Some(s))
        if g.low > 0.5 * (s.low + s.high) && g.high > s.high)
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
                range_trusted: range_trusted(&ranged[i]),
            })
            .collect(),
        colour: station.channels == Channels::Colour,
        unused: unused.iter().map(|r| r.ray).collect(),
        unused_placed: unused.iter().filter_map(|r| placed(r)).collect(),
    }
}

/// The physical width a detection implies for its rock (`ranging::width_evidence`), unless it
/// is a part of a blob separated by parallax, a piece touching another, cut off by the image's
/// bottom edge (its visible width is not its rock's), or doubted: a false
/// cut of one large rock (its sides read farther than its middle) leaves a part narrower than
/// the rock, which would bound the landmark's width too low and put the size cue's ranges too
/// far.
fn width_of(d: &Detection, ranged: &Ranged, model: &SensorModel) -> Option<RangeInterval> {
    (d.separation == Separation::Whole && !ranged.piece && !ranged.cut_off && !doubted(d))
        .then(|| ranging::width_evidence(ranged, model))
        .flatten()
}

/// A detection's rough position around the station, if its range is bounded well enough to
/// place it ([`placement`]): over the range it most likely lies at ([`likely_range`]).
fn placed(r: &Ranged) -> Option<Placed> {
    let range = likely_range(r.stereo, r.fused, r.conflict);
    placement(r.bearing.angle, r.bearing.uncertainty, range.as_array())
}

/// The range a detection most likely lies at, for association only (the map is measured with
/// the bounds): the middle half, in inverse range, of its `stereo` cue's interval (the
/// disparity ± half the bound), within its `fused` interval; the fused interval when it has no
/// stereo cue, its cues `conflict`, or the two do not meet.
///
/// The stereo bound (`SensorModel::disparity_error_px`, `_per_width`) is set by its tail: over
/// 17 preset renderings a matched pair's disparity missed the truth by 0.10 columns (median;
/// 0.58 for nine in ten, 6.6 for 99 in 100) by colour and 1.24 (2.28, 9.1) by luminance,
/// while the bound is 1.5 columns and 0.1 of the width. Placed over the whole bound, a far
/// rock ranged by stereo alone reached metres and anchored only on a far rock's strict terms:
/// on marsyard seed 7, 152 correct detections ended held back with their own landmark among
/// their candidates, placed within 2.2 m (median) against 0.38 m for those matched. Over the
/// likely half, 25 sets fused more (marsyard seed 7: 75.7 → 81.9 %), with 0 unsound relations
/// once a registration that chance nearly explains no longer anchors a pair on its own against
/// a significant one (`association::overruled`; docs/RUN.md, stop 63).
pub(crate) fn likely_range(
    stereo: Option<RangeInterval>,
    fused: RangeInterval,
    conflict: bool,
) -> RangeInterval {
    stereo
        .filter(|s| s.low > 0.0 && s.high.is_finite() && !conflict)
        .and_then(|s| {
            let (near, far) = (1.0 / s.high, 1.0 / s.low);
            let (centre, half) = (0.5 * (near + far), 0.25 * (far - near));
            RangeInterval::new(1.0 / (centre + half), 1.0 / (centre - half)).intersection(fused)
        })
        .unwrap_or(fused)
}

/// The rough position of a rock at `bearing` (± `uncertainty`) and range in `[low, high]`
/// metres, in an ellipse as long along the bearing as the interval and as wide across it as
/// the bearing error at the far end; none when the range is unbounded or wider than its middle.
///
/// It is centred at the interval's middle in inverse range, `2·low·high / (low + high)`, not
/// in metres. Both range cues measure in inverse range: a stereo disparity, and a contact
/// row's offset below the horizon. Their error bounds are symmetric there, so the measured
/// range lies at that centre, nearer than the interval's metric middle. Over 18 preset
/// renderings (colour, luminance, JPEG, stress) a placed detection's true range lay within
/// 1.9 % of that centre (median; 7.5 % for nine in ten) against 2.8 % (11.1 %) of the metric
/// middle, and one ranged by stereo alone within 4.3 % against 7.8 % (docs/RUN.md, stop 63).
pub(crate) fn placement(bearing: f64, uncertainty: f64, [low, high]: [f64; 2]) -> Option<Placed> {
    let middle = 0.5 * (low + high);
    (high.is_finite() && high - low < middle).then(|| {
        let centre = low * high / middle;
        Placed::along(
            [centre * bearing.cos(), centre * bearing.sin()],
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
    let bearings: Vec<Bearing> = chosen.iter().map(Ranged::measured_bearing).collect();
    let order: RangeOrder = ranging::range_order(&chosen);
    let ranges = chosen.iter().map(ranging::ratio_bounds).collect();
    StationView::new(bearings, order)
        .and_then(|view| view.with_ranges(ranges))
        .expect("bearings are finite, in range, with uncertainty below the limit; the order is the intervals'")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::Calibration;
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
                half_width: 0.0,
            },
            stereo_column: None,
            angular_width: 0.01,
            ground: None,
            stereo: None,
            size: None,
            fused: RangeInterval::new(4.0, 5.0),
            conflict: false,
            piece: false,
            cut_off: false,
            lit_face: 0.0,
        }
    }

    /// A range is trusted where both cues agree or stereo alone ranges a detection without a
    /// ground cue; not on the ground cue alone, nor where the two disagree.
    #[test]
    fn a_range_is_trusted_on_agreeing_cues_or_on_stereo_without_a_ground_cue() {
        let cue = RangeInterval::new;
        let with = |ground, stereo| Ranged {
            ground,
            stereo,
            ..ranged(0.01)
        };
        assert!(range_trusted(&with(
            Some(cue(4.0, 5.0)),
            Some(cue(4.5, 6.0))
        )));
        assert!(range_trusted(&with(None, Some(cue(4.5, 6.0)))));
        assert!(!range_trusted(&with(Some(cue(4.0, 5.0)), None)));
        assert!(!range_trusted(&with(
            Some(cue(4.0, 5.0)),
            Some(cue(6.0, 7.0))
        )));
        assert!(!range_trusted(&with(None, None)));
    }

    /// A ground cue that meets the stereo cue only beyond the stereo cue's middle, reaching
    /// past its far end, is not trusted (stress s49: the upper piece of a rock 12.1 m away);
    /// one within the stereo cue, or reaching past its near end, is.
    #[test]
    fn a_ground_cue_meeting_stereo_only_at_its_far_end_is_not_trusted() {
        let cue = RangeInterval::new;
        let with = |ground, stereo| Ranged {
            ground: Some(ground),
            stereo: Some(stereo),
            ..ranged(0.01)
        };
        let stereo = cue(9.9, 13.9);
        assert!(!range_trusted(&with(cue(13.5, 14.4), stereo)));
        assert!(range_trusted(&with(cue(12.5, 13.5), stereo)));
        assert!(range_trusted(&with(cue(11.0, 14.4), stereo)));
        assert!(range_trusted(&with(cue(9.0, 10.5), stereo)));
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

    /// The marsyard calibration (4096 × 768, horizon at row 300, 1.5 m mast, 0.3 m baseline).
    fn marsyard() -> Calibration {
        let text = "[image]\nwidth = 4096\nheight = 768\n[azimuth]\ncolumn0_deg = 180.0\n\
            direction = \"clockwise\"\n[elevation]\nhorizon_row = 300.0\nfocal_px = 652.0\n\
            [mast]\nheight_m = 1.5\n[stereo]\nbaseline_m = 0.3\n";
        Calibration::parse(text, "test").expect("valid")
    }

    /// How far from the station a placement's centre lies.
    fn centre_range(placed: &Placed) -> f64 {
        placed.point[0].hypot(placed.point[1])
    }

    proptest::proptest! {
        /// A range interval bounded by a symmetric error on a measurement linear in inverse
        /// range is placed at the measured range, nearer than the interval's metric middle:
        /// exactly for a contact row `±k` rows, and to the sine's curvature for a disparity
        /// `±e` columns. The ellipse's length along the bearing is the interval's.
        #[test]
        fn a_placement_is_centred_where_the_cue_measured_the_range(
            range in 1.0f64..15.0,
            rows in 0.5f64..8.0,
            columns in 0.5f64..8.0,
            bearing in 0.0f64..std::f64::consts::TAU,
        ) {
            let calib = marsyard();
            let row = calib.ground_row(range);
            let ground = [calib.ground_range(row + rows), calib.ground_range(row - rows)];
            let disparity = calib.stereo_disparity(range);
            let error = columns * calib.column_width();
            let stereo = [
                calib.stereo_range(disparity + error),
                calib.stereo_range(disparity - error),
            ];
            for (cue, tolerance) in [(ground, 1e-9), (stereo, 1e-3)] {
                let [Some(low), Some(high)] = cue else { continue };
                let Some(placed) = placement(bearing, 0.01, [low, high]) else { continue };
                proptest::prop_assert!((centre_range(&placed) - range).abs() <= tolerance * range);
                proptest::prop_assert!(centre_range(&placed) < 0.5 * (low + high));
                let direction = [bearing.cos(), bearing.sin()];
                let length = placed.extent(direction);
                proptest::prop_assert!((length - 0.5 * (high - low)).abs() < 1e-9);
            }
        }
    }

    proptest::proptest! {
        /// The likely range of a stereo pair is its disparity ± half the bound (to the sine's
        /// curvature), inside the fused interval; without a stereo cue, with conflicting cues,
        /// or where the two do not meet, it is the fused interval.
        #[test]
        fn the_likely_range_is_the_disparity_within_half_its_bound(
            range in 1.0f64..15.0,
            columns in 0.5f64..8.0,
        ) {
            let calib = marsyard();
            let disparity = calib.stereo_disparity(range);
            let error = columns * calib.column_width();
            let bounded = |e: f64| -> Option<RangeInterval> {
                Some(RangeInterval::new(
                    calib.stereo_range(disparity + e)?,
                    calib.stereo_range(disparity - e)?,
                ))
            };
            let (Some(stereo), Some(half)) = (bounded(error), bounded(0.5 * error)) else {
                return Ok(());
            };
            let likely = likely_range(Some(stereo), stereo, false);
            proptest::prop_assert!((likely.low - half.low).abs() <= 1e-3 * half.low);
            proptest::prop_assert!((likely.high - half.high).abs() <= 1e-3 * half.high);
            proptest::prop_assert!(likely.low <= range && range <= likely.high);
            let ground = RangeInterval::new(0.9 * range, 1.02 * range);
            let within = likely_range(Some(stereo), ground, false);
            proptest::prop_assert!(ground.low <= within.low && within.high <= ground.high);
            proptest::prop_assert_eq!(likely_range(None, ground, false), ground);
            proptest::prop_assert_eq!(likely_range(Some(stereo), ground, true), ground);
            let apart = RangeInterval::new(2.0 * stereo.high, 3.0 * stereo.high);
            proptest::prop_assert_eq!(likely_range(Some(stereo), apart, false), apart);
        }
    }
}
