//! Skills as OPC UA programs, through a real client (async-opcua's): the generated state tables and typed
//! inputs drive `Program::serve`, and a client sees what Part 10 promises. Inputs written, Start called,
//! CurrentState going Ready -> Running -> Ready in a subscription, the transition events with their
//! numbers; Halt while Running, Reset, and every method refused with `BadInvalidState` where its
//! transition does not start; Suspend parking the body at its checkpoint and Resume going on; bad inputs
//! refused; a failing body ending in Halted with its status as the result. A state machine that is not a
//! program (DI's ConfirmationStateMachineType) is driven by `Machine`.

mod common;

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use common::{connect, disconnect, read, serve, Running};
use nodeset_models::models::common_skills::objects::{
    AbsoluteJointPtpMoveSkillType, AbsoluteJointPtpMoveSkillTypeInputs, ProgramSkillStateMachineTypeOutputs,
};
use nodeset_models::models::{self, common_skills, di, drilling_process};
use nodeset_models::runtime::server::ServerConfig;
use nodeset_models::runtime::typed::{Instantiate, Machine, ObjectType, ProgramState, StateMachine};
use opcua::client::{MonitoredItem, Session, SubscriptionCallbacks};
use opcua::types::{
    AttributeId, BrowsePath, CallMethodResult, ContentFilter, DataValue, EventFilter, ExtensionObject, LocalizedText,
    MonitoredItemCreateRequest, MonitoringMode, MonitoringParameters, NodeId, ObjectId, ObjectTypeId, QualifiedName,
    ReadValueId, RelativePath, RelativePathElement, SimpleAttributeOperand, StatusCode, TimestampsToReturn, Variant,
    WriteValue,
};
use tokio::sync::{mpsc, Notify};

/// The event fields the tests select, by browse path (ns0 names; `SkillName` is CommonSkills').
const FIELDS: &[&[&str]] = &[
    &["EventType"],
    &["SourceNode"],
    &["Transition"],
    &["Transition", "Id"],
    &["Transition", "Number"],
    &["FromState", "Id"],
    &["FromState", "Number"],
    &["ToState", "Id"],
    &["ToState", "Number"],
    &["Severity"],
    &["SkillName"],
];

/// One transition event as the client received it.
#[derive(Clone, Debug, PartialEq)]
struct Seen {
    event_type: Variant,
    source: Variant,
    transition: Variant,
    transition_id: Variant,
    number: Variant,
    from_id: Variant,
    from_number: Variant,
    to_id: Variant,
    to_number: Variant,
    severity: Variant,
    skill_name: Variant,
}

impl Seen {
    fn from_fields(mut f: Vec<Variant>) -> Seen {
        f.resize(FIELDS.len(), Variant::Empty);
        let mut it = f.into_iter();
        let mut next = || it.next().unwrap_or_default();
        Seen {
            event_type: next(),
            source: next(),
            transition: next(),
            transition_id: next(),
            number: next(),
            from_id: next(),
            from_number: next(),
            to_id: next(),
            to_number: next(),
            severity: next(),
            skill_name: next(),
        }
    }
}

/// What a subscription saw: data changes of CurrentState (client handle 1), events (client handle 2).
#[derive(Clone, Default)]
struct Observer {
    states: Arc<Mutex<Vec<Variant>>>,
    events: Arc<Mutex<Vec<Seen>>>,
}

impl Observer {
    async fn wait(&self, what: &str, done: impl Fn(&[Variant], &[Seen]) -> bool) {
        for _ in 0..200 {
            if done(&self.states.lock().unwrap(), &self.events.lock().unwrap()) {
                return;
            }
            tokio::time::sleep(Duration::from_millis(25)).await;
        }
        panic!("timed out waiting for {what}: states {:?}, events {:#?}", self.states.lock().unwrap(), self.events.lock().unwrap());
    }

    /// Waits until CurrentState has taken the values `states` (in order, since the subscription began).
    async fn states(&self, states: &[&str]) {
        let want: Vec<Variant> = states.iter().map(|s| Variant::from(LocalizedText::from(*s))).collect();
        self.wait(&format!("CurrentState {states:?}"), |seen, _| seen == want.as_slice()).await;
    }

    /// Waits until `n` events have arrived and returns their transition numbers.
    async fn events(&self, n: usize) -> Vec<Seen> {
        self.wait(&format!("{n} events"), |_, events| events.len() >= n).await;
        let events = self.events.lock().unwrap().clone();
        assert_eq!(events.len(), n, "more events than expected: {events:#?}");
        events
    }
}

/// Subscribes to the value of `current_state` and to the events of `notifier`.
async fn observe(session: &Session, current_state: &NodeId, notifier: &NodeId, skills_ns: u16) -> Observer {
    let observer = Observer::default();
    let (states, events) = (observer.states.clone(), observer.events.clone());
    let callbacks = SubscriptionCallbacks::new(
        |_| {},
        move |dv: DataValue, item: &MonitoredItem| {
            if item.client_handle() == 1 {
                states.lock().unwrap().push(dv.value.unwrap_or_default());
            }
        },
        move |fields: Option<Vec<Variant>>, _| events.lock().unwrap().push(Seen::from_fields(fields.unwrap_or_default())),
    );
    let subscription = session
        .create_subscription(Duration::from_millis(20), 100, 10, 0, 0, true, callbacks)
        .await
        .expect("creates a subscription");
    let select_clauses = FIELDS
        .iter()
        .map(|path| SimpleAttributeOperand {
            type_definition_id: ObjectTypeId::BaseEventType.into(),
            browse_path: Some(
                path.iter().map(|n| QualifiedName::new(if *n == "SkillName" { skills_ns } else { 0 }, *n)).collect(),
            ),
            attribute_id: AttributeId::Value as u32,
            index_range: Default::default(),
        })
        .collect();
    let filter = EventFilter { select_clauses: Some(select_clauses), where_clause: ContentFilter::default() };
    let items = vec![
        MonitoredItemCreateRequest {
            item_to_monitor: ReadValueId { node_id: current_state.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() },
            monitoring_mode: MonitoringMode::Reporting,
            requested_parameters: MonitoringParameters { client_handle: 1, sampling_interval: 0.0, queue_size: 100, discard_oldest: false, ..Default::default() },
        },
        MonitoredItemCreateRequest {
            item_to_monitor: ReadValueId { node_id: notifier.clone(), attribute_id: AttributeId::EventNotifier as u32, ..Default::default() },
            monitoring_mode: MonitoringMode::Reporting,
            requested_parameters: MonitoringParameters {
                client_handle: 2,
                sampling_interval: 0.0,
                filter: ExtensionObject::from_message(filter),
                queue_size: 100,
                discard_oldest: false,
            },
        },
    ];
    let created = session.create_monitored_items(subscription, TimestampsToReturn::Both, items).await.expect("creates the items");
    for item in &created {
        assert_eq!(item.result.status_code, StatusCode::Good, "{item:?}");
    }
    observer
}

async fn call(session: &Session, object: &NodeId, method: &NodeId, args: Vec<Variant>) -> StatusCode {
    let result: CallMethodResult =
        session.call_one((object.clone(), method.clone(), Some(args))).await.expect("the Call service answers");
    result.status_code
}

async fn write(session: &Session, node: &NodeId, value: impl Into<Variant>) -> StatusCode {
    let w = WriteValue {
        node_id: node.clone(),
        attribute_id: AttributeId::Value as u32,
        value: DataValue::value_only(value.into()),
        ..Default::default()
    };
    session.write(&[w]).await.expect("the Write service answers")[0]
}

/// The node at a browse path of ns0 names below `start`, found by the client.
async fn browse_path(session: &Session, start: &NodeId, names: &[&str]) -> NodeId {
    let path = BrowsePath {
        starting_node: start.clone(),
        relative_path: RelativePath {
            elements: Some(
                names
                    .iter()
                    .map(|n| RelativePathElement {
                        reference_type_id: opcua::types::ReferenceTypeId::HierarchicalReferences.into(),
                        is_inverse: false,
                        include_subtypes: true,
                        target_name: QualifiedName::new(0, *n),
                    })
                    .collect(),
            ),
        },
    };
    let result = session.translate_browse_paths_to_node_ids(&[path]).await.expect("translates").remove(0);
    assert_eq!(result.status_code, StatusCode::Good, "{names:?} below {start}");
    result.targets.unwrap_or_default().remove(0).target_id.node_id
}

fn ns0(n: u32) -> Variant {
    Variant::from(NodeId::new(0, n))
}

/// ProgramStateMachineType's state objects and transitions (ns0 1.05.07): (NodeId, number).
const READY: (u32, u32) = (2400, 12);
const RUNNING: (u32, u32) = (2402, 13);
const SUSPENDED: (u32, u32) = (2404, 14);
const HALTED: (u32, u32) = (2406, 11);

/// Checks one event: the transition (BrowseName, NodeId, number) between two states.
fn check(e: &Seen, name: &str, transition: (u32, u32), from: (u32, u32), to: (u32, u32)) {
    assert_eq!(e.transition, Variant::from(LocalizedText::from(name)), "{e:#?}");
    assert_eq!(e.transition_id, ns0(transition.0), "{name}");
    assert_eq!(e.number, Variant::UInt32(transition.1), "{name}");
    assert_eq!((e.from_id.clone(), e.from_number.clone()), (ns0(from.0), Variant::UInt32(from.1)), "{name}");
    assert_eq!((e.to_id.clone(), e.to_number.clone()), (ns0(to.0), Variant::UInt32(to.1)), "{name}");
}

fn cell_config(name: &str) -> ServerConfig {
    models::register(ServerConfig::new(name))
}

fn skill_event_type(running: &Running) -> Variant {
    Variant::from(running.manager.resolve(common_skills::ids::object_types::SKILL_TRANSITION_EVENT_TYPE).unwrap())
}

/// The UR10e's AbsoluteJointPTPMove of the DrillingProcess cell, bound: Start with typed inputs, Ready ->
/// Running -> Ready in a subscription, the two transition events on the skill.
#[tokio::test]
async fn start_runs_the_typed_body_from_ready_to_ready() {
    let running = serve(cell_config("skill start")).await;
    let m = running.manager.clone();
    let id = m
        .resolve(drilling_process::ids::objects::TEMPLATE_DRILLING_LWR_SYSTEM_MOTION_DEVICE_SYSTEM_CONTROLLERS_UR_CONTROLLER_SKILL_SET_ABSOLUTE_JOINT_PTP_MOVE)
        .unwrap();
    let skill: AbsoluteJointPtpMoveSkillType = m.bind(&id).expect("binds the cell's move skill");
    let (inputs_tx, mut inputs_rx) = mpsc::unbounded_channel();
    let gate = Arc::new(Notify::new());
    let body_gate = gate.clone();
    let program = skill
        .serve(move |inputs: AbsoluteJointPtpMoveSkillTypeInputs, ctl| {
            let (tx, gate) = (inputs_tx.clone(), body_gate.clone());
            async move {
                tx.send(inputs).expect("the test listens");
                gate.notified().await;
                ctl.checkpoint().await;
                Ok(ProgramSkillStateMachineTypeOutputs {})
            }
        })
        .expect("serves the skill");
    assert_eq!(program.state(), ProgramState::Ready);

    let (session, event_loop) = connect(&running.url).await;
    let skills_ns = m.namespace_index(common_skills::NAMESPACE_URI).unwrap();
    let observer = observe(&session, skill.current_state.id(), &id, skills_ns).await;
    observer.states(&["Ready"]).await;

    // Inputs: a wrong type is refused by the Write service; then the real ones.
    let set = &skill.input_parameter_set;
    assert_eq!(write(&session, set.speed.id(), "fast").await, StatusCode::BadTypeMismatch);
    let joints = vec![0.0, -90.0, 90.0, 0.0, 90.0, 0.0];
    assert_eq!(write(&session, set.speed.id(), 30.0).await, StatusCode::Good);
    assert_eq!(write(&session, set.acceleration.id(), 60.0).await, StatusCode::Good);
    assert_eq!(write(&session, set.target_joint_positions.id(), joints.clone()).await, StatusCode::Good);

    assert_eq!(call(&session, &id, skill.start.id(), vec![]).await, StatusCode::Good);
    let inputs = tokio::time::timeout(Duration::from_secs(5), inputs_rx.recv()).await.unwrap().unwrap();
    assert_eq!(inputs, AbsoluteJointPtpMoveSkillTypeInputs { speed: 30.0, acceleration: 60.0, target_joint_positions: joints });
    observer.states(&["Ready", "Running"]).await;
    let state_id = browse_path(&session, &id, &["CurrentState", "Id"]).await;
    let state_number = browse_path(&session, &id, &["CurrentState", "Number"]).await;
    assert_eq!(read(&session, &state_id, AttributeId::Value).await.1, ns0(RUNNING.0));
    assert_eq!(read(&session, &state_number, AttributeId::Value).await.1, Variant::UInt32(RUNNING.1));
    // Start while Running, Reset and Resume while Running: no such transition.
    assert_eq!(call(&session, &id, skill.start.id(), vec![]).await, StatusCode::BadInvalidState);
    assert_eq!(call(&session, &id, skill.reset.id(), vec![]).await, StatusCode::BadInvalidState);

    gate.notify_one();
    observer.states(&["Ready", "Running", "Ready"]).await;
    let events = observer.events(2).await;
    check(&events[0], "ReadyToRunning", (2410, 2), READY, RUNNING);
    check(&events[1], "RunningToReady", (2414, 4), RUNNING, READY);
    for e in &events {
        assert_eq!(e.event_type, skill_event_type(&running));
        assert_eq!(e.source, Variant::from(id.clone()));
        assert_eq!(e.skill_name, Variant::from("AbsoluteJointPTPMove"));
        assert_eq!(e.severity, Variant::UInt16(100));
    }
    assert_eq!(read(&session, skill.last_transition.id(), AttributeId::Value).await.1, Variant::from(LocalizedText::from("RunningToReady")));
    let last_number = browse_path(&session, &id, &["LastTransition", "Number"]).await;
    let last_id = browse_path(&session, &id, &["LastTransition", "Id"]).await;
    assert_eq!(read(&session, &last_number, AttributeId::Value).await.1, Variant::UInt32(4));
    assert_eq!(read(&session, &last_id, AttributeId::Value).await.1, ns0(2414));
    let last_time = browse_path(&session, &id, &["LastTransition", "TransitionTime"]).await;
    assert!(matches!(read(&session, &last_time, AttributeId::Value).await.1, Variant::DateTime(_)), "TransitionTime is set");
    for property in ["Deletable", "AutoDelete"] {
        let node = browse_path(&session, &id, &[property]).await;
        assert_eq!(read(&session, &node, AttributeId::Value).await.1, Variant::Boolean(false), "{property}");
    }
    let result = skill.output_parameter_set.result.id();
    assert_eq!(read(&session, result, AttributeId::Value).await.1, Variant::StatusCode(StatusCode::Good));
    assert_eq!(program.state(), ProgramState::Ready);
    disconnect(session, event_loop).await;
    running.stop().await;
}

/// A move skill instantiated at run time with Suspend and Resume; events observed on the Server object.
#[tokio::test]
async fn methods_are_valid_only_where_their_transitions_start() {
    let running = serve(cell_config("skill states")).await;
    let m = running.manager.clone();
    let objects = NodeId::from(ObjectId::ObjectsFolder);
    let skill = AbsoluteJointPtpMoveSkillType::instantiate(&m, &objects, "Move", &Instantiate::new().optional("Suspend").optional("Resume"))
        .expect("instantiates the skill");
    let (suspend, resume) = (skill.suspend.clone().expect("Suspend was asked for"), skill.resume.clone().expect("Resume too"));
    let steps = Arc::new(AtomicU32::new(0));
    let dropped = Arc::new(AtomicBool::new(false));
    struct Guard(Arc<AtomicBool>);
    impl Drop for Guard {
        fn drop(&mut self) {
            self.0.store(true, Ordering::SeqCst);
        }
    }
    let (body_steps, body_dropped) = (steps.clone(), dropped.clone());
    skill
        .serve(move |inputs: AbsoluteJointPtpMoveSkillTypeInputs, ctl| {
            let (steps, dropped) = (body_steps.clone(), body_dropped.clone());
            async move {
                dropped.store(false, Ordering::SeqCst);
                let _guard = Guard(dropped);
                if inputs.speed < 0.0 {
                    return Err(StatusCode::BadOutOfRange);
                }
                loop {
                    ctl.checkpoint().await;
                    steps.fetch_add(1, Ordering::SeqCst);
                    tokio::time::sleep(Duration::from_millis(5)).await;
                }
            }
        })
        .expect("serves the skill");

    let (session, event_loop) = connect(&running.url).await;
    let skills_ns = m.namespace_index(common_skills::NAMESPACE_URI).unwrap();
    let server = NodeId::from(ObjectId::Server);
    let observer = observe(&session, skill.current_state.id(), &server, skills_ns).await;
    observer.states(&["Ready"]).await;
    let id = skill.node.id().clone();
    let method = |name: &str| -> NodeId {
        match name {
            "Start" => skill.start.id().clone(),
            "Halt" => skill.halt.id().clone(),
            "Reset" => skill.reset.id().clone(),
            "Suspend" => suspend.id().clone(),
            _ => resume.id().clone(),
        }
    };
    let refused = |state: &'static str, names: &'static [&'static str]| {
        let (session, id) = (&session, &id);
        let method = &method;
        async move {
            for name in names {
                assert_eq!(call(session, id, &method(name), vec![]).await, StatusCode::BadInvalidState, "{name} in {state}");
            }
        }
    };

    // Bad inputs: none written yet, then an argument Start does not take. The state stays Ready.
    assert_eq!(call(&session, &id, &method("Start"), vec![]).await, StatusCode::BadArgumentsMissing);
    assert_eq!(call(&session, &id, &method("Start"), vec![1.0.into()]).await, StatusCode::BadTooManyArguments);
    refused("Ready", &["Suspend", "Resume", "Reset"]).await;
    let set = &skill.input_parameter_set;
    assert_eq!(write(&session, set.speed.id(), 10.0).await, StatusCode::Good);
    assert_eq!(write(&session, set.acceleration.id(), 20.0).await, StatusCode::Good);
    assert_eq!(write(&session, set.target_joint_positions.id(), vec![1.0, 2.0]).await, StatusCode::Good);

    // Ready -> Running -> Suspended (the body parks) -> Running (it goes on) -> Halted (it is dropped).
    assert_eq!(call(&session, &id, &method("Start"), vec![]).await, StatusCode::Good);
    observer.states(&["Ready", "Running"]).await;
    refused("Running", &["Start", "Resume", "Reset"]).await;
    assert_eq!(call(&session, &id, &method("Suspend"), vec![]).await, StatusCode::Good);
    observer.states(&["Ready", "Running", "Suspended"]).await;
    tokio::time::sleep(Duration::from_millis(50)).await;
    let parked = steps.load(Ordering::SeqCst);
    tokio::time::sleep(Duration::from_millis(150)).await;
    assert_eq!(steps.load(Ordering::SeqCst), parked, "the body makes no progress while Suspended");
    refused("Suspended", &["Start", "Suspend"]).await;
    assert_eq!(call(&session, &id, &method("Resume"), vec![]).await, StatusCode::Good);
    observer.states(&["Ready", "Running", "Suspended", "Running"]).await;
    observer.wait("progress after Resume", |_, _| steps.load(Ordering::SeqCst) > parked + 3).await;
    assert_eq!(call(&session, &id, &method("Halt"), vec![]).await, StatusCode::Good);
    observer.states(&["Ready", "Running", "Suspended", "Running", "Halted"]).await;
    observer.wait("the body to be dropped", |_, _| dropped.load(Ordering::SeqCst)).await;
    let result = skill.output_parameter_set.result.id();
    assert_eq!(read(&session, result, AttributeId::Value).await.1, Variant::StatusCode(StatusCode::BadRequestCancelledByClient));

    // Halted: only Reset.
    refused("Halted", &["Start", "Suspend", "Resume", "Halt"]).await;
    assert_eq!(call(&session, &id, &method("Reset"), vec![]).await, StatusCode::Good);
    observer.states(&["Ready", "Running", "Suspended", "Running", "Halted", "Ready"]).await;
    let recycle = skill.recycle_count.id();
    assert_eq!(read(&session, recycle, AttributeId::Value).await.1, Variant::Int32(1));

    // A body that fails ends the run in Halted with its status as the result (RunningToHalted, severity 500).
    assert_eq!(write(&session, set.speed.id(), -1.0).await, StatusCode::Good);
    assert_eq!(call(&session, &id, &method("Start"), vec![]).await, StatusCode::Good);
    observer.states(&["Ready", "Running", "Suspended", "Running", "Halted", "Ready", "Running", "Halted"]).await;
    assert_eq!(read(&session, result, AttributeId::Value).await.1, Variant::StatusCode(StatusCode::BadOutOfRange));
    assert_eq!(call(&session, &id, &method("Reset"), vec![]).await, StatusCode::Good);

    // Reset while Suspended ends the run in Ready (SuspendedToReady, see runtime::typed::program).
    assert_eq!(write(&session, set.speed.id(), 10.0).await, StatusCode::Good);
    assert_eq!(call(&session, &id, &method("Start"), vec![]).await, StatusCode::Good);
    assert_eq!(call(&session, &id, &method("Suspend"), vec![]).await, StatusCode::Good);
    assert_eq!(call(&session, &id, &method("Reset"), vec![]).await, StatusCode::Good);
    observer
        .states(&["Ready", "Running", "Suspended", "Running", "Halted", "Ready", "Running", "Halted", "Ready", "Running", "Suspended", "Ready"])
        .await;
    observer.wait("the body to be dropped", |_, _| dropped.load(Ordering::SeqCst)).await;
    assert_eq!(read(&session, recycle, AttributeId::Value).await.1, Variant::Int32(3));

    let events = observer.events(11).await;
    let expected = [
        ("ReadyToRunning", (2410, 2), READY, RUNNING),
        ("RunningToSuspended", (2416, 5), RUNNING, SUSPENDED),
        ("SuspendedToRunning", (2418, 6), SUSPENDED, RUNNING),
        ("RunningToHalted", (2412, 3), RUNNING, HALTED),
        ("HaltedToReady", (2408, 1), HALTED, READY),
        ("ReadyToRunning", (2410, 2), READY, RUNNING),
        ("RunningToHalted", (2412, 3), RUNNING, HALTED),
        ("HaltedToReady", (2408, 1), HALTED, READY),
        ("ReadyToRunning", (2410, 2), READY, RUNNING),
        ("RunningToSuspended", (2416, 5), RUNNING, SUSPENDED),
        ("SuspendedToReady", (2422, 8), SUSPENDED, READY),
    ];
    for (e, (name, t, from, to)) in events.iter().zip(expected) {
        check(e, name, t, from, to);
        assert_eq!(e.event_type, skill_event_type(&running));
        assert_eq!(e.skill_name, Variant::from("Move"));
    }
    // The failed run is the one transition of higher severity.
    let severities: Vec<&Variant> = events.iter().map(|e| &e.severity).collect();
    assert_eq!(severities[6], &Variant::UInt16(500));
    assert!(severities.iter().enumerate().all(|(i, s)| i == 6 || **s == Variant::UInt16(100)), "{severities:?}");
    disconnect(session, event_loop).await;
    running.stop().await;
}

/// A state machine that is not a program: DI's ConfirmationStateMachineType, whose Confirm method is valid
/// only while WaitingForConfirm, and whose other transition the server takes.
#[tokio::test]
async fn a_finite_state_machine_follows_its_table() {
    let running = serve(ServerConfig::new("machine").table(&di::TABLE).type_loader(di::TypeLoader)).await;
    let m = running.manager.clone();
    let objects = NodeId::from(ObjectId::ObjectsFolder);
    let options = Instantiate::new().optional("AvailableStates").optional("AvailableTransitions");
    let confirmation = di::objects::ConfirmationStateMachineType::instantiate(&m, &objects, "Confirmation", &options)
        .expect("instantiates the machine");
    assert_eq!(<di::objects::ConfirmationStateMachineType as StateMachine>::TABLE.states.len(), 2);
    let machine = Machine::serve(&confirmation).expect("serves the machine");
    assert_eq!(machine.state(), "NotWaitingForConfirm");
    let confirm = confirmation.confirm.id().clone();

    let (session, event_loop) = connect(&running.url).await;
    let id = confirmation.node.id().clone();
    let observer = observe(&session, confirmation.current_state.id(), &id, 0).await;
    observer.states(&["NotWaitingForConfirm"]).await;
    assert_eq!(call(&session, &id, &confirm, vec![]).await, StatusCode::BadInvalidState);
    assert_eq!(machine.transition("NotWaitingForConfirm"), Err(StatusCode::BadInvalidState));
    assert_eq!(machine.transition("WaitingForConfirm"), Ok(()));
    observer.states(&["NotWaitingForConfirm", "WaitingForConfirm"]).await;
    assert_eq!(call(&session, &id, &confirm, vec![]).await, StatusCode::Good);
    observer.states(&["NotWaitingForConfirm", "WaitingForConfirm", "NotWaitingForConfirm"]).await;
    assert_eq!(machine.state(), "NotWaitingForConfirm");
    let events = observer.events(2).await;
    let di_ns = m.namespace_index(di::NAMESPACE_URI).unwrap();
    let di_id = |n: u32| Variant::from(NodeId::new(di_ns, n));
    assert_eq!(events[0].transition_id, di_id(327));
    assert_eq!(events[0].number, Variant::UInt32(12));
    assert_eq!((events[1].transition_id.clone(), events[1].number.clone()), (di_id(329), Variant::UInt32(21)));
    assert_eq!(events[1].to_id, di_id(323));
    // AvailableStates lists both states, AvailableTransitions the one that leaves the current state.
    let available = |name: &'static str| {
        let node = confirmation.node.id().clone();
        let m = m.clone();
        move || {
            let id = m.bind_with(|b| b.find_child(&node, "http://opcfoundation.org/UA/", name)).unwrap().expect("asked for");
            m.value(&id).and_then(|dv| dv.value)
        }
    };
    let ids = |ns: &[u32]| Some(Variant::from(ns.iter().map(|&n| NodeId::new(di_ns, n)).collect::<Vec<_>>()));
    assert_eq!(available("AvailableStates")(), ids(&[323, 325]));
    assert_eq!(available("AvailableTransitions")(), ids(&[327]));
    // The table names TransitionEventType: a machine raises no SkillName.
    assert_eq!(events[0].event_type, ns0(2311));
    assert_eq!(events[0].skill_name, Variant::Empty);
    disconnect(session, event_loop).await;
    running.stop().await;
}
