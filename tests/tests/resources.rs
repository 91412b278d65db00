//! Resource bounds on large inputs (bounds on deep nesting and long texts are bad-input cases in
//! `diagnostics.rs`: `deep_nesting`, `deep_value_nesting`, `text_too_long`, `value_text_too_long`,
//! `attribute_too_long`).
//!
//! The synthetic models come from `nodeset_tests::synth` and are written to the target's temporary folder,
//! never committed. Times are not asserted (the machine is shared); `cargo xtask bench --scenario scale`
//! reports how time grows with the input.

use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use nodeset_tests::synth::{self, Shape};
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// Peak resident memory allowed for `nodeset-compiler check` of the 50 MB model (with the base namespace
/// from `nodesets/vendor`), in MiB. Measured (ru_maxrss via wait4, 2 cores), for a 50.0 MiB file of
/// 100,210 nodes: 334-336 MiB with the release build, 333-337 MiB with the test profile's build (three
/// runs each). The bound leaves a third more for allocator and thread-timing noise, and fails if memory per
/// input byte grows noticeably.
const PEAK_RSS_MIB_50MB: u64 = 450;

/// Every shape the bench and this file use is a valid model: it resolves without a diagnostic, so the
/// bench measures the work a correct model causes.
#[test]
fn synthetic_models_resolve_cleanly() {
    for shape in Shape::ALL {
        let text = synth::nodeset(shape, 300);
        let opts = Options { model_dirs: vec![nodeset_tests::vendor()], all_warnings: true, ..Options::default() };
        let out = compile(vec![Input::Text { name: format!("{}.xml", shape.name()), text }], &opts);
        assert!(out.diagnostics.items.is_empty(), "{}:\n{}", shape.name(), out.render_diagnostics());
        let ns = out.model.namespaces.iter().position(|u| u == synth::URI).expect("the synthetic namespace is loaded") as u16;
        let nodes = out.model.nodes.iter().filter(|n| n.id.ns == ns).count();
        assert!((300..=303).contains(&nodes), "{}: {nodes} nodes", shape.name());
        // The depths computed in one pass are those of the chains.
        let depths = out.model.type_depths();
        assert_eq!(depths.len(), out.model.nodes.len());
        for (i, &depth) in depths.iter().enumerate() {
            let ix = nodeset_compiler::model::NodeIx(i as u32);
            assert_eq!(depth as usize + 1, out.model.super_chain(ix).len(), "{}: type depth of {}", shape.name(), out.model.qualified(ix));
        }
    }
}

/// Runs `exe args` to its end and returns (exit success, stdout, peak resident memory in KiB).
// The child is reaped by wait4 (which also gives its rusage), not by `Child::wait`.
#[allow(clippy::zombie_processes)]
fn run_measured(exe: &std::path::Path, args: &[&std::ffi::OsStr]) -> (bool, String, u64) {
    let child = Command::new(exe).args(args).stdout(Stdio::piped()).stderr(Stdio::null()).spawn().expect("the command starts");
    let pid = child.id() as libc::pid_t;
    let mut stdout = child.stdout.expect("stdout is piped");
    // The child writes a few lines; read them on another thread so it never blocks on a full pipe.
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut stdout, &mut s).map(|_| s)
    });
    let mut status: libc::c_int = 0;
    // SAFETY: `rusage` is plain data that wait4 fills in; `pid` is our own child, which nothing else waits
    // for (the `Child` handle was consumed above, so std never reaps it).
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let waited = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(waited, pid, "wait4 failed: {}", std::io::Error::last_os_error());
    let out = reader.join().expect("the reader thread ends").expect("stdout is UTF-8");
    let ok = libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0;
    // On Linux ru_maxrss is in KiB.
    (ok, out, usage.ru_maxrss as u64)
}

/// A 50 MB model loads (`nodeset-compiler check`) within [`PEAK_RSS_MIB_50MB`].
#[test]
fn fifty_megabytes_load_within_a_memory_bound() {
    let text = synth::of_size(50 << 20);
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("synth-50mb.NodeSet2.xml");
    std::fs::write(&path, &text).expect("write the synthetic model");
    let exe = nodeset_tests::command_binary();
    let vendor = nodeset_tests::vendor();
    let args = [std::ffi::OsStr::new("check"), path.as_os_str(), std::ffi::OsStr::new("--models"), vendor.as_os_str()];
    let (ok, stdout, peak_kib) = run_measured(&exe, &args);
    let _ = std::fs::remove_file(&path);
    assert!(ok, "nodeset-compiler check failed on the 50 MB model:\n{stdout}");
    let nodes = text.matches("<UAVariable ").count() + text.matches("<UAObject ").count() + text.matches("<UAObjectType ").count();
    assert!(stdout.contains(&format!("{nodes} nodes")), "all {nodes} nodes are loaded:\n{stdout}");
    let peak_mib = peak_kib / 1024;
    eprintln!("50 MB model ({} bytes, {nodes} nodes): peak RSS {peak_mib} MiB", text.len());
    assert!(peak_mib <= PEAK_RSS_MIB_50MB, "peak RSS {peak_mib} MiB exceeds the bound of {PEAK_RSS_MIB_50MB} MiB");
}

/// Generates Rust and Modelica for a synthetic model, returning the files and the rendered diagnostics.
fn generate_both(text: String) -> (Vec<nodeset_compiler::write::OutFile>, nodeset_compiler::diag::Diagnostics) {
    use nodeset_compiler::emit::{modelica, rust};
    let opts = Options { model_dirs: vec![nodeset_tests::vendor()], ..Options::default() };
    let out = compile(vec![Input::Text { name: "synth.xml".into(), text }], &opts);
    assert!(out.ok(), "{}", out.render_diagnostics());
    let cfg = rust::RustConfig {
        namespaces: vec![rust::RustNamespace { uri: synth::URI.into(), module: "synth".into() }],
        extern_paths: Default::default(),
        runtime_path: rust::RustPath::new("nodeset_models::runtime").unwrap(),
        command: "test".into(),
    };
    let r = rust::generate(&out.model, &cfg);
    let m = modelica::generate_with_diagnostics(&out.model, &modelica::ModelicaConfig::new().namespace(synth::URI));
    let mut diags = r.diagnostics;
    diags.extend(m.diagnostics);
    let mut files = r.files;
    files.extend(m.files);
    (files, diags)
}

/// A 2,000-level object hierarchy (it overflowed the Modelica emitter's stack) and 300-character
/// BrowseNames (they made class files whose names the file system refuses) generate both back ends: the
/// hierarchy is cut at 64 levels with an NS0302 warning, and every file name stays within the limit.
#[test]
fn deep_hierarchies_and_long_names_generate() {
    let (files, diags) = generate_both(synth::nodeset(Shape::DeepInstances, 2000));
    assert!(!diags.has_errors());
    let cut: Vec<_> = diags.items.iter().filter(|d| d.code.as_str() == "NS0302" && d.message.contains("nested more than 64 levels")).collect();
    assert_eq!(cut.len(), 1, "one warning where the hierarchy is cut: {:?}", diags.items.iter().map(|d| &d.message).collect::<Vec<_>>());

    let long = "Very".repeat(75);
    let text = synth::nodeset(Shape::Mixed, 20).replace("1:DeviceType0\"", &format!("1:{long}\"")).replace("1:Device0\"", &format!("1:{long}X\""));
    let (files_long, diags) = generate_both(text);
    assert!(!diags.has_errors());
    for f in files.iter().chain(&files_long) {
        for part in f.path.iter() {
            let len = part.len();
            assert!(len <= nodeset_compiler::names::MAX_IDENT_LEN + 3, "{}: a path component of {len} bytes", f.path.display());
        }
    }
    assert!(files_long.iter().any(|f| f.contents.contains(&long)), "the original BrowseName is kept in the output");
}
