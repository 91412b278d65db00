//! Snapshots of the Rust the back end generates for each one-feature fixture (the same code
//! tests/rust-fixtures compiles under deny(warnings)).

use nodeset_compiler::build::Builder;
use nodeset_tests::{root, vendor};

fn generated(case: &str) -> String {
    let dir = root().join("tests/fixtures").join(case);
    let mut files: Vec<_> = std::fs::read_dir(&dir).expect("fixture folder").flatten().map(|e| e.path()).collect();
    files.sort();
    let out = std::env::temp_dir().join(format!("nodeset-rust-snap-{}-{case}", std::process::id()));
    let mut b = Builder::new().cargo_output(false).models_dir(vendor()).models_dir(&dir).out_dir(&out);
    for f in files.into_iter().filter(|f| f.extension().is_some_and(|x| x == "xml")) {
        b = b.file(f);
    }
    let path = b.generate().unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(&path).expect("generated file");
    let _ = std::fs::remove_dir_all(&out);
    text
}

macro_rules! fixture {
    ($($case:ident),*) => {$(
        #[test]
        fn $case() {
            let text = generated(stringify!($case));
            assert!(text.contains("pub static TABLE"), "every namespace has its address-space table");
            insta::assert_snapshot!(stringify!($case), text);
        }
    )*};
}

fixture!(
    structure, optional_fields, union, enum_gaps, option_set, abstract_base, arrays, names, method, event_type,
    two_namespaces, state_machine, instances, variable_type
);

/// Asserts that prettyplease prints `text` (a generated file, its `//` header aside) exactly as it stands.
fn assert_prettyplease_layout(what: &str, text: &str) {
    let body: String = text
        .lines()
        .skip_while(|l| l.starts_with("// ") || l.is_empty())
        .map(|l| format!("{l}\n"))
        .collect();
    let file = syn::parse_file(&body).unwrap_or_else(|e| panic!("{what} does not parse: {e}"));
    let again = prettyplease::unparse(&file);
    if again != body {
        let line = again.lines().zip(body.lines()).position(|(a, b)| a != b).unwrap_or(0);
        panic!(
            "{what} is not in prettyplease's layout; first difference at line {} of the body:\n  generated:   {:?}\n  prettyplease: {:?}",
            line + 1,
            body.lines().nth(line).unwrap_or(""),
            again.lines().nth(line).unwrap_or("")
        );
    }
}

/// The NodeId constants of `ids.rs` are written as text in prettyplease's layout, not through prettyplease
/// (see `consts_text` in the emitter). This model puts constants on both sides of prettyplease's margin:
/// numeric and string identifiers, a string with multi-byte characters at the margin, GUID and opaque
/// identifiers, and descriptions with blank lines, tabs, quotes and trailing spaces.
#[test]
fn ids_text_is_what_prettyplease_prints() {
    use nodeset_compiler::emit::rust::{generate, RustConfig, RustNamespace};
    use nodeset_compiler::load::Input;
    use nodeset_compiler::{compile, Options};

    let uri = "http://example.com/fixtures/layout/";
    let mut nodes = String::new();
    let mut object = |id: &str, name: &str, description: &str| {
        nodes.push_str(&format!(
            "  <UAObject NodeId=\"{id}\" BrowseName=\"1:{name}\">\n    <DisplayName>{name}</DisplayName>\n    <Description>{description}</Description>\n    <References><Reference ReferenceType=\"i=40\">i=58</Reference></References>\n  </UAObject>\n"
        ));
    };
    // `    pub const NAME: NsNodeId = id(5000);` is 36 bytes plus the name: names of 48 to 60 letters cross
    // the margin of 89.
    for k in 48..=60 {
        let name = format!("N{}", "x".repeat(k - 1));
        object(&format!("ns=1;i={}", 5000 + k), &name, "One line.");
    }
    for k in 20..=44 {
        let name = format!("S{}", "y".repeat(k - 1));
        object(&format!("ns=1;s=Id.{}", "z".repeat(k)), &name, "Two\n\nparagraphs\twith a tab, \"quotes\" and trailing spaces   ");
    }
    for k in 30..=40 {
        let name = format!("U{}", "w".repeat(k));
        object(&format!("ns=1;s=é{}ü", "ä".repeat(k - 30)), &name, "Multi-byte characters near the margin.");
    }
    object("ns=1;g=09087e75-8e5e-499b-954f-f2a9603db28a", "GuidIdentified", "A GUID.");
    object("ns=1;b=M/RbKBsRVkePCePcx24oRA==", "OpaqueIdentified", "An opaque identifier.");
    let xml = format!(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<UANodeSet xmlns=\"http://opcfoundation.org/UA/2011/03/UANodeSet.xsd\">\n  <NamespaceUris><Uri>{uri}</Uri></NamespaceUris>\n  <Models><Model ModelUri=\"{uri}\" Version=\"1.0.0\" PublicationDate=\"2026-01-01T00:00:00Z\"><RequiredModel ModelUri=\"http://opcfoundation.org/UA/\" /></Model></Models>\n{nodes}</UANodeSet>\n"
    );
    let opts = Options { model_dirs: vec![vendor()], ..Options::default() };
    let out = compile(vec![Input::Text { name: "layout.xml".into(), text: xml }], &opts);
    assert!(!out.diagnostics.has_errors(), "{}", out.render_diagnostics());
    let cfg = RustConfig {
        namespaces: vec![RustNamespace { uri: uri.into(), module: "layout".into() }],
        extern_paths: Default::default(),
        runtime_path: "crate::runtime".into(),
        command: "test".into(),
    };
    let rust = generate(&out.model, &cfg);
    let ids = rust.files.iter().find(|f| f.path.ends_with("ids.rs")).expect("ids.rs");
    let wrapped = ids.contents.matches("NsNodeId = id(\n").count();
    let flat = ids.contents.matches("NsNodeId = id(50").count();
    assert!(wrapped > 0 && flat > 0, "the numeric constants fall on both sides of the margin ({flat} flat, {wrapped} wrapped)");
    assert!(ids.contents.contains("NsNodeId = NsNodeId::string(\n"), "some string constants are wrapped");
    assert_prettyplease_layout("ids.rs of the layout model", &ids.contents);
}

/// The same for the checked-in generated code: every file is exactly what prettyplease prints, except the
/// tables written one row per line on purpose (the node rows of nodes.rs, the member markers at the end of
/// objects.rs, which prettyplease would fold into paragraphs).
#[test]
fn generated_code_is_in_prettyplease_layout() {
    const MARKERS: &str = "/// Member markers of each ObjectType";
    let models = root().join("generated/src/models");
    let mut checked = 0;
    for dir in std::fs::read_dir(&models).expect("generated/src/models").flatten().map(|e| e.path()).filter(|p| p.is_dir()) {
        for name in ["mod.rs", "ids.rs", "types.rs", "objects.rs"] {
            let path = dir.join(name);
            let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let text = match text.find(MARKERS) {
                Some(at) if name == "objects.rs" => &text[..at],
                _ => &text[..],
            };
            assert_prettyplease_layout(&path.display().to_string(), text);
            checked += 1;
        }
    }
    assert!(checked >= 24, "only {checked} generated files found under {}", models.display());
}
