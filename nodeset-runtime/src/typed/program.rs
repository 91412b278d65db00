//! State machines and programs (OPC UA Part 5 Annex B, Part 10) driven by the tables generated code
//! declares: [`StateMachine::TABLE`] lists the states and transitions of a type as its nodeset gives them
//! (inherited ones included), [`ProgramType`] names a program's typed inputs and outputs. The logic lives
//! here, once:
//!
//! - [`Program::serve`] makes an instance of a `ProgramStateMachineType` subtype run: its cause methods
//!   (Start, Suspend, Resume, Halt, Reset, whichever the instance has) are implemented, each valid only in
//!   the states its transitions start in; Start reads the typed inputs from `InputParameterSet` and runs the
//!   user's async body; the body's outputs are written to `OutputParameterSet` when it returns.
//! - [`Machine::serve`] does the same for any other state machine type (methods cause transitions, the
//!   server may take transitions of its own), without a body.
//!
//! Every transition keeps `CurrentState` (value, `Id`, `Number`, `EffectiveDisplayName` where present),
//! `LastTransition` (value, `Id`, `Number`, `TransitionTime`, `EffectiveTransitionTime` where present),
//! `AvailableStates` and `AvailableTransitions` (where present) and the times, last method and its status
//! in `ProgramDiagnostic`'s variables (where present; its structure value is left as it is) right, and raises the event type the table names (see [`TransitionEvent`]) with the instance as its
//! source: clients monitoring the instance or the Server object (async-opcua forwards every event to the
//! Server object's monitored items) receive it.
//!
//! # Status codes
//!
//! A method whose transition does not start in the current state fails with `BadInvalidState` and changes
//! nothing: Part 4 defines it for an object "in some other invalid state" for the operation, and Part 10
//! (5.2.4) lets the Program Control Methods cause their transitions only "depending on the current state".
//! The methods' Executable attribute stays true, because async-opcua answers a call of a non-executable
//! method with `BadUserAccessDenied`, which would tell the client something false. An input variable
//! without a value fails Start with `BadArgumentsMissing` (the inputs are the program's arguments), one of
//! the wrong type with `BadTypeMismatch` (client writes of the wrong type are already refused by the Write
//! service with `BadTypeMismatch`). The outcome of a halted run is the body's error status, or
//! `BadRequestCancelledByClient` when a client called Halt or Reset.
//!
//! # Which transition a method causes
//!
//! Of the transitions that leave the current state and name the method as a cause (HasCause), the one that
//! names the fewest causes wins, then the one with the lowest TransitionNumber. The ns0 nodeset (1.05.07)
//! names Reset as a cause of both SuspendedToHalted and SuspendedToReady, where Part 10 Table 1 has Halt and
//! an internal cause; with this rule Reset in Suspended goes to Ready and Halt to Halted.

use std::future::Future;
use std::pin::Pin;
use std::sync::{Arc, Mutex, MutexGuard};

use opcua::nodes::{Event, EventField, EventNotifier, TypeTree};
use opcua::types::{
    AttributeId, ByteString, DateTime, Guid, LocalizedText, NodeId, NumericRange, ObjectTypeId,
    QualifiedName, StatusCode, Variant,
};
use tokio::sync::watch;
use tracing::warn;

use super::handle::{BindError, Binder, ObjectNode};
use super::value::UaValue;
use super::ObjectType;
use crate::server::{MethodError, MethodInvocation, ModelManager};
use crate::table::NsNodeId;

/// The ns0 namespace URI, for the BrowseNames of the state machine's variables.
const UA: &str = "http://opcfoundation.org/UA/";

/// A state of a state machine type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateRow {
    /// The state's BrowseName (name part).
    pub name: &'static str,
    /// The state's DisplayName, the value `CurrentState` takes.
    pub display_name: &'static str,
    /// The StateNumber, if the nodeset gives one.
    pub number: Option<u32>,
    /// The state object (of the type that declares it).
    pub node: NsNodeId,
    /// Whether it is the initial state (an `InitialStateType`).
    pub initial: bool,
}

/// A transition of a state machine type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TransitionRow {
    /// The transition's BrowseName (name part).
    pub name: &'static str,
    /// The transition's DisplayName, the value `LastTransition` takes.
    pub display_name: &'static str,
    /// The TransitionNumber, if the nodeset gives one.
    pub number: Option<u32>,
    /// The transition object.
    pub node: NsNodeId,
    /// FromState, an index into [`StateTable::states`].
    pub from: usize,
    /// ToState, an index into [`StateTable::states`].
    pub to: usize,
    /// The methods that cause it (HasCause), by BrowseName (namespace URI, name); empty for a transition
    /// the server takes by itself.
    pub causes: &'static [(&'static str, &'static str)],
}

/// The states and transitions of a state machine type, as generated code declares them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateTable {
    /// The states.
    pub states: &'static [StateRow],
    /// The transitions.
    pub transitions: &'static [TransitionRow],
    /// The event type a transition raises (a concrete `TransitionEventType` subtype).
    pub event_type: Option<NsNodeId>,
}

impl StateTable {
    /// The index of the state with this BrowseName.
    pub fn state(&self, name: &str) -> Option<usize> {
        self.states.iter().position(|s| s.name == name)
    }

    /// The transition that a call of method `name` causes in state `current`, if any (see the module docs
    /// for the rule when several do).
    pub fn caused_by(&self, current: usize, name: &str) -> Option<usize> {
        self.transitions
            .iter()
            .enumerate()
            .filter(|(_, t)| t.from == current && t.causes.iter().any(|(_, c)| *c == name))
            .min_by_key(|(_, t)| (t.causes.len(), t.number.unwrap_or(u32::MAX), t.name))
            .map(|(i, _)| i)
    }

    /// The transition from one state to another, if the table has one.
    pub fn between(&self, from: usize, to: usize) -> Option<usize> {
        self.transitions
            .iter()
            .enumerate()
            .filter(|(_, t)| t.from == from && t.to == to)
            .min_by_key(|(_, t)| (t.number.unwrap_or(u32::MAX), t.name))
            .map(|(i, _)| i)
    }

    /// Every method BrowseName that causes a transition, each once, sorted.
    pub fn causes(&self) -> Vec<(&'static str, &'static str)> {
        let mut out: Vec<_> = self.transitions.iter().flat_map(|t| t.causes.iter().copied()).collect();
        out.sort();
        out.dedup();
        out
    }
}

/// A generated handle of a state machine type.
pub trait StateMachine: ObjectType {
    /// The type's states and transitions, inherited ones included.
    const TABLE: StateTable;
    /// The instance the handle is bound to.
    fn state_machine_node(&self) -> &ObjectNode;
}

/// A generated handle of a `ProgramStateMachineType` subtype: the Rust types of its inputs and outputs.
pub trait ProgramType: StateMachine {
    /// The variables of `InputParameterSet` (`()` if the type has none).
    type Inputs: Parameters;
    /// The variables of `OutputParameterSet` (`()` if the type has none).
    type Outputs: Parameters;
}

/// A generated struct of a program's input or output variables.
pub trait Parameters: Sized + Send + 'static {
    /// The BrowseName of the object that holds the variables (`InputParameterSet`, `OutputParameterSet`).
    const SET: Option<(&'static str, &'static str)>;
    /// The BrowseNames of the variables, in field order.
    const NAMES: &'static [(&'static str, &'static str)];
    /// The StatusCode variable of the set that the runtime sets to the outcome of a run.
    const OUTCOME: Option<(&'static str, &'static str)>;
    /// The struct from the variables' values (in [`Parameters::NAMES`] order; `None` for an optional
    /// variable the instance lacks); on failure the index of the first bad value and why.
    fn from_values(values: &[Option<Variant>]) -> Result<Self, (usize, StatusCode)>;
    /// The values to write, in [`Parameters::NAMES`] order (`None`: leave the variable alone).
    fn into_values(self) -> Vec<Option<Variant>>;
}

impl Parameters for () {
    const SET: Option<(&'static str, &'static str)> = None;
    const NAMES: &'static [(&'static str, &'static str)] = &[];
    const OUTCOME: Option<(&'static str, &'static str)> = None;
    fn from_values(_: &[Option<Variant>]) -> Result<Self, (usize, StatusCode)> {
        Ok(())
    }
    fn into_values(self) -> Vec<Option<Variant>> {
        Vec::new()
    }
}

/// A field of a [`Parameters`] struct: a mandatory variable (`T`) or an optional one (`Option<T>`).
pub trait ParameterValue: Sized {
    /// The field from the variable's value (`None`: the instance lacks the variable).
    fn from_value(value: Option<&Variant>) -> Result<Self, StatusCode>;
    /// The value to write (`None`: leave the variable alone).
    fn to_value(&self) -> Option<Variant>;
}

impl<T: UaValue> ParameterValue for T {
    fn from_value(value: Option<&Variant>) -> Result<Self, StatusCode> {
        match value {
            None | Some(Variant::Empty) => Err(StatusCode::BadArgumentsMissing),
            Some(v) => T::from_variant(v).ok_or(StatusCode::BadTypeMismatch),
        }
    }
    fn to_value(&self) -> Option<Variant> {
        Some(self.to_variant())
    }
}

impl<T: UaValue> ParameterValue for Option<T> {
    fn from_value(value: Option<&Variant>) -> Result<Self, StatusCode> {
        match value {
            None | Some(Variant::Empty) => Ok(None),
            Some(v) => T::from_variant(v).map(Some).ok_or(StatusCode::BadTypeMismatch),
        }
    }
    fn to_value(&self) -> Option<Variant> {
        self.as_ref().map(UaValue::to_variant)
    }
}

/// Why a state machine or program could not be served.
#[derive(Clone, Debug, PartialEq)]
pub enum ProgramError {
    /// A node the driver needs is missing or of the wrong kind.
    Bind(BindError),
    /// The table has no state with this BrowseName, which a program needs.
    MissingState(&'static str),
    /// The table has no states at all, or none to start in.
    NoInitialState,
    /// The table has no state with this BrowseName.
    UnknownState(String),
    /// A namespace of the table is not registered in the server.
    UnknownNamespace(&'static str),
}

impl std::fmt::Display for ProgramError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ProgramError::Bind(e) => write!(f, "{e}"),
            ProgramError::MissingState(s) => write!(f, "the state machine has no state `{s}`, which a program needs"),
            ProgramError::NoInitialState => write!(f, "the state machine has no initial state"),
            ProgramError::UnknownState(s) => write!(f, "the state machine has no state `{s}`"),
            ProgramError::UnknownNamespace(uri) => write!(f, "the server has no namespace `{uri}`"),
        }
    }
}

impl std::error::Error for ProgramError {}

impl From<BindError> for ProgramError {
    fn from(e: BindError) -> Self {
        ProgramError::Bind(e)
    }
}

/// The variables of an instance that a transition updates; `None` where the instance lacks one.
#[derive(Clone, Debug, Default)]
struct Variables {
    current_state: Option<NodeId>,
    current_state_id: Option<NodeId>,
    current_state_number: Option<NodeId>,
    current_state_effective: Option<NodeId>,
    last_transition: Option<NodeId>,
    last_transition_id: Option<NodeId>,
    last_transition_number: Option<NodeId>,
    last_transition_time: Option<NodeId>,
    last_transition_effective: Option<NodeId>,
    available_states: Option<NodeId>,
    available_transitions: Option<NodeId>,
    diagnostic_transition_time: Option<NodeId>,
    diagnostic_method_call: Option<NodeId>,
    diagnostic_method_call_time: Option<NodeId>,
    diagnostic_method_status: Option<NodeId>,
    recycle_count: Option<NodeId>,
}

/// What a transition event carries besides the transition, per event type.
#[derive(Clone, Debug)]
struct EventSetup {
    event_type: NodeId,
    /// Extra fields: (browse path, value), for the event types of our models (`SkillName`).
    extra: Vec<(Vec<QualifiedName>, Variant)>,
}

/// A transition event: the fields of BaseEventType, TransitionEventType (`Transition`, `FromState`,
/// `ToState`, each with `Id` and `Number`, and `Transition/TransitionTime`) and of the event type the table
/// names (`SkillName` of our `SkillTransitionEventType`).
///
/// Clients select fields by browse path; the TypeDefinitionId of a select clause may be BaseEventType
/// (which python asyncua sends for every field, and Part 4 says to evaluate without considering the type)
/// or the event type or any of its supertypes.
#[derive(Clone, Debug)]
pub struct TransitionEvent {
    event_type: NodeId,
    chain: Vec<NodeId>,
    time: DateTime,
    fields: Vec<(Vec<QualifiedName>, Variant)>,
}

impl TransitionEvent {
    /// The value of a field by browse path, `Variant::Empty` if the event has no such field.
    pub fn field(&self, path: &[QualifiedName]) -> Variant {
        self.fields.iter().find(|(p, _)| p.as_slice() == path).map(|(_, v)| v.clone()).unwrap_or(Variant::Empty)
    }
}

impl EventField for TransitionEvent {
    fn get_value(&self, attribute_id: AttributeId, index_range: &NumericRange, remaining_path: &[QualifiedName]) -> Variant {
        if attribute_id != AttributeId::Value {
            return Variant::Empty;
        }
        let value = self.field(remaining_path);
        match index_range {
            NumericRange::None => value,
            range => value.range_of_owned(range).unwrap_or(Variant::Empty),
        }
    }
}

impl Event for TransitionEvent {
    fn get_field(&self, type_definition_id: &NodeId, attribute_id: AttributeId, index_range: &NumericRange, browse_path: &[QualifiedName]) -> Variant {
        if *type_definition_id != ObjectTypeId::BaseEventType && !self.chain.contains(type_definition_id) {
            return Variant::Empty;
        }
        self.get_value(attribute_id, index_range, browse_path)
    }

    fn time(&self) -> &DateTime {
        &self.time
    }

    fn event_type_id(&self) -> &NodeId {
        &self.event_type
    }
}

fn ua_path(names: &[&str]) -> Vec<QualifiedName> {
    names.iter().map(|n| QualifiedName::new(0, *n)).collect()
}

/// The part of a driver that knows the instance: its variables, the table's NodeIds on this server, and
/// how to take a transition (write the variables, raise the event). It holds no state of its own.
struct Core {
    table: &'static StateTable,
    manager: ModelManager,
    node: NodeId,
    name: String,
    states: Vec<NodeId>,
    transitions: Vec<NodeId>,
    vars: Variables,
    event: Option<EventSetup>,
}

impl Core {
    fn new(table: &'static StateTable, instance: &ObjectNode) -> Result<Core, ProgramError> {
        let manager = instance.manager().clone();
        let node = instance.id().clone();
        let resolve = |id: NsNodeId| manager.resolve(id).ok_or(ProgramError::UnknownNamespace(id.namespace_uri));
        let states = table.states.iter().map(|s| resolve(s.node)).collect::<Result<Vec<_>, _>>()?;
        let transitions = table.transitions.iter().map(|t| resolve(t.node)).collect::<Result<Vec<_>, _>>()?;
        let (name, vars) = manager.bind_with(|b| {
            let name = b.browse_name(&node).map(|q| q.name.as_ref().to_owned()).unwrap_or_default();
            Ok((name, variables(b, &node)?))
        })?;
        let event = match table.event_type {
            Some(id) => Some(event_setup(&manager, resolve(id)?, &name)),
            None => None,
        };
        // The instance is the source of its transition events, so clients may monitor it for them.
        if let Err(status) = manager.set_event_notifier(&node, EventNotifier::SUBSCRIBE_TO_EVENTS) {
            warn!("cannot make {node} an event notifier: {status}");
        }
        let core = Core { table, manager, node, name, states, transitions, vars, event };
        if core.vars.available_states.is_some() {
            core.set(&core.vars.available_states, core.states.clone());
        }
        Ok(core)
    }

    fn set(&self, node: &Option<NodeId>, value: impl Into<Variant>) {
        if let Some(node) = node {
            if let Err(status) = self.manager.set_value(node, value) {
                warn!("cannot set {node} of state machine {}: {status}", self.node);
            }
        }
    }

    /// Shows `state` in CurrentState (and the transitions that leave it in AvailableTransitions, where the
    /// instance has it), without a transition (when serving starts).
    fn show_state(&self, state: usize) {
        let row = &self.table.states[state];
        if self.vars.available_transitions.is_some() {
            let leaving: Vec<NodeId> = (self.table.transitions.iter().zip(&self.transitions))
                .filter(|(t, _)| t.from == state)
                .map(|(_, id)| id.clone())
                .collect();
            self.set(&self.vars.available_transitions, leaving);
        }
        let text = LocalizedText::from(row.display_name);
        self.set(&self.vars.current_state, text.clone());
        self.set(&self.vars.current_state_id, self.states[state].clone());
        if let Some(n) = row.number {
            self.set(&self.vars.current_state_number, n);
        }
        self.set(&self.vars.current_state_effective, text);
    }

    /// Takes transition `t`: updates the variables and raises the event. The caller holds the driver's lock.
    fn take(&self, t: usize, severity: u16) {
        let row = &self.table.transitions[t];
        let (from, to) = (&self.table.states[row.from], &self.table.states[row.to]);
        let now = DateTime::now();
        self.show_state(row.to);
        let text = LocalizedText::from(row.display_name);
        self.set(&self.vars.last_transition, text.clone());
        self.set(&self.vars.last_transition_id, self.transitions[t].clone());
        if let Some(n) = row.number {
            self.set(&self.vars.last_transition_number, n);
        }
        self.set(&self.vars.last_transition_time, now);
        self.set(&self.vars.last_transition_effective, now);
        self.set(&self.vars.diagnostic_transition_time, now);
        let Some(setup) = &self.event else { return };
        let mut fields: Vec<(Vec<QualifiedName>, Variant)> = vec![
            (ua_path(&["EventId"]), ByteString::from(Guid::new().to_bytes().to_vec()).into()),
            (ua_path(&["EventType"]), setup.event_type.clone().into()),
            (ua_path(&["SourceNode"]), self.node.clone().into()),
            (ua_path(&["SourceName"]), self.name.as_str().into()),
            (ua_path(&["Time"]), now.into()),
            (ua_path(&["ReceiveTime"]), now.into()),
            (ua_path(&["Message"]), LocalizedText::from(format!("{}: {} to {}", self.name, from.display_name, to.display_name).as_str()).into()),
            (ua_path(&["Severity"]), severity.into()),
            (ua_path(&["Transition"]), text.into()),
            (ua_path(&["Transition", "Id"]), self.transitions[t].clone().into()),
            (ua_path(&["Transition", "TransitionTime"]), now.into()),
            (ua_path(&["FromState"]), LocalizedText::from(from.display_name).into()),
            (ua_path(&["FromState", "Id"]), self.states[row.from].clone().into()),
            (ua_path(&["ToState"]), LocalizedText::from(to.display_name).into()),
            (ua_path(&["ToState", "Id"]), self.states[row.to].clone().into()),
        ];
        for (path, number) in [("Transition", row.number), ("FromState", from.number), ("ToState", to.number)] {
            if let Some(n) = number {
                fields.push((ua_path(&[path, "Number"]), n.into()));
            }
        }
        fields.extend(setup.extra.iter().cloned());
        // The chain again: the one of `setup` may have been taken before ns0's types were loaded.
        let chain = supertypes(&self.manager, &setup.event_type);
        let event = TransitionEvent { event_type: setup.event_type.clone(), chain, time: now, fields };
        // async-opcua reports an event of any node to the clients that monitor the Server object, too.
        self.manager.notify_event(&event, std::slice::from_ref(&self.node));
    }

    /// Records a method call in ProgramDiagnostic, where the instance has it.
    fn diagnose_call(&self, method: &str, status: StatusCode) {
        self.set(&self.vars.diagnostic_method_call, method);
        self.set(&self.vars.diagnostic_method_call_time, DateTime::now());
        self.set(&self.vars.diagnostic_method_status, status);
    }

    /// The instance's method nodes of the table's causes, by name.
    fn cause_methods(&self) -> Result<Vec<(&'static str, NodeId)>, ProgramError> {
        let node = self.node.clone();
        let causes = self.table.causes();
        Ok(self.manager.bind_with(|b| {
            let mut out = Vec::new();
            for (uri, name) in &causes {
                if let Some(m) = b.find_child(&node, uri, name)? {
                    out.push((*name, m));
                }
            }
            Ok(out)
        })?)
    }
}

/// Finds the variables a transition updates.
fn variables(b: &Binder<'_>, node: &NodeId) -> Result<Variables, BindError> {
    let child = |parent: &Option<NodeId>, name: &str| -> Result<Option<NodeId>, BindError> {
        match parent {
            Some(p) => b.find_child(p, UA, name),
            None => Ok(None),
        }
    };
    let this = Some(node.clone());
    let current_state = child(&this, "CurrentState")?;
    let last_transition = child(&this, "LastTransition")?;
    let diagnostic = child(&this, "ProgramDiagnostic")?;
    Ok(Variables {
        current_state_id: child(&current_state, "Id")?,
        current_state_number: child(&current_state, "Number")?,
        current_state_effective: child(&current_state, "EffectiveDisplayName")?,
        last_transition_id: child(&last_transition, "Id")?,
        last_transition_number: child(&last_transition, "Number")?,
        last_transition_time: child(&last_transition, "TransitionTime")?,
        last_transition_effective: child(&last_transition, "EffectiveTransitionTime")?,
        available_states: child(&this, "AvailableStates")?,
        available_transitions: child(&this, "AvailableTransitions")?,
        diagnostic_transition_time: child(&diagnostic, "LastTransitionTime")?,
        diagnostic_method_call: child(&diagnostic, "LastMethodCall")?,
        diagnostic_method_call_time: child(&diagnostic, "LastMethodCallTime")?,
        diagnostic_method_status: child(&diagnostic, "LastMethodReturnStatus")?,
        recycle_count: child(&this, "RecycleCount")?,
        current_state,
        last_transition,
    })
}

/// The event type's chain of supertypes, and the fields our own event types add.
fn event_setup(manager: &ModelManager, event_type: NodeId, instance_name: &str) -> EventSetup {
    let chain = supertypes(manager, &event_type);
    let mut extra = Vec::new();
    // CommonSkills' SkillTransitionEventType names the skill (its BrowseName) in `SkillName`.
    let skills = SKILL_TRANSITION_EVENT_TYPE;
    if let (Some(skill_event), Some(ns)) = (manager.resolve(skills), manager.namespace_index(skills.namespace_uri)) {
        if chain.contains(&skill_event) {
            extra.push((vec![QualifiedName::new(ns, "SkillName")], Variant::from(instance_name)));
        }
    }
    EventSetup { event_type, extra }
}

/// `event_type` and its supertypes, as far as the server's type tree knows them now. Before the server runs
/// the tree holds only the tables' types (async-opcua loads ns0's when it starts), so the chain of a skill's
/// event type ends at ns0's ProgramTransitionEventType then, and is taken again for every event.
fn supertypes(manager: &ModelManager, event_type: &NodeId) -> Vec<NodeId> {
    let mut chain = vec![event_type.clone()];
    let tree = manager.type_tree().read();
    while let Some(parent) = chain.last().and_then(|c| tree.get_supertype(c)) {
        if chain.contains(parent) {
            break;
        }
        chain.push(parent.clone());
    }
    chain
}

/// CommonSkills' `SkillTransitionEventType` (nodesets/CommonSkills.NodeSet2.xml, i=1100). Named here rather
/// than taken from the generated `models::common_skills`, so that the runtime builds without the generated
/// models (a build script's output uses it on its own); the test
/// `skill_transition_event_type_matches_the_generated_id` keeps the two equal.
pub const SKILL_TRANSITION_EVENT_TYPE: NsNodeId =
    NsNodeId::numeric("http://nodeset-compiler.dev/CommonSkills/", 1100);

/// The states of a program (Part 10), which the driver treats specially.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ProgramState {
    /// Ready to start (StateNumber 12).
    Ready,
    /// Running (13).
    Running,
    /// Suspended, to be resumed (14).
    Suspended,
    /// Halted: ended in error or stopped; Reset makes it Ready (11).
    Halted,
}

impl ProgramState {
    const ALL: [ProgramState; 4] = [ProgramState::Ready, ProgramState::Running, ProgramState::Suspended, ProgramState::Halted];

    /// The BrowseName of the state in ProgramStateMachineType.
    pub fn name(self) -> &'static str {
        match self {
            ProgramState::Ready => "Ready",
            ProgramState::Running => "Running",
            ProgramState::Suspended => "Suspended",
            ProgramState::Halted => "Halted",
        }
    }

    /// Whether a body runs (or is parked) in this state.
    fn active(self) -> bool {
        matches!(self, ProgramState::Running | ProgramState::Suspended)
    }
}

/// What the body of one run receives besides its inputs: the state (to park while suspended) and the
/// instance.
///
/// A Halt (or Reset) drops the body at its next `.await`; a Suspend takes effect at its next
/// [`Control::checkpoint`]. A body that never awaits a checkpoint cannot be suspended: its Suspend is
/// accepted (the state is Suspended) and the run ends in Ready through SuspendedToReady when it returns.
#[derive(Clone)]
pub struct Control {
    program: Program,
    rx: watch::Receiver<ProgramState>,
    arguments: Arc<[Variant]>,
}

impl Control {
    /// Waits while the program is Suspended; returns at once while it is Running.
    pub async fn checkpoint(&self) {
        let mut rx = self.rx.clone();
        // An error means the program is gone, and with it this run.
        let _ = rx.wait_for(|s| *s != ProgramState::Suspended).await;
    }

    /// The program's state now.
    pub fn state(&self) -> ProgramState {
        *self.rx.borrow()
    }

    /// A receiver that sees every state the program enters.
    pub fn watch(&self) -> watch::Receiver<ProgramState> {
        self.rx.clone()
    }

    /// Suspends the program from its own body (a composite skill whose basic skill paused or cannot be
    /// reached): the transition a Suspend call takes; `BadInvalidState` if there is none from the current
    /// state. The body parks at its next checkpoint until a client resumes the program.
    pub fn suspend(&self) -> Result<(), StatusCode> {
        self.program.call("Suspend")
    }

    /// Whether a Suspend waits for the body's next checkpoint.
    pub fn suspend_requested(&self) -> bool {
        self.state() == ProgramState::Suspended
    }

    /// The input arguments Start was called with (empty unless the type's Start declares InputArguments).
    pub fn start_arguments(&self) -> &[Variant] {
        &self.arguments
    }

    /// The program instance.
    pub fn node(&self) -> &NodeId {
        &self.program.inner.core.node
    }

    /// The manager of the server the program runs in.
    pub fn manager(&self) -> &ModelManager {
        &self.program.inner.core.manager
    }
}

type RunFuture = Pin<Box<dyn Future<Output = Result<Vec<Option<Variant>>, StatusCode>> + Send>>;
/// The typed body behind one type-erased function: inputs in, a run out (or why the inputs are bad).
type Starter = Box<dyn Fn(Vec<Option<Variant>>, Control) -> Result<RunFuture, StatusCode> + Send + Sync>;

/// The variables of one parameter set on the instance.
#[derive(Clone, Debug, Default)]
struct ParameterNodes {
    vars: Vec<Option<NodeId>>,
    outcome: Option<NodeId>,
}

fn parameter_nodes<P: Parameters>(b: &Binder<'_>, node: &NodeId) -> Result<ParameterNodes, BindError> {
    let Some((uri, name)) = P::SET else { return Ok(ParameterNodes::default()) };
    let Some(set) = b.find_child(node, uri, name)? else {
        return Err(BindError::MissingChild { parent: node.clone(), browse_name: name.to_owned() });
    };
    let vars = P::NAMES.iter().map(|(uri, name)| b.find_child(&set, uri, name)).collect::<Result<Vec<_>, _>>()?;
    let outcome = match P::OUTCOME {
        Some((uri, name)) => b.find_child(&set, uri, name)?,
        None => None,
    };
    Ok(ParameterNodes { vars, outcome })
}

struct ProgramStatus {
    current: usize,
    /// Counts runs; a run that ends after a Halt or Reset ended it finds a newer number and does nothing.
    run: u64,
    task: Option<tokio::task::AbortHandle>,
    recycle_count: i32,
}

struct ProgramInner {
    core: Core,
    /// Table indices of Ready, Running, Suspended, Halted.
    kinds: [usize; 4],
    inputs: ParameterNodes,
    outputs: ParameterNodes,
    starter: Starter,
    status: Mutex<ProgramStatus>,
    tx: watch::Sender<ProgramState>,
}

/// A served program instance (cheap to clone): its state, and the server's own way to take transitions.
#[derive(Clone)]
pub struct Program {
    inner: Arc<ProgramInner>,
}

impl std::fmt::Debug for Program {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Program({}, {:?})", self.inner.core.node, self.state())
    }
}

impl Program {
    /// Serves the program instance `program` is bound to: implements its cause methods, shows Ready in
    /// CurrentState, and runs `body` on every Start with the typed inputs read from `InputParameterSet`.
    /// `Ok(outputs)` ends the run in Ready (outputs written, outcome Good), `Err(status)` in Halted
    /// (outcome `status`). Serving an instance again replaces the earlier body.
    pub fn serve<P, F, Fut>(program: &P, body: F) -> Result<Program, ProgramError>
    where
        P: ProgramType,
        F: Fn(P::Inputs, Control) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = Result<P::Outputs, StatusCode>> + Send + 'static,
    {
        let body = Arc::new(body);
        let starter: Starter = Box::new(move |values, control| {
            let inputs = P::Inputs::from_values(&values).map_err(|(_, status)| status)?;
            let run = body(inputs, control);
            Ok(Box::pin(async move { run.await.map(P::Outputs::into_values) }))
        });
        let instance = program.state_machine_node();
        let node = instance.id().clone();
        let (inputs, outputs) = instance
            .manager()
            .bind_with(|b| Ok((parameter_nodes::<P::Inputs>(b, &node)?, parameter_nodes::<P::Outputs>(b, &node)?)))?;
        Program::serve_table(&P::TABLE, instance, inputs, outputs, starter)
    }

    fn serve_table(
        table: &'static StateTable,
        instance: &ObjectNode,
        inputs: ParameterNodes,
        outputs: ParameterNodes,
        starter: Starter,
    ) -> Result<Program, ProgramError> {
        let mut kinds = [0; 4];
        for (k, state) in kinds.iter_mut().zip(ProgramState::ALL) {
            *k = table.state(state.name()).ok_or(ProgramError::MissingState(state.name()))?;
        }
        let core = Core::new(table, instance)?;
        let ready = kinds[0];
        core.show_state(ready);
        core.set(&core.vars.recycle_count, 0i32);
        let (tx, _) = watch::channel(ProgramState::Ready);
        let inner = Arc::new(ProgramInner {
            core,
            kinds,
            inputs,
            outputs,
            starter,
            status: Mutex::new(ProgramStatus { current: ready, run: 0, task: None, recycle_count: 0 }),
            tx,
        });
        set_program_properties(&inner.core);
        let program = Program { inner };
        for (name, method) in program.inner.core.cause_methods()? {
            // The method handlers keep the program: it is served as long as the server holds them (serving
            // the instance again replaces them), whether or not the caller keeps the returned handle.
            let handler = program.clone();
            program.inner.core.manager.on_call(&method, move |call: MethodInvocation| {
                let program = handler.clone();
                async move {
                    let result = program.call_with(name, call.arguments);
                    program.inner.core.diagnose_call(name, result.err().unwrap_or(StatusCode::Good));
                    result.map(|()| Vec::new()).map_err(MethodError::Status)
                }
            });
        }
        Ok(program)
    }

    /// The state now.
    pub fn state(&self) -> ProgramState {
        *self.inner.tx.borrow()
    }

    /// A receiver that sees every state the program enters.
    pub fn watch(&self) -> watch::Receiver<ProgramState> {
        self.inner.tx.subscribe()
    }

    /// The program instance.
    pub fn node(&self) -> &NodeId {
        &self.inner.core.node
    }

    /// Does what a client's call of the cause method `method` (`Start`, `Halt`, ...) does, from the server.
    pub fn call(&self, method: &str) -> Result<(), StatusCode> {
        self.call_with(method, Vec::new())
    }

    /// Halts the program from the server (an emergency stop, a failed device) with `cause` as the outcome:
    /// from Ready, Running or Suspended, along the table's transition to Halted; `BadInvalidState` from
    /// Halted.
    pub fn halt(&self, cause: StatusCode) -> Result<(), StatusCode> {
        let mut st = self.lock();
        let halted = self.inner.kinds[3];
        let t = self.inner.core.table.between(st.current, halted).ok_or(StatusCode::BadInvalidState)?;
        self.end_run(&mut st);
        self.inner.core.set(&self.inner.outputs.outcome, cause);
        self.take(&mut st, t, 500);
        Ok(())
    }

    fn lock(&self) -> MutexGuard<'_, ProgramStatus> {
        // A poisoned lock means a panic elsewhere; the status itself is always consistent.
        self.inner.status.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn kind(&self, state: usize) -> Option<ProgramState> {
        self.inner.kinds.iter().position(|&k| k == state).map(|i| ProgramState::ALL[i])
    }

    fn take(&self, st: &mut ProgramStatus, t: usize, severity: u16) {
        self.inner.core.take(t, severity);
        st.current = self.inner.core.table.transitions[t].to;
        if let Some(kind) = self.kind(st.current) {
            self.inner.tx.send_replace(kind);
        }
    }

    /// Stops the body of the current run, if any (it is dropped at its next `.await`).
    fn end_run(&self, st: &mut ProgramStatus) {
        st.run += 1;
        if let Some(task) = st.task.take() {
            task.abort();
        }
    }

    fn call_with(&self, method: &str, arguments: Vec<Variant>) -> Result<(), StatusCode> {
        let mut st = self.lock();
        let table = self.inner.core.table;
        let t = table.caused_by(st.current, method).ok_or(StatusCode::BadInvalidState)?;
        let row = &table.transitions[t];
        let (from, to) = (self.kind(row.from), self.kind(row.to));
        let starts = to == Some(ProgramState::Running) && !from.is_some_and(ProgramState::active);
        let ends = from.is_some_and(ProgramState::active) && !to.is_some_and(ProgramState::active);
        let run = if starts { Some(self.start(&mut st, arguments)?) } else { None };
        if ends {
            self.end_run(&mut st);
        }
        if ends || to == Some(ProgramState::Halted) {
            self.inner.core.set(&self.inner.outputs.outcome, StatusCode::BadRequestCancelledByClient);
        }
        if to == Some(ProgramState::Ready) && from != Some(ProgramState::Running) {
            // Part 10: RecycleCount counts the resets of the program.
            st.recycle_count = st.recycle_count.saturating_add(1);
            self.inner.core.set(&self.inner.core.vars.recycle_count, st.recycle_count);
        }
        self.take(&mut st, t, 100);
        // The body runs once the transition to Running is taken: nothing it does (such as starting the
        // skills of other servers) can come before the program's own Running.
        if let Some(run) = run {
            st.task = Some(tokio::spawn(run).abort_handle());
        }
        Ok(())
    }

    /// Reads the inputs and prepares the body of a new run (before the transition to Running is taken, so
    /// bad inputs leave the state as it is); the caller spawns it after the transition.
    fn start(&self, st: &mut ProgramStatus, arguments: Vec<Variant>) -> Result<Pin<Box<dyn Future<Output = ()> + Send>>, StatusCode> {
        let values: Vec<Option<Variant>> = self
            .inner
            .inputs
            .vars
            .iter()
            .map(|v| v.as_ref().and_then(|v| self.inner.core.manager.value(v)).and_then(|d| d.value))
            .collect();
        st.run += 1;
        let run = st.run;
        let control = Control { program: self.clone(), rx: self.inner.tx.subscribe(), arguments: arguments.into() };
        let future = (self.inner.starter)(values, control)?;
        let weak = Arc::downgrade(&self.inner);
        Ok(Box::pin(async move {
            let result = future.await;
            if let Some(inner) = weak.upgrade() {
                Program { inner }.finish(run, result);
            }
        }))
    }

    /// Ends run `run` as its body returned: in Ready with the outputs, or in Halted with the error.
    fn finish(&self, run: u64, result: Result<Vec<Option<Variant>>, StatusCode>) {
        let mut st = self.lock();
        if st.run != run {
            return;
        }
        st.task = None;
        let (ready, halted) = (self.inner.kinds[0], self.inner.kinds[3]);
        let (target, outcome, severity) = match &result {
            Ok(_) => (ready, StatusCode::Good, 100),
            Err(status) => (halted, *status, 500),
        };
        let Some(t) = self.inner.core.table.between(st.current, target) else {
            warn!(
                "program {}: the run ended in state {}, which has no transition to {}",
                self.inner.core.node, self.inner.core.table.states[st.current].name, self.inner.core.table.states[target].name
            );
            return;
        };
        if let Ok(values) = result {
            for (node, value) in self.inner.outputs.vars.iter().zip(values) {
                if let (Some(node), Some(value)) = (node, value) {
                    self.inner.core.set(&Some(node.clone()), value);
                }
            }
        }
        self.inner.core.set(&self.inner.outputs.outcome, outcome);
        st.run += 1;
        self.take(&mut st, t, severity);
    }
}

/// Sets the properties of ProgramStateMachineType the instance has: its invocations are neither created
/// nor deleted by clients, and it is not deleted when it ends.
fn set_program_properties(core: &Core) {
    let node = core.node.clone();
    let found = core.manager.bind_with(|b| {
        Ok(["Creatable", "Deletable", "AutoDelete"].map(|name| b.find_child(&node, UA, name).ok().flatten()))
    });
    if let Ok([creatable, deletable, auto_delete]) = found {
        core.set(&creatable, false);
        core.set(&deletable, false);
        core.set(&auto_delete, false);
    }
}

/// A served state machine that is not a program: client calls of its cause methods take their
/// transitions, and the server takes others with [`Machine::transition`].
#[derive(Clone)]
pub struct Machine {
    inner: Arc<MachineInner>,
}

struct MachineInner {
    core: Core,
    current: Mutex<usize>,
}

impl Machine {
    /// Serves the state machine instance `machine` is bound to, starting in the table's initial state
    /// (`NoInitialState` if it has none).
    pub fn serve<M: StateMachine>(machine: &M) -> Result<Machine, ProgramError> {
        let initial = M::TABLE.states.iter().position(|s| s.initial).ok_or(ProgramError::NoInitialState)?;
        Machine::serve_table(&M::TABLE, machine.state_machine_node(), initial)
    }

    /// Serves the state machine instance `machine` is bound to, starting in the state with BrowseName
    /// `state` (for machines whose nodeset marks no initial state).
    pub fn serve_from<M: StateMachine>(machine: &M, state: &str) -> Result<Machine, ProgramError> {
        let initial = M::TABLE.state(state).ok_or_else(|| ProgramError::UnknownState(state.to_owned()))?;
        Machine::serve_table(&M::TABLE, machine.state_machine_node(), initial)
    }

    /// Serves the state machine instance `instance` by a table built at run time rather than generated
    /// (`nodeset-compiler serve` builds one per state machine type of the model), starting in the table's
    /// initial state (`NoInitialState` if it has none).
    pub fn serve_by_table(table: &'static StateTable, instance: &ObjectNode) -> Result<Machine, ProgramError> {
        let initial = table.states.iter().position(|s| s.initial).ok_or(ProgramError::NoInitialState)?;
        Machine::serve_table(table, instance, initial)
    }

    fn serve_table(table: &'static StateTable, instance: &ObjectNode, initial: usize) -> Result<Machine, ProgramError> {
        let core = Core::new(table, instance)?;
        core.show_state(initial);
        let inner = Arc::new(MachineInner { core, current: Mutex::new(initial) });
        let out = Machine { inner };
        for (name, method) in out.inner.core.cause_methods()? {
            let handler = out.clone();
            out.inner.core.manager.on_call(&method, move |_: MethodInvocation| {
                let machine = handler.clone();
                async move { machine.call(name).map(|()| Vec::new()).map_err(MethodError::Status) }
            });
        }
        Ok(out)
    }

    fn lock(&self) -> MutexGuard<'_, usize> {
        self.inner.current.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The BrowseName of the current state.
    pub fn state(&self) -> &'static str {
        self.inner.core.table.states[*self.lock()].name
    }

    /// Takes the transition a call of `method` causes now (`BadInvalidState` if none does).
    pub fn call(&self, method: &str) -> Result<(), StatusCode> {
        let mut current = self.lock();
        let t = self.inner.core.table.caused_by(*current, method).ok_or(StatusCode::BadInvalidState)?;
        self.inner.core.take(t, 100);
        *current = self.inner.core.table.transitions[t].to;
        Ok(())
    }

    /// Takes the table's transition from the current state to state `to` (by BrowseName);
    /// `BadInvalidState` if there is none.
    pub fn transition(&self, to: &str) -> Result<(), StatusCode> {
        let mut current = self.lock();
        let table = self.inner.core.table;
        let target = table.state(to).ok_or(StatusCode::BadInvalidState)?;
        let t = table.between(*current, target).ok_or(StatusCode::BadInvalidState)?;
        self.inner.core.take(t, 100);
        *current = target;
        Ok(())
    }
}

/// Implements [`ProgramType`] for a generated handle, with an inherent `serve`.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_program_type {
    ($t:ident, $inputs:ty, $outputs:ty) => {
        impl $crate::typed::ProgramType for $t {
            type Inputs = $inputs;
            type Outputs = $outputs;
        }
        impl $t {
            /// Serves the program this handle is bound to: every Start runs `body` with the inputs read
            /// from `InputParameterSet`; `Ok(outputs)` ends the run in Ready, `Err(status)` in Halted (see
            /// `runtime::typed::program`).
            pub fn serve<F, Fut>(
                &self,
                body: F,
            ) -> ::std::result::Result<$crate::typed::Program, $crate::typed::ProgramError>
            where
                F: Fn($inputs, $crate::typed::Control) -> Fut + Send + Sync + 'static,
                Fut: ::std::future::Future<Output = ::std::result::Result<$outputs, opcua::types::StatusCode>>
                    + Send
                    + 'static,
            {
                $crate::typed::Program::serve(self, body)
            }
        }
    };
}

/// Implements [`Parameters`] for a generated parameter struct: the set's BrowseName (index into `NS`,
/// name), optionally the outcome variable, and per field its BrowseName.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_parameters {
    ($t:ident; set: $sk:literal $set:literal; outcome: $ok:literal $oname:literal; fields: [$($f:ident: $k:literal $name:literal),* $(,)?]) => {
        $crate::__nodeset_parameters!(@impl $t; $sk $set; Some((NS[$ok], $oname)); $($f $k $name)*);
    };
    ($t:ident; set: $sk:literal $set:literal; fields: [$($f:ident: $k:literal $name:literal),* $(,)?]) => {
        $crate::__nodeset_parameters!(@impl $t; $sk $set; None; $($f $k $name)*);
    };
    (@impl $t:ident; $sk:literal $set:literal; $outcome:expr; $($f:ident $k:literal $name:literal)*) => {
        impl $crate::typed::Parameters for $t {
            const SET: Option<(&'static str, &'static str)> = Some((NS[$sk], $set));
            const NAMES: &'static [(&'static str, &'static str)] = &[$((NS[$k], $name)),*];
            const OUTCOME: Option<(&'static str, &'static str)> = $outcome;
            #[allow(unused_variables, unused_mut, unused_assignments)]
            fn from_values(
                values: &[Option<opcua::types::Variant>],
            ) -> Result<Self, (usize, opcua::types::StatusCode)> {
                let mut at = 0usize;
                Ok(Self {
                    $($f: {
                        let value = $crate::typed::ParameterValue::from_value(
                            values.get(at).and_then(|v| v.as_ref()),
                        )
                        .map_err(|status| (at, status))?;
                        at += 1;
                        value
                    }),*
                })
            }
            fn into_values(self) -> Vec<Option<opcua::types::Variant>> {
                vec![$($crate::typed::ParameterValue::to_value(&self.$f)),*]
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    const NS: &str = "http://opcfoundation.org/UA/";

    /// ProgramStateMachineType's table as ns0 1.05.07 declares it.
    const PROGRAM: StateTable = StateTable {
        states: &[
            StateRow { name: "Halted", display_name: "Halted", number: Some(11), node: NsNodeId::numeric(NS, 2406), initial: false },
            StateRow { name: "Ready", display_name: "Ready", number: Some(12), node: NsNodeId::numeric(NS, 2400), initial: false },
            StateRow { name: "Running", display_name: "Running", number: Some(13), node: NsNodeId::numeric(NS, 2402), initial: false },
            StateRow { name: "Suspended", display_name: "Suspended", number: Some(14), node: NsNodeId::numeric(NS, 2404), initial: false },
        ],
        transitions: &[
            TransitionRow { name: "HaltedToReady", display_name: "HaltedToReady", number: Some(1), node: NsNodeId::numeric(NS, 2408), from: 0, to: 1, causes: &[(NS, "Reset")] },
            TransitionRow { name: "ReadyToRunning", display_name: "ReadyToRunning", number: Some(2), node: NsNodeId::numeric(NS, 2410), from: 1, to: 2, causes: &[(NS, "Start")] },
            TransitionRow { name: "RunningToHalted", display_name: "RunningToHalted", number: Some(3), node: NsNodeId::numeric(NS, 2412), from: 2, to: 0, causes: &[(NS, "Halt")] },
            TransitionRow { name: "RunningToReady", display_name: "RunningToReady", number: Some(4), node: NsNodeId::numeric(NS, 2414), from: 2, to: 1, causes: &[] },
            TransitionRow { name: "RunningToSuspended", display_name: "RunningToSuspended", number: Some(5), node: NsNodeId::numeric(NS, 2416), from: 2, to: 3, causes: &[(NS, "Suspend")] },
            TransitionRow { name: "SuspendedToRunning", display_name: "SuspendedToRunning", number: Some(6), node: NsNodeId::numeric(NS, 2418), from: 3, to: 2, causes: &[(NS, "Resume")] },
            TransitionRow { name: "SuspendedToHalted", display_name: "SuspendedToHalted", number: Some(7), node: NsNodeId::numeric(NS, 2420), from: 3, to: 0, causes: &[(NS, "Halt"), (NS, "Reset")] },
            TransitionRow { name: "SuspendedToReady", display_name: "SuspendedToReady", number: Some(8), node: NsNodeId::numeric(NS, 2422), from: 3, to: 1, causes: &[(NS, "Reset")] },
            TransitionRow { name: "ReadyToHalted", display_name: "ReadyToHalted", number: Some(9), node: NsNodeId::numeric(NS, 2424), from: 1, to: 0, causes: &[(NS, "Halt")] },
        ],
        event_type: None,
    };

    fn caused(state: &str, method: &str) -> Option<&'static str> {
        PROGRAM.caused_by(PROGRAM.state(state)?, method).map(|t| PROGRAM.transitions[t].name)
    }

    #[test]
    fn each_method_is_valid_only_where_a_transition_starts() {
        let cases = [
            ("Ready", "Start", Some("ReadyToRunning")),
            ("Ready", "Halt", Some("ReadyToHalted")),
            ("Ready", "Suspend", None),
            ("Ready", "Resume", None),
            ("Ready", "Reset", None),
            ("Running", "Start", None),
            ("Running", "Suspend", Some("RunningToSuspended")),
            ("Running", "Halt", Some("RunningToHalted")),
            ("Running", "Resume", None),
            ("Running", "Reset", None),
            ("Suspended", "Resume", Some("SuspendedToRunning")),
            ("Suspended", "Halt", Some("SuspendedToHalted")),
            ("Suspended", "Start", None),
            ("Suspended", "Suspend", None),
            ("Halted", "Reset", Some("HaltedToReady")),
            ("Halted", "Start", None),
            ("Halted", "Halt", None),
            ("Halted", "Suspend", None),
            ("Halted", "Resume", None),
        ];
        for (state, method, want) in cases {
            assert_eq!(caused(state, method), want, "{method} in {state}");
        }
    }

    #[test]
    fn of_two_transitions_a_method_causes_the_one_with_fewer_causes() {
        // SuspendedToHalted names Halt and Reset, SuspendedToReady only Reset.
        assert_eq!(caused("Suspended", "Reset"), Some("SuspendedToReady"));
        // The rule does not depend on the order of the rows.
        let mut rows = PROGRAM.transitions.to_vec();
        rows.reverse();
        let reversed = StateTable { transitions: Box::leak(rows.into_boxed_slice()), ..PROGRAM };
        let t = reversed.caused_by(3, "Reset").map(|t| reversed.transitions[t].name);
        assert_eq!(t, Some("SuspendedToReady"));
    }

    #[test]
    fn internal_transitions_are_found_by_their_states() {
        let t = |from: &str, to: &str| {
            PROGRAM.between(PROGRAM.state(from).unwrap(), PROGRAM.state(to).unwrap()).map(|t| PROGRAM.transitions[t].number)
        };
        assert_eq!(t("Running", "Ready"), Some(Some(4)));
        assert_eq!(t("Running", "Halted"), Some(Some(3)));
        assert_eq!(t("Suspended", "Ready"), Some(Some(8)));
        assert_eq!(t("Ready", "Suspended"), None);
        assert_eq!(PROGRAM.causes(), [(NS, "Halt"), (NS, "Reset"), (NS, "Resume"), (NS, "Start"), (NS, "Suspend")]);
    }

    #[test]
    fn parameter_values_are_checked() {
        assert_eq!(f64::from_value(Some(&Variant::Double(1.5))), Ok(1.5));
        assert_eq!(f64::from_value(Some(&Variant::Empty)), Err(StatusCode::BadArgumentsMissing));
        assert_eq!(f64::from_value(None), Err(StatusCode::BadArgumentsMissing));
        assert_eq!(f64::from_value(Some(&Variant::from("fast"))), Err(StatusCode::BadTypeMismatch));
        assert_eq!(Option::<f64>::from_value(None), Ok(None));
        assert_eq!(Option::<f64>::from_value(Some(&Variant::Int32(3))), Err(StatusCode::BadTypeMismatch));
        assert_eq!(Some(2.0f64).to_value(), Some(Variant::Double(2.0)));
        assert_eq!(Option::<f64>::None.to_value(), None);
    }

    #[test]
    fn transition_events_answer_select_clauses_by_browse_path() {
        let event_type = NodeId::new(2, 1100);
        let event = TransitionEvent {
            event_type: event_type.clone(),
            chain: vec![event_type.clone(), ObjectTypeId::ProgramTransitionEventType.into(), ObjectTypeId::TransitionEventType.into()],
            time: DateTime::now(),
            fields: vec![(ua_path(&["Transition", "Number"]), Variant::UInt32(2)), (vec![QualifiedName::new(2, "SkillName")], "Move".into())],
        };
        let number = ua_path(&["Transition", "Number"]);
        let get = |ty: NodeId, path: &[QualifiedName]| event.get_field(&ty, AttributeId::Value, &NumericRange::None, path);
        assert_eq!(get(ObjectTypeId::BaseEventType.into(), &number), Variant::UInt32(2));
        assert_eq!(get(ObjectTypeId::TransitionEventType.into(), &number), Variant::UInt32(2));
        assert_eq!(get(ObjectTypeId::ConditionType.into(), &number), Variant::Empty);
        assert_eq!(get(event_type, &[QualifiedName::new(2, "SkillName")]), Variant::from("Move"));
        assert_eq!(event.get_field(&ObjectTypeId::BaseEventType.into(), AttributeId::NodeId, &NumericRange::None, &number), Variant::Empty);
    }
}
