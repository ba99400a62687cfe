//! Data association (000 §VI-C): which map landmark, if any, each detection of a station is.
//!
//! Appearance proposes, the qualitative map decides:
//! 1. the [`Gallery`] proposes, for each detection, the landmarks whose descriptor and
//!    physical width are close enough;
//! 2. **anchors** are the unambiguous correspondences of the rigid motion that best lines up
//!    the station's look-alike detections with a recent station's landmarks, or with the
//!    [`Sketch`] of all recently seen landmarks ([`register`]); a frame no motion registers
//!    is tried again with the look-alikes of colour alone, which a rock keeps when seen from
//!    another side; the motion also rules out the frame's landmarks that lie away from a detection. A
//!    registration of the fewest pairs that puts several of the frame's other landmarks in
//!    view where the station saw nothing is a chance fit and is dropped, and so is one that
//!    holds no landmark the rover saw lately ([`LastSeen`]: a loop closure on looks alone). A
//!    detection placed looser than 4 m pairs with nothing, and a pair whose landmark lies in
//!    the direction of a detection mapping does not use is dropped (it may be that rock). An
//!    anchor must be paired so by most registered frames that hold its landmark; one placed
//!    looser than 2 m (a far rock) by every one, two at least, where none knows another rock
//!    it may be ([`Registration::crowded`]); no pair anchors that only fits chance may explain
//!    make while a significant fit holding its landmark leaves it out ([`overruled`]). A
//!    detection the detector doubts ([`Evidence::doubtful`]) takes no part in the fit: each
//!    registration pairs it afterwards under its motion ([`Registration::pair_observers`]),
//!    and it anchors only as a far rock does, or, by luminance and placed within 2 m, on the
//!    sketch's pairing alone where no station's frame holds the landmark. Anchors are checked
//!    against each other: a triple of anchors whose measured states do not overlap the map's
//!    is inconsistent, and the anchor in most such triples is dropped until none is left.
//!    Matches are then checked against earlier stations' placements of their landmarks
//!    ([`agreement`], applied by the caller, which keeps the stations' history);
//! 3. every other proposal is tested as 000 §VI-C describes: the detection's triples with
//!    pairs of anchors are measured and compared with the candidate landmark's relations in
//!    the map; a candidate with an empty overlap in any relation is rejected;
//! 4. no candidate left → a new landmark, unless the motion places the detection where a
//!    landmark lies that no detection is anchored to (likely a piece or a lit face of that
//!    rock), which then becomes its candidate. With candidates, the observation is **held
//!    back** and tried again when the map is tighter, where it becomes a new landmark once
//!    every candidate has been rejected. Nothing is fused on a guess.
//!
//! Why a lone surviving candidate is not matched at once: a rejection is sound evidence (the
//! map and the measurement exclude each other), a pass is not, since a loose map lets most
//! look-alikes pass. On sixteen-station half-resolution marsyard and random surveys (`pipeline
//! synth --scale 0.5 --stations 16`, seeds 1–6) lone survivors matched on a pass were wrong
//! in 19 of 54 cases and retried held-back observations in 33 of 58 (and still wrong when
//! matched by elimination of the other candidates), against 30 of about 2300 for registration
//! anchors; the wrong ones made 8 of those 12 maps unsound.

pub mod agreement;
pub mod audit;
mod disc_grid;
pub mod duplicate;
mod gallery;
mod placement;
mod recency;
mod recognition;
mod registration;
mod significance;
pub mod sketch;
#[cfg(test)]
pub(crate) mod test_drive;

use gallery::chromaticity_distance;
pub use gallery::{distance, AppearanceScales, Gallery, Profile};
pub use placement::Placed;
pub use recency::LastSeen;
pub use recognition::{read_unmapped, Recognition, UnmappedReading};
pub use registration::{displacement, register, Frame, Registration, Tracked};
use registration::{ANCHOR_RADIUS_M, LONG_ANCHOR_RADIUS_M, MIN_INLIERS, SIGNIFICANT_NFA};
pub use sketch::Sketch;

use crate::detection::Appearance;
use crate::ranging::{RangeInterval, Ray};
use qrm_core::calculus::Calculus;
use qrm_core::map::{Hypergraph, LandmarkId, Sighting};
use qrm_core::measurement::StationView;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Closest look-alike landmarks per detection that seed registration hypotheses.
const REGISTRATION_SEEDS: usize = 6;

/// A station's only registration is dropped when this many other frames could have confirmed
/// it and did not, unless its fit is significant ([`SIGNIFICANT_NFA`]). In the three such cases
/// seen on half-resolution surveys (two stations of marsyard seed 3, one of random seed 5 under
/// an earlier detector, before fits were judged by their NFA), 7–8 look-alike pairs fit one
/// frame by chance while the other five failed to register, and every pair was wrong. Over 38
/// sets at stop 54 the rule dropped 22 registrations: the 14 significant ones paired 130 of 131
/// detections with their own rocks' landmarks (grayscale marsyard seed 3, stations 28–30: 38
/// of 38); of the 8 others (NFA 0.02–0.8) two made wrong pairs (stress seed 9, station 48: 3
/// of 7; stress seed 6, station 30: 1 of 6).
const SILENT_FRAMES: usize = 3;

/// A registration of the fewest pairs that puts this many of the frame's other landmarks in
/// view, in directions where the station detected nothing, is a chance fit and is dropped
/// ([`Registration::unseen`]). On `sparse-large` seeds 3 and 4, the registrations that mixed
/// landmarks were such fits of 4 look-alike pairs after the rover entered new ground (seed 4,
/// station 108: a 91° turn in 4 stations, 2 landmarks unseen of 5 in view; seed 3: 7 of 10).
/// A true registration can miss as many (the 1024 × 192 demo set: 4 of 6 within 15 m, where
/// small rocks go undetected), but with more pairs: of the registrations of those runs and of
/// half-resolution marsyard seed 3 that missed 2 or more, every true one had at least 5.
const MIN_UNSEEN: usize = 2;

/// Fewest pairs of a station's only registration that is believed on its margin over the other
/// hypotheses alone; with fewer, its fit must also be significant ([`Registration::nfa`]).
const LONE_PAIRS: usize = 6;

/// Slack of the placement test against a registered frame, metres: generous, since ruling
/// out the true landmark would make a duplicate.
const PLACEMENT_SLACK_M: f64 = 1.0;

/// Slack of the placement test against the sketch, metres. The sketch's averaged positions
/// are tighter than a detection's placement is right (a range interval's middle is not the
/// rock's centre): at [`PLACEMENT_SLACK_M`] it ruled out known rocks and made new landmarks
/// of them (random seed 5: 7 → 11 rocks duplicated).
const SKETCH_SLACK_M: f64 = 3.0;

/// Drift of the sketch, as a share of the distance from the station to a departed landmark's
/// last position: generous, since ruling out the true landmark of a loop closure would make a
/// duplicate.
const DRIFT: f64 = 0.25;

/// Thresholds of association.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AssociationSettings {
    pub scales: AppearanceScales,
    /// Largest descriptor distance of a candidate.
    pub gate: f64,
    /// Triples, with relations the map constrains, a candidate not seen lately must have been
    /// tested on to stay a candidate.
    pub informative_triples: usize,
    /// Most anchor pairs tested per candidate (the most constrained first).
    pub tested_pairs: usize,
    /// Registrations that must make a pair for it to anchor, at a station without colour
    /// (chroma is the descriptor's most telling part; without it rocks a few decimetres apart
    /// look alike). While placements were discs, a lone registration anchored rocks whose own
    /// landmarks were missing to their neighbours' (grayscale marsyard seed 7, full
    /// resolution: 4 landmarks mixing neighbours 0.7–1.5 m apart, 3 unsound relations), and
    /// two were needed. Ellipses along the bearings tell neighbours apart across the line of
    /// sight, and two kept luminance surveys from growing: with one, grayscale marsyard seed
    /// 7 fuses 29.1 % of its correct detections instead of 14.0 %, 1 rock duplicated instead
    /// of 15, 0 unsound relations.
    #[serde(default = "default_min_support_without_colour")]
    pub min_support_without_colour: usize,
}

fn default_min_support_without_colour() -> usize {
    1
}

impl Default for AssociationSettings {
    fn default() -> AssociationSettings {
        AssociationSettings {
            scales: AppearanceScales::default(),
            gate: 5.0,
            informative_triples: 6,
            tested_pairs: 20,
            min_support_without_colour: default_min_support_without_colour(),
        }
    }
}

/// What one detection needs for association.
#[derive(Clone, Debug, PartialEq)]
pub struct Evidence {
    pub appearance: Appearance,
    /// Physical width bounds from this station's range evidence.
    pub width: Option<RangeInterval>,
    /// Rough position around the station, if its range is bounded well enough.
    pub placed: Option<Placed>,
    /// The ray it was seen along.
    pub ray: Ray,
    /// A piece touching another detection ([`crate::ranging::Ranged::piece`]): it may be
    /// part of a rock or hold parts of two, so it observes landmarks but founds none.
    pub piece: bool,
    /// Doubted by the detector (a piece cut at a shallow notch, or beside a nearer piece that
    /// may hide some of it), or by luminance a piece, whose placement is looser than its
    /// interval says: it observes landmarks, steers no registration, founds none, and anchors
    /// only where every registered frame holding the landmark pairs it, as a far rock does
    /// (`long_anchor`).
    pub doubtful: bool,
    /// Nothing of it stands up from the ground by stereo ([`crate::detection::Detection::flat`]):
    /// a soil patch or a shadow, or a rock too smooth to tell.
    pub flat: bool,
    /// Flat where the stereo test tells a standing rock from the ground
    /// ([`crate::detection::Detection::surely_flat`]): founds no landmark.
    pub surely_flat: bool,
    /// Rock pixels of the detection: too few ([`MIN_FOUNDING_PIXELS`]) describe no looks.
    pub pixels: u32,
    /// Its range rests on what measures the rock itself: the ground contact and stereo bound
    /// it and agree, or stereo bounds it where no ground cue applies. The ground cue alone may
    /// be wrong by a whole rock (a rock's lit top taken for the whole rock puts its contact on
    /// the rock's own body).
    pub range_trusted: bool,
}

/// One station as association sees it: the bearings and range order of its usable detections,
/// and the evidence of the detection at each position of the view.
#[derive(Clone, Debug, PartialEq)]
pub struct StationEvidence {
    pub view: StationView,
    pub detections: Vec<Evidence>,
    /// Whether the detections' appearance holds colour: without it, an anchor needs more
    /// registrations (`AssociationSettings::min_support_without_colour`).
    pub colour: bool,
    /// The rays of the station's other detections, those mapping does not use (touching,
    /// doubtful): a landmark seen in one of their directions may be that rock.
    pub unused: Vec<Ray>,
    /// The placements of those other detections whose range bounds one: rocks this station
    /// maps no landmark for ([`Frame::unmapped`]).
    pub unused_placed: Vec<Placed>,
}

/// The association decision for one detection.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Decision {
    Matched(LandmarkId),
    New,
    HeldBack(Vec<LandmarkId>),
    /// A detection that matched no landmark and founds none, and why ([`unfounded`]).
    Withheld(Unfounded),
}

/// One station's association: each detection's decision, and the unmapped rocks of earlier
/// stations its anchors recognised ([`recognition`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StationAssociation {
    pub decisions: Vec<Decision>,
    pub recognitions: Vec<Recognition>,
    /// Every frame the station's detections registered against, believed or not.
    pub registrations: Vec<FrameRegistration>,
}

/// One registration of a station's detections against a frame, as association judged it: a
/// run's record of why its detections were anchored or held back (docs/RUN.md, "stations.json").
#[derive(Clone, Debug, PartialEq)]
pub struct FrameRegistration {
    /// Index into the frames association was given.
    pub frame: usize,
    /// `(detection, landmark)`, detections by index into the station's evidence: the pairs
    /// matches were drawn from when believed (anchors, and detections it placed on their
    /// landmark's track), else the fit's own.
    pub pairs: Vec<(usize, LandmarkId)>,
    /// The fit's number of false alarms ([`Registration::nfa`]).
    pub nfa: f64,
    /// Whether its pairs could anchor: it kept [`MIN_INLIERS`] pairs and chance does not
    /// explain it ([`believed`]).
    pub believed: bool,
}

/// Why a detection that matched no landmark founds none of its own ([`unfounded`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unfounded {
    /// A piece ([`Evidence::piece`]): part of a rock, or parts of two.
    Piece,
    /// Doubted by the detector ([`Evidence::doubtful`]).
    Doubtful,
    /// Fewer rock pixels than [`MIN_FOUNDING_PIXELS`].
    Small,
    /// Nothing of it stands up from the ground where the stereo test tells
    /// ([`Evidence::surely_flat`]).
    Flat,
    /// Placed looser than any registration pairs ([`LONG_ANCHOR_RADIUS_M`]), or not at all.
    Loose,
}

/// Fewest rock pixels of a detection that founds a landmark: a 3 × 3 window's. A landmark's
/// looks are those of the detection that founded it, and over fewer pixels its texture and
/// shaded fraction are noise: such a landmark passed the looks test for most rocks later seen
/// near its ray and held them back, while itself rarely seen again (half-resolution marsyard
/// seed 4: a landmark founded from 4 pixels, never seen again, was a candidate of 134 held-back
/// sightings; half-resolution marsyard seed 11 and stress seed 4 each mapped false detections
/// of under 9 pixels).
pub const MIN_FOUNDING_PIXELS: u32 = 9;

/// Why a detection that matched no landmark founds none, if it does not. A piece
/// ([`Evidence::piece`]) does not: it may be part of a rock or hold parts of two. Nor does a
/// detection of fewer than [`MIN_FOUNDING_PIXELS`], or one placed looser than any registration
/// pairs ([`LONG_ANCHOR_RADIUS_M`], a far rock whose range interval spans metres): its landmark
/// would stay as loose in every frame, so no later sighting could be paired with it, while
/// every look-alike seen along its ray would take it for a candidate and be held back
/// (half-resolution marsyard seed 4: a rock 11 m away founded a landmark placed within 7 m
/// either way, for which 36 later sightings of it and of another rock were held back and given
/// up; without it, the rock founded a landmark from 3.8 m, matched at 9 later stations).
pub fn unfounded(evidence: &Evidence) -> Option<Unfounded> {
    if evidence.piece {
        Some(Unfounded::Piece)
    } else if evidence.doubtful {
        Some(Unfounded::Doubtful)
    } else if evidence.pixels < MIN_FOUNDING_PIXELS {
        Some(Unfounded::Small)
    } else if evidence.surely_flat {
        Some(Unfounded::Flat)
    } else if evidence
        .placed
        .is_none_or(|p| p.reach() > LONG_ANCHOR_RADIUS_M)
    {
        Some(Unfounded::Loose)
    } else {
        None
    }
}

/// A new landmark for the detection with `evidence`, unless it founds none.
fn founded(evidence: &Evidence) -> Decision {
    unfounded(evidence).map_or(Decision::New, Decision::Withheld)
}

/// Associates the detections of one station with the landmarks of `map` and `gallery`;
/// `frames` are recent stations' landmarks placed around them, and `lately` tells the
/// landmarks the rover saw lately ([`LastSeen`]) from those it lost sight of.
pub fn associate<C: Calculus>(
    map: &Hypergraph<C>,
    gallery: &Gallery,
    frames: &[Frame],
    station: &StationEvidence,
    settings: &AssociationSettings,
    lately: &(dyn Fn(LandmarkId) -> bool + Sync),
) -> StationAssociation {
    let (view, evidence) = (&station.view, &station.detections);
    let placed: Vec<Option<Placed>> = evidence.iter().map(|e| e.placed).collect();
    let n = evidence.len();
    if gallery.is_empty() {
        return StationAssociation {
            decisions: evidence.iter().map(founded).collect(),
            recognitions: Vec::new(),
            registrations: Vec::new(),
        };
    }
    let candidates: Vec<Vec<(LandmarkId, f64)>> = evidence
        .iter()
        .map(|e| proposals(e, gallery, settings))
        .collect();
    // Every detection's ray, used or not: where the station saw something. (A ray, not the
    // bearing interval's middle: an unranged detection of the left eye alone has its middle
    // up to 45° from where it was seen.)
    let seen: Vec<Ray> = evidence
        .iter()
        .map(|e| e.ray)
        .chain(station.unused.iter().copied())
        .collect();
    // Doubted detections observe: registration fits the others, and pairs them under the
    // motions found ([`Registration::pair_observers`]).
    let doubtful: Vec<bool> = evidence.iter().map(|e| e.doubtful).collect();
    let firm: Vec<Option<Placed>> = evidence
        .iter()
        .map(|e| e.placed.filter(|_| !e.doubtful))
        .collect();
    let observers: Vec<usize> = (0..n).filter(|&i| doubtful[i]).collect();
    // Colour alone stays when a rock is seen from another side; without colour it says nothing.
    let by_colour: Option<Vec<Vec<(LandmarkId, f64)>>> = station.colour.then(|| {
        evidence
            .iter()
            .map(|e| colour_proposals(e, gallery, settings))
            .collect()
    });
    let mut registrations = registrations(
        frames,
        &firm,
        &candidates,
        by_colour.as_deref(),
        &seen,
        lately,
    );
    let found: Vec<(usize, Registration)> = registrations
        .iter()
        .map(|(frame, registration)| (frame_index(frames, frame), registration.clone()))
        .collect();
    // The station's usable detections' rays lead `seen`.
    let rays = &seen[..n];
    let alike = |i: usize, l: LandmarkId| looks_alike(&candidates, i, l);
    let elsewhere = unplaced_rays(station, &firm);
    for (frame, registration) in &mut registrations {
        registration.drop_pairs_seen_elsewhere(frame, &firm, rays, &elsewhere);
        // By luminance an uncorroborated piece observes: the fit's test never saw it.
        if !station.colour {
            registration.drop_ambiguous_pairs(frame, &placed, &alike);
        }
    }
    // The dropped pairs' landmarks may be other rocks, so they no longer support the motion:
    // fewer than the fewest believed left, and the fit is not trusted (the 1 000-rock drive,
    // stations 62–66: 4-pair fits left with 1 or 2 pairs anchored rocks 15–59 m from their
    // landmarks' own).
    registrations.retain(|(_, registration)| registration.pairs.len() >= MIN_INLIERS);
    let mut registrations = believed(registrations, frames);
    // Where nothing placed was seen: the directions an observer's landmark must not lie in
    // (the others' pairs passed this test with the observers' directions too).
    let unplaced = unplaced_rays(station, &placed);
    for (frame, registration) in &mut registrations {
        registration.pair_observers(frame, &placed, &observers, &alike);
        registration.drop_pairs_seen_elsewhere(frame, &placed, rays, &unplaced);
    }
    let min_support = if station.colour {
        1
    } else {
        settings.min_support_without_colour
    };
    let mut anchors = anchors(
        &registrations,
        &candidates,
        &placed,
        &doubtful,
        min_support,
        !station.colour,
    );
    let candidates = placed_near(candidates, &registrations, &placed);
    drop_inconsistent_anchors(map, view, &mut anchors);
    let anchored: Vec<Sighting> = anchors.iter().map(|a| Sighting::new(a.0, a.1)).collect();
    let recognitions =
        recognition::recognitions(frames, &registrations, &placed, &doubtful, &anchored);
    let recent = |l: LandmarkId| frames.iter().any(|f| f.landmarks.iter().any(|m| m.0 == l));
    let decisions: Vec<Decision> = (0..n)
        .into_par_iter()
        .map(|i| match anchored.iter().find(|a| a.position == i) {
            Some(anchor) => Decision::Matched(anchor.landmark),
            None => {
                // Where the sketch followed something unmapped over several stations
                // ([`Tracked`]) and a registration places the detection on it, the track
                // decides what look-alikes within the placement could not. Apart from every
                // landmark, it is a rock of its own: the detection founds its landmark. Else a
                // rock held back for a landmark nearby is never founded (colour marsyard
                // seed 41: two rocks of a cluster, 1–2.7 m from four landmarks, each seen
                // from over 40 stations; stop 74, docs/RUN.md).
                let track = || {
                    registrations
                        .iter()
                        .find_map(|(frame, r)| r.track_of(frame, &placed, i))
                };
                let survivors =
                    survivors(map, view, i, &candidates[i], &anchored, &recent, settings);
                if !survivors.is_empty() {
                    return match track().map(|t| t.landmark) {
                        Some(None) => founded(&evidence[i]),
                        // Fitting a landmark the map does not reject, it is that landmark's
                        // rock, held back before: matched, for a whole detection seen in
                        // colour. A piece's placement spans its neighbour, so its placements
                        // track the two rocks blended (stress seed 4: purity 0.956 → 0.928
                        // with pieces matched too, unchanged without); by luminance, look-alikes
                        // a few decimetres apart blend as well (stress seed 9: purity 0.952 →
                        // 0.945, a mixed landmark's wrong sightings 8 → 11; stop 74,
                        // docs/RUN.md).
                        Some(Some(l))
                            if station.colour
                                && survivors.contains(&l)
                                && !evidence[i].piece
                                && !evidence[i].doubtful =>
                        {
                            Decision::Matched(l)
                        }
                        _ => Decision::HeldBack(survivors),
                    };
                }
                // No look-alike is left, but a known landmark that no detection of this
                // station is anchored to lies where the detection is: most likely its own
                // rock, seen so differently (a piece of it, a lit face) that its looks did
                // not propose it. A new landmark would duplicate it (marsyard seed 3: two
                // rocks duplicated, 37 points of removed states lost); the map decides later.
                // (Counting a look-alike of another detection as accounted for brought the
                // duplicates back.)
                let unaccounted = placed[i]
                    .map(|p| unaccounted_near(p, &registrations, &anchored))
                    .unwrap_or_default();
                if unaccounted.is_empty() || track().is_some_and(|t| t.landmark.is_none()) {
                    founded(&evidence[i])
                } else {
                    Decision::HeldBack(unaccounted)
                }
            }
        })
        .collect();
    // The matches a registration made by placing the detection on its landmark's track, as
    // the decisions found them: each recorded with that registration's pairs.
    let on_tracks: Vec<(&Frame, usize, LandmarkId)> = decisions
        .iter()
        .enumerate()
        .filter(|&(i, _)| !anchored.iter().any(|a| a.position == i))
        .filter_map(|(i, decision)| match *decision {
            Decision::Matched(l) => registrations.iter().find_map(|(frame, r)| {
                let track = r.track_of(frame, &placed, i)?;
                (track.landmark == Some(l)).then_some((*frame, i, l))
            }),
            _ => None,
        })
        .collect();
    let registrations = found
        .into_iter()
        .map(|(frame, fit)| {
            let kept = registrations
                .iter()
                .find(|(f, _)| std::ptr::eq(*f, &frames[frame]));
            let (registration, believed) = kept.map_or((fit, false), |(_, r)| (r.clone(), true));
            let mut pairs = registration.pairs;
            if believed {
                pairs.extend(
                    on_tracks
                        .iter()
                        .filter(|(f, _, _)| std::ptr::eq(*f, &frames[frame]))
                        .map(|&(_, i, l)| (i, l)),
                );
            }
            FrameRegistration {
                frame,
                pairs,
                nfa: registration.nfa,
                believed,
            }
        })
        .collect();
    StationAssociation {
        decisions,
        recognitions,
        registrations,
    }
}

/// The index of `frame` in `frames`, which holds it.
fn frame_index(frames: &[Frame], frame: &Frame) -> usize {
    frames
        .iter()
        .position(|f| std::ptr::eq(f, frame))
        .expect("a registration's frame is one of the station's frames")
}

/// The landmarks of the registered frames, none anchored at this station, that lie within
/// placement tolerance of where the registration puts a detection placed at `p`.
fn unaccounted_near(
    p: Placed,
    registrations: &[(&Frame, Registration)],
    anchored: &[Sighting],
) -> Vec<LandmarkId> {
    let mut near: Vec<LandmarkId> = registrations
        .iter()
        .flat_map(|(frame, r)| {
            frame.landmarks.iter().filter(move |(l, q)| {
                !anchored.iter().any(|a| a.landmark == *l) && within(p, *q, r, PLACEMENT_SLACK_M)
            })
        })
        .map(|(l, _)| *l)
        .collect();
    near.sort_unstable();
    near.dedup();
    near
}

/// Whether the station's placement `p`, moved into a frame by `registration`, may be the
/// frame's landmark placed at `q`, both placements grown by `slack` metres between them.
fn within(p: Placed, q: Placed, registration: &Registration, slack: f64) -> bool {
    placement::separation(&registration.to_frame_placed(&p), &q, slack).within()
}

/// Whether `frame`, registered by `registration`, places the detection at `p` where it may be
/// the landmark it placed at `q`: within [`SKETCH_SLACK_M`] for the sketch, whose averaged
/// positions are tighter than they are right, [`PLACEMENT_SLACK_M`] for a station's frame.
fn placed_as(frame: &Frame, registration: &Registration, p: Placed, q: Placed) -> bool {
    let slack = if frame.accumulated {
        SKETCH_SLACK_M
    } else {
        PLACEMENT_SLACK_M
    };
    within(p, q, registration, slack)
}

/// Whether landmark `l` is among detection `i`'s look-alike candidates.
fn looks_alike(candidates: &[Vec<(LandmarkId, f64)>], i: usize, l: LandmarkId) -> bool {
    candidates[i].iter().any(|c| c.0 == l)
}

/// The rays of the station's detections without a placement in `placements`, and of those
/// mapping does not use: where it saw something a registration pair's landmark may be.
fn unplaced_rays(station: &StationEvidence, placements: &[Option<Placed>]) -> Vec<Ray> {
    station
        .detections
        .iter()
        .zip(placements)
        .filter(|(_, p)| p.is_none())
        .map(|(e, _)| e.ray)
        .chain(station.unused.iter().copied())
        .collect()
}

/// The frames the station registers against, with their registrations (see [`register`]).
///
/// A frame no motion registers with the look-alikes of the whole descriptor is registered
/// again with those of colour alone (`by_colour`, colour mode only), each detection seeding
/// with its closest few among the frame's landmarks. After a long step or a turn the rover sees
/// the rocks from another side: their brightness, texture and shaded share change, and so does
/// the width a partly lit rock shows, while their colour does not (stress seed 22, after a
/// 5.6 m step: 4 of 7 detections whose rock the sketch held had that landmark outside their
/// look-alikes, no frame registered for 25 stations, and 406 correct detections were held back
/// and given up). The fallback pairs only by geometry and colour, so it is judged as every
/// registration is: the significance test's null model counts any landmark near a detection
/// as a chance hit, look-alike or not.
fn registrations<'f>(
    frames: &'f [Frame],
    placed: &[Option<Placed>],
    candidates: &[Vec<(LandmarkId, f64)>],
    by_colour: Option<&[Vec<(LandmarkId, f64)>]>,
    seen: &[Ray],
    lately: &(dyn Fn(LandmarkId) -> bool + Sync),
) -> Vec<(&'f Frame, Registration)> {
    let alike = |i: usize, l: LandmarkId| looks_alike(candidates, i, l);
    // How far this station places rocks: a landmark the motion brings farther may be beyond
    // detection, so its absence says nothing.
    let reach = placed
        .iter()
        .flatten()
        .map(|p| p.point[0].hypot(p.point[1]))
        .fold(0.0, f64::max);
    // Frames in parallel: a navigator registers its panorama against every station of the
    // run (marsyard: 50 frames, 70 ms of a step's compute on one core).
    frames
        .par_iter()
        .filter_map(|frame| {
            // Registration hypotheses grow with the square of the seeds: each detection seeds
            // only with its closest few look-alikes (the lists are sorted by descriptor
            // distance) in the whole gallery, and failing that, among the frame's landmarks.
            // In a large gallery of look-alikes the closest few are mostly elsewhere
            // (`sparse-large` seed 3, station 57: 1 of 7 rocks shared with the last station
            // had its landmark among its 6 closest, 3 among the frame's 6 closest), but more
            // seeds also give chance fits more tries, so they are the second resort.
            let closest = |i: usize, l: LandmarkId| {
                candidates[i]
                    .iter()
                    .take(REGISTRATION_SEEDS)
                    .any(|c| c.0 == l)
            };
            let closest_in_frame =
                |i: usize, l: LandmarkId| closest_in(frame, &candidates[i]).any(|c| c.0 == l);
            let by_colour_only = || {
                let by_colour = by_colour?;
                let coloured = |i: usize, l: LandmarkId| looks_alike(by_colour, i, l);
                let closest_in_frame =
                    |i: usize, l: LandmarkId| closest_in(frame, &by_colour[i]).any(|c| c.0 == l);
                register(placed, frame, &coloured, &[&closest_in_frame])
            };
            let registration = register(placed, frame, &alike, &[&closest, &closest_in_frame])
                .or_else(by_colour_only)?;
            Some((frame, registration))
        })
        .filter(|(frame, registration)| {
            registration.pairs.len() > MIN_INLIERS
                || registration.unseen(frame, seen, reach) < MIN_UNSEEN
        })
        // A registration must hold a landmark the rover saw lately: see `recency`.
        .filter(|(_, registration)| registration.pairs.iter().any(|p| lately(p.1)))
        .collect()
}

/// The first [`REGISTRATION_SEEDS`] of a detection's look-alikes (sorted by distance) that
/// `frame` holds.
fn closest_in<'a>(
    frame: &'a Frame,
    look_alikes: &'a [(LandmarkId, f64)],
) -> impl Iterator<Item = &'a (LandmarkId, f64)> + 'a {
    look_alikes
        .iter()
        .filter(|c| frame.landmarks.iter().any(|m| m.0 == c.0))
        .take(REGISTRATION_SEEDS)
}

/// The registrations less those whose fit chance explains, and less a station's only one when
/// it is not believed. Applied once the
/// pairs seen elsewhere are dropped: a registration dropped then leaves another alone (the
/// 1 000-rock drive, station 380: a 4-pair fit of NFA 0.8, the lone survivor of two, paired
/// four detections with rocks 19–31 m from their landmarks' own; 144 unsound relations).
fn believed<'f>(
    mut registrations: Vec<(&'f Frame, Registration)>,
    frames: &[Frame],
) -> Vec<(&'f Frame, Registration)> {
    // No registration of any size whose fit chance explains (NFA 1 or more: as many fits as
    // tight are expected from the hypotheses tried) is believed, alone or not: consecutive
    // stations' frames share most of their landmarks, so one chance fit of look-alikes is
    // found in both (the 1 000-rock drive, station 22: two 4-pair fits at NFA 462 and 1 088
    // gave four landmarks a second rock, 985 unsound relations; such fits were dropped only
    // when alone until stop 35). Earlier: station 12's only registration, 7 pairs against the
    // sketch at NFA 1.5 × 10⁴, paired six landmarks with the wrong rocks, in an experiment
    // with unranged detections counted in the eye's direction.
    registrations.retain(|(_, registration)| registration.nfa < 1.0);
    // A station's only registration is a chance fit of look-alikes when several other frames
    // hold enough of its landmarks to have found the same pairing and none did, unless its
    // fit is significant on its own.
    match registrations.as_slice() {
        [(only, registration)]
            if registration.nfa >= SIGNIFICANT_NFA
                && frames
                    .iter()
                    .filter(|f| !std::ptr::eq(*f, *only) && f.could_confirm(registration))
                    .count()
                    >= SILENT_FRAMES =>
        {
            Vec::new()
        }
        // A station's only registration of few pairs must be more than a clear winner among
        // the hypotheses: in a dense field of look-alikes a fit of 4–5 loose pairs wins by
        // chance (the 1 000-rock drive: 19 of 40 pairs of such registrations wrong, every
        // one of 6 groups of landmarks re-identified 20–56 m from their rocks; every lone
        // registration of 6 pairs or more was right).
        [(_, registration)]
            if registration.pairs.len() < LONE_PAIRS && registration.nfa >= SIGNIFICANT_NFA =>
        {
            Vec::new()
        }
        _ => registrations,
    }
}

/// The registered correspondences all frames agree on, `(detection, landmark, descriptor
/// distance)`: a detection or landmark given two different partners by different frames is
/// left out, and so is a pair that most frames holding its landmark do not make, that fewer
/// than `min_support` make, or that a significant registration overrules ([`overruled`]).
fn anchors(
    registrations: &[(&Frame, Registration)],
    candidates: &[Vec<(LandmarkId, f64)>],
    placed: &[Option<Placed>],
    doubtful: &[bool],
    min_support: usize,
    fragmented: bool,
) -> Vec<(usize, LandmarkId, f64)> {
    let mut pairs: Vec<(usize, LandmarkId)> = registrations
        .iter()
        .flat_map(|(_, r)| r.pairs.iter().copied())
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    let conflicted =
        |&(i, l): &(usize, LandmarkId)| pairs.iter().any(|&(j, m)| (j == i) != (m == l));
    // The station's other placed detections: an unmapped rock one of them lies at is theirs.
    let others = |i: usize| -> Vec<Placed> {
        placed
            .iter()
            .enumerate()
            .filter(|&(k, _)| k != i)
            .filter_map(|(_, p)| *p)
            .collect()
    };
    // Frames that hold a landmark but pair it with no detection, or another, doubt the pair.
    let agreed = |&(i, l): &(usize, LandmarkId)| {
        let supporting = || {
            registrations
                .iter()
                .filter(|(_, r)| r.pairs.contains(&(i, l)))
        };
        let support = supporting().count();
        let holding = registrations
            .iter()
            // The sketch holds more look-alikes near each landmark than one station sees, so
            // its leaving a pair out is abstention, not doubt (counted as doubt, it cost 13 %
            // of random seed 5's sightings), unless its motion puts the detection far from
            // the landmark (then the two registrations disagree on where the rover is), or it
            // knows another landmark where the detection is placed (colour mode): with pieces
            // ranged by their own pixels' shifts, marsyard seed 19, station 11, anchored rock
            // 13 to a shadow's landmark 0.6 m from the rock's own on one station's frame while
            // the sketch, holding both, paired it with neither (5 unsound relations). The
            // sketch's unmapped rocks do not count: five stations of them crowd a random
            // survey's placements (stress seed 13: 52.3 % fused with them, 53.9 % without).
            // By luminance, where pieces take no shifts of their own, the rule moved sets
            // 2 points either way and 0 on average (docs/RUN.md, stop 69).
            .filter(|(frame, r)| {
                frame
                    .landmarks
                    .iter()
                    .find(|m| m.0 == l)
                    .is_some_and(|(_, q)| {
                        !frame.accumulated
                            || r.pairs.iter().any(|p| p.0 == i || p.1 == l)
                            || placed[i].is_some_and(|p| {
                                !placed_as(frame, r, p, *q)
                                    || (!fragmented
                                        && r.crowded_by_landmarks(frame, &p, l, &others(i)))
                            })
                    })
            })
            .count();
        let short = !doubtful[i] && placed[i].is_none_or(|p| p.reach() <= ANCHOR_RADIUS_M);
        !overruled(registrations, i, l)
            && 2 * support > holding
            && support >= min_support
            && (short
                || long_anchor(
                    &supporting().collect::<Vec<_>>(),
                    holding,
                    placed[i],
                    l,
                    &others(i),
                    fragmented,
                ))
    };
    pairs
        .iter()
        .filter(|p| !conflicted(p) && agreed(p))
        .map(|&(i, l)| {
            let d = candidates[i].iter().find(|c| c.0 == l).map_or(0.0, |c| c.1);
            (i, l, d)
        })
        .collect()
}

/// Whether the pair of detection `i` and landmark `l` is made only by registrations that chance
/// may explain (NFA of [`SIGNIFICANT_NFA`] or more), while a significant one holds `l` and
/// leaves the pair out. The sketch's leaving a pair out is otherwise abstention
/// ([`anchors`]), but a significant fit that does not make it outweighs a chance one that
/// does. With placements over the likely range (`run::selection::likely_range`), stress seed
/// 10, station 5: one station frame's registration of 8 pairs at NFA 0.87 anchored rock 8's
/// detection to rock 14's landmark, 1.19 m away, which the sketch's registration (NFA 0.007)
/// left unpaired; rock 14's own detection there was a piece, outside the fit; 3 unsound
/// relations.
fn overruled(registrations: &[(&Frame, Registration)], i: usize, l: LandmarkId) -> bool {
    let significant = |r: &Registration| r.nfa < SIGNIFICANT_NFA;
    let makes = |r: &Registration| r.pairs.contains(&(i, l));
    !registrations
        .iter()
        .any(|(_, r)| makes(r) && significant(r))
        && registrations.iter().any(|(frame, r)| {
            significant(r) && !makes(r) && frame.landmarks.iter().any(|m| m.0 == l)
        })
}

/// The candidates of each detection less those a registered frame places away from where its
/// motion puts the detection: a station's frame within [`PLACEMENT_SLACK_M`], the sketch within
/// [`SKETCH_SLACK_M`], and a landmark that left the sketch within that plus [`DRIFT`] of the way
/// to where the sketch last put it. A rock entering view on a long drive otherwise keeps every
/// old look-alike the loose map cannot reject for a candidate, is held back and given up, and
/// the map stops growing (`sparse-large` seed 3: nothing fused at stations 57–81 and 105–119;
/// with the departed landmarks, 70 % of the correct detections fused instead of 34 %).
fn placed_near(
    candidates: Vec<Vec<(LandmarkId, f64)>>,
    registrations: &[(&Frame, Registration)],
    placed: &[Option<Placed>],
) -> Vec<Vec<(LandmarkId, f64)>> {
    candidates
        .into_iter()
        .enumerate()
        .map(|(i, list)| {
            list.into_iter()
                .filter(|&(l, _)| {
                    let Some(p) = placed[i] else {
                        return true;
                    };
                    registrations.iter().all(|(frame, r)| {
                        if let Some((_, q)) = frame.landmarks.iter().find(|f| f.0 == l) {
                            return placed_as(frame, r, p, *q);
                        }
                        // A landmark the rover left behind lies where the sketch last put it,
                        // give or take the sketch's drift since, which grows with the way
                        // back to it.
                        frame
                            .departed
                            .iter()
                            .find(|f| f.0 == l)
                            .is_none_or(|(_, q)| {
                                let way = registration::distance(r.to_frame([0.0, 0.0]), q.point);
                                within(p, *q, r, SKETCH_SLACK_M + DRIFT * way)
                            })
                    })
                })
                .collect()
        })
        .collect()
}

/// Whether a pair that does not anchor on the usual terms, of a detection placed looser than
/// [`ANCHOR_RADIUS_M`] (a far rock) or of an observer, with landmark `l` anchors: every
/// registered frame holding `l` makes it (`holding`), none knows another rock where the pair's
/// placement lies ([`Registration::crowded`]), and two or more do, one a station's frame (the
/// sketch's averaged positions alone re-identified a far rock's neighbour: JPEG marsyard seed
/// 3, station 40). Far rocks are held back otherwise, and where they stand apart (sparse
/// fields) the map loses most of them; where they cluster, a far placement reaches several.
///
/// An observer placed within [`ANCHOR_RADIUS_M`] does not reach past its rock that way, and by
/// luminance (`fragmented`) the sketch alone may pair it where no station's frame holds `l`:
/// the sketch keeps the landmarks of the last [`sketch::WINDOW`] stations, the recent frames
/// those of the last few. By luminance the detector breaks rocks into pieces, and pieces the
/// stereo test does not corroborate, paired with their own rock's landmark, were refused so
/// (grayscale marsyard seed 41: 40 of 41 refusals of an observer's lone pairing were the
/// sketch's); letting them anchor raised the fused share of 17 of 22 luminance sets by
/// 1.0–8.9 points (grayscale marsyard seed 53: 72.6 → 81.5 %), the other five moving by −0.5
/// to +0.2, with no relation unsound. In colour an observer is a cut the detector doubts:
/// there it changed no colour marsyard seed, and on stress seed 49 its few sightings tipped a
/// landmark that already held two rocks 0.9 m apart into the second one's (8 unsound
/// relations; docs/RUN.md, stop 80).
fn long_anchor(
    supporting: &[&(&Frame, Registration)],
    holding: usize,
    placed: Option<Placed>,
    l: LandmarkId,
    others: &[Placed],
    fragmented: bool,
) -> bool {
    let Some(p) = placed else {
        return false;
    };
    let enough = match supporting {
        [(only, _)] => fragmented && only.accumulated && p.reach() <= ANCHOR_RADIUS_M,
        _ => supporting.len() >= 2 && supporting.iter().any(|(frame, _)| !frame.accumulated),
    };
    supporting.len() == holding
        && enough
        && supporting
            .iter()
            .all(|(frame, r)| !r.crowded(frame, &p, l, others, fragmented))
}

/// Re-tests one held-back detection of an earlier station against the current map (000 §VI-C
/// "delayed until the map has converged further"): the candidates the map still allows, empty
/// when it rejects them all (a new landmark). `decided` are the other detections of that
/// station's sightings; `None` when they took every candidate, which says nothing
/// about which rock this one is (a new landmark would duplicate a rock never proposed).
///
/// A candidate left alone after the others were rejected is not matched: it is no surer than
/// a lone pass, since the rock's own landmark need not have been among the look-alikes.
pub fn reconsider<C: Calculus>(
    map: &Hypergraph<C>,
    view: &StationView,
    detection: usize,
    candidates: &[LandmarkId],
    decided: &[Sighting],
    settings: &AssociationSettings,
) -> Option<Vec<LandmarkId>> {
    let open: Vec<(LandmarkId, f64)> = candidates
        .iter()
        .filter(|l| !decided.iter().any(|d| d.landmark == **l))
        .map(|&l| (l, settings.gate))
        .collect();
    if open.is_empty() {
        return None;
    }
    Some(survivors(
        map,
        view,
        detection,
        &open,
        decided,
        &|_| true,
        settings,
    ))
}

/// Landmarks whose looks are within the gate, nearest first.
fn proposals(
    evidence: &Evidence,
    gallery: &Gallery,
    settings: &AssociationSettings,
) -> Vec<(LandmarkId, f64)> {
    within_gate(gallery, settings, |p| resemblance(evidence, p, settings))
}

/// The looks distance of a detection from a landmark's profile, unless their widths disagree.
fn resemblance(evidence: &Evidence, p: &Profile, settings: &AssociationSettings) -> Option<f64> {
    let width_agrees = match (p.width, evidence.width) {
        (Some(a), Some(b)) => a.intersection(b).is_some(),
        _ => true,
    };
    width_agrees.then(|| distance(&evidence.appearance, &p.appearance, &settings.scales))
}

/// The landmarks the gallery proposes for a detection with `evidence` ([`proposals`]).
pub fn look_alikes(
    evidence: &Evidence,
    gallery: &Gallery,
    settings: &AssociationSettings,
) -> Vec<LandmarkId> {
    proposals(evidence, gallery, settings)
        .into_iter()
        .map(|(l, _)| l)
        .collect()
}

/// Whether the gallery would propose `landmark` for a detection with `evidence` ([`proposals`]):
/// for a detection seen before the landmark was founded, what proposing it then would have
/// asked.
pub fn looks_like(
    evidence: &Evidence,
    gallery: &Gallery,
    settings: &AssociationSettings,
    landmark: LandmarkId,
) -> bool {
    gallery
        .profile(landmark)
        .and_then(|p| resemblance(evidence, p, settings))
        .is_some_and(|d| d <= settings.gate)
}

/// The landmarks whose colour is within the gate of the detection's, whatever their other
/// looks and width, closest first: the look-alikes of a registration's second try
/// ([`registrations`]).
fn colour_proposals(
    evidence: &Evidence,
    gallery: &Gallery,
    settings: &AssociationSettings,
) -> Vec<(LandmarkId, f64)> {
    within_gate(gallery, settings, |p| {
        Some(chromaticity_distance(
            &evidence.appearance,
            &p.appearance,
            &settings.scales,
        ))
    })
}

/// The gallery's landmarks whose `distance` (none: not a candidate at all) is within the
/// gate, nearest first.
fn within_gate(
    gallery: &Gallery,
    settings: &AssociationSettings,
    distance: impl Fn(&Profile) -> Option<f64>,
) -> Vec<(LandmarkId, f64)> {
    let mut out: Vec<(LandmarkId, f64)> = gallery
        .profiles
        .iter()
        .filter_map(|p| distance(p).map(|d| (p.landmark, d)))
        .filter(|&(_, d)| d <= settings.gate)
        .collect();
    out.sort_by(|a, b| a.1.total_cmp(&b.1));
    out
}

/// Whether the measured states of detections `[a, b, c]` overlap the map's relations of
/// landmarks `ids`, and whether the map constrained them at all. `None` when the map has
/// nothing on this triple.
fn triple_consistency<C: Calculus>(
    map: &Hypergraph<C>,
    view: &StationView,
    detections: [usize; 3],
    ids: [LandmarkId; 3],
) -> Option<bool> {
    let [a, b, c] = ids;
    let open = [
        map.relation(a, b, c)?,
        map.relation(b, c, a)?,
        map.relation(c, a, b)?,
    ];
    if open.iter().all(|r| *r == C::universe()) {
        return None;
    }
    let measured = view.measure_triple::<C>(detections, open);
    Some(measured.iter().all(|r| !r.is_empty()))
}

/// Drops anchors until every triple of anchors the map knows is consistent: the anchor in
/// most inconsistent triples first, the weaker appearance match on ties. A triple's verdict
/// does not depend on the other anchors, so each triple is measured once, in parallel (a
/// navigator's panorama anchors a dozen landmarks: some 200 triples).
fn drop_inconsistent_anchors<C: Calculus>(
    map: &Hypergraph<C>,
    view: &StationView,
    anchors: &mut Vec<(usize, LandmarkId, f64)>,
) {
    let k = anchors.len();
    let triples: Vec<[usize; 3]> = (0..k)
        .flat_map(|x| (x + 1..k).flat_map(move |y| (y + 1..k).map(move |z| [x, y, z])))
        .collect();
    let inconsistent: Vec<[usize; 3]> = triples
        .into_par_iter()
        .filter(|t| {
            let (detections, ids) = (t.map(|i| anchors[i].0), t.map(|i| anchors[i].1));
            triple_consistency(map, view, detections, ids) == Some(false)
        })
        .collect();
    let mut kept = vec![true; k];
    loop {
        let mut failures = vec![0usize; k];
        for triple in inconsistent.iter().filter(|t| t.iter().all(|&i| kept[i])) {
            for &i in triple {
                failures[i] += 1;
            }
        }
        let worst = (0..k).filter(|&i| failures[i] > 0).max_by(|&i, &j| {
            failures[i]
                .cmp(&failures[j])
                .then(anchors[i].2.total_cmp(&anchors[j].2))
        });
        match worst {
            Some(i) => kept[i] = false,
            None => break,
        }
    }
    *anchors = anchors
        .iter()
        .zip(&kept)
        .filter_map(|(anchor, &kept)| kept.then_some(*anchor))
        .collect();
}

/// 000 §VI-C for one detection: the candidates the map does not reject.
fn survivors<C: Calculus>(
    map: &Hypergraph<C>,
    view: &StationView,
    detection: usize,
    candidates: &[(LandmarkId, f64)],
    anchors: &[Sighting],
    recent: &(dyn Fn(LandmarkId) -> bool + Sync),
    settings: &AssociationSettings,
) -> Vec<LandmarkId> {
    let taken = |l: LandmarkId| anchors.iter().any(|a| a.landmark == l);
    candidates
        .iter()
        .filter(|c| !taken(c.0))
        .filter_map(|&(landmark, _)| {
            let informative = test_candidate(map, view, detection, landmark, anchors, settings)?;
            // A landmark not seen lately stays a candidate only on evidence the map actually
            // constrains: otherwise every unknown rock would be held back for every old
            // look-alike, and the map would stop growing.
            (recent(landmark) || informative >= settings.informative_triples).then_some(landmark)
        })
        .collect()
}

/// `None` if `landmark` is inconsistent with the detection's triples with the anchors;
/// otherwise the number of triples on which the map constrained the test.
fn test_candidate<C: Calculus>(
    map: &Hypergraph<C>,
    view: &StationView,
    detection: usize,
    landmark: LandmarkId,
    anchors: &[Sighting],
    settings: &AssociationSettings,
) -> Option<usize> {
    // The pairs on which the map knows most about the candidate first.
    let mut pairs: Vec<(usize, usize, u32)> = Vec::new();
    for x in 0..anchors.len() {
        for y in x + 1..anchors.len() {
            let (p, q) = (anchors[x], anchors[y]);
            if let Some(r) = map.relation(landmark, p.landmark, q.landmark) {
                let open = r.len() as u32
                    + map
                        .relation(p.landmark, q.landmark, landmark)
                        .map_or(0, |s| s.len() as u32)
                    + map
                        .relation(q.landmark, landmark, p.landmark)
                        .map_or(0, |s| s.len() as u32);
                if open < 3 * C::universe().len() as u32 {
                    pairs.push((x, y, open));
                }
            }
        }
    }
    pairs.sort_by_key(|p| p.2);
    let mut informative = 0;
    for &(x, y, _) in pairs.iter().take(settings.tested_pairs) {
        let (p, q) = (anchors[x], anchors[y]);
        match triple_consistency(
            map,
            view,
            [detection, p.position, q.position],
            [landmark, p.landmark, q.landmark],
        ) {
            Some(false) => return None,
            Some(true) => informative += 1,
            None => {}
        }
    }
    Some(informative)
}

#[cfg(test)]
mod tests {
    use super::*;
    use qrm_core::edc::Edc;
    use qrm_core::measurement::{Bearing, RangeOrder};
    use registration::tests::FIELD;

    fn look() -> Appearance {
        Appearance {
            colour: [0.4, 0.33, 0.27],
            brightness: 1.1,
            texture: 0.2,
            dark_fraction: 0.1,
        }
    }

    /// A look unlike [`look`]'s: a rock no landmark of the gallery resembles.
    fn other_look() -> Appearance {
        Appearance {
            colour: [0.2, 0.3, 0.5],
            brightness: 3.0,
            texture: 0.6,
            dark_fraction: 0.5,
        }
    }

    fn at(point: [f64; 2]) -> Placed {
        Placed::disc(point, 0.3)
    }

    /// The station's detections at `points` (bearings from the positions, no range order),
    /// all alike, with landmarks 0‥6 in the gallery.
    fn station(points: &[[f64; 2]]) -> (Gallery, StationEvidence) {
        let mut gallery = Gallery::default();
        for l in 0..=6 {
            gallery.observe(l, look(), None);
        }
        let bearings = points
            .iter()
            .map(|p| Bearing {
                angle: p[1].atan2(p[0]).rem_euclid(std::f64::consts::TAU),
                uncertainty: 0.01,
            })
            .collect();
        let view = StationView::new(bearings, RangeOrder::unordered(points.len())).unwrap();
        let detections = points
            .iter()
            .map(|&p| Evidence {
                appearance: look(),
                width: None,
                placed: Some(at(p)),
                ray: toward(p),
                piece: false,
                doubtful: false,
                flat: false,
                surely_flat: false,
                pixels: 100,
                range_trusted: true,
            })
            .collect();
        (
            gallery,
            StationEvidence {
                view,
                detections,
                colour: true,
                unused: Vec::new(),
                unused_placed: Vec::new(),
            },
        )
    }

    /// The ray of a detection seen from the station centre towards `p`.
    fn toward(p: [f64; 2]) -> Ray {
        Ray {
            azimuth: p[1].atan2(p[0]).rem_euclid(std::f64::consts::TAU),
            half_baseline: 0.0,
            nearest: 0.0,
            half_width: 0.0,
        }
    }

    /// Associates the station against `frames` on an empty map with default settings, every
    /// landmark seen lately.
    fn associate_station(station: &(Gallery, StationEvidence), frames: &[Frame]) -> Vec<Decision> {
        associate_after(station, frames, &|_| true)
    }

    /// As [`associate_station`], with the landmarks seen lately given by `lately`.
    fn associate_after(
        (gallery, station): &(Gallery, StationEvidence),
        frames: &[Frame],
        lately: &(dyn Fn(LandmarkId) -> bool + Sync),
    ) -> Vec<Decision> {
        associate(
            &Hypergraph::<Edc>::new(),
            gallery,
            frames,
            station,
            &AssociationSettings::default(),
            lately,
        )
        .decisions
    }

    /// Associates `station`, of three detections, as the first station: the first and third
    /// found landmarks, the second none, for `why`.
    fn only_the_second_founds_none(station: StationEvidence, why: Unfounded) {
        let decisions = associate_station(&(Gallery::default(), station), &[]);
        assert_eq!(
            decisions,
            [Decision::New, Decision::Withheld(why), Decision::New]
        );
    }

    /// The first station founds a landmark for each detection but the piece touching another,
    /// which may be part of a rock or hold parts of two.
    #[test]
    fn a_piece_founds_no_landmark() {
        let (_, mut station) = station(&[[5.0, 0.0], [0.0, 6.0], [-4.0, -3.0]]);
        station.detections[1].piece = true;
        only_the_second_founds_none(station, Unfounded::Piece);
    }

    /// A far detection whose range interval spans metres founds no landmark: no registration
    /// could pair a later sighting with one placed so loosely. One placed as loosely as a
    /// registration still pairs founds one.
    #[test]
    fn a_detection_placed_looser_than_any_registration_pairs_founds_no_landmark() {
        let (_, mut station) = station(&[[5.0, 0.0], [0.0, 12.0], [-9.0, 0.0]]);
        let angle = std::f64::consts::FRAC_PI_2;
        station.detections[1].placed = Some(Placed::along([0.0, 12.0], angle, 6.0, 0.2));
        station.detections[2].placed = Some(Placed::along(
            [-9.0, 0.0],
            std::f64::consts::PI,
            LONG_ANCHOR_RADIUS_M,
            0.2,
        ));
        only_the_second_founds_none(station, Unfounded::Loose);
    }

    /// A detection the stereo test surely finds flat (a soil patch or a shadow) founds no
    /// landmark; one merely flat (a far or low-contrast rock the test cannot tell) does.
    #[test]
    fn a_surely_flat_detection_founds_no_landmark() {
        let (_, mut station) = station(&[[5.0, 0.0], [0.0, 6.0], [-4.0, -3.0]]);
        station.detections[1].flat = true;
        station.detections[1].surely_flat = true;
        station.detections[2].flat = true;
        only_the_second_founds_none(station, Unfounded::Flat);
    }

    /// A detection of fewer pixels than a 3 × 3 window founds no landmark: its looks are noise.
    #[test]
    fn a_detection_too_small_to_describe_founds_no_landmark() {
        let (_, mut station) = station(&[[5.0, 0.0], [0.0, 6.0], [-4.0, -3.0]]);
        station.detections[1].pixels = MIN_FOUNDING_PIXELS - 1;
        station.detections[2].pixels = MIN_FOUNDING_PIXELS;
        only_the_second_founds_none(station, Unfounded::Small);
    }

    fn frame(points: &[[f64; 2]]) -> Frame {
        Frame {
            accumulated: false,
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
            landmarks: points
                .iter()
                .enumerate()
                .map(|(l, &p)| (l as LandmarkId, at(p)))
                .collect(),
        }
    }

    #[test]
    fn the_sketch_rules_out_look_alikes_far_from_where_it_puts_them() {
        // Registered against the sketch with no motion, a detection 9.8 m from the station.
        // Landmark 1 is in the sketch 7 m from it: out, beyond the sketch's 3 m slack. The
        // rover left landmarks 2, 3 and 4 behind: 2 lies 1 m from the detection (kept), 3
        // lies 7 m from it but 16.5 m from the station, within the drift that way allows
        // (kept), and 4, 50 m off, cannot be this rock (out).
        let detection = [4.0, -9.0];
        let sketch = Frame {
            accumulated: true,
            landmarks: vec![(0, at([10.0, 10.0])), (1, at([4.0, -16.0]))],
            departed: vec![
                (2, at([4.0, -10.0])),
                (3, at([4.0, -16.0])),
                (4, at([40.0, 30.0])),
            ],
            unmapped: Vec::new(),
            tracks: Vec::new(),
        };
        let registration = Registration {
            pairs: Vec::new(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let candidates = vec![(1..=4).map(|l| (l, 0.1)).collect()];
        let kept = placed_near(
            candidates,
            &[(&sketch, registration)],
            &[Some(at(detection))],
        );
        let kept: Vec<LandmarkId> = kept[0].iter().map(|c| c.0).collect();
        assert_eq!(kept, vec![2, 3]);
    }

    #[test]
    fn a_lone_registration_of_few_loose_pairs_anchors_nothing() {
        // Four rocks placed within 0.6 m, each detected `error` metres off its landmark in a
        // different direction. 30 cm off, the fit is the hypotheses' clear winner but what
        // chance gives among look-alikes this dense: as the station's only registration it
        // anchors nothing. 5 cm off, it is no accident, and anchors all four.
        let shifts = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        let seen = |error: f64| {
            let points: Vec<[f64; 2]> = FIELD[..4]
                .iter()
                .zip(shifts)
                .map(|(p, d)| [p[0] + error * d[0], p[1] + error * d[1]])
                .collect();
            let mut seen = station(&points);
            for detection in &mut seen.1.detections {
                detection.placed = detection.placed.map(|p| Placed::disc(p.point, 0.6));
            }
            seen
        };
        let landmarks = frame(&FIELD[..4]);
        let loose = seen(0.3);
        let placed: Vec<Option<Placed>> = loose.1.detections.iter().map(|e| e.placed).collect();
        let registration = register(&placed, &landmarks, &|_, _| true, &[&|_, _| true])
            .expect("the loose fit wins");
        assert_eq!(registration.pairs.len(), 4);
        assert!(registration.nfa >= SIGNIFICANT_NFA, "{}", registration.nfa);
        let decisions = associate_station(&loose, std::slice::from_ref(&landmarks));
        assert!(
            decisions.iter().all(|d| !matches!(d, Decision::Matched(_))),
            "{decisions:?}"
        );
        let decisions = associate_station(&seen(0.05), &[landmarks]);
        assert_eq!(decisions, (0..4).map(Decision::Matched).collect::<Vec<_>>());
    }

    #[test]
    fn a_registration_left_alone_once_pairs_are_dropped_is_judged_alone() {
        // Two frames registered; the second lost its pairs to detections without a placement
        // and was dropped. The first, a 4-pair fit no more surprising than chance, is now the
        // station's only registration and is not believed; beside a second one it would be.
        let (first, second) = (frame(&FIELD[..4]), frame(&FIELD[..5]));
        let loose = Registration {
            pairs: (0..4).map(|l| (l, l as LandmarkId)).collect(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.8,
        };
        let left = |registrations: Vec<(&Frame, Registration)>| {
            believed(registrations, &[first.clone(), second.clone()]).len()
        };
        assert_eq!(left(vec![(&first, loose.clone())]), 0);
        assert_eq!(
            left(vec![(&first, loose.clone()), (&second, loose.clone())]),
            2
        );
        let significant = Registration {
            nfa: 0.001,
            ..loose
        };
        assert_eq!(left(vec![(&first, significant)]), 1);
    }

    /// A lone registration of many pairs needs no small NFA, but one that chance explains
    /// (NFA ≥ 1: as many fits as tight expected from the hypotheses tried) is not believed,
    /// alone or beside another.
    #[test]
    fn a_registration_that_chance_explains_is_not_believed_whatever_its_size() {
        let (only, other) = (frame(&FIELD), frame(&FIELD[..1]));
        let large = |nfa: f64| Registration {
            pairs: (0..6).map(|l| (l, l as LandmarkId)).collect(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa,
        };
        let left = |registration: Registration| {
            believed(vec![(&only, registration)], &[only.clone(), other.clone()]).len()
        };
        assert_eq!(left(large(0.5)), 1);
        assert_eq!(left(large(1.5e4)), 0);
        let kept = believed(
            vec![(&only, large(1.5e4)), (&other, large(0.5))],
            &[only.clone(), other.clone()],
        );
        assert_eq!(
            kept.len(),
            1,
            "beside another registration it is dropped too"
        );
        assert_eq!(kept[0].1.nfa, 0.5);
    }

    /// A station's only registration that three other frames could have confirmed, and none
    /// did, is a chance fit of look-alikes unless its fit is significant on its own.
    #[test]
    fn a_lone_registration_the_other_frames_miss_is_believed_only_if_significant() {
        let only = frame(&FIELD);
        let others = [frame(&FIELD), frame(&FIELD), frame(&FIELD)];
        let frames: Vec<Frame> = std::iter::once(only.clone()).chain(others).collect();
        let lone = |nfa: f64| Registration {
            pairs: (0..6).map(|l| (l, l as LandmarkId)).collect(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa,
        };
        let left =
            |registration: Registration| believed(vec![(&only, registration)], &frames).len();
        assert_eq!(left(lone(0.5)), 0);
        assert_eq!(left(lone(SIGNIFICANT_NFA / 2.0)), 1);
        // With two other frames that could confirm it, the same fit stands either way.
        let few =
            |registration: Registration| believed(vec![(&only, registration)], &frames[1..3]).len();
        assert_eq!(few(lone(0.5)), 1);
    }

    #[test]
    fn a_pair_the_sketch_places_far_apart_or_crowded_is_no_anchor() {
        // A station's frame pairs detection 0 with landmark 0. The sketch registered too and
        // left the pair out: abstention if its motion puts the detection near the landmark,
        // doubt if it puts it 19 m away (the two registrations disagree on where the rover is).
        let placed = [Some(at(FIELD[0]))];
        let candidates = vec![vec![(0, 0.1)]];
        let station_frame = frame(&[FIELD[0]]);
        let by_frame = Registration {
            pairs: vec![(0, 0)],
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let sketch = |q: [f64; 2]| Frame {
            accumulated: true,
            landmarks: vec![(0, at(q))],
            departed: Vec::new(),
            tracks: Vec::new(),
            unmapped: Vec::new(),
        };
        let by_sketch = Registration {
            pairs: Vec::new(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let near = sketch([3.5, 1.0]);
        let registrations = [
            (&station_frame, by_frame.clone()),
            (&near, by_sketch.clone()),
        ];
        assert_eq!(
            anchors(&registrations, &candidates, &placed, &[false], 1, false),
            vec![(0, 0, 0.1)]
        );
        let far = sketch([20.0, 10.0]);
        let registrations = [
            (&station_frame, by_frame.clone()),
            (&far, by_sketch.clone()),
        ];
        assert!(anchors(&registrations, &candidates, &placed, &[false], 1, false).is_empty());
        // Near, but the sketch knows another landmark where the detection is: doubt, in colour
        // mode. A rock it saw and did not map there is no landmark, and leaves it abstaining.
        let crowded = Frame {
            landmarks: vec![(0, at([3.5, 1.0])), (1, at([3.2, 0.8]))],
            ..sketch([3.5, 1.0])
        };
        let registrations = [
            (&station_frame, by_frame.clone()),
            (&crowded, by_sketch.clone()),
        ];
        assert!(anchors(&registrations, &candidates, &placed, &[false], 1, false).is_empty());
        assert_eq!(
            anchors(&registrations, &candidates, &placed, &[false], 1, true),
            vec![(0, 0, 0.1)],
            "by luminance the sketch abstains"
        );
        let unmapped = Frame {
            unmapped: vec![at([3.2, 0.8])],
            ..sketch([3.5, 1.0])
        };
        let registrations = [(&station_frame, by_frame), (&unmapped, by_sketch)];
        assert_eq!(
            anchors(&registrations, &candidates, &placed, &[false], 1, false),
            vec![(0, 0, 0.1)]
        );
    }

    /// A far rock's detection, placed 3 m deep along its bearing, anchors to the landmark two
    /// station frames pair it with, unless one of them knows another rock within its reach:
    /// another landmark, or a rock it saw and did not map.
    #[test]
    fn a_far_rock_anchors_where_two_station_frames_know_no_other_rock_it_may_be() {
        let placed = [Some(Placed::along([10.0, 0.0], 0.0, 3.0, 0.1))];
        let candidates = vec![vec![(0, 0.1)]];
        let pairing = Registration {
            pairs: vec![(0, 0)],
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let landmark = frame(&[[10.0, 0.0]]);
        let anchored = |second: &Frame| {
            let registrations = [(&landmark, pairing.clone()), (second, pairing.clone())];
            !anchors(&registrations, &candidates, &placed, &[false], 1, false).is_empty()
        };
        assert!(anchored(&landmark));
        assert!(anchors(
            &[(&landmark, pairing.clone())],
            &candidates,
            &placed,
            &[false],
            1,
            false
        )
        .is_empty());
        assert!(!anchored(&frame(&[[10.0, 0.0], [12.0, 0.0]])));
        let unmapped = |point: [f64; 2]| Frame {
            unmapped: vec![at(point)],
            ..frame(&[[10.0, 0.0]])
        };
        assert!(!anchored(&unmapped([12.0, 0.0])));
        assert!(anchored(&unmapped([15.0, 0.0])));
        // Unless another detection of the station lies at the unmapped rock: it is that one's.
        let beside_it = |other: [f64; 2]| {
            let registrations = [
                (&landmark, pairing.clone()),
                (&unmapped([12.0, 0.0]), pairing.clone()),
            ];
            let placed = [placed[0], Some(Placed::along(other, 0.0, 0.3, 0.1))];
            !anchors(
                &registrations,
                &candidates,
                &placed,
                &[false, false],
                1,
                false,
            )
            .is_empty()
        };
        assert!(beside_it([12.2, 0.0]));
        assert!(!beside_it([20.0, 0.0]), "the other detection is elsewhere");
        // A detection placed within 2 m anchors on one frame's pairing.
        let near = [Some(Placed::along([10.0, 0.0], 0.0, 1.5, 0.1))];
        assert!(!anchors(
            &[(&landmark, pairing.clone())],
            &candidates,
            &near,
            &[false],
            1,
            false
        )
        .is_empty());
        // A detection the detector doubts anchors, however near, only as a far rock does.
        let doubtful = |registrations: &[(&Frame, Registration)]| {
            !anchors(registrations, &candidates, &near, &[true], 1, false).is_empty()
        };
        assert!(!doubtful(&[(&landmark, pairing.clone())]));
        assert!(doubtful(&[
            (&landmark, pairing.clone()),
            (&landmark, pairing.clone())
        ]));
        let beside = frame(&[[10.0, 0.0], [11.0, 0.0]]);
        assert!(!doubtful(&[
            (&landmark, pairing.clone()),
            (&beside, pairing)
        ]));
    }

    /// By luminance an observer placed within 2 m anchors on the sketch's pairing alone where no
    /// station's frame holds the landmark, unless the sketch knows another rock within its
    /// reach; a far one, one only a station's frame pairs, or one seen in colour does not.
    #[test]
    fn a_near_observer_anchors_on_the_sketch_alone_by_luminance() {
        let candidates = vec![vec![(0, 0.1)]];
        let pairing = Registration {
            pairs: vec![(0, 0)],
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa: 0.0,
        };
        let sketch = |points: &[[f64; 2]]| Frame {
            accumulated: true,
            ..frame(points)
        };
        let anchored = |registrations: &[(&Frame, Registration)], reach: f64, luminance: bool| {
            let placed = [Some(Placed::along([10.0, 0.0], 0.0, reach, 0.1))];
            !anchors(registrations, &candidates, &placed, &[true], 1, luminance).is_empty()
        };
        let alone = |frame: &Frame, reach: f64| anchored(&[(frame, pairing.clone())], reach, true);
        assert!(alone(&sketch(&[[10.0, 0.0]]), 1.5));
        assert!(!alone(&sketch(&[[10.0, 0.0]]), 3.0), "a far observer");
        assert!(
            !alone(&sketch(&[[10.0, 0.0], [11.0, 0.0]]), 1.5),
            "another landmark within its reach"
        );
        assert!(
            !alone(&frame(&[[10.0, 0.0]]), 1.5),
            "a station's frame alone"
        );
        assert!(
            !anchored(&[(&sketch(&[[10.0, 0.0]]), pairing.clone())], 1.5, false),
            "in colour"
        );
        // A station's frame that holds the landmark and leaves the pair out doubts it.
        let silent = Registration {
            pairs: Vec::new(),
            ..pairing.clone()
        };
        assert!(!anchored(
            &[
                (&sketch(&[[10.0, 0.0]]), pairing.clone()),
                (&frame(&[[10.0, 0.0]]), silent)
            ],
            1.5,
            true
        ));
    }

    /// A detection the detector doubts (a piece cut at a shallow notch, or beside a nearer
    /// piece) founds no landmark.
    #[test]
    fn a_doubtful_detection_founds_no_landmark() {
        let (_, mut station) = station(&[[5.0, 0.0], [0.0, 6.0], [-4.0, -3.0]]);
        station.detections[1].doubtful = true;
        only_the_second_founds_none(station, Unfounded::Doubtful);
    }

    #[test]
    fn a_registration_left_with_too_few_pairs_anchors_nothing() {
        // Six look-alikes register, each detection a little off its landmark. Unplaced
        // detections lie in the directions of landmarks 0, 1 and 2, which may be those rocks:
        // their pairs are dropped, and the three pairs left are too few to trust the motion.
        // With only two such directions, the four pairs left anchor.
        let offset: Vec<[f64; 2]> = FIELD
            .iter()
            .enumerate()
            .map(|(k, p)| {
                // 10 cm across the line of sight, alternately either way.
                let side = if k % 2 == 0 { 0.1 } else { -0.1 };
                let r = p[0].hypot(p[1]);
                [p[0] - side * p[1] / r, p[1] + side * p[0] / r]
            })
            .collect();
        let mut station = station(&offset);
        station.1.unused = FIELD[..3].iter().map(|&p| toward(p)).collect();
        let decisions = associate_station(&station, &[frame(&FIELD)]);
        assert!(
            decisions.iter().all(|d| !matches!(d, Decision::Matched(_))),
            "{decisions:?}"
        );
        station.1.unused.truncate(2);
        let decisions = associate_station(&station, &[frame(&FIELD)]);
        for (i, decision) in decisions.iter().enumerate().skip(2) {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
    }

    /// Seen from the other side, every rock's texture and shaded share differ from its
    /// landmark's, while its colour does not: the whole descriptor proposes no look-alike, and
    /// colour alone registers the frame. Without colour the station is not registered.
    #[test]
    fn rocks_seen_from_another_side_register_by_colour_alone() {
        let mut station = station(&FIELD);
        for detection in &mut station.1.detections {
            detection.appearance = Appearance {
                texture: 0.6,
                dark_fraction: 0.7,
                ..look()
            };
        }
        let decisions = associate_station(&station, &[frame(&FIELD)]);
        for (i, decision) in decisions.iter().enumerate() {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
        station.1.colour = false;
        let decisions = associate_station(&station, &[frame(&FIELD)]);
        assert!(
            decisions.iter().all(|d| !matches!(d, Decision::Matched(_))),
            "{decisions:?}"
        );
    }

    #[test]
    fn registered_landmarks_are_matched_and_a_lone_look_alike_is_held_back() {
        // Landmark 6 lies where the motion puts detection 6, but just as near detection 7 (a
        // rock of another look): registration leaves it unanchored, placement and the empty
        // map cannot reject it, and a pass is no evidence. Detection 7 has no look-alike, but
        // the unanchored landmark 6 lies where it is: it may be that rock, so it is not new.
        let mut points = FIELD.to_vec();
        points.extend([[-1.0, 9.0], [-1.5, 9.0]]);
        let mut station = station(&points);
        station.1.detections[7].appearance = other_look();
        let mut landmarks = FIELD.to_vec();
        landmarks.push([-1.25, 9.0]);
        let decisions = associate_station(&station, &[frame(&landmarks)]);
        for (i, decision) in decisions.iter().take(6).enumerate() {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
        assert_eq!(decisions[6], Decision::HeldBack(vec![6]));
        assert_eq!(decisions[7], Decision::HeldBack(vec![6]));
    }

    /// The station seeing FIELD's rocks and rocks at `more`, all alike.
    fn field_and(more: &[[f64; 2]]) -> (Gallery, StationEvidence) {
        station(&[&FIELD[..], more].concat())
    }

    /// The sketch holding FIELD's rocks and rocks at `more` as landmarks 0, 1, ….
    fn sketch_of_field_and(more: &[[f64; 2]]) -> Frame {
        Frame {
            accumulated: true,
            ..frame(&[&FIELD[..], more].concat())
        }
    }

    #[test]
    fn a_detection_on_a_track_apart_from_every_landmark_founds_a_landmark() {
        // Detection 6 looks like landmark 6, 1.4 m from it: not near enough to anchor, but
        // within the sketch's slack, so it is held back. Once the sketch has followed an
        // unmapped rock where the detection lies, it is that rock, and new. A track that does
        // not hold the detection decides nothing.
        let station = field_and(&[[-1.0, 9.0]]);
        let mut sketch = sketch_of_field_and(&[[0.4, 9.0]]);
        let decisions = associate_station(&station, std::slice::from_ref(&sketch));
        assert_eq!(decisions[6], Decision::HeldBack(vec![6]));
        sketch.tracks = vec![Tracked {
            placed: at([-1.0, 9.0]),
            landmark: None,
        }];
        let decisions = associate_station(&station, std::slice::from_ref(&sketch));
        for (i, decision) in decisions.iter().take(6).enumerate() {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
        assert_eq!(decisions[6], Decision::New);
        sketch.tracks = vec![Tracked {
            placed: at([-1.0, 7.0]),
            landmark: None,
        }];
        let decisions = associate_station(&station, std::slice::from_ref(&sketch));
        assert_eq!(decisions[6], Decision::HeldBack(vec![6]));
    }

    #[test]
    fn a_whole_detection_on_a_landmarks_track_is_matched_and_a_piece_held_back() {
        // Detection 6 looks like landmark 6, 1.1 m from it, but landmark 7 lies 1.2 m from it:
        // not clearly farther, so the pair does not anchor and the detection is held back. The
        // sketch followed something held back where the detection lies, and the track fits
        // landmark 6 alone: the detection is that rock. A piece's placement spans its
        // neighbour, so a piece stays held back.
        let mut station = field_and(&[[-1.0, 9.0]]);
        let mut sketch = sketch_of_field_and(&[[0.1, 9.0], [-1.0, 10.2]]);
        let decisions = associate_station(&station, std::slice::from_ref(&sketch));
        assert_eq!(decisions[6], Decision::HeldBack(vec![6]));
        sketch.tracks = vec![Tracked {
            placed: at([-0.9, 9.0]),
            landmark: Some(6),
        }];
        let decisions = associate_station(&station, std::slice::from_ref(&sketch));
        for (i, decision) in decisions.iter().enumerate() {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
        station.1.detections[6].piece = true;
        let decisions = associate_station(&station, std::slice::from_ref(&sketch));
        assert!(
            matches!(decisions[6], Decision::HeldBack(_)),
            "{decisions:?}"
        );
    }

    #[test]
    fn a_detection_where_an_unaccounted_landmark_lies_is_not_new() {
        // Detection 6 looks like no landmark (a piece of a rock, a lit face), but the motion
        // puts it where landmark 6 lies, which no detection is anchored to: a new landmark
        // would duplicate it. Away from every landmark, detection 7 is new.
        let mut points = FIELD.to_vec();
        points.extend([[-1.0, 9.0], [4.0, -9.0]]);
        let mut station = station(&points);
        for detection in &mut station.1.detections[6..] {
            detection.appearance = other_look();
        }
        let mut landmarks = FIELD.to_vec();
        landmarks.push([-1.2, 9.0]);
        let decisions = associate_station(&station, &[frame(&landmarks)]);
        for (i, decision) in decisions.iter().take(6).enumerate() {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
        assert_eq!(decisions[6], Decision::HeldBack(vec![6]));
        assert_eq!(decisions[7], Decision::New);
    }

    #[test]
    fn a_fit_of_four_that_puts_undetected_landmarks_in_view_anchors_nothing() {
        // The motion pairs four detections, but puts the frame's landmarks 2 and 5 about 7 m
        // from the station in directions where it detected nothing: a chance fit.
        let seen = [FIELD[0], FIELD[1], FIELD[3], FIELD[4]];
        let decisions = associate_station(&station(&seen), &[frame(&FIELD)]);
        assert!(
            decisions.iter().all(|d| !matches!(d, Decision::Matched(_))),
            "{decisions:?}"
        );
        // With rock 2 detected too, five pairs and one landmark missing: the motion stands.
        let seen = [FIELD[0], FIELD[1], FIELD[2], FIELD[3], FIELD[4]];
        let decisions = associate_station(&station(&seen), &[frame(&FIELD)]);
        assert_eq!(decisions, (0..5).map(Decision::Matched).collect::<Vec<_>>());
    }

    #[test]
    fn a_registration_without_a_landmark_seen_lately_anchors_nothing() {
        // The rover lost sight of every landmark of the frame: six look-alikes are a loop
        // closure on looks alone. With one of them seen lately, the same fit anchors all six.
        let station = station(&FIELD);
        let decisions = associate_after(&station, &[frame(&FIELD)], &|_| false);
        assert!(
            decisions.iter().all(|d| !matches!(d, Decision::Matched(_))),
            "{decisions:?}"
        );
        let decisions = associate_after(&station, &[frame(&FIELD)], &|l| l == 3);
        assert_eq!(decisions, (0..6).map(Decision::Matched).collect::<Vec<_>>());
    }

    /// A station's only registration, exact and so significant, anchors though three other
    /// frames holding its landmarks do not repeat it (a loose one would not:
    /// `a_lone_registration_the_other_frames_miss_is_believed_only_if_significant`).
    #[test]
    fn a_significant_lone_registration_anchors_though_other_frames_do_not_repeat_it() {
        // The later frames hold the same landmarks, placed too close together to register.
        let shrunk = FIELD.map(|p| [0.2 * p[0], 0.2 * p[1]]);
        let station = station(&FIELD);
        let two = [frame(&FIELD), frame(&shrunk), frame(&shrunk)];
        let decisions = associate_station(&station, &two);
        for (i, decision) in decisions.iter().enumerate() {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
        let three = [
            frame(&FIELD),
            frame(&shrunk),
            frame(&shrunk),
            frame(&shrunk),
        ];
        let decisions = associate_station(&station, &three);
        for (i, decision) in decisions.iter().enumerate() {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
    }

    #[test]
    fn a_pair_most_frames_holding_its_landmark_reject_is_no_anchor() {
        // Two later frames place landmark 0 far from detection 0: only one of three agrees.
        let mut moved = FIELD;
        moved[0] = [-9.0, 9.0];
        let frames = [frame(&FIELD), frame(&moved), frame(&moved)];
        let decisions = associate_station(&station(&FIELD), &frames);
        assert_ne!(decisions[0], Decision::Matched(0));
        for (i, decision) in decisions.iter().enumerate().skip(1) {
            assert_eq!(*decision, Decision::Matched(i as LandmarkId));
        }
    }

    #[test]
    fn a_pair_only_a_chance_fit_makes_is_overruled_by_a_significant_fit_that_leaves_it_out() {
        // A station frame's chance fit pairs detection 0 with landmark 0; the sketch holds
        // landmark 0 and leaves the pair out, which on its own is abstention.
        let station_frame = frame(&FIELD);
        let sketch = Frame {
            accumulated: true,
            ..frame(&FIELD)
        };
        let registration = |pairs: &[(usize, LandmarkId)], nfa: f64| Registration {
            pairs: pairs.to_vec(),
            motion: [1.0, 0.0, 0.0, 0.0],
            nfa,
        };
        let chance = registration(&[(0, 0), (1, 1), (2, 2), (3, 3)], 0.87);
        let sketched = |nfa: f64| registration(&[(1, 1), (2, 2), (3, 3)], nfa);
        let candidates: Vec<Vec<(LandmarkId, f64)>> =
            (0..4).map(|i| vec![(i as LandmarkId, 0.1)]).collect();
        let placed: Vec<Option<Placed>> = FIELD[..4].iter().map(|&p| Some(at(p))).collect();
        let anchored = |registrations: &[(&Frame, Registration)]| -> Vec<usize> {
            anchors(registrations, &candidates, &placed, &[false; 4], 1, false)
                .iter()
                .map(|a| a.0)
                .collect()
        };
        // A significant sketch fit outweighs the chance fit.
        let overruling = [(&station_frame, chance.clone()), (&sketch, sketched(0.007))];
        assert!(overruled(&overruling, 0, 0));
        assert_eq!(anchored(&overruling), [1, 2, 3]);
        // A sketch fit that chance may explain abstains.
        let abstaining = [(&station_frame, chance.clone()), (&sketch, sketched(0.5))];
        assert!(!overruled(&abstaining, 0, 0));
        assert_eq!(anchored(&abstaining), [0, 1, 2, 3]);
        // A significant fit that makes the pair stands against one that leaves it out.
        let significant_too = [
            (&station_frame, registration(&chance.pairs, 0.005)),
            (&sketch, sketched(0.007)),
        ];
        assert!(!overruled(&significant_too, 0, 0));
        assert_eq!(anchored(&significant_too), [0, 1, 2, 3]);
    }
}
