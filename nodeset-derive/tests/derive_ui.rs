//! UI tests of `#[derive(ObjectModel)]`: what a user's mistakes look like, one case per file under
//! `tests/ui/fail/` with the expected compiler output beside it (`.stderr`). Bindings that compile are an
//! ordinary test (`bindings.rs`): with no passing case, trybuild only type-checks (`cargo check`), so its
//! own target folder holds no code generation of async-opcua and the generated models. The toolchain is
//! pinned (`rust-toolchain.toml`), so the `.stderr` files are stable; after an intended change, regenerate
//! them with `TRYBUILD=overwrite cargo test -p nodeset-derive --test derive_ui` and review the diff.

#[test]
fn derive_ui() {
    // trybuild checks the cases and their dependencies (async-opcua, tokio, the generated models) in a target
    // folder of its own with cargo's default dev profile. Its build scripts and proc macros are still compiled,
    // with full debug info unless told otherwise; the cases compare compiler errors, which debug info does
    // not change; a developer's own setting wins.
    if std::env::var_os("CARGO_PROFILE_DEV_DEBUG").is_none() {
        std::env::set_var("CARGO_PROFILE_DEV_DEBUG", "false");
    }
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/fail/*.rs");
}
