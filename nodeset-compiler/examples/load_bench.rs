//! Measures the foundation stage of the compiler (parse + load + resolve) on real NodeSet2 files.
//!
//! This is the measured program behind `cargo xtask bench`, which builds it in release mode and runs every
//! scenario in a fresh process, so that the peak resident memory (`VmHWM`) belongs to one scenario only.
//! It can also be run by hand:
//!
//! ```text
//! cargo run --release --example load_bench -p nodeset-compiler -- robotics --runs 20
//! cargo run --release --example load_bench -p nodeset-compiler -- tree --runs 3 --tree ../shared/nodesets/ua-nodeset
//! cargo run --release --example load_bench -p nodeset-compiler -- sets --runs 3 --tree ../shared/nodesets/ua-nodeset
//! ```
//!
//! Scenarios:
//!
//! * `robotics`: one `compile` of ns0 + DI + IA + Robotics from `nodesets/vendor/` (all four named).
//! * `tree`: one `compile` per NodeSet2 file of a tree such as the OPC Foundation's `UA-Nodeset`
//!   repository, each with its required models resolved from the tree itself (`model_dirs = [tree]`);
//!   one run is one pass over all files. (A single compile of every file at once is not possible: the tree
//!   holds several versions of some models.)
//! * `sets`: the same tree as a few compiles of many files each, the way a user with many models compiles
//!   them: every file is named in exactly one set, and no set names two files of one ModelUri (the first
//!   set takes the newest version of every model, the next set the next newest, and so on). Required models
//!   that a set does not name come from the tree, as in `tree`.
//!
//! Output: progress and details on stderr, and on stdout one line `BENCH key=value ...` (times in ms,
//! memory in KiB) that `cargo xtask bench` reads. Stage times come from separate runs that call
//! `load::load` and `resolve::resolve` one after the other; within loading, the share of reading, decoding
//! and parsing is estimated from standalone measurements of each file (`parse::decode_text`, `parse::parse`)
//! summed over the files each compile loaded.

use nodeset_compiler::diag::Diagnostics;
use nodeset_compiler::load::{self, Input, LoadOptions};
use nodeset_compiler::parse::{self, Limits};
use nodeset_compiler::source::FileId;
use nodeset_compiler::{compile, resolve, Options};
use std::collections::HashMap;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use bench_support::{median, min, ms, proc_status_kib, thread_cpu_ms, Line};

/// The four files of the `robotics` scenario, in `nodesets/vendor/`.
const ROBOTICS_FILES: &[&str] = &[
    "Opc.Ua.NodeSet2.xml",
    "Opc.Ua.Di.NodeSet2.xml",
    "Opc.Ua.IA.NodeSet2.xml",
    "Opc.Ua.Robotics.NodeSet2.xml",
];

fn workspace_root() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    dir.parent().map(Path::to_path_buf).unwrap_or(dir)
}

struct Cli {
    scenario: String,
    runs: usize,
    vendor: PathBuf,
    tree: PathBuf,
    split: bool,
    /// Only the headline `compile` runs (no stage split, no per-file costs): for profilers.
    compile_only: bool,
}

fn usage() -> String {
    "usage: load_bench <robotics|tree|sets> [--runs N] [--vendor DIR] [--tree DIR] [--no-split] [--compile-only]".to_string()
}

fn parse_cli() -> Result<Cli, String> {
    let root = workspace_root();
    let mut cli = Cli {
        scenario: String::new(),
        runs: 0,
        vendor: root.join("nodesets/vendor"),
        tree: root.join("../shared/nodesets/ua-nodeset"),
        split: true,
        compile_only: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| {
            args.next()
                .ok_or_else(|| format!("{name} needs a value\n{}", usage()))
        };
        match a.as_str() {
            "--runs" => {
                cli.runs = value("--runs")?
                    .parse()
                    .map_err(|e| format!("--runs: {e}"))?
            }
            "--vendor" => cli.vendor = PathBuf::from(value("--vendor")?),
            "--tree" => cli.tree = PathBuf::from(value("--tree")?),
            "--no-split" => cli.split = false,
            "--compile-only" => {
                cli.split = false;
                cli.compile_only = true;
            }
            "-h" | "--help" => return Err(usage()),
            s if !s.starts_with('-') && cli.scenario.is_empty() => cli.scenario = s.to_string(),
            s => return Err(format!("unexpected argument `{s}`\n{}", usage())),
        }
    }
    if cli.runs == 0 {
        cli.runs = match cli.scenario.as_str() {
            "tree" | "sets" => 3,
            _ => 20,
        };
    }
    match cli.scenario.as_str() {
        "robotics" | "tree" | "sets" => Ok(cli),
        "" => Err(usage()),
        s => Err(format!("unknown scenario `{s}`\n{}", usage())),
    }
}

/// One compile job: the named files and the model folders.
struct Job {
    label: String,
    inputs: Vec<PathBuf>,
    model_dirs: Vec<PathBuf>,
}

impl Job {
    fn inputs(&self) -> Vec<Input> {
        self.inputs.iter().cloned().map(Input::Path).collect()
    }

    fn options(&self) -> Options {
        Options {
            model_dirs: self.model_dirs.clone(),
            ..Options::default()
        }
    }
}

fn jobs(cli: &Cli) -> Result<Vec<Job>, String> {
    match cli.scenario.as_str() {
        "robotics" => {
            let inputs: Vec<PathBuf> = ROBOTICS_FILES.iter().map(|f| cli.vendor.join(f)).collect();
            if let Some(missing) = inputs.iter().find(|p| !p.is_file()) {
                return Err(format!(
                    "{} is missing; run `cargo xtask fetch-nodesets`",
                    missing.display()
                ));
            }
            Ok(vec![Job {
                label: "ns0+DI+IA+Robotics".into(),
                inputs,
                model_dirs: vec![cli.vendor.clone()],
            }])
        }
        scenario => {
            if !cli.tree.is_dir() {
                return Err(format!(
                    "the NodeSet tree {} does not exist",
                    cli.tree.display()
                ));
            }
            let tree = cli
                .tree
                .canonicalize()
                .map_err(|e| format!("{}: {e}", cli.tree.display()))?;
            let mut files = Vec::new();
            walk(&tree, &mut files);
            files.sort();
            if files.is_empty() {
                return Err(format!("no *NodeSet2*.xml file under {}", tree.display()));
            }
            let label = |f: &Path| f.strip_prefix(&tree).unwrap_or(f).display().to_string();
            if scenario == "sets" {
                return Ok(model_sets(&files)
                    .into_iter()
                    .enumerate()
                    .map(|(i, set)| Job {
                        label: format!(
                            "set {} ({} files, first {})",
                            i + 1,
                            set.len(),
                            label(&set[0])
                        ),
                        inputs: set,
                        model_dirs: vec![tree.clone()],
                    })
                    .collect());
            }
            Ok(files
                .into_iter()
                .map(|f| Job {
                    label: label(&f),
                    inputs: vec![f],
                    model_dirs: vec![tree.clone()],
                })
                .collect())
        }
    }
}

/// Splits files into sets that name every ModelUri at most once: newest versions first, so the first set
/// holds the newest version of every model and later sets the older versions (and duplicates).
fn model_sets(files: &[PathBuf]) -> Vec<Vec<PathBuf>> {
    let mut by_age: Vec<(&PathBuf, Vec<(String, Option<String>, Option<String>)>)> =
        files.iter().map(|f| (f, nodeset_compiler::load::declared_models(f).unwrap_or_default())).collect();
    // Newest first (version, then publication date), ties by path so the plan never depends on the walk.
    by_age.sort_by(|(pa, a), (pb, b)| {
        let key = |m: &[(String, Option<String>, Option<String>)]| {
            m.first().map(|x| (x.1.clone(), x.2.clone()))
        };
        let (ka, kb) = (key(a), key(b));
        let (va, da) = ka.unwrap_or_default();
        let (vb, db) = kb.unwrap_or_default();
        load::cmp_version(vb.as_deref(), va.as_deref())
            .then_with(|| db.cmp(&da))
            .then_with(|| pa.cmp(pb))
    });
    let mut sets: Vec<(Vec<PathBuf>, Vec<String>)> = Vec::new();
    for (file, models) in by_age {
        let uris: Vec<String> = models.into_iter().map(|m| m.0).collect();
        let slot = sets
            .iter()
            .position(|(_, taken)| !uris.iter().any(|u| taken.contains(u)));
        let slot = slot.unwrap_or_else(|| {
            sets.push((Vec::new(), Vec::new()));
            sets.len() - 1
        });
        sets[slot].0.push(file.clone());
        sets[slot].1.extend(uris);
    }
    sets.into_iter()
        .map(|(mut files, _)| {
            files.sort();
            files
        })
        .collect()
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let Ok(ft) = e.file_type() else { continue };
        if ft.is_dir() {
            walk(&p, out);
        } else {
            let name = e.file_name().to_string_lossy().to_ascii_lowercase();
            if name.ends_with(".xml") && name.contains("nodeset2") {
                out.push(p);
            }
        }
    }
}

/// The peak resident memory of this process so far, KiB (0 where there is no procfs).
fn vm_hwm_kib() -> u64 {
    proc_status_kib("VmHWM").unwrap_or(0)
}

/// What one compile of a job produced (from the first run).
#[derive(Default, Clone)]
struct Outcome {
    nodes: usize,
    files: usize,
    errors: usize,
    warnings: usize,
    loaded_paths: Vec<PathBuf>,
}

/// Standalone cost of one file, ms: read, decode (UTF-8 check, BOM), parse (quick-xml pass into RawNodeSet).
#[derive(Default, Clone, Copy)]
struct FileCost {
    read: f64,
    decode: f64,
    parse: f64,
    nodes: usize,
}

fn file_cost(path: &Path, reps: usize) -> FileCost {
    let (mut r, mut d, mut p) = (Vec::new(), Vec::new(), Vec::new());
    let mut nodes = 0;
    for _ in 0..reps.max(1) {
        let t = Instant::now();
        let Ok(bytes) = std::fs::read(path) else {
            return FileCost::default();
        };
        r.push(ms(t.elapsed()));
        let t = Instant::now();
        let text = parse::decode_text(bytes);
        d.push(ms(t.elapsed()));
        let Ok(text) = text else {
            return FileCost::default();
        };
        let mut diags = Diagnostics::new();
        let t = Instant::now();
        let set = parse::parse(FileId(0), &text, &Limits::default(), &mut diags);
        p.push(ms(t.elapsed()));
        nodes = set.as_ref().map_or(0, |s| s.nodes.len());
        drop(black_box(set));
    }
    FileCost {
        read: median(&r),
        decode: median(&d),
        parse: median(&p),
        nodes,
    }
}

fn run() -> Result<(), String> {
    let cli = parse_cli()?;
    let hwm_start = vm_hwm_kib();
    let jobs = jobs(&cli)?;
    eprintln!(
        "load_bench: scenario `{}`, {} compile(s) per run, {} run(s)",
        cli.scenario,
        jobs.len(),
        cli.runs
    );

    // Headline: the public all-in-one `compile`, as users call it.
    let mut totals = Vec::with_capacity(cli.runs);
    let mut cpu = Vec::with_capacity(cli.runs);
    let mut drops = Vec::with_capacity(cli.runs);
    let mut per_job: Vec<Vec<f64>> = vec![Vec::with_capacity(cli.runs); jobs.len()];
    let mut outcomes: Vec<Outcome> = vec![Outcome::default(); jobs.len()];
    let mut hwm_first = 0;
    for run in 0..cli.runs {
        // Per pass: the compile calls only; dropping each result is timed apart (`drop_*`).
        let (mut wall, mut cpu_ms, mut drop_ms) = (0.0, 0.0, 0.0);
        for (j, job) in jobs.iter().enumerate() {
            let cpu0 = thread_cpu_ms();
            let t = Instant::now();
            let out = compile(job.inputs(), &job.options());
            let dt = ms(t.elapsed());
            cpu_ms += thread_cpu_ms() - cpu0;
            wall += dt;
            per_job[j].push(dt);
            if run == 0 {
                outcomes[j] = Outcome {
                    nodes: out.model.nodes.len(),
                    files: out.model.sources.len(),
                    errors: out.diagnostics.error_count(),
                    warnings: out.diagnostics.warning_count(),
                    loaded_paths: out
                        .model
                        .sources
                        .files()
                        .map(|(_, f)| f.path.clone())
                        .collect(),
                };
            }
            let t = Instant::now();
            drop(black_box(out));
            drop_ms += ms(t.elapsed());
        }
        totals.push(wall);
        cpu.push(cpu_ms);
        drops.push(drop_ms);
        if run == 0 {
            hwm_first = vm_hwm_kib();
        }
    }
    let hwm_runs = vm_hwm_kib();

    // Stage split: load, then resolve, timed separately (separate runs, so the headline is untouched).
    let (mut loads, mut resolves) = (Vec::new(), Vec::new());
    if cli.split {
        for _ in 0..cli.runs {
            let (mut l, mut r) = (Duration::ZERO, Duration::ZERO);
            for job in &jobs {
                let opts = LoadOptions {
                    model_dirs: job.model_dirs.clone(),
                    limits: Limits::default(),
                };
                let mut diags = Diagnostics::new();
                let t = Instant::now();
                let mut loaded = load::load(job.inputs(), &opts, &mut diags);
                l += t.elapsed();
                if diags.has_errors() {
                    loaded.files.clear(); // as `compile` does
                }
                let t = Instant::now();
                let model = resolve::resolve(loaded, &mut diags);
                r += t.elapsed();
                drop(black_box((model, diags)));
            }
            loads.push(ms(l));
            resolves.push(ms(r));
        }
    }

    // Standalone per-file costs, summed over the files each compile loaded.
    let mut costs: HashMap<PathBuf, FileCost> = HashMap::new();
    let reps = if jobs.len() > 1 {
        3
    } else {
        cli.runs.clamp(3, 20)
    };
    let (mut read, mut decode, mut parse_ms) = (0.0, 0.0, 0.0);
    for o in outcomes.iter().filter(|_| !cli.compile_only) {
        for p in &o.loaded_paths {
            let c = *costs.entry(p.clone()).or_insert_with(|| file_cost(p, reps));
            read += c.read;
            decode += c.decode;
            parse_ms += c.parse;
        }
    }
    // Parsing every distinct file once: what a pass would cost if nothing were parsed twice.
    let unique_parse: f64 = costs.values().map(|c| c.read + c.decode + c.parse).sum();
    let unique_nodes: usize = costs.values().map(|c| c.nodes).sum();

    let nodes: usize = outcomes.iter().map(|o| o.nodes).sum();
    let max_nodes = outcomes.iter().map(|o| o.nodes).max().unwrap_or(0);
    let files_loaded: usize = outcomes.iter().map(|o| o.files).sum();
    let errors: usize = outcomes.iter().map(|o| o.errors).sum();
    let warnings: usize = outcomes.iter().map(|o| o.warnings).sum();
    let failed: Vec<&Job> = jobs
        .iter()
        .zip(&outcomes)
        .filter(|(_, o)| o.errors > 0)
        .map(|(j, _)| j)
        .collect();

    // Details for people.
    if jobs.len() > 1 {
        let mut slow: Vec<(f64, usize)> = per_job
            .iter()
            .enumerate()
            .map(|(j, t)| (median(t), j))
            .collect();
        slow.sort_by(|a, b| b.0.total_cmp(&a.0));
        eprintln!("slowest compiles (median ms, nodes, files loaded):");
        for &(t, j) in slow.iter().take(8) {
            eprintln!(
                "  {t:9.2}  {:7} {:3}  {}",
                outcomes[j].nodes, outcomes[j].files, jobs[j].label
            );
        }
        if !failed.is_empty() {
            eprintln!("{} compile(s) reported errors:", failed.len());
            for j in &failed {
                eprintln!("  {}", j.label);
            }
        }
    } else if let Some(o) = outcomes.first() {
        if o.errors > 0 {
            eprintln!(
                "warning: the compile reported {} error(s); timings may not be representative",
                o.errors
            );
        }
    }

    let load_med = median(&loads);
    Line::new()
        .kv("scenario", &cli.scenario)
        .kv("runs", cli.runs)
        .kv("compiles", jobs.len())
        .stats("total", &totals, 3)
        .num("cpu_median_ms", median(&cpu), 3)
        .num("cpu_min_ms", min(&cpu), 3)
        .num("drop_median_ms", median(&drops), 3)
        .num("load_median_ms", load_med, 3)
        .num("resolve_median_ms", median(&resolves), 3)
        .num("read_ms", read, 3)
        .num("decode_ms", decode, 3)
        .num("parse_ms", parse_ms, 3)
        .num("load_other_ms", if cli.split { load_med - read - decode - parse_ms } else { 0.0 }, 3)
        .kv("unique_files", costs.len())
        .num("unique_parse_ms", unique_parse, 3)
        .kv("unique_nodes", unique_nodes)
        .kv("hwm_start_kib", hwm_start)
        .kv("hwm_kib", hwm_first)
        .kv("hwm_all_runs_kib", hwm_runs)
        .kv("nodes", nodes)
        .kv("max_nodes", max_nodes)
        .kv("files_loaded", files_loaded)
        .kv("failed_compiles", failed.len())
        .kv("errors", errors)
        .kv("warnings", warnings)
        .print();
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("load_bench: {e}");
            ExitCode::FAILURE
        }
    }
}
