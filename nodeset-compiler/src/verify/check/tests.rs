//! The rules on an in-memory snapshot: a small model (ns0 from `nodesets/vendor` and a box type, a folder so
//! that its placeholder admits nothing else) and two
//! server instances of it, one correct and one with planted defects.

use super::*;
use crate::load::Input;
use crate::nodeid::Identifier;
use crate::verify::{RemoteReference, Snapshot};
use crate::{compile, Options};
use std::path::PathBuf;

const BOX_MODEL: &str = r#"<?xml version="1.0" encoding="utf-8"?>
<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">
  <NamespaceUris><Uri>urn:test:verify</Uri></NamespaceUris>
  <Models><Model ModelUri="urn:test:verify" Version="1.0.0" PublicationDate="2024-01-01T00:00:00Z">
    <RequiredModel ModelUri="http://opcfoundation.org/UA/" Version="1.05.00"/></Model></Models>
  <Aliases><Alias Alias="Double">i=11</Alias><Alias Alias="String">i=12</Alias><Alias Alias="HasProperty">i=46</Alias><Alias Alias="HasComponent">i=47</Alias>
    <Alias Alias="HasSubtype">i=45</Alias><Alias Alias="HasTypeDefinition">i=40</Alias><Alias Alias="HasModellingRule">i=37</Alias></Aliases>
  <UAObjectType NodeId="ns=1;i=1000" BrowseName="1:BoxType">
    <References><Reference ReferenceType="HasSubtype" IsForward="false">i=61</Reference>
      <Reference ReferenceType="HasProperty">ns=1;i=1001</Reference>
      <Reference ReferenceType="HasComponent">ns=1;i=1002</Reference>
      <Reference ReferenceType="HasComponent">ns=1;i=1003</Reference><Reference ReferenceType="HasComponent">ns=1;i=1004</Reference><Reference ReferenceType="HasComponent">ns=1;i=1005</Reference></References>
  </UAObjectType>
  <UAVariable NodeId="ns=1;i=1001" BrowseName="1:Size" DataType="Double" ParentNodeId="ns=1;i=1000">
    <References><Reference ReferenceType="HasTypeDefinition">i=68</Reference><Reference ReferenceType="HasModellingRule">i=78</Reference></References>
  </UAVariable>
  <UAObject NodeId="ns=1;i=1002" BrowseName="1:Lid" ParentNodeId="ns=1;i=1000">
    <References><Reference ReferenceType="HasTypeDefinition">i=58</Reference><Reference ReferenceType="HasModellingRule">i=78</Reference></References>
  </UAObject>
  <UAObject NodeId="ns=1;i=1003" BrowseName="1:&lt;Item&gt;" ParentNodeId="ns=1;i=1000">
    <References><Reference ReferenceType="HasTypeDefinition">ns=1;i=2000</Reference><Reference ReferenceType="HasModellingRule">i=11508</Reference></References>
  </UAObject>
  <UAObjectType NodeId="ns=1;i=2000" BrowseName="1:ItemType">
    <References><Reference ReferenceType="HasSubtype" IsForward="false">i=58</Reference></References>
  </UAObjectType>
  <UAObjectType NodeId="ns=1;i=2001" BrowseName="1:SpecialItemType">
    <References><Reference ReferenceType="HasSubtype" IsForward="false">ns=1;i=2000</Reference></References>
  </UAObjectType>
  <UAObjectType NodeId="ns=1;i=3000" BrowseName="1:OtherType">
    <References><Reference ReferenceType="HasSubtype" IsForward="false">i=58</Reference></References>
  </UAObjectType>
  <UAVariable NodeId="ns=1;i=1004" BrowseName="1:&lt;Request&gt;" DataType="Double" ParentNodeId="ns=1;i=1000">
    <References><Reference ReferenceType="HasTypeDefinition">i=63</Reference><Reference ReferenceType="HasModellingRule">i=11508</Reference></References>
  </UAVariable>
  <UAVariable NodeId="ns=1;i=1005" BrowseName="1:&lt;Response&gt;" DataType="String" ParentNodeId="ns=1;i=1000">
    <References><Reference ReferenceType="HasTypeDefinition">i=63</Reference><Reference ReferenceType="HasModellingRule">i=11508</Reference></References>
  </UAVariable>
</UANodeSet>
"#;

fn model() -> crate::model::Model {
    let vendor = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../nodesets/vendor");
    assert!(vendor.join("Opc.Ua.NodeSet2.xml").is_file(), "nodesets/vendor is missing; run `cargo xtask fetch-nodesets`");
    let opts = Options { model_dirs: vec![vendor], ..Options::default() };
    let out = compile(vec![Input::Text { name: "box.xml".into(), text: BOX_MODEL.into() }], &opts);
    assert!(out.ok(), "{}", out.render_diagnostics());
    out.model
}

/// The server numbers the box model's namespace 2 (the model numbers it 1).
fn id(n: u32) -> NodeId {
    NodeId { ns: 2, id: Identifier::Numeric(n) }
}

fn s(name: &str) -> NodeId {
    NodeId { ns: 2, id: Identifier::String(name.into()) }
}

fn reference(rt: u32, target: NodeId) -> RemoteReference {
    RemoteReference { reference_type: NodeId::numeric(0, rt), target }
}

fn object(snap: &mut Snapshot, node: NodeId, name: &str, refs: Vec<RemoteReference>) {
    let browse_name = QualifiedName { ns: 2, name: name.into() };
    snap.nodes.insert(
        node.clone(),
        RemoteNode { id: node, class: NodeClass::Object, browse_name, references: refs, data_type: None, value_rank: None, value: None, extension_objects: None },
    );
}

fn size(snap: &mut Snapshot, node: NodeId, value: RemoteValue) {
    let browse_name = QualifiedName { ns: 2, name: "Size".into() };
    snap.nodes.insert(
        node.clone(),
        RemoteNode {
            id: node,
            class: NodeClass::Variable,
            browse_name,
            references: vec![reference(ids::HAS_TYPE_DEFINITION, NodeId::numeric(0, 68))],
            data_type: Some(NodeId::numeric(0, 11)),
            value_rank: Some(-1),
            value: Some(value),
            extension_objects: None,
        },
    );
}

/// Objects/Good (correct) and Objects/Bad (four planted defects).
fn snapshot() -> Snapshot {
    let mut snap = Snapshot {
        namespaces: vec!["http://opcfoundation.org/UA/".into(), "urn:server".into(), "urn:test:verify".into()],
        ..Snapshot::default()
    };
    let td = |t: NodeId| reference(ids::HAS_TYPE_DEFINITION, t);
    object(&mut snap, Snapshot::objects_folder(), "Objects", vec![reference(ids::ORGANIZES, s("Good")), reference(ids::ORGANIZES, s("Bad"))]);
    // Objects/Good: every mandatory member, an item of a subtype in the placeholder's place.
    object(&mut snap, s("Good"), "Good", vec![
        td(id(1000)),
        reference(ids::HAS_PROPERTY, s("Good.Size")),
        reference(ids::HAS_COMPONENT, s("Good.Lid")),
        reference(ids::HAS_COMPONENT, s("Good.Item")),
    ]);
    size(&mut snap, s("Good.Size"), RemoteValue::Scalar(BuiltinType::Double));
    object(&mut snap, s("Good.Lid"), "Lid", vec![td(NodeId::numeric(0, 58))]);
    object(&mut snap, s("Good.Item"), "Item1", vec![td(id(2001))]);
    // Objects/Bad: a String in Size, no Lid, an OtherType in the placeholder's place, a ModellingRule.
    object(&mut snap, s("Bad"), "Bad", vec![
        td(id(1000)),
        reference(ids::HAS_MODELLING_RULE, NodeId::numeric(0, 78)),
        reference(ids::HAS_PROPERTY, s("Bad.Size")),
        reference(ids::HAS_COMPONENT, s("Bad.Item")),
    ]);
    size(&mut snap, s("Bad.Size"), RemoteValue::Scalar(BuiltinType::String));
    object(&mut snap, s("Bad.Item"), "Item2", vec![td(id(3000))]);
    snap
}

fn codes(report: &Report, path_prefix: &str) -> Vec<(String, String)> {
    report
        .findings
        .iter()
        .filter(|f| f.path.starts_with(path_prefix))
        .map(|f| (f.diagnostic.code.as_str().to_owned(), f.path.clone()))
        .collect()
}

#[test]
fn a_correct_instance_has_no_findings_and_every_planted_defect_one() {
    let model = model();
    let report = check(&model, &snapshot());
    assert_eq!(codes(&report, "2:Good"), Vec::<(String, String)>::new(), "{:#?}", report.findings);
    let mut bad = codes(&report, "2:Bad");
    bad.sort();
    let want = [("NS0401", "2:Bad"), ("NS0406", "2:Bad/2:Size"), ("NS0407", "2:Bad/2:Item2"), ("NS0408", "2:Bad")];
    assert_eq!(bad, want.map(|(c, p)| (c.to_owned(), p.to_owned())).to_vec(), "{:#?}", report.findings);
    assert_eq!(report.violations(), 4);
    // Good, Good/Size, Good/Lid, Good/Item1, Bad, Bad/Size, Bad/Item2.
    assert_eq!(report.checked, 7);
}

#[test]
fn findings_point_at_the_violated_declaration() {
    let model = model();
    let report = check(&model, &snapshot());
    let missing = report.findings.iter().find(|f| f.diagnostic.code == Code::MissingMember).expect("the missing Lid");
    let text = missing.diagnostic.render(&model.sources);
    assert!(text.contains("error[NS0401]: `2:Bad` has no mandatory Object `2:Lid`"), "{text}");
    assert!(text.contains("--> box.xml:17:3"), "{text}");
    assert!(text.contains("declared Mandatory in urn:test:verify:BoxType"), "{text}");
}

#[test]
fn a_member_in_another_namespace_is_missing_with_a_note() {
    let model = model();
    let mut snap = snapshot();
    snap.nodes.get_mut(&s("Good.Lid")).unwrap().browse_name.ns = 1;
    let report = check(&model, &snap);
    let found = codes(&report, "2:Good");
    assert_eq!(found, vec![("NS0401".to_owned(), "2:Good".to_owned())], "{:#?}", report.findings);
    let d = &report.findings.iter().find(|f| f.path == "2:Good").unwrap().diagnostic;
    assert!(d.notes.iter().any(|n| n.contains("in namespace 1 rather than 2")), "{:?}", d.notes);
}

#[test]
fn value_ranks() {
    assert!(rank_compatible(-2, 3) && rank_compatible(-3, 1) && rank_compatible(-3, -1) && rank_compatible(0, 2));
    assert!(!rank_compatible(-1, 1) && !rank_compatible(-3, 2) && !rank_compatible(1, 2) && !rank_compatible(0, -1));
}

#[test]
fn wrong_class_type_data_type_and_rank() {
    let model = model();
    let mut snap = snapshot();
    let size = snap.nodes.get_mut(&s("Good.Size")).unwrap();
    size.data_type = Some(NodeId::numeric(0, 12));
    size.value_rank = Some(1);
    size.value = Some(RemoteValue::Array(BuiltinType::String));
    let lid = snap.nodes.get_mut(&s("Good.Lid")).unwrap();
    lid.class = NodeClass::Variable;
    let mut found = codes(&check(&model, &snap), "2:Good");
    found.sort();
    let want = [("NS0402", "2:Good/2:Lid"), ("NS0404", "2:Good/2:Size"), ("NS0405", "2:Good/2:Size")];
    assert_eq!(found, want.map(|(c, p)| (c.to_owned(), p.to_owned())).to_vec());
    let mut snap = snapshot();
    snap.nodes.get_mut(&s("Good")).unwrap().references[0] = reference(ids::HAS_TYPE_DEFINITION, id(3000));
    snap.nodes.get_mut(&Snapshot::objects_folder()).unwrap().references.truncate(1);
    // Good is now an OtherType: it fills no declaration, so its own type (no members) is all it must match;
    // its children are then checked against their own types.
    assert_eq!(codes(&check(&model, &snap), "2:Good"), Vec::<(String, String)>::new());
}

#[test]
fn a_variable_takes_the_place_of_the_placeholder_of_its_data_type() {
    // `<Request>` (Double) and `<Response>` (String) are both BaseDataVariables: a String variable stands
    // in the place of `<Response>`, not of the first placeholder of its TypeDefinition (Safety's
    // SafetyPDUsType has this shape).
    let model = model();
    let mut snap = snapshot();
    let good = snap.nodes.get_mut(&s("Good")).unwrap();
    good.references.push(reference(ids::HAS_COMPONENT, s("Good.Response1")));
    snap.nodes.insert(
        s("Good.Response1"),
        RemoteNode {
            id: s("Good.Response1"),
            class: NodeClass::Variable,
            browse_name: QualifiedName { ns: 2, name: "Response1".into() },
            references: vec![reference(ids::HAS_TYPE_DEFINITION, NodeId::numeric(0, 63))],
            data_type: Some(NodeId::numeric(0, 12)),
            value_rank: Some(-1),
            value: Some(RemoteValue::Scalar(BuiltinType::String)),
            extension_objects: None,
        },
    );
    let report = check(&model, &snap);
    assert_eq!(codes(&report, "2:Good"), Vec::<(String, String)>::new(), "{:#?}", report.findings);
}
