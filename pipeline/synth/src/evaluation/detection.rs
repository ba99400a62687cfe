//! Which truth rock each detection shows, and the detection figures that follow: the one
//! matching rule of `pipeline eval`, the benchmarks and the tests, so that all of them report
//! the same precision and recall for the same detections.

use crate::dataset::VisibleRock;
use qrm_core::measurement::angular_distance;
use qrm_vision::calib::Calibration;
use qrm_vision::detection::{Detection, DetectorSettings};
use qrm_vision::run::DetectionRecord;

/// Which truth rocks a detector is expected to find.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detectable {
    pub min_width_m: f64,
    pub max_range_m: f64,
}

impl Detectable {
    pub fn of(settings: &DetectorSettings) -> Detectable {
        Detectable {
            min_width_m: settings.min_width_m,
            max_range_m: settings.max_range_m,
        }
    }

    /// Whether `rock`'s visible footprint is at least `min_width_m` wide and its range within
    /// `max_range_m`.
    pub fn holds(&self, rock: &VisibleRock, calib: &Calibration) -> bool {
        let width = f64::from(calib.image.width);
        let columns = (f64::from(rock.bbox[2]) - f64::from(rock.bbox[0])).rem_euclid(width) + 1.0;
        rock.range <= self.max_range_m
            && columns * calib.column_width() * rock.range >= self.min_width_m
    }
}

/// What matching needs of a detection, from the detector or from `stations.json`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectedBox {
    pub centroid: [f64; 2],
    /// `[col_min, row_min, col_max, row_max]`, inclusive; `col_max ≥ width` when it wraps.
    pub bbox: [u32; 4],
    pub contact_row: f64,
    /// What the run measured of it, once it has a range (`stations.json`); none from the
    /// detector alone.
    pub measured: Option<Measured>,
}

/// A detection's bearing and fused range intervals, as the map used them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// Rover-frame bearing and its half-width (radians).
    pub bearing: f64,
    pub bearing_uncertainty: f64,
    /// `[low, high]`, metres; `high` may be infinite.
    pub range: [f64; 2],
}

impl Measured {
    /// Whether `rock`'s true bearing and range lie inside the intervals.
    pub fn fits(&self, rock: &VisibleRock) -> bool {
        angular_distance(self.bearing, rock.bearing) <= self.bearing_uncertainty
            && (self.range[0]..=self.range[1]).contains(&rock.range)
    }
}

impl From<&Detection> for DetectedBox {
    fn from(d: &Detection) -> DetectedBox {
        DetectedBox {
            centroid: d.centroid,
            bbox: d.bbox,
            contact_row: d.contact_row,
            measured: None,
        }
    }
}

impl From<&DetectionRecord> for DetectedBox {
    fn from(d: &DetectionRecord) -> DetectedBox {
        DetectedBox {
            centroid: d.centroid,
            bbox: d.bbox,
            contact_row: d.contact_row,
            measured: Some(Measured {
                bearing: d.bearing,
                bearing_uncertainty: d.bearing_uncertainty,
                range: d.range.fused,
            }),
        }
    }
}

/// The rock (index into `rocks`) each detection is credited with. A detection claims the rock
/// whose bounding box holds its centroid (a column of slack either side, half a row above and
/// one and a half below), the nearest by centroid distance if several. A detection with a
/// measurement that claims a rock prefers one its bearing and range intervals hold, among the
/// claimed rocks and those its own box overlaps in the centroid's column: a blob that joins a
/// rock and the one behind it can have its centroid on the far rock and its range, from the
/// contact row, of the near one. A rock claimed by several detections is credited to the
/// nearest, the others (splits) to none.
pub fn match_detections(
    detections: &[DetectedBox],
    rocks: &[VisibleRock],
    width: u32,
) -> Vec<Option<usize>> {
    credit(&claims(detections, rocks, width), rocks.len())
}

/// The rocks of `rocks` that detection `d` shows besides the one it is credited with: a blob
/// over several touching rocks is credited with one of them (its nearest centroid among those
/// its measurement holds), yet its measurement may hold its neighbours as well, and then it is
/// as much a sighting of each (stress clusters: the rock credited changes with the viewpoint
/// while the blob and its landmark stay the same). Such a rock lies in the detection's rows and
/// columns, its true bearing and range lie inside the detection's intervals, and no detection
/// of the image is credited with it.
pub(super) fn also_shown(
    d: &DetectedBox,
    rocks: &[VisibleRock],
    credited: &[Option<usize>],
    width: u32,
) -> Vec<usize> {
    let Some(measured) = d.measured else {
        return Vec::new();
    };
    rocks
        .iter()
        .enumerate()
        .filter(|&(k, r)| {
            !credited.contains(&Some(k))
                && measured.fits(r)
                && in_columns(r.centroid[0], d.bbox, width)
                && r.bbox[1] <= d.bbox[3]
                && r.bbox[3] >= d.bbox[1]
        })
        .map(|(k, _)| k)
        .collect()
}

/// How near a claimant is to a rock, nearest first: its measurement fits the rock, its centroid
/// lies in the rock's box, the distance between their centroids.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Nearness {
    misfit: bool,
    off_box: bool,
    distance: f64,
}

impl Nearness {
    fn order(&self, other: &Nearness) -> std::cmp::Ordering {
        (self.misfit, self.off_box)
            .cmp(&(other.misfit, other.off_box))
            .then(self.distance.total_cmp(&other.distance))
    }
}

/// The rock each detection claims, with how near it is.
fn claims(
    detections: &[DetectedBox],
    rocks: &[VisibleRock],
    width: u32,
) -> Vec<Option<(usize, Nearness)>> {
    detections.iter().map(|d| claim(d, rocks, width)).collect()
}

/// Each claimed rock credited to its nearest claimant: the rock of each detection.
fn credit(claims: &[Option<(usize, Nearness)>], rocks: usize) -> Vec<Option<usize>> {
    let mut best: Vec<Option<(usize, Nearness)>> = vec![None; rocks];
    for (i, claim) in claims.iter().enumerate() {
        if let Some((rock, near)) = *claim {
            if best[rock].is_none_or(|(_, nearest)| near.order(&nearest).is_lt()) {
                best[rock] = Some((i, near));
            }
        }
    }
    let mut credited = vec![None; claims.len()];
    for (rock, claimant) in best.iter().enumerate() {
        if let Some((i, _)) = claimant {
            credited[*i] = Some(rock);
        }
    }
    credited
}

/// The rock a detection claims, with how near it is: none unless its centroid lies in a rock's
/// box.
fn claim(d: &DetectedBox, rocks: &[VisibleRock], width: u32) -> Option<(usize, Nearness)> {
    let near: Vec<(usize, Nearness)> = rocks
        .iter()
        .enumerate()
        .filter(|(_, r)| in_columns(d.centroid[0], r.bbox, width))
        .filter_map(|(k, r)| {
            let in_box =
                (f64::from(r.bbox[1]) - 0.5..=f64::from(r.bbox[3]) + 1.5).contains(&d.centroid[1]);
            let fits = d.measured.is_some_and(|m| m.fits(r));
            let overlaps = r.bbox[1] <= d.bbox[3] && r.bbox[3] >= d.bbox[1];
            (in_box || (fits && overlaps)).then(|| {
                let dc = column_gap(d.centroid[0], r.centroid[0], width);
                let near = Nearness {
                    misfit: !fits,
                    off_box: !in_box,
                    distance: dc.hypot(d.centroid[1] - r.centroid[1]),
                };
                (k, near)
            })
        })
        .collect();
    if near.iter().all(|(_, n)| n.off_box) {
        return None;
    }
    near.into_iter().min_by(|a, b| a.1.order(&b.1))
}

fn column_gap(a: f64, b: f64, width: u32) -> f64 {
    let w = f64::from(width);
    let d = (a - b).rem_euclid(w);
    d.min(w - d)
}

/// Whether `column` lies in the (possibly seam-wrapping) column span of `bbox`, with a column
/// of slack either side.
fn in_columns(column: f64, bbox: [u32; 4], width: u32) -> bool {
    let w = f64::from(width);
    let start = f64::from(bbox[0]);
    let span = (f64::from(bbox[2]) - start).rem_euclid(w) + 1.0;
    (column - start + 1.0).rem_euclid(w) <= span + 1.0
}

/// Detection figures over one or more images, by [`match_detections`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Score {
    pub images: usize,
    pub detections: usize,
    /// Detections credited with a truth rock (detectable or not).
    pub true_detections: usize,
    /// Detectable truth rocks, and those credited with a detection.
    pub detectable: usize,
    pub found: usize,
    /// Detections whose centroid lies on no rock.
    pub false_alarms: usize,
    /// Detections on a rock credited to a nearer detection.
    pub splits: usize,
    /// Detectable rocks not found whose centroid lies inside a detection's box (merged into
    /// another rock's detection).
    pub merged: usize,
    /// |centroid column − truth bearing column| (pixels) of found detectable rocks.
    pub bearing_errors: Vec<f64>,
    /// |contact row − truth contact row| (pixels) of found rocks whose contact is in the image.
    pub contact_errors: Vec<f64>,
    /// Bearing error over detection width (columns) of found rocks.
    pub bearing_ratios: Vec<f64>,
    /// Found rocks whose bearing error exceeds the downstream bound `1 px + 0.3 × width`.
    pub outside_bound: usize,
}

impl Score {
    /// Adds one image. The detector is scored on its boxes alone, whatever was measured of
    /// them later, so that a run and the detection benchmark give the same figures for the
    /// same detections.
    pub fn add(
        &mut self,
        detections: &[DetectedBox],
        rocks: &[VisibleRock],
        calib: &Calibration,
        detectable: Detectable,
    ) {
        let width = calib.image.width;
        let boxes: Vec<DetectedBox> = detections
            .iter()
            .map(|d| DetectedBox {
                measured: None,
                ..*d
            })
            .collect();
        let claims = claims(&boxes, rocks, width);
        let credited = credit(&claims, rocks.len());
        self.images += 1;
        self.detections += detections.len();
        self.true_detections += credited.iter().flatten().count();
        for (claim, rock) in claims.iter().zip(&credited) {
            match (claim, rock) {
                (_, Some(_)) => {}
                (Some(_), None) => self.splits += 1,
                (None, None) => self.false_alarms += 1,
            }
        }
        for (k, rock) in rocks.iter().enumerate() {
            if !detectable.holds(rock, calib) {
                continue;
            }
            self.detectable += 1;
            match credited.iter().position(|c| *c == Some(k)) {
                Some(i) => self.add_found(&detections[i], rock, calib),
                None if detections.iter().any(|d| covers(d, rock, width)) => self.merged += 1,
                None => {}
            }
        }
    }

    fn add_found(&mut self, d: &DetectedBox, rock: &VisibleRock, calib: &Calibration) {
        self.found += 1;
        let error = column_gap(d.centroid[0], rock.bearing_column, calib.image.width);
        let columns = f64::from(d.bbox[2] - d.bbox[0] + 1);
        self.bearing_errors.push(error);
        self.bearing_ratios.push(error / columns);
        if error > 1.0 + 0.3 * columns {
            self.outside_bound += 1;
        }
        if rock.contact[1] < f64::from(calib.image.height) {
            self.contact_errors
                .push((d.contact_row - rock.contact[1]).abs());
        }
    }

    /// Found over detectable.
    pub fn recall(&self) -> f64 {
        ratio(self.found, self.detectable)
    }

    /// Credited detections over all detections.
    pub fn precision(&self) -> f64 {
        ratio(self.true_detections, self.detections)
    }
}

/// Whether the rock's centroid lies inside the detection's box.
fn covers(d: &DetectedBox, rock: &VisibleRock, width: u32) -> bool {
    let w = f64::from(width);
    let lo = f64::from(d.bbox[0]);
    let mut hi = f64::from(d.bbox[2]) + 1.0;
    if hi < lo {
        hi += w;
    }
    (rock.centroid[0] - lo).rem_euclid(w) <= hi - lo
        && rock.centroid[1] >= f64::from(d.bbox[1])
        && rock.centroid[1] <= f64::from(d.bbox[3]) + 1.0
}

pub(super) fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
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

#[cfg(test)]
mod tests {
    use super::*;

    fn rock(id: u32, bbox: [u32; 4], range: f64) -> VisibleRock {
        let centroid = [
            f64::from(bbox[0] + bbox[2] + 1) / 2.0,
            f64::from(bbox[1] + bbox[3] + 1) / 2.0,
        ];
        VisibleRock {
            id,
            pixels: 20,
            bbox,
            centroid,
            bearing: 5.075,
            bearing_column: centroid[0],
            range,
            contact: [centroid[0], f64::from(bbox[3]) + 1.0],
        }
    }

    /// A stack seen on the 1 000-rock drive of `sparse-large` (station 281): the far rock's
    /// rows 159–162 lie just above the near rock's 164–167, at the same bearing.
    fn stack() -> Vec<VisibleRock> {
        vec![
            rock(731, [1411, 159, 1424, 162], 39.0),
            rock(844, [1413, 164, 1421, 167], 27.5),
        ]
    }

    /// One blob over both rocks, its centroid on the far one.
    fn blob(range: [f64; 2]) -> DetectedBox {
        DetectedBox {
            centroid: [1416.4, 162.7],
            bbox: [1411, 157, 1421, 167],
            contact_row: 168.0,
            measured: Some(Measured {
                bearing: 5.084,
                bearing_uncertainty: 0.0097,
                range,
            }),
        }
    }

    #[test]
    fn a_blob_over_a_stack_is_the_rock_its_measurement_fits() {
        assert_eq!(
            match_detections(&[blob([25.1, 30.4])], &stack(), 4096),
            vec![Some(1)]
        );
    }

    #[test]
    fn a_blob_fitting_no_rock_is_the_rock_under_its_centroid() {
        for range in [[10.0, 12.0], [25.1, 45.0]] {
            assert_eq!(
                match_detections(&[blob(range)], &stack(), 4096),
                vec![Some(0)]
            );
        }
    }

    #[test]
    fn without_a_measurement_the_centroid_decides() {
        let detector_only = DetectedBox {
            measured: None,
            ..blob([25.1, 30.4])
        };
        assert_eq!(
            match_detections(&[detector_only], &stack(), 4096),
            vec![Some(0)]
        );
    }

    #[test]
    fn a_fitting_claim_outranks_a_nearer_one_that_does_not_fit() {
        let piece = DetectedBox {
            centroid: [1417.4, 166.0],
            bbox: [1415, 165, 1420, 167],
            measured: Some(Measured {
                bearing: 5.075,
                bearing_uncertainty: 0.001,
                range: [10.0, 12.0],
            }),
            ..blob([25.1, 30.4])
        };
        assert_eq!(
            match_detections(&[piece, blob([25.1, 30.4])], &stack(), 4096),
            vec![None, Some(1)]
        );
    }

    /// A blob over the stack whose range interval holds both rocks: credited with the far
    /// one (nearest centroid), it also shows the near one, unless another detection is
    /// credited with it or the interval leaves it out.
    #[test]
    fn a_blob_whose_measurement_holds_both_rocks_also_shows_the_one_it_is_not_credited_with() {
        let both = blob([25.1, 45.0]);
        let credited = match_detections(&[both], &stack(), 4096);
        assert_eq!(credited, vec![Some(0)]);
        assert_eq!(also_shown(&both, &stack(), &credited, 4096), vec![1]);
        assert!(also_shown(&both, &stack(), &[Some(0), Some(1)], 4096).is_empty());
        let far_only = blob([30.0, 45.0]);
        assert!(also_shown(&far_only, &stack(), &credited, 4096).is_empty());
        let detector_only = DetectedBox {
            measured: None,
            ..both
        };
        assert!(also_shown(&detector_only, &stack(), &credited, 4096).is_empty());
    }
}
