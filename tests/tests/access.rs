//! RolePermissions and AccessRestrictions travel from the nodesets into the generated tables, node by node
//! (`Access` lines, which the runtime's access policy reads): a node's own, or else its model's defaults.
//! The model-defaults file lives in `tests/access/`, outside `tests/fixtures/`, whose every folder is one
//! fixture with Rust and Modelica snapshots; it is about the tables only.

use nodeset_compiler::build::Builder;
use nodeset_tests::{root, vendor};

/// The `Access` lines of the table generated for one file (under `tests/`).
fn access_lines(file: &str) -> Vec<String> {
    let out = std::env::temp_dir().join(format!("nodeset-access-{}-{}", std::process::id(), file.replace('/', "-")));
    let fixture = root().join("tests").join(file);
    let generated = Builder::new().cargo_output(false).models_dir(vendor()).out_dir(&out).file(fixture).generate();
    let text = std::fs::read_to_string(generated.unwrap_or_else(|e| panic!("{file}: {e}"))).expect("the generated file");
    let _ = std::fs::remove_dir_all(&out);
    text.lines().filter(|l| l.starts_with("Access ")).map(str::to_owned).collect()
}

/// The model's DefaultRolePermissions and DefaultAccessRestrictions reach every node of its namespace that
/// has none of its own; a node's own RolePermissions and AccessRestrictions win, each on its own.
#[test]
fn model_defaults_fill_what_nodes_leave_out() {
    assert_eq!(
        access_lines("access/Example.RoleDefaults.NodeSet2.xml"),
        [
            // Line: both defaults (Operator 33, Engineer 97; EncryptionRequired).
            "Access 1:5001 2 0:15680=33 0:16036=97",
            // Speed: its own Supervisor 97 and its own AccessRestrictions 0.
            "Access 1:6001 0 0:15692=97",
            // Mode: its own Observer 33, the default AccessRestrictions.
            "Access 1:6002 2 0:15668=33",
        ]
    );
}

/// Without model defaults, only the nodes that give RolePermissions or AccessRestrictions have a line.
#[test]
fn nodes_without_their_own_have_no_line() {
    let lines = access_lines("fixtures/roles/Example.Roles.NodeSet2.xml");
    let ids: Vec<&str> = lines.iter().filter_map(|l| l.split(' ').nth(1)).collect();
    assert_eq!(ids, ["1:6001", "1:6002", "1:7001", "1:7002"], "{lines:#?}");
}
