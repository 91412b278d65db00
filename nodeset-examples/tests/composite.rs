//! A composite skill running basic skills of other servers (Commands2's DrillHole), three servers on
//! loopback: the robot serves RelativeCartesianLinearMove, the drilling unit TemplateDrilling, the cell
//! DrillHole, whose body binds both by browse path as typed clients (`runtime::client::RemoteProgram`) and
//! runs move in, drill, move out (`run_step`, the composite semantics of `runtime::remote`). A client drives DrillHole; the composite follows its basic skills into Halted and Suspended, and
//! takes them along when it is suspended, resumed or halted itself.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use common::{connect, disconnect, serve, Running};
use nodeset_models::models::common_skills::objects::{
    ProgramSkillStateMachineTypeOutputs as Done, RelativeCartesianLinearMoveSkillType,
    RelativeCartesianLinearMoveSkillTypeInputs,
};
use nodeset_models::models::drilling_process::objects::{DrillHoleSkillType, DrillHoleSkillTypeInputs};
use nodeset_models::models::robot_cell::objects::{TemplateDrillingSkillType, TemplateDrillingSkillTypeInputs};
use nodeset_models::models::{self, drilling_process};
use nodeset_models::runtime::client::ClientError;
use nodeset_models::runtime::remote::{RemoteError, RemoteServer};
use nodeset_models::runtime::server::{ModelManager, ServerConfig};
use nodeset_models::runtime::typed::{Program, ProgramState};
use opcua::client::Session;
use opcua::types::{
    DataValue, NodeId, StatusCode, ThreeDCartesianCoordinates, ThreeDFrame, ThreeDOrientation, Variant, WriteValue,
};

const MOVE: &str = "DeviceSet/TemplateDrillingLwrSystem/MotionDeviceSystem/Controllers/URController/SkillSet/RelativeCartesianLinearMove";
const DRILL: &str = "DeviceSet/TemplateDrillingLwrSystem/DrillingEndEffector/SkillSet/TemplateDrilling";
const DRILL_HOLE: &str = "DrillingCell/SkillSet/DrillHole";

fn config(name: &str) -> ServerConfig {
    models::register(ServerConfig::new(name))
}

/// Binds the skill at `path` on a server (the server side looks it up in its own address space).
fn local<H: nodeset_models::runtime::typed::Handle>(m: &ModelManager, path: &str) -> H {
    m.bind_path(path).expect("the path leads to the skill")
}

fn offset(z: f64) -> RelativeCartesianLinearMoveSkillTypeInputs {
    RelativeCartesianLinearMoveSkillTypeInputs {
        speed: 50.0,
        acceleration: 200.0,
        pose_offset: ThreeDFrame {
            cartesian_coordinates: ThreeDCartesianCoordinates { x: 0.0, y: 0.0, z },
            orientation: ThreeDOrientation { a: 0.0, b: 0.0, c: 0.0 },
        },
    }
}

async fn wait(program: &Program, state: ProgramState) {
    let mut rx = program.watch();
    let reached = tokio::time::timeout(Duration::from_secs(10), rx.wait_for(|s| *s == state)).await;
    assert!(reached.is_ok(), "{program:?} did not reach {state:?}");
}

/// Waits until a basic skill's body has logged `entry` (it runs from then on).
async fn logged(log: &Mutex<Vec<String>>, entry: &str) {
    for _ in 0..400 {
        if log.lock().unwrap().iter().any(|e| e == entry) {
            return;
        }
        tokio::time::sleep(Duration::from_millis(25)).await;
    }
    panic!("`{entry}` was never logged: {:?}", log.lock().unwrap());
}

struct Cell {
    robot: Running,
    unit: Running,
    cell: Running,
    moves: Program,
    drill: Program,
    drill_hole: Program,
    drill_hole_handle: DrillHoleSkillType,
    log: Arc<Mutex<Vec<String>>>,
    /// While set, the drilling unit keeps drilling.
    hold: Arc<AtomicBool>,
}

async fn cell() -> Cell {
    let log = Arc::new(Mutex::new(Vec::new()));
    let hold = Arc::new(AtomicBool::new(false));

    let robot = serve(config("robot")).await;
    let move_skill: RelativeCartesianLinearMoveSkillType = local(&robot.manager, MOVE);
    let move_log = log.clone();
    let moves = move_skill
        .serve(move |inputs: RelativeCartesianLinearMoveSkillTypeInputs, ctl| {
            let log = move_log.clone();
            async move {
                log.lock().unwrap().push(format!("move {}", inputs.pose_offset.cartesian_coordinates.z));
                for _ in 0..10 {
                    ctl.checkpoint().await;
                    tokio::time::sleep(Duration::from_millis(10)).await;
                }
                Ok(Done {})
            }
        })
        .unwrap();

    let unit = serve(config("drilling unit")).await;
    let drill_skill: TemplateDrillingSkillType = local(&unit.manager, DRILL);
    let (drill_log, drill_hold) = (log.clone(), hold.clone());
    let drill = drill_skill
        .serve(move |inputs: TemplateDrillingSkillTypeInputs, ctl| {
            let (log, hold) = (drill_log.clone(), drill_hold.clone());
            async move {
                log.lock().unwrap().push(format!("drill {} x {}", inputs.hole_diameter, inputs.depth));
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

    // The cell finds both basic skills by browse path on their servers, and runs them in order.
    let cell = serve(config("cell")).await;
    let robot_server = RemoteServer::connect(&robot.url).await.expect("connects to the robot");
    let unit_server = RemoteServer::connect(&unit.url).await.expect("connects to the drilling unit");
    let remote_move = Arc::new(robot_server.program::<RelativeCartesianLinearMoveSkillType>(MOVE).await.expect("finds the move skill"));
    let remote_drill = Arc::new(unit_server.program::<TemplateDrillingSkillType>(DRILL).await.expect("finds the drilling skill"));
    assert_eq!(remote_move.state().await.unwrap().map(|s| s.name), Some("Ready"));
    let drill_hole_handle: DrillHoleSkillType = local(&cell.manager, DRILL_HOLE);
    let drill_hole = drill_hole_handle
        .serve(move |i: DrillHoleSkillTypeInputs, ctl| {
            let (mv, drill) = (remote_move.clone(), remote_drill.clone());
            async move {
                mv.run_step(offset(i.insertion_distance), &ctl).await?;
                let drilling = TemplateDrillingSkillTypeInputs {
                    hole_diameter: i.hole_diameter,
                    depth: i.depth,
                    feed_rate: i.feed_rate,
                    spindle_speed: i.spindle_speed,
                    clamp_force: i.clamp_force,
                };
                drill.run_step(drilling, &ctl).await?;
                mv.run_step(offset(-i.insertion_distance), &ctl).await?;
                Ok(Done {})
            }
        })
        .unwrap();
    // The skills keep their sessions; the servers' handles can go.
    drop((robot_server, unit_server));
    Cell { robot, unit, cell, moves, drill, drill_hole, drill_hole_handle, log, hold }
}

async fn write_inputs(session: &Session, skill: &DrillHoleSkillType) {
    let set = &skill.input_parameter_set;
    let values: [(&NodeId, f64); 6] = [
        (set.insertion_distance.id(), 12.5),
        (set.hole_diameter.id(), 6.0),
        (set.depth.id(), 8.0),
        (set.feed_rate.id(), 120.0),
        (set.spindle_speed.id(), 3000.0),
        (set.clamp_force.id(), 400.0),
    ];
    let writes: Vec<WriteValue> = values
        .iter()
        .map(|(id, v)| WriteValue {
            node_id: (*id).clone(),
            attribute_id: opcua::types::AttributeId::Value as u32,
            value: DataValue::value_only(Variant::Double(*v)),
            ..Default::default()
        })
        .collect();
    let results = session.write(&writes).await.unwrap();
    assert!(results.iter().all(|s| s.is_good()), "{results:?}");
}

async fn call(session: &Session, skill: &DrillHoleSkillType, method: &str) -> StatusCode {
    let id = match method {
        "Start" => skill.start.id().clone(),
        "Halt" => skill.halt.id().clone(),
        "Reset" => skill.reset.id().clone(),
        "Suspend" => skill.suspend.id().clone(),
        _ => skill.resume.id().clone(),
    };
    session.call_one((skill.node.id().clone(), id, None::<Vec<Variant>>)).await.unwrap().status_code
}

fn outcome(skill: &DrillHoleSkillType) -> Option<StatusCode> {
    skill.output_parameter_set.result.get()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn drill_hole_runs_its_basic_skills_in_order_and_follows_them() {
    let c = cell().await;
    let (session, event_loop) = connect(&c.cell.url).await;
    let skill = &c.drill_hole_handle;
    write_inputs(&session, skill).await;

    // 1. Move in, drill, move out, on the other two servers, in that order.
    assert_eq!(call(&session, skill, "Start").await, StatusCode::Good);
    wait(&c.drill_hole, ProgramState::Ready).await;
    assert_eq!(*c.log.lock().unwrap(), ["move 12.5", "drill 6 x 8", "move -12.5"]);
    assert_eq!(outcome(skill), Some(StatusCode::Good));
    assert_eq!((c.moves.state(), c.drill.state()), (ProgramState::Ready, ProgramState::Ready));

    // 2. The drilling unit halts (a broken drill): DrillHole halts with its cause, and does not move out.
    c.log.lock().unwrap().clear();
    c.hold.store(true, Ordering::SeqCst);
    assert_eq!(call(&session, skill, "Start").await, StatusCode::Good);
    logged(&c.log, "drill 6 x 8").await;
    c.drill.halt(StatusCode::BadDeviceFailure).unwrap();
    wait(&c.drill_hole, ProgramState::Halted).await;
    assert_eq!(outcome(skill), Some(StatusCode::BadDeviceFailure), "the composite halts with the basic skill's cause");
    assert_eq!(*c.log.lock().unwrap(), ["move 12.5", "drill 6 x 8"]);
    assert_eq!(call(&session, skill, "Start").await, StatusCode::BadInvalidState);
    assert_eq!(call(&session, skill, "Reset").await, StatusCode::Good);
    c.drill.call("Reset").unwrap();

    // 3. The drilling unit suspends its skill (the unit's own Suspend: the skill has no Suspend method for
    //    clients): DrillHole suspends too. A client's Resume of DrillHole cannot resume the drilling (no
    //    Resume method either), so DrillHole runs on when the unit resumes, and finishes the hole.
    c.log.lock().unwrap().clear();
    assert_eq!(call(&session, skill, "Start").await, StatusCode::Good);
    logged(&c.log, "drill 6 x 8").await;
    c.drill.call("Suspend").unwrap();
    wait(&c.drill_hole, ProgramState::Suspended).await;
    c.hold.store(false, Ordering::SeqCst);
    assert_eq!(call(&session, skill, "Resume").await, StatusCode::Good);
    wait(&c.drill_hole, ProgramState::Running).await;
    assert_eq!(c.drill.state(), ProgramState::Suspended);
    c.drill.call("Resume").unwrap();
    wait(&c.drill_hole, ProgramState::Ready).await;
    assert_eq!(*c.log.lock().unwrap(), ["move 12.5", "drill 6 x 8", "move -12.5"]);

    // 4. A client suspends DrillHole while the robot moves in: the move (which cannot be suspended) ends,
    //    and DrillHole waits in Suspended before drilling until the client resumes it.
    c.log.lock().unwrap().clear();
    assert_eq!(call(&session, skill, "Start").await, StatusCode::Good);
    wait(&c.moves, ProgramState::Running).await;
    assert_eq!(call(&session, skill, "Suspend").await, StatusCode::Good);
    wait(&c.moves, ProgramState::Ready).await;
    tokio::time::sleep(Duration::from_millis(200)).await;
    assert_eq!(c.drill_hole.state(), ProgramState::Suspended);
    assert_eq!(*c.log.lock().unwrap(), ["move 12.5"], "no drilling while DrillHole is suspended");
    assert_eq!(call(&session, skill, "Resume").await, StatusCode::Good);
    wait(&c.drill_hole, ProgramState::Ready).await;
    assert_eq!(*c.log.lock().unwrap(), ["move 12.5", "drill 6 x 8", "move -12.5"]);

    // 5. A client halts DrillHole while it drills: the drilling is halted too.
    c.log.lock().unwrap().clear();
    c.hold.store(true, Ordering::SeqCst);
    assert_eq!(call(&session, skill, "Start").await, StatusCode::Good);
    logged(&c.log, "drill 6 x 8").await;
    assert_eq!(call(&session, skill, "Halt").await, StatusCode::Good);
    wait(&c.drill, ProgramState::Halted).await;
    assert_eq!(c.drill_hole.state(), ProgramState::Halted);
    assert_eq!(c.moves.state(), ProgramState::Ready);
    c.hold.store(false, Ordering::SeqCst);

    disconnect(session, event_loop).await;
    c.cell.stop().await;
    c.unit.stop().await;
    c.robot.stop().await;
}

/// The drilling unit goes away while it drills: DrillHole halts with BadCommunicationError instead of
/// waiting for an event that never comes. Started again, DrillHole moves in and then suspends, since the
/// drilling unit cannot be reached; a client's Halt ends it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_lost_server_halts_the_composite_and_an_unreachable_one_suspends_it() {
    let c = cell().await;
    let (session, event_loop) = connect(&c.cell.url).await;
    let skill = &c.drill_hole_handle;
    write_inputs(&session, skill).await;

    c.hold.store(true, Ordering::SeqCst);
    assert_eq!(call(&session, skill, "Start").await, StatusCode::Good);
    logged(&c.log, "drill 6 x 8").await;
    let lost = std::time::Instant::now();
    c.unit.stop().await;
    wait(&c.drill_hole, ProgramState::Halted).await;
    assert_eq!(outcome(skill), Some(StatusCode::BadCommunicationError));
    assert!(lost.elapsed() < Duration::from_secs(8), "halted only after {:?}", lost.elapsed());
    assert_eq!(*c.log.lock().unwrap(), ["move 12.5", "drill 6 x 8"], "no move out after the lost drilling");

    c.log.lock().unwrap().clear();
    assert_eq!(call(&session, skill, "Reset").await, StatusCode::Good);
    assert_eq!(call(&session, skill, "Start").await, StatusCode::Good);
    wait(&c.drill_hole, ProgramState::Suspended).await;
    assert_eq!(*c.log.lock().unwrap(), ["move 12.5"]);
    assert_eq!(call(&session, skill, "Halt").await, StatusCode::Good);
    wait(&c.drill_hole, ProgramState::Halted).await;
    assert_eq!(c.moves.state(), ProgramState::Ready);

    disconnect(session, event_loop).await;
    c.cell.stop().await;
    c.robot.stop().await;
}

/// A path that does not lead to a skill is an error that names where it stopped.
#[tokio::test]
async fn a_wrong_path_names_where_it_stops() {
    let robot = serve(config("robot paths")).await;
    let server = RemoteServer::connect(&robot.url).await.unwrap();
    let err = server.program::<RelativeCartesianLinearMoveSkillType>("DeviceSet/TemplateDrillingLwrSystem/NoSuchDevice/SkillSet/Move").await.err();
    assert_eq!(
        err,
        Some(ClientError::Remote(RemoteError::Path {
            below: "DeviceSet/TemplateDrillingLwrSystem".into(),
            segment: "NoSuchDevice".into(),
            matches: 0
        }))
    );
    let ns = server.session().get_namespace_index_from_cache(drilling_process::NAMESPACE_URI).unwrap();
    let qualified = format!("{{{}}}DrillingCell/SkillSet/DrillHole", drilling_process::NAMESPACE_URI);
    let found = server.find(&qualified).await.unwrap();
    assert_eq!(found.namespace, ns, "DrillHole is a node of DrillingProcess");
    server.disconnect().await;
    robot.stop().await;
}
