//! Structure values are decoded once, by the model, against their DataType's definition: typed fields with
//! NodeIds and QualifiedNames mapped, nested structures, enumerations, arrays, unions, inherited fields, and
//! the reason for a field that does not decode. Nothing after the model reads a value's XML.
//!
//! The Rust back end lays every structure value out in the order of its binary encoding in the node table
//! (`Structure:` items), for structures of ns0, of other namespaces and of the file's own; a value it cannot
//! lay out is a warning that names the variable by browse path and NodeId, at its `<Value>`.

use nodeset_compiler::emit::rust::{default_module_name, generate, RustConfig, RustNamespace, RustPath};
use nodeset_compiler::load::Input;
use nodeset_compiler::model::Model;
use nodeset_compiler::nodeid::{NodeId, QualifiedName};
use nodeset_compiler::value::{Body, BuiltinType, Structure, Variant};
use nodeset_compiler::{compile, Compiled, Options};
use nodeset_runtime::table::{Kind, Val};
use nodeset_tests::{nodeset_files, root, vendor};
use std::path::PathBuf;

const TEXT: &str = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">
  <NamespaceUris><Uri>http://example.com/other/</Uri><Uri>http://example.com/values/</Uri></NamespaceUris>
  <Models><Model ModelUri="http://example.com/values/" Version="1.0"/></Models>
  <Aliases><Alias Alias="Target">ns=2;i=1</Alias><Alias Alias="HasEncoding">i=38</Alias></Aliases>
  <UAObject NodeId="ns=2;i=1" BrowseName="2:Target">
    <DisplayName>Target</DisplayName>
    <References><Reference ReferenceType="HasTypeDefinition">i=58</Reference><Reference ReferenceType="i=35" IsForward="false">i=85</Reference></References>
  </UAObject>
  <UADataType NodeId="ns=2;i=10" BrowseName="2:Mode">
    <DisplayName>Mode</DisplayName>
    <References><Reference ReferenceType="i=45" IsForward="false">i=29</Reference></References>
    <Definition Name="2:Mode"><Field Name="Off" Value="0"/><Field Name="Slow" Value="5"/></Definition>
  </UADataType>
  <UADataType NodeId="ns=2;i=11" BrowseName="2:Point">
    <DisplayName>Point</DisplayName>
    <References><Reference ReferenceType="i=45" IsForward="false">i=22</Reference></References>
    <Definition Name="2:Point"><Field Name="X" DataType="i=11"/><Field Name="Y" DataType="i=11"/></Definition>
  </UADataType>
  <UADataType NodeId="ns=2;i=12" BrowseName="2:Record">
    <DisplayName>Record</DisplayName>
    <References>
      <Reference ReferenceType="i=45" IsForward="false">i=22</Reference>
      <Reference ReferenceType="HasEncoding">ns=2;i=22</Reference>
      <Reference ReferenceType="HasEncoding">ns=2;i=25</Reference>
    </References>
    <Definition Name="2:Record">
      <Field Name="Count" DataType="i=6"/>
      <Field Name="Title" DataType="i=21"/>
      <Field Name="Source" DataType="i=17"/>
      <Field Name="Key" DataType="i=20"/>
      <Field Name="Mode" DataType="ns=2;i=10"/>
      <Field Name="At" DataType="ns=2;i=11"/>
      <Field Name="Samples" DataType="i=11" ValueRank="1"/>
      <Field Name="Left" DataType="i=1"/>
    </Definition>
  </UADataType>
  <UADataType NodeId="ns=2;i=13" BrowseName="2:Calibrated">
    <DisplayName>Calibrated</DisplayName>
    <References>
      <Reference ReferenceType="i=45" IsForward="false">ns=2;i=12</Reference>
      <Reference ReferenceType="HasEncoding">ns=2;i=23</Reference>
    </References>
    <Definition Name="2:Calibrated"><Field Name="Offset" DataType="i=11"/></Definition>
  </UADataType>
  <UADataType NodeId="ns=2;i=14" BrowseName="2:Choice">
    <DisplayName>Choice</DisplayName>
    <References>
      <Reference ReferenceType="i=45" IsForward="false">i=12756</Reference>
      <Reference ReferenceType="HasEncoding">ns=2;i=24</Reference>
    </References>
    <Definition Name="2:Choice" IsUnion="true"><Field Name="Number" DataType="i=6"/><Field Name="Text" DataType="i=12"/></Definition>
  </UADataType>
  <UAObject NodeId="ns=2;i=22" BrowseName="Default XML" SymbolicName="DefaultXml"><DisplayName>Default XML</DisplayName><References><Reference ReferenceType="HasTypeDefinition">i=76</Reference></References></UAObject>
  <UAObject NodeId="ns=2;i=23" BrowseName="Default XML" SymbolicName="DefaultXml"><DisplayName>Default XML</DisplayName><References><Reference ReferenceType="HasTypeDefinition">i=76</Reference></References></UAObject>
  <UAObject NodeId="ns=2;i=24" BrowseName="Default XML" SymbolicName="DefaultXml"><DisplayName>Default XML</DisplayName><References><Reference ReferenceType="HasTypeDefinition">i=76</Reference></References></UAObject>
  <UAObject NodeId="ns=2;i=25" BrowseName="Default Binary" SymbolicName="DefaultBinary"><DisplayName>Default Binary</DisplayName><References><Reference ReferenceType="HasTypeDefinition">i=76</Reference></References></UAObject>
  <UAVariable NodeId="ns=2;i=30" BrowseName="2:Calibration" DataType="ns=2;i=13">
    <DisplayName>Calibration</DisplayName>
    <References><Reference ReferenceType="HasTypeDefinition">i=63</Reference><Reference ReferenceType="i=47" IsForward="false">ns=2;i=1</Reference></References>
    <Value>
      <ExtensionObject xmlns="http://opcfoundation.org/UA/2008/02/Types.xsd">
        <TypeId><Identifier>ns=2;i=23</Identifier></TypeId>
        <Body>
          <Calibrated>
            <Count>3</Count>
            <Title><Locale>en</Locale><Text>Table</Text></Title>
            <Source><Identifier>Target</Identifier></Source>
            <Key><NamespaceIndex>1</NamespaceIndex><Name>Probe</Name></Key>
            <Mode>Slow_5</Mode>
            <At><X>1.5</X><Y>-2</Y></At>
            <Samples><Double>0.25</Double><Double>0.5</Double></Samples>
            <Offset>0.125</Offset>
          </Calibrated>
        </Body>
      </ExtensionObject>
    </Value>
  </UAVariable>
  <UAVariable NodeId="ns=2;i=31" BrowseName="2:Broken" DataType="ns=2;i=12">
    <DisplayName>Broken</DisplayName>
    <References><Reference ReferenceType="HasTypeDefinition">i=63</Reference><Reference ReferenceType="i=47" IsForward="false">ns=2;i=1</Reference></References>
    <Value>
      <ExtensionObject xmlns="http://opcfoundation.org/UA/2008/02/Types.xsd">
        <TypeId><Identifier>ns=2;i=22</Identifier></TypeId>
        <Body><Record><Count>many</Count><Mode>5</Mode></Record></Body>
      </ExtensionObject>
    </Value>
  </UAVariable>
  <UAVariable NodeId="ns=2;i=32" BrowseName="2:Choices" DataType="ns=2;i=14" ValueRank="1">
    <DisplayName>Choices</DisplayName>
    <References><Reference ReferenceType="HasTypeDefinition">i=63</Reference><Reference ReferenceType="i=47" IsForward="false">ns=2;i=1</Reference></References>
    <Value>
      <ListOfExtensionObject xmlns="http://opcfoundation.org/UA/2008/02/Types.xsd">
        <ExtensionObject><TypeId><Identifier>ns=2;i=24</Identifier></TypeId><Body><Choice><SwitchField>2</SwitchField><Text>two</Text></Choice></Body></ExtensionObject>
      </ListOfExtensionObject>
    </Value>
  </UAVariable>
</UANodeSet>"#;

fn model() -> Model {
    let opts = Options { model_dirs: vec![vendor()], ..Options::default() };
    let out = compile(vec![Input::Text { name: "structure_values.xml".into(), text: TEXT.into() }], &opts);
    out.model
}

fn structure(m: &Model, name: &str) -> Structure {
    let ix = m.find(&format!("http://example.com/values/#{name}"))[0];
    let v = m.value(ix).expect("a value").expect("decodes");
    let v = match v {
        Variant::Array(_, mut items) => items.remove(0),
        v => v,
    };
    let Variant::ExtensionObject(eo) = v else { panic!("{v:?}") };
    match eo.body {
        Some(Body::Structure(s)) => s,
        other => panic!("{name}: not decoded: {other:?}"),
    }
}

#[test]
fn a_structure_value_arrives_as_typed_fields() {
    let m = model();
    let ns = m.namespaces.iter().position(|u| u == "http://example.com/values/").unwrap() as u16;
    let s = structure(&m, "Calibration");
    assert_eq!(s.data_type, NodeId::numeric(ns, 13), "the DataType its encoding belongs to");
    let names: Vec<&str> = s.fields.iter().map(|(n, _)| &**n).collect();
    // Inherited fields first, in the definition's order; `Left`, which the value leaves out, is absent.
    assert_eq!(names, ["Count", "Title", "Source", "Key", "Mode", "At", "Samples", "Offset"]);
    assert_eq!(s.field("Count"), Some(&Variant::Int32(3)));
    assert_eq!(s.text("Title"), Some("Table"));
    // The alias and the file's namespace index 2 are mapped: the NodeId is the model's.
    assert_eq!(s.field("Source"), Some(&Variant::NodeId(NodeId::numeric(ns, 1))));
    // The QualifiedName's file-local index 1 is `http://example.com/other/`, not this file's namespace.
    let other = m.namespaces.iter().position(|u| u == "http://example.com/other/").unwrap() as u16;
    assert_eq!(s.field("Key"), Some(&Variant::QualifiedName(QualifiedName { ns: other, name: "Probe".into() })));
    assert_eq!(s.field("Mode"), Some(&Variant::Int32(5)), "an enumeration written `Name_5`");
    assert_eq!(s.field("Samples"), Some(&Variant::Array(BuiltinType::Double, vec![Variant::Double(0.25), Variant::Double(0.5)])));
    assert_eq!(s.field("Offset"), Some(&Variant::Double(0.125)));
    let Some(Variant::ExtensionObject(at)) = s.field("At") else { panic!("{:?}", s.field("At")) };
    let at = at.structure().expect("the nested Point is decoded too");
    assert_eq!(at.data_type, NodeId::numeric(ns, 11));
    assert_eq!((at.field("X"), at.field("Y")), (Some(&Variant::Double(1.5)), Some(&Variant::Double(-2.0))));
}

#[test]
fn a_field_that_does_not_decode_says_why_and_the_others_still_arrive() {
    let m = model();
    let s = structure(&m, "Broken");
    let why = s.get("Count").expect("present").as_ref().expect_err("`many` is no Int32");
    assert!(why.contains("Count") && why.contains("many"), "{why}");
    assert_eq!(s.field("Mode"), Some(&Variant::Int32(5)), "a plain number is an enumeration value too");
}

#[test]
fn a_union_keeps_its_switch_field() {
    let m = model();
    let s = structure(&m, "Choices");
    assert_eq!(s.switch_field, Some(2));
    assert_eq!(s.field("Text"), Some(&Variant::String("two".into())));
    assert_eq!(s.get("Number"), None);
}

/// Generates Rust for the named namespaces of a compiled model; the packed text of each `nodes.rs` by
/// namespace, and the rendered diagnostics of generation.
fn tables(out: &Compiled, uris: &[&str]) -> (Vec<(String, String)>, String) {
    let cfg = RustConfig {
        namespaces: uris.iter().map(|u| RustNamespace { uri: u.to_string(), module: default_module_name(u) }).collect(),
        extern_paths: Default::default(),
        runtime_path: RustPath::new("nodeset_runtime").unwrap(),
        command: "test".into(),
    };
    let g = generate(&out.model, &cfg);
    let texts = uris
        .iter()
        .map(|u| {
            let file = g.files.iter().find(|f| f.path == PathBuf::from(default_module_name(u)).join("nodes.rs")).expect("nodes.rs");
            let start = file.contents.find("r#\"").or_else(|| file.contents.find("r##\"")).expect("the packed text");
            let text = &file.contents[start..];
            let open = text.find('"').unwrap() + 1;
            let hashes = &text[1..open - 1];
            let close = text.find(&format!("\"{hashes};")).or_else(|| text.find(&format!("\"{hashes})"))).expect("the end of the text");
            (u.to_string(), text[open..close].to_string())
        })
        .collect();
    (texts, g.diagnostics.render(&out.model.sources))
}

/// The decoded rows of packed text, with the runtime's decoder.
fn rows(text: &str) -> Vec<nodeset_runtime::table::NodeRow> {
    nodeset_runtime::table::decode(Box::leak(text.to_string().into_boxed_str())).expect("the table decodes").into_vec()
}

fn value_of(row: &nodeset_runtime::table::NodeRow) -> Option<Val> {
    match row.kind {
        Kind::Variable { value, .. } | Kind::VariableType { value, .. } => Some(value),
        _ => None,
    }
}

/// Whether a table value is a structure, or an array of structures.
fn is_structure(v: &Val) -> bool {
    match v {
        Val::Structure(..) => true,
        Val::Array(22, items) => !items.is_empty() && items.iter().all(|i| matches!(i, Val::Structure(..))),
        _ => false,
    }
}

const FIXTURE: &str = "http://example.com/fixtures/structure_values/";
const PARTS: &str = "http://example.com/fixtures/structure_values/parts/";

#[test]
fn every_structure_value_of_the_fixture_is_in_the_table() {
    let dir = root().join("tests/fixtures/structure_values");
    let opts = Options { model_dirs: vec![vendor(), dir.clone()], ..Options::default() };
    let out = compile(nodeset_files(&dir).into_iter().map(Input::Path).collect(), &opts);
    assert!(out.diagnostics.items.is_empty(), "{}", out.render_diagnostics());
    let (texts, diags) = tables(&out, &[FIXTURE, PARTS]);
    assert!(!diags.contains("NS0302"), "every value is served: {diags}");
    let rows = rows(&texts[0].1);
    let values: Vec<(&str, Val)> = rows.iter().filter_map(|r| Some((r.browse_name.1, value_of(r)?))).filter(|(_, v)| !matches!(v, Val::None)).collect();
    let names: Vec<&str> = values.iter().map(|(n, _)| *n).collect();
    assert_eq!(
        names,
        ["Unit", "Span", "Spans", "MainTool", "LeanTool", "Tools", "Options", "BareOptions", "Choice", "PlaceChoice", "Kit", "Direction"]
    );
    for (name, v) in &values {
        assert!(is_structure(v), "{name}: {v:?}");
    }
    let text = &texts[0].1;
    // Table-local namespace indices: 0 is ns0, then the namespaces the table refers to in the model's order
    // (parts, which the fixture requires, is loaded first).
    let global = |u: &str| out.model.namespaces.iter().position(|x| x == u).unwrap();
    assert!(global(PARTS) < global(FIXTURE));
    let (parts, own) = (1, 2);
    // ns0's EUInformation by its Default Binary encoding (i=889), its fields in order; the table's namespace 0.
    assert!(
        text.contains(r#"Structure:0:889 { String:"http://www.opcfoundation.org/UA/units/un/cefact" Int32:4408652 LocalizedText:"en":"°C" LocalizedText:"en":"degree Celsius" }"#),
        "{text}"
    );
    let has = |want: String| assert!(text.contains(&want), "{want} is not in\n{text}");
    // Optional fields: the mask (Limit and Position given, Comment not), then the fields given.
    has(format!("Structure:{own}:5003 {{ UInt32:6 Int32:7 Fields:{{ Double:0.5 Double:9.5 }} Fields:{{ Double:10 Double:20 Double:30 }} }}"));
    has(format!("Structure:{own}:5003 {{ UInt32:0 Int32:-1 }}"));
    // Unions: the switch field, then the one field.
    has(format!("Structure:{own}:5005 {{ UInt32:2 String:\"two\" }}"));
    has(format!("Structure:{own}:5005 {{ UInt32:3 Fields:{{ Double:0.5 Double:0.25 Double:0.125 }} }}"));
    // Fields a value leaves out are their DataType's null: a structure in place with null fields, a null
    // array, a null NodeId, QualifiedName, Variant (Null:24, one byte 0) and LocalizedText.
    has(format!("Structure:{own}:5001 {{ String:\"Blank\" Null:6 Fields:{{ Null:11 Null:11 Null:11 }} NullArray:11 Null:17 Null:20 Null:24 Null:21 }}"));
    // NodeIds and QualifiedNames of three namespaces, with the table's indices; a Variant field.
    has(format!("NodeId:{own}:6001 QualifiedName:{parts}:\"Spindle\" Variant:Int32:42"));
    has(format!("NodeId:0:85 QualifiedName:0:\"Objects\" Variant:Double:0.5"));
    // A structure of the other namespace as a value, and as an ExtensionObject field (Extra).
    has(format!("Structure:{parts}:5001 {{ Double:0 Double:-1 Double:0.5 }}"));
    has(format!("Structure:{parts}:5003 {{ NodeId:{parts}:6001 QualifiedName:{parts}:\"RackSlot\" }}"));
    // Arrays of structures: of ExtensionObjects as a value, in place as a field.
    has("Array:22 { Structure:0:886 { Double:0 Double:1 } Structure:0:886 { Double:-1 Double:1000 } }".to_string());
    has(format!("Structure:{own}:5007 {{ Array:22 {{ Fields:{{ String:\"Mill\""));
}

#[test]
fn a_value_that_cannot_be_served_names_its_variable_at_its_value() {
    let out = compile_text();
    let (_, diags) = tables(&out, &["http://example.com/values/"]);
    // Calibration's DataType has no Default Binary encoding; Broken has a field that does not decode.
    assert!(
        diags.contains("the value of `Target/Calibration` (nsu=http://example.com/values/;i=30) is not served: structure `values:Calibrated` has no Default Binary encoding"),
        "{diags}"
    );
    assert!(diags.contains("--> structure_values.xml:61:7"), "at the ExtensionObject inside <Value>: {diags}");
    assert!(
        diags.contains("the value of `Target/Broken` (nsu=http://example.com/values/;i=31) is not served: field `Count`: <Count>many</Count> is not a valid Count"),
        "{diags}"
    );
}

fn compile_text() -> Compiled {
    let opts = Options { model_dirs: vec![vendor()], ..Options::default() };
    compile(vec![Input::Text { name: "structure_values.xml".into(), text: TEXT.into() }], &opts)
}

/// The skill nodesets (nodesets/*.NodeSet2.xml) have 111 EUInformation values: every one is in the tables.
#[test]
fn the_skill_nodesets_serve_every_structure_value() {
    let files: Vec<PathBuf> = ["CommonSkills", "RobotCell", "DrillingProcess"].iter().map(|n| root().join(format!("nodesets/{n}.NodeSet2.xml"))).collect();
    let opts = Options { model_dirs: vec![vendor(), root().join("nodesets")], ..Options::default() };
    let out = compile(files.into_iter().map(Input::Path).collect(), &opts);
    assert!(!out.diagnostics.has_errors(), "{}", out.render_diagnostics());
    let uris = ["http://nodeset-compiler.dev/CommonSkills/", "http://nodeset-compiler.dev/RobotCell/", "http://nodeset-compiler.dev/DrillingProcess/"];
    let (texts, diags) = tables(&out, &uris);
    assert!(!diags.contains("is not served"), "{diags}");
    let counts: Vec<usize> = texts.iter().map(|(_, t)| rows(t).iter().filter_map(value_of).filter(is_structure).count()).collect();
    assert_eq!(counts, [12, 38, 61], "structure values served per namespace");
}
