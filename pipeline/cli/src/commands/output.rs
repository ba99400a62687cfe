//! Output files of the command line: the directory is created, the file written atomically
//! (`qrm_atomic_file`), and errors name the file.

use anyhow::{Context, Result};
use std::path::Path;

pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create directory {}", dir.display()))?;
    }
    qrm_atomic_file::write_bytes(path, bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}
