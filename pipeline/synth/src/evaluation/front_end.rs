//! Scoring the front end image by image: detections ([`Score`]), bearings, range cues and
//! the asserted range order, against the truth rock each detection is credited with.

use super::detection::{also_shown, match_detections, ratio, Detectable, DetectedBox, Score};
use super::{BearingScore, CueScore, DetectionScore, FrontEndScore, RangeScore};
use crate::dataset::{ImageTruth, Truth};
use qrm_core::measurement::angular_distance;
use qrm_vision::calib::Calibration;
use qrm_vision::run::{Association, DetectionRecord, RangeRecord, StationRecord};
use std::collections::{HashMap, HashSet};
use std::f64::consts::TAU;

/// A detection holding less than this share of its rock's visible pixels is a piece of it: its
/// centroid may lie far from the rock's centre (docs/RUN.md, stop 55: such pieces were most of
/// the fused bearings that missed their rocks).
pub(super) const PIECE_SHARE: f64 = 0.3;

/// The front end's figures, summed over images.
#[derive(Default)]
pub(super) struct Tally {
    detection: Score,
    /// Truth rock of every matched `(station index, detection index)`.
    pub matched: HashMap<(usize, usize), u32>,
    /// Other truth rocks each matched detection also shows ([`also_shown`]).
    pub also_shows: HashMap<(usize, usize), Vec<u32>>,
    /// Bearing error with interval half-width of every matched detection, of the detections
    /// the run used, of the sightings that reached the map, and of those of the latter that
    /// are pieces of their rock ([`PIECE_SHARE`]).
    bearing_errors: Vec<(f64, f64)>,
    used_errors: Vec<(f64, f64)>,
    fused_errors: Vec<(f64, f64)>,
    piece_errors: Vec<(f64, f64)>,
    /// Per cue (ground, stereo, size, fused): whether the interval held the true range, and
    /// its width relative to it.
    cue_checks: [Vec<(bool, f64)>; 4],
    range: RangeScore,
}

impl Tally {
    /// Adds the primary image of one station; `fused` holds the `(station, detection)`
    /// sightings of the run's landmarks.
    pub fn add_image(
        &mut self,
        record: &StationRecord,
        image: &ImageTruth,
        truth: &Truth,
        calib: &Calibration,
        detectable: Detectable,
        fused: &HashSet<(usize, usize)>,
    ) {
        let boxes: Vec<DetectedBox> = record.detections.iter().map(DetectedBox::from).collect();
        self.detection.add(&boxes, &image.rocks, calib, detectable);
        let credited = match_detections(&boxes, &image.rocks, calib.image.width);
        let station = &truth.stations[image.station];
        // True bearing and range of a rock from the station centre.
        let polar = |id: u32| {
            let p = truth.rocks[id as usize].position;
            let (dx, dy) = (p[0] - station.position[0], p[1] - station.position[1]);
            (
                (dy.atan2(dx) - station.heading).rem_euclid(TAU),
                dx.hypot(dy),
            )
        };
        let ids: Vec<Option<u32>> = credited
            .iter()
            .map(|c| c.map(|k| image.rocks[k].id))
            .collect();
        let sighting: Vec<bool> = (0..record.detections.len())
            .map(|i| fused.contains(&(record.index, i)))
            .collect();
        for (i, (d, credit)) in record.detections.iter().zip(&credited).enumerate() {
            let Some(rock) = credit.map(|k| &image.rocks[k]) else {
                continue;
            };
            self.matched.insert((record.index, i), rock.id);
            let also = also_shown(&boxes[i], &image.rocks, &credited, calib.image.width);
            if !also.is_empty() {
                let ids = also.into_iter().map(|k| image.rocks[k].id).collect();
                self.also_shows.insert((record.index, i), ids);
            }
            let (bearing, range) = polar(rock.id);
            let error = self.add_bearing(d, bearing);
            if sighting[i] {
                self.fused_errors.push((error, d.bearing_uncertainty));
                if f64::from(d.pixels) < PIECE_SHARE * f64::from(rock.pixels) {
                    self.piece_errors.push((error, d.bearing_uncertainty));
                }
            }
            self.add_cues(&d.range, range);
        }
        let ranges: Vec<Option<f64>> = ids.iter().map(|id| id.map(|id| polar(id).1)).collect();
        self.add_order(record, &ranges, &sighting);
    }

    /// Adds a detection's bearing against the truth; its error.
    fn add_bearing(&mut self, d: &DetectionRecord, truth: f64) -> f64 {
        let error = angular_distance(d.bearing, truth);
        self.bearing_errors.push((error, d.bearing_uncertainty));
        if !matches!(d.association, Association::Unused { .. }) {
            self.used_errors.push((error, d.bearing_uncertainty));
        }
        error
    }

    fn add_cues(&mut self, cues: &RangeRecord, range: f64) {
        let intervals = [cues.ground, cues.stereo, cues.size, Some(cues.fused)];
        for (checks, interval) in self.cue_checks.iter_mut().zip(intervals) {
            if let Some([low, high]) = interval {
                let width = if high.is_finite() {
                    (high - low) / range
                } else {
                    f64::INFINITY
                };
                checks.push(((low..=high).contains(&range), width));
            }
        }
        if cues.conflict {
            self.range.conflicts += 1;
        }
    }

    /// The asserted order of one station against the true ranges of its matched detections;
    /// `sighting[i]` whether detection `i` reached the map.
    fn add_order(&mut self, record: &StationRecord, ranges: &[Option<f64>], sighting: &[bool]) {
        let matched = ranges.iter().flatten().count();
        self.range.pairs += matched * matched.saturating_sub(1) / 2;
        for &(i, j) in &record.order {
            let (a, b) = (&record.detections[i].range, &record.detections[j].range);
            let apart = |x: Option<[f64; 2]>, y: Option<[f64; 2]>| matches!((x, y), (Some(x), Some(y)) if x[1] < y[0]);
            let by = [
                apart(a.ground, b.ground),
                apart(a.stereo, b.stereo),
                apart(a.size, b.size),
            ];
            let r = &mut self.range;
            r.asserted_all += 1;
            r.separated_by_ground += usize::from(by[0]);
            r.separated_by_stereo += usize::from(by[1]);
            r.separated_by_size += usize::from(by[2]);
            r.separated_only_fused += usize::from(!by.iter().any(|&x| x));
            if let (Some(Some(ri)), Some(Some(rj))) = (ranges.get(i), ranges.get(j)) {
                let both_fused = sighting[i] && sighting[j];
                r.asserted_pairs += 1;
                r.fused_asserted_pairs += usize::from(both_fused);
                if ri > rj {
                    r.wrong_pairs += 1;
                    r.fused_wrong_pairs += usize::from(both_fused);
                    if both_fused {
                        r.fused_wrong.push((record.index, i, j));
                    }
                }
            }
        }
    }

    /// Detection, bearing (all matched, used, fused, fused pieces), and range figures.
    pub fn scores(&self) -> FrontEndScore {
        let d = &self.detection;
        let detection = DetectionScore {
            images: d.images,
            detections: d.detections,
            true_detections: d.true_detections,
            detectable: d.detectable,
            detectable_found: d.found,
            precision: d.precision(),
            recall: d.recall(),
        };
        let cue = |checks: &Vec<(bool, f64)>| CueScore {
            count: checks.len(),
            holds_truth: ratio(checks.iter().filter(|c| c.0).count(), checks.len()),
            median_relative_width: median(
                checks
                    .iter()
                    .map(|c| c.1)
                    .filter(|w| w.is_finite())
                    .collect(),
            ),
        };
        let range = RangeScore {
            ground: cue(&self.cue_checks[0]),
            stereo: cue(&self.cue_checks[1]),
            size: cue(&self.cue_checks[2]),
            fused: cue(&self.cue_checks[3]),
            ..self.range.clone()
        };
        FrontEndScore {
            detection,
            bearing: bearing_score(&self.bearing_errors),
            bearing_used: bearing_score(&self.used_errors),
            bearing_fused: bearing_score(&self.fused_errors),
            bearing_pieces: bearing_score(&self.piece_errors),
            range,
        }
    }
}

/// Bearing figures of `(error, interval half-width)` pairs.
fn bearing_score(errors: &[(f64, f64)]) -> BearingScore {
    BearingScore {
        count: errors.len(),
        median_error_deg: median(errors.iter().map(|e| e.0).collect()).to_degrees(),
        worst_error_deg: errors.iter().map(|e| e.0).fold(0.0, f64::max).to_degrees(),
        within_interval: ratio(errors.iter().filter(|e| e.0 <= e.1).count(), errors.len()),
        worst_error_ratio: errors
            .iter()
            .filter(|e| e.1 > 0.0)
            .map(|e| e.0 / e.1)
            .fold(0.0, f64::max),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::{RockTruth, StationTruth, VisibleRock};
    use qrm_vision::run::RangeRecord;

    /// Three rocks due ahead-left of a station at the origin, at 4, 6 and 8 m; each detection's
    /// box holds its rock's centroid.
    fn scene(calib: &Calibration) -> (Truth, ImageTruth, Vec<DetectionRecord>) {
        let ranges = [4.0, 6.0, 8.0];
        let bearing = 0.5_f64;
        let rocks = ranges
            .iter()
            .enumerate()
            .map(|(id, r)| RockTruth {
                id: id as u32,
                position: [r * bearing.cos(), r * bearing.sin()],
                size: 0.5,
                height: 0.3,
                burial: 0.0,
                albedo: [0.5; 3],
                lumps: Vec::new(),
            })
            .collect();
        let truth = Truth {
            format: crate::dataset::TRUTH_FORMAT.into(),
            version: crate::dataset::TRUTH_VERSION,
            preset: "test".into(),
            seed: 0,
            rocks,
            stations: vec![StationTruth {
                name: "s0".into(),
                position: [0.0, 0.0],
                heading: 0.0,
            }],
            images: Vec::new(),
            variant: None,
        };
        let column = calib.column(bearing);
        let visible: Vec<VisibleRock> = ranges
            .iter()
            .enumerate()
            .map(|(id, r)| {
                let row = calib.ground_row(*r);
                VisibleRock {
                    id: id as u32,
                    pixels: 100,
                    bbox: [
                        column as u32 - 5,
                        row as u32 - 5,
                        column as u32 + 5,
                        row as u32,
                    ],
                    centroid: [column, row - 2.0],
                    bearing,
                    bearing_column: column,
                    range: *r,
                    contact: [column, row],
                }
            })
            .collect();
        let detections = visible
            .iter()
            .map(|rock| DetectionRecord {
                bbox: rock.bbox,
                centroid: rock.centroid,
                contact_row: rock.contact[1],
                pixels: 100,
                bearing: rock.bearing,
                bearing_uncertainty: 0.01,
                range: RangeRecord {
                    fused: [rock.range - 0.1, rock.range + 0.1],
                    ..RangeRecord::default()
                },
                ..DetectionRecord::default()
            })
            .collect();
        let image = ImageTruth {
            file: "station_000_left.png".into(),
            station: 0,
            eye: "left".into(),
            rocks: visible,
            digest: None,
        };
        (truth, image, detections)
    }

    /// The fused figures count only the sightings that reached the map: a piece's bearing that
    /// misses its rock, and a wrong pair between detections that were never fused, are told
    /// apart from the rest.
    #[test]
    fn fused_figures_count_only_the_sightings_of_the_map() {
        let calib = Calibration::parse(
            include_str!("../../../../calib/default.toml"),
            "default.toml",
        )
        .expect("the default calibration");
        let (truth, image, mut detections) = scene(&calib);
        // Detection 1 is a piece of its rock, its bearing off by twice its interval.
        detections[1].pixels = 10;
        detections[1].bearing += 0.02;
        let record = StationRecord {
            index: 0,
            detections,
            // 0 nearer than 1 (right); 2 nearer than 0 (wrong).
            order: vec![(0, 1), (2, 0)],
            ..StationRecord::default()
        };
        let fused: HashSet<(usize, usize)> = [(0, 0), (0, 1)].into_iter().collect();
        let detectable = Detectable {
            min_width_m: 0.0,
            max_range_m: 100.0,
        };
        let mut tally = Tally::default();
        tally.add_image(&record, &image, &truth, &calib, detectable, &fused);
        let scores = tally.scores();
        assert_eq!(scores.bearing.count, 3);
        assert_eq!(scores.bearing_fused.count, 2);
        assert_eq!(scores.bearing_fused.within_interval, 0.5);
        assert_eq!(scores.bearing_pieces.count, 1);
        assert_eq!(scores.bearing_pieces.within_interval, 0.0);
        let r = &scores.range;
        assert_eq!((r.asserted_pairs, r.wrong_pairs), (2, 1));
        assert_eq!((r.fused_asserted_pairs, r.fused_wrong_pairs), (1, 0));
        assert!(r.fused_wrong.is_empty());
    }
}
