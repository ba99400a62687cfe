//! Qualitative localization from one panorama (000 §VII-B step 4): which landmark's Voronoi
//! cell the rover is in, against the map an earlier run built, from the panorama's range order
//! alone. No position is estimated.
//!
//! The panorama's detections are ranged and associated with the run's landmarks as a mapping
//! station would be (`crate::association::associate`: appearance proposes, registration
//! against the run's stations anchors, the map's relations decide), but nothing is fused. The
//! run's stations serve as the registration frames: each one's fused landmarks placed around
//! it, rebuilt from `stations.json` and `landmarks.json`.
//!
//! The rover is in landmark `L`'s cell when `L` is the nearest landmark. Only an identified
//! detection can name a landmark, and any detection not identified (held back, new, or not
//! usable for mapping: a touching or partly hidden rock) may be a landmark too, so the claims
//! are made over *every* detection of the panorama: *certain* when one identified detection
//! is known nearer than every other detection; *possible* for the identified ones that no
//! detection is known nearer than, with how many unidentified detections may be nearer still;
//! *unknown* when no identified detection may be the nearest. A certain cell also needs the
//! identified landmarks, as the panorama measures them, to fit the map (a wrong identification
//! would contradict it, as fusing it would when mapping); otherwise it is unknown. A landmark
//! hidden from view could be nearer than all of them, as for `qrm_core::navigation::cell_of`.

use crate::association::{associate, AssociationSettings, Decision, Frame, Gallery};
use crate::calib::Calibration;
use crate::ranging::{self, RangeInterval, SensorModel};
use crate::run::selection::{likely_range, placement, station_evidence, usable_firm};
use crate::run::{LandmarkRecord, StationDetections, StationRecord};
use qrm_core::calculus::Calculus;
use qrm_core::map::{Hypergraph, LandmarkId, Sighting};
use qrm_core::measurement::{RangeOrder, StationView};
use serde::Serialize;
use std::collections::HashMap;

/// The map of an earlier run, with what association needs to recognise its landmarks.
pub struct KnownMap<C: Calculus> {
    pub map: Hypergraph<C>,
    gallery: Gallery,
    frames: Vec<Frame>,
}

/// Which landmark's cell the panorama was taken in, as far as it tells.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "cell", rename_all = "snake_case")]
pub enum Whereabouts {
    /// Identified as landmark `landmark` and nearer than every other detection.
    Certain { landmark: LandmarkId },
    /// Each of `landmarks` may be the nearest; so may `unidentified` detections that are not
    /// known to be farther.
    Possible {
        landmarks: Vec<LandmarkId>,
        unidentified: usize,
    },
    /// No identified detection may be the nearest (or nothing was identified).
    Unknown,
}

/// What one panorama told.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Location {
    pub detections: usize,
    /// Detections usable for association (`run::selection`).
    pub usable: usize,
    /// `(detection, landmark)` for each detection identified as a landmark of the map.
    pub identified: Vec<(usize, LandmarkId)>,
    /// `(detection, candidates)` for each detection that several landmarks may be.
    pub ambiguous: Vec<(usize, Vec<LandmarkId>)>,
    pub whereabouts: Whereabouts,
    /// The identified landmarks as the leg follower sees them (000 §VII-B): their ids, and
    /// their bearings, range order and range intervals by position in that list.
    #[serde(skip)]
    pub seen: (Vec<LandmarkId>, StationView),
    /// Every detection's range interval from all cues (`Ranged::fused`), metres, by detection:
    /// how far its rock is, for a navigator that closes in on it.
    #[serde(skip)]
    pub ranges: Vec<RangeInterval>,
}

impl<C: Calculus> KnownMap<C> {
    /// The map of a run with its landmarks' looks (`landmarks.json`) and, as registration
    /// frames, every station's fused landmarks placed around it (`stations.json`).
    pub fn from_run(
        map: Hypergraph<C>,
        landmarks: &[LandmarkRecord],
        records: &[StationRecord],
    ) -> KnownMap<C> {
        let gallery = Gallery {
            profiles: landmarks.iter().map(|l| l.profile.clone()).collect(),
        };
        let landmark_of: HashMap<(usize, usize), LandmarkId> = landmarks
            .iter()
            .flat_map(|l| l.sightings.iter().map(move |&s| (s, l.landmark)))
            .collect();
        let frames = records
            .iter()
            .map(|record| Frame {
                accumulated: false,
                departed: Vec::new(),
                tracks: Vec::new(),
                unmapped: Vec::new(),
                landmarks: record
                    .detections
                    .iter()
                    .enumerate()
                    .filter_map(|(i, d)| {
                        let landmark = *landmark_of.get(&(record.index, i))?;
                        let interval = |[low, high]: [f64; 2]| RangeInterval::new(low, high);
                        let range = likely_range(
                            d.range.stereo.map(interval),
                            interval(d.range.fused),
                            d.range.conflict,
                        );
                        let placed = placement(d.bearing, d.bearing_uncertainty, range.as_array())?;
                        Some((landmark, placed))
                    })
                    .collect(),
            })
            .filter(Frame::registrable)
            .collect();
        KnownMap {
            map,
            gallery,
            frames,
        }
    }

    /// Stations of the run that can serve as registration frames.
    pub fn frames(&self) -> usize {
        self.frames.len()
    }

    /// Places one station's detections against the map (see the module documentation).
    pub fn locate(
        &self,
        station: &StationDetections,
        calib: &Calibration,
        sensor: &SensorModel,
        settings: &AssociationSettings,
    ) -> Location {
        let ranged = ranging::observe(
            &station.primary,
            station.right.as_deref(),
            station.eye,
            station.channels,
            calib,
            sensor,
        );
        let usable = usable_firm(station, &ranged, calib.image.width);
        let mut identified = Vec::new();
        let mut ambiguous = Vec::new();
        if !usable.is_empty() {
            let evidence = station_evidence(station, &ranged, &usable, sensor);
            // A finished map has no drive behind it: every landmark may be in view.
            let decisions = associate(
                &self.map,
                &self.gallery,
                &self.frames,
                &evidence,
                settings,
                &|_| true,
            )
            .decisions;
            for (&i, decision) in usable.iter().zip(decisions) {
                match decision {
                    Decision::Matched(landmark) => identified.push((i, landmark)),
                    Decision::HeldBack(candidates) => ambiguous.push((i, candidates)),
                    Decision::New | Decision::Withheld(_) => {}
                }
            }
        }
        // Over every detection: any of them may be a landmark.
        let order = ranging::range_order(&ranged);
        let nearest: Vec<usize> = (0..ranged.len())
            .filter(|&i| !(0..ranged.len()).any(|j| order.is_nearer(j, i)))
            .collect();
        let indices: Vec<usize> = identified.iter().map(|p| p.0).collect();
        // Measured as mapping measures a station (`run::selection::view_of`): the range
        // ratios bounded where ground and stereo agree.
        let seen = StationView::new(
            indices
                .iter()
                .map(|&i| ranged[i].measured_bearing())
                .collect(),
            RangeOrder::from_pairs(indices.len(), &order.restricted(&indices))
                .expect("a sub-order of a strict order"),
        )
        .and_then(|view| {
            view.with_ranges(
                indices
                    .iter()
                    .map(|&i| ranging::ratio_bounds(&ranged[i]))
                    .collect(),
            )
        })
        .expect("bearings of usable detections are measurable; the order is the intervals'");
        let mut whereabouts = whereabouts(&nearest, &identified);
        if matches!(whereabouts, Whereabouts::Certain { .. }) && !self.agrees(&identified, &seen) {
            whereabouts = Whereabouts::Unknown;
        }
        Location {
            detections: ranged.len(),
            usable: usable.len(),
            whereabouts,
            seen: (identified.iter().map(|p| p.1).collect(), seen),
            identified,
            ambiguous,
            ranges: ranged.iter().map(|r| r.fused).collect(),
        }
    }
}

impl<C: Calculus> KnownMap<C> {
    /// Whether the identified landmarks, measured as `seen` shows them, fit the map: a
    /// certain cell rests on its identification, and a wrong one (a look-alike registered by
    /// chance) would contradict the map as it would if fused when mapping.
    fn agrees(&self, identified: &[(usize, LandmarkId)], seen: &StationView) -> bool {
        let mut sightings: Vec<Sighting> = Vec::new();
        for (position, &(_, landmark)) in identified.iter().enumerate() {
            if !sightings.iter().any(|s| s.landmark == landmark) {
                sightings.push(Sighting::new(position, landmark));
            }
        }
        let observations = self.map.observations(seen, &sightings);
        let mut trial = self.map.clone();
        trial.fuse(&observations).is_ok()
    }
}

/// The cell claim from the detections no other is known nearer than (`nearest`) and the
/// identified ones.
fn whereabouts(nearest: &[usize], identified: &[(usize, LandmarkId)]) -> Whereabouts {
    let landmark = |i: usize| identified.iter().find(|(d, _)| *d == i).map(|p| p.1);
    let unidentified = nearest.iter().filter(|&&i| landmark(i).is_none()).count();
    let mut landmarks: Vec<LandmarkId> = Vec::new();
    // Two detections identified as one landmark (pieces of one rock) name it once.
    for l in nearest.iter().filter_map(|&i| landmark(i)) {
        if !landmarks.contains(&l) {
            landmarks.push(l);
        }
    }
    match (landmarks.as_slice(), unidentified) {
        ([], _) => Whereabouts::Unknown,
        ([only], 0) => Whereabouts::Certain { landmark: *only },
        _ => Whereabouts::Possible {
            landmarks,
            unidentified,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::{whereabouts, Whereabouts};

    #[test]
    fn a_cell_is_certain_only_when_the_lone_nearest_detection_is_identified() {
        let identified = [(0, 7), (2, 9)];
        assert_eq!(
            whereabouts(&[0], &identified),
            Whereabouts::Certain { landmark: 7 }
        );
        // Detection 1 may be nearer and may be any landmark.
        assert_eq!(
            whereabouts(&[0, 1], &identified),
            Whereabouts::Possible {
                landmarks: vec![7],
                unidentified: 1
            }
        );
        assert_eq!(
            whereabouts(&[0, 2], &identified),
            Whereabouts::Possible {
                landmarks: vec![7, 9],
                unidentified: 0
            }
        );
        assert_eq!(whereabouts(&[1], &identified), Whereabouts::Unknown);
        // Two pieces identified as one landmark: still one cell.
        assert_eq!(
            whereabouts(&[0, 3], &[(0, 7), (3, 7)]),
            Whereabouts::Certain { landmark: 7 }
        );
        assert_eq!(whereabouts(&[], &identified), Whereabouts::Unknown);
    }
}
