//! Connected components of a 360° panorama's mask: kornia labels the image as a plane, then
//! components meeting across the seam (last column next to column 0, 8-connected) are merged,
//! so a rock straddling azimuth zero is one blob.

use super::PixelSample;
use kornia_image::Image;
use kornia_imgproc::connected_components::{connected_components, Connectivity};

/// Pixel statistics of one blob; columns of a seam-straddling blob are unwrapped (its left
/// part shifted by the width), so `col_max` may reach past the width.
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

impl Blob {
    fn empty() -> Blob {
        Blob {
            col_min: usize::MAX,
            row_min: usize::MAX,
            ..Blob::default()
        }
    }

    fn add(&mut self, col: usize, row: usize, s: &PixelSample) {
        self.pixels += 1;
        self.col_min = self.col_min.min(col);
        self.col_max = self.col_max.max(col);
        self.row_min = self.row_min.min(row);
        self.row_max = self.row_max.max(row);
        self.sum_col += col as f64 + 0.5;
        self.sum_row += row as f64 + 0.5;
        let luminance = f64::from(s.rgb[0] + s.rgb[1] + s.rgb[2]);
        for (acc, c) in self.sum_rgb.iter_mut().zip(s.rgb) {
            *acc += f64::from(c);
        }
        self.sum_luminance += luminance;
        self.sum_luminance_sq += luminance * luminance;
        self.sum_ratio += f64::from(s.ratio);
        self.dark += u32::from(s.dark);
    }
}

/// One connected component: its pixels as (unwrapped column, row), in row-major order.
pub(super) type Component = Vec<(u32, u32)>;

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// The components of `mask` (`w` × `rows`, nonzero = set), merged across the seam.
pub(super) fn label_wrapped(mask: &Image<u8, 1>, w: usize, rows: usize) -> Vec<Component> {
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
    let mut components: Vec<Component> = vec![Vec::new(); parent.len()];
    for (y, row) in labels.chunks_exact(w).enumerate() {
        for (x, &label) in row.iter().enumerate() {
            if label <= 0 {
                continue;
            }
            let root = roots[label as usize];
            let col = if wraps[root] && x < w / 2 { x + w } else { x };
            components[root].push((col as u32, y as u32));
        }
    }
    components.retain(|c| !c.is_empty());
    components
}

/// The statistics of `pixels` with `sample(column mod w, row)`.
pub(super) fn blob_of(
    pixels: &[(u32, u32)],
    w: usize,
    sample: &impl Fn(usize, usize) -> PixelSample,
) -> Blob {
    let mut blob = Blob::empty();
    for &(col, row) in pixels {
        let (col, row) = (col as usize, row as usize);
        blob.add(col, row, &sample(col % w, row));
    }
    blob
}

/// `[column_min, row_min, column_max, row_max]` of a set of pixels, if it has any.
pub(super) fn bounds(pixels: &[(u32, u32)]) -> Option<[u32; 4]> {
    let (&(c, r), rest) = pixels.split_first()?;
    Some(rest.iter().fold([c, r, c, r], |[c0, r0, c1, r1], &(c, r)| {
        [c0.min(c), r0.min(r), c1.max(c), r1.max(r)]
    }))
}

/// Where each pixel of a set sits in it, by (column, row): a dense grid over the set's
/// bounding box, cheaper than hashing for blob-sized sets.
pub(super) struct PixelIndex {
    col0: i64,
    row0: i64,
    cols: i64,
    rows: i64,
    slots: Vec<u32>,
}

impl PixelIndex {
    pub fn new(pixels: &[(u32, u32)]) -> PixelIndex {
        let ([c0, r0, _, _], cols, rows) = match bounds(pixels) {
            Some(b) => (b, i64::from(b[2] - b[0]) + 1, i64::from(b[3] - b[1]) + 1),
            None => ([0; 4], 0, 0),
        };
        let mut index = PixelIndex {
            col0: i64::from(c0),
            row0: i64::from(r0),
            cols,
            rows,
            slots: vec![u32::MAX; (cols * rows) as usize],
        };
        for (k, &(c, r)) in pixels.iter().enumerate() {
            let slot = index.slot(i64::from(c), i64::from(r)).unwrap_or(0);
            index.slots[slot] = k as u32;
        }
        index
    }

    fn slot(&self, col: i64, row: i64) -> Option<usize> {
        let (c, r) = (col - self.col0, row - self.row0);
        ((0..self.cols).contains(&c) && (0..self.rows).contains(&r))
            .then(|| (r * self.cols + c) as usize)
    }

    /// The position in the set of the pixel at (`col`, `row`), if it belongs to the set.
    pub fn get(&self, col: i64, row: i64) -> Option<usize> {
        let k = self.slots[self.slot(col, row)?];
        (k != u32::MAX).then_some(k as usize)
    }
}

/// The 8-connected parts of a set of pixels, each in the input's order.
pub(super) fn connected(pixels: &[(u32, u32)]) -> Vec<Component> {
    let index = PixelIndex::new(pixels);
    let mut part = vec![usize::MAX; pixels.len()];
    let mut count = 0;
    for start in 0..pixels.len() {
        if part[start] != usize::MAX {
            continue;
        }
        part[start] = count;
        let mut stack = vec![start];
        while let Some(k) = stack.pop() {
            let (col, row) = (i64::from(pixels[k].0), i64::from(pixels[k].1));
            for dc in -1..=1 {
                for dr in -1..=1 {
                    if let Some(j) = index.get(col + dc, row + dr) {
                        if part[j] == usize::MAX {
                            part[j] = count;
                            stack.push(j);
                        }
                    }
                }
            }
        }
        count += 1;
    }
    let mut parts = vec![Vec::new(); count];
    for (&p, &k) in pixels.iter().zip(&part) {
        parts[k].push(p);
    }
    parts
}
