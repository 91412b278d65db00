//! Structure values read back from a server, compared with what the nodesets say.
//!
//! A variable whose value in a NodeSet2 file holds structures (an ExtensionObject, or an array of them:
//! EUInformation, Range, a companion spec's own structures, method arguments) must read back from a server
//! of that file with the same content. The model's value is laid out in the order of its OPC UA binary
//! encoding by the one function that lays it out for the node tables ([`layout_value`]: field order, the
//! encoding mask of optional fields, a union's switch, nested structures in place or as ExtensionObjects);
//! the bytes the server sent are then read item by item along that layout, each field decoded with
//! async-opcua's decoder of its built-in type and compared with the file's value. NodeIds and
//! QualifiedNames inside are compared by namespace URI (through the server's namespace indices).

use crate::emit::rust::{layout_value, ValueItem as Item};
use crate::model::{Model, NodeIx};
use crate::nodeid::{Identifier, NodeId};
use crate::value::{BuiltinType, Variant};
use opcua::types::{BinaryDecodable, ContextOwned, Variant as UaVariant};

/// How deep items may nest before the bytes are taken for malformed.
const MAX_DEPTH: usize = 48;

/// Whether the model's value of variable `ix` holds a structure (an ExtensionObject or an array of them).
pub fn holds_structure(model: &Model, ix: NodeIx) -> bool {
    match model.value(ix) {
        Some(Ok(Variant::ExtensionObject(_))) => true,
        Some(Ok(Variant::Array(BuiltinType::ExtensionObject, items))) => !items.is_empty(),
        _ => false,
    }
}

/// Compares the ExtensionObjects a server sent for variable `ix` (`got`, each in OPC UA binary) with the
/// model's value of `ix`. `Ok(false)` if the model's value holds no structure the node tables serve (nothing
/// to compare), `Ok(true)` if every field agrees, the first difference otherwise (with the field's place:
/// `[2].Range.High`). `to_server` maps a model namespace index to the server's.
pub fn compare(model: &Model, ix: NodeIx, got: &[Vec<u8>], to_server: &dyn Fn(u16) -> Option<u16>) -> Result<bool, String> {
    if !holds_structure(model, ix) {
        return Ok(false);
    }
    let Some(Ok(value)) = model.value(ix) else { return Ok(false) };
    let Ok(Some(item)) = layout_value(model, value) else { return Ok(false) };
    let expected: Vec<&Item> = match &item {
        Item::Structure(..) => vec![&item],
        Item::Array(BuiltinType::ExtensionObject, items) => items.iter().collect(),
        Item::Arguments(_) | Item::EnumValues(_) => return compare_special(model, &item, got, to_server),
        _ => return Ok(false),
    };
    if expected.len() != got.len() {
        return Err(format!("the file gives {} structure(s), the server sent {}", expected.len(), got.len()));
    }
    for (i, (want, bytes)) in expected.iter().zip(got).enumerate() {
        let place = if matches!(item, Item::Array(..)) { format!("[{i}]") } else { String::new() };
        let mut r = Reader { rest: bytes, ctx: ContextOwned::default(), to_server };
        r.item(want, &place, 0)?;
        if !r.rest.is_empty() {
            return Err(format!("{place}: {} byte(s) more than the file's value", r.rest.len()));
        }
    }
    Ok(true)
}

/// Method arguments and EnumValues, which the layout keeps in forms of their own: compared by their
/// fields (Argument: Name, DataType, ValueRank, ArrayDimensions, Description's text; EnumValueType: Value,
/// DisplayName's and Description's texts).
fn compare_special(model: &Model, item: &Item, got: &[Vec<u8>], to_server: &dyn Fn(u16) -> Option<u16>) -> Result<bool, String> {
    let n = match item {
        Item::Arguments(a) => a.len(),
        Item::EnumValues(v) => v.len(),
        _ => return Ok(false),
    };
    if n != got.len() {
        return Err(format!("the file gives {n} structure(s), the server sent {}", got.len()));
    }
    for (i, bytes) in got.iter().enumerate() {
        let mut r = Reader { rest: bytes, ctx: ContextOwned::default(), to_server };
        r.header(&format!("[{i}]"))?;
        let text = |t: opcua::types::LocalizedText| t.text.as_ref().to_owned();
        match item {
            Item::Arguments(args) => {
                let a = &args[i];
                let name: opcua::types::UAString = r.decode(&format!("[{i}].Name"))?;
                let data_type: opcua::types::NodeId = r.decode(&format!("[{i}].DataType"))?;
                let value_rank: i32 = r.decode(&format!("[{i}].ValueRank"))?;
                let dims: Option<Vec<u32>> = r.decode(&format!("[{i}].ArrayDimensions"))?;
                let description: opcua::types::LocalizedText = r.decode(&format!("[{i}].Description"))?;
                let want_type = match a.data_type {
                    Some(dt) => r.server_id(&model.node(dt).id),
                    None => Some(opcua::types::NodeId::new(0, crate::model::ids::BASE_DATA_TYPE)),
                };
                if want_type.is_some_and(|t| t != data_type) {
                    return Err(format!("[{i}]: the argument `{}` has the DataType {data_type} on the server", a.name));
                }
                let got = (name.as_ref().to_owned(), value_rank, dims.unwrap_or_default(), text(description));
                // ArrayDimensions a file leaves out (`<ArrayDimensions/>`) and zeros (lengths not fixed) mean the
                // same; Part 3 wants one entry per dimension, so servers pad with 0 (ours, and async-opcua's decoder).
                let mut dims = a.array_dimensions.clone();
                dims.resize(dims.len().max(usize::try_from(a.value_rank).unwrap_or(0)), 0);
                let want = (a.name.clone(), a.value_rank, dims, a.description.clone().unwrap_or_default());
                if got != want {
                    return Err(format!("[{i}]: the file gives the argument (Name, ValueRank, ArrayDimensions, Description) {want:?}, the server sent {got:?}"));
                }
            }
            Item::EnumValues(values) => {
                let v = &values[i];
                let value: i64 = r.decode(&format!("[{i}].Value"))?;
                let display: opcua::types::LocalizedText = r.decode(&format!("[{i}].DisplayName"))?;
                let description: opcua::types::LocalizedText = r.decode(&format!("[{i}].Description"))?;
                let same = value == v.value
                    && text(display) == v.display_name.as_deref().unwrap_or(&v.name)
                    && text(description) == v.description.as_deref().unwrap_or("");
                if !same {
                    return Err(format!("[{i}]: the enumeration value `{}` differs from the file's", v.name));
                }
            }
            _ => {}
        }
    }
    Ok(true)
}

/// The bytes of one ExtensionObject, read along the layout of the file's value.
struct Reader<'a> {
    rest: &'a [u8],
    ctx: ContextOwned,
    to_server: &'a dyn Fn(u16) -> Option<u16>,
}

impl Reader<'_> {
    fn decode<T: BinaryDecodable>(&mut self, place: &str) -> Result<T, String> {
        T::decode(&mut self.rest, &self.ctx.context()).map_err(|e| format!("{place}: the server's bytes do not decode ({e})"))
    }

    /// An ExtensionObject's encoding NodeId, its binary-body mark and its length; the encoding NodeId.
    fn header(&mut self, place: &str) -> Result<opcua::types::NodeId, String> {
        let encoding: opcua::types::NodeId = self.decode(place)?;
        let mark: u8 = self.decode(place)?;
        if mark != 1 {
            return Err(format!("{place}: the server sent an ExtensionObject without a binary body (encoding {encoding})"));
        }
        let len: i32 = self.decode(place)?;
        if len < 0 || len as usize > self.rest.len() {
            return Err(format!("{place}: the ExtensionObject's length {len} does not fit the {} byte(s) sent", self.rest.len()));
        }
        Ok(encoding)
    }

    fn item(&mut self, item: &Item, place: &str, depth: usize) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err(format!("{place}: structures nest too deep"));
        }
        match item {
            Item::Value(Variant::Array(b, items)) => {
                let n: i32 = self.decode(place)?;
                if n.max(0) as usize != items.len() {
                    return Err(format!("{place}: {} item(s) in the file, {n} sent", items.len()));
                }
                for (i, v) in items.iter().enumerate() {
                    self.scalar(*b, Some(v), &format!("{place}[{i}]"))?;
                }
                Ok(())
            }
            Item::Value(v) => match v.builtin() {
                Some(b) => self.scalar(b, Some(v), place),
                None => Ok(()),
            },
            Item::Structure(encoding, items) => {
                let got = self.header(place)?;
                let want = self.server_id(encoding);
                if want.as_ref().is_some_and(|w| *w != got) {
                    return Err(format!("{place}: the server sent a structure of encoding {got}, the file one of {}", display(encoding)));
                }
                self.fields(items, place, depth)
            }
            Item::Fields(items) => self.fields(items, place, depth),
            Item::Array(_, items) => {
                let n: i32 = self.decode(place)?;
                if n.max(0) as usize != items.len() {
                    return Err(format!("{place}: {} item(s) in the file, {n} sent", items.len()));
                }
                items.iter().enumerate().try_for_each(|(i, x)| self.item(x, &format!("{place}[{i}]"), depth + 1))
            }
            Item::Variant(inner) => {
                // An ExtensionObject in a Variant: its mask (22), then the object, read along the layout.
                if matches!(**inner, Item::Structure(..)) && self.rest.first() == Some(&22) {
                    self.rest = &self.rest[1..];
                    return self.item(inner, place, depth + 1);
                }
                let got: UaVariant = self.decode(place)?;
                match &**inner {
                    Item::Value(v) => self.same(v, &got, place),
                    Item::Null(_) if got != UaVariant::Empty => Err(format!("{place}: the file gives no value, the server sent {got:?}")),
                    _ => Ok(()),
                }
            }
            Item::Null(b) => self.scalar(*b, None, place),
            Item::NullArray(_) => {
                let n: i32 = self.decode(place)?;
                if n > 0 {
                    return Err(format!("{place}: the file gives no array, the server sent {n} item(s)"));
                }
                Ok(())
            }
            Item::Arguments(_) | Item::EnumValues(_) => Err(format!("{place}: arguments inside a structure")),
        }
    }

    fn fields(&mut self, items: &[Item], place: &str, depth: usize) -> Result<(), String> {
        items.iter().enumerate().try_for_each(|(i, x)| self.item(x, &format!("{place}.{i}"), depth + 1))
    }

    /// One value of built-in type `b`; compared with `want` if the file gives one.
    fn scalar(&mut self, b: BuiltinType, want: Option<&Variant>, place: &str) -> Result<(), String> {
        use opcua::types as ua;
        let got: UaVariant = match b {
            BuiltinType::Boolean => self.decode::<bool>(place)?.into(),
            BuiltinType::SByte => self.decode::<i8>(place)?.into(),
            BuiltinType::Byte => self.decode::<u8>(place)?.into(),
            BuiltinType::Int16 => self.decode::<i16>(place)?.into(),
            BuiltinType::UInt16 => self.decode::<u16>(place)?.into(),
            BuiltinType::Int32 => self.decode::<i32>(place)?.into(),
            BuiltinType::UInt32 => self.decode::<u32>(place)?.into(),
            BuiltinType::Int64 => self.decode::<i64>(place)?.into(),
            BuiltinType::UInt64 => self.decode::<u64>(place)?.into(),
            BuiltinType::Float => self.decode::<f32>(place)?.into(),
            BuiltinType::Double => self.decode::<f64>(place)?.into(),
            BuiltinType::String => self.decode::<ua::UAString>(place)?.into(),
            BuiltinType::DateTime => self.decode::<ua::DateTime>(place)?.into(),
            BuiltinType::Guid => self.decode::<ua::Guid>(place)?.into(),
            BuiltinType::ByteString => self.decode::<ua::ByteString>(place)?.into(),
            BuiltinType::XmlElement => self.decode::<ua::XmlElement>(place)?.into(),
            BuiltinType::NodeId => self.decode::<ua::NodeId>(place)?.into(),
            BuiltinType::ExpandedNodeId => self.decode::<ua::ExpandedNodeId>(place)?.into(),
            BuiltinType::StatusCode => self.decode::<ua::StatusCode>(place)?.into(),
            BuiltinType::QualifiedName => self.decode::<ua::QualifiedName>(place)?.into(),
            BuiltinType::LocalizedText => self.decode::<ua::LocalizedText>(place)?.into(),
            BuiltinType::ExtensionObject => self.decode::<ua::ExtensionObject>(place)?.into(),
            BuiltinType::DataValue => self.decode::<ua::DataValue>(place)?.into(),
            BuiltinType::Variant => self.decode::<UaVariant>(place)?,
            BuiltinType::DiagnosticInfo => self.decode::<ua::DiagnosticInfo>(place)?.into(),
        };
        match want {
            Some(v) => self.same(v, &got, place),
            None => Ok(()),
        }
    }

    /// Whether the server's value is the file's (values async-opcua cannot hold as the file writes them,
    /// XML elements among them, are not compared).
    fn same(&self, want: &Variant, got: &UaVariant, place: &str) -> Result<(), String> {
        match self.to_ua(want) {
            Some(w) if normal(w.clone()) != normal(got.clone()) => Err(format!("{place}: the file gives {}, the server sent {got:?}", show(want))),
            _ => Ok(()),
        }
    }

    fn server_id(&self, id: &NodeId) -> Option<opcua::types::NodeId> {
        let ns = (self.to_server)(id.ns)?;
        Some(super::client::to_opcua(&NodeId { ns, id: id.id.clone() }))
    }

    fn to_ua(&self, v: &Variant) -> Option<UaVariant> {
        use opcua::types as ua;
        Some(match v {
            Variant::Boolean(x) => (*x).into(),
            Variant::SByte(x) => (*x).into(),
            Variant::Byte(x) => (*x).into(),
            Variant::Int16(x) => (*x).into(),
            Variant::UInt16(x) => (*x).into(),
            Variant::Int32(x) => (*x).into(),
            Variant::UInt32(x) => (*x).into(),
            Variant::Int64(x) => (*x).into(),
            Variant::UInt64(x) => (*x).into(),
            Variant::Float(x) => (*x).into(),
            Variant::Double(x) => (*x).into(),
            Variant::String(s) => ua::UAString::from(s.as_str()).into(),
            Variant::DateTime(s) => ua::DateTime::parse_from_rfc3339(s).ok()?.into(),
            Variant::Guid(g) => ua::Guid::from_bytes(*g).into(),
            Variant::ByteString(b) => ua::ByteString::from(b.clone()).into(),
            Variant::NodeId(id) => self.server_id(id)?.into(),
            Variant::ExpandedNodeId(id) => ua::ExpandedNodeId::new(self.server_id(id)?).into(),
            Variant::StatusCode(c) => ua::StatusCode::from(*c).into(),
            Variant::QualifiedName(q) => ua::QualifiedName::new((self.to_server)(q.ns)?, q.name.as_str()).into(),
            Variant::LocalizedText(t) => ua::LocalizedText::new(t.locale.as_deref().unwrap_or(""), &t.text).into(),
            Variant::Variant(inner) => return self.to_ua(inner),
            _ => return None,
        })
    }
}

/// A value with a null string and an empty one taken as the same (a file's `<Text/>` and a Locale it leaves
/// out are both; OPC UA binary tells them apart, but neither a file nor a client does).
fn normal(v: UaVariant) -> UaVariant {
    use opcua::types as ua;
    let text = |s: &ua::UAString| ua::UAString::from(s.as_ref());
    match v {
        UaVariant::String(s) => UaVariant::String(text(&s)),
        UaVariant::LocalizedText(t) => UaVariant::LocalizedText(Box::new(ua::LocalizedText { locale: text(&t.locale), text: text(&t.text) })),
        v => v,
    }
}

fn display(id: &NodeId) -> String {
    match &id.id {
        Identifier::Numeric(n) => format!("ns={};i={n}", id.ns),
        Identifier::String(s) => format!("ns={};s={s}", id.ns),
        _ => format!("ns={};…", id.ns),
    }
}

fn show(v: &Variant) -> String {
    match v {
        Variant::String(s) => format!("{s:?}"),
        Variant::LocalizedText(t) => format!("{:?}", t.text),
        Variant::QualifiedName(q) => format!("{}:{}", q.ns, q.name),
        other => format!("{other:?}"),
    }
}
