//! Saving renders as image files, encoded as a camera and an archive would deliver them, and
//! shrinking them for previews.

use super::render::Render;
use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use std::io::BufWriter;
use std::path::Path;

/// How a dataset's panoramas are encoded: a navigation camera is often monochrome, and
/// archives often hold JPEG.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Encoding {
    /// 8-bit luminance instead of RGB (Rec. 709 weights, as `image` converts).
    pub grayscale: bool,
    /// JPEG at this quality (1–100) instead of PNG.
    pub jpeg_quality: Option<u8>,
}

impl Encoding {
    /// The file extension of this encoding.
    pub fn extension(&self) -> &'static str {
        if self.jpeg_quality.is_some() {
            "jpg"
        } else {
            "png"
        }
    }
}

impl Render {
    /// Writes the colour image with `encoding` (the extension of `path` is not consulted).
    pub fn save(&self, path: &Path, encoding: Encoding) -> Result<(), image::ImageError> {
        let luma;
        let (bytes, colour): (&[u8], ExtendedColorType) = if encoding.grayscale {
            // `DynamicImage::into_luma8`'s conversion (Rec. 709 weights), on a copy: the
            // colour path below writes the render's pixels as they are.
            let rgb = image::RgbImage::from_raw(self.width, self.height, self.rgb.clone())
                .expect("a render holds width × height RGB pixels");
            luma = image::DynamicImage::ImageRgb8(rgb).into_luma8();
            (luma.as_raw(), ExtendedColorType::L8)
        } else {
            (&self.rgb, ExtendedColorType::Rgb8)
        };
        // Created through the interrupt-safe creation: `path` is usually a temporary file.
        let file = BufWriter::new(qrm_atomic_file::create_file(path)?);
        match encoding.jpeg_quality {
            Some(quality) => JpegEncoder::new_with_quality(file, quality).write_image(
                bytes,
                self.width,
                self.height,
                colour,
            ),
            None => PngEncoder::new(file).write_image(bytes, self.width, self.height, colour),
        }
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
