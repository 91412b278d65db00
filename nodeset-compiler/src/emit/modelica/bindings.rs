//! Binding models: each top-level instance bound to its OPC UA nodes at run time.
//!
//! `<Pkg>.Instances.Bindings.<Name>` extends the instance's class `<Pkg>.Instances.<Name>` and declares one
//! read or write block of `OpcUaSupport.Interfaces` per scalar Real, Integer, Boolean or String variable of
//! the instance, with the variable's NodeId, browse path and unit conversion:
//!
//! * a variable clients may write (AccessLevel CurrentWrite, an output connector of the class, which the model
//!   hands on) takes its value from a read block, through a modifier of the `extends` clause
//!   (`extends Instances.DrillingCell(skillSet(referenceDrillBush(inputParameterSet(approachDistance=
//!   readSkillSetReferenceDrillBushInputParameterSetApproachDistance.y))))`);
//! * a variable clients may only read (an input connector, which the physics computing it connects to) is
//!   written by a write block whose input an equation binds to it
//!   (`writeSkillSetDrillHoleOutputParameterSetResult.u = skillSet.drillHole.outputParameterSet.result`).
//!
//! The block classes are replaceable (`replaceable block ReadReal = OpcUaSupport.Loopback.ReadReal
//! constrainedby OpcUaSupport.Interfaces.ReadReal`): the default, Loopback, needs no server, so a bound
//! instance simulates as it is; an OPC UA library that implements the interfaces binds it to a server.
//! What cannot be bound is listed in a comment: properties (parameters, fixed for a simulation), arrays,
//! enumerations and structures (the interfaces read scalars of the predefined types), and a variable the
//! model publishes inside an optional component (Modelica 4.4.5 lets a conditional component be modified,
//! not read).

use super::ctx::{node_id_text, Ctx};
use super::plan::{ElemKind, Element};
use super::text::{self, string_literal};
use super::plan::{Base, MType};
use crate::model::NodeIx;
use crate::raw::NodeClass;
use std::collections::BTreeMap;

/// One variable of an instance and where its component is.
struct Var {
    node: NodeIx,
    /// Component identifiers from the instance class down to the variable.
    path: Vec<String>,
    /// Whether a component on the path (the variable included) is conditional.
    conditional: bool,
    ty: MType,
    array: bool,
    writable: bool,
}

/// The modifiers of the `extends` clause, as a tree of component names.
#[derive(Default)]
struct ModTree {
    value: Option<String>,
    kids: BTreeMap<String, ModTree>,
}

impl ModTree {
    fn insert(&mut self, path: &[String], value: String) {
        match path.split_first() {
            None => self.value = Some(value),
            Some((first, rest)) => self.kids.entry(first.clone()).or_default().insert(rest, value),
        }
    }

    fn render(&self) -> String {
        let kids: Vec<String> = self
            .kids
            .iter()
            .map(|(k, t)| match &t.value {
                Some(v) => format!("{k}={v}"),
                None => format!("{k}({})", t.render()),
            })
            .collect();
        kids.join(", ")
    }
}

impl Ctx<'_> {
    /// The binding model of a top-level instance object (planned before), or `None` when it has no variable
    /// to bind.
    pub fn binding_model(&mut self, ns: u16, top: NodeIx) -> Option<String> {
        let m = self.m;
        let (elements, taken) = self.instance_classes.get(&top).cloned()?;
        let mut vars = Vec::new();
        self.collect_bound(top, &elements, &mut Vec::new(), false, &mut vars, 0);
        let names = self.names(ns);
        let pkg = self.pkg[ns as usize].clone();
        let class = names.instances[&top].clone();
        let sup = super::support::PACKAGE;

        let mut scope = self.scope::<usize>();
        for t in &taken {
            scope.reserve(t);
        }
        for b in ["Real", "Integer", "Boolean", "String"] {
            scope.reserve(&format!("Read{b}"));
            scope.reserve(&format!("Write{b}"));
        }
        let mut left_out: Vec<String> = Vec::new();
        let mut bound: Vec<(usize, Base)> = Vec::new();
        for (i, v) in vars.iter().enumerate() {
            let bn = &m.node(v.node).browse_name.name;
            let where_ = v.path.join(".");
            let why = match (&v.ty, v.array) {
                (_, true) => Some("an array"),
                (MType::Scalar { .. }, false) if !v.writable && v.conditional => {
                    Some("published inside an optional component, which Modelica lets be modified, not read")
                }
                (MType::Scalar { base, .. }, false) => {
                    bound.push((i, *base));
                    None
                }
                _ => Some("not a Real, Integer, Boolean or String"),
            };
            if let Some(why) = why {
                left_out.push(format!("{where_} ({bn}): {why}"));
            } else {
                let verb = if v.writable { "read" } else { "write" };
                scope.add(&camel_path(verb, &v.path), i);
            }
        }
        if bound.is_empty() {
            return None;
        }
        let (idents, collisions) = scope.finish();
        self.report(&format!("{pkg}.Instances.Bindings.{class}"), "blocks", collisions, |i| {
            (vars[*i].node, Some(m.node(vars[*i].node).browse_name.name.clone()))
        });

        let mut mods = ModTree::default();
        let mut blocks = Vec::new();
        let mut equations = Vec::new();
        let mut kinds: BTreeMap<String, Base> = BTreeMap::new();
        for &(i, base) in &bound {
            let v = &vars[i];
            let n = m.node(v.node);
            let ident = &idents[&i];
            let kind = format!("{}{}", if v.writable { "Read" } else { "Write" }, base.name());
            kinds.insert(kind.clone(), base);
            let mut args = vec![
                format!("nodeId={}", string_literal(&node_id_text(m, &n.id))),
                format!("browsePath={}", string_literal(&super::instances::path_from_objects(m, v.node))),
            ];
            if base == Base::Real {
                if let Some(Ok(u)) = self.unit_of(v.node) {
                    if !u.is_si() {
                        args.push(format!("siFactor={}", u.factor));
                        if u.offset != 0.0 {
                            args.push(format!("siOffset={}", u.offset));
                        }
                    }
                }
            }
            if v.writable {
                if let Some(Ok(val)) = m.value(v.node) {
                    if let Some(t) = self.value_text(&val) {
                        args.push(format!(
                            "initValue={}",
                            if base == Base::String { string_literal(&t) } else { t }
                        ));
                    }
                }
                mods.insert(&v.path, format!("{ident}.y"));
            } else {
                // An equation, not a modifier `u=...`: pymoca 0.12 cannot look up a composite name in a modifier
                // of a component once the binding model is itself a component.
                equations.push(format!("  {ident}.u = {};\n", v.path.join(".")));
            }
            let desc = text::description(&n.browse_name.name, n.doc());
            blocks.push(format!(
                "  {kind} {ident}({}) {desc};\n",
                args.join(", ")
            ));
        }

        let mut s = format!(
            "model {class} {}\n",
            string_literal(&format!("{}, bound to its OPC UA nodes", m.node(top).browse_name.name))
        );
        let extends = mods.render();
        if extends.is_empty() {
            s.push_str(&format!("  extends {pkg}.Instances.{class};\n"));
        } else {
            s.push_str(&format!("  extends {pkg}.Instances.{class}(\n    {extends});\n"));
        }
        for kind in kinds.keys() {
            s.push_str(&format!(
                "  replaceable block {kind} = {sup}.Loopback.{kind} constrainedby {sup}.Interfaces.{kind}\n    {};\n",
                string_literal(&format!(
                    "The block that {} a variable: redeclare it with an implementation of {sup}.Interfaces.{kind} to bind to a server",
                    if kind.starts_with("Read") { "reads" } else { "writes" }
                ))
            ));
        }
        for b in &blocks {
            s.push_str(b);
        }
        if !left_out.is_empty() {
            s.push_str("  // Not bound (the interfaces read and write scalars of the predefined types):\n");
            for l in &left_out {
                s.push_str(&format!("  //   {l}\n"));
            }
        }
        if !equations.is_empty() {
            s.push_str("equation\n");
            for e in &equations {
                s.push_str(e);
            }
        }
        let doc = format!(
            "<p>The instance {} with each of its variables bound to its node: a variable clients may write is \
             read from the server, a variable the model publishes is written to it. The blocks are \
             <code>{sup}.Loopback</code> until redeclared: then the model simulates without a server, its \
             reads giving the values of the nodeset. Declare <code>inner parameter \
             {sup}.Interfaces.Connection connection</code> beside it. Properties are parameters and keep the \
             values of the nodeset.</p>",
            text::html_escape(&super::instances::path_from_objects(m, top))
        );
        s.push_str(&format!(
            "  annotation (\n    {},\n    {});\nend {class};\n",
            text::documentation(&doc),
            text::MODEL_ICON
        ));
        Some(s)
    }

    /// The variables below instance node `node`, whose class has `elements`, matched by BrowseName.
    fn collect_bound(
        &self,
        node: NodeIx,
        elements: &[Element],
        path: &mut Vec<String>,
        conditional: bool,
        out: &mut Vec<Var>,
        depth: usize,
    ) {
        let m = self.m;
        if depth > super::ctx::MAX_NESTING {
            return;
        }
        let ns = m.node(node).id.ns;
        for (_, c) in m.children(node) {
            let child = m.node(c);
            if child.modelling_rule.is_some() || child.id.ns != ns {
                continue;
            }
            let Some(e) = elements.iter().find(|e| e.bn == child.browse_name) else { continue };
            let cond = conditional || e.use_flag.is_some();
            path.push(e.ident.clone());
            match (&e.kind, child.class) {
                (ElemKind::Signal { ty, dims, .. }, NodeClass::Variable) if e.count.is_none() => {
                    out.push(Var {
                        node: c,
                        path: path.clone(),
                        conditional: cond,
                        ty: ty.clone(),
                        array: dims.is_some(),
                        writable: child.attrs.access_level.unwrap_or(1) & 0x02 != 0,
                    });
                }
                (ElemKind::Object { class }, NodeClass::Object) if e.count.is_none() => {
                    if let Some(info) = self.class_infos.get(class).cloned() {
                        self.collect_bound(c, &info.elements, path, cond, out, depth + 1);
                    }
                }
                _ => {}
            }
            path.pop();
        }
    }
}

/// The name of a block: a verb and the component path as one identifier (`read`, `skillSet.drillHole.depth` ->
/// `readSkillSetDrillHoleDepth`), so that it does not take the name of a component of the instance.
fn camel_path(verb: &str, path: &[String]) -> String {
    let mut out = verb.to_string();
    for p in path {
        let mut chars = p.trim_end_matches('_').chars();
        if let Some(c) = chars.next() {
            out.extend(c.to_uppercase());
            out.push_str(chars.as_str());
        }
    }
    out
}

impl Ctx<'_> {
    /// `<Pkg>.Examples.<Name>`: a top-level instance object as a model that simulates as it is, with an
    /// `experiment` annotation: its binding model beside the `inner` connection, or the instance when it has no
    /// variable to bind.
    pub fn example_model(&mut self, ns: u16, top: NodeIx, bound: bool) -> String {
        let m = self.m;
        let names = self.names(ns);
        let pkg = self.pkg[ns as usize].clone();
        let class = names.instances[&top].clone();
        let n = m.node(top);
        let sup = super::support::PACKAGE;
        let mut scope = self.scope::<u8>();
        scope.reserve("connection");
        scope.add(&super::ctx::component_original(&n.browse_name.name), 0);
        let (idents, _) = scope.finish();
        let ident = &idents[&0];
        let (used, how) = if bound {
            (
                format!("{pkg}.Instances.Bindings.{class}"),
                format!(
                    "its binding model, whose read and write blocks are <code>{sup}.Loopback</code>: the reads give \
                     the values of the nodeset until you feed them tables (<code>{ident}(read...(table=[0, v0; t1, v1]))</code>) \
                     or redeclare them with an OPC UA library"
                ),
            )
        } else {
            (format!("{pkg}.Instances.{class}"), "the instance (it has no variable to bind)".to_string())
        };
        let mut s = format!(
            "model {class} {}\n",
            string_literal(&format!("{}, simulated as it is", n.browse_name.name))
        );
        if bound {
            s.push_str(&format!(
            "  inner parameter {sup}.Interfaces.Connection connection\n    {}\n    annotation (Placement(transformation(extent={{{{-90,70}},{{-70,90}}}})));\n",
            string_literal("The OPC UA server the read and write blocks talk to (the loopback blocks need none)")
            ));
        }
        s.push_str(&format!(
            "  {used} {ident} {}\n    annotation (Placement(transformation(extent={{{{-20,-20}},{{20,20}}}})));\n",
            text::description(&n.browse_name.name, n.doc())
        ));
        let doc = format!(
            "<p>The instance {} of the nodeset, ready to simulate: {how}. Its state machines, if any, stay in their \
             initial state until a model of yours drives their triggers.</p>",
            text::html_escape(&super::instances::path_from_objects(m, top))
        );
        s.push_str(&format!(
            "  annotation (\n    experiment(StopTime=1, Interval=0.01),\n    {},\n    {});\nend {class};\n",
            text::documentation(&doc),
            text::EXAMPLE_ICON
        ));
        s
    }
}
