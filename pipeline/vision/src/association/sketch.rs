//! A local metric sketch of the landmarks around the rover, for association only.
//!
//! One station's frame holds only the landmarks fused there, placed from one set of range
//! intervals: in a clustered field a dozen loose points, which a chance motion of look-alikes
//! fits nearly as well as the true one, so registration against single frames fails (on
//! marsyard seed 7, 13 of 50 stations registered against none of their 6 recent frames and
//! fused nothing), and every failure thins the frames that follow. The sketch accumulates the
//! landmarks of every recent station in one coordinate system (each station's sightings moved
//! there by the rigid motion its fused landmarks fit), averaging their placements, so that a
//! new station registers against all the landmarks in view at once, with tighter positions.
//!
//! The sketch proposes and rules out, like any frame (`super::register`): the map stays
//! qualitative and is never fed a metric position. Landmarks not seen for [`WINDOW`] stations
//! leave the registration, so its drift over a long traverse never reaches it; they stay
//! where the sketch last put them (`Frame::departed`) until the sketch starts again, to rule
//! out look-alikes far from there. The rocks the last few stations saw and did not map are
//! kept too (`Frame::unmapped`): a far rock's placement may reach one of them.
//!
//! Those unmapped rocks are also followed over stations ([`Track`]), their placements averaged
//! as a landmark's are: a rock that every station holds back for a look-alike landmark nearby
//! is never founded otherwise, and a track seen from a few stations, placed apart from every
//! landmark, is the evidence that it is a rock of its own; one where a single landmark lies
//! says where stations see that landmark's rock (`super::associate`).

use super::registration::{misfit, Frame, Motion, Tracked};
use super::Placed;
use nalgebra::{Matrix2, Vector2};
use qrm_core::map::LandmarkId;

/// Stations a landmark stays in the sketch after it was last seen (a rover moves 1–2 m a
/// station on the presets; the landmarks of the last few metres of the drive).
pub const WINDOW: usize = 25;

/// Weight kept by an old placement at each new sighting: the estimate follows the newest
/// views, through which the sketch drifts slowly with the drive, rather than its first ones.
const DECAY: f64 = 0.7;

/// Smallest semi-axis of a sketched position, metres: rocks are not points, and a range
/// interval's middle is not the rock's centre.
const MIN_RADIUS_M: f64 = 0.25;

/// Fewest shared landmarks that fix a station's motion into the sketch.
const MIN_SHARED: usize = 3;

/// Stations an unmapped rock's placement stays in the sketch: each is one station's
/// placement, not averaged, and only as right as that station's motion into the sketch.
const UNMAPPED_WINDOW: usize = 5;

/// Fewest stations whose placements of an unmapped rock make its track one that decides a
/// detection's association: two crossing bearings place it, a third confirms. (2, 3 and 4
/// measured at stop 74: docs/RUN.md.)
const TRACK_STATIONS: usize = 3;

/// A landmark's position in the sketch.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sketched {
    landmark: LandmarkId,
    placed: Placed,
    /// Information of the estimate: the inverse of each sighting's ellipse (`1 / radius²`
    /// for a disc), summed over decayed sightings.
    weight: Matrix2<f64>,
    /// The last station that saw it.
    seen: usize,
}

/// The recently seen landmarks in one local coordinate system.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sketch {
    landmarks: Vec<Sketched>,
    /// Landmarks not seen for [`WINDOW`] stations, where the sketch last placed them, until
    /// the sketch starts again.
    departed: Vec<Sketched>,
    /// The last station whose sightings entered the sketch.
    updated: Option<usize>,
    /// Rocks recent stations saw that no landmark holds, by the station that saw them.
    unmapped: Vec<(usize, Placed)>,
    /// The same rocks followed over stations, for [`WINDOW`] stations after one last placed
    /// them.
    tracks: Vec<Track>,
}

/// An unmapped rock followed over stations: the placements of it that no landmark holds,
/// averaged as a landmark's are ([`average`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Track {
    placed: Placed,
    weight: Matrix2<f64>,
    /// The last station that placed it.
    seen: usize,
    /// How many stations placed it.
    stations: usize,
}

impl Sketch {
    /// The landmarks seen within the last [`WINDOW`] stations before `station`, as a frame
    /// to register against.
    pub fn frame(&self, station: usize) -> Frame {
        Frame {
            accumulated: true,
            landmarks: self
                .landmarks
                .iter()
                .filter(|s| station <= s.seen + WINDOW)
                .map(|s| (s.landmark, s.placed))
                .collect(),
            departed: self
                .landmarks
                .iter()
                .chain(&self.departed)
                .filter(|s| station > s.seen + WINDOW)
                .map(|s| (s.landmark, s.placed))
                .collect(),
            unmapped: self
                .unmapped
                .iter()
                .filter(|(seen, _)| station <= seen + UNMAPPED_WINDOW)
                .map(|(_, placed)| *placed)
                .collect(),
            tracks: self.offered_tracks(station),
        }
    }

    /// The tracks offered at `station`: placed by [`TRACK_STATIONS`] stations, one of them
    /// within [`UNMAPPED_WINDOW`], each apart from every landmark of the sketch (departed ones
    /// too) or fitting one landmark in view alone. A track that fits several may be any of
    /// their rocks.
    fn offered_tracks(&self, station: usize) -> Vec<Tracked> {
        let identity = Motion::identity();
        self.tracks
            .iter()
            .filter(|t| t.stations >= TRACK_STATIONS && station <= t.seen + UNMAPPED_WINDOW)
            .filter_map(|t| {
                let mut fitting = self
                    .landmarks
                    .iter()
                    .chain(&self.departed)
                    .filter(|s| misfit(&identity, t.placed, s.placed) <= 0.0);
                let landmark = match (fitting.next(), fitting.next()) {
                    (None, _) => None,
                    (Some(s), None) if station <= s.seen + WINDOW => Some(s.landmark),
                    _ => return None,
                };
                Some(Tracked {
                    placed: t.placed,
                    landmark,
                })
            })
            .collect()
    }

    /// Forgets where `landmark` is: its sightings were found to show more than one rock.
    pub fn forget(&mut self, landmark: LandmarkId) {
        self.landmarks.retain(|s| s.landmark != landmark);
        self.departed.retain(|s| s.landmark != landmark);
    }

    /// Brings station `station`'s fused sightings (placed around it) into the sketch, with the
    /// rocks it saw that no landmark holds (`unmapped`): the
    /// rigid motion that its landmarks already in the sketch fit moves them there (pairs
    /// that do not fit it are left out of the fit; a placement away from its landmark's
    /// estimate is left out of the update). A station sharing
    /// too few landmarks with the sketch starts a new sketch in its own coordinates once the
    /// old one has not been updated for [`WINDOW`] stations (the rover has lost it); until
    /// then it is left out. Returns whether the sighting entered the sketch.
    pub fn update(
        &mut self,
        station: usize,
        sightings: &[(LandmarkId, Placed)],
        unmapped: &[Placed],
    ) -> bool {
        let motion = match self.motion(sightings) {
            Some(motion) => motion,
            None if self.updated.is_none_or(|u| station > u + WINDOW) => {
                self.landmarks.clear();
                self.departed.clear();
                self.unmapped.clear();
                self.tracks.clear();
                Motion::identity()
            }
            None => return false,
        };
        for &(landmark, p) in sightings {
            let placed = motion.apply_placed(&p).at_least(MIN_RADIUS_M);
            self.merge(landmark, placed, station);
        }
        self.unmapped
            .retain(|(seen, _)| station <= seen + UNMAPPED_WINDOW);
        let unmapped: Vec<Placed> = unmapped
            .iter()
            .map(|p| motion.apply_placed(p).at_least(MIN_RADIUS_M))
            .collect();
        self.unmapped.extend(unmapped.iter().map(|&p| (station, p)));
        self.tracks.retain(|t| station <= t.seen + WINDOW);
        for placed in unmapped {
            self.follow(placed, station);
        }
        let (kept, departed): (Vec<Sketched>, Vec<Sketched>) = std::mem::take(&mut self.landmarks)
            .into_iter()
            .partition(|s| station <= s.seen + WINDOW);
        self.landmarks = kept;
        self.departed
            .retain(|d| !self.landmarks.iter().any(|s| s.landmark == d.landmark));
        self.departed.extend(departed);
        self.updated = self.updated.max(Some(station));
        true
    }

    /// The motion of the station's sightings into the sketch, fitted on the shared landmarks
    /// that agree with it ([`Motion::consensus`]).
    fn motion(&self, sightings: &[(LandmarkId, Placed)]) -> Option<Motion> {
        let pairs: Vec<(Placed, Placed)> = sightings
            .iter()
            .filter_map(|(l, p)| {
                let s = self.landmarks.iter().find(|s| s.landmark == *l)?;
                Some((*p, s.placed))
            })
            .collect();
        Motion::consensus(pairs, MIN_SHARED)
    }

    /// Averages a new placement into a landmark's estimate (inverse-variance: each ellipse's
    /// inverse weighs it, the old weight decayed), or adds the landmark. Ellipses along
    /// different bearings cross, so a rock seen from two directions is placed tightly both
    /// ways. A placement away from the estimate (an outlier of the station's motion) is left
    /// out: if the estimate is the wrong one, the landmark leaves the sketch after [`WINDOW`]
    /// stations and comes back afresh.
    fn merge(&mut self, landmark: LandmarkId, placed: Placed, station: usize) {
        let Some(weight) = placed.shape.try_inverse() else {
            return;
        };
        match self.landmarks.iter_mut().find(|s| s.landmark == landmark) {
            Some(s) if misfit(&Motion::identity(), placed, s.placed) > 0.0 => {}
            Some(s) => {
                if let Some((placed, weight)) = average((s.placed, s.weight), (placed, weight)) {
                    s.placed = placed;
                    s.weight = weight;
                    // A revisited station is older than the latest to see the landmark.
                    s.seen = s.seen.max(station);
                }
            }
            None => self.landmarks.push(Sketched {
                landmark,
                placed,
                weight,
                seen: station,
            }),
        }
    }

    /// Averages an unmapped rock's placement into the one track it fits, or starts a track
    /// where it fits none. A placement that fits several tracks joins none: it may be either
    /// rock.
    fn follow(&mut self, placed: Placed, station: usize) {
        let Some(weight) = placed.shape.try_inverse() else {
            return;
        };
        let identity = Motion::identity();
        let mut fitting = self
            .tracks
            .iter_mut()
            .filter(|t| misfit(&identity, placed, t.placed) <= 0.0);
        match (fitting.next(), fitting.next()) {
            (None, _) => self.tracks.push(Track {
                placed,
                weight,
                seen: station,
                stations: 1,
            }),
            (Some(t), None) => {
                if let Some((placed, weight)) = average((t.placed, t.weight), (placed, weight)) {
                    t.placed = placed;
                    t.weight = weight;
                    // Pieces of one rock place it twice from one station.
                    if t.seen != station {
                        t.stations += 1;
                    }
                    t.seen = t.seen.max(station);
                }
            }
            (Some(_), Some(_)) => {}
        }
    }
}

/// An estimate `(placed, weight)` with a new placement averaged in (inverse-variance: each
/// ellipse's inverse weighs it, the old weight decayed by [`DECAY`]); none where the sum does
/// not invert.
fn average(
    (old_placed, old_weight): (Placed, Matrix2<f64>),
    (placed, weight): (Placed, Matrix2<f64>),
) -> Option<(Placed, Matrix2<f64>)> {
    let old = old_weight * DECAY;
    let total = old + weight;
    let shape = total.try_inverse()?;
    let mixed =
        shape * (old * Vector2::from(old_placed.point) + weight * Vector2::from(placed.point));
    let placed = Placed {
        point: [mixed[0], mixed[1]],
        shape,
    }
    .at_least(MIN_RADIUS_M);
    Some((placed, total))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::association::registration::distance;
    use crate::association::registration::tests::FIELD;

    fn placed(point: [f64; 2]) -> Placed {
        Placed::disc(point, 0.3)
    }

    /// FIELD's rocks as station `k` of a drive sees them: turned by `angle` and shifted.
    fn seen(angle: f64, shift: [f64; 2], ids: &[usize]) -> Vec<(LandmarkId, Placed)> {
        let (s, c) = angle.sin_cos();
        ids.iter()
            .map(|&k| {
                let [x, y] = FIELD[k];
                let p = [c * x - s * y + shift[0], s * x + c * y + shift[1]];
                (k as LandmarkId, placed(p))
            })
            .collect()
    }

    fn position(sketch: &Sketch, station: usize, landmark: LandmarkId) -> Option<[f64; 2]> {
        let frame = sketch.frame(station);
        frame
            .landmarks
            .iter()
            .find(|l| l.0 == landmark)
            .map(|l| l.1.point)
    }

    #[test]
    fn landmarks_seen_from_a_moved_station_join_the_first_stations_coordinates() {
        let mut sketch = Sketch::default();
        assert!(sketch.update(0, &seen(0.0, [0.0, 0.0], &[0, 1, 2, 3]), &[]));
        // The next station sees three of them and two new ones, turned and shifted.
        assert!(sketch.update(1, &seen(1.1, [2.0, -3.0], &[1, 2, 3, 4, 5]), &[]));
        for (k, rock) in FIELD.iter().enumerate() {
            let p = position(&sketch, 1, k as LandmarkId).expect("in the sketch");
            let gap = distance(p, *rock);
            assert!(gap < 1e-9, "landmark {k} {gap} m off");
        }
        assert!(sketch.frame(1).registrable());
    }

    #[test]
    fn a_sighting_that_does_not_fit_the_motion_is_left_out() {
        let mut sketch = Sketch::default();
        sketch.update(0, &seen(0.0, [0.0, 0.0], &[0, 1, 2, 3, 4]), &[]);
        // A wrong association: the station calls rock 5 landmark 0.
        let mut sightings = seen(0.4, [1.0, 1.0], &[1, 2, 3, 4, 5]);
        sightings[4].0 = 0;
        assert!(sketch.update(1, &sightings, &[]));
        let p = position(&sketch, 1, 0).expect("in the sketch");
        assert!(distance(p, FIELD[0]) < 1e-9, "{p:?}");
        for k in 1..5 {
            let p = position(&sketch, 1, k).expect("in the sketch");
            assert!(distance(p, FIELD[k as usize]) < 1e-9);
        }
    }

    #[test]
    fn placements_are_averaged_and_tighten() {
        let mut sketch = Sketch::default();
        sketch.update(0, &seen(0.0, [0.0, 0.0], &[0, 1, 2, 3]), &[]);
        let mut nudged = seen(0.0, [0.0, 0.0], &[0, 1, 2, 3]);
        nudged[0].1.point[0] += 0.2;
        sketch.update(1, &nudged, &[]);
        let p = position(&sketch, 1, 0).expect("in the sketch");
        // Between the two placements (the fit spreads the nudge over the four pairs).
        assert!(p[0] > FIELD[0][0] && p[0] < FIELD[0][0] + 0.2, "{p:?}");
        let radius = sketch.frame(1).landmarks[0].1.reach();
        assert!((MIN_RADIUS_M..0.3).contains(&radius), "{radius}");
    }

    /// A rock placed by two stations along crossing bearings, each 2 m deep and 5 cm wide, is
    /// placed within a few decimetres both ways, not 2 m along either: where the ellipses cross.
    #[test]
    fn placements_along_crossing_bearings_place_a_rock_tightly() {
        let rock = [4.0, 3.0];
        let along = |from: [f64; 2], error: f64| {
            let angle = (rock[1] - from[1]).atan2(rock[0] - from[0]);
            let point = [rock[0] + error * angle.cos(), rock[1] + error * angle.sin()];
            Placed::along(point, angle, 2.0, 0.05)
        };
        // Three other rocks, tightly placed, fix the second station's motion into the sketch.
        let others = |p: [f64; 2]| Placed::disc(p, 0.05);
        let fixed = [[-3.0, 2.0], [1.0, -5.0], [-4.0, -4.0]];
        let sightings = |from: [f64; 2], error: f64| -> Vec<(LandmarkId, Placed)> {
            std::iter::once((0, along(from, error)))
                .chain((1..).zip(fixed.map(others)))
                .collect()
        };
        let mut sketch = Sketch::default();
        // Both placements 1.5 m off along their bearings, from the origin and from (8, 0).
        sketch.update(0, &sightings([0.0, 0.0], 1.5), &[]);
        sketch.update(1, &sightings([8.0, 0.0], -1.5), &[]);
        let placed = sketch.frame(2).landmarks[0].1;
        assert!(distance(placed.point, rock) < 0.2, "{placed:?}");
        assert!(placed.reach() < 0.4, "{placed:?}");
    }

    /// Three landmarks, tightly placed, that fix every station's motion into the sketch
    /// (here no motion at all).
    fn fixed() -> Vec<(LandmarkId, Placed)> {
        [[-3.0, 2.0], [1.0, -5.0], [-4.0, -4.0]]
            .into_iter()
            .enumerate()
            .map(|(l, p)| (l as LandmarkId, Placed::disc(p, 0.05)))
            .collect()
    }

    /// A rock at `rock` placed from `from`, `error` metres off along the bearing, 2 m deep and
    /// 5 cm wide.
    fn placed_from(rock: [f64; 2], from: [f64; 2], error: f64) -> Placed {
        let angle = (rock[1] - from[1]).atan2(rock[0] - from[0]);
        let point = [rock[0] + error * angle.cos(), rock[1] + error * angle.sin()];
        Placed::along(point, angle, 2.0, 0.05)
    }

    /// A rock no landmark holds, placed by three stations along crossing bearings, is followed
    /// where they cross and offered to found a landmark from the third on, until no station
    /// has placed it for [`UNMAPPED_WINDOW`] stations.
    #[test]
    fn an_unmapped_rock_placed_by_three_stations_is_a_track() {
        let rock = [4.0, 3.0];
        let mut sketch = Sketch::default();
        let views = [([0.0, 0.0], 1.5), ([8.0, 0.0], -1.5), ([4.0, -6.0], 1.0)];
        for (station, (from, error)) in views.into_iter().enumerate() {
            assert!(sketch.frame(station).tracks.is_empty(), "station {station}");
            sketch.update(station, &fixed(), &[placed_from(rock, from, error)]);
        }
        let tracks = sketch.frame(3).tracks;
        assert_eq!(tracks.len(), 1);
        assert_eq!(tracks[0].landmark, None, "apart from every landmark");
        assert!(distance(tracks[0].placed.point, rock) < 0.2, "{tracks:?}");
        assert!(tracks[0].placed.reach() < 0.4, "{tracks:?}");
        assert_eq!(sketch.frame(2 + UNMAPPED_WINDOW).tracks.len(), 1);
        assert!(sketch.frame(3 + UNMAPPED_WINDOW).tracks.is_empty());
    }

    /// Where one landmark lies, a track is most likely its rock, held back: offered with that
    /// landmark. Where two lie, it may be either rock's: not offered. Nor is a rock two pieces
    /// place twice from one station followed as seen from two.
    #[test]
    fn a_track_where_landmarks_lie_is_theirs_and_one_seen_from_fewer_stations_is_none() {
        let rock = [4.0, 3.0];
        let track_among = |extra: &[(LandmarkId, Placed)]| {
            let mut landmarks = fixed();
            landmarks.extend_from_slice(extra);
            let mut sketch = Sketch::default();
            let views = [[0.0, 0.0], [8.0, 0.0], [4.0, -6.0]];
            for (station, from) in views.into_iter().enumerate() {
                sketch.update(station, &landmarks, &[placed_from(rock, from, 0.5)]);
            }
            sketch.frame(3).tracks
        };
        let tracks = track_among(&[(9, Placed::disc([4.2, 3.0], 0.3))]);
        assert_eq!(tracks.len(), 1);
        assert_eq!(tracks[0].landmark, Some(9));
        let two = [
            (9, Placed::disc([4.2, 3.0], 0.3)),
            (10, Placed::disc([3.8, 3.0], 0.3)),
        ];
        assert!(track_among(&two).is_empty());
        let mut sketch = Sketch::default();
        let pieces = [
            placed_from(rock, [0.0, 0.0], 0.3),
            placed_from(rock, [0.0, 0.0], -0.3),
        ];
        sketch.update(0, &fixed(), &pieces);
        sketch.update(1, &fixed(), &[placed_from(rock, [8.0, 0.0], 0.0)]);
        assert!(sketch.frame(2).tracks.is_empty());
    }

    #[test]
    fn landmarks_leave_after_the_window_and_a_lost_sketch_starts_again() {
        let mut sketch = Sketch::default();
        sketch.update(0, &seen(0.0, [0.0, 0.0], &[0, 1, 2, 3]), &[]);
        assert_eq!(sketch.frame(WINDOW).landmarks.len(), 4);
        assert!(sketch.frame(WINDOW + 1).landmarks.is_empty());
        // Two unrelated rocks share nothing with the sketch: left out while it may be found
        // again, the start of a new sketch once it is lost.
        let departed = sketch.frame(WINDOW + 1).departed;
        assert_eq!(departed.len(), 4, "kept where they were last placed");
        let elsewhere = seen(0.0, [50.0, 0.0], &[4, 5]);
        assert!(!sketch.update(5, &elsewhere, &[]));
        assert!(sketch.update(WINDOW + 1, &elsewhere, &[]));
        let frame = sketch.frame(WINDOW + 1);
        let ids: Vec<LandmarkId> = frame.landmarks.iter().map(|l| l.0).collect();
        assert_eq!(ids, vec![4, 5]);
        assert!(
            frame.departed.is_empty(),
            "a new sketch forgets the old one"
        );
    }

    #[test]
    fn a_departed_landmark_seen_again_rejoins_the_sketch() {
        let mut sketch = Sketch::default();
        sketch.update(0, &seen(0.0, [0.0, 0.0], &[0, 1, 2, 3]), &[]);
        sketch.update(WINDOW, &seen(0.0, [0.0, 0.0], &[1, 2, 3]), &[]);
        let frame = sketch.frame(WINDOW + 1);
        let departed: Vec<LandmarkId> = frame.departed.iter().map(|d| d.0).collect();
        assert_eq!(departed, vec![0]);
        assert!(distance(frame.departed[0].1.point, FIELD[0]) < 1e-9);
        sketch.update(WINDOW + 2, &seen(0.0, [0.0, 0.0], &[0, 1, 2, 3]), &[]);
        let frame = sketch.frame(WINDOW + 2);
        assert!(frame.departed.is_empty());
        assert!(frame.landmarks.iter().any(|l| l.0 == 0));
    }
}
