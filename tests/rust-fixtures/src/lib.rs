//! The fixtures' generated Rust, compiled with every warning an error.
#![deny(warnings)]

include!(concat!(env!("OUT_DIR"), "/nodesets.rs"));

/// The skill reference models of ../shared/nodesets/skills-reference (`skills`, `linear_axis_with_gripper`).
pub mod skills_reference {
    include!(concat!(env!("OUT_DIR"), "/skills_reference.rs"));
}

/// The recovery fixtures of tests/fixtures/recover, generated with every demotable error demoted.
pub mod recovered {
    include!(concat!(env!("OUT_DIR"), "/recovered.rs"));
}

/// The name collision fixture's subtype generated without its dependency (inherited members inlined).
pub mod name_collision_alone {
    include!(concat!(env!("OUT_DIR"), "/name_collision_alone.rs"));
}

/// The keyword fixture (tests/rust-fixtures/keyword) as the `rust` command writes it: a folder per namespace,
/// one of them the module `r#struct` in the folder `struct/`.
pub mod keyword {
    include!(concat!(env!("OUT_DIR"), "/keyword_tree.rs"));
}
