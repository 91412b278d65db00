//! The resolved model: one arena of nodes for all files, with the derived tables both emitters need.
//!
//! Every node gets a [`NodeIx`] before anything links to anything, so forward references and cycles are
//! ordinary. Tables are keyed by `NodeIx` and iterated in node order (files in dependency order, nodes in
//! file order), which does not depend on the order the user named the files in.

use crate::fxhash::FxHashMap;
use crate::load::{ModelInfo, NS0_URI};
use crate::nodeid::{NodeId, QualifiedName};
use crate::raw::{LocalizedText, NodeClass, RawDefinition, RawRolePermission, ValueArena, ValueElement, ValueRef, XmlElement};
use crate::source::{FileId, SourceMap, Span, Spanned};
use crate::value::{BuiltinType, Content, Variant};
use std::collections::BTreeMap;

mod values;
pub(crate) use values::DataTypes;

/// "a" or "an" before a node class or type name, for messages.
pub fn article(word: &str) -> &'static str {
    if word.starts_with(['A', 'E', 'I', 'O', 'U', 'a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    }
}

/// Well-known NodeIds of namespace 0.
pub mod ids {
    /// ObjectsFolder: where a server's instances start.
    pub const OBJECTS_FOLDER: u32 = 85;
    /// The References ReferenceType, root of all ReferenceTypes.
    pub const REFERENCES: u32 = 31;
    /// The HierarchicalReferences ReferenceType.
    pub const HIERARCHICAL_REFERENCES: u32 = 33;
    /// The HasChild ReferenceType.
    pub const HAS_CHILD: u32 = 34;
    /// The Organizes ReferenceType.
    pub const ORGANIZES: u32 = 35;
    /// The HasModellingRule ReferenceType.
    pub const HAS_MODELLING_RULE: u32 = 37;
    /// The GeneratesEvent ReferenceType.
    pub const GENERATES_EVENT: u32 = 41;
    /// The HasEncoding ReferenceType.
    pub const HAS_ENCODING: u32 = 38;
    /// The HasTypeDefinition ReferenceType.
    pub const HAS_TYPE_DEFINITION: u32 = 40;
    /// The Aggregates ReferenceType.
    pub const AGGREGATES: u32 = 44;
    /// The HasSubtype ReferenceType.
    pub const HAS_SUBTYPE: u32 = 45;
    /// The HasProperty ReferenceType.
    pub const HAS_PROPERTY: u32 = 46;
    /// The HasComponent ReferenceType.
    pub const HAS_COMPONENT: u32 = 47;
    /// The FromState ReferenceType.
    pub const FROM_STATE: u32 = 51;
    /// The ToState ReferenceType.
    pub const TO_STATE: u32 = 52;
    /// The HasCause ReferenceType.
    pub const HAS_CAUSE: u32 = 53;
    /// The HasEffect ReferenceType.
    pub const HAS_EFFECT: u32 = 54;
    /// The HasInterface ReferenceType.
    pub const HAS_INTERFACE: u32 = 17603;
    /// The HasAddIn ReferenceType.
    pub const HAS_ADD_IN: u32 = 17604;

    /// The Structure DataType.
    pub const STRUCTURE: u32 = 22;
    /// The BaseDataType DataType, root of all DataTypes.
    pub const BASE_DATA_TYPE: u32 = 24;
    /// The abstract Number DataType.
    pub const NUMBER: u32 = 26;
    /// The abstract Integer DataType.
    pub const INTEGER: u32 = 27;
    /// The abstract UInteger DataType.
    pub const UINTEGER: u32 = 28;
    /// The Enumeration DataType.
    pub const ENUMERATION: u32 = 29;
    /// The Decimal DataType.
    pub const DECIMAL: u32 = 50;
    /// The OptionSet DataType.
    pub const OPTION_SET: u32 = 12755;
    /// The Union DataType.
    pub const UNION: u32 = 12756;
    /// The Argument DataType (method arguments).
    pub const ARGUMENT: u32 = 296;
    /// The EnumValueType DataType (entries of an EnumValues property).
    pub const ENUM_VALUE_TYPE: u32 = 7594;

    /// The BaseObjectType ObjectType.
    pub const BASE_OBJECT_TYPE: u32 = 58;
    /// The FolderType ObjectType.
    pub const FOLDER_TYPE: u32 = 61;
    /// The BaseVariableType VariableType.
    pub const BASE_VARIABLE_TYPE: u32 = 62;
    /// The BaseDataVariableType VariableType.
    pub const BASE_DATA_VARIABLE_TYPE: u32 = 63;
    /// The PropertyType VariableType.
    pub const PROPERTY_TYPE: u32 = 68;
    /// The ModellingRuleType ObjectType.
    pub const MODELLING_RULE_TYPE: u32 = 77;
    /// The BaseEventType ObjectType.
    pub const BASE_EVENT_TYPE: u32 = 2041;
    /// The BaseInterfaceType ObjectType.
    pub const BASE_INTERFACE_TYPE: u32 = 17602;
    /// The StateMachineType ObjectType.
    pub const STATE_MACHINE_TYPE: u32 = 2299;
    /// The FiniteStateMachineType ObjectType.
    pub const FINITE_STATE_MACHINE_TYPE: u32 = 2771;
    /// The StateType ObjectType.
    pub const STATE_TYPE: u32 = 2307;
    /// The InitialStateType ObjectType.
    pub const INITIAL_STATE_TYPE: u32 = 2309;
    /// The TransitionType ObjectType.
    pub const TRANSITION_TYPE: u32 = 2310;
    /// The ProgramStateMachineType ObjectType.
    pub const PROGRAM_STATE_MACHINE_TYPE: u32 = 2391;
    /// The TransitionEventType ObjectType.
    pub const TRANSITION_EVENT_TYPE: u32 = 2311;

    /// The Mandatory ModellingRule.
    pub const MANDATORY: u32 = 78;
    /// The Optional ModellingRule.
    pub const OPTIONAL: u32 = 80;
    /// The ExposesItsArray ModellingRule.
    pub const EXPOSES_ITS_ARRAY: u32 = 83;
    /// The OptionalPlaceholder ModellingRule.
    pub const OPTIONAL_PLACEHOLDER: u32 = 11508;
    /// The MandatoryPlaceholder ModellingRule.
    pub const MANDATORY_PLACEHOLDER: u32 = 11510;
}

/// Index of a node in [`Model::nodes`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NodeIx(pub u32);

impl NodeIx {
    /// The index as a `usize`, for indexing [`Model::nodes`].
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// The ModellingRule a node's HasModellingRule reference names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ModellingRule {
    /// Mandatory (i=78): every instance has the node.
    Mandatory,
    /// Optional (i=80): an instance may have the node.
    Optional,
    /// ExposesItsArray (i=83): the elements of the array value are exposed as nodes.
    ExposesItsArray,
    /// OptionalPlaceholder (i=11508): instances may have any number of such nodes, none included.
    OptionalPlaceholder,
    /// MandatoryPlaceholder (i=11510): instances have at least one such node.
    MandatoryPlaceholder,
    /// A rule node this compiler does not know.
    Other(NodeIx),
}

impl ModellingRule {
    /// The rule's BrowseName (`Other` for a rule this compiler does not know).
    pub fn name(self) -> &'static str {
        match self {
            ModellingRule::Mandatory => "Mandatory",
            ModellingRule::Optional => "Optional",
            ModellingRule::ExposesItsArray => "ExposesItsArray",
            ModellingRule::OptionalPlaceholder => "OptionalPlaceholder",
            ModellingRule::MandatoryPlaceholder => "MandatoryPlaceholder",
            ModellingRule::Other(_) => "Other",
        }
    }

    /// Whether the rule is OptionalPlaceholder or MandatoryPlaceholder.
    pub fn is_placeholder(self) -> bool {
        matches!(self, ModellingRule::OptionalPlaceholder | ModellingRule::MandatoryPlaceholder)
    }

    /// Whether the rule is Mandatory or MandatoryPlaceholder.
    pub fn is_mandatory(self) -> bool {
        matches!(self, ModellingRule::Mandatory | ModellingRule::MandatoryPlaceholder)
    }
}

/// A reference as stored on a node: outgoing when `forward`, incoming otherwise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Reference {
    /// The ReferenceType.
    pub reference_type: NodeIx,
    /// The node at the other end.
    pub target: NodeIx,
    /// Whether the reference points from this node to `target`.
    pub forward: bool,
    /// False for the inverse the resolver added on the other node.
    pub declared: bool,
    /// The `<Reference>` element that declared the reference (on either node).
    pub span: Span,
}

/// Attributes that only some node classes have; `None` where the file leaves the default.
#[derive(Clone, Debug, Default)]
pub struct Attributes {
    /// The WriteMask bits.
    pub write_mask: Option<u32>,
    /// The UserWriteMask bits.
    pub user_write_mask: Option<u32>,
    /// The AccessRestrictions bits; the model's DefaultAccessRestrictions where the node gives none.
    pub access_restrictions: Option<u16>,
    /// The ReleaseStatus, as written.
    pub release_status: Option<String>,
    /// The DataType of a Variable or VariableType, resolved; `None` if absent, unresolved or not a DataType.
    pub data_type: Option<NodeIx>,
    /// The ValueRank.
    pub value_rank: Option<i32>,
    /// The ArrayDimensions, one length per dimension (0 for an unknown length); empty if absent.
    pub array_dimensions: Vec<u32>,
    /// The AccessLevel bits (0x01 CurrentRead, 0x02 CurrentWrite, ...).
    pub access_level: Option<u8>,
    /// The UserAccessLevel bits.
    pub user_access_level: Option<u8>,
    /// The AccessLevelEx bits.
    pub access_level_ex: Option<u32>,
    /// The MinimumSamplingInterval, in milliseconds.
    pub minimum_sampling_interval: Option<f64>,
    /// Whether the server collects the Variable's history (Historizing).
    pub historizing: Option<bool>,
    /// Whether the Method can be called (Executable).
    pub executable: Option<bool>,
    /// Whether the Method can be called by the current user (UserExecutable).
    pub user_executable: Option<bool>,
    /// The EventNotifier bits of an Object or View.
    pub event_notifier: Option<u8>,
    /// Whether the View contains no loops (ContainsNoLoops).
    pub contains_no_loops: Option<bool>,
    /// Whether the type is abstract (IsAbstract).
    pub is_abstract: Option<bool>,
    /// Whether the ReferenceType is symmetric (Symmetric).
    pub symmetric: Option<bool>,
    /// The InverseNames of a ReferenceType, in the file's order.
    pub inverse_name: Vec<LocalizedText>,
    /// The `<RolePermissions>` as written, roles not resolved (see `roles`).
    pub role_permissions: Vec<RawRolePermission>,
    /// The RolePermissions resolved: the role object and its `PermissionType` bits, in the file's order.
    /// An entry whose role names no Object is left out (NS0220).
    pub roles: Vec<(NodeIx, u32)>,
    /// The texts of the `<Category>` elements, trimmed.
    pub category: Vec<String>,
    /// The text of the `<Documentation>` element.
    pub documentation: Option<String>,
    /// The node a Method's MethodDeclarationId names, resolved.
    pub method_declaration: Option<NodeIx>,
}

/// A node of the model, with its references and attributes resolved.
#[derive(Clone, Debug)]
pub struct Node {
    /// The node's NodeId, with its global namespace index.
    pub id: NodeId,
    /// The node's NodeClass.
    pub class: NodeClass,
    /// The node's BrowseName, with its global namespace index.
    pub browse_name: QualifiedName,
    /// The node's SymbolicName, if the file gives one.
    pub symbolic_name: Option<String>,
    /// The node's DisplayNames, in the file's order (the first in the default locale).
    pub display_name: Vec<LocalizedText>,
    /// The node's Descriptions, in the file's order (the first in the default locale).
    pub description: Vec<LocalizedText>,
    /// The attributes that only some node classes have.
    pub attrs: Attributes,
    /// The element inside the node's `<Value>`, if any: read it with [`Model::value_element`] or
    /// [`Model::value_xml`], decode it with [`Model::value`].
    pub value: Option<ValueRef>,
    /// Boxed, as in the raw node: only DataTypes have one.
    pub definition: Option<Box<RawDefinition>>,
    /// The children of the node's `<Extensions>` element.
    pub extensions: Vec<XmlElement>,
    /// The node's references in both directions: those its element declares, then the inverses of those
    /// other nodes declare (a reference declared twice is kept once).
    pub references: Vec<Reference>,
    /// The supertype, named by the node's first inverse HasSubtype reference; `None` for a root type, and
    /// where the supertype has another node class or closes a cycle.
    pub super_type: Option<NodeIx>,
    /// The type the node's HasTypeDefinition reference names: an ObjectType for an Object, a VariableType
    /// for a Variable; `None` if there is none or it is of another class.
    pub type_definition: Option<NodeIx>,
    /// The ModellingRule the node's HasModellingRule reference names, if any.
    pub modelling_rule: Option<ModellingRule>,
    /// The node this one hangs under (ParentNodeId, or the source of its first inverse hierarchical reference).
    pub parent: Option<NodeIx>,
    /// The file that declares the node.
    pub file: FileId,
    /// The start tag of the node's element.
    pub span: Span,
    /// The value of the NodeId attribute (the start tag if the attribute is missing).
    pub node_id_span: Span,
    /// The value of the BrowseName attribute (the start tag if the attribute is missing).
    pub browse_name_span: Span,
}

impl Node {
    /// Whether the node is abstract (IsAbstract, false if not given).
    pub fn is_abstract(&self) -> bool {
        self.attrs.is_abstract.unwrap_or(false)
    }

    /// The first DisplayName (the file's default locale), or the BrowseName.
    pub fn display(&self) -> &str {
        self.display_name.first().map(|t| t.text.as_str()).unwrap_or(&self.browse_name.name)
    }

    /// The Description in the default (first) locale.
    pub fn doc(&self) -> Option<&str> {
        self.description.first().map(|t| t.text.as_str()).filter(|t| !t.is_empty())
    }
}

/// A member of a type: an instance declaration, own or inherited.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Member {
    /// The member's BrowseName, by which a subtype or instance overrides it.
    pub browse_name: QualifiedName,
    /// The declaring node (the override, if a subtype redeclares the member).
    pub node: NodeIx,
    /// The type (or instance declaration) whose children list holds `node`.
    pub declared_in: NodeIx,
    /// The hierarchical ReferenceType from `declared_in` to `node` (HasComponent, HasProperty, ...).
    pub reference_type: NodeIx,
    /// The member of a supertype this one overrides.
    pub overrides: Option<NodeIx>,
}

/// A field of a structure, resolved.
#[derive(Clone, Debug)]
pub struct Field {
    /// The field's Name.
    pub name: std::sync::Arc<str>,
    /// The field's SymbolicName, if the file gives one.
    pub symbolic_name: Option<String>,
    /// The field's DataType (BaseDataType if the file names none).
    pub data_type: NodeIx,
    /// The field's ValueRank (-1, a scalar, if not given).
    pub value_rank: i32,
    /// The field's ArrayDimensions; empty if not given.
    pub array_dimensions: Vec<u32>,
    /// The field's MaxStringLength, if given.
    pub max_string_length: Option<u32>,
    /// Whether the field is optional (IsOptional).
    pub is_optional: bool,
    /// Whether the field may hold a subtype of its DataType (AllowSubTypes).
    pub allow_sub_types: bool,
    /// The text of the field's first Description, if not empty.
    pub description: Option<String>,
    /// The structure that declares the field (a supertype for inherited fields).
    pub declared_in: NodeIx,
    /// The start tag of the field's `<Field>` element.
    pub span: Span,
}

/// The kind of a structure, which decides how it is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StructureKind {
    /// A structure without optional fields.
    Structure,
    /// A structure with at least one optional field (IsOptional).
    StructureWithOptionalFields,
    /// A union (IsUnion, or a subtype of Union).
    Union,
}

/// A value of an enumeration, or a bit of an OptionSet.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EnumValue {
    /// The name: a field's Name, or the text of an EnumStrings or EnumValues entry.
    pub name: String,
    /// The value; for an OptionSet, the bit's position.
    pub value: i64,
    /// The display name: a field's first DisplayName, or an EnumStrings or EnumValues entry's text.
    pub display_name: Option<String>,
    /// The description: a field's first Description, or an EnumValues entry's, if any.
    pub description: Option<String>,
}

/// Where the values of an enumeration come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnumSource {
    /// The fields of the DataType's `<Definition>` (an EnumStrings or EnumValues property that disagrees
    /// decides, NS0219); also an enumeration with neither, which has no values.
    Definition,
    /// The EnumStrings property: each value is the index of its string.
    EnumStrings,
    /// The EnumValues property.
    EnumValues,
}

/// What a DataType is, which decides how its values are encoded.
#[derive(Clone, Debug)]
pub enum DataTypeKind {
    /// One of the 25 built-in types (or an abstract one such as Number, which has no encoding of its own).
    Builtin(BuiltinType),
    /// Abstract BaseDataType, Number, Integer, UInteger, Decimal: encoded as a Variant where used.
    AbstractBuiltin,
    /// A subtype of a built-in scalar type, encoded as that type (Duration as Double).
    Simple(BuiltinType),
    /// An enumeration (Enumeration or a subtype), encoded as Int32.
    Enumeration {
        /// The values, without repeated values or names.
        values: Vec<EnumValue>,
        /// Where the values come from.
        source: EnumSource,
    },
    /// Bits of an unsigned integer (`IsOptionSet` definitions).
    OptionSet {
        /// The nearest built-in type among the DataType and its supertypes (UInt32 if none): the encoding.
        base: BuiltinType,
        /// The named bits, without repeated positions or names.
        bits: Vec<EnumValue>,
    },
    /// A structure (Structure or a subtype), encoded as an ExtensionObject.
    Structure {
        /// Plain, with optional fields, or a union.
        kind: StructureKind,
        /// All fields, inherited ones first.
        fields: Vec<Field>,
        /// Whether the DataType has a `<Definition>`; without one, `fields` are the inherited ones.
        has_definition: bool,
    },
}

/// A DataType, classified.
#[derive(Clone, Debug)]
pub struct DataTypeInfo {
    /// The DataType node.
    pub node: NodeIx,
    /// What kind of DataType it is.
    pub kind: DataTypeKind,
    /// The built-in type values of this DataType are encoded as.
    pub encoding: BuiltinType,
    /// Whether the DataType is abstract (IsAbstract).
    pub is_abstract: bool,
    /// Encoding nodes (`Default Binary`, `Default XML`, `Default JSON`) by BrowseName.
    pub encodings: Vec<(String, NodeIx)>,
}

/// A method argument decoded from an InputArguments or OutputArguments property.
#[derive(Clone, Debug)]
pub struct Argument {
    /// The argument's Name.
    pub name: String,
    /// The argument's DataType; `None` if the Argument gives none.
    pub data_type: Option<NodeIx>,
    /// The argument's ValueRank (-1, a scalar, if not given).
    pub value_rank: i32,
    /// The argument's ArrayDimensions; empty if not given.
    pub array_dimensions: Vec<u32>,
    /// The text of the argument's Description, if not empty.
    pub description: Option<String>,
}

/// The arguments of a Method.
#[derive(Clone, Debug, Default)]
pub struct MethodInfo {
    /// The arguments in its InputArguments property; empty if it has none or it cannot be decoded.
    pub inputs: Vec<Argument>,
    /// The arguments in its OutputArguments property; empty if it has none or it cannot be decoded.
    pub outputs: Vec<Argument>,
}

/// A state of a state machine type: a member whose TypeDefinition is StateType or a subtype.
#[derive(Clone, Debug)]
pub struct State {
    /// The state's instance declaration.
    pub node: NodeIx,
    /// The name of the state's BrowseName.
    pub name: String,
    /// The value of the state's StateNumber property, if it has one that fits a UInt32.
    pub number: Option<u32>,
    /// Whether the state's TypeDefinition is InitialStateType or a subtype.
    pub initial: bool,
}

/// A transition of a state machine type: a member whose TypeDefinition is TransitionType or a subtype.
#[derive(Clone, Debug)]
pub struct Transition {
    /// The transition's instance declaration.
    pub node: NodeIx,
    /// The name of the transition's BrowseName.
    pub name: String,
    /// The value of the transition's TransitionNumber property, if it has one that fits a UInt32.
    pub number: Option<u32>,
    /// The target of the transition's FromState reference.
    pub from: Option<NodeIx>,
    /// The target of the transition's ToState reference.
    pub to: Option<NodeIx>,
    /// The targets of the transition's HasCause references.
    pub causes: Vec<NodeIx>,
    /// The targets of the transition's HasEffect references.
    pub effects: Vec<NodeIx>,
}

/// The states and transitions of a state machine type, inherited ones included.
#[derive(Clone, Debug, Default)]
pub struct StateMachineInfo {
    /// The states, in member order.
    pub states: Vec<State>,
    /// The transitions, in member order.
    pub transitions: Vec<Transition>,
    /// The concrete event type a transition raises: the first TransitionEventType subtype the machine
    /// type (or a supertype, nearest first) names with GeneratesEvent; else the effect its transitions
    /// name (HasEffect), or that effect's nearest concrete supertype when it is abstract (ns0 1.05 makes
    /// ProgramTransitionEventType abstract); `None` if the model has no TransitionEventType.
    pub event_type: Option<NodeIx>,
}

impl StateMachineInfo {
    /// The index in [`StateMachineInfo::states`] of a transition's FromState or ToState target: the state
    /// itself, or the state of the same BrowseName (a subtype may override a state, while a transition it
    /// inherits still names the supertype's state object, which is the same state).
    pub fn state_index(&self, model: &Model, s: NodeIx) -> Option<usize> {
        self.states
            .iter()
            .position(|x| x.node == s)
            .or_else(|| self.states.iter().position(|x| model.node(x.node).browse_name == model.node(s).browse_name))
    }
}

/// How a loaded file maps its local namespace indices and aliases (needed to decode its values).
#[derive(Clone, Debug)]
pub struct FileContext {
    /// Local namespace index to global index (`ns_map[0] == 0`).
    pub ns_map: Vec<u16>,
    /// The file's aliases by name: the NodeId each stands for, as written, with its span.
    pub aliases: FxHashMap<String, Spanned<String>>,
}

impl FileContext {
    /// Resolves a NodeId or alias written in this file. An alias the file forgot to declare that is the
    /// BrowseName of a base DataType or ReferenceType (`IdType`, `NumericRange`) resolves to it, with a
    /// warning: official nodesets contain such omissions and every lenient server accepts them.
    ///
    /// Here rather than in `resolve` because `datatypes` needs it too, and `resolve` calls `datatypes`.
    pub(crate) fn resolve(
        &self,
        model: &Model,
        s: &str,
        span: Span,
        diags: &mut crate::diag::Diagnostics,
    ) -> Result<NodeId, crate::diag::Diagnostic> {
        use crate::diag::{Code, Diagnostic};
        match crate::load::resolve_node_id_str(&self.ns_map, &self.aliases, s, span, &model.namespaces) {
            Err(d) if d.code == Code::UnknownAlias => match model.ns0_type_names.get(s.trim()) {
                Some(&ix) => {
                    let id = model.node(ix).id.clone();
                    diags.push(
                        Diagnostic::new(Code::AliasByBrowseName, format!("alias `{}` is not declared; using the base type `{}` ({id})", s.trim(), s.trim()))
                            .at(span)
                            .help(format!("declare it: <Alias Alias=\"{}\">{id}</Alias>", s.trim())),
                    );
                    Ok(id)
                }
                None => Err(d),
            },
            other => other,
        }
    }
}

/// One model of every loaded file.
#[derive(Debug)]
pub struct Model {
    /// The text of every loaded file.
    pub sources: SourceMap,
    /// The global namespace table: index 0 is the OPC UA namespace.
    pub namespaces: Vec<String>,
    /// The models the loaded files define (declared in `<Models>` or implied by a file without them).
    pub models: Vec<ModelInfo>,
    /// Every node: files in dependency order, nodes in file order.
    pub nodes: Vec<Node>,
    pub(crate) index: FxHashMap<NodeId, NodeIx>,
    /// The namespace indices and aliases of each file, needed to decode its values.
    pub files: BTreeMap<FileId, FileContext>,
    /// Every DataType, classified.
    pub data_types: BTreeMap<NodeIx, DataTypeInfo>,
    /// The arguments of every Method.
    pub methods: BTreeMap<NodeIx, MethodInfo>,
    /// The states and transitions of each state machine type (StateMachineType or a subtype) that has any.
    pub state_machines: BTreeMap<NodeIx, StateMachineInfo>,
    /// Instance declarations of every ObjectType and VariableType, inherited ones included.
    pub members: BTreeMap<NodeIx, Vec<Member>>,
    /// The declaration each InstanceDeclaration overrides: the one at the same browse path in the
    /// fully-inherited hierarchy of its supertype, or among the members its parent declaration inherits
    /// (`resolve/inherit.rs`). [`Model::instance_members`] follows these links.
    pub overridden: BTreeMap<NodeIx, NodeIx>,
    pub(crate) hierarchical: Vec<bool>,
    /// Each node's entry and exit time in a depth-first walk of the supertype forest, so that
    /// [`Model::is_subtype_of`] is one comparison (see [`Model::index_subtypes`]); empty until then.
    pub(crate) subtype_spans: Vec<(u32, u32)>,
    /// BrowseNames of ns0 DataTypes and ReferenceTypes, for undeclared aliases such as `IdType`.
    pub(crate) ns0_type_names: FxHashMap<String, NodeIx>,
    /// The values of each file (indexed by [`FileId`]), read against the file's text in `sources`.
    pub(crate) value_arenas: Vec<ValueArena>,
}

impl Model {
    /// The node at `ix`.
    pub fn node(&self, ix: NodeIx) -> &Node {
        &self.nodes[ix.index()]
    }

    /// The node with NodeId `id`, if loaded.
    pub fn lookup(&self, id: &NodeId) -> Option<NodeIx> {
        self.index.get(id).copied()
    }

    /// The ns0 node with numeric identifier `n` (see [`ids`]), if loaded.
    pub fn ns0(&self, n: u32) -> Option<NodeIx> {
        self.lookup(&NodeId::numeric(0, n))
    }

    /// The model that defines global namespace `ns`.
    pub fn model_of_namespace(&self, ns: u16) -> Option<&ModelInfo> {
        self.models.iter().find(|m| m.ns == ns)
    }

    /// The URI of global namespace `ns` (empty if there is none).
    pub fn namespace_uri(&self, ns: u16) -> &str {
        self.namespaces.get(ns as usize).map(String::as_str).unwrap_or("")
    }

    /// Whether `ix` is the ns0 node with numeric identifier `n`.
    pub fn is_ns0(&self, ix: NodeIx, n: u32) -> bool {
        self.node(ix).id.ns0() == Some(n)
    }

    /// Whether `ix` is `ancestor` or one of its subtypes.
    pub fn is_subtype_of(&self, ix: NodeIx, ancestor: NodeIx) -> bool {
        if let (Some(a), Some(b)) = (self.subtype_spans.get(ix.index()), self.subtype_spans.get(ancestor.index())) {
            return b.0 <= a.0 && a.1 <= b.1;
        }
        let mut cur = Some(ix);
        let mut steps = 0;
        while let Some(c) = cur {
            if c == ancestor {
                return true;
            }
            steps += 1;
            if steps > 10_000 {
                return false;
            }
            cur = self.node(c).super_type;
        }
        false
    }

    /// Whether `ix` is the ns0 type `n` or one of its subtypes.
    pub fn is_subtype_of_ns0(&self, ix: NodeIx, n: u32) -> bool {
        self.ns0(n).is_some_and(|a| self.is_subtype_of(ix, a))
    }

    /// The chain from `ix` up to its root type, `ix` first.
    ///
    /// The resolver breaks subtype cycles, so the chain ends at a root; a cycle met anyway ends the chain
    /// where it closes. Linear in the length of the chain (a set of the nodes seen is kept once the chain
    /// is longer than a real type hierarchy).
    pub fn super_chain(&self, ix: NodeIx) -> Vec<NodeIx> {
        let mut out = vec![ix];
        let mut seen: crate::fxhash::FxHashSet<NodeIx> = Default::default();
        let mut cur = self.node(ix).super_type;
        while let Some(c) = cur {
            if out.len() == 32 {
                seen.extend(out.iter().copied());
            }
            let repeated = if out.len() < 32 { out.contains(&c) } else { !seen.insert(c) };
            if repeated {
                break;
            }
            out.push(c);
            cur = self.node(c).super_type;
        }
        out
    }

    /// Numbers the supertype forest for [`Model::is_subtype_of`], which otherwise walks up the chain (once
    /// per question: quadratic over a deep hierarchy). Called by the resolver once the supertypes are final
    /// (cycles broken); if a cycle remains anyway, the numbering is left out and the walk is used.
    pub(crate) fn index_subtypes(&mut self) {
        const NONE: u32 = u32::MAX;
        let n = self.nodes.len();
        let (mut first_child, mut next_sibling) = (vec![NONE; n], vec![NONE; n]);
        for i in (0..n).rev() {
            if let Some(s) = self.nodes[i].super_type {
                next_sibling[i] = first_child[s.index()];
                first_child[s.index()] = i as u32;
            }
        }
        let mut spans = vec![(0u32, 0u32); n];
        let (mut clock, mut visited) = (0u32, 0usize);
        let mut stack: Vec<(u32, u32)> = Vec::new();
        for root in (0..n).filter(|&i| self.nodes[i].super_type.is_none()) {
            spans[root].0 = clock;
            clock += 1;
            visited += 1;
            stack.push((root as u32, first_child[root]));
            while let Some(top) = stack.last_mut() {
                let child = top.1;
                if child == NONE {
                    let node = top.0 as usize;
                    stack.pop();
                    spans[node].1 = clock;
                    clock += 1;
                } else {
                    top.1 = next_sibling[child as usize];
                    spans[child as usize].0 = clock;
                    clock += 1;
                    visited += 1;
                    stack.push((child, first_child[child as usize]));
                }
            }
        }
        self.subtype_spans = if visited == n { spans } else { Vec::new() };
    }

    /// The supertypes of `ix`, nearest first, read lazily (a caller looking for the nearest one with some
    /// property pays for the types it looks at, not for the whole chain). Ends after as many steps as the
    /// model has nodes, so a cycle met anyway cannot make it endless.
    pub fn supertypes(&self, ix: NodeIx) -> impl Iterator<Item = NodeIx> + '_ {
        std::iter::successors(self.node(ix).super_type, move |&s| self.node(s).super_type).take(self.nodes.len())
    }

    /// For every node, how many supertypes are above it (0 for a node without one), in one pass over the
    /// model: what `super_chain(ix).len() - 1` gives for each node, without walking every chain (which is
    /// quadratic in the depth of a hierarchy). A cycle met anyway counts as ending where it closes.
    pub fn type_depths(&self) -> Vec<u32> {
        const UNKNOWN: u32 = u32::MAX;
        const VISITING: u32 = u32::MAX - 1;
        let mut depth = vec![UNKNOWN; self.nodes.len()];
        let mut path: Vec<usize> = Vec::new();
        for start in 0..self.nodes.len() {
            // Up from `start` to a node whose depth is known, a root, or a node of this path (a cycle).
            let mut cur = start;
            let above = loop {
                match depth[cur] {
                    UNKNOWN => {
                        depth[cur] = VISITING;
                        path.push(cur);
                        match self.nodes[cur].super_type {
                            Some(s) => cur = s.index(),
                            None => break None,
                        }
                    }
                    VISITING => break None,
                    d => break Some(d),
                }
            };
            for (d, &p) in (above.map_or(0, |d| d + 1)..).zip(path.iter().rev()) {
                depth[p] = d;
            }
            path.clear();
        }
        depth
    }

    /// For every node, whether it belongs to an instance of the files rather than to a type: a node outside
    /// namespace 0 that is not a type and whose parent chain ([`Node::parent`]) reaches no type. These are
    /// the nodes the instance rules check (`check` through [`crate::verify::instances`], as `verify` checks
    /// a server's); types, their InstanceDeclarations and namespace 0 (the server stack's own) are not. A
    /// parent cycle counts as reaching no type. One pass: each node's answer is remembered for the nodes
    /// below it.
    pub fn instance_nodes(&self) -> Vec<bool> {
        #[derive(Clone, Copy, PartialEq)]
        enum S {
            Unknown,
            InType,
            Free,
            Walking,
        }
        let mut state = vec![S::Unknown; self.nodes.len()];
        let mut path: Vec<usize> = Vec::new();
        for start in 0..self.nodes.len() {
            let mut cur = Some(start);
            // Up the parent chain to a node whose answer is known, a type, a root or a cycle.
            let answer = loop {
                let Some(i) = cur else { break S::Free };
                match state[i] {
                    S::Unknown => {}
                    S::Walking => break S::Free,
                    known => break known,
                }
                if self.nodes[i].class.is_type() {
                    state[i] = S::InType;
                    break S::InType;
                }
                state[i] = S::Walking;
                path.push(i);
                cur = self.nodes[i].parent.map(NodeIx::index);
            };
            for i in path.drain(..) {
                state[i] = answer;
            }
        }
        self.nodes.iter().zip(state).map(|(n, s)| s == S::Free && n.id.ns != 0 && !n.class.is_type()).collect()
    }

    /// Whether `reference_type` is HierarchicalReferences or a subtype, HasSubtype and its subtypes excepted.
    pub fn is_hierarchical(&self, reference_type: NodeIx) -> bool {
        self.hierarchical.get(reference_type.index()).copied().unwrap_or(false)
    }

    /// Forward hierarchical references to non-type nodes (HasSubtype excluded): the children of a node.
    pub fn children(&self, ix: NodeIx) -> impl Iterator<Item = (NodeIx, NodeIx)> + '_ {
        self.node(ix).references.iter().filter_map(move |r| {
            (r.forward && self.is_hierarchical(r.reference_type) && !self.node(r.target).class.is_type())
                .then_some((r.reference_type, r.target))
        })
    }

    /// The children of an instance declaration or instance, fully inherited (OPC UA Part 3, 6.3.3): its own
    /// children, then those of the declarations it overrides at the same browse path (nearest first, see
    /// [`Model::overridden`]), then the members with a ModellingRule of their TypeDefinitions; at each
    /// BrowseName the first of these wins. Members keep the order of the TypeDefinition's, then come the
    /// names the declarations add, farthest first.
    pub fn instance_members(&self, ix: NodeIx) -> Vec<Member> {
        let chain = self.override_chain(ix);
        let mut out: Vec<Member> = Vec::new();
        // Only members with a ModellingRule are instantiated; a type's own rule-less children (such as
        // DefaultInstanceBrowseName, or the states of a state machine type) stay on the type.
        let mut tds: Vec<NodeIx> = Vec::new();
        for &c in &chain {
            if let Some(t) = self.node(c).type_definition.filter(|t| !tds.contains(t)) {
                tds.push(t);
            }
        }
        for t in tds {
            for m in self.members.get(&t).into_iter().flatten() {
                if self.node(m.node).modelling_rule.is_some() && !out.iter().any(|o| o.browse_name == m.browse_name) {
                    out.push(m.clone());
                }
            }
        }
        for &c in chain.iter().rev() {
            for (rt, child) in self.children(c) {
                let bn = &self.node(child).browse_name;
                match out.iter_mut().find(|m| m.browse_name == *bn) {
                    Some(m) => {
                        m.overrides = Some(m.node);
                        m.node = child;
                        m.declared_in = c;
                        m.reference_type = rt;
                    }
                    None => out.push(Member { browse_name: bn.clone(), node: child, declared_in: c, reference_type: rt, overrides: None }),
                }
            }
        }
        out
    }

    /// `ix` and the declarations it overrides at its browse path, nearest first ([`Model::overridden`]).
    pub fn override_chain(&self, ix: NodeIx) -> Vec<NodeIx> {
        let mut chain = vec![ix];
        while let Some(&next) = self.overridden.get(chain.last().unwrap_or(&ix)) {
            // The resolver links no cycle; the bound keeps a hand-made model from looping.
            if chain.contains(&next) || chain.len() > 64 {
                break;
            }
            chain.push(next);
        }
        chain
    }

    /// Finds a node by `ns=…;i=…` (global index), `nsu=URI;…`, or a BrowseName (`Name` or `URI#Name`,
    /// searching types first).
    pub fn find(&self, query: &str) -> Vec<NodeIx> {
        if crate::nodeid::looks_like_node_id(query) {
            if let Ok(raw) = crate::nodeid::parse_node_id(query) {
                let ns = match raw.ns {
                    crate::nodeid::NsRef::Index(i) => Some(i),
                    crate::nodeid::NsRef::Uri(u) => self.namespaces.iter().position(|n| *n == u).map(|i| i as u16),
                };
                if let Some(ns) = ns {
                    return self.lookup(&NodeId { ns, id: raw.id }).into_iter().collect();
                }
            }
            return Vec::new();
        }
        let (uri, name) = match query.rsplit_once('#') {
            Some((u, n)) => (Some(u), n),
            None => (None, query),
        };
        let mut hits: Vec<NodeIx> = (0..self.nodes.len() as u32)
            .map(NodeIx)
            .filter(|&ix| {
                let n = self.node(ix);
                n.browse_name.name == name && uri.is_none_or(|u| self.namespace_uri(n.browse_name.ns) == u)
            })
            .collect();
        hits.sort_by_key(|&ix| (!self.node(ix).class.is_type(), ix));
        hits
    }

    /// A NodeId for messages: `i=85` in ns0, `nsu=URI;i=5` elsewhere (indices differ between files).
    pub fn display_id(&self, id: &NodeId) -> String {
        if id.ns == 0 {
            id.to_string()
        } else {
            format!("nsu={};{}", self.namespace_uri(id.ns), id.id)
        }
    }

    /// Whether a namespace is the OPC UA base namespace.
    pub fn is_base_namespace(&self, ns: u16) -> bool {
        self.namespace_uri(ns) == NS0_URI
    }

    /// `Name` for ns0 types, `prefix:Name` otherwise, for messages (see [`Model::namespace_prefix`]).
    pub fn qualified(&self, ix: NodeIx) -> String {
        let n = self.node(ix);
        if n.browse_name.ns == 0 {
            n.browse_name.name.clone()
        } else {
            format!("{}:{}", self.namespace_prefix(n.browse_name.ns), n.browse_name.name)
        }
    }

    /// The short name of a namespace in messages: the last segment of its URI (`Robotics` for
    /// `http://opcfoundation.org/UA/Robotics/`), or as many trailing segments as it takes to tell it from every
    /// other loaded namespace (`UA/Robotics` beside a vendor's `vendor.example/Robotics`).
    pub fn namespace_prefix(&self, ns: u16) -> String {
        fn body(uri: &str) -> &str {
            let trimmed = uri.trim_end_matches('/');
            trimmed.split_once("://").map_or(trimmed, |(_, rest)| rest)
        }
        fn tail(uri: &str, k: usize) -> &str {
            let body = body(uri);
            body.rmatch_indices('/').nth(k - 1).map_or(body, |(i, _)| &body[i + 1..])
        }
        let uri = self.namespace_uri(ns);
        let mut k = 1;
        loop {
            let mine = tail(uri, k);
            let clash = self
                .namespaces
                .iter()
                .enumerate()
                .any(|(i, other)| i != ns as usize && i != 0 && tail(other, k) == mine);
            // The whole URI (without its scheme) is the longest prefix there is.
            if !clash || mine.len() == body(uri).len() {
                return mine.to_string();
            }
            k += 1;
        }
    }
}
