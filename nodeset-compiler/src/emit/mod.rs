pub mod modelica;
pub mod rust;
