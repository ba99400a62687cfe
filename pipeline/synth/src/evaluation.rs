//! Scoring a `pipeline run` against the renderer's ground truth (`truth.json`): detection,
//! bearings, range cues and order, association, and the map against one built from exact
//! measurements of the same landmarks at the same stations. Pure: files in the CLI.

use crate::dataset::{ImageTruth, Truth};
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::geometry::Point;
use qrm_core::map::{Hypergraph, LandmarkId, Sighting};
use qrm_core::measurement::{Bearing, Panorama, RangeOrder};
use qrm_core::metrics::evaluate;
use qrm_core::neighborhood::{compare, estimate, RngComparison};
use qrm_vision::calib::Calibration;
use qrm_vision::run::{Association, LandmarkRecord, StationRecord};
use serde::Serialize;
use std::collections::HashMap;
use std::f64::consts::TAU;

/// Which truth rocks a detector is expected to find.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detectable {
    pub min_width_m: f64,
    pub max_range_m: f64,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Evaluation {
    pub detection: DetectionScore,
    /// Bearings of every detection matched to a rock, and of those the run used (it sets
    /// aside detections it doubts: possibly several rocks, slivers, pieces touching others).
    pub bearing: BearingScore,
    pub bearing_used: BearingScore,
    pub range: RangeScore,
    pub association: AssociationScore,
    pub map: MapScore,
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
    /// Sightings of the rock their landmark stands for (its majority rock).
    pub correct_sightings: usize,
    pub accuracy: f64,
    /// Rocks with more than one landmark, and landmarks whose sightings span several rocks.
    pub duplicated_rocks: usize,
    pub mixed_landmarks: usize,
    /// Sightings of things that are not truth rocks (false detections).
    pub unmatched_sightings: usize,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MapScore {
    pub run: MapMetricsScore,
    pub exact: MapMetricsScore,
    pub rng: Option<RngScore>,
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
    pub precision: f64,
    pub recall: f64,
    pub true_edges_pruned: usize,
}

/// The truth rock of each detection of `image` (unique: a rock claimed twice keeps the
/// nearer centroid), by the detection's centroid lying in the rock's bbox.
pub fn match_detections(
    record: &StationRecord,
    image: &ImageTruth,
    width: u32,
) -> Vec<Option<u32>> {
    let mut best: HashMap<u32, (usize, f64)> = HashMap::new();
    for (i, d) in record.detections.iter().enumerate() {
        let hit = image
            .rocks
            .iter()
            .filter(|r| in_columns(d.centroid[0], r.bbox, width))
            .filter(|r| {
                (f64::from(r.bbox[1]) - 0.5..=f64::from(r.bbox[3]) + 1.5).contains(&d.centroid[1])
            })
            .map(|r| {
                let dc = column_gap(d.centroid[0], r.centroid[0], width);
                (r.id, dc.hypot(d.centroid[1] - r.centroid[1]))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((id, distance)) = hit {
            let entry = best.entry(id).or_insert((i, distance));
            if distance < entry.1 {
                *entry = (i, distance);
            }
        }
    }
    let mut out = vec![None; record.detections.len()];
    for (id, (i, _)) in best {
        out[i] = Some(id);
    }
    out
}

fn column_gap(a: f64, b: f64, width: u32) -> f64 {
    let w = f64::from(width);
    let d = (a - b).rem_euclid(w);
    d.min(w - d)
}

/// Whether `column` lies in the (possibly seam-wrapping) column span of `bbox`.
fn in_columns(column: f64, bbox: [u32; 4], width: u32) -> bool {
    let w = f64::from(width);
    let start = f64::from(bbox[0]);
    let span = (f64::from(bbox[2]) - start).rem_euclid(w) + 1.0;
    (column - start + 1.0).rem_euclid(w) <= span + 1.0
}

fn angle_error(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
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

/// Everything `score_run` needs, read by the caller.
pub struct RunFiles<'a> {
    pub records: &'a [StationRecord],
    pub landmarks: &'a [LandmarkRecord],
    pub map: &'a Hypergraph<Edc>,
}

/// Scores a run. `detectable` says which rocks count for recall.
pub fn score_run(
    run: &RunFiles,
    truth: &Truth,
    calib: &Calibration,
    detectable: Detectable,
) -> Evaluation {
    let width = calib.image.width;
    let rock = |id: u32| {
        let p = truth.rocks[id as usize].position;
        Point::new(p[0], p[1])
    };
    let mut eval = Evaluation::default();
    // Truth rock of every (station index, detection index).
    let mut matched: HashMap<(usize, usize), u32> = HashMap::new();
    let mut bearing_errors = Vec::new();
    let mut used_errors: Vec<(f64, f64)> = Vec::new();
    let mut cue_checks: [Vec<(bool, f64)>; 4] = Default::default();
    let mut worst_ratio: f64 = 0.0;
    let mut within = 0;
    for record in eval_records(run.records, truth) {
        let (record, image) = record;
        let station = &truth.stations[image.station];
        let centre = Point::new(station.position[0], station.position[1]);
        let matches = match_detections(record, image, width);
        eval.detection.images += 1;
        eval.detection.detections += record.detections.len();
        eval.detection.true_detections += matches.iter().flatten().count();
        for r in &image.rocks {
            let columns =
                (f64::from(r.bbox[2]) - f64::from(r.bbox[0])).rem_euclid(f64::from(width)) + 1.0;
            let physical = columns * calib.column_width() * r.range;
            if r.range <= detectable.max_range_m && physical >= detectable.min_width_m {
                eval.detection.detectable += 1;
                if matches.contains(&Some(r.id)) {
                    eval.detection.detectable_found += 1;
                }
            }
        }
        let truth_of = |id: u32| {
            let p = rock(id);
            let (dx, dy) = (p.x - centre.x, p.y - centre.y);
            let bearing = (dy.atan2(dx) - station.heading).rem_euclid(TAU);
            (bearing, dx.hypot(dy))
        };
        for (i, (d, m)) in record.detections.iter().zip(&matches).enumerate() {
            let Some(id) = *m else { continue };
            matched.insert((record.index, i), id);
            let (bearing, range) = truth_of(id);
            let error = angle_error(d.bearing, bearing);
            bearing_errors.push(error);
            if d.association != Association::Unused {
                used_errors.push((error, d.bearing_uncertainty));
            }
            if error <= d.bearing_uncertainty {
                within += 1;
            }
            if d.bearing_uncertainty > 0.0 {
                worst_ratio = worst_ratio.max(error / d.bearing_uncertainty);
            }
            let cues = [
                d.range.ground,
                d.range.stereo,
                d.range.size,
                Some(d.range.fused),
            ];
            for (k, cue) in cues.iter().enumerate() {
                if let Some([low, high]) = cue {
                    let width = if high.is_finite() {
                        (high - low) / range
                    } else {
                        f64::INFINITY
                    };
                    cue_checks[k].push(((*low..=*high).contains(&range), width));
                }
            }
            if d.range.conflict {
                eval.range.conflicts += 1;
            }
        }
        // Order: every pair of matched detections.
        let ranges: Vec<Option<f64>> = matches.iter().map(|m| m.map(|id| truth_of(id).1)).collect();
        for i in 0..ranges.len() {
            for j in i + 1..ranges.len() {
                if let (Some(_), Some(_)) = (ranges[i], ranges[j]) {
                    eval.range.pairs += 1;
                }
            }
        }
        for &(i, j) in &record.order {
            let (a, b) = (&record.detections[i].range, &record.detections[j].range);
            let apart = |x: Option<[f64; 2]>, y: Option<[f64; 2]>| matches!((x, y), (Some(x), Some(y)) if x[1] < y[0]);
            let by = [
                apart(a.ground, b.ground),
                apart(a.stereo, b.stereo),
                apart(a.size, b.size),
            ];
            eval.range.asserted_all += 1;
            eval.range.separated_by_ground += usize::from(by[0]);
            eval.range.separated_by_stereo += usize::from(by[1]);
            eval.range.separated_by_size += usize::from(by[2]);
            eval.range.separated_only_fused += usize::from(!by.iter().any(|&x| x));
            if let (Some(Some(ri)), Some(Some(rj))) = (ranges.get(i), ranges.get(j)) {
                eval.range.asserted_pairs += 1;
                if ri > rj {
                    eval.range.wrong_pairs += 1;
                }
            }
        }
    }
    let d = &mut eval.detection;
    d.precision = ratio(d.true_detections, d.detections);
    d.recall = ratio(d.detectable_found, d.detectable);
    eval.bearing = BearingScore {
        count: bearing_errors.len(),
        median_error_deg: median(bearing_errors.clone()).to_degrees(),
        worst_error_deg: bearing_errors
            .iter()
            .copied()
            .fold(0.0, f64::max)
            .to_degrees(),
        within_interval: ratio(within, bearing_errors.len()),
        worst_error_ratio: worst_ratio,
    };
    eval.bearing_used = BearingScore {
        count: used_errors.len(),
        median_error_deg: median(used_errors.iter().map(|e| e.0).collect()).to_degrees(),
        worst_error_deg: used_errors
            .iter()
            .map(|e| e.0)
            .fold(0.0, f64::max)
            .to_degrees(),
        within_interval: ratio(
            used_errors.iter().filter(|e| e.0 <= e.1).count(),
            used_errors.len(),
        ),
        worst_error_ratio: used_errors
            .iter()
            .filter(|e| e.1 > 0.0)
            .map(|e| e.0 / e.1)
            .fold(0.0, f64::max),
    };
    let cue = |checks: &Vec<(bool, f64)>| CueScore {
        count: checks.len(),
        holds_truth: ratio(checks.iter().filter(|c| c.0).count(), checks.len()),
        median_relative_width: median(
            checks
                .iter()
                .map(|c| c.1)
                .filter(|w| w.is_finite())
                .collect(),
        ),
    };
    eval.range.ground = cue(&cue_checks[0]);
    eval.range.stereo = cue(&cue_checks[1]);
    eval.range.size = cue(&cue_checks[2]);
    eval.range.fused = cue(&cue_checks[3]);

    // Association: each landmark stands for the rock most of its sightings show.
    let mut rock_of: HashMap<LandmarkId, u32> = HashMap::new();
    let mut landmarks_of_rock: HashMap<u32, usize> = HashMap::new();
    let a = &mut eval.association;
    a.landmarks = run.landmarks.len();
    for landmark in run.landmarks {
        let mut votes: HashMap<u32, usize> = HashMap::new();
        for s in &landmark.sightings {
            a.sightings += 1;
            match matched.get(s) {
                Some(&id) => *votes.entry(id).or_default() += 1,
                None => a.unmatched_sightings += 1,
            }
        }
        if votes.len() > 1 {
            a.mixed_landmarks += 1;
        }
        if let Some((&id, &count)) = votes
            .iter()
            .max_by_key(|(id, c)| (**c, std::cmp::Reverse(**id)))
        {
            a.correct_sightings += count;
            rock_of.insert(landmark.landmark, id);
            *landmarks_of_rock.entry(id).or_default() += 1;
        }
    }
    a.duplicated_rocks = landmarks_of_rock.values().filter(|&&n| n > 1).count();
    a.accuracy = ratio(a.correct_sightings, a.sightings);

    // Landmarks that stand for a rock no other landmark stands for: the ones with a truth.
    let defined = |l: LandmarkId| {
        rock_of
            .get(&l)
            .filter(|r| landmarks_of_rock.get(r) == Some(&1))
            .copied()
    };
    let position = |l: LandmarkId| defined(l).map(rock);
    let truth_fn = |a: LandmarkId, b: LandmarkId, c: LandmarkId| {
        Edc::classify(position(a)?, position(b)?, position(c)?)
    };
    // Soundness of the run's map is checked on every landmark with a majority rock: a duplicate
    // shares its rock's position (triples of two such landmarks are degenerate, so undefined),
    // and a mixed landmark is held to its majority rock.
    let majority_truth = |a: LandmarkId, b: LandmarkId, c: LandmarkId| {
        let at = |l: LandmarkId| rock_of.get(&l).copied().map(rock);
        Edc::classify(at(a)?, at(b)?, at(c)?)
    };
    eval.map.run = map_score(run.map, &majority_truth, &|l| defined(l).is_some());
    let exact = exact_map(run, truth, &defined);
    eval.map.exact = map_score(&exact, &truth_fn, &|l| defined(l).is_some());
    eval.map.rng = estimate(run.map).and_then(|rng| {
        let ids = run.map.landmarks();
        if ids.iter().any(|&l| position(l).is_none()) {
            return None;
        }
        let comparison: RngComparison = compare(run.map, &rng, |l| position(l).expect("checked"));
        Some(RngScore {
            precision: comparison.precision(),
            recall: comparison.recall(),
            true_edges_pruned: comparison.pruned_true,
        })
    });
    eval
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

/// The map from exact measurements of the same landmarks at the same stations: true bearings
/// from the station centre and the true total range order.
fn exact_map(
    run: &RunFiles,
    truth: &Truth,
    defined: &dyn Fn(LandmarkId) -> Option<u32>,
) -> Hypergraph<Edc> {
    let mut map = Hypergraph::<Edc>::new();
    for (record, image) in eval_records(run.records, truth) {
        let station = &truth.stations[image.station];
        let mut ids: Vec<LandmarkId> = run
            .landmarks
            .iter()
            .filter(|l| l.sightings.iter().any(|s| s.0 == record.index))
            .map(|l| l.landmark)
            .filter(|&l| defined(l).is_some())
            .collect();
        ids.sort_unstable();
        if ids.len() < 3 {
            continue;
        }
        let polar: Vec<(f64, f64)> = ids
            .iter()
            .map(|&l| {
                let p = truth.rocks[defined(l).expect("filtered") as usize].position;
                let (dx, dy) = (p[0] - station.position[0], p[1] - station.position[1]);
                (
                    (dy.atan2(dx) - station.heading).rem_euclid(TAU),
                    dx.hypot(dy),
                )
            })
            .collect();
        let mut nearest_first: Vec<usize> = (0..ids.len()).collect();
        nearest_first.sort_by(|&a, &b| polar[a].1.total_cmp(&polar[b].1));
        let order = RangeOrder::total(&nearest_first).expect("a permutation");
        let Ok(panorama) =
            Panorama::new(polar.iter().map(|p| Bearing::exact(p.0)).collect(), order)
        else {
            continue;
        };
        let batch = map.observations(&panorama, &Sighting::all(&ids));
        let _ = map.fuse(&batch);
    }
    map
}

fn map_score<C: Calculus>(
    map: &Hypergraph<C>,
    truth: &impl Fn(LandmarkId, LandmarkId, LandmarkId) -> Option<u8>,
    defined: &dyn Fn(LandmarkId) -> bool,
) -> MapMetricsScore {
    let m = evaluate(map, truth, map.len());
    let mut unsound: HashMap<LandmarkId, usize> = HashMap::new();
    let (mut open, mut states) = (0usize, 0usize);
    for (a, b, c, relations) in map.triples() {
        if defined(a) && defined(b) && defined(c) {
            open += relations.iter().map(|s| s.len()).sum::<usize>();
            states += 3 * C::universe().len();
        }
        for (set, (x, y, z)) in relations.iter().zip([(a, b, c), (b, c, a), (c, a, b)]) {
            if truth(x, y, z).is_some_and(|t| !set.contains(t)) {
                for l in [x, y, z] {
                    *unsound.entry(l).or_default() += 1;
                }
            }
        }
    }
    let mut unsound_landmarks: Vec<(LandmarkId, usize)> = unsound.into_iter().collect();
    unsound_landmarks.sort_by_key(|&(l, n)| (std::cmp::Reverse(n), l));
    MapMetricsScore {
        unsound_landmarks,
        landmarks: map.len(),
        triples: map.triple_count(),
        open_pct: m.open_pct,
        open_pct_defined: 100.0 * ratio(open, states),
        removed_incorrect_pct: m.removed_incorrect_pct,
        fully_constrained_pct: m.fully_constrained_pct,
        unsound_relations: m.unsound_relations,
        undefined_triples: m.undefined_triples,
    }
}

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}
