//! Shared helpers of the integration tests: where the workspace, the pinned nodesets and the corpus are.

use std::path::{Path, PathBuf};

pub mod synth;

/// The workspace root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("tests/ sits in the workspace").to_path_buf()
}

/// The executable of a `bin` or `example` target of the workspace, from `cargo test --workspace --no-run`:
/// the build `cargo test --workspace` has just done, so nothing is compiled again (`cargo build --example`
/// resolves features differently and rebuilt async-opcua). Asked of cargo once per test binary.
pub fn executable(kind: &str, name: &str) -> PathBuf {
    static ARTIFACTS: std::sync::OnceLock<Vec<process_support::Artifact>> = std::sync::OnceLock::new();
    ARTIFACTS
        .get_or_init(|| process_support::cargo_artifacts(&root(), &["test", "--workspace", "--no-run"]).unwrap_or_else(|e| panic!("{e}")))
        .iter()
        .find(|a| a.kind == kind && a.name == name)
        .map(|a| a.path.clone())
        .unwrap_or_else(|| panic!("cargo test --workspace --no-run built no {kind} `{name}`"))
}

/// The folder `cargo xtask fetch-nodesets` fills with the pinned companion specs.
pub fn vendor() -> PathBuf {
    let dir = root().join("nodesets/vendor");
    assert!(
        dir.join("Opc.Ua.NodeSet2.xml").is_file(),
        "the pinned nodesets are missing from {}; run `cargo xtask fetch-nodesets` first",
        dir.display()
    );
    dir
}

/// The OPC Foundation UA-Nodeset tree beside the project (`../shared/nodesets/ua-nodeset`).
pub fn corpus() -> PathBuf {
    let dir = root().join("../shared/nodesets/ua-nodeset");
    assert!(dir.is_dir(), "the ua-nodeset corpus is missing at {}; CI puts ../shared beside the project", dir.display());
    dir
}

/// Every NodeSet2 file below a folder (root element UANodeSet), sorted.
pub fn nodeset_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    walk(dir, &mut out);
    out.sort();
    out
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            walk(&p, out);
        } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("xml")) {
            let head = std::fs::read(&p).map(|b| b.into_iter().take(8192).collect::<Vec<u8>>()).unwrap_or_default();
            if String::from_utf8_lossy(&head).contains("<UANodeSet") {
                out.push(p);
            }
        }
    }
}

/// The `nodeset-compiler` command's executable: the one `cargo test --workspace` has built (see [`executable`]).
/// A `cargo build -p nodeset-compiler --bin nodeset-compiler` of its own resolved the dependencies' features
/// for that package alone, and so compiled async-opcua and 27 other crates a second time (about 200 s of a cold
/// CI run).
pub fn command_binary() -> PathBuf {
    executable("bin", "nodeset-compiler")
}
