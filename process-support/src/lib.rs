//! Child processes for the workspace's tests, benches and `cargo xtask`.
//!
//! The example servers are tested as a user runs them: their executable, built by cargo (see
//! [`cargo_artifacts`]), started as a child process ([`Process::spawn`]) that prints `listening on <url>`
//! when it is ready. [`Process`] reads its stdout line by line on a thread of its own, so a test can wait for
//! a line with a timeout, and kills the process when dropped; [`Process::stop`] ends it with SIGTERM instead
//! and checks that it stopped cleanly. [`workspace`] says where the workspace, its cargo and its target folder
//! are.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

pub mod workspace;

/// How long [`Process::line`] waits: a cold example server starts within a few seconds, a loaded CI machine
/// needs more.
pub const STARTUP: Duration = Duration::from_secs(90);

/// A child process with its stdout read line by line; killed when dropped. Its stderr goes to ours unless
/// the command says otherwise.
pub struct Process {
    child: Child,
    lines: mpsc::Receiver<String>,
}

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Process {
    /// Starts `command` with its stdout piped to us.
    pub fn spawn(command: &mut Command) -> Result<Process, String> {
        let mut child = command
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start {:?}: {e}", command.get_program()))?;
        let out = child.stdout.take().ok_or("the child has no stdout")?;
        let (tx, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Ok(Process { child, lines })
    }

    /// Starts `exe` with `args`; panics if it cannot be started (for tests).
    pub fn start(exe: &Path, args: &[&str]) -> Process {
        Process::spawn(Command::new(exe).args(args)).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The next line it prints, waiting at most `timeout`.
    pub fn next_line(&self, timeout: Duration) -> Result<String, String> {
        self.lines.recv_timeout(timeout).map_err(|_| format!("the process printed no line within {} s", timeout.as_secs()))
    }

    /// The rest (trimmed) of the first line to come that contains `marker`, after it, waiting at most
    /// `timeout` for each line; the lines before it are skipped.
    pub fn wait_for(&self, marker: &str, timeout: Duration) -> Result<String, String> {
        loop {
            let line = self.next_line(timeout).map_err(|e| format!("waiting for `{marker}`: {e}"))?;
            if let Some((_, rest)) = line.split_once(marker) {
                return Ok(rest.trim().to_owned());
            }
        }
    }

    /// [`Process::wait_for`] with [`STARTUP`], panicking on a timeout (for tests).
    pub fn line(&self, marker: &str) -> String {
        self.wait_for(marker, STARTUP).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Sends SIGTERM and waits for the end; the lines printed until then, or why it did not end cleanly
    /// (printing `server stopped cleanly` and exiting with 0, as the example servers do).
    pub fn stop(mut self) -> Result<Vec<String>, String> {
        let killed = Command::new("kill").args(["-TERM", &self.pid().to_string()]).status().is_ok_and(|s| s.success());
        let mut rest = Vec::new();
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(15)) {
            rest.push(line);
        }
        let exit = self.child.wait().map_err(|e| e.to_string())?;
        if killed && exit.success() && rest.iter().any(|l| l == "server stopped cleanly") {
            Ok(rest)
        } else {
            Err(format!("the server did not stop cleanly ({exit}); last lines: {:?}", rest.iter().rev().take(5).collect::<Vec<_>>()))
        }
    }
}

/// An executable cargo built: its target kind (`bin`, `example`, ...), name and path.
#[derive(Clone, Debug)]
pub struct Artifact {
    pub kind: String,
    pub name: String,
    pub path: PathBuf,
}

/// Runs `cargo ARGS --message-format=json-render-diagnostics` in `dir` (cargo's diagnostics go to our
/// stderr) and returns the executables it built or found up to date (tests excluded).
pub fn cargo_artifacts(dir: &Path, args: &[&str]) -> Result<Vec<Artifact>, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let output = Command::new(cargo)
        .current_dir(dir)
        .args(args)
        .arg("--message-format=json-render-diagnostics")
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !output.status.success() {
        return Err(format!("cargo {} failed ({})", args.join(" "), output.status));
    }
    let field = |line: &str, key: &str| -> Option<String> {
        let start = line.find(key)? + key.len();
        Some(line[start..start + line[start..].find('"')?].to_owned())
    };
    Ok(String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter(|l| l.contains("\"reason\":\"compiler-artifact\"") && l.contains("\"test\":false"))
        .filter_map(|l| {
            Some(Artifact {
                kind: field(l, "\"kind\":[\"")?,
                name: field(l, "\"name\":\"")?,
                path: PathBuf::from(field(l, "\"executable\":\"")?),
            })
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shell "server": prints a line, then its URL, then on SIGTERM `ending` and exits with `code`. The trap
    /// is set before the first line, so that a SIGTERM sent as soon as a line arrives finds it.
    fn server(ending: &str, code: i32) -> Process {
        let script = format!(
            "trap 'echo {ending}; exit {code}' TERM; echo starting; echo 'listening on opc.tcp://127.0.0.1:4840/'; while true; do sleep 0.05; done"
        );
        Process::spawn(Command::new("sh").args(["-c", &script])).unwrap()
    }

    #[test]
    fn a_line_is_waited_for_and_a_clean_stop_is_told_from_an_unclean_one() {
        let clean = server("server stopped cleanly", 0);
        assert_eq!(clean.line("listening on "), "opc.tcp://127.0.0.1:4840/");
        assert_eq!(clean.stop(), Ok(vec!["server stopped cleanly".to_owned()]));

        let failing = server("server stopped cleanly", 3);
        assert_eq!(failing.next_line(STARTUP).as_deref(), Ok("starting"));
        assert!(failing.stop().is_err_and(|e| e.contains("exit status: 3")));

        let silent = server("bye", 0);
        assert!(silent.stop().is_err_and(|e| e.contains("did not stop cleanly")));

        let quiet = Process::spawn(Command::new("sh").args(["-c", "sleep 5"])).unwrap();
        assert!(quiet.wait_for("listening on ", Duration::from_millis(200)).is_err_and(|e| e.contains("waiting for `listening on `")));
    }
}
