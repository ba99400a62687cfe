//! Every landmark of a map as a person would recognise it: a grid of tiles, each the crop of the
//! panorama where the landmark was seen best, captioned with its map id. The map itself knows
//! landmarks only by id; this is what ties an id to a rock on the ground (and what route
//! directions show, 004 §6).

use super::error::PlotError;
use super::font::FAMILY;
use super::output::{write_figure, Figure, Format};
use super::panorama::RgbImage;
use plotters::coord::Shift;
use plotters::element::BitMapElement;
use plotters::prelude::{DrawingArea, DrawingAreaErrorKind, DrawingBackend, Rectangle, Text};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{Color, IntoFont, RGBColor, WHITE};
use std::path::Path;

/// One tile: an image no larger than [`TILE`] and two caption lines under it.
#[derive(Clone, Debug, PartialEq)]
pub struct Tile<'a> {
    pub image: RgbImage<'a>,
    pub caption: String,
    pub note: String,
}

/// A titled grid of tiles.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSheet<'a> {
    pub title: String,
    pub tiles: &'a [Tile<'a>],
}

/// The largest tile image, pixels (width, height).
pub const TILE: (u32, u32) = (160, 120);
const COLUMNS: usize = 8;
const GAP: u32 = 10;
const CAPTION: u32 = 40;
const TITLE_HEIGHT: u32 = 40;

/// Writes `sheet` as a PNG to `path`. Fails without writing if there are no tiles or a tile's
/// image is empty, larger than [`TILE`] or does not match its pixels.
pub fn write_contact_sheet(path: &Path, sheet: &ContactSheet) -> Result<(), PlotError> {
    let data_error = |reason: String| PlotError::Data {
        path: path.to_path_buf(),
        reason,
    };
    if Format::of(path)? != Format::Png {
        return Err(data_error("a contact sheet is written as PNG only".into()));
    }
    if sheet.tiles.is_empty() {
        return Err(data_error("no tiles to draw".into()));
    }
    for (i, tile) in sheet.tiles.iter().enumerate() {
        if let Some(problem) = tile.image.problem() {
            return Err(data_error(format!("tile {i}: {problem}")));
        }
        if tile.image.width > TILE.0 || tile.image.height > TILE.1 {
            return Err(data_error(format!(
                "tile {i} is {} × {}, larger than {} × {}",
                tile.image.width, tile.image.height, TILE.0, TILE.1
            )));
        }
    }
    write_figure(path, sheet)
}

impl ContactSheet<'_> {
    fn columns(&self) -> usize {
        self.tiles.len().clamp(1, COLUMNS)
    }
}

impl Figure for ContactSheet<'_> {
    fn size(&self) -> (u32, u32) {
        let columns = self.columns() as u32;
        let rows = self.tiles.len().div_ceil(self.columns()) as u32;
        (
            (columns * (TILE.0 + GAP) + GAP).max(480),
            TITLE_HEIGHT + rows * (TILE.1 + CAPTION + GAP) + GAP,
        )
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let black = RGBColor(0, 0, 0);
        root.draw(&Text::new(
            self.title.clone(),
            (GAP as i32, TITLE_HEIGHT as i32 / 2),
            (FAMILY, 20.0)
                .into_font()
                .color(&black)
                .pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
        let centred = |size: f64, colour: &RGBColor| {
            (FAMILY, size)
                .into_font()
                .color(colour)
                .pos(Pos::new(HPos::Center, VPos::Top))
        };
        for (i, tile) in self.tiles.iter().enumerate() {
            let (column, row) = ((i % self.columns()) as u32, (i / self.columns()) as u32);
            let x = (GAP + column * (TILE.0 + GAP)) as i32;
            let y = (TITLE_HEIGHT + row * (TILE.1 + CAPTION + GAP)) as i32;
            root.draw(&Rectangle::new(
                [(x, y), (x + TILE.0 as i32, y + TILE.1 as i32)],
                RGBColor(235, 235, 235).filled(),
            ))?;
            let image = tile.image;
            let at = (
                x + (TILE.0 - image.width) as i32 / 2,
                y + (TILE.1 - image.height) as i32 / 2,
            );
            if let Some(bitmap) =
                BitMapElement::with_ref(at, (image.width, image.height), image.pixels)
            {
                root.draw(&bitmap)?;
            }
            let middle = x + TILE.0 as i32 / 2;
            let below = y + TILE.1 as i32 + 3;
            root.draw(&Text::new(
                tile.caption.clone(),
                (middle, below),
                centred(16.0, &black),
            ))?;
            root.draw(&Text::new(
                tile.note.clone(),
                (middle, below + 19),
                centred(12.0, &RGBColor(90, 90, 90)),
            ))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{write_contact_sheet, ContactSheet, Tile, TILE};
    use crate::test_support::{file_names, png_size, scratch_dir};
    use crate::{PlotError, RgbImage};

    #[test]
    fn tiles_are_laid_out_in_rows_of_eight() {
        let dir = scratch_dir("sheet");
        let pixels = vec![200u8; 40 * 30 * 3];
        let image = RgbImage {
            pixels: &pixels,
            width: 40,
            height: 30,
        };
        let tiles: Vec<Tile> = (0..10)
            .map(|i| Tile {
                image,
                caption: format!("L{i}"),
                note: "station_001".into(),
            })
            .collect();
        let path = dir.join("landmarks.png");
        let sheet = ContactSheet {
            title: "10 landmarks".into(),
            tiles: &tiles,
        };
        write_contact_sheet(&path, &sheet).unwrap();
        let (w, h) = png_size(&path);
        assert_eq!(w, 8 * (TILE.0 + 10) + 10);
        assert!(h > 2 * TILE.1, "two rows: {h}");
        assert_eq!(file_names(&dir), ["landmarks.png"]);
    }

    #[test]
    fn no_tiles_or_oversized_tiles_are_errors() {
        let dir = scratch_dir("sheet-bad");
        let pixels = vec![0u8; 200 * 10 * 3];
        let wide = [Tile {
            image: RgbImage {
                pixels: &pixels,
                width: 200,
                height: 10,
            },
            caption: String::new(),
            note: String::new(),
        }];
        for (tiles, reason) in [(&[][..], "no tiles"), (&wide[..], "larger than")] {
            let sheet = ContactSheet {
                title: String::new(),
                tiles,
            };
            let error = write_contact_sheet(&dir.join("s.png"), &sheet).unwrap_err();
            assert!(matches!(error, PlotError::Data { .. }), "{error}");
            assert!(error.to_string().contains(reason), "{error}");
        }
        assert!(file_names(&dir).is_empty());
    }
}
