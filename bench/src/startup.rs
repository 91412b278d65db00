//! The `startup` scenario: `nodeset-compiler serve` started on ns0 + DI + IA + Robotics until the first Read
//! of a variable answers, against node-opcua's server loading the same four NodeSet2 files, in one run
//! (issue 38, "`nodeset-compiler serve`", whose target is our start-up at most a tenth of node-opcua's).
//!
//! Both servers get the four files of `nodesets/vendor/` (ours serves async-opcua's ns0 and reads the
//! vendor's ns0 for the model; node-opcua loads all four into its address space):
//!
//! - ours: `nodeset-compiler serve Opc.Ua.NodeSet2.xml Opc.Ua.Di.NodeSet2.xml Opc.Ua.IA.NodeSet2.xml
//!   Opc.Ua.Robotics.NodeSet2.xml --port P --pki DIR --trust-on-first-use` (release build);
//! - the peer: `node tests/node-peer/serve.js P` with the same four files (node-opcua from npm, installed by
//!   `cargo xtask node-peer`).
//!
//! Each is measured by the `startup_bench` example of nodeset-compiler, one process per measure: it starts
//! the server and, from that instant, tries every 5 ms to open a session and read the NamespaceArray, then
//! the Value of a variable of the Robotics namespace (`EnumStrings` of an enumeration, `i=6027`), and stops
//! the clock when that Read answers Good; then it reads the server's peak resident memory (VmHWM) and
//! stops it. The same client for both (verify's, async-opcua's client), with the same endpoint security:
//! Basic256Sha256, SignAndEncrypt, an anonymous session: the secure default of both servers, so the
//! start-up measured is the one a user gets, first secure channel included (the client trusts the server's
//! certificate; ours trusts the client's on first use, node-opcua accepts unknown client certificates by
//! default). One start of each before the rounds creates the certificates (both servers create their own
//! on first start, in their PKI folders, which are kept): certificate creation is a one-time cost, not
//! start-up.
//!
//! The rounds alternate the peer and ours, so both sample the same stretch of the shared host's time; the
//! ratio ours / peer is the median of the per-round ratios (target at most 0.10). A report, never an
//! assertion.

use std::env;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use super::{verdict, VENDOR_FILES};
use bench_support::Report;
use process_support::workspace::target_dir;

/// The target: our start-up over node-opcua's.
const TARGET_RATIO: f64 = 0.10;

/// The variable read: `EnumStrings` of an enumeration of the Robotics nodeset.
const READ: &str = "http://opcfoundation.org/UA/Robotics/;i=6027";

/// One measure of one server.
struct Measure {
    ms: f64,
    hwm_kib: f64,
    maxrss_kib: f64,
    cpu_ms: f64,
}

fn free_port() -> Result<u16, String> {
    let listener = TcpListener::bind("127.0.0.1:0").map_err(|e| format!("cannot find a free port: {e}"))?;
    listener.local_addr().map(|a| a.port()).map_err(|e| e.to_string())
}

/// The two servers' command lines for `port`, with the URL to reach each.
struct Servers {
    compiler: PathBuf,
    files: Vec<PathBuf>,
    peer_dir: PathBuf,
    pki: PathBuf,
}

impl Servers {
    fn ours(&self, port: u16) -> (String, Vec<String>) {
        let mut args: Vec<String> = vec![self.compiler.display().to_string(), "serve".into()];
        args.extend(self.files.iter().map(|f| f.display().to_string()));
        args.extend(["--port".into(), port.to_string(), "--pki".into(), self.pki.join("server").display().to_string()]);
        args.push("--trust-on-first-use".into());
        (format!("opc.tcp://127.0.0.1:{port}/"), args)
    }

    fn peer(&self, port: u16) -> (String, Vec<String>) {
        let mut args: Vec<String> = vec!["node".into(), self.peer_dir.join("serve.js").display().to_string(), port.to_string()];
        args.extend(self.files.iter().map(|f| f.display().to_string()));
        (format!("opc.tcp://127.0.0.1:{port}/UA/NodeOPCUA"), args)
    }
}

fn measure(bench: &Path, client_pki: &Path, (url, server): (String, Vec<String>)) -> Result<Measure, String> {
    let out = Command::new(bench)
        .args(["--url", &url, "--read", READ, "--policy", "Basic256Sha256", "--mode", "SignAndEncrypt", "--pki"])
        .arg(client_pki)
        .arg("--")
        .args(&server)
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", bench.display()))?;
    if !out.status.success() {
        return Err(format!("startup_bench failed for {} ({})", server[..2].join(" "), out.status));
    }
    let r = Report::parse(&String::from_utf8_lossy(&out.stdout)).ok_or("startup_bench printed no BENCH line")?;
    Ok(Measure { ms: r.f("startup_ms"), hwm_kib: r.f("hwm_kib"), maxrss_kib: r.f("maxrss_kib"), cpu_ms: r.f("cpu_ms") })
}

/// Builds what it needs, measures `rounds` rounds, and prints the table.
pub(super) fn run(root: &Path, rounds: usize) -> Result<(), String> {
    let rounds = rounds.max(1);
    let peer_dir = root.join("tests/node-peer");
    if !peer_dir.join("node_modules/node-opcua").is_dir() {
        return Err(format!("node-opcua is not installed in {}; run `cargo xtask node-peer`", peer_dir.display()));
    }
    let node_ok = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    if !node_ok {
        return Err("node is not installed; install Node.js 20 or newer with npm, then run `cargo xtask node-peer`".into());
    }
    eprintln!("startup: building nodeset-compiler and the startup_bench example (release) ...");
    let status = process_support::workspace::cargo()
        .current_dir(root)
        .args(["build", "--quiet", "--release", "-p", "nodeset-compiler", "--bin", "nodeset-compiler", "--example", "startup_bench"])
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building nodeset-compiler and startup_bench failed ({status})"));
    }
    let release = target_dir().join("release");
    let bench = release.join("examples").join(format!("startup_bench{}", env::consts::EXE_SUFFIX));
    let pki = env::temp_dir().join("nodeset-bench-startup");
    let servers = Servers {
        compiler: release.join(format!("nodeset-compiler{}", env::consts::EXE_SUFFIX)),
        files: VENDOR_FILES.iter().map(|f| root.join("nodesets/vendor").join(f)).collect(),
        peer_dir,
        pki: pki.clone(),
    };
    let client_pki = pki.join("client");

    eprintln!("startup: one start of each first (certificates created on first start are not start-up) ...");
    measure(&bench, &client_pki, servers.peer(free_port()?))?;
    measure(&bench, &client_pki, servers.ours(free_port()?))?;
    let (mut peer, mut ours) = (Vec::with_capacity(rounds), Vec::with_capacity(rounds));
    for round in 1..=rounds {
        let p = measure(&bench, &client_pki, servers.peer(free_port()?))?;
        let o = measure(&bench, &client_pki, servers.ours(free_port()?))?;
        eprintln!(
            "startup: round {round}: node-opcua {:.0} ms ({:.0} MiB), serve {:.0} ms ({:.0} MiB), ratio {:.3}",
            p.ms,
            p.hwm_kib / 1024.0,
            o.ms,
            o.hwm_kib / 1024.0,
            o.ms / p.ms
        );
        peer.push(p);
        ours.push(o);
    }

    let col = |v: &[Measure], f: fn(&Measure) -> f64| v.iter().map(f).collect::<Vec<f64>>();
    let ratios: Vec<f64> = ours.iter().zip(&peer).map(|(o, p)| o.ms / p.ms).collect();
    let cpu_ratios: Vec<f64> = ours.iter().zip(&peer).map(|(o, p)| o.cpu_ms / p.cpu_ms).collect();
    let ratio = bench_support::median(&ratios);
    println!();
    println!(
        "Start-up: ns0 + DI + IA + Robotics (nodesets/vendor) until the first Read of a Robotics variable answers, {rounds} round(s) (node-opcua, then serve)."
    );
    println!("  client: nodeset-compiler verify's (async-opcua), Basic256Sha256 SignAndEncrypt, anonymous, for both");
    let row = |label: &str, v: &[Measure]| {
        let (ms, cpu, hwm, rss) = (col(v, |m| m.ms), col(v, |m| m.cpu_ms), col(v, |m| m.hwm_kib), col(v, |m| m.maxrss_kib));
        println!(
            "  {label:<32} median {:>7.1} ms   min {:>7.1}   max {:>7.1}   CPU {:>7.0} ms   peak memory {:>6.1} MiB at the first Read (max {:.1} MiB over the process)",
            bench_support::median(&ms),
            bench_support::min(&ms),
            bench_support::max(&ms),
            bench_support::median(&cpu),
            bench_support::median(&hwm) / 1024.0,
            bench_support::median(&rss) / 1024.0,
        );
    };
    row("node-opcua 2.185 (serve.js)", &peer);
    row("nodeset-compiler serve", &ours);
    println!(
        "  ratio serve / node-opcua, start-up   {ratio:>6.3}   (median of the per-round ratios; min {:.3}, max {:.3})",
        bench_support::min(&ratios),
        bench_support::max(&ratios)
    );
    println!("  ratio serve / node-opcua, CPU time   {:>6.3}   (start-up and shutdown)", bench_support::median(&cpu_ratios));
    println!(
        "  ratio serve / node-opcua, memory     {:>6.3}   (VmHWM at the first Read)",
        bench_support::median(&col(&ours, |m| m.hwm_kib)) / bench_support::median(&col(&peer, |m| m.hwm_kib))
    );
    println!("  target: start-up at most {TARGET_RATIO:.2} of node-opcua's: {} ({ratio:.3})", verdict(ratio, TARGET_RATIO));
    Ok(())
}
