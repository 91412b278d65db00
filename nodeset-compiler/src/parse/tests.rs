//! Tests of the parser: every diagnostic, the limits, and its own reading of common forms against quick-xml's.

use super::events::{AttributeScan, GaveUp};
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
