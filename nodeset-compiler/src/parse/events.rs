//! The XML event layer of the parser: reading events, attributes and text from quick-xml (with the
//! parser's own reading of the common forms), and the diagnostics for what is not well-formed XML.

use super::*;

impl<'a, 'd> Parser<'a, 'd> {
    /// A parser of `text[range]`, with spans in `text`.
    pub(super) fn new(file: FileId, text: &'a str, range: std::ops::Range<usize>, limits: &'a Limits, diags: &'d mut Diagnostics) -> Self {
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
    pub(super) fn pos(&self) -> usize {
        self.base + self.skipped + self.reader.buffer_position() as usize
    }

    pub(super) fn span(&self, start: usize, end: usize) -> Span {
        Span::new(self.file, start, end)
    }

    pub(super) fn offset_of(&self, s: &[u8]) -> usize {
        let base = self.text.as_ptr() as usize;
        let p = s.as_ptr() as usize;
        if p >= base && p <= base + self.text.len() {
            p - base
        } else {
            0
        }
    }

    pub(super) fn fatal(&mut self, d: Diagnostic) -> Fatal {
        self.diags.push(d);
        Fatal
    }

    /// Reports a quick-xml error at byte `at`, inside the innermost open element.
    pub(super) fn xml_error(&mut self, e: &quick_xml::Error, at: usize) -> Fatal {
        let at = at.min(self.text.len());
        let open = self.open.last().map(|(n, _)| *n);
        let d = xml_error_diag(e, self.span(at, at + 1), open);
        self.fatal(d)
    }

    /// The next event that matters: element starts and ends, text. Comments, PIs and the declaration are
    /// skipped (the declaration after its encoding is checked).
    pub(super) fn next(&mut self) -> PResult<Ev<'a>> {
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
    pub(super) fn str_at(&self, s: &[u8]) -> &'a str {
        let base = self.text.as_ptr() as usize;
        let p = s.as_ptr() as usize;
        if p < base || p + s.len() > base + self.text.len() {
            return "?";
        }
        self.text.get(p - base..p - base + s.len()).unwrap_or("?")
    }

    /// A string read at `span`, kept as a span where it is the input text there.
    pub(super) fn raw_str(&self, value: &str, span: Span) -> RawStr {
        RawStr::new(value, span, self.text)
    }

    /// The attributes of a start tag, in a list lent out by the parser: give it back with
    /// [`Parser::recycle`]. A malformed attribute or value stops the file.
    ///
    /// Attributes are read by [`AttributeScan`], which reads the common form (`key="value"`, each after
    /// white space) in one pass and gives up on anything else, and without quick-xml's duplicate check
    /// (it keeps a list of keys, allocated per element): the keys are compared here. Any problem (a tag the
    /// scan gives up on, or two attributes with one local name) hands the tag to
    /// [`Parser::attrs_checked`], quick-xml's reading with its checks, which decides what is reported: the
    /// attributes and diagnostics are quick-xml's whatever the path.
    pub(super) fn attrs(&mut self, e: &BytesStart<'a>, tag: Span) -> PResult<Vec<Attr<'a>>> {
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
    pub(super) fn attrs_checked(&mut self, e: &BytesStart<'a>, tag: Span, mut out: Vec<Attr<'a>>) -> PResult<Vec<Attr<'a>>> {
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
    pub(super) fn attr(&mut self, key: &'a str, value: &[u8]) -> PResult<Attr<'a>> {
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
    pub(super) fn recycle(&mut self, attrs: Vec<Attr<'a>>) {
        self.attr_buf = attrs;
    }

    /// Consumes the rest of an element whose start has been read.
    pub(super) fn skip(&mut self) -> PResult<()> {
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

    pub(super) fn unknown(&mut self, e: &BytesStart<'a>, span: Span, within: &str) -> PResult<()> {
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
    pub(super) fn text_content(&mut self, within: &str) -> PResult<Cow<'a, str>> {
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

    pub(super) fn localized(&mut self, e: &BytesStart<'a>, span: Span, name: &str) -> PResult<LocalizedText> {
        let attrs = self.attrs(e, span)?;
        let locale = attrs.iter().find(|a| a.key == "Locale").map(|a| a.value.to_string()).filter(|l| !l.is_empty());
        self.recycle(attrs);
        let text = self.text_content(name)?;
        Ok(LocalizedText { locale, text: text.trim().to_string() })
    }
}

/// A diagnostic for a bad entity or character reference in text that starts at `text_start`.
pub(super) fn escape_diag(e: &quick_xml::Error, text_start: usize, span: impl Fn(usize, usize) -> Span) -> Diagnostic {
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

pub(super) fn escape_error_diag(esc: &quick_xml::escape::EscapeError, text_start: usize, span: impl Fn(usize, usize) -> Span) -> Diagnostic {
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
pub(super) struct GaveUp;

/// Reads the attributes of a start tag in the form nearly every tag has: white space, a key, `=`, a value
/// in quotes. The key and value ranges are those quick-xml's attribute reader gives for such a tag; for
/// anything else (white space around `=`, a value without quotes or closing quote, a key without value) the
/// scan gives up and quick-xml reads the tag.
pub(super) struct AttributeScan<'t> {
    /// The tag between `<` and `>` (and any `/` of an empty element), as quick-xml hands it out.
    pub(super) content: &'t [u8],
    /// Where the scan is: after the element name, then after each value's closing quote.
    pub(super) at: usize,
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
pub(super) fn local(name: &[u8]) -> &[u8] {
    match name.iter().position(|&b| b == b':') {
        Some(i) => &name[i + 1..],
        None => name,
    }
}

pub(super) fn normalize_newlines(s: Cow<'_, str>) -> Cow<'_, str> {
    if s.contains('\r') {
        Cow::Owned(s.replace("\r\n", "\n").replace('\r', "\n"))
    } else {
        s
    }
}

pub(super) fn xml_error_diag(e: &quick_xml::Error, span: Span, open: Option<&str>) -> Diagnostic {
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
