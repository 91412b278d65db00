//! Binding to a handle that is not an ObjectType (DI's LifetimeVariableType is a VariableType).

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::di::objects::LifetimeVariableType)]
struct Lifetime {
    start_value: f64,
}

fn main() {}
