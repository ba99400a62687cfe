//! Which landmarks the rover saw lately, and which it has lost sight of.
//!
//! Re-identifying landmarks the rover lost sight of (a loop closure) on look-alikes alone is
//! what a handful of look-alikes fits by chance in a field of hundreds, so a registration must
//! hold at least one landmark seen lately. On the 1 000-rock `sparse-large` drive (seed 5,
//! half resolution), 13 of the 21 registrations that paired a landmark unseen for 8 or more
//! stations with the wrong rock held no landmark seen lately, while every registration of
//! marsyard seed 3 and random seed 5 (half resolution), marsyard seed 7, stress seeds 4, 5
//! and 8 and `sparse-large` seeds 3 and 4 that re-identified such a landmark also paired one
//! seen lately: the rover's way back passes landmarks it keeps in view. (Requiring 4 made the
//! 1 000-rock drive sound but halved the sightings of stress seed 8, which fuses sparsely
//! enough that true registrations hold a single landmark seen lately.)

use qrm_core::map::LandmarkId;
use std::collections::HashMap;

/// Stations after its last sighting during which a landmark counts as seen lately: a few
/// stations of a drive (1–3 m a station on the presets), well inside the sketch's window.
pub const LATELY_STATIONS: usize = 8;

/// The station at which each landmark was last fused, and whether any landmark was fused again
/// at a later station than before (the rover has recognised something).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LastSeen {
    last: HashMap<LandmarkId, usize>,
    recognised: bool,
}

impl LastSeen {
    /// Records that `landmark` was fused at `station`.
    pub fn record(&mut self, landmark: LandmarkId, station: usize) {
        let last = self.last.entry(landmark).or_insert(station);
        self.recognised |= station > *last;
        *last = (*last).max(station);
    }

    /// Whether `landmark` was fused within the [`LATELY_STATIONS`] stations before `station`,
    /// or at all while the rover has recognised nothing yet.
    ///
    /// Until a first registration, the stations that fuse nothing say nothing of where the
    /// rover went: on stress seeds 9, 21, 38 and 50 the first station founds 8–9 landmarks
    /// and the next seven or more register against none, which left every landmark unseen
    /// lately and the map stalled until station 26 founded them again. Once anything is
    /// recognised, every station counts, fusing or not: counting only the stations that fused
    /// let a registration after a 22-station stall on the 1 000-rock drive re-identify rocks
    /// 24 stations back (18 183 unsound relations, docs/RUN.md stop 64).
    pub fn lately(&self, landmark: LandmarkId, station: usize) -> bool {
        self.last
            .get(&landmark)
            .is_some_and(|&last| !self.recognised || station <= last + LATELY_STATIONS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_landmark_is_seen_lately_for_a_few_stations_after_its_last_sighting() {
        let mut seen = LastSeen::default();
        seen.record(3, 4);
        seen.record(3, 10);
        assert!(seen.lately(3, 10 + LATELY_STATIONS));
        assert!(!seen.lately(3, 11 + LATELY_STATIONS));
        assert!(
            !seen.lately(4, 10),
            "a landmark never fused was not seen lately"
        );
    }

    #[test]
    fn before_anything_is_recognised_every_landmark_is_seen_lately() {
        let mut seen = LastSeen::default();
        seen.record(3, 0);
        seen.record(4, 0);
        // Stations 1–19 fused nothing, station 20 only new landmarks.
        seen.record(5, 20);
        assert!(seen.lately(3, 21));
        // Station 21 recognises landmark 4: from then on, stations count.
        seen.record(4, 21);
        assert!(!seen.lately(3, 22));
        assert!(seen.lately(4, 21 + LATELY_STATIONS));
        assert!(seen.lately(5, 20 + LATELY_STATIONS));
        assert!(!seen.lately(5, 21 + LATELY_STATIONS));
    }
}
