//! Which members are references rather than contained components, and where containment has to be cut so
//! that no class contains itself.
//!
//! A child becomes a component (a contained copy) only when its parent holds it by containment: HasChild and
//! its subtypes (HasComponent, HasProperty, HasOrderedComponent, HasAddIn, ...) or Organizes. Every other
//! reference, hierarchical or not (Requires, Moves, HasSlave, Controls, IsDrivenBy, HasNotifier, ...), points
//! at an object that lives elsewhere, and becomes a `String` parameter naming its target (see
//! `objects.rs`).
//!
//! Containment can still close a cycle: DI's FunctionalGroupType organizes `<GroupIdentifier>` groups of its
//! own type, FileDirectoryType organizes `<FileDirectoryName>` directories. Modelica rejects a class that
//! contains itself, so such a member is cut the same way: it becomes a reference parameter. The cuts are
//! found on a graph of ObjectTypes, before any class is planned: an edge from a type to its supertype
//! (`extends`), and from a type to the TypeDefinition of every object it contains, at any depth of its
//! instance declarations (their classes are declaration classes of that type). Cycles are found by a
//! depth-first search over the types in NodeId order; in each cycle found, the containment edge that closes
//! it (the last one on the path) is cut, and the search repeats until no cycle is left.

use crate::model::{ids, Model, NodeIx};
use crate::raw::NodeClass;
use std::collections::{BTreeMap, BTreeSet};

/// Whether a reference type holds its target as a part: a subtype of HasChild or Organizes.
pub fn is_containment(m: &Model, rt: NodeIx) -> bool {
    [ids::HAS_CHILD, ids::ORGANIZES].into_iter().any(|id| m.ns0(id).is_some_and(|x| m.is_subtype_of(rt, x)))
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Edge {
    to: NodeIx,
    /// The instance declaration that contains an object of type `to`; `None` for `extends`.
    via: Option<NodeIx>,
}

/// The instance declarations whose containment would make a class contain itself; each becomes a reference
/// parameter instead.
pub fn containment_cuts(m: &Model) -> BTreeSet<NodeIx> {
    let object_type = |t: NodeIx| m.node(t).class == NodeClass::ObjectType;
    let mut graph: BTreeMap<NodeIx, Vec<Edge>> = BTreeMap::new();
    for (&t, members) in &m.members {
        if !object_type(t) {
            continue;
        }
        let mut edges = Vec::new();
        if let Some(s) = m.node(t).super_type.filter(|&s| object_type(s)) {
            edges.push(Edge { to: s, via: None });
        }
        let mut stack: Vec<NodeIx> = members
            .iter()
            .filter(|x| x.declared_in == t && is_containment(m, x.reference_type))
            .map(|x| x.node)
            .collect();
        let mut seen = BTreeSet::new();
        while let Some(d) = stack.pop() {
            let n = m.node(d);
            if n.class != NodeClass::Object || n.modelling_rule.is_none() || !seen.insert(d) || seen.len() > 100_000 {
                continue;
            }
            if let Some(td) = n.type_definition.filter(|&x| object_type(x)) {
                edges.push(Edge { to: td, via: Some(d) });
            }
            stack.extend(m.children(d).filter(|&(rt, _)| is_containment(m, rt)).map(|(_, c)| c));
        }
        edges.sort();
        edges.dedup();
        graph.insert(t, edges);
    }
    let mut cuts = BTreeSet::new();
    while let Some(via) = first_cycle(&graph, &cuts) {
        cuts.insert(via);
    }
    cuts
}

/// The containment edge that closes the first cycle a depth-first search meets, skipping cut edges.
fn first_cycle(graph: &BTreeMap<NodeIx, Vec<Edge>>, cuts: &BTreeSet<NodeIx>) -> Option<NodeIx> {
    #[derive(Clone, Copy, PartialEq)]
    enum Mark {
        Open,
        Done,
    }
    let mut marks: BTreeMap<NodeIx, Mark> = BTreeMap::new();
    for &root in graph.keys() {
        if marks.contains_key(&root) {
            continue;
        }
        // The path: (node, index of the next edge, the edge that led here).
        let mut path: Vec<(NodeIx, usize, Option<Edge>)> = vec![(root, 0, None)];
        marks.insert(root, Mark::Open);
        while let Some(&(node, i, _)) = path.last() {
            let edges = graph.get(&node).map(Vec::as_slice).unwrap_or(&[]);
            let Some(&e) = edges.get(i) else {
                marks.insert(node, Mark::Done);
                path.pop();
                continue;
            };
            path.last_mut().expect("the path is not empty").1 += 1;
            if e.via.is_some_and(|v| cuts.contains(&v)) {
                continue;
            }
            match marks.get(&e.to) {
                Some(Mark::Done) => {}
                Some(Mark::Open) => {
                    // A cycle: from e.to along the path back to node, then e. Cut its last containment edge.
                    let start = path.iter().position(|p| p.0 == e.to).expect("an open node is on the path");
                    let cycle = path[start + 1..].iter().filter_map(|p| p.2).chain(std::iter::once(e));
                    if let Some(via) = cycle.filter_map(|x| x.via).next_back() {
                        return Some(via);
                    }
                    // Only `extends` edges: a supertype cycle, which the resolver reports; nothing to cut.
                }
                None => {
                    marks.insert(e.to, Mark::Open);
                    path.push((e.to, 0, Some(e)));
                }
            }
        }
    }
    None
}
