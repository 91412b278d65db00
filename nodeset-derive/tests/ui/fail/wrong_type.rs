//! A field whose Rust type cannot hold the variable's DataType (SerialNumber is a String).

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::PowerTrainType)]
struct PowerTrain {
    serial_number: u64,
}

fn main() {}
