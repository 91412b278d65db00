//! The build.rs front door (`build::Builder`) replaces its output file atomically: a build that fails, in
//! compilation or while writing, leaves the previous output byte for byte as it was and no temporary file.
//! (`cargo xtask generate` has the same test against a copy of generated/, in `xtask/src/generate.rs`.)

use nodeset_compiler::build::Builder;
use std::path::{Path, PathBuf};

fn fixture(case: &str, file: &str) -> PathBuf {
    nodeset_tests::root().join("tests/fixtures").join(case).join(file)
}

fn builder(out: &Path, files: &[PathBuf]) -> Builder {
    let b = Builder::new().models_dir(nodeset_tests::vendor()).out_dir(out).cargo_output(false);
    files.iter().fold(b, |b, f| b.file(f))
}

/// The names in `dir` with the bytes of each file (a folder has none).
fn listing(dir: &Path) -> Vec<(String, Option<Vec<u8>>)> {
    let mut v: Vec<(String, Option<Vec<u8>>)> = std::fs::read_dir(dir)
        .expect("the out dir exists")
        .map(|e| {
            let e = e.expect("readable");
            let bytes = e.path().is_file().then(|| std::fs::read(e.path()).expect("readable"));
            (e.file_name().to_string_lossy().into_owned(), bytes)
        })
        .collect();
    v.sort();
    v
}

#[test]
fn a_failed_build_leaves_the_previous_output() {
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("atomic-output");
    let _ = std::fs::remove_dir_all(&out);
    let structure = fixture("structure", "Example.Structure.NodeSet2.xml");
    let method = fixture("method", "Example.Method.NodeSet2.xml");

    let path = builder(&out, std::slice::from_ref(&structure)).generate().expect("the structure fixture generates");
    assert_eq!(path, out.join("nodesets.rs"));
    let before = listing(&out);
    assert_eq!(before.len(), 1, "only the output file is written: {:?}", before.iter().map(|e| &e.0).collect::<Vec<_>>());

    // 1. An invalid nodeset among the inputs: compilation fails, nothing is written.
    let bad = nodeset_tests::root().join("tests/fixtures/bad/truncated.xml");
    let err = builder(&out, &[method.clone(), bad]).generate().expect_err("a truncated nodeset fails the build");
    assert!(
        matches!(&err, nodeset_compiler::Error::Diagnostics { errors, .. } if *errors > 0) && err.diagnostics().contains("NS0004"),
        "the error lists the diagnostics: {err}"
    );
    assert!(listing(&out) == before, "a failed compilation changed the out dir");

    // 2. Writing fails: the temporary file cannot be created (a folder has its name). The output would
    //    change (another fixture), but the previous one stays and no temporary file is left.
    let blocker = out.join(format!(".nodesets.rs.tmp-{}", std::process::id()));
    std::fs::create_dir(&blocker).expect("create the blocking folder");
    let err = builder(&out, std::slice::from_ref(&method)).generate().expect_err("the temporary file cannot be written");
    assert!(matches!(&err, nodeset_compiler::Error::Write(_)) && err.to_string().contains("cannot write"), "{err}");
    std::fs::remove_dir(&blocker).expect("only the blocking folder is there");
    assert!(listing(&out) == before, "a failure while writing changed the out dir");

    // 3. The same build without the fault replaces the output.
    builder(&out, &[method]).generate().expect("the method fixture generates");
    let after = listing(&out);
    assert_eq!(after.len(), 1);
    assert_ne!(after, before, "the output was replaced");
}
