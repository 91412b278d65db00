//! The `verify` scenario: `nodeset-compiler verify` against a live server (issue 23, "Typed clients, and
//! verifying any live server against its nodesets", whose target is the robot cell verified in under one
//! second).
//!
//! It builds, in release mode (with `--no-release`, in the dev profile, as `cargo test` builds them), the
//! `nodeset-compiler` command, the `walk_bench` example of nodeset-compiler
//! and the `robot_cell` example of nodeset-examples; starts the robot cell (`--insecure`, on loopback,
//! free ports), whose three servers (the robot, the drilling unit and the cell) each show the whole cell,
//! and verifies the cell, that is all three servers, one after the other:
//!
//! - runs `nodeset-compiler verify URL --models nodesets/vendor --models nodesets --insecure --json` for
//!   each server, each a fresh process timed from spawn to exit (loading the nodesets, the session, the
//!   walk, the checks); a run is the three in a row, timed as a whole. Nodes checked and round trips are
//!   read from the reports and summed, and shown per server too: each server's round trips grow with the
//!   depth of its address space, not with the nodes of the cell;
//! - the baseline, in the same run: `walk_bench --batch 1` over the three servers, the same walk verify
//!   makes of them (the same nodes, browsed and read) by a naive client that sends one request per node
//!   browsed and per attribute read, timed per run (three sessions: connect, walk, disconnect) without
//!   loading nodesets or checking;
//! - `walk_bench` with verify's own batches, to show how much of verify's time is the walk.
//!
//! The ratio is verify's median over the naive walk's median: below 1, verify (nodesets and checks
//! included) takes less time than the naive client needs only to read the same nodes. The target is
//! printed as a verdict, never asserted: the host is shared and its speed varies.

use std::env;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::verdict;
use bench_support::Report;
use process_support::Process;
use process_support::workspace::target_dir;

/// The target for the robot cell, in milliseconds.
const TARGET_MS: f64 = 1000.0;

fn cargo_build(root: &Path, release: bool, args: &[&str]) -> Result<(), String> {
    let status = process_support::workspace::cargo()
        .current_dir(root)
        .args(["build", "--quiet"])
        .args(release.then_some("--release"))
        .args(args)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("cargo build {} failed ({status})", args.join(" ")))
    }
}

/// The number after `"key":` in verify's JSON report.
fn json_number(json: &str, key: &str) -> Option<u64> {
    let at = json.find(&format!("\"{key}\":"))? + key.len() + 3;
    json[at..].chars().take_while(char::is_ascii_digit).collect::<String>().parse().ok()
}

/// The robot cell's servers, in the order it starts them: the label of their `<label> listening on <url>`
/// line.
const SERVERS: [&str; 3] = ["robot", "drilling unit", "cell"];

/// One server's figures from verify's JSON report.
#[derive(Clone, Copy, Default)]
struct Figures {
    checked: u64,
    round_trips: u64,
    violations: u64,
    millis: u64,
}

/// Runs `nodeset-compiler verify URL ... --json` once: the time from spawn to exit, and its figures.
fn verify_once(compiler: &Path, root: &Path, url: &str) -> Result<(f64, Figures), String> {
    let start = Instant::now();
    let output = Command::new(compiler)
        .current_dir(root)
        .arg("verify")
        .arg(url)
        .arg("--models")
        .arg(root.join("nodesets/vendor"))
        .arg("--models")
        .arg(root.join("nodesets"))
        .args(["--insecure", "--json"])
        .stderr(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", compiler.display()))?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let json = String::from_utf8_lossy(&output.stdout);
    let number = |key: &str| json_number(&json, key).ok_or_else(|| format!("verify {url} printed no `{key}`: {json}"));
    let figures = Figures {
        checked: number("checked")?,
        round_trips: number("round_trips")?,
        violations: number("violations")?,
        millis: number("millis")?,
    };
    Ok((ms, figures))
}

/// Builds what it needs, starts the robot cell, measures, and prints the table.
pub(super) fn run(root: &Path, runs: usize, release: bool) -> Result<(), String> {
    let runs = runs.max(1);
    let profile = if release { "release" } else { "dev profile" };
    eprintln!("verify: building nodeset-compiler, walk_bench and robot_cell ({profile}) ...");
    cargo_build(root, release, &["-p", "nodeset-compiler", "--bin", "nodeset-compiler", "--example", "walk_bench"])?;
    cargo_build(root, release, &["-p", "nodeset-examples", "--example", "robot_cell"])?;
    let dir = target_dir().join(if release { "release" } else { "debug" });
    let exe = |sub: &str, name: &str| dir.join(sub).join(format!("{name}{}", env::consts::EXE_SUFFIX));
    let (compiler, walk, cell_exe) = (exe("", "nodeset-compiler"), exe("examples", "walk_bench"), exe("examples", "robot_cell"));

    let pki = env::temp_dir().join(format!("nodeset-bench-verify-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&pki);
    let cell = Process::spawn(Command::new(&cell_exe).args(["--port", "0", "--insecure", "--pki"]).arg(&pki).stderr(Stdio::null()))?;
    let mut urls: Vec<Option<String>> = vec![None; SERVERS.len()];
    loop {
        let line = cell.next_line(Duration::from_secs(120)).map_err(|e| format!("the robot cell did not get ready: {e}"))?;
        for (label, url) in SERVERS.iter().zip(urls.iter_mut()) {
            if let Some(u) = line.strip_prefix(&format!("{label} listening on ")) {
                *url = Some(u.trim().to_owned());
            }
        }
        if line.trim() == "cell ready" {
            break;
        }
    }
    let urls: Vec<String> = SERVERS
        .iter()
        .zip(urls)
        .map(|(label, url)| url.ok_or_else(|| format!("the robot cell printed no `{label} listening on <url>`")))
        .collect::<Result<_, _>>()?;

    eprintln!("verify: {runs} run(s) of `nodeset-compiler verify` against each of {} ...", urls.join(", "));
    let mut times = Vec::with_capacity(runs);
    let mut inside_ms = Vec::with_capacity(runs);
    let mut per_server = vec![Figures::default(); urls.len()];
    for run in 1..=runs {
        let mut ms = 0.0;
        for (url, figures) in urls.iter().zip(per_server.iter_mut()) {
            let (one, f) = verify_once(&compiler, root, url)?;
            ms += one;
            *figures = f;
        }
        let sum = |f: fn(&Figures) -> u64| per_server.iter().map(f).sum::<u64>();
        let (checked, round_trips, violations) = (sum(|f| f.checked), sum(|f| f.round_trips), sum(|f| f.violations));
        inside_ms.push(sum(|f| f.millis) as f64);
        eprintln!("verify: run {run}: {ms:.1} ms, {checked} nodes checked, {round_trips} round trips, {violations} violation(s)");
        times.push(ms);
    }
    let walk_report = |batch: &str| -> Result<super::Report, String> {
        eprintln!("verify: walk_bench --batch {batch} --runs {runs} ...");
        let out = Command::new(&walk)
            .args(&urls)
            .args(["--batch", batch, "--runs", &runs.to_string()])
            .stderr(Stdio::inherit())
            .output()
            .map_err(|e| format!("cannot run {}: {e}", walk.display()))?;
        if !out.status.success() {
            return Err(format!("walk_bench --batch {batch} failed ({})", out.status));
        }
        Report::parse(&String::from_utf8_lossy(&out.stdout)).ok_or_else(|| "walk_bench printed no BENCH line".to_owned())
    };
    let naive = walk_report("1")?;
    let batched = walk_report("1000")?;
    drop(cell);
    let _ = std::fs::remove_dir_all(&pki);

    let sum = |f: fn(&Figures) -> u64| per_server.iter().map(f).sum::<u64>();
    let (checked, round_trips, violations) = (sum(|f| f.checked), sum(|f| f.round_trips), sum(|f| f.violations));
    let (median, min, max) = (bench_support::median(&times), bench_support::min(&times), bench_support::max(&times));
    let inside = bench_support::median(&inside_ms);
    println!();
    println!("Verify: `nodeset-compiler verify` against the robot cell, its {} servers one after the other, {profile} build, {runs} run(s).", urls.len());
    for ((label, url), f) in SERVERS.iter().zip(&urls).zip(&per_server) {
        println!(
            "  {:<35} {:>8} nodes checked, {:>3} round trips, {} violation(s)",
            format!("{label} ({url})"),
            f.checked,
            f.round_trips,
            f.violations
        );
    }
    println!("  nodes checked, the cell              {checked:>8}   ({violations} violation(s))");
    println!("  round trips, the cell                {round_trips:>8}");
    println!("  verify, process spawn to exit        median {median:>7.1} ms   min {min:.1}   max {max:.1}   (the servers' runs summed)");
    println!("  verify's own `millis` (its reports)  median {inside:>7.1} ms");
    println!(
        "  verify's walk alone (walk_bench)     median {:>7.1} ms   min {}   max {}   ({} nodes, {} round trips)",
        batched.f("walk_median_ms"),
        batched.s("walk_min_ms"),
        batched.s("walk_max_ms"),
        batched.s("nodes"),
        batched.s("round_trips")
    );
    println!(
        "  baseline: naive walk, batch 1        median {:>7.1} ms   min {}   max {}   ({} nodes, {} round trips)",
        naive.f("walk_median_ms"),
        naive.s("walk_min_ms"),
        naive.s("walk_max_ms"),
        naive.s("nodes"),
        naive.s("round_trips")
    );
    println!(
        "  ratio verify / naive walk            {:>8.2}   (verify with nodesets and checks, against one request per node)",
        median / naive.f("walk_median_ms")
    );
    println!(
        "  target: robot cell verified in under {TARGET_MS:.0} ms: {} (median {median:.1} ms, spawn to exit)",
        verdict(median, TARGET_MS)
    );
    Ok(())
}
