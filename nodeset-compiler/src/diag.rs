//! Diagnostics: one type for every stage, stable codes, rustc-style rendering.
//!
//! A stage pushes every problem it finds into a [`Diagnostics`] collector and the driver decides at the end of
//! the stage whether to stop. Codes are stable: tests, docs and users refer to them (`NS0201` is always a
//! duplicate NodeId). The table in [`Code`] is the reference list.

use crate::source::{SourceMap, Span};
use std::fmt::Write as _;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    Error,
    Warning,
    Note,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        }
    }
}

macro_rules! codes {
    ($($variant:ident = $code:literal, $sev:ident, $title:literal;)*) => {
        /// Every diagnostic the compiler can emit, with its stable code and default severity.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Code { $($variant),* }

        impl Code {
            pub const ALL: &'static [Code] = &[$(Code::$variant),*];
            /// The stable code, such as `NS0201`.
            pub fn as_str(self) -> &'static str { match self { $(Code::$variant => $code),* } }
            /// The severity this diagnostic has unless promoted by `--deny warnings`.
            pub fn default_severity(self) -> Severity { match self { $(Code::$variant => Severity::$sev),* } }
            /// One line saying what the code means.
            pub fn title(self) -> &'static str { match self { $(Code::$variant => $title),* } }
        }
    };
}

codes! {
    // Reading and parsing one file.
    Io = "NS0001", Error, "the file cannot be read";
    Encoding = "NS0002", Error, "the file is not UTF-8";
    XmlSyntax = "NS0003", Error, "the file is not well-formed XML";
    Truncated = "NS0004", Error, "the file ends inside an element";
    Doctype = "NS0005", Error, "DOCTYPE declarations are rejected";
    NotNodeSet = "NS0006", Error, "the root element is not UANodeSet";
    TooDeep = "NS0007", Error, "elements are nested too deeply";
    BadAttribute = "NS0008", Error, "an attribute value is malformed";
    MissingAttribute = "NS0009", Error, "a required attribute is missing";
    UnknownElement = "NS0010", Warning, "an element is not part of UANodeSet.xsd and is ignored";
    TooLarge = "NS0011", Error, "a value exceeds a size limit";
    // Loading a set of files.
    MissingModel = "NS0101", Error, "a required model is not available";
    ModelTooOld = "NS0102", Error, "a required model is available only in an older version";
    ModelDateOlder = "NS0103", Warning, "a required model is older than the required publication date";
    DuplicateModel = "NS0104", Error, "two input files define the same model";
    ModelCycle = "NS0105", Error, "models require each other in a cycle";
    UnknownNamespaceIndex = "NS0106", Error, "a namespace index is not declared in NamespaceUris";
    MalformedNodeId = "NS0107", Error, "a NodeId is malformed";
    UnknownAlias = "NS0108", Error, "an alias is not declared";
    NoModel = "NS0109", Warning, "the file declares no model";
    DuplicateAlias = "NS0110", Error, "an alias is declared twice with different targets";
    MalformedQualifiedName = "NS0111", Error, "a QualifiedName is malformed";
    UnknownNamespaceUri = "NS0112", Error, "a namespace URI names no loaded model";
    AliasByBrowseName = "NS0113", Warning, "an undeclared alias was resolved by the BrowseName of a base type";
    // Resolving one model of all files.
    DuplicateNodeId = "NS0201", Error, "a NodeId is defined twice";
    DanglingReference = "NS0202", Error, "a reference points to a node that does not exist";
    BadReferenceType = "NS0203", Error, "a reference type is not a ReferenceType node";
    SubtypeCycle = "NS0204", Error, "a type is its own supertype";
    BadTypeDefinition = "NS0205", Error, "a TypeDefinition has the wrong node class";
    BrowseNameCollision = "NS0206", Warning, "two children of one node share a BrowseName";
    UnknownFieldType = "NS0207", Error, "a structure field has an unknown DataType";
    DuplicateEnumValue = "NS0208", Error, "an enumeration, OptionSet or structure repeats a value or a name";
    ValueTypeMismatch = "NS0209", Warning, "a value contradicts its DataType";
    BadSubtype = "NS0210", Error, "a HasSubtype reference joins nodes of different classes";
    MissingTypeDefinition = "NS0211", Warning, "an instance has no TypeDefinition";
    BadDataType = "NS0212", Error, "a DataType attribute does not name a DataType node";
    BadArgument = "NS0213", Warning, "a method argument cannot be decoded";
    BadValue = "NS0214", Warning, "a value cannot be decoded";
    DanglingForeignReference = "NS0215", Warning, "a reference points to a missing node of another model";
    BadModellingRule = "NS0216", Warning, "a ModellingRule reference names no known rule";
    StateMachine = "NS0217", Warning, "a state machine's states or transitions are inconsistent";
    // Generating code.
    NameCollision = "NS0301", Warning, "two names map to one identifier in generated code";
    UnsupportedFeature = "NS0302", Warning, "a model feature has no faithful representation in generated code";
    Ns0Named = "NS0303", Error, "the base namespace is named for Rust, which async-opcua provides";
}

/// A secondary position with a message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Label {
    pub span: Span,
    pub message: String,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub severity: Severity,
    pub code: Code,
    pub message: String,
    /// The primary position, if the problem has one.
    pub span: Option<Span>,
    /// Text under the caret of the primary span.
    pub span_label: Option<String>,
    pub labels: Vec<Label>,
    pub notes: Vec<String>,
    pub help: Option<String>,
}

impl Diagnostic {
    pub fn new(code: Code, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            severity: code.default_severity(),
            code,
            message: message.into(),
            span: None,
            span_label: None,
            labels: Vec::new(),
            notes: Vec::new(),
            help: None,
        }
    }

    pub fn at(mut self, span: Span) -> Self {
        self.span = Some(span);
        self
    }

    pub fn with_span_label(mut self, label: impl Into<String>) -> Self {
        self.span_label = Some(label.into());
        self
    }

    pub fn label(mut self, span: Span, message: impl Into<String>) -> Self {
        self.labels.push(Label { span, message: message.into() });
        self
    }

    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// Renders the diagnostic like rustc does: header, `--> path:line:col`, the source line and a caret.
    pub fn render(&self, sources: &SourceMap) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "{}[{}]: {}", self.severity.as_str(), self.code.as_str(), self.message);
        let mut gutter = 0;
        let mut snippets = Vec::new();
        if let Some(span) = self.span {
            snippets.push((span, self.span_label.clone().unwrap_or_default(), '^'));
        }
        for l in &self.labels {
            snippets.push((l.span, l.message.clone(), '-'));
        }
        for (span, _, _) in &snippets {
            let (line, _) = sources.get(span.file).line_col(span.start);
            gutter = gutter.max(line.to_string().len());
        }
        let pad = " ".repeat(gutter);
        for (i, (span, message, mark)) in snippets.iter().enumerate() {
            let file = sources.get(span.file);
            let (line, col) = file.line_col(span.start);
            let arrow = if i == 0 && self.span.is_some() { "-->" } else { ":::" };
            let _ = writeln!(out, "{pad}{arrow} {}:{}:{}", file.display, line, col);
            let text = file.line_text(line);
            // Show at most 160 characters of a long line, around the caret.
            let chars: Vec<char> = text.chars().collect();
            let start_char = col.saturating_sub(1);
            let (shown_from, prefix) = if start_char > 100 { (start_char - 60, "...") } else { (0, "") };
            let shown: String = chars.iter().skip(shown_from).take(160).collect();
            let (end_line, end_col) = file.line_col(span.end);
            let width = if end_line == line && end_col > col { end_col - col } else { 1 };
            let width = width.min(160usize.saturating_sub(start_char - shown_from)).max(1);
            let caret_pad: String = chars
                .iter()
                .skip(shown_from)
                .take(start_char - shown_from)
                .map(|c| if *c == '\t' { '\t' } else { ' ' })
                .collect();
            let _ = writeln!(out, "{pad} |");
            let _ = writeln!(out, "{line:>gutter$} | {prefix}{}", shown.trim_end());
            let marks: String = std::iter::repeat(*mark).take(width).collect();
            let prefix_pad = " ".repeat(prefix.len());
            if message.is_empty() {
                let _ = writeln!(out, "{pad} | {prefix_pad}{caret_pad}{marks}");
            } else {
                let _ = writeln!(out, "{pad} | {prefix_pad}{caret_pad}{marks} {message}");
            }
        }
        if !snippets.is_empty() && (!self.notes.is_empty() || self.help.is_some()) {
            let _ = writeln!(out, "{pad} |");
        }
        for n in &self.notes {
            let _ = writeln!(out, "{pad} = note: {n}");
        }
        if let Some(h) = &self.help {
            let _ = writeln!(out, "{pad} = help: {h}");
        }
        out
    }
}

/// Collects the diagnostics of a stage.
#[derive(Clone, Debug, Default)]
pub struct Diagnostics {
    pub items: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn new() -> Diagnostics {
        Diagnostics::default()
    }

    pub fn push(&mut self, d: Diagnostic) {
        self.items.push(d);
    }

    pub fn extend(&mut self, other: Diagnostics) {
        self.items.extend(other.items);
    }

    pub fn has_errors(&self) -> bool {
        self.items.iter().any(Diagnostic::is_error)
    }

    pub fn error_count(&self) -> usize {
        self.items.iter().filter(|d| d.severity == Severity::Error).count()
    }

    pub fn warning_count(&self) -> usize {
        self.items.iter().filter(|d| d.severity == Severity::Warning).count()
    }

    /// Turns every warning into an error (`--deny warnings`).
    pub fn deny_warnings(&mut self) {
        for d in &mut self.items {
            if d.severity == Severity::Warning {
                d.severity = Severity::Error;
            }
        }
    }

    /// Sorts by file, position, then code, so that output does not depend on the order checks ran in.
    pub fn sort(&mut self, sources: &SourceMap) {
        self.items.sort_by(|a, b| {
            let key = |d: &Diagnostic| {
                d.span.map(|s| (sources.get(s.file).display.clone(), s.start)).unwrap_or_default()
            };
            key(a).cmp(&key(b)).then(a.code.cmp(&b.code)).then(a.message.cmp(&b.message))
        });
        self.items.dedup();
    }

    pub fn render(&self, sources: &SourceMap) -> String {
        let mut out = String::new();
        for d in &self.items {
            out.push_str(&d.render(sources));
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::SourceFile;

    #[test]
    fn codes_are_unique_and_well_formed() {
        let mut seen = std::collections::BTreeSet::new();
        for c in Code::ALL {
            assert!(seen.insert(c.as_str()), "duplicate code {}", c.as_str());
            assert!(c.as_str().starts_with("NS") && c.as_str().len() == 6);
        }
    }

    #[test]
    fn renders_like_rustc() {
        let mut map = SourceMap::new();
        let id = map.add(SourceFile::new("a.xml".into(), "a.xml".into(), "<a>\n  <b x=\"1\"/>\n</a>\n".into(), true));
        let d = Diagnostic::new(Code::BadAttribute, "bad x")
            .at(Span::new(id, 9, 14))
            .with_span_label("here")
            .help("write a number");
        let text = d.render(&map);
        assert_eq!(
            text,
            "error[NS0008]: bad x\n --> a.xml:2:6\n  |\n2 |   <b x=\"1\"/>\n  |      ^^^^^ here\n  |\n  = help: write a number\n"
        );
    }
}
