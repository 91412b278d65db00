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
    for ns in &report.unknown_namespaces {
        let _ = writeln!(s, "note: no loaded nodeset defines the server's namespace {ns}; its types are not checked");
    }
    s
}

/// The report as one JSON object: `url`, `checked`, `instances`, `violations`, `warnings`, `round_trips`,
/// `millis`, `unknown_namespaces`, `namespaces` (the server's NamespaceArray, which numbers the prefixes of the
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
