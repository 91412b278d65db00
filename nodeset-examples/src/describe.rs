//! The values a browsing client expects of a simulated robot beyond its motion.
//!
//! Instantiation (or a nodeset's instance) gives a MotionDeviceSystem every mandatory variable, but many
//! without a value: a client then sees motors without nameplates, a gear without ratio, axes without units, a
//! safety state that says nothing. [`describe`] gives each such variable a value, and leaves alone every
//! variable that already has one (the example's own data, or values from the nodeset).

use nodeset_models::models::di::objects::ComponentType;
use nodeset_models::models::robotics::objects::{MotionDeviceSystemType, MotionDeviceType};
use nodeset_models::models::robotics::types::{AxisMotionProfileEnumeration, OperationalModeEnumeration};
use nodeset_models::runtime::server::ModelManager;
use nodeset_models::runtime::typed::{UaValue, Variable};
use opcua::types::{EUInformation, LocalizedText, NodeId, RationalNumber};

/// The namespace of UNECE Recommendation 20 units, as OPC 10000-8 encodes them (the code's letters as the
/// UnitId).
const UNECE: &str = "http://www.opcfoundation.org/UA/units/un/cefact";

/// A unit: UNECE code, symbol, name.
pub type Unit = (&'static str, &'static str, &'static str);
pub const DEGREE: Unit = ("DD", "°", "degree");
pub const DEGREE_CELSIUS: Unit = ("CEL", "°C", "degree Celsius");
pub const HOUR: Unit = ("HUR", "h", "hour");

/// The manufacturer the examples' simulated parts name.
const MAKER: &str = "nodeset-compiler robotics";

/// Gives every variable of `system` that has no value one: nameplates of motion devices, motors, gears,
/// controllers and software; gear ratios; the units of joint positions and motor temperatures; motion
/// profiles; the current user's level; the task; the safety state (no stop, automatic mode).
pub fn describe(manager: &ModelManager, system: &MotionDeviceSystemType) -> Result<(), String> {
    for (d, device) in system.motion_devices.motion_device_identifier.values().enumerate() {
        device_nameplate(device, &format!("SIX-{}", d + 1))?;
        for axis in device.axes.axis_identifier.values() {
            fill(&axis.motion_profile, AxisMotionProfileEnumeration::Rotary)?;
            units(manager, axis.parameter_set.actual_position.id(), DEGREE)?;
        }
        for (p, pt) in device.power_trains.power_train_identifier.values().enumerate() {
            for (m, motor) in pt.motor_identifier.values().enumerate() {
                fill(&motor.manufacturer, LocalizedText::new("en", MAKER))?;
                fill(&motor.model, LocalizedText::new("en", "SIX-M"))?;
                fill(&motor.product_code, "SIX-M-400".to_owned())?;
                fill(&motor.serial_number, format!("M-{}{}{}", d + 1, p + 1, m + 1))?;
                fill(&motor.parameter_set.motor_temperature, 35.0 + p as f64)?;
                units(manager, motor.parameter_set.motor_temperature.id(), DEGREE_CELSIUS)?;
            }
            for (g, gear) in pt.gear_identifier.values().enumerate() {
                fill(&gear.manufacturer, LocalizedText::new("en", MAKER))?;
                fill(&gear.model, LocalizedText::new("en", "SIX-G"))?;
                fill(&gear.product_code, "SIX-G-121".to_owned())?;
                fill(&gear.serial_number, format!("G-{}{}{}", d + 1, p + 1, g + 1))?;
                // Motor turns per output turn; the RationalNumberType's children follow the value.
                fill(&gear.gear_ratio, RationalNumber { numerator: 121, denominator: 1 })?;
            }
        }
    }
    for (c, controller) in system.controllers.controller_identifier.values().enumerate() {
        fill(&controller.manufacturer, LocalizedText::new("en", MAKER))?;
        fill(&controller.model, LocalizedText::new("en", "SIX-C"))?;
        fill(&controller.product_code, "SIX-C-1".to_owned())?;
        fill(&controller.serial_number, format!("C-{}", c + 1))?;
        fill(&controller.current_user.level, "operator".to_owned())?;
        for software in controller.software.software_identifier.values() {
            fill(&software.manufacturer, LocalizedText::new("en", MAKER))?;
            fill(&software.model, LocalizedText::new("en", "SIX-OS"))?;
            fill(&software.software_revision, env!("CARGO_PKG_VERSION").to_owned())?;
        }
        for task in controller.task_controls.task_control_identifier.values() {
            fill(&task.component_name, LocalizedText::new("en", "Main task"))?;
            fill(&task.parameter_set.task_program_name, "main".to_owned())?;
            fill(&task.parameter_set.task_program_loaded, true)?;
        }
    }
    for safety in system.safety_states.safety_state_identifier.values() {
        fill(&safety.parameter_set.emergency_stop, false)?;
        fill(&safety.parameter_set.protective_stop, false)?;
        fill(&safety.parameter_set.operational_mode, OperationalModeEnumeration::Automatic)?;
    }
    Ok(())
}

/// Fills the optional DI nameplate variables a component has (Manufacturer, Model, ProductCode,
/// SerialNumber), such as an end effector's.
pub fn nameplate(component: &ComponentType, model: &str, product_code: &str, serial_number: &str) -> Result<(), String> {
    if let Some(v) = &component.manufacturer {
        fill(v, LocalizedText::new("en", MAKER))?;
    }
    if let Some(v) = &component.model {
        fill(v, LocalizedText::new("en", model))?;
    }
    if let Some(v) = &component.product_code {
        fill(v, product_code.to_owned())?;
    }
    if let Some(v) = &component.serial_number {
        fill(v, serial_number.to_owned())?;
    }
    Ok(())
}

fn device_nameplate(device: &MotionDeviceType, model: &str) -> Result<(), String> {
    fill(&device.manufacturer, LocalizedText::new("en", MAKER))?;
    fill(&device.model, LocalizedText::new("en", model))?;
    fill(&device.product_code, format!("{model}-850"))?;
    fill(&device.serial_number, "0001".to_owned())?;
    fill(&device.parameter_set.speed_override, 1.0)
}

/// Sets `variable` to `value` if it has no value.
pub fn fill<T: UaValue>(variable: &Variable<T>, value: T) -> Result<(), String> {
    let empty = variable.data_value().is_none_or(|dv| dv.value.is_none_or(|v| v.is_empty()));
    if empty {
        variable.set(value).map_err(|s| format!("{variable:?}: {s}"))?;
    }
    Ok(())
}

/// Fills the EngineeringUnits property of an analog variable.
pub fn units(manager: &ModelManager, variable: &NodeId, (code, symbol, name): Unit) -> Result<(), String> {
    let eu: Variable<EUInformation> = manager
        .bind_with(|b| b.child(variable, "http://opcfoundation.org/UA/", "EngineeringUnits"))
        .map_err(|e| e.to_string())?;
    let unit = EUInformation {
        namespace_uri: UNECE.into(),
        unit_id: unit_id(code),
        display_name: LocalizedText::new("", symbol),
        description: LocalizedText::new("en", name),
    };
    fill(&eu, unit)
}

/// The UnitId of a UNECE code: its letters, one byte each (OPC 10000-8, 5.6.3).
fn unit_id(code: &str) -> i32 {
    code.bytes().fold(0, |id, c| (id << 8) | i32::from(c))
}

#[cfg(test)]
mod tests {
    #[test]
    fn unece_codes_become_their_letters() {
        assert_eq!(super::unit_id(super::DEGREE.0), 17476);
        assert_eq!(super::unit_id(super::DEGREE_CELSIUS.0), 4408652);
    }
}
