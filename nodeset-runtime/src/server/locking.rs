//! DI's locking (OPC 10000-100 §7, LockingServicesType) served for any Lock object of the address space.
//!
//! [`ModelManager::serve_lock`] gives one Lock object its behaviour; [`ModelManager::serve_locks`] does it
//! for every instance of LockingServicesType (or a subtype) the server holds. The lock-owner is the object
//! the Lock belongs to (the source of its HasComponent or HasAddIn reference); a Lock that only a folder
//! organizes locks itself. While an application holds the lock:
//!
//! - `InitLock(Context)` answers 0 (OK) when the element was free, -1 (E_AlreadyLocked) otherwise, and
//!   refuses an empty Context with `BadInvalidArgument` (DI leaves it open; this server wants the client to
//!   say what it locks for);
//!   `RenewLock`, `ExitLock` answer 0, or -1 (E_NotLocked) when nobody holds the lock, and `BadLocked` for
//!   another application than the holder (the spec allows only the initiator); `BreakLock` ends anyone's
//!   lock (who may call it is the model's RolePermissions, as for every method);
//! - writes and method calls of other applications on the lock-owner and every node below it are refused
//!   with `BadLocked`; reads, browsing and subscriptions stay open (DI's default, non-exclusive lock);
//! - `Locked`, `LockingClient` (the holder's ApplicationUri), `LockingUser` and `RemainingLockTime` show it;
//! - the lock ends after [`MAX_INACTIVE_LOCK_TIME`] without a request of the holder on the element
//!   (RenewLock, or a write or call below the owner, renews it); DI's MaxInactiveLockTime property of
//!   ServerCapabilities shows that time.
//!
//! The application is the ApplicationUri a client gave when it created its session.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use opcua::nodes::NodeType;
use opcua::types::{BrowseDirection, NodeId, ReferenceTypeId, StatusCode, Variant};

use super::locks::{Held, Locks};
use super::manager::{MethodError, MethodInvocation, ModelManager};

/// DI's namespace URI, the namespace of the Lock object's members.
const DI: &str = "http://opcfoundation.org/UA/DI/";
/// DI's LockingServicesType (`ns=DI;i=6388`).
const LOCKING_SERVICES_TYPE: u32 = 6388;
/// DI's MaxInactiveLockTime property of ServerCapabilities (`ns=DI;i=6387`).
const MAX_INACTIVE_LOCK_TIME_PROPERTY: u32 = 6387;
/// ns0's HasAddIn.
const HAS_ADD_IN: u32 = 17604;

/// How long a lock lasts without a request of its holder (DI's MaxInactiveLockTime of this server).
pub const MAX_INACTIVE_LOCK_TIME: Duration = Duration::from_secs(60);

/// DI's status results of the lock methods.
const OK: i32 = 0;
const E_ALREADY_LOCKED: i32 = -1;
const E_NOT_LOCKED: i32 = -1;

/// The members of one Lock object that show its state.
#[derive(Clone)]
struct Shown {
    manager: ModelManager,
    owner: NodeId,
    locked: Option<NodeId>,
    client: Option<NodeId>,
    user: Option<NodeId>,
    remaining: Option<NodeId>,
}

impl Shown {
    /// Shows the holder `(ApplicationUri, user)` of the lock, or no lock, and the time left.
    fn show(&self, holder: Option<(&str, &str)>, remaining: Duration) {
        let (client, user) = holder.unwrap_or(("", ""));
        let set = |node: &Option<NodeId>, value: Variant| {
            if let Some(node) = node {
                if let Err(s) = self.manager.set_value(node, value) {
                    tracing::warn!("cannot show the lock state in {node}: {s}");
                }
            }
        };
        set(&self.locked, holder.is_some().into());
        set(&self.client, client.into());
        set(&self.user, user.into());
        set(&self.remaining, (remaining.as_secs_f64() * 1000.0).into());
    }

    fn locks(&self) -> &Locks {
        &self.manager.nodes().locks
    }

    /// Takes the lock for the caller; DI's InitLockStatus.
    fn init(&self, call: &MethodInvocation) -> Result<i32, MethodError> {
        if matches!(call.arguments.first(), Some(Variant::String(c)) if c.is_empty() || c.is_null()) {
            return Err(MethodError::Status(StatusCode::BadInvalidArgument));
        }
        {
            let mut held = self.locks().held.write();
            if held.contains_key(&self.owner) {
                return Ok(E_ALREADY_LOCKED);
            }
            held.insert(self.owner.clone(), Held { client: call.client.clone(), last: Instant::now() });
        }
        self.show(Some((&call.client, call.user.as_deref().unwrap_or(""))), MAX_INACTIVE_LOCK_TIME);
        Ok(OK)
    }

    /// RenewLock (`release` false) or ExitLock (`release` true) of the caller's lock.
    fn holders_own(&self, call: &MethodInvocation, release: bool) -> Result<i32, MethodError> {
        let mut held = self.locks().held.write();
        let Some(h) = held.get_mut(&self.owner) else {
            return Ok(E_NOT_LOCKED);
        };
        if h.client != call.client {
            return Err(MethodError::Status(StatusCode::BadLocked));
        }
        if release {
            held.remove(&self.owner);
            drop(held);
            self.show(None, Duration::ZERO);
        } else {
            h.last = Instant::now();
            drop(held);
            self.show(Some((&call.client, call.user.as_deref().unwrap_or(""))), MAX_INACTIVE_LOCK_TIME);
        }
        Ok(OK)
    }

    /// BreakLock: ends whoever's lock.
    fn break_lock(&self) -> i32 {
        if self.locks().held.write().remove(&self.owner).is_none() {
            return E_NOT_LOCKED;
        }
        self.show(None, Duration::ZERO);
        OK
    }

    /// Ends the lock once its holder has been inactive for [`MAX_INACTIVE_LOCK_TIME`], and keeps
    /// RemainingLockTime current (each second).
    async fn expire(self) {
        let mut tick = tokio::time::interval(Duration::from_secs(1));
        loop {
            tick.tick().await;
            let Some(held) = self.locks().holder(&self.owner) else {
                continue;
            };
            let left = MAX_INACTIVE_LOCK_TIME.saturating_sub(held.last.elapsed());
            if !left.is_zero() {
                if let Some(remaining) = &self.remaining {
                    let _ = self.manager.set_value(remaining, left.as_secs_f64() * 1000.0);
                }
                continue;
            }
            let mut all = self.locks().held.write();
            // Unless the holder renewed it meanwhile.
            if all.get(&self.owner).is_some_and(|h| h.last == held.last) {
                all.remove(&self.owner);
                drop(all);
                self.show(None, Duration::ZERO);
            }
        }
    }
}

impl ModelManager {
    /// Gives the Lock object `lock` (an instance of DI's LockingServicesType) its behaviour: InitLock,
    /// RenewLock, ExitLock and BreakLock as DI defines them, the lock shown in Locked, LockingClient,
    /// LockingUser and RemainingLockTime, and changes by other applications below the lock-owner refused
    /// with `BadLocked` (see [`super::locking`]). Members the object lacks are left out. Must run inside a
    /// tokio runtime (the lock's expiry is a task).
    pub fn serve_lock(&self, lock: &NodeId) -> Result<(), String> {
        let runtime = tokio::runtime::Handle::try_current()
            .map_err(|_| format!("serve_lock({lock}) must be called inside a tokio runtime (the lock's expiry is a task)"))?;
        let (owner, members) = {
            let space = self.node_manager().address_space().read();
            let tree = self.type_tree().read();
            if space.find(lock).is_none() {
                return Err(format!("{lock} is not a node of the server"));
            }
            let di = self.namespace_index(DI).ok_or("the server has no DI namespace")?;
            let owner = space
                .find_references(lock, Some((ReferenceTypeId::HasComponent, true)), &*tree, BrowseDirection::Inverse)
                .chain(space.find_references(lock, Some((NodeId::new(0, HAS_ADD_IN), true)), &*tree, BrowseDirection::Inverse))
                .map(|r| r.target_node.clone())
                .next()
                .unwrap_or_else(|| lock.clone());
            // By any forward reference: before the server runs, the type tree does not know yet which of
            // ns0's reference types are hierarchical.
            let member = |name: &str| {
                space
                    .find_references(lock, None::<(NodeId, bool)>, &*tree, BrowseDirection::Forward)
                    .map(|r| r.target_node.clone())
                    .find(|id| space.find(id).is_some_and(|n| {
                        let b = n.as_node().browse_name();
                        b.namespace_index == di && b.name.as_ref() == name
                    }))
            };
            let members: HashMap<&str, Option<NodeId>> = [
                "Locked", "LockingClient", "LockingUser", "RemainingLockTime", "InitLock", "RenewLock", "ExitLock",
                "BreakLock",
            ]
            .into_iter()
            .map(|n| (n, member(n)))
            .collect();
            (owner, members)
        };
        self.nodes().locks.owners.write().insert(lock.clone(), owner.clone());
        // DI 7.4: the server's MaxInactiveLockTime (ms) on ServerCapabilities, where DI's nodeset gives it.
        if let Some(property) = self.resolve(crate::table::NsNodeId::numeric(DI, MAX_INACTIVE_LOCK_TIME_PROPERTY)) {
            self.set_value(&property, MAX_INACTIVE_LOCK_TIME.as_secs_f64() * 1000.0)
                .map_err(|s| format!("cannot set DI's MaxInactiveLockTime: {s}"))?;
        }
        let shown = Shown {
            manager: self.clone(),
            owner,
            locked: members["Locked"].clone(),
            client: members["LockingClient"].clone(),
            user: members["LockingUser"].clone(),
            remaining: members["RemainingLockTime"].clone(),
        };
        shown.show(None, Duration::ZERO);
        if let Some(m) = &members["InitLock"] {
            let s = shown.clone();
            self.on_call(m, move |call: MethodInvocation| {
                let status = s.init(&call);
                async move { status.map(|s| vec![Variant::Int32(s)]) }
            });
        }
        for (name, release) in [("RenewLock", false), ("ExitLock", true)] {
            if let Some(m) = &members[name] {
                let s = shown.clone();
                self.on_call(m, move |call: MethodInvocation| {
                    let status = s.holders_own(&call, release);
                    async move { status.map(|s| vec![Variant::Int32(s)]) }
                });
            }
        }
        if let Some(m) = &members["BreakLock"] {
            let s = shown.clone();
            self.on_call(m, move |_call: MethodInvocation| {
                let status = s.break_lock();
                async move { Ok(vec![Variant::Int32(status)]) }
            });
        }
        runtime.spawn(shown.expire());
        Ok(())
    }

    /// [`ModelManager::serve_lock`] for every instance of DI's LockingServicesType or a subtype; how many.
    /// None without a DI namespace.
    pub fn serve_locks(&self) -> Result<usize, String> {
        let Some(di) = self.namespace_index(DI) else {
            return Ok(0);
        };
        let lock_type = NodeId::new(di, LOCKING_SERVICES_TYPE);
        let locks: Vec<NodeId> = {
            let space = self.node_manager().address_space().read();
            let tree = self.type_tree().read();
            let mut types = vec![lock_type];
            let mut i = 0;
            while i < types.len() {
                let subtypes: Vec<NodeId> = space
                    .find_references(&types[i], Some((ReferenceTypeId::HasSubtype, false)), &*tree, BrowseDirection::Forward)
                    .map(|r| r.target_node.clone())
                    .collect();
                types.extend(subtypes);
                i += 1;
            }
            let mut found: Vec<NodeId> = types
                .iter()
                .flat_map(|t| {
                    space
                        .find_references(t, Some((ReferenceTypeId::HasTypeDefinition, false)), &*tree, BrowseDirection::Inverse)
                        .map(|r| r.target_node.clone())
                        .collect::<Vec<_>>()
                })
                // Objects, not the InstanceDeclarations of types (which have a ModellingRule).
                .filter(|id| matches!(space.find(id), Some(NodeType::Object(_))))
                .filter(|id| {
                    space
                        .find_references(id, Some((ReferenceTypeId::HasModellingRule, false)), &*tree, BrowseDirection::Forward)
                        .next()
                        .is_none()
                })
                .collect();
            found.sort_by_key(|id| id.to_string());
            found.dedup();
            found
        };
        for lock in &locks {
            self.serve_lock(lock)?;
        }
        Ok(locks.len())
    }
}
