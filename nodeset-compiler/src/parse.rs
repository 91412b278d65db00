//! The NodeSet2 front end: one streaming pass of quick-xml over a file's text into a [`RawNodeSet`].
//!
//! Well-formedness problems (bad syntax, a truncated file, a DOCTYPE) stop the file with one error at the
//! exact position. Problems inside well-formed XML (a malformed number, a missing BrowseName) are collected
//! and parsing goes on, so one run reports them all.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::raw::*;
use crate::source::{FileId, Span, Spanned};
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;
use std::borrow::Cow;

/// Limits that keep hostile input from exhausting memory or the stack.
#[derive(Clone, Debug)]
pub struct Limits {
    /// Deepest element nesting accepted anywhere in a file.
    pub max_depth: usize,
    /// Deepest nesting inside one `<Value>` (ExtensionObjects within arrays within structures ...).
    pub max_value_depth: usize,
    /// Longest text content of one element, and longest attribute value, in bytes.
    pub max_text_len: usize,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits { max_depth: 128, max_value_depth: 64, max_text_len: 64 << 20 }
    }
}

/// Turns the bytes of a file into text: strips a UTF-8 BOM, rejects UTF-16 and invalid UTF-8.
///
/// On error, returns the diagnostic and the byte offset it refers to; the caller keeps a lossy copy of the
/// text so the diagnostic can still show the line.
pub fn decode_text_keeping(bytes: Vec<u8>) -> Result<String, (Diagnostic, usize, Vec<u8>)> {
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err((
            Diagnostic::new(Code::Encoding, "the file is UTF-16 (it starts with a UTF-16 byte order mark)")
                .help("save the file as UTF-8; NodeSet2 files are UTF-8 in practice and this compiler reads only UTF-8"),
            0,
            bytes,
        ));
    }
    if bytes.starts_with(&[0x3C, 0x00, 0x3F, 0x00]) || bytes.starts_with(&[0x00, 0x3C, 0x00, 0x3F]) {
        return Err((
            Diagnostic::new(Code::Encoding, "the file is UTF-16 (without a byte order mark)")
                .help("save the file as UTF-8; NodeSet2 files are UTF-8 in practice and this compiler reads only UTF-8"),
            0,
            bytes,
        ));
    }
    if let Some(at) = memchr::memchr(0, &bytes) {
        return Err((
            Diagnostic::new(Code::Encoding, format!("the file contains a NUL byte at byte {at}; it is not a text file"))
                .help("NodeSet2 files are UTF-8 text; check that the right file was given"),
            at,
            bytes,
        ));
    }
    let mut bytes = bytes;
    let bom = bytes.starts_with(&[0xEF, 0xBB, 0xBF]);
    if bom {
        bytes.drain(..3);
    }
    match String::from_utf8(bytes) {
        Ok(s) => Ok(s),
        Err(e) => {
            let at = e.utf8_error().valid_up_to() + if bom { 3 } else { 0 };
            let mut bytes = e.into_bytes();
            if bom {
                bytes.splice(0..0, [0xEF, 0xBB, 0xBF]);
            }
            Err((
                Diagnostic::new(Code::Encoding, format!("invalid UTF-8 at byte {at}"))
                    .with_span_label("this byte sequence is not UTF-8")
                    .help("NodeSet2 files must be UTF-8; re-encode the file (iconv -t UTF-8)"),
                at,
                bytes,
            ))
        }
    }
}

/// [`decode_text_keeping`] without the bytes in the error.
pub fn decode_text(bytes: Vec<u8>) -> Result<String, (Diagnostic, usize)> {
    decode_text_keeping(bytes).map_err(|(d, at, _)| (d, at))
}

mod events;
use events::{local, normalize_newlines};
mod pieces;

pub use pieces::parse_files;

/// Parses one file on the calling thread. Returns `None` when the file is not usable at all (its errors
/// are in `diags`). [`parse_files`] parses several files, and large files in pieces, on all cores.
pub fn parse(file: FileId, text: &str, limits: &Limits, diags: &mut Diagnostics) -> Option<RawNodeSet> {
    let mut p = Parser::new(file, text, 0..text.len(), limits, diags);
    p.document().ok().map(|part| part.set)
}

/// Marker for an error that stops the file; its diagnostic has been pushed.
struct Fatal;

type PResult<T> = Result<T, Fatal>;

enum Ev<'a> {
    Start(BytesStart<'a>, Span),
    End,
    /// Text and the byte offset it starts at.
    Text(Cow<'a, str>, usize),
    Eof,
}

struct Attr<'a> {
    key: &'a str,
    value: Cow<'a, str>,
    span: Span,
}

/// The root element as seen from a piece of a file that starts inside it (see [`pieces`]).
#[derive(Clone, Copy, Debug)]
struct OuterRoot<'a> {
    /// The name as written, with any prefix.
    qname: &'a str,
    /// The local name.
    name: &'a str,
    /// Where its start tag begins.
    start: usize,
}

/// How the reading of a file, or of a piece of it, ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PartEnd {
    /// At the end of the document.
    Document,
    /// At the end of a piece that stops before the file does, with only the root element open.
    Boundary,
}

/// What reading a file, or a piece of it, gave.
struct Part {
    set: RawNodeSet,
    /// Whether `<NamespaceUris>` and `<ServerUris>` were read (a later one replaces an earlier one).
    namespace_uris_seen: bool,
    server_uris_seen: bool,
    end: PartEnd,
}

struct Parser<'a, 'd> {
    file: FileId,
    text: &'a str,
    /// Reads `text[base..]` up to the end of the part being read.
    reader: Reader<&'a [u8]>,
    base: usize,
    /// Where the part being read ends in `text`.
    end: usize,
    /// Bytes the parser read itself (see [`Parser::scan_references`]), which quick-xml's positions lack.
    skipped: usize,
    /// Whether quick-xml stands between two pieces of markup, so that the parser may read on itself: after
    /// a start tag (not of an empty element) or an end tag, not after text.
    between_tags: bool,
    /// For a piece that starts inside the root element: the root, whose start tag quick-xml did not see, so
    /// the parser checks the end tags that close it (or that there is nothing to close) itself.
    outer_root: Option<OuterRoot<'a>>,
    /// Whether the part ends before the file does (a piece that is not the last).
    ends_early: bool,
    limits: &'a Limits,
    diags: &'d mut Diagnostics,
    /// Open elements: name and start offset, for truncation messages.
    open: Vec<(&'a str, usize)>,
    /// One attribute list, lent out by [`Parser::attrs`] and given back by [`Parser::recycle`], so that
    /// reading an element's attributes allocates nothing.
    attr_buf: Vec<Attr<'a>>,
    /// The open elements of the tree [`Parser::tree`] is reading: local name, start tag, text length so far.
    tree_stack: Vec<(&'a str, Span, usize)>,
    /// The elements of the file's values.
    values: ValueArena,
    /// The references of the nodes read so far (see [`RawNode::references`]).
    references: Vec<RawReference>,
    /// The open elements of the value being read, as indices into `values`.
    value_stack: Vec<u32>,
}

impl<'a, 'd> Parser<'a, 'd> {
    /// Reads a file from its start: the root element, and its content up to the end of the part.
    fn document(&mut self) -> PResult<Part> {
        // Find the root element.
        let (root, root_span) = loop {
            match self.next()? {
                Ev::Start(e, span) => break (e, span),
                Ev::Text(t, _) if t.trim().is_empty() => {}
                Ev::Text(t, at) => {
                    let lead = t.len() - t.trim_start().len();
                    let at = at + lead;
                    let d = Diagnostic::new(Code::XmlSyntax, "text before the root element")
                        .at(self.span(at, at + t.trim().len().min(40)))
                        .with_span_label("not markup")
                        .help("a NodeSet2 file holds only the XML declaration, comments and one <UANodeSet> element");
                    return Err(self.fatal(d));
                }
                Ev::End => unreachable!(),
                Ev::Eof => {
                    let d = Diagnostic::new(Code::NotNodeSet, "the file has no root element")
                        .at(self.span(0, 0))
                        .help("a NodeSet2 file starts with <UANodeSet xmlns=\"http://opcfoundation.org/UA/2011/03/UANodeSet.xsd\">");
                    return Err(self.fatal(d));
                }
            }
        };
        let root_name = String::from_utf8_lossy(local(root.name().into_inner())).into_owned();
        if root_name != "UANodeSet" {
            let d = Diagnostic::new(Code::NotNodeSet, format!("the root element is <{root_name}>, not <UANodeSet>"))
                .at(root_span)
                .help("pass only NodeSet2 files (root <UANodeSet>); .bsd, .xsd and CSV files are not NodeSets");
            return Err(self.fatal(d));
        }
        let attrs = self.attrs(&root, root_span)?;
        let last_modified = attrs.iter().find(|a| a.key == "LastModified").map(|a| a.value.to_string());
        self.recycle(attrs);
        let mut part = self.empty_part(root_span);
        part.set.last_modified = last_modified;
        self.root_content(&mut part)?;
        Ok(part)
    }

    /// Reads a piece of a file that starts inside the root element, between two of its children.
    fn piece(&mut self, root: OuterRoot<'a>, root_span: Span) -> PResult<Part> {
        self.outer_root = Some(root);
        // The end tags of the root and after it are checked in `next`.
        self.reader.config_mut().allow_unmatched_ends = true;
        self.open.push((root.name, root.start));
        let mut part = self.empty_part(root_span);
        self.root_content(&mut part)?;
        Ok(part)
    }

    fn empty_part(&self, root_span: Span) -> Part {
        let set = RawNodeSet {
            file: self.file,
            root_span,
            namespace_uris: Vec::new(),
            server_uris: Vec::new(),
            models: Vec::new(),
            aliases: Vec::new(),
            nodes: Vec::with_capacity(self.reader.get_ref().len() / 800),
            references: Vec::new(),
            last_modified: None,
            values: ValueArena::default(),
        };
        Part { set, namespace_uris_seen: false, server_uris_seen: false, end: PartEnd::Document }
    }

    /// Reads the children of the root element, and what follows the root, up to the end of the part.
    fn root_content(&mut self, part: &mut Part) -> PResult<()> {
        let set = &mut part.set;
        // Room for the nodes up front: a node is large, and a list grown by doubling copied each one about
        // once more. Every node element starts with `<UA`; the count may be a little high (a comment). A
        // real node takes hundreds of bytes, so no more than one per 64 bytes is reserved for: a file full
        // of `<UA` cannot make the room many times its own size (its list grows as it is read).
        let rest = self.text.as_bytes().get(self.pos()..self.end).unwrap_or_default();
        let mut room = memchr::memmem::find_iter(rest, b"<UA").count().min(rest.len() / 64);
        if self.base == 0 && self.ends_early {
            // The first piece of a file read in pieces: the later pieces are appended to this list (see
            // `pieces::join`), so it gets room for about the whole file's nodes, estimated from its own
            // share (room only: memory that is never written is never touched).
            let whole = self.text.len().saturating_sub(self.pos());
            room = (room * whole / rest.len().max(1) + room / 8).min(whole / 64);
        }
        set.nodes.reserve(room);
        loop {
            match self.next()? {
                Ev::Start(e, span) => {
                    let name = self.str_at(local(e.name().into_inner()));
                    match name {
                        "NamespaceUris" => {
                            set.namespace_uris = self.uri_list("NamespaceUris")?;
                            part.namespace_uris_seen = true;
                        }
                        "ServerUris" => {
                            set.server_uris = self.uri_list("ServerUris")?;
                            part.server_uris_seen = true;
                        }
                        "Models" => self.models(&mut set.models)?,
                        "Aliases" => self.aliases(&mut set.aliases)?,
                        "Extensions" => self.skip()?,
                        _ => match NodeClass::from_element(name) {
                            Some(class) => {
                                // Read in place: a node is large, and moving it out of `node` and into the
                                // list cost a copy or two of it per node. A node left half read by an error
                                // goes with the part, which the error discards.
                                set.nodes.push(RawNode::new(class, span));
                                let node = set.nodes.last_mut().expect("just pushed");
                                self.node(node, &e)?;
                            }
                            None => self.unknown(&e, span, "UANodeSet")?,
                        },
                    }
                }
                Ev::Text(..) => {}
                Ev::End => break,
                Ev::Eof => {
                    // Only a piece that ends before the file does stops here (see `next`).
                    set.values = std::mem::take(&mut self.values);
                    set.references = std::mem::take(&mut self.references);
                    part.end = PartEnd::Boundary;
                    return Ok(());
                }
            }
        }
        // Anything after the root other than comments and white space is malformed.
        loop {
            match self.next()? {
                Ev::Eof => break,
                Ev::Text(t, _) if t.trim().is_empty() => {}
                Ev::Start(_, span) => {
                    let d = Diagnostic::new(Code::XmlSyntax, "a second root element after </UANodeSet>")
                        .at(span)
                        .help("an XML document has exactly one root element; merge the content into <UANodeSet> or split the files");
                    return Err(self.fatal(d));
                }
                Ev::Text(t, at) => {
                    let at = at + (t.len() - t.trim_start().len());
                    let d = Diagnostic::new(Code::XmlSyntax, "content after </UANodeSet>")
                        .at(self.span(at, at + 1))
                        .help("remove everything after the closing </UANodeSet> tag");
                    return Err(self.fatal(d));
                }
                Ev::End => unreachable!("no element is open after the root"),
            }
        }
        set.values = std::mem::take(&mut self.values);
        set.references = std::mem::take(&mut self.references);
        part.end = PartEnd::Document;
        Ok(())
    }

    fn uri_list(&mut self, within: &str) -> PResult<Vec<Spanned<String>>> {
        let mut out = Vec::new();
        loop {
            match self.next()? {
                Ev::Start(e, span) => {
                    if local(e.name().into_inner()) == b"Uri" {
                        let v = self.text_content("Uri")?;
                        out.push(Spanned { value: v.trim().to_string(), span });
                    } else {
                        self.unknown(&e, span, within)?;
                    }
                }
                Ev::Text(..) => {}
                Ev::End => return Ok(out),
                Ev::Eof => unreachable!(),
            }
        }
    }

    fn models(&mut self, out: &mut Vec<RawModel>) -> PResult<()> {
        loop {
            match self.next()? {
                Ev::Start(e, span) => {
                    if local(e.name().into_inner()) != b"Model" {
                        self.unknown(&e, span, "Models")?;
                        continue;
                    }
                    let attrs = self.attrs(&e, span)?;
                    let get = |k: &str| attrs.iter().find(|a| a.key == k).map(|a| a.value.to_string());
                    let uri = match get("ModelUri") {
                        Some(u) => u,
                        None => {
                            self.missing(span, "Model", "ModelUri");
                            String::new()
                        }
                    };
                    let mut model = RawModel {
                        uri,
                        version: get("Version"),
                        publication_date: get("PublicationDate"),
                        model_version: get("ModelVersion"),
                        xml_schema_uri: get("XmlSchemaUri"),
                        required: Vec::new(),
                        role_permissions: Vec::new(),
                        access_restrictions: None,
                        span,
                    };
                    if let Some(a) = attrs.iter().find(|a| a.key == "AccessRestrictions") {
                        model.access_restrictions = self.number(a);
                    }
                    self.recycle(attrs);
                    loop {
                        match self.next()? {
                            Ev::Start(e, span) => match local(e.name().into_inner()) {
                                b"RequiredModel" => {
                                    let attrs = self.attrs(&e, span)?;
                                    let get =
                                        |k: &str| attrs.iter().find(|a| a.key == k).map(|a| a.value.to_string());
                                    let uri = get("ModelUri").unwrap_or_else(|| {
                                        self.missing(span, "RequiredModel", "ModelUri");
                                        String::new()
                                    });
                                    model.required.push(RawRequiredModel {
                                        uri,
                                        version: get("Version"),
                                        publication_date: get("PublicationDate"),
                                        model_version: get("ModelVersion"),
                                        xml_schema_uri: get("XmlSchemaUri"),
                                        span,
                                    });
                                    self.recycle(attrs);
                                    self.skip()?;
                                }
                                b"RolePermissions" => model.role_permissions = self.role_permissions()?,
                                _ => self.unknown(&e, span, "Model")?,
                            },
                            Ev::Text(..) => {}
                            Ev::End => break,
                            Ev::Eof => unreachable!(),
                        }
                    }
                    out.push(model);
                }
                Ev::Text(..) => {}
                Ev::End => return Ok(()),
                Ev::Eof => unreachable!(),
            }
        }
    }

    fn missing(&mut self, span: Span, element: &str, attr: &str) {
        self.diags.push(
            Diagnostic::new(Code::MissingAttribute, format!("<{element}> has no {attr} attribute"))
                .at(span)
                .help(format!("add {attr}=\"...\"; UANodeSet.xsd requires it")),
        );
    }

    fn aliases(&mut self, out: &mut Vec<RawAlias>) -> PResult<()> {
        loop {
            match self.next()? {
                Ev::Start(e, span) => {
                    if local(e.name().into_inner()) != b"Alias" {
                        self.unknown(&e, span, "Aliases")?;
                        continue;
                    }
                    let attrs = self.attrs(&e, span)?;
                    let alias = attrs.iter().find(|a| a.key == "Alias").map(|a| a.value.to_string());
                    self.recycle(attrs);
                    let text_start = self.pos();
                    let target = self.text_content("Alias")?;
                    let trimmed = target.trim();
                    let lead = target.len() - target.trim_start().len();
                    let tspan = self.span(text_start + lead, text_start + lead + trimmed.len());
                    match alias {
                        Some(alias) => out.push(RawAlias {
                            alias,
                            target: Spanned { value: trimmed.to_string(), span: tspan },
                            span,
                        }),
                        None => self.missing(span, "Alias", "Alias"),
                    }
                }
                Ev::Text(..) => {}
                Ev::End => return Ok(()),
                Ev::Eof => unreachable!(),
            }
        }
    }

    fn role_permissions(&mut self) -> PResult<Vec<RawRolePermission>> {
        let mut out = Vec::new();
        loop {
            match self.next()? {
                Ev::Start(e, span) => {
                    if local(e.name().into_inner()) != b"RolePermission" {
                        self.unknown(&e, span, "RolePermissions")?;
                        continue;
                    }
                    let attrs = self.attrs(&e, span)?;
                    let permissions = attrs.iter().find(|a| a.key == "Permissions").and_then(|a| self.number(a));
                    self.recycle(attrs);
                    let text_start = self.pos();
                    let role = self.text_content("RolePermission")?;
                    let lead = role.len() - role.trim_start().len();
                    let rspan = self.span(text_start + lead, text_start + lead + role.trim().len());
                    out.push(RawRolePermission {
                        role: Spanned { value: role.trim().to_string(), span: rspan },
                        permissions: permissions.unwrap_or(0),
                    });
                }
                Ev::Text(..) => {}
                Ev::End => return Ok(out),
                Ev::Eof => unreachable!(),
            }
        }
    }

    fn number<T: std::str::FromStr>(&mut self, a: &Attr<'a>) -> Option<T> {
        match a.value.trim().parse::<T>() {
            Ok(v) => Some(v),
            Err(_) => {
                let what = match std::any::type_name::<T>() {
                    "u8" => "a Byte (0 to 255)",
                    "u16" => "a UInt16 (0 to 65535)",
                    "u32" => "a UInt32 (0 to 4294967295)",
                    "i32" => "an Int32",
                    "i64" => "an Int64",
                    "f64" => "a Double",
                    _ => "a number",
                };
                self.diags.push(
                    Diagnostic::new(Code::BadAttribute, format!("{}=\"{}\" is not {what}", a.key, a.value))
                    .at(a.span)
                    .with_span_label("expected a number in range")
                    .help("see UANodeSet.xsd for the attribute's type"),
                );
                None
            }
        }
    }

    /// An AccessLevel is a Byte; files that write their AccessLevelEx there (`771`) get NS0012 and the low byte
    /// (the error's recovery, kept when it is demoted).
    fn access_level(&mut self, a: &Attr<'a>) -> Option<u8> {
        match a.value.trim().parse::<u32>() {
            Ok(v) if v > 0xFF => {
                self.diags.push(
                    Diagnostic::new(Code::AccessLevelRange, format!("{}=\"{}\" does not fit in a Byte", a.key, a.value))
                        .at(a.span)
                        .with_span_label(format!("read as {} (the low byte)", v & 0xFF))
                        .help("AccessLevel is a Byte (0 to 255); bits above it belong in AccessLevelEx"),
                );
                Some((v & 0xFF) as u8)
            }
            _ => self.number(a),
        }
    }

    fn boolean(&mut self, a: &Attr<'a>) -> Option<bool> {
        match a.value.trim() {
            "true" | "1" => Some(true),
            "false" | "0" => Some(false),
            other => {
                self.diags.push(
                    Diagnostic::new(Code::BadAttribute, format!("{}=\"{other}\" is not a boolean", a.key))
                        .at(a.span)
                        .help("write true or false"),
                );
                None
            }
        }
    }

    /// Reads a node element into `node`, a fresh [`RawNode::new`] of its class and start tag.
    fn node(&mut self, node: &mut RawNode, e: &BytesStart<'a>) -> PResult<()> {
        let (class, span) = (node.class, node.span);
        let attrs = self.attrs(e, span)?;
        let mut have_id = false;
        let mut have_bn = false;
        for a in &attrs {
            let spanned = || Spanned { value: a.value.to_string(), span: a.span };
            let raw = || self.raw_str(&a.value, a.span);
            match a.key {
                "NodeId" => {
                    node.node_id = raw();
                    have_id = true
                }
                "BrowseName" => {
                    node.browse_name = raw();
                    node.qualified_name = crate::nodeid::parse_qualified_name(&a.value).ok();
                    have_bn = true
                }
                "SymbolicName" => node.symbolic_name = Some(a.value.to_string()),
                "WriteMask" => node.write_mask = self.number(a),
                "UserWriteMask" => node.user_write_mask = self.number(a),
                "AccessRestrictions" => node.access_restrictions = self.number(a),
                "HasNoPermissions" => node.has_no_permissions = self.boolean(a),
                "ReleaseStatus" => node.release_status = Some(a.value.to_string()),
                "ParentNodeId" => node.parent_node_id = Some(raw()),
                "DataType" => node.data_type = Some(raw()),
                "ValueRank" => node.value_rank = self.number(a),
                "ArrayDimensions" => node.array_dimensions = Some(spanned()),
                "AccessLevel" => node.access_level = self.access_level(a),
                "UserAccessLevel" => node.user_access_level = self.access_level(a),
                "AccessLevelEx" => node.access_level_ex = self.number(a),
                "MinimumSamplingInterval" => node.minimum_sampling_interval = self.number(a),
                "Historizing" => node.historizing = self.boolean(a),
                "Executable" => node.executable = self.boolean(a),
                "UserExecutable" => node.user_executable = self.boolean(a),
                "MethodDeclarationId" => node.method_declaration_id = Some(raw()),
                "EventNotifier" => node.event_notifier = self.number(a),
                "ContainsNoLoops" => node.contains_no_loops = self.boolean(a),
                "IsAbstract" => node.is_abstract = self.boolean(a),
                "Symmetric" => node.symmetric = self.boolean(a),
                "Purpose" => node.purpose = Some(a.value.to_string()),
                _ => {}
            }
        }
        self.recycle(attrs);
        if !have_id {
            self.missing(span, class.element(), "NodeId");
        }
        if !have_bn {
            self.missing(span, class.element(), "BrowseName");
        }
        node.references.start = self.references.len() as u32;
        node.references.end = node.references.start;
        loop {
            match self.next()? {
                Ev::Start(e, cspan) => {
                    let name = local(e.name().into_inner());
                    match name {
                        b"DisplayName" => {
                            let t = self.localized(&e, cspan, "DisplayName")?;
                            node.display_names.push(t)
                        }
                        b"Description" => {
                            let t = self.localized(&e, cspan, "Description")?;
                            node.descriptions.push(t)
                        }
                        b"InverseName" => {
                            let t = self.localized(&e, cspan, "InverseName")?;
                            node.inverse_names.push(t)
                        }
                        b"Category" => {
                            let t = self.text_content("Category")?;
                            node.category.push(t.trim().to_string())
                        }
                        b"Documentation" => node.documentation = Some(self.text_content("Documentation")?.into_owned()),
                        b"References" => {
                            let mut out = std::mem::take(&mut self.references);
                            let read = self.references(&mut out);
                            self.references = out;
                            read?
                        }
                        b"RolePermissions" => node.role_permissions = self.role_permissions()?,
                        b"Extensions" => {
                            let mut sink = ElementSink::default();
                            self.tree(&e, cspan, usize::MAX, &mut sink)?;
                            node.extensions = sink.done.map(|tree| tree.children).unwrap_or_default();
                        }
                        b"Value" => node.value = self.value(&e, cspan)?,
                        b"Definition" => node.definition = Some(Box::new(self.definition(&e, cspan)?)),
                        _ => {
                            let within = class.element();
                            self.unknown(&e, cspan, within)?
                        }
                    }
                }
                Ev::Text(..) => {}
                Ev::End => break,
                Ev::Eof => unreachable!(),
            }
        }
        node.references.end = self.references.len() as u32;
        Ok(())
    }

    fn references(&mut self, out: &mut Vec<RawReference>) -> PResult<()> {
        loop {
            self.scan_references(out);
            match self.next()? {
                Ev::Start(e, span) => {
                    if local(e.name().into_inner()) != b"Reference" {
                        self.unknown(&e, span, "References")?;
                        continue;
                    }
                    let attrs = self.attrs(&e, span)?;
                    let mut is_forward = true;
                    let mut rt = None;
                    for a in &attrs {
                        match a.key {
                            "ReferenceType" => rt = Some(self.raw_str(a.value.trim(), a.span)),
                            "IsForward" => is_forward = self.boolean(a).unwrap_or(true),
                            _ => {}
                        }
                    }
                    self.recycle(attrs);
                    let text_start = self.pos();
                    let target = self.text_content("Reference")?;
                    let trimmed = target.trim();
                    let lead = trimmed.as_ptr() as usize - target.as_ptr() as usize;
                    let tspan = self.span(text_start + lead, text_start + lead + trimmed.len());
                    let Some(reference_type) = rt else {
                        self.missing(span, "Reference", "ReferenceType");
                        continue;
                    };
                    out.push(RawReference { reference_type, target: self.raw_str(trimmed, tspan), is_forward, span });
                }
                Ev::Text(..) => {}
                Ev::End => return Ok(()),
                Ev::Eof => unreachable!(),
            }
        }
    }

    /// Reads the `<Reference>` elements that come next in their common form straight from the text, up to
    /// the first one that is not (or the end of `<References>`), which quick-xml then reads.
    ///
    /// Nearly every reference of a NodeSet2 file is written `<Reference ReferenceType="..."
    /// [IsForward="..."]>target</Reference>`, with white space between references; going through quick-xml
    /// costs four events and an attribute reader for each. The common form is recognised exactly (see
    /// [`Parser::common_reference`]), with the limits on depth and text length kept; such a reference gives
    /// what the general path gives, which reports nothing for it. For anything else the general path reads
    /// on, and it reports what it finds.
    fn scan_references(&mut self, out: &mut Vec<RawReference>) {
        if !self.between_tags || self.open.len() >= self.limits.max_depth {
            return;
        }
        #[cfg(test)]
        if tests::GENERAL_PATH_ONLY.with(std::cell::Cell::get) {
            return;
        }
        let rest: &'a [u8] = self.reader.get_ref();
        let at = self.pos();
        let mut read = 0;
        loop {
            let white = rest[read..].iter().take_while(|b| b.is_ascii_whitespace()).count();
            let Some((len, reference)) = self.common_reference(&rest[read + white..], at + read + white) else {
                read += white;
                break;
            };
            out.push(reference);
            read += white + len;
        }
        if read > 0 {
            *self.reader.get_mut() = &rest[read..];
            self.skipped += read;
        }
    }

    /// One `<Reference>` in the common form at the start of `s` (which starts at byte `at` of the text): its
    /// length and what it gives (see [`Parser::scan_references`]).
    fn common_reference(&self, s: &'a [u8], at: usize) -> Option<(usize, RawReference)> {
        const NAME: &[u8] = b"<Reference";
        // quick-xml's white space: space, tab, CR, LF.
        let ws = |b: u8| matches!(b, b' ' | b'\t' | b'\r' | b'\n');
        if !s.starts_with(NAME) || !s.get(NAME.len()).is_some_and(|&b| ws(b)) {
            return None;
        }
        // The attributes, each `key="value"` after white space, up to the `>`. Keys are plain names (so the
        // first `>` outside quotes is the end of the tag, as quick-xml finds it), and only ReferenceType and
        // IsForward, once each.
        let mut i = NAME.len();
        let mut reference_type = None;
        let mut is_forward = None;
        let tag_end = loop {
            while s.get(i).is_some_and(|&b| ws(b)) {
                i += 1;
            }
            if *s.get(i)? == b'>' {
                break i;
            }
            let key_start = i;
            while s.get(i).is_some_and(|&b| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.' | b':')) {
                i += 1;
            }
            if i == key_start || s.get(i) != Some(&b'=') {
                return None;
            }
            let key = local(&s[key_start..i]);
            let quote = *s.get(i + 1)?;
            if quote != b'"' && quote != b'\'' {
                return None;
            }
            let value_start = i + 2;
            let value = &s[value_start..value_start + s[value_start..].iter().position(|&b| b == quote)?];
            i = value_start + value.len() + 1;
            // Values with references to expand, or too long (the general path reports it), are not common.
            if value.contains(&b'&') || value.len() > self.limits.max_text_len {
                return None;
            }
            match key {
                b"ReferenceType" if reference_type.is_none() => reference_type = Some(value),
                b"IsForward" if is_forward.is_none() => {
                    is_forward = Some(match self.str_at(value).trim() {
                        "true" | "1" => true,
                        "false" | "0" => false,
                        _ => return None,
                    })
                }
                _ => return None,
            }
        };
        let reference_type = reference_type?;
        // The target: text without references or CR, not only white space (which reads as empty text with a
        // span of its own), within the length limit.
        let text_start = tag_end + 1;
        let text_len = memchr::memchr(b'<', &s[text_start..])?;
        let text = &s[text_start..text_start + text_len];
        let mut blank = true;
        for &b in text {
            if b == b'&' || b == b'\r' {
                return None;
            }
            blank &= b.is_ascii_whitespace();
        }
        if blank || text_len > self.limits.max_text_len {
            return None;
        }
        // The end tag, white space allowed before its `>`.
        let close = text_start + text_len;
        let end_name = s[close..].strip_prefix(b"</Reference")?;
        let white = end_name.iter().take_while(|&&b| ws(b)).count();
        if end_name.get(white) != Some(&b'>') {
            return None;
        }
        let len = close + b"</Reference".len() + white + 1;

        let rt_start = self.offset_of(reference_type);
        let rt_span = self.span(rt_start, rt_start + reference_type.len());
        let target = self.str_at(text);
        let trimmed = target.trim();
        let lead = trimmed.as_ptr() as usize - target.as_ptr() as usize;
        let target_span = self.span(at + text_start + lead, at + text_start + lead + trimmed.len());
        Some((
            len,
            RawReference {
                reference_type: self.raw_str(self.str_at(reference_type).trim(), rt_span),
                target: self.raw_str(trimmed, target_span),
                is_forward: is_forward.unwrap_or(true),
                span: self.span(at, at + tag_end + 1),
            },
        ))
    }

    fn definition(&mut self, e: &BytesStart<'a>, span: Span) -> PResult<RawDefinition> {
        let attrs = self.attrs(e, span)?;
        let mut def = RawDefinition {
            name: String::new(),
            symbolic_name: None,
            base_type: None,
            is_union: false,
            is_option_set: false,
            fields: Vec::new(),
            span,
        };
        for a in &attrs {
            match a.key {
                "Name" => def.name = a.value.to_string(),
                "SymbolicName" => def.symbolic_name = Some(a.value.to_string()),
                "BaseType" => def.base_type = Some(Spanned { value: a.value.to_string(), span: a.span }),
                "IsUnion" => def.is_union = self.boolean(a).unwrap_or(false),
                "IsOptionSet" => def.is_option_set = self.boolean(a).unwrap_or(false),
                _ => {}
            }
        }
        self.recycle(attrs);
        loop {
            match self.next()? {
                Ev::Start(e, fspan) => {
                    if local(e.name().into_inner()) != b"Field" {
                        self.unknown(&e, fspan, "Definition")?;
                        continue;
                    }
                    let attrs = self.attrs(&e, fspan)?;
                    let mut f = RawField {
                        name: String::new(),
                        symbolic_name: None,
                        data_type: None,
                        value_rank: None,
                        array_dimensions: None,
                        max_string_length: None,
                        is_optional: false,
                        allow_sub_types: false,
                        value: None,
                        display_names: Vec::new(),
                        descriptions: Vec::new(),
                        span: fspan,
                    };
                    let mut have_name = false;
                    for a in &attrs {
                        match a.key {
                            "Name" => {
                                f.name = a.value.to_string();
                                have_name = true
                            }
                            "SymbolicName" => f.symbolic_name = Some(a.value.to_string()),
                            "DataType" => f.data_type = Some(Spanned { value: a.value.to_string(), span: a.span }),
                            "ValueRank" => f.value_rank = self.number(a),
                            "ArrayDimensions" => f.array_dimensions = Some(a.value.to_string()),
                            "MaxStringLength" => f.max_string_length = self.number(a),
                            "IsOptional" => f.is_optional = self.boolean(a).unwrap_or(false),
                            "AllowSubTypes" => f.allow_sub_types = self.boolean(a).unwrap_or(false),
                            "Value" => f.value = self.number(a),
                            _ => {}
                        }
                    }
                    self.recycle(attrs);
                    if !have_name {
                        self.missing(fspan, "Field", "Name");
                    }
                    loop {
                        match self.next()? {
                            Ev::Start(e, s) => match local(e.name().into_inner()) {
                                b"DisplayName" => {
                                    let t = self.localized(&e, s, "DisplayName")?;
                                    f.display_names.push(t)
                                }
                                b"Description" => {
                                    let t = self.localized(&e, s, "Description")?;
                                    f.descriptions.push(t)
                                }
                                _ => self.unknown(&e, s, "Field")?,
                            },
                            Ev::Text(..) => {}
                            Ev::End => break,
                            Ev::Eof => unreachable!(),
                        }
                    }
                    def.fields.push(f);
                }
                Ev::Text(..) => {}
                Ev::End => return Ok(def),
                Ev::Eof => unreachable!(),
            }
        }
    }

    /// Reads an element whose start has been read and everything inside it, iteratively, bounded to
    /// `max_depth` levels, handing each element and piece of text to `sink`. The limits are checked here,
    /// whatever the sink builds.
    fn tree<S: TreeSink<'a>>(&mut self, e: &BytesStart<'a>, span: Span, max_depth: usize, sink: &mut S) -> PResult<()> {
        let mut stack = std::mem::take(&mut self.tree_stack);
        stack.clear();
        let result = self.tree_with(e, span, max_depth, sink, &mut stack);
        self.tree_stack = stack;
        result
    }

    fn tree_with<S: TreeSink<'a>>(
        &mut self,
        e: &BytesStart<'a>,
        span: Span,
        max_depth: usize,
        sink: &mut S,
        stack: &mut Vec<(&'a str, Span, usize)>,
    ) -> PResult<()> {
        let name = self.str_at(local(e.name().into_inner()));
        let attrs = self.attrs(e, span)?;
        sink.start(self, name, &attrs, span);
        self.recycle(attrs);
        stack.push((name, span, 0));
        loop {
            match self.next()? {
                Ev::Start(e, s) => {
                    if stack.len() >= max_depth {
                        let d = Diagnostic::new(
                            Code::TooDeep,
                            format!("a value is nested more than {max_depth} levels deep"),
                        )
                        .at(s)
                        .help("values in NodeSet2 files are a few levels deep; this one is malformed or hostile");
                        return Err(self.fatal(d));
                    }
                    let name = self.str_at(local(e.name().into_inner()));
                    let attrs = self.attrs(&e, s)?;
                    sink.start(self, name, &attrs, s);
                    self.recycle(attrs);
                    stack.push((name, s, 0));
                }
                Ev::Text(t, _) => {
                    let top = stack.last_mut().expect("stack holds the root");
                    if top.2 + t.len() > self.limits.max_text_len {
                        let d = Diagnostic::new(
                            Code::TooLarge,
                            format!("the text of <{}> is longer than {} bytes", top.0, self.limits.max_text_len),
                        )
                        .at(top.1)
                        .help("no NodeSet2 value needs this much; raise the limit in parse::Limits if the file is trusted");
                        return Err(self.fatal(d));
                    }
                    top.2 += t.len();
                    sink.text(self, t);
                }
                Ev::End => {
                    stack.pop();
                    sink.end(self);
                    if stack.is_empty() {
                        return Ok(());
                    }
                }
                Ev::Eof => unreachable!(),
            }
        }
    }

    /// Reads a `<Value>` whose start has been read into the file's value arena and returns the element
    /// inside it, if any.
    fn value(&mut self, e: &BytesStart<'a>, span: Span) -> PResult<Option<ValueRef>> {
        let mut sink = ArenaSink { stack: std::mem::take(&mut self.value_stack), root: None };
        sink.stack.clear();
        let result = self.tree(e, span, self.limits.max_value_depth, &mut sink);
        self.value_stack = sink.stack;
        result?;
        let root = sink.root.expect("the tree has a root");
        Ok(self.values.element(ValueRef(root), self.text).children().next().map(|c| ValueRef(c.index())))
    }
}

/// What [`Parser::tree`] builds from the elements it reads.
trait TreeSink<'a> {
    /// An element starts; its attributes have been read.
    fn start(&mut self, p: &mut Parser<'a, '_>, name: &'a str, attrs: &[Attr<'a>], span: Span);
    /// A piece of the innermost open element's text.
    fn text(&mut self, p: &mut Parser<'a, '_>, text: Cow<'a, str>);
    /// The innermost open element ends.
    fn end(&mut self, p: &mut Parser<'a, '_>);
}

/// Builds an owned [`XmlElement`] tree (for `<Extensions>`).
#[derive(Default)]
struct ElementSink {
    stack: Vec<XmlElement>,
    done: Option<XmlElement>,
}

impl<'a> TreeSink<'a> for ElementSink {
    fn start(&mut self, _: &mut Parser<'a, '_>, name: &'a str, attrs: &[Attr<'a>], span: Span) {
        self.stack.push(XmlElement {
            name: name.to_string(),
            attributes: attrs.iter().map(|a| (a.key.to_string(), a.value.to_string())).collect(),
            children: Vec::new(),
            text: String::new(),
            span,
        });
    }

    fn text(&mut self, _: &mut Parser<'a, '_>, text: Cow<'a, str>) {
        self.stack.last_mut().expect("an element is open").text.push_str(&text);
    }

    fn end(&mut self, _: &mut Parser<'a, '_>) {
        let mut done = self.stack.pop().expect("an element is open");
        if done.children.is_empty() {
            done.text = normalize_newlines(Cow::Owned(std::mem::take(&mut done.text))).into_owned();
        } else {
            // Elements with children carry only formatting white space.
            done.text.clear();
        }
        match self.stack.last_mut() {
            Some(parent) => parent.children.push(done),
            None => self.done = Some(done),
        }
    }
}

/// Records the elements into the parser's [`ValueArena`] (for `<Value>`).
struct ArenaSink {
    /// The open elements, as arena indices.
    stack: Vec<u32>,
    root: Option<u32>,
}

impl<'a> TreeSink<'a> for ArenaSink {
    fn start(&mut self, p: &mut Parser<'a, '_>, name: &'a str, attrs: &[Attr<'a>], span: Span) {
        let ix = p.values.open(span, name, attrs.iter().map(|a| (a.key, &*a.value)), p.text);
        self.root.get_or_insert(ix);
        self.stack.push(ix);
    }

    fn text(&mut self, p: &mut Parser<'a, '_>, text: Cow<'a, str>) {
        let ix = *self.stack.last().expect("an element is open");
        p.values.push_text(ix, &text, p.text);
    }

    fn end(&mut self, p: &mut Parser<'a, '_>) {
        let ix = self.stack.pop().expect("an element is open");
        p.values.close(ix, p.text);
    }
}

#[cfg(test)]
pub(crate) mod tests;
