//! Recursive data types: which structure fields are boxed.
//!
//! A structure that holds a value of its own type, directly or through other structures (an optional field
//! `ReferredSemanticId` of the structure's own type, say), would have no finite size in Rust. Arrays break the
//! cycle (`Option<Vec<T>>` is a pointer), and so do fields encoded as `ExtensionObject` (abstract types and
//! `AllowSubTypes`); every other field whose type reaches the owner again by value is generated as `Box<T>`
//! (`Option<Box<T>>` when optional). The box is invisible on the wire: the binary encoding of a boxed value is
//! the encoding of the value, and `types.rs` implements it for the boxed types.

use super::has_rust_type;
use crate::model::{DataTypeKind, Field, Model, NodeIx};
use std::collections::BTreeSet;

/// Whether a field holds its type by value in Rust (no array, no ExtensionObject), and which structure
/// type that is.
pub(super) fn by_value_struct(model: &Model, f: &Field) -> Option<NodeIx> {
    if f.value_rank >= 0 || f.value_rank == -2 || f.value_rank == -3 || f.allow_sub_types {
        return None;
    }
    let info = model.data_types.get(&f.data_type)?;
    let DataTypeKind::Structure { .. } = info.kind else { return None };
    if info.is_abstract || model.node(f.data_type).id.ns == 0 || !has_rust_type(model, f.data_type) {
        return None;
    }
    Some(f.data_type)
}

/// The structure types whose values are held by value in `t`'s fields.
fn by_value_edges(model: &Model, t: NodeIx) -> Vec<NodeIx> {
    match model.data_types.get(&t).map(|i| &i.kind) {
        Some(DataTypeKind::Structure { fields, .. }) => fields.iter().filter_map(|f| by_value_struct(model, f)).collect(),
        _ => Vec::new(),
    }
}

/// Whether `to` is reached from `from` through fields held by value (in one step or more; `from == to`
/// counts only through a cycle).
pub(super) fn reaches(model: &Model, from: NodeIx, to: NodeIx) -> bool {
    let mut seen = BTreeSet::new();
    let mut stack = by_value_edges(model, from);
    while let Some(t) = stack.pop() {
        if t == to {
            return true;
        }
        if seen.insert(t) {
            stack.extend(by_value_edges(model, t));
        }
    }
    false
}

/// Whether field `f` of structure `owner` is boxed: its type reaches `owner` again by value.
pub(super) fn is_boxed(model: &Model, owner: NodeIx, f: &Field) -> bool {
    match by_value_struct(model, f) {
        Some(s) => s == owner || reaches(model, s, owner),
        None => false,
    }
}

/// Whether values of structure `t` are boxed somewhere (it lies on a cycle of fields held by value), so that
/// `types.rs` implements the binary encoding of `Box<t>`.
pub(super) fn is_on_cycle(model: &Model, t: NodeIx) -> bool {
    reaches(model, t, t)
}
