//! The hand-written runtime the generated namespaces need: static tables ([`table`]), NodeIds that carry
//! their namespace URI ([`NsNodeId`]), and the mapping of table-local namespace indices to the server's.

pub mod table;

use opcua::types::NodeId;
pub use table::{Id, IdKind};

/// A NodeId as generated code names it: the namespace by URI, resolved against a server's or client's
/// namespace table at run time (generated code never hard-codes a namespace index).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NsNodeId {
    pub namespace_uri: &'static str,
    pub id: IdKind,
}

impl NsNodeId {
    pub const fn numeric(namespace_uri: &'static str, n: u32) -> NsNodeId {
        NsNodeId { namespace_uri, id: IdKind::Numeric(n) }
    }

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
    /// Server index of each table-local index.
    pub indices: Vec<u16>,
}

impl NamespaceMap {
    /// The server NodeId of a table NodeId.
    pub fn id(&self, id: Id) -> NodeId {
        let ns = self.indices.get(id.ns as usize).copied().unwrap_or(id.ns);
        make_node_id(ns, id.id)
    }

    /// The server namespace index of a table-local index.
    pub fn index(&self, local: u16) -> u16 {
        self.indices.get(local as usize).copied().unwrap_or(local)
    }
}
