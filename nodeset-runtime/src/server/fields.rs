//! Variables that show the fields of their structured value as child variables.
//!
//! OPC 10000-5 defines VariableTypes whose instances expose each field of their DataType as a component
//! of the same BrowseName: `3DFrameType` (CartesianCoordinates, Orientation), `3DCartesianCoordinatesType`
//! and `3DVectorType` (X, Y, Z), `3DOrientationType` (A, B, C), `RationalNumberType` (Numerator,
//! Denominator). A client that reads the parent and one that reads a child must see the same number, so
//! whenever the parent's value is set (by user code or by a client's write) the server sets the children
//! too, with the same status and timestamps. Children are found by their ns0 BrowseName among the parent's
//! components; a field without such a child is left out. The other direction (a write to one child) is
//! not merged back into the parent.

use opcua::nodes::{DefaultTypeTree, NodeBase, NodeType};
use opcua::server::address_space::AddressSpace;
use opcua::types::{
    BrowseDirection, DataValue, DynEncodable, ExtensionObject, NodeId, RationalNumber, ReferenceTypeId, ThreeDCartesianCoordinates, ThreeDFrame,
    ThreeDOrientation, ThreeDVector, Variant,
};

/// The fields of a structured value that ns0 VariableTypes expose as children, by BrowseName; empty for
/// any other value.
fn fields(value: &Variant) -> Vec<(&'static str, Variant)> {
    let Variant::ExtensionObject(object) = value else {
        return Vec::new();
    };
    let xyz = |x: f64, y: f64, z: f64| vec![("X", x.into()), ("Y", y.into()), ("Z", z.into())];
    if let Some(f) = object.inner_as::<ThreeDFrame>() {
        vec![
            ("CartesianCoordinates", structure(f.cartesian_coordinates.clone())),
            ("Orientation", structure(f.orientation.clone())),
        ]
    } else if let Some(c) = object.inner_as::<ThreeDCartesianCoordinates>() {
        xyz(c.x, c.y, c.z)
    } else if let Some(v) = object.inner_as::<ThreeDVector>() {
        xyz(v.x, v.y, v.z)
    } else if let Some(o) = object.inner_as::<ThreeDOrientation>() {
        vec![("A", o.a.into()), ("B", o.b.into()), ("C", o.c.into())]
    } else if let Some(r) = object.inner_as::<RationalNumber>() {
        vec![("Numerator", r.numerator.into()), ("Denominator", r.denominator.into())]
    } else {
        Vec::new()
    }
}

fn structure(value: impl DynEncodable) -> Variant {
    Variant::ExtensionObject(ExtensionObject::from_message(value))
}

/// The children of `node` that show fields of `value`, each with the DataValue it must get (the parent's
/// status and timestamps, the field as value). Only variables that are components of `node` with an ns0
/// BrowseName count; their own children are the caller's next step.
pub(crate) fn field_children(
    space: &AddressSpace,
    tree: &DefaultTypeTree,
    node: &NodeId,
    value: &DataValue,
) -> Vec<(NodeId, DataValue)> {
    let Some(v) = &value.value else {
        return Vec::new();
    };
    let fields = fields(v);
    if fields.is_empty() {
        return Vec::new();
    }
    let components = space
        .find_references(node, Some((ReferenceTypeId::HasComponent, false)), tree, BrowseDirection::Forward)
        .map(|r| r.target_node.clone())
        .collect::<Vec<_>>();
    let mut out = Vec::new();
    for (name, field) in fields {
        let child = components.iter().find(|c| match space.find(*c) {
            Some(NodeType::Variable(var)) => {
                let q = var.browse_name();
                q.namespace_index == 0 && q.name.as_ref() == name
            }
            _ => false,
        });
        if let Some(child) = child {
            out.push((child.clone(), DataValue { value: Some(field), ..value.clone() }));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_split_into_coordinates_and_orientation() {
        let frame = ThreeDFrame {
            cartesian_coordinates: ThreeDCartesianCoordinates { x: 1.0, y: 2.0, z: 3.0 },
            orientation: ThreeDOrientation { a: 4.0, b: 5.0, c: 6.0 },
        };
        let f = fields(&structure(frame));
        assert_eq!(f.iter().map(|(n, _)| *n).collect::<Vec<_>>(), ["CartesianCoordinates", "Orientation"]);
        assert_eq!(fields(&f[0].1), vec![("X", 1.0.into()), ("Y", 2.0.into()), ("Z", 3.0.into())]);
        assert_eq!(fields(&f[1].1), vec![("A", 4.0.into()), ("B", 5.0.into()), ("C", 6.0.into())]);
    }

    #[test]
    fn rational_numbers_split_and_other_values_have_no_fields() {
        let r = structure(RationalNumber { numerator: 121, denominator: 2 });
        assert_eq!(fields(&r), vec![("Numerator", Variant::Int32(121)), ("Denominator", Variant::UInt32(2))]);
        assert!(fields(&Variant::Double(1.0)).is_empty());
        assert!(fields(&Variant::Empty).is_empty());
    }
}
