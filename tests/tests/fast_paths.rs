//! The resolver's fast paths give what the general paths give, on inputs chosen to tell them apart.

use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, Options};
use nodeset_tests::vendor;

fn compile_text(text: &str) -> nodeset_compiler::Compiled {
    let opts = Options { model_dirs: vec![vendor()], all_warnings: true, ..Options::default() };
    compile(vec![Input::Text { name: "fast_paths.xml".into(), text: text.into() }], &opts)
}

#[test]
fn an_alias_that_looks_like_a_node_id_shadows_the_node_id() {
    // `i=58` is BaseObjectType, but this file declares an alias of that name for FolderType (i=61); the
    // alias wins, as it always did, for the type definition and for the reference type (`i=45` -> i=47).
    let text = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">
  <NamespaceUris><Uri>http://example.com/fast/</Uri></NamespaceUris>
  <Models><Model ModelUri="http://example.com/fast/" Version="1.0"/></Models>
  <Aliases><Alias Alias="i=58">i=61</Alias><Alias Alias="i=45">i=47</Alias></Aliases>
  <UAObject NodeId="ns=1;i=1" BrowseName="1:A">
    <DisplayName>A</DisplayName>
    <References>
      <Reference ReferenceType="HasTypeDefinition">i=58</Reference>
      <Reference ReferenceType="i=45" IsForward="false">i=85</Reference>
    </References>
  </UAObject>
</UANodeSet>"#;
    let out = compile_text(text);
    assert!(out.ok(), "{}", out.render_diagnostics());
    let m = &out.model;
    let a = m.find("http://example.com/fast/#A")[0];
    assert_eq!(m.node(m.node(a).type_definition.unwrap()).browse_name.name, "FolderType");
    let parent_ref = m.node(a).references.iter().find(|r| !r.forward).unwrap();
    assert_eq!(m.node(parent_ref.reference_type).browse_name.name, "HasComponent");
}

#[test]
fn numeric_node_ids_that_name_nothing_are_reported_by_the_general_path() {
    let text = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">
  <NamespaceUris><Uri>http://example.com/fast/</Uri></NamespaceUris>
  <Models><Model ModelUri="http://example.com/fast/" Version="1.0"/></Models>
  <UAObject NodeId="ns=1;i=1" BrowseName="1:A">
    <DisplayName>A</DisplayName>
    <References>
      <Reference ReferenceType="i=40">ns=1;i=99</Reference>
      <Reference ReferenceType="i=58">i=85</Reference>
      <Reference ReferenceType="i=999999">i=85</Reference>
      <Reference ReferenceType="i=35" IsForward="false">ns=7;i=85</Reference>
    </References>
  </UAObject>
</UANodeSet>"#;
    let out = compile_text(text);
    let codes: Vec<(&str, &str)> = out.diagnostics.items.iter().map(|d| (d.code.as_str(), d.message.as_str())).collect();
    assert_eq!(
        codes,
        [
            ("NS0202", "`nsu=http://example.com/fast/;i=99` names no node"),
            ("NS0203", "ReferenceType `i=58` is an ObjectType, not a ReferenceType"),
            ("NS0203", "ReferenceType `i=999999` names no loaded node"),
            ("NS0106", "namespace index 7 is not declared in this file's NamespaceUris"),
        ],
        "{}",
        out.render_diagnostics()
    );
}
