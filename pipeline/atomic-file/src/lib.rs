//! Files written whole or not at all: every output of the project (maps, figures, panoramas,
//! truth files) is produced under a uniquely named temporary file beside its target, synced,
//! and renamed over it; on failure the temporary file is removed. A reader — or a batch that
//! crashed half-way — never sees a half-written file, and concurrent writers of the same target
//! do not trample each other's temporary files.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Produces `path` by letting `write` fill a temporary file (whose name keeps `path`'s
/// extension, for encoders that choose their format by it), then renaming it. `io_error` turns
/// a failed sync or rename into the caller's error type.
pub fn write_via_temporary<E>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
    io_error: impl FnOnce(std::io::Error) -> E,
) -> Result<(), E> {
    let temporary = Temporary::beside(path);
    write(temporary.path())?;
    temporary.commit().map_err(io_error)
}

/// The temporary file of an output written over time (a recording fed station by station):
/// [`Temporary::commit`] moves it over its target; dropping it uncommitted removes it, so an
/// abandoned or failed output leaves nothing behind.
#[derive(Debug)]
pub struct Temporary {
    path: PathBuf,
    target: PathBuf,
    committed: bool,
}

impl Temporary {
    /// Names a fresh temporary file beside `target`; nothing is created yet.
    pub fn beside(target: &Path) -> Self {
        Self {
            path: temporary_path(target),
            target: target.to_path_buf(),
            committed: false,
        }
    }

    /// Where the writer should put the content.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file this becomes.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Syncs the temporary file and renames it over the target.
    pub fn commit(mut self) -> std::io::Result<()> {
        std::fs::File::open(&self.path)?.sync_all()?;
        std::fs::rename(&self.path, &self.target)?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.committed {
            // The file may never have been created; either way nothing is left behind, and
            // whatever made the output fail is the error worth reporting.
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_via_temporary(
        path,
        |temporary| std::fs::File::create(temporary)?.write_all(bytes),
        |e| e,
    )
}

/// `.<name>.<pid>-<n>.tmp.<extension>` next to `path`.
fn temporary_path(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(
        ".{name}.{}-{}.tmp.{extension}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_leaves_nothing_on_failure() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path();
        let target = dir.join("a.txt");
        write_bytes(&target, b"first").unwrap();
        write_bytes(&target, b"second").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"second");
        let failed: Result<(), String> = write_via_temporary(
            &dir.join("b.png"),
            |temporary| {
                assert_eq!(temporary.extension().unwrap(), "png");
                std::fs::write(temporary, b"half").unwrap();
                Err("encoder failed".to_string())
            },
            |e| e.to_string(),
        );
        assert_eq!(failed, Err("encoder failed".to_string()));
        let names: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names, ["a.txt"]);
    }
}
