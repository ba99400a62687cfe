//! A panorama with what the run made of it: every detection's box, tagged with the landmark it
//! became or why it was held back or left out, and its range interval, so that a person can
//! check the detector and the association station by station without a viewer (the COLMAP /
//! ORB-SLAM habit of annotated frames). Boxes past the right edge (a rock across the seam of a
//! 360° panorama) are drawn in two parts.

use super::error::PlotError;
use super::font::FAMILY;
use super::legend::{self, Entry, Key};
use super::output::{write_figure, Figure, Format};
use plotters::coord::Shift;
use plotters::element::BitMapElement;
use plotters::prelude::{DrawingArea, DrawingAreaErrorKind, DrawingBackend, Rectangle, Text};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{Color, IntoFont, RGBColor, TextStyle, WHITE};
use std::path::Path;

/// An RGB8 image, rows top to bottom, 3 bytes a pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbImage<'a> {
    pub pixels: &'a [u8],
    pub width: u32,
    pub height: u32,
}

impl RgbImage<'_> {
    /// Why the pixels do not make a `width × height` image, if they do not.
    pub(super) fn problem(&self) -> Option<String> {
        let expected = self.width as usize * self.height as usize * 3;
        if self.width == 0 || self.height == 0 {
            Some(format!("empty image ({} × {})", self.width, self.height))
        } else if self.pixels.len() != expected {
            Some(format!(
                "{} bytes for a {} × {} RGB image ({expected} expected)",
                self.pixels.len(),
                self.width,
                self.height
            ))
        } else {
            None
        }
    }
}

/// What became of a detection, which sets its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MarkKind {
    /// Associated with an existing landmark.
    Matched,
    /// Made a new landmark.
    New,
    /// Held back: several landmarks stayed possible.
    HeldBack,
    /// Not used for mapping.
    Unused,
}

impl MarkKind {
    const ALL: [MarkKind; 4] = [
        MarkKind::Matched,
        MarkKind::New,
        MarkKind::HeldBack,
        MarkKind::Unused,
    ];

    fn colour(self) -> RGBColor {
        match self {
            MarkKind::Matched => RGBColor(20, 170, 60),
            MarkKind::New => RGBColor(30, 110, 235),
            MarkKind::HeldBack => RGBColor(240, 140, 0),
            MarkKind::Unused => RGBColor(150, 150, 150),
        }
    }

    fn legend(self) -> &'static str {
        match self {
            MarkKind::Matched => "matched: landmark id",
            MarkKind::New => "new landmark",
            MarkKind::HeldBack => "held back (→ landmark if fused later)",
            MarkKind::Unused => "not used (why: stations.json)",
        }
    }
}

/// One detection's box and tags.
#[derive(Clone, Debug, PartialEq)]
pub struct Mark {
    /// `[col_min, row_min, col_max, row_max]` in the image's pixels, inclusive; `col_max` may
    /// reach past the right edge when the box wraps the seam.
    pub bbox: [f64; 4],
    pub kind: MarkKind,
    /// Drawn above the box (`L7`, `new L12`, `touching`).
    pub label: String,
    /// Drawn below the box (the range interval); empty: nothing.
    pub detail: String,
}

/// A panorama annotated with its detections.
#[derive(Clone, Debug, PartialEq)]
pub struct AnnotatedPanorama<'a> {
    pub title: String,
    pub image: RgbImage<'a>,
    pub marks: &'a [Mark],
}

const TITLE_HEIGHT: u32 = 30;
const LABEL_SIZE: f64 = 13.0;

/// Writes `panorama` as a PNG (the only format that carries the photograph) to `path`.
///
/// Fails without writing if the image's pixels do not match its size or a box is not finite.
pub fn write_panorama(path: &Path, panorama: &AnnotatedPanorama) -> Result<(), PlotError> {
    if Format::of(path)? != Format::Png {
        return Err(PlotError::Data {
            path: path.to_path_buf(),
            reason: "an annotated panorama is written as PNG only".into(),
        });
    }
    let data_error = |reason: String| PlotError::Data {
        path: path.to_path_buf(),
        reason,
    };
    if let Some(problem) = panorama.image.problem() {
        return Err(data_error(problem));
    }
    if let Some(i) = panorama
        .marks
        .iter()
        .position(|m| m.bbox.iter().any(|v| !v.is_finite()) || m.bbox[2] < m.bbox[0])
    {
        return Err(data_error(format!(
            "box {i} is {:?}, not a box",
            panorama.marks[i].bbox
        )));
    }
    write_figure(path, panorama)
}

fn entries() -> Vec<Entry> {
    MarkKind::ALL
        .iter()
        .map(|&kind| Entry {
            key: Key::Box(kind.colour()),
            label: kind.legend().into(),
        })
        .collect()
}

/// The legend's height across a figure `width` pixels wide; measured on a scratch backend of
/// that width so that [`Figure::size`] and the drawing agree.
fn legend_height(width: u32) -> u32 {
    let mut scratch = vec![0u8; width as usize * 3];
    let area = plotters::prelude::BitMapBackend::with_buffer(&mut scratch, (width, 1));
    let area = plotters::prelude::IntoDrawingArea::into_drawing_area(area);
    legend::height(&area, &entries()).unwrap_or(2 * 32)
}

fn label_style(colour: RGBColor) -> TextStyle<'static> {
    (FAMILY, LABEL_SIZE).into_font().color(&colour)
}

impl Figure for AnnotatedPanorama<'_> {
    fn size(&self) -> (u32, u32) {
        let width = self.image.width;
        (
            width,
            TITLE_HEIGHT + self.image.height + legend_height(width),
        )
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let (width, height) = (self.image.width, self.image.height);
        root.draw(&Text::new(
            self.title.clone(),
            (8, TITLE_HEIGHT as i32 / 2),
            (FAMILY, 18.0)
                .into_font()
                .color(&RGBColor(0, 0, 0))
                .pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        let (_, rest) = root.split_vertically(TITLE_HEIGHT);
        let (photo, legend_area) = rest.split_vertically(height);
        if let Some(bitmap) = BitMapElement::with_ref((0, 0), (width, height), self.image.pixels) {
            photo.draw(&bitmap)?;
        }
        for mark in self.marks {
            draw_mark(&photo, mark, (width as i32, height as i32))?;
        }
        legend::draw(&legend_area, &entries())
    }
}

/// The box of `mark` (in one or two parts across the seam), its label on a tag above and its
/// detail below (above the label when the box reaches the bottom of the image).
fn draw_mark<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mark: &Mark,
    (width, height): (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let colour = mark.kind.colour();
    let [c0, r0, c1, r1] = mark.bbox.map(|v| v.round() as i32);
    let mut parts = vec![(c0.min(width - 1), c1.min(width - 1))];
    if c1 >= width {
        parts.push((0, c1 - width));
    }
    for &(left, right) in &parts {
        area.draw(&Rectangle::new(
            [(left - 1, r0 - 1), (right + 1, r1 + 1)],
            colour.stroke_width(2),
        ))?;
    }
    let (left, _) = parts[0];
    let mut label_top = r0;
    if !mark.label.is_empty() {
        let style = label_style(WHITE);
        let (w, h) = area.estimate_text_size(&mark.label, &style)?;
        let (w, h) = (w as i32 + 4, h as i32 + 2);
        // Above the box, or inside its top when the box touches the top of the image.
        let top = if r0 - 2 - h >= 0 { r0 - 2 - h } else { r0 };
        label_top = top;
        let x = left.min(width - w).max(0);
        area.draw(&Rectangle::new(
            [(x, top), (x + w, top + h)],
            colour.mix(0.85).filled(),
        ))?;
        area.draw(&Text::new(mark.label.clone(), (x + 2, top + 1), style))?;
    }
    if !mark.detail.is_empty() {
        let style = label_style(RGBColor(255, 255, 255));
        let (w, h) = area.estimate_text_size(&mark.detail, &style)?;
        let (w, h) = (w as i32 + 4, h as i32 + 2);
        let x = left.min(width - w).max(0);
        let top = if r1 + 3 + h <= height {
            r1 + 3
        } else {
            (label_top - h).max(0)
        };
        area.draw(&Rectangle::new(
            [(x, top), (x + w, top + h)],
            RGBColor(0, 0, 0).mix(0.55).filled(),
        ))?;
        area.draw(&Text::new(mark.detail.clone(), (x + 2, top + 1), style))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{write_panorama, AnnotatedPanorama, Mark, MarkKind, RgbImage, TITLE_HEIGHT};
    use crate::test_support::{file_names, png_size, scratch_dir};
    use crate::PlotError;

    fn marks() -> Vec<Mark> {
        vec![
            Mark {
                bbox: [10.0, 40.0, 30.0, 55.0],
                kind: MarkKind::Matched,
                label: "L7".into(),
                detail: "2.1–3.4 m".into(),
            },
            // Across the seam: drawn at the right edge and again from column 0.
            Mark {
                bbox: [190.0, 5.0, 215.0, 20.0],
                kind: MarkKind::Unused,
                label: "touching".into(),
                detail: String::new(),
            },
        ]
    }

    #[test]
    fn the_panorama_keeps_its_size_between_title_and_legend() {
        let dir = scratch_dir("panorama");
        let pixels = vec![120u8; 200 * 80 * 3];
        let image = RgbImage {
            pixels: &pixels,
            width: 200,
            height: 80,
        };
        let marks = marks();
        let path = dir.join("station.png");
        let panorama = AnnotatedPanorama {
            title: "station 0".into(),
            image,
            marks: &marks,
        };
        write_panorama(&path, &panorama).unwrap();
        let (w, h) = png_size(&path);
        assert_eq!(w, 200);
        assert!(h > TITLE_HEIGHT + 80, "{h}");
        assert_eq!(file_names(&dir), ["station.png"]);
    }

    #[test]
    fn bad_pixels_boxes_or_formats_are_errors_and_write_nothing() {
        let dir = scratch_dir("panorama-bad");
        let pixels = vec![0u8; 10 * 10 * 3];
        let good = RgbImage {
            pixels: &pixels,
            width: 10,
            height: 10,
        };
        let short = RgbImage {
            pixels: &pixels[..20],
            ..good
        };
        let nan = [Mark {
            bbox: [f64::NAN, 0.0, 1.0, 1.0],
            ..marks()[0].clone()
        }];
        for (name, image, marks, reason) in [
            ("a.png", short, &[][..], "20 bytes for a 10 × 10"),
            ("b.png", good, &nan[..], "box 0"),
            ("c.svg", good, &[][..], "PNG only"),
        ] {
            let panorama = AnnotatedPanorama {
                title: String::new(),
                image,
                marks,
            };
            let error = write_panorama(&dir.join(name), &panorama).unwrap_err();
            assert!(matches!(error, PlotError::Data { .. }), "{error}");
            assert!(error.to_string().contains(reason), "{error}");
        }
        assert!(file_names(&dir).is_empty());
    }
}
