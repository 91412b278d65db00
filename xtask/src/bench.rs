//! `cargo xtask bench`: times the foundation stage of the compiler (parse + load + resolve) on real
//! NodeSet2 files and compares it with the project's targets.
//!
//! The measured program is the example `nodeset-compiler/examples/load_bench.rs`. This task builds it in
//! release mode, runs every scenario in its own process (so that the peak resident memory, `VmHWM`, belongs
//! to that scenario alone), reads the `BENCH key=value ...` line it prints and shows a table. It is a
//! report, not a test: a missed target prints `OVER` but the task still succeeds.
//!
//! Scenarios:
//!
//! * `robotics`: ns0 + DI + IA + Robotics from `nodesets/vendor/` (fetched first if missing).
//! * `tree`: every NodeSet2 file of the `UA-Nodeset` tree at `../shared/nodesets/ua-nodeset`, one compile
//!   per file with its required models taken from the tree.
//! * `sets`: the same tree as a few compiles of many files each (every file named once, no ModelUri twice in
//!   one compile: the newest versions together, then the older ones), required models from the tree.

use std::collections::BTreeMap;
use std::env;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::util::{display_path, workspace_root};

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
/// (both ways of compiling it).
const ROBOTICS_TIME_MS: f64 = 15.0;
const ROBOTICS_MEM_MIB: f64 = 40.0;
const TREE_TIME_MS: f64 = 1000.0;

/// Arguments of `cargo xtask bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which scenario(s) to run.
    #[arg(long, value_parser = ["all", "robotics", "tree", "sets"], default_value = "all")]
    scenario: String,

    /// Runs of the robotics scenario (ns0 + DI + IA + Robotics).
    #[arg(long, value_name = "N", default_value_t = 20)]
    runs_robotics: usize,

    /// Runs of the tree and sets scenarios (one run = one pass over the tree).
    #[arg(long, value_name = "N", default_value_t = 3)]
    runs_tree: usize,

    /// The NodeSet tree of the tree and sets scenarios (default: ../shared/nodesets/ua-nodeset from the workspace root).
    #[arg(long, value_name = "DIR")]
    tree: Option<PathBuf>,

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

    if want("robotics") {
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

    let exe = build(&root)?;
    let mut reports = Vec::new();
    if want("robotics") {
        reports.push(measure(
            &exe,
            "robotics",
            args.runs_robotics,
            &[],
            args.no_split,
        )?);
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
    print_table(&reports, !args.no_split);
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

/// Builds the example in release mode and returns the path of its executable.
fn build(root: &Path) -> Result<PathBuf, String> {
    eprintln!("building the load_bench example (release) ...");
    let cargo = env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(root)
        .args([
            "build",
            "--quiet",
            "--release",
            "--example",
            "load_bench",
            "-p",
            "nodeset-compiler",
        ])
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building the load_bench example failed ({status})"));
    }
    let target = env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let target = if target.is_absolute() {
        target
    } else {
        root.join(target)
    };
    let exe = target
        .join("release/examples")
        .join(format!("load_bench{}", env::consts::EXE_SUFFIX));
    if exe.is_file() {
        Ok(exe)
    } else {
        Err(format!(
            "built the example, but {} does not exist",
            exe.display()
        ))
    }
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
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("BENCH "))
        .ok_or_else(|| format!("scenario `{scenario}` printed no BENCH line"))?;
    let map = line
        .split_whitespace()
        .filter_map(|kv| kv.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    Ok(Report(map))
}

fn verdict(value: f64, limit: f64) -> &'static str {
    if value <= limit {
        "PASS"
    } else {
        "OVER"
    }
}

fn print_table(reports: &[Report], split: bool) {
    println!();
    println!("Foundation stage (parse + load + resolve), release build.");
    println!("time = wall clock of the `compile` calls of one run (dropping the results is not included);");
    println!("memory = VmHWM of a fresh process per scenario; targets are compared with the median and the first run's VmHWM.");
    for r in reports {
        println!();
        let scenario = r.s("scenario");
        let (title, time_limit) = match scenario {
            "robotics" => (
                "ns0 + DI + IA + Robotics (nodesets/vendor), one compile",
                ROBOTICS_TIME_MS,
            ),
            "sets" => (
                "UA-Nodeset tree, a few compiles naming every file once (models from the tree), one pass",
                TREE_TIME_MS,
            ),
            _ => (
                "UA-Nodeset tree, one compile per file (models from the tree), one pass",
                TREE_TIME_MS,
            ),
        };
        let total = r.f("total_median_ms");
        println!("== {scenario}: {title}");
        println!(
            "   runs {:>6}   compiles per run {}",
            r.s("runs"),
            r.s("compiles")
        );
        println!(
            "   time     median {:>10.2} ms   min {:>10.2} ms   max {:>10.2} ms   target <= {time_limit} ms  {}",
            total,
            r.f("total_min_ms"),
            r.f("total_max_ms"),
            verdict(total, time_limit)
        );
        println!(
            "   CPU      median {:>10.2} ms   min {:>10.2} ms   (this thread's CPU time; wall time above also counts waiting for a busy CPU)",
            r.f("cpu_median_ms"),
            r.f("cpu_min_ms")
        );
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
