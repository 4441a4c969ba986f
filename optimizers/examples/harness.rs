//! The benchmark harness without the `czid` front door: the same code as `czid harness`
//! (`cargo run -p czid-optimizers --example harness -- --help`).

#[path = "../../src/commands/harness.rs"]
mod harness;

use clap::Parser;

/// Benchmark optimizers on test problems at equal evaluation budgets.
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: harness::HarnessArgs,
}

fn main() {
    if let Err(e) = harness::run(&Cli::parse().args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
