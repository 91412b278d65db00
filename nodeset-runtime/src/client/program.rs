//! State machines and programs on a remote server, through the generated state tables: the current state
//! as a row of the table, [`RemoteMachine::wait_for_state`], the methods that cause transitions, and for a
//! program type (every skill) a run with its typed inputs awaited to its typed outputs.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use opcua::client::Session;
use opcua::types::{AttributeId, DataValue, NodeId, StatusCode, Variant, WriteValue};
use tokio::sync::watch;

use super::{call, read_values, service, translate, ClientError, Remote, Subscription};
use crate::remote::{RemoteError, RemoteServer};
use crate::typed::{Control, Parameters, ProgramState, ProgramType, StateMachine, StateRow};

/// The ns0 namespace URI (CurrentState, the program methods).
const UA: &str = "http://opcfoundation.org/UA/";

/// What the CurrentState subscription has seen: how many notifications, and the last state (an index into
/// the table; `None` for a value the table does not know).
type Seen = (u64, Option<usize>);

/// A state machine instance on a remote server, bound as the generated handle `M`, its CurrentState
/// followed by a subscription.
pub struct RemoteMachine<M> {
    remote: Remote<M>,
    current_state: NodeId,
    seen: watch::Receiver<Seen>,
    _subscription: Subscription,
    methods: Mutex<BTreeMap<&'static str, NodeId>>,
}

impl<M: StateMachine> RemoteMachine<M> {
    /// Follows the state machine `remote` is bound to (one subscription to its CurrentState).
    pub async fn of(remote: Remote<M>) -> Result<RemoteMachine<M>, ClientError> {
        let session = remote.session.clone();
        let found = translate(&session, &remote.node, &[vec![(UA, "CurrentState".to_owned())]]).await?.remove(0);
        let current_state = found.map_err(|status| ClientError::Status { what: format!("{}/CurrentState", remote.node), status })?;
        let (tx, seen) = watch::channel((0, None));
        let notify = move |value: DataValue| {
            let state = value.value.as_ref().and_then(state_of::<M>);
            tx.send_modify(|s| *s = (s.0 + 1, state));
        };
        // Every change, none dropped: a run must see each state it passes through.
        let subscription = Subscription::watch(session, &current_state, 0, false, notify).await?;
        let mut machine = RemoteMachine { remote, current_state, seen, _subscription: subscription, methods: Default::default() };
        // The first notification is the state now.
        let first = matches!(tokio::time::timeout(Duration::from_secs(5), machine.seen.wait_for(|s| s.0 > 0)).await, Ok(Ok(_)));
        if !first {
            return Err(ClientError::Timeout(format!("the first CurrentState of {}", machine.remote.node)));
        }
        Ok(machine)
    }

    /// The instance.
    pub fn remote(&self) -> &Remote<M> {
        &self.remote
    }

    /// The state the subscription last reported, as a row of `M`'s table (`None`: a state the table lacks).
    pub fn current(&self) -> Option<&'static StateRow> {
        self.seen.borrow().1.map(|i| &M::TABLE.states[i])
    }

    /// The state now, read from CurrentState.
    pub async fn state(&self) -> Result<Option<&'static StateRow>, ClientError> {
        let value = read_values(&self.remote.session, std::slice::from_ref(&self.current_state)).await?.remove(0);
        Ok(value.value.as_ref().and_then(state_of::<M>).map(|i| &M::TABLE.states[i]))
    }

    /// Waits until the machine is in the state with BrowseName `name` (at once if it is).
    pub async fn wait_for_state(&self, name: &str, timeout: Duration) -> Result<(), ClientError> {
        let wanted = self.table_state(name)?;
        let mut seen = self.seen.clone();
        let reached = tokio::time::timeout(timeout, seen.wait_for(|s| s.1 == Some(wanted))).await.map(|r| r.is_ok());
        match reached {
            Ok(true) => Ok(()),
            Ok(false) => Err(ClientError::Remote(crate::remote::RemoteError::Service("Publish", StatusCode::BadCommunicationError))),
            Err(_) => Err(ClientError::Timeout(format!("state {name} of {}", self.remote.node))),
        }
    }

    fn table_state(&self, name: &str) -> Result<usize, ClientError> {
        M::TABLE.state(name).ok_or_else(|| ClientError::Status {
            what: format!("{} has no state `{name}`", M::BROWSE_NAME),
            status: StatusCode::BadInvalidState,
        })
    }

    /// Calls a method that causes transitions (`Start`, `Halt`, ... as the table names them), without
    /// arguments. The server's Bad status (`BadInvalidState` where no transition starts) is the error.
    pub async fn cause(&self, name: &str) -> Result<(), ClientError> {
        let (uri, method) = M::TABLE.causes().into_iter().find(|(_, m)| *m == name).ok_or_else(|| ClientError::Status {
            what: format!("{} has no method `{name}` that causes a transition", M::BROWSE_NAME),
            status: StatusCode::BadMethodInvalid,
        })?;
        let node = self.method_node(uri, method).await?;
        call::<(), ()>(&self.remote.session, &self.remote.node, &node, method, ()).await
    }

    /// The NodeId of a method of the instance (translated once, then kept).
    async fn method_node(&self, uri: &'static str, method: &'static str) -> Result<NodeId, ClientError> {
        let known = self.methods.lock().unwrap_or_else(|e| e.into_inner()).get(method).cloned();
        if let Some(n) = known {
            return Ok(n);
        }
        let found = translate(&self.remote.session, &self.remote.node, &[vec![(uri, method.to_owned())]]).await?.remove(0);
        let n = found.map_err(|status| ClientError::Status { what: format!("method {method} of {}", self.remote.node), status })?;
        self.methods.lock().unwrap_or_else(|e| e.into_inner()).insert(method, n.clone());
        Ok(n)
    }
}

/// The table row of a CurrentState value (its DisplayName, or a state's BrowseName).
fn state_of<M: StateMachine>(value: &Variant) -> Option<usize> {
    let Variant::LocalizedText(text) = value else { return None };
    let text = text.text.as_ref();
    let states = M::TABLE.states;
    states.iter().position(|s| s.display_name == text).or_else(|| states.iter().position(|s| s.name == text))
}

/// A program instance (of any `ProgramStateMachineType` subtype: every skill) on a remote server: runs with
/// typed inputs, awaited to typed outputs, and Suspend, Resume, Halt and Reset.
pub struct RemoteProgram<P> {
    machine: RemoteMachine<P>,
}

impl<P> std::ops::Deref for RemoteProgram<P> {
    type Target = RemoteMachine<P>;
    fn deref(&self) -> &RemoteMachine<P> {
        &self.machine
    }
}

impl RemoteServer {
    /// Binds the program at `path` below the Objects folder as `P` and follows its state.
    pub async fn program<P: ProgramType>(&self, path: &str) -> Result<RemoteProgram<P>, ClientError> {
        RemoteProgram::of(self.bind_path(path).await?).await
    }
}

impl<P: ProgramType> RemoteProgram<P> {
    /// Follows the program `remote` is bound to.
    pub async fn of(remote: Remote<P>) -> Result<RemoteProgram<P>, ClientError> {
        Ok(RemoteProgram { machine: RemoteMachine::of(remote).await? })
    }

    /// Writes the inputs to `InputParameterSet` (one translation, one Write) and calls Start.
    pub async fn start(&self, inputs: P::Inputs) -> Result<(), ClientError> {
        self.write_inputs(inputs.into_values()).await?;
        self.cause("Start").await
    }

    /// Writes the values of the inputs (`None`: left as they are) to `InputParameterSet`.
    async fn write_inputs(&self, values: Vec<Option<Variant>>) -> Result<(), ClientError> {
        if let Some(set) = <P::Inputs as Parameters>::SET {
            let mut paths = Vec::new();
            let mut chosen = Vec::new();
            for (name, value) in <P::Inputs as Parameters>::NAMES.iter().zip(values) {
                if let Some(v) = value {
                    paths.push(vec![(set.0, set.1.to_owned()), (name.0, name.1.to_owned())]);
                    chosen.push((name.1, v));
                }
            }
            let nodes = translate(&self.remote.session, &self.remote.node, &paths).await?;
            let mut writes = Vec::with_capacity(nodes.len());
            for (node, (name, value)) in nodes.into_iter().zip(chosen) {
                let node = node.map_err(|status| ClientError::Status { what: format!("input {name}"), status })?;
                writes.push(WriteValue {
                    node_id: node,
                    attribute_id: AttributeId::Value as u32,
                    value: DataValue::value_only(value),
                    ..Default::default()
                });
            }
            if !writes.is_empty() {
                let results = self.remote.session.write(&writes).await.map_err(service("Write"))?;
                if let Some((i, status)) = results.iter().enumerate().find(|(_, s)| s.is_bad()) {
                    return Err(ClientError::Status { what: format!("write input {}", writes[i].node_id), status: *status });
                }
            }
        }
        Ok(())
    }

    /// Starts the program with `inputs` and waits until the run ends: its outputs when it ends in Ready,
    /// [`ClientError::Halted`] with the cause when it ends in Halted.
    pub async fn run(&self, inputs: P::Inputs) -> Result<P::Outputs, ClientError> {
        let mut seen = self.machine.seen.clone();
        let before = seen.borrow_and_update().0;
        self.start(inputs).await?;
        let mut started = false;
        let state = loop {
            if seen.changed().await.is_err() {
                return Err(ClientError::Remote(crate::remote::RemoteError::Service("Publish", StatusCode::BadCommunicationError)));
            }
            let (count, row) = *seen.borrow_and_update();
            if count <= before {
                continue;
            }
            let Some(state) = program_state(row.map(|i| &P::TABLE.states[i])) else { continue };
            let state = self.this_run(state, &mut started).await;
            if matches!(state, ProgramState::Ready | ProgramState::Halted) {
                break state;
            }
        };
        if state == ProgramState::Halted {
            return Err(ClientError::Halted { program: P::BROWSE_NAME.to_owned(), cause: self.halt_cause().await });
        }
        self.outputs().await
    }

    /// Reads the outputs from `OutputParameterSet` (one translation, one Read).
    pub async fn outputs(&self) -> Result<P::Outputs, ClientError> {
        let values = self.read_set::<P::Outputs>(<P::Outputs as Parameters>::NAMES).await?;
        <P::Outputs as Parameters>::from_values(&values).map_err(|(i, status)| ClientError::Status {
            what: format!("output {}", <P::Outputs as Parameters>::NAMES.get(i).map_or("?", |n| n.1)),
            status,
        })
    }

    /// Why the program halted: the StatusCode output the runtime sets to a run's outcome, if Bad, else
    /// `BadInvalidState`.
    async fn halt_cause(&self) -> StatusCode {
        let Some(outcome) = <P::Outputs as Parameters>::OUTCOME else { return StatusCode::BadInvalidState };
        match self.read_set::<P::Outputs>(&[outcome]).await {
            Ok(v) => match v.first() {
                Some(Some(Variant::StatusCode(s))) if s.is_bad() => *s,
                _ => StatusCode::BadInvalidState,
            },
            Err(_) => StatusCode::BadInvalidState,
        }
    }

    /// The values of variables of a parameter set (`None` where the instance lacks one).
    async fn read_set<S: Parameters>(&self, names: &[(&'static str, &'static str)]) -> Result<Vec<Option<Variant>>, ClientError> {
        let Some(set) = S::SET else { return Ok(vec![None; names.len()]) };
        let paths: Vec<_> = names.iter().map(|n| vec![(set.0, set.1.to_owned()), (n.0, n.1.to_owned())]).collect();
        let nodes = translate(&self.remote.session, &self.remote.node, &paths).await?;
        let present: Vec<NodeId> = nodes.iter().filter_map(|n| n.as_ref().ok().cloned()).collect();
        let mut values = read_values(&self.remote.session, &present).await?.into_iter();
        Ok(nodes.iter().map(|n| n.as_ref().ok().and_then(|_| values.next()).and_then(|v| v.value)).collect())
    }

    /// Calls Suspend.
    pub async fn suspend(&self) -> Result<(), ClientError> {
        self.cause("Suspend").await
    }

    /// Calls Resume.
    pub async fn resume(&self) -> Result<(), ClientError> {
        self.cause("Resume").await
    }

    /// Calls Halt.
    pub async fn halt(&self) -> Result<(), ClientError> {
        self.cause("Halt").await
    }

    /// Calls Reset.
    pub async fn reset(&self) -> Result<(), ClientError> {
        self.cause("Reset").await
    }
}

/// How long a request to another server may take before its server counts as unreachable.
const REQUEST_TIMEOUT: Duration = Duration::from_secs(3);
/// How long a step waits for a change of CurrentState before it reads the state itself.
const LIVENESS: Duration = Duration::from_secs(1);

/// The program state of a row of a program's state table.
fn program_state(row: Option<&'static StateRow>) -> Option<ProgramState> {
    let name = row?.name;
    [ProgramState::Ready, ProgramState::Running, ProgramState::Suspended, ProgramState::Halted].into_iter().find(|s| s.name() == name)
}

/// The status a composite halts with when a step cannot start: `None` when the server is unreachable
/// (the composite suspends and tries again), the refusal otherwise.
fn refusal(e: &ClientError) -> Option<StatusCode> {
    match e {
        ClientError::Status { status, .. } | ClientError::Arguments { status, .. } => Some(*status),
        ClientError::Halted { cause, .. } => Some(*cause),
        ClientError::Type { .. } | ClientError::WrongType { .. } => Some(StatusCode::BadTypeMismatch),
        ClientError::UnknownNamespace(_) => Some(StatusCode::BadNoMatch),
        ClientError::Remote(RemoteError::Path { .. } | RemoteError::Ambiguous { .. } | RemoteError::Missing { .. } | RemoteError::Pki(_)) => {
            Some(StatusCode::BadNoMatch)
        }
        ClientError::Remote(RemoteError::Service(..) | RemoteError::Connect(..)) | ClientError::Timeout(_) => None,
    }
}

impl<P: ProgramType> RemoteProgram<P> {
    /// Runs the program as a step of the composite skill whose body got `ctl` (see [`crate::remote`]):
    /// writes the inputs, calls Start and follows the program until it ends. `Ok` when it ends in Ready; the
    /// status the composite should halt with otherwise (its `Result` output if it halted, `BadInvalidState`
    /// if it has none, `BadCommunicationError` if its server went away during the run, the refusal if
    /// Start or an input was refused).
    pub async fn run_step(&self, inputs: P::Inputs, ctl: &Control) -> Result<(), StatusCode> {
        let values = inputs.into_values();
        let name = P::BROWSE_NAME;
        let halt = match P::TABLE.causes().into_iter().find(|(_, m)| *m == "Halt") {
            Some((uri, method)) => match self.method_node(uri, method).await {
                Ok(node) => Some(node),
                Err(e) => match refusal(&e) {
                    Some(status) => return Err(status),
                    // Unreachable now: the Start below suspends the composite, and Halt is found later.
                    None => None,
                },
            },
            None => None,
        };
        let mut seen = self.machine.seen.clone();
        // Start; a server that cannot be reached suspends the composite until a client resumes it.
        let before = loop {
            ctl.checkpoint().await;
            let before = seen.borrow_and_update().0;
            let started = async {
                self.write_inputs(values.clone()).await?;
                self.cause("Start").await
            };
            let error = match tokio::time::timeout(REQUEST_TIMEOUT, started).await {
                Ok(Ok(())) => break before,
                Ok(Err(e)) => e,
                Err(_) => ClientError::Timeout(format!("Start of {name}")),
            };
            if let Some(status) = refusal(&error) {
                return Err(status);
            }
            tracing::warn!("skill {name} is unavailable ({error}); the composite suspends");
            let _ = ctl.suspend();
        };
        // From here on, dropping this future (a Halt or Reset of the composite) halts the program.
        let halt = match halt {
            Some(h) => Some(h),
            None => self.method_node(UA, "Halt").await.ok(),
        };
        let guard = HaltOnDrop { call: halt.map(|h| (self.remote.session.clone(), self.remote.node.clone(), h)) };
        let mut composite = ctl.watch();
        let mut basic = ProgramState::Running;
        let mut started = false;
        // Without a change of CurrentState for a while, it is read: that finds a server that went away (the
        // composite halts: what the program did is unknown) and a change whose notification was lost.
        let mut quiet = tokio::time::interval_at(tokio::time::Instant::now() + LIVENESS, LIVENESS);
        let outcome = loop {
            tokio::select! {
                changed = seen.changed() => {
                    quiet.reset();
                    if changed.is_err() {
                        break Err(StatusCode::BadCommunicationError);
                    }
                    let (count, row) = *seen.borrow_and_update();
                    // Notifications of the state before this run's Start are not its outcome.
                    if count <= before {
                        continue;
                    }
                    let Some(state) = program_state(row.map(|i| &P::TABLE.states[i])) else { continue };
                    let state = self.this_run(state, &mut started).await;
                    let was = std::mem::replace(&mut basic, state);
                    match state {
                        ProgramState::Ready => break Ok(()),
                        ProgramState::Halted => break Err(self.halt_cause().await),
                        // The program has just been suspended: the composite follows (once; a client may
                        // resume the composite while the program stays suspended).
                        ProgramState::Suspended if was != ProgramState::Suspended && ctl.state() == ProgramState::Running => {
                            let _ = ctl.suspend();
                        }
                        _ => {}
                    }
                }
                _ = quiet.tick() => {
                    match tokio::time::timeout(REQUEST_TIMEOUT, self.state()).await {
                        Ok(Ok(row)) => match program_state(row) {
                            Some(ProgramState::Ready) => {
                                tracing::warn!("skill {name} is Ready, but the change of its CurrentState did not arrive");
                                break Ok(());
                            }
                            Some(ProgramState::Halted) => break Err(self.halt_cause().await),
                            _ => {}
                        },
                        Ok(Err(e)) => {
                            tracing::warn!("skill {name} cannot be read ({e}); the composite halts");
                            break Err(StatusCode::BadCommunicationError);
                        }
                        Err(_) => {
                            tracing::warn!("skill {name} does not answer; the composite halts");
                            break Err(StatusCode::BadCommunicationError);
                        }
                    }
                }
                changed = composite.changed() => {
                    if changed.is_err() {
                        break Err(StatusCode::BadShutdown);
                    }
                    let now = *composite.borrow_and_update();
                    // Where the program has no Suspend (an Optional method), it runs on; the composite
                    // waits at its next checkpoint.
                    match (now, basic) {
                        (ProgramState::Suspended, ProgramState::Running) => {
                            let _ = self.cause("Suspend").await;
                        }
                        (ProgramState::Running, ProgramState::Suspended) => {
                            let _ = self.cause("Resume").await;
                        }
                        _ => {}
                    }
                }
            }
        };
        guard.disarm();
        outcome
    }
}

impl<P: ProgramType> RemoteProgram<P> {
    /// The state of this run a notification of `state` stands for. Notifications arrive late: the Ready of
    /// a Reset before this run's Start can come after the Start. So until this run has been seen Running or
    /// Suspended (`started`), a Ready or Halted is checked by reading CurrentState; the read wins (it is
    /// the state now). Where the read fails, the notification stands: a server that went away is found by
    /// the step's own liveness read.
    async fn this_run(&self, state: ProgramState, started: &mut bool) -> ProgramState {
        let state = match state {
            ProgramState::Ready | ProgramState::Halted if !*started => {
                match tokio::time::timeout(REQUEST_TIMEOUT, self.state()).await {
                    Ok(Ok(row)) => program_state(row).unwrap_or(state),
                    _ => state,
                }
            }
            _ => state,
        };
        *started |= matches!(state, ProgramState::Running | ProgramState::Suspended);
        state
    }
}

/// Halts a remote program if the step that started it is dropped before it ended.
struct HaltOnDrop {
    call: Option<(Arc<Session>, NodeId, NodeId)>,
}

impl HaltOnDrop {
    fn disarm(mut self) {
        self.call = None;
    }
}

impl Drop for HaltOnDrop {
    fn drop(&mut self) {
        if let Some((session, node, halt)) = self.call.take() {
            // Drop cannot wait; the call runs on its own (there is a runtime: the body was running on it).
            if let Ok(rt) = tokio::runtime::Handle::try_current() {
                rt.spawn(async move {
                    let _ = session.call_one((node, halt, None::<Vec<Variant>>)).await;
                });
            }
        }
    }
}
