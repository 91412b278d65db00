//! `serve --instantiate-all`: one instance of every concrete ObjectType of the named files, below
//! `Objects/Instances`, each named by its type's BrowseName in the type's namespace (so two namespaces'
//! `ControllerType`s do not collide), made by the runtime's `instantiate` (the one generated servers use):
//! mandatory members of the fully-inherited hierarchy, one element (`<Name>` gives `Name1`, see
//! [`element_name`]) in each MandatoryPlaceholder, values from the nodeset or else the DataType's default,
//! and every state machine among them served from its initial state, by a state table built from the model.
//!
//! What to name for the placeholders, and which members are Mandatory, is read from the model
//! ([`mandatory_paths`]), which computes the hierarchy once (`resolve/inherit.rs`); the runtime follows the
//! same links in the tables, and for ns0, which async-opcua serves without them, the model's links are given
//! to it ([`ModelManager::add_overrides`]). Where the served ns0 (async-opcua's, 1.05.04) and the ns0 the
//! files were resolved against differ in a ModellingRule (ConditionType's `ConditionSubClassId`, Mandatory
//! in 1.05.03), the model's rule is the one followed: every member the model holds Mandatory is created,
//! which an Optional member of the served type also allows. A type the
//! runtime refuses (a MandatoryPlaceholder the model does not see, a type that contains itself) is reported
//! with the reason, and the others are still created.

use crate::model::{Member, Model, ModellingRule, NodeIx, StateMachineInfo};
use crate::nodeid::Identifier;
use crate::raw::NodeClass;
use nodeset_runtime::server::ModelManager;
use nodeset_runtime::typed::{Instantiate, Machine, ObjectNode, StateRow, StateTable, TransitionRow};
use nodeset_runtime::{IdKind, NsNodeId};
use opcua::types::{BrowseDirection, NodeId, ObjectId, ObjectTypeId, QualifiedName, ReferenceTypeId};
use std::collections::{BTreeMap, BTreeSet};

/// How deep instance declarations may nest before a type is taken for one that contains itself (the
/// runtime's own limit is 32).
const MAX_DEPTH: usize = 32;

/// What [`instantiate_all`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Instantiated {
    /// The concrete ObjectTypes of the named files.
    pub types: usize,
    /// How many of them were instantiated.
    pub instantiated: usize,
    /// The nodes created below `Objects/Instances` (the folder included).
    pub nodes: usize,
    /// The state machines among them served from their initial state.
    pub machines: usize,
    /// The state machines among them whose type marks no initial state (an InitialStateType): not served,
    /// their CurrentState left empty rather than guessed.
    pub without_initial_state: usize,
    /// Each type or state machine that could not be made, with the reason.
    pub failures: Vec<(String, String)>,
}

/// The element a MandatoryPlaceholder gets: its name without the angle brackets and the smallest number
/// from 1 that gives a name no other member of the same node has (`<AxisIdentifier>` gives
/// `AxisIdentifier1`). `taken` holds the names of the other members and of the elements named before.
pub fn element_name(placeholder: &str, taken: &BTreeSet<String>) -> String {
    let base = placeholder.trim_start_matches('<').trim_end_matches('>');
    (1..).map(|k| format!("{base}{k}")).find(|n| !taken.contains(n)).expect("a free number")
}

/// Every mandatory path of an instance of `t` in the model's fully-inherited hierarchy, as the runtime
/// names the nodes it creates (`ParameterSet/SpeedOverride`; the one element of each MandatoryPlaceholder;
/// a method with its argument properties), and each MandatoryPlaceholder's path (`Axes/<AxisIdentifier>`,
/// as `Instantiate::placeholder` names it) with the name of its element ([`element_name`]: the placeholders
/// of one node are named in the order of their BrowseNames, so Powertrain's `<PwmSwitchingFrequency>` gets
/// `PwmSwitchingFrequency1` and the MandatoryPlaceholder `PwmSwitchingFrequency` beside it
/// `PwmSwitchingFrequency2`, whatever the order of the file). `Err` names the path where the hierarchy nests
/// deeper than an instance can.
pub fn mandatory_paths(m: &Model, t: NodeIx) -> Result<(BTreeSet<String>, Vec<(String, String)>), String> {
    type Out = (BTreeSet<String>, Vec<(String, String)>);
    fn walk(m: &Model, members: Vec<Member>, prefix: &str, depth: usize, out: &mut Out) -> Result<(), String> {
        if depth >= MAX_DEPTH {
            return Err(format!("instance declarations nest deeper than {MAX_DEPTH} levels at `{prefix}` (a type that contains itself)"));
        }
        let is_placeholder = |x: &Member| m.node(x.node).modelling_rule == Some(ModellingRule::MandatoryPlaceholder);
        let mut taken: BTreeSet<String> = members.iter().filter(|x| !is_placeholder(x)).map(|x| x.browse_name.name.clone()).collect();
        let mut placeholders: Vec<&Member> = members.iter().filter(|x| is_placeholder(x)).collect();
        placeholders.sort_by(|a, b| (&a.browse_name.name, a.browse_name.ns).cmp(&(&b.browse_name.name, b.browse_name.ns)));
        let mut elements: BTreeMap<NodeIx, String> = BTreeMap::new();
        for x in placeholders {
            let e = element_name(&x.browse_name.name, &taken);
            taken.insert(e.clone());
            elements.insert(x.node, e);
        }
        for x in &members {
            let n = m.node(x.node);
            let name = &x.browse_name.name;
            let path = match n.modelling_rule {
                Some(ModellingRule::Mandatory) => format!("{prefix}{name}"),
                Some(ModellingRule::MandatoryPlaceholder) => {
                    let e = &elements[&x.node];
                    out.1.push((format!("{prefix}{name}"), e.clone()));
                    format!("{prefix}{e}")
                }
                _ => continue,
            };
            out.0.insert(path.clone());
            if n.class == NodeClass::Method {
                for (_, c) in m.children(x.node) {
                    out.0.insert(format!("{path}/{}", m.node(c).browse_name.name));
                }
            } else {
                walk(m, m.instance_members(x.node), &format!("{path}/"), depth + 1, out)?;
            }
        }
        Ok(())
    }
    let mut out = (BTreeSet::new(), Vec::new());
    let root: Vec<Member> = m.members.get(&t).into_iter().flatten().filter(|x| m.node(x.node).modelling_rule.is_some()).cloned().collect();
    walk(m, root, "", 0, &mut out)?;
    Ok(out)
}

/// The concrete ObjectTypes the named files define, sorted by namespace URI, then BrowseName, then NodeId.
pub fn concrete_object_types(m: &Model) -> Vec<NodeIx> {
    let named: BTreeSet<u16> = m.models.iter().filter(|x| m.sources.get(x.file).named).map(|x| x.ns).collect();
    let mut out: Vec<NodeIx> = (0..m.nodes.len() as u32)
        .map(NodeIx)
        .filter(|&ix| {
            let n = m.node(ix);
            n.class == NodeClass::ObjectType && !n.is_abstract() && named.contains(&n.id.ns)
        })
        .collect();
    out.sort_by_cached_key(|&ix| {
        let n = m.node(ix);
        (m.namespace_uri(n.id.ns).to_owned(), n.browse_name.name.clone(), m.display_id(&n.id))
    });
    out
}

/// The server's NodeId of a model node.
pub fn server_id(manager: &ModelManager, m: &Model, ix: NodeIx) -> Option<NodeId> {
    let id = &m.node(ix).id;
    let ns = manager.namespace_index(m.namespace_uri(id.ns))?;
    Some(match &id.id {
        Identifier::Numeric(n) => NodeId::new(ns, *n),
        Identifier::String(s) => NodeId::new(ns, s.to_string()),
        Identifier::Guid(g) => NodeId::new(ns, opcua::types::Guid::from_bytes(*g)),
        Identifier::Opaque(b) => NodeId::new(ns, opcua::types::ByteString::from(b.to_vec())),
    })
}

/// Creates `Objects/Instances` and one instance of every concrete ObjectType of the named files in it; serves
/// the state machines among the new nodes. Never fails as a whole: each type that cannot be instantiated is
/// listed in [`Instantiated::failures`].
pub fn instantiate_all(manager: &ModelManager, m: &Model) -> Instantiated {
    let mut done = Instantiated::default();
    let types = concrete_object_types(m);
    done.types = types.len();
    let objects: NodeId = ObjectId::ObjectsFolder.into();
    let folder_id = NodeId::new(manager.instance_namespace(), "Instances");
    let folder = manager.instantiate(
        &ObjectTypeId::FolderType.into(),
        &objects,
        QualifiedName::new(manager.instance_namespace(), "Instances"),
        &Instantiate::new().node_id(folder_id.clone()),
    );
    if let Err(e) = folder {
        done.failures.push(("the folder Objects/Instances".into(), e.to_string()));
        return done;
    }
    done.nodes += 1;
    manager.add_overrides(ns0_overrides(manager, m));
    let machines = StateTables::new(manager, m);
    // Two types of one namespace may share a BrowseName (AML's libraries): their instances are told apart
    // by the type's NodeId.
    let mut names: BTreeMap<(u16, &str), usize> = BTreeMap::new();
    for &t in &types {
        let n = m.node(t);
        *names.entry((n.id.ns, n.browse_name.name.as_str())).or_default() += 1;
    }
    for t in types {
        let n = m.node(t);
        let name = match names[&(n.id.ns, n.browse_name.name.as_str())] {
            1 => n.browse_name.name.clone(),
            _ => format!("{} ({})", n.browse_name.name, m.display_id(&n.id)),
        };
        let what = format!("{} ({})", m.qualified(t), m.display_id(&m.node(t).id));
        match instantiate_one(manager, m, t, &name, &folder_id) {
            Ok(root) => {
                done.instantiated += 1;
                let created = subtree(manager, &root);
                done.nodes += created.len();
                for (node, type_id) in created {
                    let Some(table) = machines.table(&type_id) else { continue };
                    let Some(table) = table else {
                        done.without_initial_state += 1;
                        continue;
                    };
                    let served = manager.bind::<ObjectNode>(&node).map_err(|e| e.to_string()).and_then(|instance| {
                        Machine::serve_by_table(table, &instance).map_err(|e| e.to_string())
                    });
                    match served {
                        Ok(_) => done.machines += 1,
                        Err(e) => done.failures.push((format!("the state machine {node} of {what}"), e)),
                    }
                }
            }
            Err(e) => done.failures.push((what, e)),
        }
    }
    done
}

/// The model's links of ns0's InstanceDeclarations (each to the declaration it overrides at its browse
/// path, `Model::overridden`), as server NodeIds. The node tables carry these links for the namespaces they
/// serve; ns0 is async-opcua's, served without them, so `instantiate` gets them from here, and merges an ns0
/// subtype's declaration with what it overrides as the model does (PubSubDiagnosticsDataSetReaderType's
/// `Counters` keeps `StateError` and the other counters of PubSubDiagnosticsType's).
fn ns0_overrides(manager: &ModelManager, m: &Model) -> Vec<(NodeId, NodeId)> {
    m.overridden
        .iter()
        .filter(|(&decl, _)| m.node(decl).id.ns == 0)
        .filter_map(|(&decl, &over)| Some((server_id(manager, m, decl)?, server_id(manager, m, over)?)))
        .collect()
}

fn instantiate_one(manager: &ModelManager, m: &Model, t: NodeIx, name: &str, folder: &NodeId) -> Result<NodeId, String> {
    let type_id = server_id(manager, m, t).ok_or("its namespace is not served")?;
    let (mandatory, placeholders) = mandatory_paths(m, t)?;
    // Every member the model holds Mandatory is created, also where the server's own type marks it Optional:
    // ns0 is async-opcua's (1.05.04), and the files were written against another ns0 (1.05.03 in the
    // UA-Nodeset tree, where ConditionType's ConditionSubClassId is still Mandatory). The rule is the
    // model's, computed once; an Optional member created is no fault of the served type's either.
    let options = mandatory.iter().fold(Instantiate::new().data_type_defaults(), |o, p| o.ensure(p.clone()));
    let options = placeholders.iter().fold(options, |o, (p, element)| o.placeholder(p.clone(), [element.clone()]));
    let ns = type_id.namespace;
    let id = NodeId::new(manager.instance_namespace(), format!("Instances/{ns}:{name}"));
    manager
        .instantiate(&type_id, folder, QualifiedName::new(ns, name), &options.node_id(id))
        .map_err(|e| e.to_string())
}

/// Every node below `root` (itself included) by forward hierarchical references inside the instance's
/// namespace, with its TypeDefinition (null for methods and nodes without one).
fn subtree(manager: &ModelManager, root: &NodeId) -> Vec<(NodeId, NodeId)> {
    let tree = manager.type_tree().read();
    let space = manager.node_manager().address_space().read();
    let type_of = |n: &NodeId| {
        space
            .find_references(n, Some((ReferenceTypeId::HasTypeDefinition, false)), &*tree, BrowseDirection::Forward)
            .next()
            .map(|r| r.target_node.clone())
            .unwrap_or_else(NodeId::null)
    };
    let mut out = vec![(root.clone(), type_of(root))];
    let mut seen: BTreeSet<String> = BTreeSet::from([root.to_string()]);
    let mut stack = vec![root.clone()];
    while let Some(node) = stack.pop() {
        let children: Vec<NodeId> = space
            .find_references(&node, Some((ReferenceTypeId::HierarchicalReferences, true)), &*tree, BrowseDirection::Forward)
            .filter(|r| r.target_node.namespace == root.namespace)
            .map(|r| r.target_node.clone())
            .collect();
        for c in children {
            if seen.insert(c.to_string()) {
                out.push((c.clone(), type_of(&c)));
                stack.push(c);
            }
        }
    }
    out
}

/// The state tables of the model's state machine types, built on first use and leaked (a server holds
/// them as long as it runs, like generated ones), by the type's NodeId on the server.
struct StateTables<'a> {
    model: &'a Model,
    by_server_id: BTreeMap<String, NodeIx>,
    built: std::cell::RefCell<BTreeMap<NodeIx, Option<&'static StateTable>>>,
}

impl<'a> StateTables<'a> {
    fn new(manager: &ModelManager, model: &'a Model) -> StateTables<'a> {
        let by_server_id = model
            .state_machines
            .iter()
            .filter(|(_, info)| !info.states.is_empty())
            .filter_map(|(&t, _)| Some((server_id(manager, model, t)?.to_string(), t)))
            .collect();
        StateTables { model, by_server_id, built: Default::default() }
    }

    /// For a state machine type with states (`type_id` a server NodeId), its table, or `None` if it marks
    /// no initial state; `None` for other types.
    fn table(&self, type_id: &NodeId) -> Option<Option<&'static StateTable>> {
        let &t = self.by_server_id.get(&type_id.to_string())?;
        Some(*self.built.borrow_mut().entry(t).or_insert_with(|| state_table(self.model, &self.model.state_machines[&t])))
    }
}

fn leak_str(s: &str) -> &'static str {
    Box::leak(s.to_owned().into_boxed_str())
}

fn ns_node_id(m: &Model, ix: NodeIx) -> NsNodeId {
    let id = &m.node(ix).id;
    let kind = match &id.id {
        Identifier::Numeric(n) => IdKind::Numeric(*n),
        Identifier::String(s) => IdKind::String(leak_str(s)),
        Identifier::Guid(g) => IdKind::Guid(*g),
        Identifier::Opaque(b) => IdKind::Opaque(Box::leak(b.clone())),
    };
    NsNodeId { namespace_uri: leak_str(m.namespace_uri(id.ns)), id: kind }
}

/// The runtime's state table of a state machine type, as the generated `StateMachine::TABLE` would hold
/// it; `None` if it has no initial state to start in.
fn state_table(m: &Model, info: &StateMachineInfo) -> Option<&'static StateTable> {
    if !info.states.iter().any(|s| s.initial) {
        return None;
    }
    let states: Vec<StateRow> = info
        .states
        .iter()
        .map(|s| StateRow {
            name: leak_str(&s.name),
            display_name: leak_str(m.node(s.node).display()),
            number: s.number,
            node: ns_node_id(m, s.node),
            initial: s.initial,
        })
        .collect();
    let transitions: Vec<TransitionRow> = info
        .transitions
        .iter()
        .filter_map(|tr| {
            let (from, to) = (info.state_index(m, tr.from?)?, info.state_index(m, tr.to?)?);
            let mut causes: Vec<(&'static str, &'static str)> = tr
                .causes
                .iter()
                .map(|&c| {
                    let b = &m.node(c).browse_name;
                    (m.namespace_uri(b.ns), b.name.as_str())
                })
                .collect::<BTreeSet<_>>()
                .into_iter()
                .map(|(u, n)| (leak_str(u), leak_str(n)))
                .collect();
            causes.sort();
            Some(TransitionRow {
                name: leak_str(&tr.name),
                display_name: leak_str(m.node(tr.node).display()),
                number: tr.number,
                node: ns_node_id(m, tr.node),
                from,
                to,
                causes: Box::leak(causes.into_boxed_slice()),
            })
        })
        .collect();
    Some(Box::leak(Box::new(StateTable {
        states: Box::leak(states.into_boxed_slice()),
        transitions: Box::leak(transitions.into_boxed_slice()),
        event_type: info.event_type.map(|e| ns_node_id(m, e)),
    })))
}
