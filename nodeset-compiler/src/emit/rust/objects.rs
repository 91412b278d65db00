//! `objects.rs`: typed handles of a namespace's ObjectTypes and VariableTypes, and member markers.
//!
//! For every ObjectType a struct whose fields are typed handles of its members (`Variable<T>` with `T` from
//! the DataType and ValueRank, `Method<(inputs), (outputs)>` from the Argument definitions, nested structs
//! for object members whose declaration adds children, `Box<_>` around the handle of a member typed by another
//! ObjectType (also when its declaration only repeats that type's members: one struct, not a copy per use),
//! `Option<_>` for Optional members, `Placeholders<_>` for `<Placeholder>` members); the members of the nearest supertype that has a handle of its own are in
//! its `base` field, reached through `Deref`, so a subtype's handle reaches what it inherits. Supertypes
//! without a handle (ns0's) have their members folded into the first generated subtype.
//!
//! Each handle's `Handle::build` is `#[inline]`: like a generic function, it is then compiled in the crate
//! that binds handles, for the types that crate binds (and their members), not for every type in the crate
//! that declares them. A server binding two ObjectTypes of Robotics compiles their builders, not the other
//! 150; the generated crate's own build is about a tenth shorter.
//!
//! A VariableType's handle has the variable itself in `node`, a `Variable<T>` with `T` from the type's
//! DataType and ValueRank (-1 when the nodeset leaves it out, as the NodeSet schema and the node tables
//! have it; `Variant` for an abstract DataType such as `Number`), and its child variables as fields; the
//! same `T` is its `VariableType::Value`, which typed clients read (`Remote::read_value`).
//!
//! `members::<Type>` (for ObjectTypes and VariableTypes alike) holds one marker constant
//! (`runtime::typed::VariableMember<Scalar>`) per variable reachable from an instance without crossing a
//! placeholder, named from the browse path
//! (`ParameterSet__ActualPosition`), with the DataType's Rust scalar type, ValueRank, whether it is mandatory,
//! has a default, is writable; plus `REQUIRED`, the mandatory variables without a default value.
//! `nodeset-derive` checks bindings against these at compile time (it never reads XML). Methods reachable
//! the same way get a `runtime::typed::MethodMember<Inputs, Outputs>` each (`Lock__InitLock`), with the
//! tuples of their Argument definitions, which typed clients call (`Remote::call`). Variables and methods
//! share one name scope: a path whose marker name would be `REQUIRED` gets no marker, like a name that two
//! paths map to.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::rc::Rc;

use proc_macro2::{Literal, TokenStream};
use quote::{quote, ToTokens};

use super::programs::Item;
use super::{built, doc, ident, lit, Gen};
use crate::model::{DataTypeKind, Model, ModellingRule, NodeIx};
use crate::nodeid::Identifier;
use crate::names::{Case, Scope, Target};
use crate::raw::NodeClass;
use crate::value::BuiltinType;
use crate::write::OutFile;

/// ns0 structures for which the runtime implements `UaValue` (async-opcua's own types); other ns0
/// structures are handled as ExtensionObjects.
const NS0_VALUE_STRUCTS: &[&str] = &[
    "Argument", "AxisInformation", "BuildInfo", "ComplexNumberType", "DoubleComplexNumberType", "EUInformation",
    "EnumValueType", "KeyValuePair", "Range", "RationalNumber", "ServerStatusDataType", "ThreeDCartesianCoordinates",
    "ThreeDFrame", "ThreeDOrientation", "ThreeDVector", "TimeZoneDataType", "XVType",
];

/// How deep markers follow object members.
const MAX_DEPTH: usize = 6;

/// How deep nested handle structs go (below, members are typed by their TypeDefinition's handle).
const NESTED_DEPTH: usize = 2;

/// The marker name of a browse path: the rule `nodeset-derive` uses too, defined once in `nodeset-markers`.
pub use nodeset_markers::marker_name;

/// A BrowseName as a segment of a marker's path text (`runtime::typed::MemberPath`): `/` and `\` get a
/// `\` before them.
fn escape_segment(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for c in name.chars() {
        if c == '/' || c == '\\' {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

/// One member as a field of a handle struct.
struct Field {
    name: String,
    /// Built directly (see `built`), from the value types' syn trees.
    ty: syn::Type,
    /// `b.build_child(id, NS[k], "Name")` and the like, built directly (see `built`).
    bind: syn::Expr,
    doc: String,
}

/// One member marker of a type: a variable or method reachable from an instance, not crossing placeholders.
struct Marker {
    /// The marker's name (`ParameterSet__ActualPosition`).
    name: String,
    /// BrowseNames along the path.
    path: Vec<String>,
    /// (model namespace, name) per segment.
    qpath: Vec<(u16, String)>,
    node: NodeIx,
    mandatory: bool,
    /// A method's input and output tuples, as text seen from `members::<Owner>`; `None` for a variable.
    method: Option<(String, String)>,
}

impl Marker {
    /// What the marker's constant says: two markers with the same key are the same constant, whichever
    /// type declares them (an override that changes nothing the marker holds keeps its supertype's).
    fn key(&self, model: &Model) -> impl PartialEq {
        let n = model.node(self.node);
        (
            self.qpath.clone(),
            n.attrs.data_type,
            n.attrs.value_rank.unwrap_or(-1),
            self.mandatory,
            n.value.is_some(),
            n.attrs.access_level.unwrap_or(1) & 2 != 0,
            self.method.clone(),
        )
    }
}

impl Gen<'_> {
    /// Whether a type gets a handle struct.
    pub(super) fn has_handle(&self, t: NodeIx) -> bool {
        matches!(self.model.node(t).class, NodeClass::ObjectType | NodeClass::VariableType)
    }

    /// Names of the items of a namespace's `objects.rs` in one scope: the handle structs of its types and
    /// the parameter structs of its program types.
    /// Computed once per namespace and generator (every handle path into another namespace needs them).
    pub(super) fn object_item_names(&self, ns: u16) -> Rc<BTreeMap<(NodeIx, Item), String>> {
        if let Some(names) = self.item_names_cache.borrow().get(&ns) {
            return names.clone();
        }
        let mut scope: Scope<(NodeIx, Item)> = Scope::new(Target::Rust, Case::UpperCamel);
        for r in ["NS", "Members"] {
            scope.reserve(r);
        }
        for (i, n) in self.model.nodes.iter().enumerate() {
            let ix = NodeIx(i as u32);
            if n.id.ns == ns && self.has_handle(ix) {
                scope.add(n.symbolic_name.as_deref().unwrap_or(&n.browse_name.name), (ix, Item::Handle));
            }
        }
        self.add_parameter_names(ns, &mut scope);
        let names = Rc::new(scope.finish().0);
        self.item_names_cache.borrow_mut().insert(ns, names.clone());
        names
    }

    /// Handle struct names of a namespace's types (cached like [`Self::object_item_names`]).
    pub(super) fn handle_names(&self, ns: u16) -> Rc<BTreeMap<NodeIx, String>> {
        if let Some(names) = self.handle_names_cache.borrow().get(&ns) {
            return names.clone();
        }
        let names: Rc<BTreeMap<NodeIx, String>> = Rc::new(
            self.object_item_names(ns)
                .iter()
                .filter(|((_, item), _)| *item == Item::Handle)
                .map(|((t, _), n)| (*t, n.clone()))
                .collect(),
        );
        self.handle_names_cache.borrow_mut().insert(ns, names.clone());
        names
    }

    /// The Rust path of the module of another generated namespace, if this run reaches it.
    pub(super) fn module_path(&self, ns: u16) -> Option<TokenStream> {
        let uri = self.model.namespace_uri(ns);
        if let Some(p) = self.cfg.extern_paths.get(uri) {
            Some(p.to_token_stream())
        } else {
            let m = self.cfg.namespaces.iter().find(|m| m.uri == uri)?;
            let m = ident(&m.module);
            Some(quote! { super::super::#m })
        }
    }

    /// The Rust path of a type's handle, if it has one reachable from this module.
    pub(super) fn handle_path(&self, t: NodeIx, names: &BTreeMap<NodeIx, String>) -> Option<syn::Path> {
        let n = self.model.node(t);
        if n.id.ns == self.ns {
            let name = ident(names.get(&t)?);
            return Some(syn::Path::from(name));
        }
        if n.id.ns == 0 || !self.has_handle(t) {
            return None;
        }
        let module = self.module_path(n.id.ns)?;
        let name = ident(self.handle_names(n.id.ns).get(&t)?);
        Some(syn::parse_quote! { #module::objects::#name })
    }

    /// The Rust value type of a DataType and ValueRank, as typed handles use it (memoized: thousands of
    /// members share a few dozen types).
    pub(super) fn value_type(&self, dt: Option<NodeIx>, value_rank: i32) -> syn::Type {
        if let Some(t) = self.value_type_cache.borrow().get(&(dt, value_rank)) {
            return t.clone();
        }
        let tokens = self.compute_value_type(dt, value_rank);
        let mut t: syn::Type = syn::parse_quote! { #tokens };
        // objects.rs names async-opcua's types through its `ua` alias.
        each_path(&mut t, &mut alias_ua);
        self.value_type_cache.borrow_mut().insert((dt, value_rank), t.clone());
        t
    }

    fn compute_value_type(&self, dt: Option<NodeIx>, value_rank: i32) -> TokenStream {
        let variant = quote! { opcua::types::Variant };
        let Some(dt) = dt else { return variant };
        let scalar = self.scalar_value_type(dt);
        if is_variant(&scalar) {
            return variant;
        }
        match value_rank {
            -1 => scalar,
            0 | 1 => quote! { Vec<#scalar> },
            _ => variant,
        }
    }

    fn scalar_value_type(&self, dt: NodeIx) -> TokenStream {
        let model = self.model;
        let Some(info) = model.data_types.get(&dt) else { return quote! { opcua::types::Variant } };
        let n = model.node(dt);
        let t = match &info.kind {
            DataTypeKind::Builtin(BuiltinType::String) => quote! { String },
            DataTypeKind::Builtin(BuiltinType::Variant | BuiltinType::DataValue | BuiltinType::DiagnosticInfo)
            | DataTypeKind::AbstractBuiltin => quote! { opcua::types::Variant },
            DataTypeKind::Builtin(b) => super::builtin_type(*b),
            DataTypeKind::Simple(BuiltinType::String) if n.id.ns == 0 => quote! { String },
            _ if n.id.ns == 0 => match &info.kind {
                DataTypeKind::Simple(b) => super::builtin_type(*b),
                DataTypeKind::Enumeration { .. } => quote! { i32 },
                DataTypeKind::OptionSet { base, .. } => super::builtin_type(*base),
                DataTypeKind::Structure { .. } => {
                    let name = n.browse_name.name.replace("3D", "ThreeD");
                    if NS0_VALUE_STRUCTS.contains(&name.as_str()) && !info.is_abstract {
                        let name = ident(&name);
                        quote! { opcua::types::#name }
                    } else {
                        quote! { opcua::types::ExtensionObject }
                    }
                }
                _ => quote! { opcua::types::Variant },
            },
            DataTypeKind::Structure { .. } if info.is_abstract => quote! { opcua::types::ExtensionObject },
            DataTypeKind::Structure { .. } | DataTypeKind::Enumeration { .. } | DataTypeKind::OptionSet { .. } => {
                let t = self.rust_type(dt);
                if is_variant(&t) { quote! { opcua::types::Variant } } else { t }
            }
            DataTypeKind::Simple(_) => self.rust_type(dt),
        };
        // Types of this namespace are named bare in types.rs; objects.rs reaches them through `super`.
        if n.id.ns == self.ns && syn::parse2::<syn::Ident>(t.clone()).is_ok() {
            return quote! { super::types::#t };
        }
        t
    }

    /// The modelling rule of a member, if it is instantiated at all.
    pub(super) fn rule(&self, node: NodeIx) -> Option<ModellingRule> {
        match self.model.node(node).modelling_rule? {
            r @ (ModellingRule::Mandatory
            | ModellingRule::Optional
            | ModellingRule::MandatoryPlaceholder
            | ModellingRule::OptionalPlaceholder) => Some(r),
            _ => None,
        }
    }

    /// The members of a declaration (or of an instance): `instance_members` with a rule.
    pub(super) fn decl_members(&self, decl: NodeIx) -> Vec<(NodeIx, NodeIx)> {
        self.model
            .instance_members(decl)
            .into_iter()
            .filter(|m| self.rule(m.node).is_some())
            .map(|m| (m.node, m.reference_type))
            .collect()
    }

    /// Whether a declaration has children of its own with a rule (then it gets a nested handle struct).
    fn adds_children(&self, decl: NodeIx) -> bool {
        self.model.children(decl).any(|(_, c)| self.rule(c).is_some())
    }

    /// Whether an object declaration with children of its own only repeats the members of its
    /// TypeDefinition, which has a handle: then that handle is the member's type, and no nested struct is
    /// generated for it (DI's `PendingVersion` and `FallbackVersion` are `SoftwareVersionType`s; each skill
    /// of a SkillSet repeats its skill type).
    fn repeats_its_type(&self, decl: NodeIx, names: &BTreeMap<NodeIx, String>) -> bool {
        let Some(td) = self.model.node(decl).type_definition else { return false };
        if self.handle_path(td, names).is_none() {
            return false;
        }
        let (mut a, mut b) = (String::new(), String::new());
        self.members_signature(&self.decl_members(decl), 0, &mut a);
        self.members_signature(&self.type_members(td), 0, &mut b);
        a == b
    }

    /// The members of a type, inherited ones included, that instances get (those with a rule).
    fn type_members(&self, t: NodeIx) -> Vec<(NodeIx, NodeIx)> {
        self.model
            .members
            .get(&t)
            .map(|ms| ms.iter().filter(|m| self.rule(m.node).is_some()).map(|m| (m.node, m.reference_type)).collect())
            .unwrap_or_default()
    }

    /// What a list of members gives a handle, as text: per member in BrowseName order its name, class and
    /// rule, the value or method type, and for an object its TypeDefinition and, down to [`MAX_DEPTH`],
    /// its own members. Equal signatures give handles with the same fields at every level.
    fn members_signature(&self, members: &[(NodeIx, NodeIx)], depth: usize, out: &mut String) {
        let model = self.model;
        let mut ordered: Vec<NodeIx> = members.iter().map(|&(m, _)| m).filter(|&m| self.rule(m).is_some()).collect();
        ordered.sort_by(|a, b| model.node(*a).browse_name.cmp(&model.node(*b).browse_name));
        out.push('{');
        for m in ordered {
            let n = model.node(m);
            let rule = self.rule(m).map_or("", |r| r.name());
            let _ = write!(out, "{}:{} {:?} {rule} ", n.browse_name.ns, n.browse_name.name, n.class);
            match n.class {
                NodeClass::Variable => {
                    out.push_str(&type_text(&self.value_type(n.attrs.data_type, n.attrs.value_rank.unwrap_or(-1))));
                }
                NodeClass::Method => {
                    let _ = write!(out, "{}", self.method_type(m));
                }
                NodeClass::Object => {
                    let _ = write!(out, "{:?}", n.type_definition);
                    if depth < MAX_DEPTH && !self.rule(m).is_some_and(|r| r.is_placeholder()) {
                        self.members_signature(&self.decl_members(m), depth + 1, out);
                    }
                }
                _ => {}
            }
            out.push(';');
        }
        out.push('}');
    }

    fn method_type(&self, decl: NodeIx) -> TokenStream {
        let (i, o) = self.method_io(decl);
        quote! { t::Method<#i, #o> }
    }

    /// A method's input and output types: the tuples of its Argument definitions (`(String,)`, `()`), or
    /// `Vec<ua::Variant>` beyond twelve arguments.
    fn method_io(&self, decl: NodeIx) -> (syn::Type, syn::Type) {
        let info = self.model.methods.get(&decl).cloned().unwrap_or_default();
        // Built, not parsed (see `built`).
        let tuple = |args: &[crate::model::Argument]| -> syn::Type {
            if args.len() > 12 {
                return built::generic(&["Vec"], vec![built::generic(&["ua", "Variant"], Vec::new())]);
            }
            built::tuple(args.iter().map(|a| self.value_type(a.data_type, a.value_rank)).collect())
        };
        (tuple(&info.inputs), tuple(&info.outputs))
    }

    /// A method's input and output types as the members macro names them, from `members::<Owner>`.
    fn method_io_text(&self, decl: NodeIx) -> (String, String) {
        let (i, o) = self.method_io(decl);
        (type_text(&from_members_module(i)), type_text(&from_members_module(o)))
    }

    /// Index of a namespace URI in the file's `NS` table.
    pub(super) fn ns_index(&self, uris: &mut BTreeMap<String, usize>, ns: u16) -> usize {
        let uri = self.model.namespace_uri(ns).to_owned();
        let next = uris.len();
        *uris.entry(uri).or_insert(next)
    }

    pub(super) fn ns_node_id(&self, uris: &mut BTreeMap<String, usize>, t: NodeIx) -> TokenStream {
        let id = &self.model.node(t).id;
        let k = Literal::usize_unsuffixed(self.ns_index(uris, id.ns));
        if let Identifier::Numeric(v) = &id.id {
            let v = Literal::u32_unsuffixed(*v);
            return quote! { rt::NsNodeId::numeric(NS[#k], #v) };
        }
        let kind = self.id_kind(&id.id, &quote! { rt });
        quote! { rt::NsNodeId { namespace_uri: NS[#k], id: #kind } }
    }

    /// The fields of a handle for `members`; nested handle structs go to `nested` (named in `scope_prefix`).
    fn fields(
        &mut self,
        members: &[(NodeIx, NodeIx)],
        names: &BTreeMap<NodeIx, String>,
        uris: &mut BTreeMap<String, usize>,
        prefix: &str,
        nested: &mut Vec<TokenStream>,
        depth: usize,
    ) -> Vec<Field> {
        let model = self.model;
        let mut scope: Scope<NodeIx> = Scope::new(Target::Rust, Case::Snake);
        scope.reserve("node");
        scope.reserve("base");
        for &(m, _) in members {
            scope.add(&model.node(m).browse_name.name, m);
        }
        let (fnames, _) = scope.finish();
        // Nested struct names of this struct: two members may share a BrowseName text in different
        // namespaces (a subtype's `1:Identification` beside its supertype's `3:Identification`).
        let mut nested_names: BTreeSet<String> = BTreeSet::new();
        let mut out = Vec::new();
        for &(m, _) in members {
            let n = model.node(m);
            let Some(rule) = self.rule(m) else { continue };
            let k = self.ns_index(uris, n.browse_name.ns);
            let mut boxed = false;
            let handle = match n.class {
                NodeClass::Variable => {
                    let vt = self.value_type(n.attrs.data_type, n.attrs.value_rank.unwrap_or(-1));
                    built::generic(&["t", "Variable"], vec![vt])
                }
                NodeClass::Method => {
                    let (i, o) = self.method_io(m);
                    built::generic(&["t", "Method"], vec![i, o])
                }
                NodeClass::Object
                    if depth < NESTED_DEPTH
                        && !rule.is_placeholder()
                        && self.adds_children(m)
                        && !self.repeats_its_type(m, names) =>
                {
                    let base = format!("{prefix}{}", crate::names::sanitize(&n.browse_name.name, Case::UpperCamel, Target::Rust).trim_start_matches("r#"));
                    let sname = (1..).map(|k| if k == 1 { base.clone() } else { format!("{base}_{k}") }).find(|c| !nested_names.contains(c)).unwrap_or(base);
                    nested_names.insert(sname.clone());
                    let sub = self.decl_members(m);
                    let text = format!("`{}`, a member of `{}` with children of its own.", n.browse_name.name, prefix.trim_end_matches('_'));
                    nested.push(self.handle_struct(&sname, &text, None, None, &sub, names, uris, nested_prefix(&sname), depth + 1));
                    built::path_type(syn::Path::from(ident(&sname)))
                }
                // Another type's handle is boxed: the member may be of the owner's type or of a subtype of a
                // type that contains the owner, and by value that struct would have no finite size.
                NodeClass::Object => match n.type_definition.and_then(|t| self.handle_path(t, names)) {
                    Some(h) => {
                        boxed = true;
                        built::path_type(h)
                    }
                    None => built::generic(&["t", "ObjectNode"], Vec::new()),
                },
                _ => continue,
            };
            // Placeholders are kept in a list, on the heap already.
            let single = if boxed { built::generic(&["Box"], vec![handle.clone()]) } else { handle.clone() };
            let (ty, bind) = match rule {
                ModellingRule::Mandatory => {
                    (single, built::binder_call("build_child", vec![built::id(), built::ns(k), built::str_lit(&n.browse_name.name)]))
                }
                ModellingRule::Optional => (
                    built::generic(&["Option"], vec![single]),
                    built::binder_call("build_optional", vec![built::id(), built::ns(k), built::str_lit(&n.browse_name.name)]),
                ),
                _ => {
                    let Some(td) = n.type_definition else { continue };
                    // Rare enough to parse: the NodeId's expression has several forms (`ns_node_id`).
                    let tid: syn::Expr = syn::parse2(self.ns_node_id(uris, td)).expect("internal error: a NodeId expression does not parse");
                    (built::generic(&["t", "Placeholders"], vec![handle]), built::binder_call("build_placeholders", vec![built::id(), tid]))
                }
            };
            let mut text = format!("`{}` ({}).", n.browse_name.name, rule.name());
            if let Some(d) = n.doc() {
                text.push_str(" ");
                text.push_str(d);
            }
            out.push(Field { name: fnames[&m].clone(), ty, bind, doc: text });
        }
        out
    }

    /// A handle struct with its `Handle` impl (and `Deref` to its base).
    #[allow(clippy::too_many_arguments)]
    fn handle_struct(
        &mut self,
        name: &str,
        text: &str,
        node_ty: Option<TokenStream>,
        base: Option<TokenStream>,
        members: &[(NodeIx, NodeIx)],
        names: &BTreeMap<NodeIx, String>,
        uris: &mut BTreeMap<String, usize>,
        prefix: String,
        depth: usize,
    ) -> TokenStream {
        let mut nested = Vec::new();
        let fields = self.fields(members, names, uris, &prefix, &mut nested, depth);
        let sname = ident(name);
        let docs = doc(text);
        let node_ty = node_ty.unwrap_or_else(|| quote! { t::ObjectNode });
        // Field names keep a collision's resolution visible (`self__2`), which the snake-case lint dislikes.
        let allow = if depth > 0 {
            quote! { #[allow(non_camel_case_types, non_snake_case)] }
        } else {
            quote! { #[allow(non_snake_case)] }
        };
        let mut decls = vec![quote! { #[doc = " The instance."] pub node: #node_ty }];
        let build_this = || built::binder_call("build_this", vec![built::id()]);
        let mut binds = vec![(ident("node"), build_this())];
        let mut deref = quote! {};
        if let Some(base) = &base {
            decls.push(quote! { #[doc = " The members inherited from the supertype (also reached through `Deref`)."] pub base: #base });
            binds.push((ident("base"), build_this()));
            deref = quote! { t::deref_base!(#sname => #base); };
        }
        for f in fields {
            let fname = ident(&f.name);
            let ty = built::type_placeholder(self.built_types.len());
            self.built_types.push((built::doc_attrs(&f.doc), f.ty));
            decls.push(quote! { pub #fname: #ty });
            binds.push((fname, f.bind));
        }
        let body = built::placeholder(self.bodies.len());
        self.bodies.push(built::self_struct(binds));
        let mut tokens = quote! {
            #docs
            #[derive(Clone)]
            #allow
            pub struct #sname { #(#decls),* }
            t::debug_handle!(#sname);
            impl t::Handle for #sname {
                #[inline]
                fn build(b: &t::Binder<'_>, id: &ua::NodeId) -> Self {
                    #body
                }
            }
            #deref
        };
        // Moved, not copied (see `objects_file`).
        tokens.extend(nested);
        tokens
    }

    /// Variables and methods reachable from an instance of `members`' owner, not crossing placeholders.
    fn reach(&self, members: &[(NodeIx, NodeIx)], path: &mut Vec<(NodeIx, bool)>, out: &mut Vec<(Vec<NodeIx>, NodeIx, bool)>) {
        if path.len() >= MAX_DEPTH {
            return;
        }
        for &(m, _) in members {
            let n = self.model.node(m);
            let Some(rule) = self.rule(m) else { continue };
            if rule.is_placeholder() {
                continue;
            }
            let mandatory = rule == ModellingRule::Mandatory && path.iter().all(|(_, mand)| *mand);
            match n.class {
                NodeClass::Variable | NodeClass::Method => {
                    let p: Vec<NodeIx> = path.iter().map(|(p, _)| *p).chain([m]).collect();
                    out.push((p, m, mandatory));
                }
                NodeClass::Object => {
                    path.push((m, rule == ModellingRule::Mandatory));
                    let sub = self.decl_members(m);
                    self.reach(&sub, path, out);
                    path.pop();
                }
                _ => {}
            }
        }
    }

    /// The markers of a type with these members, in order. A name two paths map to is left out (the derive
    /// cannot name either): order-independent. So is one that would be the module's `REQUIRED`.
    fn marker_list(&self, members: &[(NodeIx, NodeIx)]) -> Vec<Marker> {
        let model = self.model;
        let mut found = Vec::new();
        self.reach(members, &mut Vec::new(), &mut found);
        let all: Vec<Marker> = found
            .into_iter()
            .map(|(p, node, mandatory)| {
                let path: Vec<String> = p.iter().map(|&s| model.node(s).browse_name.name.clone()).collect();
                let segs: Vec<&str> = path.iter().map(String::as_str).collect();
                Marker {
                    name: marker_name(&segs),
                    qpath: p.iter().map(|&s| (model.node(s).browse_name.ns, model.node(s).browse_name.name.clone())).collect(),
                    path,
                    node,
                    mandatory,
                    method: (model.node(node).class == NodeClass::Method).then(|| self.method_io_text(node)),
                }
            })
            .collect();
        let mut count: BTreeMap<&str, usize> = BTreeMap::new();
        for m in &all {
            *count.entry(m.name.as_str()).or_default() += 1;
        }
        let keep: Vec<bool> = all.iter().map(|m| count[m.name.as_str()] == 1 && m.name != "REQUIRED").collect();
        all.into_iter().zip(keep).filter_map(|(m, k)| k.then_some(m)).collect()
    }

    /// The `object_members!` invocation of a type (`variable_members!` for a VariableType: the same macro), as
    /// text: one marker per line (a table, like the node rows of nodes.rs, which prettyplease would fold into
    /// a paragraph).
    ///
    /// `base` is the nearest supertype with a handle, and the path of that handle. When the type has every
    /// marker of that supertype, its module re-exports the supertype's (`pub use`, which costs the compiler
    /// next to nothing) and declares only the markers that are new or say something else; a declared marker
    /// shadows the re-exported one of its name. Otherwise (a supertype's marker name became ambiguous here)
    /// it declares them all.
    fn markers(
        &self,
        macro_name: &str,
        type_name: &str,
        members: &[(NodeIx, NodeIx)],
        base: Option<(NodeIx, &syn::Path)>,
        uris: &mut BTreeMap<String, usize>,
    ) -> String {
        let model = self.model;
        let list = self.marker_list(members);
        let mut inherited = None;
        if let Some((b, handle)) = base {
            let theirs = self.marker_list(&self.type_members(b));
            let ours: BTreeMap<&str, &Marker> = list.iter().map(|m| (m.name.as_str(), m)).collect();
            if theirs.iter().all(|m| ours.contains_key(m.name.as_str())) {
                let same: BTreeSet<String> = theirs
                    .into_iter()
                    .filter(|m| ours[m.name.as_str()].key(model) == m.key(model))
                    .map(|m| m.name)
                    .collect();
                // `Name` or `path::objects::Name`, seen from objects.rs; the markers are in `members::Name` of
                // the module that holds the handle, here seen from `members::<Owner>`.
                let mut module = handle.clone();
                let name = module.segments.pop().map(|last| last.into_value());
                module.segments.pop_punct();
                let module: syn::Type = if module.segments.is_empty() {
                    syn::parse_quote! { super::#name }
                } else {
                    let module = from_members_module(syn::Type::Path(syn::TypePath { qself: None, path: module }));
                    syn::parse_quote! { #module::members::#name }
                };
                inherited = Some((type_text(&module), same));
            }
        }
        let mut items = String::new();
        let mut methods = String::new();
        let mut required = String::new();
        for r in &list {
            let n = model.node(r.node);
            let has_default = n.value.is_some();
            if let Some((inputs, outputs)) = &r.method {
                if !inherited.as_ref().is_some_and(|(_, same)| same.contains(&r.name)) {
                    let path: Vec<String> =
                        r.qpath.iter().map(|(ns, s)| format!("{}:{}", self.ns_index(uris, *ns), escape_segment(s))).collect();
                    let path = Literal::string(&path.join("/"));
                    let _ = writeln!(methods, "            {}: {inputs} => {outputs}, {path}, {};", r.name, r.mandatory);
                }
                continue;
            }
            if r.mandatory && !has_default {
                let p = r.path.join("/");
                let msg = format!(
                    "the mandatory variable `{p}` of {type_name} has no default value in the nodeset, and no field binds it: add a field with #[opcua(path = \"{p}\")]"
                );
                let _ = writeln!(required, "            ({}, {}),", Literal::string(&p), Literal::string(&msg));
            }
            if inherited.as_ref().is_some_and(|(_, same)| same.contains(&r.name)) {
                continue;
            }
            let rank = n.attrs.value_rank.unwrap_or(-1);
            let scalar = type_text(&from_members_module(self.value_type(n.attrs.data_type, -1)));
            let writable = n.attrs.access_level.unwrap_or(1) & 2 != 0;
            let path: Vec<String> = r.qpath.iter().map(|(ns, s)| format!("{}:{}", self.ns_index(uris, *ns), escape_segment(s))).collect();
            let _ = writeln!(
                items,
                "        {}: {scalar}, {rank}, {}, {} {has_default} {writable};",
                r.name,
                Literal::string(&path.join("/")),
                r.mandatory
            );
        }
        let required = if required.is_empty() { "[]".to_string() } else { format!("[\n{required}        ]") };
        let head = match &inherited {
            Some((module, _)) => format!("{type_name}: {module}"),
            None => type_name.to_string(),
        };
        let methods = if methods.is_empty() { String::new() } else { format!("        methods: [\n{methods}        ];\n") };
        format!("    t::{macro_name}! {{\n        {head};\n{methods}        required: {required};\n{items}    }}\n")
    }

    pub(super) fn objects_file(&mut self) -> OutFile {
        let model = self.model;
        let item_names = self.object_item_names(self.ns);
        let names = self.handle_names(self.ns);
        let mut uris: BTreeMap<String, usize> = BTreeMap::new();
        self.ns_index(&mut uris, self.ns);
        let mut ordered: Vec<(&String, NodeIx)> = names.iter().map(|(k, v)| (v, *k)).collect();
        ordered.sort();
        let mut items = Vec::new();
        let mut markers = Vec::new();
        for (name, t) in ordered {
            let n = model.node(t);
            let all = self.type_members(t);
            let mut text = format!("Handle of an instance of `{}` ({}).", n.browse_name.name, model.display_id(&n.id));
            if let Some(d) = n.doc() {
                text.push_str("\n\n");
                text.push_str(d);
            }
            let tid = self.ns_node_id(&mut uris, t);
            let bname = lit(&n.browse_name.name);
            let sname = ident(name);
            if n.class == NodeClass::ObjectType {
                // The nearest supertype with a handle carries the members it declares.
                let base = model.supertypes(t).find_map(|s| Some((s, self.handle_path(s, &names)?)));
                let own: Vec<(NodeIx, NodeIx)> = match &base {
                    Some((s, _)) => {
                        let inherited: BTreeSet<NodeIx> = model.members.get(s).map(|ms| ms.iter().map(|m| m.node).collect()).unwrap_or_default();
                        all.iter().copied().filter(|(m, _)| !inherited.contains(m)).collect()
                    }
                    None => all.clone(),
                };
                let base_for_markers = base.clone();
                let body = self.handle_struct(name, &text, None, base.map(|(_, p)| p.to_token_stream()), &own, &names, &mut uris, nested_prefix(name), 0);
                let machine = self.state_machine_items(t, name, &names, &item_names, &mut uris);
                // Token streams are moved into each other with `extend`: `#body` in `quote!` would copy
                // every token of it (proc-macro2 copies a stream it does not own).
                let mut item = body;
                item.extend(quote! { t::object_type!(#sname, #tid, #bname); });
                item.extend(machine);
                items.push(item);
                markers.push(self.markers("object_members", name, &all, base_for_markers.as_ref().map(|(s, p)| (*s, p)), &mut uris));
            } else {
                // The value itself: ValueRank -1 when the nodeset leaves it out (the schema's default, and
                // what the node table gives the server).
                let vt = self.value_type(n.attrs.data_type, n.attrs.value_rank.unwrap_or(-1));
                let mut item = self.handle_struct(name, &text, Some(quote! { t::Variable<#vt> }), None, &all, &names, &mut uris, nested_prefix(name), 0);
                item.extend(quote! { t::variable_type!(#sname, #tid, #bname, #vt); });
                items.push(item);
                let base = model.supertypes(t).find_map(|s| Some((s, self.handle_path(s, &names)?)));
                markers.push(self.markers("variable_members", name, &all, base.as_ref().map(|(s, p)| (*s, p)), &mut uris));
            }
        }
        let runtime = &self.cfg.runtime_path;
        let mut ns_list: Vec<(&String, &usize)> = uris.iter().collect();
        ns_list.sort_by_key(|(_, i)| **i);
        let ns_items = ns_list.iter().map(|(u, _)| lit(u));
        let mut tokens = quote! {
            //! Typed handles of this namespace's ObjectTypes and VariableTypes (bind them to instances with
            //! `ModelManager::bind`, create instances with `ObjectType::instantiate`), and member markers for
            //! `nodeset-derive`.
            #[allow(unused_imports)]
            use #runtime as rt;
            #[allow(unused_imports)]
            use #runtime::typed as t;
            #[allow(unused_imports)]
            use opcua::types as ua;
            /// Namespace URIs of the BrowseNames and types named below.
            #[allow(dead_code)]
            const NS: &[&str] = &[#(#ns_items),*];
        };
        tokens.extend(items);
        let mut parsed = self.parse("objects.rs", tokens);
        built::fill(&mut parsed, std::mem::take(&mut self.bodies), std::mem::take(&mut self.built_types));
        let mut file = self.print("objects.rs", "Typed handles", &parsed);
        file.contents.push_str(
            "/// Member markers of each ObjectType and VariableType, named from browse paths (`ParameterSet__ActualPosition`).\n\
             #[allow(non_snake_case, non_camel_case_types)]\n\
             pub mod members {\n    #[allow(unused_imports)]\n    use super::t;\n",
        );
        for m in &markers {
            file.contents.push_str(m);
        }
        file.contents.push_str("}\n");
        file
    }
}

/// Whether a type is async-opcua's `Variant` (`opcua::types::Variant`).
fn is_variant(t: &TokenStream) -> bool {
    syn::parse2::<syn::Path>(t.clone()).is_ok_and(|p| {
        p.leading_colon.is_none()
            && p.segments.len() == 3
            && ["opcua", "types", "Variant"].iter().zip(&p.segments).all(|(s, seg)| seg.ident == s && seg.arguments.is_none())
    })
}

/// Calls `f` on every path in a type, inner ones (generic arguments, tuple elements) first.
fn each_path(ty: &mut syn::Type, f: &mut impl FnMut(&mut syn::Path)) {
    match ty {
        syn::Type::Path(p) => {
            for seg in p.path.segments.iter_mut() {
                if let syn::PathArguments::AngleBracketed(args) = &mut seg.arguments {
                    for arg in args.args.iter_mut() {
                        if let syn::GenericArgument::Type(t) = arg {
                            each_path(t, f);
                        }
                    }
                }
            }
            f(&mut p.path);
        }
        syn::Type::Tuple(t) => t.elems.iter_mut().for_each(|e| each_path(e, f)),
        syn::Type::Array(syn::TypeArray { elem, .. })
        | syn::Type::Slice(syn::TypeSlice { elem, .. })
        | syn::Type::Reference(syn::TypeReference { elem, .. })
        | syn::Type::Paren(syn::TypeParen { elem, .. })
        | syn::Type::Group(syn::TypeGroup { elem, .. }) => each_path(elem, f),
        _ => {}
    }
}

/// `opcua::types::X` -> `ua::X` (objects.rs imports `opcua::types as ua`; the value types are computed by code
/// shared with types.rs, which names the full path).
fn alias_ua(path: &mut syn::Path) {
    let is = |i: usize, s: &str| path.segments.get(i).is_some_and(|seg| seg.ident == s);
    if path.leading_colon.is_none() && path.segments.len() > 2 && is(0, "opcua") && is(1, "types") {
        let rest: Vec<syn::PathSegment> = path.segments.iter().skip(2).cloned().collect();
        path.segments = std::iter::once(syn::PathSegment::from(ident("ua"))).chain(rest).collect();
    }
}

/// A type named in objects.rs, as named from `members::<Owner>`, two modules down: each path relative to
/// objects.rs (`super::types::Mode`) climbs two modules more.
fn from_members_module(mut ty: syn::Type) -> syn::Type {
    each_path(&mut ty, &mut |path| {
        if path.leading_colon.is_none() && path.segments.first().is_some_and(|s| s.ident == "super") {
            for _ in 0..2 {
                path.segments.insert(0, syn::PathSegment::from(ident("super")));
            }
        }
    });
    ty
}

/// A type as a person writes it, for the members macros' text (`Vec<ua::LocalizedText>`, `(String,)`,
/// `super::types::Mode`). Value types are paths, with type arguments, and tuples of them; any other form is
/// written as its tokens, which is the same Rust with other spacing.
fn type_text(ty: &syn::Type) -> String {
    let mut out = String::new();
    write_type(ty, &mut out);
    out
}

fn write_type(ty: &syn::Type, out: &mut String) {
    match ty {
        syn::Type::Path(syn::TypePath { qself: None, path }) => {
            if path.leading_colon.is_some() {
                out.push_str("::");
            }
            for (i, seg) in path.segments.iter().enumerate() {
                if i > 0 {
                    out.push_str("::");
                }
                out.push_str(&seg.ident.to_string());
                match &seg.arguments {
                    syn::PathArguments::None => {}
                    syn::PathArguments::AngleBracketed(args) => {
                        out.push('<');
                        for (j, arg) in args.args.iter().enumerate() {
                            if j > 0 {
                                out.push_str(", ");
                            }
                            match arg {
                                syn::GenericArgument::Type(t) => write_type(t, out),
                                other => out.push_str(&other.to_token_stream().to_string()),
                            }
                        }
                        out.push('>');
                    }
                    other => out.push_str(&other.to_token_stream().to_string()),
                }
            }
        }
        syn::Type::Tuple(t) => {
            out.push('(');
            for (j, e) in t.elems.iter().enumerate() {
                if j > 0 {
                    out.push_str(", ");
                }
                write_type(e, out);
            }
            if t.elems.len() == 1 {
                out.push(',');
            }
            out.push(')');
        }
        other => out.push_str(&other.to_token_stream().to_string()),
    }
}

/// The prefix of nested handle struct names of a type (`AxisType` -> `AxisType_`).
fn nested_prefix(name: &str) -> String {
    format!("{name}_")
}

#[cfg(test)]
mod tests {
    use super::{each_path, alias_ua, from_members_module, type_text};

    fn seen_from_members(ty: syn::Type) -> String {
        type_text(&from_members_module(ty))
    }

    #[test]
    fn types_named_from_objects_rs_are_renamed_for_the_members_modules() {
        assert_eq!(seen_from_members(syn::parse_quote!(String)), "String");
        assert_eq!(seen_from_members(syn::parse_quote!(ua::NodeId)), "ua::NodeId");
        assert_eq!(seen_from_members(syn::parse_quote!(super::types::Mode)), "super::super::super::types::Mode");
        assert_eq!(
            seen_from_members(syn::parse_quote!(Vec<super::super::di::types::A>)),
            "Vec<super::super::super::super::di::types::A>"
        );
        assert_eq!(
            seen_from_members(syn::parse_quote!((super::types::A, Vec<i32>, ::ext::B,))),
            "(super::super::super::types::A, Vec<i32>, ::ext::B)"
        );
        assert_eq!(seen_from_members(syn::parse_quote!((super::types::A,))), "(super::super::super::types::A,)");
        assert_eq!(seen_from_members(syn::parse_quote!(())), "()");
    }

    #[test]
    fn async_opcua_types_are_named_through_the_ua_alias() {
        let mut ty: syn::Type = syn::parse_quote!(Vec<opcua::types::LocalizedText>);
        each_path(&mut ty, &mut alias_ua);
        assert_eq!(type_text(&ty), "Vec<ua::LocalizedText>");
        let mut ty: syn::Type = syn::parse_quote!(::opcua::types::X);
        each_path(&mut ty, &mut alias_ua);
        assert_eq!(type_text(&ty), "::opcua::types::X", "an absolute path is not the alias's");
    }
}
