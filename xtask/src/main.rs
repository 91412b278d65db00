//! Developer tasks for the nodeset-compiler workspace.
//!
//! Run them through the cargo alias defined in `.cargo/config.toml`, for
//! example `cargo xtask fetch-nodesets`. Every subcommand lives in its own
//! module; to add one, add a variant to [`Command`], a module that exposes an
//! `Args` struct and a `run(args) -> Result<(), String>` function, and one arm
//! in [`main`].

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod bench;
mod corpus;
mod fetch;
mod fuzz;
mod generate;
mod load;
mod one_at_a_time;
mod registry;
mod serve_corpus;
mod soak;
mod test;
mod user_crate;
mod util;
mod timing;
mod venv;
mod node_peer;

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
    /// Time the compiler and the runtime against their targets and async-opcua-codegen (a report, not a test;
    /// the program `bench/`, whose arguments pass through: `cargo xtask bench --help`).
    #[command(disable_help_flag = true)]
    Bench(bench::Args),
    /// Generate Rust for every resolvable ua-nodeset file into one crate and `cargo check` it.
    Corpus(corpus::Args),
    /// Every NodeSet2 file of a tree generated on its own (its dependencies with it), all compiled.
    OneAtATime(one_at_a_time::Args),
    /// Every NodeSet2 file of the pinned registry package through check, Rust (compiled) and Modelica (rumoca and
    /// the structural checks; `--pymoca` adds pymoca).
    Registry(registry::Args),
    /// Every file of the UA-Nodeset tree and of the registry package served with `nodeset-compiler serve
    /// --instantiate-all`, then checked with `nodeset-compiler verify`; figures and failures at the end.
    ServeCorpus(serve_corpus::Args),
    /// Run one cargo-fuzz target of fuzz/ for a number of seconds (installs cargo-fuzz, builds the seeds).
    Fuzz(fuzz::Args),
    /// Regenerate generated/ from the pinned companion specifications (`--check`: fail if stale).
    Generate(generate::Args),
    /// The generated robot server under client load: sessions subscribed to every axis variable, a writer.
    Load(load::Args),
    /// The robot cell runs DrillHole many times, a python asyncua client watching every skill's state.
    Soak(soak::Args),
    /// Everything a fresh machine needs (pinned nodesets, Python test peers), then every test.
    Test(test::Args),
    /// Build the user crate of README.md (`tests/user-crate`) outside the workspace, start it and connect.
    UserCrate(user_crate::Args),
    /// Create or update the Python venv `.venv` with the test peers of `tests/requirements.txt`.
    Venv(venv::Args),
    /// Install the node-opcua test peer of `tests/node-peer` (npm ci from its pinned package-lock.json).
    NodePeer(node_peer::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::FetchNodesets(args) => fetch::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Corpus(args) => corpus::run(args),
        Command::OneAtATime(args) => one_at_a_time::run(args),
        Command::Registry(args) => registry::run(args),
        Command::ServeCorpus(args) => serve_corpus::run(args),
        Command::Fuzz(args) => fuzz::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Load(args) => load::run(args),
        Command::Soak(args) => soak::run(args),
        Command::Test(args) => test::run(args),
        Command::UserCrate(args) => user_crate::run(args),
        Command::Venv(args) => venv::run(args),
        Command::NodePeer(args) => node_peer::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
