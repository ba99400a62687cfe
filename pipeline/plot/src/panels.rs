//! Monte-Carlo statistics per image, as in 000 Fig. 7 (§VIII-A): up to four panels laid out
//! 2×2 (a–d), each plotting one metric against the number of images incorporated, one curve
//! per experimental setting (n closest landmarks) with its mean and a ±1 standard deviation
//! band. Curves with the same label get the same colour in every panel, and one legend below
//! the panels serves them all, as in the paper. A panel may give its own x values (002 Fig. 4:
//! noise levels) and a curve its own band (the quartiles around a median).

use super::error::PlotError;
use super::font::FAMILY;
use super::legend::{self, Entry, Key};
use super::output::{write_figure, Figure};
use super::palette::curve_colour;
use super::ticks::tick_formatter;
use plotters::coord::Shift;
use plotters::prelude::{
    ChartBuilder, Circle, DrawingArea, DrawingAreaErrorKind, DrawingBackend, PathElement, Polygon,
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
    /// A band from `low` to `high` per point, drawn instead of mean ± std (e.g. the 25th and
    /// 75th percentiles around a median).
    pub band: Option<(Vec<f64>, Vec<f64>)>,
}

/// One panel: x = image number 1..=len (or `x`), y = the metric.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Caption above the panel, e.g. `(a) incorrect EDC states removed`.
    pub title: String,
    /// The y axis description.
    pub y_label: String,
    /// The curves, drawn in order.
    pub curves: Vec<Curve>,
    /// The x value of each point, increasing, one per value of every curve; empty: the image
    /// numbers 1, 2, …
    pub x: Vec<f64>,
}

impl Panel {
    /// The x value of point `i`.
    fn x_at(&self, i: usize) -> f64 {
        self.x.get(i).copied().unwrap_or(i as f64 + 1.0)
    }
}

impl Curve {
    /// The band's bounds at point `i`: low..high, or mean ± std, or the mean alone.
    fn bounds(&self, i: usize) -> (f64, f64) {
        match &self.band {
            Some((low, high)) => (low[i], high[i]),
            None => {
                let std = self.std.get(i).copied().unwrap_or(0.0);
                (self.mean[i] - std, self.mean[i] + std)
            }
        }
    }

    fn has_band(&self) -> bool {
        self.band.is_some() || !self.std.is_empty()
    }
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
            if !panel.x.is_empty() && panel.x.len() != curve.mean.len() {
                return Err(format!(
                    "{name} has {} values but the panel {} x values",
                    curve.mean.len(),
                    panel.x.len()
                ));
            }
            if let Some((low, high)) = &curve.band {
                if low.len() != curve.mean.len() || high.len() != curve.mean.len() {
                    return Err(format!(
                        "{name}: its band is not one low and high per value"
                    ));
                }
                if low.iter().chain(high).any(|v| !v.is_finite()) {
                    return Err(format!("{name}: its band has a non-finite bound"));
                }
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
        if panel.x.iter().any(|v| !v.is_finite()) || panel.x.windows(2).any(|w| w[0] >= w[1]) {
            return Err(format!(
                "{name}: its x values are not finite and increasing"
            ));
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

/// The y range covering every curve and band of `panel`, with a margin.
fn y_range(panel: &Panel) -> Range<f64> {
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for curve in &panel.curves {
        for (i, &mean) in curve.mean.iter().enumerate() {
            let (a, b) = curve.bounds(i);
            low = low.min(mean).min(a);
            high = high.max(mean).max(b);
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
    let points = panel.curves.iter().map(|c| c.mean.len()).max().unwrap_or(1);
    let (first, last) = (panel.x_at(0), panel.x_at(points - 1));
    // A single point still needs an x interval to draw in (not below 0 for a positive x).
    let x_range = if points > 1 {
        first..last
    } else {
        let low = if first >= 0.0 {
            (first - 1.0).max(0.0)
        } else {
            first - 1.0
        };
        low..first + 1.0
    };
    let real_ticks = tick_formatter(&x_range);
    // Image numbers are whole: ticks between them stay unlabelled.
    let image_numbers = panel.x.is_empty();
    let x_ticks = move |v: &f64| {
        if !image_numbers {
            real_ticks(v)
        } else if (v - v.round()).abs() < 1e-9 {
            format!("{}", v.round())
        } else {
            String::new()
        }
    };
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
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .label_style((FAMILY, 18).into_font())
        .axis_desc_style((FAMILY, 21).into_font())
        .light_line_style(RGBColor(243, 243, 243))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()?;
    for curve in &panel.curves {
        let colour = colour(&curve.label);
        if curve.has_band() {
            let n = curve.mean.len();
            let band: Vec<(f64, f64)> = (0..n)
                .map(|i| (panel.x_at(i), curve.bounds(i).1))
                .chain((0..n).rev().map(|i| (panel.x_at(i), curve.bounds(i).0)))
                .collect();
            chart.draw_series(std::iter::once(Polygon::new(band, colour.mix(0.18))))?;
        }
        let mean: Vec<(f64, f64)> = curve
            .mean
            .iter()
            .enumerate()
            .map(|(i, &m)| (panel.x_at(i), m))
            .collect();
        // Segment by segment: a thick polyline's mitred joins shoot spikes far past the chart
        // where a dense curve jumps up and straight back down (a per-station time series).
        let style = colour.stroke_width(3);
        chart.draw_series(mean.windows(2).map(|w| PathElement::new(w.to_vec(), style)))?;
        // A one-image curve is a single point, which a line alone would not show.
        if let [point] = mean[..] {
            chart.draw_series(std::iter::once(Circle::new(point, 5, style.filled())))?;
        }
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
            band: None,
        }
    }

    fn panel(curves: Vec<Curve>) -> Panel {
        Panel {
            title: "(a) states removed".into(),
            y_label: "removed [%]".into(),
            curves,
            x: Vec::new(),
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

    /// 002 Fig. 4's form: medians over noise levels with their quartiles as bands.
    #[test]
    fn x_values_and_quartile_bands_are_drawn_and_checked() {
        let dir = scratch_dir("panels-x");
        let path = dir.join("fig4.png");
        let median = Curve {
            label: "full".into(),
            mean: vec![0.0, 0.05, 0.3, 0.7],
            std: Vec::new(),
            band: Some((vec![0.0, 0.0, 0.1, 0.2], vec![0.1, 0.5, 0.9, 1.1])),
        };
        let mut fig4 = panel(vec![median.clone()]);
        fig4.x = vec![0.5, 1.0, 3.0, 7.0];
        write_panels(&path, "bearing noise [deg]", &[fig4.clone()]).unwrap();
        assert_eq!(png_size(&path), SIZE);
        let mut decreasing = fig4.clone();
        decreasing.x = vec![0.5, 1.0, 1.0, 7.0];
        let mut short = fig4.clone();
        short.x.pop();
        let mut bad_band = fig4;
        bad_band.curves[0].band = Some((vec![0.0; 3], vec![1.0; 4]));
        for (panel, reason) in [
            (decreasing, "increasing"),
            (short, "3 x values"),
            (bad_band, "band"),
        ] {
            let error = write_panels(&dir.join("bad.png"), "x", &[panel]).unwrap_err();
            assert!(error.to_string().contains(reason), "{error}");
        }
        assert_eq!(file_names(&dir), ["fig4.png"]);
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
                    band: None,
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
