//! `cargo xtask venv`: the Python virtual environment with the test peers of `tests/requirements.txt`.
//!
//! The venv lives in `.venv/` (git-ignored). A stamp file holds the SHA-256 of the requirements it was
//! built from, so the step is a no-op until the requirements change.

use crate::util::workspace_root;
use sha2::{Digest, Sha256};
use std::path::PathBuf;
use std::process::Command;

#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_: Args) -> Result<(), String> {
    let py = ensure_venv()?;
    println!("venv ready: {}", py.display());
    Ok(())
}

/// Creates or updates `.venv` and returns the path of its python.
pub fn ensure_venv() -> Result<PathBuf, String> {
    let root = workspace_root();
    let req = root.join("tests/requirements.txt");
    let venv = root.join(".venv");
    let python = venv.join("bin/python");
    let stamp = venv.join(".requirements.sha256");
    let text = std::fs::read(&req).map_err(|e| format!("cannot read {}: {e}", req.display()))?;
    let digest: String = Sha256::digest(&text).iter().map(|b| format!("{b:02x}")).collect();
    if python.is_file() && std::fs::read_to_string(&stamp).is_ok_and(|s| s.trim() == digest) {
        return Ok(python);
    }
    let host = ["python3", "python"]
        .into_iter()
        .find(|p| Command::new(p).arg("--version").output().is_ok_and(|o| o.status.success()))
        .ok_or("python3 is missing; install it (apt-get install -y python3 python3-venv)")?;
    if !python.is_file() {
        eprintln!("creating {}", venv.display());
        let st = Command::new(host)
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .map_err(|e| format!("cannot run {host} -m venv: {e}"))?;
        if !st.success() {
            return Err(format!("`{host} -m venv .venv` failed; on Debian install python3-venv (apt-get install -y python3-venv)"));
        }
    }
    eprintln!("installing the Python test peers from {}", req.display());
    let st = Command::new(&python)
        .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "-r"])
        .arg(&req)
        .status()
        .map_err(|e| format!("cannot run pip: {e}"))?;
    if !st.success() {
        return Err("pip install -r tests/requirements.txt failed (the packages come from PyPI)".into());
    }
    std::fs::write(&stamp, digest).map_err(|e| format!("cannot write {}: {e}", stamp.display()))?;
    Ok(python)
}
