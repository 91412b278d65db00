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
    /// A parser of `text[range]`, with spans in `text`.
    fn new(file: FileId, text: &'a str, range: std::ops::Range<usize>, limits: &'a Limits, diags: &'d mut Diagnostics) -> Self {
        let ends_early = range.end < text.len();
        let (base, end) = (range.start, range.end);
        let mut reader = Reader::from_str(&text[range]);
        let cfg = reader.config_mut();
        cfg.expand_empty_elements = true;
        cfg.check_end_names = true;
        cfg.check_comments = false;
        cfg.trim_text(false);
        Parser {
            file,
            text,
            reader,
            base,
            end,
            skipped: 0,
            between_tags: false,
            outer_root: None,
            ends_early,
            limits,
            diags,
            open: Vec::new(),
            attr_buf: Vec::new(),
            tree_stack: Vec::new(),
            values: ValueArena::default(),
            references: Vec::new(),
            value_stack: Vec::new(),
        }
    }

    /// The reader's position in the input.
    fn pos(&self) -> usize {
        self.base + self.skipped + self.reader.buffer_position() as usize
    }

    fn span(&self, start: usize, end: usize) -> Span {
        Span::new(self.file, start, end)
    }

    fn offset_of(&self, s: &[u8]) -> usize {
        let base = self.text.as_ptr() as usize;
        let p = s.as_ptr() as usize;
        if p >= base && p <= base + self.text.len() {
            p - base
        } else {
            0
        }
    }

    fn fatal(&mut self, d: Diagnostic) -> Fatal {
        self.diags.push(d);
        Fatal
    }

    /// Reports a quick-xml error at byte `at`, inside the innermost open element.
    fn xml_error(&mut self, e: &quick_xml::Error, at: usize) -> Fatal {
        let at = at.min(self.text.len());
        let open = self.open.last().map(|(n, _)| *n);
        let d = xml_error_diag(e, self.span(at, at + 1), open);
        self.fatal(d)
    }

    /// The next event that matters: element starts and ends, text. Comments, PIs and the declaration are
    /// skipped (the declaration after its encoding is checked).
    fn next(&mut self) -> PResult<Ev<'a>> {
        loop {
            let before = self.pos();
            let ev = match self.reader.read_event() {
                Ok(ev) => ev,
                Err(e) => {
                    let at = self.base + self.skipped + self.reader.error_position() as usize;
                    return Err(self.xml_error(&e, at));
                }
            };
            let after = self.pos();
            self.between_tags = false;
            match ev {
                Event::Start(e) => {
                    let name = self.str_at(local(e.name().into_inner()));
                    self.open.push((name, before));
                    if self.open.len() > self.limits.max_depth {
                        let d = Diagnostic::new(
                            Code::TooDeep,
                            format!("elements are nested more than {} levels deep", self.limits.max_depth),
                        )
                        .at(self.span(before, after))
                        .with_span_label("this element is too deep")
                        .help("NodeSet2 files need fewer than 20 levels; this file is malformed or hostile");
                        return Err(self.fatal(d));
                    }
                    // quick-xml reads on from after the `>`, except that the end of an empty element comes next.
                    self.between_tags = self.text.as_bytes().get(after.wrapping_sub(2)) != Some(&b'/');
                    return Ok(Ev::Start(e, self.span(before, after)));
                }
                Event::End(e) => {
                    if let Some(root) = self.outer_root.filter(|_| self.open.len() <= 1) {
                        // quick-xml saw no start tag for this end tag; check it as quick-xml would have.
                        use quick_xml::errors::{Error, IllFormedError};
                        let found = std::str::from_utf8(e.name().into_inner()).map(str::to_string).unwrap_or_default();
                        let wrong = match self.open.last() {
                            Some(_) if found == root.qname => None,
                            Some(_) => Some(IllFormedError::MismatchedEndTag { expected: root.qname.to_string(), found }),
                            None => Some(IllFormedError::UnmatchedEndTag(found)),
                        };
                        if let Some(wrong) = wrong {
                            return Err(self.xml_error(&Error::IllFormed(wrong), before));
                        }
                    }
                    self.open.pop();
                    self.between_tags = true;
                    return Ok(Ev::End);
                }
                Event::Empty(_) => unreachable!("expand_empty_elements is set"),
                Event::Text(t) => {
                    // Fast paths: white space between tags, and text without references, borrowed as is.
                    let raw: &[u8] = &t;
                    if raw.iter().all(u8::is_ascii_whitespace) {
                        return Ok(Ev::Text(Cow::Borrowed(""), before));
                    }
                    if memchr::memchr(b'&', raw).is_none() {
                        let start = self.offset_of(raw);
                        if start + raw.len() <= self.text.len() && self.text.is_char_boundary(start) && self.text.is_char_boundary(start + raw.len()) {
                            return Ok(Ev::Text(Cow::Borrowed(&self.text[start..start + raw.len()]), before));
                        }
                    }
                    match t.unescape() {
                    Ok(s) => return Ok(Ev::Text(s, before)),
                    Err(e) => {
                        let d = escape_diag(&e, before, |a, b| self.span(a, b));
                        return Err(self.fatal(d));
                    }
                    }
                }
                Event::CData(c) => {
                    let s = String::from_utf8_lossy(&c.into_inner()).into_owned();
                    return Ok(Ev::Text(Cow::Owned(s), before));
                }
                Event::Decl(decl) => {
                    if let Some(Ok(enc)) = decl.encoding() {
                        let enc = String::from_utf8_lossy(&enc).into_owned();
                        if !enc.eq_ignore_ascii_case("utf-8") && !enc.eq_ignore_ascii_case("utf8") {
                            let d = Diagnostic::new(
                                Code::Encoding,
                                format!("the XML declaration says encoding=\"{enc}\"; only UTF-8 is read"),
                            )
                            .at(self.span(before, after))
                            .help("re-encode the file as UTF-8 and declare encoding=\"utf-8\"");
                            return Err(self.fatal(d));
                        }
                    }
                }
                Event::DocType(_) => {
                    let d = Diagnostic::new(Code::Doctype, "DOCTYPE declarations are not accepted")
                        .at(self.span(before, after))
                        .with_span_label("document type declaration")
                        .note("entities declared in a DOCTYPE are never expanded, so a file cannot grow or read other files")
                        .help("remove the DOCTYPE; NodeSet2 files are validated against UANodeSet.xsd, not a DTD");
                    return Err(self.fatal(d));
                }
                Event::Eof => {
                    if self.ends_early && self.open.len() == 1 {
                        // A piece that ends before the file does, between two top-level elements.
                        return Ok(Ev::Eof);
                    }
                    if let Some(&(name, start)) = self.open.last() {
                        let d = Diagnostic::new(
                            Code::Truncated,
                            format!("the file ends before <{name}> is closed"),
                        )
                        .at(self.span(start, start + name.len() + 1))
                        .with_span_label(format!("<{name}> opened here"))
                        .note(format!("{} element(s) are still open at the end of the file", self.open.len()))
                        .help("the file is truncated or a closing tag is missing; nothing of it is loaded");
                        return Err(self.fatal(d));
                    }
                    return Ok(Ev::Eof);
                }
                Event::Comment(_) | Event::PI(_) => {}
            }
        }
    }

    /// The input text at the bytes `s`, which quick-xml handed out as a slice of it: a name, a key or a
    /// value, with the lifetime of the input ("?" if `s` is not such a slice, which does not happen).
    fn str_at(&self, s: &[u8]) -> &'a str {
        let base = self.text.as_ptr() as usize;
        let p = s.as_ptr() as usize;
        if p < base || p + s.len() > base + self.text.len() {
            return "?";
        }
        self.text.get(p - base..p - base + s.len()).unwrap_or("?")
    }

    /// A string read at `span`, kept as a span where it is the input text there.
    fn raw_str(&self, value: &str, span: Span) -> RawStr {
        RawStr::new(value, span, self.text)
    }

    /// The attributes of a start tag, in a list lent out by the parser: give it back with
    /// [`Parser::recycle`]. A malformed attribute or value stops the file.
    ///
    /// Attributes are read by [`scan_attributes`], which reads the common form (`key="value"`, each after
    /// white space) in one pass and gives up on anything else, and without quick-xml's duplicate check
    /// (it keeps a list of keys, allocated per element): the keys are compared here. Any problem (a tag the
    /// scan gives up on, or two attributes with one local name) hands the tag to
    /// [`Parser::attrs_checked`], quick-xml's reading with its checks, which decides what is reported: the
    /// attributes and diagnostics are quick-xml's whatever the path.
    fn attrs(&mut self, e: &BytesStart<'a>, tag: Span) -> PResult<Vec<Attr<'a>>> {
        let mut out = std::mem::take(&mut self.attr_buf);
        out.clear();
        let content: &[u8] = e;
        let mut scan = AttributeScan { content, at: e.name().into_inner().len() };
        loop {
            let (key, value) = match scan.next() {
                Some(Ok(kv)) => kv,
                Some(Err(GaveUp)) => return self.attrs_checked(e, tag, out),
                None => return Ok(out),
            };
            let key = self.str_at(local(key));
            if out.iter().any(|o| o.key == key) {
                return self.attrs_checked(e, tag, out);
            }
            let attr = self.attr(key, value)?;
            out.push(attr);
        }
    }

    /// [`Parser::attrs`] with quick-xml's duplicate check.
    fn attrs_checked(&mut self, e: &BytesStart<'a>, tag: Span, mut out: Vec<Attr<'a>>) -> PResult<Vec<Attr<'a>>> {
        out.clear();
        for a in e.attributes().with_checks(true) {
            let a = match a {
                Ok(a) => a,
                Err(err) => {
                    let d = Diagnostic::new(Code::XmlSyntax, format!("malformed attribute: {err}")).at(tag);
                    return Err(self.fatal(d));
                }
            };
            let key = self.str_at(local(a.key.into_inner()));
            let attr = self.attr(key, &a.value)?;
            out.push(attr);
        }
        Ok(out)
    }

    /// One attribute, given its raw value (a slice of the input): the value is borrowed from the input
    /// unless it holds references to expand.
    fn attr(&mut self, key: &'a str, value: &[u8]) -> PResult<Attr<'a>> {
        let start = self.offset_of(value);
        let span = self.span(start, start + value.len());
        if value.len() > self.limits.max_text_len {
            let d = Diagnostic::new(
                Code::TooLarge,
                format!("the value of attribute `{key}` is longer than {} bytes", self.limits.max_text_len),
            )
            .at(self.span(start, start))
            .with_span_label("this attribute's value is too long")
            .help("no NodeSet2 attribute needs this much; raise the limit in parse::Limits if the file is trusted");
            return Err(self.fatal(d));
        }
        let raw = self.str_at(value);
        let value: Cow<'a, str> = if !raw.contains('&') {
            Cow::Borrowed(raw)
        } else {
            match quick_xml::escape::unescape(raw) {
                Ok(v) => Cow::Owned(v.into_owned()),
                Err(err) => {
                    let d = Diagnostic::new(Code::XmlSyntax, format!("malformed attribute value: {err}"))
                        .at(span)
                        .help("only the predefined entities (&amp; &lt; &gt; &quot; &apos;) and character references are allowed");
                    return Err(self.fatal(d));
                }
            }
        };
        Ok(Attr { key, value, span })
    }

    /// Gives back the list [`Parser::attrs`] lent out.
    fn recycle(&mut self, attrs: Vec<Attr<'a>>) {
        self.attr_buf = attrs;
    }

    /// Consumes the rest of an element whose start has been read.
    fn skip(&mut self) -> PResult<()> {
        let mut depth = 1usize;
        loop {
            match self.next()? {
                Ev::Start(..) => depth += 1,
                Ev::End => {
                    depth -= 1;
                    if depth == 0 {
                        return Ok(());
                    }
                }
                Ev::Text(..) => {}
                Ev::Eof => unreachable!("next() reports EOF inside an element"),
            }
        }
    }

    fn unknown(&mut self, e: &BytesStart<'a>, span: Span, within: &str) -> PResult<()> {
        let name = String::from_utf8_lossy(e.name().into_inner()).into_owned();
        self.diags.push(
            Diagnostic::new(Code::UnknownElement, format!("<{name}> is not expected inside <{within}>; it is ignored"))
                .at(span)
                .help("check the element name against UANodeSet.xsd"),
        );
        self.skip()
    }

    /// Reads the text content of an element whose start has been read; child elements are reported. The
    /// text is borrowed from the input when it is one piece without references or carriage returns.
    fn text_content(&mut self, within: &str) -> PResult<Cow<'a, str>> {
        let mut s: Cow<'a, str> = Cow::Borrowed("");
        let element_start = self.open.last().map(|(_, start)| *start).unwrap_or(0);
        loop {
            match self.next()? {
                Ev::Text(t, _) => {
                    if s.len() + t.len() > self.limits.max_text_len {
                        let d = Diagnostic::new(
                            Code::TooLarge,
                            format!("the text of <{within}> is longer than {} bytes", self.limits.max_text_len),
                        )
                        .at(self.span(element_start, element_start + within.len() + 1))
                        .with_span_label("this element's text is too long")
                        .help("no NodeSet2 text needs this much; raise the limit in parse::Limits if the file is trusted");
                        return Err(self.fatal(d));
                    }
                    if s.is_empty() {
                        s = t;
                    } else {
                        s.to_mut().push_str(&t);
                    }
                }
                Ev::Start(e, span) => self.unknown(&e, span, within)?,
                Ev::End => break,
                Ev::Eof => unreachable!(),
            }
        }
        Ok(normalize_newlines(s))
    }

    fn localized(&mut self, e: &BytesStart<'a>, span: Span, name: &str) -> PResult<LocalizedText> {
        let attrs = self.attrs(e, span)?;
        let locale = attrs.iter().find(|a| a.key == "Locale").map(|a| a.value.to_string()).filter(|l| !l.is_empty());
        self.recycle(attrs);
        let text = self.text_content(name)?;
        Ok(LocalizedText { locale, text: text.trim().to_string() })
    }

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

/// A diagnostic for a bad entity or character reference in text that starts at `text_start`.
fn escape_diag(e: &quick_xml::Error, text_start: usize, span: impl Fn(usize, usize) -> Span) -> Diagnostic {
    let esc = match e {
        quick_xml::Error::Escape(esc) => esc,
        other => {
            return Diagnostic::new(Code::XmlSyntax, format!("malformed character data: {other}"))
                .at(span(text_start, text_start + 1))
                .help("the file is not well-formed XML")
        }
    };
    escape_error_diag(esc, text_start, span)
}

fn escape_error_diag(esc: &quick_xml::escape::EscapeError, text_start: usize, span: impl Fn(usize, usize) -> Span) -> Diagnostic {
    use quick_xml::escape::EscapeError;
    let help = "only the predefined entities (&amp; &lt; &gt; &quot; &apos;) and character references such as &#160; are allowed; DOCTYPE entities are never expanded";
    match esc {
        EscapeError::UnrecognizedEntity(range, name) => {
            let amp = text_start + range.start.saturating_sub(1);
            Diagnostic::new(Code::XmlSyntax, format!("unknown entity `&{name};`"))
                .at(span(amp, text_start + range.end + 1))
                .with_span_label("not a predefined entity")
                .help(help)
        }
        EscapeError::UnterminatedEntity(range) => {
            Diagnostic::new(Code::XmlSyntax, "an `&` is not followed by an entity name and `;`")
                .at(span(text_start + range.start, text_start + range.start + 1))
                .help("write a literal ampersand as &amp;")
        }
        EscapeError::InvalidCharRef(e) => Diagnostic::new(Code::XmlSyntax, format!("invalid character reference: {e}"))
            .at(span(text_start, text_start + 1))
            .help(help),
    }
}

/// The scan of a start tag's attributes gave up: the tag is not in the common form.
struct GaveUp;

/// Reads the attributes of a start tag in the form nearly every tag has: white space, a key, `=`, a value
/// in quotes. The key and value ranges are those quick-xml's attribute reader gives for such a tag; for
/// anything else (white space around `=`, a value without quotes or closing quote, a key without value) the
/// scan gives up and quick-xml reads the tag.
struct AttributeScan<'t> {
    /// The tag between `<` and `>` (and any `/` of an empty element), as quick-xml hands it out.
    content: &'t [u8],
    /// Where the scan is: after the element name, then after each value's closing quote.
    at: usize,
}

impl<'t> Iterator for AttributeScan<'t> {
    type Item = Result<(&'t [u8], &'t [u8]), GaveUp>;

    fn next(&mut self) -> Option<Self::Item> {
        // quick-xml's white space: space, tab, CR, LF.
        let ws = |b: u8| matches!(b, b' ' | b'\t' | b'\r' | b'\n');
        let c = self.content;
        let mut i = self.at;
        while i < c.len() && ws(c[i]) {
            i += 1;
        }
        if i == c.len() {
            self.at = i;
            return None;
        }
        // Keys and values are short: plain loops beat a vectorised search here.
        let key_start = i;
        let Some(eq) = c[i..].iter().position(|&b| b == b'=' || ws(b)).map(|n| i + n) else { return Some(Err(GaveUp)) };
        if c[eq] != b'=' || eq == key_start || eq + 1 >= c.len() {
            return Some(Err(GaveUp));
        }
        let key = &c[key_start..eq];
        let quote = c[eq + 1];
        if quote != b'"' && quote != b'\'' {
            return Some(Err(GaveUp));
        }
        let value_start = eq + 2;
        let Some(len) = c[value_start..].iter().position(|&b| b == quote) else { return Some(Err(GaveUp)) };
        self.at = value_start + len + 1;
        Some(Ok((key, &c[value_start..value_start + len])))
    }
}

/// The local part of a possibly prefixed XML name.
fn local(name: &[u8]) -> &[u8] {
    match name.iter().position(|&b| b == b':') {
        Some(i) => &name[i + 1..],
        None => name,
    }
}

fn normalize_newlines(s: Cow<'_, str>) -> Cow<'_, str> {
    if s.contains('\r') {
        Cow::Owned(s.replace("\r\n", "\n").replace('\r', "\n"))
    } else {
        s
    }
}

fn xml_error_diag(e: &quick_xml::Error, span: Span, open: Option<&str>) -> Diagnostic {
    use quick_xml::errors::{Error, IllFormedError, SyntaxError};
    if let Error::Syntax(SyntaxError::UnclosedTag) = e {
        let within = open.map(|o| format!(", inside <{o}>")).unwrap_or_default();
        return Diagnostic::new(Code::Truncated, format!("the file ends in the middle of a tag{within}"))
            .at(span)
            .with_span_label("this tag is never closed")
            .help("the file is truncated (a `>` and the rest of the document are missing); nothing of it is loaded");
    }
    if let Error::Escape(esc) = e {
        return escape_error_diag(esc, span.start as usize, |a, b| Span::new(span.file, a, b));
    }
    let (msg, help) = match e {
        Error::Syntax(SyntaxError::UnclosedComment) => {
            ("a comment is never closed".to_string(), "close the comment with `-->`")
        }
        Error::Syntax(s) => (format!("malformed XML: {s}"), "the file is not well-formed XML"),
        Error::IllFormed(IllFormedError::MismatchedEndTag { expected, found }) => (
            format!("closing tag </{found}> does not match the open element <{expected}>"),
            "a closing tag is missing or misspelled",
        ),
        Error::IllFormed(IllFormedError::UnmatchedEndTag(name)) => {
            (format!("closing tag </{name}> has no open element"), "remove the extra closing tag")
        }
        Error::IllFormed(i) => (format!("ill-formed XML: {i}"), "the file is not well-formed XML"),
        other => (format!("malformed XML: {other}"), "the file is not well-formed XML"),
    };
    Diagnostic::new(Code::XmlSyntax, msg).at(span).help(help)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    thread_local! {
        /// Turns the parser's own reading of common forms off, so tests can compare it with quick-xml's.
        pub(crate) static GENERAL_PATH_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    }

    /// A file parsed with and without the parser's own reading of common forms: both give the same.
    fn assert_fast_paths_agree(text: &str, limits: &Limits) {
        let run = |general: bool| {
            GENERAL_PATH_ONLY.with(|g| g.set(general));
            let mut d = Diagnostics::new();
            let set = parse(FileId(0), text, limits, &mut d);
            GENERAL_PATH_ONLY.with(|g| g.set(false));
            format!("{set:?}\n{d:?}")
        };
        let (fast, general) = (run(false), run(true));
        assert!(fast == general, "fast and general paths differ on:\n{text}\n--- fast\n{fast}\n--- general\n{general}");
    }

    #[test]
    fn references_in_common_form_read_as_quick_xml_reads_them() {
        let refs = [
            r#"<Reference ReferenceType="HasComponent">ns=1;i=5</Reference>"#,
            r#"<Reference ReferenceType="i=40" IsForward="false"> i=85 </Reference>"#,
            r#"<Reference  ReferenceType='HasProperty'   IsForward='1'>i=1</Reference  >"#,
            r#"<Reference IsForward="0" ReferenceType="Organizes" Extra="x">ns=1;s=a>b</Reference>"#,
            r#"<Reference ReferenceType="HasComponent" IsForward="no">i=1</Reference>"#,
            r#"<Reference ReferenceType="HasComponent" IsForward="true" IsForward="false">i=1</Reference>"#,
            r#"<Reference ReferenceType="Has&amp;Component">i=1</Reference>"#,
            r#"<Reference ReferenceType="HasComponent">i=1&amp;</Reference>"#,
            r#"<Reference ReferenceType="HasComponent">   </Reference>"#,
            r#"<Reference ReferenceType="HasComponent"></Reference>"#,
            r#"<Reference ReferenceType="HasComponent"/>"#,
            r#"<Reference ReferenceType="HasComponent">i=1<!-- c --></Reference>"#,
            r#"<Reference ReferenceType="HasComponent"><![CDATA[i=1]]></Reference>"#,
            r#"<Reference ReferenceType="HasComponent">i=1</ReferenceX>"#,
            r#"<Reference>i=1</Reference>"#,
            r#"<Reference IsForward="false">i=1</Reference>"#,
            r#"<Reference ReferenceType = "HasComponent">i=1</Reference>"#,
            r#"<Reference ReferenceType="HasComponent" a="1" b="2" c="3" d="4">i=1</Reference>"#,
            r#"<Reference a:x="1" b:x="2" ReferenceType="HasComponent">i=1</Reference>"#,
            r#"<ua:Reference ReferenceType="HasComponent">i=1</ua:Reference>"#,
            "<Reference ReferenceType=\"HasComponent\">i=1\r\n</Reference>",
            r#"<Reference ReferenceType="HasComponent">x&#233;</Reference>"#,
            "<Reference ReferenceType=\"HasComponent\">\u{a0}i=1\u{b}</Reference>",
            "<Reference\tReferenceType=\"HasComponent\"\n>i=1</Reference>",
            r#"<Other/>"#,
            r#"text"#,
            r#"<!-- a comment -->"#,
        ];
        let limits = Limits::default();
        let file = |body: &str| {
            format!("<UANodeSet><UAObject NodeId=\"i=1\" BrowseName=\"A\"><References>{body}</References></UAObject></UANodeSet>")
        };
        // Every reference form alone, between common ones, and in a row of all of them.
        for r in refs {
            for body in [r.to_string(), format!("\n  {0}\n  {r}\n  {0}\n", refs[0]), format!("{r}{}", refs[1])] {
                assert_fast_paths_agree(&file(&body), &limits);
            }
        }
        let all = refs.join("\n");
        assert_fast_paths_agree(&file(&all), &limits);
        // Truncated inside the references, and with tight limits.
        assert_fast_paths_agree(&format!("<UANodeSet><UAObject NodeId=\"i=1\" BrowseName=\"A\"><References>{}", refs[0]), &limits);
        for tight in [Limits { max_depth: 3, max_text_len: 4, ..Limits::default() }, Limits { max_depth: 4, max_text_len: 8, ..Limits::default() }] {
            assert_fast_paths_agree(&file(&all), &tight);
        }
    }

    #[test]
    fn the_vendored_files_read_the_same_on_both_paths() {
        // Every NodeSet2 file of the pinned package, those of its `1.02/` folder too.
        let mut dirs = vec![std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../nodesets/vendor")];
        let mut read = 0;
        while let Some(dir) = dirs.pop() {
            let entries = std::fs::read_dir(&dir)
                .unwrap_or_else(|e| panic!("{}: {e}; run `cargo xtask fetch-nodesets`", dir.display()));
            for path in entries.flatten().map(|e| e.path()) {
                if path.is_dir() {
                    dirs.push(path);
                } else if path.extension().is_some_and(|x| x == "xml") {
                    assert_fast_paths_agree(&std::fs::read_to_string(&path).unwrap(), &Limits::default());
                    read += 1;
                }
            }
        }
        assert!(read >= 38, "only {read} vendored files; run `cargo xtask fetch-nodesets`");
    }

    fn parse_str(text: &str) -> (Option<RawNodeSet>, Diagnostics) {
        let mut d = Diagnostics::new();
        let r = parse(FileId(0), text, &Limits::default(), &mut d);
        (r, d)
    }

    #[test]
    fn parses_a_small_nodeset_without_default_namespace() {
        let xml = "<?xml version=\"1.0\" encoding=\"utf-8\"?>\r\n<!-- c -->\r\n<UANodeSet>\r\n\
            <NamespaceUris><Uri>http://x/</Uri></NamespaceUris>\r\n\
            <Models><Model ModelUri=\"http://x/\" Version=\"1.0\"><RequiredModel ModelUri=\"http://opcfoundation.org/UA/\" Version=\"1.04\"/></Model></Models>\r\n\
            <Aliases><Alias Alias=\"HasComponent\">i=47</Alias></Aliases>\r\n\
            <UAObject NodeId=\"ns=1;i=1\" BrowseName=\"1:A\" EventNotifier=\"1\"><DisplayName>A</DisplayName>\
            <DisplayName Locale=\"de\">A de</DisplayName><Description>line1\r\nline2</Description>\
            <References><Reference ReferenceType=\"HasComponent\" IsForward=\"false\">i=85</Reference></References></UAObject>\r\n\
            <UAVariable NodeId=\"ns=1;i=2\" BrowseName=\"1:V\" DataType=\"Int32\"><Value><ListOfInt32 xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\"><Int32>1</Int32><Int32>2</Int32></ListOfInt32></Value></UAVariable>\r\n\
            </UANodeSet>\r\n";
        let (set, d) = parse_str(xml);
        assert!(d.items.is_empty(), "{d:?}");
        let set = set.unwrap();
        assert_eq!(set.namespace_uris[0].value, "http://x/");
        assert_eq!(set.models[0].required[0].version.as_deref(), Some("1.04"));
        assert_eq!(set.aliases[0].target.value, "i=47");
        assert_eq!(set.nodes.len(), 2);
        let a = &set.nodes[0];
        assert_eq!(a.display_names.len(), 2);
        assert_eq!(a.descriptions[0].text, "line1\nline2");
        assert!(!set.references_of(a)[0].is_forward);
        assert_eq!(&xml[a.node_id.span.start as usize..a.node_id.span.end as usize], "ns=1;i=1");
        let v = set.values.element(set.nodes[1].value.unwrap(), xml);
        assert_eq!(v.name(), "ListOfInt32");
        assert_eq!(v.attr("xmlns"), Some("http://opcfoundation.org/UA/2008/02/Types.xsd"));
        assert_eq!(v.children().count(), 2);
        assert_eq!(v.children().nth(1).unwrap().text(), "2");
        let tree = v.to_xml();
        assert_eq!(tree.children[1].text, "2");
        assert_eq!(&xml[tree.children[1].span.start as usize..tree.children[1].span.end as usize], "<Int32>");
    }

    /// Moves every span of a tree by `delta` bytes.
    fn shifted(mut el: XmlElement, delta: i64) -> XmlElement {
        el.span.start = (el.span.start as i64 + delta) as u32;
        el.span.end = (el.span.end as i64 + delta) as u32;
        el.children = el.children.into_iter().map(|c| shifted(c, delta)).collect();
        el
    }

    #[test]
    fn values_read_in_place_build_the_trees_extensions_build() {
        // Entities in text and attributes, CR LF, text in pieces around a comment and CDATA, white space
        // only, mixed content (dropped), prefixes, an empty element.
        let inner = "<x:Outer xmlns:x=\"urn:x\" a=\"1 &amp; 2\" b='\u{e9}'>\r\n  <x:A>t &lt; u</x:A>\r\n  <B>line1\r\nline2\rline3</B>\
            <C>one<!-- c -->two<![CDATA[<three>]]></C><D>   </D><E/><F> mixed <G>g</G> text </F><H>plain</H></x:Outer>";
        let xml = format!(
            "<UANodeSet><UAVariable NodeId=\"i=1\" BrowseName=\"V\"><Value>{inner}</Value>\
             <Extensions>{inner}</Extensions></UAVariable></UANodeSet>"
        );
        let (set, d) = parse_str(&xml);
        assert!(d.items.is_empty(), "{d:?}");
        let set = set.unwrap();
        let node = &set.nodes[0];
        let from_arena = set.values.element(node.value.unwrap(), &xml).to_xml();
        let delta = (xml.find("<Value>").unwrap() + "<Value>".len()) as i64 - (xml.find("<Extensions>").unwrap() + "<Extensions>".len()) as i64;
        assert_eq!(from_arena, shifted(node.extensions[0].clone(), delta));
        assert_eq!(from_arena.attributes, [("x".to_string(), "urn:x".to_string()), ("a".into(), "1 & 2".into()), ("b".into(), "\u{e9}".into())]);
        let texts: Vec<&str> = from_arena.children.iter().map(|c| c.text.as_str()).collect();
        assert_eq!(texts, ["t < u", "line1\nline2\nline3", "onetwo<three>", "", "", "", "plain"]);
        assert_eq!(&xml[from_arena.children[1].span.start as usize..from_arena.children[1].span.end as usize], "<B>");
    }

    #[test]
    fn value_limits_hold_for_values_read_in_place() {
        let limits = Limits { max_value_depth: 3, max_text_len: 8, ..Limits::default() };
        let parse_with = |value: &str| {
            let xml = format!("<UANodeSet><UAVariable NodeId=\"i=1\" BrowseName=\"V\"><Value>{value}</Value></UAVariable></UANodeSet>");
            let mut d = Diagnostics::new();
            let set = parse(FileId(0), &xml, &limits, &mut d);
            (set.is_some(), d.items.iter().map(|i| (i.code, i.message.clone())).collect::<Vec<_>>())
        };
        assert_eq!(parse_with("<A><B>12345678</B></A>"), (true, vec![]));
        let (ok, d) = parse_with("<A><B><C/></B></A>");
        assert!(!ok);
        assert_eq!(d, [(Code::TooDeep, "a value is nested more than 3 levels deep".to_string())]);
        let (ok, d) = parse_with("<A><B>1234<!---->56789</B></A>");
        assert!(!ok);
        assert_eq!(d, [(Code::TooLarge, "the text of <B> is longer than 8 bytes".to_string())]);
    }

    #[test]
    fn attribute_problems_are_reported_as_quick_xml_reports_them() {
        let node = |attrs: &str| format!("<UANodeSet><UAObject {attrs}><DisplayName>A</DisplayName></UAObject></UANodeSet>");
        let first = |xml: &str| {
            let (set, d) = parse_str(xml);
            (set.is_some(), d.items.first().map(|i| (i.code, i.message.clone(), i.span.map(|s| s.start))))
        };
        // Keys with one local name but different prefixes are distinct attributes.
        let (set, d) = parse_str(&node("NodeId=\"i=1\" BrowseName=\"A\" a:x=\"1\" b:x=\"2\""));
        assert!(d.items.is_empty(), "{d:?}");
        assert_eq!(set.unwrap().nodes[0].node_id.span.start, 29);
        let dup = first(&node("NodeId=\"i=1\" BrowseName=\"A\" NodeId=\"i=2\""));
        assert_eq!(
            dup,
            (false, Some((Code::XmlSyntax, "malformed attribute: position 37: duplicated attribute, previous declaration at position 9".into(), Some(11))))
        );
        // A bad value before a duplicate is reported first, as in document order.
        let (ok, d) = first(&node("NodeId=\"&bogus;\" NodeId=\"i=2\""));
        assert!(!ok);
        assert_eq!(d.unwrap().1, "malformed attribute value: at 1..6: unrecognized entity `bogus`");
        let (ok, d) = first(&node("NodeId=i=1 BrowseName=\"A\""));
        assert!(!ok);
        assert!(d.unwrap().1.starts_with("malformed attribute: "));
    }

    #[test]
    fn the_attribute_scan_reads_what_quick_xml_reads_or_gives_up() {
        let tags = [
            "a", "a b=\"1\"", "a  b='1'\tc=\"x y\"\r\n d=\"\"", "a b=\"1\"c=\"2\"", "a x:b=\"&amp;\" y:b='\"'", "a b = \"1\"",
            "a b=1", "a b=\"1", "a b", "a =\"1\"", "a b=", "a b=\"1\" c", "a b=\"1\" ", "a b=\"<\"", "a b\"c=\"1\"",
        ];
        for tag in tags {
            let e = BytesStart::from_content(tag, tag.find(' ').or_else(|| tag.find('\t')).unwrap_or(tag.len()));
            let content: &[u8] = &e;
            let scan: Result<Vec<_>, GaveUp> = AttributeScan { content, at: e.name().into_inner().len() }.collect();
            let quick: Result<Vec<(Vec<u8>, Vec<u8>)>, _> =
                e.attributes().with_checks(false).map(|a| a.map(|a| (a.key.into_inner().to_vec(), a.value.to_vec()))).collect();
            if let Ok(scan) = scan {
                let scan: Vec<(Vec<u8>, Vec<u8>)> = scan.into_iter().map(|(k, v)| (k.to_vec(), v.to_vec())).collect();
                assert_eq!(Ok(scan), quick.map_err(|_| ()), "{tag}");
            }
        }
    }

    #[test]
    fn node_ids_and_references_borrow_from_the_text_unless_it_differs() {
        let xml = "<UANodeSet><UAObject NodeId=\"ns=1;s=a&amp;b\" BrowseName=\"1:A\"><References>\
            <Reference ReferenceType=\" HasComponent \">\r\n  ns=1;i=5\r\n</Reference>\
            <Reference ReferenceType=\"Organizes\" IsForward=\"false\">i=85</Reference></References></UAObject></UANodeSet>";
        let (set, d) = parse_str(xml);
        assert!(d.items.is_empty(), "{d:?}");
        let set = set.unwrap();
        let n = &set.nodes[0];
        assert_eq!(n.node_id.get(xml), "ns=1;s=a&b");
        assert_eq!(&xml[n.node_id.span.start as usize..n.node_id.span.end as usize], "ns=1;s=a&amp;b");
        assert_eq!(n.browse_name.get(xml), "1:A");
        let r = set.references_of(n);
        assert_eq!((r[0].reference_type.get(xml), r[0].target.get(xml)), ("HasComponent", "ns=1;i=5"));
        assert_eq!(&xml[r[0].reference_type.span.start as usize..r[0].reference_type.span.end as usize], " HasComponent ");
        // The target's span is computed on the text after line-break normalisation, as it always was.
        let t = r[0].target.span;
        assert_eq!(&xml[t.start as usize..t.end as usize], " ns=1;i=");
        assert_eq!((r[1].reference_type.get(xml), r[1].target.get(xml), r[1].is_forward), ("Organizes", "i=85", false));
    }

    #[test]
    fn truncated_file_is_an_error_not_a_partial_model() {
        let (set, d) = parse_str("<UANodeSet><UAObject NodeId=\"i=1\" BrowseName=\"A\"><DisplayName>A</DisplayName>");
        assert!(set.is_none());
        assert_eq!(d.items[0].code, Code::Truncated);
    }

    #[test]
    fn doctype_is_rejected() {
        let (set, d) = parse_str("<!DOCTYPE x [<!ENTITY a \"b\">]><UANodeSet/>");
        assert!(set.is_none());
        assert_eq!(d.items[0].code, Code::Doctype);
    }

    #[test]
    fn deep_nesting_is_bounded() {
        let depth = 100_000;
        let xml = format!("<UANodeSet>{}{}</UANodeSet>", "<a>".repeat(depth), "</a>".repeat(depth));
        let (set, d) = parse_str(&xml);
        assert!(set.is_none());
        assert!(d.items.iter().any(|i| i.code == Code::TooDeep), "{d:?}");
    }

    #[test]
    fn utf16_and_bad_utf8_are_rejected() {
        assert!(decode_text(vec![0xFF, 0xFE, b'<', 0]).is_err());
        let (_, at) = decode_text(b"<a>\xC3\x28</a>".to_vec()).unwrap_err();
        assert_eq!(at, 3);
        assert_eq!(decode_text(b"\xEF\xBB\xBF<a/>".to_vec()).unwrap(), "<a/>");
    }
}
