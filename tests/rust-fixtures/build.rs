//! Generates every one-feature fixture of tests/fixtures through the build.rs API (bad inputs excepted), the
//! recovery fixtures of tests/fixtures/recover with every demotable error demoted (`--warn CODE`), and the two
//! public skill reference models of ../shared/nodesets/skills-reference; and the keyword fixture
//! (tests/rust-fixtures/keyword) as the `rust` command writes it, a folder per namespace.

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
    // The Builder (like the `rust` command) would generate the dependency too, so this goes through the
    // emitter's configuration directly.
    let alone = fixtures.join("name_collision");
    let opts = nodeset_compiler::Options { model_dirs: vec![vendor.clone(), alone.clone()], ..Default::default() };
    let input = nodeset_compiler::load::Input::Path(alone.join("Example.NameCollision.NodeSet2.xml"));
    let mut compiled = nodeset_compiler::compile(vec![input], &opts);
    compiled.checked(&opts.severities).unwrap_or_else(|e| panic!("{e}"));
    let rust = nodeset_compiler::RustOptions { command: "tests/rust-fixtures/build.rs".into(), ..Default::default() };
    let cfg = rust.config_of(&["http://example.com/fixtures/name_collision/".to_string()]).unwrap_or_else(|e| panic!("{e}"));
    let (files, _) = nodeset_compiler::generate_rust(&compiled.model, &cfg, Default::default(), &opts.severities)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    std::fs::write(out.join("name_collision_alone.rs"), nodeset_compiler::emit::rust::inline(&files)).expect("name_collision_alone.rs");

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

    // The keyword fixture as the `rust` command writes it (`run_rust`, then `write_tree`): a namespace named
    // `struct` is declared `pub mod r#struct;` and must be in the folder `struct/`. lib.rs includes the tree's
    // `mod.rs` through a `#[path]` module, so that rustc looks the namespace folders up as it does in a user's
    // `src/`.
    let keyword = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("keyword");
    println!("cargo:rerun-if-changed={}", keyword.display());
    let opts = nodeset_compiler::Options { model_dirs: vec![vendor.clone(), keyword.clone()], ..Default::default() };
    let mut compiled = nodeset_compiler::compile(vec![nodeset_compiler::load::Input::Path(keyword.join("Example.Keyword.NodeSet2.xml"))], &opts);
    compiled.checked(&opts.severities).unwrap_or_else(|e| panic!("{e}"));
    let rust = nodeset_compiler::RustOptions { command: "tests/rust-fixtures/build.rs".into(), ..Default::default() };
    let run = nodeset_compiler::run_rust(&compiled.model, &rust, &opts.severities).unwrap_or_else(|e| panic!("{e}"));
    let tree = out.join("keyword_tree");
    nodeset_compiler::write::write_tree(&tree, &run.files, nodeset_compiler::write::Mode::Write).unwrap_or_else(|e| panic!("{e}"));
    let wrapper = format!("#[path = {:?}]\npub mod keyword_tree;\n", tree.join("mod.rs").display().to_string());
    std::fs::write(out.join("keyword_tree.rs"), wrapper).expect("keyword_tree.rs");
}
