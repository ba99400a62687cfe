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

fn main() -> ExitCode {
    end_quietly_on_broken_pipe();
    interrupt::install();
    match dispatch(Cli::parse()) {
        Ok(status) => status,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
