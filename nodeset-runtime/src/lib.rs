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

pub use table::{make_node_id, Id, IdKind, NamespaceMap, NsNodeId};
