//! `cargo xtask generate`: regenerates `generated/` from the pinned companion specifications.
//!
//! The model is compiled once (ns0, DI, IA and Robotics from `nodesets/vendor/`, our skill models from
//! `nodesets/`); each back end returns its files in memory; only when everything succeeded are the output
//! folders replaced, each atomically (`write_tree`). `--check` writes nothing and fails when a file is stale.

use crate::util::workspace_root;
use nodeset_compiler::emit::rust::{self as rust_emit, RustConfig, RustNamespace};
use nodeset_compiler::load::Input;
use nodeset_compiler::write::{write_tree, Mode, OutFile};
use nodeset_compiler::{compile, Options};
use std::path::{Path, PathBuf};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Compare instead of writing; fail if anything is stale.
    #[arg(long)]
    check: bool,
    /// Treat generation warnings as errors.
    #[arg(long)]
    deny_warnings: bool,
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

/// Everything `generate` would write, by output folder.
pub fn plan(deny_warnings: bool) -> Result<Vec<(PathBuf, Vec<OutFile>)>, String> {
    let root = workspace_root();
    let vendor = root.join("nodesets/vendor");
    let inputs = NAMESPACES.iter().map(|(f, _)| Input::Path(root.join("nodesets").join(f))).collect();
    let out = compile(inputs, &Options { model_dirs: vec![vendor.clone()], deny_warnings, ..Options::default() });
    let rendered = out.render_diagnostics();
    if !out.ok() {
        return Err(format!("{rendered}the pinned nodesets do not compile; generated/ is left as it was"));
    }
    eprint!("{rendered}");
    let model = &out.model;

    let mut namespaces = Vec::new();
    for (file, module) in NAMESPACES {
        let m = model
            .models
            .iter()
            .find(|m| model.sources.get(m.file).path.file_name() == Path::new(file).file_name())
            .ok_or_else(|| format!("{file} defines no model"))?;
        namespaces.push(RustNamespace { uri: m.uri.clone(), module: (*module).to_string() });
    }
    let cfg = RustConfig {
        namespaces: namespaces.clone(),
        extern_paths: Default::default(),
        runtime_path: "crate::runtime".into(),
        command: COMMAND.into(),
    };
    let mut rust = rust_emit::generate(model, &cfg);
    let mut diags = rust.diagnostics;
    if deny_warnings {
        diags.deny_warnings();
    }
    diags.sort(&model.sources);
    eprint!("{}", diags.render(&model.sources));
    if diags.has_errors() {
        return Err("Rust generation failed; generated/ is left as it was".into());
    }
    let modules: Vec<(String, String)> = namespaces.iter().map(|n| (n.module.clone(), n.uri.clone())).collect();
    rust.files.push(rust_emit::models_mod(&modules, COMMAND));
    rust.files.push(rust_emit::rustfmt_toml());
    // Modelica: one package per namespace (and the used part of ns0, and the support package).
    let mcfg = namespaces
        .iter()
        .fold(nodeset_compiler::emit::modelica::ModelicaConfig::new(), |c, n| c.namespace(n.uri.clone()));
    let modelica = nodeset_compiler::emit::modelica::generate_with_diagnostics(model, &mcfg);
    let mut mdiags = modelica.diagnostics;
    if deny_warnings {
        mdiags.deny_warnings();
    }
    mdiags.sort(&model.sources);
    eprint!("{}", mdiags.render(&model.sources));
    if mdiags.has_errors() {
        return Err("Modelica generation failed; generated/ is left as it was".into());
    }
    Ok(vec![(root.join("generated/src/models"), rust.files), (root.join("generated/modelica"), modelica.files)])
}

pub fn run(args: Args) -> Result<(), String> {
    crate::fetch::ensure_fetched()?;
    let plan = plan(args.deny_warnings)?;
    let mode = if args.check { Mode::Check } else { Mode::Write };
    let mut stale = String::new();
    for (dir, files) in &plan {
        let report = write_tree(dir, files, mode)?;
        let shown = crate::util::display_path(dir);
        if args.check {
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
    if args.check {
        println!("generated/ is up to date");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// generated/ must be what the compiler produces from the pinned specs today.
    #[test]
    fn generated_tree_is_fresh() {
        crate::fetch::ensure_fetched().expect("the pinned nodesets are needed; run `cargo xtask fetch-nodesets`");
        let plan = plan(false).expect("generation succeeds");
        let mut stale = String::new();
        for (dir, files) in &plan {
            let report = write_tree(dir, files, Mode::Check).expect("check mode reads only");
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
}
