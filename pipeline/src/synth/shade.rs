//! Colours: the butterscotch sky, the regolith, rock surfaces, sunlight and haze.
//!
//! Colours are linear reflectances and radiances; the image stores their square root (a gamma
//! of 2, close to sRGB), because `sqrt` is exactly rounded everywhere while `powf` is not.

use super::ellipsoid::{dot, normalize};
use super::noise::{fbm2, fbm3, value2};
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

/// Regolith reflectance at ground point (x, y) seen with a pixel `footprint` (metres): broad
/// light and dark drifts, a mottle at tens of centimetres and sand grain with scattered pebbles
/// that fade out with distance.
pub fn ground(seed: u64, x: f64, y: f64, footprint: f64) -> Rgb {
    let drift = fbm2(seed, x / 9.0, y / 9.0, 3, footprint / 9.0);
    let mottle = fbm2(seed ^ 1, x / 0.7, y / 0.7, 4, footprint / 0.7);
    let grain = fbm2(seed ^ 2, x / 0.05, y / 0.05, 2, footprint / 0.05);
    let red: Rgb = [0.42, 0.19, 0.085];
    let dusty: Rgb = [0.33, 0.20, 0.12];
    let mut c = mix(red, dusty, (drift * 1.8 - 0.4).clamp(0.0, 1.0));
    let brightness = 0.7 + 0.6 * drift + 0.45 * (mottle - 0.5) + 0.3 * (grain - 0.5);
    c = scale(c, brightness);
    // Pebbles: dark specks where a fine noise peaks, only where a pixel can resolve them.
    let near = (0.04 / footprint - 1.0).clamp(0.0, 1.0);
    if near > 0.0 {
        let speck = value2(seed ^ 3, x / 0.035, y / 0.035);
        if speck > 0.86 {
            c = scale(
                c,
                1.0 - near * 0.55 * ((speck - 0.86) / 0.14).min(1.0).sqrt(),
            );
        }
    }
    c
}

/// Reflectance and bumped normal of `body`'s surface at world point `p` with geometric normal
/// `n`: the rock's albedo mottled and veined in the rock's own frame, so that it looks the same
/// from every station.
pub fn rock(body: &Body, p: [f64; 3], n: [f64; 3]) -> (Rgb, [f64; 3]) {
    let k = 6.0 / body.size;
    let q = [
        (p[0] - body.origin[0]) * k,
        (p[1] - body.origin[1]) * k,
        (p[2] - body.origin[2]) * k,
    ];
    let seed = body.texture_seed;
    let mottle = fbm3(seed, q, 4);
    let layers = fbm3(seed ^ 5, [q[0] * 0.3, q[1] * 0.3, q[2] * 2.5], 2);
    let tone = 0.65 + 0.7 * mottle + 0.35 * (layers - 0.5);
    let dust = ((n[2] - 0.55) * 2.0).clamp(0.0, 1.0) * 0.5;
    let albedo = mix(scale(body.albedo, tone), [0.40, 0.22, 0.11], dust);
    // Bump: tilt the normal down the gradient of a noise height field.
    let h = 1.0 / 0.35;
    let bump = |d: [f64; 3]| fbm3(seed ^ 9, [q[0] + d[0], q[1] + d[1], q[2] + d[2]], 3);
    let b0 = bump([0.0; 3]);
    let g = [
        bump([0.35, 0.0, 0.0]) - b0,
        bump([0.0, 0.35, 0.0]) - b0,
        bump([0.0, 0.0, 0.35]) - b0,
    ];
    let strength = 0.9 * h;
    let tilted = normalize([
        n[0] - strength * g[0],
        n[1] - strength * g[1],
        n[2] - strength * g[2],
    ]);
    (albedo, tilted)
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
