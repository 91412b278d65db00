//! The foundation scenarios (`robotics`, `tree`, `sets`): parse + load + resolve, timed by
//! `nodeset-compiler/examples/load_bench.rs` in a fresh process per scenario, and their table.

use std::path::Path;
use std::process::Command;

use bench_support::Report;

use super::peer::{self, Yardstick, Yardsticks};
use super::{build, run_report, verdict, Args};

/// Targets: wall time of one compile of ns0 + DI + IA + Robotics, its peak memory, one pass over the tree
/// (judged on `sets`, which reads every file of the tree once).
const ROBOTICS_TIME_MS: f64 = 15.0;
const ROBOTICS_MEM_MIB: f64 = 40.0;
const TREE_TIME_MS: f64 = 1000.0;

/// Runs `robotics` (if `robotics`) and the tree `scenarios` (over `tree`), each in a fresh process, then
/// prints their table. The robotics run is taken between two timings of the peer, the yardstick of the
/// host's speed.
pub(super) fn run<'a>(
    args: &Args,
    root: &Path,
    tree: &Path,
    robotics: bool,
    scenarios: impl Iterator<Item = &'a str>,
) -> Result<(), String> {
    let exe = build(root, "nodeset-compiler", "load_bench", &[])?;
    let mut reports = Vec::new();
    let mut yard = None;
    if robotics {
        let (report, y) = Yardsticks::new(args, root, tree).around("ours", || {
            measure(&exe, "robotics", args.runs_robotics, &[], args.no_split)
        });
        reports.push(report?);
        yard = y;
    }
    let tree_arg = ["--tree".to_string(), tree.display().to_string()];
    for scenario in scenarios {
        reports.push(measure(&exe, scenario, args.runs_tree, &tree_arg, args.no_split)?);
    }
    print_table(&reports, !args.no_split, yard.as_ref());
    Ok(())
}

/// Runs one scenario of load_bench in a fresh process and parses its `BENCH` line.
fn measure(exe: &Path, scenario: &str, runs: usize, extra: &[String], no_split: bool) -> Result<Report, String> {
    eprintln!("running scenario `{scenario}` ({runs} run(s)) ...");
    let mut cmd = Command::new(exe);
    cmd.arg(scenario).arg("--runs").arg(runs.max(1).to_string()).args(extra);
    if no_split {
        cmd.arg("--no-split");
    }
    run_report(&mut cmd).map_err(|e| format!("scenario `{scenario}`: {e}"))
}

/// Prints the table of the foundation scenarios, each judged against its targets.
fn print_table(reports: &[Report], split: bool, yard: Option<&Result<Yardstick, String>>) {
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
            peer::print_judged(yard, total, ROBOTICS_TIME_MS);
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
