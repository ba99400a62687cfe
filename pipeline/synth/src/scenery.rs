//! How a scene may differ from its preset's own look: the sun's height, how much the rocks
//! stand out from the soil in colour, and how tightly they are packed. The defaults leave
//! every preset exactly as it always rendered; each field is a documented option of
//! `pipeline synth` and one of the `stress` preset's draws, so that detection can be tried on
//! scenes it was not tuned on (issue 13).

use crate::shade;
use crate::World;

/// Scene variation applied to a preset's layout and world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scenery {
    /// Elevation of the sun above the horizon, degrees, instead of the world's own draw
    /// (20°–45°). A low sun casts long shadows: a rock of height h throws one h / tan(elevation)
    /// long (7 h at 8°).
    pub sun_elevation_deg: Option<f64>,
    /// How far each rock's albedo lies from the soil's mean reflectance where it lies
    /// ([`shade::soil`]): `soil + k · (drawn − soil)` per channel. 1 keeps the drawn palette
    /// (dark basalt to pale ochre) untouched, 0 gives rocks the soil's colour and brightness,
    /// so that only shading, texture and shadows set them apart.
    pub rock_albedo_contrast: f64,
    /// Fraction (0–1) of the rocks gathered into dense clusters where each touches or
    /// overlaps a neighbour in footprint (`dataset::Preset::layout_clustered`); 0 keeps the
    /// preset's layout.
    pub cluster: f64,
}

impl Default for Scenery {
    fn default() -> Self {
        Scenery {
            sun_elevation_deg: None,
            rock_albedo_contrast: 1.0,
            cluster: 0.0,
        }
    }
}

impl Scenery {
    /// Whether this scenery leaves presets as they are.
    pub fn is_default(&self) -> bool {
        *self == Scenery::default()
    }

    /// Sets the sun and pulls the rock albedos towards the soil, as asked. Only what differs
    /// from the default is touched, so a default scenery leaves `world` bit for bit as drawn.
    pub fn apply(&self, world: &mut World) {
        if let Some(elevation) = self.sun_elevation_deg {
            world.sun_elevation = elevation.to_radians();
        }
        if self.rock_albedo_contrast != 1.0 {
            let k = self.rock_albedo_contrast;
            for rock in &mut world.rocks {
                let soil = shade::soil(world.seed, rock.position.x, rock.position.y);
                for (albedo, soil) in rock.albedo.iter_mut().zip(soil) {
                    *albedo = (soil + k * (f64::from(*albedo) - soil)) as f32;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use qrm_core::geometry::Point;

    fn world() -> World {
        let placements: Vec<(Point, f64)> = (0..12)
            .map(|i| (Point::new(2.0 * f64::from(i), -3.0), 0.3))
            .collect();
        World::generate(5, &placements)
    }

    #[test]
    fn the_default_scenery_changes_nothing() {
        let mut w = world();
        Scenery::default().apply(&mut w);
        assert_eq!(w, world());
    }

    #[test]
    fn the_sun_goes_where_asked() {
        let mut w = world();
        Scenery {
            sun_elevation_deg: Some(8.0),
            ..Scenery::default()
        }
        .apply(&mut w);
        assert!((w.sun_elevation - 8f64.to_radians()).abs() < 1e-15);
        assert_eq!(w.sun_azimuth, world().sun_azimuth);
        assert_eq!(w.rocks, world().rocks);
    }

    #[test]
    fn albedo_contrast_moves_rocks_to_the_soil_colour() {
        let drawn = world();
        let soil: Vec<[f64; 3]> = drawn
            .rocks
            .iter()
            .map(|r| shade::soil(drawn.seed, r.position.x, r.position.y))
            .collect();
        let distance = |w: &World| -> f64 {
            w.rocks
                .iter()
                .zip(&soil)
                .map(|(r, s)| {
                    (0..3)
                        .map(|c| (f64::from(r.albedo[c]) - s[c]).abs())
                        .sum::<f64>()
                })
                .sum()
        };
        let with = |k: f64| {
            let mut w = world();
            Scenery {
                rock_albedo_contrast: k,
                ..Scenery::default()
            }
            .apply(&mut w);
            w
        };
        let (full, half, none) = (distance(&drawn), distance(&with(0.5)), distance(&with(0.0)));
        assert!((half - 0.5 * full).abs() < 1e-5 * full, "{half} {full}");
        assert!(none < 1e-5 * full, "{none}");
        // Shapes and positions stay.
        for (a, b) in with(0.0).rocks.iter().zip(&drawn.rocks) {
            assert_eq!(
                (&a.lumps, a.position, a.burial),
                (&b.lumps, b.position, b.burial)
            );
        }
    }
}
