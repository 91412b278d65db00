//! The instance rules: a pure function of the resolved model and a [`Snapshot`], read from a live server
//! (`verify`, [`super::client`]) or made from the static instances of the files (`check`,
//! [`super::instances`]), so that both apply the same rules with the same codes and severities.
//!
//! Every instance is checked against a *declaration*: the instance declaration it fills (a member of its
//! parent's type, or of the parent's own declaration), or, for an instance that fills none (a top-level
//! object, a child of a folder without placeholders), its own TypeDefinition. The expected children of a
//! node are the members of its declaration that have a ModellingRule, merged by BrowseName with those of
//! its actual TypeDefinition (which may be a subtype with more). Each server node is checked once, the
//! first time the walk (in the server's browse order) reaches it.

use super::{RemoteNode, RemoteValue, Snapshot};
use crate::diag::{Code, Diagnostic, Diagnostics, Severities};
use crate::model::{ids, Member, Model, ModellingRule, NodeIx};
use crate::nodeid::{Identifier, NodeId, QualifiedName};
use crate::raw::NodeClass;
use crate::source::SourceMap;
use crate::value::BuiltinType;
use std::collections::BTreeSet;

/// One violation: the diagnostic (its primary span is the violated declaration in its NodeSet2 file)
/// and where on the server it was found.
#[derive(Clone, Debug)]
pub struct Finding {
    /// What is wrong, pointing at the violated declaration in its NodeSet2 file.
    pub diagnostic: Diagnostic,
    /// The browse path from the Objects folder, BrowseNames joined by `/` (namespace prefixes as the
    /// server numbers them, as in `2:DeviceSet/4:Robot`).
    pub path: String,
    /// The server node, as `ns=N;i=M` in the server's numbering (the parent's for a missing member).
    pub node: String,
    /// The same node as a NodeId, in the snapshot's numbering.
    pub id: NodeId,
}

/// What [`check`] found.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Violations and warnings, in the order of the walk until [`Report::apply`] sorts them.
    pub findings: Vec<Finding>,
    /// Server nodes checked against a declaration or a type.
    pub checked: usize,
    /// Instances checked against their TypeDefinition as a whole (the roots of the walk).
    pub instances: usize,
    /// Server namespaces no loaded nodeset defines (their nodes are not checked against types).
    pub unknown_namespaces: Vec<String>,
    /// The snapshot's NamespaceArray: what the namespace prefixes of the paths (`2:DeviceSet`) number.
    pub namespaces: Vec<String>,
    /// Round trips of the snapshot.
    pub round_trips: u32,
    /// Variables read from a server whose value in the nodesets holds structures, compared field by field
    /// with what the server sent (`verify::structures`; a static snapshot holds no bytes to compare).
    pub structures_compared: usize,
    /// Each of them whose content differs: its path and the first difference.
    pub structure_mismatches: Vec<String>,
}

impl Report {
    /// The findings as diagnostics (for rendering with the model's sources).
    pub fn diagnostics(&self) -> Diagnostics {
        Diagnostics { items: self.findings.iter().map(|f| f.diagnostic.clone()).collect() }
    }

    /// Findings of error severity.
    pub fn violations(&self) -> usize {
        self.findings.iter().filter(|f| f.diagnostic.is_error()).count()
    }

    /// Findings of warning severity.
    pub fn warnings(&self) -> usize {
        self.findings.len() - self.violations()
    }

    /// Gives every finding the severity `severities` sets for its code (`--allow NS0408` drops them,
    /// `--warn NS0401` makes them warnings, `--deny warnings` makes every warning a violation), then sorts
    /// the findings by browse path, code and declaration, so that the report does not depend on the order
    /// the server listed its nodes in.
    pub fn apply(&mut self, severities: &Severities, sources: &SourceMap) {
        self.findings.retain_mut(|f| match severities.severity(f.diagnostic.code, f.diagnostic.severity) {
            Some(s) => {
                f.diagnostic.severity = s;
                true
            }
            None => false,
        });
        self.sort(sources);
    }

    /// Sorts the findings by browse path, code, server node, declaration (file and offset) and message.
    pub fn sort(&mut self, sources: &SourceMap) {
        let place = |f: &Finding| f.diagnostic.span.map(|s| (sources.get(s.file).display.clone(), s.start));
        self.findings.sort_by(|a, b| {
            (&a.path, a.diagnostic.code, &a.node, place(a), &a.diagnostic.message).cmp(&(
                &b.path,
                b.diagnostic.code,
                &b.node,
                place(b),
                &b.diagnostic.message,
            ))
        });
    }
}

/// Checks every instance of the snapshot against the model, walking from the Objects folder.
pub fn check(model: &Model, snap: &Snapshot) -> Report {
    check_from(model, snap, &[])
}

/// [`check`], then every node of `more` the walk from the Objects folder did not reach, in that order, as an
/// instance of its own type, below the browse path given with it (the nodes of a file that hang elsewhere,
/// such as below the Server object, or nowhere).
pub fn check_from(model: &Model, snap: &Snapshot, more: &[(NodeId, String)]) -> Report {
    let to_model: Vec<Option<u16>> =
        snap.namespaces.iter().map(|uri| model.namespaces.iter().position(|m| m == uri).map(|i| i as u16)).collect();
    let unknown_namespaces = snap
        .namespaces
        .iter()
        .enumerate()
        .filter(|(i, _)| *i > 1 && to_model[*i].is_none())
        .map(|(_, u)| u.clone())
        .collect();
    let mut c = Checker { model, snap, to_model, seen: BTreeSet::new(), report: Report::default() };
    c.report.unknown_namespaces = unknown_namespaces;
    c.report.namespaces = snap.namespaces.clone();
    c.report.round_trips = snap.round_trips;
    let root = Snapshot::objects_folder();
    if let Some(objects) = snap.nodes.get(&root) {
        for child in c.children(objects) {
            if child.ns != 0 {
                c.root(&child, "");
            }
        }
    }
    for (id, parent_path) in more {
        if !c.seen.contains(id) {
            c.root(id, parent_path);
        }
    }
    c.report
}

struct Checker<'a> {
    model: &'a Model,
    snap: &'a Snapshot,
    to_model: Vec<Option<u16>>,
    seen: BTreeSet<NodeId>,
    report: Report,
}

/// The server node's name in a path: `ns:Name`, or `Name` in namespace 0.
fn path_segment(bn: &QualifiedName) -> String {
    if bn.ns == 0 {
        bn.name.clone()
    } else {
        format!("{}:{}", bn.ns, bn.name)
    }
}

fn join(path: &str, bn: &QualifiedName) -> String {
    if path.is_empty() {
        path_segment(bn)
    } else {
        format!("{path}/{}", path_segment(bn))
    }
}

/// `ns=N;i=M` (or `s=`, `g=`, `b=`) in the server's numbering.
pub fn format_node_id(id: &NodeId) -> String {
    let ident = match &id.id {
        Identifier::Numeric(n) => format!("i={n}"),
        Identifier::String(s) => format!("s={s}"),
        Identifier::Guid(g) => format!("g={}", crate::nodeid::format_guid(g)),
        Identifier::Opaque(b) => format!("b={}", crate::nodeid::base64_encode(b)),
    };
    if id.ns == 0 {
        ident
    } else {
        format!("ns={};{ident}", id.ns)
    }
}

/// Whether a ValueRank is allowed where `declared` is declared (OPC UA Part 3, 5.6.2).
pub fn rank_compatible(declared: i32, actual: i32) -> bool {
    match declared {
        -3 => matches!(actual, -3 | -1 | 1),
        -2 => true,
        -1 => actual == -1,
        0 => actual == 0 || actual >= 1,
        n => actual == n,
    }
}

impl<'a> Checker<'a> {
    /// A server NodeId in the model's numbering, if its namespace is loaded.
    fn map(&self, id: &NodeId) -> Option<NodeId> {
        let ns = (*self.to_model.get(id.ns as usize)?)?;
        Some(NodeId { ns, id: id.id.clone() })
    }

    fn lookup(&self, id: &NodeId) -> Option<NodeIx> {
        self.map(id).and_then(|m| self.model.lookup(&m))
    }

    fn map_name(&self, bn: &QualifiedName) -> Option<QualifiedName> {
        let ns = (*self.to_model.get(bn.ns as usize)?)?;
        Some(QualifiedName { ns, name: bn.name.clone() })
    }

    fn target_of(&self, node: &'a RemoteNode, reference_type: u32) -> Option<&'a NodeId> {
        let want = NodeId::numeric(0, reference_type);
        node.references.iter().find(|r| r.reference_type == want).map(|r| &r.target)
    }

    /// The forward hierarchical children of a server node (each once), ordered by BrowseName (namespace URI,
    /// then name), then NodeId (namespace URI, then identifier): not in the server's browse order, so that
    /// a node with two hierarchical parents is reached first by the same path on every server and in
    /// `check`'s snapshot of the files (AML's libraries hang below two folders).
    fn children(&self, node: &RemoteNode) -> Vec<NodeId> {
        let mut out: Vec<NodeId> = Vec::new();
        let has_subtype = self.model.ns0(ids::HAS_SUBTYPE);
        for r in &node.references {
            let rt = self.lookup(&r.reference_type);
            let hierarchical = rt.is_some_and(|rt| self.model.is_hierarchical(rt)) && rt != has_subtype;
            if hierarchical && !out.contains(&r.target) {
                out.push(r.target.clone());
            }
        }
        let uri = |ns: u16| self.snap.namespaces.get(ns as usize).cloned().unwrap_or_default();
        out.sort_by_cached_key(|id| {
            let name = self.snap.nodes.get(id).map(|n| (uri(n.browse_name.ns), n.browse_name.name.clone()));
            (name, uri(id.ns), format_node_id(&NodeId { ns: 0, id: id.id.clone() }))
        });
        out
    }

    /// The reference type a parent uses for a child.
    fn reference_to(&self, parent: &RemoteNode, child: &NodeId) -> Option<NodeIx> {
        parent.references.iter().filter(|r| &r.target == child).find_map(|r| self.lookup(&r.reference_type))
    }

    fn push(&mut self, d: Diagnostic, path: &str, node: &NodeId) {
        self.report.findings.push(Finding { diagnostic: d, path: path.to_owned(), node: format_node_id(node), id: node.clone() });
    }

    /// Checks a node that fills no declaration: against its own TypeDefinition.
    fn root(&mut self, id: &NodeId, parent_path: &str) {
        let Some(node) = self.snap.nodes.get(id) else { return };
        let path = join(parent_path, &node.browse_name);
        self.report.instances += 1;
        self.visit(node, &path, None);
    }

    /// Checks `node` (found at `path`) against the declaration `decl` (None: its TypeDefinition only),
    /// then its children.
    fn visit(&mut self, node: &'a RemoteNode, path: &str, decl: Option<NodeIx>) {
        if !self.seen.insert(node.id.clone()) {
            return;
        }
        self.report.checked += 1;
        let model = self.model;
        let remote_type = if matches!(node.class, NodeClass::Object | NodeClass::Variable) {
            self.target_of(node, ids::HAS_TYPE_DEFINITION)
        } else {
            None
        };
        let actual_type = remote_type.and_then(|t| self.lookup(t));
        if let (Some(t), None) = (remote_type, actual_type) {
            let d = Diagnostic::new(
                Code::UnknownRemoteType,
                format!("`{path}` is of type {}, which no loaded nodeset defines; its members are not checked", format_node_id(t)),
            )
            .help("name the nodeset of that namespace, or put it in a --models folder");
            self.push(d, path, &node.id);
        }
        if let Some(rule) = self.target_of(node, ids::HAS_MODELLING_RULE) {
            let rule_name = self.lookup(rule).map(|r| model.node(r).browse_name.name.clone()).unwrap_or_else(|| format_node_id(rule));
            let mut d = Diagnostic::new(
                Code::InstanceModellingRule,
                format!("instance `{path}` has the ModellingRule {rule_name}; only instance declarations in types have one"),
            )
            .help("remove the HasModellingRule reference from the instance");
            if let Some(at) = decl.or(actual_type) {
                d = d.at(model.node(at).span).with_span_label("the declaration the instance was created from");
            }
            self.push(d, path, &node.id);
        }
        if let Some(d) = decl {
            self.check_against(node, path, d, actual_type);
        }
        if node.class == NodeClass::Variable {
            self.check_variable(node, path, decl.or(actual_type));
            #[cfg(feature = "verify")]
            self.compare_structure(node, path, decl);
        }
        self.check_children(node, path, decl, actual_type);
    }

    /// The content of a structure value read from a server against the nodesets: a static instance's own
    /// value, or, for an instance created from a declaration outside ns0 (whose value it copies), the
    /// declaration's. ns0's declarations are left out: async-opcua serves its own ns0 values.
    #[cfg(feature = "verify")]
    fn compare_structure(&mut self, node: &'a RemoteNode, path: &str, decl: Option<NodeIx>) {
        let Some(got) = &node.extension_objects else { return };
        let model = self.model;
        let variable = |ix: NodeIx| model.node(ix).class == NodeClass::Variable;
        let source = match self.lookup(&node.id) {
            Some(own) => Some(own).filter(|&ix| variable(ix)),
            None => decl.filter(|&d| variable(d) && model.node(d).id.ns != 0),
        };
        let Some(ix) = source else { return };
        let to_server = |ns: u16| self.to_model.iter().position(|m| *m == Some(ns)).and_then(|i| u16::try_from(i).ok());
        match super::structures::compare(model, ix, got, &to_server) {
            Ok(false) => {}
            Ok(true) => self.report.structures_compared += 1,
            Err(e) => {
                self.report.structures_compared += 1;
                self.report.structure_mismatches.push(format!("{path}: {e}"));
            }
        }
    }

    /// NodeClass and TypeDefinition against the declaration.
    fn check_against(&mut self, node: &'a RemoteNode, path: &str, decl: NodeIx, actual_type: Option<NodeIx>) {
        let model = self.model;
        let dn = model.node(decl);
        if dn.class != node.class && !dn.class.is_type() {
            let d = Diagnostic::new(
                Code::WrongNodeClass,
                format!("`{path}` is {} {}, but its declaration is {} {}", crate::model::article(node.class.name()), node.class.name(), crate::model::article(dn.class.name()), dn.class.name()),
            )
            .at(dn.span)
            .with_span_label(format!("declared as {} {}", crate::model::article(dn.class.name()), dn.class.name()));
            self.push(d, path, &node.id);
            return;
        }
        let declared_type = if dn.class.is_type() { Some(decl) } else { dn.type_definition };
        if let (Some(want), Some(have)) = (declared_type, actual_type) {
            if !model.is_subtype_of(have, want) {
                let d = Diagnostic::new(
                    Code::WrongTypeDefinition,
                    format!("`{path}` is of type {}, which is not {} or a subtype of it", model.qualified(have), model.qualified(want)),
                )
                .at(dn.span)
                .with_span_label(format!("declared with the type {}", model.qualified(want)));
                self.push(d, path, &node.id);
            }
        }
    }

    /// DataType, ValueRank and the value against the declaration (or the VariableType); without either (a
    /// variable without a TypeDefinition), the value against the variable's own DataType and ValueRank.
    fn check_variable(&mut self, node: &'a RemoteNode, path: &str, decl: Option<NodeIx>) {
        let model = self.model;
        let dn = decl.map(|d| model.node(d));
        // The violated declaration, when there is one, is where a finding points.
        let at = |d: Diagnostic, label: String| match dn {
            Some(dn) => d.at(dn.span).with_span_label(label),
            None => d,
        };
        let base = model.ns0(ids::BASE_DATA_TYPE);
        let declared_dt = dn.and_then(|dn| dn.attrs.data_type).or(base);
        let actual_dt = match &node.data_type {
            Some(id) => match self.lookup(id) {
                Some(ix) => Some(ix),
                None => {
                    let mut d = Diagnostic::new(
                        Code::UnknownRemoteType,
                        format!("`{path}` has the DataType {}, which no loaded nodeset defines", format_node_id(id)),
                    )
                    .help("name the nodeset of that namespace, or put it in a --models folder");
                    if let Some(dn) = dn {
                        d = d.at(dn.span);
                    }
                    self.push(d, path, &node.id);
                    None
                }
            },
            None => None,
        };
        if let (Some(want), Some(have), true) = (declared_dt, actual_dt, dn.is_some()) {
            if !model.is_subtype_of(have, want) {
                let d = Diagnostic::new(
                    Code::WrongDataType,
                    format!("`{path}` has the DataType {}, which is not {} or a subtype of it", model.qualified(have), model.qualified(want)),
                );
                self.push(at(d, format!("declared with the DataType {}", model.qualified(want))), path, &node.id);
            }
        }
        // A VariableType's ValueRank constrains its instances as an instance declaration's does.
        let declared_rank = dn.and_then(|dn| dn.attrs.value_rank).unwrap_or(-1);
        if let (Some(rank), true) = (node.value_rank, dn.is_some()) {
            if !rank_compatible(declared_rank, rank) {
                let d = Diagnostic::new(
                    Code::WrongValueRank,
                    format!("`{path}` has the ValueRank {rank}, which the declared ValueRank {declared_rank} does not allow"),
                );
                self.push(at(d, format!("declared with the ValueRank {declared_rank}")), path, &node.id);
            }
        }
        let dt = actual_dt.or(declared_dt);
        let rank = node.value_rank.unwrap_or(declared_rank);
        if let (Some(dt), Some(value)) = (dt, node.value) {
            let (got, array) = match value {
                RemoteValue::Empty => return,
                RemoteValue::Scalar(b) => (b, false),
                RemoteValue::Array(b) => (b, true),
            };
            let expected = encoding_of(model, dt);
            let type_ok = accepts(model, dt, got);
            let shape_ok = match rank {
                -1 => !array,
                -3 | -2 => true,
                _ => array,
            };
            if !type_ok || !shape_ok {
                let shape = if array { "an array of" } else { "a scalar" };
                let want = match expected {
                    Some(b) => format!("{} ({b:?})", model.qualified(dt)),
                    None => model.qualified(dt),
                };
                let d = Diagnostic::new(
                    Code::WrongValueType,
                    format!("`{path}` holds {shape} {got:?}, but its DataType is {want} and its ValueRank {rank}"),
                )
                .help("a client decodes the value by its DataType: give it the DataType's encoding (an enumeration is an Int32)");
                self.push(at(d, format!("declared with the DataType {}", model.qualified(dt))), path, &node.id);
            }
        }
    }

    /// The members the children of `node` must fill.
    fn expected(&self, decl: Option<NodeIx>, actual_type: Option<NodeIx>) -> Vec<Member> {
        let model = self.model;
        let type_members = |t: NodeIx| -> Vec<Member> {
            model.members.get(&t).map(|m| m.iter().filter(|m| model.node(m.node).modelling_rule.is_some()).cloned().collect()).unwrap_or_default()
        };
        let mut out: Vec<Member> = match decl {
            Some(d) if model.node(d).class.is_type() => type_members(d),
            Some(d) => model.instance_members(d).into_iter().filter(|m| model.node(m.node).modelling_rule.is_some()).collect(),
            None => Vec::new(),
        };
        if let Some(t) = actual_type {
            for m in type_members(t) {
                if !out.iter().any(|o| o.browse_name == m.browse_name) {
                    out.push(m);
                }
            }
        }
        out
    }

    fn check_children(&mut self, node: &'a RemoteNode, path: &str, decl: Option<NodeIx>, actual_type: Option<NodeIx>) {
        let model = self.model;
        let snap = self.snap;
        let expected = self.expected(decl, actual_type);
        let children = self.children(node);
        let mut filled = vec![false; children.len()];
        let names: Vec<Option<QualifiedName>> =
            children.iter().map(|c| snap.nodes.get(c).and_then(|n| self.map_name(&n.browse_name))).collect();
        for m in expected.iter().filter(|m| !model.node(m.node).modelling_rule.is_some_and(ModellingRule::is_placeholder)) {
            match names.iter().position(|n| n.as_ref() == Some(&m.browse_name)) {
                Some(i) => {
                    filled[i] = true;
                    if let Some(child) = snap.nodes.get(&children[i]) {
                        let child_path = join(path, &child.browse_name);
                        self.visit(child, &child_path, Some(m.node));
                    }
                }
                None if model.node(m.node).modelling_rule == Some(ModellingRule::Mandatory) => {
                    let member = model.node(m.node);
                    let want = format!("{}:{}", self.server_ns(m.browse_name.ns), m.browse_name.name);
                    let mut d = Diagnostic::new(
                        Code::MissingMember,
                        format!("`{path}` has no mandatory {} `{want}`", member.class.name()),
                    )
                    .at(member.span)
                    .with_span_label(format!("declared Mandatory in {}", model.qualified(m.declared_in)));
                    // A child of that name in another namespace is what the server meant: it is reported here
                    // once and checked against the declaration, not taken for a placeholder's filler.
                    let same = (0..children.len())
                        .filter(|&i| !filled[i])
                        .find(|&i| snap.nodes.get(&children[i]).is_some_and(|c| c.browse_name.name == m.browse_name.name));
                    let same = same.and_then(|i| {
                        filled[i] = true;
                        snap.nodes.get(&children[i])
                    });
                    if let Some(same) = same {
                        d = d.note(format!(
                            "a child named `{}` exists, in namespace {} rather than {}",
                            same.browse_name.name,
                            same.browse_name.ns,
                            self.server_ns(m.browse_name.ns)
                        ));
                    }
                    self.push(d, path, &node.id);
                    if let Some(same) = same {
                        let child_path = join(path, &same.browse_name);
                        self.visit(same, &child_path, Some(m.node));
                    }
                }
                None => {}
            }
        }
        let placeholders: Vec<&Member> =
            expected.iter().filter(|m| model.node(m.node).modelling_rule.is_some_and(ModellingRule::is_placeholder)).collect();
        let mut used: BTreeSet<NodeIx> = BTreeSet::new();
        for (i, id) in children.iter().enumerate() {
            if filled[i] {
                continue;
            }
            let Some(child) = snap.nodes.get(id) else { continue };
            let reference = self.reference_to(node, id);
            let places: Vec<&&Member> = placeholders
                .iter()
                .filter(|m| model.node(m.node).class == child.class)
                .filter(|m| reference.is_none_or(|r| model.is_subtype_of(r, m.reference_type)))
                .collect();
            if places.is_empty() {
                self.root(id, path);
                continue;
            }
            let child_type = self.target_of(child, ids::HAS_TYPE_DEFINITION).and_then(|t| self.lookup(t));
            let type_fits = |m: &&&Member| match (model.node(m.node).type_definition, child_type) {
                (Some(want), Some(have)) => model.is_subtype_of(have, want),
                _ => true,
            };
            // Of the placeholders of its type, a variable stands in the place of one whose DataType it has
            // (Safety's SafetyPDUsType: `<RequestSPDU>` and `<ResponseSPDU>` are both BaseDataVariables).
            let child_dt = child.data_type.as_ref().and_then(|d| self.lookup(d));
            let data_type_fits = |m: &&&Member| match (model.node(m.node).attrs.data_type, child_dt) {
                (Some(want), Some(have)) => model.is_subtype_of(have, want),
                _ => true,
            };
            let fits = places.iter().find(|m| type_fits(m) && data_type_fits(m)).or_else(|| places.iter().find(|m| type_fits(m)));
            let child_path = join(path, &child.browse_name);
            match fits {
                Some(m) => {
                    used.insert(m.node);
                    self.visit(child, &child_path, Some(m.node))
                }
                // Part 3 lets an instance have components its type does not declare, so outside a folder a
                // child of another type is an addition, checked against its own type. A folder that declares
                // placeholders (MotionDevices, Controllers) holds only what fills them.
                None if !actual_type.is_some_and(|t| model.is_subtype_of_ns0(t, ids::FOLDER_TYPE)) => self.root(id, path),
                None => {
                    let m = places[0];
                    let want = model.node(m.node).type_definition.map(|t| model.qualified(t)).unwrap_or_default();
                    let have = child_type.map(|t| model.qualified(t)).unwrap_or_else(|| "unknown".into());
                    let d = Diagnostic::new(
                        Code::WrongPlaceholderType,
                        format!("`{child_path}` stands in the place of `{}` but is of type {have}, not {want} or a subtype", model.node(m.node).browse_name.name),
                    )
                    .at(model.node(m.node).span)
                    .with_span_label(format!("placeholder of the type {want}"));
                    self.push(d, &child_path, &child.id);
                    self.report.instances += 1;
                    self.visit(child, &child_path, None);
                }
            }
        }
        for m in placeholders {
            let member = model.node(m.node);
            // A MandatoryPlaceholder is filled by any child that fits it, a declared member included: DI's
            // `ParameterSet/<ParameterIdentifier>` is filled by Robotics' `ParameterSet/SpeedOverride`.
            let fitting = |id: &NodeId| {
                let Some(child) = snap.nodes.get(id) else { return false };
                let reference = self.reference_to(node, id);
                let child_type = self.target_of(child, ids::HAS_TYPE_DEFINITION).and_then(|t| self.lookup(t));
                child.class == member.class
                    && reference.is_none_or(|r| model.is_subtype_of(r, m.reference_type))
                    && match (member.type_definition, child_type) {
                        (Some(want), Some(have)) => model.is_subtype_of(have, want),
                        _ => true,
                    }
            };
            if member.modelling_rule == Some(ModellingRule::MandatoryPlaceholder)
                && !used.contains(&m.node)
                && !children.iter().any(fitting)
            {
                let want = member.type_definition.map(|t| model.qualified(t)).unwrap_or_else(|| member.class.name().to_owned());
                let d = Diagnostic::new(
                    Code::MissingMember,
                    format!("`{path}` has nothing in the place of the mandatory placeholder `{}` (at least one {want})", m.browse_name.name),
                )
                .at(member.span)
                .with_span_label(format!("declared MandatoryPlaceholder in {}", model.qualified(m.declared_in)));
                self.push(d, path, &node.id);
            }
        }
    }

    /// The server's index of a model namespace (for messages in the server's numbering).
    fn server_ns(&self, model_ns: u16) -> usize {
        self.to_model.iter().position(|m| *m == Some(model_ns)).unwrap_or(model_ns as usize)
    }
}

/// The built-in type values of `dt` are encoded as, where there is exactly one.
fn encoding_of(model: &Model, dt: NodeIx) -> Option<BuiltinType> {
    use crate::model::DataTypeKind;
    let info = model.data_types.get(&dt)?;
    match info.kind {
        DataTypeKind::AbstractBuiltin => None,
        _ if info.encoding == BuiltinType::Variant => None,
        _ => Some(info.encoding),
    }
}

/// Whether a value of the built-in type `got` is a value of the DataType `dt`.
pub fn accepts(model: &Model, dt: NodeIx, got: BuiltinType) -> bool {
    use BuiltinType as B;
    let numeric = |b: B| matches!(b, B::SByte | B::Byte | B::Int16 | B::UInt16 | B::Int32 | B::UInt32 | B::Int64 | B::UInt64 | B::Float | B::Double);
    if model.is_ns0(dt, ids::BASE_DATA_TYPE) {
        return true;
    }
    if model.is_ns0(dt, ids::INTEGER) {
        return matches!(got, B::SByte | B::Int16 | B::Int32 | B::Int64);
    }
    if model.is_ns0(dt, ids::UINTEGER) {
        return matches!(got, B::Byte | B::UInt16 | B::UInt32 | B::UInt64);
    }
    if model.is_ns0(dt, ids::NUMBER) || model.is_ns0(dt, ids::DECIMAL) {
        return numeric(got) || got == B::ExtensionObject;
    }
    if model.is_subtype_of_ns0(dt, ids::ENUMERATION) && !model.is_subtype_of_ns0(dt, ids::OPTION_SET) {
        return got == B::Int32;
    }
    if model.is_subtype_of_ns0(dt, ids::STRUCTURE) {
        return got == B::ExtensionObject;
    }
    match encoding_of(model, dt) {
        Some(want) => want == got,
        None => true,
    }
}

#[cfg(test)]
mod tests;
