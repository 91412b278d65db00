//! `nodes.rs`: the address space of a namespace as one static table, one row per node.
//!
//! The rows are data, not code: a few thousand struct literals of a fixed shape. They are written straight
//! into the output text, one line per row, with the spacing a person would use
//! (`rt::table::Id { ns: 2, id: rt::IdKind::Numeric(6027) }`). Building them as token trees first and printing
//! those cost about 70% of the whole Rust generation. Literals are still printed by proc-macro2's `Literal`, so
//! strings, byte strings and floats are escaped exactly as the token-based parts of the emitter escape them.
//! The few lines around the rows (the module head and the table header) go through quote and prettyplease.
//!
//! A row's references are written as tuples of numbers, `(0, 45, 2, 3008, false)` (reference type namespace
//! and number, target namespace and number, forward), when all of them are numeric: references are most of a
//! table's expressions, and a tuple of literals is 6 expressions where `rt::table::Ref { .. }` with its two
//! `Id`s is 11. For DI + IA + Robotics the table text shrinks from 1,077 KB to 660 KB, and a crate of only
//! their three tables builds with 19% less rustc self time (2.54 -> 2.06 s, mean of three clean builds).

use super::{lit, path, Gen};
use crate::diag::{Code, Diagnostic};
use crate::model::{ids, DataTypeKind, NodeIx, StructureKind};
use crate::nodeid::{Identifier, NodeId};
use crate::raw::NodeClass;
use crate::value::{BuiltinType, Variant};
use crate::write::OutFile;
use proc_macro2::Literal;
use quote::quote;
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Appends a string literal.
fn str_lit(out: &mut String, s: &str) {
    out.push_str(&Literal::string(s).to_string());
}

/// Appends `Some("...")` or `None`.
fn opt_str(out: &mut String, s: Option<&str>) {
    match s {
        Some(s) => {
            out.push_str("Some(");
            str_lit(out, s);
            out.push(')');
        }
        None => out.push_str("None"),
    }
}

/// Appends `&[a, b, c]` with each item written by `item`.
fn list<T>(out: &mut String, items: impl IntoIterator<Item = T>, mut item: impl FnMut(&mut String, T)) {
    out.push_str("&[");
    for (i, x) in items.into_iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        item(out, x);
    }
    out.push(']');
}

/// Appends `&[1u32, 2u32]`.
fn dims(out: &mut String, d: &[u32]) {
    list(out, d, |out, x| {
        let _ = write!(out, "{x}u32");
    });
}

/// Appends the bytes of a GUID, `[1, 2, ...]`.
fn guid(out: &mut String, g: &[u8; 16]) {
    out.push('[');
    for (i, b) in g.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(out, "{b}");
    }
    out.push(']');
}

/// Appends an `rt::IdKind`.
fn id_kind(out: &mut String, id: &Identifier) {
    match id {
        Identifier::Numeric(v) => {
            let _ = write!(out, "rt::IdKind::Numeric({v})");
        }
        Identifier::String(s) => {
            out.push_str("rt::IdKind::String(");
            str_lit(out, s);
            out.push(')');
        }
        Identifier::Guid(g) => {
            out.push_str("rt::IdKind::Guid(");
            guid(out, g);
            out.push(')');
        }
        Identifier::Opaque(b) => {
            out.push_str("rt::IdKind::Opaque(");
            out.push_str(&Literal::byte_string(b).to_string());
            out.push(')');
        }
    }
}

/// Appends an `rt::table::Id` whose namespace is written `ns` (`2` for node ids of the table, `2u16` for
/// node ids inside values: both forms are kept so that the output does not change with this rewrite).
fn table_id(out: &mut String, ns: u16, suffixed: bool, id: &Identifier) {
    let _ = write!(out, "rt::table::Id {{ ns: {ns}{}, id: ", if suffixed { "u16" } else { "" });
    id_kind(out, id);
    out.push_str(" }");
}

/// Appends a float value (`Val::Float(1.5f32)`, `Val::Double(f64::NAN)`).
fn float(out: &mut String, x: f64, single: bool) {
    let special = if x.is_nan() {
        Some("f64::NAN")
    } else if x.is_infinite() {
        Some(if x > 0.0 { "f64::INFINITY" } else { "f64::NEG_INFINITY" })
    } else {
        None
    };
    if single {
        out.push_str("rt::table::Val::Float(");
        match special {
            Some(s) => {
                let _ = write!(out, "({s})as f32");
            }
            None => out.push_str(&Literal::f32_suffixed(x as f32).to_string()),
        }
    } else {
        out.push_str("rt::table::Val::Double(");
        match special {
            Some(s) => out.push_str(s),
            None => out.push_str(&Literal::f64_suffixed(x).to_string()),
        }
    }
    out.push(')');
}

impl Gen<'_> {
    pub(super) fn nodes_file(&mut self) -> OutFile {
        let model = self.model;
        // Table-local namespace indices: 0 is ns0, then every namespace a row refers to, in global order.
        let mut used: BTreeSet<u16> = BTreeSet::new();
        used.insert(self.ns);
        let mine: Vec<NodeIx> =
            (0..model.nodes.len() as u32).map(NodeIx).filter(|&ix| model.node(ix).id.ns == self.ns).collect();
        for &ix in &mine {
            let n = model.node(ix);
            used.insert(n.browse_name.ns);
            // Only the references a row carries (those its file declares, not the resolver's inverses).
            for r in n.references.iter().filter(|r| r.declared) {
                used.insert(model.node(r.reference_type).id.ns);
                used.insert(model.node(r.target).id.ns);
            }
            if let Some(dt) = n.attrs.data_type {
                used.insert(model.node(dt).id.ns);
            }
        }
        used.remove(&0);
        let locals: Vec<u16> = std::iter::once(0).chain(used.iter().copied()).collect();
        let local = |g: u16| locals.iter().position(|&l| l == g).unwrap_or(0) as u16;

        let mut rows = String::with_capacity(mine.len() * 400);
        let mut dropped_values = 0usize;
        let mut value = String::new();
        for &ix in &mine {
            let n = model.node(ix);
            let out = &mut rows;
            let id_of = |out: &mut String, ix: NodeIx| {
                let id = &model.node(ix).id;
                table_id(out, local(id.ns), false, &id.id);
            };
            out.push_str("        rt::table::NodeRow { id: ");
            id_of(out, ix);
            let _ = write!(out, ", browse_name: ({}, ", local(n.browse_name.ns));
            str_lit(out, &n.browse_name.name);
            out.push_str("), display_name: ");
            str_lit(out, n.display());
            out.push_str(", description: ");
            opt_str(out, n.doc());
            let _ = write!(
                out,
                ", write_mask: {}u32, user_write_mask: {}u32, kind: ",
                n.attrs.write_mask.unwrap_or(0),
                n.attrs.user_write_mask.unwrap_or(0)
            );
            match n.class {
                NodeClass::Object => {
                    let _ = write!(out, "rt::table::Kind::Object {{ event_notifier: {}u8 }}", n.attrs.event_notifier.unwrap_or(0));
                }
                NodeClass::ObjectType => {
                    let _ = write!(out, "rt::table::Kind::ObjectType {{ is_abstract: {} }}", n.is_abstract());
                }
                NodeClass::Variable | NodeClass::VariableType => {
                    value.clear();
                    if !self.value_text(&mut value, ix, &local) {
                        dropped_values += 1;
                        value.clear();
                        value.push_str("rt::table::Val::None");
                    }
                    let variable = n.class == NodeClass::Variable;
                    out.push_str(if variable { "rt::table::Kind::Variable { data_type: " } else { "rt::table::Kind::VariableType { data_type: " });
                    match n.attrs.data_type {
                        Some(dt) => id_of(out, dt),
                        None => out.push_str("rt::table::Id::ns0(24)"),
                    }
                    let _ = write!(out, ", value_rank: {}i32, array_dimensions: ", n.attrs.value_rank.unwrap_or(-1));
                    dims(out, &n.attrs.array_dimensions);
                    if variable {
                        let al = n.attrs.access_level.unwrap_or(1);
                        let ual = n.attrs.user_access_level.unwrap_or(al);
                        let _ = write!(
                            out,
                            ", access_level: {al}u8, user_access_level: {ual}u8, historizing: {}, minimum_sampling_interval: ",
                            n.attrs.historizing.unwrap_or(false)
                        );
                        match n.attrs.minimum_sampling_interval {
                            Some(v) => {
                                let _ = write!(out, "Some({})", Literal::f64_suffixed(v));
                            }
                            None => out.push_str("None"),
                        }
                    } else {
                        let _ = write!(out, ", is_abstract: {}", n.is_abstract());
                    }
                    out.push_str(", value: ");
                    out.push_str(&value);
                    out.push_str(" }");
                }
                NodeClass::Method => {
                    let e = n.attrs.executable.unwrap_or(true);
                    let ue = n.attrs.user_executable.unwrap_or(e);
                    let _ = write!(out, "rt::table::Kind::Method {{ executable: {e}, user_executable: {ue} }}");
                }
                NodeClass::ReferenceType => {
                    let _ = write!(
                        out,
                        "rt::table::Kind::ReferenceType {{ symmetric: {}, is_abstract: {}, inverse_name: ",
                        n.attrs.symmetric.unwrap_or(false),
                        n.is_abstract()
                    );
                    opt_str(out, n.attrs.inverse_name.first().map(|t| t.text.as_str()));
                    out.push_str(" }");
                }
                NodeClass::DataType => {
                    let _ = write!(out, "rt::table::Kind::DataType {{ is_abstract: {}, definition: ", n.is_abstract());
                    self.definition_text(out, ix, &id_of);
                    out.push_str(" }");
                }
                NodeClass::View => {
                    let _ = write!(
                        out,
                        "rt::table::Kind::View {{ event_notifier: {}u8, contains_no_loops: {} }}",
                        n.attrs.event_notifier.unwrap_or(0),
                        n.attrs.contains_no_loops.unwrap_or(false)
                    );
                }
            }
            // References go to `nrefs` as tuples of numbers when all of them are numeric (nearly always), else
            // all to `refs`, so that the order is the nodeset's either way.
            let declared = || n.references.iter().filter(|r| r.declared);
            let numeric = |ix: NodeIx| match model.node(ix).id.id {
                Identifier::Numeric(v) => Some(v),
                _ => None,
            };
            if declared().all(|r| numeric(r.reference_type).is_some() && numeric(r.target).is_some()) {
                out.push_str(", refs: &[], nrefs: ");
                list(out, declared(), |out, r| {
                    let (rt, target) = (model.node(r.reference_type), model.node(r.target));
                    let _ = write!(
                        out,
                        "({}, {}, {}, {}, {})",
                        local(rt.id.ns),
                        numeric(r.reference_type).unwrap_or(0),
                        local(target.id.ns),
                        numeric(r.target).unwrap_or(0),
                        r.forward
                    );
                });
            } else {
                out.push_str(", refs: ");
                list(out, declared(), |out, r| {
                    out.push_str("rt::table::Ref { reference_type: ");
                    id_of(out, r.reference_type);
                    out.push_str(", target: ");
                    id_of(out, r.target);
                    let _ = write!(out, ", forward: {} }}", r.forward);
                });
                out.push_str(", nrefs: &[]");
            }
            out.push_str(" }, \n");
        }
        if dropped_values > 0 {
            self.diags.push(
                Diagnostic::new(
                    Code::UnsupportedFeature,
                    format!("{dropped_values} value(s) of `{}` are structures the generator cannot build yet; those variables start without a value", self.uri()),
                )
                .help("Argument and EnumValueType values are supported; other ExtensionObject values are not yet"),
            );
        }
        let uri = lit(self.uri());
        let m = model.model_of_namespace(self.ns);
        let version = lit(m.and_then(|m| m.version.as_deref()).unwrap_or(""));
        let date = lit(m.and_then(|m| m.publication_date.as_deref()).unwrap_or(""));
        let ns_uris: Vec<Literal> = locals.iter().map(|&g| lit(model.namespace_uri(g))).collect();
        let own = local(self.ns);
        let runtime = path(&self.cfg.runtime_path);
        let head = quote! {
            //! The address space of this namespace as data, imported into a server by the runtime.
            #[allow(unused_imports)]
            use super::types;
            use #runtime as rt;
        };
        let head_file: syn::File = syn::parse2(head).expect("internal error: the table head does not parse");
        let mut text = prettyplease::unparse(&head_file);
        let table_head = quote! {
            pub static TABLE: rt::table::NodeSetTable = rt::table::NodeSetTable {
                namespace_uri: #uri,
                version: #version,
                publication_date: #date,
                namespaces: &[#(#ns_uris),*],
                own: #own,
                nodes: &[ ROWS ],
            };
        };
        let table_file: syn::File = syn::parse2(table_head).expect("internal error: table does not parse");
        let table_text = prettyplease::unparse(&table_file);
        let table_text = table_text.replacen("ROWS", &format!("\n{rows}    "), 1);
        text.push('\n');
        text.push_str("/// Every node of this namespace, one row per node.\n");
        text.push_str(&table_text);
        OutFile { path: PathBuf::from(&self.module).join("nodes.rs"), contents: format!("{}{text}", self.header("Address space")) }
    }

    /// Appends the `Def` of a data type, or `None`.
    fn definition_text(&self, out: &mut String, t: NodeIx, id_of: &dyn Fn(&mut String, NodeIx)) {
        let model = self.model;
        let Some(info) = model.data_types.get(&t) else {
            out.push_str("None");
            return;
        };
        match &info.kind {
            DataTypeKind::Structure { kind, fields, has_definition: true } => {
                out.push_str("Some(rt::table::Def::Structure { base: ");
                match model.node(t).super_type {
                    Some(s) => id_of(out, s),
                    None => out.push_str("rt::table::Id::ns0(22)"),
                }
                out.push_str(", default_encoding: ");
                match info.encodings.iter().find(|(n, _)| n == "Default Binary") {
                    Some((_, e)) => {
                        out.push_str("Some(");
                        id_of(out, *e);
                        out.push(')');
                    }
                    None => out.push_str("None"),
                }
                out.push_str(", kind: rt::table::StructureKind::");
                out.push_str(match kind {
                    StructureKind::Structure => "Structure",
                    StructureKind::StructureWithOptionalFields => "StructureWithOptionalFields",
                    StructureKind::Union => "Union",
                });
                out.push_str(", fields: ");
                list(out, fields, |out, f| {
                    out.push_str("rt::table::FieldRow { name: ");
                    str_lit(out, &f.name);
                    out.push_str(", description: ");
                    opt_str(out, f.description.as_deref());
                    out.push_str(", data_type: ");
                    id_of(out, f.data_type);
                    let _ = write!(out, ", value_rank: {}i32, array_dimensions: ", f.value_rank);
                    dims(out, &f.array_dimensions);
                    let _ = write!(
                        out,
                        ", max_string_length: {}u32, is_optional: {} }}",
                        f.max_string_length.unwrap_or(0),
                        f.is_optional
                    );
                });
                out.push_str(" })");
            }
            DataTypeKind::Enumeration { values, .. } | DataTypeKind::OptionSet { bits: values, .. } => {
                out.push_str("Some(rt::table::Def::Enum { fields: ");
                list(out, values, |out, v| {
                    enum_row(out, v.value, &v.name, v.display_name.as_deref().unwrap_or(&v.name), v.description.as_deref());
                });
                out.push_str(" })");
            }
            _ => out.push_str("None"),
        }
    }

    /// Appends the table value of a variable or variable type; false if it cannot be expressed (then the
    /// caller discards what was appended).
    fn value_text(&self, out: &mut String, ix: NodeIx, local: &dyn Fn(u16) -> u16) -> bool {
        match self.model.value(ix) {
            None => {
                out.push_str("rt::table::Val::None");
                true
            }
            Some(Ok(v)) => self.val_text(out, &v, local),
            Some(Err(_)) => false,
        }
    }

    fn val_text(&self, out: &mut String, v: &Variant, local: &dyn Fn(u16) -> u16) -> bool {
        let nid = |out: &mut String, id: &NodeId| table_id(out, local(id.ns), true, &id.id);
        match v {
            Variant::Boolean(b) => {
                let _ = write!(out, "rt::table::Val::Boolean({b})");
            }
            Variant::SByte(x) => {
                let _ = write!(out, "rt::table::Val::SByte({x}i8)");
            }
            Variant::Byte(x) => {
                let _ = write!(out, "rt::table::Val::Byte({x}u8)");
            }
            Variant::Int16(x) => {
                let _ = write!(out, "rt::table::Val::Int16({x}i16)");
            }
            Variant::UInt16(x) => {
                let _ = write!(out, "rt::table::Val::UInt16({x}u16)");
            }
            Variant::Int32(x) => {
                let _ = write!(out, "rt::table::Val::Int32({x}i32)");
            }
            Variant::UInt32(x) => {
                let _ = write!(out, "rt::table::Val::UInt32({x}u32)");
            }
            Variant::Int64(x) => {
                let _ = write!(out, "rt::table::Val::Int64({x}i64)");
            }
            Variant::UInt64(x) => {
                let _ = write!(out, "rt::table::Val::UInt64({x}u64)");
            }
            Variant::Float(x) => float(out, f64::from(*x), true),
            Variant::Double(x) => float(out, *x, false),
            Variant::String(s) => {
                out.push_str("rt::table::Val::String(");
                str_lit(out, s);
                out.push(')');
            }
            Variant::DateTime(s) => {
                out.push_str("rt::table::Val::DateTime(");
                str_lit(out, s);
                out.push(')');
            }
            Variant::Guid(g) => {
                out.push_str("rt::table::Val::Guid(");
                guid(out, g);
                out.push(')');
            }
            Variant::ByteString(b) => {
                out.push_str("rt::table::Val::ByteString(");
                out.push_str(&Literal::byte_string(b).to_string());
                out.push(')');
            }
            Variant::NodeId(id) => {
                out.push_str("rt::table::Val::NodeId(");
                nid(out, id);
                out.push(')');
            }
            Variant::ExpandedNodeId(id) => {
                out.push_str("rt::table::Val::ExpandedNodeId(");
                nid(out, id);
                out.push(')');
            }
            Variant::StatusCode(c) => {
                let _ = write!(out, "rt::table::Val::StatusCode({c}u32)");
            }
            Variant::QualifiedName(q) => {
                let _ = write!(out, "rt::table::Val::QualifiedName({}u16, ", local(q.ns));
                str_lit(out, &q.name);
                out.push(')');
            }
            Variant::LocalizedText(t) => {
                out.push_str("rt::table::Val::LocalizedText(");
                opt_str(out, t.locale.as_deref());
                out.push_str(", ");
                str_lit(out, &t.text);
                out.push(')');
            }
            Variant::Array(b, items) => {
                if *b == BuiltinType::ExtensionObject {
                    return self.struct_array_text(out, items, local);
                }
                let _ = write!(out, "rt::table::Val::Array({}u32, &[", b.id());
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    if !self.val_text(out, item, local) {
                        return false;
                    }
                }
                out.push_str("])");
            }
            Variant::ExtensionObject(_) => return self.struct_array_text(out, std::slice::from_ref(v), local),
            Variant::Variant(inner) => return self.val_text(out, inner, local),
            Variant::XmlElement(_) | Variant::Null => return false,
        }
        true
    }

    /// Arrays of Argument or EnumValueType structures (the ExtensionObject values every nodeset has).
    fn struct_array_text(&self, out: &mut String, items: &[Variant], local: &dyn Fn(u16) -> u16) -> bool {
        let model = self.model;
        let type_of = |v: &Variant| -> Option<u32> {
            let Variant::ExtensionObject(eo) = v else { return None };
            let ix = model.lookup(eo.type_id.as_ref()?)?;
            // The TypeId is usually the encoding node; go to its DataType.
            let n = model.node(ix);
            if n.class == NodeClass::DataType {
                return n.id.ns0();
            }
            let has_enc = model.ns0(ids::HAS_ENCODING)?;
            n.references.iter().find(|r| !r.forward && r.reference_type == has_enc).and_then(|r| model.node(r.target).id.ns0())
        };
        let Some(kind) = items.first().and_then(type_of) else { return false };
        if !items.iter().all(|i| type_of(i) == Some(kind)) {
            return false;
        }
        let bodies: Vec<&crate::raw::XmlElement> = items
            .iter()
            .filter_map(|i| match i {
                Variant::ExtensionObject(eo) => eo.body.as_ref(),
                _ => None,
            })
            .collect();
        if bodies.len() != items.len() {
            return false;
        }
        let description = |b: &crate::raw::XmlElement| -> Option<String> {
            b.child("Description").and_then(|d| d.child_text("Text")).filter(|t| !t.is_empty()).map(str::to_string)
        };
        match kind {
            ids::ARGUMENT => {
                // On failure the caller discards what was written.
                out.push_str("rt::table::Val::Arguments(&[");
                for (i, b) in bodies.iter().enumerate() {
                    let dt_text = b.child("DataType").and_then(|d| d.child_text("Identifier")).unwrap_or("i=24");
                    let Some(dt) = self.map_value_node_id(dt_text) else { return false };
                    if i > 0 {
                        out.push_str(", ");
                    }
                    out.push_str("rt::table::ArgRow { name: ");
                    str_lit(out, b.child_text("Name").unwrap_or("").trim());
                    out.push_str(", data_type: ");
                    table_id(out, local(dt.ns), true, &dt.id);
                    let vr: i32 = b.child_text("ValueRank").and_then(|t| t.trim().parse().ok()).unwrap_or(-1);
                    let _ = write!(out, ", value_rank: {vr}i32, array_dimensions: ");
                    let d: Vec<u32> = b
                        .child("ArrayDimensions")
                        .map(|a| a.children.iter().filter_map(|c| c.text.trim().parse().ok()).collect())
                        .unwrap_or_default();
                    dims(out, &d);
                    out.push_str(", description: ");
                    opt_str(out, description(b).as_deref());
                    out.push_str(" }");
                }
                out.push_str("])");
                true
            }
            ids::ENUM_VALUE_TYPE => {
                out.push_str("rt::table::Val::EnumValues(");
                list(out, &bodies, |out, b| {
                    let value: i64 = b.child_text("Value").and_then(|t| t.trim().parse().ok()).unwrap_or(0);
                    let dn = b.child("DisplayName").and_then(|d| d.child_text("Text")).unwrap_or("");
                    enum_row(out, value, dn, dn, description(b).as_deref());
                });
                out.push(')');
                true
            }
            _ => false,
        }
    }
}

/// Appends an `rt::table::EnumRow`.
fn enum_row(out: &mut String, value: i64, name: &str, display_name: &str, description: Option<&str>) {
    let _ = write!(out, "rt::table::EnumRow {{ value: {value}i64, name: ");
    str_lit(out, name);
    out.push_str(", display_name: ");
    str_lit(out, display_name);
    out.push_str(", description: ");
    opt_str(out, description);
    out.push_str(" }");
}
