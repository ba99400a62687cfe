//! Whether the landmarks a station matched sit where earlier stations placed them.
//!
//! A registration's pairs only have to fit the frame it registered against; a look-alike rock
//! a metre or two from the true one fits the loose placements of a far frame as well. Every
//! earlier station that shares a matched landmark and at least [`FEWEST_OTHERS`] others with
//! the current one is a second witness: the motion between the two stations, fitted on the
//! *other* shared landmarks, must bring the landmark's two placements within their ellipses
//! (plus the registration's slack), the same tolerance a registration pair meets. A landmark
//! placed beyond that at any such station is a different rock there, and its match is undone
//! (marsyard seed 3 at half resolution: landmark 9 took rock 16, 1.3 m from its own, at
//! stations 23 and 25 through one 4-pair registration, 10 unsound relations).
//!
//! The audit asks the same of two stations' frames after the fact ([`witness`]), and also
//! whether the motion puts one station's placement of the landmark on a rock the other
//! station saw apart from it ([`taken_for_another`]).
//!
//! Leaving a match out loses a sighting, never soundness: the caller holds the detection back
//! with the landmark as its only candidate, so it is fused later only as a new landmark, once
//! the map rejects the match.

use super::registration::{unmapped_partner, Frame, Motion, SLACK_M};
use super::{placement, Placed};
use qrm_core::map::LandmarkId;

/// Fewest other shared landmarks that fix the motion between two stations.
pub const FEWEST_OTHERS: usize = 3;

/// The landmarks of `current` (matched at this station, placed around it) whose placement
/// disagrees with theirs at one of the `earlier` stations: off the motion that at least
/// [`FEWEST_OTHERS`] other shared landmarks agree on ([`Motion::agreed`]).
pub fn disagreeing<'f>(
    current: &[(LandmarkId, Placed)],
    earlier: impl IntoIterator<Item = &'f Frame>,
) -> Vec<LandmarkId> {
    let mut out: Vec<LandmarkId> = earlier
        .into_iter()
        .flat_map(|frame| {
            let shared = shared(current, frame);
            let pairs: Vec<(Placed, Placed)> = shared.iter().map(|s| s.1).collect();
            let agree = Motion::agreed(&pairs, FEWEST_OTHERS);
            shared
                .iter()
                .zip(agree.unwrap_or_default())
                .filter(|(_, agrees)| !agrees)
                .map(|(s, _)| s.0)
                .collect::<Vec<_>>()
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// The landmarks of `current` that `frame` places too, with both placements.
fn shared(current: &[(LandmarkId, Placed)], frame: &Frame) -> Vec<(LandmarkId, (Placed, Placed))> {
    current
        .iter()
        .filter_map(|&(l, p)| Some((l, (p, frame.landmarks.iter().find(|m| m.0 == l)?.1))))
        .collect()
}

/// What the two stations' frames `a` and `b` say of landmark `l`, both placing it: `Some(true)`
/// when the motion between them that at least [`FEWEST_OTHERS`] other shared landmarks agree
/// on brings its two placements together, `Some(false)` when it does not, or when it brings
/// one station's placement onto a rock the other station saw apart from the landmark
/// ([`taken_for_another`]), `None` when too few others are shared to say.
pub fn witness(a: &Frame, b: &Frame, l: LandmarkId) -> Option<bool> {
    Witness::new(a, b).of(l)
}

/// Two stations' frames as witnesses of every landmark both place ([`witness`]). Which shared
/// landmarks agree on one motion does not depend on the landmark asked about, so it is found
/// once per pair of frames: the audit asks of every landmark of a station against every other
/// station, and finding it per landmark was an eighth of a marsyard run's CPU (`perf`, stop 77).
pub struct Witness<'f> {
    a: &'f Frame,
    b: &'f Frame,
    pairs: Vec<(LandmarkId, (Placed, Placed))>,
    /// Which of `pairs` agree on one motion ([`Motion::agreed`]); none when too few do.
    agree: Option<Vec<bool>>,
}

impl<'f> Witness<'f> {
    pub fn new(a: &'f Frame, b: &'f Frame) -> Witness<'f> {
        let pairs = shared(&a.landmarks, b);
        let placements: Vec<(Placed, Placed)> = pairs.iter().map(|s| s.1).collect();
        let agree = Motion::agreed(&placements, FEWEST_OTHERS);
        Witness { a, b, pairs, agree }
    }

    /// What the two frames say of landmark `l` ([`witness`]).
    pub fn of(&self, l: LandmarkId) -> Option<bool> {
        let k = self.pairs.iter().position(|s| s.0 == l)?;
        let agree = self.agree.as_ref()?;
        let others = agree.iter().filter(|&&a| a).count() - usize::from(agree[k]);
        if others < FEWEST_OTHERS {
            return None;
        }
        if !agree[k] {
            return Some(false);
        }
        let fitted: Vec<(Placed, Placed)> = (0..self.pairs.len())
            .filter(|&j| j != k && agree[j])
            .map(|j| self.pairs[j].1)
            .collect();
        let swapped: Vec<(Placed, Placed)> = fitted.iter().map(|&(p, q)| (q, p)).collect();
        let (p, q) = self.pairs[k].1;
        Some(
            !taken_for_another(&Motion::fit(&fitted), &p, self.b, &q)
                && !taken_for_another(&Motion::fit(&swapped), &q, self.a, &p),
        )
    }
}

/// Whether one station's placements `a` and `b` are of two rocks: apart by more than the
/// registration's slack beyond their ellipses.
fn apart(a: &Placed, b: &Placed) -> bool {
    let separation = placement::separation(a, b, 0.0);
    separation.distance > separation.gate + SLACK_M
}

/// Whether `motion` puts placement `p` of a landmark, unambiguously, on one of `frame`'s
/// unmapped rocks (its held-back or given-up detections: [`unmapped_partner`], every other
/// rock the frame places, the landmark's among them, clearly farther) that its station saw
/// [`apart`] from its own placement `own` of the landmark. Rocks closer together than their
/// placements' tolerance pass the motion's test as one; a station that saw both apart tells
/// them apart. JPEG marsyard seed 11: landmark 25 took rocks 0.66 m apart (a blob holding both
/// at station 35 joined them), while stations 22 and 42 each saw the other rock beside it;
/// grayscale marsyard seed 13: landmark 15, rocks 15 and 29. Without it the audit missed both,
/// and the sightings later stations added to them made 2 and 3 unsound relations.
fn taken_for_another(motion: &Motion, p: &Placed, frame: &Frame, own: &Placed) -> bool {
    unmapped_partner(motion, p, frame).is_some_and(|u| apart(own, &frame.unmapped[u]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(points: &[(LandmarkId, [f64; 2])]) -> Frame {
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: points
                .iter()
                .map(|&(l, point)| (l, Placed::disc(point, 0.3)))
                .collect(),
        }
    }

    /// Rocks around an earlier station, and the same rocks seen from 2 m further on, turned
    /// by 0.3 rad.
    fn seen_from_both(rocks: &[[f64; 2]]) -> (Frame, Vec<(LandmarkId, Placed)>) {
        let (sin, cos) = 0.3f64.sin_cos();
        let earlier = rocks
            .iter()
            .enumerate()
            .map(|(l, &p)| (l as LandmarkId, p))
            .collect::<Vec<_>>();
        let current = rocks
            .iter()
            .enumerate()
            .map(|(l, &[x, y])| {
                let (x, y) = (x - 2.0, y);
                let point = [cos * x + sin * y, -sin * x + cos * y];
                (l as LandmarkId, Placed::disc(point, 0.3))
            })
            .collect();
        (frame(&earlier), current)
    }

    const ROCKS: [[f64; 2]; 5] = [
        [5.0, 1.0],
        [3.0, -4.0],
        [-2.0, 6.0],
        [8.0, 5.0],
        [-4.0, -3.0],
    ];

    #[test]
    fn landmarks_where_the_earlier_station_placed_them_agree() {
        let (earlier, current) = seen_from_both(&ROCKS);
        assert!(disagreeing(&current, &[earlier]).is_empty());
    }

    #[test]
    fn a_landmark_matched_to_a_rock_a_metre_and_a_half_away_disagrees() {
        let mut moved = ROCKS;
        moved[1][0] += 1.5;
        let (_, current) = seen_from_both(&moved);
        let (earlier, _) = seen_from_both(&ROCKS);
        assert_eq!(disagreeing(&current, &[earlier]), vec![1]);
    }

    /// The test drive (`test_drive`) with its wrong association from station 12 on. Each
    /// station's matches go through [`disagreeing`] against the stations before when `check`;
    /// an undone match makes `B` a landmark of its own (100). Returns the map's unsound
    /// relations against the truth and the stations it rejected.
    fn drive_with_a_wrong_association(check: bool) -> (usize, usize) {
        use super::super::test_drive::{seen, unsound, A, B, STATIONS};
        use qrm_core::edc::Edc;
        use qrm_core::map::Hypergraph;
        let mut b_landmark = A as LandmarkId;
        let mut map = Hypergraph::<Edc>::new();
        let mut history: Vec<Frame> = Vec::new();
        let mut rejected = 0;
        for step in 0..STATIONS {
            let seen = seen(step, 12);
            if check {
                let label = |r: usize| if r == B { b_landmark } else { r as LandmarkId };
                if disagreeing(&seen.frame(label).landmarks, &history).contains(&b_landmark) {
                    b_landmark = 100;
                }
            }
            let label = |r: usize| if r == B { b_landmark } else { r as LandmarkId };
            if map
                .fuse(&map.observations(&seen.view, &seen.sightings(label)))
                .is_err()
            {
                rejected += 1;
                continue;
            }
            history.push(seen.frame(label));
        }
        let rock_of = |l: LandmarkId| if l == 100 { B } else { l as usize };
        (unsound(&map, rock_of), rejected)
    }

    #[test]
    fn a_wrong_association_injected_into_a_drive_is_undone_and_the_map_stays_sound() {
        let (unsound, rejected) = drive_with_a_wrong_association(false);
        assert!(
            unsound > 0 && rejected == 0,
            "the injected association should make the map quietly unsound: {unsound} unsound, \
             {rejected} stations rejected"
        );
        assert_eq!(drive_with_a_wrong_association(true), (0, 0));
    }

    /// Two stations placing ROCKS as landmarks without motion between them, tightly (0.2 m)
    /// but for the second station's landmark 1, loose (0.6 m) and `offset` along x from the
    /// first station's; the first station also saw a rock `beside` its landmark 1, along x.
    fn beside(offset: f64, beside: Option<f64>) -> (Frame, Frame) {
        let placed = |l: usize, p: [f64; 2], r: f64| (l as LandmarkId, Placed::disc(p, r));
        let tight: Vec<(LandmarkId, Placed)> =
            (0..ROCKS.len()).map(|l| placed(l, ROCKS[l], 0.2)).collect();
        let mut a = frame(&[]);
        a.landmarks = tight.clone();
        a.unmapped = beside
            .map(|x| Placed::disc([ROCKS[1][0] + x, ROCKS[1][1]], 0.2))
            .into_iter()
            .collect();
        let mut b = frame(&[]);
        b.landmarks = tight;
        b.landmarks[1] = placed(1, [ROCKS[1][0] + offset, ROCKS[1][1]], 0.6);
        (a, b)
    }

    /// The loose placement fits the landmark's tolerance, but lies on the rock the first
    /// station saw a metre beside it: the stations saw two rocks as the landmark, whichever
    /// frame is asked first.
    #[test]
    fn a_placement_on_a_rock_the_other_station_saw_apart_disagrees() {
        let (a, b) = beside(0.9, None);
        assert_eq!(witness(&a, &b, 1), Some(true));
        let (a, b) = beside(0.9, Some(1.0));
        assert_eq!(witness(&a, &b, 1), Some(false));
        assert_eq!(witness(&b, &a, 1), Some(false));
        // An unmapped rock the first station could not tell from its landmark (a piece of
        // it) says nothing.
        let (a, b) = beside(0.55, Some(0.6));
        assert_eq!(witness(&a, &b, 1), Some(true));
    }

    #[test]
    fn too_few_other_shared_landmarks_are_no_witness() {
        let mut moved = ROCKS;
        moved[1][0] += 1.5;
        let (_, current) = seen_from_both(&moved[..3]);
        let (earlier, _) = seen_from_both(&ROCKS);
        assert!(disagreeing(&current, &[earlier]).is_empty());
    }
}
