//! What the run remembers of each map landmark's looks: a running mean of its appearance
//! descriptor and the bounds on its physical width, used to propose association candidates
//! and, for the apparent-size cue, to bound its range.

use crate::detection::Appearance;
use crate::ranging::RangeInterval;
use qrm_core::map::LandmarkId;
use serde::{Deserialize, Serialize};

/// Scales of the descriptor's components: a difference of one scale counts 1 in the distance.
/// Chromaticity is the most viewpoint-stable; brightness and shading change with the side of
/// the rock the sun lights.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AppearanceScales {
    pub chromaticity: f64,
    pub log_brightness: f64,
    pub texture: f64,
    pub dark_fraction: f64,
}

impl Default for AppearanceScales {
    fn default() -> AppearanceScales {
        AppearanceScales {
            chromaticity: 0.01,
            log_brightness: 0.25,
            texture: 0.06,
            dark_fraction: 0.2,
        }
    }
}

/// One landmark's remembered looks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    pub landmark: LandmarkId,
    pub appearance: Appearance,
    /// Physical width, intersected over the stations that bounded it.
    pub width: Option<RangeInterval>,
    pub sightings: u32,
}

/// The profiles of every landmark in the map.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Gallery {
    pub profiles: Vec<Profile>,
}

impl Gallery {
    pub fn is_empty(&self) -> bool {
        self.profiles.is_empty()
    }

    pub fn profile(&self, landmark: LandmarkId) -> Option<&Profile> {
        self.profiles.iter().find(|p| p.landmark == landmark)
    }

    /// Records a sighting of `landmark` (a new one is added): the appearance joins the running
    /// mean, and the width interval is intersected (or, if the intervals do not meet, replaced
    /// by their hull: the evidence disagrees and neither side is trusted over the other).
    pub fn observe(
        &mut self,
        landmark: LandmarkId,
        appearance: Appearance,
        width: Option<RangeInterval>,
    ) {
        match self.profiles.iter_mut().find(|p| p.landmark == landmark) {
            Some(p) => {
                let n = p.sightings as f32;
                let mix = |old: f32, new: f32| (old * n + new) / (n + 1.0);
                p.appearance = Appearance {
                    colour: std::array::from_fn(|k| {
                        mix(p.appearance.colour[k], appearance.colour[k])
                    }),
                    brightness: mix(p.appearance.brightness, appearance.brightness),
                    texture: mix(p.appearance.texture, appearance.texture),
                    dark_fraction: mix(p.appearance.dark_fraction, appearance.dark_fraction),
                };
                p.width = match (p.width, width) {
                    (Some(a), Some(b)) => Some(a.intersection(b).unwrap_or_else(|| a.hull(b))),
                    (a, b) => a.or(b),
                };
                p.sightings += 1;
            }
            None => self.profiles.push(Profile {
                landmark,
                appearance,
                width,
                sightings: 1,
            }),
        }
    }
}

/// Descriptor distance in units of the scales.
pub fn distance(a: &Appearance, b: &Appearance, scales: &AppearanceScales) -> f64 {
    let chroma = chromaticity_distance(a, b, scales).powi(2);
    let log_ratio = (f64::from(a.brightness.max(1e-3)) / f64::from(b.brightness.max(1e-3))).ln();
    let brightness = (log_ratio / scales.log_brightness).powi(2);
    let texture = ((f64::from(a.texture) - f64::from(b.texture)) / scales.texture).powi(2);
    let dark =
        ((f64::from(a.dark_fraction) - f64::from(b.dark_fraction)) / scales.dark_fraction).powi(2);
    (chroma + brightness + texture + dark).sqrt()
}

/// The chromaticity part of [`distance`] alone: what stays of a rock's looks when it is seen
/// from another side, under another light, or at another scale (brightness, texture and the
/// shaded share change with all three).
pub fn chromaticity_distance(a: &Appearance, b: &Appearance, scales: &AppearanceScales) -> f64 {
    (0..3)
        .map(|k| (f64::from(a.colour[k]) - f64::from(b.colour[k])).powi(2))
        .sum::<f64>()
        .sqrt()
        / scales.chromaticity
}
