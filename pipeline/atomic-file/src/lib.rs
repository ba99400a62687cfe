//! Files written whole or not at all: every output of the project (maps, figures, panoramas,
//! truth files) is produced under a uniquely named temporary file beside its target, synced,
//! and renamed over it; on failure the temporary file is removed. A reader — or a batch that
//! crashed half-way — never sees a half-written file, and concurrent writers of the same target
//! do not trample each other's temporary files.
//!
//! Outputs that belong together (a run's map, records and recordings) are staged as an
//! [`OutputSet`] and renamed in one quick pass once all are written, so that a run either
//! replaces all of an earlier run's files or none. An interrupt handler calls [`abandon_all`]:
//! it waits for a pass of renames under way to finish, then removes every temporary file still
//! live, so that an interrupted process leaves the earlier outputs as they were and nothing
//! half-written beside them.
//!
//! A target that exists and is not a regular file (`/dev/null`, a named pipe, a terminal) is
//! not replaced: renaming over it would turn a device into a plain file (for `/dev/null`,
//! breaking every later process that writes to it). Its content is staged in the system's
//! temporary folder and copied into it at commit; such a target is written, not swapped.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Temporary files created and neither committed nor removed yet.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
/// Held while an [`OutputSet`] renames its files, and by [`abandon_all`].
static RENAMING: Mutex<()> = Mutex::new(());
/// Held while a temporary file is created ([`create_file`]), and by [`abandon_all`]: a file
/// is either created before the temporaries are removed (and removed with them) or never.
static CREATING: Mutex<()> = Mutex::new(());
/// Set by [`abandon_all`]: no temporary file is named after it.
static ABANDONED: AtomicBool = AtomicBool::new(false);

/// A lock that a panic elsewhere does not make unusable: the data are plain lists.
fn lock<T>(mutex: &'static Mutex<T>) -> MutexGuard<'static, T> {
    mutex
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes every live temporary file of this process, after any [`OutputSet::commit`] under
/// way has finished; for an interrupt handler that then ends the process. Returns how many
/// files were removed. The renaming and creating locks stay held until the process ends, so
/// that no set is committed half-way and no temporary file is created after this (writers on
/// other threads wait until the process ends). Every temporary file must be created with
/// [`create_file`] for this to hold: a file created otherwise after its name was registered
/// could outlive the sweep.
pub fn abandon_all() -> usize {
    ABANDONED.store(true, Ordering::SeqCst);
    std::mem::forget(lock(&RENAMING));
    std::mem::forget(lock(&CREATING));
    let live = std::mem::take(&mut *lock(&LIVE));
    live.iter()
        .filter(|path| std::fs::remove_file(path).is_ok())
        .count()
}

fn register(path: &Path) {
    if ABANDONED.load(Ordering::SeqCst) {
        // The process is ending: a new output would not be removed.
        let _wait = lock(&CREATING);
    }
    lock(&LIVE).push(path.to_path_buf());
}

/// Creates (or truncates) the temporary file `path` for writing; waits for the process to end
/// instead if [`abandon_all`] has run.
pub fn create_file(path: &Path) -> std::io::Result<std::fs::File> {
    let _creating = lock(&CREATING);
    std::fs::File::create(path)
}

/// Writes `bytes` to the temporary file `path` ([`create_file`]).
pub fn write_file(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    create_file(path)?.write_all(bytes)
}

fn unregister(path: &Path) {
    let mut live = lock(&LIVE);
    if let Some(i) = live.iter().position(|p| p == path) {
        live.swap_remove(i);
    }
}

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
    /// Names a fresh temporary file beside `target` (in the system's temporary folder when
    /// `target` is a device or pipe, see the crate documentation); nothing is created yet.
    pub fn beside(target: &Path) -> Self {
        let path = if is_special(target) {
            std::env::temp_dir().join(
                temporary_path(target)
                    .file_name()
                    .expect("a temporary name has a file name"),
            )
        } else {
            temporary_path(target)
        };
        register(&path);
        Self {
            path,
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
    pub fn commit(self) -> std::io::Result<()> {
        // Synced under the lock: after [`abandon_all`] the file is gone, and a failed sync
        // would report an error while the process is ending on the interrupt.
        let _renaming = lock(&RENAMING);
        self.sync()?;
        self.rename()
    }

    fn sync(&self) -> std::io::Result<()> {
        std::fs::File::open(&self.path)?.sync_all()
    }

    fn rename(mut self) -> std::io::Result<()> {
        if is_special(&self.target) {
            let mut content = std::fs::File::open(&self.path)?;
            let mut target = std::fs::OpenOptions::new().write(true).open(&self.target)?;
            std::io::copy(&mut content, &mut target)?;
            std::fs::remove_file(&self.path)?;
        } else {
            std::fs::rename(&self.path, &self.target)?;
        }
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
        unregister(&self.path);
    }
}

/// Outputs that replace an earlier set together: each is written to its temporary file as it
/// is staged, and [`OutputSet::commit`] syncs them all, then renames them all and removes the
/// earlier set's files this one does not replace. Dropped uncommitted, it removes its
/// temporary files and the earlier outputs stay as they were.
#[derive(Debug, Default)]
pub struct OutputSet {
    staged: Vec<Temporary>,
    stale: Vec<PathBuf>,
}

impl OutputSet {
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Stages `path`, written by `write` into its temporary file.
    pub fn stage<E>(
        &mut self,
        path: &Path,
        write: impl FnOnce(&Path) -> Result<(), E>,
    ) -> Result<(), E> {
        let temporary = Temporary::beside(path);
        write(temporary.path())?;
        self.staged.push(temporary);
        Ok(())
    }

    /// Stages `path` with content `bytes`.
    pub fn stage_bytes(&mut self, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
        self.stage(path, |temporary| write_file(temporary, bytes))
    }

    /// Adds a temporary file written elsewhere (a recording).
    pub fn adopt(&mut self, temporary: Temporary) {
        self.staged.push(temporary);
    }

    /// Removes `path` at commit, if it exists: an earlier output this set does not replace.
    pub fn remove_stale(&mut self, path: &Path) {
        self.stale.push(path.to_path_buf());
    }

    /// Syncs every staged file, then renames each over its target and removes the stale
    /// files. An interrupt waits for the renames ([`abandon_all`]).
    pub fn commit(self) -> std::io::Result<()> {
        // Synced under the lock, as in [`Temporary::commit`].
        let _renaming = lock(&RENAMING);
        for temporary in &self.staged {
            temporary.sync()?;
        }
        for temporary in self.staged {
            temporary.rename()?;
        }
        for path in &self.stale {
            match std::fs::remove_file(path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
                _ => {}
            }
        }
        Ok(())
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_via_temporary(path, |temporary| write_file(temporary, bytes), |e| e)
}

/// Whether `path` exists and is neither a regular file nor a folder (following links): a
/// device, pipe or socket, which is written into rather than replaced.
fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
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

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    }

    /// `--json /dev/null` once turned the machine's `/dev/null` into a plain file. A named
    /// pipe takes the same path as a device, without risking the machine's `/dev/null`.
    #[cfg(unix)]
    #[test]
    fn a_pipe_or_device_is_written_into_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let scratch = tempfile::tempdir().unwrap();
        let pipe = scratch.path().join("out.fifo");
        let made = std::process::Command::new("mkfifo").arg(&pipe).status();
        assert!(made.unwrap().success(), "mkfifo made the pipe");
        let reader = |pipe: PathBuf| std::thread::spawn(move || std::fs::read(pipe).unwrap());
        let read = reader(pipe.clone());
        let is_pipe = || std::fs::metadata(&pipe).unwrap().file_type().is_fifo();
        write_bytes(&pipe, b"through the pipe").unwrap();
        // Checked before joining: a replaced pipe would leave the reader waiting.
        assert!(is_pipe(), "the pipe was replaced by a file");
        assert_eq!(read.join().unwrap(), b"through the pipe");
        let read = reader(pipe.clone());
        let mut set = OutputSet::new();
        set.stage_bytes(&pipe, b"a set through the pipe").unwrap();
        set.commit().unwrap();
        assert!(is_pipe(), "the pipe was replaced by a file");
        assert_eq!(read.join().unwrap(), b"a set through the pipe");
        assert_eq!(names(scratch.path()), ["out.fifo"]);
    }

    #[test]
    fn a_set_replaces_all_or_nothing() {
        let scratch = tempfile::tempdir().unwrap();
        let dir = scratch.path();
        for name in ["map.json", "eval.json", "notes.txt"] {
            std::fs::write(dir.join(name), b"old").unwrap();
        }
        // Abandoned: the earlier files stay, no temporary is left.
        let mut set = OutputSet::new();
        set.stage_bytes(&dir.join("map.json"), b"new").unwrap();
        set.stage_bytes(&dir.join("rng.json"), b"new").unwrap();
        set.remove_stale(&dir.join("eval.json"));
        drop(set);
        assert_eq!(names(dir), ["eval.json", "map.json", "notes.txt"]);
        assert_eq!(std::fs::read(dir.join("map.json")).unwrap(), b"old");
        // Committed: every staged file replaced, the stale one gone, the rest untouched.
        let mut set = OutputSet::new();
        set.stage_bytes(&dir.join("map.json"), b"new").unwrap();
        let recording = Temporary::beside(&dir.join("run.mcap"));
        std::fs::write(recording.path(), b"new").unwrap();
        set.adopt(recording);
        set.remove_stale(&dir.join("eval.json"));
        set.remove_stale(&dir.join("never-written.png"));
        set.commit().unwrap();
        assert_eq!(names(dir), ["map.json", "notes.txt", "run.mcap"]);
        assert_eq!(std::fs::read(dir.join("run.mcap")).unwrap(), b"new");
        assert_eq!(std::fs::read(dir.join("notes.txt")).unwrap(), b"old");
    }
}
