//! An example server started as a user starts it: its binary, from the build of `cargo test --workspace`
//! (`cargo test --workspace --no-run`, a no-op when it is up to date), run as a child process
//! ([`process_support::Process`]); and the user file such a server is started with. Included with
//! `#[path = "common/example.rs"] mod example;`.

#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::Mutex;

use nodeset_models::runtime::server::{Role, Users};
pub use process_support::Process;

/// The password of the Operator `op` in [`operator_files`]'s user file.
pub const PASSWORD: &str = "op-secret-1";

/// The executables of the examples built so far by this test binary: (name, path).
static BUILT: Mutex<Vec<(String, PathBuf)>> = Mutex::new(Vec::new());

/// The executable of the example `name`, built first if this test binary has not built it yet.
pub fn executable(name: &str) -> PathBuf {
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, path)) = built.iter().find(|(n, _)| n == name) {
        return path.clone();
    }
    // The build `cargo test --workspace` has done (a no-op here when it is up to date): `cargo build -p
    // nodeset-examples --example NAME` resolves the dependencies' features for this package alone and compiled
    // async-opcua, the runtime and the models a second time (about three minutes of a cold CI run).
    let artifacts = process_support::cargo_artifacts(env!("CARGO_MANIFEST_DIR").as_ref(), &["test", "--workspace", "--no-run"])
        .unwrap_or_else(|e| panic!("{e}"));
    let path = artifacts
        .into_iter()
        .find(|a| a.kind == "example" && a.name == name)
        .map(|a| a.path)
        .unwrap_or_else(|| panic!("cargo built no example `{name}`"));
    built.push((name.to_owned(), path.clone()));
    path
}

/// Builds (if needed) and starts the example `name` with `args`.
pub fn start(name: &str, args: &[&str]) -> Process {
    Process::start(&executable(name), args)
}

/// A fresh folder `nodeset-<prefix>-<name>-<pid>` in the system's temporary directory, with a user file
/// (`users.txt`) that makes `op` an Operator with [`PASSWORD`]: (folder, user file).
pub fn operator_files(prefix: &str, name: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("nodeset-{prefix}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the temporary folder can be created");
    let mut users = Users::default();
    users.set_password("op", vec![Role::Operator], PASSWORD).expect("a user");
    let file = dir.join("users.txt");
    std::fs::write(&file, users.to_text()).expect("the user file is written");
    (dir, file)
}
