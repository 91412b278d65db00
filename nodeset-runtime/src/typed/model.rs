//! The run-time half of `#[derive(ObjectModel)]`: a user struct bound to a generated ObjectType.
//!
//! [`Bound::instantiate`] creates an instance of the ObjectType from a value of the struct (Optional
//! members that fields bind are created too), [`Bound::update`] changes the struct and publishes the fields
//! whose values changed (subscriptions see them), and client writes of writable variables land in the
//! struct, typed, before they are stored.

use std::sync::{Arc, Mutex};

pub use opcua::types::Variant;
use opcua::nodes::{AccessLevel, NodeType};
use opcua::types::{NodeId, QualifiedName, StatusCode};

use super::{BindError, Binder, Instantiate, InstantiateError, MemberPath, ObjectType};
use crate::server::ModelManager;

/// One field of a derived struct and the variable it binds.
#[derive(Clone, Copy, Debug)]
pub struct FieldBinding {
    /// The field's name.
    pub field: &'static str,
    /// The browse path as written (`ParameterSet/SpeedOverride`).
    pub path: &'static str,
    /// The browse path with namespace URIs (the marker's).
    pub browse_path: MemberPath,
    /// Whether clients may write the variable.
    pub writable: bool,
}

/// A struct bound to an ObjectType; implemented by `#[derive(ObjectModel)]`.
pub trait ObjectModel: Send + 'static {
    /// The generated ObjectType handle.
    type ObjectType: ObjectType;
    /// The bound fields, in declaration order.
    const FIELDS: &'static [FieldBinding];
    /// The fields' values, in the order of `FIELDS`.
    fn to_variants(&self) -> Vec<Variant>;
    /// Stores a client's value into field `index`; false if it does not convert.
    fn apply(&mut self, index: usize, value: &Variant) -> bool;
}

/// Whether `list` contains `s` (usable in constants: the derive checks required members with it).
pub const fn contains(list: &[&str], s: &str) -> bool {
    let mut i = 0;
    while i < list.len() {
        let a = list[i].as_bytes();
        let b = s.as_bytes();
        if a.len() == b.len() {
            let mut j = 0;
            while j < a.len() && a[j] == b[j] {
                j += 1;
            }
            if j == a.len() {
                return true;
            }
        }
        i += 1;
    }
    false
}

struct Shared<S> {
    value: S,
    /// What was last published per field.
    published: Vec<Option<Variant>>,
}

/// A struct bound to an instance of its ObjectType.
pub struct Bound<S: ObjectModel> {
    shared: Arc<Mutex<Shared<S>>>,
    nodes: Vec<NodeId>,
    root: NodeId,
    manager: ModelManager,
}

impl<S: ObjectModel> Bound<S> {
    /// Creates an instance named `name` under `parent` (with `options`, plus the Optional members the fields
    /// bind), publishes every field, and routes client writes of writable fields into the struct.
    pub fn instantiate(
        manager: &ModelManager,
        parent: &NodeId,
        name: &str,
        options: Instantiate,
        value: S,
    ) -> Result<Bound<S>, InstantiateError> {
        let mut options = options;
        for f in S::FIELDS {
            let segments: Vec<&str> = f.path.split('/').collect();
            for end in 1..=segments.len() {
                options = options.ensure(segments[..end].join("/"));
            }
        }
        let type_id = manager.resolve(<S::ObjectType as ObjectType>::TYPE_ID).ok_or_else(|| {
            InstantiateError::Bind(BindError::UnknownNamespace(<S::ObjectType as ObjectType>::TYPE_ID.namespace_uri.to_owned()))
        })?;
        let root = manager.instantiate(&type_id, parent, QualifiedName::new(manager.instance_namespace(), name), &options)?;
        Ok(Bound::bind(manager, &root, value)?)
    }

    /// Binds the struct to an existing instance (one from a nodeset, say), publishes every field and routes
    /// client writes into the struct: writes of the variables the nodeset declares writable, and of those
    /// the instance was granted CurrentWrite before binding (DI's AssetId, which the nodesets declare
    /// CurrentRead although DI makes it user writable, is one).
    pub fn bind(manager: &ModelManager, root: &NodeId, value: S) -> Result<Bound<S>, BindError> {
        let nodes = manager.bind_with(|b: &Binder<'_>| {
            S::FIELDS
                .iter()
                .map(|f| {
                    let mut node = root.clone();
                    for (uri, name) in f.browse_path.segments()? {
                        node = b.find_child(&node, uri, &name)?.ok_or_else(|| BindError::MissingChild {
                            parent: node.clone(),
                            browse_name: name,
                        })?;
                    }
                    Ok(node)
                })
                .collect::<Result<Vec<_>, BindError>>()
        })?;
        let published = vec![None; nodes.len()];
        let bound = Bound {
            shared: Arc::new(Mutex::new(Shared { value, published })),
            nodes,
            root: root.clone(),
            manager: manager.clone(),
        };
        bound.publish();
        let granted = |id: &NodeId| {
            matches!(manager.node_manager().address_space().read().find(id),
                Some(NodeType::Variable(v)) if v.access_level().contains(AccessLevel::CURRENT_WRITE))
        };
        for (i, f) in S::FIELDS.iter().enumerate() {
            if !f.writable && !granted(&bound.nodes[i]) {
                continue;
            }
            let shared = Arc::downgrade(&bound.shared);
            manager.on_write(&bound.nodes[i], move |v: &Variant| {
                let Some(shared) = shared.upgrade() else { return Err(StatusCode::BadShutdown) };
                let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
                if !s.value.apply(i, v) {
                    return Err(StatusCode::BadTypeMismatch);
                }
                s.published[i] = Some(v.clone());
                Ok(None)
            });
        }
        Ok(bound)
    }

    /// The instance's NodeId.
    pub fn node_id(&self) -> &NodeId {
        &self.root
    }

    /// The variable a field is bound to.
    pub fn node_of(&self, field: &str) -> Option<&NodeId> {
        S::FIELDS.iter().position(|f| f.field == field).map(|i| &self.nodes[i])
    }

    /// The generated handle of the instance.
    pub fn handle(&self) -> Result<S::ObjectType, BindError> {
        self.manager.bind(&self.root)
    }

    /// Reads the struct (client writes included); writes wait while `f` runs.
    pub fn read<R>(&self, f: impl FnOnce(&S) -> R) -> R {
        f(&self.shared.lock().unwrap_or_else(|e| e.into_inner()).value)
    }

    /// Changes the struct and publishes the fields whose values changed.
    pub fn update<R>(&self, f: impl FnOnce(&mut S) -> R) -> R {
        let result = {
            let mut s = self.shared.lock().unwrap_or_else(|e| e.into_inner());
            f(&mut s.value)
        };
        self.publish();
        result
    }

    /// Publishes the fields whose values differ from what was last published. Returns how many changed.
    pub fn publish(&self) -> usize {
        let changed: Vec<(usize, Variant)> = {
            let mut s = self.shared.lock().unwrap_or_else(|e| e.into_inner());
            let values = s.value.to_variants();
            let mut changed = Vec::new();
            for (i, v) in values.into_iter().enumerate() {
                if s.published[i].as_ref() != Some(&v) {
                    s.published[i] = Some(v.clone());
                    changed.push((i, v));
                }
            }
            changed
        };
        for (i, v) in &changed {
            // A value the variable's DataType refuses was already refused at compile time; an empty
            // Variant (a null String, say) is not published.
            let _ = self.manager.set_value(&self.nodes[*i], v.clone());
        }
        changed.len()
    }
}
