//! A legend strip drawn outside the plotting areas. Fig. 7 of 000 shares one legend across
//! its four panels ("the legend in (d) applies to all plots"); putting it in a strip of its
//! own keeps it off the curves, and Fig. 11 style pictures reuse it for their markers and
//! the edge-cost scale. Entries are laid out left to right, centred, wrapping into rows.

use super::cost_colour::cost_colour;
use super::font::FAMILY;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::{
    Circle, Cross, DrawingArea, DrawingAreaErrorKind, DrawingBackend, PathElement, Rectangle, Text,
    TriangleMarker,
};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{Color, IntoFont, RGBColor, TextStyle};
use std::ops::Range;

/// What an entry's swatch shows.
pub(super) enum Key {
    /// A mean line over its ±1σ band.
    Band(RGBColor),
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A thin dotted line.
    Dotted(RGBColor),
    /// A filled circle marker.
    Circle(RGBColor),
    /// An open circle marker.
    Ring(RGBColor),
    /// A filled triangle marker.
    Triangle(RGBColor),
    /// An open box (a detection's outline on a panorama).
    Box(RGBColor),
    /// A diagonal cross marker.
    Cross(RGBColor),
    /// The edge-cost colours for `0 < w ≤ 1`.
    CostScale,
}

/// The entries for RNG edges `(i, j, w)` as drawn: certain ones (`w = 0`) black, uncertain ones
/// on the cost scale, and the true RNG dashed in `true_colour` if it is drawn; only what is drawn
/// is listed.
pub(super) fn edge_entries(
    edges: &[(usize, usize, f64)],
    true_edges: bool,
    true_colour: RGBColor,
) -> Vec<Entry> {
    let mut entries = Vec::new();
    if edges.iter().any(|e| e.2 == 0.0) {
        entries.push(Entry {
            key: Key::Line(RGBColor(0, 0, 0)),
            label: "certain RNG edge (w = 0)".into(),
        });
    }
    if edges.iter().any(|e| e.2 > 0.0) {
        entries.push(Entry {
            key: Key::CostScale,
            label: "uncertain edge, cost w from 0 (blue) to 1 (red)".into(),
        });
    }
    if true_edges {
        entries.push(Entry {
            key: Key::Dashed(true_colour),
            label: "true RNG edge".into(),
        });
    }
    entries
}

/// One legend entry: a swatch and its label.
pub(super) struct Entry {
    pub key: Key,
    pub label: String,
}

const FONT_SIZE: f64 = 19.0;
const ROW_HEIGHT: i32 = 32;
const PADDING: i32 = 8;
const SWATCH_WIDTH: i32 = 40;
const SCALE_WIDTH: i32 = 110;
const LABEL_GAP: i32 = 8;
const ENTRY_GAP: i32 = 34;

fn text_style() -> TextStyle<'static> {
    (FAMILY, FONT_SIZE)
        .into_font()
        .color(&RGBColor(0, 0, 0))
        .pos(Pos::new(HPos::Left, VPos::Center))
}

fn swatch_width(key: &Key) -> i32 {
    match key {
        Key::CostScale => SCALE_WIDTH,
        _ => SWATCH_WIDTH,
    }
}

/// Pixel widths of the entries (swatch, gap, label).
fn entry_widths<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
) -> Result<Vec<i32>, DrawingAreaErrorKind<DB::ErrorType>> {
    let style = text_style();
    entries
        .iter()
        .map(|entry| {
            let (text_width, _) = area.estimate_text_size(&entry.label, &style)?;
            Ok(swatch_width(&entry.key) + LABEL_GAP + text_width as i32)
        })
        .collect()
}

/// Splits entries of the given widths into rows no wider than `available` (an entry wider
/// than `available` gets a row of its own).
fn rows(widths: &[i32], available: i32) -> Vec<Range<usize>> {
    let mut rows = Vec::new();
    let mut start = 0;
    let mut used = 0;
    for (i, &width) in widths.iter().enumerate() {
        if i > start && used + ENTRY_GAP + width > available {
            rows.push(start..i);
            start = i;
            used = 0;
        }
        used += if i > start { ENTRY_GAP } else { 0 } + width;
    }
    if start < widths.len() {
        rows.push(start..widths.len());
    }
    rows
}

/// The height of the strip that [`draw`] needs for `entries` across the width of `area`.
pub(super) fn height<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
) -> Result<u32, DrawingAreaErrorKind<DB::ErrorType>> {
    let widths = entry_widths(area, entries)?;
    let available = area.dim_in_pixel().0 as i32 - 2 * PADDING;
    let count = rows(&widths, available).len() as i32;
    Ok((count * ROW_HEIGHT + 2 * PADDING) as u32)
}

/// Draws `entries` centred in `area`.
pub(super) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let widths = entry_widths(area, entries)?;
    let width = area.dim_in_pixel().0 as i32;
    for (row, range) in rows(&widths, width - 2 * PADDING).into_iter().enumerate() {
        let row_width: i32 =
            widths[range.clone()].iter().sum::<i32>() + ENTRY_GAP * (range.len() as i32 - 1);
        let y = PADDING + row as i32 * ROW_HEIGHT + ROW_HEIGHT / 2;
        let mut x = ((width - row_width) / 2).max(PADDING);
        for i in range {
            draw_swatch(area, &entries[i].key, x, y)?;
            let label_x = x + swatch_width(&entries[i].key) + LABEL_GAP;
            area.draw(&Text::new(
                entries[i].label.clone(),
                (label_x, y),
                text_style(),
            ))?;
            x += widths[i] + ENTRY_GAP;
        }
    }
    Ok(())
}

/// Draws the swatch of `key` with its left edge at `x`, centred vertically on `y`.
fn draw_swatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    key: &Key,
    x: i32,
    y: i32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let middle = (x + SWATCH_WIDTH / 2, y);
    let line = [(x, y), (x + SWATCH_WIDTH, y)];
    match key {
        Key::Band(colour) => {
            area.draw(&Rectangle::new(
                [(x, y - 9), (x + SWATCH_WIDTH, y + 9)],
                colour.mix(0.2).filled(),
            ))?;
            area.draw(&PathElement::new(line, colour.stroke_width(3)))
        }
        Key::Line(colour) => area.draw(&PathElement::new(line, colour.stroke_width(2))),
        Key::Dashed(colour) => {
            area.draw(&DashedPathElement::new(line, 6, 4, colour.stroke_width(2)))
        }
        Key::Dotted(colour) => {
            area.draw(&DashedPathElement::new(line, 2, 4, colour.stroke_width(1)))
        }
        Key::Circle(colour) => area.draw(&Circle::new(middle, 6, colour.filled())),
        Key::Ring(colour) => area.draw(&Circle::new(middle, 6, colour.stroke_width(2))),
        Key::Triangle(colour) => area.draw(&TriangleMarker::new(middle, 9, colour.filled())),
        Key::Box(colour) => area.draw(&Rectangle::new(
            [(x + 8, y - 8), (x + SWATCH_WIDTH - 8, y + 8)],
            colour.stroke_width(2),
        )),
        Key::Cross(colour) => area.draw(&Cross::new(middle, 6, colour.stroke_width(2))),
        Key::CostScale => {
            for step in 0..SCALE_WIDTH {
                let w = f64::from(step + 1) / f64::from(SCALE_WIDTH);
                area.draw(&Rectangle::new(
                    [(x + step, y - 7), (x + step + 1, y + 7)],
                    cost_colour(w).filled(),
                ))?;
            }
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{rows, ENTRY_GAP};

    #[test]
    fn entries_wrap_into_rows_that_fit() {
        assert_eq!(rows(&[100, 100, 100], 1000), vec![0..3]);
        assert_eq!(rows(&[100, 100, 100], 200 + ENTRY_GAP), vec![0..2, 2..3]);
        assert_eq!(rows(&[500, 50], 100), vec![0..1, 1..2]);
        assert!(rows(&[], 100).is_empty());
    }
}
