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
                p.appearance = weighted_mean(&p.appearance, p.sightings, &appearance, 1);
                p.width = joined(p.width, width);
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

    /// Folds landmark `duplicate`'s profile into `landmark`'s (one rock found to have two
    /// landmarks): the looks averaged over both landmarks' sightings, the widths as
    /// [`Gallery::observe`] joins them. Nothing changes unless both have a profile.
    pub fn merge(&mut self, landmark: LandmarkId, duplicate: LandmarkId) {
        let Some(gone) = self.profile(duplicate).cloned() else {
            return;
        };
        let Some(kept) = self.profiles.iter_mut().find(|p| p.landmark == landmark) else {
            return;
        };
        kept.appearance = weighted_mean(
            &kept.appearance,
            kept.sightings,
            &gone.appearance,
            gone.sightings,
        );
        kept.width = joined(kept.width, gone.width);
        kept.sightings += gone.sightings;
        self.profiles.retain(|p| p.landmark != duplicate);
    }
}

/// The mean of descriptors `a`, over `n` sightings, and `b`, over `m`.
fn weighted_mean(a: &Appearance, n: u32, b: &Appearance, m: u32) -> Appearance {
    let (n, m) = (n as f32, m as f32);
    let mix = |x: f32, y: f32| (x * n + y * m) / (n + m).max(1.0);
    Appearance {
        colour: std::array::from_fn(|k| mix(a.colour[k], b.colour[k])),
        brightness: mix(a.brightness, b.brightness),
        texture: mix(a.texture, b.texture),
        dark_fraction: mix(a.dark_fraction, b.dark_fraction),
    }
}

/// Two bounds on one rock's width joined: intersected, or, if they do not meet, their hull
/// (the evidence disagrees and neither side is trusted over the other).
fn joined(a: Option<RangeInterval>, b: Option<RangeInterval>) -> Option<RangeInterval> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.intersection(b).unwrap_or_else(|| a.hull(b))),
        (a, b) => a.or(b),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn looks(brightness: f32) -> Appearance {
        Appearance {
            colour: [0.4, 0.3, 0.3],
            brightness,
            texture: 0.1,
            dark_fraction: 0.2,
        }
    }

    #[test]
    fn a_merged_duplicate_joins_its_rocks_looks_by_sightings() {
        let mut gallery = Gallery::default();
        for _ in 0..3 {
            gallery.observe(1, looks(1.0), Some(RangeInterval::new(0.4, 0.8)));
        }
        gallery.observe(7, looks(2.0), Some(RangeInterval::new(0.6, 1.0)));
        gallery.merge(1, 7);
        assert!(gallery.profile(7).is_none());
        let kept = gallery.profile(1).expect("the older landmark stays");
        assert_eq!(kept.sightings, 4);
        assert!((kept.appearance.brightness - 1.25).abs() < 1e-6);
        assert_eq!(kept.width, Some(RangeInterval::new(0.6, 0.8)));
    }
}
