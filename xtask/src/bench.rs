//! `cargo xtask bench`: times the compiler on real NodeSet2 files (the foundation stage, parse + load +
//! resolve, and the Rust back end) and compares it with the project's targets and with async-opcua-codegen.
//!
//! The measured programs are examples: `nodeset-compiler/examples/load_bench.rs` (front end),
//! `nodeset-compiler/examples/rust_bench.rs` (Rust generation, and a stopwatch for other programs) and
//! `nodeset-examples/examples/import_bench.rs` (address-space import). This task builds them in release mode, runs
//! every scenario in its own process (so that the peak resident memory, `VmHWM`, belongs to that scenario
//! alone), reads the `BENCH key=value ...` line each prints and shows a table. It is a report, not a test:
//! a missed target prints `OVER` but the task still succeeds; it fails only when one of our own steps fails.
//!
//! Scenarios:
//!
//! * `robotics`: ns0 + DI + IA + Robotics from `nodesets/vendor/` (fetched first if missing).
//! * `tree`: every NodeSet2 file of the `UA-Nodeset` tree at `../shared/nodesets/ua-nodeset`, one compile
//!   per file with its required models taken from the tree.
//! * `sets`: the same tree as a few compiles of many files each (every file named once, no ModelUri twice in
//!   one compile: the newest versions together, then the older ones), required models from the tree.
//! * `rust`: the Rust back end, end to end (module [`rust`] below says how each figure is taken):
//!   generation time and memory for DI + IA + Robotics, generated lines, build time of the generated crate
//!   alone, address-space import time, and the same figures for async-opcua-codegen 0.19 on the same inputs.
//! * `robots`: the typed API at scale ([`robots`]): N six-axis robots instantiated in one server, every joint
//!   position updated at 100 Hz; time per update cycle and memory per robot. Not part of `all` (it runs for
//!   `--robots-seconds` and builds the server stack in release mode).
//! * `verify`: `nodeset-compiler verify` against the robot cell's robot server, several runs, next to a
//!   naive client's walk of the same nodes in the same run (module [`verify`]). Not part of `all` (it
//!   starts the robot cell).
//! * `scale`: synthetic models of n and 4n nodes in several shapes, timed in this process, with the ratio
//!   per stage (module [`scale`]); looks for quadratic behaviour.
//!
//! The host is shared and its speed changes by half within an hour, so the time targets are also judged
//! against a yardstick taken in the same run: async-opcua-codegen's whole DI + Robotics run (types and nodes
//! of both), which the foundation issue measured at 250 ms on this machine, is timed just before and just
//! after our measurement; its median over 250 ms is the host's slowdown, and each time target is printed
//! as given and scaled by it. The crate-build target is scaled by the peer's own crate build against the
//! 2.7 s the Rust back-end issue measured. `--no-peer` leaves the targets unscaled. Two targets are judged
//! from rounds that alternate our measure and the peer's, so that both sample the same stretch of time:
//! the crate build (cold builds of both crates, back to back) and the import (the peer's run, then an
//! import_bench process), each by the median of its per-round ratios.

use std::collections::BTreeMap;
use std::env;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::util::{display_path, workspace_root};

mod robots;
mod scale;
mod verify;

/// The files of the `robotics` scenario, in `nodesets/vendor/`.
const VENDOR_FILES: &[&str] = &[
    "Opc.Ua.NodeSet2.xml",
    "Opc.Ua.Di.NodeSet2.xml",
    "Opc.Ua.IA.NodeSet2.xml",
    "Opc.Ua.Robotics.NodeSet2.xml",
];

/// The default NodeSet tree, relative to the workspace root.
const DEFAULT_TREE: &str = "../shared/nodesets/ua-nodeset";

/// Targets: wall time of one compile of ns0 + DI + IA + Robotics, its peak memory, one pass over the tree
/// (judged on `sets`, which reads every file of the tree once).
const ROBOTICS_TIME_MS: f64 = 15.0;
const ROBOTICS_MEM_MIB: f64 = 40.0;
const TREE_TIME_MS: f64 = 1000.0;

/// Arguments of `cargo xtask bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which scenario(s) to run.
    #[arg(long, value_parser = ["all", "robotics", "tree", "sets", "rust", "scale", "robots", "verify"], default_value = "all")]
    scenario: String,

    /// Runs of the robotics scenario (ns0 + DI + IA + Robotics).
    #[arg(long, value_name = "N", default_value_t = 20)]
    runs_robotics: usize,

    /// Runs of the tree and sets scenarios (one run = one pass over the tree).
    #[arg(long, value_name = "N", default_value_t = 3)]
    runs_tree: usize,

    /// The NodeSet tree of the tree and sets scenarios, and of the XML schemas async-opcua-codegen needs in
    /// the rust scenario (default: ../shared/nodesets/ua-nodeset from the workspace root).
    #[arg(long, value_name = "DIR")]
    tree: Option<PathBuf>,

    /// Runs of the generation in the rust scenario (compile + Rust emission of DI + IA + Robotics).
    #[arg(long, value_name = "N", default_value_t = 20)]
    runs_rust: usize,

    /// Runs of the address-space import in the rust scenario.
    #[arg(long, value_name = "N", default_value_t = 50)]
    runs_import: usize,

    /// Runs of each timed debug `cargo build` in the rust scenario (cold crate-only and incremental);
    /// release builds run once.
    #[arg(long, value_name = "N", default_value_t = 3)]
    runs_build: usize,

    /// Runs of each generator process in the rust scenario (our CLI and async-opcua-codegen).
    #[arg(long, value_name = "N", default_value_t = 3)]
    runs_process: usize,

    /// Rust scenario: skip the `cargo build` timings and the import bench (no async-opcua build needed).
    #[arg(long)]
    no_builds: bool,

    /// Robotics and rust scenarios: skip async-opcua-codegen (the peer, and the yardstick of the host's
    /// speed: targets are then compared unscaled).
    #[arg(long)]
    no_peer: bool,

    /// Rust scenario: skip the release builds (the import bench is still built in release). Verify
    /// scenario: measure dev-profile builds (those `cargo test` makes) instead of release ones.
    #[arg(long)]
    no_release: bool,

    /// Robots scenario: how many six-axis robots.
    #[arg(long, value_name = "N", default_value_t = 100)]
    robots: usize,

    /// Robots scenario: the update rate of every joint position.
    #[arg(long, value_name = "HZ", default_value_t = 100)]
    robots_hz: u32,

    /// Robots scenario: how long the updates run.
    #[arg(long, value_name = "S", default_value_t = 10)]
    robots_seconds: u64,
    /// Nodes of the smaller model of each shape in the scale scenario (the larger has four times as many).
    #[arg(long, value_name = "N", default_value_t = 10_000)]
    scale_n: usize,

    /// Runs of each model in the scale scenario (the median is shown).
    #[arg(long, value_name = "N", default_value_t = 3)]
    runs_scale: usize,

    /// Runs of `nodeset-compiler verify` (and of each baseline walk) in the verify scenario.
    #[arg(long, value_name = "N", default_value_t = 5)]
    runs_verify: usize,

    /// Skip the stage-split runs (halves the run time; the table then shows totals only).
    #[arg(long)]
    no_split: bool,
}

/// One parsed `BENCH` line.
struct Report(BTreeMap<String, String>);

impl Report {
    fn f(&self, key: &str) -> f64 {
        self.0
            .get(key)
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN)
    }

    fn s(&self, key: &str) -> &str {
        self.0.get(key).map(String::as_str).unwrap_or("?")
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    let want = |s: &str| args.scenario == "all" || args.scenario == s;
    let tree = args.tree.clone().unwrap_or_else(|| root.join(DEFAULT_TREE));

    if want("robotics") || want("rust") || want("scale") {
        ensure_vendor(&root.join("nodesets/vendor"))?;
    }
    let tree_scenarios: Vec<&str> = ["tree", "sets"].into_iter().filter(|s| want(s)).collect();
    let run_tree = !tree_scenarios.is_empty() && tree.is_dir();
    if !tree_scenarios.is_empty() && !run_tree {
        if args.scenario != "all" {
            return Err(format!(
                "the NodeSet tree {} does not exist (give another with --tree DIR)",
                display_path(&tree)
            ));
        }
        eprintln!(
            "note: skipping the tree and sets scenarios: {} does not exist (give it with --tree DIR)",
            display_path(&tree)
        );
    }

    let mut reports = Vec::new();
    let exe = if want("robotics") || run_tree {
        build(&root, "load_bench", &[])?
    } else {
        PathBuf::new()
    };
    // The peer's whole DI + Robotics run just before and after ours: how fast the shared host is right now.
    let mut yard: Option<Result<rust::Yardstick, String>> = None;
    if want("robotics") {
        let (report, y) = rust::Yardsticks::new(&args, &root, &tree).around("ours", || {
            measure(&exe, "robotics", args.runs_robotics, &[], args.no_split)
        });
        reports.push(report?);
        yard = y;
    }
    if run_tree {
        let tree_arg = ["--tree".to_string(), tree.display().to_string()];
        for scenario in tree_scenarios {
            reports.push(measure(
                &exe,
                scenario,
                args.runs_tree,
                &tree_arg,
                args.no_split,
            )?);
        }
    }
    if !reports.is_empty() {
        print_table(&reports, !args.no_split, yard.as_ref());
    }
    if want("rust") {
        rust::run(&args, &root, &tree)?;
    }
    if want("scale") {
        scale::run(&root.join("nodesets/vendor"), args.scale_n, args.runs_scale)?;
    }
    if args.scenario == "robots" {
        robots::run(&root, args.robots, args.robots_hz, args.robots_seconds)?;
    }
    if args.scenario == "verify" {
        ensure_vendor(&root.join("nodesets/vendor"))?;
        verify::run(&root, args.runs_verify, !args.no_release)?;
    }
    Ok(())
}

/// Makes sure the vendored files exist, fetching them (as `cargo xtask fetch-nodesets` does) if not.
fn ensure_vendor(vendor: &Path) -> Result<(), String> {
    if VENDOR_FILES.iter().all(|f| vendor.join(f).is_file()) {
        return Ok(());
    }
    eprintln!(
        "{} is incomplete; running `cargo xtask fetch-nodesets` first",
        display_path(vendor)
    );
    crate::fetch::ensure_fetched()
        .map_err(|e| format!("{e}\n(the bench needs `cargo xtask fetch-nodesets` to succeed)"))
}

/// Builds an example of nodeset-compiler in release mode (with `extra` cargo arguments, such as
/// `--bin nodeset-compiler`) and returns the path of its executable.
fn build(root: &Path, example: &str, extra: &[&str]) -> Result<PathBuf, String> {
    eprintln!("building the {example} example (release) ...");
    let cargo = env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(root)
        .args([
            "build",
            "--quiet",
            "--release",
            "--example",
            example,
            "-p",
            "nodeset-compiler",
        ])
        .args(extra)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building the {example} example failed ({status})"));
    }
    let exe = release_dir(root)
        .join("examples")
        .join(format!("{example}{}", env::consts::EXE_SUFFIX));
    if exe.is_file() {
        Ok(exe)
    } else {
        Err(format!(
            "built the example, but {} does not exist",
            exe.display()
        ))
    }
}

/// The `release` folder of the developer's target directory (`CARGO_TARGET_DIR` or `target/`).
fn release_dir(root: &Path) -> PathBuf {
    let target = env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let target = if target.is_absolute() {
        target
    } else {
        root.join(target)
    };
    target.join("release")
}

/// Runs one scenario in a fresh process and parses its `BENCH` line; its stderr goes to ours.
fn measure(
    exe: &Path,
    scenario: &str,
    runs: usize,
    extra: &[String],
    no_split: bool,
) -> Result<Report, String> {
    eprintln!("running scenario `{scenario}` ({runs} run(s)) ...");
    let mut cmd = Command::new(exe);
    cmd.arg(scenario)
        .arg("--runs")
        .arg(runs.max(1).to_string())
        .args(extra);
    if no_split {
        cmd.arg("--no-split");
    }
    let out = cmd
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    if !out.status.success() {
        return Err(format!("scenario `{scenario}` failed ({})", out.status));
    }
    parse_report(&String::from_utf8_lossy(&out.stdout))
        .ok_or_else(|| format!("scenario `{scenario}` printed no BENCH line"))
}

/// The `BENCH key=value ...` line of a measured program's stdout.
fn parse_report(stdout: &str) -> Option<Report> {
    let line = stdout.lines().find_map(|l| l.strip_prefix("BENCH "))?;
    let map = line
        .split_whitespace()
        .filter_map(|kv| kv.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    Some(Report(map))
}

fn verdict(value: f64, limit: f64) -> &'static str {
    if value <= limit {
        "PASS"
    } else {
        "OVER"
    }
}

fn print_table(reports: &[Report], split: bool, yard: Option<&Result<rust::Yardstick, String>>) {
    println!();
    println!("Foundation stage (parse + load + resolve), release build.");
    println!("time = wall clock of the `compile` calls of one run (dropping the results is not included);");
    println!("memory = VmHWM of a fresh process per scenario; targets are compared with the median and the first run's VmHWM.");
    for r in reports {
        println!();
        let scenario = r.s("scenario");
        // The whole-tree target is judged where the whole tree is parsed, loaded and resolved once (`sets`);
        // `tree` compiles each file on its own with the models it requires, re-reading ns0 117 times.
        let (title, time_limit) = match scenario {
            "robotics" => (
                "ns0 + DI + IA + Robotics (nodesets/vendor), one compile",
                Some(ROBOTICS_TIME_MS),
            ),
            "sets" => (
                "UA-Nodeset tree, a few compiles naming every file once (models from the tree), one pass",
                Some(TREE_TIME_MS),
            ),
            _ => (
                "UA-Nodeset tree, one compile per file (models from the tree), one pass",
                None,
            ),
        };
        let total = r.f("total_median_ms");
        println!("== {scenario}: {title}");
        println!(
            "   runs {:>6}   compiles per run {}",
            r.s("runs"),
            r.s("compiles")
        );
        let judged = match time_limit {
            Some(limit) => format!("target <= {limit} ms  {}", verdict(total, limit)),
            None => format!(
                "(the <= {TREE_TIME_MS} ms whole-tree target is judged on `sets`, where every file is read once; \
                 here each compile re-reads the models it requires)"
            ),
        };
        println!(
            "   time     median {:>10.2} ms   min {:>10.2} ms   max {:>10.2} ms   {judged}",
            total,
            r.f("total_min_ms"),
            r.f("total_max_ms"),
        );
        println!(
            "   CPU      median {:>10.2} ms   min {:>10.2} ms   (this thread's CPU time; wall time above also counts waiting for a busy CPU)",
            r.f("cpu_median_ms"),
            r.f("cpu_min_ms")
        );
        if scenario == "robotics" {
            match yard {
                Some(Ok(y)) => {
                    println!(
                        "   peer     async-opcua-codegen {}, its whole DI + Robotics run, {} run(s) around ours: median {:.1} ms, min {:.1} ms;",
                        rust::PEER_VERSION,
                        y.runs,
                        y.median_ms,
                        y.min_ms
                    );
                    println!(
                        "            the issue measured {} ms on this machine, so the host is {:.2}x as slow now: {}",
                        rust::PEER_RUN_STATED_MS,
                        y.slowdown(),
                        rust::scaled(total, ROBOTICS_TIME_MS, y.slowdown(), "ms")
                    );
                    println!(
                        "            (ours / peer = {:.3}; the target's ratio is {ROBOTICS_TIME_MS} / {} = {:.3})",
                        total / y.median_ms,
                        rust::PEER_RUN_STATED_MS,
                        ROBOTICS_TIME_MS / rust::PEER_RUN_STATED_MS
                    );
                }
                Some(Err(e)) => println!("   peer     not measured: {e}"),
                None => println!("   peer     not measured (--no-peer): the target is not scaled to the host's speed"),
            }
        }
        let hwm_mib = r.f("hwm_kib") / 1024.0;
        let mem_target = if scenario == "robotics" {
            format!(
                "target <= {ROBOTICS_MEM_MIB} MiB  {}",
                verdict(hwm_mib, ROBOTICS_MEM_MIB)
            )
        } else {
            "(no target)".to_string()
        };
        println!(
            "   memory   VmHWM after first run {:>7.1} MiB   after all runs {:>7.1} MiB   at start {:>5.1} MiB   {mem_target}",
            hwm_mib,
            r.f("hwm_all_runs_kib") / 1024.0,
            r.f("hwm_start_kib") / 1024.0,
        );
        if scenario == "robotics" {
            println!(
                "   nodes    {}   files loaded {}",
                r.s("nodes"),
                r.s("files_loaded")
            );
        } else {
            println!(
                "   nodes    {} summed over compiles (largest model {}); {} distinct files with {} nodes; {} files loaded in all",
                r.s("nodes"),
                r.s("max_nodes"),
                r.s("unique_files"),
                r.s("unique_nodes"),
                r.s("files_loaded")
            );
        }
        println!(
            "   diags    {} error(s), {} warning(s); compiles with errors: {}",
            r.s("errors"),
            r.s("warnings"),
            r.s("failed_compiles")
        );
        if split {
            let load = r.f("load_median_ms");
            let resolve = r.f("resolve_median_ms");
            let pct = |x: f64| {
                if load + resolve > 0.0 {
                    100.0 * x / (load + resolve)
                } else {
                    0.0
                }
            };
            println!("   stages (median of separate runs; read/decode/parse estimated from standalone per-file runs):");
            println!(
                "     load::load           {:>10.2} ms  {:>5.1}%",
                load,
                pct(load)
            );
            for (name, key) in [
                ("fs::read", "read_ms"),
                ("parse::decode_text", "decode_ms"),
                ("parse::parse", "parse_ms"),
                ("rest of load", "load_other_ms"),
            ] {
                println!(
                    "       {name:<18} {:>10.2} ms  {:>5.1}%",
                    r.f(key),
                    pct(r.f(key))
                );
            }
            println!(
                "     resolve::resolve     {:>10.2} ms  {:>5.1}%",
                resolve,
                pct(resolve)
            );
            let rest = total - load - resolve;
            if rest >= 0.0 {
                println!("     rest of compile      {rest:>10.2} ms  (total - load - resolve: diagnostic sorting, plus noise between runs)");
            } else {
                println!("     rest of compile             n/a  (the split runs were slower than the timed runs: a busy machine)");
            }
            println!(
                "     (dropping the results, not in the totals: {:.2} ms)",
                r.f("drop_median_ms")
            );
            if scenario != "robotics" {
                println!(
                    "     (reading + parsing each of the {} distinct files once would take {:.2} ms)",
                    r.s("unique_files"),
                    r.f("unique_parse_ms")
                );
            }
        }
    }
    println!();
}

/// The `rust` scenario: the Rust back end, end to end, next to async-opcua-codegen 0.19.
///
/// How each figure is taken:
///
/// 1. Generation: `nodeset-compiler/examples/rust_bench.rs generate` in a fresh process: what
///    `cargo xtask generate` does minus writing (one `compile` of DI, IA and Robotics with ns0 found in
///    `nodesets/vendor/` as their dependency, then `emit::rust::generate`), each stage timed in every run;
///    `VmHWM` after the first run. The `nodeset-compiler rust` CLI is also timed as a whole process (start,
///    read, compile, emit, write; it writes only changed files), which is what the peer's figure means.
/// 2. Lines: of `generated/src/models/<module>/*.rs` as checked in, compared with this run's output.
/// 3. Builds: `cargo build -p nodeset-models` in its own target folder (`target/bench-build`, so the
///    developer's `target/` is not disturbed). Dependencies are built once first (the warm-up); then, per
///    run, `cargo clean -p nodeset-models` and a timed build (cold, our crate alone), then
///    `generated/src/models/robotics/types.rs` is touched and the build timed again (incremental). A no-op
///    build shows cargo's own share of these wall times. Debug builds run `--runs-build` times, release
///    builds once. The hand-written runtime is the crate `nodeset-runtime` (`nodeset-runtime/`), a
///    dependency built once like async-opcua; its cold build is timed the same way, so that what a user
///    compiles in all from a clean target is also shown. nodeset-models holds six namespaces; the CLI's
///    output of step 1 (DI + IA + Robotics, the peer's inputs) is built the same way as the crate
///    `nodeset-models-di-ia-robotics` on nodeset-runtime, the figure to set beside the peer's crate.
/// 4. Import: `nodeset-examples/examples/import_bench.rs` (release), which says what it includes.
/// 5. Peer: async-opcua-codegen 0.19.0, installed once into `target/bench-tools`, with a config written to
///    `target/bench-build/peer/codegen.yml` (a `types` and a `nodes` target per namespace; the nodes target
///    needs the XML schemas of ns0 and of each model, taken from the UA-Nodeset tree). Its output is built as
///    the crate `codegen-peer-models` in the same target folder, with a `lib.rs` written here that only
///    declares the generated modules. A failing peer step is reported in the table, never fatal.
/// 6. Interleaved: `--runs-build` rounds (at least 3) of cold debug builds of the peer's crate,
///    nodeset-models and the DI + IA + Robotics crate, back to back. The crate-build target (0.556x the
///    peer) is judged by the median of the per-round ratios: steps 3 and 5 time each crate's runs together,
///    minutes apart, and this host's speed drifts too much for a ratio across them.
mod rust {
    use super::{build, parse_report, release_dir, verdict, Args, Report};
    use crate::util::display_path;
    use std::env;
    use std::fs;
    use std::path::{Path, PathBuf};
    use std::process::{Command, Stdio};
    use std::time::{Instant, SystemTime};

    /// Targets: emission time, generated lines of DI + Robotics, cold crate-only build, import.
    const EMIT_MS: f64 = 25.0;
    const LINES_DI_ROBOTICS: usize = 12_000;
    const CRATE_BUILD_S: f64 = 1.5;
    const IMPORT_MS: f64 = 1.0;

    /// The generated namespaces: (module, NodeSet2 file in nodesets/vendor, URI, XML schema in the tree).
    const NAMESPACES: [(&str, &str, &str, &str); 3] = [
        (
            "di",
            "Opc.Ua.Di.NodeSet2.xml",
            "http://opcfoundation.org/UA/DI/",
            "DI/Opc.Ua.Di.Types.xsd",
        ),
        (
            "ia",
            "Opc.Ua.IA.NodeSet2.xml",
            "http://opcfoundation.org/UA/IA/",
            "IA/Opc.Ua.IA.Types.xsd",
        ),
        (
            "robotics",
            "Opc.Ua.Robotics.NodeSet2.xml",
            "http://opcfoundation.org/UA/Robotics/",
            "Robotics/Opc.Ua.Robotics.Types.xsd",
        ),
    ];
    /// The XML schema of ns0 in the tree.
    const NS0_XSD: &str = "Schema/Opc.Ua.Types.xsd";
    const PEER: &str = "async-opcua-codegen";
    pub(super) const PEER_VERSION: &str = "0.19.0";
    const PEER_CRATE: &str = "codegen-peer-models";
    const RUNTIME_CRATE: &str = "nodeset-runtime";
    /// The CLI's output for DI + IA + Robotics (the peer's inputs) as a crate of its own on nodeset-runtime.
    const THREE_CRATE: &str = "nodeset-models-di-ia-robotics";
    /// Release builds run once: they are slow, and the release profile compiles without incremental.
    const RELEASE_RUNS: usize = 1;
    /// Our crate, and the file touched before an incremental build (the peer's counterpart is its Robotics
    /// types module).
    const CRATE: &str = "nodeset-models";
    const TOUCHED: &str = "generated/src/models/robotics/types.rs";
    const PEER_TOUCHED: &str = "src/robotics/types/mod.rs";

    type Step<T> = Result<T, String>;

    /// Median and min of some wall times, and the median CPU time, in seconds.
    #[derive(Clone, Copy)]
    struct Times {
        median: f64,
        min: f64,
        cpu: f64,
    }

    fn median(v: &[f64]) -> f64 {
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        match s.len() {
            0 => f64::NAN,
            n if n % 2 == 1 => s[n / 2],
            n => (s[n / 2 - 1] + s[n / 2]) / 2.0,
        }
    }

    impl Times {
        const NONE: Times = Times {
            median: f64::NAN,
            min: f64::NAN,
            cpu: f64::NAN,
        };

        /// Of (wall, CPU) pairs.
        fn of(v: &[(f64, f64)]) -> Times {
            let wall: Vec<f64> = v.iter().map(|p| p.0).collect();
            let cpu: Vec<f64> = v.iter().map(|p| p.1).collect();
            Times {
                median: median(&wall),
                min: wall.iter().copied().fold(f64::NAN, f64::min),
                cpu: median(&cpu),
            }
        }
    }

    /// Build times of one crate in one profile.
    struct Builds {
        /// The first build, dependencies included (cached from earlier bench runs if they are unchanged).
        warm: f64,
        noop: Times,
        cold: Times,
        /// None where nothing was touched.
        incr: Option<Times>,
    }

    /// Files, lines and bytes of some generated Rust.
    #[derive(Clone, Copy, Default, PartialEq)]
    struct Size {
        files: usize,
        lines: usize,
        bytes: usize,
    }

    impl std::ops::Add for Size {
        type Output = Size;
        fn add(self, o: Size) -> Size {
            Size {
                files: self.files + o.files,
                lines: self.lines + o.lines,
                bytes: self.bytes + o.bytes,
            }
        }
    }

    /// Sizes per module, in `NAMESPACES` order.
    type Sizes = Vec<(&'static str, Size)>;

    fn sum(sizes: &Sizes, modules: &[&str]) -> Size {
        sizes
            .iter()
            .filter(|(m, _)| modules.contains(m))
            .fold(Size::default(), |a, (_, s)| a + *s)
    }

    /// Cold debug builds (wall, CPU) per round, in the order peer, nodeset-models, DI + IA + Robotics.
    struct Interleaved {
        peer: Vec<(f64, f64)>,
        models: Vec<(f64, f64)>,
        three: Vec<(f64, f64)>,
    }

    /// What the peer produced; every part may be missing, with the reason.
    struct Peer {
        exe: Step<PathBuf>,
        install_s: Option<f64>,
        config: Option<PathBuf>,
        gen: Step<Report>,
        sizes: Step<Sizes>,
        debug: Step<Builds>,
        release: Step<Builds>,
    }

    struct Results {
        gen: Report,
        cli: Step<Report>,
        disk: Step<Sizes>,
        fresh: Option<bool>,
        debug: Step<Builds>,
        release: Step<Builds>,
        runtime_only: Step<Builds>,
        /// The CLI's DI + IA + Robotics output alone, the peer's ground (nodeset-models also holds our three
        /// skill namespaces).
        three: Step<Builds>,
        runtime_size: Step<Size>,
        import: Step<Report>,
        peer: Option<Peer>,
        /// Cold debug builds of the peer's crate and ours back to back, round after round (None: no peer or
        /// a build above failed).
        interleaved: Option<Step<Interleaved>>,
        /// The peer's whole DI + Robotics run around the generation and around the import (None: --no-peer).
        yard_gen: Option<Step<Yardstick>>,
        yard_import: Option<Step<Yardstick>>,
        /// Rounds of [the peer's run, a few imports] (None: --no-peer or no import).
        import_rounds: Option<Step<ImportRounds>>,
    }

    /// The import and the yardstick sampled over the same stretch of time: round after round, one run of the
    /// peer, then one import_bench process of a few runs.
    struct ImportRounds {
        /// Per round: the median import of its process, ms.
        import_ms: Vec<f64>,
        /// Per round: the peer's run, ms.
        peer_ms: Vec<f64>,
    }

    /// Rounds of the import against the yardstick.
    const IMPORT_ROUNDS: usize = 9;
    /// Import runs per round.
    const IMPORT_ROUND_RUNS: usize = 20;

    /// Runs a few rounds of [the peer's DI + Robotics run, `import_bench --runs IMPORT_ROUND_RUNS`].
    fn import_rounds(yardsticks: &Yardsticks, exe: &Path) -> Option<Step<ImportRounds>> {
        let peer = yardsticks.peer.as_ref()?;
        Some((|| {
            let peer = peer.as_ref().map_err(Clone::clone)?;
            eprintln!("rust: {IMPORT_ROUNDS} rounds of [the peer's run, {IMPORT_ROUND_RUNS} imports] ...");
            let mut rounds = ImportRounds { import_ms: Vec::new(), peer_ms: Vec::new() };
            for _ in 0..IMPORT_ROUNDS {
                let y = peer.time(1)?;
                rounds.peer_ms.push(y.f("wall_median_ms"));
                let i = run_report(Command::new(exe).arg("--runs").arg(IMPORT_ROUND_RUNS.to_string()))?;
                rounds.import_ms.push(i.f("import_median_ms"));
            }
            Ok(rounds)
        })())
    }

    /// Runs the scenario and prints its table; an error means one of our own steps failed.
    pub(super) fn run(args: &Args, root: &Path, tree: &Path) -> Result<(), String> {
        let start = Instant::now();
        let load_start = load_average();
        let vendor = root.join("nodesets/vendor");
        let bench_target = root.join("target/bench-build");
        let bench = build(root, "rust_bench", &["--bin", "nodeset-compiler"])?;
        let cli_exe =
            release_dir(root).join(format!("nodeset-compiler{}", env::consts::EXE_SUFFIX));

        // The yardstick of the host's speed (the peer's whole DI + Robotics run), taken around the
        // generation and around the import.
        let yardsticks = Yardsticks::new(args, root, tree);

        // 1. Generation, in process and as a CLI process.
        let (generated, yard_gen) = yardsticks.around("the generation", || -> Step<_> {
            eprintln!("rust: generation ({} run(s)) ...", args.runs_rust.max(1));
            let gen = run_report(
                Command::new(&bench)
                    .arg("generate")
                    .arg("--runs")
                    .arg(args.runs_rust.max(1).to_string())
                    .arg("--vendor")
                    .arg(&vendor),
            )?;
            eprintln!(
                "rust: the nodeset-compiler CLI as a process ({} run(s)) ...",
                args.runs_process.max(1)
            );
            let cli_out = bench_target.join("ours-cli/models");
            let mut cli_args: Vec<String> = vec!["rust".into()];
            cli_args.extend(
                NAMESPACES
                    .iter()
                    .map(|n| vendor.join(n.1).display().to_string()),
            );
            cli_args.extend(["--models".into(), vendor.display().to_string()]);
            cli_args.extend(["--out".into(), cli_out.display().to_string()]);
            cli_args.extend(["--runtime".into(), "crate::runtime".into()]);
            for (module, _, uri, _) in NAMESPACES {
                cli_args.extend(["--module".into(), format!("{uri}={module}")]);
            }
            let _ = fs::remove_dir_all(&cli_out);
            let cli = fs::create_dir_all(&bench_target)
                .map_err(|e| format!("cannot create {}: {e}", bench_target.display()))
                .and_then(|()| exec(&bench, args.runs_process, root, &[], &cli_exe, &cli_args));
            Ok((gen, cli))
        });
        let (gen, cli) = generated?;

        // 2. Lines, as checked in.
        let models = root.join("generated/src/models");
        let disk: Step<Sizes> = NAMESPACES
            .iter()
            .map(|n| Ok((n.0, count_rs(&models.join(n.0))?)))
            .collect();
        let fresh = disk.as_ref().ok().map(|d| {
            d.iter().all(|(m, s)| {
                gen.f(&format!("lines_{m}")) == s.lines as f64
                    && gen.f(&format!("bytes_{m}")) == s.bytes as f64
            })
        });

        // 3 and 4. Builds of our crate, and the import.
        let skipped = || Err::<Builds, _>("skipped (--no-builds)".to_string());
        let (mut debug, mut release, mut runtime_only) = (skipped(), skipped(), skipped());
        let mut three = skipped();
        let mut import = Err("skipped (--no-builds)".to_string());
        let mut yard_import = None;
        let mut import_rounds_result = None;
        let runtime_size = count_rs(&root.join("nodeset-runtime/src"));
        if !args.no_builds {
            let touched = root.join(TOUCHED);
            eprintln!(
                "rust: building {CRATE} (debug) in {} ...",
                display_path(&bench_target)
            );
            debug = time_builds(
                &bench,
                root,
                &bench_target,
                CRATE,
                false,
                Some(&touched),
                args.runs_build,
            );
            eprintln!(
                "rust: building the CLI's DI + IA + Robotics output as {THREE_CRATE} (debug) ..."
            );
            let dir = bench_target.join("ours-cli");
            three = match &cli {
                Ok(_) => write_three_crate(root, &dir).and_then(|()| {
                    time_builds(
                        &bench,
                        &dir,
                        &bench_target,
                        THREE_CRATE,
                        false,
                        Some(&dir.join("models/robotics/types.rs")),
                        args.runs_build,
                    )
                }),
                Err(_) => Err("the CLI run failed".into()),
            };
            eprintln!("rust: building {RUNTIME_CRATE} (debug) ...");
            runtime_only = time_builds(
                &bench,
                root,
                &bench_target,
                RUNTIME_CRATE,
                false,
                None,
                args.runs_build,
            );
            eprintln!("rust: building the import_bench example (release) ...");
            import = cargo(
                root,
                Some(&bench_target),
                &[
                    "build",
                    "--release",
                    "-p",
                    "nodeset-examples",
                    "--example",
                    "import_bench",
                ],
            )
            .and_then(|_| {
                let exe = bench_target
                    .join("release/examples")
                    .join(format!("import_bench{}", env::consts::EXE_SUFFIX));
                let (r, y) = yardsticks.around("the import", || {
                    eprintln!("rust: import ({} run(s)) ...", args.runs_import.max(1));
                    run_report(
                        Command::new(&exe)
                            .arg("--runs")
                            .arg(args.runs_import.max(1).to_string()),
                    )
                });
                yard_import = y;
                import_rounds_result = import_rounds(&yardsticks, &exe);
                r
            });
            release = if args.no_release {
                Err("skipped (--no-release)".into())
            } else {
                eprintln!("rust: building {CRATE} (release) ...");
                time_builds(
                    &bench,
                    root,
                    &bench_target,
                    CRATE,
                    true,
                    Some(&touched),
                    RELEASE_RUNS,
                )
            };
        }

        // 5. The peer.
        let peer =
            (!args.no_peer).then(|| run_peer(args, root, tree, &vendor, &bench_target, &bench));

        // 6. The ratio that the target is judged by, taken where the host is the same for both sides: the
        // cold builds of the peer's crate, nodeset-models and the DI + IA + Robotics crate, one after the
        // other, round after round. The sections above time each crate's runs together, minutes apart
        // from the peer's, and this host's speed drifts by half within an hour.
        let interleaved = match (&peer, &debug, &three) {
            (Some(Peer { debug: Ok(_), .. }), Ok(_), Ok(_)) => {
                let rounds = args.runs_build.max(3);
                eprintln!("rust: {rounds} round(s) of cold debug builds, the peer's crate and ours back to back ...");
                let entries = [
                    (bench_target.join("peer"), PEER_CRATE),
                    (root.to_path_buf(), CRATE),
                    (bench_target.join("ours-cli"), THREE_CRATE),
                ];
                Some(interleave(&bench, &bench_target, &entries, rounds))
            }
            _ => None,
        };

        let results = Results {
            interleaved,
            gen,
            cli,
            disk,
            fresh,
            debug,
            release,
            runtime_only,
            three,
            runtime_size,
            import,
            peer,
            yard_gen,
            yard_import,
            import_rounds: import_rounds_result,
        };
        print(
            &results,
            args,
            root,
            start.elapsed().as_secs_f64(),
            (load_start, load_average()),
        );

        let ours: Vec<String> = [
            ("the CLI run", results.cli.as_ref().err()),
            ("counting generated/", results.disk.as_ref().err()),
            ("the debug builds", results.debug.as_ref().err()),
            ("the release builds", results.release.as_ref().err()),
            (
                "the runtime-only builds",
                results.runtime_only.as_ref().err(),
            ),
            ("the import bench", results.import.as_ref().err()),
        ]
        .into_iter()
        .filter_map(|(what, e)| {
            e.filter(|e| !e.starts_with("skipped"))
                .map(|e| format!("{what}: {e}"))
        })
        .collect();
        if ours.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "rust scenario: our own steps failed:\n{}",
                ours.join("\n")
            ))
        }
    }

    fn run_peer(
        args: &Args,
        root: &Path,
        tree: &Path,
        vendor: &Path,
        target: &Path,
        bench: &Path,
    ) -> Peer {
        let mut peer = Peer {
            exe: Err(String::new()),
            install_s: None,
            config: None,
            gen: Err("not run".into()),
            sizes: Err("not run".into()),
            debug: Err("not run".into()),
            release: Err("skipped (--no-release)".into()),
        };
        let (exe, install_s) = ensure_peer(root);
        peer.exe = exe;
        peer.install_s = install_s;
        let Ok(exe) = peer.exe.clone() else {
            return peer;
        };

        // The config: a types and a nodes target per namespace, in a crate folder of our own.
        let dir = target.join("peer");
        let schemas: Vec<PathBuf> = std::iter::once(NS0_XSD)
            .chain(NAMESPACES.iter().map(|n| n.3))
            .map(|x| tree.join(x))
            .collect();
        if let Some(missing) = schemas.iter().find(|p| !p.is_file()) {
            peer.gen = Err(format!(
                "impractical here: its nodes target needs the XML schemas (.xsd) of ns0 and of each model, and {} \
                 is missing (give the UA-Nodeset tree with --tree DIR)",
                missing.display()
            ));
            return peer;
        }
        let config = dir.join("codegen.yml");
        if let Err(e) = write_peer_crate(root, &dir, vendor, &schemas) {
            peer.gen = Err(e);
            return peer;
        }
        peer.config = Some(config.clone());

        eprintln!("rust: {PEER} ({} run(s)) ...", args.runs_process.max(1));
        peer.gen = exec(
            bench,
            args.runs_process,
            &dir,
            &[("RUST_LOG", "warn")],
            &exe,
            &[config.display().to_string()],
        );
        if peer.gen.is_err() {
            return peer;
        }
        peer.sizes = NAMESPACES
            .iter()
            .map(|n| Ok((n.0, count_rs(&dir.join("src").join(n.0))?)))
            .collect();

        if args.no_builds {
            peer.debug = Err("skipped (--no-builds)".into());
            peer.release = Err("skipped (--no-builds)".into());
            return peer;
        }
        let touched = dir.join(PEER_TOUCHED);
        eprintln!("rust: building the {PEER} output (debug) ...");
        peer.debug = time_builds(
            bench,
            &dir,
            target,
            PEER_CRATE,
            false,
            Some(&touched),
            args.runs_build,
        );
        if !args.no_release {
            eprintln!("rust: building the {PEER} output (release) ...");
            peer.release = time_builds(
                bench,
                &dir,
                target,
                PEER_CRATE,
                true,
                Some(&touched),
                RELEASE_RUNS,
            );
        }
        peer
    }

    /// async-opcua-codegen's executable in `target/bench-tools`, installed there first if it is missing, and
    /// how long the installation took.
    fn ensure_peer(root: &Path) -> (Step<PathBuf>, Option<f64>) {
        let tools = root.join("target/bench-tools");
        let exe = tools
            .join("bin")
            .join(format!("{PEER}{}", env::consts::EXE_SUFFIX));
        let installed = fs::read_to_string(tools.join(".crates.toml"))
            .is_ok_and(|t| t.contains(&format!("{PEER} {PEER_VERSION} ")));
        if !(exe.is_file() && installed) {
            eprintln!(
                "rust: installing {PEER} {PEER_VERSION} into {} (once) ...",
                display_path(&tools)
            );
            let tools_arg = tools.display().to_string();
            let t = Instant::now();
            let r = cargo(
                root,
                None,
                &[
                    "install",
                    PEER,
                    "--version",
                    PEER_VERSION,
                    "--locked",
                    "--root",
                    &tools_arg,
                ],
            );
            let installed = r.map(|_| exe);
            return (installed, Some(t.elapsed().as_secs_f64()));
        }
        (Ok(exe), None)
    }

    /// The peer as the issues measured it on this machine: its whole DI + Robotics run (the foundation issue)
    /// and the cold debug build of its generated crate (the Rust back-end issue). Their ratio to what the
    /// peer takes in the same run of this bench says how fast the shared host is right now.
    pub(super) const PEER_RUN_STATED_MS: f64 = 250.0;
    pub(super) const PEER_BUILD_STATED_S: f64 = 2.7;

    /// The peer's whole DI + Robotics run timed in this bench: the yardstick of the host's speed.
    pub(super) struct Yardstick {
        pub(super) median_ms: f64,
        pub(super) min_ms: f64,
        pub(super) runs: usize,
    }

    impl Yardstick {
        /// How much slower than when the issue measured the peer (> 1: slower).
        pub(super) fn slowdown(&self) -> f64 {
            self.median_ms / PEER_RUN_STATED_MS
        }
    }

    /// The peer's whole DI + Robotics run, ready to be timed: `rust_bench` as the stopwatch, the peer and its
    /// config for DI + Robotics (types and nodes of both; ns0 and IA, which Robotics 1.02 requires, loaded
    /// as dependencies) in `target/bench-build/peer-di-robotics`.
    struct PeerRun {
        bench: PathBuf,
        exe: PathBuf,
        dir: PathBuf,
        config: String,
    }

    /// Takes the yardstick around measured work; holds nothing with `--no-peer`, or why the peer cannot run.
    pub(super) struct Yardsticks {
        peer: Option<Step<PeerRun>>,
        runs: usize,
    }

    impl Yardsticks {
        /// Installs the peer once if needed and writes its config (unless `args.no_peer`).
        pub(super) fn new(args: &Args, root: &Path, tree: &Path) -> Yardsticks {
            let peer = (!args.no_peer).then(|| PeerRun::prepare(root, tree));
            Yardsticks {
                peer,
                runs: args.runs_process,
            }
        }

        /// Runs `work` between two timings of the peer (`what` names the work in the progress lines); the
        /// yardstick is None with `--no-peer`.
        pub(super) fn around<T>(
            &self,
            what: &str,
            work: impl FnOnce() -> T,
        ) -> (T, Option<Step<Yardstick>>) {
            let time = |when: &str| {
                self.peer.as_ref().map(|peer| {
                    let peer = peer.as_ref().map_err(Clone::clone)?;
                    eprintln!("the peer's DI + Robotics run as a yardstick ({when} {what}) ...");
                    peer.time(self.runs)
                })
            };
            let before = time("before");
            let out = work();
            let after = time("after");
            (out, before.zip(after).map(|(b, a)| Ok(yardstick(&b?, &a?))))
        }
    }

    impl PeerRun {
        /// `runs` timed runs of the peer on DI + Robotics.
        fn time(&self, runs: usize) -> Step<Report> {
            exec(&self.bench, runs, &self.dir, &[("RUST_LOG", "warn")], &self.exe, std::slice::from_ref(&self.config))
        }

        fn prepare(root: &Path, tree: &Path) -> Step<PeerRun> {
            let (exe, _) = ensure_peer(root);
            let exe = exe?;
            let bench = build(root, "rust_bench", &["--bin", "nodeset-compiler"])?;
            let vendor = root.join("nodesets/vendor");
            let dir = root.join("target/bench-build/peer-di-robotics");
            let schemas: Vec<PathBuf> = std::iter::once(NS0_XSD)
                .chain(NAMESPACES.iter().map(|n| n.3))
                .map(|x| tree.join(x))
                .collect();
            if let Some(missing) = schemas.iter().find(|p| !p.is_file()) {
                return Err(format!(
                    "the peer needs the XML schemas of the UA-Nodeset tree and {} is missing (give the tree with --tree DIR)",
                    missing.display()
                ));
            }
            write_peer_config(
                &dir,
                &vendor,
                &schemas,
                &["di", "robotics"],
                "DI + Robotics",
            )?;
            let config = dir.join("codegen.yml").display().to_string();
            Ok(PeerRun {
                bench,
                exe,
                dir,
                config,
            })
        }
    }

    /// The yardstick from the peer's runs before and after the measured work.
    fn yardstick(before: &Report, after: &Report) -> Yardstick {
        let runs = |r: &Report| r.f("runs").max(0.0) as usize;
        let (a, b) = (runs(before), runs(after));
        Yardstick {
            median_ms: (before.f("wall_median_ms") * a as f64
                + after.f("wall_median_ms") * b as f64)
                / (a + b).max(1) as f64,
            min_ms: before.f("wall_min_ms").min(after.f("wall_min_ms")),
            runs: a + b,
        }
    }

    /// A target scaled by the host's slowdown, and the verdict against it.
    pub(super) fn scaled(value: f64, target: f64, slowdown: f64, unit: &str) -> String {
        let limit = target * slowdown;
        format!(
            "scaled target <= {limit:.2} {unit}  {}",
            verdict(value, limit)
        )
    }

    /// The profiles of the workspace's `Cargo.toml`, for crates built outside it in the same target folder, so
    /// that they share its dependencies' builds and are compiled the same way.
    const PROFILES: &str =
        "[profile.dev.package.\"*\"]\nopt-level = 2\n\n[profile.release]\ndebug = 1\n";

    /// Makes `dir` (which holds the CLI's `models/`) the crate [`THREE_CRATE`]: the generated modules on
    /// nodeset-runtime, re-exported as `crate::runtime` as the CLI was told.
    fn write_three_crate(root: &Path, dir: &Path) -> Step<()> {
        let write = |path: PathBuf, text: String| {
            fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
        };
        write(
            dir.join("Cargo.toml"),
            format!(
                "# Written by `cargo xtask bench --scenario rust`: the CLI's output for DI + IA + Robotics as a crate.\n\
                 [package]\nname = \"{THREE_CRATE}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
                 [lib]\npath = \"lib.rs\"\n\n[workspace]\n\n[features]\njson = [\"async-opcua/json\"]\nxml = [\"async-opcua/xml\"]\n\n\
                 [dependencies]\nnodeset-runtime = {{ path = {:?} }}\n\
                 async-opcua = {{ version = \"=0.19.0\", features = [\"server\", \"client\"] }}\nbitflags = \"2\"\n\n{PROFILES}",
                root.join("nodeset-runtime").display().to_string()
            ),
        )?;
        write(
            dir.join("lib.rs"),
            "//! The CLI's output for DI + IA + Robotics. Written by `cargo xtask bench`.\n#![allow(warnings)]\n\n\
             pub use nodeset_runtime as runtime;\npub mod models;\n"
                .into(),
        )?;
        let _ = fs::copy(root.join("Cargo.lock"), dir.join("Cargo.lock"));
        Ok(())
    }

    /// A YAML string (a JSON string is one).
    fn yaml(s: &str) -> String {
        let mut out = String::from("\"");
        for c in s.chars() {
            match c {
                '"' => out.push_str("\\\""),
                '\\' => out.push_str("\\\\"),
                c => out.push(c),
            }
        }
        out.push('"');
        out
    }

    /// Writes `dir/codegen.yml`: all four NodeSet2 files and the XML schemas as sources, and a `types` and a
    /// `nodes` target for each module of `targets` (the others are only loaded, as dependencies).
    fn write_peer_config(
        dir: &Path,
        vendor: &Path,
        schemas: &[PathBuf],
        targets: &[&str],
        what: &str,
    ) -> Step<()> {
        let xsd_name = |p: &PathBuf| {
            p.file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default()
        };
        let mut cfg = format!(
            "# Written by `cargo xtask bench`: async-opcua-codegen on {what}.\n\
             # Paths are absolute; outputs are relative to this file.\nsources:\n"
        );
        cfg.push_str(&format!(
            "  - {}\n",
            yaml(&vendor.join("Opc.Ua.NodeSet2.xml").display().to_string())
        ));
        for n in NAMESPACES {
            cfg.push_str(&format!(
                "  - {}\n",
                yaml(&vendor.join(n.1).display().to_string())
            ));
        }
        for s in schemas {
            cfg.push_str(&format!("  - {}\n", yaml(&s.display().to_string())));
        }
        cfg.push_str("targets:\n");
        for (i, (module, file, _, _)) in NAMESPACES.iter().enumerate() {
            if !targets.contains(module) {
                continue;
            }
            cfg.push_str(&format!(
                "  - type: types\n    file: {file}\n    output_dir: src/{module}/types\n    node_ids_from_nodeset: true\n"
            ));
            if i > 0 {
                cfg.push_str("    dependent_nodesets:\n");
                for (dep, dep_file, _, _) in &NAMESPACES[..i] {
                    cfg.push_str(&format!(
                        "      - file: {dep_file}\n        import_path: crate::{dep}::types\n"
                    ));
                }
            }
            let name = format!("{}{}Namespace", module[..1].to_uppercase(), &module[1..]);
            cfg.push_str(&format!(
                "  - type: nodes\n    file: {file}\n    output_dir: src/{module}/nodes\n    max_nodes_per_file: 100\n    \
                 name: {name}\n    types:\n      - file: {}\n        root_path: opcua::types\n      - file: {}\n        \
                 root_path: crate::{module}::types\n",
                xsd_name(&schemas[0]),
                xsd_name(&schemas[i + 1]),
            ));
        }
        let path = dir.join("codegen.yml");
        fs::create_dir_all(dir)
            .and_then(|()| fs::write(&path, cfg))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))
    }

    /// Writes the codegen config, `Cargo.toml` and `src/lib.rs` of the peer's crate.
    fn write_peer_crate(root: &Path, dir: &Path, vendor: &Path, schemas: &[PathBuf]) -> Step<()> {
        let write = |path: PathBuf, text: String| {
            fs::create_dir_all(path.parent().unwrap_or(dir))
                .and_then(|()| fs::write(&path, text))
                .map_err(|e| format!("cannot write {}: {e}", path.display()))
        };
        write_peer_config(
            dir,
            vendor,
            schemas,
            &["di", "ia", "robotics"],
            "the inputs of generated/",
        )?;
        write(
            dir.join("Cargo.toml"),
            format!(
                "# Written by `cargo xtask bench --scenario rust`: a crate around async-opcua-codegen's output.\n\
                 [package]\nname = \"{PEER_CRATE}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
                 [workspace]\n\n[features]\njson = [\"async-opcua/json\"]\nxml = [\"async-opcua/xml\"]\n\n\
                 [dependencies]\nasync-opcua = {{ version = \"=0.19.0\", features = [\"server\"] }}\nbitflags = \"2\"\n\n\
                 # The workspace's profiles, so that dependencies are shared with nodeset-models in the same target folder.\n\
                 {PROFILES}"
            ),
        )?;
        let mut lib = String::from(
            "//! async-opcua-codegen's output for DI, IA and Robotics. Written by `cargo xtask bench`; only this file\n\
             //! is not generated.\n#![allow(warnings)]\n\n",
        );
        for n in NAMESPACES {
            lib.push_str(&format!(
                "pub mod {} {{\n    pub mod nodes;\n    pub mod types;\n}}\n",
                n.0
            ));
        }
        write(dir.join("src/lib.rs"), lib)?;
        // The workspace's lock file, so that the peer's crate builds against the same dependency versions.
        let _ = fs::copy(root.join("Cargo.lock"), dir.join("Cargo.lock"));
        Ok(())
    }

    /// Runs a measured program and parses its `BENCH` line; its stderr goes to ours.
    fn run_report(cmd: &mut Command) -> Step<Report> {
        let out = cmd
            .stderr(Stdio::inherit())
            .output()
            .map_err(|e| format!("cannot run {:?}: {e}", cmd.get_program()))?;
        if !out.status.success() {
            return Err(format!("{:?} failed ({})", cmd.get_program(), out.status));
        }
        parse_report(&String::from_utf8_lossy(&out.stdout))
            .ok_or_else(|| format!("{:?} printed no BENCH line", cmd.get_program()))
    }

    /// Runs `program args` `runs` times under `rust_bench exec` (wall time, peak RSS, CPU).
    fn exec(
        bench: &Path,
        runs: usize,
        dir: &Path,
        envs: &[(&str, &str)],
        program: &Path,
        args: &[String],
    ) -> Step<Report> {
        let mut cmd = Command::new(bench);
        cmd.arg("exec")
            .arg("--runs")
            .arg(runs.max(1).to_string())
            .arg("--dir")
            .arg(dir);
        for (k, v) in envs {
            cmd.arg("--env").arg(format!("{k}={v}"));
        }
        cmd.arg("--").arg(program).args(args);
        let out = cmd
            .stderr(Stdio::piped())
            .output()
            .map_err(|e| format!("cannot run {}: {e}", bench.display()))?;
        if !out.status.success() {
            return Err(format!(
                "{} failed: {}",
                program.display(),
                tail(&out.stderr, 12)
            ));
        }
        parse_report(&String::from_utf8_lossy(&out.stdout))
            .ok_or_else(|| "rust_bench exec printed no BENCH line".to_string())
    }

    fn tail(bytes: &[u8], n: usize) -> String {
        let text = String::from_utf8_lossy(bytes);
        let lines: Vec<&str> = text.lines().collect();
        lines[lines.len().saturating_sub(n)..].join("\n")
    }

    /// Runs cargo quietly in `dir` (with `target` as `CARGO_TARGET_DIR`) and returns its wall time in s.
    fn cargo(dir: &Path, target: Option<&Path>, args: &[&str]) -> Step<f64> {
        let cargo = env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let mut cmd = Command::new(cargo);
        cmd.current_dir(dir)
            .arg("--quiet")
            .args(args)
            .stdin(Stdio::null());
        if let Some(t) = target {
            cmd.env("CARGO_TARGET_DIR", t);
        }
        let t = Instant::now();
        let out = cmd.output().map_err(|e| format!("cannot run cargo: {e}"))?;
        let secs = t.elapsed().as_secs_f64();
        if out.status.success() {
            Ok(secs)
        } else {
            Err(format!(
                "`cargo {}` failed ({}):\n{}",
                args.join(" "),
                out.status,
                tail(&out.stderr, 20)
            ))
        }
    }

    /// Per round, for each (folder, package) in order: an untimed build, a clean of the package alone and a
    /// timed cold debug build.
    fn interleave(bench: &Path, target: &Path, entries: &[(PathBuf, &str); 3], rounds: usize) -> Step<Interleaved> {
        let mut got: [Vec<(f64, f64)>; 3] = Default::default();
        for _ in 0..rounds {
            for ((dir, package), times) in entries.iter().zip(got.iter_mut()) {
                // The three crates are in different workspaces sharing one target folder; building one can
                // leave a dependency of another stale (a first round measured 3.4x for that reason). An
                // untimed build first brings the dependencies up to date, so the timed build compiles the
                // package alone.
                cargo(dir, Some(target), &["build", "-p", package])?;
                cargo(dir, Some(target), &["clean", "-p", package])?;
                times.push(timed_build(bench, dir, target, &["build", "-p", package])?);
            }
        }
        let [peer, models, three] = got;
        Ok(Interleaved { peer, models, three })
    }

    /// One `cargo --quiet <args>` in `dir` with `target` as its target folder, under `rust_bench exec`, which
    /// also takes the CPU time of cargo and rustc: (wall s, CPU s).
    fn timed_build(bench: &Path, dir: &Path, target: &Path, args: &[&str]) -> Step<(f64, f64)> {
        let cargo_exe = PathBuf::from(env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
        let target_env = target.display().to_string();
        let mut timed_args = vec!["--quiet".to_string()];
        timed_args.extend(args.iter().map(|a| a.to_string()));
        let r = exec(bench, 1, dir, &[("CARGO_TARGET_DIR", &target_env)], &cargo_exe, &timed_args)?;
        Ok((r.f("wall_median_ms") / 1e3, r.f("cpu_per_run_ms") / 1e3))
    }

    /// Warm-up, no-op, then per run a clean of `package` alone, a timed (cold) build, and unless `touched`
    /// is None, a touch of it and a timed (incremental) build.
    ///
    /// The timed builds run under `rust_bench exec`, which also takes the CPU time of cargo and rustc.
    fn time_builds(
        bench: &Path,
        dir: &Path,
        target: &Path,
        package: &str,
        release: bool,
        touched: Option<&Path>,
        runs: usize,
    ) -> Step<Builds> {
        let mut build_args = vec!["build", "-p", package];
        let mut clean_args = vec!["clean", "-p", package];
        if release {
            build_args.push("--release");
            clean_args.push("--release");
        }
        let timed = || timed_build(bench, dir, target, &build_args);
        let warm = cargo(dir, Some(target), &build_args)?;
        let (mut noop, mut cold, mut incr) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..runs.max(1) {
            noop.push(timed()?);
            cargo(dir, Some(target), &clean_args)?;
            cold.push(timed()?);
            if let Some(touched) = touched {
                touch(touched)?;
                incr.push(timed()?);
            }
        }
        Ok(Builds {
            warm,
            noop: Times::of(&noop),
            cold: Times::of(&cold),
            incr: touched.map(|_| Times::of(&incr)),
        })
    }

    /// Sets the modification time of `path` to now, without changing its content.
    fn touch(path: &Path) -> Step<()> {
        fs::File::options()
            .append(true)
            .open(path)
            .and_then(|f| f.set_modified(SystemTime::now()))
            .map_err(|e| format!("cannot touch {}: {e}", path.display()))
    }

    /// Files, lines and bytes of the `.rs` files under `dir`.
    fn count_rs(dir: &Path) -> Step<Size> {
        let mut size = Size::default();
        let entries =
            fs::read_dir(dir).map_err(|e| format!("cannot read {}: {e}", dir.display()))?;
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                size = size + count_rs(&p)?;
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = fs::read_to_string(&p)
                    .map_err(|e| format!("cannot read {}: {e}", p.display()))?;
                size = size
                    + Size {
                        files: 1,
                        lines: text.lines().count(),
                        bytes: text.len(),
                    };
            }
        }
        Ok(size)
    }

    fn mib(kib: f64) -> f64 {
        kib / 1024.0
    }

    /// `ours / theirs` as a factor, or `-` where either is missing.
    fn ratio(ours: f64, theirs: f64) -> String {
        if ours.is_finite() && theirs.is_finite() && theirs > 0.0 {
            format!("{:.2}x", ours / theirs)
        } else {
            "-".into()
        }
    }

    fn print_builds(label: &str, b: &Step<Builds>, target: Option<f64>) {
        match b {
            Ok(b) => {
                let judged = target
                    .map(|t| format!("   target <= {t} s  {}", verdict(b.cold.median, t)))
                    .unwrap_or_default();
                let incr = b.incr.map_or_else(
                    || format!("{:<49}", "   incremental        -"),
                    |i| {
                        format!(
                            "   incremental {:>6.2} s (min {:>6.2}, CPU {:>6.2})",
                            i.median, i.min, i.cpu
                        )
                    },
                );
                println!(
                    "   {label:<16} cold {:>6.2} s (min {:>6.2}, CPU {:>6.2}){incr}   no-op {:>5.2} s   warm-up {:>6.1} s{judged}",
                    b.cold.median, b.cold.min, b.cold.cpu, b.noop.median, b.warm
                );
            }
            Err(e) => println!(
                "   {label:<16} {}",
                e.replace('\n', "\n                    ")
            ),
        }
    }

    /// The 1-minute load average (`/proc/loadavg`), NaN where unknown.
    pub(super) fn load_average() -> f64 {
        fs::read_to_string("/proc/loadavg")
            .ok()
            .and_then(|s| s.split_whitespace().next()?.parse().ok())
            .unwrap_or(f64::NAN)
    }

    fn print(r: &Results, args: &Args, root: &Path, total_s: f64, load: (f64, f64)) {
        let g = &r.gen;
        println!();
        println!(
            "Rust back end: DI + IA + Robotics from nodesets/vendor (ns0 as their dependency)."
        );
        println!(
            "Times are wall clock; this machine has {} CPU(s) and may be running other builds, so CPU times are given \
             where they can be taken, and min is the figure least disturbed by other work.",
            std::thread::available_parallelism().map_or(0, |n| n.get())
        );
        println!(
            "Load average (1 min) at the start {:.1}, at the end {:.1}: above the CPU count, other work shares the CPUs \
             and wall times grow.",
            load.0, load.1
        );

        println!();
        println!(
            "== rust: generation, release build, in process without writing (as `cargo xtask generate` minus writing), {} run(s)",
            g.s("runs")
        );
        for (label, key, cpu) in [
            ("compile", "compile", Some("compile_cpu_median_ms")),
            ("emit", "emit", Some("emit_cpu_median_ms")),
            ("sum", "total", None),
        ] {
            let median = g.f(&format!("{key}_median_ms"));
            let cpu = cpu
                .map(|k| format!("   CPU (all threads) median {:>8.2} ms", g.f(k)))
                .unwrap_or_default();
            let judged = if key == "emit" {
                format!("   target <= {EMIT_MS} ms  {}", verdict(median, EMIT_MS))
            } else {
                String::new()
            };
            println!(
                "   {label:<8} median {median:>8.2} ms   min {:>8.2} ms   max {:>8.2} ms{cpu}{judged}",
                g.f(&format!("{key}_min_ms")),
                g.f(&format!("{key}_max_ms")),
            );
            if key == "emit" {
                print_yardstick(r.yard_gen.as_ref(), median, EMIT_MS, "ms");
            }
        }
        println!(
            "   memory   VmHWM after first run {:>6.1} MiB   after all runs {:>6.1} MiB   at start {:>5.1} MiB",
            mib(g.f("hwm_kib")),
            mib(g.f("hwm_all_runs_kib")),
            mib(g.f("hwm_start_kib"))
        );
        println!(
            "   model    {} nodes; compile {} error(s) {} warning(s); emit {} error(s) {} warning(s); {} files",
            g.s("nodes"),
            g.s("compile_errors"),
            g.s("compile_warnings"),
            g.s("emit_errors"),
            g.s("emit_warnings"),
            g.s("files")
        );
        match &r.cli {
            Ok(c) => println!(
                "   CLI      `nodeset-compiler rust` as a process (start, read, compile, emit, write changed files), {} run(s): \
                 median {:.1} ms   min {:.1} ms   CPU/run {:.1} ms   max RSS {:.1} MiB",
                c.s("runs"),
                c.f("wall_median_ms"),
                c.f("wall_min_ms"),
                c.f("cpu_per_run_ms"),
                mib(c.f("maxrss_kib"))
            ),
            Err(e) => println!("   CLI      failed: {e}"),
        }

        println!();
        println!("== rust: generated Rust (generated/src/models/<module>/*.rs as checked in)");
        match &r.disk {
            Ok(d) => {
                println!(
                    "   {:<22} {:>5} {:>8} {:>10}",
                    "module", "files", "lines", "bytes"
                );
                for (m, s) in d {
                    println!("   {m:<22} {:>5} {:>8} {:>10}", s.files, s.lines, s.bytes);
                }
                let dr = sum(d, &["di", "robotics"]);
                let all = sum(d, &["di", "ia", "robotics"]);
                println!(
                    "   {:<22} {:>5} {:>8} {:>10}   target <= {LINES_DI_ROBOTICS} lines  {}",
                    "DI + Robotics",
                    dr.files,
                    dr.lines,
                    dr.bytes,
                    verdict(dr.lines as f64, LINES_DI_ROBOTICS as f64)
                );
                println!(
                    "   {:<22} {:>5} {:>8} {:>10}",
                    "DI + IA + Robotics", all.files, all.lines, all.bytes
                );
                println!(
                    "   (a node table row is one line, so bytes say more than lines; average line {:.0} bytes)",
                    all.bytes as f64 / all.lines.max(1) as f64
                );
                match r.fresh {
                    Some(true) => println!("   this run's output has the same lines and bytes as the checked-in files"),
                    _ => println!(
                        "   NOTE: this run's output differs from the checked-in files (generated/ is stale or being \
                         regenerated; run `cargo xtask generate`)"
                    ),
                }
            }
            Err(e) => println!("   failed: {e}"),
        }

        println!();
        println!(
            "== rust: build of {CRATE} alone (dependencies prebuilt; CARGO_TARGET_DIR=target/bench-build), debug {} run(s), \
             release {RELEASE_RUNS}; incremental = after touching {}",
            args.runs_build.max(1),
            TOUCHED.trim_start_matches("generated/src/")
        );
        print_builds("debug", &r.debug, Some(CRATE_BUILD_S));
        if let (Ok(ours), Some(Ok(peer))) = (&r.debug, r.peer.as_ref().map(|p| &p.debug)) {
            let slowdown = peer.cold.median / PEER_BUILD_STATED_S;
            println!(
                "   {:<16} the peer's crate builds cold in {:.2} s here; the issue measured {PEER_BUILD_STATED_S} s, so the \
                 host builds {slowdown:.2}x as slow now: {}",
                "",
                peer.cold.median,
                scaled(ours.cold.median, CRATE_BUILD_S, slowdown, "s")
            );
        }
        print_builds("release", &r.release, None);
        print_builds(RUNTIME_CRATE, &r.runtime_only, None);
        print_builds("DI + IA + Robotics", &r.three, None);
        if let Some(Ok(peer)) = r.peer.as_ref().map(|p| &p.debug) {
            // The target as a ratio to the peer (1.5 s against its 2.7 s), judged for each of our crates.
            // For nodeset-models this is the scaled target above said another way; for the CLI's DI + IA +
            // Robotics it is the comparison on the peer's own inputs. (The "N x as slow" above overstates the
            // host's slowdown: this peer crate has IA too, about a quarter more lines than the DI + Robotics
            // crate the issue timed at 2.7 s. The ratio on the same inputs does not depend on that.)
            let limit = CRATE_BUILD_S / PEER_BUILD_STATED_S;
            println!(
                "   {:<16} the target as a ratio, {CRATE_BUILD_S} s / {PEER_BUILD_STATED_S} s = {limit:.3}x the peer's cold build:",
                "ratio target"
            );
            for (label, ours) in [("DI + IA + Robotics", &r.three), (CRATE, &r.debug)] {
                if let Ok(ours) = ours {
                    let x = ours.cold.median / peer.cold.median;
                    println!(
                        "   {:<16}   {label:<20} {x:.3}x (min/min {:.3}x, CPU {:.3}x)  {}{}",
                        "",
                        ours.cold.min / peer.cold.min,
                        ours.cold.cpu / peer.cold.cpu,
                        verdict(x, limit),
                        if label == CRATE { "   (six namespaces, the peer's three)" } else { "   (the peer's inputs)" }
                    );
                }
            }
        }
        match &r.interleaved {
            Some(Ok(i)) => {
                let limit = CRATE_BUILD_S / PEER_BUILD_STATED_S;
                println!(
                    "   {:<16} {} round(s) of cold debug builds back to back (peer, nodeset-models, DI + IA + Robotics); \
                     the peer took {} s; ratio per round, median:",
                    "interleaved",
                    i.peer.len(),
                    i.peer.iter().map(|t| format!("{:.2}", t.0)).collect::<Vec<_>>().join(" ")
                );
                for (label, ours) in [("DI + IA + Robotics", &i.three), (CRATE, &i.models)] {
                    let wall: Vec<f64> = ours.iter().zip(&i.peer).map(|(o, p)| o.0 / p.0).collect();
                    let cpu: Vec<f64> = ours.iter().zip(&i.peer).map(|(o, p)| o.1 / p.1).collect();
                    let x = median(&wall);
                    println!(
                        "   {:<16}   {label:<20} {x:.3}x (rounds {}; CPU {:.3}x)  {}",
                        "",
                        wall.iter().map(|w| format!("{w:.3}")).collect::<Vec<_>>().join(" "),
                        median(&cpu),
                        verdict(x, limit)
                    );
                }
            }
            Some(Err(e)) => println!("   {:<16} the interleaved builds failed: {e}", "interleaved"),
            None => {}
        }
        if let (Ok(all), Ok(rt), Ok(rt_size), Ok(disk)) =
            (&r.debug, &r.runtime_only, &r.runtime_size, &r.disk)
        {
            let models = sum(disk, &["di", "ia", "robotics"]);
            println!(
                "   {:<16} {:>6.2} s, CPU {:.2} s (debug cold, medians): {CRATE} ({} generated lines of DI + IA + \
                 Robotics, {} in all) and the {RUNTIME_CRATE} it depends on ({} hand-written lines), both from clean",
                "both",
                all.cold.median + rt.cold.median,
                all.cold.cpu + rt.cold.cpu,
                models.lines,
                count_rs(&root.join("generated/src")).map_or(0, |s| s.lines),
                rt_size.lines
            );
        }
        println!(
            "   (wall time of `cargo build`, including cargo's own start-up and checks, which the no-op build shows; \
             CPU = median CPU time of cargo and rustc (user + system; rustc may use more than one thread); \
             the release profile compiles without incremental, so there incremental is about cold)"
        );

        println!();
        match &r.import {
            Ok(i) => {
                println!(
                    "== rust: import of the DI, IA and Robotics tables into an async-opcua AddressSpace (release), {} run(s)",
                    i.s("runs")
                );
                let median = i.f("import_median_ms");
                println!(
                    "   import   median {median:>8.3} ms   min {:>8.3} ms   max {:>8.3} ms   CPU median {:>8.3} ms   \
                     target <= {IMPORT_MS} ms  {}",
                    i.f("import_min_ms"),
                    i.f("import_max_ms"),
                    i.f("import_cpu_median_ms"),
                    verdict(median, IMPORT_MS)
                );
                print_yardstick(r.yard_import.as_ref(), median, IMPORT_MS, "ms");
                match &r.import_rounds {
                    Some(Ok(rounds)) => {
                        // The verdict. A 2 ms import runs at half speed on this host for stretches of tens of
                        // runs, and for minutes at a time at other moments; the peer's 0.65 s run averages
                        // short stretches out. Sampled in alternation over the same stretch of time, both see
                        // the same host.
                        let ratios: Vec<f64> = rounds
                            .import_ms
                            .iter()
                            .zip(&rounds.peer_ms)
                            .map(|(i, p)| i / (IMPORT_MS * p / PEER_RUN_STATED_MS))
                            .collect();
                        let (import, peer) = (self::median(&rounds.import_ms), self::median(&rounds.peer_ms));
                        let shown: Vec<String> = ratios.iter().map(|x| format!("{x:.2}")).collect();
                        let verdict_ratio = self::median(&ratios);
                        println!(
                            "   verdict  {} rounds of [the peer's run, {IMPORT_ROUND_RUNS} imports], alternating; import / scaled target \
                             per round: {}; median {verdict_ratio:.2}  {}",
                            ratios.len(),
                            shown.join(" "),
                            verdict(verdict_ratio, 1.0)
                        );
                        println!(
                            "            (medians over the rounds: import {import:.3} ms, the peer's run {peer:.1} ms, host {:.2}x as \
                             slow; the figures above were taken minutes apart, these in the same stretch of time)",
                            peer / PEER_RUN_STATED_MS
                        );
                    }
                    Some(Err(e)) => println!("   verdict  (the alternating rounds failed: {e})"),
                    None => {}
                }
                println!(
                    "   decode   {:.3} ms once per process (the tables' packed text into rows, on first use; not in \
                     the median); a process's first import, decode included: {:.3} ms",
                    i.f("decode_ms"),
                    i.f("first_import_ms")
                );
                println!(
                    "   types    load_into_type_tree afterwards: median {:.3} ms   min {:.3} ms (not in the import figure)",
                    i.f("type_tree_median_ms"),
                    i.f("type_tree_min_ms")
                );
                println!(
                    "   rows     {} in the tables, {} in the address space after the import; ns0 excluded (async-opcua's \
                     core node manager serves it from its own address space)",
                    i.s("rows"),
                    i.s("imported")
                );
                let rows = i.f("rows");
                println!(
                    "   ns0      for scale: async-opcua's CoreNamespace (codegen output, a function per node), {} nodes, \
                     imported once in {:.2} ms = {:.2} us/node; ours {:.2} us/node",
                    i.s("ns0_nodes"),
                    i.f("ns0_import_ms"),
                    1e3 * i.f("ns0_import_ms") / i.f("ns0_nodes"),
                    1e3 * median / rows
                );
            }
            Err(e) => {
                println!("== rust: import into an async-opcua AddressSpace (release)");
                println!("   {e}");
            }
        }

        if let Some(p) = &r.peer {
            print_peer(r, p);
        }
        println!();
        println!("rust scenario: {total_s:.1} s in all");
        println!();
    }

    /// The line under a timed figure that scales its target by the yardstick.
    fn print_yardstick(yard: Option<&Step<Yardstick>>, value: f64, target: f64, unit: &str) {
        match yard {
            Some(Ok(y)) => println!(
                "            the peer's whole DI + Robotics run took {:.1} ms around this (median of {} runs; the issue \
                 measured {PEER_RUN_STATED_MS} ms): host {:.2}x as slow, {}",
                y.median_ms,
                y.runs,
                y.slowdown(),
                scaled(value, target, y.slowdown(), unit)
            ),
            Some(Err(e)) => println!("            (target not scaled: the peer's run failed: {e})"),
            None => {}
        }
    }

    fn print_peer(r: &Results, p: &Peer) {
        println!();
        println!("== rust: {PEER} {PEER_VERSION} on the same inputs");
        let exe = match &p.exe {
            Ok(exe) => exe,
            Err(e) => {
                println!("   not available: {e}");
                return;
            }
        };
        if let Some(s) = p.install_s {
            println!("   installed into {} in {s:.0} s (once)", display_path(exe));
        }
        if let Some(c) = &p.config {
            println!(
                "   config   {} (types + nodes target per namespace, max_nodes_per_file 100, RUST_LOG=warn)",
                display_path(c)
            );
        }
        let gen = match &p.gen {
            Ok(gen) => gen,
            Err(e) => {
                println!("   generation: {}", e.replace('\n', "\n      "));
                return;
            }
        };
        println!(
            "   generate process (start, read, generate, write everything), {} run(s): median {:.1} ms   min {:.1} ms   \
             CPU/run {:.1} ms   max RSS {:.1} MiB",
            gen.s("runs"),
            gen.f("wall_median_ms"),
            gen.f("wall_min_ms"),
            gen.f("cpu_per_run_ms"),
            mib(gen.f("maxrss_kib"))
        );
        match &p.sizes {
            Ok(s) => {
                for (m, z) in s {
                    println!("   {m:<22} {:>5} {:>8} {:>10}", z.files, z.lines, z.bytes);
                }
            }
            Err(e) => println!("   lines: {e}"),
        }
        print_builds("debug", &p.debug, None);
        print_builds("release", &p.release, None);

        println!("   ratios ours / theirs (below 1 = ours smaller or faster):");
        if let Ok(c) = &r.cli {
            println!(
                "     generation process wall (median)     {:>8}   min {:>8}   CPU/run {:>8}   max RSS {:>8}",
                ratio(c.f("wall_median_ms"), gen.f("wall_median_ms")),
                ratio(c.f("wall_min_ms"), gen.f("wall_min_ms")),
                ratio(c.f("cpu_per_run_ms"), gen.f("cpu_per_run_ms")),
                ratio(c.f("maxrss_kib"), gen.f("maxrss_kib"))
            );
        }
        if let (Ok(ours), Ok(theirs)) = (&r.disk, &p.sizes) {
            for (label, mods) in [
                ("DI + Robotics", &["di", "robotics"][..]),
                ("DI + IA + Robotics", &["di", "ia", "robotics"][..]),
            ] {
                let (a, b) = (sum(ours, mods), sum(theirs, mods));
                println!(
                    "     {label:<20} lines {:>8}   bytes {:>8}   ({} vs {} lines)",
                    ratio(a.lines as f64, b.lines as f64),
                    ratio(a.bytes as f64, b.bytes as f64),
                    a.lines,
                    b.lines
                );
            }
        }
        for (label, ours, theirs) in [
            ("debug", &r.debug, &p.debug),
            ("release", &r.release, &p.release),
        ] {
            if let (Ok(a), Ok(b)) = (ours, theirs) {
                let (ai, bi) = (a.incr.unwrap_or(Times::NONE), b.incr.unwrap_or(Times::NONE));
                println!(
                    "     {label:<7} crate build: cold {:>6} (min {:>6}, CPU {:>6})   incremental {:>6} (min {:>6}, CPU {:>6})   \
                     ({:.2} s vs {:.2} s cold)",
                    ratio(a.cold.median, b.cold.median),
                    ratio(a.cold.min, b.cold.min),
                    ratio(a.cold.cpu, b.cold.cpu),
                    ratio(ai.median, bi.median),
                    ratio(ai.min, bi.min),
                    ratio(ai.cpu, bi.cpu),
                    a.cold.median,
                    b.cold.median
                );
            }
        }
        if let (Ok(a), Ok(b)) = (&r.three, &p.debug) {
            println!(
                "     debug   same ground: the CLI's DI + IA + Robotics alone vs their crate, cold: {} (CPU {})   \
                 incremental {}   ({:.2} s vs {:.2} s cold)",
                ratio(a.cold.median, b.cold.median),
                ratio(a.cold.cpu, b.cold.cpu),
                ratio(a.incr.map_or(f64::NAN, |i| i.median), b.incr.map_or(f64::NAN, |i| i.median)),
                a.cold.median,
                b.cold.median
            );
        }
        if let (Ok(a), Ok(rt), Ok(b)) = (&r.debug, &r.runtime_only, &p.debug) {
            println!(
                "     debug   {CRATE} and {RUNTIME_CRATE} together vs their crate, cold: {} (CPU {})   \
                 ({:.2} s vs {:.2} s)",
                ratio(a.cold.median + rt.cold.median, b.cold.median),
                ratio(a.cold.cpu + rt.cold.cpu, b.cold.cpu),
                a.cold.median + rt.cold.median,
                b.cold.median
            );
        }
        println!(
            "   (the two outputs do not cover the same ground: async-opcua-codegen emits one function per node and skips \
             union types; ours is node tables plus the runtime's API; compare features as well as sizes)"
        );
    }
}
