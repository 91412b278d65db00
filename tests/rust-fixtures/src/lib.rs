//! The fixtures' generated Rust, compiled with every warning an error.
#![deny(warnings)]

include!(concat!(env!("OUT_DIR"), "/nodesets.rs"));
