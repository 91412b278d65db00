//! The `rust` scenario: the Rust back end, end to end, next to async-opcua-codegen 0.19.
//!
//! How each figure is taken:
//!
//! 1. Generation: `nodeset-compiler/examples/rust_bench.rs generate` in a fresh process: what
//!    `cargo xtask generate` does minus writing (one `compile` of DI, IA and Robotics with ns0 found in
//!    `nodesets/vendor/` as their dependency, then `emit::rust::generate`), each stage timed in every run;
//!    `VmHWM` after the first run. The `nodeset-compiler rust` CLI is also timed as a whole process (start,
//!    read, compile, emit, write; it writes only changed files), which is what the peer's figure means.
//! 2. Lines: of `generated/src/models/<module>/*.rs` as checked in, compared with this run's output.
//! 3. Builds: `cargo build -p nodeset-models` in its own target folder (`target/bench-build`, so the
//!    developer's `target/` is not disturbed). Dependencies are built once first (the warm-up); then, per
//!    run, `cargo clean -p nodeset-models` and a timed build (cold, our crate alone), then
//!    `generated/src/models/robotics/types.rs` is touched and the build timed again (incremental). A no-op
//!    build shows cargo's own share of these wall times. Debug builds run `--runs-build` times, release
//!    builds once. The hand-written runtime is the crate `nodeset-runtime` (`nodeset-runtime/`), a
//!    dependency built once like async-opcua; its cold build is timed the same way, so that what a user
//!    compiles in all from a clean target is also shown. nodeset-models holds six namespaces; the CLI's
//!    output of step 1 (DI + IA + Robotics, the peer's inputs) is built the same way as the crate
//!    `nodeset-models-di-ia-robotics` on nodeset-runtime, the figure to set beside the peer's crate.
//! 4. Import: `nodeset-examples/examples/import_bench.rs` (release), which says what it includes.
//! 5. Peer: async-opcua-codegen 0.19.0, installed once into `target/bench-tools`, with a config written to
//!    `target/bench-build/peer/codegen.yml` (a `types` and a `nodes` target per namespace; the nodes target
//!    needs the XML schemas of ns0 and of each model, taken from the UA-Nodeset tree). Its output is built as
//!    the crate `codegen-peer-models` in the same target folder, with a `lib.rs` written here that only
//!    declares the generated modules. A failing peer step is reported in the table, never fatal.
//! 6. Interleaved: `--runs-build` rounds (at least 3) of cold debug builds of the peer's crate,
//!    nodeset-models and the DI + IA + Robotics crate, back to back. The crate-build target (0.556x the
//!    peer) is judged by the median of the per-round ratios: steps 3 and 5 time each crate's runs together,
//!    minutes apart, and this host's speed drifts too much for a ratio across them.

use std::env;
use std::fs;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

use bench_support::{median, Report};

use super::builds::{cargo, exec, interleave, print_builds, time_builds, Builds, Interleaved, Times, RELEASE_RUNS};
use super::size::{count_rs, sum, Size, Sizes};
use super::peer::{
    run_peer, scaled, Peer, Yardstick, Yardsticks, PEER, PEER_BUILD_STATED_S, PEER_CRATE, PEER_RUN_STATED_MS,
    PEER_VERSION, write_crate,
};
use super::{build, run_report, verdict, Args, Step, NAMESPACES};
use process_support::workspace::{display_path, target_dir};

/// Targets: emission time, generated lines of DI + Robotics, cold crate-only build, import.
const EMIT_MS: f64 = 25.0;
const LINES_DI_ROBOTICS: usize = 12_000;
const CRATE_BUILD_S: f64 = 1.5;
const IMPORT_MS: f64 = 1.0;

const RUNTIME_CRATE: &str = "nodeset-runtime";
/// The CLI's output for DI + IA + Robotics (the peer's inputs) as a crate of its own on nodeset-runtime.
const THREE_CRATE: &str = "nodeset-models-di-ia-robotics";
/// Our crate, and the file touched before an incremental build (the peer's counterpart is its Robotics
/// types module).
const CRATE: &str = "nodeset-models";
const TOUCHED: &str = "generated/src/models/robotics/types.rs";

/// Everything the scenario measured; every step may have failed, with the reason.
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

/// The arguments of `nodeset-compiler rust` on DI + IA + Robotics from `vendor` (ns0 found there as their
/// dependency), written to `out`: the peer's inputs, as `cargo xtask generate` names their modules.
pub(super) fn cli_args(vendor: &Path, out: &Path) -> Vec<String> {
    let mut cli_args: Vec<String> = vec!["rust".into()];
    cli_args.extend(NAMESPACES.iter().map(|n| vendor.join(n.1).display().to_string()));
    cli_args.extend(["--models".into(), vendor.display().to_string()]);
    cli_args.extend(["--out".into(), out.display().to_string()]);
    cli_args.extend(["--runtime".into(), "crate::runtime".into()]);
    for (module, _, uri, _) in NAMESPACES {
        cli_args.extend(["--module".into(), format!("{uri}={module}")]);
    }
    cli_args
}

/// Runs the scenario and prints its table; an error means one of our own steps failed.
pub(super) fn run(args: &Args, root: &Path, tree: &Path) -> Result<(), String> {
    let start = Instant::now();
    let load_start = load_average();
    let vendor = root.join("nodesets/vendor");
    let bench_target = root.join("target/bench-build");
    let bench = build(root, "nodeset-compiler", "rust_bench", &["--bin", "nodeset-compiler"])?;
    let cli_exe =
        target_dir().join("release").join(format!("nodeset-compiler{}", env::consts::EXE_SUFFIX));

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
        let cli_args = cli_args(&vendor, &cli_out);
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

/// Makes `dir` (which holds the CLI's `models/`) the crate [`THREE_CRATE`]: the generated modules on
/// nodeset-runtime, re-exported as `crate::runtime` as the CLI was told.
fn write_three_crate(root: &Path, dir: &Path) -> Step<()> {
    let manifest = format!(
        "[lib]\npath = \"lib.rs\"\n\n[dependencies]\nnodeset-runtime = {{ path = {:?} }}\n\
         async-opcua = {{ version = \"=0.19.0\", features = [\"server\", \"client\"] }}\nbitflags = \"2\"\n",
        root.join("nodeset-runtime").display().to_string()
    );
    let lib = "//! The CLI's output for DI + IA + Robotics. Written by `cargo xtask bench`.\n#![allow(warnings)]\n\n\
               pub use nodeset_runtime as runtime;\npub mod models;\n";
    let what = "the CLI's output for DI + IA + Robotics as a crate";
    write_crate(root, dir, THREE_CRATE, what, &manifest, "lib.rs", lib)
}

/// KiB in MiB.
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

/// The 1-minute load average (`/proc/loadavg`), NaN where unknown.
fn load_average() -> f64 {
    fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// Prints the scenario's table.
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

/// Prints the peer's figures and the ratios of ours to them.
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
