//! Instantiation of ObjectTypes and VariableTypes: the nodes an instance needs, created as its type
//! prescribes.
//!
//! The type's members are read from the server's address spaces (ns0's and the generated tables'), so any
//! type works, generated or not: the members of the type and its supertypes (a subtype's declaration
//! overrides its supertype's of the same BrowseName), and for each member, recursively, the members of its
//! own TypeDefinition overridden by the children the declaration adds. Mandatory members are always
//! created, Optional ones on request, placeholders (`<AxisIdentifier>`) once per name the caller gives.
//! Every new node gets the declaration's attributes (DisplayName, Description, DataType, ValueRank,
//! ArrayDimensions, AccessLevel, initial value, Executable), a HasTypeDefinition reference to its type and
//! the declaration's reference from its parent; instances carry no ModellingRule. Methods are copied per
//! instance with their argument properties, so each instance can have its own implementation.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt;

use opcua::nodes::{Base, DefaultTypeTree, Method as MethodNode, NodeType, Object, TypeTree, Variable as VariableNode};
use opcua::server::address_space::AddressSpace;
use opcua::types::{
    BrowseDirection, DataEncoding, DataValue, DateTime, LocalizedText, NodeClass, NodeId, NumericRange, ObjectId,
    ObjectTypeId, QualifiedName, ReferenceTypeId, TimestampsToReturn,
};

use super::handle::BindError;
use crate::server::ModelManager;

/// How deep instance declarations may nest (a guard against types that contain themselves).
pub(crate) const MAX_DEPTH: usize = 32;

/// What to create besides the mandatory members, and where.
///
/// Paths name members below the new instance by BrowseName, `/`-separated: `ParameterSet/ActualSpeed`;
/// a placeholder is named by its declaration (`Axes/<AxisIdentifier>`), and members below a placeholder
/// instance by the name given to it (`MotionDevices/Arm/Axes/<AxisIdentifier>`).
#[derive(Clone, Debug, Default)]
pub struct Instantiate {
    optional: BTreeSet<String>,
    ensure: BTreeSet<String>,
    all_optional: bool,
    placeholders: BTreeMap<String, Vec<(String, Option<NodeId>)>>,
    reference_type: Option<NodeId>,
    node_id: Option<NodeId>,
    data_type_defaults: bool,
}

impl Instantiate {
    /// Mandatory members only.
    pub fn new() -> Instantiate {
        Instantiate::default()
    }

    /// Also create the Optional member at `path`.
    pub fn optional(mut self, path: impl Into<String>) -> Instantiate {
        self.optional.insert(path.into());
        self
    }

    /// Create the member at `path` if it is Optional; unlike [`Instantiate::optional`], a path that is
    /// Mandatory or not a member is no error (the derive asks for every prefix of the paths it binds), nor is
    /// an Optional member beside a Mandatory one of the same name in another namespace (which the path
    /// names already).
    pub fn ensure(mut self, path: impl Into<String>) -> Instantiate {
        self.ensure.insert(path.into());
        self
    }

    /// Create every Optional member (at every depth).
    pub fn all_optional(mut self) -> Instantiate {
        self.all_optional = true;
        self
    }

    /// Create one instance of the placeholder at `path` per name, of the placeholder's TypeDefinition.
    pub fn placeholder<S: Into<String>>(mut self, path: impl Into<String>, names: impl IntoIterator<Item = S>) -> Instantiate {
        let entry = self.placeholders.entry(path.into()).or_default();
        entry.extend(names.into_iter().map(|n| (n.into(), None)));
        self
    }

    /// Create one instance of the placeholder at `path`, of `type_id` (a subtype of the placeholder's
    /// TypeDefinition).
    pub fn placeholder_of_type(mut self, path: impl Into<String>, name: impl Into<String>, type_id: NodeId) -> Instantiate {
        self.placeholders.entry(path.into()).or_default().push((name.into(), Some(type_id)));
        self
    }

    /// Give every new variable whose declaration has no value the default of its DataType (zero, the empty
    /// string, an enumeration's first value, an empty array; structures get none), so that clients read a
    /// value of the declared type rather than an empty one. Off by default: the typed API binds such
    /// variables to fields.
    pub fn data_type_defaults(mut self) -> Instantiate {
        self.data_type_defaults = true;
        self
    }

    /// The reference from the parent to the new instance (default: Organizes under a folder, HasComponent
    /// otherwise).
    pub fn reference_type(mut self, reference_type: impl Into<NodeId>) -> Instantiate {
        self.reference_type = Some(reference_type.into());
        self
    }

    pub(crate) fn node_id_or(&self, namespace: u16, name: &str) -> NodeId {
        self.node_id.clone().unwrap_or_else(|| NodeId::new(namespace, name))
    }

    /// The NodeId of the new instance (default: a string NodeId in the server's instance namespace, the
    /// BrowseName; its members get `<parent id>/<BrowseName>`, or `<parent id>/<namespace index>:<BrowseName>`
    /// where members of two namespaces share the name).
    pub fn node_id(mut self, node_id: NodeId) -> Instantiate {
        self.node_id = Some(node_id);
        self
    }
}

/// Why an instance could not be created.
#[derive(Clone, Debug, PartialEq)]
pub enum InstantiateError {
    /// The type is not an ObjectType or VariableType the server knows.
    UnknownType(NodeId),
    /// The parent node does not exist.
    UnknownParent(NodeId),
    /// A node the instance needs already exists.
    NodeExists(NodeId),
    /// A MandatoryPlaceholder got no names (`Instantiate::placeholder`).
    MissingPlaceholder(String),
    /// An option names a path the type does not have (or that is not Optional, or not a placeholder).
    UnknownPath(String),
    /// A type's members nest deeper than the instantiation allows (a type that contains itself).
    TooDeep(String),
    /// Two members of one node would have the same BrowseName (two placeholder elements given one name, or
    /// an element named like a member): the path of the second, with its namespace index.
    DuplicateName(String),
    /// The instance was created but a typed handle could not be bound to it.
    Bind(BindError),
}

impl fmt::Display for InstantiateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InstantiateError::UnknownType(id) => write!(f, "{id} is not an ObjectType or VariableType of this server"),
            InstantiateError::UnknownParent(id) => write!(f, "the parent {id} does not exist"),
            InstantiateError::NodeExists(id) => write!(f, "node {id} already exists"),
            InstantiateError::MissingPlaceholder(p) => {
                write!(f, "`{p}` is a MandatoryPlaceholder: give at least one name with Instantiate::placeholder")
            }
            InstantiateError::UnknownPath(p) => {
                write!(f, "`{p}` is not an Optional member or a placeholder of the type (paths are BrowseNames joined by `/`)")
            }
            InstantiateError::TooDeep(p) => write!(f, "instance declarations nest too deep at `{p}`"),
            InstantiateError::DuplicateName(p) => write!(f, "two members would be named `{p}`: give the placeholder elements names no other member has"),
            InstantiateError::Bind(e) => write!(f, "the instance was created, but: {e}"),
        }
    }
}

impl std::error::Error for InstantiateError {}

impl From<BindError> for InstantiateError {
    fn from(e: BindError) -> Self {
        InstantiateError::Bind(e)
    }
}

/// The typed layer's side of the server's [`ModelManager`]: instances created as their type prescribes. It is
/// defined here, above the server, so that `server` never names the typed layer.
impl ModelManager {
    /// Creates an instance of an ObjectType or VariableType under `parent` as the type prescribes (see
    /// [`crate::typed::instance`]) and returns its NodeId. Nothing is created if anything fails.
    pub fn instantiate(
        &self,
        type_id: &NodeId,
        parent: &NodeId,
        browse_name: QualifiedName,
        options: &Instantiate,
    ) -> Result<NodeId, InstantiateError> {
        let core = self.core_node_manager();
        let planned = {
            // The type tree first (see `ModelManager::bind_with`).
            let tree = self.type_tree().read();
            let core_space = core.as_ref().map(|c| c.address_space().read());
            let space = self.node_manager().address_space().read();
            let overrides = self.overrides();
            let spaces = Spaces { core: core_space.as_deref(), model: &space, tree: &tree, overrides: &overrides };
            let id = options.node_id_or(self.instance_namespace(), browse_name.name.as_ref());
            let mut planner = Planner { spaces, options, used: Default::default(), out: Vec::new() };
            planner.root(type_id, parent, browse_name, id)?;
            if let Some(path) = planner.unused() {
                return Err(InstantiateError::UnknownPath(path));
            }
            planner.out
        };
        let mut space = self.node_manager().address_space().write();
        if let Some(p) = planned.iter().find(|p| space.node_exists(p.node.as_node().node_id())) {
            return Err(InstantiateError::NodeExists(p.node.as_node().node_id().clone()));
        }
        let root = planned.first().map(|p| p.node.as_node().node_id().clone()).unwrap_or_else(NodeId::null);
        for p in planned {
            space.insert::<NodeType, NodeId>(p.node, None);
            for (source, target, rt) in p.references {
                space.insert_reference(&source, &target, rt);
            }
        }
        Ok(root)
    }

}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Rule {
    Mandatory,
    Optional,
    MandatoryPlaceholder,
    OptionalPlaceholder,
    /// ExposesItsArray, or a rule this runtime does not know: not instantiated.
    Other,
}

/// An instance declaration, as a member of a type or of another declaration.
#[derive(Clone, Debug)]
struct Decl {
    id: NodeId,
    browse_name: QualifiedName,
    reference_type: NodeId,
    rule: Rule,
}

/// The address spaces the type information is read from.
pub(crate) struct Spaces<'a> {
    /// ns0 (async-opcua's core node manager), if the server has it.
    pub core: Option<&'a AddressSpace>,
    /// The generated tables and the instances.
    pub model: &'a AddressSpace,
    pub tree: &'a DefaultTypeTree,
    /// The declaration each InstanceDeclaration overrides at its browse path, as the compiler's resolved
    /// model computed it (the tables' `Overrides` rows).
    pub overrides: &'a HashMap<NodeId, NodeId>,
}

/// A node to insert, with its references (source, target, type).
pub(crate) struct Planned {
    pub node: NodeType,
    pub references: Vec<(NodeId, NodeId, NodeId)>,
}

impl<'a> Spaces<'a> {
    fn space_of(&self, id: &NodeId) -> Option<&'a AddressSpace> {
        if id.namespace == 0 {
            if let Some(core) = self.core {
                if core.node_exists(id) {
                    return Some(core);
                }
            }
        }
        Some(self.model).filter(|m| m.node_exists(id)).or(self.core.filter(|c| c.node_exists(id)))
    }

    pub(super) fn find(&self, id: &NodeId) -> Option<&'a NodeType> {
        self.space_of(id)?.find(id)
    }

    /// Forward references of `node` of type `rt` (or, for HierarchicalReferences, any hierarchical type),
    /// as (reference type, target).
    pub(super) fn refs(&self, node: &NodeId, rt: ReferenceTypeId) -> Vec<(NodeId, NodeId)> {
        let wanted = NodeId::from(rt);
        let hierarchical = rt == ReferenceTypeId::HierarchicalReferences;
        let mut out: Vec<(NodeId, NodeId)> = Vec::new();
        // A reference may be stored in either space (ns0 nodes refer to generated ones and back).
        for space in [Some(self.model), self.core].into_iter().flatten() {
            for r in space.find_references(node, None::<(NodeId, bool)>, self.tree, BrowseDirection::Forward) {
                let fits = if hierarchical { is_hierarchical(self.tree, r.reference_type) } else { *r.reference_type == wanted };
                let item = (r.reference_type.clone(), r.target_node.clone());
                if fits && !out.contains(&item) {
                    out.push(item);
                }
            }
        }
        out
    }

    fn type_definition(&self, node: &NodeId) -> Option<NodeId> {
        self.refs(node, ReferenceTypeId::HasTypeDefinition).into_iter().map(|(_, t)| t).next()
    }

    fn rule(&self, node: &NodeId) -> Option<Rule> {
        let (_, rule) = self.refs(node, ReferenceTypeId::HasModellingRule).into_iter().next()?;
        Some(match rule {
            r if r == NodeId::from(ObjectId::ModellingRule_Mandatory) => Rule::Mandatory,
            r if r == NodeId::from(ObjectId::ModellingRule_Optional) => Rule::Optional,
            r if r == NodeId::from(ObjectId::ModellingRule_MandatoryPlaceholder) => Rule::MandatoryPlaceholder,
            r if r == NodeId::from(ObjectId::ModellingRule_OptionalPlaceholder) => Rule::OptionalPlaceholder,
            _ => Rule::Other,
        })
    }

    /// The children of `node` that have a ModellingRule (a method's argument properties count even without).
    fn declared_children(&self, node: &NodeId) -> Vec<Decl> {
        let is_method = matches!(self.find(node), Some(NodeType::Method(_)));
        let has_subtype: NodeId = ReferenceTypeId::HasSubtype.into();
        let mut out = Vec::new();
        for (rt, target) in self.refs(node, ReferenceTypeId::HierarchicalReferences) {
            if rt == has_subtype {
                continue;
            }
            let Some(child) = self.find(&target) else { continue };
            let rule = match self.rule(&target) {
                Some(rule) => rule,
                None if is_method && rt == NodeId::from(ReferenceTypeId::HasProperty) => Rule::Mandatory,
                None => continue,
            };
            out.push(Decl { id: target.clone(), browse_name: child.as_node().browse_name().clone(), reference_type: rt, rule });
        }
        out
    }

    /// The members of a type: its own declarations and its supertypes', the most derived first.
    fn type_members(&self, type_id: &NodeId) -> Vec<Decl> {
        let mut out: Vec<Decl> = Vec::new();
        let mut current = Some(type_id.clone());
        let mut depth = 0;
        while let Some(t) = current {
            for d in self.declared_children(&t) {
                if !out.iter().any(|m| m.browse_name == d.browse_name) {
                    out.push(d);
                }
            }
            depth += 1;
            // By the address spaces' HasSubtype references, not the type tree: the tree holds ns0's types only
            // once the server runs, and a type's ns0 supertypes (BaseEventType's EventId, ...) count before.
            current = if depth < MAX_DEPTH { self.supertype(&t) } else { None };
        }
        out
    }

    /// The members of an instance of declaration `decl` whose TypeDefinition is `type_id`: the fully-inherited
    /// hierarchy at the declaration's browse path. Its own children win, then those of the declarations it
    /// overrides (nearest first, following the compiler's links), then the members of the TypeDefinitions,
    /// `type_id` first; the same merge as the compiler's `Model::instance_members`, on the same links.
    fn decl_members(&self, decl: Option<&NodeId>, type_id: Option<&NodeId>) -> Vec<Decl> {
        let mut chain: Vec<NodeId> = decl.into_iter().cloned().collect();
        while let Some(next) = chain.last().and_then(|d| self.overrides.get(d)) {
            if chain.contains(next) || chain.len() > MAX_DEPTH {
                break;
            }
            chain.push(next.clone());
        }
        let mut out = type_id.map(|t| self.type_members(t)).unwrap_or_default();
        for over in chain.iter().skip(1) {
            let Some(t) = self.type_definition(over) else { continue };
            for d in self.type_members(&t) {
                if !out.iter().any(|m| m.browse_name == d.browse_name) {
                    out.push(d);
                }
            }
        }
        for c in chain.iter().rev() {
            for d in self.declared_children(c) {
                match out.iter_mut().find(|m| m.browse_name == d.browse_name) {
                    Some(m) => *m = d,
                    None => out.push(d),
                }
            }
        }
        out
    }

    /// Whether an instance of declaration `member` stands in the place of `placeholder`: the same NodeClass
    /// and a TypeDefinition that is the placeholder's or a subtype of it.
    fn fills(&self, member: &Decl, placeholder: &Decl) -> bool {
        let class = |d: &Decl| self.find(&d.id).map(|n| n.node_class());
        if class(member).is_none() || class(member) != class(placeholder) {
            return false;
        }
        match (self.type_definition(&member.id), self.type_definition(&placeholder.id)) {
            (Some(have), Some(want)) => self.is_subtype(&have, &want),
            _ => true,
        }
    }

    /// Whether type `t` is `of` or a subtype of it, by the HasSubtype references of the address spaces (the
    /// type tree holds ns0's types only once the server runs, and instances are often created before).
    fn is_subtype(&self, t: &NodeId, of: &NodeId) -> bool {
        let mut cur = Some(t.clone());
        for _ in 0..MAX_DEPTH {
            let Some(c) = cur else { return false };
            if c == *of {
                return true;
            }
            cur = self.supertype(&c);
        }
        false
    }

    /// The supertype of a type, by the inverse HasSubtype reference in either address space.
    pub(super) fn supertype(&self, t: &NodeId) -> Option<NodeId> {
        [Some(self.model), self.core].into_iter().flatten().find_map(|space| {
            space
                .find_references(t, Some((ReferenceTypeId::HasSubtype, false)), self.tree, BrowseDirection::Inverse)
                .next()
                .map(|r| r.target_node.clone())
        })
    }
}

/// Plans the nodes of a new instance.
pub(crate) struct Planner<'a> {
    pub spaces: Spaces<'a>,
    pub options: &'a Instantiate,
    pub used: BTreeSet<String>,
    pub out: Vec<Planned>,
}

/// What a new node copies its attributes from.
struct Source<'a> {
    /// The instance declaration, or the type itself for the root.
    template: Option<&'a NodeType>,
    type_id: Option<NodeId>,
}

impl<'a> Planner<'a> {
    /// Plans an instance of `type_id` named `browse_name`, under `parent`.
    pub fn root(&mut self, type_id: &NodeId, parent: &NodeId, browse_name: QualifiedName, id: NodeId) -> Result<NodeClass, InstantiateError> {
        let class = match self.spaces.find(type_id) {
            Some(NodeType::ObjectType(_)) => NodeClass::Object,
            Some(NodeType::VariableType(_)) => NodeClass::Variable,
            _ => return Err(InstantiateError::UnknownType(type_id.clone())),
        };
        if self.spaces.find(parent).is_none() {
            return Err(InstantiateError::UnknownParent(parent.clone()));
        }
        let folder: NodeId = ObjectId::ObjectsFolder.into();
        let is_folder = self.spaces.type_definition(parent).is_some_and(|t| {
            let folder_type = NodeId::from(ObjectTypeId::FolderType);
            t == folder_type || self.spaces.tree.is_subtype_of(&t, &folder_type)
        }) || *parent == folder;
        let rt = self.options.reference_type.clone().unwrap_or_else(|| {
            if is_folder { ReferenceTypeId::Organizes.into() } else { ReferenceTypeId::HasComponent.into() }
        });
        let members = self.spaces.decl_members(None, Some(type_id));
        let template = self.spaces.find(type_id);
        self.node(Source { template, type_id: Some(type_id.clone()) }, class, &id, browse_name, parent, rt)?;
        self.members(&id, members, "", 0)?;
        Ok(class)
    }

    fn node(
        &mut self,
        source: Source<'_>,
        class: NodeClass,
        id: &NodeId,
        browse_name: QualifiedName,
        parent: &NodeId,
        reference_type: NodeId,
    ) -> Result<(), InstantiateError> {
        if self.spaces.model.node_exists(id) || self.out.iter().any(|p| p.node.as_node().node_id() == id) {
            return Err(InstantiateError::NodeExists(id.clone()));
        }
        let is_declaration = matches!(source.template, Some(NodeType::Object(_) | NodeType::Variable(_) | NodeType::Method(_)));
        let display_name = match source.template {
            Some(t) if is_declaration && !browse_name.name.as_ref().is_empty() && *t.as_node().browse_name() == browse_name => {
                t.as_node().display_name().clone()
            }
            _ => LocalizedText::new("", browse_name.name.as_ref()),
        };
        let description = source.template.filter(|_| is_declaration).and_then(|t| t.as_node().description().cloned());
        let base = Base::new_full(id.clone(), class, browse_name, display_name, description, None, None);
        let node: NodeType = match (class, source.template) {
            (NodeClass::Variable, Some(NodeType::Variable(v))) => {
                let mut value = v.value(TimestampsToReturn::Neither, &NumericRange::None, &DataEncoding::Binary, 0.0);
                if value.value.is_none() && self.options.data_type_defaults {
                    value.value = self.spaces.default_value(&v.data_type(), v.value_rank());
                }
                let now = DateTime::now();
                let value = DataValue { source_timestamp: Some(now), server_timestamp: Some(now), ..value };
                VariableNode::new_full(
                    base,
                    v.data_type(),
                    v.historizing(),
                    v.value_rank(),
                    value,
                    v.access_level().bits(),
                    v.user_access_level().bits(),
                    v.array_dimensions(),
                    v.minimum_sampling_interval(),
                )
                .into()
            }
            (NodeClass::Variable, Some(NodeType::VariableType(vt))) => {
                let mut value = vt.value().cloned().unwrap_or_default();
                if value.value.is_none() && self.options.data_type_defaults {
                    value.value = self.spaces.default_value(vt.data_type(), vt.value_rank());
                }
                VariableNode::new_full(base, vt.data_type().clone(), false, vt.value_rank(), value, 1, 1, vt.array_dimensions(), None)
                    .into()
            }
            (NodeClass::Object, Some(NodeType::Object(o))) => Object::new_full(base, o.event_notifier()).into(),
            (NodeClass::Object, _) => Object::new_full(base, Default::default()).into(),
            (NodeClass::Method, Some(NodeType::Method(m))) => MethodNode::new_full(base, m.executable(), m.user_executable()).into(),
            _ => return Err(InstantiateError::UnknownType(source.type_id.unwrap_or_else(NodeId::null))),
        };
        let mut references = vec![(parent.clone(), id.clone(), reference_type)];
        if let Some(t) = source.type_id {
            references.push((id.clone(), t, ReferenceTypeId::HasTypeDefinition.into()));
        }
        self.out.push(Planned { node, references });
        Ok(())
    }

    fn members(&mut self, parent: &NodeId, members: Vec<Decl>, path: &str, depth: usize) -> Result<(), InstantiateError> {
        if depth >= MAX_DEPTH {
            return Err(InstantiateError::TooDeep(path.to_owned()));
        }
        // First what to create below `parent`, then the NodeIds: they depend on the siblings.
        let mut planned: Vec<(Decl, &'a NodeType, Vec<(QualifiedName, Option<NodeId>, String)>)> = Vec::new();
        for decl in &members {
            let name = decl.browse_name.name.as_ref().to_owned();
            let member_path = format!("{path}{name}");
            let instances: Vec<(QualifiedName, Option<NodeId>, String)> = match decl.rule {
                Rule::Mandatory => vec![(decl.browse_name.clone(), None, member_path.clone())],
                Rule::Optional => {
                    let wanted = self.options.optional.contains(&member_path);
                    if wanted {
                        self.used.insert(format!("o:{member_path}"));
                    }
                    // A path names one member: ensuring it asks for nothing where a Mandatory sibling of
                    // the same name (in another namespace) is created anyway.
                    let ensured = self.options.ensure.contains(&member_path)
                        && !members.iter().any(|m| m.rule == Rule::Mandatory && m.browse_name.name == decl.browse_name.name);
                    if wanted || self.options.all_optional || ensured {
                        vec![(decl.browse_name.clone(), None, member_path.clone())]
                    } else {
                        continue;
                    }
                }
                Rule::MandatoryPlaceholder | Rule::OptionalPlaceholder => {
                    let names = self.options.placeholders.get(&member_path).cloned().unwrap_or_default();
                    // A Mandatory sibling that fits the placeholder fills it (DI's
                    // `ParameterSet/<ParameterIdentifier>` is filled by Robotics' `SpeedOverride`).
                    let filled = members.iter().any(|m| m.rule == Rule::Mandatory && self.spaces.fills(m, decl));
                    if names.is_empty() && decl.rule == Rule::MandatoryPlaceholder && !filled {
                        return Err(InstantiateError::MissingPlaceholder(member_path));
                    }
                    if !names.is_empty() {
                        self.used.insert(format!("p:{member_path}"));
                    }
                    names
                        .into_iter()
                        .map(|(n, t)| (QualifiedName::new(decl.browse_name.namespace_index, n.as_str()), t, format!("{path}{n}")))
                        .collect()
                }
                Rule::Other => continue,
            };
            let Some(template) = self.spaces.find(&decl.id) else { continue };
            planned.push((decl.clone(), template, instances));
        }
        let ids = member_ids(parent, path, planned.iter().flat_map(|(_, _, i)| i.iter().map(|(b, _, _)| b)))?;
        let mut ids = ids.into_iter();
        for (decl, template, instances) in planned {
            let class = template.node_class();
            for (browse_name, type_override, instance_path) in instances {
                let id = ids.next().expect("one NodeId per planned member");
                let type_id = type_override.clone().or_else(|| self.spaces.type_definition(&decl.id));
                let members = match class {
                    NodeClass::Method => self.spaces.declared_children(&decl.id),
                    _ => self.spaces.decl_members(Some(&decl.id), type_id.as_ref()),
                };
                let source = Source { template: Some(template), type_id: if class == NodeClass::Method { None } else { type_id } };
                self.node(source, class, &id, browse_name, parent, decl.reference_type.clone())?;
                self.members(&id, members, &format!("{instance_path}/"), depth + 1)?;
            }
        }
        Ok(())
    }

    /// Options that named nothing the type has.
    pub fn unused(&self) -> Option<String> {
        let optional = self.options.optional.iter().find(|p| !self.used.contains(&format!("o:{p}")));
        let placeholder = self.options.placeholders.keys().find(|p| !self.used.contains(&format!("p:{p}")));
        optional.or(placeholder).cloned()
    }
}

/// The NodeId of a member: `<parent id>/<name>` for string parents, otherwise `<parent id as text>/<name>`.
pub(crate) fn child_id(parent: &NodeId, name: &str) -> NodeId {
    let base = match &parent.identifier {
        opcua::types::Identifier::String(s) => s.as_ref().to_owned(),
        other => other.to_string(),
    };
    NodeId::new(parent.namespace, format!("{base}/{name}"))
}

/// The NodeIds of the members `names` of `parent` (at `path`), in their order: `<parent id>/<name>`
/// ([`child_id`]), and where members of two namespaces share a name (ShearerLoader's `RoofOffset` has ns0's
/// `EURange` and Mining's), `<parent id>/<namespace index>:<name>` for each of them, so that neither depends on
/// which comes first and a name no other member has keeps the plain form. Two members of one BrowseName are
/// refused: clients could not tell them apart by browse path either.
fn member_ids<'q>(parent: &NodeId, path: &str, names: impl Iterator<Item = &'q QualifiedName>) -> Result<Vec<NodeId>, InstantiateError> {
    let names: Vec<&QualifiedName> = names.collect();
    let mut namespaces: BTreeMap<&str, BTreeSet<u16>> = BTreeMap::new();
    for n in &names {
        if !namespaces.entry(n.name.as_ref()).or_default().insert(n.namespace_index) {
            return Err(InstantiateError::DuplicateName(format!("{path}{}:{}", n.namespace_index, n.name.as_ref())));
        }
    }
    Ok(names
        .iter()
        .map(|n| match namespaces[n.name.as_ref()].len() {
            1 => child_id(parent, n.name.as_ref()),
            _ => child_id(parent, &format!("{}:{}", n.namespace_index, n.name.as_ref())),
        })
        .collect())
}

/// Whether a reference type is hierarchical: one of ns0's (known without the type tree, which holds ns0's
/// reference types only once the server runs) or a subtype of HierarchicalReferences in the type tree.
pub(crate) fn is_hierarchical(tree: &DefaultTypeTree, rt: &NodeId) -> bool {
    const NS0: [u32; 11] = [33, 34, 35, 36, 44, 45, 46, 47, 48, 49, 17604];
    if let (0, opcua::types::Identifier::Numeric(n)) = (rt.namespace, &rt.identifier) {
        if NS0.contains(n) {
            return true;
        }
    }
    tree.is_subtype_of(rt, &ReferenceTypeId::HierarchicalReferences.into())
}
