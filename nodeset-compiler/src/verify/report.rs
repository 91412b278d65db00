//! Renders a [`Report`]: rustc-style text like every other diagnostic of the compiler, or JSON for CI.

use super::check::Report;
use crate::diag::Severity;
use crate::source::SourceMap;
use std::fmt::Write as _;

/// The findings as text (each pointing at the violated declaration in its NodeSet2 file, with the
/// browse path and the server node in a note), then a summary.
pub fn render_text(report: &Report, sources: &SourceMap, url: &str, millis: u128) -> String {
    let mut out = String::new();
    for f in &report.findings {
        let mut d = f.diagnostic.clone();
        d.notes.insert(0, format!("on the server: `{}` ({})", f.path, f.node));
        out.push_str(&d.render(sources));
        out.push('\n');
    }
    out.push_str(&summary(report, url, millis));
    out
}

/// One line: what was checked, how many violations, how many round trips and how long.
pub fn summary(report: &Report, url: &str, millis: u128) -> String {
    let warnings = report.warnings();
    let mut s = format!(
        "{url}: {} node(s) checked ({} instance(s) against their types), {} violation(s), {} warning(s), {} round trip(s), {} ms\n",
        report.checked,
        report.instances,
        report.violations(),
        warnings,
        report.round_trips,
        millis
    );
    if report.structures_compared > 0 || !report.structure_mismatches.is_empty() {
        let _ = writeln!(
            s,
            "{} structure value(s) read back and compared with the nodesets, {} differ",
            report.structures_compared,
            report.structure_mismatches.len()
        );
        for m in &report.structure_mismatches {
            let _ = writeln!(s, "error: structure value differs from the nodeset: {m}");
        }
    }
    for ns in &report.unknown_namespaces {
        let _ = writeln!(s, "note: no loaded nodeset defines the server's namespace {ns}; its types are not checked");
    }
    s
}

/// The report as one JSON object: `url`, `checked`, `instances`, `violations`, `warnings`, `round_trips`,
/// `millis`, `structures_compared`, `structure_mismatches` (path and first difference of each structure value
/// that reads back other than the nodesets give it), `unknown_namespaces`, `namespaces` (the server's NamespaceArray, which numbers the prefixes of the
/// paths) and `findings` (each with `code`, `severity`, `message`, `path`, `node`
/// and, when the declaration is known, `declaration` with `file`, `line` and `column`).
pub fn render_json(report: &Report, sources: &SourceMap, url: &str, millis: u128) -> String {
    let mut out = String::from("{");
    let _ = write!(
        out,
        "\"url\":{},\"checked\":{},\"instances\":{},\"violations\":{},\"warnings\":{},\"round_trips\":{},\"millis\":{},",
        json_str(url),
        report.checked,
        report.instances,
        report.violations(),
        report.warnings(),
        report.round_trips,
        millis
    );
    let unknown: Vec<String> = report.unknown_namespaces.iter().map(|u| json_str(u)).collect();
    let namespaces: Vec<String> = report.namespaces.iter().map(|u| json_str(u)).collect();
    let mismatches: Vec<String> = report.structure_mismatches.iter().map(|m| json_str(m)).collect();
    let _ = write!(
        out,
        "\"structures_compared\":{},\"structure_mismatches\":[{}],",
        report.structures_compared,
        mismatches.join(",")
    );
    let _ = write!(out, "\"unknown_namespaces\":[{}],\"namespaces\":[{}],\"findings\":[", unknown.join(","), namespaces.join(","));
    for (i, f) in report.findings.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        let d = &f.diagnostic;
        let severity = match d.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        };
        let _ = write!(
            out,
            "{{\"code\":{},\"severity\":{},\"message\":{},\"path\":{},\"node\":{}",
            json_str(d.code.as_str()),
            json_str(severity),
            json_str(&d.message),
            json_str(&f.path),
            json_str(&f.node)
        );
        if let Some(span) = d.span {
            let file = sources.get(span.file);
            let (line, col) = file.line_col(span.start);
            let _ = write!(out, ",\"declaration\":{{\"file\":{},\"line\":{line},\"column\":{col}}}", json_str(&file.display));
        }
        out.push('}');
    }
    out.push_str("]}\n");
    out
}

/// A JSON string literal.
pub fn json_str(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A browse path (`2:DeviceSet/1:Robot`) with each namespace index replaced by `namespaces[index]`
/// (`http://...DI/|DeviceSet/...`), so that paths of two numberings (a server's, a model's) compare.
pub fn path_by_uri(path: &str, namespaces: &[String]) -> String {
    let segments: Vec<String> = path
        .split('/')
        .map(|seg| match seg.split_once(':').and_then(|(ns, name)| Some((namespaces.get(ns.parse::<usize>().ok()?)?, name))) {
            Some((uri, name)) => format!("{uri}|{name}"),
            None => seg.to_owned(),
        })
        .collect();
    segments.join("/")
}

/// The `"namespaces"` array of a report [`render_json`] wrote.
pub fn json_namespaces(json: &str) -> Vec<String> {
    let Some(at) = json.find("\"namespaces\":[") else { return Vec::new() };
    let list = &json[at + 14..];
    let list = &list[..list.find(']').unwrap_or(list.len())];
    list.split(',').map(|u| u.trim().trim_matches('"').to_owned()).filter(|u| !u.is_empty()).collect()
}

/// The string value of `"key":"..."` at its first occurrence in `part`, unescaped.
fn json_field(part: &str, key: &str) -> String {
    let Some(at) = part.find(&format!("\"{key}\":\"")) else { return String::new() };
    let mut out = String::new();
    let mut chars = part[at + key.len() + 4..].chars();
    while let Some(c) = chars.next() {
        match c {
            '"' => break,
            '\\' => match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(n) => out.push(n),
                None => {}
            },
            c => out.push(c),
        }
    }
    out
}

/// (code, severity, path, message) of every finding of a report [`render_json`] wrote, in its order.
pub fn json_findings(json: &str) -> Vec<(String, String, String, String)> {
    json.split("{\"code\":")
        .skip(1)
        .map(|part| {
            let code: String = part.chars().skip(1).take_while(|&c| c != '"').collect();
            (code, json_field(part, "severity"), json_field(part, "path"), json_field(part, "message"))
        })
        .collect()
}

/// The declaration (file, line) of every finding of a report [`render_json`] wrote, in the order of
/// [`json_findings`]; `None` for a finding without one.
pub fn json_declarations(json: &str) -> Vec<Option<(String, usize)>> {
    json.split("{\"code\":")
        .skip(1)
        .map(|part| {
            let at = part.find("\"declaration\":{")?;
            let declaration = &part[at..];
            let file = json_field(declaration, "file");
            let line = declaration.split("\"line\":").nth(1)?.chars().take_while(char::is_ascii_digit).collect::<String>();
            Some((file, line.parse().ok()?))
        })
        .collect()
}

/// (code, severity, path by namespace URI) of every finding of a report [`render_json`] wrote, sorted:
/// comparable with [`super::instances::static_findings_by_uri`] across two numberings of the namespaces.
pub fn json_findings_by_uri(json: &str) -> Vec<(String, String, String)> {
    let namespaces = json_namespaces(json);
    let mut out: Vec<(String, String, String)> =
        json_findings(json).into_iter().map(|(code, severity, path, _)| (code, severity, path_by_uri(&path, &namespaces))).collect();
    out.sort();
    out
}

/// The findings only one side has, each side compared as a multiset: `check only: CODE SEVERITY PATH` and
/// `verify only: ...`, sorted.
pub fn disagreements(checked: &[(String, String, String)], verified: &[(String, String, String)]) -> Vec<String> {
    let mut rest = verified.to_vec();
    let mut checked = checked.to_vec();
    checked.sort();
    let mut out = Vec::new();
    for c in checked {
        match rest.iter().position(|v| *v == c) {
            Some(i) => {
                rest.remove(i);
            }
            None => out.push(format!("check only: {} {} {}", c.0, c.1, c.2)),
        }
    }
    rest.sort();
    out.extend(rest.into_iter().map(|v| format!("verify only: {} {} {}", v.0, v.1, v.2)));
    out
}
