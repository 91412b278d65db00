//! The state of one generation run: package names, the name tables of every namespace, what the ns0 subset
//! needs, and the diagnostics found on the way.

use super::plan::{ClassInfo, ClassKey, Deferred, Owner, OwnerPlan, RecordInfo};
use crate::diag::{Code, Diagnostic, Diagnostics, Severity};
use crate::model::{ids, Model, NodeIx};
use crate::names::{sanitize, Case, Collision, Scope, Target};
use crate::nodeid::{Identifier, NodeId};
use crate::raw::NodeClass;
use std::collections::{BTreeMap, BTreeSet};
use std::rc::Rc;

/// The NodeId of the ObjectsFolder.
pub const OBJECTS_FOLDER: u32 = 85;

/// The Server object: what hangs below it (NamespaceMetadata, diagnostics) describes the server, not the
/// plant, and is not an instance of the information model.
const SERVER: u32 = 2253;

/// Whether a node hangs below the ObjectsFolder through instances only (no type, no instance declaration, not
/// below the Server object).
fn below_objects(m: &Model, ix: NodeIx) -> bool {
    let mut cur = m.node(ix).parent;
    let mut steps = 0;
    while let Some(p) = cur {
        let n = m.node(p);
        if n.id.ns0() == Some(OBJECTS_FOLDER) {
            return true;
        }
        if n.id.ns0() == Some(SERVER) {
            return false;
        }
        if n.class.is_type() || n.modelling_rule.is_some() {
            return false;
        }
        steps += 1;
        if steps > 64 {
            return false;
        }
        cur = n.parent;
    }
    false
}

/// The entry points of a namespace's instances: objects and variables of the namespace below the
/// ObjectsFolder whose parent belongs to another namespace (or is the ObjectsFolder), in node order.
pub fn top_level(m: &Model, ns: u16) -> Vec<NodeIx> {
    (0..m.nodes.len() as u32)
        .map(NodeIx)
        .filter(|&ix| {
            let n = m.node(ix);
            n.id.ns == ns
                && matches!(n.class, NodeClass::Object | NodeClass::Variable)
                && n.modelling_rule.is_none()
                && n.parent.is_some_and(|p| m.node(p).id.ns != ns)
                && below_objects(m, ix)
        })
        .collect()
}

/// The class of an owner's declaration in `Declarations`: `<Owner>_<Path>`, unique in the namespace (neither
/// part contains a `_` the other could complete), and never the name of the class alias it is redeclared
/// for (rumoca ignores `redeclare model X = P.X`). Long results are capped like every identifier
/// (`names` rule 7), as the class is also a file name.
pub fn decl_class_ident(owner_ident: &str, decl: &str) -> String {
    crate::names::cap_len(format!("{owner_ident}_{decl}"), Case::Preserve)
}

/// The deepest nesting of instance declarations or instance children represented in Modelica, one nested
/// class per level. Companion specifications nest fewer than twenty; a model nested deeper (thousands of
/// levels overflowed the stack) is cut here with an NS0302 warning.
pub const MAX_NESTING: usize = 64;

/// Something of the ns0 subset that generated code refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Need {
    DataType(NodeIx),
    ObjectType(NodeIx),
}

/// The identifiers of one namespace's packages.
#[derive(Debug, Default)]
pub struct NsNames {
    pub types: BTreeMap<NodeIx, String>,
    pub object_types: BTreeMap<NodeIx, String>,
    pub owners: BTreeMap<Owner, String>,
    pub instances: BTreeMap<NodeIx, String>,
    /// Top-level instances (entry points into the namespace's instance tree), in node order.
    pub top_instances: Vec<NodeIx>,
}

pub struct Ctx<'a> {
    pub m: &'a Model,
    /// Package name per namespace index.
    pub pkg: Vec<String>,
    /// Namespaces emitted completely.
    pub full: BTreeSet<u16>,
    /// The base namespace, when only the part other packages need is emitted.
    pub subset: Option<u16>,
    names: BTreeMap<u16, Rc<NsNames>>,
    pub needs: BTreeSet<Need>,
    pub diags: Diagnostics,
    pub class_infos: BTreeMap<ClassKey, Rc<ClassInfo>>,
    pub plans: BTreeMap<Owner, OwnerPlan>,
    pub decl_names: BTreeMap<(Owner, String), String>,
    pub records: BTreeMap<NodeIx, Rc<RecordInfo>>,
    /// Identifiers no scope may use: the top-level package names, so that a qualified name always starts at a
    /// package.
    pub reserved: Vec<String>,
    /// Guards against runaway recursion through malformed type graphs.
    pub depth: usize,
    /// How many class bodies are being planned inside each other (see [`MAX_NESTING`]).
    pub nesting: usize,
    pub deferred: Vec<Deferred>,
    /// The replaceable class aliases that some planned class redeclares (filled once planning is done). A
    /// component repeats its class's choice for each of them ([`Mod::Pin`](super::plan::Mod::Pin)).
    pub redeclared: BTreeSet<String>,
    /// The instance declarations that would make a class contain itself; they become reference parameters
    /// (see `recursion.rs`).
    pub cuts: BTreeSet<NodeIx>,
    /// The elements and taken identifiers of each top-level instance's class, for its binding model (see
    /// `bindings.rs`).
    pub instance_classes: BTreeMap<NodeIx, (Vec<super::plan::Element>, BTreeSet<String>)>,
}

impl<'a> Ctx<'a> {
    pub fn new(m: &'a Model, pkg: Vec<String>, full: BTreeSet<u16>, subset: Option<u16>) -> Ctx<'a> {
        let mut reserved: Vec<String> = pkg.clone();
        reserved.push(super::support::PACKAGE.to_string());
        reserved.sort();
        reserved.dedup();
        Ctx {
            m,
            pkg,
            full,
            subset,
            names: BTreeMap::new(),
            needs: BTreeSet::new(),
            diags: Diagnostics::new(),
            class_infos: BTreeMap::new(),
            plans: BTreeMap::new(),
            decl_names: BTreeMap::new(),
            records: BTreeMap::new(),
            reserved,
            depth: 0,
            nesting: 0,
            deferred: Vec::new(),
            redeclared: BTreeSet::new(),
            cuts: super::recursion::containment_cuts(m),
            instance_classes: BTreeMap::new(),
        }
    }

    /// A scope for Modelica identifiers with the package names reserved.
    pub fn scope<K: Ord + Clone>(&self) -> Scope<K> {
        let mut s = Scope::new(Target::Modelica, Case::Preserve);
        for r in &self.reserved {
            s.reserve(r);
        }
        s
    }

    /// The name tables of a namespace, built on first use over every node of the namespace (so names do not
    /// depend on which part of it is emitted).
    pub fn names(&mut self, ns: u16) -> Rc<NsNames> {
        if let Some(n) = self.names.get(&ns) {
            return n.clone();
        }
        let m = self.m;
        let mut types: Scope<NodeIx> = self.scope();
        let mut object_types: Scope<NodeIx> = self.scope();
        let mut owners: Scope<Owner> = self.scope();
        let mut instances: Scope<NodeIx> = self.scope();
        instances.reserve("Objects");
        let top = top_level(m, ns);
        for (i, n) in m.nodes.iter().enumerate() {
            if n.id.ns != ns {
                continue;
            }
            let ix = NodeIx(i as u32);
            match n.class {
                NodeClass::DataType => types.add(&n.browse_name.name, ix),
                NodeClass::ObjectType => {
                    object_types.add(&n.browse_name.name, ix);
                    owners.add(&n.browse_name.name, Owner::Type(ix));
                }
                _ => {}
            }
        }
        for &ix in &top {
            let name = &m.node(ix).browse_name.name;
            instances.add(name, ix);
            owners.add(name, Owner::Instance(ix));
        }
        let (types, c1) = types.finish();
        let (object_types, c2) = object_types.finish();
        let (owners, c3) = owners.finish();
        let (instances, c4) = instances.finish();
        let what = format!("package {}", self.pkg[ns as usize]);
        self.report(&what, "Types", c1, |k| (*k, None));
        self.report(&what, "ObjectTypes", c2, |k| (*k, None));
        self.report(&what, "Declarations", c3, |k| (k.node(), None));
        self.report(&what, "Instances", c4, |k| (*k, None));
        let names = Rc::new(NsNames { types, object_types, owners, instances, top_instances: top });
        self.names.insert(ns, names.clone());
        names
    }

    /// Reports the collisions of a scope: two originals that map to one identifier were told apart by
    /// `_2`, `_3`, ... in the sorted order of the originals.
    /// `origin` gives the node of a key and, where the scope's original was derived from it (a component
    /// name in lower case), the name as the nodeset writes it.
    pub fn report<K>(
        &mut self,
        class: &str,
        scope: &str,
        collisions: Vec<Collision<K>>,
        origin: impl Fn(&K) -> (NodeIx, Option<String>),
    ) {
        let node = |k: &K| origin(k).0;
        for c in collisions {
            let m = self.m;
            let list: Vec<String> = c
                .members
                .iter()
                .map(|(orig, k)| {
                    let (ix, shown) = origin(k);
                    format!("`{}` ({})", shown.unwrap_or_else(|| orig.clone()), node_id_text(m, &m.node(ix).id))
                })
                .collect();
            let reserved = c.members.len() == 1;
            let msg = if reserved {
                format!(
                    "in {class} ({scope}), {} maps to the identifier `{}`, which the generator uses itself; it is renamed `{}_2`",
                    list[0], c.ident, c.ident
                )
            } else {
                format!(
                    "in {class} ({scope}), {} all map to the Modelica identifier `{}`; they are told apart by `_2`, `_3`, ... in the sorted order of the originals",
                    list.join(", "),
                    c.ident
                )
            };
            let first = node(&c.members[0].1);
            let mut d = Diagnostic::new(Code::NameCollision, msg)
                .at(m.node(first).browse_name_span)
                .note("the original BrowseName stays in the description string and the __OPCUA annotation");
            d.severity = Severity::Warning;
            self.diags.push(d);
        }
    }

    /// A warning about something of the model that has no faithful Modelica form and is left out or mapped
    /// with a loss; the generated code says the same in a comment.
    pub fn lossy(&mut self, node: NodeIx, message: String) {
        let d = Diagnostic::new(Code::UnsupportedFeature, message).at(self.m.node(node).span);
        self.diags.push(d);
    }

    fn need(&mut self, ns: u16, need: Need) {
        if self.subset == Some(ns) && !self.full.contains(&ns) {
            self.needs.insert(need);
        }
    }

    /// The qualified Modelica name of a DataType's class, recording that the ns0 subset needs it.
    pub fn datatype_path(&mut self, dt: NodeIx) -> String {
        let ns = self.m.node(dt).id.ns;
        self.need(ns, Need::DataType(dt));
        let names = self.names(ns);
        format!("{}.Types.{}", self.pkg[ns as usize], names.types[&dt])
    }

    /// The qualified Modelica name of a class.
    pub fn class_path(&mut self, key: &ClassKey) -> String {
        match key {
            ClassKey::Type(t) => {
                let ns = self.m.node(*t).id.ns;
                self.need(ns, Need::ObjectType(*t));
                let names = self.names(ns);
                format!("{}.ObjectTypes.{}", self.pkg[ns as usize], names.object_types[t])
            }
            ClassKey::Decl(owner, path) => {
                let ns = self.m.node(owner.node()).id.ns;
                if let Owner::Type(t) = owner {
                    self.need(ns, Need::ObjectType(*t));
                }
                let names = self.names(ns);
                // Every declaration class is named when its owner is planned; the fallback only guards
                // against a type graph too deep to plan.
                let decl = self.decl_names.get(&(*owner, path.clone())).cloned().unwrap_or_else(|| class_ident(path));
                format!("{}.Declarations.{}", self.pkg[ns as usize], decl_class_ident(&names.owners[owner], &decl))
            }
        }
    }

    pub fn is_event_type(&self, t: NodeIx) -> bool {
        self.m.is_subtype_of_ns0(t, ids::BASE_EVENT_TYPE)
    }
}

/// Documentation for the class of a node the information model gives no Description: what it stands for,
/// so that no generated class is undocumented.
pub fn undescribed(m: &Model, node: NodeIx, what: &str) -> String {
    let n = m.node(node);
    let sup = n
        .super_type
        .map(|s| format!(", a subtype of <code>{}</code>", super::text::html_escape(&m.qualified(s))))
        .unwrap_or_default();
    format!(
        "<p>The {what} <code>{}</code> ({}){sup}. The information model gives it no description.</p>",
        super::text::html_escape(&m.qualified(node)),
        super::text::html_escape(&node_id_text(m, &n.id))
    )
}

/// A NodeId in its standard text form with the namespace URI (`nsu=...;i=5`), or `i=5` in namespace 0.
pub fn node_id_text(m: &Model, id: &NodeId) -> String {
    if id.ns == 0 {
        id.id.to_string()
    } else {
        format!("nsu={};{}", m.namespace_uri(id.ns), id.id)
    }
}

/// The Modelica `NodeIdType` literal of an identifier.
pub fn node_id_type(id: &Identifier) -> &'static str {
    match id {
        Identifier::Numeric(_) => "Numeric",
        Identifier::String(_) => "String_",
        Identifier::Guid(_) => "Guid",
        Identifier::Opaque(_) => "Opaque",
    }
}

/// The identifier part of a NodeId as text (without the `i=` prefix).
pub fn identifier_text(id: &Identifier) -> String {
    let s = id.to_string();
    s[2..].to_string()
}

/// The original of a component name: the BrowseName with its first word in lower case (`ActualPosition` ->
/// `actualPosition`, `IOs` -> `ios`, `HTTPServer` -> `httpServer`), as Modelica libraries name instances. The
/// result goes through the one sanitizer of [`crate::names`] like every other name.
pub fn component_original(browse_name: &str) -> String {
    let words = crate::names::words(browse_name);
    let Some(first) = words.first() else { return browse_name.to_string() };
    if first.chars().next().is_some_and(|c| c.is_ascii_digit()) {
        return browse_name.to_string();
    }
    let Some(at) = browse_name.find(first.as_str()) else { return browse_name.to_string() };
    // The leading run of capitals goes to lower case: `Actual` -> `actual`, `IOs` -> `ios`, `HTTP` -> `http`.
    let run = first.chars().take_while(|c| c.is_ascii_uppercase()).count();
    let lowered = format!("{}{}", first[..run].to_ascii_lowercase(), &first[run..]);
    format!("{}{}{}", &browse_name[..at], lowered, &browse_name[at + first.len()..])
}

/// A class name's counterpart for generated parameters: `nAxisIdentifier` for the placeholder component
/// `axisIdentifier`.
pub fn count_name(ident: &str) -> String {
    let mut cs = ident.chars();
    match cs.next() {
        Some(f) => format!("n{}{}", f.to_ascii_uppercase(), cs.as_str()),
        None => "n".into(),
    }
}

/// Sanitizes a single name that is not part of a scope (package names given by the user are checked, not
/// changed).
pub fn class_ident(original: &str) -> String {
    sanitize(original, Case::Preserve, Target::Modelica)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn component_names_start_in_lower_case() {
        let cases = [
            ("ActualPosition", "actualPosition"),
            ("IOs", "ios"),
            ("HTTPServer", "httpServer"),
            ("Model", "model"),
            ("<AxisIdentifier>", "<axisIdentifier>"),
            ("UR Robot", "ur Robot"),
            ("3DFrame", "3DFrame"),
            ("x_", "x_"),
            ("Größe", "größe"),
        ];
        for (orig, want) in cases {
            assert_eq!(component_original(orig), want, "{orig}");
        }
        // After the sanitizer, reserved words are renamed.
        assert_eq!(sanitize(&component_original("Model"), Case::Preserve, Target::Modelica), "model_");
        assert_eq!(sanitize(&component_original("Input"), Case::Preserve, Target::Modelica), "input_");
        assert_eq!(sanitize(&component_original("Real"), Case::Preserve, Target::Modelica), "real");
        assert_eq!(count_name("axisIdentifier"), "nAxisIdentifier");
    }
}
