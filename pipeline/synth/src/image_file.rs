//! Saving renders as PNG files and shrinking them for previews.

use super::render::Render;
use std::path::Path;

impl Render {
    /// Writes the colour image as an 8-bit RGB PNG.
    pub fn save_png(&self, path: &Path) -> Result<(), image::ImageError> {
        image::save_buffer(
            path,
            &self.rgb,
            self.width,
            self.height,
            image::ExtendedColorType::Rgb8,
        )
    }

    /// The image shrunk by an integer `factor` (box filter over whole blocks; a partial block at
    /// the right or bottom edge is dropped); `rock_id` takes each block's centre pixel.
    ///
    /// # Panics
    /// If `factor` is 0 or larger than the image.
    pub fn downscale(&self, factor: u32) -> Render {
        assert!(
            factor >= 1 && factor <= self.width && factor <= self.height,
            "bad downscale factor {factor}"
        );
        let (w, h) = (self.width / factor, self.height / factor);
        let f = factor as usize;
        let mut rgb = Vec::with_capacity((w * h * 3) as usize);
        let mut rock_id = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            for x in 0..w as usize {
                let mut sum = [0u32; 3];
                for yy in y * f..(y + 1) * f {
                    for xx in x * f..(x + 1) * f {
                        let i = 3 * (yy * self.width as usize + xx);
                        for (total, &v) in sum.iter_mut().zip(&self.rgb[i..i + 3]) {
                            *total += u32::from(v);
                        }
                    }
                }
                let n = (f * f) as u32;
                rgb.extend(sum.map(|s| ((s + n / 2) / n) as u8));
                rock_id.push(self.rock_id[(y * f + f / 2) * self.width as usize + x * f + f / 2]);
            }
        }
        Render {
            width: w,
            height: h,
            rgb,
            rock_id,
        }
    }
}
