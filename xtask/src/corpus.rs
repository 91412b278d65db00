//! `cargo xtask corpus`: Rust for every resolvable NodeSet2 file of `../shared/nodesets/ua-nodeset`, in one
//! crate, and `cargo check` of that crate.
//!
//! Each file becomes one module (named after its path in the tree, so two versions of a model are two
//! modules). A file's dependencies are not generated again: they are the modules of the files the loader
//! resolved them to (`extern_namespace`), so the crate shares every dependency. ns0 files are skipped: ns0
//! is async-opcua's own core namespace.

use crate::util::workspace_root;
use nodeset_compiler::build::Builder;
use nodeset_compiler::load::{Input, NS0_URI};
use nodeset_compiler::names::{sanitize, Case, Target};
use nodeset_compiler::{compile, Options};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Default, clap::Args)]
pub struct Args {
    /// The tree to compile (default: ../shared/nodesets/ua-nodeset).
    #[arg(long)]
    pub(crate) tree: Option<PathBuf>,
    /// Where to put the generated crate (default: target/corpus-crate).
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
}

pub(crate) fn module_for(tree: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(tree).unwrap_or(file).to_string_lossy().replace(".NodeSet2.xml", "").replace(".nodeset2.xml", "");
    format!("m_{}", sanitize(&rel, Case::Snake, Target::Rust).trim_start_matches("r#"))
}

pub(crate) fn nodeset_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            nodeset_files(&p, out);
        } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("xml")) {
            let head: Vec<u8> = std::fs::read(&p).map(|b| b.into_iter().take(8192).collect()).unwrap_or_default();
            if String::from_utf8_lossy(&head).contains("<UANodeSet") {
                out.push(p);
            }
        }
    }
}

/// The corpus crate's package name, unique per output folder. Cargo's fingerprint of a root package
/// leaves out its path: two corpus crates of one name in one target folder would share it, and the second
/// `cargo check` would pass on the first one's result without compiling anything.
pub fn package_name(out: &Path) -> String {
    let full = out.canonicalize().unwrap_or_else(|_| out.to_path_buf());
    // FNV-1a: stable across runs and toolchains (std's hasher is not).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in full.to_string_lossy().bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("nodeset-corpus-check-{h:016x}")
}

/// The start of `corpus` and `one-at-a-time`: the tree (default: ../shared/nodesets/ua-nodeset, made
/// canonical), the crate's `src/` folder in `out`, emptied, and the tree's NodeSet2 files in order.
pub(crate) fn prepare(tree: Option<PathBuf>, out: &Path) -> Result<(PathBuf, PathBuf, Vec<PathBuf>), String> {
    let tree = tree.unwrap_or_else(|| workspace_root().join("../shared/nodesets/ua-nodeset"));
    let tree = tree.canonicalize().map_err(|e| format!("{}: {e}", tree.display()))?;
    let src = out.join("src");
    let _ = std::fs::remove_dir_all(&src);
    std::fs::create_dir_all(&src).map_err(|e| format!("cannot create {}: {e}", src.display()))?;
    let mut files = Vec::new();
    nodeset_files(&tree, &mut files);
    files.sort();
    Ok((tree, src, files))
}

/// Generates every resolvable file of the tree into one crate, prints the counts, and `cargo check`s it.
pub fn run(args: Args) -> Result<(), String> {
    run_with_groups(args, &[])
}

/// [`run`], with `groups`: sets of files of the tree that resolve only named together (files without
/// `<Models>` cannot require one another). Each group is generated as one unit, its models one module each;
/// every other file is generated on its own.
pub fn run_with_groups(args: Args, groups: &[Vec<PathBuf>]) -> Result<(), String> {
    let root = workspace_root();
    let out = args.out.unwrap_or_else(|| root.join("target/corpus-crate"));
    let (tree, src, files) = prepare(args.tree, &out)?;
    let grouped: Vec<PathBuf> = groups.iter().flatten().map(|f| f.canonicalize().unwrap_or_else(|_| f.clone())).collect();
    let mut units: Vec<Vec<PathBuf>> = files.iter().filter(|f| !grouped.contains(f)).map(|f| vec![f.clone()]).collect();
    units.extend(groups.iter().cloned());

    let mut modules: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    let (mut generated, mut skipped_ns0, mut unresolved, mut warnings) = (0, 0, Vec::new(), 0usize);
    let opts = Options { model_dirs: vec![tree.clone()], ..Options::default() };
    for unit in &units {
        let compiled = compile(unit.iter().cloned().map(Input::Path).collect(), &opts);
        if !compiled.ok() {
            unresolved.push(unit.clone());
            continue;
        }
        let model = &compiled.model;
        let own: Vec<_> = model.models.iter().filter(|m| model.sources.get(m.file).named).collect();
        if own.iter().any(|m| m.uri == NS0_URI) {
            skipped_ns0 += 1;
            continue;
        }
        // A model's module: its file's, numbered when the file holds several models.
        let module_of = |m: &nodeset_compiler::load::ModelInfo| {
            let file = model.sources.get(m.file).path.canonicalize().unwrap_or_else(|_| model.sources.get(m.file).path.clone());
            let in_file: Vec<_> = model.models.iter().filter(|x| x.file == m.file).collect();
            let module = module_for(&tree, &file);
            match in_file.iter().position(|x| x.uri == m.uri) {
                Some(i) if in_file.len() > 1 => format!("{module}_{i}"),
                _ => module,
            }
        };
        let module = module_for(&tree, &unit[0]);
        let mut b = Builder::new().cargo_output(false).models_dir(&tree).out_dir(&src).out_file(&format!("{module}.rs"));
        b = unit.iter().fold(b, |b, f| b.file(f)).runtime_path("nodeset_models::runtime");
        for m in &own {
            b = b.module_name(&m.uri, &module_of(m));
        }
        for m in model.models.iter().filter(|m| !model.sources.get(m.file).named && m.uri != NS0_URI) {
            b = b.extern_namespace(&m.uri, &format!("crate::{}", module_of(m)));
        }
        b.generate().map_err(|e| format!("{}: {e}", unit[0].display()))?;
        modules.insert(module, unit.clone());
        generated += unit.len();
        warnings += compiled.diagnostics.warning_count();
    }
    let mut lib = String::from("//! Every resolvable NodeSet2 file of a tree, generated by `cargo xtask corpus`.\n#![allow(warnings)]\n\n");
    // Each unit in a module of its own, since each has its `register()` (as the Builder writes it); its
    // namespace modules are re-exported at the root, where the other units' extern paths name them.
    for m in modules.keys() {
        lib.push_str(&format!("mod unit_{m} {{\n    include!(\"{m}.rs\");\n}}\npub use unit_{m}::*;\n"));
    }
    std::fs::write(src.join("lib.rs"), lib).map_err(|e| e.to_string())?;
    let models_path = root.join("generated");
    let manifest = format!(
        "[package]\nname = \"{}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n[workspace]\n\n[dependencies]\nasync-opcua = {{ version = \"=0.19.0\", features = [\"server\"] }}\nbitflags = \"2\"\nnodeset-models = {{ path = \"{}\" }}\n",
        package_name(&out),
        models_path.display()
    );
    std::fs::write(out.join("Cargo.toml"), manifest).map_err(|e| e.to_string())?;
    // Share the lock file and the target folder with the workspace, so nothing is built twice.
    let _ = std::fs::copy(root.join("Cargo.lock"), out.join("Cargo.lock"));
    let lines: usize = modules.keys().map(|m| std::fs::read_to_string(src.join(format!("{m}.rs"))).map(|t| t.lines().count()).unwrap_or(0)).sum();
    println!(
        "corpus: {} files, {generated} generated as Rust ({lines} lines; {} named together), {skipped_ns0} ns0 files skipped (async-opcua's own), {} not resolvable",
        files.len(),
        groups.iter().map(Vec::len).sum::<usize>(),
        unresolved.iter().map(Vec::len).sum::<usize>()
    );
    for u in &unresolved {
        let names: Vec<String> = u.iter().map(|f| f.display().to_string()).collect();
        println!("  not resolvable: {}", names.join(" + "));
    }
    let start = std::time::Instant::now();
    cargo_check(&out)?;
    println!("corpus: cargo check of {} generated modules ({generated} files) passed in {:.1} s ({warnings} model warnings)", modules.len(), start.elapsed().as_secs_f64());
    Ok(())
}

/// `cargo check` of a generated corpus crate in the target folder of the workspace (its dependencies are
/// shared with the workspace's build; the crate's own name is unique to `out`, see [`package_name`]).
pub fn cargo_check(out: &Path) -> Result<(), String> {
    let status = crate::util::cargo()
        .current_dir(out)
        .env("CARGO_TARGET_DIR", crate::util::target_dir())
        .args(["check", "--quiet", "--message-format", "short"])
        .status()
        .map_err(|e| format!("cannot run cargo check: {e}"))?;
    if !status.success() {
        return Err(format!("the generated corpus crate does not compile ({status}); see {}", out.display()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tree of ns0 and the structure fixture, generated into a corpus crate.
    fn small_tree(dir: &Path) -> PathBuf {
        let root = workspace_root();
        let tree = dir.join("tree");
        std::fs::create_dir_all(&tree).unwrap();
        for f in ["nodesets/vendor/Opc.Ua.NodeSet2.xml", "tests/fixtures/structure/Example.Structure.NodeSet2.xml"] {
            let from = root.join(f);
            std::fs::copy(&from, tree.join(from.file_name().unwrap())).unwrap();
        }
        tree
    }

    /// The corpus check compiles: a crate that compiles passes; then a second crate in another folder,
    /// the same generated code with a compile error planted in one module, fails, although the first one's
    /// build is in the same target folder (before package names were unique per folder, it passed).
    #[test]
    fn corpus_check_fails_on_a_planted_compile_error() {
        let dir = std::env::temp_dir().join(format!("xtask-corpus-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let tree = small_tree(&dir);
        let (good, bad) = (dir.join("good"), dir.join("bad"));
        run(Args { tree: Some(tree.clone()), out: Some(good.clone()) }).expect("the structure fixture's corpus crate compiles");
        run(Args { tree: Some(tree), out: Some(bad.clone()) }).expect("the same crate in a second folder compiles");
        assert_ne!(package_name(&good), package_name(&bad), "two corpus folders, two package names");
        let module = std::fs::read_dir(bad.join("src"))
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .find(|p| p.file_name().is_some_and(|n| n != "lib.rs"))
            .expect("a generated module");
        let mut text = std::fs::read_to_string(&module).unwrap();
        text.push_str("\nconst PLANTED: u8 = \"not a number\";\n");
        std::fs::write(&module, text).unwrap();
        let err = cargo_check(&bad).expect_err("a planted compile error fails the corpus check");
        assert!(err.contains("does not compile"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
