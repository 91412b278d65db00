//! The node manager that serves generated tables, and the handle user code holds to it.

use std::collections::{HashMap, HashSet};
use std::future::Future;
use std::sync::Arc;

use async_trait::async_trait;
use opcua::nodes::{DefaultTypeTree, Event, EventNotifier, NodeType};
use opcua::server::address_space::{validate_node_write, write_node_value, AccessLevel, AddressSpace};
use opcua::server::diagnostics::NamespaceMetadata;
use opcua::server::node_manager::memory::{
    CoreNodeManager, InMemoryNodeManager, InMemoryNodeManagerBuilder, InMemoryNodeManagerImpl,
};
use opcua::server::node_manager::{
    MethodCall, NodeManagerBuilder, NodeManagersRef, ParsedReadValueId, ParsedWriteValue,
    RequestContext, ServerContext, WriteNode,
};
use opcua::server::{CreateMonitoredItem, ServerHandle, SubscriptionCache};
use opcua::sync::RwLock;
use opcua::types::{
    AccessRestrictionType, Argument, AttributeId, BrowseDirection, DataEncoding, DataValue, NodeId, MessageSecurityMode, NumericRange, QualifiedName, StatusCode,
    TimestampsToReturn, Variant,
};
use tracing::{error, warn};

use super::check::Types;
use super::fields::field_children;
use super::locks::Locks;
use crate::import::{build_map, parse_date_time, TableImport, OPC_UA_NAMESPACE};
use crate::table::{NamespaceMap, NodeSetTable, NsNodeId, UNMAPPED};

/// ns0 HasProperty.
const HAS_PROPERTY: u32 = 46;

/// Decides a client's write of a variable's value.
///
/// The handler gets the value as the client sent it, already checked against the variable's DataType and
/// ValueRank (structures arrive decoded when a type loader knows them). `Err(status)` rejects the write with
/// that status, `Ok(None)` stores the value as written, `Ok(Some(v))` stores `v` instead. The handler runs
/// without locks held, so it may call [`ModelManager::set_value`].
pub type WriteHandler = Arc<dyn Fn(&Variant) -> Result<Option<Variant>, StatusCode> + Send + Sync + 'static>;

/// One call of a method, as a [`MethodHandler`] receives it.
pub struct MethodInvocation {
    /// The object (or ObjectType) the method was called on.
    pub object_id: NodeId,
    /// The method node.
    pub method_id: NodeId,
    /// The input arguments, already checked against the method's InputArguments (count and types).
    pub arguments: Vec<Variant>,
    /// The manager, to read and set values from the handler.
    pub manager: ModelManager,
    /// The calling session's user: its user name (or the name of its user certificate), `None` if it is
    /// anonymous (for an audit line, or to record who started a skill).
    pub user: Option<String>,
    /// The ApplicationUri the calling client gave when it created its session (empty if it gave none).
    pub client: String,
}

/// Why a method call failed.
#[derive(Clone, Debug, PartialEq)]
pub enum MethodError {
    /// The call's status, such as `BadInvalidState` or `BadOutOfRange`.
    Status(StatusCode),
    /// One status per input argument; the call's status becomes `BadInvalidArgument`.
    Arguments(Vec<StatusCode>),
}

impl From<StatusCode> for MethodError {
    fn from(status: StatusCode) -> Self {
        MethodError::Status(status)
    }
}

/// What a method handler returns: the output arguments, or why the call failed.
pub type MethodResult = Result<Vec<Variant>, MethodError>;

/// The implementation of a method node.
///
/// Any `Fn(MethodInvocation) -> impl Future<Output = MethodResult>` is a handler, so an async closure (or a
/// closure returning an `async move` block) can be registered directly with [`ModelManager::on_call`].
#[async_trait]
pub trait MethodHandler: Send + Sync + 'static {
    /// Runs the method.
    async fn call(&self, invocation: MethodInvocation) -> MethodResult;
}

#[async_trait]
impl<F, Fut> MethodHandler for F
where
    F: Fn(MethodInvocation) -> Fut + Send + Sync + 'static,
    Fut: Future<Output = MethodResult> + Send + 'static,
{
    async fn call(&self, invocation: MethodInvocation) -> MethodResult {
        self(invocation).await
    }
}

/// The namespace of a table the manager serves, with its indices on this server.
struct ServedTable {
    table: &'static NodeSetTable,
    map: NamespaceMap,
}

/// async-opcua's node manager implementation for generated namespaces (use it through [`ModelManager`]).
///
/// It imports tables at server build time and answers reads, writes and method calls:
///
/// - a node whose AccessRestrictions (from its nodeset) require signing or encryption refuses the read of
///   its value, a subscription to it, a write and a call with `BadSecurityModeInsufficient` on a channel
///   that is not signed, or not encrypted (Browse and its other attributes stay open);
/// - a write of a variable's value is refused with `BadNotWritable` if the variable's AccessLevel lacks
///   CurrentWrite, with `BadUserAccessDenied` if only the UserAccessLevel does, with `BadTypeMismatch` if
///   the value does not fit the DataType and ValueRank, with the status of the range (`BadIndexRangeNoData`
///   on a scalar, ...) if an IndexRange does not fit the stored value; only then the node's [`WriteHandler`],
///   if any, decides;
///   the stored value is reported to subscriptions;
/// - other attributes are writable only where the node's WriteMask allows it (async-opcua's rules);
/// - a method call is refused if the method's Executable attribute is false (async-opcua's in-memory node
///   manager answers `BadUserAccessDenied` for it before this one sees the call, not `BadNotExecutable`),
///   with `BadArgumentsMissing` or `BadTooManyArguments` if the argument count differs from its
///   InputArguments, with `BadInvalidArgument` and one status per argument (`BadTypeMismatch` where an
///   argument does not fit) if types differ, and with `BadNotImplemented` if no handler is registered;
///   otherwise the method's [`MethodHandler`] runs, without locks held.
pub struct ModelNodes {
    tables: Vec<ServedTable>,
    namespaces: Vec<NamespaceMetadata>,
    instance_ns: u16,
    node_managers: NodeManagersRef,
    subscriptions: Arc<SubscriptionCache>,
    type_tree: Arc<RwLock<DefaultTypeTree>>,
    write_handlers: RwLock<HashMap<NodeId, WriteHandler>>,
    method_handlers: RwLock<HashMap<NodeId, Arc<dyn MethodHandler>>>,
    /// The AccessRestrictions the tables give their nodes (the nodes without any are not listed).
    restrictions: HashMap<NodeId, AccessRestrictionType>,
    /// The declaration each InstanceDeclaration of the tables overrides (the compiler's `Overrides` rows),
    /// which `instantiate` follows to merge members by browse path; with the links given by
    /// [`ModelManager::add_overrides`] for declarations no table carries.
    overrides: RwLock<HashMap<NodeId, NodeId>>,
    /// DI's locks served on this server ([`super::locks`]).
    pub(super) locks: Locks,
}

/// The node manager type as async-opcua's `ServerHandle::node_managers()` holds it.
pub type ModelNodeManager = InMemoryNodeManager<ModelNodes>;

/// A node manager builder for `ServerBuilder::with_node_manager` that serves `tables`.
///
/// Namespace indices are assigned in the order of `tables` (after the server's own namespace 1), then come
/// namespaces the tables only refer to. A table whose namespace URI was already given, or whose own
/// namespace index is 0, is skipped with a warning. [`super::ServerConfig`] does all of this for you; use this function to add generated namespaces
/// to a server you configure yourself.
pub fn model_node_manager(tables: impl IntoIterator<Item = &'static NodeSetTable>) -> impl NodeManagerBuilder {
    model_node_manager_with_instances(tables, DEFAULT_INSTANCE_NAMESPACE)
}

/// The namespace of instances created with [`ModelManager::instantiate`] unless the server names one.
pub const DEFAULT_INSTANCE_NAMESPACE: &str = "urn:nodeset-models:instances";

/// [`model_node_manager`] with the namespace URI that instances created at run time get their NodeIds and
/// BrowseNames in.
pub fn model_node_manager_with_instances(
    tables: impl IntoIterator<Item = &'static NodeSetTable>,
    instance_namespace: &str,
) -> impl NodeManagerBuilder {
    let tables: Vec<&'static NodeSetTable> = tables.into_iter().collect();
    let instance_namespace = instance_namespace.to_owned();
    InMemoryNodeManagerBuilder::new(move |context: ServerContext, space: &mut AddressSpace| {
        ModelNodes::import(tables, &instance_namespace, context, space)
    })
}

impl ModelNodes {
    fn import(
        tables: Vec<&'static NodeSetTable>,
        instance_namespace: &str,
        context: ServerContext,
        space: &mut AddressSpace,
    ) -> ModelNodes {
        let mut seen = HashSet::new();
        let tables: Vec<_> = tables
            .into_iter()
            .filter(|t| {
                if t.own == 0 {
                    warn!("the table of {} claims namespace 0; it is not served", t.namespace_uri);
                    return false;
                }
                // Rows and override rows both decide what the server has; a table with either damaged is refused.
                if let Err(e) = t.rows().map(drop).and_then(|()| t.overrides().map(drop)) {
                    error!("{e}; the table is not served");
                    return false;
                }
                let fresh = seen.insert(t.namespace_uri);
                if !fresh {
                    warn!("the table of {} is given twice; served once", t.namespace_uri);
                }
                fresh
            })
            .collect();
        let mut served = Vec::new();
        let instance_ns;
        // Structure values are decoded with the server's type loaders (ns0's and the generated namespaces').
        let loaders = context.info.type_loaders.read().clone();
        {
            let mut tree = context.type_tree.write();
            for t in &tables {
                tree.namespaces_mut().add_namespace(t.namespace_uri);
            }
            for t in &tables {
                space.import_node_set(&TableImport::with_type_loaders(t, loaders.clone()), tree.namespaces_mut());
                let known = tree.namespaces();
                served.push(ServedTable { table: t, map: build_map(t, |_, uri| known.get_index(uri)) });
            }
            instance_ns = tree.namespaces_mut().add_namespace(instance_namespace);
            space.add_namespace(instance_namespace, instance_ns);
            // async-opcua loads the types when the server starts running; loading them now as well lets
            // `ModelManager::set_value` check values against them before that.
            space.load_into_type_tree(&mut tree);
        }
        let restrictions = access_restrictions(&served);
        let overrides = overrides(&served);
        let mut namespaces = namespace_metadata(&served);
        super::namespace_objects::fold_into(space, &context.type_tree.read(), &mut namespaces);
        if !namespaces.iter().any(|m| m.namespace_index == instance_ns) {
            namespaces.push(NamespaceMetadata {
                namespace_uri: instance_namespace.to_owned(),
                namespace_index: instance_ns,
                is_namespace_subset: Some(false),
                ..Default::default()
            });
        }
        ModelNodes {
            tables: served,
            namespaces,
            instance_ns,
            node_managers: context.node_managers.clone(),
            subscriptions: context.subscriptions.clone(),
            type_tree: context.type_tree.clone(),
            write_handlers: Default::default(),
            method_handlers: Default::default(),
            restrictions,
            overrides: RwLock::new(overrides),
            locks: Locks::default(),
        }
    }

    /// Why the session of `context` may not read, write or call `node` (Part 3, 5.2.11): SigningRequired
    /// needs a signed channel, EncryptionRequired an encrypted one (`BadSecurityModeInsufficient`).
    /// SessionRequired always holds (every request here comes with a session); ApplyRestrictionsToBrowse is
    /// not evaluated: Browse and the other attributes stay open.
    fn restricted(&self, context: &RequestContext, node: &NodeId) -> Option<StatusCode> {
        let r = self.restrictions.get(node)?;
        let mode = context.session().read().message_security_mode();
        let signed = matches!(mode, MessageSecurityMode::Sign | MessageSecurityMode::SignAndEncrypt);
        let encrypted = mode == MessageSecurityMode::SignAndEncrypt;
        let refused = (r.contains(AccessRestrictionType::SigningRequired) && !signed)
            || (r.contains(AccessRestrictionType::EncryptionRequired) && !encrypted);
        refused.then_some(StatusCode::BadSecurityModeInsufficient)
    }

    /// The [`ModelManager`] of this node manager, found among the server's node managers.
    fn manager(&self) -> Option<ModelManager> {
        self.node_managers.iter().find_map(|nm| {
            let nm = nm.into_any_arc().downcast::<ModelNodeManager>().ok()?;
            std::ptr::eq(nm.inner(), self).then(|| ModelManager { node_manager: nm })
        })
    }

    /// Checks a write and returns the value to store.
    fn validate_write(
        &self,
        context: &RequestContext,
        types: &Types,
        write: &ParsedWriteValue,
    ) -> Result<Variant, StatusCode> {
        if let Some(status) = self.restricted(context, &write.node_id) {
            return Err(status);
        }
        let space = types.space.ok_or(StatusCode::BadInternalError)?;
        self.locks.check(space, types.tree, &write.node_id, None, &client_of(context))?;
        let node = space.find(&write.node_id).ok_or(StatusCode::BadNodeIdUnknown)?;
        if write.attribute_id == AttributeId::Value {
            let NodeType::Variable(var) = node else {
                return Err(StatusCode::BadNotWritable);
            };
            // async-opcua only looks at the UserAccessLevel and answers BadUserAccessDenied; a variable that
            // nobody may write is BadNotWritable (Part 4, Write service).
            if !var.access_level().contains(AccessLevel::CURRENT_WRITE) {
                return Err(StatusCode::BadNotWritable);
            }
        }
        validate_node_write(node, context, write, types.tree)?;
        let value = write.value.value.clone().unwrap_or_default();
        if let (NodeType::Variable(var), AttributeId::Value) = (node, write.attribute_id) {
            types.check(&value, &var.data_type(), var.value_rank(), write.index_range.has_range())?;
            if write.index_range.has_range() {
                // async-opcua applies the range only when it stores the value; try it on a copy now, so that
                // a write it will refuse (BadIndexRangeNoData on a scalar, ...) never reaches the handler.
                let stored = var.value(TimestampsToReturn::Neither, &NumericRange::None, &DataEncoding::Binary, 0.0);
                let mut stored = stored.value.ok_or(StatusCode::BadIndexRangeInvalid)?;
                stored.set_range_of(&write.index_range, &value)?;
            }
        }
        Ok(value)
    }

    /// Checks a call against the method's Executable attribute and InputArguments.
    fn validate_call(&self, types: &Types, call: &MethodCall) -> Result<(), MethodError> {
        let Some(NodeType::Method(method)) = types.space.and_then(|s| s.find(call.method_id())) else {
            return Err(StatusCode::BadMethodInvalid.into());
        };
        // Unreachable through async-opcua 0.19's pre-checks (see above), kept should they change.
        if !method.executable() {
            return Err(StatusCode::BadNotExecutable.into());
        }
        let inputs = input_arguments(types, call.method_id());
        let args = call.arguments();
        if args.len() < inputs.len() {
            return Err(StatusCode::BadArgumentsMissing.into());
        }
        if args.len() > inputs.len() {
            return Err(StatusCode::BadTooManyArguments.into());
        }
        let results: Vec<StatusCode> = args
            .iter()
            .zip(&inputs)
            .map(|(v, a)| match types.check(v, &a.data_type, a.value_rank, false) {
                Ok(()) => StatusCode::Good,
                Err(s) => s,
            })
            .collect();
        if results.iter().any(|s| s.is_bad()) {
            return Err(MethodError::Arguments(results));
        }
        Ok(())
    }
}

/// The Arguments of a method's InputArguments property (none if it has no such property).
fn input_arguments(types: &Types, method: &NodeId) -> Vec<Argument> {
    let Some(space) = types.space else {
        return Vec::new();
    };
    let node = space.find_node_by_browse_name(
        method,
        Some((NodeId::new(0, HAS_PROPERTY), false)),
        types.tree,
        BrowseDirection::Forward,
        QualifiedName::new(0, "InputArguments"),
    );
    let Some(NodeType::Variable(var)) = node else {
        return Vec::new();
    };
    let value = var.value(TimestampsToReturn::Neither, &NumericRange::None, &DataEncoding::Binary, 0.0).value;
    let Some(Variant::Array(array)) = value else {
        return Vec::new();
    };
    array
        .values
        .iter()
        .filter_map(|v| match v {
            Variant::ExtensionObject(eo) => eo.inner_as::<Argument>().cloned(),
            _ => None,
        })
        .collect()
}

/// NamespaceMetadata of every namespace the tables use (their own and those they refer to), so the
/// server's NamespaceArray has no holes; version and publication date for the tables' own namespaces.
fn namespace_metadata(served: &[ServedTable]) -> Vec<NamespaceMetadata> {
    let mut out: Vec<NamespaceMetadata> = Vec::new();
    for s in served {
        for (local, &index) in s.map.indices.iter().enumerate() {
            let uri = if local == s.table.own as usize {
                s.table.namespace_uri
            } else {
                s.table.namespaces.get(local).copied().unwrap_or_default()
            };
            if index == 0
                || index == UNMAPPED
                || uri == OPC_UA_NAMESPACE
                || out.iter().any(|m| m.namespace_index == index)
            {
                continue;
            }
            out.push(NamespaceMetadata { namespace_uri: uri.to_owned(), namespace_index: index, ..Default::default() });
        }
    }
    for m in &mut out {
        // A namespace that is only referred to is served as an (empty) subset.
        m.is_namespace_subset = Some(true);
    }
    for s in served {
        if let Some(m) = out.iter_mut().find(|m| m.namespace_uri == s.table.namespace_uri) {
            m.namespace_version = Some(s.table.version.to_owned()).filter(|v| !v.is_empty());
            m.namespace_publication_date = parse_date_time(s.table.publication_date);
            m.is_namespace_subset = Some(false);
        }
    }
    out.sort_by_key(|m| m.namespace_index);
    out
}

#[async_trait]
impl InMemoryNodeManagerImpl for ModelNodes {
    async fn init(&self, _address_space: &mut AddressSpace, _context: ServerContext) {}

    fn name(&self) -> &str {
        "nodeset-models"
    }

    fn namespaces(&self) -> Vec<NamespaceMetadata> {
        self.namespaces.clone()
    }

    async fn read_values(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        nodes: &[&ParsedReadValueId],
        max_age: f64,
        timestamps_to_return: TimestampsToReturn,
    ) -> Vec<DataValue> {
        let space = address_space.read();
        nodes
            .iter()
            .map(|n| match self.restricted(context, &n.node_id) {
                Some(status) => DataValue { status: Some(status), ..Default::default() },
                None => space.read(context, n, max_age, timestamps_to_return),
            })
            .collect()
    }

    async fn create_value_monitored_items(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        items: &mut [&mut &mut CreateMonitoredItem],
    ) {
        // A restricted value is refused outright: notifications of later changes would bypass the check.
        let mut open = Vec::new();
        for item in items.iter_mut() {
            match self.restricted(context, &item.item_to_monitor().node_id) {
                Some(status) => item.set_status(status),
                None => open.push(item),
            }
        }
        let to_read: Vec<_> = open.iter().map(|i| i.item_to_monitor()).collect();
        let values = self.read_values(context, address_space, &to_read, 0.0, TimestampsToReturn::Both).await;
        for (value, item) in values.into_iter().zip(open) {
            if value.status() != StatusCode::BadAttributeIdInvalid {
                item.set_initial_value(value);
            }
            item.set_status(StatusCode::Good);
        }
    }

    async fn write(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        nodes_to_write: &mut [&mut WriteNode],
    ) -> Result<(), StatusCode> {
        // Three phases, so that handlers run without locks: check, ask the handlers, store and notify.
        let mut accepted = Vec::new();
        {
            let space = address_space.read();
            let tree = context.type_tree.read();
            let types = Types { tree: &tree, space: Some(&space) };
            for (i, write) in nodes_to_write.iter_mut().enumerate() {
                match self.validate_write(context, &types, write.value()) {
                    Ok(value) => accepted.push((i, value)),
                    Err(status) => write.set_status(status),
                }
            }
        }
        let mut to_store = Vec::new();
        for (i, value) in accepted {
            let write = &mut nodes_to_write[i];
            let handler = match write.value().attribute_id {
                AttributeId::Value => self.write_handlers.read().get(&write.value().node_id).cloned(),
                _ => None,
            };
            let value = match handler.map(|h| h(&value)) {
                None | Some(Ok(None)) => value,
                Some(Ok(Some(replaced))) => replaced,
                Some(Err(status)) => {
                    write.set_status(status);
                    continue;
                }
            };
            to_store.push((i, value));
        }
        let tree = context.type_tree.read();
        let mut space = address_space.write();
        let mut changed = Vec::new();
        for (i, value) in to_store {
            let write = &mut nodes_to_write[i];
            let mut parsed = write.value().clone();
            parsed.value.value = Some(value);
            let Some(node) = space.find_mut(&parsed.node_id) else {
                write.set_status(StatusCode::BadNodeIdUnknown);
                continue;
            };
            match write_node_value(node, &parsed) {
                Ok(()) => {
                    write.set_status(StatusCode::Good);
                    if parsed.attribute_id == AttributeId::Value {
                        mirror_fields(&mut space, &tree, &parsed.node_id, &parsed.value, &mut changed);
                    }
                    changed.push((parsed.node_id, parsed.attribute_id));
                }
                Err(status) => write.set_status(status),
            }
        }
        context.subscriptions.maybe_notify(changed.iter().map(|(id, a)| (id, *a)), |id, attribute, range, encoding| {
            space.find(id)?.as_node().get_attribute(TimestampsToReturn::Both, attribute, range, encoding)
        });
        Ok(())
    }

    async fn call(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        methods_to_call: &mut [&mut &mut MethodCall],
    ) -> Result<(), StatusCode> {
        // async-opcua already checked that the method is a component of the object, that the user may
        // execute it and that there are not more arguments than InputArguments.
        let mut jobs = Vec::new();
        {
            let space = address_space.read();
            let tree = context.type_tree.read();
            let types = Types { tree: &tree, space: Some(&space) };
            let handlers = self.method_handlers.read();
            for (i, call) in methods_to_call.iter_mut().enumerate() {
                if let Some(status) = self.restricted(context, call.method_id()) {
                    call.set_status(status);
                    continue;
                }
                if let Err(status) =
                    self.locks.check(&space, &*tree, call.object_id(), Some(call.object_id()), &client_of(context))
                {
                    call.set_status(status);
                    continue;
                }
                match self.validate_call(&types, call) {
                    Err(MethodError::Status(status)) => call.set_status(status),
                    Err(MethodError::Arguments(results)) => call.set_argument_error(results),
                    Ok(()) => match handlers.get(call.method_id()) {
                        Some(handler) => jobs.push((i, handler.clone())),
                        None => call.set_status(StatusCode::BadNotImplemented),
                    },
                }
            }
        }
        if jobs.is_empty() {
            return Ok(());
        }
        let Some(manager) = self.manager() else {
            for (i, _) in jobs {
                methods_to_call[i].set_status(StatusCode::BadShutdown);
            }
            return Ok(());
        };
        for (i, handler) in jobs {
            let call = &mut methods_to_call[i];
            let invocation = MethodInvocation {
                object_id: call.object_id().clone(),
                method_id: call.method_id().clone(),
                arguments: call.arguments().to_vec(),
                manager: manager.clone(),
                user: Some(context.user_token().0.clone()).filter(|u| u != opcua::server::ANONYMOUS_USER_TOKEN_ID),
                client: client_of(context),
            };
            match handler.call(invocation).await {
                Ok(outputs) => {
                    call.set_outputs(outputs);
                    call.set_status(StatusCode::Good);
                }
                Err(MethodError::Status(status)) => call.set_status(status),
                Err(MethodError::Arguments(mut results)) => {
                    // async-opcua requires one result per argument.
                    results.resize(call.arguments().len(), StatusCode::Good);
                    call.set_argument_error(results);
                }
            }
        }
        Ok(())
    }
}

/// The ApplicationUri the client of `context` gave when it created its session (empty if it gave none).
fn client_of(context: &RequestContext) -> String {
    context.session().read().application_description().application_uri.as_ref().to_owned()
}

/// The handle user code holds to the generated namespaces of a running server: resolve NodeIds, register
/// write and method handlers, read and set values.
///
/// It is cheap to clone. Get it from [`super::ModelServer::manager`], or from any async-opcua server handle
/// with [`ModelManager::from_handle`].
#[derive(Clone)]
pub struct ModelManager {
    node_manager: Arc<ModelNodeManager>,
}

impl ModelManager {
    /// The model node manager of a server, if it has one (the first, if it has several).
    pub fn from_handle(handle: &ServerHandle) -> Option<ModelManager> {
        let node_manager = handle.node_managers().get_of_type::<ModelNodeManager>()?;
        Some(ModelManager { node_manager })
    }

    /// The async-opcua node manager, for anything this handle does not offer (its address space, for one).
    pub fn node_manager(&self) -> &Arc<ModelNodeManager> {
        &self.node_manager
    }

    pub(super) fn nodes(&self) -> &ModelNodes {
        self.node_manager.inner()
    }

    /// The declaration each InstanceDeclaration of the served tables overrides, by server NodeId (for
    /// `instantiate` in [`crate::typed::instance`]).
    pub(crate) fn overrides(&self) -> impl std::ops::Deref<Target = HashMap<NodeId, NodeId>> + '_ {
        self.nodes().overrides.read()
    }

    /// Adds links (declaration, the declaration it overrides at its browse path) that no served table
    /// carries: those of ns0's InstanceDeclarations, which async-opcua serves without the compiler's
    /// `Overrides` rows. `nodeset-compiler serve` gives the ones of its resolved model, so that
    /// `instantiate` merges the members of an ns0 subtype's declaration (`Counters` of
    /// PubSubDiagnosticsDataSetReaderType) with those of the declaration it overrides (`Counters` of
    /// PubSubDiagnosticsType), as the model does. A link already known is kept.
    pub fn add_overrides(&self, links: impl IntoIterator<Item = (NodeId, NodeId)>) {
        let mut overrides = self.nodes().overrides.write();
        for (decl, over) in links {
            overrides.entry(decl).or_insert(over);
        }
    }

    /// Adds the nodes of `table`, a table of namespace 0 (`own` 0), to the ns0 the server serves (async-opcua's
    /// core node manager), with their references, and its types to the type tree; a node the served ns0
    /// has already is left as it is. For a server of nodesets resolved against a newer ns0 than async-opcua's
    /// (its 1.05.04; the registry package's is 1.05.07): `nodeset-compiler serve` gives the nodes its model's
    /// ns0 has and the served one lacks, so that their types can be instantiated. Returns how many nodes
    /// were added; call it once the server runs (async-opcua fills ns0 then).
    pub fn add_ns0_nodes(&self, table: &'static NodeSetTable) -> Result<usize, String> {
        let core = self.core_node_manager().ok_or("the server has no node manager of namespace 0")?;
        let import = TableImport::ns0_supplement(table);
        // The type tree first (see `ModelManager::bind_with`).
        let mut tree = self.type_tree().write();
        let mut space = core.address_space().write();
        let rows = table.rows().map_err(|e| e.to_string())?;
        let map = build_map(table, |_, uri| tree.namespaces().get_index(uri));
        let fresh = rows.iter().filter_map(|r| map.try_id(r.id)).filter(|id| !space.node_exists(id)).count();
        // The types reach the tree from an address space of the new nodes alone: the core's was loaded
        // into it when the server started.
        let mut added = AddressSpace::new();
        added.import_node_set(&import, tree.namespaces_mut());
        added.load_into_type_tree(&mut tree);
        space.import_node_set(&import, tree.namespaces_mut());
        Ok(fresh)
    }

    /// Gives the variable `id` of the served ns0 (async-opcua's core node manager) the DataType and ValueRank
    /// given, where they differ; returns whether it changed anything. For the InstanceDeclarations of ns0's
    /// types, when the nodesets were resolved against another ns0 than async-opcua's (1.05.03's
    /// AuditClientUpdateMethodResultEventType has a `MethodId` of DataType NodeId, async-opcua's
    /// ExpandedNodeId): `nodeset-compiler serve` gives the model's, so that the type clients browse and the
    /// instances made from it agree with the nodesets. A value that no longer fits is dropped.
    pub fn align_ns0_variable(&self, id: &NodeId, data_type: &NodeId, value_rank: i32) -> bool {
        let Some(core) = self.core_node_manager() else { return false };
        let tree = self.type_tree().read();
        let mut space = core.address_space().write();
        let Some(NodeType::Variable(v)) = space.find_mut(id) else { return false };
        if v.data_type() == *data_type && v.value_rank() == value_rank {
            return false;
        }
        v.set_data_type(data_type.clone());
        v.set_value_rank(value_rank);
        let value = v.value(TimestampsToReturn::Neither, &NumericRange::None, &DataEncoding::Binary, 0.0);
        if let Some(value) = value.value {
            let fits = Types { tree: &tree, space: None }.check(&value, data_type, value_rank, false).is_ok();
            if !fits {
                v.set_value(&NumericRange::None, Variant::Empty).ok();
            }
        }
        true
    }

    /// Whether the ns0 the server serves (async-opcua's core node manager) has the node `id`.
    pub fn ns0_has(&self, id: &NodeId) -> bool {
        self.core_node_manager().is_some_and(|core| core.address_space().read().node_exists(id))
    }

    /// The server's node manager of ns0, if it has one.
    pub(crate) fn core_node_manager(&self) -> Option<Arc<CoreNodeManager>> {
        self.nodes().node_managers.get_of_type::<CoreNodeManager>()
    }

    /// The server's index of a namespace URI, if the server knows it.
    pub fn namespace_index(&self, namespace_uri: &str) -> Option<u16> {
        self.nodes().type_tree.read().namespaces().get_index(namespace_uri)
    }

    /// The namespace map of a served table (the table named by its namespace URI).
    pub fn namespace_map(&self, namespace_uri: &str) -> Option<&NamespaceMap> {
        self.nodes().tables.iter().find(|t| t.table.namespace_uri == namespace_uri).map(|t| &t.map)
    }

    /// The server NodeId of a generated NodeId constant.
    pub fn resolve(&self, id: NsNodeId) -> Option<NodeId> {
        id.resolve(self.nodes().type_tree.read().namespaces())
    }

    /// Sets (or replaces) the write handler of a variable.
    pub fn on_write(
        &self,
        node: &NodeId,
        handler: impl Fn(&Variant) -> Result<Option<Variant>, StatusCode> + Send + Sync + 'static,
    ) {
        self.nodes().write_handlers.write().insert(node.clone(), Arc::new(handler));
    }

    /// Sets (or replaces) the handler of a method node.
    pub fn on_call(&self, method: &NodeId, handler: impl MethodHandler) {
        self.nodes().method_handlers.write().insert(method.clone(), Arc::new(handler));
    }

    /// The current value of a variable, `None` if there is no such variable.
    pub fn value(&self, node: &NodeId) -> Option<DataValue> {
        match self.node_manager.address_space().read().find(node)? {
            NodeType::Variable(v) => {
                Some(v.value(TimestampsToReturn::Both, &NumericRange::None, &DataEncoding::Binary, 0.0))
            }
            _ => None,
        }
    }

    /// Sets a variable's value (timestamped now) and reports it to subscriptions.
    ///
    /// The value must fit the variable's DataType and ValueRank (`BadTypeMismatch` otherwise);
    /// `BadNodeIdUnknown` if there is no such node, `BadAttributeIdInvalid` if it is not a variable. It
    /// never holds two locks at once, so it may be called at any time from any thread, also while the
    /// server starts.
    pub fn set_value(&self, node: &NodeId, value: impl Into<Variant>) -> Result<(), StatusCode> {
        let value = value.into();
        let (data_type, value_rank) = match self.node_manager.address_space().read().find(node) {
            Some(NodeType::Variable(var)) => (var.data_type(), var.value_rank()),
            Some(_) => return Err(StatusCode::BadAttributeIdInvalid),
            None => return Err(StatusCode::BadNodeIdUnknown),
        };
        {
            let tree = self.nodes().type_tree.read();
            Types { tree: &tree, space: None }.check(&value, &data_type, value_rank, false)?;
        }
        self.set_data_value(node, DataValue::new_now(value))
    }

    /// The namespace index of instances created with [`ModelManager::instantiate`].
    pub fn instance_namespace(&self) -> u16 {
        self.nodes().instance_ns
    }

    /// The server's type tree (types of ns0 and of every table).
    pub fn type_tree(&self) -> &Arc<RwLock<DefaultTypeTree>> {
        &self.nodes().type_tree
    }

    /// Reports an event to the clients that monitor any of `notifiers` for events (the event's source, the
    /// Server object, ...). async-opcua evaluates each monitored item's EventFilter against the event.
    pub fn notify_event(&self, event: &dyn Event, notifiers: &[NodeId]) {
        self.nodes().subscriptions.notify_events(notifiers.iter().map(|n| (event, n)));
    }

    /// Sets the EventNotifier attribute of an object (`SUBSCRIBE_TO_EVENTS` lets clients monitor it for
    /// events). `BadNodeIdUnknown` if there is no such node, `BadAttributeIdInvalid` if it is not an object.
    pub fn set_event_notifier(&self, node: &NodeId, notifier: EventNotifier) -> Result<(), StatusCode> {
        match self.node_manager.address_space().write().find_mut(node) {
            Some(NodeType::Object(object)) => {
                object.set_event_notifier(notifier);
                Ok(())
            }
            Some(_) => Err(StatusCode::BadAttributeIdInvalid),
            None => Err(StatusCode::BadNodeIdUnknown),
        }
    }

    /// Sets a variable's whole DataValue (value, status, timestamps) unchecked, and reports it to
    /// subscriptions.
    ///
    /// A structured value whose fields ns0 shows as child variables (a 3DFrame, a RationalNumber, ...) sets
    /// those children too (the VariableTypes of OPC 10000-5 that show the fields of their structure).
    pub fn set_data_value(&self, node: &NodeId, value: DataValue) -> Result<(), StatusCode> {
        let children = {
            let tree = self.nodes().type_tree.read();
            let space = self.node_manager.address_space().read();
            field_children(&space, &tree, node, &value)
        };
        self.node_manager.set_value(&self.nodes().subscriptions, node, None, value)?;
        for (child, value) in children {
            self.set_data_value(&child, value)?;
        }
        Ok(())
    }
}

/// Sets the children that show the fields of `node`'s new value (and theirs, down the tree), within the
/// write lock of a client's write; each one set is added to `changed` for the subscriptions.
fn mirror_fields(
    space: &mut AddressSpace,
    tree: &DefaultTypeTree,
    node: &NodeId,
    value: &DataValue,
    changed: &mut Vec<(NodeId, AttributeId)>,
) {
    let mut pending = field_children(space, tree, node, value);
    while let Some((child, value)) = pending.pop() {
        pending.extend(field_children(space, tree, &child, &value));
        if let Some(NodeType::Variable(var)) = space.find_mut(&child) {
            var.set_data_value(value);
            changed.push((child, AttributeId::Value));
        }
    }
}

/// The declaration each InstanceDeclaration of the served tables overrides, by server NodeId.
fn overrides(served: &[ServedTable]) -> HashMap<NodeId, NodeId> {
    let mut out = HashMap::new();
    for t in served {
        // The table's override rows were decoded when it was accepted.
        let Ok(rows) = t.table.overrides() else { continue };
        for row in rows {
            if let (Some(decl), Some(over)) = (t.map.try_id(row.id), t.map.try_id(row.overridden)) {
                out.insert(decl, over);
            }
        }
    }
    out
}

/// The AccessRestrictions the served tables give their nodes, by server NodeId.
fn access_restrictions(served: &[ServedTable]) -> HashMap<NodeId, AccessRestrictionType> {
    let mut out = HashMap::new();
    for t in served {
        // The table was checked when it was accepted; a damaged access row was reported by the access policy.
        let Ok(rows) = t.table.access() else { continue };
        for row in rows {
            let (Some(bits), Some(node)) = (row.restrictions, t.map.try_id(row.id)) else { continue };
            let bits = AccessRestrictionType::from_bits_truncate(bits as i16);
            if !bits.is_empty() {
                out.insert(node, bits);
            }
        }
    }
    out
}
