//! Measures Rust generation (compile + `emit::rust::generate`) on DI + IA + Robotics, and runs other
//! programs under a stopwatch.
//!
//! This is a measured program behind `cargo xtask bench --scenario rust`, which builds it in release mode
//! and runs it in a fresh process, so that the peak resident memory (`VmHWM`) belongs to one scenario only.
//! It can also be run by hand:
//!
//! ```text
//! cargo run --release --example rust_bench -p nodeset-compiler -- generate --runs 20
//! cargo run --release --example rust_bench -p nodeset-compiler -- exec --runs 3 -- some-program args...
//! ```
//!
//! Subcommands:
//!
//! * `generate`: what `cargo xtask generate` does, minus writing: one `compile` of DI, IA and Robotics from
//!   `nodesets/vendor/` (ns0 is found there as their dependency, as `xtask/src/generate.rs` does), then
//!   `emit::rust::generate` for the three namespaces plus the folder's `mod.rs` and `rustfmt.toml`. Both
//!   stages are timed separately in every run. The first run's files are counted (lines and bytes per
//!   namespace module), so the caller can compare them with what is checked in.
//! * `exec`: runs a command N times (stdout and stderr discarded unless it fails), and reports its wall
//!   time and the peak resident memory and CPU time of its processes (`getrusage(RUSAGE_CHILDREN)`; this
//!   program has no other children, so the figures belong to the command alone). It measures peers such as
//!   async-opcua-codegen under the same rules.
//! * `alternate`: runs several named commands in rounds, one run of each per round in the order given
//!   (A B C A B C ...), after one untimed round, and reports each command's wall times per round and its
//!   CPU time per run. Commands compared this way sample the same stretch of a shared host's time, so the
//!   per-round ratios hold where the absolute times drift.
//! * `read`: reads the files named into memory and does nothing else: as a process, the floor under any
//!   program that has to read them.
//!
//! Output: progress on stderr, and on stdout one line `BENCH key=value ...` (times in ms, memory in KiB).

use nodeset_compiler::emit::rust as rust_emit;
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options, RustOptions};
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

use bench_support::{children_usage, median, ms_since, process_cpu_ms, proc_status_kib, Line};

/// The generated namespaces: (file in nodesets/vendor, module name), as in `xtask/src/generate.rs`.
const NAMESPACES: &[(&str, &str)] = &[
    ("Opc.Ua.Di.NodeSet2.xml", "di"),
    ("Opc.Ua.IA.NodeSet2.xml", "ia"),
    ("Opc.Ua.Robotics.NodeSet2.xml", "robotics"),
];

const COMMAND: &str = "cargo xtask generate";

fn workspace_root() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    dir.parent().map(Path::to_path_buf).unwrap_or(dir)
}

fn usage() -> String {
    "usage: rust_bench generate [--runs N] [--vendor DIR]\n       rust_bench exec [--runs N] -- PROGRAM [ARGS...]\n       \
     rust_bench alternate [--rounds N] [--dir DIR] [--env K=V] --cmd NAME PROGRAM [ARGS...] --cmd NAME ...\n       \
     rust_bench read FILE..."
        .to_string()
}

/// The peak resident memory of this process so far, KiB (0 where there is no procfs).
fn vm_hwm_kib() -> u64 {
    proc_status_kib("VmHWM").unwrap_or(0)
}

/// One generation, as `xtask/src/generate.rs` `plan()` does it: returns the files, or why it failed.
struct Generated {
    files: Vec<nodeset_compiler::write::OutFile>,
    nodes: usize,
    compile_errors: usize,
    compile_warnings: usize,
    emit_errors: usize,
    emit_warnings: usize,
}

fn generate_cmd(mut args: impl Iterator<Item = String>) -> Result<(), String> {
    let mut runs = 20usize;
    let mut vendor = workspace_root().join("nodesets/vendor");
    while let Some(a) = args.next() {
        match a.as_str() {
            "--runs" => {
                runs = args
                    .next()
                    .ok_or("--runs needs a value")?
                    .parse()
                    .map_err(|e| format!("--runs: {e}"))?
            }
            "--vendor" => vendor = PathBuf::from(args.next().ok_or("--vendor needs a value")?),
            s => return Err(format!("unexpected argument `{s}`\n{}", usage())),
        }
    }
    let runs = runs.max(1);
    let inputs: Vec<PathBuf> = NAMESPACES.iter().map(|(f, _)| vendor.join(f)).collect();
    if let Some(missing) = inputs
        .iter()
        .chain([&vendor.join("Opc.Ua.NodeSet2.xml")])
        .find(|p| !p.is_file())
    {
        return Err(format!(
            "{} is missing; run `cargo xtask fetch-nodesets`",
            missing.display()
        ));
    }
    let opts = Options {
        model_dirs: vec![vendor.clone()],
        ..Options::default()
    };
    eprintln!("rust_bench: generate DI + IA + Robotics (ns0 as dependency), {runs} run(s)");

    let hwm_start = vm_hwm_kib();
    let (mut compile_ms, mut emit_ms, mut total_ms) = (Vec::new(), Vec::new(), Vec::new());
    let (mut compile_cpu, mut emit_cpu) = (Vec::new(), Vec::new());
    let mut first: Option<Generated> = None;
    let mut hwm_first = 0;
    for run in 0..runs {
        let c0 = process_cpu_ms();
        let t0 = Instant::now();
        let out = compile(inputs.iter().cloned().map(Input::Path).collect(), &opts);
        let t_compile = ms_since(t0);
        let c1 = process_cpu_ms();
        if !out.ok() {
            eprint!("{}", out.render_diagnostics());
            return Err("the pinned nodesets do not compile".into());
        }
        let t1 = Instant::now();
        let model = &out.model;
        let mut options = RustOptions {
            runtime_path: "crate::runtime".into(),
            command: COMMAND.into(),
            ..RustOptions::default()
        };
        let mut uris = Vec::new();
        for (file, module) in NAMESPACES {
            let m = model
                .models
                .iter()
                .find(|m| {
                    model
                        .sources
                        .get(m.file)
                        .path
                        .file_name()
                        .is_some_and(|n| n == *file)
                })
                .ok_or_else(|| format!("{file} defines no model"))?;
            options.modules.insert(m.uri.clone(), (*module).to_string());
            uris.push(m.uri.clone());
        }
        let cfg = options.config_of(&uris).map_err(|e| e.to_string())?;
        let mut rust = rust_emit::generate(model, &cfg);
        rust.files.extend(rust_emit::top_files(model, &cfg));
        let t_emit = ms_since(t1);
        let c2 = process_cpu_ms();
        compile_ms.push(t_compile);
        emit_ms.push(t_emit);
        total_ms.push(t_compile + t_emit);
        compile_cpu.push(c1 - c0);
        emit_cpu.push(c2 - c1);
        if run == 0 {
            hwm_first = vm_hwm_kib();
            if rust.diagnostics.has_errors() {
                eprint!("{}", rust.diagnostics.render(&model.sources));
                return Err("Rust generation reported errors".into());
            }
            first = Some(Generated {
                nodes: model.nodes.len(),
                compile_errors: out.diagnostics.error_count(),
                compile_warnings: out.diagnostics.warning_count(),
                emit_errors: rust.diagnostics.error_count(),
                emit_warnings: rust.diagnostics.warning_count(),
                files: rust.files,
            });
        } else {
            drop(black_box(rust));
        }
        drop(black_box(out));
    }
    let hwm_runs = vm_hwm_kib();
    let g = first.expect("at least one run");

    // Lines and bytes per module folder (`di/...`), and for the files at the top (`mod.rs`, `rustfmt.toml`).
    let mut per: BTreeMap<String, (usize, usize, usize)> = BTreeMap::new();
    for f in &g.files {
        let key = match f.path.components().count() {
            1 => "top".to_string(),
            _ => f
                .path
                .components()
                .next()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .unwrap_or_default(),
        };
        let e = per.entry(key).or_default();
        e.0 += 1;
        e.1 += f.contents.lines().count();
        e.2 += f.contents.len();
    }

    let mut line = Line::new();
    line.kv("scenario", "rust-generate")
        .kv("runs", runs)
        .stats("compile", &compile_ms, 3)
        .stats("emit", &emit_ms, 3)
        .stats("total", &total_ms, 3)
        .num("compile_cpu_median_ms", median(&compile_cpu), 3)
        .num("emit_cpu_median_ms", median(&emit_cpu), 3)
        .kv("hwm_start_kib", hwm_start)
        .kv("hwm_kib", hwm_first)
        .kv("hwm_all_runs_kib", hwm_runs)
        .kv("nodes", g.nodes)
        .kv("compile_errors", g.compile_errors)
        .kv("compile_warnings", g.compile_warnings)
        .kv("emit_errors", g.emit_errors)
        .kv("emit_warnings", g.emit_warnings)
        .kv("files", g.files.len());
    for (module, (files, lines, bytes)) in &per {
        line.kv(format!("files_{module}"), files)
            .kv(format!("lines_{module}"), lines)
            .kv(format!("bytes_{module}"), bytes);
    }
    line.print();
    Ok(())
}

fn exec_cmd(mut args: impl Iterator<Item = String>) -> Result<(), String> {
    let mut runs = 1usize;
    let mut dir: Option<PathBuf> = None;
    let mut envs: Vec<(String, String)> = Vec::new();
    loop {
        match args.next().as_deref() {
            Some("--runs") => {
                runs = args
                    .next()
                    .ok_or("--runs needs a value")?
                    .parse()
                    .map_err(|e| format!("--runs: {e}"))?
            }
            Some("--dir") => dir = Some(PathBuf::from(args.next().ok_or("--dir needs a value")?)),
            Some("--env") => {
                let kv = args.next().ok_or("--env needs KEY=VALUE")?;
                let (k, v) = kv.split_once('=').ok_or("--env needs KEY=VALUE")?;
                envs.push((k.into(), v.into()));
            }
            Some("--") => break,
            Some(s) => return Err(format!("unexpected argument `{s}`\n{}", usage())),
            None => return Err(usage()),
        }
    }
    let program = args.next().ok_or_else(usage)?;
    let rest: Vec<String> = args.collect();
    let mut wall = Vec::new();
    let mut failure = None;
    for _ in 0..runs.max(1) {
        let mut cmd = Command::new(&program);
        cmd.args(&rest)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        if let Some(d) = &dir {
            cmd.current_dir(d);
        }
        for (k, v) in &envs {
            cmd.env(k, v);
        }
        let t = Instant::now();
        let out = cmd
            .output()
            .map_err(|e| format!("cannot run {program}: {e}"))?;
        wall.push(ms_since(t));
        if !out.status.success() {
            let text = String::from_utf8_lossy(&out.stderr);
            let tail: Vec<&str> = text.lines().rev().take(15).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            failure = Some(format!(
                "{program} failed ({}):\n{}",
                out.status,
                tail.join("\n")
            ));
            break;
        }
    }
    let (maxrss, cpu) = children_usage();
    Line::new()
        .kv("scenario", "exec")
        .kv("ok", u8::from(failure.is_none()))
        .kv("runs", wall.len())
        .stats("wall", &wall, 3)
        .num("cpu_per_run_ms", cpu / wall.len().max(1) as f64, 3)
        .kv("maxrss_kib", maxrss)
        .print();
    match failure {
        Some(f) => Err(f),
        None => Ok(()),
    }
}

/// One command of `alternate`: its name, program and arguments.
struct Named {
    name: String,
    program: String,
    args: Vec<String>,
}

fn alternate_cmd(mut args: impl Iterator<Item = String>) -> Result<(), String> {
    let mut rounds = 10usize;
    let mut dir: Option<PathBuf> = None;
    let mut envs: Vec<(String, String)> = Vec::new();
    let mut cmds: Vec<Named> = Vec::new();
    while let Some(a) = args.next() {
        match (a.as_str(), cmds.last_mut()) {
            ("--cmd", _) => {
                let name = args.next().ok_or("--cmd needs NAME PROGRAM")?;
                let program = args.next().ok_or("--cmd needs NAME PROGRAM")?;
                cmds.push(Named { name, program, args: Vec::new() });
            }
            (_, Some(cmd)) => cmd.args.push(a),
            ("--rounds", None) => {
                rounds = args.next().ok_or("--rounds needs a value")?.parse().map_err(|e| format!("--rounds: {e}"))?
            }
            ("--dir", None) => dir = Some(PathBuf::from(args.next().ok_or("--dir needs a value")?)),
            ("--env", None) => {
                let kv = args.next().ok_or("--env needs KEY=VALUE")?;
                let (k, v) = kv.split_once('=').ok_or("--env needs KEY=VALUE")?;
                envs.push((k.into(), v.into()));
            }
            (s, None) => return Err(format!("unexpected argument `{s}`\n{}", usage())),
        }
    }
    if cmds.is_empty() {
        return Err(usage());
    }
    let run = |c: &Named| -> Result<f64, String> {
        let mut cmd = Command::new(&c.program);
        cmd.args(&c.args).stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped());
        if let Some(d) = &dir {
            cmd.current_dir(d);
        }
        for (k, v) in &envs {
            cmd.env(k, v);
        }
        let t = Instant::now();
        let out = cmd.output().map_err(|e| format!("cannot run {}: {e}", c.program))?;
        let wall = ms_since(t);
        if !out.status.success() {
            let text = String::from_utf8_lossy(&out.stderr);
            let tail: Vec<&str> = text.lines().rev().take(15).collect::<Vec<_>>().into_iter().rev().collect();
            return Err(format!("{} ({}) failed ({}):\n{}", c.name, c.program, out.status, tail.join("\n")));
        }
        Ok(wall)
    };
    eprintln!("rust_bench: alternate {} command(s), 1 untimed round and {rounds} timed", cmds.len());
    for c in &cmds {
        run(c)?;
    }
    let mut wall: Vec<Vec<f64>> = cmds.iter().map(|_| Vec::new()).collect();
    let mut cpu: Vec<Vec<f64>> = cmds.iter().map(|_| Vec::new()).collect();
    for _ in 0..rounds.max(1) {
        for (i, c) in cmds.iter().enumerate() {
            let before = children_usage().1;
            wall[i].push(run(c)?);
            cpu[i].push(children_usage().1 - before);
        }
    }
    let mut line = Line::new();
    line.kv("scenario", "alternate").kv("rounds", rounds.max(1));
    for (i, c) in cmds.iter().enumerate() {
        let list: Vec<String> = wall[i].iter().map(|w| format!("{w:.3}")).collect();
        line.stats(&c.name, &wall[i], 3)
            .num(format!("{}_cpu_median_ms", c.name), median(&cpu[i]), 3)
            .kv(format!("{}_rounds_ms", c.name), list.join(","));
    }
    line.print();
    Ok(())
}

fn read_cmd(args: impl Iterator<Item = String>) -> Result<(), String> {
    let mut bytes = 0usize;
    for path in args {
        bytes += black_box(std::fs::read(&path).map_err(|e| format!("cannot read {path}: {e}"))?).len();
    }
    println!("{bytes} bytes");
    Ok(())
}

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let result = match args.next().as_deref() {
        Some("generate") => generate_cmd(args),
        Some("exec") => exec_cmd(args),
        Some("alternate") => alternate_cmd(args),
        Some("read") => read_cmd(args),
        _ => Err(usage()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rust_bench: {e}");
            ExitCode::FAILURE
        }
    }
}
