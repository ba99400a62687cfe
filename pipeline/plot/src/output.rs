//! How a figure reaches disk: the format is chosen by the file extension (PNG for viewing,
//! SVG for the write-up), and the file is rendered under a temporary name in the same
//! directory and then renamed, so that a reader (or a crashed batch of 000 §VIII experiments)
//! never sees a half-written figure.

use super::error::PlotError;
use super::font;
use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder};
use plotters::coord::Shift;
use plotters::prelude::{BitMapBackend, DrawingArea, DrawingAreaErrorKind, DrawingBackend};
use plotters::prelude::{IntoDrawingArea, SVGBackend};
use std::path::Path;

/// A figure that can draw itself on any plotters backend.
pub(super) trait Figure {
    /// Size in pixels (PNG) or user units (SVG).
    fn size(&self) -> (u32, u32);
    /// Draws the whole figure on `root`.
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>;
}

/// The file formats a figure can be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Format {
    Png,
    Svg,
}

impl Format {
    /// The format named by the extension of `path` (case-insensitive).
    pub(super) fn of(path: &Path) -> Result<Format, PlotError> {
        let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if extension.eq_ignore_ascii_case("png") {
            Ok(Format::Png)
        } else if extension.eq_ignore_ascii_case("svg") {
            Ok(Format::Svg)
        } else {
            Err(PlotError::Format {
                path: path.to_path_buf(),
            })
        }
    }
}

/// Renders `figure` to `path` atomically. `path` must have a `.png` or `.svg` extension.
pub(super) fn write_figure(path: &Path, figure: &impl Figure) -> Result<(), PlotError> {
    let format = Format::of(path)?;
    if !font::ensure_registered() {
        return Err(PlotError::Font {
            path: path.to_path_buf(),
        });
    }
    qrm_atomic_file::write_via_temporary(
        path,
        |temporary| render(path, temporary, format, figure),
        |source| PlotError::Io {
            path: path.to_path_buf(),
            source,
        },
    )
}

/// Draws `figure` into the file `temporary`; errors name `path`, the file the caller asked for.
fn render(
    path: &Path,
    temporary: &Path,
    format: Format,
    figure: &impl Figure,
) -> Result<(), PlotError> {
    let draw_error = |reason: String| PlotError::Draw {
        path: path.to_path_buf(),
        reason,
    };
    // Drawn in memory and written in one go through the interrupt-safe creation.
    let write = |bytes: &[u8]| {
        qrm_atomic_file::write_file(temporary, bytes).map_err(|source| PlotError::Io {
            path: path.to_path_buf(),
            source,
        })
    };
    match format {
        Format::Png => {
            let (width, height) = figure.size();
            let mut pixels = vec![0u8; width as usize * height as usize * 3];
            {
                let root =
                    BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
                figure.draw(&root).map_err(|e| draw_error(e.to_string()))?;
                root.present().map_err(|e| draw_error(e.to_string()))?;
            }
            let mut png = Vec::new();
            PngEncoder::new(&mut png)
                .write_image(&pixels, width, height, ExtendedColorType::Rgb8)
                .map_err(|e| draw_error(e.to_string()))?;
            write(&png)
        }
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, figure.size()).into_drawing_area();
                figure.draw(&root).map_err(|e| draw_error(e.to_string()))?;
                root.present().map_err(|e| draw_error(e.to_string()))?;
            }
            write(svg.as_bytes())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Format;
    use crate::test_support::{file_names, scratch_dir};
    use crate::{write_rng, Axes, PlotError, RngPicture};
    use std::path::Path;

    #[test]
    fn the_extension_names_the_format() {
        assert_eq!(Format::of(Path::new("a/b.png")).unwrap(), Format::Png);
        assert_eq!(Format::of(Path::new("b.SVG")).unwrap(), Format::Svg);
        for bad in ["b.pdf", "b", "png", ".png.txt"] {
            assert!(
                Format::of(Path::new(bad)).is_err(),
                "{bad} should be rejected"
            );
        }
    }

    #[test]
    fn a_missing_directory_is_an_error_naming_the_file_and_leaves_nothing() {
        let dir = scratch_dir("output-missing");
        let picture = RngPicture {
            title: "t".into(),
            landmarks: &[(0.0, 0.0), (1.0, 1.0)],
            labels: &[],
            axes: Axes::Metres,
            edges: &[(0, 1, 0.5)],
            true_edges: &[],
            pruned: &[],
            stations: &[],
        };
        for name in ["fig.png", "fig.svg"] {
            let path = dir.join("missing").join(name);
            let error = write_rng(&path, &picture).unwrap_err();
            assert!(
                matches!(error, PlotError::Draw { .. } | PlotError::Io { .. }),
                "{error}"
            );
            assert!(error.to_string().contains(name), "{error}");
        }
        assert!(file_names(&dir).is_empty());
    }

    #[test]
    fn an_existing_file_is_replaced() {
        let dir = scratch_dir("output-replace");
        let path = dir.join("fig.svg");
        std::fs::write(&path, "old").unwrap();
        let picture = RngPicture {
            title: "new".into(),
            landmarks: &[(0.0, 0.0)],
            labels: &[],
            axes: Axes::Layout,
            edges: &[],
            true_edges: &[],
            pruned: &[],
            stations: &[],
        };
        write_rng(&path, &picture).unwrap();
        assert!(std::fs::read_to_string(&path).unwrap().starts_with("<svg"));
        assert_eq!(file_names(&dir), ["fig.svg"]);
    }
}
