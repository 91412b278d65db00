//! `nodeset-compiler verify` against live servers, run as the user runs it (the command, `--json`):
//!
//! - the robot example over SignAndEncrypt with a user name (its certificate trusted the way an operator
//!   trusts it: refused first, then moved from `rejected/` to `trusted/`), and with `--insecure` over None;
//! - the robot cell's three servers (with `--insecure`): no violation;
//! - a node-opcua server (`tests/node-peer/server.js`, installed by `cargo xtask node-peer`) with ns0, DI, IA
//!   and Robotics, one correct MotionDeviceSystem and one with three planted defects: exactly those three;
//! - a server namespace no nodeset defines: NS0409, and the run fails;
//! - NodeSet2 files served as they are by node-opcua (`tests/node-peer/serve.js`): a fixture with planted
//!   defects and files of the UA-Nodeset tree with static instances; `verify` of that server and `check` of
//!   the files give the same findings (codes, severities, paths);
//! - a server that does not trust verify's certificate: verify says so at once, and what to do;
//! - `nodeset-compiler serve` of files: every type instantiated and sound, secure by default, following the
//!   model where async-opcua's ns0 differs, every structure value of the files read back with its content.
//!
//! Bad input without a server (no server, a malformed URL, a file that is not a nodeset) is tested in
//! `nodeset-compiler/tests/cli.rs`.
//!
//! The command and the examples come from `cargo test --workspace --no-run`, as in `interop.rs`. The test
//! fails, never skips, when node or the node-opcua packages are missing, saying how to install them.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use nodeset_compiler::load::Input;
use nodeset_compiler::verify::instances::static_findings_by_uri;
use nodeset_compiler::verify::report::json_findings_by_uri;
use nodeset_compiler::{compile, Options};
use nodeset_tests::{command_binary, corpus, executable, root, vendor};
use process_support::Process;

/// The URLs of the next `n` lines that contain `listening on <url>`.
fn urls(server: &Process, n: usize) -> Vec<String> {
    (0..n).map(|_| server.line("listening on ")).collect()
}

/// A fresh folder in the system's temporary directory.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nodeset-verify-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the temporary folder can be created");
    dir
}

/// Runs `nodeset-compiler verify URL ARGS --json`; returns the output and the JSON on stdout.
fn verify(url: &str, args: &[&str], env: &[(&str, &str)]) -> (Output, String) {
    let mut command = Command::new(executable("bin", "nodeset-compiler"));
    command.current_dir(root()).arg("verify").arg(url).args(args).arg("--json");
    for (k, v) in env {
        command.env(k, v);
    }
    let output = command.output().expect("verify runs");
    let json = String::from_utf8_lossy(&output.stdout).into_owned();
    (output, json)
}

/// The `"key":value` number of the report.
fn number(json: &str, key: &str) -> u64 {
    let at = json.find(&format!("\"{key}\":")).unwrap_or_else(|| panic!("no {key} in {json}")) + key.len() + 3;
    json[at..].chars().take_while(char::is_ascii_digit).collect::<String>().parse().unwrap()
}

/// (code, path) of every finding, in the report's order.
fn findings(json: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for part in json.split("{\"code\":").skip(1) {
        let code = part[1..7].to_owned();
        let path_at = part.find("\"path\":\"").unwrap() + 8;
        let path = part[path_at..path_at + part[path_at..].find('"').unwrap()].to_owned();
        out.push((code, path));
    }
    out
}

/// `--models` for the pinned companion specs and this repository's own nodesets.
fn models() -> Vec<String> {
    vec!["--models".into(), vendor().display().to_string(), "--models".into(), root().join("nodesets").display().to_string()]
}

/// Verifies `url` and asserts a clean report; returns the JSON.
fn assert_clean(url: &str, extra: &[&str], env: &[(&str, &str)]) -> String {
    let models = models();
    let args: Vec<&str> = models.iter().map(String::as_str).chain(extra.iter().copied()).collect();
    let (output, json) = verify(url, &args, env);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(findings(&json), Vec::<(String, String)>::new(), "{url}: {json}\n{stderr}");
    assert!(output.status.success(), "{url}: exit {}: {json}\n{stderr}", output.status);
    assert!(number(&json, "checked") > 100, "{url}: too few nodes checked: {json}");
    // Batched reads: a few dozen round trips, not one per node.
    assert!(number(&json, "round_trips") < 50, "{url}: too many round trips: {json}");
    eprintln!("{url}: {json}");
    json
}

#[test]
fn the_robot_example_verifies_clean_over_sign_and_encrypt_with_a_user() {
    use nodeset_runtime::server::{Role, Users};
    let dir = temp_dir("robot-secure");
    let mut users = Users::default();
    users.set_password("op", vec![Role::Operator], "op-secret-1").unwrap();
    let users_file = dir.join("users.txt");
    std::fs::write(&users_file, users.to_text()).unwrap();
    let (server_pki, client_pki) = (dir.join("server-pki"), dir.join("client-pki"));
    let mut command = Command::new(executable("example", "robot"));
    // The server trusts the verifying client's certificate on first use; the client trusts the server's
    // only once an operator has moved it to `trusted/`.
    command.args(["--port", "0", "--pki", server_pki.to_str().unwrap(), "--users", users_file.to_str().unwrap(), "--trust-on-first-use"]);
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    let url = urls(&server, 1).remove(0);
    // No security options: verify connects over Basic256Sha256 SignAndEncrypt by default.
    let secure = [
        "--user",
        "op",
        "--password-env",
        "VERIFY_TEST_PASSWORD",
        "--pki",
        client_pki.to_str().unwrap(),
    ];
    let env = [("VERIFY_TEST_PASSWORD", "op-secret-1")];
    let models = models();
    let args: Vec<&str> = models.iter().map(String::as_str).chain(secure.iter().copied()).collect();
    // First contact: the server's certificate is not trusted, so verify refuses to go on (status 2).
    let (output, _) = verify(&url, &args, &env);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "an untrusted server certificate must stop verify: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let rejected: Vec<PathBuf> =
        std::fs::read_dir(client_pki.join("rejected")).expect("the refused certificate is in rejected/").map(|e| e.unwrap().path()).collect();
    assert_eq!(rejected.len(), 1, "{rejected:?}");
    // The message says where the certificate is and what to do with it.
    assert!(stderr.contains(&format!("the server's certificate is not trusted; it was put in {}", rejected[0].display())), "{stderr}");
    assert!(stderr.contains(&format!("move it to {}", client_pki.join("trusted").display())), "{stderr}");
    let trusted = client_pki.join("trusted");
    std::fs::create_dir_all(&trusted).unwrap();
    std::fs::rename(&rejected[0], trusted.join(rejected[0].file_name().unwrap())).unwrap();
    assert_clean(&url, &secure, &env);
    // A wrong password is refused with a clear message, not a panic.
    let (output, _) = verify(&url, &args, &[("VERIFY_TEST_PASSWORD", "wrong")]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_robot_example_verifies_clean_over_none() {
    let pki = temp_dir("robot-none");
    let mut command = Command::new(executable("example", "robot"));
    command.args(["--port", "0", "--insecure", "--pki", pki.to_str().unwrap()]);
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    let url = urls(&server, 1).remove(0);
    assert_clean(&url, &["--insecure"], &[]);
    drop(server);
    let _ = std::fs::remove_dir_all(&pki);
}

#[test]
fn the_robot_cell_verifies_clean() {
    let pki = temp_dir("robot-cell");
    let mut command = Command::new(executable("example", "robot_cell"));
    command.args(["--port", "0", "--insecure", "--pki", pki.to_str().unwrap()]);
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    for url in urls(&server, 3) {
        assert_clean(&url, &["--insecure"], &[]);
    }
    drop(server);
    let _ = std::fs::remove_dir_all(&pki);
}

/// The node-opcua peer's folder, with its packages installed, or a failure that says how to install them.
fn node_peer() -> PathBuf {
    let dir = root().join("tests/node-peer");
    let ok = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    assert!(ok, "node is not installed; install Node.js 20 or newer with npm (e.g. `apt-get install nodejs npm`), then run `cargo xtask node-peer`");
    assert!(
        dir.join("node_modules/node-opcua/package.json").is_file(),
        "node-opcua is not installed in {}; run `cargo xtask node-peer`",
        dir.display()
    );
    dir
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

#[test]
fn a_node_opcua_server_with_planted_defects() {
    let dir = node_peer();
    let port = free_port().to_string();
    let mut command = Command::new("node");
    command.current_dir(&dir).arg(Path::new("server.js")).arg(&port);
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    let url = urls(&server, 1).remove(0);
    let models = models();
    let args: Vec<&str> = models.iter().map(String::as_str).chain(["--insecure"]).collect();
    let (output, json) = verify(&url, &args, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("{json}\n{stderr}");
    // The server numbers its own namespace 1, DI 2, IA 3 and Robotics 4. The findings come sorted by path.
    let want = [
        ("NS0407", "2:DeviceSet/1:BadSystem/4:MotionDevices/1:NotAMotionDevice"),
        ("NS0401", "2:DeviceSet/1:BadSystem/4:MotionDevices/1:Robot"),
        ("NS0406", "2:DeviceSet/1:BadSystem/4:MotionDevices/1:Robot/2:Model"),
    ];
    assert_eq!(findings(&json), want.map(|(c, p)| (c.to_owned(), p.to_owned())).to_vec(), "{json}");
    assert_eq!(output.status.code(), Some(1), "violations give exit status 1");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(number(&json, "checked") > 100, "{json}");
    // Each finding names the declaration it violates and its place in a NodeSet2 file.
    assert_eq!(json.matches("\"declaration\":{\"file\":").count(), 3, "{json}");
    // The same run in text: rustc-style, with the browse path and the summary.
    let (output, _) = {
        let mut command = Command::new(executable("bin", "nodeset-compiler"));
        command.current_dir(root()).arg("verify").arg(&url).args(&args);
        let output = command.output().expect("verify runs");
        (output, ())
    };
    let text = String::from_utf8_lossy(&output.stderr);
    assert!(text.contains("error[NS0401]: `2:DeviceSet/1:BadSystem/4:MotionDevices/1:Robot` has no mandatory Variable `2:SerialNumber`"), "{text}");
    // SerialNumber is declared (again) by Robotics' MotionDeviceType.
    assert!(text.contains("Opc.Ua.Robotics.NodeSet2.xml:6163:3"), "{text}");
    assert!(text.contains("3 violation(s), 0 warning(s)"), "{text}");
    // --warn demotes a finding: it stays in the report, and only the others fail the run.
    let demoted: Vec<&str> = args.iter().copied().chain(["--warn", "NS0401", "--allow", "NS0406", "--warn", "NS0407"]).collect();
    let (output, json) = verify(&url, &demoted, &[]);
    assert_eq!(output.status.code(), Some(0), "{json}");
    assert_eq!(number(&json, "violations"), 0, "{json}");
    assert_eq!(number(&json, "warnings"), 2, "{json}");
    drop(server);
}

#[test]
fn a_server_namespace_without_a_nodeset_is_reported() {
    let dir = temp_dir("robot-no-robotics");
    let pki = dir.join("pki");
    let mut command = Command::new(executable("example", "robot"));
    command.args(["--port", "0", "--insecure", "--pki", pki.to_str().unwrap()]);
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    let url = urls(&server, 1).remove(0);
    // A models folder with ns0 and DI only: the IA and Robotics types the robot is made of are unknown.
    let models = dir.join("models");
    std::fs::create_dir_all(&models).unwrap();
    for file in ["Opc.Ua.NodeSet2.xml", "Opc.Ua.Di.NodeSet2.xml"] {
        std::fs::copy(vendor().join(file), models.join(file)).unwrap();
    }
    let (output, json) = verify(&url, &["--models", models.to_str().unwrap(), "--insecure"], &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "an incomplete check must fail: {json}\n{stderr}");
    assert!(json.contains("\"unknown_namespaces\":[") && json.contains("http://opcfoundation.org/UA/Robotics/"), "{json}");
    let found = findings(&json);
    assert!(!found.is_empty() && found.iter().all(|(code, _)| code == "NS0409"), "{json}");
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn check_and_verify_agree_on_static_instances_served_by_node_opcua() {
    let dir = node_peer();
    let tree = corpus();
    // A fixture with one planted defect of each kind, and files of the UA-Nodeset tree with static
    // instances below the Objects folder that break the rules (GDS: a missing mandatory member; DEXPI:
    // ModellingRules on instances; the laser system example: missing mandatory variables), with the models
    // they require, from the same tree (DI and Machinery among them, with static instances of their own).
    let named: Vec<PathBuf> = [
        root().join("tests/fixtures/bad/static_instances.xml"),
        tree.join("GDS/Opc.Ua.Gds.NodeSet2.xml"),
        tree.join("DEXPI/Opc.Ua.DEXPI.NodeSet2.xml"),
        tree.join("LaserSystems/LaserSystem-Example.NodeSet2.xml"),
    ]
    .into();
    // `check` of every file the server loads (the named ones and the models they require), on what a
    // server's walk from the Objects folder reaches; the same function `cargo xtask serve-corpus` compares with.
    let checked = static_findings_by_uri(&named, std::slice::from_ref(&tree)).unwrap_or_else(|e| panic!("{e}"));
    // What the server loads: every file loaded, dependencies first.
    let opts = Options { model_dirs: vec![tree.clone()], ..Options::default() };
    let loaded = compile(named.iter().cloned().map(Input::Path).collect(), &opts);
    assert!(loaded.ok(), "{}", loaded.render_diagnostics());
    let defining: std::collections::BTreeSet<_> = loaded.model.models.iter().map(|m| m.file).collect();
    let files: Vec<PathBuf> =
        loaded.model.sources.files().filter(|(id, _)| defining.contains(id)).map(|(_, f)| f.path.clone()).collect();
    // The defects planted in the fixture are among them.
    let fixture = "http://example.com/bad/static_instances/|Bad";
    let planted: Vec<&str> = checked.iter().filter(|f| f.2.starts_with(fixture)).map(|f| f.0.as_str()).collect();
    assert_eq!(planted, ["NS0401", "NS0401", "NS0403", "NS0404", "NS0405", "NS0406", "NS0408"], "{checked:#?}");
    assert!(checked.len() > planted.len(), "the corpus files should add findings of their own: {checked:#?}");

    let port = free_port().to_string();
    let mut command = Command::new("node");
    command.current_dir(&dir).arg("serve.js").arg(&port).args(&files);
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    let url = urls(&server, 1).remove(0);
    let args: Vec<String> = files.iter().map(|f| f.display().to_string()).chain(["--insecure".to_owned()]).collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (output, json) = verify(&url, &args, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    let mut verified = json_findings_by_uri(&json);
    // One defect node-opcua hides: its loader does not serve the enumeration's UInt16 as the file writes
    // it (it reads back as UncertainInitialValue), so that server cannot show it; a server that serves the
    // value as written (ours, issue 37) gives verify the same NS0406 that check gives.
    let repaired = ("NS0406".to_owned(), "error".to_owned(), format!("{fixture}/http://example.com/bad/static_instances/|Mode"));
    assert!(!verified.contains(&repaired), "{json}");
    verified.push(repaired);
    verified.sort();
    assert_eq!(checked, verified, "check (left) and verify (right) disagree\n{json}\n{stderr}");
    assert_eq!(output.status.code(), Some(1), "violations give exit status 1: {stderr}");
    drop(server);
}

#[test]
fn a_server_that_does_not_trust_verify_says_so_at_once() {
    let dir = temp_dir("robot-untrusting");
    let (server_pki, client_pki) = (dir.join("server-pki"), dir.join("client-pki"));
    // No --trust-on-first-use: the robot refuses a client certificate it has not been told to trust.
    let mut command = Command::new(executable("example", "robot"));
    command.args(["--port", "0", "--pki", server_pki.to_str().unwrap()]);
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    let url = urls(&server, 1).remove(0);
    let models = models();
    // Verify trusts the server (--trust-server-cert), so only the server's refusal is left.
    let args: Vec<&str> =
        models.iter().map(String::as_str).chain(["--pki", client_pki.to_str().unwrap(), "--trust-server-cert"]).collect();
    let start = std::time::Instant::now();
    let (output, _) = verify(&url, &args, &[]);
    let took = start.elapsed();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(took < std::time::Duration::from_secs(5), "the refusal took {took:?}, not well under the 10 s timeout: {stderr}");
    assert!(stderr.contains("the server rejected verify's application certificate (BadCertificateUntrusted)")
        || stderr.contains("the server rejected verify's application certificate (BadSecurityChecksFailed)"), "{stderr}");
    let own = client_pki.join("own/cert.der");
    assert!(stderr.contains(&format!("verify's certificate is {}", own.display())), "{stderr}");
    assert!(stderr.contains("move it from there to `trusted/`"), "{stderr}");
    // The advice holds: the server has put verify's certificate in its `rejected/` folder ...
    let rejected: Vec<PathBuf> = std::fs::read_dir(server_pki.join("rejected")).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(rejected.len(), 1, "{rejected:?}");
    assert_eq!(std::fs::read(&rejected[0]).unwrap(), std::fs::read(&own).unwrap(), "the server rejected another certificate");
    // ... and once trusted with the command the advice names (it moves the certificate out of `rejected/`,
    // where async-opcua would still refuse it), verify gets its session (a running server reads `trusted/` on
    // each connection).
    let command = format!("nodeset-compiler trust --pki <the server's PKI folder> {}", own.display());
    assert!(stderr.contains(&command), "{stderr}");
    let trust = Command::new(command_binary()).args(["trust", "--pki"]).arg(&server_pki).arg(&own).output().unwrap();
    let said = String::from_utf8_lossy(&trust.stdout);
    assert!(trust.status.success(), "{said}{}", String::from_utf8_lossy(&trust.stderr));
    assert!(said.contains("; removed from rejected/"), "{said}");
    assert!(!rejected[0].exists() && server_pki.join("trusted").join(rejected[0].file_name().unwrap()).exists());
    assert_clean(&url, &["--pki", client_pki.to_str().unwrap(), "--trust-server-cert"], &[]);
    drop(server);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `nodeset-compiler serve FILES --models ... ARGS --port 0 --pki PKI`, its stderr in `stderr`; the server
/// and its URL once it listens.
fn serve(files: &[PathBuf], args: &[&str], pki: &Path, stderr: &Path) -> (Process, String) {
    let mut command = Command::new(command_binary());
    command.current_dir(root()).arg("serve").args(files).args(models()).args(args);
    command.args(["--port", "0", "--pki", pki.to_str().unwrap()]);
    command.stderr(std::fs::File::create(stderr).unwrap());
    let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
    let url = server.wait_for("listening on ", process_support::STARTUP).unwrap_or_else(|e| {
        panic!("{e}; serve said:\n{}", std::fs::read_to_string(stderr).unwrap_or_default())
    });
    (server, url)
}

/// The vendor fixture and Robotics as `serve` names them (Robotics as a named file, so its types are
/// instantiated too).
fn robotics_and_vendor() -> Vec<PathBuf> {
    let fixture = root().join("tests/fixtures/vendor_robot");
    vec![vendor().join("Opc.Ua.Robotics.NodeSet2.xml"), fixture.join("Example.VendorRobot.NodeSet2.xml")]
}

/// `--models` for `serve` and `verify` of the vendor fixture.
fn vendor_models() -> [String; 2] {
    ["--models".into(), root().join("tests/fixtures/vendor_robot").display().to_string()]
}

#[test]
fn serve_instantiates_every_type_and_verify_and_node_opcua_find_them_sound() {
    let dir = temp_dir("serve-all");
    let (pki, client_pki, node_pki, log) = (dir.join("server-pki"), dir.join("verify-pki"), dir.join("node-pki"), dir.join("serve.log"));
    let extra = vendor_models();
    // Secure only (no --insecure): the clients come in over SignAndEncrypt, their certificates trusted on
    // first use.
    let args: Vec<&str> = extra.iter().map(String::as_str).chain(["--instantiate-all", "--trust-on-first-use"]).collect();
    let (server, url) = serve(&robotics_and_vendor(), &args, &pki, &log);
    let said = std::fs::read_to_string(&log).unwrap();
    // Robotics' 24 concrete ObjectTypes and the fixture's ArmType, ArmXType and ArmYType, each instantiated.
    assert!(said.contains("instantiated 27 of 27 concrete ObjectType(s) below Objects/Instances"), "{said}");
    assert!(!said.contains("is not instantiated"), "{said}");
    assert!(said.contains("WARNING: nodeset-compiler serve: --trust-on-first-use"), "{said}");
    assert!(!said.contains("--insecure"), "no None endpoint was asked for: {said}");

    let mut command = Command::new(command_binary());
    command.current_dir(root()).arg("verify").arg(&url).args(models()).args(&extra);
    command.args(["--pki", client_pki.to_str().unwrap(), "--trust-server-cert", "--json"]);
    let output = command.output().expect("verify runs");
    let json = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    // Every instance below Objects/Instances (and every static instance of the files) conforms to its type.
    assert_eq!(findings(&json), Vec::<(String, String)>::new(), "{json}\n{stderr}");
    assert!(output.status.success(), "{json}\n{stderr}");
    assert!(number(&json, "checked") > 300, "{json}");

    // node-opcua browses Objects/Instances and reads every variable there, over SignAndEncrypt.
    let peer = node_peer();
    let output = Command::new("node").current_dir(&peer).arg("browse.js").arg(&url).arg("Instances").arg(&node_pki).output().expect("node runs");
    let out = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{out}\n{}", String::from_utf8_lossy(&output.stderr));
    let summary = out.lines().last().unwrap_or_default();
    let count = |key: &str| -> u64 {
        let words: Vec<&str> = summary.split(' ').collect();
        let at = words.iter().position(|w| *w == key).unwrap_or_else(|| panic!("no {key} in {summary}"));
        words[at + 1].parse().unwrap()
    };
    assert!(count("variables") > 200 && count("objects") > 80 && count("methods") > 0, "{out}");
    assert_eq!((count("bad"), count("good") + count("uncertain")), (0, count("variables")), "{out}");
    // Values come from the nodeset or the DataType's default; only structures (EUInformation, RationalNumber)
    // and BaseDataType (a ParameterSet's placeholder element) have none.
    let empty: Vec<&str> = out.lines().filter(|l| l.starts_with("empty ")).collect();
    assert_eq!(empty.len() as u64, count("empty"), "{out}");
    let empty_types: BTreeSet<&str> = empty.iter().filter_map(|l| l.rsplit(' ').next()).collect();
    assert_eq!(empty_types, BTreeSet::from(["ns=0;i=18806", "ns=0;i=24", "ns=0;i=887"]), "{out}");
    // The state machines start in their initial state (Robotics marks one in its substate machines only).
    assert!(out.lines().any(|l| l == "state Instances/IdleSubstateMachineType/CurrentState StandBy"), "{out}");
    assert!(said.contains("2 state machine(s) served"), "{said}");
    // SIGTERM stops it cleanly.
    server.stop().unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn serve_is_secure_by_default() {
    let dir = temp_dir("serve-secure");
    let files = [root().join("tests/fixtures/vendor_robot/Example.VendorRobot.NodeSet2.xml")];
    let extra = vendor_models();
    let args: Vec<&str> = extra.iter().map(String::as_str).collect();
    let (server, url) = serve(&files, &args, &dir.join("pki"), &dir.join("secure.log"));
    // The PKI folder has the runtime's layout, the certificate created on first start.
    for sub in ["own/cert.der", "private/private.pem", "trusted", "rejected", "issuers"] {
        assert!(dir.join("pki").join(sub).exists(), "{sub}");
    }
    // No None endpoint: a client that asks for one gets no session.
    let verify_insecure = |url: &str| {
        let mut command = Command::new(command_binary());
        command.current_dir(root()).arg("verify").arg(url).args(models()).args(&extra).args(["--insecure", "--json"]);
        command.output().expect("verify runs")
    };
    let output = verify_insecure(&url);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("None"), "{stderr}");
    assert!(!std::fs::read_to_string(dir.join("secure.log")).unwrap().contains("WARNING"), "the secure defaults warn of nothing");
    server.stop().unwrap_or_else(|e| panic!("{e}"));
    // --insecure adds it, with the runtime's warning; --seconds ends the server by itself, cleanly.
    let (server, url) = serve(&files, &[&args[..], &["--insecure", "--seconds", "10"]].concat(), &dir.join("pki"), &dir.join("insecure.log"));
    let said = std::fs::read_to_string(dir.join("insecure.log")).unwrap();
    assert!(said.contains("WARNING: nodeset-compiler serve: --insecure: a SecurityPolicy None endpoint is open"), "{said}");
    let output = verify_insecure(&url);
    let json = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{json}\n{}", String::from_utf8_lossy(&output.stderr));
    server.wait_for("server stopped cleanly", std::time::Duration::from_secs(40)).unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every structure value of the `structure_values` fixture (ns0's EUInformation and Range, scalar and array; a
/// structure of another namespace; nested structures in place and as ExtensionObjects; optional fields; unions;
/// a Variant field; NodeIds and QualifiedNames of two namespaces) reads back from `serve` with the content the
/// file gives: `verify` reads each one and compares it field by field with the file. A server of a copy whose
/// Range differs in one field (planted) is caught at that field.
#[test]
fn serve_gives_back_every_structure_value_of_the_files() {
    let dir = temp_dir("serve-structures");
    let fixture = root().join("tests/fixtures/structure_values");
    let file = fixture.join("Example.StructureValues.NodeSet2.xml");
    let text = std::fs::read_to_string(&file).unwrap();
    let planted = dir.join("Example.StructureValues.NodeSet2.xml");
    std::fs::write(&planted, text.replacen("<High>120</High>", "<High>121</High>", 1)).unwrap();
    assert_ne!(std::fs::read_to_string(&planted).unwrap(), text, "the defect is planted");
    let extra = ["--models".to_owned(), fixture.display().to_string()];
    let args: Vec<&str> = extra.iter().map(String::as_str).chain(["--insecure"]).collect();
    let models = models();
    for (served, want) in [(&file, None), (&planted, Some(":Span: .1: the file gives Double(120.0), the server sent Double(121.0)"))] {
        let (server, url) = serve(std::slice::from_ref(served), &args, &dir.join("pki"), &dir.join("serve.log"));
        // verify holds the server to the fixture itself.
        let verify_args: Vec<&str> =
            [file.to_str().unwrap()].into_iter().chain(models.iter().map(String::as_str)).chain(args.iter().copied()).collect();
        let (output, json) = verify(&url, &verify_args, &[]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        // The twelve variables of the fixture's Workshop whose values are structures, each compared.
        assert_eq!(number(&json, "structures_compared"), 12, "{json}\n{stderr}");
        match want {
            None => {
                assert!(json.contains("\"structure_mismatches\":[]"), "{json}\n{stderr}");
                assert!(output.status.success(), "{json}\n{stderr}");
            }
            Some(want) => {
                let at = json.find("\"structure_mismatches\":[").unwrap() + 24;
                let list = &json[at..at + json[at..].find(']').unwrap()];
                assert_eq!(list.matches("\",\"").count(), 0, "one difference: {list}");
                assert!(list.contains(want), "{list}");
                assert_eq!(output.status.code(), Some(1), "a difference fails verify: {stderr}");
            }
        }
        drop(server);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The ns0 a server serves is async-opcua's (1.05.04); the files were resolved against another (the tree's
/// 1.05.03, the registry package's 1.05.07). Where the two differ, `serve --instantiate-all` follows the
/// model, the rule `verify` checks: DI's alarm types get ConditionType's `ConditionSubClassId` and
/// `ConditionSubClassName` (Mandatory in 1.05.03, Optional in async-opcua's), and ns0's PubSub diagnostics
/// types get the counters their `Counters` inherits from PubSubDiagnosticsType's (async-opcua serves ns0
/// without the compiler's override links; the model's are given to `instantiate`).
#[test]
fn serve_follows_the_model_where_the_served_ns0_differs() {
    let dir = temp_dir("serve-ns0");
    let tree = corpus();
    // Before, verify found 8 missing members on DI's instances, and 24 on ns0's.
    let cases = [
        ("di", tree.join("DI/Opc.Ua.Di.NodeSet2.xml"), tree.clone()),
        ("ns0", vendor().join("Opc.Ua.NodeSet2.xml"), vendor()),
        // 1.05.03's AuditClientUpdateMethodResultEventType has MethodId and ObjectId of DataType NodeId where
        // async-opcua's has ExpandedNodeId: the served declarations take the model's (before, two NS0404).
        ("ns0-1.05.03", tree.join("Schema/Opc.Ua.NodeSet2.xml"), tree.clone()),
    ];
    for (name, file, models) in cases {
        let log = dir.join(format!("{name}.log"));
        let mut command = Command::new(command_binary());
        command.current_dir(root()).arg("serve").arg(&file).arg("--models").arg(&models);
        command.args(["--instantiate-all", "--insecure", "--port", "0", "--pki"]).arg(dir.join("pki"));
        command.stderr(std::fs::File::create(&log).unwrap());
        let server = Process::spawn(&mut command).unwrap_or_else(|e| panic!("{e}"));
        let url = server.wait_for("listening on ", process_support::STARTUP).unwrap_or_else(|e| {
            panic!("{e}; serve said:\n{}", std::fs::read_to_string(&log).unwrap_or_default())
        });
        let models = models.display().to_string();
        let (output, json) = verify(&url, &[file.to_str().unwrap(), "--models", &models, "--insecure"], &[]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(findings(&json), Vec::<(String, String)>::new(), "{name}: {json}\n{stderr}");
        assert!(number(&json, "checked") > 250, "{name}: {json}");
        let said = std::fs::read_to_string(&log).unwrap();
        assert!(said.contains("instantiated "), "{name}: {said}");
        assert!(!said.contains("is not instantiated"), "{name}: {said}");
        if name == "ns0" {
            // The registry package's ns0 is 1.05.07: its nodes async-opcua's 1.05.04 lacks are served from the
            // model, so that its ObjectTypes are instantiated (before, eight were not, LogObjectType among them).
            assert!(said.contains("note: 363 node(s) of the model's OPC UA namespace (1.05.07) that async-opcua's ns0 lacks are served from the model, 14 ObjectType(s) among them: ApplicationConfigurationFileType,"), "{said}");
        }
        if name == "ns0-1.05.03" {
            assert!(said.contains("note: 2 InstanceDeclaration(s) of the OPC UA namespace served with the DataType and ValueRank of the model's (1.05.03), where async-opcua's differ: AuditClientUpdateMethodResultEventType/MethodId, AuditClientUpdateMethodResultEventType/ObjectId"), "{said}");
        }
        // DI's LockingServicesType instance gets DI's locking (the runtime's, as the robot example's Lock).
        assert_eq!(said.contains("served DI locking on 1 Lock object(s)"), name == "di", "{name}: {said}");
        drop(server);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// serve-corpus accepts a violation below `Objects/Instances` only where `check` names the defect of the
/// nodeset behind it: I4AAS gives four `Keys` declarations a scalar value with ValueRank 1 (check's NS0209,
/// pointing into the Value), which every instance holds (verify's NS0406, pointing at the declaration).
#[test]
fn check_explains_the_instance_findings_of_a_value_that_contradicts_its_type() {
    let file = vendor().join("Opc.Ua.I4AAS.NodeSet2.xml");
    let explains = nodeset_compiler::verify::instances::findings_check_explains(&[file.clone()], &[vendor()]).unwrap();
    let path = file.canonicalize().unwrap().display().to_string();
    for line in [2537, 3839, 3886, 3923] {
        let why = explains.get(&("NS0406".to_owned(), path.clone(), line)).unwrap_or_else(|| panic!("line {line}: {explains:?}"));
        assert!(why.starts_with("warning[NS0209]: the value of `Keys` is a scalar, but its ValueRank is 1"), "{why}");
    }
    // Only declarations check names: DI has no such defect.
    let di = vendor().join("Opc.Ua.Di.NodeSet2.xml");
    assert_eq!(nodeset_compiler::verify::instances::findings_check_explains(&[di], &[vendor()]).unwrap().len(), 0);
}
