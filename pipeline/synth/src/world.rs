//! The synthetic scene: a flat plain z = 0, irregular rocks made of ellipsoid lumps, the sun and
//! the haze, all drawn from one seed.

use qrm_core::geometry::Point;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};

/// An ellipsoid, relative to its rock's ground position (z up, metres), turned by `yaw`
/// (radians, counter-clockwise) about the vertical. Rocks are unions of these so that their
/// outlines are irregular and distinctive rather than balls.
#[derive(Clone, Debug, PartialEq)]
pub struct Lump {
    pub center: [f64; 3],
    pub radii: [f64; 3],
    pub yaw: f64,
}

/// One landmark rock.
#[derive(Clone, Debug, PartialEq)]
pub struct Rock {
    pub id: u32,
    /// Ground position (x, y), metres: the origin of the lumps' coordinates.
    pub position: Point,
    /// Characteristic radius, metres.
    pub size: f64,
    /// The rock is the union of these.
    pub lumps: Vec<Lump>,
    /// Base colour, 0..1 (linear).
    pub albedo: [f32; 3],
    /// Metres of the rock below the ground plane: every lump is shifted down by this much.
    pub burial: f64,
    /// Seed of the surface texture, so that each rock looks the same from every station.
    pub texture_seed: u64,
}

/// Rocks, lighting and atmosphere.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    pub rocks: Vec<Rock>,
    /// World azimuth (radians, counter-clockwise from +x) towards the sun.
    pub sun_azimuth: f64,
    /// Elevation of the sun above the horizon, radians.
    pub sun_elevation: f64,
    /// Seed of the regolith texture.
    pub seed: u64,
    /// Haze density per metre: a surface at distance `d` keeps `1 / (1 + haze·d)²` of its
    /// colour and takes the rest from the horizon sky.
    pub haze: f64,
}

impl World {
    /// Rocks at the given ground positions and sizes (ids 0..), shapes/colours/textures/burial
    /// drawn from `seed`; the sun is between 20° and 45° high so that shadows are long enough
    /// to see but the ground is still lit.
    pub fn generate(seed: u64, placements: &[(Point, f64)]) -> World {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let sun_azimuth = rng.random_range(0.0..TAU);
        let sun_elevation = rng.random_range(20.0f64..45.0).to_radians();
        let haze = rng.random_range(0.004..0.008);
        let ground_seed = rng.random();
        let rocks = placements
            .iter()
            .zip(0u32..)
            .map(|(&(position, size), id)| random_rock(id, position, size, &mut rng))
            .collect();
        World {
            rocks,
            sun_azimuth,
            sun_elevation,
            seed: ground_seed,
            haze,
        }
    }

    /// Top of the rock above the ground (metres), for truth files.
    ///
    /// # Panics
    /// If no rock has this id.
    pub fn rock_height(&self, id: u32) -> f64 {
        let rock = self.rock(id);
        rock.lumps
            .iter()
            .map(|l| l.center[2] + l.radii[2])
            .fold(f64::NEG_INFINITY, f64::max)
            - rock.burial
    }

    /// Radius (metres) of the smallest circle about the rock's position that holds its
    /// footprint on the ground plane (the lumps' cross-sections at z = 0), for truth files:
    /// the near edge of a rock meets the ground at its range minus about this much.
    ///
    /// # Panics
    /// If no rock has this id.
    pub fn contact_radius(&self, id: u32) -> f64 {
        let rock = self.rock(id);
        rock.lumps
            .iter()
            .filter_map(|l| {
                let z = (l.center[2] - rock.burial) / l.radii[2];
                (z.abs() < 1.0).then(|| {
                    l.center[0].hypot(l.center[1])
                        + l.radii[0].max(l.radii[1]) * (1.0 - z * z).sqrt()
                })
            })
            .fold(0.0, f64::max)
    }

    /// How far the rock's footprint on the ground plane reaches from its position in the
    /// horizontal unit direction `(dx, dy)`: the support function of the lumps' cross-sections
    /// at z = 0. Toward the camera this puts the near ground contact at `range − reach`
    /// (truth files); [`World::contact_radius`] is its maximum over directions, roughly.
    ///
    /// # Panics
    /// If no rock has this id.
    pub fn contact_reach(&self, id: u32, dx: f64, dy: f64) -> f64 {
        let rock = self.rock(id);
        rock.lumps
            .iter()
            .filter_map(|l| {
                let t = (l.center[2] - rock.burial) / l.radii[2];
                if t.abs() >= 1.0 {
                    return None;
                }
                let scale = (1.0 - t * t).sqrt();
                let (a, b) = (l.radii[0] * scale, l.radii[1] * scale);
                // The direction in the lump's frame (turned by −yaw).
                let (c, s) = (l.yaw.cos(), l.yaw.sin());
                let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
                Some((a * u).hypot(b * v) + l.center[0] * dx + l.center[1] * dy)
            })
            .fold(0.0, f64::max)
    }

    fn rock(&self, id: u32) -> &Rock {
        self.rocks
            .iter()
            .find(|r| r.id == id)
            .unwrap_or_else(|| panic!("no rock has id {id}"))
    }
}

/// A rock of about `size` radius: a flattened main lump resting on the ground and up to three
/// smaller lumps fused to it, sunk by 15–50 % of the main lump's height, in a Mars palette
/// from dark basalt grey to pale ochre.
fn random_rock(id: u32, position: Point, size: f64, rng: &mut ChaCha8Rng) -> Rock {
    let main_height = size * rng.random_range(0.3..0.8);
    let mut lumps = vec![Lump {
        center: [0.0, 0.0, main_height],
        radii: [
            size * rng.random_range(0.8..1.1),
            size * rng.random_range(0.6..1.0),
            main_height,
        ],
        yaw: rng.random_range(0.0..PI),
    }];
    for _ in 0..rng.random_range(0..=3) {
        let reach = size * rng.random_range(0.2..0.6);
        let angle = rng.random_range(0.0..TAU);
        let height = size * rng.random_range(0.25..0.6);
        lumps.push(Lump {
            center: [
                reach * angle.cos(),
                reach * angle.sin(),
                height * rng.random_range(0.5..1.1),
            ],
            radii: [
                size * rng.random_range(0.35..0.7),
                size * rng.random_range(0.3..0.6),
                height,
            ],
            yaw: rng.random_range(0.0..PI),
        });
    }
    let brightness = rng.random_range(0.5f32..1.3);
    let redness = rng.random_range(0.0f32..1.0);
    let albedo = [
        brightness * (0.20 + 0.16 * redness),
        brightness * (0.16 + 0.05 * redness),
        brightness * (0.13 + 0.01 * redness),
    ];
    Rock {
        id,
        position,
        size,
        lumps,
        albedo,
        burial: main_height * rng.random_range(0.15..0.5),
        texture_seed: rng.random(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generation_is_seeded_and_rocks_sit_in_the_ground() {
        let placements: Vec<(Point, f64)> = (0..20)
            .map(|i| (Point::new(f64::from(i), 2.0), 0.1 + 0.02 * f64::from(i)))
            .collect();
        let a = World::generate(7, &placements);
        assert_eq!(a, World::generate(7, &placements));
        assert_ne!(a, World::generate(8, &placements));
        for rock in &a.rocks {
            let h = a.rock_height(rock.id);
            assert!(
                h > 0.1 * rock.size && h < 2.0 * rock.size,
                "{h} {}",
                rock.size
            );
            let r = a.contact_radius(rock.id);
            assert!(
                r > 0.2 * rock.size && r < 2.0 * rock.size,
                "{r} {}",
                rock.size
            );
            assert!((1..=4).contains(&rock.lumps.len()));
        }
    }

    #[test]
    fn contact_radius_of_a_half_buried_ball_is_its_radius() {
        let mut w = World::generate(1, &[(Point::new(0.0, 0.0), 0.5)]);
        w.rocks[0].lumps = vec![Lump {
            center: [0.0, 0.0, 0.5],
            radii: [0.5; 3],
            yaw: 0.0,
        }];
        w.rocks[0].burial = 0.5;
        assert!((w.contact_radius(0) - 0.5).abs() < 1e-12);
        assert!((w.rock_height(0) - 0.5).abs() < 1e-12);
    }
}
