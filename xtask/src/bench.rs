//! `cargo xtask bench`: runs the bench, a program of its own (`bench/`, package `nodeset-bench`), with the
//! pinned companion specifications in place. Its arguments pass through: `cargo xtask bench --help` lists them.

use crate::util::{cargo, workspace_root};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The bench's arguments (`--scenario`, `--runs-robotics`, ...).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    args: Vec<String>,
}

pub fn run(args: Args) -> Result<(), String> {
    crate::fetch::ensure_fetched().map_err(|e| format!("{e}\n(the bench needs `cargo xtask fetch-nodesets` to succeed)"))?;
    let status = cargo()
        .current_dir(workspace_root())
        .args(["run", "--quiet", "--package", "nodeset-bench", "--"])
        .args(&args.args)
        .status()
        .map_err(|e| format!("cannot run the bench: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("the bench failed ({status})"))
    }
}
