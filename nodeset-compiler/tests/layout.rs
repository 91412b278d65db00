//! The compiler's module structure: no modules import each other in a loop, among the crate's top-level
//! modules (`resolve` and `datatypes` among them) or inside the Modelica back end.
//! A loop means two files are one concern split in two; the test names the modules of each loop and the
//! paths that tie them.
//!
//! It reads the source as text: `crate::`, `super::` and `self::` paths (with `use` groups), and the names of
//! a module's own children (`plan::ClassKey` in `mod.rs`). Doc comments and comments are left out; test
//! modules (`tests.rs`, `*_tests.rs`) are not part of the structure.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The library's modules by path (`emit::modelica::members`; the crate root is ``), with their files.
fn modules(src: &Path) -> BTreeMap<String, PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let p = entry.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    walk(src, &mut files);
    let mut out = BTreeMap::new();
    for file in files {
        let rel = file.strip_prefix(src).unwrap().with_extension("");
        let mut parts: Vec<String> = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
        let stem = parts.last().cloned().unwrap_or_default();
        if stem == "main" || stem == "tests" || stem.ends_with("_tests") {
            continue;
        }
        if stem == "mod" || stem == "lib" {
            parts.pop();
        }
        out.insert(parts.join("::"), file);
    }
    out
}

/// The code of a file without its comments and the contents of its string and character literals (a path in
/// a string or a doc comment is text, not an import).
fn code(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < c.len() {
        let at = |i: usize, k: usize| c.get(i + k).copied().unwrap_or('\0');
        if at(i, 0) == '/' && at(i, 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if at(i, 0) == '/' && at(i, 1) == '*' {
            let mut depth = 0;
            while i < c.len() {
                if at(i, 0) == '/' && at(i, 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if at(i, 0) == '*' && at(i, 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if at(i, 0) == 'r' && (at(i, 1) == '"' || at(i, 1) == '#') && (i == 0 || !is_ident_char(c[i - 1])) {
            // A raw string: r"...", r#"..."#.
            let mut j = i + 1;
            let mut hashes = 0;
            while c.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if c.get(j) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            j += 1;
            while j < c.len() && !(c[j] == '"' && (1..=hashes).all(|h| c.get(j + h) == Some(&'#'))) {
                j += 1;
            }
            out.push_str("\"\"");
            i = j + 1 + hashes;
        } else if at(i, 0) == '"' {
            i += 1;
            while i < c.len() && c[i] != '"' {
                i += if c[i] == '\\' { 2 } else { 1 };
            }
            out.push_str("\"\"");
            i += 1;
        } else if at(i, 0) == '\'' && (at(i, 2) == '\'' || at(i, 1) == '\\') {
            // A character literal ('"', '\''), not a lifetime.
            i += if at(i, 1) == '\\' { 2 } else { 1 };
            while i < c.len() && c[i] != '\'' {
                i += 1;
            }
            out.push_str("' '");
            i += 1;
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// Code without the bodies of `quote!` and `parse_quote!`: the paths in them are code being generated
/// (`super::super::NAMESPACE_URI` in a generated module), not imports of the generator.
fn without_quoted(code: &str) -> String {
    let c: Vec<char> = code.chars().collect();
    let mut out = String::with_capacity(code.len());
    let mut i = 0;
    while i < c.len() {
        let rest: String = c[i..(i + 13).min(c.len())].iter().collect();
        let name = ["parse_quote!", "quote!"].into_iter().find(|m| rest.starts_with(m));
        match name {
            Some(m) if i == 0 || !is_ident_char(c[i - 1]) => {
                let mut j = i + m.len();
                while j < c.len() && c[j].is_whitespace() {
                    j += 1;
                }
                let (open, close) = match c.get(j) {
                    Some('{') => ('{', '}'),
                    Some('(') => ('(', ')'),
                    Some('[') => ('[', ']'),
                    _ => {
                        out.push(c[i]);
                        i += 1;
                        continue;
                    }
                };
                let mut depth = 0;
                while j < c.len() {
                    if c[j] == open {
                        depth += 1;
                    } else if c[j] == close {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    j += 1;
                }
                out.push_str("quote! {}");
                i = j + 1;
            }
            _ => {
                out.push(c[i]);
                i += 1;
            }
        }
    }
    out
}

fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The paths written in some code, each as its segments, with `crate`, `super` and `self` kept as segments
/// and `use` groups expanded (`super::{a::B, c}` gives `super::a::B` and `super::c`).
fn paths(code: &str) -> Vec<Vec<String>> {
    let chars: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = (i == 0 || !(is_ident_char(chars[i - 1]) || chars[i - 1] == ':'))
            && is_ident_char(chars[i])
            && !chars[i].is_ascii_digit();
        if starts {
            let (mut found, end) = path_at(&chars, i);
            out.append(&mut found);
            i = end.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

/// The paths of the path expression at `i` (one, or several through groups), and where it ends.
fn path_at(chars: &[char], mut i: usize) -> (Vec<Vec<String>>, usize) {
    let mut segs = Vec::new();
    loop {
        let start = i;
        while i < chars.len() && is_ident_char(chars[i]) {
            i += 1;
        }
        segs.push(chars[start..i].iter().collect::<String>());
        if i + 1 < chars.len() && chars[i] == ':' && chars[i + 1] == ':' {
            i += 2;
            while i < chars.len() && chars[i].is_whitespace() {
                i += 1;
            }
            if i < chars.len() && chars[i] == '{' {
                // A group: each member continues the path.
                let mut depth = 0;
                let mut j = i;
                while j < chars.len() {
                    match chars[j] {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                break;
                            }
                        }
                        _ => {}
                    }
                    j += 1;
                }
                let inner: String = chars[i + 1..j.min(chars.len())].iter().collect();
                let mut out = Vec::new();
                for member in split_top(&inner) {
                    let member: Vec<char> = member.trim().chars().collect();
                    if member.is_empty() || !is_ident_char(member[0]) {
                        continue;
                    }
                    for tail in path_at(&member, 0).0 {
                        let mut p = segs.clone();
                        p.extend(tail);
                        out.push(p);
                    }
                }
                return (out, j + 1);
            }
            if i < chars.len() && is_ident_char(chars[i]) {
                continue;
            }
        }
        return (vec![segs], i);
    }
}

/// The members of a `use` group, split at its top-level commas.
fn split_top(s: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut depth = 0;
    for c in s.chars() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                out.push(String::new());
                continue;
            }
            _ => {}
        }
        out.last_mut().unwrap().push(c);
    }
    out
}

/// Which modules each module names: the longest module path that a path it writes starts with.
fn imports(modules: &BTreeMap<String, PathBuf>) -> BTreeMap<String, BTreeMap<String, BTreeSet<String>>> {
    let split = |m: &str| -> Vec<String> {
        if m.is_empty() {
            Vec::new()
        } else {
            m.split("::").map(str::to_string).collect()
        }
    };
    let mut out = BTreeMap::new();
    for (module, file) in modules {
        let here = split(module);
        let mut named: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for path in paths(&without_quoted(&code(&std::fs::read_to_string(file).unwrap()))) {
            // One segment is no import: a visibility (`pub(crate)`, `pub(super)`), a `mod x;` declaration, a
            // local name.
            if path.len() < 2 {
                continue;
            }
            let mut abs = match path[0].as_str() {
                "crate" => Vec::new(),
                "self" => here.clone(),
                "super" => here.clone(),
                _ => here.clone(),
            };
            let mut rest = &path[..];
            match path[0].as_str() {
                "crate" | "self" => rest = &path[1..],
                "super" => {
                    while rest.first().is_some_and(|s| s == "super") {
                        abs.pop();
                        rest = &rest[1..];
                    }
                }
                // A bare path names a module only through a child of this one (`plan::ClassKey` in mod.rs).
                first => {
                    let mut child = here.clone();
                    child.push(first.to_string());
                    if !modules.contains_key(&child.join("::")) {
                        continue;
                    }
                }
            }
            abs.extend(rest.iter().cloned());
            let target = (0..=abs.len()).rev().map(|k| abs[..k].join("::")).find(|p| modules.contains_key(p));
            if let Some(target) = target {
                if target != *module {
                    named.entry(target).or_default().insert(path.join("::"));
                }
            }
        }
        out.insert(module.clone(), named);
    }
    out
}

/// The loops among the children of `scope` (each child standing for itself and its descendants; `scope`
/// itself, the `mod.rs`, is one of them): each as its modules and the paths that tie them.
fn loops(all: &BTreeMap<String, BTreeMap<String, BTreeSet<String>>>, scope: &str) -> Vec<(Vec<String>, Vec<String>)> {
    let prefix = if scope.is_empty() { String::new() } else { format!("{scope}::") };
    let member = |m: &str| -> Option<String> {
        if m == scope {
            return Some(scope.to_string());
        }
        let rest = m.strip_prefix(&prefix)?;
        Some(format!("{prefix}{}", rest.split("::").next().unwrap()))
    };
    let mut edges: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (from, named) in all {
        let Some(a) = member(from) else { continue };
        edges.entry(a.clone()).or_default();
        for (to, how) in named {
            let Some(b) = member(to) else { continue };
            if a != b {
                edges.entry(a.clone()).or_default().entry(b).or_default().extend(how.iter().map(|h| format!("{from}: {h}")));
            }
        }
    }
    let reach = |start: &str| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![start.to_string()];
        while let Some(n) = stack.pop() {
            for next in edges.get(&n).into_iter().flat_map(|e| e.keys()) {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&String, BTreeSet<String>> = edges.keys().map(|n| (n, reach(n))).collect();
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for n in edges.keys() {
        if done.contains(n) || !reaches[n].contains(n) {
            continue;
        }
        let members: Vec<String> = edges.keys().filter(|m| reaches[n].contains(*m) && reaches[*m].contains(n)).cloned().collect();
        let ties: Vec<String> = members
            .iter()
            .flat_map(|a| edges[a].iter().filter(|(b, _)| members.contains(b)).flat_map(|(_, how)| how.iter().take(3).cloned()))
            .collect();
        done.extend(members.iter().cloned());
        out.push((members, ties));
    }
    out
}

fn compiler_imports() -> BTreeMap<String, BTreeMap<String, BTreeSet<String>>> {
    imports(&modules(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src")))
}

fn assert_no_loops(scope: &str) {
    let all = compiler_imports();
    assert!(all.keys().any(|m| m.starts_with(scope)), "no module {scope}");
    let found = loops(&all, scope);
    let text: Vec<String> = found.iter().map(|(ms, ties)| format!("{}\n    {}", ms.join(" <-> "), ties.join("\n    "))).collect();
    assert!(found.is_empty(), "modules of `{scope}` that import each other:\n{}", text.join("\n"));
}

#[test]
fn no_loop_among_the_top_level_modules() {
    assert_no_loops("");
}

#[test]
fn no_loop_inside_the_modelica_back_end() {
    assert_no_loops("emit::modelica");
}

#[test]
fn the_reader_sees_what_a_loop_is_made_of() {
    // The reading itself: group paths, `super` chains and a parent's children are edges; a loop is found.
    let text = "use super::{plan::{A, B}, text};\nfn f() { super::super::model::x(); plan::y(); }\n\
                // crate::commented\n/* crate::block */ let s = \"crate::quoted\"; let r = r#\"crate::raw\"#; let q = '\"';";
    let found: BTreeSet<String> = paths(&code(text)).into_iter().map(|p| p.join("::")).collect();
    for want in ["super::plan::A", "super::plan::B", "super::text", "super::super::model::x", "plan::y"] {
        assert!(found.contains(want), "{want} not in {found:?}");
    }
    assert!(!found.iter().any(|p| p.starts_with("crate::")), "comments and strings are not code: {found:?}");
    let generated = without_quoted("let t = quote! { use super::super::NS; }; let p: syn::Path = syn::parse_quote!(a::b);");
    assert!(paths(&generated).iter().filter(|p| p.len() > 1).all(|p| p[0] == "syn"), "{generated}");
    let mut all: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    all.entry("a::x".into()).or_default().entry("a::y::inner".into()).or_default().insert("super::y::inner::f".into());
    all.entry("a::y::inner".into()).or_default().entry("a::x".into()).or_default().insert("crate::a::x::g".into());
    all.entry("a::z".into()).or_default().entry("a::x".into()).or_default().insert("super::x".into());
    let found = loops(&all, "a");
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, vec!["a::x".to_string(), "a::y".to_string()]);
    assert!(loops(&all, "b").is_empty());
}
