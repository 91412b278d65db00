//! What the examples and the integration tests of the runtime share: the hand-written [`demo`] namespace,
//! [`describe`] (the values of a simulated robot) and [`secure`] (the examples' security options).
//!
//! The examples themselves are under `examples/` (`cargo run -p nodeset-examples --example robot`), the tests
//! of the runtime with the generated models under `tests/`.

#![cfg_attr(test, deny(warnings))]

pub mod demo;
pub mod describe;
pub mod secure;
