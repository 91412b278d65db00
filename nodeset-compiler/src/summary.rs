//! Human-readable summaries of a model: counts per namespace, and one type's instance declarations.

use crate::model::{Model, NodeIx};
use crate::raw::NodeClass;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Counts per namespace: nodes by class, types, instances.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NamespaceCounts {
    pub by_class: BTreeMap<NodeClass, usize>,
    pub types: usize,
    pub instances: usize,
}

impl NamespaceCounts {
    pub fn total(&self) -> usize {
        self.by_class.values().sum()
    }
}

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
    let _ = writeln!(s, "{} {} ({})", node.class.name(), model.qualified(t), crate::resolve::display_id(model, &node.id));
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
