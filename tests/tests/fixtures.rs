//! The minimal fixtures of `tests/fixtures/<case>/`, one feature each: every fixture resolves with no error and
//! no warning, its feature comes out of the resolver as the fixture means it, and the model dump of the
//! fixture's own namespaces is snapshotted (the emitters will be snapshotted on the same fixtures).

use nodeset_compiler::load::Input;
use nodeset_compiler::model::*;
use nodeset_compiler::raw::NodeClass;
use nodeset_compiler::value::{BuiltinType, Variant};
use nodeset_compiler::{compile, summary, Compiled, Options};
use nodeset_tests::{nodeset_files, root, vendor};
use std::path::PathBuf;

/// Compiles every NodeSet2 file of `tests/fixtures/<case>/` (required models from the pinned nodesets and the
/// fixture folder) and insists on a clean result: no error and no warning.
fn compile_fixture(case: &str) -> Compiled {
    compile_files(case, |files| files)
}

/// Like [`compile_fixture`], naming the files `pick` chooses from the fixture's files (sorted by name).
fn compile_files(case: &str, pick: impl FnOnce(Vec<PathBuf>) -> Vec<PathBuf>) -> Compiled {
    let dir = root().join("tests/fixtures").join(case);
    let files = nodeset_files(&dir);
    assert!(!files.is_empty(), "no NodeSet2 file in {}", dir.display());
    let opts = Options { model_dirs: vec![vendor(), dir.clone()], ..Options::default() };
    let out = compile(pick(files).into_iter().map(Input::Path).collect(), &opts);
    assert!(
        out.diagnostics.items.is_empty(),
        "fixture `{case}` must compile without errors or warnings, got {}:\n{}",
        out.diagnostics.items.len(),
        out.render_diagnostics()
    );
    out
}

/// The model URI of a fixture.
fn uri(case: &str) -> String {
    format!("http://example.com/fixtures/{case}/")
}

/// The node `i=<id>` of a namespace, by URI (fixture files number their nodes in their own namespace).
fn node(m: &Model, uri: &str, id: u32) -> NodeIx {
    let hits = m.find(&format!("nsu={uri};i={id}"));
    assert_eq!(hits.len(), 1, "no node i={id} in {uri}");
    hits[0]
}

/// The type with this BrowseName in a namespace.
fn ty(m: &Model, uri: &str, name: &str) -> NodeIx {
    let hits: Vec<NodeIx> =
        m.find(&format!("{uri}#{name}")).into_iter().filter(|&ix| m.node(ix).class.is_type()).collect();
    assert_eq!(hits.len(), 1, "expected one type `{name}` in {uri}, found {}", hits.len());
    hits[0]
}

fn name(m: &Model, ix: NodeIx) -> &str {
    &m.node(ix).browse_name.name
}

fn member(m: &Model, t: NodeIx, browse_name: &str) -> Member {
    m.members[&t]
        .iter()
        .find(|x| x.browse_name.name == browse_name)
        .unwrap_or_else(|| panic!("{} has no member {browse_name}", name(m, t)))
        .clone()
}

fn member_names(m: &Model, t: NodeIx) -> Vec<String> {
    m.members[&t].iter().map(|x| x.browse_name.name.clone()).collect()
}

fn data_type(m: &Model, t: NodeIx) -> &DataTypeInfo {
    m.data_types.get(&t).unwrap_or_else(|| panic!("{} is not classified as a DataType", name(m, t)))
}

fn struct_of(m: &Model, t: NodeIx) -> (StructureKind, &[Field]) {
    match &data_type(m, t).kind {
        DataTypeKind::Structure { kind, fields, has_definition: true } => (*kind, fields),
        other => panic!("{} should be a structure with a definition, is {other:?}", name(m, t)),
    }
}

/// `(field name, DataType BrowseName)` of every field, inherited ones first.
fn field_types<'a>(m: &'a Model, fields: &'a [Field]) -> Vec<(&'a str, &'a str)> {
    fields.iter().map(|f| (&*f.name, name(m, f.data_type))).collect()
}

fn enum_values(m: &Model, t: NodeIx) -> Vec<(String, i64)> {
    match &data_type(m, t).kind {
        DataTypeKind::Enumeration { values, source: EnumSource::Definition } => {
            values.iter().map(|v| (v.name.clone(), v.value)).collect()
        }
        other => panic!("{} should be an enumeration from its definition, is {other:?}", name(m, t)),
    }
}

/// The encoding objects of a DataType by BrowseName, sorted.
fn encoding_names(m: &Model, t: NodeIx) -> Vec<String> {
    let mut v: Vec<String> = data_type(m, t).encodings.iter().map(|(n, _)| n.clone()).collect();
    v.sort();
    v
}

fn value(m: &Model, ix: NodeIx) -> Variant {
    match m.value(ix) {
        Some(Ok(v)) => v,
        other => panic!("{} should have a decodable value, has {other:?}", name(m, ix)),
    }
}

fn texts(v: &Variant) -> Vec<String> {
    match v {
        Variant::Array(BuiltinType::LocalizedText, items) => items
            .iter()
            .map(|i| match i {
                Variant::LocalizedText(t) => t.text.clone(),
                other => panic!("not a LocalizedText: {other:?}"),
            })
            .collect(),
        other => panic!("not a LocalizedText array: {other:?}"),
    }
}

/// The child of `ix` with this BrowseName.
fn child(m: &Model, ix: NodeIx, browse_name: &str) -> NodeIx {
    m.children(ix)
        .map(|(_, c)| c)
        .find(|&c| name(m, c) == browse_name)
        .unwrap_or_else(|| panic!("{} has no child {browse_name}", name(m, ix)))
}

/// The model dump restricted to the fixture's own namespaces: the `namespace` and `model` header lines, and every
/// node block (a NodeId at column 0 and its indented lines) whose NodeId is outside namespace 0.
fn own_dump(m: &Model) -> String {
    let mut out = String::new();
    let mut keep = false;
    for line in summary::dump(m).lines() {
        if !line.starts_with(' ') {
            keep = line.starts_with("namespace ") || line.starts_with("model ") || line.starts_with("ns=");
        }
        if keep {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

fn snapshot(case: &str, m: &Model) {
    insta::with_settings!({
        description => format!("summary::dump of tests/fixtures/{case}/, own namespaces only"),
        omit_expression => true,
    }, {
        insta::assert_snapshot!(case, own_dump(m));
    });
}

#[test]
fn structure() {
    let out = compile_fixture("structure");
    let m = &out.model;
    let u = uri("structure");
    let position = ty(m, &u, "Position");
    let record = ty(m, &u, "MeasurementRecord");
    let calibrated = ty(m, &u, "CalibratedMeasurementRecord");

    let (kind, fields) = struct_of(m, record);
    assert_eq!(kind, StructureKind::Structure);
    assert_eq!(
        field_types(m, fields),
        [
            ("Valid", "Boolean"),
            ("Count", "Int32"),
            ("Value", "Double"),
            ("Label", "String"),
            ("Title", "LocalizedText"),
            ("Source", "NodeId"),
            ("Timestamp", "DateTime"),
            ("Location", "Position"),
        ]
    );
    assert_eq!(fields[7].data_type, position, "the nested field has this model's Position, not another");
    assert!(fields.iter().all(|f| f.value_rank == -1 && !f.is_optional && f.declared_in == record));
    assert_eq!(data_type(m, record).encoding, BuiltinType::ExtensionObject);
    assert_eq!(encoding_names(m, record), ["Default Binary", "Default JSON", "Default XML"]);
    assert_eq!(struct_of(m, position).1[0].description.as_deref(), Some("Distance from the left edge in millimetres."));

    // The subtype's definition lists only its own fields; the model has the inherited ones first.
    assert_eq!(m.node(calibrated).super_type, Some(record));
    let (kind, fields) = struct_of(m, calibrated);
    assert_eq!(kind, StructureKind::Structure);
    let names: Vec<&str> = fields.iter().map(|f| &*f.name).collect();
    assert_eq!(
        names,
        ["Valid", "Count", "Value", "Label", "Title", "Source", "Timestamp", "Location", "CalibrationDate", "Offset"]
    );
    assert!(fields[..8].iter().all(|f| f.declared_in == record));
    assert!(fields[8..].iter().all(|f| f.declared_in == calibrated));
    assert_eq!(encoding_names(m, calibrated), ["Default Binary", "Default JSON", "Default XML"]);
    snapshot("structure", m);
}

#[test]
fn optional_fields() {
    let out = compile_fixture("optional_fields");
    let m = &out.model;
    let t = ty(m, &uri("optional_fields"), "ToolData");
    let (kind, fields) = struct_of(m, t);
    assert_eq!(kind, StructureKind::StructureWithOptionalFields);
    let shape: Vec<(&str, &str, bool)> =
        fields.iter().map(|f| (&*f.name, name(m, f.data_type), f.is_optional)).collect();
    assert_eq!(
        shape,
        [
            ("Identifier", "String", false),
            ("Description", "LocalizedText", true),
            ("ToolNumber", "UInt32", false),
            ("Diameter", "Double", true),
            ("Length", "Double", false),
        ]
    );
    assert!(m.is_subtype_of_ns0(t, ids::STRUCTURE) && !m.is_subtype_of_ns0(t, ids::UNION));
    assert_eq!(data_type(m, t).encoding, BuiltinType::ExtensionObject);
    snapshot("optional_fields", m);
}

#[test]
fn union() {
    let out = compile_fixture("union");
    let m = &out.model;
    let t = ty(m, &uri("union"), "SetpointValue");
    assert!(matches!(data_type(m, t).kind, DataTypeKind::Structure { kind: StructureKind::Union, .. }));
    assert_eq!(m.node(t).super_type, m.ns0(ids::UNION));
    let (_, fields) = struct_of(m, t);
    // The field types are written as aliases (`Double`) in this fixture.
    assert_eq!(field_types(m, fields), [("Analog", "Double"), ("Named", "String"), ("Steps", "UInt32")]);
    assert!(fields.iter().all(|f| !f.is_optional && f.value_rank == -1));
    assert_eq!(data_type(m, t).encoding, BuiltinType::ExtensionObject);
    assert_eq!(encoding_names(m, t), ["Default Binary", "Default JSON", "Default XML"]);
    snapshot("union", m);
}

#[test]
fn enum_gaps() {
    let out = compile_fixture("enum_gaps");
    let m = &out.model;
    let u = uri("enum_gaps");
    let severity = ty(m, &u, "AlarmSeverityLevel");
    let expected: Vec<(String, i64)> = [("Unknown", -1), ("Low", 1), ("Medium", 2), ("High", 5), ("Critical", 10)]
        .map(|(n, v)| (n.to_string(), v))
        .into();
    assert_eq!(enum_values(m, severity), expected);
    assert_eq!(data_type(m, severity).encoding, BuiltinType::Int32);
    assert!(data_type(m, severity).encodings.is_empty(), "enumerations have no encoding objects");
    match &data_type(m, severity).kind {
        DataTypeKind::Enumeration { values, .. } => {
            assert_eq!(values[0].description.as_deref(), Some("The device did not report a level."))
        }
        _ => unreachable!(),
    }
    // The EnumValues property says the same as the definition.
    let ev = child(m, severity, "EnumValues");
    assert_eq!(m.node(ev).attrs.data_type, m.ns0(ids::ENUM_VALUE_TYPE));
    let Variant::Array(BuiltinType::ExtensionObject, items) = value(m, ev) else {
        panic!("EnumValues is not an array")
    };
    let from_property: Vec<(String, i64)> = items
        .iter()
        .map(|it| {
            let Variant::ExtensionObject(eo) = it else { panic!("{it:?}") };
            assert_eq!(eo.type_id.as_ref().and_then(|t| t.ns0()), Some(7616), "EnumValueType's Default XML encoding");
            // Decoded against EnumValueType's definition: typed fields, no XML.
            let s = eo.structure().expect("an EnumValueType structure");
            assert_eq!(m.lookup(&s.data_type), m.ns0(ids::ENUM_VALUE_TYPE));
            assert_eq!(s.field("Value").map(|v| v.builtin()), Some(Some(BuiltinType::Int64)));
            (s.text("DisplayName").expect("DisplayName").to_string(), s.field("Value").and_then(Variant::as_i64).expect("Value"))
        })
        .collect();
    assert_eq!(from_property, expected);

    let mode = ty(m, &u, "OperatingMode");
    assert_eq!(
        enum_values(m, mode),
        [("Manual".to_string(), 0), ("Automatic".to_string(), 1), ("Maintenance".to_string(), 2)]
    );
    assert_eq!(texts(&value(m, child(m, mode, "EnumStrings"))), ["Manual", "Automatic", "Maintenance"]);
    snapshot("enum_gaps", m);
}

#[test]
fn option_set() {
    let out = compile_fixture("option_set");
    let m = &out.model;
    let u = uri("option_set");
    for (t, want_base, want_bits, want_values) in [
        (
            "AxisStatusFlags",
            BuiltinType::UInt16,
            vec![("Enabled", 0), ("Homed", 1), ("Moving", 2), ("Fault", 4)],
            vec!["Enabled", "Homed", "Moving", "Reserved", "Fault"],
        ),
        (
            "SignalLampColors",
            BuiltinType::Byte,
            vec![("Red", 0), ("Yellow", 1), ("Green", 2), ("Blue", 3)],
            vec!["Red", "Yellow", "Green", "Blue"],
        ),
    ] {
        let ix = ty(m, &u, t);
        let info = data_type(m, ix);
        let DataTypeKind::OptionSet { base, bits } = &info.kind else {
            panic!("{t} should be an OptionSet, is {:?}", info.kind)
        };
        assert_eq!(*base, want_base, "{t}");
        let bits: Vec<(&str, i64)> = bits.iter().map(|b| (b.name.as_str(), b.value)).collect();
        assert_eq!(bits, want_bits, "{t}");
        assert_eq!(info.encoding, want_base, "{t} is encoded as its base integer");
        assert_eq!(m.node(ix).super_type, m.ns0(want_base.id()), "{t}");
        assert_eq!(texts(&value(m, child(m, ix, "OptionSetValues"))), want_values, "{t}");
    }
    snapshot("option_set", m);
}

#[test]
fn abstract_base() {
    let out = compile_fixture("abstract_base");
    let m = &out.model;
    let u = uri("abstract_base");
    let shape = ty(m, &u, "Shape");
    assert!(data_type(m, shape).is_abstract && m.node(shape).is_abstract());
    assert_eq!(field_types(m, struct_of(m, shape).1), [("Name", "String")]);
    for (t, own) in [("Circle", vec!["Name", "Radius"]), ("Rectangle", vec!["Name", "Width", "Height"])] {
        let ix = ty(m, &u, t);
        assert!(!data_type(m, ix).is_abstract, "{t}");
        assert_eq!(m.node(ix).super_type, Some(shape), "{t}");
        let (kind, fields) = struct_of(m, ix);
        assert_eq!(kind, StructureKind::Structure, "{t}");
        assert_eq!(fields.iter().map(|f| &*f.name).collect::<Vec<_>>(), own, "{t}");
        assert_eq!(fields[0].declared_in, shape, "{t} inherits Name from Shape");
    }
    let plan = ty(m, &u, "CuttingPlan");
    let (_, fields) = struct_of(m, plan);
    let shape_fields: Vec<(&str, NodeIx, i32, &[u32], bool)> = fields
        .iter()
        .map(|f| (&*f.name, f.data_type, f.value_rank, f.array_dimensions.as_slice(), f.allow_sub_types))
        .collect();
    assert_eq!(shape_fields[1..], [("Outline", shape, -1, &[][..], true), ("Holes", shape, 1, &[0][..], true)]);
    assert!(!shape_fields[0].4, "Title does not allow subtypes");

    let cutter = ty(m, &u, "CutterType");
    let laser = ty(m, &u, "LaserCutterType");
    assert_eq!(m.node(cutter).class, NodeClass::ObjectType);
    assert!(m.node(cutter).is_abstract() && !m.node(laser).is_abstract());
    assert_eq!(m.node(laser).super_type, Some(cutter));
    assert_eq!(member_names(m, laser), ["SerialNumber", "CurrentPlan", "LaserPower"]);
    assert_eq!(member(m, laser, "SerialNumber").declared_in, cutter);
    assert_eq!(member(m, laser, "LaserPower").declared_in, laser);
    assert_eq!(m.node(member(m, laser, "CurrentPlan").node).attrs.data_type, Some(plan));
    snapshot("abstract_base", m);
}

#[test]
fn arrays() {
    let out = compile_fixture("arrays");
    let m = &out.model;
    let u = uri("arrays");
    let sample = ty(m, &u, "Sample");
    let (_, fields) = struct_of(m, ty(m, &u, "SampleSet"));
    let shape: Vec<(&str, &str, i32, &[u32])> = fields
        .iter()
        .map(|f| (&*f.name, name(m, f.data_type), f.value_rank, f.array_dimensions.as_slice()))
        .collect();
    assert_eq!(
        shape,
        [
            ("Gains", "Double", 1, &[3][..]),
            ("Calibration", "Double", 2, &[2, 3][..]),
            ("Tags", "String", 1, &[][..]),
            ("Samples", "Sample", 1, &[][..]),
        ]
    );
    assert_eq!(fields[3].data_type, sample, "an array of this model's structure");

    let t = ty(m, &u, "SensorArrayType");
    let readings = member(m, t, "Readings").node;
    assert_eq!(
        (m.node(readings).attrs.value_rank, m.node(readings).attrs.array_dimensions.as_slice()),
        (Some(1), &[3][..])
    );
    assert_eq!(
        value(m, readings),
        Variant::Array(BuiltinType::Double, vec![Variant::Double(1.5), Variant::Double(2.5), Variant::Double(-3.25)])
    );
    let calibration = member(m, t, "Calibration").node;
    assert_eq!(
        (m.node(calibration).attrs.value_rank, m.node(calibration).attrs.array_dimensions.as_slice()),
        (Some(2), &[2, 3][..])
    );
    assert!(m.value_xml(calibration).is_none());
    let names = member(m, t, "ChannelNames").node;
    assert_eq!(
        value(m, names),
        Variant::Array(BuiltinType::String, ["X", "Y", "Z"].map(|s| Variant::String(s.into())).to_vec())
    );
    let history = m.node(member(m, t, "History").node);
    assert_eq!((history.attrs.data_type, history.attrs.value_rank), (Some(sample), Some(1)));
    snapshot("arrays", m);
}

#[test]
fn names() {
    let out = compile_fixture("names");
    let m = &out.model;
    let u = uri("names");
    // BrowseNames are kept exactly as written; ns0 has its own 3DFrame and 3DFrameType, which are other nodes.
    let frame = ty(m, &u, "3DFrame");
    assert_eq!(m.node(frame).symbolic_name.as_deref(), Some("ThreeDFrame"));
    assert!(m.find("3DFrame").iter().any(|&x| m.node(x).id.ns == 0), "ns0 defines a 3DFrame too");
    let (_, fields) = struct_of(m, frame);
    assert_eq!(
        fields.iter().map(|f| &*f.name).collect::<Vec<_>>(),
        ["_x", "x_", "match", "Type", "Real", "input"]
    );

    let mode = ty(m, &u, "RunMode");
    assert_eq!(
        enum_values(m, mode),
        [("None".to_string(), 0), ("Override".to_string(), 1), ("Automatic".to_string(), 2)]
    );

    let t = ty(m, &u, "3DFrameType");
    assert_eq!(m.node(t).class, NodeClass::ObjectType);
    assert_eq!(
        member_names(m, t),
        [
            "Type",
            "Match",
            "Self",
            "self",
            "Mode-A",
            "ModeA",
            "Precise+",
            "IOs",
            "input",
            "Model",
            "Frame",
            "In/Out\\Level",
            "UR Robot",
            "<AxisIdentifier>"
        ]
    );
    // Names that collide once sanitized are distinct nodes here, and neither is reported.
    assert_ne!(member(m, t, "Self").node, member(m, t, "self").node);
    assert_ne!(member(m, t, "Mode-A").node, member(m, t, "ModeA").node);
    for (bn, symbolic) in
        [("Mode-A", Some("Mode_A")), ("ModeA", None), ("Precise+", Some("Precise")), ("UR Robot", Some("UR_Robot"))]
    {
        assert_eq!(m.node(member(m, t, bn).node).symbolic_name.as_deref(), symbolic, "{bn}");
    }
    let axis = m.node(member(m, t, "<AxisIdentifier>").node);
    assert_eq!(axis.modelling_rule, Some(ModellingRule::OptionalPlaceholder));
    assert_eq!(axis.display(), "<AxisIdentifier>");
    assert_eq!(m.node(member(m, t, "Mode-A").node).attrs.data_type, Some(mode));
    assert_eq!(m.node(member(m, t, "Frame").node).attrs.data_type, Some(frame));
    snapshot("names", m);
}

#[test]
fn method() {
    let out = compile_fixture("method");
    let m = &out.model;
    let u = uri("method");
    let params = ty(m, &u, "JobParameters");
    let t = ty(m, &u, "JobControllerType");
    let start = member(m, t, "StartJob").node;
    let reset = member(m, t, "Reset").node;
    assert_eq!(m.node(start).class, NodeClass::Method);
    assert_eq!(m.node(start).modelling_rule, Some(ModellingRule::Mandatory));
    assert_eq!(m.node(reset).modelling_rule, Some(ModellingRule::Optional));

    let args = |a: &[Argument]| -> Vec<(String, String, i32, Vec<u32>)> {
        a.iter()
            .map(|x| {
                (
                    x.name.clone(),
                    x.data_type.map(|d| name(m, d).to_string()).unwrap_or_default(),
                    x.value_rank,
                    x.array_dimensions.clone(),
                )
            })
            .collect()
    };
    let info = &m.methods[&start];
    assert_eq!(
        args(&info.inputs),
        [
            ("Setpoints".to_string(), "Double".to_string(), 1, vec![0]),
            ("Parameters".to_string(), "JobParameters".to_string(), -1, vec![]),
            ("Comment".to_string(), "String".to_string(), -1, vec![]),
        ]
    );
    assert_eq!(info.inputs[1].data_type, Some(params));
    assert_eq!(info.inputs[0].description.as_deref(), Some("One setpoint per station, in the order of the line."));
    assert_eq!(
        args(&info.outputs),
        [
            ("JobId".to_string(), "Int32".to_string(), -1, vec![]),
            ("Result".to_string(), "StatusCode".to_string(), -1, vec![])
        ]
    );
    let none = &m.methods[&reset];
    assert!(none.inputs.is_empty() && none.outputs.is_empty());

    // The instance has its own method nodes, declared by the type's.
    let obj = node(m, &u, 5001);
    assert_eq!(m.node(obj).type_definition, Some(t));
    let members = m.instance_members(obj);
    for (bn, decl) in [("StartJob", start), ("Reset", reset)] {
        let x = members.iter().find(|x| x.browse_name.name == bn).unwrap_or_else(|| panic!("instance has no {bn}"));
        assert_ne!(x.node, decl, "{bn} is the instance's own method node");
        assert_eq!(x.overrides, Some(decl), "{bn}");
        assert_eq!(m.node(x.node).attrs.method_declaration, Some(decl), "{bn}");
        assert_eq!(args(&m.methods[&x.node].inputs), args(&m.methods[&decl].inputs), "{bn}");
        assert_eq!(args(&m.methods[&x.node].outputs), args(&m.methods[&decl].outputs), "{bn}");
    }
    snapshot("method", m);
}

#[test]
fn event_type() {
    let out = compile_fixture("event_type");
    let m = &out.model;
    let u = uri("event_type");
    let event = ty(m, &u, "ToolWearEventType");
    assert_eq!(m.node(event).super_type, m.ns0(ids::BASE_EVENT_TYPE));
    let base = m.ns0(ids::BASE_EVENT_TYPE).unwrap();
    for inherited in ["EventId", "EventType", "SourceNode", "Time", "Message", "Severity"] {
        assert_eq!(member(m, event, inherited).declared_in, base, "{inherited}");
    }
    for own in ["ToolIdentifier", "WearLevel"] {
        let x = member(m, event, own);
        assert_eq!(x.declared_in, event, "{own}");
        assert_eq!(x.reference_type, m.ns0(ids::HAS_PROPERTY).unwrap(), "{own}");
        assert_eq!(m.node(x.node).type_definition, m.ns0(ids::PROPERTY_TYPE), "{own}");
        assert_eq!(m.node(x.node).modelling_rule, Some(ModellingRule::Mandatory), "{own}");
    }

    let monitor = ty(m, &u, "ToolMonitorType");
    let generates = m.ns0(41).expect("GeneratesEvent");
    let targets: Vec<NodeIx> = m
        .node(monitor)
        .references
        .iter()
        .filter(|r| r.forward && r.reference_type == generates)
        .map(|r| r.target)
        .collect();
    assert_eq!(targets, [event]);
    assert!(!m.is_hierarchical(generates));
    assert_eq!(member_names(m, monitor), ["WarningThreshold"], "GeneratesEvent adds no member");
    snapshot("event_type", m);
}

#[test]
fn two_namespaces() {
    let out = compile_fixture("two_namespaces");
    let m = &out.model;
    let a = uri("two_namespaces/base");
    let b = uri("two_namespaces");
    let uris: Vec<&str> = m.namespaces.iter().map(String::as_str).collect();
    assert_eq!(uris, ["http://opcfoundation.org/UA/", a.as_str(), b.as_str()], "the required model comes first");
    let model_b = m.models.iter().find(|x| x.uri == b).expect("model B");
    let req: Vec<(&str, Option<&str>)> =
        model_b.required.iter().map(|r| (r.uri.as_str(), r.version.as_deref())).collect();
    assert!(req.contains(&(a.as_str(), Some("1.0.0"))), "{req:?}");

    let device = ty(m, &a, "DeviceType");
    let range = ty(m, &a, "Range");
    let sensor = ty(m, &b, "PressureSensorType");
    assert_eq!(m.node(sensor).super_type, Some(device));
    assert_eq!(member_names(m, sensor), ["SerialNumber", "MeasuringRange", "Status", "LastCalibration"]);

    // B redeclares A's MeasuringRange (BrowseName 2:MeasuringRange in B's file) and makes it Mandatory.
    let over = member(m, sensor, "MeasuringRange");
    let a_decl = node(m, &a, 6002);
    assert_eq!(m.namespace_uri(over.browse_name.ns), a, "the override keeps A's BrowseName");
    assert_eq!(over.node, node(m, &b, 6001));
    assert_eq!(over.overrides, Some(a_decl));
    assert_eq!(over.declared_in, sensor);
    assert_eq!(m.node(a_decl).modelling_rule, Some(ModellingRule::Optional));
    assert_eq!(m.node(over.node).modelling_rule, Some(ModellingRule::Mandatory));
    assert_eq!(m.node(over.node).attrs.data_type, Some(range));
    assert_eq!(member(m, sensor, "SerialNumber").declared_in, device);
    assert_eq!(member(m, sensor, "Status").overrides, None);

    // A structure of B with a field of A's structure.
    let record = ty(m, &b, "CalibrationRecord");
    let (_, fields) = struct_of(m, record);
    assert_eq!(field_types(m, fields), [("CalibratedRange", "Range"), ("CalibratedAt", "DateTime")]);
    assert_eq!(fields[0].data_type, range);
    assert_eq!(m.namespace_uri(m.node(fields[0].data_type).id.ns), a);
    assert_eq!(m.node(member(m, sensor, "LastCalibration").node).attrs.data_type, Some(record));

    // The same model whatever the order the files are named in, and when A is found in the models folder.
    let dump = own_dump(m);
    let reversed = compile_files("two_namespaces", |mut files| {
        files.reverse();
        files
    });
    assert_eq!(own_dump(&reversed.model), dump, "input order changed the model");
    let only_b = compile_files("two_namespaces", |files| {
        files.into_iter().filter(|f| f.file_name().is_some_and(|n| n == "Example.TwoNamespaces.NodeSet2.xml")).collect()
    });
    assert_eq!(only_b.model.sources.files().filter(|(_, f)| f.named).count(), 1);
    assert_eq!(own_dump(&only_b.model), dump, "loading A as a dependency changed the model");
    snapshot("two_namespaces", m);
}

#[test]
fn state_machine() {
    let out = compile_fixture("state_machine");
    let m = &out.model;
    let u = uri("state_machine");
    let feeder = ty(m, &u, "FeederStateMachineType");
    assert_eq!(m.node(feeder).super_type, m.ns0(ids::FINITE_STATE_MACHINE_TYPE));
    let sm = m.state_machines.get(&feeder).expect("FeederStateMachineType is a state machine");
    let states: Vec<(&str, Option<u32>, bool)> =
        sm.states.iter().map(|s| (s.name.as_str(), s.number, s.initial)).collect();
    assert_eq!(states, [("Idle", Some(1), true), ("Feeding", Some(2), false), ("Stopped", Some(3), false)]);
    let state = |n: &str| sm.states.iter().find(|s| s.name == n).unwrap().node;
    // (name, TransitionNumber, FromState, ToState, HasCause targets, HasEffect targets)
    type Row<'a> = (&'a str, Option<u32>, Option<NodeIx>, Option<NodeIx>, Vec<&'a str>, Vec<NodeIx>);
    let transitions: Vec<Row> = sm
        .transitions
        .iter()
        .map(|t| {
            (t.name.as_str(), t.number, t.from, t.to, t.causes.iter().map(|&c| name(m, c)).collect(), t.effects.clone())
        })
        .collect();
    let effect = m.ns0(2311).expect("TransitionEventType");
    assert_eq!(
        transitions,
        [
            ("IdleToFeeding", Some(12), Some(state("Idle")), Some(state("Feeding")), vec!["Start"], vec![effect]),
            ("FeedingToStopped", Some(23), Some(state("Feeding")), Some(state("Stopped")), vec!["Stop"], vec![effect]),
        ]
    );
    for t in &sm.transitions {
        for &c in &t.causes {
            assert_eq!(m.node(c).class, NodeClass::Method);
            assert_eq!(member(m, feeder, name(m, c)).node, c, "the cause is the machine's own method");
        }
    }

    let program = ty(m, &u, "DosingProgramType");
    assert_eq!(m.node(program).super_type, m.ns0(ids::PROGRAM_STATE_MACHINE_TYPE));
    let params = member(m, program, "DosingParameters");
    assert_eq!(params.declared_in, program);
    assert_eq!(m.node(params.node).modelling_rule, Some(ModellingRule::Mandatory));
    let vars: Vec<(String, Option<NodeIx>)> = m
        .instance_members(params.node)
        .iter()
        .map(|x| (x.browse_name.name.clone(), m.node(x.node).attrs.data_type))
        .collect();
    let double = m.ns0(11);
    assert_eq!(vars, [("TargetVolume".to_string(), double), ("FlowRate".to_string(), double)]);
    // The program inherits the states of ProgramStateMachineType.
    let mut inherited: Vec<&str> = m
        .state_machines
        .get(&program)
        .expect("DosingProgramType is a state machine")
        .states
        .iter()
        .map(|s| s.name.as_str())
        .collect();
    inherited.sort();
    assert_eq!(inherited, ["Halted", "Ready", "Running", "Suspended"]);
    snapshot("state_machine", m);
}

#[test]
fn instances() {
    let out = compile_fixture("instances");
    let m = &out.model;
    let u = uri("instances");
    let pump_t = ty(m, &u, "PumpType");
    let valve_t = ty(m, &u, "ValveType");
    let rules: Vec<(String, Option<ModellingRule>)> =
        m.members[&pump_t].iter().map(|x| (x.browse_name.name.clone(), m.node(x.node).modelling_rule)).collect();
    assert_eq!(
        rules,
        [
            ("Manufacturer".to_string(), Some(ModellingRule::Mandatory)),
            ("Speed".to_string(), Some(ModellingRule::Mandatory)),
            ("Temperature".to_string(), Some(ModellingRule::Optional)),
            ("<ValveIdentifier>".to_string(), Some(ModellingRule::MandatoryPlaceholder)),
        ]
    );
    let placeholder = member(m, pump_t, "<ValveIdentifier>").node;
    assert_eq!(m.node(placeholder).type_definition, Some(valve_t));

    let pump = node(m, &u, 5010);
    assert_eq!(name(m, pump), "Pump1");
    assert_eq!(m.node(pump).type_definition, Some(pump_t));
    assert_eq!(m.node(pump).parent, m.ns0(85), "Pump1 is in the ObjectsFolder");
    assert!(m.node(pump).modelling_rule.is_none());
    let members = m.instance_members(pump);
    let shape: Vec<(&str, NodeIx, Option<NodeIx>)> =
        members.iter().map(|x| (x.browse_name.name.as_str(), x.node, x.overrides)).collect();
    assert_eq!(
        shape,
        [
            ("Manufacturer", node(m, &u, 6010), Some(node(m, &u, 6001))),
            ("Speed", node(m, &u, 6011), Some(node(m, &u, 6002))),
            ("Temperature", node(m, &u, 6003), None),
            ("<ValveIdentifier>", placeholder, None),
            ("InletValve", node(m, &u, 5011), None),
            ("OutletValve", node(m, &u, 5012), None),
        ],
        "the optional Temperature and the placeholder stay declarations; the valves are the instance's own"
    );
    assert_eq!(m.children(pump).count(), 4);
    for (valve, position) in [("InletValve", 12.5), ("OutletValve", 80.0)] {
        let v = child(m, pump, valve);
        assert_eq!(
            m.node(v).type_definition,
            m.node(placeholder).type_definition,
            "{valve} instantiates the placeholder"
        );
        assert_eq!(m.node(v).parent, Some(pump), "{valve}");
        assert_eq!(value(m, child(m, v, "Position")), Variant::Double(position), "{valve}");
    }
    assert_eq!(value(m, child(m, pump, "Manufacturer")), Variant::String("ACME Pumps".into()));
    assert_eq!(value(m, child(m, pump, "Speed")), Variant::Double(1450.0));
    snapshot("instances", m);
}

#[test]
fn variable_type() {
    let out = compile_fixture("variable_type");
    let m = &out.model;
    let u = uri("variable_type");
    let spectrum = ty(m, &u, "SpectrumType");
    let n = m.node(spectrum);
    assert_eq!(n.class, NodeClass::VariableType);
    assert_eq!(n.super_type, m.ns0(ids::BASE_DATA_VARIABLE_TYPE));
    assert_eq!((n.attrs.data_type, n.attrs.value_rank), (m.ns0(11), Some(1)));
    let resolution = member(m, spectrum, "Resolution");
    assert_eq!(m.node(resolution.node).type_definition, m.ns0(ids::PROPERTY_TYPE));
    assert_eq!(m.node(resolution.node).modelling_rule, Some(ModellingRule::Mandatory));

    // An instance declaration of the VariableType, with its own Resolution.
    let analyzer = ty(m, &u, "AnalyzerType");
    let raw = member(m, analyzer, "RawSpectrum").node;
    assert_eq!(m.node(raw).type_definition, Some(spectrum));
    let inner = m.instance_members(raw);
    assert_eq!(inner.len(), 1);
    assert_eq!((inner[0].node, inner[0].overrides), (node(m, &u, 6003), Some(resolution.node)));

    // A variable of the VariableType in the ObjectsFolder, with values.
    let reference = node(m, &u, 6010);
    assert_eq!(m.node(reference).class, NodeClass::Variable);
    assert_eq!(m.node(reference).type_definition, Some(spectrum));
    assert_eq!(m.node(reference).parent, m.ns0(85));
    assert_eq!(
        value(m, reference),
        Variant::Array(BuiltinType::Double, [0.1, 0.4, 0.9, 0.3].map(Variant::Double).to_vec())
    );
    assert_eq!(value(m, child(m, reference, "Resolution")), Variant::Double(0.5));
    snapshot("variable_type", m);
}
