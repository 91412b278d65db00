//! State machines: an Integer state with the nodeset's state numbers, one Boolean trigger input per cause
//! (the methods Start, Suspend, ... of a program, or the transition itself when the nodeset names no cause),
//! and one `when` equation that moves between the states along the transitions of the nodeset.
//!
//! ```modelica
//!   extends OpcUa.ObjectTypes.FiniteStateMachineType(final currentState=currentStateText);
//!   parameter Integer stateMachineLevel = 1 "Which class drives the state machine";
//!   constant Integer Ready = 2 "Ready (StateNumber 2)";
//!   String currentStateText "The DisplayName of the current state, which currentState shows";
//!   discrete Integer currentStateNumber(start=Ready, fixed=true) "Number of the current state";
//!   OpcUaSupport.BooleanInput start = false "Start: a rising edge stands for a call of the method Start";
//! equation
//!   if stateMachineLevel == 1 then
//!     when start then
//!       currentStateNumber = if pre(currentStateNumber) == Ready then Running else pre(currentStateNumber);
//!     elsewhen ...
//!     end when;
//!     currentStateText = if currentStateNumber == Ready then "Ready" elseif ... else "";
//!   end if;
//! ```
//!
//! A subtype that adds states or transitions keeps the constants and triggers it inherits, declares the new
//! ones, sets `stateMachineLevel` to its own level and writes the `when` equation of the whole machine under
//! `if stateMachineLevel == <its level>`, which switches the inherited equation off. Triggers are checked in
//! the order of the `elsewhen` branches, so of two triggers that rise at the same instant the first wins.
//!
//! The text follows the number. `CurrentState` (bound to `""` in StateMachineType) gets a `final` binding
//! to `currentStateText`, which the equation of the driving level sets; so no subclass, instance or user
//! modifier can give the text a value of its own. A CurrentState value in the nodeset (an instance's
//! `Ready`, its `Id` or `Number` property) names the state the machine starts in instead: it becomes
//! `currentStateNumber(start=12)` (a literal, as the modifier may sit where the constants are not visible),
//! or nothing when that is the initial state already.
//!
//! The initial state is, in this order: the state whose TypeDefinition is InitialStateType; the state the
//! type's own CurrentState declaration names; the initial state of the machine a subtype extends; Ready for
//! ProgramStateMachineType and its subtypes, which mark none (OPC 10000-10, 5.2.3.2: Halted is the idle
//! state of a Program that cannot begin yet, and a Program ready upon its creation moves on to Ready at once;
//! a simulated Program waits for nothing, and the skill instances of our nodesets say Ready); else the first
//! state in the nodeset's order. The description of `currentStateNumber` says which rule applied.

use super::ctx::{component_original, Ctx};
use super::plan::{Body, ClassInfo, ElemKind, Item, Mod, SmInfo, TypeRef};
use super::text::string_literal;
use super::plan::{Base, MType};
use crate::model::{ids, Model, NodeIx};
use crate::nodeid::QualifiedName;
use crate::value::Variant;
use std::collections::BTreeSet;
use std::rc::Rc;

#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
enum Key {
    State(usize),
    Var,
    Level,
    Text,
    Trigger(usize),
}

/// Where the initial state of a machine comes from, in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum InitialFrom {
    /// A state whose TypeDefinition is InitialStateType.
    Marked,
    /// The value the type gives its CurrentState (its Id, Number or text).
    Declared,
    /// The initial state of the machine this one extends.
    Inherited,
    /// ProgramStateMachineType marks no initial state; Part 10 (5.2.3.2) lets a Program that is ready upon
    /// creation start in Ready, and a simulated Program has nothing to wait for.
    ProgramReady,
    /// Nothing says: the first state in the nodeset.
    First,
}

/// The state of `states` that the value of a CurrentState variable names: its Id property (a state node, or
/// one with the same BrowseName), else its Number property, else its text (DisplayName or BrowseName).
pub fn state_in_value(m: &Model, current: NodeIx, states: &[(NodeIx, String)], numbers: &[u32]) -> Option<usize> {
    let child = |name: &str| {
        m.children(current).map(|(_, c)| c).find(|&c| m.node(c).browse_name.ns == 0 && m.node(c).browse_name.name == name)
    };
    let value = |c: NodeIx| m.value(c).and_then(Result::ok);
    if let Some(Variant::NodeId(id) | Variant::ExpandedNodeId(id)) = child("Id").and_then(value) {
        if let Some(ix) = m.lookup(&id) {
            let found = states.iter().position(|(s, _)| *s == ix).or_else(|| {
                states.iter().position(|(s, _)| m.node(*s).browse_name == m.node(ix).browse_name)
            });
            if found.is_some() {
                return found;
            }
        }
    }
    if let Some(n) = child("Number").and_then(value).and_then(|v| v.as_i64()) {
        if let Some(i) = numbers.iter().position(|&x| i64::from(x) == n) {
            return Some(i);
        }
    }
    let text = match value(current)? {
        Variant::LocalizedText(t) => t.text,
        Variant::String(t) => t,
        _ => return None,
    };
    let text = text.trim();
    states
        .iter()
        .position(|(s, _)| m.node(*s).display() == text)
        .or_else(|| states.iter().position(|(s, _)| m.node(*s).browse_name.name == text))
}

impl Ctx<'_> {
    /// Adds the machinery of a state machine type to its class body.
    pub fn plan_state_machine(&mut self, t: NodeIx, base: Option<&Rc<ClassInfo>>, body: &mut Body) -> Option<SmInfo> {
        let m = self.m;
        let info = m.state_machines.get(&t)?.clone();
        if info.states.is_empty() {
            return None;
        }
        // States and transitions are the same when their BrowseNames are: a subtype may declare an inherited
        // state again (to add a sub-state machine, for instance) without changing the machine.
        let nodes: BTreeSet<QualifiedName> = info
            .states
            .iter()
            .map(|s| s.node)
            .chain(info.transitions.iter().map(|x| x.node))
            .map(|n| m.node(n).browse_name.clone())
            .collect();
        let inherited = base.and_then(|b| b.state_machine.clone());
        if inherited.as_ref().is_some_and(|b| b.nodes == nodes) {
            return None;
        }
        let level = inherited.as_ref().map(|b| b.level + 1).unwrap_or(1);

        // State numbers: the nodeset's, or the next free numbers for states without one.
        let mut numbers: Vec<u32> = Vec::new();
        let mut next = info.states.iter().filter_map(|s| s.number).max().unwrap_or(0) + 1;
        let mut numbered_here = BTreeSet::new();
        for (i, s) in info.states.iter().enumerate() {
            match s.number {
                Some(n) => numbers.push(n),
                None => {
                    numbers.push(next);
                    numbered_here.insert(i);
                    next += 1;
                }
            }
        }
        // Triggers: for each transition its cause methods, else the transition itself.
        let mut trig_nodes: Vec<NodeIx> = Vec::new();
        let mut transition_trigs: Vec<Vec<usize>> = Vec::new();
        let same_method = |a: NodeIx, b: NodeIx| a == b || m.node(a).browse_name == m.node(b).browse_name;
        for tr in &info.transitions {
            let causes: Vec<NodeIx> = if tr.causes.is_empty() { vec![tr.node] } else { tr.causes.clone() };
            let mut mine = Vec::new();
            for c in causes {
                let i = match trig_nodes.iter().position(|&x| same_method(x, c)) {
                    Some(i) => i,
                    None => {
                        trig_nodes.push(c);
                        trig_nodes.len() - 1
                    }
                };
                if !mine.contains(&i) {
                    mine.push(i);
                }
            }
            transition_trigs.push(mine);
        }
        // Names: inherited ones are reused; a method keeps the name its element has; the rest are new.
        let inherited_state = |n: NodeIx| {
            inherited.as_ref().and_then(|b| {
                b.states.iter().find(|(s, _)| m.node(*s).browse_name == m.node(n).browse_name).map(|(_, i)| i.clone())
            })
        };
        let inherited_trig = |n: NodeIx| {
            inherited.as_ref().and_then(|b| b.triggers.iter().find(|(s, _)| same_method(*s, n)).map(|(_, i)| i.clone()))
        };
        let method_element = |n: NodeIx| {
            body.elements
                .iter()
                .find(|e| matches!(e.kind, ElemKind::Method) && (e.node == n || e.bn == m.node(n).browse_name))
                .map(|e| e.ident.clone())
        };
        // CurrentState shows the DisplayName of the current state.
        let current = body
            .elements
            .iter()
            .find(|e| e.bn.ns == 0 && e.bn.name == "CurrentState" && e.use_flag.is_none())
            .filter(|e| {
                matches!(&e.kind, ElemKind::Signal { ty: MType::Scalar { base: Base::String, .. }, dims: None, .. })
            })
            .map(|e| (e.ident.clone(), e.node));
        let mut scope = self.scope::<Key>();
        for n in &body.taken {
            scope.reserve(n);
        }
        for (i, s) in info.states.iter().enumerate() {
            if inherited_state(s.node).is_none() {
                scope.add(&s.name, Key::State(i));
            }
        }
        if inherited.is_none() {
            scope.add(&component_original("CurrentStateNumber"), Key::Var);
            scope.add(&component_original("StateMachineLevel"), Key::Level);
            if current.is_some() {
                scope.add(&component_original("CurrentStateText"), Key::Text);
            }
        }
        let mut fixed_trig: Vec<Option<String>> = Vec::new();
        for (i, &n) in trig_nodes.iter().enumerate() {
            let known = inherited_trig(n).or_else(|| method_element(n));
            if known.is_none() {
                scope.add(&component_original(&m.node(n).browse_name.name), Key::Trigger(i));
            }
            fixed_trig.push(known);
        }
        let (names, collisions) = scope.finish();
        self.report(&format!("state machine {}", m.qualified(t)), "states and triggers", collisions, |_| (t, None));
        for n in names.values() {
            body.taken.insert(n.clone());
        }
        let states: Vec<String> = info
            .states
            .iter()
            .enumerate()
            .map(|(i, s)| inherited_state(s.node).unwrap_or_else(|| names[&Key::State(i)].clone()))
            .collect();
        let triggers: Vec<String> = (0..trig_nodes.len())
            .map(|i| fixed_trig[i].clone().unwrap_or_else(|| names[&Key::Trigger(i)].clone()))
            .collect();
        let (var, level_param) = match &inherited {
            Some(b) => (b.var.clone(), b.level_param.clone()),
            None => (names[&Key::Var].clone(), names[&Key::Level].clone()),
        };
        let text = match &inherited {
            Some(b) => b.text.clone(),
            None => current.as_ref().map(|(cur, _)| (cur.clone(), names[&Key::Text].clone())),
        };
        let pairs: Vec<(NodeIx, String)> = info.states.iter().map(|s| s.node).zip(states.iter().cloned()).collect();
        let (initial, from) = self.initial_state(t, &info.states, &pairs, &numbers, current.map(|c| c.1), inherited.as_deref());
        let declared_triggers: BTreeSet<String> =
            inherited.iter().flat_map(|b| b.triggers.iter().map(|(_, i)| i.clone())).collect();
        let declared_states: BTreeSet<String> =
            inherited.iter().flat_map(|b| b.states.iter().map(|(_, i)| i.clone())).collect();

        body.adds = true;
        body.items.push(Item::Comment(match &inherited {
            None => format!(
                "State machine of {}: its states, and transitions driven by the trigger inputs.",
                m.node(t).browse_name.name
            ),
            Some(_) => format!(
                "{} adds states or transitions to the inherited state machine and drives it from here.",
                m.node(t).browse_name.name
            ),
        }));
        if inherited.is_none() {
            body.items.push(Item::Decl {
                prefix: "parameter".into(),
                ty: TypeRef::Path("Integer".into()),
                ident: level_param.clone(),
                dims: String::new(),
                mods: Vec::new(),
                value: Some(level.to_string().into()),
                cond: None,
                desc: string_literal(
                    "Which class drives the state machine: a subclass that adds states sets its own level",
                ),
                annotation: "Evaluate=true".into(),
            });
        } else {
            body.mods.push(Mod::Value {
                ident: level_param.clone(),
                is_final: false,
                attrs: Vec::new(),
                value: Some(level.to_string().into()),
            });
        }
        for (i, s) in info.states.iter().enumerate() {
            if declared_states.contains(&states[i]) {
                continue;
            }
            let mut d = if numbered_here.contains(&i) {
                format!("{} (the nodeset gives no StateNumber; numbered here)", s.name)
            } else {
                format!("{} (StateNumber {})", s.name, numbers[i])
            };
            if s.initial {
                d.push_str(", the initial state");
            }
            body.items.push(Item::Decl {
                prefix: "constant".into(),
                ty: TypeRef::Path("Integer".into()),
                ident: states[i].clone(),
                dims: String::new(),
                mods: Vec::new(),
                value: Some(numbers[i].to_string().into()),
                cond: None,
                desc: string_literal(&d),
                annotation: self.opcua_annotation(s.node),
            });
        }
        let start_in = &info.states[initial].name;
        let desc = match from {
            InitialFrom::Marked => "Number of the current state (CurrentState/Number)".to_string(),
            InitialFrom::Declared => format!(
                "Number of the current state (CurrentState/Number); it starts in {start_in}, the state the nodeset gives CurrentState"
            ),
            InitialFrom::Inherited => format!("Number of the current state (CurrentState/Number); it starts in {start_in}"),
            InitialFrom::ProgramReady => format!(
                "Number of the current state (CurrentState/Number); the nodeset marks no initial state, and a Program ready upon creation starts in {start_in} (OPC 10000-10, 5.2.3.2)"
            ),
            InitialFrom::First => format!(
                "Number of the current state (CurrentState/Number); the nodeset marks no initial state, so it starts in {start_in}, the first state"
            ),
        };
        // The state a CurrentState of this type names was already applied by the planner; write it once.
        body.mods.retain(|x| !matches!(x, Mod::Value { ident, .. } if *ident == var));
        if inherited.as_ref().is_some_and(|b| b.states[b.initial].1 != states[initial]) {
            body.mods.push(Mod::Value {
                ident: var.clone(),
                is_final: false,
                attrs: vec![format!("start={}", states[initial])],
                value: None,
            });
        }
        if let (None, Some((cur, text_var))) = (&inherited, &text) {
            // The text follows the number: a final binding to a variable that the equation of the driving level
            // sets, so neither an instance nor a user can give the text a value of its own.
            body.mods.retain(|x| !matches!(x, Mod::Value { ident, .. } if ident == cur));
            for e in body.elements.iter_mut().filter(|e| e.ident == *cur) {
                if let ElemKind::Signal { free, .. } = &mut e.kind {
                    *free = false;
                }
            }
            body.mods.push(Mod::Value {
                ident: cur.clone(),
                is_final: true,
                attrs: Vec::new(),
                value: Some(text_var.clone().into()),
            });
            body.items.push(Item::Decl {
                prefix: String::new(),
                ty: TypeRef::Path("String".into()),
                ident: text_var.clone(),
                dims: String::new(),
                mods: Vec::new(),
                value: None,
                cond: None,
                desc: string_literal(&format!(
                    "The DisplayName of the current state, which {cur} shows: set from {var} by the equation of the class that drives the state machine"
                )),
                annotation: String::new(),
            });
        }
        if inherited.is_none() {
            body.items.push(Item::Decl {
                prefix: "discrete".into(),
                ty: TypeRef::Path("Integer".into()),
                ident: var.clone(),
                dims: String::new(),
                mods: vec![
                    Mod::Value {
                        ident: "start".into(),
                        is_final: false,
                        attrs: Vec::new(),
                        value: Some(states[initial].clone().into()),
                    },
                    Mod::Value {
                        ident: "fixed".into(),
                        is_final: false,
                        attrs: Vec::new(),
                        value: Some("true".into()),
                    },
                ],
                value: None,
                cond: None,
                desc: string_literal(&desc),
                annotation: String::new(),
            });
        }
        for (i, &n) in trig_nodes.iter().enumerate() {
            if declared_triggers.contains(&triggers[i]) {
                continue;
            }
            let name = &m.node(n).browse_name.name;
            let d = if m.node(n).class == crate::raw::NodeClass::Method {
                format!("{name}: a rising edge stands for a call of the method {name}")
            } else {
                format!("{name}: a rising edge takes this transition, for which the nodeset gives no cause")
            };
            body.items.push(Item::Decl {
                prefix: String::new(),
                ty: TypeRef::Path(format!("{}.BooleanInput", super::support::PACKAGE)),
                ident: triggers[i].clone(),
                dims: String::new(),
                mods: Vec::new(),
                value: Some("false".into()),
                cond: None,
                desc: string_literal(&d),
                annotation: format!("{}, {}", body.placed.next(true), self.opcua_annotation(n)),
            });
        }
        // One branch per trigger, in the order triggers first appear.
        let state_index = |node: Option<NodeIx>| node.and_then(|n| info.states.iter().position(|s| s.node == n));
        let mut branches: Vec<(usize, Vec<(usize, usize)>)> = Vec::new();
        for (ti, tr) in info.transitions.iter().enumerate() {
            let (Some(from), Some(to)) = (state_index(tr.from), state_index(tr.to)) else {
                body.items.push(Item::Comment(format!(
                    "Transition {} is left out: it does not lead from one state of this machine to another.",
                    tr.name
                )));
                continue;
            };
            for &g in &transition_trigs[ti] {
                match branches.iter_mut().find(|(x, _)| *x == g) {
                    Some((_, list)) => match list.iter().find(|(f, _)| *f == from) {
                        Some(&(_, first_to)) => {
                            let msg = format!(
                                "{} leads from {} both to {} and, through {}, to {}; the first transition is taken",
                                m.node(trig_nodes[g]).browse_name.name,
                                info.states[from].name,
                                info.states[first_to].name,
                                tr.name,
                                info.states[to].name
                            );
                            body.items.push(Item::Comment(format!("{msg}.")));
                            self.lossy(tr.node, format!("in state machine `{}`, {msg}", m.qualified(t)));
                        }
                        None => list.push((from, to)),
                    },
                    None => branches.push((g, vec![(from, to)])),
                }
            }
        }
        let mut eq = format!("if {level_param} == {level} then\n");
        if branches.is_empty() {
            eq.push_str(&format!("  {var} = pre({var});\n"));
        } else {
            for (k, (g, moves)) in branches.iter().enumerate() {
                let kw = if k == 0 { "when" } else { "elsewhen" };
                eq.push_str(&format!("  {kw} {} then\n", triggers[*g]));
                let mut expr = String::new();
                for (j, (from, to)) in moves.iter().enumerate() {
                    let kw = if j == 0 { "if" } else { " elseif" };
                    expr.push_str(&format!("{kw} pre({var}) == {} then {}", states[*from], states[*to]));
                }
                expr.push_str(&format!(" else pre({var})"));
                eq.push_str(&format!("    {var} = {expr};\n"));
            }
            eq.push_str("  end when;\n");
        }
        if let Some((_, text_var)) = &text {
            let mut expr = String::new();
            for (i, s) in info.states.iter().enumerate() {
                let kw = if i == 0 { "if" } else { " elseif" };
                expr.push_str(&format!(
                    "{kw} {var} == {} then {}",
                    states[i],
                    string_literal(m.node(s.node).display())
                ));
            }
            expr.push_str(" else \"\"");
            eq.push_str(&format!("  {text_var} = {expr};\n"));
        }
        eq.push_str("end if;");
        body.equations.push(eq);
        Some(SmInfo {
            level,
            level_param,
            var,
            states: pairs,
            numbers,
            initial,
            text,
            triggers: trig_nodes.iter().enumerate().map(|(i, &n)| (n, triggers[i].clone())).collect(),
            nodes,
        })
    }

    /// Applies the state that CurrentState child `current` names (an instance's value, or a type's) to the
    /// inherited machine `sm`: a `start` modifier on the state number when it is not the state the machine
    /// starts in already. The number is written as a literal, because the modifier may sit in an enclosing
    /// class where the state constants are not visible.
    pub fn start_state(&self, sm: &SmInfo, current: NodeIx, body: &mut Body) {
        let Some(i) = state_in_value(self.m, current, &sm.states, &sm.numbers) else { return };
        if i != sm.initial {
            body.mods.push(Mod::Value {
                ident: sm.var.clone(),
                is_final: false,
                attrs: vec![format!("start={}", sm.numbers[i])],
                value: None,
            });
            body.initial = Some(i);
        }
    }

    /// The state a machine starts in, and where that comes from (see [`InitialFrom`]).
    fn initial_state(
        &self,
        t: NodeIx,
        states: &[crate::model::State],
        pairs: &[(NodeIx, String)],
        numbers: &[u32],
        current: Option<NodeIx>,
        inherited: Option<&SmInfo>,
    ) -> (usize, InitialFrom) {
        let m = self.m;
        if let Some(i) = states.iter().position(|s| s.initial) {
            return (i, InitialFrom::Marked);
        }
        if let Some(i) = current.and_then(|c| state_in_value(m, c, pairs, numbers)) {
            return (i, InitialFrom::Declared);
        }
        let same = |a: NodeIx| states.iter().position(|s| m.node(s.node).browse_name == m.node(a).browse_name);
        if let Some(i) = inherited.and_then(|b| same(b.states[b.initial].0)) {
            return (i, InitialFrom::Inherited);
        }
        let program = m.ns0(ids::PROGRAM_STATE_MACHINE_TYPE).is_some_and(|p| m.is_subtype_of(t, p));
        let ready = states.iter().position(|s| {
            let bn = &m.node(s.node).browse_name;
            bn.ns == 0 && bn.name == "Ready"
        });
        match ready.filter(|_| program) {
            Some(i) => (i, InitialFrom::ProgramReady),
            None => (0, InitialFrom::First),
        }
    }
}
