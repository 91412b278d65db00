//! The network side of `verify`: a session to the server and a [`Snapshot`] read in batches.
//!
//! Round trips: one Read (NamespaceArray and the server's MaxNodesPerBrowse and MaxNodesPerRead), then
//! per level of the address space one Browse per `MaxNodesPerBrowse` nodes (plus BrowseNext for nodes
//! with more references than the server returns at once), then one Read per `MaxNodesPerRead`
//! attributes for the DataType, ValueRank and Value of every variable.

use super::{RemoteNode, RemoteReference, RemoteValue, Snapshot};
use crate::nodeid::{Identifier, NodeId, QualifiedName};
use crate::raw::NodeClass;
use crate::value::BuiltinType;
use opcua::client::transport::{ConnectorBuilder, StreamConnection, StreamConnector};
use opcua::client::{ClientBuilder, ConnectionSource, IdentityToken, Password, Session};
use opcua::core::comms::tcp_codec::TcpCodec;
use opcua::core::comms::url::hostname_port_from_url;
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    AttributeId, BrowseDescription, BrowseDirection, BrowseResultMask, ByteString, DecodingOptions, EndpointDescription,
    MessageSecurityMode, ReadValueId, StatusCode, TimestampsToReturn, Variant,
};
use std::future::Future;
use std::path::PathBuf;
use std::pin::Pin;
use std::sync::Arc;
use std::time::Duration;
use tokio::io::{ReadHalf, WriteHalf};
use tokio::net::TcpStream;
use tokio_util::codec::FramedRead;

/// How to reach the server.
#[derive(Clone, Debug)]
pub struct Connect {
    /// The server's endpoint URL, `opc.tcp://HOST:PORT[/PATH]`.
    pub url: String,
    /// `None`, `Basic256Sha256`, `Aes128Sha256RsaOaep`, `Aes256Sha256RsaPss`.
    pub security_policy: String,
    /// `None`, `Sign` or `SignAndEncrypt`.
    pub security_mode: String,
    /// A user name and its password; anonymous when `None`.
    pub user: Option<(String, String)>,
    /// The client's PKI folder (own certificate, trusted and rejected server certificates).
    pub pki_dir: PathBuf,
    /// Trust the server's certificate without finding it in the trust list (explicitly insecure).
    pub trust_server_cert: bool,
    /// Check the server certificate's host name, application URI and validity (async-opcua's checks; on for
    /// `verify`). async-opcua 0.19 takes the first SubjectAltName for the application URI and skips it, so
    /// it refuses node-opcua's certificates (DNS name first) over any secure channel: the start-up bench,
    /// which reaches node-opcua's server and ours over SignAndEncrypt with the same client, turns it off.
    pub verify_server_cert: bool,
}

/// Why a snapshot could not be read.
#[derive(Debug)]
pub struct ClientError(pub String);

impl std::fmt::Display for ClientError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

fn fail(what: &str, e: impl std::fmt::Display) -> ClientError {
    ClientError(format!("{what}: {e}"))
}

/// Connects, reads a [`Snapshot`] and disconnects.
pub async fn snapshot(connect: &Connect) -> Result<Snapshot, ClientError> {
    snapshot_batched(connect, None).await
}

/// [`snapshot`] with at most `max_batch` nodes a Browse and attributes a Read (besides the server's own
/// limits): `Some(1)` is the same walk one node at a time, the baseline of `cargo xtask bench --scenario
/// verify`.
pub async fn snapshot_batched(connect: &Connect, max_batch: Option<usize>) -> Result<Snapshot, ClientError> {
    let open = open(connect).await?;
    let result = read_all_batched(&open.session, max_batch).await;
    open.close().await;
    result
}

/// A session to a server, with the event loop that carries it.
pub struct Open {
    /// The session, connected and activated.
    pub session: Arc<Session>,
    event_loop: tokio::task::JoinHandle<StatusCode>,
}

impl Open {
    /// Closes the session and waits (at most 5 s) for its event loop to end.
    pub async fn close(self) {
        let _ = self.session.disconnect().await;
        let _ = tokio::time::timeout(Duration::from_secs(5), self.event_loop).await;
    }
}

/// Opens a session as `connect` says (the endpoint of its policy and mode, reached at its URL, TCP_NODELAY,
/// no retries): the one client of `verify`, also the client of `cargo xtask bench --scenario startup`.
pub async fn open(connect: &Connect) -> Result<Open, ClientError> {
    let url_ok = connect.url.starts_with("opc.tcp://")
        && hostname_port_from_url(&connect.url, opcua::core::constants::DEFAULT_OPC_UA_SERVER_PORT).is_ok_and(|(h, _)| !h.is_empty());
    if !url_ok {
        return Err(ClientError(format!("`{}` is not an OPC UA endpoint URL (opc.tcp://HOST:PORT[/PATH])", connect.url)));
    }
    let policy: SecurityPolicy = connect
        .security_policy
        .parse()
        .map_err(|_| ClientError(format!("unknown security policy `{}` (None, Basic256Sha256, Aes128Sha256RsaOaep, Aes256Sha256RsaPss)", connect.security_policy)))?;
    let mode = match connect.security_mode.as_str() {
        "None" => MessageSecurityMode::None,
        "Sign" => MessageSecurityMode::Sign,
        "SignAndEncrypt" => MessageSecurityMode::SignAndEncrypt,
        other => return Err(ClientError(format!("unknown security mode `{other}` (None, Sign, SignAndEncrypt)"))),
    };
    let secure = policy != SecurityPolicy::None;
    let client = ClientBuilder::new()
        .application_name("nodeset-compiler verify")
        .application_uri("urn:nodeset-compiler:verify")
        .pki_dir(&connect.pki_dir)
        .create_sample_keypair(secure)
        .trust_server_certs(connect.trust_server_cert)
        .verify_server_certs(connect.verify_server_cert)
        .session_retry_limit(0)
        .client()
        .map_err(|e| ClientError(format!("the client configuration is invalid: {}", e.join("; "))))?;
    let endpoints = client
        .get_server_endpoints_from_url(connect.url.as_str())
        .await
        .map_err(|e| fail(&format!("cannot read the endpoints of {}", connect.url), e))?;
    let identity = match &connect.user {
        Some((user, password)) => IdentityToken::UserName(user.clone(), Password(password.clone())),
        None => IdentityToken::Anonymous,
    };
    // The endpoint of that policy and mode, reached at the URL the user gave: servers often advertise their
    // host name (node-opcua does), which the machine running verify may not resolve.
    let mut endpoint = endpoints
        .iter()
        .find(|e| e.security_policy_uri.as_ref() == policy.to_uri() && e.security_mode == mode)
        .cloned()
        .ok_or_else(|| {
            let offered: Vec<String> = endpoints
                .iter()
                .map(|e| format!("{} {:?}", e.security_policy_uri.as_ref().rsplit('#').next().unwrap_or_default(), e.security_mode))
                .collect();
            ClientError(format!(
                "{} offers no endpoint with {} and {} (it offers: {})",
                connect.url,
                connect.security_policy,
                connect.security_mode,
                offered.join(", ")
            ))
        })?;
    endpoint.endpoint_url = connect.url.as_str().into();
    let server_certificate = endpoint.server_certificate.as_ref().to_vec();
    let (session, event_loop) = client
        .session_builder()
        .with_endpoints(endpoints)
        .connect_to_endpoint_directly(endpoint)
        .map_err(|e| fail(&format!("cannot use the endpoint {}", connect.url), e))?
        .user_identity_token(identity)
        .with_connector(NoDelay)
        .build(client.certificate_store().clone())
        .map_err(|e| fail("cannot open a session", e))?;
    let mut event_loop = event_loop.spawn();
    // With no retries the event loop ends at the first failure, with its status: that is the answer, at
    // once (waiting for the connection alone would last the whole timeout, since it never returns then).
    let failed: Option<Option<StatusCode>> = tokio::select! {
        connected = session.wait_for_connection() => (!connected).then_some(None),
        ended = &mut event_loop => Some(Some(ended.unwrap_or(StatusCode::BadUnexpectedError))),
        _ = tokio::time::sleep(Duration::from_secs(10)) => Some(None),
    };
    if let Some(status) = failed {
        event_loop.abort();
        return Err(ClientError(connect_failure(connect, status, &server_certificate)));
    }
    Ok(Open { session, event_loop })
}

/// Why no session was made, and what to do about it: `status` is what the connection ended with (`None`:
/// no answer within 10 s). Verify's own refusal of the server's certificate (found in its `rejected/`
/// folder) is told apart from the server's refusal of verify's certificate (BadCertificateUntrusted, or
/// BadSecurityChecksFailed, which servers answer so as not to say more), and each says what to move where.
fn connect_failure(connect: &Connect, status: Option<StatusCode>, server_certificate: &[u8]) -> String {
    let url = &connect.url;
    if let Some(path) = rejected_copy(&connect.pki_dir, server_certificate) {
        return format!(
            "cannot connect to {url}: verify does not trust the server's certificate\n  = note: the server's certificate is not \
             trusted; it was put in {}\n  = help: check it (its thumbprint, with the server's operator) and move it to {}, then run again",
            path.display(),
            connect.pki_dir.join("trusted").display()
        );
    }
    match status {
        None => format!("cannot connect to {url} (no session within 10 s)"),
        Some(s) if s == StatusCode::BadCertificateUntrusted || s == StatusCode::BadSecurityChecksFailed => format!(
            "cannot connect to {url}: the server rejected verify's application certificate ({s})\n  = note: verify's certificate \
             is {} (application URI urn:nodeset-compiler:verify)\n  = help: on the server, trust it: a nodeset-runtime server (the \
             examples, `ServerConfig`) has put it in the `rejected/` folder of its PKI folder (`--pki DIR`, by default `pki/<name>` \
             in its working directory): move it from there to `trusted/` beside it, keeping its file name (the server looks it up \
             by that name), or run `nodeset-compiler trust --pki <the server's PKI folder> {}` (another server: put the \
             file above into the folder of the client certificates it trusts); then run again",
            connect.pki_dir.join("own").join("cert.der").display(),
            connect.pki_dir.join("own").join("cert.der").display()
        ),
        Some(s) => format!("cannot connect to {url}: the connection ended with {s}"),
    }
}

/// The file in the PKI's `rejected/` folder that holds `certificate` (DER), if the client refused it.
fn rejected_copy(pki_dir: &std::path::Path, certificate: &[u8]) -> Option<PathBuf> {
    if certificate.is_empty() {
        return None;
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(pki_dir.join("rejected")).ok()?.filter_map(|e| e.ok().map(|e| e.path())).collect();
    files.sort();
    files.into_iter().find(|f| std::fs::read(f).is_ok_and(|bytes| bytes == certificate))
}

/// Reads the snapshot over an open session.
pub async fn read_all(session: &Arc<Session>) -> Result<Snapshot, ClientError> {
    read_all_batched(session, None).await
}

/// [`read_all`] with at most `max_batch` nodes a Browse and attributes a Read.
pub async fn read_all_batched(session: &Arc<Session>, max_batch: Option<usize>) -> Result<Snapshot, ClientError> {
    let mut snap = Snapshot::default();
    // NamespaceArray, MaxNodesPerRead, MaxNodesPerBrowse.
    let first: Vec<ReadValueId> = [2255u32, 11705, 11710]
        .iter()
        .map(|&i| ReadValueId { node_id: opcua::types::NodeId::new(0, i), attribute_id: AttributeId::Value as u32, ..Default::default() })
        .collect();
    let values = session.read(&first, TimestampsToReturn::Neither, 0.0).await.map_err(|e| fail("cannot read the NamespaceArray", e))?;
    snap.round_trips += 1;
    match values.first().and_then(|v| v.value.as_ref()) {
        Some(Variant::Array(a)) => {
            snap.namespaces = a.values.iter().map(|v| if let Variant::String(s) = v { s.as_ref().to_owned() } else { String::new() }).collect()
        }
        _ => return Err(ClientError("the server's NamespaceArray is not an array of strings".into())),
    }
    let limit = |v: Option<&opcua::types::DataValue>| match v.and_then(|v| v.value.as_ref()) {
        Some(Variant::UInt32(n)) if *n > 0 => (*n as usize).min(1000),
        _ => 1000,
    };
    let cap = max_batch.unwrap_or(usize::MAX).max(1);
    let (per_read, per_browse) = (limit(values.get(1)).min(cap), limit(values.get(2)).min(cap));

    // Breadth first from the Objects folder, one level per batch of Browse requests.
    let objects = Snapshot::objects_folder();
    snap.nodes.insert(objects.clone(), RemoteNode::empty_objects_folder());
    let mut level = vec![objects];
    while !level.is_empty() {
        let mut next: Vec<NodeId> = Vec::new();
        for chunk in level.chunks(per_browse) {
            let descriptions: Vec<BrowseDescription> = chunk
                .iter()
                .map(|id| BrowseDescription {
                    node_id: to_opcua(id),
                    browse_direction: BrowseDirection::Forward,
                    reference_type_id: opcua::types::NodeId::new(0, 31u32),
                    include_subtypes: true,
                    node_class_mask: 0,
                    result_mask: BrowseResultMask::All as u32,
                })
                .collect();
            let mut results = session.browse(&descriptions, 0, None).await.map_err(|e| fail("Browse failed", e))?;
            snap.round_trips += 1;
            let mut owners: Vec<NodeId> = chunk.to_vec();
            loop {
                let mut pending: Vec<(NodeId, ByteString)> = Vec::new();
                for (owner, result) in owners.iter().zip(results) {
                    for r in result.references.unwrap_or_default() {
                        let target = from_opcua(&r.node_id.node_id);
                        let reference_type = from_opcua(&r.reference_type_id);
                        if !snap.nodes.contains_key(&target) && target.ns != 0 && r.node_id.server_index == 0 && r.node_id.namespace_uri.is_null() {
                            // Instances only: HasTypeDefinition and other references into types are not followed.
                            // (A `continue` here would drop the reference too: HasTypeDefinition into a
                            // companion namespace was lost that way.)
                            if let Some(class) = node_class(r.node_class as u32).filter(|c| !c.is_type()) {
                            snap.nodes.insert(
                                target.clone(),
                                RemoteNode {
                                    id: target.clone(),
                                    class,
                                    browse_name: QualifiedName { ns: r.browse_name.namespace_index, name: r.browse_name.name.as_ref().to_owned() },
                                    references: Vec::new(),
                                    data_type: None,
                                    value_rank: None,
                                    value: None,
                                    extension_objects: None,
                                },
                            );
                            next.push(target.clone());
                            }
                        }
                        if let Some(n) = snap.nodes.get_mut(owner) {
                            n.references.push(RemoteReference { reference_type, target });
                        }
                    }
                    if !result.continuation_point.is_null() {
                        pending.push((owner.clone(), result.continuation_point));
                    }
                }
                if pending.is_empty() {
                    break;
                }
                owners = pending.iter().map(|(o, _)| o.clone()).collect();
                let points: Vec<ByteString> = pending.into_iter().map(|(_, p)| p).collect();
                results = session.browse_next(false, &points).await.map_err(|e| fail("BrowseNext failed", e))?;
                snap.round_trips += 1;
            }
        }
        level = next;
    }

    // DataType, ValueRank and Value of every variable.
    let variables: Vec<NodeId> = snap.nodes.values().filter(|n| n.class == NodeClass::Variable).map(|n| n.id.clone()).collect();
    let attributes = [AttributeId::DataType, AttributeId::ValueRank, AttributeId::Value];
    let reads: Vec<(usize, usize)> = (0..variables.len()).flat_map(|v| (0..attributes.len()).map(move |a| (v, a))).collect();
    for chunk in reads.chunks(per_read) {
        let ids: Vec<ReadValueId> = chunk
            .iter()
            .map(|&(v, a)| ReadValueId { node_id: to_opcua(&variables[v]), attribute_id: attributes[a] as u32, ..Default::default() })
            .collect();
        let values = session.read(&ids, TimestampsToReturn::Neither, 0.0).await.map_err(|e| fail("Read failed", e))?;
        snap.round_trips += 1;
        for (&(v, a), dv) in chunk.iter().zip(values) {
            if dv.status.is_some_and(|s| s.is_bad()) {
                continue;
            }
            let Some(node) = snap.nodes.get_mut(&variables[v]) else { continue };
            match (a, dv.value) {
                (0, Some(Variant::NodeId(id))) => node.data_type = Some(from_opcua(&id)),
                (1, Some(Variant::Int32(r))) => node.value_rank = Some(r),
                (2, value) => {
                    node.value = Some(shape(value.as_ref()));
                    node.extension_objects = Some(extension_objects(value.as_ref()));
                }
                _ => {}
            }
        }
    }
    Ok(snap)
}

/// Each ExtensionObject of a value (the value, or the items of an array), in OPC UA binary: a body the
/// client decoded (ns0's structures) encoded again, one it did not as the bytes the server sent.
fn extension_objects(v: Option<&Variant>) -> Vec<Vec<u8>> {
    use opcua::types::{BinaryEncodable, ContextOwned};
    let ctx = ContextOwned::default();
    let encode = |eo: &opcua::types::ExtensionObject| {
        let mut out = Vec::new();
        // An ExtensionObject whose encoding NodeId cannot be written is kept as no bytes: the comparison then
        // reports what it lacks.
        let _ = eo.encode(&mut out, &ctx.context());
        out
    };
    match v {
        Some(Variant::ExtensionObject(eo)) => vec![encode(eo)],
        Some(Variant::Array(a)) => a
            .values
            .iter()
            .filter_map(|i| match i {
                Variant::ExtensionObject(eo) => Some(encode(eo)),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

fn shape(v: Option<&Variant>) -> RemoteValue {
    match v {
        None | Some(Variant::Empty) => RemoteValue::Empty,
        Some(Variant::Array(a)) => match BuiltinType::from_id(a.value_type as u32) {
            Some(b) => RemoteValue::Array(b),
            None => RemoteValue::Empty,
        },
        Some(v) => match v.scalar_type_id().and_then(|t| BuiltinType::from_id(t as u32)) {
            Some(b) => RemoteValue::Scalar(b),
            None => RemoteValue::Empty,
        },
    }
}

fn node_class(mask: u32) -> Option<NodeClass> {
    NodeClass::ALL.into_iter().find(|c| c.mask() == mask)
}

fn from_opcua(id: &opcua::types::NodeId) -> NodeId {
    use opcua::types::Identifier as I;
    let ident = match &id.identifier {
        I::Numeric(n) => Identifier::Numeric(*n),
        I::String(s) => Identifier::String(s.as_ref().into()),
        I::Guid(g) => Identifier::Guid(g.to_bytes()),
        I::ByteString(b) => Identifier::Opaque(b.as_ref().to_vec().into_boxed_slice()),
    };
    NodeId { ns: id.namespace, id: ident }
}

pub(super) fn to_opcua(id: &NodeId) -> opcua::types::NodeId {
    match &id.id {
        Identifier::Numeric(n) => opcua::types::NodeId::new(id.ns, *n),
        Identifier::String(s) => opcua::types::NodeId::new(id.ns, opcua::types::UAString::from(s.as_ref())),
        Identifier::Guid(g) => opcua::types::NodeId::new(id.ns, opcua::types::Guid::from_bytes(*g)),
        Identifier::Opaque(b) => opcua::types::NodeId::new(id.ns, ByteString::from(b.to_vec())),
    }
}

/// A connection source whose TCP connections send at once (`TCP_NODELAY`): async-opcua writes a request
/// in more than one write, and with Nagle's algorithm each round trip would wait up to 40 ms for a
/// delayed ACK.
struct NoDelay;

struct NoDelayUrl(String);

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
        stream.set_nodelay(true).map_err(|e| error(StatusCode::BadCommunicationError, format!("cannot set TCP_NODELAY: {e}")))?;
        let (reader, writer) = tokio::io::split(stream);
        Ok(StreamConnection::new(FramedRead::new(reader, TcpCodec::new(options)), writer, url))
    })
}
