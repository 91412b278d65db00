//! The Commands2 drilling cell as three OPC UA servers on loopback, started by one command:
//!
//! ```text
//! cargo run -p nodeset-examples --example robot_cell -- [--port 4861] [--motion-ms 1000] [--seconds N]
//! ```
//!
//! - the **robot** (port P): the UR10e of `TemplateDrillingLwrSystem`; its controller's SkillSet serves the
//!   basic move skills `AbsoluteJointPTPMove` (the six joints' `ActualPosition` move to the target),
//!   `RelativeCartesianLinearMove` and `AbsoluteCartesianLinearMove`;
//! - the **drilling unit** (port P+1): the drilling end effector's `TemplateDrilling`;
//! - the **cell** (port P+2): `DrillingCell/SkillSet` with the composite skills `DrillHole` (move in by
//!   `InsertionDistance`, drill, move out) and `ReferenceDrillBush` (approach the bush `ApproachDistance`
//!   above `HolePosition`, move onto it, report the measured pose in `ReferencedHolePosition`). The cell
//!   finds the basic skills on the other two servers by browse path and runs them as typed clients
//!   (`runtime::client::RemoteProgram::run_step`, with the composite semantics of `runtime::remote`): a
//!   basic skill that halts halts the composite, one that is suspended suspends it, and a Halt of the
//!   composite halts the basic skill that runs.
//!
//! Every server loads the same models (CommonSkills, RobotCell, DrillingProcess and what they require), so
//! each shows the whole cell; it runs only its own device's skills. The skills of the other devices stay
//! Ready there and answer Start with `BadNotImplemented`. Each basic skill takes `--motion-ms` (in steps of
//! at most 10 ms, each a point where a Suspend parks it).
//!
//! Security: every server is secure by default (see `nodeset_examples::secure` for `--pki`, `--users`,
//! `--trust-on-first-use` and `--insecure`, which adds a None endpoint for loopback clients). The cell's
//! composite skills always reach the robot and the drilling unit over Basic256Sha256 SignAndEncrypt as
//! user `cell` (Operator there; a random password drawn at each start, stored only as an Argon2id hash),
//! and verify their certificates: the process puts each device's certificate into the trust list of the
//! cell's client (`<pki>/cell-client/trusted/`) and the client's into the devices' (`<pki>/<device>/trusted/`).
//!
//! `--port 0` takes free ports. It prints `robot listening on <url>`, `drilling unit listening on <url>`,
//! `cell listening on <url>`, then `cell ready` once the cell found the basic skills; it stops on SIGINT,
//! SIGTERM or after `--seconds N`, printing `server stopped cleanly`.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use nodeset_models::models::common_skills::objects::{
    AbsoluteCartesianLinearMoveSkillType, AbsoluteCartesianLinearMoveSkillTypeInputs, AbsoluteJointPtpMoveSkillType,
    AbsoluteJointPtpMoveSkillTypeInputs, ProgramSkillStateMachineTypeOutputs as Done,
    RelativeCartesianLinearMoveSkillType, RelativeCartesianLinearMoveSkillTypeInputs,
};
use nodeset_models::models::drilling_process::objects::{
    DrillHoleSkillType, DrillHoleSkillTypeInputs, ReferenceDrillBushSkillType, ReferenceDrillBushSkillTypeInputs,
    ReferenceDrillBushSkillTypeOutputs,
};
use nodeset_models::models::robot_cell::objects::{TemplateDrillingSkillType, TemplateDrillingSkillTypeInputs};
use nodeset_models::models::di::objects::ComponentType;
use nodeset_models::models::robotics::objects::{AxisType, MotionDeviceSystemType};
use nodeset_models::models;
use nodeset_examples::describe::{describe, nameplate};
use nodeset_examples::secure::{SecureArgs, USAGE};
use nodeset_models::runtime::client::ClientConfig;
use nodeset_models::runtime::server::users::random_password;
use nodeset_models::runtime::server::{security, stop_requested, ModelServer as Server, Role, RunningServer, ServerConfig};
use nodeset_models::runtime::typed::{Control, Program};
use opcua::types::{StatusCode, ThreeDCartesianCoordinates, ThreeDFrame, ThreeDOrientation};

const SYSTEM: &str = "DeviceSet/TemplateDrillingLwrSystem";
const CONTROLLER_SKILLS: &str = "MotionDeviceSystem/Controllers/URController/SkillSet";
const AXES: &str = "MotionDeviceSystem/MotionDevices/Manipulator/Axes";
const JOINTS: [&str; 6] = ["Base", "Shoulder", "Elbow", "Wrist1", "Wrist2", "Wrist3"];
const DRILL: &str = "DrillingEndEffector/SkillSet/TemplateDrilling";
const CELL_SKILLS: &str = "DrillingCell/SkillSet";

struct Options {
    port: u16,
    motion: Duration,
    seconds: Option<u64>,
    secure: SecureArgs,
}

fn options() -> Result<Options, String> {
    let mut o = Options { port: 4861, motion: Duration::from_millis(1000), seconds: None, secure: SecureArgs::default() };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if o.secure.take(&arg, &mut args)? {
            continue;
        }
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--port" => o.port = value("--port")?.parse().map_err(|e| format!("--port: {e}"))?,
            "--motion-ms" => {
                o.motion = Duration::from_millis(value("--motion-ms")?.parse().map_err(|e| format!("--motion-ms: {e}"))?)
            }
            "--seconds" => o.seconds = Some(value("--seconds")?.parse().map_err(|e| format!("--seconds: {e}"))?),
            other => {
                return Err(format!(
                    "unknown argument {other:?} (usage: robot_cell [--port 4861] [--motion-ms 1000] [--seconds N] {USAGE})"
                ))
            }
        }
    }
    Ok(o)
}

/// The PKI folder of the cell below `--pki` (default `pki/robot_cell`): one folder per server, and
/// `cell-client` for the composite skills' client.
fn pki(secure: &SecureArgs, sub: &str) -> PathBuf {
    secure.pki.clone().unwrap_or_else(|| PathBuf::from("pki/robot_cell")).join(sub)
}

fn config(name: &str, port: u16, secure: &SecureArgs, sub: &str) -> Result<ServerConfig, String> {
    // Each step of a composite skill ends with a transition event of a basic skill: publish quickly.
    let config = models::register(ServerConfig::new(name).port(port).min_publishing_interval_ms(10));
    let mut own = secure.clone();
    own.pki = Some(pki(secure, sub));
    own.apply(config, sub)
}

fn start(label: &str, server: Server) -> RunningServer {
    let running = server.start();
    println!("{label} listening on {}", running.endpoint_url());
    let _ = std::io::stdout().flush();
    running
}

/// Waits for `time`, in steps of at most 10 ms, calling `step` with the fraction done after each and
/// parking while the skill is suspended.
async fn work(ctl: &Control, time: Duration, mut step: impl FnMut(f64)) {
    let steps = (time.as_millis() / 10).max(1) as u32;
    for i in 1..=steps {
        ctl.checkpoint().await;
        tokio::time::sleep(time / steps).await;
        step(f64::from(i) / f64::from(steps));
    }
}

/// The robot: the three move skills of the controller's SkillSet.
fn robot(server: &Server, motion: Duration) -> Result<Vec<Program>, String> {
    let m = server.manager();
    let e = |e: nodeset_models::runtime::typed::BindError| e.to_string();
    let skills = format!("{SYSTEM}/{CONTROLLER_SKILLS}");
    let axes: Vec<AxisType> =
        JOINTS.iter().map(|j| m.bind_path(&format!("{SYSTEM}/{AXES}/{j}"))).collect::<Result<_, _>>().map_err(e)?;
    let positions: Arc<Vec<_>> = Arc::new(axes.iter().map(|a| a.parameter_set.actual_position.clone()).collect());
    for p in positions.iter() {
        p.set(0.0).map_err(|s| s.to_string())?;
    }
    // The tool centre point, which the Cartesian moves change (the cell has no kinematics).
    let tcp = Arc::new(Mutex::new(ThreeDFrame::default()));

    let ptp: AbsoluteJointPtpMoveSkillType = m.bind_path(&format!("{skills}/AbsoluteJointPTPMove")).map_err(e)?;
    let ptp = ptp
        .serve(move |inputs: AbsoluteJointPtpMoveSkillTypeInputs, ctl| {
            let positions = positions.clone();
            async move {
                if inputs.target_joint_positions.len() != positions.len() || inputs.speed <= 0.0 {
                    return Err(StatusCode::BadInvalidArgument);
                }
                let from: Vec<f64> = positions.iter().map(|p| p.get().unwrap_or(0.0)).collect();
                work(&ctl, motion, |done| {
                    for ((p, a), b) in positions.iter().zip(&from).zip(&inputs.target_joint_positions) {
                        let _ = p.set(a + (b - a) * done);
                    }
                })
                .await;
                Ok(Done {})
            }
        })
        .map_err(|e| e.to_string())?;

    let relative: RelativeCartesianLinearMoveSkillType =
        m.bind_path(&format!("{skills}/RelativeCartesianLinearMove")).map_err(e)?;
    let t = tcp.clone();
    let relative = relative
        .serve(move |inputs: RelativeCartesianLinearMoveSkillTypeInputs, ctl| {
            let tcp = t.clone();
            async move {
                if inputs.speed <= 0.0 {
                    return Err(StatusCode::BadInvalidArgument);
                }
                let from = tcp.lock().unwrap_or_else(|e| e.into_inner()).clone();
                let to = add(&from, &inputs.pose_offset);
                work(&ctl, motion, |done| *tcp.lock().unwrap_or_else(|e| e.into_inner()) = lerp(&from, &to, done)).await;
                Ok(Done {})
            }
        })
        .map_err(|e| e.to_string())?;

    let absolute: AbsoluteCartesianLinearMoveSkillType =
        m.bind_path(&format!("{skills}/AbsoluteCartesianLinearMove")).map_err(e)?;
    let absolute = absolute
        .serve(move |inputs: AbsoluteCartesianLinearMoveSkillTypeInputs, ctl| {
            let tcp = tcp.clone();
            async move {
                if inputs.speed <= 0.0 {
                    return Err(StatusCode::BadInvalidArgument);
                }
                let from = tcp.lock().unwrap_or_else(|e| e.into_inner()).clone();
                let to = inputs.target_pose;
                work(&ctl, motion, |done| *tcp.lock().unwrap_or_else(|e| e.into_inner()) = lerp(&from, &to, done)).await;
                Ok(Done {})
            }
        })
        .map_err(|e| e.to_string())?;
    Ok(vec![ptp, relative, absolute])
}

fn add(a: &ThreeDFrame, b: &ThreeDFrame) -> ThreeDFrame {
    let (p, q) = (&a.cartesian_coordinates, &b.cartesian_coordinates);
    let (r, s) = (&a.orientation, &b.orientation);
    ThreeDFrame {
        cartesian_coordinates: ThreeDCartesianCoordinates { x: p.x + q.x, y: p.y + q.y, z: p.z + q.z },
        orientation: ThreeDOrientation { a: r.a + s.a, b: r.b + s.b, c: r.c + s.c },
    }
}

fn lerp(a: &ThreeDFrame, b: &ThreeDFrame, t: f64) -> ThreeDFrame {
    let f = |x: f64, y: f64| x + (y - x) * t;
    let (p, q) = (&a.cartesian_coordinates, &b.cartesian_coordinates);
    let (r, s) = (&a.orientation, &b.orientation);
    ThreeDFrame {
        cartesian_coordinates: ThreeDCartesianCoordinates { x: f(p.x, q.x), y: f(p.y, q.y), z: f(p.z, q.z) },
        orientation: ThreeDOrientation { a: f(r.a, s.a), b: f(r.b, s.b), c: f(r.c, s.c) },
    }
}

/// Gives the variables of the cell's devices that RobotCell.NodeSet2.xml leaves without a value one
/// (nameplates, units, the safety state, ...: see `nodeset_examples::describe`), on every server, since each
/// shows the whole cell.
fn describe_cell(server: &Server) -> Result<(), String> {
    let m = server.manager();
    let system: MotionDeviceSystemType = m.bind_path(&format!("{SYSTEM}/MotionDeviceSystem")).map_err(|e| e.to_string())?;
    describe(m, &system)?;
    let unit: ComponentType = m.bind_path(&format!("{SYSTEM}/DrillingEndEffector")).map_err(|e| e.to_string())?;
    nameplate(&unit, "DU-8", "DU-8-400", "D-0001")
}

/// The drilling unit: TemplateDrilling.
fn drilling_unit(server: &Server, motion: Duration) -> Result<Program, String> {
    let drill: TemplateDrillingSkillType =
        server.manager().bind_path(&format!("{SYSTEM}/{DRILL}")).map_err(|e| e.to_string())?;
    drill
        .serve(move |inputs: TemplateDrillingSkillTypeInputs, ctl| async move {
            if inputs.hole_diameter <= 0.0 || inputs.depth <= 0.0 || inputs.feed_rate <= 0.0 {
                return Err(StatusCode::BadInvalidArgument);
            }
            work(&ctl, motion, |_| {}).await;
            Ok(Done {})
        })
        .map_err(|e| e.to_string())
}

fn frame(x: f64, y: f64, z: f64) -> ThreeDFrame {
    ThreeDFrame {
        cartesian_coordinates: ThreeDCartesianCoordinates { x, y, z },
        orientation: ThreeDOrientation { a: 0.0, b: 0.0, c: 0.0 },
    }
}

/// The cell: DrillHole and ReferenceDrillBush, composed of the skills of the robot and the drilling unit.
async fn cell(server: &Server, robot_url: &str, unit_url: &str, client: &ClientConfig) -> Result<Vec<Program>, String> {
    let e = |e: nodeset_models::runtime::client::ClientError| e.to_string();
    let robot = client.connect(robot_url).await.map_err(|e| e.to_string())?;
    let unit = client.connect(unit_url).await.map_err(|e| e.to_string())?;
    let skills = format!("{SYSTEM}/{CONTROLLER_SKILLS}");
    // The basic skills, bound by browse path as typed clients of their generated types.
    let (relative, absolute) = (format!("{skills}/RelativeCartesianLinearMove"), format!("{skills}/AbsoluteCartesianLinearMove"));
    let relative = Arc::new(robot.program::<RelativeCartesianLinearMoveSkillType>(&relative).await.map_err(e)?);
    let absolute = Arc::new(robot.program::<AbsoluteCartesianLinearMoveSkillType>(&absolute).await.map_err(e)?);
    let drill = Arc::new(unit.program::<TemplateDrillingSkillType>(&format!("{SYSTEM}/{DRILL}")).await.map_err(e)?);
    // The skills keep their sessions open; the servers' handles are not needed any more.
    drop((robot, unit));

    let m = server.manager();
    let drill_hole: DrillHoleSkillType = m.bind_path(&format!("{CELL_SKILLS}/DrillHole")).map_err(|e| e.to_string())?;
    let r = relative.clone();
    let drill_hole = drill_hole
        .serve(move |i: DrillHoleSkillTypeInputs, ctl| {
            let (relative, drill) = (r.clone(), drill.clone());
            async move {
                let offset = |z| RelativeCartesianLinearMoveSkillTypeInputs {
                    speed: 50.0,
                    acceleration: 200.0,
                    pose_offset: frame(0.0, 0.0, z),
                };
                relative.run_step(offset(i.insertion_distance), &ctl).await?;
                let drilling = TemplateDrillingSkillTypeInputs {
                    hole_diameter: i.hole_diameter,
                    depth: i.depth,
                    feed_rate: i.feed_rate,
                    spindle_speed: i.spindle_speed,
                    clamp_force: i.clamp_force,
                };
                drill.run_step(drilling, &ctl).await?;
                relative.run_step(offset(-i.insertion_distance), &ctl).await?;
                Ok(Done {})
            }
        })
        .map_err(|e| e.to_string())?;

    let reference: ReferenceDrillBushSkillType =
        m.bind_path(&format!("{CELL_SKILLS}/ReferenceDrillBush")).map_err(|e| e.to_string())?;
    let reference = reference
        .serve(move |i: ReferenceDrillBushSkillTypeInputs, ctl| {
            let (relative, absolute) = (relative.clone(), absolute.clone());
            async move {
                let mut approach = i.hole_position.clone();
                approach.cartesian_coordinates.z += i.approach_distance;
                let to_approach =
                    AbsoluteCartesianLinearMoveSkillTypeInputs { speed: 100.0, acceleration: 400.0, target_pose: approach };
                absolute.run_step(to_approach, &ctl).await?;
                let onto = RelativeCartesianLinearMoveSkillTypeInputs {
                    speed: 20.0,
                    acceleration: 100.0,
                    pose_offset: frame(0.0, 0.0, -i.approach_distance),
                };
                relative.run_step(onto, &ctl).await?;
                // The simulated hole referencing unit measures the bush where it was expected.
                Ok(ReferenceDrillBushSkillTypeOutputs { referenced_hole_position: i.hole_position })
            }
        })
        .map_err(|e| e.to_string())?;
    Ok(vec![drill_hole, reference])
}

async fn run(o: Options) -> Result<(), String> {
    let stop = stop_requested(o.seconds);
    let next = |k: u16| if o.port == 0 { 0 } else { o.port + k };
    // The composite skills reach the devices over SignAndEncrypt as user `cell` (Operator on the devices, with
    // a password drawn at each start and kept only hashed there), and verify the devices' certificates: the
    // cell provisions the trust both ways, as an administrator would by moving certificates into trusted/.
    let password = random_password();
    let client_pki = pki(&o.secure, "cell-client");
    let client = ClientConfig::new(&client_pki)
        .application("nodeset-models composite skill", "urn:nodeset-models:composite-skill")
        .user("cell", password.clone());
    let client_cert = security::prepare_pki(&client_pki, &client.application_name, &client.application_uri, &[])
        .map_err(|e| e.to_string())?
        .cert;
    let device = |name: &str, port: u16, sub: &str| -> Result<Server, String> {
        let mut config = config(name, port, &o.secure, sub)?;
        config.users.set_password("cell", vec![Role::Operator], &password)?;
        let server = config.build()?;
        security::trust_certificate(&pki(&o.secure, sub), &client_cert).map_err(|e| e.to_string())?;
        let own = security::own_certificate(&pki(&o.secure, sub)).map_err(|e| e.to_string())?;
        security::trust_certificate(&client_pki, &own).map_err(|e| e.to_string())?;
        Ok(server)
    };
    let robot_server = device("UR10e robot", o.port, "robot")?;
    let unit_server = device("Drilling unit", next(1), "drilling-unit")?;
    let cell_server = config("Drilling cell", next(2), &o.secure, "cell")?.build()?;
    let (robot_url, unit_url) = (robot_server.endpoint_url().to_owned(), unit_server.endpoint_url().to_owned());
    for server in [&robot_server, &unit_server, &cell_server] {
        describe_cell(server)?;
    }

    let robot_skills = robot(&robot_server, o.motion)?;
    let drilling = drilling_unit(&unit_server, o.motion)?;
    let servers = vec![start("robot", robot_server), start("drilling unit", unit_server)];
    let cell_skills = cell(&cell_server, &robot_url, &unit_url, &client).await?;
    let mut servers = servers;
    servers.push(start("cell", cell_server));
    println!("cell ready");
    let _ = std::io::stdout().flush();

    stop.await;
    // The cell first: its skills hold sessions to the other two.
    drop(cell_skills);
    let mut failed = Vec::new();
    for s in servers.into_iter().rev() {
        if let Err(e) = s.stop().await {
            failed.push(e);
        }
    }
    drop((robot_skills, drilling));
    if !failed.is_empty() {
        return Err(failed.join("; "));
    }
    println!("server stopped cleanly");
    Ok(())
}

fn main() -> ExitCode {
    let filter = std::env::var("RUST_LOG").unwrap_or_else(|_| "warn,opcua_server=error,opcua_nodes=error,opcua_crypto=off,opcua_core=error,opcua_core::comms::secure_channel=off,opcua_client=off".into());
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
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
