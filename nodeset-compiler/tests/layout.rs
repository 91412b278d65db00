//! The module structure of the workspace's crates: no modules import each other in a loop, among a crate's
//! top-level modules (the compiler's `resolve` and `datatypes`, the runtime's `server` and `typed`, ...) or
//! inside the compiler's Modelica back end; and the runtime's modules keep the layer order its crate
//! documentation writes down.
//! A loop means two files are one concern split in two; the test names the modules of each loop and the
//! paths that tie them.
//!
//! It reads the source as text: `crate::`, `super::` and `self::` paths (with `use` groups), and the names of
//! a module's own children (`plan::ClassKey` in `mod.rs`). Doc comments and comments are left out; test
//! modules (`tests.rs`, `*_tests.rs`) and binaries (`main.rs`, `bin/`) are not part of the structure.

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
    // The binaries beside a library are crates of their own.
    files.retain(|f| !f.strip_prefix(src).is_ok_and(|rel| rel.starts_with("bin")));
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

/// Code with the body of each `macro_rules!` reduced to its `$crate::` paths: a macro's other paths
/// (`super::super::NS`) are relative to the module that invokes it, not imports of the module that defines it.
fn without_macro_bodies(code: &str) -> String {
    let c: Vec<char> = code.chars().collect();
    let mut out = String::with_capacity(code.len());
    let mut i = 0;
    while i < c.len() {
        if word_at(&c, i, "macro_rules!") {
            let mut j = i + "macro_rules!".len();
            while j < c.len() && c[j] != '{' && c[j] != '(' && c[j] != '[' {
                j += 1;
            }
            let end = closing(&c, j);
            let body: String = c[(j + 1).min(c.len())..end.min(c.len())].iter().collect();
            let absolute: Vec<String> = paths(&body).into_iter().filter(|p| p.len() > 1 && p[0] == "crate").map(|p| p.join("::")).collect();
            out.extend(&c[i..j]);
            out.push_str(&format!("{{ {} }}", absolute.join("; ")));
            i = end + 1;
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// Code split by inline module (`mod tests { ... }`): each piece with the path of its module below the
/// file's (empty for the file's own code), so that `super::` in an inline module is resolved from it.
fn inline_modules(code: &str) -> Vec<(Vec<String>, String)> {
    fn split(c: &[char], at: Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
        let mut own = String::new();
        let mut i = 0;
        while i < c.len() {
            if word_at(c, i, "mod") && c.get(i + 3).is_some_and(|c| c.is_whitespace()) {
                let mut j = i + 3;
                while j < c.len() && c[j].is_whitespace() {
                    j += 1;
                }
                let start = j;
                while j < c.len() && is_ident_char(c[j]) {
                    j += 1;
                }
                let name: String = c[start..j].iter().collect();
                while j < c.len() && c[j].is_whitespace() {
                    j += 1;
                }
                if !name.is_empty() && c.get(j) == Some(&'{') {
                    let end = closing(c, j);
                    let mut inner = at.clone();
                    inner.push(name);
                    split(&c[j + 1..end.min(c.len())], inner, out);
                    i = end + 1;
                    continue;
                }
            }
            own.push(c[i]);
            i += 1;
        }
        out.push((at, own));
    }
    let c: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    split(&c, Vec::new(), &mut out);
    out
}

/// Whether `word` starts at `i`, not inside a longer identifier.
fn word_at(c: &[char], i: usize, word: &str) -> bool {
    (i == 0 || !is_ident_char(c[i - 1])) && word.chars().enumerate().all(|(k, w)| c.get(i + k) == Some(&w))
}

/// Where the bracket opened at `open` closes (the end of the code if it does not).
fn closing(c: &[char], open: usize) -> usize {
    let (o, e) = match c.get(open) {
        Some('(') => ('(', ')'),
        Some('[') => ('[', ']'),
        _ => ('{', '}'),
    };
    let mut depth = 0;
    for (k, &ch) in c.iter().enumerate().skip(open) {
        if ch == o {
            depth += 1;
        } else if ch == e {
            depth -= 1;
            if depth == 0 {
                return k;
            }
        }
    }
    c.len()
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

/// The names of the `macro_rules!` macros some code defines.
fn macro_names(code: &str) -> Vec<String> {
    code.match_indices("macro_rules!")
        .filter_map(|(i, m)| {
            let name: String = code[i + m.len()..].trim_start().chars().take_while(|c| is_ident_char(*c)).collect();
            (!name.is_empty()).then_some(name)
        })
        .collect()
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
    let texts: BTreeMap<&String, String> = modules
        .iter()
        .map(|(m, file)| (m, without_macro_bodies(&without_quoted(&code(&std::fs::read_to_string(file).unwrap())))))
        .collect();
    // `#[macro_export]` puts a macro at the crate root whatever module defines it: `crate::__x` names the
    // module of `macro_rules! __x`.
    let macros: BTreeMap<String, &String> = texts.iter().flat_map(|(m, text)| macro_names(text).into_iter().map(move |n| (n, *m))).collect();
    let mut out = BTreeMap::new();
    for (module, text) in &texts {
        let module = *module;
        let mut named: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        let pieces = inline_modules(text);
        for (inline, path) in pieces.iter().flat_map(|(inline, text)| paths(text).into_iter().map(move |p| (inline, p))) {
            let here: Vec<String> = split(module).into_iter().chain(inline.iter().cloned()).collect();
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
            if path[0] == "crate" {
                if let Some(defined) = macros.get(&path[1]) {
                    if *defined != module {
                        named.entry((*defined).clone()).or_default().insert(path.join("::"));
                    }
                    continue;
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
                edges.entry(a.clone()).or_default().entry(b).or_default().extend(how.iter().map(|h| format!("{}: {h}", shown(from))));
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

/// The workspace's folder (the compiler's parent).
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// The library crates of the workspace: the members of its `Cargo.toml` with a `src/lib.rs`, by folder.
fn libraries() -> Vec<String> {
    let manifest = std::fs::read_to_string(workspace().join("Cargo.toml")).unwrap();
    let start = manifest.find("members = [").expect("the workspace's members") + "members = [".len();
    let list = &manifest[start..start + manifest[start..].find(']').unwrap()];
    let mut out: Vec<String> = list
        .split(',')
        .map(|m| m.split('#').next().unwrap().trim().trim_matches('"').to_string())
        .filter(|m| !m.is_empty() && workspace().join(m).join("src/lib.rs").is_file())
        .collect();
    out.sort();
    out
}

fn imports_of(krate: &str) -> BTreeMap<String, BTreeMap<String, BTreeSet<String>>> {
    imports(&modules(&workspace().join(krate).join("src")))
}

/// A module as messages name it: the crate root as `(crate root)`.
fn shown(module: &str) -> &str {
    if module.is_empty() {
        "(crate root)"
    } else {
        module
    }
}

fn loop_text(found: &[(Vec<String>, Vec<String>)]) -> String {
    let text: Vec<String> =
        found.iter().map(|(ms, ties)| format!("{}\n    {}", ms.iter().map(|m| shown(m)).collect::<Vec<_>>().join(" <-> "), ties.join("\n    "))).collect();
    text.join("\n")
}

fn assert_no_loops(krate: &str, scope: &str) {
    let all = imports_of(krate);
    assert!(all.keys().any(|m| m.starts_with(scope)), "no module {scope} in {krate}");
    let found = loops(&all, scope);
    let which = if scope.is_empty() { format!("top-level modules of {krate}") } else { format!("modules of `{scope}` in {krate}") };
    assert!(found.is_empty(), "{which} that import each other:\n{}", loop_text(&found));
}

#[test]
fn no_loop_among_the_top_level_modules() {
    assert_no_loops("nodeset-compiler", "");
}

#[test]
fn no_loop_inside_the_modelica_back_end() {
    assert_no_loops("nodeset-compiler", "emit::modelica");
}

#[test]
fn no_loop_among_the_runtimes_layers() {
    assert_no_loops("nodeset-runtime", "");
}

#[test]
fn no_loop_in_any_library_of_the_workspace() {
    let libraries = libraries();
    for known in ["nodeset-compiler", "nodeset-runtime", "generated", "process-support"] {
        assert!(libraries.iter().any(|l| l == known), "{known} not among the workspace's libraries {libraries:?}");
    }
    let mut failures = Vec::new();
    for krate in &libraries {
        let found = loops(&imports_of(krate), "");
        if !found.is_empty() {
            failures.push(format!("{krate}:\n{}", loop_text(&found)));
        }
    }
    assert!(failures.is_empty(), "top-level modules that import each other:\n{}", failures.join("\n"));
}

/// A crate's layers as its `lib.rs` documents them, from the bottom: the rows of the table under `# Layers`,
/// each starting with its module as ``[`name`]``.
fn documented_layers(lib_rs: &str) -> Vec<String> {
    let Some((_, section)) = lib_rs.split_once("//! # Layers") else { return Vec::new() };
    section
        .lines()
        .skip(1)
        .take_while(|l| l.starts_with("//!"))
        .filter_map(|l| Some(l.strip_prefix("//! | [`")?.split_once("`]")?.0.to_string()))
        .collect()
}

/// The imports that break the layers: a module naming one of a layer above its own, or naming the crate root
/// (which only re-exports). `layers` lists the top-level modules from the bottom.
fn upward(all: &BTreeMap<String, BTreeMap<String, BTreeSet<String>>>, layers: &[String]) -> Vec<String> {
    let rank = |m: &str| layers.iter().position(|l| l == m.split("::").next().unwrap());
    let mut out = Vec::new();
    for (from, named) in all {
        for (to, how) in named {
            let how: Vec<&str> = how.iter().map(String::as_str).take(3).collect();
            match (from.is_empty(), to.is_empty(), rank(from), rank(to)) {
                (false, true, _, _) => out.push(format!("{from} names the crate root: {}", how.join(", "))),
                (false, false, Some(a), Some(b)) if b > a => {
                    out.push(format!("{from} (layer `{}`) names {to} (layer `{}`, above it): {}", layers[a], layers[b], how.join(", ")))
                }
                _ => {}
            }
        }
    }
    out
}

#[test]
fn the_runtimes_modules_use_only_the_layers_below_them() {
    let lib = std::fs::read_to_string(workspace().join("nodeset-runtime/src/lib.rs")).unwrap();
    let layers = documented_layers(&lib);
    let all = imports_of("nodeset-runtime");
    let top: BTreeSet<&str> = all.keys().filter(|m| !m.is_empty()).map(|m| m.split("::").next().unwrap()).collect();
    let listed: BTreeSet<&str> = layers.iter().map(String::as_str).collect();
    assert!(
        listed == top && listed.len() == layers.len(),
        "the table under `# Layers` in nodeset-runtime/src/lib.rs lists {layers:?}; it must name each of the modules {top:?} once"
    );
    let wrong = upward(&all, &layers);
    assert!(wrong.is_empty(), "imports against the runtime's layers ({}):\n{}", layers.join(" < "), wrong.join("\n"));
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
    assert_eq!(macro_names("#[macro_export]\nmacro_rules! __x { () => {} }"), ["__x"]);
    // A macro's body keeps only its absolute paths; an inline module resolves `super::` from itself.
    let text = "macro_rules! m { ($t:ty) => { impl $crate::typed::T for $t { const N: u16 = super::super::NS; } }; }\n\
                fn f() {} mod tests { use super::f; mod deeper { use super::super::g; } }";
    let pieces = inline_modules(&without_macro_bodies(&code(text)));
    let found: BTreeSet<(String, String)> =
        pieces.iter().flat_map(|(at, t)| paths(t).into_iter().map(move |p| (at.join("::"), p.join("::")))).collect();
    let want: BTreeSet<(String, String)> = [("", "crate::typed::T"), ("tests", "super::f"), ("tests::deeper", "super::super::g")]
        .into_iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    assert_eq!(found.into_iter().filter(|(_, p)| p.contains("::")).collect::<BTreeSet<_>>(), want);
    let doc = "//! # Layers\n//!\n//! | layer | what |\n//! |---|---|\n//! | [`low`] | a |\n//! | [`high`] | b |\n\npub mod low;";
    assert_eq!(documented_layers(doc), ["low", "high"]);
    let mut all: BTreeMap<String, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    all.entry("high::x".into()).or_default().entry("low".into()).or_default().insert("crate::low::A".into());
    all.entry("".into()).or_default().entry("high".into()).or_default().insert("high::B".into());
    assert!(upward(&all, &documented_layers(doc)).is_empty());
    all.entry("low".into()).or_default().entry("high::x".into()).or_default().insert("crate::high::x::C".into());
    all.entry("low".into()).or_default().entry("".into()).or_default().insert("crate::D".into());
    let wrong = upward(&all, &documented_layers(doc));
    assert_eq!(wrong.len(), 2, "{wrong:?}");
}
