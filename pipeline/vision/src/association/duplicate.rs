//! One rock, two landmarks: which landmarks two stations' frames put on each other.
//!
//! A rock the drive lost sight of and came back to can found a second landmark: once its first
//! landmark has left the recent frames, nothing places the later sightings on it. The map then
//! holds two landmarks of one rock, and the older one, no longer seen, stays a look-alike no
//! frame places: every later observation that looks like it keeps it as a rival, and the end of
//! the drive names none of them (colour marsyard s31 at stop 77: landmark 15, fused at
//! stations 3–9, and landmark 30, stations 16–49, both rock 19).
//!
//! Two frames that share enough landmarks to fix the motion between them (the shared
//! landmarks that agree on one motion, as [`super::agreement::witness`] finds them) compare
//! the landmarks each places and the other does not: the motion puts two of them on each
//! other when their placements meet and every other placement of either frame lies clearly
//! farther, both ways (the test of a registration's unambiguous pair), and apart when they lie
//! beyond their placements and the slack.

use super::agreement::FEWEST_OTHERS;
use super::registration::{shared_placements, Frame, Motion, ANCHOR_RADIUS_M, SLACK_M, UNIQUE};
use super::Placed;
use qrm_core::map::LandmarkId;

/// What two frames say of the landmarks each places and the other does not.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Comparison {
    /// `(a's landmark, b's landmark)` the motion puts on each other, unambiguously both ways.
    pub same: Vec<(LandmarkId, LandmarkId)>,
    /// `(a's landmark, b's landmark)` the motion puts clearly apart.
    pub apart: Vec<(LandmarkId, LandmarkId)>,
}

/// Compares the landmarks frame `a` places and `b` does not with those `b` places and `a`
/// does not, by the motion their shared landmarks agree on; nothing when fewer than
/// [`FEWEST_OTHERS`] agree ([`Motion::agreed`] says none then). Placements looser than a
/// registration anchors by ([`ANCHOR_RADIUS_M`]) are left out.
pub fn compare(a: &Frame, b: &Frame) -> Comparison {
    let pairs = shared_placements(a, b);
    let Some(agree) = Motion::agreed(&pairs, FEWEST_OTHERS) else {
        return Comparison::default();
    };
    let fitted: Vec<(Placed, Placed)> = pairs
        .iter()
        .zip(&agree)
        .filter(|(_, &agrees)| agrees)
        .map(|(pair, _)| *pair)
        .collect();
    let forward = Motion::fit(&fitted);
    let swapped: Vec<(Placed, Placed)> = fitted.iter().map(|&(p, q)| (q, p)).collect();
    let backward = Motion::fit(&swapped);
    let (in_a, in_b) = (only_in(a, b), only_in(b, a));
    let mut out = Comparison::default();
    for &(la, pa) in &in_a {
        for &(lb, pb) in &in_b {
            let separation = forward.separation(&pa, &pb);
            if separation.distance > separation.gate + SLACK_M {
                out.apart.push((la, lb));
            } else if separation.within()
                && alone(&forward, &pa, b, lb, separation.distance)
                && alone(
                    &backward,
                    &pb,
                    a,
                    la,
                    backward.separation(&pb, &pa).distance,
                )
            {
                out.same.push((la, lb));
            }
        }
    }
    out
}

/// The landmarks `frame` places, tightly enough to anchor, that `other` does not place.
fn only_in(frame: &Frame, other: &Frame) -> Vec<(LandmarkId, Placed)> {
    frame
        .landmarks
        .iter()
        .filter(|(l, p)| p.reach() <= ANCHOR_RADIUS_M && !other.landmarks.iter().any(|m| m.0 == *l))
        .copied()
        .collect()
}

/// Whether every placement of `frame` but its landmark `own`'s, its unmapped rocks' too, lies
/// clearly farther from where `motion` puts `p` than `distance` ([`UNIQUE`] times, plus the
/// slack).
fn alone(motion: &Motion, p: &Placed, frame: &Frame, own: LandmarkId, distance: f64) -> bool {
    let clear = UNIQUE * distance + SLACK_M;
    frame
        .landmarks
        .iter()
        .filter(|(l, _)| *l != own)
        .map(|(_, q)| q)
        .chain(&frame.unmapped)
        .all(|q| motion.separation(p, q).distance > clear)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(points: &[(LandmarkId, [f64; 2])], unmapped: &[[f64; 2]]) -> Frame {
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: unmapped.iter().map(|&p| Placed::disc(p, 0.3)).collect(),
            landmarks: points
                .iter()
                .map(|&(l, point)| (l, Placed::disc(point, 0.3)))
                .collect(),
        }
    }

    /// Rocks 0–3 seen from two stations 3 m apart, the second turned by 0.4 rad, and rock `x`
    /// at (5, 2): `a` holds it as landmark 10, `b` as `b_label`, at `b_offset` from where it
    /// lies.
    fn pair(b_label: LandmarkId, b_offset: [f64; 2], b_unmapped: &[[f64; 2]]) -> (Frame, Frame) {
        let rocks: [[f64; 2]; 4] = [[4.0, -3.0], [-2.0, 5.0], [8.0, 4.0], [1.0, -6.0]];
        let x = [5.0, 2.0];
        let (sin, cos) = 0.4f64.sin_cos();
        let seen_from_b = |[px, py]: [f64; 2]| {
            let (px, py) = (px - 3.0, py);
            [cos * px + sin * py, -sin * px + cos * py]
        };
        let a: Vec<(LandmarkId, [f64; 2])> = rocks
            .iter()
            .enumerate()
            .map(|(l, &p)| (l as LandmarkId, p))
            .chain([(10, x)])
            .collect();
        let b: Vec<(LandmarkId, [f64; 2])> = rocks
            .iter()
            .enumerate()
            .map(|(l, &p)| (l as LandmarkId, seen_from_b(p)))
            .chain([(
                b_label,
                seen_from_b([x[0] + b_offset[0], x[1] + b_offset[1]]),
            )])
            .collect();
        let unmapped: Vec<[f64; 2]> = b_unmapped.iter().map(|&p| seen_from_b(p)).collect();
        (frame(&a, &[]), frame(&b, &unmapped))
    }

    #[test]
    fn a_rock_each_frame_holds_under_its_own_landmark_is_put_on_itself() {
        let (a, b) = pair(20, [0.1, -0.1], &[]);
        let comparison = compare(&a, &b);
        assert_eq!(comparison.same, vec![(10, 20)]);
        assert!(comparison.apart.is_empty());
        assert_eq!(compare(&b, &a).same, vec![(20, 10)]);
    }

    #[test]
    fn landmarks_of_rocks_two_metres_apart_are_apart() {
        let (a, b) = pair(20, [2.0, 0.0], &[]);
        let comparison = compare(&a, &b);
        assert!(comparison.same.is_empty());
        assert_eq!(comparison.apart, vec![(10, 20)]);
    }

    /// Another rock the second station saw beside it (unmapped there) could be the first
    /// station's landmark as well: nothing is said.
    #[test]
    fn a_rock_beside_it_leaves_the_pair_undecided() {
        let (a, b) = pair(20, [0.2, 0.0], &[[5.5, 2.0]]);
        let comparison = compare(&a, &b);
        assert!(comparison.same.is_empty());
        assert!(comparison.apart.is_empty());
    }

    #[test]
    fn frames_sharing_too_few_landmarks_say_nothing() {
        let (a, mut b) = pair(20, [0.0, 0.0], &[]);
        b.landmarks.retain(|(l, _)| *l >= 2);
        assert_eq!(compare(&a, &b), Comparison::default());
    }
}
