//! Tables imported into a real server: every attribute, value and reference lands as the table says, and
//! malformed tables are imported as far as they can be, without a panic.

mod common;

use common::serve;
use nodeset_examples::demo::{self, ids, DemoMode, DemoPoint};
use nodeset_models::runtime::import::parse_date_time;
use nodeset_models::runtime::server::ServerConfig;
use nodeset_models::runtime::table::{Def, FieldRow, Id, Kind, NodeRow, NodeSetTable, Nodes, Ref, StructureKind, Val};
use opcua::nodes::TypeTree;
use opcua::types::{
    Argument, AttributeId, BrowseDirection, EnumDefinition, EnumValueType, LocalizedText, NodeId, QualifiedName,
    StructureDefinition, StructureType, Variant, VariantScalarTypeId,
};

fn ext<T: Clone + Send + Sync + 'static>(v: &Variant) -> T {
    match v {
        Variant::ExtensionObject(eo) => eo.inner_as::<T>().cloned().expect("an ExtensionObject of the expected type"),
        other => panic!("not an ExtensionObject: {other:?}"),
    }
}

fn array(v: Variant) -> (VariantScalarTypeId, Vec<Variant>) {
    match v {
        Variant::Array(a) => (a.value_type, a.values),
        other => panic!("not an array: {other:?}"),
    }
}

#[tokio::test]
async fn demo_table_attributes_values_and_references() {
    let running = serve(ServerConfig::new("import test").table(&demo::TABLE)).await;
    let m = &running.manager;
    let ns = m.namespace_index(demo::NAMESPACE_URI).expect("the demo namespace is registered");
    assert_eq!(ns, 2, "the first table gets the first index after the server's own namespace");
    let id = |n: u32| NodeId::new(ns, n);
    let attr = |n: u32, a: AttributeId| running.attribute(&id(n), a).unwrap_or_else(|| panic!("{n} has {a:?}"));

    // Base attributes.
    assert_eq!(attr(ids::PUMP1, AttributeId::NodeClass), Variant::Int32(1));
    assert_eq!(attr(ids::PUMP1, AttributeId::BrowseName), Variant::from(QualifiedName::new(ns, "Pump1")));
    assert_eq!(attr(ids::PUMP1, AttributeId::DisplayName), Variant::from(LocalizedText::new("", "Pump1")));
    assert_eq!(attr(ids::PUMP1, AttributeId::Description), Variant::from(LocalizedText::new("", "The first pump.")));
    assert_eq!(attr(ids::PUMP1, AttributeId::WriteMask), Variant::UInt32(0));
    assert_eq!(attr(ids::PUMP1, AttributeId::EventNotifier), Variant::Byte(0));
    assert_eq!(
        attr(ids::DEMO_POINT_DEFAULT_BINARY, AttributeId::BrowseName),
        Variant::from(QualifiedName::new(0, "Default Binary"))
    );

    // Variables.
    assert_eq!(attr(ids::PUMP1_SPEED, AttributeId::DataType), Variant::from(NodeId::new(0, 11u32)));
    assert_eq!(attr(ids::PUMP1_SPEED, AttributeId::ValueRank), Variant::Int32(-1));
    assert_eq!(attr(ids::PUMP1_SPEED, AttributeId::AccessLevel), Variant::Byte(3));
    assert_eq!(attr(ids::PUMP1_SPEED, AttributeId::MinimumSamplingInterval), Variant::Double(100.0));
    assert_eq!(attr(ids::PUMP1_SPEED, AttributeId::Historizing), Variant::Boolean(false));
    assert_eq!(attr(ids::PUMP1_SPEED, AttributeId::Value), Variant::Double(12.5));
    assert_eq!(attr(ids::PUMP1_OPERATOR_ONLY, AttributeId::UserAccessLevel), Variant::Byte(1));
    assert_eq!(attr(ids::PUMP1_OPERATOR_ONLY, AttributeId::Historizing), Variant::Boolean(true));
    assert_eq!(attr(ids::PUMP1_MODE, AttributeId::DataType), Variant::from(id(ids::DEMO_MODE)));
    assert_eq!(attr(ids::PUMP1_MODE, AttributeId::Value), Variant::Int32(5));
    assert_eq!(attr(ids::PUMP1_TAGS, AttributeId::ValueRank), Variant::Int32(1));
    assert_eq!(attr(ids::PUMP1_TAGS, AttributeId::ArrayDimensions), Variant::from(vec![0u32]));
    assert_eq!(
        array(attr(ids::PUMP1_TAGS, AttributeId::Value)),
        (VariantScalarTypeId::String, vec![Variant::from("wet"), Variant::from("loud")])
    );
    assert_eq!(array(attr(ids::PUMP1_EMPTY, AttributeId::Value)), (VariantScalarTypeId::Int32, vec![]));
    assert_eq!(
        ext::<DemoPoint>(&attr(ids::PUMP1_POSITION, AttributeId::Value)),
        DemoPoint { x: 3.0, y: 4.0, label: "home".into(), mode: DemoMode::Fast }
    );
    assert_eq!(
        attr(ids::PUMP1_STAMP, AttributeId::Value),
        Variant::from(parse_date_time("2024-01-02T03:04:05Z").unwrap())
    );
    assert_eq!(attr(ids::PUMP1_NAME, AttributeId::Value), Variant::from(LocalizedText::new("en", "Feed pump")));

    // Methods and their Arguments, with our DataTypes mapped to the server's index.
    assert_eq!(attr(ids::PUMP1_START, AttributeId::Executable), Variant::Boolean(true));
    assert_eq!(attr(ids::PUMP1_DISABLED, AttributeId::Executable), Variant::Boolean(false));
    let (ty, args) = array(attr(ids::PUMP1_START_INPUT, AttributeId::Value));
    assert_eq!(ty, VariantScalarTypeId::ExtensionObject);
    let args: Vec<Argument> = args.iter().map(ext).collect();
    assert_eq!(args.len(), 2);
    assert_eq!(args[0].name.as_ref(), "Speed");
    assert_eq!(args[0].data_type, NodeId::new(0, 11u32));
    assert_eq!(args[1].data_type, id(ids::DEMO_MODE));
    assert_eq!(args[1].value_rank, -1);
    assert_eq!(args[1].description, LocalizedText::new("", "How fast."));

    // DataTypes and their definitions.
    let point: StructureDefinition = ext(&attr(ids::DEMO_POINT, AttributeId::DataTypeDefinition));
    assert_eq!(point.default_encoding_id, id(ids::DEMO_POINT_DEFAULT_BINARY));
    assert_eq!(point.base_data_type, NodeId::new(0, 22u32));
    assert_eq!(point.structure_type, StructureType::Structure);
    let fields = point.fields.unwrap();
    assert_eq!(fields.iter().map(|f| f.name.as_ref().to_owned()).collect::<Vec<_>>(), ["X", "Y", "Label", "Mode"]);
    assert_eq!(fields[3].data_type, id(ids::DEMO_MODE));
    assert_eq!(fields[2].description, LocalizedText::new("", "What the point is."));
    assert_eq!(attr(ids::DEMO_POINT, AttributeId::IsAbstract), Variant::Boolean(false));
    let mode: EnumDefinition = ext(&attr(ids::DEMO_MODE, AttributeId::DataTypeDefinition));
    let fields = mode.fields.unwrap();
    assert_eq!(
        fields.iter().map(|f| (f.value, f.name.as_ref().to_owned())).collect::<Vec<_>>(),
        [(0, "Off".to_owned()), (5, "Slow".to_owned()), (10, "Fast".to_owned())]
    );
    let (ty, values) = array(attr(ids::DEMO_MODE_ENUM_VALUES, AttributeId::Value));
    assert_eq!(ty, VariantScalarTypeId::ExtensionObject);
    let values: Vec<EnumValueType> = values.iter().map(ext).collect();
    assert_eq!(values[2].value, 10);
    assert_eq!(values[0].description, LocalizedText::new("", "Stopped."));
    assert!(running.attribute(&id(ids::DEMO_SPEED), AttributeId::DataTypeDefinition).is_none());

    // ReferenceType, VariableType.
    assert_eq!(attr(ids::FEEDS_INTO, AttributeId::Symmetric), Variant::Boolean(false));
    assert_eq!(attr(ids::FEEDS_INTO, AttributeId::InverseName), Variant::from(LocalizedText::new("", "FedFrom")));
    assert_eq!(attr(ids::SPEED_TYPE, AttributeId::Value), Variant::Double(0.0));
    assert_eq!(attr(ids::SPEED_TYPE, AttributeId::DataType), Variant::from(NodeId::new(0, 11u32)));

    // References, both directions, and the type tree (filled when the server is built).
    {
        let tree = running.handle.type_tree().read();
        assert!(tree.is_subtype_of(&id(ids::DEMO_POINT), &NodeId::new(0, 22u32)));
        assert!(tree.is_subtype_of(&id(ids::DEMO_SPEED), &NodeId::new(0, 11u32)));
        assert!(tree.is_subtype_of(&id(ids::FEEDS_INTO), &NodeId::new(0, 32u32)));
        let space = m.node_manager().address_space().read();
        let targets = |source: NodeId, reference_type: NodeId, direction| -> Vec<NodeId> {
            space
                .find_references(&source, Some((reference_type, false)), &*tree, direction)
                .map(|r| r.target_node.clone())
                .collect()
        };
        assert_eq!(targets(id(ids::PUMP1), id(ids::FEEDS_INTO), BrowseDirection::Forward), [id(ids::PUMP2)]);
        assert_eq!(targets(id(ids::PUMP2), id(ids::FEEDS_INTO), BrowseDirection::Inverse), [id(ids::PUMP1)]);
        assert_eq!(targets(id(ids::PUMP1), NodeId::new(0, 40u32), BrowseDirection::Forward), [id(ids::PUMP_TYPE)]);
        let organized = targets(NodeId::new(0, 85u32), NodeId::new(0, 35u32), BrowseDirection::Forward);
        assert!(organized.contains(&id(ids::PUMP1)) && organized.contains(&id(ids::PUMP2)));
        assert_eq!(
            targets(id(ids::DEMO_POINT), NodeId::new(0, 38u32), BrowseDirection::Forward),
            [id(ids::DEMO_POINT_DEFAULT_BINARY)]
        );
    }
    running.stop().await;
}

// A table with every kind of damage the import must survive.
const EDGE: Id = Id::numeric(1, 1);
const fn edge_row(id: Id, name: &'static str, kind: Kind, refs: &'static [Ref]) -> NodeRow {
    NodeRow {
        id,
        browse_name: (1, name),
        display_name: name,
        description: None,
        write_mask: 0,
        user_write_mask: 0,
        kind,
        refs,
        nrefs: &[],
    }
}
const fn var(data_type: Id, value: Val) -> Kind {
    Kind::Variable {
        data_type,
        value_rank: -2,
        array_dimensions: &[],
        access_level: 1,
        user_access_level: 1,
        historizing: false,
        minimum_sampling_interval: None,
        value,
    }
}
const OBJECT: Kind = Kind::Object { event_notifier: 0 };
const ORGANIZES: Id = Id::ns0(35);
const HAS_COMPONENT: Id = Id::ns0(47);

static EDGE_TABLE: NodeSetTable = NodeSetTable {
    namespace_uri: "urn:test:edge",
    version: "",
    publication_date: "not a date",
    namespaces: &["http://opcfoundation.org/UA/", "urn:test:edge", "urn:test:other"],
    own: 1,
    nodes: Nodes::Rows(&[
        edge_row(
            EDGE,
            "Good",
            OBJECT,
            &[
                Ref { reference_type: ORGANIZES, target: Id::ns0(85), forward: false },
                // A reference to itself, targets and types in namespaces the table does not have.
                Ref { reference_type: HAS_COMPONENT, target: EDGE, forward: true },
                Ref { reference_type: HAS_COMPONENT, target: Id::numeric(7, 5), forward: true },
                Ref { reference_type: Id::numeric(9, 1), target: Id::numeric(1, 2), forward: true },
                // A dangling reference into a namespace the table knows: kept.
                Ref { reference_type: HAS_COMPONENT, target: Id::numeric(2, 10), forward: true },
                Ref { reference_type: HAS_COMPONENT, target: Id::numeric(1, 2), forward: true },
            ],
        ),
        // The same damage in the numeric reference list, which the import reads on a path of its own.
        NodeRow {
            nrefs: &[(0, 35, 0, 85, false), (0, 47, 1, 11, true), (0, 47, 7, 5, true), (9, 1, 1, 2, true), (0, 47, 2, 10, true), (0, 47, 1, 2, true)],
            ..edge_row(Id::numeric(1, 11), "Numeric", OBJECT, &[])
        },
        // Nodes outside the table's own namespace.
        edge_row(Id::numeric(2, 3), "Foreign", OBJECT, &[]),
        edge_row(Id::numeric(5, 4), "Unregistered", OBJECT, &[]),
        // The same NodeId twice: the first row wins.
        edge_row(EDGE, "Duplicate", OBJECT, &[]),
        // Values that cannot be built as written.
        edge_row(Id::numeric(1, 2), "BadDate", var(Id::numeric(7, 1), Val::DateTime("yesterday")), &[]),
        edge_row(Id::numeric(1, 3), "Mixed", var(Id::ns0(6), Val::Array(6, &[Val::Int32(1), Val::String("x")])), &[]),
        edge_row(Id::numeric(1, 4), "Name", var(Id::ns0(20), Val::QualifiedName(8, "x")), &[]),
        edge_row(Id::numeric(1, 5), "Durations", var(Id::ns0(290), Val::Array(290, &[])), &[]),
        edge_row(Id::numeric(1, 8), "Node", var(Id::ns0(17), Val::NodeId(Id::numeric(2, 77))), &[]),
        // A structure that does not name its encoding: found through HasEncoding "Default Binary".
        edge_row(
            Id::numeric(1, 6),
            "Blob",
            Kind::DataType {
                is_abstract: false,
                definition: Some(Def::Structure {
                    base: Id::ns0(22),
                    default_encoding: None,
                    kind: StructureKind::StructureWithOptionalFields,
                    fields: &[FieldRow {
                        name: "Size",
                        description: None,
                        data_type: Id::numeric(6, 1),
                        value_rank: -1,
                        array_dimensions: &[],
                        max_string_length: 0,
                        is_optional: true,
                    }],
                }),
            },
            &[
                Ref { reference_type: Id::ns0(45), target: Id::ns0(22), forward: false },
                Ref { reference_type: Id::ns0(38), target: Id::numeric(1, 9), forward: true },
                Ref { reference_type: Id::ns0(38), target: Id::numeric(1, 7), forward: true },
            ],
        ),
        NodeRow { browse_name: (0, "Default Binary"), ..edge_row(Id::numeric(1, 7), "Default Binary", OBJECT, &[]) },
        NodeRow { browse_name: (0, "Default XML"), ..edge_row(Id::numeric(1, 9), "Default XML", OBJECT, &[]) },
    ]),
};

/// A table whose own namespace index is 0 imports nothing.
static NS0_TABLE: NodeSetTable = NodeSetTable {
    namespace_uri: "urn:test:zero",
    version: "1",
    publication_date: "2020-01-01",
    namespaces: &["http://opcfoundation.org/UA/"],
    own: 0,
    nodes: Nodes::Rows(&[edge_row(Id::ns0(99999), "Intruder", OBJECT, &[])]),
};

#[tokio::test]
async fn malformed_tables_import_without_panics() {
    let running = serve(ServerConfig::new("edge test").table(&EDGE_TABLE).table(&NS0_TABLE)).await;
    let ns = running.manager.namespace_index("urn:test:edge").unwrap();
    let other = running.manager.namespace_index("urn:test:other").unwrap();
    let id = |n: u32| NodeId::new(ns, n);
    let attr = |n: u32, a: AttributeId| running.attribute(&id(n), a);

    assert_eq!(attr(1, AttributeId::BrowseName), Some(Variant::from(QualifiedName::new(ns, "Good"))));
    assert!(running.attribute(&NodeId::new(other, 3u32), AttributeId::NodeClass).is_none(), "foreign rows are skipped");
    assert!(running.attribute(&NodeId::new(0, 99999u32), AttributeId::NodeClass).is_none(), "ns0 rows are skipped");
    assert_eq!(running.manager.namespace_index("urn:test:zero"), None, "a table of namespace 0 is not served");
    assert_eq!(attr(2, AttributeId::DataType), Some(Variant::from(NodeId::null())));
    assert_eq!(attr(2, AttributeId::Value), Some(Variant::from(opcua::types::DateTime::null())));
    assert_eq!(attr(3, AttributeId::Value), Some(Variant::Empty));
    assert_eq!(attr(4, AttributeId::Value), Some(Variant::from(QualifiedName::new(0, "x"))));
    assert_eq!(array(attr(5, AttributeId::Value).unwrap()), (VariantScalarTypeId::Variant, vec![]));
    assert_eq!(attr(8, AttributeId::Value), Some(Variant::from(NodeId::new(other, 77u32))));
    let blob: StructureDefinition = ext(&attr(6, AttributeId::DataTypeDefinition).unwrap());
    assert_eq!(blob.default_encoding_id, id(7));
    assert_eq!(blob.structure_type, StructureType::StructureWithOptionalFields);
    assert_eq!(blob.fields.unwrap()[0].data_type, NodeId::null());

    {
        let tree = running.handle.type_tree().read();
        let space = running.manager.node_manager().address_space().read();
        let targets = |node: u32, reference_type: u32, direction| -> Vec<NodeId> {
            space
                .find_references(&id(node), Some((NodeId::new(0, reference_type), false)), &*tree, direction)
                .map(|r| r.target_node.clone())
                .collect()
        };
        // The row's `refs` (node 1) and its numeric references (node 11, read on a path of their own) carry
        // the same damage.
        for node in [1, 11] {
            let components = targets(node, 47, BrowseDirection::Forward);
            assert!(components.contains(&id(2)) && components.contains(&NodeId::new(other, 10u32)));
            assert_eq!(components.len(), 2, "node {node}: the self reference and the unregistered ones are skipped: {components:?}");
            let organized_by = targets(node, 35, BrowseDirection::Inverse);
            assert_eq!(organized_by, [NodeId::new(0, 85u32)]);
        }
    }
    running.stop().await;
}

// Two tables, the second depending on the first and on a namespace nobody serves.
static TABLE_A: NodeSetTable = NodeSetTable {
    namespace_uri: "urn:test:a",
    version: "1.0",
    publication_date: "2020-01-01T00:00:00Z",
    namespaces: &["http://opcfoundation.org/UA/", "urn:test:a"],
    own: 1,
    nodes: Nodes::Rows(&[edge_row(
        Id::numeric(1, 100),
        "AType",
        Kind::ObjectType { is_abstract: true },
        &[Ref { reference_type: Id::ns0(45), target: Id::ns0(58), forward: false }],
    )]),
};
static TABLE_B: NodeSetTable = NodeSetTable {
    namespace_uri: "urn:test:b",
    version: "2.0",
    publication_date: "2021-01-01",
    namespaces: &["http://opcfoundation.org/UA/", "urn:test:missing", "urn:test:a", "urn:test:b"],
    own: 3,
    nodes: Nodes::Rows(&[NodeRow {
        browse_name: (3, "BType"),
        ..edge_row(
            Id::numeric(3, 200),
            "BType",
            Kind::ObjectType { is_abstract: false },
            &[
                Ref { reference_type: Id::ns0(45), target: Id::numeric(2, 100), forward: false },
                Ref { reference_type: Id::ns0(47), target: Id::numeric(1, 5), forward: true },
            ],
        )
    }]),
};

#[tokio::test]
async fn namespaces_follow_the_order_of_the_tables() {
    let running = serve(ServerConfig::new("order test").table(&TABLE_B).table(&TABLE_A).table(&TABLE_A)).await;
    let m = &running.manager;
    assert_eq!(m.namespace_index("urn:test:b"), Some(2));
    assert_eq!(m.namespace_index("urn:test:a"), Some(3));
    assert_eq!(m.namespace_index("urn:test:missing"), Some(4));
    assert_eq!(m.namespace_map("urn:test:b").unwrap().indices, [0, 4, 3, 2]);
    let b_type = NodeId::new(2, 200u32);
    assert_eq!(
        running.attribute(&b_type, AttributeId::BrowseName),
        Some(Variant::from(QualifiedName::new(2, "BType")))
    );
    assert!(running.handle.type_tree().read().is_subtype_of(&b_type, &NodeId::new(3, 100u32)));
    assert!(running.handle.type_tree().read().is_subtype_of(&b_type, &NodeId::new(0, 58u32)));

    let (session, event_loop) = common::connect(&running.url).await;
    let (_, array) = common::read(&session, &NodeId::new(0, 2255u32), AttributeId::Value).await;
    let uris: Vec<String> = match array {
        Variant::Array(a) => a.values.iter().map(|v| v.to_string()).collect(),
        other => panic!("NamespaceArray is {other:?}"),
    };
    assert_eq!(uris[0], "http://opcfoundation.org/UA/");
    assert_eq!(uris[1], "urn:nodeset-models:order-test");
    assert_eq!(&uris[2..5], ["urn:test:b", "urn:test:a", "urn:test:missing"]);
    // The namespace of instances created at run time comes after every table's namespaces.
    assert_eq!(&uris[5..], ["urn:nodeset-models:order-test:instances"]);
    assert_eq!(m.instance_namespace(), 5);
    common::disconnect(session, event_loop).await;
    running.stop().await;
}

#[tokio::test]
async fn values_are_checked_before_the_server_runs() {
    common::init_tracing();
    let server = ServerConfig::new("early").table(&demo::TABLE).insecure_only().build().unwrap();
    let m = server.manager();
    let limit = m.resolve(demo::node(ids::PUMP1_LIMIT)).unwrap();
    let speed = m.resolve(demo::node(ids::PUMP1_SPEED)).unwrap();
    assert_eq!(m.set_value(&limit, 80.0), Ok(()), "a Double fits DemoSpeed, a subtype of Double");
    assert_eq!(m.set_value(&limit, "fast"), Err(opcua::types::StatusCode::BadTypeMismatch));
    assert_eq!(m.set_value(&speed, 1i32), Err(opcua::types::StatusCode::BadTypeMismatch));
    assert_eq!(m.value(&limit).and_then(|dv| dv.value), Some(Variant::Double(80.0)));
}
