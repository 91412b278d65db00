//! The instance rules: every instance against its type's instance declarations, on a live server
//! (`nodeset-compiler verify`) or in the files themselves (`nodeset-compiler check`), by one checker.
//!
//! The work is split so that the rules need no network (and no async-opcua: only `client` and `driver`
//! need the feature `verify`; `check` applies the rules in every build):
//!
//! ```text
//! client    (feature `verify`) a session to the server -> Snapshot: the NamespaceArray and every node
//!           below the Objects folder outside namespace 0, with its forward references and, for variables,
//!           DataType, ValueRank and the built-in type of the value; read in batches (Browse, BrowseNext and
//!           Read with many nodes per request), so the round trips grow with the depth of the address space
//!           and the number of nodes divided by the server's per-request limits, not with the node count
//! instances &Model -> Snapshot: the same, made from the static instances of the loaded files (what a
//!           server serving them shows), for `check`
//! check     (&Model, &Snapshot) -> Report: every instance against its type's instance declarations
//! report    Report -> rustc-style text (the violated declaration's place in its NodeSet2 file) or JSON
//! driver    (feature `verify`) verify from end to end: read the server, load its nodesets, check
//! ```
//!
//! What [`check::check`] verifies, each with its own diagnostic code (`NS0401`...`NS0409`, see
//! [`crate::diag::Code`]): mandatory members present with the declared BrowseName; NodeClass as declared;
//! TypeDefinition the declared one or a subtype; DataType the declared one or a subtype; ValueRank
//! compatible; the value's built-in type the one its DataType is encoded as, and its shape (scalar or array)
//! the one its ValueRank allows; children in a placeholder's place of the placeholder's type; mandatory
//! placeholders filled; no ModellingRule on instances.
//!
//! Limits: only nodes outside namespace 0 are checked (namespace 0 is the server stack's own). On a
//! server, only those reached by forward hierarchical references from the Objects folder; in the files,
//! every static instance ([`instances`]). A node whose type is in a namespace no loaded nodeset defines is
//! reported (`NS0409`, an error that `--warn NS0409` demotes) and its children are checked against their
//! own types.

pub mod check;
#[cfg(feature = "verify")]
pub mod client;
#[cfg(feature = "verify")]
pub mod driver;
pub mod instances;
pub mod report;
#[cfg(feature = "verify")]
pub mod structures;

use crate::nodeid::{NodeId, QualifiedName};
use crate::raw::NodeClass;
use crate::value::BuiltinType;
use std::collections::BTreeMap;

/// What was read of one server node. NodeIds and BrowseNames carry the *server's* namespace indices
/// (see [`Snapshot::namespaces`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RemoteNode {
    /// The node's NodeId.
    pub id: NodeId,
    /// The node's NodeClass.
    pub class: NodeClass,
    /// The node's BrowseName.
    pub browse_name: QualifiedName,
    /// Forward references of every type, in the order the server returned them.
    pub references: Vec<RemoteReference>,
    /// Variables only: the DataType attribute, if it could be read.
    pub data_type: Option<NodeId>,
    /// Variables only: the ValueRank attribute, if it could be read.
    pub value_rank: Option<i32>,
    /// Variables only: the value, if it could be read.
    pub value: Option<RemoteValue>,
    /// Variables read from a server: each ExtensionObject of the value (the value itself, or the items of
    /// an array) in OPC UA binary as the server sent it, for [`structures`] to compare with the nodesets;
    /// empty if the value holds none, `None` if the node was not read from a server.
    pub extension_objects: Option<Vec<Vec<u8>>>,
}

/// A forward reference of a [`RemoteNode`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RemoteReference {
    /// The NodeId of the reference's type.
    pub reference_type: NodeId,
    /// The node the reference points to.
    pub target: NodeId,
}

/// The shape of a value read from the server: enough to compare with a DataType and a ValueRank.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RemoteValue {
    /// A null value (an empty Variant).
    Empty,
    /// A scalar of this built-in type.
    Scalar(BuiltinType),
    /// An array with elements of this built-in type.
    Array(BuiltinType),
}

/// Everything [`check::check`] needs from a server, read once.
#[derive(Clone, Debug, Default)]
pub struct Snapshot {
    /// The server's NamespaceArray.
    pub namespaces: Vec<String>,
    /// Every node read, by NodeId; the Objects folder (`i=85`) among them.
    pub nodes: BTreeMap<NodeId, RemoteNode>,
    /// Service requests sent to read it (Read, Browse, BrowseNext).
    pub round_trips: u32,
}

impl Snapshot {
    /// The server's Objects folder.
    pub fn objects_folder() -> NodeId {
        NodeId::numeric(0, 85)
    }
}

impl RemoteNode {
    /// The Objects folder with no references yet: where a snapshot's walk starts when nothing else
    /// describes the folder.
    pub fn empty_objects_folder() -> RemoteNode {
        RemoteNode {
            id: Snapshot::objects_folder(),
            class: NodeClass::Object,
            browse_name: QualifiedName { ns: 0, name: "Objects".into() },
            references: Vec::new(),
            data_type: None,
            value_rank: None,
            value: None,
            extension_objects: None,
        }
    }
}
