//! A mandatory variable without a default value (AxisType's MotionProfile) that no field binds.

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::AxisType)]
struct Axis {
    #[opcua(path = "ParameterSet/ActualPosition")]
    position: f64,
}

fn main() {}
