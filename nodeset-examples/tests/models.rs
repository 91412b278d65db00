//! The generated DI, IA and Robotics tables, and our skill models on them, import completely into a server:
//! every row becomes a node, the namespaces get the indices of the order they are given in, and the types
//! join the type tree.

mod common;

use nodeset_models::models::{self, common_skills, di, drilling_process, ia, robot_cell, robotics};
use nodeset_models::runtime::server::ServerConfig;
use nodeset_models::runtime::table::{Id, NodeSetTable};
use opcua::nodes::TypeTree;
use opcua::types::{AttributeId, NodeId};

/// The table's NamespaceMetadata object (under Server/Namespaces) and its properties: the server folds them
/// into the object async-opcua keeps for every namespace it serves, so they are not imported as rows.
fn folded(table: &NodeSetTable) -> Vec<Id> {
    const HAS_TYPE_DEFINITION: Id = Id::ns0(40);
    const HAS_PROPERTY: Id = Id::ns0(46);
    const NAMESPACE_METADATA_TYPE: Id = Id::ns0(11616);
    let rows = table.rows().expect("the table decodes");
    let objects: Vec<Id> = rows
        .iter()
        .filter(|r| r.references().any(|x| x.forward && x.reference_type == HAS_TYPE_DEFINITION && x.target == NAMESPACE_METADATA_TYPE))
        .map(|r| r.id)
        .collect();
    let mut folded = objects.clone();
    for r in rows {
        for x in r.references().filter(|x| x.reference_type == HAS_PROPERTY) {
            if x.forward && objects.contains(&r.id) {
                folded.push(x.target);
            } else if !x.forward && objects.contains(&x.target) {
                folded.push(r.id);
            }
        }
    }
    folded
}

const TABLES: [&NodeSetTable; 3] = [&di::TABLE, &ia::TABLE, &robotics::TABLE];

#[tokio::test]
async fn generated_tables_import_completely() {
    let running = common::serve(
        ServerConfig::new("models test")
            .table(&di::TABLE)
            .type_loader(di::TypeLoader)
            .table(&ia::TABLE)
            .type_loader(ia::TypeLoader)
            .table(&robotics::TABLE)
            .type_loader(robotics::TypeLoader),
    )
    .await;
    let m = &running.manager;
    assert_eq!(m.namespace_index(di::NAMESPACE_URI), Some(2));
    assert_eq!(m.namespace_index(ia::NAMESPACE_URI), Some(3));
    assert_eq!(m.namespace_index(robotics::NAMESPACE_URI), Some(4));

    for table in TABLES {
        let map = m.namespace_map(table.namespace_uri).expect("the table is served");
        let folded = folded(table);
        let missing: Vec<_> = table
            .rows()
            .expect("the table decodes")
            .iter()
            .filter(|row| !folded.contains(&row.id))
            .map(|row| map.try_id(row.id).expect("every row's namespace is registered"))
            .filter(|id| running.attribute(id, AttributeId::NodeClass).is_none())
            .collect();
        assert!(missing.is_empty(), "{}: rows missing from the address space: {missing:?}", table.namespace_uri);
        assert!(!folded.is_empty(), "{}: the table has a NamespaceMetadata object", table.namespace_uri);
        let kept: Vec<_> = folded
            .iter()
            .map(|id| map.try_id(*id).expect("registered"))
            .filter(|id| running.attribute(id, AttributeId::NodeClass).is_some())
            .collect();
        assert!(kept.is_empty(), "{}: NamespaceMetadata rows served beside async-opcua's own: {kept:?}", table.namespace_uri);
        let mut served: Vec<String> = m.node_manager().address_space().read().namespaces().values().cloned().collect();
        served.sort();
        let mut expected: Vec<String> = TABLES.iter().map(|t| t.namespace_uri.to_owned()).collect();
        // The namespace of instances created at run time (`ModelManager::instantiate`) is the manager's too.
        expected.push("urn:nodeset-models:models-test:instances".to_owned());
        expected.sort();
        assert_eq!(served, expected, "the node manager owns the three namespaces and the instance namespace");
    }

    // MotionDeviceSystemType (Robotics i=1002) derives from DI's ComponentType (i=15063).
    {
        let tree = running.handle.type_tree().read();
        assert!(tree.is_subtype_of(&NodeId::new(4, 1002u32), &NodeId::new(2, 15063u32)));
        assert!(tree.is_subtype_of(&NodeId::new(4, 1002u32), &NodeId::new(0, 58u32)));
    }
    running.stop().await;
}

const SKILL_TABLES: [&NodeSetTable; 6] =
    [&di::TABLE, &ia::TABLE, &robotics::TABLE, &common_skills::TABLE, &robot_cell::TABLE, &drilling_process::TABLE];

#[tokio::test]
async fn skill_tables_import_completely() {
    let running = common::serve(
        models::register(ServerConfig::new("skills test")),
    )
    .await;
    let m = &running.manager;
    for (i, table) in SKILL_TABLES.iter().enumerate() {
        assert_eq!(m.namespace_index(table.namespace_uri), Some(i as u16 + 2), "{}", table.namespace_uri);
        let map = m.namespace_map(table.namespace_uri).expect("the table is served");
        let folded = folded(table);
        let missing: Vec<_> = table
            .rows()
            .expect("the table decodes")
            .iter()
            .filter(|row| !folded.contains(&row.id))
            .map(|row| map.try_id(row.id).expect("every row's namespace is registered"))
            .filter(|id| running.attribute(id, AttributeId::NodeClass).is_none())
            .collect();
        assert!(missing.is_empty(), "{}: rows missing from the address space: {missing:?}", table.namespace_uri);
    }
    // DrillHoleSkillType (DrillingProcess) -> CompositeSkillType -> ProgramSkillStateMachineType (CommonSkills)
    // -> ProgramStateMachineType (ns0 i=2391).
    {
        let tree = running.handle.type_tree().read();
        let drill_hole = m.resolve(drilling_process::ids::object_types::DRILL_HOLE_SKILL_TYPE).unwrap();
        let composite = m.resolve(common_skills::ids::object_types::COMPOSITE_SKILL_TYPE).unwrap();
        assert!(tree.is_subtype_of(&drill_hole, &composite));
        assert!(tree.is_subtype_of(&drill_hole, &NodeId::new(0, 2391u32)));
    }
    running.stop().await;
}

/// The runtime names CommonSkills' SkillTransitionEventType itself (so that it builds without the generated
/// models); it must be the generated constant.
#[test]
fn skill_transition_event_type_matches_the_generated_id() {
    assert_eq!(
        nodeset_models::runtime::typed::program::SKILL_TRANSITION_EVENT_TYPE,
        common_skills::ids::object_types::SKILL_TRANSITION_EVENT_TYPE
    );
    assert_eq!(
        nodeset_models::runtime::typed::program::SKILL_TRANSITION_EVENT_TYPE.namespace_uri,
        common_skills::NAMESPACE_URI
    );
}

/// A placeholder's instances bind in BrowseName order whatever order they were created in, and are found by
/// BrowseName.
#[tokio::test]
async fn placeholder_instances_bind_by_browse_name() {
    use nodeset_models::runtime::typed::{Instantiate, ObjectType};
    let running = common::serve(
        ServerConfig::new("placeholders")
            .table(&di::TABLE)
            .type_loader(di::TypeLoader)
            .table(&ia::TABLE)
            .type_loader(ia::TypeLoader)
            .table(&robotics::TABLE)
            .type_loader(robotics::TypeLoader),
    )
    .await;
    let objects = NodeId::from(opcua::types::ObjectId::ObjectsFolder);
    let mut options = Instantiate::new()
        .placeholder("MotionDevices/<MotionDeviceIdentifier>", ["Right", "Left"])
        .placeholder("Controllers/<ControllerIdentifier>", ["Controller"])
        .placeholder("SafetyStates/<SafetyStateIdentifier>", ["SafetyState"])
        .placeholder("Controllers/Controller/Software/<SoftwareIdentifier>", ["Software"])
        .placeholder("Controllers/Controller/TaskControls/<TaskControlIdentifier>", ["Task"]);
    for arm in ["Right", "Left"] {
        options = options
            .placeholder(format!("MotionDevices/{arm}/Axes/<AxisIdentifier>"), ["A1"])
            .placeholder(format!("MotionDevices/{arm}/PowerTrains/<PowerTrainIdentifier>"), ["PT1"])
            .placeholder(format!("MotionDevices/{arm}/PowerTrains/PT1/<MotorIdentifier>"), ["Motor"])
            .placeholder(format!("MotionDevices/{arm}/PowerTrains/PT1/<GearIdentifier>"), ["Gear"]);
    }
    let robot = robotics::objects::MotionDeviceSystemType::instantiate(&running.manager, &objects, "Cell", &options)
        .expect("instantiates the robot");
    let arms = &robot.motion_devices.motion_device_identifier;
    assert_eq!(arms.len(), 2);
    assert!(!arms.is_empty());
    assert_eq!(arms.keys().collect::<Vec<_>>(), ["Left", "Right"]);
    let left = arms.get("Left").expect("the left arm is bound");
    let browse_name = running.attribute(left.node.id(), AttributeId::BrowseName);
    assert!(matches!(browse_name, Some(opcua::types::Variant::QualifiedName(q)) if q.name.as_ref() == "Left"));
    assert!(arms.contains_key("Right"));
    assert!(arms.get("Middle").is_none());
    assert_eq!(arms.iter().map(|(name, arm)| (name, arm.node.id() == left.node.id())).collect::<Vec<_>>(), [
        ("Left", true),
        ("Right", false)
    ]);
    assert_eq!(arms.values().count(), 2);
    assert_eq!(robot.safety_states.safety_state_identifier.keys().collect::<Vec<_>>(), ["SafetyState"]);
    running.stop().await;
}

/// Binding a handle to a node that does not fit it fails with the first problem, in the order of the handle's
/// members: a node that is not there, a node of another class, a mandatory child that is missing.
#[tokio::test]
async fn binding_a_handle_to_the_wrong_node_says_why() {
    use nodeset_models::runtime::typed::{BindError, Instantiate, ObjectType, Variable};
    use opcua::types::{NodeClass, ObjectId};
    let running = common::serve(ServerConfig::new("bind errors").table(&di::TABLE).type_loader(di::TypeLoader)).await;
    let m = &running.manager;
    let objects = NodeId::from(ObjectId::ObjectsFolder);
    let device = di::objects::ComponentType::instantiate(m, &objects, "Device", &Instantiate::new().optional("SerialNumber"))
        .expect("instantiates a component");
    let serial = device.serial_number.as_ref().expect("the optional SerialNumber was created").id().clone();

    // ns0's nodes are served by async-opcua's core node manager, not by ours.
    let server = NodeId::from(ObjectId::Server);
    assert_eq!(m.bind::<di::objects::ComponentType>(&server).err(), Some(BindError::UnknownNode(server)));
    // An ObjectType handle on a variable.
    assert_eq!(
        m.bind::<di::objects::ComponentType>(&serial).err(),
        Some(BindError::WrongClass { node: serial.clone(), expected: NodeClass::Object, found: NodeClass::Variable })
    );
    // A scalar cannot be bound as an array.
    assert!(matches!(m.bind::<Variable<Vec<String>>>(&serial), Err(BindError::ValueRank { .. })));
    // A component is not a device: DeviceType's mandatory members are missing.
    match m.bind::<di::objects::DeviceType>(device.node.id()) {
        Err(BindError::MissingChild { parent, browse_name }) => {
            assert_eq!(&parent, device.node.id());
            assert!(["Manufacturer", "Model", "SerialNumber", "DeviceRevision"].contains(&browse_name.as_str()), "{browse_name}");
        }
        other => panic!("expected a missing child, got {other:?}"),
    }
    // And the right handle binds.
    let again = m.bind::<di::objects::ComponentType>(device.node.id()).expect("binds");
    assert_eq!(again.node.id(), device.node.id());
    running.stop().await;
}

/// A subtype's member markers: those it inherits unchanged are its supertype's (re-exported, across
/// namespaces), those it overrides are its own, and its REQUIRED list names the inherited ones too.
#[test]
fn subtype_markers_inherit_and_override() {
    use di::objects::members::ComponentType as Component;
    use robotics::objects::members::{AuxiliaryComponentType as Auxiliary, AxisType as Axis};
    // Inherited from DI's ComponentType: the same constant, with DI's namespace in the path.
    let segments = |m: nodeset_models::runtime::typed::MemberPath| m.segments().expect("a generated marker path decodes");
    assert_eq!(Axis::SerialNumber.browse_path(), Component::SerialNumber.browse_path());
    assert_eq!(segments(Axis::SerialNumber.browse_path()), [(di::NAMESPACE_URI, "SerialNumber".to_string())]);
    assert_eq!(Axis::AssetId.browse_path(), Component::AssetId.browse_path());
    // Robotics makes ProductCode mandatory on AuxiliaryComponentType; ComponentType has it optional.
    assert!(!Component::ProductCode.mandatory);
    assert!(Auxiliary::ProductCode.mandatory);
    assert!(Auxiliary::REQUIRED.iter().any(|(p, _)| *p == "ProductCode"));
    assert!(!Component::REQUIRED.iter().any(|(p, _)| *p == "ProductCode"));
    // AxisType's own members are declared in its own module.
    assert_eq!(
        segments(Axis::ParameterSet__ActualPosition.browse_path()),
        [(di::NAMESPACE_URI, "ParameterSet".to_string()), (robotics::NAMESPACE_URI, "ActualPosition".to_string())]
    );
}
