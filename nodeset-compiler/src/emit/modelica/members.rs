//! The members of a class: a child that is new to the class (a parameter, a connector, a component, a reference
//! parameter or a method comment), or one that overrides an element of the base class (modifiers, or a
//! redeclaration with a class of its own).

use super::complete::{bind_free, COMPLETE_NOTE};
use super::ctx::{count_name, node_id_text, Ctx};
use super::objects::{join_path, starting_in};
use super::plan::{
    pin_alias, Base, Body, ClassInfo, ClassKey, ClassPlan, Deferred, ElemKind, Element, Free, Item, MType, Mod, Mode,
    Own, Owner, Pinned, TypeRef, Value,
};
use super::text::{self, string_literal};
use super::types::dims_text;
use crate::model::{ids, ModellingRule, NodeIx};
use crate::nodeid::QualifiedName;
use crate::raw::NodeClass;
use crate::value::Variant;
use std::collections::BTreeSet;
use std::rc::Rc;

impl Ctx<'_> {
    /// The class an object child is an instance of: its TypeDefinition, or BaseObjectType.
    fn object_td(&self, node: NodeIx) -> NodeIx {
        let m = self.m;
        m.node(node)
            .type_definition
            .filter(|&t| m.node(t).class == NodeClass::ObjectType)
            .or_else(|| m.ns0(ids::BASE_OBJECT_TYPE))
            .expect("namespace 0 has BaseObjectType")
    }

    /// Whether a new child becomes a replaceable object (with a class alias).
    pub(super) fn gets_alias(&self, o: Own, mode: Mode, allow_replaceable: bool) -> bool {
        allow_replaceable
            && mode == Mode::Type
            && self.m.node(o.node).class == NodeClass::Object
            && !self.is_event_type(self.object_td(o.node))
            && !self.is_reference(o)
    }

    /// Whether a child becomes a reference parameter rather than a component (see `recursion.rs`).
    fn is_reference(&self, o: Own) -> bool {
        matches!(self.m.node(o.node).class, NodeClass::Object | NodeClass::Variable)
            && (!super::recursion::is_containment(self.m, o.rt) || self.cuts.contains(&o.node))
    }

    /// A child held by reference: a `String` parameter with the NodeId of its target (in an instance) or `""`
    /// (in a type, where the target is only declared), an array of them for a placeholder.
    fn plan_reference(
        &mut self,
        ident: String,
        o: Own,
        rule: Option<ModellingRule>,
        body: &mut Body,
        mut element: Element,
    ) -> Element {
        let m = self.m;
        let n = m.node(o.node);
        let bn = n.browse_name.clone();
        body.adds = true;
        let rt = m.node(o.rt).browse_name.name.clone();
        let why = if super::recursion::is_containment(m, o.rt) {
            format!("held by {rt}, but containing it would make the class contain itself")
        } else {
            format!("{rt} reference")
        };
        let td = n.type_definition.map(|t| format!(", an instance of {}", m.node(t).browse_name.name)).unwrap_or_default();
        let doc = match n.doc() {
            Some(d) => format!("{d} [{why}: the NodeId of the target{td}; \"\" for none]"),
            None => format!("{why}: the NodeId of the target{td}; \"\" for none"),
        };
        let desc = text::description(&bn.name, Some(&doc));
        let mut annotation = self.opcua_annotation(o.node);
        annotation.insert_str(annotation.len() - 1, &format!(", referenceType={}", string_literal(&rt)));
        let (dims, value) = if rule.is_some_and(ModellingRule::is_placeholder) {
            let count = self.derived_name(body, count_name(&ident), o.node);
            body.items.push(count_decl(&count, &bn.name, rule));
            let v = format!("fill(\"\", {count})");
            element.count = Some(count.clone());
            (format!("[{count}]"), v)
        } else if rule.is_none() {
            // An instance: the target is the node itself.
            (String::new(), string_literal(&node_id_text(m, &n.id)))
        } else {
            (String::new(), "\"\"".to_string())
        };
        element.kind = ElemKind::Reference { array: element.count.is_some() };
        body.items.push(Item::Decl {
            prefix: "parameter".into(),
            ty: TypeRef::Path("String".into()),
            ident,
            dims,
            mods: Vec::new(),
            value: Some(value.into()),
            cond: None,
            desc,
            annotation,
        });
        element
    }

    /// The count of a placeholder component and the BrowseNames of its elements; returns the count's name.
    fn placeholder_decls(
        &mut self,
        body: &mut Body,
        ident: &str,
        original: &str,
        rule: Option<ModellingRule>,
        node: NodeIx,
    ) -> String {
        let count = self.derived_name(body, count_name(ident), node);
        body.items.push(count_decl(&count, original, rule));
        let names = self.derived_name(body, format!("{ident}BrowseNames"), node);
        body.items.push(browse_names_decl(&names, &count, original));
        count
    }

    /// The names a pin on a component of `class` may hold a choice for: the class's aliases and, for its
    /// components declared through one, their pin aliases ([`Pinned`]); whether or not some class redeclares them.
    fn pin_candidates(&self, class: &ClassKey) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        let Some(info) = self.class_infos.get(class) else { return out };
        for e in &info.elements {
            let ElemKind::Object { class: k } = &e.kind else { continue };
            out.extend(e.alias.clone());
            if let Some(p) = &e.pinned {
                out.extend(self.pin_candidates(k).iter().map(|a| pin_alias(&p.pin, a)));
            }
        }
        out
    }

    /// The prefix of the aliases that hold the pins of a component of `class` declared through `alias`
    /// ([`Pinned::pin`]): the alias, or `<alias>_2`, ... when one of the names it makes is taken. Takes them all.
    fn pin_prefix(&self, body: &mut Body, alias: &str, class: &ClassKey) -> String {
        let names = self.pin_candidates(class);
        let free = |pin: &str| {
            names.iter().map(|a| pin_alias(pin, a)).all(|n| !body.taken.contains(&n) && !self.reserved.contains(&n))
        };
        let mut pin = alias.to_string();
        let mut k = 2;
        while !free(&pin) {
            pin = format!("{alias}_{k}");
            k += 1;
        }
        body.taken.extend(names.iter().map(|a| pin_alias(&pin, a)));
        pin
    }

    /// A name derived from an element's (`use_x`, `nX`), unique in the class.
    fn derived_name(&mut self, body: &mut Body, candidate: String, node: NodeIx) -> String {
        let mut name = candidate.clone();
        let mut k = 2;
        while body.taken.contains(&name) || self.reserved.contains(&name) {
            name = format!("{candidate}_{k}");
            k += 1;
        }
        if name != candidate {
            let m = self.m;
            let msg = format!(
                "the generated parameter `{candidate}` of `{}` ({}) collides with another element; it is named `{name}`",
                m.node(node).browse_name.name,
                node_id_text(m, &m.node(node).id)
            );
            let mut d = crate::diag::Diagnostic::new(crate::diag::Code::NameCollision, msg)
                .at(m.node(node).browse_name_span);
            d.severity = crate::diag::Severity::Warning;
            self.diags.push(d);
        }
        body.taken.insert(name.clone());
        name
    }

    /// A new element of a class.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn plan_new(
        &mut self,
        owner: Owner,
        path: &str,
        ident: String,
        alias: Option<String>,
        o: Own,
        mode: Mode,
        body: &mut Body,
    ) -> Element {
        let m = self.m;
        let n = m.node(o.node);
        let bn = n.browse_name.clone();
        let rule = if mode == Mode::Instance { None } else { n.modelling_rule };
        let placeholder = rule.is_some_and(ModellingRule::is_placeholder);
        let optional = rule == Some(ModellingRule::Optional);
        let mut element = Element {
            bn: bn.clone(),
            ident: ident.clone(),
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
        };
        if self.is_reference(o) {
            return self.plan_reference(ident, o, rule, body, element);
        }
        let desc = text::description(&bn.name, n.doc());
        let annotation = self.opcua_annotation(o.node);
        match n.class {
            NodeClass::Method => {
                element.kind = ElemKind::Method;
                body.items.push(Item::Comment(self.method_comment(o.node)));
                element
            }
            NodeClass::Variable => {
                // A variable without a DataType attribute has the default, BaseDataType.
                let ty = n
                    .attrs
                    .data_type
                    .or_else(|| m.ns0(ids::BASE_DATA_TYPE))
                    .map(|d| self.mtype(d))
                    .unwrap_or_else(|| MType::Unmapped("it has no DataType".into()));
                if let MType::Unmapped(why) = &ty {
                    body.items.push(Item::Comment(format!("{} is left out: {why}.", bn.name)));
                    self.lossy(
                        o.node,
                        format!(
                            "variable `{}` of `{}` has no Modelica type and is left out: {why}",
                            bn.name,
                            m.qualified(owner.node())
                        ),
                    );
                    return element;
                }
                body.adds = true;
                let mut dims = Self::dims(n.attrs.value_rank.unwrap_or(-1), &n.attrs.array_dimensions);
                let is_prop = self.is_property(o.rt);
                let writable = n.attrs.access_level.unwrap_or(1) & 0x02 != 0;
                // An array of records needs a size (rumoca rejects `[:]` for them): the length of the value,
                // else a count parameter.
                let mut record_count = None;
                if let (false, Some(d), MType::Record { .. }) = (placeholder, &dims, &ty) {
                    if d.iter().any(Option::is_none) {
                        let len = match m.value(o.node) {
                            Some(Ok(Variant::Array(_, items))) if d.len() == 1 && !items.is_empty() => {
                                Some(items.len() as u32)
                            }
                            _ => None,
                        };
                        match len {
                            Some(l) => dims = Some(vec![Some(l)]),
                            None => {
                                let count = self.derived_name(body, count_name(&ident), o.node);
                                body.items.push(Item::Decl {
                                    prefix: "parameter".into(),
                                    ty: TypeRef::Path("Integer".into()),
                                    ident: count.clone(),
                                    dims: String::new(),
                                    mods: vec![Mod::Value {
                                        ident: "min".into(),
                                        is_final: false,
                                        attrs: Vec::new(),
                                        value: Some("0".into()),
                                    }],
                                    value: Some("0".into()),
                                    cond: None,
                                    desc: string_literal(&format!("Number of elements of {}", bn.name)),
                                    annotation: "Evaluate=true".into(),
                                });
                                record_count = Some(count);
                            }
                        }
                    }
                }
                let mut value = Value::Of { node: o.node, ty: ty.clone(), dims: dims.clone() };
                let mut cond = None;
                if let Some(c) = &record_count {
                    value = Value::Fill { ty: ty.clone(), sizes: vec![c.clone()] };
                }
                if placeholder {
                    let count = self.placeholder_decls(body, &ident, &bn.name, rule, o.node);
                    let mut d = vec![None];
                    d.extend(dims.clone().unwrap_or_default());
                    let sizes: Vec<String> = std::iter::once(count.clone())
                        .chain(d[1..].iter().map(|x| x.unwrap_or(0).to_string()))
                        .collect();
                    value = match (&ty, sizes.as_slice()) {
                        (MType::Record { .. }, [n]) => Value::Each { ty: ty.clone(), count: n.clone() },
                        _ => Value::Fill { ty: ty.clone(), sizes },
                    };
                    dims = Some(d);
                    element.count = Some(count);
                } else if optional {
                    let flag = self.derived_name(body, format!("use_{ident}"), o.node);
                    body.items.push(use_decl(&flag, &bn.name));
                    cond = Some(flag.clone());
                    element.use_flag = Some(flag);
                }
                let dims_s = match (&dims, &element.count) {
                    (Some(_), None) if record_count.is_some() => {
                        format!("[{}]", record_count.clone().unwrap_or_default())
                    }
                    (Some(d), Some(c)) => {
                        let mut parts = vec![c.clone()];
                        parts.extend(d[1..].iter().map(|x| x.map(|v| v.to_string()).unwrap_or_else(|| ":".into())));
                        format!("[{}]", parts.join(", "))
                    }
                    (Some(d), None) => dims_text(d),
                    (None, _) => String::new(),
                };
                let mut desc = desc;
                let mut attrs = Vec::new();
                if let MType::Scalar { base: Base::Real, .. } = ty {
                    match self.unit_of(o.node) {
                        Some(Ok(u)) => attrs.extend(u.attrs()),
                        Some(Err(shown)) => {
                            desc = text::description(
                                &bn.name,
                                Some(&format!("{} [unit {shown}: no Modelica unit]", n.doc().unwrap_or(""))),
                            );
                        }
                        None => {}
                    }
                }
                if is_prop {
                    let mods = attr_mods(&attrs, dims.is_some());
                    body.items.push(Item::Decl {
                        prefix: "parameter".into(),
                        ty: TypeRef::Path(ty.type_name().to_string()),
                        ident: ident.clone(),
                        dims: dims_s,
                        mods,
                        value: Some(value),
                        cond,
                        desc,
                        annotation,
                    });
                    element.kind = ElemKind::Parameter { ty, dims };
                } else {
                    let (prefix, tyname, mut sattrs) = signal_type(&ty, writable);
                    if !attrs.is_empty() {
                        // The engineering unit replaces the unit a builtin type would give.
                        sattrs.retain(|a| !a.starts_with("unit="));
                        sattrs.extend(attrs);
                    }
                    let mods = attr_mods(&sattrs, dims.is_some());
                    // A value the model publishes is an input connector that the physics computing it connects
                    // to; a type leaves it unbound (its complete variant binds it). Arrays and values of other
                    // types keep the nodeset's value, as does everything in an instance.
                    let free = mode == Mode::Type && !writable && prefix.is_empty() && dims.is_none();
                    // A connector (no input/output prefix) gets its place on the icon.
                    let annotation = if prefix.is_empty() {
                        format!("{}, {annotation}", body.placed.next(!writable))
                    } else {
                        annotation
                    };
                    body.items.push(Item::Decl {
                        prefix,
                        ty: TypeRef::Path(tyname),
                        ident: ident.clone(),
                        dims: dims_s,
                        mods,
                        value: (!free).then_some(value),
                        cond,
                        desc,
                        annotation,
                    });
                    element.kind = ElemKind::Signal { ty, dims, free };
                }
                element
            }
            NodeClass::Object => {
                body.adds = true;
                let td = self.object_td(o.node);
                let child_path = join_path(path, &bn.name);
                let children = self.own_children(o.node, mode);
                let event = self.is_event_type(td);
                let abstract_td = m.node(td).is_abstract();
                let mandatory_scalar = !placeholder && !optional;
                let mut mods = Vec::new();
                let class = if event {
                    if !children.is_empty() {
                        body.items.push(Item::Comment(format!(
                            "{} is an event ({}); the children of its instance declaration are not represented.",
                            bn.name,
                            m.node(td).browse_name.name
                        )));
                    }
                    ClassKey::Type(td)
                } else if !children.is_empty() || (abstract_td && mandatory_scalar) {
                    match self.type_class(td) {
                        Some(td_info) => {
                            let allow = true;
                            let sub = self.plan_body(owner, &child_path, Some(&td_info), &children, mode, allow);
                            if sub.adds || (abstract_td && mandatory_scalar) {
                                self.add_decl(owner, &child_path, o.node, &td_info, sub)
                            } else {
                                mods = sub.mods;
                                let free = self.free_of(&sub.elements);
                                if td_info.is_partial_by_inputs() {
                                    // A component of the complete variant: bind what this node gives here,
                                    // unless the class is replaceable (a modifier on the component would bind
                                    // the inputs of any model a user plugs in; the variant's defaults stay).
                                    if alias.is_none() {
                                        for f in free {
                                            bind_free(&mut mods, &f.path, f.value());
                                        }
                                    }
                                    element.nested_free = Some(Rc::new(Vec::new()));
                                } else {
                                    element.nested_free = Some(Rc::new(free));
                                }
                                // The members of the type's class, as these modifiers leave them (a new
                                // child that declares nothing, a method or a variable without a Modelica type,
                                // is not one).
                                let mut members = sub.elements;
                                members.truncate(td_info.elements.len());
                                element.modified = Some(Rc::new(members));
                                ClassKey::Type(td)
                            }
                        }
                        None => {
                            // The type is being planned (it contains this class's owner through a
                            // placeholder): plan this class once the type is complete.
                            self.deferred.push(Deferred {
                                owner,
                                path: child_path.clone(),
                                node: o.node,
                                td,
                                children: children.clone(),
                                mode,
                            });
                            ClassKey::Decl(owner, child_path.clone())
                        }
                    }
                } else {
                    ClassKey::Type(td)
                };
                let mut cond = None;
                let mut dims_s = String::new();
                if placeholder {
                    let count = self.placeholder_decls(body, &ident, &bn.name, rule, o.node);
                    dims_s = format!("[{count}]");
                    element.count = Some(count);
                } else if optional {
                    let flag = self.derived_name(body, format!("use_{ident}"), o.node);
                    body.items.push(use_decl(&flag, &bn.name));
                    cond = Some(flag.clone());
                    element.use_flag = Some(flag);
                }
                let ty = match &alias {
                    Some(a) => {
                        body.local_replaceable = true;
                        body.items.push(Item::Alias {
                            ident: a.clone(),
                            class: TypeRef::Class(class.clone()),
                            desc: string_literal(&format!(
                                "Class of {}; redeclare it to use a model of your own",
                                bn.name
                            )),
                        });
                        TypeRef::Path(a.clone())
                    }
                    None => TypeRef::Class(class.clone()),
                };
                match (&alias, event) {
                    (_, true) => {}
                    // An array declared through an alias: the pins name aliases of this class, which derived
                    // classes redeclare (`Mod::PinVia`; pymoca misreads a derived class's change of a pin on an
                    // array sized by a parameter).
                    (Some(a), false) if placeholder => {
                        let pin = self.pin_prefix(body, a, &class);
                        body.items.push(Item::PinAliases { alias: a.clone(), pin: pin.clone(), class: class.clone() });
                        mods.insert(0, Mod::PinVia { pin: pin.clone(), class: class.clone() });
                        element.pinned = Some(Pinned { declared: class.clone(), pin });
                    }
                    (_, false) => mods.insert(0, Mod::Pin { class: class.clone() }),
                }
                body.items.push(Item::Decl {
                    prefix: String::new(),
                    ty,
                    ident: ident.clone(),
                    dims: dims_s,
                    mods,
                    value: None,
                    cond,
                    desc,
                    annotation,
                });
                element.kind = ElemKind::Object { class };
                element.alias = alias;
                element
            }
            _ => element,
        }
    }

    /// A declaration class: the class of an instance declaration (or instance child) that adds to its base.
    pub(super) fn add_decl(&mut self, owner: Owner, path: &str, node: NodeIx, base: &Rc<ClassInfo>, sub: Body) -> ClassKey {
        let m = self.m;
        let n = m.node(node);
        let key = ClassKey::Decl(owner, path.to_string());
        let free = Rc::new(self.free_of(&sub.elements));
        let by_inputs = free.iter().any(|f| f.path.len() > 1);
        let plan =
            ClassPlan {
                keyword: if by_inputs { "partial model" } else { "model" },
                desc: text::description(&n.browse_name.name, n.doc()),
                doc_html: format!(
                "{}<p>The class of <code>{}</code> in {}: {} with the children this declaration adds or changes.</p>{}",
                n.doc().map(text::html_paragraphs).unwrap_or_default(),
                text::html_escape(path),
                text::html_escape(&m.qualified(owner.node())),
                text::html_escape(&n.type_definition.map(|t| m.qualified(t)).unwrap_or_else(|| "BaseObjectType".into())),
                if by_inputs { COMPLETE_NOTE } else { "" }
            ),
                extends: Some((TypeRef::Class(base.key.clone()), sub.mods)),
                items: sub.items,
                equations: sub.equations,
                opcua: format!(
                    "__OPCUA(nodeId={}, browseName={})",
                    string_literal(&node_id_text(m, &n.id)),
                    string_literal(&n.browse_name.name)
                ),
            };
        self.plans.entry(owner).or_default().decls.push((path.to_string(), plan));
        let info = ClassInfo {
            key: key.clone(),
            elements: sub.elements,
            taken: sub.taken,
            local_replaceable: sub.local_replaceable,
            state_machine: starting_in(base.state_machine.clone(), sub.initial),
            placed: sub.placed,
            free,
        };
        self.class_infos.insert(key.clone(), Rc::new(info));
        key
    }

    /// A child that overrides element `e` of the base: modifiers, or a redeclaration with a class of its own.
    pub(super) fn plan_override(
        &mut self,
        owner: Owner,
        path: &str,
        e: &Element,
        o: Own,
        mode: Mode,
        body: &mut Body,
    ) -> Option<Element> {
        let m = self.m;
        let n = m.node(o.node);
        let mut updated = e.clone();
        updated.node = o.node;
        let present = match mode {
            Mode::Instance => true,
            Mode::Type => n.modelling_rule.is_some_and(|r| r.is_mandatory() && !r.is_placeholder()),
        };
        if let Some(flag) = &e.use_flag {
            if present && !e.present {
                body.mods.push(Mod::Value {
                    ident: flag.clone(),
                    is_final: mode == Mode::Type,
                    attrs: Vec::new(),
                    value: Some("true".into()),
                });
                updated.present = true;
            }
        }
        match &e.kind {
            ElemKind::Method | ElemKind::Skipped => None,
            ElemKind::Reference { array } => {
                // An instance names the target; a type has only a declaration of it.
                if mode == Mode::Instance && !array {
                    body.mods.push(Mod::Value {
                        ident: e.ident.clone(),
                        is_final: false,
                        attrs: Vec::new(),
                        value: Some(string_literal(&node_id_text(m, &n.id)).into()),
                    });
                }
                Some(updated)
            }
            ElemKind::Parameter { ty, dims } | ElemKind::Signal { ty, dims, .. } => {
                if e.count.is_some() {
                    return Some(updated);
                }
                let mut attrs = Vec::new();
                if let (MType::Scalar { base: Base::Real, .. }, ElemKind::Signal { .. }) = (ty, &e.kind) {
                    if let Some(Ok(u)) = self.unit_of(o.node) {
                        if self.unit_of(e.node).and_then(|x| x.ok()) != Some(u) {
                            let each = if dims.is_some() { "each " } else { "" };
                            attrs.extend(u.attrs().into_iter().map(|a| format!("{each}{a}")));
                        }
                    }
                }
                // A free input keeps no value here: the complete variant (or, in an instance, the binding of
                // every free input at the end of the body) takes it from this node.
                let free = matches!(e.kind, ElemKind::Signal { free: true, .. });
                let value = if free {
                    None
                } else if m.value(o.node).is_some() {
                    let v = self.explicit_value(o.node, ty, dims.as_deref());
                    if v.is_none() {
                        body.items.push(Item::Comment(format!(
                            "The value the nodeset gives {} does not fit its Modelica type; the default is kept.",
                            n.browse_name.name
                        )));
                    }
                    // The same value as the inherited declaration needs no modifier: planning compares the two
                    // as they would be written, and leaves the writing to rendering.
                    let inherited = self.explicit_value(e.node, ty, dims.as_deref());
                    v.filter(|x| inherited.as_ref() != Some(x))
                        .map(|_| Value::Of { node: o.node, ty: ty.clone(), dims: dims.clone() })
                } else {
                    None
                };
                if value.is_some() || !attrs.is_empty() {
                    body.mods.push(Mod::Value { ident: e.ident.clone(), is_final: false, attrs, value });
                }
                Some(updated)
            }
            ElemKind::Object { class } => {
                if e.count.is_some() && mode == Mode::Instance {
                    return Some(updated);
                }
                let td_e = m.node(e.node).type_definition;
                let td_c = n.type_definition.filter(|&t| m.node(t).class == NodeClass::ObjectType);
                let changed = td_c.is_some() && td_c != td_e && !self.is_event_type(td_c.unwrap_or(e.node));
                let children = self.own_children(o.node, mode);
                if !changed && children.is_empty() {
                    return Some(updated);
                }
                // The class of the override must be a subtype of the inherited class. When the inherited class
                // is a type's class, the new type's class is one (OPC UA subtypes the TypeDefinition). When it
                // is a declaration class, the new class extends it and declares again what the new type adds.
                // The inherited class as the component has it: with what modifiers of the base classes on the
                // component changed in its members.
                let old = self.class_infos.get(class).cloned().map(|info| match &e.modified {
                    Some(elements) => Rc::new(ClassInfo { elements: elements.to_vec(), ..(*info).clone() }),
                    None => info,
                });
                let mut children = children;
                let base_info = match (changed, class) {
                    // The modifiers on the component still apply to the new class: what they made present stays so.
                    (true, ClassKey::Type(_)) => td_c.and_then(|t| self.type_class(t)).map(|info| match &e.modified {
                        Some(elements) => Rc::new(ClassInfo {
                            elements: self.present_as_in(&info.elements, elements),
                            ..(*info).clone()
                        }),
                        None => info,
                    }),
                    (true, _) => {
                        if let (Some(new_info), Some(old)) = (td_c.and_then(|t| self.type_class(t)), &old) {
                            let have: BTreeSet<QualifiedName> = old
                                .elements
                                .iter()
                                .map(|x| x.bn.clone())
                                .chain(children.iter().map(|k| m.node(k.node).browse_name.clone()))
                                .collect();
                            let extra: Vec<Own> = new_info
                                .elements
                                .iter()
                                .filter(|x| {
                                    !have.contains(&x.bn) && !matches!(x.kind, ElemKind::Skipped | ElemKind::Method)
                                })
                                .map(|x| Own { node: x.node, rt: x.rt })
                                .collect();
                            children.splice(0..0, extra);
                        }
                        old.clone()
                    }
                    (false, _) => old.clone(),
                };
                let Some(base_info) = base_info else {
                    body.items.push(Item::Comment(format!(
                        "{} changes the inherited {} in a way that cannot be written here (its class contains itself).",
                        n.browse_name.name, e.ident
                    )));
                    return Some(updated);
                };
                let constraint_local = self.class_infos.get(class).map(|c| c.local_replaceable).unwrap_or(false);
                let child_path = join_path(path, &n.browse_name.name);
                let mut sub = self.plan_body(owner, &child_path, Some(&base_info), &children, mode, constraint_local);
                // A replaceable class whose components' inputs are free is the complete variant by default (see
                // `plan_new`), which binds them to the inherited class's values; where this node gives them other
                // values, it needs a class of its own, whose complete variant binds them.
                let rebinds = e.alias.is_some()
                    && old.as_ref().is_some_and(|c| c.is_partial_by_inputs() && self.rebinds(&c.free, &sub.elements));
                if !sub.adds && !changed && !rebinds {
                    let free = self.free_of(&sub.elements);
                    if old.as_ref().is_some_and(|c| c.is_partial_by_inputs()) {
                        // The component is of the complete variant, which binds the free inputs to the values
                        // of the class: bind the ones this node gives here, unless the class is replaceable
                        // (see `plan_new`).
                        if e.alias.is_none() {
                            for f in free {
                                bind_free(&mut sub.mods, &f.path, f.value());
                            }
                        }
                        updated.nested_free = Some(Rc::new(Vec::new()));
                    } else {
                        updated.nested_free = Some(Rc::new(free));
                    }
                    // The members of the class, as these modifiers leave them (a new child that declares
                    // nothing, a method or a variable without a Modelica type, is not one).
                    sub.elements.truncate(base_info.elements.len());
                    updated.modified = Some(Rc::new(sub.elements));
                    if !sub.mods.is_empty() {
                        body.mods.push(Mod::Nested { ident: e.ident.clone(), mods: sub.mods });
                    }
                    return Some(updated);
                }
                let Some(alias) = e.alias.clone() else {
                    body.items.push(Item::Comment(format!(
                        "{} adds children to the inherited component {}, which cannot be redeclared here; they are not represented.",
                        n.browse_name.name, e.ident
                    )));
                    self.lossy(
                        o.node,
                        format!(
                            "`{}` in `{}` adds to an inherited component that is not replaceable; the additions are left out",
                            n.browse_name.name,
                            m.qualified(owner.node())
                        ),
                    );
                    if !sub.mods.is_empty() && !changed {
                        // The members the class has, as these modifiers leave them (the additions are not there).
                        sub.elements.truncate(base_info.elements.len());
                        updated.modified = Some(Rc::new(sub.elements));
                        body.mods.push(Mod::Nested { ident: e.ident.clone(), mods: sub.mods });
                    }
                    return Some(updated);
                };
                let key = self.add_decl(owner, &child_path, o.node, &base_info, sub);
                body.mods.push(Mod::Redeclare { ident: alias.clone(), class: TypeRef::Class(key.clone()) });
                // The component's declaration repeats the choices of the class it was declared with
                // (`Mod::Pin`). That is an outer modification of the class plugged in here, so it would win
                // over this class's own choices (Modelica 7.2.4) and hide the members they add: repeat this
                // class's choices on the component, which is more outer still. (pymoca rejects the modifiers
                // of the added members otherwise; `tests/modelica/planted`, `PinnedOverride`.)
                match &e.pinned {
                    Some(p) => body.mods.push(Mod::Repin {
                        ident: e.ident.clone(),
                        pin: p.pin.clone(),
                        class: key.clone(),
                        declared: p.declared.clone(),
                    }),
                    None => body.mods.push(Mod::Nested { ident: e.ident.clone(), mods: vec![Mod::Pin { class: key.clone() }] }),
                }
                body.adds = true;
                updated.kind = ElemKind::Object { class: key };
                updated.nested_free = None;
                // The new class records its members (it was planned from the inherited ones as modified here).
                updated.modified = None;
                Some(updated)
            }
        }
    }

    /// Whether the free inputs of `elements` (a class body's members) take values other than those of `free`,
    /// the free inputs of the inherited class, which its complete variant binds. A declaration without a value
    /// changes nothing: the inherited value stays.
    fn rebinds(&mut self, free: &[Free], elements: &[Element]) -> bool {
        for f in self.free_of(elements) {
            let Some(g) = free.iter().find(|g| g.path == f.path) else { return true };
            if g.node == f.node {
                continue;
            }
            let given = self.explicit_value(f.node, &f.ty, None);
            if given.is_some() && given != self.explicit_value(g.node, &g.ty, None) {
                return true;
            }
        }
        false
    }

    /// The members of a new class of a component (`elements`), each optional member that the component's
    /// modifiers made present in its former class (`modified`, its members as they left them) present here too,
    /// at any depth: the modifiers apply to whatever class the component has.
    fn present_as_in(&self, elements: &[Element], modified: &[Element]) -> Vec<Element> {
        elements
            .iter()
            .map(|x| {
                let mut x = x.clone();
                let Some(was) = modified.iter().find(|w| w.bn == x.bn) else { return x };
                if was.present && x.use_flag.is_some() && x.use_flag == was.use_flag {
                    x.present = true;
                }
                if let (ElemKind::Object { class }, Some(inner)) = (&x.kind, &was.modified) {
                    let members = match &x.modified {
                        Some(m) => Some(m.to_vec()),
                        None => self.class_infos.get(class).map(|i| i.elements.clone()),
                    };
                    if let Some(members) = members {
                        x.modified = Some(Rc::new(self.present_as_in(&members, inner)));
                    }
                }
                x
            })
            .collect()
    }

    /// A comment that documents a method: calls go through an OPC UA client, not through Modelica.
    fn method_comment(&self, method: NodeIx) -> String {
        let m = self.m;
        let name = &m.node(method).browse_name.name;
        let args = |a: &[crate::model::Argument]| -> String {
            a.iter()
                .map(|x| {
                    let t = x.data_type.map(|d| m.node(d).browse_name.name.clone()).unwrap_or_else(|| "?".into());
                    let arr = if x.value_rank >= 0 { "[]" } else { "" };
                    format!("{t}{arr} {}", x.name)
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        match m.methods.get(&method) {
            Some(info) if !info.outputs.is_empty() => {
                format!(
                    "Method {name}({}) returns ({}): call it through an OPC UA client.",
                    args(&info.inputs),
                    args(&info.outputs)
                )
            }
            Some(info) => format!("Method {name}({}): call it through an OPC UA client.", args(&info.inputs)),
            None => format!("Method {name}: call it through an OPC UA client."),
        }
    }
}

fn use_decl(flag: &str, original: &str) -> Item {
    Item::Decl {
        prefix: "parameter".into(),
        ty: TypeRef::Path("Boolean".into()),
        ident: flag.to_string(),
        dims: String::new(),
        mods: Vec::new(),
        value: Some("false".into()),
        cond: None,
        desc: string_literal(&format!("Whether the optional {original} exists")),
        annotation: "Evaluate=true".into(),
    }
}

/// The count of a placeholder: at least one, and one by default, where the placeholder is mandatory.
fn count_decl(count: &str, original: &str, rule: Option<ModellingRule>) -> Item {
    let (what, min) = match rule {
        Some(ModellingRule::MandatoryPlaceholder) => ("MandatoryPlaceholder: a conforming object has at least one", "1"),
        _ => ("OptionalPlaceholder", "0"),
    };
    Item::Decl {
        prefix: "parameter".into(),
        ty: TypeRef::Path("Integer".into()),
        ident: count.to_string(),
        dims: String::new(),
        mods: vec![Mod::Value { ident: "min".into(), is_final: false, attrs: Vec::new(), value: Some(min.into()) }],
        value: Some(min.into()),
        cond: None,
        desc: string_literal(&format!("Number of {original} ({what})")),
        annotation: "Evaluate=true".into(),
    }
}

/// The BrowseNames of a placeholder's elements, which the server chooses: the placeholder's own BrowseName
/// (`<AxisIdentifier>`) until a user names them, so that a binding by browse path fails loudly, not on a
/// node of another name.
fn browse_names_decl(names: &str, count: &str, original: &str) -> Item {
    Item::Decl {
        prefix: "parameter".into(),
        ty: TypeRef::Path("String".into()),
        ident: names.to_string(),
        dims: format!("[{count}]"),
        mods: Vec::new(),
        value: Some(format!("fill({}, {count})", string_literal(original)).into()),
        cond: None,
        desc: string_literal(&format!("BrowseNames of the {original} elements")),
        annotation: String::new(),
    }
}

/// Attribute modifiers (`unit="m"`) of a declaration; `each` for an array.
pub fn attr_mods(attrs: &[String], array: bool) -> Vec<Mod> {
    attrs
        .iter()
        .filter_map(|a| {
            let (k, v) = a.split_once('=')?;
            let ident = if array { format!("each {k}") } else { k.to_string() };
            Some(Mod::Value { ident, is_final: false, attrs: Vec::new(), value: Some(v.into()) })
        })
        .collect()
}

/// The declared type of a signal: a connector of OpcUaSupport for the predefined types, else the type with an
/// `input`/`output` prefix; with the attributes an alias type would have carried. A value the model publishes
/// (clients only read it) is an input, computed outside and connected in; a value clients write is an output,
/// which the model hands on to the physics.
fn signal_type(ty: &MType, writable: bool) -> (String, String, Vec<String>) {
    let dir = if writable { "Output" } else { "Input" };
    match ty {
        MType::Scalar { base, min, max, unit, .. } => {
            let mut attrs = Vec::new();
            if let Some(x) = min {
                attrs.push(format!("min={x}"));
            }
            if let Some(x) = max {
                attrs.push(format!("max={x}"));
            }
            if let Some(u) = unit {
                attrs.push(format!("unit={}", string_literal(u)));
            }
            (String::new(), format!("{}.{}{dir}", super::support::PACKAGE, base.name()), attrs)
        }
        other => ((if writable { "output" } else { "input" }).into(), other.type_name().to_string(), Vec::new()),
    }
}
