//! ObjectTypes, the classes of their instance declarations, and instances: one planner for all three.
//!
//! A class is planned from a base class (the supertype, the TypeDefinition, or the class an overridden member
//! already had) and the node's own children. A child whose BrowseName matches an element of the base
//! *overrides* it: a ModellingRule made Mandatory becomes `final use_x = true`, a value becomes a modifier, a
//! child with children of its own becomes a redeclaration with a class of its own. Any other child is a new
//! element. Every element keeps its origin in an `__OPCUA(browsePath, nodeId, dataType)` annotation; the
//! browse path is relative to the object the enclosing class stands for.

use super::ctx::{component_original, count_name, node_id_text, undescribed, ClassKey, Ctx, Owner, MAX_NESTING};
use super::text::{self, string_literal};
use super::types::{as_i128, dims_text, Base, MType};
use super::units::Unit;
use crate::model::{ids, ModellingRule, NodeIx};
use crate::nodeid::QualifiedName;
use crate::raw::NodeClass;
use crate::value::{BuiltinType, Variant};
use std::collections::{BTreeSet, HashMap};
use std::rc::Rc;

/// What a planned class offers to classes built on it.
#[derive(Debug, Clone)]
pub struct ClassInfo {
    pub key: ClassKey,
    pub elements: Vec<Element>,
    /// Every identifier the class uses (elements, `use_` flags, counts, state machine names).
    pub taken: BTreeSet<String>,
    /// Whether the class declares replaceable elements itself (not through `extends`); a redeclaration may
    /// only use a class with local replaceable elements when its constraining class has some too (MLS 6.4,
    /// as rumoca checks it).
    pub local_replaceable: bool,
    /// The state machine this class (or a base class) drives.
    pub state_machine: Option<Rc<super::statemachine::SmInfo>>,
    /// The connectors on its icon.
    pub placed: Placed,
    /// The input connectors nothing binds, in the class itself and in its components (see [`Free`]).
    pub free: Rc<Vec<Free>>,
}

impl ClassInfo {
    /// Whether a component of the class leaves inputs unbound, so the class is partial and its components use
    /// its complete variant (`<Pkg>.Complete...`), which binds them to the nodeset's values.
    pub fn is_partial_by_inputs(&self) -> bool {
        self.free.iter().any(|f| f.path.len() > 1)
    }
}

/// An input connector nothing binds: a value the model publishes, which the physics that computes it
/// `connect`s to. The complete variant of a class binds it to the nodeset's value.
#[derive(Debug, Clone)]
pub struct Free {
    /// The component path, each step with whether that component is an array (`each` for what follows).
    pub path: Vec<(String, bool)>,
    /// The node whose value the complete variant binds.
    pub node: NodeIx,
    pub ty: MType,
}

#[derive(Debug, Clone)]
pub struct Element {
    pub bn: QualifiedName,
    pub ident: String,
    pub node: NodeIx,
    /// The reference from the parent (HasProperty, HasComponent, ...).
    pub rt: NodeIx,
    /// An optional element that a base class already made present (`final use_x = true`).
    pub present: bool,
    pub kind: ElemKind,
    pub use_flag: Option<String>,
    pub count: Option<String>,
    /// The replaceable class alias of an object (`replaceable model Axes = ...; Axes axes;`), which subclasses
    /// and users redeclare.
    pub alias: Option<String>,
    /// The free inputs of an object whose members this class modifies without a class of its own (else those of
    /// its class).
    pub nested_free: Option<Rc<Vec<Free>>>,
}

#[derive(Debug, Clone)]
pub enum ElemKind {
    Parameter {
        ty: MType,
        dims: Option<Vec<Option<u32>>>,
    },
    Signal {
        ty: MType,
        dims: Option<Vec<Option<u32>>>,
        /// An input connector nothing binds (see [`Free`]).
        free: bool,
    },
    Object {
        class: ClassKey,
    },
    Method,
    /// A child held by a reference that is not containment (Requires, Moves, ...), or whose containment would
    /// make the class contain itself: a `String` parameter with the NodeId of the target (an array of them for
    /// a placeholder).
    Reference {
        array: bool,
    },
    /// Declared nowhere (no Modelica type); the name stays taken.
    Skipped,
}

/// A class name in generated text: a fixed path or a class that is named once its owner is planned.
#[derive(Debug, Clone, PartialEq)]
pub enum TypeRef {
    Path(String),
    Class(ClassKey),
}

#[derive(Debug, Clone)]
pub enum Mod {
    Value {
        ident: String,
        is_final: bool,
        attrs: Vec<String>,
        value: Option<String>,
    },
    Nested {
        ident: String,
        mods: Vec<Mod>,
    },
    /// `redeclare model <Alias> = <class>`.
    Redeclare {
        ident: String,
        class: TypeRef,
    },
    /// On a component of `class`: the class's own choice for each of its replaceable aliases that some class
    /// redeclares, repeated as `redeclare model <Alias> = <class of Alias in class>` (see
    /// [`Ctx::redeclared`](super::ctx::Ctx::redeclared)). Equivalent Modelica; rumoca 0.10.2 needs it, because it
    /// lets an enclosing instance's redeclaration of an alias replace the nested class's own.
    Pin {
        class: ClassKey,
    },
}

#[derive(Debug, Clone)]
pub enum Item {
    Comment(String),
    /// `replaceable model <ident> = <class> "desc";`
    Alias {
        ident: String,
        class: TypeRef,
        desc: String,
    },
    Decl {
        prefix: String,
        ty: TypeRef,
        ident: String,
        dims: String,
        mods: Vec<Mod>,
        value: Option<String>,
        cond: Option<String>,
        desc: String,
        annotation: String,
    },
}

/// A class ready to be written.
#[derive(Debug, Clone)]
pub struct ClassPlan {
    pub keyword: &'static str,
    pub desc: String,
    pub doc_html: String,
    pub extends: Option<(TypeRef, Vec<Mod>)>,
    pub items: Vec<Item>,
    pub equations: Vec<String>,
    pub opcua: String,
}

/// The classes of one owner (an ObjectType or a top-level instance).
#[derive(Debug, Default)]
pub struct OwnerPlan {
    pub main: Option<ClassPlan>,
    pub decls: Vec<(String, ClassPlan)>,
}

/// A child of the node a class is planned for, with the reference that holds it.
#[derive(Debug, Clone, Copy)]
pub struct Own {
    pub node: NodeIx,
    pub rt: NodeIx,
}

/// A declaration class whose base is a type still being planned (types that contain each other through
/// placeholders); planned as soon as that type is complete.
#[derive(Debug, Clone)]
pub struct Deferred {
    pub owner: Owner,
    pub path: String,
    pub node: NodeIx,
    pub td: NodeIx,
    pub children: Vec<Own>,
    pub mode: Mode,
}

/// What planning a class body produced.
#[derive(Debug, Default)]
pub struct Body {
    pub mods: Vec<Mod>,
    pub items: Vec<Item>,
    pub equations: Vec<String>,
    pub elements: Vec<Element>,
    pub taken: BTreeSet<String>,
    pub local_replaceable: bool,
    /// The body declares or redeclares something, so it needs a class of its own (modifiers alone do not).
    pub adds: bool,
    /// The state the inherited state machine starts in here, when a child CurrentState names another one.
    pub initial: Option<usize>,
    /// How many input and output connectors the class has placed on its icon (inherited ones included).
    pub placed: Placed,
}

/// How many input connectors (left edge of the icon) and output connectors (right edge) a class places.
#[derive(Debug, Clone, Copy, Default)]
pub struct Placed {
    pub inputs: usize,
    pub outputs: usize,
}

impl Placed {
    /// The `Placement` of the next input (or output) connector: inputs down the left edge of the icon,
    /// outputs down the right one, 20 units apart from the top, as in the Modelica Standard Library's blocks.
    pub fn next(&mut self, input: bool) -> String {
        let i = if input { &mut self.inputs } else { &mut self.outputs };
        let y = 80 - 20 * *i as i64;
        *i += 1;
        let (x0, x1) = if input { (-120, -100) } else { (100, 120) };
        format!("Placement(transformation(extent={{{{{x0},{}}},{{{x1},{}}}}}))", y - 10, y + 10)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// An ObjectType or the class of an instance declaration: children without a ModellingRule are not
    /// instantiated.
    Type,
    /// An instance: every child is part of it, optional members are present when a child is.
    Instance,
}

impl Ctx<'_> {
    fn is_property(&self, rt: NodeIx) -> bool {
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
                    nested_free: None,
                });
                continue;
            }
            let mut dims = Self::dims(n.attrs.value_rank.unwrap_or(-1), &n.attrs.array_dimensions);
            let mut value = self.value_of(o.node, &ty, dims.as_deref());
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
                value = format!("fill({}, {count})", self.default_literal(&ty));
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
                nested_free: None,
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
        let body = eo.body.as_ref()?;
        let id: i32 = body.child_text("UnitId")?.trim().parse().ok()?;
        if id == -1 {
            return None;
        }
        match super::units::modelica_unit(id) {
            Some(u) => Some(Ok(u)),
            None => {
                let shown = body.child("DisplayName").and_then(|d| d.child_text("Text")).unwrap_or("").to_string();
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
        if mode == Mode::Instance {
            // An instance is complete: every input nothing binds yet gets the instance's value.
            for f in self.free_of(&elements) {
                let value = self.value_of(f.node, &f.ty, None);
                bind_free(&mut body.mods, &f.path, value);
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

    /// The free inputs of a class with these elements: its own, and those of its components. A component whose
    /// class leaves inputs of its components free uses the complete variant, which binds them all.
    pub fn free_of(&self, elements: &[Element]) -> Vec<Free> {
        let mut out = Vec::new();
        for e in elements {
            match &e.kind {
                ElemKind::Signal { free: true, ty, .. } => {
                    out.push(Free { path: vec![(e.ident.clone(), false)], node: e.node, ty: ty.clone() })
                }
                ElemKind::Object { class } => {
                    let inner = match &e.nested_free {
                        Some(f) => f.clone(),
                        None => match self.class_infos.get(class) {
                            Some(info) if !info.is_partial_by_inputs() => info.free.clone(),
                            _ => continue,
                        },
                    };
                    for f in inner.iter() {
                        let mut path = vec![(e.ident.clone(), e.count.is_some())];
                        path.extend(f.path.iter().cloned());
                        out.push(Free { path, node: f.node, ty: f.ty.clone() });
                    }
                }
                _ => {}
            }
        }
        out
    }

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
    fn gets_alias(&self, o: Own, mode: Mode, allow_replaceable: bool) -> bool {
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
            value: Some(value),
            cond: None,
            desc,
            annotation,
        });
        element
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
    fn plan_new(
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
            nested_free: None,
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
                let mut value = self.value_of(o.node, &ty, dims.as_deref());
                let mut cond = None;
                if let Some(c) = &record_count {
                    value = format!("fill({}, {c})", self.default_literal(&ty));
                }
                if placeholder {
                    let count = self.derived_name(body, count_name(&ident), o.node);
                    body.items.push(count_decl(&count, &bn.name, rule));
                    let mut d = vec![None];
                    d.extend(dims.clone().unwrap_or_default());
                    let default = self.default_literal(&ty);
                    let sizes: Vec<String> = std::iter::once(count.clone())
                        .chain(d[1..].iter().map(|x| x.unwrap_or(0).to_string()))
                        .collect();
                    value = format!("fill({default}, {})", sizes.join(", "));
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
                                            let value = self.value_of(f.node, &f.ty, None);
                                            bind_free(&mut mods, &f.path, value);
                                        }
                                    }
                                    element.nested_free = Some(Rc::new(Vec::new()));
                                } else {
                                    element.nested_free = Some(Rc::new(free));
                                }
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
                    let count = self.derived_name(body, count_name(&ident), o.node);
                    body.items.push(count_decl(&count, &bn.name, rule));
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
                if !event {
                    mods.insert(0, Mod::Pin { class: class.clone() });
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
    fn add_decl(&mut self, owner: Owner, path: &str, node: NodeIx, base: &Rc<ClassInfo>, sub: Body) -> ClassKey {
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
    fn plan_override(
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
                        value: Some(string_literal(&node_id_text(m, &n.id))),
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
                    // The same value as the inherited declaration needs no modifier.
                    let inherited = self.explicit_value(e.node, ty, dims.as_deref());
                    v.filter(|x| inherited.as_ref() != Some(x))
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
                let old = self.class_infos.get(class).cloned();
                let mut children = children;
                let base_info = match (changed, class) {
                    (true, ClassKey::Type(_)) => td_c.and_then(|t| self.type_class(t)),
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
                let sub = self.plan_body(owner, &child_path, Some(&base_info), &children, mode, constraint_local);
                if !sub.adds && !changed {
                    let mut sub = sub;
                    let free = self.free_of(&sub.elements);
                    if old.as_ref().is_some_and(|c| c.is_partial_by_inputs()) {
                        // The component is of the complete variant, which binds the free inputs to the values
                        // of the class: bind the ones this node gives here, unless the class is replaceable
                        // (see `plan_new`).
                        if e.alias.is_none() {
                            for f in free {
                                let value = self.value_of(f.node, &f.ty, None);
                                bind_free(&mut sub.mods, &f.path, value);
                            }
                        }
                        updated.nested_free = Some(Rc::new(Vec::new()));
                    } else {
                        updated.nested_free = Some(Rc::new(free));
                    }
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
                        body.mods.push(Mod::Nested { ident: e.ident.clone(), mods: sub.mods });
                    }
                    return Some(updated);
                };
                let key = self.add_decl(owner, &child_path, o.node, &base_info, sub);
                body.mods.push(Mod::Redeclare { ident: alias, class: TypeRef::Class(key.clone()) });
                // The component's declaration repeats the choices of the class it was declared with
                // (`Mod::Pin`). That is an outer modification of the class plugged in here, so it would win
                // over this class's own choices (Modelica 7.2.4) and hide the members they add: repeat this
                // class's choices on the component, which is more outer still. (pymoca rejects the modifiers
                // of the added members otherwise; `tests/modelica/planted`, `PinnedOverride`.)
                body.mods.push(Mod::Nested { ident: e.ident.clone(), mods: vec![Mod::Pin { class: key.clone() }] });
                body.adds = true;
                updated.kind = ElemKind::Object { class: key };
                updated.nested_free = None;
                Some(updated)
            }
        }
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

/// A state machine that starts in state `initial` instead of its own initial state.
fn starting_in(
    sm: Option<Rc<super::statemachine::SmInfo>>,
    initial: Option<usize>,
) -> Option<Rc<super::statemachine::SmInfo>> {
    match (sm, initial) {
        (Some(sm), Some(i)) => Some(Rc::new(super::statemachine::SmInfo { initial: i, ..(*sm).clone() })),
        (sm, _) => sm,
    }
}

fn join_path(path: &str, name: &str) -> String {
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

fn count_decl(count: &str, original: &str, rule: Option<ModellingRule>) -> Item {
    let what = match rule {
        Some(ModellingRule::MandatoryPlaceholder) => "MandatoryPlaceholder: a conforming object has at least one",
        _ => "OptionalPlaceholder",
    };
    Item::Decl {
        prefix: "parameter".into(),
        ty: TypeRef::Path("Integer".into()),
        ident: count.to_string(),
        dims: String::new(),
        mods: vec![Mod::Value { ident: "min".into(), is_final: false, attrs: Vec::new(), value: Some("0".into()) }],
        value: Some("0".into()),
        cond: None,
        desc: string_literal(&format!("Number of {original} ({what})")),
        annotation: "Evaluate=true".into(),
    }
}

/// The note on a class that is partial because members of its components are inputs nothing binds.
pub const COMPLETE_NOTE: &str = "<p>Members of its components are inputs that nothing binds (values the model \
publishes, which the physics computing them connects to), so the class is partial: extend it and connect them, or \
use its complete variant in the package <code>Complete</code>, which binds them to the nodeset's values.</p>";

/// Adds `path = value` to a modification list, inside the modifiers already there for the same components
/// (`a(b(x(unit="m")))` becomes `a(b(x(unit="m")=v))`); `each` after an array component.
pub fn bind_free(mods: &mut Vec<Mod>, path: &[(String, bool)], value: String) {
    bind_at(mods, path, value, false)
}

fn bind_at(mods: &mut Vec<Mod>, path: &[(String, bool)], value: String, each: bool) {
    let Some(((first, array), rest)) = path.split_first() else { return };
    let ident = if each { format!("each {first}") } else { first.clone() };
    if rest.is_empty() {
        for m in mods.iter_mut() {
            if let Mod::Value { ident: i, value: v @ None, .. } = m {
                if *i == ident {
                    *v = Some(value);
                    return;
                }
            }
        }
        mods.push(Mod::Value { ident, is_final: false, attrs: Vec::new(), value: Some(value) });
        return;
    }
    for m in mods.iter_mut() {
        if let Mod::Nested { ident: i, mods: inner } = m {
            if *i == ident {
                bind_at(inner, rest, value, *array);
                return;
            }
        }
    }
    let mut inner = Vec::new();
    bind_at(&mut inner, rest, value, *array);
    mods.push(Mod::Nested { ident, mods: inner });
}

/// Attribute modifiers (`unit="m"`) of a declaration; `each` for an array.
pub fn attr_mods(attrs: &[String], array: bool) -> Vec<Mod> {
    attrs
        .iter()
        .filter_map(|a| {
            let (k, v) = a.split_once('=')?;
            let ident = if array { format!("each {k}") } else { k.to_string() };
            Some(Mod::Value { ident, is_final: false, attrs: Vec::new(), value: Some(v.to_string()) })
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

/// A numeric value (or an array of them) in the engineering unit as the SI value, a Double; `None` for a value
/// that is not a number.
fn to_si(v: &Variant, unit: &Unit) -> Option<Variant> {
    let x = match v {
        Variant::Array(ty, items) => {
            let items: Option<Vec<Variant>> = items.iter().map(|i| to_si(i, unit)).collect();
            return Some(Variant::Array(*ty, items?));
        }
        Variant::Variant(inner) => return to_si(inner, unit),
        Variant::Float(f) => *f as f64,
        Variant::Double(f) => *f,
        other => as_i128(other)? as f64,
    };
    Some(Variant::Double(unit.to_si(x)))
}
