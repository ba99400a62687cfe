//! Association proposals from the layout of the landmarks around a station.
//!
//! A station's range intervals and bearings place each detection roughly around the rover
//! (polar → plane, an ellipse along the bearing covering the interval and across it the
//! bearing error: [`Placed`]). Between two
//! stations the landmarks move by one unknown rotation and translation (no odometry), so the
//! rigid motion that lines up most look-alike detections with an earlier station's landmarks
//! proposes who is who. Hypotheses come from every two look-alike correspondences whose
//! mutual distances agree; the one with most consistent correspondences wins. This only
//! *proposes*: the qualitative test of 000 §VI-C decides (`super::associate`).

use super::disc_grid::DiscGrid;
use super::placement::{bound_of_sum, separation, separation_of, turned_shape, Placed, Separation};
use super::significance::Chance;
use crate::ranging::Ray;
use nalgebra::{Matrix2, Matrix2x3, Matrix3, Vector2, Vector3};
use qrm_core::map::LandmarkId;
use qrm_core::measurement::angular_distance;

/// The landmarks fused at an earlier station, placed around it.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub landmarks: Vec<(LandmarkId, Placed)>,
    /// Rocks the frame's stations saw that no landmark holds (detections held back, founding
    /// none, or not used for mapping), placed in its coordinates ([`Registration::crowded`]).
    pub unmapped: Vec<Placed>,
    /// Whether the frame accumulates many stations' landmarks (the [`super::Sketch`]): it
    /// holds more look-alikes near each landmark than one station sees, so leaving a landmark
    /// unpaired is no evidence against a pair other frames make.
    pub accumulated: bool,
    /// Landmarks that left the sketch, placed in its coordinates where they were last seen:
    /// never registered against, only used to rule out look-alikes far from where they can
    /// still be (empty for a station's frame).
    pub departed: Vec<(LandmarkId, Placed)>,
    /// Unmapped rocks the sketch followed over several stations (`super::Sketch`; empty for a
    /// station's frame): where a detection placed on one belongs ([`Registration::track_of`]).
    pub tracks: Vec<Tracked>,
}

/// An unmapped rock the sketch followed over several stations, where stations saw something
/// and mapped no landmark for it, and the landmark whose placement it fits if one alone does.
/// Apart from every landmark, it is a rock of its own. Fitting one, it is most likely that
/// landmark's rock, held back station after station; its placements, averaged, say where
/// stations see that rock, which its landmark's own placement may not (a piece's range, a
/// lit face).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tracked {
    pub placed: Placed,
    pub landmark: Option<LandmarkId>,
}

impl Frame {
    /// Whether the frame holds enough placed landmarks for a registration to explain.
    pub fn registrable(&self) -> bool {
        self.landmarks.len() >= MIN_INLIERS
    }

    /// Whether the frame holds enough of `registration`'s landmarks to have found the same
    /// pairing, had it been right.
    pub fn could_confirm(&self, registration: &Registration) -> bool {
        registration
            .pairs
            .iter()
            .filter(|(_, l)| self.landmarks.iter().any(|m| m.0 == *l))
            .count()
            >= MIN_INLIERS
    }
}

/// The correspondences of the best rigid motion: `(detection, landmark)`, and the motion
/// (`[cos, sin, x, y]`: rotation, then shift) from the current station to the frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Registration {
    pub pairs: Vec<(usize, LandmarkId)>,
    pub motion: [f64; 4],
    /// How many chance fits as tight as this one the hypotheses tried should give
    /// ([`super::significance`]): far below one, the fit is no accident.
    pub nfa: f64,
}

/// Slack added to every distance comparison, metres (rock reference points are not points).
pub(super) const SLACK_M: f64 = 0.3;
/// A partner is unambiguous when every rival lies this many times farther (plus the slack).
pub(super) const UNIQUE: f64 = 2.0;
/// How much better (in fit score) the best motion must be than any different one.
const MARGIN: f64 = 1.5;
/// Loosest placement of a detection that anchors on the usual terms, metres: a looser one (a far
/// rock's range interval spans metres) reaches past its own rock, when that has no landmark
/// yet, to a neighbour's landmark, which is then the only one near and looks unambiguous
/// (marsyard seed 5: a rock 15.8 m away, placed within 6 m, paired at five stations with a
/// landmark 2.7 m from it, 2 unsound relations). A looser one anchors only where the frames
/// know no other rock it may be (`super::anchors`).
pub(super) const ANCHOR_RADIUS_M: f64 = 2.0;
/// Loosest placement of a detection that a registration pairs at all, metres: the stricter
/// terms of a pair looser than [`ANCHOR_RADIUS_M`] let the far rocks of sparse fields be
/// re-identified (`sparse-large` seed 3, half resolution: 78.8 % of the correct detections
/// fused instead of 41.7 %).
pub(super) const LONG_ANCHOR_RADIUS_M: f64 = 4.0;
/// Bearing tolerance, beyond a landmark's placement, within which a detection may be it.
const UNSEEN_WINDOW_RAD: f64 = 0.05;
/// Gauss–Newton steps of [`Motion::fit`] at most, and the step (radians and metres) below
/// which it has converged.
const FIT_ITERATIONS: usize = 8;
const FIT_CONVERGED: f64 = 1e-9;
/// Fewest correspondences a registration must explain to be believed.
pub(super) const MIN_INLIERS: usize = 4;
/// Most false alarms expected of a registration accepted on the significance of its fit …
pub(super) const SIGNIFICANT_NFA: f64 = 0.01;
/// … while every rival assignment's fit is no better than this many false alarms: what chance
/// gives.
const CHANCE_NFA: f64 = 1.0;
/// Margin around the frame's landmarks over which the null model spreads detections, metres.
const CHANCE_MARGIN_M: f64 = 2.0;
/// Radius of the disc in which the null model looks for the landmarks' densest cluster,
/// metres: a few placement errors, the scale of a cluster of rocks.
const CLUSTER_RADIUS_M: f64 = 3.0;

/// The rigid motion from the current station (`current`, by detection) to `frame` explaining
/// most look-alike correspondences (`alike(detection, landmark)`), if it explains at least
/// [`MIN_INLIERS`] and either clearly more than any motion that differs from it, or so tightly
/// that chance cannot explain it while every differing motion's fit is what chance gives
/// ([`super::significance`]). Motions are hypothesised only from pairs of seeds, the closest
/// look-alikes, which keeps the search quadratic in the detections rather than in all
/// look-alike pairs.
///
/// The sets of seeds (`seed_sets`, each a test of a correspondence) are tried in turn, each on
/// its own terms (its own count of hypotheses in the null model), and the first that registers
/// gives the registration. A hypothesis that several sets share is scored once: a navigator
/// registers against every station of the run, most of them out of sight, and there the second
/// set re-scored all of the first set's hypotheses (marsyard seed 7: two in five of its own).
pub fn register(
    current: &[Option<Placed>],
    frame: &Frame,
    alike: &dyn Fn(usize, LandmarkId) -> bool,
    seed_sets: &[&dyn Fn(usize, LandmarkId) -> bool],
) -> Option<Registration> {
    let correspondences: Vec<(usize, usize)> = (0..current.len())
        .filter(|&i| current[i].is_some())
        .flat_map(|i| (0..frame.landmarks.len()).map(move |j| (i, j)))
        .filter(|&(i, j)| alike(i, frame.landmarks[j].0))
        .collect();
    let in_set = |set: &dyn Fn(usize, LandmarkId) -> bool, (i, j): (usize, usize)| {
        set(i, frame.landmarks[j].0)
    };
    let seeds: Vec<(usize, usize)> = correspondences
        .iter()
        .copied()
        .filter(|&c| seed_sets.iter().any(|set| in_set(*set, c)))
        .collect();
    let candidates = Candidates::new(current, frame, &correspondences);
    let mut hypothesised: Vec<Hypothesis> = Vec::new();
    // Whether the seed pair, by index into the seeds, was tried for an earlier set.
    let mut paired = vec![false; seeds.len() * seeds.len()];
    for set in seed_sets {
        let member: Vec<bool> = seeds.iter().map(|&c| in_set(*set, c)).collect();
        let pairs: Vec<(usize, usize)> = seed_pairs(seeds.len())
            .filter(|&(x, y)| member[x] && member[y] && !paired[x * seeds.len() + y])
            .collect();
        for &(x, y) in &pairs {
            paired[x * seeds.len() + y] = true;
        }
        hypothesised.extend(hypotheses(current, frame, &seeds, pairs, &candidates));
        // In seed-pair order whichever set hypothesised them first, so that ties are broken
        // as for this set's hypotheses alone.
        let mut tried: Vec<usize> = (0..hypothesised.len())
            .filter(|&k| member[hypothesised[k].seeds.0] && member[hypothesised[k].seeds.1])
            .collect();
        tried.sort_unstable_by_key(|&k| hypothesised[k].seeds);
        let seeded = member.iter().filter(|&&m| m).count();
        let chance = chance(frame, seeded, &correspondences);
        let Some(inliers) = decisive(&mut hypothesised, &tried, &candidates).or_else(|| {
            significant(
                current,
                frame,
                &mut hypothesised,
                &tried,
                &candidates,
                &chance,
            )
        }) else {
            continue;
        };
        let nfa = core(current, frame, &inliers, &chance).0;
        let (motion, pairs) = unambiguous(current, frame, &inliers);
        if pairs.len() >= MIN_INLIERS {
            return Some(Registration {
                pairs,
                motion: [motion.cos, motion.sin, motion.shift[0], motion.shift[1]],
                nfa,
            });
        }
    }
    None
}

/// One motion hypothesis, scored only when its score can matter: most hypotheses cannot come
/// near the best one's, and scoring (the placements' ellipse tests) took most of a
/// registration's time.
struct Hypothesis {
    motion: Motion,
    /// The two seed correspondences it was hypothesised from, by index into the seeds.
    seeds: (usize, usize),
    /// How many detections the motion brings within reach of a look-alike ([`bounds`]):
    /// no more can be its inliers.
    most: usize,
    /// Its score is no higher: each of those detections' best fit as far as the reaches of
    /// its placement and its look-alikes' allow ([`bounds`]), summed. (Counting each as 1,
    /// as `most`, left three in four hypotheses to score where the rover saw many rocks.)
    best: f64,
    fit: Option<Fit>,
}

/// A scored hypothesis: its correspondences within tolerance, `(detection, index into the
/// frame's landmarks)`, and how tightly they fit (Σ (1 − (d / tolerance)²) over them, so that
/// a loose fit of many does not beat a tight fit of nearly as many).
struct Fit {
    inliers: Vec<(usize, usize)>,
    score: f64,
}

impl Hypothesis {
    /// Its fit, scored now if it was not yet.
    fn scored(&mut self, candidates: &Candidates) -> &Fit {
        self.fit.get_or_insert_with(|| {
            let (inliers, score) = matches(candidates, &self.motion);
            Fit { inliers, score }
        })
    }
}

/// The motions hypothesised from `pairs` of `seeds` (indices into them, first below second)
/// whose distances agree, with how many correspondences each may fit at most; none is scored
/// yet.
fn hypotheses(
    current: &[Option<Placed>],
    frame: &Frame,
    seeds: &[(usize, usize)],
    pairs: impl IntoIterator<Item = (usize, usize)>,
    candidates: &Candidates,
) -> Vec<Hypothesis> {
    let detection = |i: usize| current[i].expect("seeds are placed");
    let landmark = |j: usize| frame.landmarks[j].1;
    let between_detections = Baselines::new(seeds.iter().map(|s| s.0), current.len(), detection);
    let between_landmarks =
        Baselines::new(seeds.iter().map(|s| s.1), frame.landmarks.len(), landmark);
    let mut out = Vec::new();
    for (x, y) in pairs {
        let ((i1, j1), (i2, j2)) = (seeds[x], seeds[y]);
        if i1 == i2 || j1 == j2 {
            continue;
        }
        let (dp, p1_extent, p2_extent) = between_detections.between(i1, i2);
        let (dq, q1_extent, q2_extent) = between_landmarks.between(j1, j2);
        let tolerance = p1_extent + p2_extent + q1_extent + q2_extent + 2.0 * SLACK_M;
        // Short baselines give a poorly determined rotation.
        if (dp - dq).abs() > tolerance || dp < tolerance {
            continue;
        }
        let motion = Motion::from_pairs(
            [detection(i1).point, detection(i2).point],
            [landmark(j1).point, landmark(j2).point],
        );
        let (most, best) = bounds(candidates, &motion);
        out.push(Hypothesis {
            motion,
            seeds: (x, y),
            most,
            best,
            fit: None,
        });
    }
    out
}

/// Every two of `count` seeds, each once, the first below the second, in order.
fn seed_pairs(count: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..count).flat_map(move |x| (x + 1..count).map(move |y| (x, y)))
}

/// The distance between every two of some placements, and how far each reaches along the line
/// joining them (how much it lets that distance vary): computed once for each two placements
/// rather than for each two seed pairs that hold them (a registration tries hundreds of seed
/// pairs over a few dozen placements).
struct Baselines {
    /// Each placement's row in the table, by its index (none for those not used).
    row: Vec<Option<usize>>,
    used: usize,
    /// For rows `a`, `b`: the distance from `a` to `b`, and `a`'s and `b`'s extent along it.
    table: Vec<(f64, f64, f64)>,
}

impl Baselines {
    /// The table over the placements `used` (indices below `len`, repeats allowed), each
    /// given by `placed`.
    fn new(
        used: impl Iterator<Item = usize>,
        len: usize,
        placed: impl Fn(usize) -> Placed,
    ) -> Baselines {
        let mut row = vec![None; len];
        let mut indices = Vec::new();
        for index in used {
            if row[index].is_none() {
                row[index] = Some(indices.len());
                indices.push(index);
            }
        }
        let placed = &placed;
        let table = indices
            .iter()
            .flat_map(|&a| indices.iter().map(move |&b| (placed(a), placed(b))))
            .map(|(a, b)| {
                let along = unit(a.point, b.point);
                (distance(a.point, b.point), a.extent(along), b.extent(along))
            })
            .collect();
        Baselines {
            row,
            used: indices.len(),
            table,
        }
    }

    /// The distance from placement `a` to placement `b`, and their extents along it.
    fn between(&self, a: usize, b: usize) -> (f64, f64, f64) {
        let row = |index: usize| self.row[index].expect("a placement of the table");
        self.table[row(a) * self.used + row(b)]
    }
}

/// The inliers of the best-scoring hypothesis of those `tried` (indices into `hypotheses`), if
/// it explains at least [`MIN_INLIERS`] and scores [`MARGIN`] more than any hypothesis with a
/// different assignment.
///
/// Hypotheses are scored from the highest bound down ([`Hypothesis::best`]), and no further
/// once no bound left comes within the margin of the best score so far: such a hypothesis can
/// neither be the best nor stop it winning, whatever its assignment, so the answer is the one
/// scoring every hypothesis gives (marsyard seed 7: about a fifth of them are scored). Nor once
/// every hypothesis that may have [`MIN_INLIERS`] is scored while the best so far cannot win:
/// the best of all is then either that one or a hypothesis with too few inliers, and neither
/// registers (frames out of a navigator's sight, where nothing wins).
fn decisive(
    hypotheses: &mut [Hypothesis],
    tried: &[usize],
    candidates: &Candidates,
) -> Option<Vec<(usize, usize)>> {
    let mut order = tried.to_vec();
    order.sort_by(|&a, &b| hypotheses[b].best.total_cmp(&hypotheses[a].best));
    let may_have_enough = |h: &Hypothesis| h.most >= MIN_INLIERS && h.fit.is_none();
    let mut unjudged = tried
        .iter()
        .filter(|&&k| may_have_enough(&hypotheses[k]))
        .count();
    let mut judged_enough = false;
    let mut top = f64::NEG_INFINITY;
    for k in order {
        if unjudged == 0 && !judged_enough {
            winner(hypotheses, tried)?;
            judged_enough = true;
        }
        if hypotheses[k].best + MARGIN <= top {
            break;
        }
        unjudged -= usize::from(may_have_enough(&hypotheses[k]));
        top = top.max(hypotheses[k].scored(candidates).score);
    }
    winner(hypotheses, tried)
}

/// The inliers of the best-scoring of the scored hypotheses among those `tried`, if it has at
/// least [`MIN_INLIERS`] and scores [`MARGIN`] more than any with a different assignment.
fn winner(hypotheses: &[Hypothesis], tried: &[usize]) -> Option<Vec<(usize, usize)>> {
    let scored = || tried.iter().filter_map(|&k| hypotheses[k].fit.as_ref());
    let best = scored().max_by(|a, b| a.score.total_cmp(&b.score))?;
    let runner_up = scored()
        .filter(|h| !same_assignment(&h.inliers, &best.inliers))
        .map(|h| h.score)
        .fold(0.0, f64::max);
    (best.inliers.len() >= MIN_INLIERS && best.score >= runner_up + MARGIN)
        .then(|| best.inliers.clone())
}

/// The null model of [`super::significance`] for this registration: the pairs of its `seeds`
/// seed correspondences tried, the density of the frame's landmarks (the greater of their mean
/// density over their bounding box widened by [`CHANCE_MARGIN_M`] on each side, and the densest
/// disc of radius [`CLUSTER_RADIUS_M`] around one of them) times the share of the frame's
/// landmarks a detection looks like, and the detections with a look-alike in the frame.
///
/// A chance fit pairs a detection only with a look-alike, so a chance hit is a detection
/// falling near a landmark it looks like: counting every landmark as a hit, the null model
/// made a true fit in a dense cluster look like chance (stress seed 22, station 10 after a
/// long step: 7 correct pairs against the sketch at NFA 0.22, the only registration; no
/// station registered again for 25 stations).
fn chance(frame: &Frame, seeds: usize, correspondences: &[(usize, usize)]) -> Chance {
    let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (_, q) in &frame.landmarks {
        for axis in 0..2 {
            low[axis] = low[axis].min(q.point[axis]);
            high[axis] = high[axis].max(q.point[axis]);
        }
    }
    let side = |axis: usize| (high[axis] - low[axis]).max(0.0) + 2.0 * CHANCE_MARGIN_M;
    let mean = frame.landmarks.len() as f64 / (side(0) * side(1));
    let densest = frame
        .landmarks
        .iter()
        .map(|(_, q)| {
            frame
                .landmarks
                .iter()
                .filter(|(_, o)| distance(o.point, q.point) <= CLUSTER_RADIUS_M)
                .count()
        })
        .max()
        .unwrap_or(0) as f64
        / (std::f64::consts::PI * CLUSTER_RADIUS_M * CLUSTER_RADIUS_M);
    let mut detections: Vec<usize> = correspondences.iter().map(|c| c.0).collect();
    detections.sort_unstable();
    detections.dedup();
    let share = match detections.len() * frame.landmarks.len() {
        0 => 1.0,
        possible => correspondences.len() as f64 / possible as f64,
    };
    Chance {
        tests: (seeds * seeds.saturating_sub(1) / 2).max(1) as f64,
        density: mean.max(densest) * share,
        detections: detections.len(),
    }
}

/// The tightest core of the hypothesis least explicable by chance, if its NFA is below
/// [`SIGNIFICANT_NFA`] while every hypothesis with a different assignment is what chance gives
/// (NFA at least [`CHANCE_NFA`]): where rocks look alike and few are shared, a true motion's
/// few centimetre-tight pairs score little above a chance fit's looser ones, and the margin
/// alone turns it down (stress seed 4: 4 true pairs 3–7 cm off, best score 3.99 against a
/// chance fit's 3.15; the map never grew past the first station's 6 landmarks; with the test
/// and the cluster density of [`chance`], 52 sightings fused and no landmark mixed).
fn significant(
    current: &[Option<Placed>],
    frame: &Frame,
    hypotheses: &mut [Hypothesis],
    tried: &[usize],
    candidates: &Candidates,
    chance: &Chance,
) -> Option<Vec<(usize, usize)>> {
    // A hypothesis bounded below the fewest inliers cannot have them: it is left unscored.
    let judged: Vec<(f64, Vec<(usize, usize)>)> = tried
        .iter()
        .filter_map(|&k| {
            let hypothesis = &mut hypotheses[k];
            if hypothesis.most < MIN_INLIERS {
                return None;
            }
            let fit = hypothesis.scored(candidates);
            (fit.inliers.len() >= MIN_INLIERS).then(|| core(current, frame, &fit.inliers, chance))
        })
        .collect();
    let (nfa, inliers) = judged.iter().min_by(|a, b| a.0.total_cmp(&b.0))?;
    let rivals_by_chance = judged
        .iter()
        .filter(|(_, other)| !same_assignment(other, inliers))
        .all(|(rival, _)| *rival >= CHANCE_NFA);
    (*nfa < SIGNIFICANT_NFA && rivals_by_chance).then(|| inliers.clone())
}

/// The NFA of a hypothesis' inliers refitted by least squares, and its tightest inliers that
/// reach it.
fn core(
    current: &[Option<Placed>],
    frame: &Frame,
    inliers: &[(usize, usize)],
    chance: &Chance,
) -> (f64, Vec<(usize, usize)>) {
    let pairs = placed_pairs(current, frame, inliers);
    let motion = Motion::fit(&pairs);
    // Residuals for the placements' shapes (a separation's distance): for discs, metres.
    let mut residuals: Vec<(f64, (usize, usize))> = pairs
        .iter()
        .zip(inliers)
        .map(|(pair, &inlier)| (GrownPair::new(pair).separation(&motion).distance, inlier))
        .collect();
    residuals.sort_by(|a, b| a.0.total_cmp(&b.0));
    let distances: Vec<f64> = residuals.iter().map(|r| r.0).collect();
    let (nfa, used) = chance.nfa(&distances, MIN_INLIERS);
    (nfa, residuals[..used].iter().map(|r| r.1).collect())
}

/// The placements of `inliers`, `(detection, index into the frame's landmarks)`.
fn placed_pairs(
    current: &[Option<Placed>],
    frame: &Frame,
    inliers: &[(usize, usize)],
) -> Vec<(Placed, Placed)> {
    inliers
        .iter()
        .map(|&(i, j)| (current[i].expect("inlier"), frame.landmarks[j].1))
        .collect()
}

/// The motion refitted on all `inliers`, and the correspondences it makes unambiguous: every
/// other landmark of the frame, and every other detection, lies clearly farther (distances for
/// the placements' shapes: a [`Separation`]'s). Decided jointly: a detection near the landmark
/// that an unambiguous pair of its own explains ([`explained`]) is no rival (two touching rocks
/// with a landmark each, whose placements reach over each other).
fn unambiguous(
    current: &[Option<Placed>],
    frame: &Frame,
    inliers: &[(usize, usize)],
) -> (Motion, Vec<(usize, LandmarkId)>) {
    let motion = Motion::fit(&placed_pairs(current, frame, inliers));
    let alone: Vec<(usize, usize)> = inliers
        .iter()
        .copied()
        .filter(|&(i, j)| unambiguous_pair(&motion, current, frame, i, j, |_| true))
        .collect();
    let pairs = inliers
        .iter()
        .copied()
        .filter(|&(i, j)| {
            alone.contains(&(i, j))
                || unambiguous_pair(&motion, current, frame, i, j, |k| {
                    !explained(&motion, current, frame, &alone, k, j)
                })
        })
        .map(|(i, j)| (i, frame.landmarks[j].0))
        .collect();
    (motion, pairs)
}

/// Whether detection `k` is explained away from landmark `j` of the frame: one of `pairs`
/// (detection, index into the frame's landmarks) pairs it with another landmark, which lies
/// nearer it than `j` does.
fn explained(
    motion: &Motion,
    current: &[Option<Placed>],
    frame: &Frame,
    pairs: &[(usize, usize)],
    k: usize,
    j: usize,
) -> bool {
    let Some(p) = current[k] else {
        return false;
    };
    let distance = |m: usize| motion.separation(&p, &frame.landmarks[m].1).distance;
    pairs
        .iter()
        .any(|&(i, m)| i == k && m != j && distance(m) < distance(j))
}

/// Whether landmark `j` of the frame is detection `i`'s unambiguous partner under `motion`:
/// the detection is placed no looser than registration pairs ([`LONG_ANCHOR_RADIUS_M`]), the
/// landmark lies within the pair's separation, every other landmark clearly farther from the
/// detection and every other placed detection that `rivals` clearly farther from the landmark.
fn unambiguous_pair(
    motion: &Motion,
    current: &[Option<Placed>],
    frame: &Frame,
    i: usize,
    j: usize,
    rivals: impl Fn(usize) -> bool,
) -> bool {
    let Some(p) = current[i] else {
        return false;
    };
    let q = frame.landmarks[j].1;
    let separation = motion.separation(&p, &q);
    let near = UNIQUE * separation.distance + SLACK_M;
    separation.within()
        && p.reach() <= LONG_ANCHOR_RADIUS_M
        && (0..frame.landmarks.len())
            .all(|k| k == j || motion.separation(&p, &frame.landmarks[k].1).distance > near)
        && others_farther(motion, current, i, &q, near, rivals)
}

/// Whether every placed detection of `placed` but `i` that `counts` lies farther than `near`
/// from the landmark placed at `q`, under `motion`.
fn others_farther(
    motion: &Motion,
    placed: &[Option<Placed>],
    i: usize,
    q: &Placed,
    near: f64,
    counts: impl Fn(usize) -> bool,
) -> bool {
    placed.iter().enumerate().all(|(k, other)| {
        k == i || !counts(k) || other.is_none_or(|o| motion.separation(&o, q).distance > near)
    })
}

impl Registration {
    /// The track of the frame the motion places detection `i` (of the station's `placed`) on,
    /// unambiguously, by the pairs' own test ([`unambiguous_pair`]): the track lies within the
    /// detection's placement, every landmark of the frame but the track's own (departed ones
    /// too) and every other track clearly farther from the detection, and every other placed
    /// detection clearly farther from the track.
    pub fn track_of(&self, frame: &Frame, placed: &[Option<Placed>], i: usize) -> Option<Tracked> {
        let p = placed[i].filter(|p| p.reach() <= LONG_ANCHOR_RADIUS_M)?;
        let motion = self.motion();
        let mut within = frame
            .tracks
            .iter()
            .filter(|t| motion.separation(&p, &t.placed).within());
        let (Some(track), None) = (within.next(), within.next()) else {
            return None;
        };
        let clear = UNIQUE * motion.separation(&p, &track.placed).distance + SLACK_M;
        let unambiguous = frame
            .landmarks
            .iter()
            .chain(&frame.departed)
            .filter(|(l, _)| track.landmark != Some(*l))
            .all(|(_, q)| motion.separation(&p, q).distance > clear)
            && frame.tracks.iter().all(|t| {
                std::ptr::eq(t, track) || motion.separation(&p, &t.placed).distance > clear
            })
            && others_farther(&motion, placed, i, &track.placed, clear, |_| true);
        unambiguous.then_some(*track)
    }

    /// Adds the pairs of the `observers` (detections that took no part in the fit: doubted
    /// by the detector) under the motion the others found, by the fit's own test of an
    /// unambiguous partner: the landmark, `alike` the observer and not paired already, lies
    /// within the pair's separation, every other landmark of the frame clearly farther from
    /// the observer, and every other placed detection (`placed`, observers included) clearly
    /// farther from the landmark, but those the fit's pairs explain ([`explained`]). An
    /// observer neither steers the motion nor changes what the fit's significance is judged on
    /// (`sparse-large` seed 3 half: with the doubted detections in the fit, station 58
    /// registered against no frame, and the 25 stations after it fused nothing).
    pub fn pair_observers(
        &mut self,
        frame: &Frame,
        placed: &[Option<Placed>],
        observers: &[usize],
        alike: &dyn Fn(usize, LandmarkId) -> bool,
    ) {
        let motion = self.motion();
        // The fit's pairs, by index into the frame's landmarks.
        let paired: Vec<(usize, usize)> = self
            .pairs
            .iter()
            .filter_map(|&(i, l)| Some((i, frame.landmarks.iter().position(|m| m.0 == l)?)))
            .collect();
        let mut added = Vec::new();
        for &i in observers {
            let Some(p) = placed[i] else {
                continue;
            };
            let nearest = frame
                .landmarks
                .iter()
                .enumerate()
                .map(|(j, (_, q))| (j, motion.separation(&p, q).distance))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(j, _)| j);
            let Some(j) = nearest.filter(|&j| {
                unambiguous_pair(&motion, placed, frame, i, j, |k| {
                    !explained(&motion, placed, frame, &paired, k, j)
                })
            }) else {
                continue;
            };
            let l = frame.landmarks[j].0;
            if alike(i, l) && !self.pairs.iter().any(|&(_, m)| m == l) {
                added.push((i, l));
            }
        }
        self.pairs.extend(added);
    }

    /// Drops the pairs whose landmark lies within reach of another placed detection of the
    /// station (`placed`, observers included) that looks like it (`alike`), not clearly
    /// farther than the pair's own: the fit's own test (`unambiguous_pair`) sees only the
    /// detections that steer it, and by luminance an uncorroborated piece does not steer.
    /// JPEG marsyard seed 11, station 39 (with observers anchoring past crowded frames): rock
    /// 20's piece paired with the landmark a blob of rocks 12 and 20 had founded, while rock
    /// 12's piece, an observer, lay as near it; the landmark went on to hold both rocks, 2
    /// unsound relations. Applied in colour too, it cost 0.1–0.5 points of the fused share on
    /// each colour marsyard seed, where observers are mostly the detector's doubted cuts of
    /// the rock paired.
    pub fn drop_ambiguous_pairs(
        &mut self,
        frame: &Frame,
        placed: &[Option<Placed>],
        alike: &dyn Fn(usize, LandmarkId) -> bool,
    ) {
        let motion = self.motion();
        self.pairs.retain(|&(i, l)| {
            let (Some(p), Some((_, q))) = (placed[i], frame.landmarks.iter().find(|m| m.0 == l))
            else {
                return true;
            };
            let near = UNIQUE * motion.separation(&p, q).distance + SLACK_M;
            others_farther(&motion, placed, i, q, near, |k| alike(k, l))
        });
    }

    /// Drops the pairs whose landmark, brought back into the current station by the motion,
    /// lies in a direction nearer to where one of the station's detections without a placement
    /// was seen (its ray in `elsewhere`, at the landmark's range) than to its paired
    /// detection's (placed `placed[i]`, seen along `rays[i]`): the landmark may be that rock
    /// (on half-resolution marsyard seed 4, a rock 1.8 m from a landmark's, seen while the
    /// landmark's own rock was detected but touching another, took the landmark at three
    /// stations: 2 unsound relations). Nearer either way a blob is judged: by its centre, or by
    /// the nearest column of its span ([`Ray::half_width`]), since a rock's centre may lie
    /// anywhere across its blob (the 1 000-rock drive, station 235: a landmark brought back
    /// 0.062 rad from its paired detection's centre and 0.081 from an unranged one's, but
    /// 5 columns from the unranged blob's edge and 9 from its pair's, was the unranged blob's
    /// rock). Not a ray that starts beyond the landmark's reach ([`Ray::nearest`]): that rock
    /// is farther. Unranged detections up the image, whose contacts nearer rocks hide, lie in
    /// nearly every near rock's direction (grayscale marsyard seed 7, station 4: a rock ≥ 5 m
    /// away, 0.01° from landmark 20 at 2 m, dropped its own rock's pair, and two neighbours were
    /// held back with it as their only candidate); of the pairs this test dropped on colour
    /// marsyard seed 7, 57 were right and 3 wrong.
    pub fn drop_pairs_seen_elsewhere(
        &mut self,
        frame: &Frame,
        placed: &[Option<Placed>],
        rays: &[Ray],
        elsewhere: &[Ray],
    ) {
        let direction = |p: [f64; 2]| p[1].atan2(p[0]);
        let motion = self.motion();
        self.pairs.retain(|&(i, l)| {
            let (Some(p), Some((_, q))) = (placed[i], frame.landmarks.iter().find(|m| m.0 == l))
            else {
                return true;
            };
            let back = motion.unapply(q.point);
            let (range, back) = (back[0].hypot(back[1]), direction(back));
            let across = |ray: &Ray| {
                (angular_distance(back, ray.direction_at(range)) - ray.half_width).max(0.0)
            };
            let (own, own_across) = (angular_distance(back, direction(p.point)), across(&rays[i]));
            elsewhere
                .iter()
                .filter(|ray| ray.nearest <= range + q.reach() + SLACK_M)
                .all(|ray| {
                    angular_distance(back, ray.direction_at(range)) >= own
                        && across(ray) >= own_across
                })
        });
    }

    /// The frame's unpaired landmarks that the motion brings within `reach` metres of the
    /// current station in a direction where the station detected nothing (`seen`: the ray of
    /// every detection, at the landmark's range): rocks the motion says are in view and the
    /// panorama does not show.
    pub fn unseen(&self, frame: &Frame, seen: &[Ray], reach: f64) -> usize {
        let motion = self.motion();
        frame
            .landmarks
            .iter()
            .filter(|(l, _)| !self.pairs.iter().any(|p| p.1 == *l))
            .filter(|(_, q)| {
                let back = motion.unapply(q.point);
                let range = back[0].hypot(back[1]);
                // The line of sight to the landmark, in the frame's coordinates.
                let sight = unit(motion.apply([0.0, 0.0]), q.point);
                if range > reach || range <= q.extent(sight) {
                    return false;
                }
                let direction = back[1].atan2(back[0]);
                let across = q.extent([-sight[1], sight[0]]);
                let window = (across + SLACK_M).atan2(range) + UNSEEN_WINDOW_RAD;
                seen.iter()
                    .all(|ray| angular_distance(direction, ray.direction_at(range)) > window)
            })
            .count()
    }

    /// Whether another rock of the frame lies where the motion puts the current station's
    /// placement `p`, besides landmark `l`: another landmark, or an unmapped rock placed no
    /// looser than a long anchor may be ([`LONG_ANCHOR_RADIUS_M`]; a looser one tells no rock
    /// from another) that none of the station's `others` placements accounts for (lies nearer
    /// to it than `p`, within their separation: then it is that detection's rock). A long
    /// placement reaches along the line of sight past its rock to others, so it pairs only
    /// where no other rock is known. (An unmapped rock where `l` lies may be `l`'s own rock
    /// seen before it was mapped, but letting such rocks pass when the station that saw them
    /// had not mapped `l` mixed clustered rocks: stress seed 12 landmark purity 0.970 → 0.965,
    /// grayscale marsyard seed 3 0.991 → 0.986. Letting those pass that another detection
    /// accounts for: grayscale marsyard seed 7 33.3 → 43.7 % fused, no set of 15 lower by
    /// more than 0.2 points, purity unchanged, docs/RUN.md.) A landmark that another
    /// detection accounts for is that detection's rock too, and crowds no pair.
    ///
    /// When `fragmented` (luminance mode), an unmapped rock that lies within `l`'s own
    /// placement in the frame crowds no pair either: by luminance the detector breaks a rock
    /// into pieces, and a piece the stereo test does not corroborate observes and is mostly
    /// held back, so the frames, the sketch most of all, fill with unmapped placements of
    /// mapped rocks, and observers could never anchor (grayscale marsyard seed 3: of 423
    /// held-back detections whose own landmark was among their candidates, 244 were paired
    /// with it and refused, 216 of them with a crowded frame). Over 14 luminance sets, 3 638
    /// sightings passed through this rule to the right rock's landmark and 88 to another,
    /// 39 of those in the rock piles of stress seeds 9 and 12, where a landmark already held
    /// two rocks (docs/RUN.md, stop 68). In colour a piece steers the fit like any detection
    /// and far fewer are held back (marsyard seed 3: 197 held back, against 579 by
    /// luminance); allowed there, the rule took stress seed 4's purity from 0.955 to 0.923
    /// (piles of overlapping rocks).
    pub fn crowded(
        &self,
        frame: &Frame,
        p: &Placed,
        l: LandmarkId,
        others: &[Placed],
        fragmented: bool,
    ) -> bool {
        let motion = self.motion();
        self.crowded_by_landmarks(frame, p, l, others)
            || frame
                .unmapped
                .iter()
                .filter(|g| g.reach() <= LONG_ANCHOR_RADIUS_M)
                .filter(|g| {
                    !fragmented
                        || !frame
                            .landmarks
                            .iter()
                            .any(|m| m.0 == l && separation(g, &m.1, SLACK_M).within())
                })
                .any(|g| unaccounted(&motion, p, g, others))
    }

    /// Whether another landmark of the frame lies where the motion puts the placement `p`,
    /// besides `l`, that none of the station's `others` placements accounts for: the landmark
    /// half of [`Registration::crowded`].
    pub fn crowded_by_landmarks(
        &self,
        frame: &Frame,
        p: &Placed,
        l: LandmarkId,
        others: &[Placed],
    ) -> bool {
        let motion = self.motion();
        frame
            .landmarks
            .iter()
            .filter(|m| m.0 != l)
            .any(|m| unaccounted(&motion, p, &m.1, others))
    }

    /// The frame's unmapped rock (index into [`Frame::unmapped`]) that the current station's
    /// detection `i` is ([`unmapped_partner`]), when every other placed detection of the
    /// station lies clearly farther from the rock.
    pub fn recognised(&self, frame: &Frame, current: &[Option<Placed>], i: usize) -> Option<usize> {
        let motion = self.motion();
        let p = current[i]?;
        let g = unmapped_partner(&motion, &p, frame)?;
        let q = frame.unmapped[g];
        let near = UNIQUE * motion.separation(&p, &q).distance + SLACK_M;
        current
            .iter()
            .enumerate()
            .all(|(k, other)| {
                k == i || other.is_none_or(|o| motion.separation(&o, &q).distance > near)
            })
            .then_some(g)
    }

    /// Where the current station's point `p` lies in the frame's coordinates.
    pub fn to_frame(&self, p: [f64; 2]) -> [f64; 2] {
        self.motion().apply(p)
    }

    /// The current station's placement `p` in the frame's coordinates.
    pub fn to_frame_placed(&self, p: &Placed) -> Placed {
        self.motion().apply_placed(p)
    }

    fn motion(&self) -> Motion {
        let [cos, sin, x, y] = self.motion;
        Motion {
            cos,
            sin,
            shift: [x, y],
        }
    }
}

/// The unmapped rock of `frame` (index into [`Frame::unmapped`]) that `motion` puts the
/// placement `p` on, by the fit's own test of an unambiguous partner: both placed no looser
/// than an anchor ([`ANCHOR_RADIUS_M`]), within the pair's separation, and every landmark and
/// every other unmapped rock of the frame clearly farther from `p`.
pub(super) fn unmapped_partner(motion: &Motion, p: &Placed, frame: &Frame) -> Option<usize> {
    partner_among(motion, p, frame, |_, _| true)
}

/// [`unmapped_partner`] with a narrower crowd: a landmark or another unmapped rock `o` of the
/// frame counts only where `crowds(o, is_landmark)` says.
pub(super) fn partner_among(
    motion: &Motion,
    p: &Placed,
    frame: &Frame,
    crowds: impl Fn(&Placed, bool) -> bool,
) -> Option<usize> {
    if p.reach() > ANCHOR_RADIUS_M {
        return None;
    }
    let (g, separation) = frame
        .unmapped
        .iter()
        .enumerate()
        .map(|(g, q)| (g, motion.separation(p, q)))
        .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance))?;
    let rock = &frame.unmapped[g];
    let near = UNIQUE * separation.distance + SLACK_M;
    let landmarks = frame.landmarks.iter().map(|m| (&m.1, true));
    let unmapped = frame
        .unmapped
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != g)
        .map(|(_, o)| (o, false));
    // `crowds` is asked only of placements near enough to crowd: at the end of the drive
    // it is a pass over the other frame's placements.
    let alone = landmarks
        .chain(unmapped)
        .filter(|&(o, _)| motion.separation(p, o).distance <= near)
        .all(|(o, is_landmark)| !crowds(o, is_landmark));
    (separation.within() && rock.reach() <= ANCHOR_RADIUS_M && alone).then_some(g)
}

/// Whether the frame's rock `g` lies where `motion` puts the placement `p`, and no placement
/// of `others` accounts for it (lies nearer to it, within their separation: then it is that
/// detection's rock).
fn unaccounted(motion: &Motion, p: &Placed, g: &Placed, others: &[Placed]) -> bool {
    let ours = motion.separation(p, g);
    ours.within()
        && !others.iter().any(|o| {
            let theirs = motion.separation(o, g);
            theirs.within() && theirs.distance < ours.distance
        })
}

/// The displacement from an `earlier` station to a `later` one, seen from the earlier camera:
/// the heading of the later station (radians, the bearings' convention) and its s.d., from
/// the rigid motion that brings the landmarks both frames placed together
/// ([`Motion::consensus`], at least [`MIN_INLIERS`] of them). This is the motion command of
/// 002's probabilistic map, which a rover without odometry does not have. `None` when too few
/// landmarks agree, or when the station moved less than twice the shift's s.d.
///
/// The s.d. is the least-squares one, from the scatter the fit leaves. The placements bound
/// their errors and, as discs, overstated them about eightfold; against the true headings of
/// five rendered drives (marsyard seed 7, half-resolution marsyard seed 3 and random seed 5,
/// `sparse-large` seed 3, the demo), errors over this s.d. had an r.m.s. of 0.85–0.96 while
/// placements were discs fitted on their points alone (not measured since).
pub fn displacement(earlier: &Frame, later: &Frame) -> Option<(f64, f64)> {
    let pairs = shared_placements(later, earlier);
    let motion = Motion::consensus(pairs.clone(), MIN_INLIERS)?;
    let agreeing: Vec<&(Placed, Placed)> = pairs
        .iter()
        .filter(|(p, q)| misfit(&motion, *p, *q) <= 0.0)
        .collect();
    let n = agreeing.len() as f64;
    // Per-coordinate variance of a placement, from the residuals (2n equations, 3 unknowns).
    let variance = agreeing
        .iter()
        .map(|(p, q)| distance(motion.apply(p.point), q.point).powi(2))
        .sum::<f64>()
        / (2.0 * n - 3.0);
    let mean = agreeing.iter().fold([0.0, 0.0], |m, (p, _)| {
        [m[0] + p.point[0] / n, m[1] + p.point[1] / n]
    });
    let spread: f64 = agreeing
        .iter()
        .map(|(p, _)| distance(p.point, mean).powi(2))
        .sum();
    // The shift is q̄ − R·p̄: the mean's error plus the rotation's, lever arm |p̄|.
    let shift_sd = (variance / n + mean[0].hypot(mean[1]).powi(2) * variance / spread).sqrt();
    let [x, y] = motion.shift;
    let moved = x.hypot(y);
    (moved >= 2.0 * shift_sd).then(|| (y.atan2(x), shift_sd.atan2(moved)))
}

/// The landmarks both frames hold, each as its placement in `from` and in `onto`: the pairs a
/// motion from one frame's coordinates to the other's is fitted on ([`Motion::consensus`]).
pub(super) fn shared_placements(from: &Frame, onto: &Frame) -> Vec<(Placed, Placed)> {
    from.landmarks
        .iter()
        .filter_map(|(l, p)| {
            let (_, q) = onto.landmarks.iter().find(|(m, _)| m == l)?;
            Some((*p, *q))
        })
        .collect()
}

/// How far `motion` leaves `p` beyond the placements of `p` and `q` and the slack (a
/// [`Separation`]'s distance beyond its gate; for discs, metres beyond their radii and the
/// slack): positive when the two placements cannot be one rock under that motion.
pub(super) fn misfit(motion: &Motion, p: Placed, q: Placed) -> f64 {
    let separation = motion.separation(&p, &q);
    separation.distance - separation.gate
}

/// Whether two correspondence sets mostly agree (the same motion found twice).
fn same_assignment(a: &[(usize, usize)], b: &[(usize, usize)]) -> bool {
    let shared = a.iter().filter(|p| b.contains(p)).count();
    2 * shared >= a.len().min(b.len())
}

/// A point of the current station and its partner in the frame.
type PointPair = ([f64; 2], [f64; 2]);

/// A placement of the current station and its partner in the frame, each grown by half the
/// registration's slack once (turning a placement does not change its growth), for testing
/// motions against them.
struct GrownPair {
    p: [f64; 2],
    grown_p: Matrix2<f64>,
    q: [f64; 2],
    grown_q: Matrix2<f64>,
}

impl GrownPair {
    fn new((p, q): &(Placed, Placed)) -> GrownPair {
        GrownPair {
            p: p.point,
            grown_p: p.grown(0.5 * SLACK_M),
            q: q.point,
            grown_q: q.grown(0.5 * SLACK_M),
        }
    }

    /// Where `motion` leaves `p` from `q`.
    fn offset(&self, motion: &Motion) -> Vector2<f64> {
        let moved = motion.apply(self.p);
        Vector2::new(moved[0] - self.q[0], moved[1] - self.q[1])
    }

    /// The ellipse bounding both grown placements' sum, `p`'s turned by `motion`.
    fn gate(&self, motion: &Motion) -> Matrix2<f64> {
        bound_of_sum(
            &turned_shape(&self.grown_p, [motion.cos, motion.sin]),
            &self.grown_q,
        )
    }

    /// [`Motion::separation`] of the pair.
    fn separation(&self, motion: &Motion) -> Separation {
        separation_of(self.offset(motion), &self.gate(motion))
    }
}

/// Rotation by `angle` then translation.
pub(super) struct Motion {
    cos: f64,
    sin: f64,
    shift: [f64; 2],
}

impl Motion {
    pub(super) fn identity() -> Motion {
        Motion {
            cos: 1.0,
            sin: 0.0,
            shift: [0.0, 0.0],
        }
    }

    /// The motion taking `p[0]` onto `q[0]` and the direction `p[0]→p[1]` onto `q[0]→q[1]`.
    fn from_pairs(p: [[f64; 2]; 2], q: [[f64; 2]; 2]) -> Motion {
        let angle = (q[1][1] - q[0][1]).atan2(q[1][0] - q[0][0])
            - (p[1][1] - p[0][1]).atan2(p[1][0] - p[0][0]);
        let (sin, cos) = angle.sin_cos();
        let rotated = [cos * p[0][0] - sin * p[0][1], sin * p[0][0] + cos * p[0][1]];
        Motion {
            cos,
            sin,
            shift: [q[0][0] - rotated[0], q[0][1] - rotated[1]],
        }
    }

    /// The least-squares rigid motion taking each point `.0` onto its `.1` (2-D Procrustes).
    fn procrustes(pairs: &[PointPair]) -> Motion {
        let n = pairs.len() as f64;
        let mean = |f: fn(&PointPair) -> [f64; 2]| {
            let sum = pairs
                .iter()
                .map(f)
                .fold([0.0, 0.0], |a, p| [a[0] + p[0], a[1] + p[1]]);
            [sum[0] / n, sum[1] / n]
        };
        let (mp, mq) = (mean(|p| p.0), mean(|p| p.1));
        let (mut dot, mut cross) = (0.0, 0.0);
        for (p, q) in pairs {
            let (a, b) = ([p[0] - mp[0], p[1] - mp[1]], [q[0] - mq[0], q[1] - mq[1]]);
            dot += a[0] * b[0] + a[1] * b[1];
            cross += a[0] * b[1] - a[1] * b[0];
        }
        Motion::turning(cross.atan2(dot), mp, mq)
    }

    /// The rotation by `angle` that, with its shift, takes `from` onto `to`.
    fn turning(angle: f64, from: [f64; 2], to: [f64; 2]) -> Motion {
        let (sin, cos) = angle.sin_cos();
        let rotated = [cos * from[0] - sin * from[1], sin * from[0] + cos * from[1]];
        Motion {
            cos,
            sin,
            shift: [to[0] - rotated[0], to[1] - rotated[1]],
        }
    }

    /// The rigid motion taking each placement `.0` onto its `.1` that fits them best for their
    /// shapes: the least-squares motion of their points, refined by Gauss–Newton on the
    /// residuals measured against each pair's [`Separation`] ellipse. A placement long along
    /// its bearing then pulls the fit across its bearing only, and a loose one (a piece, a far
    /// rock) little: fitted on points alone, such placements moved a tight core's residuals
    /// and lost whole stations (the demo set, stations 5 and 6: NFA 9 × 10⁻⁵ → 0.19 with two
    /// pieces in the fit). For discs of one size it is the least-squares motion.
    pub(super) fn fit(pairs: &[(Placed, Placed)]) -> Motion {
        let points: Vec<PointPair> = pairs.iter().map(|(p, q)| (p.point, q.point)).collect();
        let mut motion = Motion::procrustes(&points);
        let grown: Vec<GrownPair> = pairs.iter().map(GrownPair::new).collect();
        for _ in 0..FIT_ITERATIONS {
            let (mut normal, mut gradient) = (Matrix3::zeros(), Vector3::zeros());
            for pair in &grown {
                let Some(weight) = pair.gate(&motion).try_inverse() else {
                    continue;
                };
                let (p, residual) = (pair.p, pair.offset(&motion));
                // ∂ residual / ∂ (angle, shift x, shift y).
                let (x, y) = (p[0], p[1]);
                let jacobian = Matrix2x3::new(
                    -motion.sin * x - motion.cos * y,
                    1.0,
                    0.0,
                    motion.cos * x - motion.sin * y,
                    0.0,
                    1.0,
                );
                normal += jacobian.transpose() * weight * jacobian;
                gradient += jacobian.transpose() * weight * residual;
            }
            let Some(step) = normal.lu().solve(&-gradient) else {
                break;
            };
            let angle = motion.sin.atan2(motion.cos) + step[0];
            let (sin, cos) = angle.sin_cos();
            motion = Motion {
                cos,
                sin,
                shift: [motion.shift[0] + step[1], motion.shift[1] + step[2]],
            };
            if step.norm() < FIT_CONVERGED {
                break;
            }
        }
        motion
    }

    /// How far apart the motion leaves the placement `p` and the frame's `q` (with the
    /// registration's slack).
    pub(super) fn separation(&self, p: &Placed, q: &Placed) -> Separation {
        GrownPair::new(&(*p, *q)).separation(self)
    }

    /// The placement `p` of the current station in the frame's coordinates.
    pub(super) fn apply_placed(&self, p: &Placed) -> Placed {
        p.turned([self.cos, self.sin], self.apply(p.point))
    }

    /// The motion ([`Motion::fit`]) taking each `.0` onto its `.1`, fitted on the pairs that agree
    /// with it: the pair left farthest beyond its placements (plus the slack, [`misfit`]) is
    /// dropped and the fit repeated, until every pair fits; none when fewer than `fewest`
    /// pairs are left.
    pub(super) fn consensus(mut pairs: Vec<(Placed, Placed)>, fewest: usize) -> Option<Motion> {
        loop {
            if pairs.len() < fewest {
                return None;
            }
            let motion = Motion::fit(&pairs);
            let excess = |&(p, q): &(Placed, Placed)| misfit(&motion, p, q);
            let worst = (0..pairs.len())
                .max_by(|&a, &b| excess(&pairs[a]).total_cmp(&excess(&pairs[b])))?;
            if excess(&pairs[worst]) <= 0.0 {
                return Some(motion);
            }
            pairs.swap_remove(worst);
        }
    }

    /// Which of `pairs` agree on one motion (each `.0` within placement tolerance of its `.1`,
    /// [`misfit`]): every motion taking one pair onto its partner and the direction to a
    /// second pair onto its partner's is tried, and the one most pairs agree with is refitted
    /// on those pairs ([`Motion::fit`]). Unlike [`Motion::consensus`] a pair that is off does
    /// not pull the fit: it never takes part in it. None when fewer than `fewest` pairs agree.
    pub(super) fn agreed(pairs: &[(Placed, Placed)], fewest: usize) -> Option<Vec<bool>> {
        let grown: Vec<GrownPair> = pairs.iter().map(GrownPair::new).collect();
        let agreeing = |motion: &Motion| -> Vec<bool> {
            grown
                .iter()
                .map(|pair| pair.separation(motion).within())
                .collect()
        };
        let count = |agree: &[bool]| agree.iter().filter(|&&a| a).count();
        let hypothesis = |(a, b): (usize, usize)| {
            Motion::from_pairs(
                [pairs[a].0.point, pairs[b].0.point],
                [pairs[a].1.point, pairs[b].1.point],
            )
        };
        // Hypotheses are counted without keeping their verdicts; of equal counts the last wins.
        let (_, chosen) = (0..pairs.len())
            .flat_map(|a| {
                (0..pairs.len())
                    .filter(move |&b| b != a)
                    .map(move |b| (a, b))
            })
            .map(|pair| {
                let motion = hypothesis(pair);
                let agreeing = grown
                    .iter()
                    .filter(|g| g.separation(&motion).within())
                    .count();
                (agreeing, pair)
            })
            .max_by_key(|&(agreeing, _)| agreeing)?;
        let best = agreeing(&hypothesis(chosen));
        if count(&best) < fewest {
            return None;
        }
        let fitted: Vec<(Placed, Placed)> = pairs
            .iter()
            .zip(&best)
            .filter(|(_, &a)| a)
            .map(|(pair, _)| *pair)
            .collect();
        let agree = agreeing(&Motion::fit(&fitted));
        (count(&agree) >= fewest).then_some(agree)
    }

    pub(super) fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        [
            self.cos * p[0] - self.sin * p[1] + self.shift[0],
            self.sin * p[0] + self.cos * p[1] + self.shift[1],
        ]
    }

    /// The inverse of [`Motion::apply`]: the point `q` of the frame in the station's
    /// coordinates (the offset from the shift rotated back).
    fn unapply(&self, q: [f64; 2]) -> [f64; 2] {
        let (dx, dy) = (q[0] - self.shift[0], q[1] - self.shift[1]);
        [
            self.cos * dx + self.sin * dy,
            -self.sin * dx + self.cos * dy,
        ]
    }
}

/// The look-alike correspondences of one registration, each placed detection with the list of
/// its look-alike landmarks: scoring a motion hypothesis ([`matches`]) is then a tight loop. A
/// registration tries hundreds of hypotheses against a few hundred correspondences each;
/// against every station of a run (`navigate`'s localization) that was most of a step.
struct Candidates {
    /// Detections with a placement and a look-alike in the frame.
    detections: Vec<Candidate>,
    /// Each detection's look-alike landmarks in turn, side by side so that the distance test
    /// runs over them without looking up the others.
    alike: Vec<LookAlike>,
    /// The frame's landmarks' placements grown by half the slack.
    grown: Vec<Matrix2<f64>>,
}

/// A look-alike landmark of a detection in [`Candidates`].
struct LookAlike {
    /// Its index into the frame's landmarks, its point and its grown placement's reach.
    landmark: usize,
    point: [f64; 2],
    reach: f64,
    /// How fast the bound on the pair's fit falls with the square of the distance between
    /// their points ([`fit_slope`]).
    fit_slope: f64,
}

/// One placed detection of [`Candidates`].
struct Candidate {
    /// Its index in the station, its point, its placement grown by half the slack and that
    /// grown placement's reach.
    detection: usize,
    point: [f64; 2],
    grown: Matrix2<f64>,
    reach: f64,
    /// Where its look-alikes lie in [`Candidates::alike`].
    alike: std::ops::Range<usize>,
    /// Its look-alikes' reach (both grown placements'), a little wide, around each: where it
    /// may lie to be one of them.
    reaches: DiscGrid,
}

impl Candidates {
    /// The table of `correspondences`, `(detection, index into the frame's landmarks)`,
    /// grouped by detection as [`register`] lists them.
    fn new(
        current: &[Option<Placed>],
        frame: &Frame,
        correspondences: &[(usize, usize)],
    ) -> Candidates {
        let half = 0.5 * SLACK_M;
        let grown: Vec<Matrix2<f64>> = frame.landmarks.iter().map(|(_, q)| q.grown(half)).collect();
        let mut detections: Vec<Candidate> = Vec::new();
        let mut alike = Vec::new();
        for &(i, j) in correspondences {
            if detections.last().is_none_or(|d| d.detection != i) {
                let p = current[i].expect("correspondences are placed");
                detections.push(Candidate {
                    detection: i,
                    point: p.point,
                    grown: p.grown(half),
                    reach: p.reach() + half,
                    alike: alike.len()..alike.len(),
                    reaches: DiscGrid::new(&[]),
                });
            }
            let q = frame.landmarks[j].1;
            let detection = detections.last_mut().expect("pushed above");
            let reach = q.reach() + half;
            alike.push(LookAlike {
                landmark: j,
                point: q.point,
                reach,
                fit_slope: fit_slope(
                    (detection.reach, detection.grown.trace()),
                    (reach, grown[j].trace()),
                ),
            });
            detection.alike.end = alike.len();
        }
        for detection in &mut detections {
            // Wider than the reach by far more than rounding, so that the grid never leaves
            // out a pair that [`in_reach`] takes.
            let reaches: Vec<([f64; 2], f64)> = alike[detection.alike.clone()]
                .iter()
                .map(|a| (a.point, (detection.reach + a.reach) * (1.0 + 1e-6)))
                .collect();
            detection.reaches = DiscGrid::new(&reaches);
        }
        Candidates {
            detections,
            alike,
            grown,
        }
    }

    /// The look-alikes of `candidate` that it may reach from `moved`, a few more than it
    /// does (under most motions a detection lands near few of its look-alikes, or none).
    fn near<'c>(
        &'c self,
        candidate: &'c Candidate,
        moved: [f64; 2],
    ) -> impl Iterator<Item = &'c LookAlike> {
        let listed = &self.alike[candidate.alike.clone()];
        candidate
            .reaches
            .near(moved)
            .iter()
            .map(move |&k| &listed[k])
    }
}

/// The squared distance from a detection moved to `moved`, its grown placement reaching
/// `reach`, to a look-alike, if it lies within reach of it: beyond both placements' reach the
/// pair is off whatever their shapes; most pairs are, and the test needs no ellipse.
fn in_reach(moved: [f64; 2], reach: f64, alike: &LookAlike) -> Option<f64> {
    let (dx, dy) = (moved[0] - alike.point[0], moved[1] - alike.point[1]);
    let bound = reach + alike.reach;
    let squared = dx * dx + dy * dy;
    (squared <= bound * bound * (1.0 + 1e-9)).then_some(squared)
}

/// How many detections `motion` brings within reach of one of their look-alikes: a bound on
/// how many it can pair one to one ([`matches`] tests the same pairs), and so on its inliers;
/// and the sum of each one's best fit bound over the look-alikes it reaches ([`fit_slope`]), a
/// bound on its score (one pair per detection, each fitting no better than its bound).
fn bounds(candidates: &Candidates, motion: &Motion) -> (usize, f64) {
    let (mut most, mut best) = (0, 0.0);
    for candidate in &candidates.detections {
        let moved = motion.apply(candidate.point);
        let mut fits: Option<f64> = None;
        for alike in candidates.near(candidate, moved) {
            if let Some(squared) = in_reach(moved, candidate.reach, alike) {
                let bound = 1.0 - squared * alike.fit_slope;
                fits = Some(fits.map_or(bound, |f| f.max(bound)));
            }
        }
        if let Some(fit) = fits {
            most += 1;
            best += fit.max(0.0);
        }
    }
    (most, best)
}

/// How fast a bound on the fit ([`Separation::fit`]) of two grown placements falls with the
/// squared distance between their points: the fit is at most `1 − slope · distance²`. From
/// each one's reach (its longest semi-axis) and trace: [`bound_of_sum`] weighs them `1 + 1/t`
/// and `1 + t`, `t` the square root of the ratio of the traces, so its ellipse's longest
/// semi-axis squared is at most the same weighing of the reaches squared (Weyl), and the
/// offset measured against that ellipse is at least the distance over that semi-axis.
/// (Turning a placement changes neither its reach nor its trace.)
fn fit_slope((reach_p, trace_p): (f64, f64), (reach_q, trace_q): (f64, f64)) -> f64 {
    let widest = if trace_p <= 0.0 {
        reach_q * reach_q
    } else if trace_q <= 0.0 {
        reach_p * reach_p
    } else {
        let t = (trace_p / trace_q).sqrt();
        (1.0 + 1.0 / t) * reach_p * reach_p + (1.0 + t) * reach_q * reach_q
    };
    // A little gentle, so that rounding never puts a fit above its bound.
    1.0 / (widest * (1.0 + 1e-6))
}

/// The one-to-one correspondences (nearest first, by [`Separation`] distance) that `motion`
/// brings within tolerance, and the fit score Σ (1 − (distance / gate)²).
fn matches(candidates: &Candidates, motion: &Motion) -> (Vec<(usize, usize)>, f64) {
    let mut close: Vec<(f64, usize, usize, f64)> = Vec::new();
    for candidate in &candidates.detections {
        let (i, grown, reach) = (candidate.detection, &candidate.grown, candidate.reach);
        let moved = motion.apply(candidate.point);
        let mut turned = None;
        for alike in candidates.near(candidate, moved) {
            if in_reach(moved, reach, alike).is_none() {
                continue;
            }
            let (j, point) = (alike.landmark, alike.point);
            let turned =
                *turned.get_or_insert_with(|| turned_shape(grown, [motion.cos, motion.sin]));
            let separation = separation_of(
                Vector2::new(moved[0] - point[0], moved[1] - point[1]),
                &bound_of_sum(&turned, &candidates.grown[j]),
            );
            if separation.within() {
                close.push((separation.distance, i, j, separation.fit()));
            }
        }
    }
    // Ties in (detection, landmark) order, whatever order the look-alikes are listed in.
    close.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut used_i = Vec::new();
    let mut used_j = Vec::new();
    let mut out = Vec::new();
    let mut score = 0.0;
    for (_, i, j, fit) in close {
        if !used_i.contains(&i) && !used_j.contains(&j) {
            used_i.push(i);
            used_j.push(j);
            out.push((i, j));
            score += fit;
        }
    }
    (out, score)
}

/// The unit vector from `a` towards `b` (zero when they coincide).
fn unit(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let d = distance(a, b);
    if d > 0.0 {
        [(b[0] - a[0]) / d, (b[1] - a[1]) / d]
    } else {
        [0.0, 0.0]
    }
}

pub(super) fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::association::placement::separation;

    /// Six rocks around a station, metres apart (also the association tests' field).
    pub(in crate::association) const FIELD: [[f64; 2]; 6] = [
        [3.0, 1.0],
        [5.0, -2.0],
        [-4.0, 6.0],
        [0.5, -7.0],
        [8.0, 8.0],
        [-6.0, -3.0],
    ];

    /// FIELD's six rocks as a frame, landmarks 0‥5.
    fn field_frame() -> Frame {
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: FIELD
                .iter()
                .enumerate()
                .map(|(k, &point)| (k as LandmarkId, Placed::disc(point, 0.3)))
                .collect(),
        }
    }

    /// The null model counts the landmarks a detection looks like: with every detection alike
    /// to every landmark, chance hits land at the landmarks' density; with each alike to two
    /// of the six, at a third of it, and the same tight fit is the less likely by chance.
    #[test]
    fn chance_hits_only_landmarks_a_detection_looks_like() {
        let frame = field_frame();
        let all: Vec<(usize, usize)> = (0..6).flat_map(|i| (0..6).map(move |j| (i, j))).collect();
        let two: Vec<(usize, usize)> = (0..6).flat_map(|i| [(i, i), (i, (i + 1) % 6)]).collect();
        let (every, some) = (chance(&frame, 12, &all), chance(&frame, 12, &two));
        assert_eq!(every.detections, some.detections);
        assert!((some.density - every.density / 3.0).abs() < 1e-12);
        let residuals = [0.2, 0.25, 0.3, 0.3, 0.35];
        assert!(some.nfa(&residuals, MIN_INLIERS).0 < every.nfa(&residuals, MIN_INLIERS).0);
    }

    /// Detections 0‥3 paired with landmarks 0‥3, with no motion.
    fn first_four_in_place() -> Registration {
        Registration {
            pairs: (0..4).map(|k| (k, k as LandmarkId)).collect(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        }
    }

    /// Under a registration of detections 0‥3 with landmarks 0‥3 (no motion), observers are
    /// paired with the landmark they lie clearly nearest to: detection 4 with landmark 4, and
    /// not detection 5, which lies as near landmark 5 as the undoubted detection 6 beside it,
    /// nor detection 7, where landmark 0 lies, already paired. An observer that does not look
    /// like the landmark is paired with none.
    #[test]
    fn observers_are_paired_under_the_motion_the_others_found() {
        let frame = field_frame();
        let registration = first_four_in_place();
        let mut points: Vec<[f64; 2]> = FIELD[..4].to_vec();
        points.extend([[8.1, 8.0], [-6.0, -3.2], [-6.0, -2.8], [3.0, 1.1]]);
        let placed: Vec<Option<Placed>> =
            points.iter().map(|&p| Some(Placed::disc(p, 0.3))).collect();
        let paired = |alike: &dyn Fn(usize, LandmarkId) -> bool| {
            let mut r = registration.clone();
            r.pair_observers(&frame, &placed, &[4, 5, 7], alike);
            r.pairs[4..].to_vec()
        };
        assert_eq!(paired(&|_, _| true), [(4, 4)]);
        assert_eq!(paired(&|i, _| i != 4), []);
    }

    /// A pair is dropped when another placed detection that looks like its landmark, an
    /// observer the fit never saw, lies as near the landmark; one that looks otherwise, or
    /// lies clearly farther, leaves it.
    #[test]
    fn a_pair_an_observer_lies_as_near_is_dropped() {
        let frame = field_frame();
        let registration = first_four_in_place();
        let kept = |observer: [f64; 2], alike: &dyn Fn(usize, LandmarkId) -> bool| {
            let mut placed: Vec<Option<Placed>> = FIELD[..4]
                .iter()
                .map(|&p| Some(Placed::disc(p, 0.3)))
                .collect();
            placed.push(Some(Placed::disc(observer, 0.3)));
            let mut r = registration.clone();
            r.drop_ambiguous_pairs(&frame, &placed, alike);
            r.pairs
        };
        let all: Vec<(usize, LandmarkId)> = (0..4).map(|k| (k, k as LandmarkId)).collect();
        assert_eq!(kept([3.2, 1.1], &|_, _| true), all[1..]);
        assert_eq!(kept([3.2, 1.1], &|i, _| i != 4), all);
        assert_eq!(kept([4.5, 2.5], &|_, _| true), all);
    }

    /// Two touching rocks, each with its landmark (6 and 7, 0.9 m apart): the piece of rock 7
    /// is placed along its neighbour's columns too, so it lies as near landmark 6 as rock 6's
    /// own detection does. Decided alone, rock 6's pair is ambiguous; rock 7's detection is
    /// explained by its own unambiguous pair with landmark 7, so both pairs stand. Unpaired,
    /// nothing explains it, and rock 6's pair stays ambiguous.
    #[test]
    fn a_neighbour_paired_with_its_own_landmark_is_no_rival() {
        let mut points: Vec<Placed> = FIELD.iter().map(|&p| Placed::disc(p, 0.3)).collect();
        points.push(Placed::disc([2.15, 4.0], 0.1));
        points.push(Placed::along([2.9, 4.0], 0.0, 0.9, 0.1));
        let current: Vec<Option<Placed>> = points.into_iter().map(Some).collect();
        let mut frame = field_frame();
        frame.landmarks.push((6, Placed::disc([2.0, 4.0], 0.1)));
        frame.landmarks.push((7, Placed::disc([2.9, 4.0], 0.1)));
        let inliers: Vec<(usize, usize)> = (0..8).map(|k| (k, k)).collect();
        let motion = Motion::identity();
        assert!(!unambiguous_pair(&motion, &current, &frame, 6, 6, |_| true));
        assert!(unambiguous_pair(&motion, &current, &frame, 7, 7, |_| true));
        let pairs = unambiguous(&current, &frame, &inliers).1;
        assert!(pairs.contains(&(6, 6)) && pairs.contains(&(7, 7)));
        let unexplained = |k| !explained(&motion, &current, &frame, &[], k, 6);
        assert!(!unambiguous_pair(
            &motion,
            &current,
            &frame,
            6,
            6,
            unexplained
        ));
    }

    /// By luminance (`fragmented`), an unmapped rock within the paired landmark's own
    /// placement is taken for a piece of its rock and crowds nothing; in colour it crowds, as
    /// does one beside the landmark, and another landmark, unless another detection of the
    /// station lies nearer to it.
    #[test]
    fn an_unmapped_rock_within_the_landmark_crowds_only_in_colour() {
        let identity = Registration {
            pairs: vec![(0, 0)],
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let p = Placed::along([10.0, 0.0], 0.0, 3.0, 0.1);
        let frame = |unmapped: [f64; 2], other: [f64; 2]| Frame {
            accumulated: true,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: vec![Placed::disc(unmapped, 0.3)],
            landmarks: vec![
                (0, Placed::disc([10.0, 0.0], 0.3)),
                (1, Placed::disc(other, 0.3)),
            ],
        };
        let crowded = |f: &Frame, fragmented: bool, others: &[Placed]| {
            identity.crowded(f, &p, 0, others, fragmented)
        };
        let within = frame([10.2, 0.0], [30.0, 0.0]);
        assert!(!crowded(&within, true, &[]));
        assert!(crowded(&within, false, &[]));
        let beside = frame([11.5, 0.0], [30.0, 0.0]);
        assert!(crowded(&beside, true, &[]));
        let landmark = frame([30.0, 0.0], [11.5, 0.0]);
        assert!(crowded(&landmark, true, &[]));
        assert!(!crowded(&landmark, true, &[Placed::disc([11.6, 0.0], 0.3)]));
    }

    /// FIELD seen from a station at `at`, turned by `turn`: each rock in that station's frame,
    /// moved by `error` metres in a direction that changes from rock to rock.
    fn seen_from(at: [f64; 2], turn: f64, error: f64) -> Frame {
        let (sin, cos) = turn.sin_cos();
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: FIELD
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let (x, y) = (p[0] - at[0], p[1] - at[1]);
                    let off = 2.4 * k as f64;
                    let point = [
                        cos * x + sin * y + error * off.cos(),
                        -sin * x + cos * y + error * off.sin(),
                    ];
                    (k as LandmarkId, Placed::disc(point, 0.3))
                })
                .collect(),
        }
    }

    #[test]
    fn the_displacement_between_two_stations_is_the_later_ones_heading_from_the_earlier() {
        let earlier = field_frame();
        // The later station is 2 m out at 30° from the earlier one, turned by 1 rad.
        let heading = 30f64.to_radians();
        let at = [2.0 * heading.cos(), 2.0 * heading.sin()];
        let (angle, sd) = displacement(&earlier, &seen_from(at, 1.0, 0.0)).expect("six shared");
        assert!(
            (angle - heading).abs() < 1e-9 && sd < 1e-9,
            "{angle} ± {sd}"
        );
        // Placements 5 cm off: the heading is off by about its s.d., which is small.
        let (angle, sd) = displacement(&earlier, &seen_from(at, 1.0, 0.05)).expect("six shared");
        assert!((angle - heading).abs() < 3.0 * sd, "{angle} ± {sd}");
        assert!(sd > 0.001 && sd < 0.05, "{sd}");
        // A move within the placements' noise has no heading; too few shared landmarks, none.
        assert!(displacement(&earlier, &seen_from([0.01, 0.0], 1.0, 0.05)).is_none());
        let mut few = seen_from(at, 1.0, 0.0);
        few.landmarks.truncate(MIN_INLIERS - 1);
        assert!(displacement(&earlier, &few).is_none());
    }

    /// A fixed pseudo-random sequence, uniform over [0, 1), from `seed` (a linear congruential
    /// generator: the tests' fields are the same on every machine).
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A field of 16 rocks, every other one a grid of rocks 3 m apart (a motion one step off
    /// pairs nearly as many, and the margin decides), and a station that sees the first
    /// `shared` of them (returned), each a random distance off, from 3 m away at a random
    /// turn, and ten other rocks.
    fn trial_scene(
        next: &mut impl FnMut() -> f64,
        trial: usize,
    ) -> (Frame, Vec<Option<Placed>>, usize) {
        let rocks: Vec<[f64; 2]> = (0..16)
            .map(|k| match trial % 2 {
                0 => [20.0 * (next() - 0.5), 20.0 * (next() - 0.5)],
                _ => [
                    3.0 * (k % 4) as f64 + 0.05 * next(),
                    3.0 * (k / 4) as f64 + 0.05 * next(),
                ],
            })
            .collect();
        let frame = Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: rocks
                .iter()
                .enumerate()
                .map(|(k, &p)| {
                    (
                        k as LandmarkId,
                        Placed::along(p, 6.3 * next(), 0.2 + next(), 0.1),
                    )
                })
                .collect(),
        };
        let (shared, error, angle) = (2 + trial % 8, next() * next(), 6.3 * next());
        let (sin, cos) = angle.sin_cos();
        let mut current: Vec<Option<Placed>> = Vec::new();
        let others = std::iter::repeat_n(None, 10);
        for seen in rocks[..shared].iter().map(Some).chain(others) {
            let [x, y] = match seen {
                Some(p) => [
                    p[0] - 3.0 + error * (next() - 0.5),
                    p[1] + error * (next() - 0.5),
                ],
                None => [20.0 * (next() - 0.5), 20.0 * (next() - 0.5)],
            };
            let point = [cos * x + sin * y, -sin * x + cos * y];
            current.push(Some(Placed::along(point, 6.3 * next(), 0.2 + next(), 0.1)));
        }
        (frame, current, shared)
    }

    /// Whether landmark `l` looks like detection `i` in [`trial_scene`]: its own rock's, and
    /// one in four others.
    fn trial_alike(shared: usize) -> impl Fn(usize, LandmarkId) -> bool {
        move |i, l| i % shared == l as usize || (i + 3 * l as usize) % 4 == 0
    }

    /// [`decisive`], scoring only the hypotheses whose bound comes within the margin of the best
    /// score, decides as scoring every one does: on fields scattered and on grids, sharing a
    /// few to most rocks with the frame, placed a little to far off, among look-alikes (a
    /// fixed pseudo-random sequence). Every bound holds its hypothesis' inliers and score, so
    /// those `significant` leaves unscored have too few inliers. (Skipping hypotheses whose
    /// bound is half a point higher than this allows fails the test.)
    #[test]
    fn deciding_on_bounds_decides_as_scoring_every_hypothesis() {
        let mut next = uniform(11);
        let (mut decided, mut undecided, mut unscored) = (0, 0, 0);
        for trial in 0..300 {
            let (frame, current, shared) = trial_scene(&mut next, trial);
            let alike = trial_alike(shared);
            let all: Vec<(usize, usize)> = (0..current.len())
                .flat_map(|i| (0..frame.landmarks.len()).map(move |j| (i, j)))
                .filter(|&(i, j)| alike(i, j as LandmarkId))
                .collect();
            let candidates = Candidates::new(&current, &frame, &all);
            let mut every = hypotheses(&current, &frame, &all, seed_pairs(all.len()), &candidates);
            let fits: Vec<&Fit> = every.iter_mut().map(|h| h.scored(&candidates)).collect();
            let best = fits.iter().max_by(|a, b| a.score.total_cmp(&b.score));
            let expected = best.and_then(|best| {
                let runner_up = fits
                    .iter()
                    .filter(|h| !same_assignment(&h.inliers, &best.inliers))
                    .map(|h| h.score)
                    .fold(0.0, f64::max);
                (best.inliers.len() >= MIN_INLIERS && best.score >= runner_up + MARGIN)
                    .then(|| best.inliers.clone())
            });
            for h in &every {
                let fit = h.fit.as_ref().expect("scored");
                assert!(fit.inliers.len() <= h.most && fit.score <= h.best);
            }
            let mut bounded =
                hypotheses(&current, &frame, &all, seed_pairs(all.len()), &candidates);
            let tried: Vec<usize> = (0..bounded.len()).collect();
            assert_eq!(
                decisive(&mut bounded, &tried, &candidates),
                expected,
                "trial {trial}"
            );
            decided += expected.is_some() as usize;
            undecided += expected.is_none() as usize;
            unscored += bounded.iter().filter(|h| h.fit.is_none()).count();
        }
        assert!(
            decided > 10 && undecided > 10,
            "{decided} decided, {undecided} not"
        );
        assert!(unscored > 1000, "{unscored} hypotheses left unscored");
    }

    /// Seed sets tried in turn, the hypotheses they share scored once, register as each set
    /// tried alone in turn does: a narrow set then a wider one holding it (as `associate`
    /// tries them), and two sets that only partly overlap.
    #[test]
    fn seed_sets_tried_together_register_as_each_tried_alone() {
        let mut next = uniform(23);
        let (mut by_first, mut by_second) = (0, 0);
        for trial in 0..300 {
            let (frame, current, shared) = trial_scene(&mut next, trial);
            let alike = trial_alike(shared);
            // In one scattered field in two the narrow set holds no true pair, and registers
            // nothing or by chance; `other` overlaps it only in part.
            let narrow = |i: usize, l: LandmarkId| {
                alike(i, l) && (trial % 4 != 0 || (i + l as usize) % 2 == 1)
            };
            let other = |i: usize, l: LandmarkId| alike(i, l) && (i + l as usize) % 3 != 1;
            let sets: [[&dyn Fn(usize, LandmarkId) -> bool; 2]; 2] =
                [[&narrow, &alike], [&narrow, &other]];
            for sets in sets {
                let first = register(&current, &frame, &alike, &sets[..1]);
                let alone = first
                    .clone()
                    .or_else(|| register(&current, &frame, &alike, &sets[1..]));
                assert_eq!(
                    register(&current, &frame, &alike, &sets),
                    alone,
                    "trial {trial}"
                );
                by_first += first.is_some() as usize;
                by_second += (first.is_none() && alone.is_some()) as usize;
            }
        }
        assert!(
            by_first > 50 && by_second > 30,
            "{by_first} registered by the first set, {by_second} by the second"
        );
    }

    /// The table-driven [`matches`] keeps exactly the pairs, in the order, that testing every
    /// correspondence with the exact distance keeps: many placements (from a fixed
    /// pseudo-random sequence), some look-alikes, motions of every size.
    #[test]
    fn matches_from_the_table_are_those_of_every_correspondence_tested() {
        let mut next = uniform(7);
        // Discs and ellipses of every direction, some long and thin as far rocks' are.
        let mut place = |spread: f64| {
            let point = [spread * (next() - 0.5), spread * (next() - 0.5)];
            if next() < 0.3 {
                Placed::disc(point, 0.1 + next())
            } else {
                Placed::along(point, 6.3 * next(), 0.1 + 2.0 * next(), 0.02 + 0.2 * next())
            }
        };
        let frame = Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: (0..20).map(|k| (k as LandmarkId, place(12.0))).collect(),
        };
        let current: Vec<Option<Placed>> =
            (0..30).map(|i| (i % 7 != 3).then(|| place(12.0))).collect();
        let correspondences: Vec<(usize, usize)> = (0..current.len())
            .filter(|&i| current[i].is_some())
            .flat_map(|i| (0..frame.landmarks.len()).map(move |j| (i, j)))
            .filter(|&(i, j)| (i + 2 * j) % 3 != 0)
            .collect();
        let candidates = Candidates::new(&current, &frame, &correspondences);
        let reference = |motion: &Motion| {
            let mut close: Vec<(f64, usize, usize)> = correspondences
                .iter()
                .filter_map(|&(i, j)| {
                    let (p, q) = (current[i].unwrap(), frame.landmarks[j].1);
                    let separation = separation(&motion.apply_placed(&p), &q, SLACK_M);
                    separation.within().then_some((separation.distance, i, j))
                })
                .collect();
            close.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (mut used_i, mut used_j, mut out) = (Vec::new(), Vec::new(), Vec::new());
            for (_, i, j) in close {
                if !used_i.contains(&i) && !used_j.contains(&j) {
                    used_i.push(i);
                    used_j.push(j);
                    out.push((i, j));
                }
            }
            out
        };
        let mut paired = 0;
        for k in 0..50 {
            let angle = 0.4 * k as f64;
            let motion = Motion {
                cos: angle.cos(),
                sin: angle.sin(),
                shift: [0.3 * (k % 5) as f64, -0.2 * (k % 3) as f64],
            };
            let (pairs, score) = matches(&candidates, &motion);
            assert_eq!(pairs, reference(&motion), "motion {k}");
            assert!(score >= 0.0 && score <= pairs.len() as f64);
            paired += pairs.len();
        }
        assert!(paired > 200, "{paired} pairs: the comparison is not empty");
    }

    #[test]
    fn unseen_counts_unpaired_landmarks_in_view_where_nothing_was_detected() {
        let frame = field_frame();
        // Identity motion pairing rocks 0‥2; the station detected rocks 0‥3 and nothing else.
        let registration = Registration {
            pairs: vec![(0, 0), (1, 1), (2, 2)],
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let bearing = |p: [f64; 2]| p[1].atan2(p[0]);
        let ray = |azimuth: f64| Ray {
            azimuth,
            half_baseline: 0.0,
            nearest: 0.0,
            half_width: 0.0,
        };
        let detected: Vec<Ray> = FIELD[..4].iter().map(|&p| ray(bearing(p))).collect();
        // Rock 3 was detected (unpaired, but seen); rocks 4 (11.3 m) and 5 (6.7 m) were not.
        assert_eq!(registration.unseen(&frame, &detected, 20.0), 2);
        // Beyond the station's reach an absence says nothing.
        assert_eq!(registration.unseen(&frame, &detected, 10.0), 1);
        assert_eq!(registration.unseen(&frame, &detected, 5.0), 0);
        // A detection within a few degrees of rock 5's direction may be it.
        let near_five = [detected.clone(), vec![ray(bearing(FIELD[5]) + 0.04)]].concat();
        assert_eq!(registration.unseen(&frame, &near_five, 20.0), 1);
    }

    #[test]
    fn recovers_who_is_who_after_a_rigid_motion() {
        let field = FIELD;
        let (angle, shift) = (0.7f64, [1.5, -0.8]);
        let frame = Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: field
                .iter()
                .enumerate()
                .map(|(k, p)| (k as LandmarkId + 10, Placed::disc(*p, 0.2)))
                .collect(),
        };
        // The current station sees the landmarks in a shuffled order, moved by the inverse.
        let order = [4usize, 0, 5, 2, 1, 3];
        let current: Vec<Option<Placed>> = order
            .iter()
            .map(|&k| {
                let q = field[k];
                let (x, y) = (q[0] - shift[0], q[1] - shift[1]);
                let (s, c) = (-angle).sin_cos();
                Some(Placed::disc([c * x - s * y, s * x + c * y], 0.2))
            })
            .collect();
        let registration =
            register(&current, &frame, &|_, _| true, &[&|_, _| true]).expect("registers");
        let mut pairs = registration.pairs.clone();
        pairs.sort_unstable();
        let expected: Vec<(usize, LandmarkId)> = order
            .iter()
            .enumerate()
            .map(|(i, &k)| (i, k as LandmarkId + 10))
            .collect();
        assert_eq!(pairs, expected);
    }

    #[test]
    fn a_loosely_placed_detection_is_not_paired() {
        // The field without motion, one more detection placed within 5 m (a far rock's range
        // interval) around where landmark 16 lies: it helps no motion and pairs with nothing,
        // though landmark 16 is the only one near. (Placed within 2–4 m, it would pair, and
        // anchor only on the terms of `super::long_anchor`.)
        let place = Placed::disc;
        let frame = Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: FIELD
                .iter()
                .chain(&[[12.0, -12.0]])
                .enumerate()
                .map(|(k, &p)| (k as LandmarkId + 10, place(p, 0.2)))
                .collect(),
        };
        let mut current: Vec<Option<Placed>> = FIELD.iter().map(|&p| Some(place(p, 0.2))).collect();
        current.push(Some(place([13.5, -13.0], 5.0)));
        let registration =
            register(&current, &frame, &|_, _| true, &[&|_, _| true]).expect("registers");
        let mut pairs = registration.pairs.clone();
        pairs.sort_unstable();
        let expected: Vec<(usize, LandmarkId)> =
            (0..6).map(|i| (i, i as LandmarkId + 10)).collect();
        assert_eq!(pairs, expected);
    }

    #[test]
    fn a_pair_whose_landmark_lies_towards_an_unplaced_detection_is_dropped() {
        // Identity motion. Detection 0 is placed 0.6 m to the left of landmark 10, and an
        // unplaced detection looks straight at it: the landmark may be that rock. Detection 1
        // is where landmark 11 lies, nearer in direction than any unplaced detection.
        let place = |point: [f64; 2]| Placed::disc(point, 0.2);
        let frame = Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: vec![(10, place([3.0, 1.0])), (11, place([5.0, -2.0]))],
        };
        let placed = [Some(place([3.0, 1.6])), Some(place([5.0, -2.0]))];
        let mut registration = Registration {
            pairs: vec![(0, 10), (1, 11)],
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let ray = |azimuth: f64| Ray {
            azimuth,
            half_baseline: 0.0,
            nearest: 0.0,
            half_width: 0.0,
        };
        let own = [ray(1.6f64.atan2(3.0)), ray((-2f64).atan2(5.0))];
        let pairs = registration.pairs.clone();
        registration.drop_pairs_seen_elsewhere(
            &frame,
            &placed,
            &own,
            &[ray(1f64.atan2(3.0)), ray(2.0)],
        );
        assert_eq!(registration.pairs, vec![(1, 11)]);
        // The left eye alone, half a 0.3 m baseline beside the centre, saw the same rock
        // asin(0.15 / 3.16) = 2.7° short of the centre's bearing: along its ray the landmark is
        // where it looked, though the middle of an unranged bearing interval is 45° further on.
        let left_eye = Ray {
            azimuth: 1f64.atan2(3.0) - (0.15 / 10f64.sqrt()).asin(),
            half_baseline: 0.15,
            nearest: 0.0,
            half_width: 0.0,
        };
        let middle = left_eye.azimuth + std::f64::consts::FRAC_PI_4;
        registration.pairs = pairs.clone();
        registration.drop_pairs_seen_elsewhere(&frame, &placed, &own, &[ray(middle), ray(2.0)]);
        assert_eq!(registration.pairs, pairs, "seen 45° away, it says nothing");
        registration.drop_pairs_seen_elsewhere(&frame, &placed, &own, &[left_eye, ray(2.0)]);
        assert_eq!(registration.pairs, vec![(1, 11)]);
        // Seen straight at landmark 10 (3.16 m away, placed within 0.2 m) by a detection that
        // lies at least `nearest` metres away: beyond the landmark and the slack, it is
        // another rock behind; within them, it may be the landmark's.
        for (nearest, kept) in [(3.7, true), (3.6, false)] {
            let behind = Ray {
                nearest,
                ..ray(1f64.atan2(3.0))
            };
            registration.pairs = pairs.clone();
            registration.drop_pairs_seen_elsewhere(&frame, &placed, &own, &[behind, ray(2.0)]);
            assert_eq!(registration.pairs == pairs, kept, "nearest {nearest}");
        }
        // A blob whose centre lies farther round than detection 0's (0.2 rad from landmark 10
        // against 0.17) but whose span reaches within 0.1 rad of it, while detection 0's blob
        // ends 0.17 rad away: the landmark may be that blob's rock. Once detection 0's own blob
        // spans to within 0.07 rad, or over the landmark, its pair stands.
        let wide = Ray {
            half_width: 0.1,
            ..ray(1f64.atan2(3.0) - 0.2)
        };
        let spanning = |half_width: f64| {
            [
                Ray {
                    half_width,
                    ..own[0]
                },
                own[1],
            ]
        };
        for (own, kept) in [(own, false), (spanning(0.1), true), (spanning(0.2), true)] {
            registration.pairs = pairs.clone();
            registration.drop_pairs_seen_elsewhere(&frame, &placed, &own, &[wide, ray(2.0)]);
            assert_eq!(
                registration.pairs == pairs,
                kept,
                "own half width {}",
                own[0].half_width
            );
        }
    }

    /// The frame's six landmarks, and a station that shares four of them, placed `error`
    /// metres off in turn each way, among six look-alike detections elsewhere; every placement
    /// within a metre.
    fn few_shared(error: f64) -> (Frame, Vec<Option<Placed>>) {
        let place = |point: [f64; 2]| Placed::disc(point, 1.0);
        let frame = Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: FIELD
                .iter()
                .enumerate()
                .map(|(k, &p)| (k as LandmarkId, place(p)))
                .collect(),
        };
        let (s, c) = 0.4f64.sin_cos();
        let back = |p: [f64; 2]| [c * p[0] + s * p[1] - 2.0, -s * p[0] + c * p[1] + 1.0];
        let offsets = [[error, 0.0], [0.0, error], [-error, 0.0], [0.0, -error]];
        let shared = FIELD[..4]
            .iter()
            .zip(offsets)
            .map(|(p, o)| back([p[0] + o[0], p[1] + o[1]]));
        let elsewhere = [
            [-11.0, 4.0],
            [12.0, -3.0],
            [-2.0, 13.0],
            [9.5, 11.0],
            [-9.0, -10.0],
            [2.0, -12.5],
        ];
        let current = shared.chain(elsewhere).map(|p| Some(place(p))).collect();
        (frame, current)
    }

    /// Where every rock looks alike and few are shared, a true motion's centimetre-tight pairs
    /// score too little above chance fits for the margin, but chance does not explain them.
    #[test]
    fn a_tight_fit_of_few_shared_rocks_registers_though_the_margin_turns_it_down() {
        let (frame, current) = few_shared(0.03);
        let alike = |_: usize, _: LandmarkId| true;
        let all: Vec<(usize, usize)> = (0..current.len())
            .flat_map(|i| (0..frame.landmarks.len()).map(move |j| (i, j)))
            .collect();
        let candidates = Candidates::new(&current, &frame, &all);
        let mut every = hypotheses(&current, &frame, &all, seed_pairs(all.len()), &candidates);
        let tried: Vec<usize> = (0..every.len()).collect();
        assert!(decisive(&mut every, &tried, &candidates).is_none());
        let registration = register(&current, &frame, &alike, &[&alike]).expect("registers");
        let mut pairs = registration.pairs;
        pairs.sort_unstable();
        assert_eq!(pairs, [(0, 0), (1, 1), (2, 2), (3, 3)]);
    }

    /// The same four pairs half a metre off, well within their placements, are what chance
    /// gives among so many look-alikes: nothing registers.
    #[test]
    fn a_loose_fit_of_few_shared_rocks_registers_nothing() {
        let (frame, current) = few_shared(0.5);
        let all: Vec<(usize, usize)> = (0..current.len())
            .flat_map(|i| (0..frame.landmarks.len()).map(move |j| (i, j)))
            .collect();
        let truth = [(0, 0), (1, 1), (2, 2), (3, 3)];
        let candidates = Candidates::new(&current, &frame, &all);
        assert!(
            hypotheses(&current, &frame, &all, seed_pairs(all.len()), &candidates)
                .iter_mut()
                .map(|h| h.scored(&candidates))
                .any(|h| h.inliers.len() >= MIN_INLIERS && same_assignment(&h.inliers, &truth))
        );
        let alike = |_: usize, _: LandmarkId| true;
        assert_eq!(register(&current, &frame, &alike, &[&alike]), None);
    }

    #[test]
    fn too_few_correspondences_register_nothing() {
        let frame = Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: vec![(1, Placed::disc([1.0, 1.0], 0.1))],
        };
        let current = vec![Some(Placed::disc([1.0, 1.0], 0.1))];
        assert_eq!(
            register(&current, &frame, &|_, _| true, &[&|_, _| true]),
            None
        );
    }
}
