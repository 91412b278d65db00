//! The NamespaceMetadata objects that nodesets bring along (DI, IA and Robotics each put one of their own
//! under `Server/Namespaces`), folded into the one async-opcua creates for every namespace a node manager
//! serves, so that a client browsing `Server/Namespaces` finds each namespace once.
//!
//! async-opcua builds its objects (and the server's NamespaceArray) from
//! [`NamespaceMetadata`](opcua::server::diagnostics::NamespaceMetadata), so the nodeset's object is the one
//! that goes: what it says beyond the URI, version and publication date the table already gives (the static
//! NodeId types, ranges and pattern) is copied into the metadata first, then the object and its properties
//! are removed from the address space.

use opcua::nodes::{DefaultTypeTree, NodeBase, NodeType};
use opcua::server::address_space::AddressSpace;
use opcua::server::diagnostics::NamespaceMetadata;
use opcua::types::{
    BrowseDirection, DataEncoding, IdType, NodeId, NumericRange, ObjectId, ObjectTypeId, ReferenceTypeId,
    TimestampsToReturn, Variant,
};

/// Removes the NamespaceMetadata objects the tables put under `Server/Namespaces` after copying their static
/// NodeId facts into `namespaces` (the entry with the same NamespaceUri, where that entry has none yet).
pub(super) fn fold_into(space: &mut AddressSpace, tree: &DefaultTypeTree, namespaces: &mut [NamespaceMetadata]) {
    let folder: NodeId = ObjectId::Server_Namespaces.into();
    let mut objects: Vec<NodeId> = space
        .find_references(&folder, Some((ReferenceTypeId::HasComponent, true)), tree, BrowseDirection::Forward)
        .map(|r| r.target_node.clone())
        .filter(|id| id.namespace != 0 && is_namespace_metadata(space, tree, id))
        .collect();
    // NodeId has no order; its text gives one, so the fold runs the same way every start.
    objects.sort_by_cached_key(|id| id.to_string());
    objects.dedup();
    for object in objects {
        let properties = properties(space, tree, &object);
        let value = |name: &str| properties.iter().find(|(n, _, _)| n == name).and_then(|(_, _, v)| v.clone());
        let uri = match value("NamespaceUri") {
            Some(Variant::String(s)) => s.as_ref().to_owned(),
            _ => String::new(),
        };
        if let Some(meta) = namespaces.iter_mut().find(|m| m.namespace_uri == uri) {
            if meta.static_node_id_types.is_none() {
                meta.static_node_id_types = id_types(value("StaticNodeIdTypes"));
            }
            if meta.static_numeric_node_id_range.is_none() {
                meta.static_numeric_node_id_range = ranges(value("StaticNumericNodeIdRange"));
            }
            if meta.static_string_node_id_pattern.is_none() {
                if let Some(Variant::String(s)) = value("StaticStringNodeIdPattern") {
                    meta.static_string_node_id_pattern = Some(s.as_ref().to_owned()).filter(|p| !p.is_empty());
                }
            }
        }
        for (_, id, _) in &properties {
            space.delete(id, true);
        }
        space.delete(&object, true);
    }
}

fn is_namespace_metadata(space: &AddressSpace, tree: &DefaultTypeTree, id: &NodeId) -> bool {
    let metadata: NodeId = ObjectTypeId::NamespaceMetadataType.into();
    space
        .find_references(id, Some((ReferenceTypeId::HasTypeDefinition, false)), tree, BrowseDirection::Forward)
        .any(|r| *r.target_node == metadata)
}

/// The properties of `object`: BrowseName (name part), NodeId and value.
fn properties(space: &AddressSpace, tree: &DefaultTypeTree, object: &NodeId) -> Vec<(String, NodeId, Option<Variant>)> {
    space
        .find_references(object, Some((ReferenceTypeId::HasProperty, false)), tree, BrowseDirection::Forward)
        .filter_map(|r| match space.find(r.target_node)? {
            NodeType::Variable(v) => {
                let value = v.value(TimestampsToReturn::Neither, &NumericRange::None, &DataEncoding::Binary, 0.0).value;
                Some((v.browse_name().name.as_ref().to_owned(), r.target_node.clone(), value))
            }
            _ => None,
        })
        .collect()
}

fn id_types(value: Option<Variant>) -> Option<Vec<IdType>> {
    let Some(Variant::Array(array)) = value else {
        return None;
    };
    let types: Vec<IdType> = array
        .values
        .iter()
        .filter_map(|v| match v {
            Variant::Int32(0) | Variant::Byte(0) => Some(IdType::Numeric),
            Variant::Int32(1) | Variant::Byte(1) => Some(IdType::String),
            Variant::Int32(2) | Variant::Byte(2) => Some(IdType::Guid),
            Variant::Int32(3) | Variant::Byte(3) => Some(IdType::Opaque),
            _ => None,
        })
        .collect();
    Some(types).filter(|t| !t.is_empty())
}

fn ranges(value: Option<Variant>) -> Option<Vec<NumericRange>> {
    let Some(Variant::Array(array)) = value else {
        return None;
    };
    let ranges: Vec<NumericRange> = array
        .values
        .iter()
        .filter_map(|v| match v {
            Variant::String(s) => s.as_ref().parse().ok(),
            _ => None,
        })
        .collect();
    Some(ranges).filter(|r| !r.is_empty())
}
