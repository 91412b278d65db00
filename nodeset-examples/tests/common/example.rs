//! An example server started as a user starts it: its binary, built by the test (`cargo build -p
//! nodeset-examples --example ...`, a no-op when it is up to date), run as a child process that is killed
//! when dropped, its stdout read line by line. Included with `#[path = "common/example.rs"] mod example;`
//! (the same process handling as `tests/client.rs`, which still has its own copy).

#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::{mpsc, Mutex};
use std::time::Duration;

/// The executables of the examples built so far by this test binary: (name, path).
static BUILT: Mutex<Vec<(String, PathBuf)>> = Mutex::new(Vec::new());

/// The executable of the example `name`, built first if this test binary has not built it yet.
pub fn executable(name: &str) -> PathBuf {
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, path)) = built.iter().find(|(n, _)| n == name) {
        return path.clone();
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let output = Command::new(cargo)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["build", "-p", "nodeset-examples", "--example", name, "--message-format=json-render-diagnostics"])
        .stderr(Stdio::inherit())
        .output()
        .expect("cargo runs");
    assert!(output.status.success(), "cargo build -p nodeset-examples --example {name} failed");
    let field = |line: &str, key: &str| -> Option<String> {
        let start = line.find(key)? + key.len();
        Some(line[start..start + line[start..].find('"')?].to_owned())
    };
    let path = String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter(|l| l.contains("\"reason\":\"compiler-artifact\"") && l.contains("\"kind\":[\"example\"]"))
        .filter(|l| field(l, "\"name\":\"").as_deref() == Some(name))
        .find_map(|l| field(l, "\"executable\":\""))
        .map(PathBuf::from)
        .unwrap_or_else(|| panic!("cargo built no example `{name}`"));
    built.push((name.to_owned(), path.clone()));
    path
}

/// A running example server.
pub struct Example {
    child: Child,
    lines: mpsc::Receiver<String>,
}

impl Drop for Example {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Example {
    /// Builds (if needed) and starts the example `name` with `args`.
    pub fn start(name: &str, args: &[&str]) -> Example {
        let mut child =
            Command::new(executable(name)).args(args).stdout(Stdio::piped()).stderr(Stdio::inherit()).spawn().expect("the example starts");
        let out = child.stdout.take().expect("stdout");
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Example { child, lines }
    }

    /// Waits (at most 90 s) for a line that starts with `prefix`; the rest of it, trimmed.
    pub fn line(&self, prefix: &str) -> String {
        loop {
            let line = self.lines.recv_timeout(Duration::from_secs(90)).unwrap_or_else(|_| panic!("the example prints `{prefix}...`"));
            if let Some(rest) = line.strip_prefix(prefix) {
                return rest.trim().to_owned();
            }
        }
    }
}
