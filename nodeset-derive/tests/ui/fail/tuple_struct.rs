//! Fields bind variables by name, so a tuple struct cannot be bound.

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::PowerTrainType)]
struct PowerTrain(String);

fn main() {}
