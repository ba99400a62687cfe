//! Held-back detections recognised at a later station (issue 13, item 3: association decided
//! across stations rather than held and given up).
//!
//! A detection the map could not tell from its look-alikes is held back, and its placement
//! stays in its station's frame as an unmapped rock. A later station that registers against
//! that frame and anchors one of its own detections to a landmark, where the motion puts that
//! detection on the unmapped rock and on nothing else, has seen the same rock twice: the
//! held-back detection is that landmark. The anchor carries the identity (its appearance,
//! several frames' agreement, the map's consistency test); the registration carries it back
//! to the earlier station, by the same unambiguous-partner test that pairs a detection with
//! a landmark ([`Registration::recognised`]).

use super::placement::Placed;
use super::registration::{
    partner_among, shared_placements, Frame, Motion, Registration, MIN_INLIERS, SLACK_M, UNIQUE,
};
use qrm_core::map::{LandmarkId, Sighting};

/// An unmapped rock of a registered station's frame recognised as a landmark.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Recognition {
    /// The frame, by index into the frames association registered against.
    pub frame: usize,
    /// The rock's placement among the frame's unmapped rocks.
    pub unmapped: Placed,
    /// The current station's detection (position in its view) anchored at the rock.
    pub detection: usize,
    pub landmark: LandmarkId,
}

/// The unmapped rocks of the registered station frames (not the sketch, whose unmapped rocks
/// belong to no one station) recognised by the `anchored` detections: only under a motion
/// whose pairs agree with the anchors (at least [`MIN_INLIERS`] of them anchored, none
/// pairing an anchored detection or landmark otherwise), only for firm detections (a doubted
/// one's placement is looser than it says), and not where the frame holds the landmark (its
/// station mapped that rock already).
pub fn recognitions(
    frames: &[Frame],
    registrations: &[(&Frame, Registration)],
    placed: &[Option<Placed>],
    doubtful: &[bool],
    anchored: &[Sighting],
) -> Vec<Recognition> {
    let agrees = |r: &Registration| {
        let anchor = |&(i, l): &(usize, LandmarkId)| {
            anchored.iter().any(|a| a.position == i && a.landmark == l)
        };
        let conflicts = |&(i, l): &(usize, LandmarkId)| {
            anchored
                .iter()
                .any(|a| (a.position == i) != (a.landmark == l))
        };
        r.pairs.iter().filter(|p| anchor(p)).count() >= MIN_INLIERS
            && !r.pairs.iter().any(conflicts)
    };
    registrations
        .iter()
        .filter(|(frame, r)| !frame.accumulated && agrees(r))
        .filter_map(|(frame, r)| {
            let index = frames.iter().position(|f| std::ptr::eq(f, *frame))?;
            Some((index, *frame, r))
        })
        .flat_map(|(index, frame, r)| {
            anchored
                .iter()
                .filter(|a| !doubtful[a.position])
                .filter(|a| !frame.landmarks.iter().any(|m| m.0 == a.landmark))
                .filter_map(move |a| {
                    let g = r.recognised(frame, placed, a.position)?;
                    Some(Recognition {
                        frame: index,
                        unmapped: frame.unmapped[g],
                        detection: a.position,
                        landmark: a.landmark,
                    })
                })
        })
        .collect()
}

/// What another station's frame says of the rocks a station's frame left unmapped
/// ([`read_unmapped`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UnmappedReading {
    /// The unmapped rocks that landmarks of the other frame lie on: (index into
    /// [`Frame::unmapped`], landmark).
    pub named: Vec<(usize, LandmarkId)>,
    /// Every landmark of the other frame that the frame does not hold, against every unmapped
    /// rock: (index into [`Frame::unmapped`], landmark, whether the motion leaves the two
    /// placements within each other's reach, so that the landmark may be that rock).
    pub may_be: Vec<(usize, LandmarkId, bool)>,
}

/// What another station's frame `other` says of station frame `frame`'s unmapped rocks,
/// through the landmarks `frame` does not hold; nothing when the two fix no motion. The
/// motion is the one the landmarks both hold agree on ([`Motion::consensus`], at least
/// [`MIN_INLIERS`]): known identities, not look-alikes, so no hypothesis is chosen. A
/// landmark names a rock by the unambiguous-partner test a live recognition passes, less
/// what the two frames know of the crowd ([`named_partner`]). Run once the drive is over
/// (`Mapper::finish`), it lets any station that saw a rock speak for a detection of it that
/// no station recent enough to register against could name, and any station that saw a
/// landmark elsewhere rule it out.
pub fn read_unmapped(frame: &Frame, other: &Frame) -> UnmappedReading {
    let Some(motion) = Motion::consensus(shared_placements(other, frame), MIN_INLIERS) else {
        return UnmappedReading::default();
    };
    let unheld: Vec<&(LandmarkId, Placed)> = other
        .landmarks
        .iter()
        .filter(|(l, _)| !frame.landmarks.iter().any(|(m, _)| m == l))
        .collect();
    let named = unheld
        .iter()
        .filter_map(|(l, q)| {
            let g = named_partner(&motion, q, frame, other)?;
            let rock = &frame.unmapped[g];
            // Nor may another landmark of `other`, or a rock it left unmapped, lie on the
            // rock: then it may be that one (colour marsyard s41: a rock 1.4 m from another's
            // landmark; stress s45: a rock 0.7 m from a landmark, which frames that held it
            // named it, where other frames saw the rock apart from it, unmapped).
            let near = UNIQUE * motion.separation(q, rock).distance + SLACK_M;
            let alone = other
                .landmarks
                .iter()
                .filter(|(m, _)| m != l)
                .map(|(_, o)| o)
                .chain(&other.unmapped)
                .all(|o| motion.separation(o, rock).distance > near);
            alone.then_some((g, *l))
        })
        .collect();
    let motion = &motion;
    let may_be = frame
        .unmapped
        .iter()
        .enumerate()
        .flat_map(|(g, rock)| {
            unheld
                .iter()
                .map(move |(l, q)| (g, *l, motion.separation(q, rock).within()))
        })
        .collect();
    UnmappedReading { named, may_be }
}

/// The unmapped rock of `frame` (index into [`Frame::unmapped`]) that `motion` puts `other`'s
/// placement `q` of a landmark on: a live recognition's unambiguous-partner test
/// ([`partner_among`]), less what the two frames already know of the crowd. The frame's
/// landmarks are rocks its station fused as other landmarks, so none is the one `q` places;
/// and another unmapped rock of the frame is another placement's of `other` (a landmark or a
/// rock it left unmapped) when that one lies within its reach and nearer to it than `q`: each
/// of `other`'s placements claims the rock nearest it, the identities decided jointly. On
/// JPEG marsyard s3 after stop 82, of the correct observations of mapped rocks that no frame
/// named, 44 were crowded mostly by a landmark of their own station's frame and 105 by another
/// held-back detection of their station. Taking both out of the crowd added 440 sightings of
/// their rock, 11 of another and 5 of none over 53 sets (docs/RUN.md, stop 83).
fn named_partner(motion: &Motion, q: &Placed, frame: &Frame, other: &Frame) -> Option<usize> {
    let claimed = |rock: &Placed| {
        let ours = motion.separation(q, rock).distance;
        other
            .landmarks
            .iter()
            .map(|m| &m.1)
            .chain(&other.unmapped)
            .filter(|&x| x != q)
            .any(|x| {
                let theirs = motion.separation(x, rock);
                theirs.within() && theirs.distance < ours
            })
    };
    partner_among(motion, q, frame, |o, is_landmark| {
        !is_landmark && !claimed(o)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::association::registration::tests::FIELD;

    /// A station's frame: FIELD's first four rocks as landmarks 0‥3, and an unmapped rock (a
    /// held-back detection) at FIELD's fifth.
    fn frame() -> Frame {
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: vec![Placed::disc(FIELD[4], 0.3)],
            landmarks: (0..4)
                .map(|k| (k as LandmarkId, Placed::disc(FIELD[k], 0.3)))
                .collect(),
        }
    }

    /// The current station, registered without motion: detections 0‥3 at the frame's
    /// landmarks and anchored to them, detection 4 beside the unmapped rock anchored to
    /// landmark 9, and the `extra` detections.
    fn recognised(frames: &[Frame], extra: &[[f64; 2]], doubtful_4: bool) -> Vec<Recognition> {
        let registration = Registration {
            pairs: (0..4).map(|k| (k, k as LandmarkId)).collect(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let mut points: Vec<[f64; 2]> = FIELD[..4].to_vec();
        points.push([8.1, 8.0]);
        points.extend(extra);
        let placed: Vec<Option<Placed>> =
            points.iter().map(|&p| Some(Placed::disc(p, 0.3))).collect();
        let mut doubtful = vec![false; placed.len()];
        doubtful[4] = doubtful_4;
        let anchored: Vec<Sighting> = (0..4)
            .map(|k| Sighting::new(k, k as LandmarkId))
            .chain([Sighting::new(4, 9)])
            .collect();
        let registrations: Vec<(&Frame, Registration)> =
            frames.iter().map(|f| (f, registration.clone())).collect();
        recognitions(frames, &registrations, &placed, &doubtful, &anchored)
    }

    #[test]
    fn an_anchor_at_an_unmapped_rock_recognises_it() {
        let frames = [frame()];
        assert_eq!(
            recognised(&frames, &[], false),
            [Recognition {
                frame: 0,
                unmapped: Placed::disc(FIELD[4], 0.3),
                detection: 4,
                landmark: 9,
            }]
        );
    }

    /// Another detection as near the rock, another unmapped rock as near the anchor, or a
    /// doubted anchor: the rock may be another one, and nothing is recognised.
    #[test]
    fn a_rival_or_a_doubted_anchor_recognises_nothing() {
        let frames = [frame()];
        assert_eq!(recognised(&frames, &[[7.9, 8.0]], false), []);
        assert_eq!(recognised(&frames, &[], true), []);
        let mut crowded = frame();
        crowded.unmapped.push(Placed::disc([8.3, 8.1], 0.3));
        assert_eq!(recognised(&[crowded], &[], false), []);
    }

    /// The sketch's unmapped rocks belong to no one station, and a station that mapped the
    /// landmark already saw its rock as that landmark.
    #[test]
    fn neither_the_sketch_nor_a_station_holding_the_landmark_recognises() {
        let mut sketch = frame();
        sketch.accumulated = true;
        assert_eq!(recognised(&[sketch], &[], false), []);
        let mut holding = frame();
        holding.landmarks.push((9, Placed::disc([-6.0, -3.0], 0.3)));
        assert_eq!(recognised(&[holding], &[], false), []);
    }

    /// Another station's frame, 2 m further along x: FIELD's first four rocks as landmarks
    /// 0‥3, its fifth as landmark 9, and the `extra` landmarks and `unmapped` rocks.
    fn other_frame(extra: &[(LandmarkId, [f64; 2])], unmapped: &[[f64; 2]]) -> Frame {
        let seen = |p: [f64; 2]| Placed::disc([p[0] - 2.0, p[1]], 0.3);
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: unmapped.iter().map(|&p| seen(p)).collect(),
            landmarks: (0..4)
                .map(|k| (k as LandmarkId, seen(FIELD[k])))
                .chain([(9, seen(FIELD[4]))])
                .chain(extra.iter().map(|&(l, p)| (l, seen(p))))
                .collect(),
        }
    }

    #[test]
    fn another_frame_names_an_unmapped_rock_by_the_shared_landmarks_motion() {
        assert_eq!(
            read_unmapped(&frame(), &other_frame(&[], &[])).named,
            [(0, 9)]
        );
    }

    /// Every landmark the frame does not hold is read against every unmapped rock: the one
    /// on it may be that rock, one 5 m from it may not.
    #[test]
    fn a_landmark_apart_from_an_unmapped_rock_may_not_be_it() {
        let far = [FIELD[4][0] + 5.0, FIELD[4][1]];
        assert_eq!(
            read_unmapped(&frame(), &other_frame(&[(7, far)], &[])).may_be,
            [(0, 9, true), (0, 7, false)]
        );
    }

    /// A landmark of the frame beside the rock is another rock its station fused: it does
    /// not crowd the rock the other frame's landmark lands on.
    #[test]
    fn a_landmark_of_the_frame_beside_the_rock_does_not_crowd_it() {
        let mut frame = frame();
        frame.landmarks.push((6, Placed::disc([8.2, 8.1], 0.3)));
        assert_eq!(
            read_unmapped(&frame, &other_frame(&[], &[])).named,
            [(0, 9)]
        );
    }

    /// Another unmapped rock of the frame beside the rock crowds it, unless a placement of
    /// the other frame lies nearer to it: then it is that one's.
    #[test]
    fn an_unmapped_rock_beside_crowds_unless_another_placement_claims_it() {
        let mut frame = frame();
        frame.unmapped.push(Placed::disc([8.28, 8.0], 0.3));
        assert_eq!(read_unmapped(&frame, &other_frame(&[], &[])).named, []);
        let claimant = [8.4, 8.0];
        assert_eq!(
            read_unmapped(&frame, &other_frame(&[], &[claimant])).named,
            [(0, 9)]
        );
        assert_eq!(
            read_unmapped(&frame, &other_frame(&[(7, claimant)], &[])).named,
            [(0, 9)]
        );
    }

    /// A second landmark, or a rock the other station left unmapped, where the rock lies may
    /// be it; and fewer shared landmarks than a registration needs fix no motion.
    #[test]
    fn a_rival_on_the_rock_or_too_few_shared_landmarks_name_nothing() {
        let beside = [8.15, 8.1];
        assert_eq!(
            read_unmapped(&frame(), &other_frame(&[(7, beside)], &[])).named,
            []
        );
        assert_eq!(
            read_unmapped(&frame(), &other_frame(&[], &[beside])).named,
            []
        );
        let mut sparse = other_frame(&[], &[]);
        sparse.landmarks.retain(|(l, _)| *l >= 1);
        assert_eq!(read_unmapped(&frame(), &sparse), UnmappedReading::default());
    }
}
