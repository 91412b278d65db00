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
//!
//! Output: progress on stderr, and on stdout one line `BENCH key=value ...` (times in ms, memory in KiB).

use nodeset_compiler::emit::rust::{self as rust_emit, RustConfig, RustNamespace};
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

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
    "usage: rust_bench generate [--runs N] [--vendor DIR]\n       rust_bench exec [--runs N] -- PROGRAM [ARGS...]"
        .to_string()
}

/// A line of `/proc/self/status`, in KiB (0 where there is no procfs).
fn proc_status_kib(key: &str) -> u64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/status") else {
        return 0;
    };
    s.lines()
        .find_map(|l| l.strip_prefix(key)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
mod sys {
    #[repr(C)]
    struct Timespec {
        tv_sec: i64,
        tv_nsec: i64,
    }

    #[repr(C)]
    struct Timeval {
        tv_sec: i64,
        tv_usec: i64,
    }

    /// `struct rusage` of 64-bit Linux: two timevals, then 14 longs starting with `ru_maxrss` (KiB).
    #[repr(C)]
    struct Rusage {
        utime: Timeval,
        stime: Timeval,
        maxrss: i64,
        rest: [i64; 13],
    }

    extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
        fn getrusage(who: i32, usage: *mut Rusage) -> i32;
    }

    /// CPU time this process has run on all its threads, ms (NaN where unavailable). Unlike wall time, it
    /// does not grow when other processes compete for the CPU; both stages use several threads, so the
    /// calling thread's time alone would undercount them.
    pub fn process_cpu_ms() -> f64 {
        const CLOCK_PROCESS_CPUTIME_ID: i32 = 2;
        let mut ts = Timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `ts` is a valid, writable timespec of the 64-bit Linux layout.
        if unsafe { clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &mut ts) } == 0 {
            ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 / 1e6
        } else {
            f64::NAN
        }
    }

    /// Peak RSS (KiB) of the largest terminated child, and the CPU time (user + system, ms) of all of them.
    pub fn children_usage() -> (u64, f64) {
        const RUSAGE_CHILDREN: i32 = -1;
        let mut ru = Rusage {
            utime: Timeval {
                tv_sec: 0,
                tv_usec: 0,
            },
            stime: Timeval {
                tv_sec: 0,
                tv_usec: 0,
            },
            maxrss: 0,
            rest: [0; 13],
        };
        // SAFETY: `ru` is a valid, writable rusage of the 64-bit Linux layout.
        if unsafe { getrusage(RUSAGE_CHILDREN, &mut ru) } != 0 {
            return (0, f64::NAN);
        }
        let ms = |t: &Timeval| t.tv_sec as f64 * 1e3 + t.tv_usec as f64 / 1e3;
        (ru.maxrss.max(0) as u64, ms(&ru.utime) + ms(&ru.stime))
    }
}

#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
mod sys {
    pub fn process_cpu_ms() -> f64 {
        f64::NAN
    }

    pub fn children_usage() -> (u64, f64) {
        (0, f64::NAN)
    }
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
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

fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

/// Adds `<prefix>_median_ms`, `_min_ms` and `_max_ms` of `v` to the report.
fn stats(kv: &mut Vec<(String, String)>, prefix: &str, v: &[f64]) {
    kv.push((format!("{prefix}_median_ms"), format!("{:.3}", median(v))));
    kv.push((format!("{prefix}_min_ms"), format!("{:.3}", min(v))));
    kv.push((format!("{prefix}_max_ms"), format!("{:.3}", max(v))));
}

fn print_bench(kv: &[(String, String)]) {
    let line: Vec<String> = kv.iter().map(|(k, v)| format!("{k}={v}")).collect();
    println!("BENCH {}", line.join(" "));
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

    let hwm_start = proc_status_kib("VmHWM");
    let (mut compile_ms, mut emit_ms, mut total_ms) = (Vec::new(), Vec::new(), Vec::new());
    let (mut compile_cpu, mut emit_cpu) = (Vec::new(), Vec::new());
    let mut first: Option<Generated> = None;
    let mut hwm_first = 0;
    for run in 0..runs {
        let c0 = sys::process_cpu_ms();
        let t0 = Instant::now();
        let out = compile(inputs.iter().cloned().map(Input::Path).collect(), &opts);
        let t_compile = ms_since(t0);
        let c1 = sys::process_cpu_ms();
        if !out.ok() {
            eprint!("{}", out.render_diagnostics());
            return Err("the pinned nodesets do not compile".into());
        }
        let t1 = Instant::now();
        let model = &out.model;
        let mut namespaces = Vec::new();
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
            namespaces.push(RustNamespace {
                uri: m.uri.clone(),
                module: (*module).to_string(),
            });
        }
        let cfg = RustConfig {
            namespaces: namespaces.clone(),
            extern_paths: Default::default(),
            runtime_path: "crate::runtime".into(),
            command: COMMAND.into(),
        };
        let mut rust = rust_emit::generate(model, &cfg);
        let modules: Vec<(String, String)> = namespaces
            .iter()
            .map(|n| (n.module.clone(), n.uri.clone()))
            .collect();
        rust.files.push(rust_emit::models_mod(&modules, &cfg.runtime_path, COMMAND));
        rust.files.push(rust_emit::rustfmt_toml());
        let t_emit = ms_since(t1);
        let c2 = sys::process_cpu_ms();
        compile_ms.push(t_compile);
        emit_ms.push(t_emit);
        total_ms.push(t_compile + t_emit);
        compile_cpu.push(c1 - c0);
        emit_cpu.push(c2 - c1);
        if run == 0 {
            hwm_first = proc_status_kib("VmHWM");
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
    let hwm_runs = proc_status_kib("VmHWM");
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

    let mut kv: Vec<(String, String)> = vec![
        ("scenario".into(), "rust-generate".into()),
        ("runs".into(), runs.to_string()),
    ];
    stats(&mut kv, "compile", &compile_ms);
    stats(&mut kv, "emit", &emit_ms);
    stats(&mut kv, "total", &total_ms);
    kv.push((
        "compile_cpu_median_ms".into(),
        format!("{:.3}", median(&compile_cpu)),
    ));
    kv.push((
        "emit_cpu_median_ms".into(),
        format!("{:.3}", median(&emit_cpu)),
    ));
    kv.push(("hwm_start_kib".into(), hwm_start.to_string()));
    kv.push(("hwm_kib".into(), hwm_first.to_string()));
    kv.push(("hwm_all_runs_kib".into(), hwm_runs.to_string()));
    kv.push(("nodes".into(), g.nodes.to_string()));
    kv.push(("compile_errors".into(), g.compile_errors.to_string()));
    kv.push(("compile_warnings".into(), g.compile_warnings.to_string()));
    kv.push(("emit_errors".into(), g.emit_errors.to_string()));
    kv.push(("emit_warnings".into(), g.emit_warnings.to_string()));
    kv.push(("files".into(), g.files.len().to_string()));
    for (module, (files, lines, bytes)) in &per {
        kv.push((format!("files_{module}"), files.to_string()));
        kv.push((format!("lines_{module}"), lines.to_string()));
        kv.push((format!("bytes_{module}"), bytes.to_string()));
    }
    print_bench(&kv);
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
    let (maxrss, cpu) = sys::children_usage();
    let mut kv: Vec<(String, String)> = vec![
        ("scenario".into(), "exec".into()),
        ("ok".into(), u8::from(failure.is_none()).to_string()),
        ("runs".into(), wall.len().to_string()),
    ];
    stats(&mut kv, "wall", &wall);
    kv.push((
        "cpu_per_run_ms".into(),
        format!("{:.3}", cpu / wall.len().max(1) as f64),
    ));
    kv.push(("maxrss_kib".into(), maxrss.to_string()));
    print_bench(&kv);
    match failure {
        Some(f) => Err(f),
        None => Ok(()),
    }
}

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let result = match args.next().as_deref() {
        Some("generate") => generate_cmd(args),
        Some("exec") => exec_cmd(args),
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
