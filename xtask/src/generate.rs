//! `cargo xtask generate`: regenerates `generated/` from the pinned companion specifications.
//!
//! The model is compiled once (ns0, DI, IA and Robotics from `nodesets/vendor/`, our skill models from
//! `nodesets/`); each back end returns its files in memory; only when everything succeeded are the output
//! folders replaced, together and atomically (`write_trees`: both new trees are built before either folder
//! is replaced, and a failure puts back what was replaced). `--check` writes nothing and fails when a file is
//! stale.

use crate::util::workspace_root;
use nodeset_compiler::load::Input;
use nodeset_compiler::write::{write_trees, Mode, OutFile};
use nodeset_compiler::{compile, Options, RustOptions};
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Compare instead of writing; fail if anything is stale.
    #[arg(long)]
    check: bool,
    /// Treat generation warnings as errors.
    #[arg(long)]
    deny_warnings: bool,
    /// Another NodeSet2 file compiled with the pinned ones (the tests make generation fail with one).
    #[arg(long, value_name = "FILE", hide = true)]
    extra_input: Vec<PathBuf>,
    /// The folder to write instead of generated/ (the tests write into a copy).
    #[arg(long, value_name = "DIR", hide = true)]
    out: Option<PathBuf>,
}

/// The namespaces of `generated/`: (file under `nodesets/`, module name). The official specifications are
/// fetched into `nodesets/vendor/`; our skill models are committed in `nodesets/` itself.
pub const NAMESPACES: &[(&str, &str)] = &[
    ("vendor/Opc.Ua.Di.NodeSet2.xml", "di"),
    ("vendor/Opc.Ua.IA.NodeSet2.xml", "ia"),
    ("vendor/Opc.Ua.Robotics.NodeSet2.xml", "robotics"),
    ("CommonSkills.NodeSet2.xml", "common_skills"),
    ("RobotCell.NodeSet2.xml", "robot_cell"),
    ("DrillingProcess.NodeSet2.xml", "drilling_process"),
];

pub const COMMAND: &str = "cargo xtask generate";

/// Everything `generate` would write, by output folder, into the crate folder `crate_dir` (normally `generated/`), with further
/// input files compiled beside the pinned ones.
pub fn plan_into(crate_dir: &Path, extra_inputs: &[PathBuf], deny_warnings: bool) -> Result<Vec<(PathBuf, Vec<OutFile>)>, String> {
    let root = workspace_root();
    let vendor = root.join("nodesets/vendor");
    let inputs = NAMESPACES
        .iter()
        .map(|(f, _)| Input::Path(root.join("nodesets").join(f)))
        .chain(extra_inputs.iter().cloned().map(Input::Path))
        .collect();
    let mut opts = Options { model_dirs: vec![vendor.clone()], ..Options::default() };
    opts.severities.deny_warnings(deny_warnings);
    let left = |e: nodeset_compiler::Error| format!("{e}generated/ is left as it was");
    let mut out = compile(inputs, &opts);
    eprint!("{}", out.checked(&opts.severities).map_err(left)?);
    let model = &out.model;

    // Rust: the modules in this file's order, which is the order `mod.rs` registers them in.
    let mut rust = RustOptions { runtime_path: "crate::runtime".into(), command: COMMAND.into(), ..RustOptions::default() };
    let mut uris = Vec::new();
    for (file, module) in NAMESPACES {
        let m = model
            .models
            .iter()
            .find(|m| model.sources.get(m.file).path.file_name() == Path::new(file).file_name())
            .ok_or_else(|| format!("{file} defines no model"))?;
        rust.modules.insert(m.uri.clone(), (*module).to_string());
        uris.push(m.uri.clone());
    }
    let cfg = rust.config_of(&uris).map_err(left)?;
    let (rust, warnings) =
        nodeset_compiler::generate_rust(model, &cfg, Default::default(), &opts.severities).map_err(left)?;
    eprint!("{warnings}");
    // Modelica: one package per namespace (and the used part of ns0, and the support package).
    let mcfg = uris.iter().fold(nodeset_compiler::emit::modelica::ModelicaConfig::new(), |c, u| c.namespace(u.clone()));
    let (modelica, warnings) = nodeset_compiler::generate_modelica(model, &mcfg, &opts.severities).map_err(left)?;
    eprint!("{warnings}");
    Ok(vec![(crate_dir.join("src/models"), rust), (crate_dir.join("modelica"), modelica)])
}

pub fn run(args: Args) -> Result<(), String> {
    crate::fetch::ensure_fetched()?;
    let out = args.out.clone().unwrap_or_else(|| workspace_root().join("generated"));
    let plan = plan_into(&out, &args.extra_input, args.deny_warnings)?;
    write_plan(&plan, args.check)
}

/// Writes (or, with `check`, compares) the folders of a plan, all or nothing.
fn write_plan(plan: &[(PathBuf, Vec<OutFile>)], check: bool) -> Result<(), String> {
    let mode = if check { Mode::Check } else { Mode::Write };
    let reports = write_trees(plan, mode).map_err(|e| format!("{e}; generated/ is left as it was"))?;
    let mut stale = String::new();
    for ((dir, files), report) in plan.iter().zip(reports) {
        let shown = crate::util::display_path(dir);
        if check {
            if !report.is_clean() {
                stale.push_str(&report.describe(dir));
            }
        } else {
            println!(
                "{shown}: {} file(s), {} new, {} changed, {} removed, {} unchanged",
                files.len(),
                report.added.len(),
                report.changed.len(),
                report.removed.len(),
                report.unchanged
            );
        }
    }
    if !stale.is_empty() {
        return Err(format!("generated/ is stale:\n{stale}run `cargo xtask generate`"));
    }
    if check {
        println!("generated/ is up to date");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Everything `generate` would write into generated/.
    fn plan(deny_warnings: bool) -> Result<Vec<(PathBuf, Vec<OutFile>)>, String> {
        plan_into(&workspace_root().join("generated"), &[], deny_warnings)
    }

    /// generated/ must be what the compiler produces from the pinned specs today.
    #[test]
    fn generated_tree_is_fresh() {
        crate::fetch::ensure_fetched().expect("the pinned nodesets are needed; run `cargo xtask fetch-nodesets`");
        let plan = plan(false).expect("generation succeeds");
        let mut stale = String::new();
        for ((dir, _), report) in plan.iter().zip(write_trees(&plan, Mode::Check).expect("check mode reads only")) {
            stale.push_str(&report.describe(dir));
        }
        assert!(stale.is_empty(), "generated/ is stale:\n{stale}run `cargo xtask generate`");
    }

    /// Generation is a pure function of the inputs: twice the same bytes.
    #[test]
    fn generation_is_deterministic() {
        crate::fetch::ensure_fetched().expect("the pinned nodesets are needed");
        let a = plan(false).expect("generation succeeds");
        let b = plan(false).expect("generation succeeds");
        assert_eq!(a, b);
    }

    /// Every file below `dir` (relative to it) with its bytes, sorted.
    fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
        fn walk(base: &Path, dir: &Path, out: &mut Vec<(PathBuf, Vec<u8>)>) {
            for e in std::fs::read_dir(dir).expect("readable").flatten() {
                let p = e.path();
                if p.is_dir() {
                    walk(base, &p, out);
                } else {
                    out.push((p.strip_prefix(base).unwrap().to_path_buf(), std::fs::read(&p).expect("readable")));
                }
            }
        }
        let mut out = Vec::new();
        walk(dir, dir, &mut out);
        out.sort();
        out
    }

    /// The files of a crate folder, and the names in it and in its `src/`, so that a temporary folder left
    /// beside an output folder shows too.
    fn snapshot(dir: &Path) -> (Vec<(PathBuf, Vec<u8>)>, Vec<String>) {
        let mut beside: Vec<String> = ["", "src"]
            .iter()
            .flat_map(|sub| std::fs::read_dir(dir.join(sub)).expect("readable").flatten().map(move |e| format!("{sub}/{}", e.file_name().to_string_lossy())))
            .collect();
        beside.sort();
        (files(dir), beside)
    }

    fn copy_dir(from: &Path, to: &Path) {
        std::fs::create_dir_all(to).expect("create the copy");
        for e in std::fs::read_dir(from).expect("readable").flatten() {
            let (p, q) = (e.path(), to.join(e.file_name()));
            if p.is_dir() {
                copy_dir(&p, &q);
            } else {
                std::fs::copy(&p, &q).expect("copy a file");
            }
        }
    }

    /// A failed `cargo xtask generate` leaves the previous tree byte for byte as it was: when an invalid
    /// nodeset is among its inputs, and when writing fails midway (a file of the second folder cannot be
    /// created after the first folder's new tree was built). It runs against a copy of generated/ in which
    /// both folders are stale, so a successful run would have to replace both.
    #[test]
    fn failed_generation_leaves_the_previous_tree_unchanged() {
        crate::fetch::ensure_fetched().expect("the pinned nodesets are needed; run `cargo xtask fetch-nodesets`");
        let root = workspace_root();
        let tmp = std::env::temp_dir().join(format!("xtask-generate-atomic-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&tmp);
        let out = tmp.join("generated");
        for sub in ["src/models", "modelica"] {
            copy_dir(&root.join("generated").join(sub), &out.join(sub));
        }
        // Both folders stale: a file changed in each, a stray file in the first.
        std::fs::write(out.join("src/models/mod.rs"), "// an older generation\n").unwrap();
        std::fs::write(out.join("src/models/stale.rs"), "// removed by the next generation\n").unwrap();
        let mo = out.join("modelica/OpcUaSupport/package.mo");
        let text = std::fs::read_to_string(&mo).expect("the support package exists");
        std::fs::write(&mo, format!("{text}// an older generation\n")).unwrap();
        let before = snapshot(&out);
        let args = |extra_input: Vec<PathBuf>| Args { check: false, deny_warnings: false, extra_input, out: Some(out.clone()) };

        // 1. An invalid nodeset among the inputs.
        let bad = root.join("tests/fixtures/bad/truncated.xml");
        let err = run(args(vec![bad])).expect_err("a truncated nodeset fails generation");
        assert!(err.contains("left as it was"), "{err}");
        assert!(snapshot(&out) == before, "a failed compilation changed the output tree");

        // 2. Writing fails midway: the second folder gets a file below one of its files.
        let mut plan = plan_into(&out, &[], false).expect("the pinned nodesets generate");
        assert_eq!(plan.len(), 2);
        let first = plan[1].1[0].path.clone();
        plan[1].1.push(OutFile { path: first.join("cannot-be-below-a-file.mo"), contents: String::new() });
        let err = write_plan(&plan, false).expect_err("a file below a file cannot be written");
        assert!(err.contains("cannot") && err.contains("left as it was"), "{err}");
        assert!(snapshot(&out) == before, "a failure while writing changed the output tree");

        // 3. The same run without a fault replaces both folders: the copy is generated/ again.
        run(args(Vec::new())).expect("generation succeeds");
        let fresh: Vec<_> = ["src/models", "modelica"].iter().map(|sub| files(&root.join("generated").join(sub))).collect();
        let written: Vec<_> = ["src/models", "modelica"].iter().map(|sub| files(&out.join(sub))).collect();
        assert!(written == fresh, "the copy does not match generated/ after a successful run");
        let _ = std::fs::remove_dir_all(&tmp);
    }
}
