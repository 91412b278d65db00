//! Two fields bound to one variable: once by name, once by an explicit path.

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::PowerTrainType)]
struct PowerTrain {
    serial_number: String,
    #[opcua(path = "SerialNumber")]
    serial: String,
}

fn main() {}
