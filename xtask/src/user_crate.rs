//! `cargo xtask user-crate`: the user's crate of README.md ("Your own crate", `tests/user-crate`), built as a
//! user builds it and run.
//!
//! The crate has a workspace of its own: its build script generates a vendor-style Robotics model and the
//! vendor Device model it requires into `OUT_DIR` (DI, IA and the OPC Foundation's Robotics mapped to
//! nodeset-models), and its `main.rs`, under `#![deny(warnings)]`, serves an instance of the vendor's
//! controller type. This builds it in the workspace's target folder with the workspace's lock file (so
//! async-opcua and nodeset-models are not compiled again), starts it on a free port, waits for it to serve
//! the instance, makes an OPC UA connection handshake (Hello, Acknowledge) on its endpoint, and stops it with
//! SIGTERM, which it must survive cleanly.

use crate::util::{target_dir, workspace_root};
use process_support::Process;
use std::io::{Read, Write};
use std::process::Command;
use std::time::{Duration, Instant};

#[derive(Debug, Default, clap::Args)]
pub struct Args {}

pub fn run(_: Args) -> Result<(), String> {
    let root = workspace_root();
    let dir = root.join("tests/user-crate");
    std::fs::copy(root.join("Cargo.lock"), dir.join("Cargo.lock")).map_err(|e| format!("cannot copy Cargo.lock: {e}"))?;
    let start = Instant::now();
    let status = crate::util::cargo()
        .current_dir(&dir)
        .env("CARGO_TARGET_DIR", target_dir())
        .args(["build", "--quiet"])
        .status()
        .map_err(|e| format!("cannot run cargo build: {e}"))?;
    if !status.success() {
        return Err(format!("the user crate of README.md ({}) does not build ({status})", dir.display()));
    }
    let built = start.elapsed();
    let exe = target_dir().join("debug/nodeset-user-crate");
    let pki = std::env::temp_dir().join(format!("nodeset-user-crate-pki-{}", std::process::id()));
    let served = serve(&exe, &pki);
    let _ = std::fs::remove_dir_all(&pki);
    let (url, instance) = served?;
    println!(
        "user-crate: built in {:.1} s, served {instance} at {url}, stopped cleanly ({:.1} s in all)",
        built.as_secs_f64(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Starts the crate's server on a free port, checks that it serves the vendor instance and answers an OPC UA
/// Hello, and stops it; the endpoint URL and what it said it serves.
fn serve(exe: &std::path::Path, pki: &std::path::Path) -> Result<(String, String), String> {
    let server = Process::spawn(Command::new(exe).args(["--port", "0", "--seconds", "120", "--pki"]).arg(pki))?;
    let url = server.wait_for("listening on ", process_support::STARTUP)?;
    let instance = server.wait_for("serving ", process_support::STARTUP)?;
    if !instance.contains("VendorControllerType") {
        return Err(format!("the server serves `{instance}`, not a VendorControllerType"));
    }
    acknowledge(&url)?;
    server.stop()?;
    Ok((url, instance))
}

/// Sends an OPC UA Hello (Part 6, 7.1.2.3) to `url` and expects an Acknowledge.
fn acknowledge(url: &str) -> Result<(), String> {
    let address = url.strip_prefix("opc.tcp://").and_then(|r| r.split('/').next()).ok_or(format!("`{url}` is not an opc.tcp URL"))?;
    let mut stream = std::net::TcpStream::connect(address).map_err(|e| format!("cannot connect to {address}: {e}"))?;
    stream.set_read_timeout(Some(Duration::from_secs(10))).map_err(|e| e.to_string())?;
    let mut body = Vec::new();
    for v in [0u32, 65536, 65536, 0, 0] {
        body.extend_from_slice(&v.to_le_bytes());
    }
    body.extend_from_slice(&(url.len() as i32).to_le_bytes());
    body.extend_from_slice(url.as_bytes());
    let mut message = b"HELF".to_vec();
    message.extend_from_slice(&((8 + body.len()) as u32).to_le_bytes());
    message.extend_from_slice(&body);
    stream.write_all(&message).map_err(|e| format!("cannot send Hello: {e}"))?;
    let mut head = [0u8; 8];
    stream.read_exact(&mut head).map_err(|e| format!("no answer to Hello: {e}"))?;
    match &head[..4] {
        b"ACKF" => Ok(()),
        other => Err(format!("the server answered Hello with `{}`, not ACKF", String::from_utf8_lossy(other))),
    }
}
