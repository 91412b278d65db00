//! The decoder of the packed format (documented in [`super`]): text to [`NodeRow`]s and [`AccessRow`]s.

use super::*;

/// Decodes the `Access` lines of packed text.
pub fn decode_access(text: &'static str) -> Result<Box<[AccessRow]>, (usize, usize, String)> {
    decode_lines(text, ACCESS, |c| {
        let id = c.id()?;
        c.sp()?;
        let restrictions = if c.eat(b'~') { None } else { Some(c.num("AccessRestrictions")?) };
        let mut roles = Vec::new();
        while c.eat(b' ') {
            let role = c.id()?;
            c.expect(b'=')?;
            roles.push((role, c.num("PermissionType bits")?));
        }
        match c.peek() {
            None => Ok(AccessRow { id, restrictions, roles }),
            Some(f) => Err(format!("unexpected `{}` after the access row", f as char)),
        }
    })
}

/// Decodes the `Overrides` lines of packed text.
pub fn decode_overrides(text: &'static str) -> Result<Box<[OverrideRow]>, (usize, usize, String)> {
    decode_lines(text, OVERRIDES, |c| {
        let id = c.id()?;
        c.sp()?;
        let overridden = c.id()?;
        match c.peek() {
            None => Ok(OverrideRow { id, overridden }),
            Some(f) => Err(format!("unexpected `{}` after the override row", f as char)),
        }
    })
}

/// Decodes each line of packed text that starts with `prefix` with `row`; an error is (line, column, message).
fn decode_lines<T>(
    text: &'static str,
    prefix: &str,
    mut row: impl FnMut(&mut Cursor) -> Result<T, String>,
) -> Result<Box<[T]>, (usize, usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.split('\n').enumerate() {
        let Some(rest) = line.strip_prefix(prefix) else { continue };
        let mut c = Cursor { s: line, b: line.as_bytes(), i: line.len() - rest.len() };
        match row(&mut c) {
            Ok(r) => out.push(r),
            Err(message) => {
                let column = line.get(..c.i.min(line.len())).map_or(c.i, |p| p.chars().count()) + 1;
                return Err((n + 1, column, message));
            }
        }
    }
    Ok(out.into_boxed_slice())
}

/// Decodes packed text into rows. Strings without escapes are slices of `text`; everything else the rows
/// point to is allocated once and leaked, because rows are `'static` data and a table is decoded once per
/// process. An error is (line, column, message).
pub fn decode(text: &'static str) -> Result<Box<[NodeRow]>, (usize, usize, String)> {
    let mut rows = Vec::with_capacity(text.len() / 128);
    // Numeric references of all rows in one allocation; each row's range is filled in at the end.
    let mut nrefs: Vec<NumRef> = Vec::with_capacity(text.len() / 48);
    let mut ranges: Vec<(usize, usize)> = Vec::with_capacity(text.len() / 128);
    let mut refs: Vec<Ref> = Vec::new();
    for (n, line) in text.split('\n').enumerate() {
        if line.is_empty() || line.starts_with(ACCESS) || line.starts_with(OVERRIDES) {
            continue;
        }
        let mut c = Cursor { s: line, b: line.as_bytes(), i: 0 };
        refs.clear();
        match c.row(&mut refs) {
            Ok(mut row) => {
                let numeric = |id: &Id| match id.id {
                    IdKind::Numeric(v) => Some((id.ns, v)),
                    _ => None,
                };
                let start = nrefs.len();
                let all_numeric = refs.iter().all(|r| numeric(&r.reference_type).is_some() && numeric(&r.target).is_some());
                if all_numeric {
                    nrefs.extend(refs.iter().filter_map(|r| {
                        let ((rns, rid), (tns, tid)) = (numeric(&r.reference_type)?, numeric(&r.target)?);
                        Some((rns, rid, tns, tid, r.forward))
                    }));
                } else {
                    row.refs = leak(refs.clone());
                }
                ranges.push((start, nrefs.len()));
                rows.push(row);
            }
            Err(message) => {
                let column = line.get(..c.i.min(line.len())).map_or(c.i, |p| p.chars().count()) + 1;
                return Err((n + 1, column, message));
            }
        }
    }
    let nrefs: &'static [NumRef] = leak(nrefs);
    for (row, (a, b)) in rows.iter_mut().zip(ranges) {
        row.nrefs = &nrefs[a..b];
    }
    Ok(rows.into_boxed_slice())
}

fn leak<T>(v: Vec<T>) -> &'static [T] {
    Box::leak(v.into_boxed_slice())
}

type Res<T> = Result<T, String>;

/// A position in one line of packed text.
struct Cursor {
    s: &'static str,
    b: &'static [u8],
    i: usize,
}

impl Cursor {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn eat(&mut self, c: u8) -> bool {
        let hit = self.peek() == Some(c);
        if hit {
            self.i += 1;
        }
        hit
    }

    fn expect(&mut self, c: u8) -> Res<()> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(match self.peek() {
                Some(f) => format!("expected `{}`, found `{}`", c as char, f as char),
                None => format!("expected `{}`, found the end of the line", c as char),
            })
        }
    }

    /// `' '` then the next item.
    fn sp(&mut self) -> Res<()> {
        self.expect(b' ')
    }

    /// A word of ASCII letters and digits (a class, a tag such as `Int32`).
    fn word(&mut self) -> &'static str {
        let start = self.i;
        while self.peek().is_some_and(|c| c.is_ascii_alphanumeric()) {
            self.i += 1;
        }
        &self.s[start..self.i]
    }

    /// A decimal integer. The magnitude is read as a u64 (no table number needs more, since every target type
    /// has at most 64 bits), which is cheaper than 128-bit arithmetic per digit.
    fn int(&mut self) -> Res<i128> {
        let neg = self.eat(b'-');
        let start = self.i;
        let mut v: u64 = 0;
        while let Some(d) = self.peek().filter(u8::is_ascii_digit) {
            v = v.checked_mul(10).and_then(|v| v.checked_add(u64::from(d - b'0'))).ok_or("number too large")?;
            self.i += 1;
        }
        if self.i == start {
            return Err("expected a number".into());
        }
        let v = i128::from(v);
        Ok(if neg { -v } else { v })
    }

    fn num<T: TryFrom<i128>>(&mut self, what: &str) -> Res<T> {
        let start = self.i;
        let v = self.int()?;
        T::try_from(v).map_err(|_| {
            self.i = start;
            format!("{v} is out of range for {what}")
        })
    }

    fn bool(&mut self) -> Res<bool> {
        match self.peek() {
            Some(b'0') => {
                self.i += 1;
                Ok(false)
            }
            Some(b'1') => {
                self.i += 1;
                Ok(true)
            }
            _ => Err("expected a boolean, `0` or `1`".into()),
        }
    }

    /// Text up to the next delimiter, for floats.
    fn token(&mut self) -> &'static str {
        let start = self.i;
        while self.peek().is_some_and(|c| !matches!(c, b' ' | b'}' | b']' | b',')) {
            self.i += 1;
        }
        &self.s[start..self.i]
    }

    fn f64(&mut self) -> Res<f64> {
        let t = self.token();
        t.parse().map_err(|_| format!("`{t}` is not a number"))
    }

    fn f32(&mut self) -> Res<f32> {
        let t = self.token();
        t.parse().map_err(|_| format!("`{t}` is not a number"))
    }

    /// Pairs of hex digits.
    fn hex(&mut self) -> Res<Vec<u8>> {
        let digit = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
        let mut out = Vec::new();
        while let Some(hi) = self.peek().and_then(digit) {
            self.i += 1;
            let lo = self.peek().and_then(digit).ok_or("odd number of hex digits")?;
            self.i += 1;
            out.push(hi << 4 | lo);
        }
        Ok(out)
    }

    fn guid(&mut self) -> Res<[u8; 16]> {
        self.hex()?.try_into().map_err(|_| "a GUID is 32 hex digits".into())
    }

    fn string(&mut self) -> Res<&'static str> {
        self.expect(b'"')?;
        let start = self.i;
        loop {
            match self.peek() {
                None => return Err("unterminated string".into()),
                Some(b'"') => {
                    self.i += 1;
                    return Ok(&self.s[start..self.i - 1]);
                }
                Some(b'\\') => break,
                Some(_) => self.i += 1,
            }
        }
        let mut out = String::from(&self.s[start..self.i]);
        loop {
            match self.peek() {
                None => return Err("unterminated string".into()),
                Some(b'"') => {
                    self.i += 1;
                    return Ok(Box::leak(out.into_boxed_str()));
                }
                Some(b'\\') => {
                    self.i += 1;
                    let e = self.peek().ok_or("unterminated string")?;
                    self.i += 1;
                    out.push(match e {
                        b'"' => '"',
                        b'\\' => '\\',
                        b'n' => '\n',
                        b'r' => '\r',
                        b't' => '\t',
                        b'u' => {
                            self.expect(b'{')?;
                            let start = self.i;
                            while self.peek().is_some_and(|c| c.is_ascii_hexdigit()) {
                                self.i += 1;
                            }
                            let code = u32::from_str_radix(&self.s[start..self.i], 16).map_err(|_| "bad `\\u{..}` escape")?;
                            self.expect(b'}')?;
                            char::from_u32(code).ok_or("`\\u{..}` is not a character")?
                        }
                        e => return Err(format!("unknown escape `\\{}`", e as char)),
                    });
                }
                Some(_) => {
                    let start = self.i;
                    while self.peek().is_some_and(|c| c != b'"' && c != b'\\') {
                        self.i += 1;
                    }
                    out.push_str(&self.s[start..self.i]);
                }
            }
        }
    }

    fn opt_string(&mut self) -> Res<Option<&'static str>> {
        if self.eat(b'~') {
            Ok(None)
        } else {
            self.string().map(Some)
        }
    }

    /// A string, or `=` for `same`.
    fn string_or(&mut self, same: &'static str) -> Res<&'static str> {
        if self.eat(b'=') {
            Ok(same)
        } else {
            self.string()
        }
    }

    fn id(&mut self) -> Res<Id> {
        let ns = self.num("a namespace index")?;
        self.expect(b':')?;
        let id = match self.peek() {
            Some(b's') => {
                self.i += 1;
                IdKind::String(self.string()?)
            }
            Some(b'g') => {
                self.i += 1;
                IdKind::Guid(self.guid()?)
            }
            Some(b'b') => {
                self.i += 1;
                IdKind::Opaque(leak(self.hex()?))
            }
            _ => IdKind::Numeric(self.num("a numeric identifier")?),
        };
        Ok(Id { ns, id })
    }

    fn opt_id(&mut self) -> Res<Option<Id>> {
        if self.eat(b'~') {
            Ok(None)
        } else {
            self.id().map(Some)
        }
    }

    /// `ns:"name"`.
    fn qualified(&mut self) -> Res<(u16, &'static str)> {
        let ns = self.num("a namespace index")?;
        self.expect(b':')?;
        Ok((ns, self.string()?))
    }

    fn dims(&mut self) -> Res<&'static [u32]> {
        self.expect(b'[')?;
        if self.eat(b']') {
            return Ok(&[]);
        }
        let mut v = Vec::new();
        loop {
            v.push(self.num("an array dimension")?);
            if self.eat(b']') {
                return Ok(leak(v));
            }
            self.expect(b',')?;
        }
    }

    /// `{ item item }` or `{ }`.
    fn list<T>(&mut self, mut item: impl FnMut(&mut Self) -> Res<T>) -> Res<&'static [T]> {
        self.expect(b'{')?;
        let mut v = Vec::new();
        loop {
            self.sp()?;
            if self.eat(b'}') {
                return Ok(leak(v));
            }
            v.push(item(self)?);
        }
    }

    fn enum_row(&mut self) -> Res<EnumRow> {
        let value = self.num("an enumeration value")?;
        self.sp()?;
        let name = self.string()?;
        self.sp()?;
        let display_name = self.string_or(name)?;
        self.sp()?;
        Ok(EnumRow { value, name, display_name, description: self.opt_string()? })
    }

    fn field_row(&mut self) -> Res<FieldRow> {
        let name = self.string()?;
        self.sp()?;
        let description = self.opt_string()?;
        self.sp()?;
        let data_type = self.id()?;
        self.sp()?;
        let value_rank = self.num("a ValueRank")?;
        self.sp()?;
        let array_dimensions = self.dims()?;
        self.sp()?;
        let max_string_length = self.num("a MaxStringLength")?;
        self.sp()?;
        Ok(FieldRow { name, description, data_type, value_rank, array_dimensions, max_string_length, is_optional: self.bool()? })
    }

    fn arg_row(&mut self) -> Res<ArgRow> {
        let name = self.string()?;
        self.sp()?;
        let data_type = self.id()?;
        self.sp()?;
        let value_rank = self.num("a ValueRank")?;
        self.sp()?;
        let array_dimensions = self.dims()?;
        self.sp()?;
        Ok(ArgRow { name, data_type, value_rank, array_dimensions, description: self.opt_string()? })
    }

    fn definition(&mut self) -> Res<Option<Def>> {
        if self.eat(b'~') {
            return Ok(None);
        }
        let kind = match self.word() {
            "Enum" => {
                self.sp()?;
                return Ok(Some(Def::Enum { fields: self.list(Self::enum_row)? }));
            }
            "Structure" => StructureKind::Structure,
            "StructureWithOptionalFields" => StructureKind::StructureWithOptionalFields,
            "Union" => StructureKind::Union,
            w => return Err(format!("unknown definition `{w}`")),
        };
        self.sp()?;
        let base = self.id()?;
        self.sp()?;
        let default_encoding = self.opt_id()?;
        self.sp()?;
        Ok(Some(Def::Structure { base, default_encoding, kind, fields: self.list(Self::field_row)? }))
    }

    fn value(&mut self) -> Res<Val> {
        if self.eat(b'~') {
            return Ok(Val::None);
        }
        let tag = self.word();
        self.expect(b':')?;
        Ok(match tag {
            "Boolean" => Val::Boolean(self.bool()?),
            "SByte" => Val::SByte(self.num("SByte")?),
            "Byte" => Val::Byte(self.num("Byte")?),
            "Int16" => Val::Int16(self.num("Int16")?),
            "UInt16" => Val::UInt16(self.num("UInt16")?),
            "Int32" => Val::Int32(self.num("Int32")?),
            "UInt32" => Val::UInt32(self.num("UInt32")?),
            "Int64" => Val::Int64(self.num("Int64")?),
            "UInt64" => Val::UInt64(self.num("UInt64")?),
            "Float" => Val::Float(self.f32()?),
            "Double" => Val::Double(self.f64()?),
            "String" => Val::String(self.string()?),
            "DateTime" => Val::DateTime(self.string()?),
            "Guid" => Val::Guid(self.guid()?),
            "ByteString" => Val::ByteString(leak(self.hex()?)),
            "NodeId" => Val::NodeId(self.id()?),
            "ExpandedNodeId" => Val::ExpandedNodeId(self.id()?),
            "StatusCode" => Val::StatusCode(self.num("a StatusCode")?),
            "QualifiedName" => {
                let (ns, name) = self.qualified()?;
                Val::QualifiedName(ns, name)
            }
            "LocalizedText" => {
                let locale = self.opt_string()?;
                self.expect(b':')?;
                Val::LocalizedText(locale, self.string()?)
            }
            "Array" => {
                let ty = self.num("a DataType number")?;
                self.sp()?;
                Val::Array(ty, self.list(Self::value)?)
            }
            "Structure" => {
                let encoding = self.id()?;
                self.sp()?;
                Val::Structure(encoding, self.list(Self::value)?)
            }
            "Fields" => Val::Fields(self.list(Self::value)?),
            "Variant" => Val::Variant(Box::leak(Box::new(self.value()?))),
            "Null" => Val::Null(self.num("a DataType number")?),
            "NullArray" => Val::NullArray(self.num("a DataType number")?),
            "Arguments" => Val::Arguments(self.list(Self::arg_row)?),
            "EnumValues" => Val::EnumValues(self.list(Self::enum_row)?),
            t => return Err(format!("unknown value tag `{t}`")),
        })
    }

    /// One line; its references go to `refs`.
    fn row(&mut self, refs: &mut Vec<Ref>) -> Res<NodeRow> {
        let class = self.word();
        if !matches!(
            class,
            "Object" | "ObjectType" | "Variable" | "VariableType" | "Method" | "ReferenceType" | "DataType" | "View"
        ) {
            self.i = 0;
            return Err(format!("unknown node class `{class}`"));
        }
        self.sp()?;
        let id = self.id()?;
        self.sp()?;
        let browse_name = self.qualified()?;
        self.sp()?;
        let display_name = self.string_or(browse_name.1)?;
        self.sp()?;
        let description = self.opt_string()?;
        self.sp()?;
        let write_mask = self.num("a WriteMask")?;
        self.sp()?;
        let user_write_mask = self.num("a UserWriteMask")?;
        self.sp()?;
        let kind = match class {
            "Object" => Kind::Object { event_notifier: self.num("an EventNotifier")? },
            "ObjectType" => Kind::ObjectType { is_abstract: self.bool()? },
            "Variable" | "VariableType" => {
                let data_type = self.id()?;
                self.sp()?;
                let value_rank = self.num("a ValueRank")?;
                self.sp()?;
                let array_dimensions = self.dims()?;
                self.sp()?;
                if class == "Variable" {
                    let access_level = self.num("an AccessLevel")?;
                    self.sp()?;
                    let user_access_level = self.num("a UserAccessLevel")?;
                    self.sp()?;
                    let historizing = self.bool()?;
                    self.sp()?;
                    let minimum_sampling_interval = if self.eat(b'~') { None } else { Some(self.f64()?) };
                    self.sp()?;
                    Kind::Variable {
                        data_type,
                        value_rank,
                        array_dimensions,
                        access_level,
                        user_access_level,
                        historizing,
                        minimum_sampling_interval,
                        value: self.value()?,
                    }
                } else {
                    let is_abstract = self.bool()?;
                    self.sp()?;
                    Kind::VariableType { data_type, value_rank, array_dimensions, is_abstract, value: self.value()? }
                }
            }
            "Method" => {
                let executable = self.bool()?;
                self.sp()?;
                Kind::Method { executable, user_executable: self.bool()? }
            }
            "ReferenceType" => {
                let symmetric = self.bool()?;
                self.sp()?;
                let is_abstract = self.bool()?;
                self.sp()?;
                Kind::ReferenceType { symmetric, is_abstract, inverse_name: self.opt_string()? }
            }
            "DataType" => {
                let is_abstract = self.bool()?;
                self.sp()?;
                Kind::DataType { is_abstract, definition: self.definition()? }
            }
            "View" => {
                let event_notifier = self.num("an EventNotifier")?;
                self.sp()?;
                Kind::View { event_notifier, contains_no_loops: self.bool()? }
            }
            c => return Err(format!("unknown node class `{c}`")),
        };
        while self.i < self.b.len() {
            self.sp()?;
            let reference_type = self.id()?;
            let forward = match self.peek() {
                Some(b'>') => true,
                Some(b'<') => false,
                _ => return Err("expected `>` or `<` between a reference's type and target".into()),
            };
            self.i += 1;
            refs.push(Ref { reference_type, target: self.id()?, forward });
        }
        Ok(NodeRow {
            id,
            browse_name,
            display_name,
            description,
            write_mask,
            user_write_mask,
            kind,
            refs: &[],
            nrefs: &[],
        })
    }
}
