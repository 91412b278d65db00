//! A browse path that the ObjectType does not have.

use nodeset_models::models::robotics::types::AxisMotionProfileEnumeration;
use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::AxisType)]
struct Axis {
    #[opcua(path = "ParameterSet/ActualPosition")]
    position: f64,
    motion_profile: AxisMotionProfileEnumeration,
    #[opcua(path = "ParameterSet/Torque")]
    torque: f64,
}

fn main() {}
