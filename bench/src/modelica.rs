//! The `modelica` scenario: Modelica generation for DI + IA + Robotics, timed by
//! `nodeset-compiler/examples/modelica_bench.rs` (generation alone, loading excluded) in a fresh process, between
//! two timings of the peer. The 20 ms target was set on the development machine; the peer's run in the same
//! bench says how fast the host is now, so the target is judged scaled by it, and as a ratio to the peer.

use std::path::Path;
use std::process::Command;

use super::peer::{self, Yardsticks};
use super::{build, run_report, verdict, Args};

/// Target: the median time of one generation of DI + IA + Robotics (with the used part of ns0 and
/// OpcUaSupport), on the development machine.
const MODELICA_TIME_MS: f64 = 20.0;

/// Runs of the generation in one process.
const RUNS: usize = 50;

pub(super) fn run(args: &Args, root: &Path, tree: &Path) -> Result<(), String> {
    let exe = build(root, "nodeset-compiler", "modelica_bench", &[])?;
    eprintln!("running scenario `modelica` ({RUNS} runs) ...");
    let (report, yard) = Yardsticks::new(args, root, tree)
        .around("ours", || run_report(Command::new(&exe).arg(RUNS.to_string())));
    let r = report.map_err(|e| format!("scenario `modelica`: {e}"))?;
    let median = r.f("total_median_ms");
    println!();
    println!("Modelica generation of DI + IA + Robotics (emit::modelica::generate, loading excluded), release build.");
    println!(
        "   time     median {median:>10.2} ms   min {:>10.2} ms   max {:>10.2} ms   target <= {MODELICA_TIME_MS} ms  {}",
        r.f("total_min_ms"),
        r.f("total_max_ms"),
        verdict(median, MODELICA_TIME_MS)
    );
    peer::print_judged(yard.as_ref(), median, MODELICA_TIME_MS);
    println!("   output   {} files, {:.1} KiB", r.s("files"), r.f("bytes") / 1024.0);
    println!();
    Ok(())
}
