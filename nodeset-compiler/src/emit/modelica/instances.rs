//! Instances: the objects and variables a nodeset puts into the address space (below the ObjectsFolder,
//! without a ModellingRule).
//!
//! Every top-level instance (one whose parent belongs to another namespace, such as the ObjectsFolder or DI's
//! DeviceSet) becomes a class `<Pkg>.Instances.<Name>` that extends the class of its type with the values
//! of the nodeset; children that fill a placeholder become named components. `<Pkg>.Instances.Objects`
//! holds one component per top-level instance and the DLR-style `OpcUaSupport.Nodes` record that lists every
//! variable of the instances with its NodeId, DataType and initial value.

use super::ctx::{identifier_text, node_id_text, node_id_type, Ctx, OBJECTS_FOLDER};
use super::plan::Owner;
use super::objects::escape_browse_name;
use super::plan::{ClassPlan, Mode, TypeRef};
use super::text::{self, string_literal};
use crate::model::{ids, Model, NodeIx};
use crate::raw::NodeClass;
use crate::value::{BuiltinType, Variant};
use std::collections::BTreeSet;

/// The BrowseNames from the ObjectsFolder to a node, '/'-separated.
pub fn path_from_objects(m: &Model, ix: NodeIx) -> String {
    let mut names = vec![escape_browse_name(&m.node(ix).browse_name.name)];
    let mut cur = m.node(ix).parent;
    let mut steps = 0;
    while let Some(p) = cur {
        if m.node(p).id.ns0() == Some(OBJECTS_FOLDER) || steps > 64 {
            break;
        }
        names.push(escape_browse_name(&m.node(p).browse_name.name));
        cur = m.node(p).parent;
        steps += 1;
    }
    names.reverse();
    names.join("/")
}

impl Ctx<'_> {
    /// Plans the class of a top-level instance object.
    pub fn plan_instance(&mut self, ix: NodeIx) {
        let m = self.m;
        let node = m.node(ix);
        let owner = Owner::Instance(ix);
        if self.plans.contains_key(&owner) {
            return;
        }
        let td = node
            .type_definition
            .filter(|&t| m.node(t).class == NodeClass::ObjectType && !self.is_event_type(t))
            .or_else(|| m.ns0(ids::BASE_OBJECT_TYPE))
            .expect("namespace 0 has BaseObjectType");
        self.plans.insert(owner, Default::default());
        let base = self.type_class(td);
        let own = self.own_children(ix, Mode::Instance);
        let mut body = self.plan_body(owner, "", base.as_ref(), &own, Mode::Instance, true);
        self.instance_classes.insert(ix, (body.elements.clone(), body.taken.clone()));
        let doc = format!(
            "{}<p>The instance {} of {} ({}).</p>",
            node.doc().map(text::html_paragraphs).unwrap_or_default(),
            text::html_escape(&path_from_objects(m, ix)),
            text::html_escape(&m.qualified(td)),
            text::html_escape(&node_id_text(m, &node.id))
        );
        let plan = ClassPlan {
            keyword: "model",
            desc: text::description(&node.browse_name.name, node.doc()),
            doc_html: doc,
            extends: base.as_ref().map(|b| (TypeRef::Class(b.key.clone()), std::mem::take(&mut body.mods))),
            items: std::mem::take(&mut body.items),
            equations: std::mem::take(&mut body.equations),
            opcua: format!(
                "__OPCUA(nodeId={}, browseName={}, browsePath={})",
                string_literal(&node_id_text(m, &node.id)),
                string_literal(&node.browse_name.name),
                string_literal(&path_from_objects(m, ix))
            ),
        };
        self.plans.entry(owner).or_default().main = Some(plan);
        self.name_decls(owner);
        self.run_deferred();
    }

    /// The `Instances.Objects` model of a namespace.
    pub fn objects_model(&mut self, ns: u16) -> String {
        let m = self.m;
        let names = self.names(ns);
        let pkg = self.pkg[ns as usize].clone();
        let mut s = format!(
            "model Objects {}\n",
            string_literal(&format!("The instances of {} below the ObjectsFolder", m.namespace_uri(ns)))
        );
        // The Nodes record: every variable below the top-level instances.
        let mut vars: Vec<NodeIx> = Vec::new();
        let mut seen = BTreeSet::new();
        for &top in &names.top_instances {
            collect_variables(m, top, &mut vars, &mut seen);
        }
        // The DLR OPC UA library creates Boolean, integer, Float, Double and String variables; the others are
        // listed in a comment.
        let (vars, unsupported): (Vec<NodeIx>, Vec<NodeIx>) = vars.into_iter().partition(|&v| dlr_creates(self.builtin_of(v)));
        let mut uris: Vec<u16> = vars.iter().map(|&v| m.node(v).id.ns).filter(|&n| n != 0).collect();
        uris.sort();
        uris.dedup();
        let ns_list: Vec<String> = uris.iter().map(|&n| string_literal(m.namespace_uri(n))).collect();
        let mut entries = Vec::new();
        for &v in &vars {
            entries.push(self.variable_node(v, &uris));
        }
        let sup = super::support::PACKAGE;
        // `{}` is no Modelica (an array constructor needs an element; rumoca accepts it, pymoca does not).
        let ns_uris = if ns_list.is_empty() { "fill(\"\", 0)".to_string() } else { format!("{{{}}}", ns_list.join(", ")) };
        s.push_str(&format!("  parameter {sup}.Nodes nodes = {sup}.Nodes(\n    nsUri={ns_uris}"));
        if !entries.is_empty() {
            s.push_str(&format!(
                ",\n    nVars={},\n    vars={{\n      {}}})",
                entries.len(),
                entries.join(",\n      ")
            ));
        } else {
            s.push(')');
        }
        s.push_str(&format!(
            "\n    {}\n    annotation (Dialog(group=\"Configuration\"));\n",
            string_literal(
                "The variables of the instances that the DLR OPC UA library can create, as the configuration record of its server and client blocks"
            )
        ));
        if !unsupported.is_empty() {
            s.push_str("  // Not in nodes: the DLR OPC UA library creates Boolean, integer, Float, Double and String variables only.\n");
            for &v in &unsupported {
                s.push_str(&format!(
                    "  //   {} ({})\n",
                    path_from_objects(m, v),
                    builtin_literal(self.builtin_of(v)).trim_end_matches('_')
                ));
            }
        }
        let mut scope = self.scope::<NodeIx>();
        scope.reserve("nodes");
        for &top in &names.top_instances {
            scope.add(&super::ctx::component_original(&m.node(top).browse_name.name), top);
        }
        let (idents, collisions) = scope.finish();
        self.report(&format!("{pkg}.Instances.Objects"), "components", collisions, |k| {
            (*k, Some(m.node(*k).browse_name.name.clone()))
        });
        for &top in &names.top_instances {
            let n = m.node(top);
            let ident = idents[&top].clone();
            let annotation = format!(
                "__OPCUA(browsePath={}, nodeId={})",
                string_literal(&path_from_objects(m, top)),
                string_literal(&node_id_text(m, &n.id))
            );
            let desc = text::description(&n.browse_name.name, n.doc());
            match n.class {
                NodeClass::Object => {
                    let class = format!("{pkg}.Instances.{}", names.instances[&top]);
                    s.push_str(&format!("  {class} {ident} {desc}\n    annotation ({annotation});\n"));
                }
                NodeClass::Variable => {
                    let ty = n.attrs.data_type.map(|d| self.mtype(d));
                    match ty {
                        Some(ty) if !matches!(ty, super::plan::MType::Unmapped(_)) => {
                            let dims = Self::dims(n.attrs.value_rank.unwrap_or(-1), &n.attrs.array_dimensions);
                            let value = self.value_of(top, &ty, dims.as_deref());
                            let writable = n.attrs.access_level.unwrap_or(1) & 0x02 != 0;
                            let dims_s = dims.as_deref().map(super::types::dims_text).unwrap_or_default();
                            let (prefix, tyname) = match &ty {
                                super::plan::MType::Scalar { base, .. } => (
                                    String::new(),
                                    format!("{sup}.{}{}", base.name(), if writable { "Output" } else { "Input" }),
                                ),
                                other => (
                                    (if writable { "output " } else { "input " }).to_string(),
                                    other.type_name().to_string(),
                                ),
                            };
                            s.push_str(&format!(
                                "  {prefix}{tyname} {ident}{dims_s} = {value} {desc}\n    annotation ({annotation});\n"
                            ));
                        }
                        Some(super::plan::MType::Unmapped(why)) => {
                            s.push_str(&format!("  // {} is left out: {why}.\n", n.browse_name.name));
                        }
                        _ => s.push_str(&format!("  // {} is left out: it has no DataType.\n", n.browse_name.name)),
                    }
                }
                _ => {}
            }
        }
        s.push_str(&format!(
            "  annotation (\n    {},\n    {});\nend Objects;\n",
            text::documentation(&format!(
                "<p>The instances of {} in the address space, one component per instance whose parent belongs to \
                 another namespace, and <code>nodes</code>, the variables of all of them with their NodeIds.</p>",
                text::html_escape(m.namespace_uri(ns))
            )),
            text::MODEL_ICON
        ));
        s
    }

    /// The built-in type a variable's value is encoded as.
    fn builtin_of(&self, v: NodeIx) -> BuiltinType {
        let m = self.m;
        m.node(v).attrs.data_type.and_then(|d| m.data_types.get(&d)).map(|i| i.encoding).unwrap_or(BuiltinType::Variant)
    }

    /// One `OpcUaSupport.VariableNode(...)` entry.
    fn variable_node(&mut self, v: NodeIx, uris: &[u16]) -> String {
        let m = self.m;
        let n = m.node(v);
        let ns_index =
            if n.id.ns == 0 { 0 } else { uris.iter().position(|&u| u == n.id.ns).map(|p| p + 1).unwrap_or(0) };
        let sup = super::support::PACKAGE;
        let dt = n.attrs.data_type;
        let builtin = self.builtin_of(v);
        let rank = n.attrs.value_rank.unwrap_or(-1);
        let dims = if rank >= 0 {
            if n.attrs.array_dimensions.is_empty() {
                vec!["0".to_string(); rank.max(1) as usize].join(",")
            } else {
                n.attrs.array_dimensions.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(",")
            }
        } else {
            String::new()
        };
        let init = match m.value(v) {
            Some(Ok(val)) => self.value_text(&val).unwrap_or_default(),
            _ => String::new(),
        };
        let mut args = vec![
            format!("nsIndex={ns_index}"),
            format!("nodeIdType={sup}.NodeIdType.{}", node_id_type(&n.id.id)),
            format!("id={}", string_literal(&identifier_text(&n.id.id))),
            format!("displayName={}", string_literal(n.display())),
        ];
        if let Some(d) = n.doc() {
            args.push(format!("description={}", string_literal(&text::one_line(d))));
        }
        args.push(format!("dataType={sup}.BuiltinType.{}", builtin_literal(builtin)));
        if let Some(d) = dt {
            args.push(format!("dataTypeId={}", string_literal(&node_id_text(m, &m.node(d).id))));
        }
        if !dims.is_empty() {
            args.push(format!("arrayDimensions={}", string_literal(&dims)));
        }
        if !init.is_empty() {
            args.push(format!("initValue={}", string_literal(&init)));
        }
        args.push(format!("browsePath={}", string_literal(&path_from_objects(m, v))));
        format!("{sup}.VariableNode({})", args.join(", "))
    }

    /// A value as the text of `VariableNode.initValue`: scalars as written, arrays as `{a, b}`; structures have
    /// no text form.
    pub(super) fn value_text(&self, v: &Variant) -> Option<String> {
        Some(match v {
            Variant::Boolean(b) => b.to_string(),
            Variant::SByte(x) => x.to_string(),
            Variant::Byte(x) => x.to_string(),
            Variant::Int16(x) => x.to_string(),
            Variant::UInt16(x) => x.to_string(),
            Variant::Int32(x) => x.to_string(),
            Variant::UInt32(x) => x.to_string(),
            Variant::Int64(x) => x.to_string(),
            Variant::UInt64(x) => x.to_string(),
            Variant::Float(x) => x.to_string(),
            Variant::Double(x) => x.to_string(),
            Variant::StatusCode(x) => x.to_string(),
            Variant::Variant(inner) => return self.value_text(inner),
            Variant::Array(_, items) => {
                let parts: Option<Vec<String>> = items.iter().map(|i| self.value_text(i)).collect();
                format!("{{{}}}", parts?.join(", "))
            }
            Variant::ExtensionObject(_) | Variant::ByteString(_) | Variant::XmlElement(_) | Variant::Null => {
                return None
            }
            other => self.string_value(other)?,
        })
    }
}

fn collect_variables(m: &Model, ix: NodeIx, out: &mut Vec<NodeIx>, seen: &mut BTreeSet<NodeIx>) {
    if !seen.insert(ix) || seen.len() > 200_000 {
        return;
    }
    if m.node(ix).class == NodeClass::Variable {
        out.push(ix);
    }
    let kids: Vec<NodeIx> = m.children(ix).map(|(_, c)| c).collect();
    for c in kids {
        // The arguments of a method are not variables a server block reads or writes; another namespace's
        // instances below this one are listed by that namespace.
        if m.node(c).modelling_rule.is_none() && m.node(c).class != NodeClass::Method && m.node(c).id.ns == m.node(ix).id.ns {
            collect_variables(m, c, out, seen);
        }
    }
}

/// Whether the DLR OPC UA library can create a variable of a built-in type (Modelica Boolean, Integer, Real and
/// String; Schönfeld et al., Modelica Conference 2021).
fn dlr_creates(b: BuiltinType) -> bool {
    use BuiltinType::*;
    matches!(b, Boolean | SByte | Byte | Int16 | UInt16 | Int32 | UInt32 | Int64 | UInt64 | Float | Double | String)
}

/// The `OpcUaSupport.BuiltinType` literal of a built-in type.
fn builtin_literal(b: BuiltinType) -> &'static str {
    match b {
        BuiltinType::ExtensionObject => "ExtensionObject",
        BuiltinType::Variant => "Variant",
        // Literals are not named like Modelica's predefined types.
        BuiltinType::Boolean => "Boolean_",
        BuiltinType::String => "String_",
        other => other.type_name(),
    }
}
