//! The `scale` scenario: how time grows with the size of a model, to find quadratic behaviour.
//!
//! For each shape of `nodeset_tests::synth` (many siblings under one parent, a deep instance hierarchy, a
//! deep subtype chain, many references to one node, many aliases, and a companion-spec-like mix, and the
//! many-aliases model with every alias misspelt, front end only) it builds
//! a model of `n` and of `4n` nodes and times, in this process, the front end (`compile`: parse + load +
//! resolve, with ns0 from `nodesets/vendor`) and the two back ends (`emit::rust::generate`,
//! `emit::modelica::generate_with_diagnostics`). A linear stage takes about 4x as long for 4x the nodes;
//! a quadratic one 16x. The front end's ratio is also shown without the fixed cost of loading ns0 (a
//! compile of an empty model), which otherwise hides growth at small `n`.
//!
//! The times are medians of `--runs` runs, in the xtask build (the compiler at the dev profile's opt-level
//! 2, debug assertions on), so they are for ratios, not for comparison with the release figures above.

use bench_support::{median, ms_since};
use nodeset_compiler::emit::modelica::{generate_with_diagnostics, ModelicaConfig};
use nodeset_compiler::emit::rust as rust_emit;
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Compiled, Options, RustOptions};
use nodeset_tests::synth::{self, Shape};
use std::path::Path;
use std::time::Instant;

/// Times of one model: front end, Rust, Modelica, in ms.
#[derive(Clone, Copy)]
struct Times {
    front: f64,
    rust: f64,
    modelica: f64,
}

/// One compile of a synthetic model, with ns0 from `vendor`.
fn compile_text(vendor: &Path, text: &str) -> Compiled {
    let opts = Options { model_dirs: vec![vendor.to_path_buf()], ..Options::default() };
    compile(vec![Input::Text { name: "synth.xml".into(), text: text.to_string() }], &opts)
}

/// The median times of `runs` runs of each stage on one model.
fn time(vendor: &Path, text: &str, runs: usize) -> Result<Times, String> {
    let (mut front, mut rust, mut modelica) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs {
        let t = Instant::now();
        let out = compile_text(vendor, text);
        front.push(ms_since(t));
        if !out.ok() {
            return Err(format!("a synthetic model does not compile:\n{}", out.render_diagnostics()));
        }
        // The synthetic model's own namespace, as the bench has always timed it (ns0 is async-opcua's).
        let cfg = RustOptions { command: "cargo xtask bench --scenario scale".into(), ..RustOptions::default() }
            .config_of(&[synth::URI.to_string()])
            .map_err(|e| e.to_string())?;
        let t = Instant::now();
        let r = rust_emit::generate(&out.model, &cfg);
        rust.push(ms_since(t));
        std::hint::black_box(&r);
        let t = Instant::now();
        let m = generate_with_diagnostics(&out.model, &ModelicaConfig::new().namespace(synth::URI));
        modelica.push(ms_since(t));
        std::hint::black_box(&m);
    }
    Ok(Times { front: median(&front), rust: median(&rust), modelica: median(&modelica) })
}

/// Runs the scenario and prints its table.
pub(super) fn run(vendor: &Path, n: usize, runs: usize) -> Result<(), String> {
    eprintln!("running scenario `scale` (n = {n}, {runs} run(s) each) ...");
    let runs = runs.max(1);
    let empty = synth::nodeset(Shape::Siblings, 0);
    let base = median(&(0..runs).map(|_| {
        let t = Instant::now();
        std::hint::black_box(compile_text(vendor, &empty));
        ms_since(t)
    }).collect::<Vec<_>>());
    println!();
    println!("Scale: time for n and 4n nodes (medians of {runs} runs; xtask build, for ratios only).");
    println!("front = compile (parse + load + resolve, ns0 included); net = front minus a compile of an empty model ({base:.1} ms).");
    println!("A linear stage shows a ratio near 4, a quadratic one near 16.");
    println!();
    println!(
        "{:<16} {:>7} {:>10} {:>10} {:>7} {:>7} {:>10} {:>10} {:>7} {:>10} {:>10} {:>7}",
        "shape", "n", "front n", "front 4n", "ratio", "net", "rust n", "rust 4n", "ratio", "mo n", "mo 4n", "ratio"
    );
    let mut worst: Vec<String> = Vec::new();
    for shape in Shape::ALL {
        let small = time(vendor, &synth::nodeset(shape, n), runs)?;
        let large = time(vendor, &synth::nodeset(shape, 4 * n), runs)?;
        let ratio = |a: f64, b: f64| if a > 0.0 { b / a } else { f64::NAN };
        let net = ratio(small.front - base, large.front - base);
        let row = [ratio(small.front, large.front), net, ratio(small.rust, large.rust), ratio(small.modelica, large.modelica)];
        println!(
            "{:<16} {:>7} {:>10.1} {:>10.1} {:>7.2} {:>7.2} {:>10.1} {:>10.1} {:>7.2} {:>10.1} {:>10.1} {:>7.2}",
            shape.name(),
            n,
            small.front,
            large.front,
            row[0],
            row[1],
            small.rust,
            large.rust,
            row[2],
            small.modelica,
            large.modelica,
            row[3]
        );
        for (stage, r) in [("front end (net)", row[1]), ("Rust", row[2]), ("Modelica", row[3])] {
            if r > 6.0 {
                worst.push(format!("{} {stage}: {r:.1}x", shape.name()));
            }
        }
    }
    // Unknown aliases: the many-aliases model with every use misspelt, so each is reported (with a search
    // for a suggestion); an invalid model, so the front end only.
    let misspelt = |n: usize| synth::nodeset(Shape::ManyAliases, n).replace("\">Folder", "\">Foldr");
    let front = |text: &str| {
        median(&(0..runs).map(|_| {
            let t = Instant::now();
            let out = compile_text(vendor, text);
            let ms = ms_since(t);
            std::hint::black_box(out.render_diagnostics());
            ms
        }).collect::<Vec<_>>())
    };
    let (small, large) = (front(&misspelt(n)), front(&misspelt(4 * n)));
    let net = (large - base) / (small - base);
    println!("{:<16} {:>7} {:>10.1} {:>10.1} {:>7.2} {:>7.2}   (front end only: every alias use is an error)", "unknown-aliases", n, small, large, large / small, net);
    if net > 6.0 {
        worst.push(format!("unknown-aliases front end (net): {net:.1}x"));
    }
    println!();
    if worst.is_empty() {
        println!("no stage grew more than 6x for 4x the nodes");
    } else {
        println!("grew more than 6x for 4x the nodes (worth a look): {}", worst.join(", "));
    }
    Ok(())
}
