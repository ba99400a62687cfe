//! How a figure reaches disk: the format is chosen by the file extension (PNG for viewing,
//! SVG for the write-up), and the file is rendered under a temporary name in the same
//! directory and then renamed, so that a reader (or a crashed batch of 000 §VIII experiments)
//! never sees a half-written figure.

use super::error::PlotError;
use super::font;
use plotters::coord::Shift;
use plotters::prelude::{BitMapBackend, DrawingArea, DrawingAreaErrorKind, DrawingBackend};
use plotters::prelude::{IntoDrawingArea, SVGBackend};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

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

    fn extension(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Svg => "svg",
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
    let temporary = temporary_path(path, format);
    let result = render(path, &temporary, format, figure).and_then(|()| {
        std::fs::rename(&temporary, path).map_err(|source| PlotError::Io {
            path: path.to_path_buf(),
            source,
        })
    });
    if result.is_err() {
        // The temporary file may not exist (the error came before it was created); either way
        // nothing is left behind, and the original error is the one worth reporting.
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

/// A name next to `path`, unique within this process and across processes, that keeps the
/// extension (the bitmap encoder picks its format from it).
fn temporary_path(path: &Path, format: Format) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(
        ".{name}.{}-{}.tmp.{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed),
        format.extension()
    ))
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
    match format {
        Format::Png => {
            let root = BitMapBackend::new(temporary, figure.size()).into_drawing_area();
            figure.draw(&root).map_err(|e| draw_error(e.to_string()))?;
            root.present().map_err(|e| draw_error(e.to_string()))
        }
        Format::Svg => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, figure.size()).into_drawing_area();
                figure.draw(&root).map_err(|e| draw_error(e.to_string()))?;
                root.present().map_err(|e| draw_error(e.to_string()))?;
            }
            std::fs::write(temporary, svg).map_err(|source| PlotError::Io {
                path: path.to_path_buf(),
                source,
            })
        }
    }
}
