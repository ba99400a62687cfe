//! Scoring a `pipeline run` against the renderer's ground truth (`truth.json`): detection,
//! bearings, range cues and order ([`front_end`]), association ([`association`]), and the map
//! against one built from exact measurements of the same landmarks at the same stations
//! ([`map`]), and 002's beliefs if the run made them. Pure: files are read and written by the
//! CLI.

mod association;
pub mod detection;
mod front_end;
mod map;

pub use detection::{match_detections, median_and_max, Detectable, DetectedBox, Score};

use crate::dataset::{ImageTruth, Truth};
use qrm_core::edc::Edc;
use qrm_core::map::{Hypergraph, LandmarkId};
use qrm_core::probabilistic::map::{compare, BeliefComparison, BeliefMap};
use qrm_vision::calib::Calibration;
use qrm_vision::run::{LandmarkRecord, StationRecord};
use serde::Serialize;
use std::collections::{BTreeMap, HashSet};

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Evaluation {
    #[serde(flatten)]
    pub front_end: FrontEndScore,
    pub association: AssociationScore,
    /// The rock each landmark stands for: the one most of its sightings show (landmarks made
    /// only of false detections have none).
    pub landmark_rocks: BTreeMap<LandmarkId, u32>,
    pub map: MapScore,
    /// `--mode probabilistic`: 002's beliefs and the map's sets against the truth, over the
    /// triples with a belief, each landmark held to its majority rock.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beliefs: Option<BeliefComparison>,
}

/// The front end's figures: detection, bearings and range cues and order, image by image.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FrontEndScore {
    pub detection: DetectionScore,
    /// Bearings of every detection matched to a rock, and of those the run used (it sets
    /// aside detections it doubts: possibly several rocks, slivers, pieces touching others).
    pub bearing: BearingScore,
    pub bearing_used: BearingScore,
    /// Bearings of the sightings that reached the map, which its soundness rests on (`used`
    /// also counts detections held back and given up), and of those that are pieces of their
    /// rock, holding under 30 % of its visible pixels.
    pub bearing_fused: BearingScore,
    pub bearing_pieces: BearingScore,
    pub range: RangeScore,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DetectionScore {
    pub images: usize,
    pub detections: usize,
    /// Detections that are the unique match of a truth rock.
    pub true_detections: usize,
    pub detectable: usize,
    pub detectable_found: usize,
    pub precision: f64,
    pub recall: f64,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BearingScore {
    pub count: usize,
    pub median_error_deg: f64,
    pub worst_error_deg: f64,
    /// Fraction of bearings whose interval holds the true bearing (must be 1 for soundness).
    pub within_interval: f64,
    /// Largest error / interval half-width (≤ 1 when sound).
    pub worst_error_ratio: f64,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CueScore {
    pub count: usize,
    /// Fraction of intervals holding the true range.
    pub holds_truth: f64,
    /// Median width of the finite intervals relative to the true range.
    pub median_relative_width: f64,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RangeScore {
    pub ground: CueScore,
    pub stereo: CueScore,
    pub size: CueScore,
    pub fused: CueScore,
    pub conflicts: usize,
    /// Pairs of matched detections in the same panorama, pairs the order asserts, and
    /// asserted pairs that are wrong (target 0).
    pub pairs: usize,
    pub asserted_pairs: usize,
    pub wrong_pairs: usize,
    /// Of those, the asserted pairs between two sightings that reached the map, and the wrong
    /// ones among them: the pairs the map's soundness rests on.
    pub fused_asserted_pairs: usize,
    pub fused_wrong_pairs: usize,
    /// Each wrong one as `(station, detection asserted nearer, detection asserted farther)`
    /// (indices into `stations.json`): where to look.
    pub fused_wrong: Vec<(usize, usize, usize)>,
    /// All asserted pairs (matched to truth or not), those each cue separates on its own, and
    /// those only the fused intervals separate.
    pub asserted_all: usize,
    pub separated_by_ground: usize,
    pub separated_by_stereo: usize,
    pub separated_by_size: usize,
    pub separated_only_fused: usize,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct AssociationScore {
    pub landmarks: usize,
    pub sightings: usize,
    /// Sightings of the rock their landmark stands for (the rock most of them show), a blob
    /// over several touching rocks showing each rock its measurement holds
    /// (`detection::also_shown`).
    pub correct_sightings: usize,
    pub accuracy: f64,
    /// Correct sightings over the sightings that show a rock: the landmarks' purity (issues 13
    /// and 14), which false detections do not lower.
    pub purity: f64,
    /// Of the correct sightings, those of a blob credited with another of the rocks it shows
    /// (its nearest centroid), counted for their landmark's rock.
    pub credited_by_measurement: usize,
    /// The purity when each sighting shows only the rock it is credited with (before stop 79).
    pub purity_nearest_centroid: f64,
    /// Rocks with more than one landmark, and landmarks whose sightings span several rocks.
    pub duplicated_rocks: usize,
    pub mixed_landmarks: usize,
    /// Sightings of things that are not truth rocks (false detections).
    pub unmatched_sightings: usize,
    /// Correct sightings over the detections matched to a rock: the share of correct
    /// detections that reached the map (issue 13's "fused").
    pub fused_fraction: f64,
    /// Rocks detected at three or more stations, and how many of them some landmark stands
    /// for: what a map of the drive could hold (issues 13 and 14's "mapped").
    pub rocks_seen_thrice: usize,
    pub rocks_seen_thrice_mapped: usize,
    pub mapped_fraction: f64,
    /// Every mixed landmark with the stations that saw each of its rocks: where association
    /// went wrong.
    pub mixed: Vec<MixedLandmark>,
}

/// A landmark whose sightings show more than one rock.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MixedLandmark {
    pub landmark: LandmarkId,
    /// Each rock it was fused from, with the stations (indices into `stations.json`) whose
    /// sightings show it: the rock the landmark stands for first, then by sightings.
    pub rocks: Vec<(u32, Vec<usize>)>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MapScore {
    pub run: MapMetricsScore,
    pub exact: MapMetricsScore,
    /// The map of the run's sightings measured with true bearings and the run's own range
    /// evidence (its "nearer than" pairs and range-ratio bounds): the run's map differs from
    /// it only by the bearings' intervals.
    pub true_bearings: MapMetricsScore,
    /// The RNG estimate (000 §VII-A) of the run's map, of the exact map and of the
    /// true-bearings map, each restricted to the landmarks that stand for one rock each,
    /// against the true RNG of those rocks. `None` with fewer than three such landmarks.
    pub rng: Option<RngScore>,
    pub rng_exact: Option<RngScore>,
    pub rng_true_bearings: Option<RngScore>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MapMetricsScore {
    pub landmarks: usize,
    pub triples: usize,
    pub open_pct: f64,
    /// Open states over the triples of landmarks that stand for one rock each (those the exact
    /// map is built from): the like-for-like comparison, since landmarks of duplicated rocks,
    /// mixed landmarks and false detections are seen at few stations and stay loose.
    pub open_pct_defined: f64,
    pub removed_incorrect_pct: f64,
    /// Incorrect states removed over the triples of landmarks that stand for one rock each,
    /// measured or not: the like-for-like comparison with the exact map. The figure over all
    /// landmarks counts the triples of false detections' landmarks, which have no true state,
    /// as unresolved (marsyard seed 17: 35 landmarks, 30 of one rock each).
    pub removed_incorrect_pct_defined: f64,
    pub fully_constrained_pct: f64,
    /// Relations whose true state was removed (target 0).
    pub unsound_relations: usize,
    /// Landmarks in unsound relations, with how many each is in, most first: where to look
    /// for a wrong association or a bad measurement.
    pub unsound_landmarks: Vec<(LandmarkId, usize)>,
    pub undefined_triples: usize,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RngScore {
    /// Landmarks compared: those that stand for one rock each (the map restricted to them).
    pub landmarks: usize,
    pub precision: f64,
    pub recall: f64,
    pub true_edges_pruned: usize,
    /// The same for only the edges of cost `w ≤ max_cost` (Algorithm 2's `w`), at each of
    /// [`COST_CUTS`]: what rng.png shows by default, and how much a cut loses.
    pub by_cost: Vec<CostCut>,
}

/// The cost cuts at which [`RngScore::by_cost`] is reported.
pub const COST_CUTS: [f64; 6] = [0.05, 0.1, 0.15, 0.2, 0.25, 0.3];

/// Precision and recall of the RNG edges of cost at most `max_cost`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CostCut {
    pub max_cost: f64,
    pub edges: usize,
    pub precision: f64,
    pub recall: f64,
}

/// Checks that `truth`, `records` and `landmarks` (read from files) refer to each other
/// consistently, so that scoring can index them: every image's station and rock exist, every
/// order pair and sighting names an existing detection.
pub fn check_files(
    truth: &Truth,
    records: &[StationRecord],
    landmarks: &[LandmarkRecord],
) -> Result<(), String> {
    for image in &truth.images {
        if image.station >= truth.stations.len() {
            return Err(format!(
                "image {} names station {} of {}",
                image.file,
                image.station,
                truth.stations.len()
            ));
        }
        if let Some(rock) = image
            .rocks
            .iter()
            .find(|r| r.id as usize >= truth.rocks.len())
        {
            return Err(format!(
                "image {} shows rock {} of {}",
                image.file,
                rock.id,
                truth.rocks.len()
            ));
        }
    }
    for record in records {
        for (k, file) in record.files.iter().enumerate() {
            let digest = record.digests.get(k).map(String::as_str);
            describes(truth, file, digest)
                .map_err(|problem| format!("station {}: {problem}", record.station))?;
        }
        let n = record.detections.len();
        if let Some(&(i, j)) = record.order.iter().find(|&&(i, j)| i >= n || j >= n) {
            return Err(format!(
                "station {} orders detections ({i}, {j}) of {n}",
                record.station
            ));
        }
    }
    for landmark in landmarks {
        for &(station, detection) in &landmark.sightings {
            let exists = records
                .iter()
                .find(|r| r.index == station)
                .is_some_and(|r| detection < r.detections.len());
            if !exists {
                return Err(format!(
                    "landmark {} was sighted at station {station}, detection {detection}, which the run does not have",
                    landmark.landmark
                ));
            }
        }
    }
    Ok(())
}

/// Whether `truth` describes the image `file` (relative to the image directory) with
/// fingerprint `digest` (`qrm_vision::survey::digest`; empty or `None` when unknown): it must
/// list the file, and when both fingerprints are known they must agree. Synthetic datasets
/// share their file names, and many their image size, so names alone would let another
/// dataset's truth score a run as if it were this one's (at precision 0, exit 0).
pub fn describes(truth: &Truth, file: &str, digest: Option<&str>) -> Result<(), String> {
    let Some(image) = truth.images.iter().find(|i| i.file == file) else {
        return Err(format!("the truth file does not describe {file}"));
    };
    match (image.digest.as_deref(), digest.filter(|d| !d.is_empty())) {
        (Some(theirs), Some(ours)) if theirs != ours => Err(format!(
            "{file} is not the image the truth file describes (fingerprint {ours}, the truth's {theirs})"
        )),
        _ => Ok(()),
    }
}

/// Everything `score_run` needs, read by the caller.
pub struct RunFiles<'a> {
    pub records: &'a [StationRecord],
    pub landmarks: &'a [LandmarkRecord],
    pub map: &'a Hypergraph<Edc>,
    /// The run's beliefs.json, if it wrote one.
    pub beliefs: Option<&'a BeliefMap>,
}

/// Scores a run. `detectable` says which rocks count for recall.
pub fn score_run(
    run: &RunFiles,
    truth: &Truth,
    calib: &Calibration,
    detectable: Detectable,
) -> Evaluation {
    let fused: HashSet<(usize, usize)> = run
        .landmarks
        .iter()
        .flat_map(|l| l.sightings.iter().copied())
        .collect();
    let mut tally = front_end::Tally::default();
    for (record, image) in eval_records(run.records, truth) {
        tally.add_image(record, image, truth, calib, detectable, &fused);
    }
    let (association, rocks) = association::score(run.landmarks, &tally.matched, &tally.also_shows);
    Evaluation {
        front_end: tally.scores(),
        association,
        landmark_rocks: rocks.all(),
        map: map::score(run, truth, &rocks),
        beliefs: run.beliefs.map(|beliefs| {
            compare(beliefs, run.map, &|ids| {
                map::majority_relation(truth, &rocks, ids)
            })
        }),
    }
}

/// The run's records paired with the truth of their primary image.
fn eval_records<'a>(
    records: &'a [StationRecord],
    truth: &'a Truth,
) -> Vec<(&'a StationRecord, &'a ImageTruth)> {
    records
        .iter()
        .filter_map(|r| {
            let file = r.files.first()?;
            let image = truth.images.iter().find(|i| &i.file == file)?;
            Some((r, image))
        })
        .collect()
}
