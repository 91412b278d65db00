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

/// `nodeset-compiler check FILE --models nodesets/vendor` for each file of `1.02/` alone (issue 37): a file
/// without `<Models>` named on the command line and also lying in the models folder once made the loader
/// read itself again without end. Each returns within a minute, loads the file once, and finds the files of
/// its own folder it refers to (errors are allowed: alone, FTNIR's references into ADI may not all resolve).
#[test]
fn each_file_without_models_named_alone_returns() {
    let dir = vendor();
    let old: Vec<PathBuf> = nodeset_files(&dir).into_iter().filter(|f| f.parent() == Some(&dir.join("1.02"))).collect();
    assert_eq!(old.len(), 3, "{old:?}");
    for f in old {
        let (tx, rx) = std::sync::mpsc::channel();
        let (file, models) = (f.clone(), dir.clone());
        std::thread::spawn(move || {
            let opts = Options { model_dirs: vec![models], ..Options::default() };
            let _ = tx.send(compile(vec![Input::Path(file)], &opts));
        });
        let compiled = match rx.recv_timeout(std::time::Duration::from_secs(60)) {
            Ok(c) => c,
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                use std::io::Write as _;
                let _ = writeln!(std::io::stderr(), "check {} --models {} did not return within 60 s", f.display(), dir.display());
                std::process::exit(101);
            }
            Err(_) => panic!("the compiler panicked on {}", f.display()),
        };
        let read: Vec<&std::path::Path> =
            compiled.model.sources.files().filter(|(_, s)| s.path == f).map(|(_, s)| s.path.as_path()).collect();
        assert_eq!(read.len(), 1, "{} read {} times", f.display(), read.len());
        let own = compiled.model.nodes.iter().filter(|n| compiled.model.sources.get(n.file).path == f).count();
        assert!(own > 0, "no node of {} resolved:\n{}", f.display(), compiled.render_diagnostics());
    }
}
