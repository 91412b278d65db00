//! `cargo xtask test`: everything a fresh machine needs, then every test, then a table of where the time went.
//!
//! 1. The pinned companion specs (`fetch-nodesets`, a no-op when they are present and verified).
//! 2. The Python venv with the test peers (`.venv`, from `tests/requirements.txt`) and the node-opcua peer
//!    (`tests/node-peer`, `cargo xtask node-peer`).
//! 3. `cargo test --workspace --locked`, as three parts so that each test binary gets its own row: the build
//!    (`--no-run`), each test binary run as cargo runs it (in its package's folder, with cargo's environment;
//!    each prints the `test result:` summary CI reads), and the doc tests (`--doc`); then `cargo xtask
//!    user-crate`: the README's user crate (`tests/user-crate`, not a workspace member) built, started and
//!    connected to.
//! 4. `cargo xtask corpus`: Rust for every resolvable ua-nodeset file, compiled; `cargo xtask registry`: every
//!    file of the pinned registry package through check, Rust (compiled) and Modelica (rumoca and the structural checks).
//! 5. `cargo xtask load --seconds 20`: the robot example under 50 subscribed client sessions and a writer.
//! 6. `cargo xtask soak`: the robot cell runs DrillHole 1,000 times, every skill state watched.
//! 7. Each fuzz target of `fuzz/` for [`FUZZ_SECS`] seconds (`cargo xtask fuzz`): CI exercises the targets
//!    and replays the corpus they grew on this machine before; a crash fails the run.
//!
//! A failing test binary or step fails the run, and the steps after it still run (a prerequisite that fails,
//! the fetch or the build, stops the run). Either way the run ends with the timing table (wall and CPU
//! seconds of each step and each test binary, see [`crate::timing`]), which is also written to
//! `target/ci-timing.txt`.

use crate::timing::{Outcome, Row, Table};
use crate::util::{display_path, target_dir, workspace_root};
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Extra arguments of `cargo test` (after `--workspace --locked`): cargo options, a test name filter, and
    /// after `--` the options of the test binaries (e.g. `-- --nocapture`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    cargo_args: Vec<String>,
}

/// The file the timing table is written to, below the target folder.
pub const TIMING_FILE: &str = "ci-timing.txt";

pub fn run(args: Args) -> Result<(), String> {
    let mut table = Table::default();
    if let Some(row) = xtask_build_row() {
        table.push(row);
    }
    let failures = steps(&mut table, &args);
    let text = table.render();
    println!("\ncargo xtask test: where the time went\n{text}");
    let file = target_dir().join(TIMING_FILE);
    if let Err(e) = std::fs::create_dir_all(target_dir()).and_then(|()| std::fs::write(&file, &text)) {
        eprintln!("cannot write {}: {e}", file.display());
    } else {
        println!("(also in {})", display_path(&file));
    }
    if failures.is_empty() {
        Ok(())
    } else {
        Err(format!("{} step(s) failed:\n  {}", failures.len(), failures.join("\n  ")))
    }
}

/// Runs every step, each timed; returns the failures. A failed prerequisite ends the run early.
fn steps(table: &mut Table, args: &Args) -> Vec<String> {
    let mut failures = Vec::new();
    let root = workspace_root();
    let prerequisites = table
        .time("fetch", crate::fetch::ensure_fetched)
        .and_then(|()| table.time("venv", || crate::venv::ensure_venv().map(|_| ())))
        .and_then(|()| table.time("node-peer", crate::node_peer::ensure_node_peer))
        .and_then(|()| {
            let shared = root.join("../shared/nodesets/ua-nodeset");
            if shared.is_dir() {
                Ok(())
            } else {
                Err(format!(
                    "the ua-nodeset corpus is missing at {}; the tests need ../shared beside the project (CI provides it)",
                    shared.display()
                ))
            }
        });
    if let Err(e) = prerequisites {
        return vec![e];
    }
    let (cargo_args, filters, binary_args) = split_args(&args.cargo_args);
    let binaries = match table.time("cargo build (tests)", || build_tests(&root, &cargo_args)) {
        Ok(b) => b,
        Err(e) => return vec![e],
    };
    for b in &binaries {
        let name = format!("test {} {}", b.package, b.label());
        if let Err(e) = table.time(&name, || run_test_binary(b, &filters, &binary_args)) {
            failures.push(e);
        }
    }
    if let Err(e) = table.time("cargo test --doc", || doc_tests(&root, &cargo_args, &filters, &binary_args)) {
        failures.push(e);
    }
    if !args.cargo_args.is_empty() {
        // A filtered run is a developer's: the long steps below are not what they asked for.
        return failures;
    }
    let mut step = |name: &str, f: &mut dyn FnMut() -> Result<(), String>| {
        if let Err(e) = table.time(name, f) {
            failures.push(format!("{name}: {e}"));
        }
    };
    // The user crate of README.md, outside the workspace: built (in the same target folder), run, connected.
    step("user crate", &mut || crate::user_crate::run(crate::user_crate::Args::default()));
    // The whole corpus as Rust, compiled: too long for a #[test] among others, so it runs after them.
    step("corpus", &mut || crate::corpus::run(crate::corpus::Args::default()));
    // The registry package's 38 files, each as a user names it: resolved, as Rust compiled, as Modelica
    // checked by rumoca and the structural checks.
    step("registry", &mut || crate::registry::run(crate::registry::Args::default()));
    // The robot server under 50 client sessions, briefly (`cargo xtask load` runs five minutes).
    step("load", &mut || crate::load::run(crate::load::Args { sessions: 50, seconds: 20, publishing_ms: 100, release: false }));
    // The robot cell, DrillHole 1,000 times in a row (about a minute).
    step("soak", &mut || crate::soak::run(crate::soak::Args { runs: 1000, motion_ms: 5, release: false }));
    for target in crate::fuzz::Target::ALL {
        step(&format!("fuzz {}", target.name()), &mut || {
            crate::fuzz::run(crate::fuzz::Args { target, secs: FUZZ_SECS, libfuzzer_args: Vec::new() })
        });
    }
    failures
}

/// How long CI fuzzes each target: long enough to replay the seeds and mutate for a while, short enough
/// that the three targets with cargo-fuzz's installation and the instrumented build add a few minutes.
pub const FUZZ_SECS: u64 = 25;

/// The row of the build `.ci/run` does before it starts xtask (the workspace's tests and xtask), passed on in
/// `NODESET_XTASK_BUILD` as `WALL CPU` (seconds).
fn xtask_build_row() -> Option<Row> {
    let value = std::env::var("NODESET_XTASK_BUILD").ok()?;
    let mut parts = value.split_whitespace().map(|p| p.parse::<f64>());
    let (Some(Ok(wall)), Some(Ok(cpu))) = (parts.next(), parts.next()) else { return None };
    Some(Row { name: "cargo build (workspace + xtask, by .ci/run)".into(), wall, cpu, outcome: Outcome::Passed })
}

/// `cargo test` arguments split into what cargo takes, the test name filters (cargo's `TESTNAME`, passed on
/// to every test binary) and what follows `--` (the test binaries' own options).
fn split_args(args: &[String]) -> (Vec<String>, Vec<String>, Vec<String>) {
    // cargo test's options that take a value, so that the value is not mistaken for a filter.
    const WITH_VALUE: &[&str] = &[
        "-p", "--package", "--exclude", "--test", "--bench", "--bin", "--example", "-F", "--features", "--target",
        "--profile", "-j", "--jobs", "--manifest-path", "--target-dir", "--color", "--config", "-Z", "--message-format",
    ];
    let (mut cargo, mut filters, mut binary) = (Vec::new(), Vec::new(), Vec::new());
    let mut iter = args.iter();
    let mut takes_value = false;
    while let Some(a) = iter.next() {
        if a == "--" {
            binary.extend(iter.by_ref().cloned());
            break;
        }
        if takes_value {
            cargo.push(a.clone());
            takes_value = false;
        } else if a.starts_with('-') {
            takes_value = WITH_VALUE.contains(&a.as_str());
            cargo.push(a.clone());
        } else {
            filters.push(a.clone());
        }
    }
    (cargo, filters, binary)
}

/// A test executable `cargo test --no-run` built, with what is needed to run it as cargo does.
#[derive(Debug, Clone)]
struct TestBinary {
    package: String,
    version: String,
    manifest: PathBuf,
    /// The target's kind (`lib`, `bin`, `test`, `proc-macro`, ...) and name.
    kind: String,
    target: String,
    src_path: PathBuf,
    exe: PathBuf,
}

impl TestBinary {
    /// The target as a row names it: `lib`, `bin NAME`, `--test NAME`, ...
    fn label(&self) -> String {
        match self.kind.as_str() {
            "lib" | "proc-macro" => "lib".to_owned(),
            "test" => format!("--test {}", self.target),
            kind => format!("{kind} {}", self.target),
        }
    }

    /// The order cargo runs them in: package, then libraries, binaries, integration tests, by name.
    fn order(&self) -> (String, u8, String) {
        let rank = match self.kind.as_str() {
            "lib" | "proc-macro" => 0,
            "bin" => 1,
            "test" => 2,
            _ => 3,
        };
        (self.package.clone(), rank, self.target.clone())
    }
}

/// The string value of `"key":"..."` in a JSON line, searched from `from` (cargo's messages have no escapes
/// in the fields read here, except in paths with quotes or backslashes, which are unescaped).
fn json_str(line: &str, from: usize, key: &str) -> Option<(String, usize)> {
    let pat = format!("\"{key}\":\"");
    let start = from + line[from..].find(&pat)? + pat.len();
    let mut value = String::new();
    let mut chars = line[start..].char_indices();
    while let Some((i, c)) = chars.next() {
        match c {
            '"' => return Some((value, start + i + 1)),
            '\\' => match chars.next()?.1 {
                'n' => value.push('\n'),
                't' => value.push('\t'),
                other => value.push(other),
            },
            c => value.push(c),
        }
    }
    None
}

/// One `compiler-artifact` message of cargo, if it is a test executable.
fn parse_artifact(line: &str) -> Option<TestBinary> {
    if !line.starts_with("{\"reason\":\"compiler-artifact\"") {
        return None;
    }
    let profile = line.find("\"profile\":{")?;
    let profile_end = profile + line[profile..].find('}')?;
    if !line[profile..profile_end].contains("\"test\":true") {
        return None;
    }
    let exe = PathBuf::from(json_str(line, 0, "executable")?.0);
    let (package_id, _) = json_str(line, 0, "package_id")?;
    let (manifest, _) = json_str(line, 0, "manifest_path")?;
    let target = line.find("\"target\":{")?;
    // `"kind":["lib"]`: the first string of the list.
    let k = target + line[target..].find("\"kind\":[\"")? + "\"kind\":[\"".len();
    let kind = line[k..k + line[k..].find('"')?].to_owned();
    let (name, _) = json_str(line, target, "name")?;
    let (src_path, _) = json_str(line, target, "src_path")?;
    // `path+file:///dir/pkg#0.1.0` (the folder is the package's name) or `path+file:///dir#name@0.1.0`.
    let (url, fragment) = package_id.rsplit_once('#')?;
    let (package, version) = match fragment.split_once('@') {
        Some((n, v)) => (n.to_owned(), v.to_owned()),
        None => (url.rsplit('/').next()?.to_owned(), fragment.to_owned()),
    };
    Some(TestBinary { package, version, manifest: PathBuf::from(manifest), kind, target: name, src_path: PathBuf::from(src_path), exe })
}

/// `cargo test --workspace --locked --no-run`: builds every test executable (the examples and binaries the
/// tests start too) and returns the test executables in the order cargo runs them.
fn build_tests(root: &Path, cargo_args: &[String]) -> Result<Vec<TestBinary>, String> {
    let output = crate::util::cargo()
        .current_dir(root)
        .args(["test", "--workspace", "--locked", "--no-run", "--message-format=json-render-diagnostics"])
        .args(cargo_args)
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run cargo test: {e}"))?;
    if !output.status.success() {
        return Err(format!("cargo test --no-run failed ({})", output.status));
    }
    let mut binaries: Vec<TestBinary> = String::from_utf8_lossy(&output.stdout).lines().filter_map(parse_artifact).collect();
    binaries.sort_by_key(TestBinary::order);
    binaries.dedup_by(|a, b| a.exe == b.exe);
    if binaries.is_empty() {
        return Err("cargo test --no-run reported no test executable".into());
    }
    Ok(binaries)
}

/// Runs one test executable as `cargo test` does: in its package's folder, with the environment cargo gives
/// a test it runs (`CARGO`, `CARGO_MANIFEST_DIR`, `CARGO_PKG_*`, ...). Its output goes straight to ours.
fn run_test_binary(b: &TestBinary, filters: &[String], binary_args: &[String]) -> Result<(), String> {
    let dir = b.manifest.parent().ok_or("a manifest has a folder")?;
    let src = b.src_path.strip_prefix(dir).unwrap_or(&b.src_path);
    eprintln!("     Running {} ({})", src.display(), display_path(&b.exe));
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut version = b.version.splitn(3, '.');
    let (major, minor) = (version.next().unwrap_or("0"), version.next().unwrap_or("0"));
    let rest = version.next().unwrap_or("0");
    let (patch, pre) = rest.split_once('-').unwrap_or((rest, ""));
    let status = std::process::Command::new(&b.exe)
        .current_dir(dir)
        .env("CARGO", cargo)
        .env("CARGO_MANIFEST_DIR", dir)
        .env("CARGO_MANIFEST_PATH", &b.manifest)
        .env("CARGO_PKG_NAME", &b.package)
        .env("CARGO_PKG_VERSION", &b.version)
        .env("CARGO_PKG_VERSION_MAJOR", major)
        .env("CARGO_PKG_VERSION_MINOR", minor)
        .env("CARGO_PKG_VERSION_PATCH", patch)
        .env("CARGO_PKG_VERSION_PRE", pre)
        .env("CARGO_CRATE_NAME", b.target.replace('-', "_"))
        .args(filters)
        .args(binary_args)
        .status()
        .map_err(|e| format!("cannot run {}: {e}", b.exe.display()))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("test {} {} failed ({status})", b.package, b.label()))
    }
}

/// `cargo test --workspace --locked --doc`: the doc tests (their dependencies are built already). Without
/// nodeset-derive, which has none (`doctest = false`): `--doc` would build its doc-test harness anyway, and a
/// proc macro's harness resolves its dev-dependencies for the host, i.e. async-opcua and the generated models
/// compiled a second time with other features.
fn doc_tests(root: &Path, cargo_args: &[String], filters: &[String], binary_args: &[String]) -> Result<(), String> {
    let mut cmd = crate::util::cargo();
    cmd.current_dir(root).args(["test", "--workspace", "--exclude", "nodeset-derive", "--locked", "--doc"]).args(cargo_args).args(filters);
    if !binary_args.is_empty() {
        cmd.arg("--").args(binary_args);
    }
    let status = cmd.status().map_err(|e| format!("cannot run cargo test --doc: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("cargo test --doc failed ({status})"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_split_into_cargo_options_filters_and_test_options() {
        let args: Vec<String> = ["-p", "nodeset-tests", "modelica", "--release", "--", "--nocapture", "x"].iter().map(|s| s.to_string()).collect();
        let (cargo, filters, binary) = split_args(&args);
        assert_eq!(cargo, ["-p", "nodeset-tests", "--release"]);
        assert_eq!(filters, ["modelica"]);
        assert_eq!(binary, ["--nocapture", "x"]);
    }

    /// A test executable of cargo's JSON messages: package and version from both forms of package id, the
    /// target's kind and name; a non-test artifact is skipped.
    #[test]
    fn test_executables_are_read_from_cargos_messages() {
        let test = r#"{"reason":"compiler-artifact","package_id":"path+file:///w/tests#nodeset-tests@0.0.0","manifest_path":"/w/tests/Cargo.toml","target":{"kind":["test"],"crate_types":["bin"],"name":"modelica","src_path":"/w/tests/tests/modelica.rs","edition":"2021","doctest":false,"test":true},"profile":{"opt_level":"0","debuginfo":1,"debug_assertions":true,"overflow_checks":true,"test":true},"features":[],"filenames":["/t/debug/deps/modelica-1"],"executable":"/t/debug/deps/modelica-1","fresh":true}"#;
        let b = parse_artifact(test).expect("a test executable");
        assert_eq!((b.package.as_str(), b.version.as_str(), b.kind.as_str(), b.target.as_str()), ("nodeset-tests", "0.0.0", "test", "modelica"));
        assert_eq!(b.manifest, PathBuf::from("/w/tests/Cargo.toml"));
        assert_eq!(b.exe, PathBuf::from("/t/debug/deps/modelica-1"));
        assert_eq!(b.label(), "--test modelica");
        let lib = test.replace("#nodeset-tests@0.0.0", "#0.1.0").replace("\"kind\":[\"test\"]", "\"kind\":[\"lib\"]");
        let b = parse_artifact(&lib.replace("file:///w/tests", "file:///w/nodeset-runtime")).expect("a unit test executable");
        assert_eq!((b.package.as_str(), b.version.as_str(), b.label().as_str()), ("nodeset-runtime", "0.1.0", "lib"));
        let example = test.replace(",\"test\":true},\"features\"", ",\"test\":false},\"features\"");
        assert!(parse_artifact(&example).is_none(), "an example built for the tests is not a test executable");
    }
}
