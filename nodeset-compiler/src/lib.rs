//! nodeset-compiler: OPC UA NodeSet2 information models to typed Rust and Modelica.
pub mod diag;
pub mod load;
pub mod nodeid;
pub mod parse;
pub mod raw;
pub mod source;
