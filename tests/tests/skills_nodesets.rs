//! Our skill nodesets (`nodesets/CommonSkills`, `RobotCell`, `DrillingProcess`) on the pinned ns0, DI, IA and
//! Robotics: they resolve without a single diagnostic, the skills are programs with the methods they
//! promise, the UR10e controller offers the three move skills, every instance carries every Mandatory
//! instance declaration of its type, python asyncua's XML importer loads them without a warning, and they
//! are valid against UANodeSet.xsd.

use std::path::PathBuf;
use std::process::Command;

use nodeset_compiler::load::Input;
use nodeset_compiler::model::{Model, ModellingRule, NodeIx};
use nodeset_compiler::raw::NodeClass;
use nodeset_compiler::{compile, Compiled, Options};
use nodeset_tests::{root, vendor};

const FILES: [&str; 3] = ["CommonSkills.NodeSet2.xml", "RobotCell.NodeSet2.xml", "DrillingProcess.NodeSet2.xml"];
const CS: &str = "http://nodeset-compiler.dev/CommonSkills/";
const RC: &str = "http://nodeset-compiler.dev/RobotCell/";
const DP: &str = "http://nodeset-compiler.dev/DrillingProcess/";

// ns0 nodes the checks name.
const PROGRAM_STATE_MACHINE_TYPE: u32 = 2391;
const HAS_INTERFACE: u32 = 17603;
const THREE_D_FRAME: u32 = 18814;

/// The three files, named; ns0, DI, IA and Robotics found in the vendor folder by their ModelUri.
fn skills() -> Compiled {
    let dir = root().join("nodesets");
    let inputs = FILES.iter().map(|f| Input::Path(dir.join(f))).collect();
    compile(inputs, &Options { model_dirs: vec![vendor()], ..Options::default() })
}

fn ours(m: &Model, ix: NodeIx) -> bool {
    [CS, RC, DP].contains(&m.namespace_uri(m.node(ix).id.ns))
}

fn find(m: &Model, uri: &str, name: &str) -> NodeIx {
    let hits = m.find(&format!("{uri}#{name}"));
    assert_eq!(hits.len(), 1, "{uri}#{name}: {hits:?}");
    hits[0]
}

/// The child of `parent` (a node, not a type's member list) with this BrowseName.
fn child(m: &Model, parent: NodeIx, name: &str) -> NodeIx {
    m.children(parent)
        .map(|(_, c)| c)
        .find(|&c| m.node(c).browse_name.name == name)
        .unwrap_or_else(|| panic!("{} has no child {name}", m.node(parent).browse_name.name))
}

fn path(m: &Model, from: NodeIx, names: &[&str]) -> NodeIx {
    names.iter().fold(from, |n, name| child(m, n, name))
}

#[test]
fn skill_nodesets_resolve_without_a_diagnostic() {
    let out = skills();
    assert!(out.diagnostics.items.is_empty(), "{}", out.render_diagnostics());
    let m = &out.model;
    for (uri, version) in [(CS, "1.0.0"), (RC, "1.0.0"), (DP, "1.0.0")] {
        let info = m.models.iter().find(|x| x.uri == uri).unwrap_or_else(|| panic!("{uri} is not loaded"));
        assert_eq!(info.version.as_deref(), Some(version), "{uri}");
        // Every RequiredModel names its version and publication date.
        for r in &info.required {
            assert!(
                r.version.is_some() && r.publication_date.is_some(),
                "{uri} requires {} without a version or date",
                r.uri
            );
        }
    }
    // Every node of ours has a DisplayName and a Description.
    for ix in (0..m.nodes.len() as u32).map(NodeIx).filter(|&ix| ours(m, ix)) {
        let n = m.node(ix);
        assert!(!n.display_name.is_empty(), "{} has no DisplayName", m.qualified(ix));
        assert!(n.description.iter().any(|d| !d.text.trim().is_empty()), "{} has no Description", m.qualified(ix));
    }
}

#[test]
fn skills_are_programs_with_the_methods_they_promise() {
    let out = skills();
    let m = &out.model;
    let psm = m.ns0(PROGRAM_STATE_MACHINE_TYPE).unwrap();
    let pssm = find(m, CS, "ProgramSkillStateMachineType");
    let composite = find(m, CS, "CompositeSkillType");
    let drill_hole = find(m, DP, "DrillHoleSkillType");
    assert!(m.is_subtype_of(drill_hole, psm), "DrillHoleSkillType is a ProgramStateMachineType");
    assert_eq!(
        m.super_chain(drill_hole).iter().map(|&t| m.qualified(t)).collect::<Vec<_>>()[..4],
        [
            "DrillingProcess:DrillHoleSkillType",
            "CommonSkills:CompositeSkillType",
            "CommonSkills:ProgramSkillStateMachineType",
            "ProgramStateMachineType"
        ]
    );

    // The methods keep their ns0 BrowseNames (the transitions' HasCause names them) and get the rules of
    // the skill: Start, Halt and Reset always, Suspend and Resume on composite skills.
    let rule = |t: NodeIx, name: &str| {
        let member = m.members[&t].iter().find(|x| x.browse_name.name == name).unwrap_or_else(|| panic!("{name}"));
        assert_eq!(member.browse_name.ns, 0, "{name} keeps its ns0 BrowseName");
        assert_eq!(m.node(member.node).class, NodeClass::Method);
        m.node(member.node).modelling_rule
    };
    for (t, optional) in [(pssm, true), (composite, false), (drill_hole, false)] {
        for name in ["Start", "Halt", "Reset"] {
            assert_eq!(rule(t, name), Some(ModellingRule::Mandatory), "{} {name}", m.qualified(t));
        }
        let pause = if optional { ModellingRule::Optional } else { ModellingRule::Mandatory };
        for name in ["Suspend", "Resume"] {
            assert_eq!(rule(t, name), Some(pause), "{} {name}", m.qualified(t));
        }
    }
    // The states and transitions are ProgramStateMachineType's, inherited, not redeclared: every cause of
    // a transition is a method with the BrowseName of one of our overrides.
    let sm = &m.state_machines[&drill_hole];
    let states: Vec<&str> = sm.states.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(states, ["Halted", "Ready", "Running", "Suspended"]);
    assert!(sm.states.iter().all(|s| m.node(s.node).id.ns == 0), "the states are ns0's");
    assert_eq!(sm.transitions.len(), 9);
    // A transition raises the event ProgramSkillStateMachineType names with GeneratesEvent (ns0 names the
    // abstract ProgramTransitionEventType as the transitions' effect).
    assert_eq!(sm.event_type, Some(find(m, CS, "SkillTransitionEventType")));
    for tr in &sm.transitions {
        for &cause in &tr.causes {
            let name = &m.node(cause).browse_name.name;
            assert!(
                m.members[&drill_hole].iter().any(|x| &x.browse_name.name == name && ours(m, x.node)),
                "cause {name} of {}",
                tr.name
            );
        }
    }

    // Input parameters: writable variables, Mandatory wherever a type declares them.
    let mut inputs = 0;
    for ix in (0..m.nodes.len() as u32).map(NodeIx).filter(|&ix| ours(m, ix)) {
        if m.node(ix).browse_name.name != "InputParameterSet" {
            continue;
        }
        for (_, p) in m.children(ix) {
            let n = m.node(p);
            assert_eq!(n.class, NodeClass::Variable, "{}", m.qualified(p));
            assert_eq!(n.attrs.access_level, Some(3), "{} is writable", m.qualified(p));
            if m.node(ix).modelling_rule.is_some() {
                assert_eq!(n.modelling_rule, Some(ModellingRule::Mandatory), "{}", m.qualified(p));
            }
            inputs += 1;
        }
    }
    assert!(inputs > 50, "{inputs} input parameters");

    // The targets of the move skills.
    let ptp = find(m, CS, "AbsoluteJointPTPMoveSkillType");
    let joints = path(m, ptp, &["InputParameterSet", "TargetJointPositions"]);
    assert_eq!(m.node(joints).attrs.value_rank, Some(1));
    assert_eq!(m.node(m.node(joints).attrs.data_type.unwrap()).browse_name.name, "Double");
    for (t, name) in
        [("AbsoluteCartesianLinearMoveSkillType", "TargetPose"), ("RelativeCartesianLinearMoveSkillType", "PoseOffset")]
    {
        let pose = path(m, find(m, CS, t), &["InputParameterSet", name]);
        assert!(m.is_ns0(m.node(pose).attrs.data_type.unwrap(), THREE_D_FRAME), "{t}.{name} is a 3DFrame");
        assert_eq!(m.node(m.node(pose).type_definition.unwrap()).browse_name.name, "3DFrameType");
    }
}

#[test]
fn the_ur10e_controller_offers_the_three_move_skills() {
    let out = skills();
    let m = &out.model;
    let ur10e = find(m, RC, "UR10eSystemType");
    assert_eq!(m.qualified(m.node(ur10e).super_type.unwrap()), "Robotics:MotionDeviceSystemType");
    let controller = path(m, ur10e, &["Controllers", "URController"]);
    assert_eq!(m.qualified(m.node(controller).type_definition.unwrap()), "Robotics:ControllerType");
    let itf = m.ns0(HAS_INTERFACE).unwrap();
    let iskillset = find(m, CS, "ISkillSetType");
    assert!(m
        .node(controller)
        .references
        .iter()
        .any(|r| r.forward && r.reference_type == itf && r.target == iskillset));
    let set = child(m, controller, "SkillSet");
    let mut skills: Vec<(String, String)> = m
        .children(set)
        .map(|(_, s)| (m.node(s).browse_name.name.clone(), m.qualified(m.node(s).type_definition.unwrap())))
        .collect();
    skills.sort();
    assert_eq!(
        skills,
        [
            ("AbsoluteCartesianLinearMove".to_owned(), "CommonSkills:AbsoluteCartesianLinearMoveSkillType".to_owned()),
            ("AbsoluteJointPTPMove".to_owned(), "CommonSkills:AbsoluteJointPTPMoveSkillType".to_owned()),
            ("RelativeCartesianLinearMove".to_owned(), "CommonSkills:RelativeCartesianLinearMoveSkillType".to_owned()),
        ]
    );
    // The instance has the same skills under the same path.
    let system = find(m, DP, "TemplateDrillingLwrSystem");
    assert_eq!(m.qualified(m.node(system).type_definition.unwrap()), "RobotCell:TemplateDrillingLwrSystemType");
    let set = path(m, system, &["MotionDeviceSystem", "Controllers", "URController", "SkillSet"]);
    assert_eq!(m.children(set).count(), 3);
    // ... and the cell its two composite skills.
    let cell_set = path(m, find(m, DP, "DrillingCell"), &["SkillSet"]);
    let mut names: Vec<&str> = m.children(cell_set).map(|(_, s)| m.node(s).browse_name.name.as_str()).collect();
    names.sort();
    assert_eq!(names, ["DrillHole", "ReferenceDrillBush"]);
}

/// The declarations that apply below a node: the ones at its BrowsePath (`sources`, most derived first)
/// and the members of its TypeDefinition, grouped by BrowseName, most derived first. Where the node's
/// TypeDefinition is a subtype of the declared one, the subtype's members come first.
fn declarations(m: &Model, sources: &[NodeIx], td: Option<NodeIx>) -> Vec<(String, u16, Vec<NodeIx>)> {
    let declared = sources.first().and_then(|&s| m.node(s).type_definition);
    let mut layers: Vec<NodeIx> = Vec::new();
    let mut td = td;
    if let (Some(t), Some(d)) = (td, declared) {
        if t != d && m.is_subtype_of(t, d) {
            layers.extend(m.super_chain(t).into_iter().take_while(|&x| x != d));
            td = Some(d);
        }
    }
    layers.extend_from_slice(sources);
    if let Some(t) = td {
        layers.extend(m.super_chain(t));
    }
    let mut out: Vec<(String, u16, Vec<NodeIx>)> = Vec::new();
    for layer in layers {
        for (_, c) in m.children(layer) {
            if m.node(c).modelling_rule.is_none() {
                continue;
            }
            let bn = &m.node(c).browse_name;
            match out.iter_mut().find(|(name, ns, _)| *name == bn.name && *ns == bn.ns) {
                Some((_, _, decls)) => decls.push(c),
                None => out.push((bn.name.clone(), bn.ns, vec![c])),
            }
        }
    }
    out
}

/// Checks that `node` carries every Mandatory declaration that applies to it, with the same BrowseName,
/// NodeClass and a fitting TypeDefinition, and at least one node for every MandatoryPlaceholder (when it
/// is an instance); then checks its children the same way. Instances must not have a ModellingRule,
/// instance declarations must.
fn complete(m: &Model, node: NodeIx, sources: &[NodeIx], instance: bool, problems: &mut Vec<String>) {
    let n = m.node(node);
    if instance && n.modelling_rule.is_some() {
        problems.push(format!("instance {} has a ModellingRule", path_of(m, node)));
    }
    if !instance && n.modelling_rule.is_none() {
        problems.push(format!("instance declaration {} has no ModellingRule", path_of(m, node)));
    }
    let children: Vec<NodeIx> = m.children(node).map(|(_, c)| c).collect();
    let mut matched = vec![false; children.len()];
    let decls_here = declarations(m, sources, n.type_definition);
    // BrowseNames that are declared as such; a placeholder stands for the other children only.
    let named: Vec<(&str, u16)> = decls_here
        .iter()
        .filter(|(_, _, d)| !m.node(d[0]).modelling_rule.is_some_and(|r| r.is_placeholder()))
        .map(|(name, ns, _)| (name.as_str(), *ns))
        .collect();
    for (name, ns, decls) in decls_here.iter().cloned() {
        let decl = m.node(decls[0]);
        let fits = |c: NodeIx| {
            let cn = m.node(c);
            cn.class == decl.class
                && match (cn.type_definition, decl.type_definition) {
                    (Some(have), Some(want)) => m.is_subtype_of(have, want),
                    (have, want) => have.is_none() && want.is_none(),
                }
        };
        match decl.modelling_rule {
            Some(rule) if rule.is_placeholder() => {
                // Any child of the placeholder's class and type counts for it, also one declared by name
                // (the six axes of UR10eSystemType); the others are checked against the placeholder.
                let found = children.iter().filter(|&&c| fits(c)).count();
                for (k, &c) in children.iter().enumerate() {
                    if !matched[k]
                        && !named.contains(&(m.node(c).browse_name.name.as_str(), m.node(c).browse_name.ns))
                        && fits(c)
                    {
                        matched[k] = true;
                        complete(m, c, &decls, instance, problems);
                    }
                }
                if instance && rule == ModellingRule::MandatoryPlaceholder && found == 0 {
                    problems.push(format!("{} has no {name} (MandatoryPlaceholder)", path_of(m, node)));
                }
            }
            rule => {
                let hit =
                    children.iter().position(|&c| m.node(c).browse_name.name == name && m.node(c).browse_name.ns == ns);
                match hit {
                    Some(k) => {
                        matched[k] = true;
                        if !fits(children[k]) {
                            problems.push(format!("{}/{name} does not fit its declaration", path_of(m, node)));
                        }
                        complete(m, children[k], &decls, instance, problems);
                    }
                    None if rule == Some(ModellingRule::Mandatory) => {
                        problems.push(format!("{} lacks its Mandatory {name}", path_of(m, node)));
                    }
                    None => {}
                }
            }
        }
    }
    // Children beyond the declarations: checked against their own type.
    for (k, &c) in children.iter().enumerate() {
        if !matched[k] && ours(m, c) {
            complete(m, c, &[], instance, problems);
        }
    }
}

fn path_of(m: &Model, mut node: NodeIx) -> String {
    let mut parts = vec![m.node(node).browse_name.name.clone()];
    while let Some(p) = m.node(node).parent {
        parts.push(m.node(p).browse_name.name.clone());
        node = p;
    }
    parts.reverse();
    parts.join("/")
}

#[test]
fn instances_and_instance_declarations_are_complete() {
    let out = skills();
    let m = &out.model;
    let mut problems = Vec::new();
    // The instances of DrillingProcess, from their roots.
    for root in [find(m, DP, "DrillingCell"), find(m, DP, "TemplateDrillingLwrSystem")] {
        complete(m, root, &[], true, &mut problems);
    }
    // The instance declarations our types add or override, against the declarations they override.
    let mut declarations_checked = 0;
    for t in
        (0..m.nodes.len() as u32).map(NodeIx).filter(|&ix| ours(m, ix) && m.node(ix).class == NodeClass::ObjectType)
    {
        let inherited = m.node(t).super_type.map(|s| declarations(m, &[], Some(s))).unwrap_or_default();
        for (_, c) in m.children(t) {
            let bn = &m.node(c).browse_name;
            let overridden: Vec<NodeIx> = inherited
                .iter()
                .find(|(name, ns, _)| *name == bn.name && *ns == bn.ns)
                .map(|(_, _, d)| d.clone())
                .unwrap_or_default();
            complete(m, c, &overridden, false, &mut problems);
            declarations_checked += 1;
        }
    }
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
    assert!(declarations_checked > 20, "{declarations_checked}");
    // The instance's methods name the methods of their skill types.
    let start = path(m, find(m, DP, "DrillingCell"), &["SkillSet", "DrillHole", "Start"]);
    let decl = m.node(start).attrs.method_declaration.expect("MethodDeclarationId");
    assert_eq!(m.qualified(m.node(decl).parent.unwrap()), "CommonSkills:ProgramSkillStateMachineType");
    let suspend = path(m, find(m, DP, "DrillingCell"), &["SkillSet", "DrillHole", "Suspend"]);
    let decl = m.node(suspend).attrs.method_declaration.expect("MethodDeclarationId");
    assert_eq!(m.qualified(m.node(decl).parent.unwrap()), "CommonSkills:CompositeSkillType");
}

/// The venv's python, or a failure that says how to create it.
fn python() -> PathBuf {
    let python = root().join(".venv/bin/python");
    assert!(python.is_file(), "the Python venv is missing ({}); run `cargo xtask venv`", python.display());
    python
}

#[test]
fn asyncua_imports_the_skill_nodesets_without_a_warning() {
    let out = Command::new(python())
        .arg(root().join("tests/interop/skills_import.py"))
        .arg("--vendor")
        .arg(vendor())
        .arg("--nodesets")
        .arg(root().join("nodesets"))
        .output()
        .expect("python runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains(" passed, 0 failed"),
        "tests/interop/skills_import.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs `tests/interop/xsd_check.py` with the OPC Foundation's UANodeSet.xsd on `files`.
fn xsd_check(files: &[PathBuf]) -> (bool, String) {
    let schema = root().join("../shared/nodesets/ua-nodeset/Schema/UANodeSet.xsd");
    assert!(schema.is_file(), "UANodeSet.xsd is missing at {}; the tests need ../shared beside the project", schema.display());
    let out = Command::new(python())
        .arg(root().join("tests/interop/xsd_check.py"))
        .arg(&schema)
        .args(files)
        .output()
        .expect("python runs");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(!text.contains("ModuleNotFoundError"), "xmlschema is not installed; run `cargo xtask venv`:\n{text}");
    (out.status.success(), text)
}

/// Each file is valid against UANodeSet.xsd; the check itself finds an element that the schema forbids.
#[test]
fn skill_nodesets_are_valid_against_uanodeset_xsd() {
    let files: Vec<PathBuf> = FILES.iter().map(|f| root().join("nodesets").join(f)).collect();
    let (valid, report) = xsd_check(&files);
    assert!(valid, "a skill nodeset is not valid against UANodeSet.xsd:\n{report}");
    assert_eq!(report.matches(": 0 errors").count(), 3, "{report}");

    // A UAObjectType without its NodeId, and an element UANodeSet.xsd does not know.
    let text = std::fs::read_to_string(&files[0]).unwrap();
    let broken = text
        .replacen("<UAObjectType NodeId=\"ns=1;i=1100\"", "<UAObjectType", 1)
        .replacen("</UANodeSet>", "<UAWidget NodeId=\"ns=1;i=1\"/></UANodeSet>", 1);
    assert_ne!(broken, text);
    let dir = std::env::temp_dir().join(format!("nodeset-xsd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("Broken.NodeSet2.xml");
    std::fs::write(&path, broken).unwrap();
    let (valid, report) = xsd_check(&[path]);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(!valid, "the broken file passed:\n{report}");
    assert!(report.contains(": 2 errors") && report.contains("NodeId") && report.contains("UAWidget"), "{report}");
}
