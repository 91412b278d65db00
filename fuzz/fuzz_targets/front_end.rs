//! Parse + load + resolve through the public `compile` path, with the diagnostics rendered as the CLI
//! renders them. The input is one NodeSet2 file; the reduced base namespace (`mini_ns0`) is given beside
//! it, so inputs that require `http://opcfoundation.org/UA/` get past loading into the resolver.
//!
//! Any panic is a bug: the compiler must answer every input with diagnostics.

#![no_main]

use libfuzzer_sys::fuzz_target;
use nodeset_compiler::load::Input;
use nodeset_compiler::{compile, summary, Options};

fuzz_target!(|data: &[u8]| {
    let ns0 = nodeset_compiler_fuzz::mini_ns0();
    // In-memory inputs are text; invalid UTF-8 becomes U+FFFD, while a BOM, UTF-16 and NUL bytes still
    // reach the loader's own checks.
    let text = String::from_utf8_lossy(data).into_owned();
    let inputs = vec![
        Input::Text { name: "ns0.xml".into(), text: ns0.to_string() },
        Input::Text { name: "input.xml".into(), text },
    ];
    let out = compile(inputs, &Options { all_warnings: true, ..Options::default() });
    let rendered = out.render_diagnostics();
    // Every diagnostic renders, and the summary of whatever was resolved prints.
    assert!(out.diagnostics.items.is_empty() || !rendered.is_empty());
    let _ = summary::render(&out.model);
});
