//! What a real camera does to the rendered light before it reaches a file: exposure, a tone
//! curve, vignetting, optical blur and sensor noise. All off by default (the renderer's own
//! images); each is a documented option of `pipeline synth`, so that the detector can be tried
//! on images that do not look like ours.

use crate::Render;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::borrow::Cow;

/// Camera effects applied to a render, in the order of the fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capture {
    /// Exposure change in stops: every channel is scaled by `2^exposure_ev`, then clipped.
    pub exposure_ev: f64,
    /// Tone curve: a channel value `v` in [0, 1] becomes `v^(1/gamma)` (1 = linear).
    pub gamma: f64,
    /// Relative light loss at the top and bottom edges of the panorama, falling off with the
    /// square of the distance from the middle row (0 = none).
    pub vignetting: f64,
    /// Standard deviation of a Gaussian blur, pixels (0 = sharp; the image's edges, the seam
    /// included, are clamped rather than wrapped).
    pub blur_px: f32,
    /// Standard deviation of additive Gaussian sensor noise, 8-bit levels (0 = none).
    pub noise: f64,
}

impl Default for Capture {
    fn default() -> Self {
        Capture {
            exposure_ev: 0.0,
            gamma: 1.0,
            vignetting: 0.0,
            blur_px: 0.0,
            noise: 0.0,
        }
    }
}

impl Capture {
    /// Whether this capture leaves renders as they are.
    pub fn is_identity(&self) -> bool {
        *self == Capture::default()
    }

    /// The render as this camera records it; `seed` draws the noise (the same seed gives the
    /// same image). The rock ids are the render's: effects change pixels, not the scene. The
    /// default capture borrows the render as it is.
    pub fn apply<'a>(&self, render: &'a Render, seed: u64) -> Cow<'a, Render> {
        if self.is_identity() {
            return Cow::Borrowed(render);
        }
        let (w, h) = (render.width as usize, render.height as usize);
        let gain = 2f64.powf(self.exposure_ev);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut rgb: Vec<u8> = render
            .rgb
            .chunks_exact(3 * w)
            .enumerate()
            .flat_map(|(row, pixels)| {
                let offset = (row as f64 + 0.5) / h as f64 - 0.5;
                let light = gain * (1.0 - self.vignetting * 4.0 * offset * offset);
                pixels
                    .iter()
                    .map(move |&v| {
                        let linear = (f64::from(v) / 255.0 * light).clamp(0.0, 1.0);
                        linear.powf(1.0 / self.gamma) * 255.0
                    })
                    .collect::<Vec<f64>>()
            })
            .map(|v| quantise(v + self.noise * gaussian(&mut rng)))
            .collect();
        if self.blur_px > 0.0 {
            let image = image::RgbImage::from_raw(render.width, render.height, rgb)
                .expect("width × height RGB pixels");
            rgb = image::imageops::blur(&image, self.blur_px).into_raw();
        }
        Cow::Owned(Render {
            width: render.width,
            height: render.height,
            rgb,
            rock_id: render.rock_id.clone(),
        })
    }
}

fn quantise(v: f64) -> u8 {
    v.round().clamp(0.0, 255.0) as u8
}

/// A standard normal draw (Box–Muller).
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u: f64 = rng.random_range(f64::MIN_POSITIVE..1.0);
    let v: f64 = rng.random();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(level: u8, width: u32, height: u32) -> Render {
        Render {
            width,
            height,
            rgb: vec![level; (3 * width * height) as usize],
            rock_id: vec![0; (width * height) as usize],
        }
    }

    fn mean(r: &Render) -> f64 {
        r.rgb.iter().map(|&v| f64::from(v)).sum::<f64>() / r.rgb.len() as f64
    }

    #[test]
    fn the_default_capture_changes_nothing() {
        let render = grey(100, 8, 4);
        assert!(matches!(
            Capture::default().apply(&render, 1),
            Cow::Borrowed(r) if *r == render
        ));
    }

    #[test]
    fn exposure_gamma_and_vignetting_move_levels_as_documented() {
        let render = grey(100, 16, 16);
        let darker = Capture {
            exposure_ev: -1.0,
            ..Capture::default()
        };
        assert_eq!(mean(&darker.apply(&render, 1)), 50.0);
        let curved = Capture {
            gamma: 2.0,
            ..Capture::default()
        };
        let expected = (100.0f64 / 255.0).sqrt() * 255.0;
        assert_eq!(mean(&curved.apply(&render, 1)), expected.round());
        let vignetted = Capture {
            vignetting: 0.5,
            ..Capture::default()
        }
        .apply(&render, 1);
        let row = |y: usize| vignetted.rgb[3 * 16 * y];
        assert!(
            row(0) < row(8) && row(15) < row(8),
            "{} {} {}",
            row(0),
            row(8),
            row(15)
        );
        assert!(row(8) >= 99);
    }

    #[test]
    fn noise_has_its_spread_and_follows_the_seed() {
        let render = grey(128, 64, 64);
        let noisy = Capture {
            noise: 4.0,
            ..Capture::default()
        };
        let a = noisy.apply(&render, 7);
        assert_eq!(a, noisy.apply(&render, 7));
        assert_ne!(a, noisy.apply(&render, 8));
        let spread = (a
            .rgb
            .iter()
            .map(|&v| (f64::from(v) - 128.0).powi(2))
            .sum::<f64>()
            / a.rgb.len() as f64)
            .sqrt();
        assert!((spread - 4.0).abs() < 0.3, "{spread}");
        let blurred = Capture {
            noise: 4.0,
            blur_px: 1.5,
            ..Capture::default()
        }
        .apply(&render, 7);
        assert!(
            blurred.rgb.iter().map(|&v| v.abs_diff(128)).max()
                < a.rgb.iter().map(|&v| v.abs_diff(128)).max()
        );
        assert_eq!(blurred.rock_id, render.rock_id);
    }
}
