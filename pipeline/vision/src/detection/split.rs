//! Splitting blobs that hold several rocks. A single rock's bottom edge, as a function of the
//! column, is concave (lowest in the middle, rising to both sides); rocks touching in the
//! image break that: side by side they leave a notch between their bottoms, and a nearer rock
//! in front of a farther one starts lower than the farther one's bottom. So a blob is cut at
//! the column where its bottom profile lies deepest under its concave hull, recursively, while
//! that depth is a sizeable part of the blob's height.

use super::components::Component;

/// Piece of a component after splitting, and whether its centroid is doubtful: its own
/// profile still looks like more than one rock (a notch too shallow to cut with confidence),
/// or it was cut from a nearer rock that may hide part of it.
pub(super) struct Piece {
    pub pixels: Component,
    pub ambiguous: bool,
}

/// Cut thresholds: a notch is cut when at least `max(min_depth, fraction × height)` rows deep
/// and both sides are at least `min_columns` wide; half that depth marks a piece ambiguous, and
/// so does a neighbouring piece whose bottom is lower by more than `min_depth`.
#[derive(Clone, Copy, Debug)]
pub(super) struct SplitRule {
    pub min_depth: f32,
    pub fraction: f32,
    pub min_columns: usize,
}

/// Per column: depth of `bottom` (row of the lowest pixel) under its upper concave hull.
fn notch_depths(bottom: &[f32]) -> Vec<f32> {
    let mut hull: Vec<usize> = Vec::with_capacity(bottom.len());
    for (i, &y) in bottom.iter().enumerate() {
        while hull.len() >= 2 {
            let (o, a) = (hull[hull.len() - 2], hull[hull.len() - 1]);
            let cross = (a - o) as f32 * (y - bottom[o]) - (bottom[a] - bottom[o]) * (i - o) as f32;
            if cross >= 0.0 {
                hull.pop();
            } else {
                break;
            }
        }
        hull.push(i);
    }
    let mut depths = vec![0.0; bottom.len()];
    for pair in hull.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let slope = (bottom[b] - bottom[a]) / (b - a) as f32;
        for (i, d) in depths.iter_mut().enumerate().take(b).skip(a + 1) {
            *d = bottom[a] + slope * (i - a) as f32 - bottom[i];
        }
    }
    depths
}

/// The deepest cuttable notch of columns `range` of the profile: (cut after this column,
/// depth), or the depth of the deepest notch if none may be cut.
fn deepest_notch(
    bottom: &[f32],
    top: &[f32],
    range: std::ops::Range<usize>,
    rule: SplitRule,
) -> Result<usize, f32> {
    let profile = &bottom[range.clone()];
    let height = profile.iter().copied().fold(f32::MIN, f32::max)
        - top[range.clone()].iter().copied().fold(f32::MAX, f32::min)
        + 1.0;
    let threshold = rule.min_depth.max(rule.fraction * height);
    let depths = notch_depths(profile);
    let n = depths.len();
    let inner = rule.min_columns.min(n)..n.saturating_sub(rule.min_columns);
    let best = inner
        .clone()
        .max_by(|&a, &b| depths[a].total_cmp(&depths[b]));
    match best {
        Some(i) if depths[i] >= threshold => Ok(range.start + i),
        _ => Err(depths.iter().copied().fold(0.0, f32::max) / threshold),
    }
}

/// Splits `pixels` (unwrapped columns) into its rocks.
pub(super) fn split(pixels: Component, rule: SplitRule) -> Vec<Piece> {
    let col_min = pixels.iter().map(|p| p.0).min().unwrap_or(0);
    let col_max = pixels.iter().map(|p| p.0).max().unwrap_or(0);
    let n = (col_max - col_min + 1) as usize;
    let (mut bottom, mut top) = (vec![f32::MIN; n], vec![f32::MAX; n]);
    for &(col, row) in &pixels {
        let c = (col - col_min) as usize;
        bottom[c] = bottom[c].max(row as f32);
        top[c] = top[c].min(row as f32);
    }
    let mut pending = Vec::with_capacity(4);
    pending.push(0..n);
    let mut done: Vec<(std::ops::Range<usize>, bool)> = Vec::new();
    while let Some(range) = pending.pop() {
        match deepest_notch(&bottom, &top, range.clone(), rule) {
            Ok(cut) => {
                pending.push(range.start..cut + 1);
                pending.push(cut + 1..range.end);
            }
            Err(relative) => done.push((range, relative >= 0.5)),
        }
    }
    if done.len() == 1 {
        return vec![Piece {
            pixels,
            ambiguous: done[0].1,
        }];
    }
    done.sort_by_key(|(r, _)| r.start);
    // A piece beside a nearer one (whose bottom is lower) may be partly hidden behind it: its
    // visible centroid is then off its bearing by up to half the hidden part.
    let lowest: Vec<f32> = done
        .iter()
        .map(|(r, _)| bottom[r.clone()].iter().copied().fold(f32::MIN, f32::max))
        .collect();
    for k in 0..done.len() {
        let left = k > 0 && lowest[k - 1] > lowest[k] + rule.min_depth;
        let right = k + 1 < done.len() && lowest[k + 1] > lowest[k] + rule.min_depth;
        if left || right {
            done[k].1 = true;
        }
    }
    let mut pieces: Vec<Piece> = done
        .iter()
        .map(|&(_, ambiguous)| Piece {
            pixels: Vec::new(),
            ambiguous,
        })
        .collect();
    for p in pixels {
        let c = (p.0 - col_min) as usize;
        let k = done.partition_point(|(r, _)| r.end <= c);
        pieces[k].pixels.push(p);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    const RULE: SplitRule = SplitRule {
        min_depth: 3.0,
        fraction: 0.15,
        min_columns: 3,
    };

    /// Pixels of the ellipse centred at (cx, cy) with half-axes (a, b).
    fn ellipse(cx: f32, cy: f32, a: f32, b: f32) -> Component {
        let mut out = Vec::new();
        for row in 0..200u32 {
            for col in 0..400u32 {
                let (x, y) = ((col as f32 - cx) / a, (row as f32 - cy) / b);
                if x * x + y * y <= 1.0 {
                    out.push((col, row));
                }
            }
        }
        out
    }

    fn union(a: Component, b: Component) -> Component {
        let mut all: Component = a.into_iter().chain(b).collect();
        all.sort_by_key(|&(c, r)| (r, c));
        all.dedup();
        all
    }

    #[test]
    fn concave_profile_has_no_notch() {
        let depths = notch_depths(&[1.0, 4.0, 6.0, 7.0, 6.0, 4.0, 1.0]);
        assert!(depths.iter().all(|&d| d.abs() < 1e-6), "{depths:?}");
        let depths = notch_depths(&[5.0, 6.0, 2.0, 6.0, 5.0]);
        assert_eq!(depths[2], 4.0);
    }

    #[test]
    fn one_ellipse_stays_whole() {
        let pieces = split(ellipse(100.0, 50.0, 30.0, 20.0), RULE);
        assert_eq!(pieces.len(), 1);
        assert!(!pieces[0].ambiguous);
    }

    /// Two rocks side by side, overlapping by a few columns: cut at the notch.
    #[test]
    fn side_by_side_rocks_are_cut_between_them() {
        let both = union(
            ellipse(100.0, 50.0, 30.0, 20.0),
            ellipse(155.0, 52.0, 28.0, 18.0),
        );
        let pieces = split(both, RULE);
        assert_eq!(pieces.len(), 2);
        let max_left = pieces[0].pixels.iter().map(|p| p.0).max().unwrap();
        assert!((125..=132).contains(&max_left), "{max_left}");
        assert!(pieces.iter().all(|p| !p.ambiguous));
    }

    /// A near rock in front of a far one (lower bottom, overlapping in columns): cut where the
    /// near rock starts, the far rock's visible part on the other side.
    #[test]
    fn near_rock_in_front_of_far_rock_is_cut_at_its_edge() {
        let near = ellipse(150.0, 80.0, 30.0, 20.0);
        let far = ellipse(105.0, 55.0, 30.0, 15.0);
        let pieces = split(union(far, near), RULE);
        assert_eq!(pieces.len(), 2);
        let max_left = pieces[0].pixels.iter().map(|p| p.0).max().unwrap();
        assert!((118..=130).contains(&max_left), "{max_left}");
        assert!(pieces[0].ambiguous, "the far rock may be partly hidden");
        assert!(!pieces[1].ambiguous);
    }
}
