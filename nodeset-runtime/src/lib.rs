//! The hand-written runtime the generated namespaces need: static tables ([`table`]), NodeIds that carry
//! their namespace URI ([`NsNodeId`]), the mapping of table-local namespace indices to the server's, the
//! import of a table into an async-opcua address space ([`import`]), a server that serves tables
//! ([`server`]), typed handles, instances and skills over it ([`typed`]), sessions to other servers and the
//! client side of composite skills ([`remote`]) and typed clients of any instance ([`client`]).
//!
//! # Layers
//!
//! The modules are layers, listed here from the bottom: each module uses only the modules listed before it,
//! never one after it, and none uses the crate root, which only re-exports (`NsNodeId`, `NamespaceMap`, ...
//! are defined in [`table`]). When two layers need the same type, it belongs to the lower one. The test
//! `nodeset-compiler/tests/layout.rs` reads this table and the imports of every module, and fails on an
//! import against it or on any loop.
//!
//! | layer | what it holds |
//! |---|---|
//! | [`table`] | the static tables generated code fills, their NodeIds ([`Id`], [`NsNodeId`]) and the [`NamespaceMap`] of a table's namespaces to a server's |
//! | [`import`] | a table imported into an async-opcua address space |
//! | [`server`] | the node manager of the tables and its handle [`server::ModelManager`], method and write handlers, [`server::ServerConfig`], users, roles and the PKI folder, how a server runs and stops ([`server::running`]), DI's locking ([`server::locking`]) |
//! | [`typed`] | typed handles bound to a server's nodes, instantiation, programs and skills; it adds `bind` and `instantiate` to `ModelManager` (an `impl` block in the layer that owns the types) |
//! | [`remote`] | sessions to other servers ([`remote::ClientConfig`], [`remote::RemoteServer`]) and browse paths resolved on them |
//! | [`client`] | typed clients of instances on those servers, their programs, and the steps of composite skills |

#![cfg_attr(test, deny(warnings))]
#![deny(missing_docs)]

pub mod client;
pub mod import;
pub mod remote;
pub mod server;
pub mod table;
pub mod typed;

pub use table::{make_node_id, Id, IdKind, NamespaceMap, NsNodeId};
