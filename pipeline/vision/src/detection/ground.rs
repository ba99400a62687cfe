//! Which pixels of the ground band lie on the flat ground, by stereo (perception notes: rocks
//! from stereo geometry, not from colour). The rotating stereo head sees flat ground at row
//! `y` at range `mast · focal / (y − horizon)`, so every ground point of that row appears in
//! the other panorama shifted by one known number of columns. A pixel whose neighbourhood
//! matches the other panorama at that shift is on the ground: soil, a soil patch of another
//! tint, or a cast shadow (darker, but it lies on the ground). A rock stands up from the
//! ground: above its foot, its face is nearer than the ground seen at the same row, so it
//! appears shifted more, and its neighbourhood does not match at the ground's shift.
//!
//! The test cannot see a rock's lowest rows: `k` rows above its contact, a face is only
//! `k · b / (mast · focal · column_width)` columns off the ground's shift (0.2 columns a row
//! with the default calibration, at any range and any resolution that scales the focal length
//! with the width), within the matching tolerance for the first few rows. Detections found by
//! this test carry that many rows of doubt on their contact ([`contact_of`]).

use crate::calib::Calibration;
use kornia_imgproc::filter::kernels::gaussian_kernel_1d;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::OnceLock;

/// Half-size of the matching window, pixels.
const RADIUS: usize = 2;

/// A pixel is textured enough for the test when its cost against itself shifted by
/// [`SELF_SHIFT`] exceeds this many times the band's median matching cost (most of the band is
/// soil matched at its own shift: the median is the matching noise of the images, whatever
/// their noise, blur or compression; [`GroundTest`] samples it) …
const NOISE_MULTIPLE: f32 = 3.0;

/// … and this many luminance levels (of `r + g + b`) per pixel: a noise-free render matches
/// the ground to a level or two, and a texture that faint tells nothing.
const MIN_COST: f32 = 6.0;

/// A textured pixel is off the ground when its cost at the ground's shift is at least this
/// fraction of its cost against itself shifted by [`SELF_SHIFT`]: compression and sensor
/// noise add to both costs alike, in proportion to the texture at edges (JPEG rings there,
/// differently in each panorama), while a face off the ground's shift by a column or more
/// mismatches like the shifted self.
const MISMATCH_RATIO: f32 = 0.5;

/// Columns off the ground's shift at which a textured face surely fails to match (half a
/// column of shift is absorbed by matching at the two integer shifts around the ground's).
const TOLERANCE_COLUMNS: f64 = 1.5;

/// Columns a neighbourhood is shifted against itself to tell whether it is textured enough
/// for the test: past [`TOLERANCE_COLUMNS`].
const SELF_SHIFT: isize = 2;

/// What the stereo test says of one pixel of the ground band.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stance {
    /// Its neighbourhood is too smooth to tell: it would match nearly as well shifted by more
    /// than the tolerance (the inside of a cast shadow, a rock's smooth face).
    Unknown,
    /// Textured, and matching the other panorama at the flat ground's shift.
    Ground,
    /// Textured, and not matching at the flat ground's shift: standing up from the ground.
    Raised,
}

/// A stereo pair's ground bands: the luminance (`r + g + b`) of the rows from image row `top`
/// down, `width` wide, of the panorama tested (`own`) and of its partner (`other`);
/// `direction` is the partner's column step per unit of shift.
#[derive(Clone, Copy)]
pub(super) struct Bands<'a> {
    pub own: &'a [u16],
    pub other: &'a [u16],
    pub width: usize,
    pub top: usize,
    pub calib: &'a Calibration,
    pub direction: isize,
}

impl Bands<'_> {
    fn rows(&self) -> usize {
        self.own.len() / self.width
    }
}

/// The stance of each pixel of the ground band, the texture threshold from the matching
/// noise of the whole band.
pub(super) fn stances(bands: &Bands) -> Vec<Stance> {
    let Costs { cost, texture } = band_costs(bands);
    let threshold = texture_threshold(cost.clone());
    cost.into_iter()
        .zip(texture)
        .map(|(c, t)| stance(c, t, threshold))
        .collect()
}

/// [`Costs`] of the whole band, tested in strips of rows in parallel.
fn band_costs(bands: &Bands) -> Costs {
    let rows = bands.rows();
    let strips: Vec<Costs> = (0..rows.div_ceil(STRIP_ROWS))
        .into_par_iter()
        .map(|i| {
            rect_costs(
                bands,
                i * STRIP_ROWS..((i + 1) * STRIP_ROWS).min(rows),
                0..bands.width,
            )
        })
        .collect();
    let (cost, texture) = strips
        .into_iter()
        .flat_map(|s| s.cost.into_iter().zip(s.texture))
        .unzip();
    Costs { cost, texture }
}

/// The stereo test of a ground band, run tile by tile where it is asked (a search around a
/// few blobs reads a tenth of the band): each pixel's costs are those [`stances`] finds, the
/// texture threshold is from a sample of the band's matching noise.
pub(super) struct GroundTest<'a> {
    tiles: Tiles<'a>,
    threshold: f32,
    /// Both bands smoothed around each tile, for matching at shifts up to `face_shifts`
    /// ([`GroundTest::nearer`]); made when a tile is first asked.
    faces: Vec<OnceLock<FacePlanes>>,
    /// The largest shift [`GroundTest::nearer`] tries: the nearest face any blob of the band
    /// may show ([`nearest_face_shift`] at the band's bottom).
    face_shifts: usize,
}

/// A tile's neighbourhood in both bands, smoothed, for [`GroundTest::nearer`]: the tested
/// panorama's around the tile, its partner's as far along as the largest shift.
struct FacePlanes {
    own: Plane,
    other: Plane,
}

impl<'a> GroundTest<'a> {
    /// Tests the tiles of the noise sample ([`SAMPLE_STRIDE`]) at once, in parallel, for
    /// the texture threshold.
    pub(super) fn new(bands: Bands<'a>) -> Self {
        let tiles = Tiles::new(bands);
        let sampled: Vec<f32> = (0..tiles.costs.len())
            .into_par_iter()
            .step_by(SAMPLE_STRIDE)
            .flat_map_iter(|t| tiles.costs(t).cost.clone())
            .collect();
        let faces = (0..tiles.costs.len()).map(|_| OnceLock::new()).collect();
        let face_shifts = nearest_face_shift(bands.calib, (bands.top + bands.rows()) as f64, true);
        GroundTest {
            tiles,
            threshold: texture_threshold(sampled),
            faces,
            face_shifts,
        }
    }

    /// Whether the pixel at `column` and `row`, too smooth for [`GroundTest::stance`], stands
    /// nearer than the ground: its neighbourhood mismatches the other panorama at the ground's
    /// shift by more than the texture threshold, and matches it best at a shift from
    /// [`SELF_SHIFT`] beyond the ground's up to `max_shift` columns (the nearest face the blob
    /// searched from may show; a nearer rock's face matches best farther along), at under
    /// [`MISMATCH_RATIO`] of that cost. A rock's smooth face between its textured edges is
    /// such a pixel (its shading still tells one shift from another; stress s16: a rock
    /// nearly the soil's colour whose face the texture test leaves unknown); smooth soil
    /// matches best at the ground's shift, and its cost there is the images' noise.
    pub(super) fn nearer(&self, column: usize, row: usize, max_shift: usize) -> bool {
        let (t, i) = self.tiles.locate(column, row);
        let costs = self.tiles.costs(t);
        let (ground, texture) = (costs.cost[i], costs.texture[i]);
        if texture > self.threshold || ground <= self.threshold {
            return false;
        }
        let bands = &self.tiles.bands;
        let planes = self.faces[t].get_or_init(|| {
            let (rows, columns) = self.tiles.rect(t);
            let read = rows.start.saturating_sub(RADIUS)..(rows.end + RADIUS).min(bands.rows());
            let r = RADIUS as isize;
            let (x0, x1) = (columns.start as isize, columns.end as isize);
            let reach = bands.direction * self.face_shifts as isize;
            let (low, high) = (reach.min(0), reach.max(0));
            FacePlanes {
                own: smooth_region(bands.own, bands.width, read.clone(), x0 - r..x1 + r),
                other: smooth_region(bands.other, bands.width, read, x0 - r + low..x1 + r + high),
            }
        });
        let window = row.saturating_sub(RADIUS)..(row + RADIUS + 1).min(bands.rows());
        let area = (window.len() * (2 * RADIUS + 1)) as f32;
        let x = column as isize - RADIUS as isize;
        let n = 2 * RADIUS + 1;
        // The cost at `shift` if under `bound`: a row at a time, given up once the sum reaches
        // the bound (it only grows), which most shifts do within a row or two.
        let cost_under = |shift: isize, bound: f32| {
            let mut sum = 0f32;
            for y in window.clone() {
                let a = planes.own.run(y, x, n);
                let b = planes.other.run(y, x + bands.direction * shift, n);
                sum += a.iter().zip(b).map(|(p, q)| (p - q).abs()).sum::<f32>();
                if sum / area >= bound {
                    return None;
                }
            }
            Some(sum / area)
        };
        let from =
            ground_shift(bands.calib, (bands.top + row) as f64 + 0.5).ceil() as isize + SELF_SHIFT;
        // The best match within the blob's shifts, under the mismatch ratio of the ground's …
        let last = max_shift.min(self.face_shifts) as isize;
        let best = (from..=last).fold(None, |best, shift| {
            cost_under(shift, best.unwrap_or(MISMATCH_RATIO * ground)).or(best)
        });
        // … and none better beyond them.
        best.is_some_and(|best| {
            (last + 1..=self.face_shifts as isize).all(|shift| cost_under(shift, best).is_none())
        })
    }

    /// The stance of the pixel at `column` and `row` of the band.
    pub(super) fn stance(&self, column: usize, row: usize) -> Stance {
        let (t, i) = self.tiles.locate(column, row);
        let costs = self.tiles.costs(t);
        stance(costs.cost[i], costs.texture[i], self.threshold)
    }
}

/// A band's tiles, row after row of them, each tested when first read.
struct Tiles<'a> {
    bands: Bands<'a>,
    /// Tiles along a row of the band.
    across: usize,
    costs: Vec<OnceLock<Costs>>,
}

impl<'a> Tiles<'a> {
    fn new(bands: Bands<'a>) -> Self {
        let across = bands.width.div_ceil(TILE_COLUMNS);
        let down = bands.rows().div_ceil(TILE_ROWS);
        Tiles {
            bands,
            across,
            costs: (0..across * down).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The rows and columns of tile `t`.
    fn rect(&self, t: usize) -> (Range<usize>, Range<usize>) {
        let (x, y) = (t % self.across * TILE_COLUMNS, t / self.across * TILE_ROWS);
        (
            y..(y + TILE_ROWS).min(self.bands.rows()),
            x..(x + TILE_COLUMNS).min(self.bands.width),
        )
    }

    /// The tile holding the pixel at `column` and `row`, and the pixel's index in the tile.
    fn locate(&self, column: usize, row: usize) -> (usize, usize) {
        let t = row / TILE_ROWS * self.across + column / TILE_COLUMNS;
        let (rows, columns) = self.rect(t);
        (
            t,
            (row - rows.start) * columns.len() + column - columns.start,
        )
    }

    fn costs(&self, t: usize) -> &Costs {
        self.costs[t].get_or_init(|| {
            let (rows, columns) = self.rect(t);
            rect_costs(&self.bands, rows, columns)
        })
    }
}

/// Rows of a strip of [`band_costs`]: a few strips a core, each smoothing a few rows more than
/// it tests.
const STRIP_ROWS: usize = 64;

/// Rows and columns of a tile of [`GroundTest`]: about the size of a far rock's search.
const TILE_ROWS: usize = 16;
const TILE_COLUMNS: usize = 64;

/// [`GroundTest`] samples the matching noise over one tile in [`SAMPLE_STRIDE`], counted row
/// after row of tiles: 31 is prime to the tiles across a row at every width in use, so the
/// sample steps across the columns as it goes down every row of tiles (the noise of far ground
/// near the horizon is not that of near ground). About 60 tiles at 4096 × 768: the median of
/// tens of thousands of costs, most of them soil's, is the whole band's within a few
/// hundredths, and a search around a few blobs need not test the rest.
const SAMPLE_STRIDE: usize = 31;

/// The texture a pixel needs for the test, from matching costs of the band.
fn texture_threshold(mut sampled: Vec<f32>) -> f32 {
    let noise = if sampled.is_empty() {
        0.0
    } else {
        let mid = sampled.len() / 2;
        *sampled.select_nth_unstable_by(mid, f32::total_cmp).1
    };
    (NOISE_MULTIPLE * noise).max(MIN_COST)
}

fn stance(cost: f32, texture: f32, threshold: f32) -> Stance {
    if texture <= threshold {
        Stance::Unknown
    } else if cost > MISMATCH_RATIO * texture {
        Stance::Raised
    } else {
        Stance::Ground
    }
}

/// The matching costs of a rectangle of the band, row after row: each pixel's cost at the
/// flat ground's shift and against itself shifted by [`SELF_SHIFT`] (its texture).
struct Costs {
    cost: Vec<f32>,
    texture: Vec<f32>,
}

/// [`Costs`] of the band's `rows` and `columns`. Every pixel's costs are the same sums in the
/// same order whatever rectangle holds it, so tiles and strips agree bit for bit.
fn rect_costs(bands: &Bands, rows: Range<usize>, columns: Range<usize>) -> Costs {
    let r = RADIUS as isize;
    let (x0, x1) = (columns.start as isize, columns.end as isize);
    // Each row's two integer shifts around the ground's, as column offsets in `other`.
    let offsets: Vec<[isize; 2]> = rows
        .clone()
        .map(|y| {
            let shift = ground_shift(bands.calib, (bands.top + y) as f64 + 0.5);
            [shift.floor(), shift.ceil()].map(|s| bands.direction * s as isize)
        })
        .collect();
    let (low, high) = offsets
        .iter()
        .flatten()
        .fold((0, 0), |(l, h), &o| (l.min(o), h.max(o)));
    let read = rows.start.saturating_sub(RADIUS)..(rows.end + RADIUS).min(bands.rows());
    let own = smooth_region(
        bands.own,
        bands.width,
        read.clone(),
        x0 - r..x1 + r + SELF_SHIFT,
    );
    let other = smooth_region(bands.other, bands.width, read, x0 - r + low..x1 + r + high);
    let n = columns.len() * rows.len();
    let (mut cost, mut texture) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for (y, [a, b]) in rows.zip(offsets) {
        let window = y.saturating_sub(RADIUS)..(y + RADIUS + 1).min(bands.rows());
        let at = |offset| window_costs(&own, &other, window.clone(), x0..x1, offset);
        cost.extend(at(a).into_iter().zip(at(b)).map(|(p, q)| p.min(q)));
        texture.extend(window_costs(&own, &own, window, x0..x1, SELF_SHIFT));
    }
    Costs { cost, texture }
}

/// Smoothed values of a band over some of its rows and a range of unwrapped columns.
struct Plane {
    rows: Range<usize>,
    x0: isize,
    width: usize,
    values: Vec<f32>,
}

impl Plane {
    /// `n` values of row `y` from unwrapped column `x`.
    fn run(&self, y: usize, x: isize, n: usize) -> &[f32] {
        let start = (y - self.rows.start) * self.width + (x - self.x0) as usize;
        &self.values[start..start + n]
    }
}

/// Mean absolute difference, per column of `columns`, between the window of `a` around it
/// and the window of `b` shifted by `offset` columns, over the `window` rows.
fn window_costs(
    a: &Plane,
    b: &Plane,
    window: Range<usize>,
    columns: Range<isize>,
    offset: isize,
) -> Vec<f32> {
    let r = RADIUS as isize;
    let n = (columns.end - columns.start) as usize;
    let span = n + 2 * RADIUS;
    let mut column_sums = vec![0f32; span];
    for y in window.clone() {
        let ra = a.run(y, columns.start - r, span);
        let rb = b.run(y, columns.start - r + offset, span);
        for ((sum, p), q) in column_sums.iter_mut().zip(ra).zip(rb) {
            *sum += (p - q).abs();
        }
    }
    let mut sums = vec![0f32; n];
    for k in 0..=2 * RADIUS {
        for (s, c) in sums.iter_mut().zip(&column_sums[k..]) {
            *s += c;
        }
    }
    let area = (window.len() * (2 * RADIUS + 1)) as f32;
    sums.into_iter().map(|s| s / area).collect()
}

/// Standard deviation (pixels) of the Gaussian both bands are smoothed with before matching:
/// JPEG rings at edges differently in each panorama, as much as half of what a shift of two
/// columns changes there; smoothed, a cast shadow's edge on the ground matches as in a
/// lossless image (marsyard seed 2 at quality 85).
const SMOOTHING_PX: f32 = 1.0;

/// Pixels the smoothing kernel reaches either side: two standard deviations hold 95 % of its
/// weight.
const SMOOTHING_REACH: usize = 2 * SMOOTHING_PX as usize;

/// `band` (rows of `width`) smoothed by kornia's Gaussian kernel of [`SMOOTHING_PX`] at its
/// `rows` and unwrapped `columns`, wrapping at the seam and taking rows beyond the band as
/// zero, as kornia's `gaussian_blur` would: the same sums in the same order, whatever the
/// region. Written as two passes over runs of a row, which compile to vector instructions:
/// kornia 0.2's separable filter tests every tap's bounds, 22 ms a band at 4096 × 768.
fn smooth_region(band: &[u16], width: usize, rows: Range<usize>, columns: Range<isize>) -> Plane {
    let kernel = gaussian_kernel_1d(2 * SMOOTHING_REACH + 1, SMOOTHING_PX);
    let pad = SMOOTHING_REACH;
    let band_rows = band.len() / width;
    let n = (columns.end - columns.start) as usize;
    let read = rows.start.saturating_sub(pad)..(rows.end + pad).min(band_rows);
    let mut across = vec![0f32; read.len() * n];
    for (y, out) in read.clone().zip(across.chunks_exact_mut(n)) {
        let row = &band[y * width..(y + 1) * width];
        let padded: Vec<f32> = (0..n + 2 * pad)
            .map(|k| {
                let x = columns.start + k as isize - pad as isize;
                f32::from(row[x.rem_euclid(width as isize) as usize])
            })
            .collect();
        for (k, &weight) in kernel.iter().enumerate() {
            for (o, &v) in out.iter_mut().zip(&padded[k..k + n]) {
                *o += v * weight;
            }
        }
    }
    let mut values = vec![0f32; rows.len() * n];
    for (y, out) in rows.clone().zip(values.chunks_exact_mut(n)) {
        for (k, &weight) in kernel.iter().enumerate() {
            let Some(from) = (y + k).checked_sub(pad).filter(|&r| r < band_rows) else {
                continue;
            };
            let from = &across[(from - read.start) * n..(from - read.start + 1) * n];
            for (o, &v) in out.iter_mut().zip(from) {
                *o += v * weight;
            }
        }
    }
    Plane {
        rows,
        x0: columns.start,
        width: n,
        values,
    }
}

/// The contact row of a rock whose lowest raised pixel row ends at `raised_bottom` (the row
/// under that pixel), and the rows under it the true contact may lie ([`contact_doubt`]).
pub(super) fn contact_of(raised_bottom: f64, calib: &Calibration) -> (f64, f64) {
    (raised_bottom - RADIUS as f64, contact_doubt(calib))
}

/// Rows of doubt on a contact found by the test: the window smears a rock's mismatch
/// [`RADIUS`] rows onto the ground below it, and the rock's lowest rows match the ground
/// within the tolerance: its face is `k · b / (mast · focal · column_width)` columns off the
/// ground's shift `k` rows above its contact.
pub(super) fn contact_doubt(calib: &Calibration) -> f64 {
    let per_row = calib.stereo.baseline_m
        / (calib.mast.height_m * calib.elevation.focal_px * calib.column_width());
    RADIUS as f64 + (TOLERANCE_COLUMNS / per_row).ceil()
}

/// The largest stereo shift (columns) of a rock whose lowest pixel row ends at image row
/// `bottom`: the shift of a rock somewhat nearer than that row reads on flat ground (a rock's
/// face overhangs its foot), nearer still when `cut` (the image's bottom hides its foot),
/// never nearer than 0.5 m.
pub(super) fn nearest_face_shift(calib: &Calibration, bottom: f64, cut: bool) -> usize {
    let margin = if cut { 0.5 } else { 0.8 };
    calib.ground_range(bottom).map_or(0, |range| {
        (calib.stereo_disparity((margin * range).max(0.5)) / calib.column_width()).ceil() as usize
            + 3
    })
}

/// Whether the test tells a rock whose top is at image row `top` and contact at `contact` from
/// the ground: standing, its rows at least [`RADIUS`] below the top (the highest whose matching
/// window lies on the rock alone) lie at its contact's range, nearer than the ground seen there
/// by [`TOLERANCE_COLUMNS`] of shift or more, so a textured top would fail to match at the
/// ground's shift. A flat verdict on a lower blob (a far rock's few rows: sparse-large's rocks
/// 25–32 m away, 8 rows tall just under the horizon) says nothing of its height.
pub(super) fn tells_height(calib: &Calibration, top: f64, contact: f64) -> bool {
    let judged = top + RADIUS as f64;
    ground_shift(calib, contact) - ground_shift(calib, judged) >= TOLERANCE_COLUMNS
}

/// Whether half or more of a blob's pixels (their `stances`) are textured and match the other
/// panorama at the ground's shift: the test saw ground there, rather than a face too smooth
/// to tell (a low-contrast rock is flat by default).
pub(super) fn mostly_ground(stances: impl Iterator<Item = Stance>) -> bool {
    let (ground, all) = stances.fold((0usize, 0usize), |(g, a), s| {
        (g + usize::from(s == Stance::Ground), a + 1)
    });
    all > 0 && 2 * ground >= all
}

/// The flat ground's stereo shift (columns) at image row `row`; 0 at and above the horizon.
pub(super) fn ground_shift(calib: &Calibration, row: f64) -> f64 {
    calib.ground_range(row).map_or(0.0, |range| {
        calib.stereo_disparity(range) / calib.column_width()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A quarter-size panorama (1024 × 192, horizon at row 75).
    fn calib() -> Calibration {
        let text = "[image]\nwidth = 1024\nheight = 192\n[azimuth]\ncolumn0_deg = 180.0\n\
            direction = \"clockwise\"\n[elevation]\nhorizon_row = 75.0\nfocal_px = 163.0\n\
            [mast]\nheight_m = 1.5\n[stereo]\nbaseline_m = 0.3\n";
        Calibration::parse(text, "test").expect("valid")
    }

    /// Value noise: a pseudo-random level per whole pixel of `(x, y)`, interpolated along x.
    fn noise(seed: u64, x: f64, y: usize) -> f64 {
        let level = |xi: i64| {
            let mut h = seed ^ (xi as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (y as u64) << 32;
            h ^= h >> 29;
            h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h ^= h >> 32;
            (h % 1000) as f64 / 1000.0
        };
        let (x0, t) = (x.floor(), x - x.floor());
        level(x0 as i64) * (1.0 - t) + level(x0 as i64 + 1) * t
    }

    /// Rows and columns of a rock standing on the ground, its contact under its last row, a
    /// cast shadow on the ground beside it, and the panoramas' ground bands (luminance).
    struct Scene {
        rock: (std::ops::Range<usize>, std::ops::Range<usize>),
        shadow: (std::ops::Range<usize>, std::ops::Range<usize>),
        left: Vec<u16>,
        right: Vec<u16>,
    }

    /// The left band shows ground texture (fixed to the ground: the right band sees it shifted
    /// by the ground's shift of its row), a darker shadow on it, and a rock whose face is at
    /// its contact range (shifted by the shift of its contact row in the right band).
    fn scene(calib: &Calibration, top: usize) -> Scene {
        let (w, rows) = (1024usize, 192 - top);
        let rock = (60..80, 300..340);
        let shadow = (60..80, 360..420);
        let contact_shift = ground_shift(calib, (top + rock.0.end) as f64);
        let band = |direction: f64| -> Vec<u16> {
            let mut out = vec![0u16; w * rows];
            for y in 0..rows {
                let shift = ground_shift(calib, (top + y) as f64 + 0.5);
                for x in 0..w {
                    // The column of the left band this pixel shows, on the rock's face or on
                    // the ground.
                    let face = x as f64 - direction * contact_shift;
                    let source = x as f64 - direction * shift;
                    let on_rock = rock.0.contains(&y) && rock.1.contains(&(face.round() as usize));
                    let value = if on_rock {
                        150.0 + 300.0 * noise(7, face, y)
                    } else {
                        let ground = 300.0 + 60.0 * noise(3, source, y);
                        // The share of the pixel the shadow covers (its edges anti-aliased).
                        let (a, b) = (shadow.1.start as f64, shadow.1.end as f64);
                        let cover = (0.5 + (source - a).min(b - source)).clamp(0.0, 1.0);
                        let cover = if shadow.0.contains(&y) { cover } else { 0.0 };
                        ground * (1.0 - 0.5 * cover)
                    };
                    out[y * w + x] = value as u16;
                }
            }
            out
        };
        // Clockwise columns: the right camera sees a point at a smaller column.
        let (left, right) = (band(0.0), band(-1.0));
        Scene {
            rock,
            shadow,
            left,
            right,
        }
    }

    /// A standing rock's row shows off the ground's shift by `baseline × rows / mast height`
    /// columns, whatever its range: at 0.3 m and 1.5 m, 7.5 rows for the 1.5-column tolerance,
    /// counted from the highest row the matching window judges on the rock alone.
    #[test]
    fn the_test_tells_a_standing_top_from_the_ground_from_ten_rows_up() {
        let calib = calib();
        for contact in [100.0, 140.0, 180.0] {
            assert!(tells_height(&calib, contact - 8.0 - RADIUS as f64, contact));
            assert!(!tells_height(
                &calib,
                contact - 7.0 - RADIUS as f64,
                contact
            ));
        }
    }

    /// Ground where half or more of the pixels matched at the ground's shift, not where most
    /// were too smooth to tell.
    #[test]
    fn mostly_ground_counts_the_pixels_seen_at_the_grounds_shift() {
        use Stance::{Ground, Unknown};
        assert!(mostly_ground(
            [Ground, Unknown, Ground, Unknown].into_iter()
        ));
        assert!(!mostly_ground([Ground, Unknown, Unknown].into_iter()));
        assert!(!mostly_ground(std::iter::empty()));
    }

    #[test]
    fn a_rock_stands_up_and_its_shadow_lies_on_the_ground() {
        let calib = calib();
        let top = 76;
        let scene = scene(&calib, top);
        let w = 1024;
        let stances = stances(&Bands {
            own: &scene.left,
            other: &scene.right,
            width: w,
            top,
            calib: &calib,
            direction: -1,
        });
        let share = |rows: std::ops::Range<usize>, cols: std::ops::Range<usize>, s: Stance| {
            let n = rows.len() * cols.len();
            let hits = rows
                .flat_map(|y| cols.clone().map(move |x| (y, x)))
                .filter(|&(y, x)| stances[y * w + x] == s)
                .count();
            hits as f64 / n as f64
        };
        // The rock's upper rows (clear of its contact by the hidden rows) stand up.
        let hidden = contact_doubt(&calib);
        let upper = scene.rock.0.start + 2..scene.rock.0.end - hidden as usize;
        let inner = scene.rock.1.start + 3..scene.rock.1.end - 3;
        assert!(share(upper, inner.clone(), Stance::Raised) > 0.9);
        // The shadow and the open ground do not.
        let shaded = scene.shadow.0.start + 3..scene.shadow.0.end - 3;
        assert!(share(shaded.clone(), scene.shadow.1.clone(), Stance::Raised) < 0.02);
        assert!(share(60..80, 500..900, Stance::Raised) < 0.02);
        // The shadow's edges are textured enough to tell: they lie on the ground.
        let (a, b) = (scene.shadow.1.start, scene.shadow.1.end);
        assert!(share(shaded.clone(), a - 2..a + 2, Stance::Ground) > 0.9);
        assert!(share(shaded, b - 2..b + 2, Stance::Ground) > 0.9);
    }

    #[test]
    fn a_smooth_face_matches_best_nearer_than_the_ground() {
        let calib = calib();
        let (top, w) = (76, 1024);
        let rows = 192 - top;
        // A face standing at its foot's range (band row 110), a gentle ramp of 2.5 levels a
        // column: too smooth for the texture test. The ground is level and smooth.
        let (face_rows, face_columns) = (20..110, 300i64..400);
        let face_shift = ground_shift(&calib, (top + face_rows.end) as f64);
        let band = |direction: f64| -> Vec<u16> {
            let mut out = vec![300u16; w * rows];
            for y in face_rows.clone() {
                for x in 0..w {
                    let face = x as f64 - direction * face_shift;
                    if face_columns.contains(&(face.round() as i64)) {
                        out[y * w + x] = (150.0 + 2.5 * (face - 300.0)) as u16;
                    }
                }
            }
            out
        };
        let (left, right) = (band(0.0), band(-1.0));
        let test = GroundTest::new(Bands {
            own: &left,
            other: &right,
            width: w,
            top,
            calib: &calib,
            direction: -1,
        });
        let share = |rows: Range<usize>, columns: Range<usize>, max_shift: usize| {
            let pixels: Vec<(usize, usize)> = rows
                .flat_map(|y| columns.clone().map(move |x| (x, y)))
                .collect();
            let unknown = pixels
                .iter()
                .filter(|&&(x, y)| test.stance(x, y) == Stance::Unknown)
                .count();
            let nearer = pixels
                .iter()
                .filter(|&&(x, y)| test.nearer(x, y, max_shift))
                .count();
            let n = pixels.len() as f64;
            (unknown as f64 / n, nearer as f64 / n)
        };
        // The face's upper rows lie several columns off the ground's shift: the texture test
        // cannot tell them, the best shift can.
        let reach = face_shift.ceil() as usize + 3;
        let (unknown, nearer) = share(20..60, 310..390, reach);
        assert!(unknown > 0.9, "{unknown}");
        assert!(nearer > 0.9, "{nearer}");
        // Smooth ground is never nearer.
        assert_eq!(share(20..110, 500..900, reach).1, 0.0);
        // A blob whose nearest face lies farther does not take this face for its own.
        assert_eq!(share(20..60, 310..390, reach / 2).1, 0.0);
    }

    /// kornia's `gaussian_blur` of the band padded by wrapping at the seam: the reference
    /// [`smooth_region`] of the whole band must equal bit for bit.
    fn smoothed_by_kornia(band: &[u16], width: usize) -> Vec<f32> {
        use kornia_image::{Image, ImageSize};
        let pad = SMOOTHING_REACH;
        let padded_width = width + 2 * pad;
        let padded: Vec<f32> = band
            .chunks_exact(width)
            .flat_map(|row| {
                (0..padded_width).map(move |k| f32::from(row[(k + pad * width - pad) % width]))
            })
            .collect();
        let size = ImageSize {
            width: padded_width,
            height: band.len() / width,
        };
        let src = Image::<f32, 1>::new(size, padded).expect("sized");
        let mut dst = Image::<f32, 1>::from_size_val(size, 0.0).expect("sized");
        let taps = 2 * SMOOTHING_REACH + 1;
        kornia_imgproc::filter::gaussian_blur(
            &src,
            &mut dst,
            (taps, taps),
            (SMOOTHING_PX, SMOOTHING_PX),
        )
        .expect("a valid kernel");
        dst.as_slice()
            .chunks_exact(padded_width)
            .flat_map(|row| row[pad..pad + width].to_vec())
            .collect()
    }

    #[test]
    fn the_smoothing_is_kornias_gaussian_blur_wrapped_at_the_seam() {
        for (width, rows) in [(61, 23), (7, 3), (3, 1), (1, 4)] {
            let band: Vec<u16> = (0..width * rows)
                .map(|i| ((i * 7919 + i * i * 31) % 766) as u16)
                .collect();
            let ours = smooth_region(&band, width, 0..rows, 0..width as isize).values;
            let theirs = smoothed_by_kornia(&band, width);
            assert!(
                ours.iter()
                    .zip(&theirs)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{width} x {rows}"
            );
            assert_eq!(ours.len(), theirs.len());
        }
    }

    /// A band of pseudo-random texture (levels below `amplitude`), and its partner: the same
    /// texture `shift(row)` columns along, with noise of a tenth of the amplitude.
    fn textured_bands(
        width: usize,
        rows: usize,
        amplitude: u16,
        shift: impl Fn(usize) -> usize,
        seed: u64,
    ) -> (Vec<u16>, Vec<u16>) {
        let level = |i: usize, salt: u64| {
            let mut h = seed ^ salt ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            h ^= h >> 31;
            h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h ^= h >> 29;
            (h % u64::from(amplitude)) as u16
        };
        let own: Vec<u16> = (0..width * rows).map(|i| level(i, 1)).collect();
        let other = (0..width * rows)
            .map(|i| {
                let (y, x) = (i / width, i % width);
                own[y * width + (x + shift(y)) % width] + level(i, 2) / 10
            })
            .collect();
        (own, other)
    }

    proptest! {
        /// The tiles tested where they are read give every pixel the costs the whole band's
        /// strips give it, bit for bit: bands of any size (tiles cut at its right edge, strips
        /// at its bottom), either stereo direction, textures faint to rough.
        #[test]
        fn tiles_read_on_demand_cost_as_the_whole_band(
            width in 1usize..300,
            rows in 1usize..116,
            amplitude in 1u16..766,
            shift in 0usize..20,
            rightwards in any::<bool>(),
            seed in any::<u64>(),
        ) {
            let calib = calib();
            let (own, other) = textured_bands(width, rows, amplitude, |_| shift, seed);
            let bands = Bands {
                own: &own,
                other: &other,
                width,
                top: 76,
                calib: &calib,
                direction: if rightwards { 1 } else { -1 },
            };
            let whole = band_costs(&bands);
            let tiles = GroundTest::new(bands);
            for (i, (&c, &t)) in whole.cost.iter().zip(&whole.texture).enumerate() {
                let expected = stance(c, t, tiles.threshold);
                prop_assert_eq!(tiles.stance(i % width, i / width), expected, "pixel {}", i);
            }
        }
    }

    /// The sampled matching noise of a rough ground seen with noise is the whole band's within
    /// 3 %, well above the threshold's floor: a full-size panorama (4096 × 768, horizon at row
    /// 300) whose partner sees the ground at each row's shift.
    #[test]
    fn the_sampled_noise_is_the_whole_bands() {
        let text = "[image]\nwidth = 4096\nheight = 768\n[azimuth]\ncolumn0_deg = 180.0\n\
            direction = \"clockwise\"\n[elevation]\nhorizon_row = 300.0\nfocal_px = 652.0\n\
            [mast]\nheight_m = 1.5\n[stereo]\nbaseline_m = 0.3\n";
        let calib = Calibration::parse(text, "test").expect("valid");
        let (width, top) = (4096, 301);
        let rows = 768 - top;
        // The partner (to the right: smaller columns) sees the ground at its row's shift.
        let ground = |y: usize| {
            let shift = ground_shift(&calib, (top + y) as f64 + 0.5).round() as usize;
            width - shift % width
        };
        let (own, other) = textured_bands(width, rows, 600, ground, 11);
        let bands = Bands {
            own: &own,
            other: &other,
            width,
            top,
            calib: &calib,
            direction: -1,
        };
        let whole = texture_threshold(band_costs(&bands).cost);
        let sampled = GroundTest::new(bands).threshold;
        assert!(whole > 2.0 * MIN_COST, "{whole}");
        assert!((sampled / whole - 1.0).abs() < 0.03, "{sampled} vs {whole}");
    }

    /// A band thinner and narrower than the smoothing kernel and the window is still judged.
    #[test]
    fn a_tiny_band_is_judged_without_panic() {
        let calib = calib();
        for (w, rows) in [(1usize, 1usize), (3, 2), (8, 3)] {
            let band: Vec<u16> = (0..w * rows).map(|i| (i * 37 % 300) as u16).collect();
            let bands = Bands {
                own: &band,
                other: &band,
                width: w,
                top: 150,
                calib: &calib,
                direction: -1,
            };
            assert_eq!(stances(&bands).len(), w * rows);
        }
    }

    #[test]
    fn the_contact_doubt_covers_the_rows_a_face_matches_the_ground() {
        let calib = calib();
        let (contact, doubt) = contact_of(100.0, &calib);
        assert_eq!(contact, 100.0 - RADIUS as f64);
        assert_eq!(doubt, contact_doubt(&calib));
        // k rows above its contact a face is k · 0.2 columns off the ground's shift.
        let per_row = 0.3 / (1.5 * 163.0 * calib.column_width());
        assert!((per_row - 0.2).abs() < 0.01, "{per_row}");
        assert!(doubt * per_row >= TOLERANCE_COLUMNS + RADIUS as f64 * per_row);
    }
}
