//! Interoperability: a real third-party OPC UA client (python asyncua, from `.venv`) against the example
//! server of `nodeset-examples`, run as its own process.
//!
//! The test takes the example from `cargo test --workspace --no-run` (a no-op after `cargo test
//! --workspace`, which builds the examples with the same features), starts it on a free port, runs `tests/interop/robotics_check.py` with the suites below, and
//! stops the server with SIGTERM, which must end it cleanly. It fails, never skips, when the venv is
//! missing: run `cargo xtask venv`.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use nodeset_tests::{executable, root};
use process_support::Process;

/// The suites of `robotics_check.py` to run: the runtime's demo namespace (writes, methods, subscriptions)
/// and the generated DI, IA and Robotics namespaces against their NodeSet2 files.
const SUITES: &[&str] = &["demo", "robotics"];

/// The venv's python, or a failure that says how to create it.
fn python() -> PathBuf {
    let python = root().join(".venv/bin/python");
    assert!(python.is_file(), "the Python venv is missing ({}); run `cargo xtask venv`", python.display());
    let ok = Command::new(&python).args(["-c", "import asyncua"]).output().is_ok_and(|o| o.status.success());
    assert!(ok, "asyncua is not installed in {}; run `cargo xtask venv`", python.display());
    python
}

/// An example of nodeset-examples, from `cargo test --workspace --no-run` (see [`executable`]).
fn build_server(example: &str) -> PathBuf {
    executable("example", example)
}

/// Starts a server on a free port; the process and the URL it prints.
fn start(exe: &Path, args: &[&str]) -> (Process, String) {
    let server = spawn(exe, args);
    let url = server.line("listening on ");
    (server, url)
}

/// Starts a server on a free port.
fn spawn(exe: &Path, args: &[&str]) -> Process {
    Process::start(exe, &[&["--port", "0"][..], args].concat())
}

/// The next line the server prints (within a minute).
fn next(server: &Process) -> String {
    server.next_line(Duration::from_secs(60)).unwrap_or_else(|e| panic!("{e}"))
}

/// Sends SIGTERM, checks that the server ends cleanly, and returns what it printed after its URL.
fn stop(server: Process) -> Vec<String> {
    server.stop().unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn asyncua_client_against_the_example_server() {
    let python = python();
    let exe = build_server("server");
    // This test checks the model, not security: the None endpoint, deliberately (`--insecure`).
    let pki = temp_dir("example-server");
    let (server, url) = start(&exe, &["--demo", "--insecure", "--pki", pki.to_str().unwrap()]);
    let script = root().join("tests/interop/robotics_check.py");
    let mut check = Command::new(&python);
    check.arg(&script).args(["--url", &url]).args(["--nodesets"]).arg(root().join("nodesets/vendor"));
    for suite in SUITES {
        check.args(["--suite", suite]);
    }
    run_check(check);
    stop(server);
}

/// The six-axis robot example (typed handles, instantiation, the derive) against `robot_check.py`: the
/// instance against its types' instance declarations, a subscription to a joint position, writes to
/// read-only variables, the derived identification, a client write that must reach the derived struct (the
/// example prints the struct's field when it changes), typed methods with correct and wrong arguments.
#[test]
fn asyncua_client_against_the_robot_example() {
    let python = python();
    let exe = build_server("robot");
    // The model and typed handles, not security: the None endpoint, deliberately (`--insecure`).
    let pki = temp_dir("robot");
    let (server, url) = start(&exe, &["--insecure", "--pki", pki.to_str().unwrap()]);
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/robot_check.py")).args(["--url", &url]);
    run_check(check);
    let printed = stop(server);
    assert!(
        printed.iter().any(|l| l == "ConfiguredDefaultStopMode written by a client: 2"),
        "the client's write of ConfiguredDefaultStopMode did not reach the derived struct; the server printed {printed:?}"
    );
}

/// The robot cell example (three servers: the robot's move skills, the drilling unit's TemplateDrilling,
/// the cell's composite skills) against `skills_check.py`: the SkillSets, a move skill started with inputs
/// and followed through CurrentState and transition events, Halt, Start while Halted, Reset, and DrillHole
/// running the basic skills of the other two servers in order and halting with them.
#[test]
fn asyncua_client_against_the_robot_cell() {
    let python = python();
    let exe = build_server("robot_cell");
    // The python client uses the None endpoint (`--insecure`); the cell's composite skills still reach the
    // other two servers over SignAndEncrypt with a user name, and verify their certificates.
    let pki = temp_dir("robot-cell");
    let server = spawn(&exe, &["--motion-ms", "600", "--insecure", "--pki", pki.to_str().unwrap()]);
    let mut urls = Vec::new();
    for label in ["robot", "drilling unit", "cell"] {
        let line = next(&server);
        let url = line.strip_prefix(&format!("{label} listening on ")).unwrap_or_else(|| panic!("unexpected line {line:?}"));
        urls.push(url.to_owned());
    }
    assert_eq!(next(&server), "cell ready");
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/skills_check.py"));
    check.args(["--robot", &urls[0], "--unit", &urls[1], "--cell", &urls[2]]);
    run_check(check);
    stop(server);
}

/// A fresh folder in the system's temporary directory for one test's PKI folders and files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nodeset-interop-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the temporary folder can be created");
    dir
}

/// The example server, secure by default, against `security_check.py`: endpoints (no None), an untrusted
/// client certificate refused and stored in `rejected/`, SignAndEncrypt with the three policies and a user
/// name, a wrong password, anonymous read allowed and write/call refused with BadUserAccessDenied, an
/// Operator's write and call accepted, an Observer's refused. Then the same server with `--insecure`
/// offers a None endpoint.
#[test]
fn asyncua_client_against_a_secure_server() {
    use nodeset_runtime::server::{Role, Users};
    let python = python();
    let exe = build_server("server");
    let dir = temp_dir("secure");
    let mut users = Users::default();
    users.set_password("op", vec![Role::Operator], "op-secret-1").unwrap();
    users.set_password("obs", vec![Role::Observer], "obs-secret-2").unwrap();
    let users_file = dir.join("users.txt");
    std::fs::write(&users_file, users.to_text()).unwrap();
    let pki = dir.join("pki");
    let args = ["--demo", "--pki", pki.to_str().unwrap(), "--users", users_file.to_str().unwrap()];
    let (server, url) = start(&exe, &args);
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/security_check.py")).args(["--url", &url]).arg("--pki").arg(&pki);
    check.arg("--work").arg(dir.join("client"));
    check.args(["--user", "op", "--password", "op-secret-1", "--observer", "obs", "--observer-password", "obs-secret-2"]);
    run_check(check);
    stop(server);

    let (server, url) = start(&exe, &[&args[..], &["--insecure"]].concat());
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/security_check.py")).args(["--url", &url]).arg("--pki").arg(&pki);
    check.arg("--work").arg(dir.join("client"));
    check.args(["--user", "op", "--password", "op-secret-1", "--observer", "obs", "--observer-password", "obs-secret-2"]);
    check.arg("--expect-none");
    run_check(check);
    stop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `roles` fixture's RolePermissions, obeyed node by node (`roles_check.py`, which reads the expectations
/// from the fixture itself): for anonymous, an Operator, an Observer, an Engineer and a Supervisor, each
/// variable's UserAccessLevel, reads and writes and each method's UserExecutable and calls; over a signed,
/// unencrypted channel, the Recipe (AccessRestrictions EncryptionRequired) refuses reads, writes and
/// subscriptions. The calls that reach the server's code are exactly the allowed ones, with the caller's name.
#[test]
fn asyncua_finds_the_role_permissions_obeyed() {
    use nodeset_runtime::server::{Role, Users};
    let python = python();
    let exe = build_server("roles_server");
    let dir = temp_dir("roles");
    let people = [("op", Role::Operator), ("obs", Role::Observer), ("eng", Role::Engineer), ("sup", Role::Supervisor)];
    let mut users = Users::default();
    for (name, role) in people {
        users.set_password(name, vec![role], &format!("{name}-secret")).unwrap();
    }
    let users_file = dir.join("users.txt");
    std::fs::write(&users_file, users.to_text()).unwrap();
    let pki = dir.join("pki");
    // Certificates are not what this test is about: the client's is trusted on first use.
    let args = ["--pki", pki.to_str().unwrap(), "--users", users_file.to_str().unwrap(), "--trust-on-first-use"];
    let (server, url) = start(&exe, &args);
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/roles_check.py")).args(["--url", &url]);
    check.arg("--nodeset").arg(root().join("tests/fixtures/roles/Example.Roles.NodeSet2.xml"));
    check.arg("--work").arg(dir.join("client"));
    for (name, role) in people {
        check.args(["--user", &format!("{name}={role}:{name}-secret")]);
    }
    run_check(check);
    let printed = stop(server);
    let calls: Vec<&String> = printed.iter().filter(|l| l.contains(" called by ")).collect();
    assert_eq!(
        calls,
        ["Start called by op", "Start called by sup", "Reset called by sup"],
        "the calls that reached the server's code: {printed:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The `structure_values` fixture served by a generated server (`structures_server`), every structure value
/// read back by asyncua and compared field by field with the fixture's XML (`structures_check.py`): ns0's
/// EUInformation and Range, structures of another namespace, nested, optional fields, unions, arrays of
/// structures, fields the nodeset leaves out.
#[test]
fn asyncua_reads_back_every_structure_value() {
    let python = python();
    let exe = build_server("structures_server");
    let pki = temp_dir("structures");
    let (server, url) = start(&exe, &["--insecure", "--pki", pki.to_str().unwrap()]);
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/structures_check.py")).args(["--url", &url]);
    check.arg("--fixture").arg(root().join("tests/fixtures/structure_values"));
    run_check(check);
    stop(server);
    let _ = std::fs::remove_dir_all(&pki);
}

/// Runs a check script; fails unless it ends with `N passed, 0 failed`.
fn run_check(mut check: Command) {
    let mut child = check.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("python runs");
    let mut stdout = String::new();
    let mut stderr = String::new();
    child.stdout.take().unwrap().read_to_string(&mut stdout).unwrap();
    child.stderr.take().unwrap().read_to_string(&mut stderr).unwrap();
    let status = child.wait().unwrap();
    println!("{stdout}");
    eprintln!("{stderr}");
    let summary = stdout.lines().last().unwrap_or_default();
    assert!(
        status.success() && summary.ends_with(" passed, 0 failed"),
        "the check failed ({status}): {summary}"
    );
}

/// The defects python asyncua and python-opcua found in the robot example (issue 20), checked by
/// `defects_check.py --robot`: writes with an IndexRange to a scalar are refused and must not reach the
/// derived struct (the example prints every value its struct receives), AssetId is user writable and a
/// client's write reaches the struct, Server/Namespaces lists each namespace once.
#[test]
fn asyncua_finds_the_robot_defects_mended() {
    let python = python();
    let exe = build_server("robot");
    // What the third-party clients found, not security: the None endpoint, deliberately (`--insecure`).
    let pki = temp_dir("robot-defects");
    let (server, url) = start(&exe, &["--insecure", "--pki", pki.to_str().unwrap()]);
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/defects_check.py")).args(["--robot", &url]);
    run_check(check);
    let printed = stop(server);
    for rejected in [1, 3] {
        let line = format!("ConfiguredDefaultStopMode written by a client: {rejected}");
        assert!(!printed.contains(&line), "a rejected IndexRange write reached the derived struct: {printed:?}");
    }
    assert!(
        printed.iter().any(|l| l == "AssetId written by a client: \"cell-2/robot\""),
        "the client's write of AssetId did not reach the derived struct; the server printed {printed:?}"
    );
}

/// The defects found in the robot cell (issue 20), checked by `defects_check.py --cell` on the cell's
/// server: transition event fields selected through TransitionEventType, asyncua's default event
/// subscription (`EventType InList [...]`) for the skill event type, Server/Namespaces once per namespace.
#[test]
fn asyncua_finds_the_robot_cell_defects_mended() {
    let python = python();
    let exe = build_server("robot_cell");
    let pki = temp_dir("robot-cell-defects");
    let server = spawn(&exe, &["--motion-ms", "600", "--insecure", "--pki", pki.to_str().unwrap()]);
    let mut urls = Vec::new();
    for label in ["robot", "drilling unit", "cell"] {
        let line = next(&server);
        let url = line.strip_prefix(&format!("{label} listening on ")).unwrap_or_else(|| panic!("unexpected line {line:?}"));
        urls.push(url.to_owned());
    }
    assert_eq!(next(&server), "cell ready");
    let mut check = Command::new(&python);
    check.arg(root().join("tests/interop/defects_check.py")).args(["--cell", &urls[2]]);
    run_check(check);
    stop(server);
}
