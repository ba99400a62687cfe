//! Colours: the butterscotch sky, the regolith, rock surfaces, sunlight and haze.
//!
//! Colours are linear reflectances and radiances; the image stores their square root (a gamma
//! of 2, close to sRGB), because `sqrt` is exactly rounded everywhere while `powf` is not.

use super::ellipsoid::{dot, normalize};
use super::noise::{cell_value, fbm2, fbm3, nearest_cell3};
use super::scene::Body;

pub(super) type Rgb = [f64; 3];

/// Sky radiance at the horizon, which is also the colour of the haze.
pub const HORIZON: Rgb = [0.74, 0.50, 0.31];
/// Sky radiance high up: a darker, redder butterscotch.
const ZENITH: Rgb = [0.40, 0.24, 0.13];
/// Direct sunlight (slightly reddened by dust) and the dim sky fill light.
const SUN: Rgb = [1.55, 1.42, 1.25];
const AMBIENT: Rgb = [0.30, 0.21, 0.15];

fn mix(a: Rgb, b: Rgb, t: f64) -> Rgb {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

fn scale(a: Rgb, s: f64) -> Rgb {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Sky seen along unit direction `d`: a gradient with elevation and a pale glow around the sun.
pub fn sky(d: [f64; 3], sun: [f64; 3]) -> Rgb {
    let up = d[2].max(0.0);
    let base = mix(HORIZON, ZENITH, (up * 1.6).min(1.0).sqrt());
    let mut glow = dot(d, sun).max(0.0);
    for _ in 0..4 {
        glow *= glow;
    }
    mix(base, [1.0, 0.92, 0.8], 0.6 * glow)
}

/// Regolith at ground point (x, y) seen with a pixel `footprint` (metres), lit from unit
/// direction `sun`: reflectance, normal, and whether a pebble shades it. Broad light and dark
/// drifts, a mottle at tens of centimetres, sand grain, and scattered pebbles (low domes with
/// their own shading and short shadows) that fade out with distance.
pub fn ground(seed: u64, x: f64, y: f64, footprint: f64, sun: [f64; 3]) -> (Rgb, [f64; 3], bool) {
    let drift = fbm2(seed, x / 9.0, y / 9.0, 3, footprint / 9.0);
    let mottle = fbm2(seed ^ 1, x / 0.7, y / 0.7, 4, footprint / 0.7);
    let grain = fbm2(seed ^ 2, x / 0.05, y / 0.05, 2, footprint / 0.05);
    let c = soil_tint(drift);
    let brightness = 0.7 + 0.6 * drift + 0.45 * (mottle - 0.5) + 0.3 * (grain - 0.5);
    let c = scale(c, brightness);
    let up = [0.0, 0.0, 1.0];
    match pebble(seed, x, y, footprint, sun) {
        Pebble::Top {
            normal,
            tone,
            visibility,
        } => {
            let stone = scale([0.20, 0.13, 0.09], tone);
            (
                mix(c, stone, visibility),
                normalize(mix(up, normal, visibility)),
                true,
            )
        }
        Pebble::Shadow => (c, up, false),
        Pebble::None => (c, up, true),
    }
}

/// The regolith's colour before brightness at `drift` (its broad light and dark patches, in
/// [0, 1)): from red iron oxide to dusty brown.
fn soil_tint(drift: f64) -> Rgb {
    let red: Rgb = [0.42, 0.19, 0.085];
    let dusty: Rgb = [0.33, 0.20, 0.12];
    mix(red, dusty, (drift * 1.8 - 0.4).clamp(0.0, 1.0))
}

/// The regolith's mean reflectance around ground point (x, y): [`ground`]'s colour and
/// brightness of the broad drift there, without the finer mottle, grain and pebbles, which
/// average out over a rock-sized patch. A rock of this albedo is as bright and as red as the
/// soil it lies on.
pub fn soil(seed: u64, x: f64, y: f64) -> Rgb {
    let drift = fbm2(seed, x / 9.0, y / 9.0, 3, 0.0);
    scale(soil_tint(drift), 0.7 + 0.6 * drift)
}

/// Pebble spacing on the ground, metres (one candidate per cell of this size).
const PEBBLE_CELL: f64 = 0.1;

/// What a ground point has to do with the pebbles around it.
enum Pebble {
    /// On a pebble: its dome normal, its tone, and how much of it the pixel resolves.
    Top {
        normal: [f64; 3],
        tone: f64,
        visibility: f64,
    },
    /// In a pebble's shadow.
    Shadow,
    None,
}

/// The pebble at or shading (x, y). Pebbles thinner than a pixel of this `footprint` are not
/// drawn: they fade into the regolith texture.
fn pebble(seed: u64, x: f64, y: f64, footprint: f64, sun: [f64; 3]) -> Pebble {
    let visibility = ((0.5 * PEBBLE_CELL / footprint - 1.0) / 3.0).clamp(0.0, 1.0);
    if visibility <= 0.0 {
        return Pebble::None;
    }
    let (u, v) = (x / PEBBLE_CELL, y / PEBBLE_CELL);
    let (cu, cv) = (u.floor() as i64, v.floor() as i64);
    // Horizontal shadow length per unit of pebble height, toward the sun.
    let horizontal = sun[0].hypot(sun[1]).max(1e-12);
    let run = horizontal / sun[2].max(0.05);
    let toward = [sun[0] / horizontal, sun[1] / horizontal];
    // Cells whose pebble can hold or shade this point: the 3 × 3 around it (a pebble is at most
    // 0.4 cell across) and, under a low sun, those along the way to the sun as far as the
    // longest pebble shadow reaches (length 0.6 · 0.4 · run, half-width 0.8 · 0.4 cells).
    // Visited in the same order either way, so a high sun shades exactly as the 3 × 3 alone.
    let length = 0.24 * run;
    let reach = |k: usize, from: f64| {
        let far = from + length * toward[k];
        let low = (from.min(far) - 0.32).floor() as i64 - from.floor() as i64;
        let high = (from.max(far) + 0.32).floor() as i64 - from.floor() as i64;
        (low.min(-1), high.max(1))
    };
    let (u_cells, v_cells) = (reach(0, u), reach(1, v));
    let mut shaded = false;
    for dv in v_cells.0..=v_cells.1 {
        for du in u_cells.0..=u_cells.1 {
            let cell = [cu + du, cv + dv, 0];
            if cell_value(seed, cell, 0) > 0.12 {
                continue;
            }
            let radius = 0.12 + 0.28 * cell_value(seed, cell, 1);
            let ox = (cell[0] as f64 + cell_value(seed, cell, 2)) - u;
            let oy = (cell[1] as f64 + cell_value(seed, cell, 3)) - v;
            let d2 = (ox * ox + oy * oy) / (radius * radius);
            if d2 < 1.0 {
                // A low dome: flatter than a hemisphere, as half-sunk pebbles are.
                let normal = normalize([-ox / radius, -oy / radius, 1.5 * (1.0 - d2).sqrt()]);
                return Pebble::Top {
                    normal,
                    tone: 0.5 + cell_value(seed, cell, 4),
                    visibility,
                };
            }
            // Shadowed if the pebble's centre lies within 0.8 radius of the segment from
            // here toward the sun, as long as its height (≈ 0.6 radius) casts.
            let length = 0.6 * radius * run;
            let s = (ox * toward[0] + oy * toward[1]).clamp(0.0, length);
            let (ax, ay) = (ox - s * toward[0], oy - s * toward[1]);
            shaded |= visibility > 0.5 && ax * ax + ay * ay < 0.64 * radius * radius;
        }
    }
    if shaded {
        Pebble::Shadow
    } else {
        Pebble::None
    }
}

/// Reflectance and normal of `body`'s surface at world point `p` with geometric normal `n`,
/// fixed in the rock's own frame so that it looks the same from every station: the albedo
/// mottled and layered, dust settled on upward faces, and the normal broken into flat facets
/// (a Voronoi partition with a random tilt per cell) so that the rock reads as fractured stone
/// rather than a smooth ball.
pub fn rock(body: &Body, p: [f64; 3], n: [f64; 3]) -> (Rgb, [f64; 3]) {
    let k = 1.0 / body.size;
    let q = [
        (p[0] - body.origin[0]) * k,
        (p[1] - body.origin[1]) * k,
        (p[2] - body.origin[2]) * k,
    ];
    let seed = body.texture_seed;
    let mottle = fbm3(seed, q.map(|v| v * 5.0), 4);
    let layers = fbm3(seed ^ 5, [q[0] * 1.5, q[1] * 1.5, q[2] * 12.0], 2);
    let tone = 0.65 + 0.7 * mottle + 0.35 * (layers - 0.5);
    let facet = nearest_cell3(seed ^ 7, q.map(|v| v * 1.8));
    let tilt = [0, 1, 2].map(|i| cell_value(seed ^ 7, facet, 10 + i) - 0.5);
    let facet_tone = 0.85 + 0.3 * cell_value(seed ^ 7, facet, 13);
    let dust = ((n[2] - 0.6) * 2.0).clamp(0.0, 1.0) * 0.45;
    let albedo = mix(
        scale(body.albedo, tone * facet_tone),
        [0.40, 0.22, 0.11],
        dust,
    );
    let grit = [0.0, 1.0, 2.0].map(|o| fbm3(seed ^ 9, q.map(|v| v * 14.0 + o * 3.1), 2) - 0.5);
    let bumped = normalize([
        n[0] + 1.3 * tilt[0] + 0.35 * grit[0],
        n[1] + 1.3 * tilt[1] + 0.35 * grit[1],
        n[2] + 1.3 * tilt[2] + 0.35 * grit[2],
    ]);
    (albedo, bumped)
}

/// Radiance of a surface of reflectance `albedo` and normal `n`: Lambert sunlight when `lit`,
/// plus sky light weighted by how much sky the normal faces.
pub fn light(albedo: Rgb, n: [f64; 3], sun: [f64; 3], lit: bool) -> Rgb {
    let direct = if lit { dot(n, sun).max(0.0) } else { 0.0 };
    let sky = 0.5 + 0.5 * n[2];
    [
        albedo[0] * (SUN[0] * direct + AMBIENT[0] * sky),
        albedo[1] * (SUN[1] * direct + AMBIENT[1] * sky),
        albedo[2] * (SUN[2] * direct + AMBIENT[2] * sky),
    ]
}

/// Blends `c`, seen at `distance` metres, toward the horizon sky.
pub fn haze(c: Rgb, distance: f64, density: f64) -> Rgb {
    let keep = 1.0 / (1.0 + density * distance).powi(2);
    mix(HORIZON, c, keep)
}

/// 8-bit display value of a linear radiance.
pub fn encode(c: Rgb) -> [u8; 3] {
    c.map(|v| (v.clamp(0.0, 1.0).sqrt() * 255.0 + 0.5) as u8)
}
