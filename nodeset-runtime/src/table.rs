//! The static tables generated code fills: one [`NodeSetTable`] per namespace.
//!
//! A generated namespace is data, not one function per node. Its rows are one string, [`Packed`] text with
//! one line per node (format below), which the compiler reads as a single literal; it is decoded into
//! [`NodeRow`]s the first time the table is used, once per process. Hand-written tables (tests, the demo
//! namespace) can give the rows directly as `const` [`NodeRow`]s ([`Nodes::Rows`]). NodeIds in a table use
//! table-local namespace indices (an index into [`NodeSetTable::namespaces`]); they are mapped to the
//! server's indices when the table is imported, so no generated code ever hard-codes a server namespace
//! index.
//!
//! # The packed format
//!
//! One line per node; empty lines are ignored. Items are separated by one space. A line is
//!
//! ```text
//! Class Id BrowseName DisplayName Description WriteMask UserWriteMask <attributes of Class> Ref*
//! ```
//!
//! - `Id` is `ns:123` (numeric), `ns:s"text"` (string), `ns:g` and 32 hex digits (GUID, the 16 bytes of
//!   [`IdKind::Guid`]) or `ns:b` and hex digits (opaque), with `ns` the table-local namespace index.
//! - `BrowseName` is `ns:"name"`. `DisplayName` is `=` (the BrowseName's name) or a string. `Description` and
//!   every other optional string are `~` (none) or a string.
//! - A string is quoted; inside, `\"`, `\\`, `\n`, `\r`, `\t` and `\u{hex}` (any other control character)
//!   are escaped. Booleans are `0` and `1`; numbers are decimal, floats as Rust prints and parses them
//!   (`1.5`, `-0`, `NaN`, `inf`). Array dimensions are `[]` or `[2,3]`. A list is `{ item item }`, or `{ }`.
//! - The attributes by class (after the name, the fields of [`Kind`] in order):
//!   - `Object event_notifier`, `ObjectType is_abstract`, `Method executable user_executable`,
//!     `View event_notifier contains_no_loops`, `ReferenceType symmetric is_abstract inverse_name`;
//!   - `Variable data_type value_rank array_dimensions access_level user_access_level historizing
//!     minimum_sampling_interval value` (the interval is `~` or a float);
//!   - `VariableType data_type value_rank array_dimensions is_abstract value`;
//!   - `DataType is_abstract definition`, where a definition is `~`, `Enum { EnumRow* }`, or the structure
//!     kind (`Structure`, `StructureWithOptionalFields`, `Union`), then `base default_encoding { FieldRow* }`
//!     with the encoding `~` if none. A `FieldRow` is `name description data_type value_rank
//!     array_dimensions max_string_length is_optional`; an `EnumRow` is `value name display_name
//!     description` (the display name `=` when it is the name).
//! - A value ([`Val`]) is `~` or `Tag:payload`, the tag a variant name: `Boolean:1`, `Int32:-5`,
//!   `Double:0.5`, `String:"text"`, `DateTime:"2025-11-15T00:00:00Z"`, `Guid:` and 32 hex digits,
//!   `ByteString:` and hex digits, `NodeId:Id`, `ExpandedNodeId:Id`, `StatusCode:0`, `QualifiedName:ns:"name"`,
//!   `LocalizedText:locale:"text"` (the locale `~` or a string), `Array:type { Val* }` (`type` the ns0
//!   DataType number), `Arguments:{ ArgRow* }` with an `ArgRow` `name data_type value_rank
//!   array_dimensions description`, and `EnumValues:{ EnumRow* }`. [`Val::Struct`] has no text form.
//! - A structure value (an ExtensionObject) is `Structure:Id { Val* }`: the NodeId of its DataType's Default
//!   Binary encoding, then its body as the items of its OPC UA binary encoding, in order (the compiler, which
//!   knows every field's DataType, lays them out; see [`Val::Structure`]). Inside a body, an item is written
//!   as Part 6 encodes it: a scalar as its built-in type (`UInt32:5` is also how an encoding mask or a union's
//!   switch field is written), `Array:type { Val* }` as a length and its items, `Structure:` as an
//!   ExtensionObject, `Fields:{ Val* }` as a structure encoded in place (a field of a concrete structure
//!   DataType), `Variant:Val` as a Variant (a field of DataType BaseDataType), `Null:type` as the null value
//!   of a built-in type and `NullArray:type` as a null array (fields a value leaves out).
//! - A reference is `ReferenceTypeId>TargetId` (forward) or `ReferenceTypeId<TargetId` (inverse), in the
//!   nodeset's order.
//! - A node with RolePermissions or AccessRestrictions in its nodeset has a second line after its row,
//!   `Access Id restrictions Role=permissions*`: the AccessRestrictions bits or `~`, then each role
//!   object's Id and its `PermissionType` bits, in the nodeset's order ([`AccessRow`]).
//! - An InstanceDeclaration that overrides another (the one at the same browse path in its supertype's, or
//!   its parent declaration's, fully-inherited hierarchy, as the compiler's resolved model computes it) has a
//!   line after its row, `Overrides Id OverriddenId` ([`OverrideRow`]); `instantiate` merges the members of
//!   the two.
//!
//! For example, a property and a structure data type of DI:
//!
//! ```text
//! Variable 1:15002 0:"NamespaceUri" = ~ 0 0 0:12 -1 [] 1 1 0 ~ String:"http://opcfoundation.org/UA/DI/" 0:40>0:68
//! DataType 1:15888 1:"TransferResultErrorDataType" = ~ 0 0 0 Structure 1:6522 1:15891 { "Status" ~ 0:6 -1 [] 0 0 "Diagnostics" ~ 0:25 -1 [] 0 0 } 0:45<1:6522
//! ```

use std::sync::OnceLock;

use opcua::types::NodeId;

mod packed;
#[cfg(test)]
mod tests;

pub use packed::{decode, decode_access, decode_overrides};

/// The identifier part of a NodeId in a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IdKind {
    /// A numeric identifier (`i=`).
    Numeric(u32),
    /// A string identifier (`s=`).
    String(&'static str),
    /// A GUID identifier (`g=`), as its 16 bytes.
    Guid([u8; 16]),
    /// An opaque identifier (`b=`), as its bytes.
    Opaque(&'static [u8]),
}

/// A NodeId with a table-local namespace index (0 is always the OPC UA namespace).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Id {
    /// The table-local namespace index (see [`NodeSetTable::namespaces`]).
    pub ns: u16,
    /// The identifier.
    pub id: IdKind,
}

impl Id {
    /// A numeric NodeId of the OPC UA namespace.
    pub const fn ns0(n: u32) -> Id {
        Id { ns: 0, id: IdKind::Numeric(n) }
    }

    /// A numeric NodeId of table-local namespace `ns`.
    pub const fn numeric(ns: u16, n: u32) -> Id {
        Id { ns, id: IdKind::Numeric(n) }
    }
}

/// A NodeId as generated code names it: the namespace by URI, resolved against a server's or client's
/// namespace table at run time (generated code never hard-codes a namespace index).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NsNodeId {
    /// The namespace URI.
    pub namespace_uri: &'static str,
    /// The identifier within the namespace.
    pub id: IdKind,
}

impl NsNodeId {
    /// A numeric NodeId.
    pub const fn numeric(namespace_uri: &'static str, n: u32) -> NsNodeId {
        NsNodeId { namespace_uri, id: IdKind::Numeric(n) }
    }

    /// A string NodeId.
    pub const fn string(namespace_uri: &'static str, s: &'static str) -> NsNodeId {
        NsNodeId { namespace_uri, id: IdKind::String(s) }
    }

    /// The NodeId in a namespace table (such as the server's NamespaceArray); `None` if the namespace is not
    /// in it.
    pub fn resolve(&self, namespaces: &opcua::types::NamespaceMap) -> Option<NodeId> {
        let ns = namespaces.get_index(self.namespace_uri)?;
        Some(make_node_id(ns, self.id))
    }
}

/// Builds an async-opcua NodeId from a namespace index and an identifier.
#[inline]
pub fn make_node_id(ns: u16, id: IdKind) -> NodeId {
    match id {
        IdKind::Numeric(n) => NodeId::new(ns, n),
        IdKind::String(s) => NodeId::new(ns, opcua::types::UAString::from(s)),
        IdKind::Guid(g) => NodeId::new(ns, opcua::types::Guid::from_bytes(g)),
        IdKind::Opaque(b) => NodeId::new(ns, opcua::types::ByteString::from(b.to_vec())),
    }
}

/// Maps a table's local namespace indices to the server's, once the table's namespaces are registered.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NamespaceMap {
    /// Server index of each table-local index; `u16::MAX` where the namespace is not registered.
    pub indices: Vec<u16>,
}

impl NamespaceMap {
    /// The server NodeId of a table NodeId.
    ///
    /// An index the map does not know is kept as it is; use [`NamespaceMap::try_id`] to notice that.
    pub fn id(&self, id: Id) -> NodeId {
        make_node_id(self.index(id.ns), id.id)
    }

    /// The server namespace index of a table-local index (kept as it is if the map does not know it).
    pub fn index(&self, local: u16) -> u16 {
        self.try_index(local).unwrap_or(local)
    }

    /// The server NodeId of a table NodeId, `None` if its namespace is not registered.
    #[inline]
    pub fn try_id(&self, id: Id) -> Option<NodeId> {
        Some(make_node_id(self.try_index(id.ns)?, id.id))
    }

    /// The server namespace index of a table-local index, `None` if it is not registered.
    #[inline]
    pub fn try_index(&self, local: u16) -> Option<u16> {
        if local == 0 {
            return Some(0);
        }
        self.indices.get(local as usize).copied().filter(|&i| i != UNMAPPED)
    }
}

/// The server index of a table-local namespace that has none.
pub(crate) const UNMAPPED: u16 = u16::MAX;

/// A reference from the row's node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ref {
    /// The ReferenceType.
    pub reference_type: Id,
    /// The node at the other end.
    pub target: Id,
    /// Whether the reference points from the row's node to the target (false: from the target to it).
    pub forward: bool,
}

/// A reference whose type and target have numeric identifiers (nearly all of a nodeset's): reference type
/// namespace and number, target namespace and number, forward. A tuple of literals, because a row is data
/// the compiler checks expression by expression: this is 6 expressions where a [`Ref`] with its two
/// [`Id`]s is 11.
pub type NumRef = (u16, u32, u16, u32, bool);

impl Ref {
    /// The reference a [`NumRef`] stands for.
    pub fn from_numeric(&(rns, rid, tns, tid, forward): &NumRef) -> Ref {
        Ref { reference_type: Id::numeric(rns, rid), target: Id::numeric(tns, tid), forward }
    }
}

/// A field of a structure's DataTypeDefinition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldRow {
    /// The field's name.
    pub name: &'static str,
    /// Its description, if the nodeset gives one.
    pub description: Option<&'static str>,
    /// Its DataType.
    pub data_type: Id,
    /// Its ValueRank (-1 scalar, n >= 1 an n-dimensional array, ...).
    pub value_rank: i32,
    /// The length of each dimension (0: any), empty when not given.
    pub array_dimensions: &'static [u32],
    /// The longest string the field may hold (0: no limit).
    pub max_string_length: u32,
    /// Whether the field is optional (a StructureWithOptionalFields).
    pub is_optional: bool,
}

/// A field of an enumeration's (or OptionSet's) DataTypeDefinition; also an EnumValues entry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnumRow {
    /// The value (for an OptionSet, the bit number).
    pub value: i64,
    /// The field's name.
    pub name: &'static str,
    /// Its DisplayName text.
    pub display_name: &'static str,
    /// Its description, if the nodeset gives one.
    pub description: Option<&'static str>,
}

/// StructureType of OPC UA Part 3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StructureKind {
    /// Every field is always present.
    Structure,
    /// Fields marked optional may be absent (an encoding mask says which are present).
    StructureWithOptionalFields,
    /// Exactly one field is present (a switch field says which).
    Union,
}

/// A DataTypeDefinition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Def {
    /// A StructureDefinition.
    Structure {
        /// The supertype (BaseDataType's Structure, or another structure).
        base: Id,
        /// The DataTypeEncoding node of the default binary encoding, if the nodeset has one.
        default_encoding: Option<Id>,
        /// Structure, with optional fields, or union.
        kind: StructureKind,
        /// The fields, in order.
        fields: &'static [FieldRow],
    },
    /// An EnumDefinition (of an enumeration or an OptionSet).
    Enum {
        /// The fields, in order.
        fields: &'static [EnumRow],
    },
}

/// An Argument of a method's InputArguments or OutputArguments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArgRow {
    /// The argument's name.
    pub name: &'static str,
    /// Its DataType.
    pub data_type: Id,
    /// Its ValueRank.
    pub value_rank: i32,
    /// The length of each dimension (0: any), empty when not given.
    pub array_dimensions: &'static [u32],
    /// Its description, if the nodeset gives one.
    pub description: Option<&'static str>,
}

/// A node's initial value.
#[derive(Clone, Copy, Debug)]
pub enum Val {
    /// No value in the nodeset.
    None,
    /// A Boolean.
    Boolean(bool),
    /// An SByte.
    SByte(i8),
    /// A Byte.
    Byte(u8),
    /// An Int16.
    Int16(i16),
    /// A UInt16.
    UInt16(u16),
    /// An Int32.
    Int32(i32),
    /// A UInt32.
    UInt32(u32),
    /// An Int64.
    Int64(i64),
    /// A UInt64.
    UInt64(u64),
    /// A Float.
    Float(f32),
    /// A Double.
    Double(f64),
    /// A String.
    String(&'static str),
    /// ISO 8601 text as written in the nodeset.
    DateTime(&'static str),
    /// A Guid, as its 16 bytes.
    Guid([u8; 16]),
    /// A ByteString.
    ByteString(&'static [u8]),
    /// A NodeId.
    NodeId(Id),
    /// An ExpandedNodeId (of this server).
    ExpandedNodeId(Id),
    /// A StatusCode, as its 32 bits.
    StatusCode(u32),
    /// A QualifiedName: table-local namespace index and name.
    QualifiedName(u16, &'static str),
    /// A LocalizedText: locale, if any, and text.
    LocalizedText(Option<&'static str>, &'static str),
    /// A one-dimensional array; its items are all of one built-in type (given by its ns0 DataType id, so an
    /// empty array keeps its type).
    Array(u32, &'static [Val]),
    /// An array of Argument structures (InputArguments, OutputArguments).
    Arguments(&'static [ArgRow]),
    /// An array of EnumValueType structures (EnumValues).
    EnumValues(&'static [EnumRow]),
    /// Any other ExtensionObject value (scalar, or an array when it returns several), built at import time
    /// because it contains NodeIds whose namespace indices are only known then.
    Struct(fn(&NamespaceMap) -> opcua::types::Variant),
    /// A structure value: the Default Binary encoding of its DataType and the items of its body, in the
    /// order of its binary encoding. The import writes the body's bytes with the server's namespace indices
    /// and decodes them with the server's type loaders (or keeps the bytes, for a type no loader knows).
    Structure(Id, &'static [Val]),
    /// Inside a structure's body: a nested structure encoded in place, its items in order.
    Fields(&'static [Val]),
    /// Inside a structure's body: a value encoded as a Variant.
    Variant(&'static Val),
    /// Inside a structure's body: the null value of a built-in type (by its ns0 DataType number).
    Null(u32),
    /// Inside a structure's body: a null array of a built-in type (by its ns0 DataType number).
    NullArray(u32),
}

/// What kind of node a row is, with the attributes of that node class.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// An Object.
    Object {
        /// Its EventNotifier bits.
        event_notifier: u8,
    },
    /// An ObjectType.
    ObjectType {
        /// Whether it is abstract.
        is_abstract: bool,
    },
    /// A Variable.
    Variable {
        /// Its DataType.
        data_type: Id,
        /// Its ValueRank.
        value_rank: i32,
        /// The length of each dimension (0: any), empty when not given.
        array_dimensions: &'static [u32],
        /// Its AccessLevel bits.
        access_level: u8,
        /// Its UserAccessLevel bits.
        user_access_level: u8,
        /// Whether the server keeps its history.
        historizing: bool,
        /// Its MinimumSamplingInterval in milliseconds, if the nodeset gives one.
        minimum_sampling_interval: Option<f64>,
        /// Its initial value.
        value: Val,
    },
    /// A VariableType.
    VariableType {
        /// Its DataType.
        data_type: Id,
        /// Its ValueRank.
        value_rank: i32,
        /// The length of each dimension (0: any), empty when not given.
        array_dimensions: &'static [u32],
        /// Whether it is abstract.
        is_abstract: bool,
        /// The default value of its instances.
        value: Val,
    },
    /// A Method.
    Method {
        /// Whether it can be called.
        executable: bool,
        /// Whether the current user can call it.
        user_executable: bool,
    },
    /// A ReferenceType.
    ReferenceType {
        /// Whether the reference means the same in both directions.
        symmetric: bool,
        /// Whether it is abstract.
        is_abstract: bool,
        /// Its InverseName text, if it has one.
        inverse_name: Option<&'static str>,
    },
    /// A DataType.
    DataType {
        /// Whether it is abstract.
        is_abstract: bool,
        /// Its DataTypeDefinition (structures and enumerations).
        definition: Option<Def>,
    },
    /// A View.
    View {
        /// Its EventNotifier bits.
        event_notifier: u8,
        /// Whether following its references never loops.
        contains_no_loops: bool,
    },
}

/// One node.
#[derive(Clone, Copy, Debug)]
pub struct NodeRow {
    /// Its NodeId.
    pub id: Id,
    /// BrowseName: table-local namespace index and name.
    pub browse_name: (u16, &'static str),
    /// Its DisplayName text.
    pub display_name: &'static str,
    /// Its Description text, if the nodeset gives one.
    pub description: Option<&'static str>,
    /// Its WriteMask bits.
    pub write_mask: u32,
    /// Its UserWriteMask bits.
    pub user_write_mask: u32,
    /// Its node class, with the attributes of that class.
    pub kind: Kind,
    /// References declared on this node (forward and inverse), as the nodeset declares them, when one of
    /// them has an identifier that is not numeric; otherwise empty, and they are in `nrefs`.
    pub refs: &'static [Ref],
    /// References declared on this node when all of them are numeric (generated tables use one of the two
    /// lists, so the order is the nodeset's either way).
    pub nrefs: &'static [NumRef],
}

impl NodeRow {
    /// Every reference of the row: `refs`, then `nrefs`.
    pub fn references(&self) -> impl Iterator<Item = Ref> + '_ {
        self.refs.iter().copied().chain(self.nrefs.iter().map(Ref::from_numeric))
    }
}

/// A namespace's address space.
#[derive(Debug)]
pub struct NodeSetTable {
    /// The namespace this table defines.
    pub namespace_uri: &'static str,
    /// The model's version and publication date, from the nodeset.
    pub version: &'static str,
    /// The model's publication date (ISO 8601), from the nodeset.
    pub publication_date: &'static str,
    /// Table-local namespace index to URI; index 0 is `http://opcfoundation.org/UA/`.
    pub namespaces: &'static [&'static str],
    /// The index of `namespace_uri` in `namespaces`.
    pub own: u16,
    /// The rows; read them with [`NodeSetTable::rows`].
    pub nodes: Nodes,
}

impl NodeSetTable {
    /// Every node of the table, one row per node. Packed rows are decoded on the first call (once per
    /// process, kept for the process's lifetime); an error names the line of the text that does not
    /// decode, and is returned again on every later call.
    pub fn rows(&self) -> Result<&[NodeRow], TableError> {
        match &self.nodes {
            Nodes::Rows(rows) => Ok(rows),
            Nodes::Packed(p) => p.rows.get_or_init(|| decode(p.text)).as_deref().map_err(|e| self.error(e)),
        }
    }
}

impl NodeSetTable {
    /// The nodes whose nodeset gives RolePermissions or AccessRestrictions, in table order (none for
    /// [`Nodes::Rows`]). Decoded on the first call, like [`NodeSetTable::rows`].
    pub fn access(&self) -> Result<&[AccessRow], TableError> {
        match &self.nodes {
            Nodes::Rows(_) => Ok(&[]),
            Nodes::Packed(p) => p.access.get_or_init(|| decode_access(p.text)).as_deref().map_err(|e| self.error(e)),
        }
    }

    /// The InstanceDeclarations that override another, in table order (none for [`Nodes::Rows`]). Decoded
    /// on the first call, like [`NodeSetTable::rows`].
    pub fn overrides(&self) -> Result<&[OverrideRow], TableError> {
        match &self.nodes {
            Nodes::Rows(_) => Ok(&[]),
            Nodes::Packed(p) => p.overrides.get_or_init(|| decode_overrides(p.text)).as_deref().map_err(|e| self.error(e)),
        }
    }

    /// The error of packed text that does not decode, as the table reports it.
    fn error(&self, (line, column, message): &(usize, usize, String)) -> TableError {
        TableError { namespace_uri: self.namespace_uri, line: *line, column: *column, message: message.clone() }
    }
}

/// The RolePermissions and AccessRestrictions a nodeset gives one node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AccessRow {
    /// The node.
    pub id: Id,
    /// The `AccessRestrictionType` bits, if the nodeset gives them.
    pub restrictions: Option<u16>,
    /// Each role object (a well-known role of the base namespace, or a role of the nodeset) and its
    /// `PermissionType` bits.
    pub roles: Vec<(Id, u32)>,
}

/// How the line of a node's RolePermissions and AccessRestrictions starts.
const ACCESS: &str = "Access ";

/// An InstanceDeclaration and the declaration it overrides at its browse path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OverrideRow {
    /// The overriding declaration.
    pub id: Id,
    /// The declaration it overrides (of a supertype, or of its parent declaration's TypeDefinition).
    pub overridden: Id,
}

/// How the line of a declaration's override starts.
const OVERRIDES: &str = "Overrides ";

/// The rows of a [`NodeSetTable`].
#[derive(Debug)]
pub enum Nodes {
    /// Rows written as Rust values.
    Rows(&'static [NodeRow]),
    /// Rows as text in the packed format of this module's documentation (what the generator writes).
    Packed(Packed),
}

/// Rows as packed text, decoded once.
#[derive(Debug)]
pub struct Packed {
    text: &'static str,
    rows: OnceLock<Result<Box<[NodeRow]>, (usize, usize, String)>>,
    access: OnceLock<Result<Box<[AccessRow]>, (usize, usize, String)>>,
    overrides: OnceLock<Result<Box<[OverrideRow]>, (usize, usize, String)>>,
}

impl Packed {
    /// Packed text, decoded on first use.
    pub const fn new(text: &'static str) -> Packed {
        Packed { text, rows: OnceLock::new(), access: OnceLock::new(), overrides: OnceLock::new() }
    }

    /// The text as the table holds it.
    pub fn text(&self) -> &'static str {
        self.text
    }
}

/// A packed table whose text does not decode (the generated file was edited, or comes from an
/// incompatible generator version).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TableError {
    /// The namespace whose table does not decode.
    pub namespace_uri: &'static str,
    /// 1-based line (within the table's text).
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong there.
    pub message: String,
}

impl std::fmt::Display for TableError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the node table of {} does not decode at line {}, column {}: {}; regenerate the module with \
             nodeset-compiler (generated files must not be edited)",
            self.namespace_uri, self.line, self.column, self.message
        )
    }
}

impl std::error::Error for TableError {}
