//! A struct that does not say which ObjectType it binds.

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
struct PowerTrain {
    serial_number: String,
}

fn main() {}
