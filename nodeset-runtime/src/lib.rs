//! The hand-written runtime the generated namespaces need: static tables ([`table`]), NodeIds that carry
//! their namespace URI ([`NsNodeId`]), the mapping of table-local namespace indices to the server's, the
//! import of a table into an async-opcua address space ([`import`]), a server that serves tables
//! ([`server`]), the client side of composite skills ([`remote`]) and typed clients of any instance ([`client`]).

#![cfg_attr(test, deny(warnings))]
#![deny(missing_docs)]

pub mod client;
pub mod import;
pub mod remote;
pub mod server;
pub mod table;
pub mod typed;

use opcua::types::NodeId;
pub use table::{Id, IdKind};

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
        self.indices.get(local as usize).copied().filter(|&i| i != import::UNMAPPED)
    }
}
