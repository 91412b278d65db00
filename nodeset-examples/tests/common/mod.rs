//! Helpers of the runtime's tests: a running server on a free loopback port, an async-opcua client session
//! to it, and attribute reads straight from the server's address space.

#![allow(dead_code)]

use std::sync::Arc;
use std::time::Duration;

use nodeset_models::runtime::server::{ModelManager, ServerConfig};
use opcua::client::{ClientBuilder, IdentityToken, Session};
use opcua::crypto::SecurityPolicy;
use opcua::server::ServerHandle;
use opcua::types::{
    AttributeId, DataEncoding, MessageSecurityMode, NodeId, NumericRange, ReadValueId, StatusCode, TimestampsToReturn,
    Variant,
};
use tokio::task::JoinHandle;

/// Logs to the test output when `RUST_LOG` asks for it.
pub fn init_tracing() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "off".into());
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_test_writer().try_init();
}

/// A server running on a free port of 127.0.0.1.
pub struct Running {
    pub manager: ModelManager,
    pub handle: ServerHandle,
    pub url: String,
    task: JoinHandle<Result<(), String>>,
}

/// Builds and starts a server.
pub async fn serve(config: ServerConfig) -> Running {
    init_tracing();
    // These tests exercise the runtime, not security: they use the None endpoint only, deliberately.
    let server = config.port(0).insecure_only().build().expect("the server builds");
    let manager = server.manager().clone();
    let handle = server.handle().clone();
    let url = server.endpoint_url().to_owned();
    let task = tokio::spawn(server.run());
    Running { manager, handle, url, task }
}

impl Running {
    /// Stops the server and checks that it stopped cleanly.
    pub async fn stop(self) {
        self.handle.cancel();
        let result = tokio::time::timeout(Duration::from_secs(10), self.task).await;
        assert!(matches!(result, Ok(Ok(Ok(())))), "the server did not stop cleanly: {result:?}");
    }

    /// The attribute of a node as the server's address space holds it (no client involved).
    pub fn attribute(&self, node: &NodeId, attribute: AttributeId) -> Option<Variant> {
        let space = self.manager.node_manager().address_space().read();
        let dv = space.find(node)?.as_node().get_attribute(
            TimestampsToReturn::Neither,
            attribute,
            &NumericRange::None,
            &DataEncoding::Binary,
        )?;
        dv.value
    }
}

/// A client session (SecurityPolicy None, anonymous) to `url`, with the namespace table read so that type
/// loaders match.
pub async fn connect(url: &str) -> (Arc<Session>, JoinHandle<StatusCode>) {
    let mut client = ClientBuilder::new()
        .application_name("nodeset-models test client")
        .application_uri("urn:nodeset-models:test-client")
        .pki_dir(std::env::temp_dir().join("nodeset-models-pki-client"))
        .create_sample_keypair(false)
        .trust_server_certs(true)
        .session_retry_limit(3)
        .client()
        .expect("client config");
    let (session, event_loop) = client
        .connect_to_matching_endpoint(
            (url, SecurityPolicy::None.to_str(), MessageSecurityMode::None),
            IdentityToken::Anonymous,
        )
        .await
        .expect("connects");
    let event_loop = event_loop.spawn();
    let connected = tokio::time::timeout(Duration::from_secs(10), session.wait_for_connection()).await;
    assert_eq!(connected.ok(), Some(true), "the session connects to {url}");
    session.read_namespace_array().await.expect("reads the NamespaceArray");
    (session, event_loop)
}

/// Reads one attribute over the wire.
pub async fn read(session: &Session, node: &NodeId, attribute: AttributeId) -> (StatusCode, Variant) {
    let id = ReadValueId { node_id: node.clone(), attribute_id: attribute as u32, ..Default::default() };
    let dv = session.read(&[id], TimestampsToReturn::Neither, 0.0).await.expect("read").remove(0);
    (dv.status(), dv.value.unwrap_or_default())
}

/// Disconnects a session and waits for its event loop to end.
pub async fn disconnect(session: Arc<Session>, event_loop: JoinHandle<StatusCode>) {
    let _ = session.disconnect().await;
    let _ = tokio::time::timeout(Duration::from_secs(5), event_loop).await;
}
