//! The table of DI's locks a server holds, and the check every write and call passes through: which
//! element each Lock object locks, and which client application holds which element. Their behaviour
//! (the Lock methods, what the Lock object shows, the expiry) is [`super::locking`].

use std::collections::{HashMap, HashSet};
use std::time::Instant;

use opcua::nodes::TypeTree;
use opcua::server::address_space::AddressSpace;
use opcua::sync::RwLock;
use opcua::types::{BrowseDirection, NodeId, ReferenceTypeId, StatusCode};

/// The locks of one server: which element each Lock object locks, and who holds which element.
#[derive(Default)]
pub(super) struct Locks {
    /// Lock object -> lock-owner.
    pub(super) owners: RwLock<HashMap<NodeId, NodeId>>,
    /// Lock-owner -> the holder.
    pub(super) held: RwLock<HashMap<NodeId, Held>>,
}

#[derive(Clone)]
pub(super) struct Held {
    pub(super) client: String,
    pub(super) last: Instant,
}

impl Locks {
    /// Whether `client` may change `node` (write it, or call a method on it): `BadLocked` when `node` or an
    /// object above it is locked by another application. A request of the holder on its element renews
    /// the lock. The lock's own methods (`object` a Lock object) are always let through to their handlers.
    pub(super) fn check(
        &self,
        space: &AddressSpace,
        tree: &dyn TypeTree,
        node: &NodeId,
        object: Option<&NodeId>,
        client: &str,
    ) -> Result<(), StatusCode> {
        if self.held.read().is_empty() || object.is_some_and(|o| self.owners.read().contains_key(o)) {
            return Ok(());
        }
        let mut seen = HashSet::new();
        let mut open = vec![node.clone()];
        while let Some(at) = open.pop() {
            if !seen.insert(at.clone()) || seen.len() > 10_000 {
                continue;
            }
            if let Some(held) = self.held.write().get_mut(&at) {
                if held.client != client {
                    return Err(StatusCode::BadLocked);
                }
                held.last = Instant::now();
            }
            let parents = space.find_references(
                &at,
                Some((ReferenceTypeId::HierarchicalReferences, true)),
                tree,
                BrowseDirection::Inverse,
            );
            open.extend(parents.map(|r| r.target_node.clone()));
        }
        Ok(())
    }

    pub(super) fn holder(&self, owner: &NodeId) -> Option<Held> {
        self.held.read().get(owner).cloned()
    }
}

