//! Output files of the command line: the directory is created, the file written atomically
//! (`qrm_atomic_file`), and errors name the file.

use anyhow::{Context, Result};
use qrm_atomic_file::OutputSet;
use std::path::Path;

pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create directory {}", dir.display()))?;
    }
    qrm_atomic_file::write_bytes(path, bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Stages `value` as pretty JSON (with a final newline) at `path` in `outputs`.
pub fn stage_json(outputs: &mut OutputSet, path: &Path, value: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value)? + "\n";
    outputs
        .stage_bytes(path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}
