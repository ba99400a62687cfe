//! `truth.json`: the ground truth of a synthetic dataset (format in `datasets/README.md`). Only
//! evaluation reads it; the pipeline proper never does.

use crate::{optical_centre, viewing_azimuth, Eye, Pose, Render, World};
use qrm_vision::calib::{Calibration, ColumnDirection};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Truth {
    pub format: String,
    pub version: u32,
    pub preset: String,
    pub seed: u64,
    pub rocks: Vec<RockTruth>,
    pub stations: Vec<StationTruth>,
    pub images: Vec<ImageTruth>,
    /// How the set departs from its preset's own look, when it does (`--preset stress`, or
    /// scene, camera or encoding options): a record for people and reports, read by nothing
    /// else. Absent otherwise, so that such sets' files stay as they always were.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant: Option<VariantTruth>,
}

pub const FORMAT: &str = "qrm-truth";
pub const VERSION: u32 = 1;

/// The scene, camera, encoding and calibration a set was rendered with (`datasets/README.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariantTruth {
    /// The preset whose layout was used (`marsyard` or `random` for `stress`).
    pub layout: String,
    /// Sun elevation, degrees: asked for, or the world's own draw.
    pub sun_elevation_deg: f64,
    pub rock_albedo_contrast: f64,
    pub cluster: f64,
    pub exposure_ev: f64,
    pub gamma: f64,
    pub vignetting: f64,
    pub blur_px: f32,
    pub noise: f64,
    pub grayscale: bool,
    pub jpeg_quality: Option<u8>,
    /// The calibration's `azimuth.direction` and `azimuth.column0_deg`.
    pub column_direction: ColumnDirection,
    pub column0_deg: f64,
    /// Panorama size, pixels.
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RockTruth {
    pub id: u32,
    /// Ground position (x, y), metres.
    pub position: [f64; 2],
    /// Characteristic radius, metres.
    pub size: f64,
    /// Top above the ground, metres.
    pub height: f64,
    /// Depth of the rock below the ground plane, metres.
    pub burial: f64,
    pub albedo: [f32; 3],
    /// The ellipsoids whose union is the rock: centre relative to `position` (z up, before
    /// burial), radii, yaw.
    pub lumps: Vec<LumpTruth>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LumpTruth {
    pub center: [f64; 3],
    pub radii: [f64; 3],
    pub yaw: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StationTruth {
    /// File name stem of its images (`<name>_left.png`, `<name>_right.png`, or `<name>.png`).
    pub name: String,
    pub position: [f64; 2],
    /// World azimuth (radians) of the rover's +x axis, from which calibration azimuths count.
    pub heading: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageTruth {
    pub file: String,
    pub station: usize,
    /// `"left"`, `"right"` or `"mono"`.
    pub eye: String,
    /// Rocks with at least one visible pixel.
    pub rocks: Vec<VisibleRock>,
    /// Fingerprint of the image file as written (`qrm_vision::survey::digest`); absent in
    /// truth files written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub digest: Option<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VisibleRock {
    pub id: u32,
    /// Visible pixels.
    pub pixels: u32,
    /// `[column_min, row_min, column_max, row_max]`, inclusive pixel indices; a rock seen across
    /// the panorama's seam has `column_min > column_max`.
    pub bbox: [u32; 4],
    /// Mean (column, row) of the visible pixels, pixel centres at `+0.5`, continuous across the
    /// seam (may exceed the width).
    pub centroid: [f64; 2],
    /// True bearing of the rock's ground position in the rover frame (radians) and its column.
    pub bearing: f64,
    pub bearing_column: f64,
    /// Horizontal range from the optical centre to the rock's ground position, metres.
    pub range: f64,
    /// Where the rock meets the ground nearest the camera: the bearing column and the row of
    /// flat ground at `range − contact radius` along the bearing.
    pub contact: [f64; 2],
}

impl RockTruth {
    pub fn of(world: &World, id: u32) -> RockTruth {
        let rock = &world.rocks[id as usize];
        RockTruth {
            id,
            position: [rock.position.x, rock.position.y],
            size: rock.size,
            height: world.rock_height(id),
            burial: rock.burial,
            albedo: rock.albedo,
            lumps: rock
                .lumps
                .iter()
                .map(|l| LumpTruth {
                    center: l.center,
                    radii: l.radii,
                    yaw: l.yaw,
                })
                .collect(),
        }
    }
}

/// What image `render` of `world` from `pose` shows of each rock.
pub fn visible_rocks(
    world: &World,
    calib: &Calibration,
    pose: Pose,
    eye: Eye,
    render: &Render,
) -> Vec<VisibleRock> {
    /// Per rock: pixel count, row range, row sum, and a histogram over columns (columns wrap
    /// around at the seam, so the centroid is taken once the seam side is known).
    struct Acc {
        pixels: u32,
        rows: (u32, u32),
        sum_row: f64,
        per_column: Vec<u32>,
    }
    let width = render.width as usize;
    let mut acc: Vec<Option<Acc>> = (0..world.rocks.len()).map(|_| None).collect();
    for (i, &id) in render.rock_id.iter().enumerate() {
        if id == 0 {
            continue;
        }
        let (row, column) = ((i / width) as u32, i % width);
        let a = acc[id as usize - 1].get_or_insert_with(|| Acc {
            pixels: 0,
            rows: (row, row),
            sum_row: 0.0,
            per_column: vec![0; width],
        });
        a.pixels += 1;
        a.rows = (a.rows.0.min(row), a.rows.1.max(row));
        a.sum_row += f64::from(row) + 0.5;
        a.per_column[column] += 1;
    }
    let mut out = Vec::new();
    for (index, a) in acc.into_iter().enumerate() {
        let Some(a) = a else { continue };
        let id = index as u32;
        let columns: Vec<usize> = (0..width).filter(|&c| a.per_column[c] > 0).collect();
        // The rock spans the circle except its largest gap of empty columns: it starts right
        // after that gap.
        let mut start = columns[0];
        let mut gap = columns[0] + width - columns[columns.len() - 1];
        for pair in columns.windows(2) {
            if pair[1] - pair[0] > gap {
                gap = pair[1] - pair[0];
                start = pair[1];
            }
        }
        let end = (start + width - gap) % width;
        let sum_column: f64 = columns
            .iter()
            .map(|&c| {
                let unwrapped = if c >= start { c } else { c + width };
                f64::from(a.per_column[c]) * (unwrapped as f64 + 0.5)
            })
            .sum();
        let rock = &world.rocks[index];
        let azimuth = viewing_azimuth(calib, pose, eye, rock.position);
        let centre = optical_centre(calib, pose, eye, azimuth);
        let (dx, dy) = (rock.position.x - centre.x, rock.position.y - centre.y);
        let range = dx.hypot(dy);
        let bearing = (dy.atan2(dx) - pose.heading).rem_euclid(std::f64::consts::TAU);
        let bearing_column = calib.column(bearing);
        let contact = range - world.contact_reach(id, dx / range, dy / range);
        out.push(VisibleRock {
            id,
            pixels: a.pixels,
            bbox: [start as u32, a.rows.0, end as u32, a.rows.1],
            centroid: [
                sum_column / f64::from(a.pixels),
                a.sum_row / f64::from(a.pixels),
            ],
            bearing,
            bearing_column,
            range,
            contact: [bearing_column, calib.ground_row(contact.max(1e-3))],
        });
    }
    out
}
