//! The raw model of one NodeSet2 file: what the file says, nothing resolved.
//!
//! Strings are kept as written (NodeIds and aliases are not yet expanded) together with their spans, so
//! that later stages can point at the exact attribute a problem comes from. The strings the resolver only
//! looks up (NodeIds, reference types and targets) are [`RawStr`]s: spans into the file's text, with a copy
//! only where the string differs from the text it was read from. The elements of `<Value>`s are kept the
//! same way, in one [`ValueArena`] per file.

use crate::source::{FileId, Span, Spanned};

/// The eight node classes of OPC UA.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum NodeClass {
    /// An Object (`UAObject`).
    Object,
    /// A Variable (`UAVariable`).
    Variable,
    /// A Method (`UAMethod`).
    Method,
    /// A View (`UAView`).
    View,
    /// An ObjectType (`UAObjectType`).
    ObjectType,
    /// A VariableType (`UAVariableType`).
    VariableType,
    /// A ReferenceType (`UAReferenceType`).
    ReferenceType,
    /// A DataType (`UADataType`).
    DataType,
}

impl NodeClass {
    /// Every node class, in the order of the variants.
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

    /// The class whose NodeSet2 element name is `name` (`UAObject`, ...).
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

    /// Whether the class is one of the four type classes (ObjectType, VariableType, ReferenceType, DataType).
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
    /// The `Locale`, such as `de-DE`; `None` when it is absent or empty.
    pub locale: Option<String>,
    /// The text.
    pub text: String,
}

/// A `<RequiredModel>` of a `<Model>`: a model the file's model depends on.
#[derive(Clone, Debug)]
pub struct RawRequiredModel {
    /// The ModelUri attribute (empty when missing).
    pub uri: String,
    /// The Version attribute.
    pub version: Option<String>,
    /// The PublicationDate attribute, as written.
    pub publication_date: Option<String>,
    /// The ModelVersion attribute.
    pub model_version: Option<String>,
    /// The XmlSchemaUri attribute.
    pub xml_schema_uri: Option<String>,
    /// The span of the start tag.
    pub span: Span,
}

/// A `<Model>` of `<Models>`: a model the file defines.
#[derive(Clone, Debug)]
pub struct RawModel {
    /// The ModelUri attribute (empty when missing).
    pub uri: String,
    /// The Version attribute.
    pub version: Option<String>,
    /// The PublicationDate attribute, as written.
    pub publication_date: Option<String>,
    /// The ModelVersion attribute.
    pub model_version: Option<String>,
    /// The XmlSchemaUri attribute.
    pub xml_schema_uri: Option<String>,
    /// The `<RequiredModel>`s, in document order.
    pub required: Vec<RawRequiredModel>,
    /// The model's `<RolePermissions>`.
    pub role_permissions: Vec<RawRolePermission>,
    /// The AccessRestrictions attribute.
    pub access_restrictions: Option<u16>,
    /// The span of the start tag.
    pub span: Span,
}

/// An `<Alias>` of `<Aliases>`: a name that stands for a NodeId.
#[derive(Clone, Debug)]
pub struct RawAlias {
    /// The name (the `Alias` attribute).
    pub alias: String,
    /// The NodeId the alias stands for: the element's trimmed text, with its span.
    pub target: Spanned<String>,
    /// The span of the start tag.
    pub span: Span,
}

/// A string read from a file (an attribute value or an element's text), kept as its span in the file's
/// text. The string is stored only where it differs from what the span covers: after entity or character
/// references (`&amp;`, `&#160;`) were expanded, line breaks normalised or white space trimmed.
///
/// Most such strings are NodeIds, and almost all NodeIds are numeric: their numbers are read with the
/// string, while the parser has the text at hand, so that the resolver need not read the text again.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct RawStr {
    /// Where the string was read in the file (for a string made by [`RawStr::owned`], the span given to it).
    pub span: Span,
    owned: Option<Box<str>>,
    numeric: Option<(u16, u32)>,
}

impl RawStr {
    /// `value` as read at `span` of `source`: borrowed from the source when it is exactly the text there.
    pub fn new(value: &str, span: Span, source: &str) -> RawStr {
        // A value borrowed from the source is the text at its span; only copies need comparing.
        let same = source
            .get(span.start as usize..span.end as usize)
            .is_some_and(|at| std::ptr::eq(at.as_ptr(), value.as_ptr()) && at.len() == value.len() || at == value);
        let numeric = crate::nodeid::parse_numeric_node_id(value);
        RawStr { span, owned: if same { None } else { Some(value.into()) }, numeric }
    }

    /// A string that is not the text at its span (such as the empty NodeId of a node that has none).
    pub fn owned(value: &str, span: Span) -> RawStr {
        RawStr { span, owned: Some(value.into()), numeric: crate::nodeid::parse_numeric_node_id(value) }
    }

    /// The string as a numeric NodeId (`i=N` or `ns=I;i=N`): what
    /// [`parse_numeric_node_id`](crate::nodeid::parse_numeric_node_id) gives for it.
    pub fn numeric_node_id(&self) -> Option<(u16, u32)> {
        self.numeric
    }

    /// The string, given the text of the file it was read from.
    pub fn get<'s>(&'s self, source: &'s str) -> &'s str {
        match &self.owned {
            Some(s) => s,
            None => source.get(self.span.start as usize..self.span.end as usize).unwrap_or(""),
        }
    }
}

/// A `<Reference>` of a node.
#[derive(Clone, Debug)]
pub struct RawReference {
    /// The ReferenceType attribute (a NodeId or alias), trimmed.
    pub reference_type: RawStr,
    /// The target node (a NodeId or alias): the element's trimmed text.
    pub target: RawStr,
    /// The IsForward attribute; `true` when it is absent.
    pub is_forward: bool,
    /// The span of the start tag.
    pub span: Span,
}

/// A `<RolePermission>`: a role and the permissions it is granted.
#[derive(Clone, Debug)]
pub struct RawRolePermission {
    /// The role's NodeId (or alias): the element's trimmed text, with its span.
    pub role: Spanned<String>,
    /// The Permissions attribute (a bit mask); 0 when absent or invalid.
    pub permissions: u32,
}

/// A field of a `<Definition>`.
#[derive(Clone, Debug)]
pub struct RawField {
    /// The Name attribute (empty when missing).
    pub name: String,
    /// The SymbolicName attribute.
    pub symbolic_name: Option<String>,
    /// The DataType attribute (a NodeId or alias), with its span.
    pub data_type: Option<Spanned<String>>,
    /// The ValueRank attribute.
    pub value_rank: Option<i32>,
    /// The ArrayDimensions attribute, unparsed.
    pub array_dimensions: Option<String>,
    /// The MaxStringLength attribute.
    pub max_string_length: Option<u32>,
    /// The IsOptional attribute; `false` when absent.
    pub is_optional: bool,
    /// The AllowSubTypes attribute; `false` when absent.
    pub allow_sub_types: bool,
    /// The Value attribute (of an enumeration or option set field).
    pub value: Option<i64>,
    /// The field's `<DisplayName>`s.
    pub display_names: Vec<LocalizedText>,
    /// The field's `<Description>`s.
    pub descriptions: Vec<LocalizedText>,
    /// The span of the start tag.
    pub span: Span,
}

/// A DataType's `<Definition>`.
#[derive(Clone, Debug)]
pub struct RawDefinition {
    /// The Name attribute.
    pub name: String,
    /// The SymbolicName attribute.
    pub symbolic_name: Option<String>,
    /// The BaseType attribute, with its span.
    pub base_type: Option<Spanned<String>>,
    /// The IsUnion attribute; `false` when absent.
    pub is_union: bool,
    /// The IsOptionSet attribute; `false` when absent.
    pub is_option_set: bool,
    /// The `<Field>`s, in document order.
    pub fields: Vec<RawField>,
    /// The span of the start tag.
    pub span: Span,
}

/// An XML element of a `<Extensions>` (or of a `<Value>`, built from its [`ValueElement`] on request), kept as
/// an owned tree.
#[derive(Clone, Debug, PartialEq)]
pub struct XmlElement {
    /// Local name, without namespace prefix.
    pub name: String,
    /// The attributes, local name and value, in document order.
    pub attributes: Vec<(String, String)>,
    /// The child elements, in document order.
    pub children: Vec<XmlElement>,
    /// The concatenated text content (line endings normalised to `\n`).
    pub text: String,
    /// The start tag.
    pub span: Span,
}

impl XmlElement {
    /// The first child element named `name`, if any.
    pub fn child(&self, name: &str) -> Option<&XmlElement> {
        self.children.iter().find(|c| c.name == name)
    }

    /// The value of the attribute named `name`, if present.
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
    /// The node class, from the element's name.
    pub class: NodeClass,
    /// The span of the start tag.
    pub span: Span,
    /// The NodeId attribute, as written (empty when missing).
    pub node_id: RawStr,
    /// The BrowseName attribute, as written (empty when missing).
    pub browse_name: RawStr,
    /// The BrowseName read as `N:Name` (local namespace index), when it is one: read by the parser while
    /// the text is at hand. `None` when it is malformed or missing; the resolver then reads the text and
    /// says what is wrong.
    pub qualified_name: Option<crate::nodeid::RawQualifiedName>,
    /// The SymbolicName attribute.
    pub symbolic_name: Option<String>,
    /// The WriteMask attribute.
    pub write_mask: Option<u32>,
    /// The UserWriteMask attribute.
    pub user_write_mask: Option<u32>,
    /// The AccessRestrictions attribute.
    pub access_restrictions: Option<u16>,
    /// The HasNoPermissions attribute.
    pub has_no_permissions: Option<bool>,
    /// The ReleaseStatus attribute, as written.
    pub release_status: Option<String>,
    /// The `<DisplayName>`s, in document order.
    pub display_names: Vec<LocalizedText>,
    /// The `<Description>`s, in document order.
    pub descriptions: Vec<LocalizedText>,
    /// The texts of the `<Category>` elements, trimmed.
    pub category: Vec<String>,
    /// The text of the `<Documentation>` element.
    pub documentation: Option<String>,
    /// The node's `<Reference>`s: a range of its file's [`RawNodeSet::references`] (read them with
    /// [`RawNodeSet::references_of`]). One list per file, not one per node: nearly every node has
    /// references, and a list of its own cost an allocation or more per node to build and free.
    pub references: RefRange,
    /// The node's `<RolePermissions>`.
    pub role_permissions: Vec<RawRolePermission>,
    /// The child elements of `<Extensions>`.
    pub extensions: Vec<XmlElement>,
    // Instance attributes.
    /// The ParentNodeId attribute.
    pub parent_node_id: Option<RawStr>,
    // Variable and VariableType attributes.
    /// The DataType attribute (a NodeId or alias).
    pub data_type: Option<RawStr>,
    /// The ValueRank attribute.
    pub value_rank: Option<i32>,
    /// The ArrayDimensions attribute, unparsed, with its span.
    pub array_dimensions: Option<Spanned<String>>,
    /// The AccessLevel attribute (bit 0x01 CurrentRead, 0x02 CurrentWrite); a value above 255 is kept as its
    /// low byte.
    pub access_level: Option<u8>,
    /// The UserAccessLevel attribute; a value above 255 is kept as its low byte.
    pub user_access_level: Option<u8>,
    /// The AccessLevelEx attribute.
    pub access_level_ex: Option<u32>,
    /// The MinimumSamplingInterval attribute.
    pub minimum_sampling_interval: Option<f64>,
    /// The Historizing attribute.
    pub historizing: Option<bool>,
    /// The element inside `<Value>`, if any, in the file's [`ValueArena`].
    pub value: Option<ValueRef>,
    // Method attributes.
    /// The Executable attribute.
    pub executable: Option<bool>,
    /// The UserExecutable attribute.
    pub user_executable: Option<bool>,
    /// The MethodDeclarationId attribute.
    pub method_declaration_id: Option<RawStr>,
    // Object and View attributes.
    /// The EventNotifier attribute.
    pub event_notifier: Option<u8>,
    /// The ContainsNoLoops attribute.
    pub contains_no_loops: Option<bool>,
    // Type attributes.
    /// The IsAbstract attribute.
    pub is_abstract: Option<bool>,
    /// The Symmetric attribute of a ReferenceType.
    pub symmetric: Option<bool>,
    /// The `<InverseName>`s of a ReferenceType, in document order.
    pub inverse_names: Vec<LocalizedText>,
    /// Boxed: only DataTypes have one, and every other node would carry its room.
    pub definition: Option<Box<RawDefinition>>,
    /// The Purpose attribute of a DataType, as written.
    pub purpose: Option<String>,
}

impl RawNode {
    /// A node of class `class` with start tag `span` and no attributes read yet: its NodeId and BrowseName
    /// are empty strings spanning the start tag.
    pub fn new(class: NodeClass, span: Span) -> RawNode {
        // Until the attributes are read: empty strings spanning the start tag.
        let empty = RawStr::owned("", span);
        RawNode {
            class,
            span,
            node_id: empty.clone(),
            browse_name: empty,
            qualified_name: None,
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
            references: RefRange::default(),
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
    /// The file the set was read from.
    pub file: FileId,
    /// The start tag of `<UANodeSet>`.
    pub root_span: Span,
    /// The `<Uri>`s of `<NamespaceUris>`, trimmed, with their spans: the first is namespace index 1.
    pub namespace_uris: Vec<Spanned<String>>,
    /// The `<Uri>`s of `<ServerUris>`, trimmed, with their spans.
    pub server_uris: Vec<Spanned<String>>,
    /// The `<Model>`s of `<Models>`: the models the file defines.
    pub models: Vec<RawModel>,
    /// The `<Alias>`es of `<Aliases>`, in document order.
    pub aliases: Vec<RawAlias>,
    /// The node elements, in document order.
    pub nodes: Vec<RawNode>,
    /// The references of every node, in document order (see [`RawNode::references`]).
    pub references: Vec<RawReference>,
    /// The LastModified attribute of `<UANodeSet>`, as written.
    pub last_modified: Option<String>,
    /// The elements of every `<Value>` of the file.
    pub values: ValueArena,
}

impl RawNodeSet {
    /// The references of one of the file's nodes.
    pub fn references_of(&self, node: &RawNode) -> &[RawReference] {
        self.references.get(node.references.start as usize..node.references.end as usize).unwrap_or_default()
    }
}

/// A node's references: the range `start..end` of its file's [`RawNodeSet::references`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RefRange {
    /// The index of the node's first reference.
    pub start: u32,
    /// The index after the node's last reference.
    pub end: u32,
}

impl RefRange {
    /// The number of references.
    pub fn len(&self) -> usize {
        (self.end - self.start) as usize
    }

    /// Whether the node has no references.
    pub fn is_empty(&self) -> bool {
        self.start == self.end
    }
}

/// A node's value: the element inside its `<Value>`, as an index into its file's [`ValueArena`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ValueRef(pub(crate) u32);

/// The elements of the `<Value>`s of one file, as one tree of spans into the file's text.
///
/// Values make up a large share of the elements of a NodeSet2 file (some 13,000 elements in the base
/// namespace), and most of them are only ever checked against their DataType. The parser reads each value
/// once and records every element here, without a string of its own where the name, attribute or text is
/// a slice of the file; [`ValueElement`] reads the tree in place and [`ValueElement::to_xml`] builds an
/// owned [`XmlElement`] where one is wanted.
///
/// Elements are stored in document order; an element's descendants follow it, up to its `end`.
#[derive(Clone, Debug, Default)]
pub struct ValueArena {
    elements: Vec<ArenaElement>,
    attributes: Vec<ArenaAttribute>,
    /// Texts and attribute values that are not a slice of the file.
    owned: Vec<Box<str>>,
}

#[derive(Clone, Copy, Debug)]
struct ArenaElement {
    /// The start tag.
    span: Span,
    /// The local name, as a byte range of the file.
    name: (u32, u32),
    text: ArenaText,
    /// The element's range of [`ValueArena::attributes`].
    attributes: (u32, u32),
    /// The index after the element's last descendant.
    end: u32,
}

#[derive(Clone, Copy, Debug)]
struct ArenaAttribute {
    /// The local name, as a byte range of the file.
    key: (u32, u32),
    value: ArenaText,
}

/// A string of the arena: a byte range of the file, or an index into [`ValueArena::owned`].
#[derive(Clone, Copy, Debug)]
enum ArenaText {
    Slice(u32, u32),
    Owned(u32),
}

const EMPTY: ArenaText = ArenaText::Slice(0, 0);

/// Where a string lies in `source`, if it is a slice of it.
fn range_in(source: &str, s: &str) -> Option<(u32, u32)> {
    let base = source.as_ptr() as usize;
    let p = s.as_ptr() as usize;
    (p >= base && p + s.len() <= base + source.len()).then(|| ((p - base) as u32, (p - base + s.len()) as u32))
}

impl ValueArena {
    fn text<'a>(&'a self, t: ArenaText, source: &'a str) -> &'a str {
        match t {
            ArenaText::Slice(a, b) => source.get(a as usize..b as usize).unwrap_or(""),
            ArenaText::Owned(i) => &self.owned[i as usize],
        }
    }

    /// Stores a string read from `source`: as a range if it is a slice of it, else as a copy.
    fn store(&mut self, s: &str, source: &str) -> ArenaText {
        if s.is_empty() {
            return EMPTY;
        }
        match range_in(source, s) {
            Some((a, b)) => ArenaText::Slice(a, b),
            None => {
                self.owned.push(s.into());
                ArenaText::Owned(self.owned.len() as u32 - 1)
            }
        }
    }

    /// Opens an element (the parser calls this with the element's start tag, local name and attributes,
    /// all read from `source`) and returns its index.
    pub(crate) fn open<'s>(
        &mut self,
        span: Span,
        name: &'s str,
        attributes: impl Iterator<Item = (&'s str, &'s str)>,
        source: &'s str,
    ) -> u32 {
        let first = self.attributes.len() as u32;
        for (k, v) in attributes {
            let key = range_in(source, k).unwrap_or((0, 0));
            let value = self.store(v, source);
            self.attributes.push(ArenaAttribute { key, value });
        }
        let name = range_in(source, name).unwrap_or((0, 0));
        self.elements.push(ArenaElement {
            span,
            name,
            text: EMPTY,
            attributes: (first, self.attributes.len() as u32),
            end: u32::MAX,
        });
        self.elements.len() as u32 - 1
    }

    /// Appends a piece of text to an open element's text.
    pub(crate) fn push_text(&mut self, ix: u32, piece: &str, source: &str) {
        if piece.is_empty() {
            return;
        }
        let el = self.elements[ix as usize];
        let current = self.text(el.text, source);
        let text = if current.is_empty() {
            self.store(piece, source)
        } else {
            let joined: Box<str> = [current, piece].concat().into();
            match el.text {
                ArenaText::Owned(i) => {
                    self.owned[i as usize] = joined;
                    el.text
                }
                ArenaText::Slice(..) => {
                    self.owned.push(joined);
                    ArenaText::Owned(self.owned.len() as u32 - 1)
                }
            }
        };
        self.elements[ix as usize].text = text;
    }

    /// Closes an element: an element with children keeps no text (it is only formatting white space
    /// between them); the text of a leaf has its line breaks normalised to `\n`.
    pub(crate) fn close(&mut self, ix: u32, source: &str) {
        let end = self.elements.len() as u32;
        let el = &mut self.elements[ix as usize];
        el.end = end;
        if end > ix + 1 {
            el.text = EMPTY;
            return;
        }
        let text = el.text;
        let current = self.text(text, source);
        if current.contains('\r') {
            let normalized: Box<str> = current.replace("\r\n", "\n").replace('\r', "\n").into();
            self.owned.push(normalized);
            self.elements[ix as usize].text = ArenaText::Owned(self.owned.len() as u32 - 1);
        }
    }

    /// Appends the elements of another arena of the same file (read from a later piece of it) and returns
    /// the index its first element now has: [`ValueRef`]s into `other` move by that much.
    pub(crate) fn append(&mut self, other: ValueArena) -> u32 {
        let (elements, attributes, owned) = (self.elements.len() as u32, self.attributes.len() as u32, self.owned.len() as u32);
        let text = |t: ArenaText| match t {
            ArenaText::Owned(i) => ArenaText::Owned(i + owned),
            slice => slice,
        };
        self.elements.extend(other.elements.into_iter().map(|e| ArenaElement {
            text: text(e.text),
            attributes: (e.attributes.0 + attributes, e.attributes.1 + attributes),
            end: e.end + elements,
            ..e
        }));
        self.attributes.extend(other.attributes.into_iter().map(|a| ArenaAttribute { value: text(a.value), ..a }));
        self.owned.extend(other.owned);
        elements
    }

    /// The element `ix`, read against the text of the file the arena belongs to.
    pub fn element<'a>(&'a self, value: ValueRef, source: &'a str) -> ValueElement<'a> {
        ValueElement { arena: self, source, ix: value.0 }
    }

    /// The number of elements (for capacity planning and statistics).
    pub fn len(&self) -> usize {
        self.elements.len()
    }

    /// Whether the arena holds no elements.
    pub fn is_empty(&self) -> bool {
        self.elements.is_empty()
    }
}

/// An element of a value, read in place from its file's [`ValueArena`]; it reads as an [`XmlElement`] does.
#[derive(Clone, Copy)]
pub struct ValueElement<'a> {
    arena: &'a ValueArena,
    source: &'a str,
    ix: u32,
}

impl std::fmt::Debug for ValueElement<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(&self.to_xml(), f)
    }
}

impl<'a> ValueElement<'a> {
    /// The element's index in its arena.
    pub(crate) fn index(&self) -> u32 {
        self.ix
    }

    fn data(&self) -> &'a ArenaElement {
        &self.arena.elements[self.ix as usize]
    }

    /// Local name, without namespace prefix.
    pub fn name(&self) -> &'a str {
        let (a, b) = self.data().name;
        self.source.get(a as usize..b as usize).unwrap_or("")
    }

    /// The text content of a leaf element (line endings normalised to `\n`); empty for an element with
    /// children.
    pub fn text(&self) -> &'a str {
        self.arena.text(self.data().text, self.source)
    }

    /// The start tag.
    pub fn span(&self) -> Span {
        self.data().span
    }

    /// The attributes, local name and value, in document order.
    pub fn attributes(&self) -> impl Iterator<Item = (&'a str, &'a str)> + 'a {
        let (arena, source) = (self.arena, self.source);
        let (first, last) = self.data().attributes;
        arena.attributes[first as usize..last as usize].iter().map(move |a| {
            let key = source.get(a.key.0 as usize..a.key.1 as usize).unwrap_or("");
            (key, arena.text(a.value, source))
        })
    }

    /// The value of the attribute named `name`, if present.
    pub fn attr(&self, name: &str) -> Option<&'a str> {
        self.attributes().find(|(k, _)| *k == name).map(|(_, v)| v)
    }

    /// The child elements, in document order.
    pub fn children(&self) -> impl Iterator<Item = ValueElement<'a>> + 'a {
        let (arena, source) = (self.arena, self.source);
        let end = self.data().end;
        let mut next = self.ix + 1;
        std::iter::from_fn(move || {
            if next >= end {
                return None;
            }
            let child = ValueElement { arena, source, ix: next };
            next = arena.elements[next as usize].end;
            Some(child)
        })
    }

    /// The first child element named `name`, if any.
    pub fn child(&self, name: &str) -> Option<ValueElement<'a>> {
        self.children().find(|c| c.name() == name)
    }

    /// Text of a child element, if present.
    pub fn child_text(&self, name: &str) -> Option<&'a str> {
        self.child(name).map(|c| c.text())
    }

    /// The element alone, without its children, as an owned [`XmlElement`].
    fn shallow(&self) -> XmlElement {
        XmlElement {
            name: self.name().to_string(),
            attributes: self.attributes().map(|(k, v)| (k.to_string(), v.to_string())).collect(),
            children: Vec::new(),
            text: self.text().to_string(),
            span: self.span(),
        }
    }

    /// The element and everything inside it as an owned tree (built without recursion, as values may nest
    /// as deeply as the parser's limits allow).
    pub fn to_xml(&self) -> XmlElement {
        // Each frame: the element being built, and the index of its next child.
        let mut stack: Vec<(XmlElement, u32, u32)> = vec![(self.shallow(), self.data().end, self.ix + 1)];
        loop {
            let top = stack.last_mut().expect("the stack holds the root until it is returned");
            if top.2 < top.1 {
                let child = ValueElement { arena: self.arena, source: self.source, ix: top.2 };
                top.2 = child.data().end;
                stack.push((child.shallow(), child.data().end, child.ix + 1));
                continue;
            }
            let (done, _, _) = stack.pop().expect("checked above");
            match stack.last_mut() {
                Some(parent) => parent.0.children.push(done),
                None => return done,
            }
        }
    }
}
