//! Human-readable summaries of a model: counts per namespace, and one type's instance declarations.

use crate::model::{Model, NodeIx};
use crate::raw::NodeClass;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Counts per namespace: nodes by class, types, instances.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NamespaceCounts {
    /// Nodes of each NodeClass.
    pub by_class: BTreeMap<NodeClass, usize>,
    /// Nodes of a type class (ObjectType, VariableType, ReferenceType, DataType).
    pub types: usize,
    /// Objects and Variables without a ModellingRule.
    pub instances: usize,
}

impl NamespaceCounts {
    /// The number of nodes of the namespace.
    pub fn total(&self) -> usize {
        self.by_class.values().sum()
    }
}

/// The counts of every namespace that has nodes, by global namespace index.
pub fn counts(model: &Model) -> BTreeMap<u16, NamespaceCounts> {
    let mut out: BTreeMap<u16, NamespaceCounts> = BTreeMap::new();
    for n in &model.nodes {
        let c = out.entry(n.id.ns).or_default();
        *c.by_class.entry(n.class).or_default() += 1;
        if n.class.is_type() {
            c.types += 1;
        } else if matches!(n.class, NodeClass::Object | NodeClass::Variable) && n.modelling_rule.is_none() {
            c.instances += 1;
        }
    }
    out
}

/// The per-namespace summary printed by `nodeset-compiler check`.
pub fn render(model: &Model) -> String {
    let mut s = String::new();
    for (ns, c) in counts(model) {
        let m = model.model_of_namespace(ns);
        let version = m.and_then(|m| m.version.as_deref()).unwrap_or("-");
        let _ = writeln!(s, "ns={ns} {} (version {version}): {} nodes, {} types, {} instances", model.namespace_uri(ns), c.total(), c.types, c.instances);
        let parts: Vec<String> = c.by_class.iter().map(|(k, v)| format!("{} {v}", k.name())).collect();
        let _ = writeln!(s, "    {}", parts.join(", "));
    }
    s
}

/// A type's supertypes and its instance declaration tree (inherited members included, `depth` levels).
pub fn show_type(model: &Model, t: NodeIx, depth: usize) -> String {
    let mut s = String::new();
    let node = model.node(t);
    let _ = writeln!(s, "{} {} ({})", node.class.name(), model.qualified(t), model.display_id(&node.id));
    let chain: Vec<String> = model.super_chain(t).iter().skip(1).map(|&c| model.qualified(c)).collect();
    if !chain.is_empty() {
        let _ = writeln!(s, "  supertypes: {}", chain.join(" -> "));
    }
    if let Some(doc) = node.doc() {
        let _ = writeln!(s, "  {}", doc.lines().next().unwrap_or(""));
    }
    let members = model.members.get(&t).cloned().unwrap_or_else(|| model.instance_members(t));
    let mut path = vec![t];
    tree(model, &members, 1, depth, &mut path, &mut s);
    s
}

fn tree(model: &Model, members: &[crate::model::Member], level: usize, depth: usize, path: &mut Vec<NodeIx>, s: &mut String) {
    for m in members {
        let n = model.node(m.node);
        let td = n.type_definition.map(|t| model.qualified(t)).unwrap_or_else(|| "-".into());
        let rule = n.modelling_rule.map(|r| r.name()).unwrap_or("no rule");
        let mut extra = String::new();
        if let Some(dt) = n.attrs.data_type {
            let _ = write!(extra, " dataType={}", model.qualified(dt));
            if let Some(r) = n.attrs.value_rank {
                let _ = write!(extra, " valueRank={r}");
            }
        }
        if m.declared_in != *path.last().unwrap_or(&m.declared_in) {
            let _ = write!(extra, " (from {})", model.qualified(m.declared_in));
        }
        let _ = writeln!(
            s,
            "{}{} {} : {} [{}]{}",
            "  ".repeat(level),
            n.class.name(),
            model.qualified(m.node),
            td,
            rule,
            extra
        );
        if level < depth && !path.contains(&m.node) && n.class != NodeClass::Method {
            let sub = model.instance_members(m.node);
            // Properties of properties are rare; skip empty levels.
            if !sub.is_empty() {
                path.push(m.node);
                tree(model, &sub, level + 1, depth, path, s);
                path.pop();
            }
        }
    }
}

/// A complete, stable text dump of the resolved model: namespaces, models, then every node sorted by NodeId
/// with its attributes, resolved references and derived facts. Used by snapshot and determinism tests.
pub fn dump(model: &Model) -> String {
    let mut s = String::new();
    for (i, ns) in model.namespaces.iter().enumerate() {
        let _ = writeln!(s, "namespace {i} {ns}");
    }
    let mut models: Vec<_> = model.models.iter().collect();
    models.sort_by_key(|m| m.ns);
    for m in models {
        let req: Vec<String> =
            m.required.iter().map(|r| format!("{}@{}", r.uri, r.version.as_deref().unwrap_or("-"))).collect();
        let _ = writeln!(s, "model {} {} requires [{}]", m.uri, m.version.as_deref().unwrap_or("-"), req.join(", "));
    }
    let mut order: Vec<NodeIx> = (0..model.nodes.len() as u32).map(NodeIx).collect();
    order.sort_by(|a, b| model.node(*a).id.cmp(&model.node(*b).id));
    let id = |ix: NodeIx| model.node(ix).id.to_string();
    for ix in order {
        let n = model.node(ix);
        let _ = write!(s, "{} {} {}", n.id, n.class.name(), n.browse_name);
        if let Some(t) = n.super_type {
            let _ = write!(s, " super={}", id(t));
        }
        if let Some(t) = n.type_definition {
            let _ = write!(s, " type={}", id(t));
        }
        if let Some(r) = n.modelling_rule {
            let _ = write!(s, " rule={}", r.name());
        }
        if let Some(dt) = n.attrs.data_type {
            let _ = write!(s, " dataType={}", id(dt));
        }
        if let Some(r) = n.attrs.value_rank {
            let _ = write!(s, " valueRank={r}");
        }
        if !n.attrs.array_dimensions.is_empty() {
            let _ = write!(s, " arrayDimensions={:?}", n.attrs.array_dimensions);
        }
        if let Some(a) = n.attrs.access_level {
            let _ = write!(s, " accessLevel={a}");
        }
        if n.is_abstract() {
            s.push_str(" abstract");
        }
        if let Some(p) = n.parent {
            let _ = write!(s, " parent={}", id(p));
        }
        if let Some(m) = n.attrs.method_declaration {
            let _ = write!(s, " methodDeclaration={}", id(m));
        }
        s.push('\n');
        match model.value(ix) {
            Some(Ok(v)) => {
                let mut text = format!("{v:?}");
                if text.len() > 160 {
                    let cut = (0..=160).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
                    text.truncate(cut);
                    text.push_str("...");
                }
                let _ = writeln!(s, "    value {text}");
            }
            Some(Err(e)) => {
                let _ = writeln!(s, "    value error: {e}");
            }
            None => {}
        }
        let mut refs: Vec<String> = n
            .references
            .iter()
            .map(|r| format!("{}{}{}", model.node(r.reference_type).browse_name.name, if r.forward { "->" } else { "<-" }, id(r.target)))
            .collect();
        refs.sort();
        if !refs.is_empty() {
            let _ = writeln!(s, "    refs {}", refs.join(" "));
        }
        if let Some(dt) = model.data_types.get(&ix) {
            let _ = writeln!(s, "    datatype {} encoding={:?}", kind_summary(model, &dt.kind), dt.encoding);
        }
        if let Some(m) = model.methods.get(&ix) {
            let args = |a: &[crate::model::Argument]| {
                a.iter()
                    .map(|x| format!("{}:{}[{}]", x.name, x.data_type.map(id).unwrap_or_default(), x.value_rank))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let _ = writeln!(s, "    method in ({}) out ({})", args(&m.inputs), args(&m.outputs));
        }
        if let Some(sm) = model.state_machines.get(&ix) {
            for st in &sm.states {
                let _ = writeln!(s, "    state {} number={:?} initial={}", st.name, st.number, st.initial);
            }
            for t in &sm.transitions {
                let _ = writeln!(
                    s,
                    "    transition {} number={:?} from={} to={} causes={}",
                    t.name,
                    t.number,
                    t.from.map(|f| model.node(f).browse_name.name.clone()).unwrap_or_default(),
                    t.to.map(|f| model.node(f).browse_name.name.clone()).unwrap_or_default(),
                    t.causes.iter().map(|c| model.node(*c).browse_name.name.clone()).collect::<Vec<_>>().join("|")
                );
            }
            if let Some(e) = sm.event_type {
                let _ = writeln!(s, "    transition event {}", model.node(e).browse_name.name);
            }
        }
        if let Some(members) = model.members.get(&ix) {
            for m in members {
                let _ = writeln!(s, "    member {} = {} (declared in {})", m.browse_name, id(m.node), id(m.declared_in));
            }
        }
    }
    s
}

fn kind_summary(model: &Model, k: &crate::model::DataTypeKind) -> String {
    use crate::model::DataTypeKind as K;
    match k {
        K::Builtin(b) => format!("builtin {}", b.type_name()),
        K::AbstractBuiltin => "abstract".into(),
        K::Simple(b) => format!("simple {}", b.type_name()),
        K::Enumeration { values, source } => format!(
            "enum({source:?}) {}",
            values.iter().map(|v| format!("{}={}", v.name, v.value)).collect::<Vec<_>>().join(",")
        ),
        K::OptionSet { base, bits } => format!(
            "optionset {} {}",
            base.type_name(),
            bits.iter().map(|v| format!("{}={}", v.name, v.value)).collect::<Vec<_>>().join(",")
        ),
        K::Structure { kind, fields, .. } => format!(
            "{kind:?} {}",
            fields
                .iter()
                .map(|f| format!(
                    "{}{}:{}[{}{}]{}",
                    f.name,
                    if f.is_optional { "?" } else { "" },
                    model.node(f.data_type).browse_name.name,
                    f.value_rank,
                    if f.array_dimensions.is_empty() { String::new() } else { format!(";{:?}", f.array_dimensions) },
                    if f.allow_sub_types { "+subtypes" } else { "" }
                ))
                .collect::<Vec<_>>()
                .join(",")
        ),
    }
}
