//! `cargo xtask serve-corpus`: every NodeSet2 file of the UA-Nodeset tree and of the registry package served
//! by `nodeset-compiler serve FILE --models TREE --instantiate-all` (its required models found in the same
//! tree), then checked by `nodeset-compiler verify --json`, as a user runs both. Each file gets a time limit
//! for each of the two steps; a file that does not compile, does not start, or does not answer in time is
//! reported and the run goes on.
//!
//! The static instances of the files (everything verify finds outside `Objects/Instances`) must give the
//! same findings as `check` of the same files (codes, severities, browse paths with namespace URIs): `check`
//! runs in this process on every file the server loaded (the named ones and their required models, as the
//! server serves all of them), and each finding only one side has is a disagreement.
//!
//! At the end: the figures (files, files served, concrete ObjectTypes instantiated of those the files
//! define, nodes created below `Objects/Instances`, nodes verify checked, violations below
//! `Objects/Instances` and elsewhere, disagreements with `check`, structure values read back and compared
//! with the files), then each file with violations below `Objects/Instances`, types not instantiated,
//! disagreements or structure values that differ, with the reasons. A violation below `Objects/Instances`
//! that a diagnostic of `check` on the same files explains as a defect of the nodeset (the same declaration:
//! `findings_check_explains`) is listed with that diagnostic and does not fail the run. Fails when another
//! violation below `Objects/Instances`, a disagreement with `check` or a structure value that differs remains.

use crate::util::workspace_root;
use nodeset_compiler::verify::instances::{findings_check_explains, static_findings_by_uri};
use nodeset_compiler::verify::report as verify_report;
use process_support::Process;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Options of `cargo xtask serve-corpus`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The UA-Nodeset tree (default: ../shared/nodesets/ua-nodeset).
    #[arg(long)]
    tree: Option<PathBuf>,
    /// Skip the registry package's files (nodesets/vendor).
    #[arg(long)]
    no_registry: bool,
    /// Seconds each file may take to start serving, and again to be verified.
    #[arg(long, default_value_t = 180)]
    timeout: u64,
    /// Only the files whose path contains this text.
    #[arg(long)]
    only: Option<String>,
}

/// What one run (one or a few files named together) gave.
#[derive(Debug, Default)]
struct Outcome {
    name: String,
    /// Why nothing could be verified (the file does not compile, the server did not start, ...).
    failed: Option<String>,
    types: usize,
    instantiated: usize,
    instance_nodes: usize,
    machines: usize,
    checked: u64,
    /// (code, path, message) of each finding below `Objects/Instances`.
    below: Vec<(String, String, String)>,
    /// Violations below `Objects/Instances` that a diagnostic of `check` on the same files explains as a
    /// defect of the nodeset (the violation, then check's diagnostic).
    explained: Vec<(String, String)>,
    /// Findings elsewhere (static instances of the files).
    elsewhere: usize,
    /// Findings on the static instances only one of verify and check has: `verify only: ...` or
    /// `check only: ...`, with code, severity and path (namespace URIs for prefixes).
    disagreements: Vec<String>,
    /// `serve`'s reasons for the types it did not instantiate.
    not_instantiated: Vec<String>,
    /// Structure values read back and compared with the files (`verify`'s `structures_compared`).
    structures: usize,
    /// Those whose content differs (path and first difference).
    structure_mismatches: Vec<String>,
}

pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    let start = Instant::now();
    let exe = compiler(&root)?;
    let tree = args.tree.unwrap_or_else(|| root.join("../shared/nodesets/ua-nodeset"));
    let tree = tree.canonicalize().map_err(|e| format!("{}: {e}", tree.display()))?;
    let mut runs: Vec<(Vec<PathBuf>, PathBuf)> = Vec::new();
    let mut files = Vec::new();
    crate::corpus::nodeset_files(&tree, &mut files);
    files.sort();
    runs.extend(files.into_iter().map(|f| (vec![f], tree.clone())));
    if !args.no_registry {
        crate::fetch::ensure_fetched()?;
        let vendor = root.join(crate::fetch::VENDOR_DIR).canonicalize().map_err(|e| format!("{}: {e}", crate::fetch::VENDOR_DIR))?;
        runs.extend(crate::registry::units(&vendor).into_iter().map(|u| (u, vendor.clone())));
    }
    if let Some(only) = &args.only {
        runs.retain(|(u, _)| u.iter().any(|f| f.display().to_string().contains(only.as_str())));
    }
    let work = root.join("target/serve-corpus");
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let timeout = Duration::from_secs(args.timeout);
    let mut outcomes = Vec::new();
    for (i, (unit, models)) in runs.iter().enumerate() {
        let name = unit.iter().map(|f| rel(&root, f)).collect::<Vec<_>>().join(" + ");
        let t = Instant::now();
        let mut o = serve_and_verify(&exe, unit, models, &work, i, timeout);
        o.name = name;
        println!(
            "[{}/{}] {}: {} ({:.1} s)",
            i + 1,
            runs.len(),
            o.name,
            match &o.failed {
                Some(why) => format!("not verified: {}", why.lines().next().unwrap_or_default()),
                None => format!(
                    "{}/{} types, {} instance nodes, {} checked, {} below Instances ({} explained by check), {} elsewhere, {} disagreement(s) with check, {} structure value(s) compared, {} differ",
                    o.instantiated,
                    o.types,
                    o.instance_nodes,
                    o.checked,
                    o.below.len() + o.explained.len(),
                    o.explained.len(),
                    o.elsewhere,
                    o.disagreements.len(),
                    o.structures,
                    o.structure_mismatches.len()
                ),
            },
            t.elapsed().as_secs_f64()
        );
        outcomes.push(o);
    }
    report(&outcomes, start.elapsed())
}

fn report(outcomes: &[Outcome], took: Duration) -> Result<(), String> {
    let served: Vec<&Outcome> = outcomes.iter().filter(|o| o.failed.is_none()).collect();
    let sum = |f: fn(&Outcome) -> usize| served.iter().map(|o| f(o)).sum::<usize>();
    let below = sum(|o| o.below.len());
    let disagreements = sum(|o| o.disagreements.len());
    let mismatches = sum(|o| o.structure_mismatches.len());
    println!("\nserve-corpus: {} run(s) in {:.0} s", outcomes.len(), took.as_secs_f64());
    println!("  served and verified: {} (not verified: {})", served.len(), outcomes.len() - served.len());
    println!("  concrete ObjectTypes instantiated: {} of {}", sum(|o| o.instantiated), sum(|o| o.types));
    println!("  nodes created below Objects/Instances: {}", sum(|o| o.instance_nodes));
    println!("  state machines served: {}", sum(|o| o.machines));
    println!("  nodes verify checked: {}", served.iter().map(|o| o.checked).sum::<u64>());
    println!(
        "  violations below Objects/Instances: {below} not explained, {} explained by a diagnostic of check (defects of the nodesets)",
        sum(|o| o.explained.len())
    );
    println!("  findings elsewhere (static instances of the files): {}", sum(|o| o.elsewhere));
    println!("  disagreements of verify and check on the static instances: {disagreements}");
    println!("  structure values read back and compared with the files: {} ({mismatches} differ)", sum(|o| o.structures));
    for o in outcomes.iter().filter(|o| o.failed.is_some()) {
        println!("\nnot verified: {}\n  {}", o.name, o.failed.as_deref().unwrap_or_default().replace('\n', "\n  "));
    }
    for o in served.iter().filter(|o| {
        !o.below.is_empty()
            || !o.explained.is_empty()
            || !o.not_instantiated.is_empty()
            || !o.disagreements.is_empty()
            || !o.structure_mismatches.is_empty()
    }) {
        println!("\n{}:", o.name);
        for why in &o.not_instantiated {
            println!("  {why}");
        }
        for (code, path, message) in &o.below {
            println!("  {code} {path}: {message}");
        }
        for (violation, why) in &o.explained {
            println!("  {violation}: explained by check's {why}");
        }
        for d in &o.disagreements {
            println!("  {d}");
        }
        for m in &o.structure_mismatches {
            println!("  structure value differs: {m}");
        }
    }
    if below > 0 || disagreements > 0 || mismatches > 0 {
        return Err(format!(
            "serve-corpus: {below} violation(s) below Objects/Instances, {disagreements} disagreement(s) of verify and check, {mismatches} structure value(s) that differ from the files (listed above)"
        ));
    }
    Ok(())
}

/// Builds `nodeset-compiler` (default features: `serve` and `verify`) and returns its path.
fn compiler(root: &Path) -> Result<PathBuf, String> {
    process_support::cargo_artifacts(root, &["build", "-p", "nodeset-compiler", "--bin", "nodeset-compiler"])?
        .into_iter()
        .find(|a| a.kind == "bin" && a.name == "nodeset-compiler")
        .map(|a| a.path)
        .ok_or_else(|| "cargo built no nodeset-compiler".to_owned())
}

fn serve_and_verify(exe: &Path, unit: &[PathBuf], models: &Path, work: &Path, i: usize, timeout: Duration) -> Outcome {
    let mut o = Outcome::default();
    let log = work.join(format!("serve-{i}.log"));
    let Ok(stderr) = std::fs::File::create(&log) else {
        o.failed = Some(format!("cannot create {}", log.display()));
        return o;
    };
    let mut command = Command::new(exe);
    command.arg("serve").args(unit).arg("--models").arg(models);
    command.args(["--instantiate-all", "--insecure", "--port", "0", "--pki"]).arg(work.join("pki"));
    command.stderr(stderr);
    let server = match Process::spawn(&mut command) {
        Ok(s) => s,
        Err(e) => {
            o.failed = Some(e);
            return o;
        }
    };
    let url = match server.wait_for("listening on ", timeout) {
        Ok(url) => url,
        Err(e) => {
            let said = std::fs::read_to_string(&log).unwrap_or_default();
            let errors: Vec<&str> = said.lines().filter(|l| l.starts_with("error")).take(3).collect();
            o.failed = Some(if errors.is_empty() { e } else { errors.join("\n") });
            return o;
        }
    };
    let said = std::fs::read_to_string(&log).unwrap_or_default();
    for line in said.lines() {
        if let Some(rest) = line.strip_prefix("instantiated ") {
            let numbers: Vec<usize> =
                rest.split(|c: char| !c.is_ascii_digit()).filter(|w| !w.is_empty()).filter_map(|w| w.parse().ok()).collect();
            if let [inst, types, nodes, machines, ..] = numbers[..] {
                (o.instantiated, o.types, o.instance_nodes, o.machines) = (inst, types, nodes, machines);
            }
        } else if line.contains(" is not instantiated: ") {
            o.not_instantiated.push(line.trim_start_matches("warning: ").to_owned());
        }
    }
    let out = work.join(format!("verify-{i}.json"));
    let verified = Command::new(exe)
        .arg("verify")
        .arg(&url)
        .args(unit)
        .arg("--models")
        .arg(models)
        .args(["--insecure", "--json"])
        .stdout(std::fs::File::create(&out).map(Stdio::from).unwrap_or(Stdio::null()))
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())
        .and_then(|child| wait(child, timeout));
    drop(server);
    let json = std::fs::read_to_string(&out).unwrap_or_default();
    match verified {
        Ok((_, stderr)) if json.contains("\"findings\":") => {
            o.checked = number(&json, "checked").unwrap_or(0);
            o.structures = number(&json, "structures_compared").unwrap_or(0) as usize;
            o.structure_mismatches = strings(&json, "structure_mismatches");
            let namespaces = verify_report::json_namespaces(&json);
            // check's explanations, computed for the files with a violation below Instances only.
            let mut explains = None;
            let mut verified = Vec::new();
            let declarations = verify_report::json_declarations(&json);
            for ((code, severity, path, message), declaration) in verify_report::json_findings(&json).into_iter().zip(declarations) {
                if path.split('/').next().is_some_and(|top| top.ends_with(":Instances")) {
                    let explained = declaration.and_then(|(file, line)| {
                        explains.get_or_insert_with(|| findings_check_explains(unit, &[models.to_path_buf()]));
                        let key = (code.clone(), canonical(&file), line);
                        explains.as_ref()?.as_ref().ok()?.get(&key).map(|d| format!("{d} ({}:{line})", key.1))
                    });
                    match explained {
                        Some(why) => o.explained.push((format!("{code} {path}"), why)),
                        None => o.below.push((code, path, message.replace('\n', " "))),
                    }
                } else {
                    o.elsewhere += 1;
                    verified.push((code, severity, verify_report::path_by_uri(&path, &namespaces)));
                }
            }
            match static_findings_by_uri(unit, &[models.to_path_buf()]) {
                Ok(checked) => o.disagreements = verify_report::disagreements(&checked, &verified),
                Err(e) => o.disagreements.push(format!("check could not run: {e}")),
            }
            let _ = stderr;
        }
        Ok((status, stderr)) => {
            let errors: Vec<&str> = stderr.lines().filter(|l| !l.starts_with("warning: --insecure")).take(3).collect();
            o.failed = Some(format!("verify ended with {status}: {}", errors.join("\n")));
        }
        Err(e) => o.failed = Some(e),
    }
    o
}

/// Waits for `child` at most `timeout` (then kills it); its exit status and stderr.
fn wait(mut child: std::process::Child, timeout: Duration) -> Result<(std::process::ExitStatus, String), String> {
    let start = Instant::now();
    let mut err = child.stderr.take();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        if let Some(e) = err.as_mut() {
            let _ = std::io::Read::read_to_string(e, &mut s);
        }
        s
    });
    loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            return Ok((status, reader.join().unwrap_or_default()));
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("verify did not finish within {} s", timeout.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn number(json: &str, key: &str) -> Option<u64> {
    let at = json.find(&format!("\"{key}\":"))? + key.len() + 3;
    json[at..].chars().take_while(char::is_ascii_digit).collect::<String>().parse().ok()
}

/// The strings of the array `"key":[...]` of a `verify --json` report (none of them holds `"]`).
fn strings(json: &str, key: &str) -> Vec<String> {
    let Some(at) = json.find(&format!("\"{key}\":[")) else { return Vec::new() };
    let list = &json[at + key.len() + 4..];
    if list.starts_with(']') {
        return Vec::new();
    }
    let list = &list[..list.find("\"]").map_or(0, |e| e + 1)];
    list.split("\",\"").map(|m| m.trim_matches('"').replace("\\\"", "\"")).filter(|m| !m.is_empty()).collect()
}

/// `file` canonicalized, as text (as it is when it cannot be).
fn canonical(file: &str) -> String {
    std::fs::canonicalize(file).map_or_else(|_| file.to_owned(), |p| p.display().to_string())
}

fn rel(root: &Path, f: &Path) -> String {
    let shared = root.join("../shared/nodesets").canonicalize().unwrap_or_default();
    let vendor = root.join(crate::fetch::VENDOR_DIR).canonicalize().unwrap_or_default();
    if let Ok(r) = f.strip_prefix(&vendor) {
        return Path::new(crate::fetch::VENDOR_DIR).join(r).display().to_string();
    }
    f.strip_prefix(&shared).or_else(|_| f.strip_prefix(root)).unwrap_or(f).display().to_string()
}
