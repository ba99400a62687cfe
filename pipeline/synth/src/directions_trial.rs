//! Route directions followed through rendered panoramas (issue 17; 004 §6.1): does a route's
//! predicted reliability come true when the rover picks each target from its own panorama?
//!
//! A route is planned on the map of an earlier run ([`qrm_core::directions`]). For each leg the
//! rover stands near the leg's starting rock — uniform over the ring from its footprint plus
//! [`CLEARANCE_M`] out to half the distance to the nearest other rock, so that the starting rock
//! is the nearest — with a random heading. Its stereo panorama is rendered there, the vision
//! front end detects the rocks and ranges them, and each detection is placed at its bearing and
//! the geometric mean of its range interval (where that is unbounded, the flat-ground range of
//! its contact row; detections with neither are left out). The rock the rover stands at is seldom detected (too near the
//! camera), so the rover takes itself for it, as in the ideal-sensor model of leg reliability,
//! and leaves that rock out if it is seen (the detection identified as its landmark, or else
//! one under half the range of the next); it and its `n − 1` nearest detections form the
//! scene, and the rover heads for the most isolated.
//! Two rovers are scored from the same panorama:
//! - **literal**: the scene is made of every detection, as a person reading the instruction
//!   would take every rock in view;
//! - **identified**: only detections the rover associates with landmarks of the map
//!   (`KnownMap::locate`) count, since the map's scenes are made of its landmarks and a field
//!   holds rocks the run never mapped.
//!
//! A leg succeeds when the rock the chosen detection shows (the renderer's rock under most of
//! its pixels) is the target landmark's rock. A route succeeds when all its legs do. The drive
//! between legs is not simulated: the next leg starts near its own rock, as 004's model of leg
//! reliability assumes (`navigate drive` measures driving).

use crate::closed_loop::{Terrain, CLEARANCE_M};
use crate::render::{render, Eye, Pose, Render};
use image::RgbImage;
use qrm_core::directions::reliability::most_isolated_seen;
use qrm_core::directions::{Leg, LegGraph};
use qrm_core::edc::Edc;
use qrm_core::geometry::Point;
use qrm_core::map::LandmarkId;
use qrm_vision::localization::KnownMap;
use qrm_vision::ranging::{self, PrimaryEye};
use qrm_vision::run::front_end::detect_panoramas;
use qrm_vision::run::RunSettings;
use rand::Rng;
use serde::Serialize;
use std::collections::BTreeMap;

/// One leg followed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LegTrial {
    pub from: LandmarkId,
    pub to: LandmarkId,
    /// Objects in the leg's scene (counting `from`).
    pub objects: usize,
    /// The leg's predicted reliability, `R(n, σ) · support`.
    pub predicted: f64,
    /// Whether the leg holds among the true positions of the map's landmarks' rocks: the
    /// target is the most isolated of the starting rock and its `n − 1` nearest landmark rocks.
    pub holds: bool,
    /// The rock the literal rover headed for (none: no usable detection, or the scene was too
    /// small), and the identified one.
    pub selected_rock: Option<u32>,
    pub selected_rock_identified: Option<u32>,
    pub intended_rock: u32,
    pub correct: bool,
    pub correct_identified: bool,
    /// Where the rover stood (world metres), if a clear point was found.
    pub rover: Option<[f64; 2]>,
    /// Whether the target's rock was among the detections with a bounded range, and among the
    /// identified ones.
    pub target_seen: bool,
    pub target_identified: bool,
    /// `ln(estimated / true range)` of the panorama's detections of known rocks.
    pub range_log_errors: Vec<f64>,
}

/// One route followed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RouteTrial {
    pub landmarks: Vec<LandmarkId>,
    /// `e^−U` of the planned route.
    pub predicted: f64,
    pub legs: Vec<LegTrial>,
    pub succeeded: bool,
    pub succeeded_identified: bool,
}

/// Attempts to find a clear standing point near a rock.
const STAND_ATTEMPTS: usize = 50;

/// Follows the planned route `legs` of `graph` (landmark positions in `ids`), each leg from a
/// fresh standing point near its starting rock. `None` when a leg's landmarks stand for no
/// rock (the map's landmark has no rock in `terrain.landmark_rocks`).
pub fn follow_route(
    terrain: &Terrain,
    known: &KnownMap<Edc>,
    settings: &RunSettings,
    graph: &LegGraph,
    path: &qrm_core::directions::Path,
    ids: &[LandmarkId],
    rng: &mut impl Rng,
) -> Option<RouteTrial> {
    let mut legs = Vec::new();
    for (k, leg) in graph.legs_of(path).into_iter().enumerate() {
        let (from, to) = (ids[leg.from], ids[leg.to]);
        let from_rock = *terrain.landmark_rocks.get(&from)?;
        let intended_rock = *terrain.landmark_rocks.get(&to)?;
        let choice = select_from_panorama(
            terrain,
            known,
            settings,
            (from, from_rock),
            leg.objects(),
            rng,
        );
        legs.push(LegTrial {
            from,
            to,
            objects: leg.objects(),
            predicted: (-graph.arcs[path.arcs[k]].u).exp(),
            holds: holds(terrain, leg, ids),
            selected_rock: choice.literal,
            selected_rock_identified: choice.identified,
            intended_rock,
            correct: choice.literal == Some(intended_rock),
            correct_identified: choice.identified == Some(intended_rock),
            rover: choice.rover,
            target_seen: choice.seen.contains(&intended_rock),
            target_identified: choice.identified_rocks.contains(&intended_rock),
            range_log_errors: choice.range_log_errors,
        });
    }
    Some(RouteTrial {
        landmarks: path.nodes.iter().map(|&n| ids[n]).collect(),
        predicted: path.reliability(),
        succeeded: legs.iter().all(|l| l.correct),
        succeeded_identified: legs.iter().all(|l| l.correct_identified),
        legs,
    })
}

/// Whether `leg` holds among the true positions of the landmarks' rocks.
fn holds(terrain: &Terrain, leg: &Leg, ids: &[LandmarkId]) -> bool {
    let located: Vec<(usize, Point)> = ids
        .iter()
        .enumerate()
        .filter_map(|(i, l)| {
            let rock = *terrain.landmark_rocks.get(l)?;
            Some((i, terrain.world.rocks[rock as usize].position))
        })
        .collect();
    let points: Vec<Point> = located.iter().map(|&(_, p)| p).collect();
    let position = |index: usize| located.iter().position(|&(i, _)| i == index);
    let (Some(from), Some(to)) = (position(leg.from), position(leg.to)) else {
        return false;
    };
    most_isolated_seen(&points, from, leg.objects()) == Some(to)
}

/// What the two rovers picked from one panorama.
struct Choice {
    literal: Option<u32>,
    identified: Option<u32>,
    /// Rocks of the detections with a bounded range, and of the identified ones among them.
    seen: Vec<u32>,
    identified_rocks: Vec<u32>,
    rover: Option<[f64; 2]>,
    range_log_errors: Vec<f64>,
}

/// Stands near rock `from_rock`, renders, detects, ranges, and picks the most isolated of the
/// nearest detection and its `objects − 1` nearest, among all detections and among those
/// identified as landmarks (rocks by the renderer's rock ids); and the range errors seen.
fn select_from_panorama(
    terrain: &Terrain,
    known: &KnownMap<Edc>,
    settings: &RunSettings,
    (from, from_rock): (LandmarkId, u32),
    objects: usize,
    rng: &mut impl Rng,
) -> Choice {
    let world = terrain.world;
    let centre = world.rocks[from_rock as usize].position;
    let inner = world.contact_radius(from_rock) + CLEARANCE_M;
    let nearest = world
        .rocks
        .iter()
        .filter(|r| r.id != from_rock)
        .map(|r| r.position.distance(centre))
        .fold(f64::INFINITY, f64::min);
    let outer = (0.5 * nearest).max(inner);
    let pose = (0..STAND_ATTEMPTS).find_map(|_| {
        let radius = (inner * inner + rng.random::<f64>() * (outer * outer - inner * inner)).sqrt();
        let angle = rng.random_range(0.0..std::f64::consts::TAU);
        let p = Point::new(
            centre.x + radius * angle.cos(),
            centre.y + radius * angle.sin(),
        );
        (!terrain.blocked(p, CLEARANCE_M)).then(|| Pose {
            position: p,
            heading: rng.random_range(0.0..std::f64::consts::TAU),
        })
    });
    let Some(pose) = pose else {
        return Choice {
            literal: None,
            identified: None,
            seen: Vec::new(),
            identified_rocks: Vec::new(),
            rover: None,
            range_log_errors: Vec::new(),
        };
    };
    let Render {
        width,
        height,
        rgb,
        rock_id: rock_ids,
    } = render(world, terrain.calib, pose, Eye::Left);
    let left = RgbImage::from_raw(width, height, rgb).expect("a render fills it");
    let right = {
        let r = render(world, terrain.calib, pose, Eye::Right);
        RgbImage::from_raw(r.width, r.height, r.rgb).expect("a render fills it")
    };
    let detections = detect_panoramas(
        "leg",
        &left,
        Some(&right),
        PrimaryEye::Left,
        false,
        terrain.calib,
        &settings.detector,
    );
    let ranged = ranging::observe(
        &detections.primary,
        detections.right.as_deref(),
        PrimaryEye::Left,
        detections.channels,
        terrain.calib,
        &settings.sensor,
    );
    let location = known.locate(
        &detections,
        terrain.calib,
        &settings.sensor,
        &settings.association,
    );
    let identified: Vec<usize> = location.identified.iter().map(|&(d, _)| d).collect();
    let identified_own = location
        .identified
        .iter()
        .find(|&&(_, l)| l == from)
        .map(|&(d, _)| d);
    // Rover-frame positions of the detections with a bounded range, and their rocks.
    let mut seen: Vec<(usize, Point, Option<u32>)> = Vec::new();
    let mut range_log_errors = Vec::new();
    for (i, (d, r)) in detections.primary.iter().zip(&ranged).enumerate() {
        let Some(range) = estimated_range(d, r, terrain.calib) else {
            continue;
        };
        let rock = rock_under(&rock_ids, width, d.bbox);
        if let Some(rock) = rock {
            let truth = world.rocks[rock as usize].position.distance(pose.position);
            range_log_errors.push((range / truth).ln());
        }
        let b = r.bearing.angle;
        seen.push((i, Point::new(range * b.cos(), range * b.sin()), rock));
    }
    // The rover takes itself for the rock it stands at (too near to be seen whole). That rock,
    // if seen, is left out: the detection identified as its landmark, or else a detection
    // under half the range of the next.
    let mut by_range: Vec<usize> = (0..seen.len()).collect();
    by_range.sort_by(|&a, &b| range_of(&seen[a]).total_cmp(&range_of(&seen[b])));
    let own = identified_own.or(match by_range[..] {
        [a, b, ..] if range_of(&seen[a]) < 0.5 * range_of(&seen[b]) => Some(seen[a].0),
        _ => None,
    });
    let pick = |keep: &dyn Fn(usize) -> bool| {
        let scene: Vec<&(usize, Point, Option<u32>)> = seen
            .iter()
            .filter(|s| Some(s.0) != own && keep(s.0))
            .collect();
        let points: Vec<Point> = std::iter::once(Point::new(0.0, 0.0))
            .chain(scene.iter().map(|s| s.1))
            .collect();
        most_isolated_seen(&points, 0, objects).and_then(|i| scene[i - 1].2)
    };
    Choice {
        literal: pick(&|_| true),
        identified: pick(&|i| identified.contains(&i)),
        seen: seen.iter().filter_map(|s| s.2).collect(),
        identified_rocks: seen
            .iter()
            .filter(|s| identified.contains(&s.0))
            .filter_map(|s| s.2)
            .collect(),
        rover: Some([pose.position.x, pose.position.y]),
        range_log_errors,
    }
}

/// A detection's range for placing it: the geometric mean of its range interval; where that is
/// unbounded (a rock touching another, whose ground cue is withheld as unsure), the flat-ground
/// range of its contact row if the contact is in the picture; else none.
fn estimated_range(
    d: &qrm_vision::detection::Detection,
    r: &ranging::Ranged,
    calib: &qrm_vision::calib::Calibration,
) -> Option<f64> {
    if r.fused.high.is_finite() {
        return Some((r.fused.low.max(1e-3) * r.fused.high).sqrt());
    }
    (d.bbox[3] + 1 < calib.image.height)
        .then(|| calib.ground_range(d.contact_row))
        .flatten()
}

fn range_of(seen: &(usize, Point, Option<u32>)) -> f64 {
    seen.1.x.hypot(seen.1.y)
}

/// The rock under most of the pixels of `bbox` (columns may run past the seam).
fn rock_under(rock_ids: &[u32], width: u32, bbox: [u32; 4]) -> Option<u32> {
    let mut counts: BTreeMap<u32, usize> = BTreeMap::new();
    let height = rock_ids.len() as u32 / width;
    for row in bbox[1]..=bbox[3].min(height.saturating_sub(1)) {
        for column in bbox[0]..=bbox[2] {
            let id = rock_ids[(row * width + column % width) as usize];
            if id > 0 {
                *counts.entry(id - 1).or_default() += 1;
            }
        }
    }
    counts
        .into_iter()
        .max_by_key(|&(id, n)| (n, id))
        .map(|(id, _)| id)
}
