//! The `czid` command.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Identify cohesive-zone interface laws from laboratory tests.
#[derive(Parser)]
#[command(name = "czid", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the bundled end-to-end example.
    Demo,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Demo => demo(),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn demo() -> Result<(), czid_core::CzError> {
    Err(czid_core::CzError::config(
        "czid demo",
        "the end-to-end identification demo is not part of this version yet; \
         see the book's Quick start for what runs today",
    ))
}
