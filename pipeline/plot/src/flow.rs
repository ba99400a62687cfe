//! A navigation flow field as in 000 Fig. 6 (§VII-B): landmarks with their Voronoi cells, the
//! RNG used for navigation, at points of a grid the direction a rover drives toward the cell of
//! the landmark nearest the goal, and trajectories from a few starts.

use super::cost_colour::cost_colour;
use super::error::PlotError;
use super::font::FAMILY;
use super::legend::{self, Entry, Key};
use super::output::{write_figure, Figure};
use super::ticks::tick_formatter;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::{
    ChartBuilder, Circle, Cross, DrawingArea, DrawingAreaErrorKind, DrawingBackend, PathElement,
    Polygon, TriangleMarker,
};
use plotters::style::{Color, IntoFont, RGBColor, WHITE};
use std::path::Path;

/// A flow field over a square field `[0, side]²`.
#[derive(Clone, Debug, PartialEq)]
pub struct FlowPicture {
    pub title: String,
    /// Landmark positions (open circles).
    pub landmarks: Vec<(f64, f64)>,
    /// RNG edges planned on, `(i, j, w)`: black for `w = 0`, blue → red as `w → 1`.
    pub edges: Vec<(usize, usize, f64)>,
    /// The true RNG, dashed grey underneath (empty: not drawn).
    pub true_edges: Vec<(usize, usize)>,
    /// `(point, unit direction)` of motion (red arrows), drawn `arrow_length` long.
    pub arrows: Vec<((f64, f64), (f64, f64))>,
    pub arrow_length: f64,
    /// Points of the grid where the navigator says it has arrived in the goal's cell (purple
    /// dots), and where it chose no heading (grey crosses: nothing identified, no route, or
    /// the route's landmark lost).
    pub arrived: Vec<(f64, f64)>,
    pub undecided: Vec<(f64, f64)>,
    /// The goal (green triangle).
    pub goal: (f64, f64),
    /// Driven paths, start first (blue lines from filled circles).
    pub trips: Vec<Vec<(f64, f64)>>,
    /// Obstacles on the ground, `(centre, radius)` (light grey discs): the rocks' footprints
    /// in a rendered world.
    pub rocks: Vec<((f64, f64), f64)>,
    pub side: f64,
}

const SIZE: (u32, u32) = (900, 980);
const MARGIN: u32 = 16;
const X_LABEL_AREA: u32 = 46;
const Y_LABEL_AREA: u32 = 64;
const LANDMARK: RGBColor = RGBColor(0, 0, 0);
const BORDER: RGBColor = RGBColor(40, 170, 60);
const ARROW: RGBColor = RGBColor(220, 30, 30);
const TRIP: RGBColor = RGBColor(30, 80, 230);
const GOAL: RGBColor = RGBColor(20, 160, 40);
const TRUE_EDGE: RGBColor = RGBColor(170, 170, 170);
const ARRIVED: RGBColor = RGBColor(140, 60, 170);
const UNDECIDED: RGBColor = RGBColor(110, 110, 110);
const ROCK: RGBColor = RGBColor(215, 215, 215);
/// Sides of the polygon a rock's footprint is drawn as.
const ROCK_SIDES: usize = 24;
/// Samples per side for tracing the Voronoi borders.
const BORDER_SAMPLES: usize = 450;

/// Writes `picture` to `path` (`.png`, 900×980 pixels, or `.svg`).
///
/// Fails without writing if there are no landmarks, a coordinate is not finite, the side is
/// not positive, or an edge names a landmark that does not exist.
pub fn write_flow(path: &Path, picture: &FlowPicture) -> Result<(), PlotError> {
    validate(picture).map_err(|reason| PlotError::Data {
        path: path.to_path_buf(),
        reason,
    })?;
    write_figure(path, picture)
}

fn validate(picture: &FlowPicture) -> Result<(), String> {
    let n = picture.landmarks.len();
    if n == 0 {
        return Err("no landmarks to draw".into());
    }
    if !(picture.side > 0.0 && picture.side.is_finite()) {
        return Err(format!("side {} is not a positive length", picture.side));
    }
    if !(picture.arrow_length > 0.0 && picture.arrow_length.is_finite()) {
        return Err(format!(
            "arrow length {} is not a positive length",
            picture.arrow_length
        ));
    }
    if let Some(rock) = picture
        .rocks
        .iter()
        .find(|(c, r)| !(c.0.is_finite() && c.1.is_finite() && *r >= 0.0 && r.is_finite()))
    {
        return Err(format!("rock {rock:?} is not a finite disc"));
    }
    let finite = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite();
    let points = picture
        .landmarks
        .iter()
        .chain(picture.trips.iter().flatten())
        .chain(picture.arrows.iter().flat_map(|(p, d)| [p, d]))
        .chain(picture.arrived.iter().chain(&picture.undecided))
        .chain(std::iter::once(&picture.goal));
    if let Some(p) = points.into_iter().find(|p| !finite(p)) {
        return Err(format!("{p:?} is not a finite position"));
    }
    let named = |i: usize, j: usize| i < n && j < n && i != j;
    if let Some(e) = picture.edges.iter().find(|e| !named(e.0, e.1)) {
        return Err(format!("edge {e:?} does not join two of the {n} landmarks"));
    }
    if let Some(e) = picture.true_edges.iter().find(|e| !named(e.0, e.1)) {
        return Err(format!(
            "true RNG edge {e:?} does not join two of the {n} landmarks"
        ));
    }
    Ok(())
}

impl FlowPicture {
    /// Short segments along the borders between Voronoi cells, traced on a grid of samples.
    fn borders(&self) -> Vec<[(f64, f64); 2]> {
        let step = self.side / BORDER_SAMPLES as f64;
        let cell = |x: f64, y: f64| {
            (0..self.landmarks.len())
                .min_by(|&a, &b| {
                    let d = |i: usize| {
                        let (px, py) = self.landmarks[i];
                        (px - x).powi(2) + (py - y).powi(2)
                    };
                    d(a).total_cmp(&d(b))
                })
                .expect("landmarks")
        };
        let centre = |i: usize| (i as f64 + 0.5) * step;
        let labels: Vec<Vec<usize>> = (0..BORDER_SAMPLES)
            .map(|i| {
                (0..BORDER_SAMPLES)
                    .map(|j| cell(centre(i), centre(j)))
                    .collect()
            })
            .collect();
        let mut out = Vec::new();
        for i in 0..BORDER_SAMPLES {
            for j in 0..BORDER_SAMPLES {
                let (x, y) = (centre(i), centre(j));
                if i + 1 < BORDER_SAMPLES && labels[i][j] != labels[i + 1][j] {
                    let bx = x + step / 2.0;
                    out.push([(bx, y - step / 2.0), (bx, y + step / 2.0)]);
                }
                if j + 1 < BORDER_SAMPLES && labels[i][j] != labels[i][j + 1] {
                    let by = y + step / 2.0;
                    out.push([(x - step / 2.0, by), (x + step / 2.0, by)]);
                }
            }
        }
        out
    }

    fn legend(&self) -> Vec<Entry> {
        let mut entries = Vec::new();
        if !self.rocks.is_empty() {
            entries.push(Entry {
                key: Key::Circle(ROCK),
                label: "rock footprint".into(),
            });
        }
        entries.extend([
            Entry {
                key: Key::Ring(LANDMARK),
                label: "landmark".into(),
            },
            Entry {
                key: Key::Line(BORDER),
                label: "Voronoi cell border".into(),
            },
        ]);
        entries.extend(legend::edge_entries(
            &self.edges,
            !self.true_edges.is_empty(),
            TRUE_EDGE,
        ));
        if !self.arrows.is_empty() {
            entries.push(Entry {
                key: Key::Line(ARROW),
                label: "direction of motion".into(),
            });
        }
        if !self.arrived.is_empty() {
            entries.push(Entry {
                key: Key::Circle(ARRIVED),
                label: "arrived (as the navigator sees it)".into(),
            });
        }
        if !self.undecided.is_empty() {
            entries.push(Entry {
                key: Key::Cross(UNDECIDED),
                label: "no heading: nothing identified, no route, or lost".into(),
            });
        }
        if !self.trips.is_empty() {
            entries.push(Entry {
                key: Key::Line(TRIP),
                label: "trajectory from a start (dot)".into(),
            });
        }
        entries.push(Entry {
            key: Key::Triangle(GOAL),
            label: "goal".into(),
        });
        entries
    }
}

impl Figure for FlowPicture {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let root = root.titled(&self.title, (FAMILY, 24))?;
        let entries = self.legend();
        let legend_height = legend::height(&root, &entries)?;
        let (_, height) = root.dim_in_pixel();
        let (plot, legend_area) = root.split_vertically(height - legend_height);
        legend::draw(&legend_area, &entries)?;
        let range = 0.0..self.side;
        let ticks = tick_formatter(&range);
        let mut chart = ChartBuilder::on(&plot)
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(range.clone(), range)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x")
            .y_desc("y")
            .x_label_formatter(&ticks)
            .y_label_formatter(&ticks)
            .label_style((FAMILY, 17).into_font())
            .axis_desc_style((FAMILY, 20).into_font())
            .draw()?;
        chart.draw_series(self.rocks.iter().map(|&((x, y), r)| {
            let outline: Vec<(f64, f64)> = (0..ROCK_SIDES)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / ROCK_SIDES as f64;
                    (x + r * a.cos(), y + r * a.sin())
                })
                .collect();
            Polygon::new(outline, ROCK.filled())
        }))?;
        chart.draw_series(
            self.borders()
                .into_iter()
                .map(|segment| PathElement::new(segment, BORDER.stroke_width(2))),
        )?;
        let at = |i: usize| self.landmarks[i];
        chart.draw_series(self.true_edges.iter().map(|&(i, j)| {
            DashedPathElement::new([at(i), at(j)], 7, 5, TRUE_EDGE.stroke_width(2))
        }))?;
        let mut edges = self.edges.clone();
        edges.sort_by(|a, b| a.2.total_cmp(&b.2));
        chart.draw_series(
            edges
                .iter()
                .map(|&(i, j, w)| PathElement::new([at(i), at(j)], cost_colour(w).stroke_width(2))),
        )?;
        let length = self.arrow_length;
        chart.draw_series(self.arrows.iter().flat_map(|&((x, y), (dx, dy))| {
            let tip = (x + length * dx, y + length * dy);
            let head = |turn: f64| {
                let (s, c) = turn.sin_cos();
                let (hx, hy) = (dx * c - dy * s, dx * s + dy * c);
                (tip.0 - 0.4 * length * hx, tip.1 - 0.4 * length * hy)
            };
            [
                PathElement::new(vec![(x, y), tip], ARROW.stroke_width(2)),
                PathElement::new(vec![head(0.5), tip, head(-0.5)], ARROW.stroke_width(2)),
            ]
        }))?;
        chart.draw_series(
            self.arrived
                .iter()
                .map(|&p| Circle::new(p, 4, ARRIVED.filled())),
        )?;
        chart.draw_series(
            self.undecided
                .iter()
                .map(|&p| Cross::new(p, 5, UNDECIDED.stroke_width(2))),
        )?;
        chart.draw_series(
            self.trips
                .iter()
                .map(|path| PathElement::new(path.clone(), TRIP.stroke_width(3))),
        )?;
        chart.draw_series(
            self.trips
                .iter()
                .filter_map(|path| path.first())
                .map(|&p| Circle::new(p, 7, TRIP.filled())),
        )?;
        chart.draw_series(
            self.landmarks
                .iter()
                .map(|&p| Circle::new(p, 6, LANDMARK.stroke_width(2))),
        )?;
        chart.draw_series(std::iter::once(TriangleMarker::new(
            self.goal,
            12,
            GOAL.filled(),
        )))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{file_names, png_size, scratch_dir};

    fn picture() -> FlowPicture {
        FlowPicture {
            title: "flow".into(),
            landmarks: vec![(20.0, 20.0), (80.0, 30.0), (50.0, 80.0)],
            edges: vec![(0, 1, 0.0), (1, 2, 0.4)],
            true_edges: vec![(0, 1), (1, 2), (0, 2)],
            arrows: vec![((10.0, 10.0), (1.0, 0.0))],
            arrow_length: 2.0,
            rocks: vec![((30.0, 60.0), 3.0)],
            arrived: vec![(50.0, 70.0)],
            undecided: vec![(90.0, 90.0)],
            goal: (55.0, 75.0),
            trips: vec![vec![(5.0, 5.0), (20.0, 20.0), (55.0, 75.0)]],
            side: 100.0,
        }
    }

    #[test]
    fn png_and_svg_are_written() {
        let dir = scratch_dir("flow");
        write_flow(&dir.join("flow.png"), &picture()).unwrap();
        write_flow(&dir.join("flow.svg"), &picture()).unwrap();
        assert_eq!(png_size(&dir.join("flow.png")), SIZE);
        assert_eq!(file_names(&dir), ["flow.png", "flow.svg"]);
    }

    #[test]
    fn a_bad_edge_is_an_error_and_writes_nothing() {
        let dir = scratch_dir("flow-bad");
        let bad = FlowPicture {
            edges: vec![(0, 7, 0.0)],
            ..picture()
        };
        assert!(matches!(
            write_flow(&dir.join("bad.png"), &bad),
            Err(PlotError::Data { .. })
        ));
        assert!(file_names(&dir).is_empty());
    }

    /// Three landmarks: the borders lie on the perpendicular bisectors, between cells.
    #[test]
    fn borders_separate_the_cells() {
        let p = picture();
        let borders = p.borders();
        assert!(!borders.is_empty());
        for [a, b] in borders {
            let mid = ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
            let mut d: Vec<f64> = p
                .landmarks
                .iter()
                .map(|l| (l.0 - mid.0).hypot(l.1 - mid.1))
                .collect();
            d.sort_by(f64::total_cmp);
            assert!(d[1] - d[0] < 2.0 * 100.0 / BORDER_SAMPLES as f64);
        }
    }
}
