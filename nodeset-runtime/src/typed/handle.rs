//! Typed handles to the nodes of an instance: [`ObjectNode`], [`Variable<T>`], [`Method<I, O>`],
//! [`Placeholders<H>`], and the [`Binder`] that generated handle structs use to find their children.

use std::fmt;
use std::future::Future;
use std::marker::PhantomData;
use std::sync::Arc;

use opcua::nodes::{DefaultTypeTree, NodeType, TypeTree};
use opcua::server::address_space::AddressSpace;
use opcua::types::{
    BrowseDirection, DataValue, DateTime, NodeClass, NodeId, QualifiedName, ReferenceTypeId, StatusCode, Variant,
};

use super::value::{rank_fits, UaValue};
use crate::server::{MethodError, MethodInvocation, ModelManager};
use crate::table::NsNodeId;

/// Why a handle could not be bound to a node.
#[derive(Clone, Debug, PartialEq)]
pub enum BindError {
    /// No node with this id in the model node manager's address space.
    UnknownNode(NodeId),
    /// The node's class is not the one the handle needs.
    WrongClass {
        /// The node.
        node: NodeId,
        /// The class the handle needs.
        expected: NodeClass,
        /// The node's class.
        found: NodeClass,
    },
    /// A mandatory child is missing.
    MissingChild {
        /// The node that lacks it.
        parent: NodeId,
        /// The child's BrowseName.
        browse_name: String,
    },
    /// A variable's ValueRank cannot be held by the handle's Rust type.
    ValueRank {
        /// The variable.
        node: NodeId,
        /// Its ValueRank.
        value_rank: i32,
        /// The ValueRank the Rust type holds.
        rust_value_rank: i32,
    },
    /// A namespace a handle names is not registered in the server.
    UnknownNamespace(String),
    /// A member marker's browse path does not follow [`MemberPath`](super::MemberPath)'s format (generated
    /// markers always do; this is for hand-written ones).
    BadMemberPath(super::BadMemberPath),
}

impl fmt::Display for BindError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BindError::UnknownNode(id) => write!(f, "there is no node {id}"),
            BindError::WrongClass { node, expected, found } => {
                write!(f, "node {node} is {found:?}, a handle of {expected:?} was asked for")
            }
            BindError::MissingChild { parent, browse_name } => {
                write!(f, "node {parent} has no child `{browse_name}`, which its type makes mandatory")
            }
            BindError::ValueRank { node, value_rank, rust_value_rank } => write!(
                f,
                "variable {node} has ValueRank {value_rank}, which a Rust type of ValueRank {rust_value_rank} cannot hold"
            ),
            BindError::UnknownNamespace(uri) => write!(f, "the server has no namespace `{uri}`"),
            BindError::BadMemberPath(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for BindError {}

impl From<super::BadMemberPath> for BindError {
    fn from(e: super::BadMemberPath) -> Self {
        BindError::BadMemberPath(e)
    }
}

/// A typed handle to a node: generated handle structs, [`ObjectNode`], [`Variable<T>`], [`Method<I, O>`].
pub trait Handle: Sized {
    /// Builds the handle of `node`, finding its children through `binder`. It does not fail: a problem is
    /// recorded in the binder, which keeps the first one, and the rest of the handle is built without
    /// looking anything up; [`Handle::bind`] then returns that problem. (Generated handles are structs of
    /// many members: a `?` per member made their code several times larger.)
    fn build(binder: &Binder<'_>, node: &NodeId) -> Self;

    /// Binds the handle to `node`: [`Handle::build`], then the first problem it met, if any.
    fn bind(binder: &Binder<'_>, node: &NodeId) -> Result<Self, BindError> {
        binder.finish(Self::build(binder, node))
    }
}

/// The typed layer's side of the server's [`ModelManager`]: typed handles bound to its nodes. It is defined
/// here, above the server, so that `server` never names the typed layer.
impl ModelManager {
    /// Binds a typed handle (a generated ObjectType handle, `Variable<T>`, ...) to an existing node.
    pub fn bind<H: Handle>(&self, node: &NodeId) -> Result<H, BindError> {
        Binder::bind(self, node)
    }

    /// Binds a typed handle to the node at `path` below the Objects folder: BrowseNames (their name part)
    /// separated by `/`, such as `DrillingCell/SkillSet/DrillHole`. A segment that matches no child, or
    /// several, is a `MissingChild` error naming the node where the path stopped.
    pub fn bind_path<H: Handle>(&self, path: &str) -> Result<H, BindError> {
        self.bind_with(|b| {
            let mut node: NodeId = opcua::types::ObjectId::ObjectsFolder.into();
            for segment in path.split('/').filter(|s| !s.is_empty()) {
                let hits: Vec<NodeId> = b
                    .children(&node)
                    .into_iter()
                    .filter(|c| b.browse_name(c).is_some_and(|q| q.name.as_ref() == segment))
                    .collect();
                match <[NodeId; 1]>::try_from(hits) {
                    Ok([one]) => node = one,
                    Err(_) => return Err(BindError::MissingChild { parent: node, browse_name: segment.to_owned() }),
                }
            }
            H::bind(b, &node)
        })
    }

    /// Runs `f` with a [`Binder`] (one read lock for a whole tree of handles).
    pub fn bind_with<H>(&self, f: impl FnOnce(&Binder<'_>) -> Result<H, BindError>) -> Result<H, BindError> {
        // The type tree first, then the address space: async-opcua initialises node managers holding the
        // type tree and then taking the address space, so the other order deadlocks a bind that runs while a
        // server on another thread starts.
        let tree = self.type_tree().read();
        let space = self.node_manager().address_space().read();
        f(&Binder::new(self, &space, &tree))
    }

}

/// Finds the children of instances for [`Handle::build`] while holding one read lock on the address space.
pub struct Binder<'a> {
    manager: &'a ModelManager,
    space: &'a AddressSpace,
    tree: &'a DefaultTypeTree,
    /// The first problem met since the last [`Binder::finish`].
    problem: std::cell::RefCell<Option<BindError>>,
}

impl<'a> Binder<'a> {
    /// Binds a handle of type `H` to `node` of the server `manager` serves.
    pub fn bind<H: Handle>(manager: &ModelManager, node: &NodeId) -> Result<H, BindError> {
        manager.bind_with(|b| H::bind(b, node))
    }

    pub(crate) fn new(manager: &'a ModelManager, space: &'a AddressSpace, tree: &'a DefaultTypeTree) -> Binder<'a> {
        Binder { manager, space, tree, problem: Default::default() }
    }

    /// Records a problem; the first one is kept.
    pub fn fail(&self, problem: BindError) {
        self.problem.borrow_mut().get_or_insert(problem);
    }

    /// Whether a problem has been recorded: what is built from now on is not looked up.
    pub fn failed(&self) -> bool {
        self.problem.borrow().is_some()
    }

    /// `value`, or the first problem recorded while it was built (which is then cleared).
    pub fn finish<H>(&self, value: H) -> Result<H, BindError> {
        match self.problem.borrow_mut().take() {
            Some(problem) => Err(problem),
            None => Ok(value),
        }
    }

    /// The manager the handles will use.
    pub fn manager(&self) -> &ModelManager {
        self.manager
    }

    /// The node's class, checked against `expected`.
    pub fn expect_class(&self, node: &NodeId, expected: NodeClass) -> Result<(), BindError> {
        let found = self.space.find(node).ok_or_else(|| BindError::UnknownNode(node.clone()))?.node_class();
        if found != expected {
            return Err(BindError::WrongClass { node: node.clone(), expected, found });
        }
        Ok(())
    }

    /// `H` bound to the same node (for the supertype part of a generated handle).
    pub fn this<H: Handle>(&self, node: &NodeId) -> Result<H, BindError> {
        H::bind(self, node)
    }

    /// [`Binder::this`] for [`Handle::build`].
    pub fn build_this<H: Handle>(&self, node: &NodeId) -> H {
        H::build(self, node)
    }

    /// [`Binder::child`] for [`Handle::build`].
    pub fn build_child<H: Handle>(&self, node: &NodeId, uri: &str, name: &str) -> H {
        H::build(self, &self.mandatory_child(node, uri, name))
    }

    /// [`Binder::optional`] for [`Handle::build`].
    pub fn build_optional<H: Handle>(&self, node: &NodeId, uri: &str, name: &str) -> Option<H> {
        match self.optional_child(node, uri, name) {
            Some(child) => Some(H::build(self, &child)),
            None => None,
        }
    }

    /// [`Binder::placeholders`] for [`Handle::build`].
    pub fn build_placeholders<H: Handle>(&self, node: &NodeId, type_id: NsNodeId) -> Placeholders<H> {
        let found = if self.failed() {
            Vec::new()
        } else {
            self.placeholder_children(node, type_id).unwrap_or_else(|e| {
                self.fail(e);
                Vec::new()
            })
        };
        let mut out = Vec::with_capacity(found.len());
        for (name, child) in found {
            out.push((name, H::build(self, &child)));
        }
        Placeholders(out)
    }

    /// The mandatory child to build; after a problem (or for a missing child, which is one) the null NodeId.
    fn mandatory_child(&self, node: &NodeId, uri: &str, name: &str) -> NodeId {
        let child = self.optional_child(node, uri, name);
        child.unwrap_or_else(|| {
            if !self.failed() {
                self.fail(BindError::MissingChild { parent: node.clone(), browse_name: name.to_owned() });
            }
            NodeId::null()
        })
    }

    /// The optional child to build, if the instance has it (and no problem was met before).
    fn optional_child(&self, node: &NodeId, uri: &str, name: &str) -> Option<NodeId> {
        if self.failed() {
            return None;
        }
        self.find_child(node, uri, name).unwrap_or_else(|e| {
            self.fail(e);
            None
        })
    }

    /// The BrowseName of a node, if there is such a node.
    pub fn browse_name(&self, node: &NodeId) -> Option<QualifiedName> {
        self.space.find(node).map(|n| n.as_node().browse_name().clone())
    }

    /// The child of `node` with BrowseName `name` in namespace `uri`, if there is one.
    pub fn find_child(&self, node: &NodeId, uri: &str, name: &str) -> Result<Option<NodeId>, BindError> {
        let ns = self.tree.namespaces().get_index(uri).ok_or_else(|| BindError::UnknownNamespace(uri.to_owned()))?;
        let wanted = QualifiedName::new(ns, name);
        Ok(self
            .children(node)
            .into_iter()
            .find(|c| self.space.find(c).is_some_and(|n| *n.as_node().browse_name() == wanted)))
    }

    /// The targets of `node`'s forward hierarchical references (HasSubtype excluded), in the order stored.
    pub fn children(&self, node: &NodeId) -> Vec<NodeId> {
        let has_subtype: NodeId = ReferenceTypeId::HasSubtype.into();
        self.space
            .find_references(node, None::<(NodeId, bool)>, self.tree, BrowseDirection::Forward)
            .filter(|r| *r.reference_type != has_subtype && super::instance::is_hierarchical(self.tree, r.reference_type))
            .map(|r| r.target_node.clone())
            .collect()
    }

    /// A mandatory child, bound as `H`.
    pub fn child<H: Handle>(&self, node: &NodeId, uri: &str, name: &str) -> Result<H, BindError> {
        self.finish(self.build_child(node, uri, name))
    }

    /// An optional child, bound as `H` if the instance has it.
    pub fn optional<H: Handle>(&self, node: &NodeId, uri: &str, name: &str) -> Result<Option<H>, BindError> {
        self.finish(self.build_optional(node, uri, name))
    }

    /// The instances of a placeholder: the children of `node` whose TypeDefinition is `type_id` or a
    /// subtype of it, keyed by BrowseName.
    pub fn placeholders<H: Handle>(&self, node: &NodeId, type_id: NsNodeId) -> Result<Placeholders<H>, BindError> {
        self.finish(self.build_placeholders(node, type_id))
    }

    /// The children [`Binder::placeholders`] binds, sorted by BrowseName.
    fn placeholder_children(&self, node: &NodeId, type_id: NsNodeId) -> Result<Vec<(String, NodeId)>, BindError> {
        let ty = type_id.resolve(self.tree.namespaces()).ok_or(BindError::UnknownNamespace(type_id.namespace_uri.to_owned()))?;
        let has_type_definition: NodeId = ReferenceTypeId::HasTypeDefinition.into();
        let mut found = Vec::new();
        for child in self.children(node) {
            let definition = self
                .space
                .find_references(&child, None::<(NodeId, bool)>, self.tree, BrowseDirection::Forward)
                .find(|r| *r.reference_type == has_type_definition)
                .map(|r| r.target_node.clone());
            if definition.is_some_and(|d| d == ty || self.tree.is_subtype_of(&d, &ty)) {
                let name = self.space.find(&child).map(|n| n.as_node().browse_name().name.as_ref().to_owned());
                found.push((name.unwrap_or_default(), child));
            }
        }
        // BrowseNames are unique among siblings; should a server break that, the first one stored wins.
        found.sort_by(|a, b| a.0.cmp(&b.0));
        found.dedup_by(|later, first| later.0 == first.0);
        Ok(found)
    }

    /// Records that `node` is not of class `expected`, if it is not (and no problem was met before).
    fn check_class(&self, node: &NodeId, expected: NodeClass) {
        if !self.failed() {
            if let Err(e) = self.expect_class(node, expected) {
                self.fail(e);
            }
        }
    }

    /// Records why `node` cannot be a variable of a Rust type of ValueRank `rust_value_rank`, if it cannot.
    fn check_variable(&self, node: &NodeId, rust_value_rank: i32) {
        if self.failed() {
            return;
        }
        match self.variable_rank(node) {
            Ok(value_rank) if !rank_fits(rust_value_rank, value_rank) => {
                self.fail(BindError::ValueRank { node: node.clone(), value_rank, rust_value_rank })
            }
            Ok(_) => {}
            Err(e) => self.fail(e),
        }
    }

    /// The ValueRank of a variable, for checks.
    fn variable_rank(&self, node: &NodeId) -> Result<i32, BindError> {
        match self.space.find(node) {
            Some(NodeType::Variable(v)) => Ok(v.value_rank()),
            Some(other) => Err(BindError::WrongClass {
                node: node.clone(),
                expected: NodeClass::Variable,
                found: other.node_class(),
            }),
            None => Err(BindError::UnknownNode(node.clone())),
        }
    }
}

/// An object of an instance, untyped: its NodeId and the manager.
#[derive(Clone)]
pub struct ObjectNode {
    id: NodeId,
    manager: ModelManager,
}

impl ObjectNode {
    /// The object's NodeId.
    pub fn id(&self) -> &NodeId {
        &self.id
    }

    /// The manager of the server that holds the object.
    pub fn manager(&self) -> &ModelManager {
        &self.manager
    }

    /// A child bound as any handle, by BrowseName (namespace URI and name).
    pub fn child<H: Handle>(&self, uri: &str, name: &str) -> Result<H, BindError> {
        let id = self.id.clone();
        let (uri, name) = (uri.to_owned(), name.to_owned());
        self.manager.bind_with(move |b| b.child(&id, &uri, &name))
    }
}

impl fmt::Debug for ObjectNode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "ObjectNode({})", self.id)
    }
}

impl Handle for ObjectNode {
    fn build(binder: &Binder<'_>, node: &NodeId) -> Self {
        binder.check_class(node, NodeClass::Object);
        ObjectNode { id: node.clone(), manager: binder.manager.clone() }
    }
}

/// A variable whose values are `T`: typed get and set (a set is reported to subscriptions), status and
/// timestamps, and typed client writes.
pub struct Variable<T> {
    id: NodeId,
    manager: ModelManager,
    _value: PhantomData<fn() -> T>,
}

impl<T> Clone for Variable<T> {
    fn clone(&self) -> Self {
        Variable { id: self.id.clone(), manager: self.manager.clone(), _value: PhantomData }
    }
}

impl<T> fmt::Debug for Variable<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Variable<{}>({})", std::any::type_name::<T>(), self.id)
    }
}

impl<T: UaValue> Variable<T> {
    /// The variable's NodeId.
    pub fn id(&self) -> &NodeId {
        &self.id
    }

    /// The current value; `None` while it has none (an empty Variant) or holds another type.
    pub fn get(&self) -> Option<T> {
        T::from_variant(&self.manager.value(&self.id)?.value?)
    }

    /// The whole DataValue (value, status, timestamps).
    pub fn data_value(&self) -> Option<DataValue> {
        self.manager.value(&self.id)
    }

    /// Sets the value, timestamped now with status Good, and reports it to subscriptions.
    pub fn set(&self, value: T) -> Result<(), StatusCode> {
        self.manager.set_value(&self.id, value.to_variant())
    }

    /// Sets the value with a status and a source timestamp, and reports it to subscriptions.
    pub fn set_with(&self, value: T, status: StatusCode, source_timestamp: DateTime) -> Result<(), StatusCode> {
        let now = DateTime::now();
        let value = DataValue {
            value: Some(value.to_variant()),
            status: Some(status),
            source_timestamp: Some(source_timestamp),
            server_timestamp: Some(now),
            ..Default::default()
        };
        self.manager.set_data_value(&self.id, value)
    }

    /// Sets only the status (keeping the value), e.g. `BadSensorFailure` or `UncertainLastUsableValue`.
    pub fn set_status(&self, status: StatusCode) -> Result<(), StatusCode> {
        let mut value = self.manager.value(&self.id).ok_or(StatusCode::BadNodeIdUnknown)?;
        value.status = Some(status);
        value.source_timestamp = Some(DateTime::now());
        value.server_timestamp = value.source_timestamp;
        self.manager.set_data_value(&self.id, value)
    }

    /// Receives client writes as `T`: `Err(status)` rejects a write, `Ok(())` stores it. Writes only reach
    /// the handler if the variable is writable (its AccessLevel has CurrentWrite) and the value fits the
    /// DataType and ValueRank.
    pub fn on_write(&self, handler: impl Fn(T) -> Result<(), StatusCode> + Send + Sync + 'static) {
        self.manager.on_write(&self.id, move |v: &Variant| {
            let value = T::from_variant(v).ok_or(StatusCode::BadTypeMismatch)?;
            handler(value).map(|()| None)
        });
    }
}

/// A handle behind a `Box`: generated handles hold the handles of members typed by other ObjectTypes boxed,
/// because such a member may be of its owner's own type (PROFINET's `EthernetPortType` has an
/// `<EthernetPort>` of type `EthernetPortType`), or of a subtype of a type that contains it, which by value
/// would be a struct of infinite size. Field access and method calls reach through the `Box` as before.
impl<H: Handle> Handle for Box<H> {
    fn build(binder: &Binder<'_>, node: &NodeId) -> Self {
        Box::new(H::build(binder, node))
    }
}

impl<T: UaValue> Handle for Variable<T> {
    fn build(binder: &Binder<'_>, node: &NodeId) -> Self {
        binder.check_variable(node, T::VALUE_RANK);
        Variable { id: node.clone(), manager: binder.manager.clone(), _value: PhantomData }
    }
}

/// The arguments of a method as a Rust tuple: `()`, `(A,)`, `(A, B)`, ... up to twelve, each a [`UaValue`].
pub trait Arguments: Sized + Send + 'static {
    /// The number of arguments.
    const COUNT: usize;
    /// The arguments of a call; one status per argument on failure.
    fn from_variants(values: &[Variant]) -> Result<Self, Vec<StatusCode>>;
    /// The arguments as Variants.
    fn into_variants(self) -> Vec<Variant>;
}

macro_rules! arguments {
    ($n:expr; $($t:ident $i:tt),*) => {
        impl<$($t: UaValue),*> Arguments for ($($t,)*) {
            const COUNT: usize = $n;
            #[allow(unused_variables)]
            fn from_variants(values: &[Variant]) -> Result<Self, Vec<StatusCode>> {
                if values.len() != $n {
                    return Err(vec![StatusCode::BadInvalidArgument; values.len()]);
                }
                let parsed = ($($t::from_variant(&values[$i]),)*);
                if let ($(Some($t),)*) = parsed {
                    return Ok(($($t,)*));
                }
                let ok = [$(parsed.$i.is_some()),*];
                Err(ok.iter().map(|&ok| if ok { StatusCode::Good } else { StatusCode::BadTypeMismatch }).collect())
            }
            #[allow(non_snake_case)]
            fn into_variants(self) -> Vec<Variant> {
                let ($($t,)*) = self;
                vec![$($t.to_variant()),*]
            }
        }
    };
}

impl Arguments for () {
    const COUNT: usize = 0;
    fn from_variants(values: &[Variant]) -> Result<Self, Vec<StatusCode>> {
        if values.is_empty() {
            Ok(())
        } else {
            Err(vec![StatusCode::BadInvalidArgument; values.len()])
        }
    }
    fn into_variants(self) -> Vec<Variant> {
        Vec::new()
    }
}

/// More arguments than a tuple takes: the Variants as the call gave them.
impl Arguments for Vec<Variant> {
    const COUNT: usize = usize::MAX;
    fn from_variants(values: &[Variant]) -> Result<Self, Vec<StatusCode>> {
        Ok(values.to_vec())
    }
    fn into_variants(self) -> Vec<Variant> {
        self
    }
}

#[allow(non_snake_case)]
mod tuples {
    use super::*;
    arguments!(1; A 0);
    arguments!(2; A 0, B 1);
    arguments!(3; A 0, B 1, C 2);
    arguments!(4; A 0, B 1, C 2, D 3);
    arguments!(5; A 0, B 1, C 2, D 3, E 4);
    arguments!(6; A 0, B 1, C 2, D 3, E 4, F 5);
    arguments!(7; A 0, B 1, C 2, D 3, E 4, F 5, G 6);
    arguments!(8; A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7);
    arguments!(9; A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8);
    arguments!(10; A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9);
    arguments!(11; A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9, K 10);
    arguments!(12; A 0, B 1, C 2, D 3, E 4, F 5, G 6, H 7, I 8, J 9, K 10, L 11);
}

/// What a typed method gets besides its arguments.
#[derive(Clone)]
pub struct CallContext {
    /// The object the method was called on.
    pub object_id: NodeId,
    /// The method node.
    pub method_id: NodeId,
    /// The manager, to read and set values.
    pub manager: ModelManager,
    /// The calling session's user name (or the name of its user certificate); `None` if anonymous.
    pub user: Option<String>,
    /// The calling client's ApplicationUri (empty if it gave none).
    pub client: String,
}

/// A method whose input arguments are `I` and output arguments `O` (tuples of [`UaValue`]s, as its
/// InputArguments and OutputArguments declare them).
pub struct Method<I, O> {
    id: NodeId,
    manager: ModelManager,
    _signature: PhantomData<fn(I) -> O>,
}

impl<I, O> Clone for Method<I, O> {
    fn clone(&self) -> Self {
        Method { id: self.id.clone(), manager: self.manager.clone(), _signature: PhantomData }
    }
}

impl<I, O> fmt::Debug for Method<I, O> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Method({})", self.id)
    }
}

impl<I: Arguments, O: Arguments> Method<I, O> {
    /// The method's NodeId.
    pub fn id(&self) -> &NodeId {
        &self.id
    }

    /// Implements the method with an async function of its typed arguments.
    ///
    /// The server has already checked the call against the InputArguments (count: `BadArgumentsMissing`,
    /// `BadTooManyArguments`; types: `BadInvalidArgument` with `BadTypeMismatch` per wrong argument) and the
    /// Executable attribute before `f` runs. `f` returns the outputs, or a [`MethodError`] (a status such as
    /// `BadInvalidState`).
    pub fn implement<F, Fut>(&self, f: F)
    where
        F: Fn(CallContext, I) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = Result<O, MethodError>> + Send + 'static,
    {
        let f = Arc::new(f);
        self.manager.on_call(&self.id, move |invocation: MethodInvocation| {
            let f = f.clone();
            async move {
                let input = I::from_variants(&invocation.arguments).map_err(MethodError::Arguments)?;
                let context = CallContext {
                    object_id: invocation.object_id,
                    method_id: invocation.method_id,
                    manager: invocation.manager,
                    user: invocation.user,
                    client: invocation.client,
                };
                f(context, input).await.map(O::into_variants)
            }
        });
    }
}

impl<I: Arguments, O: Arguments> Handle for Method<I, O> {
    fn build(binder: &Binder<'_>, node: &NodeId) -> Self {
        binder.check_class(node, NodeClass::Method);
        Method { id: node.clone(), manager: binder.manager.clone(), _signature: PhantomData }
    }
}

/// The instances of a placeholder (`<AxisIdentifier>`), by BrowseName, in BrowseName order.
///
/// A sorted list rather than a `BTreeMap`: every handle type of a placeholder instantiates this type, and a
/// map's code is several times larger for the few instances a placeholder has.
#[derive(Clone, Debug)]
pub struct Placeholders<H>(Vec<(String, H)>);

impl<H> Placeholders<H> {
    /// The instance with this BrowseName.
    pub fn get(&self, name: &str) -> Option<&H> {
        self.0.binary_search_by(|(n, _)| n.as_str().cmp(name)).ok().map(|i| &self.0[i].1)
    }

    /// Whether there is an instance with this BrowseName.
    pub fn contains_key(&self, name: &str) -> bool {
        self.get(name).is_some()
    }

    /// (BrowseName, instance) pairs in BrowseName order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (&str, &H)> {
        self.0.iter().map(|(n, h)| (n.as_str(), h))
    }

    /// The BrowseNames, in order.
    pub fn keys(&self) -> impl ExactSizeIterator<Item = &str> {
        self.0.iter().map(|(n, _)| n.as_str())
    }

    /// The instances, in BrowseName order.
    pub fn values(&self) -> impl ExactSizeIterator<Item = &H> {
        self.0.iter().map(|(_, h)| h)
    }

    /// How many instances there are.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<H> Default for Placeholders<H> {
    fn default() -> Self {
        Placeholders(Vec::new())
    }
}
