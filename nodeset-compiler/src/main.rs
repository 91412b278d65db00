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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
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
