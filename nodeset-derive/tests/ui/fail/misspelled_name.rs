//! A field name one letter off a member's browse name: the compiler suggests the right one.

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::PowerTrainType)]
struct PowerTrain {
    serial_numbr: String,
}

fn main() {}
