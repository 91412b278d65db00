//! The default value of a DataType, for the variables of a new instance whose declaration has no value
//! ([`super::Instantiate::data_type_defaults`]).
//!
//! A variable of a built-in type (or of a subtype, such as Duration or LocaleId) gets the type's zero: false,
//! 0, the empty string, the null NodeId, Good, ...; an enumeration its first value (the first of
//! `EnumValues`, else 0, the first of `EnumStrings`); an array (ValueRank 0 or more) an empty array of the
//! type. Structures, BaseDataType, DataValue and DiagnosticInfo get none: no value of theirs is the
//! default of every subtype, and a structure's zero would have to be encoded field by field.

use opcua::types::{
    Array, ByteString, DateTime, ExpandedNodeId, Guid, Identifier, LocalizedText, NodeId, QualifiedName, ReferenceTypeId,
    StatusCode, UAString, Variant, VariantScalarTypeId, XmlElement,
};

use super::instance::Spaces;

/// ns0's Enumeration DataType.
const ENUMERATION: u32 = 29;

impl Spaces<'_> {
    /// The default value of `data_type` with `value_rank`, if it has one (see the module docs).
    pub(crate) fn default_value(&self, data_type: &NodeId, value_rank: i32) -> Option<Variant> {
        let (builtin, enumeration) = self.builtin_of(data_type)?;
        let scalar = VariantScalarTypeId::try_from(builtin).ok()?;
        if value_rank >= 0 {
            return Array::new(scalar, Vec::<Variant>::new()).ok().map(|a| Variant::Array(Box::new(a)));
        }
        if let Some(e) = enumeration {
            return Some(Variant::Int32(self.first_enum_value(&e)));
        }
        zero(scalar)
    }

    /// The built-in type a DataType's values are encoded as (1 to 21), and for an enumeration the
    /// enumeration DataType itself (its values are Int32).
    fn builtin_of(&self, data_type: &NodeId) -> Option<(u32, Option<NodeId>)> {
        let mut current = data_type.clone();
        for _ in 0..super::instance::MAX_DEPTH {
            if let (0, Identifier::Numeric(n)) = (current.namespace, &current.identifier) {
                match *n {
                    ENUMERATION => return Some((6, Some(data_type.clone()).filter(|d| *d != current))),
                    // Number, Integer, UInteger: abstract; their widest concrete kind.
                    26 => return Some((11, None)),
                    27 => return Some((8, None)),
                    28 => return Some((9, None)),
                    1..=21 => return Some((*n, None)),
                    // Structure, DataValue, BaseDataType, DiagnosticInfo.
                    22..=25 => return None,
                    _ => {}
                }
            }
            current = self.supertype(&current)?;
        }
        None
    }

    /// The first value of an enumeration: the first `EnumValues` entry's Value, else 0 (the first of
    /// `EnumStrings`, or an enumeration that lists neither).
    fn first_enum_value(&self, enumeration: &NodeId) -> i32 {
        let property = self
            .refs(enumeration, ReferenceTypeId::HasProperty)
            .into_iter()
            .find(|(_, p)| self.find(p).is_some_and(|n| n.as_node().browse_name().name.as_ref() == "EnumValues"));
        let Some((_, property)) = property else { return 0 };
        let Some(opcua::nodes::NodeType::Variable(v)) = self.find(&property) else { return 0 };
        let value = v.value(
            opcua::types::TimestampsToReturn::Neither,
            &opcua::types::NumericRange::None,
            &opcua::types::DataEncoding::Binary,
            0.0,
        );
        let Some(Variant::Array(array)) = value.value else { return 0 };
        array
            .values
            .iter()
            .filter_map(|v| match v {
                Variant::ExtensionObject(eo) => eo.inner_as::<opcua::types::EnumValueType>().map(|e| e.value),
                _ => None,
            })
            .next()
            .and_then(|v| i32::try_from(v).ok())
            .unwrap_or(0)
    }
}

/// The zero of a built-in scalar type.
fn zero(t: VariantScalarTypeId) -> Option<Variant> {
    use VariantScalarTypeId as T;
    Some(match t {
        T::Boolean => Variant::Boolean(false),
        T::SByte => Variant::SByte(0),
        T::Byte => Variant::Byte(0),
        T::Int16 => Variant::Int16(0),
        T::UInt16 => Variant::UInt16(0),
        T::Int32 => Variant::Int32(0),
        T::UInt32 => Variant::UInt32(0),
        T::Int64 => Variant::Int64(0),
        T::UInt64 => Variant::UInt64(0),
        T::Float => Variant::Float(0.0),
        T::Double => Variant::Double(0.0),
        T::String => Variant::String(UAString::from("")),
        T::DateTime => Variant::DateTime(Box::new(DateTime::null())),
        T::Guid => Variant::Guid(Box::new(Guid::null())),
        T::ByteString => Variant::ByteString(ByteString::from(Vec::<u8>::new())),
        T::XmlElement => Variant::XmlElement(XmlElement::from("")),
        T::NodeId => Variant::NodeId(Box::new(NodeId::null())),
        T::ExpandedNodeId => Variant::ExpandedNodeId(Box::new(ExpandedNodeId::null())),
        T::StatusCode => Variant::StatusCode(StatusCode::Good),
        T::QualifiedName => Variant::QualifiedName(Box::new(QualifiedName::null())),
        T::LocalizedText => Variant::LocalizedText(Box::new(LocalizedText::null())),
        _ => return None,
    })
}
