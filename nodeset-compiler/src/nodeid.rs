//! NodeIds and QualifiedNames in their NodeSet2 text forms.
//!
//! A NodeSet2 file writes NodeIds as `i=85`, `ns=1;s=Name`, `g=…`, `b=…` or `nsu=http://…;i=5`. The
//! namespace index in such a string is local to the file (an index into its `NamespaceUris`); the loader
//! maps it to the global namespace table, giving a [`NodeId`] that is the same whichever file it came from.

use std::fmt;

/// The identifier part of a NodeId.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Identifier {
    /// `i=N`: a numeric identifier.
    Numeric(u32),
    /// `s=...`: a string identifier.
    String(Box<str>),
    /// `g=...`: a GUID, as its 16 bytes in text order.
    Guid([u8; 16]),
    /// `b=...`: an opaque identifier (a ByteString, written in base64).
    Opaque(Box<[u8]>),
}

impl fmt::Display for Identifier {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Identifier::Numeric(n) => write!(f, "i={n}"),
            Identifier::String(s) => write!(f, "s={s}"),
            Identifier::Guid(g) => write!(f, "g={}", format_guid(g)),
            Identifier::Opaque(b) => write!(f, "b={}", base64_encode(b)),
        }
    }
}

/// A NodeId with a global namespace index (an index into the model's namespace table).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NodeId {
    /// The global namespace index.
    pub ns: u16,
    /// The identifier within the namespace.
    pub id: Identifier,
}

impl NodeId {
    /// The numeric NodeId `n` in namespace `ns`.
    pub const fn numeric(ns: u16, n: u32) -> NodeId {
        NodeId { ns, id: Identifier::Numeric(n) }
    }

    /// The ns0 numeric id, if this is one.
    pub fn ns0(&self) -> Option<u32> {
        match (self.ns, &self.id) {
            (0, Identifier::Numeric(n)) => Some(*n),
            _ => None,
        }
    }
}

impl fmt::Display for NodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.ns == 0 {
            write!(f, "{}", self.id)
        } else {
            write!(f, "ns={};{}", self.ns, self.id)
        }
    }
}

/// How a NodeId string names its namespace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NsRef {
    /// `ns=N` (or no prefix, meaning 0): an index into the file's NamespaceUris.
    Index(u16),
    /// `nsu=URI`.
    Uri(String),
}

/// A NodeId as written in a file, before namespace mapping.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RawNodeId {
    /// The namespace, as written.
    pub ns: NsRef,
    /// The identifier.
    pub id: Identifier,
}

/// Whether a string is written in NodeId syntax (rather than being an alias name).
pub fn looks_like_node_id(s: &str) -> bool {
    let s = s.trim();
    ["i=", "s=", "g=", "b=", "ns=", "nsu="].iter().any(|p| s.starts_with(p))
}

/// Parses the text form of a NodeId. The error says what is wrong, for a diagnostic.
pub fn parse_node_id(text: &str) -> Result<RawNodeId, String> {
    let s = text.trim();
    if s.is_empty() {
        return Err("the NodeId is empty".into());
    }
    let (ns, rest) = if let Some(r) = s.strip_prefix("nsu=") {
        let Some(semi) = r.find(';') else {
            return Err("`nsu=` must be followed by `;` and an identifier".into());
        };
        let uri = &r[..semi];
        if uri.is_empty() {
            return Err("the namespace URI after `nsu=` is empty".into());
        }
        (NsRef::Uri(uri.to_string()), &r[semi + 1..])
    } else if let Some(r) = s.strip_prefix("ns=") {
        let Some(semi) = r.find(';') else {
            return Err("`ns=` must be followed by `;` and an identifier".into());
        };
        let idx: u16 = r[..semi]
            .parse()
            .map_err(|_| format!("the namespace index `{}` is not a number from 0 to 65535", &r[..semi]))?;
        (NsRef::Index(idx), &r[semi + 1..])
    } else {
        (NsRef::Index(0), s)
    };
    let id = parse_identifier(rest)?;
    Ok(RawNodeId { ns, id })
}

/// The common numeric NodeIds, `i=N` and `ns=I;i=N`, as `(I, N)` (`I` is 0 without `ns=`): what
/// [`parse_node_id`] makes of such a string, without allocating; `None` for any other string, including
/// every malformed one (which [`parse_node_id`] then explains).
pub fn parse_numeric_node_id(text: &str) -> Option<(u16, u32)> {
    // Most strings asked about are not numeric NodeIds (BrowseNames, aliases): turn them away at the first
    // byte unless it is `i`, `n` or possibly white space.
    let first = *text.as_bytes().first()?;
    if !matches!(first, b'i' | b'n') && first < 0x80 && !(first as char).is_whitespace() {
        return None;
    }
    let s = text.trim();
    let (ns, rest) = match s.strip_prefix("ns=") {
        Some(r) => {
            let semi = r.find(';')?;
            (r[..semi].parse().ok()?, &r[semi + 1..])
        }
        None => (0, s),
    };
    Some((ns, rest.strip_prefix("i=")?.parse().ok()?))
}

fn parse_identifier(s: &str) -> Result<Identifier, String> {
    if let Some(n) = s.strip_prefix("i=") {
        return n
            .parse::<u32>()
            .map(Identifier::Numeric)
            .map_err(|_| format!("the numeric identifier `{n}` is not a number from 0 to 4294967295"));
    }
    if let Some(v) = s.strip_prefix("s=") {
        if v.is_empty() {
            return Err("the string identifier is empty".into());
        }
        return Ok(Identifier::String(v.into()));
    }
    if let Some(g) = s.strip_prefix("g=") {
        return parse_guid(g).map(Identifier::Guid).ok_or_else(|| format!("`{g}` is not a GUID"));
    }
    if let Some(b) = s.strip_prefix("b=") {
        return base64_decode(b)
            .map(|v| Identifier::Opaque(v.into()))
            .ok_or_else(|| format!("`{b}` is not base64"));
    }
    Err(format!("`{s}` does not start with `i=`, `s=`, `g=` or `b=`"))
}

/// Parses `xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx` (braces allowed) into the 16 bytes of its text order.
pub fn parse_guid(s: &str) -> Option<[u8; 16]> {
    let s = s.trim().trim_start_matches('{').trim_end_matches('}');
    let groups: Vec<&str> = s.split('-').collect();
    if groups.len() != 5 || [8, 4, 4, 4, 12].iter().zip(&groups).any(|(n, g)| g.len() != *n) {
        return None;
    }
    let hex: String = groups.concat();
    let mut out = [0u8; 16];
    for (i, o) in out.iter_mut().enumerate() {
        *o = u8::from_str_radix(hex.get(2 * i..2 * i + 2)?, 16).ok()?;
    }
    Some(out)
}

/// Writes 16 bytes in text order as lowercase `xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx` (what [`parse_guid`] reads).
pub fn format_guid(g: &[u8; 16]) -> String {
    let h: String = g.iter().map(|b| format!("{b:02x}")).collect();
    format!("{}-{}-{}-{}-{}", &h[0..8], &h[8..12], &h[12..16], &h[16..20], &h[20..32])
}

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// The value of each base64 character, 255 for characters that are not base64.
const B64_INV: [u8; 256] = {
    let mut t = [255u8; 256];
    let mut i = 0;
    while i < 64 {
        t[B64[i] as usize] = i as u8;
        i += 1;
    }
    t
};

/// Decodes standard base64, ignoring white space (NodeSet2 files wrap long ByteStrings).
pub fn base64_decode(s: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(s.len() * 3 / 4);
    base64_each(s, |b| out.push(b)).then_some(out)
}

/// Whether [`base64_decode`] accepts `s`, without decoding it: letters of the alphabet (none after a `=`),
/// white space, and at most two `=`.
pub fn base64_valid(s: &str) -> bool {
    let b = s.as_bytes();
    let mut i = 0;
    let mut padding = 0;
    while i < b.len() {
        // Runs of letters, the common case, take one test per byte.
        if padding == 0 {
            while i < b.len() && B64_INV[b[i] as usize] != 255 {
                i += 1;
            }
            if i == b.len() {
                break;
            }
        }
        let c = b[i];
        if B64_INV[c as usize] != 255 {
            // A letter after a `=`.
            return false;
        }
        if c == b'=' {
            padding += 1;
        } else if !c.is_ascii_whitespace() {
            return false;
        }
        i += 1;
    }
    padding <= 2
}

/// Decodes base64 (white space ignored, padding optional), handing each byte to `out`; false if `s` is not
/// base64.
fn base64_each(s: &str, mut out: impl FnMut(u8)) -> bool {
    let mut acc = 0u32;
    let mut bits = 0;
    let mut padding = 0;
    for &c in s.as_bytes() {
        let v = B64_INV[c as usize];
        if v == 255 {
            if c.is_ascii_whitespace() {
                continue;
            }
            if c == b'=' {
                padding += 1;
                continue;
            }
            return false;
        }
        if padding > 0 {
            return false;
        }
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    padding <= 2
}

/// Encodes `data` as standard base64, with `=` padding.
pub fn base64_encode(data: &[u8]) -> String {
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(B64[((n >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A QualifiedName as written in a file: `Name` (namespace 0) or `N:Name`, N local to the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RawQualifiedName {
    /// The namespace index, local to the file (0 without a prefix).
    pub ns: u16,
    /// The name after the prefix.
    pub name: String,
}

/// Parses `N:Name`. A colon not preceded by a number belongs to the name (`Unit:m` is ns 0, name `Unit:m`).
pub fn parse_qualified_name(s: &str) -> Result<RawQualifiedName, String> {
    if let Some(colon) = s.find(':') {
        let prefix = &s[..colon];
        if !prefix.is_empty() && prefix.bytes().all(|b| b.is_ascii_digit()) {
            let ns: u16 = prefix
                .parse()
                .map_err(|_| format!("the namespace index `{prefix}` is not a number from 0 to 65535"))?;
            let name = &s[colon + 1..];
            if name.is_empty() {
                return Err("the name after the namespace index is empty".into());
            }
            return Ok(RawQualifiedName { ns, name: name.to_string() });
        }
    }
    if s.is_empty() {
        return Err("the BrowseName is empty".into());
    }
    Ok(RawQualifiedName { ns: 0, name: s.to_string() })
}

/// A QualifiedName with a global namespace index.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct QualifiedName {
    /// The global namespace index.
    pub ns: u16,
    /// The name, without a namespace prefix.
    pub name: String,
}

impl fmt::Display for QualifiedName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.ns == 0 {
            f.write_str(&self.name)
        } else {
            write!(f, "{}:{}", self.ns, self.name)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numeric_fast_path_agrees_with_the_general_parser() {
        let cases = [
            "i=85", " ns=1;i=5001 ", "ns=65535;i=4294967295", "i=+7", "ns=01;i=007", "ns=1; i=5", "ns=70000;i=1", "i=4294967296",
            "i=", "ns=1;", "ns=;i=1", "nsu=http://x/;i=1", "s=i=1", "g=09087e75-8e5e-499b-954f-f2a9603db28a", "b=AQID", "", "i=1x",
            "I=1", "ns=1;s=Name", "1:Name", "Name", "\u{a0}i=5", "\u{b}i=5", "\u{3000}ns=1;i=2", "nsx",
        ];
        for c in cases {
            let general = parse_node_id(c).ok().and_then(|r| match (r.ns, r.id) {
                (NsRef::Index(ns), Identifier::Numeric(n)) => Some((ns, n)),
                _ => None,
            });
            assert_eq!(parse_numeric_node_id(c), general, "{c:?}");
        }
    }

    #[test]
    fn parses_every_node_id_form() {
        assert_eq!(parse_node_id("i=85").unwrap(), RawNodeId { ns: NsRef::Index(0), id: Identifier::Numeric(85) });
        assert_eq!(
            parse_node_id("ns=2;s=a;b=c").unwrap(),
            RawNodeId { ns: NsRef::Index(2), id: Identifier::String("a;b=c".into()) }
        );
        assert_eq!(
            parse_node_id("nsu=http://x/;i=5").unwrap(),
            RawNodeId { ns: NsRef::Uri("http://x/".into()), id: Identifier::Numeric(5) }
        );
        let g = parse_node_id("ns=1;g=09087e75-8e5e-499b-954f-f2a9603db28a").unwrap();
        assert_eq!(g.id.to_string(), "g=09087e75-8e5e-499b-954f-f2a9603db28a");
        let b = parse_node_id("b=M/RbKBsRVkePCePcx24oRA==").unwrap();
        assert_eq!(b.id.to_string(), "b=M/RbKBsRVkePCePcx24oRA==");
    }

    #[test]
    fn rejects_malformed_node_ids() {
        for bad in ["", "i=", "i=-1", "i=99999999999", "ns=x;i=1", "ns=1", "nsu=;i=1", "x=1", "g=1234", "b=!!", "s="] {
            assert!(parse_node_id(bad).is_err(), "{bad:?} should be rejected");
        }
    }

    #[test]
    fn qualified_names_keep_colons_that_are_not_prefixes() {
        assert_eq!(parse_qualified_name("1:3DFrame").unwrap(), RawQualifiedName { ns: 1, name: "3DFrame".into() });
        assert_eq!(parse_qualified_name("Unit:m").unwrap(), RawQualifiedName { ns: 0, name: "Unit:m".into() });
        assert_eq!(parse_qualified_name("<AxisIdentifier>").unwrap().name, "<AxisIdentifier>");
        assert!(parse_qualified_name("1:").is_err());
        assert!(parse_qualified_name("").is_err());
    }

    #[test]
    fn base64_round_trips() {
        for data in [&b""[..], b"a", b"ab", b"abc", b"abcd", &[0, 255, 128, 7]] {
            assert_eq!(base64_decode(&base64_encode(data)).unwrap(), data);
        }
        assert_eq!(base64_decode("YW Jj\nZA==").unwrap(), b"abcd");
    }
}
