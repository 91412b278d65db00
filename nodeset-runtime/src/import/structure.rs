//! Structure values of a table ([`Val::Structure`]): the body written in OPC UA binary with the server's
//! namespace indices, then decoded by the server's type loaders.
//!
//! The compiler lays a structure value out as the items of its binary encoding (encoding mask, switch field,
//! fields in place or as ExtensionObjects, nulls for fields the value leaves out), because it knows every
//! field's DataType; what it cannot know are the namespace indices of the NodeIds and QualifiedNames inside,
//! which are the server's. Here each item is written as Part 6 encodes it, and the bytes are decoded with
//! the encoding's type loader: ns0's (EUInformation, Range, ...), a generated namespace's `TypeLoader` the
//! server was given, or, for a type no loader knows, async-opcua's fallback, which keeps the bytes and sends
//! them as they are. Either way a client reads the same bytes.

use opcua::types::{
    BinaryEncodable, ByteString, ByteStringBody, DataValue, DateTime, DiagnosticInfo, ExpandedNodeId, ExtensionObject, Guid,
    LocalizedText, NodeId, QualifiedName, StatusCode, UAString, Variant,
};

use super::{parse_date_time, Ctx};
use crate::table::Val;

type Res<T> = Result<T, String>;

impl Ctx<'_> {
    /// The ExtensionObject of a structure value, or why it cannot be built.
    pub(super) fn structure(&self, encoding: crate::table::Id, items: &[Val], node: &NodeId) -> Res<ExtensionObject> {
        let encoding = self.map.try_id(encoding).ok_or_else(|| format!("its encoding {encoding:?} has an unregistered namespace"))?;
        let mut body = Vec::with_capacity(16 * items.len());
        for item in items {
            self.write(&mut body, item, node)?;
        }
        let len = body.len();
        let mut rest = &body[..];
        match self.types.load_from_binary(&encoding, &mut rest, Some(len)) {
            Ok(eo) if rest.is_empty() => return Ok(eo),
            Ok(_) => tracing::warn!(
                "table {}: node {node}: the type loader of {encoding} read {} of the {len} bytes of the value; the bytes are served as they are",
                self.table.namespace_uri,
                len - rest.len()
            ),
            Err(e) => tracing::warn!(
                "table {}: node {node}: the type loader of {encoding} cannot decode the value ({e}); the bytes are served as they are",
                self.table.namespace_uri
            ),
        }
        Ok(ExtensionObject { body: Some(Box::new(ByteStringBody::new(ByteString::from(body), encoding))) })
    }

    /// Appends one item of a structure's body in OPC UA binary.
    fn write(&self, out: &mut Vec<u8>, v: &Val, node: &NodeId) -> Res<()> {
        let c = self.types;
        let r = match v {
            Val::Boolean(x) => x.encode(out, c),
            Val::SByte(x) => x.encode(out, c),
            Val::Byte(x) => x.encode(out, c),
            Val::Int16(x) => x.encode(out, c),
            Val::UInt16(x) => x.encode(out, c),
            Val::Int32(x) => x.encode(out, c),
            Val::UInt32(x) => x.encode(out, c),
            Val::Int64(x) => x.encode(out, c),
            Val::UInt64(x) => x.encode(out, c),
            Val::Float(x) => x.encode(out, c),
            Val::Double(x) => x.encode(out, c),
            Val::String(s) => UAString::from(*s).encode(out, c),
            Val::DateTime(s) => parse_date_time(s).ok_or_else(|| format!("DateTime {s:?} is not ISO 8601"))?.encode(out, c),
            Val::Guid(g) => Guid::from_bytes(*g).encode(out, c),
            Val::ByteString(b) => ByteString::from(b.to_vec()).encode(out, c),
            Val::NodeId(id) => self.id_in_value(*id)?.encode(out, c),
            Val::ExpandedNodeId(id) => ExpandedNodeId::new(self.id_in_value(*id)?).encode(out, c),
            Val::StatusCode(s) => StatusCode::from(*s).encode(out, c),
            Val::QualifiedName(ns, name) => {
                let ns = self.map.try_index(*ns).ok_or_else(|| format!("QualifiedName {ns}:{name} has an unregistered namespace"))?;
                QualifiedName::new(ns, *name).encode(out, c)
            }
            Val::LocalizedText(locale, text) => LocalizedText::new(locale.unwrap_or(""), text).encode(out, c),
            Val::Array(_, items) => {
                let n = i32::try_from(items.len()).map_err(|_| "an array longer than i32::MAX")?;
                n.encode(out, c).map_err(|e| e.to_string())?;
                return items.iter().try_for_each(|i| self.write(out, i, node));
            }
            Val::Structure(encoding, items) => {
                // An ExtensionObject: its encoding's NodeId, 1 (a binary body), the body's length, the body.
                let id = self.map.try_id(*encoding).ok_or_else(|| format!("encoding {encoding:?} has an unregistered namespace"))?;
                let mut body = Vec::new();
                for item in items.iter() {
                    self.write(&mut body, item, node)?;
                }
                let len = i32::try_from(body.len()).map_err(|_| "a structure longer than i32::MAX bytes")?;
                id.encode(out, c).and_then(|_| 1u8.encode(out, c)).and_then(|_| len.encode(out, c)).map_err(|e| e.to_string())?;
                out.extend_from_slice(&body);
                return Ok(());
            }
            Val::Fields(items) => return items.iter().try_for_each(|i| self.write(out, i, node)),
            Val::Variant(inner) => {
                let value = match inner {
                    Val::Null(_) => Variant::Empty,
                    inner => self.value(inner, node).ok_or("a Variant item has no value")?,
                };
                value.encode(out, c)
            }
            Val::Null(builtin) => null(*builtin, out, c)?,
            Val::NullArray(_) => (-1i32).encode(out, c),
            Val::None | Val::Arguments(_) | Val::EnumValues(_) | Val::Struct(_) => {
                return Err(format!("{v:?} cannot be an item of a structure's body"))
            }
        };
        r.map_err(|e| e.to_string())
    }

    /// A NodeId inside a structure value with the server's namespace index.
    fn id_in_value(&self, id: crate::table::Id) -> Res<NodeId> {
        self.map.try_id(id).ok_or_else(|| format!("NodeId {id:?} has an unregistered namespace"))
    }
}

/// Writes the null value of a built-in type (by its ns0 DataType number).
fn null(builtin: u32, out: &mut Vec<u8>, c: &opcua::types::Context<'_>) -> Res<opcua::types::EncodingResult<()>> {
    Ok(match builtin {
        1 => false.encode(out, c),
        2 | 3 => 0u8.encode(out, c),
        4 | 5 => 0u16.encode(out, c),
        6 | 7 | 19 => 0u32.encode(out, c),
        8 | 9 => 0u64.encode(out, c),
        10 => 0f32.encode(out, c),
        11 => 0f64.encode(out, c),
        12 | 15 | 16 => (-1i32).encode(out, c),
        13 => DateTime::null().encode(out, c),
        14 => Guid::null().encode(out, c),
        17 => NodeId::null().encode(out, c),
        18 => ExpandedNodeId::null().encode(out, c),
        20 => QualifiedName::null().encode(out, c),
        21 => LocalizedText::null().encode(out, c),
        22 => ExtensionObject::null().encode(out, c),
        23 => DataValue::null().encode(out, c),
        24 => Variant::Empty.encode(out, c),
        25 => DiagnosticInfo::null().encode(out, c),
        other => return Err(format!("{other} is not a built-in type")),
    })
}
