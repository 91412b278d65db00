//! Bindings the derive accepts: field names as browse names, explicit paths, skipped fields, arrays as
//! `Vec<T>`, generated enumerations, and members a subtype inherits. An ordinary test, compiled with the
//! workspace (the mistakes the derive refuses are the UI tests, `derive_ui.rs`).

use nodeset_models::models::robotics::objects::{AxisType, ControllerType, PowerTrainType};
use nodeset_models::models::robotics::types::AxisMotionProfileEnumeration;
use nodeset_models::runtime::typed::model::ObjectModel as _;
use nodeset_models::ObjectModel;
use opcua::types::{LocalizedText, NodeId};

/// Every mandatory variable of AxisType without a default is bound.
#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::AxisType)]
struct Axis {
    #[opcua(path = "ParameterSet/ActualPosition")]
    position: f64,
    motion_profile: AxisMotionProfileEnumeration,
    #[opcua(skip)]
    _target: f64,
}

/// PowerTrainType has no required member; DI's identification members are inherited from ComponentType.
#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::PowerTrainType)]
struct PowerTrain {
    manufacturer: LocalizedText,
    serial_number: String,
    revision_counter: i32,
}

/// An array variable (ValueRank 1) binds as `Vec<T>`.
#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::ControllerType)]
struct Controller {
    manufacturer: LocalizedText,
    model: LocalizedText,
    product_code: String,
    serial_number: String,
    #[opcua(path = "CurrentUser/Level")]
    user_level: String,
    #[opcua(path = "SystemOperation/SystemOperationStateMachine/AvailableStates")]
    available_states: Vec<NodeId>,
}

#[test]
fn bindings_compile_and_carry_their_paths() {
    let axis: Vec<&str> = Axis::FIELDS.iter().map(|f| f.path).collect();
    assert_eq!(axis, ["ParameterSet/ActualPosition", "MotionProfile"]);
    assert_eq!(PowerTrain::FIELDS.len(), 3);
    assert_eq!(Controller::FIELDS[5].browse_path.segments().map(|s| s.len()), Ok(3));
    let _: fn() -> (Option<AxisType>, Option<PowerTrainType>, Option<ControllerType>) = || (None, None, None);
}
