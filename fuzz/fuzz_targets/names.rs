//! The Rust and Modelica name sanitizers and the per-scope name tables.
//!
//! The input is a list of names, one per line. For every target language and every case:
//!
//! 1. each name sanitizes to a valid identifier: checked by `names::is_valid`, and independently for Rust
//!    by building it as the emitter does (`proc_macro2::Ident::new`/`new_raw`, which panic on anything
//!    else) and by parsing it with syn, and for Modelica against the grammar and reserved words of the
//!    Modelica 3.6 specification;
//! 2. in one `Scope`, distinct originals get distinct identifiers, every identifier is valid, none reuses
//!    a reserved one, every merge of two originals onto one sanitized name is reported as a collision
//!    naming both, and the result does not depend on the order the names were added in.

#![no_main]

use libfuzzer_sys::fuzz_target;
use nodeset_compiler::names::{is_valid, sanitize, Case, Scope, Target};
use std::collections::{BTreeMap, BTreeSet};

const CASES: [Case; 4] = [Case::UpperCamel, Case::Snake, Case::ShoutySnake, Case::Preserve];

/// Modelica 3.6, section 2.3.3: the reserved words.
const MODELICA_KEYWORDS: &[&str] = &[
    "algorithm", "and", "annotation", "block", "break", "class", "connect", "connector", "constant",
    "constrainedby", "der", "discrete", "each", "else", "elseif", "elsewhen", "encapsulated", "end", "enumeration",
    "equation", "expandable", "extends", "external", "false", "final", "flow", "for", "function", "if", "import",
    "impure", "in", "initial", "inner", "input", "loop", "model", "not", "operator", "or", "outer", "output",
    "package", "parameter", "partial", "protected", "public", "pure", "record", "redeclare", "replaceable",
    "return", "stream", "then", "true", "type", "when", "while", "within",
];

fn valid_rust(s: &str) -> bool {
    // The emitter's construction (emit::rust::ident): panics on an invalid identifier.
    let ident = match s.strip_prefix("r#") {
        Some(raw) => proc_macro2::Ident::new_raw(raw, proc_macro2::Span::call_site()),
        None => proc_macro2::Ident::new(s, proc_macro2::Span::call_site()),
    };
    // A reader's view: syn rejects keywords that are not raw.
    syn::parse_str::<syn::Ident>(&ident.to_string()).is_ok() && is_valid(s, Target::Rust)
}

fn valid_modelica(s: &str) -> bool {
    // IDENT = NONDIGIT { DIGIT | NONDIGIT }, NONDIGIT = "_" | a-z | A-Z (quoted identifiers are never made).
    let mut cs = s.chars();
    let grammar = cs.next().is_some_and(|c| c == '_' || c.is_ascii_alphabetic())
        && cs.all(|c| c == '_' || c.is_ascii_alphanumeric());
    grammar && !MODELICA_KEYWORDS.contains(&s) && is_valid(s, Target::Modelica)
}

fn valid(s: &str, target: Target) -> bool {
    match target {
        Target::Rust => valid_rust(s),
        Target::Modelica => valid_modelica(s),
    }
}

fn scope(names: &[String], reserved: &[String], order: impl Iterator<Item = usize>, target: Target, case: Case) -> (BTreeMap<usize, String>, Vec<nodeset_compiler::names::Collision<usize>>) {
    let mut s: Scope<usize> = Scope::new(target, case);
    for r in reserved {
        s.reserve(r);
    }
    for i in order {
        s.add(&names[i], i);
    }
    s.finish()
}

fuzz_target!(|data: &[u8]| {
    let mut names = nodeset_compiler_fuzz::names(data);
    names.sort();
    names.dedup();
    names.truncate(16);
    for target in [Target::Rust, Target::Modelica] {
        for case in CASES {
            for n in &names {
                let id = sanitize(n, case, target);
                assert!(valid(&id, target), "{n:?} -> {id:?} ({case:?}, {target:?}) is not a valid identifier");
            }
            // The generator reserves identifiers of its own; take the sanitized first name as one, so
            // clashes with reserved identifiers are exercised too.
            let reserved: Vec<String> = names.first().map(|n| sanitize(n, case, target)).into_iter().collect();
            let (map, collisions) = scope(&names, &reserved, 0..names.len(), target, case);
            let (map2, collisions2) = scope(&names, &reserved, (0..names.len()).rev(), target, case);
            assert_eq!(map, map2, "the names depend on the order they were added in ({case:?}, {target:?})");
            assert_eq!(collisions, collisions2, "the collisions depend on the order ({case:?}, {target:?})");
            assert_eq!(map.len(), names.len(), "a name got no identifier");
            let mut seen: BTreeSet<&str> = reserved.iter().map(String::as_str).collect();
            for (i, id) in &map {
                assert!(valid(id, target), "{:?} -> {id:?} ({case:?}, {target:?}) is not a valid identifier", names[*i]);
                assert!(seen.insert(id.as_str()), "{:?} -> {id:?} ({case:?}, {target:?}) merges with another name or a reserved identifier", names[*i]);
            }
            // Every merge of distinct originals onto one sanitized identifier is reported, naming all of them.
            let mut by_ident: BTreeMap<String, BTreeSet<usize>> = BTreeMap::new();
            for (i, n) in names.iter().enumerate() {
                by_ident.entry(sanitize(n, case, target)).or_default().insert(i);
            }
            for (ident, members) in by_ident {
                if members.len() > 1 || reserved.contains(&ident) {
                    let c = collisions.iter().find(|c| c.ident == ident);
                    let reported: BTreeSet<usize> = c.map(|c| c.members.iter().map(|m| m.1).collect()).unwrap_or_default();
                    assert_eq!(reported, members, "the merge onto {ident:?} is not reported completely ({case:?}, {target:?})");
                }
            }
        }
    }
});
