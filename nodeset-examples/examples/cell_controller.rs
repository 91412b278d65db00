//! A cell controller: a client of the robot of the robot cell, written with the typed client
//! (`runtime::client`), started by one command:
//!
//! ```text
//! cargo run -p nodeset-examples --example cell_controller -- [--url opc.tcp://127.0.0.1:4861/] [--motion-ms 1000]
//! ```
//!
//! Without `--url` it builds and starts the `robot_cell` example itself (on free ports, through the `cargo`
//! that runs it) and stops it at the end; with `--url` it uses the robot of a robot cell that runs already
//! (`cargo run -p nodeset-examples --example robot_cell`). It binds the Manipulator as a Robotics
//! `MotionDeviceType`, finds its joints (the `<AxisIdentifier>` placeholder) by browsing, reads their
//! `ActualPosition`s in one Read, subscribes to them, runs the controller's `AbsoluteJointPTPMove` skill
//! with typed inputs and waits for it to be Ready again, then reads the joints and checks that they reached
//! the target. It prints what it does; the exit status is 0 if the joints reached the target.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, ExitCode, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

use nodeset_models::models::common_skills::objects::{AbsoluteJointPtpMoveSkillType, AbsoluteJointPtpMoveSkillTypeInputs};
use nodeset_models::models::robotics::objects::{members, AxisType, MotionDeviceType};
use nodeset_models::runtime::client::{ClientConfig, Remote};

const SYSTEM: &str = "DeviceSet/TemplateDrillingLwrSystem/MotionDeviceSystem";
const MANIPULATOR: &str = "MotionDevices/Manipulator";
const PTP: &str = "Controllers/URController/SkillSet/AbsoluteJointPTPMove";
/// The joints' target, in degrees, from the base to the flange.
const TARGET: [f64; 6] = [10.0, -45.0, 60.0, -15.0, 90.0, 0.0];

struct Options {
    url: Option<String>,
    motion_ms: u64,
}

fn options() -> Result<Options, String> {
    let mut o = Options { url: None, motion_ms: 1000 };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--url" => o.url = Some(value("--url")?),
            "--motion-ms" => o.motion_ms = value("--motion-ms")?.parse().map_err(|e| format!("--motion-ms: {e}"))?,
            other => return Err(format!("unknown argument {other:?} (usage: cell_controller [--url URL] [--motion-ms 1000])")),
        }
    }
    Ok(o)
}

/// The robot cell, started as a child process; stopped (SIGTERM, then kill) when dropped.
struct Cell(Child);

impl Drop for Cell {
    fn drop(&mut self) {
        let pid = self.0.id().to_string();
        let terminated = Command::new("kill").args(["-TERM", &pid]).status().is_ok_and(|s| s.success());
        if !terminated {
            let _ = self.0.kill();
        }
        let _ = self.0.wait();
    }
}

/// Builds the robot_cell example with the cargo that runs this one, starts it on free ports and returns the
/// robot's URL once the cell is ready.
fn start_cell(motion_ms: u64) -> Result<(Cell, String), String> {
    let cargo = std::env::var("CARGO").map_err(|_| {
        "no --url given and not run by cargo (CARGO is unset): run `cargo run -p nodeset-examples --example cell_controller`, or pass --url".to_owned()
    })?;
    let built = Command::new(&cargo)
        .args(["build", "-q", "-p", "nodeset-examples", "--example", "robot_cell"])
        .status()
        .map_err(|e| format!("cannot run {cargo}: {e}"))?;
    if !built.success() {
        return Err(format!("`{cargo} build -p nodeset-examples --example robot_cell` failed ({built})"));
    }
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let robot_cell = exe.with_file_name(format!("robot_cell{}", std::env::consts::EXE_SUFFIX));
    let child = Command::new(&robot_cell)
        .args(["--port", "0", "--motion-ms", &motion_ms.to_string()])
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", robot_cell.display()))?;
    let mut cell = Cell(child);
    let stdout = cell.0.stdout.take().ok_or("the robot cell has no stdout")?;
    let mut url = None;
    for line in BufReader::new(stdout).lines() {
        let line = line.map_err(|e| e.to_string())?;
        println!("[robot_cell] {line}");
        if let Some(u) = line.strip_prefix("robot listening on ") {
            url = Some(u.to_owned());
        }
        if line == "cell ready" {
            let url = url.ok_or("the robot cell did not print the robot's URL")?;
            return Ok((cell, url));
        }
    }
    Err("the robot cell ended before it was ready".into())
}

async fn control(url: &str) -> Result<bool, String> {
    let e = |e: nodeset_models::runtime::client::ClientError| e.to_string();
    let robot = ClientConfig::new(url)
        .application("cell controller", "urn:nodeset-models:cell-controller")
        .connect()
        .await
        .map_err(|e| e.to_string())?;
    let manipulator: Remote<MotionDeviceType> = robot.bind_path(&format!("{SYSTEM}/{MANIPULATOR}")).await.map_err(e)?;
    let serial = manipulator.read::<String, _>(&members::MotionDeviceType::SerialNumber).await.map_err(e)?;
    println!("manipulator {}: serial number {:?}", manipulator.node(), serial.value.unwrap_or_default());

    // The joints, by browsing the Axes placeholder, read in one Read.
    let joints = manipulator.placeholders::<AxisType>("Axes").await.map_err(e)?;
    let (names, axes): (Vec<String>, Vec<Remote<AxisType>>) = joints.into_iter().unzip();
    let position = &members::AxisType::ParameterSet__ActualPosition;
    let before = Remote::read_each::<f64, _>(&axes, position).await.map_err(e)?;
    for (n, s) in names.iter().zip(&before) {
        println!("joint {n}: {:?} ({})", s.value, s.status);
    }
    if axes.len() != TARGET.len() {
        return Err(format!("the manipulator has {} joints, the target {}", axes.len(), TARGET.len()));
    }

    // Subscriptions to every joint, counted while the skill runs.
    let counts: Arc<Vec<AtomicUsize>> = Arc::new(axes.iter().map(|_| AtomicUsize::new(0)).collect());
    let mut watchers = Vec::new();
    for (i, axis) in axes.iter().enumerate() {
        let mut samples = axis.subscribe::<f64, _>(position, 50).await.map_err(e)?;
        let counts = counts.clone();
        watchers.push(tokio::spawn(async move {
            while let Some(_sample) = samples.next().await {
                counts[i].fetch_add(1, Ordering::Relaxed);
            }
        }));
    }

    // The skill, with typed inputs, awaited to Ready.
    let ptp = robot.program::<AbsoluteJointPtpMoveSkillType>(&format!("{SYSTEM}/{PTP}")).await.map_err(e)?;
    println!("AbsoluteJointPTPMove is {}", ptp.current().map_or("in a state its type lacks", |s| s.name));
    let inputs = AbsoluteJointPtpMoveSkillTypeInputs { speed: 90.0, acceleration: 180.0, target_joint_positions: TARGET.to_vec() };
    println!("AbsoluteJointPTPMove to {TARGET:?}");
    ptp.run(inputs).await.map_err(e)?;
    ptp.wait_for_state("Ready", Duration::from_secs(5)).await.map_err(e)?;
    println!("AbsoluteJointPTPMove is Ready");

    let after = Remote::read_each::<f64, _>(&axes, position).await.map_err(e)?;
    let mut reached = true;
    for ((n, s), (target, count)) in names.iter().zip(&after).zip(TARGET.iter().zip(counts.iter())) {
        let ok = s.value.is_some_and(|v| (v - target).abs() < 1e-6);
        reached &= ok;
        println!("joint {n}: {:?} (target {target}; {} samples while moving)", s.value, count.load(Ordering::Relaxed));
    }
    for w in watchers {
        w.abort();
    }
    drop(ptp);
    robot.disconnect().await;
    Ok(reached)
}

fn main() -> ExitCode {
    let filter = std::env::var("RUST_LOG").unwrap_or_else(|_| "warn,opcua_client=off,opcua_core=error,opcua_crypto=off".into());
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
    let o = match options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let (cell, url) = match o.url {
        Some(url) => (None, url),
        None => match start_cell(o.motion_ms) {
            Ok((cell, url)) => (Some(cell), url),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        },
    };
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: cannot start tokio: {e}");
            return ExitCode::FAILURE;
        }
    };
    let outcome = runtime.block_on(control(&url));
    drop(runtime);
    drop(cell);
    match outcome {
        Ok(true) => {
            println!("the joints reached the target");
            ExitCode::SUCCESS
        }
        Ok(false) => {
            eprintln!("error: the joints did not reach the target");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
