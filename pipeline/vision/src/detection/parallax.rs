//! Separating rocks at different ranges by stereo parallax (000 §IV, range cue (c)). A farther
//! rock seen over or beside a nearer one of the same tint merges with it in the mask, and the
//! nearer rock hides the farther one's bottom edge, so the notch rule of [`super::split`] cannot
//! see it. The other camera of the rotating head sees every point turned in azimuth by
//! `2·asin(b / 2d)`, less for the farther rock. Each blob pixel's shift is found by block
//! matching against the other panorama; a blob whose shifts fall into two groups apart by a
//! step (an occluding edge) rather than a slope (one rock's curved face), and far enough apart
//! in range that two rocks fit, is separated into a nearer and a farther layer.

use super::components::{bounds, connected, Component, PixelIndex};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, VecDeque};

/// The other panorama of the stereo pair, for block matching.
pub(super) struct Partner<'a> {
    /// Luminance (`r + g + b`) of this panorama's ground band and of the other's, row-major.
    pub own: &'a [u16],
    pub other: &'a [u16],
    pub width: usize,
    pub rows: usize,
    /// `+1` or `−1`: the other camera sees a point this many columns per pixel of shift.
    pub direction: isize,
    /// Radians per column, and the stereo baseline (metres): shifts to ranges.
    pub column_width: f64,
    pub baseline_m: f64,
}

impl Partner<'_> {
    /// Range (metres) of a point seen shifted by `shift` columns (`Calibration::stereo_range`).
    fn range(&self, shift: f32) -> f64 {
        self.baseline_m / (2.0 * (0.5 * f64::from(shift.max(0.01)) * self.column_width).sin())
    }
}

/// When a blob is separated by parallax (`DetectorSettings::parallax`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParallaxRule {
    /// Window half-size of the block matching, pixels.
    pub radius: usize,
    /// Blobs with fewer pixels are left whole (too few windows to tell two groups apart).
    pub min_pixels: usize,
    /// The shift jumps across the border between the groups by this many pixels at least
    /// (matching noise) …
    pub min_step_px: f32,
    /// … and by this fraction of the nearer group's shift …
    pub min_step_fraction: f32,
    /// … and by this fraction of the difference of the groups' means: a step, where one
    /// rock's curved face would show a slope.
    pub step_ratio: f32,
    /// The jump puts the farther surface behind the nearer by this many of the nearer layer's
    /// half-widths at least: two rocks cannot overlap, while one rock's face curves back by
    /// about its half-width from its middle to its sides.
    pub min_depth_halfwidths: f64,
    /// Each group holds at least this fraction of the blob's reliable pixels.
    pub min_share: f32,
    /// Fragments of a layer smaller than this (pixels) join the other layer.
    pub min_fragment: usize,
    /// Disconnected parts of a separated layer smaller than this fraction of its largest part
    /// are dropped.
    pub sliver_fraction: f32,
}

/// Whether a detection's blob was separated by parallax, and which part it is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Separation {
    /// Not separated.
    #[default]
    Whole,
    /// In front of the farther part(s) it was separated from: its outline against them is its
    /// own occluding edge, so touching them does not make its centroid doubtful.
    Nearer,
    /// Behind a nearer part, which may hide some of it (its foot at least).
    Farther,
}

/// Most matching costs held for one blob (64 MB), and most window sums computed for it (about
/// a tenth of a second): a rock filling the bottom of the panorama right before the rover, or
/// a sparse blob spread over a wide box, is left whole rather than matched over hundreds of
/// shifts.
const MAX_COSTS: usize = 1 << 24;
const MAX_WORK: usize = 1 << 27;

/// Blobs whose matching would take more window sums than this are matched at half resolution
/// (2 × 2 means, a quarter of the pixels over half the shifts: an eighth of the work). Only a
/// large rock close to the rover reaches it (tens of thousands of pixels over 100–190 shifts;
/// up to a seventh of a second on one core at 4096 columns), and its shifts are large: a
/// shift found to a fraction of a half-resolution column still gives its range to about 1 %.
const COARSE_WORK: usize = 1 << 22;

/// A connected part of a blob at one range.
pub(super) struct Layer {
    pub pixels: Component,
    pub part: Separation,
    /// For a separated part, the [`SHIFT_QUANTILES`] of its pixels' reliable shifts (columns):
    /// its own stereo evidence, since the other panorama's blob holds both parts.
    pub shifts: Option<[f32; 2]>,
    /// For a blob matched and left whole, each pixel's shift, in the order of `pixels`
    /// (empty if it was not matched): the pieces it is cut into take theirs ([`ShiftLookup`]).
    pub pixel_shifts: Vec<Option<f32>>,
}

/// The shifts of a blob matched and left whole, by pixel, for the pieces it is cut into: a
/// piece's own stereo evidence, since a piece touching another has no counterpart in the other
/// panorama (`ranging::stereo::match_stereo` leaves it unpaired).
pub(super) struct ShiftLookup(HashMap<(u32, u32), f32>);

impl ShiftLookup {
    /// The reliable shifts of `pixels`, given in the same order (`shifts` is empty for a blob
    /// that was not matched).
    pub fn new(pixels: &[(u32, u32)], shifts: Vec<Option<f32>>) -> ShiftLookup {
        ShiftLookup(
            pixels
                .iter()
                .zip(shifts)
                .filter_map(|(&p, s)| Some((p, s?)))
                .collect(),
        )
    }

    /// The [`SHIFT_QUANTILES`] of `piece`'s reliable shifts, if it has any.
    pub fn range_of(&self, piece: &[(u32, u32)]) -> Option<[f32; 2]> {
        let own: Vec<Option<f32>> = piece.iter().map(|p| self.0.get(p).copied()).collect();
        shift_range(&own)
    }
}

/// The quantiles of a separated part's pixel shifts taken as its range of shifts: the
/// matching's outliers (windows straddling the occluding edge) lie beyond them.
const SHIFT_QUANTILES: [f64; 2] = [0.1, 0.9];

/// The [`SHIFT_QUANTILES`] of `shifts`' reliable values, if it has any.
fn shift_range(shifts: &[Option<f32>]) -> Option<[f32; 2]> {
    let mut reliable: Vec<f32> = shifts.iter().flatten().copied().collect();
    if reliable.is_empty() {
        return None;
    }
    reliable.sort_by(f32::total_cmp);
    let at = |q: f64| reliable[((reliable.len() - 1) as f64 * q).round() as usize];
    Some([at(SHIFT_QUANTILES[0]), at(SHIFT_QUANTILES[1])])
}

/// The layers of `pixels` (unwrapped columns); one layer if the blob is at one range.
/// `max_shift` bounds the search (the shift of the nearest range the blob's lowest row allows).
/// Layers are separated again, for rocks one behind another behind another.
pub(super) fn layers(
    pixels: Component,
    partner: &Partner,
    max_shift: usize,
    rule: ParallaxRule,
) -> Vec<Layer> {
    let [c0, r0, c1, r1] = bounds(&pixels).unwrap_or([0; 4]);
    let (cols, rows) = ((c1 - c0) as usize + 1, (r1 - r0) as usize + 1);
    let work = (cols + 2 * rule.radius) * (rows + 2 * rule.radius) * (max_shift + 1);
    if pixels.len() < rule.min_pixels
        || max_shift < 2
        || pixels.len() * (max_shift + 1) > MAX_COSTS
        || work > MAX_WORK
    {
        return vec![Layer {
            pixels,
            part: Separation::Whole,
            shifts: None,
            pixel_shifts: Vec::new(),
        }];
    }
    let scale = if work > COARSE_WORK { 2 } else { 1 };
    layers_at(pixels, partner, max_shift, rule, scale)
}

/// [`layers`], matching at `scale` (1, or 2 for half resolution).
fn layers_at(
    pixels: Component,
    partner: &Partner,
    max_shift: usize,
    rule: ParallaxRule,
    scale: u32,
) -> Vec<Layer> {
    let shifts = pixel_shifts(&pixels, partner, max_shift, rule.radius, scale);
    // Pixels a window apart across an occluding edge: the window is `scale` times wider at
    // half resolution.
    let window = (2 * rule.radius + 1) * scale as usize;
    let mut out = Vec::new();
    let mut pending = vec![(pixels, shifts, Separation::Whole, 0)];
    while let Some((pixels, shifts, part, depth)) = pending.pop() {
        let labels = if depth < 2 {
            separate(&pixels, &shifts, partner, rule, window)
        } else {
            None
        };
        let Some(labels) = labels else {
            if depth == 0 {
                out.push(Layer {
                    pixels,
                    part,
                    shifts: None,
                    pixel_shifts: shifts,
                });
            } else {
                let range = shift_range(&shifts);
                // A separated layer may come apart; its slivers (window-sized runs along the
                // other layer's edge) are dropped rather than reported as rocks.
                let parts = connected(&pixels);
                let largest = parts.iter().map(Vec::len).max().unwrap_or(0);
                let keep =
                    ((rule.sliver_fraction * largest as f32) as usize).max(rule.min_fragment);
                out.extend(
                    parts
                        .into_iter()
                        .filter(|p| p.len() >= keep)
                        .map(|pixels| Layer {
                            pixels,
                            part,
                            shifts: range,
                            pixel_shifts: Vec::new(),
                        }),
                );
            }
            continue;
        };
        let (mut near, mut far) = ((Vec::new(), Vec::new()), (Vec::new(), Vec::new()));
        for ((p, s), nearer) in pixels.into_iter().zip(shifts).zip(labels) {
            let side = if nearer { &mut near } else { &mut far };
            side.0.push(p);
            side.1.push(s);
        }
        let nearer = if part == Separation::Farther {
            Separation::Farther
        } else {
            Separation::Nearer
        };
        pending.push((near.0, near.1, nearer, depth + 1));
        pending.push((far.0, far.1, Separation::Farther, depth + 1));
    }
    out
}

/// Which pixels are nearer (`true`), if the blob's shifts show two ranges: the threshold
/// between all shifts' two groups is tried first, then those within either group (three rocks
/// one behind another form three groups).
fn separate(
    pixels: &Component,
    shifts: &[Option<f32>],
    partner: &Partner,
    rule: ParallaxRule,
    window: usize,
) -> Option<Vec<bool>> {
    if pixels.len() < rule.min_pixels {
        return None;
    }
    let mut reliable: Vec<f32> = shifts.iter().flatten().copied().collect();
    if reliable.len() < rule.min_pixels / 2 {
        return None;
    }
    reliable.sort_by(f32::total_cmp);
    let (threshold, k) = two_groups(&reliable)?;
    let mut candidates = vec![threshold];
    candidates.extend(two_groups(&reliable[..k]).map(|t| t.0));
    candidates.extend(two_groups(&reliable[k..]).map(|t| t.0));
    let blob = Matched {
        pixels,
        index: PixelIndex::new(pixels),
        shifts,
        window,
    };
    candidates
        .into_iter()
        .find_map(|t| separate_at(&blob, &reliable, t, partner, rule))
}

/// A blob's pixels with their shifts, and the matching window's width (pixels).
struct Matched<'a> {
    pixels: &'a Component,
    index: PixelIndex,
    shifts: &'a [Option<f32>],
    window: usize,
}

/// The labels of a separation of the blob at shift `threshold`, if it passes `rule`.
fn separate_at(
    blob: &Matched,
    reliable: &[f32],
    threshold: f32,
    partner: &Partner,
    rule: ParallaxRule,
) -> Option<Vec<bool>> {
    let Matched {
        pixels,
        ref index,
        shifts,
        window,
    } = *blob;
    let k = reliable.partition_point(|&s| s <= threshold);
    let share = k.min(reliable.len() - k) as f32 / reliable.len() as f32;
    if share < rule.min_share || share == 0.0 {
        return None;
    }
    let mean = |s: &[f32]| s.iter().sum::<f32>() / s.len() as f32;
    let (far, near) = (mean(&reliable[..k]), mean(&reliable[k..]));
    if near - far < rule.min_step_px.max(rule.min_step_fraction * near) {
        return None;
    }
    let mut labels = fill_labels(pixels, index, shifts, threshold);
    absorb_fragments(pixels, index, &mut labels, rule.min_fragment);
    let near_pixels: Component = pixels
        .iter()
        .zip(&labels)
        .filter(|(_, &nearer)| nearer)
        .map(|(&p, _)| p)
        .collect();
    if near_pixels.is_empty() || near_pixels.len() == pixels.len() {
        return None;
    }
    let widest = connected(&near_pixels)
        .iter()
        .map(|c| column_span(c))
        .fold(0.0, f64::max);
    let near_range = partner.range(near);
    let half_width = 0.5 * widest * partner.column_width * near_range;
    // The jump across the border, not the groups' means, says how far apart the two surfaces
    // are: the means also hold each surface's own slope.
    let step = border_step(pixels, index, shifts, &labels, window)?;
    let behind = partner.range(near - step) - near_range;
    (step >= rule.step_ratio * (near - far)
        && step >= rule.min_step_px.max(rule.min_step_fraction * near)
        && behind >= rule.min_depth_halfwidths * half_width)
        .then_some(labels)
}

fn column_span(pixels: &[(u32, u32)]) -> f64 {
    bounds(pixels).map_or(0.0, |[c0, _, c1, _]| f64::from(c1 - c0 + 1))
}

/// Block matching: each pixel's shift into the other panorama (sub-pixel, columns), or `None`
/// where the match is not unique. At `scale` 2 the panoramas are matched at half resolution
/// (`COARSE_WORK`): each pixel takes the shift of its 2 × 2 cell, doubled.
fn pixel_shifts(
    pixels: &Component,
    partner: &Partner,
    max_shift: usize,
    radius: usize,
    scale: u32,
) -> Vec<Option<f32>> {
    let (cells, cell_of) = cells(pixels, scale);
    let step = scale as usize;
    let shifts = cell_shifts(&cells, partner, max_shift / step, radius, step);
    cell_of
        .into_iter()
        .map(|c| shifts[c].map(|s| s * scale as f32))
        .collect()
}

/// The distinct `scale` × `scale` cells that `pixels` fall in, and each pixel's cell.
fn cells(pixels: &Component, scale: u32) -> (Component, Vec<usize>) {
    let coarse: Component = pixels
        .iter()
        .map(|&(c, r)| (c / scale, r / scale))
        .collect();
    let [c0, r0, c1, r1] = bounds(&coarse).unwrap_or([0; 4]);
    let cols = (c1 - c0) as usize + 1;
    let mut slots = vec![usize::MAX; cols * ((r1 - r0) as usize + 1)];
    let mut cells = Component::new();
    let cell_of = coarse
        .into_iter()
        .map(|(c, r)| {
            let slot = &mut slots[(r - r0) as usize * cols + (c - c0) as usize];
            if *slot == usize::MAX {
                *slot = cells.len();
                cells.push((c, r));
            }
            *slot
        })
        .collect();
    (cells, cell_of)
}

/// Each cell's shift in cells (sub-pixel), or `None` where the match is not unique: a cell is
/// `scale` × `scale` pixels, matched by the sum of their luminance. Costs are mean absolute
/// luminance differences over a square window of cells, from an integral image of the region
/// per shift.
fn cell_shifts(
    pixels: &Component,
    partner: &Partner,
    max_shift: usize,
    radius: usize,
    scale: usize,
) -> Vec<Option<f32>> {
    let rows = partner.rows.div_ceil(scale);
    let [col_min, row_min, col_max, row_max] = bounds(pixels).unwrap_or([0; 4]).map(|v| v as usize);
    // Region: the bounding box grown by the window; columns unwrapped from `x0`.
    let x0 = col_min as isize - radius as isize;
    let rw = col_max - col_min + 1 + 2 * radius;
    let y0 = row_min.saturating_sub(radius);
    let rh = (row_max + radius).min(rows - 1) - y0 + 1;
    let shifts = max_shift + 1;
    // The other panorama's rows cover the region at every shift: shift `s` starts at
    // `s` (direction +1) or `max_shift − s` (direction −1).
    let ow = rw + max_shift;
    let ox0 = if partner.direction > 0 {
        x0
    } else {
        x0 - max_shift as isize
    };
    let w = partner.width as isize;
    let read = |img: &[u16], y: usize, x: isize| {
        let mut sum = 0;
        for row in (y * scale..(y + 1) * scale).map(|r| r.min(partner.rows - 1)) {
            for col in x * scale as isize..(x + 1) * scale as isize {
                sum += i32::from(img[row * partner.width + col.rem_euclid(w) as usize]);
            }
        }
        sum
    };
    let own: Vec<i32> = (0..rh)
        .flat_map(|y| (0..rw).map(move |x| (y, x)))
        .map(|(y, x)| read(partner.own, y0 + y, x0 + x as isize))
        .collect();
    let other: Vec<i32> = (0..rh)
        .flat_map(|y| (0..ow).map(move |x| (y, x)))
        .map(|(y, x)| read(partner.other, y0 + y, ox0 + x as isize))
        .collect();
    let windows: Vec<(usize, usize, usize, usize, f32)> = pixels
        .iter()
        .map(|&(col, row)| {
            let cx = col as usize - col_min + radius;
            let cy = row as usize - y0;
            let (ya, yb) = (cy.saturating_sub(radius), (cy + radius + 1).min(rh));
            let (xa, xb) = (cx - radius, cx + radius + 1);
            (
                xa,
                xb,
                ya,
                yb,
                1.0 / ((xb - xa) * (yb - ya) * scale * scale) as f32,
            )
        })
        .collect();
    // Filled shift by shift, pixel after pixel (written in a pixel's row of shifts, the costs
    // went to memory one cache line per write), then turned to a row per pixel.
    let n = pixels.len();
    let mut by_shift = vec![0f32; n * shifts];
    let stride = rw + 1;
    // Integral images wrap around u32: a window's sum (at most 765 per pixel) fits, so the
    // wrapped differences of four corners give it exactly, at half the memory traffic of i64.
    // Shifts in parallel, each thread with an integral image of its own: a large rock near
    // the rover is most of a panorama's matching.
    by_shift.par_chunks_mut(n).enumerate().for_each_init(
        || vec![0u32; (rh + 1) * stride],
        |integral, (s, costs)| {
            let start = if partner.direction > 0 {
                s
            } else {
                max_shift - s
            };
            for y in 0..rh {
                let a = &own[y * rw..(y + 1) * rw];
                let b = &other[y * ow + start..y * ow + start + rw];
                let (above, below) = integral.split_at_mut((y + 1) * stride);
                let above = &above[y * stride + 1..];
                let mut run = 0u32;
                for (((p, q), up), out) in a.iter().zip(b).zip(above).zip(&mut below[1..stride]) {
                    run = run.wrapping_add(p.abs_diff(*q));
                    *out = up.wrapping_add(run);
                }
            }
            for (&(xa, xb, ya, yb, scale), cost) in windows.iter().zip(costs) {
                let sum = integral[yb * stride + xb]
                    .wrapping_sub(integral[ya * stride + xb])
                    .wrapping_sub(integral[yb * stride + xa])
                    .wrapping_add(integral[ya * stride + xa]);
                *cost = sum as f32 * scale;
            }
        },
    );
    // Each block of pixels gathers its costs into a row per pixel, in cache, and finds their
    // minima; blocks in parallel (the gather and the minima had taken as long as the matching
    // for a rock before the rover, on one core).
    const BLOCK: usize = 64;
    let starts: Vec<usize> = (0..n).step_by(BLOCK).collect();
    starts
        .par_iter()
        .flat_map_iter(|&k0| {
            let block = BLOCK.min(n - k0);
            let mut costs = vec![0f32; block * shifts];
            for (s, row) in by_shift.chunks_exact(n).enumerate() {
                for (k, &cost) in row[k0..k0 + block].iter().enumerate() {
                    costs[k * shifts + s] = cost;
                }
            }
            costs
                .chunks_exact(shifts)
                .map(unique_minimum)
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The sub-pixel position of the minimum of `cost`, if it is clearly below every cost two or
/// more shifts away (a textureless or repetitive window matches many shifts alike).
fn unique_minimum(cost: &[f32]) -> Option<f32> {
    let (best, &low) = cost.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1))?;
    // At the end of the search the surface may lie beyond it.
    if best + 1 == cost.len() {
        return None;
    }
    let outside = |range: &[f32]| range.iter().copied().fold(f32::INFINITY, f32::min);
    let rival =
        outside(&cost[..best.saturating_sub(1)]).min(outside(cost.get(best + 2..).unwrap_or(&[])));
    // Costs are mean absolute luminance differences (0–765); a few units is noise. With no
    // shift two or more away there is nothing to be unique against.
    if !rival.is_finite() || rival < 1.3 * low + 6.0 {
        return None;
    }
    let refined = match (best.checked_sub(1).map(|i| cost[i]), cost.get(best + 1)) {
        (Some(a), Some(&c)) if a - 2.0 * low + c > 0.0 => 0.5 * (a - c) / (a - 2.0 * low + c),
        _ => 0.0,
    };
    Some(best as f32 + refined)
}

/// The threshold splitting sorted `values` into two groups of least within-group variance
/// (Otsu), and the size of the lower group.
fn two_groups(sorted: &[f32]) -> Option<(f32, usize)> {
    let n = sorted.len();
    let total: f64 = sorted.iter().map(|&v| f64::from(v)).sum();
    let mut below = 0.0;
    let mut best: Option<(f64, usize)> = None;
    for k in 1..n {
        below += f64::from(sorted[k - 1]);
        let (m1, m2) = (below / k as f64, (total - below) / (n - k) as f64);
        let between = k as f64 * (n - k) as f64 * (m2 - m1).powi(2);
        if best.is_none_or(|(b, _)| between > b) {
            best = Some((between, k));
        }
    }
    let (_, k) = best?;
    Some((0.5 * (sorted[k - 1] + sorted[k]), k))
}

/// The eight neighbours of a pixel that belong to the blob (blobs are 8-connected).
fn neighbours<'a>(
    (col, row): (u32, u32),
    index: &'a PixelIndex,
) -> impl Iterator<Item = usize> + 'a {
    [
        (1i64, 0i64),
        (-1, 0),
        (0, 1),
        (0, -1),
        (1, 1),
        (1, -1),
        (-1, 1),
        (-1, -1),
    ]
    .into_iter()
    .filter_map(move |(dc, dr)| index.get(i64::from(col) + dc, i64::from(row) + dr))
}

/// Nearer (`true`) or farther for every pixel: reliable pixels by their shift, the others
/// taking the label of the nearest reliable pixel through the blob (breadth first).
fn fill_labels(
    pixels: &Component,
    index: &PixelIndex,
    shifts: &[Option<f32>],
    threshold: f32,
) -> Vec<bool> {
    let mut label: Vec<Option<bool>> = shifts.iter().map(|s| s.map(|s| s > threshold)).collect();
    let mut queue: VecDeque<usize> = (0..pixels.len()).filter(|&k| label[k].is_some()).collect();
    while let Some(k) = queue.pop_front() {
        for j in neighbours(pixels[k], index) {
            if label[j].is_none() {
                label[j] = label[k];
                queue.push_back(j);
            }
        }
    }
    label.into_iter().map(|l| l.unwrap_or(true)).collect()
}

/// Flips the label of every 8-connected run of one label smaller than `min_fragment` pixels:
/// stray windows along an edge, not a rock.
fn absorb_fragments(
    pixels: &Component,
    index: &PixelIndex,
    labels: &mut [bool],
    min_fragment: usize,
) {
    let mut seen = vec![false; pixels.len()];
    for start in 0..pixels.len() {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let mut fragment = vec![start];
        let mut next = 0;
        while next < fragment.len() {
            let k = fragment[next];
            next += 1;
            for j in neighbours(pixels[k], index) {
                if !seen[j] && labels[j] == labels[start] {
                    seen[j] = true;
                    fragment.push(j);
                }
            }
        }
        if fragment.len() < min_fragment {
            for k in fragment {
                labels[k] = !labels[k];
            }
        }
    }
}

/// The median shift difference of reliable pixels a `window` apart across the border between
/// the two groups, if enough such pairs exist: a step at an occluding edge, where one rock's
/// sloping face differs little over so short a distance.
fn border_step(
    pixels: &Component,
    index: &PixelIndex,
    shifts: &[Option<f32>],
    labels: &[bool],
    window: usize,
) -> Option<f32> {
    let gap = window as i64;
    let mut across = Vec::new();
    for (k, &(col, row)) in pixels.iter().enumerate() {
        let Some(s) = shifts[k] else { continue };
        let (col, row) = (i64::from(col), i64::from(row));
        for (c, r) in [(col + gap, row), (col, row + gap)] {
            if let Some(j) = index.get(c, r) {
                if let (Some(t), true) = (shifts[j], labels[j] != labels[k]) {
                    // Nearer side minus farther side.
                    across.push(if labels[k] { s - t } else { t - s });
                }
            }
        }
    }
    if across.len() < 5 {
        return None;
    }
    let mid = across.len() / 2;
    Some(*across.select_nth_unstable_by(mid, f32::total_cmp).1)
}

#[cfg(test)]
mod tests {
    use super::*;

    const WIDTH: usize = 300;
    const ROWS: usize = 90;
    /// The full-resolution panorama's column width and the default 0.3 m baseline.
    const COLUMN_WIDTH: f64 = std::f64::consts::TAU / 4096.0;
    const BASELINE: f64 = 0.3;

    /// Smooth random texture of one surface: bilinear value noise on 3-pixel cells.
    fn texture(surface: u32, x: f64, y: f64) -> f64 {
        let hash = |i: i64, j: i64| {
            let mut h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
                ^ u64::from(surface).wrapping_mul(0x1656_67B1_9E37_79F9);
            h ^= h >> 29;
            h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h ^= h >> 32;
            (h % 1000) as f64 / 1000.0
        };
        let (u, v) = (x / 3.0, y / 3.0);
        let (i, j) = (u.floor() as i64, v.floor() as i64);
        let (fu, fv) = (u - i as f64, v - j as f64);
        let top = hash(i, j) * (1.0 - fu) + hash(i + 1, j) * fu;
        let bottom = hash(i, j + 1) * (1.0 - fu) + hash(i + 1, j + 1) * fu;
        150.0 + 300.0 * (top * (1.0 - fv) + bottom * fv)
    }

    /// A surface of the scene: which own-image pixels it covers and its shift at each column.
    struct Surface {
        id: u32,
        covers: Box<dyn Fn(f64, f64) -> bool>,
        shift: Box<dyn Fn(f64) -> f64>,
    }

    /// Both panoramas of `surfaces` (back to front) over ground shifted by 4 columns, the
    /// other camera seeing each point `shift` columns towards `direction`, turned by `turn`
    /// columns (so that a scene may straddle the seam); and the own pixels of every surface but
    /// the ground, columns unwrapped past the seam as the detector's blobs are.
    fn scene(surfaces: &[Surface], direction: f64, turn: usize) -> (Vec<u16>, Vec<u16>, Component) {
        let (mut own, mut other) = (vec![0u16; WIDTH * ROWS], vec![0u16; WIDTH * ROWS]);
        let mut pixels = Component::new();
        for y in 0..ROWS {
            for x in 0..WIDTH {
                let (fx, fy) = (x as f64, y as f64);
                let at = y * WIDTH + (x + turn) % WIDTH;
                let front = surfaces.iter().rev().find(|s| (s.covers)(fx, fy));
                own[at] = match front {
                    Some(s) => {
                        pixels.push(((x + turn) as u32, y as u32));
                        texture(s.id, fx, fy) as u16
                    }
                    None => texture(0, fx, fy) as u16,
                };
                // The point seen at column x by the other camera: solve x = u ± shift(u).
                let seen = surfaces.iter().rev().find_map(|s| {
                    let mut u = fx - direction * (s.shift)(fx);
                    for _ in 0..20 {
                        u = fx - direction * (s.shift)(u);
                    }
                    (s.covers)(u.round(), fy).then(|| texture(s.id, u, fy))
                });
                other[at] = seen.unwrap_or_else(|| texture(0, fx - direction * 4.0, fy)) as u16;
            }
        }
        (own, other, pixels)
    }

    fn partner<'a>(own: &'a [u16], other: &'a [u16], direction: isize) -> Partner<'a> {
        Partner {
            own,
            other,
            width: WIDTH,
            rows: ROWS,
            direction,
            column_width: COLUMN_WIDTH,
            baseline_m: BASELINE,
        }
    }

    fn rule() -> ParallaxRule {
        crate::detection::DetectorSettings::default().parallax
    }

    /// The default rule without its depth test, to show which rule keeps a blob whole.
    fn without_depth_rule() -> ParallaxRule {
        ParallaxRule {
            min_depth_halfwidths: 0.0,
            ..rule()
        }
    }

    /// A surface seen shifted by the same `shift` everywhere (a rock face at one range).
    fn at_shift(id: u32, covers: Box<dyn Fn(f64, f64) -> bool>, shift: f64) -> Surface {
        Surface {
            id,
            covers,
            shift: Box::new(move |_| shift),
        }
    }

    fn ellipse(cx: f64, cy: f64, a: f64, b: f64) -> Box<dyn Fn(f64, f64) -> bool> {
        Box::new(move |x, y| ((x - cx) / a).powi(2) + ((y - cy) / b).powi(2) <= 1.0)
    }

    /// A rock at 19.6 m (shift 10) seen above and behind one at 12.2 m (shift 16): two layers,
    /// the farther one flagged, each holding (nearly) only its own rock's pixels; whichever way
    /// the other camera sees points shifted, and across the panorama's seam.
    #[test]
    fn a_farther_rock_over_a_nearer_one_is_separated() {
        let near_covers = ellipse(140.0, 62.0, 45.0, 22.0);
        for (direction, turn) in [(1, 0), (-1, 0), (-1, 200)] {
            let far = at_shift(1, ellipse(150.0, 35.0, 40.0, 25.0), 10.0);
            let near = at_shift(2, ellipse(140.0, 62.0, 45.0, 22.0), 16.0);
            let (own, other, pixels) = scene(&[far, near], direction as f64, turn);
            let layers = layers(pixels, &partner(&own, &other, direction), 25, rule());
            assert_eq!(layers.len(), 2, "{direction} {turn}");
            for layer in &layers {
                let wrong = layer
                    .pixels
                    .iter()
                    .filter(|&&(x, y)| {
                        let x = f64::from(x) - turn as f64;
                        near_covers(x, f64::from(y)) == (layer.part == Separation::Farther)
                    })
                    .count();
                assert!(
                    wrong * 20 < layer.pixels.len(),
                    "{wrong} of {} pixels in the wrong layer ({:?}; {direction} {turn})",
                    layer.pixels.len(),
                    layer.part
                );
            }
            let parts: Vec<Separation> = layers.iter().map(|l| l.part).collect();
            assert!(parts.contains(&Separation::Nearer) && parts.contains(&Separation::Farther));
            // Each layer's shifts are its own rock's, within a column of matching error.
            for layer in &layers {
                let [low, high] = layer.shifts.expect("a separated layer has shifts");
                let own = if layer.part == Separation::Farther {
                    10.0
                } else {
                    16.0
                };
                assert!(
                    (own - 1.0..=own + 1.0).contains(&low) && (low..=own + 1.0).contains(&high),
                    "{:?}: shifts {low}–{high}, its rock's {own}",
                    layer.part
                );
            }
        }
    }

    /// One rock whose round face curves back from 17 columns of shift in its middle (11.5 m)
    /// to 15 at its sides, steeply near them as a sphere's does: no step, so one layer.
    #[test]
    fn one_rocks_curved_face_stays_whole() {
        let rock = Surface {
            id: 1,
            covers: ellipse(150.0, 45.0, 50.0, 30.0),
            shift: Box::new(|x| 15.0 + 2.0 * (1.0 - ((x - 150.0) / 50.0).powi(2)).max(0.0).sqrt()),
        };
        let (own, other, pixels) = scene(&[rock], 1.0, 0);
        let n = pixels.len();
        let whole = layers(pixels.clone(), &partner(&own, &other, 1), 25, rule());
        assert_eq!(whole.len(), 1);
        assert_eq!(
            whole[0].shifts, None,
            "a whole blob has a stereo partner instead"
        );
        assert_eq!(whole[0].pixels.len(), n);
        assert_eq!(whole[0].part, Separation::Whole);
        // The step rule alone keeps it whole.
        assert_eq!(
            layers(pixels, &partner(&own, &other, 1), 25, without_depth_rule()).len(),
            1
        );
    }

    /// Two rocks at the same range, side by side: nothing for parallax to separate (the notch
    /// rule cuts them).
    #[test]
    fn rocks_at_one_range_stay_together() {
        let left = at_shift(1, ellipse(110.0, 50.0, 35.0, 25.0), 15.0);
        let right = at_shift(2, ellipse(170.0, 52.0, 35.0, 25.0), 15.0);
        let (own, other, pixels) = scene(&[left, right], 1.0, 0);
        assert_eq!(
            layers(pixels, &partner(&own, &other, 1), 25, rule()).len(),
            1
        );
    }

    /// Two touching rocks at 15.9 m (shift 12) and 10.6 m (shift 18) in a blob left whole: each
    /// piece the blob is cut into takes the shifts of its own pixels, not the blob's, which
    /// span both ranges.
    #[test]
    fn the_pieces_of_a_whole_blob_take_their_own_shifts() {
        let left = at_shift(1, ellipse(110.0, 50.0, 36.0, 25.0), 12.0);
        let right = at_shift(2, ellipse(170.0, 52.0, 36.0, 25.0), 18.0);
        let (own, other, pixels) = scene(&[left, right], 1.0, 0);
        let whole = ParallaxRule {
            min_depth_halfwidths: f64::INFINITY,
            ..rule()
        };
        let mut layers = layers(pixels, &partner(&own, &other, 1), 25, whole);
        assert_eq!(layers.len(), 1);
        let layer = layers.remove(0);
        assert!(layer.shifts.is_none());
        let (left, right): (Vec<_>, Vec<_>) = layer.pixels.iter().partition(|p| p.0 < 140);
        let lookup = ShiftLookup::new(&layer.pixels, layer.pixel_shifts);
        let within = |range: Option<[f32; 2]>, shift: f32| {
            range.is_some_and(|[low, high]| {
                (low - shift).abs() <= 1.0 && (high - shift).abs() <= 1.0
            })
        };
        assert!(
            within(lookup.range_of(&left), 12.0),
            "{:?}",
            lookup.range_of(&left)
        );
        assert!(
            within(lookup.range_of(&right), 18.0),
            "{:?}",
            lookup.range_of(&right)
        );
        assert_eq!(lookup.range_of(&[(0, 0)]), None, "a pixel outside the blob");
    }

    /// A lump on top of a wide rock, 0.75 m behind its face at 9.8 m: a step, but less than
    /// the rock's half-width (0.9 m) behind it, so one rock's shape, not two rocks.
    #[test]
    fn a_lump_closer_than_the_half_width_stays_whole() {
        let lump = at_shift(1, ellipse(150.0, 30.0, 30.0, 18.0), 18.6);
        let body = at_shift(2, ellipse(150.0, 60.0, 60.0, 22.0), 20.0);
        let (own, other, pixels) = scene(&[lump, body], 1.0, 0);
        let whole = layers(pixels.clone(), &partner(&own, &other, 1), 28, rule());
        assert_eq!(whole.len(), 1);
        assert_eq!(
            layers(pixels, &partner(&own, &other, 1), 28, without_depth_rule()).len(),
            2
        );
    }

    /// The same scene at nearly twice the shifts (a rock at 9.8 m over one at 6.1 m), matched
    /// at half resolution as a large rock near the rover is: two layers, each with its own
    /// rock's pixels and shifts, within two columns (one column at half resolution).
    #[test]
    fn a_farther_rock_over_a_nearer_one_is_separated_at_half_resolution() {
        let near_covers = ellipse(140.0, 62.0, 45.0, 22.0);
        for direction in [1, -1] {
            let far = at_shift(1, ellipse(150.0, 35.0, 40.0, 25.0), 20.0);
            let near = at_shift(2, ellipse(140.0, 62.0, 45.0, 22.0), 32.0);
            let (own, other, pixels) = scene(&[far, near], direction as f64, 0);
            let layers = layers_at(pixels, &partner(&own, &other, direction), 48, rule(), 2);
            assert_eq!(layers.len(), 2, "{direction}");
            for layer in &layers {
                let wrong = layer
                    .pixels
                    .iter()
                    .filter(|&&(x, y)| {
                        near_covers(f64::from(x), f64::from(y))
                            == (layer.part == Separation::Farther)
                    })
                    .count();
                assert!(
                    wrong * 10 < layer.pixels.len(),
                    "{wrong} of {} pixels in the wrong layer ({:?}; {direction})",
                    layer.pixels.len(),
                    layer.part
                );
                let [low, high] = layer.shifts.expect("a separated layer has shifts");
                let own = if layer.part == Separation::Farther {
                    20.0
                } else {
                    32.0
                };
                assert!(
                    (own - 2.0..=own + 2.0).contains(&low) && (low..=own + 2.0).contains(&high),
                    "{:?}: shifts {low}–{high}, its rock's {own}",
                    layer.part
                );
            }
        }
    }

    /// Each pixel of a rock face at one range takes its 2 × 2 cell's shift, doubled: the
    /// face's shift within a column of what matching at full resolution finds, for nine in
    /// ten of the pixels away from the face's edge.
    #[test]
    fn half_resolution_shifts_are_the_full_resolution_ones_within_a_column() {
        let rock = at_shift(1, ellipse(150.0, 45.0, 50.0, 30.0), 27.0);
        let (own, other, pixels) = scene(&[rock], 1.0, 0);
        let partner = partner(&own, &other, 1);
        let full = pixel_shifts(&pixels, &partner, 40, 2, 1);
        let half = pixel_shifts(&pixels, &partner, 40, 2, 2);
        let inside = |&&(x, y): &&(u32, u32)| {
            ((f64::from(x) - 150.0) / 44.0).powi(2) + ((f64::from(y) - 45.0) / 24.0).powi(2) <= 1.0
        };
        let (mut inner, mut compared) = (0, 0);
        for (p, (f, h)) in pixels.iter().zip(full.iter().zip(&half)) {
            if !inside(&p) {
                continue;
            }
            inner += 1;
            let (Some(f), Some(h)) = (f, h) else { continue };
            assert!((f - 27.0).abs() < 0.5, "{p:?}: full resolution {f}");
            assert!((h - f).abs() < 1.0, "{p:?}: half {h}, full {f}");
            compared += 1;
        }
        assert!(compared * 10 > inner * 9, "{compared} of {inner}");
    }

    #[test]
    fn unique_minimum_refines_and_rejects_flat_costs() {
        let cost = [50.0, 40.0, 10.0, 20.0, 45.0, 60.0];
        let s = unique_minimum(&cost).unwrap();
        assert!(s > 2.0 && s < 2.5, "{s}");
        assert_eq!(unique_minimum(&[30.0, 29.0, 28.0, 29.0, 30.0]), None);
        assert_eq!(
            unique_minimum(&[60.0, 40.0, 10.0]),
            None,
            "minimum at the search's end"
        );
        assert_eq!(
            unique_minimum(&[60.0, 10.0, 40.0]),
            None,
            "no rival two shifts away"
        );
    }
}
