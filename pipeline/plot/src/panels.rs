//! Monte-Carlo statistics per image, as in 000 Fig. 7 (§VIII-A): up to four panels laid out
//! 2×2 (a–d), each plotting one metric against the number of images incorporated, one curve
//! per experimental setting (n closest landmarks) with its mean and a ±1 standard deviation
//! band. Curves with the same label get the same colour in every panel, and one legend below
//! the panels serves them all, as in the paper.

use super::error::PlotError;
use super::font::FAMILY;
use super::legend::{self, Entry, Key};
use super::output::{write_figure, Figure};
use super::palette::curve_colour;
use super::ticks::tick_formatter;
use plotters::coord::Shift;
use plotters::prelude::{
    ChartBuilder, DrawingArea, DrawingAreaErrorKind, DrawingBackend, LineSeries, Polygon,
};
use plotters::style::{Color, IntoFont, RGBColor, WHITE};
use std::ops::Range;
use std::path::Path;

/// One line with a ±1 standard deviation band (000 Fig. 7 style).
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Legend text, e.g. `n = 6`; curves with equal labels share a colour across panels.
    pub label: String,
    /// The mean of the metric after image 1, 2, …
    pub mean: Vec<f64>,
    /// Its standard deviation per image (same length as `mean`), or empty to draw the mean
    /// alone (as Fig. 7d does for computation times).
    pub std: Vec<f64>,
}

/// One panel: x = image number 1..=len, y = the metric.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Caption above the panel, e.g. `(a) incorrect EDC states removed`.
    pub title: String,
    /// The y axis description.
    pub y_label: String,
    /// The curves, drawn in order.
    pub curves: Vec<Curve>,
}

/// The most panels one figure holds (Fig. 7 a–d).
const MAX_PANELS: usize = 4;
const SIZE: (u32, u32) = (1400, 1000);

/// Writes `panels` (1–4, laid out 2×2 like Fig. 7 a–d; one or two panels side by side) to
/// `path`; format by extension: `.png` (1400×1000 pixels) or `.svg`.
///
/// Fails without writing if there is nothing to draw, a curve is empty, has a standard
/// deviation vector of another length, or has a non-finite or negative value.
pub fn write_panels(path: &Path, x_label: &str, panels: &[Panel]) -> Result<(), PlotError> {
    validate(panels).map_err(|reason| PlotError::Data {
        path: path.to_path_buf(),
        reason,
    })?;
    write_figure(path, &Panels { x_label, panels })
}

/// Why `panels` cannot be drawn, if they cannot.
fn validate(panels: &[Panel]) -> Result<(), String> {
    if panels.is_empty() {
        return Err("no panels to draw".into());
    }
    if panels.len() > MAX_PANELS {
        return Err(format!(
            "{} panels given, at most {MAX_PANELS} fit the 2×2 layout",
            panels.len()
        ));
    }
    for (p, panel) in panels.iter().enumerate() {
        let name = format!("panel {} ({:?})", p + 1, panel.title);
        if panel.curves.is_empty() {
            return Err(format!("{name} has no curves"));
        }
        for curve in &panel.curves {
            let name = format!("{name}, curve {:?}", curve.label);
            if curve.mean.is_empty() {
                return Err(format!("{name} has no values"));
            }
            if !curve.std.is_empty() && curve.std.len() != curve.mean.len() {
                return Err(format!(
                    "{name} has {} means but {} standard deviations",
                    curve.mean.len(),
                    curve.std.len()
                ));
            }
            if let Some((i, v)) = curve.mean.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(format!("{name}: mean at image {} is {v}", i + 1));
            }
            if let Some((i, v)) = curve
                .std
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
            {
                return Err(format!(
                    "{name}: standard deviation at image {} is {v}",
                    i + 1
                ));
            }
        }
        let range = y_range(panel);
        if !(range.end - range.start).is_finite() {
            return Err(format!("{name}: values too large to plot"));
        }
    }
    Ok(())
}

/// Validated panels with their shared x axis description.
struct Panels<'a> {
    x_label: &'a str,
    panels: &'a [Panel],
}

impl Panels<'_> {
    /// Distinct curve labels in order of first appearance; index = colour index.
    fn labels(&self) -> Vec<&str> {
        let mut labels: Vec<&str> = Vec::new();
        for curve in self.panels.iter().flat_map(|p| &p.curves) {
            if !labels.contains(&curve.label.as_str()) {
                labels.push(&curve.label);
            }
        }
        labels
    }
}

impl Figure for Panels<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let labels = self.labels();
        let colour = |label: &str| {
            let index = labels.iter().position(|l| *l == label).unwrap_or(0);
            curve_colour(index, labels.len())
        };
        let entries: Vec<Entry> = labels
            .iter()
            .map(|label| Entry {
                key: Key::Band(colour(label)),
                label: label.to_string(),
            })
            .collect();
        let legend_height = legend::height(root, &entries)?;
        // However many curves there are, the panels keep at least half of the height.
        let legend_height = legend_height.min(SIZE.1 / 2);
        let (grid, legend_area) = root.split_vertically(SIZE.1 - legend_height);
        legend::draw(&legend_area, &entries)?;
        let layout = match self.panels.len() {
            1 => (1, 1),
            2 => (1, 2),
            _ => (2, 2),
        };
        for (panel, area) in self.panels.iter().zip(grid.split_evenly(layout)) {
            draw_panel(&area, self.x_label, panel, &colour)?;
        }
        Ok(())
    }
}

/// The y range covering every mean ± std of `panel`, with a margin.
fn y_range(panel: &Panel) -> Range<f64> {
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for curve in &panel.curves {
        for (i, &mean) in curve.mean.iter().enumerate() {
            let std = curve.std.get(i).copied().unwrap_or(0.0);
            low = low.min(mean - std);
            high = high.max(mean + std);
        }
    }
    let span = high - low;
    let margin = if span > 0.0 {
        0.05 * span
    } else {
        0.5 * low.abs().max(1.0)
    };
    (low - margin)..(high + margin)
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    x_label: &str,
    panel: &Panel,
    colour: &impl Fn(&str) -> RGBColor,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let images = panel.curves.iter().map(|c| c.mean.len()).max().unwrap_or(1) as i32;
    // A single image still needs an x interval to draw in.
    let x_range = if images > 1 { 1..images } else { 0..2 };
    let y_range = y_range(panel);
    let y_ticks = tick_formatter(&y_range);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FAMILY, 26))
        .margin(14)
        .x_label_area_size(56)
        .y_label_area_size(86)
        .build_cartesian_2d(x_range, y_range)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(&panel.y_label)
        .y_label_formatter(&y_ticks)
        .label_style((FAMILY, 18).into_font())
        .axis_desc_style((FAMILY, 21).into_font())
        .light_line_style(RGBColor(243, 243, 243))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()?;
    for curve in &panel.curves {
        let colour = colour(&curve.label);
        let points = |sign: f64| {
            curve
                .mean
                .iter()
                .zip(&curve.std)
                .enumerate()
                .map(move |(i, (m, s))| (i as i32 + 1, m + sign * s))
        };
        if !curve.std.is_empty() {
            let band: Vec<(i32, f64)> = points(1.0).chain(points(-1.0).rev()).collect();
            chart.draw_series(std::iter::once(Polygon::new(band, colour.mix(0.18))))?;
        }
        let mean = curve
            .mean
            .iter()
            .enumerate()
            .map(|(i, &m)| (i as i32 + 1, m));
        // A one-image curve is a single point, which a line alone would not show.
        let marker = if curve.mean.len() == 1 { 5 } else { 0 };
        chart.draw_series(LineSeries::new(mean, colour.stroke_width(3)).point_size(marker))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{write_panels, Curve, Panel, SIZE};
    use crate::test_support::{file_names, png_size, scratch_dir};
    use crate::PlotError;

    fn curve(label: &str, mean: Vec<f64>) -> Curve {
        let std = mean.iter().map(|m| 0.1 * m.abs()).collect();
        Curve {
            label: label.into(),
            mean,
            std,
        }
    }

    fn panel(curves: Vec<Curve>) -> Panel {
        Panel {
            title: "(a) states removed".into(),
            y_label: "removed [%]".into(),
            curves,
        }
    }

    fn four_panels() -> Vec<Panel> {
        let ramp = |n: f64| {
            (1..=20)
                .map(|k| 100.0 * (1.0 - (-k as f64 * n / 60.0).exp()))
                .collect()
        };
        (0..4)
            .map(|_| panel(vec![curve("n = 6", ramp(6.0)), curve("n = 30", ramp(30.0))]))
            .collect()
    }

    #[test]
    fn png_and_svg_are_written_at_the_expected_size() {
        let dir = scratch_dir("panels");
        let png = dir.join("fig7.png");
        let svg = dir.join("fig7.svg");
        write_panels(&png, "image number", &four_panels()).unwrap();
        write_panels(&svg, "image number", &four_panels()).unwrap();
        assert_eq!(png_size(&png), SIZE);
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.starts_with("<svg") && text.contains("n = 30"),
            "{text:.200}"
        );
        assert_eq!(file_names(&dir), ["fig7.png", "fig7.svg"]);
    }

    #[test]
    fn one_point_curves_and_curves_without_deviation_are_drawn() {
        let dir = scratch_dir("panels-small");
        let path = dir.join("small.PNG");
        let mut alone = curve("n = 9", vec![4.0, 4.0, 4.0]);
        alone.std.clear();
        let panels = [panel(vec![curve("n = 6", vec![3.0])]), panel(vec![alone])];
        write_panels(&path, "image", &panels).unwrap();
        assert_eq!(png_size(&path), SIZE);
    }

    #[test]
    fn bad_extension_is_an_error_naming_the_file() {
        let dir = scratch_dir("panels-extension");
        for name in ["fig.jpg", "fig"] {
            let path = dir.join(name);
            let error = write_panels(&path, "image", &four_panels()).unwrap_err();
            assert!(matches!(error, PlotError::Format { .. }), "{error}");
            assert!(error.to_string().contains(name), "{error}");
        }
        assert!(file_names(&dir).is_empty());
    }

    #[test]
    fn undrawable_data_is_an_error_and_writes_nothing() {
        let dir = scratch_dir("panels-data");
        let path = dir.join("bad.png");
        let mut short_std = curve("n = 6", vec![1.0, 2.0]);
        short_std.std.pop();
        let cases: Vec<(Vec<Panel>, &str)> = vec![
            (Vec::new(), "no panels"),
            (vec![panel(vec![curve("n = 6", vec![1.0])]); 5], "at most 4"),
            (vec![panel(Vec::new())], "no curves"),
            (vec![panel(vec![curve("n = 6", Vec::new())])], "no values"),
            (vec![panel(vec![short_std])], "2 means but 1 standard"),
            (
                vec![panel(vec![curve("n = 6", vec![1.0, f64::NAN])])],
                "mean at image 2 is NaN",
            ),
            (
                vec![panel(vec![Curve {
                    label: "n = 6".into(),
                    mean: vec![1.0],
                    std: vec![f64::INFINITY],
                }])],
                "standard deviation at image 1 is inf",
            ),
            (
                vec![panel(vec![curve("n = 6", vec![f64::MAX, -f64::MAX])])],
                "too large",
            ),
        ];
        for (panels, reason) in cases {
            let error = write_panels(&path, "image", &panels).unwrap_err();
            assert!(matches!(error, PlotError::Data { .. }), "{error}");
            let message = error.to_string();
            assert!(
                message.contains("bad.png") && message.contains(reason),
                "{message}"
            );
        }
        assert!(file_names(&dir).is_empty());
    }
}
