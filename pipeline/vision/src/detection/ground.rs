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

/// Half-size of the matching window, pixels.
const RADIUS: usize = 2;

/// A pixel is textured enough for the test when its cost against itself shifted by
/// [`SELF_SHIFT`] exceeds this many times the band's median matching cost (most of the band is
/// soil matched at its own shift: the median is the matching noise of the images, whatever
/// their noise, blur or compression) …
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

/// The stance of each pixel of the ground band (`own.len() / width` rows from image row
/// `top`), given the luminance (`r + g + b`) of both panoramas' bands; `direction` is the
/// other camera's column step per unit of shift.
pub(super) fn stances(
    own: &[u16],
    other: &[u16],
    width: usize,
    top: usize,
    calib: &Calibration,
    direction: isize,
) -> Vec<Stance> {
    let rows = own.len() / width;
    let (own, other) = rayon::join(|| smoothed(own, width), || smoothed(other, width));
    let (own, other) = (&own, &other);
    let mut cost = vec![0f32; own.len()];
    let mut texture = vec![0f32; own.len()];
    // Rows in parallel: each is its own windows' sums.
    cost.par_chunks_mut(width)
        .zip(texture.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, (out, texture))| {
            let shift = ground_shift(calib, (top + y) as f64 + 0.5);
            let (ya, yb) = (y.saturating_sub(RADIUS), (y + RADIUS + 1).min(rows));
            let (own_band, other_band) =
                (&own[ya * width..yb * width], &other[ya * width..yb * width]);
            out.fill(f32::INFINITY);
            for s in [shift.floor(), shift.ceil()] {
                let sums = window_costs(own_band, other_band, width, direction * s as isize);
                for (o, c) in out.iter_mut().zip(sums) {
                    *o = o.min(c);
                }
            }
            // The same neighbourhood against itself shifted past the tolerance: how much a
            // mismatch of the shift would cost.
            texture.copy_from_slice(&window_costs(own_band, own_band, width, SELF_SHIFT));
        });
    let threshold = (NOISE_MULTIPLE * median(&cost)).max(MIN_COST);
    cost.into_iter()
        .zip(texture)
        .map(|(c, t)| {
            if t <= threshold {
                Stance::Unknown
            } else if c > MISMATCH_RATIO * t {
                Stance::Raised
            } else {
                Stance::Ground
            }
        })
        .collect()
}

/// Rows above and below a pixel that its stance depends on: the matching window's and the
/// smoothing's.
pub(super) const READ_ROWS: usize = RADIUS + SMOOTHING_REACH;

/// Columns a neighbourhood is shifted against itself to tell whether it is textured enough
/// for the test: past [`TOLERANCE_COLUMNS`].
const SELF_SHIFT: isize = 2;

/// Mean absolute difference, per pixel of a row, between the window of `a` around it and the
/// window of `b` shifted by `offset` columns; `a` and `b` hold the window's rows (`width`
/// each, the middle one the row's), columns wrap at the seam.
fn window_costs(a: &[f32], b: &[f32], width: usize, offset: isize) -> Vec<f32> {
    let rows = a.len() / width;
    let mut column_sums = vec![0f32; width];
    let start = offset.rem_euclid(width as isize) as usize;
    let split = width - start;
    for (ra, rb) in a.chunks_exact(width).zip(b.chunks_exact(width)) {
        // Column x of `a` against column x + start of `b`, wrapping at the seam: two
        // contiguous runs, which compile to vector instructions (one chained run did not).
        let (sums_before, sums_after) = column_sums.split_at_mut(split);
        let (ra_before, ra_after) = ra.split_at(split);
        for ((sum, p), q) in sums_before.iter_mut().zip(ra_before).zip(&rb[start..]) {
            *sum += (p - q).abs();
        }
        for ((sum, p), q) in sums_after.iter_mut().zip(ra_after).zip(&rb[..start]) {
            *sum += (p - q).abs();
        }
    }
    let area = (rows * (2 * RADIUS + 1)) as f32;
    window_sums(&column_sums)
        .into_iter()
        .map(|c| c / area)
        .collect()
}

/// Standard deviation (pixels) of the Gaussian both bands are smoothed with before matching:
/// JPEG rings at edges differently in each panorama, as much as half of what a shift of two
/// columns changes there; smoothed, a cast shadow's edge on the ground matches as in a
/// lossless image (marsyard seed 2 at quality 85).
const SMOOTHING_PX: f32 = 1.0;

/// Pixels the smoothing kernel reaches either side: two standard deviations hold 95 % of its
/// weight.
const SMOOTHING_REACH: usize = 2 * SMOOTHING_PX as usize;

/// `band` (rows of `width`) smoothed by kornia's Gaussian kernel of [`SMOOTHING_PX`], wrapping
/// at the seam and taking rows beyond the band as zero, as kornia's `gaussian_blur` would: the
/// same sums in the same order. Written as two passes over whole rows, rows in parallel, which
/// compile to vector instructions: kornia 0.2's separable filter tests every tap's bounds on
/// one thread, 22 ms a band at 4096 × 768, half the stereo test's time in a navigator's step.
fn smoothed(band: &[u16], width: usize) -> Vec<f32> {
    let kernel = gaussian_kernel_1d(2 * SMOOTHING_REACH + 1, SMOOTHING_PX);
    let pad = SMOOTHING_REACH;
    let rows = band.len() / width;
    let mut across = vec![0f32; band.len()];
    across
        .par_chunks_mut(width)
        .zip(band.par_chunks(width))
        .for_each(|(out, row)| {
            let wrapped = |k: usize| f32::from(row[k % width]);
            let padded: Vec<f32> = (0..width + 2 * pad)
                .map(|k| wrapped(k + pad * width - pad))
                .collect();
            for (k, &weight) in kernel.iter().enumerate() {
                for (o, &v) in out.iter_mut().zip(&padded[k..k + width]) {
                    *o += v * weight;
                }
            }
        });
    let mut out = vec![0f32; band.len()];
    out.par_chunks_mut(width).enumerate().for_each(|(y, out)| {
        for (k, &weight) in kernel.iter().enumerate() {
            let Some(from) = (y + k).checked_sub(pad).filter(|&r| r < rows) else {
                continue;
            };
            for (o, &v) in out
                .iter_mut()
                .zip(&across[from * width..(from + 1) * width])
            {
                *o += v * weight;
            }
        }
    });
    out
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

/// The flat ground's stereo shift (columns) at image row `row`; 0 at and above the horizon.
fn ground_shift(calib: &Calibration, row: f64) -> f64 {
    calib.ground_range(row).map_or(0.0, |range| {
        calib.stereo_disparity(range) / calib.column_width()
    })
}

/// Sums of `2·RADIUS + 1` consecutive values around each column, wrapping at the seam.
fn window_sums(values: &[f32]) -> Vec<f32> {
    let w = values.len();
    let at = |x: isize| values[x.rem_euclid(w as isize) as usize];
    let r = RADIUS;
    let mut sum: f32 = (-(r as isize)..=r as isize).map(at).sum();
    // Indices wrap only near the seam; elsewhere they index directly (no division a column).
    (0..w)
        .map(|x| {
            let out = sum;
            let entering = if x + r + 1 < w {
                values[x + r + 1]
            } else {
                at((x + r + 1) as isize)
            };
            let leaving = if x >= r {
                values[x - r]
            } else {
                at(x as isize - r as isize)
            };
            sum += entering - leaving;
            out
        })
        .collect()
}

fn median(values: &[f32]) -> f32 {
    let mut finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return 0.0;
    }
    let mid = finite.len() / 2;
    *finite.select_nth_unstable_by(mid, f32::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn a_rock_stands_up_and_its_shadow_lies_on_the_ground() {
        let calib = calib();
        let top = 76;
        let scene = scene(&calib, top);
        let w = 1024;
        let stances = stances(&scene.left, &scene.right, w, top, &calib, -1);
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

    /// A band thinner and narrower than the smoothing kernel and the window is still judged.
    /// kornia's `gaussian_blur` of the band padded by wrapping at the seam: the reference
    /// [`smoothed`] must equal bit for bit.
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
            let ours = smoothed(&band, width);
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

    #[test]
    fn a_tiny_band_is_judged_without_panic() {
        let calib = calib();
        for (w, rows) in [(1usize, 1usize), (3, 2), (8, 3)] {
            let band: Vec<u16> = (0..w * rows).map(|i| (i * 37 % 300) as u16).collect();
            assert_eq!(stances(&band, &band, w, 150, &calib, -1).len(), w * rows);
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
