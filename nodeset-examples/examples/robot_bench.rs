//! Benchmark of the typed API at scale: N six-axis robots (Robotics `MotionDeviceSystemType`, instantiated as
//! the `robot` example does) in one running server, every joint position updated at a fixed rate through the
//! typed `Variable<f64>` handles.
//!
//! ```text
//! cargo run --release -p nodeset-examples --example robot_bench -- [--robots 100] [--hz 100] [--seconds 10]
//! ```
//!
//! `cargo xtask bench --scenario robots` builds and runs it. It reports, on one `BENCH key=value ...` line:
//!
//! * `nodes_per_robot`: the nodes of one instance (everything its hierarchical references reach);
//! * `instantiate_ms`: wall time to instantiate and bind all robots, `instantiate_per_robot_ms` per robot;
//! * `rss_base_kib`: resident memory of the running server with ns0, DI, IA and Robotics, before any robot;
//!   `rss_robots_kib` after the robots exist; `kib_per_robot` the difference per robot (VmRSS from
//!   `/proc/self/status`, measured after the first second of updates so that values are allocated too);
//! * `cycle_*_us`: the time of one update cycle (every joint of every robot set once, each set reported to
//!   the subscription machinery): median, 99th percentile and maximum over all cycles;
//! * `cycles`, `late_cycles`: cycles run, and cycles whose work took longer than the period;
//! * `achieved_hz`: cycles per second actually run (the period is a tokio interval that skips missed ticks).

use std::process::ExitCode;
use std::time::{Duration, Instant};

use bench_support::{proc_status_kib, Line};

use nodeset_models::models::robotics::objects::MotionDeviceSystemType;
use nodeset_models::models::{di, ia, robotics};
use nodeset_models::runtime::server::{ModelManager, ServerConfig};
use nodeset_models::runtime::typed::{Instantiate, ObjectType, Variable};
use opcua::types::{NodeId, ObjectId};

const AXES: [&str; 6] = ["A1", "A2", "A3", "A4", "A5", "A6"];

struct Options {
    robots: usize,
    hz: u32,
    seconds: u64,
}

fn options() -> Result<Options, String> {
    let mut o = Options { robots: 100, hz: 100, seconds: 10 };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--robots" => o.robots = value("--robots")?.parse().map_err(|e| format!("--robots: {e}"))?,
            "--hz" => o.hz = value("--hz")?.parse().map_err(|e| format!("--hz: {e}"))?,
            "--seconds" => o.seconds = value("--seconds")?.parse().map_err(|e| format!("--seconds: {e}"))?,
            other => return Err(format!("unknown argument {other:?} (usage: robot_bench [--robots N] [--hz N] [--seconds N])")),
        }
    }
    if o.robots == 0 || o.hz == 0 || o.seconds == 0 {
        return Err("--robots, --hz and --seconds must be at least 1".into());
    }
    Ok(o)
}

/// The robot of the `robot` example: one arm, six axes with power trains, a controller and a safety state.
fn robot_options() -> Instantiate {
    let mut o = Instantiate::new()
        .placeholder("MotionDevices/<MotionDeviceIdentifier>", ["Arm"])
        .placeholder("MotionDevices/Arm/Axes/<AxisIdentifier>", AXES)
        .placeholder("MotionDevices/Arm/PowerTrains/<PowerTrainIdentifier>", AXES.map(|a| format!("PT{}", &a[1..])))
        .placeholder("Controllers/<ControllerIdentifier>", ["Controller"])
        .placeholder("SafetyStates/<SafetyStateIdentifier>", ["SafetyState"])
        .placeholder("Controllers/Controller/TaskControls/<TaskControlIdentifier>", ["Task"])
        .placeholder("Controllers/Controller/Software/<SoftwareIdentifier>", ["Software"]);
    for a in AXES {
        let pt = format!("MotionDevices/Arm/PowerTrains/PT{}", &a[1..]);
        o = o.placeholder(format!("{pt}/<MotorIdentifier>"), ["Motor"]).placeholder(format!("{pt}/<GearIdentifier>"), ["Gear"]);
    }
    o
}

/// A field of `/proc/self/status` in KiB (`VmRSS`, `VmHWM`); an error where it cannot be read.
fn status_kib(field: &str) -> Result<u64, String> {
    proc_status_kib(field).ok_or_else(|| format!("/proc/self/status cannot be read or has no {field}"))
}

/// The nodes reachable from `root` through forward hierarchical references, `root` included.
fn count_nodes(manager: &ModelManager, root: &NodeId) -> usize {
    manager
        .bind_with(|b| {
            let mut seen = std::collections::HashSet::new();
            let mut stack = vec![root.clone()];
            while let Some(n) = stack.pop() {
                if seen.insert(n.clone()) {
                    stack.extend(b.children(&n));
                }
            }
            Ok(seen.len())
        })
        .unwrap_or(0)
}

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

async fn run(o: Options) -> Result<(), String> {
    let server = ServerConfig::new("robot bench")
        .port(0)
        .table(&di::TABLE)
        .type_loader(di::TypeLoader)
        .table(&ia::TABLE)
        .type_loader(ia::TypeLoader)
        .table(&robotics::TABLE)
        .type_loader(robotics::TypeLoader)
        .build()?;
    let manager = server.manager().clone();
    let handle = server.handle().clone();
    let task = tokio::spawn(server.run());
    tokio::time::sleep(Duration::from_millis(200)).await;
    let rss_base = status_kib("VmRSS")?;

    let objects: NodeId = ObjectId::ObjectsFolder.into();
    let options = robot_options();
    let started = Instant::now();
    let mut joints: Vec<Variable<f64>> = Vec::with_capacity(o.robots * AXES.len());
    let mut nodes_per_robot = 0;
    for r in 0..o.robots {
        let robot = MotionDeviceSystemType::instantiate(&manager, &objects, &format!("Robot{r:04}"), &options)
            .map_err(|e| format!("robot {r}: {e}"))?;
        if r == 0 {
            nodes_per_robot = count_nodes(&manager, robot.node.id());
        }
        let arm = robot.motion_devices.motion_device_identifier.get("Arm").ok_or("a robot without its arm")?;
        joints.extend(arm.axes.axis_identifier.values().map(|a| a.parameter_set.actual_position.clone()));
    }
    let instantiate = started.elapsed();
    if joints.len() != o.robots * AXES.len() {
        return Err(format!("{} joints bound, {} expected", joints.len(), o.robots * AXES.len()));
    }

    let period = Duration::from_secs_f64(1.0 / f64::from(o.hz));
    let mut tick = tokio::time::interval(period);
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let mut cycles = Vec::with_capacity(o.seconds as usize * o.hz as usize);
    let mut rss_robots = None;
    let began = Instant::now();
    let end = began + Duration::from_secs(o.seconds);
    while Instant::now() < end {
        tick.tick().await;
        let t = began.elapsed().as_secs_f64();
        let cycle = Instant::now();
        for (i, joint) in joints.iter().enumerate() {
            let axis = (i % AXES.len()) as f64;
            joint.set((90.0 - 10.0 * axis) * (t * (0.2 + 0.05 * axis)).sin()).map_err(|s| format!("set: {s}"))?;
        }
        cycles.push(cycle.elapsed());
        if rss_robots.is_none() && began.elapsed() >= Duration::from_secs(1).min(Duration::from_secs(o.seconds) / 2) {
            rss_robots = Some(status_kib("VmRSS")?);
        }
    }
    let ran = began.elapsed();
    let rss_robots = match rss_robots {
        Some(r) => r,
        None => status_kib("VmRSS")?,
    };
    handle.cancel();
    task.await.map_err(|e| e.to_string())??;

    let late = cycles.iter().filter(|c| **c > period).count();
    let n = cycles.len();
    cycles.sort();
    let us = |d: Duration| d.as_secs_f64() * 1e6;
    let instantiate_ms = instantiate.as_secs_f64() * 1e3;
    Line::new()
        .kv("scenario", "robots")
        .kv("robots", o.robots)
        .kv("joints", joints.len())
        .kv("hz", o.hz)
        .kv("seconds", o.seconds)
        .kv("nodes_per_robot", nodes_per_robot)
        .num("instantiate_ms", instantiate_ms, 1)
        .num("instantiate_per_robot_ms", instantiate_ms / o.robots as f64, 2)
        .kv("rss_base_kib", rss_base)
        .kv("rss_robots_kib", rss_robots)
        .num("kib_per_robot", rss_robots.saturating_sub(rss_base) as f64 / o.robots as f64, 1)
        .kv("cycles", n)
        .kv("late_cycles", late)
        .num("achieved_hz", n as f64 / ran.as_secs_f64(), 1)
        .num("cycle_median_us", us(percentile(&cycles, 0.5)), 1)
        .num("cycle_p99_us", us(percentile(&cycles, 0.99)), 1)
        .num("cycle_max_us", us(cycles[n - 1]), 1)
        .kv("vmhwm_kib", status_kib("VmHWM")?)
        .print();
    Ok(())
}

fn main() -> ExitCode {
    let o = match options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: cannot start tokio: {e}");
            return ExitCode::FAILURE;
        }
    };
    match runtime.block_on(run(o)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
