//! The value decoder over arbitrary `<Value>` contents.
//!
//! The input is the XML inside one `<Value>` element. It is put into a one-variable NodeSet2 file and read by
//! the parser into the file's value arena (so the parser's value limits apply as they do to real files),
//! then decoded three ways, which must agree: in place from the arena (`decode_element`), from the owned
//! tree (`decode`), and as every built-in type in turn (`decode_scalar`, which must only ever return an
//! error). What decodes must survive the text forms it is written back in: byte strings through base64,
//! GUIDs through their string form, NodeIds through `Display` and `parse_node_id`.

#![no_main]

use libfuzzer_sys::fuzz_target;
use nodeset_compiler::diag::Diagnostics;
use nodeset_compiler::nodeid::{base64_decode, base64_encode, format_guid, parse_guid, parse_node_id, NodeId, NsRef};
use nodeset_compiler::parse::{parse, Limits};
use nodeset_compiler::source::FileId;
use nodeset_compiler::value::{decode, decode_element, decode_scalar, BuiltinType, Variant};

const HEAD: &str = "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<UANodeSet xmlns=\"http://opcfoundation.org/UA/2011/03/UANodeSet.xsd\">\n<UAVariable NodeId=\"i=1\" BrowseName=\"V\" DataType=\"i=24\">\n<Value>";
const TAIL: &str = "</Value>\n</UAVariable>\n</UANodeSet>\n";

/// NodeIds inside values keep their file-local namespace index (namespaces 0-3 exist); `nsu=` is refused.
fn ids(s: &str) -> Result<NodeId, String> {
    let raw = parse_node_id(s)?;
    match raw.ns {
        NsRef::Index(i) if i < 4 => Ok(NodeId { ns: i, id: raw.id }),
        NsRef::Index(i) => Err(format!("namespace index {i} is not declared")),
        NsRef::Uri(u) => Err(format!("namespace `{u}` is not loaded")),
    }
}

fn ns(i: u16) -> Option<u16> {
    (i < 4).then_some(i)
}

/// The text forms of what was decoded read back as the same value.
fn round_trips(v: &Variant) {
    match v {
        Variant::ByteString(b) => assert_eq!(base64_decode(&base64_encode(b)).as_deref(), Some(&b[..]), "base64 of {b:?}"),
        Variant::Guid(g) => assert_eq!(parse_guid(&format_guid(g)), Some(*g), "GUID {}", format_guid(g)),
        Variant::NodeId(id) | Variant::ExpandedNodeId(id) => {
            let text = id.to_string();
            assert_eq!(ids(&text).as_ref(), Ok(id), "NodeId {id:?} prints as `{text}`");
        }
        Variant::Variant(inner) => round_trips(inner),
        Variant::Array(_, items) => items.iter().for_each(round_trips),
        _ => {}
    }
}

fuzz_target!(|data: &[u8]| {
    let inner = String::from_utf8_lossy(data);
    let text = format!("{HEAD}{inner}{TAIL}");
    let mut diags = Diagnostics::new();
    let Some(set) = parse(FileId(0), &text, &Limits::default(), &mut diags) else { return };
    let Some(value) = set.nodes.first().and_then(|n| n.value) else { return };
    let el = set.values.element(value, &text);
    let in_place = decode_element(el, &ids, &ns);
    let owned = el.to_xml();
    let from_tree = decode(&owned, &ids, &ns);
    // Debug, not PartialEq: a NaN is not equal to itself but prints the same.
    assert_eq!(format!("{in_place:?}"), format!("{from_tree:?}"), "decoding in place and from the tree disagree");
    if let Ok(v) = &in_place {
        round_trips(v);
    }
    for b in BuiltinType::ALL {
        if let Ok(v) = decode_scalar(b, &owned, &ids, &ns, 0) {
            round_trips(&v);
        }
    }
});
