//! Pass 5: the fully-inherited InstanceDeclaration hierarchy (OPC UA Part 3, 6.3.3; `notes/inheritance.md`).
//!
//! A type's instances contain, path by path, the declarations of the type merged with those of its
//! supertypes: where a subtype declares a member at a browse path its supertype already declares, the
//! subtype's declaration wins, and every path the subtype does not redeclare keeps the supertype's
//! declaration, at any depth. So a vendor `MotionDeviceType` subtype that declares its own `ParameterSet`
//! with two variables still has `ParameterSet/SpeedOverride` from Robotics.
//!
//! The whole rule is one datum per declaration, computed here and stored in [`Model::overridden`]: the
//! declaration each InstanceDeclaration overrides, the one found at the same browse path when the
//! declaration itself is left out. Every consumer reads the merged members through
//! [`Model::instance_members`], which follows that chain: `check --show`, both back ends, `verify`, and the
//! runtime's `instantiate` (through the links the Rust back end writes into the node tables).
//!
//! What a declaration overrides is decided where it stands: for a member of a type, the member of the same
//! BrowseName of the supertype; for a child of a declaration `c`, the member of that BrowseName among the
//! members `c` would have without its own children (those of the declarations `c` overrides, then of the
//! TypeDefinitions). Each override is checked against what it overrides (NodeClass, TypeDefinition,
//! DataType, ModellingRule); a mismatch is a warning of the nodeset, never a silent choice.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::fxhash::FxHashMap;
use crate::model::{Model, ModellingRule, NodeIx};
use crate::raw::NodeClass;
use std::collections::BTreeMap;

/// How deep declarations may nest below a type, and how long an override chain may be (guards against
/// nodesets whose declarations contain themselves).
const MAX_DEPTH: usize = 32;

/// The declaration each InstanceDeclaration overrides, for every type of the model.
pub(crate) fn overrides(model: &Model, diags: &mut Diagnostics) -> BTreeMap<NodeIx, NodeIx> {
    let mut pass = Pass { model, links: BTreeMap::new(), state: FxHashMap::default(), found: Vec::new() };
    for i in 0..model.nodes.len() {
        let t = NodeIx(i as u32);
        if matches!(model.node(t).class, NodeClass::ObjectType | NodeClass::VariableType) {
            pass.visit_type(t, 0);
        }
    }
    // Checked in NodeId order of the override, so the diagnostics come in a stable order.
    pass.found.sort();
    pass.found.dedup();
    for (decl, over) in pass.found {
        check(model, decl, over, diags);
    }
    pass.links
}

#[derive(Clone, Copy, PartialEq)]
enum State {
    Visiting,
    Done,
}

struct Pass<'m> {
    model: &'m Model,
    links: BTreeMap<NodeIx, NodeIx>,
    state: FxHashMap<NodeIx, State>,
    /// Every (override, overridden) pair, to check once all links are known.
    found: Vec<(NodeIx, NodeIx)>,
}

impl Pass<'_> {
    /// Links the declarations of type `t`, after those of the types its links can lead into. `nesting`
    /// counts how many types are being visited on the way here, so that no input can exhaust the stack; a
    /// type met again while it is being visited (a declaration whose TypeDefinition contains it) is used
    /// with the links it has so far.
    fn visit_type(&mut self, t: NodeIx, nesting: usize) {
        if self.state.contains_key(&t) || nesting > MAX_DEPTH {
            return;
        }
        self.state.insert(t, State::Visiting);
        let model = self.model;
        if let Some(s) = model.node(t).super_type {
            self.visit_type(s, nesting + 1);
        }
        // A member of the type overrides the supertype's member of the same BrowseName: `build_members`
        // already merged the type's members along the supertype chain and recorded it.
        if let Some(members) = model.members.get(&t) {
            for m in members.iter().filter(|m| m.declared_in == t) {
                if let Some(over) = m.overrides.filter(|&o| o != m.node) {
                    self.link(m.node, over);
                }
            }
        }
        for (_, c) in model.children(t).collect::<Vec<_>>() {
            self.walk(c, 1, nesting);
        }
        self.state.insert(t, State::Done);
    }

    /// Links the children of declaration `c`, whose own link is already known, then their children.
    fn walk(&mut self, c: NodeIx, depth: usize, nesting: usize) {
        let model = self.model;
        if depth > MAX_DEPTH || model.node(c).class == NodeClass::Method {
            return;
        }
        for (_, d) in model.children(c).collect::<Vec<_>>() {
            if let Some(over) = self.inherited(c, d, nesting) {
                self.link(d, over);
            }
            self.walk(d, depth + 1, nesting);
        }
    }

    fn link(&mut self, decl: NodeIx, over: NodeIx) {
        // A node reached twice (one node shared by two parents) keeps its first link.
        if decl != over && !self.links.contains_key(&decl) {
            self.links.insert(decl, over);
            self.found.push((decl, over));
        }
    }

    /// The member named like `d` that declaration `c` has without its own children: a child of the
    /// declarations `c` overrides (nearest first), else a member with a ModellingRule of their
    /// TypeDefinitions (`c`'s first).
    fn inherited(&mut self, c: NodeIx, d: NodeIx, nesting: usize) -> Option<NodeIx> {
        let model = self.model;
        let name = &model.node(d).browse_name;
        let mut chain = Vec::new();
        let mut cur = self.links.get(&c).copied();
        while let Some(x) = cur {
            if chain.len() >= MAX_DEPTH || chain.contains(&x) {
                break;
            }
            // The links of `x` belong to the type that declares it: visit that type first.
            if let Some(owner) = owner_type(model, x) {
                self.visit_type(owner, nesting + 1);
            }
            chain.push(x);
            cur = self.links.get(&x).copied();
        }
        for &x in &chain {
            if let Some((_, child)) = model.children(x).find(|&(_, ch)| model.node(ch).browse_name == *name) {
                return Some(child);
            }
        }
        let mut tds: Vec<NodeIx> = Vec::new();
        for x in std::iter::once(c).chain(chain.iter().copied()) {
            if let Some(td) = model.node(x).type_definition {
                if !tds.contains(&td) {
                    tds.push(td);
                }
            }
        }
        tds.into_iter().find_map(|td| {
            model.members.get(&td)?.iter().find(|m| m.browse_name == *name && model.node(m.node).modelling_rule.is_some()).map(|m| m.node)
        })
    }
}

/// The type whose InstanceDeclaration hierarchy holds `x`: the first type up its parents.
fn owner_type(model: &Model, x: NodeIx) -> Option<NodeIx> {
    let mut cur = model.node(x).parent;
    for _ in 0..MAX_DEPTH {
        let p = cur?;
        if model.node(p).class.is_type() {
            return Some(p);
        }
        cur = model.node(p).parent;
    }
    None
}

/// Whether `decl` stays compatible with the declaration it overrides; a warning if not.
fn check(model: &Model, decl: NodeIx, over: NodeIx, diags: &mut Diagnostics) {
    let (d, o) = (model.node(decl), model.node(over));
    let what = |why: String, help: &str| {
        Diagnostic::new(Code::IncompatibleOverride, format!("`{}` overrides {} of {}, but {why}", d.browse_name.name, model.display_id(&o.id), model.qualified(owner_type(model, over).unwrap_or(over))))
            .at(d.browse_name_span)
            .with_span_label("this declaration overrides")
            .label(o.browse_name_span, "the declaration it overrides")
            .help(help.to_owned())
    };
    if d.class != o.class {
        diags.push(what(format!("it is {} {} and that is {} {}", crate::model::article(d.class.name()), d.class.name(), crate::model::article(o.class.name()), o.class.name()), "an override keeps the NodeClass of what it overrides"));
        return;
    }
    if let (Some(dt), Some(ot)) = (d.type_definition, o.type_definition) {
        if dt != ot && !model.is_subtype_of(dt, ot) {
            diags.push(what(
                format!("its TypeDefinition {} is not {} or a subtype of it", model.qualified(dt), model.qualified(ot)),
                "give the override the TypeDefinition of what it overrides, or a subtype of it",
            ));
        }
    }
    if let (Some(dd), Some(od)) = (d.attrs.data_type, o.attrs.data_type) {
        if dd != od && !model.is_subtype_of(dd, od) {
            diags.push(what(
                format!("its DataType {} is not {} or a subtype of it", model.qualified(dd), model.qualified(od)),
                "give the override the DataType of what it overrides, or a subtype of it",
            ));
        }
    }
    let weaker = matches!(
        (o.modelling_rule, d.modelling_rule),
        (Some(ModellingRule::Mandatory), Some(ModellingRule::Optional))
            | (Some(ModellingRule::MandatoryPlaceholder), Some(ModellingRule::OptionalPlaceholder))
    );
    if weaker {
        diags.push(what(
            format!("it is {} where that is {}", d.modelling_rule.map_or("", |r| r.name()), o.modelling_rule.map_or("", |r| r.name())),
            "a ModellingRule may go from Optional to Mandatory in a subtype, not back",
        ));
    }
}
