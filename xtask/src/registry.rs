//! `cargo xtask registry`: every NodeSet2 file of the pinned registry package (`node-opcua-nodesets`, all
//! of [`crate::fetch::SELECTION`]: the current specifications and the older files of its `1.02/` folder)
//! through the three things a user does with one: `check`, Rust that compiles, and Modelica that rumoca
//! accepts. Each step prints its counts; the step fails when a file does not resolve, when the Rust crate
//! does not compile, or when rumoca rejects a class.
//!
//! Each file is compiled on its own with `nodesets/vendor/` as the model folder, as
//! `nodeset-compiler check FILE --models nodesets/vendor` does. The Rust is `cargo xtask corpus` over the
//! vendor folder (one module per file, the three of `1.02/` generated together, its dependencies the modules
//! of the files they resolve to, one `cargo check`; ns0 is async-opcua's own). The Modelica of each file is the `modelica` command's run
//! (every model it requires generated with it, the used part of ns0 as `OpcUa`), checked by
//! `tests/modelica/check.py --aggregate` in the project's venv, two files at a time.

use crate::util::workspace_root;
use nodeset_compiler::diag::Severities;
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[derive(Debug, Default, clap::Args)]
pub struct Args {
    /// Where to put the generated Rust crate and Modelica folders (default: target/registry).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(args: Args) -> Result<(), String> {
    let start = Instant::now();
    crate::fetch::ensure_fetched()?;
    let python = crate::venv::ensure_venv()?;
    let root = workspace_root();
    let vendor = root.join(crate::fetch::VENDOR_DIR).canonicalize().map_err(|e| format!("{}: {e}", crate::fetch::VENDOR_DIR))?;
    let out = args.out.unwrap_or_else(|| root.join("target/registry"));
    let files: Vec<PathBuf> = crate::fetch::SELECTION.iter().map(|w| vendor.join(w.name)).collect();
    // The older files of `1.02/` declare no <Model>, so none of them can require another: they are named
    // together (DI, ADI, FTNIR), as a user of that set must. Every current file is named alone.
    let old_order = ["Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.Adi.NodeSet2.xml", "FTNIR.NodeSet2.xml"];
    let mut old: Vec<PathBuf> = files.iter().filter(|f| rel(&vendor, f).starts_with("1.02/")).cloned().collect();
    old.sort_by_key(|f| old_order.iter().position(|n| f.ends_with(n)).unwrap_or(old_order.len()));
    let mut units: Vec<Vec<PathBuf>> = files.iter().filter(|f| !old.contains(f)).map(|f| vec![f.clone()]).collect();
    units.push(old);
    let unit_name = |u: &[PathBuf]| u.iter().map(|f| rel(&vendor, f)).collect::<Vec<_>>().join(" + ");

    // 1. check.
    let t = Instant::now();
    let opts = Options { model_dirs: vec![vendor.clone()], ..Options::default() };
    let (mut errors, mut warnings, mut failed) = (0, 0, Vec::new());
    for u in &units {
        let compiled = compile(u.iter().cloned().map(Input::Path).collect(), &opts);
        let (e, w) = (compiled.diagnostics.error_count(), compiled.diagnostics.warning_count());
        println!("  check {}: {e} error(s), {w} warning(s)", unit_name(u));
        errors += e;
        warnings += w;
        if e > 0 {
            failed.push(format!("{}:\n{}", unit_name(u), compiled.render_diagnostics()));
        }
    }
    println!(
        "registry check: {} files in {} runs, {} runs resolve, {errors} error(s), {warnings} warning(s) in {:.1} s",
        files.len(),
        units.len(),
        units.len() - failed.len(),
        t.elapsed().as_secs_f64()
    );
    if !failed.is_empty() {
        return Err(format!("{} registry file(s) do not resolve:\n{}", failed.len(), failed.join("\n")));
    }

    // 2. Rust, compiled.
    let groups: Vec<Vec<PathBuf>> = units.iter().filter(|u| u.len() > 1).cloned().collect();
    crate::corpus::run_with_groups(crate::corpus::Args { tree: Some(vendor.clone()), out: Some(out.join("rust")) }, &groups)?;

    // 3. Modelica, checked by rumoca.
    let t = Instant::now();
    let modelica = out.join("modelica");
    let _ = std::fs::remove_dir_all(&modelica);
    let mut jobs: Vec<(String, PathBuf, usize)> = Vec::new();
    for (i, u) in units.iter().enumerate() {
        let compiled = compile(u.iter().cloned().map(Input::Path).collect(), &opts);
        let run = nodeset_compiler::run_modelica(&compiled.model, &Default::default(), &Severities::new())
            .map_err(|e| format!("{}: {e}", unit_name(u)))?;
        let dir = modelica.join(format!("{i:02}"));
        let mut classes = 0;
        for file in &run.files {
            let path = dir.join(&file.path);
            std::fs::create_dir_all(path.parent().unwrap_or(&dir)).map_err(|e| format!("{}: {e}", path.display()))?;
            std::fs::write(&path, &file.contents).map_err(|e| format!("{}: {e}", path.display()))?;
            if path.extension().is_some_and(|x| x == "mo") && !path.ends_with("package.mo") {
                classes += 1;
            }
        }
        jobs.push((unit_name(u), dir, classes));
    }
    let generation = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let checker = root.join("tests/modelica/check.py");
    // Two workers: the CI machine has two cores.
    let results: Vec<Result<(String, usize, usize, usize, String), String>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|w| {
                let (jobs, python, checker) = (&jobs, &python, &checker);
                s.spawn(move || {
                    jobs.iter()
                        .skip(w)
                        .step_by(2)
                        .map(|(name, dir, classes)| {
                            rumoca(python, checker, dir).map(|(p, fl, text)| (name.clone(), *classes, p, fl, text))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("a rumoca worker panicked")).collect()
    });
    let (mut classes, mut passed, mut failed, mut problems) = (0, 0, 0, Vec::new());
    for r in results {
        let (name, c, p, fl, text) = r?;
        classes += c;
        passed += p;
        failed += fl;
        if fl > 0 || p != c {
            problems.push(format!("{name}: {c} classes, rumoca: {p} passed, {fl} failed\n{text}"));
        }
    }
    println!(
        "registry modelica: {} files, {classes} classes generated in {generation:.1} s; rumoca: {passed} passed, {failed} failed in {:.1} s",
        jobs.len(),
        t.elapsed().as_secs_f64()
    );
    if !problems.is_empty() {
        return Err(format!("rumoca rejects the Modelica of {} registry file(s):\n{}", problems.len(), problems.join("\n")));
    }
    println!("registry: {} files through check, Rust and Modelica in {:.1} s", files.len(), start.elapsed().as_secs_f64());
    Ok(())
}

/// `file` relative to the vendor folder, for messages.
fn rel(vendor: &Path, file: &Path) -> String {
    file.strip_prefix(vendor).unwrap_or(file).display().to_string()
}

/// Runs `check.py --aggregate` over `dir`: (passed, failed, output).
fn rumoca(python: &Path, checker: &Path, dir: &Path) -> Result<(usize, usize, String), String> {
    let out = Command::new(python)
        .arg(checker)
        .arg(dir)
        .args(["--quiet", "--aggregate", "--jobs", "1"])
        .output()
        .map_err(|e| format!("cannot run {}: {e}", checker.display()))?;
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    // The last line of check.py's output is always `N passed, N failed`.
    let last = text.lines().rev().find(|l| l.ends_with(" failed")).ok_or_else(|| format!("no summary line from check.py for {}:\n{text}", dir.display()))?;
    let nums: Vec<usize> = last.split_whitespace().filter_map(|w| w.trim_end_matches(',').parse().ok()).collect();
    match nums.as_slice() {
        [p, f] => Ok((*p, *f, text)),
        _ => Err(format!("unexpected summary `{last}` from check.py for {}", dir.display())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rumoca stage fails on a class rumoca rejects: a package of two classes, one of which reads a
    /// variable that does not exist, gives `1 passed, 1 failed`, and `run` turns any failure into an error.
    #[test]
    fn the_rumoca_stage_counts_a_rejected_class() {
        let python = crate::venv::ensure_venv().expect("the project's venv (cargo xtask venv)");
        let dir = std::env::temp_dir().join(format!("xtask-registry-{}", std::process::id()));
        let pkg = dir.join("Planted");
        std::fs::create_dir_all(&pkg).unwrap();
        std::fs::write(pkg.join("package.mo"), "package Planted\nend Planted;\n").unwrap();
        std::fs::write(pkg.join("Good.mo"), "within Planted;\nmodel Good\n  Real x = 1;\nend Good;\n").unwrap();
        std::fs::write(pkg.join("Bad.mo"), "within Planted;\nmodel Bad\n  Real x = notDeclared;\nend Bad;\n").unwrap();
        let (passed, failed, text) = rumoca(&python, &workspace_root().join("tests/modelica/check.py"), &dir).expect("check.py runs");
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!((passed, failed), (1, 1), "{text}");
    }
}
