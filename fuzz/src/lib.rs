//! Helpers shared by the fuzz targets in `fuzz_targets/`.
//!
//! The front-end target compiles every input together with a reduced base namespace, [`mini_ns0`]: the full
//! `Opc.Ua.NodeSet2.xml` (5,476 nodes, 4 MB) costs milliseconds per execution even uninstrumented, and
//! all its types (747 nodes) still left an instrumented build at 17 executions a second. The reduced one
//! keeps the ns0 nodes that our fixtures and skill nodesets point at, those the resolver knows by id, and
//! everything they need in turn (supertypes, type definitions, modelling rules, reference types, data
//! types), so that inputs requiring `http://opcfoundation.org/UA/` load and resolve as they would against
//! the real file.

use nodeset_compiler::diag::Diagnostics;
use nodeset_compiler::parse::{parse, Limits};
use nodeset_compiler::source::FileId;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::OnceLock;

/// The pinned base namespace, fetched by `cargo xtask fetch-nodesets`.
pub fn ns0_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../nodesets/vendor/Opc.Ua.NodeSet2.xml")
}

/// Where the reduction starts: the ns0 nodes named in `tests/fixtures` and `nodesets/*.xml`, the ones the
/// resolver knows by id (`model::ids`), the built-in DataTypes and the standard folders.
const ROOTS: &[u32] = &[
    // Built-in DataTypes (1-25) and the abstract number types.
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 50,
    // Reference types the resolver knows.
    31, 33, 34, 35, 37, 38, 40, 41, 44, 45, 46, 47, 51, 52, 53, 54, 17603, 17604,
    // Types the resolver knows.
    58, 61, 62, 63, 68, 76, 77, 2041, 17602, 2299, 2771, 2307, 2309, 2310, 2311, 2391, 2378, 2400, 12755, 12756,
    296, 297, 7594, 7616, 294, 887, 888, 2760, 2767, 17497, 18774, 18781, 18791, 18810, 18812, 18814,
    // ModellingRules.
    78, 80, 83, 11508, 11510,
    // Root, Objects, Types, Views, the type folders, Server.
    84, 85, 86, 87, 88, 89, 90, 91, 2253,
];

/// The reduced base namespace (computed once per process; see the module documentation).
///
/// Panics when the pinned base namespace is missing, with the command that fetches it: a fuzz run without
/// it would exercise nothing past loading.
pub fn mini_ns0() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| {
        let path = ns0_path();
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!("cannot read {}: {e}; run `cargo xtask fetch-nodesets`", path.display())
        });
        reduce(&text, ROOTS)
    })
}

/// Keeps the nodes of a base-namespace file reachable from `roots` through what a node needs (its
/// supertype, type definition, modelling rule, reference types, DataType and field types; not its
/// children), and only the references among the kept nodes.
///
/// The file is cut at the start tags of its nodes (the parser gives their spans), so every kept node keeps
/// its own text; a `<Reference>` line whose target was dropped is removed. The official file writes one
/// reference per line with a plain `i=N` target, which is what this relies on.
pub fn reduce(text: &str, roots: &[u32]) -> String {
    let mut diags = Diagnostics::new();
    let set = parse(FileId(0), text, &Limits::default(), &mut diags).expect("the pinned base namespace parses");
    let aliases: BTreeMap<&str, &str> = set.aliases.iter().map(|a| (a.alias.as_str(), a.target.value.as_str())).collect();
    let number = |s: &str| -> Option<u32> {
        let s = s.trim();
        aliases.get(s).copied().unwrap_or(s).strip_prefix("i=")?.parse().ok()
    };
    let by_id: BTreeMap<u32, usize> = set
        .nodes
        .iter()
        .enumerate()
        .filter_map(|(i, n)| n.node_id.numeric_node_id().filter(|&(ns, _)| ns == 0).map(|(_, id)| (id, i)))
        .collect();
    let needed_refs = [40, 37].map(Some); // HasTypeDefinition, HasModellingRule (forward)
    let mut kept: BTreeSet<u32> = BTreeSet::new();
    let mut work: Vec<u32> = roots.to_vec();
    while let Some(id) = work.pop() {
        let Some(&i) = by_id.get(&id) else { continue };
        if !kept.insert(id) {
            continue;
        }
        let n = &set.nodes[i];
        for r in set.references_of(n) {
            let rt = number(r.reference_type.get(text));
            work.extend(rt);
            let supertype = rt == Some(45) && !r.is_forward;
            if supertype || (r.is_forward && needed_refs.contains(&rt)) {
                work.extend(number(r.target.get(text)));
            }
        }
        work.extend(n.data_type.as_ref().and_then(|d| number(d.get(text))));
        if let Some(def) = &n.definition {
            work.extend(def.fields.iter().filter_map(|f| f.data_type.as_ref().and_then(|d| number(&d.value))));
        }
    }
    let mut starts: Vec<(usize, Option<u32>)> = set
        .nodes
        .iter()
        .map(|n| (n.span.start as usize, n.node_id.numeric_node_id().filter(|&(ns, _)| ns == 0).map(|(_, i)| i)))
        .collect();
    starts.sort();
    let end = text.rfind("</UANodeSet>").expect("the base namespace ends with </UANodeSet>");
    let first = starts.first().map_or(end, |s| s.0);
    let mut out = String::with_capacity(text.len() / 8);
    out.push_str(&text[..first]);
    for (i, &(start, id)) in starts.iter().enumerate() {
        if !id.is_some_and(|id| kept.contains(&id)) {
            continue;
        }
        let stop = starts.get(i + 1).map_or(end, |s| s.0);
        for line in text[start..stop].split_inclusive('\n') {
            if let Some(target) = reference_target(line) {
                if !number(target).is_some_and(|n| kept.contains(&n)) {
                    continue;
                }
            }
            out.push_str(line);
        }
    }
    out.push_str(&text[end..]);
    out
}

/// The target of a one-line `<Reference ...>TARGET</Reference>`.
fn reference_target(line: &str) -> Option<&str> {
    let rest = line.trim_start().strip_prefix("<Reference ")?;
    let (_, tail) = rest.split_once('>')?;
    let (target, _) = tail.split_once("</Reference>")?;
    Some(target.trim())
}

/// Splits a fuzz input into names: UTF-8 (lossily), one name per line. Shared by the name target and its
/// seed corpus (`cargo xtask fuzz` writes the BrowseNames of each fixture one per line).
pub fn names(data: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(data).split('\n').map(str::to_string).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nodeset_compiler::load::Input;
    use nodeset_compiler::{compile, Options};

    /// The reduced base namespace compiles on its own without errors, and is much smaller.
    #[test]
    fn mini_ns0_resolves_cleanly() {
        let text = mini_ns0();
        let out = compile(vec![Input::Text { name: "mini-ns0.xml".into(), text: text.to_string() }], &Options::default());
        assert!(out.ok(), "{}", out.render_diagnostics());
        let full = std::fs::read_to_string(ns0_path()).unwrap();
        assert!(text.len() * 10 < full.len(), "{} of {} bytes", text.len(), full.len());
    }
}
