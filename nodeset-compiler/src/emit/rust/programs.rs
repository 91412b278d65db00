//! State machines and programs in `objects.rs`: data for the runtime's one implementation of their logic.
//!
//! - Every ObjectType with states or transitions (a `FiniteStateMachineType` or `ProgramStateMachineType`
//!   subtype) implements `StateMachine`: a static `StateTable` of its states (BrowseName, DisplayName,
//!   StateNumber, the state object's NodeId, whether it is the initial state), its transitions
//!   (BrowseName, DisplayName, TransitionNumber, NodeId, FromState and ToState as indices into the states,
//!   the BrowseNames of the HasCause methods), inherited ones included, and the event type a transition
//!   raises. A subtype whose machine is its supertype's names the supertype's table instead of repeating it.
//! - Every `ProgramStateMachineType` subtype implements `ProgramType`, and gets an inherent `serve` that runs
//!   a typed async body per Start. Its inputs and outputs are generated structs with one field per variable
//!   of the `InputParameterSet` and `OutputParameterSet` objects (the convention of our skill models),
//!   declared once by the type that declares the parameter set and named by the subtypes that inherit it.
//!   An output variable `Result` of DataType StatusCode is the run's outcome, which the runtime sets (Good
//!   in Ready, the cause in Halted), so it is not a field.
//!
//! The state logic (which method is allowed in which state, the CurrentState and LastTransition variables,
//! the events) lives once, in the runtime (`runtime::typed::program`).

use std::collections::BTreeMap;

use proc_macro2::{Literal, TokenStream};
use quote::{quote, ToTokens};

use super::{doc, ident, lit, Gen};
use crate::model::{ids, ModellingRule, NodeIx, StateMachineInfo};
use crate::names::{Case, Scope, Target};
use crate::raw::NodeClass;

/// The BrowseName of the object that holds a program's input variables.
pub const INPUT_SET: &str = "InputParameterSet";
/// The BrowseName of the object that holds a program's output variables.
pub const OUTPUT_SET: &str = "OutputParameterSet";
/// The BrowseName of the StatusCode output that is the outcome of a run.
pub const OUTCOME: &str = "Result";

/// The two parameter structs of a program type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Params {
    Inputs,
    Outputs,
}

impl Params {
    pub fn set_name(self) -> &'static str {
        match self {
            Params::Inputs => INPUT_SET,
            Params::Outputs => OUTPUT_SET,
        }
    }

    /// The suffix of the struct's name after the type's name.
    pub fn suffix(self) -> &'static str {
        match self {
            Params::Inputs => "Inputs",
            Params::Outputs => "Outputs",
        }
    }
}

/// Items of an `objects.rs` name scope: handle structs, and the parameter structs of program types.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Item {
    Handle,
    Params(Params),
}

impl Gen<'_> {
    /// Whether an ObjectType is ProgramStateMachineType or one of its subtypes.
    pub(super) fn is_program(&self, t: NodeIx) -> bool {
        self.model.node(t).class == NodeClass::ObjectType && self.model.is_subtype_of_ns0(t, ids::PROGRAM_STATE_MACHINE_TYPE)
    }

    /// The parameter-set object of a program type (own or inherited, the most derived declaration).
    fn parameter_set(&self, t: NodeIx, which: Params) -> Option<crate::model::Member> {
        let model = self.model;
        model.members.get(&t)?.iter().find(|m| {
            m.browse_name.name == which.set_name()
                && model.node(m.node).class == NodeClass::Object
                && self.rule(m.node) == Some(ModellingRule::Mandatory)
        }).cloned()
    }

    /// Whether generated code of this run can name a type's handle (and so the items declared with it).
    fn reachable(&self, t: NodeIx) -> bool {
        let n = self.model.node(t);
        if n.id.ns == self.ns {
            return true;
        }
        let uri = self.model.namespace_uri(n.id.ns);
        n.id.ns != 0 && (self.cfg.extern_paths.contains_key(uri) || self.cfg.namespaces.iter().any(|m| m.uri == uri))
    }

    /// The type that declares the parameter struct program type `t` uses: the type that declares the
    /// parameter-set object, if generated code reaches it; else `t` itself. `None` if `t` has no such set.
    fn params_owner(&self, t: NodeIx, which: Params) -> Option<NodeIx> {
        let member = self.parameter_set(t, which)?;
        let owner = member.declared_in;
        Some(if owner != t && self.model.node(owner).class == NodeClass::ObjectType && self.is_program(owner) && self.reachable(owner) {
            owner
        } else {
            t
        })
    }

    /// The variables of a program type's parameter set that become fields (placeholders are not; nor is the
    /// outcome of an output set), with their rules.
    fn parameter_vars(&self, t: NodeIx, which: Params) -> Vec<(NodeIx, ModellingRule)> {
        let Some(set) = self.parameter_set(t, which) else { return Vec::new() };
        self.decl_members(set.node)
            .into_iter()
            .filter_map(|(m, _)| {
                let rule = self.rule(m)?;
                (self.model.node(m).class == NodeClass::Variable && !rule.is_placeholder() && !(which == Params::Outputs && self.is_outcome(m)))
                    .then_some((m, rule))
            })
            .collect()
    }

    /// Whether an output variable is the outcome of a run: `Result`, a scalar StatusCode.
    fn is_outcome(&self, v: NodeIx) -> bool {
        let n = self.model.node(v);
        n.browse_name.name == OUTCOME
            && n.attrs.data_type.is_some_and(|dt| self.model.is_ns0(dt, 19))
            && n.attrs.value_rank.unwrap_or(-1) == -1
            && self.rule(v) == Some(ModellingRule::Mandatory)
    }

    /// The outcome variable of a program type's output set, if it has one.
    fn outcome(&self, t: NodeIx) -> Option<NodeIx> {
        let set = self.parameter_set(t, Params::Outputs)?;
        self.decl_members(set.node).into_iter().map(|(m, _)| m).find(|&m| self.is_outcome(m))
    }

    /// Adds the parameter struct names of a namespace's program types to its `objects.rs` scope. Every
    /// program type reserves both names, whether it declares the structs or not, so that the names never
    /// depend on which namespaces a run generates.
    pub(super) fn add_parameter_names(&self, ns: u16, scope: &mut Scope<(NodeIx, Item)>) {
        for (i, n) in self.model.nodes.iter().enumerate() {
            let t = NodeIx(i as u32);
            if n.id.ns == ns && self.is_program(t) {
                let base = n.symbolic_name.as_deref().unwrap_or(&n.browse_name.name);
                for which in [Params::Inputs, Params::Outputs] {
                    scope.add(&format!("{base}{}", which.suffix()), (t, Item::Params(which)));
                }
            }
        }
    }

    /// The Rust path of the parameter struct a program type uses (`()` if it has no parameter set).
    fn params_path(&self, t: NodeIx, which: Params) -> TokenStream {
        let Some(owner) = self.params_owner(t, which) else { return quote! { () } };
        let n = self.model.node(owner);
        let name = self.object_item_names(n.id.ns).get(&(owner, Item::Params(which))).cloned();
        let Some(name) = name else { return quote! { () } };
        let name = ident(&name);
        if n.id.ns == self.ns {
            return quote! { #name };
        }
        match self.module_path(n.id.ns) {
            Some(module) => quote! { #module::objects::#name },
            None => quote! { () },
        }
    }

    /// The parameter struct a program type declares, with its `Parameters` impl, if it declares one.
    fn params_struct(&self, t: NodeIx, which: Params, names: &BTreeMap<(NodeIx, Item), String>, uris: &mut BTreeMap<String, usize>) -> TokenStream {
        let model = self.model;
        if self.params_owner(t, which) != Some(t) {
            return quote! {};
        }
        let Some(set) = self.parameter_set(t, which) else { return quote! {} };
        let Some(name) = names.get(&(t, Item::Params(which))) else { return quote! {} };
        let vars = self.parameter_vars(t, which);
        let mut scope: Scope<NodeIx> = Scope::new(Target::Rust, Case::Snake);
        for &(v, _) in &vars {
            scope.add(&model.node(v).browse_name.name, v);
        }
        let (fnames, _) = scope.finish();
        let mut fields = Vec::new();
        let mut rows = Vec::new();
        for &(v, rule) in &vars {
            let n = model.node(v);
            let vt = self.value_type(n.attrs.data_type, n.attrs.value_rank.unwrap_or(-1));
            let ty = if rule == ModellingRule::Mandatory { vt.to_token_stream() } else { quote! { Option<#vt> } };
            let fname = ident(&fnames[&v]);
            let mut text = format!("`{}` ({}).", n.browse_name.name, rule.name());
            if let Some(d) = n.doc() {
                text.push(' ');
                text.push_str(d);
            }
            let d = doc(&text);
            fields.push(quote! { #d pub #fname: #ty });
            let k = Literal::usize_unsuffixed(self.ns_index(uris, n.browse_name.ns));
            let bname = lit(&n.browse_name.name);
            rows.push(quote! { #fname: #k #bname });
        }
        let tn = model.node(t);
        let (what, when) = match which {
            Params::Inputs => ("Inputs", "read from the instance when Start is called"),
            Params::Outputs => ("Outputs", "written to the instance when a run ends in Ready"),
        };
        let mut text = format!("{what} of the program `{}`: the variables of its `{}`, {when}.", tn.browse_name.name, which.set_name());
        if let Some(d) = model.node(set.node).doc() {
            text.push_str("\n\n");
            text.push_str(d);
        }
        let docs = doc(&text);
        let sname = ident(name);
        let k = Literal::usize_unsuffixed(self.ns_index(uris, set.browse_name.ns));
        let set_name = lit(which.set_name());
        let outcome = match (which, self.outcome(t)) {
            (Params::Outputs, Some(o)) => {
                let on = model.node(o);
                let ok = Literal::usize_unsuffixed(self.ns_index(uris, on.browse_name.ns));
                let oname = lit(&on.browse_name.name);
                quote! { outcome: #ok #oname; }
            }
            _ => quote! {},
        };
        quote! {
            #docs
            #[derive(Clone, Debug, PartialEq)]
            pub struct #sname { #(#fields),* }
            t::parameters!(#sname; set: #k #set_name; #outcome fields: [#(#rows),*]);
        }
    }

    /// The `StateMachine` impl of a type with states or transitions, and for a program its `ProgramType`
    /// impl and parameter structs.
    pub(super) fn state_machine_items(
        &mut self,
        t: NodeIx,
        name: &str,
        handles: &BTreeMap<NodeIx, String>,
        names: &BTreeMap<(NodeIx, Item), String>,
        uris: &mut BTreeMap<String, usize>,
    ) -> TokenStream {
        let model = self.model;
        let Some(info) = model.state_machines.get(&t) else { return quote! {} };
        let sname = ident(name);
        let table = match self.table_owner(t) {
            Some(base) => match self.handle_path(base, handles) {
                Some(p) => quote! { <#p as t::StateMachine>::TABLE },
                None => self.table_tokens(info, uris),
            },
            None => self.table_tokens(info, uris),
        };
        let n = model.node(t);
        let mut text = format!("The state machine of `{}`: ", n.browse_name.name);
        let states: Vec<String> = info
            .states
            .iter()
            .map(|s| match s.number {
                Some(k) => format!("{} ({k})", s.name),
                None => s.name.clone(),
            })
            .collect();
        text.push_str(&if states.is_empty() { "no states of its own".to_string() } else { format!("states {}", states.join(", ")) });
        text.push_str(&format!("; {} transitions.", info.transitions.len()));
        let docs = doc(&text);
        let mut out = quote! {
            #docs
            impl t::StateMachine for #sname {
                const TABLE: t::StateTable = #table;
                fn state_machine_node(&self) -> &t::ObjectNode {
                    &self.node
                }
            }
        };
        if self.is_program(t) {
            let inputs = self.params_path(t, Params::Inputs);
            let outputs = self.params_path(t, Params::Outputs);
            let in_struct = self.params_struct(t, Params::Inputs, names, uris);
            let out_struct = self.params_struct(t, Params::Outputs, names, uris);
            out.extend(quote! {
                t::program_type!(#sname, #inputs, #outputs);
                #in_struct
                #out_struct
            });
        }
        out
    }

    /// The nearest supertype whose machine is the same as `t`'s (same state and transition nodes, same
    /// event type) and whose handle generated code reaches, so `t` can name its table.
    fn table_owner(&self, t: NodeIx) -> Option<NodeIx> {
        let model = self.model;
        let info = model.state_machines.get(&t)?;
        let base = model.node(t).super_type?;
        let base_info = model.state_machines.get(&base)?;
        (same_machine(info, base_info) && self.reachable(base) && self.has_handle(base)).then_some(base)
    }

    fn table_tokens(&self, info: &StateMachineInfo, uris: &mut BTreeMap<String, usize>) -> TokenStream {
        let model = self.model;
        let index = |s: NodeIx| info.state_index(model, s);
        let opt = |n: Option<u32>| match n {
            Some(n) => {
                let n = Literal::u32_unsuffixed(n);
                quote! { Some(#n) }
            }
            None => quote! { None },
        };
        let states: Vec<TokenStream> = info
            .states
            .iter()
            .map(|s| {
                let n = model.node(s.node);
                let (name, display, number, node, initial) =
                    (lit(&s.name), lit(n.display()), opt(s.number), self.ns_node_id(uris, s.node), s.initial);
                quote! { t::StateRow { name: #name, display_name: #display, number: #number, node: #node, initial: #initial } }
            })
            .collect();
        let transitions: Vec<TokenStream> = info
            .transitions
            .iter()
            .filter_map(|tr| {
                let (from, to) = (index(tr.from?)?, index(tr.to?)?);
                let n = model.node(tr.node);
                let (name, display, number, node) = (lit(&tr.name), lit(n.display()), opt(tr.number), self.ns_node_id(uris, tr.node));
                let (from, to) = (Literal::usize_unsuffixed(from), Literal::usize_unsuffixed(to));
                let mut causes: Vec<(usize, String)> = tr
                    .causes
                    .iter()
                    .map(|&c| {
                        let b = &model.node(c).browse_name;
                        (self.ns_index(uris, b.ns), b.name.clone())
                    })
                    .collect();
                causes.sort();
                causes.dedup();
                let causes = causes.iter().map(|(k, c)| {
                    let (k, c) = (Literal::usize_unsuffixed(*k), lit(c));
                    quote! { (NS[#k], #c) }
                });
                Some(quote! {
                    t::TransitionRow { name: #name, display_name: #display, number: #number, node: #node, from: #from, to: #to, causes: &[#(#causes),*] }
                })
            })
            .collect();
        let event = match info.event_type {
            Some(e) => {
                let e = self.ns_node_id(uris, e);
                quote! { Some(#e) }
            }
            None => quote! { None },
        };
        quote! {
            t::StateTable { states: &[#(#states),*], transitions: &[#(#transitions),*], event_type: #event }
        }
    }
}

/// Whether two machines have the same states, transitions and event type.
fn same_machine(a: &StateMachineInfo, b: &StateMachineInfo) -> bool {
    a.states.iter().map(|s| s.node).eq(b.states.iter().map(|s| s.node))
        && a.transitions.iter().map(|s| s.node).eq(b.transitions.iter().map(|s| s.node))
        && a.event_type == b.event_type
}
