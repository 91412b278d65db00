//! An OPC UA server for generated namespaces.
//!
//! [`ServerConfig`] builds an async-opcua server with the OPC UA namespace (ns0), the generated tables and
//! their type loaders, on encrypted endpoints (Basic256Sha256, Aes128_Sha256_RsaOaep, Aes256_Sha256_RsaPss in
//! Sign and SignAndEncrypt), with a PKI folder, users and roles ([`security`], [`users`], [`access`]); a
//! SecurityPolicy None endpoint only when [`ServerConfig::insecure`] asks for one:
//!
//! ```no_run
//! # async fn demo(table: &'static nodeset_runtime::table::NodeSetTable) -> Result<(), String> {
//! use nodeset_runtime::server::ServerConfig;
//! use opcua::types::{StatusCode, Variant};
//!
//! let server = ServerConfig::new("My robot").port(4855).table(table).build()?;
//! let manager = server.manager().clone();
//! let speed = manager.resolve(nodeset_runtime::NsNodeId::numeric(table.namespace_uri, 6001)).unwrap();
//! manager.on_write(&speed, |v| match v {
//!     Variant::Double(d) if *d > 100.0 => Err(StatusCode::BadOutOfRange),
//!     _ => Ok(None),
//! });
//! let handle = server.handle().clone();
//! let task = tokio::spawn(server.run());
//! manager.set_value(&speed, 12.5).map_err(|s| s.to_string())?;
//! // ... later
//! handle.cancel();
//! task.await.map_err(|e| e.to_string())??;
//! # Ok(())
//! # }
//! ```
//!
//! A program that only serves ends with [`ModelServer::run_until_stopped`]: it prints `listening on <url>`,
//! serves until Ctrl-C, SIGTERM or a number of seconds, and stops the server cleanly ([`running`]).
//!
//! The node manager behind it ([`ModelNodes`], reached through [`ModelManager`]) can also be added to a
//! server configured by hand, with [`model_node_manager`].

pub mod access;
mod check;
mod fields;
pub mod locking;
mod locks;
mod manager;
mod namespace_objects;
pub mod running;
pub mod security;
pub mod users;

use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::Arc;

use opcua::crypto::SecurityPolicy;
use opcua::server::{Server, ServerBuilder, ServerEndpoint, ServerHandle, ANONYMOUS_USER_TOKEN_ID};
use opcua::types::{MessageSecurityMode, TypeLoader};

pub use access::{AccessPolicy, Permissions, Role};
pub use running::{stop_requested, RunningServer};
pub use security::{PkiError, Security};
pub use users::{Caller, ModelAuth, Users};

pub use manager::{
    model_node_manager, model_node_manager_with_instances, MethodError, DEFAULT_INSTANCE_NAMESPACE, MethodHandler, MethodInvocation, MethodResult, ModelManager, ModelNodeManager,
    ModelNodes, WriteHandler,
};

use super::table::NodeSetTable;

/// What a model server serves and where.
#[derive(Clone)]
pub struct ServerConfig {
    /// The host name or address to listen on, and the one endpoint URLs name. Defaults to `127.0.0.1`.
    pub host: String,
    /// The TCP port; 0 (the default) picks a free one when the server is built.
    pub port: u16,
    /// The ApplicationName of the server.
    pub application_name: String,
    /// The ApplicationUri of the server, which becomes namespace 1. Defaults to `urn:nodeset-models:<name>`.
    pub application_uri: String,
    /// The generated namespaces to serve, in the order their namespace indices are assigned. A table's
    /// dependencies should come before it (DI, then IA, then Robotics). [`ServerConfig::table`] adds each
    /// table once, however often it is given (a generated `register` adds the namespaces it requires).
    pub tables: Vec<&'static NodeSetTable>,
    /// Type loaders of the generated data types, so that structures written by clients or passed to
    /// methods arrive decoded.
    pub type_loaders: Vec<Arc<dyn TypeLoader>>,
    /// The Rust types of the loaders [`ServerConfig::type_loader`] added, so that each is added once.
    loader_types: Vec<std::any::TypeId>,
    /// The namespace URI of instances created at run time ([`ModelManager::instantiate`]). Defaults to
    /// `<application URI>:instances`.
    pub instance_namespace: Option<String>,
    /// The smallest sampling interval the server grants, in milliseconds. Defaults to 0: the values the
    /// runtime sets are pushed to subscriptions when they change, so a client that asks for 0 gets every
    /// change, each state of a program however short it lasts. (async-opcua 0.19 holds back a change that
    /// follows another within a non-zero sampling interval until the next change of the variable.)
    pub min_sampling_interval_ms: f64,
    /// The smallest publishing interval the server grants, in milliseconds, which is also how often it
    /// looks for notifications to send. Defaults to async-opcua's 100. A server whose programs are run by
    /// the composite skills of other servers wants less: `runtime::remote` learns that a basic skill ended
    /// from its transition event, so each step of a composite skill waits for a publish.
    pub min_publishing_interval_ms: u64,
    /// The PKI folder (own, private, trusted, rejected, issuers; see [`security`]). Defaults to
    /// `pki/<name>` below the working directory; the certificate is created there on first start.
    pub pki_dir: PathBuf,
    /// The endpoints' security: the three secure policies in Sign and SignAndEncrypt by default, no None
    /// endpoint unless [`ServerConfig::insecure`] asks for one.
    pub security: Security,
    /// The users and their roles (none by default: anonymous sessions only, which may read but not write
    /// or call).
    pub users: Users,
    /// Which roles may read, write and call (see [`AccessPolicy`]).
    pub access: AccessPolicy,
    /// Host names and addresses the certificate names besides `host` (created certificates only).
    pub host_names: Vec<String>,
    /// How many client sessions the server accepts at once; more get `BadTooManySessions`. Defaults to
    /// [`DEFAULT_MAX_SESSIONS`] (async-opcua's own default, 20, is too few for a cell whose devices are
    /// watched by dashboards, HMIs and the composite skills of other servers at the same time).
    pub max_sessions: usize,
}

/// The default of [`ServerConfig::max_sessions`].
pub const DEFAULT_MAX_SESSIONS: usize = 100;

impl ServerConfig {
    /// A configuration with the defaults above and no tables.
    pub fn new(application_name: impl Into<String>) -> ServerConfig {
        let application_name = application_name.into();
        let slug: String = application_name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' })
            .collect();
        ServerConfig {
            host: "127.0.0.1".to_owned(),
            port: 0,
            application_uri: format!("urn:nodeset-models:{slug}"),
            application_name,
            tables: Vec::new(),
            type_loaders: Vec::new(),
            loader_types: Vec::new(),
            instance_namespace: None,
            min_sampling_interval_ms: 0.0,
            min_publishing_interval_ms: 100,
            pki_dir: PathBuf::from("pki").join(&slug),
            security: Security::default(),
            users: Users::default(),
            access: AccessPolicy::default(),
            host_names: Vec::new(),
            max_sessions: DEFAULT_MAX_SESSIONS,
        }
    }

    /// Sets the host.
    pub fn host(mut self, host: impl Into<String>) -> ServerConfig {
        self.host = host.into();
        self
    }

    /// Sets the port (0 picks a free one).
    pub fn port(mut self, port: u16) -> ServerConfig {
        self.port = port;
        self
    }

    /// Sets the PKI folder.
    pub fn pki_dir(mut self, dir: impl Into<PathBuf>) -> ServerConfig {
        self.pki_dir = dir.into();
        self
    }

    /// Adds the SecurityPolicy None endpoint, on which anonymous sessions act as Operator: for loopback
    /// testing only. The secure endpoints stay.
    pub fn insecure(mut self) -> ServerConfig {
        self.security.insecure = true;
        self
    }

    /// Serves only the SecurityPolicy None endpoint, with anonymous sessions acting as Operator, and
    /// touches no PKI folder: for tests of the runtime on loopback.
    pub fn insecure_only(mut self) -> ServerConfig {
        self.security.insecure = true;
        self.security.policies.clear();
        self
    }

    /// Trusts unknown client certificates on first use (development only).
    pub fn trust_on_first_use(mut self) -> ServerConfig {
        self.security.trust_on_first_use = true;
        self
    }

    /// Sets the users.
    pub fn users(mut self, users: Users) -> ServerConfig {
        self.users = users;
        self
    }

    /// Sets the access policy.
    pub fn access(mut self, access: AccessPolicy) -> ServerConfig {
        self.access = access;
        self
    }

    /// Sets how many client sessions the server accepts at once.
    pub fn max_sessions(mut self, max_sessions: usize) -> ServerConfig {
        self.max_sessions = max_sessions;
        self
    }

    /// Adds a table to serve (once: a table already added is not added again).
    pub fn table(mut self, table: &'static NodeSetTable) -> ServerConfig {
        if !self.tables.iter().any(|t| std::ptr::eq(*t, table)) {
            self.tables.push(table);
        }
        self
    }

    /// Sets the namespace URI of instances created at run time.
    pub fn instance_namespace(mut self, uri: impl Into<String>) -> ServerConfig {
        self.instance_namespace = Some(uri.into());
        self
    }

    /// Sets the smallest sampling interval the server grants.
    pub fn min_sampling_interval_ms(mut self, ms: f64) -> ServerConfig {
        self.min_sampling_interval_ms = ms;
        self
    }

    /// Sets the smallest publishing interval the server grants (at least 1 ms).
    pub fn min_publishing_interval_ms(mut self, ms: u64) -> ServerConfig {
        self.min_publishing_interval_ms = ms.max(1);
        self
    }

    /// Adds a type loader (once: a loader of a Rust type already added is not added again).
    pub fn type_loader<L: TypeLoader + 'static>(mut self, loader: L) -> ServerConfig {
        let id = std::any::TypeId::of::<L>();
        if !self.loader_types.contains(&id) {
            self.loader_types.push(id);
            self.type_loaders.push(Arc::new(loader));
        }
        self
    }

    /// What this configuration weakens, one line each, for a server to print when it starts: the None
    /// endpoint ([`ServerConfig::insecure`]) and trust on first use. Empty for the secure defaults.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.security.trust_on_first_use {
            out.push(format!(
                "WARNING: {}: --trust-on-first-use: every client certificate is trusted on first use (development only)",
                self.application_name
            ));
        }
        if self.security.insecure {
            out.push(format!(
                "WARNING: {}: --insecure: a SecurityPolicy None endpoint is open, and anonymous sessions may write and call methods (loopback testing only)",
                self.application_name
            ));
        }
        out
    }

    /// Binds the port and builds the server, importing every table.
    ///
    /// Fails if the PKI folder cannot be used (see [`security::prepare_pki`]), the port cannot be bound or
    /// async-opcua rejects the configuration.
    pub fn build(self) -> Result<ModelServer, String> {
        let secure = !self.security.policies.is_empty();
        if !secure && !self.security.insecure {
            return Err("the configuration has no endpoint: give it a security policy or ask for `insecure`".into());
        }
        let mut hosts = vec![self.host.clone()];
        hosts.extend(self.host_names.iter().filter(|h| **h != self.host).cloned());
        if secure {
            security::prepare_pki(&self.pki_dir, &self.application_name, &self.application_uri, &hosts)
                .map_err(|e| e.to_string())?;
        }
        let listener = TcpListener::bind((self.host.as_str(), self.port))
            .map_err(|e| format!("cannot listen on {}:{}: {e}", self.host, self.port))?;
        let instance_namespace =
            self.instance_namespace.clone().unwrap_or_else(|| format!("{}:instances", self.application_uri));
        let port = listener.local_addr().map_err(|e| format!("cannot read the bound address: {e}"))?.port();
        let mut users = self.users;
        if self.security.insecure {
            users.anonymous_roles.push(Role::Operator);
        }
        let anonymous = self.security.anonymous || self.security.insecure;
        let auth = std::sync::Arc::new(ModelAuth::new(users, self.access, anonymous));
        let tables = self.tables.clone();
        let endpoint_url = format!("opc.tcp://{}:{port}/", self.host);
        let mut builder = ServerBuilder::new()
            .discovery_urls(vec![endpoint_url.clone()])
            .application_name(self.application_name)
            .application_uri(&self.application_uri)
            .product_uri(&self.application_uri)
            .host(&self.host)
            .port(port)
            .pki_dir(self.pki_dir)
            .create_sample_keypair(false)
            .certificate_path("own/cert.der")
            .private_key_path("private/private.pem")
            .trust_client_certs(self.security.trust_on_first_use)
            .with_authenticator(auth.clone())
            .max_sessions(self.max_sessions)
            .with_node_manager(model_node_manager_with_instances(self.tables, &instance_namespace));
        for loader in self.type_loaders {
            builder = builder.with_type_loader(loader);
        }
        let anonymous_ids = [ANONYMOUS_USER_TOKEN_ID.to_owned()];
        let mut first = None;
        for &policy in &self.security.policies {
            for &mode in &self.security.modes {
                let id = security::endpoint_id(policy, mode);
                first.get_or_insert_with(|| id.clone());
                builder = builder.add_endpoint(&id, ServerEndpoint::new("/", policy, mode, &anonymous_ids));
            }
        }
        if self.security.insecure {
            let id = security::endpoint_id(SecurityPolicy::None, MessageSecurityMode::None);
            first.get_or_insert_with(|| id.clone());
            builder =
                builder.add_endpoint(&id, ServerEndpoint::new("/", SecurityPolicy::None, MessageSecurityMode::None, &anonymous_ids));
        }
        if let Some(id) = first {
            builder = builder.default_endpoint(id);
        }
        builder.limits_mut().subscriptions.min_sampling_interval_ms = self.min_sampling_interval_ms;
        builder.limits_mut().subscriptions.min_publishing_interval_ms = self.min_publishing_interval_ms as f64;
        builder = builder.subscription_poll_interval_ms(self.min_publishing_interval_ms.min(100));
        let (server, handle) = builder.build()?;
        let manager = ModelManager::from_handle(&handle).ok_or("the model node manager is missing from the server")?;
        auth.add_node_permissions(access::table_permissions(&manager, &tables)?);
        Ok(ModelServer { server, handle, manager, listener, endpoint_url })
    }
}

/// A built server, bound to its port, not yet serving.
pub struct ModelServer {
    server: Server,
    handle: ServerHandle,
    manager: ModelManager,
    listener: TcpListener,
    endpoint_url: String,
}

impl ModelServer {
    /// async-opcua's handle of the server: clone it before [`ModelServer::run`] to stop the server later
    /// (`handle.cancel()`).
    pub fn handle(&self) -> &ServerHandle {
        &self.handle
    }

    /// The handle to the generated namespaces.
    pub fn manager(&self) -> &ModelManager {
        &self.manager
    }

    /// The URL clients connect to, `opc.tcp://<host>:<port>/`.
    pub fn endpoint_url(&self) -> &str {
        &self.endpoint_url
    }

    /// The port the server listens on.
    pub fn port(&self) -> u16 {
        self.listener.local_addr().map(|a| a.port()).unwrap_or_default()
    }

    /// Serves clients until the handle is cancelled; must run inside a tokio runtime.
    pub async fn run(self) -> Result<(), String> {
        self.listener.set_nonblocking(true).map_err(|e| format!("cannot make the listener non-blocking: {e}"))?;
        if let Err(e) = socket2::SockRef::from(&self.listener).set_tcp_nodelay(true) {
            tracing::warn!("cannot set TCP_NODELAY on the listener: {e}");
        }
        let listener = tokio::net::TcpListener::from_std(self.listener)
            .map_err(|e| format!("cannot hand the listener to tokio: {e}"))?;
        self.server.run_with(listener).await
    }
}
