//! The peer, async-opcua-codegen 0.19: installed once into `target/bench-tools`, given a config and a crate
//! around its output, timed on the inputs of our generation (the `rust` scenario), and its whole
//! DI + Robotics run timed around our measurements as the yardstick of the host's speed.

use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use bench_support::Report;

use super::builds::{cargo, exec, time_builds, Builds, RELEASE_RUNS};
use super::size::{count_rs, Sizes};
use super::{build, verdict, Args, Step, NAMESPACES};
use process_support::workspace::display_path;

/// The XML schema of ns0 in the tree.
const NS0_XSD: &str = "Schema/Opc.Ua.Types.xsd";
pub(super) const PEER: &str = "async-opcua-codegen";
pub(super) const PEER_VERSION: &str = "0.19.0";
pub(super) const PEER_CRATE: &str = "codegen-peer-models";
/// The file touched before an incremental build of the peer's crate (its Robotics types module).
const PEER_TOUCHED: &str = "src/robotics/types/mod.rs";

/// What the peer produced; every part may be missing, with the reason.
pub(super) struct Peer {
    pub(super) exe: Step<PathBuf>,
    pub(super) install_s: Option<f64>,
    pub(super) config: Option<PathBuf>,
    pub(super) gen: Step<Report>,
    pub(super) sizes: Step<Sizes>,
    pub(super) debug: Step<Builds>,
    pub(super) release: Step<Builds>,
}

/// The XML schemas the peer's nodes targets need (ns0's, then each namespace's, from the UA-Nodeset tree).
fn schemas(tree: &Path) -> Step<Vec<PathBuf>> {
    let schemas: Vec<PathBuf> = std::iter::once(NS0_XSD)
        .chain(NAMESPACES.iter().map(|n| n.3))
        .map(|x| tree.join(x))
        .collect();
    match schemas.iter().find(|p| !p.is_file()) {
        Some(missing) => Err(format!(
            "its nodes target needs the XML schemas (.xsd) of ns0 and of each model, and {} is missing (give the \
             UA-Nodeset tree with --tree DIR)",
            missing.display()
        )),
        None => Ok(schemas),
    }
}

/// Installs and runs the peer on DI + IA + Robotics and builds its output; never fails, every part records
/// why it is missing.
pub(super) fn run_peer(
    args: &Args,
    root: &Path,
    tree: &Path,
    vendor: &Path,
    target: &Path,
    bench: &Path,
) -> Peer {
    let mut peer = Peer {
        exe: Err(String::new()),
        install_s: None,
        config: None,
        gen: Err("not run".into()),
        sizes: Err("not run".into()),
        debug: Err("not run".into()),
        release: Err("skipped (--no-release)".into()),
    };
    let (exe, install_s) = ensure_peer(root);
    peer.exe = exe;
    peer.install_s = install_s;
    let Ok(exe) = peer.exe.clone() else {
        return peer;
    };

    // The config: a types and a nodes target per namespace, in a crate folder of our own.
    let dir = target.join("peer");
    let schemas = match schemas(tree) {
        Ok(s) => s,
        Err(e) => {
            peer.gen = Err(format!("impractical here: {e}"));
            return peer;
        }
    };
    let config = dir.join("codegen.yml");
    if let Err(e) = write_peer_crate(root, &dir, vendor, &schemas) {
        peer.gen = Err(e);
        return peer;
    }
    peer.config = Some(config.clone());

    eprintln!("rust: {PEER} ({} run(s)) ...", args.runs_process.max(1));
    peer.gen = exec(
        bench,
        args.runs_process,
        &dir,
        &[("RUST_LOG", "warn")],
        &exe,
        &[config.display().to_string()],
    );
    if peer.gen.is_err() {
        return peer;
    }
    peer.sizes = NAMESPACES
        .iter()
        .map(|n| Ok((n.0, count_rs(&dir.join("src").join(n.0))?)))
        .collect();

    if args.no_builds {
        peer.debug = Err("skipped (--no-builds)".into());
        peer.release = Err("skipped (--no-builds)".into());
        return peer;
    }
    let touched = dir.join(PEER_TOUCHED);
    eprintln!("rust: building the {PEER} output (debug) ...");
    peer.debug = time_builds(
        bench,
        &dir,
        target,
        PEER_CRATE,
        false,
        Some(&touched),
        args.runs_build,
    );
    if !args.no_release {
        eprintln!("rust: building the {PEER} output (release) ...");
        peer.release = time_builds(
            bench,
            &dir,
            target,
            PEER_CRATE,
            true,
            Some(&touched),
            RELEASE_RUNS,
        );
    }
    peer
}

/// The peer ready to run on DI + IA + Robotics, types and nodes of all three (the inputs of our `rust`
/// command in the `rust` and `generation` scenarios): its executable, the folder it runs in (with its
/// config, `codegen.yml`, written under `target/bench-build/peer-generation`) and the config.
pub(super) fn prepare_three(root: &Path, tree: &Path) -> Step<(PathBuf, PathBuf, PathBuf)> {
    let exe = ensure_peer(root).0?;
    let dir = root.join("target/bench-build/peer-generation");
    let schemas = schemas(tree)?;
    write_peer_config(&dir, &root.join("nodesets/vendor"), &schemas, &["di", "ia", "robotics"], "DI + IA + Robotics")?;
    let config = dir.join("codegen.yml");
    Ok((exe, dir, config))
}

/// async-opcua-codegen's executable in `target/bench-tools`, installed there first if it is missing, and
/// how long the installation took.
fn ensure_peer(root: &Path) -> (Step<PathBuf>, Option<f64>) {
    let tools = root.join("target/bench-tools");
    let exe = tools
        .join("bin")
        .join(format!("{PEER}{}", env::consts::EXE_SUFFIX));
    let installed = fs::read_to_string(tools.join(".crates.toml"))
        .is_ok_and(|t| t.contains(&format!("{PEER} {PEER_VERSION} ")));
    if !(exe.is_file() && installed) {
        eprintln!(
            "rust: installing {PEER} {PEER_VERSION} into {} (once) ...",
            display_path(&tools)
        );
        let tools_arg = tools.display().to_string();
        let t = Instant::now();
        let r = cargo(
            root,
            None,
            &[
                "install",
                PEER,
                "--version",
                PEER_VERSION,
                "--locked",
                "--root",
                &tools_arg,
            ],
        );
        let installed = r.map(|_| exe);
        return (installed, Some(t.elapsed().as_secs_f64()));
    }
    (Ok(exe), None)
}

/// The peer as the issues measured it on this machine: its whole DI + Robotics run (the foundation issue)
/// and the cold debug build of its generated crate (the Rust back-end issue). Their ratio to what the
/// peer takes in the same run of this bench says how fast the shared host is right now.
pub(super) const PEER_RUN_STATED_MS: f64 = 250.0;
pub(super) const PEER_BUILD_STATED_S: f64 = 2.7;

/// The peer's whole DI + Robotics run timed in this bench: the yardstick of the host's speed.
pub(super) struct Yardstick {
    pub(super) median_ms: f64,
    pub(super) min_ms: f64,
    pub(super) runs: usize,
}

impl Yardstick {
    /// How much slower than when the issue measured the peer (> 1: slower).
    pub(super) fn slowdown(&self) -> f64 {
        self.median_ms / PEER_RUN_STATED_MS
    }
}

/// The peer's whole DI + Robotics run, ready to be timed: `rust_bench` as the stopwatch, the peer and its
/// config for DI + Robotics (types and nodes of both; ns0 and IA, which Robotics 1.02 requires, loaded
/// as dependencies) in `target/bench-build/peer-di-robotics`.
pub(super) struct PeerRun {
    bench: PathBuf,
    exe: PathBuf,
    dir: PathBuf,
    config: String,
}

/// Takes the yardstick around measured work; holds nothing with `--no-peer`, or why the peer cannot run.
pub(super) struct Yardsticks {
    pub(super) peer: Option<Step<PeerRun>>,
    runs: usize,
}

impl Yardsticks {
    /// Installs the peer once if needed and writes its config (unless `args.no_peer`).
    pub(super) fn new(args: &Args, root: &Path, tree: &Path) -> Yardsticks {
        let peer = (!args.no_peer).then(|| PeerRun::prepare(root, tree));
        Yardsticks {
            peer,
            runs: args.runs_process,
        }
    }

    /// Runs `work` between two timings of the peer (`what` names the work in the progress lines); the
    /// yardstick is None with `--no-peer`.
    pub(super) fn around<T>(
        &self,
        what: &str,
        work: impl FnOnce() -> T,
    ) -> (T, Option<Step<Yardstick>>) {
        let time = |when: &str| {
            self.peer.as_ref().map(|peer| {
                let peer = peer.as_ref().map_err(Clone::clone)?;
                eprintln!("the peer's DI + Robotics run as a yardstick ({when} {what}) ...");
                peer.time(self.runs)
            })
        };
        let before = time("before");
        let out = work();
        let after = time("after");
        (out, before.zip(after).map(|(b, a)| Ok(yardstick(&b?, &a?))))
    }
}

impl PeerRun {
    /// `runs` timed runs of the peer on DI + Robotics.
    pub(super) fn time(&self, runs: usize) -> Step<Report> {
        exec(&self.bench, runs, &self.dir, &[("RUST_LOG", "warn")], &self.exe, std::slice::from_ref(&self.config))
    }

    /// Installs the peer if needed, builds the stopwatch and writes the DI + Robotics config.
    fn prepare(root: &Path, tree: &Path) -> Step<PeerRun> {
        let (exe, _) = ensure_peer(root);
        let exe = exe?;
        let bench = build(root, "nodeset-compiler", "rust_bench", &["--bin", "nodeset-compiler"])?;
        let vendor = root.join("nodesets/vendor");
        let dir = root.join("target/bench-build/peer-di-robotics");
        let schemas = schemas(tree)?;
        write_peer_config(
            &dir,
            &vendor,
            &schemas,
            &["di", "robotics"],
            "DI + Robotics",
        )?;
        let config = dir.join("codegen.yml").display().to_string();
        Ok(PeerRun {
            bench,
            exe,
            dir,
            config,
        })
    }
}

/// The yardstick from the peer's runs before and after the measured work.
fn yardstick(before: &Report, after: &Report) -> Yardstick {
    let runs = |r: &Report| r.f("runs").max(0.0) as usize;
    let (a, b) = (runs(before), runs(after));
    Yardstick {
        median_ms: (before.f("wall_median_ms") * a as f64
            + after.f("wall_median_ms") * b as f64)
            / (a + b).max(1) as f64,
        min_ms: before.f("wall_min_ms").min(after.f("wall_min_ms")),
        runs: a + b,
    }
}

/// A target scaled by the host's slowdown, and the verdict against it.
/// Prints how the peer's runs around ours judge `ours_ms` against `target_ms`: the host's slowdown, the
/// scaled target, and ours / peer beside the target's own ratio.
pub(super) fn print_judged(yard: Option<&Result<Yardstick, String>>, ours_ms: f64, target_ms: f64) {
    match yard {
        Some(Ok(y)) => {
            println!(
                "   peer     {PEER} {PEER_VERSION}, its whole DI + Robotics run, {} run(s) around ours: median {:.1} ms, min {:.1} ms;",
                y.runs, y.median_ms, y.min_ms
            );
            println!(
                "            the issue measured {PEER_RUN_STATED_MS} ms on this machine, so the host is {:.2}x as slow now: {}",
                y.slowdown(),
                scaled(ours_ms, target_ms, y.slowdown(), "ms")
            );
            println!(
                "            (ours / peer = {:.3}; the target's ratio is {target_ms} / {PEER_RUN_STATED_MS} = {:.3})",
                ours_ms / y.median_ms,
                target_ms / PEER_RUN_STATED_MS
            );
        }
        Some(Err(e)) => println!("   peer     not measured: {e}"),
        None => println!("   peer     not measured (--no-peer): the target is not scaled to the host's speed"),
    }
}

pub(super) fn scaled(value: f64, target: f64, slowdown: f64, unit: &str) -> String {
    let limit = target * slowdown;
    format!(
        "scaled target <= {limit:.2} {unit}  {}",
        verdict(value, limit)
    )
}

/// A YAML string (a JSON string is one).
fn yaml(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Writes `dir/codegen.yml`: all four NodeSet2 files and the XML schemas as sources, and a `types` and a
/// `nodes` target for each module of `targets` (the others are only loaded, as dependencies).
fn write_peer_config(
    dir: &Path,
    vendor: &Path,
    schemas: &[PathBuf],
    targets: &[&str],
    what: &str,
) -> Step<()> {
    let xsd_name = |p: &PathBuf| {
        p.file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let mut cfg = format!(
        "# Written by `cargo xtask bench`: async-opcua-codegen on {what}.\n\
         # Paths are absolute; outputs are relative to this file.\nsources:\n"
    );
    cfg.push_str(&format!(
        "  - {}\n",
        yaml(&vendor.join("Opc.Ua.NodeSet2.xml").display().to_string())
    ));
    for n in NAMESPACES {
        cfg.push_str(&format!(
            "  - {}\n",
            yaml(&vendor.join(n.1).display().to_string())
        ));
    }
    for s in schemas {
        cfg.push_str(&format!("  - {}\n", yaml(&s.display().to_string())));
    }
    cfg.push_str("targets:\n");
    for (i, (module, file, _, _)) in NAMESPACES.iter().enumerate() {
        if !targets.contains(module) {
            continue;
        }
        cfg.push_str(&format!(
            "  - type: types\n    file: {file}\n    output_dir: src/{module}/types\n    node_ids_from_nodeset: true\n"
        ));
        if i > 0 {
            cfg.push_str("    dependent_nodesets:\n");
            for (dep, dep_file, _, _) in &NAMESPACES[..i] {
                cfg.push_str(&format!(
                    "      - file: {dep_file}\n        import_path: crate::{dep}::types\n"
                ));
            }
        }
        let name = format!("{}{}Namespace", module[..1].to_uppercase(), &module[1..]);
        cfg.push_str(&format!(
            "  - type: nodes\n    file: {file}\n    output_dir: src/{module}/nodes\n    max_nodes_per_file: 100\n    \
             name: {name}\n    types:\n      - file: {}\n        root_path: opcua::types\n      - file: {}\n        \
             root_path: crate::{module}::types\n",
            xsd_name(&schemas[0]),
            xsd_name(&schemas[i + 1]),
        ));
    }
    let path = dir.join("codegen.yml");
    fs::create_dir_all(dir)
        .and_then(|()| fs::write(&path, cfg))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Writes the codegen config, `Cargo.toml` and `src/lib.rs` of the peer's crate.
fn write_peer_crate(root: &Path, dir: &Path, vendor: &Path, schemas: &[PathBuf]) -> Step<()> {
    write_peer_config(dir, vendor, schemas, &["di", "ia", "robotics"], "the inputs of generated/")?;
    let mut lib = String::from(
        "//! async-opcua-codegen's output for DI, IA and Robotics. Written by `cargo xtask bench`; only this file\n\
         //! is not generated.\n#![allow(warnings)]\n\n",
    );
    for n in NAMESPACES {
        lib.push_str(&format!("pub mod {} {{\n    pub mod nodes;\n    pub mod types;\n}}\n", n.0));
    }
    let manifest = "[dependencies]\nasync-opcua = { version = \"=0.19.0\", features = [\"server\"] }\nbitflags = \"2\"\n";
    write_crate(root, dir, PEER_CRATE, "a crate around async-opcua-codegen's output", manifest, "src/lib.rs", &lib)
}

/// Writes a crate of its own in `dir`, built beside the workspace in the bench's target folder: its
/// `Cargo.toml` (`what` says what it is; `manifest` holds its `[lib]` and `[dependencies]`), its library
/// root `lib_path` with `lib`, and the workspace's lock file and profiles, so that it builds against the
/// same dependency versions, compiled the same way, sharing the dependencies' builds.
pub(super) fn write_crate(
    root: &Path,
    dir: &Path,
    name: &str,
    what: &str,
    manifest: &str,
    lib_path: &str,
    lib: &str,
) -> Step<()> {
    let write = |path: PathBuf, text: &str| {
        fs::create_dir_all(path.parent().unwrap_or(dir))
            .and_then(|()| fs::write(&path, text))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    let toml = format!(
        "# Written by `cargo xtask bench --scenario rust`: {what}.\n\
         [package]\nname = \"{name}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [workspace]\n\n[features]\njson = [\"async-opcua/json\"]\nxml = [\"async-opcua/xml\"]\n\n{manifest}\n\
         # The workspace's profiles.\n\
         [profile.dev.package.\"*\"]\nopt-level = 2\n\n[profile.release]\ndebug = 1\n"
    );
    write(dir.join("Cargo.toml"), &toml)?;
    write(dir.join(lib_path), lib)?;
    let _ = fs::copy(root.join("Cargo.lock"), dir.join("Cargo.lock"));
    Ok(())
}
