//! Generates every one-feature fixture of tests/fixtures through the build.rs API (bad inputs excepted), the
//! recovery fixtures of tests/fixtures/recover with every demotable error demoted (`--warn CODE`), and the two
//! public skill reference models of ../shared/nodesets/skills-reference.

fn main() {
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures");
    let vendor = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../nodesets/vendor");
    let mut builder = nodeset_compiler::build::Builder::new().models_dir(&vendor).models_dir(&fixtures);
    let mut cases: Vec<_> = std::fs::read_dir(&fixtures)
        .expect("tests/fixtures exists")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir() && p.file_name().is_some_and(|n| n != "bad" && n != "recover"))
        .collect();
    cases.sort();
    for case in cases {
        let mut files: Vec<_> = std::fs::read_dir(&case).expect("fixture folder").flatten().map(|e| e.path()).collect();
        files.sort();
        for f in files.into_iter().filter(|f| f.extension().is_some_and(|x| x == "xml")) {
            builder = builder.file(f);
        }
    }
    builder.generate().unwrap_or_else(|e| panic!("{e}"));

    // The recovery fixtures, each error demoted: what the compiler does instead must compile too.
    let recover = fixtures.join("recover");
    let mut builder = nodeset_compiler::build::Builder::new().models_dir(&vendor).out_file("recovered.rs");
    for code in nodeset_compiler::diag::Code::ALL {
        if code.default_severity() == nodeset_compiler::diag::Severity::Error && code.recovery().is_some() {
            builder = builder.warn(code.as_str());
        }
    }
    let mut files: Vec<_> = std::fs::read_dir(&recover).expect("tests/fixtures/recover exists").flatten().map(|e| e.path()).collect();
    files.sort();
    for f in files.into_iter().filter(|f| f.extension().is_some_and(|x| x == "xml")) {
        builder = builder.file(f);
    }
    builder.generate().unwrap_or_else(|e| panic!("{e}"));

    // The name collision fixture's subtype alone, its dependency not generated: the inherited members are
    // inlined, two of them named `Identification` (in two namespaces), as two nested structs of two names.
    nodeset_compiler::build::Builder::new()
        .models_dir(&vendor)
        .models_dir(fixtures.join("name_collision"))
        .file(fixtures.join("name_collision/Example.NameCollision.NodeSet2.xml"))
        .out_file("name_collision_alone.rs")
        .generate()
        .unwrap_or_else(|e| panic!("{e}"));

    // The two public skill reference models (../shared/nodesets/skills-reference), on DI from nodeset-models.
    let reference = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/nodesets/skills-reference");
    let mut files: Vec<_> = std::fs::read_dir(&reference)
        .unwrap_or_else(|e| panic!("{} is needed beside the repository: {e}", reference.display()))
        .flatten()
        .map(|e| e.path())
        .filter(|f| f.extension().is_some_and(|x| x == "xml"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 2, "the two skill reference models are expected in {}", reference.display());
    let mut builder = nodeset_compiler::build::Builder::new()
        .models_dir(&vendor)
        .models_dir(&reference)
        .extern_namespace("http://opcfoundation.org/UA/DI/", "nodeset_models::models::di")
        .out_file("skills_reference.rs");
    for f in files {
        builder = builder.file(f);
    }
    builder.generate().unwrap_or_else(|e| panic!("{e}"));
}
