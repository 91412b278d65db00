//! The Modelica back end: snapshots of the fixtures, and real inputs checked by a real Modelica compiler.
//!
//! * one insta snapshot per fixture: every generated file of the fixture's own packages and of the ns0 subset,
//!   concatenated with `// file: <path>` separators, then the rendered diagnostics;
//! * DI + IA + Robotics (with the ns0 subset) and the hand-written example on top of them, checked class by
//!   class by rumoca (`tests/modelica/check.py`), and the example simulated;
//! * every resolvable file of the ua-nodeset corpus and the skill reference models, checked by rumoca one
//!   aggregate model per nodeset;
//! * the checked-in `generated/modelica` (with our skill models), checked class by class by rumoca, and by a
//!   second front end, pymoca (`tests/modelica/check2.py`), which catches what rumoca 0.10.2 lets through
//!   (misspelt nested modifiers, a redeclaration hidden by an outer one);
//! * structural checks (`tests/modelica/structure.py`) of every output above: every modifier names a member,
//!   at any depth, and only connections and modifiers reach a conditional component;
//! * no recursive class: the class graph (extends, components, aliases, redeclarations) of
//!   `generated/modelica`, of every corpus output and of the skill reference models has no cycle;
//! * each of these checks fails on its planted mistake (`tests/modelica/planted`);
//! * what each compiler misreads, and the generator works around, reproduced in small packages and asserted as it
//!   is today (`tests/modelica/RumocaBehaviour`, `tests/modelica/PymocaBehaviour`);
//! * a skill instance of our drilling cell simulated through Start, Halt and Reset (`tests/modelica/SkillExample`);
//! * determinism: same input, byte-identical output, whatever the input order.
//!
//! rumoca and pymoca run in the venv that `cargo xtask venv` creates; a missing venv fails the tests with that
//! command.

use nodeset_compiler::emit::modelica::{generate, generate_with_diagnostics, ModelicaConfig};
use nodeset_compiler::load::{Input, NS0_URI};
use nodeset_compiler::model::Model;
use nodeset_compiler::write::{write_tree, Mode, OutFile};
use nodeset_compiler::{compile, Compiled, Options};
use nodeset_tests::{corpus, nodeset_files, root, vendor};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The fixtures with a snapshot; `every_fixture_has_a_snapshot` keeps the list complete.
const CASES: &[&str] = &[
    "abstract_base",
    "arrays",
    "engineering_units",
    "enum_gaps",
    "event_type",
    "instances",
    "member_ids",
    "method",
    "name_collision",
    "names",
    "option_set",
    "optional_fields",
    "recursive",
    "roles",
    "state_machine",
    "structure",
    "structure_values",
    "two_namespaces",
    "union",
    "variable_type",
    "vendor_robot",
];

fn python() -> PathBuf {
    let py = root().join(".venv/bin/python");
    assert!(
        py.is_file(),
        "{} is missing: run `cargo xtask venv` (it installs rumoca and pymoca from tests/requirements.txt)",
        py.display()
    );
    py
}

fn compile_files(files: &[PathBuf], dirs: Vec<PathBuf>) -> Compiled {
    let out = compile(
        files.iter().map(|f| Input::Path(f.clone())).collect(),
        &Options { model_dirs: dirs, ..Options::default() },
    );
    assert!(out.ok(), "{}", out.render_diagnostics());
    out
}

/// The namespaces a set of files defines (their own models, not the ones they require).
fn own_models(model: &Model) -> Vec<String> {
    let mut uris: Vec<String> = model
        .models
        .iter()
        .filter(|m| model.sources.get(m.file).named && m.uri != NS0_URI)
        .map(|m| m.uri.clone())
        .collect();
    uris.sort();
    uris
}

fn fixture(case: &str) -> Compiled {
    let dir = root().join("tests/fixtures").join(case);
    let files = nodeset_files(&dir);
    assert!(!files.is_empty(), "no NodeSet2 files in {}", dir.display());
    compile_files(&files, vec![dir, vendor()])
}

fn concatenate(files: &[OutFile]) -> String {
    let mut s = String::new();
    for f in files {
        s.push_str(&format!("// file: {}\n", f.path.display()));
        s.push_str(&f.contents);
    }
    s
}

fn snapshot(case: &str) {
    let out = fixture(case);
    let mut cfg = ModelicaConfig::new().support_package(false);
    for uri in own_models(&out.model) {
        cfg = cfg.namespace(uri);
    }
    let g = generate_with_diagnostics(&out.model, &cfg);
    assert!(!g.diagnostics.has_errors(), "{}", g.diagnostics.render(&out.model.sources));
    let mut text = concatenate(&g.files);
    text.push_str("// diagnostics:\n");
    // Paths relative to the workspace root, so the snapshot does not depend on where the checkout is.
    text.push_str(&g.diagnostics.render(&out.model.sources).replace(&format!("{}/", root().display()), ""));
    insta::assert_snapshot!(case, text);
}

macro_rules! snapshots {
    ($($case:ident),* $(,)?) => { $( #[test] fn $case() { snapshot(stringify!($case)); } )* };
}

snapshots!(
    abstract_base,
    arrays,
    engineering_units,
    enum_gaps,
    event_type,
    instances,
    member_ids,
    method,
    name_collision,
    names,
    option_set,
    optional_fields,
    recursive,
    roles,
    state_machine,
    structure,
    structure_values,
    two_namespaces,
    union,
    variable_type,
    vendor_robot,
);

#[test]
fn every_fixture_has_a_snapshot() {
    let mut dirs: Vec<String> = std::fs::read_dir(root().join("tests/fixtures"))
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        // `bad` holds files that stop with errors; `recover` files whose errors are demoted one by one
        // (tests/tests/recovery.rs), which the Modelica snapshots do not do.
        .filter(|n| n != "bad" && n != "recover")
        .collect();
    dirs.sort();
    assert_eq!(dirs, CASES, "add the new fixture to CASES and to the snapshots! list");
}

/// Writes generated files below `dir`, replacing what was there.
fn write(dir: &Path, files: &[OutFile]) {
    let _ = std::fs::remove_dir_all(dir);
    write_tree(dir, files, Mode::Write).unwrap_or_else(|e| panic!("cannot write {}: {e}", dir.display()));
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            copy_dir(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

/// Runs the checker; returns (passed, failed) and the output. The support package, when it is
/// `generated/modelica`'s byte for byte, is left out (`check.py --same-as`, see [`left_out`]): that tree's
/// test checks it class by class, and it refers to nothing outside itself.
fn check(dir: &Path, aggregate: bool) -> (usize, usize, String) {
    let same_as = format!("OpcUaSupport={}", root().join("generated/modelica").display());
    let mut args = vec!["--same-as", same_as.as_str()];
    if aggregate {
        args.extend(["--aggregate", "--jobs", "1"]);
    }
    run_checker("check.py", dir, &args)
}

/// How many classes `check.py --same-as` left out (checked in the reference tree), from its output.
fn left_out(text: &str) -> usize {
    text.lines()
        .filter_map(|l| l.strip_prefix("left out: "))
        .filter_map(|l| l.split_whitespace().next()?.parse::<usize>().ok())
        .sum()
}

/// The checkers of `tests/modelica`: `check.py` (rumoca), `check2.py` (pymoca, the second front end) and
/// `structure.py` (the structural checks, with pymoca's parser).
fn run_checker(script: &str, dir: &Path, args: &[&str]) -> (usize, usize, String) {
    let out = Command::new(python())
        .arg(root().join("tests/modelica").join(script))
        .arg(dir)
        .arg("--quiet")
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run tests/modelica/{script}: {e}"));
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    let last = text
        .lines()
        .rev()
        .find(|l| l.ends_with(" failed"))
        .unwrap_or_else(|| panic!("no summary line from {script}:\n{text}"));
    let nums: Vec<usize> = last.split_whitespace().filter_map(|w| w.parse().ok()).collect();
    assert_eq!(nums.len(), 2, "unexpected summary `{last}` from {script}");
    (nums[0], nums[1], text)
}

/// The classes a checker's `--quiet` output names as failed, sorted.
fn failed_classes(text: &str) -> Vec<String> {
    let mut v: Vec<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix("FAIL "))
        .map(|l| l.split(':').next().unwrap_or(l).to_string())
        .collect();
    v.sort();
    v
}

/// pymoca (`check2.py`) and the structural checks (`structure.py`) over a library; with `only`, pymoca checks
/// only the classes of those packages (the rest is checked elsewhere). Returns a line for the test's output.
fn second_checks(label: &str, dir: &Path, only: &[&str], classes: usize) -> String {
    let mut args = vec![];
    for o in only {
        args.extend(["--only", *o]);
    }
    let t = Instant::now();
    let (p2, f2, text2) = run_checker("check2.py", dir, &args);
    let pymoca_s = t.elapsed().as_secs_f64();
    assert_eq!(f2, 0, "{label}: pymoca rejects classes\n{text2}");
    if only.is_empty() {
        assert_eq!(p2, classes, "{label}: pymoca checks every class\n{text2}");
    } else {
        assert!(p2 > 0, "{label}: pymoca checked nothing\n{text2}");
    }
    let t = Instant::now();
    let (ps, fs, texts) = run_checker("structure.py", dir, &[]);
    let structure_s = t.elapsed().as_secs_f64();
    assert_eq!(fs, 0, "{label}: the structural checks fail\n{texts}");
    assert_eq!(ps, classes, "{label}: the structural checks cover every class\n{texts}");
    format!("{label}: pymoca {p2} passed, 0 failed in {pymoca_s:.1} s; structure {ps} passed, 0 failed in {structure_s:.1} s")
}

fn tmp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("modelica").join(name)
}

#[test]
fn companion_specs_and_the_example_pass_rumoca_and_the_example_simulates() {
    let dir = vendor();
    let out = compile_files(&[dir.join("Opc.Ua.Robotics.NodeSet2.xml")], vec![dir]);
    let cfg = ModelicaConfig::new()
        .namespace("http://opcfoundation.org/UA/DI/")
        .namespace("http://opcfoundation.org/UA/IA/")
        .namespace("http://opcfoundation.org/UA/Robotics/");
    let files = generate(&out.model, &cfg).unwrap_or_else(|d| panic!("{}", d.render(&out.model.sources)));
    let classes = files
        .iter()
        .filter(|f| f.path.extension().is_some_and(|x| x == "mo") && !f.path.ends_with("package.mo"))
        .count();
    let target = tmp("robotics");
    write(&target, &files);
    let example = root().join("tests/modelica/RoboticsExample");
    copy_dir(&example, &target.join("RoboticsExample"));
    let example_classes = std::fs::read_dir(&example)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name() != "package.mo" && e.path().extension().is_some_and(|x| x == "mo"))
        .count();

    let t = Instant::now();
    let (passed, failed, text) = check(&target, false);
    println!(
        "DI + IA + Robotics + ns0 subset + OpcUaSupport + RoboticsExample: {passed} passed, {failed} failed in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    assert_eq!(failed, 0, "{text}");
    assert_eq!(
        passed + left_out(&text),
        classes + example_classes,
        "every generated class and the example are checked (here or in generated/modelica)\n{text}"
    );
    // The second checker flattens the example (and with it the Robotics classes it uses); the generated classes
    // one by one are `generated_tree_passes_pymoca_and_the_structural_checks`'s.
    println!("{}", second_checks("RoboticsExample", &target, &["RoboticsExample"], classes + example_classes));

    // The example: the axis follows its target with a first-order lag, and the generated OPC UA variable
    // ParameterSet/ActualPosition carries the position.
    let axis = simulate(&target, "RoboticsExample.AxisDemo", "0.2");
    let (at_t, end) = value(&axis, "axis.parameterSet.actualPosition");
    let expected = 1.0 - (-1.0f64).exp();
    assert!((at_t - expected).abs() < 1e-3, "ActualPosition at t = T is {at_t}, expected {expected}");
    assert!((end - 1.0).abs() < 1e-3, "ActualPosition at the end is {end}");
    // The robot: each axis of the placeholder follows its own first-order response, y(t) = target*(1 - exp(-t/T))
    // with T = 0.1 s and 0.3 s.
    let robot = simulate(&target, "RoboticsExample.RobotDemo", "0.2");
    let (b1, a1) = value(&robot, "robot.axes.axisIdentifier[1].drive.y");
    let (b2, a2) = value(&robot, "robot.axes.axisIdentifier[2].drive.y");
    let (e1, e2) = (1.0 - (-2.0f64).exp(), -0.5 * (1.0 - (-2.0f64 / 3.0).exp()));
    assert!((b1 - e1).abs() < 1e-3 && (b2 - e2).abs() < 1e-3, "at 0.2 s the axes are at {b1} and {b2}, expected {e1} and {e2}");
    assert!((a1 - 1.0).abs() < 1e-2 && (a2 + 0.5).abs() < 1e-2, "the robot's axes end at {a1} and {a2}");
    // Each axis inside the motion device keeps its own ParameterSet class (AxisType_ParameterSet, with
    // ActualPosition), not the motion device's: rumoca would otherwise let MotionDeviceType's redeclaration of
    // ParameterSet replace it (see tests/modelica/RumocaBehaviour).
    for (i, target_pos) in [(1, 1.0), (2, -0.5)] {
        let (_, p) = value(&robot, &format!("robot.axes.axisIdentifier[{i}].parameterSet.actualPosition"));
        assert!((p - target_pos).abs() < 1e-2, "axis {i}: ParameterSet/ActualPosition ends at {p}");
    }
}

/// Whether the files below `dir` are those below `reference`, byte for byte, apart from the top-level folders
/// `except`; the first difference otherwise.
fn same_tree_except(dir: &Path, reference: &Path, except: &[&str]) -> Result<(), String> {
    fn files(base: &Path, dir: &Path, out: &mut std::collections::BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())).flatten() {
            let p = e.path();
            if p.is_dir() {
                files(base, &p, out);
            } else {
                out.insert(p.strip_prefix(base).unwrap().to_path_buf(), std::fs::read(&p).unwrap());
            }
        }
    }
    let (mut ours, mut theirs) = (std::collections::BTreeMap::new(), std::collections::BTreeMap::new());
    files(dir, dir, &mut ours);
    files(reference, reference, &mut theirs);
    ours.retain(|p, _| !except.iter().any(|x| p.starts_with(x)));
    if let Some(p) = ours.keys().find(|p| !theirs.contains_key(*p)).or_else(|| theirs.keys().find(|p| !ours.contains_key(*p))) {
        return Err(format!("{} is in one tree only", p.display()));
    }
    match ours.iter().find(|(p, bytes)| theirs[*p] != **bytes) {
        Some((p, _)) => Err(format!("{} differs", p.display())),
        None => Ok(()),
    }
}

/// Simulates `model` below `root` with `tests/modelica/simulate.py`; (name, value at `at`, final value).
fn simulate(root_dir: &Path, model: &str, at: &str) -> Vec<(String, f64, f64)> {
    let out = Command::new(python())
        .arg(root().join("tests/modelica/simulate.py"))
        .arg(root_dir)
        .arg(model)
        .arg(at)
        .output()
        .expect("cannot run tests/modelica/simulate.py");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains(&format!("simulated {model}")), "{text}");
    text.lines()
        .filter_map(|l| {
            let mut parts = l.split_whitespace();
            let name = parts.next()?.to_string();
            let at: f64 = parts.next()?.split('@').next()?.parse().ok()?;
            let end: f64 = parts.next()?.split('@').next()?.parse().ok()?;
            Some((name, at, end))
        })
        .collect()
}

/// The value of variable `name` in a [`simulate`] result: (at the requested time, at the end).
fn value(vars: &[(String, f64, f64)], name: &str) -> (f64, f64) {
    vars.iter()
        .find(|v| v.0 == name)
        .map(|v| (v.1, v.2))
        .unwrap_or_else(|| panic!("no variable {name} in {vars:?}"))
}

/// Simulates `model` below `root` with `tests/modelica/simulate.py --strings-as-parameters` (rumoca 0.10.2
/// cannot simulate String variables, see `RumocaBehaviour.StringDemo`); (name, value at each of `times`).
fn simulate_at(root_dir: &Path, model: &str, times: &[f64]) -> Vec<(String, Vec<f64>)> {
    let out = Command::new(python())
        .arg(root().join("tests/modelica/simulate.py"))
        .arg("--strings-as-parameters")
        .arg(root_dir)
        .arg(model)
        .args(times.iter().map(|t| t.to_string()))
        .output()
        .expect("cannot run tests/modelica/simulate.py");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains(&format!("simulated {model}")), "{text}");
    text.lines()
        .filter_map(|l| {
            let mut parts = l.split_whitespace();
            let name = parts.next()?.to_string();
            let values: Option<Vec<f64>> =
                parts.take(times.len()).map(|p| p.split('@').next()?.parse().ok()).collect();
            Some((name, values?))
        })
        .collect()
}

/// The values of variable `name` in a [`simulate_at`] result.
fn values_at(vars: &[(String, Vec<f64>)], name: &str) -> Vec<f64> {
    vars.iter()
        .find(|v| v.0 == name)
        .map(|v| v.1.clone())
        .unwrap_or_else(|| panic!("no variable {name} in {:?}", vars.iter().map(|v| &v.0).collect::<Vec<_>>()))
}

/// The skill state machine and the binding to OPC UA, generated afresh from our skill models.
///
/// `tests/modelica/SkillExample.DrillHoleRun`
/// drives the DrillHole skill of the generated DrillingCell instance with pulses on its trigger inputs.
/// The skill starts in Ready (the instance's CurrentState and Program rule, see `statemachine.rs`), so Start
/// runs it at once; Halt stops it; a Start in Halted does nothing; Reset brings it back to Ready, and Start
/// runs it again. The model passes rumoca's check as it is; the simulation has the String variables as
/// parameters, so the state text (a `final` binding to the text the machine's equation sets) is checked by
/// the generator's unit test `state_text_follows_the_number_and_instances_set_the_initial_state`.
#[test]
fn a_skill_instance_runs_through_start_halt_and_reset() {
    let dir = vendor();
    let files: Vec<PathBuf> = ["CommonSkills", "RobotCell", "DrillingProcess"]
        .iter()
        .map(|n| root().join("nodesets").join(format!("{n}.NodeSet2.xml")))
        .collect();
    let out = compile_files(&files, vec![dir]);
    let mut cfg = ModelicaConfig::new();
    for m in &out.model.models {
        if m.uri != NS0_URI {
            cfg = cfg.namespace(m.uri.clone());
        }
    }
    let generated = generate(&out.model, &cfg).unwrap_or_else(|d| panic!("{}", d.render(&out.model.sources)));
    let target = tmp("skills-run");
    write(&target, &generated);
    copy_dir(&root().join("tests/modelica/SkillExample"), &target.join("SkillExample"));
    copy_dir(&root().join("tests/modelica/BindingExample"), &target.join("BindingExample"));
    // The library and the examples as they are (with their String variables) pass rumoca's check.
    let (passed, failed, text) = check(&target, true);
    assert_eq!(failed, 0, "{text}");
    assert!(passed > 100, "{text}");
    // The classes below the tree, those the support package left out included (pymoca and the structural
    // checks see all of them).
    let passed = passed + left_out(&text);
    // pymoca flattens the examples, the binding models and OpcUaSupport. When the library beside the examples is
    // generated/modelica byte for byte (as it is when generated/ is up to date), the binding models and
    // OpcUaSupport are flattened class by class in that tree by `generated_tree_passes_pymoca_and_the_structural_checks`
    // (the examples' packages change no lookup of a generated class), so only the examples are flattened here:
    // the same classes, checked once instead of twice (about 70 s of pymoca).
    let examples = ["SkillExample", "BindingExample"];
    let library = ["NodesetCompilerDrillingProcess.Instances.Bindings", "OpcUaSupport"];
    let only: Vec<&str> = match same_tree_except(&target, &root().join("generated/modelica"), &examples) {
        Ok(()) => examples.to_vec(),
        Err(differs) => {
            println!("the library differs from generated/modelica ({differs}): pymoca checks {library:?} here too");
            examples.iter().chain(&library).copied().collect()
        }
    };
    println!("{}", second_checks("the examples, the binding models and OpcUaSupport", &target, &only, passed));
    // (time, state number): before anything, after Start, after Halt, after the ignored Start, after Reset,
    // after the second Start.
    let expected = [(0.5, 12.0), (1.5, 13.0), (2.3, 11.0), (2.8, 11.0), (3.5, 12.0), (4.5, 13.0)];
    let times: Vec<f64> = expected.iter().map(|e| e.0).collect();
    let vars = simulate_at(&target, "SkillExample.DrillHoleRun", &times);
    let get = |name: &str| values_at(&vars, name);
    let states = get("state");
    let want: Vec<f64> = expected.iter().map(|e| e.1).collect();
    assert_eq!(states, want, "state numbers at {times:?} (Halted 11, Ready 12, Running 13)");

    // The generated binding model of the same instance, its blocks the loopback ones
    // (`tests/modelica/BindingExample.LoopbackCell`): a read feeds the instance in SI units from a table in
    // the variable's engineering unit, and a write sends what the instance publishes.
    let times = [0.0, 0.5, 1.5, 2.5];
    let vars = simulate_at(&target, "BindingExample.LoopbackCell", &times);
    let get = |name: &str| values_at(&vars, name);
    let close = |got: Vec<f64>, want: [f64; 4], what: &str| {
        assert!(got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-9), "{what} at {times:?}: {got:?}, want {want:?}");
    };
    // ApproachDistance: 10 mm rising linearly to 30 mm at 1 s, read in millimetres, used in metres.
    close(get("cell.skillSet.referenceDrillBush.inputParameterSet.approachDistance"), [0.01, 0.02, 0.03, 0.03], "approachDistance (m)");
    close(get("cell.readSkillSetReferenceDrillBushInputParameterSetApproachDistance.value"), [10.0, 20.0, 30.0, 30.0], "the ApproachDistance read (mm)");
    // Depth: 5 mm, 8 mm from 2 s on.
    close(get("cell.skillSet.drillHole.inputParameterSet.depth"), [0.005, 0.005, 0.005, 0.008], "depth (m)");
    // A read without a table gives the nodeset's value (FeedRate has none: 0).
    close(get("cell.skillSet.drillHole.inputParameterSet.feedRate"), [0.0; 4], "feedRate");
    // DrillHole's Result, set by the example, is what its write block sends: Good, then Bad_Timeout.
    close(get("result"), [0.0, 0.0, -2136276992.0, -2136276992.0], "the Result written");

    // The generated example of the cell simulates as it is (its experiment annotation gives the time): both
    // skills stay in Ready, the initial state of the nodeset.
    let vars = simulate_at(&target, "NodesetCompilerDrillingProcess.Examples.DrillingCell", &[0.5]);
    for skill in ["referenceDrillBush", "drillHole"] {
        let state = values_at(&vars, &format!("drillingCell.skillSet.{skill}.currentStateNumber"));
        assert_eq!(state, [12.0], "{skill} in Ready");
    }
}

/// What rumoca 0.10.2 does with redeclarations, reproduced with small hand-written models
/// (`tests/modelica/RumocaBehaviour`, which documents each case). The generator works around the first one
/// (`Mod::Pin`); if a rumoca release fixes it, this test fails and the workaround can be reconsidered.
#[test]
fn rumoca_behaviour_is_as_reproduced() {
    let dir = root().join("tests/modelica");
    let names = |vars: &[(String, f64, f64)]| vars.iter().map(|v| v.0.clone()).collect::<Vec<_>>();
    // An enclosing instance's redeclaration of an inherited alias replaces the nested class's own choice.
    let leak = simulate(&dir, "RumocaBehaviour.LeakDemo", "1");
    assert!(names(&leak).contains(&"r.a.ps.speed".to_string()), "the leak is gone: {:?}", names(&leak));
    assert!(!names(&leak).contains(&"r.a.ps.pos".to_string()), "the leak is gone: {:?}", names(&leak));
    // Repeating the choice on the component (what the generator writes) keeps the nested class's own.
    let pinned = simulate(&dir, "RumocaBehaviour.PinnedDemo", "1");
    let (_, pos) = value(&pinned, "r.a.ps.pos");
    assert!((pos - (1.0 - (-5.0f64).exp())).abs() < 1e-3, "r.a.ps.pos ends at {pos}");
    assert!(!names(&pinned).contains(&"r.a.ps.speed".to_string()), "{:?}", names(&pinned));
    // The leak reaches an array of axes, and an axis two levels in whose holder has no alias of its own.
    let array = simulate(&dir, "RumocaBehaviour.ArrayLeakDemo", "1");
    assert!(names(&array).contains(&"r.a[1].ps.speed".to_string()), "the leak is gone: {:?}", names(&array));
    assert!(!names(&array).contains(&"r.a[1].ps.pos".to_string()), "the leak is gone: {:?}", names(&array));
    let deep = simulate(&dir, "RumocaBehaviour.DeepLeakDemo", "1");
    assert!(names(&deep).contains(&"r.m.a.ps.speed".to_string()), "the leak is gone: {:?}", names(&deep));
    assert!(!names(&deep).contains(&"r.m.a.ps.pos".to_string()), "the leak is gone: {:?}", names(&deep));
    // Repeating the choice in the class alias's definition does not stop it; through an alias of the enclosing
    // class (what the generator writes for a component declared through an alias) does.
    let alias_pinned = simulate(&dir, "RumocaBehaviour.AliasPinnedDemo", "1");
    assert!(names(&alias_pinned).contains(&"r.a[1].ps.speed".to_string()), "{:?}", names(&alias_pinned));
    let via = simulate(&dir, "RumocaBehaviour.ViaDemo", "1");
    let (_, pos) = value(&via, "r.a[1].ps.pos");
    assert!((pos - (1.0 - (-5.0f64).exp())).abs() < 1e-3, "r.a[1].ps.pos ends at {pos}");
    assert!(!names(&via).contains(&"r.a[1].ps.speed".to_string()), "{:?}", names(&via));
    // A replaceable component redeclared two extends levels below its declaration is dropped.
    let dropped = simulate(&dir, "RumocaBehaviour.DroppedDemo", "1");
    assert!(names(&dropped).contains(&"a.y".to_string()), "{:?}", names(&dropped));
    assert!(!names(&dropped).contains(&"a.ps.pos".to_string()), "rumoca keeps the component now: {:?}", names(&dropped));
    // A String variable: the model cannot be simulated (simulate.py --strings-as-parameters works around it).
    let out = Command::new(python())
        .arg(root().join("tests/modelica/simulate.py"))
        .arg(&dir)
        .arg("RumocaBehaviour.StringDemo")
        .output()
        .expect("cannot run tests/modelica/simulate.py");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(
        !out.status.success() && text.contains("String values are not numeric"),
        "rumoca simulates String variables now; drop --strings-as-parameters: {text}"
    );
}

/// pymoca 0.12.0 keeps a declaration's redeclaration on an array component sized by a parameter when a derived
/// class changes it, and so rejects a valid class (`tests/modelica/PymocaBehaviour`, whose package documents the
/// cases); the same through an alias of the enclosing class, which the generator writes, passes. The day pymoca
/// reads the array right, this fails, and `Mod::PinVia` can be reconsidered.
#[test]
fn pymoca_behaviour_is_as_reproduced() {
    let dir = root().join("tests/modelica/PymocaBehaviour");
    let (passed, _, text) = run_checker("check2.py", &dir, &["--jobs", "1"]);
    assert_eq!(failed_classes(&text), ["PymocaBehaviour.ArrayOverride"], "{text}");
    assert!(text.contains("\"giveAway\", which does not exist"), "{text}");
    assert_eq!(passed, 9, "{text}");
    // rumoca accepts every class, the one pymoca rejects included.
    let (passed, failed, text) = run_checker("check.py", &dir, &[]);
    assert_eq!((passed, failed), (10, 0), "{text}");
}

/// Generates the models of each file (with everything it requires, ns0 as a subset), checks that no class of
/// an output contains itself, and checks each output with one aggregate rumoca model and the structural checks
/// (`structure.py`), two nodesets at a time.
fn check_tree(label: &str, tree: &Path, files: &[PathBuf], absent_ok: bool) {
    let t0 = Instant::now();
    let mut jobs: Vec<(PathBuf, PathBuf, usize)> = Vec::new();
    let mut unresolvable = Vec::new();
    let mut generated_classes = 0;
    let mut gen_time = 0.0;
    for (i, f) in files.iter().enumerate() {
        let out = compile(
            vec![Input::Path(f.clone())],
            &Options { model_dirs: vec![tree.to_path_buf()], ..Options::default() },
        );
        if !out.ok() {
            unresolvable.push(f.clone());
            continue;
        }
        // Every non-base namespace that was loaded, so the output is complete on its own.
        let mut cfg = ModelicaConfig::new();
        for m in &out.model.models {
            if m.uri != NS0_URI {
                cfg = cfg.namespace(m.uri.clone());
            }
        }
        let t = Instant::now();
        let files =
            generate(&out.model, &cfg).unwrap_or_else(|d| panic!("{}: {}", f.display(), d.render(&out.model.sources)));
        gen_time += t.elapsed().as_secs_f64();
        let classes = files
            .iter()
            .filter(|x| x.path.extension().is_some_and(|e| e == "mo") && !x.path.ends_with("package.mo"))
            .count();
        generated_classes += classes;
        let dir = tmp(&format!("{label}/{i:03}"));
        write(&dir, &files);
        jobs.push((f.clone(), dir, classes));
    }
    if !absent_ok {
        assert!(unresolvable.is_empty(), "{unresolvable:?} do not resolve");
    }
    // No class contains itself (see `no_generated_class_contains_itself`).
    let cycles: Vec<String> = jobs
        .iter()
        .filter_map(|(f, dir, _)| class_cycle(&class_graph(dir)).map(|c| format!("{}: {c}", f.display())))
        .collect();
    assert!(cycles.is_empty(), "classes that contain themselves:\n{}", cycles.join("\n"));
    let gen_elapsed = t0.elapsed().as_secs_f64();
    // Two workers (the CI machine has two cores), each taking the next tree when it is done with one.
    let t1 = Instant::now();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<(PathBuf, usize, usize, String, f64)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|_| {
                let (jobs, next) = (&jobs, &next);
                s.spawn(move || {
                    std::iter::from_fn(|| jobs.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed)))
                        .map(|(f, dir, classes)| {
                            let (p, fl, mut text) = check(dir, true);
                            let p = p + left_out(&text);
                            // The structural checks (modifier targets, conditional reads) too.
                            let t = Instant::now();
                            let (ps, fs, texts) = run_checker("structure.py", dir, &[]);
                            if fs > 0 || ps != *classes {
                                text.push_str(&format!("structure: {ps} of {classes} passed\n{texts}"));
                            }
                            (f.clone(), p, fl + fs + classes.saturating_sub(ps), text, t.elapsed().as_secs_f64())
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let mut all: Vec<_> = handles.into_iter().flat_map(|h| h.join().expect("a checker thread panicked")).collect();
        all.sort_by(|a, b| a.0.cmp(&b.0));
        all
    });
    let mut passed = 0;
    let mut failed = 0;
    let mut structure_s = 0.0;
    let mut failures = String::new();
    for (f, p, fl, text, secs) in &results {
        passed += p;
        failed += fl;
        structure_s += secs;
        if *fl > 0 {
            failures.push_str(&format!("{}:\n{text}\n", f.display()));
        }
    }
    println!(
        "{label}: {} files, {} generated ({generated_classes} classes, generation {gen_time:.2} s, {gen_elapsed:.1} s with loading), {} unresolvable (missing models); rumoca: {passed} passed (the support package's where it is generated/modelica's: there), {failed} failed (with the structural checks, {structure_s:.1} s of them) in {:.1} s",
        files.len(),
        jobs.len(),
        unresolvable.len(),
        t1.elapsed().as_secs_f64()
    );
    for u in &unresolvable {
        println!("  unresolvable: {}", u.strip_prefix(tree).unwrap_or(u).display());
    }
    assert_eq!(failed, 0, "{failures}");
    assert_eq!(passed, jobs.iter().map(|j| j.2).sum::<usize>(), "every generated class is checked");
}

#[test]
fn every_resolvable_corpus_file_passes_rumoca() {
    let tree = corpus();
    let files = nodeset_files(&tree);
    assert!(files.len() >= 117, "expected the 117+ NodeSet2 files of the corpus, found {}", files.len());
    check_tree("corpus", &tree, &files, true);
}

/// The checked-in tree of `cargo xtask generate` (DI, IA, Robotics and our three skill models with the ns0
/// subset they use) passes rumoca class by class, as it is committed.
#[test]
fn generated_tree_passes_rumoca() {
    let tree = root().join("generated/modelica");
    for package in ["NodesetCompilerCommonSkills", "NodesetCompilerRobotCell", "NodesetCompilerDrillingProcess"] {
        assert!(tree.join(package).join("package.mo").is_file(), "{package} is missing: run `cargo xtask generate`");
    }
    let mut classes = 0;
    let mut dirs = vec![tree.clone()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|x| x == "mo") && !path.ends_with("package.mo") {
                classes += 1;
            }
        }
    }
    let t = Instant::now();
    // Every class, the support package's included: the other trees' checks leave it out when theirs is this one.
    let (passed, failed, text) = run_checker("check.py", &tree, &[]);
    println!("generated/modelica: {passed} passed, {failed} failed in {:.1} s", t.elapsed().as_secs_f64());
    assert_eq!(failed, 0, "{text}");
    assert_eq!(passed, classes, "every class of generated/modelica is checked\n{text}");
}

/// The checked-in tree passes the second checker, pymoca (`tests/modelica/check2.py`), class by class, and the
/// structural checks (`tests/modelica/structure.py`): no modifier names a member that does not exist, at any
/// depth, and nothing but a connection or a modifier reaches a conditional component.
#[test]
fn generated_tree_passes_pymoca_and_the_structural_checks() {
    let tree = root().join("generated/modelica");
    let classes = class_graph(&tree).len();
    assert!(classes > 200, "expected the classes of generated/modelica, found {classes}");
    println!("{}", second_checks("generated/modelica", &tree, &[], classes));
}

/// `check.py --same-as` leaves out a package only when it is the reference's byte for byte: a copy of the support
/// package is left out whole; the same copy with one file changed is checked, every class of it.
#[test]
fn only_an_identical_support_package_is_left_out() {
    let reference = root().join("generated/modelica");
    let dir = tmp("same-as");
    let _ = std::fs::remove_dir_all(&dir);
    copy_dir(&reference.join("OpcUaSupport"), &dir.join("OpcUaSupport"));
    let classes = class_graph(&dir).len();
    assert!(classes > 30, "expected the support package's classes, found {classes}");
    let (passed, failed, text) = check(&dir, true);
    assert_eq!((passed, failed, left_out(&text)), (0, 0, classes), "{text}");
    // One changed byte: the package is checked here.
    let package = dir.join("OpcUaSupport/package.mo");
    let mut source = std::fs::read_to_string(&package).unwrap();
    source.push('\n');
    std::fs::write(&package, source).unwrap();
    let (passed, failed, text) = check(&dir, true);
    assert_eq!((passed, failed, left_out(&text)), (classes, 0, 0), "{text}");
}

/// Each check fails on its planted mistake (`tests/modelica/planted`, whose package documents each case) and
/// on nothing else there: pymoca on misspelt modifiers at any depth, on a recursive class and on a component's
/// repeated choice that hides the members of the class an instance plugs in; the structural checks on the
/// misspelt modifiers and on reads of a conditional component; the class graph on the recursive pair.
#[test]
fn the_checks_catch_the_planted_mistakes() {
    let dir = root().join("tests/modelica/planted");
    let (passed, _, text) = run_checker("check2.py", &dir, &["--jobs", "1"]);
    assert_eq!(
        failed_classes(&text),
        [
            "Planted.ExtendsModifierTypo",
            "Planted.ModifierTypo",
            "Planted.NestedModifierTypo",
            "Planted.PinnedOverride",
            "Planted.RecursiveA",
            "Planted.RecursiveB"
        ],
        "{text}"
    );
    assert_eq!(passed, 12, "{text}");
    let (passed, _, text) = run_checker("structure.py", &dir, &[]);
    assert_eq!(
        failed_classes(&text),
        [
            "Planted.ConditionalBinding",
            "Planted.ConditionalEquation",
            "Planted.ExtendsModifierTypo",
            "Planted.ModifierTypo",
            "Planted.NestedModifierTypo"
        ],
        "{text}"
    );
    assert_eq!(passed, 13, "{text}");
    assert_eq!(
        class_cycle(&class_graph(&dir)).as_deref(),
        Some("Planted.RecursiveA -> Planted.RecursiveB -> Planted.RecursiveA")
    );
}

/// Removes comments and the contents of string literals from Modelica text.
fn code_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(d) = chars.next() {
                    match d {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
                out.push_str("\"\"");
            }
            '/' if chars.peek() == Some(&'/') => {
                for d in chars.by_ref() {
                    if d == '\n' {
                        out.push('\n');
                        break;
                    }
                }
            }
            '/' if chars.peek() == Some(&'*') => {
                chars.next();
                let mut last = ' ';
                for d in chars.by_ref() {
                    if last == '*' && d == '/' {
                        break;
                    }
                    last = d;
                }
            }
            _ => out.push(c),
        }
    }
    out
}

/// The class graph of a Modelica library below `dir` (one class per file): for each class, the classes its
/// text names by their full names, which is how the generator writes every `extends`, component class,
/// replaceable alias and redeclaration. Package files are not classes of the graph.
fn class_graph(dir: &Path) -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let mut texts = std::collections::BTreeMap::new();
    let mut dirs = vec![dir.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for entry in std::fs::read_dir(&d).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|x| x == "mo") && !path.ends_with("package.mo") {
                let rel = path.strip_prefix(dir).unwrap().with_extension("");
                let name: Vec<String> =
                    rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
                texts.insert(name.join("."), code_only(&std::fs::read_to_string(&path).unwrap()));
            }
        }
    }
    let mut graph = std::collections::BTreeMap::new();
    for (class, text) in &texts {
        let mut edges = std::collections::BTreeSet::new();
        let is_ident = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.';
        for word in text.split(|c: char| !is_ident(c)) {
            if word.contains('.') && texts.contains_key(word) {
                edges.insert(word.to_string());
            }
        }
        graph.insert(class.clone(), edges);
    }
    graph
}

/// A cycle of the class graph, as `A -> B -> A`, if there is one.
fn class_cycle(graph: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>) -> Option<String> {
    #[derive(PartialEq)]
    enum Mark {
        Open,
        Done,
    }
    let mut marks: std::collections::BTreeMap<&str, Mark> = std::collections::BTreeMap::new();
    for root in graph.keys() {
        if marks.contains_key(root.as_str()) {
            continue;
        }
        let mut path: Vec<(&str, Vec<&str>)> = vec![(root, graph[root].iter().map(String::as_str).collect())];
        marks.insert(root, Mark::Open);
        while let Some((node, next)) = path.last_mut() {
            let node: &str = node;
            let Some(to) = next.pop() else {
                marks.insert(node, Mark::Done);
                path.pop();
                continue;
            };
            match marks.get(to) {
                Some(Mark::Done) => {}
                Some(Mark::Open) => {
                    let start = path.iter().position(|p| p.0 == to).unwrap();
                    let mut names: Vec<&str> = path[start..].iter().map(|p| p.0).collect();
                    names.push(to);
                    return Some(names.join(" -> "));
                }
                None => {
                    marks.insert(to, Mark::Open);
                    path.push((to, graph[to].iter().map(String::as_str).collect()));
                }
            }
        }
    }
    None
}

/// No generated class contains itself, directly or through the classes it extends or contains: the
/// checked-in tree of DI, IA, Robotics and our skill models. (Modelica tools reject recursive classes;
/// rumoca does not notice them.) The walk itself is checked on a small cycle.
#[test]
fn no_generated_class_contains_itself() {
    let mut toy = std::collections::BTreeMap::new();
    toy.insert("P.A".to_string(), ["P.B".to_string()].into_iter().collect());
    toy.insert("P.B".to_string(), ["P.A".to_string()].into_iter().collect());
    assert_eq!(class_cycle(&toy).as_deref(), Some("P.A -> P.B -> P.A"));
    let tree = root().join("generated/modelica");
    let graph = class_graph(&tree);
    assert!(graph.len() > 200, "expected the classes of generated/modelica, found {}", graph.len());
    let edges: usize = graph.values().map(|e| e.len()).sum();
    if let Some(cycle) = class_cycle(&graph) {
        panic!("a class contains itself: {cycle}");
    }
    println!("generated/modelica: {} classes, {edges} edges, no cycle", graph.len());
}

#[test]
fn skill_reference_models_pass_rumoca() {
    let tree = root().join("../shared/nodesets/skills-reference");
    let mut files = nodeset_files(&tree);
    assert_eq!(files.len(), 2, "the two skill reference models are expected in {}", tree.display());
    // The skills need DI, which the reference folder does not hold; the corpus has it.
    let dir = tmp("skills-models");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for f in &files {
        std::fs::copy(f, dir.join(f.file_name().unwrap())).unwrap();
    }
    let di = corpus().join("DI/Opc.Ua.Di.NodeSet2.xml");
    std::fs::copy(&di, dir.join("Opc.Ua.Di.NodeSet2.xml")).unwrap();
    std::fs::copy(corpus().join("Schema/Opc.Ua.NodeSet2.xml"), dir.join("Opc.Ua.NodeSet2.xml")).unwrap();
    files = files.iter().map(|f| dir.join(f.file_name().unwrap())).collect();
    check_tree("skills", &dir, &files, false);
}

#[test]
fn output_does_not_depend_on_input_order_or_run() {
    let dir = vendor();
    let names = ["Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.IA.NodeSet2.xml", "Opc.Ua.Robotics.NodeSet2.xml"];
    let forward: Vec<PathBuf> = names.iter().map(|n| dir.join(n)).collect();
    let backward: Vec<PathBuf> = forward.iter().rev().cloned().collect();
    let cfg = ModelicaConfig::new()
        .namespace("http://opcfoundation.org/UA/Robotics/")
        .namespace("http://opcfoundation.org/UA/DI/")
        .namespace("http://opcfoundation.org/UA/IA/");
    let a = generate(&compile_files(&forward, vec![dir.clone()]).model, &cfg).unwrap();
    let b = generate(&compile_files(&forward, vec![dir.clone()]).model, &cfg).unwrap();
    let c = generate(&compile_files(&backward, vec![dir.clone()]).model, &cfg).unwrap();
    assert_eq!(a, b, "two runs differ");
    assert_eq!(a, c, "the input order changes the output");
}

#[test]
fn files_are_utf8_without_bom_with_header_and_within() {
    let dir = vendor();
    let out = compile_files(&[dir.join("Opc.Ua.Robotics.NodeSet2.xml")], vec![dir]);
    let files = generate(
        &out.model,
        &ModelicaConfig::new()
            .namespace("http://opcfoundation.org/UA/Robotics/")
            .namespace("http://opcfoundation.org/UA/DI/")
            .namespace("http://opcfoundation.org/UA/IA/"),
    )
    .unwrap();
    for f in &files {
        assert!(!f.contents.starts_with('\u{feff}'), "{} starts with a BOM", f.path.display());
        let name = f.path.file_name().unwrap().to_string_lossy();
        if name == "package.order" {
            assert!(
                f.contents
                    .lines()
                    .all(|l| nodeset_compiler::names::is_valid(l, nodeset_compiler::names::Target::Modelica)),
                "{}",
                f.path.display()
            );
            continue;
        }
        assert!(f.contents.starts_with("// Generated by nodeset-compiler"), "{} has no header", f.path.display());
        assert!(
            f.contents.contains("`cargo xtask generate`"),
            "{} does not say how to regenerate it",
            f.path.display()
        );
        if f.path.starts_with("OpcUaSupport/Resources") {
            // Files for the Modelica tool (the C header of OpcUaSupport.Live), not classes: no `within`.
            assert_eq!(f.path.extension().and_then(|x| x.to_str()), Some("h"), "{}", f.path.display());
            continue;
        }
        let parent: Vec<String> =
            f.path.parent().unwrap().components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
        let class = name.strip_suffix(".mo").unwrap();
        let within = if class == "package" { parent[..parent.len() - 1].join(".") } else { parent.join(".") };
        let expected = if within.is_empty() { "within;".to_string() } else { format!("within {within};") };
        assert!(f.contents.contains(&format!("\n{expected}\n")), "{} lacks `{expected}`", f.path.display());
    }
    // Every class of a folder is listed in its package.order.
    let mut dirs = std::collections::BTreeMap::<PathBuf, Vec<String>>::new();
    for f in &files {
        if let Some(c) = f.path.file_name().unwrap().to_string_lossy().strip_suffix(".mo") {
            if c != "package" {
                dirs.entry(f.path.parent().unwrap().to_path_buf()).or_default().push(c.to_string());
            }
        }
    }
    for (dir, mut classes) in dirs {
        let order = files
            .iter()
            .find(|f| f.path == dir.join("package.order"))
            .unwrap_or_else(|| panic!("{} has no package.order", dir.display()));
        let mut listed: Vec<String> = order.contents.lines().map(str::to_string).collect();
        // Sub-packages are listed too, and so are classes nested in package.mo (OpcUaSupport's UsersGuide).
        listed.retain(|l| !files.iter().any(|f| f.path == dir.join(l).join("package.mo")));
        if let Some(package) = files.iter().find(|f| f.path == dir.join("package.mo")) {
            classes.extend(package.contents.lines().filter_map(|l| {
                let rest = ["  package ", "  model ", "  record ", "  block ", "  type "].iter().find_map(|k| l.strip_prefix(k))?;
                rest.split_whitespace().next().map(str::to_string)
            }));
        }
        listed.sort();
        classes.sort();
        assert_eq!(listed, classes, "{}", dir.display());
    }
}
