//! The values of the node table: each value the model decodes ([`Model::value`]), laid out as the table holds
//! it, then written as packed text.
//!
//! A structure value (an ExtensionObject whose body the model decoded against its DataType) is laid out here
//! in the order of its OPC UA binary encoding (Part 6, 5.2.7): the encoding mask of a structure with optional
//! fields, the switch field of a union, then the fields the value has, each as its DataType encodes it: a
//! nested structure of a concrete DataType inline ([`Item::Fields`]), one of an abstract DataType or of a
//! field that allows subtypes as an ExtensionObject ([`Item::Structure`]), BaseDataType as a Variant, an
//! enumeration as Int32, a field the value leaves out as its DataType's null value. The runtime writes these
//! items as bytes when a server imports the table, because NodeIds and QualifiedNames inside a structure have
//! namespace indices that only the server knows; the compiler knows every field's DataType, the runtime
//! knows none. See the runtime's `table` module for the text of each item.
//!
//! [`Model::value`]: crate::model::Model::value

use super::{dims, enum_row, flag, hex, list, opt_str, str_lit, table_id};
use crate::model::{ids, Argument, DataTypeKind, EnumValue, Field, Model, NodeIx, StructureKind};
use crate::nodeid::NodeId;
use crate::value::{Body, BuiltinType, ExtensionObject, Structure, Variant};
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// How deep structures may nest in one value (the model decodes at most 32 levels).
const MAX_DEPTH: usize = 40;

/// A value as the table holds it. NodeIds are the model's (global namespace indices) until written.
#[derive(Debug)]
pub enum Item {
    /// A value without structures: a scalar of a built-in type or an array of them.
    Value(Variant),
    /// An array of Argument structures (InputArguments, OutputArguments).
    Arguments(Vec<Argument>),
    /// An array of EnumValueType structures (EnumValues).
    EnumValues(Vec<EnumValue>),
    /// An ExtensionObject: the NodeId of its DataType's Default Binary encoding, and its body.
    Structure(NodeId, Vec<Item>),
    /// A structure encoded inline, as a field of a concrete structure DataType is: its body alone.
    Fields(Vec<Item>),
    /// An array whose items are structures (or Variants, inside a structure).
    Array(BuiltinType, Vec<Item>),
    /// A field of DataType BaseDataType: the value encoded as a Variant.
    Variant(Box<Item>),
    /// The null value of a built-in type, for a field the value leaves out.
    Null(BuiltinType),
    /// A null array, for an array field the value leaves out.
    NullArray(BuiltinType),
}

impl Item {
    /// Adds the namespaces the item's NodeIds and QualifiedNames are in.
    pub(super) fn namespaces(&self, model: &Model, out: &mut BTreeSet<u16>) {
        match self {
            Item::Value(v) => variant_namespaces(v, out),
            Item::Arguments(args) => out.extend(args.iter().filter_map(|a| a.data_type).map(|dt| model.node(dt).id.ns)),
            Item::EnumValues(_) | Item::Null(_) | Item::NullArray(_) => {}
            Item::Structure(encoding, items) => {
                out.insert(encoding.ns);
                items.iter().for_each(|i| i.namespaces(model, out));
            }
            Item::Fields(items) | Item::Array(_, items) => items.iter().for_each(|i| i.namespaces(model, out)),
            Item::Variant(inner) => inner.namespaces(model, out),
        }
    }
}

fn variant_namespaces(v: &Variant, out: &mut BTreeSet<u16>) {
    match v {
        Variant::NodeId(id) | Variant::ExpandedNodeId(id) => {
            out.insert(id.ns);
        }
        Variant::QualifiedName(q) => {
            out.insert(q.ns);
        }
        Variant::Array(_, items) => items.iter().for_each(|i| variant_namespaces(i, out)),
        Variant::Variant(inner) => variant_namespaces(inner, out),
        _ => {}
    }
}

/// A node's value laid out as the table holds it, structures in the order of their OPC UA binary encoding:
/// what a server of the table sends (`verify` compares the structure values it reads with it,
/// `verify::structures`). `Ok(None)` for a null value; the reason if the table cannot hold it.
pub fn layout_value(model: &Model, v: Variant) -> Result<Option<Item>, String> {
    Layout { model }.node_value(v)
}

/// Lays out values against the model's DataTypes.
pub(super) struct Layout<'m> {
    pub model: &'m Model,
}

impl Layout<'_> {
    /// The table item of a node's value; `Ok(None)` for a null value; the reason if it cannot be served.
    pub fn node_value(&self, v: Variant) -> Result<Option<Item>, String> {
        match v {
            Variant::Variant(inner) => self.node_value(*inner),
            Variant::Null => Ok(None),
            Variant::ExtensionObject(eo) => self.extension_object(&eo, 0).map(Some),
            Variant::Array(BuiltinType::ExtensionObject, items) => {
                if let Some(special) = self.argument_or_enum_values(&items) {
                    return Ok(Some(special));
                }
                let items = items
                    .iter()
                    .enumerate()
                    .map(|(i, item)| match item {
                        Variant::ExtensionObject(eo) => self.extension_object(eo, 0).map_err(|e| format!("item {i}: {e}")),
                        Variant::Null => Ok(Item::Null(BuiltinType::ExtensionObject)),
                        other => Err(format!("item {i} is a {:?}, not an ExtensionObject", other.builtin())),
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Some(Item::Array(BuiltinType::ExtensionObject, items)))
            }
            v => {
                plain(&v)?;
                Ok(Some(Item::Value(v)))
            }
        }
    }

    /// Arrays of Argument or EnumValueType structures, which the table holds in forms of their own (the
    /// runtime reads method arguments and enumeration values from them).
    fn argument_or_enum_values(&self, items: &[Variant]) -> Option<Item> {
        let structures: Vec<&Structure> = items
            .iter()
            .map(|i| match i {
                Variant::ExtensionObject(eo) => eo.structure(),
                _ => None,
            })
            .collect::<Option<_>>()?;
        let kind = structures.first()?.data_type.ns0()?;
        if !structures.iter().all(|s| s.data_type.ns0() == Some(kind)) {
            return None;
        }
        match kind {
            ids::ARGUMENT => {
                let args = structures.iter().map(|s| Argument::from_structure(self.model, s)).collect::<Result<Vec<_>, _>>().ok()?;
                Some(Item::Arguments(args))
            }
            ids::ENUM_VALUE_TYPE => Some(Item::EnumValues(structures.iter().map(|s| EnumValue::from_enum_value_type(s, 0)).collect())),
            _ => None,
        }
    }

    /// An ExtensionObject with its type's Default Binary encoding and its body.
    fn extension_object(&self, eo: &ExtensionObject, depth: usize) -> Result<Item, String> {
        let s = match &eo.body {
            None => return Ok(Item::Null(BuiltinType::ExtensionObject)),
            Some(Body::Xml(_)) => {
                let named = eo.type_id.as_ref().map(|t| self.model.display_id(t)).unwrap_or_else(|| "nothing".into());
                return Err(format!("its TypeId names {named}, which is not the encoding of a structure DataType with a definition"));
            }
            Some(Body::Structure(s)) => s,
        };
        let dt = self.model.lookup(&s.data_type).ok_or_else(|| format!("DataType {} is not loaded", self.model.display_id(&s.data_type)))?;
        let info = &self.model.data_types[&dt];
        let encoding = info
            .encodings
            .iter()
            .find(|(n, _)| n == "Default Binary")
            .map(|(_, e)| self.model.node(*e).id.clone())
            .ok_or_else(|| format!("structure `{}` has no Default Binary encoding", self.model.qualified(dt)))?;
        Ok(Item::Structure(encoding, self.body(dt, s, depth + 1)?))
    }

    /// The body of a structure value of DataType `dt`, in encoding order.
    fn body(&self, dt: NodeIx, s: &Structure, depth: usize) -> Result<Vec<Item>, String> {
        if depth > MAX_DEPTH {
            return Err("structures nest too deep".into());
        }
        let Some(DataTypeKind::Structure { kind, fields, has_definition: true }) = self.model.data_types.get(&dt).map(|i| &i.kind) else {
            return Err(format!("`{}` is not a structure with a definition", self.model.qualified(dt)));
        };
        let mut out = Vec::with_capacity(fields.len() + 1);
        match kind {
            StructureKind::Structure => {
                for f in fields {
                    out.push(self.field(f, s.get(&f.name), depth)?);
                }
            }
            StructureKind::StructureWithOptionalFields => {
                let mut mask = 0u32;
                for (bit, f) in fields.iter().filter(|f| f.is_optional).enumerate() {
                    if s.get(&f.name).is_some() {
                        mask |= 1u32.checked_shl(bit as u32).ok_or("more than 32 optional fields")?;
                    }
                }
                out.push(Item::Value(Variant::UInt32(mask)));
                for f in fields {
                    let v = s.get(&f.name);
                    if !f.is_optional || v.is_some() {
                        out.push(self.field(f, v, depth)?);
                    }
                }
            }
            StructureKind::Union => {
                let given = fields.iter().position(|f| s.get(&f.name).is_some()).map(|i| i as u32 + 1);
                let switch = s.switch_field.or(given).unwrap_or(0);
                out.push(Item::Value(Variant::UInt32(switch)));
                if switch > 0 {
                    let f = fields
                        .get(switch as usize - 1)
                        .ok_or_else(|| format!("SwitchField {switch} names no field (the union has {})", fields.len()))?;
                    out.push(self.field(f, s.get(&f.name), depth)?);
                }
            }
        }
        Ok(out)
    }

    /// One field: its value, or its DataType's null value when the structure value leaves it out.
    fn field(&self, f: &Field, v: Option<&Result<Variant, String>>, depth: usize) -> Result<Item, String> {
        let v = match v {
            Some(Err(e)) => return Err(e.clone()),
            Some(Ok(v)) => Some(v),
            None => None,
        };
        let in_field = |e: String| if e.starts_with("field `") { e } else { format!("field `{}`: {e}", f.name) };
        // Arrays as async-opcua's derive encodes them (`Option<Vec<T>>`, see `field_type`).
        if f.value_rank >= 0 || f.value_rank == -2 || f.value_rank == -3 {
            if f.value_rank > 1 {
                return Err(in_field(format!("ValueRank {} (multi-dimensional) is not supported", f.value_rank)));
            }
            let builtin = self.model.data_types.get(&f.data_type).map_or(BuiltinType::Variant, |i| i.encoding);
            let items = match v {
                None => return Ok(Item::NullArray(builtin)),
                Some(Variant::Array(_, items)) => items.iter().collect(),
                Some(v) => vec![v],
            };
            let items = items.into_iter().map(|i| self.scalar(f, Some(i), depth)).collect::<Result<Vec<_>, _>>().map_err(in_field)?;
            return Ok(Item::Array(builtin, items));
        }
        self.scalar(f, v, depth).map_err(in_field)
    }

    /// One value of a field's DataType (a scalar field, or an item of an array field).
    fn scalar(&self, f: &Field, v: Option<&Variant>, depth: usize) -> Result<Item, String> {
        let info = self.model.data_types.get(&f.data_type).ok_or("the field's DataType is not classified")?;
        let Some(v) = v else { return self.null(f.data_type, depth) };
        match &info.kind {
            DataTypeKind::Structure { has_definition: true, .. } if !info.is_abstract && !f.allow_sub_types => {
                let s = match v {
                    Variant::ExtensionObject(eo) => eo.structure(),
                    _ => None,
                };
                let s = s.ok_or("the value is not a structure of the field's DataType")?;
                if self.model.lookup(&s.data_type) != Some(f.data_type) {
                    return Err(format!(
                        "the value is a `{}`, but the field's DataType `{}` is encoded in place and allows no subtype",
                        self.model.display_id(&s.data_type),
                        self.model.qualified(f.data_type)
                    ));
                }
                Ok(Item::Fields(self.body(f.data_type, s, depth + 1)?))
            }
            _ if info.encoding == BuiltinType::ExtensionObject => match v {
                Variant::ExtensionObject(eo) => self.extension_object(eo, depth),
                Variant::Null => Ok(Item::Null(BuiltinType::ExtensionObject)),
                _ => Err("the value is not an ExtensionObject".into()),
            },
            _ if info.encoding == BuiltinType::Variant => {
                let inner = match v {
                    Variant::Variant(inner) => &**inner,
                    v => v,
                };
                Ok(Item::Variant(Box::new(match self.node_value(inner.clone())? {
                    Some(item) => item,
                    None => Item::Null(BuiltinType::Variant),
                })))
            }
            _ => match v {
                Variant::Null => Ok(Item::Null(info.encoding)),
                Variant::XmlElement(x) if matches!(info.encoding, BuiltinType::DiagnosticInfo | BuiltinType::DataValue) => {
                    if x.children.is_empty() && x.text.trim().is_empty() {
                        Ok(Item::Null(info.encoding))
                    } else {
                        Err(format!("{} values are not supported", info.encoding.xml_name()))
                    }
                }
                v if v.builtin() == Some(info.encoding) && !v.is_array() => {
                    plain(v)?;
                    Ok(Item::Value(v.clone()))
                }
                v => Err(format!("the value is a {:?}, not a {}", v.builtin(), info.encoding.xml_name())),
            },
        }
    }

    /// The null value of a DataType, for a field the value leaves out: a structure of a concrete DataType with
    /// each of its fields null (no optional field, SwitchField 0), every other DataType its built-in type's
    /// null.
    fn null(&self, dt: NodeIx, depth: usize) -> Result<Item, String> {
        let info = self.model.data_types.get(&dt).ok_or("the field's DataType is not classified")?;
        match &info.kind {
            DataTypeKind::Structure { has_definition: true, .. } if !info.is_abstract => {
                let empty = Structure { data_type: self.model.node(dt).id.clone(), switch_field: None, fields: Vec::new() };
                Ok(Item::Fields(self.body(dt, &empty, depth + 1)?))
            }
            _ => Ok(Item::Null(info.encoding)),
        }
    }
}

/// Checks that a value holds no structure, XML element or null (which only [`Item`]s other than
/// [`Item::Value`] can hold).
fn plain(v: &Variant) -> Result<(), String> {
    match v {
        Variant::ExtensionObject(_) => Err("an ExtensionObject inside an array of another type is not supported".into()),
        Variant::XmlElement(_) => Err("XmlElement values are not supported".into()),
        Variant::Null => Err("an array item is null".into()),
        Variant::Array(_, items) => items.iter().try_for_each(plain),
        Variant::Variant(inner) => plain(inner),
        _ => Ok(()),
    }
}

/// Appends an item as packed text; `local` maps a global namespace index to the table's.
pub(super) fn item_text(model: &Model, out: &mut String, item: &Item, local: &dyn Fn(u16) -> u16) {
    match item {
        Item::Value(v) => val_text(out, v, local),
        Item::Arguments(args) => {
            out.push_str("Arguments:{");
            for a in args {
                let dt = match a.data_type {
                    Some(dt) => model.node(dt).id.clone(),
                    None => NodeId::numeric(0, ids::BASE_DATA_TYPE),
                };
                out.push(' ');
                str_lit(out, &a.name);
                out.push(' ');
                table_id(out, local(dt.ns), &dt.id);
                let _ = write!(out, " {} ", a.value_rank);
                dims(out, &a.array_dimensions);
                out.push(' ');
                opt_str(out, a.description.as_deref());
            }
            out.push_str(" }");
        }
        Item::EnumValues(values) => {
            out.push_str("EnumValues:");
            list(out, values, |out, v| {
                let dn = v.display_name.as_deref().unwrap_or("");
                enum_row(out, v.value, dn, dn, v.description.as_deref());
            });
        }
        Item::Structure(encoding, items) => {
            out.push_str("Structure:");
            table_id(out, local(encoding.ns), &encoding.id);
            out.push(' ');
            list(out, items, |out, i| item_text(model, out, i, local));
        }
        Item::Fields(items) => {
            out.push_str("Fields:");
            list(out, items, |out, i| item_text(model, out, i, local));
        }
        Item::Array(b, items) => {
            let _ = write!(out, "Array:{} ", b.id());
            list(out, items, |out, i| item_text(model, out, i, local));
        }
        Item::Variant(inner) => {
            out.push_str("Variant:");
            item_text(model, out, inner, local);
        }
        Item::Null(b) => {
            let _ = write!(out, "Null:{}", b.id());
        }
        Item::NullArray(b) => {
            let _ = write!(out, "NullArray:{}", b.id());
        }
    }
}

/// Appends a value without structures (checked by [`plain`]).
fn val_text(out: &mut String, v: &Variant, local: &dyn Fn(u16) -> u16) {
    let nid = |out: &mut String, id: &NodeId| table_id(out, local(id.ns), &id.id);
    match v {
        Variant::Boolean(b) => {
            out.push_str("Boolean:");
            flag(out, *b);
        }
        Variant::SByte(x) => {
            let _ = write!(out, "SByte:{x}");
        }
        Variant::Byte(x) => {
            let _ = write!(out, "Byte:{x}");
        }
        Variant::Int16(x) => {
            let _ = write!(out, "Int16:{x}");
        }
        Variant::UInt16(x) => {
            let _ = write!(out, "UInt16:{x}");
        }
        Variant::Int32(x) => {
            let _ = write!(out, "Int32:{x}");
        }
        Variant::UInt32(x) => {
            let _ = write!(out, "UInt32:{x}");
        }
        Variant::Int64(x) => {
            let _ = write!(out, "Int64:{x}");
        }
        Variant::UInt64(x) => {
            let _ = write!(out, "UInt64:{x}");
        }
        // Rust prints floats so that they parse back to the same value (`NaN`, `inf` and `-0` included).
        Variant::Float(x) => {
            let _ = write!(out, "Float:{x}");
        }
        Variant::Double(x) => {
            let _ = write!(out, "Double:{x}");
        }
        Variant::String(s) => {
            out.push_str("String:");
            str_lit(out, s);
        }
        Variant::DateTime(s) => {
            out.push_str("DateTime:");
            str_lit(out, s);
        }
        Variant::Guid(g) => {
            out.push_str("Guid:");
            hex(out, g);
        }
        Variant::ByteString(b) => {
            out.push_str("ByteString:");
            hex(out, b);
        }
        Variant::NodeId(id) => {
            out.push_str("NodeId:");
            nid(out, id);
        }
        Variant::ExpandedNodeId(id) => {
            out.push_str("ExpandedNodeId:");
            nid(out, id);
        }
        Variant::StatusCode(c) => {
            let _ = write!(out, "StatusCode:{c}");
        }
        Variant::QualifiedName(q) => {
            let _ = write!(out, "QualifiedName:{}:", local(q.ns));
            str_lit(out, &q.name);
        }
        Variant::LocalizedText(t) => {
            out.push_str("LocalizedText:");
            opt_str(out, t.locale.as_deref());
            out.push(':');
            str_lit(out, &t.text);
        }
        Variant::Array(b, items) => {
            let _ = write!(out, "Array:{} ", b.id());
            list(out, items, |out, item| val_text(out, item, local));
        }
        Variant::Variant(inner) => val_text(out, inner, local),
        // `plain` lets none of these through.
        Variant::ExtensionObject(_) | Variant::XmlElement(_) | Variant::Null => out.push('~'),
    }
}
