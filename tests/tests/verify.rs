//! `nodeset-compiler verify` against live servers, run as the user runs it (the CLI, `--json`):
//!
//! - every example server of `nodeset-examples` (server, robot, the three servers of robot_cell): no
//!   violation;
//! - a node-opcua server (`tests/node-peer/server.js`, installed by `cargo xtask node-peer`) with ns0, DI, IA
//!   and Robotics, one correct MotionDeviceSystem and one with three planted defects: exactly those three.
//!
//! It fails, never skips, when node or the node-opcua packages are missing, saying how to install them.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use nodeset_tests::{root, vendor};

/// Builds a binary target (`--bin NAME` or `--example NAME`) and returns its path.
fn build(kind: &str, name: &str) -> PathBuf {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let output = Command::new(cargo)
        .current_dir(root())
        .args(["build", "--workspace", kind, name, "--message-format=json-render-diagnostics"])
        .stderr(Stdio::inherit())
        .output()
        .expect("cargo runs");
    assert!(output.status.success(), "cargo build --workspace {kind} {name} failed");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout
        .lines()
        .filter(|l| l.contains("\"reason\":\"compiler-artifact\"") && l.contains("\"executable\":\""))
        .find(|l| l.contains(&format!("\"name\":\"{name}\"")))
        .expect("cargo reports the executable");
    let start = line.find("\"executable\":\"").unwrap() + "\"executable\":\"".len();
    let end = start + line[start..].find('"').unwrap();
    PathBuf::from(&line[start..end])
}

/// A server process, killed when dropped.
struct Server {
    child: Child,
    lines: mpsc::Receiver<String>,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Server {
    fn spawn(mut command: Command) -> Server {
        let mut child = command.stdout(Stdio::piped()).stderr(Stdio::inherit()).spawn().expect("the server starts");
        let out = child.stdout.take().unwrap();
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Server { child, lines }
    }

    /// The URLs of the first `n` lines that contain `listening on <url>`.
    fn urls(&self, n: usize) -> Vec<String> {
        let mut urls = Vec::new();
        while urls.len() < n {
            let line = self.lines.recv_timeout(Duration::from_secs(90)).expect("the server prints its URL");
            if let Some((_, url)) = line.split_once("listening on ") {
                urls.push(url.trim().to_owned());
            }
        }
        urls
    }
}

/// Runs `nodeset-compiler verify URL ARGS --json`.
fn verify(url: &str, args: &[&str]) -> (Output, String) {
    let exe = build("--bin", "nodeset-compiler");
    let output = Command::new(exe).current_dir(root()).arg("verify").arg(url).args(args).arg("--json").output().expect("verify runs");
    let json = String::from_utf8_lossy(&output.stdout).into_owned();
    (output, json)
}

/// The `"key":value` number of the report.
fn number(json: &str, key: &str) -> u64 {
    let at = json.find(&format!("\"{key}\":")).unwrap_or_else(|| panic!("no {key} in {json}")) + key.len() + 3;
    json[at..].chars().take_while(char::is_ascii_digit).collect::<String>().parse().unwrap()
}

/// (code, path) of every finding.
fn findings(json: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for part in json.split("{\"code\":").skip(1) {
        let code = part[1..7].to_owned();
        let path_at = part.find("\"path\":\"").unwrap() + 8;
        let path = part[path_at..path_at + part[path_at..].find('"').unwrap()].to_owned();
        out.push((code, path));
    }
    out.sort();
    out
}

fn models() -> [String; 4] {
    let vendor = vendor();
    ["--models".into(), vendor.display().to_string(), "--models".into(), root().join("nodesets").display().to_string()]
}

fn assert_clean(url: &str) {
    let models = models();
    let args: Vec<&str> = models.iter().map(String::as_str).collect();
    let (output, json) = verify(url, &args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(findings(&json), Vec::<(String, String)>::new(), "{url}: {json}\n{stderr}");
    assert!(output.status.success(), "{url}: exit {}: {json}\n{stderr}", output.status);
    assert!(number(&json, "checked") > 100, "{url}: too few nodes checked: {json}");
    eprintln!("{url}: {json}");
}

fn example(name: &str, args: &[&str], servers: usize) -> (Server, Vec<String>) {
    let exe = build("--example", name);
    let mut command = Command::new(exe);
    command.args(["--port", "0"]).args(args);
    let server = Server::spawn(command);
    let urls = server.urls(servers);
    (server, urls)
}

#[test]
fn the_example_server_verifies_clean() {
    let (_server, urls) = example("server", &[], 1);
    assert_clean(&urls[0]);
}

#[test]
fn the_robot_example_verifies_clean() {
    let (_server, urls) = example("robot", &[], 1);
    assert_clean(&urls[0]);
}

#[test]
fn the_robot_cell_verifies_clean() {
    let (_server, urls) = example("robot_cell", &[], 3);
    for url in &urls {
        assert_clean(url);
    }
}

/// The node-opcua peer's folder, with its packages installed, or a failure that says how to install them.
fn node_peer() -> PathBuf {
    let dir = root().join("tests/node-peer");
    let ok = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    assert!(ok, "node is not installed; install Node.js 20 or newer (e.g. `apt-get install nodejs npm`)");
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
    let server = Server::spawn(command);
    let url = server.urls(1).remove(0);
    let models = models();
    let args: Vec<&str> = models.iter().map(String::as_str).collect();
    let (output, json) = verify(&url, &args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    eprintln!("{json}\n{stderr}");
    let found = findings(&json);
    // The server numbers its own namespace 1, DI 2 and Robotics 4 (IA is 3).
    let want = [
        ("NS0401", "2:DeviceSet/1:BadSystem/4:MotionDevices/1:Robot"),
        ("NS0406", "2:DeviceSet/1:BadSystem/4:MotionDevices/1:Robot/2:Model"),
        ("NS0407", "2:DeviceSet/1:BadSystem/4:MotionDevices/1:NotAMotionDevice"),
    ];
    assert_eq!(found, want.map(|(c, p)| (c.to_owned(), p.to_owned())).to_vec(), "{json}");
    assert_eq!(output.status.code(), Some(1), "violations give exit status 1");
    assert!(stderr.is_empty() || !stderr.contains("panicked"), "{stderr}");
    assert!(number(&json, "checked") > 100);
}
