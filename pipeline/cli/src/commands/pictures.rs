//! The run's pictures of its panoramas (docs/RUN.md, "Pictures"): each station's panorama
//! annotated with its detections (`panoramas/STATION.png`), and a contact sheet with the best
//! crop of every landmark (`landmarks.png`). The panoramas are decoded once more here, in
//! parallel, rather than kept from detection: a long drive's images do not fit in memory.

use anyhow::{Context, Result};
use image::imageops::{self, FilterType};
use image::RgbImage;
use kornia_image::{Image, ImageSize};
use kornia_imgproc::interpolation::InterpolationMode;
use kornia_imgproc::resize::resize_fast_rgb;
use qrm_atomic_file::{OutputSet, Temporary};
use qrm_core::map::LandmarkId;
use qrm_plot::{
    write_contact_sheet, write_panorama, AnnotatedPanorama, ContactSheet, Mark, MarkKind, Tile,
    TILE,
};
use qrm_vision::run::{Association, DetectionRecord, LandmarkRecord, StationRecord};
use qrm_vision::survey::read_image;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// `--panoramas`: how the annotated panoramas are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PanoramaSize {
    /// Scaled by a power of two to between 1025 and 2048 pixels wide (a 4096-wide panorama
    /// at half size, a 1024-wide one at twice its size).
    Reduced,
    /// At the panorama's own size.
    Full,
    /// Not written (the contact sheet still is).
    #[value(name = "none")]
    Off,
}

/// The widest annotated panorama written by default, pixels.
const REDUCED_WIDTH: u32 = 2048;
/// Context kept around a landmark's box in its crop, as a fraction of the box's size.
const CROP_MARGIN: f64 = 0.35;

/// What the run hands to the pictures.
pub struct RunImages<'a> {
    pub directory: &'a Path,
    pub size: (u32, u32),
    pub records: &'a [StationRecord],
    pub landmarks: &'a [LandmarkRecord],
}

/// Stages `out/panoramas/*.png` (unless `size` is `None`) and `out/landmarks.png`, removing
/// the earlier run's pictures that these do not replace. A panorama that cannot be read again
/// is left out with a warning (returned).
pub fn stage_pictures(
    outputs: &mut OutputSet,
    out: &Path,
    run: &RunImages,
    size: PanoramaSize,
) -> Result<Vec<String>> {
    let directory = out.join("panoramas");
    if size != PanoramaSize::Off {
        std::fs::create_dir_all(&directory)
            .with_context(|| format!("cannot create {}", directory.display()))?;
    }
    let fused: HashMap<(usize, usize), LandmarkId> = run
        .landmarks
        .iter()
        .flat_map(|l| l.sightings.iter().map(move |&s| (s, l.landmark)))
        .collect();
    let best = best_sightings(run.records, run.landmarks);
    let stations: Vec<StationPictures> = run
        .records
        .par_iter()
        .map(|record| station_pictures(record, run, &directory, size, &fused, &best))
        .collect::<Result<_>>()?;

    let mut warnings = Vec::new();
    let mut written = Vec::new();
    let mut crops = Vec::new();
    for station in stations {
        match station {
            StationPictures::Unreadable(warning) => warnings.push(warning),
            StationPictures::Drawn { panorama, crops: c } => {
                if let Some(temporary) = panorama {
                    written.push(temporary.target().to_path_buf());
                    outputs.adopt(temporary);
                }
                crops.extend(c);
            }
        }
    }
    for stale in earlier_pictures(&directory)
        .into_iter()
        .filter(|p| !written.contains(p))
    {
        outputs.remove_stale(&stale);
    }
    let sheet = out.join("landmarks.png");
    if crops.is_empty() {
        outputs.remove_stale(&sheet);
    } else {
        crops.sort_by_key(|c| c.landmark);
        let tiles: Vec<Tile> = crops
            .iter()
            .map(|c| Tile {
                image: plot_image(&c.image),
                caption: format!("L{}", c.landmark),
                note: c.note.clone(),
            })
            .collect();
        let title = format!(
            "{} landmarks, each where it was seen largest (map id; sightings, station)",
            tiles.len()
        );
        outputs.stage(&sheet, |temporary| {
            write_contact_sheet(
                temporary,
                &ContactSheet {
                    title,
                    tiles: &tiles,
                },
            )
        })?;
    }
    Ok(warnings)
}

/// One station's share of the pictures.
enum StationPictures {
    Drawn {
        panorama: Option<Temporary>,
        crops: Vec<Crop>,
    },
    Unreadable(String),
}

/// A landmark's best view, fitted into a tile.
struct Crop {
    landmark: LandmarkId,
    image: RgbImage,
    note: String,
}

/// The sighting of each landmark with the most pixels, as `(station, detection) → (landmark,
/// sightings)`.
fn best_sightings(
    records: &[StationRecord],
    landmarks: &[LandmarkRecord],
) -> HashMap<(usize, usize), (LandmarkId, usize)> {
    let pixels = |&(station, detection): &(usize, usize)| {
        records
            .get(station)
            .and_then(|r| r.detections.get(detection))
            .map_or(0, |d| d.pixels)
    };
    landmarks
        .iter()
        .filter_map(|l| {
            let best = l.sightings.iter().max_by_key(|s| (pixels(s), s.0))?;
            Some((*best, (l.landmark, l.sightings.len())))
        })
        .collect()
}

fn station_pictures(
    record: &StationRecord,
    run: &RunImages,
    directory: &Path,
    size: PanoramaSize,
    fused: &HashMap<(usize, usize), LandmarkId>,
    best: &HashMap<(usize, usize), (LandmarkId, usize)>,
) -> Result<StationPictures> {
    let Some(file) = record.files.first() else {
        return Ok(StationPictures::Drawn {
            panorama: None,
            crops: Vec::new(),
        });
    };
    let image = match read_image(&run.directory.join(file), run.size) {
        Ok(image) => image,
        Err(e) => {
            return Ok(StationPictures::Unreadable(format!(
                "station {}: no annotated panorama or crops: {e}",
                record.station
            )))
        }
    };
    let crops = record
        .detections
        .iter()
        .enumerate()
        .filter_map(|(i, d)| {
            let &(landmark, sightings) = best.get(&(record.index, i))?;
            Some(Crop {
                landmark,
                image: crop(&image, d.bbox),
                note: format!(
                    "{sightings} sighting{}, {}",
                    if sightings == 1 { "" } else { "s" },
                    record.station
                ),
            })
        })
        .collect();
    let panorama = match size {
        PanoramaSize::Off => None,
        PanoramaSize::Full | PanoramaSize::Reduced => {
            let path = directory.join(format!("{}.png", record.station));
            Some(annotate(record, &image, size, fused, &path)?)
        }
    };
    Ok(StationPictures::Drawn { panorama, crops })
}

/// Draws the annotated panorama of `record` into a temporary file for `path`.
fn annotate(
    record: &StationRecord,
    image: &RgbImage,
    size: PanoramaSize,
    fused: &HashMap<(usize, usize), LandmarkId>,
    path: &Path,
) -> Result<Temporary> {
    let scale = match size {
        PanoramaSize::Reduced => reduced_scale(image.width()),
        _ => 1.0,
    };
    let shown = if scale == 1.0 {
        image.clone()
    } else {
        resized(image, scale)
    };
    let marks: Vec<Mark> = record
        .detections
        .iter()
        .enumerate()
        .map(|(i, d)| mark(d, fused.get(&(record.index, i)).copied(), scale))
        .collect();
    let count = |kind: MarkKind| marks.iter().filter(|m| m.kind == kind).count();
    let shown_at = if scale == 1.0 {
        String::new()
    } else {
        format!(" (shown at {scale}× size)")
    };
    let title = format!(
        "{}: {} detections: {} matched, {} new, {} held back, {} not used; ranges in metres{shown_at}",
        record.station,
        marks.len(),
        count(MarkKind::Matched),
        count(MarkKind::New),
        count(MarkKind::HeldBack),
        count(MarkKind::Unused),
    );
    let temporary = Temporary::beside(path);
    write_panorama(
        temporary.path(),
        &AnnotatedPanorama {
            title,
            image: plot_image(&shown),
            marks: &marks,
        },
    )
    .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(temporary)
}

/// `image` scaled by `scale` (a power of two), bilinear: halving averages each 2 × 2 block.
/// kornia's SIMD resize, since `image`'s area filter took 7 % of a marsyard run's CPU time.
fn resized(image: &RgbImage, scale: f64) -> RgbImage {
    let scaled = |v: u32| ((f64::from(v) * scale).round() as u32).max(1);
    let (width, height) = (scaled(image.width()), scaled(image.height()));
    let size = |width: u32, height: u32| ImageSize {
        width: width as usize,
        height: height as usize,
    };
    Image::<u8, 3>::new(size(image.width(), image.height()), image.as_raw().clone())
        .and_then(|src| {
            let mut dst = Image::<u8, 3>::from_size_val(size(width, height), 0)?;
            resize_fast_rgb(&src, &mut dst, InterpolationMode::Bilinear)?;
            Ok(dst)
        })
        .ok()
        .and_then(|dst| RgbImage::from_raw(width, height, dst.as_slice().to_vec()))
        .expect("a decoded panorama and a positive size")
}

/// The power of two that brings a panorama `width` pixels wide to more than
/// [`REDUCED_WIDTH`]/2 and at most [`REDUCED_WIDTH`]: large panoramas shrink, small ones grow so
/// that the tags have room.
fn reduced_scale(width: u32) -> f64 {
    let mut scale = 1.0;
    while f64::from(width) * scale > f64::from(REDUCED_WIDTH) {
        scale /= 2.0;
    }
    while f64::from(width) * scale * 2.0 <= f64::from(REDUCED_WIDTH) {
        scale *= 2.0;
    }
    scale
}

/// The box and tags of one detection, `fused` its landmark if it reached the map, in the
/// coordinates of the panorama scaled by `scale`. Detections left out get a plain box: their
/// reasons are in stations.json, and tags on every sliver would hide the rocks.
fn mark(d: &DetectionRecord, fused: Option<LandmarkId>, scale: f64) -> Mark {
    let (kind, label) = match &d.association {
        Association::Matched { landmark } => (MarkKind::Matched, format!("L{landmark}")),
        Association::New { landmark } => (MarkKind::New, format!("new L{landmark}")),
        Association::HeldBack { .. } => (
            MarkKind::HeldBack,
            fused.map_or("held".into(), |l| format!("held → L{l}")),
        ),
        Association::Unused { .. } => (MarkKind::Unused, String::new()),
    };
    let [low, high] = d.range.fused;
    let detail = match (kind, fused) {
        (MarkKind::Unused, _) | (MarkKind::HeldBack, None) => String::new(),
        _ if high.is_finite() => format!("{low:.1}–{high:.1}"),
        _ => format!("≥ {low:.1}"),
    };
    Mark {
        bbox: d.bbox.map(|v| f64::from(v) * scale),
        kind,
        label,
        detail,
    }
}

/// The box `bbox` with some context around it, across the seam if it wraps, shrunk to fit a
/// tile.
fn crop(image: &RgbImage, bbox: [u32; 4]) -> RgbImage {
    crop_with_context(image, bbox).1
}

/// The box `bbox` with some context around it, across the seam if it wraps: at the image's
/// resolution, and shrunk to fit a contact-sheet tile.
pub(super) fn crop_with_context(image: &RgbImage, bbox: [u32; 4]) -> (RgbImage, RgbImage) {
    let (width, height) = (image.width() as i64, image.height() as i64);
    let [c0, r0, c1, r1] = bbox.map(i64::from);
    let margin_c = ((c1 - c0 + 1) as f64 * CROP_MARGIN).ceil() as i64;
    let margin_r = ((r1 - r0 + 1) as f64 * CROP_MARGIN).ceil() as i64;
    let (c0, c1) = (c0 - margin_c, c1 + margin_c);
    // A box from a record (stations.json) may lie outside the image: clamp, keep a pixel.
    let r0 = (r0 - margin_r).clamp(0, height - 1);
    let r1 = (r1 + margin_r).clamp(r0, height - 1);
    let (w, h) = ((c1 - c0 + 1).clamp(1, width) as u32, (r1 - r0 + 1) as u32);
    let piece = RgbImage::from_fn(w, h, |x, y| {
        let column = (c0 + i64::from(x)).rem_euclid(width);
        *image.get_pixel(column as u32, (r0 + i64::from(y)) as u32)
    });
    let scale = (f64::from(TILE.0) / f64::from(w)).min(f64::from(TILE.1) / f64::from(h));
    let fitted = (
        ((f64::from(w) * scale) as u32).clamp(1, TILE.0),
        ((f64::from(h) * scale) as u32).clamp(1, TILE.1),
    );
    let tile = imageops::resize(&piece, fitted.0, fitted.1, FilterType::CatmullRom);
    (piece, tile)
}

pub(super) fn plot_image(image: &RgbImage) -> qrm_plot::RgbImage<'_> {
    qrm_plot::RgbImage {
        pixels: image.as_raw(),
        width: image.width(),
        height: image.height(),
    }
}

/// The PNG files an earlier run left in `directory` (not the hidden temporary files of this
/// one).
fn earlier_pictures(directory: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(directory)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension().is_some_and(|e| e == "png")
                        && !p
                            .file_name()
                            .is_some_and(|n| n.to_string_lossy().starts_with('.'))
                })
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::crop;
    use image::{Rgb, RgbImage};
    use qrm_plot::TILE;

    #[test]
    fn a_crop_across_the_seam_joins_both_edges() {
        // Left half red, right half blue: a box over the seam shows blue then red.
        let image = RgbImage::from_fn(100, 20, |x, _| {
            if x < 50 {
                Rgb([255, 0, 0])
            } else {
                Rgb([0, 0, 255])
            }
        });
        let piece = crop(&image, [95, 5, 104, 14]);
        assert!(piece.width() <= TILE.0 && piece.height() <= TILE.1);
        let (left, right) = (
            piece.get_pixel(2, piece.height() / 2),
            piece.get_pixel(piece.width() - 3, piece.height() / 2),
        );
        assert_eq!((left[2], right[0]), (255, 255), "{left:?} {right:?}");
    }
}
