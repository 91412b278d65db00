//! The raw model of one NodeSet2 file: what the file says, nothing resolved.
//!
//! Strings are kept as written (NodeIds and aliases are not yet expanded) together with their spans, so
//! that later stages can point at the exact attribute a problem comes from.

use crate::source::{FileId, Span, Spanned};

/// The eight node classes of OPC UA.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum NodeClass {
    Object,
    Variable,
    Method,
    View,
    ObjectType,
    VariableType,
    ReferenceType,
    DataType,
}

impl NodeClass {
    pub const ALL: [NodeClass; 8] = [
        NodeClass::Object,
        NodeClass::Variable,
        NodeClass::Method,
        NodeClass::View,
        NodeClass::ObjectType,
        NodeClass::VariableType,
        NodeClass::ReferenceType,
        NodeClass::DataType,
    ];

    /// The element name in NodeSet2 (`UAObject`, ...).
    pub fn element(self) -> &'static str {
        match self {
            NodeClass::Object => "UAObject",
            NodeClass::Variable => "UAVariable",
            NodeClass::Method => "UAMethod",
            NodeClass::View => "UAView",
            NodeClass::ObjectType => "UAObjectType",
            NodeClass::VariableType => "UAVariableType",
            NodeClass::ReferenceType => "UAReferenceType",
            NodeClass::DataType => "UADataType",
        }
    }

    pub fn from_element(name: &str) -> Option<NodeClass> {
        NodeClass::ALL.into_iter().find(|c| c.element() == name)
    }

    /// The name OPC UA gives the class (`Object`, ...).
    pub fn name(self) -> &'static str {
        &self.element()[2..]
    }

    /// The NodeClass mask value of OPC UA Part 3.
    pub fn mask(self) -> u32 {
        match self {
            NodeClass::Object => 1,
            NodeClass::Variable => 2,
            NodeClass::Method => 4,
            NodeClass::ObjectType => 8,
            NodeClass::VariableType => 16,
            NodeClass::ReferenceType => 32,
            NodeClass::DataType => 64,
            NodeClass::View => 128,
        }
    }

    pub fn is_type(self) -> bool {
        matches!(
            self,
            NodeClass::ObjectType | NodeClass::VariableType | NodeClass::ReferenceType | NodeClass::DataType
        )
    }
}

/// A localized text: `<DisplayName Locale="de-DE">…</DisplayName>`.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct LocalizedText {
    pub locale: Option<String>,
    pub text: String,
}

#[derive(Clone, Debug)]
pub struct RawRequiredModel {
    pub uri: String,
    pub version: Option<String>,
    pub publication_date: Option<String>,
    pub model_version: Option<String>,
    pub xml_schema_uri: Option<String>,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct RawModel {
    pub uri: String,
    pub version: Option<String>,
    pub publication_date: Option<String>,
    pub model_version: Option<String>,
    pub xml_schema_uri: Option<String>,
    pub required: Vec<RawRequiredModel>,
    pub role_permissions: Vec<RawRolePermission>,
    pub access_restrictions: Option<u16>,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct RawAlias {
    pub alias: String,
    pub target: Spanned<String>,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct RawReference {
    pub reference_type: Spanned<String>,
    pub target: Spanned<String>,
    pub is_forward: bool,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct RawRolePermission {
    pub role: Spanned<String>,
    pub permissions: u32,
}

/// A field of a `<Definition>`.
#[derive(Clone, Debug)]
pub struct RawField {
    pub name: String,
    pub symbolic_name: Option<String>,
    pub data_type: Option<Spanned<String>>,
    pub value_rank: Option<i32>,
    pub array_dimensions: Option<String>,
    pub max_string_length: Option<u32>,
    pub is_optional: bool,
    pub allow_sub_types: bool,
    pub value: Option<i64>,
    pub display_names: Vec<LocalizedText>,
    pub descriptions: Vec<LocalizedText>,
    pub span: Span,
}

/// A DataType's `<Definition>`.
#[derive(Clone, Debug)]
pub struct RawDefinition {
    pub name: String,
    pub symbolic_name: Option<String>,
    pub base_type: Option<Spanned<String>>,
    pub is_union: bool,
    pub is_option_set: bool,
    pub fields: Vec<RawField>,
    pub span: Span,
}

/// An XML element of a `<Value>` (or of `<Extensions>`), kept as a tree to be decoded against the model.
#[derive(Clone, Debug, PartialEq)]
pub struct XmlElement {
    /// Local name, without namespace prefix.
    pub name: String,
    pub attributes: Vec<(String, String)>,
    pub children: Vec<XmlElement>,
    /// The concatenated text content (line endings normalised to `\n`).
    pub text: String,
    pub span: Span,
}

impl XmlElement {
    pub fn child(&self, name: &str) -> Option<&XmlElement> {
        self.children.iter().find(|c| c.name == name)
    }

    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attributes.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_str())
    }

    /// Text of a child element, if present.
    pub fn child_text(&self, name: &str) -> Option<&str> {
        self.child(name).map(|c| c.text.as_str())
    }
}

/// One node element, with every attribute of UANodeSet.xsd (class-specific ones are `None` elsewhere).
#[derive(Clone, Debug)]
pub struct RawNode {
    pub class: NodeClass,
    /// The span of the start tag.
    pub span: Span,
    pub node_id: Spanned<String>,
    pub browse_name: Spanned<String>,
    pub symbolic_name: Option<String>,
    pub write_mask: Option<u32>,
    pub user_write_mask: Option<u32>,
    pub access_restrictions: Option<u16>,
    pub has_no_permissions: Option<bool>,
    pub release_status: Option<String>,
    pub display_names: Vec<LocalizedText>,
    pub descriptions: Vec<LocalizedText>,
    pub category: Vec<String>,
    pub documentation: Option<String>,
    pub references: Vec<RawReference>,
    pub role_permissions: Vec<RawRolePermission>,
    pub extensions: Vec<XmlElement>,
    // Instance attributes.
    pub parent_node_id: Option<Spanned<String>>,
    // Variable and VariableType attributes.
    pub data_type: Option<Spanned<String>>,
    pub value_rank: Option<i32>,
    pub array_dimensions: Option<Spanned<String>>,
    pub access_level: Option<u8>,
    pub user_access_level: Option<u8>,
    pub access_level_ex: Option<u32>,
    pub minimum_sampling_interval: Option<f64>,
    pub historizing: Option<bool>,
    /// The element inside `<Value>`, if any.
    pub value: Option<XmlElement>,
    // Method attributes.
    pub executable: Option<bool>,
    pub user_executable: Option<bool>,
    pub method_declaration_id: Option<Spanned<String>>,
    // Object and View attributes.
    pub event_notifier: Option<u8>,
    pub contains_no_loops: Option<bool>,
    // Type attributes.
    pub is_abstract: Option<bool>,
    pub symmetric: Option<bool>,
    pub inverse_names: Vec<LocalizedText>,
    pub definition: Option<RawDefinition>,
    pub purpose: Option<String>,
}

impl RawNode {
    pub fn new(class: NodeClass, span: Span) -> RawNode {
        let empty = Spanned { value: String::new(), span };
        RawNode {
            class,
            span,
            node_id: empty.clone(),
            browse_name: empty,
            symbolic_name: None,
            write_mask: None,
            user_write_mask: None,
            access_restrictions: None,
            has_no_permissions: None,
            release_status: None,
            display_names: Vec::new(),
            descriptions: Vec::new(),
            category: Vec::new(),
            documentation: None,
            references: Vec::new(),
            role_permissions: Vec::new(),
            extensions: Vec::new(),
            parent_node_id: None,
            data_type: None,
            value_rank: None,
            array_dimensions: None,
            access_level: None,
            user_access_level: None,
            access_level_ex: None,
            minimum_sampling_interval: None,
            historizing: None,
            value: None,
            executable: None,
            user_executable: None,
            method_declaration_id: None,
            event_notifier: None,
            contains_no_loops: None,
            is_abstract: None,
            symmetric: None,
            inverse_names: Vec::new(),
            definition: None,
            purpose: None,
        }
    }
}

/// One parsed NodeSet2 file.
#[derive(Clone, Debug)]
pub struct RawNodeSet {
    pub file: FileId,
    pub root_span: Span,
    pub namespace_uris: Vec<Spanned<String>>,
    pub server_uris: Vec<Spanned<String>>,
    pub models: Vec<RawModel>,
    pub aliases: Vec<RawAlias>,
    pub nodes: Vec<RawNode>,
    pub last_modified: Option<String>,
}
