//! `cargo xtask registry`: every NodeSet2 file of the pinned registry package (`node-opcua-nodesets`, all
//! of [`crate::fetch::SELECTION`]: the current specifications and the older files of its `1.02/` folder)
//! through the three things a user does with one: `check`, Rust that compiles, and Modelica that rumoca
//! accepts and that passes the structural checks (and, with `--pymoca`, that pymoca flattens). Each step prints its counts; the step fails when a
//! file does not resolve, when the Rust crate does not compile, or when a Modelica check rejects a class.
//!
//! Each file is compiled on its own with `nodesets/vendor/` as the model folder, as
//! `nodeset-compiler check FILE --models nodesets/vendor` does. The Rust is `cargo xtask corpus` over the
//! vendor folder (one module per file, the three of `1.02/` generated together, its dependencies the modules
//! of the files they resolve to, one `cargo check`; ns0 is async-opcua's own). The Modelica of each file is the `modelica` command's run
//! (every model it requires generated with it, the used part of ns0 as `OpcUa`), checked by
//! `tests/modelica/check.py --aggregate` (rumoca) and `structure.py` in the project's venv, two files at a
//! time; `--pymoca` adds `check2.py` (pymoca, class by class: over an hour, so not in `cargo xtask test`).

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
    /// Also flatten every class with pymoca, one at a time (`tests/modelica/check2.py`). About 1.2 s of CPU
    /// per class, over an hour for the package's ~6,500 classes, so it is not part of `cargo xtask test`;
    /// pymoca checks `generated/modelica` and the examples there.
    #[arg(long)]
    pymoca: bool,
}

/// The runs the registry package's files are named in: every current file alone; the older files of `1.02/`,
/// which declare no <Model> (so none of them can require another), together (DI, ADI, FTNIR), as a user of
/// that set must.
pub(crate) fn units(vendor: &Path) -> Vec<Vec<PathBuf>> {
    let files: Vec<PathBuf> = crate::fetch::SELECTION.iter().map(|w| vendor.join(w.name)).collect();
    let old_order = ["Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.Adi.NodeSet2.xml", "FTNIR.NodeSet2.xml"];
    let mut old: Vec<PathBuf> = files.iter().filter(|f| rel(vendor, f).starts_with("1.02/")).cloned().collect();
    old.sort_by_key(|f| old_order.iter().position(|n| f.ends_with(n)).unwrap_or(old_order.len()));
    let mut units: Vec<Vec<PathBuf>> = files.iter().filter(|f| !old.contains(f)).map(|f| vec![f.clone()]).collect();
    units.push(old);
    units
}

pub fn run(args: Args) -> Result<(), String> {
    let start = Instant::now();
    crate::fetch::ensure_fetched()?;
    let python = crate::venv::ensure_venv()?;
    let root = workspace_root();
    let vendor = root.join(crate::fetch::VENDOR_DIR).canonicalize().map_err(|e| format!("{}: {e}", crate::fetch::VENDOR_DIR))?;
    let out = args.out.unwrap_or_else(|| root.join("target/registry"));
    let files: Vec<PathBuf> = crate::fetch::SELECTION.iter().map(|w| vendor.join(w.name)).collect();
    let units = units(&vendor);
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
    // The checkers per file: rumoca (one aggregate model), the structural checks (tests/modelica/structure.py)
    // and, with --pymoca, pymoca (class by class: the second front end). Two workers: the CI machine has two cores.
    // rumoca leaves out the support package where it is generated/modelica's byte for byte (`--same-as`): the
    // modelica test checks that one class by class, and it refers to nothing outside itself.
    let same_as = format!("OpcUaSupport={}", root.join("generated/modelica").display());
    let rumoca_args = ["--aggregate", "--jobs", "1", "--same-as", same_as.as_str()];
    let mut checkers: Vec<(&str, &str, &[&str])> =
        vec![("rumoca", "check.py", &rumoca_args), ("structure", "structure.py", &[])];
    if args.pymoca {
        checkers.push(("pymoca", "check2.py", &["--jobs", "1"]));
    }
    type Outcome = Result<(String, usize, Vec<(usize, usize, f64, String)>), String>;
    // Each worker takes the next file when it is done with one.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Outcome> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|_| {
                let (jobs, python, root, checkers, next) = (&jobs, &python, &root, &checkers, &next);
                s.spawn(move || {
                    std::iter::from_fn(|| jobs.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed)))
                        .map(|(name, dir, classes)| {
                            let mut per = Vec::new();
                            for (_, script, args) in checkers {
                                let t = Instant::now();
                                let (p, fl, text) = checker(python, &root.join("tests/modelica").join(script), dir, args)?;
                                per.push((p, fl, t.elapsed().as_secs_f64(), text));
                            }
                            Ok((name.clone(), *classes, per))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("a checker worker panicked")).collect()
    });
    let mut classes = 0;
    let mut totals = vec![(0usize, 0usize, 0f64); checkers.len()];
    let mut problems = Vec::new();
    for r in results {
        let (name, c, per) = r?;
        classes += c;
        for (i, (p, fl, secs, text)) in per.into_iter().enumerate() {
            totals[i].0 += p;
            totals[i].1 += fl;
            totals[i].2 += secs;
            if fl > 0 || p != c {
                problems.push(format!("{name}: {c} classes, {}: {p} passed, {fl} failed\n{text}", checkers[i].0));
            }
        }
    }
    let counts: Vec<String> =
        checkers.iter().zip(totals).map(|((n, ..), (p, f, secs))| format!("{n}: {p} passed, {f} failed in {secs:.1} s")).collect();
    println!(
        "registry modelica: {} files, {classes} classes generated in {generation:.1} s; {} (seconds summed over two workers)",
        jobs.len(),
        counts.join("; ")
    );
    problems.sort();
    if !problems.is_empty() {
        return Err(format!("the Modelica checks reject {} registry file(s):\n{}", problems.len(), problems.join("\n")));
    }
    println!("registry: {} files through check, Rust and Modelica in {:.1} s", files.len(), start.elapsed().as_secs_f64());
    Ok(())
}

/// `file` relative to the vendor folder, for messages.
fn rel(vendor: &Path, file: &Path) -> String {
    file.strip_prefix(vendor).unwrap_or(file).display().to_string()
}

/// Runs a checker of `tests/modelica` (`check.py`, `check2.py` or `structure.py`) over `dir`: (passed, failed,
/// output). Passed counts the classes `check.py --same-as` left out, which pass in the reference tree.
fn checker(python: &Path, script: &Path, dir: &Path, args: &[&str]) -> Result<(usize, usize, String), String> {
    let out = Command::new(python)
        .arg(script)
        .arg(dir)
        .arg("--quiet")
        .args(args)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", script.display()))?;
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    // The last line of each checker's output is always `N passed, N failed`.
    let last = text
        .lines()
        .rev()
        .find(|l| l.ends_with(" failed"))
        .ok_or_else(|| format!("no summary line from {} for {}:\n{text}", script.display(), dir.display()))?;
    let nums: Vec<usize> = last.split_whitespace().filter_map(|w| w.trim_end_matches(',').parse().ok()).collect();
    let left_out: usize = text
        .lines()
        .filter_map(|l| l.strip_prefix("left out: "))
        .filter_map(|l| l.split_whitespace().next()?.parse::<usize>().ok())
        .sum();
    match nums.as_slice() {
        [p, f] => Ok((*p + left_out, *f, text)),
        _ => Err(format!("unexpected summary `{last}` from {} for {}", script.display(), dir.display())),
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
        let script = workspace_root().join("tests/modelica/check.py");
        let (passed, failed, text) = checker(&python, &script, &dir, &["--aggregate", "--jobs", "1"]).expect("check.py runs");
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!((passed, failed), (1, 1), "{text}");
    }
}
