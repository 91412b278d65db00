//! A key the derive does not know, on a field (`pth`) and on the struct (`object`).

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::PowerTrainType, object = "x")]
struct PowerTrain {
    #[opcua(pth = "SerialNumber")]
    serial: String,
}

fn main() {}
