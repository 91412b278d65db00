//! Developer tasks for the nodeset-compiler workspace.
//!
//! Run them through the cargo alias defined in `.cargo/config.toml`, for
//! example `cargo xtask fetch-nodesets`. Every subcommand lives in its own
//! module; to add one, add a variant to [`Command`], a module that exposes an
//! `Args` struct and a `run(args) -> Result<(), String>` function, and one arm
//! in [`main`].

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod fetch;
mod util;

/// The top-level command line of `cargo xtask`.
#[derive(Debug, Parser)]
#[command(
    name = "cargo xtask",
    about = "Developer tasks for the nodeset-compiler workspace"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// One variant per subcommand; each wraps the arguments of its own module.
#[derive(Debug, Subcommand)]
enum Command {
    /// Fetch the pinned official NodeSet2 files into `nodesets/vendor/` and verify them against
    /// `nodesets/node-opcua-nodesets.lock`.
    FetchNodesets(fetch::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::FetchNodesets(args) => fetch::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
