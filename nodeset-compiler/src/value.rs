//! Decoding `<Value>` trees into typed values.
//!
//! The parser keeps a value in its file's [`ValueArena`](crate::raw::ValueArena); a value can also be an
//! owned [`XmlElement`] tree. This module turns either into a [`Variant`]: every built-in scalar, `ListOf…`
//! arrays, and ExtensionObjects whose TypeId is resolved and whose body is kept as a tree. NodeIds inside values
//! are written with file-local namespace indices, so decoding takes a function that maps them.
//!
//! [`Model::value`](crate::model::Model::value) is where a node's value is decoded: it also decodes every
//! structure body against its DataType's definition ([`Structure`]), so that what the resolver and the emitters
//! read is typed data, never XML or a file's namespace table.

use crate::nodeid::{base64_decode, base64_valid, parse_guid, NodeId, QualifiedName};
use crate::raw::{LocalizedText, ValueElement, XmlElement};
use std::sync::Arc;

/// An element as the decoder reads it: an owned [`XmlElement`] or a [`ValueElement`] read in place.
pub(crate) trait XmlNode<'a>: Copy {
    fn name(self) -> &'a str;
    fn text(self) -> &'a str;
    fn children(self) -> impl Iterator<Item = Self>;
    fn to_xml(self) -> XmlElement;
    /// The element as read in place, if it is one (structure bodies are decoded only from those).
    fn in_place(self) -> Option<ValueElement<'a>>;

    fn child(self, name: &str) -> Option<Self> {
        self.children().find(|c| c.name() == name)
    }

    fn child_text(self, name: &str) -> Option<&'a str> {
        self.child(name).map(|c| c.text())
    }
}

impl<'a> XmlNode<'a> for &'a XmlElement {
    fn name(self) -> &'a str {
        &self.name
    }

    fn text(self) -> &'a str {
        &self.text
    }

    fn children(self) -> impl Iterator<Item = Self> {
        self.children.iter()
    }

    fn to_xml(self) -> XmlElement {
        self.clone()
    }

    fn in_place(self) -> Option<ValueElement<'a>> {
        None
    }
}

impl<'a> XmlNode<'a> for ValueElement<'a> {
    fn name(self) -> &'a str {
        ValueElement::name(&self)
    }

    fn text(self) -> &'a str {
        ValueElement::text(&self)
    }

    fn children(self) -> impl Iterator<Item = Self> {
        ValueElement::children(&self)
    }

    fn to_xml(self) -> XmlElement {
        ValueElement::to_xml(&self)
    }

    fn in_place(self) -> Option<ValueElement<'a>> {
        Some(self)
    }
}

/// The built-in types of OPC UA Part 6, by their ns0 numeric id.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u8)]
pub enum BuiltinType {
    /// Boolean: true or false.
    Boolean = 1,
    /// SByte: a signed 8-bit integer.
    SByte = 2,
    /// Byte: an unsigned 8-bit integer.
    Byte = 3,
    /// Int16: a signed 16-bit integer.
    Int16 = 4,
    /// UInt16: an unsigned 16-bit integer.
    UInt16 = 5,
    /// Int32: a signed 32-bit integer.
    Int32 = 6,
    /// UInt32: an unsigned 32-bit integer.
    UInt32 = 7,
    /// Int64: a signed 64-bit integer.
    Int64 = 8,
    /// UInt64: an unsigned 64-bit integer.
    UInt64 = 9,
    /// Float: an IEEE 754 single-precision number.
    Float = 10,
    /// Double: an IEEE 754 double-precision number.
    Double = 11,
    /// String: a Unicode text.
    String = 12,
    /// DateTime: a point in time.
    DateTime = 13,
    /// Guid: a 16-byte globally unique identifier.
    Guid = 14,
    /// ByteString: a sequence of bytes.
    ByteString = 15,
    /// XmlElement: an XML fragment.
    XmlElement = 16,
    /// NodeId: the identifier of a node.
    NodeId = 17,
    /// ExpandedNodeId: a NodeId that may name its namespace by URI and its server.
    ExpandedNodeId = 18,
    /// StatusCode: a 32-bit result code.
    StatusCode = 19,
    /// QualifiedName: a name qualified by a namespace index.
    QualifiedName = 20,
    /// LocalizedText: a text with an optional locale.
    LocalizedText = 21,
    /// ExtensionObject: an encoded structure together with the id of its type.
    ExtensionObject = 22,
    /// DataValue: a value with its status and timestamps.
    DataValue = 23,
    /// Variant: a value of any built-in type.
    Variant = 24,
    /// DiagnosticInfo: details of an error.
    DiagnosticInfo = 25,
}

impl BuiltinType {
    /// Every built-in type, in the order of their ids.
    pub const ALL: [BuiltinType; 25] = [
        BuiltinType::Boolean,
        BuiltinType::SByte,
        BuiltinType::Byte,
        BuiltinType::Int16,
        BuiltinType::UInt16,
        BuiltinType::Int32,
        BuiltinType::UInt32,
        BuiltinType::Int64,
        BuiltinType::UInt64,
        BuiltinType::Float,
        BuiltinType::Double,
        BuiltinType::String,
        BuiltinType::DateTime,
        BuiltinType::Guid,
        BuiltinType::ByteString,
        BuiltinType::XmlElement,
        BuiltinType::NodeId,
        BuiltinType::ExpandedNodeId,
        BuiltinType::StatusCode,
        BuiltinType::QualifiedName,
        BuiltinType::LocalizedText,
        BuiltinType::ExtensionObject,
        BuiltinType::DataValue,
        BuiltinType::Variant,
        BuiltinType::DiagnosticInfo,
    ];

    /// The built-in type with ns0 numeric id `id`, if there is one.
    pub fn from_id(id: u32) -> Option<BuiltinType> {
        BuiltinType::ALL.get((id as usize).wrapping_sub(1)).copied()
    }

    /// The type's ns0 numeric id.
    pub fn id(self) -> u32 {
        self as u32
    }

    /// The XML element name of a scalar of this type.
    pub fn xml_name(self) -> &'static str {
        match self {
            BuiltinType::ExtensionObject => "ExtensionObject",
            BuiltinType::Variant => "Variant",
            other => other.type_name(),
        }
    }

    /// The DataType's BrowseName in ns0 (`Structure` for ExtensionObject, `BaseDataType` for Variant).
    pub fn type_name(self) -> &'static str {
        match self {
            BuiltinType::Boolean => "Boolean",
            BuiltinType::SByte => "SByte",
            BuiltinType::Byte => "Byte",
            BuiltinType::Int16 => "Int16",
            BuiltinType::UInt16 => "UInt16",
            BuiltinType::Int32 => "Int32",
            BuiltinType::UInt32 => "UInt32",
            BuiltinType::Int64 => "Int64",
            BuiltinType::UInt64 => "UInt64",
            BuiltinType::Float => "Float",
            BuiltinType::Double => "Double",
            BuiltinType::String => "String",
            BuiltinType::DateTime => "DateTime",
            BuiltinType::Guid => "Guid",
            BuiltinType::ByteString => "ByteString",
            BuiltinType::XmlElement => "XmlElement",
            BuiltinType::NodeId => "NodeId",
            BuiltinType::ExpandedNodeId => "ExpandedNodeId",
            BuiltinType::StatusCode => "StatusCode",
            BuiltinType::QualifiedName => "QualifiedName",
            BuiltinType::LocalizedText => "LocalizedText",
            BuiltinType::ExtensionObject => "Structure",
            BuiltinType::DataValue => "DataValue",
            BuiltinType::Variant => "BaseDataType",
            BuiltinType::DiagnosticInfo => "DiagnosticInfo",
        }
    }

    /// The built-in type whose scalar element is named `name` (see [`BuiltinType::xml_name`]).
    pub fn from_xml_name(name: &str) -> Option<BuiltinType> {
        BuiltinType::ALL.into_iter().find(|b| b.xml_name() == name)
    }

    /// Whether the type is one of the eight integer types.
    pub fn is_integer(self) -> bool {
        matches!(
            self,
            BuiltinType::SByte
                | BuiltinType::Byte
                | BuiltinType::Int16
                | BuiltinType::UInt16
                | BuiltinType::Int32
                | BuiltinType::UInt32
                | BuiltinType::Int64
                | BuiltinType::UInt64
        )
    }

    /// Whether the type is an unsigned integer type.
    pub fn is_unsigned(self) -> bool {
        matches!(self, BuiltinType::Byte | BuiltinType::UInt16 | BuiltinType::UInt32 | BuiltinType::UInt64)
    }

    /// Whether the type is an integer type, Float or Double.
    pub fn is_number(self) -> bool {
        self.is_integer() || matches!(self, BuiltinType::Float | BuiltinType::Double)
    }
}

/// An ExtensionObject from a value: its encoding or type id and its body.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtensionObject {
    /// The TypeId as written (usually the XML encoding node, sometimes the DataType itself).
    pub type_id: Option<NodeId>,
    /// What `<Body>` holds, if anything.
    pub body: Option<Body>,
}

impl ExtensionObject {
    /// The structure, if the body was decoded against its DataType's definition.
    pub fn structure(&self) -> Option<&Structure> {
        match &self.body {
            Some(Body::Structure(s)) => Some(s),
            _ => None,
        }
    }
}

/// The body of an ExtensionObject.
#[derive(Clone, Debug, PartialEq)]
pub enum Body {
    /// The fields, decoded against the definition of the DataType the TypeId names. [`Model::value`]
    /// decodes every body it can this way.
    ///
    /// [`Model::value`]: crate::model::Model::value
    Structure(Structure),
    /// The element inside `<Body>` as written: the TypeId names no structure with a definition, or the value
    /// was decoded without the model's DataTypes ([`decode`]).
    Xml(XmlElement),
}

/// A structure value, decoded against its DataType's definition (inherited fields included). NodeIds and
/// QualifiedNames in it are mapped like those of any value.
#[derive(Clone, Debug, PartialEq)]
pub struct Structure {
    /// The DataType.
    pub data_type: NodeId,
    /// A union's SwitchField, if the value gives one.
    pub switch_field: Option<u32>,
    /// The fields the value gives, in the definition's order; a field it leaves out is absent. A field that
    /// does not decode holds the reason. An array field (ValueRank 0 or more) is a [`Variant::Array`].
    pub fields: Vec<(Arc<str>, Result<Variant, String>)>,
}

impl Structure {
    /// A field's value: `None` if the value leaves it out, the reason if it does not decode.
    pub fn get(&self, name: &str) -> Option<&Result<Variant, String>> {
        self.fields.iter().find(|(n, _)| &**n == name).map(|(_, v)| v)
    }

    /// A field's value, if the value gives it and it decodes.
    pub fn field(&self, name: &str) -> Option<&Variant> {
        self.get(name).and_then(|v| v.as_ref().ok())
    }

    /// The text of a String, LocalizedText or QualifiedName field; `None` if absent, empty or of another type.
    pub fn text(&self, name: &str) -> Option<&str> {
        match self.field(name)? {
            Variant::String(s) => Some(s.as_str()),
            Variant::LocalizedText(t) => Some(t.text.as_str()),
            Variant::QualifiedName(q) => Some(q.name.as_str()),
            _ => None,
        }
        .filter(|s| !s.is_empty())
    }
}

/// A decoded value.
#[derive(Clone, Debug, PartialEq)]
pub enum Variant {
    /// A Boolean.
    Boolean(bool),
    /// An SByte.
    SByte(i8),
    /// A Byte.
    Byte(u8),
    /// An Int16.
    Int16(i16),
    /// A UInt16.
    UInt16(u16),
    /// An Int32.
    Int32(i32),
    /// A UInt32.
    UInt32(u32),
    /// An Int64.
    Int64(i64),
    /// A UInt64.
    UInt64(u64),
    /// A Float.
    Float(f32),
    /// A Double.
    Double(f64),
    /// A String.
    String(String),
    /// A DateTime, as its trimmed text.
    DateTime(String),
    /// A Guid, as the 16 bytes of its text order.
    Guid([u8; 16]),
    /// A ByteString, decoded from base64.
    ByteString(Vec<u8>),
    /// An XmlElement, as the tree of its element; DataValues and DiagnosticInfos are kept this way too.
    XmlElement(XmlElement),
    /// A NodeId, as the [`NodeIdMapper`] maps it.
    NodeId(NodeId),
    /// An ExpandedNodeId, as the [`NodeIdMapper`] maps it.
    ExpandedNodeId(NodeId),
    /// A StatusCode, as its numeric code.
    StatusCode(u32),
    /// A QualifiedName, its namespace index mapped by the [`NsMapper`].
    QualifiedName(QualifiedName),
    /// A LocalizedText.
    LocalizedText(LocalizedText),
    /// An ExtensionObject.
    ExtensionObject(Box<ExtensionObject>),
    /// A Variant: the value inside it.
    Variant(Box<Variant>),
    /// `ListOf…`: the element type and the items.
    Array(BuiltinType, Vec<Variant>),
    /// An element that decodes to nothing (`<String/>` is an empty string, but `<NodeId/>` is null).
    Null,
}

impl Variant {
    /// The built-in type of the value (for arrays, of their elements).
    pub fn builtin(&self) -> Option<BuiltinType> {
        Some(match self {
            Variant::Boolean(_) => BuiltinType::Boolean,
            Variant::SByte(_) => BuiltinType::SByte,
            Variant::Byte(_) => BuiltinType::Byte,
            Variant::Int16(_) => BuiltinType::Int16,
            Variant::UInt16(_) => BuiltinType::UInt16,
            Variant::Int32(_) => BuiltinType::Int32,
            Variant::UInt32(_) => BuiltinType::UInt32,
            Variant::Int64(_) => BuiltinType::Int64,
            Variant::UInt64(_) => BuiltinType::UInt64,
            Variant::Float(_) => BuiltinType::Float,
            Variant::Double(_) => BuiltinType::Double,
            Variant::String(_) => BuiltinType::String,
            Variant::DateTime(_) => BuiltinType::DateTime,
            Variant::Guid(_) => BuiltinType::Guid,
            Variant::ByteString(_) => BuiltinType::ByteString,
            Variant::XmlElement(_) => BuiltinType::XmlElement,
            Variant::NodeId(_) => BuiltinType::NodeId,
            Variant::ExpandedNodeId(_) => BuiltinType::ExpandedNodeId,
            Variant::StatusCode(_) => BuiltinType::StatusCode,
            Variant::QualifiedName(_) => BuiltinType::QualifiedName,
            Variant::LocalizedText(_) => BuiltinType::LocalizedText,
            Variant::ExtensionObject(_) => BuiltinType::ExtensionObject,
            Variant::Variant(_) => BuiltinType::Variant,
            Variant::Array(b, _) => *b,
            Variant::Null => return None,
        })
    }

    /// Whether the value is a `ListOf…` array.
    pub fn is_array(&self) -> bool {
        matches!(self, Variant::Array(..))
    }

    /// The value of an integer as an `i64`, if it is one and fits.
    pub fn as_i64(&self) -> Option<i64> {
        match *self {
            Variant::SByte(v) => Some(v.into()),
            Variant::Byte(v) => Some(v.into()),
            Variant::Int16(v) => Some(v.into()),
            Variant::UInt16(v) => Some(v.into()),
            Variant::Int32(v) => Some(v.into()),
            Variant::UInt32(v) => Some(v.into()),
            Variant::Int64(v) => Some(v),
            Variant::UInt64(v) => i64::try_from(v).ok(),
            _ => None,
        }
    }
}

/// Maps a NodeId string found inside a value (file-local namespace indices, aliases) to a global NodeId.
pub type NodeIdMapper<'a> = dyn Fn(&str) -> Result<NodeId, String> + 'a;
/// Maps a file-local namespace index (of a QualifiedName) to a global one.
pub type NsMapper<'a> = dyn Fn(u16) -> Option<u16> + 'a;

/// How much of a value decoding copies out of the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Content {
    /// Everything: the value [`decode`] returns.
    All,
    /// What a check of the value against its DataType needs. The value decodes, or fails with the same
    /// error, as with `All`, with the same type and shape, but nothing it holds is copied: strings,
    /// localized texts and byte strings (checked, not decoded) are empty, ExtensionObjects have no body.
    Shape,
}

/// Decodes the body of an ExtensionObject into a [`Structure`], for [`Decoder::structures`]: the model, which
/// knows the DataTypes.
pub(crate) trait Structures {
    /// The fields of `body`, if `type_id` names a structure with a definition; `depth` is the nesting so far.
    fn structure(&self, type_id: &NodeId, body: ValueElement<'_>, depth: usize) -> Option<Structure>;
}

/// What decoding needs besides the element: the mappers, how much to copy, and who decodes structure bodies.
#[derive(Clone, Copy)]
pub(crate) struct Decoder<'d> {
    /// Maps NodeIds written in the file.
    pub ids: &'d NodeIdMapper<'d>,
    /// Maps namespace indices written in the file.
    pub ns: &'d NsMapper<'d>,
    /// How much to copy.
    pub content: Content,
    /// Decodes structure bodies read in place; without it (or for owned trees) a body is kept as XML.
    pub structures: Option<&'d dyn Structures>,
}

/// Decodes one value element. Errors name the element and what is wrong with it.
pub fn decode(el: &XmlElement, ids: &NodeIdMapper, ns: &NsMapper) -> Result<Variant, String> {
    decode_node(el, Decoder { ids, ns, content: Content::All, structures: None })
}

/// Decodes one value element read in place from its file's value arena.
pub fn decode_element(el: ValueElement<'_>, ids: &NodeIdMapper, ns: &NsMapper) -> Result<Variant, String> {
    decode_node(el, Decoder { ids, ns, content: Content::All, structures: None })
}

/// Decodes an element as `d` says.
pub(crate) fn decode_node<'a, E: XmlNode<'a>>(el: E, d: Decoder) -> Result<Variant, String> {
    decode_depth(el, d, 0)
}

fn decode_depth<'a, E: XmlNode<'a>>(el: E, d: Decoder, depth: usize) -> Result<Variant, String> {
    if depth > 64 {
        return Err("the value is nested more than 64 levels deep".into());
    }
    let name = el.name();
    if let Some(item) = name.strip_prefix("ListOf") {
        let b = BuiltinType::from_xml_name(item).ok_or_else(|| format!("<{name}> is not a known array type"))?;
        let mut items = Vec::new();
        for c in el.children() {
            if c.name() != item {
                return Err(format!("<{}> inside <{name}>: expected <{item}>", c.name()));
            }
            items.push(scalar(b, c, d, depth)?);
        }
        return Ok(Variant::Array(b, items));
    }
    let b = BuiltinType::from_xml_name(name).ok_or_else(|| format!("<{name}> is not a built-in type"))?;
    scalar(b, el, d, depth)
}

fn num<'a, T: std::str::FromStr, E: XmlNode<'a>>(el: E) -> Result<T, String> {
    let t = el.text().trim();
    let name = el.name();
    t.parse::<T>().map_err(|_| format!("<{name}>{t}</{name}> is not a valid {name}"))
}

fn float<'a, T: std::str::FromStr, E: XmlNode<'a>>(el: E) -> Result<T, String> {
    let t = el.text().trim();
    let t = match t {
        "INF" => "inf",
        "-INF" => "-inf",
        "NaN" => "NaN",
        other => other,
    };
    let name = el.name();
    t.parse::<T>().map_err(|_| format!("<{name}>{}</{name}> is not a valid {name}", el.text().trim()))
}

/// Decodes an element known to hold a scalar of type `b`.
pub fn decode_scalar(
    b: BuiltinType,
    el: &XmlElement,
    ids: &NodeIdMapper,
    ns: &NsMapper,
    depth: usize,
) -> Result<Variant, String> {
    scalar(b, el, Decoder { ids, ns, content: Content::All, structures: None }, depth)
}

/// Decodes an element known to hold a scalar of type `b`, as `d` says.
pub(crate) fn scalar<'a, E: XmlNode<'a>>(b: BuiltinType, el: E, d: Decoder, depth: usize) -> Result<Variant, String> {
    let (ids, ns) = (d.ids, d.ns);
    let all = d.content == Content::All;
    // The text of `el` if everything is copied, else an empty string.
    let copy = |s: &str| if all { s.to_string() } else { String::new() };
    Ok(match b {
        BuiltinType::Boolean => match el.text().trim() {
            "true" | "1" => Variant::Boolean(true),
            "false" | "0" => Variant::Boolean(false),
            t => return Err(format!("<Boolean>{t}</Boolean> is not true or false")),
        },
        BuiltinType::SByte => Variant::SByte(num(el)?),
        BuiltinType::Byte => Variant::Byte(num(el)?),
        BuiltinType::Int16 => Variant::Int16(num(el)?),
        BuiltinType::UInt16 => Variant::UInt16(num(el)?),
        BuiltinType::Int32 => Variant::Int32(num(el)?),
        BuiltinType::UInt32 => Variant::UInt32(num(el)?),
        BuiltinType::Int64 => Variant::Int64(num(el)?),
        BuiltinType::UInt64 => Variant::UInt64(num(el)?),
        BuiltinType::Float => Variant::Float(float(el)?),
        BuiltinType::Double => Variant::Double(float(el)?),
        BuiltinType::String => Variant::String(copy(el.text())),
        BuiltinType::DateTime => Variant::DateTime(copy(el.text().trim())),
        BuiltinType::Guid => {
            let t = el.child_text("String").unwrap_or(el.text());
            Variant::Guid(parse_guid(t).ok_or_else(|| format!("`{}` is not a GUID", t.trim()))?)
        }
        BuiltinType::ByteString => {
            let bytes = if all { base64_decode(el.text()) } else { base64_valid(el.text()).then(Vec::new) };
            Variant::ByteString(bytes.ok_or_else(|| "the ByteString is not base64".to_string())?)
        }
        BuiltinType::XmlElement => Variant::XmlElement(el.to_xml()),
        BuiltinType::NodeId | BuiltinType::ExpandedNodeId => {
            let t = el.child_text("Identifier").unwrap_or("").trim();
            if t.is_empty() {
                Variant::Null
            } else {
                let id = ids(t)?;
                if b == BuiltinType::NodeId {
                    Variant::NodeId(id)
                } else {
                    Variant::ExpandedNodeId(id)
                }
            }
        }
        BuiltinType::StatusCode => {
            let t = el.child_text("Code").unwrap_or(el.text()).trim();
            let code = if let Some(h) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
                u32::from_str_radix(h, 16).ok()
            } else {
                t.parse::<u32>().ok()
            };
            Variant::StatusCode(code.ok_or_else(|| format!("`{t}` is not a StatusCode"))?)
        }
        BuiltinType::QualifiedName => {
            let idx: u16 = match el.child_text("NamespaceIndex") {
                Some(t) => t.trim().parse().map_err(|_| format!("NamespaceIndex `{}` is not a number", t.trim()))?,
                None => 0,
            };
            let g = ns(idx).ok_or_else(|| format!("namespace index {idx} of a QualifiedName is not declared"))?;
            Variant::QualifiedName(QualifiedName { ns: g, name: copy(el.child_text("Name").unwrap_or("").trim()) })
        }
        BuiltinType::LocalizedText if !all => Variant::LocalizedText(LocalizedText::default()),
        BuiltinType::LocalizedText => Variant::LocalizedText(LocalizedText {
            locale: el.child_text("Locale").map(|s| s.trim().to_string()).filter(|s| !s.is_empty()),
            text: el.child_text("Text").unwrap_or("").to_string(),
        }),
        BuiltinType::ExtensionObject => {
            let type_id = match el.child("TypeId").and_then(|t| t.child_text("Identifier")) {
                Some(t) if !t.trim().is_empty() => Some(ids(t.trim())?),
                _ => None,
            };
            let body = match el.child("Body").and_then(|b| b.children().next()) {
                Some(b) if all => {
                    let decoded = match (d.structures, &type_id, b.in_place()) {
                        (Some(st), Some(t), Some(b)) => st.structure(t, b, depth + 1),
                        _ => None,
                    };
                    Some(decoded.map_or_else(|| Body::Xml(b.to_xml()), Body::Structure))
                }
                _ => None,
            };
            Variant::ExtensionObject(Box::new(ExtensionObject { type_id, body }))
        }
        BuiltinType::Variant => {
            let inner = el.children().next().ok_or_else(|| "<Variant> is empty".to_string())?;
            let inner = if inner.name() == "Value" {
                inner.children().next().ok_or_else(|| "<Variant><Value> is empty".to_string())?
            } else {
                inner
            };
            Variant::Variant(Box::new(decode_depth(inner, d, depth + 1)?))
        }
        BuiltinType::DataValue | BuiltinType::DiagnosticInfo => Variant::XmlElement(el.to_xml()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::{FileId, Span};

    fn el(name: &str, text: &str, children: Vec<XmlElement>) -> XmlElement {
        XmlElement {
            name: name.into(),
            attributes: vec![],
            children,
            text: text.into(),
            span: Span::new(FileId(0), 0, 0),
        }
    }

    fn ids(s: &str) -> Result<NodeId, String> {
        let r = crate::nodeid::parse_node_id(s)?;
        match r.ns {
            crate::nodeid::NsRef::Index(i) => Ok(NodeId { ns: i + 10, id: r.id }),
            crate::nodeid::NsRef::Uri(_) => Err("uri".into()),
        }
    }

    #[test]
    fn shape_decoding_fails_and_succeeds_as_full_decoding_does() {
        let ns = |i: u16| (i < 3).then_some(i + 10);
        let leaf = |name: &str, text: &str| el(name, text, vec![]);
        let cases = vec![
            leaf("String", " a b "),
            leaf("DateTime", " 2020-01-01 "),
            leaf("ByteString", "AQID\n BA=="),
            leaf("ByteString", "AQ*D"),
            leaf("ByteString", "AQ==A"),
            leaf("ByteString", "A==="),
            leaf("Int32", "x"),
            el("LocalizedText", "", vec![leaf("Locale", "de"), leaf("Text", "t")]),
            el("QualifiedName", "", vec![leaf("NamespaceIndex", "2"), leaf("Name", "n")]),
            el("QualifiedName", "", vec![leaf("NamespaceIndex", "5"), leaf("Name", "n")]),
            el("QualifiedName", "", vec![leaf("NamespaceIndex", "x")]),
            el("ListOfString", "", vec![leaf("String", "a"), leaf("String", "b")]),
            el("ListOfString", "", vec![leaf("String", "a"), leaf("Int32", "1")]),
            el("ListOfLocalizedText", "", vec![el("LocalizedText", "", vec![leaf("Text", "t")])]),
            el("ExtensionObject", "", vec![el("TypeId", "", vec![leaf("Identifier", "i=5")]), el("Body", "", vec![leaf("X", "")])]),
            el("ExtensionObject", "", vec![el("TypeId", "", vec![leaf("Identifier", "q=5")])]),
            el("Variant", "", vec![el("Value", "", vec![leaf("String", "s")])]),
            el("Variant", "", vec![]),
        ];
        for c in &cases {
            let all = decode_node(c, Decoder { ids: &ids, ns: &ns, content: Content::All, structures: None });
            let shape = decode_node(c, Decoder { ids: &ids, ns: &ns, content: Content::Shape, structures: None });
            match (&all, &shape) {
                (Ok(a), Ok(s)) => assert_eq!((a.builtin(), a.is_array()), (s.builtin(), s.is_array()), "{c:?}"),
                (Err(a), Err(s)) => assert_eq!(a, s),
                _ => panic!("{c:?}: {all:?} but {shape:?}"),
            }
        }
        for s in ["", "AQID", "AQ ID\r\n", "AQ=", "AQ==", "AQ===", "A=Q", "*", "\u{e9}"] {
            assert_eq!(base64_valid(s), base64_decode(s).is_some(), "{s:?}");
        }
    }

    #[test]
    fn decodes_scalars_arrays_and_extension_objects() {
        let ns = |i: u16| Some(i + 10);
        assert_eq!(decode(&el("Int32", " -5 ", vec![]), &ids, &ns).unwrap(), Variant::Int32(-5));
        assert!(decode(&el("Byte", "256", vec![]), &ids, &ns).is_err());
        assert_eq!(decode(&el("Double", "INF", vec![]), &ids, &ns).unwrap(), Variant::Double(f64::INFINITY));
        let list = el("ListOfUInt32", "", vec![el("UInt32", "1", vec![]), el("UInt32", "2", vec![])]);
        assert_eq!(
            decode(&list, &ids, &ns).unwrap(),
            Variant::Array(BuiltinType::UInt32, vec![Variant::UInt32(1), Variant::UInt32(2)])
        );
        let eo = el(
            "ExtensionObject",
            "",
            vec![
                el("TypeId", "", vec![el("Identifier", "ns=1;i=5", vec![])]),
                el("Body", "", vec![el("Argument", "", vec![el("Name", "X", vec![])])]),
            ],
        );
        match decode(&eo, &ids, &ns).unwrap() {
            Variant::ExtensionObject(e) => {
                assert_eq!(e.type_id, Some(NodeId::numeric(11, 5)));
                let Some(Body::Xml(body)) = e.body else { panic!("{:?}", e.body) };
                assert_eq!(body.child_text("Name"), Some("X"));
            }
            other => panic!("{other:?}"),
        }
        let qn = el("QualifiedName", "", vec![el("NamespaceIndex", "1", vec![]), el("Name", "N", vec![])]);
        assert_eq!(
            decode(&qn, &ids, &ns).unwrap(),
            Variant::QualifiedName(QualifiedName { ns: 11, name: "N".into() })
        );
    }
}
