//! Helpers for the figure tests: a fresh scratch directory per test, and reading the size of
//! a PNG from its header, which checks the encoder's output without a decoder dependency.

use std::ops::Deref;
use std::path::Path;

/// An empty temporary directory, removed when dropped.
pub(super) struct Scratch(tempfile::TempDir);

impl Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.0.path()
    }
}

/// A fresh [`Scratch`] directory for `test`.
pub(super) fn scratch_dir(test: &str) -> Scratch {
    let dir = tempfile::Builder::new()
        .prefix(&format!("qrm-plot-{test}-"))
        .tempdir()
        .expect("create scratch directory");
    Scratch(dir)
}

/// The (width, height) of the PNG at `path`, after checking its signature and that the first
/// chunk is IHDR (PNG specification §5.2, §11.2.2).
pub(super) fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).expect("read PNG");
    assert!(
        bytes.len() > 24,
        "{} is too short for a PNG",
        path.display()
    );
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR", "first chunk is IHDR");
    let word = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    (word(16), word(20))
}

/// The names of the files in `dir`, sorted (to check that no temporary file is left behind).
pub(super) fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("list scratch directory")
        .map(|e| {
            e.expect("directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}
