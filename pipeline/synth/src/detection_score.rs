//! Scoring detections against ground truth (`truth.json` or [`crate::dataset::visible_rocks`]),
//! shared by the benchmark and the tests so that both report the same figures.

use crate::dataset::VisibleRock;
use qrm_vision::calib::Calibration;
use qrm_vision::detection::{Detection, DetectorSettings};

/// Counts and errors of one or more images' detections.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Score {
    /// Detectable truth rocks (at least `min_width_m` wide and within `max_range_m`).
    pub detectable: usize,
    /// Detectable rocks found by exactly one detection.
    pub found: usize,
    /// Detections on no rock at all.
    pub false_alarms: usize,
    /// Extra detections on an already found rock (splits), counted as false.
    pub splits: usize,
    /// Detectable rocks seen by a detection credited to another rock (merges).
    pub merged: usize,
    /// |centroid column − truth bearing column| (pixels) of found rocks.
    pub bearing_errors: Vec<f64>,
    /// |contact row − truth contact row| (pixels) of found rocks whose contact is in the image.
    pub contact_errors: Vec<f64>,
    /// Bearing error over detection width (columns) of found rocks.
    pub bearing_ratios: Vec<f64>,
    /// Found rocks whose bearing error exceeds the downstream bound `1 px + 0.3 × width`.
    pub outside_bound: usize,
    /// Detections flagged ambiguous: left out of the matching (the downstream skips them).
    pub ambiguous: usize,
}

fn column_gap(a: f64, b: f64, width: f64) -> f64 {
    let d = (a - b).rem_euclid(width);
    d.min(width - d)
}

/// Whether continuous column `col` lies in `[lo, hi]` (inclusive pixel indices, `hi` may pass
/// the width or be below `lo` at the seam), with `slack` pixels either side.
fn within_columns(col: f64, lo: u32, hi: u32, width: f64, slack: f64) -> bool {
    let lo = f64::from(lo) - slack;
    let mut hi = f64::from(hi) + 1.0 + slack;
    if hi < lo {
        hi += width;
    }
    let c = (col - lo).rem_euclid(width);
    c <= hi - lo
}

/// Whether `rock` is one the detector must find: its visible footprint at least `min_width_m`
/// wide and its range within `max_range_m`.
pub fn detectable(rock: &VisibleRock, calib: &Calibration, settings: &DetectorSettings) -> bool {
    let width = f64::from(calib.image.width);
    let span = (f64::from(rock.bbox[2]) - f64::from(rock.bbox[0])).rem_euclid(width) + 1.0;
    rock.range <= settings.max_range_m
        && span * calib.column_width() * rock.range >= settings.min_width_m
}

impl Score {
    /// Adds one image: each detection is credited to the visible rock whose bounding box holds
    /// its centroid (nearest truth centroid if several), a detection holding the centroids of
    /// several detectable rocks counts as merging them.
    pub fn add(
        &mut self,
        detections: &[Detection],
        truth: &[VisibleRock],
        calib: &Calibration,
        settings: &DetectorSettings,
    ) {
        let width = f64::from(calib.image.width);
        let mut hits = vec![0usize; truth.len()];
        let mut first: Vec<Option<&Detection>> = vec![None; truth.len()];
        for d in detections {
            if d.ambiguous {
                self.ambiguous += 1;
                continue;
            }
            let owner = truth
                .iter()
                .enumerate()
                .filter(|(_, t)| {
                    within_columns(d.centroid[0], t.bbox[0], t.bbox[2], width, 1.0)
                        && d.centroid[1] >= f64::from(t.bbox[1]) - 1.0
                        && d.centroid[1] <= f64::from(t.bbox[3]) + 2.0
                })
                .min_by(|(_, a), (_, b)| {
                    let da = column_gap(a.centroid[0], d.centroid[0], width)
                        + (a.centroid[1] - d.centroid[1]).abs();
                    let db = column_gap(b.centroid[0], d.centroid[0], width)
                        + (b.centroid[1] - d.centroid[1]).abs();
                    da.total_cmp(&db)
                })
                .map(|(i, _)| i);
            match owner {
                Some(i) => {
                    hits[i] += 1;
                    first[i].get_or_insert(d);
                }
                None => self.false_alarms += 1,
            }
        }
        for (i, t) in truth.iter().enumerate() {
            if !detectable(t, calib, settings) {
                continue;
            }
            self.detectable += 1;
            if let Some(d) = first[i] {
                self.found += 1;
                self.splits += hits[i] - 1;
                let error = column_gap(d.centroid[0], t.bearing_column, width);
                let columns = f64::from(d.bbox[2] - d.bbox[0] + 1);
                self.bearing_errors.push(error);
                self.bearing_ratios.push(error / columns);
                if error > 1.0 + 0.3 * columns {
                    self.outside_bound += 1;
                }
                if t.contact[1] < f64::from(calib.image.height) {
                    self.contact_errors
                        .push((d.contact_row - t.contact[1]).abs());
                }
            } else if detections.iter().any(|d| {
                !d.ambiguous
                    && within_columns(t.centroid[0], d.bbox[0], d.bbox[2], width, 0.0)
                    && t.centroid[1] >= f64::from(d.bbox[1])
                    && t.centroid[1] <= f64::from(d.bbox[3]) + 1.0
            }) {
                self.merged += 1;
            }
        }
    }

    /// Found over detectable (merged rocks are not found).
    pub fn recall(&self) -> f64 {
        self.found as f64 / self.detectable.max(1) as f64
    }

    /// Found over found plus false alarms and splits.
    pub fn precision(&self) -> f64 {
        let claimed = self.found + self.false_alarms + self.splits;
        self.found as f64 / claimed.max(1) as f64
    }
}

/// Median and maximum of `values` (0 for none).
pub fn median_and_max(values: &[f64]) -> (f64, f64) {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    (
        v.get(v.len() / 2).copied().unwrap_or(0.0),
        v.last().copied().unwrap_or(0.0),
    )
}
