//! How noisy a panorama's chroma is, for choosing the channels that tell rocks from the ground.

/// Rows of the band that the estimate samples, at most: tens of thousands of pixel pairs
/// estimate a median to a fraction of a percent, and every row of a full-resolution band took a
/// quarter of a detection's time.
const SAMPLED_ROWS: u32 = 64;

/// The standard deviation of one pixel's chroma `(r − b)/(r + g + b)` from sensor noise,
/// estimated over the lower `share` of the image's rows (ground, below any horizon; at most
/// [`SAMPLED_ROWS`] of them, evenly spaced) from the differences between horizontally adjacent
/// pixels: their median absolute value over `0.6745 · √2` (a Gaussian's), which the soil's slow
/// changes and the few edges of rocks leave almost untouched.
pub fn chroma_noise(image: &image::RgbImage, share: f64) -> f32 {
    let (width, height) = image.dimensions();
    let rows = ((f64::from(height) * share).round() as u32).min(height);
    let step = rows.div_ceil(SAMPLED_ROWS).max(1);
    let chroma = |p: &image::Rgb<u8>| {
        let (r, g, b) = (f32::from(p[0]), f32::from(p[1]), f32::from(p[2]));
        let sum = r + g + b;
        (sum > 0.0).then(|| (r - b) / sum)
    };
    let mut differences: Vec<f32> = ((height - rows)..height)
        .step_by(step as usize)
        .flat_map(|y| {
            (1..width).filter_map(move |x| {
                let (a, b) = (image.get_pixel(x - 1, y), image.get_pixel(x, y));
                Some((chroma(b)? - chroma(a)?).abs())
            })
        })
        .collect();
    if differences.is_empty() {
        return 0.0;
    }
    let middle = differences.len() / 2;
    let (_, median, _) = differences.select_nth_unstable_by(middle, f32::total_cmp);
    *median / (0.6745 * std::f32::consts::SQRT_2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Red soil, each pixel's channels shifted by independent noise of s.d. `sd` levels (a
    /// sum of uniform draws from a fixed-seed generator).
    fn soil(sd: f64) -> image::RgbImage {
        let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        // Twelve uniform draws on [-0.5, 0.5) sum to unit variance.
        let mut gauss = move || (0..12).map(|_| uniform()).sum::<f64>();
        image::RgbImage::from_fn(400, 100, |_, _| {
            let level = |base: f64, g: f64| (base + sd * g).round().clamp(0.0, 255.0) as u8;
            image::Rgb([
                level(150.0, gauss()),
                level(90.0, gauss()),
                level(60.0, gauss()),
            ])
        })
    }

    /// Of chroma `(r − b)/(r + g + b)` at `r, g, b = 150, 90, 60`, each channel's noise of s.d.
    /// σ gives one pixel's chroma an s.d. of about `σ · √((1 − c)² + c² + (1 + c)²) / 300`.
    #[test]
    fn the_estimate_follows_the_chroma_noise() {
        let c: f64 = 0.3;
        let per_level = ((1.0 - c).powi(2) + c.powi(2) + (1.0 + c).powi(2)).sqrt() / 300.0;
        for sd in [2.0, 5.0] {
            let estimate = f64::from(chroma_noise(&soil(sd), 0.4));
            let expected = sd * per_level;
            assert!(
                (estimate / expected - 1.0).abs() < 0.15,
                "noise {sd}: {estimate} against {expected}"
            );
        }
        assert_eq!(chroma_noise(&soil(0.0), 0.4), 0.0);
    }
}
