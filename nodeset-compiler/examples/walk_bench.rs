//! The baseline of `cargo xtask bench --scenario verify`: the walk `nodeset-compiler verify` makes of a live
//! server (breadth first from the Objects folder, then the DataType, ValueRank and Value of every variable),
//! with at most `--batch` nodes a Browse and attributes a Read. `--batch 1` is the naive client: one
//! request per node browsed and per attribute read, over the same nodes verify reads.
//!
//! ```text
//! cargo run --release --example walk_bench -p nodeset-compiler -- opc.tcp://127.0.0.1:4840/ --batch 1 --runs 3
//! ```
//!
//! It connects without security (the bench starts its servers with `--insecure`, on loopback). Each run is
//! one session: connect, walk, disconnect, timed as a whole. Output: one line per run on stderr, and on
//! stdout `BENCH nodes=N round_trips=N median_ms=X min_ms=X max_ms=X`.

use std::process::ExitCode;
use std::time::Instant;

use nodeset_compiler::verify::client::{snapshot_batched, Connect};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(url) = args.first().cloned() else {
        eprintln!("usage: walk_bench URL [--batch N] [--runs N]");
        return ExitCode::from(2);
    };
    let option = |name: &str, default: usize| -> usize {
        args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).and_then(|v| v.parse().ok()).unwrap_or(default)
    };
    let (batch, runs) = (option("--batch", 1), option("--runs", 3).max(1));
    let connect = Connect {
        url,
        security_policy: "None".into(),
        security_mode: "None".into(),
        user: None,
        pki_dir: std::env::temp_dir().join("nodeset-compiler-walk-bench-pki"),
        trust_server_cert: false,
    };
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().expect("a tokio runtime");
    let mut times = Vec::with_capacity(runs);
    let (mut nodes, mut round_trips) = (0, 0);
    for run in 1..=runs {
        let start = Instant::now();
        let snapshot = match runtime.block_on(snapshot_batched(&connect, Some(batch))) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        };
        let ms = start.elapsed().as_secs_f64() * 1e3;
        (nodes, round_trips) = (snapshot.nodes.len(), snapshot.round_trips);
        eprintln!("walk_bench: run {run}: {nodes} nodes, {round_trips} round trips, {ms:.1} ms (batch {batch})");
        times.push(ms);
    }
    bench_support::Line::new().kv("nodes", nodes).kv("round_trips", round_trips).stats("walk", &times, 1).print();
    ExitCode::SUCCESS
}
