//! `pipeline`: the qrm command line, thin glue over `qrm_cli` (docs/ARCHITECTURE.md): it
//! parses the arguments, installs the interrupt handler and turns an error into exit status 2.

use clap::Parser;
use qrm_cli::{dispatch, Cli};
use std::process::ExitCode;

mod interrupt;

/// Output piped into a reader that stops early (`pipeline tables | head`) ends the process
/// quietly, as it does `cat`: Rust ignores SIGPIPE, so the next print would panic on the
/// broken pipe instead. Every command prints only after its files are written.
#[cfg(unix)]
fn end_quietly_on_broken_pipe() {
    // SAFETY: restoring a signal's default disposition at start-up, before any thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn end_quietly_on_broken_pipe() {}

/// Keeps freed full-frame buffers in the heap for the next panorama. Detection allocates a
/// few buffers of megabytes per panorama; glibc serves blocks that large by `mmap` and unmaps
/// them on free, so every panorama faulted its pages in afresh, a tenth of detection's time
/// (docs/BENCHMARKS.md, "Freed buffers kept in the heap"). A setting refused only costs speed.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_freed_buffers() {
    /// glibc's largest mmap threshold on 64-bit systems (`mallopt(3)`): larger than a
    /// 4096 × 768 frame of `f32`.
    const LARGEST_THRESHOLD: libc::c_int = 32 << 20;
    // SAFETY: allocator settings changed at start-up, before any thread exists.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, LARGEST_THRESHOLD);
        libc::mallopt(libc::M_TRIM_THRESHOLD, libc::c_int::MAX);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_freed_buffers() {}

fn main() -> ExitCode {
    end_quietly_on_broken_pipe();
    keep_freed_buffers();
    interrupt::install();
    match dispatch(Cli::parse()) {
        Ok(status) => status,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
