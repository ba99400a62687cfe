//! Rock detection in one panorama: which blobs below the horizon are rocks, where they touch the
//! ground (for flat-ground range) and where their centre lies (for bearing), plus an appearance
//! signature for telling the same rock apart in panoramas taken a few metres apart.
//!
//! The ground's brightness and colour depend mainly on the row (haze grows with range), so the
//! background is modelled per row by medians, which rocks (a small fraction of any row) do not
//! move. Rock pixels differ from regolith in chroma (rocks are greyer than the red soil), or are
//! much brighter; cast shadows are darker but keep the regolith's red hue, so they are left out
//! and cannot drag the contact row or centroid. Small blobs are rejected by physical width at
//! the flat-ground range of their contact row, which removes pebbles at every resolution.
//! With a stereo partner, pixels standing up from the ground that join a blob bound how far
//! its rock may reach beyond what the colour test found (`extent`).

mod components;
mod extent;
mod faint;
mod ground;
pub mod noise;
mod parallax;
mod split;

use crate::calib::Calibration;
use components::{blob_of, bounds, label_wrapped, Blob};
use kornia_image::{Image, ImageSize};
pub use parallax::{ParallaxRule, Separation};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Thresholds of the detector. Ratios are relative to the row's median regolith.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DetectorSettings {
    /// Narrowest rock kept, metres of visible width at the contact range (pebbles are ≤ 8 cm).
    pub min_width_m: f64,
    /// Farthest rock kept, metres of flat-ground range at the contact row.
    pub max_range_m: f64,
    /// A blob whose luminance varies less than this (standard deviation over mean) and which is
    /// within `bright_ratio` of the regolith's brightness either way is a tint of the ground
    /// (a dust drift just greyer than the row's median), not a rock: rocks are faceted and
    /// shaded on one side, or differ in brightness.
    pub min_texture: f32,
    /// A blob whose top edge, read as flat ground, lies less than this many of its widths
    /// beyond its contact is a patch lying on the ground (pebbles, clumps of them), not a rock
    /// standing up from it: a flat patch as deep as it is wide reaches 1, any rock of that
    /// width rises higher in the image.
    pub min_rise: f64,
    /// A pixel whose `(r − b)/(r + g + b)` is this much below its row's median is rock: rocks
    /// are greyer than the red regolith, in sun and in shade alike.
    pub chroma_drop: f32,
    /// A pixel this many times brighter than its row's median is rock (shadows never are).
    pub bright_ratio: f32,
    /// A pixel darker than this fraction of its row's median is rock if it is also greyer by
    /// `dark_chroma_drop`: the shaded side of a rock, told from cast shadows (which stay red).
    pub dark_ratio: f32,
    pub dark_chroma_drop: f32,
    /// A blob is cut where its bottom edge lies this many rows (at least) under the concave
    /// hull of its bottom edge: one rock's bottom edge is concave, touching rocks notch it.
    /// Small blobs need a shallow cut: two touching pebbles notch each other by a couple of
    /// rows, and each half is then too narrow to keep.
    pub split_depth_px: f32,
    /// … or this fraction of the blob's height, if more (ragged edges grow with size).
    pub split_depth_fraction: f32,
    /// When a blob holding a nearer and a farther rock is separated by stereo parallax.
    pub parallax: ParallaxRule,
    /// Which channels tell rock from regolith.
    #[serde(default)]
    pub channels: Channels,
    /// In luminance mode, a pixel whose luminance differs from its row's median by this
    /// fraction either way is rock if it lies between pixels standing up from the flat ground
    /// (by stereo) in its row.
    #[serde(default = "default_luminance_contrast")]
    pub luminance_contrast: f32,
}

fn default_luminance_contrast() -> f32 {
    0.08
}

/// What tells rock pixels from regolith.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Channels {
    /// Luminance for grayscale panoramas (every pixel's channels equal) and for JPEG files of
    /// stereo pairs (their chroma is subsampled and quantised: the per-pixel chroma test fires
    /// on the artefacts), colour otherwise.
    #[default]
    Auto,
    /// Chroma and luminance: rocks are greyer than the red regolith; cast shadows stay red.
    Colour,
    /// Luminance and stereo: a pixel is rock if it differs from the row's regolith in
    /// luminance and does not lie on the flat ground (`ground`); cast shadows and soil
    /// patches do. Without a right panorama, shadows cannot be told from rocks: every
    /// detection is then flagged ambiguous.
    Luminance,
}

/// Share of a panorama's rows, from the bottom, over which its chroma noise is measured: the
/// ground, below the horizon of any preset's camera.
const NOISE_ROWS: f64 = 0.4;

/// Largest chroma noise (one pixel's s.d.) of a panorama detected by colour, as a share of
/// `DetectorSettings::chroma_drop`: the threshold then lies three s.d. from the soil's chroma.
/// Colour renders measure about 0.0008 (2 % of the 0.035 drop; marsyard seeds 3, 7, 11, 13, 17),
/// a JPEG pair with sensor noise 0.005 (stress seed 9), and stress seed 21 (sensor noise 4.3
/// levels, gamma 0.61, dark soil) 0.041–0.049, where colour detection found 628 rocks among
/// 7 779 detections and luminance 1 155 among 1 309.
const NOISE_SHARE: f32 = 1.0 / 3.0;

impl Channels {
    /// The mode `image` is detected in: `Auto` resolved by whether it holds any colour.
    pub fn resolve(self, image: &image::RgbImage) -> Channels {
        match self {
            Channels::Auto if image.pixels().all(|p| p[0] == p[1] && p[1] == p[2]) => {
                Channels::Luminance
            }
            Channels::Auto => Channels::Colour,
            other => other,
        }
    }
}

impl DetectorSettings {
    /// The mode a panorama is detected in: [`Channels::resolve`], and where a stereo partner
    /// lets luminance tell rocks from cast shadows (`stereo`), `Auto` is resolved to luminance
    /// also for a JPEG pair (`jpeg`: its chroma is subsampled and quantised, and the per-pixel
    /// chroma test fires on the artefacts) and for a panorama whose chroma noise
    /// ([`noise::chroma_noise`], over the lower [`NOISE_ROWS`] of its rows) exceeds
    /// [`NOISE_SHARE`] of `chroma_drop`: the chroma test then fires on the soil's own pixels,
    /// which join into blobs spanning the ground. `primary` is the pair's left panorama.
    pub fn channels_of(&self, primary: &image::RgbImage, stereo: bool, jpeg: bool) -> Channels {
        match self.channels.resolve(primary) {
            Channels::Colour
                if stereo
                    && self.channels == Channels::Auto
                    && (jpeg
                        || noise::chroma_noise(primary, NOISE_ROWS)
                            > NOISE_SHARE * self.chroma_drop) =>
            {
                Channels::Luminance
            }
            resolved => resolved,
        }
    }
}

impl Default for DetectorSettings {
    fn default() -> Self {
        DetectorSettings {
            min_width_m: 0.12,
            max_range_m: 30.0,
            min_rise: 0.9,
            min_texture: 0.04,
            chroma_drop: 0.035,
            bright_ratio: 1.25,
            dark_ratio: 0.6,
            dark_chroma_drop: 0.02,
            split_depth_px: 2.0,
            split_depth_fraction: 0.15,
            channels: Channels::Auto,
            luminance_contrast: default_luminance_contrast(),
            parallax: ParallaxRule {
                radius: 2,
                min_pixels: 60,
                min_step_px: 1.0,
                min_step_fraction: 0.05,
                step_ratio: 0.4,
                min_depth_halfwidths: 1.0,
                min_share: 0.05,
                min_fragment: 30,
                sliver_fraction: 0.1,
            },
        }
    }
}

/// One rock-like blob in one panorama.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Detection {
    /// Mean continuous (column, row) of the rock pixels, pixel centres at `+0.5`; the column in
    /// `[0, width)`.
    pub centroid: [f64; 2],
    /// `[col_min, row_min, col_max, row_max]`, inclusive; `col_max ≥ width` when the blob
    /// straddles the seam.
    pub bbox: [u32; 4],
    /// Rock pixels (shadow excluded).
    pub pixels: u32,
    /// Continuous row of the bottom edge of the rock itself (its ground contact).
    pub contact_row: f64,
    /// Rows below `contact_row` the true contact may lie: in luminance mode a rock's lowest
    /// rows cannot be told from the ground by stereo.
    #[serde(default)]
    pub contact_slack_rows: f64,
    pub appearance: Appearance,
    /// May be several rocks (its bottom edge is notched, but too shallowly to cut), or only the
    /// visible part of a rock cut from a nearer one in front of it: do not use its bearing.
    pub ambiguous: bool,
    /// Whether parallax separated this blob from another part, and which part it is.
    #[serde(default)]
    pub separation: Separation,
    /// The connected blob of the mask this detection was cut from: pieces of one blob share it.
    #[serde(default)]
    pub blob: u32,
    /// Columns before and after `bbox` over which the rock may reach: pixels standing up from
    /// the ground (by stereo) that join the blob where this piece ends it. The colour test
    /// can find only part of a rock nearly the soil's colour (`extent`); 0 for a piece whose
    /// blob ends where the raised pixels do.
    #[serde(default)]
    pub beyond_columns: [u32; 2],
    /// For a part separated by parallax, the range of its pixels' left–right shifts
    /// (columns, the 10th–90th percentile): its own stereo evidence, which the other
    /// panorama's blob, holding both parts, cannot give.
    #[serde(default)]
    pub parallax_shifts: Option<[f64; 2]>,
    /// By colour, with stereo: none of its pixels stands up from the ground by the stereo test
    /// (`ground::GroundTest`: raised, or a smooth face nearer than the ground). A soil patch
    /// or a cast shadow, or a rock too smooth to tell. False where untested: without stereo,
    /// and by luminance, where every detection stands by construction.
    #[serde(default)]
    pub flat: bool,
    /// Flat, with half or more of its pixels matching the other panorama at the ground's shift
    /// where the test tells a standing rock from the ground ([`ground::tells_height`]: its top
    /// lies far enough above its contact that, standing, it would not match there): a soil
    /// patch or a cast shadow. A flat detection lower in the image, or one too smooth to
    /// match, may be a far or low-contrast rock the test cannot tell. Such a detection founds
    /// no landmark (`association::unfounded`).
    #[serde(default)]
    pub surely_flat: bool,
}

/// Statistics that change little with viewpoint, for associating a rock across panoramas.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Appearance {
    /// Mean chromaticity (r, g, b summing to 1).
    pub colour: [f32; 3],
    /// Rock luminance over the regolith's median luminance at the same rows.
    pub brightness: f32,
    /// Luminance standard deviation over mean, inside the rock.
    pub texture: f32,
    /// Fraction of the rock's pixels darker than `dark_ratio` of the regolith: its shaded side.
    pub dark_fraction: f32,
}

/// The panoramas of a stereo pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eye {
    Left,
    Right,
}

/// Detects rocks in `image`, sorted by centroid column. Given the right panorama of its
/// stereo pair (`image` being the left), blobs of a nearer and a farther rock are also
/// separated by parallax, and in luminance mode rocks are told from the ground by stereo. An
/// image whose size differs from the calibration's yields no detections (its geometry would be
/// meaningless); a right panorama of another size is ignored.
pub fn detect(
    image: &image::RgbImage,
    right: Option<&image::RgbImage>,
    calib: &Calibration,
    settings: &DetectorSettings,
) -> Vec<Detection> {
    detect_in(image, right.map(|r| (r, Eye::Right)), calib, settings)
}

/// Detects rocks in the right panorama of a stereo pair, given its left partner: as
/// [`detect`], but without parallax separation (its detections serve the stereo cue only).
pub fn detect_right(
    image: &image::RgbImage,
    left: Option<&image::RgbImage>,
    calib: &Calibration,
    settings: &DetectorSettings,
) -> Vec<Detection> {
    detect_in(image, left.map(|l| (l, Eye::Left)), calib, settings)
}

/// Detects rocks in `image` given the other panorama of its pair and which one that is.
fn detect_in(
    image: &image::RgbImage,
    other: Option<(&image::RgbImage, Eye)>,
    calib: &Calibration,
    settings: &DetectorSettings,
) -> Vec<Detection> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    if image.width() != calib.image.width || image.height() != calib.image.height || w == 0 {
        return Vec::new();
    }
    let top = (calib.elevation.horizon_row.floor().max(0.0) as usize).min(h);
    let rows = h - top;
    if rows == 0 {
        return Vec::new();
    }
    let raw = &image.as_raw()[top * w * 3..];
    let background = row_medians(raw, w);
    let luminance = settings.channels.resolve(image) == Channels::Luminance;
    // The other panorama serves parallax separation and the rocks' extents (a left image's
    // right partner) and, in luminance mode, the ground test.
    let bands = other
        .filter(|(o, eye)| {
            o.dimensions() == image.dimensions()
                && calib.stereo.baseline_m > 0.0
                && (luminance || *eye == Eye::Right)
        })
        .map(|(o, _)| (ground_luminance(image, top), ground_luminance(o, top)));
    // The right camera sees a point turned towards increasing azimuth, the left one away.
    let towards = if calib.column_sign() > 0.0 { 1 } else { -1 };
    let direction = match other {
        Some((_, Eye::Left)) => -towards,
        _ => towards,
    };
    let ground_bands = bands.as_ref().map(|(own, other)| ground::Bands {
        own,
        other,
        width: w,
        top,
        calib,
        direction,
    });
    let stances = ground_bands
        .filter(|_| luminance)
        .map(|bands| ground::stances(&bands));
    let pixels_rule = match (luminance, &stances) {
        (false, _) => PixelRule::Colour,
        (true, Some(stances)) => PixelRule::OffGround(stances),
        (true, None) => PixelRule::Luminance,
    };
    let Some(mask) = rock_mask(raw, &background, w, rows, settings, &pixels_rule) else {
        return Vec::new();
    };
    // Without stereo, a luminance-only mask holds cast shadows with the rocks: neither the
    // centroid nor the contact can be trusted.
    let doubted = matches!(pixels_rule, PixelRule::Luminance);
    // With stereo, the contact is the lowest row standing up from the ground, and the rows
    // under it that the test cannot tell from the ground are doubt.
    let raised_bottom = |piece: &components::Component| -> Option<f64> {
        let stances = stances.as_ref()?;
        piece
            .iter()
            .filter(|&&(col, row)| {
                stances[row as usize * w + col as usize % w] == ground::Stance::Raised
            })
            .map(|&(_, row)| (row as usize + top + 1) as f64)
            .max_by(f64::total_cmp)
    };
    let sample = |col: usize, row: usize| {
        let i = row * w + col;
        let p = &raw[3 * i..3 * i + 3];
        let sum = f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2]);
        let ratio = sum / background[row].0.max(1.0);
        PixelSample {
            rgb: [f32::from(p[0]), f32::from(p[1]), f32::from(p[2])],
            ratio,
            dark: ratio < settings.dark_ratio,
        }
    };
    // Notch splitting and ambiguity are measured against the contact's doubt.
    let slack = if stances.is_some() {
        ground::contact_doubt(calib)
    } else {
        0.0
    };
    // A bottom edge found by stereo is ragged by the rows the test cannot tell from the
    // ground: only notches deeper than that mark two rocks (half the cutting depth).
    let rule = split::SplitRule {
        min_depth: settings.split_depth_px.max(2.0 * slack as f32),
        fraction: settings.split_depth_fraction,
        min_columns: 3,
    };
    let separable = bands
        .as_ref()
        .filter(|_| matches!(other, Some((_, Eye::Right))));
    let partner = separable.map(|(own, other)| parallax::Partner {
        own,
        other,
        width: w,
        rows,
        direction,
        column_width: calib.column_width(),
        baseline_m: calib.stereo.baseline_m,
    });
    let blobs = label_wrapped(&mask, w, rows);
    // Blobs in parallel: a navigator detects one station at a time, and a large rock close by
    // takes most of a panorama's parallax matching.
    let mut detections: Vec<Detection> = blobs
        .par_iter()
        .cloned()
        .enumerate()
        .flat_map_iter(|(blob, c)| {
            let layers = match &partner {
                Some(partner) => {
                    let shift = max_shift(&c, top, rows, calib);
                    parallax::layers(c, partner, shift, settings.parallax)
                }
                None => vec![parallax::Layer {
                    pixels: c,
                    part: Separation::Whole,
                    shifts: None,
                    pixel_shifts: Vec::new(),
                }],
            };
            layers.into_iter().map(move |layer| (blob as u32, layer))
        })
        .flat_map_iter(|(blob, layer)| {
            let parallax::Layer {
                pixels,
                part,
                shifts,
                pixel_shifts,
            } = layer;
            // A part separated by parallax has its shifts; a whole blob's pieces take theirs
            // from its pixels'. Ranging decides when they stand in for a stereo partner (by
            // luminance only where the piece's contact is hidden: `ranging::observe`).
            let lookup = parallax::ShiftLookup::new(&pixels, pixel_shifts);
            pieces(pixels, part, rule).into_iter().map(move |piece| {
                let shifts = shifts.or_else(|| lookup.range_of(&piece.pixels));
                (blob, piece, part, shifts)
            })
        })
        .filter_map(|(blob, piece, part, shifts)| {
            let pixels = blob_of(&piece.pixels, w, &sample);
            let mut detection = accept(pixels, piece.ambiguous || doubted, top, calib, settings)?;
            if stances.is_some() {
                // A piece with nothing standing up from the ground is not a rock.
                let (contact, doubt) = ground::contact_of(raised_bottom(&piece.pixels)?, calib);
                detection.contact_row = contact;
                detection.contact_slack_rows = doubt;
                // A piece shorter than the rows the test cannot see is the top of a rock whose
                // body it missed: its width and centroid may be off the rock's.
                let rows = f64::from(detection.bbox[3] - detection.bbox[1] + 1);
                detection.ambiguous |= rows < doubt;
            }
            detection.separation = part;
            detection.parallax_shifts = shifts.map(|s| s.map(f64::from));
            detection.blob = blob;
            Some(detection)
        })
        .collect();
    // In colour mode, whether anything of each detection stands up from the ground, and how
    // far each detected blob's rock may reach beyond what the colour test found: by stereo,
    // and by faint colour.
    if let Some(bands) = ground_bands.filter(|_| !luminance) {
        apply_ground_test(&mut detections, &blobs, mask.as_slice(), bands);
    }
    // (Only for the primary panorama: a right one's detections serve the stereo cue alone.)
    if !luminance && !matches!(other, Some((_, Eye::Left))) {
        let searched = detected_blobs(&detections);
        let components: Vec<&components::Component> =
            searched.iter().map(|&b| &blobs[b as usize]).collect();
        let reach = faint::reach(&components, mask.as_slice(), raw, w, settings);
        let reach: std::collections::HashMap<u32, [u32; 2]> =
            searched.into_iter().zip(reach).collect();
        widen_beyond(&mut detections, &blobs, |blob| reach[&blob]);
    }
    detections.sort_by(|a, b| a.centroid[0].total_cmp(&b.centroid[0]));
    detections
}

/// Sets each detection's [`Detection::flat`] (none of its blob's pixels within its columns
/// stands up from the ground: `ground::GroundTest`, raised or a smooth face nearer than the
/// ground) and [`Detection::beyond_columns`]: the standing pixels that join its blob
/// (`blobs`, components of the colour test's `mask`, as wide as the bands) beside it, on the
/// sides where it ends the blob. The stereo test of `bands` runs over the tiles the
/// detections and searches visit only; detections and blobs are tested in parallel.
fn apply_ground_test(
    detections: &mut [Detection],
    blobs: &[components::Component],
    mask: &[u8],
    bands: ground::Bands,
) {
    if detections.is_empty() {
        return;
    }
    let w = bands.width;
    let rows = mask.len() / w;
    let test = ground::GroundTest::new(bands);
    let limits = |b: [u32; 4]| {
        (
            REACH_WIDTHS * (b[2] - b[0] + 1),
            REACH_HEIGHTS * (b[3] - b[1] + 1),
        )
    };
    // Standing up from the ground: textured and off the ground's shift, or smooth and
    // matching best nearer than the ground but not nearer than the blob's own rock may be.
    let stands = |c: i64, r: i64, shift: usize| {
        usize::try_from(r).is_ok_and(|r| {
            let c = c.rem_euclid(w as i64) as usize;
            r < rows && (test.stance(c, r) == ground::Stance::Raised || test.nearer(c, r, shift))
        })
    };
    let flat: Vec<(bool, bool)> = detections
        .par_iter()
        .map(|d| {
            let pixels = &blobs[d.blob as usize];
            let shift = max_shift(pixels, bands.top, rows, bands.calib);
            let columns = d.bbox[0]..=d.bbox[2];
            let own: Vec<&(u32, u32)> = pixels.iter().filter(|p| columns.contains(&p.0)).collect();
            let flat = !own
                .iter()
                .any(|&&(c, r)| stands(i64::from(c), i64::from(r), shift));
            let stances = own
                .iter()
                .filter(|&&&(_, r)| (r as usize) < rows)
                .map(|&&(c, r)| test.stance(c as usize % w, r as usize));
            let tells = ground::tells_height(bands.calib, f64::from(d.bbox[1]), d.contact_row);
            (flat, flat && tells && ground::mostly_ground(stances))
        })
        .collect();
    for (detection, (flat, surely)) in detections.iter_mut().zip(flat) {
        detection.flat = flat;
        detection.surely_flat = surely;
    }
    let reach: std::collections::HashMap<u32, [u32; 2]> = detected_blobs(detections)
        .into_par_iter()
        .filter_map(|blob| {
            let pixels = &blobs[blob as usize];
            let b = bounds(pixels)?;
            let shift = max_shift(pixels, bands.top, rows, bands.calib);
            let stands = |c, r| stands(c, r, shift);
            Some((
                blob,
                extent::beyond(pixels, mask, w, rows, limits(b), stands),
            ))
        })
        .collect();
    widen_beyond(detections, blobs, |blob| {
        reach.get(&blob).copied().unwrap_or_default()
    });
}

/// The blobs (indices into the mask's components) that some detection was cut from, once each.
fn detected_blobs(detections: &[Detection]) -> Vec<u32> {
    let mut blobs: Vec<u32> = detections.iter().map(|d| d.blob).collect();
    blobs.sort_unstable();
    blobs.dedup();
    blobs
}

/// Widens each detection's [`Detection::beyond_columns`] to the columns its blob's rock may
/// reach (`reach` of its blob), on the sides where it ends the blob.
fn widen_beyond(
    detections: &mut [Detection],
    blobs: &[components::Component],
    reach: impl Fn(u32) -> [u32; 2],
) {
    for detection in detections {
        let Some(b) = bounds(&blobs[detection.blob as usize]) else {
            continue;
        };
        let [before, after] = reach(detection.blob);
        let beyond = &mut detection.beyond_columns;
        if detection.bbox[0] == b[0] {
            beyond[0] = beyond[0].max(before);
        }
        if detection.bbox[2] == b[2] {
            beyond[1] = beyond[1].max(after);
        }
    }
}

/// Raised pixels more than this many of a blob's widths beyond it are not taken for more of
/// its rock (a neighbour the colour test missed, or ground the stereo test mismatched): the
/// smallest piece seen of a rock is a quarter of its width (stress member 5, `extent`).
const REACH_WIDTHS: u32 = 3;

/// … nor raised pixels more than this many of its heights above it, or below its contact
/// (the piece of stress member 5 is half its rock's height, and on the ground).
const REACH_HEIGHTS: u32 = 2;

/// How a pixel is told to be rock.
enum PixelRule<'a> {
    /// By chroma and luminance ([`segment`]).
    Colour,
    /// By luminance, off the flat ground (the stereo test's stance of each pixel of the band).
    OffGround(&'a [ground::Stance]),
    /// By luminance alone (no stereo partner).
    Luminance,
}

/// The closed mask of rock pixels of the ground rows `raw` (`rows` × `w`, RGB).
fn rock_mask(
    raw: &[u8],
    background: &[(f32, f32)],
    w: usize,
    rows: usize,
    settings: &DetectorSettings,
    rule: &PixelRule,
) -> Option<Image<u8, 1>> {
    let mut mask = match rule {
        PixelRule::Colour => segment(raw, background, w, settings),
        PixelRule::OffGround(stances) => {
            segment_luminance(raw, background, w, settings, Some(stances))
        }
        PixelRule::Luminance => segment_luminance(raw, background, w, settings, None),
    };
    close3(&mut mask, w);
    Image::<u8, 1>::new(
        ImageSize {
            width: w,
            height: rows,
        },
        mask,
    )
    .ok()
}

/// Per-pixel R+G+B below the horizon row `top`, for stereo block matching.
fn ground_luminance(image: &image::RgbImage, top: usize) -> Vec<u16> {
    image.as_raw()[top * image.width() as usize * 3..]
        .chunks_exact(3)
        .map(|p| u16::from(p[0]) + u16::from(p[1]) + u16::from(p[2]))
        .collect()
}

/// The largest stereo shift (columns) to search for a blob: the shift of a rock somewhat
/// nearer than the blob's lowest row reads on flat ground (a rock's face overhangs its foot);
/// a blob cut off by the image's bottom may hold a rock nearer still. `top` is the horizon
/// row, `rows` the rows below it.
fn max_shift(
    pixels: &components::Component,
    top: usize,
    rows: usize,
    calib: &Calibration,
) -> usize {
    let bottom = pixels.iter().map(|p| p.1 as usize).max().unwrap_or(0);
    ground::nearest_face_shift(calib, (bottom + top + 1) as f64, bottom + 1 >= rows)
}

/// The pieces of one parallax layer: touching rocks cut at notches of the bottom edge. A
/// farther layer is not cut: its bottom edge is the nearer rock's outline, notched where that
/// outline rises, and the notch rule would cut the farther rock in two.
fn pieces(
    pixels: components::Component,
    part: Separation,
    rule: split::SplitRule,
) -> Vec<split::Piece> {
    if part == Separation::Farther {
        vec![split::Piece {
            pixels,
            ambiguous: true,
        }]
    } else {
        split::split(pixels, rule)
    }
}

/// What a blob accumulates of each of its pixels for its appearance.
struct PixelSample {
    rgb: [f32; 3],
    /// Luminance over the row's median.
    ratio: f32,
    /// Darker than `dark_ratio` of the row's median.
    dark: bool,
}

/// Luminance `r + g + b` and redness `(r − b)/(r + g + b)` of a pixel.
fn luminance_redness(p: &[u8]) -> (f32, f32) {
    let s = f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2]);
    (s, (f32::from(p[0]) - f32::from(p[2])) / (s + 1.0))
}

/// Median luminance and redness of each row, from every fourth column at most (rocks cover a
/// small part of any row; the sample keeps the medians cheap).
fn row_medians(raw: &[u8], w: usize) -> Vec<(f32, f32)> {
    let step = if w >= 1024 { 4 } else { 1 };
    let mut sums = Vec::with_capacity(w / step + 1);
    let mut reds = Vec::with_capacity(w / step + 1);
    raw.chunks_exact(3 * w)
        .map(|row| {
            sums.clear();
            reds.clear();
            for p in row.chunks_exact(3).step_by(step) {
                let (s, r) = luminance_redness(p);
                sums.push(s);
                reds.push(r);
            }
            let mid = sums.len() / 2;
            (
                *sums.select_nth_unstable_by(mid, f32::total_cmp).1,
                *reds.select_nth_unstable_by(mid, f32::total_cmp).1,
            )
        })
        .collect()
}

/// Rock pixels (255) of the ground band, tested without divisions: `ratio > k` as
/// `sum > k · median`, a redness drop as `(median − t)(sum + 1) > r − b`.
fn segment(raw: &[u8], background: &[(f32, f32)], w: usize, s: &DetectorSettings) -> Vec<u8> {
    let rows = background.len();
    let mut mask = vec![0u8; w * rows];
    for ((row, out), &(bg_sum, bg_red)) in raw
        .chunks_exact(3 * w)
        .zip(mask.chunks_exact_mut(w))
        .zip(background)
    {
        let bright = s.bright_ratio * bg_sum;
        let dark = s.dark_ratio * bg_sum;
        let grey = bg_red - s.chroma_drop;
        let dark_grey = bg_red - s.dark_chroma_drop;
        for (p, m) in row.chunks_exact(3).zip(out.iter_mut()) {
            let sum = f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2]);
            let red = f32::from(p[0]) - f32::from(p[2]);
            let scale = sum + 1.0;
            let rock =
                red < grey * scale || sum > bright || (sum < dark && red < dark_grey * scale);
            *m = if rock { 255 } else { 0 };
        }
    }
    mask
}

/// Rock pixels (255) of the ground band by luminance: pixels `luminance_contrast` brighter or
/// darker than the row's median (rock faces lit or shaded, and cast shadows) or standing up
/// from the ground by stereo, kept where they lie between raised pixels of their row
/// ([`between_raised`]). Without `stances`, every pixel that contrast brighter or darker,
/// shadows included.
fn segment_luminance(
    raw: &[u8],
    background: &[(f32, f32)],
    w: usize,
    s: &DetectorSettings,
    stances: Option<&[ground::Stance]>,
) -> Vec<u8> {
    let mut contrasted = vec![false; w * background.len()];
    for (y, (row, out)) in raw
        .chunks_exact(3 * w)
        .zip(contrasted.chunks_exact_mut(w))
        .enumerate()
    {
        let bg = background[y].0;
        let (low, high) = (
            (1.0 - s.luminance_contrast) * bg,
            (1.0 + s.luminance_contrast) * bg,
        );
        for (p, c) in row.chunks_exact(3).zip(out.iter_mut()) {
            let sum = f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2]);
            *c = sum < low || sum > high;
        }
    }
    let rock = match stances {
        Some(stances) => {
            // Standing up from the ground is what makes a rock, whatever its shade.
            for (c, s) in contrasted.iter_mut().zip(stances) {
                *c |= *s == ground::Stance::Raised;
            }
            between_raised(&contrasted, stances, w)
        }
        None => contrasted,
    };
    rock.into_iter().map(|r| if r { 255 } else { 0 }).collect()
}

/// For each pixel of `inside`: whether it lies, within its row's run of `inside` pixels,
/// between the run's first and last pixel standing up from the ground. A rock's smooth face
/// lies between its textured, raised edges; a cast shadow beside it lies outside them, and
/// the rows of a shadow in front of it hold nothing raised.
fn between_raised(inside: &[bool], stances: &[ground::Stance], w: usize) -> Vec<bool> {
    let mut out = vec![false; inside.len()];
    for (y, row) in inside.chunks_exact(w).enumerate() {
        // Runs wrap at the seam: the scan starts after a pixel outside, if the row has one.
        let start = row.iter().position(|&i| !i).map_or(0, |x| x + 1);
        let at = |k: usize| (start + k) % w;
        let raised = |k: usize| stances[y * w + at(k)] == ground::Stance::Raised;
        let mut k = 0;
        while k < w {
            if !row[at(k)] {
                k += 1;
                continue;
            }
            let begin = k;
            while k < w && row[at(k)] {
                k += 1;
            }
            let first = (begin..k).find(|&j| raised(j));
            let last = (begin..k).rev().find(|&j| raised(j));
            if let (Some(first), Some(last)) = (first, last) {
                for j in first..=last {
                    out[y * w + at(j)] = true;
                }
            }
        }
    }
    out
}

/// Morphological closing of `mask` (`w` wide) by a 3 × 3 square, the neighbourhood clipped at
/// the image's edges: it bridges one-pixel cracks inside rocks. Separable u8 max/min passes,
/// several times faster than a distance transform.
fn close3(mask: &mut [u8], w: usize) {
    let mut tmp = vec![0u8; mask.len()];
    along_rows(mask, &mut tmp, w, u8::max);
    along_columns(&tmp, mask, w, u8::max);
    along_rows(mask, &mut tmp, w, u8::min);
    along_columns(&tmp, mask, w, u8::min);
}

/// `out[x] = f(input[x − 1], input[x], input[x + 1])` within each row, edges clipped.
fn along_rows(input: &[u8], out: &mut [u8], w: usize, f: fn(u8, u8) -> u8) {
    for (row, o) in input.chunks_exact(w).zip(out.chunks_exact_mut(w)) {
        o[0] = f(row[0], row[1.min(w - 1)]);
        for (x, win) in row.windows(3).enumerate() {
            o[x + 1] = f(f(win[0], win[1]), win[2]);
        }
        if w > 1 {
            o[w - 1] = f(row[w - 2], row[w - 1]);
        }
    }
}

/// `out[y] = f(input[y − 1], input[y], input[y + 1])` within each column, edges clipped.
fn along_columns(input: &[u8], out: &mut [u8], w: usize, f: fn(u8, u8) -> u8) {
    let rows = input.len() / w;
    for y in 0..rows {
        let centre = &input[y * w..(y + 1) * w];
        let above = &input[y.saturating_sub(1) * w..][..w];
        let below = &input[(y + 1).min(rows - 1) * w..][..w];
        let o = &mut out[y * w..(y + 1) * w];
        for (((o, &a), &c), &b) in o.iter_mut().zip(above).zip(centre).zip(below) {
            *o = f(f(a, c), b);
        }
    }
}

/// The detection of `blob` (band rows offset by `top`), or `None` if it is empty, its contact
/// row is at or above the horizon, it is narrower than `min_width_m` or farther than
/// `max_range_m`, or it lies flat on the ground (`min_rise`) or is a tint of it (`min_texture`).
fn accept(
    blob: Blob,
    ambiguous: bool,
    top: usize,
    calib: &Calibration,
    settings: &DetectorSettings,
) -> Option<Detection> {
    if blob.pixels == 0 || blob.col_max < blob.col_min {
        return None;
    }
    let n = f64::from(blob.pixels);
    let contact_row = (blob.row_max + top + 1) as f64;
    let range = calib.ground_range(contact_row)?;
    let width_px = (blob.col_max - blob.col_min + 1) as f64;
    let width_m = width_px * calib.column_width() * range;
    let top_row = (blob.row_min + top) as f64;
    let clipped = contact_row >= f64::from(calib.image.height);
    let appearance = appearance_of(&blob);
    if range > settings.max_range_m
        || width_m < settings.min_width_m
        || (!clipped && lies_flat(top_row, range, width_m, calib, settings.min_rise))
        || ground_tint(&appearance, settings)
    {
        return None;
    }
    let width = f64::from(calib.image.width);
    Some(Detection {
        centroid: [
            (blob.sum_col / n).rem_euclid(width),
            blob.sum_row / n + top as f64,
        ],
        bbox: [
            blob.col_min as u32,
            (blob.row_min + top) as u32,
            blob.col_max as u32,
            (blob.row_max + top) as u32,
        ],
        pixels: blob.pixels,
        contact_row,
        contact_slack_rows: 0.0,
        appearance,
        ambiguous,
        separation: Separation::Whole,
        blob: 0,
        beyond_columns: [0, 0],
        parallax_shifts: None,
        flat: false,
        surely_flat: false,
    })
}

/// The appearance statistics of a non-empty `blob`.
fn appearance_of(blob: &Blob) -> Appearance {
    let n = f64::from(blob.pixels);
    let mean_luminance = blob.sum_luminance / n;
    let variance = (blob.sum_luminance_sq / n - mean_luminance * mean_luminance).max(0.0);
    let total: f64 = blob.sum_rgb.iter().sum::<f64>().max(1.0);
    Appearance {
        colour: blob.sum_rgb.map(|c| (c / total) as f32),
        brightness: (blob.sum_ratio / n) as f32,
        texture: (variance.sqrt() / mean_luminance.max(1.0)) as f32,
        dark_fraction: (f64::from(blob.dark) / n) as f32,
    }
}

/// Whether a blob looks like regolith of another tint: as bright as the ground (within
/// `bright_ratio` either way) and smoother than `min_texture`.
fn ground_tint(a: &Appearance, s: &DetectorSettings) -> bool {
    a.texture < s.min_texture
        && a.brightness * s.bright_ratio > 1.0
        && a.brightness < s.bright_ratio
}

/// Whether a blob from `top_row` down to a contact at `range` (metres), `width_m` wide, is no
/// taller than flat ground `min_rise × width_m` deep: its top edge, read as ground, lies less
/// than that beyond the contact. A blob reaching the horizon stands up.
fn lies_flat(top_row: f64, range: f64, width_m: f64, calib: &Calibration, min_rise: f64) -> bool {
    calib
        .ground_range(top_row)
        .is_some_and(|far| far - range < min_rise * width_m)
}

#[cfg(test)]
mod tests {
    use super::ground::{self, Stance};
    use super::{
        between_raised, close3, ground_tint, lies_flat, Appearance, Channels, DetectorSettings,
    };
    use crate::calib::Calibration;

    /// A smooth blob as bright as the regolith is a tint of it; a textured one, or a smooth
    /// one clearly darker or brighter, may be a rock.
    #[test]
    fn smooth_ground_bright_blobs_are_tints() {
        let s = DetectorSettings::default();
        let blob = |brightness, texture| Appearance {
            colour: [0.4, 0.33, 0.27],
            brightness,
            texture,
            dark_fraction: 0.0,
        };
        assert!(ground_tint(&blob(1.05, 0.01), &s));
        assert!(!ground_tint(&blob(1.05, 0.1), &s));
        assert!(!ground_tint(&blob(0.7, 0.01), &s));
        assert!(!ground_tint(&blob(1.3, 0.01), &s));
    }

    /// From the 1.5 m mast at 4 m: a patch on the ground 0.2 m wide and 0.1 m deep lies flat;
    /// a rock as wide and 0.1 m tall rises above it.
    #[test]
    fn flat_patches_lie_flat_and_rocks_rise() {
        let calib =
            Calibration::parse(include_str!("../../../../calib/default.toml"), "default").unwrap();
        let patch_top = calib.ground_row(4.1);
        assert!(lies_flat(patch_top, 4.0, 0.2, &calib, 0.9));
        let rock_top = calib.row((0.1f64 - 1.5).atan2(4.0));
        assert!(!lies_flat(rock_top, 4.0, 0.2, &calib, 0.9));
        assert!(!lies_flat(
            calib.elevation.horizon_row,
            4.0,
            0.2,
            &calib,
            0.9
        ));
    }

    /// A rock's smooth middle lies between its raised edges and is kept; the dark shadow beside
    /// it, in the same run of contrasted pixels, is not, nor is a run with nothing raised.
    #[test]
    fn only_what_lies_between_raised_pixels_is_rock() {
        let (r, g, u) = (Stance::Raised, Stance::Ground, Stance::Unknown);
        let inside = [
            true, true, true, true, true, true, true, false, true, true, //
            false, true, true, true, false, false, false, false, false, false,
        ];
        let stances = [
            u, r, u, u, r, u, g, u, u, u, //
            u, g, u, u, u, u, u, u, u, u,
        ];
        let rock = between_raised(&inside, &stances, 10);
        let expected = [
            false, true, true, true, true, false, false, false, false, false, //
            false, false, false, false, false, false, false, false, false, false,
        ];
        assert_eq!(rock, expected);
    }

    #[test]
    fn grayscale_panoramas_are_detected_by_luminance() {
        let grey = image::RgbImage::from_pixel(4, 2, image::Rgb([90, 90, 90]));
        let mut colour = grey.clone();
        colour.put_pixel(3, 1, image::Rgb([120, 90, 70]));
        assert_eq!(Channels::Auto.resolve(&grey), Channels::Luminance);
        assert_eq!(Channels::Auto.resolve(&colour), Channels::Colour);
        assert_eq!(Channels::Colour.resolve(&grey), Channels::Colour);
        assert_eq!(Channels::Luminance.resolve(&colour), Channels::Luminance);
    }

    /// A stereo pair is detected by luminance when JPEG or when its chroma is noisy; a
    /// requested mode stands, and a panorama without a stereo partner keeps its colour.
    #[test]
    fn noisy_or_jpeg_colour_of_a_stereo_pair_is_detected_by_luminance() {
        let auto = DetectorSettings::default();
        let colour = DetectorSettings {
            channels: Channels::Colour,
            ..DetectorSettings::default()
        };
        // Soil and greyer soil in alternate columns: adjacent pixels differ in chroma by 0.12.
        let striped = image::RgbImage::from_fn(64, 10, |x, _| {
            if x % 2 == 0 {
                image::Rgb([150, 90, 60])
            } else {
                image::Rgb([130, 100, 75])
            }
        });
        let clean = image::RgbImage::from_pixel(64, 10, image::Rgb([150, 90, 60]));
        let cases = [
            (&auto, &clean, true, false, Channels::Colour),
            (&auto, &clean, true, true, Channels::Luminance),
            (&auto, &striped, true, false, Channels::Luminance),
            (&colour, &striped, true, true, Channels::Colour),
            (&auto, &striped, false, false, Channels::Colour),
        ];
        for (settings, image, stereo, jpeg, mode) in cases {
            assert_eq!(settings.channels_of(image, stereo, jpeg), mode);
        }
    }

    /// A grey patch on textured soil, seen by a quarter-size stereo pair: painted on the
    /// ground (the right panorama sees each of its rows at the ground's shift) nothing of it
    /// stands and its detection is flat; as a rock's face (every row at its contact's shift)
    /// it stands, and is not surely flat. Without stereo nothing is flat (untested).
    #[test]
    fn a_patch_on_the_ground_is_flat_and_a_standing_face_is_not() {
        let calib = Calibration::parse(
            "[image]\nwidth = 1024\nheight = 192\n[azimuth]\ncolumn0_deg = 180.0\n\
             direction = \"clockwise\"\n[elevation]\nhorizon_row = 75.0\nfocal_px = 163.0\n\
             [mast]\nheight_m = 1.5\n[stereo]\nbaseline_m = 0.3\n",
            "test",
        )
        .expect("valid");
        let (w, h) = (1024u32, 192u32);
        let (rows, columns) = (95..120u32, 500.0..530.0);
        // A level per whole pixel, from a hash of its column and row.
        let level = |x: f64, y: u32| {
            let mut k =
                (x.floor() as i64 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ u64::from(y) << 32;
            k ^= k >> 29;
            k = k.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            k ^= k >> 32;
            0.9 + 0.2 * (k % 1000) as f32 / 1000.0
        };
        let contact = ground::ground_shift(&calib, f64::from(rows.end));
        // The panorama whose columns see the world's columns shifted by `eye` (0 left, 1 right,
        // the right camera seeing a point at a smaller column).
        let pair = |standing: bool| {
            let paint = |eye: f64| {
                image::RgbImage::from_fn(w, h, |x, y| {
                    let ground =
                        f64::from(x) + eye * ground::ground_shift(&calib, f64::from(y) + 0.5);
                    let face = if standing {
                        f64::from(x) + eye * contact
                    } else {
                        ground
                    };
                    let (base, at) = if rows.contains(&y) && columns.contains(&face) {
                        ([120.0, 110.0, 100.0], face)
                    } else {
                        ([180.0, 110.0, 70.0], ground)
                    };
                    let t = level(at, y);
                    image::Rgb(base.map(|c: f32| (c * t).min(255.0) as u8))
                })
            };
            (paint(0.0), paint(1.0))
        };
        let colour = DetectorSettings {
            channels: Channels::Colour,
            ..DetectorSettings::default()
        };
        let patch = |left: &image::RgbImage, right: Option<&image::RgbImage>, settings| {
            let found = super::detect(left, right, &calib, settings);
            found
                .into_iter()
                .find(|d| d.bbox[0] < 530 && d.bbox[2] >= 500 && d.bbox[1] < 120 && d.bbox[3] >= 95)
                .unwrap_or_else(|| panic!("the patch is detected"))
        };
        let (left, right) = pair(false);
        assert!(patch(&left, Some(&right), &colour).flat);
        assert!(!patch(&left, None, &colour).flat);
        let (left, right) = pair(true);
        let standing = patch(&left, Some(&right), &colour);
        assert!(!standing.flat && !standing.surely_flat);
    }

    /// A one-pixel crack inside a blob is bridged; the blob does not grow, even at the edge.
    #[test]
    fn closing_bridges_cracks_without_growing() {
        let w = 8;
        let mut mask = vec![0u8; w * 6];
        for y in 0..4 {
            for x in 0..5 {
                if x != 2 {
                    mask[y * w + x] = 255;
                }
            }
        }
        let mut expected = vec![0u8; w * 6];
        for y in 0..4 {
            expected[y * w..y * w + 5].fill(255);
        }
        close3(&mut mask, w);
        assert_eq!(mask, expected);
    }
}
