//! Sessions to other servers, and what the body of a composite skill needs to run their skills.
//!
//! [`ClientConfig::connect`] (or [`RemoteServer::connect`] for an `--insecure` server on loopback) opens a
//! session; [`RemoteServer::program`] binds a skill by its browse path below the Objects folder (no NodeId
//! is written down anywhere: names are looked up by browsing, namespaces through the server's
//! NamespaceArray) as the generated type's typed client ([`crate::client::RemoteProgram`]), and
//! [`RemoteProgram::run_step`](crate::client::RemoteProgram::run_step) writes its typed inputs, calls Start
//! and follows its CurrentState until it ends:
//!
//! ```text
//! let robot = ClientConfig::new(pki).user("cell", password).connect("opc.tcp://127.0.0.1:4861/").await?;
//! let move_in = robot.program::<RelativeCartesianLinearMoveSkillType>("DeviceSet/TemplateDrillingLwrSystem/MotionDeviceSystem/Controllers/URController/SkillSet/RelativeCartesianLinearMove").await?;
//! let drill_hole = cell.serve(move |inputs: DrillHoleSkillTypeInputs, ctl| async move {
//!     move_in.run_step(RelativeCartesianLinearMoveSkillTypeInputs { .. }, &ctl).await?;   // Err: the composite halts
//!     ...
//! })?;
//! ```
//!
//! While a basic skill runs, the composite follows it as the Commands2 paper asks ("if one of the basic
//! skills is unavailable or is in Halted state, the composite skill also needs to go into Suspended or
//! Halted state"):
//!
//! - the basic skill ends in Ready: `run_step` returns `Ok`;
//! - it ends in Halted: `run_step` returns its `Result` output (the cause), or `BadInvalidState` if it has
//!   none, so the composite's body returns it and the composite halts with the same cause;
//! - it is suspended: the composite suspends itself; a client's Resume of the composite resumes it;
//! - the composite is suspended (a client's Suspend): the basic skill is suspended too (where it has a
//!   Suspend method), and resumed with the composite;
//! - the composite is halted or reset while the basic skill runs (its body is dropped): the basic skill is
//!   halted;
//! - the server of the basic skill cannot be reached when the run starts (a transport error or no answer
//!   within 3 s, not a status of the skill): the composite suspends itself and tries again when a client
//!   resumes it;
//! - the server of the basic skill goes away while the skill runs (no change of CurrentState for a second,
//!   and CurrentState cannot be read within 3 s): `run_step` returns `BadCommunicationError`, so the
//!   composite halts; what the basic skill did is unknown, so the composite does not go on by itself. A
//!   change whose notification is lost (the skill is Ready or Halted, but no notification said so) is found
//!   by the same read.

use std::future::Future;
use std::path::PathBuf;
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

use opcua::client::{ClientBuilder, IdentityToken, Session, SessionPollResult};
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    BrowseDescription, BrowseDirection, BrowsePath, BrowseResultMask, MessageSecurityMode, NodeClassMask, NodeId, ObjectId,
    QualifiedName, ReferenceTypeId, RelativePath, RelativePathElement, StatusCode,
};
use tokio::task::JoinHandle;


/// How a client connects: the security policy and mode, the user, the client's PKI folder and its
/// application name and URI. Every client of the runtime (typed handles and composite skills) connects
/// through it ([`ClientConfig::connect`]); one configuration serves any number of servers.
///
/// Secure by default: [`ClientConfig::new`] is Basic256Sha256 with SignAndEncrypt, and the server's
/// certificate must be in the PKI folder's `trusted/` (an unknown one is refused and written to
/// `rejected/`, for an administrator to move). [`ClientConfig::insecure`] (SecurityPolicy None, anonymous)
/// is for servers started with `--insecure` on loopback.
#[derive(Clone)]
pub struct ClientConfig {
    /// The application name the session shows (and the client's certificate carries).
    pub application_name: String,
    /// The application URI of the client, which its certificate carries.
    pub application_uri: String,
    /// The security policy of the endpoint to use.
    pub policy: SecurityPolicy,
    /// The message security mode of the endpoint to use.
    pub mode: MessageSecurityMode,
    /// User name and password; `None` connects anonymously.
    pub user: Option<(String, String)>,
    /// The client's PKI folder: its certificate (`own/cert.der`, `private/private.pem`, created on first
    /// use) and the server certificates it trusts (`trusted/`) or refused (`rejected/`).
    pub pki_dir: PathBuf,
    /// Trusts an unknown server certificate (development only).
    pub trust_server_on_first_use: bool,
    /// How long the session may take to open.
    pub connect_timeout: Duration,
}

impl std::fmt::Debug for ClientConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ClientConfig")
            .field("application_name", &self.application_name)
            .field("application_uri", &self.application_uri)
            .field("policy", &self.policy)
            .field("mode", &self.mode)
            .field("user", &self.user.as_ref().map(|(name, _)| (name, "<password>")))
            .field("pki_dir", &self.pki_dir)
            .field("trust_server_on_first_use", &self.trust_server_on_first_use)
            .field("connect_timeout", &self.connect_timeout)
            .finish()
    }
}

impl ClientConfig {
    /// Basic256Sha256, SignAndEncrypt, anonymous, with the client's PKI folder at `pki_dir`.
    pub fn new(pki_dir: impl Into<PathBuf>) -> ClientConfig {
        ClientConfig {
            application_name: "nodeset-models client".into(),
            application_uri: "urn:nodeset-models:client".into(),
            policy: SecurityPolicy::Basic256Sha256,
            mode: MessageSecurityMode::SignAndEncrypt,
            user: None,
            pki_dir: pki_dir.into(),
            trust_server_on_first_use: false,
            connect_timeout: Duration::from_secs(10),
        }
    }

    /// SecurityPolicy None, anonymous: only for servers started with `insecure`, on loopback. No
    /// certificate is made or checked.
    pub fn insecure() -> ClientConfig {
        ClientConfig {
            policy: SecurityPolicy::None,
            mode: MessageSecurityMode::None,
            ..ClientConfig::new(std::env::temp_dir().join("nodeset-models-pki-remote"))
        }
    }

    /// Sets the user name and password.
    pub fn user(mut self, name: impl Into<String>, password: impl Into<String>) -> ClientConfig {
        self.user = Some((name.into(), password.into()));
        self
    }

    /// Sets the security policy and mode.
    pub fn policy(mut self, policy: SecurityPolicy, mode: MessageSecurityMode) -> ClientConfig {
        self.policy = policy;
        self.mode = mode;
        self
    }

    /// Sets the application name and URI (a PKI folder holds the certificate of one application URI).
    pub fn application(mut self, name: &str, uri: &str) -> ClientConfig {
        self.application_name = name.to_owned();
        self.application_uri = uri.to_owned();
        self
    }

    /// Trusts unknown server certificates: development only.
    pub fn trust_server_on_first_use(mut self) -> ClientConfig {
        self.trust_server_on_first_use = true;
        self
    }

    /// Sets how long the session may take to open.
    pub fn connect_timeout(mut self, timeout: Duration) -> ClientConfig {
        self.connect_timeout = timeout;
        self
    }

    /// Opens a session to the server at `url` (`opc.tcp://host:port/`) and reads its namespaces. A refusal
    /// that retrying cannot change (the user, or a certificate: `BadIdentityTokenRejected`,
    /// `BadCertificateUntrusted`, ...) fails at once with its status; a server that does not answer fails
    /// after `connect_timeout` with the status of the last attempt.
    pub async fn connect(&self, url: &str) -> Result<RemoteServer, RemoteError> {
        RemoteServer::open(url, self).await
    }
}

/// Why a remote skill could not be reached or found.
#[derive(Clone, Debug, PartialEq)]
pub enum RemoteError {
    /// The session could not be opened (the endpoint, and why).
    Connect(String, StatusCode),
    /// A service call failed.
    Service(&'static str, StatusCode),
    /// A segment of a browse path matches no child, or several.
    Path {
        /// The path so far.
        below: String,
        /// The segment.
        segment: String,
        /// How many children it matches (0, or more than one).
        matches: usize,
    },
    /// A browse path whose segments leave out their namespace leads to several nodes.
    Ambiguous {
        /// The path.
        path: String,
        /// Each match with every segment qualified, `{uri}name/...`, in order.
        matches: Vec<String>,
    },
    /// The skill lacks a node a run needs (`CurrentState`, `Start`, ...).
    Missing {
        /// The skill.
        skill: String,
        /// The node it lacks.
        what: String,
    },
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
            RemoteError::Ambiguous { path, matches } => {
                write!(f, "`{path}` leads to {} nodes; name the one meant by namespace URIs: {}", matches.len(), matches.join(", "))
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
    /// name, or by namespace URI and name when written `{uri}name`. A path of qualified segments is one
    /// TranslateBrowsePathsToNodeIds; a segment without its namespace is tried in each namespace of the
    /// server, several segments in one request (see [`RemoteServer::find_counted`]).
    pub async fn find(&self, path: &str) -> Result<NodeId, RemoteError> {
        Ok(self.find_counted(path).await?.node)
    }

    /// [`RemoteServer::find`], and how many requests (round trips) it took.
    ///
    /// The path is translated in steps. Each step is one TranslateBrowsePathsToNodeIds of at most
    /// [`PATHS_PER_REQUEST`] browse paths, which takes as many of the next segments as fit: from each node
    /// the previous step reached, every choice of namespace for those segments (one for a qualified segment,
    /// each of the server's namespaces for another), each prefix of them too, so that a path that stops
    /// names the segment where it stops. A path of qualified segments is one request; with N namespaces on
    /// the server, about log_N(100) unqualified segments go in one. Several matches are followed on; the
    /// path is [`RemoteError::Ambiguous`] only if more than one node matches it all.
    pub async fn find_counted(&self, path: &str) -> Result<Found, RemoteError> {
        find_path(&self.session, &ObjectId::ObjectsFolder.into(), path).await
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

/// The forward hierarchical children of a node with their TypeDefinitions (null for a child without
/// one), from one Browse (and BrowseNext while the server has more): (BrowseName, NodeId, TypeDefinition).
pub(crate) async fn typed_children(session: &Session, node: &NodeId) -> Result<Vec<(QualifiedName, NodeId, NodeId)>, RemoteError> {
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
    let row = |r: opcua::types::ReferenceDescription| (r.browse_name, r.node_id.node_id, r.type_definition.node_id);
    let mut out: Vec<_> = result.references.unwrap_or_default().into_iter().map(row).collect();
    let mut point = result.continuation_point;
    while !point.is_null() {
        let mut next =
            session.browse_next(false, &[point.clone()]).await.map_err(|e| RemoteError::Service("BrowseNext", e.status()))?;
        let Some(r) = next.pop() else { break };
        out.extend(r.references.unwrap_or_default().into_iter().map(row));
        point = r.continuation_point;
    }
    Ok(out)
}

/// The node at `path` (see [`RemoteServer::find`]) below `start`.
pub(crate) async fn find_below(session: &Session, start: &NodeId, path: &str) -> Result<NodeId, RemoteError> {
    Ok(find_path(session, start, path).await?.node)
}

/// What [`RemoteServer::find_counted`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    /// The node.
    pub node: NodeId,
    /// The path with every segment qualified (`{uri}name/...`): finding it again is one request.
    pub path: String,
    /// How many TranslateBrowsePathsToNodeIds requests it took (each one round trip).
    pub requests: u32,
}

/// How many browse paths one TranslateBrowsePathsToNodeIds of [`RemoteServer::find`] holds at most: the
/// default MaxNodesPerTranslateBrowsePathsToNodeIds of async-opcua servers (a larger step is sent as more
/// than one request).
pub const PATHS_PER_REQUEST: usize = 100;

/// How many nodes a path may lead to part way before it is called ambiguous.
const MAX_PARTIAL_MATCHES: usize = 100;

/// A node reached part way along a path: its NodeId and the qualified path to it (`{uri}name/...`).
type Reached = (NodeId, String);

/// [`RemoteServer::find_counted`] below `start`.
async fn find_path(session: &Session, start: &NodeId, path: &str) -> Result<Found, RemoteError> {
    let written = segments(path);
    let (uris, all): (Vec<(u16, String)>, Vec<u16>) = {
        let context = session.encoding_context().read();
        let mut uris: Vec<(u16, String)> = context.namespaces().known_namespaces().iter().map(|(u, i)| (*i, u.clone())).collect();
        uris.sort();
        let all = uris.iter().map(|(i, _)| *i).collect();
        (uris, all)
    };
    // Each segment: its name and the namespaces it may be in (none if it names a URI the server lacks).
    let wanted: Vec<(&str, Vec<u16>)> = written
        .iter()
        .map(|segment| match segment.strip_prefix('{').and_then(|s| s.split_once('}')) {
            Some((uri, name)) => (name, session.get_namespace_index_from_cache(uri).into_iter().collect()),
            None => (*segment, all.clone()),
        })
        .collect();
    let uri_of = |ns: u16| uris.iter().find(|(i, _)| *i == ns).map_or("", |(_, u)| u.as_str());
    let mut reached: Vec<Reached> = vec![(start.clone(), String::new())];
    let mut requests = 0u32;
    let mut done = 0;
    while done < wanted.len() {
        // As many segments as fit in one request (at least one).
        let (mut depth, mut total, mut product) = (0, 0usize, reached.len());
        while done + depth < wanted.len() {
            let next = product.saturating_mul(wanted[done + depth].1.len());
            if depth > 0 && total.saturating_add(next) > PATHS_PER_REQUEST {
                break;
            }
            product = next;
            total = total.saturating_add(next);
            depth += 1;
        }
        // Every (start, namespaces) combination, for each prefix length: (length, qualified path, BrowsePath).
        let mut asked: Vec<(usize, String, BrowsePath)> = Vec::new();
        for (node, qualified) in &reached {
            let mut partial: Vec<(String, Vec<RelativePathElement>)> = vec![(qualified.clone(), Vec::new())];
            for (length, (name, namespaces)) in wanted[done..done + depth].iter().enumerate() {
                let mut longer = Vec::with_capacity(partial.len() * namespaces.len());
                for (text, elements) in &partial {
                    for &ns in namespaces {
                        let mut elements = elements.clone();
                        elements.push(RelativePathElement {
                            reference_type_id: ReferenceTypeId::HierarchicalReferences.into(),
                            is_inverse: false,
                            include_subtypes: true,
                            target_name: QualifiedName::new(ns, *name),
                        });
                        let separator = if text.is_empty() { "" } else { "/" };
                        let text = format!("{text}{separator}{{{}}}{name}", uri_of(ns));
                        let request = BrowsePath {
                            starting_node: node.clone(),
                            relative_path: RelativePath { elements: Some(elements.clone()) },
                        };
                        asked.push((length + 1, text.clone(), request));
                        longer.push((text, elements));
                    }
                }
                partial = longer;
            }
        }
        // One request per PATHS_PER_REQUEST paths; each fully matched target is reached at its length.
        let mut levels: Vec<Vec<Reached>> = vec![Vec::new(); depth + 1];
        for chunk in asked.chunks(PATHS_PER_REQUEST) {
            let paths: Vec<BrowsePath> = chunk.iter().map(|(_, _, p)| p.clone()).collect();
            requests += 1;
            let results = session
                .translate_browse_paths_to_node_ids(&paths)
                .await
                .map_err(|e| RemoteError::Service("TranslateBrowsePathsToNodeIds", e.status()))?;
            for ((length, text, _), result) in chunk.iter().zip(results) {
                if !result.status_code.is_good() {
                    continue;
                }
                for target in result.targets.unwrap_or_default() {
                    if target.remaining_path_index == u32::MAX && target.target_id.server_index == 0 {
                        levels[*length].push((target.target_id.node_id, text.clone()));
                    }
                }
            }
        }
        for (length, level) in levels.iter_mut().enumerate().skip(1) {
            // In order of the qualified paths, each node once (reached along two paths, the first is kept).
            level.sort_by(|a, b| a.1.cmp(&b.1));
            let mut seen: Vec<NodeId> = Vec::with_capacity(level.len());
            level.retain(|(node, _)| !seen.contains(node) && {
                seen.push(node.clone());
                true
            });
            if level.is_empty() {
                let below = if done + length == 1 { "Objects".to_owned() } else { written[..done + length - 1].join("/") };
                return Err(RemoteError::Path { below, segment: written[done + length - 1].to_owned(), matches: 0 });
            }
        }
        reached = levels.pop().unwrap_or_default();
        done += depth;
        if reached.len() > MAX_PARTIAL_MATCHES && done < wanted.len() {
            return Err(RemoteError::Ambiguous {
                path: written[..done].join("/"),
                matches: reached.into_iter().map(|(_, text)| text).collect(),
            });
        }
    }
    match reached.len() {
        1 => {
            let (node, path) = reached.remove(0);
            Ok(Found { node, path, requests })
        }
        _ => Err(RemoteError::Ambiguous { path: path.to_owned(), matches: reached.into_iter().map(|(_, text)| text).collect() }),
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn browse_paths_split_outside_namespace_uris() {
        assert_eq!(segments("DeviceSet/Robot/SkillSet/Move"), ["DeviceSet", "Robot", "SkillSet", "Move"]);
        assert_eq!(segments("{http://x/A/}Cell//SkillSet/"), ["{http://x/A/}Cell", "SkillSet"]);
        assert!(segments("").is_empty());
    }

    #[test]
    fn a_client_config_is_secure_by_default_and_does_not_show_the_password() {
        let config = ClientConfig::new("pki/client").user("op", "s3cret-pass");
        assert_eq!((config.policy, config.mode), (SecurityPolicy::Basic256Sha256, MessageSecurityMode::SignAndEncrypt));
        assert!(!config.trust_server_on_first_use);
        assert_eq!(config.pki_dir, PathBuf::from("pki/client"));
        let shown = format!("{config:?}");
        assert!(shown.contains("\"op\"") && !shown.contains("s3cret-pass"), "{shown}");
        let none = ClientConfig::insecure();
        assert_eq!((none.policy, none.mode, none.user), (SecurityPolicy::None, MessageSecurityMode::None, None));
    }
}
