//! `nodes.rs`: the address space of a namespace as one static table, one line of text per node.
//!
//! The rows are data, not code. They are written in the runtime's packed format (documented in the
//! runtime's `table` module, which decodes it on first use) inside one raw string literal, so the Rust
//! compiler reads a namespace's whole address space as a single token. Written as struct literals
//! instead (the previous form, one `rt::table::NodeRow { .. }` per node), the rows were about a tenth of
//! the generated crate's compile time: every literal is parsed, type-checked, const-evaluated and emitted
//! with its relocations.
//!
//! The format is positional, one item per space, so a row reads like the nodeset's attributes in order:
//! `Variable 1:15002 0:"NamespaceUri" = ~ 0 0 0:12 -1 [] 1 1 0 ~ String:"http://..." 0:40>0:68`. Strings are
//! quoted with `"`, `\`, line breaks and control characters escaped; floats are printed the way Rust parses
//! them back to the same value.

mod values;

use super::{lit, Gen};
use crate::diag::{Code, Diagnostic};
use crate::model::{DataTypeKind, Model, NodeIx, StructureKind};
use crate::nodeid::Identifier;
use crate::raw::NodeClass;
use crate::write::OutFile;
use values::{item_text, Layout};
pub use values::{layout_value, Item};
use proc_macro2::Literal;
use quote::quote;
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// Appends a string in the packed format: quoted, with `"`, `\`, line breaks, tabs and other control
/// characters escaped (so a row stays on one line and the Rust raw string around the text stays valid).
fn str_lit(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{{{:x}}}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

/// Appends a string, or `~`.
fn opt_str(out: &mut String, s: Option<&str>) {
    match s {
        Some(s) => str_lit(out, s),
        None => out.push('~'),
    }
}

/// Appends `=` if `s` is `same`, else the string.
fn str_or_same(out: &mut String, s: &str, same: &str) {
    if s == same {
        out.push('=');
    } else {
        str_lit(out, s);
    }
}

/// Appends `{ a b c }` (or `{ }`) with each item written by `item`.
fn list<T>(out: &mut String, items: impl IntoIterator<Item = T>, mut item: impl FnMut(&mut String, T)) {
    out.push('{');
    for x in items {
        out.push(' ');
        item(out, x);
    }
    out.push_str(" }");
}

/// Appends `[]` or `[2,3]`.
fn dims(out: &mut String, d: &[u32]) {
    out.push('[');
    for (i, x) in d.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        let _ = write!(out, "{x}");
    }
    out.push(']');
}

/// Appends bytes as hex digits.
fn hex(out: &mut String, bytes: &[u8]) {
    for b in bytes {
        let _ = write!(out, "{b:02x}");
    }
}

/// Appends a boolean, `0` or `1`.
fn flag(out: &mut String, b: bool) {
    out.push(if b { '1' } else { '0' });
}

/// Appends a NodeId with its table-local namespace index: `2:6027`, `2:s"Pump"`, `2:g<hex>`, `2:b<hex>`.
fn table_id(out: &mut String, ns: u16, id: &Identifier) {
    let _ = write!(out, "{ns}:");
    match id {
        Identifier::Numeric(v) => {
            let _ = write!(out, "{v}");
        }
        Identifier::String(s) => {
            out.push('s');
            str_lit(out, s);
        }
        Identifier::Guid(g) => {
            out.push('g');
            hex(out, g);
        }
        Identifier::Opaque(b) => {
            out.push('b');
            hex(out, b);
        }
    }
}

/// The raw string literal around packed text: `r#"` .. `"#` with one `#` more than any run of `#` that
/// follows a `"` in the text.
fn raw_string(text: &str) -> String {
    let mut most = 0;
    for (i, _) in text.match_indices('"') {
        let run = text[i + 1..].bytes().take_while(|&b| b == b'#').count();
        most = most.max(run);
    }
    let hashes = "#".repeat(most + 1);
    format!("r{hashes}\"{text}\"{hashes}")
}

/// The node table of one namespace, the data of a generated `nodes.rs`: what the runtime's `NodeSetTable`
/// holds (see `nodeset-runtime/src/table.rs` for the packed format of `rows`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NodeTable {
    /// The namespace the table defines.
    pub namespace_uri: String,
    /// The model's version, or empty.
    pub version: String,
    /// The model's publication date, or empty.
    pub publication_date: String,
    /// Table-local namespace index to URI; index 0 is the OPC UA namespace.
    pub namespaces: Vec<String>,
    /// The index of `namespace_uri` in `namespaces`.
    pub own: u16,
    /// The packed rows, one line per node.
    pub rows: String,
}

impl Gen<'_> {
    pub(super) fn nodes_file(&mut self) -> OutFile {
        let table = self.table_data();
        let uri = lit(&table.namespace_uri);
        let version = lit(&table.version);
        let date = lit(&table.publication_date);
        let ns_uris: Vec<Literal> = table.namespaces.iter().map(|u| lit(u)).collect();
        let own = table.own;
        let rows = table.rows;
        let runtime = &self.cfg.runtime_path;
        let head = quote! {
            //! The address space of this namespace as data, imported into a server by the runtime.
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
                nodes: rt::table::Nodes::Packed(rt::table::Packed::new(ROWS)),
            };
        };
        let table_file: syn::File = syn::parse2(table_head).expect("internal error: table does not parse");
        let table_text = prettyplease::unparse(&table_file);
        let table_text = table_text.replacen("ROWS", &raw_string(&format!("\n{rows}")), 1);
        text.push('\n');
        text.push_str(
            "/// Every node of this namespace, one line per node, in the packed format of [`rt::table`] (decoded on\n\
             /// first use).\n",
        );
        text.push_str(&table_text);
        OutFile { path: super::module_dir(&self.module).join("nodes.rs"), contents: format!("{}{text}", self.header("Address space")) }
    }

    /// The node table of the namespace as data: what `nodes.rs` holds, for a server built in memory.
    pub(super) fn table_data(&mut self) -> NodeTable {
        let model = self.model;
        // Table-local namespace indices: 0 is ns0, then every namespace a row refers to, in global order.
        let mut used: BTreeSet<u16> = BTreeSet::new();
        used.insert(self.ns);
        let mine: Vec<NodeIx> =
            (0..model.nodes.len() as u32)
                .map(NodeIx)
                .filter(|&ix| model.node(ix).id.ns == self.ns && self.only.is_none_or(|only| only.contains(&ix)))
                .collect();
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
            for &(role, _) in &n.attrs.roles {
                used.insert(model.node(role).id.ns);
            }
        }
        // Values, laid out once: the namespaces of the NodeIds in them are the table's too.
        let layout = Layout { model };
        let mut values: Vec<Option<Item>> = Vec::with_capacity(mine.len());
        for &ix in &mine {
            let n = model.node(ix);
            if !matches!(n.class, NodeClass::Variable | NodeClass::VariableType) {
                values.push(None);
                continue;
            }
            let item = match model.value(ix) {
                None => None,
                Some(decoded) => match decoded.and_then(|v| layout.node_value(v)) {
                    Ok(item) => item,
                    Err(why) => {
                        self.diags.push(unserved_value(model, ix, &why));
                        None
                    }
                },
            };
            if let Some(item) = &item {
                item.namespaces(model, &mut used);
            }
            values.push(item);
        }
        used.remove(&0);
        let locals: Vec<u16> = std::iter::once(0).chain(used.iter().copied()).collect();
        let local = |g: u16| locals.iter().position(|&l| l == g).unwrap_or(0) as u16;

        let mut rows = String::with_capacity(mine.len() * 160);
        for (&ix, value) in mine.iter().zip(&values) {
            let n = model.node(ix);
            let out = &mut rows;
            let id_of = |out: &mut String, ix: NodeIx| {
                let id = &model.node(ix).id;
                table_id(out, local(id.ns), &id.id);
            };
            out.push_str(match n.class {
                NodeClass::Object => "Object ",
                NodeClass::ObjectType => "ObjectType ",
                NodeClass::Variable => "Variable ",
                NodeClass::VariableType => "VariableType ",
                NodeClass::Method => "Method ",
                NodeClass::ReferenceType => "ReferenceType ",
                NodeClass::DataType => "DataType ",
                NodeClass::View => "View ",
            });
            id_of(out, ix);
            let _ = write!(out, " {}:", local(n.browse_name.ns));
            str_lit(out, &n.browse_name.name);
            out.push(' ');
            str_or_same(out, n.display(), &n.browse_name.name);
            out.push(' ');
            opt_str(out, n.doc());
            let _ = write!(out, " {} {} ", n.attrs.write_mask.unwrap_or(0), n.attrs.user_write_mask.unwrap_or(0));
            match n.class {
                NodeClass::Object => {
                    let _ = write!(out, "{}", n.attrs.event_notifier.unwrap_or(0));
                }
                NodeClass::ObjectType => flag(out, n.is_abstract()),
                NodeClass::Variable | NodeClass::VariableType => {
                    match n.attrs.data_type {
                        Some(dt) => id_of(out, dt),
                        None => out.push_str("0:24"),
                    }
                    let _ = write!(out, " {} ", n.attrs.value_rank.unwrap_or(-1));
                    dims(out, &n.attrs.array_dimensions);
                    if n.class == NodeClass::Variable {
                        let al = n.attrs.access_level.unwrap_or(1);
                        let ual = n.attrs.user_access_level.unwrap_or(al);
                        let _ = write!(out, " {al} {ual} ");
                        flag(out, n.attrs.historizing.unwrap_or(false));
                        match n.attrs.minimum_sampling_interval {
                            Some(v) => {
                                let _ = write!(out, " {v}");
                            }
                            None => out.push_str(" ~"),
                        }
                    } else {
                        out.push(' ');
                        flag(out, n.is_abstract());
                    }
                    out.push(' ');
                    match value {
                        Some(item) => item_text(model, out, item, &local),
                        None => out.push('~'),
                    }
                }
                NodeClass::Method => {
                    let e = n.attrs.executable.unwrap_or(true);
                    flag(out, e);
                    out.push(' ');
                    flag(out, n.attrs.user_executable.unwrap_or(e));
                }
                NodeClass::ReferenceType => {
                    flag(out, n.attrs.symmetric.unwrap_or(false));
                    out.push(' ');
                    flag(out, n.is_abstract());
                    out.push(' ');
                    opt_str(out, n.attrs.inverse_name.first().map(|t| t.text.as_str()));
                }
                NodeClass::DataType => {
                    flag(out, n.is_abstract());
                    out.push(' ');
                    self.definition_text(out, ix, &id_of);
                }
                NodeClass::View => {
                    let _ = write!(out, "{} ", n.attrs.event_notifier.unwrap_or(0));
                    flag(out, n.attrs.contains_no_loops.unwrap_or(false));
                }
            }
            // The references the row's file declares, in its order: `type>target` forward, `type<target`
            // inverse.
            for r in n.references.iter().filter(|r| r.declared) {
                out.push(' ');
                id_of(out, r.reference_type);
                out.push(if r.forward { '>' } else { '<' });
                id_of(out, r.target);
            }
            out.push('\n');
            // RolePermissions and AccessRestrictions, on a line of their own after the row, only where the
            // nodeset gives them: `Access ID RESTRICTIONS ROLE=PERMISSIONS ...` (`~` for no restrictions).
            if !n.attrs.roles.is_empty() || n.attrs.access_restrictions.is_some() {
                out.push_str("Access ");
                id_of(out, ix);
                match n.attrs.access_restrictions {
                    Some(r) => {
                        let _ = write!(out, " {r}");
                    }
                    None => out.push_str(" ~"),
                }
                for &(role, permissions) in &n.attrs.roles {
                    out.push(' ');
                    id_of(out, role);
                    let _ = write!(out, "={permissions}");
                }
                out.push('\n');
            }
            // The declaration this one overrides at its browse path (`Model::overridden`), on a line of its
            // own, so that the runtime's `instantiate` merges the members the model merged.
            if let Some(&over) = self.model.overridden.get(&ix) {
                out.push_str("Overrides ");
                id_of(out, ix);
                out.push(' ');
                id_of(out, over);
                out.push('\n');
            }
        }
        let m = model.model_of_namespace(self.ns);
        NodeTable {
            namespace_uri: self.uri().to_owned(),
            version: m.and_then(|m| m.version.clone()).unwrap_or_default(),
            publication_date: m.and_then(|m| m.publication_date.clone()).unwrap_or_default(),
            namespaces: locals.iter().map(|&g| model.namespace_uri(g).to_owned()).collect(),
            own: local(self.ns),
            rows,
        }
    }

    /// Appends the definition of a data type, or `~`.
    fn definition_text(&self, out: &mut String, t: NodeIx, id_of: &dyn Fn(&mut String, NodeIx)) {
        let model = self.model;
        let Some(info) = model.data_types.get(&t) else {
            out.push('~');
            return;
        };
        match &info.kind {
            DataTypeKind::Structure { kind, fields, has_definition: true } => {
                out.push_str(match kind {
                    StructureKind::Structure => "Structure ",
                    StructureKind::StructureWithOptionalFields => "StructureWithOptionalFields ",
                    StructureKind::Union => "Union ",
                });
                match model.node(t).super_type {
                    Some(s) => id_of(out, s),
                    None => out.push_str("0:22"),
                }
                out.push(' ');
                match info.encodings.iter().find(|(n, _)| n == "Default Binary") {
                    Some((_, e)) => id_of(out, *e),
                    None => out.push('~'),
                }
                out.push(' ');
                list(out, fields, |out, f| {
                    str_lit(out, &f.name);
                    out.push(' ');
                    opt_str(out, f.description.as_deref());
                    out.push(' ');
                    id_of(out, f.data_type);
                    let _ = write!(out, " {} ", f.value_rank);
                    dims(out, &f.array_dimensions);
                    let _ = write!(out, " {} ", f.max_string_length.unwrap_or(0));
                    flag(out, f.is_optional);
                });
            }
            DataTypeKind::Enumeration { values, .. } | DataTypeKind::OptionSet { bits: values, .. } => {
                out.push_str("Enum ");
                list(out, values, |out, v| {
                    enum_row(out, v.value, &v.name, v.display_name.as_deref().unwrap_or(&v.name), v.description.as_deref());
                });
            }
            _ => out.push('~'),
        }
    }
}

/// Appends an enumeration row: `value name display_name description`.
fn enum_row(out: &mut String, value: i64, name: &str, display_name: &str, description: Option<&str>) {
    let _ = write!(out, "{value} ");
    str_lit(out, name);
    out.push(' ');
    str_or_same(out, display_name, name);
    out.push(' ');
    opt_str(out, description);
}

/// The warning for a value the table cannot hold: the variable by browse path and NodeId, at its `<Value>`.
fn unserved_value(model: &Model, ix: NodeIx, why: &str) -> Diagnostic {
    let n = model.node(ix);
    let span = model.value_element(ix).map_or(n.span, |v| v.span());
    Diagnostic::new(
        Code::UnsupportedFeature,
        format!(
            "the value of `{}` ({}) is not served: {why}; the variable starts without a value",
            browse_path(model, ix),
            model.display_id(&n.id)
        ),
    )
    .at(span)
    .help("a structure value is served when its TypeId names the encoding of a structure DataType with a definition and every field decodes")
}

/// The browse path of a node from its type or top object (`MotorType/Speed/EngineeringUnits`), for messages.
fn browse_path(model: &Model, ix: NodeIx) -> String {
    let mut parts = Vec::new();
    let mut cur = Some(ix);
    while let Some(c) = cur.filter(|_| parts.len() < 16) {
        let n = model.node(c);
        parts.push(n.browse_name.name.as_str());
        if n.class.is_type() {
            break;
        }
        // Up to the type, or to the object below a folder of the base namespace (Objects).
        cur = n.parent.filter(|&p| n.id.ns == 0 || model.node(p).id.ns != 0);
    }
    parts.reverse();
    parts.join("/")
}
