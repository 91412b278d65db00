//! ObjectTypes, the classes of their instance declarations, and instances: one planner for all three.
//!
//! A class is planned from a base class (the supertype, the TypeDefinition, or the class an overridden member
//! already had) and the node's own children. A child whose BrowseName matches an element of the base
//! *overrides* it: a ModellingRule made Mandatory becomes `final use_x = true`, a value becomes a modifier, a
//! child with children of its own becomes a redeclaration with a class of its own. Any other child is a new
//! element. Every element keeps its origin in an `__OPCUA(browsePath, nodeId, dataType)` annotation; the
//! browse path is relative to the object the enclosing class stands for.

use super::complete::{bind_free, COMPLETE_NOTE};
use super::ctx::{component_original, count_name, node_id_text, undescribed, Ctx, MAX_NESTING};
use super::plan::{ClassKey, Owner};
use super::plan::{Body, ClassInfo, ClassPlan, ElemKind, Element, Item, Mod, Mode, Own, OwnerPlan, Placed, TypeRef, Value};
use super::text::{self, string_literal};
use super::types::{as_i128, dims_text};
use super::plan::{Base, MType};
use super::units::Unit;
use crate::model::{ids, NodeIx};
use crate::nodeid::QualifiedName;
use crate::raw::NodeClass;
use crate::value::{BuiltinType, Variant};
use std::collections::{BTreeSet, HashMap};
use std::rc::Rc;

impl Ctx<'_> {
    pub(super) fn is_property(&self, rt: NodeIx) -> bool {
        self.m.ns0(ids::HAS_PROPERTY).is_some_and(|p| self.m.is_subtype_of(rt, p))
    }

    /// The children that count for a class: those with a ModellingRule (types), or all (instances).
    pub fn own_children(&self, node: NodeIx, mode: Mode) -> Vec<Own> {
        let ns = self.m.node(node).id.ns;
        self.m
            .children(node)
            .filter(|&(_, c)| mode == Mode::Instance || self.m.node(c).modelling_rule.is_some())
            // Another namespace's instance below this one (our models' cell below DI's DeviceSet) is a top-level
            // instance of that namespace, with its class in that namespace's package.
            .filter(|&(_, c)| !(mode == Mode::Instance && self.m.node(c).modelling_rule.is_none() && self.m.node(c).id.ns != ns))
            .filter(|&(_, c)| {
                matches!(self.m.node(c).class, NodeClass::Object | NodeClass::Variable | NodeClass::Method)
            })
            .map(|(rt, c)| Own { node: c, rt })
            .collect()
    }

    /// The ClassInfo of an ObjectType's class, planning it (and its supertypes) on first use.
    pub fn type_class(&mut self, t: NodeIx) -> Option<Rc<ClassInfo>> {
        let key = ClassKey::Type(t);
        if let Some(i) = self.class_infos.get(&key) {
            return Some(i.clone());
        }
        if self.plans.contains_key(&Owner::Type(t)) {
            // Being planned: a type that contains itself through one of its members.
            return None;
        }
        self.depth += 1;
        if self.depth > 200 {
            self.depth -= 1;
            return None;
        }
        self.plans.insert(Owner::Type(t), OwnerPlan::default());
        let info = if self.is_event_type(t) { self.plan_event_type(t) } else { self.plan_object_type(t) };
        self.name_decls(Owner::Type(t));
        self.depth -= 1;
        let info = Rc::new(info);
        self.class_infos.insert(key, info.clone());
        self.run_deferred();
        Some(info)
    }

    /// Plans the declaration classes that waited for their base type.
    pub fn run_deferred(&mut self) {
        while let Some(i) = self.deferred.iter().position(|d| self.class_infos.contains_key(&ClassKey::Type(d.td))) {
            let d = self.deferred.remove(i);
            let td_info = self.class_infos[&ClassKey::Type(d.td)].clone();
            let sub = self.plan_body(d.owner, &d.path, Some(&td_info), &d.children, d.mode, true);
            self.add_decl(d.owner, &d.path, d.node, &td_info, sub);
            self.name_decls(d.owner);
        }
    }

    fn plan_object_type(&mut self, t: NodeIx) -> ClassInfo {
        let m = self.m;
        let node = m.node(t);
        let base =
            node.super_type.filter(|&s| m.node(s).class == NodeClass::ObjectType).and_then(|s| self.type_class(s));
        let own: Vec<Own> = m
            .members
            .get(&t)
            .map(|ms| {
                ms.iter()
                    .filter(|x| x.declared_in == t && m.node(x.node).modelling_rule.is_some())
                    .map(|x| Own { node: x.node, rt: x.reference_type })
                    .collect()
            })
            .unwrap_or_default();
        let owner = Owner::Type(t);
        let mut body = self.plan_body(owner, "", base.as_ref(), &own, Mode::Type, true);
        let mut state_machine = starting_in(base.as_ref().and_then(|b| b.state_machine.clone()), body.initial);
        if let Some(sm) = self.plan_state_machine(t, base.as_ref(), &mut body) {
            state_machine = Some(Rc::new(sm));
        }
        let free = Rc::new(self.free_of(&body.elements));
        let by_inputs = free.iter().any(|f| f.path.len() > 1);
        let partial = node.is_abstract() || by_inputs;
        let mut doc = node.doc().map(text::html_paragraphs).unwrap_or_else(|| undescribed(m, t, "ObjectType"));
        if node.is_abstract() {
            doc.push_str("<p>The ObjectType is abstract, so the class is partial: extend it.</p>");
        } else if by_inputs {
            doc.push_str(COMPLETE_NOTE);
        }
        let plan = ClassPlan {
            keyword: if partial { "partial model" } else { "model" },
            desc: text::description(&node.browse_name.name, node.doc()),
            doc_html: doc,
            extends: base.as_ref().map(|b| (TypeRef::Class(b.key.clone()), std::mem::take(&mut body.mods))),
            items: std::mem::take(&mut body.items),
            equations: std::mem::take(&mut body.equations),
            opcua: format!(
                "__OPCUA(nodeId={}, browseName={})",
                string_literal(&node_id_text(m, &node.id)),
                string_literal(&node.browse_name.name)
            ),
        };
        self.plans.entry(owner).or_default().main = Some(plan);
        ClassInfo {
            key: ClassKey::Type(t),
            elements: body.elements,
            taken: body.taken,
            local_replaceable: body.local_replaceable,
            state_machine,
            placed: body.placed,
            free,
        }
    }

    /// An event type as a record of its fields (its variables); objects and methods of event types describe
    /// where an event comes from, not what it carries.
    fn plan_event_type(&mut self, t: NodeIx) -> ClassInfo {
        let m = self.m;
        let node = m.node(t);
        let base = node.super_type.filter(|&s| self.is_event_type(s)).and_then(|s| self.type_class(s));
        let base_names: BTreeSet<QualifiedName> =
            base.iter().flat_map(|b| b.elements.iter().map(|e| e.bn.clone())).collect();
        let own: Vec<Own> = m
            .members
            .get(&t)
            .map(|ms| {
                ms.iter()
                    .filter(|x| {
                        x.declared_in == t
                            && m.node(x.node).class == NodeClass::Variable
                            && m.node(x.node).modelling_rule.is_some()
                    })
                    .filter(|x| !base_names.contains(&x.browse_name))
                    .map(|x| Own { node: x.node, rt: x.reference_type })
                    .collect()
            })
            .unwrap_or_default();
        let mut taken = base.as_ref().map(|b| b.taken.clone()).unwrap_or_default();
        let mut scope = self.scope::<usize>();
        for n in &taken {
            scope.reserve(n);
        }
        for (i, o) in own.iter().enumerate() {
            scope.add(&component_original(&m.node(o.node).browse_name.name), i);
        }
        let (names, collisions) = scope.finish();
        let what = format!("record {}", m.qualified(t));
        self.report(&what, "fields", collisions, |i| {
            (own[*i].node, Some(m.node(own[*i].node).browse_name.name.clone()))
        });
        let mut elements = base.as_ref().map(|b| b.elements.clone()).unwrap_or_default();
        let mut items = Vec::new();
        for (i, o) in own.iter().enumerate() {
            let n = m.node(o.node);
            let ident = names[&i].clone();
            taken.insert(ident.clone());
            // A variable without a DataType attribute has the default, BaseDataType.
            let ty = n
                .attrs
                .data_type
                .or_else(|| m.ns0(ids::BASE_DATA_TYPE))
                .map(|d| self.mtype(d))
                .unwrap_or_else(|| MType::Unmapped("it has no DataType".into()));
            if let MType::Unmapped(why) = &ty {
                items.push(Item::Comment(format!("Field {} is left out: {why}.", n.browse_name.name)));
                self.lossy(
                    o.node,
                    format!(
                        "event field `{}` of `{}` has no Modelica type and is left out: {why}",
                        n.browse_name.name,
                        m.qualified(t)
                    ),
                );
                elements.push(Element {
                    bn: n.browse_name.clone(),
                    ident,
                    node: o.node,
                    rt: o.rt,
                    present: false,
                    kind: ElemKind::Skipped,
                    use_flag: None,
                    count: None,
                    alias: None,
                    pinned: None,
                    nested_free: None,
                    modified: None,
                });
                continue;
            }
            let mut dims = Self::dims(n.attrs.value_rank.unwrap_or(-1), &n.attrs.array_dimensions);
            let mut value = Value::Of { node: o.node, ty: ty.clone(), dims: dims.clone() };
            let mut dims_s = dims.as_deref().map(dims_text).unwrap_or_default();
            if dims.as_ref().is_some_and(|d| d.len() == 1 && d[0].is_none()) {
                // As in the records of DataTypes: the length of an array of unknown length is a field.
                let mut count = count_name(&ident);
                while taken.contains(&count) {
                    count.push('_');
                }
                taken.insert(count.clone());
                items.push(Item::Decl {
                    prefix: "parameter".into(),
                    ty: TypeRef::Path("Integer".into()),
                    ident: count.clone(),
                    dims: String::new(),
                    mods: Vec::new(),
                    value: Some("0".into()),
                    cond: None,
                    desc: string_literal(&format!("Number of elements of {}", n.browse_name.name)),
                    annotation: String::new(),
                });
                value = Value::Fill { ty: ty.clone(), sizes: vec![count.clone()] };
                dims_s = format!("[{count}]");
                dims = Some(vec![None]);
            }
            items.push(Item::Decl {
                prefix: String::new(),
                ty: TypeRef::Path(ty.type_name().to_string()),
                ident: ident.clone(),
                dims: dims_s,
                mods: Vec::new(),
                value: Some(value),
                cond: None,
                desc: text::description(&n.browse_name.name, n.doc()),
                annotation: self.opcua_annotation(o.node),
            });
            elements.push(Element {
                bn: n.browse_name.clone(),
                ident,
                node: o.node,
                rt: o.rt,
                present: false,
                kind: ElemKind::Parameter { ty, dims },
                use_flag: None,
                count: None,
                alias: None,
                pinned: None,
                nested_free: None,
                modified: None,
            });
        }
        let mut doc = node.doc().map(text::html_paragraphs).unwrap_or_else(|| undescribed(m, t, "EventType"));
        doc.push_str("<p>An event type: the record holds the fields an event of this type carries.</p>");
        let plan = ClassPlan {
            keyword: "record",
            desc: text::description(&node.browse_name.name, node.doc()),
            doc_html: doc,
            extends: base.as_ref().map(|b| (TypeRef::Class(b.key.clone()), Vec::new())),
            items,
            equations: Vec::new(),
            opcua: format!(
                "__OPCUA(nodeId={}, browseName={})",
                string_literal(&node_id_text(m, &node.id)),
                string_literal(&node.browse_name.name)
            ),
        };
        self.plans.entry(Owner::Type(t)).or_default().main = Some(plan);
        ClassInfo {
            key: ClassKey::Type(t),
            elements,
            taken,
            local_replaceable: false,
            state_machine: None,
            placed: Placed::default(),
            free: Rc::new(Vec::new()),
        }
    }

    /// Gives the declaration classes of an owner their names: one scope over their browse paths.
    pub fn name_decls(&mut self, owner: Owner) {
        let paths: Vec<String> =
            self.plans.get(&owner).map(|p| p.decls.iter().map(|(p, _)| p.clone()).collect()).unwrap_or_default();
        if paths.is_empty() {
            return;
        }
        let mut scope = self.scope::<usize>();
        for (i, p) in paths.iter().enumerate() {
            scope.add(p, i);
        }
        let (names, collisions) = scope.finish();
        let what = format!("declarations of {}", self.m.qualified(owner.node()));
        self.report(&what, "classes", collisions, |_| (owner.node(), None));
        for (i, p) in paths.into_iter().enumerate() {
            self.decl_names.insert((owner, p), names[&i].clone());
        }
    }

    /// The annotation that ties an element to its node.
    pub fn opcua_annotation(&self, node: NodeIx) -> String {
        let m = self.m;
        let n = m.node(node);
        let path = escape_browse_name(&n.browse_name.name);
        let mut s =
            format!("__OPCUA(browsePath={}, nodeId={}", string_literal(&path), string_literal(&node_id_text(m, &n.id)));
        if let Some(dt) = n.attrs.data_type {
            s.push_str(&format!(", dataType={}", string_literal(&node_id_text(m, &m.node(dt).id))));
        }
        if n.class == NodeClass::Object {
            if let Some(td) = n.type_definition {
                s.push_str(&format!(", typeDefinition={}", string_literal(&node_id_text(m, &m.node(td).id))));
            }
        }
        if let Some(Ok(unit)) = self.unit_of(node) {
            s.push_str(&format!(", engineeringUnit={}", string_literal(unit.code)));
            if !unit.is_si() {
                s.push_str(&format!(", siFactor={}", text::real_literal(unit.factor).unwrap_or_default()));
                if unit.offset != 0.0 {
                    s.push_str(&format!(", siOffset={}", text::real_literal(unit.offset).unwrap_or_default()));
                }
            }
        }
        s.push(')');
        s
    }

    /// The declared value of a variable as a literal (its value in the nodeset, else the type's default).
    pub fn value_of(&mut self, node: NodeIx, ty: &MType, dims: Option<&[Option<u32>]>) -> String {
        self.explicit_value(node, ty, dims).unwrap_or_else(|| match dims {
            Some(d) => self.default_array(ty, d),
            None => self.default_literal(ty),
        })
    }

    /// The value the nodeset gives a variable, as a literal, if it has one that fits.
    pub fn explicit_value(&mut self, node: NodeIx, ty: &MType, dims: Option<&[Option<u32>]>) -> Option<String> {
        let m = self.m;
        let v = m.value(node)?.ok()?;
        if matches!(v, Variant::Null) {
            return None;
        }
        // A Real in an engineering unit is held in SI (see `units.rs`).
        let v = match (ty, self.unit_of(node)) {
            (MType::Scalar { base: Base::Real, builtin, .. }, Some(Ok(unit)))
                if !unit.is_si() && *builtin != BuiltinType::DateTime =>
            {
                to_si(&v, unit)?
            }
            _ => v,
        };
        let file = m.node(node).file;
        match (dims, &v) {
            (Some(d), Variant::Array(_, items)) => {
                // A fixed length must match the value.
                if d.len() == 1 && d[0].is_some_and(|n| n as usize != items.len()) {
                    return None;
                }
                if d.len() > 1 {
                    return None;
                }
                let lit = self.array_literal(&v, ty, file)?;
                if items.is_empty() {
                    return None;
                }
                Some(lit)
            }
            (Some(_), _) => None,
            (None, Variant::Array(..)) => None,
            (None, v) => self.literal(v, ty, file),
        }
    }

    /// The Modelica unit of a variable from its EngineeringUnits property (a child, or one its VariableType or a
    /// supertype of it declares with a value); `Err` with the unit's display name when the table has no Modelica
    /// form for it.
    pub fn unit_of(&self, node: NodeIx) -> Option<Result<&'static Unit, String>> {
        let m = self.m;
        let eu_of = |n: NodeIx| {
            m.children(n)
                .map(|(_, c)| c)
                .find(|&c| m.node(c).browse_name.ns == 0 && m.node(c).browse_name.name == "EngineeringUnits")
        };
        // The variable's own EngineeringUnits, else the one its VariableType (or a supertype of it) gives a value.
        let eu = match eu_of(node).filter(|&eu| m.value(eu).is_some()) {
            Some(eu) => eu,
            None => {
                let mut t = m.node(node).type_definition;
                let mut found = None;
                for _ in 0..64 {
                    let Some(ty) = t else { break };
                    if let Some(eu) = eu_of(ty).filter(|&eu| m.value(eu).is_some()) {
                        found = Some(eu);
                        break;
                    }
                    t = m.node(ty).super_type;
                }
                found?
            }
        };
        let Ok(Variant::ExtensionObject(eo)) = m.value(eu)? else { return None };
        let eu = eo.structure()?;
        let id = i32::try_from(eu.field("UnitId")?.as_i64()?).ok()?;
        if id == -1 {
            return None;
        }
        match super::units::modelica_unit(id) {
            Some(u) => Some(Ok(u)),
            None => {
                let shown = eu.text("DisplayName").unwrap_or("").to_string();
                Some(Err(if shown.is_empty() { format!("UnitId {id}") } else { format!("{shown} (UnitId {id})") }))
            }
        }
    }

    /// Plans the body of a class: overrides of `base` and new elements for `own`. `allow_replaceable` is false
    /// for the class of a redeclaration whose constraining class has no replaceable elements of its own.
    pub fn plan_body(
        &mut self,
        owner: Owner,
        path: &str,
        base: Option<&Rc<ClassInfo>>,
        own: &[Own],
        mode: Mode,
        allow_replaceable: bool,
    ) -> Body {
        // Each level of an object hierarchy is a nested class (and a few stack frames here); below
        // MAX_NESTING levels the children are left out, with a warning, rather than overflowing the stack.
        let own = if self.nesting >= MAX_NESTING && !own.is_empty() {
            let at = own[0].node;
            self.lossy(
                at,
                format!(
                    "the children of `{path}` are nested more than {MAX_NESTING} levels deep; they are not represented in Modelica"
                ),
            );
            &[][..]
        } else {
            own
        };
        self.nesting += 1;
        let body = self.plan_body_at(owner, path, base, own, mode, allow_replaceable);
        self.nesting -= 1;
        body
    }

    fn plan_body_at(
        &mut self,
        owner: Owner,
        path: &str,
        base: Option<&Rc<ClassInfo>>,
        own: &[Own],
        mode: Mode,
        allow_replaceable: bool,
    ) -> Body {
        let m = self.m;
        let mut body = Body {
            taken: base.map(|b| b.taken.clone()).unwrap_or_default(),
            placed: base.map(|b| b.placed).unwrap_or_default(),
            ..Body::default()
        };
        let mut elements: Vec<Element> = base.map(|b| b.elements.clone()).unwrap_or_default();
        let by_bn: HashMap<QualifiedName, usize> =
            elements.iter().enumerate().map(|(i, e)| (e.bn.clone(), i)).collect();

        // Name the new elements first, in one scope with everything the base takes.
        // An object that subclasses may redeclare also gets a class alias, named like a class.
        let mut scope = self.scope::<(usize, bool)>();
        for t in &body.taken {
            scope.reserve(t);
        }
        let mut seen: BTreeSet<QualifiedName> = BTreeSet::new();
        for (i, o) in own.iter().enumerate() {
            let bn = &m.node(o.node).browse_name;
            if !seen.insert(bn.clone()) {
                continue; // A second child with one BrowseName (the resolver reports it); the first one wins.
            }
            if !by_bn.contains_key(bn) {
                scope.add(&component_original(&bn.name), (i, false));
                if self.gets_alias(*o, mode, allow_replaceable) {
                    scope.add(&bn.name, (i, true));
                }
            }
        }
        let (names, collisions) = scope.finish();
        let what = format!("class of {}", m.qualified(owner.node()));
        self.report(&what, "components", collisions, |(i, _)| {
            (own[*i].node, Some(m.node(own[*i].node).browse_name.name.clone()))
        });
        for n in names.values() {
            body.taken.insert(n.clone());
        }

        let mut seen: BTreeSet<QualifiedName> = BTreeSet::new();
        for (i, o) in own.iter().enumerate() {
            let bn = m.node(o.node).browse_name.clone();
            if !seen.insert(bn.clone()) {
                continue;
            }
            match by_bn.get(&bn) {
                Some(&ei) if !matches!(elements[ei].kind, ElemKind::Skipped) => {
                    let e = elements[ei].clone();
                    let machine = base.and_then(|b| b.state_machine.clone());
                    if let Some(sm) = machine.filter(|sm| sm.text.as_ref().is_some_and(|(cur, _)| *cur == e.ident)) {
                        // The text of the state follows the number: the state a CurrentState names is where the
                        // machine starts, never a value of the text.
                        self.start_state(&sm, o.node, &mut body);
                        elements[ei].node = o.node;
                        continue;
                    }
                    if let Some(updated) = self.plan_override(owner, path, &e, *o, mode, &mut body) {
                        elements[ei] = updated;
                    }
                }
                Some(&ei) => {
                    // The base could not declare it; this child may.
                    let ident = elements[ei].ident.clone();
                    let el = self.plan_new(owner, path, ident, None, *o, mode, &mut body);
                    elements[ei] = el;
                }
                None => {
                    let ident = names[&(i, false)].clone();
                    let alias = names.get(&(i, true)).cloned();
                    let el = self.plan_new(owner, path, ident, alias, *o, mode, &mut body);
                    elements.push(el);
                }
            }
        }
        // The elements that fill a placeholder here are named components. So the placeholder's array, one
        // element by default where it is mandatory, is empty: always in an instance (it holds what the nodeset
        // gives it), in a type when a new child fits the placeholder.
        let inherited = base.map_or(0, |b| b.elements.len());
        for e in &elements[..inherited] {
            let mandatory = m.node(e.node).modelling_rule == Some(crate::model::ModellingRule::MandatoryPlaceholder);
            let Some(count) = e.count.as_ref().filter(|_| mandatory) else { continue };
            if mode == Mode::Instance || own.iter().any(|o| !by_bn.contains_key(&m.node(o.node).browse_name) && self.fills(*o, e)) {
                body.mods.push(Mod::Value {
                    ident: count.clone(),
                    is_final: false,
                    attrs: vec!["min=0".into()],
                    value: Some("0".into()),
                });
            }
        }
        if mode == Mode::Instance {
            // An instance is complete: every input nothing binds yet gets the instance's value.
            for f in self.free_of(&elements) {
                bind_free(&mut body.mods, &f.path, f.value());
            }
            for e in &mut elements {
                if let ElemKind::Signal { free, .. } = &mut e.kind {
                    *free = false;
                }
                if matches!(e.kind, ElemKind::Object { .. }) {
                    e.nested_free = Some(Rc::new(Vec::new()));
                }
            }
        }
        body.elements = elements;
        body
    }

    /// Whether child `o` fits placeholder `e`: a node of its NodeClass, with its TypeDefinition or a subtype.
    fn fills(&self, o: Own, e: &Element) -> bool {
        let m = self.m;
        let (child, decl) = (m.node(o.node), m.node(e.node));
        child.class == decl.class
            && match (child.type_definition, decl.type_definition) {
                (Some(c), Some(d)) => m.is_subtype_of(c, d),
                (_, None) => true,
                (None, Some(_)) => false,
            }
    }
}

/// A state machine that starts in state `initial` instead of its own initial state.
pub(super) fn starting_in(
    sm: Option<Rc<super::plan::SmInfo>>,
    initial: Option<usize>,
) -> Option<Rc<super::plan::SmInfo>> {
    match (sm, initial) {
        (Some(sm), Some(i)) => Some(Rc::new(super::plan::SmInfo { initial: i, ..(*sm).clone() })),
        (sm, _) => sm,
    }
}

pub(super) fn join_path(path: &str, name: &str) -> String {
    let name = escape_browse_name(name);
    if path.is_empty() {
        name
    } else {
        format!("{path}/{name}")
    }
}

/// A BrowseName as one element of a '/'-separated path: '&' and '/' are escaped with '&' (OPC UA Part 4,
/// A.2 RelativePath).
pub fn escape_browse_name(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for c in name.chars() {
        if matches!(c, '&' | '/') {
            s.push('&');
        }
        s.push(c);
    }
    s
}

/// A numeric value (or an array of them) in the engineering unit as the SI value, a Double; `None` for a value
/// that is not a number.
fn to_si(v: &Variant, unit: &Unit) -> Option<Variant> {
    let x = match v {
        Variant::Array(ty, items) => {
            let items: Option<Vec<Variant>> = items.iter().map(|i| to_si(i, unit)).collect();
            return Some(Variant::Array(*ty, items?));
        }
        Variant::Variant(inner) => return to_si(inner, unit),
        // The Float as written (its shortest text), not its binary value widened: 0.1, not 0.10000000149011612.
        Variant::Float(f) => f.to_string().parse().unwrap_or(*f as f64),
        Variant::Double(f) => *f,
        other => as_i128(other)? as f64,
    };
    Some(Variant::Double(unit.to_si(x)))
}
