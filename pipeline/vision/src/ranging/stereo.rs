//! Left–right correspondence of detections for the stereo cue.
//!
//! The rotating head's right camera sees a rock at range `d` turned by `2·asin(b / 2d)` in
//! azimuth from where the left one sees it, always in the same direction, at the same rows.
//! A pair is admissible when that azimuth difference lies in what the ranges from
//! `min_range_m` to infinity allow, the rows agree and the sizes and colours are alike; each
//! left detection takes its cheapest admissible partner, kept only when the choice is mutual
//! and unambiguous, so that a doubtful pair gives no stereo cue rather than a wrong one.

use super::{azimuth_difference, SensorModel};
use crate::calib::Calibration;
use crate::detection::{Detection, Separation};

/// For each primary (left) detection, the index of its right-panorama partner, if any.
pub fn match_stereo(
    left: &[Detection],
    right: &[Detection],
    calib: &Calibration,
    model: &SensorModel,
) -> Vec<Option<usize>> {
    // A right detection the detector doubts, or one touching another, may be several rocks or
    // part of one: its centroid would corrupt both the range and the bearing.
    let width = calib.image.width;
    let trusted: Vec<bool> = (0..right.len())
        .map(|j| !right[j].ambiguous && !super::touches_neighbour(j, right, width))
        .collect();
    let cost: Vec<Vec<Option<f64>>> = left
        .iter()
        .map(|l| {
            right
                .iter()
                .map(|r| pair_cost(l, r, calib, model))
                .collect()
        })
        .collect();
    let best_right = |i: usize| best_of(cost[i].iter().copied().enumerate());
    let best_left = |j: usize| best_of(cost.iter().map(|row| row[j]).enumerate());
    (0..left.len())
        .map(|i| {
            // A part of a blob separated by parallax has no counterpart: the right panorama's
            // blob still holds both rocks, and pairing with it would bend bearing and range.
            if left[i].separation != Separation::Whole {
                return None;
            }
            // Nor has a piece touching another: its partner may be the whole rock, whose
            // centroid lies elsewhere (marsyard seed 7, station 26: a piece of a rock filling
            // a third of the view took the whole rock's centroid, 0.2 m too near).
            if super::touches_neighbour(i, left, width) {
                return None;
            }
            // The best partner, if it is a doubtful detection, gives no cue: falling back to
            // the runner-up would pair the rock with a neighbour.
            let (j, _) = best_right(i)?;
            (trusted[j] && best_left(j).map(|(k, _)| k) == Some(i)).then_some(j)
        })
        .collect()
}

/// The cheapest candidate, unless a second one is nearly as cheap (ambiguous).
fn best_of(candidates: impl Iterator<Item = (usize, Option<f64>)>) -> Option<(usize, f64)> {
    let mut scored: Vec<(usize, f64)> = candidates.filter_map(|(i, c)| Some((i, c?))).collect();
    scored.sort_by(|a, b| a.1.total_cmp(&b.1));
    match scored.as_slice() {
        [] => None,
        [only] => Some(*only),
        [first, second, ..] => (first.1 < 0.6 * second.1 + 0.05).then_some(*first),
    }
}

/// Dissimilarity of a left and a right detection, or `None` if they cannot be one rock.
fn pair_cost(
    l: &Detection,
    r: &Detection,
    calib: &Calibration,
    model: &SensorModel,
) -> Option<f64> {
    let column_width = calib.column_width();
    let width = |d: &Detection| f64::from(d.bbox[2].saturating_sub(d.bbox[0]) + 1);
    let height = |d: &Detection| f64::from(d.bbox[3].saturating_sub(d.bbox[1]) + 1);
    let tolerance = (model.disparity_error_px
        + model.disparity_error_per_width * 0.5 * (width(l) + width(r)))
        * column_width;
    let disparity = azimuth_difference(calib.azimuth(r.centroid[0]), calib.azimuth(l.centroid[0]));
    let largest = calib.stereo_disparity(model.min_range_m);
    if disparity < -tolerance || disparity > largest + tolerance {
        return None;
    }
    let rows = 2.0 + 0.2 * height(l).max(height(r));
    let contact = (l.contact_row - r.contact_row).abs();
    let centre = (l.centroid[1] - r.centroid[1]).abs();
    if contact > rows || centre > rows {
        return None;
    }
    let size_ratio = f64::from(l.pixels.max(1)) / f64::from(r.pixels.max(1));
    if !(0.5..=2.0).contains(&size_ratio) {
        return None;
    }
    let colour: f64 = l
        .appearance
        .colour
        .iter()
        .zip(&r.appearance.colour)
        .map(|(a, b)| f64::from(a - b).powi(2))
        .sum::<f64>()
        .sqrt();
    Some(contact / rows + centre / rows + size_ratio.ln().abs() + colour / 0.02)
}
