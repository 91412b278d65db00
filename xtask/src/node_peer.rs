//! `cargo xtask node-peer`: the node-opcua test peer of `tests/node-peer/` (`npm ci` from its
//! `package-lock.json`, which pins node-opcua and node-opcua-nodesets; `node_modules/` is git-ignored).
//!
//! A stamp file in `node_modules/` holds the SHA-256 of the lock file it was installed from, so the step is
//! a no-op until the lock changes.

use crate::util::workspace_root;
use sha2::{Digest, Sha256};
use std::process::Command;

#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_: Args) -> Result<(), String> {
    ensure_node_peer()?;
    println!("node-opcua peer ready: tests/node-peer/node_modules");
    Ok(())
}

/// Installs the node-opcua peer unless it is installed from the current lock file.
pub fn ensure_node_peer() -> Result<(), String> {
    let dir = workspace_root().join("tests/node-peer");
    let lock = dir.join("package-lock.json");
    let stamp = dir.join("node_modules/.lock.sha256");
    let text = std::fs::read(&lock).map_err(|e| format!("cannot read {}: {e}", lock.display()))?;
    let digest: String = Sha256::digest(&text).iter().map(|b| format!("{b:02x}")).collect();
    if std::fs::read_to_string(&stamp).is_ok_and(|s| s.trim() == digest) {
        return Ok(());
    }
    let npm_ok = Command::new("npm").arg("--version").output().is_ok_and(|o| o.status.success());
    if !npm_ok {
        return Err("npm is missing; install Node.js 20 or newer with npm (apt-get install -y nodejs npm)".into());
    }
    eprintln!("installing the node-opcua test peer in {}", dir.display());
    let st = Command::new("npm")
        .current_dir(&dir)
        .args(["ci", "--no-audit", "--no-fund", "--ignore-scripts"])
        .status()
        .map_err(|e| format!("cannot run npm: {e}"))?;
    if !st.success() {
        return Err("`npm ci` in tests/node-peer failed (the packages come from the npm registry)".into());
    }
    std::fs::write(&stamp, digest).map_err(|e| format!("cannot write {}: {e}", stamp.display()))?;
    Ok(())
}
