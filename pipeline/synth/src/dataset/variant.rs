//! The `stress` preset family (issue 13): a renderer that stops the detector overfitting our
//! own look. Each seed draws a layout and a full set of scene, camera and calibration
//! variations; every draw is one of `pipeline synth`'s documented options, so any member can
//! be reproduced, or varied one option at a time, with the layout preset and those options.

use super::layout::Preset;
use crate::{Capture, Encoding, Scenery};
use qrm_vision::calib::{AzimuthAxis, Calibration, CalibrationError, ColumnDirection};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Everything a dataset's look depends on besides its layout's seed and counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variant {
    /// The preset whose rock field and imaging points are used.
    pub layout: Preset,
    pub scenery: Scenery,
    pub capture: Capture,
    pub encoding: Encoding,
    /// Which way columns run and where column 0 starts (the calibration's `[azimuth]`).
    pub column_axis: AzimuthAxis,
    /// Image size (and focal length) relative to the calibration's.
    pub scale: f64,
}

/// The image scales the `stress` preset draws from: each gives whole pixel sizes from the
/// default 4096 × 768 camera.
const SCALES: [f64; 5] = [0.5, 0.625, 0.75, 0.875, 1.0];

impl Variant {
    /// The `stress` member for `seed` (the same seed, the same member). About half of the
    /// draws leave an effect off, so that members differ in which effects they combine:
    ///
    /// | draw | values |
    /// |---|---|
    /// | layout | `marsyard` (2/3) or `random` |
    /// | sun elevation | 5°–12° (low, 40 %) or 12°–60° |
    /// | rock albedo contrast | 0.1–1 |
    /// | cluster | 0 (half) or 0.2–0.6 |
    /// | exposure | 0 (half) or −1.2…0.8 EV |
    /// | gamma | 1 (half) or 0.6–2.4 |
    /// | vignetting | 0 (half) or 0.1–0.45 |
    /// | blur | 0 (half) or 0.3–1.2 px |
    /// | noise | 0 (half) or 1–6 levels |
    /// | grayscale | 30 % |
    /// | JPEG | 30 %, quality 80–95 |
    /// | column direction, column 0 | either direction (half each), whole degrees 0–359 |
    /// | scale | 0.5, 0.625, 0.75, 0.875 or 1 |
    ///
    /// Values are rounded to the digits the command line prints, so that passing them as
    /// options renders the same member.
    pub fn stress(seed: u64) -> Variant {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x57e5_5f00);
        let layout = if rng.random_bool(1.0 / 3.0) {
            Preset::Random
        } else {
            Preset::Marsyard
        };
        let sun = if rng.random_bool(0.4) {
            rng.random_range(5.0..12.0)
        } else {
            rng.random_range(12.0..60.0)
        };
        let scenery = Scenery {
            sun_elevation_deg: Some(decimals(sun, 1)),
            rock_albedo_contrast: decimals(rng.random_range(0.1..1.0), 2),
            cluster: sometimes(&mut rng, 0.0, 0.2..0.6, 2),
        };
        let capture = Capture {
            exposure_ev: sometimes(&mut rng, 0.0, -1.2..0.8, 2),
            gamma: sometimes(&mut rng, 1.0, 0.6..2.4, 2),
            vignetting: sometimes(&mut rng, 0.0, 0.1..0.45, 2),
            blur_px: sometimes(&mut rng, 0.0, 0.3..1.2, 2) as f32,
            noise: sometimes(&mut rng, 0.0, 1.0..6.0, 1),
        };
        let encoding = Encoding {
            grayscale: rng.random_bool(0.3),
            jpeg_quality: rng.random_bool(0.3).then(|| rng.random_range(80..=95)),
        };
        let column_axis = AzimuthAxis {
            direction: if rng.random_bool(0.5) {
                ColumnDirection::Clockwise
            } else {
                ColumnDirection::CounterClockwise
            },
            column0_deg: f64::from(rng.random_range(0..360u32)),
        };
        Variant {
            layout,
            scenery,
            capture,
            encoding,
            column_axis,
            scale: SCALES[rng.random_range(0..SCALES.len())],
        }
    }

    /// The camera of this variant: `base` with this column axis, scaled.
    pub fn calibration(&self, base: &Calibration) -> Result<Calibration, CalibrationError> {
        let mut calib = *base;
        calib.azimuth = self.column_axis;
        calib.scaled(self.scale)
    }
}

/// `off` half the time, otherwise a value drawn from `range` and rounded to `places` decimals.
fn sometimes(rng: &mut ChaCha8Rng, off: f64, range: std::ops::Range<f64>, places: i32) -> f64 {
    if rng.random_bool(0.5) {
        decimals(rng.random_range(range), places)
    } else {
        off
    }
}

/// `v` rounded to `places` decimals: the double nearest that decimal, so it prints as written.
fn decimals(v: f64, places: i32) -> f64 {
    let factor = 10f64.powi(places);
    (v * factor).round() / factor
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn members_follow_the_seed_and_differ_across_seeds() {
        let members: Vec<Variant> = (0..40).map(Variant::stress).collect();
        assert_eq!(members[7], Variant::stress(7));
        for (i, a) in members.iter().enumerate() {
            assert!(members[i + 1..].iter().all(|b| a != b), "seed {i} repeats");
        }
        let count = |f: &dyn Fn(&Variant) -> bool| members.iter().filter(|v| f(v)).count();
        // Each effect is on in some members and off in others.
        for (name, on) in [
            ("random layout", count(&|v| v.layout == Preset::Random)),
            (
                "low sun",
                count(&|v| v.scenery.sun_elevation_deg.is_some_and(|e| e < 12.0)),
            ),
            ("cluster", count(&|v| v.scenery.cluster > 0.0)),
            ("gamma", count(&|v| v.capture.gamma != 1.0)),
            ("noise", count(&|v| v.capture.noise > 0.0)),
            ("blur", count(&|v| v.capture.blur_px > 0.0)),
            ("grayscale", count(&|v| v.encoding.grayscale)),
            ("jpeg", count(&|v| v.encoding.jpeg_quality.is_some())),
            (
                "counter-clockwise",
                count(&|v| v.column_axis.direction == ColumnDirection::CounterClockwise),
            ),
            ("reduced scale", count(&|v| v.scale < 1.0)),
        ] {
            assert!((3..=37).contains(&on), "{name}: {on} of 40");
        }
        for v in &members {
            assert!(v
                .encoding
                .jpeg_quality
                .is_none_or(|q| (80..=95).contains(&q)));
            assert!((0.1..=1.0).contains(&v.scenery.rock_albedo_contrast));
            assert!(matches!(v.layout, Preset::Marsyard | Preset::Random));
        }
    }
}
