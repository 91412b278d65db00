//! Unit tests of the planning rules, on the plans themselves: each test names a rule and checks the decision
//! planning records for it (elements, declarations, modifiers, bindings), over DI, IA and Robotics, without
//! writing any Modelica. `tests.rs` checks what rendering makes of the same decisions.

use super::plan::{ClassInfo, ClassKey, ClassPlan, ElemKind, Element, Item, Mod, Owner, Value};
use super::tests::{robotics, vendor_robot_with, VENDOR_ROBOT};
use super::{plan, ModelicaConfig, Planned};
use crate::model::{Model, NodeIx};

const ROBOTICS: &str = "http://opcfoundation.org/UA/Robotics/";
const DI: &str = "http://opcfoundation.org/UA/DI/";

fn planned(model: &Model) -> Planned<'_> {
    let cfg = ModelicaConfig::new().namespace(ROBOTICS).namespace(DI).namespace("http://opcfoundation.org/UA/IA/");
    match plan(model, &cfg) {
        Ok(p) => p,
        Err(d) => panic!("{d:?}"),
    }
}

fn object_type(m: &Model, uri: &str, name: &str) -> NodeIx {
    *m.find(&format!("{uri}#{name}")).first().unwrap_or_else(|| panic!("no {name} in {uri}"))
}

fn info<'p>(p: &'p Planned, key: &ClassKey) -> &'p ClassInfo {
    p.ctx.class_infos.get(key).map(|i| &**i).unwrap_or_else(|| panic!("{key:?} is not planned"))
}

fn main_plan<'p>(p: &'p Planned, t: NodeIx) -> &'p ClassPlan {
    p.ctx.plans[&Owner::Type(t)].main.as_ref().expect("the type has a class")
}

fn decl_plan<'p>(p: &'p Planned, t: NodeIx, path: &str) -> &'p ClassPlan {
    let decls = &p.ctx.plans[&Owner::Type(t)].decls;
    decls.iter().find(|(q, _)| q == path).map(|(_, c)| c).unwrap_or_else(|| panic!("no declaration class {path}"))
}

fn element<'i>(info: &'i ClassInfo, browse_name: &str) -> &'i Element {
    info.elements.iter().find(|e| e.bn.name == browse_name).unwrap_or_else(|| panic!("no element {browse_name}"))
}

/// The declaration of `ident` in a class: (dims, value, condition).
fn declaration<'c>(class: &'c ClassPlan, ident: &str) -> (&'c str, &'c Option<Value>, &'c Option<String>) {
    class
        .items
        .iter()
        .find_map(|item| match item {
            Item::Decl { ident: i, dims, value, cond, .. } if i == ident => Some((dims.as_str(), value, cond)),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no declaration of {ident}"))
}

#[test]
fn an_optional_member_is_declared_on_a_use_flag() {
    let out = robotics();
    let p = planned(&out.model);
    // DI's ComponentType: SerialNumber is Optional.
    let t = object_type(&out.model, DI, "ComponentType");
    let serial = element(info(&p, &ClassKey::Type(t)), "SerialNumber");
    let flag = serial.use_flag.clone().expect("an optional member has a use flag");
    assert_eq!(flag, format!("use_{}", serial.ident));
    let (_, _, cond) = declaration(main_plan(&p, t), &serial.ident);
    assert_eq!(cond.as_deref(), Some(flag.as_str()), "declared if the flag is set");
}

#[test]
fn a_subtype_that_makes_an_optional_member_mandatory_sets_its_flag_final() {
    let out = robotics();
    let p = planned(&out.model);
    // Robotics' AxisType makes ComponentType's optional ParameterSet mandatory.
    let t = object_type(&out.model, ROBOTICS, "AxisType");
    assert!(element(info(&p, &ClassKey::Type(t)), "ParameterSet").present);
    let (_, mods) = main_plan(&p, t).extends.as_ref().expect("AxisType extends its supertype");
    let set = mods.iter().find_map(|m| match m {
        Mod::Value { ident, is_final, value: Some(Value::Text(v)), .. } if ident == "use_parameterSet" => {
            Some((*is_final, v.as_str()))
        }
        _ => None,
    });
    assert_eq!(set, Some((true, "true")), "{mods:?}");
}

#[test]
fn a_published_value_is_a_free_input_that_the_complete_variant_binds_to_its_node() {
    let out = robotics();
    let p = planned(&out.model);
    // AxisType's ParameterSet publishes ActualPosition (clients read it).
    let t = object_type(&out.model, ROBOTICS, "AxisType");
    let key = ClassKey::Decl(Owner::Type(t), "ParameterSet".into());
    let position = element(info(&p, &key), "ActualPosition");
    assert!(matches!(position.kind, ElemKind::Signal { free: true, .. }), "{:?}", position.kind);
    let (_, value, _) = declaration(decl_plan(&p, t, "ParameterSet"), &position.ident);
    assert!(value.is_none(), "a free input has no value: {value:?}");
    // The type is partial by that input, which its complete variant binds to the node's value.
    let axis = info(&p, &ClassKey::Type(t));
    assert!(axis.is_partial_by_inputs());
    let free = axis.free.iter().find(|f| f.node == position.node).expect("ActualPosition is a free input of AxisType");
    assert_eq!(free.path.last().map(|(i, _)| i.as_str()), Some(position.ident.as_str()));
    assert!(matches!(free.value(), Value::Of { node, dims: None, .. } if node == position.node));
}

#[test]
fn a_placeholder_is_an_array_sized_by_a_count() {
    let out = robotics();
    let p = planned(&out.model);
    // AxisType Requires <PowerTrainIdentifier>: not containment, so NodeId strings, one per target.
    let t = object_type(&out.model, ROBOTICS, "AxisType");
    let trains = element(info(&p, &ClassKey::Type(t)), "<PowerTrainIdentifier>");
    assert!(matches!(trains.kind, ElemKind::Reference { array: true }), "{:?}", trains.kind);
    let count = trains.count.clone().expect("a placeholder has a count");
    let (dims, value, _) = declaration(main_plan(&p, t), &trains.ident);
    assert_eq!(dims, format!("[{count}]"));
    assert!(matches!(value, Some(Value::Text(v)) if *v == format!("fill(\"\", {count})")), "{value:?}");
    // MotionDeviceType's Axes hold <AxisIdentifier> objects: an array of the axis class, sized the same way.
    let t = object_type(&out.model, ROBOTICS, "MotionDeviceType");
    let key = ClassKey::Decl(Owner::Type(t), "Axes".into());
    let axes = element(info(&p, &key), "<AxisIdentifier>");
    assert!(matches!(axes.kind, ElemKind::Object { .. }), "{:?}", axes.kind);
    let count = axes.count.clone().expect("a placeholder has a count");
    let (dims, _, _) = declaration(decl_plan(&p, t, "Axes"), &axes.ident);
    assert_eq!(dims, format!("[{count}]"));
}

#[test]
fn a_declared_value_is_bound_to_the_node_that_gives_it() {
    let out = robotics();
    let p = planned(&out.model);
    let m = &out.model;
    // Every binding planning takes from the nodeset names the node of its own declaration: planning records
    // which node's value, rendering writes it.
    let mut bound = 0;
    for plans in p.ctx.plans.values() {
        for class in plans.main.iter().chain(plans.decls.iter().map(|(_, c)| c)) {
            for item in &class.items {
                if let Item::Decl { value: Some(Value::Of { node, .. }), annotation, .. } = item {
                    assert!(
                        annotation.contains(&format!("nodeId={}", super::text::string_literal(&super::ctx::node_id_text(m, &m.node(*node).id)))),
                        "{annotation}"
                    );
                    bound += 1;
                }
            }
        }
    }
    assert!(bound > 100, "only {bound} declarations take their value from the nodeset");
}

/// The `final` modifiers of `ident` in a modification list, at any depth.
fn finals(mods: &[Mod], ident: &str) -> usize {
    mods.iter()
        .map(|m| match m {
            Mod::Value { ident: i, is_final: true, .. } if i == ident => 1,
            Mod::Nested { mods, .. } => finals(mods, ident),
            _ => 0,
        })
        .sum()
}

#[test]
fn a_member_a_final_flag_made_present_higher_up_is_present_to_subtypes_at_any_depth() {
    // ArmXType makes Tuning/Limits/MaxAccel (Optional in VendorMotionDeviceType, two levels down) Mandatory, and
    // ArmYType declares it again: `final use_maxAccel = true` is written once along the chain (Modelica refuses
    // a modifier of a final element). With MaxAccel's value left as inherited, ArmXType modifies the members of
    // its Tuning component without a class of its own; with its own values, each type's Tuning has a class.
    let same = |text: &str| text.replace(">4</Double>", ">3</Double>").replace(">5</Double>", ">3</Double>");
    for (out, modifies) in [(vendor_robot_with(same), true), (vendor_robot_with(str::to_string), false)] {
        let m = &out.model;
        let cfg = VENDOR_ROBOT.iter().fold(ModelicaConfig::new(), |c, u| c.namespace(*u));
        let p = plan(m, &cfg).unwrap_or_else(|d| panic!("{d:?}"));
        let uri = VENDOR_ROBOT[2];
        let mut written = 0;
        for name in ["ArmXType", "ArmYType"] {
            let plans = &p.ctx.plans[&Owner::Type(object_type(m, uri, name))];
            for class in plans.main.iter().chain(plans.decls.iter().map(|(_, c)| c)) {
                written += class.extends.as_ref().map_or(0, |(_, mods)| finals(mods, "use_maxAccel"));
            }
        }
        assert_eq!(written, 1, "modifiers on the component: {modifies}");
        // What ArmXType's modifiers (or class) made present is recorded where a subtype looks for it.
        let t = object_type(m, uri, "ArmXType");
        let tuning = element(info(&p, &ClassKey::Type(t)), "Tuning");
        let limits = match (&tuning.modified, &tuning.kind) {
            (Some(members), _) => members.iter().find(|e| e.bn.name == "Limits").expect("Limits").clone(),
            (None, ElemKind::Object { class }) => element(info(&p, class), "Limits").clone(),
            (None, k) => panic!("{k:?}"),
        };
        assert_eq!(tuning.modified.is_some(), modifies);
        let members = limits.modified.as_deref().expect("Limits is modified without a class of its own");
        assert!(members.iter().any(|e| e.bn.name == "MaxAccel" && e.present), "{members:?}");
    }

    // The shape of the laboratory-device packages of the issue: a new component of a type's class whose
    // declaration makes an optional member Mandatory (ArmType's Controller, FirmwareLevel of ControllerInfoType),
    // declared Mandatory again by a subtype (ArmXType), with the same TypeDefinition or a subtype of it (then the
    // component gets that type's class, and ArmType's modifiers still apply to it).
    let firmware = |id: u32, parent: u32| {
        format!(
            r#"<UAVariable NodeId="ns=1;i={id}" BrowseName="5:FirmwareLevel" ParentNodeId="ns=1;i={parent}" DataType="UInt32">
    <DisplayName>FirmwareLevel</DisplayName>
    <References>
      <Reference ReferenceType="HasTypeDefinition">i=68</Reference>
      <Reference ReferenceType="HasModellingRule">i=78</Reference>
    </References>
  </UAVariable>
  "#
        )
    };
    let controller = |td: &str| {
        format!(
            r#"<UAObject NodeId="ns=1;i=5101" BrowseName="1:Controller" ParentNodeId="ns=1;i=1002">
    <DisplayName>Controller</DisplayName>
    <References>
      <Reference ReferenceType="HasTypeDefinition">{td}</Reference>
      <Reference ReferenceType="HasModellingRule">i=78</Reference>
      <Reference ReferenceType="HasProperty">ns=1;i=6102</Reference>
    </References>
  </UAObject>
  <UAObjectType NodeId="ns=1;i=1099" BrowseName="1:ControllerInfoXType">
    <DisplayName>ControllerInfoXType</DisplayName>
    <References>
      <Reference ReferenceType="HasSubtype" IsForward="false">ns=5;i=1001</Reference>
    </References>
  </UAObjectType>
  "#
        )
    };
    for (td, redeclared) in [("ns=5;i=1001", false), ("ns=1;i=1099", true)] {
        let out = vendor_robot_with(|text| {
            let type_def = r#"<Reference ReferenceType="HasTypeDefinition">ns=5;i=1001</Reference>"#;
            let firmware_ref = r#"<Reference ReferenceType="HasProperty">ns=1;i=6101</Reference>"#;
            let arm_x = r#"<Reference ReferenceType="HasComponent">ns=1;i=5010</Reference>"#;
            let text = text.replacen(type_def, &format!("{type_def}{firmware_ref}"), 1).replace(
                arm_x,
                &format!(r#"{arm_x}<Reference ReferenceType="HasComponent">ns=1;i=5101</Reference>"#),
            );
            let end = text.rfind("</UANodeSet>").expect("the end of the file");
            let added = format!("{}{}{}", firmware(6101, 5004), controller(td), firmware(6102, 5101));
            format!("{}{added}{}", &text[..end], &text[end..])
        });
        let m = &out.model;
        let cfg = VENDOR_ROBOT.iter().fold(ModelicaConfig::new(), |c, u| c.namespace(*u));
        let p = plan(m, &cfg).unwrap_or_else(|d| panic!("{d:?}"));
        let extends = |name: &str| {
            let plans = &p.ctx.plans[&Owner::Type(object_type(m, VENDOR_ROBOT[2], name))];
            plans.main.as_ref().and_then(|c| c.extends.clone()).map(|(_, mods)| mods).unwrap_or_default()
        };
        // Not in ArmXType, nor in the class it may give its Controller.
        let arm_x = &p.ctx.plans[&Owner::Type(object_type(m, VENDOR_ROBOT[2], "ArmXType"))];
        for class in arm_x.main.iter().chain(arm_x.decls.iter().map(|(_, c)| c)) {
            let mods = class.extends.as_ref().map(|(_, mods)| mods.as_slice()).unwrap_or_default();
            assert_eq!(finals(mods, "use_firmwareLevel"), 0, "TypeDefinition {td}: {mods:?}");
        }
        let controller_redeclared =
            extends("ArmXType").iter().any(|x| matches!(x, Mod::Redeclare { ident, .. } if ident == "Controller"));
        assert_eq!(controller_redeclared, redeclared);
        // ArmType sets the flag on its declaration of the component.
        let t = object_type(m, VENDOR_ROBOT[2], "ArmType");
        let mods = p.ctx.plans[&Owner::Type(t)]
            .main
            .as_ref()
            .and_then(|c| {
                c.items.iter().find_map(|i| match i {
                    Item::Decl { ident, mods, .. } if ident == "controller" => Some(mods),
                    _ => None,
                })
            })
            .expect("ArmType declares controller");
        assert_eq!(finals(mods, "use_firmwareLevel"), 1, "{mods:?}");
        let controller = element(info(&p, &ClassKey::Type(t)), "Controller");
        let members = controller.modified.as_deref().expect("the declaration modifies the members of its class");
        assert!(members.iter().any(|e| e.bn.name == "FirmwareLevel" && e.present), "{members:?}");
    }
}
