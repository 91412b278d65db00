//! Unit tests of the Modelica back end over the pinned companion specifications and the fixtures.
//!
//! rumoca accepts duplicate enumeration literals and does not complain about a modifier of an element that
//! does not exist, so these properties are checked here, on the generator's own tables.

use super::ctx::Ctx;
use super::plan::ClassKey;
use super::plan::ElemKind;
use super::*;
use crate::load::Input;
use crate::model::DataTypeKind;
use crate::{compile, Options};
use std::collections::BTreeSet;
use std::path::PathBuf;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn load(files: &[PathBuf], dirs: Vec<PathBuf>) -> crate::Compiled {
    let out = compile(
        files.iter().map(|f| Input::Path(f.clone())).collect(),
        &Options { model_dirs: dirs, ..Options::default() },
    );
    assert!(out.ok(), "{}", out.render_diagnostics());
    out
}

pub(super) fn robotics() -> crate::Compiled {
    let v = workspace().join("nodesets/vendor");
    load(&[v.join("Opc.Ua.Robotics.NodeSet2.xml")], vec![v])
}

fn fixture(case: &str) -> crate::Compiled {
    let dir = workspace().join("tests/fixtures").join(case);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "xml"))
        .collect();
    files.sort();
    load(&files, vec![dir, workspace().join("nodesets/vendor")])
}

/// The fixture `vendor_robot`, the text of its vendor file (`Example.VendorRobot.NodeSet2.xml`, which ArmType,
/// ArmXType and ArmYType come from) changed by `patch`.
pub(super) fn vendor_robot_with(patch: impl Fn(&str) -> String) -> crate::Compiled {
    let dir = workspace().join("tests/fixtures/vendor_robot");
    let mut inputs = Vec::new();
    for name in ["Example.VendorRobot.Device", "Example.VendorRobot.Robotics", "Example.VendorRobot"] {
        let path = dir.join(format!("{name}.NodeSet2.xml"));
        let mut text = std::fs::read_to_string(&path).unwrap();
        if name == "Example.VendorRobot" {
            text = patch(&text);
        }
        inputs.push(Input::Text { name: path.display().to_string(), text });
    }
    let out = compile(inputs, &Options { model_dirs: vec![workspace().join("nodesets/vendor")], ..Options::default() });
    assert!(out.ok(), "{}", out.render_diagnostics());
    out
}

/// The namespaces of the fixture `vendor_robot`.
pub(super) const VENDOR_ROBOT: [&str; 3] = [
    "http://example.com/fixtures/vendor_robot/Device/",
    "http://example.com/fixtures/vendor_robot/Robotics/",
    "http://example.com/fixtures/vendor_robot/",
];

/// Plans every ObjectType and instance of every namespace of the model (ns0 included) and checks that the
/// identifiers of each class are unique: elements, their `use_` flags, counts and class aliases.
fn assert_unique_names(model: &crate::model::Model) {
    let pkg: Vec<String> = (0..model.namespaces.len()).map(|i| format!("P{i}")).collect();
    let all: BTreeSet<u16> = (0..model.namespaces.len() as u16).collect();
    let mut ctx = Ctx::new(model, pkg, all.clone(), None);
    for ns in all {
        for ix in (0..model.nodes.len() as u32).map(crate::model::NodeIx) {
            let n = model.node(ix);
            if n.id.ns != ns {
                continue;
            }
            if n.class == crate::raw::NodeClass::ObjectType {
                ctx.type_class(ix);
            }
            if let Some(DataTypeKind::Enumeration { .. }) = model.data_types.get(&ix).map(|i| &i.kind) {
                let lits = ctx.enum_literals(ix);
                let set: BTreeSet<&String> = lits.iter().map(|(_, l)| l).collect();
                assert_eq!(set.len(), lits.len(), "duplicate literals in {}", model.qualified(ix));
                for (_, l) in &lits {
                    assert!(crate::names::is_valid(l, crate::names::Target::Modelica), "{l}");
                }
            }
            if matches!(
                model.data_types.get(&ix).map(|i| &i.kind),
                Some(DataTypeKind::Structure { .. } | DataTypeKind::OptionSet { .. })
            ) {
                let r = ctx.record_info(ix);
                let mut names: Vec<&String> = r.fields.iter().map(|f| &f.ident).collect();
                names.extend(r.fields.iter().filter_map(|f| f.has_flag.as_ref()));
                names.extend(r.fields.iter().filter_map(|f| f.count.as_ref()));
                let set: BTreeSet<&String> = names.iter().copied().collect();
                assert_eq!(set.len(), names.len(), "duplicate fields in {}: {names:?}", model.qualified(ix));
            }
        }
        let names = ctx.names(ns);
        for &top in &names.top_instances {
            if model.node(top).class == crate::raw::NodeClass::Object {
                ctx.plan_instance(top);
            }
        }
    }
    assert!(!ctx.class_infos.is_empty());
    for (key, info) in &ctx.class_infos {
        let mut names: Vec<&String> = Vec::new();
        for e in &info.elements {
            names.push(&e.ident);
            names.extend(e.use_flag.iter());
            names.extend(e.count.iter());
            names.extend(e.alias.iter());
        }
        let set: BTreeSet<&String> = names.iter().copied().collect();
        assert_eq!(set.len(), names.len(), "duplicate identifiers in {key:?}: {names:?}");
        for n in &names {
            assert!(crate::names::is_valid(n, crate::names::Target::Modelica), "{n} in {key:?}");
            assert!(info.taken.contains(*n), "{n} of {key:?} is not recorded as taken");
        }
        // An element that refers to a class refers to one that was planned.
        for e in &info.elements {
            if let ElemKind::Object { class } = &e.kind {
                match class {
                    ClassKey::Type(t) => assert_eq!(model.node(*t).class, crate::raw::NodeClass::ObjectType),
                    other => assert!(ctx.class_infos.contains_key(other), "{other:?} of {key:?} was never planned"),
                }
            }
        }
    }
    // Every declaration class has a name.
    for (owner, plan) in &ctx.plans {
        for (path, _) in &plan.decls {
            assert!(ctx.decl_names.contains_key(&(*owner, path.clone())), "{path} of {owner:?} has no name");
        }
    }
}

#[test]
fn names_are_unique_in_every_scope_of_the_companion_specs() {
    assert_unique_names(&robotics().model);
}

#[test]
fn names_are_unique_in_every_scope_of_the_fixtures() {
    for case in ["names", "instances", "state_machine", "two_namespaces", "optional_fields", "union", "enum_gaps"] {
        assert_unique_names(&fixture(case).model);
    }
}

#[test]
fn colliding_names_are_renamed_and_reported() {
    let out = fixture("names");
    let g =
        generate_with_diagnostics(&out.model, &ModelicaConfig::new().namespace("http://example.com/fixtures/names/"));
    let class =
        g.files.iter().find(|f| f.path.ends_with("ObjectTypes/N3DFrameType.mo")).expect("3DFrameType is generated");
    for decl in [
        "String type_ =",
        "parameter String model_ =",
        "OpcUaSupport.RealInput input_\n",
        "modeA =",
        "modeA_2 =",
        "self_2 =",
        "ios(min=0)",
    ] {
        assert!(class.contents.contains(decl), "`{decl}` missing in\n{}", class.contents);
    }
    let collisions: Vec<&str> = g
        .diagnostics
        .items
        .iter()
        .filter(|d| d.code == crate::diag::Code::NameCollision)
        .map(|d| d.message.as_str())
        .collect();
    assert!(collisions.iter().any(|m| m.contains("`modeA`") && m.contains("Mode-A")), "{collisions:?}");
}

#[test]
fn package_names_derive_from_uris() {
    assert_eq!(package_words("http://opcfoundation.org/UA/Robotics/"), "Opc Ua Robotics");
    let cases = [
        ("http://opcfoundation.org/UA/", "OpcUa"),
        ("http://opcfoundation.org/UA/DI/", "OpcUaDI"),
        ("http://opcfoundation.org/UA/Robotics/", "OpcUaRobotics"),
        ("http://opcfoundation.org/UA/Mining/General/1.0.0/", "OpcUaMiningGeneral"),
        ("http://example.com/fixtures/union/", "ExampleFixturesUnion"),
        ("urn:vendor:models:press", "VendorModelsPress"),
    ];
    for (uri, want) in cases {
        assert_eq!(
            crate::names::sanitize(&package_words(uri), crate::names::Case::UpperCamel, crate::names::Target::Modelica),
            want,
            "{uri}"
        );
    }
}

#[test]
fn configuration_errors_are_diagnostics() {
    let out = fixture("structure");
    let bad_ns = generate(&out.model, &ModelicaConfig::new().namespace("http://nowhere.invalid/"));
    let d = bad_ns.expect_err("an unknown namespace is an error");
    assert!(d.items.iter().any(|x| x.code == crate::diag::Code::UnknownNamespaceUri));
    let bad_name = generate(
        &out.model,
        &ModelicaConfig::new()
            .namespace("http://example.com/fixtures/structure/")
            .package_name("http://example.com/fixtures/structure/", "model"),
    );
    assert!(bad_name.is_err(), "`model` is no package name");
    let renamed = generate(
        &out.model,
        &ModelicaConfig::new()
            .namespace("http://example.com/fixtures/structure/")
            .package_name("http://example.com/fixtures/structure/", "Plant"),
    )
    .unwrap();
    assert!(renamed.iter().any(|f| f.path.as_path() == std::path::Path::new("Plant/Types/Position.mo")));
}

#[test]
fn enumerations_keep_their_opc_ua_values() {
    let out = fixture("enum_gaps");
    let files =
        generate(&out.model, &ModelicaConfig::new().namespace("http://example.com/fixtures/enum_gaps/")).unwrap();
    let values = files.iter().find(|f| f.path.ends_with("EnumerationValues.mo")).unwrap();
    assert!(
        values.contents.contains("constant Integer AlarmSeverityLevel[5] = {-1, 1, 2, 5, 10}"),
        "{}",
        values.contents
    );
}

#[test]
fn a_subtype_makes_an_optional_member_mandatory_and_redeclares_its_class() {
    let files = generate(
        &robotics().model,
        &ModelicaConfig::new()
            .namespace("http://opcfoundation.org/UA/Robotics/")
            .namespace("http://opcfoundation.org/UA/DI/")
            .namespace("http://opcfoundation.org/UA/IA/"),
    )
    .unwrap();
    let axis = files.iter().find(|f| f.path.ends_with("OpcUaRobotics/ObjectTypes/AxisType.mo")).unwrap();
    assert!(axis.contents.contains("final use_parameterSet=true"), "{}", axis.contents);
    assert!(
        axis.contents.contains("redeclare model ParameterSet = OpcUaRobotics.Declarations.AxisType_ParameterSet"),
        "{}",
        axis.contents
    );
}

fn robotics_files() -> Vec<crate::write::OutFile> {
    generate(
        &robotics().model,
        &ModelicaConfig::new()
            .namespace("http://opcfoundation.org/UA/Robotics/")
            .namespace("http://opcfoundation.org/UA/DI/")
            .namespace("http://opcfoundation.org/UA/IA/"),
    )
    .unwrap()
}

fn contents<'a>(files: &'a [crate::write::OutFile], path: &str) -> &'a str {
    &files.iter().find(|f| f.path.ends_with(path)).unwrap_or_else(|| panic!("no {path}")).contents
}

#[test]
fn published_values_are_unbound_inputs_and_complete_variants_bind_them() {
    let files = robotics_files();
    // ActualPosition is published (clients read it): an input connector nothing binds, for the physics to
    // connect to; so AxisType, whose ParameterSet holds it, is partial.
    let set = contents(&files, "OpcUaRobotics/Declarations/AxisType_ParameterSet.mo");
    assert!(set.contains("  OpcUaSupport.RealInput actualPosition\n"), "{set}");
    assert!(set.starts_with("// ") && set.contains("\nmodel AxisType_ParameterSet "), "{set}");
    let axis = contents(&files, "OpcUaRobotics/ObjectTypes/AxisType.mo");
    assert!(axis.contains("\npartial model AxisType "), "{axis}");
    // The complete variant binds every free input to the nodeset's value.
    let complete = contents(&files, "OpcUaRobotics/Complete/AxisType.mo");
    assert!(
        complete.contains("  extends OpcUaRobotics.ObjectTypes.AxisType(\n    parameterSet(actualAcceleration=0, actualPosition=0, actualSpeed=0),"),
        "{complete}"
    );
    // A placeholder's replaceable class defaults to the complete variant and accepts any model extending the
    // partial class.
    let axes = contents(&files, "OpcUaRobotics/Declarations/MotionDeviceType_Axes.mo");
    assert!(
        axes.contains("replaceable model AxisIdentifier = OpcUaRobotics.Complete.AxisType constrainedby OpcUaRobotics.ObjectTypes.AxisType"),
        "{axes}"
    );
    // A value clients write is an output connector with the nodeset's value.
    let level = contents(&files, "OpcUaIA/ObjectTypes/StackLevelType.mo");
    assert!(level.contains("  OpcUaSupport.RealOutput levelPercent = 0\n"), "{level}");
}

#[test]
fn mandatory_placeholders_hold_one_element_until_named_children_fill_them() {
    let files = robotics_files();
    // A MotionDevice has at least one axis: one by default, never fewer; the elements' BrowseNames are parameters,
    // the placeholder's own until a user names them.
    let axes = contents(&files, "OpcUaRobotics/Declarations/MotionDeviceType_Axes.mo");
    assert!(axes.contains("  parameter Integer nAxisIdentifier(min=1) = 1\n"), "{axes}");
    assert!(axes.contains("  extends OpcUa.ObjectTypes.FolderType;\n"), "the placeholder does not fill itself: {axes}");
    assert!(
        axes.contains("  parameter String axisIdentifierBrowseNames[nAxisIdentifier] = fill(\"<AxisIdentifier>\", nAxisIdentifier)\n"),
        "{axes}"
    );
    // An optional placeholder stays empty.
    let modules = contents(&files, "OpcUaRobotics/Declarations/TaskControlType_TaskModules.mo");
    assert!(modules.contains("  parameter Integer nTaskModule(min=0) = 0\n"), "{modules}");
    assert!(modules.contains("  parameter String taskModuleBrowseNames[nTaskModule] = "), "{modules}");

    let skills = skills_with(str::to_string);
    // A type whose own children fit the placeholder (the UR10e's six named axes) empties its array.
    let ur_axes = contents(&skills, "NodesetCompilerRobotCell/Declarations/UR10eSystemType_MotionDevicesManipulatorAxes.mo");
    assert!(ur_axes.contains("  extends OpcUaRobotics.Declarations.MotionDeviceType_Axes(nAxisIdentifier(min=0)=0);\n"), "{ur_axes}");
    // An instance holds what the nodeset gives it: every mandatory placeholder's array is empty.
    let system = contents(&skills, "NodesetCompilerDrillingProcess/Declarations/TemplateDrillingLwrSystem_MotionDeviceSystem.mo");
    for count in ["nControllerIdentifier", "nMotionDeviceIdentifier", "nSafetyStateIdentifier", "nAxisIdentifier"] {
        assert!(system.contains(&format!("{count}(min=0)=0")), "{count}: {system}");
    }
}

#[test]
fn names_keep_their_spelling_where_legal_and_never_name_an_annotation() {
    let files = robotics_files();
    // DI's ISupportInfoType has an optional folder Documentation: its class is not called like the annotation.
    let support = contents(&files, "OpcUaDI/ObjectTypes/ISupportInfoType.mo");
    assert!(support.contains("  replaceable model Documentation_ = OpcUa.ObjectTypes.FolderType\n"), "{support}");
    assert!(!support.contains("model Documentation "), "{support}");
    let category = contents(&files, "OpcUaRobotics/Types/MotionDeviceCategoryEnumeration.mo");
    assert!(category.contains("\n    ARTICULATED_ROBOT \"ARTICULATED_ROBOT = 1: "), "{category}");
    let mode = contents(&files, "OpcUaRobotics/Types/OperationalModeEnumeration.mo");
    assert!(mode.contains("\n    MANUAL_REDUCED_SPEED \""), "{mode}");
}

#[test]
fn references_that_are_not_containment_name_their_target() {
    let files = robotics_files();
    // AxisType Requires <PowerTrainIdentifier>; PowerTrainType Moves <AxisIdentifier> and HasSlave
    // <PowerTrainIdentifier>: parameters with the NodeIds of the targets, not contained copies.
    let axis = contents(&files, "OpcUaRobotics/ObjectTypes/AxisType.mo");
    assert!(axis.contains("parameter String powerTrainIdentifier[nPowerTrainIdentifier] = fill(\"\", nPowerTrainIdentifier)"), "{axis}");
    assert!(axis.contains("referenceType=\"Requires\""), "{axis}");
    assert!(!axis.contains("model PowerTrainIdentifier"), "{axis}");
    let power_train = contents(&files, "OpcUaRobotics/ObjectTypes/PowerTrainType.mo");
    for (name, rt) in [("axisIdentifier", "Moves"), ("powerTrainIdentifier", "HasSlave")] {
        assert!(power_train.contains(&format!("parameter String {name}[")), "{power_train}");
        assert!(power_train.contains(&format!("referenceType=\"{rt}\"")), "{power_train}");
    }
    assert!(!power_train.contains("model AxisIdentifier"), "{power_train}");
}

#[test]
fn containment_that_would_make_a_class_contain_itself_is_cut() {
    let out = robotics();
    let m = &out.model;
    let cuts = recursion::containment_cuts(m);
    let named: BTreeSet<String> = cuts
        .iter()
        .map(|&c| format!("{}/{}", m.node(m.node(c).parent.unwrap()).browse_name.name, m.node(c).browse_name.name))
        .collect();
    for want in ["FunctionalGroupType/<GroupIdentifier>", "FileDirectoryType/<FileDirectoryName>"] {
        assert!(named.contains(want), "{want} is not cut: {named:?}");
    }
    let files = robotics_files();
    let group = contents(&files, "OpcUaDI/ObjectTypes/FunctionalGroupType.mo");
    assert!(group.contains("parameter String groupIdentifier["), "{group}");
    assert!(group.contains("containing it would make the class contain itself"), "{group}");
}

/// The skill models, with the CurrentState of the DrillingCell's ReferenceDrillBush instance changed from
/// Ready to `state` (Id, Number and text).
fn skills_with_reference_drill_bush_in(state: Option<(&str, &str, &str)>) -> Vec<crate::write::OutFile> {
    skills_with(|text| match state {
        None => text.to_string(),
        Some((id, number, shown)) => {
            let mut text = text.to_string();
            let from = text.find("NodeId=\"ns=1;i=4003\"").unwrap();
            let to = text.find("NodeId=\"ns=1;i=4006\"").unwrap();
            let part = text[from..to]
                .replace("<uax:Text>Ready</uax:Text>", &format!("<uax:Text>{shown}</uax:Text>"))
                .replace("<uax:Identifier>i=2400</uax:Identifier>", &format!("<uax:Identifier>{id}</uax:Identifier>"))
                .replace("<uax:UInt32>12</uax:UInt32>", &format!("<uax:UInt32>{number}</uax:UInt32>"));
            text.replace_range(from..to, &part);
            text
        }
    })
}

/// The Modelica packages of our skill models, with the text of DrillingProcess changed by `patch`.
fn skills_with(patch: impl Fn(&str) -> String) -> Vec<crate::write::OutFile> {
    let dir = workspace().join("nodesets");
    let mut inputs = Vec::new();
    for name in ["CommonSkills", "RobotCell", "DrillingProcess"] {
        let path = dir.join(format!("{name}.NodeSet2.xml"));
        let mut text = std::fs::read_to_string(&path).unwrap();
        if name == "DrillingProcess" {
            text = patch(&text);
        }
        inputs.push(Input::Text { name: path.display().to_string(), text });
    }
    let out = compile(inputs, &Options { model_dirs: vec![dir.join("vendor")], ..Options::default() });
    assert!(out.ok(), "{}", out.render_diagnostics());
    let mut cfg = ModelicaConfig::new();
    for m in &out.model.models {
        if m.uri != crate::load::NS0_URI {
            cfg = cfg.namespace(m.uri.clone());
        }
    }
    generate(&out.model, &cfg).unwrap()
}

#[test]
fn state_text_follows_the_number_and_instances_set_the_initial_state() {
    let files = skills_with_reference_drill_bush_in(None);
    let program = contents(&files, "OpcUa/ObjectTypes/ProgramStateMachineType.mo");
    assert!(program.contains("final currentState=currentStateText"), "{program}");
    assert!(program.contains("discrete Integer currentStateNumber(start=Ready, fixed=true)"), "{program}");
    assert!(program.contains("currentStateText = if currentStateNumber == Halted then \"Halted\""), "{program}");
    // The instances are in Ready, where the skills start anyway: no modifier, and never the text.
    let cell = contents(&files, "NodesetCompilerDrillingProcess/Instances/DrillingCell.mo");
    assert!(!cell.contains("currentState"), "{cell}");
    // An instance in another state starts there; Id, Number and text each name it.
    for (id, number, shown) in [("i=2406", "11", "Halted"), ("i=2402", "13", "Running")] {
        let files = skills_with_reference_drill_bush_in(Some((id, number, shown)));
        let cell = contents(&files, "NodesetCompilerDrillingProcess/Instances/DrillingCell.mo");
        assert!(cell.contains(&format!("referenceDrillBush(currentStateNumber(start={number})")), "{cell}");
        assert!(!cell.contains("currentState="), "{cell}");
    }
}

#[test]
fn an_instance_names_the_target_of_its_reference() {
    // DrillingCell Requires the robot system TemplateDrillingLwrSystem (Requires, i=25256, is hierarchical but
    // not containment): a parameter with the target's NodeId, not a copy of the robot system.
    let files = skills_with(|text| {
        let at = text.find("<Reference ReferenceType=\"HasComponent\">ns=1;i=4001</Reference>").expect("DrillingCell's SkillSet");
        let mut text = text.to_string();
        text.insert_str(at, "<Reference ReferenceType=\"i=25256\">ns=1;i=5000</Reference>\n      ");
        text
    });
    let cell = contents(&files, "NodesetCompilerDrillingProcess/Instances/DrillingCell.mo");
    assert!(
        cell.contains("parameter String templateDrillingLwrSystem = \"nsu=http://nodeset-compiler.dev/DrillingProcess/;i=5000\""),
        "{cell}"
    );
    assert!(cell.contains("referenceType=\"Requires\""), "{cell}");
    assert!(!cell.contains("NodesetCompilerRobotCell."), "no component of the robot system's class: {cell}");
}

/// What the library conventions ask of a generated tree: documentation on every class, an icon on every model,
/// record and package, and a place on the icon for every connector, no two in one class at the same place.
/// Returns the offences, one per line.
fn convention_offences(files: &[crate::write::OutFile]) -> Vec<String> {
    let connector = is_support_connector();
    let mut out = Vec::new();
    for f in files.iter().filter(|f| f.path.extension().is_some_and(|e| e == "mo")) {
        let path = f.path.display();
        let text = &f.contents;
        let class = text.lines().find(|l| !l.starts_with("//") && !l.starts_with("within")).unwrap_or("");
        if !text.contains("Documentation(info=") {
            out.push(format!("{path}: no Documentation"));
        }
        let kind = class.split_whitespace().take_while(|w| *w != "=").collect::<Vec<_>>();
        let needs_icon = ["model", "block", "record", "package", "connector"].iter().any(|k| kind.contains(k));
        if needs_icon && !text.contains("Icon(") {
            out.push(format!("{path}: no Icon"));
        }
        let mut places = BTreeSet::new();
        for statement in text.split(";\n") {
            let first = statement.trim_start_matches('\n');
            if first.starts_with("  ") && !first.starts_with("   ") && connector(first.trim_start()) {
                match statement.find("Placement(transformation(extent=") {
                    None => out.push(format!("{path}: connector without Placement: {}", first.lines().next().unwrap_or(""))),
                    Some(at) => {
                        let place = statement[at..].split(")").next().unwrap_or("").to_string();
                        if !places.insert(place.clone()) {
                            out.push(format!("{path}: two connectors at {place}"));
                        }
                    }
                }
            }
        }
    }
    out
}

/// Whether a declaration starts with a connector of the support package (`OpcUaSupport.RealOutput x`).
fn is_support_connector() -> impl Fn(&str) -> bool {
    |decl: &str| {
        let Some(ty) = decl.strip_prefix("OpcUaSupport.") else { return false };
        let ty = ty.split_whitespace().next().unwrap_or("");
        ["Real", "Integer", "Boolean", "String"].iter().any(|b| ty == format!("{b}Input") || ty == format!("{b}Output"))
    }
}

#[test]
fn every_class_is_documented_and_has_an_icon_and_every_connector_a_place() {
    let mut files = robotics_files();
    files.extend(skills_with(str::to_string));
    let mut offences = convention_offences(&files);
    offences.sort();
    offences.dedup();
    assert!(offences.is_empty(), "{} offences:\n{}", offences.len(), offences.join("\n"));
    // The check sees what it looks for.
    let mut bare = robotics_files();
    let axis = bare.iter_mut().find(|f| f.path.ends_with("Declarations/AxisType_ParameterSet.mo")).unwrap();
    axis.contents = axis.contents.replacen("Placement(", "Place(", 1).replace("Documentation(", "Doc(").replace("Icon(", "I(");
    let offences = convention_offences(&bare);
    assert_eq!(offences.len(), 3, "{offences:?}");
}

#[test]
fn values_are_written_from_typed_data_a_float_as_its_shortest_text_and_a_structure_field_by_field() {
    use crate::nodeid::NodeId;
    use crate::raw::LocalizedText;
    use crate::value::{Body, ExtensionObject, Structure, Variant};
    let out = robotics();
    let m = &out.model;
    let all: BTreeSet<u16> = (0..m.namespaces.len() as u16).collect();
    let mut ctx = Ctx::new(m, (0..m.namespaces.len()).map(|i| format!("P{i}")).collect(), all, None);
    let file = m.node(m.ns0(crate::model::ids::ARGUMENT).unwrap()).file;
    let float = ctx.mtype(m.ns0(10).unwrap());
    assert_eq!(ctx.literal(&Variant::Float(0.1), &float, file).as_deref(), Some("0.1"));
    // EUInformation (i=887): fields by name, an absent field keeps its default, a field that did not decode too.
    let eu = m.ns0(887).unwrap();
    let s = Structure {
        data_type: NodeId::numeric(0, 887),
        switch_field: None,
        fields: vec![
            ("UnitId".into(), Ok(Variant::Int32(5066068))),
            ("DisplayName".into(), Ok(Variant::LocalizedText(LocalizedText { locale: None, text: "mm".into() }))),
            ("Description".into(), Err("field `Description`: broken".into())),
        ],
    };
    let v = Variant::ExtensionObject(Box::new(ExtensionObject { type_id: None, body: Some(Body::Structure(s)) }));
    let record = ctx.mtype(eu);
    let lit = ctx.literal(&v, &record, file).expect("a record literal");
    assert!(lit.ends_with("EUInformation(unitId = 5066068, displayName = \"mm\")"), "{lit}");
}

/// The Modelica package of Scales V2, its text changed by `patch`.
fn scales_with(patch: impl Fn(&str) -> String) -> Vec<crate::write::OutFile> {
    let v = workspace().join("nodesets/vendor");
    let path = v.join("Opc.Ua.Scales.NodeSet2.xml");
    let text = patch(&std::fs::read_to_string(&path).unwrap());
    let out = compile(
        vec![Input::Text { name: path.display().to_string(), text }],
        &Options { model_dirs: vec![v], ..Options::default() },
    );
    assert!(out.ok(), "{}", out.render_diagnostics());
    generate(&out.model, &ModelicaConfig::new().namespace("http://opcfoundation.org/UA/Scales/V2/")).unwrap()
}

#[test]
fn a_placeholder_array_repeats_its_choices_through_aliases_that_derived_classes_redeclare() {
    // Scales' ProductionPreset holds products in a placeholder, each with a replaceable Statistic. The array
    // repeats the product class's choice (for rumoca) through an alias of the Products class...
    let files = scales_with(str::to_string);
    let products = contents(&files, "OpcUaScalesV2/Declarations/ProductionPresetType_Products.mo");
    assert!(products.contains("  replaceable model Product_Statistic = OpcUaScalesV2.ObjectTypes.StatisticType\n"), "{products}");
    assert!(products.contains("  Product product_[nProduct_](redeclare model Statistic = Product_Statistic)\n"), "{products}");
    // ... which the checkweigher's Products class redeclares at class level, not on the array (pymoca 0.12.0
    // keeps the declaration's choice then, `tests/modelica/PymocaBehaviour`).
    let checkweigher = contents(&files, "OpcUaScalesV2/Declarations/CheckweigherType_ProductionPresetProducts.mo");
    assert!(
        checkweigher.contains(
            "    redeclare model Product_Statistic = OpcUaScalesV2.Declarations.CheckweigherType_ProductionPresetProductsProductStatistic,\n"
        ),
        "{checkweigher}"
    );
    assert!(!checkweigher.contains("redeclare model Statistic"), "{checkweigher}");

    // An element of the class already named like a pin alias: the pin aliases take the next free prefix.
    let object = r#"<UAObject NodeId="ns=1;i=99999" BrowseName="1:Product_Statistic" ParentNodeId="ns=1;i=75">
    <DisplayName>Product_Statistic</DisplayName>
    <References>
      <Reference ReferenceType="HasTypeDefinition">i=61</Reference>
      <Reference ReferenceType="HasModellingRule">i=80</Reference>
      <Reference ReferenceType="HasComponent" IsForward="false">ns=1;i=75</Reference>
    </References>
  </UAObject>
  "#;
    let files = scales_with(|text| {
        let at = text.find(r#"<UAObject NodeId="ns=1;i=92""#).unwrap();
        format!("{}{object}{}", &text[..at], &text[at..])
    });
    let products = contents(&files, "OpcUaScalesV2/Declarations/ProductionPresetType_Products.mo");
    assert!(products.contains("  replaceable model Product_Statistic = OpcUa.ObjectTypes.FolderType\n"), "{products}");
    assert!(products.contains("  replaceable model Product_2_Statistic = OpcUaScalesV2.ObjectTypes.StatisticType\n"), "{products}");
    assert!(products.contains("  Product product_[nProduct_](redeclare model Statistic = Product_2_Statistic)\n"), "{products}");
    let checkweigher = contents(&files, "OpcUaScalesV2/Declarations/CheckweigherType_ProductionPresetProducts.mo");
    assert!(checkweigher.contains("    redeclare model Product_2_Statistic = "), "{checkweigher}");
}

#[test]
fn a_value_a_subtype_gives_a_free_input_of_a_replaceable_member_is_bound_by_the_class_it_uses() {
    // VendorMotionDeviceType's Tuning (a replaceable class whose Limits publish MaxSpeed = 1.5 and MaxAccel = 3.0,
    // inputs nothing binds) defaults to its complete variant. ArmType declares Tuning/Limits/MaxSpeed = 2, ArmXType
    // MaxAccel = 4, ArmYType MaxAccel = 5: each type's Tuning gets a class of its own, whose complete variant
    // (the default of the alias) binds the type's values; a model a user plugs in binds its own.
    let out = vendor_robot_with(str::to_string);
    let mut cfg = ModelicaConfig::new();
    for uri in VENDOR_ROBOT {
        cfg = cfg.namespace(uri);
    }
    let files = generate(&out.model, &cfg).unwrap();
    let pkg = "ExampleFixturesVendorRobot";
    for (ty, values) in [
        ("ArmType", "maxSpeed=2.0, maxAccel=3.0"),
        ("ArmXType", "maxSpeed=2.0, maxAccel=4.0"),
        ("ArmYType", "maxSpeed=2.0, maxAccel=5.0"),
    ] {
        let class = contents(&files, &format!("{pkg}/ObjectTypes/{ty}.mo"));
        assert!(class.contains(&format!("redeclare model Tuning = {pkg}.Complete.{ty}_Tuning")), "{class}");
        let complete = contents(&files, &format!("{pkg}/Complete/{ty}_Tuning.mo"));
        let extends = format!("  extends {pkg}.Declarations.{ty}_Tuning(limits({values}));\n");
        assert!(complete.contains(&extends), "{complete}");
    }
    // The value stays where a subtype gives none (or the same): the inherited class binds it already.
    let out = vendor_robot_with(|text| {
        text.replace("<Value><Double xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\">5</Double></Value>", "")
    });
    let files = generate(&out.model, &cfg).unwrap();
    let arm_y = contents(&files, "ExampleFixturesVendorRobot/ObjectTypes/ArmYType.mo");
    assert!(!arm_y.contains("tuning(") && !arm_y.contains("model Tuning"), "{arm_y}");
    assert!(!files.iter().any(|f| f.path.ends_with("ArmYType_Tuning.mo")));
}
