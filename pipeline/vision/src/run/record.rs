//! What `pipeline run` reports about each panorama: the record every output (`run.mcap`, the
//! rerun recording, the summary) is written from. Plain data, serialised as JSON; the field
//! meanings are documented in `docs/RUN.md`.

use crate::association::Unfounded;
use crate::ranging::RangeInterval;
use qrm_core::map::LandmarkId;
use qrm_core::measurement::RangeBounds;
use serde::{Deserialize, Serialize};

/// Everything the run learned from one station's panorama(s).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StationRecord {
    /// Position of the station in the run, from 0.
    pub index: usize,
    /// Station name (the image file name without `_left`/`_right` and extension).
    pub station: String,
    /// Image files read for this station (left first), relative to the image directory.
    pub files: Vec<String>,
    /// Fingerprints of `files`, in order (`survey::digest`; empty when unknown): scoring
    /// checks them against `truth.json`'s.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub digests: Vec<String>,
    /// What told rocks from the ground in its panorama: `colour`, or `luminance` (and stereo
    /// height) for grayscale, JPEG or noisy-colour panoramas.
    #[serde(default)]
    pub channels: crate::detection::Channels,
    /// Detections in the primary (left or mono) panorama, in column order.
    pub detections: Vec<DetectionRecord>,
    /// The asserted "nearer than" pairs `(i, j)`: detection `i` is nearer than detection `j`.
    pub order: Vec<(usize, usize)>,
    /// Every earlier frame its detections registered against, believed or not: why they were
    /// anchored or held back (000 §VI-C).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub registrations: Vec<RegistrationRecord>,
    /// The outcome of fusing this panorama into the map.
    pub fusion: FusionRecord,
    /// The map after this panorama.
    pub metrics: MetricsRecord,
    /// Wall time of each stage for this station, seconds.
    pub seconds: StageSeconds,
    /// Warnings about this station (skipped images, too few detections, …).
    pub warnings: Vec<String>,
}

/// One registration of a station's detections against a frame: the rigid motion fitted to
/// detections and landmarks that look alike (`association::register`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RegistrationRecord {
    /// The station whose frame it registered against; `None` for the sketch of recent
    /// stations' landmarks (`association::Sketch`).
    pub frame: Option<usize>,
    /// `(detection, landmark)` pairs, detections numbered as in `detections`: those matches
    /// were drawn from when believed (its anchors, and the detections it placed on a
    /// landmark's track, `association::Tracked`), else the fit's own.
    pub pairs: Vec<(usize, LandmarkId)>,
    /// The fit's number of false alarms: how many fits as tight the hypotheses tried would
    /// give by chance (`association::significance`); `null` in JSON when unbounded.
    pub nfa: Option<f64>,
    /// Whether association believed it (NFA below 1, enough pairs left, and not a lone fit
    /// other frames should have confirmed): only a believed registration's pairs can anchor.
    pub believed: bool,
}

/// One detection, its bearing, its range evidence and what association decided.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DetectionRecord {
    /// `[col_min, row_min, col_max, row_max]`, inclusive; `col_max ≥ width` when it wraps.
    pub bbox: [u32; 4],
    /// Centroid `(column, row)` in the primary panorama.
    pub centroid: [f64; 2],
    /// Row of the ground contact.
    pub contact_row: f64,
    /// Rows below `contact_row` the true contact may lie (luminance mode: a rock's lowest rows
    /// cannot be told from the ground by stereo).
    #[serde(default)]
    pub contact_slack_rows: f64,
    pub pixels: u32,
    /// By colour with stereo, nothing of it stands up from the ground
    /// ([`crate::detection::Detection::flat`]): never fused on later stations' recognitions.
    #[serde(default)]
    pub flat: bool,
    /// Centroid column of the matched detection in the right panorama, if any.
    pub stereo_column: Option<f64>,
    /// Bearing from the station centre, radians counter-clockwise from the calibration's zero.
    pub bearing: f64,
    /// Half-width of the bearing interval the map measures with, radians
    /// (`ranging::Ranged::measured_bearing`).
    pub bearing_uncertainty: f64,
    /// Range intervals (metres) from each cue that applied, and their fusion.
    pub range: RangeRecord,
    pub association: Association,
}

/// Range evidence for one detection: `[low, high]` in metres; an unbounded `high` is written
/// `null` (JSON has no infinity).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RangeRecord {
    #[serde(with = "optional_bounds")]
    pub ground: Option<[f64; 2]>,
    #[serde(with = "optional_bounds")]
    pub stereo: Option<[f64; 2]>,
    #[serde(with = "optional_bounds")]
    pub size: Option<[f64; 2]>,
    #[serde(with = "bounds")]
    pub fused: [f64; 2],
    /// The cues' intervals did not overlap; `fused` is then their hull.
    pub conflict: bool,
}

impl RangeRecord {
    /// The bounds the map measured the detection's range ratios with
    /// ([`crate::ranging::ratio_bounds`]).
    pub fn ratio_bounds(&self) -> RangeBounds {
        let interval = |b: [f64; 2]| RangeInterval::new(b[0], b[1]);
        crate::ranging::corroborated_bounds(self.ground.map(interval), self.stereo.map(interval))
    }
}

/// What data association decided for one detection (000 §VI-C).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "decision", rename_all = "snake_case")]
pub enum Association {
    /// The detection is map landmark `landmark`.
    Matched { landmark: u32 },
    /// No landmark is consistent with it: a new landmark.
    New { landmark: u32 },
    /// Several landmarks remain possible: the observation is held back.
    HeldBack { candidates: Vec<u32> },
    /// Not used for mapping: `reason` says why, absent when the detection was usable but its
    /// panorama added nothing (fewer than three usable detections, or the map rejected it).
    Unused {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        reason: Option<Exclusion>,
    },
}

impl Default for Association {
    fn default() -> Association {
        Association::Unused { reason: None }
    }
}

/// Why mapping leaves a detection out (`selection::exclusion`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Exclusion {
    /// Behind a nearer rock it was told apart from by parallax, which may hide some of it:
    /// written by runs before such parts were used (stop 35), and kept so that their
    /// `stations.json` still reads.
    Behind,
    /// The detector doubts it is one whole rock (a piece cut at a shallow notch, a top without
    /// its body, or no stereo to tell it from a shadow), and it matched no landmark: a doubted
    /// detection founds none. (Runs before stop 54 left such detections out in luminance
    /// mode.)
    Doubted,
    /// Matched no landmark and placed too loosely to found one (a far rock whose range
    /// interval spans metres: `association::unfounded`).
    Loose,
    /// Surely flat by stereo (`Detection::surely_flat`: nothing of it stands up where the test
    /// tells a standing rock from the ground, and half or more of it matched at the ground's
    /// shift: a soil patch or a shadow), and it matched no landmark: such a detection founds
    /// none (`association::unfounded`). A merely flat one, maybe a rock too smooth or far to
    /// tell, still founds.
    Flat,
    /// Narrower than a 512th of the view: mostly pieces of larger rocks.
    Sliver,
    /// Matched no landmark and too small to found one (`association::MIN_FOUNDING_PIXELS`).
    Small,
    /// Taller than wide: a farther rock seen over a nearer one.
    Stacked,
    /// A piece, its box meeting another detection's (two rocks, or one rock in two pieces),
    /// and it matched no landmark: a piece founds none. (Runs before stop 54 left such
    /// detections out in luminance mode.)
    Touching,
    /// Its bearing interval is too wide to measure with.
    WideBearing,
}

/// A detection that matched no landmark and founds none is recorded unused, for its reason.
impl From<Unfounded> for Exclusion {
    fn from(why: Unfounded) -> Exclusion {
        match why {
            Unfounded::Piece => Exclusion::Touching,
            Unfounded::Doubtful => Exclusion::Doubted,
            Unfounded::Small => Exclusion::Small,
            Unfounded::Loose => Exclusion::Loose,
            Unfounded::Flat => Exclusion::Flat,
        }
    }
}

/// The outcome of fusing one panorama.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FusionRecord {
    /// Detections usable for mapping (not doubted by the detector or by ranging).
    #[serde(default)]
    pub usable: usize,
    /// Landmarks whose triples were measured.
    pub landmarks: usize,
    /// Triples measured.
    pub triples: usize,
    /// Relations the update tightened.
    pub relations_tightened: usize,
    /// Held-back observations of earlier panoramas resolved and fused at this station.
    pub resolved_held_back: usize,
    /// Held-back observations of earlier panoramas that a detection of this one recognised
    /// (`association::recognition`) and that were fused as its landmark. The earlier
    /// station's record keeps the decision made when it was mapped.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub recognised: Vec<LateSighting>,
    /// Detections of earlier stalled panoramas (whose detections registered against nothing
    /// and were all given up) fused once this one gave them frames to register against
    /// (`Mapper::revisit_stalled`). The earlier station's record keeps its first decisions.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub revisited: Vec<LateSighting>,
    /// Why the map rejected the panorama, if it did.
    pub contradiction: Option<String>,
    /// Landmarks found, once this panorama was fused, to mix rocks, and split.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub splits: Vec<SplitRecord>,
}

/// A held-back detection fused at a later station: detection `detection` (index into the
/// station's detections) of station `station` is landmark `landmark`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LateSighting {
    pub station: usize,
    pub detection: usize,
    pub landmark: LandmarkId,
}

/// A landmark whose sightings at two stations disagreed on where it is, split into the rocks
/// its sightings show (`association::audit`): the stations of `groups[0]` keep `landmark`,
/// those of each further group saw `new_landmarks` (in order), and the sightings of `retired`
/// stations left the map. `landmarks.json` has the sightings as split; a station's record
/// keeps the decision made when it was mapped.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SplitRecord {
    pub landmark: LandmarkId,
    pub new_landmarks: Vec<LandmarkId>,
    pub groups: Vec<Vec<usize>>,
    pub retired: Vec<usize>,
}

/// Two landmarks found to be one rock once the drive was over (`association::duplicate`): the
/// sightings of `duplicate` joined `landmark`, from `frame_pairs` pairs of stations whose
/// frames put the two on each other. `landmarks.json` has the sightings as merged; a station's
/// record keeps the decision made when it was mapped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct MergeRecord {
    pub landmark: LandmarkId,
    pub duplicate: LandmarkId,
    pub frame_pairs: usize,
}

/// The map after a panorama.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MetricsRecord {
    pub landmarks: usize,
    pub triples: usize,
    /// Open states, fraction of all states of the map's triples.
    pub open_fraction: f64,
    /// Triples whose three relations are single states, fraction of the map's triples.
    pub fully_constrained_fraction: f64,
    /// RNG edges the map proves (cost 0), and edges still uncertain.
    pub rng_certain: usize,
    pub rng_uncertain: usize,
    /// `Σ w_ij` of Algorithm 2.
    pub rng_cost: f64,
}

/// Wall time per stage, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StageSeconds {
    pub decode: f64,
    pub detect: f64,
    pub range: f64,
    pub associate: f64,
    pub map: f64,
    /// The map's metrics and RNG estimate after the station (Algorithm 2 over every pair).
    #[serde(default)]
    pub metrics: f64,
    /// Handing the station to the recorders (run.mcap, run.rrd, with the RNG's layout): 0,
    /// and not written, in the record the recorders get (it is timed around them).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub recording: f64,
}

fn is_zero(seconds: &f64) -> bool {
    *seconds == 0.0
}

/// `[low, high]` with an infinite `high` as `null`.
mod bounds {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(value: &[f64; 2], s: S) -> Result<S::Ok, S::Error> {
        (value[0], value[1].is_finite().then_some(value[1])).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
        let (low, high) = <(f64, Option<f64>)>::deserialize(d)?;
        Ok([low, high.unwrap_or(f64::INFINITY)])
    }
}

mod optional_bounds {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(value: &Option<[f64; 2]>, s: S) -> Result<S::Ok, S::Error> {
        value
            .map(|v| (v[0], v[1].is_finite().then_some(v[1])))
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
        let value = <Option<(f64, Option<f64>)>>::deserialize(d)?;
        Ok(value.map(|(low, high)| [low, high.unwrap_or(f64::INFINITY)]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unbounded_ranges_round_trip_through_json() {
        let record = RangeRecord {
            ground: Some([2.0, f64::INFINITY]),
            stereo: None,
            size: Some([1.0, 3.0]),
            fused: [2.0, f64::INFINITY],
            conflict: false,
        };
        let text = serde_json::to_string(&record).unwrap();
        assert!(text.contains("null"), "{text}");
        assert_eq!(serde_json::from_str::<RangeRecord>(&text).unwrap(), record);
    }

    /// A record bounds its ratios as the run measured them: by the two cues where both range
    /// the detection and agree, not by one cue alone, nor by the size cue.
    #[test]
    fn a_record_bounds_range_ratios_only_where_ground_and_stereo_agree() {
        let record = |ground, stereo| RangeRecord {
            ground,
            stereo,
            size: Some([4.5, 5.5]),
            fused: [0.0, f64::INFINITY],
            conflict: false,
        };
        let both = record(Some([4.0, 6.0]), Some([5.0, 7.0])).ratio_bounds();
        assert_eq!((both.low, both.high), (5.0, 6.0));
        for (ground, stereo) in [
            (Some([4.0, 6.0]), None),
            (None, Some([5.0, 7.0])),
            (Some([4.0, 4.5]), Some([5.0, 7.0])),
        ] {
            assert_eq!(
                record(ground, stereo).ratio_bounds(),
                RangeBounds::UNBOUNDED
            );
        }
    }
}
