//! A cell controller: a client of the robot of the robot cell, written with the typed client
//! (`runtime::client`), started by one command:
//!
//! ```text
//! cargo run -p nodeset-examples --example cell_controller
//! ```
//!
//! Without `--url` it builds and starts the `robot_cell` example itself (on free ports, through the `cargo`
//! that runs it, with its PKI folders and user file in a fresh temporary folder) and stops it at the end:
//! it adds a user `controller` (Operator, a password drawn at each start) to the cell's user file, puts its
//! own certificate into the robot's `trusted/` and the robot's into its own, as an administrator would.
//! With `--url` it uses a robot that runs already (`cargo run -p nodeset-examples --example robot_cell`):
//!
//! ```text
//! CELL_CONTROLLER_PASSWORD=... cargo run -p nodeset-examples --example cell_controller -- \
//!     --url opc.tcp://127.0.0.1:4861/ [--pki pki/cell-controller] [--user NAME] [--insecure]
//! ```
//!
//! The session is Basic256Sha256 SignAndEncrypt with the user name and password (`--insecure`: SecurityPolicy
//! None, anonymous, for a robot started with `--insecure`), and the robot's certificate must be in the
//! client's `<pki>/trusted/`: on first contact it is refused and written to `<pki>/rejected/`, to be moved.
//!
//! It binds the Manipulator as a Robotics `MotionDeviceType`, finds its joints (the `<AxisIdentifier>`
//! placeholder) by browsing, reads their `ActualPosition`s in one Read, subscribes to them, runs the
//! controller's `AbsoluteJointPTPMove` skill with typed inputs and waits for it to be Ready again, then
//! reads the joints and checks that they reached the target. It prints what it does; the exit status is 0
//! if the joints reached the target.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

use nodeset_models::models::common_skills::objects::{AbsoluteJointPtpMoveSkillType, AbsoluteJointPtpMoveSkillTypeInputs};
use nodeset_models::models::robotics::objects::{members, AxisType, MotionDeviceType};
use nodeset_models::runtime::client::{ClientConfig, Remote};
use nodeset_models::runtime::server::users::random_password;
use nodeset_models::runtime::server::{security, Role, Users};

const SYSTEM: &str = "DeviceSet/TemplateDrillingLwrSystem/MotionDeviceSystem";
const MANIPULATOR: &str = "MotionDevices/Manipulator";
const PTP: &str = "Controllers/URController/SkillSet/AbsoluteJointPTPMove";
/// The joints, from the base to the flange (the order of the skill's TargetJointPositions).
const JOINTS: [&str; 6] = ["Base", "Shoulder", "Elbow", "Wrist1", "Wrist2", "Wrist3"];
/// The joints' target, in degrees, from the base to the flange.
const TARGET: [f64; 6] = [10.0, -45.0, 60.0, -15.0, 90.0, 0.0];
/// The user the controller adds to a robot cell it starts.
const USER: &str = "controller";

struct Options {
    url: Option<String>,
    motion_ms: u64,
    pki: PathBuf,
    user: Option<String>,
    insecure: bool,
}

const USAGE: &str = "cell_controller [--motion-ms 1000] | cell_controller --url URL [--pki DIR] [--user NAME] [--insecure]";

fn options() -> Result<Options, String> {
    let mut o = Options { url: None, motion_ms: 1000, pki: PathBuf::from("pki/cell-controller"), user: None, insecure: false };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--url" => o.url = Some(value("--url")?),
            "--motion-ms" => o.motion_ms = value("--motion-ms")?.parse().map_err(|e| format!("--motion-ms: {e}"))?,
            "--pki" => o.pki = value("--pki")?.into(),
            "--user" => o.user = Some(value("--user")?),
            "--insecure" => o.insecure = true,
            other => return Err(format!("unknown argument {other:?} (usage: {USAGE})")),
        }
    }
    Ok(o)
}

/// The robot cell, started as a child process; stopped (SIGTERM, then kill) when dropped, and its
/// temporary folder removed.
struct Cell(Child, PathBuf);

impl Drop for Cell {
    fn drop(&mut self) {
        let pid = self.0.id().to_string();
        let terminated = Command::new("kill").args(["-TERM", &pid]).status().is_ok_and(|s| s.success());
        if !terminated {
            let _ = self.0.kill();
        }
        let _ = self.0.wait();
        let _ = std::fs::remove_dir_all(&self.1);
    }
}

/// Builds the robot_cell example with the cargo that runs this one, starts it on free ports with a user
/// for this controller and trust both ways, and returns the robot's URL and the client configuration once
/// the cell is ready.
fn start_cell(motion_ms: u64) -> Result<(Cell, String, ClientConfig), String> {
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
    let dir = std::env::temp_dir().join(format!("nodeset-cell-controller-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let (cell_pki, client_pki, users_file) = (dir.join("cell-pki"), dir.join("client-pki"), dir.join("users.txt"));
    let text = |e: &dyn std::fmt::Display| e.to_string();
    std::fs::create_dir_all(&dir).map_err(|e| text(&e))?;
    let password = random_password();
    let mut users = Users::default();
    users.set_password(USER, vec![Role::Operator], &password)?;
    std::fs::write(&users_file, users.to_text()).map_err(|e| format!("{}: {e}", users_file.display()))?;
    let config = ClientConfig::new(&client_pki).application("cell controller", "urn:nodeset-models:cell-controller").user(USER, password);
    // The robot trusts this controller from its first start: its trust list is in place before it starts.
    let own = security::prepare_pki(&client_pki, &config.application_name, &config.application_uri, &[]).map_err(|e| text(&e))?;
    std::fs::create_dir_all(cell_pki.join("robot/trusted")).map_err(|e| text(&e))?;
    security::trust_certificate(&cell_pki.join("robot"), &own.cert).map_err(|e| text(&e))?;

    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let robot_cell = exe.with_file_name(format!("robot_cell{}", std::env::consts::EXE_SUFFIX));
    let child = Command::new(&robot_cell)
        .args(["--port", "0", "--motion-ms", &motion_ms.to_string()])
        .args([Path::new("--pki"), &cell_pki, Path::new("--users"), &users_file])
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", robot_cell.display()))?;
    let mut cell = Cell(child, dir);
    let stdout = cell.0.stdout.take().ok_or("the robot cell has no stdout")?;
    let mut url = None;
    let mut lines = BufReader::new(stdout).lines();
    while let Some(line) = lines.next() {
        let line = line.map_err(|e| e.to_string())?;
        println!("[robot_cell] {line}");
        if let Some(u) = line.strip_prefix("robot listening on ") {
            url = Some(u.to_owned());
        }
        if line == "cell ready" {
            let url = url.ok_or("the robot cell did not print the robot's URL")?;
            // This controller trusts the robot's certificate.
            let robot = security::own_certificate(&cell_pki.join("robot")).map_err(|e| text(&e))?;
            security::trust_certificate(&client_pki, &robot).map_err(|e| text(&e))?;
            // The rest of the cell's output, until it stops (a closed pipe would make its last line fail).
            std::thread::spawn(move || {
                for line in lines.map_while(Result::ok) {
                    println!("[robot_cell] {line}");
                }
            });
            return Ok((cell, url, config));
        }
    }
    Err("the robot cell ended before it was ready".into())
}

/// The client configuration for a robot that runs already (`--url`).
fn given(o: &Options) -> Result<ClientConfig, String> {
    if o.insecure {
        return Ok(ClientConfig::insecure().application("cell controller", "urn:nodeset-models:cell-controller"));
    }
    let mut config = ClientConfig::new(&o.pki).application("cell controller", "urn:nodeset-models:cell-controller");
    if let Some(user) = &o.user {
        let password = std::env::var("CELL_CONTROLLER_PASSWORD").map_err(|_| format!("--user {user}: set CELL_CONTROLLER_PASSWORD to the password"))?;
        config = config.user(user.clone(), password);
    }
    Ok(config)
}

async fn control(url: &str, config: &ClientConfig) -> Result<bool, String> {
    let e = |e: nodeset_models::runtime::client::ClientError| e.to_string();
    let robot = config.connect(url).await.map_err(|e| {
        let refused: Vec<_> = std::fs::read_dir(config.pki_dir.join("rejected"))
            .map(|dir| dir.filter_map(Result::ok).map(|f| f.path()).collect())
            .unwrap_or_default();
        match refused.first() {
            Some(cert) => format!(
                "{e} (this client does not trust the server's certificate yet: to trust it, move {} to {})",
                cert.display(),
                config.pki_dir.join("trusted").display()
            ),
            None => format!("{e} (if the server does not trust this client yet, its certificate is in the server's rejected/ folder, to be moved to the server's trusted/)"),
        }
    })?;
    let manipulator: Remote<MotionDeviceType> = robot.bind_path(&format!("{SYSTEM}/{MANIPULATOR}")).await.map_err(e)?;
    let serial = manipulator.read::<String, _>(&members::MotionDeviceType::SerialNumber).await.map_err(e)?;
    println!("manipulator {}: serial number {:?}", manipulator.node(), serial.value.unwrap_or_default());

    // The joints, by browsing the Axes placeholder, read in one Read.
    // (Placeholders come in BrowseName order; the skill's target goes from the base to the flange.)
    let joints = manipulator.placeholders::<AxisType>("Axes").await.map_err(e)?;
    let found: Vec<&str> = joints.iter().map(|(n, _)| n.as_str()).collect();
    println!("joints found by browsing: {found:?}");
    let mut axes: Vec<Remote<AxisType>> = Vec::with_capacity(JOINTS.len());
    for joint in JOINTS {
        let axis = joints.iter().find(|(n, _)| n == joint).ok_or(format!("the manipulator has no joint {joint} (it has {found:?})"))?;
        axes.push(axis.1.clone());
    }
    let names = JOINTS;
    let position = &members::AxisType::ParameterSet__ActualPosition;
    let before = Remote::read_each::<f64, _>(&axes, position).await.map_err(e)?;
    for (n, s) in names.iter().zip(&before) {
        println!("joint {n}: {:?} ({})", s.value, s.status);
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
    let started = match &o.url {
        Some(url) => given(&o).map(|config| (None, url.clone(), config)),
        None => start_cell(o.motion_ms).map(|(cell, url, config)| (Some(cell), url, config)),
    };
    let (cell, url, config) = match started {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: cannot start tokio: {e}");
            return ExitCode::FAILURE;
        }
    };
    let outcome = runtime.block_on(control(&url, &config));
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
