//! The two public skill reference models of ../shared/nodesets/skills-reference as typed Rust: they compile
//! (this crate is built under `deny(warnings)`), their state machine type carries its table as the nodeset
//! gives it, and a server drives the state machine of an example skill through that table.

use nodeset_fixture_code::skills_reference::{linear_axis_with_gripper, skills};
use nodeset_models::models::di;
use nodeset_models::runtime::server::ServerConfig;
use nodeset_models::runtime::typed::{Instantiate, Machine, ObjectType, ProgramError, StateMachine};
use nodeset_models::runtime::NsNodeId;
use opcua::types::{LocalizedText, NodeId, ObjectId, StatusCode};

const SKILLS: &str = "http://opcfoundation.org/UA/Skills/";

/// SkillStateMachineType is a FiniteStateMachineType with the four states of a program; the model gives
/// its states and transitions no numbers and its transitions no causes, and names SkillStateTransitionEventType
/// as their effect. The table says exactly that.
#[test]
fn the_skill_state_machine_has_its_table() {
    let table = <skills::objects::SkillStateMachineType as StateMachine>::TABLE;
    let mut states: Vec<&str> = table.states.iter().map(|s| s.name).collect();
    states.sort();
    assert_eq!(states, ["Halted", "Ready", "Running", "Suspended"]);
    assert!(table.states.iter().all(|s| s.number.is_none() && !s.initial && s.node.namespace_uri == SKILLS));
    let mut transitions: Vec<(&str, &str, &str)> =
        table.transitions.iter().map(|t| (t.name, table.states[t.from].name, table.states[t.to].name)).collect();
    transitions.sort();
    assert_eq!(
        transitions,
        [
            ("HaltedToReady", "Halted", "Ready"),
            ("ReadyToHalted", "Ready", "Halted"),
            ("ReadyToRunning", "Ready", "Running"),
            ("RunningToHalted", "Running", "Halted"),
            ("RunningToReady", "Running", "Ready"),
            ("RunningToSuspended", "Running", "Suspended"),
            ("SuspendedToHalted", "Suspended", "Halted"),
            ("SuspendedToReady", "Suspended", "Ready"),
            ("SuspendedToRunning", "Suspended", "Running"),
        ]
    );
    assert!(table.transitions.iter().all(|t| t.causes.is_empty() && t.number.is_none()));
    assert_eq!(table.event_type, Some(NsNodeId::numeric(SKILLS, 15040)), "SkillStateTransitionEventType");
}

/// An example skill (GraspSkillType of LinearAxisWithGripper) instantiated at run time: its state machine,
/// bound as SkillStateMachineType, follows the table, and refuses a transition the table does not have.
#[tokio::test]
async fn an_example_skill_follows_its_state_machine() {
    let server = ServerConfig::new("skills reference")
        .table(&di::TABLE)
        .type_loader(di::TypeLoader)
        .table(&skills::TABLE)
        .type_loader(skills::TypeLoader)
        .table(&linear_axis_with_gripper::TABLE)
        .type_loader(linear_axis_with_gripper::TypeLoader)
        .insecure_only()
        .build()
        .expect("the server builds");
    let m = server.manager().clone();
    let objects = NodeId::from(ObjectId::ObjectsFolder);
    let grasp = linear_axis_with_gripper::objects::GraspSkillType::instantiate(&m, &objects, "Grasp", &Instantiate::new())
        .expect("instantiates GraspSkillType");
    let sm: skills::objects::SkillStateMachineType = m.bind(grasp.state_machine.node.id()).expect("binds its state machine");
    assert!(matches!(Machine::serve(&sm), Err(ProgramError::NoInitialState)), "the model marks no initial state");
    let machine = Machine::serve_from(&sm, "Ready").expect("serves the state machine");
    let shown = || sm.current_state.get().map(|t: LocalizedText| t.text.as_ref().to_owned());
    assert_eq!(shown().as_deref(), Some("Ready"));
    for (to, last) in [("Running", "ReadyToRunning"), ("Suspended", "RunningToSuspended"), ("Running", "SuspendedToRunning"), ("Halted", "RunningToHalted"), ("Ready", "HaltedToReady")] {
        assert_eq!(machine.transition(to), Ok(()), "to {to}");
        assert_eq!(shown().as_deref(), Some(to));
        assert_eq!(sm.last_transition.get().map(|t| t.text.as_ref().to_owned()).as_deref(), Some(last));
    }
    assert_eq!(machine.transition("Suspended"), Err(StatusCode::BadInvalidState), "no ReadyToSuspended");
    // The model names no causes, so no method takes a transition.
    assert_eq!(machine.call("Start"), Err(StatusCode::BadInvalidState));
    assert_eq!(machine.state(), "Ready");
}
