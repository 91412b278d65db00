//! The compatibility corpus: every NodeSet2 file of ../shared/nodesets/ua-nodeset loads and resolves
//! together with the models it requires from the same tree.

use nodeset_compiler::diag::Code;
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use nodeset_tests::{corpus, nodeset_files};
use std::path::PathBuf;

/// Models the OPC Foundation tree references but whose files are absent from this snapshot.
const ABSENT_MODELS: &[&str] = &["http://opcfoundation.org/UA/Pumps/", "http://opcfoundation.org/UA/TMC/"];

struct Outcome {
    file: PathBuf,
    nodes: usize,
    errors: Vec<String>,
    warnings: usize,
    missing_absent: bool,
}

#[test]
fn every_corpus_file_resolves_with_its_required_models() {
    let tree = corpus();
    let files = nodeset_files(&tree);
    assert!(files.len() >= 117, "expected the 117+ NodeSet2 files of the corpus, found {}", files.len());
    let opts = Options { model_dirs: vec![tree.clone()], ..Options::default() };
    // Two workers: the CI machine has two cores.
    let chunks: Vec<Vec<PathBuf>> = (0..2).map(|w| files.iter().skip(w).step_by(2).cloned().collect()).collect();
    let mut outcomes: Vec<Outcome> = std::thread::scope(|s| {
        let handles: Vec<_> = chunks
            .iter()
            .map(|chunk| {
                let opts = &opts;
                s.spawn(move || {
                    chunk
                        .iter()
                        .map(|f| {
                            let out = compile(vec![Input::Path(f.clone())], opts);
                            let missing_absent = out.diagnostics.items.iter().any(|d| {
                                d.code == Code::MissingModel && ABSENT_MODELS.iter().any(|m| d.message.contains(m))
                            });
                            let errors: Vec<String> = out
                                .diagnostics
                                .items
                                .iter()
                                .filter(|d| d.is_error())
                                .filter(|d| !(d.code == Code::MissingModel && missing_absent))
                                .map(|d| d.render(&out.model.sources))
                                .collect();
                            let own: usize = out
                                .model
                                .nodes
                                .iter()
                                .filter(|n| out.model.sources.get(n.file).path == *f)
                                .count();
                            Outcome { file: f.clone(), nodes: own, errors, warnings: out.diagnostics.warning_count(), missing_absent }
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("a worker panicked")).collect()
    });
    outcomes.sort_by(|a, b| a.file.cmp(&b.file));
    let resolved = outcomes.iter().filter(|o| o.errors.is_empty() && !o.missing_absent).count();
    let missing = outcomes.iter().filter(|o| o.missing_absent).count();
    let nodes: usize = outcomes.iter().map(|o| o.nodes).sum();
    let warnings: usize = outcomes.iter().map(|o| o.warnings).sum();
    for o in &outcomes {
        println!(
            "{:>6} nodes {:>4} warnings {}{}",
            o.nodes,
            o.warnings,
            o.file.strip_prefix(&tree).unwrap_or(&o.file).display(),
            if o.missing_absent { "  (requires a model absent from the tree)" } else { "" }
        );
    }
    println!(
        "corpus: {} files, {resolved} resolved with zero errors, {missing} missing an absent model (Pumps/TMC), {nodes} nodes, {warnings} warnings",
        outcomes.len()
    );
    let failed: Vec<&Outcome> = outcomes.iter().filter(|o| !o.errors.is_empty()).collect();
    if !failed.is_empty() {
        let mut msg = String::new();
        for o in &failed {
            msg.push_str(&format!("\n== {}\n{}", o.file.display(), o.errors.join("")));
        }
        panic!("{} corpus file(s) have errors:{msg}", failed.len());
    }
    assert_eq!(resolved + missing, outcomes.len());
}
