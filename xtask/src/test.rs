//! `cargo xtask test`: everything a fresh machine needs, then every test.
//!
//! 1. The pinned companion specs (`fetch-nodesets`, a no-op when they are present and verified).
//! 2. The Python venv with the test peers (`.venv`, from `tests/requirements.txt`) and the node-opcua peer
//!    (`tests/node-peer`, `cargo xtask node-peer`).
//! 3. `cargo test --workspace --locked`, whose summary lines CI reads; then `cargo xtask user-crate`: the
//!    README's user crate (`tests/user-crate`, not a workspace member) built, started and connected to.
//! 4. `cargo xtask corpus`: Rust for every resolvable ua-nodeset file, compiled; `cargo xtask registry`: every
//!    file of the pinned registry package through check, Rust (compiled) and Modelica (rumoca and the structural checks).
//! 5. `cargo xtask load --seconds 20`: the robot example under 50 subscribed client sessions and a writer.
//! 6. `cargo xtask soak`: the robot cell runs DrillHole 1,000 times, every skill state watched.
//! 7. Each fuzz target of `fuzz/` for [`FUZZ_SECS`] seconds (`cargo xtask fuzz`): CI exercises the targets
//!    and replays the corpus they grew on this machine before; a crash fails the run.

use crate::util::workspace_root;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Extra arguments passed to `cargo test` (after `--workspace --locked`), e.g. a test name filter.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    cargo_args: Vec<String>,
}

pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    crate::fetch::ensure_fetched()?;
    crate::venv::ensure_venv()?;
    crate::node_peer::ensure_node_peer()?;
    let shared = root.join("../shared/nodesets/ua-nodeset");
    if !shared.is_dir() {
        return Err(format!(
            "the ua-nodeset corpus is missing at {}; the tests need ../shared beside the project (CI provides it)",
            shared.display()
        ));
    }
    let status = crate::util::cargo()
        .current_dir(&root)
        .args(["test", "--workspace", "--locked"])
        .args(&args.cargo_args)
        .status()
        .map_err(|e| format!("cannot run cargo test: {e}"))?;
    if !status.success() {
        return Err(format!("cargo test failed ({status})"));
    }
    // The user crate of README.md, outside the workspace: built (in the same target folder), run, connected.
    crate::user_crate::run(crate::user_crate::Args::default())?;
    // The whole corpus as Rust, compiled: too long for a #[test] among others, so it runs after them.
    crate::corpus::run(crate::corpus::Args::default())?;
    // The registry package's 38 files, each as a user names it: resolved, as Rust compiled, as Modelica
    // checked by rumoca and the structural checks (about six minutes on two cores).
    crate::registry::run(crate::registry::Args::default())?;
    // The robot server under 50 client sessions, briefly (`cargo xtask load` runs five minutes).
    crate::load::run(crate::load::Args { sessions: 50, seconds: 20, publishing_ms: 100, release: false })?;
    // The robot cell, DrillHole 1,000 times in a row (about a minute).
    crate::soak::run(crate::soak::Args { runs: 1000, motion_ms: 5, release: false })?;
    for target in crate::fuzz::Target::ALL {
        crate::fuzz::run(crate::fuzz::Args { target, secs: FUZZ_SECS, libfuzzer_args: Vec::new() })?;
    }
    Ok(())
}

/// How long CI fuzzes each target: long enough to replay the seeds and mutate for a while, short enough
/// that the three targets with cargo-fuzz's installation and the instrumented build add a few minutes.
pub const FUZZ_SECS: u64 = 25;
