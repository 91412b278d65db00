//! `cargo xtask one-at-a-time`: every NodeSet2 file of a tree generated on its own, as a user runs
//! `nodeset-compiler rust FILE --models TREE`: the file named, its dependencies found in the tree and generated
//! with it (the command's run, `nodeset_compiler::run_rust`), nothing mapped. Each file's
//! output is one module of one crate (so the dependencies of the crate are built once), and one
//! `cargo check` compiles them all. ns0 files are answered with NS0303 and counted as such.

use crate::corpus::{cargo_check, module_for, package_name, prepare};
use crate::util::workspace_root;
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Error, Options, RustOptions};
use std::path::PathBuf;

/// Options of `cargo xtask one-at-a-time`.
#[derive(Debug, Default, clap::Args)]
pub struct Args {
    /// The tree whose files are generated one at a time (default: ../shared/nodesets/ua-nodeset).
    #[arg(long)]
    tree: Option<PathBuf>,
    /// Where to put the generated crate (default: target/one-at-a-time-crate).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Generates every file of the tree on its own into one crate, prints the counts, and `cargo check`s it;
/// fails when a file does not resolve on its own, or when no file was generated.
pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    let out = args.out.unwrap_or_else(|| root.join("target/one-at-a-time-crate"));
    let (tree, src, files) = prepare(args.tree, &out)?;
    let start = std::time::Instant::now();
    let opts = Options { model_dirs: vec![tree.clone()], ..Options::default() };
    let (mut modules, mut ns0, mut unresolved, mut lines) = (Vec::new(), 0usize, Vec::new(), 0usize);
    for f in &files {
        let compiled = compile(vec![Input::Path(f.clone())], &opts);
        if !compiled.ok() {
            unresolved.push(f.clone());
            continue;
        }
        let model = &compiled.model;
        let rust = RustOptions { command: "cargo xtask one-at-a-time".into(), ..RustOptions::default() };
        let run = match nodeset_compiler::run_rust(model, &rust, &opts.severities) {
            Ok(run) => run,
            Err(e @ Error::Diagnostics { .. }) if e.diagnostics().contains("error[NS0303]") => {
                ns0 += 1;
                continue;
            }
            Err(e) => return Err(format!("{}: {e}", f.display())),
        };
        let module = module_for(&tree, f);
        for file in &run.files {
            let path = src.join(&module).join(&file.path);
            std::fs::create_dir_all(path.parent().unwrap()).map_err(|e| e.to_string())?;
            std::fs::write(&path, &file.contents).map_err(|e| format!("{}: {e}", path.display()))?;
            lines += file.contents.lines().count();
        }
        modules.push(module);
    }
    let generation = start.elapsed().as_secs_f64();
    let mut lib = String::from("//! Every resolvable file of a tree generated on its own, by `cargo xtask one-at-a-time`.\n#![allow(warnings)]\n\n");
    for m in &modules {
        lib.push_str(&format!("#[path = \"{m}/mod.rs\"]\npub mod {m};\n"));
    }
    std::fs::write(src.join("lib.rs"), lib).map_err(|e| e.to_string())?;
    let manifest = format!(
        "[package]\nname = \"{}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n[workspace]\n\n[dependencies]\nasync-opcua = {{ version = \"=0.19.0\", features = [\"server\"] }}\nbitflags = \"2\"\nnodeset-models = {{ path = \"{}\" }}\n",
        package_name(&out).replace("corpus-check", "one-at-a-time"),
        root.join("generated").display()
    );
    std::fs::write(out.join("Cargo.toml"), manifest).map_err(|e| e.to_string())?;
    let _ = std::fs::copy(root.join("Cargo.lock"), out.join("Cargo.lock"));
    println!(
        "one-at-a-time: {} files of {}: {} generated on their own ({lines} lines, {generation:.1} s), {ns0} ns0 files refused with NS0303, {} not resolvable",
        files.len(),
        tree.display(),
        modules.len(),
        unresolved.len()
    );
    for u in &unresolved {
        println!("  not resolvable: {}", u.display());
    }
    if modules.is_empty() {
        // A check of nothing is no check (a tree without ns0, say, resolves no file).
        return Err(format!("one-at-a-time: no file of {} generated, nothing to compile", tree.display()));
    }
    let start = std::time::Instant::now();
    cargo_check(&out)?;
    println!("one-at-a-time: cargo check of {} outputs passed in {:.1} s", modules.len(), start.elapsed().as_secs_f64());
    if !unresolved.is_empty() {
        return Err(format!(
            "one-at-a-time: {} file(s) do not resolve on their own (listed above; `nodeset-compiler check FILE --models {}` says why)",
            unresolved.len(),
            tree.display()
        ));
    }
    Ok(())
}
