//! The server a simulation runs (component simulation): it serves the namespaces of the nodesets given as
//! a parameter, from node tables built in memory by the compiler (`nodeset_compiler::serve::tables`, what
//! `nodeset-compiler serve` serves), so a package generated from any nodesets runs live without Rust being
//! generated or compiled for it. Write blocks set
//! the values clients see; read blocks return what clients wrote.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use nodeset_runtime::server::{ModelManager, ServerConfig, Users};
use nodeset_runtime::table::NodeSetTable;
use opcua::server::address_space::NodeType;
use opcua::server::ServerHandle;
use opcua::types::{NodeId, StatusCode, Variant};

use crate::value::{candidates, from_variant, Builtin, Failure, Kind, NodeRef, Value};

/// What the server constructor is given (the parameters of `OpcUaSupport.Live.Server`).
#[derive(Clone, Debug)]
pub struct ServerParams {
    /// The TCP port (0 picks a free one).
    pub port: u16,
    /// NodeSet2 files to serve and folders holding the models they require, separated by `;`. With no
    /// file named, every NodeSet2 file directly in the folders is served.
    pub nodesets: String,
    /// The PKI folder (own certificate created on first start, trusted client certificates).
    pub pki_dir: PathBuf,
    /// The user file (`nodeset-users`); empty for anonymous sessions only, which may read but not write.
    pub users_file: String,
    /// Adds the SecurityPolicy None endpoint, where anonymous sessions may write: loopback testing only.
    pub insecure: bool,
}

/// The shortest publishing interval the server grants a subscription, in milliseconds.
pub const MIN_PUBLISHING_INTERVAL_MS: u64 = 10;

/// A running server.
pub struct LiveServer {
    runtime: tokio::runtime::Runtime,
    handle: ServerHandle,
    manager: ModelManager,
    task: Option<tokio::task::JoinHandle<Result<(), String>>>,
    port: u16,
    /// Each block's NodeId text, resolved once, with the built-in type its writes use once one was accepted.
    nodes: Mutex<HashMap<String, (NodeId, Option<Builtin>)>>,
}

impl LiveServer {
    /// Reads the nodesets, builds the server and starts it on a runtime of its own.
    pub fn start(params: &ServerParams) -> Result<LiveServer, Failure> {
        let config = || Failure::new(StatusCode::BadConfigurationError, String::new());
        let tables = load_tables(&params.nodesets).map_err(|m| Failure {
            message: m,
            ..config()
        })?;
        // A simulation publishes at its sample period (tens of milliseconds): subscribers may ask for a
        // publishing interval that short (the runtime's default floor is 100 ms).
        let mut server = ServerConfig::new("Modelica simulation")
            .port(params.port)
            .pki_dir(&params.pki_dir)
            .min_publishing_interval_ms(MIN_PUBLISHING_INTERVAL_MS);
        if !params.users_file.is_empty() {
            let users = Users::load(Path::new(&params.users_file)).map_err(|e| Failure {
                message: e.to_string(),
                ..config()
            })?;
            server = server.users(users);
        }
        if params.insecure {
            server = server.insecure();
        }
        for t in tables {
            server = server.table(t);
        }
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .thread_name("opcua-live-server")
            .enable_all()
            .build()
            .map_err(|e| Failure {
                message: format!("cannot start the server's threads: {e}"),
                ..config()
            })?;
        // async-opcua's server builder spawns nothing, but its types expect to be made inside a runtime.
        let built = runtime.block_on(async { server.build() });
        let built = built.map_err(|e| Failure {
            message: format!("the server cannot start: {e}"),
            ..config()
        })?;
        let handle = built.handle().clone();
        let manager = built.manager().clone();
        let port = built.port();
        let task = runtime.spawn(built.run());
        Ok(LiveServer {
            runtime,
            handle,
            manager,
            task: Some(task),
            port,
            nodes: Mutex::new(HashMap::new()),
        })
    }

    /// The port the server listens on.
    pub fn port(&self) -> u16 {
        self.port
    }

    fn node(&self, text: &str) -> Result<(NodeId, Option<Builtin>), Failure> {
        if let Some(hit) = self
            .nodes
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get(text)
        {
            return Ok(hit.clone());
        }
        let parsed = NodeRef::parse(text)?;
        let id = {
            let tree = self.manager.type_tree().read();
            parsed.resolve(tree.namespaces(), text)?
        };
        let data_type = match self.manager.node_manager().address_space().read().find(&id) {
            Some(NodeType::Variable(v)) => v.data_type(),
            Some(_) => {
                return Err(Failure::new(
                    StatusCode::BadAttributeIdInvalid,
                    format!("`{text}` is not a variable"),
                ))
            }
            None => return Err(unknown(text)),
        };
        let fixed = Builtin::of_data_type(&data_type);
        self.nodes
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .insert(text.to_owned(), (id.clone(), fixed));
        Ok((id, fixed))
    }

    /// The value of a variable: what a client wrote last, or what a write block published.
    pub fn read(&self, text: &str, kind: Kind) -> Result<Value, Failure> {
        let (id, _) = self.node(text)?;
        let value = self.manager.value(&id).ok_or_else(|| unknown(text))?;
        if let Some(status) = value.status.filter(|s| !s.is_good()) {
            return Err(Failure::new(
                status,
                format!("`{text}` has the status {status}"),
            ));
        }
        let variant = value.value.unwrap_or(Variant::Empty);
        from_variant(&variant, kind).map_err(|m| {
            Failure::new(
                StatusCode::BadTypeMismatch,
                format!("reading `{text}`: {m}"),
            )
        })
    }

    /// Publishes a value, as the variable's built-in type (a Real to a Float variable becomes a Float).
    pub fn write(&self, text: &str, value: Value) -> Result<(), Failure> {
        let (id, fixed) = self.node(text)?;
        let mismatch = |m: String| {
            Failure::new(
                StatusCode::BadTypeMismatch,
                format!("writing `{text}`: {m}"),
            )
        };
        let tries: Vec<Builtin> = match fixed {
            Some(b) if candidates(value.kind()).contains(&b) => vec![b],
            Some(b) => {
                return Err(mismatch(format!(
                    "the variable is a {b:?}, which a Modelica {} cannot write",
                    value.kind().name()
                )))
            }
            // A DataType of no fixed built-in type (BaseDataType, Number, a subtype): the first variant the
            // server's type check accepts.
            None => candidates(value.kind()).to_vec(),
        };
        let mut last = String::new();
        for b in tries {
            let variant = match b.variant(&value) {
                Ok(v) => v,
                Err(m) if fixed.is_some() => {
                    return Err(Failure::new(
                        StatusCode::BadOutOfRange,
                        format!("writing `{text}`: {m}"),
                    ))
                }
                Err(m) => {
                    last = m;
                    continue;
                }
            };
            match self.manager.set_value(&id, variant) {
                Ok(()) => {
                    if let Some(slot) = self
                        .nodes
                        .lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .get_mut(text)
                    {
                        slot.1 = Some(b);
                    }
                    return Ok(());
                }
                Err(StatusCode::BadTypeMismatch) => {
                    last = format!("the variable's DataType does not accept a {b:?}")
                }
                Err(status) => {
                    return Err(Failure::new(status, format!("writing `{text}`: {status}")))
                }
            }
        }
        Err(mismatch(last))
    }
}

impl Drop for LiveServer {
    fn drop(&mut self) {
        self.handle.cancel();
        if let Some(task) = self.task.take() {
            let _ = self.runtime.block_on(async {
                tokio::time::timeout(std::time::Duration::from_secs(5), task).await
            });
        }
    }
}

fn unknown(text: &str) -> Failure {
    Failure::new(
        StatusCode::BadNodeIdUnknown,
        format!("`{text}`: the server has no such node; check the nodeId against the nodesets the server was given"),
    )
}

/// The node tables of every model the nodesets load, but the OPC UA namespace, dependencies first.
///
/// Each table is made `'static`, as the server requires, and so lives until the process ends: a server
/// object keeps its nodesets' tables (their packed rows, about the size of the XML's node count times 100
/// bytes) after it is destroyed.
fn load_tables(nodesets: &str) -> Result<Vec<&'static NodeSetTable>, String> {
    let mut files = Vec::new();
    let mut dirs = Vec::new();
    for entry in nodesets.split(';').map(str::trim).filter(|e| !e.is_empty()) {
        let path = PathBuf::from(entry);
        if path.is_dir() {
            dirs.push(path);
        } else if path.is_file() {
            files.push(path);
        } else {
            return Err(format!("{entry}: no such file or folder (nodesets: NodeSet2 files and model folders separated by `;`)"));
        }
    }
    if files.is_empty() {
        for dir in &dirs {
            let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
                .map_err(|e| format!("{}: cannot read the folder: {e}", dir.display()))?
                .flatten()
                .map(|e| e.path())
                .filter(|p| {
                    p.is_file() && p.extension().is_some_and(|x| x.eq_ignore_ascii_case("xml"))
                })
                .collect();
            found.sort();
            files.extend(found);
        }
    }
    if files.is_empty() {
        return Err(format!("`{nodesets}` names no NodeSet2 file: give the files to serve and the folders of the models they require, separated by `;`"));
    }
    let opts = Options {
        model_dirs: dirs,
        ..Options::default()
    };
    let out = compile(files.into_iter().map(Input::Path).collect(), &opts);
    if !out.ok() {
        return Err(format!(
            "the nodesets do not compile:\n{}",
            out.render_diagnostics()
        ));
    }
    // The tables `nodeset-compiler serve` builds: one home for the rule.
    let (tables, diags) = nodeset_compiler::serve::tables(&out.model);
    if diags.has_errors() {
        return Err(format!(
            "the node tables cannot be built:\n{}",
            diags.render(&out.model.sources)
        ));
    }
    Ok(tables)
}
