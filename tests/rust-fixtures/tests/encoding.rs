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

/// The `structure_values` fixture's tables imported with the type loaders of its namespaces, as a server
/// imports them: each structure value the compiler laid out decodes into the generated type (or ns0's), which
/// holds only if the layout is the binary encoding async-opcua's derive reads, field for field.
#[test]
fn structure_values_of_a_table_decode_into_the_generated_types() {
    use nodeset_fixture_code::{parts, structure_values};
    use nodeset_models::runtime::import::TableImport;
    use opcua::nodes::NodeType;
    use opcua::server::address_space::AddressSpace;
    use opcua::types::{EUInformation, NodeId, QualifiedName, Range};
    use structure_values::types::{Tool, ToolChoice, ToolMode, ToolOptions, Toolset};

    let mut ns = NamespaceMap::new();
    let mut loaders = TypeLoaderCollection::new();
    loaders.add_type_loader(parts::TypeLoader);
    loaders.add_type_loader(structure_values::TypeLoader);
    let mut space = AddressSpace::new();
    for table in [&parts::TABLE, &structure_values::TABLE] {
        ns.add_namespace(table.namespace_uri);
    }
    for table in [&parts::TABLE, &structure_values::TABLE] {
        space.import_node_set(&TableImport::with_type_loaders(table, loaders.clone()), &mut ns);
    }
    let own = ns.get_index(structure_values::NAMESPACE_URI).unwrap();
    let other = ns.get_index(parts::NAMESPACE_URI).unwrap();
    let value = |id: u32| -> Variant {
        match space.find(&NodeId::new(own, id)) {
            Some(NodeType::Variable(v)) => v.value(opcua::types::TimestampsToReturn::Neither, &opcua::types::NumericRange::None, &opcua::types::DataEncoding::Binary, 0.0).value.unwrap_or_default(),
            other => panic!("i={id} is not a variable: {other:?}"),
        }
    };
    let structure = |id: u32| -> ExtensionObject {
        match value(id) {
            Variant::ExtensionObject(eo) => eo,
            other => panic!("i={id}: {other:?}"),
        }
    };
    let unit = structure(6010);
    let unit = unit.inner_as::<EUInformation>().expect("ns0's EUInformation");
    assert_eq!((unit.unit_id, unit.display_name.text.as_ref()), (4408652, "°C"));
    assert_eq!(structure(6011).inner_as::<Range>(), Some(&Range { low: -5.5, high: 120.0 }));

    let main = structure(6013);
    let main = main.inner_as::<Tool>().expect("the generated Tool");
    assert_eq!(main.name.as_ref(), "Drill 6 mm");
    assert_eq!(main.mode, ToolMode::Drilling);
    assert_eq!((main.offset.x, main.offset.y, main.offset.z), (1.5, -2.0, 0.25));
    assert_eq!(main.weights, Some(vec![1.5, 2.25, -0.5]));
    assert_eq!(main.holder, NodeId::new(own, 6001), "the file's ns=1 is the server's index of the fixture");
    assert_eq!(main.tag, QualifiedName::new(other, "Spindle"), "the file's ns=2 is the server's index of parts");
    assert_eq!(main.setting, Variant::Int32(42));
    assert_eq!(main.label, LocalizedText::new("en", "Six millimetre drill"));

    let lean = structure(6014);
    let lean = lean.inner_as::<Tool>().expect("the generated Tool");
    assert_eq!(lean, &Tool { name: "Blank".into(), ..Tool::default() }, "fields left out are null");

    let options = structure(6016);
    let options = options.inner_as::<ToolOptions>().expect("the generated ToolOptions");
    assert_eq!((options.required, options.comment.clone()), (7, None));
    assert_eq!(options.limit, Some(Range { low: 0.5, high: 9.5 }));
    assert_eq!(options.position.as_ref().map(|p| (p.x, p.y, p.z)), Some((10.0, 20.0, 30.0)));

    let choice = structure(6018);
    assert_eq!(choice.inner_as::<ToolChoice>(), Some(&ToolChoice::Label("two".into())));
    let place = structure(6019);
    assert!(matches!(place.inner_as::<ToolChoice>(), Some(ToolChoice::Where(w)) if (w.x, w.y, w.z) == (0.5, 0.25, 0.125)));

    let kit = structure(6020);
    let kit = kit.inner_as::<Toolset>().expect("the generated Toolset");
    let tools = kit.tools.as_ref().expect("two tools");
    assert_eq!(tools.iter().map(|t| t.name.as_ref()).collect::<Vec<_>>(), ["Mill", "Tap"]);
    assert_eq!(tools[1].weights, Some(vec![]), "an empty array stays empty");
    let extra = kit.extra.inner_as::<parts::types::Marker>().expect("the Extra field, an ExtensionObject of parts");
    assert_eq!((extra.target.clone(), extra.name.clone()), (NodeId::new(other, 6001), QualifiedName::new(other, "RackSlot")));
    assert_eq!(kit.marks.as_ref().map(Vec::len), Some(2));
    assert_eq!(kit.unit.unit_id, 5066068);

    match value(6015) {
        Variant::Array(a) => {
            let names: Vec<String> = a.values.iter().map(|v| match v {
                Variant::ExtensionObject(eo) => eo.inner_as::<Tool>().expect("a Tool").name.to_string(),
                other => panic!("{other:?}"),
            }).collect();
            assert_eq!(names, ["Mill", "Tap"]);
        }
        other => panic!("Tools: {other:?}"),
    }
    let direction = structure(6021);
    let direction = direction.inner_as::<parts::types::Vector>().expect("a structure of the other namespace");
    assert_eq!((direction.x, direction.y, direction.z), (0.0, -1.0, 0.5));
}
