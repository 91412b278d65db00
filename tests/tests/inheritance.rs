//! The fully-inherited InstanceDeclaration hierarchy (OPC UA Part 3, 6.3.3), on the shape every robot vendor
//! model has: `tests/fixtures/vendor_robot`, a subtype of Robotics' MotionDeviceType that overrides
//! `ParameterSet` (three ParameterSet declarations deep), a nested override chain
//! (`Tuning/Limits/MaxSpeed|MaxAccel`) re-modified at two levels, and a member typed by the vendor's own
//! Device model.
//!
//! The rule is computed once, by the resolver (`Model::overridden`, `Model::instance_members`); these tests
//! hold `check --show` and the runtime's `instantiate` (which reads the links from the node tables) to it:
//! for every concrete ObjectType of the fixture and of Robotics, the nodes a server creates are exactly the
//! mandatory paths of the model's hierarchy.

use nodeset_compiler::diag::Code;
use nodeset_compiler::load::Input;
use nodeset_compiler::model::{Member, Model, ModellingRule, NodeIx};
use nodeset_compiler::serve::{self, instances::mandatory_paths};
use nodeset_compiler::raw::NodeClass;
use nodeset_compiler::{compile, summary, Compiled, Options};
use nodeset_runtime::server::ServerConfig;
use nodeset_runtime::typed::{Instantiate, InstantiateError};
use nodeset_tests::{root, vendor};
use opcua::types::{BrowseDirection, NodeId, QualifiedName, ReferenceTypeId};
use std::collections::BTreeSet;
use std::path::PathBuf;

const VENDOR: &str = "http://example.com/fixtures/vendor_robot/";
const ROBOTICS: &str = "http://opcfoundation.org/UA/Robotics/";

fn fixture_dir() -> PathBuf {
    root().join("tests/fixtures/vendor_robot")
}

/// The vendor file as a user names it, its models in the fixture folder and the pinned specs.
fn vendor_model() -> Compiled {
    let dir = fixture_dir();
    let opts = Options { model_dirs: vec![vendor(), dir.clone()], ..Options::default() };
    let out = compile(vec![Input::Path(dir.join("Example.VendorRobot.NodeSet2.xml"))], &opts);
    assert!(out.diagnostics.items.is_empty(), "the fixture compiles cleanly:\n{}", out.render_diagnostics());
    out
}

fn ty(m: &Model, uri: &str, name: &str) -> NodeIx {
    let hits: Vec<NodeIx> = m.find(&format!("{uri}#{name}")).into_iter().filter(|&ix| m.node(ix).class.is_type()).collect();
    assert_eq!(hits.len(), 1, "one type `{name}` in {uri}");
    hits[0]
}

fn get(members: &[Member], name: &str) -> Member {
    members.iter().find(|x| x.browse_name.name == name).unwrap_or_else(|| panic!("no member {name}")).clone()
}

fn names(members: &[Member]) -> Vec<&str> {
    members.iter().map(|x| x.browse_name.name.as_str()).collect()
}

#[test]
fn a_vendor_subtype_keeps_every_member_below_the_declarations_it_overrides() {
    let out = vendor_model();
    let m = &out.model;
    let arm_x = ty(m, VENDOR, "ArmXType");
    let top = &m.members[&arm_x];
    // ParameterSet: declared by DI's TopologyElementType, Robotics' MotionDeviceType, the vendor's Robotics
    // model, ArmType and ArmXType; every one of their members is there, the nearest declaration's wins.
    let params = get(top, "ParameterSet");
    let members = m.instance_members(params.node);
    assert_eq!(
        names(&members),
        ["<ParameterIdentifier>", "InControl", "OnPath", "SpeedOverride", "Payload", "ToolWeight", "Reach"],
        "the ParameterSet of ArmXType"
    );
    let speed = get(&members, "SpeedOverride");
    assert_eq!(m.node(speed.node).modelling_rule, Some(ModellingRule::Mandatory));
    assert_eq!(m.namespace_uri(m.node(speed.node).id.ns), ROBOTICS, "SpeedOverride comes from Robotics");
    // The chain of ParameterSet declarations, nearest first, ends at DI's.
    let chain: Vec<String> = m.override_chain(params.node).iter().map(|&x| m.qualified(m.node(x).parent.unwrap())).collect();
    assert_eq!(chain.len(), 5, "{chain:?}");
    // Tuning/Limits, three levels down: MaxSpeed as ArmType re-declared it (value 2, Mandatory), MaxAccel as
    // ArmXType made it (Mandatory, where the vendor's Robotics model had it Optional).
    let tuning = get(top, "Tuning");
    let limits = get(&m.instance_members(tuning.node), "Limits");
    let limit_members = m.instance_members(limits.node);
    assert_eq!(names(&limit_members), ["MaxSpeed", "MaxAccel"]);
    let value = |x: &Member| match m.value(x.node).and_then(|v| v.ok()) {
        Some(nodeset_compiler::value::Variant::Double(v)) => Some(v),
        _ => None,
    };
    let max_speed = get(&limit_members, "MaxSpeed");
    assert_eq!(value(&max_speed), Some(2.0));
    let tuning_of_max_speed = m.node(m.node(max_speed.node).parent.unwrap()).parent.unwrap();
    assert_eq!(m.node(tuning_of_max_speed).parent, Some(ty(m, VENDOR, "ArmType")), "MaxSpeed is ArmType's");
    let max_accel = get(&limit_members, "MaxAccel");
    assert_eq!((value(&max_accel), m.node(max_accel.node).modelling_rule), (Some(4.0), Some(ModellingRule::Mandatory)));
    // The member typed by the vendor's Device model has that type's members.
    let controller = get(top, "Controller");
    assert_eq!(names(&m.instance_members(controller.node)), ["SerialCode", "FirmwareLevel"]);
}

#[test]
fn check_show_lists_the_inherited_members_of_an_override() {
    let out = vendor_model();
    let m = &out.model;
    let shown = summary::show_type(m, ty(m, VENDOR, "ArmXType"), 3);
    let block: Vec<&str> =
        shown.lines().skip_while(|l| !l.contains("Object DI:ParameterSet")).skip(1).take_while(|l| l.starts_with("    ")).collect();
    // Two loaded namespaces end in `Robotics`: each is named by as many URI segments as tell it apart.
    for want in [
        "Variable UA/Robotics:SpeedOverride : BaseDataVariableType [Mandatory]",
        "Variable vendor_robot/Robotics:Payload",
        "Variable vendor_robot:ToolWeight",
        "Variable vendor_robot:Reach",
    ] {
        assert!(block.iter().any(|l| l.contains(want)), "`check --show ArmXType` lists {want} under ParameterSet:\n{shown}");
    }
    let prefixes: BTreeSet<String> = (1..m.namespaces.len() as u16).map(|ns| m.namespace_prefix(ns)).collect();
    assert_eq!(prefixes.len(), m.namespaces.len() - 1, "two namespaces share a prefix: {prefixes:?}");
    assert!(prefixes.contains("DI") && prefixes.contains("vendor_robot"), "a prefix is one segment where that is unique: {prefixes:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn instantiate_creates_exactly_the_model_hierarchy() {
    let out = vendor_model();
    let m = &out.model;
    // Every model but ns0 as a table, dependencies first (the model's order), built in memory as `serve`
    // builds them.
    let (tables, diags) = serve::tables(m);
    assert!(diags.items.is_empty(), "the tables build without diagnostics");
    let mut config = ServerConfig::new("inheritance").port(0).insecure_only();
    for t in tables {
        config = config.table(t);
    }
    let server = config.build().expect("the server builds");
    let manager = server.manager().clone();
    let handle = server.handle().clone();
    let task = tokio::spawn(server.run());
    // async-opcua fills ns0 once the server runs: ns0's types (a Robotics alarm's ConditionType members)
    // are there only then (without the wait, about one run in ten found none of them).
    serve::wait_for_ns0_types(&handle).await.expect("ns0 loads");
    let objects = NodeId::from(opcua::types::ObjectId::ObjectsFolder);
    let mut checked = 0;
    let served: Vec<(String, u16)> = m
        .models
        .iter()
        .filter(|x| x.uri == VENDOR || x.uri.ends_with("/vendor_robot/Robotics/") || x.uri == ROBOTICS)
        .map(|x| (x.uri.clone(), x.ns))
        .collect();
    let types: Vec<(String, NodeIx)> = served
        .iter()
        .flat_map(|(uri, ns)| {
            (0..m.nodes.len() as u32)
                .map(NodeIx)
                .filter(|&ix| m.node(ix).id.ns == *ns && m.node(ix).class == NodeClass::ObjectType && !m.node(ix).is_abstract())
                .map(|ix| (uri.clone(), ix))
                .collect::<Vec<_>>()
        })
        .collect();
    for (uri, t) in types {
        let name = &m.node(t).browse_name.name;
        let (want, placeholders) = mandatory_paths(m, t).expect("no type of the fixture contains itself");
        let options = placeholders.iter().fold(Instantiate::new(), |o, (p, element)| o.placeholder(p.clone(), [element.clone()]));
        let type_id = NodeId::new(manager.namespace_index(&uri).expect("namespace served"), node_number(m, t));
        let id = manager
            .instantiate(&type_id, &objects, QualifiedName::new(0, format!("I{checked}")), &options)
            .unwrap_or_else(|e| panic!("instantiating {name}: {e}"));
        let got = created_paths(&manager, &handle, &id);
        let missing: Vec<_> = want.difference(&got).collect();
        let extra: Vec<_> = got.difference(&want).collect();
        assert!(missing.is_empty() && extra.is_empty(), "{name}: the server lacks {missing:?} and adds {extra:?}");
        checked += 1;
    }
    assert!(checked >= 20, "the vendor types and Robotics' concrete ObjectTypes are all instantiated, not {checked}");
    // A MandatoryPlaceholder is filled by a Mandatory member that fits it: a Robotics MotorType needs no name
    // for DI's `ParameterSet/<ParameterIdentifier>`, its `ParameterSet/MotorTemperature` (an AnalogUnitType)
    // is a parameter. DI's own ParameterSet, asked for with no parameter in it, is refused.
    let robotics = manager.namespace_index(ROBOTICS).expect("Robotics served");
    let motor = ty(m, ROBOTICS, "MotorType");
    let plain = Instantiate::new();
    manager
        .instantiate(&NodeId::new(robotics, node_number(m, motor)), &objects, QualifiedName::new(0, "Motor"), &plain)
        .expect("a motor needs no name for its ParameterSet's placeholder");
    let di = "http://opcfoundation.org/UA/DI/";
    let component = NodeId::new(manager.namespace_index(di).expect("DI served"), node_number(m, ty(m, di, "ComponentType")));
    let refused = manager.instantiate(&component, &objects, QualifiedName::new(0, "Component"), &Instantiate::new().optional("ParameterSet"));
    assert_eq!(
        refused.err().map(|e| e.to_string()),
        Some(InstantiateError::MissingPlaceholder("ParameterSet/<ParameterIdentifier>".into()).to_string()),
        "an empty ParameterSet is refused"
    );
    handle.cancel();
    let _ = tokio::time::timeout(std::time::Duration::from_secs(10), task).await;
}

/// Two shapes of the UA-Nodeset tree that once gave two members of an instance one NodeId
/// (`tests/fixtures/member_ids`): ns0's `EURange` beside a companion spec's (Mining's ShearerLoaderType), and a
/// MandatoryPlaceholder `PwmSwitchingFrequency` beside `<PwmSwitchingFrequency>` (Powertrain's drive types).
/// `serve --instantiate-all` creates both types; the members of two namespaces are told apart by namespace in
/// their NodeIds, the two placeholders' elements by number, and a name no other member has keeps its plain
/// NodeId.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn members_that_share_a_name_get_nodeids_of_their_own() {
    let dir = root().join("tests/fixtures/member_ids");
    let out = compile(vec![Input::Path(dir.join("Example.MemberIds.NodeSet2.xml"))], &Options { model_dirs: vec![vendor()], ..Options::default() });
    assert!(out.ok(), "{}", out.render_diagnostics());
    let m = &out.model;
    let (tables, diags) = serve::tables(m);
    assert!(diags.items.is_empty(), "the tables build without diagnostics");
    let mut config = ServerConfig::new("member-ids").port(0).insecure_only();
    for t in tables {
        config = config.table(t);
    }
    let server = config.build().expect("the server builds");
    let manager = server.manager().clone();
    let handle = server.handle().clone();
    let task = tokio::spawn(server.run());
    serve::wait_for_ns0_types(&handle).await.expect("ns0 loads");
    let done = serve::instances::instantiate_all(&manager, m);
    assert_eq!(done.failures, Vec::<(String, String)>::new());
    assert_eq!((done.instantiated, done.types), (3, 3));
    let ns = manager.namespace_index("http://example.com/fixtures/member_ids/").expect("served");
    let inst = manager.instance_namespace();
    let space = manager.node_manager().address_space().read();
    let name_of = |id: &str| space.find(&NodeId::new(inst, id.to_owned())).map(|n| n.as_node().browse_name().clone());
    let roof = format!("Instances/{ns}:ShearerType/RoofOffset");
    assert_eq!(name_of(&roof), Some(QualifiedName::new(ns, "RoofOffset")), "a name no sibling shares keeps its plain NodeId");
    assert_eq!(name_of(&format!("{roof}/0:EURange")), Some(QualifiedName::new(0, "EURange")));
    assert_eq!(name_of(&format!("{roof}/{ns}:EURange")), Some(QualifiedName::new(ns, "EURange")));
    assert_eq!(name_of(&format!("{roof}/EURange")), None, "neither EURange takes the plain NodeId");
    let attributes = format!("Instances/{ns}:DriveType/ConverterAttributes1");
    for element in ["PwmSwitchingFrequency1", "PwmSwitchingFrequency2"] {
        assert_eq!(name_of(&format!("{attributes}/{element}")), Some(QualifiedName::new(ns, element)));
    }
    drop(space);
    // What the model names for the placeholders: one element each, numbered in the order of their BrowseNames.
    let drive = ty(m, "http://example.com/fixtures/member_ids/", "DriveType");
    let (_, placeholders) = mandatory_paths(m, drive).expect("no type of the fixture contains itself");
    assert_eq!(
        placeholders,
        [
            ("<ConverterAttributes>".to_owned(), "ConverterAttributes1".to_owned()),
            ("ConverterAttributes1/<PwmSwitchingFrequency>".to_owned(), "PwmSwitchingFrequency1".to_owned()),
            ("ConverterAttributes1/PwmSwitchingFrequency".to_owned(), "PwmSwitchingFrequency2".to_owned()),
        ]
    );
    // The runtime refuses, with the path, two elements given one name rather than creating one of them twice.
    let refused = manager.instantiate(
        &NodeId::new(ns, node_number(m, drive)),
        &NodeId::from(opcua::types::ObjectId::ObjectsFolder),
        QualifiedName::new(ns, "Drive"),
        &Instantiate::new()
            .placeholder("<ConverterAttributes>", ["A"])
            .placeholder("A/<PwmSwitchingFrequency>", ["F"])
            .placeholder("A/PwmSwitchingFrequency", ["F"]),
    );
    assert_eq!(refused.err(), Some(InstantiateError::DuplicateName(format!("A/{ns}:F"))));
    handle.cancel();
    let _ = tokio::time::timeout(std::time::Duration::from_secs(10), task).await;
}

fn node_number(m: &Model, t: NodeIx) -> u32 {
    match m.node(t).id.id {
        nodeset_compiler::nodeid::Identifier::Numeric(n) => n,
        _ => panic!("the fixture's and Robotics' types have numeric NodeIds"),
    }
}

/// The browse paths of the nodes below `root` that the server holds, by hierarchical references.
fn created_paths(manager: &nodeset_runtime::server::ModelManager, handle: &opcua::server::ServerHandle, root: &NodeId) -> BTreeSet<String> {
    let tree = handle.type_tree().read();
    let space = manager.node_manager().address_space().read();
    let mut out = BTreeSet::new();
    let mut stack = vec![(root.clone(), String::new(), 0)];
    while let Some((node, prefix, depth)) = stack.pop() {
        assert!(depth < 20, "the instance nests too deep");
        let children: Vec<NodeId> = space
            .find_references(&node, Some((ReferenceTypeId::HierarchicalReferences, true)), &*tree, BrowseDirection::Forward)
            .filter(|r| r.target_node.namespace == root.namespace)
            .map(|r| r.target_node.clone())
            .collect();
        for c in children {
            let Some(n) = space.find(&c) else { continue };
            let path = format!("{prefix}{}", n.as_node().browse_name().name.as_ref());
            out.insert(path.clone());
            stack.push((c, format!("{path}/"), depth + 1));
        }
    }
    out
}

#[test]
fn an_override_incompatible_with_what_it_overrides_is_a_warning() {
    let dir = fixture_dir();
    let text = std::fs::read_to_string(dir.join("Example.VendorRobot.NodeSet2.xml")).unwrap();
    // Two defects planted: ArmXType's Limits made Optional where the vendor's Robotics model has it Mandatory,
    // and ArmType's MaxSpeed made a String where it is a Double.
    let planted = text
        .replacen(
            "BrowseName=\"4:Limits\" ParentNodeId=\"ns=1;i=5010\">\n    <DisplayName>Limits</DisplayName>\n    <References>\n      <Reference ReferenceType=\"HasTypeDefinition\">i=58</Reference>\n      <Reference ReferenceType=\"HasModellingRule\">i=78</Reference>",
            "BrowseName=\"4:Limits\" ParentNodeId=\"ns=1;i=5010\">\n    <DisplayName>Limits</DisplayName>\n    <References>\n      <Reference ReferenceType=\"HasTypeDefinition\">i=58</Reference>\n      <Reference ReferenceType=\"HasModellingRule\">i=80</Reference>",
            1,
        )
        .replacen(
            "BrowseName=\"4:MaxSpeed\" ParentNodeId=\"ns=1;i=5003\" DataType=\"Double\"",
            "BrowseName=\"4:MaxSpeed\" ParentNodeId=\"ns=1;i=5003\" DataType=\"String\"",
            1,
        );
    assert_eq!(planted.matches("i=80</Reference>").count(), text.matches("i=80</Reference>").count() + 1, "the rule is planted");
    assert!(planted.contains("4:MaxSpeed\" ParentNodeId=\"ns=1;i=5003\" DataType=\"String\""), "the DataType is planted");
    let tmp = std::env::temp_dir().join(format!("inheritance-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let file = tmp.join("Example.VendorRobot.NodeSet2.xml");
    std::fs::write(&file, planted).unwrap();
    let opts = Options { model_dirs: vec![vendor(), dir.clone()], ..Options::default() };
    let out = compile(vec![Input::Path(file.clone())], &opts);
    let _ = std::fs::remove_dir_all(&tmp);
    let found: Vec<_> = out.diagnostics.items.iter().filter(|d| d.code == Code::IncompatibleOverride).collect();
    let rendered = out.render_diagnostics();
    assert_eq!(found.len(), 2, "one warning per planted defect, nothing else:\n{rendered}");
    assert!(rendered.contains("`Limits` overrides") && rendered.contains("it is Optional where that is Mandatory"), "{rendered}");
    assert!(rendered.contains("`MaxSpeed` overrides") && rendered.contains("its DataType String is not Double or a subtype of it"), "{rendered}");
    assert!(rendered.contains(&format!("{}:", file.display())), "each warning points into the file:\n{rendered}");
}
