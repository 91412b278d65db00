//! Binding to a handle that is not an ObjectType (DI's LifetimeVariableType is a VariableType; it has member
//! markers, which a field of the right type matches, but the derive binds ObjectTypes only).

use nodeset_models::ObjectModel;

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::di::objects::LifetimeVariableType)]
struct Lifetime {
    start_value: opcua::types::Variant,
}

fn main() {}
