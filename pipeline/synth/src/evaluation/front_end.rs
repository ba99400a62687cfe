//! Scoring the front end image by image: detections ([`Score`]), bearings, range cues and
//! the asserted range order, against the truth rock each detection is credited with.

use super::detection::{ratio, Detectable, DetectedBox, Score};
use super::{BearingScore, CueScore, DetectionScore, RangeScore};
use crate::dataset::{ImageTruth, Truth};
use qrm_core::measurement::angular_distance;
use qrm_vision::calib::Calibration;
use qrm_vision::run::{Association, DetectionRecord, RangeRecord, StationRecord};
use std::collections::HashMap;
use std::f64::consts::TAU;

/// The front end's figures, summed over images.
#[derive(Default)]
pub(super) struct Tally {
    detection: Score,
    /// Truth rock of every matched `(station index, detection index)`.
    pub matched: HashMap<(usize, usize), u32>,
    /// Bearing error of every matched detection; and error with interval half-width of the
    /// detections the run used.
    bearing_errors: Vec<f64>,
    used_errors: Vec<(f64, f64)>,
    within: usize,
    worst_ratio: f64,
    /// Per cue (ground, stereo, size, fused): whether the interval held the true range, and
    /// its width relative to it.
    cue_checks: [Vec<(bool, f64)>; 4],
    range: RangeScore,
}

impl Tally {
    /// Adds the primary image of one station.
    pub fn add_image(
        &mut self,
        record: &StationRecord,
        image: &ImageTruth,
        truth: &Truth,
        calib: &Calibration,
        detectable: Detectable,
    ) {
        let boxes: Vec<DetectedBox> = record.detections.iter().map(DetectedBox::from).collect();
        let credited = self.detection.add(&boxes, &image.rocks, calib, detectable);
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
        for (i, (d, id)) in record.detections.iter().zip(&ids).enumerate() {
            let Some(id) = *id else { continue };
            self.matched.insert((record.index, i), id);
            let (bearing, range) = polar(id);
            self.add_bearing(d, bearing);
            self.add_cues(&d.range, range);
        }
        let ranges: Vec<Option<f64>> = ids.iter().map(|id| id.map(|id| polar(id).1)).collect();
        self.add_order(record, &ranges);
    }

    fn add_bearing(&mut self, d: &DetectionRecord, truth: f64) {
        let error = angular_distance(d.bearing, truth);
        self.bearing_errors.push(error);
        if !matches!(d.association, Association::Unused { .. }) {
            self.used_errors.push((error, d.bearing_uncertainty));
        }
        if error <= d.bearing_uncertainty {
            self.within += 1;
        }
        if d.bearing_uncertainty > 0.0 {
            self.worst_ratio = self.worst_ratio.max(error / d.bearing_uncertainty);
        }
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

    /// The asserted order of one station against the true ranges of its matched detections.
    fn add_order(&mut self, record: &StationRecord, ranges: &[Option<f64>]) {
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
                r.asserted_pairs += 1;
                if ri > rj {
                    r.wrong_pairs += 1;
                }
            }
        }
    }

    /// Detection, bearing (all matched, and used), and range figures.
    pub fn scores(&self) -> (DetectionScore, BearingScore, BearingScore, RangeScore) {
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
        let all = BearingScore {
            count: self.bearing_errors.len(),
            median_error_deg: median(self.bearing_errors.clone()).to_degrees(),
            worst_error_deg: self
                .bearing_errors
                .iter()
                .copied()
                .fold(0.0, f64::max)
                .to_degrees(),
            within_interval: ratio(self.within, self.bearing_errors.len()),
            worst_error_ratio: self.worst_ratio,
        };
        let used = &self.used_errors;
        let used = BearingScore {
            count: used.len(),
            median_error_deg: median(used.iter().map(|e| e.0).collect()).to_degrees(),
            worst_error_deg: used.iter().map(|e| e.0).fold(0.0, f64::max).to_degrees(),
            within_interval: ratio(used.iter().filter(|e| e.0 <= e.1).count(), used.len()),
            worst_error_ratio: used
                .iter()
                .filter(|e| e.1 > 0.0)
                .map(|e| e.0 / e.1)
                .fold(0.0, f64::max),
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
        (detection, all, used, range)
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
