//! `cargo xtask soak`: the robot cell runs DrillHole many times in a row (issue "Skills", must-show 3).
//!
//! Builds the `robot_cell` example, starts its three servers on free loopback ports with short motions,
//! and runs `tests/interop/skills_soak.py` (python asyncua from `.venv`) against them: one session per
//! server subscribed to CurrentState and the transition events of every skill, DrillHole started `--runs`
//! times, each transition event checked in order, the servers' memory sampled. Then it stops the servers,
//! which must end cleanly. `cargo xtask test` runs it as it is by default: 1,000 runs, about a minute.

use std::process::Command;
use std::time::Duration;

use process_support::Process;

use crate::load::build;
use crate::util::workspace_root;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// How many DrillHole runs.
    #[arg(long, default_value_t = 1000)]
    pub runs: usize,
    /// How long each basic skill's simulated motion takes.
    #[arg(long, default_value_t = 5)]
    pub motion_ms: u64,
    /// Build the example in release mode (the default reuses the debug build of `cargo test`).
    #[arg(long)]
    pub release: bool,
}

pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    crate::fetch::ensure_fetched()?;
    let python = crate::venv::ensure_venv()?;
    let examples = build(&root, args.release, &["robot_cell"])?;
    let motion = args.motion_ms.to_string();
    // The soak client (python asyncua) uses the None endpoint that `--insecure` adds; the composite skills of
    // the cell reach the robot and the drilling unit over SignAndEncrypt with a user name, as always.
    let pki = std::env::temp_dir().join(format!("nodeset-soak-pki-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&pki);
    let pki_arg = pki.to_string_lossy().into_owned();
    let cell =
        Process::spawn(Command::new(examples.join("robot_cell")).args(["--port", "0", "--motion-ms", &motion, "--insecure", "--pki", &pki_arg]))?;
    let mut urls = Vec::new();
    for label in ["robot", "drilling unit", "cell"] {
        let line = cell.next_line(Duration::from_secs(60))?;
        let url = line.strip_prefix(&format!("{label} listening on ")).ok_or_else(|| format!("unexpected line {line:?}"))?;
        urls.push(url.to_owned());
    }
    let ready = cell.next_line(Duration::from_secs(60))?;
    if ready != "cell ready" {
        return Err(format!("unexpected line {ready:?}"));
    }
    eprintln!("soak: robot cell (pid {}) at {}", cell.pid(), urls.join(", "));
    let status = Command::new(python)
        .current_dir(root.join("tests/interop"))
        .arg("skills_soak.py")
        .args(["--robot", &urls[0], "--unit", &urls[1], "--cell", &urls[2]])
        .args(["--runs", &args.runs.to_string(), "--server-pid", &cell.pid().to_string()])
        .status()
        .map_err(|e| format!("cannot run the soak client: {e}"))?;
    let stopped = cell.stop();
    if !status.success() {
        return Err(format!("the soak run failed ({status})"));
    }
    stopped.map(|_| ()).map_err(|e| format!("after the soak run, {e}"))
}
