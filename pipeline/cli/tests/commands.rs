//! The `pipeline` binary end to end: one test binary, a module per group of commands.

mod bad_input;
mod directions;
mod navigate;
mod run;
mod subcommands;

use std::process::{Command, Output};

/// Runs the binary with `args` and collects its output.
fn pipeline(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pipeline"))
        .args(args)
        .output()
        .expect("binary runs")
}
