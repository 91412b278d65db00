//! The `generation` scenario: `nodeset-compiler rust` on DI + IA + Robotics (ns0 found in
//! `nodesets/vendor` as their dependency) as a whole process, against async-opcua-codegen 0.19 on the
//! same files and against the floor, a process that only reads the four input files.
//!
//! The three run in rounds, one run of each per round in the order peer, ours, floor (`rust_bench
//! alternate`), after one untimed round, so that all three sample the same stretch of the shared host's
//! time. The verdicts are the medians of the per-round ratios: ours / peer against the target 0.05 (the
//! issue: generation at most 1/20 of the peer's time), and ours / floor, how far above the floor we are.
//! Our CLI writes its output folder (only changed files: after the first round, none), as a build script
//! would; the peer writes its files every run.

use std::path::Path;
use std::process::Command;

use bench_support::{median, Report};

use super::peer::{prepare_three, PEER, PEER_VERSION};
use super::rust::cli_args;
use super::{build, run_report, verdict, Args, VENDOR_FILES};
use process_support::workspace::{display_path, target_dir};

/// The target: our whole process at most this fraction of the peer's.
const TARGET_RATIO: f64 = 0.05;

/// Runs the scenario and prints its table.
pub(super) fn run(args: &Args, root: &Path, tree: &Path) -> Result<(), String> {
    let vendor = root.join("nodesets/vendor");
    let bench = build(root, "nodeset-compiler", "rust_bench", &["--bin", "nodeset-compiler"])?;
    let cli = target_dir().join("release").join(format!("nodeset-compiler{}", std::env::consts::EXE_SUFFIX));
    let out = root.join("target/bench-build/generation-cli/models");
    let _ = std::fs::remove_dir_all(&out);

    let mut cmd = Command::new(&bench);
    cmd.arg("alternate").arg("--rounds").arg(args.runs_generation.max(1).to_string()).arg("--env").arg("RUST_LOG=warn");
    let peer = if args.no_peer {
        Err("--no-peer".to_string())
    } else {
        prepare_three(root, tree)
    };
    if let Ok((exe, dir, config)) = &peer {
        cmd.arg("--dir").arg(dir).arg("--cmd").arg("peer").arg(exe).arg(config);
    }
    cmd.arg("--cmd").arg("ours").arg(&cli).args(cli_args(&vendor, &out));
    cmd.arg("--cmd").arg("floor").arg(&bench).arg("read").args(VENDOR_FILES.iter().map(|f| vendor.join(f)));
    eprintln!(
        "generation: {} round(s) of [{}our CLI, a plain read of the four files] ...",
        args.runs_generation.max(1),
        if peer.is_ok() { "the peer, " } else { "" }
    );
    let report = run_report(&mut cmd)?;
    print(&report, peer.as_ref().err(), &out);
    Ok(())
}

/// The per-round walls of `name`, ms.
fn rounds(r: &Report, name: &str) -> Vec<f64> {
    r.s(&format!("{name}_rounds_ms")).split(',').filter_map(|x| x.parse().ok()).collect()
}

/// The median of the per-round ratios `a / b`.
fn ratio(r: &Report, a: &str, b: &str) -> f64 {
    let ratios: Vec<f64> = rounds(r, a).iter().zip(rounds(r, b)).map(|(x, y)| x / y).collect();
    median(&ratios)
}

fn print(r: &Report, no_peer: Option<&String>, out: &Path) {
    println!();
    println!(
        "== generation: `nodeset-compiler rust` on DI + IA + Robotics (ns0 from nodesets/vendor) as a whole process, {} round(s)",
        r.s("rounds")
    );
    println!("   (output: {}; each round runs peer, ours, floor once; wall per process)", display_path(out));
    let row = |label: &str, name: &str| {
        println!(
            "   {label:<34} median {:>8.1} ms   min {:>8.1} ms   CPU/run {:>8.1} ms",
            r.f(&format!("{name}_median_ms")),
            r.f(&format!("{name}_min_ms")),
            r.f(&format!("{name}_cpu_median_ms"))
        );
    };
    if no_peer.is_none() {
        row(&format!("{PEER} {PEER_VERSION}"), "peer");
    }
    row("ours (nodeset-compiler rust)", "ours");
    row("floor (read the four files)", "floor");
    match no_peer {
        None => {
            let x = ratio(r, "ours", "peer");
            println!(
                "   ours / peer   median of per-round ratios {x:.3}   target <= {TARGET_RATIO}  {}",
                verdict(x, TARGET_RATIO)
            );
        }
        Some(why) => println!("   ours / peer   not measured: {why}"),
    }
    println!("   ours / floor  median of per-round ratios {:.2}   (1 would be the cost of reading the inputs)", ratio(r, "ours", "floor"));
}
