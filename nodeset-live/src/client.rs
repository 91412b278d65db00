//! The client a simulation runs (interactive simulation and control): a session to a real server, secure
//! by default, through which read blocks read and write blocks write by NodeId, or by browse path from the
//! ObjectsFolder (`Robot/Controllers/Controller/...`, translated by the server at the first call of each
//! session and kept: a server whose NodeIds differ from the nodesets' is still reached).
//!
//! A sampled call never waits for a connection: while there is none, calls fail at once with
//! `BadNotConnected` and the reason, and a task of the client's own runtime connects again every
//! [`RETRY`]. A call that finds the connection lost (a communication status, or no answer within
//! [`CALL_TIMEOUT`]) reports it and starts that task.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};

use nodeset_runtime::client::ClientConfig;
use nodeset_runtime::remote::{RemoteError, RemoteServer};
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    AttributeId, DataValue, MessageSecurityMode, NodeId, ReadValueId, StatusCode,
    TimestampsToReturn, Variant, WriteValue,
};

use crate::value::{candidates, from_variant, Builtin, Failure, Kind, NodeRef, Value};

/// How long a sampled read or write may take before the connection counts as lost.
pub const CALL_TIMEOUT: Duration = Duration::from_secs(3);
/// How long opening a session may take (at construction, and each retry).
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);
/// The pause between attempts to connect again.
pub const RETRY: Duration = Duration::from_millis(500);

/// What the client constructor is given (the parameters of `OpcUaSupport.Live.Client`).
#[derive(Clone, Debug)]
pub struct ClientParams {
    /// The endpoint URL, `opc.tcp://host:port/`.
    pub url: String,
    /// The security policy (`Basic256Sha256`, `Aes128_Sha256_RsaOaep`, `Aes256_Sha256_RsaPss`, `None`);
    /// empty for Basic256Sha256.
    pub policy: String,
    /// The message security mode (`SignAndEncrypt`, `Sign`, `None`); empty for SignAndEncrypt.
    pub mode: String,
    /// The client's PKI folder (its certificate, created on first use; the server certificates it trusts).
    pub pki_dir: PathBuf,
    /// The user name; empty for an anonymous session.
    pub user: String,
    /// The name of the environment variable that holds the user's password (never the password itself).
    pub password_env: String,
}

enum Link {
    Up(Arc<RemoteServer>),
    Down { why: String, retrying: bool },
}

struct Shared {
    link: Mutex<Link>,
}

/// A client object.
pub struct LiveClient {
    runtime: tokio::runtime::Runtime,
    url: String,
    config: ClientConfig,
    /// The client's PKI folder, named in the messages about certificates.
    pki_dir: PathBuf,
    /// When the object was made: a certificate rejected since was rejected by this client.
    created: SystemTime,
    shared: Arc<Shared>,
    /// Each block's NodeId, resolved against the namespaces of the current session (cleared on reconnect),
    /// with the built-in type of the variable's value once known.
    nodes: Mutex<HashMap<String, (NodeId, Option<Builtin>)>>,
}

/// Reads the configuration a client object is made from: a bad policy or mode, or a password variable
/// that is not set, fails here (no connection is tried).
pub fn config(params: &ClientParams) -> Result<ClientConfig, Failure> {
    let bad = |m: String| Failure::new(StatusCode::BadConfigurationError, m);
    let policy = match params.policy.as_str() {
        "" => SecurityPolicy::Basic256Sha256,
        p => match SecurityPolicy::from_str(p) {
            Ok(SecurityPolicy::Unknown) | Err(()) => {
                return Err(bad(format!(
                    "unknown security policy `{p}`: use Basic256Sha256, Aes128_Sha256_RsaOaep, Aes256_Sha256_RsaPss or None"
                )))
            }
            Ok(p) => p,
        },
    };
    let mode = match params.mode.as_str() {
        "" | "SignAndEncrypt" => MessageSecurityMode::SignAndEncrypt,
        "Sign" => MessageSecurityMode::Sign,
        "None" => MessageSecurityMode::None,
        m => {
            return Err(bad(format!(
                "unknown security mode `{m}`: use SignAndEncrypt, Sign or None"
            )))
        }
    };
    if (policy == SecurityPolicy::None) != (mode == MessageSecurityMode::None) {
        return Err(bad(format!(
            "security policy {} and mode {mode:?} do not go together: None goes with None",
            policy.to_str()
        )));
    }
    let mut config = ClientConfig::new(&params.pki_dir)
        .policy(policy, mode)
        .application("Modelica simulation client", "urn:nodeset-live:client")
        .connect_timeout(CONNECT_TIMEOUT);
    if !params.user.is_empty() {
        if params.password_env.is_empty() {
            return Err(bad(format!("user `{}` has no password variable: name the environment variable that holds the password", params.user)));
        }
        let password = std::env::var(&params.password_env).map_err(|_| {
            bad(format!("the environment variable `{}`, which should hold the password of user `{}`, is not set", params.password_env, params.user))
        })?;
        config = config.user(params.user.clone(), password);
    }
    Ok(config)
}

impl LiveClient {
    /// Makes the client and tries to connect once; a failed attempt is kept as the reason calls fail and
    /// retried in the background.
    pub fn start(params: &ClientParams) -> Result<LiveClient, Failure> {
        let config = config(params)?;
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .thread_name("opcua-live-client")
            .enable_all()
            .build()
            .map_err(|e| {
                Failure::new(
                    StatusCode::BadConfigurationError,
                    format!("cannot start the client's threads: {e}"),
                )
            })?;
        let created = SystemTime::now();
        let first = runtime.block_on(config.connect(&params.url));
        let link = match first {
            Ok(server) => Link::Up(Arc::new(server)),
            Err(e) => Link::Down {
                why: explain(&e, &params.pki_dir, created),
                retrying: false,
            },
        };
        let client = LiveClient {
            runtime,
            url: params.url.clone(),
            config,
            pki_dir: params.pki_dir.clone(),
            created,
            shared: Arc::new(Shared {
                link: Mutex::new(link),
            }),
            nodes: Mutex::new(HashMap::new()),
        };
        let _ = client.session();
        Ok(client)
    }

    /// Ok when a session is open, else why not (and the reconnecting task started).
    pub fn check(&self) -> Result<(), Failure> {
        self.session().map(|_| ())
    }

    /// Whether a session is open.
    pub fn connected(&self) -> bool {
        matches!(
            *self.shared.link.lock().unwrap_or_else(|p| p.into_inner()),
            Link::Up(_)
        )
    }

    /// The session, or why there is none (and the reconnecting task started if it is not running).
    fn session(&self) -> Result<Arc<RemoteServer>, Failure> {
        let mut link = self.shared.link.lock().unwrap_or_else(|p| p.into_inner());
        match &mut *link {
            Link::Up(s) => Ok(s.clone()),
            Link::Down { why, retrying } => {
                let message = format!(
                    "not connected to {}: {why}; connecting again every {} ms",
                    self.url,
                    RETRY.as_millis()
                );
                if !*retrying {
                    *retrying = true;
                    self.runtime.spawn(reconnect(
                        self.shared.clone(),
                        self.config.clone(),
                        self.url.clone(),
                        self.pki_dir.clone(),
                        self.created,
                    ));
                }
                Err(Failure::new(StatusCode::BadNotConnected, message))
            }
        }
    }

    /// Marks the session `lost` as gone (unless a new one replaced it already) and starts connecting again.
    fn lost(&self, lost: &Arc<RemoteServer>, why: String) {
        {
            let mut link = self.shared.link.lock().unwrap_or_else(|p| p.into_inner());
            if matches!(&*link, Link::Up(s) if Arc::ptr_eq(s, lost)) {
                *link = Link::Down {
                    why,
                    retrying: false,
                };
            }
        }
        self.nodes.lock().unwrap_or_else(|p| p.into_inner()).clear();
        let _ = self.session();
    }

    fn node(
        &self,
        session: &Arc<RemoteServer>,
        text: &str,
    ) -> Result<(NodeId, Option<Builtin>), Failure> {
        if let Some(hit) = self
            .nodes
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get(text)
        {
            return Ok(hit.clone());
        }
        if is_browse_path(text) {
            let id = self.find(session, text)?;
            self.nodes
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .insert(text.to_owned(), (id.clone(), None));
            return Ok((id, None));
        }
        let parsed = NodeRef::parse(text)?;
        let id = {
            let context = session.session().encoding_context().read();
            parsed.resolve(context.namespaces(), text)?
        };
        Ok((id, None))
    }

    /// The node at a browse path from the ObjectsFolder, translated by the server (once per session: the
    /// caller keeps it with the block's text until the connection is lost).
    fn find(&self, session: &Arc<RemoteServer>, path: &str) -> Result<NodeId, Failure> {
        let s = session.clone();
        let owned = path.to_owned();
        let outcome = self.runtime.block_on(async move {
            tokio::time::timeout(CALL_TIMEOUT, async move { s.find(&owned).await }).await
        });
        let status = match outcome {
            Ok(Ok(id)) => return Ok(id),
            Ok(Err(RemoteError::Service(_, status))) if !lost_connection(status) => status,
            Ok(Err(RemoteError::Service(_, status))) => {
                self.lost(session, format!("the connection was lost ({status})"));
                return Err(Failure::new(status, format!("finding `{path}` on {}: {status}: the connection is lost; connecting again every {} ms", self.url, RETRY.as_millis())));
            }
            Ok(Err(e)) => {
                return Err(Failure::new(
                    StatusCode::BadNoMatch,
                    format!("finding `{path}` on {}: {e}", self.url),
                ))
            }
            Err(_) => {
                self.lost(session, "the connection was lost (BadTimeout)".into());
                return Err(Failure::new(StatusCode::BadTimeout, format!("finding `{path}` on {}: no answer within {} ms: the connection is lost; connecting again every {} ms", self.url, CALL_TIMEOUT.as_millis(), RETRY.as_millis())));
            }
        };
        Err(Failure::new(
            status,
            format!("finding `{path}` on {}: {status}", self.url),
        ))
    }

    /// One service call with the timeout; a communication failure marks the connection lost.
    fn call<T>(
        &self,
        session: &Arc<RemoteServer>,
        what: &str,
        fut: impl std::future::Future<Output = Result<T, opcua::types::Error>>,
    ) -> Result<T, Failure> {
        let outcome = self
            .runtime
            .block_on(async { tokio::time::timeout(CALL_TIMEOUT, fut).await });
        let status = match outcome {
            Ok(Ok(v)) => return Ok(v),
            Ok(Err(e)) => e.status(),
            Err(_) => StatusCode::BadTimeout,
        };
        let message = format!("{what} on {}: {status}", self.url);
        if lost_connection(status) {
            self.lost(session, format!("the connection was lost ({status})"));
            return Err(Failure::new(
                status,
                format!(
                    "{message}: the connection is lost; connecting again every {} ms",
                    RETRY.as_millis()
                ),
            ));
        }
        Err(Failure::new(status, message))
    }

    /// Reads a variable's value.
    pub fn read(&self, text: &str, kind: Kind) -> Result<Value, Failure> {
        let session = self.session()?;
        let (id, known) = self.node(&session, text)?;
        let request = ReadValueId {
            node_id: id.clone(),
            attribute_id: AttributeId::Value as u32,
            ..Default::default()
        };
        let s = session.session().clone();
        let mut values = self.call(&session, &format!("reading `{text}`"), async move {
            s.read(&[request], TimestampsToReturn::Neither, 0.0).await
        })?;
        let value: DataValue = values.pop().unwrap_or_default();
        if let Some(status) = value.status.filter(|s| s.is_bad()) {
            let hint = if status == StatusCode::BadNodeIdUnknown {
                ": the server has no such node"
            } else {
                ""
            };
            return Err(Failure::new(
                status,
                format!("reading `{text}`: {status}{hint}"),
            ));
        }
        let variant = value.value.unwrap_or(Variant::Empty);
        let builtin = known.or_else(|| Builtin::of(&variant));
        self.nodes
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .insert(text.to_owned(), (id, builtin));
        from_variant(&variant, kind).map_err(|m| {
            Failure::new(
                StatusCode::BadTypeMismatch,
                format!("reading `{text}`: {m}"),
            )
        })
    }

    /// Writes a value as the built-in type of the variable's value (read once, at the first write).
    pub fn write(&self, text: &str, value: Value) -> Result<(), Failure> {
        let session = self.session()?;
        let (id, mut known) = self.node(&session, text)?;
        if known.is_none() {
            let request = ReadValueId {
                node_id: id.clone(),
                attribute_id: AttributeId::DataType as u32,
                ..Default::default()
            };
            let s = session.session().clone();
            let mut values = self.call(
                &session,
                &format!("reading the DataType of `{text}`"),
                async move { s.read(&[request], TimestampsToReturn::Neither, 0.0).await },
            )?;
            let data_type = values.pop().unwrap_or_default();
            if let Some(status) = data_type.status.filter(|s| s.is_bad()) {
                let hint = if status == StatusCode::BadNodeIdUnknown {
                    ": the server has no such node"
                } else {
                    ""
                };
                return Err(Failure::new(
                    status,
                    format!("writing `{text}`: {status}{hint}"),
                ));
            }
            known = match data_type.value {
                Some(Variant::NodeId(t)) => Builtin::of_data_type(&t),
                _ => None,
            };
        }
        // A DataType of no fixed built-in type: the first candidate (Double, Int32, Boolean).
        let builtin = known.unwrap_or(candidates(value.kind())[0]);
        if !candidates(value.kind()).contains(&builtin) {
            return Err(Failure::new(
                StatusCode::BadTypeMismatch,
                format!("writing `{text}`: the variable is a {builtin:?}, which a Modelica {} cannot write", value.kind().name()),
            ));
        }
        let variant = builtin.variant(&value).map_err(|m| {
            Failure::new(StatusCode::BadOutOfRange, format!("writing `{text}`: {m}"))
        })?;
        self.nodes
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .insert(text.to_owned(), (id.clone(), Some(builtin)));
        let request = WriteValue {
            node_id: id,
            attribute_id: AttributeId::Value as u32,
            value: DataValue::value_only(variant),
            ..Default::default()
        };
        let s = session.session().clone();
        let results = self.call(&session, &format!("writing `{text}`"), async move {
            s.write(&[request]).await
        })?;
        match results
            .first()
            .copied()
            .unwrap_or(StatusCode::BadUnexpectedError)
        {
            s if s.is_good() => Ok(()),
            s => {
                let hint = match s {
                    StatusCode::BadUserAccessDenied | StatusCode::BadNotWritable => {
                        ": the session's user may not write it (connect as a user whose role may write)"
                    }
                    StatusCode::BadTypeMismatch => ": the variable does not take this type",
                    _ => "",
                };
                Err(Failure::new(s, format!("writing `{text}`: {s}{hint}")))
            }
        }
    }
}

impl Drop for LiveClient {
    fn drop(&mut self) {
        let link = std::mem::replace(
            &mut *self.shared.link.lock().unwrap_or_else(|p| p.into_inner()),
            Link::Down {
                why: "closed".into(),
                retrying: true,
            },
        );
        if let Link::Up(server) = link {
            if let Ok(server) = Arc::try_unwrap(server) {
                self.runtime
                    .block_on(async {
                        tokio::time::timeout(Duration::from_secs(5), server.disconnect()).await
                    })
                    .ok();
            }
        }
    }
}

/// Connects until it succeeds, keeping the reason of each failed attempt for the calls to report.
async fn reconnect(
    shared: Arc<Shared>,
    config: ClientConfig,
    url: String,
    pki_dir: PathBuf,
    since: SystemTime,
) {
    loop {
        match config.connect(&url).await {
            Ok(server) => {
                *shared.link.lock().unwrap_or_else(|p| p.into_inner()) = Link::Up(Arc::new(server));
                return;
            }
            Err(e) => {
                let mut link = shared.link.lock().unwrap_or_else(|p| p.into_inner());
                match &mut *link {
                    Link::Down { why, .. } => *why = explain(&e, &pki_dir, since),
                    Link::Up(_) => return,
                }
            }
        }
        tokio::time::sleep(RETRY).await;
    }
}

/// Why a session could not be opened, with what to do where a certificate was refused.
///
/// Both sides answer a refused certificate with one of a few statuses (BadCertificateUntrusted,
/// BadSecurityChecksFailed, ...), so the status does not say which side refused. This client puts a server
/// certificate it does not trust into `rejected/` (async-opcua's certificate store): a file written there
/// since the client object was made (`since`) says this client refused; otherwise the server did.
fn explain(e: &RemoteError, pki_dir: &Path, since: SystemTime) -> String {
    let RemoteError::Connect(_, status) = e else {
        return e.to_string();
    };
    let certificate = status.to_string().starts_with("BadCertificate")
        || *status == StatusCode::BadSecurityChecksFailed;
    if !certificate {
        return e.to_string();
    }
    let rejected = pki_dir.join("rejected");
    let mut files: Vec<(PathBuf, bool)> = std::fs::read_dir(&rejected)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|f| f.path().extension().is_some_and(|x| x == "der"))
        .map(|f| {
            let fresh = f
                .metadata()
                .and_then(|m| m.modified())
                .is_ok_and(|m| m + Duration::from_secs(2) >= since);
            (f.path(), fresh)
        })
        .collect();
    files.sort();
    let trusted = pki_dir.join("trusted");
    if let Some((file, _)) = files.iter().find(|(_, fresh)| *fresh) {
        return format!(
            "{e}: this client does not trust the server's certificate, which it put in {}: if it is the server's, an administrator moves it to {}",
            file.display(),
            trusted.display()
        );
    }
    let mut message = format!(
        "{e}: the server refused this client's certificate: its administrator trusts {} (or lets the server trust clients on first use)",
        pki_dir.join("own/cert.der").display()
    );
    if !files.is_empty() {
        let names: Vec<String> = files.iter().map(|(f, _)| f.display().to_string()).collect();
        message.push_str(&format!(
            "; or, if the server's certificate is one this client rejected before ({}), move it to {}",
            names.join(", "),
            trusted.display()
        ));
    }
    message
}

/// Whether a block's text is a browse path (BrowseNames from the ObjectsFolder separated by `/`, as the
/// generated blocks' `browsePath` parameter gives it) rather than a NodeId, every form of which has an `=`.
pub fn is_browse_path(text: &str) -> bool {
    let text = text.trim();
    !text.is_empty() && !text.contains('=')
}

/// Whether a status says the session or its connection is gone (not that one request was refused).
fn lost_connection(status: StatusCode) -> bool {
    [
        StatusCode::BadTimeout,
        StatusCode::BadNotConnected,
        StatusCode::BadConnectionClosed,
        StatusCode::BadServerNotConnected,
        StatusCode::BadCommunicationError,
        StatusCode::BadSecureChannelClosed,
        StatusCode::BadSecureChannelIdInvalid,
        StatusCode::BadSessionClosed,
        StatusCode::BadSessionIdInvalid,
        StatusCode::BadSessionNotActivated,
        StatusCode::BadRequestTimeout,
        StatusCode::BadShutdown,
    ]
    .contains(&status)
}
