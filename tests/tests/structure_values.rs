//! Structure values are decoded once, by the model, against their DataType's definition: typed fields with
//! NodeIds and QualifiedNames mapped, nested structures, enumerations, arrays, unions, inherited fields, and
//! the reason for a field that does not decode. Nothing after the model reads a value's XML.

use nodeset_compiler::load::Input;
use nodeset_compiler::model::Model;
use nodeset_compiler::nodeid::{NodeId, QualifiedName};
use nodeset_compiler::value::{Body, BuiltinType, Structure, Variant};
use nodeset_compiler::{compile, Options};
use nodeset_tests::vendor;

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
