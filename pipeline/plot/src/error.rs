//! Why a figure could not be written. Every message names the target file, since figures are
//! typically written in batches (one per experiment or per RNG snapshot, 000 §VIII).

use std::path::PathBuf;

/// Why [`write_panels`](super::write_panels) or [`write_rng`](super::write_rng) failed.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The extension does not say which format to write.
    #[error("{}: unsupported figure format, expected a .png or .svg extension", path.display())]
    Format { path: PathBuf },
    /// The data cannot be drawn (empty, not finite, inconsistent lengths or indices).
    #[error("{}: {reason}", path.display())]
    Data { path: PathBuf, reason: String },
    /// The embedded font was rejected by the text renderer.
    #[error("{}: the embedded DejaVu Sans font could not be loaded", path.display())]
    Font { path: PathBuf },
    /// The drawing backend failed while rendering or encoding.
    #[error("{}: drawing failed: {reason}", path.display())]
    Draw { path: PathBuf, reason: String },
    /// Writing or renaming the file failed.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}
