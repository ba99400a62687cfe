//! The mapping half of `pipeline run`: station by station, range evidence and association
//! (000 §VI-C) turn detections into measurements, fused into the map (000 §VI-B); held-back
//! observations are retried after every station.

use super::record::{Association, DetectionRecord, MetricsRecord, RangeRecord, StationRecord};
use crate::association::{
    associate, reconsider, AssociationSettings, Decision, Evidence, Frame, Gallery, Placed,
};
use crate::calib::Calibration;
use crate::detection::{Detection, Separation};
use crate::ranging::{self, PrimaryEye, RangeInterval, Ranged, SensorModel};
use qrm_core::calculus::{Calculus, RelationSet};
use qrm_core::map::{Hypergraph, LandmarkId, Observation};
use qrm_core::measurement::{Bearing, Panorama, MAX_BEARING_UNCERTAINTY};
use qrm_core::neighborhood::estimate;
use qrm_core::simulation::observations;
use rayon::prelude::*;
use std::time::Instant;

/// One station's detections, ready for mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct StationDetections {
    pub name: String,
    pub files: Vec<String>,
    pub eye: PrimaryEye,
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

/// An observation whose association stayed ambiguous, kept to be fused later.
#[derive(Clone, Debug, PartialEq)]
struct HeldBack {
    station: usize,
    panorama: Panorama,
    /// Position in `panorama`, and index among the station's detections.
    detection: usize,
    primary_index: usize,
    candidates: Vec<LandmarkId>,
    /// The station's other detections that were fused, with their landmarks.
    decided: Vec<(usize, LandmarkId)>,
    evidence: Evidence,
}

/// The map being built and what association needs to remember.
pub struct Mapper<C: Calculus> {
    pub map: Hypergraph<C>,
    pub gallery: Gallery,
    calib: Calibration,
    sensor: SensorModel,
    association: AssociationSettings,
    held: Vec<HeldBack>,
    /// The most recent stations' fused landmarks, placed around each station.
    frames: Vec<Frame>,
    /// Held-back observations given up after [`HOLD_STATIONS`].
    pub expired: usize,
    next_landmark: LandmarkId,
    /// `(station, detection) → landmark` for every fused detection, for evaluation.
    pub sightings: Vec<(usize, usize, LandmarkId)>,
}

impl<C: Calculus> Mapper<C> {
    pub fn new(calib: Calibration, sensor: SensorModel, association: AssociationSettings) -> Self {
        Mapper {
            map: Hypergraph::new(),
            gallery: Gallery::default(),
            calib,
            sensor,
            association,
            held: Vec::new(),
            frames: Vec::new(),
            expired: 0,
            next_landmark: 0,
            sightings: Vec::new(),
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

    /// Maps one station; the record has everything but the decode/detect times.
    pub fn process(&mut self, index: usize, station: &StationDetections) -> StationRecord {
        let mut record = StationRecord {
            index,
            station: station.name.clone(),
            files: station.files.clone(),
            warnings: station.warnings.clone(),
            ..StationRecord::default()
        };
        let start = Instant::now();
        let mut ranged = ranging::observe(
            &station.primary,
            station.right.as_deref(),
            station.eye,
            &self.calib,
            &self.sensor,
        );
        record.seconds.range = start.elapsed().as_secs_f64();
        // Detections the detector doubts (possibly several rocks, or part of one), pieces
        // touching another piece, stacks, and those whose bearing is too uncertain to measure
        // with are not used.
        let width = self.calib.image.width;
        let narrowest = MIN_COLUMNS.max(width / 512);
        let usable: Vec<usize> = (0..ranged.len())
            .filter(|&i| {
                let d = &station.primary[i];
                !d.ambiguous
                    && d.bbox[2] + 1 >= d.bbox[0] + narrowest
                    && !stacked(d)
                    && !ranging::touches_neighbour(i, &station.primary, width)
                    && ranged[i].bearing.uncertainty < MAX_BEARING_UNCERTAINTY
            })
            .collect();
        record.detections = station
            .primary
            .iter()
            .zip(&ranged)
            .map(|(d, r)| detection_record(d, r))
            .collect();
        if usable.len() < 3 {
            record.warnings.push(format!(
                "{}: {} usable detections; a panorama needs at least 3 landmarks to measure",
                station.name,
                usable.len()
            ));
            record.fusion.resolved_held_back = self.retry_held_back(&mut record);
            record.metrics = self.metrics();
            return record;
        }

        let start = Instant::now();
        let panorama = panorama_of(&ranged, &usable);
        let evidence: Vec<Evidence> = usable
            .iter()
            .map(|&i| Evidence {
                appearance: station.primary[i].appearance.clone(),
                width: width_of(&station.primary[i], &ranged[i], &self.sensor),
            })
            .collect();
        let placed: Vec<Option<Placed>> = usable.iter().map(|&i| placed(&ranged[i])).collect();
        let decisions = associate(
            &self.map,
            &self.gallery,
            &panorama,
            &evidence,
            &placed,
            &self.frames,
            &self.association,
        );
        record.seconds.associate = start.elapsed().as_secs_f64();

        let start = Instant::now();
        // Landmark ids of the detections to fuse (positions in `usable`).
        let mut fused: Vec<(usize, LandmarkId)> = Vec::new();
        let mut fresh = self.next_landmark;
        let mut held = Vec::new();
        for (k, decision) in decisions.iter().enumerate() {
            match decision {
                Decision::Matched(l) => fused.push((k, *l)),
                Decision::New => {
                    fused.push((k, fresh));
                    fresh += 1;
                }
                Decision::HeldBack(candidates) => held.push((k, candidates.clone())),
            }
        }
        // The size cue, for landmarks whose width earlier stations bounded (not for parts of
        // a blob separated by parallax: see `width_of`).
        for &(k, l) in &fused {
            if station.primary[usable[k]].separation != Separation::Whole {
                continue;
            }
            if let Some(width) = self.gallery.profile(l).and_then(|p| p.width) {
                ranging::apply_size(&mut ranged[usable[k]], width, &self.sensor);
            }
        }
        for (i, r) in ranged.iter().enumerate() {
            record.detections[i].range = detection_record(&station.primary[i], r).range;
        }
        let panorama = panorama_of(&ranged, &usable);
        record.order = (0..usable.len())
            .flat_map(|a| (0..usable.len()).map(move |b| (a, b)))
            .filter(|&(a, b)| panorama.order.is_nearer(a, b))
            .map(|(a, b)| (usable[a], usable[b]))
            .collect();
        let fused_positions: Vec<usize> = fused.iter().map(|f| f.0).collect();
        let ids: Vec<LandmarkId> = fused.iter().map(|f| f.1).collect();
        // With fewer than three landmarks there is no triple to measure, but the sightings
        // still place and describe the landmarks for association at later stations.
        let sub = sub_panorama(&panorama, &fused_positions);
        let batch = if ids.len() >= 3 {
            observations(&self.map, &ids, &sub)
        } else {
            Vec::new()
        };
        record.fusion.landmarks = ids.len();
        record.fusion.triples = batch.len() / 3;
        match self.map.fuse(&batch) {
            Ok(report) => {
                record.fusion.relations_tightened = report.relations_tightened;
                self.next_landmark = fresh;
                for &(position, landmark) in &fused {
                    let i = usable[position];
                    // The size cue applied since does not enter the width evidence.
                    self.gallery.observe(
                        landmark,
                        evidence[position].appearance.clone(),
                        evidence[position].width,
                    );
                    self.sightings.push((index, i, landmark));
                    record.detections[i].association = match decisions[position] {
                        Decision::New => Association::New { landmark },
                        _ => Association::Matched { landmark },
                    };
                }
                let frame = Frame {
                    landmarks: fused
                        .iter()
                        .filter_map(|&(position, landmark)| Some((landmark, placed[position]?)))
                        .collect(),
                };
                // A station that fused too few landmarks to register against does not push an
                // older, useful one out: with no registrable frame left, every rock would come
                // back as a new landmark.
                if frame.registrable() {
                    self.frames.push(frame);
                    if self.frames.len() > RECENT_FRAMES {
                        self.frames.remove(0);
                    }
                }
                for (k, candidates) in held {
                    record.detections[usable[k]].association = Association::HeldBack {
                        candidates: candidates.clone(),
                    };
                    self.held.push(HeldBack {
                        station: index,
                        panorama: panorama.clone(),
                        detection: k,
                        primary_index: usable[k],
                        candidates,
                        decided: fused.clone(),
                        evidence: evidence[k].clone(),
                    });
                }
            }
            Err(contradiction) => {
                record.fusion.contradiction = Some(contradiction.to_string());
                record.warnings.push(format!(
                    "{}: the panorama contradicts the map and was not fused ({contradiction})",
                    station.name
                ));
            }
        }
        record.fusion.resolved_held_back = self.retry_held_back(&mut record);
        record.seconds.map = start.elapsed().as_secs_f64();
        record.metrics = self.metrics();
        record
    }

    /// Tries every held-back observation against the current map; returns how many were
    /// resolved (every candidate rejected: a new landmark) and fused.
    fn retry_held_back(&mut self, record: &mut StationRecord) -> usize {
        let current = record.index;
        let mut pending = std::mem::take(&mut self.held);
        let before = pending.len();
        // Observations that waited long enough, or have too few fused partners at their
        // station to be measured with, are given up.
        pending.retain(|item| current <= item.station + HOLD_STATIONS && item.decided.len() >= 2);
        self.expired += before - pending.len();
        let mut resolved = 0;
        let mut done = vec![false; pending.len()];
        for k in 0..pending.len() {
            let item = &pending[k];
            let standing = reconsider(
                &self.map,
                &item.panorama,
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
                // Every candidate rejected: a rock the map did not have.
                Some(_) => done[k] = true,
            }
            let landmark = self.next_landmark;
            let batch = focused_observations(&self.map, item, landmark);
            match self.map.fuse(&batch) {
                Ok(_) => {
                    self.next_landmark += 1;
                    self.gallery.observe(
                        landmark,
                        item.evidence.appearance.clone(),
                        item.evidence.width,
                    );
                    self.sightings
                        .push((item.station, item.primary_index, landmark));
                    resolved += 1;
                    // The station's other held observations now have this detection's
                    // landmark as a partner to measure with.
                    let (station, detection) = (item.station, item.detection);
                    for other in pending.iter_mut().filter(|o| o.station == station) {
                        if other.detection != detection {
                            other.decided.push((detection, landmark));
                        }
                    }
                }
                Err(contradiction) => record.warnings.push(format!(
                    "held-back observation of station {} dropped: {contradiction}",
                    item.station
                )),
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

    /// The map's state after a station.
    pub fn metrics(&self) -> MetricsRecord {
        let triples = self.map.triple_count();
        let states = 3 * triples * C::universe().len();
        let rng = estimate(&self.map);
        MetricsRecord {
            landmarks: self.map.len(),
            triples,
            open_fraction: ratio(self.map.open_states(), states),
            fully_constrained_fraction: ratio(self.map.fully_constrained_triples(), triples),
            rng_certain: rng.as_ref().map_or(0, |r| r.certain().count()),
            rng_uncertain: rng
                .as_ref()
                .map_or(0, |r| r.edges.len() - r.certain().count()),
            rng_cost: rng.as_ref().map_or(0.0, |r| r.total_cost()),
        }
    }
}

/// Narrowest usable detection, columns (at least a 512th of the panorama): slivers are mostly
/// pieces of larger rocks, whose centroids say little about where the rock is.
const MIN_COLUMNS: u32 = 3;

/// Tallest height-to-width ratio of a single rock's footprint: rocks are wider than they stand
/// tall (on the marsyard and random presets no visible footprint exceeds 1.44, 99 % stay under
/// 1.15). A taller blob is a farther rock seen over a nearer one, whose contact row (the
/// nearer rock's) and centroid (between the two) belong to neither.
const MAX_ASPECT: f64 = 1.5;

fn stacked(d: &Detection) -> bool {
    let width = f64::from(d.bbox[2] - d.bbox[0] + 1);
    let height = f64::from(d.bbox[3] - d.bbox[1] + 1);
    height > MAX_ASPECT * width
}

/// The physical width a detection implies for its rock (`ranging::width_evidence`), unless it
/// is a part of a blob separated by parallax: a false cut of one large rock (its sides read
/// farther than its middle) leaves a part narrower than the rock, which would bound the
/// landmark's width too low and put the size cue's ranges too far.
fn width_of(d: &Detection, ranged: &Ranged, model: &SensorModel) -> Option<RangeInterval> {
    (d.separation == Separation::Whole)
        .then(|| ranging::width_evidence(ranged, model))
        .flatten()
}

/// Recent stations registered against (a rover moves a few metres between stations: the most
/// recent ones share most landmarks with the current one).
const RECENT_FRAMES: usize = 6;

/// Stations a held-back observation waits for the map to tighten before it is given up (an
/// observation not fused loses information, never soundness). One: on the presets no
/// observation resolved at a second retry, and every retry measures again.
const HOLD_STATIONS: usize = 1;

/// A detection's rough position around the station, if its range is bounded well enough to
/// place it: the middle of its range interval along its bearing.
fn placed(r: &Ranged) -> Option<Placed> {
    let [low, high] = r.fused.as_array();
    let middle = 0.5 * (low + high);
    (high.is_finite() && high - low < middle).then(|| Placed {
        point: [
            middle * r.bearing.angle.cos(),
            middle * r.bearing.angle.sin(),
        ],
        radius: 0.5 * (high - low) + high * r.bearing.uncertainty,
    })
}

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

/// The panorama of the detections at `usable` (bearings and the range order among them).
fn panorama_of(ranged: &[Ranged], usable: &[usize]) -> Panorama {
    let chosen: Vec<Ranged> = usable.iter().map(|&i| ranged[i]).collect();
    let bearings: Vec<Bearing> = chosen.iter().map(|r| r.bearing).collect();
    Panorama::new(bearings, ranging::range_order(&chosen))
        .expect("bearings are finite, in range, with uncertainty below the limit")
}

/// The panorama restricted to `positions`.
fn sub_panorama(panorama: &Panorama, positions: &[usize]) -> Panorama {
    let bearings = positions.iter().map(|&p| panorama.bearings[p]).collect();
    let pairs: Vec<(usize, usize)> = (0..positions.len())
        .flat_map(|a| (0..positions.len()).map(move |b| (a, b)))
        .filter(|&(a, b)| a != b && panorama.order.is_nearer(positions[a], positions[b]))
        .collect();
    let order = qrm_core::measurement::RangeOrder::from_pairs(positions.len(), &pairs)
        .expect("a restriction of a strict order is one");
    Panorama::new(bearings, order).expect("a restriction of a valid panorama is valid")
}

/// The held-back detection's triples with the station's fused detections, as `landmark`.
fn focused_observations<C: Calculus>(
    map: &Hypergraph<C>,
    item: &HeldBack,
    landmark: LandmarkId,
) -> Vec<Observation> {
    let decided = &item.decided;
    let pairs: Vec<(usize, usize)> = (0..decided.len())
        .flat_map(|x| (x + 1..decided.len()).map(move |y| (x, y)))
        .collect();
    pairs
        .par_iter()
        .flat_map_iter(|&(x, y)| {
            let (p, q) = (decided[x], decided[y]);
            let ids = [landmark, p.1, q.1];
            let open = |a, b, c| map.relation(a, b, c).unwrap_or(C::universe());
            let states: [RelationSet; 3] = item.panorama.measure_triple::<C>(
                [item.detection, p.0, q.0],
                [
                    open(ids[0], ids[1], ids[2]),
                    open(ids[1], ids[2], ids[0]),
                    open(ids[2], ids[0], ids[1]),
                ],
            );
            [
                Observation::new(ids[0], ids[1], ids[2], states[0]),
                Observation::new(ids[1], ids[2], ids[0], states[1]),
                Observation::new(ids[2], ids[0], ids[1], states[2]),
            ]
        })
        .collect()
}

fn detection_record(d: &Detection, r: &Ranged) -> DetectionRecord {
    DetectionRecord {
        bbox: d.bbox,
        centroid: d.centroid,
        contact_row: d.contact_row,
        pixels: d.pixels,
        stereo_column: r.stereo_column,
        bearing: r.bearing.angle,
        bearing_uncertainty: r.bearing.uncertainty,
        range: RangeRecord {
            ground: r.ground.map(|g| g.as_array()),
            stereo: r.stereo.map(|s| s.as_array()),
            size: r.size.map(|s| s.as_array()),
            fused: r.fused.as_array(),
            conflict: r.conflict,
        },
        association: Association::Unused,
    }
}
