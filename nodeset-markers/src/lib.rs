//! The naming rule of member markers, shared by `nodeset-compiler` and `nodeset-derive`.
//!
//! The Rust that nodeset-compiler generates declares, for every ObjectType, one marker constant per
//! variable reachable from its instances (`objects::members::MotionDeviceType::ParameterSet__SpeedOverride`).
//! `#[derive(ObjectModel)]` never reads XML: from a field's browse path (`#[opcua(path = "ParameterSet/SpeedOverride")]`)
//! it computes the same name and lets rustc find the constant. The two crates therefore have to agree on
//! one function, [`marker_name`], which lives here and nowhere else.
//!
//! ```
//! assert_eq!(nodeset_markers::marker_name(&["ParameterSet", "SpeedOverride"]), "ParameterSet__SpeedOverride");
//! assert_eq!(nodeset_markers::marker_name(&["3DFrame"]), "_3DFrame");
//! assert_eq!(nodeset_markers::marker_name(&["type"]), "type_");
//! ```

#![forbid(unsafe_code)]
#![deny(missing_docs)]

/// The words a Rust identifier cannot be (syn 2's list: strict, reserved and weak keywords it refuses, and
/// `_`). A marker name equal to one of these gets a trailing `_`.
pub const RESERVED: &[&str] = &[
    "_", "abstract", "as", "async", "await", "become", "box", "break", "const", "continue", "crate", "do", "dyn",
    "else", "enum", "extern", "false", "final", "fn", "for", "if", "impl", "in", "let", "loop", "macro", "match",
    "mod", "move", "mut", "override", "priv", "pub", "ref", "return", "Self", "self", "static", "struct", "super",
    "trait", "true", "try", "type", "typeof", "unsafe", "unsized", "use", "virtual", "where", "while", "yield",
];

/// The marker name of a browse path (one BrowseName per segment, namespace indices left out).
///
/// Every character that cannot be in an identifier (anything but ASCII letters, digits and `_`) becomes
/// `_`; an empty segment or one that starts with a digit gets a `_` before it; the segments are joined by
/// `__`; a result that is not an identifier (a keyword, see [`RESERVED`], or the empty path) gets a trailing
/// `_`. Two paths can map to one name (`A/B` and `A__B`); the compiler declares no marker for such a name.
pub fn marker_name(segments: &[&str]) -> String {
    let mut name = String::new();
    for (i, s) in segments.iter().enumerate() {
        if i > 0 {
            name.push_str("__");
        }
        if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
            name.push('_');
        }
        name.extend(s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }));
    }
    if name.is_empty() || RESERVED.contains(&name.as_str()) {
        name.push('_');
    }
    name
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether syn, and so `format_ident!` in the derive and the generated code's parser, takes `s` as an
    /// identifier.
    fn is_ident(s: &str) -> bool {
        syn::parse_str::<syn::Ident>(s).is_ok()
    }

    #[test]
    fn the_documented_cases() {
        assert_eq!(marker_name(&["ParameterSet", "ActualPosition"]), "ParameterSet__ActualPosition");
        assert_eq!(marker_name(&["<AxisIdentifier>", "Run-1"]), "_AxisIdentifier___Run_1");
        assert_eq!(marker_name(&["3DFrame", "UR Robot"]), "_3DFrame__UR_Robot");
        assert_eq!(marker_name(&["", "x"]), "___x");
        assert_eq!(marker_name(&["Precise+"]), "Precise_");
        assert_eq!(marker_name(&["Gültig"]), "G_ltig");
        assert_eq!(marker_name(&["self"]), "self_");
        assert_eq!(marker_name(&["Self"]), "Self_");
        assert_eq!(marker_name(&["Type"]), "Type");
        assert_eq!(marker_name(&["_"]), "__");
        assert_eq!(marker_name(&[""]), "__");
        assert_eq!(marker_name(&[]), "_");
    }

    /// The keyword list is syn's: each is refused as it is and accepted with the trailing `_`.
    #[test]
    fn reserved_words_are_exactly_what_syn_refuses() {
        for w in RESERVED {
            assert!(!is_ident(w), "`{w}` is an identifier for syn; drop it from RESERVED");
            assert!(is_ident(&marker_name(&[w])), "`{w}_` is not an identifier");
        }
        // Every keyword of the Rust reference (strict, reserved, weak, any edition), written out here rather
        // than taken from RESERVED: each gives an identifier, the one syn's parser gives. Words a newer
        // edition reserves that syn 2 still accepts (`gen`, `union`) stay as they are.
        let reference = "as break const continue crate else enum extern false fn for if impl in let loop match mod \
            move mut pub ref return self Self static struct super trait true type unsafe use where while async await \
            dyn abstract become box do final macro override priv typeof unsized virtual yield try gen \
            macro_rules raw safe union auto default _";
        for w in reference.split_whitespace() {
            assert!(is_ident(&marker_name(&[w])), "`{w}` -> `{}` is not an identifier", marker_name(&[w]));
            assert_eq!(marker_name(&[w]), syn_rule(&[w]), "`{w}`");
        }
    }

    /// The rule as both crates wrote it before it moved here, asking syn whether the name is an identifier.
    fn syn_rule(segments: &[&str]) -> String {
        let parts: Vec<String> = segments
            .iter()
            .map(|s| {
                let mut p: String = s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
                if p.is_empty() || p.starts_with(|c: char| c.is_ascii_digit()) {
                    p.insert(0, '_');
                }
                p
            })
            .collect();
        let mut name = parts.join("__");
        if !is_ident(&name) {
            name.push('_');
        }
        name
    }

    /// Every name the rule makes is an identifier, and the one syn's parser would give, over segments built
    /// from an alphabet that holds each kind of character the rule treats differently.
    #[test]
    fn every_name_is_an_identifier() {
        let alphabet = ["", "a", "Z", "0", "9", "_", "-", " ", "/", "é", "<", "type", "Self", "r#", "1x"];
        let mut checked = 0;
        for a in alphabet {
            for b in alphabet {
                for c in alphabet {
                    let seg = format!("{a}{b}{c}");
                    for path in [vec![seg.as_str()], vec![seg.as_str(), a], vec![b, seg.as_str(), c]] {
                        let name = marker_name(&path);
                        assert!(is_ident(&name), "{path:?} -> `{name}` is not an identifier");
                        assert_eq!(name, syn_rule(&path), "{path:?}");
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 3 * alphabet.len().pow(3));
    }
}
