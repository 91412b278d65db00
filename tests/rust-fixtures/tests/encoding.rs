//! Binary encoding of generated data types: exact bytes of OPC UA Part 6 for the optional-field and union
//! fixtures, and round trips (including as ExtensionObjects with run-time namespace indices) for the rest.

use nodeset_fixture_code::{enum_gaps, option_set, optional_fields, structure, union};
use opcua::types::{
    BinaryDecodable, BinaryEncodable, ContextOwned, DecodingOptions, ExtensionObject, LocalizedText, NamespaceMap,
    TypeLoaderCollection, UAString, Variant,
};

fn context() -> ContextOwned {
    let mut ns = NamespaceMap::new();
    ns.add_namespace("urn:server");
    ns.add_namespace(structure::NAMESPACE_URI); // 2
    ns.add_namespace(optional_fields::NAMESPACE_URI); // 3
    ns.add_namespace(union::NAMESPACE_URI); // 4
    let mut loaders = TypeLoaderCollection::new();
    loaders.add_type_loader(structure::TypeLoader);
    loaders.add_type_loader(optional_fields::TypeLoader);
    loaders.add_type_loader(union::TypeLoader);
    ContextOwned::new(ns, loaders, DecodingOptions::default())
}

fn encode<T: BinaryEncodable>(v: &T) -> Vec<u8> {
    let c = context();
    let ctx = c.context();
    let mut buf = Vec::new();
    v.encode(&mut buf, &ctx).expect("encodes");
    assert_eq!(buf.len(), v.byte_len(&ctx), "byte_len agrees with the encoding");
    buf
}

fn decode<T: BinaryDecodable>(bytes: &[u8]) -> T {
    let c = context();
    T::decode(&mut &bytes[..], &c.context()).expect("decodes")
}

#[test]
fn optional_fields_follow_part6_with_an_encoding_mask() {
    let v = optional_fields::types::ToolData {
        identifier: UAString::from("T1"),
        description: None,
        tool_number: 7,
        diameter: Some(2.5),
        length: 10.0,
    };
    let mut want = vec![0b10, 0, 0, 0]; // EncodingMask: Description absent (bit 0), Diameter present (bit 1)
    want.extend([2, 0, 0, 0, b'T', b'1']); // Identifier
    want.extend(7u32.to_le_bytes()); // ToolNumber
    want.extend(2.5f64.to_le_bytes()); // Diameter
    want.extend(10.0f64.to_le_bytes()); // Length
    assert_eq!(encode(&v), want);
    assert_eq!(decode::<optional_fields::types::ToolData>(&want), v);

    let both = optional_fields::types::ToolData { description: Some(LocalizedText::from("drill")), ..v.clone() };
    let bytes = encode(&both);
    assert_eq!(&bytes[..4], &[0b11, 0, 0, 0]);
    assert_eq!(decode::<optional_fields::types::ToolData>(&bytes), both);
}

#[test]
fn unions_follow_part6_with_a_switch_field() {
    use union::types::SetpointValue;
    assert_eq!(encode(&SetpointValue::Null), vec![0, 0, 0, 0]);
    let mut want = vec![2, 0, 0, 0]; // SwitchField 2: the second field, Named
    want.extend([2, 0, 0, 0, b'a', b'b']);
    assert_eq!(encode(&SetpointValue::Named(UAString::from("ab"))), want);
    assert_eq!(decode::<SetpointValue>(&want), SetpointValue::Named(UAString::from("ab")));
    let mut steps = vec![3, 0, 0, 0];
    steps.extend(42u32.to_le_bytes());
    assert_eq!(encode(&SetpointValue::Steps(42)), steps);
    let analog = SetpointValue::Analog(-1.5);
    assert_eq!(decode::<SetpointValue>(&encode(&analog)), analog);
}

#[test]
fn enumerations_keep_the_nodesets_values() {
    use enum_gaps::types::AlarmSeverityLevel as L;
    assert_eq!(encode(&L::Unknown), (-1i32).to_le_bytes().to_vec());
    assert_eq!(encode(&L::Critical), 10i32.to_le_bytes().to_vec());
    assert_eq!(decode::<L>(&5i32.to_le_bytes()), L::High);
    assert!(L::try_from(3).is_err(), "3 is a gap");
    assert_eq!(Variant::from(L::Medium), Variant::Int32(2));
}

#[test]
fn option_sets_have_the_base_types_width() {
    use option_set::types::AxisStatusFlags as F;
    let v = F::ENABLED | F::FAULT;
    assert_eq!(encode(&v), vec![0b1_0001, 0], "UInt16: two bytes");
    assert_eq!(decode::<F>(&[0b11, 0]), F::ENABLED | F::HOMED);
    assert_eq!(Variant::from(v), Variant::UInt16(0b1_0001));
}

#[test]
fn structures_round_trip_as_extension_objects_with_runtime_namespace_indices() {
    let c = context();
    let ctx = c.context();
    let v = optional_fields::types::ToolData { identifier: "T9".into(), tool_number: 9, diameter: Some(1.0), ..Default::default() };
    let eo = ExtensionObject::from_message(v.clone());
    let mut buf = Vec::new();
    eo.encode(&mut buf, &ctx).expect("encodes");
    // The encoding NodeId is written with the namespace index of this context (3), not a generated constant.
    assert_eq!(buf[0], 0x01, "four-byte NodeId encoding");
    assert_eq!(buf[1], 3, "namespace index resolved from the URI at run time");
    let back = ExtensionObject::decode(&mut buf.as_slice(), &ctx).expect("decodes");
    assert_eq!(back.inner_as::<optional_fields::types::ToolData>(), Some(&v));
}

#[test]
fn every_fixture_structure_round_trips() {
    fn rt<T: BinaryEncodable + BinaryDecodable + PartialEq + std::fmt::Debug + Default>() {
        let v = T::default();
        assert_eq!(decode::<T>(&encode(&v)), v);
    }
    rt::<structure::types::MeasurementRecord>();
    rt::<optional_fields::types::ToolData>();
    rt::<union::types::SetpointValue>();
    rt::<enum_gaps::types::OperatingMode>();
    rt::<option_set::types::AxisStatusFlags>();
}
