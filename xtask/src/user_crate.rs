//! `cargo xtask user-crate`: the user's crate of README.md ("Your own crate", `tests/user-crate`), built as a
//! user builds it and run.
//!
//! The crate has a workspace of its own: its build script generates a vendor-style Robotics model and the
//! vendor Device model it requires into `OUT_DIR` (DI, IA and the OPC Foundation's Robotics mapped to
//! nodeset-models), and its `main.rs`, under `#![deny(warnings)]`, serves an instance of the vendor's
//! controller type and one of its arm type (Robotics' MotionDeviceType with ParameterSet overridden). This
//! builds it in the workspace's target folder with the workspace's lock file (so async-opcua and
//! nodeset-models are not compiled again), starts it on a free port with its secure endpoints only, waits for
//! it to serve the instances, makes an OPC UA connection handshake (Hello, Acknowledge) on its endpoint, runs
//! `nodeset-compiler verify` over SignAndEncrypt as a user would (refused until the server's certificate is
//! moved to `trusted/`, then 0 violations), and stops it with SIGTERM, which it must survive cleanly.

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
    let compiler = compiler()?;
    let pki = std::env::temp_dir().join(format!("nodeset-user-crate-pki-{}", std::process::id()));
    let served = serve(&exe, &compiler, &pki);
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
fn serve(exe: &std::path::Path, compiler: &std::path::Path, pki: &std::path::Path) -> Result<(String, String), String> {
    let server = Process::spawn(Command::new(exe).args(["--port", "0", "--seconds", "120", "--trust-on-first-use", "--pki"]).arg(pki.join("server")))?;
    let instance = server.wait_for("serving ", process_support::STARTUP)?;
    let url = server.wait_for("listening on ", process_support::STARTUP)?;
    if !instance.contains("VendorControllerType") || !instance.contains("VendorArmType") {
        return Err(format!("the server serves `{instance}`, not a VendorControllerType and a VendorArmType"));
    }
    acknowledge(&url)?;
    verify(compiler, &url, &pki.join("verify"))?;
    server.stop()?;
    Ok((url, instance))
}

/// The `nodeset-compiler` command of the workspace's test build (what `.ci/run` built before; built now
/// otherwise).
fn compiler() -> Result<std::path::PathBuf, String> {
    let artifacts = process_support::cargo_artifacts(&workspace_root(), &["test", "--workspace", "--no-run"])?;
    artifacts
        .iter()
        .find(|a| a.kind == "bin" && a.name == "nodeset-compiler")
        .map(|a| a.path.clone())
        .ok_or_else(|| "cargo test --workspace --no-run built no nodeset-compiler".to_owned())
}

/// `nodeset-compiler verify URL` of the crate's server over Basic256Sha256 SignAndEncrypt (verify's
/// default), with the crate's nodesets: the first run stops because the server's certificate is not trusted
/// yet; the certificate moved from `rejected/` to `trusted/` as the message says, the second finds no
/// violation (the vendor arm's overridden ParameterSet keeps Robotics' mandatory SpeedOverride).
fn verify(compiler: &std::path::Path, url: &str, pki: &std::path::Path) -> Result<(), String> {
    let root = workspace_root();
    let crate_dir = root.join("tests/user-crate");
    let run = || {
        Command::new(&compiler)
            .arg("verify")
            .arg(url)
            .arg(crate_dir.join("nodesets/Example.VendorRobotics.NodeSet2.xml"))
            .arg("--models")
            .arg(crate_dir.join("nodesets"))
            .arg("--models")
            .arg(root.join("nodesets/vendor"))
            .arg("--pki")
            .arg(pki)
            .arg("--json")
            .output()
            .map_err(|e| format!("cannot run {}: {e}", compiler.display()))
    };
    let first = run()?;
    let rejected: Vec<std::path::PathBuf> = std::fs::read_dir(pki.join("rejected"))
        .map_err(|e| format!("verify put no certificate in {}: {e}", pki.join("rejected").display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    if first.status.code() != Some(2) || rejected.len() != 1 {
        return Err(format!(
            "verify's first contact should stop on the untrusted server certificate (exit 2, one file in rejected/), got {} and {rejected:?}: {}",
            first.status,
            String::from_utf8_lossy(&first.stderr)
        ));
    }
    let trusted = pki.join("trusted");
    std::fs::create_dir_all(&trusted).map_err(|e| e.to_string())?;
    let name = rejected[0].file_name().ok_or("a rejected certificate without a name")?;
    std::fs::rename(&rejected[0], trusted.join(name)).map_err(|e| e.to_string())?;
    let second = run()?;
    let json = String::from_utf8_lossy(&second.stdout);
    let count = |key: &str| -> Option<u64> {
        let at = json.find(&format!("\"{key}\":"))? + key.len() + 3;
        json[at..].chars().take_while(char::is_ascii_digit).collect::<String>().parse().ok()
    };
    // Both instances (and so every node below them) checked, and nothing found.
    let clean = count("violations") == Some(0) && count("instances").is_some_and(|n| n >= 2) && !json.contains("{\"code\":");
    if !second.status.success() || !clean {
        return Err(format!("verify of the user crate's server is not clean ({}): {json}\n{}", second.status, String::from_utf8_lossy(&second.stderr)));
    }
    println!("user-crate: verify over SignAndEncrypt: {}", json.trim());
    Ok(())
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
