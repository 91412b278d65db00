//! UI tests of `#[derive(ObjectModel)]`: what a user's mistakes look like, one case per file under
//! `tests/ui/fail/` with the expected compiler output beside it (`.stderr`), and bindings that compile and
//! run under `tests/ui/pass/`. The toolchain is pinned (`rust-toolchain.toml`), so the `.stderr` files are
//! stable; after an intended change, regenerate them with `TRYBUILD=overwrite cargo test -p nodeset-derive
//! --test derive_ui` and review the diff.

#[test]
fn derive_ui() {
    let t = trybuild::TestCases::new();
    t.pass("tests/ui/pass/*.rs");
    t.compile_fail("tests/ui/fail/*.rs");
}
