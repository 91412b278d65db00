//! A small hand-written namespace in the shape generated code has: a table, a structure and an
//! enumeration with their Rust types, a type loader and NodeId constants.
//!
//! It exercises every feature of the runtime (all node classes but View, a structure with its encoding and
//! definition, an enumeration with EnumValues, a DataType derived from Double, a custom reference type, an
//! ObjectType with an instance declaration, methods with Arguments, typed and empty arrays, read-only and
//! writable variables), so the runtime's tests, the example server (`--demo`) and the Python
//! interoperability check use it. Writing it by hand also documents what the emitter produces.

use std::sync::LazyLock;

use opcua::types::{
    binary_decode_to_enc, ExpandedMessageInfo, ExpandedNodeId, StaticTypeLoader, TypeLoaderInstance, UAString,
};

use nodeset_runtime::table::{ArgRow, Def, EnumRow, FieldRow, Id, Kind, NodeRow, NodeSetTable, Nodes, Ref, StructureKind, Val};
use nodeset_runtime::NsNodeId;

/// The demo namespace URI.
pub const NAMESPACE_URI: &str = "urn:nodeset-models:demo";

/// Numeric identifiers of the demo nodes (in the demo namespace), named after their browse paths.
#[allow(missing_docs)]
pub mod ids {
    pub const DEMO_POINT: u32 = 1000;
    pub const DEMO_POINT_DEFAULT_BINARY: u32 = 1001;
    pub const DEMO_MODE: u32 = 1010;
    pub const DEMO_MODE_ENUM_VALUES: u32 = 1011;
    pub const DEMO_SPEED: u32 = 1020;
    pub const FEEDS_INTO: u32 = 1030;
    pub const PUMP_TYPE: u32 = 2000;
    pub const PUMP_TYPE_SPEED: u32 = 2001;
    pub const SPEED_TYPE: u32 = 2010;
    pub const PUMP1: u32 = 5000;
    pub const PUMP1_SPEED: u32 = 5001;
    pub const PUMP1_MODE: u32 = 5002;
    pub const PUMP1_POSITION: u32 = 5003;
    pub const PUMP1_COUNTER: u32 = 5004;
    pub const PUMP1_TAGS: u32 = 5005;
    pub const PUMP1_EMPTY: u32 = 5006;
    pub const PUMP1_LIMIT: u32 = 5007;
    pub const PUMP1_START: u32 = 5008;
    pub const PUMP1_START_INPUT: u32 = 5009;
    pub const PUMP1_START_OUTPUT: u32 = 5010;
    pub const PUMP1_MOVE: u32 = 5011;
    pub const PUMP1_MOVE_INPUT: u32 = 5012;
    pub const PUMP1_MOVE_OUTPUT: u32 = 5013;
    pub const PUMP1_DISABLED: u32 = 5014;
    pub const PUMP1_STAMP: u32 = 5015;
    pub const PUMP1_OPERATOR_ONLY: u32 = 5016;
    pub const PUMP1_NAME: u32 = 5017;
    pub const PUMP2: u32 = 5100;
}

/// A demo NodeId as generated constants name it.
pub const fn node(id: u32) -> NsNodeId {
    NsNodeId::numeric(NAMESPACE_URI, id)
}

/// DemoMode, an enumeration with gaps.
#[opcua::types::ua_encodable]
#[derive(Debug, Copy, Clone, PartialEq, Eq)]
#[repr(i32)]
pub enum DemoMode {
    /// Stopped.
    #[opcua(default)]
    Off = 0,
    /// Running slowly.
    Slow = 5,
    /// Running fast.
    Fast = 10,
}

/// DemoPoint, a structure with a field of an enumeration type.
#[opcua::types::ua_encodable]
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DemoPoint {
    /// The X coordinate.
    pub x: f64,
    /// The Y coordinate.
    pub y: f64,
    /// What the point is.
    pub label: UAString,
    /// How fast to get there.
    pub mode: DemoMode,
}

impl ExpandedMessageInfo for DemoPoint {
    fn full_type_id(&self) -> ExpandedNodeId {
        ExpandedNodeId::from((ids::DEMO_POINT_DEFAULT_BINARY, NAMESPACE_URI))
    }
    fn full_json_type_id(&self) -> ExpandedNodeId {
        ExpandedNodeId::from((ids::DEMO_POINT, NAMESPACE_URI))
    }
    fn full_xml_type_id(&self) -> ExpandedNodeId {
        ExpandedNodeId::from((ids::DEMO_POINT, NAMESPACE_URI))
    }
    fn full_data_type_id(&self) -> ExpandedNodeId {
        ExpandedNodeId::from((ids::DEMO_POINT, NAMESPACE_URI))
    }
}

/// Decodes DemoPoint bodies for servers and clients (`ServerConfig::type_loader`,
/// `Session::add_type_loader`).
pub struct TypeLoader;

static TYPES: LazyLock<TypeLoaderInstance> = LazyLock::new(|| {
    let mut types = TypeLoaderInstance::new();
    types.add_binary_type(ids::DEMO_POINT, ids::DEMO_POINT_DEFAULT_BINARY, binary_decode_to_enc::<DemoPoint>);
    types
});

impl StaticTypeLoader for TypeLoader {
    fn instance() -> &'static TypeLoaderInstance {
        &TYPES
    }
    fn namespace() -> &'static str {
        NAMESPACE_URI
    }
}

const fn own(n: u32) -> Id {
    Id::numeric(1, n)
}
const fn fwd(reference_type: Id, target: Id) -> Ref {
    Ref { reference_type, target, forward: true }
}
const fn inv(reference_type: Id, target: Id) -> Ref {
    Ref { reference_type, target, forward: false }
}

const ORGANIZES: Id = Id::ns0(35);
const HAS_MODELLING_RULE: Id = Id::ns0(37);
const HAS_ENCODING: Id = Id::ns0(38);
const HAS_TYPE_DEFINITION: Id = Id::ns0(40);
const HAS_SUBTYPE: Id = Id::ns0(45);
const HAS_PROPERTY: Id = Id::ns0(46);
const HAS_COMPONENT: Id = Id::ns0(47);
const NON_HIERARCHICAL_REFERENCES: Id = Id::ns0(32);
const OBJECTS_FOLDER: Id = Id::ns0(85);
const BASE_OBJECT_TYPE: Id = Id::ns0(58);
const BASE_DATA_VARIABLE_TYPE: Id = Id::ns0(63);
const PROPERTY_TYPE: Id = Id::ns0(68);
const DATA_TYPE_ENCODING_TYPE: Id = Id::ns0(76);
const MANDATORY: Id = Id::ns0(78);
const BOOLEAN: Id = Id::ns0(1);
const INT32: Id = Id::ns0(6);
const DOUBLE: Id = Id::ns0(11);
const STRING: Id = Id::ns0(12);
const DATE_TIME: Id = Id::ns0(13);
const LOCALIZED_TEXT: Id = Id::ns0(21);
const STRUCTURE: Id = Id::ns0(22);
const ENUMERATION: Id = Id::ns0(29);
const ARGUMENT: Id = Id::ns0(296);
const ENUM_VALUE_TYPE: Id = Id::ns0(7594);

const READ: u8 = 1;
const READ_WRITE: u8 = 3;

const MODE_VALUES: &[EnumRow] = &[
    EnumRow { value: 0, name: "Off", display_name: "Off", description: Some("Stopped.") },
    EnumRow { value: 5, name: "Slow", display_name: "Slow", description: None },
    EnumRow { value: 10, name: "Fast", display_name: "Fast", description: None },
];

const fn variable(data_type: Id, value_rank: i32, access_level: u8, value: Val) -> Kind {
    Kind::Variable {
        data_type,
        value_rank,
        array_dimensions: &[],
        access_level,
        user_access_level: access_level,
        historizing: false,
        minimum_sampling_interval: None,
        value,
    }
}

const fn row(id: u32, name: &'static str, kind: Kind, refs: &'static [Ref]) -> NodeRow {
    NodeRow {
        id: own(id),
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

const fn property(id: u32, name: &'static str, data_type: Id, value: Val) -> NodeRow {
    NodeRow {
        id: own(id),
        browse_name: (0, name),
        display_name: name,
        description: None,
        write_mask: 0,
        user_write_mask: 0,
        kind: variable(data_type, 1, READ, value),
        refs: PROPERTY_REFS,
        nrefs: &[],
    }
}

const PROPERTY_REFS: &[Ref] = &[fwd(HAS_TYPE_DEFINITION, PROPERTY_TYPE)];

fn position(_: &nodeset_runtime::NamespaceMap) -> opcua::types::Variant {
    DemoPoint { x: 3.0, y: 4.0, label: "home".into(), mode: DemoMode::Fast }.into()
}

/// The demo namespace's nodes.
pub static TABLE: NodeSetTable = NodeSetTable {
    namespace_uri: NAMESPACE_URI,
    version: "1.0.0",
    publication_date: "2024-01-01T00:00:00Z",
    namespaces: &["http://opcfoundation.org/UA/", NAMESPACE_URI],
    own: 1,
    nodes: Nodes::Rows(&[
        // Types.
        NodeRow {
            description: Some("A point with a label."),
            ..row(
                ids::DEMO_POINT,
                "DemoPoint",
                Kind::DataType {
                    is_abstract: false,
                    definition: Some(Def::Structure {
                        base: STRUCTURE,
                        default_encoding: Some(own(ids::DEMO_POINT_DEFAULT_BINARY)),
                        kind: StructureKind::Structure,
                        fields: &[
                            FieldRow {
                                name: "X",
                                description: None,
                                data_type: DOUBLE,
                                value_rank: -1,
                                array_dimensions: &[],
                                max_string_length: 0,
                                is_optional: false,
                            },
                            FieldRow {
                                name: "Y",
                                description: None,
                                data_type: DOUBLE,
                                value_rank: -1,
                                array_dimensions: &[],
                                max_string_length: 0,
                                is_optional: false,
                            },
                            FieldRow {
                                name: "Label",
                                description: Some("What the point is."),
                                data_type: STRING,
                                value_rank: -1,
                                array_dimensions: &[],
                                max_string_length: 0,
                                is_optional: false,
                            },
                            FieldRow {
                                name: "Mode",
                                description: None,
                                data_type: own(ids::DEMO_MODE),
                                value_rank: -1,
                                array_dimensions: &[],
                                max_string_length: 0,
                                is_optional: false,
                            },
                        ],
                    }),
                },
                &[inv(HAS_SUBTYPE, STRUCTURE), fwd(HAS_ENCODING, own(ids::DEMO_POINT_DEFAULT_BINARY))],
            )
        },
        NodeRow {
            id: own(ids::DEMO_POINT_DEFAULT_BINARY),
            browse_name: (0, "Default Binary"),
            display_name: "Default Binary",
            description: None,
            write_mask: 0,
            user_write_mask: 0,
            kind: Kind::Object { event_notifier: 0 },
            refs: &[fwd(HAS_TYPE_DEFINITION, DATA_TYPE_ENCODING_TYPE)],
            nrefs: &[],
        },
        row(
            ids::DEMO_MODE,
            "DemoMode",
            Kind::DataType { is_abstract: false, definition: Some(Def::Enum { fields: MODE_VALUES }) },
            &[inv(HAS_SUBTYPE, ENUMERATION), fwd(HAS_PROPERTY, own(ids::DEMO_MODE_ENUM_VALUES))],
        ),
        property(ids::DEMO_MODE_ENUM_VALUES, "EnumValues", ENUM_VALUE_TYPE, Val::EnumValues(MODE_VALUES)),
        row(
            ids::DEMO_SPEED,
            "DemoSpeed",
            Kind::DataType { is_abstract: false, definition: None },
            &[inv(HAS_SUBTYPE, DOUBLE)],
        ),
        row(
            ids::FEEDS_INTO,
            "FeedsInto",
            Kind::ReferenceType { symmetric: false, is_abstract: false, inverse_name: Some("FedFrom") },
            &[inv(HAS_SUBTYPE, NON_HIERARCHICAL_REFERENCES)],
        ),
        row(
            ids::PUMP_TYPE,
            "PumpType",
            Kind::ObjectType { is_abstract: false },
            &[inv(HAS_SUBTYPE, BASE_OBJECT_TYPE), fwd(HAS_COMPONENT, own(ids::PUMP_TYPE_SPEED))],
        ),
        row(
            ids::PUMP_TYPE_SPEED,
            "Speed",
            variable(DOUBLE, -1, READ_WRITE, Val::Double(0.0)),
            &[fwd(HAS_TYPE_DEFINITION, own(ids::SPEED_TYPE)), fwd(HAS_MODELLING_RULE, MANDATORY)],
        ),
        row(
            ids::SPEED_TYPE,
            "SpeedType",
            Kind::VariableType {
                data_type: DOUBLE,
                value_rank: -1,
                array_dimensions: &[],
                is_abstract: false,
                value: Val::Double(0.0),
            },
            &[inv(HAS_SUBTYPE, BASE_DATA_VARIABLE_TYPE)],
        ),
        // Instances.
        NodeRow {
            description: Some("The first pump."),
            ..row(
                ids::PUMP1,
                "Pump1",
                Kind::Object { event_notifier: 0 },
                &[
                    inv(ORGANIZES, OBJECTS_FOLDER),
                    fwd(HAS_TYPE_DEFINITION, own(ids::PUMP_TYPE)),
                    fwd(own(ids::FEEDS_INTO), own(ids::PUMP2)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_SPEED)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_MODE)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_POSITION)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_COUNTER)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_TAGS)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_EMPTY)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_LIMIT)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_START)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_MOVE)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_DISABLED)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_STAMP)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_OPERATOR_ONLY)),
                    fwd(HAS_COMPONENT, own(ids::PUMP1_NAME)),
                ],
            )
        },
        NodeRow {
            kind: Kind::Variable {
                data_type: DOUBLE,
                value_rank: -1,
                array_dimensions: &[],
                access_level: READ_WRITE,
                user_access_level: READ_WRITE,
                historizing: false,
                minimum_sampling_interval: Some(100.0),
                value: Val::Double(12.5),
            },
            ..row(
                ids::PUMP1_SPEED,
                "Speed",
                variable(DOUBLE, -1, READ_WRITE, Val::None),
                &[fwd(HAS_TYPE_DEFINITION, own(ids::SPEED_TYPE))],
            )
        },
        row(
            ids::PUMP1_MODE,
            "Mode",
            variable(own(ids::DEMO_MODE), -1, READ_WRITE, Val::Int32(5)),
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_POSITION,
            "Position",
            variable(own(ids::DEMO_POINT), -1, READ_WRITE, Val::Struct(position)),
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_COUNTER,
            "Counter",
            variable(INT32, -1, READ, Val::Int32(0)),
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_TAGS,
            "Tags",
            Kind::Variable {
                data_type: STRING,
                value_rank: 1,
                array_dimensions: &[0],
                access_level: READ_WRITE,
                user_access_level: READ_WRITE,
                historizing: false,
                minimum_sampling_interval: None,
                value: Val::Array(12, &[Val::String("wet"), Val::String("loud")]),
            },
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_EMPTY,
            "Empty",
            variable(INT32, 1, READ, Val::Array(6, &[])),
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_LIMIT,
            "Limit",
            variable(own(ids::DEMO_SPEED), -1, READ_WRITE, Val::Double(100.0)),
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_START,
            "Start",
            Kind::Method { executable: true, user_executable: true },
            &[fwd(HAS_PROPERTY, own(ids::PUMP1_START_INPUT)), fwd(HAS_PROPERTY, own(ids::PUMP1_START_OUTPUT))],
        ),
        property(
            ids::PUMP1_START_INPUT,
            "InputArguments",
            ARGUMENT,
            Val::Arguments(&[
                ArgRow { name: "Speed", data_type: DOUBLE, value_rank: -1, array_dimensions: &[], description: None },
                ArgRow {
                    name: "Mode",
                    data_type: own(ids::DEMO_MODE),
                    value_rank: -1,
                    array_dimensions: &[],
                    description: Some("How fast."),
                },
            ]),
        ),
        property(
            ids::PUMP1_START_OUTPUT,
            "OutputArguments",
            ARGUMENT,
            Val::Arguments(&[ArgRow {
                name: "Accepted",
                data_type: BOOLEAN,
                value_rank: -1,
                array_dimensions: &[],
                description: None,
            }]),
        ),
        row(
            ids::PUMP1_MOVE,
            "Move",
            Kind::Method { executable: true, user_executable: true },
            &[fwd(HAS_PROPERTY, own(ids::PUMP1_MOVE_INPUT)), fwd(HAS_PROPERTY, own(ids::PUMP1_MOVE_OUTPUT))],
        ),
        property(
            ids::PUMP1_MOVE_INPUT,
            "InputArguments",
            ARGUMENT,
            Val::Arguments(&[ArgRow {
                name: "Target",
                data_type: own(ids::DEMO_POINT),
                value_rank: -1,
                array_dimensions: &[],
                description: None,
            }]),
        ),
        property(
            ids::PUMP1_MOVE_OUTPUT,
            "OutputArguments",
            ARGUMENT,
            Val::Arguments(&[ArgRow {
                name: "Distance",
                data_type: DOUBLE,
                value_rank: -1,
                array_dimensions: &[],
                description: None,
            }]),
        ),
        row(ids::PUMP1_DISABLED, "Disabled", Kind::Method { executable: false, user_executable: true }, &[]),
        row(
            ids::PUMP1_STAMP,
            "Stamp",
            variable(DATE_TIME, -1, READ, Val::DateTime("2024-01-02T03:04:05Z")),
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_OPERATOR_ONLY,
            "OperatorOnly",
            Kind::Variable {
                data_type: INT32,
                value_rank: -1,
                array_dimensions: &[],
                access_level: READ_WRITE,
                user_access_level: READ,
                historizing: true,
                minimum_sampling_interval: None,
                value: Val::Int32(7),
            },
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP1_NAME,
            "Name",
            variable(LOCALIZED_TEXT, -1, READ_WRITE, Val::LocalizedText(Some("en"), "Feed pump")),
            &[fwd(HAS_TYPE_DEFINITION, BASE_DATA_VARIABLE_TYPE)],
        ),
        row(
            ids::PUMP2,
            "Pump2",
            Kind::Object { event_notifier: 0 },
            &[inv(ORGANIZES, OBJECTS_FOLDER), fwd(HAS_TYPE_DEFINITION, own(ids::PUMP_TYPE))],
        ),
    ]),
};
