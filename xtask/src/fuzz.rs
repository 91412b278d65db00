//! `cargo xtask fuzz <target> <secs>`: one cargo-fuzz target of `fuzz/`, for a given time.
//!
//! 1. cargo-fuzz itself, pinned ([`CARGO_FUZZ_VERSION`]), installed from crates.io into
//!    `target/tools/` when that version is not there yet (`cargo install --locked`).
//! 2. A seed corpus built afresh from the repository's inputs into the git-ignored `fuzz/seeds/<target>/`
//!    (see [`seeds`]); the corpus libFuzzer grows is kept in the git-ignored `fuzz/corpus/<target>/` and
//!    reused by the next run.
//! 3. `cargo fuzz run` with the NodeSet2 dictionary (`fuzz/dict/nodeset2.dict`) for the XML targets,
//!    for `secs` seconds; its progress lines are passed on, then a summary of executions, coverage and
//!    corpus size.
//! 4. Any crash, timeout or out-of-memory input (a new file in `fuzz/artifacts/<target>/`) fails the
//!    command, naming the file and how to replay it.
//!
//! The toolchain is stable (`rust-toolchain.toml`), so the `-Z` flags cargo-fuzz passes to rustc (the
//! sanitizer-coverage passes libFuzzer needs) are enabled with `RUSTC_BOOTSTRAP=1`. AddressSanitizer works
//! that way too, but the targets are built with `--sanitizer none`: the compiler has no `unsafe` code, so
//! ASan can only find what safe Rust already rules out, and it cost 7x the executions a second (218 vs
//! 1,454 on the name target, measured side by side) and 500 MB of quarantine per process. Panics, overflow
//! checks and debug assertions are on either way; they are what finds bugs in this code.

use crate::util::{cargo, display_path, target_dir, workspace_root};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The cargo-fuzz release `cargo xtask fuzz` installs.
pub const CARGO_FUZZ_VERSION: &str = "0.13.2";

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
#[clap(rename_all = "snake_case")]
pub enum Target {
    /// Parse + load + resolve of one NodeSet2 file (with a reduced base namespace beside it).
    FrontEnd,
    /// The Rust and Modelica name sanitizers and name scopes.
    Names,
    /// The value decoder over the contents of one `<Value>`.
    Value,
}

impl Target {
    pub const ALL: [Target; 3] = [Target::FrontEnd, Target::Names, Target::Value];

    pub fn name(self) -> &'static str {
        match self {
            Target::FrontEnd => "front_end",
            Target::Names => "names",
            Target::Value => "value",
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which fuzz target to run.
    #[arg(value_enum)]
    pub target: Target,
    /// How long to fuzz, in seconds.
    pub secs: u64,
    /// Further libFuzzer options, after `--` (e.g. `-- -fork=1 -ignore_crashes=1` to go on after a crash).
    #[arg(last = true)]
    pub libfuzzer_args: Vec<String>,
}

/// Installs the pinned cargo-fuzz into `target/tools` unless it is there; returns its `bin` folder.
pub fn ensure_cargo_fuzz() -> Result<PathBuf, String> {
    let tools = target_dir().join("tools");
    let bin = tools.join("bin");
    let want = format!("cargo-fuzz {CARGO_FUZZ_VERSION}");
    let have = Command::new(bin.join("cargo-fuzz"))
        .arg("--version")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    if have == want {
        return Ok(bin);
    }
    eprintln!("installing {want} into {}", display_path(&tools));
    let status = cargo()
        .args(["install", "cargo-fuzz", "--locked", "--version", &format!("={CARGO_FUZZ_VERSION}"), "--root"])
        .arg(&tools)
        .status()
        .map_err(|e| format!("cannot run cargo install: {e}"))?;
    if !status.success() {
        return Err(format!(
            "cargo install cargo-fuzz --locked --version ={CARGO_FUZZ_VERSION} --root {} failed ({status})",
            tools.display()
        ));
    }
    Ok(bin)
}

/// Files below `dir` (recursively), sorted.
fn files_below(dir: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, &mut out);
    out.sort();
    out
}

/// The inner text of every outermost `<Value>...</Value>` of a NodeSet2 text.
pub fn value_contents(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = text;
    let mut offset = 0;
    while let Some(open) = rest.find("<Value>") {
        let start = offset + open + "<Value>".len();
        // Match nested <Value> elements (a Variant holds one) by counting.
        let mut depth = 1;
        let mut at = start;
        let end = loop {
            let next_open = text[at..].find("<Value>").map(|i| at + i);
            let Some(next_close) = text[at..].find("</Value>").map(|i| at + i) else { break None };
            match next_open {
                Some(o) if o < next_close => {
                    depth += 1;
                    at = o + "<Value>".len();
                }
                _ => {
                    depth -= 1;
                    at = next_close + "</Value>".len();
                    if depth == 0 {
                        break Some(next_close);
                    }
                }
            }
        };
        let Some(end) = end else { break };
        out.push(&text[start..end]);
        offset = end + "</Value>".len();
        rest = &text[offset..];
    }
    out
}

/// The names of a NodeSet2 text a generator turns into identifiers: BrowseNames (without their namespace
/// prefix), SymbolicNames and the Names of DataType fields, in order of appearance, without repeats.
pub fn names_in(text: &str) -> Vec<String> {
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    for attr in [" BrowseName=\"", " SymbolicName=\"", "<Field Name=\"", "<Definition Name=\""] {
        for (i, _) in text.match_indices(attr) {
            let value = &text[i + attr.len()..];
            let Some(end) = value.find('"') else { continue };
            let raw = &value[..end];
            let name = match raw.split_once(':') {
                Some((ns, rest)) if ns.chars().all(|c| c.is_ascii_digit()) => rest,
                _ => raw,
            };
            let name = name.replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&").replace("&quot;", "\"");
            if seen.insert(name.clone()) {
                out.push(name);
            }
        }
    }
    out
}

/// Seeds for a target, as (file name, contents), from the repository's fixtures (every file below
/// `tests/fixtures`), our skill nodesets, the pinned companion specs and, for the front end, the small
/// files of the ua-nodeset corpus.
pub fn seeds(target: Target) -> Result<Vec<(String, Vec<u8>)>, String> {
    let root = workspace_root();
    let fixtures = files_below(&root.join("tests/fixtures"));
    let mut texts: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    for p in &fixtures {
        let bytes = std::fs::read(p).map_err(|e| format!("cannot read {}: {e}", p.display()))?;
        texts.push((p.clone(), bytes));
    }
    // Larger inputs: ours and the pinned specs, for the values and names they hold.
    let mut large: Vec<PathBuf> = files_below(&root.join("nodesets")).into_iter().filter(|p| p.extension().is_some_and(|x| x == "xml")).collect();
    large.sort();
    let mut out: BTreeMap<String, Vec<u8>> = BTreeMap::new();
    let mut add = |name: String, bytes: Vec<u8>| {
        out.entry(name).or_insert(bytes);
    };
    match target {
        Target::FrontEnd => {
            for (p, bytes) in &texts {
                if bytes.len() <= 64 << 10 {
                    add(seed_name("fixture", p), bytes.clone());
                }
            }
            let corpus = root.join("../shared/nodesets/ua-nodeset");
            for p in files_below(&corpus) {
                let small = std::fs::metadata(&p).is_ok_and(|m| m.len() <= 16 << 10);
                if small && p.extension().is_some_and(|x| x.eq_ignore_ascii_case("xml")) {
                    let bytes = std::fs::read(&p).map_err(|e| format!("cannot read {}: {e}", p.display()))?;
                    if String::from_utf8_lossy(&bytes).contains("<UANodeSet") {
                        add(seed_name("ua-nodeset", &p), bytes);
                    }
                }
            }
        }
        Target::Value => {
            let mut seen = BTreeSet::new();
            let all = texts.iter().map(|(p, b)| (p.clone(), b.clone())).chain(large.iter().filter_map(|p| std::fs::read(p).ok().map(|b| (p.clone(), b))));
            for (p, bytes) in all {
                let text = String::from_utf8_lossy(&bytes);
                for (i, v) in value_contents(&text).into_iter().enumerate() {
                    if v.len() <= 4 << 10 && seen.len() < 2000 && seen.insert(v.trim().to_string()) {
                        add(format!("{}-{i}", seed_name("value", &p)), v.trim().as_bytes().to_vec());
                    }
                }
            }
        }
        Target::Names => {
            let all = texts.iter().map(|(p, b)| (p.clone(), b.clone())).chain(large.iter().filter_map(|p| std::fs::read(p).ok().map(|b| (p.clone(), b))));
            for (p, bytes) in all {
                let names = names_in(&String::from_utf8_lossy(&bytes));
                // The target reads at most 16 names an input.
                for (i, chunk) in names.chunks(16).enumerate() {
                    add(format!("{}-{i}", seed_name("names", &p)), chunk.join("\n").into_bytes());
                }
            }
        }
    }
    Ok(out.into_iter().collect())
}

/// A file name for a seed taken from `path`: the path's components joined by `_`.
fn seed_name(kind: &str, path: &Path) -> String {
    let root = workspace_root();
    let rel = path.strip_prefix(&root).unwrap_or(path).to_string_lossy().replace("../", "");
    let flat: String = rel.chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '_' }).collect();
    format!("{kind}-{flat}")
}

/// What libFuzzer said at the end of a run.
#[derive(Debug, Default)]
struct Summary {
    /// The last status line (`#N DONE cov: ... ft: ... corp: ... exec/s: ...`).
    last_status: Option<String>,
    stats: BTreeMap<String, String>,
}

fn count_files(dir: &Path) -> (usize, u64) {
    let files = files_below(dir);
    let bytes = files.iter().filter_map(|f| std::fs::metadata(f).ok()).map(|m| m.len()).sum();
    (files.len(), bytes)
}

pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    let target = args.target.name();
    // The front end's reduced base namespace is cut from the pinned one.
    crate::fetch::ensure_fetched()?;
    let bin = ensure_cargo_fuzz()?;
    let fuzz_dir = root.join("fuzz");
    // The fuzz workspace's lock file is committed; refuse to run with one that needs changes.
    let status = cargo()
        .args(["fetch", "--locked", "--manifest-path"])
        .arg(fuzz_dir.join("Cargo.toml"))
        .status()
        .map_err(|e| format!("cannot run cargo fetch: {e}"))?;
    if !status.success() {
        return Err("fuzz/Cargo.lock is out of date (`cargo fetch --locked` failed); update it with `cargo update --manifest-path fuzz/Cargo.toml` and commit it".into());
    }

    let seed_dir = fuzz_dir.join("seeds").join(target);
    let _ = std::fs::remove_dir_all(&seed_dir);
    std::fs::create_dir_all(&seed_dir).map_err(|e| format!("cannot create {}: {e}", seed_dir.display()))?;
    let seeds = seeds(args.target)?;
    for (name, bytes) in &seeds {
        std::fs::write(seed_dir.join(name), bytes).map_err(|e| format!("cannot write a seed: {e}"))?;
    }
    let corpus_dir = fuzz_dir.join("corpus").join(target);
    std::fs::create_dir_all(&corpus_dir).map_err(|e| format!("cannot create {}: {e}", corpus_dir.display()))?;
    let artifacts = fuzz_dir.join("artifacts").join(target);
    std::fs::create_dir_all(&artifacts).map_err(|e| format!("cannot create {}: {e}", artifacts.display()))?;
    let before: BTreeSet<PathBuf> = files_below(&artifacts).into_iter().collect();
    eprintln!("fuzz {target}: {} seeds in {}, corpus in {}", seeds.len(), display_path(&seed_dir), display_path(&corpus_dir));

    let fuzz_target_dir = target_dir().join("fuzz");
    let path = std::env::join_paths(std::iter::once(bin.clone()).chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())))
        .map_err(|e| format!("cannot extend PATH: {e}"))?;
    let mut cmd = cargo();
    cmd.current_dir(&root)
        .env("PATH", path)
        .env("RUSTC_BOOTSTRAP", "1")
        .args(["fuzz", "run", "--sanitizer", "none", "--target-dir"])
        .arg(&fuzz_target_dir)
        .arg(target)
        .arg(&corpus_dir)
        .arg(&seed_dir)
        .arg("--")
        .arg(format!("-max_total_time={}", args.secs))
        .arg("-timeout=30")
        .arg("-print_final_stats=1");
    if args.target != Target::Names {
        cmd.arg(format!("-dict={}", fuzz_dir.join("dict/nodeset2.dict").display()));
    }
    cmd.args(&args.libfuzzer_args).stderr(Stdio::piped());
    let mut child = cmd.spawn().map_err(|e| format!("cannot run cargo fuzz: {e}"))?;
    let mut summary = Summary::default();
    if let Some(err) = child.stderr.take() {
        for line in BufReader::new(err).lines() {
            let Ok(line) = line else { break };
            let event = line.split_whitespace().nth(1).unwrap_or("");
            if line.starts_with('#') && matches!(event, "NEW" | "REDUCE") || line.starts_with("\tNEW_FUNC") {
                // Every new corpus entry is a line; the pulse lines show progress well enough.
            } else {
                eprintln!("{line}");
            }
            if line.starts_with('#') && line.contains(" cov: ") {
                summary.last_status = Some(line.clone());
            }
            if let Some(stat) = line.strip_prefix("stat::") {
                if let Some((k, v)) = stat.split_once(':') {
                    summary.stats.insert(k.trim().to_string(), v.trim().to_string());
                }
            }
        }
    }
    let status = child.wait().map_err(|e| format!("cargo fuzz did not finish: {e}"))?;
    let new: Vec<PathBuf> = files_below(&artifacts).into_iter().filter(|p| !before.contains(p)).collect();
    let (corpus_files, corpus_bytes) = count_files(&corpus_dir);
    // Fork mode (`-fork=N`) prints no final stats; its status lines start with the execution count.
    let from_status = || {
        let status = summary.last_status.as_deref()?;
        Some(status.trim_start_matches('#').split(|c: char| !c.is_ascii_digit()).next()?.to_string())
    };
    let execs = summary.stats.get("number_of_executed_units").cloned().or_else(from_status).unwrap_or_else(|| "?".into());
    println!(
        "fuzz {target}: {execs} executions in {} s; last status: {}; corpus: {corpus_files} files, {corpus_bytes} bytes; crashes: {}",
        args.secs,
        summary.last_status.as_deref().unwrap_or("(none)"),
        new.len()
    );
    if !new.is_empty() {
        let binary = fuzz_target_dir.join("x86_64-unknown-linux-gnu/release").join(target);
        let list: Vec<String> = new.iter().map(|p| format!("  {}", display_path(p))).collect();
        return Err(format!(
            "fuzz target {target} found {} failing input(s):\n{}\nreplay one with `{} <file>`",
            new.len(),
            list.join("\n"),
            display_path(&binary)
        ));
    }
    if !status.success() {
        return Err(format!("cargo fuzz run {target} failed ({status})"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_contents_match_nested_values() {
        let text = "<Value><Int32>1</Int32></Value> x <Value><Variant><Value><String>a</String></Value></Variant></Value><Value>";
        assert_eq!(
            value_contents(text),
            vec!["<Int32>1</Int32>", "<Variant><Value><String>a</String></Value></Variant>"]
        );
    }

    #[test]
    fn names_drop_namespace_prefixes_and_repeats() {
        let text = r#"<UAObject BrowseName="1:&lt;AxisIdentifier&gt;" SymbolicName="Axis"/><UAObject BrowseName="Type"/><X BrowseName="1:Type"/><Field Name="Run-1"/>"#;
        assert_eq!(names_in(text), vec!["<AxisIdentifier>", "Type", "Axis", "Run-1"]);
    }

    /// Every target gets seeds from the repository (the front end's include the bad-input fixtures).
    #[test]
    fn every_target_has_seeds() {
        for t in Target::ALL {
            let s = seeds(t).expect("the fixtures are readable");
            assert!(s.len() >= 10, "{}: {} seeds", t.name(), s.len());
        }
        let fe = seeds(Target::FrontEnd).unwrap();
        assert!(fe.iter().any(|(n, _)| n.contains("truncated")), "the bad-input fixtures are front-end seeds");
    }
}
