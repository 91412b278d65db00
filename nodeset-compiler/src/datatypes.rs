//! Classifies every DataType: built-in, simple subtype, enumeration, OptionSet, structure (plain, with
//! optional fields, union), with inherited fields and resolved field types.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::model::*;
use crate::raw::NodeClass;
use crate::value::{BuiltinType, Variant};
use crate::source::Span;
use std::collections::{BTreeMap, HashMap};

/// The DataTypes of the model, classified.
pub(crate) fn classify(model: &Model, diags: &mut Diagnostics) -> BTreeMap<NodeIx, DataTypeInfo> {
    let types: Vec<NodeIx> =
        (0..model.nodes.len() as u32).map(NodeIx).filter(|&ix| model.node(ix).class == NodeClass::DataType).collect();
    // Supertypes first, so inherited fields are known; enumerations last, so that the EnumValueType
    // structures of their EnumValues properties can be decoded.
    let depths = model.type_depths();
    let mut order: Vec<(bool, u32, NodeIx)> =
        types.iter().map(|&t| (model.is_subtype_of_ns0(t, ids::ENUMERATION), depths[t.index()], t)).collect();
    order.sort();
    let has_encoding = model.ns0(ids::HAS_ENCODING);
    let mut out: BTreeMap<NodeIx, DataTypeInfo> = BTreeMap::new();
    for (_, _, t) in order {
        let node = model.node(t);
        let chain = model.super_chain(t);
        let ns0_in_chain = |n: u32| chain.iter().any(|&c| model.node(c).id.ns0() == Some(n));
        let own_builtin = node.id.ns0().and_then(BuiltinType::from_id);
        let base_builtin = chain.iter().find_map(|&c| model.node(c).id.ns0().and_then(BuiltinType::from_id));
        let encodings: Vec<(String, NodeIx)> = node
            .references
            .iter()
            .filter(|r| r.forward && Some(r.reference_type) == has_encoding)
            .map(|r| (model.node(r.target).browse_name.name.clone(), r.target))
            .collect();
        let is_abstract = node.is_abstract();
        let def = node.definition.as_deref();
        let kind = if let Some(b) = own_builtin.filter(|b| !matches!(b, BuiltinType::ExtensionObject | BuiltinType::Variant)) {
            DataTypeKind::Builtin(b)
        } else if matches!(node.id.ns0(), Some(ids::BASE_DATA_TYPE | ids::NUMBER | ids::INTEGER | ids::UINTEGER | ids::DECIMAL)) {
            DataTypeKind::AbstractBuiltin
        } else if ns0_in_chain(ids::ENUMERATION) {
            enumeration(model, t, &out, diags)
        } else if def.is_some_and(|d| d.is_option_set) {
            let base = base_builtin.unwrap_or(BuiltinType::UInt32);
            let bits: Vec<EnumValue> = def
                .map(|d| {
                    d.fields
                        .iter()
                        .enumerate()
                        .map(|(i, f)| EnumValue {
                            name: f.name.clone(),
                            value: f.value.unwrap_or(i as i64),
                            display_name: f.display_names.first().map(|d| d.text.clone()),
                            description: f.descriptions.first().map(|d| d.text.clone()),
                        })
                        .collect::<Vec<_>>()
                })
                .unwrap_or_default();
            let spans: Vec<Span> = def.map(|d| d.fields.iter().map(|f| f.span).collect()).unwrap_or_default();
            let bits = check_unique(model, t, bits, &spans, diags);
            DataTypeKind::OptionSet { base, bits }
        } else if ns0_in_chain(ids::STRUCTURE) {
            structure(model, t, &out, diags)
        } else if let Some(b) = base_builtin {
            if b == BuiltinType::Variant {
                DataTypeKind::AbstractBuiltin
            } else {
                DataTypeKind::Simple(b)
            }
        } else {
            DataTypeKind::AbstractBuiltin
        };
        let encoding = match &kind {
            DataTypeKind::Builtin(b) | DataTypeKind::Simple(b) => *b,
            DataTypeKind::OptionSet { base, .. } => *base,
            DataTypeKind::Enumeration { .. } => BuiltinType::Int32,
            DataTypeKind::Structure { .. } => BuiltinType::ExtensionObject,
            DataTypeKind::AbstractBuiltin => {
                if node.id.ns0() == Some(ids::STRUCTURE) {
                    BuiltinType::ExtensionObject
                } else {
                    BuiltinType::Variant
                }
            }
        };
        out.insert(t, DataTypeInfo { node: t, kind, encoding, is_abstract, encodings });
    }
    out
}

fn structure(model: &Model, t: NodeIx, done: &BTreeMap<NodeIx, DataTypeInfo>, diags: &mut Diagnostics) -> DataTypeKind {
    let node = model.node(t);
    let inherited: Vec<Field> = node
        .super_type
        .and_then(|s| done.get(&s))
        .and_then(|i| match &i.kind {
            DataTypeKind::Structure { fields, .. } => Some(fields.clone()),
            _ => None,
        })
        .unwrap_or_default();
    let Some(def) = &node.definition else {
        return DataTypeKind::Structure { kind: StructureKind::Structure, fields: inherited, has_definition: false };
    };
    let ctx = &model.files[&node.file];
    let mut own = Vec::new();
    for f in &def.fields {
        let data_type = match &f.data_type {
            None => model.ns0(ids::BASE_DATA_TYPE),
            Some(dt) => match ctx.resolve(model, &dt.value, dt.span, diags) {
                Ok(id) => match model.lookup(&id) {
                    Some(ix) if model.node(ix).class == NodeClass::DataType => Some(ix),
                    found => {
                        let what = match found {
                            Some(ix) => format!("is a {}", model.node(ix).class.name()),
                            None => "names no loaded node".to_string(),
                        };
                        diags.push(
                            Diagnostic::new(
                                Code::UnknownFieldType,
                                format!("field `{}` of `{}` has DataType `{}`, which {what}", f.name, node.browse_name.name, dt.value),
                            )
                            .at(dt.span)
                            .help("name a DataType defined in this model or one it requires"),
                        );
                        None
                    }
                },
                Err(mut d) => {
                    d.code = match d.code {
                        Code::UnknownAlias | Code::MalformedNodeId | Code::UnknownNamespaceIndex => d.code,
                        _ => Code::UnknownFieldType,
                    };
                    diags.push(d);
                    None
                }
            },
        };
        let Some(data_type) = data_type else { continue };
        let array_dimensions =
            f.array_dimensions.as_deref().map(|a| a.split(',').filter_map(|x| x.trim().parse().ok()).collect()).unwrap_or_default();
        own.push(Field {
            name: f.name.as_str().into(),
            symbolic_name: f.symbolic_name.clone(),
            data_type,
            value_rank: f.value_rank.unwrap_or(-1),
            array_dimensions,
            max_string_length: f.max_string_length,
            is_optional: f.is_optional,
            allow_sub_types: f.allow_sub_types,
            description: f.descriptions.first().map(|d| d.text.clone()).filter(|d| !d.is_empty()),
            declared_in: t,
            span: f.span,
        });
    }
    // Some files repeat the supertype's fields in the subtype's definition; others list only their own.
    let repeats = !inherited.is_empty()
        && own.len() >= inherited.len()
        && inherited.iter().zip(&own).all(|(a, b)| a.name == b.name);
    let mut fields = if repeats { Vec::new() } else { inherited };
    fields.extend(own);
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, f) in fields.iter().enumerate() {
        if let Some(&j) = seen.get(&*f.name) {
            diags.push(
                Diagnostic::new(Code::DuplicateEnumValue, format!("structure `{}` has two fields named `{}`", node.browse_name.name, f.name))
                    .at(f.span)
                    .label(fields[j].span, "first field with this name")
                    .help("field names must be unique within a structure and its supertypes"),
            );
        } else {
            seen.insert(&f.name, i);
        }
    }
    let kind = if def.is_union || model.is_subtype_of_ns0(t, ids::UNION) {
        StructureKind::Union
    } else if fields.iter().any(|f| f.is_optional) {
        StructureKind::StructureWithOptionalFields
    } else {
        StructureKind::Structure
    };
    DataTypeKind::Structure { kind, fields, has_definition: true }
}

/// An enumeration's values. The definition's fields give them, a field without `Value` being -1 as
/// UANodeSet.xsd says; where the DataType also has an EnumValues or EnumStrings property and the two
/// disagree (a missing Value colliding with a real one, or another value), the property decides and NS0219
/// names the choice. Without fields, the property alone gives them.
fn enumeration(model: &Model, t: NodeIx, done: &DataTypes, diags: &mut Diagnostics) -> DataTypeKind {
    let node = model.node(t);
    let property = enum_property(model, t, done);
    if let Some(def) = &node.definition {
        if !def.fields.is_empty() {
            let mut values: Vec<EnumValue> = def
                .fields
                .iter()
                .map(|f| EnumValue {
                    name: f.name.clone(),
                    value: f.value.unwrap_or(-1),
                    display_name: f.display_names.first().map(|d| d.text.clone()),
                    description: f.descriptions.first().map(|d| d.text.clone()).filter(|d| !d.is_empty()),
                })
                .collect();
            let mut spans: Vec<Span> = def.fields.iter().map(|f| f.span).collect();
            if let Some(p) = &property {
                let differ: Vec<usize> =
                    (0..values.len().max(p.values.len())).filter(|&i| values.get(i).map(|v| v.value) != p.values.get(i).map(|v| v.value)).collect();
                if !differ.is_empty() {
                    diags.push(enum_choice(node, &def.fields, &values, p, &differ, &spans));
                    if values.len() == p.values.len() {
                        // Same entries: the definition's names, the property's values.
                        for (v, pv) in values.iter_mut().zip(&p.values) {
                            v.value = pv.value;
                        }
                    } else {
                        values = p.values.clone();
                        spans = p.spans.clone();
                    }
                }
            }
            let values = check_unique(model, t, values, &spans, diags);
            return DataTypeKind::Enumeration { values, source: EnumSource::Definition };
        }
    }
    match property {
        Some(p) => {
            let values = check_unique(model, t, p.values, &p.spans, diags);
            DataTypeKind::Enumeration { values, source: p.source }
        }
        None => DataTypeKind::Enumeration { values: Vec::new(), source: EnumSource::Definition },
    }
}

/// The values an enumeration's EnumStrings or EnumValues property gives, with the span of each entry.
struct EnumProperty {
    values: Vec<EnumValue>,
    spans: Vec<Span>,
    source: EnumSource,
    /// The property node's span.
    span: Span,
}

fn enum_property(model: &Model, t: NodeIx, done: &DataTypes) -> Option<EnumProperty> {
    for (_, child) in model.children(t) {
        let c = model.node(child);
        if c.browse_name.ns != 0 {
            continue;
        }
        let which = c.browse_name.name.as_str();
        if which != "EnumStrings" && which != "EnumValues" {
            continue;
        }
        let Some(Ok(v)) = model.value_with(child, done) else { continue };
        let items = match v {
            Variant::Array(_, items) => items,
            other => vec![other],
        };
        let mut values = Vec::new();
        let item_spans: Vec<Span> = model.value_element(child).map(|x| x.children().map(|e| e.span()).collect()).unwrap_or_default();
        let mut spans = Vec::new();
        for (i, it) in items.into_iter().enumerate() {
            let before = values.len();
            match it {
                Variant::LocalizedText(lt) => values.push(EnumValue {
                    name: lt.text.clone(),
                    value: i as i64,
                    display_name: Some(lt.text),
                    description: None,
                }),
                Variant::ExtensionObject(eo) => {
                    let Some(s) = eo.structure() else { continue };
                    values.push(EnumValue::from_enum_value_type(s, i as i64));
                }
                _ => {}
            }
            if values.len() > before {
                spans.push(item_spans.get(i).copied().unwrap_or(c.span));
            }
        }
        let source = if which == "EnumStrings" { EnumSource::EnumStrings } else { EnumSource::EnumValues };
        return Some(EnumProperty { values, spans, source, span: c.span });
    }
    None
}

/// NS0219: the definition and the property disagree at the positions `differ`; the property decides.
fn enum_choice(
    node: &Node,
    fields: &[crate::raw::RawField],
    values: &[EnumValue],
    p: &EnumProperty,
    differ: &[usize],
    spans: &[Span],
) -> Diagnostic {
    let prop = if p.source == EnumSource::EnumStrings { "EnumStrings" } else { "EnumValues" };
    let show = |i: usize| {
        let def = match (values.get(i), fields.get(i)) {
            (Some(_), Some(f)) if f.value.is_none() => "-1 (no Value) in the definition".to_string(),
            (Some(v), _) => format!("{} in the definition", v.value),
            (None, _) => "absent from the definition".to_string(),
        };
        let name = values.get(i).map(|v| v.name.as_str()).or_else(|| p.values.get(i).map(|v| v.name.as_str())).unwrap_or("");
        let by_prop = p.values.get(i).map_or_else(|| format!("absent from {prop}"), |v| format!("{} in {prop}", v.value));
        format!("`{name}` is {def} and {by_prop}")
    };
    let mut list: Vec<String> = differ.iter().take(3).map(|&i| show(i)).collect();
    if differ.len() > 3 {
        list.push(format!("{} more", differ.len() - 3));
    }
    let first = differ[0];
    let at = spans.get(first).copied().or(node.definition.as_ref().map(|d| d.span)).unwrap_or(node.span);
    let how = if values.len() == p.values.len() {
        format!("the {prop} property decides: the values are {prop}'s, the names the definition's")
    } else {
        format!("the {prop} property decides: its {} entries are used", p.values.len())
    };
    Diagnostic::new(
        Code::EnumValueChoice,
        format!("enumeration `{}`: its definition and its {prop} property disagree: {}", node.browse_name.name, list.join("; ")),
    )
    .at(at)
    .with_span_label("the definition says otherwise")
    .label(p.span, format!("{prop} is used"))
    .note(how)
    .help("give every field a Value that matches the property (a field without Value is -1 in UANodeSet.xsd)")
}

/// Reports repeated values and names, and returns the entries without the later repetitions (NS0208's recovery).
fn check_unique(model: &Model, t: NodeIx, values: Vec<EnumValue>, spans: &[Span], diags: &mut Diagnostics) -> Vec<EnumValue> {
    let node = model.node(t);
    let fallback = node.definition.as_ref().map(|d| d.span).unwrap_or(node.span);
    let span_of = |i: usize| spans.get(i).copied().unwrap_or(fallback);
    let mut by_value: HashMap<i64, usize> = HashMap::new();
    let mut by_name: HashMap<&str, usize> = HashMap::new();
    let mut keep = vec![true; values.len()];
    for (i, v) in values.iter().enumerate() {
        if let Some(&j) = by_value.get(&v.value) {
            diags.push(
                Diagnostic::new(
                    Code::DuplicateEnumValue,
                    format!("`{}` gives value {} to both `{}` and `{}`", node.browse_name.name, v.value, values[j].name, v.name),
                )
                .at(span_of(i))
                .with_span_label(format!("value {} again", v.value))
                .label(span_of(j), format!("first used by `{}`", values[j].name))
                .help("each enumeration value and option bit must be distinct"),
            );
            keep[i] = false;
        } else {
            by_value.insert(v.value, i);
        }
        if let Some(&j) = by_name.get(v.name.as_str()) {
            diags.push(
                Diagnostic::new(
                    Code::DuplicateEnumValue,
                    format!("`{}` has two entries named `{}` ({} and {})", node.browse_name.name, v.name, values[j].value, v.value),
                )
                .at(span_of(i))
                .with_span_label("second entry with this name")
                .label(span_of(j), "first entry with this name")
                .help("each enumeration name must be distinct"),
            );
            keep[i] = false;
        } else {
            by_name.insert(&v.name, i);
        }
    }
    values.iter().zip(keep).filter(|(_, k)| *k).map(|(v, _)| v.clone()).collect()
}
