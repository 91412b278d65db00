//! Skills of other servers, run through async-opcua's client: what the body of a composite skill needs.
//!
//! [`RemoteServer::connect`] opens a session to a server, [`RemoteServer::skill`] finds a skill by its
//! browse path below the Objects folder (no NodeId is written down anywhere: names are looked up by
//! browsing, namespaces through the server's NamespaceArray), and [`RemoteSkill::run`] writes its typed
//! inputs, calls Start and follows it through its transition events until it ends:
//!
//! ```text
//! let robot = RemoteServer::connect("opc.tcp://127.0.0.1:4861/").await?;
//! let move_in = robot.skill("DeviceSet/TemplateDrillingLwrSystem/MotionDeviceSystem/Controllers/URController/SkillSet/RelativeCartesianLinearMove").await?;
//! let drill_hole = cell.serve(move |inputs: DrillHoleSkillTypeInputs, ctl| async move {
//!     move_in.run(RelativeCartesianLinearMoveSkillTypeInputs { .. }, &ctl).await?;   // Err: the composite halts
//!     ...
//! })?;
//! ```
//!
//! While a basic skill runs, the composite follows it as the Commands2 paper asks ("if one of the basic
//! skills is unavailable or is in Halted state, the composite skill also needs to go into Suspended or
//! Halted state"):
//!
//! - the basic skill ends in Ready: `run` returns `Ok`;
//! - it ends in Halted: `run` returns its `Result` output (the cause), or `BadInvalidState` if it has
//!   none, so the composite's body returns it and the composite halts with the same cause;
//! - it is suspended: the composite suspends itself; a client's Resume of the composite resumes it;
//! - the composite is suspended (a client's Suspend): the basic skill is suspended too, and resumed with the
//!   composite;
//! - the composite is halted or reset while the basic skill runs (its body is dropped): the basic skill is
//!   halted;
//! - the server of the basic skill cannot be reached when the run starts (a transport error or no answer
//!   within 3 s, not a status of the skill): the composite suspends itself and tries again when a client
//!   resumes it;
//! - the server of the basic skill goes away while the skill runs (no event for a second, and CurrentState
//!   cannot be read within 3 s): `run` returns `BadCommunicationError`, so the composite halts; what the
//!   basic skill did is unknown, so the composite does not go on by itself. A transition event that is lost
//!   (the skill is Ready or Halted, but no event said so) is found by the same read.

use std::collections::BTreeMap;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::time::Duration;

use opcua::client::transport::{ConnectorBuilder, StreamConnection, StreamConnector};
use opcua::client::ConnectionSource;
use opcua::core::comms::tcp_codec::TcpCodec;
use opcua::core::comms::url::hostname_port_from_url;
use opcua::types::{DecodingOptions, EndpointDescription};
use tokio::io::{ReadHalf, WriteHalf};
use tokio::net::TcpStream;
use tokio_util::codec::FramedRead;

use opcua::client::{ClientBuilder, IdentityToken, MonitoredItem, Session, SessionPollResult, SubscriptionCallbacks};
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    AttributeId, BrowseDescription, BrowseDirection, BrowseResultMask, ContentFilter, DataValue, EventFilter,
    ExtensionObject, MonitoredItemCreateRequest, MonitoringMode,
    MonitoringParameters, NodeClassMask, NodeId, ObjectId, ObjectTypeId, QualifiedName, ReadValueId,
    ReferenceTypeId, SimpleAttributeOperand, StatusCode, TimestampsToReturn, Variant, WriteValue,
};
use tokio::sync::{mpsc, Mutex};
use tokio::task::JoinHandle;

use crate::client::ClientConfig;
use crate::typed::{Control, Parameters, ProgramState};

/// How long a request to another server may take before its server counts as unreachable.
const REQUEST_TIMEOUT: Duration = Duration::from_secs(3);
/// How long a run waits for a transition event before it reads the skill's state itself.
const LIVENESS: Duration = Duration::from_secs(1);

/// Why a remote skill could not be reached or found.
#[derive(Clone, Debug, PartialEq)]
pub enum RemoteError {
    /// The session could not be opened (the endpoint, and why).
    Connect(String, StatusCode),
    /// A service call failed.
    Service(&'static str, StatusCode),
    /// A segment of a browse path matches no child, or several (the path so far, the segment).
    Path { below: String, segment: String, matches: usize },
    /// The skill lacks a node a run needs (`CurrentState`, `Start`, ...).
    Missing { skill: String, what: String },
    /// The client's PKI folder cannot be used (why).
    Pki(String),
}

impl std::fmt::Display for RemoteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RemoteError::Connect(url, s) => write!(f, "cannot open a session to {url}: {s}"),
            RemoteError::Service(what, s) => write!(f, "{what} failed: {s}"),
            RemoteError::Path { below, segment, matches: 0 } => write!(f, "`{below}` has no child `{segment}`"),
            RemoteError::Path { below, segment, matches } => {
                write!(f, "`{below}` has {matches} children named `{segment}`; name one by its namespace URI: `{{uri}}{segment}`")
            }
            RemoteError::Missing { skill, what } => write!(f, "skill `{skill}` has no {what}"),
            RemoteError::Pki(e) => write!(f, "the client's PKI folder: {e}"),
        }
    }
}

impl std::error::Error for RemoteError {}

/// A connection source for async-opcua's client whose TCP connections send at once (`TCP_NODELAY`).
///
/// async-opcua writes a request in more than one write, and with Nagle's algorithm the second waits for
/// the server's ACK of the first, which Linux delays by up to 40 ms: every read after a Publish request
/// took that long, and each step of a composite skill waited for two of them. Use it with
/// `client.session_builder()...with_connector(NoDelay)`; [`RemoteServer::connect`] does.
pub struct NoDelay;

/// The connector [`NoDelay`] builds for one endpoint.
pub struct NoDelayUrl(String);

type Halves = StreamConnection<ReadHalf<TcpStream>, WriteHalf<TcpStream>>;
type Connecting = Pin<Box<dyn Future<Output = Result<Halves, opcua::types::Error>> + Send + Sync>>;

impl ConnectionSource for NoDelay {
    type Builder = NoDelayUrl;

    fn get_connector(&self, endpoint: &EndpointDescription) -> Result<NoDelayUrl, opcua::types::Error> {
        Ok(NoDelayUrl(endpoint.endpoint_url.as_ref().to_owned()))
    }
}

impl ConnectorBuilder for NoDelayUrl {
    type ConnectorType = StreamConnector<ReadHalf<TcpStream>, WriteHalf<TcpStream>, fn(String, DecodingOptions) -> Connecting, Connecting>;

    fn build(self) -> Result<Self::ConnectorType, opcua::types::Error> {
        Ok(StreamConnector::new(connect_no_delay as fn(String, DecodingOptions) -> Connecting, self.0))
    }
}

fn connect_no_delay(url: String, options: DecodingOptions) -> Connecting {
    Box::pin(async move {
        let error = |status: StatusCode, what: String| opcua::types::Error::new(status, what);
        let (host, port) = hostname_port_from_url(&url, opcua::core::constants::DEFAULT_OPC_UA_SERVER_PORT)
            .map_err(|s| error(s, format!("cannot read host and port from {url}")))?;
        let stream = TcpStream::connect((host.as_str(), port))
            .await
            .map_err(|e| error(StatusCode::BadCommunicationError, format!("cannot connect to {host}:{port}: {e}")))?;
        stream
            .set_nodelay(true)
            .map_err(|e| error(StatusCode::BadCommunicationError, format!("cannot set TCP_NODELAY: {e}")))?;
        let (reader, writer) = tokio::io::split(stream);
        Ok(StreamConnection::new(FramedRead::new(reader, TcpCodec::new(options)), writer, url))
    })
}

/// A session to another server.
pub struct RemoteServer {
    session: Arc<Session>,
    event_loop: JoinHandle<StatusCode>,
    url: String,
}

impl RemoteServer {
    /// Opens a session with SecurityPolicy None and no user (anonymous) to the server at `url` and reads its
    /// namespaces: only for servers started with `insecure`, on loopback. Connect with
    /// [`ClientConfig::connect`] otherwise (Basic256Sha256 SignAndEncrypt, a user, a PKI folder).
    pub async fn connect(url: &str) -> Result<RemoteServer, RemoteError> {
        ClientConfig::insecure().connect(url).await
    }

    /// Opens the session `config` describes to the server at `url` (what [`ClientConfig::connect`] does):
    /// on a secure policy the client's certificate is created in its PKI folder on first use, and the
    /// server's certificate must be in `trusted/` (an unknown one is refused and written to `rejected/`).
    pub(crate) async fn open(url: &str, config: &ClientConfig) -> Result<RemoteServer, RemoteError> {
        let connect_error = |s: StatusCode| RemoteError::Connect(url.to_owned(), s);
        let secure = config.policy != SecurityPolicy::None;
        if secure {
            crate::server::security::prepare_pki(&config.pki_dir, &config.application_name, &config.application_uri, &[])
                .map_err(|e| RemoteError::Pki(e.to_string()))?;
        }
        let client = ClientBuilder::new()
            .application_name(config.application_name.as_str())
            .application_uri(config.application_uri.as_str())
            .product_uri(config.application_uri.as_str())
            .pki_dir(config.pki_dir.clone())
            .create_sample_keypair(false)
            .certificate_path("own/cert.der")
            .private_key_path("private/private.pem")
            .trust_server_certs(!secure || config.trust_server_on_first_use)
            .verify_server_certs(secure)
            .session_retry_limit(3)
            .client()
            .map_err(|_| connect_error(StatusCode::BadConfigurationError))?;
        let endpoints = client.get_server_endpoints_from_url(url).await.map_err(|e| connect_error(e.status()))?;
        let (session, event_loop) = client
            .session_builder()
            .with_endpoints(endpoints)
            .connect_to_matching_endpoint((url, config.policy.to_str(), config.mode))
            .map_err(|e| connect_error(e.status()))?
            .user_identity_token(match &config.user {
                Some((user, password)) => IdentityToken::new_user_name(user.clone(), opcua::client::Password::new(password.clone())),
                None => IdentityToken::Anonymous,
            })
            .with_connector(NoDelay)
            .build(client.certificate_store().clone())
            .map_err(|e| connect_error(e.status()))?;
        // The event loop, driven here so that a failed attempt is seen: a wrong password or a refused
        // certificate is answered with its own status at once, not with BadTimeout after the retries.
        let (failed_tx, mut failed) = tokio::sync::watch::channel(None::<StatusCode>);
        let event_loop = tokio::spawn(drive(event_loop.enter(), failed_tx));
        let outcome = tokio::time::timeout(config.connect_timeout, async {
            tokio::select! {
                connected = session.wait_for_connection() => if connected { Ok(()) } else { Err(StatusCode::BadNotConnected) },
                refused = failed.wait_for(|f| f.is_some_and(refused_for_good)) => {
                    Err(refused.ok().and_then(|f| *f).unwrap_or(StatusCode::BadNotConnected))
                }
            }
        })
        .await;
        let outcome = outcome.unwrap_or_else(|_| Err(failed.borrow().unwrap_or(StatusCode::BadTimeout)));
        if let Err(status) = outcome {
            event_loop.abort();
            return Err(connect_error(status));
        }
        session.read_namespace_array().await.map_err(|e| connect_error(e.status()))?;
        Ok(RemoteServer { session, event_loop, url: url.to_owned() })
    }

    /// The session, for anything else.
    pub fn session(&self) -> &Arc<Session> {
        &self.session
    }

    /// The server's endpoint URL.
    pub fn url(&self) -> &str {
        &self.url
    }

    /// The node at `path` below the Objects folder: BrowseNames separated by `/`, each matched by its
    /// name, or by namespace URI and name when written `{uri}name`.
    pub async fn find(&self, path: &str) -> Result<NodeId, RemoteError> {
        find_path(&self.session, &ObjectId::ObjectsFolder.into(), path).await
    }

    /// The skill at `path` below the Objects folder (see [`RemoteServer::find`]), subscribed to its
    /// transition events.
    pub async fn skill(&self, path: &str) -> Result<RemoteSkill, RemoteError> {
        let node = self.find(path).await?;
        RemoteSkill::bind(self.session.clone(), node, path.rsplit('/').next().unwrap_or(path).to_owned()).await
    }

    /// Closes the session.
    pub async fn disconnect(self) {
        let _ = self.session.disconnect().await;
        let _ = tokio::time::timeout(Duration::from_secs(5), self.event_loop).await;
    }
}

/// Polls a session's event loop until it ends (its status), telling `failed` the status of each attempt to
/// (re)connect that failed.
async fn drive<S>(events: S, failed: tokio::sync::watch::Sender<Option<StatusCode>>) -> StatusCode
where
    S: futures_core::Stream<Item = Result<SessionPollResult, StatusCode>> + Send + 'static,
{
    let mut events = Box::pin(events);
    loop {
        match std::future::poll_fn(|cx| events.as_mut().poll_next(cx)).await {
            Some(Ok(SessionPollResult::ReconnectFailed(status))) => {
                failed.send_replace(Some(status));
            }
            Some(Ok(_)) => {}
            Some(Err(status)) => break status,
            None => break StatusCode::Good,
        }
    }
}

/// Whether a failed attempt to open a session will fail again however often it is retried: the server
/// refused the user or a certificate, or the security checks failed (a network error may pass).
fn refused_for_good(status: StatusCode) -> bool {
    [
        StatusCode::BadUserAccessDenied,
        StatusCode::BadIdentityTokenInvalid,
        StatusCode::BadIdentityTokenRejected,
        StatusCode::BadSecurityChecksFailed,
        StatusCode::BadSecurityPolicyRejected,
        StatusCode::BadCertificateInvalid,
        StatusCode::BadCertificateUntrusted,
        StatusCode::BadCertificateUriInvalid,
        StatusCode::BadCertificateTimeInvalid,
        StatusCode::BadCertificateRevoked,
        StatusCode::BadCertificateUseNotAllowed,
        StatusCode::BadCertificateHostNameInvalid,
    ]
    .contains(&status)
}

/// The forward hierarchical children of a node: (BrowseName, NodeId).
pub(crate) async fn children(session: &Session, node: &NodeId) -> Result<Vec<(QualifiedName, NodeId)>, RemoteError> {
    let description = BrowseDescription {
        node_id: node.clone(),
        browse_direction: BrowseDirection::Forward,
        reference_type_id: ReferenceTypeId::HierarchicalReferences.into(),
        include_subtypes: true,
        node_class_mask: NodeClassMask::all().bits(),
        result_mask: BrowseResultMask::All as u32,
    };
    let mut results = session.browse(&[description], 0, None).await.map_err(|e| RemoteError::Service("Browse", e.status()))?;
    let result = results.pop().ok_or(RemoteError::Service("Browse", StatusCode::BadUnexpectedError))?;
    if result.status_code.is_bad() {
        return Err(RemoteError::Service("Browse", result.status_code));
    }
    let mut out: Vec<_> =
        result.references.unwrap_or_default().into_iter().map(|r| (r.browse_name, r.node_id.node_id)).collect();
    let mut point = result.continuation_point;
    while !point.is_null() {
        let mut next =
            session.browse_next(false, &[point.clone()]).await.map_err(|e| RemoteError::Service("BrowseNext", e.status()))?;
        let Some(r) = next.pop() else { break };
        out.extend(r.references.unwrap_or_default().into_iter().map(|r| (r.browse_name, r.node_id.node_id)));
        point = r.continuation_point;
    }
    Ok(out)
}

/// The node at `path` (see [`RemoteServer::find`]) below `start`.
pub(crate) async fn find_below(session: &Session, start: &NodeId, path: &str) -> Result<NodeId, RemoteError> {
    find_path(session, start, path).await
}

async fn find_path(session: &Session, start: &NodeId, path: &str) -> Result<NodeId, RemoteError> {
    let mut node = start.clone();
    let mut walked = String::new();
    for segment in segments(path) {
        let (ns, name) = match segment.strip_prefix('{').and_then(|s| s.split_once('}')) {
            Some((uri, name)) => (Some(session.get_namespace_index_from_cache(uri).unwrap_or(u16::MAX)), name),
            None => (None, segment),
        };
        let kids = children(session, &node).await?;
        let hits: Vec<&NodeId> = kids
            .iter()
            .filter(|(b, _)| b.name.as_ref() == name && ns.is_none_or(|ns| b.namespace_index == ns))
            .map(|(_, id)| id)
            .collect();
        let below = if walked.is_empty() { "Objects".to_owned() } else { walked.clone() };
        match hits.as_slice() {
            [one] => node = (*one).clone(),
            _ => return Err(RemoteError::Path { below, segment: segment.to_owned(), matches: hits.len() }),
        }
        if !walked.is_empty() {
            walked.push('/');
        }
        walked.push_str(segment);
    }
    Ok(node)
}

/// The segments of a browse path: split at `/`, except inside `{uri}`.
pub(crate) fn segments(path: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let (mut start, mut depth) = (0, 0usize);
    for (i, c) in path.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth = depth.saturating_sub(1),
            '/' if depth == 0 => {
                out.push(&path[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&path[start..]);
    out.retain(|s| !s.is_empty());
    out
}

/// The event fields a remote skill's subscription selects: ToState/Id and ToState.
fn to_state_clauses() -> Vec<SimpleAttributeOperand> {
    [vec!["ToState", "Id"], vec!["ToState"]]
        .into_iter()
        .map(|path| SimpleAttributeOperand {
            type_definition_id: ObjectTypeId::BaseEventType.into(),
            browse_path: Some(path.into_iter().map(|n| QualifiedName::new(0, n)).collect()),
            attribute_id: AttributeId::Value as u32,
            index_range: Default::default(),
        })
        .collect()
}

/// A program state from a transition event's ToState (its Id for ProgramStateMachineType's states, else its
/// name).
fn program_state(id: &Variant, name: &Variant) -> Option<ProgramState> {
    if let Variant::NodeId(id) = id {
        let by_id = [(2400, ProgramState::Ready), (2402, ProgramState::Running), (2404, ProgramState::Suspended), (2406, ProgramState::Halted)];
        if let Some((_, s)) = by_id.iter().find(|(n, _)| **id == NodeId::new(0, *n as u32)) {
            return Some(*s);
        }
    }
    let Variant::LocalizedText(text) = name else { return None };
    [ProgramState::Ready, ProgramState::Running, ProgramState::Suspended, ProgramState::Halted]
        .into_iter()
        .find(|s| text.text.as_ref() == s.name())
}

/// A skill of another server, found and subscribed to.
pub struct RemoteSkill {
    session: Arc<Session>,
    node: NodeId,
    name: String,
    current_state: NodeId,
    methods: BTreeMap<&'static str, NodeId>,
    inputs: Vec<(QualifiedName, NodeId)>,
    outputs: Vec<(QualifiedName, NodeId)>,
    result: Option<NodeId>,
    states: Mutex<mpsc::UnboundedReceiver<ProgramState>>,
}

impl RemoteSkill {
    async fn bind(session: Arc<Session>, node: NodeId, name: String) -> Result<RemoteSkill, RemoteError> {
        let missing = |what: &str| RemoteError::Missing { skill: name.clone(), what: what.to_owned() };
        let kids = children(&session, &node).await?;
        let child = |n: &str| kids.iter().find(|(b, _)| b.namespace_index == 0 && b.name.as_ref() == n).map(|(_, id)| id.clone());
        let any_ns = |n: &str| kids.iter().find(|(b, _)| b.name.as_ref() == n).map(|(_, id)| id.clone());
        let current_state = child("CurrentState").ok_or_else(|| missing("CurrentState"))?;
        let mut methods = BTreeMap::new();
        for m in ["Start", "Suspend", "Resume", "Halt", "Reset"] {
            if let Some(id) = child(m) {
                methods.insert(m, id);
            }
        }
        for m in ["Start", "Halt"] {
            if !methods.contains_key(m) {
                return Err(missing(&format!("method {m}")));
            }
        }
        let inputs = match any_ns("InputParameterSet") {
            Some(set) => children(&session, &set).await?,
            None => Vec::new(),
        };
        let outputs = match any_ns("OutputParameterSet") {
            Some(set) => children(&session, &set).await?,
            None => Vec::new(),
        };
        let result = outputs.iter().find(|(b, _)| b.name.as_ref() == "Result").map(|(_, id)| id.clone());

        // The skill's transition events, as the states they enter.
        let (tx, rx) = mpsc::unbounded_channel();
        let callbacks = SubscriptionCallbacks::new(
            |_| {},
            |_: DataValue, _: &MonitoredItem| {},
            move |fields: Option<Vec<Variant>>, _: &MonitoredItem| {
                let fields = fields.unwrap_or_default();
                if let (Some(id), Some(text)) = (fields.first(), fields.get(1)) {
                    if let Some(state) = program_state(id, text) {
                        let _ = tx.send(state);
                    }
                }
            },
        );
        let subscription = session
            .create_subscription(Duration::from_millis(10), 600, 20, 0, 0, true, callbacks)
            .await
            .map_err(|e| RemoteError::Service("CreateSubscription", e.status()))?;
        let filter = EventFilter { select_clauses: Some(to_state_clauses()), where_clause: ContentFilter::default() };
        let item = MonitoredItemCreateRequest {
            item_to_monitor: ReadValueId { node_id: node.clone(), attribute_id: AttributeId::EventNotifier as u32, ..Default::default() },
            monitoring_mode: MonitoringMode::Reporting,
            requested_parameters: MonitoringParameters {
                client_handle: 1,
                sampling_interval: 0.0,
                filter: ExtensionObject::from_message(filter),
                queue_size: 100,
                discard_oldest: false,
            },
        };
        let created = session
            .create_monitored_items(subscription, TimestampsToReturn::Neither, vec![item])
            .await
            .map_err(|e| RemoteError::Service("CreateMonitoredItems", e.status()))?;
        if let Some(bad) = created.iter().map(|c| c.result.status_code).find(|s| s.is_bad()) {
            return Err(RemoteError::Service("CreateMonitoredItems", bad));
        }
        Ok(RemoteSkill { session, node, name, current_state, methods, inputs, outputs, result, states: Mutex::new(rx) })
    }

    /// The skill's node on its server.
    pub fn node(&self) -> &NodeId {
        &self.node
    }

    /// The skill's BrowseName (name part), as the path named it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The skill's state now, read from CurrentState.
    pub async fn state(&self) -> Result<Option<ProgramState>, RemoteError> {
        let id = ReadValueId { node_id: self.current_state.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() };
        let mut values = self.session.read(&[id], TimestampsToReturn::Neither, 0.0).await.map_err(|e| RemoteError::Service("Read", e.status()))?;
        let value = values.pop().and_then(|v| v.value).unwrap_or_default();
        Ok(program_state(&Variant::Empty, &value))
    }

    /// Calls one of the skill's methods (`Start`, `Halt`, ...); the method's status.
    pub async fn call(&self, method: &str) -> Result<StatusCode, RemoteError> {
        let Some(id) = self.methods.get(method) else { return Ok(StatusCode::BadMethodInvalid) };
        let result = self
            .session
            .call_one((self.node.clone(), id.clone(), None::<Vec<Variant>>))
            .await
            .map_err(|e| RemoteError::Service("Call", e.status()))?;
        Ok(result.status_code)
    }

    /// Writes the inputs (the variables of `InputParameterSet`, matched by BrowseName); the first bad
    /// status of the writes, or Good.
    pub async fn write_inputs<I: Parameters>(&self, inputs: I) -> Result<StatusCode, RemoteError> {
        let values: Vec<(&str, Variant)> =
            I::NAMES.iter().zip(inputs.into_values()).filter_map(|((_, name), v)| Some((*name, v?))).collect();
        self.write_values(&values).await
    }

    async fn write_values(&self, values: &[(&str, Variant)]) -> Result<StatusCode, RemoteError> {
        let mut writes = Vec::new();
        for (name, value) in values {
            let node = self
                .inputs
                .iter()
                .find(|(b, _)| b.name.as_ref() == *name)
                .map(|(_, id)| id.clone())
                .ok_or_else(|| RemoteError::Missing { skill: self.name.clone(), what: format!("input {name}") })?;
            writes.push(WriteValue {
                node_id: node,
                attribute_id: AttributeId::Value as u32,
                value: DataValue::value_only(value.clone()),
                ..Default::default()
            });
        }
        let results = self.session.write(&writes).await.map_err(|e| RemoteError::Service("Write", e.status()))?;
        Ok(results.into_iter().find(|s| s.is_bad()).unwrap_or(StatusCode::Good))
    }

    /// Reads the outputs (the variables of `OutputParameterSet`, matched by BrowseName).
    pub async fn read_outputs<O: Parameters>(&self) -> Result<Result<O, StatusCode>, RemoteError> {
        let ids: Vec<Option<NodeId>> = O::NAMES
            .iter()
            .map(|(_, name)| self.outputs.iter().find(|(b, _)| b.name.as_ref() == *name).map(|(_, id)| id.clone()))
            .collect();
        let reads: Vec<ReadValueId> = ids
            .iter()
            .flatten()
            .map(|id| ReadValueId { node_id: id.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() })
            .collect();
        let mut values = self.session.read(&reads, TimestampsToReturn::Neither, 0.0).await.map_err(|e| RemoteError::Service("Read", e.status()))?.into_iter();
        let values: Vec<Option<Variant>> = ids.iter().map(|id| id.as_ref().and_then(|_| values.next()).and_then(|v| v.value)).collect();
        Ok(O::from_values(&values).map_err(|(_, s)| s))
    }

    /// Why the skill halted: its `Result` output, or `BadInvalidState` if it has none (or it is Good).
    async fn cause(&self) -> StatusCode {
        let Some(result) = &self.result else { return StatusCode::BadInvalidState };
        let id = ReadValueId { node_id: result.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() };
        match self.session.read(&[id], TimestampsToReturn::Neither, 0.0).await {
            Ok(mut v) => match v.pop().and_then(|v| v.value) {
                Some(Variant::StatusCode(s)) if s.is_bad() => s,
                _ => StatusCode::BadInvalidState,
            },
            Err(_) => StatusCode::BadInvalidState,
        }
    }

    /// Runs the skill as a step of the composite whose body got `ctl`: writes the inputs, calls Start and
    /// follows the skill until it ends (see the module docs). `Ok` when it ends in Ready, the status the
    /// composite should halt with otherwise.
    pub async fn run<I: Parameters>(&self, inputs: I, ctl: &Control) -> Result<(), StatusCode> {
        let mut states = self.states.lock().await;
        while states.try_recv().is_ok() {}
        // Start; a server that cannot be reached suspends the composite until a client resumes it.
        let values: Vec<(&str, Variant)> =
            I::NAMES.iter().zip(inputs.into_values()).filter_map(|((_, name), v)| Some((*name, v?))).collect();
        loop {
            ctl.checkpoint().await;
            let started = async {
                let written = self.write_values(&values).await?;
                if written.is_bad() {
                    return Ok(written);
                }
                self.call("Start").await
            };
            // A server that is gone may not fail a request at once: the session waits for a reconnection.
            let started = tokio::time::timeout(REQUEST_TIMEOUT, started)
                .await
                .unwrap_or(Err(RemoteError::Service("Start", StatusCode::BadTimeout)));
            match started {
                Ok(s) if s.is_good() => break,
                Ok(s) => return Err(s),
                Err(e) => {
                    tracing::warn!("skill {} is unavailable ({e}); the composite suspends", self.name);
                    let _ = ctl.suspend();
                }
            }
        }
        // From here on, dropping this future (a Halt or Reset of the composite) halts the skill.
        let guard = HaltOnDrop { skill: Some((self.session.clone(), self.node.clone(), self.methods["Halt"].clone())) };
        let mut composite = ctl.watch();
        let mut basic = ProgramState::Running;
        // Without events for a while, CurrentState is read: it finds a server that went away (the
        // composite halts: what the basic skill did is unknown) and a state whose event was lost.
        let mut quiet = tokio::time::interval_at(tokio::time::Instant::now() + LIVENESS, LIVENESS);
        let outcome = loop {
            tokio::select! {
                next = states.recv() => {
                    quiet.reset();
                    if next.is_none() {
                        break Err(StatusCode::BadCommunicationError);
                    }
                    // An event says the skill changed state; CurrentState says to which. (An event of a
                    // transition before this run's Start can arrive after it: its state is not the skill's.)
                    let state = match tokio::time::timeout(REQUEST_TIMEOUT, self.state()).await {
                        Ok(Ok(Some(state))) => state,
                        Ok(Ok(None)) => continue,
                        Ok(Err(_)) | Err(_) => break Err(StatusCode::BadCommunicationError),
                    };
                    let before = std::mem::replace(&mut basic, state);
                    match state {
                        ProgramState::Ready => break Ok(()),
                        ProgramState::Halted => break Err(self.cause().await),
                        // The skill has just been suspended: the composite follows (once; a client may
                        // resume the composite while the skill stays suspended).
                        ProgramState::Suspended if before != ProgramState::Suspended && ctl.state() == ProgramState::Running => {
                            let _ = ctl.suspend();
                        }
                        _ => {}
                    }
                }
                _ = quiet.tick() => {
                    match tokio::time::timeout(REQUEST_TIMEOUT, self.state()).await {
                        Ok(Ok(Some(ProgramState::Ready))) if basic != ProgramState::Ready => {
                            tracing::warn!("skill {} is Ready, but its transition event did not arrive", self.name);
                            break Ok(());
                        }
                        Ok(Ok(Some(ProgramState::Halted))) => break Err(self.cause().await),
                        Ok(Ok(_)) => {}
                        Ok(Err(e)) => {
                            tracing::warn!("skill {} cannot be read ({e}); the composite halts", self.name);
                            break Err(StatusCode::BadCommunicationError);
                        }
                        Err(_) => {
                            tracing::warn!("skill {} does not answer; the composite halts", self.name);
                            break Err(StatusCode::BadCommunicationError);
                        }
                    }
                }
                changed = composite.changed() => {
                    if changed.is_err() {
                        break Err(StatusCode::BadShutdown);
                    }
                    let now = *composite.borrow_and_update();
                    match (now, basic) {
                        (ProgramState::Suspended, ProgramState::Running) => {
                            let _ = self.call("Suspend").await;
                        }
                        (ProgramState::Running, ProgramState::Suspended) => {
                            let _ = self.call("Resume").await;
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

/// Halts a remote skill if the run that started it is dropped before it ended.
struct HaltOnDrop {
    skill: Option<(Arc<Session>, NodeId, NodeId)>,
}

impl HaltOnDrop {
    fn disarm(mut self) {
        self.skill = None;
    }
}

impl Drop for HaltOnDrop {
    fn drop(&mut self) {
        if let Some((session, node, halt)) = self.skill.take() {
            // Drop cannot wait; the call runs on its own (there is a runtime: the body was running on it).
            if let Ok(rt) = tokio::runtime::Handle::try_current() {
                rt.spawn(async move {
                    let _ = session.call_one((node, halt, None::<Vec<Variant>>)).await;
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use opcua::types::LocalizedText;

    #[test]
    fn browse_paths_split_outside_namespace_uris() {
        assert_eq!(segments("DeviceSet/Robot/SkillSet/Move"), ["DeviceSet", "Robot", "SkillSet", "Move"]);
        assert_eq!(segments("{http://x/A/}Cell//SkillSet/"), ["{http://x/A/}Cell", "SkillSet"]);
        assert!(segments("").is_empty());
    }

    #[test]
    fn transition_events_map_to_program_states() {
        let text = |s: &str| Variant::from(LocalizedText::from(s));
        assert_eq!(program_state(&Variant::from(NodeId::new(0, 2402u32)), &Variant::Empty), Some(ProgramState::Running));
        assert_eq!(program_state(&Variant::from(NodeId::new(0, 2406u32)), &text("Ready")), Some(ProgramState::Halted), "the Id wins");
        assert_eq!(program_state(&Variant::from(NodeId::new(3, 2400u32)), &text("Suspended")), Some(ProgramState::Suspended));
        assert_eq!(program_state(&Variant::Empty, &text("Idle")), None);
    }
}
