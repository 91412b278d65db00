//! The `robots` scenario: the typed API at scale (issue "Typed ObjectTypes"): `nodeset-examples/examples/robot_bench.rs`
//! instantiates N six-axis Robotics robots in one running server and updates every joint position at a fixed
//! rate through typed handles; this task builds it in release mode, runs it once and shows its figures.

use std::path::Path;
use std::process::Command;

use super::{build, run_report};

/// Builds and runs the robot bench with `robots` robots for `seconds` seconds at `hz`, and prints its report.
pub(super) fn run(root: &Path, robots: usize, hz: u32, seconds: u64) -> Result<(), String> {
    let exe = build(root, "nodeset-examples", "robot_bench", &[])?;
    eprintln!("robots: {robots} robots, every joint set at {hz} Hz for {seconds} s ...");
    let r = run_report(Command::new(&exe).args([
        "--robots",
        &robots.to_string(),
        "--hz",
        &hz.to_string(),
        "--seconds",
        &seconds.to_string(),
    ]))
    .map_err(|e| format!("the robot bench: {e}"))?;
    let period_us = 1e6 / f64::from(hz);
    println!();
    println!("Typed API at scale: {} robots x 6 axes ({} joints) in one server, release build.", r.s("robots"), r.s("joints"));
    println!("  nodes per robot                 {:>10}", r.s("nodes_per_robot"));
    println!("  instantiate + bind, all robots  {:>10.1} ms  ({:.2} ms per robot)", r.f("instantiate_ms"), r.f("instantiate_per_robot_ms"));
    println!("  resident memory before robots   {:>10.1} MiB", r.f("rss_base_kib") / 1024.0);
    println!("  resident memory with robots     {:>10.1} MiB", r.f("rss_robots_kib") / 1024.0);
    println!("  memory per robot                {:>10.1} KiB", r.f("kib_per_robot"));
    println!(
        "  update cycle ({} joints set)   median {:.1} us, p99 {:.1} us, max {:.1} us  ({:.1}% of the {:.0} us period at the median)",
        r.s("joints"),
        r.f("cycle_median_us"),
        r.f("cycle_p99_us"),
        r.f("cycle_max_us"),
        100.0 * r.f("cycle_median_us") / period_us,
        period_us
    );
    println!(
        "  cycles                          {:>10}  ({} late, {:.1} Hz achieved of {hz} Hz)",
        r.s("cycles"),
        r.s("late_cycles"),
        r.f("achieved_hz")
    );
    Ok(())
}
