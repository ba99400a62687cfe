//! How far a rock may reach beyond a blob, by hysteresis of the colour test against the
//! blob's own surroundings.
//!
//! A rock nearly the soil's colour passes the colour test only where it differs most: its
//! shaded side, a band along its foot, a lit top. On stress seed 13 (albedo contrast 0.49
//! under a low sun) 198 of the 251 fused sightings were such pieces, holding under 30 % of
//! their rock's pixels, and only 69 % of their bearing intervals held the rock (`pipeline
//! eval`, `bearing_pieces`). The row's median, against which the test is set, is a poor
//! reference for a faint difference: soil tints and lighting change along a row by more than
//! the faint margin. The soil right around a blob is a good one. So the pixels around each
//! blob that pass the test by a fraction of its margins ([`FAINT`]) against the median of the
//! soil in a window around it, and join the blob, may be more of its rock (edge detection's
//! hysteresis, with a local background), and the piece's bearing is widened over them as over
//! the stereo test's raised pixels (`extent`). Taking them into the blob instead moved the
//! detections of well-found rocks too and cost marsyard surveys up to 6 points of fused share
//! (docs/RUN.md, stop 55).

use super::components::{bounds, Component};
use super::DetectorSettings;
use rayon::prelude::*;

/// Share of the colour test's margins that a pixel joined to a blob needs to pass.
const FAINT: f32 = 0.5;

/// The window around a blob whose soil is its background reaches this many of the blob's
/// widths beside it, and above and below it as many of its heights or widths, whichever is
/// more (a piece may be a band along the rock's foot, and a rock may rise as high as it is
/// wide); the reach is searched only within it.
const WINDOW_SPANS: u32 = 1;

/// Pixels beyond the ring next to a blob that it must take in, as a share of its own pixels,
/// for its growth to count: a rock the colour test found whole only gains its blurred edge.
const MIN_GROWTH: f64 = 0.5;

/// A faint pixel differs from the soil by at least this many of the soil's own spreads (its
/// median absolute deviation scaled to a standard deviation): sensor noise and soil texture
/// must not pass for rock.
const SPREADS: f32 = 3.0;

/// Fewest soil pixels in the window for its median to be a background.
const MIN_SOIL: usize = 16;

/// Columns before and after each of `blobs` (components of `mask`, nonzero = rock, over the
/// ground band `raw`, `w` columns, RGB) that the faint pixels joined to it reach; `[0, 0]`
/// where they are only its blurred edge. Blobs in parallel.
pub(super) fn reach(
    blobs: &[&Component],
    mask: &[u8],
    raw: &[u8],
    w: usize,
    settings: &DetectorSettings,
) -> Vec<[u32; 2]> {
    let rows = mask.len() / w;
    blobs
        .par_iter()
        .map(|blob| {
            let grown = grow_blob(blob, mask, raw, w, rows, settings);
            let (Some([first, _, last, _]), false) = (bounds(blob), grown.is_empty()) else {
                return [0, 0];
            };
            let (first, last) = (i64::from(first), i64::from(last));
            grown.iter().fold([0, 0], |[before, after], &(c, _)| {
                [
                    before.max((first - c).max(0) as u32),
                    after.max((c - last).max(0) as u32),
                ]
            })
        })
        .collect()
}

/// The pixels (unwrapped column, row) one blob takes in, none if they are only its edge.
fn grow_blob(
    blob: &Component,
    mask: &[u8],
    raw: &[u8],
    w: usize,
    rows: usize,
    settings: &DetectorSettings,
) -> Vec<(i64, i64)> {
    let Some([c0, r0, c1, r1]) = bounds(blob) else {
        return Vec::new();
    };
    let (span_c, span_r) = (
        WINDOW_SPANS * (c1 - c0 + 1),
        WINDOW_SPANS * (r1 - r0 + 1).max(c1 - c0 + 1),
    );
    let columns = (
        i64::from(c0) - i64::from(span_c),
        i64::from(c1) + i64::from(span_c),
    );
    let row_range = (
        i64::from(r0.saturating_sub(span_r)),
        (i64::from(r1) + i64::from(span_r)).min(rows as i64 - 1),
    );
    let index = |c: i64, r: i64| r as usize * w + c.rem_euclid(w as i64) as usize;
    let sample = |i: usize| {
        let p = &raw[3 * i..3 * i + 3];
        let sum = f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2]);
        (sum, (f32::from(p[0]) - f32::from(p[2])) / (sum + 1.0))
    };
    // The soil's median luminance and redness in the window.
    let (mut sums, mut reds) = (Vec::new(), Vec::new());
    for r in row_range.0..=row_range.1 {
        for c in columns.0..=columns.1 {
            let i = index(c, r);
            if mask[i] == 0 {
                let (s, red) = sample(i);
                sums.push(s);
                reds.push(red);
            }
        }
    }
    if sums.len() < MIN_SOIL {
        return Vec::new();
    }
    let (soil_sum, sum_spread) = median_and_spread(&mut sums);
    let (soil_red, red_spread) = median_and_spread(&mut reds);
    let bright =
        soil_sum + (FAINT * (settings.bright_ratio - 1.0) * soil_sum).max(SPREADS * sum_spread);
    let dark = settings.dark_ratio * soil_sum;
    let grey = soil_red - (FAINT * settings.chroma_drop).max(SPREADS * red_spread);
    let dark_grey = soil_red - (FAINT * settings.dark_chroma_drop).max(SPREADS * red_spread);
    let faint = |i: usize| {
        let (sum, red) = sample(i);
        red < grey || sum > bright || (sum < dark && red < dark_grey)
    };
    let width = (columns.1 - columns.0 + 1) as usize;
    let mut seen = vec![false; width * (row_range.1 - row_range.0 + 1) as usize];
    let slot = |c: i64, r: i64| (r - row_range.0) as usize * width + (c - columns.0) as usize;
    let mut stack: Vec<(i64, i64)> = blob
        .iter()
        .map(|&(c, r)| (i64::from(c), i64::from(r)))
        .collect();
    let mut grown = Vec::new();
    while let Some((c, r)) = stack.pop() {
        for (nc, nr) in (-1..=1).flat_map(|dc| (-1..=1).map(move |dr| (c + dc, r + dr))) {
            if nc < columns.0 || nc > columns.1 || nr < row_range.0 || nr > row_range.1 {
                continue;
            }
            let (i, k) = (index(nc, nr), slot(nc, nr));
            if mask[i] != 0 || seen[k] {
                continue;
            }
            seen[k] = true;
            if faint(i) {
                grown.push((nc, nr));
                stack.push((nc, nr));
            }
        }
    }
    // The faint ring just outside a blob is its edge, blurred over a pixel by the optics and
    // the pixel grid, not more of its rock: growth counts only if it reaches well beyond.
    let core = |c: i64, r: i64| {
        (-1..=1).any(|dc| {
            (-1..=1).any(|dr| {
                let nr = r + dr;
                (0..rows as i64).contains(&nr) && mask[index(c + dc, nr)] != 0
            })
        })
    };
    let beyond = grown.iter().filter(|&&(c, r)| !core(c, r)).count();
    if (beyond as f64) < MIN_GROWTH * blob.len() as f64 {
        return Vec::new();
    }
    grown
}

/// Median of `values` and their median absolute deviation scaled to a normal standard
/// deviation.
fn median_and_spread(values: &mut [f32]) -> (f32, f32) {
    let mid = values.len() / 2;
    let median = *values.select_nth_unstable_by(mid, f32::total_cmp).1;
    for v in values.iter_mut() {
        *v = (*v - median).abs();
    }
    let mad = *values.select_nth_unstable_by(mid, f32::total_cmp).1;
    (median, 1.4826 * mad)
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: usize = 60;
    const ROWS: usize = 20;
    const SOIL: [u8; 3] = [150, 100, 70];
    /// Redness 0.218 against the soil's 0.249: past half the colour test's margin (0.035).
    const FAINT_GREY: [u8; 3] = [145, 100, 75];

    /// A band of soil with a grey blob at columns 20–24, rows 5–9 (the colour test's mask).
    fn band() -> (Vec<u8>, Vec<u8>, Vec<Component>) {
        let mut raw: Vec<u8> = SOIL.repeat(W * ROWS);
        let mut mask = vec![0u8; W * ROWS];
        let mut blob = Component::new();
        for r in 5..10 {
            for c in 20..25 {
                raw[3 * (r * W + c)..3 * (r * W + c) + 3].copy_from_slice(&[100, 100, 100]);
                mask[r * W + c] = 255;
                blob.push((c as u32, r as u32));
            }
        }
        (raw, mask, vec![blob])
    }

    fn paint(raw: &mut [u8], columns: std::ops::Range<usize>, rows: std::ops::Range<usize>) {
        for r in rows {
            for c in columns.clone() {
                raw[3 * (r * W + c)..3 * (r * W + c) + 3].copy_from_slice(&FAINT_GREY);
            }
        }
    }

    #[test]
    fn faint_pixels_joined_to_a_blob_bound_its_reach() {
        let (mut raw, mask, blobs) = band();
        // The rest of the rock, faintly grey, runs 4 columns on from the blob's right end.
        paint(&mut raw, 25..29, 5..10);
        let settings = DetectorSettings::default();
        assert_eq!(reach(&[&blobs[0]], &mask, &raw, W, &settings), vec![[0, 4]]);
        // Beyond the window (one blob width) the search stops.
        paint(&mut raw, 25..40, 5..10);
        assert_eq!(reach(&[&blobs[0]], &mask, &raw, W, &settings), vec![[0, 5]]);
    }

    #[test]
    fn a_blurred_edge_alone_reaches_nothing() {
        let (mut raw, mask, blobs) = band();
        // A one-pixel faint ring around the blob.
        paint(&mut raw, 19..26, 4..5);
        paint(&mut raw, 19..26, 10..11);
        paint(&mut raw, 19..20, 5..10);
        paint(&mut raw, 25..26, 5..10);
        let settings = DetectorSettings::default();
        assert_eq!(reach(&[&blobs[0]], &mask, &raw, W, &settings), vec![[0, 0]]);
    }

    #[test]
    fn soil_as_varied_as_the_faint_margin_does_not_pass_for_rock() {
        let (mut raw, mask, blobs) = band();
        // A checkerboard soil whose redness varies by 0.06: half its pixels lie past the
        // faint margin below the other half.
        for r in 0..ROWS {
            for c in 0..W {
                if mask[r * W + c] == 0 && (r + c) % 2 == 0 {
                    raw[3 * (r * W + c)..3 * (r * W + c) + 3].copy_from_slice(&[140, 100, 80]);
                }
            }
        }
        let settings = DetectorSettings::default();
        assert_eq!(reach(&[&blobs[0]], &mask, &raw, W, &settings), vec![[0, 0]]);
    }
}
