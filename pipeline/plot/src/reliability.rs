//! Leg reliability of route directions (004 §6.1.2, Fig. 21; docs/DIRECTIONS.md): (a) how often
//! the most isolated landmark of a scene of `n` objects is selected correctly, measured per
//! range error σ (markers) beside the fitted Eq. (1) (lines); (b) the calibration of whole
//! routes: predicted reliability `e^−U` against the measured success rate, with 95 % intervals
//! and the diagonal a perfect model would follow.

use super::error::PlotError;
use super::font::FAMILY;
use super::legend::{self, Entry, Key};
use super::output::{write_figure, Figure};
use super::palette::curve_colour;
use plotters::coord::cartesian::Cartesian2d;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::{
    ChartBuilder, ChartContext, Circle, DrawingArea, DrawingAreaErrorKind, DrawingBackend,
    LineSeries, PathElement, Text,
};
use plotters::style::{Color, IntoFont, RGBColor, WHITE};
use std::ops::Range;
use std::path::Path;

/// Measured selection rates, and the model they are compared with.
#[derive(Clone, Debug, PartialEq)]
pub struct SelectionSeries {
    /// Legend text, e.g. `σ = 0.1: measured (dots), Eq. (1) fit (line)`.
    pub label: String,
    /// `(n, measured rate)`, drawn as dots.
    pub measured: Vec<(f64, f64)>,
    /// `(n, model)`, drawn as a line (none when empty).
    pub fitted: Vec<(f64, f64)>,
}

/// Routes of one kind, binned by predicted reliability.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrationSeries {
    /// Legend text, e.g. `routes: measured success per bin, 95 % interval`.
    pub label: String,
    pub points: Vec<CalibrationPoint>,
}

/// One bin of the calibration plot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationPoint {
    pub predicted: f64,
    pub measured: f64,
    pub low: f64,
    pub high: f64,
    pub routes: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ReliabilityPicture {
    pub title: String,
    pub selection: Vec<SelectionSeries>,
    pub calibration: Vec<CalibrationSeries>,
    /// Caption of the calibration panel, e.g. how many routes.
    pub calibration_title: String,
}

const SIZE: (u32, u32) = (1500, 760);
const DIAGONAL: RGBColor = RGBColor(150, 150, 150);
/// Colours of the calibration series (apart from the selection panel's): black, then purple.
const BINS: [RGBColor; 2] = [RGBColor(0, 0, 0), RGBColor(148, 60, 200)];

/// Writes `picture` to `path` (`.png`, 1500×760 pixels, or `.svg`). Fails without writing when
/// there is nothing to draw or a value is outside `[0, 1]` (rates) or not finite.
pub fn write_reliability(path: &Path, picture: &ReliabilityPicture) -> Result<(), PlotError> {
    validate(picture).map_err(|reason| PlotError::Data {
        path: path.to_path_buf(),
        reason,
    })?;
    write_figure(path, picture)
}

fn validate(picture: &ReliabilityPicture) -> Result<(), String> {
    if picture.selection.iter().all(|s| s.measured.is_empty()) {
        return Err("no selection rates to draw".into());
    }
    if picture.calibration.iter().all(|c| c.points.is_empty()) {
        return Err("no calibration bins to draw".into());
    }
    if picture.calibration.len() > BINS.len() {
        return Err(format!("at most {} calibration series", BINS.len()));
    }
    let rate = |v: f64| (0.0..=1.0).contains(&v);
    for s in &picture.selection {
        for &(n, r) in s.measured.iter().chain(&s.fitted) {
            if !(n.is_finite() && rate(r)) {
                return Err(format!(
                    "{}: ({n}, {r}) is not a rate at a scene size",
                    s.label
                ));
            }
        }
    }
    for b in picture.calibration.iter().flat_map(|c| &c.points) {
        if ![b.predicted, b.measured, b.low, b.high]
            .into_iter()
            .all(rate)
        {
            return Err(format!("calibration bin {b:?} has a value outside [0, 1]"));
        }
    }
    Ok(())
}

impl Figure for ReliabilityPicture {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let (title, body) = root.split_vertically(50);
        title.draw(&Text::new(
            self.title.clone(),
            (20, 12),
            (FAMILY, 26).into_font(),
        ))?;
        let count = self.selection.len();
        let mut entries: Vec<Entry> = self
            .selection
            .iter()
            .enumerate()
            .map(|(i, s)| Entry {
                key: if s.fitted.is_empty() {
                    Key::Circle(curve_colour(i, count))
                } else {
                    Key::Line(curve_colour(i, count))
                },
                label: s.label.clone(),
            })
            .collect();
        for (series, colour) in self.calibration.iter().zip(BINS) {
            entries.push(Entry {
                key: Key::Circle(colour),
                label: series.label.clone(),
            });
        }
        entries.push(Entry {
            key: Key::Dashed(DIAGONAL),
            label: "perfect calibration".into(),
        });
        let legend_height = legend::height(&body, &entries)?;
        let (panels, legend_area) = body.split_vertically(SIZE.1 - 50 - legend_height);
        legend::draw(&legend_area, &entries)?;
        let halves = panels.split_evenly((1, 2));
        self.draw_selection(&halves[0])?;
        self.draw_calibration(&halves[1])
    }
}

impl ReliabilityPicture {
    fn draw_selection<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let xs = self
            .selection
            .iter()
            .flat_map(|s| s.measured.iter().chain(&s.fitted).map(|p| p.0));
        let (low, high) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
        let mut chart = rate_chart(
            area,
            "(a) correct selection of the most isolated",
            (low - 0.3)..(high + 0.3),
            (
                "objects in the scene n (counting the landmark you are at)",
                "R: intended landmark selected",
            ),
        )?;
        let count = self.selection.len();
        for (i, s) in self.selection.iter().enumerate() {
            let colour = curve_colour(i, count);
            chart.draw_series(LineSeries::new(
                s.fitted.iter().copied(),
                colour.stroke_width(3),
            ))?;
            chart.draw_series(
                s.measured
                    .iter()
                    .map(|&p| Circle::new(p, 5, colour.filled())),
            )?;
        }
        Ok(())
    }

    fn draw_calibration<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let mut chart = rate_chart(
            area,
            &self.calibration_title,
            0.0..1.0,
            (
                "predicted reliability e^−U",
                "measured: intended landmark(s) reached",
            ),
        )?;
        chart.draw_series(std::iter::once(DashedPathElement::new(
            vec![(0.0, 0.0), (1.0, 1.0)],
            8,
            6,
            DIAGONAL.stroke_width(2),
        )))?;
        for (k, (series, colour)) in self.calibration.iter().zip(BINS).enumerate() {
            // A second series is nudged right so that its intervals do not hide the first's.
            let nudge = 0.008 * k as f64;
            for b in &series.points {
                let x = b.predicted + nudge;
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(x, b.low), (x, b.high)],
                    colour.stroke_width(2),
                )))?;
                chart.draw_series(std::iter::once(Circle::new(
                    (x, b.measured),
                    6,
                    colour.filled(),
                )))?;
                chart.draw_series(std::iter::once(Text::new(
                    format!("{}", b.routes),
                    (x + 0.012, b.measured - 0.015),
                    (FAMILY, 16).into_font(),
                )))?;
            }
        }
        Ok(())
    }
}

/// A panel whose y axis is a rate in `[0, 1]`, with its caption, x range and axis texts
/// `(x, y)`, mesh drawn: both panels of the figure.
fn rate_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    x_range: Range<f64>,
    (x_desc, y_desc): (&str, &str),
) -> Result<RateChart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 24))
        .margin(14)
        .x_label_area_size(56)
        .y_label_area_size(76)
        .build_cartesian_2d(x_range, 0.0..1.02)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FAMILY, 18).into_font())
        .axis_desc_style((FAMILY, 20).into_font())
        .light_line_style(RGBColor(243, 243, 243))
        .bold_line_style(RGBColor(205, 205, 205))
        .draw()?;
    Ok(chart)
}

type RateChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{png_size, scratch_dir};

    fn picture() -> ReliabilityPicture {
        ReliabilityPicture {
            title: "leg reliability".into(),
            selection: vec![SelectionSeries {
                label: "σ = 0.1".into(),
                measured: vec![(2.0, 0.95), (3.0, 0.9), (4.0, 0.85)],
                fitted: vec![(2.0, 0.96), (4.0, 0.84)],
            }],
            calibration: vec![CalibrationSeries {
                label: "routes".into(),
                points: vec![CalibrationPoint {
                    predicted: 0.7,
                    measured: 0.65,
                    low: 0.55,
                    high: 0.75,
                    routes: 80,
                }],
            }],
            calibration_title: "(b) 80 routes".into(),
        }
    }

    #[test]
    fn writes_png_and_svg_and_refuses_bad_rates() {
        let dir = scratch_dir("reliability");
        let png = dir.join("reliability.png");
        write_reliability(&png, &picture()).unwrap();
        assert_eq!(png_size(&png), SIZE);
        write_reliability(&dir.join("reliability.svg"), &picture()).unwrap();
        let mut bad = picture();
        bad.calibration[0].points[0].measured = 1.5;
        let error = write_reliability(&dir.join("bad.png"), &bad).unwrap_err();
        assert!(error.to_string().contains("outside [0, 1]"), "{error}");
        assert!(!dir.join("bad.png").exists());
    }
}
