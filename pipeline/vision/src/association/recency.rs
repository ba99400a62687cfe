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

/// The station at which each landmark was last fused.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LastSeen(HashMap<LandmarkId, usize>);

impl LastSeen {
    /// Records that `landmark` was fused at `station`.
    pub fn record(&mut self, landmark: LandmarkId, station: usize) {
        let last = self.0.entry(landmark).or_insert(station);
        *last = (*last).max(station);
    }

    /// Whether `landmark` was fused within the [`LATELY_STATIONS`] stations before `station`.
    pub fn lately(&self, landmark: LandmarkId, station: usize) -> bool {
        self.0
            .get(&landmark)
            .is_some_and(|&last| station <= last + LATELY_STATIONS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_landmark_is_seen_lately_for_a_few_stations_after_its_last_sighting() {
        let mut seen = LastSeen::default();
        seen.record(3, 10);
        seen.record(3, 4);
        assert!(seen.lately(3, 10 + LATELY_STATIONS));
        assert!(!seen.lately(3, 11 + LATELY_STATIONS));
        assert!(
            !seen.lately(4, 10),
            "a landmark never fused was not seen lately"
        );
    }
}
