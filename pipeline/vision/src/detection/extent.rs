//! How far the rock a blob belongs to may reach beyond the blob.
//!
//! The colour test can find only part of a rock: a rock nearly the soil's colour shows its
//! shaded side and little else (stress member 5, albedo contrast 0.58: a 7-column piece of a
//! rock 26 columns wide, its centroid 11 columns off the rock's centre, far outside the
//! centroid's error model; 16 % of the bearings that run used lay outside their intervals).
//! The stereo test tells such a rock from the ground wherever its face is textured
//! (`ground`), and where it is smooth by the shift it matches best, nearer than the ground's
//! (stress s16: a rock 221 columns wide, nearly the soil's colour, of which the colour test
//! found a 47-column corner; its smooth face left the textured test's raised pixels in
//! pieces, and the corner's bearing 8.5 intervals off). So the pixels standing up from the
//! ground that the colour test left out, and that join the blob, may be more of its rock:
//! the rock holds the blob and lies within them, and its centre lies between the centres of
//! the narrowest and the widest such spans (`ranging` widens the bearing accordingly). They
//! stop at other blobs: a neighbour the colour test found is a rock of its own.

use super::components::{bounds, Component};

/// Columns the raised pixels joined to `blob` (unwrapped (column, row) pixels of a band `w`
/// wide and `rows` high) reach before and after the blob's own columns, through pixels
/// outside `mask` (the colour test's rock pixels, nonzero); `[0, 0]` when nothing raised
/// joins it. `raised(column, row)` (unwrapped column) is the stereo test's verdict; the search
/// stays within `limit` columns of the blob, and within `rise` rows above it and one below.
pub(super) fn beyond(
    blob: &Component,
    mask: &[u8],
    w: usize,
    rows: usize,
    (limit, rise): (u32, u32),
    raised: impl Fn(i64, i64) -> bool,
) -> [u32; 2] {
    let Some([first, top, last, bottom]) = bounds(blob).map(|b| b.map(i64::from)) else {
        return [0, 0];
    };
    let limit = i64::from(limit);
    let (columns, row_range) = (
        first - limit..=last + limit,
        (top - i64::from(rise)).max(0)..=(bottom + 1).min(rows as i64 - 1),
    );
    // Pixels tested, over the searched rows and columns (wrapped when the columns go round
    // the panorama).
    let span = (columns.end() - columns.start() + 1).min(w as i64);
    let mut seen = vec![false; span as usize * (row_range.end() - row_range.start() + 1) as usize];
    let mut stack: Vec<(i64, i64)> = blob
        .iter()
        .map(|&(c, r)| (i64::from(c), i64::from(r)))
        .collect();
    let (mut low, mut high) = (first, last);
    while let Some((c, r)) = stack.pop() {
        for (nc, nr) in (-1..=1).flat_map(|dc| (-1..=1).map(move |dr| (c + dc, r + dr))) {
            if !columns.contains(&nc) || !row_range.contains(&nr) {
                continue;
            }
            let i = nr as usize * w + nc.rem_euclid(w as i64) as usize;
            let slot = ((nr - row_range.start()) * span + (nc - columns.start()).rem_euclid(span))
                as usize;
            // Each pixel is tested once: the stereo verdict may cost a search over shifts.
            if mask[i] != 0 || seen[slot] {
                continue;
            }
            seen[slot] = true;
            if !raised(nc, nr) {
                continue;
            }
            low = low.min(nc);
            high = high.max(nc);
            stack.push((nc, nr));
        }
    }
    [(first - low) as u32, (high - last) as u32]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the pixel at an unwrapped column and a row is among `raised` (wrapped).
    fn raised_at(w: usize, raised: &[(usize, usize)]) -> impl Fn(i64, i64) -> bool + '_ {
        move |c, r| raised.contains(&(c.rem_euclid(w as i64) as usize, r as usize))
    }

    #[test]
    fn raised_pixels_beside_a_blob_extend_it() {
        // Blob: columns 5..=7 of row 1; raised: columns 2..=4 and 8..=12 of row 1.
        let (w, rows) = (20, 3);
        let blob: Component = (5..=7).map(|c| (c, 1)).collect();
        let mut mask = vec![0u8; w * rows];
        for c in 5..=7 {
            mask[w + c] = 255;
        }
        let raised: Vec<(usize, usize)> = (2..=4).chain(8..=12).map(|c| (c, 1)).collect();
        let at = raised_at(w, &raised);
        assert_eq!(beyond(&blob, &mask, w, rows, (100, 100), &at), [3, 5]);
        assert_eq!(beyond(&blob, &mask, w, rows, (2, 100), &at), [2, 2]);
        // Another blob of the colour mask at columns 10..=12 stops the reach at column 9.
        for c in 10..=12 {
            mask[w + c] = 255;
        }
        assert_eq!(beyond(&blob, &mask, w, rows, (100, 100), &at), [3, 2]);
    }

    #[test]
    fn the_reach_crosses_the_seam() {
        // Blob: columns 18..=19 of row 0; raised: columns 0..=2 (after the seam).
        let (w, rows) = (20, 2);
        let blob: Component = vec![(18, 0), (19, 0)];
        let mut mask = vec![0u8; w * rows];
        mask[18] = 255;
        mask[19] = 255;
        let raised = [(0, 0), (1, 0), (2, 0)];
        assert_eq!(
            beyond(&blob, &mask, w, rows, (100, 100), raised_at(w, &raised)),
            [0, 3]
        );
    }
}
