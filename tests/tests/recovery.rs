//! Severity control and the recoveries behind it (`tests/fixtures/recover/`).
//!
//! Every error code with a recovery has a minimal fixture here that fails with that error by default, and
//! with `--warn CODE` resolves and generates Rust in which the recovery shows. (The same fixtures, all
//! demoted, are compiled under `#![deny(warnings)]` by `tests/rust-fixtures`, module `recovered`.) Codes with
//! no recovery refuse to be demoted. The enumeration-value and redefinition fixtures have snapshots of their
//! diagnostics and their code.

use nodeset_compiler::build::Builder;
use nodeset_compiler::diag::{Code, Level, Severities, Severity};
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Compiled, Error, Options};
use nodeset_tests::{root, vendor};
use std::path::PathBuf;

/// (fixture, code, text the generated Rust must hold, text it must not hold): the recovery made visible.
const CASES: &[(&str, &str, &str, &str)] = &[
    // ValueRank="scalar" is read as absent: Speed is a scalar Int32.
    ("bad_attribute", "NS0008", "SPEED", "scalar\""),
    // AccessLevel="771" is masked to 3.
    ("access_level_range", "NS0012", "SPEED", "771"),
    // `Component` stays HasComponent (i=47): Speed is a component of PumpType, not a property.
    ("duplicate_alias", "NS0110", "SPEED", "HasProperty"),
    // The first definition of ns=1;i=1001 (Speed) is kept, the second (Torque) ignored.
    ("duplicate_node_id", "NS0201", "SPEED", "TORQUE"),
    // The reference to ns=1;i=2000 is dropped; PumpType keeps Speed.
    ("dangling_reference", "NS0202", "SPEED", "2000"),
    // The reference typed by an ObjectType is dropped: Torque is not a member of PumpType.
    ("bad_reference_type", "NS0203", "PUMP_TYPE", "pub torque"),
    // The cycle is broken; both types are generated.
    ("subtype_cycle", "NS0204", "VALVE_TYPE", "ValveType_ValveType"),
    // The TypeDefinition (String) is ignored: Pump is generated, typed by nothing.
    ("wrong_type_definition", "NS0205", "PUMP", "String"),
    // Stopped (value 1 again) is dropped.
    ("duplicate_enum_value", "NS0208", "Running = 1", "Stopped"),
    // The VariableType supertype is ignored.
    ("subtype_of_other_class", "NS0210", "PUMP_TYPE", "BaseDataVariable"),
    // The DataType i=58 is ignored: Speed takes a Variant.
    ("bad_data_type", "NS0212", "SPEED", "BaseObjectType"),
    // The entry naming i=63 is dropped; Operator's (i=15680, Browse, Read and Write) stays.
    ("bad_role", "NS0220", "Access 1:1001 ~ 0:15680=97\n", "0:63=97"),
];

/// Demotable errors of the `rust` command's plan rather than of compiling: their recovery is tested with the
/// plan (`rust_output.rs`, `naming_ns0_for_rust_is_a_diagnostic`, which demotes NS0303).
const PLAN_CODES: &[&str] = &["NS0303"];

/// The findings of `verify` on a live server: demoting one changes only the exit status, which
/// `verify.rs` (`a_node_opcua_server_with_planted_defects`) tests with `--warn`
/// and `--allow`.
const VERIFY_CODES: &[&str] = &["NS0401", "NS0402", "NS0403", "NS0404", "NS0405", "NS0406", "NS0407", "NS0408", "NS0409"];

fn fixture(case: &str) -> PathBuf {
    root().join("tests/fixtures/recover").join(format!("{case}.xml"))
}

fn compile_with(case: &str, severities: Severities) -> Compiled {
    let opts = Options { model_dirs: vec![vendor()], severities, ..Options::default() };
    compile(vec![Input::Path(fixture(case))], &opts)
}

fn relative(text: &str) -> String {
    text.replace(&format!("{}/", root().display()), "")
}

/// The Rust the `build.rs` Builder writes for one fixture file with these `--warn` codes.
fn generate(case: &str, warn: &[&str]) -> Result<String, Error> {
    let out = std::env::temp_dir().join(format!("nodeset-recover-{}-{case}", std::process::id()));
    let b = warn.iter().fold(Builder::new().cargo_output(false).models_dir(vendor()).out_dir(&out).file(fixture(case)), |b, c| b.warn(c));
    let text = b.generate().map(|p| std::fs::read_to_string(p).expect("the generated file"));
    let _ = std::fs::remove_dir_all(&out);
    text
}

/// Every error code that has a recovery has a case above, and no case names a code without one.
#[test]
fn every_demotable_error_has_a_fixture() {
    let demotable: Vec<&str> = Code::ALL
        .iter()
        .filter(|c| c.default_severity() == Severity::Error && c.recovery().is_some())
        .map(|c| c.as_str())
        .collect();
    let covered: Vec<&str> =
        CASES.iter().map(|c| c.1).chain(PLAN_CODES.iter().copied()).chain(VERIFY_CODES.iter().copied()).collect();
    let missing: Vec<&&str> = demotable.iter().filter(|c| !covered.contains(c)).collect();
    assert!(missing.is_empty(), "demotable codes without a recovery fixture: {missing:?}");
    for c in &covered {
        assert!(demotable.contains(c), "{c} has a fixture but is not a demotable error");
    }
}

/// Each fixture fails with its error; with `--warn CODE` it resolves, the error is a warning, and the Rust
/// generated shows the recovery.
#[test]
fn demoted_errors_recover() {
    for &(case, code_text, present, absent) in CASES {
        let code = Code::parse(code_text).expect("a code");
        let strict = compile_with(case, Severities::new());
        assert!(!strict.ok(), "{case}: compiles without --warn {code_text}");
        assert!(
            strict.diagnostics.items.iter().any(|d| d.code == code && d.severity == Severity::Error),
            "{case}: no {code_text} error:\n{}",
            strict.render_diagnostics()
        );
        let err = generate(case, &[]).expect_err("the Builder fails without --warn");
        assert!(matches!(err, Error::Diagnostics { .. }) && err.diagnostics().contains(code_text), "{case}: {err}");

        let mut warn = Severities::new();
        warn.set(code, Level::Warn).expect("a demotable code");
        let demoted = compile_with(case, warn);
        assert!(demoted.ok(), "{case}: still fails with --warn {code_text}:\n{}", demoted.render_diagnostics());
        assert!(
            demoted.diagnostics.items.iter().any(|d| d.code == code && d.severity == Severity::Warning),
            "{case}: the demoted {code_text} is not reported as a warning"
        );
        let text = generate(case, &[code_text]).unwrap_or_else(|e| panic!("{case}: {e}"));
        assert!(text.contains(present), "{case}: the generated Rust lacks `{present}`");
        assert!(!text.contains(absent), "{case}: the generated Rust holds `{absent}`; the recovery did not happen");
    }
}

/// `--allow CODE` drops the diagnostic and still recovers.
#[test]
fn allowed_error_recovers_silently() {
    let mut s = Severities::new();
    s.set_named(Level::Allow, "NS0202").unwrap();
    let out = compile_with("dangling_reference", s);
    assert!(out.ok() && out.diagnostics.items.iter().all(|d| d.code != Code::DanglingReference), "{}", out.render_diagnostics());
}

/// A code's own level outranks `--deny warnings`; `--deny CODE` makes a warning an error.
#[test]
fn levels_combine_like_rustc() {
    let mut s = Severities::new();
    s.deny_warnings(true);
    s.set_named(Level::Warn, "ns0202").unwrap();
    let out = compile_with("dangling_reference", s);
    assert!(out.ok(), "--warn NS0202 --deny warnings:\n{}", out.render_diagnostics());
    let mut s = Severities::new();
    s.set_named(Level::Deny, "NS0218").unwrap();
    let out = compile_with("redefinition", s);
    assert!(!out.ok() && out.diagnostics.items.iter().any(|d| d.code == Code::IdenticalRedefinition && d.is_error()));
}

/// Errors with no safe recovery cannot be demoted, and say so; unknown codes are refused.
#[test]
fn codes_without_recovery_cannot_be_demoted() {
    for code in [Code::XmlSyntax, Code::MissingModel, Code::UnknownFieldType] {
        for level in [Level::Warn, Level::Allow] {
            let err = Severities::new().set(code, level).expect_err("no recovery");
            let text = err.to_string();
            assert!(text.contains(code.as_str()) && text.contains("cannot be demoted"), "{text}");
        }
        Severities::new().set(code, Level::Deny).expect("any code can be denied");
    }
    let err = Severities::new().set_named(Level::Warn, "NS9999").expect_err("unknown");
    assert!(err.to_string().contains("not a diagnostic code"), "{err}");
    let err = generate("dangling_reference", &["NS0003"]).expect_err("the Builder refuses it too");
    assert!(matches!(err, Error::Severity(_)), "{err}");
}

/// The command line: `--warn CODE` on `rust` writes code; `--warn` of a code with no recovery is refused with
/// the reason; `codes` prints the table with the recovery of each code.
#[test]
fn command_line_severity_flags() {
    let exe = nodeset_tests::command_binary();
    let out = std::env::temp_dir().join(format!("nodeset-recover-cli-{}", std::process::id()));
    let run = |args: &[&str]| std::process::Command::new(&exe).args(args).output().expect("the command runs");
    let file = fixture("dangling_reference");
    let (file, vendor, out_s) = (file.to_str().unwrap(), vendor(), out.to_str().unwrap().to_string());
    let vendor = vendor.to_str().unwrap();
    let failed = run(&["rust", file, "--models", vendor, "--out", &out_s]);
    assert!(!failed.status.success());
    assert!(String::from_utf8_lossy(&failed.stderr).contains("error[NS0202]"));
    let ok = run(&["rust", file, "--models", vendor, "--out", &out_s, "--warn", "NS0202"]);
    let stderr = String::from_utf8_lossy(&ok.stderr);
    assert!(ok.status.success(), "{stderr}");
    assert!(stderr.contains("warning[NS0202]"), "{stderr}");
    assert!(out.join("mod.rs").exists(), "nothing written to {}", out.display());
    let refused = run(&["check", file, "--models", vendor, "-W", "NS0003"]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success() && stderr.contains("cannot be demoted"), "{stderr}");
    let table = run(&["codes", "NS0202", "NS0101"]);
    let stdout = String::from_utf8_lossy(&table.stdout);
    assert!(stdout.contains("the reference is dropped") && stdout.contains("cannot be demoted"), "{stdout}");
    let _ = std::fs::remove_dir_all(&out);
}

/// Enumeration fields without Value are -1; where the EnumStrings/EnumValues property disagrees, it decides
/// with NS0219. Diagnostics and code snapshotted.
#[test]
fn enumeration_values() {
    let out = compile_with("enum_values", Severities::new());
    assert!(out.ok(), "{}", out.render_diagnostics());
    let choices = out.diagnostics.items.iter().filter(|d| d.code == Code::EnumValueChoice).count();
    assert_eq!(choices, 2, "Mode and Level disagree with their properties:\n{}", out.render_diagnostics());
    insta::assert_snapshot!("enum_values_diagnostics", relative(&out.render_diagnostics()));
    let text = generate("enum_values", &[]).unwrap_or_else(|e| panic!("{e}"));
    for want in ["NotAvailable = -1", "SensorOK = 0", "Test5 = -1", "Four = 4", "Auto = 0", "Service = 2", "Low = 10", "High = 20"] {
        assert!(text.contains(want), "the generated enumerations lack `{want}`");
    }
    insta::assert_snapshot!("enum_values_rust", text);
}

/// An identical copy of a loaded node is a warning (and ignored); a differing one stays NS0201 with both
/// locations.
#[test]
fn redefinitions() {
    let out = compile_with("redefinition", Severities::new());
    assert!(out.ok(), "{}", out.render_diagnostics());
    assert_eq!(out.diagnostics.items.iter().filter(|d| d.code == Code::IdenticalRedefinition).count(), 2);
    insta::assert_snapshot!("redefinition_diagnostics", relative(&out.render_diagnostics()));
    insta::assert_snapshot!("redefinition_rust", generate("redefinition", &[]).unwrap_or_else(|e| panic!("{e}")));

    // The same copy of Byte, abstract: no longer identical.
    let text = std::fs::read_to_string(fixture("redefinition")).unwrap().replace(
        "<UADataType NodeId=\"i=3\" BrowseName=\"Byte\">",
        "<UADataType NodeId=\"i=3\" BrowseName=\"Byte\" IsAbstract=\"true\">",
    );
    let opts = Options { model_dirs: vec![vendor()], ..Options::default() };
    let out = compile(vec![Input::Text { name: "in-memory/redefinition_differs.xml".into(), text }], &opts);
    let d = out.diagnostics.items.iter().find(|d| d.code == Code::DuplicateNodeId).expect("NS0201 for the differing copy");
    assert!(d.is_error() && d.labels.len() == 1, "both locations are shown");
    assert_eq!(out.diagnostics.items.iter().filter(|d| d.code == Code::IdenticalRedefinition).count(), 1, "String is still identical");
    insta::assert_snapshot!("redefinition_differs_diagnostics", relative(&out.render_diagnostics()));
}
