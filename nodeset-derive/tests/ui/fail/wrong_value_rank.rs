//! A scalar field bound to an array variable (AvailableStates has ValueRank 1).

use nodeset_models::ObjectModel;
use opcua::types::{LocalizedText, NodeId};

#[derive(ObjectModel)]
#[opcua(object_type = nodeset_models::models::robotics::objects::ControllerType)]
struct Controller {
    manufacturer: LocalizedText,
    model: LocalizedText,
    product_code: String,
    serial_number: String,
    #[opcua(path = "CurrentUser/Level")]
    user_level: String,
    #[opcua(path = "SystemOperation/SystemOperationStateMachine/AvailableStates")]
    available_states: NodeId,
}

fn main() {}
