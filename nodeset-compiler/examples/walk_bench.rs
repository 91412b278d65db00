//! The baseline of `cargo xtask bench --scenario verify`: the walk `nodeset-compiler verify` makes of live
//! servers (breadth first from the Objects folder, then the DataType, ValueRank and Value of every variable),
//! with at most `--batch` nodes a Browse and attributes a Read. `--batch 1` is the naive client: one
//! request per node browsed and per attribute read, over the same nodes verify reads.
//!
//! ```text
//! cargo run --release --example walk_bench -p nodeset-compiler -- URL [URL...] [--batch 1] [--runs 3]
//! ```
//!
//! It connects without security (the bench starts its servers with `--insecure`, on loopback). Each run
//! walks every URL, one after the other, each in a session of its own (connect, walk, disconnect), and is
//! timed as a whole: the robot cell is three servers, and verifying the cell is verifying all three. Output:
//! one line per run on stderr, and on stdout `BENCH servers=N nodes=N round_trips=N walk_median_ms=X
//! walk_min_ms=X walk_max_ms=X`, nodes and round trips summed over the servers.

use std::process::ExitCode;
use std::time::Instant;

use nodeset_compiler::verify::client::{snapshot_batched, Connect};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let option = |name: &str, default: usize| -> usize {
        args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).and_then(|v| v.parse().ok()).unwrap_or(default)
    };
    let (batch, runs) = (option("--batch", 1), option("--runs", 3).max(1));
    let urls: Vec<String> = args.iter().filter(|a| a.starts_with("opc.tcp://")).cloned().collect();
    if urls.is_empty() {
        eprintln!("usage: walk_bench URL [URL...] [--batch N] [--runs N]");
        return ExitCode::from(2);
    }
    let connect = |url: &str| Connect {
        url: url.to_owned(),
        security_policy: "None".into(),
        security_mode: "None".into(),
        user: None,
        pki_dir: std::env::temp_dir().join("nodeset-compiler-walk-bench-pki"),
        trust_server_cert: false,
        verify_server_cert: true,
    };
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().expect("a tokio runtime");
    let mut times = Vec::with_capacity(runs);
    let (mut nodes, mut round_trips) = (0, 0);
    for run in 1..=runs {
        let start = Instant::now();
        (nodes, round_trips) = (0, 0);
        for url in &urls {
            let snapshot = match runtime.block_on(snapshot_batched(&connect(url), Some(batch))) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("error: {url}: {e}");
                    return ExitCode::FAILURE;
                }
            };
            nodes += snapshot.nodes.len();
            round_trips += snapshot.round_trips;
        }
        let ms = start.elapsed().as_secs_f64() * 1e3;
        eprintln!("walk_bench: run {run}: {} server(s), {nodes} nodes, {round_trips} round trips, {ms:.1} ms (batch {batch})", urls.len());
        times.push(ms);
    }
    bench_support::Line::new()
        .kv("servers", urls.len())
        .kv("nodes", nodes)
        .kv("round_trips", round_trips)
        .stats("walk", &times, 1)
        .print();
    ExitCode::SUCCESS
}
