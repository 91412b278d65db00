//! The Rust back end: typed Rust for async-opcua 0.19 from the resolved model.
//!
//! For each namespace it emits a module with five files:
//!
//! - `mod.rs`: the namespace URI, model version, and re-exports;
//! - `ids.rs`: a constant for every node (`NsNodeId`: the namespace by URI, resolved at run time), named from
//!   the SymbolicName or the browse path below the node's type, grouped by node class;
//! - `types.rs`: the data types: structures (inherited fields included), structures with optional fields
//!   (`Option<T>` with the encoding mask), unions (enums with one-field variants), enumerations with the
//!   nodeset's values, OptionSets as bit flags of the right width, simple subtypes as aliases, plus the
//!   encoding ids and a type loader so servers and clients decode them;
//! - `nodes.rs`: the address space as one static [`NodeSetTable`] (data: one line of packed text per node,
//!   decoded on first use), which the hand-written runtime imports into a server with the namespace
//!   indices of that server;
//! - `objects.rs`: typed handles of the ObjectTypes and VariableTypes and member markers (`objects`), the
//!   state tables of state machine types, and the typed inputs and outputs of program types (`programs`).
//!
//! `generate` is a pure function of the model and the configuration; it returns files in memory. Its files
//! are generated on all cores (one job per namespace and file), with the same output whatever the number of
//! threads.
//!
//! Code is built with quote and printed by prettyplease. Three tables are written as text instead, because
//! building and parsing token trees for data cost most of the generation time: the node rows of `nodes.rs`
//! (one line of packed text each, inside one raw string literal), the NodeId constants of `ids.rs` (in prettyplease's own layout; the tests
//! `ids_text_is_what_prettyplease_prints` and `generated_code_is_in_prettyplease_layout` hold it to that),
//! and the member markers at the end of `objects.rs` (one line each).
//!
//! [`NodeSetTable`]: https://docs.rs/nodeset-models (runtime::table::NodeSetTable)

mod async_opcua_ns0;
mod built;
mod objects;
mod programs;
mod recursion;
mod table;

pub use objects::marker_name;
pub use table::{layout_value, Item as ValueItem, NodeTable};

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::model::{ids, DataTypeKind, Model, NodeIx, StructureKind};
use crate::names::{self, Case, Scope, Target};
use crate::nodeid::Identifier;
use crate::raw::NodeClass;
use crate::value::BuiltinType;
use crate::write::OutFile;
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{quote, ToTokens};
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

/// One namespace to generate.
#[derive(Clone, Debug)]
pub struct RustNamespace {
    /// The namespace URI.
    pub uri: String,
    /// The module name (a Rust identifier), e.g. `robotics`.
    pub module: String,
}

/// What to generate and how generated code reaches its dependencies.
#[derive(Clone, Debug)]
pub struct RustConfig {
    /// The namespaces to generate, one module each.
    pub namespaces: Vec<RustNamespace>,
    /// Rust paths of namespaces generated elsewhere (URI -> path of their module, e.g.
    /// `nodeset_models::models::di`). Namespaces generated in this run are reached as `super::<module>`.
    pub extern_paths: BTreeMap<String, RustPath>,
    /// Path of the runtime module (`crate::runtime` inside nodeset-models, `nodeset_models::runtime` elsewhere).
    pub runtime_path: RustPath,
    /// The command that regenerates the output, for file headers.
    pub command: String,
}

/// Generated files and the diagnostics of generation.
#[derive(Debug, Default)]
pub struct RustOutput {
    /// The generated files, sorted by path, relative to the output folder (`<module>/<file>`).
    pub files: Vec<OutFile>,
    /// The errors and warnings of generation.
    pub diagnostics: Diagnostics,
}

/// A node table of the OPC UA namespace holding only `nodes` (nodes of ns0): for a server whose ns0 (async-opcua's)
/// lacks nodes the model's ns0 has (`nodeset-compiler serve` adds them to it).
pub fn ns0_table(model: &Model, cfg: &RustConfig, nodes: &BTreeSet<NodeIx>) -> (NodeTable, Diagnostics) {
    let mut g = Gen::new(model, cfg, 0, "opcua");
    g.only = Some(nodes);
    let table = g.table_data();
    (table, g.diags)
}

/// A default module name for a model URI: the last path segment in snake case (`.../Robotics/` -> `robotics`).
pub fn default_module_name(uri: &str) -> String {
    let seg = uri.trim_end_matches('/').rsplit(['/', ':']).next().unwrap_or(uri);
    names::sanitize(seg, Case::Snake, Target::Rust)
}

/// The node tables of `cfg`'s namespaces, as data (what each `nodes.rs` holds), with the diagnostics of
/// building them: for a server built in memory, with no Rust compiled.
pub fn node_tables(model: &Model, cfg: &RustConfig) -> (Vec<NodeTable>, Diagnostics) {
    let mut diags = Diagnostics::new();
    let mut tables = Vec::new();
    for ns_cfg in &cfg.namespaces {
        let Some(ns) = model.namespaces.iter().position(|u| *u == ns_cfg.uri) else { continue };
        let mut g = Gen::new(model, cfg, ns as u16, &ns_cfg.module);
        tables.push(g.table_data());
        diags.extend(g.diags);
    }
    (tables, diags)
}

/// The folder of a namespace module's files: the module name without `r#`. A namespace named by a keyword
/// is declared `pub mod r#struct;`, and rustc looks for that module in `struct/` (a raw identifier's file
/// has the identifier's own name).
pub fn module_dir(module: &str) -> PathBuf {
    PathBuf::from(module.strip_prefix("r#").unwrap_or(module))
}

/// Generates Rust for the configured namespaces.
///
/// Each file of each namespace is generated on its own (a fresh `Gen` per file) and the files are spread
/// over the cores; files and diagnostics come out in the same order whatever the number of threads.
pub fn generate(model: &Model, cfg: &RustConfig) -> RustOutput {
    let mut out = RustOutput::default();
    let namespaces: Vec<Option<u16>> = cfg
        .namespaces
        .iter()
        .map(|ns_cfg| model.namespaces.iter().position(|u| *u == ns_cfg.uri).map(|i| i as u16))
        .collect();
    // The largest parts first, so that the threads finish together.
    let mut jobs: Vec<(usize, u16, Part)> = Vec::new();
    for part in [Part::Objects, Part::Ids, Part::Nodes, Part::Types, Part::Module] {
        for (i, ns) in namespaces.iter().enumerate() {
            if let Some(ns) = *ns {
                jobs.push((i, ns, part));
            }
        }
    }
    let done = crate::par::par_map(&jobs, |&(i, ns, part)| {
        let mut g = Gen::new(model, cfg, ns, &cfg.namespaces[i].module);
        let file = g.part(part);
        (file, g.diags)
    });
    let mut per_ns: Vec<Vec<(Part, OutFile, Diagnostics)>> = namespaces.iter().map(|_| Vec::new()).collect();
    for (&(i, _, part), (file, diags)) in jobs.iter().zip(done) {
        per_ns[i].push((part, file, diags));
    }
    for (i, mut parts) in per_ns.into_iter().enumerate() {
        if namespaces[i].is_none() {
            out.diagnostics.push(
                Diagnostic::new(Code::MissingModel, format!("namespace `{}` is not in the loaded model", cfg.namespaces[i].uri))
                    .help("name the NodeSet2 file that defines it"),
            );
            continue;
        }
        // Diagnostics in the order the parts were always generated in.
        parts.sort_by_key(|(part, _, _)| *part);
        for (_, file, diags) in parts {
            out.diagnostics.extend(diags);
            out.files.push(file);
        }
    }
    out.files.sort_by(|a, b| a.path.cmp(&b.path));
    out
}

/// The files of a namespace.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Part {
    Ids,
    Types,
    Nodes,
    Objects,
    Module,
}

/// The width prettyplease fills before it breaks a line (its `MARGIN`), in bytes.
const PRETTYPLEASE_MARGIN: usize = 89;

/// Per-namespace generation state.
struct Gen<'m> {
    model: &'m Model,
    cfg: &'m RustConfig,
    ns: u16,
    module: String,
    diags: Diagnostics,
    /// Rust type names of this namespace's data types.
    type_names: BTreeMap<NodeIx, String>,
    /// Type names of other namespaces, computed on demand with the same rules.
    foreign_type_names: std::cell::RefCell<BTreeMap<u16, BTreeMap<NodeIx, String>>>,
    /// `objects.rs` item names and handle names per namespace, computed on demand.
    item_names_cache: std::cell::RefCell<BTreeMap<u16, std::rc::Rc<BTreeMap<(NodeIx, programs::Item), String>>>>,
    handle_names_cache: std::cell::RefCell<BTreeMap<u16, std::rc::Rc<BTreeMap<NodeIx, String>>>>,
    value_type_cache: std::cell::RefCell<std::collections::HashMap<(Option<NodeIx>, i32), syn::Type>>,
    ns0_types: BTreeSet<&'static str>,
    /// The nodes of the namespace a node table holds, if not all of them (see [`ns0_table`]).
    only: Option<&'m BTreeSet<NodeIx>>,
    /// The `Handle::build` bodies of `objects.rs`, built directly, by placeholder index (see `built`).
    bodies: Vec<syn::Expr>,
    /// The field doc attributes and types of the handles in `objects.rs`, built directly, by placeholder index (see `built`).
    built_types: Vec<(Vec<syn::Attribute>, syn::Type)>,
}

fn ident(s: &str) -> Ident {
    match s.strip_prefix("r#") {
        Some(raw) => Ident::new_raw(raw, Span::call_site()),
        None => Ident::new(s, Span::call_site()),
    }
}

/// A Rust path such as `crate::runtime` or `nodeset_models::models::di`, checked when it is made (a path a user
/// gives is refused there, with the reason, and never reaches the generator as text to splice). It keeps its
/// text, so that a configuration can be shared by the generator's threads, which syn's tokens cannot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RustPath(String);

impl RustPath {
    /// The path written as `text`, or why it is not a Rust path.
    pub fn new(text: &str) -> Result<RustPath, String> {
        match syn::parse_str::<syn::Path>(text) {
            Ok(_) => Ok(RustPath(text.trim().to_string())),
            Err(e) => Err(format!("`{text}` is not a Rust path ({e})")),
        }
    }

    /// The path as written.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl ToTokens for RustPath {
    fn to_tokens(&self, tokens: &mut TokenStream) {
        let path: syn::Path = syn::parse_str(&self.0).expect("a RustPath is checked when it is made");
        path.to_tokens(tokens);
    }
}

fn doc(text: &str) -> TokenStream {
    let lines: Vec<TokenStream> = text
        .lines()
        .map(|l| {
            let l = format!(" {}", l.trim_end());
            quote! { #[doc = #l] }
        })
        .collect();
    quote! { #(#lines)* }
}

/// A string literal token.
fn lit(s: &str) -> Literal {
    Literal::string(s)
}

/// Whether a data type gets a Rust type of its own in its namespace's `types.rs`.
fn has_rust_type(model: &Model, t: NodeIx) -> bool {
    let Some(info) = model.data_types.get(&t) else { return false };
    match &info.kind {
        DataTypeKind::Structure { .. } => !info.is_abstract,
        DataTypeKind::Enumeration { values, .. } => !values.is_empty(),
        DataTypeKind::OptionSet { base, bits } => base.is_unsigned() && !bits.is_empty(),
        DataTypeKind::Simple(_) => true,
        _ => false,
    }
}

/// The Rust type names of a namespace's data types (one scope per namespace, UpperCamel).
fn type_names_of(model: &Model, ns: u16) -> BTreeMap<NodeIx, String> {
    let mut scope: Scope<NodeIx> = Scope::new(Target::Rust, Case::UpperCamel);
    for reserved in ["TypeLoader", "NAMESPACE_URI"] {
        scope.reserve(reserved);
    }
    for (&t, _) in model.data_types.iter() {
        let n = model.node(t);
        if n.id.ns == ns && has_rust_type(model, t) {
            scope.add(n.symbolic_name.as_deref().unwrap_or(&n.browse_name.name), t);
        }
    }
    scope.finish().0
}

impl<'m> Gen<'m> {
    fn new(model: &'m Model, cfg: &'m RustConfig, ns: u16, module: &str) -> Gen<'m> {
        let type_names = type_names_of(model, ns);
        Gen {
            model,
            cfg,
            ns,
            module: module.to_string(),
            diags: Diagnostics::new(),
            type_names,
            foreign_type_names: Default::default(),
            item_names_cache: Default::default(),
            handle_names_cache: Default::default(),
            value_type_cache: Default::default(),
            ns0_types: async_opcua_ns0::TYPES.iter().copied().collect(),
            only: None,
            bodies: Vec::new(),
            built_types: Vec::new(),
        }
    }

    fn uri(&self) -> &str {
        self.model.namespace_uri(self.ns)
    }

    fn header(&self, what: &str) -> String {
        let m = self.model.model_of_namespace(self.ns);
        let file = m.map(|m| self.model.sources.get(m.file).path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default()).unwrap_or_default();
        format!(
            "// {what} of {} {} ({file}).\n// Generated by nodeset-compiler; do not edit. Regenerate with `{}`.\n\n",
            self.uri(),
            m.and_then(|m| m.version.as_deref()).unwrap_or("(no version)"),
            self.cfg.command
        )
    }

    fn file(&self, name: &str, what: &str, tokens: TokenStream) -> OutFile {
        self.print(name, what, &self.parse(name, tokens))
    }

    fn parse(&self, name: &str, tokens: TokenStream) -> syn::File {
        syn::parse2(tokens).unwrap_or_else(|e| panic!("internal error: generated {name} for {} does not parse: {e}", self.uri()))
    }

    fn print(&self, name: &str, what: &str, parsed: &syn::File) -> OutFile {
        let text = prettyplease::unparse(parsed);
        OutFile { path: module_dir(&self.module).join(name), contents: format!("{}{text}", self.header(what)) }
    }

    fn part(&mut self, part: Part) -> OutFile {
        match part {
            Part::Ids => self.ids_file(),
            Part::Types => self.types_file(),
            Part::Nodes => self.nodes_file(),
            Part::Objects => self.objects_file(),
            Part::Module => self.mod_file(),
        }
    }

    fn mod_file(&self) -> OutFile {
        let m = self.model.model_of_namespace(self.ns);
        let uri = lit(self.uri());
        let version = lit(m.and_then(|m| m.version.as_deref()).unwrap_or(""));
        let date = lit(m.and_then(|m| m.publication_date.as_deref()).unwrap_or(""));
        let title = format!(" The OPC UA information model `{}`.", self.uri());
        let mod_rs = quote! {
            #![doc = #title]
            #![allow(clippy::all)]
            pub mod ids;
            pub mod nodes;
            pub mod objects;
            pub mod types;
            /// The namespace URI of this model.
            pub const NAMESPACE_URI: &str = #uri;
            /// The model's version, as its NodeSet2 file declares it.
            pub const VERSION: &str = #version;
            /// The model's publication date, as its NodeSet2 file declares it.
            pub const PUBLICATION_DATE: &str = #date;
            pub use nodes::TABLE;
            pub use types::TypeLoader;
        };
        self.file("mod.rs", "Module", mod_rs)
    }

    // ----- NodeId constants -------------------------------------------------------------------------

    /// The name of a node for its constant: SymbolicName, or the browse path below its type or top object.
    fn path_name(&self, ix: NodeIx) -> String {
        let model = self.model;
        // Encoding objects hang off their DataType by HasEncoding, which is not hierarchical.
        if let Some(enc) = model.ns0(ids::HAS_ENCODING) {
            let n = model.node(ix);
            if n.parent.is_none() {
                if let Some(r) = n.references.iter().find(|r| !r.forward && r.reference_type == enc) {
                    let dt = model.node(r.target);
                    let dt_name = dt.symbolic_name.clone().unwrap_or_else(|| dt.browse_name.name.clone());
                    return format!("{dt_name}_Encoding_{}", n.symbolic_name.clone().unwrap_or_else(|| n.browse_name.name.clone()));
                }
            }
        }
        let mut parts = Vec::new();
        let mut cur = Some(ix);
        let mut guard = 0;
        while let Some(c) = cur {
            let n = self.model.node(c);
            parts.push(n.symbolic_name.clone().unwrap_or_else(|| n.browse_name.name.clone()));
            if n.class.is_type() {
                break;
            }
            guard += 1;
            cur = n.parent.filter(|p| self.model.node(*p).id.ns == self.ns && guard < 12);
        }
        parts.reverse();
        parts.join("_")
    }

    fn ids_file(&mut self) -> OutFile {
        let mut groups: BTreeMap<NodeClass, Vec<NodeIx>> = BTreeMap::new();
        for (i, n) in self.model.nodes.iter().enumerate() {
            if n.id.ns == self.ns {
                groups.entry(n.class).or_default().push(NodeIx(i as u32));
            }
        }
        let runtime = &self.cfg.runtime_path;
        let mut mods = Vec::new();
        let mut bodies: Vec<String> = Vec::new();
        for (class, nodes) in groups {
            let mut scope: Scope<NodeIx> = Scope::new(Target::Rust, Case::ShoutySnake);
            for &ix in &nodes {
                scope.add(&self.path_name(ix), ix);
            }
            let (names, collisions) = scope.finish();
            for c in collisions {
                self.collision_warning(&c, "NodeId constants");
            }
            let mut items: Vec<(NodeIx, String)> = names.into_iter().collect();
            items.sort_by(|a, b| a.1.cmp(&b.1));
            // The constants are written as text (see `consts_text`); the module around them goes through
            // prettyplease with a marker where they belong.
            let marker = ident(&format!("NODESET_COMPILER_CONSTS_{}", bodies.len()));
            bodies.push(self.consts_text(&items));
            let module = ident(&names::sanitize(&format!("{}s", class.name()), Case::Snake, Target::Rust));
            let mdoc = format!(" The {} nodes of this namespace.", class.name());
            mods.push(quote! {
                #[doc = #mdoc]
                pub mod #module {
                    use super::super::NAMESPACE_URI as NS;
                    use #runtime::NsNodeId;
                    #[allow(dead_code)]
                    const fn id(n: u32) -> NsNodeId { NsNodeId::numeric(NS, n) }
                    const #marker: () = ();
                }
            });
        }
        let tokens = quote! {
            //! NodeIds of every node of this namespace, resolved against a namespace table at run time.
            #(#mods)*
        };
        let mut file = self.file("ids.rs", "NodeIds", tokens);
        for (i, body) in bodies.iter().enumerate() {
            let line = format!("    const NODESET_COMPILER_CONSTS_{i}: () = ();\n");
            file.contents = file.contents.replacen(&line, body, 1);
        }
        file
    }

    /// The NodeId constants of one module of `ids.rs`, as prettyplease prints them (checked by the test
    /// `ids_text_is_what_prettyplease_prints`): the doc lines, then `pub const NAME: NsNodeId = value;` on
    /// one line if that fits in prettyplease's margin, else with the call's arguments one per line.
    fn consts_text(&self, items: &[(NodeIx, String)]) -> String {
        use std::fmt::Write as _;
        let mut out = String::with_capacity(items.len() * 160);
        for (ix, name) in items {
            let n = self.model.node(*ix);
            let mut text = format!("`{}` ({}).", n.browse_name.name, n.class.name());
            if let Some(d) = n.doc() {
                text.push_str("\n\n");
                text.push_str(d);
            }
            for l in text.lines() {
                let l = l.trim_end();
                out.push_str(if l.is_empty() { "    ///\n" } else { "    /// " });
                if !l.is_empty() {
                    out.push_str(l);
                    out.push('\n');
                }
            }
            // (the callee, its arguments): `id(5)` or `NsNodeId::string(NS, "x")`.
            let (callee, args): (&str, Vec<String>) = match &n.id.id {
                Identifier::Numeric(v) => ("id", vec![v.to_string()]),
                Identifier::String(s) => ("NsNodeId::string", vec!["NS".to_string(), Literal::string(s).to_string()]),
                other => {
                    let idk = self.id_kind(other, &self.cfg.runtime_path.to_token_stream());
                    let name = ident(name);
                    let item = quote! { pub const #name: NsNodeId = NsNodeId { namespace_uri: NS, id: #idk }; };
                    let file: syn::File = syn::parse2(quote! { mod m { #item } }).expect("internal error: a NodeId constant does not parse");
                    let text = prettyplease::unparse(&file);
                    // `mod m {` ... `}`: the item is indented by four spaces already.
                    let inner: Vec<&str> = text.lines().collect();
                    for l in &inner[1..inner.len() - 1] {
                        out.push_str(l);
                        out.push('\n');
                    }
                    continue;
                }
            };
            let flat = format!("    pub const {name}: NsNodeId = {callee}({});", args.join(", "));
            if flat.len() <= PRETTYPLEASE_MARGIN {
                out.push_str(&flat);
                out.push('\n');
            } else {
                let _ = writeln!(out, "    pub const {name}: NsNodeId = {callee}(");
                for a in &args {
                    let _ = writeln!(out, "        {a},");
                }
                out.push_str("    );\n");
            }
        }
        out
    }

    fn collision_warning(&mut self, c: &names::Collision<NodeIx>, scope: &str) {
        let model = self.model;
        let list: Vec<String> = c
            .members
            .iter()
            .map(|(orig, ix)| format!("`{orig}` ({})", model.display_id(&model.node(*ix).id)))
            .collect();
        let first = c.members.first().map(|(_, ix)| *ix);
        let mut d = Diagnostic::new(
            Code::NameCollision,
            format!("{} map to the Rust name `{}` among the {scope}", list.join(" and "), c.ident),
        )
        .help("the first in sorted order keeps the name, the others get _2, _3, ...; rename one in the nodeset or set a SymbolicName");
        if let Some(ix) = first {
            d = d.at(model.node(ix).browse_name_span);
        }
        self.diags.push(d);
    }

    // ----- data types -------------------------------------------------------------------------------

    /// The Rust type of values of DataType `dt` (a scalar).
    fn rust_type(&self, dt: NodeIx) -> TokenStream {
        let model = self.model;
        let n = model.node(dt);
        let Some(info) = model.data_types.get(&dt) else { return quote! { opcua::types::Variant } };
        if n.id.ns == 0 {
            if let DataTypeKind::Builtin(b) = info.kind {
                return builtin_type(b);
            }
            if let Some(name) = self.ns0_rust_name(dt) {
                let name = ident(&name);
                return quote! { opcua::types::#name };
            }
            return self.encoding_type(dt);
        }
        if !has_rust_type(model, dt) {
            return self.encoding_type(dt);
        }
        let name = if n.id.ns == self.ns {
            self.type_names.get(&dt).cloned()
        } else {
            let mut cache = self.foreign_type_names.borrow_mut();
            cache.entry(n.id.ns).or_insert_with(|| type_names_of(model, n.id.ns)).get(&dt).cloned()
        };
        let Some(name) = name else { return self.encoding_type(dt) };
        let name = ident(&name);
        if n.id.ns == self.ns {
            return quote! { #name };
        }
        let uri = model.namespace_uri(n.id.ns);
        let module = if let Some(p) = self.cfg.extern_paths.get(uri) {
            p.to_token_stream()
        } else if let Some(m) = self.cfg.namespaces.iter().find(|m| m.uri == uri) {
            let m = ident(&m.module);
            quote! { super::super::#m }
        } else {
            return self.encoding_type(dt);
        };
        quote! { #module::types::#name }
    }

    /// The type of a value encoded as the DataType's encoding (when no better Rust type exists).
    fn encoding_type(&self, dt: NodeIx) -> TokenStream {
        let info = &self.model.data_types[&dt];
        match info.encoding {
            BuiltinType::ExtensionObject => quote! { opcua::types::ExtensionObject },
            b => builtin_type(b),
        }
    }

    /// async-opcua's name for an ns0 data type, if it has one.
    fn ns0_rust_name(&self, dt: NodeIx) -> Option<String> {
        let n = self.model.node(dt);
        let name = n.browse_name.name.replace("3D", "ThreeD");
        self.ns0_types.contains(name.as_str()).then_some(name)
    }

    /// The Rust type of field `f` of structure `owner` (boxed where the field's type contains the owner again,
    /// see [`recursion`]).
    fn field_type(&self, owner: NodeIx, f: &crate::model::Field) -> TokenStream {
        if recursion::is_boxed(self.model, owner, f) {
            let scalar = self.rust_type(f.data_type);
            return quote! { Box<#scalar> };
        }
        let info = &self.model.data_types[&f.data_type];
        let scalar = match &info.kind {
            DataTypeKind::Structure { .. } if info.is_abstract || f.allow_sub_types => {
                quote! { opcua::types::ExtensionObject }
            }
            _ => self.rust_type(f.data_type),
        };
        if f.value_rank >= 0 || f.value_rank == -2 || f.value_rank == -3 {
            quote! { Option<Vec<#scalar>> }
        } else {
            scalar
        }
    }

    fn types_file(&mut self) -> OutFile {
        let model = self.model;
        let mut items = Vec::new();
        let mut loader = Vec::new();
        let runtime = &self.cfg.runtime_path;
        let types: Vec<(NodeIx, String)> = self.type_names.iter().map(|(k, v)| (*k, v.clone())).collect();
        for (t, name) in types {
            let n = model.node(t);
            let info = &model.data_types[&t];
            let name_id = ident(&name);
            let mut text = format!("`{}` ({}).", n.browse_name.name, model.display_id(&n.id));
            if let Some(d) = n.doc() {
                text.push_str("\n\n");
                text.push_str(d);
            }
            let docs = doc(&text);
            match &info.kind {
                DataTypeKind::Simple(b) => {
                    let ty = builtin_type(*b);
                    items.push(quote! { #docs pub type #name_id = #ty; });
                }
                DataTypeKind::Enumeration { values, .. } => {
                    let mut scope: Scope<usize> = Scope::new(Target::Rust, Case::UpperCamel);
                    for (i, v) in values.iter().enumerate() {
                        scope.add(&v.name, i);
                    }
                    let (vnames, collisions) = scope.finish();
                    for c in collisions {
                        let members: Vec<(String, NodeIx)> = c.members.iter().map(|(o, _)| (o.clone(), t)).collect();
                        self.collision_warning(&names::Collision { ident: c.ident.clone(), members }, "enumeration values");
                    }
                    // The default is the value 0 if there is one, else the first.
                    let default = values.iter().position(|v| v.value == 0).unwrap_or(0);
                    let variants: Vec<TokenStream> = values
                        .iter()
                        .enumerate()
                        .filter_map(|(i, v)| {
                            let vn = ident(&vnames[&i]);
                            let Ok(value) = i32::try_from(v.value) else {
                                return None;
                            };
                            let value = Literal::i32_unsuffixed(value);
                            let d = doc(&match &v.description {
                                Some(desc) => format!("`{}` = {}: {desc}", v.name, v.value),
                                None => format!("`{}` = {}", v.name, v.value),
                            });
                            let def = (i == default).then(|| quote! { #[opcua(default)] });
                            Some(quote! { #d #def #vn = #value })
                        })
                        .collect();
                    items.push(quote! {
                        #docs
                        #[opcua::types::ua_encodable]
                        #[derive(Debug, Copy, Clone, PartialEq, Eq, Hash)]
                        #[repr(i32)]
                        pub enum #name_id { #(#variants),* }
                        #runtime::typed::ua_enum!(#name_id);
                    });
                }
                DataTypeKind::OptionSet { base, bits } => {
                    let width = builtin_type(*base);
                    let variant = ident(match base {
                        BuiltinType::Byte => "Byte",
                        BuiltinType::UInt16 => "UInt16",
                        BuiltinType::UInt32 => "UInt32",
                        _ => "UInt64",
                    });
                    let mut scope: Scope<usize> = Scope::new(Target::Rust, Case::ShoutySnake);
                    for (i, v) in bits.iter().enumerate() {
                        scope.add(&v.name, i);
                    }
                    let (bnames, _) = scope.finish();
                    let max_bit = match base {
                        BuiltinType::Byte => 8,
                        BuiltinType::UInt16 => 16,
                        BuiltinType::UInt32 => 32,
                        _ => 64,
                    };
                    let flags: Vec<TokenStream> = bits
                        .iter()
                        .enumerate()
                        .filter(|(_, v)| v.value >= 0 && v.value < max_bit)
                        .map(|(i, v)| {
                            let bn = ident(&bnames[&i]);
                            let bit = Literal::u32_unsuffixed(v.value as u32);
                            let d = doc(&format!("`{}`: bit {}{}", v.name, v.value, v.description.as_deref().map(|d| format!(". {d}")).unwrap_or_default()));
                            quote! { #d const #bn = 1 << #bit; }
                        })
                        .collect();
                    items.push(quote! {
                        bitflags::bitflags! {
                            #docs
                            #[derive(Debug, Copy, Clone, PartialEq, Eq, Hash, Default)]
                            pub struct #name_id: #width { #(#flags)* }
                        }
                        impl opcua::types::UaNullable for #name_id {
                            fn is_ua_null(&self) -> bool { self.is_empty() }
                        }
                        opcua::types::impl_encoded_as!(
                            #name_id,
                            |v| Ok(#name_id::from_bits_truncate(v)),
                            |v: &#name_id| Ok::<_, opcua::types::Error>(v.bits()),
                            |v: &#name_id| opcua::types::SimpleBinaryEncodable::byte_len(&v.bits())
                        );
                        impl opcua::types::IntoVariant for #name_id {
                            fn into_variant(self) -> opcua::types::Variant {
                                opcua::types::IntoVariant::into_variant(self.bits())
                            }
                        }
                        #runtime::typed::ua_option_set!(#name_id, #width, #variant);
                        #[cfg(feature = "xml")]
                        impl opcua::types::xml::XmlType for #name_id {
                            const TAG: &'static str = stringify!(#name_id);
                        }
                    });
                }
                DataTypeKind::Structure { kind, fields, .. } => {
                    let mut scope: Scope<usize> = Scope::new(
                        Target::Rust,
                        if *kind == StructureKind::Union { Case::UpperCamel } else { Case::Snake },
                    );
                    if *kind == StructureKind::Union {
                        scope.reserve("Null");
                    }
                    for (i, f) in fields.iter().enumerate() {
                        scope.add(f.symbolic_name.as_deref().unwrap_or(&f.name), i);
                    }
                    let (fnames, collisions) = scope.finish();
                    for c in collisions {
                        let members: Vec<(String, NodeIx)> = c.members.iter().map(|(o, _)| (o.clone(), t)).collect();
                        self.collision_warning(&names::Collision { ident: c.ident.clone(), members }, "structure fields");
                    }
                    for f in fields {
                        if f.value_rank > 1 {
                            self.diags.push(
                                Diagnostic::new(
                                    Code::UnsupportedFeature,
                                    format!("field `{}` of `{}` has ValueRank {}; it is generated as a one-dimensional array", f.name, n.browse_name.name, f.value_rank),
                                )
                                .at(f.span)
                                .help("the binary encoding of multi-dimensional structure fields is not supported by async-opcua's derive"),
                            );
                        }
                    }
                    let body = if *kind == StructureKind::Union {
                        let variants: Vec<TokenStream> = fields
                            .iter()
                            .enumerate()
                            .map(|(i, f)| {
                                let vn = ident(&fnames[&i]);
                                let ty = self.field_type(t, f);
                                let d = doc(&field_doc(f));
                                quote! { #d #vn(#ty) }
                            })
                            .collect();
                        quote! {
                            #docs
                            #[opcua::types::ua_encodable]
                            #[derive(Debug, Clone, PartialEq)]
                            pub enum #name_id {
                                /// No field is set (SwitchField 0).
                                Null,
                                #(#variants),*
                            }
                            impl Default for #name_id {
                                fn default() -> Self { Self::Null }
                            }
                        }
                    } else {
                        let fs: Vec<TokenStream> = fields
                            .iter()
                            .enumerate()
                            .map(|(i, f)| {
                                let fname = ident(&fnames[&i]);
                                let ty = self.field_type(t, f);
                                let d = doc(&field_doc(f));
                                let original = lit(&f.name);
                                if f.is_optional {
                                    quote! { #d #[opcua(optional, rename = #original)] pub #fname: Option<#ty> }
                                } else {
                                    quote! { #d #[opcua(rename = #original)] pub #fname: #ty }
                                }
                            })
                            .collect();
                        quote! {
                            #docs
                            #[opcua::types::ua_encodable]
                            #[derive(Debug, Clone, PartialEq, Default)]
                            pub struct #name_id { #(#fs),* }
                        }
                    };
                    items.push(body);
                    items.push(quote! { #runtime::typed::ua_struct!(#name_id); });
                    if recursion::is_on_cycle(model, t) {
                        items.push(boxed_encoding(&name_id));
                    }
                    // Encoding ids and the type loader.
                    let enc = |which: &str| info.encodings.iter().find(|(n, _)| n == which).map(|(_, ix)| *ix);
                    let binary = enc("Default Binary");
                    let dt_num = numeric(model, t);
                    let uri = quote! { super::NAMESPACE_URI };
                    let id_expr = |ix: Option<NodeIx>| -> TokenStream {
                        match ix.and_then(|ix| numeric(model, ix)).or(dt_num) {
                            Some(v) => quote! { opcua::types::ExpandedNodeId::from((#v, #uri)) },
                            None => quote! { opcua::types::ExpandedNodeId::null() },
                        }
                    };
                    let (bin, json, xml, dtid) =
                        (id_expr(binary), id_expr(enc("Default JSON")), id_expr(enc("Default XML")), id_expr(Some(t)));
                    items.push(quote! {
                        impl opcua::types::ExpandedMessageInfo for #name_id {
                            fn full_type_id(&self) -> opcua::types::ExpandedNodeId { #bin }
                            fn full_json_type_id(&self) -> opcua::types::ExpandedNodeId { #json }
                            fn full_xml_type_id(&self) -> opcua::types::ExpandedNodeId { #xml }
                            fn full_data_type_id(&self) -> opcua::types::ExpandedNodeId { #dtid }
                        }
                    });
                    match (dt_num, binary.and_then(|b| numeric(model, b))) {
                        (Some(d), Some(b)) => loader.push(quote! {
                            inst.add_binary_type(#d, #b, opcua::types::binary_decode_to_enc::<#name_id>);
                        }),
                        _ => self.diags.push(
                            Diagnostic::new(
                                Code::UnsupportedFeature,
                                format!("structure `{}` has no numeric Default Binary encoding; servers and clients cannot decode it from the wire", n.browse_name.name),
                            )
                            .at(n.browse_name_span)
                            .help("add a `Default Binary` encoding object with a numeric NodeId (HasEncoding, TypeDefinition DataTypeEncodingType)"),
                        ),
                    }
                }
                _ => {}
            }
        }
        // async-opcua's `ua_encodable` and `impl_encoded_as!` derive the JSON and XML encodings under
        // `cfg(feature = "json")` and `cfg(feature = "xml")`, tested in the crate that holds this code: that
        // crate declares both features, forwarded to async-opcua (README, "Your own crate"). An
        // `allow(unexpected_cfgs)` here would not help: rustc reports cfgs that come out of an attribute macro
        // at the crate's level, not the module's.
        let tokens = quote! {
            //! Data types of this namespace, encodable with async-opcua.
            #(#items)*

            static TYPES: std::sync::LazyLock<opcua::types::TypeLoaderInstance> = std::sync::LazyLock::new(|| {
                #[allow(unused_mut)]
                let mut inst = opcua::types::TypeLoaderInstance::new();
                #(#loader)*
                inst
            });

            /// Decodes this namespace's structures from the wire: register it with the server
            /// (`ServerBuilder::with_type_loader`) and clients (`Session::add_type_loader`).
            pub struct TypeLoader;

            impl opcua::types::StaticTypeLoader for TypeLoader {
                fn instance() -> &'static opcua::types::TypeLoaderInstance { &TYPES }
                fn namespace() -> &'static str { super::NAMESPACE_URI }
            }
        };
        self.file("types.rs", "Data types", tokens)
    }

    // ----- the address space table -----------------------------------------------------------------

    /// An `IdKind` value, the type named through the runtime path `rt`.
    fn id_kind(&self, id: &Identifier, rt: &TokenStream) -> TokenStream {
        match id {
            Identifier::Numeric(v) => {
                let v = Literal::u32_unsuffixed(*v);
                quote! { #rt::IdKind::Numeric(#v) }
            }
            Identifier::String(s) => {
                let s = lit(s);
                quote! { #rt::IdKind::String(#s) }
            }
            Identifier::Guid(g) => {
                let bytes = g.iter().map(|b| Literal::u8_unsuffixed(*b));
                quote! { #rt::IdKind::Guid([#(#bytes),*]) }
            }
            Identifier::Opaque(b) => {
                let bytes = proc_macro2::Literal::byte_string(b);
                quote! { #rt::IdKind::Opaque(#bytes) }
            }
        }
    }
}

/// The binary encoding of `Box<T>` for a structure `T` on a cycle of fields (async-opcua implements JSON and
/// XML for boxes, not binary): the encoding of the value itself.
fn boxed_encoding(name: &Ident) -> TokenStream {
    quote! {
        impl opcua::types::BinaryEncodable for Box<#name> {
            fn byte_len(&self, ctx: &opcua::types::Context<'_>) -> usize {
                opcua::types::BinaryEncodable::byte_len(&**self, ctx)
            }
            fn encode<S: std::io::Write + ?Sized>(&self, stream: &mut S, ctx: &opcua::types::Context<'_>) -> opcua::types::EncodingResult<()> {
                opcua::types::BinaryEncodable::encode(&**self, stream, ctx)
            }
        }
        impl opcua::types::BinaryDecodable for Box<#name> {
            fn decode<S: std::io::Read + ?Sized>(stream: &mut S, ctx: &opcua::types::Context<'_>) -> opcua::types::EncodingResult<Self> {
                <#name as opcua::types::BinaryDecodable>::decode(stream, ctx).map(Box::new)
            }
        }
    }
}

fn numeric(model: &Model, ix: NodeIx) -> Option<u32> {
    match model.node(ix).id.id {
        Identifier::Numeric(v) => Some(v),
        _ => None,
    }
}

fn field_doc(f: &crate::model::Field) -> String {
    let mut s = format!("`{}`", f.name);
    if f.value_rank >= 1 {
        s.push_str(&format!(" (ValueRank {})", f.value_rank));
    }
    if let Some(d) = &f.description {
        s.push_str(": ");
        s.push_str(d);
    }
    s
}

fn builtin_type(b: BuiltinType) -> TokenStream {
    match b {
        BuiltinType::Boolean => quote! { bool },
        BuiltinType::SByte => quote! { i8 },
        BuiltinType::Byte => quote! { u8 },
        BuiltinType::Int16 => quote! { i16 },
        BuiltinType::UInt16 => quote! { u16 },
        BuiltinType::Int32 => quote! { i32 },
        BuiltinType::UInt32 => quote! { u32 },
        BuiltinType::Int64 => quote! { i64 },
        BuiltinType::UInt64 => quote! { u64 },
        BuiltinType::Float => quote! { f32 },
        BuiltinType::Double => quote! { f64 },
        BuiltinType::String => quote! { opcua::types::UAString },
        BuiltinType::DateTime => quote! { opcua::types::DateTime },
        BuiltinType::Guid => quote! { opcua::types::Guid },
        BuiltinType::ByteString => quote! { opcua::types::ByteString },
        BuiltinType::XmlElement => quote! { opcua::types::XmlElement },
        BuiltinType::NodeId => quote! { opcua::types::NodeId },
        BuiltinType::ExpandedNodeId => quote! { opcua::types::ExpandedNodeId },
        BuiltinType::StatusCode => quote! { opcua::types::StatusCode },
        BuiltinType::QualifiedName => quote! { opcua::types::QualifiedName },
        BuiltinType::LocalizedText => quote! { opcua::types::LocalizedText },
        BuiltinType::ExtensionObject => quote! { opcua::types::ExtensionObject },
        BuiltinType::DataValue => quote! { opcua::types::DataValue },
        BuiltinType::Variant => quote! { opcua::types::Variant },
        BuiltinType::DiagnosticInfo => quote! { opcua::types::DiagnosticInfo },
    }
}

/// The files at the top of a folder that holds the namespaces of `cfg`, one module each: `mod.rs`, which declares
/// them and registers them with a server in `cfg`'s order (dependencies first), and `rustfmt.toml`. The models of
/// `model` that `cfg` maps to modules generated elsewhere are registered first, in the model's order, so that
/// `register` alone serves everything the generated namespaces need (a server adds each table once).
pub fn top_files(model: &Model, cfg: &RustConfig) -> [OutFile; 2] {
    let modules: Vec<(String, String)> = cfg.namespaces.iter().map(|n| (n.module.clone(), n.uri.clone())).collect();
    let mapped: Vec<(&str, &RustPath)> = model
        .namespaces
        .iter()
        .filter_map(|uri| cfg.extern_paths.get_key_value(uri.as_str()))
        .filter(|(uri, _)| !modules.iter().any(|(_, u)| u == *uri))
        .map(|(uri, path)| (uri.as_str(), path))
        .collect();
    [models_mod(&modules, &mapped, &cfg.runtime_path, &cfg.command), rustfmt_toml()]
}

/// The `mod.rs` of a folder holding several generated namespaces (`modules`: module name and namespace URI,
/// dependencies first), with `register`, which adds the `mapped` namespaces (URI and module path) and then all
/// of the folder's to a server configuration in that order.
fn models_mod(modules: &[(String, String)], mapped: &[(&str, &RustPath)], runtime: &RustPath, command: &str) -> OutFile {
    let items: Vec<TokenStream> = modules
        .iter()
        .map(|(m, uri)| {
            let m = ident(m);
            let d = format!(" `{uri}`");
            quote! { #[doc = #d] pub mod #m; }
        })
        .collect();
    let externs = mapped.iter().map(|(_, path)| quote! { .table(&#path::TABLE).type_loader(#path::TypeLoader) });
    let adds = modules.iter().map(|(m, _)| {
        let m = ident(m);
        quote! { .table(&#m::TABLE).type_loader(#m::TypeLoader) }
    });
    let doc = if mapped.is_empty() {
        " Adds the address space and the type loader of every namespace above to a server, dependencies\n first.".to_string()
    } else {
        let names: Vec<String> = mapped.iter().map(|(uri, path)| format!("`{}` ({uri})", path.as_str())).collect();
        format!(
            " Adds the address space and the type loader of every namespace above to a server, dependencies\n first, after those of the namespaces they require from elsewhere: {}. A server adds each table\n once, so registering those again (say with their crate's own `register`) changes nothing.",
            names.join(", ")
        )
    };
    // One `///` line each, as written by hand.
    let doc_lines = doc.split('\n');
    let register = quote! {
        #(#[doc = #doc_lines])*
        pub fn register(config: #runtime::server::ServerConfig) -> #runtime::server::ServerConfig {
            config #(#externs)* #(#adds)*
        }
    };
    let file: syn::File = syn::parse2(quote! { #(#items)* #register }).expect("internal error: models mod.rs");
    OutFile {
        path: PathBuf::from("mod.rs"),
        contents: format!(
            "// Generated by nodeset-compiler; do not edit. Regenerate with `{command}`.\n\n{}",
            prettyplease::unparse(&file)
        ),
    }
}

/// The rustfmt configuration that keeps `cargo fmt` off generated files.
fn rustfmt_toml() -> OutFile {
    OutFile {
        path: PathBuf::from("rustfmt.toml"),
        contents: "# Generated code is formatted by nodeset-compiler (prettyplease); rustfmt leaves it alone.\ndisable_all_formatting = true\n".into(),
    }
}

/// Joins a generated module tree (the files of [`crate::run_rust`]: `mod.rs` with `register` at the top, a
/// folder per namespace) into one text of inline modules (`pub mod robotics { pub mod ids { ... } ... }`), for
/// `include!` from `OUT_DIR` (an included file cannot declare out-of-line modules). Each `pub mod NAME;` line
/// of a `mod.rs` is replaced by the module's file, found where rustc would look for it ([`module_dir`]); the
/// rest of the text is the tree's, so the build script's output and the `rust` command's say the same.
pub fn inline(files: &[OutFile]) -> String {
    let by_path: BTreeMap<&std::path::Path, &str> = files.iter().map(|f| (f.path.as_path(), f.contents.as_str())).collect();
    let mut out = String::from("// Generated by nodeset-compiler from a build script; do not edit.\n\n");
    inline_file(&by_path, std::path::Path::new("mod.rs"), std::path::Path::new(""), &mut out);
    out
}

/// Appends the file `path` of the tree, its out-of-line modules (children in `dir`) made inline.
fn inline_file(files: &BTreeMap<&std::path::Path, &str>, path: &std::path::Path, dir: &std::path::Path, out: &mut String) {
    let text = files.get(path).unwrap_or_else(|| panic!("internal error: the generated tree has no {}", path.display()));
    // Only a `mod.rs` declares modules; other files (the node table's rows among them) are copied as they are.
    let declares = path.file_name().is_some_and(|n| n == "mod.rs");
    for line in text.lines() {
        let module = line.trim().strip_prefix("pub mod ").and_then(|r| r.strip_suffix(';')).filter(|_| declares);
        match module {
            Some(name) => {
                let sub = dir.join(module_dir(name));
                let file = [sub.join("mod.rs"), sub.with_extension("rs")]
                    .into_iter()
                    .find(|p| files.contains_key(p.as_path()))
                    .unwrap_or_else(|| panic!("internal error: the generated tree declares `{name}` in {} but has no file for it", path.display()));
                out.push_str(&format!("pub mod {name} {{\n"));
                inline_file(files, &file, &sub, out);
                out.push_str("}\n");
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
}
