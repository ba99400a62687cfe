//! Curve colours for the statistics panels. Fig. 7 of 000 compares up to six sensor limits
//! (n = 6 … 30 closest landmarks) in every panel, so each curve needs a colour that stays
//! distinguishable from the others both as a line and as a light ±1σ band.

use plotters::style::{HSLColor, RGBColor};

/// Tableau 10: ten colours chosen to be mutually distinct, also for common colour blindness.
const TABLEAU: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The colour of curve `index` among `count` curves: Tableau 10 while it suffices, otherwise
/// `count` hues spaced evenly around the colour wheel.
pub(super) fn curve_colour(index: usize, count: usize) -> RGBColor {
    if count <= TABLEAU.len() {
        TABLEAU[index % TABLEAU.len()]
    } else {
        let hsl = HSLColor(index as f64 / count as f64, 0.75, 0.42);
        let (r, g, b) = plotters::style::Color::rgb(&hsl);
        RGBColor(r, g, b)
    }
}

#[cfg(test)]
mod tests {
    use super::curve_colour;
    use std::collections::HashSet;

    #[test]
    fn colours_are_distinct_for_small_and_large_counts() {
        for count in [1, 6, 10, 11, 24] {
            let colours: HashSet<(u8, u8, u8)> = (0..count)
                .map(|i| {
                    let c = curve_colour(i, count);
                    (c.0, c.1, c.2)
                })
                .collect();
            assert_eq!(colours.len(), count, "{count} curves");
        }
    }
}
