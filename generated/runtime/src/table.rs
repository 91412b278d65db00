//! The static tables generated code fills: one [`NodeSetTable`] per namespace.
//!
//! Everything here is `const`-constructible, so a generated namespace is data the compiler barely looks at,
//! not one function per node. NodeIds in a table use table-local namespace indices (an index into
//! [`NodeSetTable::namespaces`]); they are mapped to the server's indices when the table is imported, so no
//! generated code ever hard-codes a server namespace index.

/// The identifier part of a NodeId in a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IdKind {
    Numeric(u32),
    String(&'static str),
    Guid([u8; 16]),
    Opaque(&'static [u8]),
}

/// A NodeId with a table-local namespace index (0 is always the OPC UA namespace).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Id {
    pub ns: u16,
    pub id: IdKind,
}

impl Id {
    pub const fn ns0(n: u32) -> Id {
        Id { ns: 0, id: IdKind::Numeric(n) }
    }

    pub const fn numeric(ns: u16, n: u32) -> Id {
        Id { ns, id: IdKind::Numeric(n) }
    }
}

/// A reference from the row's node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ref {
    pub reference_type: Id,
    pub target: Id,
    pub forward: bool,
}

/// A reference whose type and target have numeric identifiers (nearly all of a nodeset's): reference type
/// namespace and number, target namespace and number, forward. A tuple of literals, because a row is data
/// the compiler checks expression by expression: this is 6 expressions where a [`Ref`] with its two
/// [`Id`]s is 11.
pub type NumRef = (u16, u32, u16, u32, bool);

/// A field of a structure's DataTypeDefinition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldRow {
    pub name: &'static str,
    pub description: Option<&'static str>,
    pub data_type: Id,
    pub value_rank: i32,
    pub array_dimensions: &'static [u32],
    pub max_string_length: u32,
    pub is_optional: bool,
}

/// A field of an enumeration's (or OptionSet's) DataTypeDefinition; also an EnumValues entry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnumRow {
    pub value: i64,
    pub name: &'static str,
    pub display_name: &'static str,
    pub description: Option<&'static str>,
}

/// StructureType of OPC UA Part 3.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StructureKind {
    Structure,
    StructureWithOptionalFields,
    Union,
}

/// A DataTypeDefinition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Def {
    Structure { base: Id, default_encoding: Option<Id>, kind: StructureKind, fields: &'static [FieldRow] },
    Enum { fields: &'static [EnumRow] },
}

/// An Argument of a method's InputArguments or OutputArguments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArgRow {
    pub name: &'static str,
    pub data_type: Id,
    pub value_rank: i32,
    pub array_dimensions: &'static [u32],
    pub description: Option<&'static str>,
}

/// A node's initial value.
#[derive(Clone, Copy, Debug)]
pub enum Val {
    None,
    Boolean(bool),
    SByte(i8),
    Byte(u8),
    Int16(i16),
    UInt16(u16),
    Int32(i32),
    UInt32(u32),
    Int64(i64),
    UInt64(u64),
    Float(f32),
    Double(f64),
    String(&'static str),
    /// ISO 8601 text as written in the nodeset.
    DateTime(&'static str),
    Guid([u8; 16]),
    ByteString(&'static [u8]),
    NodeId(Id),
    ExpandedNodeId(Id),
    StatusCode(u32),
    QualifiedName(u16, &'static str),
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
    Object {
        event_notifier: u8,
    },
    ObjectType {
        is_abstract: bool,
    },
    Variable {
        data_type: Id,
        value_rank: i32,
        array_dimensions: &'static [u32],
        access_level: u8,
        user_access_level: u8,
        historizing: bool,
        minimum_sampling_interval: Option<f64>,
        value: Val,
    },
    VariableType {
        data_type: Id,
        value_rank: i32,
        array_dimensions: &'static [u32],
        is_abstract: bool,
        value: Val,
    },
    Method {
        executable: bool,
        user_executable: bool,
    },
    ReferenceType {
        symmetric: bool,
        is_abstract: bool,
        inverse_name: Option<&'static str>,
    },
    DataType {
        is_abstract: bool,
        definition: Option<Def>,
    },
    View {
        event_notifier: u8,
        contains_no_loops: bool,
    },
}

/// One node.
#[derive(Clone, Copy, Debug)]
pub struct NodeRow {
    pub id: Id,
    /// BrowseName: table-local namespace index and name.
    pub browse_name: (u16, &'static str),
    pub display_name: &'static str,
    pub description: Option<&'static str>,
    pub write_mask: u32,
    pub user_write_mask: u32,
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
        self.refs.iter().copied().chain(self.nrefs.iter().map(|&(rns, rid, tns, tid, forward)| Ref {
            reference_type: Id::numeric(rns, rid),
            target: Id::numeric(tns, tid),
            forward,
        }))
    }
}

/// A namespace's address space.
#[derive(Debug)]
pub struct NodeSetTable {
    /// The namespace this table defines.
    pub namespace_uri: &'static str,
    /// The model's version and publication date, from the nodeset.
    pub version: &'static str,
    pub publication_date: &'static str,
    /// Table-local namespace index to URI; index 0 is `http://opcfoundation.org/UA/`.
    pub namespaces: &'static [&'static str],
    /// The index of `namespace_uri` in `namespaces`.
    pub own: u16,
    pub nodes: &'static [NodeRow],
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn general_references_come_through_unchanged() {
        const REFS: &[Ref] =
            &[Ref { reference_type: Id::ns0(47), target: Id { ns: 1, id: IdKind::String("Pump") }, forward: true }];
        assert_eq!(row(REFS, &[]).references().collect::<Vec<_>>(), REFS);
        assert_eq!(row(&[], &[]).references().count(), 0);
    }
}
