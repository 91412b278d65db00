//! The typed client (`runtime::client`) against the example servers, started as a user starts them (their
//! binaries, `--port 0`, secure by default) and reached over Basic256Sha256 SignAndEncrypt as an Operator:
//!
//! - the robot example (`examples/robot.rs`): its certificate refused on first contact and written to the
//!   client's `rejected/`, then trusted; binding by browse path and by NodeId (a handle of another type
//!   refused); placeholders by browsing; one member of six axes in one Read, a selection, Optional members
//!   present and absent; writes refused and accepted; a subscription stream of the moving joints; typed
//!   method calls through the generated marker `Lock__InitLock` (a wrong argument refused with the server's
//!   status; per-argument statuses through a hand-written marker of the wrong type); the controller's
//!   SystemOperationStateMachine through its generated state table;
//! - the robot cell (`examples/robot_cell.rs`): the robot's AbsoluteJointPTPMove run with typed inputs and
//!   awaited to Ready while the joints are subscribed, a run with refused inputs ending in Halted with its
//!   cause, a Halt while it runs observed by the run and by `wait_for_state`; the cell's composite DrillHole
//!   (which runs the robot's and the drilling unit's skills) suspended, resumed and awaited to Ready.
//!
//! The example binaries are built by the test (`cargo build -p nodeset-examples --example ...`, a no-op
//! when they are up to date; `tests/common/example.rs`).

#[path = "common/example.rs"]
mod example;

use std::marker::PhantomData;
use std::path::{Path, PathBuf};
use std::time::Duration;

use example::PASSWORD;

use nodeset_models::models::common_skills::objects::{
    AbsoluteJointPtpMoveSkillType, AbsoluteJointPtpMoveSkillTypeInputs, ProgramSkillStateMachineTypeOutputs as Done,
};
use nodeset_models::models::drilling_process::objects::{DrillHoleSkillType, DrillHoleSkillTypeInputs};
use nodeset_models::models::robotics::objects::{
    members, AxisType, ControllerType, MotionDeviceSystemType, MotionDeviceType, SystemOperationStateMachineType,
};
use nodeset_models::runtime::client::{ClientConfig, ClientError, Remote, RemoteMachine};
use nodeset_models::runtime::remote::RemoteError;
use nodeset_models::runtime::server::security;
use nodeset_models::runtime::typed::{MethodMember, ObjectType};
use opcua::types::StatusCode;

fn path(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_robot_example_is_read_written_subscribed_and_called_through_typed_handles() {
    let (dir, users) = example::operator_files("client", "robot");
    let (server_pki, client_pki) = (dir.join("server-pki"), dir.join("client-pki"));
    // The server trusts the client's certificate on first use; the client trusts the server's only once it
    // has been moved from rejected/ to trusted/, as an administrator does (the first attempt fails at once
    // with BadCertificateUntrusted).
    let robot = tokio::task::spawn_blocking(move || {
        let robot = example::start("robot", &["--port", "0", "--pki", path(&server_pki), "--users", path(&users), "--trust-on-first-use"]);
        let url = robot.line("listening on ");
        (robot, url)
    });
    let (robot, url) = robot.await.unwrap();
    let config = ClientConfig::new(&client_pki).user("op", PASSWORD);
    match config.connect(&url).await {
        Err(RemoteError::Connect(_, status)) => assert_eq!(status, StatusCode::BadCertificateUntrusted),
        Err(other) => panic!("an untrusted server certificate was refused with {other}"),
        Ok(_) => panic!("a session to a server whose certificate is not trusted"),
    }
    let rejected: Vec<PathBuf> =
        std::fs::read_dir(client_pki.join("rejected")).expect("rejected/").map(|e| e.unwrap().path()).collect();
    assert_eq!(rejected.len(), 1, "the server's certificate lands in rejected/: {rejected:?}");
    std::fs::rename(&rejected[0], client_pki.join("trusted").join(rejected[0].file_name().unwrap())).unwrap();
    let client = config.connect(&url).await.expect("a session once the server's certificate is trusted");
    // A wrong password is refused, with the server's status (not a timeout).
    match ClientConfig::new(&client_pki).user("op", "not-the-password").connect(&url).await {
        Err(RemoteError::Connect(_, status)) => assert_eq!(status, StatusCode::BadIdentityTokenRejected),
        Err(other) => panic!("a wrong password was refused with {other}"),
        Ok(_) => panic!("a session with a wrong password"),
    }

    // By browse path and by NodeId; a handle of another type is refused.
    let system: Remote<MotionDeviceSystemType> = client.bind_path("Robot").await.unwrap();
    let by_id: Remote<MotionDeviceSystemType> = client.bind(system.node()).await.unwrap();
    assert_eq!(system.node(), by_id.node());
    match client.bind_path::<AxisType>("Robot").await {
        Err(ClientError::WrongType { expected, .. }) => assert_eq!(expected, AxisType::BROWSE_NAME),
        other => panic!("a MotionDeviceSystem bound as an AxisType: {other:?}"),
    }

    // Paths in a bounded number of requests. The robot serves 6 namespaces; a segment without its namespace
    // is tried in each, with every prefix, so a request of at most 100 browse paths takes two segments
    // (6 + 36 = 42; three would be 42 + 216): five segments are three TranslateBrowsePathsToNodeIds, where
    // a Browse a segment was five round trips. The same path with its segments qualified is one request.
    let namespaces = client.session().encoding_context().read().namespaces().known_namespaces().len();
    assert_eq!(namespaces, 6, "the robot's NamespaceArray");
    let machine_path = "Robot/Controllers/Controller/SystemOperation/SystemOperationStateMachine";
    let found = client.find_counted(machine_path).await.unwrap();
    assert_eq!(found.requests, 3, "{found:?}");
    let qualified = client.find_counted(&found.path).await.unwrap();
    assert_eq!((&qualified.node, qualified.requests), (&found.node, 1), "{qualified:?}");
    assert!(found.path.starts_with('{') && found.path.matches('{').count() == 5, "{}", found.path);
    // A path that stops says where.
    match client.find_counted("Robot/Controllers/NoSuchController/SystemOperation").await {
        Err(RemoteError::Path { below, segment, matches: 0 }) => assert_eq!((below.as_str(), segment.as_str()), ("Robot/Controllers", "NoSuchController")),
        other => panic!("a path through a controller the robot lacks: {other:?}"),
    }

    // Placeholders, by browsing.
    let devices = system.placeholders::<MotionDeviceType>("MotionDevices").await.unwrap();
    assert_eq!(devices.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["Arm"]);
    let arm = &devices[0].1;
    let axes = arm.placeholders::<AxisType>("Axes").await.unwrap();
    assert_eq!(axes.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["A1", "A2", "A3", "A4", "A5", "A6"]);
    assert!(system.placeholders::<AxisType>("MotionDevices").await.unwrap().is_empty(), "an arm is not an axis");
    let axes: Vec<Remote<AxisType>> = axes.into_iter().map(|(_, a)| a).collect();

    // Typed reads: one member, the same member of every axis in one Read, a selection.
    let serial = arm.read::<String, _>(&members::MotionDeviceType::SerialNumber).await.unwrap();
    assert_eq!(serial.value.as_deref(), Some("0001"));
    assert!(serial.status.is_good());
    let position = &members::AxisType::ParameterSet__ActualPosition;
    let all = Remote::read_each::<f64, _>(&axes, position).await.unwrap();
    assert_eq!(all.len(), 6);
    assert!(all.iter().all(|s| s.value.is_some() && s.status.is_good() && s.source_timestamp.is_some()), "{all:?}");
    let selection = arm
        .read_selection(&[
            members::MotionDeviceType::SerialNumber.browse_path(),
            members::MotionDeviceType::Lock__Locked.browse_path(),
            members::MotionDeviceType::FlangeLoad__Mass.browse_path(),
        ])
        .await
        .unwrap();
    assert!(selection[0].is_ok() && selection[1].is_ok(), "{selection:?}");
    assert!(selection[2].is_err(), "the arm has no FlangeLoad: {:?}", selection[2]);

    // Optional members: present (AssetId) and absent (FlangeLoad/Mass).
    let asset = arm.read_optional::<String, _>(&members::MotionDeviceType::AssetId).await.unwrap();
    assert_eq!(asset.and_then(|s| s.value).as_deref(), Some("cell-1/robot"));
    assert_eq!(arm.read_optional::<f64, _>(&members::MotionDeviceType::FlangeLoad__Mass).await.unwrap(), None);

    // Writes: a read-only variable is refused with the server's status; a writable one lands in the
    // server's struct (which prints it).
    match arm.write(&members::MotionDeviceType::ParameterSet__SpeedOverride, 0.5).await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadNotWritable),
        other => panic!("a read-only variable was written: {other:?}"),
    }
    arm.write(&members::MotionDeviceType::AssetId, "cell-2/robot".to_owned()).await.unwrap();
    let controllers = system.placeholders::<ControllerType>("Controllers").await.unwrap();
    let controller = &controllers[0].1;
    let stop_mode = &members::ControllerType::SystemOperation__SystemOperationStateMachine__ConfiguredDefaultStopMode;
    controller.write(stop_mode, 2i16).await.unwrap();
    assert_eq!(controller.read::<i16, _>(stop_mode).await.unwrap().value, Some(2));
    let robot = tokio::task::spawn_blocking(move || {
        assert_eq!(robot.line("AssetId written by a client: "), "\"cell-2/robot\"");
        assert_eq!(robot.line("ConfiguredDefaultStopMode written by a client: "), "2");
        robot
    })
    .await
    .unwrap();

    // A subscription: the joint moves (a sine at 100 Hz), and its values arrive typed, each with its status
    // and a later source timestamp than the one before.
    let mut samples = axes[0].subscribe::<f64, _>(position, 20).await.unwrap();
    let mut seen = Vec::new();
    while seen.len() < 6 {
        let s = tokio::time::timeout(Duration::from_secs(5), samples.next()).await.expect("a sample in time").expect("a sample");
        assert!(s.status.is_good(), "{s:?}");
        seen.push((s.value.expect("an f64"), s.source_timestamp.expect("a source timestamp")));
    }
    assert!(seen.windows(2).all(|w| w[0].1 < w[1].1), "source timestamps go forward: {seen:?}");
    assert!(seen.windows(2).all(|w| w[0].0 != w[1].0), "every sample is a changed value: {seen:?}");
    drop(samples);

    // Typed method calls through the generated marker, whose type gives the arguments' and outputs' types: a
    // wrong argument is refused with the server's status, the right one runs.
    let init_lock = &members::MotionDeviceType::Lock__InitLock;
    match arm.call(init_lock, (String::new(),)).await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadInvalidArgument),
        other => panic!("an empty context was accepted: {other:?}"),
    }
    let (first,): (i32,) = arm.call(init_lock, ("cell".to_owned(),)).await.unwrap();
    assert_eq!(first, 0, "InitLock's InitLockStatus: 0 is the lock taken");
    assert_eq!(arm.call(init_lock, ("other".to_owned(),)).await.unwrap(), (-1,), "a second lock is refused in its output");
    assert_eq!(arm.read::<bool, _>(&members::MotionDeviceType::Lock__Locked).await.unwrap().value, Some(true));
    // A hand-written marker that gets the input type wrong (an Int32 context; the generated one does not
    // compile with it): the server refuses the argument, and its status per argument comes back.
    let int_context: MethodMember<(i32,), (i32,)> =
        MethodMember { ns: init_lock.ns, path: init_lock.path, mandatory: false, signature: PhantomData };
    match arm.call(&int_context, (7,)).await {
        Err(ClientError::Arguments { status, arguments, .. }) => {
            assert_eq!(status, StatusCode::BadInvalidArgument);
            assert_eq!(arguments, [StatusCode::BadTypeMismatch]);
        }
        other => panic!("an Int32 context was accepted: {other:?}"),
    }
    // Outputs of another type than the marker says (a hand-written marker of ExitLock without its Int32
    // output): the call runs (the lock is released), and the outputs are a typed error, not a panic.
    let exit_lock: MethodMember<(), ()> = MethodMember { ns: init_lock.ns, path: "0:Lock/0:ExitLock", mandatory: false, signature: PhantomData };
    match arm.call(&exit_lock, ()).await {
        Err(ClientError::Type { what, .. }) => assert!(what.contains("ExitLock"), "{what}"),
        other => panic!("ExitLock's Int32 output read as no outputs: {other:?}"),
    }
    assert_eq!(arm.read::<bool, _>(&members::MotionDeviceType::Lock__Locked).await.unwrap().value, Some(false));
    // A method the instance lacks: the translation finds nothing, and no Call is made.
    let absent: MethodMember<(), ()> = MethodMember { ns: init_lock.ns, path: "0:NoSuchMethod", mandatory: false, signature: PhantomData };
    match arm.call(&absent, ()).await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadNoMatch),
        other => panic!("a method the arm lacks was called: {other:?}"),
    }

    // A state machine through its generated table: the controller's SystemOperationStateMachine is Ready.
    let machine: Remote<SystemOperationStateMachineType> =
        client.bind_path("Robot/Controllers/Controller/SystemOperation/SystemOperationStateMachine").await.unwrap();
    let machine = RemoteMachine::of(machine).await.unwrap();
    assert_eq!(machine.current().map(|s| s.name), Some("Ready"));
    assert_eq!(machine.state().await.unwrap().map(|s| s.name), Some("Ready"));
    machine.wait_for_state("Ready", Duration::from_secs(1)).await.unwrap();
    match machine.wait_for_state("Idle", Duration::from_millis(300)).await {
        Err(ClientError::Timeout(_)) => {}
        other => panic!("the machine is Ready, not Idle: {other:?}"),
    }
    drop(machine);

    client.disconnect().await;
    drop(robot);
    let _ = std::fs::remove_dir_all(&dir);
}

const SYSTEM: &str = "DeviceSet/TemplateDrillingLwrSystem/MotionDeviceSystem";
const PTP: &str = "Controllers/URController/SkillSet/AbsoluteJointPTPMove";
const JOINTS: [&str; 6] = ["Base", "Shoulder", "Elbow", "Wrist1", "Wrist2", "Wrist3"];

fn ptp(target: [f64; 6], speed: f64) -> AbsoluteJointPtpMoveSkillTypeInputs {
    AbsoluteJointPtpMoveSkillTypeInputs { speed, acceleration: 180.0, target_joint_positions: target.to_vec() }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn skills_of_the_robot_cell_run_to_ready_and_are_halted() {
    let (dir, users) = example::operator_files("client", "robot-cell");
    let (server_pki, client_pki) = (dir.join("server-pki"), dir.join("client-pki"));
    let pki = server_pki.clone();
    let cell = tokio::task::spawn_blocking(move || {
        let cell = example::start(
            "robot_cell",
            &["--port", "0", "--pki", path(&pki), "--users", path(&users), "--trust-on-first-use", "--motion-ms", "1000"],
        );
        let robot_url = cell.line("robot listening on ");
        let cell_url = cell.line("cell listening on ");
        cell.line("cell ready");
        (cell, robot_url, cell_url)
    });
    let (cell, robot_url, cell_url) = cell.await.unwrap();
    // The client trusts the robot's and the cell's certificates, as an administrator would.
    let config = ClientConfig::new(&client_pki).user("op", PASSWORD);
    security::prepare_pki(&client_pki, &config.application_name, &config.application_uri, &[]).unwrap();
    for server in ["robot", "cell"] {
        let own = security::own_certificate(&server_pki.join(server)).unwrap();
        security::trust_certificate(&client_pki, &own).unwrap();
    }
    let robot = config.connect(&robot_url).await.expect("a session to the robot");

    let skill = robot.program::<AbsoluteJointPtpMoveSkillType>(&format!("{SYSTEM}/{PTP}")).await.unwrap();
    assert_eq!(skill.current().map(|s| s.name), Some("Ready"));
    let manipulator: Remote<MotionDeviceType> = robot.bind_path(&format!("{SYSTEM}/MotionDevices/Manipulator")).await.unwrap();
    // Placeholders come in BrowseName order; the skill's TargetJointPositions go from the base to the flange.
    let found = manipulator.placeholders::<AxisType>("Axes").await.unwrap();
    assert_eq!(found.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["Base", "Elbow", "Shoulder", "Wrist1", "Wrist2", "Wrist3"]);
    let axes: Vec<Remote<AxisType>> =
        JOINTS.iter().map(|j| found.iter().find(|(n, _)| n == j).expect("the joint").1.clone()).collect();
    let position = &members::AxisType::ParameterSet__ActualPosition;

    // A run with typed inputs, awaited to Ready, while a subscription sees the first joint move.
    let target = [10.0, -45.0, 60.0, -15.0, 90.0, 0.0];
    let mut samples = axes[0].subscribe::<f64, _>(position, 0).await.unwrap();
    let _: Done = tokio::time::timeout(Duration::from_secs(20), skill.run(ptp(target, 90.0))).await.expect("the run ends").unwrap();
    assert_eq!(skill.state().await.unwrap().map(|s| s.name), Some("Ready"));
    let reached = Remote::read_each::<f64, _>(&axes, position).await.unwrap();
    assert_eq!(reached.iter().map(|s| s.value).collect::<Vec<_>>(), target.map(Some));
    let mut moved = Vec::new();
    while moved.last() != Some(&target[0]) {
        let s = tokio::time::timeout(Duration::from_secs(5), samples.next()).await.expect("the joint's last value").unwrap();
        moved.push(s.value.expect("an f64"));
    }
    assert!(moved.len() > 2, "the joint's way to its target, sampled: {moved:?}");
    drop(samples);

    // A run whose inputs the skill refuses ends in Halted with the skill's status as the cause.
    match tokio::time::timeout(Duration::from_secs(20), skill.run(ptp(target, 0.0))).await.expect("the run ends") {
        Err(ClientError::Halted { cause, .. }) => assert_eq!(cause, StatusCode::BadInvalidArgument),
        other => panic!("a refused run did not halt: {other:?}"),
    }
    skill.reset().await.unwrap();
    skill.wait_for_state("Ready", Duration::from_secs(5)).await.unwrap();

    // The robot's skills have no Suspend (an Optional method of their type that the instances leave out):
    // the client says so before any call.
    match skill.suspend().await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadNoMatch),
        other => panic!("Suspend of a skill without a Suspend method: {other:?}"),
    }
    // A Halt while it runs, observed by the run (Halted, with the cause the skill gives) and by
    // wait_for_state.
    let control = async {
        skill.wait_for_state("Running", Duration::from_secs(5)).await.unwrap();
        skill.halt().await.unwrap();
        skill.wait_for_state("Halted", Duration::from_secs(5)).await.unwrap();
    };
    let home = [0.0; 6];
    let (run, ()) = tokio::time::timeout(Duration::from_secs(20), async { tokio::join!(skill.run(ptp(home, 90.0)), control) })
        .await
        .expect("the halted run ends");
    match run {
        Err(ClientError::Halted { cause, .. }) => assert_eq!(cause, StatusCode::BadRequestCancelledByClient),
        other => panic!("a halted run: {other:?}"),
    }
    assert_eq!(skill.state().await.unwrap().map(|s| s.name), Some("Halted"));
    let stopped = Remote::read_each::<f64, _>(&axes, position).await.unwrap();
    // The joint stopped where the Halt found it, on its way from 10 towards 0 (a move takes a second).
    assert!(stopped[0].value.is_some_and(|v| v > 0.0 && v <= target[0]), "halted on the way home: {stopped:?}");
    skill.reset().await.unwrap();
    skill.wait_for_state("Ready", Duration::from_secs(5)).await.unwrap();
    drop(skill);

    // The cell's composite skill, which runs the robot's and the drilling unit's skills: suspended and
    // resumed while it runs (a second Suspend is refused by the table's rules), then awaited to Ready.
    let cell_client = config.connect(&cell_url).await.expect("a session to the cell");
    let drill_hole = cell_client.program::<DrillHoleSkillType>("DrillingCell/SkillSet/DrillHole").await.unwrap();
    let inputs = DrillHoleSkillTypeInputs {
        insertion_distance: 12.0,
        hole_diameter: 4.8,
        depth: 6.0,
        feed_rate: 200.0,
        spindle_speed: 6000.0,
        clamp_force: 300.0,
    };
    let control = async {
        drill_hole.wait_for_state("Running", Duration::from_secs(5)).await.unwrap();
        drill_hole.suspend().await.unwrap();
        drill_hole.wait_for_state("Suspended", Duration::from_secs(5)).await.unwrap();
        match drill_hole.suspend().await {
            Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadInvalidState),
            other => panic!("Suspend in Suspended was accepted: {other:?}"),
        }
        drill_hole.resume().await.unwrap();
        drill_hole.wait_for_state("Running", Duration::from_secs(5)).await.unwrap();
    };
    let (run, ()) = tokio::time::timeout(Duration::from_secs(30), async { tokio::join!(drill_hole.run(inputs), control) })
        .await
        .expect("DrillHole ends");
    let _: Done = run.unwrap();
    assert_eq!(drill_hole.state().await.unwrap().map(|s| s.name), Some("Ready"));
    drop(drill_hole);

    cell_client.disconnect().await;
    robot.disconnect().await;
    drop(cell);
    let _ = std::fs::remove_dir_all(&dir);
}
