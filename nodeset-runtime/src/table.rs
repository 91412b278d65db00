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
//! - A reference is `ReferenceTypeId>TargetId` (forward) or `ReferenceTypeId<TargetId` (inverse), in the
//!   nodeset's order.
//! - A node with RolePermissions or AccessRestrictions in its nodeset has a second line after its row,
//!   `Access Id restrictions Role=permissions*`: the AccessRestrictions bits or `~`, then each role
//!   object's Id and its `PermissionType` bits, in the nodeset's order ([`AccessRow`]).
//!
//! For example, a property and a structure data type of DI:
//!
//! ```text
//! Variable 1:15002 0:"NamespaceUri" = ~ 0 0 0:12 -1 [] 1 1 0 ~ String:"http://opcfoundation.org/UA/DI/" 0:40>0:68
//! DataType 1:15888 1:"TransferResultErrorDataType" = ~ 0 0 0 Structure 1:6522 1:15891 { "Status" ~ 0:6 -1 [] 0 0 "Diagnostics" ~ 0:25 -1 [] 0 0 } 0:45<1:6522
//! ```

use std::sync::OnceLock;

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
    Struct(fn(&crate::NamespaceMap) -> opcua::types::Variant),
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

/// Decodes the `Access` lines of packed text.
pub fn decode_access(text: &'static str) -> Result<Box<[AccessRow]>, (usize, usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.split('\n').enumerate() {
        let Some(rest) = line.strip_prefix(ACCESS) else { continue };
        let mut c = Cursor { s: line, b: line.as_bytes(), i: line.len() - rest.len() };
        let row = (|| {
            let id = c.id()?;
            c.sp()?;
            let restrictions = if c.eat(b'~') { None } else { Some(c.num("AccessRestrictions")?) };
            let mut roles = Vec::new();
            while c.eat(b' ') {
                let role = c.id()?;
                c.expect(b'=')?;
                roles.push((role, c.num("PermissionType bits")?));
            }
            match c.peek() {
                None => Ok(AccessRow { id, restrictions, roles }),
                Some(f) => Err(format!("unexpected `{}` after the access row", f as char)),
            }
        })();
        match row {
            Ok(row) => out.push(row),
            Err(message) => {
                let column = line.get(..c.i.min(line.len())).map_or(c.i, |p| p.chars().count()) + 1;
                return Err((n + 1, column, message));
            }
        }
    }
    Ok(out.into_boxed_slice())
}

/// How the line of a node's RolePermissions and AccessRestrictions starts.
const ACCESS: &str = "Access ";

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
}

impl Packed {
    /// Packed text, decoded on first use.
    pub const fn new(text: &'static str) -> Packed {
        Packed { text, rows: OnceLock::new(), access: OnceLock::new() }
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

/// Decodes packed text into rows. Strings without escapes are slices of `text`; everything else the rows
/// point to is allocated once and leaked, because rows are `'static` data and a table is decoded once per
/// process. An error is (line, column, message).
pub fn decode(text: &'static str) -> Result<Box<[NodeRow]>, (usize, usize, String)> {
    let mut rows = Vec::with_capacity(text.len() / 128);
    // Numeric references of all rows in one allocation; each row's range is filled in at the end.
    let mut nrefs: Vec<NumRef> = Vec::with_capacity(text.len() / 48);
    let mut ranges: Vec<(usize, usize)> = Vec::with_capacity(text.len() / 128);
    let mut refs: Vec<Ref> = Vec::new();
    for (n, line) in text.split('\n').enumerate() {
        if line.is_empty() || line.starts_with(ACCESS) {
            continue;
        }
        let mut c = Cursor { s: line, b: line.as_bytes(), i: 0 };
        refs.clear();
        match c.row(&mut refs) {
            Ok(mut row) => {
                let numeric = |id: &Id| match id.id {
                    IdKind::Numeric(v) => Some((id.ns, v)),
                    _ => None,
                };
                let start = nrefs.len();
                let all_numeric = refs.iter().all(|r| numeric(&r.reference_type).is_some() && numeric(&r.target).is_some());
                if all_numeric {
                    nrefs.extend(refs.iter().filter_map(|r| {
                        let ((rns, rid), (tns, tid)) = (numeric(&r.reference_type)?, numeric(&r.target)?);
                        Some((rns, rid, tns, tid, r.forward))
                    }));
                } else {
                    row.refs = leak(refs.clone());
                }
                ranges.push((start, nrefs.len()));
                rows.push(row);
            }
            Err(message) => {
                let column = line.get(..c.i.min(line.len())).map_or(c.i, |p| p.chars().count()) + 1;
                return Err((n + 1, column, message));
            }
        }
    }
    let nrefs: &'static [NumRef] = leak(nrefs);
    for (row, (a, b)) in rows.iter_mut().zip(ranges) {
        row.nrefs = &nrefs[a..b];
    }
    Ok(rows.into_boxed_slice())
}

fn leak<T>(v: Vec<T>) -> &'static [T] {
    Box::leak(v.into_boxed_slice())
}

type Res<T> = Result<T, String>;

/// A position in one line of packed text.
struct Cursor {
    s: &'static str,
    b: &'static [u8],
    i: usize,
}

impl Cursor {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn eat(&mut self, c: u8) -> bool {
        let hit = self.peek() == Some(c);
        if hit {
            self.i += 1;
        }
        hit
    }

    fn expect(&mut self, c: u8) -> Res<()> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(match self.peek() {
                Some(f) => format!("expected `{}`, found `{}`", c as char, f as char),
                None => format!("expected `{}`, found the end of the line", c as char),
            })
        }
    }

    /// `' '` then the next item.
    fn sp(&mut self) -> Res<()> {
        self.expect(b' ')
    }

    /// A word of ASCII letters and digits (a class, a tag such as `Int32`).
    fn word(&mut self) -> &'static str {
        let start = self.i;
        while self.peek().is_some_and(|c| c.is_ascii_alphanumeric()) {
            self.i += 1;
        }
        &self.s[start..self.i]
    }

    /// A decimal integer. The magnitude is read as a u64 (no table number needs more, since every target type
    /// has at most 64 bits), which is cheaper than 128-bit arithmetic per digit.
    fn int(&mut self) -> Res<i128> {
        let neg = self.eat(b'-');
        let start = self.i;
        let mut v: u64 = 0;
        while let Some(d) = self.peek().filter(u8::is_ascii_digit) {
            v = v.checked_mul(10).and_then(|v| v.checked_add(u64::from(d - b'0'))).ok_or("number too large")?;
            self.i += 1;
        }
        if self.i == start {
            return Err("expected a number".into());
        }
        let v = i128::from(v);
        Ok(if neg { -v } else { v })
    }

    fn num<T: TryFrom<i128>>(&mut self, what: &str) -> Res<T> {
        let start = self.i;
        let v = self.int()?;
        T::try_from(v).map_err(|_| {
            self.i = start;
            format!("{v} is out of range for {what}")
        })
    }

    fn bool(&mut self) -> Res<bool> {
        match self.peek() {
            Some(b'0') => {
                self.i += 1;
                Ok(false)
            }
            Some(b'1') => {
                self.i += 1;
                Ok(true)
            }
            _ => Err("expected a boolean, `0` or `1`".into()),
        }
    }

    /// Text up to the next delimiter, for floats.
    fn token(&mut self) -> &'static str {
        let start = self.i;
        while self.peek().is_some_and(|c| !matches!(c, b' ' | b'}' | b']' | b',')) {
            self.i += 1;
        }
        &self.s[start..self.i]
    }

    fn f64(&mut self) -> Res<f64> {
        let t = self.token();
        t.parse().map_err(|_| format!("`{t}` is not a number"))
    }

    fn f32(&mut self) -> Res<f32> {
        let t = self.token();
        t.parse().map_err(|_| format!("`{t}` is not a number"))
    }

    /// Pairs of hex digits.
    fn hex(&mut self) -> Res<Vec<u8>> {
        let digit = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
        let mut out = Vec::new();
        while let Some(hi) = self.peek().and_then(digit) {
            self.i += 1;
            let lo = self.peek().and_then(digit).ok_or("odd number of hex digits")?;
            self.i += 1;
            out.push(hi << 4 | lo);
        }
        Ok(out)
    }

    fn guid(&mut self) -> Res<[u8; 16]> {
        self.hex()?.try_into().map_err(|_| "a GUID is 32 hex digits".into())
    }

    fn string(&mut self) -> Res<&'static str> {
        self.expect(b'"')?;
        let start = self.i;
        loop {
            match self.peek() {
                None => return Err("unterminated string".into()),
                Some(b'"') => {
                    self.i += 1;
                    return Ok(&self.s[start..self.i - 1]);
                }
                Some(b'\\') => break,
                Some(_) => self.i += 1,
            }
        }
        let mut out = String::from(&self.s[start..self.i]);
        loop {
            match self.peek() {
                None => return Err("unterminated string".into()),
                Some(b'"') => {
                    self.i += 1;
                    return Ok(Box::leak(out.into_boxed_str()));
                }
                Some(b'\\') => {
                    self.i += 1;
                    let e = self.peek().ok_or("unterminated string")?;
                    self.i += 1;
                    out.push(match e {
                        b'"' => '"',
                        b'\\' => '\\',
                        b'n' => '\n',
                        b'r' => '\r',
                        b't' => '\t',
                        b'u' => {
                            self.expect(b'{')?;
                            let start = self.i;
                            while self.peek().is_some_and(|c| c.is_ascii_hexdigit()) {
                                self.i += 1;
                            }
                            let code = u32::from_str_radix(&self.s[start..self.i], 16).map_err(|_| "bad `\\u{..}` escape")?;
                            self.expect(b'}')?;
                            char::from_u32(code).ok_or("`\\u{..}` is not a character")?
                        }
                        e => return Err(format!("unknown escape `\\{}`", e as char)),
                    });
                }
                Some(_) => {
                    let start = self.i;
                    while self.peek().is_some_and(|c| c != b'"' && c != b'\\') {
                        self.i += 1;
                    }
                    out.push_str(&self.s[start..self.i]);
                }
            }
        }
    }

    fn opt_string(&mut self) -> Res<Option<&'static str>> {
        if self.eat(b'~') {
            Ok(None)
        } else {
            self.string().map(Some)
        }
    }

    /// A string, or `=` for `same`.
    fn string_or(&mut self, same: &'static str) -> Res<&'static str> {
        if self.eat(b'=') {
            Ok(same)
        } else {
            self.string()
        }
    }

    fn id(&mut self) -> Res<Id> {
        let ns = self.num("a namespace index")?;
        self.expect(b':')?;
        let id = match self.peek() {
            Some(b's') => {
                self.i += 1;
                IdKind::String(self.string()?)
            }
            Some(b'g') => {
                self.i += 1;
                IdKind::Guid(self.guid()?)
            }
            Some(b'b') => {
                self.i += 1;
                IdKind::Opaque(leak(self.hex()?))
            }
            _ => IdKind::Numeric(self.num("a numeric identifier")?),
        };
        Ok(Id { ns, id })
    }

    fn opt_id(&mut self) -> Res<Option<Id>> {
        if self.eat(b'~') {
            Ok(None)
        } else {
            self.id().map(Some)
        }
    }

    /// `ns:"name"`.
    fn qualified(&mut self) -> Res<(u16, &'static str)> {
        let ns = self.num("a namespace index")?;
        self.expect(b':')?;
        Ok((ns, self.string()?))
    }

    fn dims(&mut self) -> Res<&'static [u32]> {
        self.expect(b'[')?;
        if self.eat(b']') {
            return Ok(&[]);
        }
        let mut v = Vec::new();
        loop {
            v.push(self.num("an array dimension")?);
            if self.eat(b']') {
                return Ok(leak(v));
            }
            self.expect(b',')?;
        }
    }

    /// `{ item item }` or `{ }`.
    fn list<T>(&mut self, mut item: impl FnMut(&mut Self) -> Res<T>) -> Res<&'static [T]> {
        self.expect(b'{')?;
        let mut v = Vec::new();
        loop {
            self.sp()?;
            if self.eat(b'}') {
                return Ok(leak(v));
            }
            v.push(item(self)?);
        }
    }

    fn enum_row(&mut self) -> Res<EnumRow> {
        let value = self.num("an enumeration value")?;
        self.sp()?;
        let name = self.string()?;
        self.sp()?;
        let display_name = self.string_or(name)?;
        self.sp()?;
        Ok(EnumRow { value, name, display_name, description: self.opt_string()? })
    }

    fn field_row(&mut self) -> Res<FieldRow> {
        let name = self.string()?;
        self.sp()?;
        let description = self.opt_string()?;
        self.sp()?;
        let data_type = self.id()?;
        self.sp()?;
        let value_rank = self.num("a ValueRank")?;
        self.sp()?;
        let array_dimensions = self.dims()?;
        self.sp()?;
        let max_string_length = self.num("a MaxStringLength")?;
        self.sp()?;
        Ok(FieldRow { name, description, data_type, value_rank, array_dimensions, max_string_length, is_optional: self.bool()? })
    }

    fn arg_row(&mut self) -> Res<ArgRow> {
        let name = self.string()?;
        self.sp()?;
        let data_type = self.id()?;
        self.sp()?;
        let value_rank = self.num("a ValueRank")?;
        self.sp()?;
        let array_dimensions = self.dims()?;
        self.sp()?;
        Ok(ArgRow { name, data_type, value_rank, array_dimensions, description: self.opt_string()? })
    }

    fn definition(&mut self) -> Res<Option<Def>> {
        if self.eat(b'~') {
            return Ok(None);
        }
        let kind = match self.word() {
            "Enum" => {
                self.sp()?;
                return Ok(Some(Def::Enum { fields: self.list(Self::enum_row)? }));
            }
            "Structure" => StructureKind::Structure,
            "StructureWithOptionalFields" => StructureKind::StructureWithOptionalFields,
            "Union" => StructureKind::Union,
            w => return Err(format!("unknown definition `{w}`")),
        };
        self.sp()?;
        let base = self.id()?;
        self.sp()?;
        let default_encoding = self.opt_id()?;
        self.sp()?;
        Ok(Some(Def::Structure { base, default_encoding, kind, fields: self.list(Self::field_row)? }))
    }

    fn value(&mut self) -> Res<Val> {
        if self.eat(b'~') {
            return Ok(Val::None);
        }
        let tag = self.word();
        self.expect(b':')?;
        Ok(match tag {
            "Boolean" => Val::Boolean(self.bool()?),
            "SByte" => Val::SByte(self.num("SByte")?),
            "Byte" => Val::Byte(self.num("Byte")?),
            "Int16" => Val::Int16(self.num("Int16")?),
            "UInt16" => Val::UInt16(self.num("UInt16")?),
            "Int32" => Val::Int32(self.num("Int32")?),
            "UInt32" => Val::UInt32(self.num("UInt32")?),
            "Int64" => Val::Int64(self.num("Int64")?),
            "UInt64" => Val::UInt64(self.num("UInt64")?),
            "Float" => Val::Float(self.f32()?),
            "Double" => Val::Double(self.f64()?),
            "String" => Val::String(self.string()?),
            "DateTime" => Val::DateTime(self.string()?),
            "Guid" => Val::Guid(self.guid()?),
            "ByteString" => Val::ByteString(leak(self.hex()?)),
            "NodeId" => Val::NodeId(self.id()?),
            "ExpandedNodeId" => Val::ExpandedNodeId(self.id()?),
            "StatusCode" => Val::StatusCode(self.num("a StatusCode")?),
            "QualifiedName" => {
                let (ns, name) = self.qualified()?;
                Val::QualifiedName(ns, name)
            }
            "LocalizedText" => {
                let locale = self.opt_string()?;
                self.expect(b':')?;
                Val::LocalizedText(locale, self.string()?)
            }
            "Array" => {
                let ty = self.num("a DataType number")?;
                self.sp()?;
                Val::Array(ty, self.list(Self::value)?)
            }
            "Arguments" => Val::Arguments(self.list(Self::arg_row)?),
            "EnumValues" => Val::EnumValues(self.list(Self::enum_row)?),
            t => return Err(format!("unknown value tag `{t}`")),
        })
    }

    /// One line; its references go to `refs`.
    fn row(&mut self, refs: &mut Vec<Ref>) -> Res<NodeRow> {
        let class = self.word();
        if !matches!(
            class,
            "Object" | "ObjectType" | "Variable" | "VariableType" | "Method" | "ReferenceType" | "DataType" | "View"
        ) {
            self.i = 0;
            return Err(format!("unknown node class `{class}`"));
        }
        self.sp()?;
        let id = self.id()?;
        self.sp()?;
        let browse_name = self.qualified()?;
        self.sp()?;
        let display_name = self.string_or(browse_name.1)?;
        self.sp()?;
        let description = self.opt_string()?;
        self.sp()?;
        let write_mask = self.num("a WriteMask")?;
        self.sp()?;
        let user_write_mask = self.num("a UserWriteMask")?;
        self.sp()?;
        let kind = match class {
            "Object" => Kind::Object { event_notifier: self.num("an EventNotifier")? },
            "ObjectType" => Kind::ObjectType { is_abstract: self.bool()? },
            "Variable" | "VariableType" => {
                let data_type = self.id()?;
                self.sp()?;
                let value_rank = self.num("a ValueRank")?;
                self.sp()?;
                let array_dimensions = self.dims()?;
                self.sp()?;
                if class == "Variable" {
                    let access_level = self.num("an AccessLevel")?;
                    self.sp()?;
                    let user_access_level = self.num("a UserAccessLevel")?;
                    self.sp()?;
                    let historizing = self.bool()?;
                    self.sp()?;
                    let minimum_sampling_interval = if self.eat(b'~') { None } else { Some(self.f64()?) };
                    self.sp()?;
                    Kind::Variable {
                        data_type,
                        value_rank,
                        array_dimensions,
                        access_level,
                        user_access_level,
                        historizing,
                        minimum_sampling_interval,
                        value: self.value()?,
                    }
                } else {
                    let is_abstract = self.bool()?;
                    self.sp()?;
                    Kind::VariableType { data_type, value_rank, array_dimensions, is_abstract, value: self.value()? }
                }
            }
            "Method" => {
                let executable = self.bool()?;
                self.sp()?;
                Kind::Method { executable, user_executable: self.bool()? }
            }
            "ReferenceType" => {
                let symmetric = self.bool()?;
                self.sp()?;
                let is_abstract = self.bool()?;
                self.sp()?;
                Kind::ReferenceType { symmetric, is_abstract, inverse_name: self.opt_string()? }
            }
            "DataType" => {
                let is_abstract = self.bool()?;
                self.sp()?;
                Kind::DataType { is_abstract, definition: self.definition()? }
            }
            "View" => {
                let event_notifier = self.num("an EventNotifier")?;
                self.sp()?;
                Kind::View { event_notifier, contains_no_loops: self.bool()? }
            }
            c => return Err(format!("unknown node class `{c}`")),
        };
        while self.i < self.b.len() {
            self.sp()?;
            let reference_type = self.id()?;
            let forward = match self.peek() {
                Some(b'>') => true,
                Some(b'<') => false,
                _ => return Err("expected `>` or `<` between a reference's type and target".into()),
            };
            self.i += 1;
            refs.push(Ref { reference_type, target: self.id()?, forward });
        }
        Ok(NodeRow {
            id,
            browse_name,
            display_name,
            description,
            write_mask,
            user_write_mask,
            kind,
            refs: &[],
            nrefs: &[],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn access_lines_decode_and_rows_skip_them() {
        let text = "\nVariable 1:6001 1:\"Setpoint\" = ~ 0 0 0:11 -1 [] 3 3 0 ~ ~ 0:40>0:63\nAccess 1:6001 ~ 0:15680=97 0:15668=33\nMethod 1:7002 1:\"Reset\" = ~ 0 0 1 1\nAccess 1:7002 2 0:15692=4097\n";
        let rows = decode(text).unwrap();
        assert_eq!(rows.len(), 2, "the Access lines are not rows");
        let access = decode_access(text).unwrap();
        assert_eq!(
            access.as_ref(),
            [
                AccessRow { id: Id::numeric(1, 6001), restrictions: None, roles: vec![(Id::ns0(15680), 97), (Id::ns0(15668), 33)] },
                AccessRow { id: Id::numeric(1, 7002), restrictions: Some(2), roles: vec![(Id::ns0(15692), 4097)] },
            ]
        );
        assert!(decode_access("Object 1:1 1:\"A\" = ~ 0 0 0\n").unwrap().is_empty());
        // A damaged line names its line and column.
        let (line, column, message) = decode_access("\nAccess 1:6001 ~ 0:15680-97\n").unwrap_err();
        assert_eq!((line, column), (2, 24), "{message}");
        assert!(message.contains("expected `=`"), "{message}");
        let (_, _, message) = decode_access("Access 1:6001 70000\n").unwrap_err();
        assert!(message.contains("out of range"), "{message}");
    }

    const fn row(refs: &'static [Ref], nrefs: &'static [NumRef]) -> NodeRow {
        NodeRow {
            id: Id::numeric(1, 1),
            browse_name: (1, "N"),
            display_name: "N",
            description: None,
            write_mask: 0,
            user_write_mask: 0,
            kind: Kind::Object { event_notifier: 0 },
            refs,
            nrefs,
        }
    }

    #[test]
    fn numeric_references_read_as_refs_in_their_order() {
        let r = row(&[], &[(0, 40, 0, 58, true), (2, 4002, 1, 1003, false)]);
        let got: Vec<Ref> = r.references().collect();
        assert_eq!(
            got,
            [
                Ref { reference_type: Id::ns0(40), target: Id::ns0(58), forward: true },
                Ref { reference_type: Id::numeric(2, 4002), target: Id::numeric(1, 1003), forward: false },
            ]
        );
    }

    /// Lines as the generator writes them, one per node class, with every kind of identifier and escape.
    const TEXT: &str = r#"
Object 1:5 1:"Cell \"A\" > 1#" "Zelle\tA" "line\nbreak \\ \u{1} ü" 3 4 1 0:47>1:s"a b>c" 0:40<0:58
ObjectType 1:g000102030405060708090a0b0c0d0e0f 0:"T" = ~ 0 0 1 0:45<0:58 0:47>1:6
Variable 1:b00ff 0:"V" = ~ 0 0 0:11 1 [2,3] 3 1 1 250.5 Array:11 { Double:NaN Double:-0 Double:inf Double:0.0000001 }
VariableType 1:7 1:"VT" = ~ 0 0 1:3001 -2 [] 1 LocalizedText:"en":"Hallo"
Method 1:8 1:"Start" = ~ 0 0 1 0 0:46>1:9
Variable 1:9 0:"InputArguments" = ~ 0 0 0:296 1 [0] 1 1 0 ~ Arguments:{ "Speed" 0:11 -1 [] "mm/s" "Axes" 1:s"Id" 1 [6] ~ }
ReferenceType 1:10 1:"Feeds" = ~ 0 0 0 1 "FedBy"
DataType 1:11 1:"Mode" = ~ 0 0 0 Enum { -1 "Off" = ~ 5 "On" "Running" "the axis moves" } 0:45<0:29
DataType 1:12 1:"Point" = ~ 0 0 0 StructureWithOptionalFields 0:22 1:13 { "X" ~ 0:11 -1 [] 0 0 "Label" "a name" 0:12 -1 [] 40 1 }
DataType 1:14 1:"Abstract" = ~ 0 0 1 ~
View 1:15 1:"Overview" = ~ 0 0 1 1
"#;

    #[test]
    fn packed_rows_decode_every_construct() {
        let rows = decode(TEXT).expect("the text decodes");
        assert_eq!(rows.len(), 11);
        let cell = &rows[0];
        assert_eq!(cell.id, Id::numeric(1, 5));
        assert_eq!(cell.browse_name, (1, "Cell \"A\" > 1#"));
        assert_eq!(cell.display_name, "Zelle\tA");
        assert_eq!(cell.description, Some("line\nbreak \\ \u{1} ü"));
        assert_eq!((cell.write_mask, cell.user_write_mask), (3, 4));
        assert!(matches!(cell.kind, Kind::Object { event_notifier: 1 }));
        // A string identifier among the references: all of the row's references are general ones.
        assert!(cell.nrefs.is_empty());
        assert_eq!(
            cell.refs,
            [
                Ref { reference_type: Id::ns0(47), target: Id { ns: 1, id: IdKind::String("a b>c") }, forward: true },
                Ref { reference_type: Id::ns0(40), target: Id::ns0(58), forward: false },
            ]
        );

        let t = &rows[1];
        let guid: [u8; 16] = std::array::from_fn(|i| i as u8);
        assert_eq!(t.id, Id { ns: 1, id: IdKind::Guid(guid) });
        assert_eq!((t.browse_name, t.display_name, t.description), ((0, "T"), "T", None));
        assert!(matches!(t.kind, Kind::ObjectType { is_abstract: true }));
        assert!(t.refs.is_empty());
        assert_eq!(t.nrefs, [(0, 45, 0, 58, false), (0, 47, 1, 6, true)]);

        let v = &rows[2];
        assert_eq!(v.id, Id { ns: 1, id: IdKind::Opaque(&[0x00, 0xff]) });
        let Kind::Variable {
            data_type,
            value_rank,
            array_dimensions,
            access_level,
            user_access_level,
            historizing,
            minimum_sampling_interval,
            value: Val::Array(11, items),
        } = v.kind
        else {
            panic!("a Variable with an array value: {:?}", v.kind)
        };
        assert_eq!((data_type, value_rank, array_dimensions), (Id::ns0(11), 1, &[2, 3][..]));
        assert_eq!((access_level, user_access_level, historizing, minimum_sampling_interval), (3, 1, true, Some(250.5)));
        let doubles: Vec<f64> = items
            .iter()
            .map(|i| match i {
                Val::Double(x) => *x,
                other => panic!("not a Double: {other:?}"),
            })
            .collect();
        assert!(doubles[0].is_nan());
        assert!(doubles[1] == 0.0 && doubles[1].is_sign_negative());
        assert_eq!(doubles[2..], [f64::INFINITY, 1e-7]);

        assert!(matches!(
            rows[3].kind,
            Kind::VariableType { data_type: Id { ns: 1, id: IdKind::Numeric(3001) }, value_rank: -2, is_abstract: true, value: Val::LocalizedText(Some("en"), "Hallo"), .. }
        ));
        assert!(matches!(rows[4].kind, Kind::Method { executable: true, user_executable: false }));
        let Kind::Variable { value: Val::Arguments(args), .. } = rows[5].kind else { panic!("arguments: {:?}", rows[5].kind) };
        assert_eq!(
            args,
            [
                ArgRow { name: "Speed", data_type: Id::ns0(11), value_rank: -1, array_dimensions: &[], description: Some("mm/s") },
                ArgRow {
                    name: "Axes",
                    data_type: Id { ns: 1, id: IdKind::String("Id") },
                    value_rank: 1,
                    array_dimensions: &[6],
                    description: None
                },
            ]
        );
        assert!(matches!(rows[6].kind, Kind::ReferenceType { symmetric: false, is_abstract: true, inverse_name: Some("FedBy") }));
        let Kind::DataType { is_abstract: false, definition: Some(Def::Enum { fields }) } = rows[7].kind else { panic!("{:?}", rows[7].kind) };
        assert_eq!(
            fields,
            [
                EnumRow { value: -1, name: "Off", display_name: "Off", description: None },
                EnumRow { value: 5, name: "On", display_name: "Running", description: Some("the axis moves") },
            ]
        );
        let Kind::DataType { definition: Some(Def::Structure { base, default_encoding, kind, fields }), .. } = rows[8].kind else {
            panic!("{:?}", rows[8].kind)
        };
        assert_eq!((base, default_encoding, kind), (Id::ns0(22), Some(Id::numeric(1, 13)), StructureKind::StructureWithOptionalFields));
        assert_eq!(fields.len(), 2);
        assert_eq!(
            fields[1],
            FieldRow {
                name: "Label",
                description: Some("a name"),
                data_type: Id::ns0(12),
                value_rank: -1,
                array_dimensions: &[],
                max_string_length: 40,
                is_optional: true
            }
        );
        assert!(matches!(rows[9].kind, Kind::DataType { is_abstract: true, definition: None }));
        assert!(matches!(rows[10].kind, Kind::View { event_notifier: 1, contains_no_loops: true }));
    }

    /// Every scalar value tag, each as a Variable's value.
    #[test]
    fn packed_values_of_every_tag() {
        let values = [
            "~",
            "Boolean:1",
            "SByte:-128",
            "Byte:255",
            "Int16:-32768",
            "UInt16:65535",
            "Int32:-2147483648",
            "UInt32:4294967295",
            "Int64:-9223372036854775808",
            "UInt64:18446744073709551615",
            "Float:1.5",
            "Double:-2.25",
            "String:\"\"",
            "DateTime:\"2025-11-15T00:00:00Z\"",
            "Guid:ffeeddccbbaa99887766554433221100",
            "ByteString:",
            "NodeId:2:s\"Pump\"",
            "ExpandedNodeId:0:85",
            "StatusCode:2147483648",
            "QualifiedName:1:\"Name\"",
            "LocalizedText:~:\"\"",
            "Array:21 { }",
            "EnumValues:{ 0 \"A\" = ~ }",
        ];
        let text: String =
            values.iter().enumerate().map(|(i, v)| format!("Variable 1:{i} 1:\"V\" = ~ 0 0 0:24 -1 [] 1 1 0 ~ {v}\n")).collect();
        let rows = decode(Box::leak(text.into_boxed_str())).expect("every value decodes");
        let got: Vec<String> = rows
            .iter()
            .map(|r| match r.kind {
                Kind::Variable { value, .. } => format!("{value:?}"),
                _ => unreachable!(),
            })
            .collect();
        assert_eq!(
            got,
            [
                "None",
                "Boolean(true)",
                "SByte(-128)",
                "Byte(255)",
                "Int16(-32768)",
                "UInt16(65535)",
                "Int32(-2147483648)",
                "UInt32(4294967295)",
                "Int64(-9223372036854775808)",
                "UInt64(18446744073709551615)",
                "Float(1.5)",
                "Double(-2.25)",
                "String(\"\")",
                "DateTime(\"2025-11-15T00:00:00Z\")",
                "Guid([255, 238, 221, 204, 187, 170, 153, 136, 119, 102, 85, 68, 51, 34, 17, 0])",
                "ByteString([])",
                "NodeId(Id { ns: 2, id: String(\"Pump\") })",
                "ExpandedNodeId(Id { ns: 0, id: Numeric(85) })",
                "StatusCode(2147483648)",
                "QualifiedName(1, \"Name\")",
                "LocalizedText(None, \"\")",
                "Array(21, [])",
                "EnumValues([EnumRow { value: 0, name: \"A\", display_name: \"A\", description: None }])",
            ]
        );
    }

    #[test]
    fn bad_packed_text_names_line_column_and_cause() {
        let cases: [(&'static str, (usize, usize, &str)); 8] = [
            ("Object 1:18446744073709551616 1:\"N\" = ~ 0 0 0", (1, 29, "number too large")),
            ("\nObject 1:5 1:\"N\" = ~ 0 0 x", (2, 26, "expected a number")),
            ("Object 1:5 1:\"N\" = ~ 0 0 300", (1, 26, "300 is out of range for an EventNotifier")),
            ("Thing 1:5 1:\"N\" = ~ 0 0 0", (1, 1, "unknown node class `Thing`")),
            ("Object 1:5 1:\"N", (1, 16, "unterminated string")),
            ("Object 1:5 1:\"N\\q\" = ~ 0 0 0", (1, 18, "unknown escape `\\q`")),
            ("Object 1:5 1:\"N\" = ~ 0 0 0 0:47=1:6", (1, 32, "expected `>` or `<` between a reference's type and target")),
            ("ObjectType 1:gabcd 0:\"T\" = ~ 0 0 1", (1, 19, "a GUID is 32 hex digits")),
        ];
        for (text, (line, column, message)) in cases {
            assert_eq!(decode(text).err(), Some((line, column, message.to_owned())), "{text:?}");
        }
    }

    static BROKEN: NodeSetTable = NodeSetTable {
        namespace_uri: "urn:broken",
        version: "",
        publication_date: "",
        namespaces: &["http://opcfoundation.org/UA/", "urn:broken"],
        own: 1,
        nodes: Nodes::Packed(Packed::new("Object 1:1 1:\"A\" = ~ 0 0 0\nObject 1:2")),
    };

    #[test]
    fn a_table_that_does_not_decode_says_where_every_time() {
        for _ in 0..2 {
            let e = BROKEN.rows().expect_err("line 2 is cut short");
            assert_eq!((e.namespace_uri, e.line, e.column), ("urn:broken", 2, 11));
            assert!(e.to_string().contains("urn:broken does not decode at line 2, column 11: expected ` `"), "{e}");
        }
    }

    #[test]
    fn general_references_come_through_unchanged() {
        const REFS: &[Ref] =
            &[Ref { reference_type: Id::ns0(47), target: Id { ns: 1, id: IdKind::String("Pump") }, forward: true }];
        assert_eq!(row(REFS, &[]).references().collect::<Vec<_>>(), REFS);
        assert_eq!(row(&[], &[]).references().count(), 0);
    }
}
