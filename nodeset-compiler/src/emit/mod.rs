//! The back ends: [`rust`] (typed Rust for the async-opcua server stack), [`modelica`] (Modelica packages)
//! and [`plan`], which namespaces a run generates and which it maps to code that exists elsewhere.

pub mod modelica;
pub mod plan;
pub mod rust;
