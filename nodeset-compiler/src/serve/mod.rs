//! `nodeset-compiler serve`: the address space of NodeSet2 files on a secure OPC UA server, straight from the
//! resolved model, with no Rust generated or compiled (feature `serve`).
//!
//! ```text
//! Model ──emit::rust::node_tables──▶ node tables in memory ──leak──▶ &'static NodeSetTable
//!       ──nodeset_runtime::server::ServerConfig──▶ the server the generated code would run (ns0 from async-opcua)
//!       ──instances::instantiate_all (--instantiate-all)──▶ Objects/Instances/<ns>:<TypeName>, one per concrete ObjectType
//! ```
//!
//! The tables are the ones `nodeset-compiler rust` writes into `nodes.rs`, decoded by the same runtime import,
//! so a served file shows what a generated server of it would show. The server is the runtime's
//! [`ServerConfig`]: encrypted endpoints, the PKI folder layout, the user file, roles and the nodesets'
//! RolePermissions; `--insecure` adds the None endpoint with the runtime's warning. Variables keep what
//! clients write (the runtime's write rules); methods answer `BadNotImplemented` unless the runtime
//! implements them: the cause methods of the state machines [`instances`] serves, and DI's locking on every
//! Lock object (LockingServicesType, `ModelManager::serve_locks`).

pub mod instances;

use crate::diag::Diagnostics;
use crate::emit::rust::{default_module_name, node_tables, NodeTable, RustConfig, RustNamespace, RustPath};
use crate::model::Model;
use crate::raw::NodeClass;
use nodeset_runtime::server::{stop_requested, ServerConfig, Users};
use nodeset_runtime::table::{NodeSetTable, Nodes, Packed};
use std::path::PathBuf;
use std::time::Duration;

/// The options of `nodeset-compiler serve` besides the files.
#[derive(Clone, Debug, Default)]
pub struct ServeOptions {
    /// The TCP port (0 picks a free one).
    pub port: u16,
    /// The host to listen on and to name in the endpoint URL (default `127.0.0.1`).
    pub host: Option<String>,
    /// The PKI folder (default `pki/nodeset-compiler-serve` below the working directory).
    pub pki: Option<PathBuf>,
    /// The user file (`nodeset_runtime::server::users`).
    pub users: Option<PathBuf>,
    /// Trust unknown client certificates on first use (development only).
    pub trust_on_first_use: bool,
    /// Add the SecurityPolicy None endpoint (loopback testing only).
    pub insecure: bool,
    /// One instance of every concrete ObjectType of the named files below `Objects/Instances`.
    pub instantiate_all: bool,
    /// Stop after this many seconds (else on SIGINT or SIGTERM).
    pub seconds: Option<u64>,
}

/// The ApplicationName of the server.
pub const APPLICATION_NAME: &str = "nodeset-compiler serve";

/// The node tables of every namespace of the model but ns0 (async-opcua serves its own), dependencies
/// first, built in memory exactly as `nodeset-compiler rust` writes them, and leaked: a server holds its
/// tables for as long as the process runs, as it holds the generated ones.
pub fn tables(model: &Model) -> (Vec<&'static NodeSetTable>, Diagnostics) {
    let (tables, diags) = node_tables(model, &rust_config(model));
    (tables.into_iter().map(leak).collect(), diags)
}

fn rust_config(model: &Model) -> RustConfig {
    let namespaces: Vec<RustNamespace> = model
        .models
        .iter()
        .filter(|x| x.ns != 0)
        .map(|x| RustNamespace { uri: x.uri.clone(), module: format!("{}_{}", default_module_name(&x.uri), x.ns) })
        .collect();
    RustConfig {
        namespaces,
        extern_paths: Default::default(),
        runtime_path: RustPath::new("crate::runtime").expect("a valid Rust path"),
        command: "nodeset-compiler serve".into(),
    }
}

/// What [`add_missing_ns0`] added to the served ns0.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Ns0Added {
    /// Nodes added.
    pub nodes: usize,
    /// The ObjectTypes among them, by BrowseName, sorted.
    pub types: Vec<String>,
    /// The version of the model's ns0 they come from.
    pub version: String,
    /// The InstanceDeclarations of ns0's types given the model's DataType or ValueRank (async-opcua's differ).
    pub aligned: Vec<String>,
}

/// Adds to the running server's ns0 (async-opcua's, 1.05.04) every node of the model's ns0 that it lacks: the
/// files were resolved against their own ns0 (the registry package's 1.05.07, whose
/// ApplicationConfigurationFileType, LogObjectType, ... async-opcua does not have), and a server of the
/// resolved model serves those nodes too, so that clients find them and their types can be instantiated.
/// The nodes go through the node table the other namespaces use, made for these nodes alone
/// ([`crate::emit::rust::ns0_table`]). Call it once ns0 is loaded ([`wait_for_ns0_types`]).
pub fn add_missing_ns0(manager: &nodeset_runtime::server::ModelManager, model: &Model) -> Result<Ns0Added, String> {
    let missing: std::collections::BTreeSet<_> = (0..model.nodes.len() as u32)
        .map(crate::model::NodeIx)
        .filter(|&ix| model.node(ix).id.ns == 0)
        .filter(|&ix| instances::server_id(manager, model, ix).is_some_and(|id| !manager.ns0_has(&id)))
        .collect();
    let version = model.model_of_namespace(0).and_then(|m| m.version.clone()).unwrap_or_default();
    let nodes = if missing.is_empty() {
        0
    } else {
        let (table, diags) = crate::emit::rust::ns0_table(model, &rust_config(model), &missing);
        if diags.has_errors() {
            return Err(format!("the table of ns0's missing nodes cannot be built:\n{}", diags.render(&model.sources)));
        }
        manager.add_ns0_nodes(leak(table))?
    };
    // The InstanceDeclarations of ns0's types (variables with a ModellingRule) get the model's DataType and
    // ValueRank where async-opcua's differ: instances are made from the served declarations, and verify and
    // clients hold them to the nodesets.
    let mut aligned = Vec::new();
    for ix in (0..model.nodes.len() as u32).map(crate::model::NodeIx) {
        let n = model.node(ix);
        if n.id.ns != 0 || n.class != NodeClass::Variable || n.modelling_rule.is_none() || missing.contains(&ix) {
            continue;
        }
        let (Some(id), Some(dt)) = (instances::server_id(manager, model, ix), n.attrs.data_type.and_then(|dt| instances::server_id(manager, model, dt)))
        else {
            continue;
        };
        if manager.align_ns0_variable(&id, &dt, n.attrs.value_rank.unwrap_or(-1)) {
            let parent = n.parent.map(|p| format!("{}/", model.node(p).browse_name.name)).unwrap_or_default();
            aligned.push(format!("{parent}{}", n.browse_name.name));
        }
    }
    aligned.sort();
    let mut types: Vec<String> = missing
        .iter()
        .map(|&ix| model.node(ix))
        .filter(|n| n.class == NodeClass::ObjectType)
        .map(|n| n.browse_name.name.clone())
        .collect();
    types.sort();
    Ok(Ns0Added { nodes, types, version, aligned })
}

/// A node table built in memory, made as `'static` as a generated one.
pub fn leak(t: NodeTable) -> &'static NodeSetTable {
    let namespaces: Vec<&'static str> = t.namespaces.into_iter().map(|u| &*Box::leak(u.into_boxed_str())).collect();
    Box::leak(Box::new(NodeSetTable {
        namespace_uri: Box::leak(t.namespace_uri.into_boxed_str()),
        version: Box::leak(t.version.into_boxed_str()),
        publication_date: Box::leak(t.publication_date.into_boxed_str()),
        namespaces: Box::leak(namespaces.into_boxed_slice()),
        own: t.own,
        nodes: Nodes::Packed(Packed::new(Box::leak(t.rows.into_boxed_str()))),
    }))
}

/// The server's configuration for `tables` with `opts`: the runtime's secure defaults, then what the
/// options weaken (each with the runtime's warning, printed by [`serve`]).
pub fn config(tables: &[&'static NodeSetTable], opts: &ServeOptions) -> Result<ServerConfig, String> {
    let mut config = ServerConfig::new(APPLICATION_NAME).port(opts.port);
    if let Some(host) = &opts.host {
        config = config.host(host.clone());
    }
    if let Some(pki) = &opts.pki {
        config = config.pki_dir(pki.clone());
    }
    if let Some(file) = &opts.users {
        config = config.users(Users::load(file).map_err(|e| e.to_string())?);
    }
    if opts.trust_on_first_use {
        config = config.trust_on_first_use();
    }
    if opts.insecure {
        config = config.insecure();
    }
    for &t in tables {
        config = config.table(t);
    }
    Ok(config)
}

/// Serves `model` until SIGINT, SIGTERM or `opts.seconds`: prints the warnings of the configuration and
/// the instances that could not be created on stderr, `listening on <url>` on stdout once clients may
/// connect, and `server stopped cleanly` at the end. Must run inside a multi-threaded tokio runtime.
pub async fn serve(model: &Model, opts: &ServeOptions) -> Result<(), String> {
    let (tables, diags) = tables(model);
    if diags.has_errors() {
        return Err(format!("the node tables cannot be built:\n{}", diags.render(&model.sources)));
    }
    let config = config(&tables, opts)?;
    for warning in config.warnings() {
        eprintln!("{warning}");
    }
    let server = config.build()?;
    let manager = server.manager().clone();
    let handle = server.handle().clone();
    let stop = stop_requested(opts.seconds);
    let running = server.start();
    // ns0's missing nodes are added, and instances made, once async-opcua has loaded ns0 into its address
    // space and the type tree (when the server starts running): before, a reference type of the files that
    // derives from ns0's HasComponent is not known to be hierarchical, and which members an instance gets
    // would depend on timing.
    wait_for_ns0_types(&handle).await?;
    let added = add_missing_ns0(&manager, model)?;
    if added.nodes > 0 {
        let types = match added.types.len() {
            0 => String::new(),
            n => format!(", {n} ObjectType(s) among them: {}", added.types.join(", ")),
        };
        eprintln!(
            "note: {} node(s) of the model's OPC UA namespace ({}) that async-opcua's ns0 lacks are served from the model{types}",
            added.nodes, added.version
        );
    }
    if !added.aligned.is_empty() {
        eprintln!(
            "note: {} InstanceDeclaration(s) of the OPC UA namespace served with the DataType and ValueRank of the model's ({}), where async-opcua's differ: {}",
            added.aligned.len(),
            added.version,
            added.aligned.join(", ")
        );
    }
    if opts.instantiate_all {
        let done = instances::instantiate_all(&manager, model);
        for (what, why) in &done.failures {
            eprintln!("warning: {what} is not instantiated: {why}");
        }
        eprintln!(
            "instantiated {} of {} concrete ObjectType(s) below Objects/Instances ({} nodes, {} state machine(s) served, {} without an initial state)",
            done.instantiated,
            done.types,
            done.nodes,
            done.machines,
            done.without_initial_state
        );
    }
    let locks = manager.serve_locks()?;
    if locks > 0 {
        eprintln!("served DI locking on {locks} Lock object(s)");
    }
    running.serve_until(stop, std::future::pending()).await
}

/// Waits (at most 30 s) until the running server's type tree holds ns0's reference types. async-opcua loads
/// them under one write lock when the server starts, so once HasComponent is known to be hierarchical, all
/// of ns0 is there.
pub async fn wait_for_ns0_types(handle: &opcua::server::ServerHandle) -> Result<(), String> {
    use opcua::nodes::TypeTree;
    use opcua::types::ReferenceTypeId;
    let (component, hierarchical) = (ReferenceTypeId::HasComponent.into(), ReferenceTypeId::HierarchicalReferences.into());
    for _ in 0..3000 {
        if handle.type_tree().read().is_subtype_of(&component, &hierarchical) {
            return Ok(());
        }
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    Err("the server did not load the OPC UA namespace's types within 30 s".into())
}
