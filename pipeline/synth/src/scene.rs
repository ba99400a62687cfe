//! The world prepared for ray casting: each rock as a bounding sphere over a run of
//! ellipsoids, plus the unit vector towards the sun.

use super::ellipsoid::{dot, Ellipsoid};
use super::world::World;

/// A rock ready for intersection tests.
pub(super) struct Body {
    /// What the `rock_id` image stores for it: id + 1.
    pub label: u32,
    /// Bounding sphere of all lumps.
    pub center: [f64; 3],
    pub radius: f64,
    /// This rock's lumps in [`Scene::lumps`].
    pub lumps: std::ops::Range<usize>,
    pub albedo: [f64; 3],
    pub texture_seed: u64,
    /// Ground position and size: the frame the surface texture is fixed in.
    pub origin: [f64; 3],
    pub size: f64,
}

pub(super) struct Scene {
    pub bodies: Vec<Body>,
    pub lumps: Vec<Ellipsoid>,
    pub sun: [f64; 3],
}

impl Scene {
    pub fn new(world: &World) -> Scene {
        let mut lumps = Vec::new();
        let bodies = world
            .rocks
            .iter()
            .map(|rock| {
                let start = lumps.len();
                let (px, py) = (rock.position.x, rock.position.y);
                lumps.extend(rock.lumps.iter().map(|l| {
                    Ellipsoid::new(
                        [
                            px + l.center[0],
                            py + l.center[1],
                            l.center[2] - rock.burial,
                        ],
                        l.radii,
                        l.yaw,
                    )
                }));
                let own = &lumps[start..];
                let mut low = [f64::INFINITY; 3];
                let mut high = [f64::NEG_INFINITY; 3];
                for e in own {
                    for k in 0..3 {
                        low[k] = low[k].min(e.center[k] - e.bound);
                        high[k] = high[k].max(e.center[k] + e.bound);
                    }
                }
                let center = [
                    0.5 * (low[0] + high[0]),
                    0.5 * (low[1] + high[1]),
                    0.5 * (low[2] + high[2]),
                ];
                let radius = own
                    .iter()
                    .map(|e| {
                        let d = [
                            e.center[0] - center[0],
                            e.center[1] - center[1],
                            e.center[2] - center[2],
                        ];
                        dot(d, d).sqrt() + e.bound
                    })
                    .fold(0.0, f64::max);
                Body {
                    label: rock.id + 1,
                    center,
                    radius,
                    lumps: start..lumps.len(),
                    albedo: rock.albedo.map(f64::from),
                    texture_seed: rock.texture_seed,
                    origin: [px, py, -rock.burial],
                    size: rock.size,
                }
            })
            .collect();
        let (ce, se) = (world.sun_elevation.cos(), world.sun_elevation.sin());
        Scene {
            bodies,
            lumps,
            sun: [
                ce * world.sun_azimuth.cos(),
                ce * world.sun_azimuth.sin(),
                se,
            ],
        }
    }

    /// Whether a ray meets `body`'s bounding sphere at some `t > 0`.
    pub fn may_hit(body: &Body, origin: [f64; 3], direction: [f64; 3]) -> bool {
        let o = [
            origin[0] - body.center[0],
            origin[1] - body.center[1],
            origin[2] - body.center[2],
        ];
        let a = dot(direction, direction);
        let b = dot(o, direction);
        let c = dot(o, o) - body.radius * body.radius;
        if c <= 0.0 {
            return true;
        }
        b < 0.0 && b * b >= a * c
    }

    /// Nearest lump of `body` hit beyond `min_t`, as (t, lump index).
    pub fn hit_body(
        &self,
        body: &Body,
        origin: [f64; 3],
        direction: [f64; 3],
        min_t: f64,
    ) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for i in body.lumps.clone() {
            if let Some(t) = self.lumps[i].hit(origin, direction, min_t) {
                if best.is_none_or(|(b, _)| t < b) {
                    best = Some((t, i));
                }
            }
        }
        best
    }
}
