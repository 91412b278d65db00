//! `cargo xtask load`: the generated server under client load (issue "Reliability", item 5).
//!
//! Builds the `robot` and `load` examples of `nodeset-models`, starts the robot (six axes updated at 100 Hz)
//! on a free loopback port, runs the load client against it (`--sessions` sessions, each subscribed to every
//! axis variable at `--publishing-ms`, plus one session writing a writable variable, for `--seconds`), then
//! stops the robot with SIGTERM, which must end it cleanly. The load client prints the report (notifications
//! received versus expected, sequence-number gaps, errors, server RSS at start and end) and fails on any gap
//! or error. `cargo xtask test` runs it with a short duration; the default is the full five minutes.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use crate::util::workspace_root;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Client sessions, each subscribed to every axis variable.
    #[arg(long, default_value_t = 50)]
    pub sessions: usize,
    /// How long the load runs.
    #[arg(long, default_value_t = 300)]
    pub seconds: u64,
    /// The publishing interval of every subscription (the sampling interval too).
    #[arg(long, default_value_t = 100)]
    pub publishing_ms: u64,
    /// Build the examples in release mode (the default reuses the debug build of `cargo test`, whose
    /// dependencies are optimised).
    #[arg(long)]
    pub release: bool,
}

/// Builds the examples and returns the folder of their executables.
fn build(root: &Path, release: bool) -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    // --workspace resolves features as `cargo test --workspace` does, so nothing is built twice.
    cmd.current_dir(root).args(["build", "--quiet", "--workspace", "--example", "robot", "--example", "load"]);
    if release {
        cmd.arg("--release");
    }
    let status = cmd.status().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building the robot and load examples failed ({status})"));
    }
    let target = std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| root.join("target"));
    let target = if target.is_absolute() { target } else { root.join(target) };
    Ok(target.join(if release { "release" } else { "debug" }).join("examples"))
}

struct Robot {
    child: Child,
    lines: mpsc::Receiver<String>,
}

impl Drop for Robot {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    crate::fetch::ensure_fetched()?;
    let examples = build(&root, args.release)?;
    let mut child = Command::new(examples.join("robot"))
        .args(["--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("cannot start the robot example: {e}"))?;
    let out = child.stdout.take().ok_or("no stdout")?;
    let (tx, lines) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(out).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let robot = Robot { child, lines };
    let first = robot.lines.recv_timeout(Duration::from_secs(60)).map_err(|_| "the robot example printed no URL")?;
    let url = first.strip_prefix("listening on ").ok_or_else(|| format!("unexpected first line {first:?}"))?.to_owned();
    let pid = robot.child.id();
    eprintln!("load: robot example (pid {pid}) listening on {url}");

    let status = Command::new(examples.join("load"))
        .args(["--url", &url, "--server-pid", &pid.to_string()])
        .args(["--sessions", &args.sessions.to_string(), "--seconds", &args.seconds.to_string()])
        .args(["--publishing-ms", &args.publishing_ms.to_string()])
        .status()
        .map_err(|e| format!("cannot run the load client: {e}"))?;

    // Stop the robot; it must end cleanly under (and after) the load.
    let mut robot = robot;
    let killed = Command::new("kill").args(["-TERM", &pid.to_string()]).status().is_ok_and(|s| s.success());
    let mut rest = Vec::new();
    while let Ok(line) = robot.lines.recv_timeout(Duration::from_secs(15)) {
        rest.push(line);
    }
    let exit = robot.child.wait().map_err(|e| e.to_string())?;
    let clean = killed && exit.success() && rest.iter().any(|l| l == "server stopped cleanly");
    let writes_seen = rest.iter().filter(|l| l.starts_with("ConfiguredDefaultStopMode written by a client")).count();
    eprintln!("load: the robot printed {writes_seen} client writes received by its derived struct");
    if !status.success() {
        return Err(format!("the load test failed ({status})"));
    }
    if !clean {
        return Err(format!("the robot example did not stop cleanly after the load ({exit}); last lines: {:?}", rest.iter().rev().take(5).collect::<Vec<_>>()));
    }
    if writes_seen == 0 {
        return Err("no client write reached the robot's derived struct".into());
    }
    Ok(())
}
