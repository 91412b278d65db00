//! The registry package's files (`node-opcua-nodesets`, pinned by `nodesets/node-opcua-nodesets.lock`):
//! every one of the 38 resolves without an error, as `nodeset-compiler check FILE --models nodesets/vendor`
//! resolves it. The current specifications are named one at a time; the three files of `1.02/`, which
//! declare no `<Model>` and so cannot require one another, are named together, as a user of that set must.
//! `cargo xtask registry` goes further (Rust compiled, Modelica checked by rumoca).

use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use nodeset_tests::{nodeset_files, vendor};
use std::path::PathBuf;

#[test]
fn every_registry_file_resolves() {
    let dir = vendor();
    let files = nodeset_files(&dir);
    assert_eq!(files.len(), 38, "the lock pins 38 files; run `cargo xtask fetch-nodesets`: {files:?}");
    let (old, current): (Vec<PathBuf>, Vec<PathBuf>) = files.into_iter().partition(|f| f.parent() == Some(&dir.join("1.02")));
    assert_eq!(old.len(), 3, "{old:?}");
    let mut units: Vec<Vec<PathBuf>> = current.into_iter().map(|f| vec![f]).collect();
    // DI first: ADI and FTNIR build on it.
    let order = ["Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.Adi.NodeSet2.xml", "FTNIR.NodeSet2.xml"];
    let mut old = old;
    old.sort_by_key(|f| order.iter().position(|n| f.ends_with(n)));
    units.push(old);
    let opts = Options { model_dirs: vec![dir.clone()], ..Options::default() };
    let mut failed = Vec::new();
    let mut nodes = 0;
    for unit in &units {
        let compiled = compile(unit.iter().cloned().map(Input::Path).collect(), &opts);
        nodes += compiled.model.nodes.len();
        if compiled.model.nodes.is_empty() {
            failed.push(format!("{unit:?}: no node resolved"));
        }
        if compiled.diagnostics.error_count() > 0 {
            failed.push(format!("{unit:?}:\n{}", compiled.render_diagnostics()));
        }
    }
    assert!(failed.is_empty(), "{} of {} runs do not resolve:\n{}", failed.len(), units.len(), failed.join("\n"));
    // 236,287 nodes when written (the part of ns0 each run uses, its files and the models they require).
    assert!(nodes > 200_000, "too few nodes resolved: {nodes} in {} runs", units.len());
    eprintln!("{} runs, {nodes} nodes resolved", units.len());
}
