//! Generation is a pure function of the input files: the Rust and Modelica for DI, IA, Robotics and our
//! three skill nodesets (with the pinned base namespace from `nodesets/vendor`) are the same bytes
//!
//! 1. generated twice in this process,
//! 2. with the input files in reverse order,
//! 3. by the `nodeset-compiler` command started in another working directory with relative paths, and
//! 4. by the command started in a temporary directory with absolute paths, in reverse order.
//!
//! In-process generation uses the configuration the command uses (module names from the URIs, the same
//! header command), so all four runs are compared file by file, byte by byte.

use nodeset_compiler::emit::modelica::{generate_with_diagnostics, ModelicaConfig};
use nodeset_compiler::emit::rust::{self as rust_emit, RustConfig, RustNamespace, RustPath};
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Every generated file by `rust/<path>` or `modelica/<path>`.
type Output = BTreeMap<String, Vec<u8>>;

/// The named inputs: the companion specs and our skills (the base namespace comes from `--models`).
fn inputs() -> Vec<PathBuf> {
    let root = nodeset_tests::root();
    let vendor = nodeset_tests::vendor();
    let mut files: Vec<PathBuf> = ["Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.IA.NodeSet2.xml", "Opc.Ua.Robotics.NodeSet2.xml"]
        .iter()
        .map(|f| vendor.join(f))
        .collect();
    for f in ["CommonSkills.NodeSet2.xml", "RobotCell.NodeSet2.xml", "DrillingProcess.NodeSet2.xml"] {
        files.push(root.join("nodesets").join(f));
    }
    for f in &files {
        assert!(f.is_file(), "{} is missing; run `cargo xtask fetch-nodesets`", f.display());
    }
    files
}

/// What `nodeset-compiler rust` and `nodeset-compiler modelica` write for these files, generated in-process.
fn in_process(files: &[PathBuf]) -> Output {
    let opts = Options { model_dirs: vec![nodeset_tests::vendor()], ..Options::default() };
    let out = compile(files.iter().cloned().map(Input::Path).collect(), &opts);
    assert!(out.ok(), "the inputs compile:\n{}", out.render_diagnostics());
    let model = &out.model;
    let command = "nodeset-compiler rust ...";
    let namespaces: Vec<RustNamespace> = model
        .models
        .iter()
        .filter(|m| model.sources.get(m.file).named)
        .map(|m| RustNamespace { uri: m.uri.clone(), module: rust_emit::default_module_name(&m.uri) })
        .collect();
    assert_eq!(namespaces.len(), 6, "DI, IA, Robotics and the three skill models are generated");
    let cfg = RustConfig {
        namespaces: namespaces.clone(),
        extern_paths: Default::default(),
        runtime_path: RustPath::new("nodeset_models::runtime").unwrap(),
        command: command.into(),
    };
    let mut rust = rust_emit::generate(model, &cfg);
    assert!(!rust.diagnostics.has_errors(), "{}", rust.diagnostics.render(&model.sources));
    rust.files.extend(rust_emit::top_files(model, &cfg));
    let modelica = generate_with_diagnostics(model, &ModelicaConfig::new());
    assert!(!modelica.diagnostics.has_errors(), "{}", modelica.diagnostics.render(&model.sources));
    let mut files = Output::new();
    for (kind, list) in [("rust", &rust.files), ("modelica", &modelica.files)] {
        for f in list {
            let key = format!("{kind}/{}", f.path.display());
            assert!(files.insert(key.clone(), f.contents.clone().into_bytes()).is_none(), "{key} generated twice");
        }
    }
    files
}

/// Runs the command's `rust` and `modelica` subcommands in `cwd` with `files` and `models` as given (relative
/// to `cwd` or absolute), writing below `out`, and reads back what they wrote.
fn by_command(exe: &Path, cwd: &Path, files: &[PathBuf], models: &Path, out: &Path) -> Output {
    let _ = std::fs::remove_dir_all(out);
    let mut files_out = Output::new();
    for kind in ["rust", "modelica"] {
        let dir = out.join(kind);
        let status = Command::new(exe)
            .current_dir(cwd)
            .arg(kind)
            .args(files)
            .arg("--models")
            .arg(models)
            .arg("--out")
            .arg(&dir)
            .stderr(Stdio::null())
            .status()
            .expect("the command runs");
        assert!(status.success(), "nodeset-compiler {kind} failed in {}", cwd.display());
        for (path, bytes) in read_tree(&dir) {
            files_out.insert(format!("{kind}/{path}"), bytes);
        }
    }
    files_out
}

fn read_tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<(String, Vec<u8>)>) {
        for e in std::fs::read_dir(dir).expect("readable").flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push((p.strip_prefix(base).unwrap().display().to_string(), std::fs::read(&p).expect("readable")));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out
}

/// Panics naming the first file that differs (or exists in one output only).
fn assert_same(what: &str, a: &Output, b: &Output) {
    for (path, bytes) in a {
        match b.get(path) {
            None => panic!("{what}: {path} is missing"),
            Some(other) if other != bytes => {
                let at = bytes.iter().zip(other).position(|(x, y)| x != y).unwrap_or(bytes.len().min(other.len()));
                let line = bytes[..at].iter().filter(|&&c| c == b'\n').count() + 1;
                panic!("{what}: {path} differs first at byte {at} (line {line})");
            }
            Some(_) => {}
        }
    }
    if let Some(extra) = b.keys().find(|k| !a.contains_key(*k)) {
        panic!("{what}: {extra} is new");
    }
}

#[test]
fn generation_is_byte_identical_across_runs_orders_and_directories() {
    let root = nodeset_tests::root();
    let files = inputs();
    let first = in_process(&files);
    assert!(first.keys().any(|k| k.starts_with("rust/")) && first.keys().any(|k| k.starts_with("modelica/")));

    assert_same("a second run", &first, &in_process(&files));
    let reversed: Vec<PathBuf> = files.iter().rev().cloned().collect();
    assert_same("the inputs in reverse order", &first, &in_process(&reversed));

    // The command, started in nodesets/vendor with paths relative to it.
    let exe = nodeset_tests::command_binary();
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("determinism");
    let vendor = nodeset_tests::vendor();
    let relative: Vec<PathBuf> = files
        .iter()
        .map(|f| match f.strip_prefix(&vendor) {
            Ok(rel) => rel.to_path_buf(),
            Err(_) => Path::new("../").join(f.strip_prefix(root.join("nodesets")).expect("our nodesets are in nodesets/")),
        })
        .collect();
    let by_relative = by_command(&exe, &vendor, &relative, Path::new("."), &tmp.join("relative"));
    assert_same("the command in nodesets/vendor with relative paths", &first, &by_relative);

    // The command, started in an empty temporary folder with absolute paths, in reverse order.
    let elsewhere = tmp.join("cwd");
    std::fs::create_dir_all(&elsewhere).expect("create a working directory");
    let by_absolute = by_command(&exe, &elsewhere, &reversed, &vendor, &tmp.join("absolute"));
    assert_same("the command elsewhere with absolute paths in reverse order", &first, &by_absolute);
}
