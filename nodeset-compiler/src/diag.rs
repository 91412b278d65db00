//! Diagnostics: one type for every stage, stable codes, rustc-style rendering.
//!
//! A stage pushes every problem it finds into a [`Diagnostics`] collector and the driver decides at the end of
//! the stage whether to stop. Codes are stable: tests, docs and users refer to them (`NS0201` is always a
//! duplicate NodeId). The table in [`Code`] is the reference list.

use crate::source::{SourceMap, Span};
use std::fmt::Write as _;

/// How serious a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// Makes the stage fail.
    Error,
    /// Reported; the stage goes on (with the code's recovery).
    Warning,
    /// Information only: printed, counted neither as an error nor as a warning. NS0115 (a superset file of
    /// a model chosen over its subset, a safe choice the user may want to know about) is one by default.
    Note,
}

impl Severity {
    /// The word that starts the rendered header: `error`, `warning` or `note`.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        }
    }
}

macro_rules! codes {
    ($($variant:ident = $code:literal, $sev:ident, $title:literal, $recovery:expr;)*) => {
        /// Every diagnostic the compiler can emit, with its stable code, default severity and recovery.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Code { $(#[doc = $title] $variant),* }

        impl Code {
            /// Every code, in the order of the table.
            pub const ALL: &'static [Code] = &[$(Code::$variant),*];
            /// The stable code, such as `NS0201`.
            pub fn as_str(self) -> &'static str { match self { $(Code::$variant => $code),* } }
            /// The severity this diagnostic has unless a [`Severities`] setting changes it.
            pub fn default_severity(self) -> Severity { match self { $(Code::$variant => Severity::$sev),* } }
            /// One line saying what the code means.
            pub fn title(self) -> &'static str { match self { $(Code::$variant => $title),* } }
            /// What the compiler does instead when it meets the problem, so that it can go on: for a warning,
            /// what it always does; for an error, what it does when the error is demoted (`--warn CODE`).
            /// `None` for an error with no safe recovery, which cannot be demoted.
            pub fn recovery(self) -> Option<&'static str> { match self { $(Code::$variant => $recovery),* } }
        }
    };
}

const NO: Option<&str> = None;
/// What demoting a finding of the instance rules does: checking goes on either way, so only the exit status
/// changes.
const VERIFY_RECOVERY: Option<&str> = Some("the finding is reported as a warning (or, allowed, not at all) and does not fail check or verify");

codes! {
    // Reading and parsing one file.
    Io = "NS0001", Error, "the file cannot be read", NO;
    Encoding = "NS0002", Error, "the file is not UTF-8", NO;
    XmlSyntax = "NS0003", Error, "the file is not well-formed XML", NO;
    Truncated = "NS0004", Error, "the file ends inside an element", NO;
    Doctype = "NS0005", Error, "DOCTYPE declarations are rejected", NO;
    NotNodeSet = "NS0006", Error, "the root element is not UANodeSet", NO;
    TooDeep = "NS0007", Error, "elements are nested too deeply", NO;
    BadAttribute = "NS0008", Error, "an attribute value is malformed",
        Some("the attribute is read as absent, so its default applies (a malformed ArrayDimensions entry is skipped)");
    MissingAttribute = "NS0009", Error, "a required attribute is missing", NO;
    UnknownElement = "NS0010", Warning, "an element is not part of UANodeSet.xsd and is ignored", Some("the element is ignored");
    TooLarge = "NS0011", Error, "a value exceeds a size limit", NO;
    AccessLevelRange = "NS0012", Error, "an AccessLevel or UserAccessLevel does not fit in a Byte",
        Some("the value is masked to its low byte (the bits above it belong to AccessLevelEx)");
    // Loading a set of files.
    MissingModel = "NS0101", Error, "a required model is not available", NO;
    ModelTooOld = "NS0102", Error, "a required model is available only in an older version", NO;
    ModelDateOlder = "NS0103", Warning, "a required model is older than the required publication date",
        Some("the older model is used");
    DuplicateModel = "NS0104", Error, "two input files define the same model", NO;
    ModelCycle = "NS0105", Error, "models require each other in a cycle", NO;
    UnknownNamespaceIndex = "NS0106", Error, "a namespace index is not declared in NamespaceUris", NO;
    MalformedNodeId = "NS0107", Error, "a NodeId is malformed", NO;
    UnknownAlias = "NS0108", Error, "an alias is not declared", NO;
    NoModel = "NS0109", Warning, "the file declares no model", Some("each namespace it defines nodes in becomes a model without version; the namespaces it only refers to are looked for in the named files and the model folders");
    DuplicateAlias = "NS0110", Error, "an alias is declared twice with different targets", Some("the first declaration is kept");
    MalformedQualifiedName = "NS0111", Error, "a QualifiedName is malformed", NO;
    UnknownNamespaceUri = "NS0112", Error, "a namespace URI names no loaded model", NO;
    AliasByBrowseName = "NS0113", Warning, "an undeclared alias was resolved by the BrowseName of a base type",
        Some("the base DataType or ReferenceType of that BrowseName is used");
    AmbiguousModel = "NS0114", Error, "different files of the model folders define one model in the same version and publication date", NO;
    ModelFilesDiffer = "NS0115", Note, "different files of the model folders define one model in the same version and publication date, one holding every node of the others",
        Some("the file holding every node of the others is used");
    // Resolving one model of all files.
    DuplicateNodeId = "NS0201", Error, "a NodeId is defined twice", Some("the first definition is kept and the second is ignored");
    DanglingReference = "NS0202", Error, "a reference points to a node that does not exist", Some("the reference is dropped");
    BadReferenceType = "NS0203", Error, "a reference type is not a ReferenceType node", Some("the reference is dropped");
    SubtypeCycle = "NS0204", Error, "a type is its own supertype",
        Some("the cycle is broken: the type the diagnostic points at loses its supertype");
    BadTypeDefinition = "NS0205", Error, "a TypeDefinition has the wrong node class",
        Some("the TypeDefinition is ignored, as if the instance had none");
    BrowseNameCollision = "NS0206", Warning, "two children of one node share a BrowseName", Some("both children are kept");
    UnknownFieldType = "NS0207", Error, "a structure field has an unknown DataType", NO;
    DuplicateEnumValue = "NS0208", Error, "an enumeration, OptionSet or structure repeats a value or a name",
        Some("the later entry is dropped");
    ValueTypeMismatch = "NS0209", Warning, "a value in a type contradicts its DataType (an instance's value: NS0406)", Some("the value is kept as written");
    BadSubtype = "NS0210", Error, "a HasSubtype reference joins nodes of different classes",
        Some("the wrong supertype is ignored (of several supertypes, the first is used)");
    MissingTypeDefinition = "NS0211", Warning, "an instance has no TypeDefinition", Some("the instance is generated without a type");
    BadDataType = "NS0212", Error, "a DataType attribute does not name a DataType node",
        Some("the DataType attribute is ignored, so the variable takes any value (BaseDataType)");
    BadArgument = "NS0213", Warning, "a method argument cannot be decoded", Some("the argument list is left empty");
    BadValue = "NS0214", Warning, "a value cannot be decoded", Some("the value is left out");
    DanglingForeignReference = "NS0215", Warning, "a reference points to a missing node of another model", Some("the reference is dropped");
    BadModellingRule = "NS0216", Warning, "a ModellingRule reference names no known rule", Some("the ModellingRule is ignored");
    StateMachine = "NS0217", Warning, "a state machine's states or transitions are inconsistent",
        Some("the inconsistent states or transitions are left out of the state machine");
    IdenticalRedefinition = "NS0218", Warning, "a node is defined again, identically, by another file",
        Some("the copy is ignored; the node loaded first is used");
    EnumValueChoice = "NS0219", Warning, "an enumeration's definition disagrees with its EnumValues or EnumStrings property",
        Some("the property decides the values");
    BadRolePermission = "NS0220", Error, "a RolePermission names a node that is not a role",
        Some("the entry is dropped: the node grants that role nothing");
    IncompatibleOverride = "NS0221", Warning, "a declaration overrides one of a supertype it is not compatible with",
        Some("the override is used as declared");
    TwoModellingRules = "NS0222", Warning, "a node has HasModellingRule references to two different rules", Some("the last one is kept; the others are left out of the node tables, so that a server sees the rule the model has");
    // Generating code.
    NameCollision = "NS0301", Warning, "two names map to one identifier in generated code", Some("the names are told apart by a suffix");
    UnsupportedFeature = "NS0302", Warning, "a model feature has no faithful representation in generated code",
        Some("the feature is left out of the generated code");
    Ns0Named = "NS0303", Error, "the base namespace is named for Rust, which async-opcua provides",
        Some("the base namespace is not generated: generated code uses async-opcua's, as when its file is only in --models");
    MappedNeedsGenerated = "NS0304", Error, "a namespace mapped to existing code requires a namespace this run generates", NO;
    // Instances against their types: the static instances of the files (`nodeset-compiler check`) and a live
    // server's (`nodeset-compiler verify`), by one checker.
    MissingMember = "NS0401", Error, "a mandatory member (or anything in a mandatory placeholder's place) is missing", VERIFY_RECOVERY;
    WrongNodeClass = "NS0402", Error, "a member has another NodeClass than its declaration", VERIFY_RECOVERY;
    WrongTypeDefinition = "NS0403", Error, "a TypeDefinition is neither the declared type nor a subtype of it", VERIFY_RECOVERY;
    WrongDataType = "NS0404", Error, "a DataType is neither the declared DataType nor a subtype of it", VERIFY_RECOVERY;
    WrongValueRank = "NS0405", Error, "a ValueRank is not compatible with the declared ValueRank", VERIFY_RECOVERY;
    WrongValueType = "NS0406", Error, "a value's built-in type or shape does not match its DataType and ValueRank", VERIFY_RECOVERY;
    WrongPlaceholderType = "NS0407", Error, "a member in a placeholder's place is not of the placeholder's type", VERIFY_RECOVERY;
    InstanceModellingRule = "NS0408", Error, "an instance has a ModellingRule", VERIFY_RECOVERY;
    UnknownRemoteType = "NS0409", Error, "a server node names a type or DataType the loaded nodesets do not define",
        Some("the node is not checked against that type (its children are checked against their own types)");
}

impl Code {
    /// Whether `--warn CODE` and `--allow CODE` are accepted: every warning, and every error with a recovery.
    pub fn demotable(self) -> bool {
        self.default_severity() != Severity::Error || self.recovery().is_some()
    }

    /// The code named `text` (`NS0201`, case-insensitive).
    pub fn parse(text: &str) -> Option<Code> {
        Code::ALL.iter().copied().find(|c| c.as_str().eq_ignore_ascii_case(text.trim()))
    }

    /// The table of codes as `nodeset-compiler codes` prints it: code, default severity, meaning, and what
    /// the compiler does instead (or that the error cannot be demoted).
    pub fn table() -> String {
        let mut out = String::new();
        for c in Code::ALL {
            let _ = writeln!(out, "{} {:<7} {}", c.as_str(), c.default_severity().as_str(), c.title());
            match (c.recovery(), c.default_severity()) {
                (Some(r), Severity::Error) => {
                    let _ = writeln!(out, "       demotable: with --warn {} or --allow {}, {r}", c.as_str(), c.as_str());
                }
                (Some(r), _) => {
                    let _ = writeln!(out, "       recovery: {r}");
                }
                (None, _) => {
                    let _ = writeln!(out, "       cannot be demoted: there is no safe recovery");
                }
            }
        }
        out
    }
}

/// A severity setting for one code, as rustc's lint levels: `--allow`, `--warn`, `--deny`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Level {
    /// Drop the diagnostic (an error only when it has a recovery, which then happens silently).
    Allow,
    /// Report it as a warning (an error only when it has a recovery, which then happens).
    Warn,
    /// Report it as an error: the stage fails.
    Deny,
}

impl Level {
    /// The flag that sets this level: `allow`, `warn` or `deny`.
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Allow => "allow",
            Level::Warn => "warn",
            Level::Deny => "deny",
        }
    }
}

/// Why a severity setting was refused.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SeverityError {
    /// The text names no code.
    UnknownCode(String),
    /// The code is an error with no safe recovery, so it cannot be warned about or allowed.
    NotDemotable {
        /// The code that was to be demoted.
        code: Code,
        /// The level asked for.
        level: Level,
    },
}

impl std::fmt::Display for SeverityError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SeverityError::UnknownCode(t) => {
                write!(f, "`{t}` is not a diagnostic code (codes look like NS0201; `nodeset-compiler codes` lists them)")
            }
            SeverityError::NotDemotable { code, level } => write!(
                f,
                "--{} {} is refused: {} ({}) is an error with no safe recovery, so it cannot be demoted",
                level.as_str(),
                code.as_str(),
                code.as_str(),
                code.title()
            ),
        }
    }
}

impl std::error::Error for SeverityError {}

/// How severe each diagnostic is, beyond its code's default: the `--allow`, `--warn` and `--deny` settings of
/// every front door (the command line, [`crate::build::Builder`], `cargo xtask generate`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Severities {
    levels: std::collections::BTreeMap<Code, Level>,
    deny_warnings: bool,
}

impl Severities {
    /// The defaults: every code at its default severity.
    pub fn new() -> Severities {
        Severities::default()
    }

    /// Sets the level of one code. A later setting of the same code replaces an earlier one. Refuses to
    /// demote an error that has no recovery.
    pub fn set(&mut self, code: Code, level: Level) -> Result<(), SeverityError> {
        if level != Level::Deny && !code.demotable() {
            return Err(SeverityError::NotDemotable { code, level });
        }
        self.levels.insert(code, level);
        Ok(())
    }

    /// Sets a level from its command-line text: a code such as `NS0202`, or `warnings` with [`Level::Deny`]
    /// (`--deny warnings`).
    pub fn set_named(&mut self, level: Level, what: &str) -> Result<(), SeverityError> {
        if level == Level::Deny && what.trim() == "warnings" {
            self.deny_warnings = true;
            return Ok(());
        }
        let code = Code::parse(what).ok_or_else(|| SeverityError::UnknownCode(what.to_string()))?;
        self.set(code, level)
    }

    /// Turns every warning into an error (`--deny warnings`), except codes given a level of their own.
    pub fn deny_warnings(&mut self, on: bool) {
        self.deny_warnings = on;
    }

    /// Whether `--deny warnings` is set.
    pub fn denies_warnings(&self) -> bool {
        self.deny_warnings
    }

    /// The level set for `code`, if any.
    pub fn level(&self, code: Code) -> Option<Level> {
        self.levels.get(&code).copied()
    }

    /// The severity a diagnostic of `code` reported as `severity` has under these settings, or `None` when
    /// `--allow` drops it. A setting for the code outranks `--deny warnings`.
    pub fn severity(&self, code: Code, severity: Severity) -> Option<Severity> {
        match self.level(code) {
            Some(Level::Allow) => None,
            Some(Level::Warn) => Some(Severity::Warning),
            Some(Level::Deny) => Some(Severity::Error),
            None if self.deny_warnings && severity == Severity::Warning => Some(Severity::Error),
            None => Some(severity),
        }
    }
}

/// A secondary position with a message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Label {
    /// Where the label points.
    pub span: Span,
    /// The text shown beside the position's `-` marks.
    pub message: String,
}

/// One problem found by a stage: its code, severity, message, positions, notes and help.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// How severe it is: the code's default severity unless changed (see [`Diagnostics::apply`]).
    pub severity: Severity,
    /// What kind of problem it is.
    pub code: Code,
    /// The headline, shown after the severity and code (`error[NS0201]: ...`).
    pub message: String,
    /// The primary position, if the problem has one.
    pub span: Option<Span>,
    /// Text under the caret of the primary span.
    pub span_label: Option<String>,
    /// Secondary positions, each marked with `-` and its message.
    pub labels: Vec<Label>,
    /// Notes, shown after the source lines as `= note: ...`.
    pub notes: Vec<String>,
    /// A suggestion, shown last as `= help: ...`.
    pub help: Option<String>,
}

impl Diagnostic {
    /// A diagnostic of `code` at its default severity, with no position, labels, notes or help.
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

    /// Sets the primary position.
    pub fn at(mut self, span: Span) -> Self {
        self.span = Some(span);
        self
    }

    /// Sets the text under the caret of the primary position.
    pub fn with_span_label(mut self, label: impl Into<String>) -> Self {
        self.span_label = Some(label.into());
        self
    }

    /// Adds a secondary position with a message.
    pub fn label(mut self, span: Span, message: impl Into<String>) -> Self {
        self.labels.push(Label { span, message: message.into() });
        self
    }

    /// Adds a note.
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// Sets the help text, replacing any earlier one.
    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// Whether the severity is [`Severity::Error`].
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
    /// The diagnostics, in the order they were pushed until [`Diagnostics::sort`] sorts them.
    pub items: Vec<Diagnostic>,
}

impl Diagnostics {
    /// An empty collector.
    pub fn new() -> Diagnostics {
        Diagnostics::default()
    }

    /// Adds one diagnostic.
    pub fn push(&mut self, d: Diagnostic) {
        self.items.push(d);
    }

    /// Appends every diagnostic of `other`.
    pub fn extend(&mut self, other: Diagnostics) {
        self.items.extend(other.items);
    }

    /// Whether any diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.items.iter().any(Diagnostic::is_error)
    }

    /// The number of errors.
    pub fn error_count(&self) -> usize {
        self.items.iter().filter(|d| d.severity == Severity::Error).count()
    }

    /// The number of warnings.
    pub fn warning_count(&self) -> usize {
        self.items.iter().filter(|d| d.severity == Severity::Warning).count()
    }

    /// Gives every diagnostic the severity `severities` sets for it: `--allow CODE` drops it, `--warn CODE`
    /// makes it a warning, `--deny CODE` an error, and `--deny warnings` turns every other warning into an
    /// error. A setting for a code outranks `--deny warnings`. Applying the same settings twice changes nothing.
    pub fn apply(&mut self, severities: &Severities) {
        self.items.retain_mut(|d| match severities.severity(d.code, d.severity) {
            Some(s) => {
                d.severity = s;
                true
            }
            None => false,
        });
    }

    /// The end of every stage and front door: applies `severities`, sorts, renders, and fails when errors
    /// remain. Returns the rendered diagnostics either way (the caller prints or passes them on); `stage`
    /// says what failed (`"the NodeSet2 files do not compile"`).
    pub fn finalize(&mut self, severities: &Severities, sources: &SourceMap, stage: &str) -> Result<String, Error> {
        self.apply(severities);
        self.sort(sources);
        let rendered = self.render(sources);
        if self.has_errors() {
            return Err(Error::Diagnostics { stage: stage.to_string(), errors: self.error_count(), rendered });
        }
        Ok(rendered)
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

    /// Renders every diagnostic in order, each followed by an empty line.
    pub fn render(&self, sources: &SourceMap) -> String {
        let mut out = String::new();
        for d in &self.items {
            out.push_str(&d.render(sources));
            out.push('\n');
        }
        out
    }
}

/// Everything that can stop a front door, typed so that callers can tell a bad input from a bad setting
/// from a failed write.
#[derive(Debug)]
pub enum Error {
    /// A stage found errors in the input: `stage` says which, `rendered` holds every diagnostic as rustc
    /// would print them.
    Diagnostics {
        /// What failed, such as "the NodeSet2 files do not compile".
        stage: String,
        /// The number of errors.
        errors: usize,
        /// The rendered diagnostics, warnings included.
        rendered: String,
    },
    /// A severity setting was refused (an unknown code, or an error that cannot be demoted).
    Severity(SeverityError),
    /// A setting is malformed or missing (`--extern` without `=`, no `OUT_DIR`).
    Config(String),
    /// Writing or comparing the output failed.
    Write(String),
    /// Check mode found output that differs from what would be generated.
    Stale(String),
}

impl Error {
    /// The rendered diagnostics an [`Error::Diagnostics`] carries (empty for the other kinds).
    pub fn diagnostics(&self) -> &str {
        match self {
            Error::Diagnostics { rendered, .. } => rendered,
            _ => "",
        }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Diagnostics { stage, errors, rendered } => {
                write!(f, "{stage} ({errors} error(s)); nothing was written:\n{rendered}")
            }
            Error::Severity(e) => e.fmt(f),
            Error::Config(m) | Error::Write(m) | Error::Stale(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Severity(e) => Some(e),
            _ => None,
        }
    }
}

impl From<SeverityError> for Error {
    fn from(e: SeverityError) -> Error {
        Error::Severity(e)
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
