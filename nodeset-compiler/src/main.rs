//! The `nodeset-compiler` command.

use clap::{Parser, Subcommand};
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, summary, Options};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "nodeset-compiler", version, about = "Compiles OPC UA NodeSet2 information models")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Parse, load and resolve NodeSet2 files; print diagnostics and a per-namespace summary.
    Check {
        /// NodeSet2 files to check.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Folders searched recursively for the models the files require.
        #[arg(long = "models", value_name = "DIR")]
        models: Vec<PathBuf>,
        /// `--deny warnings` turns warnings into errors.
        #[arg(long, value_name = "WHAT", value_parser = ["warnings"])]
        deny: Option<String>,
        /// Also report warnings of model files that were loaded only as dependencies.
        #[arg(long)]
        all_warnings: bool,
        /// Print a type's supertypes and instance declarations (BrowseName, `URI#Name` or NodeId).
        #[arg(long, value_name = "TYPE")]
        show: Vec<String>,
        /// How many levels of instance declarations `--show` prints.
        #[arg(long, default_value_t = 3)]
        depth: usize,
    },
    /// Generate Rust for async-opcua 0.19 from NodeSet2 files: one module folder per namespace.
    Rust {
        /// NodeSet2 files whose models are generated.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Folders searched recursively for the models the files require.
        #[arg(long = "models", value_name = "DIR")]
        models: Vec<PathBuf>,
        /// Output folder (replaced atomically; it must hold only generated files).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// A namespace generated elsewhere, as URI=RUST_PATH (e.g. http://opcfoundation.org/UA/DI/=nodeset_models::models::di).
        #[arg(long = "extern", value_name = "URI=PATH")]
        externs: Vec<String>,
        /// The module name of a namespace, as URI=NAME.
        #[arg(long = "module", value_name = "URI=NAME")]
        modules: Vec<String>,
        /// The Rust path of the runtime module.
        #[arg(long, default_value = "nodeset_models::runtime")]
        runtime: String,
        /// Compare with the output folder instead of writing; fail if it differs.
        #[arg(long)]
        check: bool,
        /// `--deny warnings` turns warnings into errors.
        #[arg(long, value_name = "WHAT", value_parser = ["warnings"])]
        deny: Option<String>,
    },
    /// Generate Modelica component skeletons from NodeSet2 files: one package per namespace, the used part
    /// of the base namespace (`OpcUa`) and `OpcUaSupport`.
    Modelica {
        /// NodeSet2 files whose models are generated.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Folders searched recursively for the models the files require.
        #[arg(long = "models", value_name = "DIR")]
        models: Vec<PathBuf>,
        /// Output folder (replaced atomically; it must hold only generated files).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// A namespace whose package exists elsewhere, as URI=PACKAGE (not generated; classes extend PACKAGE).
        #[arg(long = "extern", value_name = "URI=PACKAGE")]
        externs: Vec<String>,
        /// Compare with the output folder instead of writing; fail if it differs.
        #[arg(long)]
        check: bool,
        /// `--deny warnings` turns warnings into errors.
        #[arg(long, value_name = "WHAT", value_parser = ["warnings"])]
        deny: Option<String>,
    },
}

fn pairs(items: &[String], what: &str) -> Result<Vec<(String, String)>, String> {
    items
        .iter()
        .map(|i| {
            // URIs contain `=` rarely but `:` always; split at the last `=`.
            i.rsplit_once('=')
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .ok_or_else(|| format!("--{what} takes URI=VALUE, got `{i}`"))
        })
        .collect()
}

fn rust_command(
    files: Vec<PathBuf>,
    models: Vec<PathBuf>,
    out: PathBuf,
    externs: Vec<String>,
    modules: Vec<String>,
    runtime: String,
    check: bool,
    deny: bool,
) -> Result<(), String> {
    use nodeset_compiler::emit::rust as r;
    use nodeset_compiler::write::{write_tree, Mode};
    let externs = pairs(&externs, "extern")?;
    let modules = pairs(&modules, "module")?;
    let opts = Options { model_dirs: models, deny_warnings: deny, ..Options::default() };
    let compiled = compile(files.into_iter().map(Input::Path).collect(), &opts);
    eprint!("{}", compiled.render_diagnostics());
    if !compiled.ok() {
        return Err("the NodeSet2 files do not compile; nothing was written".into());
    }
    let model = &compiled.model;
    // Every required model that is not mapped with --extern is generated too, so the output compiles alone.
    let (plan, module_names, mut gen) =
        nodeset_compiler::emit::plan::generate_rust(model, &externs, &modules, &runtime, "nodeset-compiler rust ...").map_err(|d| {
            eprint!("{}", d.render(&model.sources));
            "nothing was written".to_string()
        })?;
    let module_of = |uri: &str| module_names.get(uri).cloned().unwrap_or_else(|| r::default_module_name(uri));
    if deny {
        gen.diagnostics.deny_warnings();
    }
    gen.diagnostics.sort(&model.sources);
    eprint!("{}", gen.diagnostics.render(&model.sources));
    if gen.diagnostics.has_errors() {
        return Err("generation failed; nothing was written".into());
    }
    let report = write_tree(&out, &gen.files, if check { Mode::Check } else { Mode::Write })?;
    if check && !report.is_clean() {
        return Err(format!("{} is stale:\n{}", out.display(), report.describe(&out)));
    }
    eprint!("{}", plan.describe(module_of));
    eprintln!(
        "{}: {} file(s), {} new, {} changed, {} removed, {} unchanged",
        out.display(),
        gen.files.len(),
        report.added.len(),
        report.changed.len(),
        report.removed.len(),
        report.unchanged
    );
    Ok(())
}

fn modelica_command(files: Vec<PathBuf>, models: Vec<PathBuf>, out: PathBuf, externs: Vec<String>, check: bool, deny: bool) -> Result<(), String> {
    use nodeset_compiler::emit::modelica::{generate_with_diagnostics, ModelicaConfig};
    use nodeset_compiler::write::{write_tree, Mode};
    let opts = Options { model_dirs: models, deny_warnings: deny, ..Options::default() };
    let compiled = compile(files.into_iter().map(Input::Path).collect(), &opts);
    eprint!("{}", compiled.render_diagnostics());
    if !compiled.ok() {
        return Err("the NodeSet2 files do not compile; nothing was written".into());
    }
    let model = &compiled.model;
    // Every required model not mapped to an existing package is generated too (ns0: the part used, `OpcUa`).
    let externs = pairs(&externs, "extern")?;
    let plan = nodeset_compiler::emit::plan::plan(model, &externs, false).map_err(|d| d.render(&model.sources))?;
    let mut cfg = ModelicaConfig::new();
    cfg.namespaces = plan.generated.clone();
    if model.models.iter().any(|m| m.uri == nodeset_compiler::load::NS0_URI && model.sources.get(m.file).named) {
        cfg.namespaces.insert(0, nodeset_compiler::load::NS0_URI.to_string());
    }
    cfg.package_names = externs.iter().cloned().collect();
    let mut gen = generate_with_diagnostics(model, &cfg);
    if deny {
        gen.diagnostics.deny_warnings();
    }
    gen.diagnostics.sort(&model.sources);
    eprint!("{}", gen.diagnostics.render(&model.sources));
    if gen.diagnostics.has_errors() {
        return Err("generation failed; nothing was written".into());
    }
    let report = write_tree(&out, &gen.files, if check { Mode::Check } else { Mode::Write })?;
    if check && !report.is_clean() {
        return Err(format!("{} is stale:\n{}", out.display(), report.describe(&out)));
    }
    eprint!("{}", plan.describe(|_| String::new()));
    eprintln!(
        "{}: {} file(s), {} new, {} changed, {} removed, {} unchanged",
        out.display(),
        gen.files.len(),
        report.added.len(),
        report.changed.len(),
        report.removed.len(),
        report.unchanged
    );
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Rust { files, models, out, externs, modules, runtime, check, deny } => {
            match rust_command(files, models, out, externs, modules, runtime, check, deny.is_some()) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Modelica { files, models, out, externs, check, deny } => match modelica_command(files, models, out, externs, check, deny.is_some()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
        Command::Check { files, models, deny, all_warnings, show, depth } => {
            let opts = Options {
                model_dirs: models,
                deny_warnings: deny.is_some(),
                all_warnings,
                ..Options::default()
            };
            let out = compile(files.into_iter().map(Input::Path).collect(), &opts);
            eprint!("{}", out.render_diagnostics());
            print!("{}", summary::render(&out.model));
            for q in &show {
                let hits = out.model.find(q);
                match hits.first() {
                    Some(&t) => print!("\n{}", summary::show_type(&out.model, t, depth)),
                    None => eprintln!("error: `{q}` names no node (try a BrowseName, `URI#Name` or `ns=N;i=M`)"),
                }
            }
            let (e, w) = (out.diagnostics.error_count(), out.diagnostics.warning_count());
            eprintln!("{e} error(s), {w} warning(s)");
            if e > 0 {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            }
        }
    }
}
