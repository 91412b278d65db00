//! Rust types for OPC UA values: [`UaValue`] converts between a Rust value and a [`Variant`] and states the
//! ValueRank the Rust type stands for, so that typed handles and the derive can check a binding at compile
//! time.

use opcua::types::{
    ByteString, DateTime, DynEncodable, ExpandedNodeId, ExtensionObject, Guid, LocalizedText, NodeId,
    QualifiedName, StatusCode, TryFromVariant, UAString, Variant, VariantScalarTypeId, XmlElement,
};

/// ValueRank of a scalar.
pub const SCALAR: i32 = -1;
/// ValueRank of a one-dimensional array.
pub const ONE_DIMENSION: i32 = 1;
/// ValueRank `Any`: the Rust type is [`Variant`], which holds anything.
pub const ANY: i32 = -3;

/// A Rust type that stands for values of one OPC UA DataType and ValueRank.
///
/// Implemented for the built-in types (`bool`, the integers, `f32`, `f64`, `String` and `UAString`,
/// `LocalizedText`, `NodeId`, ...), `Vec<T>` (one dimension), [`Variant`] (any value), and for every
/// generated data type: structures through [`UaStruct`], enumerations and OptionSets by generated impls.
#[diagnostic::on_unimplemented(
    message = "`{Self}` is not an OPC UA value type",
    label = "not a built-in OPC UA type, a generated data type, `Vec` of one, or `Variant`"
)]
pub trait UaValue: Sized + Clone + Send + Sync + 'static {
    /// The scalar type: `Self` for scalars, the element type for arrays, `Variant` for any value.
    type Scalar: 'static;
    /// The ValueRank this type stands for: [`SCALAR`], [`ONE_DIMENSION`] or [`ANY`].
    const VALUE_RANK: i32;
    /// The Variant type of one scalar (for arrays: of each element), so that an empty array keeps its type.
    const VARIANT_TYPE: VariantScalarTypeId;
    /// The value as a Variant.
    fn to_variant(&self) -> Variant;
    /// The value of a Variant, `None` if it holds something else.
    fn from_variant(value: &Variant) -> Option<Self>;
}

/// Marks a generated structure, which travels as an ExtensionObject (generated code implements it).
pub trait UaStruct: DynEncodable + Clone + Send + Sync + 'static {}

impl<T: UaStruct> UaValue for T {
    type Scalar = T;
    const VALUE_RANK: i32 = SCALAR;
    const VARIANT_TYPE: VariantScalarTypeId = VariantScalarTypeId::ExtensionObject;
    fn to_variant(&self) -> Variant {
        Variant::ExtensionObject(ExtensionObject::new(self.clone()))
    }
    fn from_variant(value: &Variant) -> Option<Self> {
        match value {
            Variant::ExtensionObject(eo) => eo.inner_as::<T>().cloned(),
            _ => None,
        }
    }
}

macro_rules! scalar {
    ($($t:ty => $vt:ident),* $(,)?) => {$(
        impl UaValue for $t {
            type Scalar = $t;
            const VALUE_RANK: i32 = SCALAR;
            const VARIANT_TYPE: VariantScalarTypeId = VariantScalarTypeId::$vt;
            fn to_variant(&self) -> Variant {
                Variant::from(self.clone())
            }
            fn from_variant(value: &Variant) -> Option<Self> {
                // Only the exact Variant type: a typed handle must not silently convert.
                match value {
                    Variant::$vt(_) => <$t as TryFromVariant>::try_from_variant(value.clone()).ok(),
                    _ => None,
                }
            }
        }
    )*};
}

scalar! {
    bool => Boolean, i8 => SByte, u8 => Byte, i16 => Int16, u16 => UInt16, i32 => Int32, u32 => UInt32,
    i64 => Int64, u64 => UInt64, f32 => Float, f64 => Double, UAString => String, DateTime => DateTime,
    Guid => Guid, ByteString => ByteString, XmlElement => XmlElement, NodeId => NodeId,
    ExpandedNodeId => ExpandedNodeId, StatusCode => StatusCode, QualifiedName => QualifiedName,
    LocalizedText => LocalizedText, ExtensionObject => ExtensionObject,
}

/// A null String reads as the empty string.
impl UaValue for String {
    type Scalar = String;
    const VALUE_RANK: i32 = SCALAR;
    const VARIANT_TYPE: VariantScalarTypeId = VariantScalarTypeId::String;
    fn to_variant(&self) -> Variant {
        Variant::String(UAString::from(self.as_str()))
    }
    fn from_variant(value: &Variant) -> Option<Self> {
        match value {
            Variant::String(s) => Some(s.as_ref().to_owned()),
            _ => None,
        }
    }
}

impl UaValue for Variant {
    type Scalar = Variant;
    const VALUE_RANK: i32 = ANY;
    const VARIANT_TYPE: VariantScalarTypeId = VariantScalarTypeId::Variant;
    fn to_variant(&self) -> Variant {
        self.clone()
    }
    fn from_variant(value: &Variant) -> Option<Self> {
        Some(value.clone())
    }
}

/// A one-dimensional array. An empty Variant (no value yet) reads as `None`, not as an empty array.
impl<T: UaValue<Scalar = T>> UaValue for Vec<T> {
    type Scalar = T;
    const VALUE_RANK: i32 = ONE_DIMENSION;
    const VARIANT_TYPE: VariantScalarTypeId = T::VARIANT_TYPE;
    fn to_variant(&self) -> Variant {
        let items: Vec<Variant> = self.iter().map(UaValue::to_variant).collect();
        match opcua::types::Array::new(T::VARIANT_TYPE, items) {
            Ok(array) => Variant::Array(Box::new(array)),
            // Unreachable: every item has the element type.
            Err(_) => Variant::Empty,
        }
    }
    fn from_variant(value: &Variant) -> Option<Self> {
        match value {
            Variant::Array(array) if array.dimensions.as_ref().is_none_or(|d| d.len() <= 1) => {
                array.values.iter().map(T::from_variant).collect()
            }
            // A ByteString is the encoding of a Byte array.
            Variant::ByteString(b) if T::VARIANT_TYPE == VariantScalarTypeId::Byte => {
                b.value.as_ref().map_or(Some(Vec::new()), |bytes| {
                    bytes.iter().map(|&x| T::from_variant(&Variant::Byte(x))).collect()
                })
            }
            _ => None,
        }
    }
}

/// The integer in an enumeration's Variant (Int32, or another integer type a client may send).
pub fn enum_value(value: &Variant) -> Option<i64> {
    match *value {
        Variant::Int32(i) => Some(i as i64),
        Variant::SByte(i) => Some(i as i64),
        Variant::Byte(i) => Some(i as i64),
        Variant::Int16(i) => Some(i as i64),
        Variant::UInt16(i) => Some(i as i64),
        Variant::UInt32(i) => Some(i as i64),
        Variant::Int64(i) => Some(i),
        _ => None,
    }
}

/// The bits of an OptionSet's Variant (an unsigned integer of any width).
pub fn option_set_bits(value: &Variant) -> Option<u64> {
    match *value {
        Variant::Byte(i) => Some(i as u64),
        Variant::UInt16(i) => Some(i as u64),
        Variant::UInt32(i) => Some(i as u64),
        Variant::UInt64(i) => Some(i),
        _ => None,
    }
}

/// Whether a Rust type of ValueRank `rust` can hold the values of a node of ValueRank `node`.
///
/// A scalar type binds scalar nodes; `Vec<T>` binds nodes of one dimension (ValueRank 1) and of "one or
/// more dimensions" (0) when it has one; `Variant` binds anything. A node that may be a scalar or an array
/// (-2, -3) needs `Variant`.
pub const fn rank_fits(rust: i32, node: i32) -> bool {
    match rust {
        ANY => true,
        SCALAR => node == SCALAR,
        _ => node == ONE_DIMENSION || node == 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalars_round_trip_and_reject_other_types() {
        assert_eq!(f64::from_variant(&2.5f64.to_variant()), Some(2.5));
        assert_eq!(f64::from_variant(&Variant::Int32(2)), None);
        assert_eq!(String::from_variant(&"x".to_owned().to_variant()), Some("x".to_owned()));
        assert_eq!(String::from_variant(&Variant::String(UAString::null())), Some(String::new()));
        let lt = LocalizedText::new("en", "Arm");
        assert_eq!(LocalizedText::from_variant(&lt.to_variant()), Some(lt));
    }

    #[test]
    fn arrays_keep_their_element_type() {
        let v = vec![1.0f64, 2.0].to_variant();
        assert_eq!(Vec::<f64>::from_variant(&v), Some(vec![1.0, 2.0]));
        match Vec::<i32>::new().to_variant() {
            Variant::Array(a) => assert_eq!(a.value_type, VariantScalarTypeId::Int32),
            other => panic!("not an array: {other:?}"),
        }
        assert_eq!(Vec::<f64>::from_variant(&Variant::Double(1.0)), None);
        assert_eq!(Vec::<u8>::from_variant(&Variant::ByteString(ByteString::from(vec![1u8, 2]))), Some(vec![1, 2]));
    }

    #[test]
    fn ranks() {
        assert!(rank_fits(SCALAR, -1) && !rank_fits(SCALAR, 1));
        assert!(rank_fits(ONE_DIMENSION, 1) && rank_fits(ONE_DIMENSION, 0) && !rank_fits(ONE_DIMENSION, -1));
        assert!(rank_fits(ANY, -2) && !rank_fits(SCALAR, -2));
        assert_eq!(<Vec<f64> as UaValue>::VALUE_RANK, 1);
    }
}
