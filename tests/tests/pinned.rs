//! The companion specifications of the pinned registry package: ns0 1.05.07, DI 1.05.0, IA 1.01.4 and
//! Robotics 1.02 resolve together, and MotionDeviceSystemType's instance declarations span all four.

use nodeset_compiler::load::Input;
use nodeset_compiler::model::{ModellingRule, Model, NodeIx};
use nodeset_compiler::raw::NodeClass;
use nodeset_compiler::{compile, summary, Compiled, Options};
use nodeset_tests::vendor;

const FILES: [&str; 4] =
    ["Opc.Ua.NodeSet2.xml", "Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.IA.NodeSet2.xml", "Opc.Ua.Robotics.NodeSet2.xml"];
const ROBOTICS: &str = "http://opcfoundation.org/UA/Robotics/";

fn robotics(order: &[&str], all_warnings: bool) -> Compiled {
    let dir = vendor();
    let inputs = order.iter().map(|f| Input::Path(dir.join(f))).collect();
    compile(inputs, &Options { all_warnings, ..Options::default() })
}

fn member(model: &Model, t: NodeIx, name: &str) -> NodeIx {
    model.members[&t]
        .iter()
        .find(|m| m.browse_name.name == name)
        .unwrap_or_else(|| panic!("{} has no member {name}", model.node(t).browse_name.name))
        .node
}

#[test]
fn four_companion_specs_resolve_with_zero_errors() {
    let out = robotics(&FILES, true);
    assert!(out.ok(), "{}", out.render_diagnostics());
    let m = &out.model;
    let uris: Vec<&str> = m.namespaces.iter().map(String::as_str).collect();
    assert_eq!(
        uris,
        ["http://opcfoundation.org/UA/", "http://opcfoundation.org/UA/DI/", "http://opcfoundation.org/UA/IA/", ROBOTICS]
    );
    let versions: Vec<(&str, &str)> =
        m.models.iter().map(|x| (x.uri.as_str(), x.version.as_deref().unwrap_or(""))).collect();
    assert!(versions.contains(&("http://opcfoundation.org/UA/", "1.05.07")), "{versions:?}");
    assert!(versions.contains(&(ROBOTICS, "1.02")), "{versions:?}");
    println!("{}", summary::render(m));
}

#[test]
fn motion_device_system_type_members_resolve_across_namespaces() {
    let out = robotics(&FILES, false);
    let m = &out.model;
    let t = m.find(&format!("{ROBOTICS}#MotionDeviceSystemType"))[0];
    assert_eq!(m.node(t).class, NodeClass::ObjectType);
    // The supertype chain crosses into DI and ns0.
    let chain: Vec<String> = m.super_chain(t).iter().map(|&c| m.qualified(c)).collect();
    assert_eq!(chain, ["Robotics:MotionDeviceSystemType", "DI:ComponentType", "DI:TopologyElementType", "BaseObjectType"]);

    for (folder, placeholder, ty) in [
        ("MotionDevices", "<MotionDeviceIdentifier>", "MotionDeviceType"),
        ("Controllers", "<ControllerIdentifier>", "ControllerType"),
        ("SafetyStates", "<SafetyStateIdentifier>", "SafetyStateType"),
    ] {
        let f = member(m, t, folder);
        assert_eq!(m.node(f).modelling_rule, Some(ModellingRule::Mandatory), "{folder}");
        assert_eq!(m.node(m.node(f).type_definition.unwrap()).browse_name.name, "FolderType");
        let inner = m.instance_members(f);
        let p = inner.iter().find(|x| x.browse_name.name == placeholder).unwrap_or_else(|| panic!("{folder}/{placeholder}"));
        let pn = m.node(p.node);
        assert_eq!(pn.modelling_rule, Some(ModellingRule::MandatoryPlaceholder), "{folder}/{placeholder}");
        let td = pn.type_definition.unwrap();
        assert_eq!(m.node(td).browse_name.name, ty);
        assert_eq!(m.namespace_uri(m.node(td).id.ns), ROBOTICS);
    }
    // Inherited DI members of a motion device: ComponentType's Manufacturer, made Mandatory by Robotics.
    let device = m.instance_members(member(m, t, "MotionDevices"))[0].node;
    let manufacturer = m.instance_members(device).into_iter().find(|x| x.browse_name.name == "Manufacturer").unwrap();
    assert_eq!(m.namespace_uri(manufacturer.browse_name.ns), "http://opcfoundation.org/UA/DI/");
    assert_eq!(m.node(manufacturer.node).modelling_rule, Some(ModellingRule::Mandatory));
    assert!(manufacturer.overrides.is_some(), "Robotics overrides DI's optional Manufacturer");
    // Axes of a motion device, with their ParameterSet.ActualPosition of type Double.
    let axes = m.instance_members(device).into_iter().find(|x| x.browse_name.name == "Axes").unwrap();
    let axis = m.instance_members(axes.node).into_iter().find(|x| x.browse_name.name == "<AxisIdentifier>").unwrap();
    let params = m.instance_members(axis.node).into_iter().find(|x| x.browse_name.name == "ParameterSet").unwrap();
    let pos = m.instance_members(params.node).into_iter().find(|x| x.browse_name.name == "ActualPosition").unwrap();
    assert_eq!(m.node(m.node(pos.node).attrs.data_type.unwrap()).browse_name.name, "Double");

    insta::assert_snapshot!("motion_device_system_type", summary::show_type(m, t, 2));
}

#[test]
fn input_order_does_not_change_the_model() {
    let a = robotics(&FILES, true);
    let mut rev = FILES;
    rev.reverse();
    let b = robotics(&rev, true);
    assert!(a.ok() && b.ok());
    let (da, db) = (summary::dump(&a.model), summary::dump(&b.model));
    assert!(da.len() > 1_000_000, "the dump covers the whole model ({} bytes)", da.len());
    assert!(da == db, "the model depends on the order of the input files");
    assert_eq!(a.render_diagnostics(), b.render_diagnostics());
}

#[test]
fn required_models_are_found_in_a_models_folder() {
    // Only Robotics is named; ns0, DI and IA come from the folder (Machinery, also there, is not needed).
    let dir = vendor();
    let out = compile(
        vec![Input::Path(dir.join("Opc.Ua.Robotics.NodeSet2.xml"))],
        &Options { model_dirs: vec![dir.clone()], ..Options::default() },
    );
    assert!(out.ok(), "{}", out.render_diagnostics());
    assert_eq!(out.model.namespaces.len(), 4, "{:?}", out.model.namespaces);
    let named: Vec<bool> = out.model.sources.files().map(|(_, f)| f.named).collect();
    assert_eq!(named.iter().filter(|n| **n).count(), 1);
}
