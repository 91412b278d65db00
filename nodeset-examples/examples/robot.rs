//! A simulated six-axis robot, served over OPC UA with the typed API and `#[derive(ObjectModel)]`.
//!
//! ```text
//! cargo run -p nodeset-examples --example robot -- [--port 4856] [--seconds N]
//! ```
//!
//! It instantiates a Robotics `MotionDeviceSystemType` named `Robot` under the Objects folder: one
//! MotionDevice `Arm` with six Axes `A1`..`A6` and their PowerTrains `PT1`..`PT6` (each with a Motor and a
//! Gear), a Controller and a SafetyState, every mandatory child as the types prescribe. The arm's DI
//! identification (Manufacturer, Model, ProductCode, SerialNumber, ...) comes from a struct bound with the
//! derive; its AssetId, user writable in DI, is writable by clients, and a client's write lands in that
//! struct and is printed (`AssetId written by a client: <value>`). The controller is bound to a second struct whose `default_stop_mode` field is the writable
//! `SystemOperation/SystemOperationStateMachine/ConfiguredDefaultStopMode`: a client's write lands in that
//! struct and is printed (`ConfiguredDefaultStopMode written by a client: <value>`). Joint positions
//! (`Axes/<axis>/ParameterSet/ActualPosition`) move along sine curves, updated at 100 Hz through the typed
//! handles. The arm's `Lock` object (DI LockingServicesType) is served by the runtime
//! (`ModelManager::serve_lock`): `InitLock(Context)` locks the arm for a client application (Locked,
//! LockingClient and LockingUser show who holds it), other applications' writes and calls below the arm get
//! BadLocked, `ExitLock` unlocks. The
//! controller's SystemOperationStateMachine is served as a state machine: it comes up Idle and takes
//! IdleToReady. Each gear has a `Lifetime` variable (DI LifetimeVariableType, an AnalogUnitType): its
//! remaining life in hours, counting down while the robot runs, from StartValue 20000 h to LimitValue 0 h.
//! Every other variable a client may browse has a value too (`describe`): nameplates of motors,
//! gears and software, gear ratios, engineering units, motion profiles, the safety state and the task.
//!
//! The first line on stdout is `listening on <url>`; the server stops on SIGINT, SIGTERM or after
//! `--seconds N`, printing `server stopped cleanly`.

use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use nodeset_models::models::robotics::objects::MotionDeviceSystemType;
use nodeset_models::models::robotics::types::MotionDeviceCategoryEnumeration;
use nodeset_models::models::{di, ia, robotics};
use nodeset_examples::describe::{describe, units, HOUR};
use nodeset_examples::secure::{SecureArgs, USAGE};
use nodeset_models::runtime::server::{ModelManager, ServerConfig};
use nodeset_models::runtime::typed::{Bound, Instantiate, Machine, ObjectType, Variable, VariableType};
use nodeset_models::ObjectModel;
use opcua::nodes::NodeType;
use opcua::server::address_space::AccessLevel;
use opcua::types::{Identifier, LocalizedText, NodeId, ObjectId, QualifiedName, Variant};

/// The arm's identification, bound to the Robotics MotionDeviceType (and the DI members it inherits).
#[derive(Clone, Debug, ObjectModel)]
#[opcua(object_type = robotics::objects::MotionDeviceType)]
struct ArmIdentity {
    manufacturer: LocalizedText,
    model: LocalizedText,
    product_code: String,
    serial_number: String,
    motion_device_category: MotionDeviceCategoryEnumeration,
    /// Writable by clients: DI's AssetId is user writable, and `run` grants CurrentWrite to the instance.
    asset_id: String,
    #[opcua(path = "ParameterSet/SpeedOverride")]
    speed_override: f64,
    #[opcua(skip)]
    writes_seen: u32,
}

/// The controller's identification and its one client-writable setting.
#[derive(Clone, Debug, ObjectModel)]
#[opcua(object_type = robotics::objects::ControllerType)]
struct ControllerSettings {
    manufacturer: LocalizedText,
    model: LocalizedText,
    product_code: String,
    serial_number: String,
    #[opcua(path = "CurrentUser/Level")]
    user_level: String,
    /// Writable by clients (AccessLevel CurrentRead | CurrentWrite in Robotics).
    #[opcua(path = "SystemOperation/SystemOperationStateMachine/ConfiguredDefaultStopMode")]
    default_stop_mode: i16,
}

/// The axes and their simulated motion.
const AXES: [&str; 6] = ["A1", "A2", "A3", "A4", "A5", "A6"];

fn options() -> Result<(u16, Option<u64>, SecureArgs), String> {
    let (mut port, mut seconds, mut secure) = (4856, None, SecureArgs::default());
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if secure.take(&arg, &mut args)? {
            continue;
        }
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--port" => port = value("--port")?.parse().map_err(|e| format!("--port: {e}"))?,
            "--seconds" => seconds = Some(value("--seconds")?.parse().map_err(|e| format!("--seconds: {e}"))?),
            other => return Err(format!("unknown argument {other:?} (usage: robot [--port 4856] [--seconds N] {USAGE})")),
        }
    }
    Ok((port, seconds, secure))
}

/// What `Instantiate` needs for the robot: the names of every placeholder instance.
fn robot_options() -> Instantiate {
    let mut o = Instantiate::new()
        .placeholder("MotionDevices/<MotionDeviceIdentifier>", ["Arm"])
        .placeholder("MotionDevices/Arm/Axes/<AxisIdentifier>", AXES)
        .placeholder("MotionDevices/Arm/PowerTrains/<PowerTrainIdentifier>", AXES.map(|a| format!("PT{}", &a[1..])))
        .placeholder("Controllers/<ControllerIdentifier>", ["Controller"])
        .placeholder("SafetyStates/<SafetyStateIdentifier>", ["SafetyState"])
        .placeholder("Controllers/Controller/TaskControls/<TaskControlIdentifier>", ["Task"])
        .placeholder("Controllers/Controller/Software/<SoftwareIdentifier>", ["Software"])
        .optional("MotionDevices/Arm/Lock")
        .optional("MotionDevices/Arm/AssetId")
        .optional("Controllers/Controller/SystemOperation")
        .optional("Controllers/Controller/SystemOperation/SystemOperationStateMachine/ConfiguredDefaultStopMode");
    for a in AXES {
        let pt = format!("MotionDevices/Arm/PowerTrains/PT{}", &a[1..]);
        o = o.placeholder(format!("{pt}/<MotorIdentifier>"), ["Motor"]).placeholder(format!("{pt}/<GearIdentifier>"), ["Gear"]);
    }
    o
}

async fn run(port: u16, seconds: Option<u64>, secure: SecureArgs) -> Result<(), String> {
    let config = ServerConfig::new("Six-axis robot");
    let server = secure
        .apply(config, "robot")?
        .port(port)
        .table(&di::TABLE)
        .type_loader(di::TypeLoader)
        .table(&ia::TABLE)
        .type_loader(ia::TypeLoader)
        .table(&robotics::TABLE)
        .type_loader(robotics::TypeLoader)
        .build()?;
    let manager = server.manager().clone();
    let objects: NodeId = ObjectId::ObjectsFolder.into();
    let robot = MotionDeviceSystemType::instantiate(&manager, &objects, "Robot", &robot_options()).map_err(|e| e.to_string())?;
    let arm = robot.motion_devices.motion_device_identifier.get("Arm").ok_or("the robot has no arm")?.clone();
    // DI (OPC 10000-100, 4.5.3) makes AssetId "user writable"; the nodesets declare it with the default
    // AccessLevel (CurrentRead only), which the instance copies, so the server grants the write here.
    let asset_id = arm.asset_id.as_ref().ok_or("the arm has no AssetId")?;
    match manager.node_manager().address_space().write().find_mut(asset_id.id()) {
        Some(NodeType::Variable(v)) => {
            v.set_access_level(AccessLevel::CURRENT_READ | AccessLevel::CURRENT_WRITE);
            v.set_user_access_level(AccessLevel::CURRENT_READ | AccessLevel::CURRENT_WRITE);
        }
        _ => return Err("the arm's AssetId is not a variable".into()),
    }

    let identity = ArmIdentity {
        manufacturer: LocalizedText::new("en", "nodeset-compiler robotics"),
        model: LocalizedText::new("en", "SIX-1"),
        product_code: "SIX-1-850".into(),
        serial_number: "0001".into(),
        motion_device_category: MotionDeviceCategoryEnumeration::ArticulatedRobot,
        asset_id: "cell-1/robot".into(),
        speed_override: 1.0,
        writes_seen: 0,
    };
    let identity = Arc::new(Bound::bind(&manager, arm.node.id(), identity).map_err(|e| e.to_string())?);
    let controller = robot.controllers.controller_identifier.get("Controller").ok_or("the robot has no controller")?;
    let settings = ControllerSettings {
        manufacturer: LocalizedText::new("en", "nodeset-compiler robotics"),
        model: LocalizedText::new("en", "SIX-C"),
        product_code: "SIX-C-1".into(),
        serial_number: "C-0001".into(),
        user_level: "operator".into(),
        default_stop_mode: 0,
    };
    let settings = Bound::bind(&manager, controller.node.id(), settings).map_err(|e| e.to_string())?;

    describe(&manager, &robot)?;
    // The controller comes up Idle and makes itself Ready (a transition the system takes by itself).
    let operation = controller.system_operation.as_ref().ok_or("the controller has no SystemOperation")?;
    let machine = &operation.system_operation_state_machine;
    let system = Machine::serve_from(machine.as_ref(), "Idle").map_err(|e| e.to_string())?;
    machine.last_transition_reason.set(LAST_TRANSITION_REASON_SYSTEM).map_err(|s| s.to_string())?;
    system.transition("Ready").map_err(|s| s.to_string())?;

    // The arm's Lock: DI's locking, as the runtime serves it for any Lock object.
    if let Some(lock) = &arm.lock {
        manager.serve_lock(lock.node.id())?;
    }

    let lifetimes = gear_lifetimes(&manager, &robot)?;
    let axes: Vec<_> = arm.axes.axis_identifier.values().map(|a| a.parameter_set.actual_position.clone()).collect();
    // Joint motion at 100 Hz, beside the server.
    let started = Instant::now();
    let mut tick = tokio::time::interval(Duration::from_millis(10));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let mut last_asset = identity.read(|i| i.asset_id.clone());
    let mut last_stop_mode = settings.read(|s| s.default_stop_mode);
    let motion = async {
        loop {
            tick.tick().await;
            let t = started.elapsed().as_secs_f64();
            for (i, position) in axes.iter().enumerate() {
                let amplitude = 90.0 - 10.0 * i as f64;
                let _ = position.set(amplitude * (t * (0.2 + 0.05 * i as f64)).sin());
            }
            for (i, lifetime) in lifetimes.iter().enumerate() {
                let _ = lifetime.set(Variant::Double(remaining_hours(i, t)));
            }
            let asset = identity.read(|i| i.asset_id.clone());
            if asset != last_asset {
                identity.update(|i| i.writes_seen += 1);
                println!("AssetId written by a client: {asset:?}");
                let _ = std::io::stdout().flush();
                last_asset = asset;
            }
            let stop_mode = settings.read(|s| s.default_stop_mode);
            if stop_mode != last_stop_mode {
                println!("ConfiguredDefaultStopMode written by a client: {stop_mode}");
                let _ = std::io::stdout().flush();
                last_stop_mode = stop_mode;
            }
        }
    };
    server.run_until_stopped(seconds, motion).await
}

/// The gears' lifetime in hours (DI LifetimeVariableType's StartValue; its LimitValue is 0).
const GEAR_LIFETIME_HOURS: f64 = 20_000.0;

/// The remaining lifetime of gear `i` after `seconds` of running: each gear has seen some use before.
fn remaining_hours(i: usize, seconds: f64) -> f64 {
    GEAR_LIFETIME_HOURS - 1_000.0 * (i + 1) as f64 - seconds / 3_600.0
}

/// Gives each gear a `Lifetime` variable of DI's LifetimeVariableType (NodeId `<gear>/Lifetime`), with its
/// StartValue, LimitValue and EngineeringUnits (hours); the values of the variables, in gear order.
fn gear_lifetimes(manager: &ModelManager, robot: &MotionDeviceSystemType) -> Result<Vec<Variable<Variant>>, String> {
    let type_id = manager.resolve(di::objects::LifetimeVariableType::TYPE_ID).ok_or("the server has no DI namespace")?;
    let mut out = Vec::new();
    for device in robot.motion_devices.motion_device_identifier.values() {
        for pt in device.power_trains.power_train_identifier.values() {
            for gear in pt.gear_identifier.values() {
                let gear_id = gear.node.id();
                let Identifier::String(path) = &gear_id.identifier else { return Err(format!("gear {gear_id} has no path NodeId")) };
                let options = Instantiate::new().node_id(NodeId::new(gear_id.namespace, format!("{path}/Lifetime")));
                let name = QualifiedName::new(manager.instance_namespace(), "Lifetime");
                let id = manager.instantiate(&type_id, gear_id, name, &options).map_err(|e| e.to_string())?;
                let lifetime: di::objects::LifetimeVariableType = manager.bind(&id).map_err(|e| e.to_string())?;
                lifetime.start_value.set(Variant::Double(GEAR_LIFETIME_HOURS)).map_err(|s| s.to_string())?;
                lifetime.limit_value.set(Variant::Double(0.0)).map_err(|s| s.to_string())?;
                units(manager, &id, HOUR)?;
                lifetime.node.set(Variant::Double(remaining_hours(out.len(), 0.0))).map_err(|s| s.to_string())?;
                out.push(lifetime.node);
            }
        }
    }
    Ok(out)
}

/// Robotics' LastTransitionReason 3: "System", the system took the transition by itself.
const LAST_TRANSITION_REASON_SYSTEM: i16 = 3;

fn main() -> ExitCode {
    let filter = std::env::var("RUST_LOG").unwrap_or_else(|_| "warn,opcua_server=error,opcua_nodes=error,opcua_crypto=off,opcua_core=error,opcua_core::comms::secure_channel=off".into());
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
    let (port, seconds, secure) = match options() {
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
    match runtime.block_on(run(port, seconds, secure)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
