//! Values: where a node's `<Value>` becomes typed data.
//!
//! [`Model::value`] decodes a value (see [`crate::value`]) in place with its file's aliases and namespace table, and
//! decodes every ExtensionObject body whose TypeId names a structure with a definition into a [`Structure`],
//! field by field, against the classified DataTypes. The resolver's method arguments and enumeration values and
//! both emitters read structures this way; nothing after this module reads a value's XML or a file's namespace
//! table.
//!
//! Values stay in their files' arenas and are decoded on each call: the model holds no decoded copy.

use super::*;
use crate::value::{Body, Decoder, ExtensionObject, Structure, Structures};

/// How deep structures may nest inside one value.
const MAX_DEPTH: usize = 32;

/// The DataTypes a structure body is decoded against: the model's own, or those classified so far while the
/// resolver classifies them (enumerations read their EnumValues property that way).
pub(crate) type DataTypes = BTreeMap<NodeIx, DataTypeInfo>;

/// Decodes the values of one file: its NodeIds and namespace indices mapped, its structure bodies decoded
/// against `types`.
struct FileDecoder<'m> {
    model: &'m Model,
    ctx: Option<&'m FileContext>,
    types: &'m DataTypes,
}

impl FileDecoder<'_> {
    fn node_id(&self, s: &str) -> Result<NodeId, String> {
        self.model.map_node_id(self.ctx.ok_or("unknown file")?, s)
    }

    fn ns(&self, i: u16) -> Option<u16> {
        self.ctx.and_then(|c| c.ns_map.get(i as usize).copied())
    }

    /// Runs `f` with the [`Decoder`] of this file; `structures` says whether structure bodies are decoded.
    fn with<R>(&self, content: Content, structures: bool, f: impl FnOnce(Decoder) -> R) -> R {
        let ids = |s: &str| self.node_id(s);
        let ns = |i: u16| self.ns(i);
        f(Decoder { ids: &ids, ns: &ns, content, structures: structures.then_some(self as &dyn Structures) })
    }

    /// The fields of the structure `dt` from a body element (`<Argument><Name>..</Name>...`); `None` when `dt`
    /// is not a structure with a definition (an OptionSet structure included) or nesting is too deep.
    fn decode_structure(&self, dt: NodeIx, body: ValueElement<'_>, depth: usize) -> Option<Structure> {
        if depth > MAX_DEPTH {
            return None;
        }
        let DataTypeKind::Structure { kind, fields, has_definition: true } = &self.types.get(&dt)?.kind else { return None };
        let switch_field = match kind {
            StructureKind::Union => body.child_text("SwitchField").and_then(|t| t.trim().parse().ok()),
            _ => None,
        };
        let fields = fields
            .iter()
            .filter_map(|f| {
                let el = body.child(&f.name)?;
                Some((f.name.clone(), self.decode_field(f, el, depth)))
            })
            .collect();
        Some(Structure { data_type: self.model.node(dt).id.clone(), switch_field, fields })
    }

    /// One field's element: each child an item for an array field (ValueRank 0 or more), else the value.
    fn decode_field(&self, f: &Field, el: ValueElement<'_>, depth: usize) -> Result<Variant, String> {
        let item = |el: ValueElement<'_>| self.decode_field_item(f.data_type, el, depth).map_err(|e| format!("field `{}`: {e}", f.name));
        if f.value_rank < 0 {
            return item(el);
        }
        let items = el.children().map(item).collect::<Result<Vec<_>, _>>()?;
        let builtin = match self.types.get(&f.data_type) {
            Some(DataTypeInfo { kind: DataTypeKind::Enumeration { .. }, .. }) => BuiltinType::Int32,
            Some(info) => info.encoding,
            None => BuiltinType::Variant,
        };
        Ok(Variant::Array(builtin, items))
    }

    /// One value of DataType `dt`, written as the content of `el`: an enumeration as `Name_5`, a structure
    /// with a definition as its fields (or as an ExtensionObject, for a subtype), anything else as its
    /// built-in type.
    fn decode_field_item(&self, dt: NodeIx, el: ValueElement<'_>, depth: usize) -> Result<Variant, String> {
        let info = self.types.get(&dt).ok_or("the field's DataType is not classified")?;
        match &info.kind {
            DataTypeKind::Enumeration { .. } => {
                let t = el.text().trim();
                let n = t.rsplit('_').next().and_then(|n| n.parse::<i32>().ok());
                n.map(Variant::Int32).ok_or_else(|| format!("`{t}` is not an enumeration value (`Name_5`)"))
            }
            DataTypeKind::Structure { has_definition: true, .. } if el.child("Body").is_none() && el.child("TypeId").is_none() => {
                let s = self.decode_structure(dt, el, depth + 1).ok_or("the structure nests too deep")?;
                let type_id = Some(self.model.node(dt).id.clone());
                Ok(Variant::ExtensionObject(Box::new(ExtensionObject { type_id, body: Some(Body::Structure(s)) })))
            }
            _ => self.with(Content::All, true, |d| crate::value::scalar(info.encoding, el, d, depth + 1)),
        }
    }
}

impl Structures for FileDecoder<'_> {
    fn structure(&self, type_id: &NodeId, body: ValueElement<'_>, depth: usize) -> Option<Structure> {
        let dt = self.model.structure_of_type_id(type_id)?;
        self.decode_structure(dt, body, depth)
    }
}

impl Model {
    /// The element inside a node's `<Value>`, read in place from its file's text.
    pub fn value_element(&self, ix: NodeIx) -> Option<ValueElement<'_>> {
        let node = self.node(ix);
        let value = node.value?;
        let arena = self.value_arenas.get(node.file.0 as usize)?;
        Some(arena.element(value, &self.sources.get(node.file).text))
    }

    /// The element inside a node's `<Value>` as an owned tree, built on each call (with the spans of the
    /// file it was read from). To only read a value, [`Model::value_element`] needs no copy.
    pub fn value_xml(&self, ix: NodeIx) -> Option<XmlElement> {
        self.value_element(ix).map(|e| e.to_xml())
    }

    /// Decodes a node's value, mapping the NodeIds in it through its file's namespace table and decoding its
    /// structures against their DataTypes ([`crate::value::Body::Structure`]).
    pub fn value(&self, ix: NodeIx) -> Option<Result<Variant, String>> {
        self.value_with(ix, &self.data_types)
    }

    /// [`Model::value`] against the DataTypes in `types`.
    pub(crate) fn value_with(&self, ix: NodeIx, types: &DataTypes) -> Option<Result<Variant, String>> {
        let el = self.value_element(ix)?;
        let file = self.file_decoder(self.node(ix).file, types);
        Some(file.with(Content::All, true, |d| crate::value::decode_node(el, d)))
    }

    /// [`Model::value`], copying only what `content` says (structures are not decoded).
    pub(crate) fn decode_value(&self, ix: NodeIx, content: Content) -> Option<Result<Variant, String>> {
        if content == Content::All {
            return self.value(ix);
        }
        let el = self.value_element(ix)?;
        let file = self.file_decoder(self.node(ix).file, &self.data_types);
        Some(file.with(content, false, |d| crate::value::decode_node(el, d)))
    }

    fn file_decoder<'m>(&'m self, file: FileId, types: &'m DataTypes) -> FileDecoder<'m> {
        FileDecoder { model: self, ctx: self.files.get(&file), types }
    }

    pub(crate) fn map_node_id(&self, ctx: &FileContext, s: &str) -> Result<NodeId, String> {
        let s = s.trim();
        let text = ctx.aliases.get(s).map(|t| t.value.as_str()).unwrap_or(s);
        let raw = crate::nodeid::parse_node_id(text)?;
        let ns = match raw.ns {
            crate::nodeid::NsRef::Index(i) => {
                *ctx.ns_map.get(i as usize).ok_or_else(|| format!("namespace index {i} is not declared"))?
            }
            crate::nodeid::NsRef::Uri(u) => {
                self.namespaces.iter().position(|n| *n == u).ok_or_else(|| format!("namespace `{u}` is not loaded"))?
                    as u16
            }
        };
        Ok(NodeId { ns, id: raw.id })
    }

    /// The structure DataType a TypeId names: the DataType itself, or the DataType one of its encodings
    /// (`Default XML`, usually) belongs to.
    pub fn structure_of_type_id(&self, type_id: &NodeId) -> Option<NodeIx> {
        let ix = self.lookup(type_id)?;
        let n = self.node(ix);
        if n.class == NodeClass::DataType {
            return Some(ix);
        }
        let has_encoding = self.ns0(ids::HAS_ENCODING)?;
        n.references.iter().find(|r| !r.forward && r.reference_type == has_encoding).map(|r| r.target)
    }
}

impl Argument {
    /// The method argument an Argument structure value describes; `Err` when the structure is of another
    /// DataType, a field does not decode, or its DataType names no node.
    pub fn from_structure(model: &Model, s: &Structure) -> Result<Argument, String> {
        if model.lookup(&s.data_type) != model.ns0(ids::ARGUMENT) {
            return Err(format!("an element is a {}, not an Argument", model.display_id(&s.data_type)));
        }
        let name = s.text("Name").unwrap_or("").trim().to_string();
        let data_type = match s.get("DataType") {
            Some(Ok(Variant::NodeId(id))) => Some(model.lookup(id).ok_or_else(|| {
                format!("argument `{name}` has DataType {} which names no node", model.display_id(id))
            })?),
            Some(Ok(_)) | None => None,
            Some(Err(e)) => return Err(e.clone()),
        };
        let value_rank = match s.get("ValueRank") {
            Some(Ok(v)) => v.as_i64().and_then(|v| i32::try_from(v).ok()).unwrap_or(-1),
            Some(Err(e)) => return Err(e.clone()),
            None => -1,
        };
        let array_dimensions = match s.field("ArrayDimensions") {
            Some(Variant::Array(_, items)) => items.iter().filter_map(|d| d.as_i64().and_then(|d| u32::try_from(d).ok())).collect(),
            _ => Vec::new(),
        };
        let description = s.text("Description").map(str::to_string);
        Ok(Argument { name, data_type, value_rank, array_dimensions, description })
    }
}

impl EnumValue {
    /// The entry an EnumValueType structure value (of an EnumValues property) gives: its DisplayName is the
    /// name; `value` stands in for a Value that is missing.
    pub fn from_enum_value_type(s: &Structure, value: i64) -> EnumValue {
        let text = s.text("DisplayName").unwrap_or("").to_string();
        EnumValue {
            name: text.clone(),
            value: s.field("Value").and_then(Variant::as_i64).unwrap_or(value),
            display_name: Some(text),
            description: s.text("Description").map(str::to_string),
        }
    }
}
