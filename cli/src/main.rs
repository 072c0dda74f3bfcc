//! The `emray` command: parse the command line, run the command (`src/cmd/`), and turn
//! its error, if any, into one message and the exit status README.md documents.

mod cmd;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    match cmd::run(cmd::Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => e.report(),
    }
}
