//! The colour of an estimated RNG edge by its cost `w` (000 Algorithm 2, Fig. 11 caption):
//! black for `w = 0`, an edge no measurement disputes, then from dark blue to red as `w`
//! rises to 1, so that the contested edges stand out.

use plotters::style::RGBColor;

const DARK_BLUE: (f64, f64, f64) = (0.0, 0.0, 139.0);
const RED: (f64, f64, f64) = (255.0, 0.0, 0.0);

/// The colour of an edge of cost `w ∈ [0, 1]` (values outside are clamped).
pub(super) fn cost_colour(w: f64) -> RGBColor {
    if w <= 0.0 {
        return RGBColor(0, 0, 0);
    }
    let t = w.min(1.0);
    let mix = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
    RGBColor(
        mix(DARK_BLUE.0, RED.0),
        mix(DARK_BLUE.1, RED.1),
        mix(DARK_BLUE.2, RED.2),
    )
}

#[cfg(test)]
mod tests {
    use super::cost_colour;
    use plotters::style::RGBColor;

    #[test]
    fn zero_is_black_and_the_scale_runs_from_dark_blue_to_red() {
        assert_eq!(cost_colour(0.0), RGBColor(0, 0, 0));
        assert_eq!(cost_colour(1e-9), RGBColor(0, 0, 139));
        assert_eq!(cost_colour(1.0), RGBColor(255, 0, 0));
        let reds: Vec<u8> = (1..=10).map(|k| cost_colour(k as f64 / 10.0).0).collect();
        assert!(reds.windows(2).all(|p| p[0] < p[1]));
    }
}
