//! `verify` from end to end: read the server, load the nodesets of its namespaces, check.

use super::check::{self, Report};
use super::client::{self, Connect};
use crate::diag::Severities;
use crate::load::{self, Input, NS0_URI};
use crate::{compile, Compiled, Options};
use std::path::PathBuf;
use std::time::Instant;

/// The result of [`verify`].
#[derive(Debug)]
pub struct Verified {
    /// The nodesets loaded for the server's namespaces.
    pub compiled: Compiled,
    /// The findings, with the severity settings applied, sorted.
    pub report: Report,
    /// The nodesets loaded, in the order they were passed to the loader.
    pub files: Vec<PathBuf>,
    /// A note on the warnings the nodesets themselves gave (empty without any): they are not about the
    /// server, so `verify` only counts them.
    pub load_warnings: String,
    /// Milliseconds reading the server (connect, browse, read, disconnect).
    pub read_millis: u128,
    /// Milliseconds loading the nodesets.
    pub load_millis: u128,
    /// Milliseconds checking.
    pub check_millis: u128,
    /// All of it.
    pub millis: u128,
}

/// Reads the server, loads `files` and, for every namespace of the server no named file defines, the
/// newest nodeset of that URI in the `models` folders, and checks the server against them. `severities`
/// applies to the nodesets' diagnostics and to the findings alike (`--warn NS0408`).
pub async fn verify(connect: &Connect, files: &[PathBuf], models: &[PathBuf], severities: &Severities) -> Result<Verified, String> {
    let start = Instant::now();
    // The nodesets named on the command line are read first: a typo there should not wait for a server.
    let provided = provided_models(files)?;
    let snap = client::snapshot(connect).await.map_err(|e| e.to_string())?;
    let read_millis = start.elapsed().as_millis();
    let load_start = Instant::now();
    let (compiled, files) = load_for(&snap.namespaces, files, &provided, models, severities)?;
    let warnings = compiled.diagnostics.warning_count();
    let load_warnings = if warnings == 0 {
        String::new()
    } else {
        format!("note: the nodesets gave {warnings} warning(s) of their own; `nodeset-compiler check` with the same files shows them\n")
    };
    let load_millis = load_start.elapsed().as_millis();
    let check_start = Instant::now();
    let mut report = check::check(&compiled.model, &snap);
    report.apply(severities, &compiled.model.sources);
    let check_millis = check_start.elapsed().as_millis();
    Ok(Verified { compiled, report, files, load_warnings, read_millis, load_millis, check_millis, millis: start.elapsed().as_millis() })
}

/// The models (URIs) the named files declare; fails on a file that is not a readable NodeSet2 file.
fn provided_models(files: &[PathBuf]) -> Result<Vec<String>, String> {
    let mut provided: Vec<String> = Vec::new();
    for f in files {
        provided.extend(load::models_of_file(f).ok_or_else(|| format!("{} is not a readable NodeSet2 file", f.display()))?);
    }
    Ok(provided)
}

/// Loads the nodesets of the server's `namespaces`: the named `files` (which define the models
/// `provided`), and for each namespace they do not define the newest nodeset of that URI in the `models`
/// folders. Fails with the rendered diagnostics when they do not load. A namespace no nodeset defines is
/// not an error here: the check reports it (`NS0409` on every node typed from it, and a note).
pub fn load_for(
    namespaces: &[String],
    files: &[PathBuf],
    provided: &[String],
    models: &[PathBuf],
    severities: &Severities,
) -> Result<(Compiled, Vec<PathBuf>), String> {
    let wanted: Vec<String> =
        namespaces.iter().filter(|u| u.as_str() != NS0_URI && !provided.contains(u)).cloned().collect();
    let found = load::find_model_files(models, &wanted);
    let mut inputs: Vec<PathBuf> = files.to_vec();
    for path in found.values() {
        if !inputs.contains(path) {
            inputs.push(path.clone());
        }
    }
    if inputs.is_empty() {
        return Err(format!(
            "no nodeset defines any of the server's namespaces ({}); name the files or a --models folder",
            namespaces.iter().skip(1).cloned().collect::<Vec<_>>().join(", ")
        ));
    }
    let opts = Options { model_dirs: models.to_vec(), severities: severities.clone(), ..Options::default() };
    let mut compiled = compile(inputs.iter().cloned().map(Input::Path).collect(), &opts);
    compiled.checked(severities).map_err(|e| format!("the nodesets of the server's namespaces do not load: {}", e.diagnostics()))?;
    Ok((compiled, inputs))
}
