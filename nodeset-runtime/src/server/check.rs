//! Does a value fit a DataType and ValueRank? The check behind BadTypeMismatch for writes and method
//! arguments.
//!
//! async-opcua's own write validation accepts any scalar of the wrong type, so the node manager checks
//! values here, against the server's type tree (which holds ns0 and every imported table's types):
//!
//! - a value of DataType `A` fits DataType `D` if `A` is `D` or a subtype of it (Int32 fits Integer and
//!   Number, a structure fits its supertypes, anything fits BaseDataType);
//! - a value of a built-in type fits a DataType derived from that built-in type (a Double fits Duration, a
//!   UInt32 fits an OptionSet based on UInt32, an Int32 fits any Enumeration);
//! - an ExtensionObject's DataType is that of its decoded body, or the DataType whose encoding it carries if
//!   no type loader decoded it; a body of an unknown encoding is accepted (nothing proves it wrong), and so
//!   is any value for a DataType the type tree does not know (ns0's abstract types before the server runs);
//! - the shape fits the ValueRank (scalar, one or more dimensions, any), and a ByteString may be written to
//!   a Byte array, as OPC UA Part 4 allows.
//!
//! The walks up the type tree are bounded, so a cyclic HasSubtype chain in a table cannot hang a request.

use opcua::nodes::{DefaultTypeTree, TypeTree};
use opcua::server::address_space::AddressSpace;
use opcua::types::{BrowseDirection, NodeClass, NodeId, StatusCode, Variant};

/// ns0 DataTypes the rules name.
const BYTE: u32 = 3;
const INT32: u32 = 6;
const BASE_DATA_TYPE: u32 = 24;
const ENUMERATION: u32 = 29;
const HAS_ENCODING: u32 = 38;

/// How many supertypes a walk follows before it gives up.
const MAX_DEPTH: usize = 64;

/// What a check knows about the server's types.
pub(crate) struct Types<'a> {
    pub tree: &'a DefaultTypeTree,
    /// The address space of the model node manager, to map encodings of undecoded ExtensionObjects to
    /// their DataTypes; without it such bodies are accepted.
    pub space: Option<&'a AddressSpace>,
}

impl Types<'_> {
    /// `Ok` if `value` may be stored in a variable (or passed as an argument) of `data_type` and
    /// `value_rank`. With `partial` (a write to an index range) only the element types are checked.
    pub fn check(&self, value: &Variant, data_type: &NodeId, value_rank: i32, partial: bool) -> Result<(), StatusCode> {
        let mismatch = Err(StatusCode::BadTypeMismatch);
        if is_ns0(data_type, BASE_DATA_TYPE) && (value_rank == -2 || value_rank == -1 && !value.is_array()) {
            return Ok(());
        }
        match value {
            Variant::Empty => mismatch,
            Variant::Array(array) => {
                let rank = array.dimensions.as_ref().map_or(1, |d| d.len().max(1)) as i32;
                if !partial && !rank_fits(rank, value_rank) {
                    return mismatch;
                }
                array.values.iter().try_for_each(|v| self.check_scalar(v, data_type))
            }
            // A ByteString is the encoding of a Byte array (Part 4, Write service).
            Variant::ByteString(_) if is_ns0(data_type, BYTE) && matches!(value_rank, -3 | -2 | 0 | 1) => Ok(()),
            scalar => {
                if !partial && !(-3..=-1).contains(&value_rank) {
                    return mismatch;
                }
                self.check_scalar(scalar, data_type)
            }
        }
    }

    fn check_scalar(&self, value: &Variant, data_type: &NodeId) -> Result<(), StatusCode> {
        if is_ns0(data_type, BASE_DATA_TYPE) {
            return Ok(());
        }
        let actual = match value {
            Variant::Variant(inner) => return self.check_scalar(inner, data_type),
            Variant::Empty | Variant::Array(_) => return Err(StatusCode::BadTypeMismatch),
            Variant::ExtensionObject(eo) => {
                if self.builtin_base(data_type).is_some() {
                    return Err(StatusCode::BadTypeMismatch);
                }
                let Some(id) = eo.data_type() else {
                    // A null structure.
                    return Ok(());
                };
                let Some(id) = id.try_resolve(self.tree.namespaces()).map(|c| c.into_owned()) else {
                    return Ok(());
                };
                match self.structure_type(&id) {
                    Some(t) => t,
                    None => return Ok(()),
                }
            }
            other => {
                match other.data_type().and_then(|d| d.try_resolve(self.tree.namespaces()).map(|c| c.into_owned())) {
                    Some(id) => id,
                    None => return Err(StatusCode::BadTypeMismatch),
                }
            }
        };
        if self.is_subtype(&actual, data_type) {
            return Ok(());
        }
        match self.builtin_base(data_type) {
            Some(base) if base == actual => Ok(()),
            Some(_) => Err(StatusCode::BadTypeMismatch),
            // A DataType the type tree does not know (ns0's types before the server runs, a DataType of a
            // namespace nobody serves): nothing proves the value wrong.
            None if self.tree.get(data_type).is_none() => Ok(()),
            None => Err(StatusCode::BadTypeMismatch),
        }
    }

    /// The DataType of an ExtensionObject body whose type id is `id`: `id` itself if it is a DataType,
    /// else the DataType that has `id` as an encoding; `None` if neither is known.
    fn structure_type(&self, id: &NodeId) -> Option<NodeId> {
        if self.tree.get(id) == Some(NodeClass::DataType) {
            return Some(id.clone());
        }
        self.space?
            .find_references(id, Some((NodeId::new(0, HAS_ENCODING), false)), self.tree, BrowseDirection::Inverse)
            .map(|r| r.target_node.clone())
            .next()
    }

    /// `child` is `ancestor` or one of its subtypes.
    pub fn is_subtype(&self, child: &NodeId, ancestor: &NodeId) -> bool {
        let mut node = child;
        for _ in 0..MAX_DEPTH {
            if node == ancestor {
                return true;
            }
            match self.tree.get_supertype(node) {
                Some(s) => node = s,
                None => return false,
            }
        }
        false
    }

    /// The built-in type (ns0 i=1..=25) a DataType derives from, with Enumerations counted as Int32;
    /// `None` for structures and abstract types above the built-ins.
    pub fn builtin_base(&self, data_type: &NodeId) -> Option<NodeId> {
        let mut node = data_type;
        for _ in 0..MAX_DEPTH {
            if node.namespace == 0 {
                if let Some(n) = node.as_u32() {
                    if n == ENUMERATION {
                        return Some(NodeId::new(0, INT32));
                    }
                    if (1..=25).contains(&n) && n != BASE_DATA_TYPE && n != 22 {
                        return Some(node.clone());
                    }
                }
            }
            node = self.tree.get_supertype(node)?;
        }
        None
    }
}

fn is_ns0(id: &NodeId, n: u32) -> bool {
    id.namespace == 0 && id.as_u32() == Some(n)
}

/// Does an array of `rank` dimensions fit ValueRank `value_rank`?
fn rank_fits(rank: i32, value_rank: i32) -> bool {
    match value_rank {
        -2 => true,
        -3 => rank == 1,
        0 => rank >= 1,
        n if n > 0 => rank == n,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::rank_fits;

    #[test]
    fn ranks() {
        assert!(rank_fits(1, 1));
        assert!(rank_fits(1, -3));
        assert!(rank_fits(2, 0));
        assert!(rank_fits(3, -2));
        assert!(!rank_fits(1, -1));
        assert!(!rank_fits(2, 1));
        assert!(!rank_fits(2, -3));
    }
}
