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
    two_namespaces, state_machine, instances, variable_type, recursive, name_collision
);

/// Compiles the fixture folder `case` (its files named) with the vendor models, generates Rust for every
/// model the plan generates, and returns the code of `module` and the rendered diagnostics of loading,
/// planning and generation.
fn generate_case(case: &str, only: Option<&str>) -> (String, String) {
    use nodeset_compiler::emit::rust::{generate, RustConfig, RustNamespace, RustPath};
    use nodeset_compiler::load::Input;
    use nodeset_compiler::{compile, Options};
    let dir = root().join("tests/fixtures").join(case);
    let mut files: Vec<_> = std::fs::read_dir(&dir).expect("fixture folder").flatten().map(|e| e.path()).collect();
    files.sort();
    files.retain(|f| only.is_none_or(|o| f.file_name().is_some_and(|n| n == o)));
    let opts = Options { model_dirs: vec![vendor(), dir.clone()], ..Options::default() };
    let compiled = compile(files.into_iter().map(Input::Path).collect(), &opts);
    let mut text = compiled.render_diagnostics();
    assert!(compiled.ok(), "{text}");
    let model = &compiled.model;
    let (plan, planning) = nodeset_compiler::emit::plan::plan(model, &Default::default(), true);
    assert!(planning.items.is_empty(), "{}", planning.render(&model.sources));
    let modules = plan.module_names(&Default::default());
    let namespaces: Vec<RustNamespace> = plan.generated.iter().map(|u| RustNamespace { uri: u.clone(), module: modules[u].clone() }).collect();
    text.push_str(&plan.describe(|u| modules[u].clone()));
    let cfg = RustConfig {
        namespaces,
        extern_paths: Default::default(),
        runtime_path: RustPath::new("nodeset_models::runtime").unwrap(),
        command: "test".into(),
    };
    let gen = generate(model, &cfg);
    text.push_str(&gen.diagnostics.render(&model.sources));
    let code: String = gen.files.iter().map(|f| format!("==> {}\n{}", f.path.display(), f.contents)).collect();
    (code, text)
}

/// A structure that contains its own type by value is boxed on the cycle and only there: an optional field
/// of the own type, a structure and a union that contain each other; not an array of the own type, nor a
/// structure that merely holds a recursive one. The boxed types get the binary encoding of their box.
#[test]
fn recursive_structures_are_boxed_on_the_cycle() {
    let (code, diagnostics) = generate_case("recursive", None);
    insta::assert_snapshot!("recursive_diagnostics", diagnostics);
    let types = code.split("==> ").find(|f| f.starts_with("recursive/types.rs")).expect("types.rs");
    for expected in [
        "pub referred_semantic_id: Option<Box<Reference>>,",
        "pub next: Option<Box<Link>>,",
        "Target(Box<Node>),",
        "pub children: Option<Vec<Tree>>,",
        "pub main: Reference,",
        "impl opcua::types::BinaryEncodable for Box<Reference>",
        "impl opcua::types::BinaryDecodable for Box<Link>",
    ] {
        assert!(types.contains(expected), "types.rs lacks `{expected}`:\n{types}");
    }
    for unexpected in ["for Box<Tree>", "for Box<Holder>"] {
        assert!(!types.contains(unexpected), "types.rs has `{unexpected}`, off the cycle");
    }
}

/// A type whose supertype's handle is not generated inlines the inherited members; two of them with one
/// BrowseName text in different namespaces (`1:Identification`, `2:Identification`) get two nested structs
/// of two names. Naming the subtype's file alone: its dependency is generated with it (the plan), so the
/// handle reaches the supertype's and inlines nothing; the collision is forced by generating the subtype's
/// namespace without its dependency's module.
#[test]
fn members_of_one_name_in_two_namespaces_get_two_struct_names() {
    use nodeset_compiler::emit::rust::{generate, RustConfig, RustNamespace, RustPath};
    use nodeset_compiler::load::Input;
    use nodeset_compiler::{compile, Options};
    let (_, diagnostics) = generate_case("name_collision", Some("Example.NameCollision.NodeSet2.xml"));
    insta::assert_snapshot!("name_collision_diagnostics", diagnostics);
    let dir = root().join("tests/fixtures/name_collision");
    let opts = Options { model_dirs: vec![vendor(), dir.clone()], ..Options::default() };
    let compiled = compile(vec![Input::Path(dir.join("Example.NameCollision.NodeSet2.xml"))], &opts);
    let cfg = RustConfig {
        namespaces: vec![RustNamespace { uri: "http://example.com/fixtures/name_collision/".into(), module: "name_collision".into() }],
        extern_paths: Default::default(),
        runtime_path: RustPath::new("nodeset_models::runtime").unwrap(),
        command: "test".into(),
    };
    let gen = generate(&compiled.model, &cfg);
    let objects = gen.files.iter().find(|f| f.path.ends_with("objects.rs")).expect("objects.rs");
    insta::assert_snapshot!("name_collision_alone_objects", objects.contents);
    let structs: Vec<&str> = objects.contents.lines().filter(|l| l.starts_with("pub struct ")).collect();
    let mut unique = structs.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(structs.len(), unique.len(), "a struct name is defined twice: {structs:?}");
    assert!(structs.iter().any(|s| s.starts_with("pub struct DozerType_Identification_2 ")), "{structs:?}");
}

/// Naming the base namespace's file for Rust is a diagnostic (async-opcua provides ns0), not code with
/// thousands of type errors. Demoted (`--warn NS0303`), the run recovers: ns0 is left to async-opcua and the
/// files that build on it are generated.
#[test]
fn naming_ns0_for_rust_is_a_diagnostic() {
    use nodeset_compiler::diag::{Code, Level, Severities};
    use nodeset_compiler::load::Input;
    use nodeset_compiler::{compile, run_rust, Error, Options, RustOptions};
    let compiled = compile(vec![Input::Path(vendor().join("Opc.Ua.NodeSet2.xml"))], &Options::default());
    assert!(compiled.ok(), "{}", compiled.render_diagnostics());
    let err = run_rust(&compiled.model, &RustOptions::default(), &Severities::new()).expect_err("ns0 named for Rust is refused");
    assert!(matches!(err, Error::Diagnostics { errors: 1, .. }), "{err}");
    let text = err.diagnostics().replace(&root().display().to_string(), "<root>");
    assert!(text.contains("error[NS0303]"), "{text}");
    insta::assert_snapshot!("ns0_named_diagnostics", text);
    // For Modelica, where the base namespace is a package like any other, the plan accepts it.
    let (_, planning) = nodeset_compiler::emit::plan::plan(&compiled.model, &Default::default(), false);
    assert!(planning.items.is_empty(), "{}", planning.render(&compiled.model.sources));

    // ns0 named beside a file that builds on it, NS0303 demoted: a warning, and the other file's module alone.
    let structure = root().join("tests/fixtures/structure/Example.Structure.NodeSet2.xml");
    let files = vec![Input::Path(vendor().join("Opc.Ua.NodeSet2.xml")), Input::Path(structure)];
    let compiled = compile(files, &Options::default());
    assert!(compiled.ok(), "{}", compiled.render_diagnostics());
    let mut warn = Severities::new();
    warn.set(Code::Ns0Named, Level::Warn).expect("NS0303 has a recovery");
    let run = run_rust(&compiled.model, &RustOptions::default(), &warn).unwrap_or_else(|e| panic!("{e}"));
    assert!(run.warnings.contains("warning[NS0303]"), "{}", run.warnings);
    assert_eq!(run.plan.generated, ["http://example.com/fixtures/structure/"], "{:?}", run.plan);
    assert_eq!(run.modules.keys().collect::<Vec<_>>(), ["http://example.com/fixtures/structure/"]);
    // `--deny warnings` without `--warn NS0303` leaves it an error.
    let mut deny = Severities::new();
    deny.deny_warnings(true);
    assert!(run_rust(&compiled.model, &RustOptions::default(), &deny).is_err());
}

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
    use nodeset_compiler::emit::rust::{generate, RustConfig, RustNamespace, RustPath};
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
        runtime_path: RustPath::new("crate::runtime").unwrap(),
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

/// The build.rs front door generates what the `rust` command generates (one run, `run_rust`): the vendor
/// Robotics model of `tests/user-crate` with the vendor Device model it requires (not named, found in the
/// model folder), and the same `register`; the OPC Foundation's namespaces mapped to nodeset-models are not
/// generated, and the vendor's `.../Robotics/` does not take the mapped Robotics' module name. Mapping Robotics
/// without the DI and IA it requires is NS0304, naming the models and the fix.
#[test]
fn the_builder_generates_what_the_command_line_generates() {
    use nodeset_compiler::load::Input;
    use nodeset_compiler::{compile, run_rust, Options, RustOptions};
    let dir = root().join("tests/user-crate/nodesets");
    let file = dir.join("Example.VendorRobotics.NodeSet2.xml");
    let externs = [
        ("http://opcfoundation.org/UA/DI/", "nodeset_models::models::di"),
        ("http://opcfoundation.org/UA/IA/", "nodeset_models::models::ia"),
        ("http://opcfoundation.org/UA/Robotics/", "nodeset_models::models::robotics"),
    ];
    let out = std::env::temp_dir().join(format!("nodeset-builder-cli-{}", std::process::id()));
    let builder = |externs: &[(&str, &str)]| {
        externs
            .iter()
            .fold(Builder::new().cargo_output(false).models_dir(&dir).models_dir(vendor()).out_dir(&out).file(&file), |b, (u, p)| {
                b.extern_namespace(u, p)
            })
    };
    let path = builder(&externs).generate().unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(&path).expect("generated file");
    for expected in ["pub mod device {", "pub mod ua_robotics {", "pub fn register(", ".table(&device::TABLE)", ".type_loader(ua_robotics::TypeLoader)"] {
        assert!(text.contains(expected), "the Builder's output lacks `{expected}`");
    }
    for unexpected in ["pub mod robotics {", "pub mod di {"] {
        assert!(!text.contains(unexpected), "the Builder's output generates a mapped namespace: `{unexpected}`");
    }
    // The command's run over the same input, inlined, is the same text.
    let opts = Options { model_dirs: vec![dir.clone(), vendor()], ..Options::default() };
    let compiled = compile(vec![Input::Path(file.clone())], &opts);
    assert!(compiled.ok(), "{}", compiled.render_diagnostics());
    let rust = RustOptions {
        extern_paths: externs.iter().map(|(u, p)| (u.to_string(), p.to_string())).collect(),
        command: "cargo build (build.rs)".into(),
        ..RustOptions::default()
    };
    let run = run_rust(&compiled.model, &rust, &opts.severities).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(text, nodeset_compiler::emit::rust::inline(&run.files), "the Builder's output is not the command's");
    // Robotics mapped, DI and IA (which the mapped Robotics requires) not: refused, nothing written.
    let err = builder(&externs[2..]).out_file("refused.rs").generate().expect_err("a mapped model's requirement generated here is refused");
    let rendered = err.diagnostics().replace(&root().display().to_string(), "<root>");
    assert!(rendered.contains("error[NS0304]"), "{rendered}");
    assert!(rendered.contains("`http://opcfoundation.org/UA/Robotics/` is mapped to `nodeset_models::models::robotics`, but the model it requires, `http://opcfoundation.org/UA/DI/`"), "{rendered}");
    assert!(rendered.contains(".extern_namespace(\"http://opcfoundation.org/UA/DI/\", PATH)"), "{rendered}");
    assert!(!out.join("refused.rs").exists());
    // Nothing mapped: every required model is generated, as the command does.
    let path = builder(&[]).out_file("all.rs").generate().unwrap_or_else(|e| panic!("{e}"));
    let all = std::fs::read_to_string(&path).expect("generated file");
    for expected in ["pub mod di {", "pub mod ia {", "pub mod device {"] {
        assert!(all.contains(expected), "with nothing mapped, the Builder's output lacks `{expected}`");
    }
    // The two Robotics models (the OPC Foundation's and the vendor's) take their URIs' segments until they differ.
    let robotics: Vec<&str> = all.lines().filter(|l| l.starts_with("pub mod ") && l.ends_with("_robotics {")).collect();
    assert_eq!(robotics.len(), 2, "{robotics:?}");
    let _ = std::fs::remove_dir_all(&out);
}
