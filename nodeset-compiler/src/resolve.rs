//! The resolver: one [`Model`] from the loaded files, and the checks that need the whole model.
//!
//! Passes, each over the whole arena: (1) give every node its index, (2) resolve references and add
//! inverses, (3) type hierarchy, type definitions, modelling rules, parents, (4) instance declarations per
//! type, (5) data types, (6) method arguments, (7) state machines, (8) checks on values and names.
//! Every pass collects its problems; nothing stops at the first one.

use crate::fxhash::{FxHashMap, FxHashSet};
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::load::Loaded;
use crate::model::*;
use crate::nodeid::{parse_qualified_name, NodeId, QualifiedName};
use crate::raw::{NodeClass, RawRolePermission, RawStr, ValueArena};
use crate::source::{SourceMap, Span};
use crate::value::{BuiltinType, Content, Variant};
use std::collections::{BTreeMap, HashSet};

mod inherit;

/// Builds the model. Problems go to `diags`; the model is returned even when there are errors, with the
/// offending parts left out, so that later checks can still report what they find.
pub fn resolve(loaded: Loaded, diags: &mut Diagnostics) -> Model {
    let Loaded { sources, files, namespaces, models } = loaded;
    let mut value_arenas: Vec<ValueArena> = (0..sources.len()).map(|_| ValueArena::default()).collect();
    let mut model = Model {
        // The sources join the model after pass 2; until then the raw strings borrow from them.
        sources: SourceMap::new(),
        namespaces,
        models,
        nodes: Vec::new(),
        index: FxHashMap::default(),
        files: BTreeMap::new(),
        data_types: BTreeMap::new(),
        methods: BTreeMap::new(),
        state_machines: BTreeMap::new(),
        members: BTreeMap::new(),
        overridden: BTreeMap::new(),
        hierarchical: Vec::new(),
        subtype_spans: Vec::new(),
        ns0_type_names: FxHashMap::default(),
        value_arenas: Vec::new(),
    };
    let total: usize = files.iter().map(|f| f.raw.nodes.len()).sum();
    model.nodes.reserve(total);
    model.index.reserve(total);

    let t_pass1 = crate::timing::span("pass 1 (index)");
    // Pass 1: every node gets its index and what it owns of its raw node. Raw nodes stay where the loader
    // put them; `pending` says where.
    let mut files = files;
    let contexts: Vec<FileContext> = files
        .iter_mut()
        .map(|f| FileContext { ns_map: std::mem::take(&mut f.ns_map), aliases: std::mem::take(&mut f.aliases) })
        .collect();
    // Files whose alias names look like NodeIds (an alias `i=5` would shadow the NodeId) take the general
    // path for every NodeId string; the others resolve numeric NodeIds on the fast path.
    let numeric_fast: Vec<bool> =
        contexts.iter().map(|c| !c.aliases.keys().any(|a| crate::nodeid::looks_like_node_id(a))).collect();
    let mut pending: Vec<(NodeIx, u32, u32)> = Vec::with_capacity(total);
    let mut redefined: Vec<Redefinition> = Vec::new();
    for (fi, f) in files.iter_mut().enumerate() {
        let file = f.raw.file;
        let text = sources.get(file).text.as_str();
        let ctx = &contexts[fi];
        value_arenas[file.0 as usize] = std::mem::take(&mut f.raw.values);
        for (ni, raw) in f.raw.nodes.iter_mut().enumerate() {
            let fast = numeric_fast[fi]
                .then(|| raw.node_id.numeric_node_id())
                .flatten()
                .and_then(|(ns, n)| Some(NodeId::numeric(*ctx.ns_map.get(ns as usize)?, n)));
            let id = match fast.map(Ok).unwrap_or_else(|| {
                let node_id = raw.node_id.get(text);
                crate::load::resolve_node_id_str(&ctx.ns_map, &ctx.aliases, node_id, raw.node_id.span, &model.namespaces)
            }) {
                Ok(id) => id,
                Err(d) => {
                    diags.push(d);
                    continue;
                }
            };
            // The parser read well-formed BrowseNames; the text is read again only for the others.
            let parsed = match raw.qualified_name.take() {
                Some(q) => Ok(q),
                None => parse_qualified_name(raw.browse_name.get(text)),
            };
            let browse_name = match parsed {
                Ok(q) => match ctx.ns_map.get(q.ns as usize) {
                    Some(&ns) => QualifiedName { ns, name: q.name },
                    None => {
                        diags.push(
                            Diagnostic::new(
                                Code::UnknownNamespaceIndex,
                                format!("BrowseName namespace index {} is not declared in NamespaceUris", q.ns),
                            )
                            .at(raw.browse_name.span)
                            .help("add the namespace's URI to <NamespaceUris> or correct the prefix"),
                        );
                        QualifiedName { ns: 0, name: q.name }
                    }
                },
                Err(why) => {
                    let browse_name_text = raw.browse_name.get(text);
                    if !browse_name_text.is_empty() || raw.browse_name.span != raw.span {
                        diags.push(
                            Diagnostic::new(Code::MalformedQualifiedName, format!("malformed BrowseName: {why}"))
                                .at(raw.browse_name.span)
                                .help("write N:Name, N being the namespace index"),
                        );
                    }
                    QualifiedName { ns: 0, name: browse_name_text.to_string() }
                }
            };
            if let Some(&prev) = model.index.get(&id) {
                // Judged after this pass, when both raw nodes can be read: an identical copy is a warning.
                redefined.push(Redefinition { prev, file: fi as u32, node: ni as u32, id, browse_name });
                continue;
            }
            let ix = NodeIx(model.nodes.len() as u32);
            model.index.insert(id.clone(), ix);
            if id.ns == 0 && matches!(raw.class, NodeClass::DataType | NodeClass::ReferenceType) {
                model.ns0_type_names.insert(browse_name.name.clone(), ix);
            }
            let attrs = Attributes {
                write_mask: raw.write_mask,
                user_write_mask: raw.user_write_mask,
                access_restrictions: raw.access_restrictions,
                release_status: raw.release_status.take(),
                data_type: None,
                value_rank: raw.value_rank,
                array_dimensions: Vec::new(),
                access_level: raw.access_level,
                user_access_level: raw.user_access_level,
                access_level_ex: raw.access_level_ex,
                minimum_sampling_interval: raw.minimum_sampling_interval,
                historizing: raw.historizing,
                executable: raw.executable,
                user_executable: raw.user_executable,
                event_notifier: raw.event_notifier,
                contains_no_loops: raw.contains_no_loops,
                is_abstract: raw.is_abstract,
                symmetric: raw.symmetric,
                inverse_name: std::mem::take(&mut raw.inverse_names),
                role_permissions: std::mem::take(&mut raw.role_permissions),
                roles: Vec::new(),
                category: std::mem::take(&mut raw.category),
                documentation: raw.documentation.take(),
                method_declaration: None,
            };
            model.nodes.push(Node {
                id,
                class: raw.class,
                browse_name,
                symbolic_name: raw.symbolic_name.take(),
                display_name: std::mem::take(&mut raw.display_names),
                description: std::mem::take(&mut raw.descriptions),
                attrs,
                value: raw.value,
                definition: raw.definition.take(),
                extensions: std::mem::take(&mut raw.extensions),
                // Filled once all references are known, in one allocation (see `link`).
                references: Vec::new(),
                super_type: None,
                type_definition: None,
                modelling_rule: None,
                parent: None,
                file,
                span: raw.span,
                node_id_span: raw.node_id.span,
                browse_name_span: raw.browse_name.span,
            });
            pending.push((ix, fi as u32, ni as u32));
        }
    }

    drop(t_pass1);
    let t_pass2 = crate::timing::span("pass 2 (references)");
    for r in &redefined {
        diags.push(redefinition(&model, &files, &contexts, &sources, &value_arenas, &pending, r));
    }

    // Pass 2: attributes that name nodes, and references. The raw nodes are only read from here on. Two
    // threads resolve the two halves of the nodes, reading the model only; what they found is then entered
    // in node order, duplicate references dropped as they come, with their diagnostics in that order: the
    // outcome of one pass over the nodes in order.
    let files = files;
    let pass = Pass2 { model: &model, files: &files, sources: &sources, contexts: &contexts, numeric_fast: &numeric_fast };
    let half = {
        let total_refs: usize = pending.iter().map(|&(_, fi, ni)| files[fi as usize].raw.nodes[ni as usize].references.len()).sum();
        let mut seen = 0;
        pending
            .iter()
            .position(|&(_, fi, ni)| {
                seen += files[fi as usize].raw.nodes[ni as usize].references.len() + 1;
                seen > total_refs.div_ceil(2)
            })
            .unwrap_or(pending.len())
    };
    let (first, second) = pending.split_at(half);
    let (later, earlier) = crate::par::join(|| pass.links(second), || pass.links(first));
    let mut seen_refs: FxHashSet<(NodeIx, NodeIx, NodeIx)> = FxHashSet::with_capacity_and_hasher(total * 3, Default::default());
    // The declared references of every node, in node order (node `i`'s end at `own_end[i]`), and
    // the inverses they give their targets: each node's list is built from both in `link`, in one go.
    let mut own: Vec<Reference> = Vec::with_capacity(total * 3);
    let mut own_end: Vec<u32> = Vec::with_capacity(total);
    // What pass 2 found for every node, in node order: entered with the references in `link`, so that each
    // node is written once.
    let mut found_all: Vec<NodeLinks> = Vec::with_capacity(total);
    let mut incoming: Vec<(NodeIx, Reference)> = Vec::with_capacity(total * 3);
    // Nodes with a reference that could not be resolved (already reported): no follow-on warnings.
    let mut broken: HashSet<NodeIx> = HashSet::new();
    for (part, links) in [(first, earlier), (second, later)] {
        diags.extend(links.diags);
        broken.extend(links.broken);
        let mut from = 0;
        for (&(ix, _, _), found) in part.iter().zip(links.nodes) {
            debug_assert_eq!(ix.index(), own_end.len(), "pending is in node order");
            for &(reference_type, target, forward, span) in &links.references[from..found.references_end as usize] {
                let (src, dst) = if forward { (ix, target) } else { (target, ix) };
                if !seen_refs.insert((src, reference_type, dst)) {
                    continue;
                }
                own.push(Reference { reference_type, target, forward, declared: true, span });
                incoming.push((target, Reference { reference_type, target: ix, forward: !forward, declared: false, span }));
            }
            own_end.push(own.len() as u32);
            from = found.references_end as usize;
            found_all.push(found);
        }
    }
    model.files = files.iter().map(|f| f.raw.file).zip(contexts).collect();
    model.sources = sources;
    model.value_arenas = value_arenas;
    drop(pending);
    drop(t_pass2);
    let _t = crate::timing::span("passes 3-8");
    // The raw files are not needed any more: another thread frees them while this one goes on.
    let own = OwnReferences { references: own, ends: own_end, found: found_all };
    crate::par::join(move || drop(files), || link(&mut model, own, incoming, &broken, diags));
    model
}

/// What pass 2 found for every node, in node order: the declared references (node `i`'s end at
/// `ends[i]`) and the attributes that name nodes.
struct OwnReferences {
    references: Vec<Reference>,
    ends: Vec<u32>,
    found: Vec<NodeLinks>,
}

/// Passes 3 to 8, on the model with its references resolved.
fn link(model: &mut Model, own: OwnReferences, incoming: Vec<(NodeIx, Reference)>, broken: &HashSet<NodeIx>, diags: &mut Diagnostics) {
    // Each node's inverse references go after its own, in the order they were found. The inverses are
    // first sorted by node (stably, by counting), so that each node's list is allocated once at its final
    // size and filled in order.
    let n = model.nodes.len();
    let mut starts = vec![0u32; n + 1];
    for (target, _) in &incoming {
        starts[target.index() + 1] += 1;
    }
    for i in 0..n {
        starts[i + 1] += starts[i];
    }
    let mut next = starts.clone();
    let placeholder = Reference { reference_type: NodeIx(0), target: NodeIx(0), forward: false, declared: false, span: Span::new(crate::source::FileId(0), 0, 0) };
    let mut sorted = vec![placeholder; incoming.len()];
    for (target, r) in incoming {
        let at = &mut next[target.index()];
        sorted[*at as usize] = r;
        *at += 1;
    }
    let mut start = 0;
    let OwnReferences { references: own, ends, found } = own;
    for (i, ((node, &end), found)) in model.nodes.iter_mut().zip(&ends).zip(found).enumerate() {
        node.attrs.array_dimensions = found.array_dimensions;
        node.attrs.data_type = found.data_type;
        node.attrs.method_declaration = found.method_declaration;
        node.attrs.roles = found.roles;
        node.parent = found.parent;
        let declared = &own[start..end as usize];
        let inverse = &sorted[starts[i] as usize..starts[i + 1] as usize];
        let mut list = Vec::with_capacity(declared.len() + inverse.len());
        list.extend_from_slice(declared);
        list.extend_from_slice(inverse);
        node.references = list;
        start = end as usize;
    }
    drop((own, ends, sorted, starts, next));
    model_defaults(model, diags);
    let t3 = crate::timing::span("pass 3 (types)");
    // Pass 3: hierarchy flags, supertypes, type definitions, modelling rules, parents.
    link_types(model, broken, diags);

    // Passes 4 to 6 and 8 only read the model and do not depend on one another, except on the data types:
    // the method arguments (Argument structures) and the value check need them. So two rounds of two threads:
    // instance declarations beside the data types, then method arguments beside the value check. Each pass
    // keeps its diagnostics, which are added in pass order.
    drop(t3);
    let t48 = crate::timing::span("passes 4-6, 8");
    let m = &*model;
    let ((members, members_said), (data_types, data_types_said)) = crate::par::join(
        || said(|d| build_members(m, d)),
        || said(|d| crate::datatypes::classify(m, d)),
    );
    let ((methods, methods_said), (_, values_said)) =
        crate::par::join(|| said(|d| methods(m, &data_types, d)), || said(|d| check_values(m, &data_types, d)));
    model.members = members;
    model.data_types = data_types;
    model.methods = methods;
    diags.extend(members_said);
    // Pass 5: what each declaration overrides, from the members of every type.
    model.overridden = inherit::overrides(model, diags);
    diags.extend(data_types_said);
    diags.extend(methods_said);
    drop(t48);
    let _t = crate::timing::span("pass 7 (state machines)");
    // Pass 7: state machines, from the instance declarations.
    state_machines(model, diags);
    diags.extend(values_said);
}

/// Runs a pass that reports into diagnostics of its own, so that passes on two threads can be merged in order.
fn said<T>(pass: impl FnOnce(&mut Diagnostics) -> T) -> (T, Diagnostics) {
    let mut d = Diagnostics::new();
    (pass(&mut d), d)
}

/// What pass 2 reads: the model with every node indexed, and the raw files it came from.
struct Pass2<'m> {
    model: &'m Model,
    files: &'m [crate::load::LoadedFile],
    sources: &'m SourceMap,
    contexts: &'m [FileContext],
    /// Per file: whether numeric NodeIds may take the fast path (see [`numeric_node`]).
    numeric_fast: &'m [bool],
}

/// What pass 2 found for a run of nodes, with the diagnostics in the order it found them.
struct Links {
    nodes: Vec<NodeLinks>,
    /// The references of all the nodes, resolved: type, target, direction, span.
    references: Vec<(NodeIx, NodeIx, bool, Span)>,
    broken: Vec<NodeIx>,
    diags: Diagnostics,
}

/// What pass 2 found for one node.
struct NodeLinks {
    array_dimensions: Vec<u32>,
    data_type: Option<NodeIx>,
    method_declaration: Option<NodeIx>,
    roles: Vec<(NodeIx, u32)>,
    /// Where the node's references end in [`Links::references`] (they start where the previous node's end).
    references_end: u32,
    parent: Option<NodeIx>,
}

impl Pass2<'_> {
    /// Resolves the attributes that name nodes and the references of the `pending` nodes.
    fn links(&self, pending: &[(NodeIx, u32, u32)]) -> Links {
        let model = self.model;
        let mut out = Links { nodes: Vec::with_capacity(pending.len()), references: Vec::new(), broken: Vec::new(), diags: Diagnostics::new() };
        let diags = &mut out.diags;
        // Per file: NodeId strings already resolved (reference types repeat thousands of times), keyed by
        // the strings as the file writes them.
        let mut caches: Vec<FxHashMap<&str, NodeIx>> = self.contexts.iter().map(|_| FxHashMap::default()).collect();
        for &(ix, fi, ni) in pending {
            let raw = &self.files[fi as usize].raw.nodes[ni as usize];
            let text = self.sources.get(self.files[fi as usize].raw.file).text.as_str();
            let ctx = &self.contexts[fi as usize];
            let fast = self.numeric_fast[fi as usize];
            let cache = &mut caches[fi as usize];
            let mut array_dimensions = Vec::new();
            if let Some(ad) = &raw.array_dimensions {
                for part in ad.value.split(',').map(str::trim).filter(|p| !p.is_empty()) {
                    match part.parse::<u32>() {
                        Ok(v) => array_dimensions.push(v),
                        Err(_) => diags.push(
                            Diagnostic::new(Code::BadAttribute, format!("ArrayDimensions=\"{}\" is not a list of numbers", ad.value))
                                .at(ad.span)
                                .with_span_label(format!("`{part}` is not a UInt32"))
                                .help("write a comma-separated list such as 3,3 (0 for an unknown length)"),
                        ),
                    }
                }
            }
            let mut data_type = None;
            if let Some(dt) = &raw.data_type {
                if let Some(t) = resolve_cached(cache, ctx, fast, model, ix, dt, text, diags) {
                    if model.nodes[t.index()].class != NodeClass::DataType {
                        let class = model.nodes[t.index()].class.name();
                        diags.push(
                            Diagnostic::new(
                                Code::BadDataType,
                                format!("DataType `{}` is {} {class}, not a DataType", dt.get(text), article(class)),
                            )
                            .at(dt.span)
                            .help("name a DataType node (an alias such as Int32, or its NodeId)"),
                        );
                    } else {
                        data_type = Some(t);
                    }
                }
            }
            let method_declaration =
                raw.method_declaration_id.as_ref().and_then(|m| resolve_cached(cache, ctx, fast, model, ix, m, text, diags));
            for r in self.files[fi as usize].raw.references_of(raw) {
                // Numeric NodeIds need neither the text nor the cache; everything else, and every problem,
                // takes the general path.
                let numeric = fast.then(|| numeric_node(model, ctx, &r.reference_type)).flatten();
                let rt = match numeric {
                    Some(t) if model.nodes[t.index()].class == NodeClass::ReferenceType => t,
                    _ => {
                        let rt_text = r.reference_type.get(text);
                        let cached = numeric.or_else(|| cache.get(rt_text).copied());
                        let found = match cached {
                            Some(t) => Ok(Some(t)),
                            None => ctx.resolve(model, rt_text, r.reference_type.span, diags).map(|id| model.lookup(&id)),
                        };
                        match found {
                            Ok(Some(t)) if model.nodes[t.index()].class == NodeClass::ReferenceType => {
                                if cached.is_none() {
                                    cache.insert(rt_text, t);
                                }
                                t
                            }
                            Ok(Some(t)) => {
                                let class = model.nodes[t.index()].class.name();
                                diags.push(
                                    Diagnostic::new(
                                        Code::BadReferenceType,
                                        format!("ReferenceType `{rt_text}` is {} {class}, not a ReferenceType", article(class)),
                                    )
                                    .at(r.reference_type.span)
                                    .help("use a ReferenceType such as HasComponent (i=47)"),
                                );
                                continue;
                            }
                            Ok(None) => {
                                diags.push(
                                    Diagnostic::new(Code::BadReferenceType, format!("ReferenceType `{rt_text}` names no loaded node"))
                                        .at(r.reference_type.span)
                                        .help("load the model that defines the reference type"),
                                );
                                continue;
                            }
                            Err(d) => {
                                diags.push(d);
                                out.broken.push(ix);
                                continue;
                            }
                        }
                    }
                };
                let Some(target) = resolve_cached(cache, ctx, fast, model, ix, &r.target, text, diags) else {
                    out.broken.push(ix);
                    continue;
                };
                out.references.push((rt, target, r.is_forward, r.span));
            }
            let mut parent = None;
            if let Some(p) = &raw.parent_node_id {
                parent = match fast.then(|| numeric_node(model, ctx, p)).flatten() {
                    Some(p) => Some(p),
                    None => ctx.resolve(model, p.get(text), p.span, diags).ok().and_then(|id| model.lookup(&id)),
                };
            }
            let roles = model.nodes[ix.index()].attrs.role_permissions.iter().filter_map(|p| role(model, ctx, p, diags)).collect();
            out.nodes.push(NodeLinks { array_dimensions, data_type, method_declaration, roles, references_end: out.references.len() as u32, parent });
        }
        out
    }
}

/// The role object a RolePermission names, with its permissions; NS0220 (and `None`) if the node is not an
/// Object.
fn role(model: &Model, ctx: &FileContext, p: &RawRolePermission, diags: &mut Diagnostics) -> Option<(NodeIx, u32)> {
    let id = ctx.resolve(model, &p.role.value, p.role.span, diags).ok()?;
    match model.lookup(&id).map(|r| (r, model.nodes[r.index()].class)) {
        Some((r, NodeClass::Object)) => Some((r, p.permissions)),
        found => {
            let what = match found {
                Some((_, class)) => format!("{} {}", article(class.name()), class.name()),
                None => "no loaded node".to_owned(),
            };
            diags.push(
                Diagnostic::new(Code::BadRolePermission, format!("RolePermission names `{}`, {what}, not a role", p.role.value))
                    .at(p.role.span)
                    .help("name a role object, such as a well-known role of the base namespace (Operator is i=15680)"),
            );
            None
        }
    }
}

/// A model's DefaultRolePermissions and DefaultAccessRestrictions (the `<RolePermissions>` and
/// `AccessRestrictions` of its `<Model>` element) given to every node of its namespace that has no
/// RolePermissions, or no AccessRestrictions, of its own (OPC 10000-3, 5.2.9 and 5.2.11). The tables then
/// carry them node by node, as if the nodeset had written them there.
fn model_defaults(model: &mut Model, diags: &mut Diagnostics) {
    for mi in 0..model.models.len() {
        let info = &model.models[mi];
        if info.default_role_permissions.is_empty() && info.default_access_restrictions.is_none() {
            continue;
        }
        let Some(ctx) = model.files.get(&info.file) else { continue };
        let roles: Vec<(NodeIx, u32)> =
            info.default_role_permissions.iter().filter_map(|p| role(model, ctx, p, diags)).collect();
        let (ns, restrictions, declared) =
            (info.ns, info.default_access_restrictions, !info.default_role_permissions.is_empty());
        for node in model.nodes.iter_mut().filter(|n| n.id.ns == ns) {
            if declared && node.attrs.role_permissions.is_empty() {
                node.attrs.roles = roles.clone();
            }
            if node.attrs.access_restrictions.is_none() {
                node.attrs.access_restrictions = restrictions;
            }
        }
    }
}

/// The node a numeric NodeId string (`i=N`, `ns=I;i=N`) of a file names, found without the alias table,
/// the cache, the text or an allocation. `None` for any other string and for a NodeId that names no node:
/// the general path then resolves it and reports what is wrong. Only for files where no alias looks like a
/// NodeId.
fn numeric_node(model: &Model, ctx: &FileContext, s: &RawStr) -> Option<NodeIx> {
    let (ns, n) = s.numeric_node_id()?;
    model.lookup(&NodeId::numeric(*ctx.ns_map.get(ns as usize)?, n))
}

/// Resolves a NodeId or alias written in a file to a node: numeric NodeIds on the fast path where `fast`
/// allows it, other strings through the file's cache of strings already resolved. Problems are reported
/// (a dangling one as coming from node `from`) and give `None`.
#[allow(clippy::too_many_arguments)]
fn resolve_cached<'s>(
    cache: &mut FxHashMap<&'s str, NodeIx>,
    ctx: &FileContext,
    fast: bool,
    model: &Model,
    from: NodeIx,
    raw: &'s RawStr,
    text: &'s str,
    diags: &mut Diagnostics,
) -> Option<NodeIx> {
    if let Some(t) = fast.then(|| numeric_node(model, ctx, raw)).flatten() {
        return Some(t);
    }
    let (s, span) = (raw.get(text), raw.span);
    if let Some(&t) = cache.get(s) {
        return Some(t);
    }
    match ctx.resolve(model, s, span, diags) {
        Ok(id) => match model.lookup(&id) {
            Some(t) => {
                cache.insert(s, t);
                Some(t)
            }
            None => {
                diags.push(dangling(model, from, &id, span));
                None
            }
        },
        Err(d) => {
            diags.push(d);
            None
        }
    }
}

/// A node whose NodeId was already defined (NS0201, or NS0218 when the copy is identical).
struct Redefinition {
    /// The node defined first.
    prev: NodeIx,
    /// Where the second definition is: file and node index of the raw node.
    file: u32,
    node: u32,
    id: NodeId,
    browse_name: QualifiedName,
}

/// The diagnostic for a second definition of a NodeId: a warning when it is an identical copy (same class,
/// names, attributes, DataType, references, definition and value; files without `<Models>` often carry
/// their own copy of part of ns0), the error NS0201 with both locations otherwise. Either way the first
/// definition is kept.
fn redefinition(
    model: &Model,
    files: &[crate::load::LoadedFile],
    contexts: &[FileContext],
    sources: &SourceMap,
    values: &[ValueArena],
    pending: &[(NodeIx, u32, u32)],
    r: &Redefinition,
) -> Diagnostic {
    let p = &model.nodes[r.prev.index()];
    let (_, pfi, pni) = pending[r.prev.index()];
    let node_of = |fi: u32, ni: u32| &files[fi as usize].raw.nodes[ni as usize];
    let (a, b) = (node_of(pfi, pni), node_of(r.file, r.node));
    let b_span = b.node_id.span;
    let resolve = |fi: u32, text: &str, span: Span| {
        let ctx = &contexts[fi as usize];
        crate::load::resolve_node_id_str(&ctx.ns_map, &ctx.aliases, text, span, &model.namespaces).ok()
    };
    let text_of = |fi: u32| sources.get(files[fi as usize].raw.file).text.as_str();
    let refs = |fi: u32, n: &crate::raw::RawNode| {
        let text = text_of(fi);
        let mut list: Vec<Option<(NodeId, NodeId, bool)>> = files[fi as usize]
            .raw
            .references_of(n)
            .iter()
            .map(|x| {
                Some((resolve(fi, x.reference_type.get(text), x.reference_type.span)?, resolve(fi, x.target.get(text), x.target.span)?, x.is_forward))
            })
            .collect();
        list.sort();
        list.dedup();
        list
    };
    let data_type = |fi: u32, n: &crate::raw::RawNode| n.data_type.as_ref().map(|d| resolve(fi, d.get(text_of(fi)), d.span));
    let value = |fi: u32, n: &crate::raw::RawNode| {
        let file = files[fi as usize].raw.file;
        n.value.map(|v| {
            let text = sources.get(file).text.as_str();
            let e = values[file.0 as usize].element(v, text);
            let span = e.span();
            text.get(span.start as usize..span.end as usize).unwrap_or("").split_whitespace().collect::<String>()
        })
    };
    let fields = |d: Option<&crate::raw::RawDefinition>| {
        d.map(|d| {
            let list: Vec<_> = d.fields.iter().map(|f| (f.name.clone(), f.value, f.data_type.as_ref().map(|t| t.value.clone()), f.value_rank, f.is_optional)).collect();
            (d.name.clone(), d.is_union, d.is_option_set, list)
        })
    };
    let identical = p.class == b.class
        && p.browse_name == r.browse_name
        && p.display_name == b.display_names
        && (a.value_rank, a.access_level, a.user_access_level, a.is_abstract, a.symmetric, a.event_notifier, a.executable)
            == (b.value_rank, b.access_level, b.user_access_level, b.is_abstract, b.symmetric, b.event_notifier, b.executable)
        && data_type(pfi, a) == data_type(r.file, b)
        && refs(pfi, a) == refs(r.file, b)
        && value(pfi, a) == value(r.file, b)
        && fields(p.definition.as_deref()) == fields(b.definition.as_deref());
    if identical {
        Diagnostic::new(Code::IdenticalRedefinition, format!("NodeId `{}` is defined again, identically", model.display_id(&r.id)))
            .at(b_span)
            .with_span_label("an identical copy")
            .label(p.node_id_span, "first defined here")
            .note("the copy is ignored; the node loaded first is used")
            .help("remove the copy from the file, or load the file that defines the node without it")
    } else {
        Diagnostic::new(Code::DuplicateNodeId, format!("NodeId `{}` is defined twice", model.display_id(&r.id)))
            .at(b_span)
            .with_span_label("defined again here, differently")
            .label(p.node_id_span, "first defined here")
            .help("every node needs its own NodeId; the second definition is ignored")
    }
}

fn dangling(model: &Model, from: NodeIx, id: &NodeId, span: Span) -> Diagnostic {
    let from_node = model.node(from);
    let same_model = {
        let own_ns = model.models.iter().find(|m| m.file == from_node.file).map(|m| m.ns);
        own_ns == Some(id.ns) || model.models.iter().all(|m| m.ns != id.ns)
    };
    let code = if same_model { Code::DanglingReference } else { Code::DanglingForeignReference };
    let owner = model.models.iter().find(|m| m.ns == id.ns);
    let mut d = Diagnostic::new(code, format!("`{}` names no node", model.display_id(id)))
        .at(span)
        .with_span_label("no node has this NodeId");
    if let Some(o) = owner {
        d = d.note(format!(
            "namespace {} is model `{}` version {}",
            id.ns,
            o.uri,
            o.version.as_deref().unwrap_or("(none)")
        ));
    }
    if same_model {
        d.help("define the node, or correct the NodeId (a typo, or a node removed from this file)")
    } else {
        d.help("the other model's loaded version lacks this node; the reference is dropped")
    }
}

fn link_types(model: &mut Model, broken: &HashSet<NodeIx>, diags: &mut Diagnostics) {
    let n = model.nodes.len();
    // Hierarchical reference types: HierarchicalReferences and its subtypes, minus HasSubtype.
    let has_subtype = model.ns0(ids::HAS_SUBTYPE);
    // Supertypes first (needed for the hierarchy flags).
    for i in 0..n {
        let ix = NodeIx(i as u32);
        let mut supers: Vec<NodeIx> = Vec::new();
        let mut sub_span = model.nodes[i].span;
        for r in &model.nodes[i].references {
            if Some(r.reference_type) == has_subtype && !r.forward {
                if supers.is_empty() {
                    sub_span = r.span;
                }
                supers.push(r.target);
            }
        }
        supers.dedup();
        if supers.is_empty() {
            continue;
        }
        let class = model.nodes[i].class;
        let sup = supers[0];
        if model.nodes[sup.index()].class != class {
            let s = &model.nodes[sup.index()];
            diags.push(
                Diagnostic::new(
                    Code::BadSubtype,
                    format!(
                        "{} `{}` is declared a subtype of {} {} `{}`",
                        class.name(),
                        model.nodes[i].browse_name.name,
                        article(s.class.name()),
                        s.class.name(),
                        s.browse_name.name
                    ),
                )
                .at(sub_span)
                .with_span_label("this HasSubtype reference")
                .help("a type's supertype must have the same node class"),
            );
            continue;
        }
        if supers.len() > 1 && class != NodeClass::ReferenceType {
            diags.push(
                Diagnostic::new(Code::BadSubtype, format!("`{}` has {} supertypes", model.nodes[i].browse_name.name, supers.len()))
                    .at(model.nodes[i].span)
                    .help("OPC UA types have exactly one supertype; the first is used"),
            );
        }
        model.nodes[i].super_type = Some(sup);
        let _ = ix;
    }
    // Break cycles, reporting each once.
    let mut state = vec![0u8; n]; // 0 unvisited, 1 on the current path, 2 done
    for start in 0..n {
        let mut path = Vec::new();
        let mut cur = Some(start);
        while let Some(c) = cur {
            if state[c] == 2 {
                break;
            }
            if state[c] == 1 {
                let cycle: Vec<String> = path
                    .iter()
                    .skip_while(|&&p| p != c)
                    .map(|&p: &usize| model.nodes[p].browse_name.name.clone())
                    .collect();
                diags.push(
                    Diagnostic::new(Code::SubtypeCycle, format!("subtype cycle: {} -> {}", cycle.join(" -> "), model.nodes[c].browse_name.name))
                        .at(model.nodes[c].span)
                        .help("a type cannot be its own supertype; remove one HasSubtype reference"),
                );
                model.nodes[c].super_type = None;
                break;
            }
            state[c] = 1;
            path.push(c);
            cur = model.nodes[c].super_type.map(NodeIx::index);
        }
        for p in path {
            state[p] = 2;
        }
    }
    model.index_subtypes();
    let hier = model.ns0(ids::HIERARCHICAL_REFERENCES);
    model.hierarchical = (0..n)
        .map(|i| {
            let ix = NodeIx(i as u32);
            model.nodes[i].class == NodeClass::ReferenceType
                && Some(ix) != has_subtype
                && hier.is_some_and(|h| model.is_subtype_of(ix, h))
                && !has_subtype.is_some_and(|h| model.is_subtype_of(ix, h))
        })
        .collect();

    let has_type_def = model.ns0(ids::HAS_TYPE_DEFINITION);
    let has_rule = model.ns0(ids::HAS_MODELLING_RULE);
    for i in 0..n {
        let ix = NodeIx(i as u32);
        let mut type_def = None;
        let mut rule = None;
        // Every HasModellingRule reference: (its index, target, span).
        let mut rules: Vec<(usize, NodeIx, Span)> = Vec::new();
        let mut parent = model.nodes[i].parent;
        for (k, r) in model.nodes[i].references.iter().enumerate() {
            if r.forward && Some(r.reference_type) == has_type_def {
                type_def = Some((r.target, r.span));
            } else if r.forward && Some(r.reference_type) == has_rule {
                rule = Some((r.target, r.span));
                rules.push((k, r.target, r.span));
            } else if !r.forward && parent.is_none() && model.is_hierarchical(r.reference_type) {
                parent = Some(r.target);
            }
        }
        if let Some(&(_, kept, kept_span)) = rules.last().filter(|&&(_, kept, _)| rules.iter().any(|r| r.1 != kept)) {
            // Two rules: the model keeps the last; the others leave the node tables, or a server's instantiate
            // would pick one of them by the order of its reference store.
            let name = |r: NodeIx| model.nodes[r.index()].browse_name.name.clone();
            let others: Vec<String> = rules.iter().filter(|r| r.1 != kept).map(|r| format!("`{}`", name(r.1))).collect();
            let mut d = Diagnostic::new(
                Code::TwoModellingRules,
                format!("`{}` has the ModellingRules {} and `{}`", model.nodes[i].browse_name.name, others.join(", "), name(kept)),
            )
            .at(kept_span)
            .with_span_label("the one kept");
            for &(_, r, span) in rules.iter().filter(|r| r.1 != kept) {
                d = d.label(span, format!("`{}`, left out", name(r)));
            }
            diags.push(d.help("remove the HasModellingRule reference that is wrong"));
            for &(k, r, _) in &rules {
                if r != kept {
                    model.nodes[i].references[k].declared = false;
                }
            }
        }
        let node = &model.nodes[i];
        if let Some((t, ref_span)) = type_def {
            let expected = match node.class {
                NodeClass::Object => Some(NodeClass::ObjectType),
                NodeClass::Variable => Some(NodeClass::VariableType),
                _ => None,
            };
            let actual = model.nodes[t.index()].class;
            if expected != Some(actual) {
                diags.push(
                    Diagnostic::new(
                        Code::BadTypeDefinition,
                        format!(
                            "{} `{}` has TypeDefinition `{}`, {} {}",
                            node.class.name(),
                            node.browse_name.name,
                            model.nodes[t.index()].browse_name.name,
                            article(actual.name()),
                            actual.name()
                        ),
                    )
                    .at(ref_span)
                    .with_span_label("this HasTypeDefinition reference")
                    .help(match node.class {
                        NodeClass::Object => "an Object's TypeDefinition must be an ObjectType",
                        NodeClass::Variable => "a Variable's TypeDefinition must be a VariableType",
                        _ => "only Objects and Variables have a TypeDefinition",
                    }),
                );
            } else {
                model.nodes[i].type_definition = Some(t);
            }
        } else if matches!(node.class, NodeClass::Object | NodeClass::Variable) && !broken.contains(&ix) {
            diags.push(
                Diagnostic::new(
                    Code::MissingTypeDefinition,
                    format!("{} `{}` has no HasTypeDefinition reference", node.class.name(), node.browse_name.name),
                )
                .at(node.span)
                .help("add <Reference ReferenceType=\"HasTypeDefinition\">i=58</Reference> (BaseObjectType) or the right type"),
            );
        }
        if let Some((r, rule_span)) = rule {
            let rule = match model.nodes[r.index()].id.ns0() {
                Some(ids::MANDATORY) => ModellingRule::Mandatory,
                Some(ids::OPTIONAL) => ModellingRule::Optional,
                Some(ids::EXPOSES_ITS_ARRAY) => ModellingRule::ExposesItsArray,
                Some(ids::OPTIONAL_PLACEHOLDER) => ModellingRule::OptionalPlaceholder,
                Some(ids::MANDATORY_PLACEHOLDER) => ModellingRule::MandatoryPlaceholder,
                _ => {
                    diags.push(
                        Diagnostic::new(
                            Code::BadModellingRule,
                            format!("`{}` is not a standard ModellingRule", model.nodes[r.index()].browse_name.name),
                        )
                        .at(rule_span)
                        .with_span_label("this HasModellingRule reference")
                        .help("use Mandatory, Optional, ExposesItsArray, OptionalPlaceholder or MandatoryPlaceholder"),
                    );
                    ModellingRule::Other(r)
                }
            };
            model.nodes[i].modelling_rule = Some(rule);
        }
        model.nodes[i].parent = parent;
        let _ = ix;
    }
}

/// Pass 4: the instance declarations of every ObjectType and VariableType.
fn build_members(model: &Model, diags: &mut Diagnostics) -> BTreeMap<NodeIx, Vec<Member>> {
    // Types in an order where supertypes come first.
    let types: Vec<NodeIx> = (0..model.nodes.len() as u32)
        .map(NodeIx)
        .filter(|&ix| matches!(model.node(ix).class, NodeClass::ObjectType | NodeClass::VariableType))
        .collect();
    let depths = model.type_depths();
    let mut depth: Vec<(u32, NodeIx)> = types.iter().map(|&t| (depths[t.index()], t)).collect();
    depth.sort();
    let mut members: BTreeMap<NodeIx, Vec<Member>> = BTreeMap::new();
    // A type's own children by BrowseName (reused from type to type).
    let mut own: FxHashMap<&QualifiedName, NodeIx> = FxHashMap::default();
    for (_, t) in depth {
        let mut list: Vec<Member> = model.node(t).super_type.and_then(|s| members.get(&s)).cloned().unwrap_or_default();
        own.clear();
        for (rt, child) in model.children(t) {
            let bn = &model.node(child).browse_name;
            if let Some(&prev) = own.get(bn) {
                if prev != child {
                    collision(model, t, prev, child, diags);
                }
                continue;
            }
            own.insert(bn, child);
            match list.iter_mut().find(|m| m.browse_name == *bn) {
                Some(m) => {
                    m.overrides = Some(m.node);
                    m.node = child;
                    m.declared_in = t;
                    m.reference_type = rt;
                }
                None => list.push(Member { browse_name: bn.clone(), node: child, declared_in: t, reference_type: rt, overrides: None }),
            }
        }
        members.insert(t, list);
    }
    // Collisions among the children of instances and instance declarations too.
    let mut found = Vec::new();
    for i in 0..model.nodes.len() {
        let ix = NodeIx(i as u32);
        if model.node(ix).class.is_type() {
            continue;
        }
        own.clear();
        for (_, child) in model.children(ix) {
            let bn = &model.node(child).browse_name;
            match own.get(bn) {
                Some(&prev) if prev != child => found.push((prev, child)),
                Some(_) => {}
                None => {
                    own.insert(bn, child);
                }
            }
        }
        for (a, b) in found.drain(..) {
            collision(model, ix, a, b, diags);
        }
    }
    members
}

fn collision(model: &Model, parent: NodeIx, a: NodeIx, b: NodeIx, diags: &mut Diagnostics) {
    let (na, nb) = (model.node(a), model.node(b));
    // Organizes between folders of a server's address space may legitimately reach a shared node twice.
    diags.push(
        Diagnostic::new(
            Code::BrowseNameCollision,
            format!(
                "`{}` has two children named `{}`: {} and {}",
                model.node(parent).browse_name.name,
                na.browse_name.name,
                model.display_id(&na.id),
                model.display_id(&nb.id)
            ),
        )
        .at(nb.browse_name_span)
        .with_span_label("second child with this BrowseName")
        .label(na.browse_name_span, "first child with this BrowseName")
        .help("browse paths must be unique: rename one child or give it another namespace"),
    );
}

/// Pass 6: the arguments of every method.
fn methods(model: &Model, types: &DataTypes, diags: &mut Diagnostics) -> BTreeMap<NodeIx, MethodInfo> {
    let mut out = BTreeMap::new();
    for i in 0..model.nodes.len() {
        let ix = NodeIx(i as u32);
        if model.node(ix).class != NodeClass::Method {
            continue;
        }
        let mut info = MethodInfo::default();
        for (_, child) in model.children(ix).collect::<Vec<_>>() {
            let c = model.node(child);
            let which = match (c.browse_name.ns, c.browse_name.name.as_str()) {
                (0, "InputArguments") => 0,
                (0, "OutputArguments") => 1,
                _ => continue,
            };
            let Some(value) = model.value_with(child, types) else { continue };
            let args = match value.and_then(|v| decode_arguments(model, v)) {
                Ok(a) => a,
                Err(why) => {
                    diags.push(
                        Diagnostic::new(Code::BadArgument, format!("the {} of method `{}` cannot be decoded: {why}", c.browse_name.name, model.node(ix).browse_name.name))
                            .at(c.span)
                            .help("write a ListOfExtensionObject of Argument (TypeId i=297)"),
                    );
                    continue;
                }
            };
            if which == 0 {
                info.inputs = args;
            } else {
                info.outputs = args;
            }
        }
        out.insert(ix, info);
    }
    out
}

/// The arguments in a decoded InputArguments or OutputArguments value: Argument structures, one or an array.
fn decode_arguments(model: &Model, v: Variant) -> Result<Vec<Argument>, String> {
    let items = match v {
        Variant::Array(_, items) => items,
        other => vec![other],
    };
    items
        .iter()
        .map(|it| match it {
            Variant::ExtensionObject(eo) => match eo.structure() {
                Some(s) => Argument::from_structure(model, s),
                None if eo.body.is_none() => Err("an Argument has no body".into()),
                None => Err("an element's TypeId names no Argument encoding".into()),
            },
            _ => Err("an element is not an ExtensionObject".into()),
        })
        .collect()
}

fn state_machines(model: &mut Model, diags: &mut Diagnostics) {
    let Some(sm) = model.ns0(ids::STATE_MACHINE_TYPE) else { return };
    let state_t = model.ns0(ids::STATE_TYPE);
    let initial_t = model.ns0(ids::INITIAL_STATE_TYPE);
    let trans_t = model.ns0(ids::TRANSITION_TYPE);
    let (from, to, cause, effect) =
        (model.ns0(ids::FROM_STATE), model.ns0(ids::TO_STATE), model.ns0(ids::HAS_CAUSE), model.ns0(ids::HAS_EFFECT));
    let mut out = BTreeMap::new();
    for (&t, members) in &model.members {
        if model.node(t).class != NodeClass::ObjectType || !model.is_subtype_of(t, sm) {
            continue;
        }
        let mut info = StateMachineInfo::default();
        for m in members {
            let node = model.node(m.node);
            let Some(td) = node.type_definition else { continue };
            let number = |name: &str| -> Option<u32> {
                let prop = model.children(m.node).find(|&(_, c)| model.node(c).browse_name.name == name).map(|(_, c)| c)?;
                model.value(prop)?.ok()?.as_i64().and_then(|v| u32::try_from(v).ok())
            };
            if state_t.is_some_and(|s| model.is_subtype_of(td, s)) {
                info.states.push(State {
                    node: m.node,
                    name: node.browse_name.name.clone(),
                    number: number("StateNumber"),
                    initial: initial_t.is_some_and(|s| model.is_subtype_of(td, s)),
                });
            } else if trans_t.is_some_and(|s| model.is_subtype_of(td, s)) {
                let mut tr = Transition {
                    node: m.node,
                    name: node.browse_name.name.clone(),
                    number: number("TransitionNumber"),
                    from: None,
                    to: None,
                    causes: Vec::new(),
                    effects: Vec::new(),
                };
                for r in node.references.iter().filter(|r| r.forward) {
                    let rt = Some(r.reference_type);
                    if rt == from {
                        tr.from = Some(r.target);
                    } else if rt == to {
                        tr.to = Some(r.target);
                    } else if rt == cause {
                        tr.causes.push(r.target);
                    } else if rt == effect {
                        tr.effects.push(r.target);
                    }
                }
                info.transitions.push(tr);
            }
        }
        for tr in &info.transitions {
            for (what, end) in [("FromState", tr.from), ("ToState", tr.to)] {
                match end {
                    None if !model.node(t).is_abstract() => diags.push(
                        Diagnostic::new(Code::StateMachine, format!("transition `{}` of `{}` has no {what}", tr.name, model.node(t).browse_name.name))
                            .at(model.node(tr.node).span)
                            .help(format!("add a {what} reference to one of the machine's states")),
                    ),
                    Some(s) if !info.states.iter().any(|st| st.node == s) && model.node(s).class != NodeClass::Object => diags.push(
                        Diagnostic::new(Code::StateMachine, format!("{what} of transition `{}` is not a state", tr.name))
                            .at(model.node(tr.node).span)
                            .help("point it at a State object"),
                    ),
                    _ => {}
                }
            }
        }
        if !info.states.is_empty() || !info.transitions.is_empty() {
            info.event_type = transition_event_type(model, t, &info);
            out.insert(t, info);
        }
    }
    model.state_machines = out;
}

/// The event type a transition of state machine type `t` raises (see [`StateMachineInfo::event_type`]).
fn transition_event_type(model: &Model, t: NodeIx, info: &StateMachineInfo) -> Option<NodeIx> {
    let base = model.ns0(ids::TRANSITION_EVENT_TYPE)?;
    let generates = model.ns0(ids::GENERATES_EVENT);
    let concrete = |e: NodeIx| model.is_subtype_of(e, base) && !model.node(e).is_abstract();
    for s in model.super_chain(t) {
        let mut named: Vec<NodeIx> = model
            .node(s)
            .references
            .iter()
            .filter(|r| r.forward && Some(r.reference_type) == generates && concrete(r.target))
            .map(|r| r.target)
            .collect();
        named.sort_by(|a, b| model.node(*a).id.cmp(&model.node(*b).id));
        if let Some(&e) = named.first() {
            return Some(e);
        }
    }
    // The effects the transitions name; of several, the one most transitions name, then the lowest NodeId.
    let mut effects: BTreeMap<NodeIx, usize> = BTreeMap::new();
    for tr in &info.transitions {
        for &e in tr.effects.iter().filter(|&&e| model.is_subtype_of(e, base)) {
            *effects.entry(e).or_default() += 1;
        }
    }
    let effect = effects.iter().max_by(|a, b| a.1.cmp(b.1).then(model.node(*b.0).id.cmp(&model.node(*a.0).id))).map(|(&e, _)| e);
    let chain = effect.map(|e| model.super_chain(e)).unwrap_or_default();
    Some(chain.into_iter().find(|&e| concrete(e)).unwrap_or(base))
}

/// Whether a value of built-in type `have` may stand for DataType `dt`.
fn value_fits(model: &Model, data_types: &BTreeMap<NodeIx, DataTypeInfo>, dt: NodeIx, have: BuiltinType) -> bool {
    let Some(info) = data_types.get(&dt) else { return true };
    match &info.kind {
        DataTypeKind::AbstractBuiltin => {
            let n = model.node(dt).id.ns0();
            match n {
                Some(ids::NUMBER) => have.is_number(),
                Some(ids::INTEGER) => have.is_integer() && !have.is_unsigned() || have.is_integer(),
                Some(ids::UINTEGER) => have.is_unsigned(),
                _ => true,
            }
        }
        DataTypeKind::Builtin(BuiltinType::Variant) => true,
        DataTypeKind::Enumeration { .. } => have == BuiltinType::Int32,
        DataTypeKind::Structure { .. } => have == BuiltinType::ExtensionObject,
        _ => info.encoding == have || (info.encoding == BuiltinType::ExtensionObject && have == BuiltinType::ExtensionObject),
    }
}

/// Pass 8: every value in a type (an InstanceDeclaration's, a VariableType's, a DataType's EnumStrings) and in
/// namespace 0 against its node's DataType (given before they join the model) and ValueRank: NS0209. The
/// values of the files' instances ([`Model::instance_nodes`]) are not checked here: the instance rules,
/// which `check` and `verify` share, check them (NS0406), so that one defect is one finding with one code.
/// Every value is decoded here either way, so an undecodable one is NS0214 wherever it is.
fn check_values(model: &Model, data_types: &BTreeMap<NodeIx, DataTypeInfo>, diags: &mut Diagnostics) {
    let instance = model.instance_nodes();
    for (i, node) in model.nodes.iter().enumerate() {
        let ix = NodeIx(i as u32);
        // The check needs the type and shape of the value only, not copies of what it holds.
        let Some(xml) = model.value_element(ix) else { continue };
        let v = match model.decode_value(ix, Content::Shape) {
            Some(Ok(v)) => v,
            Some(Err(why)) => {
                diags.push(
                    Diagnostic::new(Code::BadValue, format!("the value of `{}` cannot be decoded: {why}", node.browse_name.name))
                        .at(xml.span())
                        .help("see OPC UA Part 6, 5.3 for the XML encoding of values"),
                );
                continue;
            }
            None => continue,
        };
        if instance[i] {
            continue;
        }
        let Some(dt) = node.attrs.data_type else { continue };
        let Some(have) = v.builtin() else { continue };
        if !value_fits(model, data_types, dt, have) {
            diags.push(
                Diagnostic::new(
                    Code::ValueTypeMismatch,
                    format!(
                        "the value of `{}` is a {}, but its DataType is {}",
                        node.browse_name.name,
                        xml.name(),
                        model.node(dt).browse_name.name
                    ),
                )
                .at(xml.span())
                .with_span_label(format!("a {}", have.type_name()))
                .help("a server would reject this value; write it in the DataType's encoding"),
            );
            continue;
        }
        let rank = node.attrs.value_rank.unwrap_or(-1);
        if v.is_array() && rank == -1 || !v.is_array() && rank >= 1 {
            diags.push(
                Diagnostic::new(
                    Code::ValueTypeMismatch,
                    format!(
                        "the value of `{}` is {}, but its ValueRank is {rank}",
                        node.browse_name.name,
                        if v.is_array() { "an array" } else { "a scalar" }
                    ),
                )
                .at(xml.span())
                .help("ValueRank -1 is a scalar, 1 an array, 0 one or more dimensions, -2 any, -3 scalar or array"),
            );
        }
    }
}
