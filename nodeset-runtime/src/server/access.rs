//! Roles and what they may do: the well-known roles of the base namespace, the permission bits of
//! `PermissionType` (Part 3, 8.55) and the [`AccessPolicy`] a server applies per session.
//!
//! A node's permissions for a session are the union of the permissions of the session's roles, taken from
//! the node's own entry in [`AccessPolicy::nodes`] if it has one, otherwise from [`AccessPolicy::default`].
//! The server turns them into the session's UserAccessLevel (Read, Write) and UserExecutable (Call), which
//! async-opcua checks before a read, a write or a call reaches the application: a write or call the
//! session's roles do not allow is answered with `BadUserAccessDenied`.

use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::str::FromStr;

use opcua::types::NodeId;

use super::ModelManager;
use crate::table::NodeSetTable;

/// A well-known role of the base namespace (Part 3, 4.9.2; Part 18).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Role {
    /// Every session, whoever it is; the only role of an anonymous session.
    Anonymous,
    /// Every session with a user name or a user certificate.
    AuthenticatedUser,
    /// Reads and watches.
    Observer,
    /// Runs the machine: writes set points, calls methods.
    Operator,
    /// Changes how the machine works.
    Engineer,
    /// Watches the operators.
    Supervisor,
    /// Configures the server.
    ConfigureAdmin,
    /// Configures security.
    SecurityAdmin,
}

impl Role {
    /// Every well-known role, in the order of their NodeIds' names.
    pub const ALL: [Role; 8] = [
        Role::Anonymous,
        Role::AuthenticatedUser,
        Role::Observer,
        Role::Operator,
        Role::Engineer,
        Role::Supervisor,
        Role::ConfigureAdmin,
        Role::SecurityAdmin,
    ];

    /// The role's BrowseName.
    pub fn name(self) -> &'static str {
        match self {
            Role::Anonymous => "Anonymous",
            Role::AuthenticatedUser => "AuthenticatedUser",
            Role::Observer => "Observer",
            Role::Operator => "Operator",
            Role::Engineer => "Engineer",
            Role::Supervisor => "Supervisor",
            Role::ConfigureAdmin => "ConfigureAdmin",
            Role::SecurityAdmin => "SecurityAdmin",
        }
    }

    /// The NodeId of the role's object in namespace 0 (`WellKnownRole_*`).
    pub fn node_id(self) -> NodeId {
        NodeId::new(
            0,
            match self {
                Role::Anonymous => 15644u32,
                Role::AuthenticatedUser => 15656,
                Role::Observer => 15668,
                Role::Operator => 15680,
                Role::Engineer => 16036,
                Role::Supervisor => 15692,
                Role::ConfigureAdmin => 15716,
                Role::SecurityAdmin => 15704,
            },
        )
    }

    /// The role whose object is `id`, if it is a well-known role.
    pub fn from_node_id(id: &NodeId) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.node_id() == *id)
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Role {
    type Err = String;

    fn from_str(s: &str) -> Result<Role, String> {
        Role::ALL.into_iter().find(|r| r.name() == s).ok_or_else(|| {
            let names: Vec<_> = Role::ALL.iter().map(|r| r.name()).collect();
            format!("unknown role `{s}` (the well-known roles are {})", names.join(", "))
        })
    }
}

/// A set of `PermissionType` bits (Part 3, 8.55); the constants name the ones the server evaluates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Permissions(pub u32);

impl Permissions {
    /// No permission.
    pub const NONE: Permissions = Permissions(0);
    /// Browse the node.
    pub const BROWSE: Permissions = Permissions(0x1);
    /// Read the node's value.
    pub const READ: Permissions = Permissions(0x20);
    /// Write the node's value.
    pub const WRITE: Permissions = Permissions(0x40);
    /// Receive the node's events.
    pub const RECEIVE_EVENTS: Permissions = Permissions(0x800);
    /// Call the method.
    pub const CALL: Permissions = Permissions(0x1000);

    /// Whether every bit of `other` is set.
    pub fn contains(self, other: Permissions) -> bool {
        self.0 & other.0 == other.0
    }
}

impl std::ops::BitOr for Permissions {
    type Output = Permissions;

    fn bitor(self, rhs: Permissions) -> Permissions {
        Permissions(self.0 | rhs.0)
    }
}

/// Which roles may do what: a default for every node, and the nodes that have their own RolePermissions.
///
/// The default ([`AccessPolicy::default`]) lets every role browse, read and receive events, and lets
/// Operator, Engineer, Supervisor and ConfigureAdmin also write and call methods. A node with an entry in
/// [`AccessPolicy::nodes`] follows that entry only: a role it does not name may do nothing there.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AccessPolicy {
    /// The permissions of each role on a node without an entry of its own; a role not named has none.
    pub default: BTreeMap<Role, Permissions>,
    /// The RolePermissions of single nodes (looked up only, never listed, so a hash map is deterministic).
    pub nodes: HashMap<NodeId, BTreeMap<Role, Permissions>>,
}

impl Default for AccessPolicy {
    fn default() -> AccessPolicy {
        let look = Permissions::BROWSE | Permissions::READ | Permissions::RECEIVE_EVENTS;
        let act = look | Permissions::WRITE | Permissions::CALL;
        let default = Role::ALL
            .into_iter()
            .map(|r| match r {
                Role::Operator | Role::Engineer | Role::Supervisor | Role::ConfigureAdmin => (r, act),
                _ => (r, look),
            })
            .collect();
        AccessPolicy { default, nodes: HashMap::new() }
    }
}

impl AccessPolicy {
    /// Gives `node` its own RolePermissions (replacing the default there).
    pub fn node(mut self, node: NodeId, permissions: impl IntoIterator<Item = (Role, Permissions)>) -> AccessPolicy {
        self.nodes.insert(node, permissions.into_iter().collect());
        self
    }

    /// What a session with `roles` may do on `node`.
    pub fn permissions(&self, roles: &[Role], node: &NodeId) -> Permissions {
        let table = self.nodes.get(node).unwrap_or(&self.default);
        roles.iter().filter_map(|r| table.get(r)).fold(Permissions::NONE, |a, &b| a | b)
    }
}

/// The RolePermissions the tables' nodesets give their nodes, as [`AccessPolicy::nodes`] entries with server
/// NodeIds, each with whether the node is a Variable (whose Value the Read permission guards; the attributes
/// of other nodes are guarded by Browse). A node entry names only the well-known roles: a role object of a nodeset is no role any session
/// has here, so it grants nothing. The nodes' AccessRestrictions are evaluated by the node manager, which
/// sees the session's security mode (see [`super::ModelNodes`]).
pub(crate) fn table_permissions(
    manager: &ModelManager,
    tables: &[&'static NodeSetTable],
) -> Result<Vec<(NodeId, BTreeMap<Role, Permissions>, bool)>, String> {
    let mut out = Vec::new();
    for table in tables {
        let rows = table.access().map_err(|e| e.to_string())?;
        let variables: std::collections::HashSet<crate::table::Id> = table
            .rows()
            .map_err(|e| e.to_string())?
            .iter()
            .filter(|r| matches!(r.kind, crate::table::Kind::Variable { .. }))
            .map(|r| r.id)
            .collect();
        let Some(map) = manager.namespace_map(table.namespace_uri) else { continue };
        for row in rows.iter().filter(|r| !r.roles.is_empty()) {
            let Some(node) = map.try_id(row.id) else { continue };
            let mut permissions: BTreeMap<Role, Permissions> = BTreeMap::new();
            for &(role, bits) in &row.roles {
                match map.try_id(role).as_ref().and_then(Role::from_node_id) {
                    Some(role) => {
                        let p = permissions.entry(role).or_default();
                        *p = *p | Permissions(bits);
                    }
                    None => tracing::warn!("{node}: RolePermissions name {role:?}, which is not a well-known role; it grants nothing"),
                }
            }
            out.push((node, permissions, variables.contains(&row.id)));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn role_names_round_trip_and_unknown_names_are_refused() {
        for r in Role::ALL {
            assert_eq!(r.name().parse::<Role>(), Ok(r));
            assert_eq!(Role::from_node_id(&r.node_id()), Some(r));
        }
        let e = "Admin".parse::<Role>().unwrap_err();
        assert!(e.contains("unknown role `Admin`") && e.contains("SecurityAdmin"), "{e}");
    }

    #[test]
    fn default_lets_anyone_read_and_operators_write_and_call() {
        let p = AccessPolicy::default();
        let node = NodeId::new(2, 7u32);
        let anonymous = p.permissions(&[Role::Anonymous], &node);
        assert!(anonymous.contains(Permissions::READ) && anonymous.contains(Permissions::BROWSE));
        assert!(!anonymous.contains(Permissions::WRITE) && !anonymous.contains(Permissions::CALL));
        let operator = p.permissions(&[Role::AuthenticatedUser, Role::Operator], &node);
        assert!(operator.contains(Permissions::WRITE | Permissions::CALL));
        let observer = p.permissions(&[Role::AuthenticatedUser, Role::Observer], &node);
        assert!(!observer.contains(Permissions::WRITE));
    }

    #[test]
    fn a_node_entry_replaces_the_default() {
        let node = NodeId::new(2, 7u32);
        let p = AccessPolicy::default().node(node.clone(), [(Role::Engineer, Permissions::READ | Permissions::WRITE)]);
        assert_eq!(p.permissions(&[Role::Operator], &node), Permissions::NONE);
        assert!(p.permissions(&[Role::Engineer], &node).contains(Permissions::WRITE));
        assert!(p.permissions(&[Role::Operator], &NodeId::new(2, 8u32)).contains(Permissions::WRITE));
    }
}
