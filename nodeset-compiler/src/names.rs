//! Identifiers for generated code: one sanitizer per target language, and name tables per scope.
//!
//! The rules, in order (they are the documentation users rely on):
//!
//! 1. A placeholder BrowseName `<AxisIdentifier>` loses its brackets (the caller records that it is a
//!    placeholder; the name itself is `AxisIdentifier`).
//! 2. The name is split into words at every character that is not a letter or digit, at lower-to-upper
//!    case changes (`MotionDevice` → `Motion` `Device`) and before the last capital of a run of capitals
//!    followed by lower case (`HTTPServer` → `HTTP` `Server`). A run of capitals ending in a lone `s` is one
//!    word (`IOs`, `PLCs`). Digits stay with the letters before them (`Axis1`), and a leading number stays
//!    with the letters after it when they are capitals (`3DFrame` → `3D` `Frame`).
//!
//!    With [`Case::Preserve`] (Modelica), a name that already is an identifier of ASCII letters, digits and
//!    underscores starting with a letter keeps its spelling: `MANUAL_REDUCED_SPEED` stays as it is, where the
//!    other cases give `ManualReducedSpeed`, `manual_reduced_speed`. Rules 5 and 7 still apply to it.
//! 3. Characters outside ASCII are kept as `uXXXX` (their code point), so distinct names stay distinct.
//! 4. The words are joined in the requested case. A name that then starts with a digit gets the prefix `N`
//!    (`n` in snake case): `3DFrameType` → `N3DFrameType`, `n3d_frame`.
//! 5. A Rust keyword becomes a raw identifier (`r#type`, `r#match`); the ones that cannot be raw (`self`,
//!    `Self`, `super`, `crate`, `_`) get a trailing underscore. A Modelica reserved word, predefined type
//!    name or annotation name (`model`, `input`, `Real`, `time`, `Documentation`, `Icon`, ...) gets a trailing
//!    underscore.
//! 6. An empty result (a name of punctuation only) becomes `_` followed by the code points (`Precise+` is
//!    fine, `+` alone becomes `u002b`).
//! 7. A Modelica identifier longer than [`MAX_IDENT_LEN`] bytes keeps its first 103 bytes and ends in 16 hex
//!    digits of a hash (FNV-1a, 64 bit) of the whole identifier, after `_` (`H` in UpperCamel case, which
//!    allows no underscore): Modelica classes become file and folder names, which file systems limit to 255
//!    bytes. Rust identifiers are not capped: no generated Rust file is named after a BrowseName (modules are
//!    the configured namespace names), and a cut name would hide the end of a long path, which is what tells
//!    two long NodeId constants apart for a reader.
//!
//! Two originals that map to one identifier in one scope are resolved by [`Scope::finish`]: the originals
//! are sorted, the first keeps the identifier, the others get `_2`, `_3`, ... in that sorted order, and a
//! collision is reported. The result depends only on the set of names in the scope, never on the order
//! they were added in.

use std::collections::BTreeMap;

/// The letter case of a generated identifier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case {
    /// `MotionDeviceType`
    UpperCamel,
    /// `motion_device_type`
    Snake,
    /// `MOTION_DEVICE_TYPE`
    ShoutySnake,
    /// Keep the words' own case, joined by nothing (Modelica components keep `ActualPosition`).
    Preserve,
}

/// The language an identifier is for: it decides the keywords and reserved words, and the length cap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// Rust.
    Rust,
    /// Modelica.
    Modelica,
}

/// Rust keywords of the 2021 edition (strict and reserved).
pub const RUST_KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern", "false", "fn",
    "for", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return", "self", "Self",
    "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where", "while", "abstract", "become",
    "box", "do", "final", "macro", "override", "priv", "try", "typeof", "unsized", "virtual", "yield", "gen",
];

/// Rust keywords that cannot be written as raw identifiers.
const RUST_NOT_RAW: &[&str] = &["self", "Self", "super", "crate", "_"];

/// Modelica 3.6 reserved words, plus the predefined type names and built-ins a class or component may not
/// shadow without confusing every reader.
pub const MODELICA_RESERVED: &[&str] = &[
    "algorithm", "and", "annotation", "block", "break", "class", "connect", "connector", "constant",
    "constrainedby", "der", "discrete", "each", "else", "elseif", "elsewhen", "encapsulated", "end", "enumeration",
    "equation", "expandable", "extends", "external", "false", "final", "flow", "for", "function", "if", "import",
    "impure", "in", "initial", "inner", "input", "loop", "model", "not", "operator", "or", "outer", "output",
    "package", "parameter", "partial", "protected", "public", "pure", "record", "redeclare", "replaceable",
    "return", "stream", "then", "true", "type", "when", "while", "within",
    // Predefined types and names.
    "Real", "Integer", "Boolean", "String", "Clock", "ExternalObject", "StateSelect", "AssertionLevel", "time",
    "sample", "pre", "edge", "change", "reinit", "assert", "terminate", "cardinality", "size", "ndims", "abs",
    "sign", "sqrt", "min", "max", "sum", "product", "fill", "zeros", "ones", "noEvent", "smooth", "homotopy",
    "delay", "initial", "terminal", "Modelica",
    // Annotations the generator writes, and the graphical records inside them: a class of one of these names
    // would read as the annotation to some tools and to every reader.
    "Documentation", "Icon", "Diagram", "Placement", "Rectangle", "Text", "Line", "Polygon", "Ellipse", "Bitmap",
    "experiment", "Evaluate",
];

/// Splits a name into words per the module rules (brackets and punctuation removed).
pub fn words(original: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    // First, separate at anything that is not alphanumeric; encode non-ASCII letters.
    let mut chunks: Vec<String> = Vec::new();
    let mut cur = String::new();
    for c in original.chars() {
        if c.is_ascii_alphanumeric() {
            cur.push(c);
        } else if !c.is_ascii() {
            if !cur.is_empty() {
                chunks.push(std::mem::take(&mut cur));
            }
            chunks.push(format!("u{:04x}", c as u32));
        } else if !cur.is_empty() {
            chunks.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        chunks.push(cur);
    }
    for chunk in chunks {
        let cs: Vec<char> = chunk.chars().collect();
        let mut start = 0;
        for i in 1..cs.len() {
            let (p, c) = (cs[i - 1], cs[i]);
            let next = cs.get(i + 1).copied();
            let boundary = (p.is_ascii_lowercase() && c.is_ascii_uppercase())
                // HTTPServer: split before the S of Server (upper, upper, lower), but not IOs / PLCs.
                || (p.is_ascii_uppercase()
                    && c.is_ascii_uppercase()
                    && next.is_some_and(|n| n.is_ascii_lowercase())
                    && !(next == Some('s') && cs.get(i + 2).is_none_or(|x| !x.is_ascii_lowercase())));
            if boundary {
                out.push(cs[start..i].iter().collect());
                start = i;
            }
        }
        out.push(cs[start..].iter().collect());
    }
    out.retain(|w| !w.is_empty());
    out
}

fn capitalize(w: &str) -> String {
    let mut cs = w.chars();
    match cs.next() {
        Some(f) => f.to_ascii_uppercase().to_string() + &cs.as_str().to_ascii_lowercase(),
        None => String::new(),
    }
}

/// Joins words in a case, before the digit, keyword and empty rules.
fn join(words: &[String], case: Case) -> String {
    match case {
        Case::UpperCamel => words
            .iter()
            .map(|w| {
                // Two-letter acronyms and numbers with a unit letter stay upper case (`IO`, `3D`); longer
                // acronyms are capitalised like words (`HttpServer`), as Rust's naming guidelines ask.
                if w.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit()) && w.len() <= 2 {
                    w.clone()
                } else if w.chars().next().is_some_and(|c| c.is_ascii_digit()) {
                    w.to_ascii_uppercase()
                } else {
                    capitalize(w)
                }
            })
            .collect(),
        Case::Snake => words.iter().map(|w| w.to_ascii_lowercase()).collect::<Vec<_>>().join("_"),
        Case::ShoutySnake => words.iter().map(|w| w.to_ascii_uppercase()).collect::<Vec<_>>().join("_"),
        Case::Preserve => words.concat(),
    }
}

/// The longest identifier [`sanitize`] returns, in bytes (rule 7).
pub const MAX_IDENT_LEN: usize = 120;

/// Rule 7: shortens an identifier longer than [`MAX_IDENT_LEN`] to exactly that length, keeping its start
/// and ending in a hash of the whole. Shorter identifiers are returned as they are.
pub fn cap_len(name: String, case: Case) -> String {
    if name.len() <= MAX_IDENT_LEN {
        return name;
    }
    let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3));
    let suffix = match case {
        Case::UpperCamel => format!("H{hash:016X}"),
        Case::ShoutySnake => format!("_{hash:016X}"),
        Case::Snake | Case::Preserve => format!("_{hash:016x}"),
    };
    // Sanitized identifiers are ASCII, so any byte index is a character boundary.
    let keep = MAX_IDENT_LEN - suffix.len();
    let mut out: String = name.chars().take(keep).collect();
    out.push_str(&suffix);
    out
}

/// The identifier for `original` in `case` for `target`. Always a valid identifier of the target language.
pub fn sanitize(original: &str, case: Case, target: Target) -> String {
    let bare = original.strip_prefix('<').and_then(|s| s.strip_suffix('>')).unwrap_or(original);
    let mut name = if case == Case::Preserve && is_plain(bare) { bare.to_string() } else { join(&words(original), case) };
    if name.is_empty() {
        name = original.chars().map(|c| format!("u{:04x}", c as u32)).collect();
        if name.is_empty() {
            name = "unnamed".into();
        }
    }
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        let prefix = if case == Case::Snake { "n" } else { "N" };
        name = format!("{prefix}{name}");
    }
    match target {
        Target::Rust => {
            if RUST_NOT_RAW.contains(&name.as_str()) {
                name.push('_');
            } else if RUST_KEYWORDS.contains(&name.as_str()) {
                name = format!("r#{name}");
            }
        }
        Target::Modelica => {
            if MODELICA_RESERVED.contains(&name.as_str()) {
                name.push('_');
            }
        }
    }
    match target {
        Target::Modelica => cap_len(name, case),
        Target::Rust => name,
    }
}

/// Rule 2, for [`Case::Preserve`]: whether a name is already written the way every target spells an identifier (ASCII letters,
/// digits and underscores, starting with a letter), so that [`Case::Preserve`] keeps it as it is.
fn is_plain(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_alphabetic()) && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Whether `s` is a valid identifier of the target (used by tests and debug assertions).
pub fn is_valid(s: &str, target: Target) -> bool {
    let body = match (target, s.strip_prefix("r#")) {
        (Target::Rust, Some(rest)) => {
            if !RUST_KEYWORDS.contains(&rest) || RUST_NOT_RAW.contains(&rest) {
                return false;
            }
            rest
        }
        _ => s,
    };
    let mut cs = body.chars();
    let Some(first) = cs.next() else { return false };
    if !(first.is_ascii_alphabetic() || first == '_') || !cs.all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return false;
    }
    match target {
        Target::Rust => body != "_" && (s.starts_with("r#") || !RUST_KEYWORDS.contains(&body)),
        Target::Modelica => !MODELICA_RESERVED.contains(&body),
    }
}

/// A collision found by [`Scope::finish`]: the identifier and the originals that map to it, sorted.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Collision<K> {
    /// The identifier the originals map to.
    pub ident: String,
    /// The originals that map to it, each with its key, sorted.
    pub members: Vec<(String, K)>,
}

/// One scope's name table: add every original (with a key identifying it), then [`Scope::finish`].
#[derive(Clone, Debug)]
pub struct Scope<K: Ord + Clone> {
    target: Target,
    case: Case,
    /// Identifiers that are taken before any name is added (e.g. fields the generator itself adds).
    reserved: Vec<String>,
    entries: Vec<(String, K)>,
}

impl<K: Ord + Clone> Scope<K> {
    /// An empty scope for identifiers in `case` for `target`.
    pub fn new(target: Target, case: Case) -> Scope<K> {
        Scope { target, case, reserved: Vec::new(), entries: Vec::new() }
    }

    /// Marks an identifier as taken by the generator.
    pub fn reserve(&mut self, ident: &str) {
        self.reserved.push(ident.to_string());
    }

    /// Adds an original name with the key that identifies it.
    pub fn add(&mut self, original: &str, key: K) {
        self.entries.push((original.to_string(), key));
    }

    /// Assigns identifiers. The result maps each key to its identifier; collisions are returned for the caller
    /// to report.
    pub fn finish(self) -> (BTreeMap<K, String>, Vec<Collision<K>>) {
        let mut by_ident: BTreeMap<String, Vec<(String, K)>> = BTreeMap::new();
        for (orig, key) in self.entries {
            by_ident.entry(sanitize(&orig, self.case, self.target)).or_default().push((orig, key));
        }
        let mut out = BTreeMap::new();
        let mut collisions = Vec::new();
        let mut taken: std::collections::BTreeSet<String> = by_ident.keys().cloned().collect();
        taken.extend(self.reserved.iter().cloned());
        for (ident, mut members) in by_ident {
            members.sort();
            let reserved_clash = self.reserved.contains(&ident);
            for (i, (_, key)) in members.iter().enumerate() {
                let n = if reserved_clash { i + 2 } else { i + 1 };
                let name = if n == 1 {
                    ident.clone()
                } else {
                    let base = ident.trim_start_matches("r#");
                    let mut k = n;
                    loop {
                        let candidate = format!("{base}_{k}");
                        if !taken.contains(&candidate) {
                            taken.insert(candidate.clone());
                            break candidate;
                        }
                        k += 1;
                    }
                };
                out.insert(key.clone(), name);
            }
            if members.len() > 1 || reserved_clash {
                collisions.push(Collision { ident, members });
            }
        }
        (out, collisions)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corpus_names_become_identifiers() {
        let cases = [
            ("3DFrameType", Case::UpperCamel, Target::Rust, "N3DFrameType"),
            ("3DFrame", Case::Snake, Target::Rust, "n3d_frame"),
            ("Type", Case::Snake, Target::Rust, "r#type"),
            ("Match", Case::Snake, Target::Rust, "r#match"),
            ("Self", Case::UpperCamel, Target::Rust, "Self_"),
            ("self", Case::Snake, Target::Rust, "self_"),
            ("Mode-A", Case::UpperCamel, Target::Rust, "ModeA"),
            ("Mode-A", Case::Snake, Target::Rust, "mode_a"),
            ("<AxisIdentifier>", Case::UpperCamel, Target::Rust, "AxisIdentifier"),
            ("UR Robot", Case::Snake, Target::Rust, "ur_robot"),
            ("Precise+", Case::UpperCamel, Target::Rust, "Precise"),
            ("IOs", Case::Snake, Target::Rust, "ios"),
            ("HTTPServer", Case::Snake, Target::Rust, "http_server"),
            ("MotionDeviceSystemType", Case::ShoutySnake, Target::Rust, "MOTION_DEVICE_SYSTEM_TYPE"),
            ("Run-1", Case::Snake, Target::Rust, "run_1"),
            ("Axis1", Case::Snake, Target::Rust, "axis1"),
            ("Model", Case::Preserve, Target::Modelica, "Model"),
            ("MANUAL_REDUCED_SPEED", Case::Preserve, Target::Modelica, "MANUAL_REDUCED_SPEED"),
            ("<Axis_Identifier>", Case::Preserve, Target::Modelica, "Axis_Identifier"),
            ("Mode-A", Case::Preserve, Target::Modelica, "ModeA"),
            ("_x", Case::Preserve, Target::Modelica, "x"),
            ("MANUAL_REDUCED_SPEED", Case::UpperCamel, Target::Rust, "ManualReducedSpeed"),
            ("model", Case::Preserve, Target::Modelica, "model_"),
            ("Real", Case::Preserve, Target::Modelica, "Real_"),
            ("input", Case::Preserve, Target::Modelica, "input_"),
            ("Documentation", Case::Preserve, Target::Modelica, "Documentation_"),
            ("Documentation", Case::UpperCamel, Target::Rust, "Documentation"),
            ("+", Case::Snake, Target::Rust, "u002b"),
            ("Größe", Case::Snake, Target::Rust, "gr_u00f6_u00df_e"),
        ];
        for (orig, case, target, want) in cases {
            let got = sanitize(orig, case, target);
            assert_eq!(got, want, "{orig:?} {case:?} {target:?}");
            assert!(is_valid(&got, target), "{got} is not valid for {target:?}");
        }
    }

    #[test]
    fn any_string_becomes_a_valid_identifier() {
        // A property test without a framework: many pseudo-random strings over a hostile alphabet.
        let alphabet: Vec<char> = "aZ09_- <>+.:/#$ÄéߥIOsSelfmatchtypeinputReal\u{200b}\u{1F600}".chars().collect();
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let len = (x % 12) as usize;
            let mut s = String::new();
            let mut y = x;
            for _ in 0..len {
                s.push(alphabet[(y % alphabet.len() as u64) as usize]);
                y = y.rotate_left(7).wrapping_mul(0x2545_F491_4F6C_DD1D);
            }
            for target in [Target::Rust, Target::Modelica] {
                for case in [Case::UpperCamel, Case::Snake, Case::ShoutySnake, Case::Preserve] {
                    let id = sanitize(&s, case, target);
                    assert!(is_valid(&id, target), "{s:?} -> {id:?} ({case:?}, {target:?})");
                }
            }
        }
    }

    #[test]
    fn long_identifiers_are_capped_distinct_and_valid() {
        let long = "VeryLongBrowseName".repeat(20);
        for target in [Target::Rust, Target::Modelica] {
            for case in [Case::UpperCamel, Case::Snake, Case::ShoutySnake, Case::Preserve] {
                let a = sanitize(&format!("{long}A"), case, target);
                let b = sanitize(&format!("{long}B"), case, target);
                match target {
                    Target::Modelica => assert_eq!(a.len(), MAX_IDENT_LEN, "{a}"),
                    // Rust keeps the whole name, end included.
                    Target::Rust => assert!(a.len() > MAX_IDENT_LEN && a.to_ascii_lowercase().ends_with('a'), "{a}"),
                }
                assert!(is_valid(&a, target) && is_valid(&b, target), "{a} / {b}");
                assert_ne!(a, b, "two long names that differ only at the end stay distinct");
                assert_eq!(a, sanitize(&format!("{long}A"), case, target), "the hash is stable");
            }
        }
        assert_eq!(sanitize(&"x".repeat(MAX_IDENT_LEN), Case::Snake, Target::Modelica).len(), MAX_IDENT_LEN);
        assert!(!sanitize(&"ab".repeat(100), Case::UpperCamel, Target::Modelica).contains('_'));
    }

    #[test]
    fn collisions_resolve_independently_of_order() {
        let names = ["Mode-A", "ModeA", "Mode A", "Other"];
        let run = |order: &[usize]| {
            let mut s: Scope<usize> = Scope::new(Target::Rust, Case::UpperCamel);
            for &i in order {
                s.add(names[i], i);
            }
            s.finish()
        };
        let (a, ca) = run(&[0, 1, 2, 3]);
        let (b, cb) = run(&[3, 2, 1, 0]);
        assert_eq!(a, b);
        assert_eq!(ca, cb);
        assert_eq!(ca.len(), 1);
        assert_eq!(ca[0].members.len(), 3);
        // Sorted originals: "Mode A" < "Mode-A" < "ModeA".
        assert_eq!(a[&2], "ModeA");
        assert_eq!(a[&0], "ModeA_2");
        assert_eq!(a[&1], "ModeA_3");
        let distinct: std::collections::BTreeSet<&String> = a.values().collect();
        assert_eq!(distinct.len(), 4);
    }

    #[test]
    fn reserved_identifiers_are_never_reused() {
        let mut s: Scope<u8> = Scope::new(Target::Rust, Case::Snake);
        s.reserve("node_id");
        s.add("NodeId", 1);
        let (m, c) = s.finish();
        assert_eq!(m[&1], "node_id_2");
        assert_eq!(c.len(), 1);
    }
}
