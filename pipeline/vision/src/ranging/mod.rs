//! Bearings and range evidence of one station's detections (000 §IV assumptions 1–2), and the
//! partial range order they support.
//!
//! Three cues bound each landmark's horizontal range from the station centre, each with an
//! interval that covers the truth within the [`SensorModel`]:
//! - **flat ground**: the row of the ground contact gives the range of the rock's near edge;
//!   its reference point lies beyond that by at most a fraction of its apparent width;
//! - **stereo parallax**: the azimuth difference between the left and right panoramas of the
//!   rotating head, `2·asin(b / 2d)` ([`Calibration::stereo_range`]);
//! - **apparent size**: once a landmark's physical width is bounded by earlier stations, its
//!   apparent width bounds its range (sizes are only compared with the same rock's).
//!
//! The fused interval is their intersection; "A nearer than B" is asserted only when A's
//! interval lies entirely below B's, so the order is partial where the evidence is weak.

mod interval;
mod stereo;

pub use interval::RangeInterval;
pub use stereo::match_stereo;

use crate::calib::Calibration;
use crate::detection::{Channels, Detection, Separation};
use qrm_core::measurement::{Bearing, RangeBounds, RangeOrder};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// The error bounds of the vision front end: every interval it produces is widened by these.
/// The defaults are calibrated on the synthetic presets (`docs/RUN.md`, "Figures", gives how
/// often the measured errors stay inside them).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorModel {
    /// Bearing error of a centroid: `px + per_width × apparent width`, in columns. The
    /// centroid of a silhouette moves with the viewpoint by a fraction of the rock's width.
    pub bearing_error_px: f64,
    pub bearing_error_per_width: f64,
    /// By luminance, how much farther a rock's centre may lie from the centroid, as a
    /// fraction of the detection's width: the luminance test can find only a rock's lit
    /// face. Widens the bearings the map and the consistency test measure with
    /// ([`Ranged::measured_bearing`]), not the placements registration pairs by.
    pub lit_face_per_width: f64,
    /// Error of the contact row, rows.
    pub contact_error_px: f64,
    /// How far beyond its ground contact the landmark's reference point may lie, as a multiple
    /// of its apparent physical width.
    pub reach_per_width: f64,
    /// Error of a left–right azimuth difference: `px + per_width × apparent width`, columns.
    pub disparity_error_px: f64,
    pub disparity_error_per_width: f64,
    /// Factor by which a rock's apparent width may differ from its reference width at any
    /// viewpoint: applied when a view bounds the reference width and again when the reference
    /// bounds another view's range, so two views may differ by its square.
    pub size_change: f64,
    /// Nearest range at which rocks are looked for in the right panorama, metres.
    pub min_range_m: f64,
}

impl Default for SensorModel {
    fn default() -> SensorModel {
        SensorModel {
            bearing_error_px: 1.5,
            bearing_error_per_width: 0.15,
            lit_face_per_width: LIT_FACE_PER_WIDTH,
            contact_error_px: 1.5,
            reach_per_width: 0.75,
            disparity_error_px: 1.5,
            disparity_error_per_width: 0.1,
            size_change: 1.6,
            min_range_m: 0.5,
        }
    }
}

/// [`SensorModel::lit_face_per_width`]: on grayscale marsyard s3 and stress s12 (grayscale)
/// 10 of 744 and 23 of 776 fused bearings missed their interval, by up to 3.4 times, where
/// colour marsyard missed 2 of 6 316 (docs/RUN.md, stop 70).
const LIT_FACE_PER_WIDTH: f64 = 0.3;

/// Which camera took the primary panorama: bearings from an eye of the rotating stereo head
/// are offset from the station centre by `asin(b / 2d)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrimaryEye {
    Mono,
    Left,
}

/// The ray a detection was seen along: the rock lies somewhere on it, so its bearing from the
/// station centre depends on how far it is. A detection of the left eye alone is seen from half
/// a baseline beside the centre, where a rock at range `d` lies `asin(b / 2d)` further round:
/// unranged, its bearing interval spans every such offset up to a right angle, and the
/// interval's middle is up to 45° from where the rock was seen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Bearing (radians) from the centre of a rock on the ray far away.
    pub azimuth: f64,
    /// Half the baseline (metres) when seen by the left eye alone, else 0.
    pub half_baseline: f64,
    /// Least range (metres from the centre) its rock can lie at ([`nearest`]): the ray starts
    /// there. 0 when the panorama bounds nothing.
    pub nearest: f64,
    /// Half the azimuth (radians) its blob spans ([`Ranged::angular_width`]; a piece's own
    /// columns, not those it may reach over: a touching neighbour's rock is the neighbour's):
    /// its rock's centre may lie anywhere across it, not only on the ray.
    pub half_width: f64,
}

impl Ray {
    /// The ray from the station centre at `azimuth` (radians).
    fn from_centre(azimuth: f64) -> Ray {
        Ray {
            azimuth: azimuth.rem_euclid(TAU),
            half_baseline: 0.0,
            nearest: 0.0,
            half_width: 0.0,
        }
    }

    /// Bearing from the station centre of the ray's point `range` metres from the centre.
    pub fn direction_at(&self, range: f64) -> f64 {
        (self.azimuth + self.offset_at(range)).rem_euclid(TAU)
    }

    /// How much further round than `azimuth` the ray's point `range` metres from the centre
    /// lies: `asin(b / 2d)` for the left eye, 0 from the centre.
    fn offset_at(&self, range: f64) -> f64 {
        if self.half_baseline > 0.0 {
            (self.half_baseline / range.max(self.half_baseline)).asin()
        } else {
            0.0
        }
    }
}

/// Bearing and range evidence for one detection of the primary panorama.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ranged {
    /// Bearing from the station centre, radians counter-clockwise.
    pub bearing: Bearing,
    /// The ray it was seen along: where it was seen, for a rock at a known range.
    pub ray: Ray,
    /// Centroid column of the matched right-panorama detection.
    pub stereo_column: Option<f64>,
    /// Apparent width, radians of azimuth.
    pub angular_width: f64,
    pub ground: Option<RangeInterval>,
    pub stereo: Option<RangeInterval>,
    pub size: Option<RangeInterval>,
    pub fused: RangeInterval,
    /// The cues did not overlap: `fused` is their hull and no cue is trusted over another.
    pub conflict: bool,
    /// A detection touching it reaches beyond its columns ([`neighbour_reach`]): it may be a
    /// piece of a rock, or a rock with a piece of another. Its bearing interval and ground cue
    /// reach over the neighbour's columns, and its apparent width says nothing of its rock's.
    /// (One whose touching neighbours all lie within its own columns is not a piece.)
    pub piece: bool,
    /// The image's bottom edge cuts it ([`cut_off`]): what shows may be any part of a rock
    /// beside the rover, so its bearing and stereo cue span the rock ([`bearing_of`],
    /// [`stereo_cue`]) and its apparent width bounds nothing.
    pub cut_off: bool,
    /// Radians either side by which the measured bearing widens `bearing`: a luminance
    /// detection's lit-face margin ([`SensorModel::lit_face_per_width`]); 0 in colour.
    pub lit_face: f64,
}

impl Ranged {
    /// The bearing interval that holds the rock's centre, which the map and the qualitative
    /// consistency test measure with; `bearing` is where the rock most likely lies, which
    /// registration places it by.
    pub fn measured_bearing(&self) -> Bearing {
        Bearing {
            uncertainty: self.bearing.uncertainty + self.lit_face,
            ..self.bearing
        }
    }
}

/// Bearings and the flat-ground and stereo cues of `primary` (with `right` for stereo
/// stations). Pure: the same detections always give the same evidence.
pub fn observe(
    primary: &[Detection],
    right: Option<&[Detection]>,
    eye: PrimaryEye,
    channels: Channels,
    calib: &Calibration,
    model: &SensorModel,
) -> Vec<Ranged> {
    let lit_face = match channels {
        Channels::Luminance => model.lit_face_per_width,
        Channels::Auto | Channels::Colour => 0.0,
    };
    let matches = match right {
        Some(right) if eye == PrimaryEye::Left => match_stereo(primary, right, calib, model),
        _ => vec![None; primary.len()],
    };
    let half_baseline = match eye {
        PrimaryEye::Mono => 0.0,
        PrimaryEye::Left => 0.5 * calib.stereo.baseline_m,
    };
    primary
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let columns = apparent_columns(d);
            let angular_width = columns * calib.column_width();
            // A piece touching another may reach under it: its rock's centre and reach are
            // judged over the columns the two cover.
            let reach = neighbour_reach(i, primary, calib.image.width);
            let piece = reach != [0, 0];
            let spread = piece.then(|| Detection {
                beyond_columns: [
                    d.beyond_columns[0].max(reach[0]),
                    d.beyond_columns[1].max(reach[1]),
                ],
                ..d.clone()
            });
            let reach_width = spread.as_ref().map_or(angular_width, |s| {
                let beyond = f64::from(s.beyond_columns[0] + s.beyond_columns[1]);
                (columns + beyond) * calib.column_width()
            });
            let ground = ground_cue(d, i, primary, calib, model, reach_width, half_baseline);
            // By luminance a piece whose ground and stereo cues agree steers registrations
            // (`run::selection::corroborated`), and the luminance detector's pieces are often
            // parts of a rock: given its pixels' shifts wherever it has a ground cue too, JPEG
            // marsyard s47 fell 70.8 → 65.6 % fused (stop 69). Where a nearer detection hides
            // its contact, the shifts are its only range: without them its bearing spans the
            // left eye's offsets at any range and it is left out (`WideBearing`; 122 correct
            // detections on grayscale marsyard s7), with them it observes (stop 81, docs/RUN.md).
            let piece_stereo = piece && (channels != Channels::Luminance || ground.is_none());
            let right_detection = matches[i].zip(right).map(|(j, r)| &r[j]);
            let stereo = right_detection
                .and_then(|r| stereo_cue(d, r, calib, model, angular_width))
                // Pixel shifts stand in for a partner only where none can be had: a separated
                // part, or a piece touching another. A whole detection whose pairing was
                // ambiguous keeps no cue, as `match_stereo` chose (given one, marsyard s19 and
                // stress s10 had 5 and 3 unsound relations, docs/RUN.md stop 66).
                .or_else(|| {
                    parallax_cue(d, calib, model, reach_width)
                        .filter(|_| d.separation != Separation::Whole || piece_stereo)
                });
            let (fused, conflict) = fuse([ground, stereo, None]);
            // The ray is where the detection itself was seen; a piece's bearing takes in the
            // columns it may reach over.
            let (bearing, ray) = bearing_of(d, right_detection, calib, model, half_baseline, fused);
            let bearing = spread.as_ref().map_or(bearing, |s| {
                bearing_of(s, right_detection, calib, model, half_baseline, fused).0
            });
            Ranged {
                bearing,
                ray: Ray {
                    nearest: nearest(i, primary, fused, calib, model),
                    half_width: 0.5 * angular_width,
                    ..ray
                },
                piece,
                cut_off: cut_off(d, calib),
                lit_face: lit_face * angular_width,
                stereo_column: right_detection.map(|r| r.centroid[0]),
                angular_width,
                ground,
                stereo,
                size: None,
                fused,
                conflict,
            }
        })
        .collect()
}

/// Adds the apparent-size cue from a physical width interval known from earlier stations.
pub fn apply_size(ranged: &mut Ranged, width: RangeInterval, model: &SensorModel) {
    if ranged.angular_width <= 0.0 {
        return;
    }
    let size = RangeInterval::new(
        width.low / (model.size_change * ranged.angular_width),
        width.high * model.size_change / ranged.angular_width,
    );
    ranged.size = Some(size);
    let (fused, conflict) = fuse([ranged.ground, ranged.stereo, ranged.size]);
    ranged.fused = fused;
    ranged.conflict = conflict;
}

/// The physical width this detection implies for its rock, widened by the viewpoint factor so
/// that intervals from different stations can be intersected: only ground and stereo evidence
/// count, so the size cue never feeds itself.
pub fn width_evidence(ranged: &Ranged, model: &SensorModel) -> Option<RangeInterval> {
    let (fused, conflict) = fuse([ranged.ground, ranged.stereo, None]);
    (!conflict && fused.high.is_finite() && ranged.angular_width > 0.0).then(|| {
        RangeInterval::new(
            fused.low * ranged.angular_width / model.size_change,
            fused.high * ranged.angular_width * model.size_change,
        )
    })
}

/// What a detection's range interval says to the measurement of its triples' range ratios
/// (`StationView::with_ranges`): the intersection of the flat-ground and stereo cues where
/// both range it and agree; unbounded otherwise. The order needs a cue to miss by a whole gap
/// between two rocks, a ratio bound is broken by any miss, so a ratio is bounded only where two
/// independent cues corroborate each other. Over the 16 sets of docs/RUN.md (10 233 sightings
/// fused) the ground or the stereo cue alone missed the sighting's own rock 16 times, by up to
/// 30 % (rocks within 2 m of the rover; the ground cue of clustered stress rocks). Bounded by
/// either cue alone, triples of landmarks that mix two rocks lost their majority rock's
/// arrangement (7 relations on two sets); by the size cue too, a rock cut off by the image's
/// bottom edge was put 25 % too far (6 relations on marsyard seed 11).
pub fn ratio_bounds(ranged: &Ranged) -> RangeBounds {
    corroborated_bounds(ranged.ground, ranged.stereo)
}

/// [`ratio_bounds`] from the flat-ground and stereo cues' intervals, as a run's records keep
/// them (`run::RangeRecord::ratio_bounds`).
pub fn corroborated_bounds(
    ground: Option<RangeInterval>,
    stereo: Option<RangeInterval>,
) -> RangeBounds {
    match (ground, stereo) {
        (Some(ground), Some(stereo)) => {
            ground
                .intersection(stereo)
                .map_or(RangeBounds::UNBOUNDED, |both| RangeBounds {
                    low: both.low,
                    high: both.high,
                })
        }
        _ => RangeBounds::UNBOUNDED,
    }
}

/// "Nearer than" wherever the fused intervals separate (000 §IV assumption 2, partial).
pub fn range_order(ranged: &[Ranged]) -> RangeOrder {
    let pairs: Vec<(usize, usize)> = (0..ranged.len())
        .flat_map(|i| (0..ranged.len()).map(move |j| (i, j)))
        .filter(|&(i, j)| i != j && ranged[i].fused.entirely_below(ranged[j].fused))
        .collect();
    RangeOrder::from_pairs(ranged.len(), &pairs)
        .expect("interval separation is a strict order: irreflexive and transitive")
}

/// Width of a detection in columns (its bbox, wrap-aware).
fn apparent_columns(d: &Detection) -> f64 {
    f64::from(d.bbox[2].saturating_sub(d.bbox[0]) + 1)
}

/// Intersection of the cues that apply; their hull (flagged) if they disagree.
fn fuse(cues: [Option<RangeInterval>; 3]) -> (RangeInterval, bool) {
    let mut present = cues.into_iter().flatten();
    let Some(first) = present.next() else {
        return (RangeInterval::unbounded(), false);
    };
    let rest: Vec<RangeInterval> = present.collect();
    let intersection = rest.iter().try_fold(first, |acc, &c| acc.intersection(c));
    match intersection {
        Some(fused) => (fused, false),
        None => (rest.iter().fold(first, |acc, &c| acc.hull(c)), true),
    }
}

/// Flat-ground cue (000 §IV: flat ground, mast height known). `None` if the contact is at or
/// above the horizon, below the image, or may be hidden behind a nearer detection (then the
/// visible bottom is not the contact).
fn ground_cue(
    d: &Detection,
    index: usize,
    all: &[Detection],
    calib: &Calibration,
    model: &SensorModel,
    angular_width: f64,
    half_baseline: f64,
) -> Option<RangeInterval> {
    if cut_off(d, calib) || contact_hidden(index, all, calib.image.width, model) {
        return None;
    }
    let near = contact_near(d, calib, model)?;
    let far = calib.ground_range(d.contact_row - model.contact_error_px)?;
    // Range from the eye along the view, then from the station centre (the eye sits half a
    // baseline across the view).
    let centre = |r: f64| r.hypot(half_baseline);
    Some(RangeInterval::new(
        centre(near),
        beyond_reach(centre(far), model, angular_width)?,
    ))
}

/// Whether `d` reaches the image's bottom edge: its contact is not in the picture.
fn cut_off(d: &Detection, calib: &Calibration) -> bool {
    d.bbox[3] + 1 >= calib.image.height
}

/// The flat-ground range from the eye of the lowest row `d`'s contact may lie at (its
/// contact row, the slack its shape allows and the contact's error): the near end of its
/// ground cue. `None` at or above the horizon.
fn contact_near(d: &Detection, calib: &Calibration, model: &SensorModel) -> Option<f64> {
    calib.ground_range(d.contact_row + d.contact_slack_rows + model.contact_error_px)
}

/// The far end of a cue for the rock's reference point, which lies beyond the visible
/// surface (its contact, its face) at `far` by at most `reach_per_width` of its width, the
/// width itself growing with range (≤ `angular_width` · range): `far / (1 − k)`, none when
/// `k = reach_per_width · angular_width` is 1 or more.
fn beyond_reach(far: f64, model: &SensorModel, angular_width: f64) -> Option<f64> {
    let k = model.reach_per_width * angular_width;
    (k < 1.0).then(|| far / (1.0 - k))
}

/// Whether detection `index` touches another one side by side (columns within two of each
/// other, rows overlapping): the two may be pieces of one rock, or two rocks cut apart where
/// they touch, and either way its centroid may be far from its rock's centre. The nearer part
/// of a blob separated by parallax is not doubted for touching a farther part of the same
/// blob: the edge between them is its own outline.
pub fn touches_neighbour(index: usize, all: &[Detection], width: u32) -> bool {
    neighbours(index, all, width).next().is_some()
}

/// The detections [`touches_neighbour`] finds touching detection `index`.
fn neighbours<'a>(
    index: usize,
    all: &'a [Detection],
    width: u32,
) -> impl Iterator<Item = &'a Detection> + 'a {
    let me = &all[index];
    all.iter().enumerate().filter_map(move |(j, other)| {
        (j != index
            && !(me.separation == Separation::Nearer
                && other.separation == Separation::Farther
                && other.blob == me.blob)
            && boxes_touch(me.bbox, other.bbox, width))
        .then_some(other)
    })
}

/// Whether two detections' boxes touch side by side: their columns within two of each other
/// (either may wrap the panorama `width`), their rows overlapping.
pub(crate) fn boxes_touch(a: [u32; 4], b: [u32; 4], width: u32) -> bool {
    columns_overlap(a, b, 2, width) && b[1] <= a[3] && a[1] <= b[3]
}

/// Columns before and after detection `index`'s box that the detections touching it cover:
/// if it is a piece of a rock, the rest may lie there (one rock in two pieces, or its side
/// hidden by a nearer rock). `[0, 0]` for a detection touching none.
fn neighbour_reach(index: usize, all: &[Detection], width: u32) -> [u32; 2] {
    let me = &all[index];
    let (first, last) = (i64::from(me.bbox[0]), i64::from(me.bbox[2]));
    let width = i64::from(width);
    neighbours(index, all, width as u32).fold([0, 0], |[before, after], other| {
        // The neighbour's span in the unwrapping nearest to this box (either may wrap).
        let (start, end) = [0, width, -width]
            .into_iter()
            .map(|s| (i64::from(other.bbox[0]) + s, i64::from(other.bbox[2]) + s))
            .max_by_key(|&(start, end)| last.min(end) - first.max(start))
            .unwrap_or_default();
        let columns = |c: i64| u32::try_from(c.max(0)).unwrap_or(u32::MAX);
        [
            before.max(columns(first - start)),
            after.max(columns(end - last)),
        ]
    })
}

/// Whether another detection overlaps `index`'s columns and reaches down to or below its
/// contact row: a nearer rock may hide the true contact. A detection no taller than twice the
/// contact's error has no shape to show that its bottom edge is a contact: it may be the last
/// rows of a far rock above a nearer one whose top the detector missed, so a nearer rock whose
/// top lies within a quarter of its own height below counts too (`sparse-large` seed 5 with
/// 300 rocks, half resolution: a 2-row strip of a rock 17 m away, 5 rows above a rock 12 m
/// away, was ranged at 26–33 m, 147 unsound relations; over 9 sets such detections' ground
/// cues missed their rock 30 times in 32).
fn contact_hidden(index: usize, all: &[Detection], width: u32, model: &SensorModel) -> bool {
    hiders(index, all, width, model).next().is_some()
}

/// The detections that may hide detection `index`'s contact ([`contact_hidden`]).
fn hiders<'a>(
    index: usize,
    all: &'a [Detection],
    width: u32,
    model: &SensorModel,
) -> impl Iterator<Item = usize> + 'a {
    let me = &all[index];
    let flat = f64::from(me.bbox[3] - me.bbox[1] + 1) <= 2.0 * model.contact_error_px;
    all.iter().enumerate().filter_map(move |(j, other)| {
        let reach = if flat {
            MIN_CONTACT_GAP_ROWS.max(0.25 * f64::from(other.bbox[3] - other.bbox[1] + 1))
        } else {
            MIN_CONTACT_GAP_ROWS
        };
        (j != index
            && columns_overlap(me.bbox, other.bbox, 2, width)
            && other.contact_row > me.contact_row
            && f64::from(other.bbox[1]) <= me.contact_row + reach)
            .then_some(j)
    })
}

/// The least range from the centre at which detection `index`'s rock can lie: its range
/// interval's near end when a cue bounds it, else, when nearer detections may hide its contact
/// ([`contact_hidden`]), the flat-ground range from the eye (no more than from the centre) of
/// the lowest contact among them and the detections hiding theirs in turn (a hidden contact
/// lies behind them, so no lower in the image); 0 when one of those is cut off by the image's
/// bottom edge, or when nothing bounds it. Association uses it to tell that a landmark the
/// motion brings nearer than that is not this detection's rock.
fn nearest(
    index: usize,
    all: &[Detection],
    fused: RangeInterval,
    calib: &Calibration,
    model: &SensorModel,
) -> f64 {
    if fused.low > 0.0 {
        return fused.low;
    }
    let width = calib.image.width;
    let mut behind = vec![false; all.len()];
    behind[index] = true;
    let mut frontier = vec![index];
    let mut least: Option<f64> = None;
    while let Some(k) = frontier.pop() {
        for j in hiders(k, all, width, model) {
            if !behind[j] {
                behind[j] = true;
                if cut_off(&all[j], calib) {
                    return 0.0;
                }
                if let Some(near) = contact_near(&all[j], calib, model) {
                    least = Some(least.map_or(near, |l: f64| l.min(near)));
                }
                frontier.push(j);
            }
        }
    }
    least.unwrap_or(0.0)
}

/// Rows below a contact within which a nearer detection's top hides it.
const MIN_CONTACT_GAP_ROWS: f64 = 2.0;

/// Whether two wrap-aware column spans of a `width`-column panorama overlap, with `slack`
/// columns of tolerance.
fn columns_overlap(a: [u32; 4], b: [u32; 4], slack: u32, width: u32) -> bool {
    let span = |x: [u32; 4]| (i64::from(x[0]), i64::from(x[2]));
    let (a0, a1) = span(a);
    let (b0, b1) = span(b);
    let slack = i64::from(slack);
    // Compare in both unwrappings: a span may have col_max ≥ width.
    let overlap = |s: i64| a0 - slack <= b1 + s && b0 + s <= a1 + slack;
    let width = i64::from(width);
    overlap(0) || overlap(width) || overlap(-width)
}

/// Stereo cue from the left (`d`) and right (`r`) detections of one rock. The centroids'
/// disparity is the range of the rock's middle, except for a rock the image's bottom edge cuts:
/// each eye sees the part above the edge, which may lie on any side of its reference point, so
/// that point may be nearer or farther by `reach_per_width` of its width (`angular_width` ·
/// range). On six colour marsyard renderings 7 of 115 such rocks fused lay outside their
/// stereo-and-size interval, by up to 21 %, and 1 of 6 316 other sightings (docs/RUN.md, stop 70).
/// `None` when that reach spans every range.
fn stereo_cue(
    d: &Detection,
    r: &Detection,
    calib: &Calibration,
    model: &SensorModel,
    angular_width: f64,
) -> Option<RangeInterval> {
    let disparity = azimuth_difference(calib.azimuth(r.centroid[0]), calib.azimuth(d.centroid[0]));
    let columns = 0.5 * (apparent_columns(d) + apparent_columns(r));
    let error = (model.disparity_error_px + model.disparity_error_per_width * columns)
        * calib.column_width();
    let near = calib.stereo_range(disparity + error).unwrap_or(0.0);
    let far = calib
        .stereo_range(disparity - error)
        .unwrap_or(f64::INFINITY);
    if !cut_off(d, calib) {
        return Some(RangeInterval::new(near, far));
    }
    let reach = model.reach_per_width * angular_width;
    Some(RangeInterval::new(
        near / (1.0 + reach),
        beyond_reach(far, model, angular_width)?,
    ))
}

/// Stereo cue of a part of a blob separated by parallax, which has no partner in the other
/// panorama (its blob there holds both parts): its own pixels' shifts put its visible surface
/// between the ranges of their 10th and 90th percentiles, give or take the matching error, and
/// the reference point lies beyond that surface by at most `reach_per_width` of the width the
/// rock may have (`angular_width`, taking in a neighbour it may reach under), as for the
/// ground cue. `None` for a detection without such shifts.
fn parallax_cue(
    d: &Detection,
    calib: &Calibration,
    model: &SensorModel,
    angular_width: f64,
) -> Option<RangeInterval> {
    let [low, high] = d.parallax_shifts?;
    let disparity = |shift: f64| shift * calib.column_width();
    let near = calib
        .stereo_range(disparity(high + model.disparity_error_px))
        .unwrap_or(0.0);
    let far = calib
        .stereo_range(disparity(low - model.disparity_error_px))
        .unwrap_or(f64::INFINITY);
    Some(RangeInterval::new(
        near,
        beyond_reach(far, model, angular_width)?,
    ))
}

/// Bearing from the station centre, and the ray the detection was seen along. Left eye:
/// α_L = φ − asin(b/2d) and α_R = φ + asin(b/2d), so a stereo pair gives φ as their mean; a
/// lone left detection gives φ within the offsets its range interval allows.
fn bearing_of(
    d: &Detection,
    right: Option<&Detection>,
    calib: &Calibration,
    model: &SensorModel,
    half_baseline: f64,
    range: RangeInterval,
) -> (Bearing, Ray) {
    let left = calib.azimuth(d.centroid[0]);
    let columns = model.bearing_error_px + model.bearing_error_per_width * apparent_columns(d);
    // Where the rock's centre may lie off the centroid, in columns: within the centroid's
    // error, or within a column's error of the centre of a span the rock may cover. The
    // right eye's piece of a stereo pair is taken to be the same part of the rock (the same
    // colour test on nearly the same view), so its centroid is off by as much; not so for a
    // rock the image's bottom edge cuts, whose eyes see different parts of it above the
    // edge: its centre lies within its columns' reach ([`cut_off_offsets`]), seen along the
    // left eye's ray.
    let width = f64::from(calib.image.width);
    let (low, high) = centre_offsets(d, width);
    let (right, (low, high)) = if cut_off(d, calib) {
        let (first, end) = cut_off_offsets(d, width);
        (None, (low.min(first), high.max(end)))
    } else {
        (right, (low, high))
    };
    let (low, high) = (
        (low - model.bearing_error_px).min(-columns),
        (high + model.bearing_error_px).max(columns),
    );
    let shift = 0.5 * (low + high) * calib.column_sign() * calib.column_width();
    let error = 0.5 * (high - low) * calib.column_width();
    let (angle, spread, ray) = match right {
        Some(r) => {
            let difference = azimuth_difference(calib.azimuth(r.centroid[0]), left);
            let angle = left + 0.5 * difference;
            (angle, 0.0, Ray::from_centre(angle + shift))
        }
        None if half_baseline > 0.0 => {
            let eye = Ray {
                azimuth: (left + shift).rem_euclid(TAU),
                half_baseline,
                nearest: 0.0,
                half_width: 0.0,
            };
            let (small, large) = (eye.offset_at(range.high), eye.offset_at(range.low));
            (left + 0.5 * (small + large), 0.5 * (large - small), eye)
        }
        None => (left, 0.0, Ray::from_centre(left + shift)),
    };
    let bearing = Bearing {
        angle: (angle + shift).rem_euclid(TAU),
        uncertainty: error + spread,
    };
    (bearing, ray)
}

/// Columns, relative to the centroid, between which the centre of the rock a piece belongs to
/// may lie: the rock holds the piece's columns and stays within
/// [`Detection::beyond_columns`] of them, so its centre lies between the centres of the
/// narrowest and the widest such spans; the centroid itself is kept inside. `(0, 0)` for a
/// piece with nothing beyond it.
fn centre_offsets(d: &Detection, width: f64) -> (f64, f64) {
    let [before, after] = d.beyond_columns.map(f64::from);
    if before == 0.0 && after == 0.0 {
        return (0.0, 0.0);
    }
    let (first, end, centroid) = unwrapped_span(d, width);
    let low = 0.5 * (first - before + end) - centroid;
    let high = 0.5 * (first + end + after) - centroid;
    (low.min(0.0), high.max(0.0))
}

/// Columns, relative to the centroid, between which the centre of a rock the image's bottom
/// edge cuts may lie: its visible columns and as many again either side. The hidden part is
/// the rock's near side, and beside the rover the reference point on the ground below it can
/// lie off the visible top's columns: on six colour marsyard renderings 3 of 117 such
/// sightings fused had it outside them, by up to 0.95 of their width (docs/RUN.md, stop 70).
fn cut_off_offsets(d: &Detection, width: f64) -> (f64, f64) {
    let (first, end, centroid) = unwrapped_span(d, width);
    (2.0 * first - end - centroid, 2.0 * end - first - centroid)
}

/// `d`'s first and past-last columns and its centroid's, in the bbox's unwrapped columns.
fn unwrapped_span(d: &Detection, width: f64) -> (f64, f64, f64) {
    let (first, end) = (f64::from(d.bbox[0]), f64::from(d.bbox[2]) + 1.0);
    let centroid = if d.centroid[0] < first {
        d.centroid[0] + width
    } else {
        d.centroid[0]
    };
    (first, end, centroid)
}

/// `a − b` wrapped into `(−π, π]`.
fn azimuth_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    if d > PI {
        d - TAU
    } else {
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detection::Appearance;
    use qrm_core::measurement::angular_distance;

    fn blob(bbox: [u32; 4], separation: Separation) -> Detection {
        Detection {
            centroid: [
                f64::from(bbox[0] + bbox[2]) / 2.0,
                f64::from(bbox[1] + bbox[3]) / 2.0,
            ],
            bbox,
            pixels: 100,
            contact_row: f64::from(bbox[3] + 1),
            contact_slack_rows: 0.0,
            appearance: Appearance {
                colour: [0.4, 0.33, 0.27],
                brightness: 0.8,
                texture: 0.1,
                dark_fraction: 0.2,
            },
            ambiguous: separation == Separation::Farther,
            separation,
            blob: 7,
            beyond_columns: [0, 0],
            parallax_shifts: None,
            flat: false,
            surely_flat: false,
        }
    }

    /// Two blobs side by side doubt each other; the nearer part of a parallax separation is not
    /// doubted for touching its own blob's farther part, though the farther part still is, and
    /// the nearer part still is for touching anything else.
    #[test]
    fn touching_doubts_all_but_a_nearer_part_against_a_farther_one() {
        let width = 4096;
        let whole = [
            blob([100, 50, 120, 70], Separation::Whole),
            blob([121, 52, 140, 72], Separation::Whole),
        ];
        assert!(touches_neighbour(0, &whole, width) && touches_neighbour(1, &whole, width));
        let separated = [
            blob([100, 60, 140, 80], Separation::Nearer),
            blob([110, 40, 135, 66], Separation::Farther),
        ];
        assert!(!touches_neighbour(0, &separated, width));
        assert!(touches_neighbour(1, &separated, width));
        let crowded = [
            separated[0].clone(),
            separated[1].clone(),
            blob([141, 62, 160, 80], Separation::Whole),
        ];
        assert!(touches_neighbour(0, &crowded, width));
        let strangers = [
            separated[0].clone(),
            Detection {
                blob: 8,
                ..separated[1].clone()
            },
        ];
        assert!(
            touches_neighbour(0, &strangers, width),
            "a farther part of another blob"
        );
    }

    /// A strip no taller than twice the contact's error, a few rows above a nearer rock, may be
    /// the last rows of a rock the nearer one hides the bottom of: its contact is hidden. A
    /// taller detection at the same gap shows its own contact.
    #[test]
    fn a_flat_strip_above_a_nearer_rock_has_no_contact() {
        let width = 4096;
        let model = SensorModel::default();
        let near = blob([660, 172, 726, 193], Separation::Whole);
        let strip = blob([679, 165, 695, 166], Separation::Whole);
        assert!(contact_hidden(0, &[strip, near.clone()], width, &model));
        let rock = blob([679, 150, 695, 166], Separation::Whole);
        assert!(!contact_hidden(
            0,
            &[rock.clone(), near.clone()],
            width,
            &model
        ));
        let touching = blob([660, 168, 726, 193], Separation::Whole);
        assert!(contact_hidden(0, &[rock, touching], width, &model));
        let aside = blob([700, 165, 710, 166], Separation::Whole);
        let low = blob([660, 190, 726, 230], Separation::Whole);
        assert!(
            !contact_hidden(0, &[aside, low], width, &model),
            "ground shows between the strip and the rock below"
        );
    }

    /// A rock whose contact a nearer rock hides lies behind it: no nearer than the flat-ground
    /// range of the hider's contact, or of the contact of a rock hiding the hider's in turn.
    /// A hider cut off by the image's bottom edge bounds nothing, and nor does a detection
    /// nothing hides; one a cue ranges starts at its interval's near end.
    #[test]
    fn a_rock_behind_a_nearer_one_lies_no_nearer_than_the_nearer_ones_contact() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let unranged = RangeInterval::unbounded();
        let far = blob([400, 170, 440, 185], Separation::Whole);
        let hider = blob([420, 186, 470, 215], Separation::Whole);
        let ground = |row: f64| calib.ground_range(row + model.contact_error_px).unwrap();
        let behind = nearest(0, &[far.clone(), hider.clone()], unranged, &calib, &model);
        assert_eq!(behind, ground(216.0));
        assert!(behind > 3.0 && behind < ground(186.0), "{behind}");
        let under = blob([430, 214, 480, 260], Separation::Whole);
        let chain = [far.clone(), hider.clone(), under.clone()];
        assert_eq!(nearest(0, &chain, unranged, &calib, &model), ground(261.0));
        let cut = blob([430, 214, 480, 383], Separation::Whole);
        assert_eq!(
            nearest(0, &[far.clone(), hider, cut], unranged, &calib, &model),
            0.0
        );
        let beside = blob([500, 186, 520, 215], Separation::Whole);
        assert_eq!(
            nearest(0, &[far.clone(), beside], unranged, &calib, &model),
            0.0
        );
        let ranged = RangeInterval::new(6.0, 9.0);
        assert_eq!(nearest(0, &[far, under], ranged, &calib, &model), 6.0);
    }

    /// The left eye alone, without a range: the bearing interval runs from the eye's direction
    /// to a right angle beyond, its middle 45° from where the rock was seen; the ray gives the
    /// rock's bearing from the centre at whatever range it turns out to be.
    #[test]
    fn an_unranged_left_detection_is_seen_along_its_ray() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let mut piece = blob([68, 222, 74, 228], Separation::Whole);
        piece.centroid[0] = 71.0;
        let unranged = RangeInterval::new(0.0, f64::INFINITY);
        let (bearing, ray) = bearing_of(&piece, None, &calib, &model, 0.15, unranged);
        let eye = calib.azimuth(71.0);
        for range in [0.5, 2.0, 10.0, 100.0] {
            // The left eye sees a rock at `range` asin(b / 2d) short of the centre's bearing.
            let centre = eye + (0.15f64 / range).asin();
            assert!(azimuth_difference(ray.direction_at(range), centre).abs() < 1e-12);
            assert!(azimuth_difference(centre, bearing.angle).abs() <= bearing.uncertainty);
        }
        assert!(
            azimuth_difference(bearing.angle, eye).abs() > 0.7,
            "{bearing:?}"
        );
    }

    /// A separated part's range from its own pixels' shifts holds its rock's reference point:
    /// by brute force over rocks 1.5–30 m away and 0.1–1.5 m wide, whose visible surface lies
    /// up to `reach_per_width` of their width in front of the reference point, the shifts'
    /// quantiles off by up to the matching error.
    #[test]
    fn a_parts_parallax_range_holds_its_rock() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let shift_of = |range: f64| calib.stereo_disparity(range) / calib.column_width();
        for range in (3..=60).map(|k| 0.5 * f64::from(k)) {
            for width in (1..=15).map(|k| 0.1 * f64::from(k)) {
                // Visible points from the reference point's range to the reach in front of
                // it, or only the front face; each quantile off by the matching error the
                // wrong way (the far one read nearer, the near one farther).
                let depth = model.reach_per_width * width;
                if depth >= range {
                    continue;
                }
                let error = model.disparity_error_px;
                let (far, front) = (shift_of(range), shift_of(range - depth));
                for (low, high) in [
                    (far + error, (front - error).max(far + error)),
                    (front + error, front + error),
                    (far - error, front + error),
                ] {
                    let part = Detection {
                        parallax_shifts: Some([low, high]),
                        ..blob([100, 100, 110, 110], Separation::Farther)
                    };
                    let angular = width / range;
                    if let Some(cue) = parallax_cue(&part, &calib, &model, angular) {
                        assert!(
                            cue.low <= range && range <= cue.high * (1.0 + 1e-9),
                            "{range} m, {width} m wide: {cue:?}"
                        );
                    }
                }
            }
        }
        let whole = blob([100, 100, 110, 110], Separation::Whole);
        assert_eq!(parallax_cue(&whole, &calib, &model, 0.1), None);
    }

    /// A rock the image's bottom edge cuts is seen along the left eye's ray, not at the mean of
    /// the two eyes' centroids (each sees another part of it), with its centre anywhere within
    /// its columns' reach; its stereo cue reaches nearer and farther than the same rock's
    /// lifted off the edge. The same blob above the edge keeps the stereo mean.
    #[test]
    fn a_rock_the_bottom_edge_cuts_spans_its_reach() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let half_baseline = 0.5 * calib.stereo.baseline_m;
        let (left, right) = (
            blob([1000, 300, 1040, 383], Separation::Whole),
            blob([960, 300, 1000, 383], Separation::Whole),
        );
        let lift = |d: &Detection| Detection {
            bbox: [d.bbox[0], 250, d.bbox[2], 333],
            contact_row: 334.0,
            ..d.clone()
        };
        let angular = 41.0 * calib.column_width();
        let cut = stereo_cue(&left, &right, &calib, &model, angular).expect("bounded");
        let whole =
            stereo_cue(&lift(&left), &lift(&right), &calib, &model, angular).expect("bounded");
        assert!(
            cut.low < whole.low && whole.high < cut.high,
            "{cut:?} {whole:?}"
        );

        let (bearing, ray) = bearing_of(&left, Some(&right), &calib, &model, half_baseline, cut);
        assert_eq!(ray.half_baseline, half_baseline, "the left eye's ray");
        for column in [1000.0 - 41.0, 1041.0 + 41.0] {
            let eye = Ray {
                azimuth: calib.azimuth(column),
                half_baseline,
                nearest: 0.0,
                half_width: 0.0,
            };
            for range in [cut.low, cut.high] {
                let off = angular_distance(eye.direction_at(range), bearing.angle);
                assert!(
                    off <= bearing.uncertainty + 1e-9,
                    "column {column}, {range} m"
                );
            }
        }
        let (lifted, _) = bearing_of(
            &lift(&left),
            Some(&lift(&right)),
            &calib,
            &model,
            half_baseline,
            whole,
        );
        let mean = calib.azimuth(0.5 * (left.centroid[0] + right.centroid[0]));
        assert!(angular_distance(lifted.angle, mean) < 1e-9);
        assert!(lifted.uncertainty < 0.5 * bearing.uncertainty);

        let ranged = observe(
            &[left],
            Some(&[right]),
            PrimaryEye::Left,
            Channels::Colour,
            &calib,
            &model,
        );
        assert!(ranged[0].cut_off);
    }

    /// By luminance the measured bearing widens by the lit-face margin, in proportion to the
    /// detection's width; the likely bearing, which places it, does not move; in colour the two
    /// are one.
    #[test]
    fn a_luminance_bearing_is_measured_with_its_lit_face_margin() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let primary = [
            blob([100, 200, 140, 240], Separation::Whole),
            blob([600, 200, 610, 240], Separation::Whole),
        ];
        let seen = |channels| observe(&primary, None, PrimaryEye::Mono, channels, &calib, &model);
        let (colour, luminance) = (seen(Channels::Colour), seen(Channels::Luminance));
        for (c, l) in colour.iter().zip(&luminance) {
            assert_eq!(c.measured_bearing(), c.bearing);
            assert_eq!(l.bearing, c.bearing);
            let margin = l.measured_bearing().uncertainty - l.bearing.uncertainty;
            let expected = model.lit_face_per_width * l.angular_width;
            assert!(
                (margin - expected).abs() < 1e-12,
                "{margin} against {expected}"
            );
            assert_eq!(l.measured_bearing().angle, l.bearing.angle);
        }
        assert!(luminance[0].lit_face > 3.0 * luminance[1].lit_face);
    }

    /// A half-resolution panorama of a stereo head with a 0.3 m baseline.
    fn half_resolution_stereo() -> Calibration {
        Calibration::parse(
            "[image]\nwidth = 2048\nheight = 384\n[azimuth]\ncolumn0_deg = 102.0\n\
             direction = \"clockwise\"\n[elevation]\nhorizon_row = 150.0\nfocal_px = 326.0\n\
             [mast]\nheight_m = 1.5\n[stereo]\nbaseline_m = 0.3\n",
            "test",
        )
        .expect("valid")
    }

    /// Stress member 5's piece: columns 68–74 of a rock whose visible columns are 68–93, the
    /// raised pixels beside it reaching 19 columns further. The bearing keeps the piece's
    /// centroid and takes in the rock's centre; a piece with nothing beyond keeps its bearing.
    #[test]
    fn a_piece_with_raised_pixels_beyond_it_is_widened_to_the_rock() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let range = RangeInterval::new(4.0, 5.0);
        let mut piece = blob([68, 222, 74, 228], Separation::Whole);
        piece.centroid[0] = 71.3;
        let alone = bearing_of(&piece, None, &calib, &model, 0.0, range).0;
        piece.beyond_columns = [0, 19];
        let widened = bearing_of(&piece, None, &calib, &model, 0.0, range).0;
        let holds = |b: Bearing, column: f64| {
            azimuth_difference(calib.azimuth(column), b.angle).abs() <= b.uncertainty
        };
        assert!(!holds(alone, 81.0), "{alone:?}");
        assert!(holds(widened, 81.0) && holds(widened, 71.3), "{widened:?}");
        assert!(widened.uncertainty < 3.0 * alone.uncertainty, "{widened:?}");
        piece.beyond_columns = [0, 0];
        assert_eq!(
            bearing_of(&piece, None, &calib, &model, 0.0, range).0,
            alone
        );
    }

    #[test]
    fn fusion_intersects_and_flags_conflicts() {
        let a = RangeInterval::new(2.0, 6.0);
        let b = RangeInterval::new(4.0, 9.0);
        assert_eq!(
            fuse([Some(a), Some(b), None]),
            (RangeInterval::new(4.0, 6.0), false)
        );
        let c = RangeInterval::new(7.0, 8.0);
        assert_eq!(
            fuse([Some(a), None, Some(c)]),
            (RangeInterval::new(2.0, 8.0), true)
        );
        assert_eq!(
            fuse([None, None, None]),
            (RangeInterval::unbounded(), false)
        );
    }

    /// Two pieces side by side, across the seam of a 2048-column panorama: each one's reach
    /// is the columns the other covers beyond it, whichever unwrapping holds the boxes.
    #[test]
    fn a_piece_reaches_over_the_columns_its_neighbour_covers() {
        let pieces = [
            blob([2040, 200, 2050, 220], Separation::Whole),
            blob([3, 205, 12, 224], Separation::Whole),
            blob([600, 200, 620, 220], Separation::Whole),
        ];
        assert_eq!(neighbour_reach(0, &pieces, 2048), [0, 10]);
        assert_eq!(neighbour_reach(1, &pieces, 2048), [11, 0]);
        assert_eq!(neighbour_reach(2, &pieces, 2048), [0, 0]);
    }

    /// A rock in two pieces (columns 100–139, cut at column 120): each piece's bearing interval
    /// takes in the whole rock's centre, each one's ray stays where the piece was seen, and
    /// only the pieces are flagged. Brute force: every centre of a rock holding the piece and
    /// within its neighbour's columns lies in the interval.
    #[test]
    fn a_piece_touching_another_takes_in_the_rock_it_may_be_part_of() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let primary = [
            blob([100, 200, 119, 230], Separation::Whole),
            blob([120, 200, 139, 230], Separation::Whole),
            blob([400, 200, 419, 230], Separation::Whole),
        ];
        let ranged = observe(
            &primary,
            None,
            PrimaryEye::Mono,
            Channels::Colour,
            &calib,
            &model,
        );
        assert_eq!(
            ranged.iter().map(|r| r.piece).collect::<Vec<_>>(),
            [true, true, false]
        );
        let holds = |b: Bearing, column: f64| {
            azimuth_difference(calib.azimuth(column), b.angle).abs() <= b.uncertainty
        };
        for (k, own) in [(0, (100.0, 120.0)), (1, (120.0, 140.0))] {
            let r = ranged[k];
            assert!(
                azimuth_difference(r.ray.azimuth, calib.azimuth(primary[k].centroid[0])).abs()
                    < 1e-12
            );
            // The rock spans the piece's columns and any run of the neighbour's beside it.
            for first in 100..=own.0 as u32 {
                for end in own.1 as u32..=140 {
                    let centre = 0.5 * f64::from(first + end);
                    assert!(holds(r.bearing, centre), "piece {k}, rock {first}..{end}");
                }
            }
        }
        // The lone detection keeps the centroid's own error.
        let lone = ranged[2].bearing;
        assert!(holds(lone, 410.0) && !holds(lone, 416.0), "{lone:?}");
    }

    /// A piece's own pixels' shifts range it where no partner can: in colour always, by
    /// luminance only where a nearer detection hides its contact. There they are its only
    /// range, and its bearing, without them as wide as the left eye's offsets at any range,
    /// narrows to those of its stereo interval; a luminance piece with a ground cue keeps that
    /// cue alone, as its ground and stereo cues agreeing would let it steer registrations.
    #[test]
    fn by_luminance_a_piece_takes_its_pixels_shifts_only_where_its_contact_is_hidden() {
        let calib = half_resolution_stereo();
        let model = SensorModel::default();
        let shift = calib.stereo_disparity(5.0) / calib.column_width();
        let shifted = |bbox, shifts: Option<[f64; 2]>| Detection {
            parallax_shifts: shifts,
            ..blob(bbox, Separation::Whole)
        };
        let primary = |shifts| {
            [
                shifted([100, 200, 119, 230], shifts),
                shifted([120, 200, 139, 230], shifts),
                shifted([90, 225, 112, 260], shifts),
            ]
        };
        let seen = |channels, shifts| {
            observe(
                &primary(shifts),
                None,
                PrimaryEye::Left,
                channels,
                &calib,
                &model,
            )
        };
        let shifts = Some([shift - 0.5, shift + 0.5]);
        let colour = seen(Channels::Colour, shifts);
        let luminance = seen(Channels::Luminance, shifts);
        assert!(colour.iter().chain(&luminance).all(|r| r.piece));
        assert!(colour.iter().all(|r| r.stereo.is_some()));
        // The first piece's contact lies behind the third, the others' show: (ground, stereo).
        assert_eq!(
            luminance
                .iter()
                .map(|r| (r.ground.is_some(), r.stereo.is_some()))
                .collect::<Vec<_>>(),
            [(false, true), (true, false), (true, false)]
        );
        let hidden = luminance[0];
        assert!(
            hidden.fused.low <= 5.0 && 5.0 <= hidden.fused.high,
            "{hidden:?}"
        );
        let unranged = seen(Channels::Luminance, None)[0];
        assert_eq!(unranged.fused, RangeInterval::unbounded());
        assert!(
            hidden.bearing.uncertainty < 0.5 * unranged.bearing.uncertainty,
            "{hidden:?} against {unranged:?}"
        );
    }

    #[test]
    fn azimuth_difference_wraps() {
        assert!((azimuth_difference(0.1, TAU - 0.1) - 0.2).abs() < 1e-12);
        assert!((azimuth_difference(TAU - 0.1, 0.1) + 0.2).abs() < 1e-12);
    }

    #[test]
    fn column_overlap_across_the_seam() {
        // [4090, 4100] wraps to columns 4090..4095 and 0..4; [0, 3] overlaps it.
        assert!(columns_overlap([4090, 0, 4100, 10], [0, 0, 3, 10], 0, 4096));
        assert!(!columns_overlap(
            [4090, 0, 4100, 10],
            [6, 0, 9, 10],
            0,
            4096
        ));
        assert!(!columns_overlap(
            [100, 0, 110, 10],
            [120, 0, 130, 10],
            2,
            4096
        ));
    }

    /// Ratio bounds come from the ground and stereo cues together, where they agree; a single
    /// cue, the size cue, or cues that disagree bound nothing.
    #[test]
    fn ratio_bounds_need_ground_and_stereo_to_agree() {
        let ranged =
            |ground: Option<[f64; 2]>, stereo: Option<[f64; 2]>, size: Option<[f64; 2]>| {
                let interval = |c: Option<[f64; 2]>| c.map(|[a, b]| RangeInterval::new(a, b));
                let (fused, conflict) = fuse([interval(ground), interval(stereo), interval(size)]);
                Ranged {
                    bearing: Bearing::exact(0.0),
                    ray: Ray {
                        azimuth: 0.0,
                        half_baseline: 0.0,
                        nearest: 0.0,
                        half_width: 0.0,
                    },
                    stereo_column: None,
                    angular_width: 0.01,
                    ground: interval(ground),
                    stereo: interval(stereo),
                    size: interval(size),
                    fused,
                    conflict,
                    piece: false,
                    cut_off: false,
                    lit_face: 0.0,
                }
            };
        let both = ratio_bounds(&ranged(
            Some([4.0, 6.0]),
            Some([5.0, 7.0]),
            Some([5.5, 5.6]),
        ));
        assert_eq!((both.low, both.high), (5.0, 6.0));
        for r in [
            ranged(Some([4.0, 5.0]), Some([6.0, 7.0]), None),
            ranged(Some([4.0, 5.0]), None, Some([4.5, 5.0])),
            ranged(None, Some([5.0, f64::INFINITY]), None),
            ranged(None, None, Some([5.0, 6.0])),
        ] {
            assert_eq!(ratio_bounds(&r), RangeBounds::UNBOUNDED);
        }
    }
}
