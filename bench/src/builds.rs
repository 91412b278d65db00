//! Timed cargo builds and timed processes: `rust_bench exec` as the stopwatch (wall time, and the CPU time
//! and peak memory of the program's processes), cold and incremental builds of one crate, and cold builds
//! of several crates in alternation.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Instant, SystemTime};

use bench_support::{median, min, Report};

use super::{verdict, Step};
use process_support::workspace::cargo as cargo_command;

/// Release builds run once: they are slow, and the release profile compiles without incremental.
pub(super) const RELEASE_RUNS: usize = 1;

/// Median and min of some wall times, and the median CPU time, in seconds.
#[derive(Clone, Copy)]
pub(super) struct Times {
    pub(super) median: f64,
    pub(super) min: f64,
    pub(super) cpu: f64,
}

impl Times {
    pub(super) const NONE: Times = Times {
        median: f64::NAN,
        min: f64::NAN,
        cpu: f64::NAN,
    };

    /// Of (wall, CPU) pairs.
    pub(super) fn of(v: &[(f64, f64)]) -> Times {
        let wall: Vec<f64> = v.iter().map(|p| p.0).collect();
        let cpu: Vec<f64> = v.iter().map(|p| p.1).collect();
        Times {
            median: median(&wall),
            min: min(&wall),
            cpu: median(&cpu),
        }
    }
}

/// Build times of one crate in one profile.
pub(super) struct Builds {
    /// The first build, dependencies included (cached from earlier bench runs if they are unchanged).
    pub(super) warm: f64,
    pub(super) noop: Times,
    pub(super) cold: Times,
    /// None where nothing was touched.
    pub(super) incr: Option<Times>,
}

/// Cold debug builds (wall, CPU) per round, in the order peer, nodeset-models, DI + IA + Robotics.
pub(super) struct Interleaved {
    pub(super) peer: Vec<(f64, f64)>,
    pub(super) models: Vec<(f64, f64)>,
    pub(super) three: Vec<(f64, f64)>,
}

/// Runs `program args` `runs` times under `rust_bench exec` (wall time, peak RSS, CPU).
pub(super) fn exec(
    bench: &Path,
    runs: usize,
    dir: &Path,
    envs: &[(&str, &str)],
    program: &Path,
    args: &[String],
) -> Step<Report> {
    let mut cmd = Command::new(bench);
    cmd.arg("exec")
        .arg("--runs")
        .arg(runs.max(1).to_string())
        .arg("--dir")
        .arg(dir);
    for (k, v) in envs {
        cmd.arg("--env").arg(format!("{k}={v}"));
    }
    cmd.arg("--").arg(program).args(args);
    let out = cmd
        .stderr(Stdio::piped())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", bench.display()))?;
    if !out.status.success() {
        return Err(format!(
            "{} failed: {}",
            program.display(),
            tail(&out.stderr, 12)
        ));
    }
    Report::parse(&String::from_utf8_lossy(&out.stdout))
        .ok_or_else(|| "rust_bench exec printed no BENCH line".to_string())
}

/// The last `n` lines of some output.
fn tail(bytes: &[u8], n: usize) -> String {
    let text = String::from_utf8_lossy(bytes);
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// Runs cargo quietly in `dir` (with `target` as `CARGO_TARGET_DIR`) and returns its wall time in s.
pub(super) fn cargo(dir: &Path, target: Option<&Path>, args: &[&str]) -> Step<f64> {
    let mut cmd = cargo_command();
    cmd.current_dir(dir)
        .arg("--quiet")
        .args(args)
        .stdin(Stdio::null());
    if let Some(t) = target {
        cmd.env("CARGO_TARGET_DIR", t);
    }
    let t = Instant::now();
    let out = cmd.output().map_err(|e| format!("cannot run cargo: {e}"))?;
    let secs = t.elapsed().as_secs_f64();
    if out.status.success() {
        Ok(secs)
    } else {
        Err(format!(
            "`cargo {}` failed ({}):\n{}",
            args.join(" "),
            out.status,
            tail(&out.stderr, 20)
        ))
    }
}

/// Per round, for each (folder, package) in order: an untimed build, a clean of the package alone and a
/// timed cold debug build.
pub(super) fn interleave(bench: &Path, target: &Path, entries: &[(PathBuf, &str); 3], rounds: usize) -> Step<Interleaved> {
    let mut got: [Vec<(f64, f64)>; 3] = Default::default();
    for _ in 0..rounds {
        for ((dir, package), times) in entries.iter().zip(got.iter_mut()) {
            // The three crates are in different workspaces sharing one target folder; building one can
            // leave a dependency of another stale (a first round measured 3.4x for that reason). An
            // untimed build first brings the dependencies up to date, so the timed build compiles the
            // package alone.
            cargo(dir, Some(target), &["build", "-p", package])?;
            cargo(dir, Some(target), &["clean", "-p", package])?;
            times.push(timed_build(bench, dir, target, &["build", "-p", package])?);
        }
    }
    let [peer, models, three] = got;
    Ok(Interleaved { peer, models, three })
}

/// One `cargo --quiet <args>` in `dir` with `target` as its target folder, under `rust_bench exec`, which
/// also takes the CPU time of cargo and rustc: (wall s, CPU s).
fn timed_build(bench: &Path, dir: &Path, target: &Path, args: &[&str]) -> Step<(f64, f64)> {
    let cargo_exe = PathBuf::from(cargo_command().get_program());
    let target_env = target.display().to_string();
    let mut timed_args = vec!["--quiet".to_string()];
    timed_args.extend(args.iter().map(|a| a.to_string()));
    let r = exec(bench, 1, dir, &[("CARGO_TARGET_DIR", &target_env)], &cargo_exe, &timed_args)?;
    Ok((r.f("wall_median_ms") / 1e3, r.f("cpu_per_run_ms") / 1e3))
}

/// Warm-up, no-op, then per run a clean of `package` alone, a timed (cold) build, and unless `touched`
/// is None, a touch of it and a timed (incremental) build.
///
/// The timed builds run under `rust_bench exec`, which also takes the CPU time of cargo and rustc.
pub(super) fn time_builds(
    bench: &Path,
    dir: &Path,
    target: &Path,
    package: &str,
    release: bool,
    touched: Option<&Path>,
    runs: usize,
) -> Step<Builds> {
    let mut build_args = vec!["build", "-p", package];
    let mut clean_args = vec!["clean", "-p", package];
    if release {
        build_args.push("--release");
        clean_args.push("--release");
    }
    let timed = || timed_build(bench, dir, target, &build_args);
    let warm = cargo(dir, Some(target), &build_args)?;
    let (mut noop, mut cold, mut incr) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..runs.max(1) {
        noop.push(timed()?);
        cargo(dir, Some(target), &clean_args)?;
        cold.push(timed()?);
        if let Some(touched) = touched {
            touch(touched)?;
            incr.push(timed()?);
        }
    }
    Ok(Builds {
        warm,
        noop: Times::of(&noop),
        cold: Times::of(&cold),
        incr: touched.map(|_| Times::of(&incr)),
    })
}

/// Sets the modification time of `path` to now, without changing its content.
fn touch(path: &Path) -> Step<()> {
    fs::File::options()
        .append(true)
        .open(path)
        .and_then(|f| f.set_modified(SystemTime::now()))
        .map_err(|e| format!("cannot touch {}: {e}", path.display()))
}

/// One line of build times (cold, incremental, no-op, warm-up), judged against `target` seconds if given.
pub(super) fn print_builds(label: &str, b: &Step<Builds>, target: Option<f64>) {
    match b {
        Ok(b) => {
            let judged = target
                .map(|t| format!("   target <= {t} s  {}", verdict(b.cold.median, t)))
                .unwrap_or_default();
            let incr = b.incr.map_or_else(
                || format!("{:<49}", "   incremental        -"),
                |i| {
                    format!(
                        "   incremental {:>6.2} s (min {:>6.2}, CPU {:>6.2})",
                        i.median, i.min, i.cpu
                    )
                },
            );
            println!(
                "   {label:<16} cold {:>6.2} s (min {:>6.2}, CPU {:>6.2}){incr}   no-op {:>5.2} s   warm-up {:>6.1} s{judged}",
                b.cold.median, b.cold.min, b.cold.cpu, b.noop.median, b.warm
            );
        }
        Err(e) => println!(
            "   {label:<16} {}",
            e.replace('\n', "\n                    ")
        ),
    }
}
