//! The typed client (`runtime::client`) against a robot (a Robotics MotionDeviceSystem with a lockable arm,
//! as the robot example builds it) and against the robot of the robot cell (its skills): binding by browse
//! path and by NodeId, placeholders, batched and optional reads, writes refused and accepted, a
//! subscription stream, typed method calls (one refused for a wrong argument), and skills run to Ready and
//! halted.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use common::serve;
use nodeset_models::models::common_skills::objects::{
    ProgramSkillStateMachineTypeOutputs as Done, RelativeCartesianLinearMoveSkillType,
    RelativeCartesianLinearMoveSkillTypeInputs,
};
use nodeset_models::models::robotics::objects::{members, AxisType, ControllerType, MotionDeviceSystemType, MotionDeviceType};
use nodeset_models::models;
use nodeset_models::runtime::client::{ClientConfig, ClientError, Remote, RemoteProgram};
use nodeset_models::runtime::server::{MethodError, ServerConfig};
use nodeset_models::runtime::typed::{Instantiate, ObjectType, Program, ProgramState};
use opcua::types::{NodeId, ObjectId, StatusCode, ThreeDCartesianCoordinates, ThreeDFrame, ThreeDOrientation};

const AXES: [&str; 3] = ["A1", "A2", "A3"];

/// A robot like the robot example's: an arm with three axes and a Lock whose InitLock refuses an empty
/// context.
async fn robot() -> (common::Running, MotionDeviceSystemType) {
    let server = serve(models::register(ServerConfig::new("robot").min_publishing_interval_ms(10))).await;
    let options = Instantiate::new()
        .placeholder("MotionDevices/<MotionDeviceIdentifier>", ["Arm"])
        .placeholder("MotionDevices/Arm/Axes/<AxisIdentifier>", AXES)
        .placeholder("MotionDevices/Arm/PowerTrains/<PowerTrainIdentifier>", ["PT1"])
        .placeholder("MotionDevices/Arm/PowerTrains/PT1/<MotorIdentifier>", ["Motor"])
        .placeholder("MotionDevices/Arm/PowerTrains/PT1/<GearIdentifier>", ["Gear"])
        .placeholder("Controllers/<ControllerIdentifier>", ["Controller"])
        .placeholder("SafetyStates/<SafetyStateIdentifier>", ["SafetyState"])
        .placeholder("Controllers/Controller/TaskControls/<TaskControlIdentifier>", ["Task"])
        .placeholder("Controllers/Controller/Software/<SoftwareIdentifier>", ["Software"])
        .optional("MotionDevices/Arm/Lock")
        .optional("Controllers/Controller/SystemOperation")
        .optional("Controllers/Controller/SystemOperation/SystemOperationStateMachine/ConfiguredDefaultStopMode");
    let objects: NodeId = ObjectId::ObjectsFolder.into();
    let robot = MotionDeviceSystemType::instantiate(&server.manager, &objects, "Robot", &options).expect("the robot");
    let arm = robot.motion_devices.motion_device_identifier.get("Arm").expect("an arm");
    let lock = arm.lock.as_ref().expect("the arm has a Lock");
    let held = Arc::new(Mutex::new(None::<String>));
    lock.init_lock.implement(move |_, (context,): (String,)| {
        let held = held.clone();
        async move {
            if context.is_empty() {
                return Err(MethodError::Status(StatusCode::BadInvalidArgument));
            }
            let mut h = held.lock().unwrap();
            Ok((if h.is_some() { -1 } else { *h = Some(context); 0 },))
        }
    });
    for (i, axis) in arm.axes.axis_identifier.values().enumerate() {
        axis.parameter_set.actual_position.set(10.0 * (i + 1) as f64).unwrap();
    }
    (server, robot)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_robot_is_read_written_subscribed_and_called_through_typed_handles() {
    let (server, local) = robot().await;
    let client = ClientConfig::new(&server.url).connect().await.expect("a session");

    // By browse path and by NodeId; a handle of another type is refused.
    let robot: Remote<MotionDeviceSystemType> = client.bind_path("Robot").await.unwrap();
    let by_id: Remote<MotionDeviceSystemType> = client.bind(local.node.id()).await.unwrap();
    assert_eq!(robot.node(), by_id.node());
    match client.bind_path::<AxisType>("Robot").await {
        Err(ClientError::WrongType { expected, .. }) => assert_eq!(expected, AxisType::BROWSE_NAME),
        other => panic!("a MotionDeviceSystem bound as an AxisType: {other:?}"),
    }

    // Placeholders, by browsing.
    let devices = robot.placeholders::<MotionDeviceType>("MotionDevices").await.unwrap();
    assert_eq!(devices.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["Arm"]);
    let arm = &devices[0].1;
    let axes = arm.placeholders::<AxisType>("Axes").await.unwrap();
    assert_eq!(axes.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), AXES);
    assert!(robot.placeholders::<AxisType>("MotionDevices").await.unwrap().is_empty(), "an arm is not an axis");

    // Typed reads: one member, the same member of every axis in one Read, a selection.
    let axes: Vec<Remote<AxisType>> = axes.into_iter().map(|(_, a)| a).collect();
    let first = axes[0].read::<f64, _>(&members::AxisType::ParameterSet__ActualPosition).await.unwrap();
    assert_eq!(first.value, Some(10.0));
    assert!(first.status.is_good() && first.source_timestamp.is_some());
    let all = Remote::read_each::<f64, _>(&axes, &members::AxisType::ParameterSet__ActualPosition).await.unwrap();
    assert_eq!(all.iter().map(|s| s.value).collect::<Vec<_>>(), [Some(10.0), Some(20.0), Some(30.0)]);
    let selection = arm
        .read_selection(&[
            members::MotionDeviceType::SerialNumber.browse_path(),
            members::MotionDeviceType::Lock__Locked.browse_path(),
            members::MotionDeviceType::AssetId.browse_path(),
        ])
        .await
        .unwrap();
    assert!(selection[0].is_ok() && selection[1].is_ok());
    assert!(selection[2].is_err(), "the arm has no AssetId: {:?}", selection[2]);

    // Optional members: present (Lock) and absent (AssetId).
    let locked = arm.read_optional::<bool, _>(&members::MotionDeviceType::Lock__Locked).await.unwrap();
    assert!(locked.is_some());
    assert_eq!(arm.read_optional::<String, _>(&members::MotionDeviceType::AssetId).await.unwrap(), None);

    // Writes: a read-only variable is refused with the server's status; a writable one is written.
    match arm.write(&members::MotionDeviceType::ParameterSet__SpeedOverride, 0.5).await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadNotWritable),
        other => panic!("a read-only variable was written: {other:?}"),
    }
    let controllers = robot.placeholders::<ControllerType>("Controllers").await.unwrap();
    let controller = &controllers[0].1;
    let stop_mode = &members::ControllerType::SystemOperation__SystemOperationStateMachine__ConfiguredDefaultStopMode;
    controller.write(stop_mode, 2i16).await.unwrap();
    assert_eq!(controller.read::<i16, _>(stop_mode).await.unwrap().value, Some(2));

    // A subscription: the values the server sets arrive, typed, with status and timestamps.
    let mut samples = axes[1].subscribe::<f64, _>(&members::AxisType::ParameterSet__ActualPosition, 0).await.unwrap();
    let initial = tokio::time::timeout(Duration::from_secs(5), samples.next()).await.unwrap().unwrap();
    assert_eq!(initial.value, Some(20.0));
    let a2 = &local.motion_devices.motion_device_identifier.get("Arm").unwrap().axes.axis_identifier.get("A2").unwrap().parameter_set.actual_position;
    for v in [21.0, 22.0, 23.0] {
        a2.set(v).unwrap();
        let s = tokio::time::timeout(Duration::from_secs(5), samples.next()).await.expect("a sample in time").unwrap();
        assert_eq!(s.value, Some(v));
        assert!(s.status.is_good() && s.source_timestamp.is_some() && s.server_timestamp.is_some());
    }

    // Typed method calls: a wrong argument is refused with the server's status, the right one runs.
    match arm.call::<(String,), (i32,)>("Lock/InitLock", (String::new(),)).await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadInvalidArgument),
        other => panic!("an empty context was accepted: {other:?}"),
    }
    match arm.call::<(i32,), (i32,)>("Lock/InitLock", (7,)).await {
        Err(ClientError::Arguments { status, arguments, .. }) => {
            assert_eq!(status, StatusCode::BadInvalidArgument);
            assert_eq!(arguments, [StatusCode::BadTypeMismatch]);
        }
        other => panic!("an Int32 context was accepted: {other:?}"),
    }
    assert_eq!(arm.call::<(String,), (i32,)>("Lock/InitLock", ("cell".to_owned(),)).await.unwrap(), (0,));
    assert_eq!(arm.call::<(String,), (i32,)>("Lock/InitLock", ("other".to_owned(),)).await.unwrap(), (-1,));

    drop(samples);
    client.disconnect().await;
    server.stop().await;
}

const MOVE: &str = "DeviceSet/TemplateDrillingLwrSystem/MotionDeviceSystem/Controllers/URController/SkillSet/RelativeCartesianLinearMove";

fn offset(z: f64) -> RelativeCartesianLinearMoveSkillTypeInputs {
    RelativeCartesianLinearMoveSkillTypeInputs {
        speed: if z == 0.0 { -1.0 } else { 50.0 },
        acceleration: 200.0,
        pose_offset: ThreeDFrame {
            cartesian_coordinates: ThreeDCartesianCoordinates { x: 0.0, y: 0.0, z },
            orientation: ThreeDOrientation { a: 0.0, b: 0.0, c: 0.0 },
        },
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_skill_of_the_robot_cell_runs_to_ready_and_is_halted() {
    let server = serve(models::register(ServerConfig::new("robot").min_publishing_interval_ms(10))).await;
    let skill: RelativeCartesianLinearMoveSkillType = server.manager.bind_path(MOVE).unwrap();
    let (hold, seen) = (Arc::new(AtomicBool::new(false)), Arc::new(Mutex::new(Vec::new())));
    let (h, s) = (hold.clone(), seen.clone());
    let program: Program = skill
        .serve(move |inputs: RelativeCartesianLinearMoveSkillTypeInputs, ctl| {
            let (hold, seen) = (h.clone(), s.clone());
            async move {
                if inputs.speed <= 0.0 {
                    return Err(StatusCode::BadInvalidArgument);
                }
                seen.lock().unwrap().push(inputs.pose_offset.cartesian_coordinates.z);
                let mut steps = 0;
                while steps < 5 || hold.load(Ordering::SeqCst) {
                    ctl.checkpoint().await;
                    tokio::time::sleep(Duration::from_millis(10)).await;
                    steps += 1;
                }
                Ok(Done {})
            }
        })
        .unwrap();

    let client = ClientConfig::new(&server.url).connect().await.unwrap();
    let remote: RemoteProgram<RelativeCartesianLinearMoveSkillType> = client.program(MOVE).await.unwrap();
    assert_eq!(remote.current().map(|s| s.name), Some("Ready"));

    // A run with typed inputs, awaited to Ready.
    let _: Done = tokio::time::timeout(Duration::from_secs(10), remote.run(offset(12.5))).await.unwrap().unwrap();
    assert_eq!(remote.state().await.unwrap().map(|s| s.name), Some("Ready"));
    assert_eq!(*seen.lock().unwrap(), [12.5]);

    // A run whose body refuses its inputs ends in Halted with the body's status as the cause.
    match tokio::time::timeout(Duration::from_secs(10), remote.run(offset(0.0))).await.unwrap() {
        Err(ClientError::Halted { cause, .. }) => assert_eq!(cause, StatusCode::BadInvalidArgument),
        other => panic!("a refused run did not halt: {other:?}"),
    }
    remote.reset().await.unwrap();
    remote.wait_for_state("Ready", Duration::from_secs(5)).await.unwrap();

    // Suspend and Resume where the table allows them; Halt while it runs is observed by the run and by
    // wait_for_state.
    hold.store(true, Ordering::SeqCst);
    let control = async {
        remote.wait_for_state("Running", Duration::from_secs(5)).await.unwrap();
        remote.suspend().await.unwrap();
        remote.wait_for_state("Suspended", Duration::from_secs(5)).await.unwrap();
        match remote.suspend().await {
            Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadInvalidState),
            other => panic!("Suspend in Suspended was accepted: {other:?}"),
        }
        remote.resume().await.unwrap();
        remote.wait_for_state("Running", Duration::from_secs(5)).await.unwrap();
        remote.halt().await.unwrap();
        remote.wait_for_state("Halted", Duration::from_secs(5)).await.unwrap();
    };
    let (run, ()) = tokio::time::timeout(Duration::from_secs(20), async { tokio::join!(remote.run(offset(3.0)), control) })
        .await
        .expect("the halted run ends");
    assert!(matches!(run, Err(ClientError::Halted { .. })), "{run:?}");
    assert_eq!(program.state(), ProgramState::Halted);

    drop(remote);
    client.disconnect().await;
    drop(program);
    server.stop().await;
}
