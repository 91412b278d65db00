//! Where things are in the workspace, for `cargo xtask` and the bench: its root, its cargo and target folder.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Returns the root of the workspace, which is the parent of this crate's directory.
///
/// The path is fixed at compile time, so a tool behaves the same whichever directory it is started from.
pub fn workspace_root() -> PathBuf {
    let manifest_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    match manifest_dir.parent() {
        Some(parent) => parent.to_path_buf(),
        None => manifest_dir,
    }
}

/// A command for the cargo that runs this tool (`$CARGO`, else `cargo` from the `PATH`).
pub fn cargo() -> Command {
    Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
}

/// The developer's cargo target folder: `CARGO_TARGET_DIR` (relative to the workspace root unless
/// absolute), else `target/` in the workspace root.
pub fn target_dir() -> PathBuf {
    let root = workspace_root();
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) => root.join(dir),
        None => root.join("target"),
    }
}

/// Shows `path` relative to the workspace root when it lies inside it, for shorter messages.
pub fn display_path(path: &Path) -> String {
    let root = workspace_root();
    path.strip_prefix(&root)
        .unwrap_or(path)
        .display()
        .to_string()
}
