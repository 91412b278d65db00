//! Modelica generation time for DI + IA + Robotics, with the base namespace as a dependency (its needed
//! subset emitted as `OpcUa`): the time of `emit::modelica::generate` alone, loading excluded.
//!
//! ```text
//! cargo run --release -p nodeset-compiler --example modelica_bench [-- RUNS]
//! ```
//!
//! Prints the median and the minimum over RUNS runs (default 50) and the size of the output, and the same as a
//! `BENCH` line for `cargo xtask bench --scenario modelica`, which times it between runs of the peer (the
//! yardstick of the host's speed) and judges the median against the 20 ms target scaled by that yardstick.

use nodeset_compiler::emit::modelica::{generate, ModelicaConfig};
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn main() {
    let runs: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(50).max(1);
    let vendor = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../nodesets/vendor");
    let t = Instant::now();
    let out = compile(
        vec![Input::Path(vendor.join("Opc.Ua.Robotics.NodeSet2.xml"))],
        &Options { model_dirs: vec![vendor.clone()], ..Options::default() },
    );
    if !out.ok() {
        eprint!("{}", out.render_diagnostics());
        std::process::exit(1);
    }
    let load = t.elapsed();
    let cfg = ModelicaConfig::new()
        .namespace("http://opcfoundation.org/UA/DI/")
        .namespace("http://opcfoundation.org/UA/IA/")
        .namespace("http://opcfoundation.org/UA/Robotics/");
    let mut times: Vec<Duration> = Vec::with_capacity(runs);
    let mut files = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        files = generate(&out.model, &cfg).unwrap_or_else(|d| panic!("{}", d.render(&out.model.sources)));
        times.push(t.elapsed());
    }
    times.sort();
    let bytes: usize = files.iter().map(|f| f.contents.len()).sum();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let all: Vec<f64> = times.iter().map(|d| ms(*d)).collect();
    bench_support::Line::new()
        .kv("scenario", "modelica")
        .kv("runs", runs)
        .stats("total", &all, 3)
        .kv("files", files.len())
        .kv("bytes", bytes)
        .print();
    println!("loading ns0 + DI + IA + Robotics: {:.1} ms (once)", ms(load));
    println!(
        "Modelica generation, {runs} runs: median {:.2} ms, min {:.2} ms, max {:.2} ms; {} files, {:.1} KiB",
        ms(times[runs / 2]),
        ms(times[0]),
        ms(times[runs - 1]),
        files.len(),
        bytes as f64 / 1024.0
    );
}
