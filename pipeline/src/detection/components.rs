//! Connected components of a 360° panorama's mask: kornia labels the image as a plane, then
//! components meeting across the seam (last column next to column 0, 8-connected) are merged,
//! so a rock straddling azimuth zero is one blob.

use super::PixelSample;
use kornia_image::Image;
use kornia_imgproc::connected_components::{connected_components, Connectivity};

/// Pixel statistics of one merged component; columns of a seam-straddling blob are unwrapped
/// (its left part shifted by the width), so `col_max` may reach past the width.
#[derive(Clone, Debug, Default)]
pub(super) struct Blob {
    pub pixels: u32,
    pub col_min: usize,
    pub col_max: usize,
    pub row_min: usize,
    pub row_max: usize,
    pub sum_col: f64,
    pub sum_row: f64,
    pub sum_rgb: [f64; 3],
    pub sum_luminance: f64,
    pub sum_luminance_sq: f64,
    pub sum_ratio: f64,
    pub dark: u32,
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// The components of `mask` (`w` × `rows`, nonzero = set), merged across the seam, with the
/// statistics of `sample(pixel index)` over their pixels.
pub(super) fn label_wrapped(
    mask: &Image<u8, 1>,
    w: usize,
    rows: usize,
    sample: impl Fn(usize) -> PixelSample,
) -> Vec<Blob> {
    let Ok(mut labels) = Image::<i32, 1>::from_size_val(mask.size(), 0) else {
        return Vec::new();
    };
    let Ok(count) = connected_components(mask, &mut labels, Connectivity::Eight) else {
        return Vec::new();
    };
    let labels = labels.as_slice();
    let mut parent: Vec<usize> = (0..count.max(1) as usize).collect();
    let mut seam_pairs = Vec::new();
    for y in 0..rows {
        let left = labels[y * w] as usize;
        if left == 0 {
            continue;
        }
        for yy in y.saturating_sub(1)..(y + 2).min(rows) {
            let right = labels[yy * w + w - 1] as usize;
            if right != 0 {
                let (a, b) = (find(&mut parent, left), find(&mut parent, right));
                parent[a.max(b)] = a.min(b);
                seam_pairs.push(left);
            }
        }
    }
    let mut wraps = vec![false; parent.len()];
    for left in seam_pairs {
        wraps[find(&mut parent, left)] = true;
    }
    let roots: Vec<usize> = (0..parent.len()).map(|l| find(&mut parent, l)).collect();
    let mut blobs: Vec<Option<Blob>> = vec![None; parent.len()];
    for (i, &label) in labels.iter().enumerate() {
        if label <= 0 {
            continue;
        }
        let root = roots[label as usize];
        let (x, y) = (i % w, i / w);
        let col = if wraps[root] && x < w / 2 { x + w } else { x };
        let s = sample(i);
        let b = blobs[root].get_or_insert_with(|| Blob {
            col_min: usize::MAX,
            row_min: usize::MAX,
            ..Blob::default()
        });
        b.pixels += 1;
        b.col_min = b.col_min.min(col);
        b.col_max = b.col_max.max(col);
        b.row_min = b.row_min.min(y);
        b.row_max = b.row_max.max(y);
        b.sum_col += col as f64 + 0.5;
        b.sum_row += y as f64 + 0.5;
        let luminance = f64::from(s.rgb[0] + s.rgb[1] + s.rgb[2]);
        for (acc, c) in b.sum_rgb.iter_mut().zip(s.rgb) {
            *acc += f64::from(c);
        }
        b.sum_luminance += luminance;
        b.sum_luminance_sq += luminance * luminance;
        b.sum_ratio += f64::from(s.ratio);
        b.dark += u32::from(s.dark);
    }
    blobs.into_iter().flatten().collect()
}
