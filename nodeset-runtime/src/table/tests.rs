//! Tests of the table types and of the packed format.

use super::*;

#[test]
fn access_lines_decode_and_rows_skip_them() {
    let text = "\nVariable 1:6001 1:\"Setpoint\" = ~ 0 0 0:11 -1 [] 3 3 0 ~ ~ 0:40>0:63\nAccess 1:6001 ~ 0:15680=97 0:15668=33\nMethod 1:7002 1:\"Reset\" = ~ 0 0 1 1\nAccess 1:7002 2 0:15692=4097\n";
    let rows = decode(text).unwrap();
    assert_eq!(rows.len(), 2, "the Access lines are not rows");
    let access = decode_access(text).unwrap();
    assert_eq!(
        access.as_ref(),
        [
            AccessRow { id: Id::numeric(1, 6001), restrictions: None, roles: vec![(Id::ns0(15680), 97), (Id::ns0(15668), 33)] },
            AccessRow { id: Id::numeric(1, 7002), restrictions: Some(2), roles: vec![(Id::ns0(15692), 4097)] },
        ]
    );
    assert!(decode_access("Object 1:1 1:\"A\" = ~ 0 0 0\n").unwrap().is_empty());
    // A damaged line names its line and column.
    let (line, column, message) = decode_access("\nAccess 1:6001 ~ 0:15680-97\n").unwrap_err();
    assert_eq!((line, column), (2, 24), "{message}");
    assert!(message.contains("expected `=`"), "{message}");
    let (_, _, message) = decode_access("Access 1:6001 70000\n").unwrap_err();
    assert!(message.contains("out of range"), "{message}");
}

const fn row(refs: &'static [Ref], nrefs: &'static [NumRef]) -> NodeRow {
    NodeRow {
        id: Id::numeric(1, 1),
        browse_name: (1, "N"),
        display_name: "N",
        description: None,
        write_mask: 0,
        user_write_mask: 0,
        kind: Kind::Object { event_notifier: 0 },
        refs,
        nrefs,
    }
}

#[test]
fn numeric_references_read_as_refs_in_their_order() {
    let r = row(&[], &[(0, 40, 0, 58, true), (2, 4002, 1, 1003, false)]);
    let got: Vec<Ref> = r.references().collect();
    assert_eq!(
        got,
        [
            Ref { reference_type: Id::ns0(40), target: Id::ns0(58), forward: true },
            Ref { reference_type: Id::numeric(2, 4002), target: Id::numeric(1, 1003), forward: false },
        ]
    );
}

/// Lines as the generator writes them, one per node class, with every kind of identifier and escape.
const TEXT: &str = r#"
Object 1:5 1:"Cell \"A\" > 1#" "Zelle\tA" "line\nbreak \\ \u{1} ü" 3 4 1 0:47>1:s"a b>c" 0:40<0:58
ObjectType 1:g000102030405060708090a0b0c0d0e0f 0:"T" = ~ 0 0 1 0:45<0:58 0:47>1:6
Variable 1:b00ff 0:"V" = ~ 0 0 0:11 1 [2,3] 3 1 1 250.5 Array:11 { Double:NaN Double:-0 Double:inf Double:0.0000001 }
VariableType 1:7 1:"VT" = ~ 0 0 1:3001 -2 [] 1 LocalizedText:"en":"Hallo"
Method 1:8 1:"Start" = ~ 0 0 1 0 0:46>1:9
Variable 1:9 0:"InputArguments" = ~ 0 0 0:296 1 [0] 1 1 0 ~ Arguments:{ "Speed" 0:11 -1 [] "mm/s" "Axes" 1:s"Id" 1 [6] ~ }
ReferenceType 1:10 1:"Feeds" = ~ 0 0 0 1 "FedBy"
DataType 1:11 1:"Mode" = ~ 0 0 0 Enum { -1 "Off" = ~ 5 "On" "Running" "the axis moves" } 0:45<0:29
DataType 1:12 1:"Point" = ~ 0 0 0 StructureWithOptionalFields 0:22 1:13 { "X" ~ 0:11 -1 [] 0 0 "Label" "a name" 0:12 -1 [] 40 1 }
DataType 1:14 1:"Abstract" = ~ 0 0 1 ~
View 1:15 1:"Overview" = ~ 0 0 1 1
"#;

#[test]
fn packed_rows_decode_every_construct() {
    let rows = decode(TEXT).expect("the text decodes");
    assert_eq!(rows.len(), 11);
    let cell = &rows[0];
    assert_eq!(cell.id, Id::numeric(1, 5));
    assert_eq!(cell.browse_name, (1, "Cell \"A\" > 1#"));
    assert_eq!(cell.display_name, "Zelle\tA");
    assert_eq!(cell.description, Some("line\nbreak \\ \u{1} ü"));
    assert_eq!((cell.write_mask, cell.user_write_mask), (3, 4));
    assert!(matches!(cell.kind, Kind::Object { event_notifier: 1 }));
    // A string identifier among the references: all of the row's references are general ones.
    assert!(cell.nrefs.is_empty());
    assert_eq!(
        cell.refs,
        [
            Ref { reference_type: Id::ns0(47), target: Id { ns: 1, id: IdKind::String("a b>c") }, forward: true },
            Ref { reference_type: Id::ns0(40), target: Id::ns0(58), forward: false },
        ]
    );

    let t = &rows[1];
    let guid: [u8; 16] = std::array::from_fn(|i| i as u8);
    assert_eq!(t.id, Id { ns: 1, id: IdKind::Guid(guid) });
    assert_eq!((t.browse_name, t.display_name, t.description), ((0, "T"), "T", None));
    assert!(matches!(t.kind, Kind::ObjectType { is_abstract: true }));
    assert!(t.refs.is_empty());
    assert_eq!(t.nrefs, [(0, 45, 0, 58, false), (0, 47, 1, 6, true)]);

    let v = &rows[2];
    assert_eq!(v.id, Id { ns: 1, id: IdKind::Opaque(&[0x00, 0xff]) });
    let Kind::Variable {
        data_type,
        value_rank,
        array_dimensions,
        access_level,
        user_access_level,
        historizing,
        minimum_sampling_interval,
        value: Val::Array(11, items),
    } = v.kind
    else {
        panic!("a Variable with an array value: {:?}", v.kind)
    };
    assert_eq!((data_type, value_rank, array_dimensions), (Id::ns0(11), 1, &[2, 3][..]));
    assert_eq!((access_level, user_access_level, historizing, minimum_sampling_interval), (3, 1, true, Some(250.5)));
    let doubles: Vec<f64> = items
        .iter()
        .map(|i| match i {
            Val::Double(x) => *x,
            other => panic!("not a Double: {other:?}"),
        })
        .collect();
    assert!(doubles[0].is_nan());
    assert!(doubles[1] == 0.0 && doubles[1].is_sign_negative());
    assert_eq!(doubles[2..], [f64::INFINITY, 1e-7]);

    assert!(matches!(
        rows[3].kind,
        Kind::VariableType { data_type: Id { ns: 1, id: IdKind::Numeric(3001) }, value_rank: -2, is_abstract: true, value: Val::LocalizedText(Some("en"), "Hallo"), .. }
    ));
    assert!(matches!(rows[4].kind, Kind::Method { executable: true, user_executable: false }));
    let Kind::Variable { value: Val::Arguments(args), .. } = rows[5].kind else { panic!("arguments: {:?}", rows[5].kind) };
    assert_eq!(
        args,
        [
            ArgRow { name: "Speed", data_type: Id::ns0(11), value_rank: -1, array_dimensions: &[], description: Some("mm/s") },
            ArgRow {
                name: "Axes",
                data_type: Id { ns: 1, id: IdKind::String("Id") },
                value_rank: 1,
                array_dimensions: &[6],
                description: None
            },
        ]
    );
    assert!(matches!(rows[6].kind, Kind::ReferenceType { symmetric: false, is_abstract: true, inverse_name: Some("FedBy") }));
    let Kind::DataType { is_abstract: false, definition: Some(Def::Enum { fields }) } = rows[7].kind else { panic!("{:?}", rows[7].kind) };
    assert_eq!(
        fields,
        [
            EnumRow { value: -1, name: "Off", display_name: "Off", description: None },
            EnumRow { value: 5, name: "On", display_name: "Running", description: Some("the axis moves") },
        ]
    );
    let Kind::DataType { definition: Some(Def::Structure { base, default_encoding, kind, fields }), .. } = rows[8].kind else {
        panic!("{:?}", rows[8].kind)
    };
    assert_eq!((base, default_encoding, kind), (Id::ns0(22), Some(Id::numeric(1, 13)), StructureKind::StructureWithOptionalFields));
    assert_eq!(fields.len(), 2);
    assert_eq!(
        fields[1],
        FieldRow {
            name: "Label",
            description: Some("a name"),
            data_type: Id::ns0(12),
            value_rank: -1,
            array_dimensions: &[],
            max_string_length: 40,
            is_optional: true
        }
    );
    assert!(matches!(rows[9].kind, Kind::DataType { is_abstract: true, definition: None }));
    assert!(matches!(rows[10].kind, Kind::View { event_notifier: 1, contains_no_loops: true }));
}

/// Every scalar value tag, each as a Variable's value.
#[test]
fn packed_values_of_every_tag() {
    let values = [
        "~",
        "Boolean:1",
        "SByte:-128",
        "Byte:255",
        "Int16:-32768",
        "UInt16:65535",
        "Int32:-2147483648",
        "UInt32:4294967295",
        "Int64:-9223372036854775808",
        "UInt64:18446744073709551615",
        "Float:1.5",
        "Double:-2.25",
        "String:\"\"",
        "DateTime:\"2025-11-15T00:00:00Z\"",
        "Guid:ffeeddccbbaa99887766554433221100",
        "ByteString:",
        "NodeId:2:s\"Pump\"",
        "ExpandedNodeId:0:85",
        "StatusCode:2147483648",
        "QualifiedName:1:\"Name\"",
        "LocalizedText:~:\"\"",
        "Array:21 { }",
        "EnumValues:{ 0 \"A\" = ~ }",
    ];
    let text: String =
        values.iter().enumerate().map(|(i, v)| format!("Variable 1:{i} 1:\"V\" = ~ 0 0 0:24 -1 [] 1 1 0 ~ {v}\n")).collect();
    let rows = decode(Box::leak(text.into_boxed_str())).expect("every value decodes");
    let got: Vec<String> = rows
        .iter()
        .map(|r| match r.kind {
            Kind::Variable { value, .. } => format!("{value:?}"),
            _ => unreachable!(),
        })
        .collect();
    assert_eq!(
        got,
        [
            "None",
            "Boolean(true)",
            "SByte(-128)",
            "Byte(255)",
            "Int16(-32768)",
            "UInt16(65535)",
            "Int32(-2147483648)",
            "UInt32(4294967295)",
            "Int64(-9223372036854775808)",
            "UInt64(18446744073709551615)",
            "Float(1.5)",
            "Double(-2.25)",
            "String(\"\")",
            "DateTime(\"2025-11-15T00:00:00Z\")",
            "Guid([255, 238, 221, 204, 187, 170, 153, 136, 119, 102, 85, 68, 51, 34, 17, 0])",
            "ByteString([])",
            "NodeId(Id { ns: 2, id: String(\"Pump\") })",
            "ExpandedNodeId(Id { ns: 0, id: Numeric(85) })",
            "StatusCode(2147483648)",
            "QualifiedName(1, \"Name\")",
            "LocalizedText(None, \"\")",
            "Array(21, [])",
            "EnumValues([EnumRow { value: 0, name: \"A\", display_name: \"A\", description: None }])",
        ]
    );
}

#[test]
fn bad_packed_text_names_line_column_and_cause() {
    let cases: [(&'static str, (usize, usize, &str)); 8] = [
        ("Object 1:18446744073709551616 1:\"N\" = ~ 0 0 0", (1, 29, "number too large")),
        ("\nObject 1:5 1:\"N\" = ~ 0 0 x", (2, 26, "expected a number")),
        ("Object 1:5 1:\"N\" = ~ 0 0 300", (1, 26, "300 is out of range for an EventNotifier")),
        ("Thing 1:5 1:\"N\" = ~ 0 0 0", (1, 1, "unknown node class `Thing`")),
        ("Object 1:5 1:\"N", (1, 16, "unterminated string")),
        ("Object 1:5 1:\"N\\q\" = ~ 0 0 0", (1, 18, "unknown escape `\\q`")),
        ("Object 1:5 1:\"N\" = ~ 0 0 0 0:47=1:6", (1, 32, "expected `>` or `<` between a reference's type and target")),
        ("ObjectType 1:gabcd 0:\"T\" = ~ 0 0 1", (1, 19, "a GUID is 32 hex digits")),
    ];
    for (text, (line, column, message)) in cases {
        assert_eq!(decode(text).err(), Some((line, column, message.to_owned())), "{text:?}");
    }
}

static BROKEN: NodeSetTable = NodeSetTable {
    namespace_uri: "urn:broken",
    version: "",
    publication_date: "",
    namespaces: &["http://opcfoundation.org/UA/", "urn:broken"],
    own: 1,
    nodes: Nodes::Packed(Packed::new("Object 1:1 1:\"A\" = ~ 0 0 0\nObject 1:2")),
};

#[test]
fn a_table_that_does_not_decode_says_where_every_time() {
    for _ in 0..2 {
        let e = BROKEN.rows().expect_err("line 2 is cut short");
        assert_eq!((e.namespace_uri, e.line, e.column), ("urn:broken", 2, 11));
        assert!(e.to_string().contains("urn:broken does not decode at line 2, column 11: expected ` `"), "{e}");
    }
}

#[test]
fn general_references_come_through_unchanged() {
    const REFS: &[Ref] =
        &[Ref { reference_type: Id::ns0(47), target: Id { ns: 1, id: IdKind::String("Pump") }, forward: true }];
    assert_eq!(row(REFS, &[]).references().collect::<Vec<_>>(), REFS);
    assert_eq!(row(&[], &[]).references().count(), 0);
}
