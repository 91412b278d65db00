//! The measure of `cargo xtask bench --scenario startup`: how long a server takes from its start until it
//! answers a Read of a variable of a given namespace, and how much memory it holds by then.
//!
//! ```text
//! startup_bench --url URL --read NAMESPACE_URI;i=N [--policy P --mode M] --pki DIR -- SERVER ARGS...
//! ```
//!
//! It starts `SERVER ARGS...` (stdout and stderr discarded), then, as one client would, tries to open a
//! session to `URL` (the client of `nodeset-compiler verify`, [`nodeset_compiler::verify::client::open`],
//! anonymous, with the given security, trusting the server's certificate without checking its host name,
//! which async-opcua misreads in node-opcua's certificates) every 5 ms until it gets one, reads
//! the server's NamespaceArray, then the Value of the named variable (its namespace found in that array), and
//! stops the clock when that answer is Good. So the time covers everything a server does before its address
//! space can be read (loading or importing its nodesets, opening its endpoints, the first secure channel and
//! session), whatever it prints and whenever. Then it reads the server's peak resident memory so far (VmHWM
//! of `/proc/PID/status`), stops it with SIGTERM and, once it has ended, takes its CPU time (user + system,
//! from the end of the process, start-up and shutdown included) and peak memory from `getrusage`.
//!
//! Output: on stdout `BENCH startup_ms=X hwm_kib=N maxrss_kib=N cpu_ms=X attempts=N`.

use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use nodeset_compiler::verify::client::{open, Connect};
use opcua::types::{AttributeId, DataValue, NodeId, ReadValueId, StatusCode, TimestampsToReturn, Variant, VariableId};

/// How long a server may take to answer before the measure fails.
const TIMEOUT: Duration = Duration::from_secs(300);

struct Args {
    url: String,
    uri: String,
    id: u32,
    policy: String,
    mode: String,
    pki: std::path::PathBuf,
    server: Vec<String>,
}

fn args() -> Result<Args, String> {
    let all: Vec<String> = std::env::args().skip(1).collect();
    let split = all.iter().position(|a| a == "--").ok_or("no `-- SERVER ARGS...`")?;
    let (own, server) = (&all[..split], all[split + 1..].to_vec());
    let get = |name: &str| own.iter().position(|a| a == name).and_then(|i| own.get(i + 1)).cloned();
    let read = get("--read").ok_or("no --read NAMESPACE_URI;i=N")?;
    let (uri, id) = read.rsplit_once(";i=").ok_or("--read wants NAMESPACE_URI;i=N")?;
    Ok(Args {
        url: get("--url").ok_or("no --url")?,
        uri: uri.to_owned(),
        id: id.parse().map_err(|_| format!("`{id}` is not a numeric identifier"))?,
        policy: get("--policy").unwrap_or_else(|| "Basic256Sha256".into()),
        mode: get("--mode").unwrap_or_else(|| "SignAndEncrypt".into()),
        pki: get("--pki").ok_or("no --pki DIR")?.into(),
        server: if server.is_empty() { return Err("no server command after `--`".into()) } else { server },
    })
}

fn read_value(node_id: NodeId) -> ReadValueId {
    ReadValueId { node_id, attribute_id: AttributeId::Value as u32, ..Default::default() }
}

/// One session: the NamespaceArray, then the variable; the variable's value.
async fn first_read(connect: &Connect, uri: &str, id: u32) -> Result<DataValue, String> {
    let session = open(connect).await.map_err(|e| e.to_string())?;
    let result = async {
        let s = &session.session;
        let array = s
            .read(&[read_value(VariableId::Server_NamespaceArray.into())], TimestampsToReturn::Neither, 0.0)
            .await
            .map_err(|e| format!("reading the NamespaceArray: {e}"))?;
        let Some(Variant::Array(uris)) = array.first().and_then(|v| v.value.clone()) else {
            return Err("the NamespaceArray is not an array".to_owned());
        };
        let ns = uris
            .values
            .iter()
            .position(|u| matches!(u, Variant::String(s) if s.as_ref() == uri))
            .ok_or_else(|| format!("the server has no namespace {uri}"))?;
        let values = s
            .read(&[read_value(NodeId::new(ns as u16, id))], TimestampsToReturn::Neither, 0.0)
            .await
            .map_err(|e| format!("reading {uri};i={id}: {e}"))?;
        values.into_iter().next().ok_or_else(|| "an empty Read response".to_owned())
    }
    .await;
    session.close().await;
    result
}

fn proc_kib(pid: u32, field: &str) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

fn run(a: Args) -> Result<(), String> {
    let connect = Connect {
        url: a.url.clone(),
        security_policy: a.policy.clone(),
        security_mode: a.mode.clone(),
        user: None,
        pki_dir: a.pki.clone(),
        trust_server_cert: true,
        verify_server_cert: false,
    };
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().map_err(|e| e.to_string())?;
    let start = Instant::now();
    let mut child = Command::new(&a.server[0])
        .args(&a.server[1..])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", a.server[0]))?;
    let pid = child.id();
    let (mut attempts, mut answered) = (0u32, 0u32);
    let outcome = loop {
        attempts += 1;
        match runtime.block_on(first_read(&connect, &a.uri, a.id)) {
            Ok(value) => break Ok(value),
            Err(e) => {
                if let Ok(Some(status)) = child.try_wait() {
                    break Err(format!("the server ended ({status}) before it answered; last attempt: {e}"));
                }
                // Until the server listens, connections are refused; an answer that is not a session (a
                // certificate refused, an endpoint missing) will not change by trying on.
                if !e.contains("refused") {
                    answered += 1;
                    if answered >= 20 {
                        break Err(format!("the server answers, but gives no session: {e}"));
                    }
                }
                if start.elapsed() > TIMEOUT {
                    break Err(format!("no answer within {} s; last attempt: {e}", TIMEOUT.as_secs()));
                }
                std::thread::sleep(Duration::from_millis(5));
            }
        }
    };
    let startup_ms = start.elapsed().as_secs_f64() * 1e3;
    let hwm = proc_kib(pid, "VmHWM");
    let _ = Command::new("kill").args(["-TERM", &pid.to_string()]).status();
    let deadline = Instant::now() + Duration::from_secs(20);
    while child.try_wait().map_err(|e| e.to_string())?.is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let value = outcome?;
    let status = value.status.unwrap_or(StatusCode::Good);
    if !status.is_good() || value.value.is_none() {
        return Err(format!("{};i={} answered {status} with no value", a.uri, a.id));
    }
    let (maxrss, cpu_ms) = bench_support::children_usage();
    bench_support::Line::new()
        .num("startup_ms", startup_ms, 1)
        .kv("hwm_kib", hwm.unwrap_or(0))
        .kv("maxrss_kib", maxrss)
        .num("cpu_ms", cpu_ms, 1)
        .kv("attempts", attempts)
        .print();
    Ok(())
}

fn main() -> ExitCode {
    match args().and_then(run) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("startup_bench: {e}");
            ExitCode::FAILURE
        }
    }
}
