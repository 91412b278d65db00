//! Typed clients of remote instances: any generated ObjectType or VariableType handle, bound to an instance
//! on another server, with typed reads, writes, subscriptions and method calls, driven by the tables and
//! member markers the generated code already has (no per-type client code is generated, so the generated
//! crate does not grow).
//!
//! ```text
//! let robot = ClientConfig::new("pki/cell-controller").user("operator", password).connect("opc.tcp://127.0.0.1:4861/").await?;
//! let axis: Remote<AxisType> = robot.bind_path("DeviceSet/.../Axes/Base").await?;
//! let position = axis.read(&members::AxisType::ParameterSet__ActualPosition).await?;  // Sample<f64>
//! let mut joints = axis.subscribe(&members::AxisType::ParameterSet__ActualPosition, 50).await?;
//! while let Some(sample) = joints.next().await { println!("{:?} at {:?}", sample.value, sample.source_timestamp) }
//! let lifetime: Remote<LifetimeVariableType> = robot.bind_path(".../Gear/Lifetime").await?;   // a Variable
//! let left = lifetime.read_value().await?;                                                  // Sample<Variant>
//! let unit = lifetime.read(&members::LifetimeVariableType::EngineeringUnits).await?;       // Sample<EUInformation>
//! ```
//!
//! - [`ClientConfig`] is the one place where a connection is configured (security, identity, PKI folder);
//! - [`RemoteServer::bind`] and [`RemoteServer::bind_path`] bind a [`Remote<H>`] to an instance (an Object
//!   for an ObjectType handle, a Variable for a VariableType handle: any [`TypeHandle`]) by NodeId or browse
//!   path, checking that its TypeDefinition is `H`'s type or a subtype of it (a path's segments
//!   may leave out their namespace: they are tried in every namespace of the server, several segments to
//!   one TranslateBrowsePathsToNodeIds, see [`RemoteServer::find_counted`]; member paths, whose namespaces
//!   the markers carry, are translated in batches);
//! - a member marker (`members::<Type>::<Path>`) names a variable: [`Remote::read`], [`Remote::write`],
//!   [`Remote::subscribe`]; [`Remote::read_optional`] answers `None` for an Optional member the instance
//!   lacks; [`Remote::read_selection`] reads any number of members with one TranslateBrowsePathsToNodeIds
//!   and one Read; resolved paths are kept, so later reads are one round trip;
//! - a Variable bound with its VariableType handle has a value of its own, typed by the VariableType's
//!   DataType ([`VariableType::Value`]): [`Remote::read_value`], [`Remote::write_value`],
//!   [`Remote::subscribe_value`]; its child variables have markers like an object's members;
//! - a method marker (`members::<Type>::<Path>`, a [`MethodMember<I, O>`]) names a method and its argument
//!   types: [`Remote::call`] calls it with typed arguments and outputs; a Bad status of the server is the
//!   error, with the status of each argument when the server gives them;
//! - [`Remote::placeholders`] enumerates the instances of a placeholder by browsing;
//! - [`RemoteMachine`] and [`RemoteProgram`] follow state machines and run programs (every skill type);
//!   [`RemoteProgram::run_step`] runs one as a step of a composite skill (the rules are in
//!   [`crate::remote`]).

mod program;

use std::collections::BTreeMap;
use std::marker::PhantomData;
use std::pin::Pin;
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll};
use std::time::Duration;

use opcua::client::{DataChangeCallback, MonitoredItem, Session};
use opcua::types::{
    Array, AttributeId, BrowseDescription, BrowseDirection, BrowsePath, BrowseResultMask, CallMethodRequest, DataValue,
    DateTime, MonitoredItemCreateRequest, MonitoringMode, MonitoringParameters, NodeClassMask,
    NodeId, QualifiedName, ReadValueId, ReferenceTypeId, RelativePath, RelativePathElement, StatusCode,
    TimestampsToReturn, Variant, VariantScalarTypeId, WriteValue,
};
use tokio::sync::mpsc;

pub use program::{RemoteMachine, RemoteProgram};
// The connection settings live with the sessions they open, in `remote`, the layer below.
pub use crate::remote::ClientConfig;

use crate::remote::{RemoteError, RemoteServer};
use crate::typed::{Arguments, Holds, MemberPath, MethodMember, TypeHandle, UaValue, VariableMember, VariableType};
use crate::table::NsNodeId;

/// Why a typed client operation failed.
#[derive(Clone, Debug, PartialEq)]
pub enum ClientError {
    /// No session, a failed service or a path that does not lead anywhere.
    Remote(RemoteError),
    /// The server answered an operation with a Bad status.
    Status {
        /// What was asked (`read Robotics:MotionDeviceType/...`).
        what: String,
        /// The status the server answered.
        status: StatusCode,
    },
    /// The server refused a method call's arguments.
    Arguments {
        /// The method called.
        method: String,
        /// The call's status.
        status: StatusCode,
        /// One status per input argument.
        arguments: Vec<StatusCode>,
    },
    /// A value is not of the Rust type asked for.
    Type {
        /// What was read.
        what: String,
        /// The value the server gave.
        value: Variant,
    },
    /// The node is not an instance of the handle's type.
    WrongType {
        /// The node.
        node: NodeId,
        /// Its TypeDefinition, if it has one.
        type_definition: Option<NodeId>,
        /// The type the handle needs.
        expected: &'static str,
    },
    /// The server's namespace table lacks a namespace a handle names.
    UnknownNamespace(String),
    /// Nothing happened in time (what was awaited).
    Timeout(String),
    /// A program ended in Halted (the program, the cause it gave: its `Result` output, or
    /// `BadInvalidState`).
    Halted {
        /// The program.
        program: String,
        /// The cause it gave.
        cause: StatusCode,
    },
}

impl std::fmt::Display for ClientError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ClientError::Remote(e) => e.fmt(f),
            ClientError::Status { what, status } => write!(f, "{what}: the server answered {status}"),
            ClientError::Arguments { method, status, arguments } => {
                write!(f, "{method}: the server refused the arguments ({status}; per argument: {arguments:?})")
            }
            ClientError::Type { what, value } => write!(f, "{what}: the value {value:?} is not of the expected type"),
            ClientError::WrongType { node, type_definition, expected } => match type_definition {
                Some(t) => write!(f, "node {node} is of type {t}, not {expected} or a subtype"),
                None => write!(f, "node {node} has no TypeDefinition; {expected} was expected"),
            },
            ClientError::UnknownNamespace(uri) => write!(f, "the server has no namespace `{uri}`"),
            ClientError::Timeout(what) => write!(f, "timed out waiting for {what}"),
            ClientError::Halted { program, cause } => write!(f, "program `{program}` halted: {cause}"),
        }
    }
}

impl std::error::Error for ClientError {}

impl From<RemoteError> for ClientError {
    fn from(e: RemoteError) -> Self {
        ClientError::Remote(e)
    }
}

fn service(what: &'static str) -> impl Fn(opcua::types::Error) -> ClientError {
    move |e| ClientError::Remote(RemoteError::Service(what, e.status()))
}

/// A value as the server reported it: typed (`None` if the variable has no value or one of another type),
/// with its status and timestamps.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample<T> {
    /// The value, `None` if there is none or it is not a `T`.
    pub value: Option<T>,
    /// The value's status (Good if the server gave none).
    pub status: StatusCode,
    /// When the source produced it.
    pub source_timestamp: Option<DateTime>,
    /// When the server saw it.
    pub server_timestamp: Option<DateTime>,
}

impl<T: UaValue> Sample<T> {
    /// The sample of a DataValue.
    pub fn of(value: &DataValue) -> Sample<T> {
        Sample {
            value: value.value.as_ref().and_then(T::from_variant),
            status: value.status.unwrap_or(StatusCode::Good),
            source_timestamp: value.source_timestamp,
            server_timestamp: value.server_timestamp,
        }
    }
}

/// A typed instance on a remote server, bound as the generated handle `H` (its ObjectType or VariableType).
pub struct Remote<H> {
    session: Arc<Session>,
    node: NodeId,
    /// Member paths resolved so far (path text -> NodeId, or the status that says it is absent).
    resolved: Arc<Mutex<BTreeMap<String, Result<NodeId, StatusCode>>>>,
    _type: PhantomData<fn() -> H>,
}

impl<H> Clone for Remote<H> {
    fn clone(&self) -> Self {
        Remote { session: self.session.clone(), node: self.node.clone(), resolved: self.resolved.clone(), _type: PhantomData }
    }
}

impl<H: TypeHandle> std::fmt::Debug for Remote<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Remote<{}>({})", H::TYPE_NAME, self.node)
    }
}

impl RemoteServer {
    /// Binds the instance `node` as `H`, after checking that its TypeDefinition is `H`'s type or a subtype.
    pub async fn bind<H: TypeHandle>(&self, node: &NodeId) -> Result<Remote<H>, ClientError> {
        Remote::bind(self.session().clone(), node).await
    }

    /// Binds the instance at `path` below the Objects folder (see [`RemoteServer::find`]) as `H`.
    pub async fn bind_path<H: TypeHandle>(&self, path: &str) -> Result<Remote<H>, ClientError> {
        let node = self.find(path).await?;
        self.bind(&node).await
    }
}

impl<H: TypeHandle> Remote<H> {
    async fn bind(session: Arc<Session>, node: &NodeId) -> Result<Remote<H>, ClientError> {
        let expected = resolve_id(&session, H::TYPE_NODE_ID)?;
        let type_definition = type_definition(&session, node).await?;
        let fits = match &type_definition {
            Some(t) => is_subtype(&session, t, &expected).await?,
            None => false,
        };
        if !fits {
            return Err(ClientError::WrongType { node: node.clone(), type_definition, expected: H::TYPE_NAME });
        }
        Ok(Remote { session, node: node.clone(), resolved: Default::default(), _type: PhantomData })
    }

    /// The instance's NodeId.
    pub fn node(&self) -> &NodeId {
        &self.node
    }

    /// The session.
    pub fn session(&self) -> &Arc<Session> {
        &self.session
    }

    /// The NodeIds of members, each `Err(status)` if the instance lacks it: one TranslateBrowsePathsToNodeIds
    /// for the paths not resolved before.
    pub async fn resolve(&self, paths: &[MemberPath]) -> Result<Vec<Result<NodeId, StatusCode>>, ClientError> {
        let missing: Vec<MemberPath> = {
            let known = self.resolved.lock().unwrap_or_else(|e| e.into_inner());
            let mut m: Vec<MemberPath> = paths.iter().filter(|p| !known.contains_key(p.text)).copied().collect();
            m.dedup_by_key(|p| p.text);
            m
        };
        if !missing.is_empty() {
            let segments = missing
                .iter()
                .map(|p| p.segments().map_err(|e| ClientError::Type { what: e.to_string(), value: Variant::Empty }))
                .collect::<Result<Vec<_>, _>>()?;
            let found = translate(&self.session, &self.node, &segments).await?;
            let mut known = self.resolved.lock().unwrap_or_else(|e| e.into_inner());
            for (p, r) in missing.iter().zip(found) {
                known.insert(p.text.to_owned(), r);
            }
        }
        let known = self.resolved.lock().unwrap_or_else(|e| e.into_inner());
        Ok(paths.iter().map(|p| known.get(p.text).cloned().unwrap_or(Err(StatusCode::BadNoMatch))).collect())
    }

    async fn member(&self, path: MemberPath) -> Result<NodeId, ClientError> {
        self.resolve(&[path]).await?.remove(0).map_err(|status| ClientError::Status { what: self.what(path), status })
    }

    fn what(&self, path: MemberPath) -> String {
        format!("{} {}/{}", H::TYPE_NAME, self.node, path.text)
    }

    /// Reads a variable member as `T` (`S` for a scalar, `Vec<S>` for an array, per the marker's ValueRank).
    pub async fn read<T: UaValue + Holds<S>, S>(&self, member: &VariableMember<S>) -> Result<Sample<T>, ClientError> {
        let node = self.member(member.browse_path()).await?;
        read_one(&self.session, node, &self.what(member.browse_path())).await
    }

    /// Reads an Optional member: `None` if the instance lacks it.
    pub async fn read_optional<T: UaValue + Holds<S>, S>(
        &self,
        member: &VariableMember<S>,
    ) -> Result<Option<Sample<T>>, ClientError> {
        match self.resolve(&[member.browse_path()]).await?.remove(0) {
            Ok(_) => self.read(member).await.map(Some),
            Err(_) => Ok(None),
        }
    }

    /// Reads any number of members (absent ones are `Err(status)`): one translation for the paths not
    /// resolved before, and one Read.
    pub async fn read_selection(&self, paths: &[MemberPath]) -> Result<Vec<Result<DataValue, StatusCode>>, ClientError> {
        let nodes = self.resolve(paths).await?;
        let present: Vec<NodeId> = nodes.iter().filter_map(|n| n.as_ref().ok().cloned()).collect();
        let mut values = read_values(&self.session, &present).await?.into_iter();
        Ok(nodes.into_iter().map(|n| n.map(|_| values.next().unwrap_or_default())).collect())
    }

    /// Reads one member of each of several instances of this type: one translation and one Read.
    pub async fn read_each<T: UaValue + Holds<S>, S>(
        handles: &[Remote<H>],
        member: &VariableMember<S>,
    ) -> Result<Vec<Sample<T>>, ClientError> {
        let Some(first) = handles.first() else { return Ok(Vec::new()) };
        let path = member.browse_path();
        let segments = path.segments().map_err(|e| ClientError::Type { what: e.to_string(), value: Variant::Empty })?;
        let mut nodes = Vec::with_capacity(handles.len());
        let starts: Vec<&NodeId> = handles.iter().map(|h| &h.node).collect();
        let found = translate_from(&first.session, &starts, &segments).await?;
        for (h, r) in handles.iter().zip(found) {
            nodes.push(r.map_err(|status| ClientError::Status { what: h.what(path), status })?);
        }
        let values = read_values(&first.session, &nodes).await?;
        values.into_iter().zip(handles).map(|(v, h)| sample(v, &h.what(path))).collect()
    }

    /// Writes a variable member.
    pub async fn write<T: UaValue + Holds<S>, S>(&self, member: &VariableMember<S>, value: T) -> Result<(), ClientError> {
        let node = self.member(member.browse_path()).await?;
        write_one(&self.session, node, value.to_variant(), &self.what(member.browse_path())).await
    }

    /// Subscribes to a variable member: a stream of its values, sampled every `interval_ms` (0: every
    /// change).
    pub async fn subscribe<T: UaValue + Holds<S>, S>(
        &self,
        member: &VariableMember<S>,
        interval_ms: u64,
    ) -> Result<Samples<T>, ClientError> {
        let node = self.member(member.browse_path()).await?;
        Samples::open(self.session.clone(), node, interval_ms).await
    }

    /// Calls a method member (`&members::<Type>::<Path>`, whose type gives the input and output tuples) on
    /// the object that holds it, with typed arguments; its typed outputs. The method's and the object's
    /// NodeIds come from one TranslateBrowsePathsToNodeIds the first time (kept for later calls, which are
    /// then one Call). A Bad status of the call is the error: [`ClientError::Arguments`] with the status of
    /// each argument when the server gives them, [`ClientError::Status`] otherwise (and for a method the
    /// instance lacks: `BadNoMatch`).
    pub async fn call<I: Arguments, O: Arguments>(&self, method: &MethodMember<I, O>, arguments: I) -> Result<O, ClientError> {
        let path = method.browse_path();
        let (object, method_node) = match path.parent() {
            None => (Ok(self.node.clone()), self.resolve(&[path]).await?.remove(0)),
            Some(parent) => {
                let mut found = self.resolve(&[parent, path]).await?;
                let method_node = found.remove(1);
                (found.remove(0), method_node)
            }
        };
        let what = self.what(path);
        let object = object.map_err(|status| ClientError::Status { what: what.clone(), status })?;
        let method_node = method_node.map_err(|status| ClientError::Status { what: what.clone(), status })?;
        call(&self.session, &object, &method_node, &what, arguments).await
    }

    /// The instances of a placeholder below the member at `below` (`""`: the instance itself), bound as
    /// `C` (children whose TypeDefinition is `C`'s type or a subtype), in BrowseName order: one Browse for
    /// the children, and the supertypes of each distinct TypeDefinition (one Browse a level).
    pub async fn placeholders<C: TypeHandle>(&self, below: &str) -> Result<Vec<(String, Remote<C>)>, ClientError> {
        let parent = if below.is_empty() { self.node.clone() } else { crate::remote::find_below(&self.session, &self.node, below).await? };
        let expected = resolve_id(&self.session, C::TYPE_NODE_ID)?;
        let mut out = Vec::new();
        // One Browse gives the children with their TypeDefinitions; each distinct type is checked once.
        let mut verdicts: Vec<(NodeId, bool)> = Vec::new();
        for (name, child, t) in crate::remote::typed_children(&self.session, &parent).await? {
            if t.is_null() {
                continue;
            }
            let fits = match verdicts.iter().find(|(known, _)| *known == t) {
                Some((_, fits)) => *fits,
                None => {
                    let fits = is_subtype(&self.session, &t, &expected).await?;
                    verdicts.push((t, fits));
                    fits
                }
            };
            if fits {
                out.push((name.name.as_ref().to_owned(), Remote { session: self.session.clone(), node: child, resolved: Default::default(), _type: PhantomData }));
            }
        }
        out.sort_by(|a, b| a.0.cmp(&b.0));
        Ok(out)
    }
}

/// The value of a Variable bound with its VariableType handle, typed by the VariableType's DataType
/// ([`VariableType::Value`]). Its child variables are read, written and subscribed with their markers,
/// like an object's members.
impl<H: VariableType> Remote<H> {
    fn what_value(&self) -> String {
        format!("{} {}", H::TYPE_NAME, self.node)
    }

    /// Reads the variable's own value: one Read.
    pub async fn read_value(&self) -> Result<Sample<H::Value>, ClientError> {
        read_one(&self.session, self.node.clone(), &self.what_value()).await
    }

    /// Writes the variable's own value: one Write.
    pub async fn write_value(&self, value: H::Value) -> Result<(), ClientError> {
        write_one(&self.session, self.node.clone(), value.to_variant(), &self.what_value()).await
    }

    /// Subscribes to the variable's own value: a stream of its values, sampled every `interval_ms` (0: every
    /// change).
    pub async fn subscribe_value(&self, interval_ms: u64) -> Result<Samples<H::Value>, ClientError> {
        Samples::open(self.session.clone(), self.node.clone(), interval_ms).await
    }
}

/// A subscription's values as a [`Stream`](futures_core::Stream) (or with [`Samples::next`]); the
/// subscription is deleted when it is dropped.
pub struct Samples<T> {
    rx: mpsc::UnboundedReceiver<DataValue>,
    _subscription: Subscription,
    _value: PhantomData<fn() -> T>,
}

impl<T: UaValue> Samples<T> {
    async fn open(session: Arc<Session>, node: NodeId, interval_ms: u64) -> Result<Samples<T>, ClientError> {
        let (tx, rx) = mpsc::unbounded_channel();
        let notify = move |value: DataValue| {
            let _ = tx.send(value);
        };
        let subscription = Subscription::watch(session, &node, interval_ms, true, notify).await?;
        Ok(Samples { rx, _subscription: subscription, _value: PhantomData })
    }

    /// The next value; `None` once the session is gone.
    pub async fn next(&mut self) -> Option<Sample<T>> {
        self.rx.recv().await.map(|v| Sample::of(&v))
    }
}

impl<T: UaValue> futures_core::Stream for Samples<T> {
    type Item = Sample<T>;
    fn poll_next(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<Sample<T>>> {
        self.rx.poll_recv(cx).map(|v| v.map(|v| Sample::of(&v)))
    }
}

/// A subscription with one monitored item, the Value of one variable; deleted when dropped. [`Samples`]
/// and [`RemoteMachine`] (CurrentState) both follow a variable through it.
pub(crate) struct Subscription {
    session: Arc<Session>,
    id: u32,
}

impl Subscription {
    /// Subscribes to the Value of `node`, sampled every `interval_ms` (0: every change) and published as
    /// often (but not more often than every 10 ms), each notification given to `notify`. `discard_oldest`:
    /// whether a full queue (100 values) drops its oldest value or its newest.
    pub(crate) async fn watch(
        session: Arc<Session>,
        node: &NodeId,
        interval_ms: u64,
        discard_oldest: bool,
        notify: impl Fn(DataValue) + Send + Sync + 'static,
    ) -> Result<Subscription, ClientError> {
        let callback = DataChangeCallback::new(move |value: DataValue, _: &MonitoredItem| notify(value));
        let publishing = Duration::from_millis(interval_ms.max(10));
        let id = session
            .create_subscription(publishing, 600, 20, 0, 0, true, callback)
            .await
            .map_err(service("CreateSubscription"))?;
        // From here on, dropping the guard deletes the subscription (also on the error below).
        let subscription = Subscription { session, id };
        let item = MonitoredItemCreateRequest {
            item_to_monitor: ReadValueId { node_id: node.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() },
            monitoring_mode: MonitoringMode::Reporting,
            requested_parameters: MonitoringParameters {
                client_handle: 1,
                sampling_interval: interval_ms as f64,
                queue_size: 100,
                discard_oldest,
                ..Default::default()
            },
        };
        let created = subscription
            .session
            .create_monitored_items(id, TimestampsToReturn::Both, vec![item])
            .await
            .map_err(service("CreateMonitoredItems"))?;
        if let Some(bad) = created.iter().map(|c| c.result.status_code).find(|s| s.is_bad()) {
            return Err(ClientError::Status { what: format!("subscribe to {node}"), status: bad });
        }
        Ok(subscription)
    }
}

impl Drop for Subscription {
    fn drop(&mut self) {
        let (session, id) = (self.session.clone(), self.id);
        if let Ok(rt) = tokio::runtime::Handle::try_current() {
            rt.spawn(async move {
                let _ = session.delete_subscription(id).await;
            });
        }
    }
}

/// One Read of the Value of `node`, as a `T` (a value of another type is an error).
async fn read_one<T: UaValue>(session: &Session, node: NodeId, what: &str) -> Result<Sample<T>, ClientError> {
    let mut values = read_values(session, &[node]).await?;
    sample(values.remove(0), what)
}

/// One Write of the Value of `node`; a Bad status is the error.
async fn write_one(session: &Session, node: NodeId, value: Variant, what: &str) -> Result<(), ClientError> {
    let write = WriteValue { node_id: node, attribute_id: AttributeId::Value as u32, value: DataValue::value_only(value), ..Default::default() };
    let status = session.write(&[write]).await.map_err(service("Write"))?.pop().unwrap_or(StatusCode::BadUnexpectedError);
    if status.is_bad() {
        return Err(ClientError::Status { what: format!("write {what}"), status });
    }
    Ok(())
}

fn sample<T: UaValue>(value: DataValue, what: &str) -> Result<Sample<T>, ClientError> {
    let s = Sample::of(&value);
    match (&s.value, value.value) {
        (None, Some(v)) if !matches!(v, Variant::Empty) => Err(ClientError::Type { what: what.to_owned(), value: v }),
        _ => Ok(s),
    }
}

/// The NodeId of a generated NsNodeId on the session's server.
pub(crate) fn resolve_id(session: &Session, id: NsNodeId) -> Result<NodeId, ClientError> {
    let ns = session.get_namespace_index_from_cache(id.namespace_uri).ok_or(ClientError::UnknownNamespace(id.namespace_uri.to_owned()))?;
    Ok(crate::table::make_node_id(ns, id.id))
}

/// One Read of the Value attribute of `nodes`.
pub(crate) async fn read_values(session: &Session, nodes: &[NodeId]) -> Result<Vec<DataValue>, ClientError> {
    if nodes.is_empty() {
        return Ok(Vec::new());
    }
    let ids: Vec<ReadValueId> = nodes
        .iter()
        .map(|n| ReadValueId { node_id: n.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() })
        .collect();
    let values = session.read(&ids, TimestampsToReturn::Both, 0.0).await.map_err(service("Read"))?;
    if values.len() != nodes.len() {
        return Err(ClientError::Remote(RemoteError::Service("Read", StatusCode::BadUnexpectedError)));
    }
    Ok(values)
}

/// Calls `method` on `object`; a Bad status is the error.
pub(crate) async fn call<I: Arguments, O: Arguments>(
    session: &Session,
    object: &NodeId,
    method: &NodeId,
    name: &str,
    arguments: I,
) -> Result<O, ClientError> {
    let request = CallMethodRequest {
        object_id: object.clone(),
        method_id: method.clone(),
        input_arguments: Some(arguments.into_variants()),
    };
    let result = session.call(vec![request]).await.map_err(service("Call"))?.pop();
    let result = result.ok_or(ClientError::Remote(RemoteError::Service("Call", StatusCode::BadUnexpectedError)))?;
    let per_argument = result.input_argument_results.unwrap_or_default();
    if result.status_code.is_bad() {
        if per_argument.iter().any(|s| s.is_bad()) {
            return Err(ClientError::Arguments { method: name.to_owned(), status: result.status_code, arguments: per_argument });
        }
        return Err(ClientError::Status { what: format!("call {name}"), status: result.status_code });
    }
    let outputs = result.output_arguments.unwrap_or_default();
    O::from_variants(&outputs).map_err(|_| {
        // The outputs as one array of Variants (each element boxed, as an array of BaseDataType holds them).
        let boxed: Vec<Variant> = outputs.iter().cloned().map(|v| Variant::Variant(Box::new(v))).collect();
        let value = Array::new(VariantScalarTypeId::Variant, boxed).map(Variant::from).unwrap_or(Variant::Empty);
        ClientError::Type { what: format!("outputs of {name}"), value }
    })
}

/// One TranslateBrowsePathsToNodeIds of `paths` (BrowseNames with namespace URIs) from `start`.
pub(crate) async fn translate(
    session: &Session,
    start: &NodeId,
    paths: &[Vec<(&'static str, String)>],
) -> Result<Vec<Result<NodeId, StatusCode>>, ClientError> {
    translate_pairs(session, paths.iter().map(|p| (start, p.as_slice()))).await
}

/// One TranslateBrowsePathsToNodeIds of the same path from each of `starts`.
async fn translate_from(
    session: &Session,
    starts: &[&NodeId],
    path: &[(&'static str, String)],
) -> Result<Vec<Result<NodeId, StatusCode>>, ClientError> {
    translate_pairs(session, starts.iter().map(|s| (*s, path))).await
}

/// One TranslateBrowsePathsToNodeIds of each (start, path) pair, in order; a path with a namespace the
/// server does not serve is `BadNoMatch` without being asked.
async fn translate_pairs<'a>(
    session: &Session,
    pairs: impl Iterator<Item = (&'a NodeId, &'a [(&'static str, String)])>,
) -> Result<Vec<Result<NodeId, StatusCode>>, ClientError> {
    let (mut out, mut asked, mut requests) = (Vec::new(), Vec::new(), Vec::new());
    for (i, (start, path)) in pairs.enumerate() {
        out.push(Err(StatusCode::BadNoMatch));
        if let Some(request) = browse_path(session, start, path) {
            asked.push(i);
            requests.push(request);
        }
    }
    resolve_paths(session, requests, asked, out).await
}

async fn resolve_paths(
    session: &Session,
    requests: Vec<BrowsePath>,
    asked: Vec<usize>,
    mut out: Vec<Result<NodeId, StatusCode>>,
) -> Result<Vec<Result<NodeId, StatusCode>>, ClientError> {
    if requests.is_empty() {
        return Ok(out);
    }
    let results = session.translate_browse_paths_to_node_ids(&requests).await.map_err(service("TranslateBrowsePathsToNodeIds"))?;
    for (i, r) in asked.into_iter().zip(results) {
        let target = r.targets.unwrap_or_default().into_iter().find(|t| t.remaining_path_index == u32::MAX);
        out[i] = match target {
            Some(t) if r.status_code.is_good() => Ok(t.target_id.node_id),
            _ if r.status_code.is_bad() => Err(r.status_code),
            _ => Err(StatusCode::BadNoMatch),
        };
    }
    Ok(out)
}

/// The BrowsePath of `path` from `start`; `None` if a namespace is not on the server (nothing can match).
fn browse_path(session: &Session, start: &NodeId, path: &[(&'static str, String)]) -> Option<BrowsePath> {
    let mut elements = Vec::with_capacity(path.len());
    for (uri, name) in path {
        let ns = session.get_namespace_index_from_cache(uri)?;
        elements.push(RelativePathElement {
            reference_type_id: ReferenceTypeId::HierarchicalReferences.into(),
            is_inverse: false,
            include_subtypes: true,
            target_name: QualifiedName::new(ns, name.as_str()),
        });
    }
    Some(BrowsePath { starting_node: start.clone(), relative_path: RelativePath { elements: Some(elements) } })
}

/// The targets of one reference type from `node` (forward or inverse).
async fn references(session: &Session, node: &NodeId, reference: ReferenceTypeId, direction: BrowseDirection) -> Result<Vec<NodeId>, ClientError> {
    let description = BrowseDescription {
        node_id: node.clone(),
        browse_direction: direction,
        reference_type_id: reference.into(),
        include_subtypes: false,
        node_class_mask: NodeClassMask::all().bits(),
        result_mask: BrowseResultMask::None as u32,
    };
    let result = session.browse(&[description], 0, None).await.map_err(service("Browse"))?.pop();
    let result = result.ok_or(ClientError::Remote(RemoteError::Service("Browse", StatusCode::BadUnexpectedError)))?;
    if result.status_code.is_bad() {
        return Err(ClientError::Status { what: format!("browse {node}"), status: result.status_code });
    }
    Ok(result.references.unwrap_or_default().into_iter().map(|r| r.node_id.node_id).collect())
}

/// The TypeDefinition of an instance.
async fn type_definition(session: &Session, node: &NodeId) -> Result<Option<NodeId>, ClientError> {
    Ok(references(session, node, ReferenceTypeId::HasTypeDefinition, BrowseDirection::Forward).await?.into_iter().next())
}

/// Whether `ty` is `ancestor` or one of its subtypes (following HasSubtype up, one Browse per level).
async fn is_subtype(session: &Session, ty: &NodeId, ancestor: &NodeId) -> Result<bool, ClientError> {
    let mut current = ty.clone();
    for _ in 0..64 {
        if current == *ancestor {
            return Ok(true);
        }
        match references(session, &current, ReferenceTypeId::HasSubtype, BrowseDirection::Inverse).await?.into_iter().next() {
            Some(parent) => current = parent,
            None => return Ok(false),
        }
    }
    Ok(false)
}
