//! Snapshots of the relative neighbourhood graph estimated from the qualitative map, as in
//! 000 Fig. 11 (§VII, §VIII-C): landmarks at their ground-truth positions (used only to place
//! them), estimated RNG edges coloured by their cost `w` (Algorithm 2), the true RNG dashed
//! over them for comparison, and the imaging points with the latest one highlighted. Both
//! axes share one scale so that lunes and distances look as they are.

use super::cost_colour::cost_colour;
use super::error::PlotError;
use super::font::FAMILY;
use super::legend::{self, Entry, Key};
use super::output::{write_figure, Figure};
use super::ticks::tick_formatter;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::{
    ChartBuilder, Circle, DrawingArea, DrawingAreaErrorKind, DrawingBackend, EmptyElement,
    PathElement, Text, TriangleMarker,
};
use plotters::style::{Color, IntoFont, RGBColor, WHITE};
use std::ops::Range;
use std::path::Path;

/// What an RNG picture's positions are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axes {
    /// Metres (ground truth, simulated fields): numbered axes on one scale.
    Metres,
    /// A graph layout made for drawing: the axes carry no numbers, which would mean nothing.
    Layout,
    /// A realization of the map (`Hypergraph::realize`): one of the layouts its relations
    /// allow, so arrangements mean something but distances and scale do not.
    Realization,
}

/// An RNG estimate over landmark positions (000 Fig. 11 style).
#[derive(Clone, Debug, PartialEq)]
pub struct RngPicture<'a> {
    /// Caption above the picture, e.g. `after image 15`.
    pub title: String,
    /// Ground-truth landmark positions; only used for drawing.
    pub landmarks: &'a [(f64, f64)],
    /// Each landmark's name (its map id), drawn beside it; empty: none drawn.
    pub labels: &'a [String],
    /// What the positions are, which says what the axes may show.
    pub axes: Axes,
    /// Estimated edges `(i, j, w)` between landmark indices with cost `w ∈ [0, 1]`: black for
    /// `w = 0`, then dark blue → red as `w → 1`.
    pub edges: &'a [(usize, usize, f64)],
    /// Edges of the true RNG, drawn dashed in orange over the estimate (may be empty).
    pub true_edges: &'a [(usize, usize)],
    /// Pairs the map rules out as edges (a third landmark certainly in their lune), drawn
    /// thin, dotted and light under everything (may be empty).
    pub pruned: &'a [(usize, usize)],
    /// Imaging points in order (green triangles); the last one is drawn red.
    pub stations: &'a [(f64, f64)],
}

const SIZE: (u32, u32) = (900, 900);
const MARGIN: u32 = 16;
const X_LABEL_AREA: u32 = 46;
const Y_LABEL_AREA: u32 = 64;
const LANDMARK: RGBColor = RGBColor(31, 90, 220);
const STATION: RGBColor = RGBColor(20, 160, 40);
const LATEST_STATION: RGBColor = RGBColor(230, 0, 0);
/// Drawn dashed over the estimate, so that the true edges among the estimated ones stand out
/// (under it, every true edge the estimate keeps would be hidden).
const TRUE_EDGE: RGBColor = RGBColor(255, 170, 0);
const PRUNED: RGBColor = RGBColor(185, 185, 185);

/// Writes `picture` to `path`; format by extension: `.png` (900×900 pixels) or `.svg`.
///
/// Fails without writing if there are no landmarks, a position is not finite, an edge names
/// a landmark that does not exist or joins one to itself, or a cost is outside `[0, 1]`.
pub fn write_rng(path: &Path, picture: &RngPicture) -> Result<(), PlotError> {
    validate(picture).map_err(|reason| PlotError::Data {
        path: path.to_path_buf(),
        reason,
    })?;
    write_figure(path, picture)
}

/// Why `picture` cannot be drawn, if it cannot.
fn validate(picture: &RngPicture) -> Result<(), String> {
    let n = picture.landmarks.len();
    if n == 0 {
        return Err("no landmarks to draw".into());
    }
    let finite = |(x, y): &(f64, f64)| x.is_finite() && y.is_finite();
    if let Some(i) = picture.landmarks.iter().position(|p| !finite(p)) {
        return Err(format!(
            "landmark {i} is at {:?}, not a finite position",
            picture.landmarks[i]
        ));
    }
    if !picture.labels.is_empty() && picture.labels.len() != n {
        return Err(format!("{} labels for {n} landmarks", picture.labels.len()));
    }
    if let Some(i) = picture.stations.iter().position(|p| !finite(p)) {
        return Err(format!(
            "imaging point {i} is at {:?}, not a finite position",
            picture.stations[i]
        ));
    }
    let check = |kind: &str, i: usize, j: usize| {
        if i >= n || j >= n {
            Err(format!("{kind} ({i}, {j}) names a landmark ≥ {n}"))
        } else if i == j {
            Err(format!("{kind} ({i}, {j}) joins a landmark to itself"))
        } else {
            Ok(())
        }
    };
    for &(i, j, w) in picture.edges {
        check("edge", i, j)?;
        if !(0.0..=1.0).contains(&w) {
            return Err(format!("edge ({i}, {j}) has cost {w}, outside [0, 1]"));
        }
    }
    for &(i, j) in picture.true_edges {
        check("true RNG edge", i, j)?;
    }
    for &(i, j) in picture.pruned {
        check("pruned pair", i, j)?;
    }
    let points = picture.landmarks.iter().chain(picture.stations).copied();
    let (x, y) = equal_aspect(points, (1, 1));
    if !(x.end - x.start).is_finite() || !(y.end - y.start).is_finite() {
        return Err("positions too far apart to plot".into());
    }
    Ok(())
}

/// The x and y ranges that show every point of `points` with a margin and give both axes the
/// same scale on a plotting area of `pixels` (width, height).
fn equal_aspect(
    points: impl Iterator<Item = (f64, f64)>,
    pixels: (u32, u32),
) -> (Range<f64>, Range<f64>) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in points {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let span = (x1 - x0).max(y1 - y0);
    let span = if span > 0.0 { 1.1 * span } else { 1.0 };
    let (w, h) = (f64::from(pixels.0.max(1)), f64::from(pixels.1.max(1)));
    let scale = (span / w).max(span / h);
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let (half_w, half_h) = (scale * w / 2.0, scale * h / 2.0);
    ((cx - half_w)..(cx + half_w), (cy - half_h)..(cy + half_h))
}

impl Figure for RngPicture<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let root = if self.title.is_empty() {
            root.clone()
        } else {
            root.titled(&self.title, (FAMILY, 26))?
        };
        let mut entries = vec![Entry {
            key: Key::Circle(LANDMARK),
            label: "landmark".into(),
        }];
        entries.extend(legend::edge_entries(
            self.edges,
            !self.true_edges.is_empty(),
            TRUE_EDGE,
        ));
        if !self.pruned.is_empty() {
            entries.push(Entry {
                key: Key::Dotted(PRUNED),
                label: "pair the map rules out".into(),
            });
        }
        if !self.stations.is_empty() {
            entries.push(Entry {
                key: Key::Triangle(STATION),
                label: "imaging point".into(),
            });
            entries.push(Entry {
                key: Key::Triangle(LATEST_STATION),
                label: "latest imaging point".into(),
            });
        }
        let legend_height = legend::height(&root, &entries)?;
        let (width, height) = root.dim_in_pixel();
        let (plot, legend_area) = root.split_vertically(height - legend_height);
        legend::draw(&legend_area, &entries)?;

        let pixels = (
            width - 2 * MARGIN - Y_LABEL_AREA,
            height - legend_height - 2 * MARGIN - X_LABEL_AREA,
        );
        let points = self.landmarks.iter().chain(self.stations).copied();
        let (x_range, y_range) = equal_aspect(points, pixels);
        let (x_ticks, y_ticks) = (tick_formatter(&x_range), tick_formatter(&y_range));
        let mut chart = ChartBuilder::on(&plot)
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(x_range, y_range)?;
        let blank = |_: &f64| String::new();
        let metric = self.axes == Axes::Metres;
        let (x_desc, y_desc) = match self.axes {
            Axes::Metres => ("x (m)", "y (m)"),
            Axes::Layout => ("graph layout: positions carry no distances", ""),
            Axes::Realization => (
                "one realization: every relation of the map holds here; the map allows many others",
                "",
            ),
        };
        let mut mesh = chart.configure_mesh();
        if !metric {
            mesh.disable_mesh();
        }
        mesh.x_desc(x_desc)
            .y_desc(y_desc)
            .x_label_formatter(if metric { &x_ticks } else { &blank })
            .y_label_formatter(if metric { &y_ticks } else { &blank })
            .label_style((FAMILY, 17).into_font())
            .axis_desc_style((FAMILY, 20).into_font())
            .light_line_style(WHITE)
            .bold_line_style(RGBColor(215, 215, 215))
            .draw()?;

        let at = |i: usize| self.landmarks[i];
        chart.draw_series(
            self.pruned.iter().map(|&(i, j)| {
                DashedPathElement::new([at(i), at(j)], 2, 4, PRUNED.stroke_width(1))
            }),
        )?;
        // Contested edges last, so that red is not hidden under black.
        let mut edges = self.edges.to_vec();
        edges.sort_by(|a, b| a.2.total_cmp(&b.2));
        chart.draw_series(
            edges
                .iter()
                .map(|&(i, j, w)| PathElement::new([at(i), at(j)], cost_colour(w).stroke_width(3))),
        )?;
        chart.draw_series(self.true_edges.iter().map(|&(i, j)| {
            DashedPathElement::new([at(i), at(j)], 7, 5, TRUE_EDGE.stroke_width(2))
        }))?;
        if let Some((latest, earlier)) = self.stations.split_last() {
            chart.draw_series(
                earlier
                    .iter()
                    .map(|&p| TriangleMarker::new(p, 9, STATION.filled())),
            )?;
            chart.draw_series(std::iter::once(TriangleMarker::new(
                *latest,
                11,
                LATEST_STATION.filled(),
            )))?;
        }
        chart.draw_series(
            self.landmarks
                .iter()
                .map(|&p| Circle::new(p, 6, LANDMARK.filled())),
        )?;
        let label_style = (FAMILY, 18).into_font().color(&RGBColor(0, 0, 0));
        chart.draw_series(self.labels.iter().zip(self.landmarks).map(|(label, &p)| {
            EmptyElement::at(p) + Text::new(label.clone(), (8, -20), label_style.clone())
        }))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{equal_aspect, write_rng, Axes, RngPicture, SIZE};
    use crate::test_support::{file_names, png_size, scratch_dir};
    use crate::PlotError;

    const LANDMARKS: [(f64, f64); 4] = [(0.0, 0.0), (4.0, 0.0), (4.0, 2.0), (0.0, 2.0)];
    const EDGES: [(usize, usize, f64); 4] = [(0, 1, 0.0), (1, 2, 0.3), (2, 3, 1.0), (0, 2, 0.6)];
    const TRUE_EDGES: [(usize, usize); 4] = [(0, 1), (1, 2), (2, 3), (3, 0)];
    const STATIONS: [(f64, f64); 2] = [(1.0, 1.0), (3.0, 1.0)];
    static LABELS: std::sync::LazyLock<Vec<String>> =
        std::sync::LazyLock::new(|| ["0", "1", "2", "3"].map(String::from).to_vec());

    fn picture() -> RngPicture<'static> {
        RngPicture {
            title: "after image 2".into(),
            landmarks: &LANDMARKS,
            labels: LABELS.as_slice(),
            axes: Axes::Metres,
            edges: &EDGES,
            true_edges: &TRUE_EDGES,
            pruned: &[],
            stations: &STATIONS,
        }
    }

    #[test]
    fn png_and_svg_are_written_at_the_expected_size() {
        let dir = scratch_dir("rng");
        let png = dir.join("rng.png");
        let svg = dir.join("rng.svg");
        write_rng(&png, &picture()).unwrap();
        write_rng(&svg, &picture()).unwrap();
        assert_eq!(png_size(&png), SIZE);
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.starts_with("<svg") && text.contains("after image 2"),
            "{text:.200}"
        );
        assert_eq!(file_names(&dir), ["rng.png", "rng.svg"]);
    }

    #[test]
    fn a_lone_landmark_without_edges_or_stations_is_drawn() {
        let dir = scratch_dir("rng-lone");
        let path = dir.join("lone.png");
        let lone = RngPicture {
            title: String::new(),
            landmarks: &LANDMARKS[..1],
            labels: &[],
            axes: Axes::Layout,
            edges: &[],
            true_edges: &[],
            pruned: &[],
            stations: &[],
        };
        write_rng(&path, &lone).unwrap();
        assert_eq!(png_size(&path), SIZE);
    }

    #[test]
    fn undrawable_data_is_an_error_and_writes_nothing() {
        let dir = scratch_dir("rng-data");
        let path = dir.join("bad.svg");
        let nan = [(0.0, 0.0), (f64::NAN, 1.0)];
        let cases: Vec<(RngPicture, &str)> = vec![
            (
                RngPicture {
                    landmarks: &[],
                    edges: &[],
                    true_edges: &[],
                    pruned: &[],
                    ..picture()
                },
                "no landmarks",
            ),
            (
                RngPicture {
                    landmarks: &nan,
                    edges: &[],
                    true_edges: &[],
                    pruned: &[],
                    ..picture()
                },
                "landmark 1",
            ),
            (
                RngPicture {
                    stations: &nan,
                    ..picture()
                },
                "imaging point 1",
            ),
            (
                RngPicture {
                    edges: &[(0, 4, 0.0)],
                    ..picture()
                },
                "names a landmark ≥ 4",
            ),
            (
                RngPicture {
                    edges: &[(2, 2, 0.0)],
                    ..picture()
                },
                "to itself",
            ),
            (
                RngPicture {
                    edges: &[(0, 1, f64::NAN)],
                    ..picture()
                },
                "cost NaN",
            ),
            (
                RngPicture {
                    edges: &[(0, 1, 1.5)],
                    ..picture()
                },
                "cost 1.5",
            ),
            (
                RngPicture {
                    true_edges: &[(9, 0)],
                    pruned: &[],
                    ..picture()
                },
                "true RNG edge (9, 0)",
            ),
            (
                RngPicture {
                    stations: &[(f64::MAX, 0.0), (-f64::MAX, 0.0)],
                    ..picture()
                },
                "too far apart",
            ),
            (
                RngPicture {
                    labels: &LABELS[..2],
                    ..picture()
                },
                "2 labels for 4 landmarks",
            ),
        ];
        for (bad, reason) in cases {
            let error = write_rng(&path, &bad).unwrap_err();
            assert!(matches!(error, PlotError::Data { .. }), "{error}");
            let message = error.to_string();
            assert!(
                message.contains("bad.svg") && message.contains(reason),
                "{message}"
            );
        }
        let error = write_rng(&dir.join("rng.pdf"), &picture()).unwrap_err();
        assert!(matches!(error, PlotError::Format { .. }), "{error}");
        assert!(file_names(&dir).is_empty());
    }

    #[test]
    fn both_axes_get_the_same_scale() {
        let points = LANDMARKS.iter().copied();
        let (x, y) = equal_aspect(points, (800, 400));
        let per_pixel = ((x.end - x.start) / 800.0, (y.end - y.start) / 400.0);
        assert!((per_pixel.0 - per_pixel.1).abs() < 1e-12, "{per_pixel:?}");
        assert!(x.start < 0.0 && x.end > 4.0 && y.start < 0.0 && y.end > 2.0);
        let (x, y) = equal_aspect(std::iter::once((3.0, 3.0)), (100, 100));
        assert!(x.contains(&3.0) && y.contains(&3.0) && x.end - x.start > 0.0);
    }
}
