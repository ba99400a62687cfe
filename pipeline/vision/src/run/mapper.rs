//! The mapping half of `pipeline run`: station by station, range evidence and association
//! (000 §VI-C) turn detections into measurements, fused into the map (000 §VI-B); held-back
//! observations are retried after every station, and stations that registered against
//! nothing are mapped again when later stations change the map.

use super::record::{
    Association, DetectionRecord, Exclusion, LateSighting, MergeRecord, MetricsRecord, RangeRecord,
    RegistrationRecord, SplitRecord, StationRecord,
};
use super::selection;
use crate::association::audit::{regroup, Regrouping};
use crate::association::duplicate;
use crate::association::{
    agreement, associate, look_alikes, looks_like, read_unmapped, reconsider, sketch, unfounded,
    AssociationSettings, Decision, Evidence, Frame, Gallery, LastSeen, Placed, Profile,
    Recognition, Sketch, StationEvidence, Unfounded, UnmappedReading,
};
use crate::calib::Calibration;
use crate::detection::{Detection, Separation};
use crate::ranging::{self, PrimaryEye, Ranged, SensorModel};
use qrm_core::calculus::Calculus;
use qrm_core::map::{Hypergraph, Journal, LandmarkId, Sighting};
use qrm_core::measurement::{Bearing, StationView};
use qrm_core::neighborhood::{estimate, RngEstimate};
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;
use std::time::Instant;

/// One station's detections, ready for mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct StationDetections {
    pub name: String,
    pub files: Vec<String>,
    /// Fingerprints of `files` ([`crate::survey::digest`]).
    pub digests: Vec<String>,
    pub eye: PrimaryEye,
    /// The detector's mode for the primary panorama (`Channels::resolve`).
    pub channels: crate::detection::Channels,
    pub primary: Vec<Detection>,
    /// Detections of the right panorama of a stereo station.
    pub right: Option<Vec<Detection>>,
    pub warnings: Vec<String>,
}

/// One landmark of `landmarks.json`: which detections it was fused from, as `(station index,
/// detection index)` into `stations.json`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LandmarkRecord {
    pub landmark: LandmarkId,
    pub sightings: Vec<(usize, usize)>,
    pub profile: crate::association::Profile,
}

/// One station's fused landmarks as 002's probabilistic map needs them: each one's bearing
/// (radians, camera frame) with its bound, and the station's frame of placements, from
/// which the motion between two stations is found.
#[derive(Clone, Debug, PartialEq)]
pub struct Sighted {
    pub station: usize,
    pub bearings: BTreeMap<LandmarkId, Bearing>,
    pub frame: Frame,
}

impl Sighted {
    /// Adds a landmark founded after the station was mapped, from one of its held-back
    /// detections seen along `bearing` and placed at `placed`: the frame holds it where the
    /// station placed it, and no longer counts that placement among the rocks it left
    /// unmapped. Without it no registration could pair a later sighting with the landmark,
    /// and every later sighting of its rock, the landmark a look-alike the map cannot reject,
    /// would be held back for it and given up (marsyard s7 at stop 56: a near rock seen
    /// from 9 stations, fused once).
    fn found_late(&mut self, landmark: LandmarkId, bearing: Bearing, placed: Option<Placed>) {
        self.bearings.insert(landmark, bearing);
        let Some(placed) = placed else {
            return;
        };
        self.frame.landmarks.push((landmark, placed));
        if let Some(k) = self.frame.unmapped.iter().position(|&u| u == placed) {
            self.frame.unmapped.remove(k);
        }
    }
}

/// What the other stations' frames say of one rock a station's frame left unmapped
/// ([`Mapper::frames_naming`]).
#[derive(Default)]
struct RockReadings {
    /// The landmark each frame that names the rock puts on it.
    names: Vec<LandmarkId>,
    /// Every landmark the naming frames hold.
    held: BTreeSet<LandmarkId>,
    /// Landmarks some frame places apart from the rock, and those some frame places within
    /// its reach.
    apart: BTreeSet<LandmarkId>,
    within: BTreeSet<LandmarkId>,
}

/// An observation whose association stayed ambiguous, kept to be fused later.
#[derive(Clone, Debug, PartialEq)]
struct HeldBack {
    station: usize,
    view: Arc<StationView>,
    /// Position in `view`, and index among the station's detections.
    detection: usize,
    primary_index: usize,
    candidates: Vec<LandmarkId>,
    /// The station's other detections that were fused, with their landmarks.
    decided: Vec<Sighting>,
    evidence: Evidence,
    /// The landmark each later station that recognised it recognised it as (a station's
    /// frame is registered once, so it recognises an observation once at most).
    recognised: Vec<LandmarkId>,
    /// The map's next landmark id once its station was fused: landmarks from this one on
    /// were founded later, and were never offered to it as candidates.
    founded_after: LandmarkId,
    /// A detection that matched no landmark and founded none (a piece or a doubted one,
    /// [`Unfounded`]), recorded unused: not held back, only named at the end of the drive
    /// ([`Mapper::recognise_given_up`]).
    withheld: bool,
    /// Its box in the image: observations of one station whose boxes touch may be one rock's
    /// pieces, or neighbours of one cluster.
    bbox: [u32; 4],
}

/// A station whose detections registered against no frame and were all held back, then
/// given up: no landmark the map held was near enough in the drive, or seen alike enough,
/// for any pair to anchor. On surveys of random imaging points the first few stations see
/// the field from 10–20 m apart and none registers until one is taken near an earlier one;
/// every station before it was lost (stress seed 9: stations 1–7, 135 detections). Later
/// stations may give it frames to register against ([`Mapper::revisit_stalled`]).
#[derive(Clone, Debug)]
struct Stalled {
    index: usize,
    station: StationDetections,
    /// Its detections' range evidence before the size cue, and the usable ones.
    ranged: Vec<Ranged>,
    usable: Vec<usize>,
    /// Its held-back detections (indices into its detections), all given up.
    held: Vec<usize>,
    /// The map's revision when it was last tried.
    revision: u64,
}

/// A station's association, decided and not yet fused.
struct Decided {
    associated: Associated,
    /// The held-back observations of earlier stations its matches recognise, with the
    /// station of each.
    recognitions: Vec<(usize, Recognition)>,
    registrations: Vec<RegistrationRecord>,
}

/// The map being built and what association needs to remember.
pub struct Mapper<C: Calculus> {
    pub map: Hypergraph<C>,
    /// Every fusion into `map`, to rebuild it without a landmark's wrong sightings.
    journal: Journal,
    pub gallery: Gallery,
    calib: Calibration,
    sensor: SensorModel,
    association: AssociationSettings,
    held: Vec<HeldBack>,
    /// Observations that waited out [`RECENT_FRAMES`] unfused, measurable with their
    /// station's other sightings: named, if the drive's frames agree, when it is over
    /// ([`Mapper::recognise_given_up`]).
    given_up: Vec<HeldBack>,
    /// Observations [`Mapper::finish`] fused as the landmark other stations' frames put on
    /// them ([`Mapper::recognise_given_up`]).
    pub recognised_at_end: Vec<LateSighting>,
    /// The recently seen landmarks placed in one coordinate system.
    sketch: Sketch,
    /// When each landmark was last fused.
    last_seen: LastSeen,
    /// Every station that fused landmarks, in order: the recent ones' frames are registered
    /// against ([`Mapper::recent`]), all of them make 002's beliefs (`super::beliefs`).
    pub sighted: Vec<Sighted>,
    /// Held-back observations given up after [`HOLD_STATIONS`].
    pub expired: usize,
    /// Stalled stations within the sketch's window, oldest first.
    stalled: Vec<Stalled>,
    next_landmark: LandmarkId,
    /// `(station, detection) → landmark` for every fused detection, for evaluation.
    pub sightings: Vec<(usize, usize, LandmarkId)>,
    /// Landmarks [`Mapper::finish`] left out of the map: fused from one station only.
    pub uncorroborated: Vec<LandmarkId>,
    /// Landmarks [`Mapper::finish`] found to be one rock and merged
    /// ([`Mapper::merge_duplicates`]).
    pub merged: Vec<MergeRecord>,
    /// The RNG estimate after the latest station.
    rng: RngEstimate,
    /// Counts the changes of the map: a station that fused nothing new leaves it, and its
    /// metrics and RNG estimate are those of the station before.
    revision: u64,
    /// The metrics of the map at `revision`, if computed.
    metrics: Option<(u64, MetricsRecord)>,
}

impl<C: Calculus> Mapper<C> {
    pub fn new(calib: Calibration, sensor: SensorModel, association: AssociationSettings) -> Self {
        Mapper {
            map: Hypergraph::new(),
            journal: Journal::default(),
            gallery: Gallery::default(),
            calib,
            sensor,
            association,
            held: Vec::new(),
            given_up: Vec::new(),
            recognised_at_end: Vec::new(),
            sketch: Sketch::default(),
            last_seen: LastSeen::default(),
            sighted: Vec::new(),
            expired: 0,
            stalled: Vec::new(),
            next_landmark: 0,
            sightings: Vec::new(),
            uncorroborated: Vec::new(),
            merged: Vec::new(),
            rng: RngEstimate::default(),
            revision: 0,
            metrics: None,
        }
    }

    /// Every landmark with its looks and the station detections it was fused from.
    pub fn landmarks(&self) -> Vec<LandmarkRecord> {
        self.gallery
            .profiles
            .iter()
            .map(|p| LandmarkRecord {
                landmark: p.landmark,
                sightings: self
                    .sightings
                    .iter()
                    .filter(|s| s.2 == p.landmark)
                    .map(|s| (s.0, s.1))
                    .collect(),
                profile: p.clone(),
            })
            .collect()
    }

    /// Observations still held back.
    pub fn held_back(&self) -> usize {
        self.held.len()
    }

    /// Ends the run: leaves out of the map every landmark fused from fewer than
    /// [`CORROBORATING_STATIONS`] stations ([`Mapper::uncorroborated`]), and returns the
    /// metrics of the map that remains, which the run publishes.
    ///
    /// A detection that founded a landmark and was never matched again from anywhere else is
    /// mostly no rock but a blob of ground or shadow the stereo test could not call flat: on
    /// the ten colour marsyard seeds, 21 landmarks were fused from one station only and none
    /// was a rock (s17, s19 and s29: 4–5 each); on all 27 sets of stop 75's figures, 13 of 59
    /// were, 5 of them second landmarks of rocks mapped already (docs/RUN.md, stage 9). Each
    /// such landmark is a node of the RNG no later station can find, and its triples with
    /// every other landmark have no true state. Leaving it out loses no soundness: the
    /// relations kept are those the map holds, and path consistency through the dropped
    /// landmark derived them from its own station's measurement, which the rock or ground
    /// point it saw satisfies.
    pub fn finish(&mut self) -> MetricsRecord {
        self.merge_duplicates();
        self.recognise_given_up();
        let stations = self.stations_of_landmarks();
        let corroborated =
            |l: LandmarkId| stations.get(&l).map_or(0, BTreeSet::len) >= CORROBORATING_STATIONS;
        self.uncorroborated = self
            .map
            .landmarks()
            .iter()
            .copied()
            .filter(|&l| !corroborated(l))
            .collect();
        if !self.uncorroborated.is_empty() {
            self.map = self.map.restricted(corroborated);
            self.gallery.profiles.retain(|p| corroborated(p.landmark));
            self.relabel_fused(|_, l| corroborated(l).then_some(l));
            self.revision += 1;
        }
        self.refresh_metrics()
    }

    /// The stations each landmark was fused at.
    fn stations_of_landmarks(&self) -> BTreeMap<LandmarkId, BTreeSet<usize>> {
        let mut stations: BTreeMap<LandmarkId, BTreeSet<usize>> = BTreeMap::new();
        for &(station, _, l) in &self.sightings {
            stations.entry(l).or_default().insert(station);
        }
        stations
    }

    /// Merges the landmarks that are one rock, once the drive is over: two landmarks never
    /// fused at one station, which the frames of [`MERGING_FRAME_PAIRS`] or more pairs of
    /// stations put on each other and no pair puts apart ([`duplicate::compare`]). The younger takes the
    /// older's id and the map is rebuilt from its journal, as for a split; a merge that the
    /// rebuilt map contradicts at any station is not made. Merging before the given-up
    /// observations are named ([`Mapper::recognise_given_up`]) leaves them one landmark of
    /// the rock to be named as, and no rival that no frame places (colour marsyard s31: 80.2
    /// → 84.6 % of correct detections fused; docs/RUN.md, stop 78).
    fn merge_duplicates(&mut self) {
        let mut refused: BTreeSet<(LandmarkId, LandmarkId)> = BTreeSet::new();
        while let Some((pair, frame_pairs)) = self.duplicate_pair(&refused) {
            let (landmark, duplicate) = pair;
            let relabel = |_: usize, l: LandmarkId| Some(if l == duplicate { landmark } else { l });
            let replay = self.journal.replay::<C>(relabel);
            if !replay.rejected.is_empty() {
                refused.insert(pair);
                continue;
            }
            let last = self
                .sightings
                .iter()
                .filter(|s| s.2 == duplicate)
                .map(|s| s.0)
                .max();
            self.map = replay.map;
            self.journal = replay.journal;
            self.relabel_fused(relabel);
            for item in self.held.iter_mut().chain(&mut self.given_up) {
                if item.candidates.contains(&landmark) {
                    item.candidates.retain(|&c| c != duplicate);
                } else if let Some(c) = item.candidates.iter_mut().find(|c| **c == duplicate) {
                    *c = landmark;
                }
            }
            self.gallery.merge(landmark, duplicate);
            if let Some(last) = last {
                self.last_seen.record(landmark, last);
            }
            self.sketch.forget(duplicate);
            self.revision += 1;
            self.merged.push(MergeRecord {
                landmark,
                duplicate,
                frame_pairs,
            });
        }
    }

    /// The pair of landmarks (older, younger) most pairs of stations' frames put on each other
    /// ([`Mapper::merge_duplicates`]), and how many, leaving out `refused` pairs.
    fn duplicate_pair(
        &self,
        refused: &BTreeSet<(LandmarkId, LandmarkId)>,
    ) -> Option<((LandmarkId, LandmarkId), usize)> {
        let stations = self.stations_of_landmarks();
        let n = self.sighted.len();
        let comparisons: Vec<duplicate::Comparison> = (0..n)
            .into_par_iter()
            .flat_map_iter(|i| (i + 1..n).map(move |j| (i, j)))
            .map(|(i, j)| duplicate::compare(&self.sighted[i].frame, &self.sighted[j].frame))
            .collect();
        let ordered = |a: LandmarkId, b: LandmarkId| (a.min(b), a.max(b));
        let mut same: BTreeMap<(LandmarkId, LandmarkId), usize> = BTreeMap::new();
        let mut apart: BTreeSet<(LandmarkId, LandmarkId)> = BTreeSet::new();
        for comparison in &comparisons {
            for &(a, b) in &comparison.same {
                *same.entry(ordered(a, b)).or_default() += 1;
            }
            apart.extend(comparison.apart.iter().map(|&(a, b)| ordered(a, b)));
        }
        let never_together =
            |(a, b): (LandmarkId, LandmarkId)| match (stations.get(&a), stations.get(&b)) {
                (Some(x), Some(y)) => x.is_disjoint(y),
                _ => false,
            };
        same.into_iter()
            .filter(|&(pair, votes)| {
                votes >= MERGING_FRAME_PAIRS
                    && !apart.contains(&pair)
                    && !refused.contains(&pair)
                    && never_together(pair)
            })
            .max_by_key(|&(pair, votes)| (votes, std::cmp::Reverse(pair)))
    }

    /// Renames the landmarks of every record of what stations fused: their bearings and
    /// frames, the fused sightings, and the fused partners of held-back observations. A
    /// landmark fused at `station` as `l` becomes `relabel(station, l)`, or is dropped when
    /// that is `None`.
    fn relabel_fused(&mut self, relabel: impl Fn(usize, LandmarkId) -> Option<LandmarkId>) {
        for s in &mut self.sighted {
            let station = s.station;
            s.frame.landmarks = s
                .frame
                .landmarks
                .iter()
                .filter_map(|&(l, p)| Some((relabel(station, l)?, p)))
                .collect();
            s.bearings = s
                .bearings
                .iter()
                .filter_map(|(&l, &b)| Some((relabel(station, l)?, b)))
                .collect();
        }
        self.sightings = self
            .sightings
            .iter()
            .filter_map(|&(station, detection, l)| Some((station, detection, relabel(station, l)?)))
            .collect();
        for item in self.held.iter_mut().chain(&mut self.given_up) {
            let station = item.station;
            item.decided = item
                .decided
                .iter()
                .filter_map(|s| Some(Sighting::new(s.position, relabel(station, s.landmark)?)))
                .collect();
        }
    }

    /// Maps one station; the record has everything but the decode/detect times.
    pub fn process(&mut self, index: usize, station: &StationDetections) -> StationRecord {
        let mut record = StationRecord {
            index,
            station: station.name.clone(),
            files: station.files.clone(),
            digests: station.digests.clone(),
            channels: station.channels,
            warnings: station.warnings.clone(),
            ..StationRecord::default()
        };
        let start = Instant::now();
        let ranged = ranging::observe(
            &station.primary,
            station.right.as_deref(),
            station.eye,
            station.channels,
            &self.calib,
            &self.sensor,
        );
        record.seconds.range = start.elapsed().as_secs_f64();
        let usable = selection::usable(station, &ranged, self.calib.image.width);
        record.detections = self.detection_records(station, &ranged);
        record.fusion.usable = usable.len();
        if usable.len() < 3 {
            record.warnings.push(format!(
                "{}: {} usable detections; a panorama needs at least 3 landmarks to measure",
                station.name,
                usable.len()
            ));
            let start = Instant::now();
            record.fusion.resolved_held_back = self.retry_held_back(&mut record);
            record.seconds.map = start.elapsed().as_secs_f64();
            let start = Instant::now();
            record.metrics = self.refresh_metrics();
            record.seconds.metrics = start.elapsed().as_secs_f64();
            return record;
        }

        let fused = self.map_station(&mut record, station, ranged.clone(), usable.clone());
        let start = Instant::now();
        self.revisit_stalled(&mut record);
        record.fusion.resolved_held_back = self.retry_held_back(&mut record);
        // Its held-back detections, with no fused partner to be measured with, were given up.
        let held: Vec<usize> = (0..record.detections.len())
            .filter(|&i| {
                matches!(
                    record.detections[i].association,
                    Association::HeldBack { .. }
                )
            })
            .collect();
        if fused == 0 && !held.is_empty() {
            self.stalled.push(Stalled {
                index,
                station: station.clone(),
                ranged,
                usable,
                held,
                revision: self.revision,
            });
        }
        record.seconds.map += start.elapsed().as_secs_f64();
        let start = Instant::now();
        record.metrics = self.refresh_metrics();
        record.seconds.metrics = start.elapsed().as_secs_f64();
        record
    }

    /// The station's detections as records, each unused with the reason mapping leaves it
    /// out until association decides.
    fn detection_records(
        &self,
        station: &StationDetections,
        ranged: &[Ranged],
    ) -> Vec<DetectionRecord> {
        station
            .primary
            .iter()
            .zip(ranged)
            .enumerate()
            .map(|(i, (d, r))| DetectionRecord {
                association: Association::Unused {
                    reason: selection::exclusion(station, ranged, i, self.calib.image.width),
                },
                ..detection_record(d, r)
            })
            .collect()
    }

    /// Associates and fuses the usable detections of station `record.index`: the record gets
    /// their decisions, fusion outcome and the stage times of association and mapping.
    /// Returns how many detections were fused.
    fn map_station(
        &mut self,
        record: &mut StationRecord,
        station: &StationDetections,
        ranged: Vec<Ranged>,
        usable: Vec<usize>,
    ) -> usize {
        let start = Instant::now();
        let decided = self.decide(record.index, station, &ranged, usable);
        record.seconds.associate += start.elapsed().as_secs_f64();
        self.fuse_decided(record, station, ranged, decided)
    }

    /// The association of station `index`'s usable detections (000 §VI-C), with the
    /// recognitions its matches make.
    fn decide(
        &self,
        index: usize,
        station: &StationDetections,
        ranged: &[Ranged],
        usable: Vec<usize>,
    ) -> Decided {
        let evidence = selection::station_evidence(station, ranged, &usable, &self.sensor);
        let (stations, frames) = self.frames(index);
        let association = associate(
            &self.map,
            &self.gallery,
            &frames,
            &evidence,
            &self.association,
            &|landmark| self.last_seen.lately(landmark, index),
        );
        let decisions = self.undo_disagreeing(association.decisions, &evidence.detections, index);
        // Only what this station still matches recognises anything.
        let recognitions: Vec<(usize, Recognition)> = association
            .recognitions
            .into_iter()
            .filter(|r| decisions[r.detection] == Decision::Matched(r.landmark))
            .filter_map(|r| Some((stations[r.frame]?, r)))
            .collect();
        let registrations = association
            .registrations
            .into_iter()
            .map(|r| RegistrationRecord {
                frame: stations[r.frame],
                pairs: r.pairs.iter().map(|&(i, l)| (usable[i], l)).collect(),
                nfa: Some(r.nfa).filter(|nfa| nfa.is_finite()),
                believed: r.believed,
            })
            .collect();
        Decided {
            associated: Associated::new(usable, evidence, decisions, self.next_landmark),
            recognitions,
            registrations,
        }
    }

    /// Fuses a station's decided detections; returns how many were fused (none when the map
    /// rejected the panorama).
    fn fuse_decided(
        &mut self,
        record: &mut StationRecord,
        station: &StationDetections,
        mut ranged: Vec<Ranged>,
        decided: Decided,
    ) -> usize {
        let start = Instant::now();
        let Decided {
            associated,
            recognitions,
            registrations,
        } = decided;
        record.registrations = registrations;
        for (position, decision) in associated.decisions.iter().enumerate() {
            if let Decision::Withheld(why) = decision {
                record.detections[associated.usable[position]].association = Association::Unused {
                    reason: Some(Exclusion::from(*why)),
                };
            }
        }
        let count = associated.fused.len();
        self.apply_size_cue(station, &mut ranged, &associated);
        for (i, r) in ranged.iter().enumerate() {
            record.detections[i].range = detection_record(&station.primary[i], r).range;
        }
        let view = selection::view_of(&ranged, &associated.usable);
        record.order = asserted_order(&view, &associated.usable);
        let fused = self.fuse_station(record, associated, view);
        if fused {
            self.fuse_recognised(record, &recognitions);
        }
        self.audit(record);
        record.seconds.map += start.elapsed().as_secs_f64();
        if fused {
            count
        } else {
            0
        }
    }

    /// The frames station `index` registers against, each with the station it is the frame
    /// of (none for the sketch): the sketch's, and those of the [`RECENT_FRAMES`] stations
    /// nearest in the drive among the recent ones that fused enough landmarks, oldest first.
    /// For the station being mapped the nearest are the latest; a stalled station revisited
    /// later ([`Mapper::revisit_stalled`]) takes those on either side of it.
    fn frames(&self, index: usize) -> (Vec<Option<usize>>, Vec<Frame>) {
        let mut recent: Vec<&Sighted> = self
            .recent(index)
            .iter()
            .filter(|s| s.station != index && s.frame.registrable())
            .collect();
        recent.sort_by_key(|s| (s.station.abs_diff(index), std::cmp::Reverse(s.station)));
        recent.truncate(RECENT_FRAMES);
        recent.sort_by_key(|s| s.station);
        std::iter::once((None, self.sketch.frame(index)))
            .filter(|(_, frame)| frame.registrable())
            .chain(recent.iter().map(|s| (Some(s.station), s.frame.clone())))
            .unzip()
    }

    /// Maps again each stalled station (one whose detections registered against nothing and
    /// were all held back, then given up: [`Stalled`]) within the sketch's window before the
    /// current one whose map has changed since it was last tried, now that later stations
    /// may give it frames to register against; the first pass's decisions stand unless the
    /// new association anchors a detection. The record of the current station lists what
    /// they fused (`fusion.revisited`); a stalled station's own record keeps its first
    /// decisions.
    fn revisit_stalled(&mut self, record: &mut StationRecord) {
        let current = record.index;
        self.stalled.retain(|s| current <= s.index + sketch::WINDOW);
        // A revisit that fuses changes the map and may unstick the others.
        loop {
            let Some(k) = self
                .stalled
                .iter()
                .rposition(|s| s.revision != self.revision)
            else {
                return;
            };
            let stalled = self.stalled.remove(k);
            match self.revisit(&stalled) {
                Some(revisit) => {
                    // Its first pass gave up every held-back detection; those held back again
                    // are counted when they are resolved or given up, those it now leaves out
                    // stay given up.
                    debug_assert!(self.expired >= stalled.held.len());
                    self.expired = self.expired.saturating_sub(stalled.held.len());
                    self.expired += stalled
                        .held
                        .iter()
                        .filter(|&&i| {
                            matches!(
                                revisit.detections[i].association,
                                Association::Unused { .. }
                            )
                        })
                        .count();
                    record.fusion.revisited.extend(
                        revisit
                            .detections
                            .iter()
                            .enumerate()
                            .filter_map(|(detection, d)| match d.association {
                                Association::Matched { landmark }
                                | Association::New { landmark } => Some(LateSighting {
                                    station: stalled.index,
                                    detection,
                                    landmark,
                                }),
                                _ => None,
                            }),
                    );
                    record.fusion.recognised.extend(revisit.fusion.recognised);
                    record.fusion.splits.extend(revisit.fusion.splits);
                    record.warnings.extend(revisit.warnings);
                }
                None => self.stalled.insert(
                    k,
                    Stalled {
                        revision: self.revision,
                        ..stalled
                    },
                ),
            }
        }
    }

    /// Maps the stalled station again if association now anchors any of its detections:
    /// returns its scratch record, whose detections carry the new decisions.
    fn revisit(&mut self, stalled: &Stalled) -> Option<StationRecord> {
        let decided = self.decide(
            stalled.index,
            &stalled.station,
            &stalled.ranged,
            stalled.usable.clone(),
        );
        if !decided
            .associated
            .decisions
            .iter()
            .any(|d| matches!(d, Decision::Matched(_)))
        {
            return None;
        }
        // A station stalls where its view is hard to place (a sharp turn, a long step), and
        // the audit, which compares it with every station that placed its landmarks, would
        // take a placement error of its own for a wrong match and retire every sighting of
        // the landmark (stress seed 17, station 41 revisited: 9 matches, all right; the
        // audit then retired 21 stations' sightings of one). Its matches must agree with
        // every station's placements before anything of it is fused.
        let frame = decided.associated.frame();
        let disputed = self
            .sighted
            .iter()
            .filter(|s| s.station != stalled.index)
            .map(|s| agreement::Witness::new(&s.frame, &frame))
            .any(|witness| {
                frame
                    .landmarks
                    .iter()
                    .any(|&(l, _)| witness.of(l) == Some(false))
            });
        if disputed {
            return None;
        }
        let mut scratch = StationRecord {
            index: stalled.index,
            station: stalled.station.name.clone(),
            detections: self.detection_records(&stalled.station, &stalled.ranged),
            ..StationRecord::default()
        };
        self.fuse_decided(
            &mut scratch,
            &stalled.station,
            stalled.ranged.clone(),
            decided,
        );
        // What its first pass left out and the revisit did not fuse stays out: only what was
        // held back then waits again, so that every held-back detection is counted once.
        self.held.retain(|item| {
            item.station != stalled.index || stalled.held.contains(&item.primary_index)
        });
        Some(scratch)
    }

    /// The decisions with every match whose landmark an earlier station (within the sketch's
    /// window before `index`) placed elsewhere ([`agreement`]) held back, the landmark its only candidate: the detection is another
    /// rock, which may have a landmark of its own, so it is not made a new one on the spot.
    fn undo_disagreeing(
        &self,
        mut decisions: Vec<Decision>,
        evidence: &[Evidence],
        index: usize,
    ) -> Vec<Decision> {
        let matched: Vec<(LandmarkId, Placed)> = decisions
            .iter()
            .zip(evidence)
            .filter_map(|(decision, e)| match decision {
                Decision::Matched(l) => Some((*l, e.placed?)),
                _ => None,
            })
            .collect();
        let disagreeing =
            agreement::disagreeing(&matched, self.recent(index).iter().map(|s| &s.frame));
        for decision in &mut decisions {
            if let Decision::Matched(l) = *decision {
                if disagreeing.contains(&l) {
                    *decision = Decision::HeldBack(vec![l]);
                }
            }
        }
        decisions
    }

    /// The size cue, for landmarks whose width earlier stations bounded (not for parts of a
    /// blob separated by parallax, pieces or doubted detections, whose apparent width may be
    /// part of their rock's: see `selection::width_of`; `sparse-large` seed 3 half, station 38:
    /// a doubted piece 31.5 m away was put at 25.08 m by it; nor for luminance-mode
    /// detections: the stereo test's window widens every blob by a few columns, far more of
    /// a distant rock's width than of a near one's, beyond the cue's margin).
    fn apply_size_cue(
        &self,
        station: &StationDetections,
        ranged: &mut [Ranged],
        associated: &Associated,
    ) {
        for s in &associated.fused {
            let i = associated.usable[s.position];
            let d = &station.primary[i];
            if d.separation != Separation::Whole
                || d.contact_slack_rows > 0.0
                || ranged[i].piece
                || ranged[i].cut_off
                || selection::doubted(d)
            {
                continue;
            }
            if let Some(width) = self.gallery.profile(s.landmark).and_then(|p| p.width) {
                ranging::apply_size(&mut ranged[i], width, &self.sensor);
            }
        }
    }

    /// Fuses the station's associated detections (000 §VI-B) and, if the map takes them,
    /// remembers their looks, sightings and placement, and holds back the undecided ones.
    fn fuse_station(
        &mut self,
        record: &mut StationRecord,
        associated: Associated,
        view: StationView,
    ) -> bool {
        let view = Arc::new(view);
        // With fewer than three landmarks there is no triple to measure, but the sightings
        // still place and describe the landmarks for association at later stations.
        let batch = if associated.fused.len() >= 3 {
            self.map.observations(&view, &associated.fused)
        } else {
            Vec::new()
        };
        record.fusion.landmarks = associated.fused.len();
        record.fusion.triples = batch.len() / 3;
        let before = self.map.len();
        match self.map.fuse(&batch) {
            Ok(report) => {
                record.fusion.relations_tightened = report.relations_tightened;
                // Without a triple, the landmarks decided here enter the map unrelated.
                let decided: Vec<_> = associated.fused.iter().map(|s| s.landmark).collect();
                self.map.add_landmarks(&decided);
                self.journal
                    .record(record.index, Arc::clone(&view), &associated.fused);
                if report.relations_tightened > 0 || self.map.len() != before {
                    self.revision += 1;
                }
                self.next_landmark = associated.next_landmark;
                self.remember(record, &associated, &view);
                self.hold_back(record, associated, view);
                true
            }
            Err(contradiction) => {
                record.fusion.contradiction = Some(contradiction.to_string());
                record.warnings.push(format!(
                    "{}: the panorama contradicts the map and was not fused ({contradiction})",
                    record.station
                ));
                false
            }
        }
    }

    /// Counts the recognitions of held-back observations by this station's anchors
    /// ([`Recognition`], with the station of its frame): of the observation held at that
    /// station and placed at the recognised rock, when the landmark is among its candidates
    /// (its looks and the map allowed it), no other detection of that station took it, and it
    /// is not flat ([`Evidence::flat`]: a soil patch or shadow beside the rock is placed where
    /// the rock is). An observation that [`RECOGNITIONS`] stations recognised, all as one
    /// landmark, is fused as that landmark.
    fn fuse_recognised(
        &mut self,
        record: &mut StationRecord,
        recognitions: &[(usize, Recognition)],
    ) {
        let mut held = std::mem::take(&mut self.held);
        for (station, recognition) in recognitions {
            let landmark = recognition.landmark;
            let Some(k) = held.iter().position(|item| {
                item.station == *station
                    && item.evidence.placed == Some(recognition.unmapped)
                    && !item.evidence.flat
                    && item.candidates.contains(&landmark)
                    && !item.decided.iter().any(|d| d.landmark == landmark)
            }) else {
                continue;
            };
            held[k].recognised.push(landmark);
            let votes = &held[k].recognised;
            if votes.len() < RECOGNITIONS || votes.iter().any(|&l| l != landmark) {
                continue;
            }
            let item = held.remove(k);
            match self.fuse_held(&item, landmark, &mut held) {
                Ok(()) => record.fusion.recognised.push(LateSighting {
                    station: item.station,
                    detection: item.primary_index,
                    landmark,
                }),
                Err(warning) => record.warnings.push(warning),
            }
        }
        self.held = held;
    }

    /// Names the observations given up during the drive, and those still held, once it is
    /// over: an observation is fused as the landmark that the frames of [`RECOGNITIONS`] or
    /// more other stations put on it, each by the motion their shared landmarks agree on and
    /// the unambiguous-partner test of a live recognition
    /// ([`read_unmapped`]), when no frame names another, it may
    /// have been that landmark ([`Mapper::may_have_been`]), it is not flat, and the map does
    /// not reject it ([`Mapper::allows`]). A naming that needed the map to rule a rival out
    /// ([`Mapper::frames_naming`]) is not made while an observation touching it at its
    /// station was held back with the same landmark among its candidates: the frames cannot
    /// tell which of the two the landmark is (stress s4: the blob of a cluster and a whole
    /// rock 0.8 m from it, both held with the cluster's landmark at 20 stations). A live
    /// recognition needs a later station within [`RECENT_FRAMES`] that anchors the rock; a
    /// rock founded later, or seen again only after the rover came back, never had one (colour
    /// marsyard s31 at stop 75: of 60 pieces of mapped rocks left unused, 55 were of rocks
    /// founded 1–20 stations after them, 19 with no station anchoring it within the window;
    /// stop 76, docs/RUN.md).
    fn recognise_given_up(&mut self) {
        let given_up = std::mem::take(&mut self.given_up);
        let pending = std::mem::take(&mut self.held);
        let names = self.frames_naming(given_up.iter().chain(&pending));
        let mut items: Vec<(HeldBack, bool)> = given_up
            .into_iter()
            .map(|item| (item, true))
            .chain(pending.into_iter().map(|item| (item, false)))
            .collect();
        let mut fused = vec![false; items.len()];
        let width = self.calib.image.width;
        for k in 0..items.len() {
            let item = &items[k].0;
            let contested = |l: LandmarkId| {
                items.iter().any(|(other, _)| {
                    other.station == item.station
                        && other.detection != item.detection
                        && other.candidates.contains(&l)
                        && ranging::boxes_touch(other.bbox, item.bbox, width)
                })
            };
            let named = names[k].filter(|&(l, by_map)| !(by_map && contested(l)));
            let Some(landmark) = named.map(|(l, _)| l).filter(|&l| {
                !item.evidence.flat
                    && !item.decided.iter().any(|d| d.landmark == l)
                    && self.may_have_been(item, l)
                    && self.allows(item, l)
            }) else {
                continue;
            };
            let item = item.clone();
            if self.fuse_held(&item, landmark, &mut []).is_err() {
                continue;
            }
            let sighting = Sighting::new(item.detection, landmark);
            for (other, _) in items
                .iter_mut()
                .filter(|(o, _)| o.station == item.station && o.detection != item.detection)
            {
                other.decided.push(sighting);
            }
            // Held back and given up before, it is now recognised instead.
            if items[k].1 && !item.withheld {
                debug_assert!(self.expired > 0, "a given-up observation was counted");
                self.expired = self.expired.saturating_sub(1);
            }
            fused[k] = true;
            self.recognised_at_end.push(LateSighting {
                station: item.station,
                detection: item.primary_index,
                landmark,
            });
        }
        for ((item, given_up), fused) in items.into_iter().zip(fused) {
            match (fused, given_up) {
                (true, _) => {}
                (false, true) => self.given_up.push(item),
                (false, false) => self.held.push(item),
            }
        }
    }

    /// For each of `items`, the landmark that the frames of [`RECOGNITIONS`] or more other
    /// stations put on it ([`read_unmapped`]), if none puts another, and each of its rivals
    /// (its candidates and the landmarks it looks like, [`look_alikes`]) is fused at its
    /// station or held by a naming frame, which places it elsewhere. A rival none of them
    /// holds may be the rock (colour marsyard s41: a blob of two rocks 1.4 m apart, named as
    /// the one whose landmark the naming frames held), unless the observation's range is
    /// trusted ([`crate::association::Evidence::range_trusted`]) and the map rejects the
    /// observation as that rival (000 §VI-C's test) or another station's frame places the
    /// rival apart from the rock, by the motion their shared landmarks agree on, and none
    /// within its reach. The placements and the map's test both rest on the observation's
    /// range, so a ground cue alone does not do (colour marsyard s13: the lit top of a rock
    /// at 1.7 m, read as standing at 2.6 m, named against a rival so ruled out made the map
    /// unsound, by the map at stop 79 and by the frames at stop 82). Stereo where no ground
    /// cue applies measures the rock itself (stop 81). Ruling rivals out by the frames too
    /// raised the fused share of 44 of 53 sets by 0.1–3.6 points (JPEG s11 72.8 → 76.3 %),
    /// lowering none, with no relation unsound (docs/RUN.md, stop 82; stop 76 measured it
    /// without the trusted range and lost purity to blobs named as a neighbour). With each
    /// landmark, whether the map rejected a rival (then an observation touching it may be
    /// the rock: [`Mapper::recognise_given_up`]).
    fn frames_naming<'a>(
        &self,
        items: impl Iterator<Item = &'a HeldBack> + Clone,
    ) -> Vec<Option<(LandmarkId, bool)>> {
        let stations: BTreeSet<usize> = items.clone().map(|item| item.station).collect();
        let mut readings: BTreeMap<(usize, usize), RockReadings> = BTreeMap::new();
        for sighted in self
            .sighted
            .iter()
            .filter(|s| stations.contains(&s.station))
        {
            let found: Vec<(&Frame, UnmappedReading)> = self
                .sighted
                .par_iter()
                .filter(|other| other.station != sighted.station)
                .map(|other| (&other.frame, read_unmapped(&sighted.frame, &other.frame)))
                .collect();
            for (other, reading) in found {
                for (g, l) in reading.named {
                    let rock = readings.entry((sighted.station, g)).or_default();
                    rock.names.push(l);
                    rock.held.extend(other.landmarks.iter().map(|m| m.0));
                }
                for (g, l, may_be) in reading.may_be {
                    let rock = readings.entry((sighted.station, g)).or_default();
                    if may_be {
                        rock.within.insert(l);
                    } else {
                        rock.apart.insert(l);
                    }
                }
            }
        }
        items
            .map(|item| {
                let sighted = self.sighted.iter().find(|s| s.station == item.station)?;
                let placed = item.evidence.placed?;
                let g = sighted.frame.unmapped.iter().position(|&u| u == placed)?;
                let rock = readings.get(&(item.station, g))?;
                let l = *rock.names.first()?;
                if rock.names.len() < RECOGNITIONS || rock.names.iter().any(|&m| m != l) {
                    return None;
                }
                let rivals: BTreeSet<LandmarkId> = item
                    .candidates
                    .iter()
                    .copied()
                    .chain(look_alikes(
                        &item.evidence,
                        &self.gallery,
                        &self.association,
                    ))
                    .filter(|&r| {
                        r != l
                            && !rock.held.contains(&r)
                            && !item.decided.iter().any(|d| d.landmark == r)
                    })
                    .collect();
                let placed_apart =
                    |r: LandmarkId| rock.apart.contains(&r) && !rock.within.contains(&r);
                // The map's test of each rival runs once: whether it rejects any says how the
                // naming was made, whether or not a frame places that rival apart too.
                let mut rejected_any = false;
                let ruled_out = rivals.iter().all(|&r| {
                    item.evidence.range_trusted && {
                        let rejected = !self.allows(item, r);
                        rejected_any |= rejected;
                        placed_apart(r) || rejected
                    }
                });
                ruled_out.then_some((l, rejected_any))
            })
            .collect()
    }

    /// Whether observation `item` may be `landmark`: one of its candidates, or one founded
    /// after its station, never offered to it, whose looks it shares. (A piece left unused is
    /// mostly of a rock whose landmark a whole view of it founded later: colour marsyard s31,
    /// 55 of 60 pieces of mapped rocks; stop 76, docs/RUN.md.)
    fn may_have_been(&self, item: &HeldBack, landmark: LandmarkId) -> bool {
        item.candidates.contains(&landmark)
            || (landmark >= item.founded_after
                && looks_like(&item.evidence, &self.gallery, &self.association, landmark))
    }

    /// Whether the map, as it now stands, does not reject held-back observation `item` as
    /// `landmark` (000 §VI-C's test, which its candidates passed when it was held back).
    fn allows(&self, item: &HeldBack, landmark: LandmarkId) -> bool {
        reconsider(
            &self.map,
            &item.view,
            item.detection,
            &[landmark],
            &item.decided,
            &self.association,
        )
        .is_some_and(|left| left.contains(&landmark))
    }

    /// Fuses held-back observation `item` as `landmark`: its triples with the station's fused
    /// detections, its looks, its sighting, and its place in the station's frame. The
    /// station's other `held` observations gain it as a partner to measure with.
    fn fuse_held(
        &mut self,
        item: &HeldBack,
        landmark: LandmarkId,
        held: &mut [HeldBack],
    ) -> Result<(), String> {
        let sighting = Sighting::new(item.detection, landmark);
        let batch = self
            .map
            .observations_of(&item.view, sighting, &item.decided);
        self.map.fuse(&batch).map_err(|contradiction| {
            format!(
                "held-back observation of station {} dropped: {contradiction}",
                item.station
            )
        })?;
        self.journal.record_added(
            item.station,
            Arc::clone(&item.view),
            sighting,
            &item.decided,
        );
        self.revision += 1;
        self.gallery.observe(
            landmark,
            item.evidence.appearance.clone(),
            item.evidence.width,
        );
        self.sightings
            .push((item.station, item.primary_index, landmark));
        self.last_seen.record(landmark, item.station);
        if let Some(sighted) = self.sighted.iter_mut().find(|s| s.station == item.station) {
            sighted.found_late(
                landmark,
                item.view.bearings[item.detection],
                item.evidence.placed,
            );
        }
        for other in held
            .iter_mut()
            .chain(&mut self.given_up)
            .filter(|o| o.station == item.station && o.detection != item.detection)
        {
            other.decided.push(sighting);
        }
        Ok(())
    }

    /// Records the fused detections' looks and sightings, and the station's bearings and frame
    /// for registration at later stations and for 002's beliefs.
    fn remember(
        &mut self,
        record: &mut StationRecord,
        associated: &Associated,
        view: &StationView,
    ) {
        for s in &associated.fused {
            let i = associated.usable[s.position];
            let evidence = &associated.evidence[s.position];
            // The size cue applied since does not enter the width evidence.
            self.gallery
                .observe(s.landmark, evidence.appearance.clone(), evidence.width);
            self.sightings.push((record.index, i, s.landmark));
            self.last_seen.record(s.landmark, record.index);
            record.detections[i].association = match associated.decisions[s.position] {
                Decision::New => Association::New {
                    landmark: s.landmark,
                },
                _ => Association::Matched {
                    landmark: s.landmark,
                },
            };
        }
        let frame = associated.frame();
        self.sketch
            .update(record.index, &frame.landmarks, &frame.unmapped);
        let sighted = Sighted {
            station: record.index,
            bearings: associated
                .fused
                .iter()
                .map(|s| (s.landmark, view.bearings[s.position]))
                .collect(),
            frame,
        };
        // In drive order: a revisited station takes its first pass's place.
        let at = self.sighted.partition_point(|s| s.station < record.index);
        match self.sighted.get_mut(at) {
            Some(s) if s.station == record.index => *s = sighted,
            _ => self.sighted.insert(at, sighted),
        }
    }

    /// Splits every landmark fused at this station whose placement here an earlier station
    /// contradicts ([`agreement::witness`]) into the rocks its sightings show ([`regroup`]),
    /// and rebuilds the map without the mixture. Association already held back the matches
    /// that recent stations contradict; what is left are sightings whose disagreement only
    /// a station that shares enough landmarks with both can tell.
    fn audit(&mut self, record: &mut StationRecord) {
        let Some(current) = self.sighted.iter().find(|s| s.station == record.index) else {
            return;
        };
        let witnesses: Vec<agreement::Witness> = self
            .sighted
            .iter()
            .filter(|s| s.station != record.index)
            .map(|s| agreement::Witness::new(&s.frame, &current.frame))
            .collect();
        let contradicted: Vec<LandmarkId> = current
            .frame
            .landmarks
            .iter()
            .map(|m| m.0)
            .filter(|&l| witnesses.iter().any(|w| w.of(l) == Some(false)))
            .collect();
        for landmark in contradicted {
            let sightings: Vec<(usize, &Frame)> = self
                .sighted
                .iter()
                .filter(|s| s.frame.landmarks.iter().any(|m| m.0 == landmark))
                .map(|s| (s.station, &s.frame))
                .collect();
            if let Some(regrouping) = regroup(landmark, &sightings) {
                self.split(record, &regrouping);
            }
        }
    }

    /// Gives each further group of `regrouping` a landmark of its own, takes the retired
    /// sightings out, and rebuilds the map from the journal so that the relations the mixed
    /// landmark brought, and what path consistency derived from them, are reverted.
    fn split(&mut self, record: &mut StationRecord, regrouping: &Regrouping) {
        let landmark = regrouping.landmark;
        let new: Vec<LandmarkId> = (1..regrouping.groups.len())
            .map(|_| {
                self.next_landmark += 1;
                self.next_landmark - 1
            })
            .collect();
        let relabel = |station: usize, l: LandmarkId| -> Option<LandmarkId> {
            if l != landmark {
                return Some(l);
            }
            if regrouping.retired.contains(&station) {
                return None;
            }
            Some(
                regrouping
                    .groups
                    .iter()
                    .skip(1)
                    .zip(&new)
                    .find(|(group, _)| group.contains(&station))
                    .map_or(landmark, |(_, &n)| n),
            )
        };
        let replay = self.journal.replay::<C>(relabel);
        self.map = replay.map;
        self.journal = replay.journal;
        for station in replay.rejected {
            record.warnings.push(format!(
                "station {station} no longer fits the map once landmark {landmark} was split, \
                 and was taken out of it"
            ));
        }
        self.relabel_fused(relabel);
        if let Some(profile) = self.gallery.profile(landmark).cloned() {
            for &n in &new {
                self.gallery.profiles.push(Profile {
                    landmark: n,
                    ..profile.clone()
                });
            }
        }
        // A landmark all of whose sightings were retired is no landmark any more.
        if !self.sightings.iter().any(|s| s.2 == landmark) {
            self.gallery.profiles.retain(|p| p.landmark != landmark);
        }
        for (group, &n) in regrouping.groups.iter().skip(1).zip(&new) {
            if let Some(&last) = group.iter().max() {
                self.last_seen.record(n, last);
            }
        }
        // Where the sketch put the landmark averages both rocks' placements.
        self.sketch.forget(landmark);
        self.revision += 1;
        record.fusion.splits.push(SplitRecord {
            landmark,
            new_landmarks: new,
            groups: regrouping.groups.clone(),
            retired: regrouping.retired.clone(),
        });
    }

    /// The stations within the sketch's window before `index`, oldest first. A frame older
    /// than that shows rocks the rover has left behind: on sparse-large seed 3, after 47
    /// stations that fused too few landmarks to push a new frame, station 51 registered six
    /// look-alikes of stations 0–3's rocks by chance (67 unsound relations).
    fn recent(&self, index: usize) -> &[Sighted] {
        let start = self
            .sighted
            .partition_point(|s| s.station + sketch::WINDOW < index);
        &self.sighted[start..]
    }

    /// Keeps the station's undecided detections to be tried again on a tighter map.
    fn hold_back(
        &mut self,
        record: &mut StationRecord,
        associated: Associated,
        view: Arc<StationView>,
    ) {
        let station = record.index;
        let boxes: Vec<[u32; 4]> = associated
            .usable
            .iter()
            .map(|&i| record.detections[i].bbox)
            .collect();
        let observation = |position: usize, candidates: Vec<LandmarkId>, withheld: bool| HeldBack {
            station,
            view: Arc::clone(&view),
            detection: position,
            primary_index: associated.usable[position],
            candidates,
            decided: associated.fused.clone(),
            evidence: associated.evidence[position].clone(),
            recognised: Vec::new(),
            founded_after: associated.next_landmark,
            withheld,
            bbox: boxes[position],
        };
        for (position, candidates) in &associated.held {
            record.detections[associated.usable[*position]].association = Association::HeldBack {
                candidates: candidates.clone(),
            };
            self.held
                .push(observation(*position, candidates.clone(), false));
        }
        // Without two fused partners at its station it could not be measured.
        if associated.fused.len() >= 2 {
            for &position in &associated.withheld {
                self.given_up.push(observation(position, Vec::new(), true));
            }
        }
    }

    /// Tries the held-back observations of the last [`HOLD_STATIONS`] stations against the
    /// current map; returns how many were resolved (every candidate rejected: a new landmark)
    /// and fused. The others wait to be recognised while their station's frame is among the
    /// recent ones ([`Mapper::fuse_recognised`]).
    fn retry_held_back(&mut self, record: &mut StationRecord) -> usize {
        let current = record.index;
        // Observations whose station's frame is no longer registered against, or that have
        // too few fused partners at their station to be measured with, are given up; the
        // measurable ones wait for the end of the drive ([`Mapper::recognise_given_up`]).
        let (mut pending, out): (Vec<HeldBack>, Vec<HeldBack>) = std::mem::take(&mut self.held)
            .into_iter()
            .partition(|item| current < item.station + RECENT_FRAMES && item.decided.len() >= 2);
        for item in out {
            self.expired += 1;
            if item.decided.len() >= 2 && item.evidence.placed.is_some() {
                self.given_up.push(item);
            }
        }
        let mut resolved = 0;
        let mut done = vec![false; pending.len()];
        for k in 0..pending.len() {
            let item = &pending[k];
            if current > item.station + HOLD_STATIONS {
                continue;
            }
            let standing = reconsider(
                &self.map,
                &item.view,
                item.detection,
                &item.candidates,
                &item.decided,
                &self.association,
            );
            match standing {
                // Other detections of the station took every candidate: undecidable.
                None => {
                    done[k] = true;
                    self.expired += 1;
                    continue;
                }
                Some(candidates) if !candidates.is_empty() => {
                    pending[k].candidates = candidates;
                    continue;
                }
                // Every candidate rejected: a rock the map did not have, unless the detection
                // founds no landmark (a piece, too small, or placed too loosely).
                Some(_) if unfounded(&item.evidence).is_some() => {
                    done[k] = true;
                    self.expired += 1;
                    continue;
                }
                Some(_) => done[k] = true,
            }
            let item = pending[k].clone();
            match self.fuse_held(&item, self.next_landmark, &mut pending) {
                Ok(()) => {
                    self.next_landmark += 1;
                    resolved += 1;
                }
                Err(warning) => record.warnings.push(warning),
            }
        }
        self.held = pending
            .into_iter()
            .zip(done)
            .filter(|(_, d)| !d)
            .map(|(item, _)| item)
            .collect();
        resolved
    }

    /// The RNG estimate of the map after the latest station.
    pub fn rng(&self) -> &RngEstimate {
        &self.rng
    }

    /// Counts the changes of the map (see [`Mapper::rng`]): equal revisions, equal maps.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The map's state after a station; the RNG estimate is computed once here and kept for
    /// [`Mapper::rng`] (on a long drive it is the costliest per-station query: every pair of
    /// landmarks against every third), and neither is computed again while the map is
    /// unchanged (on the 1 000-rock drive, half the stations fuse nothing new).
    fn refresh_metrics(&mut self) -> MetricsRecord {
        match &self.metrics {
            Some((revision, metrics)) if *revision == self.revision => metrics.clone(),
            _ => {
                let metrics = self.measure_map();
                self.metrics = Some((self.revision, metrics.clone()));
                metrics
            }
        }
    }

    /// The map's metrics and RNG estimate, computed afresh.
    fn measure_map(&mut self) -> MetricsRecord {
        let triples = self.map.triple_count();
        let states = 3 * triples * C::universe().len();
        self.rng = estimate(&self.map).unwrap_or_default();
        let rng = &self.rng;
        MetricsRecord {
            landmarks: self.map.len(),
            triples,
            open_fraction: ratio(self.map.open_states(), states),
            fully_constrained_fraction: ratio(self.map.fully_constrained_triples(), triples),
            rng_certain: rng.certain().count(),
            rng_uncertain: rng.edges.len() - rng.certain().count(),
            rng_cost: rng.total_cost(),
        }
    }
}

/// Stations whose sightings a landmark must have been fused from for the published map to
/// hold it ([`Mapper::finish`]): one other station that found the same rock is the least
/// corroboration there is.
const CORROBORATING_STATIONS: usize = 2;

/// Recent stations registered against (a rover moves a few metres between stations: the most
/// recent ones share most landmarks with the current one). Only stations that fused enough
/// landmarks to register against count: with no registrable frame left, every rock would come
/// back as a new landmark.
const RECENT_FRAMES: usize = 6;

/// Stations a held-back observation waits for the map to tighten before it is given up (an
/// observation not fused loses information, never soundness). One: on the presets no
/// observation resolved at a second retry, and every retry measures again.
const HOLD_STATIONS: usize = 1;

/// Stations that must recognise a held-back observation, all as the same landmark, before it
/// is fused ([`Mapper::fuse_recognised`]). One registration can carry a neighbour's identity
/// back: on grayscale marsyard seed 7, fusing on the first recognition fused 130 held-back
/// observations, 7 of them of a rock 0.7–2.3 m from the landmark's (3 unsound relations);
/// on the second, 40, every one of its rock (marsyard seed 7: 91 of 91).
const RECOGNITIONS: usize = 2;

/// Fewest pairs of stations whose frames put two landmarks on each other before they are
/// merged as one rock ([`Mapper::merge_duplicates`]): one pair may fit by chance, as one
/// recognition may ([`RECOGNITIONS`]). The two merges of stop 78's 27 sets had 100 and 104.
const MERGING_FRAME_PAIRS: usize = 2;

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

fn detection_record(d: &Detection, r: &Ranged) -> DetectionRecord {
    DetectionRecord {
        bbox: d.bbox,
        centroid: d.centroid,
        contact_row: d.contact_row,
        contact_slack_rows: d.contact_slack_rows,
        pixels: d.pixels,
        flat: d.flat,
        stereo_column: r.stereo_column,
        bearing: r.bearing.angle,
        bearing_uncertainty: r.measured_bearing().uncertainty,
        range: RangeRecord {
            ground: r.ground.map(|g| g.as_array()),
            stereo: r.stereo.map(|s| s.as_array()),
            size: r.size.map(|s| s.as_array()),
            fused: r.fused.as_array(),
            conflict: r.conflict,
        },
        association: Association::default(),
    }
}

/// A station after association: its usable detections (indices into its primary detections,
/// by position in its panorama), the evidence and decision of each, and what follows for the
/// map: the sightings to fuse, new landmarks numbered from the map's next id, and the
/// detections to hold back with their candidates.
struct Associated {
    usable: Vec<usize>,
    evidence: Vec<Evidence>,
    /// Placements of the station's detections mapping does not use.
    unused: Vec<Placed>,
    decisions: Vec<Decision>,
    fused: Vec<Sighting>,
    held: Vec<(usize, Vec<LandmarkId>)>,
    /// Placed detections that matched no landmark and founded none for being a piece or
    /// doubted: they wait for the end of the drive ([`HeldBack::withheld`]).
    withheld: Vec<usize>,
    /// The map's next landmark id once the new ones are fused.
    next_landmark: LandmarkId,
}

impl Associated {
    /// The station's frame: its fused landmarks and the rocks it left unmapped, placed.
    fn frame(&self) -> Frame {
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: self.unmapped(),
            landmarks: self
                .fused
                .iter()
                .filter_map(|s| Some((s.landmark, self.evidence[s.position].placed?)))
                .collect(),
        }
    }

    /// The rocks the station saw that it fused into no landmark: detections held back or
    /// founding none, and those mapping does not use.
    fn unmapped(&self) -> Vec<Placed> {
        (0..self.evidence.len())
            .filter(|&position| !self.fused.iter().any(|s| s.position == position))
            .filter_map(|position| self.evidence[position].placed)
            .chain(self.unused.iter().copied())
            .collect()
    }

    fn new(
        usable: Vec<usize>,
        station: StationEvidence,
        decisions: Vec<Decision>,
        mut next_landmark: LandmarkId,
    ) -> Associated {
        let mut fused = Vec::new();
        let mut held = Vec::new();
        let mut withheld = Vec::new();
        for (position, decision) in decisions.iter().enumerate() {
            match decision {
                Decision::Matched(l) => fused.push(Sighting::new(position, *l)),
                Decision::New => {
                    fused.push(Sighting::new(position, next_landmark));
                    next_landmark += 1;
                }
                Decision::HeldBack(candidates) => held.push((position, candidates.clone())),
                Decision::Withheld(Unfounded::Piece | Unfounded::Doubtful)
                    if station.detections[position].placed.is_some() =>
                {
                    withheld.push(position)
                }
                Decision::Withheld(_) => {}
            }
        }
        Associated {
            usable,
            evidence: station.detections,
            unused: station.unused_placed,
            decisions,
            fused,
            held,
            withheld,
            next_landmark,
        }
    }
}

/// The asserted "nearer than" pairs of the panorama, as indices into the station's primary
/// detections.
fn asserted_order(view: &StationView, usable: &[usize]) -> Vec<(usize, usize)> {
    (0..usable.len())
        .flat_map(|a| (0..usable.len()).map(move |b| (a, b)))
        .filter(|&(a, b)| view.order.is_nearer(a, b))
        .map(|(a, b)| (usable[a], usable[b]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::association::test_drive::{seen, unsound, Seen, A, B, STATIONS};
    use crate::detection::Appearance;
    use qrm_core::edc::Edc;

    fn test_mapper() -> Mapper<Edc> {
        let calib = Calibration::parse(
            include_str!("../../../../calib/default.toml"),
            "default.toml",
        )
        .expect("the default calibration");
        Mapper::new(
            calib,
            SensorModel::default(),
            AssociationSettings::default(),
        )
    }

    /// Fuses station `step` of the test drive as `label` associates its rocks, with nothing
    /// checking the association, and remembers it as `Mapper::remember` would.
    fn fuse_unchecked(
        mapper: &mut Mapper<Edc>,
        step: usize,
        seen: &Seen,
        label: impl Fn(usize) -> LandmarkId + Copy,
    ) {
        let looks = Appearance {
            colour: [0.4, 0.3, 0.3],
            brightness: 1.0,
            texture: 0.1,
            dark_fraction: 0.2,
        };
        let fused = seen.sightings(label);
        let view = Arc::new(seen.view.clone());
        let batch = mapper.map.observations(&view, &fused);
        mapper.map.fuse(&batch).expect("a quiet association fits");
        mapper.journal.record(step, view, &fused);
        for s in &fused {
            mapper.sightings.push((step, s.position, s.landmark));
            mapper.gallery.observe(s.landmark, looks.clone(), None);
            mapper.last_seen.record(s.landmark, step);
        }
        mapper.sighted.push(Sighted {
            station: step,
            bearings: fused
                .iter()
                .map(|s| (s.landmark, seen.view.bearings[s.position]))
                .collect(),
            frame: seen.frame(label),
        });
    }

    #[test]
    fn a_landmark_founded_late_joins_its_stations_frame() {
        let placed = |x: f64| Placed::disc([x, 0.0], 0.5);
        let mut sighted = Sighted {
            station: 2,
            bearings: BTreeMap::new(),
            frame: Frame {
                landmarks: vec![(0, placed(1.0))],
                unmapped: vec![placed(2.0), placed(3.0)],
                accumulated: false,
                departed: Vec::new(),
                tracks: Vec::new(),
            },
        };
        sighted.found_late(7, Bearing::exact(0.5), Some(placed(3.0)));
        assert_eq!(
            sighted.frame.landmarks,
            vec![(0, placed(1.0)), (7, placed(3.0))]
        );
        assert_eq!(sighted.frame.unmapped, vec![placed(2.0)]);
        assert_eq!(sighted.bearings.get(&7), Some(&Bearing::exact(0.5)));
        // Unplaced, it is only a bearing.
        sighted.found_late(8, Bearing::exact(1.0), None);
        assert_eq!(sighted.frame.landmarks.len(), 2);
        assert_eq!(sighted.bearings.len(), 2);
    }

    /// The test drive's stations 0–2 fused with every rock as its own landmark, but rock
    /// `R` at station 2 held back with landmarks `R` and 3 for candidates; returns the held
    /// observation's placement.
    fn held_at_station_2(mapper: &mut Mapper<Edc>) -> Placed {
        const R: usize = 15;
        let identity = |r: usize| r as LandmarkId;
        fuse_unchecked(mapper, 0, &seen(0, STATIONS), identity);
        fuse_unchecked(mapper, 1, &seen(1, STATIONS), identity);
        let seen = seen(2, STATIONS);
        let k = seen.rocks.iter().position(|&r| r == R).expect("R in view");
        let decided: Vec<Sighting> = seen
            .sightings(identity)
            .into_iter()
            .filter(|s| s.position != k)
            .collect();
        let view = Arc::new(seen.view.clone());
        let batch = mapper.map.observations(&view, &decided);
        mapper.map.fuse(&batch).expect("a true association fits");
        mapper.journal.record(2, Arc::clone(&view), &decided);
        let mut frame = seen.frame(identity);
        frame.landmarks.remove(k);
        frame.unmapped.push(seen.placed[k]);
        mapper.sighted.push(Sighted {
            station: 2,
            bearings: BTreeMap::new(),
            frame,
        });
        let p = seen.placed[k].point;
        mapper.held.push(HeldBack {
            station: 2,
            view,
            detection: k,
            primary_index: k,
            candidates: vec![R as LandmarkId, 3],
            decided,
            evidence: Evidence {
                appearance: Appearance {
                    colour: [0.4, 0.3, 0.3],
                    brightness: 1.0,
                    texture: 0.1,
                    dark_fraction: 0.2,
                },
                width: None,
                placed: Some(seen.placed[k]),
                ray: crate::ranging::Ray {
                    azimuth: p[1].atan2(p[0]).rem_euclid(std::f64::consts::TAU),
                    half_baseline: 0.0,
                    nearest: 0.0,
                    half_width: 0.0,
                },
                piece: false,
                doubtful: false,
                flat: false,
                surely_flat: false,
                pixels: 100,
                range_trusted: true,
            },
            recognised: Vec::new(),
            founded_after: LandmarkId::MAX,
            withheld: false,
            bbox: [0, 0, 9, 9],
        });
        seen.placed[k]
    }

    /// Station `index`'s record after it recognised the observation held at station 2 as
    /// `landmark`.
    fn recognise(
        mapper: &mut Mapper<Edc>,
        index: usize,
        at: Placed,
        landmark: LandmarkId,
    ) -> StationRecord {
        let mut record = StationRecord {
            index,
            ..StationRecord::default()
        };
        let recognition = Recognition {
            frame: 1,
            unmapped: at,
            detection: 0,
            landmark,
        };
        mapper.fuse_recognised(&mut record, &[(2, recognition)]);
        record
    }

    #[test]
    fn a_held_back_observation_recognised_twice_as_one_landmark_is_fused() {
        let mut mapper = test_mapper();
        let at = held_at_station_2(&mut mapper);
        assert!(recognise(&mut mapper, 3, at, 15)
            .fusion
            .recognised
            .is_empty());
        assert_eq!(mapper.held_back(), 1, "one recognition fuses nothing");
        let record = recognise(&mut mapper, 4, at, 15);
        let k = mapper.sighted[2].frame.landmarks.len();
        assert_eq!(
            record.fusion.recognised,
            [LateSighting {
                station: 2,
                detection: seen(2, STATIONS)
                    .rocks
                    .iter()
                    .position(|&r| r == 15)
                    .unwrap(),
                landmark: 15,
            }]
        );
        assert_eq!(mapper.held_back(), 0);
        assert!(mapper
            .sightings
            .contains(&(2, record.fusion.recognised[0].detection, 15)));
        // Station 2's frame now holds the landmark where it placed the rock.
        assert_eq!(mapper.sighted[2].frame.landmarks[k - 1], (15, at));
        assert!(mapper.sighted[2].frame.unmapped.is_empty());
        assert_eq!(unsound(&mapper.map, |l| l as usize), 0);
    }

    /// Stations 3 and 4 recognise the observation held at station 2 (flat or not) as `first`
    /// and `second`: nothing is fused, and it stays held.
    fn assert_stays_held(flat: bool, first: LandmarkId, second: LandmarkId) {
        let mut mapper = test_mapper();
        let at = held_at_station_2(&mut mapper);
        mapper.held[0].evidence.flat = flat;
        recognise(&mut mapper, 3, at, first);
        assert!(recognise(&mut mapper, 4, at, second)
            .fusion
            .recognised
            .is_empty());
        assert_eq!(mapper.held_back(), 1);
    }

    /// A flat detection (nothing of it stands up by stereo) may be a soil patch beside the
    /// rock: recognised twice, it stays held (the 1 000-rock drive, station 97: a 24 × 5 px
    /// box that meets no rock, recognised as landmark 316, made 8 unsound relations).
    #[test]
    fn a_flat_held_back_observation_is_not_fused_on_recognitions() {
        assert_stays_held(true, 15, 15);
    }

    /// Two stations that recognise the observation as different landmarks leave it held, nor
    /// does a landmark the observation was not a candidate for count.
    #[test]
    fn recognitions_as_different_landmarks_fuse_nothing() {
        assert_stays_held(false, 15, 3);
        assert_stays_held(false, 15, 7);
    }

    /// The observation of rock 15 held at station 2 with `candidates`, given up, its looks
    /// unlike every landmark's (its candidates are its only rivals), and stations 3 and 4
    /// fused after it; returns its position in station 2's view.
    fn given_up_at_station_2(mapper: &mut Mapper<Edc>, candidates: Vec<LandmarkId>) -> usize {
        held_at_station_2(mapper);
        let mut item = mapper.held.pop().expect("held at station 2");
        item.candidates = candidates;
        item.evidence.appearance.brightness *= 50.0;
        let k = item.detection;
        mapper.given_up.push(item);
        mapper.expired = 1;
        for step in 3..5 {
            fuse_unchecked(mapper, step, &seen(step, STATIONS), |r| r as LandmarkId);
        }
        k
    }

    /// The end of the drive fused station 2's detection at position `k`, and only that, as
    /// landmark 15.
    fn assert_named_15_at_end(mapper: &Mapper<Edc>, k: usize) {
        assert_eq!(
            mapper.recognised_at_end,
            [LateSighting {
                station: 2,
                detection: k,
                landmark: 15,
            }]
        );
    }

    /// Once the drive is over, the frames of the stations before and after name the given-up
    /// observation as its rock's landmark, and it is fused as that.
    #[test]
    fn a_given_up_observation_named_by_other_frames_is_fused_at_the_end() {
        let mut mapper = test_mapper();
        let k = given_up_at_station_2(&mut mapper, vec![15, 3]);
        mapper.finish();
        assert_named_15_at_end(&mapper, k);
        assert!(mapper.sightings.contains(&(2, k, 15)));
        assert_eq!(mapper.expired, 0, "no longer given up");
        assert!(mapper.given_up.is_empty());
        assert_eq!(unsound(&mapper.map, |l| l as usize), 0);
    }

    /// A candidate that neither the observation's station fused nor any naming frame holds
    /// may be its rock: the observation stays given up.
    #[test]
    fn a_rival_no_frame_places_keeps_a_given_up_observation_out() {
        let mut mapper = test_mapper();
        given_up_at_station_2(&mut mapper, vec![15, 99]);
        mapper.finish();
        assert!(mapper.recognised_at_end.is_empty());
        assert_eq!(mapper.given_up.len(), 1);
        assert_eq!(mapper.expired, 1);
    }

    /// The observation given up at station 2 with landmarks 15 and 7 for candidates, no
    /// naming frame holding 7 (rock 7, 11 m down the drive, seen from station 4 on): a rival
    /// only the map can rule out. Returns its position.
    fn given_up_with_a_rival_only_the_map_rejects(
        mapper: &mut Mapper<Edc>,
        range_trusted: bool,
    ) -> usize {
        let k = given_up_at_station_2(mapper, vec![15, 7]);
        for sighted in &mut mapper.sighted {
            sighted.frame.landmarks.retain(|&(l, _)| l != 7);
        }
        mapper.given_up[0].evidence.range_trusted = range_trusted;
        k
    }

    /// The map rejects rock 15's observation as landmark 7, and the observation's range is
    /// trusted: the rival is ruled out, and the frames' naming stands.
    #[test]
    fn a_rival_the_map_rejects_rules_itself_out_for_an_observation_whose_range_is_trusted() {
        let mut mapper = test_mapper();
        let k = given_up_with_a_rival_only_the_map_rejects(&mut mapper, true);
        assert!(!mapper.allows(&mapper.given_up[0], 7));
        mapper.finish();
        assert_named_15_at_end(&mapper, k);
        assert_eq!(unsound(&mapper.map, |l| l as usize), 0);
    }

    /// On a ground cue alone the map's rejection rests on a range that may be wrong: the rival
    /// stands, and so does an observation touching it held with the same landmark.
    #[test]
    fn a_rival_the_map_rejects_stands_on_an_untrusted_range_or_beside_a_contested_observation() {
        let mut mapper = test_mapper();
        given_up_with_a_rival_only_the_map_rejects(&mut mapper, false);
        mapper.finish();
        assert!(mapper.recognised_at_end.is_empty());
        assert_eq!(mapper.given_up.len(), 1);

        let mut mapper = test_mapper();
        let k = given_up_with_a_rival_only_the_map_rejects(&mut mapper, true);
        hold_one_touching(&mut mapper, k);
        mapper.finish();
        assert!(mapper.recognised_at_end.is_empty());
        assert!(mapper.given_up.iter().any(|item| item.detection == k));
    }

    /// Holds back at station 2, beside the given-up observation at position `k`, one whose box
    /// touches it, with landmark 15 for its only candidate.
    fn hold_one_touching(mapper: &mut Mapper<Edc>, k: usize) {
        let mut beside = mapper.given_up[0].clone();
        mapper.given_up[0].bbox = [100, 50, 120, 60];
        beside.bbox = [122, 52, 140, 62];
        beside.detection = (k + 1) % beside.view.bearings.len();
        beside.candidates = vec![15];
        beside.evidence.placed = None;
        mapper.held.push(beside);
    }

    /// A rival the map rejects leaves the naming to the map even where another frame places
    /// it apart too (station 5's, which does not hold 15): beside a contested observation it
    /// stands.
    #[test]
    fn a_rival_the_map_rejects_and_a_frame_places_apart_stands_beside_a_contested_observation() {
        let mut mapper = test_mapper();
        let k = given_up_with_a_rival_only_the_map_rejects(&mut mapper, true);
        fuse_unchecked(&mut mapper, 5, &seen(5, STATIONS), |r| r as LandmarkId);
        let frame = &mut mapper.sighted.last_mut().expect("just fused").frame;
        frame.landmarks.retain(|&(l, _)| l != 15);
        assert!(frame.landmarks.iter().any(|&(l, _)| l == 7));
        hold_one_touching(&mut mapper, k);
        mapper.finish();
        assert!(mapper.recognised_at_end.is_empty());
        assert!(mapper.given_up.iter().any(|item| item.detection == k));
    }

    /// The observation given up at station 2 with landmarks 15 and 99 for candidates, 99 a
    /// landmark the map does not reject it as and no naming frame holds: the frames of
    /// stations 5 and on, which do not hold 15, hold it as placed in `rival` (each in its
    /// station's coordinates; rock 15 lies at (5 − station, 1.5)). Returns its position.
    fn given_up_with_a_rival_later_frames_hold(
        mapper: &mut Mapper<Edc>,
        rival: &[Placed],
        range_trusted: bool,
    ) -> usize {
        let k = given_up_at_station_2(mapper, vec![15, 99]);
        for (step, &at) in (5..).zip(rival) {
            fuse_unchecked(mapper, step, &seen(step, STATIONS), |r| r as LandmarkId);
            let frame = &mut mapper.sighted.last_mut().expect("just fused").frame;
            frame.landmarks.retain(|&(l, _)| l != 15);
            frame.landmarks.push((99, at));
        }
        mapper.given_up[0].evidence.range_trusted = range_trusted;
        assert!(mapper.allows(&mapper.given_up[0], 99));
        k
    }

    /// 6 m from rock 15, seen from station 5.
    fn apart() -> Placed {
        Placed::disc([-2.0, -6.0], 0.3)
    }

    /// A rival that another station's frame places apart from the rock is not the rock, when
    /// the observation's range is trusted: the frames' naming stands.
    #[test]
    fn a_rival_another_frame_places_apart_rules_itself_out_for_an_observation_whose_range_is_trusted(
    ) {
        let mut mapper = test_mapper();
        let k = given_up_with_a_rival_later_frames_hold(&mut mapper, &[apart()], true);
        mapper.finish();
        assert_named_15_at_end(&mapper, k);
        assert_eq!(unsound(&mapper.map, |l| l as usize), 0);
    }

    /// Not on a range that may be wrong, nor where another frame places the rival within the
    /// rock's reach (station 6, too loosely to name the rock).
    #[test]
    fn a_rival_placed_apart_from_an_untrusted_range_or_also_within_reach_stands() {
        let within = Placed::disc([-0.5, 1.5], 2.5);
        for (rival, range_trusted) in [(vec![apart()], false), (vec![apart(), within], true)] {
            let mut mapper = test_mapper();
            given_up_with_a_rival_later_frames_hold(&mut mapper, &rival, range_trusted);
            mapper.finish();
            assert!(mapper.recognised_at_end.is_empty(), "{rival:?}");
            assert_eq!(mapper.given_up.len(), 1);
        }
    }

    /// Rock 15's detection at station 2 as a piece that matched no landmark and founded none,
    /// seen before landmarks `founded_after` on were founded, and stations 3 and 4 fused after
    /// it; landmark 15 alone looks like it when `alike`. Returns its position.
    fn piece_at_station_2(
        mapper: &mut Mapper<Edc>,
        founded_after: LandmarkId,
        alike: bool,
    ) -> usize {
        let k = given_up_at_station_2(mapper, Vec::new());
        mapper.expired = 0;
        let item = &mut mapper.given_up[0];
        item.withheld = true;
        item.evidence.piece = true;
        item.founded_after = founded_after;
        if alike {
            let looks = item.evidence.appearance.clone();
            let profile = mapper
                .gallery
                .profiles
                .iter_mut()
                .find(|p| p.landmark == 15);
            profile.expect("landmark 15's looks").appearance = looks;
        }
        k
    }

    /// A piece named by the other stations' frames as a landmark founded after it, whose
    /// looks it shares, is fused as that landmark at the end.
    #[test]
    fn a_piece_named_as_a_landmark_founded_after_it_is_fused_at_the_end() {
        let mut mapper = test_mapper();
        let k = piece_at_station_2(&mut mapper, 10, true);
        mapper.finish();
        assert_named_15_at_end(&mapper, k);
        assert_eq!(mapper.expired, 0, "a piece was never held back");
        assert_eq!(unsound(&mapper.map, |l| l as usize), 0);
    }

    /// Not as a landmark that existed when the piece was seen (association did not take it
    /// then), nor as one whose looks are not the piece's.
    #[test]
    fn a_piece_is_not_named_as_an_older_or_unlike_landmark() {
        for (founded_after, alike) in [(16, true), (10, false)] {
            let mut mapper = test_mapper();
            piece_at_station_2(&mut mapper, founded_after, alike);
            mapper.finish();
            assert!(mapper.recognised_at_end.is_empty());
            assert_eq!(mapper.given_up.len(), 1);
        }
    }

    #[test]
    fn a_landmark_found_to_mix_two_rocks_is_split_and_the_map_rebuilt_sound() {
        let mut mapper = test_mapper();
        mapper.next_landmark = 100;
        let mut b_landmark = A as LandmarkId;
        let mut splits = Vec::new();
        for step in 0..STATIONS {
            let seen = seen(step, 12);
            let label = |r: usize| if r == B { b_landmark } else { r as LandmarkId };
            fuse_unchecked(&mut mapper, step, &seen, label);
            let mut record = StationRecord {
                index: step,
                ..StationRecord::default()
            };
            mapper.audit(&mut record);
            splits.extend(record.fusion.splits);
            if let Some(k) = seen.rocks.iter().position(|&r| r == B) {
                b_landmark = mapper
                    .sightings
                    .iter()
                    .find(|s| s.0 == step && s.1 == k)
                    .map_or(b_landmark, |s| s.2);
            }
        }
        assert_eq!(splits.len(), 1, "{splits:?}");
        assert_eq!(splits[0].new_landmarks, vec![100]);
        // Every landmark's sightings now show one rock; rock A's keep landmark A.
        let mut rock_of: BTreeMap<LandmarkId, usize> = BTreeMap::new();
        for &(station, position, l) in &mapper.sightings {
            let r = seen(station, 12).rocks[position];
            assert_eq!(
                *rock_of.entry(l).or_insert(r),
                r,
                "landmark {l} mixes rocks"
            );
        }
        assert_eq!(rock_of[&(A as LandmarkId)], A);
        assert_eq!(unsound(&mapper.map, |l| rock_of[&l]), 0);
        // Frames, gallery and journal follow the split.
        for s in &mapper.sighted {
            for &(l, _) in &s.frame.landmarks {
                assert!(mapper.gallery.profile(l).is_some());
                assert!(mapper.map.contains(l));
            }
        }
        let replayed = mapper.journal.replay::<Edc>(|_, l| Some(l));
        assert_eq!(replayed.map, mapper.map);
    }

    /// Rock A of the test drive, founded again as landmark 100 from station 12 on, as if the
    /// rover had lost it and come back: the frames put the two landmarks on each other, and
    /// they are merged into the older with a sound map, journal and gallery to match.
    #[test]
    fn a_rock_founded_twice_is_merged_into_its_older_landmark() {
        let mut mapper = test_mapper();
        for step in 0..STATIONS {
            let label = |r: usize| match r {
                A if step >= 12 => 100,
                r => r as LandmarkId,
            };
            fuse_unchecked(&mut mapper, step, &seen(step, STATIONS), label);
        }
        assert!(mapper.map.contains(100));
        mapper.merge_duplicates();
        assert_eq!(mapper.merged.len(), 1, "{:?}", mapper.merged);
        assert_eq!(
            (mapper.merged[0].landmark, mapper.merged[0].duplicate),
            (A as LandmarkId, 100)
        );
        assert!(mapper.merged[0].frame_pairs >= MERGING_FRAME_PAIRS);
        assert!(!mapper.map.contains(100));
        assert!(mapper.sightings.iter().all(|s| s.2 != 100));
        assert!(mapper.gallery.profile(100).is_none());
        assert!(mapper
            .sighted
            .iter()
            .all(|s| s.frame.landmarks.iter().all(|m| m.0 != 100)));
        assert_eq!(unsound(&mapper.map, |l| l as usize), 0);
        let replayed = mapper.journal.replay::<Edc>(|_, l| Some(l));
        assert_eq!(replayed.map, mapper.map);
    }

    /// Rocks A and B, 1.5 m apart, each seen on one half of the drive only: never fused at one
    /// station, but the frames put them apart, and they stay two landmarks.
    #[test]
    fn rocks_seen_on_either_half_of_the_drive_stay_two_landmarks() {
        let mut mapper = test_mapper();
        for step in 0..STATIONS {
            fuse_unchecked(&mut mapper, step, &seen(step, 12), |r| r as LandmarkId);
        }
        mapper.merge_duplicates();
        assert!(mapper.merged.is_empty(), "{:?}", mapper.merged);
        assert!(mapper.map.contains(A as LandmarkId) && mapper.map.contains(B as LandmarkId));
    }

    /// A regrouping may retire every sighting (one group that disagrees with itself): the
    /// landmark then leaves the map, its gallery and the frames, and nothing else changes.
    #[test]
    fn a_landmark_whose_every_sighting_is_retired_leaves_the_map() {
        let mut mapper = test_mapper();
        let stations = 6;
        for step in 0..stations {
            fuse_unchecked(&mut mapper, step, &seen(step, usize::MAX), |r| {
                r as LandmarkId
            });
        }
        let landmark = A as LandmarkId;
        let retired: Vec<usize> = (0..stations)
            .filter(|&step| seen(step, usize::MAX).rocks.contains(&A))
            .collect();
        assert!(!retired.is_empty());
        let mut record = StationRecord::default();
        mapper.split(
            &mut record,
            &Regrouping {
                landmark,
                groups: Vec::new(),
                retired,
            },
        );
        assert!(mapper.sightings.iter().all(|s| s.2 != landmark));
        assert!(mapper.gallery.profile(landmark).is_none());
        assert!(!mapper.map.contains(landmark));
        assert!(mapper.sighted.iter().all(|s| s
            .frame
            .landmarks
            .iter()
            .all(|&(l, _)| l != landmark)));
        assert_eq!(
            record.fusion.splits[0].new_landmarks,
            Vec::<LandmarkId>::new()
        );
    }

    /// A landmark fused from one station only leaves the published map, its gallery, the
    /// frames and the RNG; the landmarks fused from two or more stay, related as before.
    #[test]
    fn finishing_leaves_out_the_landmarks_fused_from_one_station_only() {
        const ONCE: LandmarkId = 100;
        let mut mapper = test_mapper();
        let identity = |r: usize| r as LandmarkId;
        fuse_unchecked(&mut mapper, 0, &seen(0, usize::MAX), identity);
        fuse_unchecked(&mut mapper, 1, &seen(1, usize::MAX), identity);
        let third = seen(2, usize::MAX);
        let first_seen = |k: &usize| (0..2).all(|step| !seen(step, usize::MAX).rocks.contains(k));
        // A rock station 2 is the first to see: as another label for a rock the earlier
        // stations fused, landmark ONCE would be merged into that rock's landmark.
        let r = *third
            .rocks
            .iter()
            .find(|k| first_seen(k))
            .expect("a new rock");
        fuse_unchecked(&mut mapper, 2, &third, |k| {
            if k == r {
                ONCE
            } else {
                k as LandmarkId
            }
        });
        assert!(mapper.map.contains(ONCE));
        let before = mapper.map.clone();
        let published = mapper.finish();
        // The rocks station 2 is the first to see are fused from it alone too.
        let mut once: Vec<LandmarkId> = third
            .rocks
            .iter()
            .filter(|&k| *k != r && first_seen(k))
            .map(|&k| k as LandmarkId)
            .chain([ONCE])
            .collect();
        once.sort_unstable();
        let mut uncorroborated = mapper.uncorroborated.clone();
        uncorroborated.sort_unstable();
        assert_eq!(uncorroborated, once);
        assert!(mapper.merged.is_empty());
        assert!(!mapper.map.contains(ONCE));
        assert!(mapper.landmarks().iter().all(|l| l.landmark != ONCE));
        assert!(mapper
            .sighted
            .iter()
            .all(|s| !s.bearings.contains_key(&ONCE)
                && s.frame.landmarks.iter().all(|&(l, _)| l != ONCE)));
        assert_eq!(published.landmarks, before.len() - once.len());
        assert_eq!(published.landmarks, mapper.map.len());
        for (a, b, c, [ab_c, bc_a, ca_b]) in mapper.map.triples() {
            assert_eq!(before.relation(a, b, c), Some(ab_c));
            assert_eq!(before.relation(b, c, a), Some(bc_a));
            assert_eq!(before.relation(c, a, b), Some(ca_b));
        }
        assert_eq!(unsound(&mapper.map, |l| l as usize), 0);
        assert!(mapper
            .rng()
            .edges
            .iter()
            .all(|e| !once.contains(&e.a) && !once.contains(&e.b)));
    }
}
