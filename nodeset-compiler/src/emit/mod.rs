pub mod modelica;
pub mod plan;
pub mod rust;
