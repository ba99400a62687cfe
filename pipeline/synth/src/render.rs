//! Ray casting one cylindrical panorama (mono, or one eye of the rotating stereo head).

use super::scene::Scene;
use super::shade;
use super::shadow::Shadows;
use super::world::World;
use qrm_core::geometry::Point;
use qrm_vision::calib::Calibration;
use rayon::prelude::*;

/// Where the rover stands and which way it faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub position: Point,
    /// World azimuth (radians) of the rover's +x axis; calibration azimuths are rover-frame.
    pub heading: f64,
}

/// Which camera of the head takes the panorama.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eye {
    Mono,
    Left,
    Right,
}

/// A rendered panorama with its per-pixel ground truth.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Render {
    pub width: u32,
    pub height: u32,
    /// Row-major RGB8.
    pub rgb: Vec<u8>,
    /// Per pixel: 0 = no rock, rock id + 1 otherwise (the surface hit by the pixel-centre ray).
    pub rock_id: Vec<u32>,
}

/// Ground farther than this (metres) is pure haze: it saves texture work at the horizon.
const FAR: f64 = 3000.0;

/// Rows of slack around a rock's projected bounding sphere (rounding of the row formula).
const ROW_SLACK: f64 = 2.0;

/// Everything a column's rays share: the optical centre, the horizontal viewing direction and
/// the rocks whose bounding spheres the column's ray fan can meet, with the rows they span.
struct Column {
    origin: [f64; 3],
    along: [f64; 2],
    candidates: std::ops::Range<usize>,
}

struct Candidate {
    body: usize,
    rows: (f64, f64),
}

/// The optical centre (on the ground plane's x, y) of `eye` for the column looking along world
/// azimuth `azimuth`: the rotating stereo head puts the left camera baseline/2 to the left of
/// the viewing direction and the right camera baseline/2 to its right.
pub fn optical_centre(calib: &Calibration, pose: Pose, eye: Eye, azimuth: f64) -> Point {
    let offset = eye_offset(calib, eye);
    Point::new(
        pose.position.x - offset * azimuth.sin(),
        pose.position.y + offset * azimuth.cos(),
    )
}

/// How far `eye` sits to the left of the viewing direction, metres.
fn eye_offset(calib: &Calibration, eye: Eye) -> f64 {
    match eye {
        Eye::Mono => 0.0,
        Eye::Left => 0.5 * calib.stereo.baseline_m,
        Eye::Right => -0.5 * calib.stereo.baseline_m,
    }
}

/// The world azimuth of the column of `eye` whose ray, from that column's optical centre
/// ([`optical_centre`]), passes through `point`. With the eye `s` to the left of the viewing
/// direction φ, the ray meets `point` when `d · sin(θ − φ) = s`, `θ` and `d` being the azimuth
/// and distance of `point` from the station centre: `φ = θ − asin(s / d)` (calib/README.md). A
/// point within half a baseline of the centre, which no column sees, gets `θ`.
pub fn viewing_azimuth(calib: &Calibration, pose: Pose, eye: Eye, point: Point) -> f64 {
    let (dx, dy) = (point.x - pose.position.x, point.y - pose.position.y);
    let (theta, d) = (dy.atan2(dx), dx.hypot(dy));
    let s = eye_offset(calib, eye);
    if d > s.abs() {
        theta - (s / d).asin()
    } else {
        theta
    }
}

/// Renders one panorama: each column is a ray fan at that column's azimuth; for Left/Right the
/// optical centre is displaced ±baseline/2 perpendicular to that column's viewing direction
/// (left eye to the left of the viewing direction), at height mast.height_m above the ground
/// plane z = 0.
pub fn render(world: &World, calib: &Calibration, pose: Pose, eye: Eye) -> Render {
    let scene = Scene::new(world);
    let shadows = Shadows::new(&scene);
    let (width, height) = (calib.image.width as usize, calib.image.height as usize);
    let mast = calib.mast.height_m;
    let mut candidates = Vec::new();
    let columns: Vec<Column> = (0..width)
        .map(|c| {
            let azimuth = pose.heading + calib.azimuth(c as f64 + 0.5);
            let along = [azimuth.cos(), azimuth.sin()];
            let centre = optical_centre(calib, pose, eye, azimuth);
            let origin = [centre.x, centre.y, mast];
            let start = candidates.len();
            for (body, b) in scene.bodies.iter().enumerate() {
                if let Some(rows) = rows_of_sphere(calib, origin, along, b.center, b.radius) {
                    candidates.push(Candidate { body, rows });
                }
            }
            Column {
                origin,
                along,
                candidates: start..candidates.len(),
            }
        })
        .collect();
    let mut rgb = vec![0u8; width * height * 3];
    let mut rock_id = vec![0u32; width * height];
    let column_width = calib.column_width();
    rgb.par_chunks_mut(width * 3)
        .zip(rock_id.par_chunks_mut(width))
        .enumerate()
        .for_each(|(row, (rgb_row, id_row))| {
            let centre = row as f64 + 0.5;
            // The cylindrical projection gives tan(elevation) directly; keeping the ray's
            // horizontal part of unit length makes t the horizontal range.
            let rise = (calib.elevation.horizon_row - centre) / calib.elevation.focal_px;
            let slant = (1.0 + rise * rise).sqrt();
            for (c, column) in columns.iter().enumerate() {
                let direction = [column.along[0], column.along[1], rise];
                let mut t_best = if rise < 0.0 {
                    mast / -rise
                } else {
                    f64::INFINITY
                };
                let mut hit = None;
                for cand in &candidates[column.candidates.clone()] {
                    if centre < cand.rows.0 || centre > cand.rows.1 {
                        continue;
                    }
                    let body = &scene.bodies[cand.body];
                    if let Some((t, lump)) = scene.hit_body(body, column.origin, direction, 0.0) {
                        if t < t_best {
                            t_best = t;
                            hit = Some((cand.body, lump));
                        }
                    }
                }
                let p = [
                    column.origin[0] + t_best * direction[0],
                    column.origin[1] + t_best * direction[1],
                    column.origin[2] + t_best * direction[2],
                ];
                let colour = if let Some((b, lump)) = hit {
                    let body = &scene.bodies[b];
                    id_row[c] = body.label;
                    let n = scene.lumps[lump].normal(p);
                    let lit = Shadows::surface_lit(&scene, p, n);
                    let (albedo, bumped) = shade::rock(body, p, n);
                    let c = shade::light(albedo, bumped, scene.sun, lit);
                    shade::haze(c, t_best * slant, world.haze)
                } else if t_best < FAR {
                    // A pixel covers about t·Δazimuth across and t²/(focal·mast) along the range.
                    let footprint = (t_best * column_width)
                        .max(t_best * t_best / (calib.elevation.focal_px * mast));
                    let (albedo, n, open) =
                        shade::ground(world.seed, p[0], p[1], footprint, scene.sun);
                    let lit = open && shadows.ground_lit(&scene, p[0], p[1]);
                    let c = shade::light(albedo, n, scene.sun, lit);
                    shade::haze(c, t_best * slant, world.haze)
                } else if rise < 0.0 {
                    shade::HORIZON
                } else {
                    let d = [
                        direction[0] / slant,
                        direction[1] / slant,
                        direction[2] / slant,
                    ];
                    shade::sky(d, scene.sun)
                };
                rgb_row[3 * c..3 * c + 3].copy_from_slice(&shade::encode(colour));
            }
        });
    Render {
        width: calib.image.width,
        height: calib.image.height,
        rgb,
        rock_id,
    }
}

/// Continuous row interval (with slack) in which the column with optical centre `origin` and
/// horizontal direction `along` can see the sphere, or `None` if the column's vertical ray
/// plane misses it or it lies behind the camera.
fn rows_of_sphere(
    calib: &Calibration,
    origin: [f64; 3],
    along: [f64; 2],
    center: [f64; 3],
    radius: f64,
) -> Option<(f64, f64)> {
    let (dx, dy) = (center[0] - origin[0], center[1] - origin[1]);
    let ahead = dx * along[0] + dy * along[1];
    let across = -dx * along[1] + dy * along[0];
    if across.abs() > radius || ahead < -radius {
        return None;
    }
    let near = ahead - radius;
    if near <= 0.0 {
        return Some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let far = ahead + radius;
    let (top, bottom) = (
        center[2] + radius - origin[2],
        center[2] - radius - origin[2],
    );
    let top_rise = top / if top >= 0.0 { near } else { far };
    let bottom_rise = bottom / if bottom >= 0.0 { far } else { near };
    let row = |rise: f64| calib.elevation.horizon_row - calib.elevation.focal_px * rise;
    Some((row(top_rise) - ROW_SLACK, row(bottom_rise) + ROW_SLACK))
}
