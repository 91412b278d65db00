//! The Rust back end writes each namespace's address space as packed text in `nodes.rs`, and the runtime
//! decodes that text when a server first uses the table. This test holds the two sides to one format over
//! every resolvable file of the ua-nodeset corpus, ns0 included: every generated table decodes with the
//! runtime's own decoder into exactly the model's nodes of that namespace, in the model's order, with their
//! attributes, declared references, data type definitions and values.

use nodeset_compiler::emit::rust::{default_module_name, generate, RustConfig, RustNamespace, RustPath};
use nodeset_compiler::load::Input;
use nodeset_compiler::model::{DataTypeKind, Model, NodeIx, StructureKind};
use nodeset_compiler::nodeid::{Identifier, NodeId};
use nodeset_compiler::raw::NodeClass;
use nodeset_compiler::value::{BuiltinType, Variant};
use nodeset_compiler::{compile, Options};
use nodeset_runtime::table::{self, Def, Id, IdKind, Kind, NodeRow, Val};
use nodeset_tests::{corpus, nodeset_files};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// The namespace URIs, own index and packed text of a generated `nodes.rs`, read with syn.
struct Table {
    namespaces: Vec<String>,
    own: u16,
    text: String,
}

fn parse_table(file: &str) -> Result<Table, String> {
    let body: String = file.lines().skip_while(|l| l.starts_with("// ")).map(|l| format!("{l}\n")).collect();
    let f = syn::parse_file(&body).map_err(|e| format!("nodes.rs does not parse: {e}"))?;
    let table = f
        .items
        .iter()
        .find_map(|i| match i {
            syn::Item::Static(s) if s.ident == "TABLE" => Some(s),
            _ => None,
        })
        .ok_or("no `static TABLE`")?;
    let syn::Expr::Struct(st) = &*table.expr else { return Err("TABLE is not a struct expression".into()) };
    let field = |name: &str| {
        st.fields
            .iter()
            .find(|f| matches!(&f.member, syn::Member::Named(i) if i == name))
            .map(|f| &f.expr)
            .ok_or(format!("TABLE has no field `{name}`"))
    };
    let str_lit = |e: &syn::Expr| match e {
        syn::Expr::Lit(syn::ExprLit { lit: syn::Lit::Str(s), .. }) => Some(s.value()),
        _ => None,
    };
    let namespaces = match field("namespaces")? {
        syn::Expr::Reference(r) => match &*r.expr {
            syn::Expr::Array(a) => a.elems.iter().map(|e| str_lit(e).ok_or("a namespace is not a string")).collect(),
            _ => Err("namespaces is not an array"),
        },
        _ => Err("namespaces is not a reference"),
    }?;
    let own = match field("own")? {
        syn::Expr::Lit(syn::ExprLit { lit: syn::Lit::Int(i), .. }) => i.base10_parse::<u16>().map_err(|e| e.to_string())?,
        _ => return Err("own is not an integer".into()),
    };
    // `rt::table::Nodes::Packed(rt::table::Packed::new(r#"..."#))`
    let text = match field("nodes")? {
        syn::Expr::Call(outer) => match outer.args.first() {
            Some(syn::Expr::Call(inner)) => inner.args.first().and_then(str_lit),
            _ => None,
        },
        _ => None,
    }
    .ok_or("nodes is not `Nodes::Packed(Packed::new(<string>))`")?;
    Ok(Table { namespaces, own, text })
}

/// Compares one decoded row with its model node; the first difference, if any.
struct Check<'a> {
    model: &'a Model,
    namespaces: &'a [String],
}

impl Check<'_> {
    fn same_id(&self, id: &Id, node: &NodeId) -> bool {
        self.namespaces.get(id.ns as usize).map(String::as_str) == Some(self.model.namespace_uri(node.ns))
            && match (&id.id, &node.id) {
                (IdKind::Numeric(a), Identifier::Numeric(b)) => a == b,
                (IdKind::String(a), Identifier::String(b)) => **a == **b,
                (IdKind::Guid(a), Identifier::Guid(b)) => a == b,
                (IdKind::Opaque(a), Identifier::Opaque(b)) => **a == **b,
                _ => false,
            }
    }

    fn same_ix(&self, id: &Id, ix: NodeIx) -> bool {
        self.same_id(id, &self.model.node(ix).id)
    }

    fn row(&self, row: &NodeRow, ix: NodeIx) -> Result<(), String> {
        let m = self.model;
        let n = m.node(ix);
        let a = &n.attrs;
        let want = |ok: bool, what: &str| if ok { Ok(()) } else { Err(format!("{what} differs")) };
        want(self.same_id(&row.id, &n.id), "NodeId")?;
        want(
            self.namespaces.get(row.browse_name.0 as usize).map(String::as_str) == Some(m.namespace_uri(n.browse_name.ns))
                && row.browse_name.1 == n.browse_name.name,
            "BrowseName",
        )?;
        want(row.display_name == n.display(), "DisplayName")?;
        want(row.description == n.doc(), "Description")?;
        want((row.write_mask, row.user_write_mask) == (a.write_mask.unwrap_or(0), a.user_write_mask.unwrap_or(0)), "WriteMask")?;
        let data_type_ok = |id: &Id| match a.data_type {
            Some(dt) => self.same_ix(id, dt),
            None => *id == Id::ns0(24),
        };
        match (n.class, &row.kind) {
            (NodeClass::Object, Kind::Object { event_notifier }) => want(*event_notifier == a.event_notifier.unwrap_or(0), "EventNotifier")?,
            (NodeClass::ObjectType, Kind::ObjectType { is_abstract }) => want(*is_abstract == n.is_abstract(), "IsAbstract")?,
            (
                NodeClass::Variable,
                Kind::Variable {
                    data_type,
                    value_rank,
                    array_dimensions,
                    access_level,
                    user_access_level,
                    historizing,
                    minimum_sampling_interval,
                    value,
                },
            ) => {
                want(data_type_ok(data_type), "DataType")?;
                want(*value_rank == a.value_rank.unwrap_or(-1) && *array_dimensions == a.array_dimensions, "ValueRank")?;
                let al = a.access_level.unwrap_or(1);
                want((*access_level, *user_access_level) == (al, a.user_access_level.unwrap_or(al)), "AccessLevel")?;
                want(*historizing == a.historizing.unwrap_or(false), "Historizing")?;
                want(*minimum_sampling_interval == a.minimum_sampling_interval, "MinimumSamplingInterval")?;
                self.value(value, ix)?;
            }
            (NodeClass::VariableType, Kind::VariableType { data_type, value_rank, array_dimensions, is_abstract, value }) => {
                want(data_type_ok(data_type), "DataType")?;
                want(*value_rank == a.value_rank.unwrap_or(-1) && *array_dimensions == a.array_dimensions, "ValueRank")?;
                want(*is_abstract == n.is_abstract(), "IsAbstract")?;
                self.value(value, ix)?;
            }
            (NodeClass::Method, Kind::Method { executable, user_executable }) => {
                let e = a.executable.unwrap_or(true);
                want((*executable, *user_executable) == (e, a.user_executable.unwrap_or(e)), "Executable")?;
            }
            (NodeClass::ReferenceType, Kind::ReferenceType { symmetric, is_abstract, inverse_name }) => {
                want(*symmetric == a.symmetric.unwrap_or(false) && *is_abstract == n.is_abstract(), "Symmetric")?;
                want(*inverse_name == a.inverse_name.first().map(|t| t.text.as_str()), "InverseName")?;
            }
            (NodeClass::DataType, Kind::DataType { is_abstract, definition }) => {
                want(*is_abstract == n.is_abstract(), "IsAbstract")?;
                self.definition(definition.as_ref(), ix)?;
            }
            (NodeClass::View, Kind::View { event_notifier, contains_no_loops }) => want(
                *event_notifier == a.event_notifier.unwrap_or(0) && *contains_no_loops == a.contains_no_loops.unwrap_or(false),
                "View attributes",
            )?,
            (class, kind) => return Err(format!("node class {class:?} decoded as {kind:?}")),
        }
        let declared: Vec<_> = n.references.iter().filter(|r| r.declared).collect();
        let refs: Vec<table::Ref> = row.references().collect();
        want(refs.len() == declared.len(), "reference count")?;
        for (i, (r, d)) in refs.iter().zip(&declared).enumerate() {
            want(
                self.same_ix(&r.reference_type, d.reference_type) && self.same_ix(&r.target, d.target) && r.forward == d.forward,
                &format!("reference {i}"),
            )?;
        }
        Ok(())
    }

    fn definition(&self, def: Option<&Def>, ix: NodeIx) -> Result<(), String> {
        let m = self.model;
        match (m.data_types.get(&ix).map(|i| (&i.kind, i)), def) {
            (Some((DataTypeKind::Structure { kind, fields, has_definition: true }, info)), Some(Def::Structure { base, default_encoding, kind: k, fields: f })) => {
                let kind_ok = matches!(
                    (kind, k),
                    (StructureKind::Structure, table::StructureKind::Structure)
                        | (StructureKind::StructureWithOptionalFields, table::StructureKind::StructureWithOptionalFields)
                        | (StructureKind::Union, table::StructureKind::Union)
                );
                let base_ok = match m.node(ix).super_type {
                    Some(s) => self.same_ix(base, s),
                    None => *base == Id::ns0(22),
                };
                let enc = info.encodings.iter().find(|(n, _)| n == "Default Binary").map(|(_, e)| *e);
                let enc_ok = match (enc, default_encoding) {
                    (Some(e), Some(d)) => self.same_ix(d, e),
                    (None, None) => true,
                    _ => false,
                };
                let fields_ok = fields.len() == f.len()
                    && fields.iter().zip(f.iter()).all(|(a, b)| {
                        *a.name == *b.name
                            && a.description.as_deref() == b.description
                            && self.same_ix(&b.data_type, a.data_type)
                            && a.value_rank == b.value_rank
                            && a.array_dimensions == b.array_dimensions
                            && a.max_string_length.unwrap_or(0) == b.max_string_length
                            && a.is_optional == b.is_optional
                    });
                if kind_ok && base_ok && enc_ok && fields_ok {
                    Ok(())
                } else {
                    Err(format!("structure definition differs: {def:?}"))
                }
            }
            (Some((DataTypeKind::Enumeration { values, .. } | DataTypeKind::OptionSet { bits: values, .. }, _)), Some(Def::Enum { fields })) => {
                let ok = values.len() == fields.len()
                    && values.iter().zip(fields.iter()).all(|(v, f)| {
                        v.value == f.value
                            && v.name == f.name
                            && v.display_name.as_deref().unwrap_or(&v.name) == f.display_name
                            && v.description.as_deref() == f.description
                    });
                if ok {
                    Ok(())
                } else {
                    Err(format!("enumeration definition differs: {def:?}"))
                }
            }
            (Some((DataTypeKind::Structure { has_definition: true, .. }, _)), _)
            | (Some((DataTypeKind::Enumeration { .. } | DataTypeKind::OptionSet { .. }, _)), _) => {
                Err(format!("definition missing or of another kind: {def:?}"))
            }
            (_, None) => Ok(()),
            (_, Some(d)) => Err(format!("a definition the model does not have: {d:?}")),
        }
    }

    /// The decoded value against the model's: equal where the table can hold it, `None` where the model has
    /// none or one the generator leaves out (a structure it cannot lay out, with a warning).
    fn value(&self, val: &Val, ix: NodeIx) -> Result<(), String> {
        match (self.model.value(ix), val) {
            (None, Val::None) | (Some(Err(_)), Val::None) => Ok(()),
            (Some(Ok(v)), Val::None) if !representable(&v) => Ok(()),
            (Some(Ok(v)), val) if self.same_value(val, &v) => Ok(()),
            (v, val) => Err(format!("value differs: the model has {v:?}, the table {val:?}")),
        }
    }

    fn same_value(&self, val: &Val, v: &Variant) -> bool {
        match (v, val) {
            (Variant::Variant(inner), _) => self.same_value(val, inner),
            (Variant::Boolean(a), Val::Boolean(b)) => a == b,
            (Variant::SByte(a), Val::SByte(b)) => a == b,
            (Variant::Byte(a), Val::Byte(b)) => a == b,
            (Variant::Int16(a), Val::Int16(b)) => a == b,
            (Variant::UInt16(a), Val::UInt16(b)) => a == b,
            (Variant::Int32(a), Val::Int32(b)) => a == b,
            (Variant::UInt32(a), Val::UInt32(b)) => a == b,
            (Variant::Int64(a), Val::Int64(b)) => a == b,
            (Variant::UInt64(a), Val::UInt64(b)) => a == b,
            (Variant::Float(a), Val::Float(b)) => a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
            (Variant::Double(a), Val::Double(b)) => a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
            (Variant::String(a), Val::String(b)) | (Variant::DateTime(a), Val::DateTime(b)) => a == b,
            (Variant::Guid(a), Val::Guid(b)) => a == b,
            (Variant::ByteString(a), Val::ByteString(b)) => a == b,
            (Variant::NodeId(a), Val::NodeId(b)) | (Variant::ExpandedNodeId(a), Val::ExpandedNodeId(b)) => self.same_id(b, a),
            (Variant::StatusCode(a), Val::StatusCode(b)) => a == b,
            (Variant::QualifiedName(a), Val::QualifiedName(ns, name)) => {
                self.namespaces.get(*ns as usize).map(String::as_str) == Some(self.model.namespace_uri(a.ns)) && a.name == *name
            }
            (Variant::LocalizedText(a), Val::LocalizedText(locale, text)) => a.locale.as_deref() == *locale && a.text == *text,
            (Variant::Array(BuiltinType::ExtensionObject, items), Val::Arguments(rows)) => items.len() == rows.len(),
            (Variant::Array(BuiltinType::ExtensionObject, items), Val::EnumValues(rows)) => items.len() == rows.len(),
            (Variant::ExtensionObject(eo), Val::Structure(encoding, _)) => self.is_binary_encoding(encoding, eo),
            (Variant::Array(BuiltinType::ExtensionObject, items), Val::Array(22, vals)) => {
                items.len() == vals.len() && items.iter().zip(vals.iter()).all(|(i, v)| self.same_value(v, i))
            }
            (Variant::Array(b, items), Val::Array(ty, vals)) => {
                b.id() == *ty && items.len() == vals.len() && items.iter().zip(vals.iter()).all(|(i, v)| self.same_value(v, i))
            }
            _ => false,
        }
    }

    /// Whether a structure value's table encoding is the Default Binary encoding of the value's DataType.
    fn is_binary_encoding(&self, encoding: &Id, eo: &nodeset_compiler::value::ExtensionObject) -> bool {
        let Some(dt) = eo.structure().and_then(|s| self.model.lookup(&s.data_type)) else { return false };
        let info = &self.model.data_types[&dt];
        info.encodings.iter().any(|(n, e)| n == "Default Binary" && self.same_id(encoding, &self.model.node(*e).id))
    }
}

/// Whether the table must hold a value: everything but structures (a structure the generator cannot lay out
/// is left out with a warning; those it lays out `same_value` checks), XML elements and null.
fn representable(v: &Variant) -> bool {
    match v {
        Variant::ExtensionObject(_) | Variant::XmlElement(_) | Variant::Null => false,
        Variant::Array(BuiltinType::ExtensionObject, _) => false,
        Variant::Array(_, items) => items.iter().all(representable),
        Variant::Variant(inner) => representable(inner),
        _ => true,
    }
}

/// The outcome of one corpus file: tables and rows checked, or the first difference.
fn check_file(file: &PathBuf, opts: &Options) -> Result<(usize, usize), String> {
    let out = compile(vec![Input::Path(file.clone())], opts);
    if !out.ok() {
        // Not resolvable (a required model is absent from the tree); the corpus test reports those.
        return Ok((0, 0));
    }
    let model = &out.model;
    let mut namespaces = Vec::new();
    let mut extern_paths = BTreeMap::new();
    for (i, m) in model.models.iter().enumerate() {
        if model.sources.get(m.file).named {
            namespaces.push(RustNamespace { uri: m.uri.clone(), module: format!("{}_{i}", default_module_name(&m.uri)) });
        } else {
            extern_paths.insert(m.uri.clone(), RustPath::new(&format!("crate::dep_{i}")).unwrap());
        }
    }
    let cfg = RustConfig { namespaces: namespaces.clone(), extern_paths, runtime_path: RustPath::new("crate::runtime").unwrap(), command: "test".into() };
    let generated = generate(model, &cfg);
    let (mut tables, mut rows) = (0, 0);
    for ns_cfg in &namespaces {
        let Some(ns) = model.namespaces.iter().position(|u| *u == ns_cfg.uri).map(|i| i as u16) else { continue };
        let path = nodeset_compiler::emit::rust::module_dir(&ns_cfg.module).join("nodes.rs");
        let nodes = generated.files.iter().find(|f| f.path == path).ok_or(format!("no {}", path.display()))?;
        let t = parse_table(&nodes.contents).map_err(|e| format!("{}: {e}", path.display()))?;
        if t.namespaces.get(t.own as usize) != Some(&ns_cfg.uri) {
            return Err(format!("{}: `own` is not the namespace's index", path.display()));
        }
        let text: &'static str = Box::leak(t.text.into_boxed_str());
        let decoded = table::decode(text).map_err(|(l, c, e)| format!("{}: line {l}, column {c}: {e}", path.display()))?;
        let mine: Vec<NodeIx> = (0..model.nodes.len() as u32).map(NodeIx).filter(|&ix| model.node(ix).id.ns == ns).collect();
        if decoded.len() != mine.len() {
            return Err(format!("{}: {} rows for {} nodes", path.display(), decoded.len(), mine.len()));
        }
        let check = Check { model, namespaces: &t.namespaces };
        for (row, &ix) in decoded.iter().zip(&mine) {
            check.row(row, ix).map_err(|e| format!("{}: node {}: {e}", path.display(), model.node(ix).id))?;
        }
        tables += 1;
        rows += decoded.len();
    }
    Ok((tables, rows))
}

#[test]
fn every_corpus_table_decodes_into_the_models_nodes() {
    let tree = corpus();
    let files = nodeset_files(&tree);
    let opts = Options { model_dirs: vec![tree.clone()], ..Options::default() };
    // Two workers: the CI machine has two cores.
    let results: Vec<(PathBuf, Result<(usize, usize), String>)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..2)
            .map(|w| {
                let (files, opts) = (&files, &opts);
                s.spawn(move || files.iter().skip(w).step_by(2).map(|f| (f.clone(), check_file(f, opts))).collect::<Vec<_>>())
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("a worker panicked")).collect()
    });
    let tables: usize = results.iter().filter_map(|(_, r)| r.as_ref().ok()).map(|r| r.0).sum();
    let rows: usize = results.iter().filter_map(|(_, r)| r.as_ref().ok()).map(|r| r.1).sum();
    println!("packed tables: {} corpus files, {tables} tables, {rows} rows decoded and matched", results.len());
    let failed: Vec<String> =
        results.iter().filter_map(|(f, r)| r.as_ref().err().map(|e| format!("{}: {e}", f.display()))).collect();
    assert!(failed.is_empty(), "{} file(s) differ:\n{}", failed.len(), failed.join("\n"));
    // The corpus has 117 files; all but a handful resolve, ns0 among them with about 20,000 nodes.
    assert!(tables >= 100 && rows >= 50_000, "too little was checked: {tables} tables, {rows} rows");
}
