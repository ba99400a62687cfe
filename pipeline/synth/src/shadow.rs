//! Cast shadows: whether the sun is blocked by a rock, seen from a point on the ground or on a
//! rock.
//!
//! Ground points are the bulk of every image, so they look up the rocks that can shade them in
//! a grid: a rock's bounding sphere shades only ground inside the capsule swept by its
//! horizontal disc from the heights it spans down the sun's rays.

use super::ellipsoid::dot;
use super::scene::Scene;

/// Offset (metres) along the surface normal before casting a shadow ray, so that a surface
/// does not shade itself through rounding.
const LIFT: f64 = 1e-4;

pub(super) struct Shadows {
    /// Lower-left corner of the grid, cell size and cell counts.
    x0: f64,
    y0: f64,
    cell: f64,
    nx: usize,
    ny: usize,
    /// Bodies that may shade cell `k`: `casters[starts[k]..starts[k + 1]]`.
    starts: Vec<u32>,
    casters: Vec<u32>,
}

/// A 2-D segment with a radius.
struct Capsule {
    a: [f64; 2],
    b: [f64; 2],
    radius: f64,
}

impl Capsule {
    fn distance(&self, p: [f64; 2]) -> f64 {
        let ab = [self.b[0] - self.a[0], self.b[1] - self.a[1]];
        let ap = [p[0] - self.a[0], p[1] - self.a[1]];
        let len2 = ab[0] * ab[0] + ab[1] * ab[1];
        let s = if len2 > 0.0 {
            ((ap[0] * ab[0] + ap[1] * ab[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (ap[0] - s * ab[0]).hypot(ap[1] - s * ab[1])
    }
}

impl Shadows {
    pub fn new(scene: &Scene) -> Shadows {
        let sun = scene.sun;
        let horizontal = sun[0].hypot(sun[1]).max(1e-12);
        // Horizontal run of a sun ray per metre of rise, and its direction.
        let run = horizontal / sun[2].max(1e-3);
        let toward = [sun[0] / horizontal, sun[1] / horizontal];
        let capsules: Vec<Capsule> = scene
            .bodies
            .iter()
            .map(|b| {
                let low = (b.center[2] - b.radius).max(0.0) * run;
                let high = (b.center[2] + b.radius).max(0.0) * run;
                Capsule {
                    a: [b.center[0] - toward[0] * low, b.center[1] - toward[1] * low],
                    b: [
                        b.center[0] - toward[0] * high,
                        b.center[1] - toward[1] * high,
                    ],
                    radius: b.radius,
                }
            })
            .collect();
        let mut low = [f64::INFINITY; 2];
        let mut high = [f64::NEG_INFINITY; 2];
        for c in &capsules {
            for k in 0..2 {
                low[k] = low[k].min(c.a[k].min(c.b[k]) - c.radius);
                high[k] = high[k].max(c.a[k].max(c.b[k]) + c.radius);
            }
        }
        if capsules.is_empty() {
            low = [0.0; 2];
            high = [0.0; 2];
        }
        let extent = (high[0] - low[0]).max(high[1] - low[1]);
        let cell = (extent / 1024.0).max(0.25);
        let nx = ((high[0] - low[0]) / cell).ceil() as usize + 1;
        let ny = ((high[1] - low[1]) / cell).ceil() as usize + 1;
        let half_diagonal = cell * std::f64::consts::FRAC_1_SQRT_2;
        let mut lists: Vec<(usize, u32)> = Vec::new();
        for (body, c) in capsules.iter().enumerate() {
            let cells = |k: usize, v: f64| ((v - low[k]) / cell).floor().max(0.0) as usize;
            let (i0, i1) = (
                cells(0, c.a[0].min(c.b[0]) - c.radius),
                cells(0, c.a[0].max(c.b[0]) + c.radius).min(nx - 1),
            );
            let (j0, j1) = (
                cells(1, c.a[1].min(c.b[1]) - c.radius),
                cells(1, c.a[1].max(c.b[1]) + c.radius).min(ny - 1),
            );
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let middle = [
                        low[0] + (i as f64 + 0.5) * cell,
                        low[1] + (j as f64 + 0.5) * cell,
                    ];
                    if c.distance(middle) <= c.radius + half_diagonal {
                        lists.push((j * nx + i, body as u32));
                    }
                }
            }
        }
        lists.sort_unstable();
        let mut starts = vec![0u32; nx * ny + 1];
        for &(k, _) in &lists {
            starts[k + 1] += 1;
        }
        for k in 0..nx * ny {
            starts[k + 1] += starts[k];
        }
        Shadows {
            x0: low[0],
            y0: low[1],
            cell,
            nx,
            ny,
            starts,
            casters: lists.into_iter().map(|(_, b)| b).collect(),
        }
    }

    /// Whether the ground point (x, y, 0) sees the sun.
    pub fn ground_lit(&self, scene: &Scene, x: f64, y: f64) -> bool {
        let (fx, fy) = ((x - self.x0) / self.cell, (y - self.y0) / self.cell);
        if fx < 0.0 || fy < 0.0 || fx >= self.nx as f64 || fy >= self.ny as f64 {
            return true;
        }
        let k = fy as usize * self.nx + fx as usize;
        let range = self.starts[k] as usize..self.starts[k + 1] as usize;
        let origin = [x, y, LIFT];
        !self.casters[range].iter().any(|&b| {
            let body = &scene.bodies[b as usize];
            Scene::may_hit(body, origin, scene.sun)
                && scene.hit_body(body, origin, scene.sun, 0.0).is_some()
        })
    }

    /// Whether the rock surface point `p` with outward normal `normal` sees the sun (tested
    /// against every rock, its own included: lumps shade each other).
    pub fn surface_lit(scene: &Scene, p: [f64; 3], normal: [f64; 3]) -> bool {
        if dot(normal, scene.sun) <= 0.0 {
            return false;
        }
        let origin = [
            p[0] + LIFT * normal[0],
            p[1] + LIFT * normal[1],
            p[2] + LIFT * normal[2],
        ];
        !scene.bodies.iter().any(|body| {
            Scene::may_hit(body, origin, scene.sun)
                && scene.hit_body(body, origin, scene.sun, 0.0).is_some()
        })
    }
}
