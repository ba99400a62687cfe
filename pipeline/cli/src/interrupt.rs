//! Ctrl-C and SIGTERM end a command without leaving half an output behind: every file is
//! written under a temporary name and renamed into place (`qrm_atomic_file`), a run's outputs
//! in one pass of renames; on an interrupt the handler waits for a pass under way, removes every
//! temporary file still live, and ends the process with status 130.

/// Installs the handler. If another handler is already installed, the default behaviour stays
/// (the process ends; temporary files, never the outputs, may be left).
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        let removed = qrm_atomic_file::abandon_all();
        eprintln!(
            "interrupted: no partial output left behind (outputs are replaced whole or not at all; {removed} temporary file{} removed)",
            if removed == 1 { "" } else { "s" }
        );
        std::process::exit(130);
    });
}
