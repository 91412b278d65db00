//! `cargo xtask load`: the generated server under client load (issue "Reliability", item 5).
//!
//! Builds the `robot` and `load` examples of `nodeset-examples`, starts the robot (six axes updated at 100 Hz)
//! on a free loopback port, runs the load client against it (`--sessions` sessions, each subscribed to every
//! axis variable at `--publishing-ms`, plus one session writing a writable variable, for `--seconds`), then
//! stops the robot with SIGTERM, which must end it cleanly. The load client prints the report (notifications
//! received versus expected, sequence-number gaps, errors, server RSS at start and end) and fails on any gap
//! or error. `cargo xtask test` runs it with a short duration; the default is the full five minutes.
//!
//! It runs twice against the same robot process: over SecurityPolicy None (anonymous, the endpoint
//! `--insecure` adds) and over Basic256Sha256 SignAndEncrypt as an Operator user, so that the cost of
//! encryption (notifications per second, server CPU) is measured in one run.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use process_support::Process;

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

/// Adds a password user to a user file with the runtime's `nodeset-users` command, from the folder
/// [`build`] left it in (`target/<profile>`).
fn add_user(bins: &Path, file: &Path, name: &str, roles: &str, password: &str) -> Result<(), String> {
    let mut cmd = Command::new(bins.join("nodeset-users"));
    let mut child = cmd
        .arg("add")
        .arg(file)
        .args([name, roles])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .map_err(|e| format!("cannot run nodeset-users: {e}"))?;
    use std::io::Write;
    child.stdin.take().ok_or("no stdin")?.write_all(format!("{password}\n").as_bytes()).map_err(|e| e.to_string())?;
    let status = child.wait().map_err(|e| e.to_string())?;
    if !status.success() {
        return Err(format!("nodeset-users add failed ({status})"));
    }
    Ok(())
}

/// Builds examples of nodeset-examples and returns the folder of their executables.
pub(crate) fn build(root: &Path, release: bool, examples: &[&str]) -> Result<PathBuf, String> {
    let mut cmd = crate::util::cargo();
    cmd.current_dir(root);
    if release {
        cmd.args(["build", "--quiet", "--release", "-p", "nodeset-examples", "-p", "nodeset-runtime", "--bins"]);
        for e in examples {
            cmd.args(["--example", e]);
        }
    } else {
        // The build `cargo test --workspace` has just done (examples and the runtime's `nodeset-users`
        // included), so nothing is compiled again: `cargo build --example` or `cargo run -p` resolve
        // features differently and rebuilt async-opcua.
        cmd.args(["test", "--quiet", "--workspace", "--no-run"]);
    }
    let status = cmd.status().map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building the examples {} failed ({status})", examples.join(", ")));
    }
    Ok(crate::util::target_dir().join(if release { "release" } else { "debug" }).join("examples"))
}

pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    crate::fetch::ensure_fetched()?;
    let examples = build(&root, args.release, &["robot", "load"])?;
    // The user the encrypted phase logs in as (Operator, for the writer), added with the runtime's own
    // command; its password is random and reaches the load client through the environment only.
    let dir = std::env::temp_dir().join(format!("nodeset-load-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let users = dir.join("users.txt");
    let password = format!("load-{}-{}", std::process::id(), std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or_default());
    add_user(examples.parent().ok_or("the examples folder has a parent")?, &users, "load", "Operator", &password)?;
    // The robot serves both phases in the same run: `--insecure` adds the None endpoint of the first, and
    // `--trust-on-first-use` lets the load client's certificate in without an administrator (a test harness).
    let pki = dir.join("pki").to_string_lossy().into_owned();
    let users_arg = users.to_string_lossy().into_owned();
    let robot = Process::spawn(
        Command::new(examples.join("robot"))
            .args(["--port", "0", "--insecure", "--trust-on-first-use", "--pki", &pki, "--users", &users_arg]),
    )?;
    let first = robot.next_line(Duration::from_secs(60))?;
    let url = first.strip_prefix("listening on ").ok_or_else(|| format!("unexpected first line {first:?}"))?.to_owned();
    let pid = robot.pid();
    eprintln!("load: robot example (pid {pid}) listening on {url}");

    let mut status = Ok(());
    for encrypt in [false, true] {
        let mut cmd = Command::new(examples.join("load"));
        cmd.args(["--url", &url, "--server-pid", &pid.to_string()])
            .args(["--sessions", &args.sessions.to_string(), "--seconds", &args.seconds.to_string()])
            .args(["--publishing-ms", &args.publishing_ms.to_string()]);
        if encrypt {
            cmd.args(["--encrypt", "load"]).env("NODESET_LOAD_PASSWORD", &password);
        }
        let phase = if encrypt { "SignAndEncrypt" } else { "None" };
        eprintln!("load: phase {phase}");
        match cmd.status() {
            Ok(s) if s.success() => {}
            Ok(s) => status = Err(format!("the load test over {phase} failed ({s})")),
            Err(e) => status = Err(format!("cannot run the load client: {e}")),
        }
    }
    let _ = std::fs::remove_dir_all(&dir);

    // Stop the robot; it must end cleanly under (and after) the load.
    let stopped = robot.stop();
    status?;
    let rest = stopped.map_err(|e| format!("after the load, {e}"))?;
    let writes_seen = rest.iter().filter(|l| l.starts_with("ConfiguredDefaultStopMode written by a client")).count();
    eprintln!("load: the robot printed {writes_seen} client writes received by its derived struct");
    if writes_seen == 0 {
        return Err("no client write reached the robot's derived struct".into());
    }
    Ok(())
}
